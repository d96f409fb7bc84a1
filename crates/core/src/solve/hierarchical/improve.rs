//! Improvement of a certified THB map on its own basis (paper §4.1 on a truncated
//! hierarchical basis, §4; issue 35): the Winslow functional (eq. 16),
//! `J(x) = ∫ (|x_ξ|² + |x_η|²) / det J`, minimized over the free THB functions (those
//! whose trace on the boundary is zero) from the certified map, the fixed ones kept, on
//! the THB discretization with the tensor path's kernels
//! (`methods::hierarchical::HierarchicalWinslowProblem`). The minimizer is certified
//! again and replaces the start only when it is at least as well certified (a certified
//! start needs a certified result) and its Winslow value is not larger, as on a tensor
//! basis ([`crate::solve::improve`]).

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use super::accepted;
use crate::discrete::hierarchical::HierarchicalDiscretization;
use crate::error::{Error, Result};
use crate::methods::hierarchical::{hierarchical_winslow_objective, HierarchicalWinslowProblem};
use crate::methods::winslow::WinslowMethod;
use crate::methods::DiscreteProblem;
use crate::solve::improve::{from_bijective_start, kept, winslow_text, Kept};
use crate::solve::newton::{NonlinearOptions, NonlinearSolver, Status};
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::verify::certificate::hierarchical::{certify_hierarchical, HierarchicalCertificate};
use crate::verify::certificate::{CertifyOptions, Finding};

/// What the improvement of a THB map did (the `improvement` of a THB report).
#[derive(Debug, Clone, Serialize)]
pub struct ThbImprovement {
    /// Method name (`"winslow"`).
    pub method: &'static str,
    /// Whether the minimized map replaced the start (certified as well, value not larger).
    pub accepted: bool,
    /// Whether the nonlinear solver met its stopping rule.
    pub converged: bool,
    /// Why the solver stopped early, if it did.
    pub failure: Option<String>,
    /// Newton iterations.
    pub iterations: usize,
    /// Free unknowns `2 m`.
    pub unknowns: usize,
    /// `J` of the start on the THB discretization's quadrature (`None` where `det J <= 0`
    /// at a quadrature point).
    pub winslow_before: Option<f64>,
    /// `J` of the minimized map.
    pub winslow_after: Option<f64>,
    /// Largest control-point displacement from the start, relative to the diameter of the
    /// control net.
    pub max_displacement: f64,
    /// Verdict of the certificate of the minimized map.
    pub certificate: &'static str,
    /// Seconds of the stage (set-up, iterations, certificate).
    pub seconds: f64,
    /// Plain-language summary.
    pub message: String,
}

/// The outcome of [`improve_thb`]: the map to use (the minimizer or the start), its
/// certificate and the stage's record.
#[derive(Debug, Clone)]
pub(crate) struct ThbImproved {
    pub map: HierarchicalMap,
    pub certificate: HierarchicalCertificate,
    pub report: ThbImprovement,
}

/// The diagonal of the bounding box of the control points.
fn diameter(map: &HierarchicalMap) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &map.control_points {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1]).max(f64::MIN_POSITIVE)
}

/// Minimize the Winslow functional from the certified THB map `map` (certificate
/// `certificate`) on its own basis, Newton from a bijective start
/// ([`from_bijective_start`]), and certify the result (see the module documentation).
///
/// Errors: [`Error::InfeasibleStart`] when the certificate does not accept the start.
pub(crate) fn improve_thb(
    map: &HierarchicalMap,
    certificate: &HierarchicalCertificate,
    nonlinear: NonlinearOptions,
    certify: &CertifyOptions,
) -> Result<ThbImproved> {
    let t0 = Instant::now();
    if !accepted(certificate) {
        return Err(Error::InfeasibleStart { method: "winslow".into(), reason: certificate.message() });
    }
    let disc = Arc::new(HierarchicalDiscretization::new(map.basis.clone()));
    let m = disc.num_free();
    let before = finite(hierarchical_winslow_objective(&disc, &map.control_points));
    let diam = diameter(map);
    let mut solver = NonlinearSolver::new(
        HierarchicalWinslowProblem::new(disc.clone(), map.control_points.clone()),
        disc.gather(&map.control_points),
        from_bijective_start(nonlinear, &WinslowMethod, diam, m),
    );
    let (mut iterations, mut failure) = (0, None);
    if m > 0 {
        for it in solver.by_ref() {
            match it {
                Ok(s) => iterations = s.iteration,
                Err(e) => {
                    failure = Some(e.to_string());
                    break;
                }
            }
        }
    }
    let converged = m == 0 || solver.status() == &Status::Converged;
    if let (None, Status::Failed(why)) = (&failure, solver.status()) {
        failure = Some(why.clone());
    }
    let (prob, c) = solver.into_parts();
    let cps = prob.control_points(&c);
    let candidate = HierarchicalMap::new(map.basis.clone(), cps)?;
    let after = finite(hierarchical_winslow_objective(&disc, &candidate.control_points));
    let cert = certify_hierarchical(&candidate, certify)?;
    let as_good = match certificate.verdict {
        Finding::Certified { .. } => matches!(cert.verdict, Finding::Certified { .. }),
        _ => accepted(&cert),
    };
    let outcome = kept(as_good, true, converged, before, after);
    let max_displacement = candidate
        .control_points
        .iter()
        .zip(&map.control_points)
        .fold(0.0f64, |d, (a, b)| d.max((a[0] - b[0]).hypot(a[1] - b[1])))
        / diam;
    let verdict = cert.verdict.name();
    let message = match outcome {
        Kept::Accepted => format!(
            "winslow on the THB basis: J {} -> {}, {iterations} iterations, {verdict}",
            winslow_text(before),
            winslow_text(after)
        ),
        Kept::NotCertified => format!("winslow on the THB basis: the minimizer is {verdict}; the map is the repair's"),
        Kept::NotLower | Kept::NotConverged => format!(
            "winslow on the THB basis: J {} -> {} not lower; the map is the repair's",
            winslow_text(before),
            winslow_text(after)
        ),
    };
    let accepted = outcome == Kept::Accepted;
    let report = ThbImprovement {
        method: "winslow",
        accepted,
        converged,
        failure,
        iterations,
        unknowns: 2 * m,
        winslow_before: before,
        winslow_after: after,
        max_displacement,
        certificate: verdict,
        seconds: t0.elapsed().as_secs_f64(),
        message,
    };
    Ok(if accepted {
        ThbImproved { map: candidate, certificate: cert, report }
    } else {
        ThbImproved { map: map.clone(), certificate: certificate.clone(), report }
    })
}

/// `Some(v)` for a finite `v`.
fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}
