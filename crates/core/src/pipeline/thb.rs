//! The THB defect correction as a stage of the pipeline (paper §8.2 on a truncated
//! hierarchical basis, §4; issue 35). With [`Refinement::Thb`] the coarse-to-fine solve
//! runs without tensor repair rounds; when its map is folded or undecided and repair
//! rounds are allowed, the rounds start from the contour fit's THB basis (each side
//! refined along itself only, `solve::hierarchical::contour`, EGG solved on it) or, where
//! that does not apply, from the tensor map as a one-level THB map, and
//! [`repair_thb_observed`] refines only the offending cells and a ring
//! around them, round by round ([`Stage::ThbRound`](super::Stage::ThbRound)), until the
//! certificate accepts the map or the rounds run out. When the offending cells grow in
//! two successive rounds (the folds pushed deeper instead of removed) or the rounds end
//! unaccepted, the rounds start again from the same start with a ring of
//! `RETRY_RING` cells in every round. The result is
//! [`Solved::Thb`](super::Solved::Thb): the THB map and its [`ThbReport`].

use std::time::Instant;

use serde::Serialize;

use super::{Observer, Stage};
use crate::boundary::hierarchy::Hierarchy;
use crate::boundary::BasisChoice;
use crate::error::{Error, Result};
use crate::solve::hierarchical::contour::{coarsened_levels, contour_start};
use crate::solve::hierarchical::improve::{improve_thb, ThbImprovement};
use crate::solve::hierarchical::{accepted, repair_thb_observed, solve_egg, ThbRepairOptions, ThbRound};
use crate::solve::improve::Improve;
use crate::solve::levels::prepare_levels;
use crate::solve::newton::NonlinearOptions;
use crate::solve::options::{Refinement, SolveOptions};
use crate::solve::report::{Report, Solution, ThbFallback, ThbStart, Verdict};
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::hierarchical::HierarchicalBasis;
use crate::verify::certificate::hierarchical::{certify_hierarchical, HierarchicalCertificate};
use crate::verify::poisson::{poisson_benchmark, PoissonReport};

/// A THB map solved by the pipeline: the tensor solve's map repaired by THB defect
/// correction.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ThbSolution {
    /// Name of the geometry.
    pub name: String,
    /// The THB map.
    pub map: HierarchicalMap,
    /// What the tensor solve and the THB rounds did.
    pub report: ThbReport,
}

/// The report of a THB solve (the `report` of the THB map document `winslow solve
/// --refinement thb` writes, and its `--json` output).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ThbReport {
    /// Always [`Refinement::Thb`] (`"thb"`).
    pub refinement: Refinement,
    /// The verdict of the THB map's certificate.
    pub verdict: Verdict,
    /// The certificate's summary.
    pub message: String,
    /// The certificate of the THB map, active cell by active cell.
    pub certificate: HierarchicalCertificate,
    /// THB functions of the map.
    pub functions: usize,
    /// Levels of its hierarchy.
    pub levels: usize,
    /// Free unknowns of the last round's solve (0 when no round ran).
    pub unknowns: usize,
    /// The rounds of the defect correction.
    pub thb_rounds: Vec<ThbRound>,
    /// Seconds of the THB stage (the conversion, the rounds, the certificates).
    pub thb_seconds: f64,
    /// With `--improve winslow`: the Winslow functional minimized on the repaired THB
    /// map's basis (`solve::hierarchical::improve`); `None` when no improvement was asked
    /// for or the repaired map is not certified.
    pub improvement: Option<ThbImprovement>,
    /// With `--poisson` (the options' `report.poisson`): the manufactured-solution Poisson
    /// benchmark ([`crate::verify::poisson`]) on the THB map's exact tensor form.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub poisson: Option<PoissonReport>,
    /// When the first rounds (a ring of `--halo` cells in the first, the offending cells
    /// only in the later ones) left the map folded or undecided, or were stopped because
    /// the offending cells grew in two successive rounds (`solve::hierarchical::growing`),
    /// so that the rounds ran again from the tensor map with a ring of 2 cells in every
    /// round: what the first rounds ended with. When the second rounds certify, the map and
    /// `thb_rounds` are theirs (and `first_rounds` the first ones); otherwise the first
    /// rounds'. Absent when the first rounds sufficed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_attempt: Option<ThbFallback>,
    /// The first rounds when the second ones certified (see `first_attempt`); empty (and
    /// absent from the JSON) otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub first_rounds: Vec<ThbRound>,
    /// Where the THB rounds started: the THB basis of the contour fit (each side refined
    /// only along itself, `solve::hierarchical::contour`) with EGG solved on it, or the
    /// tensor solve's map, and why.
    pub start: ThbStart,
    /// The report of the tensor solve the THB stage started from.
    pub solve: Report,
}

impl ThbSolution {
    /// Whether the map is certified (or degenerate only at corners the boundary forces),
    /// its boundary the input's and the kinks of the `C^0` route kept (as
    /// [`Report::success`] of the tensor solve it started from).
    pub fn success(&self) -> bool {
        matches!(self.report.verdict, Verdict::Certified | Verdict::DegenerateCorner)
            && self.report.solve.boundary.kept
            && self.report.solve.kinks_kept()
    }
}

/// The ring (in cell widths of the offending cell's level) of every round of the second
/// THB attempt, when the first one (ring `--halo` then 0) does not certify: on the hard
/// corpus's puzzle-3 the first attempt's offending cells grow every round (64 to 456 in
/// six rounds, BENCHMARKS.md "THB on the puzzle family"), a ring of 1 in every round
/// leaves 14 after six rounds, a ring of 2 certifies in six with 20,702 functions (the
/// tensor repair: 62,238).
pub(crate) const RETRY_RING: usize = 2;

/// Whether the pipeline repairs `sol` by THB refinement: [`Refinement::Thb`] (or
/// [`Refinement::Auto`] on a boundary with rounded point-cloud corners, the report's
/// `roundings`), repair rounds allowed, and the map folded or undecided.
pub(crate) fn repairs(sol: &Solution, opts: &SolveOptions) -> bool {
    opts.repair.refinement.resolved(!sol.report.boundary.roundings.is_empty()) == Refinement::Thb
        && opts.repair.rounds > 0
        && matches!(sol.report.outcome.verdict, Verdict::Folded | Verdict::Undecided)
}

/// The THB map `t` when its certificate accepts it; otherwise the tensor repair's map
/// (`tensor`, the same input with [`Refinement::Tensor`], solved from the start: the
/// tensor solve's repair state is gone), its report's `thb_fallback` saying what the THB
/// rounds ended with, when that map is accepted ([`Report::success`]'s verdicts); the THB
/// map again when neither is.
pub(crate) fn or_tensor_repair(
    t: ThbSolution,
    tensor: super::Pipeline,
    observer: &mut Observer<'_>,
) -> Result<super::Solved> {
    use super::Solved;
    if matches!(t.report.verdict, Verdict::Certified | Verdict::DegenerateCorner) {
        return Ok(Solved::Thb(Box::new(t)));
    }
    let note = ThbFallback {
        verdict: t.report.verdict,
        rounds: t.report.thb_rounds.len(),
        functions: t.report.functions,
        offending_cells: t.report.certificate.offending_cells().len(),
        seconds: t.report.thb_seconds,
    };
    if !observer(&Stage::ThbFallback { thb: &note }) {
        return Err(Error::Cancelled);
    }
    let (mut sol, _) = tensor.run_keeping_hierarchy(observer)?;
    if !matches!(sol.report.outcome.verdict, Verdict::Certified | Verdict::DegenerateCorner) {
        return Ok(Solved::Thb(Box::new(t)));
    }
    sol.report.solve.thb_fallback = Some(note);
    Ok(Solved::Map(Box::new(sol)))
}

/// The options of the THB defect correction from those of the solve: its repair rounds
/// and halo, operator, Newton and certificate options.
fn thb_options(opts: &SolveOptions) -> ThbRepairOptions {
    ThbRepairOptions {
        rounds: opts.repair.rounds,
        ring: opts.repair.halo,
        operator: opts.operator,
        nonlinear: opts.nonlinear,
        certify: opts.certify,
        ..Default::default()
    }
}

/// The admissibility classes of the contour start, tried in this order: class 3 grades
/// less (puzzle3's start 409 functions against 481, certified with 469 against 526;
/// the hard corpus's puzzle-1 to puzzle-3 2,158, 1,531, 3,029 against 2,506, 1,993, 3,374),
/// class 2 where Newton does not converge on class 3's basis (male_casing_ring's input
/// basis; BENCHMARKS.md "THB: anisotropic levels and the start's Newton").
const START_CLASSES: [usize; 2] = [3, 2];

/// The map the THB rounds start from: with the hierarchy `h` the tensor solve's map was
/// solved on, the THB basis of its contour fit ([`contour_start`]: level 0 the solver's
/// coarsest level, each side refined along itself only) with EGG solved on it
/// ([`solve_egg`]); the tensor map `sol.map` (one level) when there is no hierarchy, the
/// fit keeps kinks exactly (knots of multiplicity `p`), the contour basis does not
/// apply or is not smaller than the tensor basis, or Newton does not converge on it for
/// any of [`START_CLASSES`] (the reason in the report).
fn start(sol: &Solution, h: Option<&Hierarchy>, opts: &SolveOptions) -> Result<(HierarchicalMap, ThbStart)> {
    let t0 = Instant::now();
    let tensor = |reason: String| -> Result<(HierarchicalMap, ThbStart)> {
        let map = HierarchicalMap::from_surface(&sol.map)?;
        let report = ThbStart {
            basis: "tensor",
            reason: Some(reason),
            functions: map.basis.len(),
            levels: 1,
            iterations: 0,
            converged: true,
            verdict: sol.report.outcome.verdict,
            seconds: 0.0,
            functions_per_level: map.basis.functions_per_level(),
            cells_per_level: map.basis.cells_per_level(),
            refined: Vec::new(),
        };
        Ok((map, report))
    };
    let Some(h) = h else { return tensor("no contour fit (the tensor map was given)".into()) };
    if h.kinked.is_some() {
        return tensor("kinks kept exactly (C0 route): their knots are not dyadic".into());
    }
    let sides = h.fits.each_ref().map(|f| f.finest().knots.clone());
    let basis = if matches!(h.basis.used, BasisChoice::Input) {
        // the input basis: its knot vectors the finest given level, every other break
        // removed below it, down to the solver's minimum elements
        match coarsened_levels(&sol.map.knots, opts.levels.min_elements) {
            Ok(levels) => HierarchicalBasis::with_levels(levels)?,
            Err(why) => return tensor(format!("the input basis has no coarser levels: {why}")),
        }
    } else {
        // the solver's coarsest level (`EggSolver::with_method`: balanced, its minimum elements)
        let (min_elements, aspect) = (opts.levels.min_elements, opts.levels.aspect);
        let Some(coarse) = prepare_levels(vec![h.levels[0].clone()], min_elements, 0, aspect)?.into_iter().next()
        else {
            return tensor("no coarse level".into());
        };
        HierarchicalBasis::new(coarse.knots)?
    };
    // Newton only: the start is a start for the rounds, and the tensor map is one too; a
    // Newton that stalls would otherwise go on in pseudo time (up to `max_pseudo` steps,
    // each an assembly and a factorization: minutes on male_casing_ring's start of class 3)
    let newton = NonlinearOptions { fallback: false, ..opts.nonlinear };
    let mut why = String::new();
    for class in START_CLASSES {
        let thb = match contour_start(&sol.map, basis.clone(), &sides, class)? {
            Ok(thb) if thb.basis.len() < sol.map.control_points.len() => thb,
            Ok(thb) => {
                let n = thb.basis.len();
                return tensor(format!("the contour basis ({n} functions) is not smaller than the tensor one"));
            }
            Err(why) => return tensor(why),
        };
        let egg = match solve_egg(&thb, opts.operator, newton) {
            Ok(egg) if egg.converged => egg,
            Ok(egg) => {
                let n = egg.iterations;
                why = format!(
                    "Newton on the contour basis (admissibility class {class}) did not converge in {n} iterations"
                );
                continue;
            }
            Err(e) => {
                why = format!("the EGG solve on the contour basis (admissibility class {class}) failed: {e}");
                continue;
            }
        };
        let cert = certify_hierarchical(&egg.map, &opts.certify)?;
        let report = ThbStart {
            basis: "contour",
            reason: None,
            functions: egg.map.basis.len(),
            levels: egg.map.basis.num_levels(),
            iterations: egg.iterations,
            converged: egg.converged,
            verdict: Verdict::of_finding(&cert.verdict),
            seconds: t0.elapsed().as_secs_f64(),
            functions_per_level: egg.map.basis.functions_per_level(),
            cells_per_level: egg.map.basis.cells_per_level(),
            refined: egg.map.basis.refined_lists(),
        };
        return Ok((egg.map, report));
    }
    tensor(why)
}

/// The THB defect correction of the tensor solve `sol` (see the module documentation):
/// at most `opts.repair.rounds` rounds, each refining the offending cells and `opts.repair.halo`
/// cells around them, EGG with the options' operator and Newton options, the
/// certificate with theirs; every round to `observer`.
///
/// With `--improve winslow` the certified THB map is then improved on its own basis
/// ([`improve_thb`]); `--improve weak` is refused ([`Error::Invalid`]): the weak form
/// (eq. 14) has no THB discretization here.
pub(crate) fn repair(
    sol: Solution,
    hierarchy: Option<&Hierarchy>,
    opts: &SolveOptions,
    observer: &mut Observer<'_>,
) -> Result<ThbSolution> {
    let t0 = Instant::now();
    if opts.improve == Some(Improve::WeakForm) {
        return Err(Error::Invalid(
            "a THB map (--refinement thb) is improved by the Winslow functional only (eq. 16): \
             use --improve winslow or no improvement"
                .into(),
        ));
    }
    let (start, start_report) = start(&sol, hierarchy, opts)?;
    // the first rounds stop as soon as the offending cells keep growing
    let narrow = ThbRepairOptions { stop_when_growing: true, ..thb_options(opts) };
    let mut out = repair_thb_observed(start.clone(), &narrow, &mut |round| observer(&Stage::ThbRound(round)))?;
    let (mut first_attempt, mut first_rounds) = (None, Vec::new());
    if !accepted(&out.certificate) && !out.rounds.is_empty() {
        let seconds = t0.elapsed().as_secs_f64();
        // the rounds again from the tensor map, a ring of `RETRY_RING` cells in every round
        let wide = ThbRepairOptions { ring: RETRY_RING, later_ring: RETRY_RING, stop_when_growing: false, ..narrow };
        let again = repair_thb_observed(start, &wide, &mut |round| observer(&Stage::ThbRound(round)))?;
        first_attempt = Some(ThbFallback {
            verdict: Verdict::of_finding(&out.certificate.verdict),
            rounds: out.rounds.len(),
            functions: out.map.basis.len(),
            offending_cells: out.certificate.offending_cells().len(),
            seconds,
        });
        if accepted(&again.certificate) {
            first_rounds = std::mem::replace(&mut out, again).rounds;
        }
    }
    let (map, c, improvement) = match opts.improve {
        Some(Improve::Winslow) if accepted(&out.certificate) => {
            let imp = improve_thb(&out.map, &out.certificate, opts.nonlinear, &opts.certify)?;
            (imp.map, imp.certificate, Some(imp.report))
        }
        _ => (out.map, out.certificate, None),
    };
    let report = ThbReport {
        refinement: Refinement::Thb,
        verdict: Verdict::of_finding(&c.verdict),
        message: c.message(),
        functions: map.basis.len(),
        levels: map.basis.num_levels(),
        unknowns: out.rounds.last().map_or(0, |r| r.unknowns),
        certificate: c,
        thb_rounds: out.rounds,
        thb_seconds: t0.elapsed().as_secs_f64(),
        improvement,
        poisson: if opts.report.poisson { poisson_benchmark(&map.to_surface()?, None).ok() } else { None },
        first_attempt,
        first_rounds,
        start: start_report,
        solve: sol.report,
    };
    Ok(ThbSolution { name: sol.name, map, report })
}

#[cfg(test)]
mod tests {
    use super::super::{Pipeline, Solved};
    use super::*;
    use crate::error::Error;
    use crate::io::{read_boundary, ReadOptions};
    use crate::solve::hierarchical::repair_thb;
    use crate::testutil::data;

    /// puzzle4 with `--refinement thb` (the geometry of the CLI's THB test): the
    /// pipeline's THB result is, bit for bit, what the front end made before the stage
    /// moved into the pipeline (the tensor solve without repair, its THB start (`start`:
    /// the contour basis), then `repair_thb` with
    /// the options' rounds, halo, operator, Newton and certificate options); the observer
    /// sees every round, in order, after the tensor solve's stages, and stops the run at
    /// the first round with [`Error::Cancelled`].
    #[test]
    fn the_thb_stage_gives_what_the_front_end_gave_and_is_observed() {
        let b = read_boundary(&data("gismo/puzzle4.json"), &ReadOptions::default()).unwrap();
        let mut opts = SolveOptions::default();
        opts.repair.refinement = Refinement::Thb;
        // the former path: the pipeline's map (no tensor repair, no fallback), then the repair
        let (unrepaired, h) = Pipeline::new(b.clone(), opts.clone()).run_keeping_hierarchy(&mut |_| true).unwrap();
        assert!(repairs(&unrepaired, &opts), "{:?}", unrepaired.report.outcome.verdict);
        let (begin, how) = start(&unrepaired, Some(&h), &opts).unwrap();
        assert_eq!(how.functions, begin.basis.len());
        let before = repair_thb(begin, &thb_options(&opts)).unwrap();
        assert!(accepted(&before.certificate), "{}", before.certificate.message());

        let mut seen = Vec::new();
        let solved = Pipeline::new(b.clone(), opts.clone())
            .run(&mut |stage| {
                seen.push(match stage {
                    Stage::ThbRound(r) => format!("round {} {}", r.round, r.functions),
                    _ => "tensor".to_string(),
                });
                true
            })
            .unwrap();
        assert_eq!(solved.kind(), "THB map");
        assert_eq!(solved.verdict(), Verdict::of_finding(&before.certificate.verdict));
        let Solved::Thb(t) = solved else { unreachable!() };
        assert_eq!(t.name, "puzzle4");
        assert_eq!(t.map.basis.active_functions(), before.map.basis.active_functions());
        assert_eq!(t.map.control_points, before.map.control_points);
        let r = &t.report;
        assert_eq!((r.functions, r.levels), (before.map.basis.len(), before.map.basis.num_levels()));
        assert_eq!(r.unknowns, before.rounds.last().unwrap().unknowns);
        assert_eq!(r.message, before.certificate.message());
        assert_eq!(r.solve.outcome.verdict, unrepaired.report.outcome.verdict);
        let strip = |rounds: &[ThbRound]| -> Vec<_> {
            rounds.iter().map(|x| (x.round, x.offending_cells, x.marked_cells, x.functions, x.iterations)).collect()
        };
        assert_eq!(strip(&r.thb_rounds), strip(&before.rounds));
        // the report's JSON fields, as the CLI wrote them by hand before
        let v = serde_json::to_value(r).unwrap();
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
        for k in ["refinement", "verdict", "message", "certificate", "functions", "levels", "unknowns"] {
            assert!(keys.contains(&k), "{k} in {keys:?}");
        }
        for k in ["thb_rounds", "thb_seconds", "solve"] {
            assert!(keys.contains(&k), "{k} in {keys:?}");
        }
        assert_eq!(
            (v["refinement"].as_str(), v["verdict"].as_str()),
            (Some("thb"), Some(before.certificate.verdict.name()))
        );
        // every round observed, after the tensor stages
        let rounds: Vec<&String> = seen.iter().filter(|s| s.starts_with("round")).collect();
        let expected: Vec<String> =
            before.rounds.iter().map(|x| format!("round {} {}", x.round, x.functions)).collect();
        assert_eq!(rounds, expected.iter().collect::<Vec<_>>());
        let first = seen.iter().position(|s| s.starts_with("round")).unwrap();
        assert!(first > 0 && seen[first..].iter().all(|s| s.starts_with("round")), "{seen:?}");
        // stopped at the first round
        let out = Pipeline::new(b, opts).run(&mut |stage| !matches!(stage, Stage::ThbRound(_)));
        assert!(matches!(out, Err(Error::Cancelled)), "{:?}", out.map(|s| s.kind()));
    }

    /// A THB defect correction that ends folded (puzzle4's tensor map, no round) falls
    /// back to the tensor repair, which certifies puzzle4 in its six rounds: the
    /// tensor map comes back with the THB rounds' outcome in `thb_fallback`, after a
    /// [`Stage::ThbFallback`]; a certified THB map is returned as it is.
    #[test]
    fn a_folded_thb_repair_falls_back_to_the_tensor_repair() {
        let b = read_boundary(&data("gismo/puzzle4.json"), &ReadOptions::default()).unwrap();
        let mut opts = SolveOptions::default();
        opts.repair.refinement = Refinement::Thb;
        let (unrepaired, _) = Pipeline::new(b.clone(), opts.clone()).run_keeping_hierarchy(&mut |_| true).unwrap();
        opts.repair.rounds = 0;
        let t = repair(unrepaired, None, &opts, &mut |_| true).unwrap();
        assert_eq!(t.report.verdict, Verdict::Folded, "{}", t.report.message);
        assert!(t.report.thb_rounds.is_empty() && t.report.first_attempt.is_none());
        let tensor_opts = SolveOptions::default();
        assert_eq!(tensor_opts.repair.refinement, Refinement::Tensor);
        let mut fell_back = 0;
        let out = or_tensor_repair(t.clone(), Pipeline::new(b.clone(), tensor_opts), &mut |stage| {
            if let Stage::ThbFallback { thb } = stage {
                assert_eq!((thb.rounds, thb.verdict), (0, Verdict::Folded));
                fell_back += 1;
            }
            true
        })
        .unwrap();
        assert_eq!(fell_back, 1);
        let Solved::Map(sol) = out else { panic!("the tensor map, got a {}", out.kind()) };
        assert_eq!(sol.report.outcome.verdict, Verdict::Certified, "{}", sol.report.outcome.message);
        assert!(sol.report.solve.repairs > 0);
        let note = sol.report.solve.thb_fallback.as_ref().expect("the THB rounds' outcome");
        assert_eq!((note.rounds, note.functions), (0, t.report.functions));
        assert!(note.offending_cells > 0);
        let v = serde_json::to_value(&sol.report).unwrap();
        assert_eq!(v["thb_fallback"]["verdict"], "folded");
        // the same tensor solve as without THB: the fallback is the tensor route's map
        let Solved::Map(direct) = Pipeline::new(b, SolveOptions::default()).solve().unwrap() else { panic!() };
        assert_eq!(direct.map.control_points, sol.map.control_points);
        assert!(serde_json::to_value(&direct.report).unwrap().get("thb_fallback").is_none());
    }
}
