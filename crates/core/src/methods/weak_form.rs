//! The weak form (paper eq. 14) of the inverse map's Laplace equations: `ξ(x)` and `η(x)`
//! harmonic in the weak sense, `∫_Ω ∇w_i · ∇ξ dx = 0`, `∫_Ω ∇w_i · ∇η dx = 0` (eq. 13),
//! pulled back to the parameter square:
//!
//! `F^x_i = ∫ (w_i,ξ g22 - w_i,η g12) / det J dξ`, `F^y_i = ∫ (-w_i,ξ g12 + w_i,η g11) / det J dξ`.
//!
//! Only first derivatives of the map appear, so a `C⁰` basis is allowed (§4.1, §9), but
//! `det J` divides: the method needs a bijective start ([`Start::Bijective`]) and
//! [`DiscreteProblem::admissible`] is false where `det J <= 0` at a quadrature point, so
//! the line search never accepts such a step.
//!
//! # Jacobian
//!
//! `F` is the first-order form of [`flux_form`] with the flux `G = (g22, -g12, -g12, g11) /
//! D` of `e = (a, b, c, d) = (x_ξ, x_η, y_ξ, y_η)`, `D = ad - bc`: with `∂g11/∂e = (2a, 0,
//! 2c, 0)`, `∂g12/∂e = (b, a, d, c)`, `∂g22/∂e = (0, 2b, 0, 2d)`, `∂D/∂e = (d, -c, -b, a)`,
//! `∂(g/D)/∂e = (∂g/∂e - (g/D) ∂D/∂e) / D`. Near the identity `F^x ≈ -∫ ∇w·∇x`: the
//! Jacobian is negative definite like EGG's, and `K = ∫ ∇w·A∇w / D` with `A = [[g22, -g12],
//! [-g12, g11]]` (the physical Laplacian pulled back, [`weak_laplace`]) preconditions it.

use std::sync::Arc;

use super::flux::{flux_form, gradient_at, min_det_j};
use super::galerkin::GalerkinState;
use super::{DiscreteProblem, Method, Start};
use crate::discrete::assembly::{element_product, Discretization};
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// The weak form (eq. 14), solved from a bijective start.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WeakFormMethod;

impl Method for WeakFormMethod {
    fn name(&self) -> &'static str {
        "weak-form"
    }

    fn start(&self) -> Start {
        Start::Bijective
    }

    /// `G` is dimensionless.
    fn residual_size(&self, _diameter: f64) -> f64 {
        1.0
    }

    /// `F_i = ∫ ∇w_i · G ~ 1 / sqrt(m)`, so `|F| ~ 1` whatever `m` and the diameter.
    fn residual_scale(&self, _diameter: f64, _m: usize) -> f64 {
        1.0
    }

    fn problem(&self, disc: Arc<Discretization>, control_points: Vec<Point>) -> Box<dyn DiscreteProblem + Send> {
        Box::new(WeakFormProblem::new(disc, control_points))
    }
}

/// The flux `G(e) = (g22, -g12, -g12, g11) / D` of eq. (14) and `∂G/∂e`.
pub(crate) fn weak_flux(e: [f64; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
    let [a, b, c, d] = e;
    let inv = 1.0 / (a * d - b * c);
    let (g11, g12, g22) = (a * a + c * c, a * b + c * d, b * b + d * d);
    let dg11 = [2.0 * a, 0.0, 2.0 * c, 0.0];
    let dg12 = [b, a, d, c];
    let dg22 = [0.0, 2.0 * b, 0.0, 2.0 * d];
    let dd = [d, -c, -b, a];
    let quotient = |g: f64, dg: [f64; 4], sign: f64| -> (f64, [f64; 4]) {
        let v = g * inv;
        (sign * v, std::array::from_fn(|i| sign * (dg[i] - v * dd[i]) * inv))
    };
    let (f0, d0) = quotient(g22, dg22, 1.0);
    let (f1, d1) = quotient(g12, dg12, -1.0);
    let (f3, d3) = quotient(g11, dg11, 1.0);
    ([f0, f1, f1, f3], [d0, d1, d1, d3])
}

/// `K_ab = ∫ ∇w_a · A ∇w_b / det J` (`A = [[g22, -g12], [-g12, g11]]`), plus `shift` times
/// the mass matrix, into a scalar stencil; `|det J|` where it is not positive.
pub(crate) fn weak_laplace(disc: &Discretization, cps: &[Point], shift: f64, stencil: &mut [f64]) {
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
                let [a, b, c, d] = gradient_at(disc, ex, ey, cps, s);
                let det = (a * d - b * c).abs().max(1e-300);
                let (g11, g12, g22) = (a * a + c * c, a * b + c * d, b * b + d * d);
                let w = wq / det;
                let (a11, a12, a22) = (w * g22, -w * g12, w * g11);
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

/// Eq. (14) on one level: the [`GalerkinState`] and a scratch net for the feasibility
/// test.
pub(crate) struct WeakFormProblem {
    /// Basis, control points and storage.
    pub state: GalerkinState,
    scratch: Vec<Point>,
}

impl std::fmt::Debug for WeakFormProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WeakFormProblem").field("unknowns", &self.size()).finish()
    }
}

impl WeakFormProblem {
    /// Set up with all control points `cps` (free ones are the start).
    pub fn new(disc: Arc<Discretization>, cps: Vec<Point>) -> Self {
        Self { scratch: cps.clone(), state: GalerkinState::new(disc, cps) }
    }

    /// The current unknown vector.
    #[cfg(test)]
    pub fn unknowns(&self) -> Vec<f64> {
        self.state.unknowns()
    }
}

impl DiscreteProblem for WeakFormProblem {
    fn size(&self) -> usize {
        self.state.size()
    }

    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        let s = &mut self.state;
        s.load(c);
        flux_form(&s.disc, &s.cps, &mut s.res_full, &mut [], weak_flux);
        s.restrict_residual(f);
    }

    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        let s = &mut self.state;
        s.load_for_jacobian(c);
        flux_form(&s.disc, &s.cps, &mut s.res_full, &mut s.stencil, weak_flux);
        s.restrict_residual(f);
        s.gather_jacobian(jac);
    }

    fn mass(&mut self) -> &Csr {
        self.state.mass(|disc, st| disc.mass(st))
    }

    /// `det J > 0` at every quadrature point.
    fn admissible(&mut self, c: &[f64]) -> bool {
        self.state.disc.dofs.scatter(c, &mut self.scratch);
        min_det_j(&self.state.disc, &self.scratch) > 0.0
    }

    /// `K` of [`weak_laplace`] on the current control points.
    fn preconditioner(&mut self, shift: f64) -> Option<&Csr> {
        Some(self.state.preconditioner(|disc, cps, st| weak_laplace(disc, cps, shift, st)))
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
    use crate::methods::density::tests::annulus_points;
    use crate::solve::newton::{NonlinearOptions, NonlinearSolver, Status};
    use crate::spline::knots::KnotVector;
    use crate::testutil::Lcg;

    /// A perturbed annulus sector (positively oriented), with a C0 knot in `ξ`.
    fn curved(seed: u64, noise: f64) -> (Arc<Discretization>, Vec<Point>) {
        let kx = KnotVector::open_uniform(3, 4).with_inserted(&[0.5, 0.5]);
        let ky = KnotVector::open_uniform(2, 3).with_inserted(&[0.3]);
        let cps = annulus_points(&kx, &ky, seed, noise);
        (Arc::new(Discretization::new([kx, ky])), cps)
    }

    #[test]
    fn flux_derivative_matches_finite_differences() {
        let e = [1.3, 0.4, -0.2, 0.9];
        let (_, dg) = weak_flux(e);
        let h = 1e-6;
        for j in 0..4 {
            let (mut ep, mut em) = (e, e);
            ep[j] += h;
            em[j] -= h;
            let (gp, gm) = (weak_flux(ep).0, weak_flux(em).0);
            for i in 0..4 {
                assert!(((gp[i] - gm[i]) / (2.0 * h) - dg[i][j]).abs() < 1e-8, "({i}, {j})");
            }
        }
    }

    /// The exact Jacobian against central differences of the residual, on a curved map
    /// whose basis has a C0 knot line (triple knot at ξ = 1/2 for p = 3).
    #[test]
    fn jacobian_matches_finite_differences() {
        let (disc, cps) = curved(5, 0.04);
        let mut prob = WeakFormProblem::new(disc, cps);
        let c = prob.unknowns();
        assert!(prob.admissible(&c));
        let (err, scale) = crate::methods::jacobian_fd_mismatch(&mut prob, &c, 1e-6);
        assert!(err < 1e-7 * scale, "{err} (scale {scale})");
    }

    /// The affine map solves eq. (14) exactly; Newton from a perturbed interior returns
    /// to it quadratically, and a folded start is refused.
    #[test]
    fn affine_map_is_the_solution() {
        let kx = KnotVector::open_uniform(2, 5).with_inserted(&[0.4]); // C0 at 0.4
        let ky = KnotVector::open_uniform(3, 4);
        let (gx, gy) = (kx.greville(), ky.greville());
        let exact: Vec<Point> =
            gy.iter().flat_map(|&v| gx.iter().map(move |&u| [2.0 * u + 0.5 * v + 1.0, -0.3 * u + 1.5 * v])).collect();
        let disc = Arc::new(Discretization::new([kx, ky]));
        let mut at = WeakFormProblem::new(disc.clone(), exact.clone());
        let ce = at.unknowns();
        let mut f = vec![0.0; ce.len()];
        at.residual(&ce, &mut f);
        let fmax = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(fmax < 1e-13, "{fmax}");
        let mut rng = Lcg::new(9);
        let mut cps = exact.clone();
        for &k in disc.dofs.free() {
            cps[k][0] += 0.05 * (rng.uniform() - 0.5);
            cps[k][1] += 0.05 * (rng.uniform() - 0.5);
        }
        let prob = WeakFormProblem::new(disc.clone(), cps);
        let c0 = prob.unknowns();
        let mut s = NonlinearSolver::new(prob, c0, NonlinearOptions { fallback: false, ..Default::default() });
        let its: Vec<_> = s.by_ref().collect::<crate::Result<Vec<_>>>().unwrap();
        assert_eq!(s.status(), &Status::Converged, "{its:?}");
        assert!(its.len() <= 7, "{its:?}");
        let (prob, c) = s.into_parts();
        let err = prob
            .control_points(&c)
            .iter()
            .zip(&exact)
            .fold(0.0f64, |m, (a, b)| m.max((a[0] - b[0]).abs()).max((a[1] - b[1]).abs()));
        assert!(err < 1e-10, "{err}");
        // a start that folds is outside the admissible set: refused
        let mut folded = exact.clone();
        let mid = disc.dofs.free()[disc.dofs.num_free() / 2];
        folded[mid][0] += 3.0;
        let mut prob = WeakFormProblem::new(disc, folded);
        let c = prob.unknowns();
        assert!(!prob.admissible(&c));
        let mut s = NonlinearSolver::new(prob, c, NonlinearOptions::default());
        for it in s.by_ref() {
            it.unwrap();
        }
        assert!(matches!(s.status(), Status::Failed(why) if why.contains("feasible")));
    }
}
