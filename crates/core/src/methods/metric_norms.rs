//! Two quality functionals of paper §2 (eq. 3) that are norms of the metric tensor
//! `g = JᵀJ` (eq. 2), as minimization methods:
//!
//! * **Liao**: `∫ g11² + g22² + 2 g12² dξ = ∫ |g|_F² dξ = ∫ σ₁⁴ + σ₂⁴ dξ`,
//! * **area orthogonality**: `∫ g11² + g22² dξ = ∫ |x_ξ|⁴ + |x_η|⁴ dξ`,
//!
//! (`σ` the singular values of `J`) over the free control points of one basis. Both are
//! convex in `e = (x_ξ, x_η, y_ξ, y_η)` (a Schatten norm to the fourth power; fourth
//! powers of Euclidean norms), hence in `c`, and both are defined for every map, folded
//! or not: their unconstrained minimizer need not be bijective (paper Fig. 1), which is
//! why Gravesen et al. minimize them subject to `d(c) >= ε`
//! ([`crate::solve::constrained`]).
//!
//! # Derivatives
//!
//! With `g11 = a² + c²`, `g22 = b² + d²`, `g12 = ab + cd` for `e = (a, b, c, d)` and the
//! weight `ω` of `g12²` (`2` for Liao, `0` for area orthogonality), the density
//! `W = g11² + g22² + ω g12²` has
//!
//! * `∂W/∂e = 2 g11 ∇g11 + 2 g22 ∇g22 + 2 ω g12 ∇g12`, `∇g11 = (2a, 0, 2c, 0)`,
//!   `∇g22 = (0, 2b, 0, 2d)`, `∇g12 = (b, a, d, c)`;
//! * `∂²W/∂e² = 2 ∇g11 ∇g11ᵀ + 4 g11 diag(1, 0, 1, 0) + 2 ∇g22 ∇g22ᵀ + 4 g22 diag(0, 1, 0, 1)
//!   + 2 ω (∇g12 ∇g12ᵀ + g12 S)`, `S` the constant Hessian of `g12` (`S_01 = S_10 = S_23 = S_32 = 1`).
//!
//! `e` is linear in `c`, so the gradient and Hessian of `J` are the first-order form of
//! [`flux_form`] with `G = -∂W/∂e` (the sign convention of [`super`]): exact, in the
//! vector pattern of the [`Discretization`].

use std::sync::Arc;

use serde::Serialize;

use super::density::{first_derivatives, integrate, Order};
use super::flux::flux_form;
use super::galerkin::GalerkinState;
use super::{DiscreteProblem, Method};
use crate::discrete::assembly::Discretization;
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// Which norm of the metric tensor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum MetricNorm {
    /// `∫ g11² + g22² + 2 g12²` (Liao).
    Liao,
    /// `∫ g11² + g22²` (area orthogonality).
    AreaOrthogonality,
}

impl MetricNorm {
    /// The weight `ω` of `g12²`.
    fn omega(self) -> f64 {
        match self {
            MetricNorm::Liao => 2.0,
            MetricNorm::AreaOrthogonality => 0.0,
        }
    }

    /// Short name (`liao`, `area-orthogonality`).
    pub fn name(self) -> &'static str {
        match self {
            MetricNorm::Liao => "liao",
            MetricNorm::AreaOrthogonality => "area-orthogonality",
        }
    }
}

/// The density `W = g11² + g22² + ω g12²` of `e = (x_ξ, x_η, y_ξ, y_η)` with its gradient
/// and Hessian in `e` (formulas in the module documentation).
pub(crate) fn metric_density(norm: MetricNorm, e: [f64; 4]) -> (f64, [f64; 4], [[f64; 4]; 4]) {
    let [a, b, c, d] = e;
    let w12 = norm.omega();
    let (g11, g22, g12) = (a * a + c * c, b * b + d * d, a * b + c * d);
    let n11 = [2.0 * a, 0.0, 2.0 * c, 0.0];
    let n22 = [0.0, 2.0 * b, 0.0, 2.0 * d];
    let n12 = [b, a, d, c];
    let w = g11 * g11 + g22 * g22 + w12 * g12 * g12;
    let grad: [f64; 4] = std::array::from_fn(|i| 2.0 * g11 * n11[i] + 2.0 * g22 * n22[i] + 2.0 * w12 * g12 * n12[i]);
    let mut h = [[0.0; 4]; 4];
    for (i, row) in h.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = 2.0 * (n11[i] * n11[j] + n22[i] * n22[j] + w12 * n12[i] * n12[j]);
        }
    }
    for (i, g) in [g11, g22, g11, g22].into_iter().enumerate() {
        h[i][i] += 4.0 * g;
    }
    for (i, j) in [(0, 1), (1, 0), (2, 3), (3, 2)] {
        h[i][j] += 2.0 * w12 * g12;
    }
    (w, grad, h)
}

/// `∫ W(∇x) dξ` of a density `W` of `e = (x_ξ, x_η, y_ξ, y_η)` by the quadrature of
/// `disc`; rows of elements in parallel, summed in order (deterministic).
pub(crate) fn density_integral(disc: &Discretization, cps: &[Point], density: impl Fn([f64; 4]) -> f64 + Sync) -> f64 {
    integrate(disc, cps, Order::First, |e| density(first_derivatives(e)))
}

/// A metric norm (Liao or area orthogonality) minimized from any start.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MetricNormMethod(pub MetricNorm);

impl Method for MetricNormMethod {
    fn name(&self) -> &'static str {
        self.0.name()
    }

    /// `∂W/∂e ~ diam³`, so `∂J/∂c_i ~ diam³ / sqrt(m)`.
    fn residual_size(&self, diameter: f64) -> f64 {
        diameter.powi(3)
    }

    /// `|∇J| ~ diam³` whatever `m`.
    fn residual_scale(&self, diameter: f64, _m: usize) -> f64 {
        1.0 / diameter.powi(3)
    }

    fn problem(&self, disc: Arc<Discretization>, control_points: Vec<Point>) -> Box<dyn DiscreteProblem + Send> {
        Box::new(MetricNormProblem::new(self.0, disc, control_points))
    }
}

/// A metric norm on one level: `F = -∇J`, `dF/dc = -∇²J` (exact), objective `J`.
#[derive(Debug)]
pub(crate) struct MetricNormProblem {
    norm: MetricNorm,
    /// Basis, control points and storage.
    pub state: GalerkinState,
}

impl MetricNormProblem {
    /// Set up with all control points `cps` (free ones are the start).
    pub fn new(norm: MetricNorm, disc: Arc<Discretization>, cps: Vec<Point>) -> Self {
        Self { norm, state: GalerkinState::new(disc, cps) }
    }

    /// The current unknown vector.
    #[cfg(test)]
    pub fn unknowns(&self) -> Vec<f64> {
        self.state.unknowns()
    }

    fn flux(norm: MetricNorm) -> impl Fn([f64; 4]) -> ([f64; 4], [[f64; 4]; 4]) + Sync {
        move |e| {
            let (_, g, h) = metric_density(norm, e);
            (g.map(|v| -v), h.map(|row| row.map(|v| -v)))
        }
    }
}

impl DiscreteProblem for MetricNormProblem {
    fn size(&self) -> usize {
        self.state.size()
    }

    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        let s = &mut self.state;
        s.load(c);
        flux_form(&s.disc, &s.cps, &mut s.res_full, &mut [], Self::flux(self.norm));
        s.restrict_residual(f);
    }

    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        let s = &mut self.state;
        s.load_for_jacobian(c);
        flux_form(&s.disc, &s.cps, &mut s.res_full, &mut s.stencil, Self::flux(self.norm));
        s.restrict_residual(f);
        s.gather_jacobian(jac);
    }

    fn mass(&mut self) -> &Csr {
        self.state.mass(|disc, st| disc.mass(st))
    }

    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        let norm = self.norm;
        Some(density_integral(&self.state.disc, &self.state.control_points(c), |e| metric_density(norm, e).0))
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
