//! Improvement of a certified map on its own basis (paper §4.1, §9): a method that needs
//! a bijective start (the Winslow functional, eq. 16) is run from the map, with the
//! boundary control points fixed, and the result is certified again. The improved map is
//! returned only when the certificate proves it bijective (as the start was) and its
//! Winslow value is not larger; otherwise the start is kept and the report says why.
//!
//! The minimizer of eq. (16) over the spline space tends to the EGG solution under
//! refinement (both discretize the same harmonic inverse map, §4.1): on a fine basis the
//! improvement is small and [`Improvement::max_displacement`] measures how far the two
//! discrete maps are.

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use super::fixed_basis::{as_well_certified, bijective, scaled_options, FixedBasisSolve, Solved};
use super::newton::{NonlinearMethod, NonlinearOptions};
use crate::discrete::assembly::Discretization;
use crate::discrete::dofs::DofMap;
use crate::discrete::topology::Topology;
use crate::error::{Error, Result};
use crate::methods::weak_form::WeakFormMethod;
use crate::methods::winslow::WinslowMethod;
use crate::methods::{DiscreteProblem, Method};
use crate::spline::surface::Surface;
use crate::verify::certificate::{certify, Certificate, CertifyOptions};
use crate::verify::quality::quality;

/// Which improvement runs after the solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Improve {
    /// Minimize the Winslow functional (eq. 16): [`WinslowMethod`].
    #[default]
    #[cfg_attr(feature = "clap", value(help = "Minimize the Winslow functional (eq. 16)"))]
    Winslow,
    /// Solve the weak form (eq. 14) from the map: `WeakFormMethod`.
    #[cfg_attr(feature = "clap", value(name = "weak", help = "Solve the weak form (eq. 14) from the certified map"))]
    WeakForm,
}

impl Improve {
    /// The method that improves.
    pub fn method(self) -> Arc<dyn Method> {
        match self {
            Improve::Winslow => Arc::new(WinslowMethod),
            Improve::WeakForm => Arc::new(WeakFormMethod),
        }
    }

    /// The method's name: `"winslow"` or `"weak-form"`.
    pub fn name(self) -> &'static str {
        self.method().name()
    }
}

/// The quality figures compared before and after an improvement.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MapQuality {
    /// Winslow functional (eq. 16) at `(p + 2)^2` Gauss points per element; `None` when
    /// `det J <= 0` at one.
    pub winslow: Option<f64>,
    /// Smallest per-element minimum of the scaled Jacobian `det J / (|x_ξ| |x_η|)`.
    pub scaled_jacobian_min: f64,
    /// Mean scaled Jacobian.
    pub scaled_jacobian_mean: f64,
    /// Largest deviation of the angle between `x_ξ` and `x_η` from 90 degrees.
    pub orthogonality_max_degrees: f64,
    /// Mean over the elements of the per-element largest deviation from 90 degrees.
    pub orthogonality_mean_degrees: f64,
}

impl MapQuality {
    /// The figures of `map` ([`crate::verify::quality::quality`]).
    pub fn of(map: &Surface) -> Self {
        let q = quality(map);
        let w = q.functionals.winslow;
        Self {
            winslow: w.is_finite().then_some(w),
            scaled_jacobian_min: q.scaled_jacobian.min,
            scaled_jacobian_mean: q.scaled_jacobian_mean,
            orthogonality_max_degrees: q.orthogonality_degrees.max,
            orthogonality_mean_degrees: q.orthogonality_degrees.mean,
        }
    }
}

/// What an improvement stage did (stored in the report).
#[derive(Debug, Clone, Serialize)]
pub struct Improvement {
    /// Method name ("winslow").
    pub method: &'static str,
    /// The start.
    pub before: MapQuality,
    /// The minimized map (also when it was not accepted).
    pub after: MapQuality,
    /// Whether the minimized map replaced the start (certified, value not larger).
    pub accepted: bool,
    /// Whether the nonlinear solver met its stopping rule (gradient norm).
    pub converged: bool,
    /// Why the solver stopped early, if it did.
    pub failure: Option<String>,
    /// Nonlinear iterations (Newton steps: one Jacobian or Hessian each).
    pub iterations: usize,
    /// Chord steps taken after Newton steps ([`NonlinearOptions::chord`]): one residual
    /// and one solve with the step's factorization each.
    pub chord_steps: usize,
    /// Unknowns (`2 m`).
    pub unknowns: usize,
    /// `|∇J|` per iterate, start first.
    pub residuals: Vec<f64>,
    /// `J` per iterate, start first.
    pub objective: Vec<f64>,
    /// Largest control-point displacement from the start, relative to the diameter.
    pub max_displacement: f64,
    /// Verdict of the certificate of the minimized map.
    pub certificate: String,
    /// Seconds for the stage (set-up, iterations, certificate, quality).
    pub seconds: f64,
    /// Seconds of it spent assembling gradients, Hessians and objectives.
    pub assembly_seconds: f64,
    /// Seconds of it spent in factorizations and solves.
    pub linear_seconds: f64,
    /// Plain-language summary.
    pub message: String,
}

impl Improvement {
    /// The record of a stage that did not run (start not certified, solve not
    /// converged): `after` equals `before`, nothing accepted.
    pub fn skipped(method: &dyn Method, map: &Surface, why: String) -> Self {
        let q = MapQuality::of(map);
        Self {
            method: method.name(),
            before: q,
            after: q,
            accepted: false,
            converged: false,
            failure: Some(why.clone()),
            iterations: 0,
            chord_steps: 0,
            unknowns: 0,
            residuals: Vec::new(),
            objective: Vec::new(),
            max_displacement: 0.0,
            certificate: String::new(),
            seconds: 0.0,
            assembly_seconds: 0.0,
            linear_seconds: 0.0,
            message: format!("{}: not run: {why}; the map is the solve's", method.name()),
        }
    }
}

/// The outcome of [`improve`]: the map to use (improved or the start) and its
/// certificate.
#[derive(Debug, Clone)]
pub struct Improved {
    /// The map.
    pub map: Surface,
    /// Its certificate.
    pub certificate: Certificate,
    /// The stage report.
    pub report: Improvement,
}

/// The nonlinear options of `method` run from a bijective start on `m` free functions:
/// Newton with its line search only (pseudo time-stepping is for starts far from a
/// solution, and 400 of its steps cost minutes on a fine basis), the residual scaled by
/// [`Method::residual_scale`], the step tolerance in length units, a failed line search
/// on a GMRES direction retried with LU ([`NonlinearOptions::direct_retry`]), a
/// Newton step followed by chord steps ([`NonlinearOptions::chord`]), a
/// minimisation's full step by a longer one where `J` falls further
/// ([`NonlinearOptions::extrapolate`]); a minimisation stops
/// when its decrement is negligible ([`crate::solve::newton::DECREMENT_TOL`]) or after
/// [`MAX_MODIFIED_STEPS`] steps with a modified Hessian.
pub(crate) fn from_bijective_start(
    nonlinear: NonlinearOptions,
    method: &dyn Method,
    diameter: f64,
    m: usize,
) -> NonlinearOptions {
    let mut nl = nonlinear;
    nl.method = NonlinearMethod::Newton;
    nl.direct_retry = true;
    nl.chord = true;
    nl.extrapolate = true;
    nl.fallback = false;
    let mut nl = scaled_options(nl, method, diameter, m);
    nl.max_modified = nl.max_modified.or(Some(MAX_MODIFIED_STEPS));
    if nl.decrement_tol == 0.0 {
        nl.decrement_tol = crate::solve::newton::DECREMENT_TOL;
    }
    nl
}

/// Consecutive Newton steps with a modified (not positive definite) Hessian after which a
/// minimisation from a bijective start stops ([`NonlinearOptions::max_modified`]): on the
/// shared geometries the Winslow Hessian at the EGG map is positive definite or becomes so
/// within a step or two, except on male_casing_ring, where the functional keeps falling
/// slowly along a long valley while its smallest scaled Jacobian falls (30 modified steps:
/// Winslow value -1.2 %, smallest scaled Jacobian 0.12 -> 0.014): BENCHMARKS.md,
/// "Improving the EGG map".
pub(crate) const MAX_MODIFIED_STEPS: usize = 4;

/// Whether an improvement is kept: its certificate is at least as good as the start's
/// ([`as_well_certified`], `as_good`) and, for a minimisation, its Winslow value `after`
/// is not larger than `before` (a minimisation only lowers its objective, the line search
/// sees to it), for a root-finding method, the solver converged.
pub(crate) fn kept(as_good: bool, minimizes: bool, converged: bool, before: Option<f64>, after: Option<f64>) -> Kept {
    let lower = match (after, before) {
        (Some(a), Some(b)) => a <= b,
        (Some(_), None) => true,
        (None, _) => false,
    };
    match (as_good, minimizes) {
        (false, _) => Kept::NotCertified,
        (true, true) if !lower => Kept::NotLower,
        (true, false) if !converged => Kept::NotConverged,
        _ => Kept::Accepted,
    }
}

/// The outcome of [`kept`]: the result replaces the start, or is not as well certified,
/// or (a minimisation) has a larger Winslow value, or (root finding) did not converge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kept {
    Accepted,
    NotCertified,
    NotLower,
    NotConverged,
}

/// A Winslow value for a message (`undefined` when the map folds at a quadrature point).
pub(crate) fn winslow_text(w: Option<f64>) -> String {
    w.map_or("undefined".to_string(), |w| format!("{w:.6}"))
}

/// What [`improve_layout`] gives: the candidate maps (one per patch), their certificates,
/// the solve, the `quality` figures of the start and of the candidate, and the verdict of
/// [`kept`].
pub(crate) struct LayoutImprovement<Q> {
    pub(crate) candidate: Vec<Surface>,
    pub(crate) certificates: Vec<Certificate>,
    pub(crate) solved: Solved,
    pub(crate) before: Q,
    pub(crate) after: Q,
    pub(crate) outcome: Kept,
}

/// Improvement on a layout (one patch: a one-patch layout, §4.1; several: the free
/// interfaces of §11.2): run `solve` (a method that needs a bijective start, from the
/// patch maps `maps` certified by `certificates`) while `quality` measures the start, cut
/// its control points into the patches' maps, certify each while `quality` measures them,
/// and judge the candidate by [`kept`] (every patch [`as_well_certified`] as before, the
/// Winslow value `winslow` of the figures not larger, or the solve converged).
pub(crate) fn improve_layout<P: DiscreteProblem + Send, Q: Send>(
    maps: &[Surface],
    certificates: &[Certificate],
    mut solve: FixedBasisSolve<P>,
    quality: impl Fn(&[Surface]) -> Q + Sync,
    winslow: impl Fn(&Q) -> Option<f64>,
    certify_opts: &CertifyOptions,
) -> Result<LayoutImprovement<Q>> {
    let minimizes = solve.start_objective().is_some();
    // the start's figures on the other core meanwhile (a small basis assembles on one)
    let (before, run) = rayon::join(|| quality(maps), || solve.drain());
    run?;
    let solved = solve.finish()?;
    let mut rest = solved.control_points.as_slice();
    let candidate: Vec<Surface> = maps
        .iter()
        .map(|m| {
            let (cp, tail) = rest.split_at(m.control_points.len());
            rest = tail;
            Surface { control_points: cp.to_vec(), ..m.clone() }
        })
        .collect();
    let certify_all = || candidate.iter().map(|m| certify(m, certify_opts)).collect::<Result<Vec<_>>>();
    let (after, certs) = rayon::join(|| quality(&candidate), certify_all);
    let certs = certs?;
    let as_good = certificates.iter().zip(&certs).all(|(before, after)| as_well_certified(before, after));
    let outcome = kept(as_good, minimizes, solved.converged(), winslow(&before), winslow(&after));
    Ok(LayoutImprovement { candidate, certificates: certs, solved, before, after, outcome })
}

/// Run `method` from the certified map `map` (certificate `certificate`) on the same
/// basis, the control points on the sides fixed by `topology` kept; certify the result
/// and return it when it is at least as well certified as the start (a certified start
/// needs a certified result) and, for a minimization, its Winslow value is not larger,
/// for a root-finding method, the solver converged; the start otherwise.
///
/// Errors: [`Error::InfeasibleStart`] when the certificate does not prove the start
/// bijective, [`Error::Invalid`] for a rational map (the kernels are polynomial).
pub fn improve(
    map: &Surface,
    certificate: &Certificate,
    method: &dyn Method,
    topology: &Topology,
    nonlinear: NonlinearOptions,
    certify_opts: &CertifyOptions,
    diameter: f64,
) -> Result<Improved> {
    let t0 = Instant::now();
    if !bijective(certificate) {
        return Err(Error::InfeasibleStart { method: method.name().into(), reason: certificate.message() });
    }
    let [p, q] = map.degrees();
    let dofs = DofMap::for_basis(&map.knots, topology)?;
    // the quadrature of the report's Winslow value, (p + 2) points
    // a rational map keeps its weights: the method moves its control points only
    let disc =
        Arc::new(Discretization::with_dofs(map.knots.clone(), p.max(q) + 2, dofs).with_weights(map.weights.clone())?);
    let m = disc.dofs.num_free();
    let nl = from_bijective_start(nonlinear, method, diameter, m);
    let solve = FixedBasisSolve::new(method, disc, map.control_points.clone(), nl);
    let (maps, certificates) = (std::slice::from_ref(map), std::slice::from_ref(certificate));
    let out = improve_layout(maps, certificates, solve, |m| MapQuality::of(&m[0]), |q| q.winslow, certify_opts)?;
    let LayoutImprovement { mut candidate, certificates: mut certs, solved, before, after, outcome } = out;
    let (candidate, cert) = (candidate.swap_remove(0), certs.swap_remove(0));
    let max_displacement = candidate
        .control_points
        .iter()
        .zip(&map.control_points)
        .fold(0.0f64, |d, (a, b)| d.max((a[0] - b[0]).hypot(a[1] - b[1])))
        / diameter;
    let converged = solved.converged();
    let accepted = outcome == Kept::Accepted;
    let (iterations, chord_steps) = (solved.history.iterations, solved.chord_steps);
    let message = match outcome {
        Kept::Accepted => format!(
            "{}: Winslow value {} -> {}, min scaled Jacobian {:.4} -> {:.4} in {iterations} iterations{}; {}",
            method.name(),
            winslow_text(before.winslow),
            winslow_text(after.winslow),
            before.scaled_jacobian_min,
            after.scaled_jacobian_min,
            match chord_steps {
                0 => String::new(),
                k => format!(" and {k} chord step(s)"),
            },
            cert.message()
        ),
        Kept::NotCertified => {
            format!("{}: the minimized map is not certified ({}); the start is kept", method.name(), cert.message())
        }
        Kept::NotConverged => format!(
            "{}: the solver did not converge ({}); the start is kept",
            method.name(),
            solved.failure().unwrap_or("stopped")
        ),
        Kept::NotLower => format!(
            "{}: the minimized map's Winslow value {} is not below the start's {}; the start is kept",
            method.name(),
            winslow_text(after.winslow),
            winslow_text(before.winslow)
        ),
    };
    let report = Improvement {
        method: method.name(),
        before,
        after,
        accepted,
        converged,
        failure: solved.failure().map(str::to_string),
        iterations,
        chord_steps,
        unknowns: 2 * m,
        residuals: solved.history.residuals,
        objective: solved.history.objectives,
        max_displacement,
        certificate: cert.message(),
        seconds: 0.0,
        assembly_seconds: solved.timings.assembly.as_secs_f64(),
        linear_seconds: solved.timings.linear.as_secs_f64(),
        message,
    };
    let (map, certificate) = if accepted { (candidate, cert) } else { (map.clone(), certificate.clone()) };
    let mut out = Improved { map, certificate, report };
    out.report.seconds = t0.elapsed().as_secs_f64();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;
    use crate::verify::certificate::Finding;

    /// A quarter annulus interpolated at the Greville points with a sheared interior:
    /// bijective, not the Winslow minimizer.
    fn sheared_annulus(shear: f64) -> Surface {
        let k = KnotVector::open_uniform(3, 6);
        let g = k.greville();
        let n = g.len();
        let mut cps = Vec::new();
        for (j, &v) in g.iter().enumerate() {
            for (i, &u) in g.iter().enumerate() {
                let interior = i > 0 && j > 0 && i + 1 < n && j + 1 < n;
                let t = std::f64::consts::FRAC_PI_2
                    * (v + if interior { shear * u * (1.0 - u) * v * (1.0 - v) } else { 0.0 });
                let r = 1.0 + u;
                cps.push([r * t.cos(), r * t.sin()]);
            }
        }
        Surface::new([k.clone(), k], cps, None).unwrap()
    }

    #[test]
    fn winslow_improvement_lowers_the_value_and_stays_certified() {
        let map = sheared_annulus(2.0);
        let opts = CertifyOptions::default();
        let cert = certify(&map, &opts).unwrap();
        assert!(bijective(&cert), "{}", cert.message());
        let out = improve(&map, &cert, &WinslowMethod, &Topology::dirichlet(), NonlinearOptions::default(), &opts, 3.0)
            .unwrap();
        let r = &out.report;
        assert!(r.accepted && r.converged, "{}", r.message);
        assert!(r.after.winslow.unwrap() < 0.99 * r.before.winslow.unwrap(), "{}", r.message);
        assert!(r.after.scaled_jacobian_min > r.before.scaled_jacobian_min, "{}", r.message);
        assert!(matches!(out.certificate.verdict, Finding::Certified { .. }));
        // the boundary is kept exactly
        for s in crate::spline::surface::Side::ALL {
            let (a, b) = (map.boundary(s), out.map.boundary(s));
            assert_eq!(a.control_points, b.control_points);
        }
        // a minimizer: improving again does (almost) nothing
        let again = improve(
            &out.map,
            &out.certificate,
            &WinslowMethod,
            &Topology::dirichlet(),
            NonlinearOptions::default(),
            &opts,
            3.0,
        )
        .unwrap();
        // (the stopping rule leaves J within 1e-6 relative of its model's minimum: control
        // points within about 1e-6 of the diameter)
        assert!(again.report.iterations <= 3 && again.report.max_displacement < 1e-6, "{:?}", again.report);
    }

    /// A start the certificate does not prove bijective is refused.
    #[test]
    fn a_folded_start_is_refused() {
        let map = sheared_annulus(-30.0);
        let opts = CertifyOptions::default();
        let cert = certify(&map, &opts).unwrap();
        assert!(!bijective(&cert), "the start must fold: {}", cert.message());
        let r = improve(&map, &cert, &WinslowMethod, &Topology::dirichlet(), NonlinearOptions::default(), &opts, 3.0);
        assert!(matches!(r, Err(Error::InfeasibleStart { .. })), "{r:?}");
    }
}
