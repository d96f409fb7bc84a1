//! Free interfaces (paper §11.2, §9): from a conforming layout whose patches are all
//! certified bijective (the fixed-interface solve), the interior control points of the
//! interfaces become unknowns of one problem over all patches ([`MultipatchProblem`]:
//! the Winslow functional eq. 16, or the weak form eq. 14, both defined for `C⁰` joins
//! and both needing `det J > 0`), solved by Newton with the line search that never
//! leaves the bijective maps: the improvement of a certified map on a layout
//! (`improve_layout` of [`crate::solve::improve`]). Every patch is certified again; the
//! result replaces the start only when every patch is at least as well certified as
//! before and, for the Winslow functional, the total value is not larger (for the weak
//! form: the solve converged).

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use super::dofs::GlobalDofs;
use super::layout::Layout;
use super::problem::{Functional, MultipatchProblem};
use crate::error::{Error, Result};
use crate::solve::fixed_basis::{bijective, scaled_options, FixedBasisSolve};
use crate::solve::improve::{improve_layout, winslow_text, Kept, LayoutImprovement};
use crate::solve::newton::{NonlinearMethod, NonlinearOptions};
use crate::spline::surface::Surface;
use crate::verify::certificate::{Certificate, CertifyOptions, Finding};
use crate::verify::quality::quality;

/// What the free-interface stage did.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct FreeReport {
    /// `"winslow"` or `"weak-form"`.
    pub functional: &'static str,
    /// Whether the result replaced the fixed-interface maps.
    pub accepted: bool,
    /// Whether the nonlinear solver met its stopping rule.
    pub converged: bool,
    /// Why it stopped early, if it did.
    pub failure: Option<String>,
    /// Nonlinear iterations.
    pub iterations: usize,
    /// Unknowns (`2 m`, interface points included).
    pub unknowns: usize,
    /// Free control points on interfaces (counted once).
    pub interface_unknowns: usize,
    /// Corners where three or more patches meet (kept fixed).
    pub fixed_vertices: usize,
    /// `|F|` per iterate, start first.
    pub residuals: Vec<f64>,
    /// Total Winslow value per iterate (the Winslow functional only).
    pub objective: Vec<f64>,
    /// Total Winslow value of the start (`(p + 2)` Gauss points per element).
    pub winslow_before: Option<f64>,
    /// Total Winslow value of the result.
    pub winslow_after: Option<f64>,
    /// Largest displacement of an interface control point, relative to the diameter.
    pub max_interface_displacement: f64,
    /// Certificate of each patch of the result.
    pub certificates: Vec<String>,
    /// Seconds for the stage.
    pub seconds: f64,
    /// Plain-language summary.
    pub message: String,
}

/// The outcome of [`free_interfaces`]: the maps to use (the result or the start), their
/// certificates, and the report.
#[derive(Debug, Clone)]
pub(crate) struct Freed {
    /// One map per patch.
    pub maps: Vec<Surface>,
    /// Their certificates.
    pub certificates: Vec<Certificate>,
    /// The stage report.
    pub report: FreeReport,
}

/// Total Winslow value of `maps` (`None` when one folds at a quadrature point).
pub(crate) fn total_winslow(maps: &[Surface]) -> Option<f64> {
    let w: f64 = maps.iter().map(|m| quality(m).functionals.winslow).sum();
    w.is_finite().then_some(w)
}

/// Run the free-interface stage (see the module documentation) on the conforming
/// `maps` of `layout` (one per patch, interface control points identical), certified by
/// `certificates`. `diameter` scales the stopping rule.
///
/// Errors: [`Error::InfeasibleStart`] when a patch is not certified bijective; an
/// [`Error::Layout`] when the maps are not conforming.
pub(crate) fn free_interfaces(
    layout: &Layout,
    maps: &[Surface],
    certificates: &[Certificate],
    functional: Functional,
    nonlinear: NonlinearOptions,
    certify_opts: &CertifyOptions,
    diameter: f64,
) -> Result<Freed> {
    let t0 = Instant::now();
    if let Some((p, c)) = certificates.iter().enumerate().find(|(_, c)| !bijective(c)) {
        return Err(Error::InfeasibleStart {
            method: functional.name().into(),
            reason: format!("patch {} is not certified ({})", layout.label(p), c.message()),
        });
    }
    let shapes: Vec<[usize; 2]> = maps.iter().map(Surface::shape).collect();
    let dofs = Arc::new(GlobalDofs::new(layout, &shapes, &layout.topologies())?);
    let interface_unknowns = dofs.copies.iter().filter(|c| c.len() > 1).count();
    let problem = MultipatchProblem::new(functional, maps, dofs.clone())?;
    let c0 = problem.unknowns();
    let m = dofs.num_free();
    let mut nl = nonlinear;
    nl.method = NonlinearMethod::Newton;
    nl.fallback = false;
    let nl = scaled_options(nl, &*functional.method(), diameter, m);
    let solve = FixedBasisSolve::with_problem(problem, c0, nl);
    let out = improve_layout(maps, certificates, solve, total_winslow, |w| *w, certify_opts)?;
    let LayoutImprovement { candidate, certificates: certs, solved, before, after, outcome } = out;
    let mut max_disp = 0.0f64;
    for copies in dofs.copies.iter().filter(|c| c.len() > 1) {
        let (p, k) = copies[0];
        let (a, b) = (maps[p].control_points[k], candidate[p].control_points[k]);
        max_disp = max_disp.max((a[0] - b[0]).hypot(a[1] - b[1]) / diameter);
    }
    let converged = solved.converged();
    let accepted = outcome == Kept::Accepted;
    let iterations = solved.history.iterations;
    let message = match outcome {
        Kept::Accepted => format!(
            "free interfaces ({}): total Winslow value {} -> {} in {iterations} iterations, {m} free control points ({interface_unknowns} on interfaces), interface points moved by up to {max_disp:.3e} of the diameter; every patch certified again",
            functional.name(),
            winslow_text(before),
            winslow_text(after)
        ),
        Kept::NotCertified => {
            let bad: Vec<String> = certs
                .iter()
                .enumerate()
                .filter(|(_, c)| !matches!(c.verdict, Finding::Certified { .. }))
                .map(|(p, c)| format!("patch {}: {}", layout.label(p), c.message()))
                .collect();
            format!(
                "free interfaces ({}): the result is not certified ({}); the fixed-interface maps are kept",
                functional.name(),
                bad.join("; ")
            )
        }
        Kept::NotLower => format!(
            "free interfaces (winslow): the result's total Winslow value {} is not below the start's {}; the fixed-interface maps are kept",
            winslow_text(after),
            winslow_text(before)
        ),
        Kept::NotConverged => format!(
            "free interfaces (weak-form): the solver did not converge ({:?}); the fixed-interface maps are kept",
            solved.status
        ),
    };
    let report = FreeReport {
        functional: functional.name(),
        accepted,
        converged,
        failure: solved.failure().map(str::to_string),
        iterations,
        unknowns: 2 * m,
        interface_unknowns,
        fixed_vertices: dofs.fixed_vertices,
        residuals: solved.history.residuals,
        objective: solved.history.objectives,
        winslow_before: before,
        winslow_after: after,
        max_interface_displacement: max_disp,
        certificates: certs.iter().map(Certificate::message).collect(),
        seconds: t0.elapsed().as_secs_f64(),
        message,
    };
    let (maps, certificates) = if accepted { (candidate, certs) } else { (maps.to_vec(), certificates.to_vec()) };
    Ok(Freed { maps, certificates, report })
}
