//! Local defect correction with THB-splines (paper §8.2 on a truncated hierarchical
//! basis, §4): while the certificate of the THB map finds folded or undecided active
//! cells, only those cells and (in the first round) a ring of active cells around them
//! are refined
//! ([`HierarchicalMap::refined`], admissible of class `m`), the map is prolonged onto the
//! refined basis (exactly: the THB spaces are nested) and EGG (eq. 8) is solved again on
//! the THB discretization (`HierarchicalEggProblem`). Where a tensor repair bisects
//! whole knot spans across the patch, this one adds functions only near the defect.

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use super::newton::{NonlinearOptions, NonlinearSolver, Status};
use crate::discrete::assembly::Operator;
use crate::discrete::hierarchical::HierarchicalDiscretization;
use crate::error::{Error, Result};
use crate::methods::hierarchical::HierarchicalEggProblem;
use crate::methods::DiscreteProblem;
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::hierarchical::{HierarchicalBasis, Index2};
use crate::verify::certificate::hierarchical::{certify_hierarchical, CellIndex, HierarchicalCertificate};
use crate::verify::certificate::{CertifyOptions, Finding};

/// Options of the THB defect correction.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ThbRepairOptions {
    /// Rounds at most.
    pub rounds: usize,
    /// In the first round, active cells within this many cell widths (of the offending
    /// cell's level) of an offending cell are refined too.
    pub ring: usize,
    /// The same in every later round (default 0: the offending cells and what
    /// admissibility needs; BENCHMARKS.md "Local defect correction": with 1, puzzle4 ends
    /// with 949 functions, with 0 with 805, jigsaw01 2,076 against 1,624).
    pub later_ring: usize,
    /// Stop the rounds as soon as the offending cells have grown (in number and as a
    /// share of the active cells) in [`GROWTHS`] successive rounds ([`growing`]; the map
    /// is then not accepted): the caller starts again with
    /// a wider ring instead of paying every round of one that does not remove the folds.
    pub stop_when_growing: bool,
    /// Admissibility class `m >= 2` of the refined hierarchy.
    pub admissibility: usize,
    /// Operator of eq. (8).
    pub operator: Operator,
    /// Newton options of each round. Their linear solver as on a tensor basis: by
    /// default ([`LinearMethod::Auto`](crate::linalg::linsolve::LinearMethod::Auto))
    /// GMRES preconditioned by `-diag(K, K)`, `K` the metric Laplacian on the THB
    /// discretization (`methods::hierarchical::hierarchical_metric_laplace`), LU for small
    /// systems and where GMRES stalls;
    /// [`LinearMethod::Multigrid`](crate::linalg::linsolve::LinearMethod::Multigrid) is
    /// GMRES here (a THB space has no knot-halving transfers yet).
    pub nonlinear: NonlinearOptions,
    /// Certificate options.
    pub certify: CertifyOptions,
}

impl Default for ThbRepairOptions {
    fn default() -> Self {
        Self {
            rounds: 6,
            ring: 1,
            later_ring: 0,
            stop_when_growing: false,
            admissibility: 2,
            operator: Operator::Scaled,
            nonlinear: NonlinearOptions::default(),
            certify: CertifyOptions::default(),
        }
    }
}

/// One round of THB defect correction.
#[derive(Debug, Clone, Serialize)]
pub struct ThbRound {
    /// Round number (1-based).
    pub round: usize,
    /// Verdict of the map that was repaired.
    pub verdict: &'static str,
    /// Folded or undecided active cells.
    pub offending_cells: usize,
    /// Active cells of the map that was repaired.
    pub cells: usize,
    /// Parameter area of the offending cells (the parameter domain is the unit square).
    pub offending_area: f64,
    /// Active cells marked for refinement (offending ones and their ring).
    pub marked_cells: usize,
    /// THB functions after refinement.
    pub functions: usize,
    /// Free unknowns `2 m` of the round's solve.
    pub unknowns: usize,
    /// Levels after refinement.
    pub levels: usize,
    /// The ring of the round: active cells within this many cell widths of an offending
    /// cell were marked too.
    pub ring: usize,
    /// Newton iterations of the round's solve.
    pub iterations: usize,
    /// Whether the round's solve converged.
    pub converged: bool,
    /// Seconds of the round (refinement, solve, certificate).
    pub seconds: f64,
    /// Of `seconds`: the refinement of the basis and the prolongation of the map.
    pub refine_seconds: f64,
    /// Of `seconds`: the THB discretization (element extraction of the active cells).
    pub discretization_seconds: f64,
    /// Of `seconds`: the Newton solve on the discretization.
    pub newton_seconds: f64,
    /// Of `newton_seconds`: the residual and Jacobian assemblies.
    pub assembly_seconds: f64,
    /// Of `newton_seconds`: the linear solves (factorizations or preconditioners included).
    pub linear_seconds: f64,
    /// Of `seconds`: the certificate of the solved map.
    pub certify_seconds: f64,
}

/// The result of `repair_thb`: the last map, its certificate and the rounds.
#[derive(Debug, Clone)]
pub(crate) struct ThbRepair {
    /// The map.
    pub map: HierarchicalMap,
    /// Its certificate.
    pub certificate: HierarchicalCertificate,
    /// The rounds run.
    pub rounds: Vec<ThbRound>,
}

/// Successive rounds in which the offending cells must grow before the THB rounds are
/// abandoned for a wider ring ([`ThbRepairOptions::stop_when_growing`]).
pub(crate) const GROWTHS: usize = 2;

/// Whether the offending cells grew in each of the last `k` rounds, in number and as a
/// share of the active cells: `history` holds `(offending cells, active cells)` before
/// every round so far and now, and in its last `k + 1` entries both the count and the
/// share `offending / active` rise strictly. On the hard corpus's puzzles started from
/// the tensor map the count grows from the start (puzzle-3: 64, 101, 138, ...;
/// BENCHMARKS.md "THB on the puzzle family"): a ring of 1 then 0 pushes the folds one
/// level deeper along the necks round after round, where a ring of 2 removes them. On
/// jigsaw01 the count grows too (28, 40, 56) while the rounds refine far more cells
/// around them (64, 232 active cells: shares 0.44, 0.17), and they certify with 1,624
/// functions where the wider ring needs 2,624 (BENCHMARKS.md "THB: the contour fit's
/// basis").
pub(crate) fn growing(history: &[(usize, usize)], k: usize) -> bool {
    history.len() > k
        && history[history.len() - k - 1..].windows(2).all(|w| {
            let ((a0, c0), (a1, c1)) = (w[0], w[1]);
            a0 < a1 && a0 * c1 < a1 * c0
        })
}

/// Whether a verdict needs no repair (certified, or a degenerate corner that the boundary
/// forces).
pub fn accepted(cert: &HierarchicalCertificate) -> bool {
    matches!(cert.verdict, Finding::Certified { .. } | Finding::DegenerateCorner { .. })
}

/// The active cells of `map` to refine around `offending`: every active cell whose box
/// meets an offending cell's box widened by `ring` of that cell's widths per direction.
pub fn marked_cells(map: &HierarchicalMap, offending: &[CellIndex], ring: usize) -> Vec<(usize, Index2)> {
    let b = &map.basis;
    let boxes: Vec<[[f64; 2]; 2]> = offending
        .iter()
        .map(|o| {
            let bb = b.cell_bounds(o.level, o.cell);
            bb.map(|[lo, hi]| {
                let w = (hi - lo) * ring as f64;
                [lo - w, hi + w]
            })
        })
        .collect();
    let tiny = 1e-12;
    b.active_cells()
        .into_iter()
        .filter(|&(l, c)| {
            let cb = b.cell_bounds(l, c);
            boxes.iter().any(|ob| (0..2).all(|d| cb[d][0] < ob[d][1] - tiny && cb[d][1] > ob[d][0] + tiny))
        })
        .collect()
}

/// The parameter area of the cells `cells` of `basis`.
fn area(basis: &HierarchicalBasis, cells: &[CellIndex]) -> f64 {
    cells
        .iter()
        .map(|o| {
            let [[a, b], [c, d]] = basis.cell_bounds(o.level, o.cell);
            (b - a) * (d - c)
        })
        .sum()
}

/// A solve of EGG on a THB discretization (`solve_egg`).
#[derive(Debug, Clone)]
pub struct EggSolve {
    /// The solved map.
    pub map: HierarchicalMap,
    /// Newton iterations.
    pub iterations: usize,
    /// Whether Newton converged.
    pub converged: bool,
    /// Free unknowns `2 m`.
    pub unknowns: usize,
    /// Seconds of the discretization (element extraction).
    pub discretization_seconds: f64,
    /// Seconds of Newton's residual and Jacobian assemblies.
    pub assembly_seconds: f64,
    /// Seconds of Newton's linear solves (preconditioner or factorization included).
    pub linear_seconds: f64,
}

/// Solve EGG (eq. 8) on the THB discretization of `map` from its control points (the
/// fixed ones are the Dirichlet data), Newton's linear systems by `nonlinear.linear` (see
/// [`ThbRepairOptions::nonlinear`]).
pub(crate) fn solve_egg(map: &HierarchicalMap, operator: Operator, nonlinear: NonlinearOptions) -> Result<EggSolve> {
    let t0 = Instant::now();
    let disc = Arc::new(HierarchicalDiscretization::new(map.basis.clone()));
    solve_egg_on(map, disc, t0.elapsed().as_secs_f64(), operator, nonlinear)
}

/// [`solve_egg`] on `disc`, the discretization of `map.basis` (made in
/// `discretization_seconds`).
fn solve_egg_on(
    map: &HierarchicalMap,
    disc: Arc<HierarchicalDiscretization>,
    discretization_seconds: f64,
    operator: Operator,
    nonlinear: NonlinearOptions,
) -> Result<EggSolve> {
    if disc.num_free() == 0 {
        let map = map.clone();
        let (assembly_seconds, linear_seconds) = (0.0, 0.0);
        return Ok(EggSolve {
            map,
            iterations: 0,
            converged: true,
            unknowns: 0,
            discretization_seconds,
            assembly_seconds,
            linear_seconds,
        });
    }
    let c0 = disc.gather(&map.control_points);
    let unknowns = c0.len();
    let prob = HierarchicalEggProblem::new(disc, map.control_points.clone(), operator);
    let mut solver = NonlinearSolver::new(prob, c0, nonlinear);
    let mut iterations = 0;
    for it in solver.by_ref() {
        iterations = it?.iteration;
    }
    let (assembly_seconds, linear_seconds) =
        (solver.timings.assembly.as_secs_f64(), solver.timings.linear.as_secs_f64());
    let converged = solver.status() == &Status::Converged;
    let (prob, c) = solver.into_parts();
    let cps = prob.control_points(&c);
    if cps.iter().flatten().any(|x| !x.is_finite()) {
        return Err(Error::Invalid("the THB solve produced non-finite control points".into()));
    }
    let map = HierarchicalMap::new(map.basis.clone(), cps)?;
    Ok(EggSolve { map, iterations, converged, unknowns, discretization_seconds, assembly_seconds, linear_seconds })
}

#[cfg(test)]
/// Local defect correction of `map` (see the module documentation): at most
/// `opts.rounds` rounds; stops as soon as the certificate accepts the map, or when a
/// round has nothing to refine.
pub(crate) fn repair_thb(map: HierarchicalMap, opts: &ThbRepairOptions) -> Result<ThbRepair> {
    repair_thb_observed(map, opts, &mut |_| true)
}

/// `repair_thb`, every finished round to `observer`; [`Error::Cancelled`] when it
/// returns `false` (the pipeline's [`Stage::ThbRound`](crate::pipeline::Stage::ThbRound)).
pub(crate) fn repair_thb_observed(
    map: HierarchicalMap,
    opts: &ThbRepairOptions,
    observer: &mut dyn FnMut(&ThbRound) -> bool,
) -> Result<ThbRepair> {
    let mut map = map;
    let mut cert = certify_hierarchical(&map, &opts.certify)?;
    let mut rounds = Vec::new();
    // the last round's basis and discretization: the next one extracts only what changed
    let mut last: Option<(HierarchicalBasis, Arc<HierarchicalDiscretization>)> = None;
    // the offending cells before every round so far
    let mut history = Vec::new();
    while !accepted(&cert) && rounds.len() < opts.rounds {
        let t0 = Instant::now();
        let offending = cert.offending_cells();
        history.push((offending.len(), cert.cells));
        if opts.stop_when_growing && growing(&history, GROWTHS) {
            return Ok(ThbRepair { map, certificate: cert, rounds });
        }
        let (cells, offending_area) = (cert.cells, area(&map.basis, &offending));
        let ring = if rounds.is_empty() { opts.ring } else { opts.later_ring };
        let marked = marked_cells(&map, &offending, ring);
        if marked.is_empty() {
            break;
        }
        let refined = map.refined(&marked, opts.admissibility)?;
        let refine_seconds = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let disc = Arc::new(match &last {
            Some((before, disc)) => disc.refined(before, refined.basis.clone()),
            None => HierarchicalDiscretization::new(refined.basis.clone()),
        });
        let egg = solve_egg_on(&refined, disc.clone(), t1.elapsed().as_secs_f64(), opts.operator, opts.nonlinear)?;
        last = Some((refined.basis.clone(), disc));
        let newton_seconds = t1.elapsed().as_secs_f64() - egg.discretization_seconds;
        map = egg.map;
        let verdict = cert.verdict.name();
        let t2 = Instant::now();
        cert = certify_hierarchical(&map, &opts.certify)?;
        let certify_seconds = t2.elapsed().as_secs_f64();
        let round = ThbRound {
            round: rounds.len() + 1,
            verdict,
            offending_cells: offending.len(),
            cells,
            offending_area,
            marked_cells: marked.len(),
            functions: map.basis.len(),
            unknowns: egg.unknowns,
            levels: map.basis.num_levels(),
            ring,
            iterations: egg.iterations,
            converged: egg.converged,
            seconds: t0.elapsed().as_secs_f64(),
            refine_seconds,
            discretization_seconds: egg.discretization_seconds,
            newton_seconds,
            assembly_seconds: egg.assembly_seconds,
            linear_seconds: egg.linear_seconds,
            certify_seconds,
        };
        if !observer(&round) {
            return Err(Error::Cancelled);
        }
        rounds.push(round);
    }
    Ok(ThbRepair { map, certificate: cert, rounds })
}

pub(crate) mod contour;
pub mod improve;
#[cfg(test)]
mod tests;
