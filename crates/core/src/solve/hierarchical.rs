//! Local defect correction with THB-splines (paper §8.2 on a truncated hierarchical
//! basis, §4): while the certificate of the THB map finds folded or undecided active
//! cells, only those cells and a ring of active cells around them are refined
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
use crate::linalg::linsolve::LinearMethod;
use crate::methods::hierarchical::HierarchicalEggProblem;
use crate::methods::DiscreteProblem;
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::hierarchical::Index2;
use crate::verify::certificate::hierarchical::{certify_hierarchical, CellIndex, HierarchicalCertificate};
use crate::verify::certificate::{CertifyOptions, Finding};

/// Options of the THB defect correction.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ThbRepairOptions {
    /// Rounds at most.
    pub rounds: usize,
    /// Active cells within this many cell widths (of the offending cell's level) of an
    /// offending cell are refined too.
    pub ring: usize,
    /// Admissibility class `m >= 2` of the refined hierarchy.
    pub admissibility: usize,
    /// Operator of eq. (8).
    pub operator: Operator,
    /// Newton options of each round (the linear solver is sparse LU).
    pub nonlinear: NonlinearOptions,
    /// Certificate options.
    pub certify: CertifyOptions,
}

impl Default for ThbRepairOptions {
    fn default() -> Self {
        Self {
            rounds: 6,
            ring: 1,
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
    /// Active cells marked for refinement (offending ones and their ring).
    pub marked_cells: usize,
    /// THB functions after refinement.
    pub functions: usize,
    /// Free unknowns `2 m` of the round's solve.
    pub unknowns: usize,
    /// Levels after refinement.
    pub levels: usize,
    /// Newton iterations of the round's solve.
    pub iterations: usize,
    /// Whether the round's solve converged.
    pub converged: bool,
    /// Seconds of the round (refinement, solve, certificate).
    pub seconds: f64,
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

/// Solve EGG (eq. 8) on the THB discretization of `map` from its control points (the
/// fixed ones are the Dirichlet data); returns the solved map, the Newton iterations,
/// whether Newton converged and the number of unknowns.
pub(crate) fn solve_egg(
    map: &HierarchicalMap,
    operator: Operator,
    nonlinear: NonlinearOptions,
) -> Result<(HierarchicalMap, usize, bool, usize)> {
    let disc = Arc::new(HierarchicalDiscretization::new(map.basis.clone()));
    if disc.num_free() == 0 {
        return Ok((map.clone(), 0, true, 0));
    }
    let c0 = disc.gather(&map.control_points);
    let unknowns = c0.len();
    let prob = HierarchicalEggProblem::new(disc, map.control_points.clone(), operator);
    let opts = NonlinearOptions { linear: LinearMethod::Lu, ..nonlinear };
    let mut solver = NonlinearSolver::new(prob, c0, opts);
    let mut iterations = 0;
    for it in solver.by_ref() {
        iterations = it?.iteration;
    }
    let converged = solver.status() == &Status::Converged;
    let (prob, c) = solver.into_parts();
    let cps = prob.control_points(&c);
    if cps.iter().flatten().any(|x| !x.is_finite()) {
        return Err(Error::Invalid("the THB solve produced non-finite control points".into()));
    }
    Ok((HierarchicalMap::new(map.basis.clone(), cps)?, iterations, converged, unknowns))
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
    while !accepted(&cert) && rounds.len() < opts.rounds {
        let t0 = Instant::now();
        let offending = cert.offending_cells();
        let marked = marked_cells(&map, &offending, opts.ring);
        if marked.is_empty() {
            break;
        }
        let refined = map.refined(&marked, opts.admissibility)?;
        let (solved, iterations, converged, unknowns) = solve_egg(&refined, opts.operator, opts.nonlinear)?;
        map = solved;
        let verdict = cert.verdict.name();
        cert = certify_hierarchical(&map, &opts.certify)?;
        let round = ThbRound {
            round: rounds.len() + 1,
            verdict,
            offending_cells: offending.len(),
            marked_cells: marked.len(),
            functions: map.basis.len(),
            unknowns,
            levels: map.basis.num_levels(),
            iterations,
            converged,
            seconds: t0.elapsed().as_secs_f64(),
        };
        if !observer(&round) {
            return Err(Error::Cancelled);
        }
        rounds.push(round);
    }
    Ok(ThbRepair { map, certificate: cert, rounds })
}

#[cfg(test)]
mod tests;
