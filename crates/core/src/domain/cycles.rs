//! Closed cycles of half-edges in a [`Graph`]: the faces of a plane graph are found by
//! walking half-edges with the face to their left, turning at every vertex to the next
//! outgoing half-edge clockwise from the one just arrived along (the rotation system of
//! the embedding: outgoing half-edges ordered by the angle of their chord to a point a
//! thousandth of the way along). A cycle of positive signed area bounds a face from
//! outside; a cycle of negative area is the outer boundary of a connected component,
//! seen from outside (a hole of the face around it, or the unbounded face).

use super::graph::{FaceSide, Graph};
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};

/// The direction in which half-edge `h` leaves its start vertex: the angle of the chord
/// to the point a thousandth of the way along.
fn leave_angle(g: &Graph, h: FaceSide) -> f64 {
    let c = &g.edges[h.0].curve;
    let (a, b) = if h.1 { (c.eval(0.0), c.eval(1e-3)) } else { (c.eval(1.0), c.eval(1.0 - 1e-3)) };
    (b[1] - a[1]).atan2(b[0] - a[0])
}

/// The cycles of the half-edges `halves` (each used once), every one turning at each
/// vertex to the next half-edge of `halves` clockwise from the reversed incoming one.
/// Errors when a walk does not close (a half-edge set that is not a union of cycles).
pub fn trace(g: &Graph, halves: &[FaceSide]) -> Result<Vec<Vec<FaceSide>>> {
    let tau = 2.0 * std::f64::consts::PI;
    let mut out_of: Vec<Vec<(f64, FaceSide)>> = vec![Vec::new(); g.vertices.len()];
    for &h in halves {
        out_of[g.start(h)].push((leave_angle(g, h), h));
    }
    let index = |h: FaceSide| halves.iter().position(|&x| x == h);
    let mut used = vec![false; halves.len()];
    let mut cycles = Vec::new();
    for first in 0..halves.len() {
        if used[first] {
            continue;
        }
        let mut cycle = Vec::new();
        let mut cur = halves[first];
        for _ in 0..=halves.len() {
            let Some(i) = index(cur) else { break };
            if used[i] {
                break;
            }
            used[i] = true;
            cycle.push(cur);
            let v = g.end(cur);
            let back = leave_angle(g, (cur.0, !cur.1));
            // the smallest clockwise turn from the reversed incoming direction (a
            // half-edge back along the same edge only when there is no other)
            let next = out_of[v]
                .iter()
                .map(|&(a, h)| {
                    let mut t = (back - a).rem_euclid(tau);
                    if t <= 1e-12 || h.0 == cur.0 {
                        t += tau;
                    }
                    (t, h)
                })
                .min_by(|x, y| x.0.total_cmp(&y.0));
            match next {
                Some((_, h)) => cur = h,
                None => break,
            }
        }
        if cycle.is_empty() || g.end(cycle[cycle.len() - 1]) != g.start(cycle[0]) {
            return Err(Error::Invalid(format!(
                "the half-edges from edge {} do not close into a cycle",
                halves[first].0
            )));
        }
        cycles.push(cycle);
    }
    Ok(cycles)
}

/// A closed polyline of a cycle: every side sampled at 16 points per knot span (the
/// last point of each side left out).
pub fn polyline(g: &Graph, cycle: &[FaceSide]) -> Vec<Point> {
    let mut pts = Vec::new();
    for &(e, fwd) in cycle {
        add_samples(&mut pts, &g.edges[e].curve, fwd);
    }
    pts
}

/// [`polyline`] of a closed chain of curves, each in its own direction.
pub(crate) fn curves_polyline(curves: &[Curve]) -> Vec<Point> {
    let mut pts = Vec::new();
    for c in curves {
        add_samples(&mut pts, c, true);
    }
    pts
}

/// The samples of `c` (16 per knot span, forwards or backwards) but its last, added to `pts`.
fn add_samples(pts: &mut Vec<Point>, c: &Curve, fwd: bool) {
    let m = 16 * c.knots.num_elements().max(1);
    let mut p = c.sample(m);
    if !fwd {
        p.reverse();
    }
    pts.extend_from_slice(&p[..m]);
}

/// Signed area of a closed polyline (shoelace; positive counter-clockwise).
pub fn signed_area(p: &[Point]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i][0] * p[(i + 1) % n][1] - p[(i + 1) % n][0] * p[i][1]).sum::<f64>() * 0.5
}

/// A point just to the left of the middle of the first side of `cycle` (inside the face
/// the cycle bounds), `off` away from it.
pub(crate) fn point_left_of(g: &Graph, cycle: &[FaceSide], off: f64) -> Point {
    let (e, fwd) = cycle[0];
    let c = &g.edges[e].curve;
    let d = c.derivs(0.5, 1);
    let s = if fwd { 1.0 } else { -1.0 };
    let l = d.d1[0].hypot(d.d1[1]).max(f64::MIN_POSITIVE);
    [d.x[0] - s * off * d.d1[1] / l, d.x[1] + s * off * d.d1[0] / l]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::reflex::line;

    /// A square split by a vertical edge, with a triangle hanging inside the left half:
    /// two faces, the triangle, its outside and the outside of the whole.
    #[test]
    fn faces_of_a_split_square() {
        let mut g = Graph::default();
        let pts = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [0.0, 1.0]];
        for p in pts {
            g.add_vertex(p);
        }
        let mut edges = Vec::new();
        for k in 0..6 {
            edges.push(g.add_edge(line(pts[k], pts[(k + 1) % 6]), k, (k + 1) % 6, false));
        }
        edges.push(g.add_edge(line(pts[1], pts[4]), 1, 4, false));
        let t = [[0.2, 0.2], [0.6, 0.2], [0.4, 0.6]];
        for p in t {
            g.add_vertex(p);
        }
        for k in 0..3 {
            edges.push(g.add_edge(line(t[k], t[(k + 1) % 3]), 6 + k, 6 + (k + 1) % 3, false));
        }
        let halves: Vec<FaceSide> = edges.iter().flat_map(|&e| [(e, true), (e, false)]).collect();
        let cycles = trace(&g, &halves).unwrap();
        let mut areas: Vec<f64> = cycles.iter().map(|c| signed_area(&polyline(&g, c))).collect();
        areas.sort_by(f64::total_cmp);
        let want = [-2.0, -0.08, 0.08, 1.0, 1.0];
        assert_eq!(areas.len(), 5);
        for (a, w) in areas.iter().zip(want) {
            assert!((a - w).abs() < 1e-12, "{areas:?}");
        }
    }
}
