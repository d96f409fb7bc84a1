//! The graded level: a nested space between two solved levels, as fine as the finer one
//! where the coarse solution's residual sits and as coarse as the coarser one elsewhere.
//!
//! A coarse solution prolonged onto the finest level (paper §6.3) is the finest level's
//! Newton start. Where the map is smooth its residual is small (quarter_annulus at
//! 918 k unknowns: scaled 5e-4), but along wavy_lid's lid the defect of the coarse
//! solution on the fine basis does not fall with `h`: the finest level starts at a scaled
//! residual of 1.4-1.9 from the level 4 times smaller and 3.5 from the level 16 times
//! smaller at every refinement, 90-98 % of `|F|²` in the rows of functions next to the
//! lid (the first interior row holds the largest entries, spread along the whole lid),
//! and Newton needs 5 to 9 steps, the first ones damped to 0.1-0.4, each a GMRES solve
//! on the whole finest level (BENCHMARKS.md "Finest-level Newton").
//!
//! The nonlinear part of that work is local. Before the finest level is solved, the
//! residual `F` of its start (eq. 8, which the finest level computes anyway) is summed
//! per basis index in each direction, `E_ξ(i) = Σ_j |F_ij|²` and `E_η(j)`; the indices
//! holding [`GRADED_ENERGY`] of the sum are kept, each function's support widened by
//! [`GRADED_MARGIN`] support widths on both sides, and the fine knots inside those
//! intervals are inserted into the coarse knot vectors. The graded space contains the
//! coarse one and is contained in the fine one (nested, so both transfers are exact knot
//! insertion); it is solved like any level, and the finest level then starts from its
//! solution with the defect already resolved at the fine scale (a nonlinear
//! elimination of the local defect, Lanzkron, Rose & Wilkes 1996, Cai & Li 2011, on a
//! tensor space): on wavy_lid the finest start falls to 0.01-0.07 and the finest level
//! takes 3 Newton steps.

use crate::boundary::hierarchy::Level;
use crate::discrete::dofs::DofMap;
use crate::error::Result;
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;

/// A finest-level start whose scaled residual is below this is left alone: quarter_annulus
/// starts at 5e-4 and male_rotor at 0.05 (2 and 3 Newton steps), wavy_lid at 1.4-3.5 and
/// puzzle4 at 1.6 from the level 16 times smaller (graded: 12-34 % and 8 % fewer CPU
/// seconds); puzzle4 at 460 k unknowns starts at 0.52 and takes 4 steps, and its graded
/// level (44 % of the finest size, 4 steps) cost 16 % more than it saved.
pub(crate) const GRADED_MIN_RESIDUAL: f64 = 1.0;

/// Share of the start's squared residual the refined indices of each direction hold.
pub(crate) const GRADED_ENERGY: f64 = 0.9;

/// Each kept function's support is widened by this many support widths on each side.
pub(crate) const GRADED_MARGIN: f64 = 1.0;

/// A graded level with more than this share of the finest level's functions is not
/// made: the residual is spread over the domain, and a level of nearly the finest size
/// costs a full solve.
pub(crate) const GRADED_MAX_SHARE: f64 = 0.6;

/// The knots of one direction of the graded level: `coarse` with the knots of `fine`
/// inserted inside the widened supports of the fine functions (indices of `fine`) whose
/// energies `energy` (one per fine function) hold the share `GRADED_ENERGY` of their sum,
/// the largest first. `None` when `coarse` is not contained in `fine` (no nested space
/// between them) or the energies are all zero.
pub(crate) fn graded_knots(coarse: &KnotVector, fine: &KnotVector, energy: &[f64], margin: f64) -> Option<KnotVector> {
    let new = fine.difference(coarse)?;
    let total: f64 = energy.iter().sum();
    if !(total > 0.0 && total.is_finite()) || new.is_empty() {
        return None;
    }
    let mut order: Vec<usize> = (0..energy.len()).collect();
    order.sort_by(|&a, &b| energy[b].total_cmp(&energy[a]));
    let (t, p) = (fine.knots(), fine.degree());
    let mut intervals = Vec::new();
    let mut held = 0.0;
    for i in order {
        if held >= GRADED_ENERGY * total {
            break;
        }
        held += energy[i];
        let (a, b) = (t[i], t[i + p + 1]);
        let w = margin * (b - a);
        intervals.push((a - w, b + w));
    }
    let inside = |u: f64| intervals.iter().any(|&(a, b)| a < u && u < b);
    let kept: Vec<f64> = new.into_iter().filter(|&u| inside(u)).collect();
    Some(coarse.with_inserted(&kept))
}

/// The graded level between `coarse` (the level solved last) and `fine` (the finest
/// level, nested: its knots contain `coarse`'s) from the residual `f = (F^x, F^y)` of the
/// finest level's start on the DOF map `dofs` of `fine`: the knots of [`graded_knots`] in
/// both directions, the sides of `coarse` refined onto them (exact knot insertion).
/// `None` when no nested level lies strictly between the two or when it would have more
/// than [`GRADED_MAX_SHARE`] of the finest level's functions.
pub(crate) fn graded_level(coarse: &Level, fine: &Level, dofs: &DofMap, f: &[f64]) -> Result<Option<Level>> {
    if coarse.knots.iter().chain(&fine.knots).any(KnotVector::is_periodic) {
        return Ok(None);
    }
    let [n0, n1] = dofs.shape();
    let m = dofs.num_free();
    let (mut e0, mut e1) = (vec![0.0; n0], vec![0.0; n1]);
    for (k, &g) in dofs.free().iter().enumerate() {
        let r2 = f[k] * f[k] + f[m + k] * f[m + k];
        e0[g % n0] += r2;
        e1[g / n0] += r2;
    }
    let knots = match (
        graded_knots(&coarse.knots[0], &fine.knots[0], &e0, GRADED_MARGIN),
        graded_knots(&coarse.knots[1], &fine.knots[1], &e1, GRADED_MARGIN),
    ) {
        (Some(a), Some(b)) => [a, b],
        _ => return Ok(None),
    };
    let size = knots[0].num_basis() * knots[1].num_basis();
    if knots == coarse.knots || knots == fine.knots || size as f64 > GRADED_MAX_SHARE * fine.num_basis() as f64 {
        return Ok(None);
    }
    let mut sides = coarse.sides.clone();
    for s in Side::ALL {
        sides[s as usize] = coarse.sides[s as usize].refined(&knots[s.direction()])?;
    }
    Ok(Some(Level { knots, sides }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The graded knots of a residual at the start of `xi` (the first two fine
    /// functions): the fine knots within the widened supports there, the coarse knots
    /// elsewhere, nested between the two; energies spread evenly refine (nearly) all of
    /// the fine vector, and none at all give no level.
    #[test]
    fn graded_knots_refine_where_the_residual_sits() {
        let (coarse, fine) = (KnotVector::open_uniform(3, 8), KnotVector::open_uniform(3, 32));
        let mut energy = vec![0.0; fine.num_basis()];
        (energy[0], energy[1], energy[20]) = (10.0, 5.0, 0.01);
        let g = graded_knots(&coarse, &fine, &energy, 1.0).unwrap();
        assert!(fine.contains(&g) && g.contains(&coarse));
        // the supports of functions 0 and 1 are [0, 1/32] and [0, 2/32]: widened by their
        // widths, [0, 4/32) takes the fine knots 1/32, 2/32, 3/32 (4/32 is a coarse knot)
        let added = g.difference(&coarse).unwrap();
        assert_eq!(added, vec![1.0 / 32.0, 2.0 / 32.0, 3.0 / 32.0]);
        // with no margin only the supports' interior knots: 1/32
        let narrow = graded_knots(&coarse, &fine, &energy, 0.0).unwrap();
        assert_eq!(narrow.difference(&coarse).unwrap(), vec![1.0 / 32.0]);
        // an even residual: every fine knot but those outside the share's supports
        let even = graded_knots(&coarse, &fine, &vec![1.0; fine.num_basis()], 1.0).unwrap();
        assert_eq!(even, fine);
        assert!(graded_knots(&coarse, &fine, &vec![0.0; fine.num_basis()], 1.0).is_none());
        // not nested: no graded level
        assert!(graded_knots(&KnotVector::open_uniform(3, 3), &fine, &energy, 1.0).is_none());
    }
}
