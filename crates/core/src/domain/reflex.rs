//! Cuts from reflex corners (issue 31; Hinz, arXiv 2406.01347, §3: concave corners are
//! removed by splitting faces): every corner of a face whose interior angle exceeds 180°
//! is cut by a straight edge into the face, along the angle's bisector to the first side
//! it meets, or from the corner to an end of that side; of these candidates that stay
//! inside the face and leave all four new corner angles below 180°, the one whose
//! smallest new angle is largest is taken. A cut never ends inside an edge that another face shares (that face
//! would get a 180° corner there). The worst reflex corner is cut first, until none is
//! left.

use serde::Serialize;

use super::graph::{ccw_angle, end_tangent, Graph};
use super::validate::{inside, segment_distance};
use crate::boundary::validate::sample_side;
use crate::boundary::SideCurve;
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;

/// A cut from a reflex corner.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct CutReport {
    /// The reflex corner.
    pub from: Point,
    /// Where the cut ends.
    pub to: Point,
    /// The corner's interior angle, degrees.
    pub angle: f64,
    /// `"vertex"` (an existing corner) or `"side"` (a new vertex on a side).
    pub ends_on: &'static str,
    /// The four corner angles the cut makes (two at each end), degrees.
    pub new_angles: [f64; 4],
}

/// The straight segment from `a` to `b` (degree 1).
pub fn line(a: Point, b: Point) -> Curve {
    Curve::polynomial(KnotVector::open_uniform(1, 1), vec![a, b])
}

/// Sampled points of every side of face `f` with the side they belong to.
fn face_polyline(g: &Graph, f: usize) -> Vec<(Point, usize)> {
    let mut out = Vec::new();
    for (k, &s) in g.faces[f].sides.iter().enumerate() {
        let p = sample_side(&SideCurve::Spline(g.side_curve(s)), f64::INFINITY);
        out.extend(p[..p.len() - 1].iter().map(|&q| (q, k)));
    }
    out
}

/// Whether the straight segment `a b` stays inside face `f` (it touches the face's
/// boundary only at its ends).
pub(super) fn segment_inside(g: &Graph, f: usize, a: Point, b: Point, tol: f64) -> bool {
    let poly = face_polyline(g, f);
    let n = poly.len();
    // the segment without its ends, which lie on the boundary
    let e = 1e-6;
    let (a1, b1) =
        ([a[0] + e * (b[0] - a[0]), a[1] + e * (b[1] - a[1])], [b[0] + e * (a[0] - b[0]), b[1] + e * (a[1] - b[1])]);
    for i in 0..n {
        let (p, q) = (poly[i].0, poly[(i + 1) % n].0);
        if segment_distance(a1, b1, p, q).0 <= tol {
            return false;
        }
    }
    let pts: Vec<Point> = poly.iter().map(|x| x.0).collect();
    inside(&pts, [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])])
}

/// The first point where the ray from `o` in direction `d` meets a side of face `f`
/// (other than at `o`): the side index, the parameter on its edge and the distance.
fn ray_hit(g: &Graph, f: usize, o: Point, d: Point, tol: f64) -> Option<(usize, f64, f64)> {
    let edges: Vec<usize> = g.faces[f].sides.iter().map(|s| s.0).collect();
    let (e, u, s) = ray_hit_edges(g, &edges, o, d, tol)?;
    Some((g.faces[f].sides.iter().position(|x| x.0 == e)?, u, s))
}

/// The first point where the ray from `o` in direction `d` meets one of `edges` (farther
/// than `tol` from `o`), on polylines of 64 chords per knot span: the edge, the parameter
/// on it and the distance.
pub(crate) fn ray_hit_edges(g: &Graph, edges: &[usize], o: Point, d: Point, tol: f64) -> Option<(usize, f64, f64)> {
    let mut best: Option<(usize, f64, f64)> = None;
    for &e in edges {
        let c = &g.edges[e].curve;
        let m = 64 * c.knots.num_elements().max(1);
        let pts = c.sample(m);
        for i in 0..m {
            let (p, q) = (pts[i], pts[i + 1]);
            let v = [q[0] - p[0], q[1] - p[1]];
            let den = d[0] * v[1] - d[1] * v[0];
            if den.abs() < 1e-300 {
                continue;
            }
            let w = [p[0] - o[0], p[1] - o[1]];
            let s = (w[0] * v[1] - w[1] * v[0]) / den;
            let t = (w[0] * d[1] - w[1] * d[0]) / den;
            if s > tol && (-1e-12..=1.0 + 1e-12).contains(&t) && best.is_none_or(|b| s < b.2) {
                best = Some((e, (i as f64 + t.clamp(0.0, 1.0)) / m as f64, s));
            }
        }
    }
    best
}

/// A candidate cut: its end (a corner of the face, or a new vertex on side `k` at the
/// edge parameter `u`), the point, its score and its four new angles.
struct Candidate {
    corner: Option<usize>,
    on_side: Option<(usize, f64)>,
    point: Point,
    score: f64,
    angles: [f64; 4],
}

/// Where a cut may end: a corner of the face or a point on its side `k` at the edge
/// parameter `u`; the point; the directions there (outgoing side, reversed incoming).
type Target = (Option<usize>, Option<(usize, f64)>, Point, Point, Point);

/// Angles within this of 180° (radians) are flat: such a corner is cut as well.
const FLAT: f64 = 1e-6;

/// Cut every reflex and flat corner of every face (see the module documentation).
pub(crate) fn cut_reflex(g: &mut Graph, diameter: f64, cuts: &mut Vec<CutReport>) -> Result<()> {
    let tol = 1e-9 * diameter;
    let pi = std::f64::consts::PI;
    for _ in 0..10_000 {
        let mut worst: Option<(usize, usize, f64)> = None;
        for f in 0..g.faces.len() {
            for i in 0..g.faces[f].sides.len() {
                let a = g.corner_angle(f, i);
                if a > pi - FLAT && worst.is_none_or(|w| a > w.2) {
                    worst = Some((f, i, a));
                }
            }
        }
        let Some((f, i, alpha)) = worst else { return Ok(()) };
        let o_vertex = g.corners(f)[i];
        let o = g.vertices[o_vertex];
        let (t_out, back) = g.corner_directions(f, i);
        let label = g.faces[f].label.clone();
        let reflex_error = || {
            Error::Domain {
            at: format!("face {f} (label {label})"),
            reason: format!(
                "the corner at ({:.6}, {:.6}) ({:.1} degrees) cannot be cut: no straight cut from it stays inside the face",
                o[0],
                o[1],
                alpha.to_degrees()
            ),
        }
        };
        let n = g.faces[f].sides.len();
        let corners = g.corners(f);
        // the bisector, and for a reflex corner the two extensions of its sides
        let reflex = alpha > pi + FLAT;
        let thetas: Vec<f64> = if reflex { vec![0.5 * alpha, alpha - pi, pi] } else { vec![0.5 * alpha] };
        let mut cands: Vec<Candidate> = Vec::new();
        for theta in thetas {
            let (c, s) = (theta.cos(), theta.sin());
            let dir = [c * t_out[0] - s * t_out[1], s * t_out[0] + c * t_out[1]];
            let Some((k, u, _)) = ray_hit(g, f, o, dir, 1e3 * tol) else { continue };
            let (e, fwd) = g.faces[f].sides[k];
            // the hit point on the side, and the two corners of that side
            let mut targets: Vec<Target> = Vec::new();
            if u > 1e-6 && u < 1.0 - 1e-6 {
                let c = &g.edges[e].curve;
                let d1 = c.derivs(u, 1).d1;
                let l = d1[0].hypot(d1[1]);
                let mut t = if l > 0.0 { [d1[0] / l, d1[1] / l] } else { end_tangent(c, false) };
                if !fwd {
                    t = [-t[0], -t[1]];
                }
                targets.push((None, Some((k, u)), c.eval(u), t, [-t[0], -t[1]]));
            }
            for j in [k, (k + 1) % n] {
                if j != i && j != (i + 1) % n && (j + 1) % n != i {
                    let (to, bj) = g.corner_directions(f, j);
                    targets.push((Some(j), None, g.vertices[corners[j]], to, bj));
                }
            }
            for (corner, on_side, p, to, bj) in targets {
                if cands.iter().any(|c| c.point == p) || !segment_inside(g, f, o, p, tol) {
                    continue;
                }
                let d = [p[0] - o[0], p[1] - o[1]];
                let a1 = ccw_angle(t_out, d);
                let a2 = ccw_angle(d, back);
                let b1 = ccw_angle(to, [-d[0], -d[1]]);
                let b2 = ccw_angle([-d[0], -d[1]], bj);
                let angles = [a1, a2, b1, b2];
                // no new reflex angle and no sliver; a flat part only where the corner
                // was reflex (it is cut next)
                let ok =
                    angles.iter().all(|&a| a > 1e-3 && a < pi + FLAT) && (reflex || (a1 < pi - FLAT && a2 < pi - FLAT));
                if ok {
                    let score = angles.iter().copied().filter(|a| (a - pi).abs() > FLAT).fold(pi, f64::min);
                    cands.push(Candidate { corner, on_side, point: p, score, angles });
                }
            }
        }
        // the largest smallest angle; a corner before a new vertex when they tie
        let Some(best) = cands
            .iter()
            .max_by(|a, b| a.score.total_cmp(&b.score).then_with(|| a.corner.is_some().cmp(&b.corner.is_some())))
        else {
            return Err(reflex_error());
        };
        let j_vertex = match (best.corner, best.on_side) {
            (Some(j), _) => corners[j],
            (None, Some((k, u))) => g.split_edge(g.faces[f].sides[k].0, u)?.0,
            (None, None) => return Err(reflex_error()),
        };
        let now = g.corners(f);
        let (Some(ci), Some(cj)) = (now.iter().position(|&v| v == o_vertex), now.iter().position(|&v| v == j_vertex))
        else {
            return Err(reflex_error());
        };
        let p = g.vertices[j_vertex];
        let cut = g.add_edge(line(o, p), o_vertex, j_vertex, false);
        g.split_face(f, ci, cj, cut);
        cuts.push(CutReport {
            from: o,
            to: p,
            angle: alpha.to_degrees(),
            ends_on: if best.corner.is_some() { "vertex" } else { "side" },
            new_angles: best.angles.map(f64::to_degrees),
        });
    }
    Err(Error::Domain { at: "layout".into(), reason: "more than 10000 cuts from reflex corners".into() })
}
