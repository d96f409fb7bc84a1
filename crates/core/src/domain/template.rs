//! The templates of the automatic layout (issue 31, step 3 of [`super::layout`]): a face
//! with four corners stays one patch. Every other face with `N` corners is cut into `N`
//! quads around one interior vertex (valence `N`), the midpoint template: the harmonic
//! map of the regular `N`-gon onto the face (`HarmonicMap`, Hinz & Buffa) places the
//! interior vertex (the image of the polygon's centre) and the cuts (the images of the
//! segments from the centre to the midpoints of the sides, fitted by splines); the sides
//! are split at their arc-length midpoints, the images of the polygon's side midpoints. A
//! four-sided face beside a split edge is split too, by the image of the segment between
//! the midpoints of that edge and the opposite one (so the splits run through chains of
//! four-sided faces and the layout stays conforming), or into four when both pairs are
//! split. Where the layout so made is not valid, the interior vertex and the cuts are
//! placed by the inverse of the map of the face onto the polygon (`PolygonMap`,
//! one-to-one on every face); where a harmonic map folds and no such map is taken, the
//! cuts are straight from a point the face is star-shaped about.
//!
//! The report of every face ([`FaceReport`]) and the interior vertices whose valence is
//! not 4 ([`IrregularVertex`]) are defined here.

use serde::Serialize;

use super::cycles::{polyline, signed_area};
use super::graph::end_tangent;
use super::graph::{Face, FaceSide, Graph};
use super::harmonic::{ArcLength, HarmonicMap};
use super::polygon_map::{PolygonMap, POLYGON_MAP_LEVELS};
use super::reflex::{fit_points, line, segment_inside};
use super::spokes::{curve_angles, score, search_centre, MIN_TEMPLATE_ANGLE};
use crate::boundary::fit::FitOptions;
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};

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
    /// The smallest of the patch corner angles the template made (degrees; the midpoint
    /// template: at the interior vertex and at the side midpoints, `domain::spokes`).
    pub min_angle: Option<f64>,
    /// The search of the interior vertex, where the first placement had a new patch
    /// corner within `MIN_TEMPLATE_ANGLE` (15) degrees of 0 or 180.
    pub angle_search: Option<AngleSearch>,
}

/// The search of a midpoint template's interior vertex in the parameter domain of the
/// face's map onto the polygon (`domain::spokes`).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct AngleSearch {
    /// The first placement's score: its smallest `min(α, 180° − α)` over the new patch
    /// corners `α`, degrees.
    pub first: f64,
    /// The point of the regular polygon (inscribed in the unit circle) whose preimage is
    /// the searched interior vertex (`None`: no map onto the polygon, or no point with a
    /// preimage).
    pub polygon_point: Option<Point>,
    /// The searched placement's score (its spokes fitted), degrees.
    pub searched: Option<f64>,
    /// The searched placement scores higher and was taken: the spokes are the preimages
    /// of the segments from `polygon_point` to the polygon's side midpoints, not those
    /// `straight` and `inverse` describe.
    pub kept: bool,
}

/// An interior vertex whose valence is not 4.
#[derive(Debug, Clone, Serialize)]
pub struct IrregularVertex {
    /// Where.
    pub point: Point,
    /// Number of patches (edges) meeting there.
    pub valence: usize,
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
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

/// Points on a spoke taken from a [`PolygonMap`] before the spline fit.
const SPOKE_SAMPLES: usize = 64;

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
    // 3. templates: harmonic maps on the faces as they are, then the splits
    let split = edges_to_split(g);
    let nf = g.faces.len();
    #[allow(clippy::type_complexity)]
    let mut plans: Vec<(Template, usize, Option<HarmonicMap>, Option<PolygonMap>, Vec<Curve>)> = Vec::with_capacity(nf);
    // per face: ten times its area over its perimeter (the fit scale of its cuts)
    let scales: Vec<f64> = (0..nf)
        .map(|f| {
            let p = polyline(g, &g.faces[f].sides);
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
                    spoke_curve(pts, p0, p2, diameter, scales[f], fit)?
                } else if h.min_area_ratio <= 0.0 && segment_inside(g, f, p0, p2, 1e-9 * diameter) {
                    report.straight = true;
                    line(p0, p2)
                } else {
                    let mut pts: Vec<Point> = h.spoke(r).into_iter().rev().collect();
                    pts.extend(h.spoke(r + 2).into_iter().skip(1));
                    spoke_curve(pts, p0, p2, diameter, scales[f], fit)?
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
                    .then(|| star_centre(&polyline(g, &g.faces[f].sides), h.centre()))
                    .flatten();
                report.straight = star.is_some();
                report.inverse = inv.is_some();
                let mut centre_point = inv.as_ref().map(|i| i.0).or(star).unwrap_or_else(|| h.centre());
                let mut mids = Vec::with_capacity(k);
                let mut parts = Vec::with_capacity(k);
                for (s, side) in hv.iter().enumerate() {
                    let &Ok((a, b, m)) = side else {
                        return Err(Error::Invalid(format!("layout: side {s} of face {f} is not split as planned")));
                    };
                    mids.push(m);
                    parts.push((a, b));
                }
                let mut cuts = Vec::with_capacity(k);
                for (s, &m) in mids.iter().enumerate() {
                    let to = g.vertices[m];
                    cuts.push(if let Some((_, spokes)) = &inv {
                        spoke_curve(spokes[s].clone(), centre_point, to, diameter, scales[f], fit)?
                    } else if star.is_some() {
                        line(centre_point, to)
                    } else {
                        spoke_curve(h.spoke(s), centre_point, to, diameter, scales[f], fit)?
                    });
                }
                // the new patch corners; near 0 or 180 degrees, the interior vertex searched
                let at_mids: Vec<(Point, Point)> = parts
                    .iter()
                    .map(|&(a, b)| (end_tangent(&g.side_curve(a), true), end_tangent(&g.side_curve(b), false)))
                    .collect();
                let mut angles = curve_angles(&cuts, &at_mids);
                let first = score(&angles);
                if first < MIN_TEMPLATE_ANGLE {
                    let built =
                        if pm.is_none() { PolygonMap::new(&curves, rings, POLYGON_MAP_LEVELS).ok() } else { None };
                    let mut search = AngleSearch { first, polygon_point: None, searched: None, kept: false };
                    if let Some(pm) = pm.as_ref().or(built.as_ref()) {
                        let found = search_centre(pm, &at_mids).and_then(|(q, _)| {
                            let spokes: Option<Vec<Vec<Point>>> =
                                (0..k).map(|s| pm.segment(q, pm.side_midpoint(s), SPOKE_SAMPLES)).collect();
                            Some((q, pm.inverse(q)?, spokes?))
                        });
                        if let Some((q, x, spokes)) = found {
                            search.polygon_point = Some(q);
                            let fitted: Option<Vec<Curve>> = spokes
                                .into_iter()
                                .zip(&mids)
                                .map(|(pts, &m)| spoke_curve(pts, x, g.vertices[m], diameter, scales[f], fit).ok())
                                .collect();
                            if let Some(fitted) = fitted {
                                let a = curve_angles(&fitted, &at_mids);
                                let v = score(&a);
                                search.searched = Some(v);
                                if v > first {
                                    search.kept = true;
                                    (centre_point, cuts, angles) = (x, fitted, a);
                                }
                            }
                        }
                    }
                    report.angle_search = Some(search);
                }
                report.min_angle = Some(angles.iter().fold(f64::INFINITY, |m, a| m.min(a.to_degrees())));
                let centre = g.add_vertex(centre_point);
                let spokes: Vec<usize> =
                    cuts.into_iter().zip(&mids).map(|(c, &m)| g.add_edge(c, centre, m, false)).collect();
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
    Ok(faces)
}
