//! The map of free versus fixed degrees of freedom, shared by every assembler.
//!
//! Global basis index `k = j * n_xi + i`. Fixed DOFs carry Dirichlet data (the fitted
//! boundary control points, or frozen control points during defect correction);
//! free ones are the unknowns `c = (c^x, c^y)` of paper eq. (9)-(10).

use super::topology::{SideCondition, Topology};
use crate::error::{Error, Result};
use crate::spline::surface::{Side, Surface};

/// Free/fixed split of the tensor basis functions.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    shape: [usize; 2],
    free_of: Vec<usize>,
    free: Vec<usize>,
}

/// Marker for a fixed DOF in [`DofMap::free_index`].
pub const FIXED: usize = usize::MAX;

impl DofMap {
    /// Free = not on the boundary of the parameter square (`Sigma_0` of eq. 8).
    pub fn interior(shape: [usize; 2]) -> Self {
        let [nx, ny] = shape;
        Self::from_predicate(shape, |i, j| i > 0 && j > 0 && i + 1 < nx && j + 1 < ny)
    }

    /// The free / fixed split of a patch with boundary conditions `topology`: the
    /// functions on Dirichlet sides are fixed, all others free. Periodic and interface
    /// sides need shared DOFs, which this single-patch map does not number yet: they are
    /// a [`Error::Topology`] naming the side.
    pub fn for_topology(shape: [usize; 2], topology: &Topology) -> Result<Self> {
        topology.validate(None)?;
        for s in Side::ALL {
            let what = match topology.side(s) {
                SideCondition::Dirichlet => continue,
                SideCondition::Periodic => "periodic",
                SideCondition::Interface { .. } => "an interface",
            };
            return Err(Error::Topology {
                side: s.name().into(),
                reason: format!("{what}; the single-patch DOF map has Dirichlet sides only"),
            });
        }
        Ok(Self::interior(shape))
    }

    /// Free where `is_free(i, j)` holds.
    pub fn from_predicate(shape: [usize; 2], is_free: impl Fn(usize, usize) -> bool) -> Self {
        let [nx, ny] = shape;
        let mut free_of = vec![FIXED; nx * ny];
        let mut free = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                if is_free(i, j) {
                    free_of[j * nx + i] = free.len();
                    free.push(j * nx + i);
                }
            }
        }
        Self { shape, free_of, free }
    }

    /// Basis shape `[n_xi, n_eta]`.
    pub fn shape(&self) -> [usize; 2] {
        self.shape
    }

    /// Number of free scalar basis functions `m` (unknowns are `2 m`).
    pub fn num_free(&self) -> usize {
        self.free.len()
    }

    /// Total number of basis functions.
    pub fn num_total(&self) -> usize {
        self.free_of.len()
    }

    /// Free index of global basis function `k`, or [`FIXED`].
    pub fn free_index(&self, k: usize) -> usize {
        self.free_of[k]
    }

    /// Global indices of the free functions, increasing.
    pub fn free(&self) -> &[usize] {
        &self.free
    }

    /// Whether global function `k` is on a side of the square.
    pub fn on_side(&self, k: usize, side: Side) -> bool {
        Surface::side_indices(self.shape, side).contains(&k)
    }

    /// Gather the unknown vector `c = (c^x, c^y)` from control points.
    pub fn gather(&self, cps: &[[f64; 2]]) -> Vec<f64> {
        let m = self.num_free();
        let mut c = vec![0.0; 2 * m];
        for (f, &k) in self.free.iter().enumerate() {
            c[f] = cps[k][0];
            c[m + f] = cps[k][1];
        }
        c
    }

    /// Scatter the unknown vector into the control points (fixed ones untouched).
    pub fn scatter(&self, c: &[f64], cps: &mut [[f64; 2]]) {
        let m = self.num_free();
        for (f, &k) in self.free.iter().enumerate() {
            cps[k] = [c[f], c[m + f]];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interior_dofs() {
        let d = DofMap::interior([5, 4]);
        assert_eq!(d.num_free(), 3 * 2);
        assert_eq!(d.free_index(0), FIXED);
        assert_eq!(d.free_index(6), 0);
        let cps: Vec<[f64; 2]> = (0..20).map(|k| [k as f64, -(k as f64)]).collect();
        let c = d.gather(&cps);
        let mut back = vec![[0.0; 2]; 20];
        d.scatter(&c, &mut back);
        assert_eq!(back[6], cps[6]);
        assert!(d.on_side(3, Side::South) && d.on_side(19, Side::East));
        assert_eq!(DofMap::for_topology([5, 4], &Topology::dirichlet()).unwrap(), d);
        let mut t = Topology::dirichlet();
        t.sides =
            [SideCondition::Periodic, SideCondition::Dirichlet, SideCondition::Periodic, SideCondition::Dirichlet];
        let e = DofMap::for_topology([5, 4], &t).unwrap_err().to_string();
        assert!(e.contains("south") && e.contains("periodic"), "{e}");
    }
}
