//! The Bernstein coefficients `d(c)` of `det J` as functions of the control points, and
//! their exact derivatives: the constraints `d(c) >= z 1` of Gravesen's feasible start
//! (paper eq. 49) and `d(c) >= ε` of the constrained optimisation (§10.3).
//!
//! On an element `[a, b] x [c, e]` of a polynomial map of degree `(p, q)` every basis
//! function's derivatives are Bernstein polynomials: with the extraction operators `C`
//! of [`crate::spline::bezier`] (`N_i = Σ_k C_ik B_k^p`),
//!
//! `∂_ξ N_a = U_a`, `U_a[k, l] = p / (b - a) (C^ξ_{i,k+1} - C^ξ_{i,k}) C^η_{j,l}` (degree `(p-1, q)`),
//! `∂_η N_a = V_a`, `V_a[k, l] = q / (e - c) C^ξ_{i,k} (C^η_{j,l+1} - C^η_{j,l})` (degree `(p, q-1)`),
//!
//! for `a = (i, j)`. Products of Bernstein polynomials are Bernstein polynomials (module
//! `bernstein`, `⊗`), so on the element
//!
//! `det J = x_ξ y_η - x_η y_ξ = Σ_ab c^x_a c^y_b (U_a ⊗ V_b - V_a ⊗ U_b)`,
//!
//! a polynomial of degree `(2p - 1, 2q - 1)` whose coefficients `d` are **bilinear** in
//! `(c^x, c^y)`: `d = B(c^x, c^y)`. Its derivatives are therefore exact and cheap,
//!
//! `∂d/∂c^x_a = U_a ⊗ Y_η - V_a ⊗ Y_ξ`, `∂d/∂c^y_b = X_ξ ⊗ V_b - X_η ⊗ U_b`,
//!
//! with `X_ξ = Σ_a c^x_a U_a` etc. the derivative nets of the map, and the second
//! derivatives do not depend on `c`: `∂²d/∂c^x_a ∂c^y_b = U_a ⊗ V_b - V_a ⊗ U_b`. For the
//! Hessian of a Lagrangian, `Σ_k λ_k ∂²d_k/∂c^x_a ∂c^y_b = T_ab - T_ba` with
//! `T_ab = U_aᵀ M V_b`, `M[k₁, k₂] = w(k₁, k₂) λ[k₁ + k₂]` and `w` the weights of the
//! Bernstein product.
//!
//! These are the same coefficients as the certificate's (which computes them with a
//! rigorous rounding bound, relative to a local origin and scaled): here they are plain
//! floating point, in units of `det J` (the factors `p q / (h_ξ h_η)` included), for
//! optimisation, not proof. Polynomial maps only (the numerator of a rational map's
//! `det J` is not bilinear in the control points alone).
//!
//! Rows are numbered element by element (`ξ` fastest), coefficient `(k, l)` of an element
//! at `l (2p) + k`; columns of the Jacobian are the unknowns `c = (c^x, c^y)` of a
//! [`DofMap`] (free control points; replicas of periodic ones summed).

use rayon::prelude::*;

use super::bernstein::{mul_add, normalize, Binom, Deg};
use crate::discrete::dofs::{DofMap, FIXED};
use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;
use crate::spline::bezier::BezierExtraction;
use crate::spline::curve::Point;
use crate::spline::knots::KnotVector;

/// The map `c -> d(c)` of a polynomial tensor basis (symbolic data, no control points).
#[derive(Debug)]
pub(crate) struct DetCoefficients {
    p: usize,
    q: usize,
    nx: usize,
    ex: [BezierExtraction; 2],
    binom: Binom,
}

/// The derivative nets `U_a`, `V_a` of the local basis functions of one element.
struct LocalNets {
    /// Global index of local function `a = j (p + 1) + i`.
    global: Vec<usize>,
    /// `U_a`, degree `(p - 1, q)`, coefficient `(k, l)` at `l p + k`.
    u: Vec<Vec<f64>>,
    /// `V_a`, degree `(p, q - 1)`, coefficient `(k, l)` at `l (p + 1) + k`.
    v: Vec<Vec<f64>>,
}

impl DetCoefficients {
    /// The coefficient map of the basis `knots` (degrees at least 1, interior
    /// multiplicities at most the degree).
    pub fn new(knots: &[KnotVector; 2]) -> Result<Self> {
        let (p, q) = (knots[0].degree(), knots[1].degree());
        if p < 1 || q < 1 {
            return Err(Error::Invalid(format!("det J coefficients need degrees >= 1, got ({p}, {q})")));
        }
        let ex = [BezierExtraction::new(&knots[0])?, BezierExtraction::new(&knots[1])?];
        Ok(Self { p, q, nx: knots[0].num_basis(), ex, binom: Binom::new(2 * p.max(q) + 2) })
    }

    /// Degree `(2p - 1, 2q - 1)` of `det J` on an element.
    pub fn degree(&self) -> [usize; 2] {
        [2 * self.p - 1, 2 * self.q - 1]
    }

    /// Coefficients per element, `(2p) (2q)`.
    pub(crate) fn per_element(&self) -> usize {
        4 * self.p * self.q
    }

    /// Elements per direction.
    pub fn shape(&self) -> [usize; 2] {
        [self.ex[0].elements.len(), self.ex[1].elements.len()]
    }

    /// Number of coefficients (rows).
    pub fn len(&self) -> usize {
        let [a, b] = self.shape();
        a * b * self.per_element()
    }

    /// Parameter area of element `e` (row-major, `ξ` fastest).
    pub(crate) fn element_area(&self, e: usize) -> f64 {
        let n = self.shape()[0];
        let (_, a, b) = self.ex[0].elements[e % n];
        let (_, c, d) = self.ex[1].elements[e / n];
        (b - a) * (d - c)
    }

    fn deg_u(&self) -> Deg<2> {
        Deg([self.p - 1, self.q])
    }

    fn deg_v(&self) -> Deg<2> {
        Deg([self.p, self.q - 1])
    }

    fn deg_d(&self) -> Deg<2> {
        Deg(self.degree())
    }

    fn nets(&self, e: usize) -> LocalNets {
        let (p, q) = (self.p, self.q);
        let n = self.shape()[0];
        let (ei, ej) = (e % n, e / n);
        let (su, a, b) = self.ex[0].elements[ei];
        let (sv, c, d) = self.ex[1].elements[ej];
        let (ox, oy) = (&self.ex[0].ops[ei], &self.ex[1].ops[ej]);
        let (fu, fv) = (p as f64 / (b - a), q as f64 / (d - c));
        let nloc = (p + 1) * (q + 1);
        let mut nets = LocalNets { global: Vec::with_capacity(nloc), u: Vec::new(), v: Vec::new() };
        for j in 0..=q {
            for i in 0..=p {
                nets.global.push((sv - q + j) * self.nx + su - p + i);
                let cx = &ox[i * (p + 1)..(i + 1) * (p + 1)];
                let cy = &oy[j * (q + 1)..(j + 1) * (q + 1)];
                let mut u = vec![0.0; p * (q + 1)];
                for l in 0..=q {
                    for k in 0..p {
                        u[l * p + k] = fu * (cx[k + 1] - cx[k]) * cy[l];
                    }
                }
                let mut v = vec![0.0; (p + 1) * q];
                for l in 0..q {
                    for k in 0..=p {
                        v[l * (p + 1) + k] = fv * cx[k] * (cy[l + 1] - cy[l]);
                    }
                }
                nets.u.push(u);
                nets.v.push(v);
            }
        }
        nets
    }

    /// The map's derivative nets `(X_ξ, Y_ξ)` and `(X_η, Y_η)` on an element.
    fn map_nets(&self, nets: &LocalNets, cps: &[Point]) -> ([Vec<f64>; 2], [Vec<f64>; 2]) {
        let (lu, lv) = (self.deg_u().len(), self.deg_v().len());
        let mut xu = [vec![0.0; lu], vec![0.0; lu]];
        let mut xv = [vec![0.0; lv], vec![0.0; lv]];
        for (a, &g) in nets.global.iter().enumerate() {
            for z in 0..2 {
                let c = cps[g][z];
                xu[z].iter_mut().zip(&nets.u[a]).for_each(|(o, u)| *o += c * u);
                xv[z].iter_mut().zip(&nets.v[a]).for_each(|(o, v)| *o += c * v);
            }
        }
        (xu, xv)
    }

    /// `out = a ⊗ b - c ⊗ e` with `a`, `e` of degree `(p-1, q)` and `b`, `c` of degree `(p, q-1)`.
    fn cross(&self, a: &[f64], b: &[f64], c: &[f64], e: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        mul_add(&self.binom, a, self.deg_u(), b, self.deg_v(), 1.0, out);
        mul_add(&self.binom, e, self.deg_u(), c, self.deg_v(), -1.0, out);
        normalize(&self.binom, self.deg_d(), out);
    }

    /// `d(c)` of the map with control points `cps` (all of them, in net order).
    pub fn values(&self, cps: &[Point]) -> Vec<f64> {
        let per = self.per_element();
        let [n, m] = self.shape();
        let mut out = vec![0.0; self.len()];
        out.par_chunks_mut(per).enumerate().for_each(|(e, o)| {
            let nets = self.nets(e);
            let (xu, xv) = self.map_nets(&nets, cps);
            self.cross(&xu[0], &xv[1], &xv[0], &xu[1], o);
        });
        debug_assert_eq!(out.len(), n * m * per);
        out
    }

    /// `∫ det J` over the parameter domain: each element's mean coefficient times its area
    /// (exact: a Bernstein polynomial's mean over its box is the mean of its coefficients).
    pub fn area(&self, d: &[f64]) -> f64 {
        let per = self.per_element();
        d.chunks(per).enumerate().map(|(e, c)| self.element_area(e) * c.iter().sum::<f64>() / per as f64).sum()
    }

    /// The Jacobian `∂d/∂c` at `cps` (rows: coefficients; columns: the `2 m` unknowns of
    /// `dofs`, `c^x` block then `c^y` block).
    pub fn jacobian(&self, cps: &[Point], dofs: &DofMap) -> Csr {
        let per = self.per_element();
        let m = dofs.num_free();
        let ne = self.shape()[0] * self.shape()[1];
        let rows: Vec<Vec<Vec<(usize, f64)>>> = (0..ne)
            .into_par_iter()
            .map(|e| {
                let nets = self.nets(e);
                let (xu, xv) = self.map_nets(&nets, cps);
                let mut rows = vec![Vec::new(); per];
                let mut out = vec![0.0; per];
                for (a, &g) in nets.global.iter().enumerate() {
                    let f = dofs.free_index(g);
                    if f == FIXED {
                        continue;
                    }
                    // x: U_a ⊗ Y_η - V_a ⊗ Y_ξ; y: X_ξ ⊗ V_a - X_η ⊗ U_a
                    self.cross(&nets.u[a], &xv[1], &nets.v[a], &xu[1], &mut out);
                    push_column(&mut rows, &out, f);
                    self.cross(&xu[0], &nets.v[a], &xv[0], &nets.u[a], &mut out);
                    push_column(&mut rows, &out, m + f);
                }
                rows
            })
            .collect();
        Csr::from_rows(2 * m, rows.into_iter().flatten().collect())
    }

    /// Which coefficients depend on the unknowns of `dofs` at all (the others are fixed
    /// by the boundary control points: e.g. a corner's, `det J` there). Exact up to
    /// rounding: coefficient `k` is free when some `∂²d_k/∂c^x_a ∂c^y_b` with `a` or `b`
    /// free is nonzero.
    pub(crate) fn depends_on_unknowns(&self, dofs: &DofMap) -> Vec<bool> {
        let per = self.per_element();
        let mut out = vec![false; self.len()];
        out.par_chunks_mut(per).enumerate().for_each(|(e, o)| {
            let nets = self.nets(e);
            let nloc = nets.global.len();
            let free: Vec<bool> = nets.global.iter().map(|&g| dofs.free_index(g) != FIXED).collect();
            let mut pab = vec![0.0; per];
            let mut sizes = vec![0.0f64; per];
            let mut vals = Vec::new();
            for a in 0..nloc {
                for b in 0..nloc {
                    self.cross(&nets.u[a], &nets.v[b], &nets.v[a], &nets.u[b], &mut pab);
                    for (s, x) in sizes.iter_mut().zip(&pab) {
                        *s = s.max(x.abs());
                    }
                    if free[a] || free[b] {
                        vals.push(pab.clone());
                    }
                }
            }
            let scale = sizes.iter().fold(0.0f64, |m, &s| m.max(s));
            for pab in vals {
                for (k, x) in pab.iter().enumerate() {
                    o[k] |= x.abs() > 1e-12 * scale;
                }
            }
        });
        out
    }

    /// `Σ_k λ_k ∇²d_k` (constant in `c`), a symmetric `2m x 2m` matrix in the unknowns of
    /// `dofs` (only the `x`-`y` blocks are nonzero).
    pub(crate) fn weighted_hessian(&self, lambda: &[f64], dofs: &DofMap) -> Csr {
        let per = self.per_element();
        let m = dofs.num_free();
        let ne = self.shape()[0] * self.shape()[1];
        let (du, dv, dd) = (self.deg_u(), self.deg_v(), self.deg_d());
        let (lu, lv) = (du.len(), dv.len());
        // product weights w(k1, k2) and output index k1 + k2
        let mut w = vec![0.0; lu * lv];
        let mut idx = vec![0usize; lu * lv];
        let bn = &self.binom;
        for k1 in 0..lu {
            // (k1 % p, k1 / p) in degree (p - 1, q); (k2 % (p + 1), k2 / (p + 1)) in (p, q - 1)
            let (u1, v1) = (k1 % self.p, k1 / self.p);
            for k2 in 0..lv {
                let (u2, v2) = (k2 % (self.p + 1), k2 / (self.p + 1));
                let wu = bn.get(du.0[0], u1) * bn.get(dv.0[0], u2) / bn.get(dd.0[0], u1 + u2);
                let wv = bn.get(du.0[1], v1) * bn.get(dv.0[1], v2) / bn.get(dd.0[1], v1 + v2);
                w[k1 * lv + k2] = wu * wv;
                idx[k1 * lv + k2] = (v1 + v2) * (dd.0[0] + 1) + u1 + u2;
            }
        }
        let rows: Vec<Vec<(usize, usize, f64)>> = (0..ne)
            .into_par_iter()
            .filter(|&e| lambda[e * per..(e + 1) * per].iter().any(|&l| l != 0.0))
            .map(|e| {
                let lam = &lambda[e * per..(e + 1) * per];
                let nets = self.nets(e);
                let nloc = nets.global.len();
                let mmat: Vec<f64> = w.iter().zip(&idx).map(|(w, &k)| w * lam[k]).collect();
                // T_ab = U_a^T M V_b: first (U_a^T M) per a
                let um: Vec<Vec<f64>> = nets
                    .u
                    .iter()
                    .map(|u| {
                        let mut r = vec![0.0; lv];
                        for (k1, &x) in u.iter().enumerate() {
                            if x != 0.0 {
                                r.iter_mut().zip(&mmat[k1 * lv..(k1 + 1) * lv]).for_each(|(o, m)| *o += x * m);
                            }
                        }
                        r
                    })
                    .collect();
                let t: Vec<f64> = (0..nloc * nloc)
                    .map(|ab| um[ab / nloc].iter().zip(&nets.v[ab % nloc]).map(|(a, b)| a * b).sum())
                    .collect();
                let mut trip = Vec::new();
                for a in 0..nloc {
                    let fa = dofs.free_index(nets.global[a]);
                    if fa == FIXED {
                        continue;
                    }
                    for b in 0..nloc {
                        let fb = dofs.free_index(nets.global[b]);
                        if fb == FIXED {
                            continue;
                        }
                        let h = t[a * nloc + b] - t[b * nloc + a];
                        if h != 0.0 {
                            trip.push((fa, m + fb, h));
                            trip.push((m + fb, fa, h));
                        }
                    }
                }
                trip
            })
            .collect();
        let all: Vec<(usize, usize, f64)> = rows.into_iter().flatten().collect();
        Csr::from_triplets(2 * m, 2 * m, &all)
    }
}

fn push_column(rows: &mut [Vec<(usize, f64)>], col: &[f64], j: usize) {
    for (r, &v) in rows.iter_mut().zip(col) {
        if v != 0.0 {
            r.push((j, v));
        }
    }
}

#[cfg(test)]
mod tests;
