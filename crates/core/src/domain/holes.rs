//! Holes cut away (issue 31): a face with holes becomes simply connected faces by
//! straight cuts along one direction `d` (horizontal below; the layout tries several,
//! [`super::template`]). From the leftmost and the rightmost point of every hole (the
//! middle of the part of the hole within 2 % of its width of the extreme, so that the
//! middle of a vertical side is taken rather than its ends; an existing vertex within 5
//! % of the width is taken instead of a new one) a cut runs left, resp. right, to the
//! first edge it meets: the outer boundary or another hole (or an earlier cut). Every
//! right cut ends further right than it starts, so following right cuts from any hole
//! reaches the outer boundary: the cuts join every hole to it, and `h` holes give `h + 1`
//! faces (fewer where two cuts coincide), each bounded by one cycle and found by
//! [`super::cycles::trace`]. A cut ends at an existing vertex when the point it meets is
//! within a tenth of the cut's length of one (and the straight segment to that vertex
//! crosses nothing), else at a new vertex on the edge it meets.

use serde::Serialize;

use super::cycles::{polyline, signed_area, trace};
use super::graph::{FaceSide, Graph};
use super::reflex::{line, ray_hit_edges};
use super::validate::{nearest_chord, segment_distance};
use crate::error::{Error, Result};
use crate::spline::curve::Point;

/// A cut from a hole.
#[derive(Debug, Clone, Serialize)]
pub struct HoleCut {
    /// The face (label) and the hole, `"LABEL, hole K"`.
    pub hole: String,
    /// Where it starts (on the hole).
    pub from: Point,
    /// Where it ends.
    pub to: Point,
    /// `"vertex"` (an existing vertex) or `"side"` (a new vertex on an edge).
    pub ends_on: &'static str,
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Whether the straight segment `a b` meets none of `edges` except at its ends: on the
/// edges' polylines (16 chords per knot span) with `a` and `b` made vertices of them
/// first ([`nearest_chord`]: a cut's end on a curved edge lies on the curve, and where
/// the edge bulges away from the cut, the chord there passes between them).
fn segment_clear(g: &Graph, edges: &[usize], a: Point, b: Point, tol: f64) -> bool {
    let mut lines: Vec<Vec<Point>> = edges
        .iter()
        .map(|&k| {
            let c = &g.edges[k].curve;
            c.sample(16 * c.knots.num_elements().max(1))
        })
        .collect();
    for q in [a, b] {
        if lines.iter().any(|l| l.contains(&q)) {
            continue;
        }
        if let Some((l, i)) = nearest_chord(&lines, false, q) {
            lines[l].insert(i + 1, q);
        }
    }
    let e = 1e-6;
    let a1 = [a[0] + e * (b[0] - a[0]), a[1] + e * (b[1] - a[1])];
    let b1 = [b[0] + e * (a[0] - b[0]), b[1] + e * (a[1] - b[1])];
    lines.iter().all(|p| p.windows(2).all(|w| segment_distance(a1, b1, w[0], w[1]).0 > tol))
}

/// The vertex of hole `k` of face `f` from which the cut in direction `dir` (`-1`: left,
/// `1`: right) starts (a new one on an edge when no vertex is near the extreme).
fn extreme_vertex(g: &mut Graph, f: usize, k: usize, dir: f64, d: Point) -> Result<usize> {
    let cycle = g.faces[f].holes[k].clone();
    // samples in cycle order: (edge, parameter, point)
    let mut samples: Vec<(usize, f64, Point)> = Vec::new();
    for &(e, fwd) in &cycle {
        let c = &g.edges[e].curve;
        let m = 64 * c.knots.num_elements().max(1);
        for j in 0..m {
            let t = j as f64 / m as f64;
            let u = if fwd { t } else { 1.0 - t };
            samples.push((e, u, c.eval(u)));
        }
    }
    let along = |p: Point| p[0] * d[0] + p[1] * d[1];
    let xs = samples.iter().map(|s| along(s.2));
    let width = xs.clone().fold(f64::NEG_INFINITY, f64::max) - xs.fold(f64::INFINITY, f64::min);
    let best = samples.iter().map(|s| dir * along(s.2)).fold(f64::NEG_INFINITY, f64::max);
    let near: Vec<bool> = samples.iter().map(|s| dir * along(s.2) >= best - 0.02 * width).collect();
    // the longest run of near samples (cyclically), and its middle
    let n = samples.len();
    let start = (0..n).find(|&i| !near[i]).unwrap_or(0);
    let (mut run, mut best_run) = ((0, 0), (0, 0));
    for j in 1..=n {
        let i = (start + j) % n;
        if near[i] {
            run = if run.1 == 0 { (i, 1) } else { (run.0, run.1 + 1) };
            if run.1 > best_run.1 {
                best_run = run;
            }
        } else {
            run = (0, 0);
        }
    }
    let (e, u, p) = samples[(best_run.0 + best_run.1 / 2) % n];
    let corners: Vec<usize> = cycle.iter().map(|&s| g.start(s)).collect();
    let closest = corners.iter().copied().min_by(|&a, &b| dist(g.vertices[a], p).total_cmp(&dist(g.vertices[b], p)));
    match closest {
        Some(v) if dist(g.vertices[v], p) <= 0.05 * width => Ok(v),
        _ => Ok(g.split_edge(e, u)?.0),
    }
}

/// Points of `edges` (16 per knot span).
fn samples_of(g: &Graph, edges: impl Iterator<Item = usize>) -> Vec<Point> {
    edges
        .flat_map(|e| {
            let c = &g.edges[e].curve;
            c.sample(16 * c.knots.num_elements().max(1))
        })
        .collect()
}

/// The unit direction from hole `k` of face `f` to the nearest point of the face's other
/// loops, at their closest approach.
fn nearest_direction(g: &Graph, f: usize, k: usize) -> Point {
    let face = &g.faces[f];
    let mine = samples_of(g, face.holes[k].iter().map(|s| s.0));
    let others = samples_of(
        g,
        face.sides
            .iter()
            .chain(face.holes.iter().enumerate().filter(|(j, _)| *j != k).flat_map(|(_, h)| h))
            .map(|s| s.0),
    );
    let mut best = (f64::INFINITY, [1.0, 0.0]);
    for p in &mine {
        for q in &others {
            let d = dist(*p, *q);
            if d < best.0 && d > 0.0 {
                best = (d, [(q[0] - p[0]) / d, (q[1] - p[1]) / d]);
            }
        }
    }
    best.1
}

/// Cut every hole of every face away (see the module documentation), along the
/// direction `theta` (degrees from the `x` axis), or, when `theta` is not a number,
/// every hole along the direction to its nearest neighbour (another hole or the outer
/// boundary), so that the cut crosses the narrowest gap.
pub(crate) fn cut_holes(g: &mut Graph, diameter: f64, theta: f64, cuts: &mut Vec<HoleCut>) -> Result<()> {
    let tol = 1e-9 * diameter;
    let global = [theta.to_radians().cos(), theta.to_radians().sin()];
    for f in 0..g.faces.len() {
        let nh = g.faces[f].holes.len();
        if nh == 0 {
            continue;
        }
        let label = g.faces[f].label.clone();
        let mut cut_edges: Vec<usize> = Vec::new();
        for k in 0..nh {
            let axis = if theta.is_nan() { nearest_direction(g, f, k) } else { global };
            for dir in [1.0, -1.0] {
                let v = extreme_vertex(g, f, k, dir, axis)?;
                let o = g.vertices[v];
                let d = [dir * axis[0], dir * axis[1]];
                // an earlier cut that already leaves v this way (two holes at one height)
                let along = cut_edges.iter().any(|&c| {
                    let e = &g.edges[c];
                    let other = if e.a == v {
                        Some(e.b)
                    } else if e.b == v {
                        Some(e.a)
                    } else {
                        None
                    };
                    other.is_some_and(|w| {
                        let q = g.vertices[w];
                        let l = dist(o, q);
                        l > 0.0 && ((q[0] - o[0]) * d[0] + (q[1] - o[1]) * d[1]) / l > (1.0f64).to_radians().cos()
                    })
                });
                if along {
                    continue;
                }
                let face = &g.faces[f];
                let own: Vec<usize> = face.holes[k].iter().map(|s| s.0).collect();
                let mut edges: Vec<usize> = face.sides.iter().chain(face.holes.iter().flatten()).map(|s| s.0).collect();
                edges.extend(&cut_edges);
                let where_ = || format!("face {f} (label {label}), hole {k}");
                let Some((e, u, s)) = ray_hit_edges(g, &edges, o, d, 1e3 * tol) else {
                    return Err(Error::Domain {
                        at: where_(),
                        reason: format!("the cut from ({:.6}, {:.6}) meets no edge", o[0], o[1]),
                    });
                };
                if own.contains(&e) {
                    return Err(Error::Domain {
                        at: where_(),
                        reason: format!(
                            "the horizontal cut from ({:.6}, {:.6}) meets the hole itself (a hole that wraps around)",
                            o[0], o[1]
                        ),
                    });
                }
                let q = g.edges[e].curve.eval(u);
                let ends = [g.edges[e].a, g.edges[e].b];
                let snap = ends
                    .into_iter()
                    .filter(|&w| w != v)
                    .min_by(|&a, &b| dist(g.vertices[a], q).total_cmp(&dist(g.vertices[b], q)));
                let (w, snapped) = match snap {
                    Some(w) if dist(g.vertices[w], q) <= 0.1 * s && segment_clear(g, &edges, o, g.vertices[w], tol) => {
                        (w, true)
                    }
                    _ => {
                        if !segment_clear(g, &edges, o, q, tol) {
                            return Err(Error::Domain {
                                at: where_(),
                                reason: format!(
                                    "the cut from ({:.6}, {:.6}) to ({:.6}, {:.6}) crosses an edge",
                                    o[0], o[1], q[0], q[1]
                                ),
                            });
                        }
                        let (w, e2) = g.split_edge(e, u)?;
                        if cut_edges.contains(&e) {
                            cut_edges.push(e2);
                        }
                        (w, false)
                    }
                };
                let to = g.vertices[w];
                cut_edges.push(g.add_edge(line(o, to), v, w, false));
                let ends_on = if snapped { "vertex" } else { "side" };
                cuts.push(HoleCut { hole: format!("{label}, hole {k}"), from: o, to, ends_on });
            }
        }
        let face = &g.faces[f];
        let mut halves: Vec<FaceSide> = face.sides.iter().chain(face.holes.iter().flatten()).copied().collect();
        halves.extend(cut_edges.iter().flat_map(|&c| [(c, true), (c, false)]));
        let cycles = trace(g, &halves)?;
        for c in &cycles {
            if let Some(&(e, _)) = c.iter().find(|&&(e, d)| c.contains(&(e, !d))) {
                return Err(Error::Domain {
                    at: format!("face {f} (label {label})"),
                    reason: format!("the cut from a hole along edge {e} has the same part on both sides"),
                });
            }
            let a = signed_area(&polyline(g, c));
            if a <= tol * diameter {
                return Err(Error::Domain {
                    at: format!("face {f} (label {label})"),
                    reason: format!("cutting its holes away left a part of area {a:.3e}: the cuts cross"),
                });
            }
        }
        let mut cycles = cycles.into_iter();
        let first = cycles.next().expect("a face has a boundary");
        g.faces[f].sides = first;
        g.faces[f].holes.clear();
        for c in cycles {
            g.faces.push(super::graph::Face::new(c, label.clone()));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::curve::Curve;
    use crate::spline::knots::KnotVector;

    /// The unit circle as four quarter arcs (rational quadratics), the edges of `g`.
    fn circle(g: &mut Graph) -> Vec<usize> {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let corners = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
        let v: Vec<usize> = corners.iter().map(|&p| g.add_vertex(p)).collect();
        (0..4)
            .map(|k| {
                let (a, b) = (corners[k], corners[(k + 1) % 4]);
                let mid = [a[0] + b[0], a[1] + b[1]];
                let arc = Curve::new(KnotVector::open_uniform(2, 1), vec![a, mid, b], Some(vec![1.0, w, 1.0])).unwrap();
                g.add_edge(arc, v[k], v[(k + 1) % 4], true)
            })
            .collect()
    }

    /// A segment from inside the unit circle to a point of it that is not one of its
    /// samples meets no edge: its end lies on the arc, and the chord there passes inside
    /// the circle by up to `1 - cos(45° / 16)` = 0.0012, which the segment crossed before
    /// its ends were made vertices of the polylines. A segment through a second edge (a
    /// segment of the `x` axis) is not clear, with or without that.
    #[test]
    fn a_segment_to_a_point_of_a_curved_edge_is_clear() {
        let mut g = Graph::default();
        let edges = circle(&mut g);
        let q = g.edges[edges[0]].curve.eval(0.3);
        assert!((q[0].hypot(q[1]) - 1.0).abs() < 1e-15);
        // the polyline of 16 chords misses q: the chord nearest to it is inside the circle
        let p = g.edges[edges[0]].curve.sample(16);
        assert!(!p.contains(&q));
        let a = [0.3, 0.1];
        assert!(segment_clear(&g, &edges, a, q, 1e-9));
        // the same from a point below the x axis, across a segment of it: not clear
        let (u, v) = (g.add_vertex([-0.5, 0.0]), g.add_vertex([0.95, 0.0]));
        let mut more = edges.clone();
        more.push(g.add_edge(line([-0.5, 0.0], [0.95, 0.0]), u, v, false));
        assert!(!segment_clear(&g, &more, [0.3, -0.1], q, 1e-9));
        assert!(segment_clear(&g, &more, [0.3, 0.1], q, 1e-9));
    }
}
