//! The outcome of a solve: the map and its report (stored in the map file and printed
//! by the CLI): the verdict of the certificate (§8.1), the quality functionals (§2,
//! §4.1), corners and kinks, the fit, per-level iterations and timings, the repair
//! rounds (§8.2) and, when asked for, the Poisson benchmark of §10.

use std::time::Duration;

use serde::Serialize;

use super::improve::Improvement;
use super::kinks::KinkStage;
use super::options::SolveOptions;
use super::repair::RepairRound;
use crate::boundary::corners::{corner_report, CornerReport, KinkReport};
use crate::boundary::hierarchy::{BasisReport, Hierarchy};
use crate::boundary::kinks::Rounding;
use crate::discrete::assembly::Operator;
use crate::spline::curve::Curve;
use crate::spline::surface::{Side, Surface};
use crate::verify::certificate::Certificate;
use crate::verify::quality::{quality, sample_det_j, Quality};

/// How a level's initial guess was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum InitialGuess {
    /// Transfinite interpolation (coarsest level).
    Coons,
    /// Prolongation of the previous level plus linear elasticity.
    Elasticity,
}

/// Summary of one solved level.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct LevelReport {
    /// Index among the solved levels.
    pub level: usize,
    /// Basis functions per direction.
    pub shape: [usize; 2],
    /// Elements per direction.
    pub elements: [usize; 2],
    /// Number of scalar unknowns (`2 m`).
    pub unknowns: usize,
    /// Initial guess used.
    pub initial_guess: InitialGuess,
    /// The level is the graded level put before the finest one (`solve::graded`): the
    /// coarser level's knots with the finest level's inserted where the finest start's
    /// residual sits. Written only when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub graded: bool,
    /// Smallest sampled `det J` of the initial guess.
    pub initial_det_j_min: f64,
    /// Damped boundary steps solved before the full boundary (paper §9); 0 when the
    /// elasticity guess was already positive.
    pub continuation_steps: usize,
    /// Nonlinear iterations spent in those steps.
    pub continuation_iterations: usize,
    /// Nonlinear iterations (excluding the initial residual evaluation).
    pub iterations: usize,
    /// Newton iterations among them.
    pub newton_iterations: usize,
    /// Pseudo-time iterations among them.
    pub pseudo_time_iterations: usize,
    /// Whether the stopping rule was met.
    pub converged: bool,
    /// Failure reason, if any.
    pub failure: Option<String>,
    /// `||F||` per iterate, initial guess first.
    pub residuals: Vec<f64>,
    /// Scaled residuals per iterate.
    pub scaled_residuals: Vec<f64>,
    /// Seconds spent assembling.
    pub assembly_seconds: f64,
    /// Seconds spent in linear solves.
    pub linear_seconds: f64,
    /// Of `linear_seconds`: assembling the preconditioner's metric Laplacian and
    /// factorizing.
    pub factor_seconds: f64,
    /// GMRES iterations over all linear solves of the level (0 with direct LU).
    pub krylov_iterations: usize,
    /// The most GMRES iterations of one linear solve of the level (0 with direct LU).
    pub krylov_max: usize,
    /// Linear solves of the level (Newton, chord and pseudo-time steps).
    pub linear_solves: usize,
    /// Seconds for the whole level (set-up, initial guess, iterations).
    pub seconds: f64,
}

/// Overall outcome of a solve: the bijectivity certificate of the final map
/// ([`crate::verify::certificate`]), unless the solver did not converge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// Converged and `det J > 0` proven on the whole map.
    Certified,
    /// Converged, `det J > 0` proven except near corners whose angle forces
    /// `det J <= 0`: the best map the boundary allows.
    DegenerateCorner,
    /// `det J <= 0` at a point away from forced corners: the map folds.
    Folded,
    /// Neither proven positive nor shown to fold within the subdivision budget.
    Undecided,
    /// The finest level did not converge.
    NotConverged,
}

impl Verdict {
    /// The verdict of a certificate (a converged map's).
    pub fn of_certificate(c: &Certificate) -> Self {
        Self::of_finding(&c.verdict)
    }

    /// The verdict of what a certificate found, of a map of the plane or of a volume.
    pub fn of_finding<const D: usize>(f: &crate::verify::certificate::Finding<D>) -> Self {
        match f {
            crate::verify::certificate::Finding::Certified { .. } => Verdict::Certified,
            crate::verify::certificate::Finding::DegenerateCorner { .. } => Verdict::DegenerateCorner,
            crate::verify::certificate::Finding::Folded { .. } => Verdict::Folded,
            crate::verify::certificate::Finding::Undecided { .. } => Verdict::Undecided,
        }
    }

    /// The name in the JSON report (`"certified"`, `"degenerate-corner"`, `"folded"`,
    /// `"undecided"`, `"not-converged"`).
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Certified => "certified",
            Verdict::DegenerateCorner => "degenerate-corner",
            Verdict::Folded => "folded",
            Verdict::Undecided => "undecided",
            Verdict::NotConverged => "not-converged",
        }
    }
}

/// Contour-fit summary per side.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct FitReport {
    /// Side name.
    pub side: &'static str,
    /// Number of fit levels.
    pub levels: usize,
    /// Elements on the finest fit.
    pub elements: usize,
    /// Max deviation of the finest fit.
    pub max_error: f64,
    /// Whether the tolerance was met.
    pub converged: bool,
}

/// The report stored in the map file and printed by the CLI, grouped by the stage each
/// part describes. Every group is flattened into the one JSON object of the map file
/// (`docs/formats.md`): the keys are the groups' fields, named as before the grouping.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct Report {
    /// The problem: version, back end, degree, operator and basis of the map.
    #[serde(flatten)]
    pub setup: SetupReport,
    /// The fit of the boundary (§5, §7): tolerance, per-side fits, reparameterization.
    #[serde(flatten)]
    pub fit: FitStage,
    /// The solve: levels, repair rounds (§8.2), improvement, warm start, time.
    #[serde(flatten)]
    pub solve: SolveStage,
    /// The outcome: the certificate (§8.1), the verdict and its message.
    #[serde(flatten)]
    pub outcome: Outcome,
    /// `det J` on the sample grid (information; the verdict comes from the certificate).
    #[serde(flatten)]
    pub det_j: DetJReport,
    /// The quality functionals (§2, §4.1), the area and the Poisson benchmark (§10).
    #[serde(flatten)]
    pub measures: QualityReport,
    /// The boundary of the map: corners, kinks, the `C^0` route (§9), the deviation.
    #[serde(flatten)]
    pub boundary: BoundaryReport,
}

/// The problem a report describes: what was solved, how, and in which basis.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct SetupReport {
    /// Crate version.
    pub version: &'static str,
    /// Assembly back end.
    pub backend: String,
    /// Degree of the map.
    pub degree: [usize; 2],
    /// Operator.
    pub operator: &'static str,
    /// Tensor-product basis functions of the map (`n_xi * n_eta`).
    pub basis_functions: usize,
    /// The basis of the map: fitted (§5) or the input's own (§5.2), and why the input
    /// basis was not used when it was asked for.
    pub basis: BasisReport,
}

/// The fit of the boundary (§5) and its preparation: normalisation and
/// reparameterization (§7).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct FitStage {
    /// Absolute fit tolerance and the diameter it is relative to.
    pub fit_tolerance: f64,
    /// Bounding-box diameter of the boundary.
    pub diameter: f64,
    /// Per-side fit summary (the `fit` key).
    #[serde(rename = "fit")]
    pub sides: Vec<FitReport>,
    /// The boundary reparameterization (paper §7): method used and matched pairs.
    pub reparam: crate::boundary::reparam::ReparamReport,
    /// The similarity `x = centre + scale x̂` from the normalised coordinates the solve ran
    /// in (`boundary::normalise`); `null` when the input was solved as given.
    pub normalisation: Option<crate::boundary::normalise::Similarity>,
}

/// The solve: every level, the repair rounds and the improvement stage.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct SolveStage {
    /// Per-level summaries.
    pub levels: Vec<LevelReport>,
    /// Defect-correction rounds run because the finest map folded or was undecided.
    pub repairs: usize,
    /// Each defect-correction round.
    pub repair_rounds: Vec<RepairRound>,
    /// The improvement stage after the solve (`--improve winslow`): quality before and
    /// after, iterations, time; `null` when none was asked for.
    pub improvement: Option<Improvement>,
    /// Seconds of the solve: the levels (initial guesses, iterations), repair rounds,
    /// the improvement stage and the certificate of the map written; not the fit of
    /// the boundary before it, nor the report's own measurements of the map after it
    /// (boundary deviation, det J sample, quality functionals).
    pub seconds: f64,
    /// When a warm start was asked for ([`crate::Pipeline::warm_start`]) and did not
    /// apply: `{"used": false, "reason": ...}`; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warm_start: Option<WarmNote>,
    /// When THB refinement was asked for and its rounds left the map folded or
    /// undecided, so the tensor repair ran instead (`crate::pipeline`): what the THB
    /// rounds ended with; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thb_fallback: Option<ThbFallback>,
}

/// The start of the THB rounds (`crate::pipeline::ThbReport::start`).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ThbStart {
    /// `"contour"`: the THB basis of the contour fit, the boundary the fitted sides, EGG
    /// solved on it from the tensor map's blossoms; `"tensor"`: the tensor solve's map on
    /// its own basis (a one-level THB map).
    pub basis: &'static str,
    /// Why the contour basis was not used (`None` when it was).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// THB functions of the start.
    pub functions: usize,
    /// Levels of its hierarchy.
    pub levels: usize,
    /// Newton iterations of the EGG solve on the contour basis (0 for the tensor start).
    pub iterations: usize,
    /// Whether that solve converged (true for the tensor start).
    pub converged: bool,
    /// The verdict of the start map's certificate (the contour start after its solve).
    pub verdict: Verdict,
    /// Seconds of the contour basis, the blossoms and the solve (0 for the tensor start).
    pub seconds: f64,
    /// Active THB functions of each level of the start, coarse to fine.
    pub functions_per_level: Vec<usize>,
    /// Active cells of each level of the start, coarse to fine.
    pub cells_per_level: Vec<usize>,
    /// The refined cells `[i, j]` of each level of the start (as the THB map's `refined`,
    /// on the same level knots: the rounds refine the start further), so that the start's
    /// active cells can be drawn from the written map.
    pub refined: Vec<Vec<[usize; 2]>>,
}

/// What a THB defect correction that did not end certified (or degenerate at forced
/// corners only) ended with: the `thb_fallback` field of a report (the tensor repair then
/// took over) and the `first_attempt` of a THB report (`crate::pipeline::ThbReport`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThbFallback {
    /// Verdict of the THB map after its rounds.
    pub verdict: Verdict,
    /// THB rounds run.
    pub rounds: usize,
    /// THB functions of that map.
    pub functions: usize,
    /// Folded and undecided active cells left.
    pub offending_cells: usize,
    /// Seconds of the THB stage.
    pub seconds: f64,
}

/// The outcome of a solve: the certificate and the verdict drawn from it.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct Outcome {
    /// The bijectivity certificate of the map.
    pub certificate: Certificate,
    /// The outcome.
    pub verdict: Verdict,
    /// Plain-language summary of the verdict.
    pub message: String,
}

/// `det J` on the sample grid (corners included; the sample is additional information,
/// the verdict comes from the certificate). Keys `det_j_min`, `det_j_min_interior`,
/// `det_j_min_away_from_forced_corners`, `det_j_max`, `det_j_argmin`, `det_j_sample`.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct DetJReport {
    /// `det J` minimum on the sample grid.
    #[serde(rename = "det_j_min")]
    pub min: f64,
    /// `det J` minimum away from the four corners.
    #[serde(rename = "det_j_min_interior")]
    pub min_interior: f64,
    /// `det J` minimum away from the corners the boundary forces (two spans around
    /// each); the verdict is `folded` when this is not positive.
    #[serde(rename = "det_j_min_away_from_forced_corners")]
    pub min_away_from_forced_corners: f64,
    /// `det J` maximum on the sample grid.
    #[serde(rename = "det_j_max")]
    pub max: f64,
    /// Parameter point of the minimum.
    #[serde(rename = "det_j_argmin")]
    pub argmin: [f64; 2],
    /// Sample grid size.
    #[serde(rename = "det_j_sample")]
    pub sample: usize,
}

/// The quality of the map: functionals, cell statistics, area, the Poisson benchmark.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct QualityReport {
    /// Quality functionals and cell statistics.
    pub quality: Quality,
    /// Winslow functional (eq. 15-16); `null` when `det J <= 0` at a quadrature point.
    pub winslow: Option<f64>,
    /// Area of the mapped domain.
    pub area: f64,
    /// The Poisson benchmark of §10 (when asked for, and when it could be solved).
    pub poisson: Option<crate::verify::poisson::PoissonReport>,
}

/// The boundary of the map: its corners and kinks and how far it is from the input's.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct BoundaryReport {
    /// Corner angles.
    pub corners: Vec<CornerReport>,
    /// Kinks inside the sides (spline sides' `C^0` and zero-speed knots, point clouds'
    /// corners): kept exactly by the `C^0` route of §9 or rounded, with the deviation of
    /// the map's boundary at each.
    pub kinks: Vec<KinkReport>,
    /// The `C^0` route of §9 (`--kinks`): EGG on the smoothed basis, elasticity to the
    /// kinked boundary, Winslow on the `C^0` basis; `null` when no kink is kept.
    pub c0_route: Option<KinkStage>,
    /// Largest distance of the map's boundary from the input boundary, per side
    /// (south, east, north, west): [`crate::verify::quality::boundary_deviation`], the
    /// measure `winslow check --boundary` reports too (the `boundary_deviation` key).
    #[serde(rename = "boundary_deviation")]
    pub deviation: [f64; 4],
    /// Whether the map's boundary is the input's within the stated tolerance: the largest
    /// [`deviation`](Self::deviation) at most [`FitStage::fit_tolerance`]. A bijective map
    /// whose boundary is not (kinks the `C^0` route of §9 could not keep, a fit short of
    /// its tolerance) is not a success ([`Report::success`]); the `boundary_kept` key.
    #[serde(rename = "boundary_kept")]
    pub kept: bool,
    /// Point-cloud corners the cloud resolves as roundings over two or more chords: no
    /// kinks, the `C^1` fit follows them (`boundary::kinks::rounding_of`), in the input's
    /// coordinates; the key is absent when there are none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub roundings: Vec<Rounding>,
}

impl Report {
    /// A success: certified (or the best map a forced degenerate corner admits), its
    /// boundary the input's within the fit tolerance ([`BoundaryReport::kept`]) and the
    /// kinks of the `C^0` route kept ([`Report::kinks_kept`]).
    pub fn success(&self) -> bool {
        matches!(self.outcome.verdict, Verdict::Certified | Verdict::DegenerateCorner)
            && self.boundary.kept
            && self.kinks_kept()
    }

    /// Whether the `C^0` route of §9, where it ran, kept its kinks: a kink it could not
    /// keep is rounded, and the run is not a success ([`Report::success`]) even where the
    /// rounding stays within the fit tolerance.
    pub fn kinks_kept(&self) -> bool {
        self.boundary.c0_route.as_ref().is_none_or(|r| r.kept)
    }
}

/// A solved map and its report.
#[derive(Debug, Clone)]
pub struct Solution {
    /// Name of the geometry.
    pub name: String,
    /// The map of the finest level.
    pub map: Surface,
    /// The report.
    pub report: Report,
}

/// Smallest sampled `det J` outside the neighbourhoods of the corners that the
/// boundary forces to `det J <= 0`: the first two knot spans in each direction there.
pub fn min_away_from_corners(map: &Surface, s: &crate::verify::quality::DetJSample, corners: &[CornerReport]) -> f64 {
    // the widths of the first two and the last two knot spans, [direction][at end]
    let spans: [[f64; 2]; 2] = std::array::from_fn(|d| {
        let b = map.knots[d].breaks();
        let k = b.len();
        [(b[2.min(k - 1)] - b[0]).max(0.0), (b[k - 1] - b[k.saturating_sub(3)]).max(0.0)]
    });
    let span = |d: usize, at_end: bool| spans[d][usize::from(at_end)];
    let centres = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let n = s.n;
    let mut min = f64::INFINITY;
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            let near = corners.iter().zip(centres).any(|(c, (cu, cv))| {
                c.forces_nonpositive_det_j && (u - cu).abs() <= span(0, cu > 0.5) && (v - cv).abs() <= span(1, cv > 0.5)
            });
            if !near {
                min = min.min(s.values[j * (n + 1) + i]);
            }
        }
    }
    min
}

/// What the report is made from besides the map.
pub(crate) struct ReportContext<'a> {
    pub hierarchy: &'a Hierarchy,
    pub sides: &'a [Curve; 4],
    pub kinks: Vec<KinkReport>,
    pub c0_route: Option<KinkStage>,
    pub boundary_deviation: [f64; 4],
    pub opts: &'a SolveOptions,
    pub backend: String,
    pub repairs: usize,
    pub rounds: Vec<RepairRound>,
    pub certificate: Certificate,
    pub improvement: Option<Improvement>,
    pub elapsed: Duration,
}

impl Solution {
    pub(crate) fn new(name: &str, map: Surface, levels: Vec<LevelReport>, ctx: ReportContext<'_>) -> Self {
        let (h, opts) = (ctx.hierarchy, ctx.opts);
        let sample = sample_det_j(&map, opts.report.sample);
        let quality = quality(&map);
        let fun = quality.functionals;
        let certificate = ctx.certificate;
        // a ring (eta periodic) has no corners
        let corners = if opts.topology.eta_periodic() { Vec::new() } else { corner_report(ctx.sides) };
        let converged = levels.last().is_some_and(|l| l.converged);
        let away = min_away_from_corners(&map, &sample, &corners);
        let kinks = ctx.kinks;
        let (verdict, message) = if !converged {
            (
                Verdict::NotConverged,
                format!(
                    "the nonlinear solver did not converge on the finest level ({}); the map is the last iterate",
                    levels.last().and_then(|l| l.failure.clone()).unwrap_or_default()
                ),
            )
        } else {
            let v = Verdict::of_certificate(&certificate);
            let mut m = certificate.message();
            if v == Verdict::Certified {
                for c in corners.iter().filter(|c| c.forces_nonpositive_det_j) {
                    m.push_str(&format!(
                        "; note: the {} corner has an angle of {:.2} degrees, where the exact boundary forbids det J > 0; \
                         the fitted boundary rounds it within the fit tolerance",
                        c.corner, c.angle_degrees
                    ));
                }
            }
            (v, m)
        };
        let fit_tolerance = h.physical_tol_abs();
        let deviation = ctx.boundary_deviation.iter().fold(0.0f64, |m, &d| m.max(d));
        let boundary_kept = deviation <= fit_tolerance;
        let mut message = message;
        if !boundary_kept {
            message.push_str(&format!(
                "; the map's boundary is NOT the input's: it deviates by {deviation:.3e}, above the fit tolerance \
                 {fit_tolerance:.3e}"
            ));
        }
        if let Some(r) = &ctx.c0_route {
            message.push_str(&format!("; {}", r.message));
        }
        let input = h.basis.used == crate::boundary::BasisChoice::Input;
        let route_failed = ctx.c0_route.as_ref().is_some_and(|r| !r.kept);
        for k in &kinks {
            let at = format!(
                "the {} side's kink at ({:.6}, {:.6}) (tangent turns {:.1} degrees)",
                k.side, k.point[0], k.point[1], k.turning_degrees
            );
            message.push_str(&if k.kept {
                format!("; {at} is kept exactly (deviation {:.1e})", k.deviation)
            } else if route_failed {
                format!("; {at} is NOT kept (the C0 route failed, above): rounded, deviation {:.3e}", k.deviation)
            } else if input {
                format!(
                    "; note: {at} is not kept by a C0 knot line: the map's boundary is the input's, whose speed vanishes \
                     there, so det J = 0 at that point"
                )
            } else {
                format!(
                    "; note: {at}, where any C1 map of the exact boundary has det J = 0, is rounded by the fitted boundary \
                     (deviation {:.3e}; --kinks keeps it)",
                    k.deviation
                )
            });
        }
        if let Some(imp) = &ctx.improvement {
            message.push_str(&format!("; improvement: {}", imp.message));
        }
        let fit = Side::ALL
            .iter()
            .map(|&s| {
                let f = &h.fits[s as usize];
                FitReport {
                    side: s.name(),
                    levels: f.levels.len(),
                    elements: f.levels.last().map_or(0, |c| c.knots.num_elements()),
                    max_error: h.similarity.length(f.max_error.last().copied().unwrap_or(0.0)),
                    converged: f.converged,
                }
            })
            .collect();
        let report = Report {
            setup: SetupReport {
                version: env!("CARGO_PKG_VERSION"),
                backend: ctx.backend,
                degree: map.degrees(),
                operator: match opts.operator {
                    Operator::Plain => "plain",
                    Operator::Scaled => "scaled",
                },
                basis_functions: map.knots[0].num_basis() * map.knots[1].num_basis(),
                basis: h.basis.clone(),
            },
            fit: FitStage {
                fit_tolerance,
                diameter: h.physical_diameter(),
                sides: fit,
                reparam: h.physical_reparam(),
                normalisation: (!h.similarity.is_identity()).then_some(h.similarity),
            },
            solve: SolveStage {
                levels,
                repairs: ctx.repairs,
                repair_rounds: ctx.rounds,
                improvement: ctx.improvement,
                seconds: ctx.elapsed.as_secs_f64(),
                warm_start: None,
                thb_fallback: None,
            },
            outcome: Outcome { certificate, verdict, message },
            det_j: DetJReport {
                min: sample.min,
                min_interior: sample.min_interior,
                min_away_from_forced_corners: away,
                max: sample.max,
                argmin: sample.argmin,
                sample: sample.n,
            },
            measures: QualityReport {
                quality,
                winslow: fun.winslow.is_finite().then_some(fun.winslow),
                area: fun.area,
                poisson: if opts.report.poisson {
                    crate::verify::poisson::poisson_benchmark(&map, None).ok()
                } else {
                    None
                },
            },
            boundary: BoundaryReport {
                corners,
                kinks,
                c0_route: ctx.c0_route,
                deviation: ctx.boundary_deviation,
                kept: boundary_kept,
                roundings: h
                    .roundings
                    .iter()
                    .map(|r| Rounding {
                        point: h.similarity.to_physical(r.point),
                        radius: h.similarity.length(r.radius),
                        sagitta: h.similarity.length(r.sagitta),
                        ..r.clone()
                    })
                    .collect(),
            },
        };
        Self { name: name.to_string(), map, report }
    }
}

/// Whether a warm start was used, and why not (the `warm_start` field of a report).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WarmNote {
    /// Whether the shape was solved from the previous map.
    pub used: bool,
    /// Why not, when not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}
