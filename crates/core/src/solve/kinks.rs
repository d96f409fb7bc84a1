//! The `C^0` route of paper §9: a map whose sides keep their kinks exactly.
//!
//! The Galerkin form (8) needs a `C^1` basis, so the solver has solved it on the smoothed
//! basis `Σ¹` (the kinks' knots at multiplicity `p - 1`, the contour projected there,
//! [`crate::boundary::kinks`]). [`keep_kinks`] then
//! 1. prolongs that map to the `C^0` basis `Σ⁰` (the kinks' knots at multiplicity `p`,
//!    joined with the knots the solve added: balancing, refinement, repair), exactly;
//! 2. imposes the difference of the boundary control points (the kinked sides against the
//!    smoothed ones) by the linear-elasticity step, with the boundary displacement damped
//!    by `α < 1` and the Winslow functional (16) minimised for each damped boundary while
//!    the full step is not certified bijective, `α` raised towards 1 from each bijective
//!    solution ([`continuation_with`], the same continuation as between levels, judged
//!    by the certificate);
//! 3. minimises the Winslow functional (16) on `Σ⁰` (it allows `C^0`, needs a bijective
//!    start: [`WinslowMethod`]) from that start, with the kinked boundary fixed;
//! 4. certifies the result. Where the minimiser is not certified, step 3 runs once more
//!    with the certified maps as its feasible set (module `certified`: every iterate the
//!    line search accepts is certified), kept where `J` falls and the certified margin
//!    `min det J / mean det J` stays at least half the start's. The map is replaced only by a certified one (the
//!    minimised map, else the certified start of step 3); otherwise the `Σ¹` map stays,
//!    with its rounded kinks, and the report says why.
//!
//! Where the full step of 2. is not certified (next to a reflex kink the harmonic map is
//! singular, `x_ξ → 0`, and a coarse basis cannot follow), the offending elements and a
//! halo are bisected as in the defect correction (§8.2), the last certified map of the
//! continuation is prolonged onto the refined basis and the continuation goes on from
//! there, at most `repair` rounds. Where neither `p + 2` nor `p + 4` Gauss points give a
//! bijective start, a third try pins the control point next to each kink inside the kink's
//! wedge (`corner_pins`): the folds left sit at the kink point itself. With the pins they
//! sit on the kink's knot line one element row in, one-sided, at every refinement: the
//! Gauss points never reach a `C^0` knot line. A last try (no pins) takes `p + 4`
//! Gauss-Lobatto points per element and direction, whose end points put the one-sided
//! limits of `det J` on every knot line, the kink points included, into the Winslow
//! barrier; where that gives none either, once more with Gauss-Lobatto points and pins.

mod certified;

use std::cell::RefCell;
use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use super::fixed_basis::{bijective, FixedBasisSolve};
use super::improve::from_bijective_start;
use super::initial::{continuation_with, set_boundary, Continuation};
use super::newton::NonlinearOptions;
use super::options::SolveOptions;
use super::repair::{frozen_dofs, plan_repair};
use crate::boundary::kinks::{Kink, KinkedLevel};
use crate::boundary::level::Level;
use crate::discrete::assembly::Discretization;
use crate::discrete::dofs::{DofMap, FIXED};
use crate::error::Result;
use crate::methods::egg::EggAssembler;
use crate::methods::winslow::{winslow_objective, WinslowMethod};
use crate::methods::Method;
use crate::spline::curve::Point;
use crate::spline::knots::KnotVector;
use crate::spline::surface::{Side, Surface};
use crate::verify::certificate::{certify, Certificate};
use certified::Certified;

/// Gauss points per direction beyond the degree in the continuation and the final
/// minimisation: the first try, and the retry where it gives no bijective start.
const QUADRATURE_EXTRA: [usize; 2] = [2, 4];

/// What the `C^0` route did (stored in the report as `c0_route`).
#[derive(Debug, Clone, Serialize)]
pub struct KinkStage {
    /// Kinks kept on the map's sides.
    pub kinks: usize,
    /// Functions of the smoothed basis `Σ¹` the EGG map was solved on.
    pub smoothed_functions: usize,
    /// Functions of the `C^0` basis `Σ⁰`.
    pub functions: usize,
    /// Largest distance between a boundary control point of the prolonged `Σ¹` map and
    /// its `Σ⁰` target, relative to the diameter (what the elasticity step imposes).
    pub boundary_shift: f64,
    /// Damped-boundary Winslow solves (`α < 1`) before the full boundary.
    pub continuation_steps: usize,
    /// Newton iterations spent in them.
    pub continuation_iterations: usize,
    /// Rounds of local refinement (§8.2) around elements where the continuation's full
    /// step was not certified (at most the solve's `repair`).
    pub refinements: usize,
    /// The largest fraction of the boundary displacement reached by a certified map (1
    /// when the kinks were reached).
    pub alpha: f64,
    /// Newton iterations of the final Winslow minimisation.
    pub iterations: usize,
    /// Its unknowns (`2 x` the control points it moves: all interior ones, or with
    /// `kinks_local` those near the kinks).
    pub unknowns: usize,
    /// The knot spans around each kink it moved (`kinks_local`), `None` when all.
    pub local_spans: Option<usize>,
    /// Newton iterations of the rerun of the final minimisation whose line search accepts
    /// only certified maps (module `kinks::certified`; absent: not run, the unconstrained
    /// minimiser was certified).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub certified_rerun: Option<usize>,
    /// Whether it met its stopping rule.
    pub converged: bool,
    /// Winslow value (eq. 16) of its start and of its result (`null` where undefined).
    pub winslow: [Option<f64>; 2],
    /// Whether the map with the kinks replaced the `Σ¹` map (certified).
    pub kept: bool,
    /// The certificate's sentence on the `Σ⁰` map.
    pub certificate: String,
    /// Why the kinks were not kept, when they were not.
    pub failure: Option<String>,
    /// Seconds for the stage.
    pub seconds: f64,
    /// Plain-language summary.
    pub message: String,
}

impl KinkStage {
    /// The stage not yet run: `kinked` on `functions` functions (from `smoothed_functions`
    /// of the smoothed basis), nothing done.
    fn new(kinked: &KinkedLevel, smoothed_functions: usize, functions: usize) -> Self {
        Self {
            kinks: kinked.kinks.len(),
            smoothed_functions,
            functions,
            boundary_shift: 0.0,
            continuation_steps: 0,
            continuation_iterations: 0,
            refinements: 0,
            alpha: 0.0,
            iterations: 0,
            unknowns: 0,
            local_spans: None,
            certified_rerun: None,
            converged: false,
            winslow: [None, None],
            kept: false,
            certificate: String::new(),
            failure: None,
            seconds: 0.0,
            message: String::new(),
        }
    }

    /// The record of a route that did not run (the `Σ¹` map is not a bijective start).
    pub fn skipped(kinked: &KinkedLevel, smoothed_functions: usize, why: String) -> Self {
        let message = format!("kinks not kept: {why}; the map is the one on the smoothed basis Σ¹");
        Self { failure: Some(why), message, ..Self::new(kinked, smoothed_functions, kinked.level.num_basis()) }
    }
}

/// The outcome of [`keep_kinks`]: the map with the kinks and its certificate when kept.
#[derive(Debug, Clone)]
pub(crate) struct KinkOutcome {
    /// The certified `Σ⁰` map (`None`: not kept).
    pub map: Option<Surface>,
    /// Its certificate.
    pub certificate: Option<Certificate>,
    /// Its level (basis and sides).
    pub level: Option<Level>,
    /// The stage report.
    pub report: KinkStage,
}

/// The `Σ⁰` level `c0` joined with the knots of `map` (the `Σ¹` map, which may hold
/// knots of repair rounds): the sides refined onto the union.
fn joined_level(map: &Surface, c0: &Level) -> Result<Level> {
    let knots = [map.knots[0].union(&c0.knots[0])?, map.knots[1].union(&c0.knots[1])?];
    let mut sides = c0.sides.clone();
    for s in Side::ALL {
        sides[s as usize] = sides[s as usize].refined(&knots[s.direction()])?;
    }
    Ok(Level { knots, sides })
}

/// The `C^0` route (module documentation) from the `Σ¹` map `map`, certified bijective,
/// to the `C^0` level `c0` (the kinks `kinked` at multiplicity `p`): the map on `Σ⁰` with
/// the kinks kept exactly, certified, or why not.
pub(crate) fn keep_kinks(
    map: &Surface,
    c0: &Level,
    kinked: &KinkedLevel,
    opts: &SolveOptions,
    assembler: &dyn EggAssembler,
    diameter: f64,
) -> Result<KinkOutcome> {
    let t0 = Instant::now();
    let mut report = KinkStage::new(kinked, map.knots[0].num_basis() * map.knots[1].num_basis(), c0.num_basis());
    // `p + 2` Gauss points per direction first (as every other solve); where that gives no
    // bijective start, once more from the Σ¹ map with `p + 4`: the Winslow barrier (16) only
    // sees det J at the quadrature points, and next to a reflex kink of a narrow V-notch
    // (tests/data/cad_kinks/vnotch.json: 332 degrees inside) the damped minimisers with
    // p + 2 points folded between them at 0.77 of the boundary displacement whatever the
    // refinement, while p + 4 reach the kinked boundary with no refinement
    // where that gives none either, a third try from the Σ¹ map with p + 4 and the control
    // point next to each kink pinned inside the kink's wedge ([`corner_pins`]): the
    // Winslow barrier does not see `det J` at the kink itself, where the folds sit;
    // where the folds then sit on the kink's knot line one element row in (one-sided: cad-
    // kinks seeds 23 and 24 of the corpus), a last try with Gauss-Lobatto points, which
    // put the knot lines' one-sided limits into the barrier, first without the pins (with
    // them seed 24 still folded), then with them (without them seed 5 folded)
    let tries = [
        Try { extra: QUADRATURE_EXTRA[0], pinned: false, lobatto: false },
        Try { extra: QUADRATURE_EXTRA[1], pinned: false, lobatto: false },
        Try { extra: QUADRATURE_EXTRA[1], pinned: true, lobatto: false },
        Try { extra: QUADRATURE_EXTRA[1], pinned: false, lobatto: true },
        Try { extra: QUADRATURE_EXTRA[1], pinned: true, lobatto: true },
    ];
    let mut first = elasticity_start(map, c0, tries[0], &[], opts, assembler, diameter, &mut report)?;
    let (mut chosen, mut retried, mut spent) = (tries[0], String::new(), Continuation::default());
    let mut failed = vec![(tries[0], first.cont.steps, report.refinements, report.alpha)];
    for &next in &tries[1..] {
        if bijective(&first.cert) {
            break;
        }
        let mut again = report.clone();
        let pinned: &[Kink] = if next.pinned { &kinked.kinks } else { &[] };
        let attempt = elasticity_start(map, c0, next, pinned, opts, assembler, diameter, &mut again)?;
        spent.steps += attempt.cont.steps;
        spent.iterations += attempt.cont.iterations;
        if !bijective(&attempt.cert) {
            failed.push((next, attempt.cont.steps, again.refinements, again.alpha));
            continue;
        }
        retried = match (next.pinned, next.lobatto) {
            (false, false) => format!(
                "; p + {} Gauss points per direction, since p + {} gave no bijective start ({} damped solves, {:.3} \
                 of the boundary displacement reached)",
                next.extra, tries[0].extra, first.cont.steps, report.alpha
            ),
            _ => format!("; {}, since {}", next.describe(), tried_text(&failed)),
        };
        report = again;
        let earlier = first.cont;
        first = attempt;
        first.cont.steps = earlier.steps + spent.steps;
        first.cont.iterations = earlier.iterations + spent.iterations;
        chosen = next;
    }
    let ElasticityStart { level, disc, weights, start, cert: start_cert, cont } = first;
    let [p, q] = map.degrees();
    let method = WinslowMethod;
    report.functions = level.num_basis();
    report.continuation_steps = cont.steps;
    report.continuation_iterations = cont.iterations;
    let surface =
        |cps: &[Point]| Surface { knots: level.knots.clone(), control_points: cps.to_vec(), weights: weights.clone() };
    let finite = |j: f64| j.is_finite().then_some(j);
    if !bijective(&start_cert) {
        report.winslow[0] = finite(winslow_objective(&disc, &start));
        let why = format!(
            "the elasticity step to the kinked boundary ({} damped Winslow solves, {} refinement round(s), {:.3} of the \
             boundary displacement reached with a certified map) gave no bijective start: {}",
            cont.steps,
            report.refinements,
            report.alpha,
            start_cert.message()
        );
        let why = match failed.len() {
            1 => why,
            _ => format!("{why}; tried {}", tried_text(&failed)),
        };
        report.certificate = start_cert.message();
        report.message = format!("kinks not kept: {why}; the map is the one on the smoothed basis Σ¹");
        report.failure = Some(why);
        report.seconds = t0.elapsed().as_secs_f64();
        return Ok(KinkOutcome { map: None, certificate: None, level: None, report });
    }
    // §9, last paragraph: only the control points near the kinks move (`kinks_local`)
    let spans = opts.kinks_local.spans(2 * disc.dofs.num_free());
    let boxes = spans.map(|spans| kink_boxes(&level.knots, &kinked.kinks, spans));
    let local = match &boxes {
        Some(b) => frozen_dofs(&level.knots, b, &opts.topology)?,
        None => None,
    };
    let moved = match local {
        Some(dofs) => {
            Arc::new(chosen.discretization(level.knots.clone(), p.max(q), dofs).with_weights(weights.clone())?)
        }
        None => disc.clone(),
    };
    report.unknowns = 2 * moved.dofs.num_free();
    report.local_spans = spans;
    let nl = from_bijective_start(opts.nonlinear, &method, diameter, moved.dofs.num_free());
    let solved = FixedBasisSolve::new(&method, moved.clone(), start.clone(), nl).finish()?;
    report.iterations = solved.history.iterations;
    report.converged = solved.converged();
    report.failure = solved.failure().map(|why| format!("Winslow minimisation: {why}"));
    // `J` on the same knots and quadrature as `disc` (the DOF map does not change it)
    report.winslow = [solved.start_objective.and_then(finite), solved.objective.and_then(finite)];
    let cert = certify(&surface(&solved.control_points), &opts.certify)?;
    let minimised = solved.control_points;
    let (cps, cert, which) = if bijective(&cert) {
        (minimised, cert, "the Winslow minimiser")
    } else {
        // once more from the start with the certified maps as the feasible set: every
        // iterate the line search accepts is certified, so the last one is a certified
        // map with `J` no larger than the start's ([`Certified`])
        let problem =
            Certified::new(method.problem(moved.clone(), start.clone()), moved.clone(), weights.clone(), opts.certify);
        let rerun = FixedBasisSolve::with_problem(problem, moved.dofs.gather(&start), nl).finish()?;
        let rerun_cert = certify(&surface(&rerun.control_points), &opts.certify)?;
        report.certified_rerun = Some(rerun.history.iterations);
        let lower = matches!((rerun.objective, rerun.start_objective), (Some(a), Some(b)) if a < b);
        // a constrained minimiser may hug `det J = 0` where the functional (16) does not
        // see it (on contour_l_shape: a lower bound of 1e-11 against the start's 1.6e-3):
        // kept only with at least half the start's relative margin `min det J / mean det J`
        let margin = |c: &Certificate| c.lower_bound / c.mean_det_j;
        let margin_kept = margin(&rerun_cert) >= 0.5 * margin(&start_cert);
        if bijective(&rerun_cert) && lower && margin_kept {
            report.winslow[1] = rerun.objective.and_then(finite);
            report.converged = rerun.converged();
            report.failure =
                rerun.failure().map(|why| format!("Winslow minimisation within the certified maps: {why}"));
            (rerun.control_points, rerun_cert, "the Winslow minimiser within the certified maps")
        } else {
            (start, start_cert, "the certified elasticity start (the Winslow minimiser is not certified)")
        }
    };
    report.kept = true;
    report.certificate = cert.message();
    report.message = format!(
        "{} kink(s) kept exactly: {which} on the C0 basis ({} functions, from the smoothed {}; boundary moved by \
         {:.3e} of the diameter, {} damped step(s), {} refinement round(s){retried})",
        report.kinks,
        report.functions,
        report.smoothed_functions,
        report.boundary_shift,
        cont.steps,
        report.refinements
    );
    report.seconds = t0.elapsed().as_secs_f64();
    let map = surface(&cps);
    Ok(KinkOutcome { map: Some(map), certificate: Some(cert), level: Some(level), report })
}

/// One try of [`keep_kinks`]: `p + extra` quadrature points per element and direction,
/// Gauss-Lobatto (the element edges sampled) or Gauss-Legendre, and the control points
/// next to the kinks pinned ([`corner_pins`]) or not.
#[derive(Debug, Clone, Copy)]
struct Try {
    extra: usize,
    pinned: bool,
    lobatto: bool,
}

impl Try {
    /// The try in words.
    fn describe(self) -> String {
        let rule = if self.lobatto { "Gauss-Lobatto" } else { "Gauss" };
        let every = if self.pinned { " with the control points next to the kinks pinned" } else { "" };
        format!("p + {} {rule} points per direction{every}", self.extra)
    }

    /// The discretization of this try on `knots` of largest degree `p`.
    fn discretization(self, knots: [KnotVector; 2], p: usize, dofs: DofMap) -> Discretization {
        match self.lobatto {
            true => Discretization::with_dofs_lobatto(knots, p + self.extra, dofs),
            false => Discretization::with_dofs(knots, p + self.extra, dofs),
        }
    }
}

/// The tries of [`keep_kinks`] that gave no bijective start, `(try, damped solves,
/// refinement rounds, α reached)`, in words.
fn tried_text(failed: &[(Try, usize, usize, f64)]) -> String {
    let text = |&(t, steps, rounds, alpha): &(Try, usize, usize, f64)| {
        format!(
            "{} ({steps} damped solves, {rounds} refinement round(s), {alpha:.3} of the boundary displacement \
             reached)",
            t.describe()
        )
    };
    failed.iter().map(text).collect::<Vec<_>>().join(", ")
}

/// What [`elasticity_start`] returns: the level, discretization, weights and control
/// points of the start of the final minimisation, its certificate and the continuation's
/// counts.
struct ElasticityStart {
    level: Level,
    disc: Arc<Discretization>,
    weights: Option<Vec<f64>>,
    start: Vec<Point>,
    cert: Certificate,
    cont: Continuation,
}

/// Step 2 of the module documentation from the `Σ¹` map `map` to the `Σ⁰` level `c0`,
/// with `p + extra` Gauss points per direction (in the elasticity step, the damped Winslow
/// solves and the discretization returned), with the control points next to the kinks
/// of `pinned` fixed inside the kinks' wedges ([`corner_pins`]); `report` gets
/// `boundary_shift`, `refinements` and `alpha`.
#[allow(clippy::too_many_arguments)]
fn elasticity_start(
    map: &Surface,
    c0: &Level,
    t: Try,
    pinned: &[Kink],
    opts: &SolveOptions,
    assembler: &dyn EggAssembler,
    diameter: f64,
    report: &mut KinkStage,
) -> Result<ElasticityStart> {
    let mut level = joined_level(map, c0)?;
    let mut base = map.refined(&level.knots)?.control_points;
    let [p, q] = map.degrees();
    let mut cont = Continuation::default();
    report.refinements = 0;
    report.alpha = 0.0;
    // the damped elasticity continuation to the kinked boundary; where its full step is
    // not certified, the offending elements are bisected (§8.2) and it goes on from the
    // last certified map, prolonged
    let (disc, weights, start, cert) = loop {
        let weights = level.weights()?;
        let mut dofs = DofMap::for_basis(&level.knots, &opts.topology)?;
        let mut target = base.clone();
        set_boundary(dofs.shape(), &level.sides, &mut target)?;
        let pins = match dofs.replicas().is_empty() {
            true => corner_pins(&level.knots, pinned, &base, &target),
            false => Vec::new(),
        };
        if !pins.is_empty() {
            let nx = dofs.shape()[0];
            let all = dofs;
            dofs = DofMap::from_predicate(all.shape(), |i, j| {
                all.free_index(j * nx + i) != FIXED && !pins.iter().any(|&(k, _)| k == j * nx + i)
            });
            for &(k, x) in &pins {
                target[k] = x;
            }
        }
        let disc = Arc::new(t.discretization(level.knots.clone(), p.max(q), dofs).with_weights(weights.clone())?);
        if report.refinements == 0 {
            report.boundary_shift =
                base.iter().zip(&target).fold(0.0f64, |d, (a, b)| d.max((a[0] - b[0]).hypot(a[1] - b[1]))) / diameter;
        }
        let surface = |cps: &[Point]| Surface {
            knots: level.knots.clone(),
            control_points: cps.to_vec(),
            weights: weights.clone(),
        };
        // the continuation's last certificate, reused for its guess below
        let last: RefCell<Option<(Vec<Point>, Certificate)>> = RefCell::new(None);
        let positive = |cps: &[Point]| match certify(&surface(cps), &opts.certify) {
            Ok(c) => {
                let ok = bijective(&c);
                *last.borrow_mut() = Some((cps.to_vec(), c));
                ok
            }
            Err(_) => false,
        };
        // no extrapolated steps in the continuation: a damped solve must stay well inside
        // the bijective maps for the next boundary increment, and a step up to three times
        // the Newton step's length, feasible at the quadrature points only, folded
        // l_shape's map between them (the continuation then ran 35 damped solves and 6
        // refinement rounds and gave up at 0.8 of the boundary displacement)
        let method = WinslowMethod;
        let nl = NonlinearOptions {
            extrapolate: false,
            ..from_bijective_start(opts.nonlinear, &method, diameter, disc.dofs.num_free())
        };
        // the damped steps are counted per round (the cap of the continuation is per basis)
        let mut round = Continuation::default();
        let out = continuation_with(&method, assembler, &disc, base, &target, nl, diameter, &mut round, &positive)?;
        cont.steps += round.steps;
        cont.iterations += round.iterations;
        report.alpha = report.alpha.max(out.alpha);
        let cert = match last.take() {
            Some((cps, c)) if cps == out.guess => c,
            _ => certify(&surface(&out.guess), &opts.certify)?,
        };
        if bijective(&cert) || report.refinements >= opts.repair.rounds {
            break (disc, weights, out.guess, cert);
        }
        let Some(r) = plan_repair(&level, &cert, report.refinements + 1, opts.repair.halo, None)? else {
            break (disc, weights, out.guess, cert);
        };
        let reached = surface(&out.base);
        level = r.level;
        base = reached.refined(&level.knots)?.control_points;
        report.refinements += 1;
    };
    Ok(ElasticityStart { level, disc, weights, start, cert, cont })
}

/// The control point next to each kink (one row into the domain from the kink's boundary
/// control point, which the `C^0` knot of multiplicity `p` makes interpolating) with a
/// position inside the kink's wedge: at the kink `det J` from either side is
/// `det(t_∓, x_across)` up to the orientation, with `t_∓` the side's one-sided tangents
/// and `x_across ∝ P_1 - P_0`, so both are positive when `P_1 - P_0` points along
/// `n_- + n_+` (the unit left normals of the tangents, for the south and east sides; the
/// opposite for north and west: `det(t_∓, n_- + n_+) = 1 + cos θ > 0` for a turn `θ`
/// other than ±180°). `P_1` keeps its distance from `P_0` in `base`; `target` holds the
/// kinked sides. Pairs `(control point index, position)`.
fn corner_pins(knots: &[KnotVector; 2], kinks: &[Kink], base: &[Point], target: &[Point]) -> Vec<(usize, Point)> {
    let (nx, ny) = (knots[0].num_basis(), knots[1].num_basis());
    let greville = [knots[0].greville(), knots[1].greville()];
    let unit = |v: Point| {
        let l = v[0].hypot(v[1]);
        [v[0] / l, v[1] / l]
    };
    kinks
        .iter()
        .filter_map(|k| {
            let t = k.map_parameter?;
            let d = k.side.direction();
            let g = &greville[d];
            let i = (0..g.len()).min_by(|&a, &b| (g[a] - t).abs().total_cmp(&(g[b] - t).abs()))?;
            if i == 0 || i + 1 >= g.len() {
                return None;
            }
            // the index of the control point `along` on the side and `across` rows in
            let at = |along: usize, across: usize| match k.side {
                Side::South => across * nx + along,
                Side::North => (ny - 1 - across) * nx + along,
                Side::West => along * nx + across,
                Side::East => along * nx + nx - 1 - across,
            };
            let (a, b, c) = (target[at(i - 1, 0)], target[at(i, 0)], target[at(i + 1, 0)]);
            let (t0, t1) = (unit([b[0] - a[0], b[1] - a[1]]), unit([c[0] - b[0], c[1] - b[1]]));
            let sign = match k.side {
                Side::South | Side::East => 1.0,
                Side::North | Side::West => -1.0,
            };
            let v = unit([sign * (-t0[1] - t1[1]), sign * (t0[0] + t1[0])]);
            let (p0, p1) = (base[at(i, 0)], base[at(i, 1)]);
            let l = (p1[0] - p0[0]).hypot(p1[1] - p0[1]);
            (v[0].is_finite() && v[1].is_finite()).then(|| (at(i, 1), [b[0] + l * v[0], b[1] + l * v[1]]))
        })
        .collect()
}

/// The parameter boxes `[ξ0, ξ1, η0, η1]` reaching `spans` knot spans of `knots` along
/// the side on either side of each kink and `spans` spans into the domain (the control
/// points whose support meets one are those "in the vicinity of the boundary control
/// points that correspond to the C0-continuities", §9).
fn kink_boxes(knots: &[KnotVector; 2], kinks: &[Kink], spans: usize) -> Vec<[f64; 4]> {
    let breaks = [knots[0].breaks(), knots[1].breaks()];
    kinks
        .iter()
        .filter_map(|k| {
            let t = k.map_parameter?;
            let d = k.side.direction();
            let (along, across) = (&breaks[d], &breaks[1 - d]);
            let (n, m) = (along.len() - 1, across.len() - 1);
            let i = along.partition_point(|&b| b < t).min(n);
            let (lo, hi) = (along[i.saturating_sub(spans)], along[(i + spans).min(n)]);
            let (c0, c1) = match k.side {
                Side::South | Side::West => (across[0], across[spans.min(m)]),
                Side::North | Side::East => (across[m.saturating_sub(spans)], across[m]),
            };
            Some(if d == 0 { [lo, hi, c0, c1] } else { [c0, c1, lo, hi] })
        })
        .collect()
}

/// Distance from `x` to the curve `c`: the closest of 32 samples per element, refined by
/// golden-section search around it.
fn distance_to_curve(c: &crate::spline::curve::Curve, x: Point) -> f64 {
    let d = |t: f64| {
        let y = c.eval(t);
        (y[0] - x[0]).hypot(y[1] - x[1])
    };
    let (lo, hi) = c.domain();
    let mut best = (f64::INFINITY, lo, 0.0);
    for (_, a, b) in c.knots.elements() {
        let h = (b - a) / 32.0;
        for k in 0..=32 {
            let t = a + h * k as f64;
            let v = d(t);
            if v < best.0 {
                best = (v, t, h);
            }
        }
    }
    let (mut a, mut b) = ((best.1 - best.2).max(lo), (best.1 + best.2).min(hi));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (u, v) = (b - g * (b - a), a + g * (b - a));
        if d(u) < d(v) {
            b = v;
        } else {
            a = u;
        }
    }
    best.0.min(d(0.5 * (a + b)))
}

/// The kinks of the report: those the hierarchy keeps (`kept` says whether the `C^0`
/// route kept them on `map`) and those it detected with the thresholds of `--kinks auto`
/// ([`Hierarchy::detected`](crate::boundary::hierarchy::Hierarchy::detected)) but nothing
/// keeps (rounded, their points those of `boundary`'s sides), each with the distance of
/// `map` (in the input's coordinates, like `boundary`) from the point.
pub(crate) fn kink_reports(
    boundary: &crate::boundary::Boundary,
    h: &crate::boundary::hierarchy::Hierarchy,
    map: &Surface,
    kept: bool,
) -> Vec<crate::boundary::corners::KinkReport> {
    use crate::boundary::kinks::Kink;
    let kept_list: &[Kink] = h.kinked.as_ref().map_or(&[], |k| &k.kinks);
    let entry = |k: &Kink, point: Point, kept: bool| {
        let side = map.boundary(k.side);
        let at = if kept { k.map_parameter } else { None };
        let deviation = match at {
            Some(t) => {
                let y = side.eval(t);
                (y[0] - point[0]).hypot(y[1] - point[1])
            }
            None => distance_to_curve(&side, point),
        };
        crate::boundary::corners::KinkReport {
            side: k.side.name(),
            parameter: k.parameter,
            point,
            turning_degrees: k.turning_degrees,
            kind: k.kind,
            kept,
            map_parameter: at,
            deviation,
        }
    };
    let mut out: Vec<_> = kept_list.iter().map(|k| entry(k, h.similarity.to_physical(k.point), kept)).collect();
    for k in &h.detected {
        if !kept_list.iter().any(|x| x.side == k.side && (x.parameter - k.parameter).abs() <= 1e-12) {
            let point = k.point_on(boundary).unwrap_or_else(|| h.similarity.to_physical(k.point));
            out.push(entry(k, point, false));
        }
    }
    let side = |name: &str| Side::ALL.iter().position(|s| s.name() == name);
    out.sort_by(|a, b| side(a.side).cmp(&side(b.side)).then(a.parameter.total_cmp(&b.parameter)));
    out
}

#[cfg(test)]
mod tests {
    use super::corner_pins;
    use crate::boundary::kinks::{Kink, KinkKind};
    use crate::spline::curve::Point;
    use crate::spline::knots::KnotVector;
    use crate::spline::surface::Surface;

    /// A degree-2 net on `[0, 1]²` (a `C^0` knot at `ξ = 1/2`, the greville grid) whose
    /// south side turns at `(1/2, 0)` by `turn` degrees (down and back for a reflex kink,
    /// up for a convex one): where the control point above the kink leaves `det J` of one
    /// element at the kink non-positive, the pinned one makes it positive from both sides,
    /// `det(t_∓, x_η) > 0` at the kink evaluated on the map itself, at the same distance
    /// from the kink.
    #[test]
    fn pinned_control_point_makes_det_j_positive_at_the_kink() {
        let knots =
            [KnotVector::new(2, vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0]).unwrap(), KnotVector::open_uniform(2, 2)];
        let (gu, gv) = (knots[0].greville(), knots[1].greville());
        for turn in [-100.0f64, -152.0, -60.0, 40.0] {
            let mut cps: Vec<Point> = gv.iter().flat_map(|&v| gu.iter().map(move |&u| [u, v])).collect();
            // P1 on the incoming line, P3 leaving the kink at `turn` from east
            let a = turn.to_radians();
            cps[3] = [0.5 + 0.25 * a.cos(), 0.25 * a.sin()];
            let det_at_kink = |cps: &[Point]| {
                let m = Surface { knots: knots.clone(), control_points: cps.to_vec(), weights: None };
                [m.derivs(0.5 - 1e-9, 0.0, 1).det_j(), m.derivs(0.5 + 1e-9, 0.0, 1).det_j()]
            };
            let kink = Kink {
                side: crate::spline::surface::Side::South,
                parameter: 0.5,
                point: [0.5, 0.0],
                turning_degrees: turn.abs(),
                kind: KinkKind::C0Knot,
                index: None,
                map_parameter: Some(0.5),
            };
            let pins = corner_pins(&knots, &[kink], &cps, &cps);
            assert_eq!(pins.len(), 1);
            let (k, x) = pins[0];
            assert_eq!(k, gu.len() + 2, "the control point above the kink");
            let before = det_at_kink(&cps);
            let l = |p: Point| (p[0] - 0.5).hypot(p[1]);
            assert!((l(x) - l(cps[k])).abs() <= 1e-14);
            cps[k] = x;
            let after = det_at_kink(&cps);
            assert!(after.iter().all(|&d| d > 0.0), "turn {turn}: det J {after:?} (before {before:?})");
            if turn < -90.0 {
                assert!(before.iter().any(|&d| d <= 0.0), "turn {turn}: det J {before:?} already positive");
            }
        }
    }

    use crate::boundary::families::Family;
    use crate::io::{read_boundary, ReadOptions};
    use crate::pipeline::solve;
    use crate::solve::options::SolveOptions;
    use crate::solve::report::Verdict;
    use crate::spline::surface::Side;
    use crate::testutil::data;

    /// A V-notch pointing into the unit square (degree 2, C0 knots at its base and tip; the
    /// tip a reflex kink of 332 degrees inside): certified with its three kinks kept, the
    /// map's boundary the input side to rounding (the continuation with `p + 2` Gauss points
    /// stalled at 0.77 of the boundary displacement; the retry with `p + 4` reaches it), and
    /// the same for two notches on one side.
    #[test]
    fn v_notches_keep_their_kinks_and_certify() {
        for (name, kinks) in [("vnotch", 3), ("two_notches", 6)] {
            let b = read_boundary(&data(&format!("cad_kinks/{name}.json")), &ReadOptions::default()).unwrap();
            let sol = solve(&b, &SolveOptions::default()).unwrap();
            let r = &sol.report;
            assert_eq!(r.outcome.verdict, Verdict::Certified, "{name}: {}", r.outcome.message);
            let c0 = r.boundary.c0_route.as_ref().expect("the C0 route ran");
            assert!(c0.kept && c0.kinks == kinks, "{name}: {}", c0.message);
            assert_eq!(r.boundary.kinks.len(), kinks);
            for k in &r.boundary.kinks {
                assert!(k.kept && k.deviation <= 1e-12, "{name}: {k:?}");
            }
            // the whole boundary, kinks included, is the input's to rounding
            assert!(r.boundary.deviation.iter().all(|&d| d <= 1e-12), "{name}: {:?}", r.boundary.deviation);
        }
    }

    /// Two domains of the `cad-kinks` family the route keeps (seed 2: a V-notch into the
    /// domain and one out of it; seed 17: one into it): certified, and at every kink's
    /// knot line the map's side passes through the input's `C^0` knot point to rounding,
    /// and its one-sided tangents there (chords of `1e-7` in the parameter; the pieces are
    /// straight) turn by the input's angle: a kink of the map, not a rounding.
    #[test]
    fn generated_kinks_keep_their_points_and_angles() {
        for seed in [2, 17] {
            let b = Family::CadKinks.generate(seed);
            let sol = solve(&b, &SolveOptions::default()).unwrap();
            let r = &sol.report;
            assert_eq!(r.outcome.verdict, Verdict::Certified, "seed {seed}: {}", r.outcome.message);
            assert!(r.kinks_kept() && r.success() && r.boundary.kinks.len() >= 3, "seed {seed}: {}", r.outcome.message);
            for k in &r.boundary.kinks {
                let side = Side::ALL.into_iter().find(|s| s.name() == k.side).unwrap();
                let curve = sol.map.boundary(side);
                let t = k.map_parameter.expect("a kept kink has its knot line");
                let y = curve.eval(t);
                assert!((y[0] - k.point[0]).hypot(y[1] - k.point[1]) <= 1e-12, "seed {seed}: {k:?} at {y:?}");
                let (a, c) = (curve.eval(t - 1e-7), curve.eval(t + 1e-7));
                let (d0, d1) = ([y[0] - a[0], y[1] - a[1]], [c[0] - y[0], c[1] - y[1]]);
                let turn = (d0[0] * d1[1] - d0[1] * d1[0]).atan2(d0[0] * d1[0] + d0[1] * d1[1]).abs().to_degrees();
                assert!((turn - k.turning_degrees).abs() <= 1e-4, "seed {seed}: turns {turn}, input {k:?}");
            }
        }
    }
}
