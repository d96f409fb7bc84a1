//! The automatic quad layout of a general planar domain or a plane graph (issue 31),
//! with no interaction:
//!
//! 1. **Sides**: point clouds are fitted by the contour fit of §5 (`FitOptions`); the
//!    outer loop of a domain becomes one face of a `Graph` and its holes the face's
//!    holes, their sides boundary edges; the faces of a plane graph are found by
//!    `build_graph`, each labelled. Holes are cut away by `holes`.
//! 2. **Reflex corners** are cut by straight edges into the face (`reflex`);
//!    a cut ending inside an edge shared with another face gives that face a flat
//!    corner, cut in turn. A cut's end is where its new angles stay farthest from 0° and
//!    180°; where the cuts along the bisector and the side extensions leave a sliver, the
//!    end is searched along the sides. A domain without holes whose layout is not valid
//!    so is laid out again without that search, then with it at every corner.
//! 3. **Templates**: a face with four corners stays one patch. Every other face with `N`
//!    corners is cut into `N` quads around one interior vertex (valence `N`), the
//!    midpoint template: the harmonic map of the regular `N`-gon onto the face
//!    (`HarmonicMap`, Hinz & Buffa) places the interior vertex (the image of the
//!    polygon's centre) and the cuts (the images of the segments from the centre to the
//!    midpoints of the sides, fitted by splines); the sides are split at their arc-length
//!    midpoints, the images of the polygon's side midpoints. A four-sided face beside a
//!    split edge is split too, by the image of the segment between the midpoints of that
//!    edge and the opposite one (so the splits run through chains of four-sided faces and
//!    the layout stays conforming), or into four when both pairs are split.
//!    When the layout so made is not valid (a cut leaves its face or crosses another, in
//!    every direction of the hole cuts), it is made again with the interior vertex and
//!    the cuts placed by the inverse of the map of the face onto the polygon
//!    (`PolygonMap`, one-to-one on every face).
//! 4. **Layout**: every face is now a patch (south, east, reversed north and reversed west
//!    are its four sides; an edge shared by two patches is an interface), named `p0`,
//!    `p1`, ..., each with the label of its face (`"domain"`, or the graph face's).
//!
//! The report lists every cut, every face's template and the interior vertices whose
//! valence is not 4.

use std::time::Instant;

use serde::Serialize;

use super::cycles::{polyline, signed_area};
use super::graph::{Face, FaceSide, Graph};
use super::harmonic::{ArcLength, HarmonicMap};
use super::holes::{cut_holes, HoleCut};
use super::plane::{build_graph, GraphReport, PlaneGraph};
use super::polygon_map::{PolygonMap, POLYGON_MAP_LEVELS};
use super::reflex::{cut_reflex, fit_points, line, segment_inside, CutReport, GOOD_CUT_ANGLE};
use super::validate::{validate_domain, DomainReport};
use super::{domain_error, Domain, LoopId};
use crate::boundary::fit::{fit_side, FitOptions};
use crate::boundary::SideCurve;
use crate::error::{Error, Result};
use crate::multipatch::check::validate_layout;
use crate::multipatch::layout::{Interface, Layout, Patch, PatchSide};
use crate::spline::curve::{Curve, Point};
use crate::spline::surface::Side;

/// Options of the automatic layout.
#[derive(Debug, Clone)]
pub struct LayoutOptions {
    /// The fit of point-cloud sides and of the template's cuts (degree, tolerance
    /// relative to the diameter).
    pub fit: FitOptions,
    /// Rings of the discrete harmonic map of every face.
    pub rings: usize,
}

impl Default for LayoutOptions {
    fn default() -> Self {
        Self { fit: FitOptions::default(), rings: 24 }
    }
}

/// The template of one face.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct FaceReport {
    /// The face's label.
    pub label: String,
    /// Its corners.
    pub corners: usize,
    /// `"one patch"`, `"split in two"` or `"midpoint"` (`N` quads around a vertex).
    pub template: &'static str,
    /// Patches it became.
    pub patches: usize,
    /// The image of the polygon's centre (the interior vertex), for the midpoint template.
    pub centre: Option<Point>,
    /// Smallest ratio of image to parameter area over the harmonic map's triangles
    /// (negative: the discrete map folds and the cuts may leave the face).
    pub harmonic_min_area_ratio: Option<f64>,
    /// The harmonic map folds (`harmonic_min_area_ratio <= 0`), so its spokes may leave
    /// the face: the cuts are straight instead, from a point the face is star-shaped
    /// about (see `star_centre`) to the side midpoints, or the straight segment between the
    /// two midpoints of a face split in two when it lies inside.
    pub straight: bool,
    /// The cuts are the preimages of the polygon's segments under the map of the face
    /// onto the polygon (`PolygonMap`, one-to-one on every face), taken when the layout
    /// by the harmonic map of the polygon onto the faces is not valid.
    pub inverse: bool,
}

/// An interior vertex whose valence is not 4.
#[derive(Debug, Clone, Serialize)]
pub struct IrregularVertex {
    /// Where.
    pub point: Point,
    /// Number of patches (edges) meeting there.
    pub valence: usize,
}

/// What the automatic layout did.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct LayoutReport {
    /// The validation of the domain (a `domain` document).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub domain: Option<DomainReport>,
    /// The validation of the plane graph and its faces (a `graph` document).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub graph: Option<GraphReport>,
    /// Area of the domain (holes and voids subtracted), from polylines.
    pub area: f64,
    /// Cuts from holes (`holes`).
    pub hole_cuts: Vec<HoleCut>,
    /// Their direction, degrees from the `x` axis (`None`: every hole toward its
    /// nearest neighbour, or no holes).
    pub hole_cut_direction: Option<f64>,
    /// The directions tried (with holes): the valid layout with the largest smallest
    /// corner angle is taken.
    pub hole_cut_tries: Vec<HoleCutTry>,
    /// Cuts from reflex corners.
    pub cuts: Vec<CutReport>,
    /// Below this smallest new angle (degrees) of a cut along a corner's bisector or
    /// side extensions, the cut's end was searched along the sides (`cuts[].spread`):
    /// 30 by default; 0 (never) or 180 (always) where the default gives no valid layout.
    pub cut_search: f64,
    /// The template of every face.
    pub faces: Vec<FaceReport>,
    /// Interior vertices of valence other than 4.
    pub irregular_vertices: Vec<IrregularVertex>,
    /// Patches.
    pub patches: usize,
    /// Smallest and largest corner angle of a patch, degrees.
    pub corner_angles: [f64; 2],
    /// Seconds.
    pub seconds: f64,
}

/// A laid-out domain: the multipatch layout (every patch naming its face) and the report.
#[derive(Debug, Clone)]
pub struct AutoLayout {
    /// The layout, ready for [`Pipeline`](crate::pipeline::Pipeline) ([`Input::Layout`](crate::pipeline::Input::Layout)).
    pub layout: Layout,
    /// What was done.
    pub report: LayoutReport,
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The sides of loop `id` of `domain` as spline curves on `[0, 1]`.
fn loop_curves(domain: &Domain, id: LoopId, diameter: f64, fit: &FitOptions) -> Result<Vec<Curve>> {
    let l = domain.loop_of(id);
    let n = l.sides.len();
    let corners: Vec<Point> = l.sides.iter().map(|s| s.endpoints().0).collect();
    l.sides
        .iter()
        .enumerate()
        .map(|(k, s)| match s {
            SideCurve::Spline(c) => Ok(c.normalized()),
            other => {
                let ends = (corners[k], corners[(k + 1) % n]);
                let f = fit_side(Side::South, other, ends, fit, fit.tol * diameter)
                    .map_err(|e| domain_error(id, Some(k), format!("its fit failed: {e}")))?;
                Ok(f.finest().clone())
            }
        })
        .collect()
}

/// The sides of loop `id` added to `g` as a closed cycle of boundary edges (each
/// joint a vertex; the ends of consecutive curves made equal bit for bit).
fn add_loop(g: &mut Graph, d: &Domain, id: LoopId, diameter: f64, fit: &FitOptions) -> Result<Vec<FaceSide>> {
    let mut curves = loop_curves(d, id, diameter, fit)?;
    let n = curves.len();
    let first = g.vertices.len();
    for c in &curves {
        g.add_vertex(c.control_points[0]);
    }
    for (k, c) in curves.iter_mut().enumerate() {
        let last = c.control_points.len() - 1;
        c.control_points[last] = g.vertices[first + (k + 1) % n];
    }
    Ok(curves
        .into_iter()
        .enumerate()
        .map(|(k, c)| (g.add_edge(c, first + k, first + (k + 1) % n, true), true))
        .collect())
}

/// How a face is quadrangulated.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Template {
    /// Four corners, no side split: one patch.
    One,
    /// Four corners, sides `r` and `r + 2` split: two patches.
    Two(usize),
    /// `N` quads around the image of the polygon's centre.
    Midpoint,
}

/// The edges to split at their midpoints: every edge of a face that is not four-sided,
/// and, through every four-sided face, the edge opposite a split one.
fn edges_to_split(g: &Graph) -> Vec<bool> {
    let mut split = vec![false; g.edges.len()];
    for f in &g.faces {
        if f.sides.len() != 4 {
            for &(e, _) in &f.sides {
                split[e] = true;
            }
        }
    }
    loop {
        let mut changed = false;
        for f in g.faces.iter().filter(|f| f.sides.len() == 4) {
            for k in 0..4 {
                let (a, b) = (f.sides[k].0, f.sides[(k + 2) % 4].0);
                if split[a] && !split[b] {
                    split[b] = true;
                    changed = true;
                }
            }
        }
        if !changed {
            return split;
        }
    }
}

/// The halves of every side of a face after its edges were split: per original side,
/// the first and second half (in the face's direction) and the vertex between them, or
/// the side itself when it was not split.
type Halves = Vec<Result<(FaceSide, FaceSide, usize), FaceSide>>;

fn halves(g: &Graph, f: usize, mids: &[Option<usize>], n: usize) -> Halves {
    let cur = &g.faces[f].sides;
    let mut out = Vec::with_capacity(n);
    let mut k = 0;
    for _ in 0..n {
        let first = cur[k];
        let end = g.start(cur[(k + 1) % cur.len()]);
        if mids.get(end).copied().flatten().is_some() {
            out.push(Ok((first, cur[k + 1], end)));
            k += 2;
        } else {
            out.push(Err(first));
            k += 1;
        }
    }
    out
}

/// A point about which the closed counter-clockwise polyline `p` is strictly
/// star-shaped (every `(p_i - c) × (p_{i+1} - c) > 0`, so every ray from `c` meets the
/// boundary once and the straight segments from `c` to boundary points cut the face
/// into simple sectors): `first` if it is one, else the area centroid, else the mean
/// of the vertices; `None` when none is.
pub(super) fn star_centre(p: &[Point], first: Point) -> Option<Point> {
    let n = p.len();
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let (u, v) = (p[i], p[(i + 1) % n]);
        let w = u[0] * v[1] - v[0] * u[1];
        a += w;
        cx += (u[0] + v[0]) * w;
        cy += (u[1] + v[1]) * w;
    }
    let centroid = [cx / (3.0 * a), cy / (3.0 * a)];
    let mean = p.iter().fold([0.0, 0.0], |m, q| [m[0] + q[0] / n as f64, m[1] + q[1] / n as f64]);
    [first, centroid, mean].into_iter().find(|c| {
        (0..n).all(|i| {
            let (u, v) = (p[i], p[(i + 1) % n]);
            (u[0] - c[0]) * (v[1] - c[1]) - (u[1] - c[1]) * (v[0] - c[0]) > 0.0
        })
    })
}

/// A spoke of the harmonic map as a curve from `from` to `to` (its exact ends).
fn spoke_curve(
    mut pts: Vec<Point>,
    from: Point,
    to: Point,
    diameter: f64,
    scale: f64,
    fit: &FitOptions,
) -> Result<Curve> {
    let last = pts.len() - 1;
    pts[0] = from;
    pts[last] = to;
    fit_points(&pts, diameter, scale, fit)
}

/// Lay out `domain` (see the module documentation).
pub fn auto_layout(domain: &Domain, opts: &LayoutOptions) -> Result<AutoLayout> {
    let t0 = Instant::now();
    opts.fit.validate()?;
    let mut d = domain.clone();
    let checked = validate_domain(&mut d)?;
    let diameter = checked.diameter;
    let n = d.outer.sides.len();
    if n < 3 && d.holes.is_empty() {
        return Err(domain_error(
            LoopId::Outer,
            None,
            format!("has {n} corner(s): the automatic layout needs at least 3 (list the corners, or give more curves)"),
        ));
    }
    // 1. the outer loop as one face, the holes as its holes
    let mut g = Graph::default();
    let sides = add_loop(&mut g, &d, LoopId::Outer, diameter, &opts.fit)?;
    let mut face = Face::new(sides, "domain");
    for k in 0..d.holes.len() {
        face.holes.push(add_loop(&mut g, &d, LoopId::Hole(k), diameter, &opts.fit)?);
    }
    g.faces.push(face);
    let area = checked.area;
    lay_out_graph(g, &d.name, diameter, area, (Some(checked), None), opts, t0, &CUT_SEARCHES)
}

/// Lay out the plane graph `pg`: its faces (with their holes and labels) as
/// `build_graph` finds them, then as a domain's (see the module documentation).
pub fn graph_layout(pg: &PlaneGraph, opts: &LayoutOptions) -> Result<AutoLayout> {
    let t0 = Instant::now();
    opts.fit.validate()?;
    let (g, report) = build_graph(pg, &opts.fit)?;
    let (diameter, area) = (report.diameter, report.area);
    lay_out_graph(g, &pg.name, diameter, area, (None, Some(report)), opts, t0, &CUT_SEARCHES)
}

/// [`graph_layout`] with the given searches of the cuts' ends in turn (tests reach the
/// curved cuts with `[f64::NEG_INFINITY]`: never a search).
#[cfg(test)]
pub(super) fn graph_layout_searching(pg: &PlaneGraph, opts: &LayoutOptions, searches: &[f64]) -> Result<AutoLayout> {
    let t0 = Instant::now();
    let (g, report) = build_graph(pg, &opts.fit)?;
    let (diameter, area) = (report.diameter, report.area);
    lay_out_graph(g, &pg.name, diameter, area, (None, Some(report)), opts, t0, searches)
}

/// Points on a spoke taken from a [`PolygonMap`] before the spline fit.
const SPOKE_SAMPLES: usize = 64;

/// The searches of the cuts' ends tried in turn on a domain without holes until the
/// layout is valid (radians, [`cut_reflex`]): below 30 degrees, only where no straight
/// cut along the bisector or a side extension stays inside, always.
const CUT_SEARCHES: [f64; 3] = [GOOD_CUT_ANGLE, 0.0, std::f64::consts::PI];

/// The directions (degrees) of the cuts from holes that are tried; `NaN`: every hole
/// toward its nearest neighbour ([`cut_holes`]).
const HOLE_CUT_DIRECTIONS: [f64; 5] = [f64::NAN, 0.0, 90.0, 45.0, 135.0];

/// Steps 2 to 4 on a graph of faces (with holes). Without holes, the layout is made with
/// every search of the cuts' ends in `searches` in turn until it is valid
/// ([`validate_layout`]: no patch crossing itself or another). With holes, it is made
/// with the first search for every cut direction of [`HOLE_CUT_DIRECTIONS`] and the valid
/// one whose smallest patch corner angle is largest is kept; every try is in the report.
#[allow(clippy::too_many_arguments)]
fn lay_out_graph(
    g: Graph,
    name: &str,
    diameter: f64,
    area: f64,
    checked: (Option<DomainReport>, Option<GraphReport>),
    opts: &LayoutOptions,
    t0: Instant,
    searches: &[f64],
) -> Result<AutoLayout> {
    if g.faces.iter().all(|f| f.holes.is_empty()) {
        // per search of the cuts' ends: the harmonic maps' cuts, and where they leave a
        // face or cross, their preimages under the maps of the faces onto the polygons;
        // the first valid layout is kept, else the first one made (which the solve
        // refuses, naming the patch), else the first error
        let mut first: Option<Result<AutoLayout>> = None;
        for &search in searches {
            for inverse in [false, true] {
                let auto =
                    lay_out_with(g.clone(), name, diameter, area, checked.clone(), opts, t0, f64::NAN, inverse, search);
                if auto.as_ref().is_ok_and(|a| validate_layout(&a.layout).is_ok()) {
                    return auto;
                }
                if first.as_ref().is_none_or(|f| f.is_err() && auto.is_ok()) {
                    first = Some(auto);
                }
            }
        }
        return first.unwrap_or_else(|| Err(Error::Invalid("layout: no search of the cuts was tried".into())));
    }
    let first_search = searches.first().copied().unwrap_or(GOOD_CUT_ANGLE);
    let mut best: Option<(AutoLayout, bool)> = None;
    let mut first_err = None;
    let mut tries = Vec::new();
    for inverse in [false, true] {
        if best.as_ref().is_some_and(|b| b.1) {
            break;
        }
        for theta in HOLE_CUT_DIRECTIONS {
            match lay_out_with(g.clone(), name, diameter, area, checked.clone(), opts, t0, theta, inverse, first_search)
            {
                Ok(auto) => {
                    let valid = validate_layout(&auto.layout);
                    let min_angle = auto.report.corner_angles[0];
                    tries.push(HoleCutTry {
                        direction: (!theta.is_nan()).then_some(theta),
                        inverse,
                        patches: auto.layout.patches.len(),
                        min_corner_angle: Some(min_angle),
                        error: valid.as_ref().err().map(ToString::to_string),
                    });
                    let better = best.as_ref().is_none_or(|(b, b_ok)| {
                        (valid.is_ok() && !b_ok)
                            || (!inverse && valid.is_ok() == *b_ok && min_angle > b.report.corner_angles[0])
                            || (inverse && valid.is_ok() && min_angle > b.report.corner_angles[0])
                    });
                    if better {
                        best = Some((auto, valid.is_ok()));
                    }
                }
                Err(e) => {
                    tries.push(HoleCutTry {
                        direction: (!theta.is_nan()).then_some(theta),
                        inverse,
                        patches: 0,
                        min_corner_angle: None,
                        error: Some(e.to_string()),
                    });
                    first_err.get_or_insert(e);
                }
            }
        }
    }
    match (best, first_err) {
        (Some((mut auto, _)), _) => {
            auto.report.hole_cut_tries = tries;
            auto.report.seconds = t0.elapsed().as_secs_f64();
            Ok(auto)
        }
        (None, Some(e)) => Err(e),
        (None, None) => Err(Error::Invalid("layout: no direction of cuts from holes was tried".into())),
    }
}

/// One try of a direction of the cuts from holes.
#[derive(Debug, Clone, Serialize)]
pub struct HoleCutTry {
    /// The direction, degrees from the `x` axis (and the opposite one); `null`: every
    /// hole toward its nearest neighbour.
    pub direction: Option<f64>,
    /// The cuts of the faces' templates by the maps of the faces onto the polygons
    /// (`PolygonMap`; tried when no direction gives a valid layout otherwise).
    pub inverse: bool,
    /// Patches of the layout.
    pub patches: usize,
    /// Its smallest patch corner angle, degrees.
    pub min_corner_angle: Option<f64>,
    /// Why the layout is not valid (or was not made).
    pub error: Option<String>,
}

/// Steps 2 to 4 with the cuts from holes in direction `theta` (degrees), the cuts'
/// ends searched along the sides below the smallest new angle `search` (radians,
/// [`cut_reflex`]).
#[allow(clippy::too_many_arguments)]
fn lay_out_with(
    mut g: Graph,
    name: &str,
    diameter: f64,
    area: f64,
    checked: (Option<DomainReport>, Option<GraphReport>),
    opts: &LayoutOptions,
    t0: Instant,
    theta: f64,
    inverse: bool,
    search: f64,
) -> Result<AutoLayout> {
    let mut hole_cuts = Vec::new();
    cut_holes(&mut g, diameter, theta, &mut hole_cuts)?;
    // 2. reflex corners
    let mut cuts = Vec::new();
    cut_reflex(&mut g, diameter, &opts.fit, search, &mut cuts)?;
    // 3. templates: harmonic maps on the faces as they are, then the splits
    let split = edges_to_split(&g);
    let nf = g.faces.len();
    #[allow(clippy::type_complexity)]
    let mut plans: Vec<(Template, usize, Option<HarmonicMap>, Option<PolygonMap>)> = Vec::with_capacity(nf);
    // per face: ten times its area over its perimeter (the fit scale of its cuts)
    let scales: Vec<f64> = (0..nf)
        .map(|f| {
            let p = polyline(&g, &g.faces[f].sides);
            let perimeter: f64 = (0..p.len()).map(|i| dist(p[i], p[(i + 1) % p.len()])).sum();
            10.0 * signed_area(&p).abs() / perimeter.max(f64::MIN_POSITIVE)
        })
        .collect();
    for f in 0..nf {
        let sides = &g.faces[f].sides;
        let k = sides.len();
        let template = if k != 4 || sides.iter().all(|s| split[s.0]) {
            Template::Midpoint
        } else if split[sides[0].0] {
            Template::Two(0)
        } else if split[sides[1].0] {
            Template::Two(1)
        } else {
            Template::One
        };
        let curves: Vec<Curve> =
            if template == Template::One { Vec::new() } else { sides.iter().map(|&s| g.side_curve(s)).collect() };
        let h = (template != Template::One).then(|| HarmonicMap::new(&curves, opts.rings));
        // a face the map cannot be built on keeps the harmonic map's cuts
        let pm = (inverse && template != Template::One)
            .then(|| PolygonMap::new(&curves, opts.rings, POLYGON_MAP_LEVELS).ok())
            .flatten();
        plans.push((template, k, h, pm));
    }
    let mut mids: Vec<Option<usize>> = Vec::new();
    for e in 0..split.len() {
        if split[e] {
            let u = ArcLength::new(&g.edges[e].curve).param(0.5);
            let (v, _) = g.split_edge(e, u)?;
            mids.resize(g.vertices.len(), None);
            mids[v] = Some(e);
        }
    }
    mids.resize(g.vertices.len(), None);
    let mut faces = Vec::with_capacity(nf);
    for (f, (template, k, h, pm)) in plans.into_iter().enumerate() {
        let label = g.faces[f].label.clone();
        let hv = halves(&g, f, &mids, k);
        let mut report = FaceReport {
            label: label.clone(),
            corners: k,
            template: "one patch",
            patches: 1,
            centre: None,
            harmonic_min_area_ratio: h.as_ref().map(|h| h.min_area_ratio),
            straight: false,
            inverse: false,
        };
        match (template, h) {
            (Template::One, _) | (_, None) => {}
            (Template::Two(r), Some(h)) => {
                let (Ok((a0, b0, m0)), Err(s1), Ok((a2, b2, m2)), Err(s3)) =
                    (hv[r], hv[(r + 1) % 4], hv[(r + 2) % 4], hv[(r + 3) % 4])
                else {
                    return Err(Error::Invalid(format!("layout: face {f} is not split in two as planned")));
                };
                let (p0, p2) = (g.vertices[m0], g.vertices[m2]);
                let through = pm.as_ref().and_then(|pm| {
                    let mut pts: Vec<Point> = pm.spoke(r, SPOKE_SAMPLES)?.into_iter().rev().collect();
                    pts.extend(pm.spoke(r + 2, SPOKE_SAMPLES)?.into_iter().skip(1));
                    Some(pts)
                });
                let c = if let Some(pts) = through {
                    report.inverse = true;
                    spoke_curve(pts, p0, p2, diameter, scales[f], &opts.fit)?
                } else if h.min_area_ratio <= 0.0 && segment_inside(&g, f, p0, p2, 1e-9 * diameter) {
                    report.straight = true;
                    line(p0, p2)
                } else {
                    let mut pts: Vec<Point> = h.spoke(r).into_iter().rev().collect();
                    pts.extend(h.spoke(r + 2).into_iter().skip(1));
                    spoke_curve(pts, p0, p2, diameter, scales[f], &opts.fit)?
                };
                let cut = g.add_edge(c, m0, m2, false);
                g.faces[f].sides = vec![b0, s1, a2, (cut, false)];
                g.faces.push(Face::new(vec![b2, s3, a0, (cut, true)], label.clone()));
                report.template = "split in two";
                report.patches = 2;
            }
            (Template::Midpoint, Some(h)) => {
                // a folded harmonic map: straight spokes from a point the face is
                // star-shaped about, where there is one
                let inv = pm.as_ref().and_then(|pm| {
                    let spokes: Option<Vec<Vec<Point>>> = (0..k).map(|s| pm.spoke(s, SPOKE_SAMPLES)).collect();
                    Some((pm.centre()?, spokes?))
                });
                let star = (inv.is_none() && h.min_area_ratio <= 0.0)
                    .then(|| star_centre(&polyline(&g, &g.faces[f].sides), h.centre()))
                    .flatten();
                report.straight = star.is_some();
                report.inverse = inv.is_some();
                let centre = g.add_vertex(inv.as_ref().map(|i| i.0).or(star).unwrap_or_else(|| h.centre()));
                let mut spokes = Vec::with_capacity(k);
                let mut parts = Vec::with_capacity(k);
                for (s, side) in hv.iter().enumerate() {
                    let &Ok((a, b, m)) = side else {
                        return Err(Error::Invalid(format!("layout: side {s} of face {f} is not split as planned")));
                    };
                    let c = if let Some((_, spokes)) = &inv {
                        spoke_curve(
                            spokes[s].clone(),
                            g.vertices[centre],
                            g.vertices[m],
                            diameter,
                            scales[f],
                            &opts.fit,
                        )?
                    } else if star.is_some() {
                        line(g.vertices[centre], g.vertices[m])
                    } else {
                        spoke_curve(h.spoke(s), g.vertices[centre], g.vertices[m], diameter, scales[f], &opts.fit)?
                    };
                    spokes.push(g.add_edge(c, centre, m, false));
                    parts.push((a, b));
                }
                for s in 0..k {
                    let prev = (s + k - 1) % k;
                    let sides = vec![parts[s].0, (spokes[s], false), (spokes[prev], true), parts[prev].1];
                    if s == 0 {
                        g.faces[f].sides = sides;
                    } else {
                        g.faces.push(Face::new(sides, label.clone()));
                    }
                }
                report.template = "midpoint";
                report.patches = k;
                report.centre = Some(g.vertices[centre]);
            }
        }
        faces.push(report);
    }
    // 4. the layout
    let layout = layout_of(&g, name)?;
    let valence = g.valences();
    let boundary = g.on_boundary();
    let irregular_vertices = (0..g.vertices.len())
        .filter(|&v| !boundary[v] && valence[v] != 4)
        .map(|v| IrregularVertex { point: g.vertices[v], valence: valence[v] })
        .collect();
    let mut corner_angles = [f64::INFINITY, f64::NEG_INFINITY];
    for f in 0..g.faces.len() {
        for i in 0..4 {
            let a = g.corner_angle(f, i).to_degrees();
            corner_angles = [corner_angles[0].min(a), corner_angles[1].max(a)];
        }
    }
    let report = LayoutReport {
        domain: checked.0,
        graph: checked.1,
        area,
        hole_cuts,
        hole_cut_direction: (!theta.is_nan()).then_some(theta),
        hole_cut_tries: Vec::new(),
        cuts,
        cut_search: search.to_degrees(),
        faces,
        irregular_vertices,
        patches: layout.patches.len(),
        corner_angles,
        seconds: t0.elapsed().as_secs_f64(),
    };
    Ok(AutoLayout { layout, report })
}

/// The multipatch layout of a graph whose faces are all four-sided.
fn layout_of(g: &Graph, name: &str) -> Result<Layout> {
    let mut patches = Vec::with_capacity(g.faces.len());
    // per edge: the patch sides along it and whether each runs with the edge
    let mut users: Vec<Vec<(PatchSide, bool)>> = vec![Vec::new(); g.edges.len()];
    for (p, f) in g.faces.iter().enumerate() {
        if f.sides.len() != 4 {
            return Err(Error::Invalid(format!("layout: face {p} has {} sides, not 4", f.sides.len())));
        }
        let mut sides = Vec::with_capacity(4);
        for (k, side) in Side::ALL.into_iter().enumerate() {
            let (e, fwd) = f.sides[k];
            // south and east run with the face, north and west against it
            let along = fwd != matches!(side, Side::North | Side::West);
            let c = &g.edges[e].curve;
            sides.push(if along { c.clone() } else { c.reversed().normalized() });
            users[e].push((PatchSide { patch: p, side }, along));
        }
        let mut patch = Patch::from_sides(format!("p{p}"), sides.try_into().expect("four sides"));
        patch.face = Some(f.label.clone());
        patches.push(patch);
    }
    let mut interfaces = Vec::new();
    for (e, u) in users.iter().enumerate() {
        match u.as_slice() {
            [] | [_] => {}
            [(a, ra), (b, rb)] => interfaces.push(Interface { first: *a, second: *b, reversed: ra != rb }),
            _ => return Err(Error::Invalid(format!("layout: edge {e} is a side of {} patches", u.len()))),
        }
    }
    Ok(Layout { name: name.to_string(), patches, interfaces })
}
