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
//! 3. **Templates** ([`super::template`]): a face with four corners stays one patch;
//!    every other face is quadrangulated by its template, placed by the harmonic map of
//!    the regular polygon onto the face. When the layout so made is not valid (a cut
//!    leaves its face or crosses another, in every direction of the hole cuts), it is
//!    made again with the templates placed by the inverse of the map of each face onto
//!    the polygon (`PolygonMap`, one-to-one on every face).
//! 4. **Layout**: every face is now a patch (south, east, reversed north and reversed west
//!    are its four sides; an edge shared by two patches is an interface), named `p0`,
//!    `p1`, ..., each with the label of its face (`"domain"`, or the graph face's).
//!
//! The report lists every cut, every face's template and the interior vertices whose
//! valence is not 4.

use std::time::Instant;

use serde::Serialize;

use super::graph::{Face, FaceSide, Graph};
use super::holes::{cut_holes, HoleCut};
use super::plane::{build_graph, GraphReport, PlaneGraph};
use super::reflex::{cut_reflex, CutReport, GOOD_CUT_ANGLE};
use super::spokes::MIN_TEMPLATE_ANGLE;
use super::template::{apply_templates, FaceReport, IrregularVertex};
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
/// Either way the layout through the maps of the faces onto the polygons is made when the
/// first has no valid layout or only one with a patch corner below `MIN_TEMPLATE_ANGLE`.
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
        // face or cross (or the valid layout has a patch corner below
        // `MIN_TEMPLATE_ANGLE`), their preimages under the maps of
        // the faces onto the polygons; the first valid layout is kept (of two, the one
        // whose smallest patch corner angle is larger), else the first one made (which
        // the solve refuses, naming the patch), else the first error
        let mut first: Option<Result<AutoLayout>> = None;
        for &search in searches {
            let mut valid: Option<AutoLayout> = None;
            for inverse in [false, true] {
                let auto =
                    lay_out_with(g.clone(), name, diameter, area, checked.clone(), opts, t0, f64::NAN, inverse, search);
                match auto {
                    Ok(a) if validate_layout(&a.layout).is_ok() => {
                        if valid.as_ref().is_none_or(|v| a.report.corner_angles[0] > v.report.corner_angles[0]) {
                            valid = Some(a);
                        }
                        if valid.as_ref().is_some_and(|v| !sharp(&v.report)) {
                            break;
                        }
                    }
                    auto => {
                        if first.as_ref().is_none_or(|f| f.is_err() && auto.is_ok()) {
                            first = Some(auto);
                        }
                    }
                }
            }
            if let Some(v) = valid {
                return Ok(v);
            }
        }
        return first.unwrap_or_else(|| Err(Error::Invalid("layout: no search of the cuts was tried".into())));
    }
    let first_search = searches.first().copied().unwrap_or(GOOD_CUT_ANGLE);
    let mut best: Option<(AutoLayout, bool)> = None;
    let mut first_err = None;
    let mut tries = Vec::new();
    for inverse in [false, true] {
        if best.as_ref().is_some_and(|b| b.1 && !sharp(&b.0.report)) {
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

/// Whether a layout has a patch corner below `MIN_TEMPLATE_ANGLE` (15 degrees): then the
/// layout through the maps of the faces onto the polygons is made too, and the one with
/// the larger smallest corner kept.
fn sharp(r: &LayoutReport) -> bool {
    r.corner_angles[0] < MIN_TEMPLATE_ANGLE
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
    // 3. templates
    let faces = apply_templates(&mut g, &opts.fit, opts.rings, diameter, inverse)?;
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
