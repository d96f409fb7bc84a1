//! The spokes of the midpoint template (a face of `N` corners cut into `N` quads around
//! one interior vertex, [`super::template`]) and the patch corner angles they make.
//!
//! With the interior vertex `c`, the spoke `s` running from `c` to the midpoint `m_s` of
//! side `s`, `d_s` its unit tangent at `c`, `e_s` its reversed unit tangent at `m_s`
//! (pointing back into the face), and `t_s⁻`, `t_s⁺` the unit tangents of side `s`
//! arriving at and leaving `m_s`, the template makes `3N` new patch corners (the face's
//! own corners stay those of its patches):
//!
//! - at `c`, between spokes `s` and `s + 1`: `∠(d_s → d_{s+1})`;
//! - at `m_s`, in the patch before it: `∠(e_s → −t_s⁻)`, and in the patch after it:
//!   `∠(t_s⁺ → e_s)`;
//!
//! `∠(a → b)` the angle in `[0, 2π)` by which `a` turns counter-clockwise to `b`. A
//! corner near 0° or 180° makes a patch whose map degenerates there, so a placement is
//! scored by `min(α, 180° − α)` over those angles (negative for a reflex patch corner).
//!
//! Where the first placement of a face (the harmonic map's, or the map onto the polygon's)
//! scores below [`MIN_TEMPLATE_ANGLE`], the interior vertex is searched in the parameter
//! domain of the face's map onto the regular polygon ([`PolygonMap`], one-to-one on every
//! face): a point `q` of the polygon, the spokes the preimages of the straight segments
//! from `q` to the midpoints of the polygon's sides (which do not cross and stay inside
//! the face, since the polygon is convex and the map one-to-one), `q` the one whose
//! spokes score best (a polar grid, then a compass search, within 60 % of the polygon's
//! inradius of its centre, so that no spoke shrinks to nothing). The spokes' ends on the sides
//! stay the sides' arc-length midpoints, which the neighbouring faces share.

use super::graph::{ccw_angle, end_tangent};
use super::polygon_map::PolygonMap;
use crate::spline::curve::{Curve, Point};

/// Below this score (degrees: the smallest `min(α, 180° − α)` over the new patch
/// corners `α` of a face's template) the interior vertex is searched.
pub(super) const MIN_TEMPLATE_ANGLE: f64 = 15.0;

fn unit(d: Point) -> Point {
    let l = d[0].hypot(d[1]);
    if l > 0.0 {
        [d[0] / l, d[1] / l]
    } else {
        d
    }
}

fn neg(d: Point) -> Point {
    [-d[0], -d[1]]
}

fn lerp(a: Point, b: Point, t: f64) -> Point {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
}

/// The `3N` new patch corner angles (radians) of the midpoint template from the spokes'
/// unit directions `d` at the interior vertex, `e` at the side midpoints (pointing into
/// the face), and the sides' unit tangents `(t⁻, t⁺)` at their midpoints (see the module
/// documentation): per spoke `s`, the angle at the vertex between spokes `s` and `s + 1`,
/// then the two at `m_s`.
pub(super) fn midpoint_angles(d: &[Point], e: &[Point], at_mids: &[(Point, Point)]) -> Vec<f64> {
    let k = d.len();
    let mut out = Vec::with_capacity(3 * k);
    for s in 0..k {
        out.push(ccw_angle(d[s], d[(s + 1) % k]));
        out.extend(side_angles(e[s], at_mids[s]));
    }
    out
}

/// The two new patch corner angles (radians) where a cut leaves a side's midpoint into
/// the face along `e`, the side arriving along `t⁻` and leaving along `t⁺`: `∠(e → −t⁻)`
/// in the patch before the midpoint and `∠(t⁺ → e)` in the one after (they sum to `π`
/// where the side is smooth).
pub(super) fn side_angles(e: Point, (t_in, t_out): (Point, Point)) -> [f64; 2] {
    [ccw_angle(e, neg(t_in)), ccw_angle(t_out, e)]
}

/// [`midpoint_angles`] of spoke curves (each from the interior vertex to its side's
/// midpoint).
pub(super) fn curve_angles(spokes: &[Curve], at_mids: &[(Point, Point)]) -> Vec<f64> {
    let d: Vec<Point> = spokes.iter().map(|c| end_tangent(c, false)).collect();
    let e: Vec<Point> = spokes.iter().map(|c| neg(end_tangent(c, true))).collect();
    midpoint_angles(&d, &e, at_mids)
}

/// The score of a placement (degrees): the smallest `min(α, 180° − α)` over its angles.
pub(super) fn score(angles: &[f64]) -> f64 {
    angles.iter().map(|a| a.min(std::f64::consts::PI - a)).fold(f64::INFINITY, f64::min).to_degrees()
}

/// Fraction of a spoke's segment in the polygon over which its end directions are
/// estimated during the search (the chord of its preimage).
const CHORD: f64 = 1.0 / 16.0;

/// The estimated score (degrees) of the interior vertex at the polygon's point `q`: the
/// spokes' directions by the chords of the preimages of the first and last [`CHORD`] of
/// each segment; `None` where a point has no preimage (outside the polygon).
fn estimate(pm: &PolygonMap, q: Point, at_mids: &[(Point, Point)]) -> Option<f64> {
    let k = at_mids.len();
    let x = pm.inverse(q)?;
    let mut d = Vec::with_capacity(k);
    let mut e = Vec::with_capacity(k);
    for s in 0..k {
        let mid = pm.side_midpoint(s);
        let (near, m, m_near) =
            (pm.inverse(lerp(q, mid, CHORD))?, pm.inverse(mid)?, pm.inverse(lerp(q, mid, 1.0 - CHORD))?);
        d.push(unit([near[0] - x[0], near[1] - x[1]]));
        e.push(unit([m_near[0] - m[0], m_near[1] - m[1]]));
    }
    Some(score(&midpoint_angles(&d, &e, at_mids)))
}

/// How far from the polygon's centre the interior vertex is searched, as a fraction of
/// the polygon's inradius `cos(π/N)`: the angles alone would push it onto a side (a spoke
/// of length zero, a patch of zero area).
const REACH: f64 = 0.6;

/// The interior vertex searched in the polygon (see the module documentation): the
/// polygon's points on rings of radius `ρ r / 6` (`r = 0 ... 6`, `ρ` the [`REACH`] times
/// the inradius, 16 directions), then a compass search from the best (steps `ρ / 12 /
/// 2^i`, `i = 0 ... 3`) within the disc of radius `ρ`. Returns the point of the polygon
/// and its estimated score (degrees).
pub(super) fn search_centre(pm: &PolygonMap, at_mids: &[(Point, Point)]) -> Option<(Point, f64)> {
    let k = at_mids.len();
    let reach = REACH * (std::f64::consts::PI / k as f64).cos();
    let mut best: Option<(Point, f64)> = None;
    let consider = |q: Point, best: &mut Option<(Point, f64)>| {
        if q[0].hypot(q[1]) > reach * (1.0 + 1e-12) {
            return;
        }
        if let Some(v) = estimate(pm, q, at_mids) {
            if best.is_none_or(|b| v > b.1) {
                *best = Some((q, v));
            }
        }
    };
    consider([0.0, 0.0], &mut best);
    for r in 1..=6 {
        for j in 0..16 {
            let a = 2.0 * std::f64::consts::PI * j as f64 / 16.0;
            let r = reach * r as f64 / 6.0;
            consider([r * a.cos(), r * a.sin()], &mut best);
        }
    }
    let mut step = reach / 12.0;
    for _ in 0..4 {
        loop {
            let (q, v) = best?;
            for dir in [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]] {
                consider([q[0] + step * dir[0], q[1] + step * dir[1]], &mut best);
            }
            if best.is_none_or(|b| b.1 <= v) {
                break;
            }
        }
        step *= 0.5;
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Straight spokes from `(1/4, 1/2)` to the side midpoints of the unit square: the
    /// angles at the vertex are `atan 2` twice and `π − atan 2` twice; at each side
    /// midpoint the two angles sum to `π`, at `(1/2, 0)` they are `atan 2` (before) and
    /// `π − atan 2` (after).
    #[test]
    fn angles_of_straight_spokes_in_a_square() {
        let c = [0.25, 0.5];
        let mids = [[0.5, 0.0], [1.0, 0.5], [0.5, 1.0], [0.0, 0.5]];
        let d: Vec<Point> = mids.iter().map(|m| unit([m[0] - c[0], m[1] - c[1]])).collect();
        let e: Vec<Point> = d.iter().map(|&v| neg(v)).collect();
        let sides = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
        let at_mids: Vec<(Point, Point)> = sides.iter().map(|&t| (t, t)).collect();
        let a = midpoint_angles(&d, &e, &at_mids);
        let t = 2.0f64.atan();
        let pi = std::f64::consts::PI;
        // at the vertex: d0 -> d1, d1 -> d2, d2 -> d3, d3 -> d0
        for (s, want) in [t, t, pi - t, pi - t].into_iter().enumerate() {
            assert!((a[3 * s] - want).abs() < 1e-14, "vertex {s}: {} {want}", a[3 * s]);
        }
        // at (1/2, 0): atan 2 before (in the patch with the corner (0, 0)), π − atan 2 after
        assert!((a[1] - t).abs() < 1e-14 && (a[2] - (pi - t)).abs() < 1e-14, "{a:?}");
        // at (1, 1/2): the spoke is horizontal, a right angle on both sides
        assert!((a[4] - pi / 2.0).abs() < 1e-14 && (a[5] - pi / 2.0).abs() < 1e-14);
        for s in 0..4 {
            assert!((a[3 * s + 1] + a[3 * s + 2] - pi).abs() < 1e-14);
        }
        let sum: f64 = (0..4).map(|s| a[3 * s]).sum();
        assert!((sum - 2.0 * pi).abs() < 1e-13);
        // the score: every angle is atan 2, π − atan 2 or π/2, so the smallest
        // min(α, π − α) is atan 2 (63.43 degrees)
        assert!((score(&a) - t.to_degrees()).abs() < 1e-12);
    }
}
