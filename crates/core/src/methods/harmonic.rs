//! The variational harmonic method (VHM, paper §10.1, eq. 46; Xu et al. 2013):
//!
//! `VH(c) = ∫ L(x, y, x)² + L(x, y, y)² + λ₁ (‖x_ξξ‖² + ‖x_ηη‖² + ‖x_ξη‖²) + λ₂ (g₁₁² + g₂₂²) dξ`
//!
//! with `L(x, y, z) = g₂₂ z_ξξ − 2 g₁₂ z_ξη + g₁₁ z_ηη` (eq. 4) and the metric `g` of eq. (2):
//! the least-squares form of the EGG equations (6) plus the uniformity and the area
//! orthogonality functionals of eq. (3). The paper sets `λ₁ = λ₂ = 0` ("comparable to
//! ours") and minimizes by the Newton method of §6.1 applied to `∂VH/∂c`; so does
//! [`VariationalHarmonicMethod`], with the exact gradient and Hessian of the density in
//! the jet (kernel: [`super::density`]) and the Levenberg-Marquardt shift of
//! [`ShiftedHessian`] where the Hessian is not definite along the Newton direction.
//!
//! # Derivatives
//!
//! With `E` the jet of [`super::density`] and `u_k` the `k`-th unit vector, the metric
//! has `∂g₁₁ = 2 (x_ξ u₀ + y_ξ u₅)`, `∂g₁₂ = x_η u₀ + x_ξ u₁ + y_η u₅ + y_ξ u₆`,
//! `∂g₂₂ = 2 (x_η u₁ + y_η u₆)` and constant second derivatives; for component `z` with
//! second derivatives `(Z₂, Z₃, Z₄) = (z_ξξ, z_ξη, z_ηη)` at slots `5z + 2 .. 5z + 4`,
//!
//! * `∂L_z = g₂₂ u_{5z+2} − 2 g₁₂ u_{5z+3} + g₁₁ u_{5z+4} + Z₂ ∂g₂₂ − 2 Z₃ ∂g₁₂ + Z₄ ∂g₁₁`,
//! * `∂²L_z = Z₂ ∂²g₂₂ − 2 Z₃ ∂²g₁₂ + Z₄ ∂²g₁₁ + sym(u_{5z+2}, ∂g₂₂) − 2 sym(u_{5z+3}, ∂g₁₂) + sym(u_{5z+4}, ∂g₁₁)`,
//!
//! `sym(a, b) = a bᵀ + b aᵀ`, and `∂²(L_z²) = 2 (∂L_z ∂L_zᵀ + L_z ∂²L_z)`.
//!
//! # Scale
//!
//! The three terms scale as `D⁶`, `D²` and `D⁴` under `x ↦ D x`; the weights are applied
//! as `λ₁ ℓ⁴` and `λ₂ ℓ²` with the reference length `ℓ` of the method
//! ([`VariationalHarmonicMethod::length`], the domain's diameter in `winslow compare`), so
//! that `λ₁`, `λ₂` are dimensionless and the method is invariant under similarities;
//! with `ℓ = 1` the functional is eq. (46) as printed.

use std::sync::Arc;

use super::density::{assemble, integrate, jet_at, outer, Jet, JetMatrix, Order, ShiftedHessian, JET};
use super::galerkin::GalerkinState;
use super::{DiscreteProblem, Method};
use crate::discrete::assembly::{element_product, Discretization};
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// The variational harmonic method of eq. (46), minimized by Newton's method from any
/// start (the functional is defined for folded maps too).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VariationalHarmonicMethod {
    /// Weight `λ₁` of the uniformity term (dimensionless; see the module documentation).
    pub lambda1: f64,
    /// Weight `λ₂` of the area-orthogonality term (dimensionless).
    pub lambda2: f64,
    /// Reference length `ℓ` that makes the weights dimensionless.
    pub length: f64,
}

impl Default for VariationalHarmonicMethod {
    /// `λ₁ = λ₂ = 0` as in the paper's comparison.
    fn default() -> Self {
        Self { lambda1: 0.0, lambda2: 0.0, length: 1.0 }
    }
}

impl VariationalHarmonicMethod {
    /// The weights as applied to the functional: `(λ₁ ℓ⁴, λ₂ ℓ²)`.
    pub fn weights(&self) -> (f64, f64) {
        (self.lambda1 * self.length.powi(4), self.lambda2 * self.length.powi(2))
    }
}

impl Method for VariationalHarmonicMethod {
    fn name(&self) -> &'static str {
        "vhm"
    }

    /// `∂VH/∂c_a = ∫ 2 L ∂L/∂c_a` with `L ~ D³` and `∂L/∂c_a ~ D² w_a''`: about `D⁵` per
    /// entry when the control points are off by the domain size.
    fn residual_size(&self, diameter: f64) -> f64 {
        diameter.powi(5)
    }

    /// `|∇VH| ~ D⁵ sqrt(m)` at such a start (the entries do not shrink with `m`: the
    /// second derivatives `~ m` of `w_a` make up for its support `~ 1/m`).
    fn residual_scale(&self, diameter: f64, m: usize) -> f64 {
        1.0 / (self.residual_size(diameter) * (m.max(1) as f64).sqrt())
    }

    fn problem(&self, disc: Arc<Discretization>, control_points: Vec<Point>) -> Box<dyn DiscreteProblem + Send> {
        Box::new(HarmonicProblem::new(disc, control_points, *self))
    }
}

/// Unit vector `u_k` of the jet.
fn unit(k: usize) -> Jet {
    let mut u = [0.0; JET];
    u[k] = 1.0;
    u
}

/// `sym(a, b) = a bᵀ + b aᵀ`.
fn sym(a: &Jet, b: &Jet) -> JetMatrix {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i] * b[j] + b[i] * a[j]))
}

/// `a += s m`.
fn add_scaled(a: &mut JetMatrix, s: f64, m: &JetMatrix) {
    for (ra, rm) in a.iter_mut().zip(m) {
        for (x, y) in ra.iter_mut().zip(rm) {
            *x += s * y;
        }
    }
}

/// `a += s v`.
fn axpy(a: &mut Jet, s: f64, v: &Jet) {
    for (x, y) in a.iter_mut().zip(v) {
        *x += s * y;
    }
}

/// The metric `(g₁₁, g₁₂, g₂₂)` of the jet, its gradients and (constant) Hessians.
struct Metric {
    g: [f64; 3],
    dg: [Jet; 3],
    d2g: [JetMatrix; 3],
}

impl Metric {
    fn of(e: &Jet) -> Self {
        let g = [e[0] * e[0] + e[5] * e[5], e[0] * e[1] + e[5] * e[6], e[1] * e[1] + e[6] * e[6]];
        let mut dg = [[0.0; JET]; 3];
        dg[0][0] = 2.0 * e[0];
        dg[0][5] = 2.0 * e[5];
        dg[1][0] = e[1];
        dg[1][1] = e[0];
        dg[1][5] = e[6];
        dg[1][6] = e[5];
        dg[2][1] = 2.0 * e[1];
        dg[2][6] = 2.0 * e[6];
        let mut d2g = [[[0.0; JET]; JET]; 3];
        for z in [0, 5] {
            d2g[0][z][z] = 2.0;
            d2g[1][z][z + 1] = 1.0;
            d2g[1][z + 1][z] = 1.0;
            d2g[2][z + 1][z + 1] = 2.0;
        }
        Self { g, dg, d2g }
    }
}

/// The density of eq. (46) with weights `(w1, w2)` (already multiplied by the reference
/// length, [`VariationalHarmonicMethod::weights`]): value, gradient and, when `hessian`,
/// Hessian in the jet (formulas in the module documentation).
pub(crate) fn vhm_density(e: &Jet, w1: f64, w2: f64, hessian: bool) -> (f64, Jet, JetMatrix) {
    let m = Metric::of(e);
    let [g11, g12, g22] = m.g;
    let mut v = 0.0;
    let mut grad = [0.0; JET];
    let mut hess = [[0.0; JET]; JET];
    for z in [0, 5] {
        let (z2, z3, z4) = (e[z + 2], e[z + 3], e[z + 4]);
        let l = g22 * z2 - 2.0 * g12 * z3 + g11 * z4;
        let mut dl = [0.0; JET];
        dl[z + 2] += g22;
        dl[z + 3] -= 2.0 * g12;
        dl[z + 4] += g11;
        axpy(&mut dl, z2, &m.dg[2]);
        axpy(&mut dl, -2.0 * z3, &m.dg[1]);
        axpy(&mut dl, z4, &m.dg[0]);
        v += l * l;
        axpy(&mut grad, 2.0 * l, &dl);
        if hessian {
            let mut d2l = [[0.0; JET]; JET];
            add_scaled(&mut d2l, z2, &m.d2g[2]);
            add_scaled(&mut d2l, -2.0 * z3, &m.d2g[1]);
            add_scaled(&mut d2l, z4, &m.d2g[0]);
            add_scaled(&mut d2l, 1.0, &sym(&unit(z + 2), &m.dg[2]));
            add_scaled(&mut d2l, -2.0, &sym(&unit(z + 3), &m.dg[1]));
            add_scaled(&mut d2l, 1.0, &sym(&unit(z + 4), &m.dg[0]));
            add_scaled(&mut hess, 2.0, &outer(&dl, &dl));
            add_scaled(&mut hess, 2.0 * l, &d2l);
        }
        if w1 != 0.0 {
            for k in z + 2..z + 5 {
                v += w1 * e[k] * e[k];
                grad[k] += 2.0 * w1 * e[k];
                hess[k][k] += 2.0 * w1;
            }
        }
    }
    if w2 != 0.0 {
        for (g, k) in [(g11, 0), (g22, 2)] {
            v += w2 * g * g;
            axpy(&mut grad, 2.0 * w2 * g, &m.dg[k]);
            if hessian {
                add_scaled(&mut hess, 2.0 * w2, &outer(&m.dg[k], &m.dg[k]));
                add_scaled(&mut hess, 2.0 * w2 * g, &m.d2g[k]);
            }
        }
    }
    (v, grad, hess)
}

/// `VH(c)` (eq. 46) of the map with control points `cps` on the quadrature of `disc`.
pub(crate) fn vhm_objective(disc: &Discretization, cps: &[Point], method: &VariationalHarmonicMethod) -> f64 {
    let (w1, w2) = method.weights();
    integrate(disc, cps, Order::Second, |e| vhm_density(e, w1, w2, false).0)
}

/// The principal part of the VHM Hessian as a scalar operator for `-diag(K, K)`
/// preconditioning: `K_ab = 2 ∫ L̃(w_a) L̃(w_b) + 2 λ₁ ℓ⁴ ∫ ∇²w_a : ∇²w_b + shift ∫ w_a w_b`
/// with `L̃(w) = g₂₂ w_ξξ − 2 g₁₂ w_ξη + g₁₁ w_ηη` (the terms of `2 ∂L_z ∂L_zᵀ` with
/// two second derivatives, the same for both components); symmetric positive definite for
/// a non-degenerate metric, since `L̃` is elliptic and `w_a` vanish on the boundary.
pub(crate) fn vhm_principal(disc: &Discretization, cps: &[Point], w1: f64, shift: f64, stencil: &mut [f64]) {
    let nq = [disc.tables[0].nq, disc.tables[1].nq];
    let nqp = nq[0] * nq[1];
    let blocks = 1 + if w1 != 0.0 { 3 } else { 0 } + usize::from(shift != 0.0);
    disc.assemble(1, &mut [], stencil, |ex, ey, s| {
        let nloc = s.nloc;
        s.reserve_products(blocks * nqp * nloc, blocks * nqp * nloc);
        for kv in 0..nq[1] {
            for ku in 0..nq[0] {
                let k = kv * nq[0] + ku;
                let wq = disc.tensor_basis(ex, ey, ku, kv, s);
                let e = jet_at(disc, ex, ey, cps, s, 2);
                let [g11, g12, g22] = Metric::of(&e).g;
                for (a, b) in s.b.iter().enumerate() {
                    let lw = g22 * b[3] - 2.0 * g12 * b[4] + g11 * b[5];
                    let mut row = 0;
                    s.wa[(row * nqp + k) * nloc + a] = 2.0 * wq * lw;
                    s.tz[(row * nqp + k) * nloc + a] = lw;
                    if w1 != 0.0 {
                        for d in 3..6 {
                            row += 1;
                            s.wa[(row * nqp + k) * nloc + a] = 2.0 * w1 * wq * b[d];
                            s.tz[(row * nqp + k) * nloc + a] = b[d];
                        }
                    }
                    if shift != 0.0 {
                        row += 1;
                        s.wa[(row * nqp + k) * nloc + a] = shift * wq * b[0];
                        s.tz[(row * nqp + k) * nloc + a] = b[0];
                    }
                }
            }
        }
        element_product(&mut s.ke, &s.wa, &s.tz, nloc);
    });
}

/// VHM on one level: the [`GalerkinState`], the method's weights and the shifted
/// Hessian.
pub(crate) struct HarmonicProblem {
    /// Basis, control points and storage.
    pub state: GalerkinState,
    method: VariationalHarmonicMethod,
    hessian: ShiftedHessian,
}

impl std::fmt::Debug for HarmonicProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HarmonicProblem")
            .field("unknowns", &self.size())
            .field("method", &self.method)
            .field("shift", &self.hessian.shift())
            .finish()
    }
}

impl HarmonicProblem {
    /// Set up with all control points `cps` (free ones are the start).
    pub fn new(disc: Arc<Discretization>, cps: Vec<Point>, method: VariationalHarmonicMethod) -> Self {
        let hessian = ShiftedHessian::new(&disc);
        Self { state: GalerkinState::new(disc, cps), method, hessian }
    }

    /// The current unknown vector.
    #[cfg(test)]
    pub fn unknowns(&self) -> Vec<f64> {
        self.state.unknowns()
    }

    fn assemble(&mut self, with_hessian: bool) {
        let (w1, w2) = self.method.weights();
        let s = &mut self.state;
        let stencil: &mut [f64] = if with_hessian { &mut s.stencil } else { &mut [] };
        assemble(&s.disc, &s.cps, Order::Second, &mut s.res_full, stencil, |e, h| {
            let (_, g, hh) = vhm_density(e, w1, w2, h);
            (g, hh)
        });
    }
}

impl DiscreteProblem for HarmonicProblem {
    fn size(&self) -> usize {
        self.state.size()
    }

    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        self.state.load(c);
        self.assemble(false);
        self.hessian.invalidate();
        self.state.restrict_residual(f);
    }

    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        if self.hessian.prepare(c) {
            self.state.load_for_jacobian(c);
            self.assemble(true);
            self.hessian.assembled_at(c);
        }
        self.state.restrict_residual(f);
        self.state.gather_jacobian(jac);
        self.hessian.apply(jac);
    }

    fn mass(&mut self) -> &Csr {
        self.state.mass(|disc, st| disc.mass(st))
    }

    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        Some(vhm_objective(&self.state.disc, &self.state.control_points(c), &self.method))
    }

    fn raise_shift(&mut self) -> bool {
        self.hessian.raise()
    }

    fn step_accepted(&mut self, delta: f64) {
        self.hessian.accepted(delta);
    }

    /// `K` of [`vhm_principal`] on the current control points.
    fn preconditioner(&mut self, shift: f64) -> Option<&Csr> {
        let (w1, _) = self.method.weights();
        Some(self.state.preconditioner(|disc, cps, st| vhm_principal(disc, cps, w1, shift, st)))
    }

    fn ordering(&self) -> Option<&[usize]> {
        Some(&self.state.disc.ordering)
    }

    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        self.state.control_points(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::density::tests::{affine, curved, density_fd, newton_to, problem_fd};

    #[test]
    fn density_derivatives_match_finite_differences() {
        let e: Jet = [1.3, 0.4, 0.2, -0.3, 0.5, -0.2, 0.9, -0.4, 0.25, 0.1];
        for (w1, w2) in [(0.0, 0.0), (0.7, 0.0), (0.0, 0.4), (0.3, 1.1)] {
            let psi = |e: &Jet| vhm_density(e, w1, w2, false).0;
            let dpsi = |e: &Jet, h: bool| {
                let (_, g, hh) = vhm_density(e, w1, w2, h);
                (g, hh)
            };
            let (eg, eh) = density_fd(psi, dpsi, &e, &(0..JET).collect::<Vec<_>>());
            assert!(eg < 1e-8 && eh < 1e-8, "weights ({w1}, {w2}): gradient {eg}, Hessian {eh}");
        }
        // the value is eq. (46)'s: L of eq. (4) by hand
        let (g11, g12, g22) =
            (1.3f64.powi(2) + 0.2f64.powi(2), 1.3 * 0.4 + (-0.2) * 0.9, 0.4f64.powi(2) + 0.9f64.powi(2));
        let lx = g22 * 0.2 - 2.0 * g12 * -0.3 + g11 * 0.5;
        let ly = g22 * -0.4 - 2.0 * g12 * 0.25 + g11 * 0.1;
        let u = 0.2f64.powi(2) + 0.3f64.powi(2) + 0.5f64.powi(2) + 0.4f64.powi(2) + 0.25f64.powi(2) + 0.1f64.powi(2);
        let want = lx * lx + ly * ly + 0.3 * u + 1.1 * (g11 * g11 + g22 * g22);
        assert!((vhm_density(&e, 0.3, 1.1, false).0 - want).abs() < 1e-13 * want);
    }

    /// `F = -∇VH` against differences of `VH`, `dF/dc` against differences of `F`, on a
    /// curved map (cubic in ξ, quadratic in η), with and without the weights.
    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        for (lambda1, lambda2) in [(0.0, 0.0), (0.5, 0.2)] {
            let (disc, cps) = curved(3, 2, 7, 0.05);
            let method = VariationalHarmonicMethod { lambda1, lambda2, length: 1.7 };
            let mut prob = HarmonicProblem::new(Arc::new(disc), cps, method);
            let c = prob.unknowns();
            let (eg, eh) = problem_fd(&mut prob, &c, 1e-6);
            assert!(eg < 1e-7 && eh < 1e-7, "({lambda1}, {lambda2}): gradient {eg}, Hessian {eh}");
        }
    }

    /// With an affine boundary the affine map is the minimizer (`VH = 0` for `λ = 0`; a
    /// critical point of every term): Newton converges to it from a perturbed interior.
    #[test]
    fn minimiser_of_an_affine_boundary_is_the_affine_map() {
        for (p, lambda1, lambda2) in [(2, 0.0, 0.0), (3, 0.0, 0.0), (3, 0.2, 0.3)] {
            let (disc, cps, exact) = affine(p, 5, 3, 0.04);
            let method = VariationalHarmonicMethod { lambda1, lambda2, length: 1.0 };
            let mut at_exact = HarmonicProblem::new(disc.clone(), exact.clone(), method);
            let ce = at_exact.unknowns();
            let mut f = vec![0.0; ce.len()];
            at_exact.residual(&ce, &mut f);
            let worst = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(worst < 1e-9, "p = {p}: the affine map is critical ({worst}, rounding of second derivatives)");
            let m = disc.dofs.num_free();
            let prob = HarmonicProblem::new(disc, cps, method);
            let c0 = prob.unknowns();
            let (converged, its, err) = newton_to(Box::new(prob), c0, method.residual_scale(2.5, m), &exact);
            assert!(converged, "p = {p}, ({lambda1}, {lambda2})");
            assert!(err < 1e-9, "p = {p}: distance to the affine map {err} after {its} iterations");
        }
    }

    /// At an affine map (no second derivatives) with `λ₂ = 0` the Hessian is exactly the
    /// block-diagonal `diag(K, K)` of the preconditioner: the principal part is the whole.
    #[test]
    fn preconditioner_is_the_hessian_at_an_affine_map() {
        let (disc, _, exact) = affine(3, 4, 1, 0.0);
        let method = VariationalHarmonicMethod { lambda1: 0.3, lambda2: 0.0, length: 1.0 };
        let mut prob = HarmonicProblem::new(disc.clone(), exact, method);
        let c = prob.unknowns();
        let (mut f, mut jac) = (vec![0.0; c.len()], Csr::default());
        prob.jacobian(&c, &mut f, &mut jac);
        let jac = jac.to_dense();
        let k = prob.preconditioner(0.0).unwrap().to_dense();
        let m = disc.dofs.num_free();
        let scale = k.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
        for i in 0..2 * m {
            for j in 0..2 * m {
                let want = if i / m == j / m { -k[i % m][j % m] } else { 0.0 };
                assert!((jac[i][j] - want).abs() < 1e-12 * scale, "({i}, {j}): {} vs {want}", jac[i][j]);
            }
        }
    }
}
