//! Elliptic grid generation of a volume in Galerkin form: the 3D analogue of the
//! paper's eq. (8), its residual and exact Jacobian, and Newton's method on it.
//!
//! # The equation
//!
//! EGG asks the inverse map `ξ(x)` (components `ξ₁, ξ₂, ξ₃`) to be harmonic, `Δξ_k = 0`
//! (eq. 5 in 3D). Differentiating `x(ξ(x)) = x` twice and summing over the physical
//! coordinates gives `Σ_ij (G⁻¹)_ij ∂_i∂_j x = -J Δξ` with `J = ∇x = [x_ξ x_η x_ζ]` and
//! `G = JᵀJ`, so for an invertible `J` the inverted system (eq. 6 in 3D) is
//! `Σ_ij (G⁻¹)_ij ∂_i∂_j x = 0`. Multiplied by `det G = (det J)²`, with
//! `adj G = adj J adj Jᵀ = Cᵀ C` for the cofactor matrix `C = cof J = det J · J⁻ᵀ`
//! (columns `c₁ = x_η × x_ζ`, `c₂ = x_ζ × x_ξ`, `c₃ = x_ξ × x_η`), it is polynomial in
//! the derivatives:
//!
//! `L(x) = Σ_ij A_ij ∂_i∂_j x = 0`, `A = Cᵀ C`, `A_ij = c_i · c_j`.
//!
//! In the plane `c₁ = (y_η, -x_η)`, `c₂ = (-y_ξ, x_ξ)`, so `A = [[g₂₂, -g₁₂], [-g₁₂, g₁₁]]`
//! and `L` is the paper's `g₂₂ x_ξξ - 2 g₁₂ x_ξη + g₁₁ x_ηη` (eq. 4). As in 2D (and in
//! G+Smo) the operator is scaled by `tr A = |cof J|²_F` (the plane's `g₁₁ + g₂₂`), which
//! makes it homogeneous of degree 1 in `x`. The Galerkin form (eq. 8 in 3D):
//!
//! `F_(A,c)(x) = ∫ R_A (Σ_ij A_ij ∂_i∂_j x_c) / tr A dξ = 0`
//!
//! for every interior basis function `R_A` and component `c`, the boundary control points
//! the Dirichlet data. Second derivatives appear, so the basis must be `C¹` (degree 2 or
//! more, no knot of multiplicity `p`); no `det J` is divided by, so any start will do
//! (the Coons patch), unlike the Winslow functional.
//!
//! # Jacobian
//!
//! With `X_c = ∇²x_c`, `T = tr A`, `L_c = (A : X_c) / T` and the basis function `B` moving
//! component `d`, `∂d_a/∂c_(B,d) = ∂_a R_B e_d`, so
//!
//! `∂L_c/∂c_(B,d) = δ_cd (A : ∇²R_B)/T + Σ_a ∂_a R_B s_(c,a,d)`,
//! `s_(c,a,d) = (∂A/∂(d_a)_d : X_c - L_c ∂T/∂(d_a)_d) / T`,
//!
//! where `∂c_i/∂(d_a)_d` is `e_d × d_(i+2)` for `a = i + 1`, `d_(i+1) × e_d` for
//! `a = i + 2` (cyclic) and zero for `a = i`; `∂A_ij = ∂c_i · c_j + c_i · ∂c_j`,
//! `∂T = 2 Σ_i c_i · ∂c_i`. The element Jacobian is one matrix product
//! `K = P Q`, `P[a, q] = w_q R_a(q)`, `Q[q, (b, i_b, i_a)] = ∂L_(i_a)/∂c_(b, i_b)` at `q`.
//! The quadrature tables, free unknowns and sparsity pattern are those of the 3D Winslow
//! functional ([`VolumeDiscretization`]).

use std::sync::Arc;

use super::assembly::{Local, VolumeDiscretization};
use super::tensor_points;
use crate::linalg::sparse::Csr;
use crate::spline::volume::Point3;
use metric::{cross, dot};

/// Pairs `(i, j)` of the six second derivatives, in the order they are stored.
const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// `A : H` for symmetric `A` and `H` given by the six entries of [`PAIRS`].
fn contract(a: &[[f64; 3]; 3], h: &[f64; 6]) -> f64 {
    PAIRS.iter().zip(h).map(|(&(i, j), v)| if i == j { a[i][j] * v } else { 2.0 * a[i][j] * v }).sum()
}

/// The table of one point (see `EggVolume::element_points`) of the B-splines `N` made
/// that of the rational basis `R = w N / Σ w N` with the weights `w`.
fn rational(table: &mut [f64], w: impl Iterator<Item = f64>) {
    let m = table.len() / 10;
    for (a, wa) in w.enumerate() {
        for k in 0..10 {
            table[k * m + a] *= wa;
        }
    }
    let sum = |k: usize| table[k * m..(k + 1) * m].iter().sum::<f64>();
    let (ws, wg, wh): (f64, [f64; 3], [f64; 6]) =
        (sum(0), std::array::from_fn(|i| sum(1 + i)), std::array::from_fn(|k| sum(4 + k)));
    for a in 0..m {
        let r = table[a] / ws;
        let gr: Point3 = std::array::from_fn(|i| (table[(1 + i) * m + a] - r * wg[i]) / ws);
        for k in 0..6 {
            let (i, j) = PAIRS[k];
            table[(4 + k) * m + a] = (table[(4 + k) * m + a] - gr[i] * wg[j] - gr[j] * wg[i] - r * wh[k]) / ws;
        }
        table[a] = r;
        for i in 0..3 {
            table[(1 + i) * m + a] = gr[i];
        }
    }
}

/// The scaled EGG operator of volumes on one [`VolumeDiscretization`].
#[derive(Debug, Clone)]
pub struct EggVolume {
    disc: Arc<VolumeDiscretization>,
}

/// Residual (of the free coordinates) and Jacobian of [`EggVolume`].
#[derive(Debug, Clone)]
pub struct EggEvaluation {
    /// `F` over the free coordinates, `3 f + component` (empty when `tr A = 0` at a
    /// quadrature point).
    pub residual: Vec<f64>,
    /// `∂F/∂c` over the free coordinates.
    pub jacobian: Option<Csr>,
    /// The stiffness of the cofactor metric over the free control points (one scalar
    /// unknown each), `K_AB = ∫ ∇R_A · (A / tr A) ∇R_B dξ`: SPD where `det J ≠ 0`, and
    /// `-diag(K, K, K)` is the Jacobian's principal part (integrate `R_A (A : ∇²R_B) / T`
    /// by parts), the preconditioner of its GMRES solve.
    pub laplace: Option<Csr>,
    /// The Winslow energy `∫ |cof J|²_F / det J dξ = ∫ tr A / det J dξ` at the same
    /// points (`super::winslow`'s functional, to rounding; `+∞` where `det J <= 0`),
    /// for the report: `tr A` is at hand and `det J = d₀ · c₀`.
    pub energy: f64,
}

/// The Winslow density `tr A / det J` at a point of the columns `d` of `J` and its
/// cofactor columns `cof` (`det J = d₀ · c₀`), `+∞` where `det J <= 0`.
fn winslow_density(d: &[Point3; 3], cof: &[Point3; 3], t: f64) -> f64 {
    let det = dot(d[0], cof[0]);
    if det > 0.0 {
        t / det
    } else {
        f64::INFINITY
    }
}

impl EggVolume {
    /// The operator on the basis of `vol` (its knots and weights), `g` Gauss points per
    /// direction and element.
    #[cfg(test)]
    pub fn new(vol: &crate::spline::volume::Volume, g: usize) -> Self {
        Self { disc: Arc::new(VolumeDiscretization::new(vol, g)) }
    }

    /// The operator on the discretization `disc`.
    pub fn on(disc: Arc<VolumeDiscretization>) -> Self {
        Self { disc }
    }

    /// Its discretization.
    #[cfg(test)]
    pub fn discretization(&self) -> &VolumeDiscretization {
        &self.disc
    }

    /// The element's quadrature: weights `w_q`, and at every point `q` the table
    /// `B[(10 q + k) m + a]` of `R_a` (`k = 0`), `∇R_a` (`k = 1..4`) and `∇²R_a` (`k =
    /// 4..10`, the six entries of [`PAIRS`]); tensor products of the univariate tables,
    /// and for a rational basis `R = n / W`, `∇R = (∇n - R ∇W) / W`,
    /// `∂_ij R = (∂_ij n - ∂_i R ∂_j W - ∂_j R ∂_i W - R ∂_ij W) / W` with `n = w N` and
    /// `W = Σ n`.
    fn element_points(&self, e: usize, idx: &[usize]) -> (Vec<f64>, Vec<f64>) {
        let [bx, by, bz] = self.disc.element_tables(e);
        let p = [bx[0].0.degree, by[0].0.degree, bz[0].0.degree];
        let m = idx.len();
        let nq = bx.len() * by.len() * bz.len();
        let mut weights = Vec::with_capacity(nq);
        // written in order (no zero fill first)
        let mut basis = Vec::with_capacity(nq * 10 * m);
        let (na, nb) = (p[0] + 1, p[1] + 1);
        // (x derivative, yz factor) of each of the ten rows
        const ROWS: [(usize, usize); 10] =
            [(0, 0), (1, 0), (0, 1), (0, 2), (2, 0), (0, 3), (0, 4), (1, 1), (1, 2), (0, 5)];
        // over the functions (`lin = (c nb + b) na + a`): the x-table repeated per (b, c),
        // per x-point and derivative, and the six yz products per (y, z)-point, so that
        // every row of the table is one product of two vectors of length m
        let xs: Vec<[Vec<f64>; 3]> =
            bx.iter().map(|(x, _)| std::array::from_fn(|dx| (0..m).map(|lin| x.d[dx][lin % na]).collect())).collect();
        let mut yz = [vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]];
        for (z, wz) in bz {
            for (y, wy) in by {
                for lin in 0..m {
                    let (b, c) = ((lin / na) % nb, lin / (na * nb));
                    let (y0, y1, y2, z0, z1, z2) = (y.d[0][b], y.d[1][b], y.d[2][b], z.d[0][c], z.d[1][c], z.d[2][c]);
                    for (f, v) in [y0 * z0, y1 * z0, y0 * z1, y2 * z0, y0 * z2, y1 * z1].into_iter().enumerate() {
                        yz[f][lin] = v;
                    }
                }
                for ((_, wx), xq) in bx.iter().zip(&xs) {
                    let q = weights.len();
                    for &(dx, f) in &ROWS {
                        basis.extend(xq[dx].iter().zip(&yz[f]).map(|(&xa, &v)| xa * v));
                    }
                    if let Some(w) = self.disc.weights.as_ref() {
                        rational(&mut basis[q * 10 * m..(q + 1) * 10 * m], idx.iter().map(|&l| w[l]));
                    }
                    weights.push(wx * wy * wz);
                }
            }
        }
        (weights, basis)
    }

    /// Element `e`'s residual, Jacobian (when `jacobian`) and cofactor-metric stiffness
    /// `K_ab = Σ_q w_q ∇R_a · (A/T) ∇R_b` (when `laplace`), through the basis tables of
    /// [`EggVolume::element_points`] (see [`Local`]; the scalar is the element's Winslow
    /// energy, [`EggEvaluation::energy`]); `None` when `tr A = 0` at one of its points.
    fn element(&self, e: usize, cps: &[Point3], jacobian: bool, laplace: bool) -> Option<Local> {
        let idx = self.disc.element_indices(e);
        let (weights, basis) = self.element_points(e, &idx);
        let (m, nq) = (idx.len(), weights.len());
        // x, ∇x and ∇²x at every point: X[(10 q + k), c] = Σ_a B[(10 q + k), a] c_(a, c)
        let mut cl = vec![0.0; 3 * m];
        for (a, &lin) in idx.iter().enumerate() {
            for c in 0..3 {
                cl[c * m + a] = cps[lin][c];
            }
        }
        let mut xq = vec![0.0; 30 * nq];
        faer::linalg::matmul::matmul(
            faer::MatMut::from_column_major_slice_mut(&mut xq, 10 * nq, 3),
            faer::Accum::Replace,
            faer::MatRef::from_row_major_slice(&basis, 10 * nq, m),
            faer::MatRef::from_column_major_slice(&cl, m, 3),
            1.0,
            faer::Par::Seq,
        );
        // the residual by component (`c m + a`), interleaved at the end
        let mut rc = vec![0.0; 3 * m];
        // Q[q, (3 i_b + i_a) m + b] = ∂L_(i_a)/∂c_(b, i_b) at q (rows of b contiguous)
        // (written in order, no zero fill first)
        let mut qm = Vec::with_capacity(if jacobian { nq * 9 * m } else { 0 });
        // K = U V: U[a, (q, i)] = w_q ((A/T) ∇R_a)_i, V[(q, i), b] = ∂_i R_b
        let (mut um, mut vm) =
            if laplace { (vec![0.0; 3 * nq * m], vec![0.0; 3 * nq * m]) } else { (Vec::new(), Vec::new()) };
        let mut v = vec![0.0; if jacobian { m } else { 0 }];
        let mut energy = 0.0;
        for (q, &wq) in weights.iter().enumerate() {
            let table = &basis[q * 10 * m..(q + 1) * 10 * m];
            let (rq, gq, hq) = (&table[..m], &table[m..4 * m], &table[4 * m..]);
            let (g0, g1, g2) = (&gq[..m], &gq[m..2 * m], &gq[2 * m..]);
            // J's columns and the components' Hessians
            let d: [Point3; 3] = std::array::from_fn(|col| std::array::from_fn(|c| xq[c * 10 * nq + 10 * q + 1 + col]));
            let xh: [[f64; 6]; 3] = std::array::from_fn(|c| std::array::from_fn(|k| xq[c * 10 * nq + 10 * q + 4 + k]));
            let cof: [Point3; 3] = std::array::from_fn(|i| cross(d[(i + 1) % 3], d[(i + 2) % 3]));
            let am: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| dot(cof[i], cof[j])));
            let t = am[0][0] + am[1][1] + am[2][2];
            if t.is_nan() || t <= 0.0 {
                return None;
            }
            energy += wq * winslow_density(&d, &cof, t);
            let l: [f64; 3] = std::array::from_fn(|c| contract(&am, &xh[c]) / t);
            for (c, &lc) in l.iter().enumerate() {
                for (r, &ra) in rc[c * m..(c + 1) * m].iter_mut().zip(rq) {
                    *r += wq * ra * lc;
                }
            }
            if laplace {
                for i in 0..3 {
                    let (a0, a1, a2) = (am[i][0], am[i][1], am[i][2]);
                    let row = &mut um[(3 * q + i) * m..(3 * q + i + 1) * m];
                    for (((u, &x0), &x1), &x2) in row.iter_mut().zip(g0).zip(g1).zip(g2) {
                        *u = wq * (a0 * x0 + a1 * x1 + a2 * x2) / t;
                    }
                    vm[(3 * q + i) * m..(3 * q + i + 1) * m].copy_from_slice(&gq[i * m..(i + 1) * m]);
                }
            }
            if !jacobian {
                continue;
            }
            // s[c][a][dd] = (∂A/∂(d_a)_dd : X_c - L_c ∂T/∂(d_a)_dd) / T
            let mut s = [[[0.0; 3]; 3]; 3];
            for a in 0..3 {
                for dd in 0..3 {
                    let mut ed = [0.0; 3];
                    ed[dd] = 1.0;
                    let dc: [Point3; 3] = std::array::from_fn(|i| {
                        if a == (i + 1) % 3 {
                            cross(ed, d[(i + 2) % 3])
                        } else if a == (i + 2) % 3 {
                            cross(d[(i + 1) % 3], ed)
                        } else {
                            [0.0; 3]
                        }
                    });
                    let da: [[f64; 3]; 3] =
                        std::array::from_fn(|i| std::array::from_fn(|j| dot(dc[i], cof[j]) + dot(cof[i], dc[j])));
                    let dt = da[0][0] + da[1][1] + da[2][2];
                    for c in 0..3 {
                        s[c][a][dd] = (contract(&da, &xh[c]) - l[c] * dt) / t;
                    }
                }
            }
            // v_b = A : ∇²R_b / T, the coefficients in the order of PAIRS
            let ah: [f64; 6] = std::array::from_fn(|k| {
                let (i, j) = PAIRS[k];
                if i == j {
                    am[i][j] / t
                } else {
                    2.0 * am[i][j] / t
                }
            });
            let h: [&[f64]; 6] = std::array::from_fn(|k| &hq[k * m..(k + 1) * m]);
            for (b, vb) in v.iter_mut().enumerate() {
                *vb = ah[0] * h[0][b]
                    + ah[1] * h[1][b]
                    + ah[2] * h[2][b]
                    + ah[3] * h[3][b]
                    + ah[4] * h[4][b]
                    + ah[5] * h[5][b];
            }
            for ib in 0..3 {
                for ia in 0..3 {
                    let (s0, s1, s2) = (s[ia][0][ib], s[ia][1][ib], s[ia][2][ib]);
                    let cols = g0.iter().zip(g1).zip(g2);
                    if ia == ib {
                        qm.extend(cols.zip(&v).map(|(((&x0, &x1), &x2), &vb)| x0 * s0 + x1 * s1 + x2 * s2 + vb));
                    } else {
                        qm.extend(cols.map(|((&x0, &x1), &x2)| x0 * s0 + x1 * s1 + x2 * s2));
                    }
                }
            }
        }
        let mut res = vec![0.0; 3 * m];
        for (a, r) in res.chunks_exact_mut(3).enumerate() {
            for (c, x) in r.iter_mut().enumerate() {
                *x = rc[c * m + a];
            }
        }
        let mut k = Vec::new();
        if jacobian {
            let mut pm = vec![0.0; m * nq];
            for (q, &wq) in weights.iter().enumerate() {
                for a in 0..m {
                    pm[q * m + a] = wq * basis[q * 10 * m + a];
                }
            }
            // P Q, column-major: entry (a, (3 i_b + i_a) m + b) at ((3 i_b + i_a) m + b) m + a
            let mut pq = vec![0.0; 9 * m * m];
            faer::linalg::matmul::matmul(
                faer::MatMut::from_column_major_slice_mut(&mut pq, m, 9 * m),
                faer::Accum::Replace,
                faer::MatRef::from_column_major_slice(&pm, m, nq),
                faer::MatRef::from_row_major_slice(&qm, nq, 9 * m),
                1.0,
                faer::Par::Seq,
            );
            // to the layout of `Local`: (a, i_a; b, i_b) at b 9m + (3 i_b + i_a) m + a
            k = Vec::with_capacity(9 * m * m);
            for b in 0..m {
                for blk in 0..9 {
                    k.extend_from_slice(&pq[(blk * m + b) * m..(blk * m + b + 1) * m]);
                }
            }
        }
        let mut kl = Vec::new();
        if laplace {
            kl = vec![0.0; m * m];
            faer::linalg::matmul::matmul(
                faer::MatMut::from_column_major_slice_mut(&mut kl, m, m),
                faer::Accum::Replace,
                faer::MatRef::from_column_major_slice(&um, m, 3 * nq),
                faer::MatRef::from_column_major_slice(&vm, m, 3 * nq).transpose(),
                1.0,
                faer::Par::Seq,
            );
        }
        Some(Local { idx, scalar: energy, vector: res, matrix: k, scalar_matrix: kl })
    }

    /// Element `e`'s residual (`dir` `None`) or its part of the Jacobian's product
    /// `F'(c) v` with the displacement `dir` of the control points (zero at the fixed
    /// ones), without the Jacobian: at each point, with `δd_a = ∂_a δx` and
    /// `δX_c = ∇²δx_c` of `δx = Σ_B R_B dir_B`,
    ///
    /// `δL_c = (δA : X_c + A : δX_c - L_c δT) / T`, `δA_ij = δc_i · c_j + c_i · δc_j`,
    /// `δc_i = δd_(i+1) × d_(i+2) + d_(i+1) × δd_(i+2)`, `δT = tr δA`
    ///
    /// (the directional derivative of `L_c`, which the Jacobian's columns of
    /// [`EggVolume::element`] hold per basis function), and `δF_(a,c) = Σ_q w_q R_a δL_c`.
    /// On a polynomial basis the values at the points and the integrals are sum
    /// factorised ([`super::tensor_points`]), on a rational one they go through the
    /// basis tables of [`EggVolume::element_points`]. `None` when `tr A = 0` at one of
    /// its points.
    ///
    /// With the residual (`dir` `None`) come the element's Winslow energy (the scalar,
    /// [`EggEvaluation::energy`]) and, when `laplace` (polynomial basis only), the
    /// cofactor-metric stiffness `K` of [`EggVolume::element`], sum factorised
    /// ([`tensor_points::stiffness`] with `C = w_q A / T`).
    fn element_linear(&self, e: usize, cps: &[Point3], dir: Option<&[Point3]>, laplace: bool) -> Option<Local> {
        let idx = self.disc.element_indices(e);
        let m = idx.len();
        let k = if dir.is_some() { 6 } else { 3 };
        // x (columns 0..3) and δx (columns 3..6)
        let mut cl = vec![0.0; k * m];
        for (a, &lin) in idx.iter().enumerate() {
            for c in 0..3 {
                cl[c * m + a] = cps[lin][c];
                if let Some(dir) = dir {
                    cl[(3 + c) * m + a] = dir[lin][c];
                }
            }
        }
        let tables = self.disc.element_tables(e);
        // their values, gradients and Hessians at every point, as rows over the points,
        // X[(10 c + row) n_q + q]
        let (weights, xq, basis) = if self.disc.weights.is_some() {
            let (weights, basis) = self.element_points(e, &idx);
            let nq = weights.len();
            // X[c 10 n_q + 10 q + row], then moved to the rows
            let mut xt = vec![0.0; k * 10 * nq];
            faer::linalg::matmul::matmul(
                faer::MatMut::from_column_major_slice_mut(&mut xt, 10 * nq, k),
                faer::Accum::Replace,
                faer::MatRef::from_row_major_slice(&basis, 10 * nq, m),
                faer::MatRef::from_column_major_slice(&cl, m, k),
                1.0,
                faer::Par::Seq,
            );
            let mut xq = vec![0.0; k * 10 * nq];
            for (xc, tc) in xq.chunks_exact_mut(10 * nq).zip(xt.chunks_exact(10 * nq)) {
                for (q, point) in tc.chunks_exact(10).enumerate() {
                    for (row, &v) in point.iter().enumerate() {
                        xc[row * nq + q] = v;
                    }
                }
            }
            (weights, xq, Some(basis))
        } else {
            (tensor_points::weights(tables), tensor_points::values(tables, &cl), None)
        };
        let nq = weights.len();
        // w_q δL_c(q) (or w_q L_c(q)) per component, `c n_q + q`
        let mut f = vec![0.0; 3 * nq];
        // w_q A_ij / T, `(3 i + j) n_q + q`
        let laplace = laplace && dir.is_none() && basis.is_none();
        let mut coef = vec![0.0; if laplace { 9 * nq } else { 0 }];
        let mut energy = 0.0;
        let ok = if dir.is_none() {
            let mut density = vec![0.0; nq];
            let ok = metric::residual(&weights, &xq, &mut f, &mut density, &mut coef);
            // in point order, as a sum over the points
            energy = density.iter().fold(energy, |e, d| e + d);
            ok
        } else {
            metric::linearised(&weights, &xq, &mut f)
        };
        if !ok {
            return None;
        }
        // Σ_q R_a(q) f_c(q), `c m + a`
        let rc = match basis {
            Some(basis) => {
                let mut rc = vec![0.0; 3 * m];
                for q in 0..nq {
                    let rq = &basis[q * 10 * m..q * 10 * m + m];
                    for c in 0..3 {
                        let fq = f[c * nq + q];
                        for (r, &ra) in rc[c * m..(c + 1) * m].iter_mut().zip(rq) {
                            *r += ra * fq;
                        }
                    }
                }
                rc
            }
            None => tensor_points::integrals(tables, &f),
        };
        let mut res = vec![0.0; 3 * m];
        for (a, r) in res.chunks_exact_mut(3).enumerate() {
            for (c, x) in r.iter_mut().enumerate() {
                *x = rc[c * m + a];
            }
        }
        let scalar_matrix = if laplace { tensor_points::stiffness(tables, &coef) } else { Vec::new() };
        Some(Local { idx, scalar: energy, vector: res, matrix: Vec::new(), scalar_matrix })
    }

    /// `F'(c) v` over the free coordinates (`3 f + component`, as the residual) without
    /// assembling the Jacobian ([`EggVolume::element_linear`], elements added in
    /// order): the assembled Jacobian's product to rounding, at the cost of about one
    /// residual. `None` when `tr A = 0` at a quadrature point.
    fn jacobian_times(&self, cps: &[Point3], v: &[f64]) -> Option<Vec<f64>> {
        let mut dir = vec![[0.0; 3]; cps.len()];
        self.disc.scatter(&mut dir, v);
        self.disc.assemble(false, false, |e| self.element_linear(e, cps, Some(&dir), false)).map(|(_, y, _, _)| y)
    }

    /// Number of free scalar unknowns (3 per interior control point).
    pub fn unknowns(&self) -> usize {
        self.disc.unknowns()
    }

    /// `F` (and `∂F/∂c` when `jacobian`) at the control points `cps`
    /// ([`VolumeDiscretization::assemble`]).
    pub fn evaluate(&self, cps: &[Point3], jacobian: bool) -> EggEvaluation {
        self.evaluate_with(cps, jacobian, false)
    }

    /// [`EggVolume::evaluate`], with the cofactor-metric stiffness `K` of the scalar
    /// unknowns when `laplace` ([`EggEvaluation::laplace`]).
    ///
    /// Without the Jacobian the residual (and `K` on a polynomial basis) come from
    /// [`EggVolume::element_linear`] (sum factorised), the Jacobian (and `K` on a
    /// rational basis) from the basis tables of [`EggVolume::element`].
    pub fn evaluate_with(&self, cps: &[Point3], jacobian: bool, laplace: bool) -> EggEvaluation {
        let tables = jacobian || laplace && self.disc.weights.is_some();
        let element = |e| {
            if tables {
                self.element(e, cps, jacobian, laplace)
            } else {
                self.element_linear(e, cps, None, laplace)
            }
        };
        match self.disc.assemble(jacobian, laplace, element) {
            Some((energy, residual, jacobian, laplace)) => EggEvaluation { residual, jacobian, laplace, energy },
            None => EggEvaluation { residual: Vec::new(), jacobian: None, laplace: None, energy: f64::INFINITY },
        }
    }
}

mod metric;
mod newton;

pub(super) use newton::{solve_egg, EggSolved};

#[cfg(test)]
mod tests;
