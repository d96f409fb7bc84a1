//! The templates of the automatic layout (issue 31, step 3 of [`super::layout`]): a face
//! with four corners stays one patch. Every other face with `N` corners is cut into `N`
//! quads around one interior vertex (valence `N`), the midpoint template
//! (`domain::midpoint`): the harmonic map of the regular `N`-gon onto the face
//! (`HarmonicMap`, Hinz & Buffa) places the interior vertex (the image of the polygon's
//! centre) and the cuts (the images of the segments from the centre to the midpoints of
//! the sides, fitted by splines); the sides are split at their arc-length midpoints, the
//! images of the polygon's side midpoints. A four-sided face beside a split edge is split
//! too, by the image of the segment between the midpoints of that edge and the opposite
//! one (so the splits run through chains of four-sided faces and the layout stays
//! conforming), or into four when both pairs are split. Where the layout so made is not
//! valid, the interior vertex and the cuts are placed by the inverse of the map of the
//! face onto the polygon (`PolygonMap`, one-to-one on every face); where a harmonic map
//! folds and no such map is taken, the cuts are straight from a point the face is
//! star-shaped about.
//!
//! Every template's new patch corners are scored (`spokes::score`, the smallest
//! `min(α, 180° − α)`): below `MIN_TEMPLATE_ANGLE` (15°) the midpoint template's interior
//! vertex is searched (`super::spokes`), a face split in two tries its other placements
//! (the straight segment where it stays inside, the preimage through the map onto the
//! polygon), and a face of five corners or more whose midpoint template still scores
//! below 15° tries the cuts across it (`domain::crosscut`: two faces with fewer corners),
//! the best placement kept.
//!
//! The report of every face ([`FaceReport`]) and the interior vertices whose valence is
//! not 4 ([`IrregularVertex`]) are defined here.

use serde::Serialize;

use super::crosscut;
use super::cycles::polyline;
use super::graph::{end_tangent, Face, FaceSide, Graph};
use super::harmonic::{ArcLength, HarmonicMap};
use super::midpoint::{self, fit_scale, tangents_at_mid, CutFit, SplitFace, SPOKE_SAMPLES};
use super::polygon_map::{PolygonMap, POLYGON_MAP_LEVELS};
use super::reflex::{line, polyline_inside, segment_inside};
use super::spokes::{score, side_angles, MIN_TEMPLATE_ANGLE};
use crate::boundary::fit::FitOptions;
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};

pub use super::crosscut::{CrossCut, CrossFace};
pub use super::midpoint::AngleSearch;

/// The template of one face.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct FaceReport {
    /// The face's label.
    pub label: String,
    /// Its corners.
    pub corners: usize,
    /// `"one patch"`, `"split in two"`, `"midpoint"` (`N` quads around a vertex) or
    /// `"cut across"` (two faces with fewer corners, each by the midpoint template:
    /// `cut_across`).
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
    /// two midpoints of a face split in two when it lies inside. (A face cut across: its
    /// midpoint template's, which the cut replaced.)
    pub straight: bool,
    /// The cuts are the preimages of the polygon's segments under the map of the face
    /// onto the polygon (`PolygonMap`, one-to-one on every face), taken when the layout
    /// by the harmonic map of the polygon onto the faces is not valid. (A face cut
    /// across: its midpoint template's.)
    pub inverse: bool,
    /// The smallest of the patch corner angles the template made (degrees; the midpoint
    /// template: at the interior vertex and at the side midpoints, `domain::spokes`; a
    /// face split in two: the four where its cut meets the split sides; a face cut
    /// across: its cut's four and its two faces' templates').
    pub min_angle: Option<f64>,
    /// The search of the interior vertex, where the first placement had a new patch
    /// corner within `MIN_TEMPLATE_ANGLE` (15) degrees of 0 or 180 (a face cut across:
    /// its midpoint template's). A face split in two whose first cut scores below 15
    /// degrees: `first` its score, `searched` the best of its other placements (the
    /// straight segment where it stays inside, the preimage through the map onto the
    /// polygon), `kept` when that is higher; no `polygon_point`.
    pub angle_search: Option<AngleSearch>,
    /// The cut across the face (`template: "cut across"`), written only then.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_across: Option<CrossCut>,
}

/// An interior vertex whose valence is not 4.
#[derive(Debug, Clone, Serialize)]
pub struct IrregularVertex {
    /// Where.
    pub point: Point,
    /// Number of patches (edges) meeting there.
    pub valence: usize,
}

/// How a face is quadrangulated.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Template {
    /// Four corners, no side split: one patch.
    One,
    /// Four corners, sides `r` and `r + 2` split: two patches.
    Two(usize),
    /// `N` quads around the image of the polygon's centre (or, where that scores below
    /// 15 degrees, a cut across).
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

/// The four new patch corner angles (radians) of a face split in two by `c`, from the
/// midpoint between the halves `(a0, b0)` of one side to the midpoint between the halves
/// `(a2, b2)` of the opposite one (`spokes::side_angles` at each end).
fn split_angles(g: &Graph, c: &Curve, (a0, b0): (FaceSide, FaceSide), (a2, b2): (FaceSide, FaceSide)) -> Vec<f64> {
    let e0 = end_tangent(c, false);
    let e2 = end_tangent(c, true);
    let mut out = side_angles(e0, tangents_at_mid(g, a0, b0)).to_vec();
    out.extend(side_angles([-e2[0], -e2[1]], tangents_at_mid(g, a2, b2)));
    out
}

/// Step 3 of the layout (see [`super::layout`]): every face of `g` quadrangulated by its
/// template, the edges to split split at their arc-length midpoints; the template's
/// interior vertex and cuts placed by the harmonic map of the regular polygon onto the
/// face, or with `inverse` by the inverse of the face's map onto the polygon
/// ([`PolygonMap`]). Returns the report of every face.
/// `fit` fits the cuts, `rings` are the rings of each face's discrete harmonic map (the
/// layout options' `fit` and `rings`).
pub(super) fn apply_templates(
    g: &mut Graph,
    fit: &FitOptions,
    rings: usize,
    diameter: f64,
    inverse: bool,
) -> Result<Vec<FaceReport>> {
    let cf = CutFit { fit, rings, diameter };
    // 3. templates: harmonic maps on the faces as they are, then the splits
    let split = edges_to_split(g);
    let nf = g.faces.len();
    #[allow(clippy::type_complexity)]
    let mut plans: Vec<(Template, usize, Option<HarmonicMap>, Option<PolygonMap>, Vec<Curve>)> = Vec::with_capacity(nf);
    // per face: ten times its area over its perimeter (the fit scale of its cuts)
    let scales: Vec<f64> = (0..nf).map(|f| fit_scale(&polyline(g, &g.faces[f].sides))).collect();
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
        let h = (template != Template::One).then(|| HarmonicMap::new(&curves, rings));
        // a face the map cannot be built on keeps the harmonic map's cuts
        let pm = (inverse && template != Template::One)
            .then(|| PolygonMap::new(&curves, rings, POLYGON_MAP_LEVELS).ok())
            .flatten();
        plans.push((template, k, h, pm, curves));
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
    for (f, (template, k, h, pm, curves)) in plans.into_iter().enumerate() {
        let label = g.faces[f].label.clone();
        let hv = halves(g, f, &mids, k);
        let mut report = FaceReport {
            label: label.clone(),
            corners: k,
            template: "one patch",
            patches: 1,
            centre: None,
            harmonic_min_area_ratio: h.as_ref().map(|h| h.min_area_ratio),
            straight: false,
            inverse: false,
            min_angle: None,
            angle_search: None,
            cut_across: None,
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
                let through = |pm: &PolygonMap| {
                    let mut pts: Vec<Point> = pm.spoke(r, SPOKE_SAMPLES)?.into_iter().rev().collect();
                    pts.extend(pm.spoke(r + 2, SPOKE_SAMPLES)?.into_iter().skip(1));
                    Some(pts)
                };
                let tol = 1e-9 * diameter;
                let c = if let Some(pts) = pm.as_ref().and_then(through) {
                    report.inverse = true;
                    cf.curve(pts, p0, p2, scales[f])?
                } else if h.min_area_ratio <= 0.0 && segment_inside(g, f, p0, p2, tol) {
                    report.straight = true;
                    line(p0, p2)
                } else {
                    let mut pts: Vec<Point> = h.spoke(r).into_iter().rev().collect();
                    pts.extend(h.spoke(r + 2).into_iter().skip(1));
                    cf.curve(pts, p0, p2, scales[f])?
                };
                let mut angles = split_angles(g, &c, (a0, b0), (a2, b2));
                let first = score(&angles);
                let mut c = c;
                if first < MIN_TEMPLATE_ANGLE {
                    // the other placements: the straight segment where it stays inside,
                    // the preimage through the map onto the polygon
                    let mut search = AngleSearch::new(first);
                    let mut others = Vec::new();
                    if !report.straight && segment_inside(g, f, p0, p2, tol) {
                        others.push((line(p0, p2), true, false));
                    }
                    if !report.inverse {
                        let built = PolygonMap::new(&curves, rings, POLYGON_MAP_LEVELS).ok();
                        let fitted =
                            built.as_ref().and_then(through).and_then(|pts| cf.curve(pts, p0, p2, scales[f]).ok());
                        others.extend(
                            fitted
                                .filter(|x| polyline_inside(g, f, &x.sample(4 * SPOKE_SAMPLES), tol))
                                .map(|x| (x, false, true)),
                        );
                    }
                    for (x, straight, inv) in others {
                        let a = split_angles(g, &x, (a0, b0), (a2, b2));
                        let v = score(&a);
                        if search.searched.is_none_or(|s| v > s) {
                            search.searched = Some(v);
                            if v > score(&angles) {
                                search.kept = true;
                                (c, angles, report.straight, report.inverse) = (x, a, straight, inv);
                            }
                        }
                    }
                    report.angle_search = Some(search);
                }
                report.min_angle = Some(angles.iter().fold(f64::INFINITY, |m, a| m.min(a.to_degrees())));
                let cut = g.add_edge(c, m0, m2, false);
                g.faces[f].sides = vec![b0, s1, a2, (cut, false)];
                g.faces.push(Face::new(vec![b2, s3, a0, (cut, true)], label.clone()));
                report.template = "split in two";
                report.patches = 2;
            }
            (Template::Midpoint, Some(h)) => {
                let mut parts = Vec::with_capacity(k);
                let mut mid_vertices = Vec::with_capacity(k);
                for (s, side) in hv.iter().enumerate() {
                    let &Ok((a, b, m)) = side else {
                        return Err(Error::Invalid(format!("layout: side {s} of face {f} is not split as planned")));
                    };
                    mid_vertices.push(m);
                    parts.push((a, b));
                }
                let whole = SplitFace {
                    mids: mid_vertices.iter().map(|&m| g.vertices[m]).collect(),
                    at_mids: parts.iter().map(|&(a, b)| tangents_at_mid(g, a, b)).collect(),
                    polyline: polyline(g, &g.faces[f].sides),
                    scale: scales[f],
                    curves,
                };
                let (placement, built) = midpoint::place(&whole, &h, pm.as_ref(), cf)?;
                report.straight = placement.straight;
                report.inverse = placement.inverse;
                report.angle_search = placement.search.clone();
                // still near 0 or 180 degrees: the cuts across the face
                let across = if placement.score() < MIN_TEMPLATE_ANGLE {
                    let map = pm.as_ref().or(built.as_ref());
                    crosscut::best(g, f, &whole, &parts, map, &placement, inverse, cf)?
                } else {
                    None
                };
                if let Some(plan) = across {
                    let min_angle = plan.min_angle();
                    let (r, patches) = crosscut::apply(g, f, &parts, &mid_vertices, plan, placement.score(), &label)?;
                    report.min_angle = Some(min_angle);
                    report.template = "cut across";
                    report.patches = patches;
                    report.cut_across = Some(r);
                } else {
                    report.min_angle = Some(placement.min_angle());
                    let centre = midpoint::apply(g, Some(f), &parts, &mid_vertices, placement, &label);
                    report.template = "midpoint";
                    report.patches = k;
                    report.centre = Some(g.vertices[centre]);
                }
            }
        }
        faces.push(report);
    }
    Ok(faces)
}
