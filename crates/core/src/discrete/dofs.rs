//! The map of free versus fixed degrees of freedom, shared by every assembler.
//!
//! Global basis index `k = j * n_xi + i`. Fixed DOFs carry Dirichlet data (the fitted
//! boundary control points, or frozen control points during defect correction);
//! free ones are the unknowns `c = (c^x, c^y)` of paper eq. (9)-(10).
//!
//! **Shared (periodic) DOFs.** In a periodic direction with `d` distinct functions and
//! degree `q` the basis stores `d + q` functions whose last `q` repeat the first `q`
//! (`spline::periodic`): the stored function `(i, j)`, `j >= d`, is a *replica*
//! of its *primary* `(i, j - d)`. Both carry the same control point, so the periodic
//! basis function is `N_(i,j) + N_(i,j+d)` and everything assembled per stored function
//! is summed over replicas: residual rows (`super::assembly::Discretization::restrict`),
//! Jacobian rows and columns (the pattern's extra sources), Dirichlet lifts. Assemblers
//! keep working on the stored (unwrapped) tensor basis unchanged.

use super::topology::{SideCondition, Topology};
use crate::error::{Error, Result};
use crate::spline::knots::KnotVector;
use crate::spline::surface::{Side, Surface};

/// Free/fixed split of the tensor basis functions.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    shape: [usize; 2],
    free_of: Vec<usize>,
    free: Vec<usize>,
    /// `(replica, primary)` global indices of the periodic replicas (empty without a
    /// periodic direction).
    replicas: Vec<(usize, usize)>,
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
        Self::for_wrapped(shape, [0, 0], topology)
    }

    /// The DOF map of the tensor basis `knots` with boundary conditions `topology`: a
    /// periodic knot vector in `xi` (`eta`) needs periodic west/east (south/north) sides
    /// and vice versa; its last `p` stored functions are replicas of the first `p`.
    pub fn for_basis(knots: &[KnotVector; 2], topology: &Topology) -> Result<Self> {
        let mut wrap = [0, 0];
        for (dir, (side, kv)) in [Side::West, Side::South].into_iter().zip(knots).enumerate() {
            let periodic_side = topology.side(side) == SideCondition::Periodic;
            if periodic_side != kv.is_periodic() {
                return Err(Error::Topology {
                    side: side.name().into(),
                    reason: format!(
                        "{}, but the knot vector in {} is {}",
                        if periodic_side { "periodic" } else { "not periodic" },
                        ["xi", "eta"][dir],
                        if kv.is_periodic() { "periodic" } else { "open" }
                    ),
                });
            }
            if kv.is_periodic() {
                wrap[dir] = kv.degree();
            }
        }
        Self::for_wrapped([knots[0].num_basis(), knots[1].num_basis()], wrap, topology)
    }

    /// The split with `wrap[dir]` replicated functions at the end of direction `dir`
    /// (periodic when non-zero): functions on Dirichlet sides are fixed; interface sides
    /// need multipatch numbering and are a [`Error::Topology`] naming the side.
    fn for_wrapped(shape: [usize; 2], wrap: [usize; 2], topology: &Topology) -> Result<Self> {
        topology.validate(None)?;
        for s in Side::ALL {
            let what = match topology.side(s) {
                SideCondition::Dirichlet => continue,
                SideCondition::Periodic if wrap[s.direction() ^ 1] > 0 => continue,
                SideCondition::Periodic => "periodic without a periodic knot vector across",
                SideCondition::Interface { .. } => "an interface",
            };
            return Err(Error::Topology {
                side: s.name().into(),
                reason: format!("{what}; the single-patch DOF map has Dirichlet and periodic sides only"),
            });
        }
        if wrap == [0, 0] {
            return Ok(Self::interior(shape));
        }
        let [nx, ny] = shape;
        let d = [nx - wrap[0], ny - wrap[1]];
        let fixed = |i: usize, j: usize| {
            (i == 0 && topology.is_dirichlet(Side::West))
                || (i + 1 == nx && topology.is_dirichlet(Side::East))
                || (j == 0 && topology.is_dirichlet(Side::South))
                || (j + 1 == ny && topology.is_dirichlet(Side::North))
        };
        let mut map = Self::from_predicate(shape, |i, j| i < d[0] && j < d[1] && !fixed(i, j));
        for j in 0..ny {
            for i in 0..nx {
                if i >= d[0] || j >= d[1] {
                    let (k, primary) = (j * nx + i, (j % d[1]) * nx + i % d[0]);
                    map.free_of[k] = map.free_of[primary];
                    map.replicas.push((k, primary));
                }
            }
        }
        Ok(map)
    }

    /// Free where `is_free(i, j)` holds.
    pub(crate) fn from_predicate(shape: [usize; 2], is_free: impl Fn(usize, usize) -> bool) -> Self {
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
        Self { shape, free_of, free, replicas: Vec::new() }
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

    /// `(replica, primary)` pairs of the periodic replicas: stored function `replica`
    /// carries the control point of `primary` (empty without a periodic direction).
    pub fn replicas(&self) -> &[(usize, usize)] {
        &self.replicas
    }

    /// Copy every primary control point onto its replicas.
    pub fn wrap(&self, cps: &mut [[f64; 2]]) {
        for &(k, primary) in &self.replicas {
            cps[k] = cps[primary];
        }
    }

    /// Free index of global basis function `k` (a replica has its primary's), or [`FIXED`].
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

    /// Scatter the unknown vector into the control points (fixed ones untouched),
    /// replicas of free functions included.
    pub fn scatter(&self, c: &[f64], cps: &mut [[f64; 2]]) {
        let m = self.num_free();
        for (f, &k) in self.free.iter().enumerate() {
            cps[k] = [c[f], c[m + f]];
        }
        for &(k, primary) in &self.replicas {
            if self.free_of[k] != FIXED {
                cps[k] = cps[primary];
            }
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

    #[test]
    fn periodic_eta_shares_replicas() {
        let mut t = Topology::dirichlet();
        t.sides[Side::South as usize] = SideCondition::Periodic;
        t.sides[Side::North as usize] = SideCondition::Periodic;
        let knots = [KnotVector::open_uniform(2, 3), KnotVector::periodic_uniform(2, 5)];
        let d = DofMap::for_basis(&knots, &t).unwrap();
        // 5 x 7 stored, 5 distinct rows, interior xi: 3 x 5 free
        assert_eq!(d.shape(), [5, 7]);
        assert_eq!(d.num_free(), 15);
        assert_eq!(d.replicas().len(), 2 * 5);
        assert_eq!(d.free_index(5 * 5 + 2), d.free_index(2));
        assert_eq!(d.free_index(5 * 6), FIXED);
        let c: Vec<f64> = (0..30).map(|k| k as f64).collect();
        let mut cps = vec![[0.0; 2]; 35];
        d.scatter(&c, &mut cps);
        assert_eq!(cps[5 * 5 + 2], cps[2]);
        assert_eq!(d.gather(&cps), c);
        // a periodic knot vector needs periodic sides, and vice versa
        assert!(DofMap::for_basis(&knots, &Topology::dirichlet()).unwrap_err().to_string().contains("south"));
        let open = [knots[0].clone(), KnotVector::open_uniform(2, 5)];
        assert!(DofMap::for_basis(&open, &t).is_err());
    }
}
