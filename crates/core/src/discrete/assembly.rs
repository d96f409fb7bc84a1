//! Assembly of the Galerkin systems on a tensor-product basis: the EGG residual of
//! paper eq. (8) with its exact Jacobian, the scaled variant `L / (g11 + g22)`, the mass
//! matrix of eq. (30) and linear elasticity (§6.3).
//!
//! Symbolic work is done once per basis ([`Discretization::new`]): univariate basis
//! tables at the Gauss points, the free/fixed [`DofMap`], and the fixed sparsity pattern
//! of the free-free system with a gather map from a dense *stencil* storage. Numeric work
//! per Newton step writes element contributions straight into the stencil storage
//! (entry `(k, k + di + n_xi dj)` at a computed offset, no search, no allocation per
//! quadrature point) and gathers them into the CSR values. Element rows are processed in
//! `q + 1` colours so that rows of one colour touch disjoint basis rows and run in
//! parallel without atomics.

use rayon::prelude::*;

use crate::discrete::dofs::{DofMap, FIXED};
use crate::discrete::pattern::stencil_neighbours;
pub use crate::discrete::pattern::{LazyPattern, SystemPattern};
use crate::discrete::tables::DirTable;
use crate::discrete::topology::Topology;
use crate::error::Result;
pub(crate) use crate::linalg::dense::element_product;
use crate::spline::knots::KnotVector;

/// One element row of [`Discretization::assemble`] with its chunks of the residual and
/// of the stencil storage.
type RowChunks<'a> = ((usize, Option<&'a mut [f64]>), Option<&'a mut [f64]>);

/// Quadrature points below which the assembly of a basis runs on the calling thread: waking
/// the rayon pool for each of its `q + 1` colours costs more than the work below it.
pub(crate) const SERIAL_ASSEMBLY_POINTS: usize = 4096;

/// Quadrature points below which `Discretization::tensor_basis_first` reads the
/// first-order basis values from a table made on first use (`24 nloc` bytes a point: at
/// most 1.5 MB for p = 3) instead of forming them at every pass: on such bases the
/// products and, on a NURBS basis, the quotient rule are a sizeable part of a pass (the
/// Winslow stage on disk 1.44 -> 1.20 ms, BENCHMARKS.md).
pub(crate) const FIRST_ORDER_TABLE_POINTS: usize = 4096;

/// Everything computed once per basis: tables, DOF map, patterns.
#[derive(Debug, Clone)]
pub struct Discretization {
    /// Knot vectors in `xi`, `eta`.
    pub knots: [KnotVector; 2],
    /// Basis tables per direction.
    pub tables: [DirTable; 2],
    /// Free versus fixed DOFs.
    pub dofs: DofMap,
    /// Pattern of the 2-component systems (EGG Jacobian, elasticity, block mass), built
    /// on first use.
    pub vector: LazyPattern,
    /// Pattern of scalar systems (mass, Laplacian), built on first use (a solve by
    /// `--linear multigrid` on a patch takes `K` and the elasticity blocks straight from
    /// their stencil storage and never builds it).
    pub scalar: LazyPattern,
    /// Fill-reducing (nested-dissection) order of the free scalar unknowns for sparse
    /// Cholesky factorizations, `ordering[new] = old`; see [`crate::linalg::ordering`].
    pub ordering: Vec<usize>,
    /// Weights `w_b` of a rational (NURBS) basis `R_b = w_b N_b / W`, `W = sum w_b N_b`,
    /// in control-net order, or `None` for the polynomial B-spline basis; see
    /// [`Discretization::with_weights`].
    pub weights: Option<Vec<f64>>,
    /// `(w, w_u, w_v)` of every function at every quadrature point, element by element,
    /// for [`Discretization::tensor_basis_first`] on a basis of fewer than
    /// [`FIRST_ORDER_TABLE_POINTS`] points (computed on first use: the first-order forms
    /// of eq. 14 and 16 then copy what they would recompute at every pass).
    pub(crate) first_order: std::sync::OnceLock<Vec<[f64; 3]>>,
}

/// Which operator [`Discretization::egg`] discretizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Operator {
    /// `L(x, y, .)` of eq. (4), as in eq. (8).
    #[default]
    Plain,
    /// `L(x, y, .) / (g11 + g22)`, the scaling G+Smo uses.
    Scaled,
}

/// Geometry of the map at one quadrature point.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Geo {
    pub(crate) xu: [f64; 2],
    pub(crate) xv: [f64; 2],
    pub(crate) xuu: [f64; 2],
    pub(crate) xuv: [f64; 2],
    pub(crate) xvv: [f64; 2],
}

impl Geo {
    /// The metric terms `(g11, g12, g22)`: `g11 = x_xi.x_xi`, `g12 = x_xi.x_eta`,
    /// `g22 = x_eta.x_eta`.
    pub(crate) fn metric(&self) -> (f64, f64, f64) {
        let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
        (dot(self.xu, self.xu), dot(self.xu, self.xv), dot(self.xv, self.xv))
    }
}

/// The test-weight row and the trial-derivative rows of one quadrature point in the
/// element-matrix operands of [`egg_point`].
pub(crate) struct EggRows<'a> {
    /// `w_k w_a / s` of the point (length `nloc`).
    pub(crate) wa: &'a mut [f64],
    /// `dL_z/dc^d_b` at `((z * 2 + d) * nqp + k) * nloc + b`.
    pub(crate) tz: &'a mut [f64],
    /// The point.
    pub(crate) k: usize,
    /// Points per element.
    pub(crate) nqp: usize,
}

/// The EGG integrand (eq. 8) at one quadrature point of weight `wq`, with the `nloc`
/// basis functions' `(w, w_u, w_v, w_uu, w_uv, w_vv)` in `b` and the map's derivatives
/// in `g`: adds `wq w_a L(z) / s` to `re[z * nloc + a]` and, with `rows`, writes the
/// operands of the Jacobian's element product (see [`Discretization::egg`] for the
/// formulas). Shared by the tensor assembly and the THB assembly
/// ([`crate::discrete::hierarchical`]).
#[inline]
pub(crate) fn egg_point(b: &[[f64; 6]], g: &Geo, wq: f64, op: Operator, re: &mut [f64], rows: Option<EggRows<'_>>) {
    let nloc = b.len();
    let (g11, g12, g22) = g.metric();
    let l = [
        g22 * g.xuu[0] - 2.0 * g12 * g.xuv[0] + g11 * g.xvv[0],
        g22 * g.xuu[1] - 2.0 * g12 * g.xuv[1] + g11 * g.xvv[1],
    ];
    let (scale, sden) = match op {
        Operator::Plain => (1.0, 0.0),
        Operator::Scaled => {
            let sd = g11 + g22;
            (1.0 / sd, sd)
        }
    };
    for a in 0..nloc {
        let wa = wq * b[a][0] * scale;
        re[a] += wa * l[0];
        re[nloc + a] += wa * l[1];
    }
    let Some(EggRows { wa, tz, k, nqp }) = rows else { return };
    // quotient-rule factor L(z) / s, once per point (no division per entry)
    let ls = if op == Operator::Scaled { [l[0] / sden, l[1] / sden] } else { [0.0; 2] };
    for (a, w) in wa.iter_mut().enumerate() {
        *w = wq * b[a][0] * scale;
    }
    for (bi, wb) in b.iter().enumerate() {
        let lw = g22 * wb[3] - 2.0 * g12 * wb[4] + g11 * wb[5];
        for d in 0..2 {
            let dg11 = 2.0 * g.xu[d] * wb[1];
            let dg12 = g.xu[d] * wb[2] + g.xv[d] * wb[1];
            let dg22 = 2.0 * g.xv[d] * wb[2];
            let ds = 2.0 * (g.xu[d] * wb[1] + g.xv[d] * wb[2]);
            for z in 0..2 {
                let mut v = dg22 * g.xuu[z] - 2.0 * dg12 * g.xuv[z] + dg11 * g.xvv[z];
                if z == d {
                    v += lw;
                }
                v -= ls[z] * ds;
                tz[((z * 2 + d) * nqp + k) * nloc + bi] = v;
            }
        }
    }
}

/// Scratch of one element: tensor basis values and element vector/matrix.
pub(crate) struct Scratch {
    pub(crate) nloc: usize,
    /// `b[k][a]` for k in (w, w_u, w_v, w_uu, w_uv, w_vv).
    pub(crate) b: Vec<[f64; 6]>,
    /// Per trial function: physical gradients (elasticity).
    pub(crate) t: Vec<[f64; 4]>,
    /// `dL_z/dc^d_b` at quadrature point `k` at `((z * 2 + d) * nqp + k) * nloc + b`:
    /// contiguous in `b` for the element-matrix product.
    pub(crate) tz: Vec<f64>,
    /// Test-function weights `w_k w_a(k) / s(k)` at `k * nloc + a`.
    pub(crate) wa: Vec<f64>,
    pub(crate) re: Vec<f64>,
    pub(crate) ke: Vec<f64>,
}

impl Scratch {
    /// Size the operands of [`element_product`] (`wa` and `tz`): allocated on a thread's
    /// first element, reused by the others.
    pub(crate) fn reserve_products(&mut self, wa: usize, tz: usize) {
        if self.wa.len() != wa || self.tz.len() != tz {
            self.wa = vec![0.0; wa];
            self.tz = vec![0.0; tz];
        }
    }

    pub(crate) fn new(p: usize, q: usize, ncomp: usize) -> Self {
        let nloc = (p + 1) * (q + 1);
        Self {
            nloc,
            b: vec![[0.0; 6]; nloc],
            t: vec![[0.0; 4]; nloc],
            tz: Vec::new(),
            wa: Vec::new(),
            re: vec![0.0; ncomp * nloc],
            ke: vec![0.0; ncomp * ncomp * nloc * nloc],
        }
    }
}

/// Split `data` into the disjoint mutable chunks `[lo, hi)` (sorted, non-overlapping).
fn split_ranges<'a>(mut data: &'a mut [f64], ranges: &[(usize, usize)]) -> Vec<&'a mut [f64]> {
    let mut out = Vec::with_capacity(ranges.len());
    let mut offset = 0;
    for &(lo, hi) in ranges {
        let rest = std::mem::take(&mut data);
        let (_, tail) = rest.split_at_mut(lo - offset);
        let (chunk, tail) = tail.split_at_mut(hi - lo);
        out.push(chunk);
        data = tail;
        offset = hi;
    }
    out
}

impl Discretization {
    /// Tables and patterns for the tensor basis `knots`, with `nq` Gauss points per
    /// element and direction, and the given DOF map.
    pub fn with_dofs(knots: [KnotVector; 2], nq: usize, dofs: DofMap) -> Self {
        let tables = [DirTable::new(&knots[0], nq), DirTable::new(&knots[1], nq)];
        Self::with_tables(knots, tables, dofs)
    }

    /// As [`Discretization::with_dofs`] with `nq` Gauss-Lobatto points per element and
    /// direction: the integrals (the Winslow functional, eq. 16) then sample the element
    /// edges, where a map only `C^0` across a knot line has its one-sided limits.
    pub fn with_dofs_lobatto(knots: [KnotVector; 2], nq: usize, dofs: DofMap) -> Self {
        let tables = [DirTable::lobatto(&knots[0], nq), DirTable::lobatto(&knots[1], nq)];
        Self::with_tables(knots, tables, dofs)
    }

    fn with_tables(knots: [KnotVector; 2], tables: [DirTable; 2], dofs: DofMap) -> Self {
        let (p, q) = (knots[0].degree(), knots[1].degree());
        let vector = LazyPattern::new(&dofs, p, q, 2);
        let scalar = LazyPattern::new(&dofs, p, q, 1);
        let nx = dofs.shape()[0];
        let nodes: Vec<[usize; 2]> = dofs.free().iter().map(|&k| [k % nx, k / nx]).collect();
        let ordering = crate::linalg::ordering::nested_dissection(&nodes, [p, q]);
        Self { knots, tables, dofs, vector, scalar, ordering, weights: None, first_order: Default::default() }
    }

    /// The rational basis `R_b = w_b N_b / W` with `W = sum_b w_b N_b` (NURBS, §5.2) on
    /// the same knots, DOF map and patterns: every kernel (EGG eq. 8, mass, elasticity,
    /// the Winslow functional and the weak form) then discretizes in it, trial and test
    /// functions alike, through `Discretization::tensor_basis`. `None`, or weights all
    /// equal to one, give the polynomial basis back. Weights must be finite and positive.
    pub fn with_weights(mut self, weights: Option<Vec<f64>>) -> Result<Self> {
        let weights = weights.filter(|w| w.iter().any(|&x| x != 1.0));
        if let Some(w) = &weights {
            if w.len() != self.dofs.num_total() {
                return Err(crate::error::Error::Invalid(format!(
                    "{} weights for a basis of {} functions",
                    w.len(),
                    self.dofs.num_total()
                )));
            }
            if let Some((k, x)) = w.iter().enumerate().find(|(_, x)| !(x.is_finite() && **x > 0.0)) {
                return Err(crate::error::Error::Invalid(format!(
                    "weight {k} of the rational basis is {x}: weights must be finite and positive"
                )));
            }
        }
        self.weights = weights;
        self.first_order = Default::default();
        Ok(self)
    }

    /// Whether the basis is rational.
    pub fn is_rational(&self) -> bool {
        self.weights.is_some()
    }

    /// Interior DOFs free, `max(p, q) + 1` Gauss points per direction: exact for the mass
    /// matrix (degree `2p`, the rule is exact to `2p + 1`) and the parametric Laplacian,
    /// and of order `2p + 2` for the non-polynomial EGG integrand (`p + 2` points cost 56 %
    /// more; on the quarter annulus at 132 k unknowns the two rules give control points
    /// within 4e-12 of each other).
    pub fn new(knots: [KnotVector; 2]) -> Self {
        let nq = knots[0].degree().max(knots[1].degree()) + 1;
        let dofs = DofMap::interior([knots[0].num_basis(), knots[1].num_basis()]);
        Self::with_dofs(knots, nq, dofs)
    }

    /// [`Self::new`] with the free / fixed / shared split of `topology` on this basis
    /// ([`DofMap::for_basis`]: a periodic knot vector goes with periodic sides).
    pub fn for_topology(knots: [KnotVector; 2], topology: &Topology) -> Result<Self> {
        let nq = knots[0].degree().max(knots[1].degree()) + 1;
        let dofs = DofMap::for_basis(&knots, topology)?;
        Ok(Self::with_dofs(knots, nq, dofs))
    }

    /// Basis shape.
    pub fn shape(&self) -> [usize; 2] {
        self.dofs.shape()
    }

    /// Degrees `(p, q)`.
    pub fn degrees(&self) -> (usize, usize) {
        (self.tables[0].p, self.tables[1].p)
    }

    /// Number of elements.
    pub fn num_elements(&self) -> usize {
        self.tables[0].num_elements() * self.tables[1].num_elements()
    }

    pub(crate) fn stencil_width(&self) -> usize {
        let (p, q) = self.degrees();
        (2 * p + 1) * (2 * q + 1)
    }

    /// Length of the stencil storage of an `ncomp`-component system.
    pub fn stencil_len(&self, ncomp: usize) -> usize {
        self.dofs.num_total() * ncomp * ncomp * self.stencil_width()
    }

    /// Run `kernel(ex, ey, scratch)` on every element and scatter the element vectors
    /// (`re`, `ncomp` per function) and matrices (`ke`) into full-size `res` (length
    /// `n * ncomp`, may be empty) and stencil storage `stencil` (may be empty). Element
    /// rows run in parallel, in `q + 1` colours.
    pub(crate) fn assemble<K>(&self, ncomp: usize, res: &mut [f64], stencil: &mut [f64], kernel: K)
    where
        K: Fn(usize, usize, &mut Scratch) + Sync,
    {
        self.assemble_band(ncomp, 0..self.tables[1].num_elements(), res, stencil, &kernel);
    }

    /// [`Discretization::assemble`] over the element rows `band`, into `res` and `stencil`
    /// from the band's first function row on; each entry summed in the whole assembly's
    /// order (by colour): a row whose elements are all in the band gets the same bits.
    pub(crate) fn assemble_band<K>(
        &self,
        ncomp: usize,
        band: std::ops::Range<usize>,
        res: &mut [f64],
        stencil: &mut [f64],
        kernel: &K,
    ) where
        K: Fn(usize, usize, &mut Scratch) + Sync,
    {
        let (p, q) = self.degrees();
        let nx = self.shape()[0];
        let sw = self.stencil_width();
        let row_len = ncomp * ncomp * sw;
        let (tx, ty) = (&self.tables[0], &self.tables[1]);
        let want_res = !res.is_empty();
        let want_mat = !stencil.is_empty();
        res.fill(0.0);
        stencil.fill(0.0);
        // one thread for small bases, where waking the pool costs more than it saves
        let serial = band.len() * tx.num_elements() * tx.nq * ty.nq < SERIAL_ASSEMBLY_POINTS;
        let mut scratch = None;
        let row0 = ty.first.get(band.start).copied().unwrap_or(0);
        for color in 0..=q {
            let rows: Vec<usize> = band.clone().filter(|ey| ey % (q + 1) == color).collect();
            let ranges = |w: usize| -> Vec<(usize, usize)> {
                rows.iter()
                    .map(|&ey| ((ty.first[ey] - row0) * nx * w, (ty.first[ey] - row0 + q + 1) * nx * w))
                    .collect()
            };
            let (r_ranges, m_ranges) = (ranges(ncomp), ranges(row_len));
            let r_chunks: Vec<Option<&mut [f64]>> = if want_res {
                split_ranges(res, &r_ranges).into_iter().map(Some).collect()
            } else {
                rows.iter().map(|_| None).collect()
            };
            let m_chunks: Vec<Option<&mut [f64]>> = if want_mat {
                split_ranges(stencil, &m_ranges).into_iter().map(Some).collect()
            } else {
                rows.iter().map(|_| None).collect()
            };
            let body = |s: &mut Scratch, ((ey, mut rc), mut mc): RowChunks<'_>| {
                for ex in 0..tx.num_elements() {
                    let fx = tx.first[ex];
                    kernel(ex, ey, s);
                    let nloc = s.nloc;
                    for ja in 0..=q {
                        for ia in 0..=p {
                            let a = ja * (p + 1) + ia;
                            let row = ja * nx + fx + ia; // row inside the chunk
                            if let Some(rc) = rc.as_deref_mut() {
                                for z in 0..ncomp {
                                    rc[row * ncomp + z] += s.re[z * nloc + a];
                                }
                            }
                            if let Some(mc) = mc.as_deref_mut() {
                                let base = row * row_len;
                                for zd in 0..ncomp * ncomp {
                                    let blk = &s.ke[(zd * nloc + a) * nloc..(zd * nloc + a + 1) * nloc];
                                    let out = &mut mc[base + zd * sw..base + (zd + 1) * sw];
                                    for jb in 0..=q {
                                        let off = (jb + q - ja) * (2 * p + 1) + p - ia;
                                        let src = &blk[jb * (p + 1)..(jb + 1) * (p + 1)];
                                        for (o, v) in out[off..off + p + 1].iter_mut().zip(src) {
                                            *o += v;
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
            };
            if serial {
                let s = scratch.get_or_insert_with(|| Scratch::new(p, q, ncomp));
                for item in rows.into_iter().zip(r_chunks).zip(m_chunks) {
                    body(s, item);
                }
            } else {
                rows.into_par_iter().zip(r_chunks).zip(m_chunks).for_each_init(|| Scratch::new(p, q, ncomp), body);
            }
        }
    }

    /// Fill `s.b` with the tensor-product basis values at point `(ku, kv)` of element
    /// `(ex, ey)` and return the quadrature weight.
    ///
    /// For a rational basis ([`Discretization::with_weights`]) the B-spline products
    /// `N_b` become `R_b = w_b N_b / W` by the quotient rule, with `W = sum_b w_b N_b`:
    /// `R_u = (w N_u - R W_u) / W`, `R_uu = (w N_uu - 2 R_u W_u - R W_uu) / W`,
    /// `R_uv = (w N_uv - R_u W_v - R_v W_u - R W_uv) / W` (and likewise in `v`).
    pub(crate) fn tensor_basis(&self, ex: usize, ey: usize, ku: usize, kv: usize, s: &mut Scratch) -> f64 {
        let (p, q) = self.degrees();
        let tu = self.tables[0].at(ex, ku);
        let tv = self.tables[1].at(ey, kv);
        for jb in 0..=q {
            for ib in 0..=p {
                let (u0, u1, u2) = (tu.n[0][ib], tu.n[1][ib], tu.n[2][ib]);
                let (v0, v1, v2) = (tv.n[0][jb], tv.n[1][jb], tv.n[2][jb]);
                s.b[jb * (p + 1) + ib] = [u0 * v0, u1 * v0, u0 * v1, u2 * v0, u1 * v1, u0 * v2];
            }
        }
        if let Some(w) = &self.weights {
            let nx = self.shape()[0];
            let (fx, fy) = (self.tables[0].first[ex], self.tables[1].first[ey]);
            let weight = |a: usize| w[(fy + a / (p + 1)) * nx + fx + a % (p + 1)];
            let mut ww = [0.0; 6];
            for (a, b) in s.b.iter().enumerate() {
                let wa = weight(a);
                for (t, v) in ww.iter_mut().zip(b) {
                    *t += wa * v;
                }
            }
            let [w0, wu, wv, wuu, wuv, wvv] = ww;
            for (a, b) in s.b.iter_mut().enumerate() {
                let wa = weight(a);
                let r = wa * b[0] / w0;
                let ru = (wa * b[1] - r * wu) / w0;
                let rv = (wa * b[2] - r * wv) / w0;
                let ruu = (wa * b[3] - 2.0 * ru * wu - r * wuu) / w0;
                let ruv = (wa * b[4] - ru * wv - rv * wu - r * wuv) / w0;
                let rvv = (wa * b[5] - 2.0 * rv * wv - r * wvv) / w0;
                *b = [r, ru, rv, ruu, ruv, rvv];
            }
        }
        tu.w * tv.w
    }

    /// [`Discretization::tensor_basis`] up to first derivatives: `s.b[a][0..3] = (w,
    /// w_u, w_v)`, the second-derivative slots left as they are, for the first-order
    /// forms (eq. 14, 16), which read no others. The rational quotient rule takes one
    /// division per point instead of six per function.
    pub(crate) fn tensor_basis_first(&self, ex: usize, ey: usize, ku: usize, kv: usize, s: &mut Scratch) -> f64 {
        let (tx, ty) = (&self.tables[0], &self.tables[1]);
        let nqp = tx.nq * ty.nq;
        if self.num_elements() * nqp < FIRST_ORDER_TABLE_POINTS {
            let cache = self.first_order.get_or_init(|| {
                let mut s = Scratch::new(self.degrees().0, self.degrees().1, 1);
                let mut out = Vec::with_capacity(self.num_elements() * nqp * s.nloc);
                for ey in 0..ty.num_elements() {
                    for ex in 0..tx.num_elements() {
                        for kv in 0..ty.nq {
                            for ku in 0..tx.nq {
                                self.compute_first(ex, ey, ku, kv, &mut s);
                                out.extend(s.b.iter().map(|b| [b[0], b[1], b[2]]));
                            }
                        }
                    }
                }
                out
            });
            let nloc = s.nloc;
            let k = ((ey * tx.num_elements() + ex) * nqp + kv * tx.nq + ku) * nloc;
            for (b, c) in s.b.iter_mut().zip(&cache[k..k + nloc]) {
                b[..3].copy_from_slice(c);
            }
            return tx.at(ex, ku).w * ty.at(ey, kv).w;
        }
        self.compute_first(ex, ey, ku, kv, s)
    }

    /// [`Discretization::tensor_basis_first`], computed.
    fn compute_first(&self, ex: usize, ey: usize, ku: usize, kv: usize, s: &mut Scratch) -> f64 {
        let (p, q) = self.degrees();
        let tu = self.tables[0].at(ex, ku);
        let tv = self.tables[1].at(ey, kv);
        for jb in 0..=q {
            let (v0, v1) = (tv.n[0][jb], tv.n[1][jb]);
            for ib in 0..=p {
                let (u0, u1) = (tu.n[0][ib], tu.n[1][ib]);
                let b = &mut s.b[jb * (p + 1) + ib];
                b[0] = u0 * v0;
                b[1] = u1 * v0;
                b[2] = u0 * v1;
            }
        }
        if let Some(w) = &self.weights {
            let nx = self.shape()[0];
            let (fx, fy) = (self.tables[0].first[ex], self.tables[1].first[ey]);
            let weight = |a: usize| w[(fy + a / (p + 1)) * nx + fx + a % (p + 1)];
            let (mut w0, mut wu, mut wv) = (0.0, 0.0, 0.0);
            for (a, b) in s.b.iter().enumerate() {
                let wa = weight(a);
                w0 += wa * b[0];
                wu += wa * b[1];
                wv += wa * b[2];
            }
            let inv = 1.0 / w0;
            for (a, b) in s.b.iter_mut().enumerate() {
                let wa = weight(a) * inv;
                let r = wa * b[0];
                b[0] = r;
                b[1] = wa * b[1] - r * wu * inv;
                b[2] = wa * b[2] - r * wv * inv;
            }
        }
        tu.w * tv.w
    }

    fn geometry(&self, ex: usize, ey: usize, cps: &[[f64; 2]], s: &Scratch) -> Geo {
        let (p, q) = self.degrees();
        let nx = self.shape()[0];
        let (fx, fy) = (self.tables[0].first[ex], self.tables[1].first[ey]);
        let mut g = Geo::default();
        for jb in 0..=q {
            for ib in 0..=p {
                let c = cps[(fy + jb) * nx + fx + ib];
                let b = &s.b[jb * (p + 1) + ib];
                for d in 0..2 {
                    g.xu[d] += b[1] * c[d];
                    g.xv[d] += b[2] * c[d];
                    g.xuu[d] += b[3] * c[d];
                    g.xuv[d] += b[4] * c[d];
                    g.xvv[d] += b[5] * c[d];
                }
            }
        }
        g
    }

    /// EGG residual (eq. 8) and, when `stencil` is non-empty, its exact Jacobian.
    ///
    /// With `g11 = x_xi.x_xi`, `g12 = x_xi.x_eta`, `g22 = x_eta.x_eta` and
    /// `L(z) = g22 z_xixi - 2 g12 z_xieta + g11 z_etaeta` (eq. 4), the residual is
    /// `F^z_a = int w_a L(z)`. Its derivative with respect to component `d` of control
    /// point `b` is `int w_a [dg22 z_xixi - 2 dg12 z_xieta + dg11 z_etaeta + delta_zd L(w_b)]`
    /// with `dg11 = 2 x^d_xi w_b,xi`, `dg12 = x^d_xi w_b,eta + x^d_eta w_b,xi`,
    /// `dg22 = 2 x^d_eta w_b,eta`. For [`Operator::Scaled`] the integrand is divided by
    /// `s = g11 + g22` and the quotient rule adds `-L(z) ds / s^2`,
    /// `ds = 2 (x^d_xi w_b,xi + x^d_eta w_b,eta)`.
    ///
    /// `res` has length `2 n` (full, component-interleaved); `stencil` has length
    /// [`Discretization::stencil_len`]`(2)` or is empty.
    pub fn egg(&self, cps: &[[f64; 2]], op: Operator, res: &mut [f64], stencil: &mut [f64]) {
        let want_mat = !stencil.is_empty();
        self.assemble(2, res, stencil, self.egg_kernel(cps, op, want_mat));
    }

    /// The element kernel of [`Discretization::egg`] (with the element matrices when
    /// `want_mat`).
    pub(crate) fn egg_kernel<'a>(
        &'a self,
        cps: &'a [[f64; 2]],
        op: Operator,
        want_mat: bool,
    ) -> impl Fn(usize, usize, &mut Scratch) + Sync + 'a {
        let nq = [self.tables[0].nq, self.tables[1].nq];
        let nqp = nq[0] * nq[1];
        move |ex, ey, s| {
            let nloc = s.nloc;
            s.re.fill(0.0);
            if want_mat {
                s.reserve_products(nqp * nloc, 4 * nqp * nloc);
            }
            for kv in 0..nq[1] {
                for ku in 0..nq[0] {
                    let k = kv * nq[0] + ku;
                    let wq = self.tensor_basis(ex, ey, ku, kv, s);
                    let g = self.geometry(ex, ey, cps, s);
                    let rows =
                        want_mat.then(|| EggRows { wa: &mut s.wa[k * nloc..(k + 1) * nloc], tz: &mut s.tz, k, nqp });
                    egg_point(&s.b, &g, wq, op, &mut s.re, rows);
                }
            }
            if want_mat {
                // K^{zd}_{ab} = sum_k wa_{ka} tz^{zd}_{kb}: one small matrix product per block
                for zd in 0..4 {
                    let tz = &s.tz[zd * nqp * nloc..(zd + 1) * nqp * nloc];
                    let ke = &mut s.ke[zd * nloc * nloc..(zd + 1) * nloc * nloc];
                    element_product(ke, &s.wa, tz, nloc);
                }
            }
        }
    }

    /// Scalar mass matrix `int w_a w_b` (eq. 30) into `stencil` (length `stencil_len(1)`).
    pub fn mass(&self, stencil: &mut [f64]) {
        self.scalar_form(stencil, |b, c| b[0] * c[0]);
    }

    fn scalar_form(&self, stencil: &mut [f64], form: impl Fn(&[f64; 6], &[f64; 6]) -> f64 + Sync) {
        let nq = [self.tables[0].nq, self.tables[1].nq];
        self.assemble(1, &mut [], stencil, |ex, ey, s| {
            let nloc = s.nloc;
            s.ke.fill(0.0);
            for kv in 0..nq[1] {
                for ku in 0..nq[0] {
                    let wq = self.tensor_basis(ex, ey, ku, kv, s);
                    for a in 0..nloc {
                        for b in 0..nloc {
                            s.ke[a * nloc + b] += wq * form(&s.b[a], &s.b[b]);
                        }
                    }
                }
            }
        });
    }

    /// The symmetric principal part of the EGG Jacobian, `K_ab = int grad w_a . A grad w_b / s`
    /// with `A = [[g22, -g12], [-g12, g11]]` (`s = 1` for [`Operator::Plain`], `s = g11 + g22`
    /// for [`Operator::Scaled`]), plus `shift` times the mass matrix, into `stencil` (length
    /// `stencil_len(1)`).
    ///
    /// Integrating eq. (8) by parts against `w_a` (zero on the boundary) gives
    /// `int w_a L(w_b) = -int grad w_a . A grad w_b + (first-order terms)`, and the
    /// derivatives of the metric add first-order terms only, so `dF/dc = -diag(K, K) + B`
    /// with `B` of lower order: `diag(K, K)` is a mesh-independent preconditioner of the
    /// Newton systems. `det A = (det J)^2 >= 0` and `tr A > 0`: `K` is symmetric positive
    /// (semi)definite even on a folded map; a relative `1e-10 tr A` is added to the diagonal
    /// of `A` to keep it definite.
    pub(crate) fn metric_laplace(&self, cps: &[[f64; 2]], op: Operator, shift: f64, stencil: &mut [f64]) {
        let nq = [self.tables[0].nq, self.tables[1].nq];
        let nqp = nq[0] * nq[1];
        // K_ab = sum_k (A grad w_a)_u w_b,u + (A grad w_a)_v w_b,v (+ shift w_a w_b): one
        // product of (2 or 3) nqp rows
        let nrows = if shift != 0.0 { 3 * nqp } else { 2 * nqp };
        self.assemble(1, &mut [], stencil, |ex, ey, s| {
            let nloc = s.nloc;
            s.reserve_products(nrows * nloc, nrows * nloc);
            for kv in 0..nq[1] {
                for ku in 0..nq[0] {
                    let k = kv * nq[0] + ku;
                    let wq = self.tensor_basis(ex, ey, ku, kv, s);
                    let g = self.geometry(ex, ey, cps, s);
                    let (g11, g12, g22) = g.metric();
                    let tr = g11 + g22;
                    let scale = match op {
                        Operator::Plain => 1.0,
                        Operator::Scaled if tr > 0.0 => 1.0 / tr,
                        Operator::Scaled => 1.0,
                    };
                    let eps = 1e-10 * tr;
                    let w = wq * scale;
                    let (a11, a12, a22) = (w * (g22 + eps), -w * g12, w * (g11 + eps));
                    for (a, ba) in s.b.iter().enumerate() {
                        s.wa[k * nloc + a] = a11 * ba[1] + a12 * ba[2];
                        s.tz[k * nloc + a] = ba[1];
                        s.wa[(nqp + k) * nloc + a] = a12 * ba[1] + a22 * ba[2];
                        s.tz[(nqp + k) * nloc + a] = ba[2];
                        if shift != 0.0 {
                            s.wa[(2 * nqp + k) * nloc + a] = wq * shift * ba[0];
                            s.tz[(2 * nqp + k) * nloc + a] = ba[0];
                        }
                    }
                }
            }
            element_product(&mut s.ke, &s.wa, &s.tz, nloc);
        });
    }

    /// Linear elasticity on the physical domain of the map `cps` (Lamé `lambda`, `mu`):
    /// `a(u, v) = int_Omega lambda div u div v + 2 mu eps(u):eps(v) dx`, pulled back with
    /// `grad_x w = J^{-T} grad_xi w` and `dx = |det J| dxi`. Where `det J` vanishes the
    /// parametric gradients are used instead, so the operator stays definite.
    pub fn elasticity(&self, cps: &[[f64; 2]], lambda: f64, mu: f64, stencil: &mut [f64]) {
        let nq = [self.tables[0].nq, self.tables[1].nq];
        let nqp = nq[0] * nq[1];
        // block (z, d): K_ab = sum_k dx [c^{zd}_x(a) w_b,x + c^{zd}_y(a) w_b,y] with the
        // physical gradients w_,x, w_,y: for each block one product of 2 nqp rows
        self.assemble(2, &mut [], stencil, |ex, ey, s| {
            let nloc = s.nloc;
            s.reserve_products(8 * nqp * nloc, 2 * nqp * nloc);
            for kv in 0..nq[1] {
                for ku in 0..nq[0] {
                    let k = kv * nq[0] + ku;
                    let wq = self.tensor_basis(ex, ey, ku, kv, s);
                    let g = self.geometry(ex, ey, cps, s);
                    let det = g.xu[0] * g.xv[1] - g.xv[0] * g.xu[1];
                    let scale = g.xu[0].hypot(g.xu[1]) * g.xv[0].hypot(g.xv[1]);
                    let regular = det.abs() > 1e-12 * scale && scale > 0.0;
                    let dx = wq * if regular { det.abs() } else { 1.0 };
                    let (l2m, l, m) = (dx * (lambda + 2.0 * mu), dx * lambda, dx * mu);
                    for a in 0..nloc {
                        let (bu, bv) = (s.b[a][1], s.b[a][2]);
                        // physical gradient of w_a
                        let (gx, gy) = if regular {
                            ((g.xv[1] * bu - g.xu[1] * bv) / det, (-g.xv[0] * bu + g.xu[0] * bv) / det)
                        } else {
                            (bu, bv)
                        };
                        s.tz[k * nloc + a] = gx;
                        s.tz[(nqp + k) * nloc + a] = gy;
                        // coefficients of w_b,x (rows k) and w_b,y (rows nqp + k) per block
                        let c = [[l2m * gx, m * gy], [m * gy, l * gx], [l * gy, m * gx], [m * gx, l2m * gy]];
                        for (zd, [cx, cy]) in c.into_iter().enumerate() {
                            s.wa[(2 * zd * nqp + k) * nloc + a] = cx;
                            s.wa[((2 * zd + 1) * nqp + k) * nloc + a] = cy;
                        }
                    }
                }
            }
            for zd in 0..4 {
                let w = &s.wa[2 * zd * nqp * nloc..2 * (zd + 1) * nqp * nloc];
                element_product(&mut s.ke[zd * nloc * nloc..(zd + 1) * nloc * nloc], w, &s.tz, nloc);
            }
        });
    }

    /// Restrict a full component-interleaved vector (length `ncomp n`) to the free
    /// unknowns `(z * m + f)`, summing the rows of periodic replicas into their primary's.
    pub(crate) fn restrict(&self, full: &[f64], ncomp: usize) -> Vec<f64> {
        let m = self.dofs.num_free();
        let mut out = vec![0.0; ncomp * m];
        for (f, &k) in self.dofs.free().iter().enumerate() {
            for z in 0..ncomp {
                out[z * m + f] = full[k * ncomp + z];
            }
        }
        for &(k, _) in self.dofs.replicas() {
            let f = self.dofs.free_index(k);
            if f != FIXED {
                for z in 0..ncomp {
                    out[z * m + f] += full[k * ncomp + z];
                }
            }
        }
        out
    }

    /// Every stored function of a free one: `(f, k)` for the primaries, then for the
    /// periodic replicas.
    fn free_rows(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let d = &self.dofs;
        let replicas = d.replicas().iter().map(|&(k, _)| (d.free_index(k), k)).filter(|&(f, _)| f != FIXED);
        d.free().iter().copied().enumerate().chain(replicas)
    }

    /// `K_free,fixed * u_fixed` for a scalar stencil operator: the right-hand side
    /// contribution of Dirichlet data `u` (full, per basis function).
    pub(crate) fn apply_to_fixed_scalar(&self, stencil: &[f64], u: &[f64]) -> Vec<f64> {
        let (p, q) = self.degrees();
        let sw = self.stencil_width();
        let mut out = vec![0.0; self.dofs.num_free()];
        for (f, k) in self.free_rows() {
            for (s, kk) in stencil_neighbours(self.shape(), p, q, k) {
                if self.dofs.free_index(kk) == FIXED {
                    out[f] += stencil[k * sw + s] * u[kk];
                }
            }
        }
        out
    }

    /// `K_free,fixed * u_fixed` for a 2-component stencil operator: the right-hand side
    /// contribution of Dirichlet data `u` (full, per basis function) in a linear problem.
    pub(crate) fn apply_to_fixed(&self, stencil: &[f64], u: &[[f64; 2]]) -> Vec<f64> {
        let (p, q) = self.degrees();
        let sw = self.stencil_width();
        let row_len = 4 * sw;
        let m = self.dofs.num_free();
        let mut out = vec![0.0; 2 * m];
        for (f, k) in self.free_rows() {
            for (s, kk) in stencil_neighbours(self.shape(), p, q, k) {
                if self.dofs.free_index(kk) != FIXED {
                    continue;
                }
                for z in 0..2 {
                    for d in 0..2 {
                        out[z * m + f] += stencil[k * row_len + (z * 2 + d) * sw + s] * u[kk][d];
                    }
                }
            }
        }
        out
    }
}
