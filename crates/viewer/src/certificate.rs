//! What the viewer says about a map's bijectivity, in one place: the verdict of the
//! solver's [`Report`] (this session's solve, or the `"report"` stored in a map file)
//! and the core's exact certificate of the loaded map ([`winslow::verify::certificate::certify`]:
//! Bernstein bounds of det J with adaptive subdivision); the sample rules only when the
//! certificate cannot be computed.

use winslow::boundary::corners::{corner_report, CornerReport};
use winslow::solve::report::{min_away_from_corners, Report, Verdict};
use winslow::verify::quality::{DetJSample, Functionals};
use winslow::{Side, Surface};

/// Quality numbers of a map, all computed by the core.
#[derive(Debug, Clone)]
pub struct Quality {
    /// Sample grid size (`(n+1)^2` points).
    pub sample_n: usize,
    /// Smallest sampled `det J`.
    pub det_j_min: f64,
    /// Largest sampled `det J`.
    pub det_j_max: f64,
    /// Parameter point of the smallest sample.
    pub det_j_argmin: [f64; 2],
    /// Smallest sample away from the four corners.
    pub det_j_min_interior: f64,
    /// Smallest sample away from the corners the boundary forces
    /// ([`min_away_from_corners`]).
    pub det_j_min_away_from_forced_corners: f64,
    /// Area, Winslow functional, harmonic energy, smallest `det J` at the quadrature points.
    pub functionals: Functionals,
    /// Corner angles of the map's boundary and whether they force `det J <= 0`.
    pub corners: Vec<CornerReport>,
}

impl Quality {
    /// The numbers of `map` from its `det J` sample.
    pub fn of(map: &Surface, sample: &DetJSample) -> Self {
        let sides = Side::ALL.map(|s| map.boundary(s));
        let corners = corner_report(&sides);
        Self {
            sample_n: sample.n,
            det_j_min: sample.min,
            det_j_max: sample.max,
            det_j_argmin: sample.argmin,
            det_j_min_interior: sample.min_interior,
            det_j_min_away_from_forced_corners: min_away_from_corners(map, sample, &corners),
            functionals: winslow::verify::quality::functionals(map),
            corners,
        }
    }

    /// Which corners (south-west, south-east, north-east, north-west) force `det J <= 0`.
    pub fn forced_corners(&self) -> [bool; 4] {
        let mut f = [false; 4];
        for (k, c) in self.corners.iter().take(4).enumerate() {
            f[k] = c.forces_nonpositive_det_j;
        }
        f
    }
}

/// Where a verdict comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CertificateSource {
    /// The report of a solve run in the viewer.
    Solver,
    /// The `"report"` stored in the map file.
    File,
    /// The core's exact certificate of the loaded map.
    Exact,
    /// The viewer's `det J` sample, read with the solver's rules.
    Sample,
}

impl CertificateSource {
    /// Label shown in the viewer.
    pub fn label(self) -> &'static str {
        match self {
            CertificateSource::Solver => "solver report",
            CertificateSource::File => "report stored in the file",
            CertificateSource::Exact => "exact certificate (Bernstein bounds of det J)",
            CertificateSource::Sample => "viewer's det J sample",
        }
    }
}

/// A verdict with its explanation.
#[derive(Debug, Clone)]
pub struct Certificate {
    /// The verdict.
    pub verdict: Verdict,
    /// Plain-language explanation.
    pub message: String,
    /// Where it comes from.
    pub source: CertificateSource,
    /// Further facts as (label, value) lines.
    pub details: Vec<(String, String)>,
}

/// Whether the verdict means the map can be used (proven bijective, or the best map the
/// boundary admits).
pub fn verdict_is_good(v: Verdict) -> bool {
    matches!(v, Verdict::Certified | Verdict::DegenerateCorner)
}

fn verdict_from_name(s: &str) -> Option<Verdict> {
    [Verdict::Certified, Verdict::DegenerateCorner, Verdict::Folded, Verdict::Undecided, Verdict::NotConverged]
        .into_iter()
        .find(|&v| v.name() == s)
}

/// The det J lines of an exact certificate's details (tensor or THB): the proven lower
/// bound where the `verdict` is good, the smallest value found otherwise, then the mean.
pub(crate) fn det_j_details(verdict: Verdict, lower_bound: f64, min_found: f64, mean: f64) -> Vec<(String, String)> {
    let first = if verdict_is_good(verdict) {
        ("proven det J lower bound".to_string(), format!("{lower_bound:.4e}"))
    } else {
        ("smallest det J found".to_string(), format!("{min_found:.4e}"))
    };
    vec![first, ("mean det J".to_string(), format!("{mean:.4e}"))]
}

impl Certificate {
    /// The verdict of a solver report.
    pub fn from_report(r: &Report) -> Self {
        let mut details = vec![
            ("backend".to_string(), r.setup.backend.clone()),
            ("operator".to_string(), r.setup.operator.to_string()),
            ("levels".to_string(), r.solve.levels.len().to_string()),
        ];
        if let Some(l) = r.solve.levels.last() {
            details.push((
                "finest level".to_string(),
                format!(
                    "{}x{} basis, {} iterations{}",
                    l.shape[0],
                    l.shape[1],
                    l.iterations,
                    if l.converged { "" } else { ", not converged" }
                ),
            ));
        }
        details.push(("repairs".to_string(), r.solve.repairs.to_string()));
        details.push((
            "boundary deviation".to_string(),
            format!("{:.2e}", r.boundary.deviation.iter().copied().fold(0.0, f64::max)),
        ));
        Self {
            verdict: r.outcome.verdict,
            message: r.outcome.message.clone(),
            source: CertificateSource::Solver,
            details,
        }
    }

    /// The verdict of one patch of a layout solve (§11.2): the core's certificate of the
    /// patch's map with its conforming sides.
    pub fn of_patch(p: &winslow::multipatch::solve::PatchSolution) -> Self {
        let c = &p.certificate;
        let mut details = vec![("patch".to_string(), p.name.clone())];
        if verdict_is_good(p.verdict) {
            details.push(("proven det J lower bound".to_string(), format!("{:.4e}", c.lower_bound)));
        } else {
            details.push(("smallest det J found".to_string(), format!("{:.4e}", c.min_value_found)));
        }
        details.push(("mean det J".to_string(), format!("{:.4e}", c.mean_det_j)));
        if let Some(l) = p.solve.solve.levels.last() {
            details.push((
                "finest level".to_string(),
                format!("{}x{} basis, {} iterations", l.shape[0], l.shape[1], l.iterations),
            ));
        }
        Self { verdict: p.verdict, message: c.message(), source: CertificateSource::Solver, details }
    }

    /// The verdict of a report stored in a map file (`None` if it has none we know).
    pub fn from_stored(report: &serde_json::Value) -> Option<Self> {
        let verdict = verdict_from_name(report.get("verdict")?.as_str()?)?;
        let message = report.get("message").and_then(|m| m.as_str()).unwrap_or_default().to_string();
        let mut details = Vec::new();
        for key in ["backend", "operator", "repairs", "det_j_min_away_from_forced_corners"] {
            if let Some(v) = report.get(key).filter(|v| !v.is_null()) {
                details.push((key.replace('_', " "), v.to_string().trim_matches('"').to_string()));
            }
        }
        Some(Self { verdict, message, source: CertificateSource::File, details })
    }

    /// The core's exact certificate of `map`; the sample rules ([`Certificate::from_sample`])
    /// when it cannot be computed (e.g. a degree past the certificate's limit).
    pub fn exact(map: &Surface, q: &Quality) -> Self {
        use winslow::verify::certificate::{certify, CertifyOptions};
        let Ok(c) = certify(map, &CertifyOptions::default()) else { return Self::from_sample(q) };
        let verdict = Verdict::of_certificate(&c);
        let mut details = det_j_details(verdict, c.lower_bound, c.min_value_found, c.mean_det_j);
        details.extend([
            ("det J degree".to_string(), format!("{}x{}", c.det_degree[0], c.det_degree[1])),
            ("elements / boxes / depth".to_string(), format!("{} / {} / {}", c.elements, c.boxes, c.max_depth)),
        ]);
        for k in &c.corners {
            if let Some(e) = k.excused_extent {
                details.push((format!("excused near {}", k.corner), format!("{:.3e} x {:.3e} (xi, eta)", e[0], e[1])));
            }
        }
        if let Some(u) = c.undecided_info.first() {
            let why = if u.smallest_coefficient.abs() <= u.error_bound { "zero within rounding" } else { u.reason };
            details.push((format!("undecided ({} elements)", c.undecided_info.len()), why.to_string()));
        }
        Self { verdict, message: c.message(), source: CertificateSource::Exact, details }
    }

    /// The solver's rules applied to the viewer's sample: folded when `det J <= 0` away
    /// from the corners the boundary forces, a degenerate corner when only such corners
    /// have it, positive otherwise. (Convergence is unknown for a map read from a file.)
    pub fn from_sample(q: &Quality) -> Self {
        let grid = format!("{0}x{0}", q.sample_n + 1);
        let (verdict, message) = if !crate::colour::is_positive(q.det_j_min_away_from_forced_corners) {
            let [u, v] = q.det_j_argmin;
            (Verdict::Folded, format!("det J <= 0 at (xi, eta) = ({u:.4}, {v:.4}) on the {grid} sample: the map folds"))
        } else if q.corners.iter().any(|c| c.forces_nonpositive_det_j) {
            let why: Vec<String> = q
                .corners
                .iter()
                .filter(|c| c.forces_nonpositive_det_j)
                .map(|c| format!("the {} corner ({:.1} degrees)", c.corner, c.angle_degrees))
                .collect();
            (
                Verdict::DegenerateCorner,
                format!(
                    "the boundary forces det J <= 0 at {}; det J > 0 elsewhere on the {grid} sample",
                    why.join(" and ")
                ),
            )
        } else {
            (Verdict::Undecided, format!("det J > 0 on the {grid} sample grid (not proven)"))
        };
        Self { verdict, message, source: CertificateSource::Sample, details: Vec::new() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use winslow::verify::quality::sample_det_j;
    use winslow::KnotVector;

    fn square(scale: f64) -> Surface {
        let kv = KnotVector::open_uniform(2, 2);
        let g = kv.greville();
        let cps = g.iter().flat_map(|&v| g.iter().map(move |&u| [scale * u, scale * v])).collect();
        Surface::new([kv.clone(), kv], cps, None).unwrap()
    }

    #[test]
    fn quality_of_a_square() {
        let s = square(2.0);
        let q = Quality::of(&s, &sample_det_j(&s, 16));
        assert!((q.det_j_min - 4.0).abs() < 1e-12 && (q.det_j_max - 4.0).abs() < 1e-12);
        assert!((q.functionals.area - 4.0).abs() < 1e-12);
        // Winslow functional (g11 + g22) / det J = 2 on the unit square
        assert!((q.functionals.winslow - 2.0).abs() < 1e-12);
        assert_eq!(q.forced_corners(), [false; 4]);
        for c in &q.corners {
            assert!((c.angle_degrees - 90.0).abs() < 1e-9);
        }
        let c = Certificate::exact(&s, &q);
        assert_eq!(c.verdict, Verdict::Certified);
        assert_eq!(c.source, CertificateSource::Exact);
        assert!(verdict_is_good(c.verdict));
        assert_eq!(Certificate::from_sample(&q).verdict, Verdict::Undecided);
    }

    #[test]
    fn folded_sample_gives_folded_verdict() {
        let mut s = square(1.0);
        let nx = s.shape()[0];
        s.control_points[nx + 1] = [2.0, 2.0];
        let q = Quality::of(&s, &sample_det_j(&s, 40));
        assert!(q.det_j_min < 0.0);
        let c = Certificate::from_sample(&q);
        assert_eq!(c.verdict, Verdict::Folded);
        assert!(!verdict_is_good(c.verdict));
        let e = Certificate::exact(&s, &q);
        assert_eq!(e.verdict, Verdict::Folded, "{}", e.message);
    }

    #[test]
    fn stored_report_verdicts() {
        let v = serde_json::json!({ "verdict": "degenerate-corner", "message": "m", "repairs": 1 });
        let c = Certificate::from_stored(&v).unwrap();
        assert_eq!(
            (c.verdict, c.message.as_str(), c.source),
            (Verdict::DegenerateCorner, "m", CertificateSource::File)
        );
        assert_eq!(c.details, vec![("repairs".to_string(), "1".to_string())]);
        assert!(Certificate::from_stored(&serde_json::json!({ "verdict": "maybe" })).is_none());
        assert!(Certificate::from_stored(&serde_json::json!(3)).is_none());
        for v in
            [Verdict::Certified, Verdict::DegenerateCorner, Verdict::Folded, Verdict::Undecided, Verdict::NotConverged]
        {
            // the names are the serde names of the core
            assert_eq!(serde_json::to_value(v).unwrap(), serde_json::json!(v.name()));
            assert_eq!(verdict_from_name(v.name()), Some(v));
        }
    }
}
