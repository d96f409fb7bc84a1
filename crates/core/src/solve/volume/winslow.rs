//! The Winslow functional of a volume (the trivariate analogue of the paper's eq. 16):
//!
//! `E(c) = ∫ W(J) dξ`, `W(J) = |cof J|²_F / det J`,
//!
//! where `J = ∇x = [x_ξ x_η x_ζ]` and `cof J = det J · J⁻ᵀ`, with columns
//! `x_η × x_ζ`, `x_ζ × x_ξ`, `x_ξ × x_η`. `E = ∫_Ω |∇ξ|² dx` is the Dirichlet energy of
//! the inverse map, so its minimiser is the map whose inverse is harmonic (elliptic grid
//! generation, eq. 5-6); in the plane `|cof J| = |J|` and `W` is the paper's
//! `(g₁₁ + g₂₂)/det J`. `E = +∞` when `det J <= 0` at a quadrature point (a barrier:
//! Newton's line search never leaves the maps positive at the quadrature points).
//!
//! # Derivatives
//!
//! With the columns `d_a` of `J`, `N = Σ_(a<b) |d_a × d_b|²`, `D = det J`:
//!
//! * `∂D/∂d_a = d_(a+1) × d_(a+2)` (cyclic), `∂²D/∂(d_a)_i ∂(d_b)_j = σ ε_ijk (d_c)_k`
//!   (`σ` the sign of the permutation `(a, b, c)`);
//! * for one pair, `f(a, b) = |a|²|b|² - (a·b)²`: `∂f/∂a = 2(|b|² a - (a·b) b)`,
//!   `∂²f/∂a² = 2(|b|² I - b bᵀ)`, `∂²f/∂a∂b = 4 a bᵀ - 2 b aᵀ - 2 (a·b) I`;
//! * `∇W = ∇N/D - N ∇D/D²`,
//!   `∇²W = ∇²N/D - (∇N ∇Dᵀ + ∇D ∇Nᵀ)/D² + 2N ∇D ∇Dᵀ/D³ - N ∇²D/D²`.
//!
//! `x = Σ_A c_A R_A` is linear in the control points (the rational basis `R_A` with the
//! weights fixed), so `∇E` and `∇²E` are quadrature sums of `∇W`, `∇²W` between the
//! basis gradients `∇R_A`: no other term.

use std::sync::Arc;

use super::assembly::{Local, VolumeDiscretization};
use crate::linalg::sparse::Csr;
use crate::spline::volume::Point3;

/// `W`, `∇W` (9: `d_0, d_1, d_2`) and `∇²W` (9 x 9) at `J` (columns `d`), or `None`
/// when `det J <= 0`.
pub fn density(d: &[Point3; 3], hessian: bool) -> Option<(f64, [f64; 9], [[f64; 9]; 9])> {
    let cross =
        |a: Point3, b: Point3| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let dot = |a: Point3, b: Point3| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cof: [Point3; 3] = std::array::from_fn(|a| cross(d[(a + 1) % 3], d[(a + 2) % 3]));
    let det = dot(d[0], cof[0]);
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    let n: f64 = cof.iter().map(|c| dot(*c, *c)).sum();
    let mut gn = [0.0; 9];
    let mut gd = [0.0; 9];
    for a in 0..3 {
        for &b in &[(a + 1) % 3, (a + 2) % 3] {
            let (bb, ab) = (dot(d[b], d[b]), dot(d[a], d[b]));
            for i in 0..3 {
                gn[3 * a + i] += 2.0 * (bb * d[a][i] - ab * d[b][i]);
            }
        }
        for i in 0..3 {
            gd[3 * a + i] = cof[a][i];
        }
    }
    let w = n / det;
    let mut g = [0.0; 9];
    for k in 0..9 {
        g[k] = gn[k] / det - n * gd[k] / (det * det);
    }
    let mut h = [[0.0; 9]; 9];
    if !hessian {
        return Some((w, g, h));
    }
    // ∇²N and ∇²D
    let mut hn = [[0.0; 9]; 9];
    let mut hd = [[0.0; 9]; 9];
    for a in 0..3 {
        for b in 0..3 {
            if a == b {
                for &o in &[(a + 1) % 3, (a + 2) % 3] {
                    let oo = dot(d[o], d[o]);
                    for i in 0..3 {
                        for j in 0..3 {
                            hn[3 * a + i][3 * a + j] += 2.0 * (if i == j { oo } else { 0.0 } - d[o][i] * d[o][j]);
                        }
                    }
                }
                continue;
            }
            let (u, v) = (d[a], d[b]);
            let uv = dot(u, v);
            let c = 3 - a - b;
            // sign of the permutation (a, b, c)
            let sigma = if (b + 3 - a) % 3 == 1 { 1.0 } else { -1.0 };
            for i in 0..3 {
                for j in 0..3 {
                    hn[3 * a + i][3 * b + j] +=
                        4.0 * u[i] * v[j] - 2.0 * v[i] * u[j] - if i == j { 2.0 * uv } else { 0.0 };
                    if i != j {
                        let k = 3 - i - j;
                        let eps = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
                        hd[3 * a + i][3 * b + j] = sigma * eps * d[c][k];
                    }
                }
            }
        }
    }
    let (d2, d3) = (det * det, det * det * det);
    for k in 0..9 {
        for l in 0..9 {
            h[k][l] = hn[k][l] / det - (gn[k] * gd[l] + gd[k] * gn[l]) / d2 + 2.0 * n * gd[k] * gd[l] / d3
                - n * hd[k][l] / d2;
        }
    }
    Some((w, g, h))
}

/// The Winslow energy of volumes on one [`VolumeDiscretization`] (its basis, weights,
/// free unknowns and pattern).
#[derive(Debug, Clone)]
pub(crate) struct WinslowVolume {
    disc: Arc<VolumeDiscretization>,
}

/// Energy, gradient (of the free coordinates) and Hessian of [`WinslowVolume`].
#[derive(Debug, Clone)]
pub(crate) struct Evaluation {
    /// `E(c)` (`+∞` when `det J <= 0` at a quadrature point).
    pub energy: f64,
    /// `∇E` over the free coordinates, `3 f + component`.
    pub gradient: Vec<f64>,
    /// `∇²E` over the free coordinates.
    pub hessian: Option<Csr>,
}

impl WinslowVolume {
    /// The energy on the basis of `vol` (its knots and weights), with `g` Gauss points
    /// per direction and element (`max degree + 1` is enough for polynomial maps).
    #[cfg(test)]
    pub fn new(vol: &crate::spline::volume::Volume, g: usize) -> Self {
        Self { disc: Arc::new(VolumeDiscretization::new(vol, g)) }
    }

    /// The energy on the discretization `disc`.
    pub fn on(disc: Arc<VolumeDiscretization>) -> Self {
        Self { disc }
    }

    /// The element's quadrature: weights `w_q` and `∇R_A` at every point (`q m + a`),
    /// tensor products of the univariate tables, `R = w N / W`,
    /// `∇R = (w ∇N W - w N ∇W) / W²`.
    fn element_points(&self, e: usize, idx: &[usize]) -> (Vec<f64>, Vec<Point3>) {
        let [bx, by, bz] = self.disc.element_tables(e);
        let p = [bx[0].0.degree, by[0].0.degree, bz[0].0.degree];
        let m = idx.len();
        let nq = bx.len() * by.len() * bz.len();
        let mut weights = Vec::with_capacity(nq);
        let mut grads = Vec::with_capacity(nq * m);
        // per point: n = w N and ∇n of every function (`a` fastest)
        let (mut n, mut gn) = (vec![0.0; m], [vec![0.0; m], vec![0.0; m], vec![0.0; m]]);
        let w: Vec<f64> =
            self.disc.weights.as_ref().map_or_else(|| vec![1.0; m], |w| idx.iter().map(|&l| w[l]).collect());
        let na = p[0] + 1;
        for (z, wz) in bz {
            for (y, wy) in by {
                for (x, wx) in bx {
                    let mut lin = 0;
                    for c in 0..=p[2] {
                        for b in 0..=p[1] {
                            let (y0, y1, z0, z1) = (y.d[0][b], y.d[1][b], z.d[0][c], z.d[1][c]);
                            for a in 0..na {
                                let wa = w[lin + a];
                                n[lin + a] = wa * x.d[0][a] * y0 * z0;
                                gn[0][lin + a] = wa * x.d[1][a] * y0 * z0;
                                gn[1][lin + a] = wa * x.d[0][a] * y1 * z0;
                                gn[2][lin + a] = wa * x.d[0][a] * y0 * z1;
                            }
                            lin += na;
                        }
                    }
                    // the sums in the order of the functions
                    let (mut wsum, mut wgrad) = (0.0, [0.0; 3]);
                    for a in 0..m {
                        wsum += n[a];
                        for q in 0..3 {
                            wgrad[q] += gn[q][a];
                        }
                    }
                    let w2 = wsum * wsum;
                    grads.extend(
                        (0..m).map(|a| -> Point3 { std::array::from_fn(|q| (gn[q][a] * wsum - n[a] * wgrad[q]) / w2) }),
                    );
                    weights.push(wx * wy * wz);
                }
            }
        }
        (weights, grads)
    }

    /// Element `e`'s energy, gradient and Hessian (see [`Local`]); `None` when
    /// `det J <= 0` at one of its points.
    ///
    /// The Hessian is one matrix product: with `U[(i_b, i_a, a), (q, c')] =
    /// w_q Σ_c ∂_c R_a(q) ∂²W/∂(d_c)_(i_a) ∂(d_c')_(i_b)` and `G[(q, c'), b] = ∂_c' R_b(q)`,
    /// `∂²E_e / ∂x_(a, i_a) ∂x_(b, i_b) = (U G)[(i_b, i_a, a), b]`.
    fn element(&self, e: usize, cps: &[Point3], hessian: bool) -> Option<Local> {
        let idx = self.disc.element_indices(e);
        let (weights, grads) = self.element_points(e, &idx);
        let (m, nq) = (idx.len(), weights.len());
        let mut energy = 0.0;
        let mut g = vec![0.0; 3 * m];
        // (written in order, no zero fill first)
        let mut u = Vec::with_capacity(if hessian { 27 * m * nq } else { 0 });
        // the gradients by component, for the columns of U
        let soa: [Vec<f64>; 3] =
            if hessian { std::array::from_fn(|c| grads.iter().map(|g| g[c]).collect()) } else { Default::default() };
        for (q, &wq) in weights.iter().enumerate() {
            let gq = &grads[q * m..(q + 1) * m];
            let mut d = [[0.0; 3]; 3];
            for (a, gr) in gq.iter().enumerate() {
                let c = cps[idx[a]];
                for col in 0..3 {
                    for comp in 0..3 {
                        d[col][comp] += c[comp] * gr[col];
                    }
                }
            }
            let (w, gw, hw) = density(&d, hessian)?;
            energy += wq * w;
            for (a, gr) in gq.iter().enumerate() {
                for comp in 0..3 {
                    let mut s = 0.0;
                    for col in 0..3 {
                        s += gw[3 * col + comp] * gr[col];
                    }
                    g[3 * a + comp] += wq * s;
                }
            }
            if hessian {
                let (gx, gy, gz) =
                    (&soa[0][q * m..(q + 1) * m], &soa[1][q * m..(q + 1) * m], &soa[2][q * m..(q + 1) * m]);
                // U's columns (3 q + c_b), rows (3 i_b + i_a) m + a, in order
                for cb in 0..3 {
                    for ib in 0..3 {
                        let kb = 3 * cb + ib;
                        for ia in 0..3 {
                            let (h0, h1, h2) = (wq * hw[ia][kb], wq * hw[3 + ia][kb], wq * hw[6 + ia][kb]);
                            u.extend(gx.iter().zip(gy).zip(gz).map(|((&x, &y), &z)| h0 * x + h1 * y + h2 * z));
                        }
                    }
                }
            }
        }
        let mut k = Vec::new();
        if hessian {
            let mut gm = vec![0.0; 3 * nq * m];
            for b in 0..m {
                for q in 0..nq {
                    gm[b * 3 * nq + 3 * q..b * 3 * nq + 3 * q + 3].copy_from_slice(&grads[q * m + b]);
                }
            }
            k = vec![0.0; 9 * m * m];
            faer::linalg::matmul::matmul(
                faer::MatMut::from_column_major_slice_mut(&mut k, 9 * m, m),
                faer::Accum::Replace,
                faer::MatRef::from_column_major_slice(&u, 9 * m, 3 * nq),
                faer::MatRef::from_column_major_slice(&gm, 3 * nq, m),
                1.0,
                faer::Par::Seq,
            );
        }
        Some(Local { idx, scalar: energy, vector: g, matrix: k, scalar_matrix: Vec::new() })
    }

    /// Number of free scalar unknowns (3 per interior control point).
    pub fn unknowns(&self) -> usize {
        self.disc.unknowns()
    }

    /// `E`, and `∇E` (and `∇²E` when `hessian`) at the control points `cps`; the
    /// gradient is empty and the Hessian `None` when `E = +∞`
    /// ([`VolumeDiscretization::assemble`]).
    pub fn evaluate(&self, cps: &[Point3], hessian: bool) -> Evaluation {
        match self.disc.assemble(hessian, false, |e| self.element(e, cps, hessian)) {
            Some((energy, gradient, hessian, _)) => Evaluation { energy, gradient, hessian },
            None => Evaluation { energy: f64::INFINITY, gradient: Vec::new(), hessian: None },
        }
    }

    /// Hand back a Hessian no longer needed ([`VolumeDiscretization::recycle`]).
    pub fn recycle(&self, hessian: Csr) {
        self.disc.recycle(hessian)
    }

    /// The free coordinates of `cps` (`3 f + component`).
    pub fn gather(&self, cps: &[Point3]) -> Vec<f64> {
        self.disc.gather(cps)
    }

    /// `cps` with the free coordinates set to `x`.
    pub fn scatter(&self, cps: &mut [Point3], x: &[f64]) {
        self.disc.scatter(cps, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    fn sample_j() -> [Point3; 3] {
        [[1.2, 0.1, -0.2], [0.3, 0.9, 0.15], [-0.1, 0.25, 1.4]]
    }

    /// `∇W` and `∇²W` of the density against central differences.
    #[test]
    fn density_derivatives_match_finite_differences() {
        let d = sample_j();
        let (_, g, h) = density(&d, true).unwrap();
        let eps = 1e-6;
        for k in 0..9 {
            let mut p = d;
            let mut m = d;
            p[k / 3][k % 3] += eps;
            m[k / 3][k % 3] -= eps;
            let (wp, gp, _) = density(&p, false).unwrap();
            let (wm, gm, _) = density(&m, false).unwrap();
            assert!((g[k] - (wp - wm) / (2.0 * eps)).abs() < 1e-7 * (1.0 + g[k].abs()), "grad {k}");
            for l in 0..9 {
                let fd = (gp[l] - gm[l]) / (2.0 * eps);
                assert!((h[l][k] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "hess {l} {k}: {} vs {fd}", h[l][k]);
            }
        }
        // W(I) = 3; W is homogeneous of degree 1; a reflection is outside the barrier
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!((density(&id, false).unwrap().0 - 3.0).abs() < 1e-15);
        let s = d.map(|c| c.map(|x| 2.0 * x));
        let (w1, w2) = (density(&d, false).unwrap().0, density(&s, false).unwrap().0);
        assert!((w2 - 2.0 * w1).abs() < 1e-12 * w1);
        let mut flipped = d;
        flipped[0] = flipped[0].map(|x| -x);
        assert!(density(&flipped, false).is_none());
    }

    /// The assembled gradient and Hessian of the energy against central differences
    /// of the energy and the gradient, on a rational curved volume.
    #[test]
    fn energy_gradient_and_hessian_match_finite_differences() {
        let (vol, cps) = super::super::tests::curved_rational_volume([
            KnotVector::open_uniform(2, 2),
            KnotVector::open_uniform(2, 1),
            KnotVector::open_from_breaks(2, &[0.0, 0.4, 1.0], 1),
        ]);
        let shape = vol.shape();
        let e = WinslowVolume::new(&vol, 4);
        assert_eq!(e.unknowns(), 3 * (shape[0] - 2) * (shape[1] - 2) * (shape[2] - 2));
        let at = e.evaluate(&cps, true);
        assert!(at.energy.is_finite());
        let x0 = e.gather(&cps);
        let h = at.hessian.unwrap();
        let eps = 1e-6;
        for k in 0..x0.len() {
            let shifted = |s: f64| {
                let mut x = x0.clone();
                x[k] += s;
                let mut c = cps.clone();
                e.scatter(&mut c, &x);
                e.evaluate(&c, false)
            };
            let (p, m) = (shifted(eps), shifted(-eps));
            let fd = (p.energy - m.energy) / (2.0 * eps);
            assert!((at.gradient[k] - fd).abs() < 1e-7 * (1.0 + fd.abs()), "grad {k}: {} vs {fd}", at.gradient[k]);
            for l in 0..x0.len() {
                let fd = (p.gradient[l] - m.gradient[l]) / (2.0 * eps);
                assert!((h.get(l, k) - fd).abs() < 1e-6 * (1.0 + fd.abs()), "hess {l} {k}: {} vs {fd}", h.get(l, k));
            }
        }
    }
}
