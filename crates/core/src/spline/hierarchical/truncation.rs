//! The two-scale relation between successive levels and the restriction of the THB
//! functions to an active cell.
//!
//! **Two-scale relation.** A level-`l` B-spline `σ` with local knots `t_σ, ..., t_{σ+p+1}`
//! is a combination of the level-`(l + 1)` B-splines obtained by inserting the split points
//! of its non-empty spans (their midpoints, or the given level's knots; Boehm): inserting `u` into a knot sequence `t` maps the
//! coefficients `c_j` to `ĉ_j = ω_j c_j + (1 - ω_j) c_{j-1}` with
//! `ω_j = (u - t_j) / (t_{j+p} - t_j)` clamped to `[0, 1]` (`c_{-1} = c_n = 0`).
//!
//! **Restriction to a cell.** Write the partial sums of a THB combination
//! `f = Σ_β c_β Trunc β` level by level: `f_0 = Σ_{β ∈ A^0} c_β β` and
//! `f_l = trunc^l(f_{l-1}) + Σ_{β ∈ A^l} c_β β`, so that `f = f_L`. In the level-`l`
//! B-splines, `f_l = Σ_τ d^l_τ τ` with
//!
//! `d^l_τ = c_τ` if `τ` is active, `0` if `supp τ ⊆ Ω^{l+1}` (masked by the truncation),
//! `d^l_τ = Σ_σ P^l_{τσ} d^{l-1}_σ` (two-scale relation) if `supp τ ⊄ Ω^l`.
//!
//! On an active cell `Q` of level `l`, `f = f_l` (the finer levels only change `f` inside
//! `Ω^{l+1}`), so `f|_Q = Σ_{τ non-zero on Q} d^l_τ τ`: the `(p + 1)(q + 1)` level-`l`
//! coefficients of the cell, computed by the recursion above (memoised, and only for the
//! functions whose support meets `Ω^l`). With `c` a unit vector this is the restriction of
//! one THB function; with control points, the map's local net.

use std::collections::HashMap;

use super::{HierarchicalBasis, Index2};
use crate::spline::curve::Point;

/// Insert `u` (strictly inside `(t_0, t_{last})`) into the knot sequence `t` of a degree-`p`
/// spline with coefficients `c` (`c.len() = t.len() - p - 1`), keeping the function.
pub(crate) fn insert_knot(p: usize, t: &mut Vec<f64>, c: &mut Vec<f64>, u: f64) {
    let n = c.len();
    let omega = |j: usize| {
        if t[j + p] <= u {
            1.0
        } else if u <= t[j] {
            0.0
        } else {
            (u - t[j]) / (t[j + p] - t[j])
        }
    };
    let out: Vec<f64> = (0..=n)
        .map(|j| {
            let w = omega(j);
            let cj = if j < n { c[j] } else { 0.0 };
            let cm = if j > 0 { c[j - 1] } else { 0.0 };
            w * cj + (1.0 - w) * cm
        })
        .collect();
    *c = out;
    let k = t.partition_point(|&x| x <= u);
    t.insert(k, u);
}

/// The blossom of the polynomial piece of `Σ_j c_j N_{s-p+j}` on the span `[t_s, t_{s+1}]`,
/// given by its local knots `t_{s-p}, ..., t_{s+p+1}` (`2p + 2` values), at the arguments
/// `x_1, ..., x_p` (de Boor's algorithm with one argument per level). The coefficient of a
/// B-spline with interior knots `x` in any space containing the piece is this value.
pub(crate) fn blossom<V: Coefficient>(t: &[f64], c: &[V], x: &[f64]) -> V {
    let p = c.len() - 1;
    let mut d: Vec<V> = c.to_vec();
    for r in 1..=p {
        for i in (r..=p).rev() {
            let (ti, tr) = (t[i], t[i + p + 1 - r]);
            let al = (x[r - 1] - ti) / (tr - ti);
            let mut v = d[i - 1].clone();
            v.scale(1.0 - al);
            v.add_scaled(al, &d[i]);
            d[i] = v;
        }
    }
    d.swap_remove(p)
}

/// A value the THB coefficients can carry: a point of the plane, or a sparse vector over
/// the THB functions (the restriction of each function).
pub(crate) trait Coefficient: Clone {
    /// The zero value.
    fn zero() -> Self;
    /// `self += a x`.
    fn add_scaled(&mut self, a: f64, x: &Self);
    /// `self *= a`.
    fn scale(&mut self, a: f64);
}

impl Coefficient for Point {
    fn zero() -> Self {
        [0.0; 2]
    }
    fn add_scaled(&mut self, a: f64, x: &Self) {
        self[0] += a * x[0];
        self[1] += a * x[1];
    }
    fn scale(&mut self, a: f64) {
        self[0] *= a;
        self[1] *= a;
    }
}

/// A sparse vector `(index, value)`, sorted by index.
pub(crate) type Sparse = Vec<(usize, f64)>;

impl Coefficient for Sparse {
    fn zero() -> Self {
        Vec::new()
    }
    fn add_scaled(&mut self, a: f64, x: &Self) {
        for &(k, v) in x {
            match self.binary_search_by_key(&k, |e| e.0) {
                Ok(i) => self[i].1 += a * v,
                Err(i) => self.insert(i, (k, a * v)),
            }
        }
    }
    fn scale(&mut self, a: f64) {
        for e in self.iter_mut() {
            e.1 *= a;
        }
    }
}

impl HierarchicalBasis {
    /// The two-scale relation in direction `d`: the level-`(l + 1)` functions
    /// `(index, coefficient)` whose combination is the level-`l` function `sigma`.
    pub(crate) fn children_1d(&self, l: usize, d: usize, sigma: usize) -> Vec<(usize, f64)> {
        if !self.splits(l + 1, d) {
            return vec![(sigma, 1.0)];
        }
        let kv = &self.levels[l].knots[d];
        let p = kv.degree();
        let mut t: Vec<f64> = kv.knots()[sigma..=sigma + p + 1].to_vec();
        // the split points of the support's elements (consecutive from the first)
        let e0 = self.levels[l].support(d, sigma).start;
        let n_spans = t.windows(2).filter(|w| w[1] > w[0]).count();
        let mids: Vec<f64> = (e0..e0 + n_spans).filter_map(|e| self.split_point(l, d, e)).collect();
        let mut c = vec![1.0];
        for u in mids {
            insert_knot(p, &mut t, &mut c, u);
        }
        let start = sigma + self.levels[l].first[d][sigma];
        c.into_iter().enumerate().filter(|e| e.1 != 0.0).map(|(k, v)| (start + k, v)).collect()
    }

    /// The level-`(l - 1)` functions `(index, P_{τσ})` whose two-scale relation holds the
    /// level-`l` function `tau` (`l >= 1`), in direction `d`.
    pub(crate) fn parents_1d(&self, l: usize, d: usize, tau: usize) -> Vec<(usize, f64)> {
        if !self.splits(l, d) {
            return vec![(tau, 1.0)];
        }
        let e0 = self.levels[l].support(d, tau).start;
        self.levels[l - 1]
            .functions(d, e0 / 2)
            .filter_map(|s| self.children_1d(l - 1, d, s).into_iter().find(|c| c.0 == tau).map(|c| (s, c.1)))
            .collect()
    }
}

/// The level coefficients `d^l_τ` of a THB combination (see the module doc), memoised.
pub(crate) struct LevelCoefficients<'a, V: Coefficient> {
    basis: &'a HierarchicalBasis,
    /// The coefficient of active function `k`.
    leaf: Box<dyn Fn(usize) -> V + 'a>,
    memo: HashMap<(usize, Index2), V>,
    /// [`HierarchicalBasis::parents_1d`] by `(level, direction, function)`: every
    /// function of a row of cells asks for the same ones.
    parents: HashMap<(usize, usize, usize), Vec<(usize, f64)>>,
}

impl<V: Coefficient> std::fmt::Debug for LevelCoefficients<'_, V> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LevelCoefficients").field("memoised", &self.memo.len()).finish()
    }
}

impl<'a, V: Coefficient> LevelCoefficients<'a, V> {
    /// The combination with coefficient `leaf(k)` on the `k`-th active function.
    pub fn new(basis: &'a HierarchicalBasis, leaf: impl Fn(usize) -> V + 'a) -> Self {
        Self { basis, leaf: Box::new(leaf), memo: HashMap::new(), parents: HashMap::new() }
    }

    /// [`HierarchicalBasis::parents_1d`], memoised.
    fn parents(&mut self, l: usize, d: usize, tau: usize) -> Vec<(usize, f64)> {
        let b = self.basis;
        self.parents.entry((l, d, tau)).or_insert_with(|| b.parents_1d(l, d, tau)).clone()
    }

    /// `d^l_τ` for the level-`l` function `tau` whose support meets `Ω^l`.
    pub fn get(&mut self, l: usize, tau: Index2) -> V {
        if let Some(v) = self.memo.get(&(l, tau)) {
            return v.clone();
        }
        let b = self.basis;
        let v = if b.support_in_domain(l, tau) {
            b.index_of(l, tau).map_or_else(V::zero, |k| (self.leaf)(k))
        } else {
            let (px, py) = (self.parents(l, 0, tau[0]), self.parents(l, 1, tau[1]));
            let mut v = V::zero();
            for &(sy, wy) in &py {
                for &(sx, wx) in &px {
                    let s = self.get(l - 1, [sx, sy]);
                    v.add_scaled(wx * wy, &s);
                }
            }
            v
        };
        self.memo.insert((l, tau), v.clone());
        v
    }

    /// The local net of cell `c` of level `l` (in `Ω^l`): `d^l_τ` of the `(p + 1)(q + 1)`
    /// functions non-zero there, `xi` index fastest.
    pub(crate) fn cell_net(&mut self, l: usize, c: Index2) -> Vec<V> {
        let [fi, fj] = self.basis.functions_on(l, c);
        let mut out = Vec::with_capacity(fi.len() * fj.len());
        for j in fj {
            for i in fi.clone() {
                out.push(self.get(l, [i, j]));
            }
        }
        out
    }
}

#[cfg(test)]
/// Value and first derivatives `(N, ∂_ξ N, ∂_η N)` of one THB function at a point.
pub(crate) type BasisValue = (usize, [f64; 3]);

impl HierarchicalBasis {
    #[cfg(test)]
    /// The THB functions non-zero at `(u, v)`: `(index, [value, ∂_ξ, ∂_η])`, from the
    /// restriction of every THB function to the active cell containing the point.
    pub(crate) fn eval_basis(&self, u: f64, v: f64) -> Vec<BasisValue> {
        let (l, c) = self.cell_at(u, v);
        let mut lc = LevelCoefficients::<Sparse>::new(self, |k| vec![(k, 1.0)]);
        let net = lc.cell_net(l, c);
        let spans = self.cell_spans(l, c);
        let kv = self.knots(l);
        let mut bu = crate::spline::basis::BasisDerivs::default();
        let mut bv = crate::spline::basis::BasisDerivs::default();
        bu.eval_in_span(&kv[0], spans[0], u, 1);
        bv.eval_in_span(&kv[1], spans[1], v, 1);
        let p1 = self.degrees()[0] + 1;
        let mut acc: Sparse = Vec::new();
        let mut acc_u: Sparse = Vec::new();
        let mut acc_v: Sparse = Vec::new();
        for (k, row) in net.iter().enumerate() {
            let (i, j) = (k % p1, k / p1);
            acc.add_scaled(bu.d[0][i] * bv.d[0][j], row);
            acc_u.add_scaled(bu.d[1][i] * bv.d[0][j], row);
            acc_v.add_scaled(bu.d[0][i] * bv.d[1][j], row);
        }
        acc.iter().zip(&acc_u).zip(&acc_v).map(|((a, b), c)| (a.0, [a.1, b.1, c.1])).collect()
    }
}
