//! The Winslow functional (paper eq. 15-16) as a minimization method:
//!
//! `J(c) = ∫ W(∇x) dξ`, `W = (x_ξ² + x_η² + y_ξ² + y_η²) / det J`,
//!
//! over the free control points `c` of one basis, `+∞` when `det J <= 0` at a
//! quadrature point (a barrier: the line search never leaves the bijective maps).
//! [`WinslowProblem`] presents `F = -∇J` and `dF/dc = -∇²J` with the exact gradient and
//! Hessian, assembled into the same vector pattern and stencil storage as EGG (the
//! [`Discretization`]'s tables and patterns, element rows in parallel).
//!
//! # Derivatives
//!
//! With `e = (a, b, c, d) = (x_ξ, x_η, y_ξ, y_η)`, `N = |e|²`, `D = ad - bc` and
//! `D' = ∂D/∂e = (d, -c, -b, a)`:
//!
//! * `∂W/∂e = 2 e / D - N D' / D²`,
//! * `∂²W/∂e² = 2 I / D - 2 (e D'ᵀ + D' eᵀ) / D² + 2 N D' D'ᵀ / D³ - N S / D²`, where `S`
//!   is the (constant) Hessian of `D` (`S_ad = S_da = 1`, `S_bc = S_cb = -1`).
//!
//! `e` is linear in `c` (`∂(a, b)/∂c^x_j = (w_j,ξ, w_j,η)`, `∂(c, d)/∂c^y_j` likewise), so
//! `∇²J` is the quadrature sum of `∂²W/∂e²` between the basis gradients: no other term.
//!
//! # Positive definiteness
//!
//! `W` is homogeneous of degree 0 and invariant under rotations, so `∂²W/∂e²` is only
//! positive semidefinite at conformal points (`x_ξ ⊥ x_η`, equal lengths) and indefinite
//! at every other (in the singular values `s₁ ≠ s₂` of `∇x`, `W = s₁/s₂ + s₂/s₁` has a
//! Hessian of determinant `-(1/s₁² - 1/s₂²)² < 0`): the assembled Hessian is positive
//! definite near a minimizer (the fixed boundary and the sum over points make it so), but
//! need not be far from one. The Newton solver finds out: its Cholesky factorization of
//! `∇²J` fails exactly when it is not positive definite (and a direction with `∇J·δ >=
//! 0` proves `δᵀ ∇²J δ <= 0`). It then calls [`DiscreteProblem::raise_shift`], which
//! modifies the presented Hessian step by step: first `∇²J + m (P - ∇²J)` with `P` the
//! assembly of every quadrature point's `∂²W/∂e²` projected onto the positive
//! semidefinite matrices (`project_psd`), `m = 0.3, 0.9, 1` (`m = 1` is positive
//! semidefinite, definite with the boundary fixed, and its Newton step has a moderate
//! length where a diagonal shift of an indefinite Hessian gives huge steps along its
//! near-null directions, which fold the map and force the line search down to 1/10),
//! then the diagonal shift `P + τ diag(|P_ii|)` (`τ = 10⁻⁴, 10⁻³, ...`). At a new point
//! the modification steps back one stage (`m = 1` becomes `0.9`, then `0.3`, then the
//! exact Hessian; diagonal shifts decay tenfold), so near the minimizer Newton converges
//! quadratically, and where the exact Hessian is far from definite no assembly and
//! factorization are spent on it at every step. A point where the modification had to be
//! raised passes it on unchanged to the next one (which then steps back): the stages
//! that failed at a point are not tried again at the next (on wavy_lid and jigsaw01
//! this saves one failed assembly and factorization, with the same iterates).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use super::density::{first_derivatives, integrate, lowered, raised, shift_diagonal, Order};
use super::flux::{flux_form_with, gradient_at};
use super::galerkin::GalerkinState;
use super::{DiscreteProblem, Method, Start};
use crate::discrete::assembly::{element_product, Discretization};
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// The Winslow functional (eq. 16), minimized from a bijective start.
#[derive(Debug, Clone, Copy, Default)]
pub struct WinslowMethod;

impl Method for WinslowMethod {
    fn name(&self) -> &'static str {
        "winslow"
    }

    fn start(&self) -> Start {
        Start::Bijective
    }

    /// `∂W/∂e ~ 1 / diam`, so `∂J/∂c_i ~ ∫ |∇w_i| / diam ~ 1 / (sqrt(m) diam)`.
    fn residual_size(&self, diameter: f64) -> f64 {
        1.0 / diameter
    }

    /// `|∇J| ~ 1 / diam` whatever `m`: the scaled residual is `|∇J| diam`.
    fn residual_scale(&self, diameter: f64, _m: usize) -> f64 {
        diameter
    }

    fn problem(&self, disc: Arc<Discretization>, control_points: Vec<Point>) -> Box<dyn DiscreteProblem + Send> {
        Box::new(WinslowProblem::new(disc, control_points))
    }
}

/// The Winslow density `W = N / D` of `e = (x_ξ, x_η, y_ξ, y_η)` with its gradient and
/// Hessian in `e` (formulas in the module documentation). Not finite when `D <= 0`.
pub(crate) fn winslow_density(e: [f64; 4]) -> (f64, [f64; 4], [[f64; 4]; 4]) {
    let [a, b, c, d] = e;
    let n = a * a + b * b + c * c + d * d;
    let det = a * d - b * c;
    let dd = [d, -c, -b, a];
    let inv = 1.0 / det;
    let w = n * inv;
    let g: [f64; 4] = std::array::from_fn(|i| 2.0 * e[i] * inv - w * dd[i] * inv);
    let inv2 = inv * inv;
    let mut h = [[0.0; 4]; 4];
    for (i, row) in h.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = -2.0 * (e[i] * dd[j] + dd[i] * e[j]) * inv2 + 2.0 * w * dd[i] * dd[j] * inv2;
        }
        row[i] += 2.0 * inv;
    }
    // - N S / D²
    let ns = w * inv;
    h[0][3] -= ns;
    h[3][0] -= ns;
    h[1][2] += ns;
    h[2][1] += ns;
    (w, g, h)
}

/// `J = ∫ W` (eq. 16) of the map with control points `cps` by the quadrature of `disc`;
/// `+∞` when `det J <= 0` at a quadrature point. Element rows in parallel, summed in
/// order (deterministic).
pub(crate) fn winslow_objective(disc: &Discretization, cps: &[Point]) -> f64 {
    integrate(disc, cps, Order::First, |e| {
        let [a, b, c, d] = first_derivatives(e);
        let det = a * d - b * c;
        if det.is_nan() || det <= 0.0 {
            f64::INFINITY
        } else {
            (a * a + b * b + c * c + d * d) / det
        }
    })
}

/// `-∂W/∂e = -(2 e - W D') / D` at `e`, with `W` and `1 / D` given (the gradient of
/// [`winslow_density`] without its Hessian).
fn neg_density_gradient(e: [f64; 4], w: f64, inv: f64) -> [f64; 4] {
    let [a, b, c, d] = e;
    let dd = [d, -c, -b, a];
    std::array::from_fn(|i| -(2.0 * e[i] - w * dd[i]) * inv)
}

/// `J = ∫ W` (eq. 16, as `winslow_objective`, bit for bit) and `F = -∇J` (full,
/// component-interleaved, length `2 n`, into `res`) in one pass over the quadrature
/// points: a line search that accepts a point needs both there, and the basis values and
/// `∇x` at a point are the larger part of either pass. `+∞` (and `res` meaningless) when
/// `det J <= 0` at a quadrature point.
pub fn winslow_value_and_gradient(disc: &Discretization, cps: &[Point], res: &mut [f64]) -> f64 {
    let nq = [disc.tables[0].nq, disc.tables[1].nq];
    let nex = disc.tables[0].num_elements();
    // the value of each element (written once, by the thread that assembles it)
    let cells: Vec<AtomicU64> = (0..disc.num_elements()).map(|_| AtomicU64::new(0)).collect();
    disc.assemble(2, res, &mut [], |ex, ey, s| {
        let nloc = s.nloc;
        s.re.fill(0.0);
        let mut cell = 0.0;
        for kv in 0..nq[1] {
            for ku in 0..nq[0] {
                let wq = disc.tensor_basis_first(ex, ey, ku, kv, s);
                let e = gradient_at(disc, ex, ey, cps, s);
                let [a, b, c, d] = e;
                let det = a * d - b * c;
                if det.is_nan() || det <= 0.0 {
                    cell = f64::INFINITY;
                    continue;
                }
                let n = a * a + b * b + c * c + d * d;
                let w = n / det;
                cell += wq * w;
                let g = neg_density_gradient(e, w, 1.0 / det);
                for a in 0..nloc {
                    let (bu, bv) = (s.b[a][1], s.b[a][2]);
                    s.re[a] += wq * (g[0] * bu + g[1] * bv);
                    s.re[nloc + a] += wq * (g[2] * bu + g[3] * bv);
                }
            }
        }
        cells[ey * nex + ex].store(cell.to_bits(), Ordering::Relaxed);
    });
    let values: Vec<f64> = cells.iter().map(|c| f64::from_bits(c.load(Ordering::Relaxed))).collect();
    values.chunks_exact(nex).map(|row| row.iter().fold(0.0, |s, v| s + v)).sum()
}

/// `F = -∇J` (full, component-interleaved, length `2 n`) and, when `stencil` is
/// non-empty, `dF/dc = -∇²J` in the vector stencil storage of `disc`: the first-order
/// form of `flux_form` with `G = -∂W/∂e`.
pub(crate) fn winslow_gradient(disc: &Discretization, cps: &[Point], res: &mut [f64], stencil: &mut [f64]) {
    if stencil.is_empty() {
        // the gradient only: `∂W/∂e = 2 e / D - W D' / D` without the Hessian
        flux_form_with(disc, cps, res, stencil, true, |e| {
            let [a, b, c, d] = e;
            let inv = 1.0 / (a * d - b * c);
            let w = (a * a + b * b + c * c + d * d) * inv;
            (neg_density_gradient(e, w, inv), [[0.0; 4]; 4])
        });
        return;
    }
    winslow_gradient_with(disc, cps, res, stencil, 0.0);
}

/// `winslow_gradient` with the Hessian of the density at each quadrature point moved by
/// the fraction `projected` towards its projection `P` onto the positive semidefinite
/// matrices (`project_psd`): `H + projected (P - H)`. With `projected = 1` the
/// assembled matrix is positive semidefinite (definite with the boundary fixed) wherever
/// the map is, and its Newton direction descends.
pub fn winslow_gradient_with(
    disc: &Discretization,
    cps: &[Point],
    res: &mut [f64],
    stencil: &mut [f64],
    projected: f64,
) {
    flux_form_with(disc, cps, res, stencil, true, |e| {
        let (_, g, h) = winslow_density(e);
        let h = if projected > 0.0 {
            let p = projected_density_hessian(e);
            std::array::from_fn(|i| std::array::from_fn(|j| h[i][j] + projected * (p[i][j] - h[i][j])))
        } else {
            h
        };
        (g.map(|v| -v), h.map(|row| row.map(|v| -v)))
    });
}

/// The projection of the Winslow density's Hessian `∂²W/∂e²` at `e` (with `D > 0`) onto
/// the positive semidefinite matrices, in closed form (Smith, de Goes, Kim 2019, analytic
/// eigensystems of isotropic energies): with the singular value decomposition `∇x = U Σ
/// Vᵀ`, `W = σ₁/σ₂ + σ₂/σ₁`, and the eigenvectors of the Hessian are the twist `U [[0,-1],
/// [1,0]] Vᵀ/√2` with eigenvalue `(W_σ₁ + W_σ₂)/(σ₁ + σ₂) = -(σ₁ - σ₂)² / (σ₁σ₂)² <= 0`
/// (zero at conformal points: W is invariant under rotations), the flip `U [[0,1],[1,0]]
/// Vᵀ/√2` with `(W_σ₁ - W_σ₂)/(σ₁ - σ₂) = (σ₁ + σ₂)² / (σ₁σ₂)² > 0`, and two in the span of `U diag(1,0) Vᵀ`,
/// `U diag(0,1) Vᵀ` from the `2 x 2` Hessian of `W(σ₁, σ₂)`, whose determinant is
/// `-(1/σ₁² - 1/σ₂²)² <= 0`: one of each sign. Negative eigenvalues are dropped. The
/// same as `project_psd` of [`winslow_density`]'s Hessian, about 20 times cheaper.
///
/// No angle is computed: `∇x = [[a, b], [c, d]] = q R(α₂) + r R(α₁) Z` (`R` a rotation,
/// `Z = diag(1, -1)`; `q (cos α₂, sin α₂) = ((a + d)/2, (c - b)/2)`, `r (cos α₁, sin α₁) =
/// ((a - d)/2, (c + b)/2)`, `σ₁,₂ = q ± r`), and with `U = R(φ)`, `Vᵀ = R(θ)`, `φ ± θ = α₂,
/// α₁`: `U Vᵀ = R(α₂)`, `U Z Vᵀ = R(α₁) Z`, `U [[0,1],[1,0]] Vᵀ = R(α₁ + π/2) Z`; the
/// eigenvector `(u₁, u₂)` of the `2 x 2` block is `∝ (λ - h₂₂, h₁₂)`.
pub(crate) fn projected_density_hessian(e: [f64; 4]) -> [[f64; 4]; 4] {
    let [a, b, c, d] = e;
    let (ee, ff, gg, hh) = (0.5 * (a + d), 0.5 * (a - d), 0.5 * (c + b), 0.5 * (c - b));
    let (q, r) = (ee.hypot(hh), ff.hypot(gg));
    let (s1, s2) = (q + r, q - r);
    // cos, sin of α₂ and α₁ (α₁ = 0 at a conformal point, where the result does not
    // depend on it)
    let (c2, n2) = (ee / q, hh / q);
    let (c1, n1) = if r > 0.0 { (ff / r, gg / r) } else { (1.0, 0.0) };
    // row-major vec of R(α₂) and of R(α₁) Z, R(α₁ + π/2) Z
    let rot = [c2, -n2, n2, c2];
    let refl = [c1, n1, n1, -c1];
    let r2 = std::f64::consts::FRAC_1_SQRT_2;
    let flip = [-r2 * n1, r2 * c1, r2 * c1, r2 * n1];
    let p = s1 * s2;
    let mut out = [[0.0; 4]; 4];
    let mut add = |l: f64, v: [f64; 4]| {
        for i in 0..4 {
            for j in 0..4 {
                out[i][j] += l * v[i] * v[j];
            }
        }
    };
    add((s1 + s2) * (s1 + s2) / (p * p), flip);
    // scaling block: [[2 s2 / s1³, -(1/s1² + 1/s2²)], [., 2 s1 / s2³]]
    let (h11, h22, h12) = (2.0 * s2 / (s1 * s1 * s1), 2.0 * s1 / (s2 * s2 * s2), -(1.0 / (s1 * s1) + 1.0 / (s2 * s2)));
    let (mean, half) = (0.5 * (h11 + h22), 0.5 * (h11 - h22));
    let rad = half.hypot(h12);
    let lambda = mean + rad;
    if lambda > 0.0 {
        // eigenvector (u1, u2) of the larger eigenvalue, ∝ (λ - h22, h12) (h12 < 0);
        // U diag(u1, u2) Vᵀ = (u1 + u2)/2 R(α₂) + (u1 - u2)/2 R(α₁) Z
        let (v1, v2) = (half + rad, h12);
        let norm = v1.hypot(v2);
        let (u1, u2) = (v1 / norm, v2 / norm);
        let (sp, sm) = (0.5 * (u1 + u2), 0.5 * (u1 - u2));
        add(lambda, std::array::from_fn(|i| sp * rot[i] + sm * refl[i]));
    }
    out
}

#[cfg(test)]
/// The symmetric `h` with its negative eigenvalues set to zero, `Q max(Λ, 0) Qᵀ`, by
/// cyclic Jacobi rotations (to rounding).
pub(crate) fn project_psd(h: [[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut a = h;
    let mut q = [[0.0; 4]; 4];
    for (i, row) in q.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let scale: f64 = a.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
    for _sweep in 0..50 {
        let off: f64 = (0..4)
            .flat_map(|i| (0..4).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        if off.sqrt() <= 1e-15 * scale {
            break;
        }
        for p in 0..3 {
            for r in p + 1..4 {
                if a[p][r] == 0.0 {
                    continue;
                }
                // rotation annihilating a[p][r]
                let theta = (a[r][r] - a[p][p]) / (2.0 * a[p][r]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let sn = t * c;
                for k in 0..4 {
                    let (akp, akr) = (a[k][p], a[k][r]);
                    a[k][p] = c * akp - sn * akr;
                    a[k][r] = sn * akp + c * akr;
                }
                for k in 0..4 {
                    let (apk, ark) = (a[p][k], a[r][k]);
                    a[p][k] = c * apk - sn * ark;
                    a[r][k] = sn * apk + c * ark;
                }
                for row in q.iter_mut() {
                    let (qp, qr) = (row[p], row[r]);
                    row[p] = c * qp - sn * qr;
                    row[r] = sn * qp + c * qr;
                }
            }
        }
    }
    let lambda: [f64; 4] = std::array::from_fn(|i| a[i][i].max(0.0));
    std::array::from_fn(|i| std::array::from_fn(|j| (0..4).map(|k| q[i][k] * lambda[k] * q[j][k]).sum()))
}

/// A scalar approximation of the Winslow Hessian for `-diag(K, K)` preconditioning:
/// `K_ab = ∫ ∇w_a · A ∇w_b` with `A` the mean of the two diagonal `2 x 2` blocks of
/// `∂²W/∂e²` (the `x`-`x` and `y`-`y` couplings, which carry the cell's anisotropy),
/// its eigenvalues raised to at least `10⁻³` of its trace so that `K` is definite, plus
/// `shift` times the mass matrix, into a scalar stencil.
pub(crate) fn winslow_laplace(disc: &Discretization, cps: &[Point], shift: f64, stencil: &mut [f64]) {
    let nq = [disc.tables[0].nq, disc.tables[1].nq];
    let nqp = nq[0] * nq[1];
    let nrows = if shift != 0.0 { 3 * nqp } else { 2 * nqp };
    disc.assemble(1, &mut [], stencil, |ex, ey, s| {
        let nloc = s.nloc;
        s.reserve_products(nrows * nloc, nrows * nloc);
        for kv in 0..nq[1] {
            for ku in 0..nq[0] {
                let k = kv * nq[0] + ku;
                let wq = disc.tensor_basis_first(ex, ey, ku, kv, s);
                let e = gradient_at(disc, ex, ey, cps, s);
                let [a11, a12, a22] = definite_mean_block(e);
                let (a11, a12, a22) = (wq * a11, wq * a12, wq * a22);
                for (i, ba) in s.b.iter().enumerate() {
                    s.wa[k * nloc + i] = a11 * ba[1] + a12 * ba[2];
                    s.tz[k * nloc + i] = ba[1];
                    s.wa[(nqp + k) * nloc + i] = a12 * ba[1] + a22 * ba[2];
                    s.tz[(nqp + k) * nloc + i] = ba[2];
                    if shift != 0.0 {
                        s.wa[(2 * nqp + k) * nloc + i] = wq * shift * ba[0];
                        s.tz[(2 * nqp + k) * nloc + i] = ba[0];
                    }
                }
            }
        }
        element_product(&mut s.ke, &s.wa, &s.tz, nloc);
    });
}

/// `(A_11, A_12, A_22)` of the mean diagonal block of `∂²W/∂e²` at `e`, eigenvalues
/// raised to `10⁻³` of the trace (`2 I / |D|` where `D <= 0`).
fn definite_mean_block(e: [f64; 4]) -> [f64; 3] {
    let [a, b, c, d] = e;
    let det = a * d - b * c;
    if det.is_nan() || det <= 0.0 {
        let v = 2.0 / det.abs().max(1e-300);
        return [v, 0.0, v];
    }
    let (_, _, h) = winslow_density(e);
    let m11 = 0.5 * (h[0][0] + h[2][2]);
    let m12 = 0.25 * (h[0][1] + h[1][0] + h[2][3] + h[3][2]);
    let m22 = 0.5 * (h[1][1] + h[3][3]);
    let (mean, diff) = (0.5 * (m11 + m22), 0.5 * (m11 - m22));
    let r = diff.hypot(m12);
    let floor = 1e-3 * (m11.abs() + m22.abs()).max(f64::MIN_POSITIVE);
    let (l1, l2) = ((mean + r).max(floor), (mean - r).max(floor));
    if r == 0.0 {
        return [l1, 0.0, l2];
    }
    // eigenvector of l1: (cos t, sin t) with tan 2t = m12 / diff
    let t = 0.5 * m12.atan2(diff);
    let (co, si) = (t.cos(), t.sin());
    [l1 * co * co + l2 * si * si, (l1 - l2) * co * si, l1 * si * si + l2 * co * co]
}

/// The first partial projection of a modified Hessian (see
/// [`WinslowProblem`]'s `raise_shift`): `H + 0.3 (P - H)`, then `0.9`, then `1`.
pub(crate) const PROJECTION_FIRST: f64 = 0.3;

/// The projection share one stage stronger after a failed factorization: none, then
/// [`PROJECTION_FIRST`], then three times that, then 1 (the whole negative part).
pub(crate) fn projection_raised(projected: f64) -> f64 {
    if projected == 0.0 {
        PROJECTION_FIRST
    } else {
        (3.0 * projected).min(1.0)
    }
}

/// The projection share one stage weaker at a new point (towards the exact Hessian):
/// the inverse of [`projection_raised`].
pub(crate) fn projection_lowered(projected: f64) -> f64 {
    match projected {
        x if x >= 1.0 => 3.0 * PROJECTION_FIRST,
        x if x > PROJECTION_FIRST => PROJECTION_FIRST,
        _ => 0.0,
    }
}

/// The Winslow functional on one level: discretization, control points (fixed ones hold
/// the boundary) and storage requested once.
pub struct WinslowProblem {
    /// Basis, control points and storage.
    pub(crate) state: GalerkinState,
    /// Positions of the diagonal entries in the vector pattern's values.
    diag: Vec<usize>,
    /// Relative diagonal shift `τ` of the presented Hessian.
    shift: f64,
    /// The stencil holds the Hessian at `assembled`, projected or not (for a re-shift
    /// without assembly).
    assembled: Option<(Vec<f64>, f64)>,
    raised: bool,
    /// The modification was raised at the current point ([`DiscreteProblem::raise_shift`]):
    /// the next point starts with it rather than one stage back.
    raised_at_point: bool,
    /// The density Hessians are projected onto the semidefinite matrices
    /// ([`winslow_gradient_with`]) at this point.
    projected: f64,
    /// The full `F = -∇J` at the point of the last [`DiscreteProblem::objective`]
    /// ([`winslow_value_and_gradient`]), with that point: the residual there is read, not
    /// assembled again.
    gradient: (Vec<f64>, Option<Vec<f64>>),
}

impl std::fmt::Debug for WinslowProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WinslowProblem").field("unknowns", &self.size()).field("shift", &self.shift).finish()
    }
}

impl WinslowProblem {
    /// Set up with all control points `cps` (free ones are the start).
    pub fn new(disc: Arc<Discretization>, cps: Vec<Point>) -> Self {
        let pat = &disc.vector.csr;
        let diag = (0..pat.nrows).map(|r| pat.position(r, r).expect("the pattern holds the diagonal")).collect();
        Self {
            state: GalerkinState::new(disc, cps),
            diag,
            shift: 0.0,
            assembled: None,
            raised: false,
            raised_at_point: false,
            projected: 0.0,
            gradient: (Vec::new(), None),
        }
    }

    /// The current unknown vector.
    pub fn unknowns(&self) -> Vec<f64> {
        self.state.unknowns()
    }

    /// The relative diagonal shift `τ` the last Jacobian carried.
    pub fn shift(&self) -> f64 {
        self.shift
    }
}

impl DiscreteProblem for WinslowProblem {
    fn size(&self) -> usize {
        self.state.size()
    }

    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        if self.gradient.1.as_deref() == Some(c) {
            f.copy_from_slice(&self.state.disc.restrict(&self.gradient.0, 2));
            return;
        }
        let s = &mut self.state;
        s.load(c);
        winslow_gradient(&s.disc, &s.cps, &mut s.res_full, &mut []);
        self.assembled = None;
        s.restrict_residual(f);
    }

    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        if !std::mem::take(&mut self.raised) && !std::mem::take(&mut self.raised_at_point) {
            // a new point: one step back towards the exact Hessian (after a fully
            // projected one the exact Hessian is rarely definite: trying it would cost
            // an assembly and a failed factorization); where the last point needed a
            // stronger modification than the one it started with, its modification
            // is kept for this one (the stages it failed would fail here too)
            self.shift = lowered(self.shift);
            self.projected = projection_lowered(self.projected);
        }
        let s = &mut self.state;
        if !self.assembled.as_ref().is_some_and(|(at, pr)| at == c && *pr == self.projected) {
            s.load_for_jacobian(c);
            winslow_gradient_with(&s.disc, &s.cps, &mut s.res_full, &mut s.stencil, self.projected);
            self.assembled = Some((c.to_vec(), self.projected));
        }
        s.restrict_residual(f);
        s.gather_jacobian(jac);
        shift_diagonal(self.shift, &self.diag, &mut jac.values);
    }

    fn mass(&mut self) -> &Csr {
        self.state.mass(|disc, st| disc.mass(st))
    }

    /// With the gradient there ([`winslow_value_and_gradient`]), for the residual the
    /// solver asks for at an accepted point.
    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        let cps = self.state.control_points(c);
        let (grad, at) = &mut self.gradient;
        grad.resize(2 * cps.len(), 0.0);
        let j = winslow_value_and_gradient(&self.state.disc, &cps, grad);
        *at = j.is_finite().then(|| c.to_vec());
        Some(j)
    }

    /// First the partly, then fully projected Hessian ([`winslow_gradient_with`] with
    /// `PROJECTION_FIRST`, then three times that, then 1: positive semidefinite per
    /// point, a descent direction of moderate length where the exact one is indefinite),
    /// then diagonal shifts on top of it.
    fn modified(&self) -> bool {
        self.projected > 0.0 || self.shift > 0.0
    }

    fn raise_shift(&mut self) -> bool {
        self.raised = true;
        self.raised_at_point = true;
        if self.projected < 1.0 {
            self.projected = projection_raised(self.projected);
            return true;
        }
        let Some(next) = raised(self.shift) else { return false };
        self.shift = next;
        true
    }

    /// `K` of `winslow_laplace` on the current control points.
    fn preconditioner(&mut self, shift: f64) -> Option<&Csr> {
        Some(self.state.preconditioner(|disc, cps, st| winslow_laplace(disc, cps, shift, st)))
    }

    fn ordering(&self) -> Option<&[usize]> {
        Some(&self.state.disc.ordering)
    }

    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        self.state.control_points(c)
    }
}

#[cfg(test)]
mod tests;
