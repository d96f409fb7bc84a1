//! The midpoint template (issue 31, step 3 of [`super::layout`]): a face of `N` corners
//! whose sides are split at their arc-length midpoints `m_s` is cut into `N` quads
//! around one interior vertex `c` (valence `N`) by the `N` cuts (spokes) from `c` to the
//! `m_s`; the quad `s` has the corners `(corner s, m_s, c, m_{s-1})`.
//!
//! Its placement ([`place`]): the harmonic map of the regular `N`-gon onto the face
//! (`HarmonicMap`, Hinz & Buffa) carries the polygon's centre to `c` and the segments
//! from the centre to the side midpoints to the spokes (fitted by splines); with the
//! face's map onto the polygon (`PolygonMap`, one-to-one on every face) the preimages of
//! those segments are taken instead; where the harmonic map folds and no such map is
//! given, the spokes are straight from a point the face is star-shaped about
//! ([`star_centre`]). Where the new patch corners score below
//! [`MIN_TEMPLATE_ANGLE`] (`super::spokes`), the interior vertex is searched in the
//! polygon and the searched placement kept when it scores higher.

use serde::Serialize;

use super::graph::{end_tangent, Face, FaceSide, Graph};
use super::harmonic::HarmonicMap;
use super::polygon_map::{PolygonMap, POLYGON_MAP_LEVELS};
use super::reflex::{fit_points, line};
use super::spokes::{curve_angles, score, search_centre, MIN_TEMPLATE_ANGLE};
use crate::boundary::fit::FitOptions;
use crate::error::Result;
use crate::spline::curve::{Curve, Point};

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

impl AngleSearch {
    /// A search whose first placement scored `first` (degrees), nothing found yet.
    pub(super) fn new(first: f64) -> Self {
        Self { first, polygon_point: None, searched: None, kept: false }
    }
}

/// Points on a spoke taken from a [`PolygonMap`] before the spline fit.
pub(super) const SPOKE_SAMPLES: usize = 64;

/// What the templates' cuts are fitted with: the fit options, the rings of the harmonic
/// maps (and boundary nodes a side of the maps onto the polygon), the domain's diameter.
#[derive(Debug, Clone, Copy)]
pub(super) struct CutFit<'a> {
    pub fit: &'a FitOptions,
    pub rings: usize,
    pub diameter: f64,
}

impl CutFit<'_> {
    /// A cut through the points `pts` as a curve from `from` to `to` (its exact ends),
    /// `scale` the fit scale of its face ([`fit_points`]).
    pub(super) fn curve(&self, mut pts: Vec<Point>, from: Point, to: Point, scale: f64) -> Result<Curve> {
        let last = pts.len() - 1;
        pts[0] = from;
        pts[last] = to;
        fit_points(&pts, self.diameter, scale, self.fit)
    }
}

/// A face as the midpoint template sees it: its whole sides (counter-clockwise, side `s`
/// from corner `s` to corner `s + 1`; the maps are made on them), the midpoints where
/// they are split, the unit tangents of the two halves at each midpoint (arriving,
/// leaving), its closed polyline and the fit scale of its cuts (ten times its area over
/// its perimeter).
#[derive(Debug, Clone)]
pub(super) struct SplitFace {
    pub curves: Vec<Curve>,
    pub mids: Vec<Point>,
    pub at_mids: Vec<(Point, Point)>,
    pub polyline: Vec<Point>,
    pub scale: f64,
}

/// The fit scale of the cuts of a face of closed polyline `p`: ten times its area over
/// its perimeter.
pub(super) fn fit_scale(p: &[Point]) -> f64 {
    let n = p.len();
    let perimeter: f64 = (0..n).map(|i| (p[i][0] - p[(i + 1) % n][0]).hypot(p[i][1] - p[(i + 1) % n][1])).sum();
    10.0 * super::cycles::signed_area(p).abs() / perimeter.max(f64::MIN_POSITIVE)
}

/// A placement of the midpoint template: the interior vertex, the spokes (spoke `s` from
/// it to the midpoint of side `s`), their new patch corner angles (radians,
/// `spokes::midpoint_angles`) and how they were made.
#[derive(Debug, Clone)]
pub(super) struct Placement {
    pub centre: Point,
    pub cuts: Vec<Curve>,
    pub angles: Vec<f64>,
    /// Straight spokes from a star centre (the harmonic map folds).
    pub straight: bool,
    /// The preimages under the map onto the polygon.
    pub inverse: bool,
    pub search: Option<AngleSearch>,
}

impl Placement {
    /// Its score, degrees (`spokes::score`).
    pub(super) fn score(&self) -> f64 {
        score(&self.angles)
    }

    /// Its smallest new patch corner angle, degrees.
    pub(super) fn min_angle(&self) -> f64 {
        self.angles.iter().fold(f64::INFINITY, |m, a| m.min(a.to_degrees()))
    }
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

/// The midpoint template's placement on `face` (see the module documentation): by the
/// face's map onto the polygon `pm` where one is given, else straight from a star centre
/// where the harmonic map `h` folds, else by `h`; searched where it scores below
/// [`MIN_TEMPLATE_ANGLE`]. Returns the placement and the map onto the polygon the search
/// built (when `pm` was `None` and the search ran).
pub(super) fn place(
    face: &SplitFace,
    h: &HarmonicMap,
    pm: Option<&PolygonMap>,
    cf: CutFit,
) -> Result<(Placement, Option<PolygonMap>)> {
    let k = face.curves.len();
    let inv = pm.and_then(|pm| {
        let spokes: Option<Vec<Vec<Point>>> = (0..k).map(|s| pm.spoke(s, SPOKE_SAMPLES)).collect();
        Some((pm.centre()?, spokes?))
    });
    // a folded harmonic map: straight spokes from a point the face is star-shaped about,
    // where there is one
    let star = (inv.is_none() && h.min_area_ratio <= 0.0).then(|| star_centre(&face.polyline, h.centre())).flatten();
    let mut centre = inv.as_ref().map(|i| i.0).or(star).unwrap_or_else(|| h.centre());
    let mut cuts = Vec::with_capacity(k);
    for (s, &to) in face.mids.iter().enumerate() {
        cuts.push(if let Some((_, spokes)) = &inv {
            cf.curve(spokes[s].clone(), centre, to, face.scale)?
        } else if star.is_some() {
            line(centre, to)
        } else {
            cf.curve(h.spoke(s), centre, to, face.scale)?
        });
    }
    // the new patch corners; near 0 or 180 degrees, the interior vertex searched
    let mut angles = curve_angles(&cuts, &face.at_mids);
    let first = score(&angles);
    let mut search = None;
    let mut built = None;
    if first < MIN_TEMPLATE_ANGLE {
        if pm.is_none() {
            built = PolygonMap::new(&face.curves, cf.rings, POLYGON_MAP_LEVELS).ok();
        }
        let mut s = AngleSearch::new(first);
        if let Some(pm) = pm.or(built.as_ref()) {
            let found = search_centre(pm, &face.at_mids).and_then(|(q, _)| {
                let spokes: Option<Vec<Vec<Point>>> =
                    (0..k).map(|s| pm.segment(q, pm.side_midpoint(s), SPOKE_SAMPLES)).collect();
                Some((q, pm.inverse(q)?, spokes?))
            });
            if let Some((q, x, spokes)) = found {
                s.polygon_point = Some(q);
                let fitted: Option<Vec<Curve>> =
                    spokes.into_iter().zip(&face.mids).map(|(pts, &m)| cf.curve(pts, x, m, face.scale).ok()).collect();
                if let Some(fitted) = fitted {
                    let a = curve_angles(&fitted, &face.at_mids);
                    let v = score(&a);
                    s.searched = Some(v);
                    if v > first {
                        s.kept = true;
                        (centre, cuts, angles) = (x, fitted, a);
                    }
                }
            }
        }
        search = Some(s);
    }
    let placement = Placement { centre, cuts, angles, straight: star.is_some(), inverse: inv.is_some(), search };
    Ok((placement, built))
}

/// The unit tangents `(t⁻, t⁺)` at the midpoint between the halves `a` and `b` of a side
/// (in the face's direction): `a` arriving there, `b` leaving.
pub(super) fn tangents_at_mid(g: &Graph, a: FaceSide, b: FaceSide) -> (Point, Point) {
    (end_tangent(&g.side_curve(a), true), end_tangent(&g.side_curve(b), false))
}

/// The placement `p` made in the graph: the interior vertex `c`, the spokes to the
/// midpoint vertices `mids` and the `N` quads, quad `s` with the corners `(corner s, m_s,
/// c, m_{s-1})` (`parts[s]`: the halves of side `s`). The first quad replaces face
/// `into` (when given) and the others are new faces labelled `label`. Returns the
/// interior vertex.
pub(super) fn apply(
    g: &mut Graph,
    into: Option<usize>,
    parts: &[(FaceSide, FaceSide)],
    mids: &[usize],
    p: Placement,
    label: &str,
) -> usize {
    let k = parts.len();
    let centre = g.add_vertex(p.centre);
    let spokes: Vec<usize> = p.cuts.into_iter().zip(mids).map(|(c, &m)| g.add_edge(c, centre, m, false)).collect();
    for s in 0..k {
        let prev = (s + k - 1) % k;
        let sides = vec![parts[s].0, (spokes[s], false), (spokes[prev], true), parts[prev].1];
        match into {
            Some(f) if s == 0 => g.faces[f].sides = sides,
            _ => g.faces.push(Face::new(sides, label)),
        }
    }
    centre
}
