//! The coarse-to-fine EGG solver (paper §6.3) as an object that yields its iterates:
//! level starts, nonlinear iterates and level summaries come out of one stream that the
//! CLI progress, the viewer's live plot and the tests all read.

use std::sync::Arc;
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::assembly::{Discretization, Operator};
use crate::boundary::Boundary;
use crate::certificate::{certify, Certificate, CertifyOptions};
use crate::curve::Curve;
use crate::egg::{CpuAssembler, EggAssembler, EggProblem};
use crate::error::{Error, Result};
use crate::fit::{build_hierarchy, FitOptions, Hierarchy, Level};
use crate::initial::{coons, displaced, elasticity_displacement_with, set_boundary};
use crate::knots::KnotVector;
use crate::newton::{Iterate, Method, NonlinearOptions, NonlinearSolver, Status};
use crate::quality::{quality, sample_det_j, Quality};
use crate::surface::{Side, Surface};

/// Options of a complete solve.
#[derive(Debug, Clone)]
pub struct SolveOptions {
    /// Contour fitting (degree, tolerance).
    pub fit: FitOptions,
    /// Nonlinear iteration on every level.
    pub nonlinear: NonlinearOptions,
    /// Operator of eq. (8), plain or scaled.
    pub operator: Operator,
    /// The finest level has at least this many elements per direction.
    pub min_elements: usize,
    /// Extra uniform halvings of the finest level.
    pub refine: usize,
    /// Solve at most this many levels (the finest is always solved).
    pub max_levels: Option<usize>,
    /// Basis growth factor between solved levels (the paper advises 4).
    pub growth: f64,
    /// Largest mean physical aspect ratio of the elements; the coarser direction of a
    /// level is halved until it is met (see [`prepare_levels`]).
    pub aspect: f64,
    /// `det J` is sampled on an `(n+1)^2` grid for the report.
    pub sample: usize,
    /// Rounds of defect correction (paper §8.2): while the certificate of the finest
    /// map says folded or undecided, refine around the offending elements and solve
    /// again, at most this many times.
    pub repair: usize,
    /// Spans around each offending element that a repair round also bisects.
    pub repair_halo: usize,
    /// When set, a repair round solves only for the control points whose support meets
    /// the offending elements widened by this many spans; the others keep the values of
    /// the prolonged map (paper §8.2: fewer unknowns).
    pub repair_freeze: Option<usize>,
    /// Options of the bijectivity certificate.
    pub certify: CertifyOptions,
    /// Run the grid-quality benchmark Q(x) of §10 on the final map.
    pub poisson: bool,
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            fit: FitOptions::default(),
            nonlinear: NonlinearOptions::default(),
            operator: Operator::Scaled,
            min_elements: 8,
            refine: 0,
            max_levels: None,
            growth: 4.0,
            aspect: 2.0,
            sample: 200,
            repair: 3,
            repair_halo: 1,
            repair_freeze: None,
            certify: CertifyOptions::default(),
            poisson: false,
        }
    }
}

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
    /// GMRES iterations over all linear solves of the level (0 with direct LU).
    pub krylov_iterations: usize,
    /// Seconds for the whole level (set-up, initial guess, iterations).
    pub seconds: f64,
}

/// One item of the solver's stream.
#[derive(Debug, Clone)]
pub enum Event {
    /// A level begins.
    LevelStarted {
        /// Index among the solved levels.
        level: usize,
        /// Number of levels that will be solved.
        levels: usize,
        /// Basis shape.
        shape: [usize; 2],
        /// Scalar unknowns.
        unknowns: usize,
        /// Initial guess.
        initial_guess: InitialGuess,
    },
    /// A nonlinear iterate.
    Iterate {
        /// Level index.
        level: usize,
        /// The iterate.
        iterate: Iterate,
    },
    /// A level is done.
    LevelFinished(LevelReport),
}

/// Angle of the domain at a corner and whether it forces `det J <= 0` there.
#[derive(Debug, Clone, Serialize)]
pub struct CornerReport {
    /// "south-west", ...
    pub corner: &'static str,
    /// Interior angle in degrees (from the fitted sides' tangents).
    pub angle_degrees: f64,
    /// `det J` at the corner equals the cross product of the two side tangents; it is
    /// `<= 0` whenever the angle is `>= 180` degrees or a tangent vanishes.
    pub forces_nonpositive_det_j: bool,
}

/// Corner angles at or above this (degrees) force `det J <= 0` up to the fit tolerance.
pub const FORCED_ANGLE: f64 = 179.0;

/// A kink inside a spline side: a break of continuity `C^0` where the tangent turns.
#[derive(Debug, Clone, Serialize)]
pub struct KinkReport {
    /// Side name.
    pub side: &'static str,
    /// Parameter on the side, in `[0, 1]`.
    pub parameter: f64,
    /// Physical point.
    pub point: [f64; 2],
    /// Turning angle of the tangent in degrees (180 for a cusp or zero speed).
    pub turning_degrees: f64,
}

/// Kinks of the input's spline sides: at every interior knot the one-sided tangent
/// directions are compared (just off the knot, so that a zero speed at the knot, as
/// with coincident control points, still shows its turn); a turn of more than one
/// degree is a kink. Any `C^1` map of the exact boundary has zero speed, so
/// `det J = 0`, at such a point; the fitted boundary rounds it within the tolerance.
pub fn boundary_kinks(boundary: &Boundary) -> Vec<KinkReport> {
    use crate::basis::BasisDerivs;
    let mut out = Vec::new();
    for s in Side::ALL {
        let crate::boundary::SideCurve::Spline(c) = boundary.side(s) else { continue };
        let bm = c.knots.breaks_with_multiplicity();
        let spans: Vec<(usize, f64, f64)> = c.knots.elements();
        for &(u, _) in &bm[1..bm.len().saturating_sub(1)] {
            let left = spans.iter().find(|e| e.2 == u);
            let right = spans.iter().find(|e| e.1 == u);
            let (Some(l), Some(r)) = (left, right) else { continue };
            // one-sided tangent directions just off the break (robust to zero speed at it)
            let mut b = BasisDerivs::default();
            let dl = {
                b.eval_in_span(&c.knots, l.0, u - 1e-9 * (l.2 - l.1), 1);
                c.derivs_with(&b, 1).d1
            };
            let dr = {
                b.eval_in_span(&c.knots, r.0, u + 1e-9 * (r.2 - r.1), 1);
                c.derivs_with(&b, 1).d1
            };
            let (sl, sr) = (dl[0].hypot(dl[1]), dr[0].hypot(dr[1]));
            let turning = if sl == 0.0 || sr == 0.0 {
                180.0
            } else {
                (dl[0] * dr[1] - dl[1] * dr[0]).atan2(dl[0] * dr[0] + dl[1] * dr[1]).to_degrees().abs()
            };
            if turning > 1.0 {
                let (a, bb) = c.domain();
                out.push(KinkReport {
                    side: s.name(),
                    parameter: (u - a) / (bb - a),
                    point: c.eval(u),
                    turning_degrees: turning,
                });
            }
        }
    }
    out
}

/// Geometry of one corner of a patch: interior angle, `x_xi x x_eta` (det J there) and
/// `|x_xi| |x_eta|`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CornerGeometry {
    pub name: &'static str,
    pub angle_degrees: f64,
    pub cross: f64,
    pub speed: f64,
}

/// The four corners (south-west, south-east, north-east, north-west) from the side
/// tangents `d(side, at_end)`: the interior angle is 180 degrees minus the turning angle
/// between the incoming and outgoing tangents of the counter-clockwise traversal (south,
/// east, reversed north, reversed west).
pub(crate) fn corner_geometry(d: impl Fn(Side, bool) -> crate::curve::Point) -> [CornerGeometry; 4] {
    // (name, x_xi, x_eta) at the corner; det J = x_xi x x_eta.
    let corners = [
        ("south-west", d(Side::South, false), d(Side::West, false)),
        ("south-east", d(Side::South, true), d(Side::East, false)),
        ("north-east", d(Side::North, true), d(Side::East, true)),
        ("north-west", d(Side::North, false), d(Side::West, true)),
    ];
    std::array::from_fn(|k| {
        let (name, a, b) = corners[k];
        let (din, dout) = match k {
            0 => ([-b[0], -b[1]], a),
            1 => (a, b),
            2 => (b, [-a[0], -a[1]]),
            _ => ([-a[0], -a[1]], [-b[0], -b[1]]),
        };
        let turn = (din[0] * dout[1] - din[1] * dout[0]).atan2(din[0] * dout[0] + din[1] * dout[1]).to_degrees();
        CornerGeometry {
            name,
            angle_degrees: 180.0 - turn,
            cross: a[0] * b[1] - a[1] * b[0],
            speed: a[0].hypot(a[1]) * b[0].hypot(b[1]),
        }
    })
}

/// Corners in the order south-west, south-east, north-east, north-west with their
/// angles, from the side curves of a level.
pub fn corner_report(sides: &[Curve; 4]) -> Vec<CornerReport> {
    let d = |s: Side, end: bool| sides[s as usize].derivs(if end { 1.0 } else { 0.0 }, 1).d1;
    corner_geometry(d)
        .into_iter()
        .map(|c| CornerReport {
            corner: c.name,
            angle_degrees: c.angle_degrees,
            // 180 degrees within the fit tolerance also counts: det J -> 0 there
            forces_nonpositive_det_j: c.speed == 0.0 || c.cross <= 1e-10 * c.speed || c.angle_degrees >= FORCED_ANGLE,
        })
        .collect()
}

/// Choose the levels to solve: from the coarsest, each next one at least `growth` times
/// larger, always ending with the finest. A level of nearly the finest's size (less than
/// [`SAME_SIZE`] times smaller) is replaced by the finest: solving twice at one size
/// costs a full solve and gains nothing. The coarsest level always stays.
pub fn select_levels(sizes: &[usize], growth: f64, max_levels: Option<usize>) -> Vec<usize> {
    let last = sizes.len() - 1;
    let mut out = vec![0];
    for (k, &s) in sizes.iter().enumerate().skip(1) {
        let previous = *out.last().expect("non-empty");
        if s as f64 >= growth * sizes[previous] as f64 {
            out.push(k);
        } else if k == last {
            if out.len() > 1 && (s as f64) < SAME_SIZE * sizes[previous] as f64 {
                out.pop();
            }
            out.push(k);
        }
    }
    if let Some(m) = max_levels {
        let m = m.max(1);
        while out.len() > m {
            out.remove(out.len() - 2);
        }
    }
    out
}

/// Size ratio below which two levels count as one size in [`select_levels`].
pub const SAME_SIZE: f64 = 1.5;

fn polyline_length(c: &Curve) -> f64 {
    let n = 16 * c.knots.num_elements().max(4);
    c.sample(n).windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum()
}

/// Two sides count as a seam (see [`prepare_levels`]) when the mean distance between
/// the other two sides exceeds their mean length by this factor.
pub const SEAM_FACTOR: f64 = 4.0;

/// Mean distance `|b(t) - a(t)|` between two opposite sides at equal parameters: the
/// mean length of the straight lines joining them, which is the extent of the domain
/// across them when the sides joining them are much shorter (a ring cut along a seam).
fn mean_gap(a: &Curve, b: &Curve) -> f64 {
    let n = 16 * a.knots.num_elements().max(b.knots.num_elements()).max(4);
    (0..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let (p, q) = (a.eval(t), b.eval(t));
            (p[0] - q[0]).hypot(p[1] - q[1])
        })
        .sum::<f64>()
        / (n + 1) as f64
}

/// Prepare the hierarchy for solving (paper §5.4 builds each level from the side fits
/// alone, so a straight side keeps a single element however fine its opposite is):
/// 1. *balance* every level, halving a direction until its elements are on average no
///    more than `aspect` times longer (physically) than those of the other direction
///    (the extent of a direction is the mean length of its two sides, or the mean
///    distance between the two other sides at equal parameters when that is more than
///    [`SEAM_FACTOR`] times larger: a ring cut open along a seam),
///    and until it has `min_elements` elements; each level then takes the union with
///    the coarser one so the hierarchy stays nested;
/// 2. append `refine` uniformly halved copies of the finest level.
///
/// Sides are refined exactly (knot insertion), so the fitted contours are unchanged.
pub fn prepare_levels(mut levels: Vec<Level>, min_elements: usize, refine: usize, aspect: f64) -> Result<Vec<Level>> {
    let last = levels.last().ok_or_else(|| Error::Invalid("empty hierarchy".into()))?;
    // mean physical length of the xi sides (south, north) and of the eta sides (west, east)
    let len_xi =
        0.5 * (polyline_length(&last.sides[Side::South as usize]) + polyline_length(&last.sides[Side::North as usize]));
    let len_eta =
        0.5 * (polyline_length(&last.sides[Side::West as usize]) + polyline_length(&last.sides[Side::East as usize]));
    // a seam (short sides joining long ones far apart) understates the extent across:
    // there the mean distance between the other two sides is used instead
    let across = |len: f64, gap: f64| if gap > SEAM_FACTOR * len { gap } else { len };
    let len_xi = across(len_xi, mean_gap(&last.sides[Side::West as usize], &last.sides[Side::East as usize]));
    let len_eta = across(len_eta, mean_gap(&last.sides[Side::South as usize], &last.sides[Side::North as usize]));
    let mut previous: Option<[KnotVector; 2]> = None;
    for level in levels.iter_mut() {
        let mut knots = level.knots.clone();
        // balance the mean physical element sizes of the two directions ...
        loop {
            let h = [len_xi / knots[0].num_elements() as f64, len_eta / knots[1].num_elements() as f64];
            let d = if h[1] > aspect * h[0] {
                1
            } else if h[0] > aspect * h[1] {
                0
            } else {
                break;
            };
            knots[d] = knots[d].halved();
        }
        // ... then give each direction its minimum number of elements
        for kv in knots.iter_mut() {
            while kv.num_elements() < min_elements {
                *kv = kv.halved();
            }
        }
        let size = knots[0].num_basis() * knots[1].num_basis();
        if size > MAX_BASIS {
            return Err(Error::TooLarge {
                context: "solver hierarchy".into(),
                what: "tensor basis size".into(),
                found: size,
                limit: MAX_BASIS,
            });
        }
        // contain the coarser level: keeps the hierarchy nested
        if let Some(prev) = &previous {
            for d in 0..2 {
                knots[d] = knots[d].union(&prev[d])?;
            }
        }
        if knots != level.knots {
            for s in Side::ALL {
                level.sides[s as usize] = level.sides[s as usize].refined(&knots[s.direction()])?;
            }
            level.knots = knots.clone();
        }
        previous = Some(knots);
    }
    for _ in 0..refine {
        let last = levels.last().expect("non-empty");
        let knots = [last.knots[0].halved(), last.knots[1].halved()];
        let mut sides = last.sides.clone();
        for s in Side::ALL {
            sides[s as usize] = sides[s as usize].refined(&knots[s.direction()])?;
        }
        levels.push(Level { knots, sides });
    }
    // levels made identical by balancing: keep the last of each run, whose sides are
    // the most accurate fits on that basis
    let mut out: Vec<Level> = Vec::with_capacity(levels.len());
    for l in levels {
        match out.last_mut() {
            Some(prev) if prev.knots == l.knots => *prev = l,
            _ => out.push(l),
        }
    }
    Ok(out)
}

/// Bookkeeping of the boundary continuation of one level.
#[derive(Debug, Default)]
struct Continuation {
    steps: usize,
    iterations: usize,
}

/// Smallest `det J` on a sample of `2 max(n_xi, n_eta)` points per direction, away
/// from the corners.
fn det_j_min(assembler: &dyn EggAssembler, disc: &Discretization, cps: &[crate::curve::Point]) -> f64 {
    let shape = disc.shape();
    let map = Surface { knots: disc.knots.clone(), control_points: cps.to_vec(), weights: None };
    assembler.sample_det_j(&map, 2 * shape[0].max(shape[1])).min_interior
}

/// A discretization whose free DOFs are the interior functions with support meeting one
/// of `boxes` (`[u0, u1, v0, v1]`); all interior ones when that leaves none.
fn frozen_discretization(knots: &[KnotVector; 2], boxes: &[[f64; 4]]) -> Discretization {
    let shape = [knots[0].num_basis(), knots[1].num_basis()];
    let (p, q) = (knots[0].degree(), knots[1].degree());
    let (tu, tv) = (knots[0].knots(), knots[1].knots());
    let interior = |i: usize, j: usize| i > 0 && j > 0 && i + 1 < shape[0] && j + 1 < shape[1];
    let near = |i: usize, j: usize| {
        boxes.iter().any(|b| tu[i] < b[1] && tu[i + p + 1] > b[0] && tv[j] < b[3] && tv[j + q + 1] > b[2])
    };
    let dofs = crate::dofs::DofMap::from_predicate(shape, |i, j| interior(i, j) && near(i, j));
    if dofs.num_free() == 0 {
        return Discretization::new(knots.clone());
    }
    Discretization::with_dofs(knots.clone(), p.max(q) + 1, dofs)
}

/// Largest tensor basis the solver accepts (about 8 million unknowns).
pub const MAX_BASIS: usize = 1 << 22;

/// Smallest fraction of the boundary displacement tried in one continuation step.
const MIN_CONTINUATION_STEP: f64 = 1.0 / 64.0;
/// Most damped boundary solves per level.
const MAX_CONTINUATION_STEPS: usize = 24;

struct Active {
    level: usize,
    solver: NonlinearSolver<EggProblem>,
    report: LevelReport,
    started: Instant,
}

/// The coarse-to-fine solver; an `Iterator` over [`Event`]s. Drop it to cancel.
pub struct EggSolver {
    plan: Vec<Level>,
    opts: SolveOptions,
    assembler: Arc<dyn EggAssembler>,
    diameter: f64,
    next_level: usize,
    active: Option<Active>,
    previous: Option<Surface>,
    reports: Vec<LevelReport>,
    started: Instant,
    failed: bool,
    repairs: usize,
    rounds: Vec<RepairRound>,
    /// Certificate of the last solved map (the finest level so far).
    certificate: Option<Certificate>,
    /// For repair levels solved with frozen DOFs: plan index and the parameter boxes
    /// `[u0, u1, v0, v1]` whose control points stay free.
    free_boxes: Vec<(usize, Vec<[f64; 4]>)>,
}

impl std::fmt::Debug for EggSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EggSolver").field("levels", &self.plan.len()).field("next_level", &self.next_level).finish()
    }
}

impl EggSolver {
    /// A solver over the levels of `hierarchy` (extended and selected by `opts`).
    pub fn new(hierarchy: &Hierarchy, opts: SolveOptions, assembler: Arc<dyn EggAssembler>) -> Result<Self> {
        let levels = prepare_levels(hierarchy.levels.clone(), opts.min_elements, opts.refine, opts.aspect)?;
        let sizes: Vec<usize> = levels.iter().map(|l| l.num_basis()).collect();
        let chosen = select_levels(&sizes, opts.growth, opts.max_levels);
        let plan = chosen.into_iter().map(|k| levels[k].clone()).collect();
        Ok(Self {
            plan,
            opts,
            assembler,
            diameter: hierarchy.diameter,
            next_level: 0,
            active: None,
            previous: None,
            reports: Vec::new(),
            started: Instant::now(),
            failed: false,
            repairs: 0,
            rounds: Vec::new(),
            certificate: None,
            free_boxes: Vec::new(),
        })
    }

    /// The levels that will be solved.
    pub fn plan(&self) -> &[Level] {
        &self.plan
    }

    /// Factor making `||F||` dimensionless: `F_i = int w_i L` with `int w_i ~ 1/m` and
    /// `L ~ diam^3` (plain) or `L / (g11 + g22) ~ diam` (scaled), so `||F|| sqrt(m)`
    /// divided by that size is the relative size of the operator's residual.
    fn residual_scale(&self, m: usize) -> f64 {
        let size = match self.opts.operator {
            Operator::Plain => self.diameter.powi(3),
            Operator::Scaled => self.diameter,
        };
        (m.max(1) as f64).sqrt() / size
    }

    /// Initial guess of a finer level (§6.3, §9): the elasticity correction of the
    /// prolonged map `base` towards the fitted boundary `target`. When that guess is not
    /// positive on a sample, the boundary displacement is damped by `alpha < 1`, the EGG
    /// equations are solved with the damped boundary from the (positive) elasticity
    /// guess, and the remaining displacement is applied from that solution, until the
    /// target contour is reached.
    fn continuation(
        &self,
        disc: &Arc<Discretization>,
        base: Vec<crate::curve::Point>,
        target: &[crate::curve::Point],
        cont: &mut Continuation,
    ) -> Result<Vec<crate::curve::Point>> {
        let tol = 1e-12 * self.diameter;
        if base.iter().zip(target).all(|(b, t)| (b[0] - t[0]).abs() <= tol && (b[1] - t[1]).abs() <= tol) {
            // same boundary (e.g. a refinement of the previous level): nothing to move
            return Ok(base);
        }
        let mut base = base;
        let (mut done, mut step) = (0.0f64, 1.0f64);
        let mut nl = self.opts.nonlinear;
        nl.scale = self.residual_scale(disc.dofs.num_free());
        nl.step_tol = self.opts.nonlinear.step_tol.max(1e-13) * self.diameter;
        // displacement from `base` to the full target; linear in the boundary motion, so
        // a fraction `f` of the remaining motion is `f * u`
        let mut u = elasticity_displacement_with(&*self.assembler, disc, &base, target)?;
        if det_j_min(&*self.assembler, disc, &base) <= 0.0 {
            // the prolonged map itself is not positive on this level's (denser) sample:
            // damping the boundary motion cannot make the guess positive, Newton starts
            // from the full elasticity guess
            return Ok(displaced(&base, &u, 1.0));
        }
        loop {
            let a = (done + step).min(1.0);
            let f = (a - done) / (1.0 - done);
            let guess = displaced(&base, &u, f);
            let positive = det_j_min(&*self.assembler, disc, &guess) > 0.0;
            let exhausted = step <= MIN_CONTINUATION_STEP || cont.steps >= MAX_CONTINUATION_STEPS;
            if a >= 1.0 && (positive || exhausted) {
                return Ok(guess);
            }
            if !positive && !exhausted {
                step *= 0.5;
                continue;
            }
            // solve with the damped boundary
            let problem = EggProblem::new(disc.clone(), guess.clone(), self.opts.operator, self.assembler.clone());
            let c0 = problem.unknowns();
            let mut solver = NonlinearSolver::new(problem, c0, nl);
            let mut iterations = 0;
            for it in solver.by_ref() {
                iterations = it?.iteration;
            }
            cont.steps += 1;
            let converged = *solver.status() == Status::Converged;
            let (problem, c) = solver.into_parts();
            let mut sol = problem.cps.clone();
            problem.disc.dofs.scatter(&c, &mut sol);
            cont.iterations += iterations;
            if converged && det_j_min(&*self.assembler, disc, &sol) > 0.0 {
                base = sol;
                done = a;
                step = (2.0 * step).min(1.0 - done).max(MIN_CONTINUATION_STEP);
                u = elasticity_displacement_with(&*self.assembler, disc, &base, target)?;
            } else if exhausted {
                return Ok(guess);
            } else {
                step *= 0.5;
            }
        }
    }

    fn start_level(&mut self, k: usize) -> Result<Event> {
        let t0 = Instant::now();
        let level = &self.plan[k];
        let disc = Arc::new(match self.free_boxes.iter().find(|(i, _)| *i == k) {
            Some((_, boxes)) => frozen_discretization(&level.knots, boxes),
            None => Discretization::new(level.knots.clone()),
        });
        let mut cont = Continuation::default();
        let (cps, guess) = match &self.previous {
            None => (coons(&level.knots, &level.sides)?, InitialGuess::Coons),
            Some(prev) => {
                let fine = prev.refined(&level.knots)?.control_points;
                let mut target = fine.clone();
                set_boundary(disc.shape(), &level.sides, &mut target)?;
                let cps = self.continuation(&disc, fine, &target, &mut cont)?;
                (cps, InitialGuess::Elasticity)
            }
        };
        let shape = disc.shape();
        let initial_det_j_min = det_j_min(&*self.assembler, &disc, &cps);
        let m = disc.dofs.num_free();
        let mut nl = self.opts.nonlinear;
        nl.scale = self.residual_scale(m);
        nl.step_tol = self.opts.nonlinear.step_tol.max(1e-13) * self.diameter;
        let problem = EggProblem::new(disc, cps, self.opts.operator, self.assembler.clone());
        let c0 = problem.unknowns();
        let solver = NonlinearSolver::new(problem, c0, nl);
        let report = LevelReport {
            level: k,
            shape,
            elements: [level.knots[0].num_elements(), level.knots[1].num_elements()],
            unknowns: 2 * m,
            initial_guess: guess,
            initial_det_j_min,
            continuation_steps: cont.steps,
            continuation_iterations: cont.iterations,
            iterations: 0,
            newton_iterations: 0,
            pseudo_time_iterations: 0,
            converged: false,
            failure: None,
            residuals: Vec::new(),
            scaled_residuals: Vec::new(),
            assembly_seconds: 0.0,
            linear_seconds: 0.0,
            krylov_iterations: 0,
            seconds: 0.0,
        };
        self.active = Some(Active { level: k, solver, report, started: t0 });
        Ok(Event::LevelStarted { level: k, levels: self.plan.len(), shape, unknowns: 2 * m, initial_guess: guess })
    }

    fn finish_level(&mut self) -> Event {
        let mut a = self.active.take().expect("active level");
        let status = a.solver.status().clone();
        a.report.converged = status == Status::Converged;
        if let Status::Failed(why) = status {
            a.report.failure = Some(why);
        }
        let timings = a.solver.timings;
        a.report.assembly_seconds = timings.assembly.as_secs_f64();
        a.report.linear_seconds = timings.linear.as_secs_f64();
        a.report.krylov_iterations = a.solver.krylov_iterations();
        a.report.seconds = a.started.elapsed().as_secs_f64();
        let (problem, c) = a.solver.into_parts();
        let mut cps = problem.cps.clone();
        problem.disc.dofs.scatter(&c, &mut cps);
        self.previous = Some(Surface { knots: problem.disc.knots.clone(), control_points: cps, weights: None });
        self.reports.push(a.report.clone());
        Event::LevelFinished(a.report)
    }

    /// Finish: the map of the finest level and the full report. Runs the remaining
    /// iterations first if the stream was not drained.
    pub fn finish(mut self, boundary: &Boundary, hierarchy: &Hierarchy) -> Result<Solution> {
        for e in self.by_ref() {
            e?;
        }
        let map = self.previous.clone().ok_or_else(|| Error::Invalid("no level was solved".into()))?;
        let certificate = match self.certificate.take() {
            Some(c) => c,
            None => certify(&map, &self.certify_options())?,
        };
        let finest = self.plan.last().expect("non-empty plan");
        let ctx = ReportContext {
            hierarchy,
            sides: &finest.sides,
            kinks: boundary_kinks(boundary),
            boundary_deviation: crate::quality::boundary_deviation(&map, boundary, 400),
            opts: &self.opts,
            backend: self.assembler.name(),
            repairs: self.repairs,
            rounds: self.rounds.clone(),
            certificate,
            elapsed: self.started.elapsed(),
        };
        Ok(Solution::new(&boundary.name, map, self.reports, ctx))
    }

    fn certify_options(&self) -> CertifyOptions {
        self.opts.certify
    }

    /// Certify the last solved map (once) and, when it folds or is undecided, plan a
    /// defect-correction level: the offending elements (and `repair_halo` spans around
    /// them) bisected in both directions. Returns `Ok(true)` when a level was added.
    fn plan_repair(&mut self) -> Result<bool> {
        let (Some(map), Some(last)) = (&self.previous, self.plan.last()) else { return Ok(false) };
        if self.certificate.is_none() {
            self.certificate = Some(certify(map, &self.certify_options())?);
        }
        let cert = self.certificate.as_ref().expect("set above");
        let offending = cert.offending_elements();
        if offending.is_empty() || self.repairs >= self.opts.repair {
            return Ok(false);
        }
        let halo = self.opts.repair_halo;
        let mut knots = last.knots.clone();
        let mut spans_refined = [0usize; 2];
        for d in 0..2 {
            let elems = last.knots[d].elements();
            let n = elems.len();
            let mut mark = vec![false; n];
            for e in &offending {
                let i = e[d];
                for k in i.saturating_sub(halo)..=(i + halo).min(n - 1) {
                    mark[k] = true;
                }
            }
            let mids: Vec<f64> =
                elems.iter().zip(&mark).filter(|(_, &m)| m).map(|(&(_, a, b), _)| 0.5 * (a + b)).collect();
            spans_refined[d] = mids.len();
            knots[d] = knots[d].with_inserted(&mids);
        }
        let size = knots[0].num_basis() * knots[1].num_basis();
        if size > MAX_BASIS {
            return Ok(false);
        }
        let sides = Side::ALL.map(|s| last.sides[s as usize].refined(&knots[s.direction()]));
        let sides: [Curve; 4] = sides.into_iter().collect::<Result<Vec<_>>>()?.try_into().expect("four sides");
        self.rounds.push(RepairRound {
            round: self.repairs + 1,
            verdict: cert.verdict.name(),
            offending_elements: offending.len(),
            spans_refined,
            shape: [knots[0].num_basis(), knots[1].num_basis()],
            elements: [knots[0].num_elements(), knots[1].num_elements()],
        });
        if let Some(r) = self.opts.repair_freeze {
            let (ex, ey) = (last.knots[0].elements(), last.knots[1].elements());
            let boxes = offending
                .iter()
                .map(|e| {
                    let (i0, i1) = (e[0].saturating_sub(r), (e[0] + r).min(ex.len() - 1));
                    let (j0, j1) = (e[1].saturating_sub(r), (e[1] + r).min(ey.len() - 1));
                    [ex[i0].1, ex[i1].2, ey[j0].1, ey[j1].2]
                })
                .collect();
            self.free_boxes.push((self.plan.len(), boxes));
        }
        self.plan.push(Level { knots, sides });
        self.repairs += 1;
        self.certificate = None;
        Ok(true)
    }
}

impl Iterator for EggSolver {
    type Item = Result<Event>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        if let Some(a) = self.active.as_mut() {
            match a.solver.step() {
                Ok(Some(it)) => {
                    a.report.residuals.push(it.residual);
                    a.report.scaled_residuals.push(it.scaled_residual);
                    if it.iteration > 0 {
                        a.report.iterations = it.iteration;
                        match it.method {
                            Method::Newton => a.report.newton_iterations += 1,
                            Method::PseudoTime => a.report.pseudo_time_iterations += 1,
                        }
                    }
                    return Some(Ok(Event::Iterate { level: a.level, iterate: it }));
                }
                Ok(None) => return Some(Ok(self.finish_level())),
                Err(e) => {
                    self.failed = true;
                    return Some(Err(e));
                }
            }
        }
        if self.next_level == self.plan.len() && !self.plan.is_empty() && self.previous.is_some() {
            // defect correction (§8.2): certify, refine around the defects, solve again
            if let Err(e) = self.plan_repair() {
                self.failed = true;
                return Some(Err(e));
            }
        }
        if self.next_level < self.plan.len() {
            let k = self.next_level;
            self.next_level += 1;
            let r = self.start_level(k);
            if r.is_err() {
                self.failed = true;
            }
            return Some(r);
        }
        None
    }
}

/// Overall outcome of a solve: the bijectivity certificate of the final map
/// ([`crate::certificate`]), unless the solver did not converge.
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

/// One round of defect correction.
#[derive(Debug, Clone, Serialize)]
pub struct RepairRound {
    /// Round number (1-based).
    pub round: usize,
    /// Certificate verdict of the map that was repaired.
    pub verdict: &'static str,
    /// Folded or undecided elements.
    pub offending_elements: usize,
    /// Spans bisected per direction (offending ones and their halo).
    pub spans_refined: [usize; 2],
    /// Basis shape after refinement.
    pub shape: [usize; 2],
    /// Elements per direction after refinement.
    pub elements: [usize; 2],
}

/// Contour-fit summary per side.
#[derive(Debug, Clone, Serialize)]
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

/// The report stored in the map file and printed by the CLI.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Crate version.
    pub version: &'static str,
    /// Assembly back end.
    pub backend: String,
    /// Degree of the map.
    pub degree: [usize; 2],
    /// Operator.
    pub operator: &'static str,
    /// Absolute fit tolerance and the diameter it is relative to.
    pub fit_tolerance: f64,
    /// Bounding-box diameter of the boundary.
    pub diameter: f64,
    /// Per-side fit summary.
    pub fit: Vec<FitReport>,
    /// Per-level summaries.
    pub levels: Vec<LevelReport>,
    /// Defect-correction rounds run because the finest map folded or was undecided.
    pub repairs: usize,
    /// Each defect-correction round.
    pub repair_rounds: Vec<RepairRound>,
    /// The bijectivity certificate of the map.
    pub certificate: Certificate,
    /// Quality functionals and cell statistics.
    pub quality: Quality,
    /// The Poisson benchmark of §10 (when asked for, and when it could be solved).
    pub poisson: Option<crate::poisson::PoissonReport>,
    /// `det J` minimum on the sample grid (corners included; the sample is additional
    /// information, the verdict comes from the certificate).
    pub det_j_min: f64,
    /// `det J` minimum away from the four corners.
    pub det_j_min_interior: f64,
    /// `det J` minimum away from the corners the boundary forces (two spans around
    /// each); the verdict is `folded` when this is not positive.
    pub det_j_min_away_from_forced_corners: f64,
    /// `det J` maximum on the sample grid.
    pub det_j_max: f64,
    /// Parameter point of the minimum.
    pub det_j_argmin: [f64; 2],
    /// Sample grid size.
    pub det_j_sample: usize,
    /// Winslow functional (eq. 15-16); `null` when `det J <= 0` at a quadrature point.
    pub winslow: Option<f64>,
    /// Area of the mapped domain.
    pub area: f64,
    /// Corner angles.
    pub corners: Vec<CornerReport>,
    /// Kinks inside the input's spline sides.
    pub kinks: Vec<KinkReport>,
    /// Largest distance of the map's boundary from the input boundary, per side
    /// (south, east, north, west).
    pub boundary_deviation: [f64; 4],
    /// The outcome.
    pub verdict: Verdict,
    /// Plain-language summary of the verdict.
    pub message: String,
    /// Total seconds.
    pub seconds: f64,
    /// Tensor-product basis functions of the map (`n_xi * n_eta`).
    pub basis_functions: usize,
    /// The boundary reparameterization (paper §7): method used and matched pairs.
    pub reparam: crate::reparam::ReparamReport,
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
pub fn min_away_from_corners(map: &Surface, s: &crate::quality::DetJSample, corners: &[CornerReport]) -> f64 {
    let span = |d: usize, at_end: bool| {
        let b = map.knots[d].breaks();
        let k = b.len();
        let w = if at_end { b[k - 1] - b[k.saturating_sub(3)] } else { b[2.min(k - 1)] - b[0] };
        w.max(0.0)
    };
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
struct ReportContext<'a> {
    hierarchy: &'a Hierarchy,
    sides: &'a [Curve; 4],
    kinks: Vec<KinkReport>,
    boundary_deviation: [f64; 4],
    opts: &'a SolveOptions,
    backend: String,
    repairs: usize,
    rounds: Vec<RepairRound>,
    certificate: Certificate,
    elapsed: Duration,
}

impl Solution {
    fn new(name: &str, map: Surface, levels: Vec<LevelReport>, ctx: ReportContext<'_>) -> Self {
        let (h, opts) = (ctx.hierarchy, ctx.opts);
        let sample = sample_det_j(&map, opts.sample);
        let quality = quality(&map);
        let fun = quality.functionals;
        let certificate = ctx.certificate;
        let corners = corner_report(ctx.sides);
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
            let v = match certificate.verdict {
                crate::certificate::Verdict::Certified { .. } => Verdict::Certified,
                crate::certificate::Verdict::DegenerateCorner { .. } => Verdict::DegenerateCorner,
                crate::certificate::Verdict::Folded { .. } => Verdict::Folded,
                crate::certificate::Verdict::Undecided { .. } => Verdict::Undecided,
            };
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
        let mut message = message;
        for k in &kinks {
            message.push_str(&format!(
                "; note: the input's {} side has a kink at ({:.6}, {:.6}) (tangent turns {:.1} degrees), where any C1 map of the \
                 exact boundary has det J = 0; this map follows the fitted boundary, which rounds the kink within the fit tolerance",
                k.side, k.point[0], k.point[1], k.turning_degrees
            ));
        }
        let fit = Side::ALL
            .iter()
            .map(|&s| {
                let f = &h.fits[s as usize];
                FitReport {
                    side: s.name(),
                    levels: f.levels.len(),
                    elements: f.levels.last().map_or(0, |c| c.knots.num_elements()),
                    max_error: f.max_error.last().copied().unwrap_or(0.0),
                    converged: f.converged,
                }
            })
            .collect();
        let report = Report {
            version: env!("CARGO_PKG_VERSION"),
            backend: ctx.backend,
            degree: map.degrees(),
            operator: match opts.operator {
                Operator::Plain => "plain",
                Operator::Scaled => "scaled",
            },
            fit_tolerance: h.tol_abs,
            diameter: h.diameter,
            fit,
            levels,
            repairs: ctx.repairs,
            repair_rounds: ctx.rounds,
            certificate,
            quality,
            poisson: if opts.poisson { crate::poisson::poisson_benchmark(&map, None).ok() } else { None },
            det_j_min: sample.min,
            det_j_min_interior: sample.min_interior,
            det_j_min_away_from_forced_corners: away,
            det_j_max: sample.max,
            det_j_argmin: sample.argmin,
            det_j_sample: sample.n,
            winslow: fun.winslow.is_finite().then_some(fun.winslow),
            area: fun.area,
            corners,
            kinks,
            boundary_deviation: ctx.boundary_deviation,
            verdict,
            message,
            seconds: ctx.elapsed.as_secs_f64(),
            basis_functions: map.knots[0].num_basis() * map.knots[1].num_basis(),
            reparam: h.reparam.clone(),
        };
        Self { name: name.to_string(), map, report }
    }
}

/// Fit the boundary, then solve coarse to fine on the CPU; drains the event stream.
pub fn solve(boundary: &Boundary, opts: &SolveOptions) -> Result<Solution> {
    let h = build_hierarchy(boundary, &opts.fit)?;
    EggSolver::new(&h, opts.clone(), Arc::new(CpuAssembler))?.finish(boundary, &h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::{Analytic, SideCurve};

    fn annulus(r0: f64, r1: f64, angle: f64) -> Boundary {
        let arc =
            move |r: f64| SideCurve::Analytic(Analytic::new(move |t| [r * (angle * t).cos(), r * (angle * t).sin()]));
        let ray = move |a: f64| {
            SideCurve::Analytic(Analytic::new(move |t| {
                [(r0 + (r1 - r0) * t) * a.cos(), (r0 + (r1 - r0) * t) * a.sin()]
            }))
        };
        // south: inner radius? use south = ray at angle 0, north = ray at `angle`,
        // west = inner arc, east = outer arc (counter-clockwise).
        Boundary { name: "annulus".into(), sides: [ray(0.0), arc(r1), ray(angle), arc(r0)] }
    }

    #[test]
    fn quarter_annulus_solves_and_is_positive() {
        let b = annulus(1.0, 2.0, std::f64::consts::FRAC_PI_2);
        let sol = solve(&b, &SolveOptions::default()).unwrap();
        let r = &sol.report;
        assert_eq!(r.verdict, Verdict::Certified, "{}", r.message);
        let last = r.levels.last().unwrap();
        assert!(last.converged && last.newton_iterations <= 5, "{last:?}");
        assert!((r.area - 0.75 * std::f64::consts::PI).abs() < 10.0 * r.fit_tolerance * r.diameter, "area {}", r.area);
    }

    #[test]
    fn level_selection_quadruples() {
        // 310 replaces 300: both would be solved at nearly one size
        assert_eq!(select_levels(&[16, 20, 64, 70, 300, 310], 4.0, None), vec![0, 2, 5]);
        assert_eq!(select_levels(&[16, 20, 64, 70, 300], 4.0, None), vec![0, 2, 4]);
        assert_eq!(select_levels(&[16, 20], 4.0, None), vec![0, 1]);
        // a finest level well above the previous one (here 1.67 times) keeps it
        assert_eq!(select_levels(&[162, 1122, 1870], 4.0, None), vec![0, 1, 2]);
        assert_eq!(select_levels(&[16], 4.0, None), vec![0]);
        assert_eq!(select_levels(&[16, 64, 256, 1024], 4.0, Some(2)), vec![0, 3]);
    }
}
