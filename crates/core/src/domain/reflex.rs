//! Cuts from reflex corners (issue 31; Hinz, arXiv 2406.01347, §3: concave corners are
//! removed by splitting faces): every corner of a face whose interior angle exceeds 180°
//! is cut by a straight edge into the face, along the angle's bisector to the first side
//! it meets, or from the corner to an end of that side; of these candidates that stay
//! inside the face and leave all four new corner angles below 180°, the one whose new
//! angles stay farthest from 0° and 180° is taken (the largest `min(a, 180° - a)` over
//! them, a flat part of a reflex corner left out: it is cut next). Where that is below 30° (the cut meets a
//! side at a grazing angle), straight cuts to points spread along the sides that do not
//! meet the corner are candidates too, scored alike. A cut never ends inside an edge that another face shares (that face
//! would get a 180° corner there). The worst reflex corner is cut first, until none is
//! left. A ray from a reflex corner may meet one of the corner's own (curved) sides:
//! that cut would leave a face of two corners, so the part of the side between its end
//! and the corner gets a flat corner at its arc-length midpoint, cut in turn; a flat
//! corner's cut never ends on its own sides.

use serde::Serialize;

use super::graph::{ccw_angle, end_tangent, Graph};
use super::harmonic::{polygon_vertex, ArcLength};
use super::polygon_map::{PolygonMap, POLYGON_MAP_LEVELS};
use super::validate::{inside, nearest_chord, segment_distance};
use crate::boundary::fit::{fit_side, FitOptions};
use crate::boundary::validate::sample_side;
use crate::boundary::SideCurve;
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;

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
    /// A curved cut: no straight one stays inside the face, so the cut is the preimage
    /// of a straight segment of the regular polygon under the face's map onto it
    /// (written only when true).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub curved: bool,
    /// The end was chosen among points spread along the sides, because the cuts along
    /// the bisector and the side extensions end at a sliver (written only when true).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub spread: bool,
    /// The cut ends on a side at the reflex corner (its extension or bisector meets it
    /// again), which would leave a face of two corners: the part of that side between
    /// the cut's end and the corner got a corner at its arc-length midpoint (flat, so it
    /// is cut in turn); written only when there is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub corner_added: Option<Point>,
}

/// Whether side `k` of a face of `n` corners meets its corner `i` (a cut from the corner
/// to that side would leave a face of two corners). Faces of one or two corners have no
/// such rule.
fn at_corner(n: usize, i: usize, k: usize) -> bool {
    n > 2 && (k == i || (k + 1) % n == i)
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
    segment_inside_polyline(&face_polyline(g, f), a, b, tol)
}

/// `poly` with the points `ends` on it made vertices: each that is not already one goes
/// into the chord nearest to it ([`nearest_chord`], which says why).
fn with_ends(poly: &[(Point, usize)], ends: [Point; 2]) -> Vec<(Point, usize)> {
    let mut out = poly.to_vec();
    for q in ends {
        if out.len() < 2 || out.iter().any(|x| x.0 == q) {
            continue;
        }
        let pts = vec![out.iter().map(|x| x.0).collect()];
        let nearest = nearest_chord(&pts, true, q).map_or(0, |x| x.1);
        out.insert(nearest + 1, (q, out[nearest].1));
    }
    out
}

/// [`segment_inside`] on the face's sampled boundary `poly` ([`face_polyline`]), its
/// ends made vertices of it ([`with_ends`]).
fn segment_inside_polyline(poly: &[(Point, usize)], a: Point, b: Point, tol: f64) -> bool {
    let poly = with_ends(poly, [a, b]);
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
    /// A curved cut (from the corner to `point`); `None`: the straight segment.
    curve: Option<Curve>,
    /// Its end was found among points spread along the sides ([`spread_candidates`]).
    spread: bool,
}

/// Where a cut may end: a corner of the face or a point on its side `k` at the edge
/// parameter `u`; the point; the directions there (outgoing side, reversed incoming).
type Target = (Option<usize>, Option<(usize, f64)>, Point, Point, Point);

/// Points of a curved cut's preimage polyline before its fit.
const CURVED_SAMPLES: usize = 48;

/// Boundary nodes a side of the face's map onto the polygon for curved cuts.
const CURVED_PER_SIDE: usize = 16;

/// Below this smallest new angle (radians, 30 degrees) of the best straight cut along
/// the bisector or the side extensions, straight cuts to points spread along the sides
/// ([`spread_candidates`]) are tried as well.
pub(super) const GOOD_CUT_ANGLE: f64 = std::f64::consts::PI / 6.0;

/// Points per side (at equal fractions of its arc length, ends excluded) that
/// [`spread_candidates`] tries as a cut's end.
const SPREAD_SAMPLES: usize = 32;

/// Straight cuts from corner `i` of face `f` to points spread along every side that does
/// not meet the corner (`SPREAD_SAMPLES - 1` interior points at equal fractions of its
/// arc length), for a corner whose cuts along the bisector and the side extensions end
/// at a sliver (a side met at a grazing angle): those that stay inside the face and keep
/// the rules of [`cut_reflex`], scored alike (how far the four new angles stay from 0
/// and 180 degrees). A
/// cut to a side at the corner would leave a face of two corners, so those sides are
/// skipped.
fn spread_candidates(g: &Graph, f: usize, i: usize, reflex: bool, tol: f64) -> Vec<Candidate> {
    let n = g.faces[f].sides.len();
    let poly = face_polyline(g, f);
    let o = g.vertices[g.corners(f)[i]];
    let (t_out, back) = g.corner_directions(f, i);
    let mut out = Vec::new();
    for k in 0..n {
        if k == i || (k + 1) % n == i {
            continue;
        }
        let (e, fwd) = g.faces[f].sides[k];
        let c = &g.edges[e].curve;
        let arc = ArcLength::new(c);
        for j in 1..SPREAD_SAMPLES {
            let u = arc.param(j as f64 / SPREAD_SAMPLES as f64);
            let p = c.eval(u);
            if !segment_inside_polyline(&poly, o, p, tol) {
                continue;
            }
            let mut t = end_tangent_at(c, u);
            if !fwd {
                t = [-t[0], -t[1]];
            }
            let d = [p[0] - o[0], p[1] - o[1]];
            let angles = cut_angles([t_out, back], d, [t, [-t[0], -t[1]]], [-d[0], -d[1]]);
            out.extend(Candidate::admitted(angles, reflex, (None, Some((k, u)), p), None, true));
        }
    }
    out
}

/// The four new angles of a cut (the two at the corner, then the two at its end): it
/// leaves the corner (outgoing side `t_out`, reversed incoming side `back`) along
/// `start`, and arrives at its end, whose sides go `to` and (reversed) `bj`, so that
/// `home` points from the end back along the cut.
pub(super) fn cut_angles([t_out, back]: [Point; 2], start: Point, [to, bj]: [Point; 2], home: Point) -> [f64; 4] {
    [ccw_angle(t_out, start), ccw_angle(start, back), ccw_angle(to, home), ccw_angle(home, bj)]
}

impl Candidate {
    /// The cut of `angles` ([`cut_angles`]) to `point` (a corner of the face or a point
    /// on a side), when it keeps the rules of [`admissible`], scored by [`score`].
    fn admitted(
        angles: [f64; 4],
        reflex: bool,
        (corner, on_side, point): (Option<usize>, Option<(usize, f64)>, Point),
        curve: Option<Curve>,
        spread: bool,
    ) -> Option<Self> {
        admissible(angles, reflex).then(|| Self { corner, on_side, point, score: score(angles), angles, curve, spread })
    }
}

/// The rules every cut keeps: no new reflex angle and no sliver; a flat part only where
/// the corner was reflex (it is cut next). `angles`: the two at the corner, then the two
/// at the cut's end.
fn admissible(angles: [f64; 4], reflex: bool) -> bool {
    let pi = std::f64::consts::PI;
    angles.iter().all(|&a| a > 1e-3 && a < pi + FLAT) && (reflex || (angles[0] < pi - FLAT && angles[1] < pi - FLAT))
}

/// A cut's score: how far its new angles that are not flat stay from 0 and 180 degrees,
/// `min(a, π - a)` over them (a flat one is allowed only where a reflex corner is cut
/// along a side's extension, and is cut next), rounded to `1e-9` radians so that cuts
/// equal up to rounding tie (an L's two side extensions, at 90 degrees and at 90 degrees
/// plus an ulp).
fn score(angles: [f64; 4]) -> f64 {
    let pi = std::f64::consts::PI;
    let s = angles.iter().copied().filter(|a| (a - pi).abs() > FLAT).map(|a| a.min(pi - a)).fold(pi, f64::min);
    (s * 1e9).round() * 1e-9
}

/// Whether the polyline `cut` (from the boundary of face `f` back to its boundary)
/// stays inside the face: no chord comes within `tol` of the face's boundary away from
/// the cut's two ends (the first and last hundredth of the end chords), and its middle
/// point lies inside.
pub(super) fn polyline_inside(g: &Graph, f: usize, cut: &[Point], tol: f64) -> bool {
    let poly = face_polyline(g, f);
    let n = poly.len();
    let m = cut.len() - 1;
    let e = 1e-2;
    for k in 0..m {
        let (mut a, mut b) = (cut[k], cut[k + 1]);
        if k == 0 {
            a = [a[0] + e * (b[0] - a[0]), a[1] + e * (b[1] - a[1])];
        }
        if k + 1 == m {
            b = [b[0] + e * (a[0] - b[0]), b[1] + e * (a[1] - b[1])];
        }
        if (0..n).any(|i| segment_distance(a, b, poly[i].0, poly[(i + 1) % n].0).0 <= tol) {
            return false;
        }
    }
    let pts: Vec<Point> = poly.iter().map(|x| x.0).collect();
    inside(&pts, cut[m / 2])
}

/// Curved cuts from corner `i` of face `f`, for a corner no straight cut leaves inside
/// the face: the map of the face onto the regular polygon with as many sides
/// ([`PolygonMap`], one-to-one on every face because the polygon is convex) carries the
/// corner to a vertex of the polygon, and the straight segments from it to the other
/// vertices (not its neighbours) and to the midpoints of the sides not at it, which stay
/// inside the convex polygon, are carried back: their preimages stay inside the face.
/// Each is fitted by a spline; the ones whose fit stays inside and whose four new
/// angles keep the rules of the straight cuts are the candidates, scored alike.
fn curved_candidates(g: &Graph, f: usize, i: usize, reflex: bool, diameter: f64, fit: &FitOptions) -> Vec<Candidate> {
    let tol = 1e-9 * diameter;
    let sides: Vec<Curve> = g.faces[f].sides.iter().map(|&s| g.side_curve(s)).collect();
    let n = sides.len();
    let Ok(map) = PolygonMap::new(&sides, CURVED_PER_SIDE, POLYGON_MAP_LEVELS) else { return Vec::new() };
    let corners = g.corners(f);
    let o = g.vertices[corners[i]];
    let (t_out, back) = g.corner_directions(f, i);
    // the fit scale of the face: ten times its area over its perimeter
    let poly: Vec<Point> = face_polyline(g, f).into_iter().map(|x| x.0).collect();
    let perimeter: f64 = (0..poly.len()).map(|k| dist(poly[k], poly[(k + 1) % poly.len()])).sum();
    let area = (0..poly.len())
        .map(|k| {
            let (u, v) = (poly[k], poly[(k + 1) % poly.len()]);
            u[0] * v[1] - v[0] * u[1]
        })
        .sum::<f64>()
        .abs()
        / 2.0;
    let scale = 10.0 * area / perimeter.max(f64::MIN_POSITIVE);
    let from = polygon_vertex(n, i);
    let mut targets: Vec<(Point, Target)> = Vec::new();
    for j in 0..n {
        if j != i && j != (i + 1) % n && (j + 1) % n != i {
            let (to, bj) = g.corner_directions(f, j);
            targets.push((polygon_vertex(n, j), (Some(j), None, g.vertices[corners[j]], to, bj)));
        }
        if j != i && (j + 1) % n != i {
            // the midpoint of side j: the point at half its arc length
            let (e, fwd) = g.faces[f].sides[j];
            let u_side = ArcLength::new(&sides[j]).param(0.5);
            let u = if fwd { u_side } else { 1.0 - u_side };
            let t = end_tangent_at(&sides[j], u_side);
            let q = polygon_vertex(n, j);
            let r = polygon_vertex(n, j + 1);
            targets.push((
                [0.5 * (q[0] + r[0]), 0.5 * (q[1] + r[1])],
                (None, Some((j, u)), g.edges[e].curve.eval(u), t, [-t[0], -t[1]]),
            ));
        }
    }
    let mut out = Vec::new();
    for (image, (corner, on_side, p, to, bj)) in targets {
        let pre: Option<Vec<Point>> = (0..=CURVED_SAMPLES)
            .map(|k| {
                let t = k as f64 / CURVED_SAMPLES as f64;
                map.inverse([from[0] + t * (image[0] - from[0]), from[1] + t * (image[1] - from[1])])
            })
            .collect();
        let Some(mut pts) = pre else { continue };
        pts[0] = o;
        pts[CURVED_SAMPLES] = p;
        let Ok(curve) = fit_points(&pts, diameter, scale, fit) else { continue };
        if !polyline_inside(g, f, &curve.sample(4 * CURVED_SAMPLES), tol) {
            continue;
        }
        let d0 = end_tangent(&curve, false);
        let d1 = end_tangent(&curve, true);
        let angles = cut_angles([t_out, back], d0, [to, bj], [-d1[0], -d1[1]]);
        if let Some(c) = Candidate::admitted(angles, reflex, (corner, on_side, p), Some(curve), false) {
            out.push(c);
        }
    }
    out
}

/// A spline curve through `pts` from its first to its last point (both kept exactly):
/// the straight segment when the points are on it (to `1e-9` of the diameter), else the
/// contour fit of §5 at a tenth of the fit tolerance's accuracy demand relative to
/// `scale` (the smaller of the diameter and ten times the face's area over its
/// perimeter, so that a cut through a thin face keeps to it).
pub(super) fn fit_points(pts: &[Point], diameter: f64, scale: f64, fit: &FitOptions) -> Result<Curve> {
    let (a, b) = (pts[0], pts[pts.len() - 1]);
    let l = dist(a, b);
    let off =
        |p: &Point| ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])).abs() / l.max(f64::MIN_POSITIVE);
    if pts.iter().all(|p| off(p) <= 1e-9 * diameter) {
        return Ok(line(a, b));
    }
    let opts = FitOptions { max_elements: 16, max_levels: 6, ..*fit };
    let tol = (10.0 * fit.tol).min(1e-2) * scale.min(diameter);
    Ok(fit_side(Side::South, &SideCurve::Points(pts.to_vec()), (a, b), &opts, tol)?.finest().clone())
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The unit tangent of `c` at the parameter `u` (in its direction).
fn end_tangent_at(c: &Curve, u: f64) -> Point {
    let d = c.derivs(u, 1).d1;
    let l = d[0].hypot(d[1]);
    if l > 0.0 && l.is_finite() {
        [d[0] / l, d[1] / l]
    } else {
        end_tangent(c, u > 0.5)
    }
}

/// Angles within this of 180° (radians) are flat: such a corner is cut as well.
const FLAT: f64 = 1e-6;

/// Cut every reflex and flat corner of every face (see the module documentation).
///
/// `search`: below this smallest new angle (radians) of the best cut along the bisector
/// or the side extensions, cuts to points spread along the sides are tried as well
/// ([`GOOD_CUT_ANGLE`] by default; 0: only where no such cut stays inside the face,
/// `-inf`: never, π: always).
pub(crate) fn cut_reflex(
    g: &mut Graph,
    diameter: f64,
    fit: &FitOptions,
    search: f64,
    cuts: &mut Vec<CutReport>,
) -> Result<()> {
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
                "the corner at ({:.6}, {:.6}) ({:.1} degrees) cannot be cut: no straight cut from it stays inside the face, nor a curved one (the preimages of the segments of the face's map onto the polygon)",
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
            // a cut to a side at the corner leaves a face of two corners: taken only from a
            // reflex corner, whose side part is then given a corner (see below)
            if !reflex && at_corner(n, i, k) {
                continue;
            }
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
                let angles = cut_angles([t_out, back], d, [to, bj], [-d[0], -d[1]]);
                cands.extend(Candidate::admitted(angles, reflex, (corner, on_side, p), None, false));
            }
        }
        // a sliver at the best cut's end (or none inside): cuts to points along the sides
        if cands.iter().map(|c| c.score).fold(f64::NEG_INFINITY, f64::max) < search {
            let spread: Vec<Candidate> = spread_candidates(g, f, i, reflex, tol)
                .into_iter()
                .filter(|c| !cands.iter().any(|x| x.point == c.point))
                .collect();
            cands.extend(spread);
        }
        if cands.is_empty() {
            cands = curved_candidates(g, f, i, reflex, diameter, fit);
        }
        // the largest smallest angle; a corner before a new vertex when they tie
        let Some(best) = cands
            .iter()
            .max_by(|a, b| a.score.total_cmp(&b.score).then_with(|| a.corner.is_some().cmp(&b.corner.is_some())))
        else {
            return Err(reflex_error());
        };
        let mut corner_added = None;
        let j_vertex = match (best.corner, best.on_side) {
            (Some(j), _) => corners[j],
            (None, Some((k, u))) => {
                let e = g.faces[f].sides[k].0;
                let (v, e2) = g.split_edge(e, u)?;
                if at_corner(n, i, k) {
                    // the part of the side between the cut's end and the corner would
                    // be a face of two corners: it gets a third, flat one at its
                    // arc-length midpoint, which is cut in turn
                    let part = if g.edges[e].a == o_vertex { e } else { e2 };
                    let m = ArcLength::new(&g.edges[part].curve).param(0.5);
                    let (mid, _) = g.split_edge(part, m)?;
                    corner_added = Some(g.vertices[mid]);
                }
                v
            }
            (None, None) => return Err(reflex_error()),
        };
        let now = g.corners(f);
        let (Some(ci), Some(cj)) = (now.iter().position(|&v| v == o_vertex), now.iter().position(|&v| v == j_vertex))
        else {
            return Err(reflex_error());
        };
        let p = g.vertices[j_vertex];
        let curve = match &best.curve {
            Some(c) => {
                // the exact ends: the corner and the vertex the split made
                let mut c = c.clone();
                let last = c.control_points.len() - 1;
                c.control_points[0] = o;
                c.control_points[last] = p;
                c
            }
            None => line(o, p),
        };
        let (curved, spread) = (best.curve.is_some(), best.spread);
        let cut = g.add_edge(curve, o_vertex, j_vertex, false);
        g.split_face(f, ci, cj, cut);
        cuts.push(CutReport {
            from: o,
            to: p,
            angle: alpha.to_degrees(),
            ends_on: if best.corner.is_some() { "vertex" } else { "side" },
            new_angles: best.angles.map(f64::to_degrees),
            curved,
            spread,
            corner_added,
        });
    }
    Err(Error::Domain { at: "layout".into(), reason: "more than 10000 cuts from reflex corners".into() })
}
