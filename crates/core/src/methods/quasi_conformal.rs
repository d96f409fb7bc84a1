//! The quasi-conformal method (paper §10.2, eq. 47-48, after Nian and Chen 2016):
//! minimize
//!
//! `T(x, k) = ∫ (f − k²)² dξ`,  `f = ((x_ξ − y_η)² + (y_ξ + x_η)²) / ((x_ξ + y_η)² + (y_ξ − x_η)²)`
//!
//! over the free control points and the scalar `k`. With `N = |∇x|²` and `D = det J`,
//! `f = (N − 2D) / (N + 2D) = |μ|²`, the squared modulus of the Beltrami coefficient
//! `μ = x_z̄ / x_z`: `f = 0` for a conformal map, `0 <= f < 1` where `D > 0`, `f > 1` where
//! the map folds, and `f` is undefined only where `N + 2D = 0` (an anti-conformal
//! point), where `QuasiConformalMethod` returns `+∞`. Minimizing `T` makes the
//! distortion `|μ|` as uniform as the boundary allows (a Teichmüller-like map); nothing
//! in `T` forbids folds, so the certificate decides.
//!
//! # The scalar `k`: eliminated
//!
//! `T` is quadratic in `s = k²`, minimized at the mean `s* = ∫ f / ∫ 1` (`>= 0`, so
//! `k = √s*` is real). The problem solved is therefore the reduced functional
//!
//! `T*(c) = min_k T(c, k) = ∫ (f − f̄)²`,  `f̄ = ∫ f / ∫ 1`,
//!
//! the variance of `f` over the parameter square (variable projection; `k` is recovered
//! as `√f̄`). By the envelope theorem `∇T* = ∫ 2 (f − f̄) ∇f`, and its exact Hessian is
//! the Schur complement of the bordered Hessian in `(c, s)`:
//!
//! `∇²T* = ∫ 2 (∇f ∇fᵀ + (f − f̄) ∇²f) − (2 / ∫ 1) g gᵀ`,  `g = ∫ ∇f`,
//!
//! a sparse matrix (the density `(f − s)²` at fixed `s = f̄`, assembled by
//! `density`) minus a dense rank-one term, which `QuasiConformalProblem`
//! presents through [`DiscreteProblem::rank_one`] and the Newton solver applies by the
//! Sherman-Morrison formula: the steps of the bordered system on the shared sparse
//! factorizations, without a matrix with a dense row and column, and without an extra
//! unknown in the hierarchy's vectors (the Gauss-Newton matrix below has the same
//! rank-one term). Parameterising by `s` rather than `k` also removes the symmetry `k ↔ −k` and
//! the singular Hessian at `k = 0` of the paper's form.
//!
//! # Globalisation: Levenberg-Marquardt
//!
//! The paper reports that Newton's method applied to `∂T/∂c` "generally did not lead to
//! convergence" and used IPOPT. `T*` is a nonlinear least-squares functional (the
//! residual `f − f̄` at every quadrature point), and the method used here is the one made
//! for those: Levenberg-Marquardt on the shared sparse machinery. The presented Hessian
//! is by default the Gauss-Newton matrix
//!
//! `H_GN = ∫ 2 ∇f ∇fᵀ − (2 / ∫ 1) g gᵀ = 2 ∫ (∇f − ḡ)(∇f − ḡ)ᵀ`,  `ḡ = g / ∫ 1`,
//!
//! (the covariance of `∇f`: positive semidefinite at every map, so every direction
//! descends), plus the shift `τ diag(|H_ii|)` of `ShiftedHessian`, which the Armijo
//! line search of [`crate::solve::newton`] drives as an LM method drives its damping: a
//! heavily damped step raises `τ`, a full step lowers it. The exact Hessian (the extra
//! term `∫ 2 (f − f̄) ∇²f`, [`QcHessian::Exact`]) is available and tested, but is not the
//! default: it is indefinite away from a minimizer, and Newton's method with it, even
//! globalised by the same shift and line search, stops at much poorer critical points on
//! the shared geometries (`T*` of the quarter annulus 1.6e-4 against 1.1e-5 with
//! Gauss-Newton, the disk 5.4e-4 against 2.3e-4, Cook's membrane 3.0e-4 against 9.3e-5;
//! `winslow compare --qc-hessian exact`). A general optimisation crate (L-BFGS, trust
//! region) would see neither the sparsity nor the least-squares structure.
//!
//! # Degenerate minimizers
//!
//! Since `f = |μ|²`, a first-order change of `arg μ` leaves `f` unchanged: `∇²T*` is
//! singular at a minimizer (for an affine boundary, where `T* = 0` at the affine map,
//! `T*` grows like the fourth power of the distance along those directions). Convergence
//! is therefore linear, not quadratic: tens to hundreds of iterations where EGG needs a
//! handful, which is the paper's observation too.

use std::sync::Arc;

use super::density::{assemble, integrate, outer, Jet, JetMatrix, Order, ShiftedHessian, JET};
use super::galerkin::GalerkinState;
use super::{DiscreteProblem, Method};
use crate::discrete::assembly::Discretization;
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// The quasi-conformal functional of eq. (47)-(48), minimized from any start by
/// Levenberg-Marquardt (or Newton's method), `k` eliminated (module documentation).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct QuasiConformalMethod {
    /// Which Hessian the iteration uses.
    pub hessian: QcHessian,
}

/// The Hessian of `T*` presented to the nonlinear solver.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum QcHessian {
    /// The Gauss-Newton matrix `2 ∫ (∇f − ḡ)(∇f − ḡ)ᵀ` (Levenberg-Marquardt).
    #[default]
    GaussNewton,
    /// The exact Hessian (Newton's method).
    Exact,
}

impl Method for QuasiConformalMethod {
    fn name(&self) -> &'static str {
        "qc"
    }

    /// `f` is dimensionless, `∂f/∂(∇x) ~ 1 / D`.
    fn residual_size(&self, diameter: f64) -> f64 {
        1.0 / diameter
    }

    /// `|∇T*| ~ 1 / D` whatever `m` (a form `∫ ∇w_a · G` with `G ~ 1 / D`, as eq. 16).
    fn residual_scale(&self, diameter: f64, _m: usize) -> f64 {
        diameter
    }

    fn problem(&self, disc: Arc<Discretization>, control_points: Vec<Point>) -> Box<dyn DiscreteProblem + Send> {
        Box::new(QuasiConformalProblem::new(disc, control_points, self.hessian))
    }
}

/// Jet slots of `(x_ξ, x_η, y_ξ, y_η)`.
const SLOTS: [usize; 4] = [0, 1, 5, 6];

/// `f` of eq. (48) with its gradient and, when `hessian`, Hessian in the jet; `f = +∞`
/// where the denominator `N + 2D` is not positive.
pub(crate) fn beltrami(e: &Jet, hessian: bool) -> (f64, Jet, JetMatrix) {
    let (a, b, c, d) = (e[0], e[1], e[5], e[6]);
    let (pm, pp) = (a - d, b + c);
    let (qp, qm) = (a + d, c - b);
    let p = pm * pm + pp * pp;
    let q = qp * qp + qm * qm;
    let mut grad = [0.0; JET];
    let mut hess = [[0.0; JET]; JET];
    if q.is_nan() || q <= 0.0 {
        return (f64::INFINITY, grad, hess);
    }
    let f = p / q;
    let dp = [2.0 * pm, 2.0 * pp, 2.0 * pp, -2.0 * pm];
    let dq = [2.0 * qp, -2.0 * qm, 2.0 * qm, 2.0 * qp];
    for (k, &s) in SLOTS.iter().enumerate() {
        grad[s] = (dp[k] - f * dq[k]) / q;
    }
    if hessian {
        const D2P: [[f64; 4]; 4] =
            [[2.0, 0.0, 0.0, -2.0], [0.0, 2.0, 2.0, 0.0], [0.0, 2.0, 2.0, 0.0], [-2.0, 0.0, 0.0, 2.0]];
        const D2Q: [[f64; 4]; 4] =
            [[2.0, 0.0, 0.0, 2.0], [0.0, 2.0, -2.0, 0.0], [0.0, -2.0, 2.0, 0.0], [2.0, 0.0, 0.0, 2.0]];
        for (i, &si) in SLOTS.iter().enumerate() {
            for (j, &sj) in SLOTS.iter().enumerate() {
                hess[si][sj] = (D2P[i][j] - f * D2Q[i][j] - grad[si] * dq[j] - dq[i] * grad[sj]) / q;
            }
        }
    }
    (f, grad, hess)
}

/// The density `(f − s)²` at fixed `s`: gradient and, when `hessian` is given, the
/// exact Hessian `2 (∇f ∇fᵀ + (f − s) ∇²f)` or its Gauss-Newton part `2 ∇f ∇fᵀ`.
fn deviation_derivatives(e: &Jet, s: f64, hessian: Option<QcHessian>) -> (Jet, JetMatrix) {
    let exact = hessian == Some(QcHessian::Exact);
    let (f, g, h) = beltrami(e, exact);
    let r = f - s;
    let grad = g.map(|v| 2.0 * r * v);
    let mut hess = [[0.0; JET]; JET];
    if hessian.is_some() {
        let gg = outer(&g, &g);
        for i in 0..JET {
            for j in 0..JET {
                hess[i][j] = 2.0 * gg[i][j] + if exact { 2.0 * r * h[i][j] } else { 0.0 };
            }
        }
    }
    (grad, hess)
}

#[cfg(test)]
/// The value of eq. (47) at its optimal `k` and that `k`: `(T*, k)` with
/// `k² = f̄ = ∫ f / ∫ 1` (module documentation), on the quadrature of `disc`; `T* = +∞`
/// (and `k` not finite) where `f` is undefined at a quadrature point.
pub(crate) fn quasi_conformal_value(disc: &Discretization, cps: &[Point]) -> (f64, f64) {
    value_on(disc, cps, integrate(disc, cps, Order::First, |_| 1.0))
}

/// [`quasi_conformal_value`] with `∫ 1 = area` known.
fn value_on(disc: &Discretization, cps: &[Point], area: f64) -> (f64, f64) {
    let mean = integrate(disc, cps, Order::First, |e| beltrami(e, false).0) / area;
    if !mean.is_finite() {
        return (f64::INFINITY, f64::NAN);
    }
    let t = integrate(disc, cps, Order::First, |e| {
        let r = beltrami(e, false).0 - mean;
        r * r
    });
    (t, mean.sqrt())
}

/// The quasi-conformal functional on one level: the `GalerkinState`, the shifted
/// Hessian and the rank-one term of the eliminated `k`.
pub(crate) struct QuasiConformalProblem {
    /// Basis, control points and storage.
    pub(crate) state: GalerkinState,
    hessian: ShiftedHessian,
    /// `∫ 1` on the quadrature (the parameter square's area, 1 up to rounding).
    area: f64,
    /// `f̄` at the control points of the last assembly.
    mean: f64,
    /// `g = ∫ ∇f` restricted to the free unknowns, at the last Hessian's point.
    g: Vec<f64>,
    /// Storage for the full-length `g`.
    g_full: Vec<f64>,
    /// Which Hessian is presented.
    kind: QcHessian,
}

impl std::fmt::Debug for QuasiConformalProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("QuasiConformalProblem")
            .field("unknowns", &self.size())
            .field("k", &self.mean.sqrt())
            .field("shift", &self.hessian.shift())
            .finish()
    }
}

impl QuasiConformalProblem {
    /// Set up with all control points `cps` (free ones are the start), presenting the
    /// Hessian `kind`.
    pub fn new(disc: Arc<Discretization>, cps: Vec<Point>, kind: QcHessian) -> Self {
        let hessian = ShiftedHessian::new(&disc);
        let area = integrate(&disc, &cps, Order::First, |_| 1.0);
        let n = disc.dofs.num_total();
        Self {
            state: GalerkinState::new(disc, cps),
            hessian,
            area,
            mean: f64::NAN,
            g: Vec::new(),
            g_full: vec![0.0; 2 * n],
            kind,
        }
    }

    #[cfg(test)]
    /// The current unknown vector.
    pub fn unknowns(&self) -> Vec<f64> {
        self.state.unknowns()
    }

    /// `f̄` of the loaded control points, then `-∇T*` into the full residual and, with
    /// `hessian`, the sparse part of `-∇²T*` into the stencil and `g`.
    fn assemble(&mut self, hessian: bool) {
        let s = &mut self.state;
        self.mean = integrate(&s.disc, &s.cps, Order::First, |e| beltrami(e, false).0) / self.area;
        let mean = self.mean;
        if !mean.is_finite() {
            s.res_full.fill(f64::NAN);
            return;
        }
        let stencil: &mut [f64] = if hessian { &mut s.stencil } else { &mut [] };
        let kind = self.kind;
        assemble(&s.disc, &s.cps, Order::First, &mut s.res_full, stencil, |e, h| {
            deviation_derivatives(e, mean, h.then_some(kind))
        });
        if hessian {
            // -g, from the form of the density f alone (the sign drops out of g gᵀ)
            assemble(&s.disc, &s.cps, Order::First, &mut self.g_full, &mut [], |e, _| {
                (beltrami(e, false).1, [[0.0; JET]; JET])
            });
            self.g = s.disc.restrict(&self.g_full, 2);
        }
    }
}

impl DiscreteProblem for QuasiConformalProblem {
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

    /// `dF/dc = -∇²T* = jac + (2 / ∫ 1) g gᵀ`.
    fn rank_one(&self) -> Option<(f64, &[f64])> {
        (!self.g.is_empty()).then(|| (2.0 / self.area, self.g.as_slice()))
    }

    fn mass(&mut self) -> &Csr {
        self.state.mass(|disc, st| disc.mass(st))
    }

    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        Some(value_on(&self.state.disc, &self.state.control_points(c), self.area).0)
    }

    fn raise_shift(&mut self) -> bool {
        self.hessian.raise()
    }

    fn step_accepted(&mut self, delta: f64) {
        self.hessian.accepted(delta);
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

    fn jet(a: f64, b: f64, c: f64, d: f64) -> Jet {
        let mut e = [0.0; JET];
        (e[0], e[1], e[5], e[6]) = (a, b, c, d);
        e
    }

    /// `f = |μ|²`: zero for a conformal Jacobian, `(s₁ − s₂)² / (s₁ + s₂)²` for a stretch,
    /// above one for a reflection; derivatives against finite differences.
    #[test]
    fn beltrami_values_and_derivatives() {
        // rotation-scaling: conformal
        assert!(beltrami(&jet(1.2, -0.5, 0.5, 1.2), false).0.abs() < 1e-15);
        // stretch diag(3, 1): |μ| = (3 - 1) / (3 + 1)
        assert!((beltrami(&jet(3.0, 0.0, 0.0, 1.0), false).0 - 0.25).abs() < 1e-15);
        // a reflection folds: f = 4 for diag(3, -1)
        assert!((beltrami(&jet(3.0, 0.0, 0.0, -1.0), false).0 - 4.0).abs() < 1e-14);
        // anti-conformal: undefined
        assert_eq!(beltrami(&jet(1.0, 0.3, 0.3, -1.0), false).0, f64::INFINITY);
        let slots = SLOTS.to_vec();
        for e in [jet(1.3, 0.4, -0.2, 0.9), jet(0.5, -1.1, 0.7, 0.2)] {
            let (eg, eh) =
                density_fd(|e| beltrami(e, false).0, |e, h| (beltrami(e, h).1, beltrami(e, h).2), &e, &slots);
            assert!(eg < 1e-8 && eh < 1e-7, "{e:?}: gradient {eg}, Hessian {eh}");
            let (eg, eh) = density_fd(
                |e| (beltrami(e, false).0 - 0.3).powi(2),
                |e, h| deviation_derivatives(e, 0.3, h.then_some(QcHessian::Exact)),
                &e,
                &slots,
            );
            assert!(eg < 1e-8 && eh < 1e-7, "{e:?}: (f - s)²: gradient {eg}, Hessian {eh}");
        }
    }

    /// `F = -∇T*` against differences of `T*` (with `k` re-optimised at every point), and
    /// the exact `dF/dc` with its rank-one term against differences of `F`.
    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let (disc, cps) = curved(3, 2, 5, 0.05);
        let mut prob = QuasiConformalProblem::new(Arc::new(disc), cps, QcHessian::Exact);
        let c = prob.unknowns();
        let (eg, eh) = problem_fd(&mut prob, &c, 1e-6);
        assert!(eg < 1e-7 && eh < 1e-7, "gradient {eg}, Hessian {eh}");
        // the rank-one term is not negligible: without it the Jacobian is off
        let mut f = vec![0.0; c.len()];
        let mut jac = Csr::default();
        prob.jacobian(&c, &mut f, &mut jac);
        let (sigma, g) = prob.rank_one().unwrap();
        let big = g.iter().fold(0.0f64, |m, v| m.max(sigma * v * v));
        let sparse = jac.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(big > 1e-3 * sparse, "rank-one {big} vs sparse {sparse}");
    }

    /// The Gauss-Newton matrix (with its rank-one term) is symmetric and negative
    /// semidefinite as presented (`-H_GN`, the covariance of `∇f`), differs from the
    /// exact Hessian by the curvature term only, and comes with the same gradient.
    #[test]
    fn gauss_newton_matrix_is_the_covariance_of_the_gradient_of_f() {
        let (disc, cps) = curved(3, 2, 5, 0.05);
        let disc = Arc::new(disc);
        let dense = |kind| {
            let mut prob = QuasiConformalProblem::new(disc.clone(), cps.clone(), kind);
            let c = prob.unknowns();
            let (mut f, mut jac) = (vec![0.0; c.len()], Csr::default());
            prob.jacobian(&c, &mut f, &mut jac);
            let mut d = jac.to_dense();
            let (sigma, g) = prob.rank_one().unwrap();
            for (row, gi) in d.iter_mut().zip(g) {
                for (v, gj) in row.iter_mut().zip(g) {
                    *v += sigma * gi * gj;
                }
            }
            (f, d)
        };
        let (f_gn, gn) = dense(QcHessian::GaussNewton);
        let (f_ex, ex) = dense(QcHessian::Exact);
        assert_eq!(f_gn, f_ex);
        let n = gn.len();
        let scale = gn.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        // symmetric, and -H_GN = -2 ∫ (∇f - ḡ)(∇f - ḡ)ᵀ: xᵀ (-H_GN) x <= 0
        let mut rng = crate::testutil::Lcg::new(3);
        for _ in 0..20 {
            let x: Vec<f64> = (0..n).map(|_| rng.uniform() - 0.5).collect();
            let q: f64 = (0..n).map(|i| x[i] * (0..n).map(|j| gn[i][j] * x[j]).sum::<f64>()).sum();
            assert!(q <= 1e-12 * scale * n as f64, "xᵀ H x = {q}");
        }
        for i in 0..n {
            for j in 0..n {
                assert!((gn[i][j] - gn[j][i]).abs() <= 1e-12 * scale);
            }
        }
        // the exact Hessian differs (the curvature term is not zero on a curved map)
        let diff = gn.iter().flatten().zip(ex.iter().flatten()).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(diff > 1e-6 * scale, "{diff}");
    }

    /// With an affine boundary the affine map has constant `f`, so `T* = 0`: Newton
    /// converges to it from a perturbed interior, with `k² = f` of the affine Jacobian.
    /// The minimizer is degenerate: first-order changes of `arg μ` leave `f = |μ|²`
    /// unchanged, so `∇²T*` is singular there, convergence is linear (tens of
    /// iterations, against a handful for EGG) and along those directions `T*` grows like
    /// the fourth power of the distance, its gradient like the third: a stopping rule on
    /// the gradient resolves the map there only to about the cube root of its tolerance.
    #[test]
    fn minimiser_of_an_affine_boundary_is_the_affine_map() {
        for (p, kind) in [(2, QcHessian::GaussNewton), (3, QcHessian::GaussNewton), (3, QcHessian::Exact)] {
            let (disc, cps, exact) = affine(p, 5, 9, 0.04);
            let (t, k) = quasi_conformal_value(&disc, &exact);
            let f = beltrami(&jet(2.0, 0.5, -0.3, 1.5), false).0;
            assert!(t < 1e-28 && (k * k - f).abs() < 1e-14, "T* = {t}, k² = {} vs {f}", k * k);
            let m = disc.dofs.num_free();
            let method = QuasiConformalMethod { hessian: kind };
            let scale = (m as f64).sqrt() * method.residual_scale(2.5, m);
            let c0 = disc.dofs.gather(&cps);
            let (converged, its, err) = newton_to(method.problem(disc, cps), c0, scale, &exact);
            assert!(converged, "p = {p}, {kind:?}");
            assert!(err < 1e-5, "p = {p}, {kind:?}: distance to the affine map {err} after {its} iterations");
        }
    }
}
