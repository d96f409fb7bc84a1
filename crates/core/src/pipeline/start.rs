//! The pipeline's last stage on its own: a certified map given as the input
//! ([`Input::Map`](super::Input::Map)), improved on its own basis by the pipeline's
//! method (the Winslow functional, eq. 16; the weak form, eq. 14; or EGG, eq. 8) with its
//! boundary fixed, certified again (§8.1), and kept only when certified
//! ([`crate::solve::improve::improve`]). `winslow solve --start MAP` runs it.

use serde::Serialize;

use crate::boundary::Boundary;
use crate::error::Result;
use crate::methods::Method;
use crate::solve::improve::{improve, Improvement};
use crate::solve::options::SolveOptions;
use crate::solve::report::Verdict;
use crate::spline::surface::Surface;
use crate::verify::certificate::{certify, Certificate};
use crate::verify::quality::{boundary_deviation, quality, Quality};

/// A map improved from a start: the map written, and its report.
#[derive(Debug, Clone)]
pub struct Improved {
    /// Name of the geometry.
    pub name: String,
    /// The improved map (the start when the improvement was not accepted).
    pub map: Surface,
    /// The report.
    pub report: ImprovedReport,
}

/// The report of [`Improved`] (the `report` of the map document written).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ImprovedReport {
    /// The crate's version.
    pub version: &'static str,
    /// The method that improved.
    pub method: &'static str,
    /// The verdict of the certificate of the map written.
    pub verdict: Verdict,
    /// The certificate's message and the improvement's.
    pub message: String,
    /// The certificate of the map written.
    pub certificate: Certificate,
    /// Its quality figures.
    pub quality: Quality,
    /// Its Winslow value (eq. 16); `None` where it is not finite.
    pub winslow: Option<f64>,
    /// The distance of the map's sides (south, east, north, west) from the boundary
    /// given with the start ([`boundary_deviation`]), when one was.
    pub boundary_deviation: Option<[f64; 4]>,
    /// The improvement stage.
    pub improvement: Improvement,
    /// Seconds for the certificate of the start, the improvement and its certificate.
    pub seconds: f64,
}

/// Certify `map`, improve it with `method` on its own basis with `opts`' topology,
/// nonlinear and certificate options, and measure the result (against `boundary` when
/// given). [`crate::Error::InfeasibleStart`] when the start is not certified.
pub(crate) fn improve_start(
    name: &str,
    map: &Surface,
    boundary: Option<&Boundary>,
    method: &dyn Method,
    opts: &SolveOptions,
) -> Result<Improved> {
    let t0 = std::time::Instant::now();
    let cert = certify(map, &opts.certify)?;
    let diameter = map.control_diameter();
    let out = improve(map, &cert, method, &opts.topology, opts.nonlinear, &opts.certify, diameter)?;
    let q = quality(&out.map);
    let w = q.functionals.winslow;
    let report = ImprovedReport {
        version: env!("CARGO_PKG_VERSION"),
        method: method.name(),
        verdict: Verdict::of_certificate(&out.certificate),
        message: format!("{}; {}", out.certificate.message(), out.report.message),
        boundary_deviation: boundary.map(|b| boundary_deviation(&out.map, b, 400)),
        certificate: out.certificate,
        quality: q,
        winslow: w.is_finite().then_some(w),
        improvement: out.report,
        seconds: t0.elapsed().as_secs_f64(),
    };
    Ok(Improved { name: name.to_string(), map: out.map, report })
}
