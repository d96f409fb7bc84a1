//! THB maps of the plane, `x(ξ, η) = Σ_β c_β Trunc β(ξ, η)` (paper §4: the map in a
//! (truncated) hierarchical basis).
//!
//! On an active cell `Q` of level `l` the map is the polynomial `Σ_τ d^l_τ τ` of its local
//! net (`truncation`); everything here is read off that net by blossoming
//! (`blossom`): the Bézier net of the cell (the blossom at `(a^{p-k}, b^k)`), the
//! coefficients after a refinement (the blossom of the old piece at the new function's
//! interior knots, exact since the old map lies in the refined space) and the tensor map
//! on the knot lines of all active cells (knot insertion, exact: the THB space is a
//! subspace of that tensor space).

use std::collections::BTreeSet;

use super::truncation::{blossom, LevelCoefficients};
use super::{HierarchicalBasis, Index2};
use crate::error::{Error, Result};
use crate::spline::basis::BasisDerivs;
use crate::spline::curve::{check_points, Point};
use crate::spline::knots::KnotVector;
use crate::spline::surface::{Surface, SurfaceDerivs};

/// A THB map: basis and one control point per active function.
#[derive(Debug, Clone)]
pub struct HierarchicalMap {
    /// The basis.
    pub basis: HierarchicalBasis,
    /// Control points in the order of `HierarchicalBasis::active_functions`.
    pub control_points: Vec<Point>,
}

/// The local knots `t_{s-p}, ..., t_{s+p+1}` of span `s`.
fn local_knots(kv: &KnotVector, s: usize) -> &[f64] {
    let p = kv.degree();
    &kv.knots()[s - p..=s + p + 1]
}

/// The blossom of a cell's polynomial (local net `net`, `xi` fastest, local knots `tx`,
/// `ty`) at the arguments `ax` (`p` values), `ay` (`q` values).
fn blossom2(net: &[Point], tx: &[f64], ty: &[f64], ax: &[f64], ay: &[f64]) -> Point {
    let p1 = ax.len() + 1;
    let rows: Vec<Point> = net.chunks_exact(p1).map(|row| blossom(tx, row, ax)).collect();
    blossom(ty, &rows, ay)
}

/// The Bernstein arguments `(a^{p-k}, b^k)`.
fn bernstein_args(p: usize, k: usize, a: f64, b: f64) -> Vec<f64> {
    (0..p).map(|r| if r < p - k { a } else { b }).collect()
}

impl HierarchicalMap {
    /// A map from a basis and its control points (one per active function, finite).
    pub fn new(basis: HierarchicalBasis, control_points: Vec<Point>) -> Result<Self> {
        if control_points.len() != basis.len() {
            return Err(Error::Length {
                context: "hierarchical map".into(),
                what: "control_points".into(),
                found: control_points.len(),
                expected: basis.len(),
            });
        }
        check_points(&control_points, "control point")?;
        Ok(Self { basis, control_points })
    }

    /// The tensor map as a one-level THB map (polynomial maps only).
    pub fn from_surface(map: &Surface) -> Result<Self> {
        if map.weights.is_some() {
            return Err(Error::Invalid("a THB map is polynomial: rational (NURBS) maps are not supported".into()));
        }
        let basis = HierarchicalBasis::new(map.knots.clone())?;
        Self::new(basis, map.control_points.clone())
    }

    /// The control net of the map: for every level `l`, the segments between the control
    /// points of the active functions `(l, [i, j])` and `(l, [i + 1, j])`, or `(l, [i, j])`
    /// and `(l, [i, j + 1])`, when both are active (the level's tensor control net
    /// restricted to its active functions; on a one-level map the tensor net), as pairs of
    /// indices into `control_points`, by level, then `eta`, then `xi` (the `xi` segment of
    /// a function before its `eta` segment).
    pub fn control_net(&self) -> Vec<[usize; 2]> {
        let b = &self.basis;
        let mut out = Vec::new();
        for (k, &(l, [i, j])) in b.active_functions().iter().enumerate() {
            for next in [[i + 1, j], [i, j + 1]] {
                if let Some(n) = b.index_of(l, next) {
                    out.push([k, n]);
                }
            }
        }
        out
    }

    /// The level coefficients of the map (see `truncation`).
    pub(crate) fn level_coefficients(&self) -> LevelCoefficients<'_, Point> {
        LevelCoefficients::new(&self.basis, |k| self.control_points[k])
    }

    /// Value, gradient and Hessian at `(u, v)` (from the active cell containing the point).
    pub fn derivs(&self, u: f64, v: f64) -> SurfaceDerivs {
        let (l, c) = self.basis.cell_at(u, v);
        let net = self.level_coefficients().cell_net(l, c);
        let spans = self.basis.cell_spans(l, c);
        let kv = self.basis.knots(l);
        let mut bu = BasisDerivs::default();
        let mut bv = BasisDerivs::default();
        bu.eval_in_span(&kv[0], spans[0], u, 2);
        bv.eval_in_span(&kv[1], spans[1], v, 2);
        let p1 = self.basis.degrees()[0] + 1;
        let mut out = SurfaceDerivs::default();
        for (k, x) in net.iter().enumerate() {
            let (i, j) = (k % p1, k / p1);
            for z in 0..2 {
                out.x[z] += bu.d[0][i] * bv.d[0][j] * x[z];
                out.xu[z] += bu.d[1][i] * bv.d[0][j] * x[z];
                out.xv[z] += bu.d[0][i] * bv.d[1][j] * x[z];
                out.xuu[z] += bu.d[2][i] * bv.d[0][j] * x[z];
                out.xuv[z] += bu.d[1][i] * bv.d[1][j] * x[z];
                out.xvv[z] += bu.d[0][i] * bv.d[2][j] * x[z];
            }
        }
        out
    }

    /// The point `x(u, v)`.
    pub fn eval(&self, u: f64, v: f64) -> Point {
        self.derivs(u, v).x
    }

    /// The Bézier patch of every active cell, `(level, cell, patch)`: a one-element tensor
    /// map on the cell's parameter box equal to the THB map there (element extraction).
    pub(crate) fn bezier_patches(&self) -> Result<Vec<(usize, Index2, Surface)>> {
        let mut lc = self.level_coefficients();
        self.basis.active_cells().into_iter().map(|(l, c)| Ok((l, c, self.bezier_patch(&mut lc, l, c)?))).collect()
    }

    /// The Bézier patch of the active cell `c` of level `l`.
    pub(crate) fn bezier_patch(&self, lc: &mut LevelCoefficients<'_, Point>, l: usize, c: Index2) -> Result<Surface> {
        let [p, q] = self.basis.degrees();
        let net = lc.cell_net(l, c);
        let spans = self.basis.cell_spans(l, c);
        let kv = self.basis.knots(l);
        let (tx, ty) = (local_knots(&kv[0], spans[0]), local_knots(&kv[1], spans[1]));
        let [[a, b], [cc, dd]] = self.basis.cell_bounds(l, c);
        let mut cps = Vec::with_capacity((p + 1) * (q + 1));
        for ky in 0..=q {
            let ay = bernstein_args(q, ky, cc, dd);
            for kx in 0..=p {
                cps.push(blossom2(&net, tx, ty, &bernstein_args(p, kx, a, b), &ay));
            }
        }
        let bez = |p: usize, a: f64, b: f64| {
            let mut t = vec![a; p + 1];
            t.extend(std::iter::repeat_n(b, p + 1));
            KnotVector::new(p, t)
        };
        Surface::new([bez(p, a, b)?, bez(q, cc, dd)?], cps, None)
    }

    /// The map after refining the active cells `marked` with admissibility class `m`
    /// ([`HierarchicalBasis::refine`]): the same function in the finer THB space, every new
    /// function's coefficient the blossom of the old map's piece on an active cell of its
    /// level inside its support (the functions active before keep theirs).
    pub fn refined(&self, marked: &[(usize, Index2)], m: usize) -> Result<Self> {
        let mut basis = self.basis.clone();
        basis.refine(marked, m)?;
        self.blossomed(basis, true)
    }

    /// This map in the THB space of `basis` (a hierarchy of the same degrees on the same
    /// domain, any level-0 knots) by the blossom quasi-interpolant: the coefficient of an
    /// active function `(l, f)` is the blossom, at `f`'s interior knots, of this map's
    /// polynomial piece at a point of an active level-`l` cell `Q` in `supp f` (the
    /// centre of `Q`; in a direction where `f` is the first or last function, the
    /// domain's end: there `Q` touches the boundary). When this map lies in the THB
    /// space it is reproduced (the coefficient of an active function is the level-`l`
    /// coefficient of the piece on any active level-`l` cell of its support, `truncation`).
    /// The functions non-zero on a side are the 1D THB functions of the side's row of
    /// cells, and their coefficients read only this map's boundary curve: the THB map's
    /// boundary is this map's when the curve is one polynomial on each active cell along
    /// the side and lies in the side's 1D THB space (checked by the caller, e.g. through
    /// [`Self::to_surface`]).
    pub fn quasi_interpolant(&self, basis: HierarchicalBasis) -> Result<Self> {
        if basis.degrees() != self.basis.degrees()
            || (0..2).any(|d| basis.knots(0)[d].domain() != self.basis.knots(0)[d].domain())
        {
            return Err(Error::Invalid(
                "a THB quasi-interpolant needs a basis of the same degrees on the same domain".into(),
            ));
        }
        self.blossomed(basis, false)
    }

    /// The coefficients on `basis` by blossoming (see [`Self::quasi_interpolant`]);
    /// with `keep`, `basis` refines `self.basis` and the functions active in both keep
    /// their coefficients (the blossom of the same piece, both times), the new ones are
    /// blossomed at the centre of their cell.
    fn blossomed(&self, basis: HierarchicalBasis, keep: bool) -> Result<Self> {
        let mut old = self.level_coefficients();
        let mut cps = Vec::with_capacity(basis.len());
        for &(l, f) in basis.active_functions() {
            if let Some(k) = self.basis.index_of(l, f).filter(|_| keep) {
                cps.push(self.control_points[k]);
                continue;
            }
            let [ri, rj] = basis.support(l, f);
            let cell = rj
                .flat_map(|j| ri.clone().map(move |i| [i, j]))
                .find(|&c| basis.is_active_cell(l, c))
                .ok_or_else(|| Error::Invalid(format!("active function {f:?} of level {l} has no active cell")))?;
            let bounds = basis.cell_bounds(l, cell);
            let kv = basis.knots(l);
            let at: [f64; 2] = std::array::from_fn(|d| {
                let [a, b] = bounds[d];
                match f[d] {
                    0 if !keep => a,
                    i if !keep && i + 1 == kv[d].num_basis() => b,
                    _ => 0.5 * (a + b),
                }
            });
            cps.push(self.piece_blossom(&mut old, at, kv, f));
        }
        Self::new(basis, cps)
    }

    /// The blossom of this map's piece at the point `at` (inside an active cell) at the
    /// interior knots of function `f` of the tensor space `kv`.
    fn piece_blossom(
        &self,
        lc: &mut LevelCoefficients<'_, Point>,
        at: [f64; 2],
        kv: &[KnotVector; 2],
        f: Index2,
    ) -> Point {
        let (lo, co) = self.basis.cell_at(at[0], at[1]);
        let net = lc.cell_net(lo, co);
        let spans = self.basis.cell_spans(lo, co);
        let okv = self.basis.knots(lo);
        let args: [&[f64]; 2] = std::array::from_fn(|d| {
            let p = kv[d].degree();
            &kv[d].knots()[f[d] + 1..=f[d] + p]
        });
        blossom2(&net, local_knots(&okv[0], spans[0]), local_knots(&okv[1], spans[1]), args[0], args[1])
    }

    /// The knot vectors of the coarsest tensor space containing this THB space: the
    /// level-0 knots and, once each, every edge of an active cell of a finer level.
    pub(crate) fn tensor_knots(&self) -> Result<[KnotVector; 2]> {
        let mut edges: [BTreeSet<u64>; 2] = [BTreeSet::new(), BTreeSet::new()];
        for (l, c) in self.basis.active_cells() {
            if l == 0 {
                continue;
            }
            let bounds = self.basis.cell_bounds(l, c);
            for d in 0..2 {
                edges[d].extend(bounds[d].iter().map(|x| x.to_bits()));
            }
        }
        let k0 = self.basis.knots(0);
        let out: Vec<KnotVector> = (0..2)
            .map(|d| {
                let old = &k0[d];
                let new: Vec<f64> =
                    edges[d].iter().map(|&b| f64::from_bits(b)).filter(|&x| old.multiplicity(x) == 0).collect();
                old.with_inserted(&new)
            })
            .collect();
        Ok([out[0].clone(), out[1].clone()])
    }

    /// The same map as a tensor-product map on `Self::tensor_knots` (exact: every
    /// coefficient is the blossom of the piece on an element of its support).
    pub fn to_surface(&self) -> Result<Surface> {
        let kv = self.tensor_knots()?;
        let n = kv.each_ref().map(KnotVector::num_basis);
        let mut lc = self.level_coefficients();
        let mut cps = Vec::with_capacity(n[0] * n[1]);
        // a point inside the first non-empty span of each function's support
        let inside = |kv: &KnotVector, i: usize| {
            let t = kv.knots();
            let s = (i..=i + kv.degree()).find(|&s| t[s + 1] > t[s]).unwrap_or(i);
            0.5 * (t[s] + t[s + 1])
        };
        let ys: Vec<f64> = (0..n[1]).map(|j| inside(&kv[1], j)).collect();
        let xs: Vec<f64> = (0..n[0]).map(|i| inside(&kv[0], i)).collect();
        for (j, &y) in ys.iter().enumerate() {
            for (i, &x) in xs.iter().enumerate() {
                cps.push(self.piece_blossom(&mut lc, [x, y], &kv, [i, j]));
            }
        }
        Surface::new(kv, cps, None)
    }
}
