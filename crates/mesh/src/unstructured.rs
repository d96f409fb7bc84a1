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
//!    is inverted (down to `size / 64`), or over which `det J` (eq. 43) varies by more
//!    than `det_j_ratio` between its vertices (the paper's criterion: "the value of the
//!    Jacobian determinant in the vertices can in turn serve as a refinement
//!    criterion") gets its physically longest edge split at the parameter midpoint (cut
//!    into `ceil(len / size)` equal pieces when longer than `2 size`, which saves rounds
//!    where the map stretches); so does every boundary segment whose chord deviates
//!    from the mapped side by more than `chord_tol` (the largest distance, measured:
//!    this refines where the boundary's curvature `kappa` is high, the deviation being
//!    `kappa h^2 / 8`). Stop when no triangle asks; give up (error) past 50 times the
//!    vertex count an equilateral mesh of the area needs, which happens where the map
//!    stretches parameter triangles into slivers. A round skips spade's refinement (a
//!    scan of every triangle) when the triangles around the points just inserted
//!    already meet its limits (`star_meets_limits`), and checks only the triangles and
//!    segments with a vertex new since the last round.
//!
//! Speed: the criteria and the mapping of new vertices run in parallel (rayon), each
//! midpoint is inserted with a walk from an end of its edge (not from the last vertex
//! inserted, which costs `O(sqrt n)` steps a point); [`MeshingStats`] says where the time
//! goes (printed by `winslow mesh`).
//!
//! A ring (a periodic direction, or two coinciding sides of a ring cut into a four-sided
//! map, [`crate::seam`]) is triangulated in the same rectangle with its seam's two sides
//! kept identical: the end side gets the start side's points, every point that
//! refinement puts on one of them (spade's encroachment splits, the size criterion) is
//! inserted on the other too before a round may end (`seam_mirrors`), and no triangle may
//! touch both (its longest edge is split). The end side's vertices are then identified
//! with the start side's (same coordinate along the seam, bit for bit), so the seam is
//! one line of nodes shared by the triangles on both sides, with no boundary edge on
//! it; the walls are the groups `inner` and `outer` ([`crate::seam::wall_names`]).
//! A ring's rectangle is its mean width across and, around, the arc length of the local
//! aspect ([`crate::rectangle`]): where the ring narrows, the rectangle stretches, so a
//! well-shaped triangle there is one about as wide as the ring is, not a sliver of the
//! mean width's shape (a ring whose width varies a hundredfold, the rotor in its casing,
//! made angles of 0 and 180 degrees and ran into the vertex guard before). The extent
//! around is a power of two (spade's splits of the seam's segments stay on them bit for
//! bit). A size whose expected vertex count (over the area, or over a ring's rectangle
//! with its local widths) is above the guard is refused before any refinement.
//!
//! The minimum angle holds in the stretched parameter rectangle (spade's guarantee);
//! the physical angles are reported by [`crate::quality`].

use std::collections::{BTreeSet, HashMap};
use std::time::Instant;

use glam::DVec2;
use rayon::prelude::*;
use spade::{AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};
use winslow::{Side, Surface};

use crate::equidistribution::{segment_deviation, SideCurve};
use crate::error::{MeshError, Result};
use crate::high_order::JacobianProbe;
use crate::rectangle::Rectangle;
use crate::{BoundaryEdge, ElementKind, Mesh};

/// Options of an unstructured mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct UnstructuredOptions {
    /// Target physical edge length `H`.
    pub size: f64,
    /// Smallest angle in the parameter square, degrees (at most 34; spade's refinement
    /// may not terminate above about 30).
    pub min_angle: f64,
    /// Largest distance between a boundary segment (chord) and the mapped side
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
pub(crate) fn side_points(map: &Surface, side: Side, size: f64) -> Vec<DVec2> {
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

/// Where an unstructured mesh's time went (seconds), and its rounds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeshingStats {
    /// Rounds of refinement and splitting.
    pub rounds: usize,
    /// Rounds that ran spade's refinement (the others were settled, see step 2).
    pub spade_refinements: usize,
    /// Boundary points, the stretch and the initial constrained triangulation.
    pub boundary: f64,
    /// spade's Delaunay refinement.
    pub refine: f64,
    /// Mapping the vertices through the spline (`x` and `det J`).
    pub map: f64,
    /// The physical criteria on every triangle and boundary segment.
    pub criteria: f64,
    /// Inserting the midpoints of the edges to split.
    pub insert: f64,
    /// Building the mesh from the triangulation.
    pub build: f64,
}

/// Rounds and times added (several meshes' stats summed).
impl std::ops::AddAssign for MeshingStats {
    fn add_assign(&mut self, o: Self) {
        let Self { rounds, spade_refinements, boundary, refine, map, criteria, insert, build } = o;
        self.rounds += rounds;
        self.spade_refinements += spade_refinements;
        [self.boundary, self.refine, self.map, self.criteria, self.insert, self.build] = [
            self.boundary + boundary,
            self.refine + refine,
            self.map + map,
            self.criteria + criteria,
            self.insert + insert,
            self.build + build,
        ];
    }
}

/// A triangulation of `map`'s image (linear triangles, counter-clockwise).
pub fn unstructured(map: &Surface, opts: &UnstructuredOptions) -> Result<Mesh> {
    unstructured_with_stats(map, opts).map(|(m, _)| m)
}

/// [`unstructured`] and where its time went.
pub fn unstructured_with_stats(map: &Surface, opts: &UnstructuredOptions) -> Result<(Mesh, MeshingStats)> {
    triangulate(map, opts, None)
}

/// The boundary points of a side given in advance: parameters along the side's own
/// direction (`xi` on south and north, `eta` on west and east), strictly between its
/// corners; the side list of the rectangle's boundary walk (its first corner, then these
/// counter-clockwise).
fn prescribed_side(side: Side, along: &[f64]) -> Vec<DVec2> {
    let mut t: Vec<f64> = along.to_vec();
    if matches!(side, Side::North | Side::West) {
        t.reverse();
    }
    let (corner, at): (DVec2, fn(f64) -> DVec2) = match side {
        Side::South => (DVec2::new(0.0, 0.0), |t| DVec2::new(t, 0.0)),
        Side::East => (DVec2::new(1.0, 0.0), |t| DVec2::new(1.0, t)),
        Side::North => (DVec2::new(1.0, 1.0), |t| DVec2::new(t, 1.0)),
        Side::West => (DVec2::new(0.0, 1.0), |t| DVec2::new(0.0, t)),
    };
    std::iter::once(corner).chain(t.into_iter().map(at)).collect()
}

/// The triangulation of [`unstructured_with_stats`], with the boundary points of every
/// side given (`sides[s]`: see [`prescribed_side`]; a patch of a multipatch layout, whose
/// interface points its neighbour must share) or made at equal arc length (`None`).
/// Refinement may still split boundary segments (spade's encroachment, the size and chord
/// criteria); the caller reads the sides' final points from the mesh's boundary edges.
pub(crate) fn triangulate(
    map: &Surface,
    opts: &UnstructuredOptions,
    sides: Option<&[Vec<f64>; 4]>,
) -> Result<(Mesh, MeshingStats)> {
    let mut stats = MeshingStats::default();
    let mut clock = Instant::now();
    let mut lap = || {
        let t = clock.elapsed().as_secs_f64();
        clock = Instant::now();
        t
    };
    // a ring's seam (periodic, or two coinciding sides): its two sides get one point set
    let seam = if sides.is_some() { crate::seam::Seams::default() } else { crate::seam::seams(map)? };
    let sd = seam.dir();
    if !(opts.size.is_finite() && opts.size > 0.0) {
        return Err(MeshError::param("size", format!("must be positive, got {}", opts.size)));
    }
    if !(opts.min_angle >= 0.0 && opts.min_angle <= 34.0) {
        return Err(MeshError::param("min angle", format!("must be in [0, 34] degrees, got {}", opts.min_angle)));
    }
    let chord_tol = opts.chord_tol.unwrap_or(opts.size / 20.0);
    let mut lists = match sides {
        Some(given) => Side::ALL.map(|side| prescribed_side(side, &given[side as usize])),
        None => Side::ALL.map(|side| side_points(map, side, opts.size)),
    };
    if let Some(d) = sd {
        // the end side: its first corner, then the start side's interior points in
        // reverse (both run counter-clockwise around the square)
        let [s0, s1] = crate::seam::ends(d);
        let start = &lists[s0 as usize];
        let mut end = vec![lists[s1 as usize][0]];
        end.extend(start[1..].iter().rev().map(|q| {
            let mut q = *q;
            q[d] = 1.0;
            q
        }));
        lists[s1 as usize] = end;
    }
    let boundary: Vec<DVec2> = lists.concat();
    let nb = boundary.len();
    let edges: Vec<[usize; 2]> = (0..nb).map(|i| [i, (i + 1) % nb]).collect();
    // vertices of an equilateral mesh of edge `size` over the area (shoelace of the
    // boundary points), the yardstick of the guard against refinement that does not settle
    let area = {
        let x: Vec<DVec2> = boundary.iter().map(|q| at(map, *q)).collect();
        0.5 * (0..x.len()).map(|k| x[k].perp_dot(x[(k + 1) % x.len()])).sum::<f64>()
    };
    let rect = match sd {
        // across a ring: its mean width (area over the length around), not the width at
        // the seam, which may be the narrowest or the widest place; around: the local
        // aspect's arc length (crate::rectangle)
        Some(d) => {
            let scale = parameter_scale(map);
            let across = area.abs() / scale[d];
            if across.is_finite() && across > 0.0 {
                Rectangle::ring(map, d, scale[d], across)
            } else {
                let mut scale = scale;
                scale[d] = 2f64.powi(scale[d].log2().round() as i32);
                Rectangle::linear(scale)
            }
        }
        None => Rectangle::linear(parameter_scale(map)),
    };
    let extent = rect.extent();
    let expected = match rect.expected_vertices(opts.size) {
        Some(e) if e.is_finite() => e.min(1e15) as usize + nb,
        _ => (area.abs() / (0.433 * opts.size * opts.size) / 2.0) as usize + nb,
    };
    // `expected` counts equilateral triangles of edge `size`; the size criterion halves
    // edges longer than `size`, so the meshes have more: 2.4 times on the quarter
    // annulus, 2.8 on the rotor's ring (sizes 0.01 to 0.2). Twice it is below what
    // refinement makes (curvature and det J only add): a size the guard would stop
    // anyway is refused before any work
    if expected.saturating_mul(2) > opts.max_vertices {
        return Err(MeshError::Triangulation(format!(
            "at least {} vertices expected for triangles of size {} ({}), more than the limit of {}; use a larger size",
            expected.saturating_mul(2),
            opts.size,
            if rect.is_warped() { "over the ring, each as wide as the ring is there" } else { "over the area" },
            opts.max_vertices
        )));
    }
    let verts: Vec<Point2<f64>> = boundary.iter().map(|q| rect.point(*q)).collect();
    let mut cdt = Cdt::bulk_load_cdt(verts, edges).map_err(|e| MeshError::Triangulation(format!("{e:?}")))?;
    let mut phys: Vec<DVec2> = Vec::new();
    let mut det: Vec<f64> = Vec::new();
    let limit = AngleLimit::from_deg(opts.min_angle);
    let probe = (opts.order > 1).then(|| JacobianProbe::new(ElementKind::Triangle, opts.order.min(3)));
    // whether the triangles made by the last round's insertions all meet spade's limits
    // (then spade's refinement, a scan of every triangle, would add nothing)
    let mut settled = false;
    let sides = Side::ALL.map(|s| SideCurve::new(map, s));
    stats.boundary = lap();
    for round in 0..200 {
        stats.rounds = round + 1;
        // a ring's rectangle may stretch triangles into slivers where its width varies
        // strongly: spade's refinement stops at the guard below instead of running on
        let most = if sd.is_some() { opts.max_vertices.min(50 * expected + 10_000) } else { opts.max_vertices };
        let budget = most.saturating_sub(cdt.num_vertices());
        // the first round also bounds the area by the equilateral triangle of edge `size`
        // in the stretched rectangle: most vertices come from spade's own refinement
        let mut params = RefinementParameters::new().with_angle_limit(limit).with_max_additional_vertices(budget);
        if round == 0 && !rect.is_warped() {
            params = params.with_max_allowed_area(0.433 * opts.size * opts.size);
        }
        let r = if settled {
            spade::RefinementResult { excluded_faces: Vec::new(), refinement_complete: true }
        } else {
            stats.spade_refinements += 1;
            cdt.refine(params)
        };
        stats.refine += lap();
        if !r.refinement_complete {
            return Err(MeshError::Triangulation(format!(
                "refinement stopped at {} vertices (the limit) before meeting the angle {}°; use a larger size or a smaller angle",
                cdt.num_vertices(),
                opts.min_angle
            )));
        }
        // map the new vertices (in parallel: one spline evaluation each)
        let pos: Vec<Point2<f64>> = cdt.vertices().map(|v| snap(v.position(), extent)).collect();
        let prm: Vec<DVec2> = pos.par_iter().map(|p| rect.param(*p)).collect();
        // vertices from `first_new` on are new since the last scan: a triangle or segment of
        // older vertices only existed then and passed (inserting a point only makes
        // triangles that have it as a vertex; a split edge's triangles are gone)
        let first_new = phys.len();
        let fresh: Vec<(DVec2, f64)> = prm[phys.len()..]
            .par_iter()
            .map(|q| {
                let d = map.derivs(q.x, q.y, 1);
                (DVec2::from(d.x), d.det_j())
            })
            .collect();
        for (x, d) in fresh {
            phys.push(x);
            det.push(d);
        }
        stats.map += lap();
        let param = |i: usize| prm[i];
        let faces: Vec<[usize; 3]> = cdt
            .inner_faces()
            .map(|f| f.vertices().map(|h| h.fix().index()))
            .filter(|v| v.iter().any(|&i| i >= first_new))
            .collect();
        // the edge to split of each triangle that asks (in parallel)
        let mut split: Vec<(usize, usize, usize)> = faces
            .par_iter()
            .filter_map(|&v| {
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
                let varies =
                    opts.det_j_ratio.is_some_and(|r| longest > opts.size / 8.0 && dmin > 0.0 && dmax > r * dmin);
                // an inverted image is split while it is not tiny (a folded map stays folded)
                let inverted = (area.is_nan() || area <= 0.0) && longest > opts.size / 64.0;
                // a triangle on both sides of a seam would fold when they are identified
                let spans = sd.is_some_and(|d| {
                    let q = v.map(|i| pos[i]);
                    let end = extent[d];
                    let c = |p: Point2<f64>| if d == 0 { p.x } else { p.y };
                    q.iter().any(|&p| c(p) == 0.0) && q.iter().any(|&p| c(p) == end)
                });
                let curved_bad = || {
                    probe
                        .as_ref()
                        .is_some_and(|pr| longest > opts.size / 64.0 && pr.curved_min(map, &v.map(param)) <= 0.0)
                };
                (longest > opts.size || inverted || varies || spans || curved_bad()).then(|| {
                    let (a, b) = (v[e], v[(e + 1) % 3]);
                    // an edge k times too long is cut into k pieces at once (fewer rounds)
                    let k = if longest > 2.0 * opts.size { (longest / opts.size).ceil().min(64.0) as usize } else { 2 };
                    (a.min(b), a.max(b), k)
                })
            })
            .collect();
        // boundary segments farther than `chord_tol` from their side (largest distance
        // between the mapped side and the chord, in parallel)
        let segments: Vec<[usize; 2]> = cdt
            .undirected_edges()
            .filter(|e| e.is_constraint_edge())
            .map(|e| e.vertices().map(|h| h.fix().index()))
            .filter(|&[a, b]| a.max(b) >= first_new && phys[a].distance(phys[b]) > opts.size / 64.0)
            .collect();
        let far: Vec<(usize, usize, usize)> = segments
            .par_iter()
            .filter_map(|&[a, b]| {
                let (p, q) = (param(a), param(b));
                let side = side_of(p, q)?;
                // the seam is interior: no chord to keep near a side
                if sd.is_some_and(|d| crate::seam::ends(d).contains(&side)) {
                    return None;
                }
                let (t0, t1) = match side {
                    Side::South | Side::North => (p.x, q.x),
                    Side::East | Side::West => (p.y, q.y),
                };
                let dev = segment_deviation(&sides[side as usize], t0.min(t1), t0.max(t1));
                (dev > chord_tol).then_some((a.min(b), a.max(b), 2))
            })
            .collect();
        split.extend(far);
        // one entry per edge, the most pieces asked for
        split.sort_unstable_by(|x, y| (x.0, x.1).cmp(&(y.0, y.1)).then(y.2.cmp(&x.2)));
        split.dedup_by_key(|x| (x.0, x.1));
        stats.criteria += lap();
        if split.is_empty() && sd.is_none_or(|d| seam_mirrors(&cdt, d, extent).is_empty()) {
            let mesh = build(&cdt, phys, &rect, sd.map(|d| (d, crate::seam::wall_names(map, d))))?;
            stats.build = lap();
            return Ok((mesh, stats));
        }
        if cdt.num_vertices() > 50 * expected + 10_000 {
            return Err(MeshError::Triangulation(format!(
                "{} vertices and {} edges still to split, against about {expected} for triangles of size {} over the area: the map stretches parameter triangles into slivers (strong local anisotropy, e.g. a narrow gap); isotropic refinement in the parameter square does not settle here: use --structured or a larger size",
                cdt.num_vertices(),
                split.len(),
                opts.size
            )));
        }
        if cdt.num_vertices() + split.iter().map(|s| s.2 - 1).sum::<usize>() > opts.max_vertices {
            return Err(MeshError::Triangulation(format!(
                "more than {} vertices needed for size {}; use a larger size",
                opts.max_vertices, opts.size
            )));
        }
        let mut inserted = Vec::with_capacity(split.len());
        for (a, b, k) in split {
            for i in 1..k {
                let t = i as f64 / k as f64;
                let m = Point2::new(pos[a].x + t * (pos[b].x - pos[a].x), pos[a].y + t * (pos[b].y - pos[a].y));
                // the walk to the new point starts at an end of its edge: O(1) steps, where
                // spade's last-inserted hint walks across the mesh (O(sqrt n))
                let hint = spade::handles::FixedVertexHandle::from_index(a);
                let h = cdt.insert_with_hint(m, hint).map_err(|e| MeshError::Triangulation(format!("{e:?}")))?;
                inserted.push(h);
            }
        }
        // the points refinement put on one side of a seam, copied to the other
        if let Some(d) = sd {
            for m in seam_mirrors(&cdt, d, extent) {
                inserted.push(cdt.insert(m).map_err(|e| MeshError::Triangulation(format!("{e:?}")))?);
            }
        }
        settled = inserted.iter().all(|&h| star_meets_limits(&cdt, h, limit));
        stats.insert += lap();
    }
    Err(MeshError::Triangulation("refinement did not settle in 200 rounds".into()))
}

/// Whether every triangle around vertex `v` meets what spade's refinement asks
/// (`spade::RefinementParameters` with the angle limit and no area limit): circumradius
/// over shortest edge at most `1 / (2 sin(angle))` (with a margin of 1e-9, so this is
/// never laxer than spade), and no constraint edge of it encroached by its opposite
/// vertex (inside the edge's diametral circle). Inserting a point into a Delaunay
/// triangulation only makes triangles that have it as a vertex, so when the triangles
/// around every point inserted since spade's last refinement pass this, the
/// triangulation is as spade's refinement would leave it and another refinement (a scan
/// of every triangle) is skipped.
fn star_meets_limits(cdt: &Cdt, v: spade::handles::FixedVertexHandle, limit: AngleLimit) -> bool {
    let lim2 = limit.radius_to_shortest_edge_limit().powi(2) * (1.0 - 1e-9);
    cdt.vertex(v).out_edges().all(|e| {
        let Some(f) = e.face().as_inner() else { return true };
        let p = f.vertices().map(|h| h.position());
        let d2 = |a: Point2<f64>, b: Point2<f64>| (a.x - b.x).powi(2) + (a.y - b.y).powi(2);
        let shortest = d2(p[0], p[1]).min(d2(p[1], p[2])).min(d2(p[2], p[0]));
        let (_, r2) = f.circumcircle();
        // NaN (a degenerate triangle) fails too
        if !matches!(r2.partial_cmp(&(lim2 * shortest)), Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)) {
            return false;
        }
        f.adjacent_edges().iter().all(|edge| {
            if !(edge.is_constraint_edge() || edge.is_part_of_convex_hull()) {
                return true;
            }
            let (a, b) = (edge.from().position(), edge.to().position());
            let Some(o) = edge.opposite_position() else { return true };
            let c = Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
            d2(o, c) >= 0.25 * d2(a, b)
        })
    })
}

/// The points to insert so that the two sides of the seam across direction `d` (at
/// coordinate `0` and `L_d` of the stretched rectangle) hold the same points: each
/// vertex of one side without a partner at the same coordinate along the side (bit for
/// bit) on the other, copied there. Sorted (deterministic).
fn seam_mirrors(cdt: &Cdt, d: usize, extent: DVec2) -> Vec<Point2<f64>> {
    let end = extent[d];
    let split = |p: Point2<f64>| if d == 0 { (p.x, p.y) } else { (p.y, p.x) };
    let make = |fixed: f64, along: f64| if d == 0 { Point2::new(fixed, along) } else { Point2::new(along, fixed) };
    let (mut lo, mut hi) = (BTreeSet::new(), BTreeSet::new());
    for v in cdt.vertices() {
        let (fixed, along) = split(snap(v.position(), extent));
        if fixed == 0.0 {
            lo.insert(along.to_bits());
        } else if fixed == end {
            hi.insert(along.to_bits());
        }
    }
    let mut out: Vec<Point2<f64>> = lo.difference(&hi).map(|&a| make(end, f64::from_bits(a))).collect();
    out.extend(hi.difference(&lo).map(|&a| make(0.0, f64::from_bits(a))));
    out
}

/// A vertex position with a coordinate within `1e-12` (relative) of a side of the
/// rectangle `[0, L_xi] x [0, L_eta]` put on it: spade splits a segment at
/// `w0 a + w1 b`, which can miss `L` by an ulp; the vertex is on the segment all the same
/// (spade inserts it into the edge).
fn snap(p: Point2<f64>, extent: DVec2) -> Point2<f64> {
    let s = |x: f64, l: f64| {
        if (x - l).abs() <= 1e-12 * l {
            l
        } else if x.abs() <= 1e-12 * l {
            0.0
        } else {
            x
        }
    };
    Point2::new(s(p.x, extent.x), s(p.y, extent.y))
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

/// The mesh of the triangulation; with a seam `(d, wall names)`, the vertices of the
/// seam's end side are identified with the start side's and its edges are no boundary.
fn build(cdt: &Cdt, points: Vec<DVec2>, rect: &Rectangle, seam: Option<(usize, [&str; 2])>) -> Result<Mesh> {
    let extent = rect.extent();
    // x / L is exactly 0 or 1 on the sides (their points are exactly 0 or L)
    let mut params: Vec<DVec2> = cdt.vertices().map(|v| rect.param(snap(v.position(), extent))).collect();
    let mut points = points;
    // the index of each vertex in the mesh (a seam's end side: its start-side partner's)
    let mut index: Vec<usize> = (0..params.len()).collect();
    if let Some((d, _)) = seam {
        let start: HashMap<u64, usize> =
            params.iter().enumerate().filter(|(_, q)| q[d] == 0.0).map(|(i, q)| (q[1 - d].to_bits(), i)).collect();
        for (i, q) in params.iter().enumerate().filter(|(_, q)| q[d] == 1.0) {
            index[i] = *start
                .get(&q[1 - d].to_bits())
                .ok_or_else(|| MeshError::Triangulation(format!("seam vertex {i} at {q} has no partner")))?;
        }
        // the kept vertices numbered in order; an end-side vertex takes its partner's number
        let mut new = vec![usize::MAX; params.len()];
        let mut next = 0;
        for (i, slot) in new.iter_mut().enumerate() {
            if index[i] == i {
                *slot = next;
                next += 1;
            }
        }
        index = index.iter().map(|&k| new[k]).collect();
        let keep: Vec<bool> = params.iter().map(|q| q[d] != 1.0).collect();
        params = params.iter().zip(&keep).filter(|(_, &k)| k).map(|(q, _)| *q).collect();
        points = points.iter().zip(&keep).filter(|(_, &k)| k).map(|(p, _)| *p).collect();
    }
    let mut cells = Vec::with_capacity(3 * cdt.num_inner_faces());
    for f in cdt.inner_faces() {
        let v = f.vertices().map(|h| index[h.fix().index()]);
        if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
            return Err(MeshError::Triangulation(format!("triangle {v:?} collapses where the seam is merged")));
        }
        cells.extend(v);
    }
    let mut boundary = Vec::new();
    for e in cdt.undirected_edges().filter(|e| e.is_constraint_edge()) {
        let [va, vb] = e.vertices();
        let [a, b] = [va, vb].map(|h| h.fix().index());
        let (pa, pb) = (rect.param(snap(va.position(), extent)), rect.param(snap(vb.position(), extent)));
        let Some(side) = side_of(pa, pb) else {
            return Err(MeshError::Triangulation(format!("constraint edge {a}-{b} is not on a side")));
        };
        if seam.is_some_and(|(d, _)| crate::seam::ends(d).contains(&side)) {
            continue;
        }
        let [a, b] = [index[a], index[b]];
        if a == b {
            return Err(MeshError::Triangulation(format!("wall edge at node {a} collapses where the seam is merged")));
        }
        // counter-clockwise around the square
        let forward = match side {
            Side::South => pa.x < pb.x,
            Side::East => pa.y < pb.y,
            Side::North => pa.x > pb.x,
            Side::West => pa.y > pb.y,
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
    let mut names = crate::side_names();
    let mut periodic = [false, false];
    if let Some((d, walls)) = seam {
        periodic[d] = true;
        for (side, name) in crate::seam::ends(1 - d).into_iter().zip(walls) {
            names[side as usize] = name.into();
        }
    }
    Ok(Mesh {
        points,
        params,
        kind: ElementKind::Triangle,
        order: 1,
        cells,
        boundary,
        structured: None,
        periodic,
        names,
        groups: None,
    })
}
