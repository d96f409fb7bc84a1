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
use crate::error::{Error, Result};
use crate::linalg::linsolve::{LinearMethod, LinearSolver};
use crate::linalg::sparse::Csr;
use crate::spline::volume::Point3;

/// Pairs `(i, j)` of the six second derivatives, in the order they are stored.
const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

fn cross(a: Point3, b: Point3) -> Point3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `A : H` for symmetric `A` and `H` given by the six entries of [`PAIRS`].
fn contract(a: &[[f64; 3]; 3], h: &[f64; 6]) -> f64 {
    PAIRS.iter().zip(h).map(|(&(i, j), v)| if i == j { a[i][j] * v } else { 2.0 * a[i][j] * v }).sum()
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

    /// The element's quadrature: weights `w_q`, and at every point (`q m + a`) `R_a`,
    /// `∇R_a` and `∇²R_a` (the six entries of [`PAIRS`]); rational:
    /// `R = n / W`, `∇R = (∇n - R ∇W) / W`, `∂_ij R = (∂_ij n - ∂_i R ∂_j W - ∂_j R ∂_i W - R ∂_ij W) / W`
    /// with `n = w N` and `W = Σ n`.
    #[allow(clippy::type_complexity)]
    fn element_points(&self, e: usize, idx: &[usize]) -> (Vec<f64>, Vec<f64>, Vec<Point3>, Vec<[f64; 6]>) {
        let [bx, by, bz] = self.disc.element_tables(e);
        let p = [bx[0].0.degree, by[0].0.degree, bz[0].0.degree];
        let m = idx.len();
        let nq = bx.len() * by.len() * bz.len();
        let (mut weights, mut vals, mut grads, mut hess) = (
            Vec::with_capacity(nq),
            Vec::with_capacity(nq * m),
            Vec::with_capacity(nq * m),
            Vec::with_capacity(nq * m),
        );
        let mut local: Vec<(f64, Point3, [f64; 6])> = Vec::with_capacity(m);
        for (z, wz) in bz {
            for (y, wy) in by {
                for (x, wx) in bx {
                    local.clear();
                    let (mut ws, mut wg, mut wh) = (0.0, [0.0; 3], [0.0; 6]);
                    let mut lin = idx.iter();
                    for c in 0..=p[2] {
                        for b in 0..=p[1] {
                            for a in 0..=p[0] {
                                let l = *lin.next().expect("one index per basis function");
                                let w = self.disc.weights.as_ref().map_or(1.0, |w| w[l]);
                                let f = |i: usize, j: usize, k: usize| w * x.d[i][a] * y.d[j][b] * z.d[k][c];
                                let n = f(0, 0, 0);
                                let g = [f(1, 0, 0), f(0, 1, 0), f(0, 0, 1)];
                                let h = [f(2, 0, 0), f(0, 2, 0), f(0, 0, 2), f(1, 1, 0), f(1, 0, 1), f(0, 1, 1)];
                                ws += n;
                                for q in 0..3 {
                                    wg[q] += g[q];
                                }
                                for q in 0..6 {
                                    wh[q] += h[q];
                                }
                                local.push((n, g, h));
                            }
                        }
                    }
                    for (n, g, h) in &local {
                        let r = n / ws;
                        let gr: Point3 = std::array::from_fn(|i| (g[i] - r * wg[i]) / ws);
                        let hr: [f64; 6] = std::array::from_fn(|k| {
                            let (i, j) = PAIRS[k];
                            (h[k] - gr[i] * wg[j] - gr[j] * wg[i] - r * wh[k]) / ws
                        });
                        vals.push(r);
                        grads.push(gr);
                        hess.push(hr);
                    }
                    weights.push(wx * wy * wz);
                }
            }
        }
        (weights, vals, grads, hess)
    }

    /// Element `e`'s residual and Jacobian (see [`Local`]; the scalar is unused);
    /// `None` when `tr A = 0` at one of its points.
    fn element(&self, e: usize, cps: &[Point3], jacobian: bool) -> Option<Local> {
        let idx = self.disc.element_indices(e);
        let (weights, vals, grads, hess) = self.element_points(e, &idx);
        let (m, nq) = (idx.len(), weights.len());
        let mut res = vec![0.0; 3 * m];
        let mut qm = if jacobian { vec![0.0; nq * 9 * m] } else { Vec::new() };
        for (q, &wq) in weights.iter().enumerate() {
            let (rq, gq, hq) = (&vals[q * m..(q + 1) * m], &grads[q * m..(q + 1) * m], &hess[q * m..(q + 1) * m]);
            // J's columns and the components' Hessians
            let mut d = [[0.0; 3]; 3];
            let mut xh = [[0.0; 6]; 3];
            for a in 0..m {
                let c = cps[idx[a]];
                for comp in 0..3 {
                    for col in 0..3 {
                        d[col][comp] += c[comp] * gq[a][col];
                    }
                    for k in 0..6 {
                        xh[comp][k] += c[comp] * hq[a][k];
                    }
                }
            }
            let cof: [Point3; 3] = std::array::from_fn(|i| cross(d[(i + 1) % 3], d[(i + 2) % 3]));
            let am: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| dot(cof[i], cof[j])));
            let t = am[0][0] + am[1][1] + am[2][2];
            if t.is_nan() || t <= 0.0 {
                return None;
            }
            let l: [f64; 3] = std::array::from_fn(|c| contract(&am, &xh[c]) / t);
            for a in 0..m {
                for c in 0..3 {
                    res[3 * a + c] += wq * rq[a] * l[c];
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
            let row = &mut qm[q * 9 * m..(q + 1) * 9 * m];
            for b in 0..m {
                let v = contract(&am, &hq[b]) / t;
                let g = gq[b];
                for ib in 0..3 {
                    for ia in 0..3 {
                        let mut x = g[0] * s[ia][0][ib] + g[1] * s[ia][1][ib] + g[2] * s[ia][2][ib];
                        if ia == ib {
                            x += v;
                        }
                        row[b * 9 + 3 * ib + ia] = x;
                    }
                }
            }
        }
        let mut k = Vec::new();
        if jacobian {
            let mut pm = vec![0.0; m * nq];
            for (q, &wq) in weights.iter().enumerate() {
                for a in 0..m {
                    pm[q * m + a] = wq * vals[q * m + a];
                }
            }
            k = vec![0.0; 9 * m * m];
            faer::linalg::matmul::matmul(
                faer::MatMut::from_column_major_slice_mut(&mut k, m, 9 * m),
                faer::Accum::Replace,
                faer::MatRef::from_column_major_slice(&pm, m, nq),
                faer::MatRef::from_row_major_slice(&qm, nq, 9 * m),
                1.0,
                faer::Par::Seq,
            );
        }
        Some(Local { idx, scalar: 0.0, vector: res, matrix: k })
    }

    /// Number of free scalar unknowns (3 per interior control point).
    pub fn unknowns(&self) -> usize {
        self.disc.unknowns()
    }

    /// `F` (and `∂F/∂c` when `jacobian`) at the control points `cps`
    /// ([`VolumeDiscretization::assemble`]).
    pub fn evaluate(&self, cps: &[Point3], jacobian: bool) -> EggEvaluation {
        match self.disc.assemble(jacobian, |e| self.element(e, cps, jacobian)) {
            Some((_, residual, jacobian)) => EggEvaluation { residual, jacobian },
            None => EggEvaluation { residual: Vec::new(), jacobian: None },
        }
    }
}

/// Statistics of one EGG solve.
#[derive(Debug, Clone, Copy)]
pub(super) struct EggSolved {
    pub(super) iterations: usize,
    /// `|F|` of the result relative to that of the start.
    pub(super) relative_residual: f64,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Newton's method on `F(c) = 0` over the free control points of `cps` (the rest are
/// the Dirichlet data), sparse LU on the Jacobian, the step halved while `|F|` does not
/// decrease (Armijo on `|F|`); stops when `|F| <= tolerance max(|F(start)|, 1)` (the
/// operator is of unit size in the unit frame the volume solve works in) or after
/// `max_iterations`.
pub(super) fn solve_egg(
    op: &EggVolume,
    cps: &mut [Point3],
    max_iterations: usize,
    tolerance: f64,
) -> Result<EggSolved> {
    let mut ev = op.evaluate(cps, true);
    if ev.residual.is_empty() && op.unknowns() > 0 {
        return Err(Error::InfeasibleStart {
            method: "3D EGG".into(),
            reason: "the cofactor metric vanishes (J of rank 1 or less) at a quadrature point of the start".into(),
        });
    }
    let f0 = norm(&ev.residual);
    let stop = tolerance * f0.max(1.0);
    let mut x = op.disc.gather(cps);
    let mut solver = LinearSolver::new(LinearMethod::Lu);
    let mut iterations = 0;
    let mut fnorm = f0;
    while iterations < max_iterations && op.unknowns() > 0 && fnorm > stop {
        let jac = ev.jacobian.as_ref().expect("evaluated with the Jacobian");
        solver.factor(jac)?;
        let rhs: Vec<f64> = ev.residual.iter().map(|f| -f).collect();
        let d = solver.solve(&rhs)?;
        if !d.iter().all(|v| v.is_finite()) {
            return Err(Error::NoConvergence("3D EGG: the Newton step is not finite".into()));
        }
        iterations += 1;
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..30 {
            let trial: Vec<f64> = x.iter().zip(&d).map(|(a, b)| a + alpha * b).collect();
            let mut c = cps.to_vec();
            op.disc.scatter(&mut c, &trial);
            let t = op.evaluate(&c, false);
            let tn = if t.residual.is_empty() { f64::INFINITY } else { norm(&t.residual) };
            if tn <= (1.0 - 1e-4 * alpha) * fnorm {
                accepted = Some((trial, c));
                break;
            }
            alpha *= 0.5;
        }
        let Some((trial, c)) = accepted else { break };
        x = trial;
        cps.copy_from_slice(&c);
        ev = op.evaluate(cps, true);
        fnorm = norm(&ev.residual);
    }
    Ok(EggSolved { iterations, relative_residual: fnorm / f0.max(f64::MIN_POSITIVE) })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;
    use crate::spline::volume::Volume;

    /// A rational curved volume of degrees (3, 2, 2) with an interior wobble.
    fn sample() -> (Volume, Vec<Point3>) {
        super::super::tests::curved_rational_volume([
            KnotVector::open_uniform(3, 2),
            KnotVector::open_uniform(2, 2),
            KnotVector::open_from_breaks(2, &[0.0, 0.4, 1.0], 1),
        ])
    }

    /// The assembled Jacobian against central differences of the residual, on a
    /// rational curved volume.
    #[test]
    fn jacobian_matches_finite_differences() {
        let (vol, cps) = sample();
        let op = EggVolume::new(&vol, 5);
        let at = op.evaluate(&cps, true);
        assert_eq!(at.residual.len(), op.unknowns());
        assert!(at.residual.iter().any(|f| f.abs() > 1e-3), "a wobbled volume is not a solution");
        let x0 = op.disc.gather(&cps);
        let jac = at.jacobian.unwrap();
        let eps = 1e-6;
        for k in 0..x0.len() {
            let shifted = |s: f64| {
                let mut x = x0.clone();
                x[k] += s;
                let mut c = cps.clone();
                op.disc.scatter(&mut c, &x);
                op.evaluate(&c, false).residual
            };
            let (p, m) = (shifted(eps), shifted(-eps));
            for l in 0..x0.len() {
                let fd = (p[l] - m[l]) / (2.0 * eps);
                assert!((jac.get(l, k) - fd).abs() < 1e-7 * (1.0 + fd.abs()), "jac {l} {k}: {} vs {fd}", jac.get(l, k));
            }
        }
    }

    /// The residual against the operator evaluated directly: for the quadratic volume
    /// `x = ξ + a ξη`, `y = η + b ζ²`, `z = ζ + c ξ²` (control points from its blossoms,
    /// so the B-spline basis holds it exactly), `F_(A,c) = ∫ R_A L_c` with `L_c` from the
    /// closed-form derivatives, summed over the same Gauss points.
    #[test]
    fn residual_matches_the_operator_in_closed_form() {
        let kv = KnotVector::open_uniform(2, 2);
        let k = [kv.clone(), kv.clone(), kv.clone()];
        let (a, b, c) = (0.3, -0.2, 0.25);
        let t = kv.knots();
        let g = kv.greville();
        let sq: Vec<f64> = (0..kv.num_basis()).map(|i| t[i + 1] * t[i + 2]).collect();
        let n = kv.num_basis();
        let cps: Vec<Point3> = (0..n * n * n)
            .map(|lin| {
                let (i, j, l) = (lin % n, (lin / n) % n, lin / (n * n));
                [g[i] + a * g[i] * g[j], g[j] + b * sq[l], g[l] + c * sq[i]]
            })
            .collect();
        let vol = Volume::new(k, cps.clone(), None).unwrap();
        for u in [[0.2, 0.7, 0.4], [0.9, 0.1, 0.55]] {
            let (x, want) = (vol.eval(u), [u[0] + a * u[0] * u[1], u[1] + b * u[2] * u[2], u[2] + c * u[0] * u[0]]);
            assert!((0..3).all(|i| (x[i] - want[i]).abs() < 1e-14), "{x:?} vs {want:?}");
        }
        let op = EggVolume::new(&vol, 4);
        let f = op.evaluate(&cps, false).residual;
        let l = |u: [f64; 3]| -> Point3 {
            let d = [[1.0 + a * u[1], 0.0, 2.0 * c * u[0]], [a * u[0], 1.0, 0.0], [0.0, 2.0 * b * u[2], 1.0]];
            // second derivatives per component, in the order of PAIRS
            let h =
                [[0.0, 0.0, 0.0, a, 0.0, 0.0], [0.0, 0.0, 2.0 * b, 0.0, 0.0, 0.0], [2.0 * c, 0.0, 0.0, 0.0, 0.0, 0.0]];
            let cof: [Point3; 3] = std::array::from_fn(|i| cross(d[(i + 1) % 3], d[(i + 2) % 3]));
            let am: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| dot(cof[i], cof[j])));
            let t = am[0][0] + am[1][1] + am[2][2];
            std::array::from_fn(|comp| contract(&am, &h[comp]) / t)
        };
        let rule = crate::spline::quadrature::GaussLegendre::new(4);
        let nodes: Vec<(f64, f64)> =
            kv.elements().into_iter().flat_map(|(_, lo, hi)| rule.on(lo, hi).collect::<Vec<_>>()).collect();
        let mut checked = 0;
        for lin in 0..cps.len() {
            let Some(fr) = op.disc.free_index(lin) else { continue };
            let ijk = [lin % n, (lin / n) % n, lin / (n * n)];
            let mut want = [0.0; 3];
            for &(x, wx) in &nodes {
                for &(y, wy) in &nodes {
                    for &(z, wz) in &nodes {
                        let u = [x, y, z];
                        let r: f64 = (0..3).map(|d| crate::spline::basis::dense_values(&kv, u[d])[ijk[d]]).product();
                        let lv = l(u);
                        for comp in 0..3 {
                            want[comp] += wx * wy * wz * r * lv[comp];
                        }
                    }
                }
            }
            for comp in 0..3 {
                let got = f[3 * fr + comp];
                assert!((got - want[comp]).abs() < 1e-13, "{lin} {comp}: {got} vs {}", want[comp]);
            }
            assert!(want.iter().any(|w| w.abs() > 1e-3), "a curved volume is not a solution");
            checked += 1;
        }
        assert_eq!(checked, 8);
    }
}
