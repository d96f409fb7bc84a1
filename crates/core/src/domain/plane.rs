//! Plane graphs (`formats.md`, "Plane graph"): vertices, edges between them (straight or
//! curved) and optional face labels; the faces are the bounded regions. Validation with
//! errors naming the vertex, edge or face ([`crate::Error::Domain`] at `graph vertex K`,
//! `graph edge K`, `graph face K`, `graph label K`): indices in range, curves ending at
//! their vertices, no vertex on no edge, no dangling edge (a vertex on one edge, or an
//! edge with the same face on both sides), no two edges crossing away from their
//! vertices (a sweep over the edges' polylines), no face of zero area, every label in a
//! face and no face labelled twice.
//!
//! The faces are found by [`super::cycles::trace`] on both half-edges of every edge: a
//! counter-clockwise cycle bounds a face; a clockwise one is the outside of a connected
//! component, a hole of the smallest face around it (none: the outside of the graph). A
//! face that contains a point of `voids` (a field winslow adds to the format,
//! `docs/formats-extensions.md`: regions that are not part of the domain, such as a shaft bore) is
//! left out; its edges bound the faces around it.

use serde::Serialize;

use super::cycles::{point_left_of, polyline, signed_area, trace};
use super::graph::{Face, FaceSide, Graph};
use super::reflex::line;
use super::validate::{inside, segment_distance};
use crate::boundary::fit::{fit_side, FitOptions};
use crate::boundary::validate::{sample_side, CORNER_TOL, FLATNESS};
use crate::boundary::SideCurve;
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};
use crate::spline::surface::Side;

/// An edge of a plane graph.
#[derive(Debug, Clone)]
pub struct PlaneEdge {
    /// Start vertex.
    pub from: usize,
    /// End vertex.
    pub to: usize,
    /// The curve from `from` to `to` (a straight segment when `None`).
    pub curve: Option<SideCurve>,
}

/// A face label: the face that contains `point` is called `name`.
#[derive(Debug, Clone)]
pub struct PlaneLabel {
    /// The name.
    pub name: String,
    /// A point inside the face.
    pub point: Point,
}

/// A plane graph as read (not yet validated: `build_graph`).
#[derive(Debug, Clone, Default)]
pub struct PlaneGraph {
    /// Name of the geometry.
    pub name: String,
    /// Vertex positions.
    pub vertices: Vec<Point>,
    /// Edges.
    pub edges: Vec<PlaneEdge>,
    /// Face labels.
    pub labels: Vec<PlaneLabel>,
    /// Points inside regions that are not part of the domain.
    pub voids: Vec<Point>,
}

/// One face of a plane graph.
#[derive(Debug, Clone, Serialize)]
pub struct GraphFace {
    /// Its label (its index when no label names it).
    pub label: String,
    /// Vertices on its outer cycle.
    pub corners: usize,
    /// Its holes.
    pub holes: usize,
    /// Its area (holes subtracted), from polylines.
    pub area: f64,
}

/// What the validation of a plane graph found.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct GraphReport {
    /// Vertices.
    pub vertices: usize,
    /// Edges.
    pub edges: usize,
    /// The faces.
    pub faces: Vec<GraphFace>,
    /// Regions left out as voids.
    pub voids: usize,
    /// Total area of the faces.
    pub area: f64,
    /// Diameter of the bounding box.
    pub diameter: f64,
}

fn gerr(at: impl std::fmt::Display, reason: impl Into<String>) -> Error {
    Error::Domain { at: format!("graph {at}"), reason: reason.into() }
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The curve of edge `k` from its `from` to its `to` vertex, ends set to the vertices
/// exactly.
fn edge_curve(pg: &PlaneGraph, k: usize, tol: f64, diameter: f64, fit: &FitOptions) -> Result<Curve> {
    let e = &pg.edges[k];
    let (a, b) = (pg.vertices[e.from], pg.vertices[e.to]);
    let Some(side) = &e.curve else { return Ok(line(a, b)) };
    let (s, t) = side.endpoints();
    if dist(s, a) > tol || dist(t, b) > tol {
        let swapped = dist(s, b) <= tol && dist(t, a) <= tol;
        return Err(gerr(
            format!("edge {k}"),
            format!(
                "its curve runs from ({:.6}, {:.6}) to ({:.6}, {:.6}), not from vertex {} ({:.6}, {:.6}) to vertex {} ({:.6}, {:.6}){}",
                s[0],
                s[1],
                t[0],
                t[1],
                e.from,
                a[0],
                a[1],
                e.to,
                b[0],
                b[1],
                if swapped { ": it runs backwards (swap from and to)" } else { "" }
            ),
        ));
    }
    let mut c = match side {
        SideCurve::Spline(c) => c.normalized(),
        SideCurve::Points(p) if p.len() == 2 => line(a, b),
        other => fit_side(Side::South, other, (a, b), fit, fit.tol * diameter)
            .map_err(|err| gerr(format!("edge {k}"), format!("its fit failed: {err}")))?
            .finest()
            .clone(),
    };
    let last = c.control_points.len() - 1;
    c.control_points[0] = a;
    c.control_points[last] = b;
    Ok(c)
}

/// The first two edges (and a point) whose polylines cross or touch away from the
/// vertices they share: a sweep in `x` over the segments.
fn crossing(lines: &[Vec<Point>], ends: &[(usize, usize)], tol: f64) -> Option<(usize, usize, Point)> {
    // (min x, max x, edge, segment)
    let mut segs: Vec<(f64, f64, usize, usize)> = Vec::new();
    for (e, l) in lines.iter().enumerate() {
        for i in 0..l.len() - 1 {
            let (a, b) = (l[i], l[i + 1]);
            segs.push((a[0].min(b[0]) - tol, a[0].max(b[0]) + tol, e, i));
        }
    }
    segs.sort_by(|x, y| x.0.total_cmp(&y.0));
    for (k, &(_, hi, e1, i1)) in segs.iter().enumerate() {
        let (a, b) = (lines[e1][i1], lines[e1][i1 + 1]);
        for &(lo2, _, e2, i2) in &segs[k + 1..] {
            if lo2 > hi {
                break;
            }
            let last = |e: usize, i: usize| i + 2 == lines[e].len();
            if e1 == e2 {
                if i1.abs_diff(i2) <= 1 {
                    continue;
                }
            } else {
                // segments at a vertex both edges share
                let at = |e: usize, i: usize, v: usize| (i == 0 && ends[e].0 == v) || (last(e, i) && ends[e].1 == v);
                let shared = [ends[e1].0, ends[e1].1].into_iter().any(|v| at(e1, i1, v) && at(e2, i2, v));
                if shared {
                    continue;
                }
            }
            let (c, d) = (lines[e2][i2], lines[e2][i2 + 1]);
            let (dd, p) = segment_distance(a, b, c, d);
            if dd <= tol {
                return Some((e1.min(e2), e1.max(e2), p));
            }
        }
    }
    None
}

/// Validate `pg` (see the module documentation) and build the graph of its faces: every
/// face with its outer cycle, its holes and its label, boundary edges marked. Returns
/// the graph and the report.
pub(crate) fn build_graph(pg: &PlaneGraph, fit: &FitOptions) -> Result<(Graph, GraphReport)> {
    let n = pg.vertices.len();
    if pg.edges.is_empty() {
        return Err(gerr("", "has no edges"));
    }
    for (k, p) in pg.vertices.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(gerr(format!("vertex {k}"), "is not finite"));
        }
    }
    for (k, e) in pg.edges.iter().enumerate() {
        if e.from >= n || e.to >= n {
            return Err(gerr(
                format!("edge {k}"),
                format!("joins vertices {} and {}, but there are {n}", e.from, e.to),
            ));
        }
        if e.from == e.to {
            return Err(gerr(
                format!("edge {k}"),
                format!("starts and ends at vertex {}: a closed curve needs at least two vertices on it", e.from),
            ));
        }
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &pg.vertices {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    for e in &pg.edges {
        for p in e.curve.iter().flat_map(|c| sample_side(c, f64::INFINITY)) {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
    }
    let diameter = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    if !(diameter.is_finite() && diameter > 0.0) {
        return Err(gerr("", format!("has no extent (diameter {diameter})")));
    }
    let tol = CORNER_TOL * diameter;
    let mut valence = vec![0usize; n];
    for e in &pg.edges {
        valence[e.from] += 1;
        valence[e.to] += 1;
    }
    if let Some(v) = (0..n).find(|&v| valence[v] == 0) {
        return Err(gerr(format!("vertex {v}"), "is on no edge"));
    }
    if let Some(v) = (0..n).find(|&v| valence[v] == 1) {
        let e = pg.edges.iter().position(|e| e.from == v || e.to == v).unwrap_or(0);
        return Err(gerr(format!("edge {e}"), format!("dangles: its vertex {v} is on no other edge")));
    }
    let curves: Vec<Curve> =
        (0..pg.edges.len()).map(|k| edge_curve(pg, k, tol, diameter, fit)).collect::<Result<_>>()?;
    let lines: Vec<Vec<Point>> =
        curves.iter().map(|c| sample_side(&SideCurve::Spline(c.clone()), FLATNESS * diameter)).collect();
    let ends: Vec<(usize, usize)> = pg.edges.iter().map(|e| (e.from, e.to)).collect();
    if let Some((a, b, p)) = crossing(&lines, &ends, tol) {
        let reason = if a == b {
            format!("crosses itself near ({:.6}, {:.6})", p[0], p[1])
        } else {
            format!("crosses or touches edge {a} near ({:.6}, {:.6}), away from a vertex they share", p[0], p[1])
        };
        return Err(gerr(format!("edge {b}"), reason));
    }
    let mut g = Graph::default();
    for &p in &pg.vertices {
        g.add_vertex(p);
    }
    for (k, c) in curves.into_iter().enumerate() {
        g.add_edge(c, pg.edges[k].from, pg.edges[k].to, false);
    }
    let halves: Vec<FaceSide> = (0..pg.edges.len()).flat_map(|e| [(e, true), (e, false)]).collect();
    let cycles = trace(&g, &halves)?;
    for c in &cycles {
        if let Some(&(e, _)) = c.iter().find(|&&(e, d)| c.contains(&(e, !d))) {
            return Err(gerr(
                format!("edge {e}"),
                "has the same face on both sides: it dangles into a face or is the only link between two parts of the graph",
            ));
        }
    }
    let polys: Vec<Vec<Point>> = cycles.iter().map(|c| polyline(&g, c)).collect();
    let areas: Vec<f64> = polys.iter().map(|p| signed_area(p)).collect();
    for (i, c) in cycles.iter().enumerate() {
        if areas[i].abs() <= tol * diameter {
            let vs: Vec<usize> = c.iter().map(|&s| g.start(s)).collect();
            return Err(gerr(format!("face at vertices {vs:?}"), format!("has zero area ({:.3e})", areas[i])));
        }
    }
    let outer: Vec<usize> = (0..cycles.len()).filter(|&i| areas[i] > 0.0).collect();
    // the smallest face around a point
    let around = |p: Point| {
        outer.iter().copied().filter(|&i| inside(&polys[i], p)).min_by(|&a, &b| areas[a].total_cmp(&areas[b]))
    };
    let mut holes: Vec<Vec<usize>> = vec![Vec::new(); cycles.len()];
    for i in (0..cycles.len()).filter(|&i| areas[i] <= 0.0) {
        if let Some(f) = around(point_left_of(&g, &cycles[i], 1e-7 * diameter)) {
            holes[f].push(i);
        }
    }
    let mut void = vec![false; cycles.len()];
    for (k, &p) in pg.voids.iter().enumerate() {
        match around(p) {
            Some(f) => void[f] = true,
            None => return Err(gerr(format!("void {k}"), format!("({:.6}, {:.6}) lies in no face", p[0], p[1]))),
        }
    }
    let mut label: Vec<Option<String>> = vec![None; cycles.len()];
    for (k, l) in pg.labels.iter().enumerate() {
        let Some(f) = around(l.point) else {
            return Err(gerr(format!("label {k} ({})", l.name), "its point lies in no face"));
        };
        if void[f] {
            return Err(gerr(format!("label {k} ({})", l.name), "its point lies in a void"));
        }
        if let Some(other) = &label[f] {
            return Err(gerr(format!("label {k} ({})", l.name), format!("names the face already called {other}")));
        }
        label[f] = Some(l.name.clone());
    }
    let mut faces = Vec::new();
    let mut area = 0.0;
    for (k, &i) in outer.iter().filter(|&&i| !void[i]).enumerate() {
        let name = label[i].clone().unwrap_or_else(|| k.to_string());
        let a = areas[i] + holes[i].iter().map(|&h| areas[h]).sum::<f64>();
        area += a;
        faces.push(GraphFace { label: name.clone(), corners: cycles[i].len(), holes: holes[i].len(), area: a });
        let mut face = Face::new(cycles[i].clone(), name);
        face.holes = holes[i].iter().map(|&h| cycles[h].clone()).collect();
        g.faces.push(face);
    }
    if g.faces.is_empty() {
        return Err(gerr("", "has no face to lay out (every bounded region is a void)"));
    }
    let mut uses = vec![0usize; g.edges.len()];
    for f in &g.faces {
        for &(e, _) in f.sides.iter().chain(f.holes.iter().flatten()) {
            uses[e] += 1;
        }
    }
    for (e, u) in uses.iter().enumerate() {
        g.edges[e].boundary = *u == 1;
    }
    let report = GraphReport { vertices: n, edges: pg.edges.len(), faces, voids: pg.voids.len(), area, diameter };
    Ok((g, report))
}
