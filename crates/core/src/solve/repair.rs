//! Local defect correction (paper §8.2): while the certificate of the finest map says
//! folded or undecided, the offending elements and a halo around them are bisected, the
//! map is prolonged onto the refined basis as the initial guess and solved again,
//! optionally only for the control points near the defect.

use serde::Serialize;

use super::levels::MAX_BASIS;
use crate::boundary::hierarchy::Level;
use crate::discrete::assembly::Discretization;
use crate::discrete::dofs::{DofMap, FIXED};
use crate::discrete::topology::Topology;
use crate::error::Result;
use crate::spline::curve::Curve;
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;
use crate::verify::certificate::Certificate;

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

/// A planned repair round: the refined level, its report entry and, when only the
/// control points near the defect are solved for, their parameter boxes.
#[derive(Debug, Clone)]
pub(crate) struct Repair {
    /// The refined level to solve next.
    pub level: Level,
    /// The round's report entry.
    pub round: RepairRound,
    /// Parameter boxes `[u0, u1, v0, v1]` whose control points stay free.
    pub free_boxes: Option<Vec<[f64; 4]>>,
}

/// The defect-correction level (§8.2) after `last`, whose map has certificate `cert`:
/// the offending (folded or undecided) elements and `opts.repair.halo` spans around
/// them bisected in both directions, the sides refined exactly. `None` when nothing
/// offends or the refined basis would exceed [`MAX_BASIS`]. With `freeze = Some(r)` the
/// round also gives the parameter boxes (the offending elements widened by `r` spans)
/// whose control points stay free.
pub(crate) fn plan_repair(
    last: &Level,
    cert: &Certificate,
    round: usize,
    halo: usize,
    freeze: Option<usize>,
) -> Result<Option<Repair>> {
    let offending = cert.offending_elements();
    if offending.is_empty() {
        return Ok(None);
    }
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
        let mids: Vec<f64> = elems.iter().zip(&mark).filter(|(_, &m)| m).map(|(&(_, a, b), _)| 0.5 * (a + b)).collect();
        spans_refined[d] = mids.len();
        knots[d] = knots[d].with_inserted(&mids);
    }
    let size = knots[0].num_basis() * knots[1].num_basis();
    if size > MAX_BASIS {
        return Ok(None);
    }
    let sides = Side::ALL.map(|s| last.sides[s as usize].refined(&knots[s.direction()]));
    let sides: [Curve; 4] = sides.into_iter().collect::<Result<Vec<_>>>()?.try_into().expect("four sides");
    let round = RepairRound {
        round,
        verdict: cert.verdict.name(),
        offending_elements: offending.len(),
        spans_refined,
        shape: [knots[0].num_basis(), knots[1].num_basis()],
        elements: [knots[0].num_elements(), knots[1].num_elements()],
    };
    let free_boxes = freeze.map(|r| {
        let (ex, ey) = (last.knots[0].elements(), last.knots[1].elements());
        offending
            .iter()
            .map(|e| {
                let (i0, i1) = (e[0].saturating_sub(r), (e[0] + r).min(ex.len() - 1));
                let (j0, j1) = (e[1].saturating_sub(r), (e[1] + r).min(ey.len() - 1));
                [ex[i0].1, ex[i1].2, ey[j0].1, ey[j1].2]
            })
            .collect()
    });
    Ok(Some(Repair { level: Level { knots, sides }, round, free_boxes }))
}

/// A discretization whose free DOFs are the functions free under `topology` whose
/// support meets one of `boxes` (`[u0, u1, v0, v1]`); all free ones when that leaves
/// none (paper §8.2: fewer unknowns in a repair round), and on a periodic basis.
pub(crate) fn frozen_discretization(
    knots: &[KnotVector; 2],
    boxes: &[[f64; 4]],
    topology: &Topology,
) -> Result<Discretization> {
    let (p, q) = (knots[0].degree(), knots[1].degree());
    match frozen_dofs(knots, boxes, topology)? {
        Some(dofs) => Ok(Discretization::with_dofs(knots.clone(), p.max(q) + 1, dofs)),
        None => Discretization::for_topology(knots.clone(), topology),
    }
}

/// The DOF map of [`frozen_discretization`]: free are the functions free under
/// `topology` whose support meets one of `boxes`; `None` (all free ones) when that leaves
/// none, and on a periodic basis (which shares DOFs across the seam).
pub(crate) fn frozen_dofs(knots: &[KnotVector; 2], boxes: &[[f64; 4]], topology: &Topology) -> Result<Option<DofMap>> {
    let shape = [knots[0].num_basis(), knots[1].num_basis()];
    let (p, q) = (knots[0].degree(), knots[1].degree());
    let (tu, tv) = (knots[0].knots(), knots[1].knots());
    let all = DofMap::for_basis(knots, topology)?;
    if !all.replicas().is_empty() {
        return Ok(None);
    }
    let interior = |i: usize, j: usize| all.free_index(j * shape[0] + i) != FIXED;
    let near = |i: usize, j: usize| {
        boxes.iter().any(|b| tu[i] < b[1] && tu[i + p + 1] > b[0] && tv[j] < b[3] && tv[j + q + 1] > b[2])
    };
    let dofs = DofMap::from_predicate(shape, |i, j| interior(i, j) && near(i, j));
    Ok((dofs.num_free() > 0).then_some(dofs))
}
