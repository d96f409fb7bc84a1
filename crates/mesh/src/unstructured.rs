//! Unstructured triangulations: a constrained Delaunay triangulation of the parameter
//! square made with `spade`, refined against limits measured **in physical space**
//! through the map, its vertices mapped by the spline.
//!
//! 0. The triangulation lives in the parameter rectangle `[0, L_xi] x [0, L_eta]`, the
//!    square stretched by the mean physical lengths of opposite sides
//!    ([`parameter_scale`]), so that a map much longer than wide (a channel) does not
//!    turn well-shaped parameter triangles into slivers.
//! 1. The boundary of the square is split so that each side's segments have physical
//!    length about `size` (equal arc length along the mapped side).
//! 2. Rounds of: spade's Delaunay refinement with the angle limit (in the parameter
//!    square); then every triangle whose straight image has an edge longer than `size`,
//!    is inverted (down to `size / 64`), or over which `det J` (eq. 43) varies by more than `det_j_ratio`
//!    between its vertices, gets its physically longest edge split at the parameter
//!    midpoint; so does every boundary segment whose image deviates from the mapped
//!    curve by more than `chord_tol` at its midpoint. Stop when no triangle asks; give
//!    up (error) past 50 times the vertex count an equilateral mesh of the area needs,
//!    which happens where the map stretches parameter triangles into slivers.
//!
//! The minimum angle holds in the stretched parameter rectangle (spade's guarantee);
//! the physical angles are reported by [`crate::quality`].

use std::collections::HashSet;

use glam::DVec2;
use spade::{AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};
use winslow::{Side, Surface};

use crate::error::{MeshError, Result};
use crate::high_order::JacobianProbe;
use crate::{BoundaryEdge, ElementKind, Mesh};

/// Options of an unstructured mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct UnstructuredOptions {
    /// Target physical edge length `H`.
    pub size: f64,
    /// Smallest angle in the parameter square, degrees (at most 34; spade's refinement
    /// may not terminate above about 30).
    pub min_angle: f64,
    /// Largest distance between a boundary segment's midpoint and the mapped side
    /// (physical units); `None`: `size / 20`.
    pub chord_tol: Option<f64>,
    /// Largest ratio of `det J` between a triangle's vertices (applied to triangles
    /// longer than `size / 8`, so singular corners do not refine forever); `None`: off.
    pub det_j_ratio: Option<f64>,
    /// Most vertices (a guard against a size too small for the memory).
    pub max_vertices: usize,
    /// Order of the elements that will be made of the triangles (1-3): for order > 1,
    /// a triangle whose curved element ([`crate::high_order::elevate`]) would have a
    /// Jacobian <= 0 at a node or Gauss point is split too (down to `size / 64`).
    pub order: usize,
}

impl Default for UnstructuredOptions {
    fn default() -> Self {
        Self { size: 0.1, min_angle: 28.0, chord_tol: None, det_j_ratio: Some(4.0), max_vertices: 20_000_000, order: 1 }
    }
}

/// Physical point of a parameter.
fn at(map: &Surface, q: DVec2) -> DVec2 {
    DVec2::from(map.eval(q.x, q.y))
}

/// Parameters on a side at equal physical arc length, `n` segments (ends excluded).
fn side_points(map: &Surface, side: Side, size: f64) -> Vec<DVec2> {
    let param = |t: f64| match side {
        Side::South => DVec2::new(t, 0.0),
        Side::East => DVec2::new(1.0, t),
        Side::North => DVec2::new(1.0 - t, 1.0),
        Side::West => DVec2::new(0.0, 1.0 - t),
    };
    const M: usize = 2048;
    let mut s = vec![0.0; M + 1];
    let mut prev = at(map, param(0.0));
    for k in 1..=M {
        let p = at(map, param(k as f64 / M as f64));
        s[k] = s[k - 1] + p.distance(prev);
        prev = p;
    }
    let n = ((s[M] / size).ceil() as usize).max(1);
    let mut out = Vec::with_capacity(n);
    let mut k = 0;
    for m in 0..n {
        let target = s[M] * m as f64 / n as f64;
        while k < M && s[k + 1] < target {
            k += 1;
        }
        let f = if s[k + 1] > s[k] { (target - s[k]) / (s[k + 1] - s[k]) } else { 0.0 };
        let t = if m == 0 { 0.0 } else { (k as f64 + f.clamp(0.0, 1.0)) / M as f64 };
        out.push(param(t));
    }
    out
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

fn pos_of(cdt: &Cdt, i: usize) -> Point2<f64> {
    cdt.vertex(spade::handles::FixedVertexHandle::from_index(i)).position()
}

/// Physical length of a side (polyline of 2048 chords).
fn side_length(map: &Surface, side: Side) -> f64 {
    let c = map.boundary(side);
    let p = c.sample(2048);
    p.windows(2).map(|w| DVec2::from(w[0]).distance(DVec2::from(w[1]))).sum()
}

/// `(L_xi, L_eta)`: the means of the physical lengths of south and north, and of west
/// and east; the triangulation is made in `[0, L_xi] x [0, L_eta]`.
pub fn parameter_scale(map: &Surface) -> DVec2 {
    let l = Side::ALL.map(|s| side_length(map, s));
    let s = DVec2::new(0.5 * (l[0] + l[2]), 0.5 * (l[1] + l[3]));
    if s.x > 0.0 && s.y > 0.0 && s.is_finite() {
        s
    } else {
        DVec2::ONE
    }
}

/// A triangulation of `map`'s image (linear triangles, counter-clockwise).
pub fn unstructured(map: &Surface, opts: &UnstructuredOptions) -> Result<Mesh> {
    if !(opts.size.is_finite() && opts.size > 0.0) {
        return Err(MeshError::param("size", format!("must be positive, got {}", opts.size)));
    }
    if !(opts.min_angle >= 0.0 && opts.min_angle <= 34.0) {
        return Err(MeshError::param("min angle", format!("must be in [0, 34] degrees, got {}", opts.min_angle)));
    }
    let chord_tol = opts.chord_tol.unwrap_or(opts.size / 20.0);
    let mut boundary: Vec<DVec2> = Vec::new();
    for side in Side::ALL {
        boundary.extend(side_points(map, side, opts.size));
    }
    let nb = boundary.len();
    let edges: Vec<[usize; 2]> = (0..nb).map(|i| [i, (i + 1) % nb]).collect();
    let scale = parameter_scale(map);
    // vertices of an equilateral mesh of edge `size` over the area (shoelace of the
    // boundary points), the yardstick of the guard against refinement that does not settle
    let area = {
        let x: Vec<DVec2> = boundary.iter().map(|q| at(map, *q)).collect();
        0.5 * (0..x.len()).map(|k| x[k].perp_dot(x[(k + 1) % x.len()])).sum::<f64>()
    };
    let expected = (area.abs() / (0.433 * opts.size * opts.size) / 2.0) as usize + nb;
    let verts: Vec<Point2<f64>> = boundary.iter().map(|q| Point2::new(q.x * scale.x, q.y * scale.y)).collect();
    let mut cdt = Cdt::bulk_load_cdt(verts, edges).map_err(|e| MeshError::Triangulation(format!("{e:?}")))?;
    let mut phys: Vec<DVec2> = Vec::new();
    let mut det: Vec<f64> = Vec::new();
    let limit = AngleLimit::from_deg(opts.min_angle);
    let probe = (opts.order > 1).then(|| JacobianProbe::new(ElementKind::Triangle, opts.order.min(3)));
    for round in 0..200 {
        let budget = opts.max_vertices.saturating_sub(cdt.num_vertices());
        // the first round also bounds the area by the equilateral triangle of edge `size`
        // in the stretched rectangle: most vertices come from spade's own refinement
        let mut params = RefinementParameters::new().with_angle_limit(limit).with_max_additional_vertices(budget);
        if round == 0 {
            params = params.with_max_allowed_area(0.433 * opts.size * opts.size);
        }
        let r = cdt.refine(params);
        if !r.refinement_complete {
            return Err(MeshError::Triangulation(format!(
                "refinement stopped at {} vertices (the limit) before meeting the angle {}°; use a larger size or a smaller angle",
                cdt.num_vertices(),
                opts.min_angle
            )));
        }
        for v in cdt.vertices().skip(phys.len()) {
            let p = v.position();
            let d = map.derivs(p.x / scale.x, p.y / scale.y, 1);
            phys.push(DVec2::from(d.x));
            det.push(d.det_j());
        }
        let mut split: HashSet<(usize, usize)> = HashSet::new();
        for f in cdt.inner_faces() {
            let v = f.vertices().map(|h| h.fix().index());
            let x = v.map(|i| phys[i]);
            let len = [x[0].distance(x[1]), x[1].distance(x[2]), x[2].distance(x[0])];
            let (mut e, mut longest) = (0, len[0]);
            for k in 1..3 {
                if len[k] > longest {
                    (e, longest) = (k, len[k]);
                }
            }
            let area = (x[1] - x[0]).perp_dot(x[2] - x[0]);
            let dets = v.map(|i| det[i]);
            let (dmin, dmax) =
                (dets.iter().copied().fold(f64::INFINITY, f64::min), dets.iter().copied().fold(0.0, f64::max));
            let varies = opts.det_j_ratio.is_some_and(|r| longest > opts.size / 8.0 && dmin > 0.0 && dmax > r * dmin);
            // an inverted image is split while it is not tiny (a folded map stays folded)
            let inverted = (area.is_nan() || area <= 0.0) && longest > opts.size / 64.0;
            let curved_bad = || {
                probe.as_ref().is_some_and(|pr| {
                    let q = v.map(|i| {
                        let p = pos_of(&cdt, i);
                        DVec2::new(p.x / scale.x, p.y / scale.y)
                    });
                    longest > opts.size / 64.0 && pr.curved_min(map, &q) <= 0.0
                })
            };
            if longest > opts.size || inverted || varies || curved_bad() {
                let (a, b) = (v[e], v[(e + 1) % 3]);
                split.insert((a.min(b), a.max(b)));
            }
        }
        for edge in cdt.undirected_edges().filter(|e| e.is_constraint_edge()) {
            let [a, b] = edge.vertices().map(|h| h.fix().index());
            let (pa, pb) = (edge.vertices()[0].position(), edge.vertices()[1].position());
            if phys[a].distance(phys[b]) <= opts.size / 64.0 {
                continue;
            }
            let mid = at(map, DVec2::new(0.5 * (pa.x + pb.x) / scale.x, 0.5 * (pa.y + pb.y) / scale.y));
            if mid.distance(0.5 * (phys[a] + phys[b])) > chord_tol {
                split.insert((a.min(b), a.max(b)));
            }
        }
        if split.is_empty() {
            return build(&cdt, phys, scale);
        }
        if cdt.num_vertices() > 50 * expected + 10_000 {
            return Err(MeshError::Triangulation(format!(
                "{} vertices and {} edges still to split, against about {expected} for triangles of size {} over the area: the map stretches parameter triangles into slivers (strong local anisotropy, e.g. a narrow gap); isotropic refinement in the parameter square does not settle here: use --structured or a larger size",
                cdt.num_vertices(),
                split.len(),
                opts.size
            )));
        }
        if cdt.num_vertices() + split.len() > opts.max_vertices {
            return Err(MeshError::Triangulation(format!(
                "more than {} vertices needed for size {}; use a larger size",
                opts.max_vertices, opts.size
            )));
        }
        let mut split: Vec<_> = split.into_iter().collect();
        split.sort_unstable();
        let pos: Vec<Point2<f64>> = cdt.vertices().map(|v| v.position()).collect();
        for (a, b) in split {
            let m = Point2::new(0.5 * (pos[a].x + pos[b].x), 0.5 * (pos[a].y + pos[b].y));
            cdt.insert(m).map_err(|e| MeshError::Triangulation(format!("{e:?}")))?;
        }
    }
    Err(MeshError::Triangulation("refinement did not settle in 200 rounds".into()))
}

/// The side of a boundary edge from its parameters.
fn side_of(a: DVec2, b: DVec2) -> Option<Side> {
    if a.y == 0.0 && b.y == 0.0 {
        Some(Side::South)
    } else if a.x == 1.0 && b.x == 1.0 {
        Some(Side::East)
    } else if a.y == 1.0 && b.y == 1.0 {
        Some(Side::North)
    } else if a.x == 0.0 && b.x == 0.0 {
        Some(Side::West)
    } else {
        None
    }
}

fn build(cdt: &Cdt, points: Vec<DVec2>, scale: DVec2) -> Result<Mesh> {
    // x / L is exactly 0 or 1 on the sides (their points are exactly 0 or L)
    let params: Vec<DVec2> =
        cdt.vertices().map(|v| DVec2::new(v.position().x / scale.x, v.position().y / scale.y)).collect();
    let mut cells = Vec::with_capacity(3 * cdt.num_inner_faces());
    for f in cdt.inner_faces() {
        cells.extend(f.vertices().map(|h| h.fix().index()));
    }
    let mut boundary = Vec::new();
    for e in cdt.undirected_edges().filter(|e| e.is_constraint_edge()) {
        let [a, b] = e.vertices().map(|h| h.fix().index());
        let Some(side) = side_of(params[a], params[b]) else {
            return Err(MeshError::Triangulation(format!("constraint edge {a}-{b} is not on a side")));
        };
        // counter-clockwise around the square
        let forward = match side {
            Side::South => params[a].x < params[b].x,
            Side::East => params[a].y < params[b].y,
            Side::North => params[a].x > params[b].x,
            Side::West => params[a].y > params[b].y,
        };
        let nodes = if forward { vec![a, b] } else { vec![b, a] };
        boundary.push(BoundaryEdge { side, nodes });
    }
    // by side, then along it
    let along = |e: &BoundaryEdge| {
        let q = params[e.nodes[0]];
        match e.side {
            Side::South => q.x,
            Side::East => q.y,
            Side::North => -q.x,
            Side::West => -q.y,
        }
    };
    boundary.sort_by(|a, b| (a.side as usize).cmp(&(b.side as usize)).then(along(a).total_cmp(&along(b))));
    Ok(Mesh { points, params, kind: ElementKind::Triangle, order: 1, cells, boundary, structured: None })
}
