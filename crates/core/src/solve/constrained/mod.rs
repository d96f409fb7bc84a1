//! Constrained quality optimisation (Gravesen et al. 2012; paper §10.3): minimise a
//! quality functional of eq. (3) subject to positive Bernstein coefficients of `det J`,
//! started from a feasible map.
//!
//! Let `d(c)` be the Bernstein coefficients of `det J` on every element
//! (`DetCoefficients`): `d > 0` proves `det J > 0` (convex hull), so every feasible
//! map is bijective. The coefficients fixed by the boundary alone (`det J` at the four
//! corners) are no constraints; they must be positive for any map of this boundary to be
//! feasible.
//!
//! * **Feasible start, eq. (49)** ([`max_z`]): maximise `z` subject to `d(c) >= z 1` over
//!   the free control points, stopped as soon as `z` exceeds its target (`0`: a
//!   certified start). A sequential LP with a trust region on the control points; each
//!   LP is solved by Clarabel.
//! * **Constrained optimisation** ([`optimise`]): minimise `J(c)` (Liao, Winslow eq. 16,
//!   or area orthogonality) subject to `d(c) >= ε`, `ε` a fraction of the mean `det J`,
//!   by SQP with a trust region: each step solves the QP of the exact gradient and
//!   Hessian of `J` (optionally of the Lagrangian `J - λᵀ (d - ε)`; `∇²d` is constant:
//!   `d` is bilinear), is corrected to second order with the exact constraint remainder,
//!   and is accepted by the ℓ₁ merit function `J + μ Σ max(0, ε - d_k)`. A start with
//!   some `d_k < ε` is first made feasible by [`max_z`] with target `ε`.
//!
//! [`run`] composes them as in the paper's Table 3: from the EGG map (G) or from the
//! max-z point of the Coons patch (Z), on the EGG map's basis. Every result is
//! certified by [`certify`]; a result that is not says so, with its best iterate.

mod feasible;
mod qp;
mod sqp;

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

pub use feasible::max_z;
pub use sqp::{optimise, MAX_UNKNOWNS};

use crate::discrete::assembly::Discretization;
use crate::discrete::dofs::DofMap;
use crate::discrete::topology::Topology;
use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;
use crate::methods::metric_norms::{MetricNorm, MetricNormMethod};
use crate::methods::winslow::WinslowMethod;
use crate::methods::Method;
use crate::spline::curve::Point;
use crate::spline::surface::{Side, Surface};
use crate::verify::certificate::coefficients::DetCoefficients;
use crate::verify::certificate::{certify, Certificate, CertifyOptions, Finding};

/// The quality functional minimised subject to `d(c) >= ε`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Functional {
    /// `∫ g11² + g22² + 2 g12²` (eq. 3).
    Liao,
    /// `∫ (g11 + g22) / det J` (eq. 16).
    Winslow,
    /// `∫ g11² + g22²` (eq. 3).
    #[cfg_attr(feature = "clap", value(name = "ao"))]
    AreaOrthogonality,
}

impl Functional {
    /// Short name (`liao`, `winslow`, `ao`).
    pub fn name(self) -> &'static str {
        match self {
            Functional::Liao => "liao",
            Functional::Winslow => "winslow",
            Functional::AreaOrthogonality => "ao",
        }
    }

    /// The minimisation method of the functional (objective, exact gradient and Hessian).
    pub fn method(self) -> Arc<dyn Method> {
        match self {
            Functional::Liao => Arc::new(MetricNormMethod(MetricNorm::Liao)),
            Functional::Winslow => Arc::new(WinslowMethod),
            Functional::AreaOrthogonality => Arc::new(MetricNormMethod(MetricNorm::AreaOrthogonality)),
        }
    }
}

/// Options of [`max_z`], [`optimise`] and [`run`].
#[derive(Debug, Clone, Copy)]
pub struct ConstrainedOptions {
    /// `ε` of the constraints `d(c) >= ε`, relative to the mean `det J` (area over
    /// parameter area).
    pub eps: f64,
    /// Most SQP iterations (QP subproblems) of [`optimise`].
    pub max_iterations: usize,
    /// Most LP iterations of [`max_z`].
    pub max_z_iterations: usize,
    /// [`optimise`] stops when the QP step predicts a decrease of the merit function
    /// below `tol |J|` inside the trust region.
    pub tol: f64,
    /// Initial trust-region radius (largest move of a control point coordinate),
    /// relative to the diameter of the control net.
    pub radius: f64,
    /// The QP Hessian of [`optimise`]: the Lagrangian's (exact constraint curvature, made
    /// semidefinite on the active constraints) instead of the functional's.
    pub lagrangian_hessian: bool,
    /// The certificate of the result.
    pub certify: CertifyOptions,
}

impl Default for ConstrainedOptions {
    fn default() -> Self {
        Self {
            eps: 1e-2,
            max_iterations: 200,
            max_z_iterations: 200,
            tol: 1e-10,
            radius: 0.05,
            lagrangian_hessian: false,
            certify: CertifyOptions::default(),
        }
    }
}

impl ConstrainedOptions {
    /// [`Error::Invalid`] naming the option when `ε` is not in `(0, 1)` (a fraction of the
    /// mean `det J`), an iteration limit is 0, or the tolerance or the trust radius is not
    /// positive and finite.
    pub fn validate(&self) -> Result<()> {
        if !(self.eps > 0.0 && self.eps < 1.0) {
            return Err(Error::Invalid(format!(
                "eps must be in (0, 1) (a fraction of the mean det J), got {}",
                self.eps
            )));
        }
        if self.max_iterations == 0 || self.max_z_iterations == 0 {
            return Err(Error::Invalid(format!(
                "the SQP and LP iteration limits must be at least 1, got {} and {}",
                self.max_iterations, self.max_z_iterations
            )));
        }
        for (name, v) in [("tol", self.tol), ("radius", self.radius)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Invalid(format!("{name} must be positive and finite, got {v}")));
            }
        }
        Ok(())
    }
}

/// What [`max_z`] did.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct MaxZReport {
    /// `"maxz"`.
    pub name: &'static str,
    /// LP subproblems solved.
    pub iterations: usize,
    /// Whether `z` exceeded the target.
    pub converged: bool,
    /// Why it stopped.
    pub why: String,
    /// Target of `z`, relative to the mean `det J`.
    pub target: f64,
    /// `z = min_k d_k` over the constraints, relative to the mean `det J`, at the start
    /// and after each accepted step.
    pub z_history: Vec<f64>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// The result of [`max_z`].
#[derive(Debug, Clone)]
pub struct MaxZ {
    /// The report.
    pub report: MaxZReport,
    /// All control points of the last iterate (the best `z` found).
    pub control_points: Vec<Point>,
}

/// What [`optimise`] did.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct OptimiseReport {
    /// The functional's name (`liao`, `winslow`, `ao`).
    pub name: &'static str,
    /// The functional.
    pub functional: Functional,
    /// The feasibility restoration of a start with some `d_k < ε` (eq. 49 with target `ε`).
    pub restoration: Option<MaxZReport>,
    /// SQP iterations (QP subproblems solved, rejected steps included).
    pub iterations: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Whether the stopping rule was met.
    pub converged: bool,
    /// Why it stopped.
    pub why: String,
    /// `ε`, relative to the mean `det J`.
    pub eps: f64,
    /// The functional at the start (after restoration) and after each accepted step.
    pub objective_history: Vec<f64>,
    /// Smallest constraint coefficient `min_k d_k` at the result, relative to the mean `det J`.
    pub min_coefficient: f64,
    /// Wall-clock seconds (restoration included).
    pub seconds: f64,
}

/// The result of [`optimise`].
#[derive(Debug, Clone)]
pub struct Optimised {
    /// The report.
    pub report: OptimiseReport,
    /// All control points of the result (the last accepted iterate).
    pub control_points: Vec<Point>,
}

/// The constraints `d_k(c)` that depend on the unknowns, on one basis.
#[derive(Debug)]
pub(crate) struct Constraints {
    coeffs: DetCoefficients,
    dofs: DofMap,
    /// Rows of `d` that depend on the unknowns.
    rows: Vec<usize>,
    /// Smallest coefficient fixed by the boundary (`+∞` if none) and its row.
    fixed_min: (f64, usize),
    /// Mean `det J` (area over parameter area; fixed by the boundary).
    mean: f64,
    /// Diameter of the start's control net.
    diameter: f64,
}

impl Constraints {
    /// The constraints of `disc` (a polynomial basis) at the start `cps`.
    pub(crate) fn new(disc: &Discretization, cps: &[Point]) -> Result<Self> {
        if disc.is_rational() {
            return Err(Error::Invalid(
                "the det J coefficient constraints need a polynomial basis (the numerator of a rational map's det J \
                 is not bilinear in its control points): use the fitted basis"
                    .into(),
            ));
        }
        let coeffs = DetCoefficients::new(&disc.knots)?;
        let free = coeffs.depends_on_unknowns(&disc.dofs);
        let d = coeffs.values(cps);
        let rows: Vec<usize> = (0..d.len()).filter(|&k| free[k]).collect();
        let fixed_min = (0..d.len()).filter(|&k| !free[k]).map(|k| (d[k], k)).fold((f64::INFINITY, 0), |a, b| {
            if b.0 < a.0 {
                b
            } else {
                a
            }
        });
        let ((u0, u1), (v0, v1)) = (disc.knots[0].domain(), disc.knots[1].domain());
        let mean = coeffs.area(&d) / ((u1 - u0) * (v1 - v0));
        if !(mean.is_finite() && mean > 0.0) {
            return Err(Error::Invalid(format!(
                "the map's area is {mean:.3e}: the boundary must run counter-clockwise"
            )));
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in cps {
            for z in 0..2 {
                lo[z] = lo[z].min(p[z]);
                hi[z] = hi[z].max(p[z]);
            }
        }
        let diameter = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        Ok(Self { coeffs, dofs: disc.dofs.clone(), rows, fixed_min, mean, diameter })
    }

    /// The constraint values `d_k`, `k` in `rows`.
    pub(crate) fn values(&self, cps: &[Point]) -> Vec<f64> {
        let d = self.coeffs.values(cps);
        self.rows.iter().map(|&k| d[k]).collect()
    }

    /// `∂d_k/∂c` for `k` in `rows`.
    pub(crate) fn jacobian(&self, cps: &[Point]) -> Csr {
        let full = self.coeffs.jacobian(cps, &self.dofs);
        let rows = self.rows.iter().map(|&k| full.row(k).collect()).collect();
        Csr::from_rows(full.ncols, rows)
    }

    /// `Σ_k λ_k ∇²d_k` for multipliers `λ` of the `rows`.
    pub(crate) fn weighted_hessian(&self, lambda: &[f64]) -> Csr {
        let mut full = vec![0.0; self.coeffs.len()];
        for (&k, &l) in self.rows.iter().zip(lambda) {
            full[k] = l;
        }
        self.coeffs.weighted_hessian(&full, &self.dofs)
    }

    /// A reason why no map of this boundary is feasible: a coefficient fixed by the
    /// boundary (a corner's `det J`) that is not positive.
    pub(crate) fn boundary_obstruction(&self) -> Option<String> {
        let (v, k) = self.fixed_min;
        (v <= 0.0).then(|| {
            let per = self.coeffs.per_element();
            let e = k / per;
            let n = self.coeffs.shape()[0];
            format!(
                "the boundary fixes det J = {v:.3e} <= 0 at a corner (coefficient {} of element ({}, {})): no map of \
                 this boundary has positive Bernstein coefficients",
                k % per,
                e % n,
                e / n
            )
        })
    }
}

/// `min` of a slice (`+∞` when empty).
pub(crate) fn min_of(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

/// Where the constrained optimisation of [`run`] starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StartFrom {
    /// The EGG map (G).
    Egg,
    /// The max-z point (eq. 49) reached from the Coons patch of the boundary (Z).
    MaxZ,
}

impl StartFrom {
    /// `egg` or `maxz`.
    pub fn name(self) -> &'static str {
        match self {
            StartFrom::Egg => "egg",
            StartFrom::MaxZ => "maxz",
        }
    }
}

/// The result of [`run`] and [`run_max_z`].
#[derive(Debug, Clone, Serialize)]
pub struct Outcome {
    /// `"{functional}-from-{start}"` or `"maxz"`.
    pub name: String,
    /// Where it started.
    pub start: StartFrom,
    /// The max-z stage from the Coons patch (start Z only, or `--maxz-only`).
    pub max_z: Option<MaxZReport>,
    /// The constrained optimisation (`None` for max-z alone).
    pub optimisation: Option<OptimiseReport>,
    /// Iterations from the start to the result: LP and QP subproblems of the restoration
    /// and the SQP (for max-z alone: its LPs). The max-z stage that makes start Z is not
    /// counted here (it is in `max_z`), as the EGG solve that makes G is not.
    pub iterations: usize,
    /// Whether every stage met its stopping rule.
    pub converged: bool,
    /// Why it stopped (the last stage's reason).
    pub why: String,
    /// The certificate of the result.
    pub certificate: Certificate,
    /// Whether the certificate proves the result bijective.
    pub certified: bool,
    /// Wall-clock seconds of all stages.
    pub seconds: f64,
    /// The result (the best iterate when a stage failed).
    #[serde(skip)]
    pub map: Surface,
    /// The start: the EGG map (G), the max-z point (Z), the Coons patch (max-z alone).
    #[serde(skip)]
    pub start_map: Surface,
}

/// The discretization of `map`'s basis with the sides fixed by `topology` and `p + 2`
/// Gauss points (those of the report's functionals).
pub fn discretization(map: &Surface, topology: &Topology) -> Result<Arc<Discretization>> {
    if map.weights.is_some() {
        return Err(Error::Invalid(
            "constrained optimisation needs a polynomial map (B-spline basis): solve on the fitted basis".into(),
        ));
    }
    let [p, q] = map.degrees();
    let dofs = DofMap::for_basis(&map.knots, topology)?;
    Ok(Arc::new(Discretization::with_dofs(map.knots.clone(), p.max(q) + 2, dofs)))
}

/// The Coons patch of `map`'s boundary on its basis: the common infeasible start.
pub(crate) fn coons_start(map: &Surface) -> Result<Vec<Point>> {
    let sides = Side::ALL.map(|s| map.boundary(s));
    crate::solve::initial::coons(&map.knots, &sides)
}

fn outcome_certificate(map: &Surface, opts: &ConstrainedOptions) -> Result<(Certificate, bool)> {
    let c = certify(map, &opts.certify)?;
    let ok = matches!(c.verdict, Finding::Certified { .. });
    Ok((c, ok))
}

/// Eq. (49) alone on `map`'s basis from the Coons patch of its boundary, stopped at
/// `z > 0`, certified.
pub fn run_max_z(map: &Surface, topology: &Topology, opts: &ConstrainedOptions) -> Result<Outcome> {
    opts.validate()?;
    let t0 = Instant::now();
    let disc = discretization(map, topology)?;
    let coons = coons_start(map)?;
    let z = max_z(&disc, &coons, 0.0, opts)?;
    let result = Surface::new(map.knots.clone(), z.control_points, None)?;
    let start_map = Surface::new(map.knots.clone(), coons, None)?;
    let (certificate, certified) = outcome_certificate(&result, opts)?;
    Ok(Outcome {
        name: "maxz".into(),
        start: StartFrom::MaxZ,
        iterations: z.report.iterations,
        converged: z.report.converged,
        why: z.report.why.clone(),
        max_z: Some(z.report),
        optimisation: None,
        certificate,
        certified,
        seconds: t0.elapsed().as_secs_f64(),
        map: result,
        start_map,
    })
}

/// The constrained optimisation of `functional` on the basis of the EGG map `egg`, from
/// `egg` itself (G) or from the max-z point of the Coons patch (Z), sides fixed by
/// `topology`; the result certified.
pub fn run(
    egg: &Surface,
    from: StartFrom,
    functional: Functional,
    topology: &Topology,
    opts: &ConstrainedOptions,
) -> Result<Outcome> {
    opts.validate()?;
    let t0 = Instant::now();
    let disc = discretization(egg, topology)?;
    let (start, stage) = match from {
        StartFrom::Egg => (egg.control_points.clone(), None),
        StartFrom::MaxZ => {
            let z = max_z(&disc, &coons_start(egg)?, 0.0, opts)?;
            (z.control_points, Some(z.report))
        }
    };
    let name = format!("{}-from-{}", functional.name(), from.name());
    let start_map = Surface::new(egg.knots.clone(), start.clone(), None)?;
    if let Some(z) = stage.as_ref().filter(|z| !z.converged) {
        // no feasible start: the max-z iterate is the best there is
        let result = Surface::new(egg.knots.clone(), start, None)?;
        let (certificate, certified) = outcome_certificate(&result, opts)?;
        return Ok(Outcome {
            name,
            start: from,
            iterations: 0,
            converged: false,
            why: format!("no feasible start: {}", z.why),
            max_z: stage,
            optimisation: None,
            certificate,
            certified,
            seconds: t0.elapsed().as_secs_f64(),
            map: result,
            start_map,
        });
    }
    let o = optimise(&disc, &start, functional, opts)?;
    let result = Surface::new(egg.knots.clone(), o.control_points, None)?;
    let (certificate, certified) = outcome_certificate(&result, opts)?;
    let restoration = o.report.restoration.as_ref().map_or(0, |r| r.iterations);
    Ok(Outcome {
        name,
        start: from,
        max_z: stage,
        iterations: restoration + o.report.iterations,
        converged: o.report.converged,
        why: o.report.why.clone(),
        optimisation: Some(o.report),
        certificate,
        certified,
        seconds: t0.elapsed().as_secs_f64(),
        map: result,
        start_map,
    })
}

#[cfg(test)]
mod tests;
