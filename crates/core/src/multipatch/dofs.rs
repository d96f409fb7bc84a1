//! The global numbering of the control points of a conforming layout: the control points
//! on the two sides of an interface are one (shared) degree of freedom, numbered once;
//! every patch keeps its own tensor numbering `k = j n_xi + i` and reads its unknowns
//! through `free_of[patch][k]`, so the per-patch assembly kernels
//! ([`crate::methods::flux::flux_form`], [`crate::methods::winslow`]) run unchanged and
//! their rows and columns are summed into the global system (eq. 9-10 over all patches).
//!
//! This is the numbering the patch topologies' [`SideCondition::Interface`] sides ask
//! for. Free: every control point that is not on the outer boundary (a Dirichlet side)
//! and not a corner where three or more patches meet; the interior control points of
//! the interfaces are free, so the interfaces move.

use super::layout::Layout;
use crate::discrete::dofs::FIXED;
use crate::discrete::topology::{SideCondition, Topology};
use crate::error::Result;
use crate::spline::curve::Point;
use crate::spline::surface::{Side, Surface};

/// The global free / fixed / shared split of the control points of all patches.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GlobalDofs {
    /// Basis shape `[n_xi, n_eta]` per patch.
    pub shapes: Vec<[usize; 2]>,
    /// Per patch: the global free index of each control point, or [`FIXED`].
    pub free_of: Vec<Vec<usize>>,
    /// Per free index: every `(patch, k)` that is this control point (one, or two and
    /// more on interfaces).
    pub copies: Vec<Vec<(usize, usize)>>,
    /// Number of distinct control points of the layout (free and fixed).
    pub distinct: usize,
    /// Corners where three or more patches meet (kept fixed).
    pub fixed_vertices: usize,
}

impl GlobalDofs {
    /// The numbering for patches of basis shapes `shapes` with boundary conditions
    /// `topologies` (Dirichlet and interface sides; see the module documentation).
    /// Errors when the two sides of an interface have different numbers of control
    /// points (the patches are not conforming), naming the patch and side.
    pub fn new(layout: &Layout, shapes: &[[usize; 2]], topologies: &[Topology]) -> Result<Self> {
        let offsets: Vec<usize> = shapes
            .iter()
            .scan(0, |acc, s| {
                let o = *acc;
                *acc += s[0] * s[1];
                Some(o)
            })
            .collect();
        let total: usize = shapes.iter().map(|s| s[0] * s[1]).sum();
        let mut parent: Vec<usize> = (0..total).collect();
        let mut outer = vec![false; total];
        for (p, t) in topologies.iter().enumerate() {
            for s in Side::ALL {
                let idx = Surface::side_indices(shapes[p], s);
                match t.side(s) {
                    SideCondition::Dirichlet => idx.iter().for_each(|&k| outer[offsets[p] + k] = true),
                    SideCondition::Interface { patch: q, side: t, reversed } => {
                        let other = Surface::side_indices(shapes[q], t);
                        if other.len() != idx.len() {
                            return Err(layout.error(
                                p,
                                Some(s),
                                format!(
                                    "has {} control points, the {t} side of patch {} across the interface has {}: the patches are not conforming",
                                    idx.len(),
                                    layout.label(q),
                                    other.len()
                                ),
                            ));
                        }
                        let n = idx.len();
                        for (i, &k) in idx.iter().enumerate() {
                            let kk = other[if reversed { n - 1 - i } else { i }];
                            let (a, b) = (find(&mut parent, offsets[p] + k), find(&mut parent, offsets[q] + kk));
                            parent[b] = a;
                        }
                    }
                    SideCondition::Periodic => {
                        return Err(layout.error(p, Some(s), "periodic sides are not part of a multipatch layout"));
                    }
                }
            }
        }
        // per group: outer?, patches meeting at a corner
        let mut group_outer = vec![false; total];
        let mut corner_patches: Vec<Vec<usize>> = vec![Vec::new(); total];
        for (p, &[nx, ny]) in shapes.iter().enumerate() {
            for k in 0..nx * ny {
                let r = find(&mut parent, offsets[p] + k);
                group_outer[r] |= outer[offsets[p] + k];
                let (i, j) = (k % nx, k / nx);
                if (i == 0 || i + 1 == nx) && (j == 0 || j + 1 == ny) && !corner_patches[r].contains(&p) {
                    corner_patches[r].push(p);
                }
            }
        }
        let mut number = vec![usize::MAX; total];
        let mut free_of = Vec::with_capacity(shapes.len());
        let mut copies: Vec<Vec<(usize, usize)>> = Vec::new();
        let mut distinct = 0;
        let mut seen = vec![false; total];
        let mut fixed_vertices = 0;
        for (p, &[nx, ny]) in shapes.iter().enumerate() {
            let mut f = vec![FIXED; nx * ny];
            for (k, fk) in f.iter_mut().enumerate() {
                let r = find(&mut parent, offsets[p] + k);
                if !seen[r] {
                    seen[r] = true;
                    distinct += 1;
                    let vertex = corner_patches[r].len() >= 3;
                    fixed_vertices += usize::from(vertex && !group_outer[r]);
                    if !group_outer[r] && !vertex {
                        number[r] = copies.len();
                        copies.push(Vec::new());
                    }
                }
                if number[r] != usize::MAX {
                    *fk = number[r];
                    copies[number[r]].push((p, k));
                }
            }
            free_of.push(f);
        }
        Ok(Self { shapes: shapes.to_vec(), free_of, copies, distinct, fixed_vertices })
    }

    /// Number of free (global) control points `m`; the unknowns are `2 m`.
    pub fn num_free(&self) -> usize {
        self.copies.len()
    }

    /// The unknowns `c = (c^x, c^y)` from the patches' control points (first copy).
    pub fn gather(&self, cps: &[Vec<Point>]) -> Vec<f64> {
        let m = self.num_free();
        let mut c = vec![0.0; 2 * m];
        for (f, cp) in self.copies.iter().enumerate() {
            let (p, k) = cp[0];
            c[f] = cps[p][k][0];
            c[m + f] = cps[p][k][1];
        }
        c
    }

    /// Write the unknowns into every copy of every free control point.
    pub fn scatter(&self, c: &[f64], cps: &mut [Vec<Point>]) {
        let m = self.num_free();
        for (f, cp) in self.copies.iter().enumerate() {
            for &(p, k) in cp {
                cps[p][k] = [c[f], c[m + f]];
            }
        }
    }
}

/// The root of `x` in the union-find forest `parent` (`parent[r] == r` at a root), with
/// the path from `x` compressed onto it.
pub(crate) fn find(parent: &mut [usize], x: usize) -> usize {
    let mut r = x;
    while parent[r] != r {
        r = parent[r];
    }
    let mut y = x;
    while parent[y] != r {
        let next = parent[y];
        parent[y] = r;
        y = next;
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::multipatch::layout::{Interface, Patch, PatchSide};
    use crate::spline::curve::Curve;
    use crate::spline::knots::KnotVector;

    fn line(a: Point, b: Point) -> Curve {
        Curve::new(KnotVector::open_uniform(1, 1), vec![a, b], None).unwrap()
    }

    fn square(x: f64, y: f64) -> Patch {
        Patch::from_sides(
            format!("{x},{y}"),
            [
                line([x, y], [x + 1.0, y]),
                line([x + 1.0, y], [x + 1.0, y + 1.0]),
                line([x, y + 1.0], [x + 1.0, y + 1.0]),
                line([x, y], [x, y + 1.0]),
            ],
        )
    }

    fn iface(a: usize, sa: Side, b: usize, sb: Side) -> Interface {
        Interface { first: PatchSide { patch: a, side: sa }, second: PatchSide { patch: b, side: sb }, reversed: false }
    }

    /// A 2x2 grid of 4x4 control nets: the interfaces share their control points, the
    /// centre (four patches) stays fixed, the outer boundary is fixed.
    #[test]
    fn a_2x2_grid_shares_interfaces() {
        let layout = Layout {
            name: "2x2".into(),
            patches: vec![square(0.0, 0.0), square(1.0, 0.0), square(0.0, 1.0), square(1.0, 1.0)],
            interfaces: vec![
                iface(0, Side::East, 1, Side::West),
                iface(0, Side::North, 2, Side::South),
                iface(1, Side::North, 3, Side::South),
                iface(2, Side::East, 3, Side::West),
            ],
        };
        let shapes = vec![[4, 4]; 4];
        let d = GlobalDofs::new(&layout, &shapes, &layout.topologies()).unwrap();
        // distinct points: a 7x7 net
        assert_eq!(d.distinct, 49);
        // free: the 5x5 interior minus the centre
        assert_eq!(d.num_free(), 24);
        assert_eq!(d.fixed_vertices, 1);
        // patch 0's east interior points are patch 1's west ones
        for j in 1..3 {
            assert_eq!(d.free_of[0][j * 4 + 3], d.free_of[1][j * 4]);
            assert_ne!(d.free_of[0][j * 4 + 3], FIXED);
        }
        // the centre is fixed in all four
        assert_eq!(d.free_of[0][15], FIXED);
        assert_eq!(d.free_of[3][0], FIXED);
        let mut cps: Vec<Vec<Point>> = vec![vec![[0.0; 2]; 16]; 4];
        let c: Vec<f64> = (0..48).map(|k| k as f64).collect();
        d.scatter(&c, &mut cps);
        assert_eq!(cps[0][7], cps[1][4]);
        assert_eq!(d.gather(&cps), c);
        // a shape mismatch across an interface is an error naming the side
        let e = GlobalDofs::new(&layout, &[[4, 4], [4, 5], [4, 4], [4, 5]], &layout.topologies()).unwrap_err();
        assert!(e.to_string().contains("not conforming"), "{e}");
    }
}
