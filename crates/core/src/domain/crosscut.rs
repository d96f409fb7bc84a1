//! The cut across a thin face (issue 31, step 3 of [`super::layout`]). A face of `N ≥ 5`
//! corners whose midpoint template ([`super::midpoint`]) keeps a new patch corner within
//! `MIN_TEMPLATE_ANGLE` (15°) of 0° or 180° after its interior vertex was searched (a
//! strip, whose spokes to the far side midpoints bunch wherever the vertex is) is cut
//! across into two faces with fewer corners, each laid out by the midpoint template:
//!
//! - `N` even: from corner `i` to corner `i + N/2`: two faces of `N/2 + 1` corners (for
//!   `N = 6` two quads, whose interior vertices have valence 4: no irregular vertex);
//! - `N` odd: from corner `i` to the midpoint `m_j` of the opposite side `j = i + (N −
//!   1)/2`: two faces of `(N + 3)/2` corners (for `N = 5` two quads), each with a half of
//!   side `j` as a side, split at its own arc-length midpoint; taken only where side `j`
//!   is on the domain's boundary, so that no other face shares that point.
//!
//! The face's sides are split at their arc-length midpoints already (as every side of a
//! face that is not four-sided), and the cut is split at its own arc-length midpoint `p`:
//! every side of the two faces is split where their templates need it and the layout
//! stays conforming without a change to the neighbouring faces.
//!
//! The cut is the straight segment where that stays inside the face, or the preimage of
//! the polygon's straight segment (from vertex `i` to vertex `i + N/2`, or to the midpoint
//! of side `j`) under the face's map onto the regular polygon (`PolygonMap`, one-to-one on
//! every face, so the preimage stays inside), fitted by a spline; both are candidates for
//! every `i`. A candidate is scored as the template is (`spokes::score`: the smallest
//! `min(α, 180° − α)` over its new patch corners `α`, which are the four where the cut
//! meets the boundary and those of the two faces' templates) and admitted only when
//! every one of its patches is a counter-clockwise boundary that does not cross itself.
//! The best (of equal scores, the one with fewer irregular vertices) replaces the
//! midpoint template when it scores higher.

use serde::Serialize;

use super::cycles::curves_polyline;
use super::graph::{end_tangent, split_curve, FaceSide, Graph};
use super::harmonic::{polygon_vertex, ArcLength, HarmonicMap};
use super::midpoint::{self, fit_scale, AngleSearch, CutFit, Placement, SplitFace, SPOKE_SAMPLES};
use super::polygon_map::{PolygonMap, POLYGON_MAP_LEVELS};
use super::reflex::{cut_angles, line, polyline_inside, segment_inside};
use super::spokes::score;
use crate::boundary::validate::{inspect, Orientation};
use crate::boundary::{Boundary, SideCurve};
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};

/// A face cut across (the report).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct CrossCut {
    /// Where it starts (a corner of the face).
    pub from: Point,
    /// Where it ends.
    pub to: Point,
    /// `"corner"` (the opposite corner, `N` even) or `"side midpoint"` (the midpoint of
    /// the opposite side, `N` odd).
    pub ends_on: &'static str,
    /// The straight segment (else the preimage of the polygon's segment).
    pub straight: bool,
    /// The four new corner angles where it meets the boundary (two at each end), degrees.
    pub new_angles: [f64; 4],
    /// The two faces it makes, each laid out by the midpoint template.
    pub faces: [CrossFace; 2],
    /// Its score: the smallest `min(α, 180° − α)` over the new patch corners `α` (its
    /// four and those of the two faces' templates), degrees.
    pub score: f64,
    /// The score of the face's midpoint template that it replaced, degrees.
    pub midpoint_score: f64,
    /// Candidates scored (cuts from every corner, straight and through the map onto the
    /// polygon, that stay inside the face).
    pub candidates: usize,
}

/// One of the two faces of a cut across, laid out by the midpoint template.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct CrossFace {
    /// Its corners (4: a regular interior vertex).
    pub corners: usize,
    /// The interior vertex.
    pub centre: Point,
    /// Straight spokes from a star centre (its harmonic map folds).
    pub straight: bool,
    /// Spokes through its map onto the polygon.
    pub inverse: bool,
    /// Its template's smallest new patch corner, degrees.
    pub min_angle: f64,
    /// The search of its interior vertex (first placement below 15 degrees).
    pub angle_search: Option<AngleSearch>,
}

/// Where a cut across ends: at corner `j`, or at the midpoint of side `j`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum End {
    Corner(usize),
    Mid(usize),
}

/// A side of one of the two new faces: the whole curve (in the face's direction), its
/// halves, its midpoint and the unit tangents of the halves there (arriving, leaving).
#[derive(Debug, Clone)]
struct NewSide {
    curve: Curve,
    halves: (Curve, Curve),
    mid: Point,
    at: (Point, Point),
}

fn neg(d: Point) -> Point {
    [-d[0], -d[1]]
}

fn reversed(c: &Curve) -> Curve {
    c.reversed().normalized()
}

/// A curve split at its arc-length midpoint: the parameter, the halves and their
/// tangents at the midpoint (arriving, leaving).
type Halved = (f64, (Curve, Curve), (Point, Point));

/// The halves of a side and the vertex between them.
type SidePart = ((FaceSide, FaceSide), usize);

/// `c` split at its arc-length midpoint ([`Halved`]).
fn halve(c: &Curve) -> Result<Halved> {
    let u = ArcLength::new(c).param(0.5);
    let (a, b) = split_curve(c, u)?;
    let at = (end_tangent(&a, true), end_tangent(&b, false));
    Ok((u, (a, b), at))
}

/// The end point of `c`.
fn last(c: &Curve) -> Point {
    c.control_points[c.control_points.len() - 1]
}

/// The half `s` of a split side (an edge on the domain's boundary) split in turn at its
/// edge's arc-length midpoint: the edge parameter and the new side.
fn split_half(g: &Graph, s: FaceSide) -> Result<(f64, NewSide)> {
    let (u, (a, b), at) = halve(&g.edges[s.0].curve)?;
    let mid = last(&a);
    Ok(if s.1 {
        (u, NewSide { curve: g.side_curve(s), halves: (a, b), mid, at })
    } else {
        let at = (neg(at.1), neg(at.0));
        (u, NewSide { curve: g.side_curve(s), halves: (reversed(&b), reversed(&a)), mid, at })
    })
}

/// A candidate cut across and the templates of its two faces.
#[derive(Debug, Clone)]
pub(super) struct CrossPlan {
    from: usize,
    end: End,
    /// The cut's halves, from the corner to `p` and from `p` to the end.
    cut: (Curve, Curve),
    straight: bool,
    angles: [f64; 4],
    /// `N` odd: the edge parameters where the halves of side `j` are split.
    quarters: Option<[f64; 2]>,
    faces: [(usize, Placement); 2],
    score: f64,
    irregular: usize,
    candidates: usize,
}

impl CrossPlan {
    /// Its smallest new patch corner angle (the cut's four and the two templates'),
    /// degrees.
    pub(super) fn min_angle(&self) -> f64 {
        let cut = self.angles.iter().fold(f64::INFINITY, |m, a| m.min(a.to_degrees()));
        cut.min(self.faces[0].1.min_angle()).min(self.faces[1].1.min_angle())
    }
}

/// The split face of the sides `sides` (for its midpoint template).
fn split_face(sides: &[NewSide]) -> SplitFace {
    let curves: Vec<Curve> = sides.iter().map(|s| s.curve.clone()).collect();
    let polyline = curves_polyline(&curves);
    let scale = fit_scale(&polyline);
    SplitFace {
        curves,
        mids: sides.iter().map(|s| s.mid).collect(),
        at_mids: sides.iter().map(|s| s.at).collect(),
        polyline,
        scale,
    }
}

/// Whether every patch of the midpoint template `p` on `sides` is a counter-clockwise
/// boundary that does not cross itself (quad `s`: south the first half of side `s`, east
/// spoke `s` reversed, north spoke `s − 1` reversed, west the second half of side
/// `s − 1` reversed).
fn patches_valid(sides: &[NewSide], p: &Placement) -> bool {
    let k = sides.len();
    (0..k).all(|s| {
        let prev = (s + k - 1) % k;
        let quad =
            [sides[s].halves.0.clone(), reversed(&p.cuts[s]), reversed(&p.cuts[prev]), reversed(&sides[prev].halves.1)];
        let b = Boundary { name: String::new(), sides: quad.map(SideCurve::Spline) };
        inspect(&b).is_ok_and(|r| r.orientation == Orientation::CounterClockwise)
    })
}

/// The best cut across face `f` of `g` (see the module documentation), when it scores
/// higher than the face's midpoint template `midpoint`: `whole` is the face as the
/// midpoint template saw it, `parts` the halves of its sides, `pm` its map onto the
/// polygon (no curved candidates without one); with `inverse` the two faces' templates
/// are placed through their maps onto the polygon.
#[allow(clippy::too_many_arguments)]
pub(super) fn best(
    g: &Graph,
    f: usize,
    whole: &SplitFace,
    parts: &[(FaceSide, FaceSide)],
    pm: Option<&PolygonMap>,
    midpoint: &Placement,
    inverse: bool,
    cf: CutFit,
) -> Result<Option<CrossPlan>> {
    let n = parts.len();
    if n < 5 {
        return Ok(None);
    }
    let tol = 1e-9 * cf.diameter;
    let corners: Vec<Point> = parts.iter().map(|&(a, _)| g.vertices[g.start(a)]).collect();
    // per corner: the outgoing side's direction and the reversed incoming side's
    let dirs: Vec<[Point; 2]> = (0..n)
        .map(|s| {
            let t_out = end_tangent(&g.side_curve(parts[s].0), false);
            let t_in = end_tangent(&g.side_curve(parts[(s + n - 1) % n].1), true);
            [t_out, neg(t_in)]
        })
        .collect();
    let whole_side = |s: usize| NewSide {
        curve: whole.curves[s].clone(),
        halves: (g.side_curve(parts[s].0), g.side_curve(parts[s].1)),
        mid: whole.mids[s],
        at: whole.at_mids[s],
    };
    let ends: Vec<(usize, End)> = if n.is_multiple_of(2) {
        (0..n / 2).map(|i| (i, End::Corner(i + n / 2))).collect()
    } else {
        (0..n)
            .map(|i| (i, (i + (n - 1) / 2) % n))
            .filter(|&(_, j)| g.edges[parts[j].0 .0].boundary && g.edges[parts[j].1 .0].boundary)
            .map(|(i, j)| (i, End::Mid(j)))
            .collect()
    };
    let mut best: Option<CrossPlan> = None;
    let mut candidates = 0;
    for (i, end) in ends {
        let from = corners[i];
        let (to, to_dirs, image) = match end {
            End::Corner(j) => (corners[j], dirs[j], polygon_vertex(n, j)),
            End::Mid(j) => {
                let (t_in, t_out) = whole.at_mids[j];
                let image = pm.map_or([0.0; 2], |pm| pm.side_midpoint(j));
                (whole.mids[j], [t_out, neg(t_in)], image)
            }
        };
        let mut paths: Vec<(Curve, bool)> = Vec::new();
        if segment_inside(g, f, from, to, tol) {
            paths.push((line(from, to), true));
        }
        let curved = pm
            .and_then(|pm| pm.segment(polygon_vertex(n, i), image, SPOKE_SAMPLES))
            .and_then(|pts| cf.curve(pts, from, to, whole.scale).ok())
            .filter(|c| c.degree() > 1 && polyline_inside(g, f, &c.sample(4 * SPOKE_SAMPLES), tol));
        paths.extend(curved.map(|c| (c, false)));
        for (cut, straight) in paths {
            candidates += 1;
            let (d0, d1) = (end_tangent(&cut, false), end_tangent(&cut, true));
            let angles = cut_angles(dirs[i], d0, to_dirs, neg(d1));
            let own = score(&angles);
            // the candidate scores no more than its own four corners
            let bar = best.as_ref().map_or(midpoint.score(), |b| b.score);
            if own <= bar {
                continue;
            }
            let (_, (c1, c2), at) = halve(&cut)?;
            let p = last(&c1);
            let back = NewSide {
                curve: reversed(&cut),
                halves: (reversed(&c2), reversed(&c1)),
                mid: p,
                at: (neg(at.1), neg(at.0)),
            };
            let fwd = NewSide { curve: cut.clone(), halves: (c1.clone(), c2.clone()), mid: p, at };
            let (mut a, mut b): (Vec<NewSide>, Vec<NewSide>) = (Vec::new(), Vec::new());
            let mut quarters = None;
            match end {
                End::Corner(j) => {
                    a.extend((i..j).map(whole_side));
                    a.push(back);
                    b.extend((j..i + n).map(|s| whole_side(s % n)));
                    b.push(fwd);
                }
                End::Mid(j) => {
                    let (ua, ha) = split_half(g, parts[j].0)?;
                    let (ub, hb) = split_half(g, parts[j].1)?;
                    quarters = Some([ua, ub]);
                    let jj = if j < i { j + n } else { j };
                    a.extend((i..jj).map(|s| whole_side(s % n)));
                    a.push(ha);
                    a.push(back);
                    b.push(hb);
                    b.extend((jj + 1..i + n).map(|s| whole_side(s % n)));
                    b.push(fwd);
                }
            }
            let mut faces = Vec::with_capacity(2);
            for sides in [&a, &b] {
                let face = split_face(sides);
                let h = HarmonicMap::new(&face.curves, cf.rings);
                let own_pm =
                    if inverse { PolygonMap::new(&face.curves, cf.rings, POLYGON_MAP_LEVELS).ok() } else { None };
                match midpoint::place(&face, &h, own_pm.as_ref(), cf) {
                    Ok((placement, _)) => faces.push((sides.len(), placement)),
                    Err(_) => break,
                }
            }
            let [fa, fb]: [(usize, Placement); 2] = match faces.try_into() {
                Ok(x) => x,
                Err(_) => continue,
            };
            let total = own.min(fa.1.score()).min(fb.1.score());
            let irregular = usize::from(fa.0 != 4) + usize::from(fb.0 != 4);
            let better =
                best.as_ref().map_or(total > midpoint.score() || (total == midpoint.score() && irregular < 1), |b| {
                    total > b.score || (total == b.score && irregular < b.irregular)
                });
            if !better || !patches_valid(&a, &fa.1) || !patches_valid(&b, &fb.1) {
                continue;
            }
            best = Some(CrossPlan {
                from: i,
                end,
                cut: (c1, c2),
                straight,
                angles,
                quarters,
                faces: [fa, fb],
                score: total,
                irregular,
                candidates: 0,
            });
        }
    }
    Ok(best.map(|b| CrossPlan { candidates, ..b }))
}

/// The cut across `plan` made in the graph on face `f` (whose sides' halves are `parts`,
/// their midpoint vertices `mids`): the cut split at its midpoint, for `N` odd the halves
/// of the opposite side split at theirs, and the two faces' midpoint templates; the first
/// patch replaces face `f`, the others are new faces labelled `label`. Returns the report
/// and the patches made.
pub(super) fn apply(
    g: &mut Graph,
    f: usize,
    parts: &[(FaceSide, FaceSide)],
    mids: &[usize],
    plan: CrossPlan,
    midpoint_score: f64,
    label: &str,
) -> Result<(CrossCut, usize)> {
    let n = parts.len();
    let i = plan.from;
    let from = g.start(parts[i].0);
    let (c1, c2) = plan.cut;
    let p = g.add_vertex(last(&c1));
    let (to, ends_on) = match plan.end {
        End::Corner(j) => (g.start(parts[j].0), "corner"),
        End::Mid(j) => (mids[j], "side midpoint"),
    };
    let e1 = g.add_edge(c1, from, p, false);
    let e2 = g.add_edge(c2, p, to, false);
    let back = ((e2, false), (e1, false));
    let fwd = ((e1, true), (e2, true));
    let (mut a, mut b): (Vec<SidePart>, Vec<SidePart>) = (Vec::new(), Vec::new());
    match (plan.end, plan.quarters) {
        (End::Corner(j), _) => {
            a.extend((i..j).map(|s| (parts[s], mids[s])));
            a.push((back, p));
            b.extend((j..i + n).map(|s| (parts[s % n], mids[s % n])));
            b.push((fwd, p));
        }
        (End::Mid(j), Some([ua, ub])) => {
            // the halves of side j (boundary edges: no other face has them) split at
            // their own midpoints
            let mut split = |s: FaceSide, u: f64| -> Result<SidePart> {
                let (v, e2) = g.split_edge(s.0, u)?;
                Ok((if s.1 { ((s.0, true), (e2, true)) } else { ((e2, false), (s.0, false)) }, v))
            };
            let ha = split(parts[j].0, ua)?;
            let hb = split(parts[j].1, ub)?;
            let jj = if j < i { j + n } else { j };
            a.extend((i..jj).map(|s| (parts[s % n], mids[s % n])));
            a.push(ha);
            a.push((back, p));
            b.push(hb);
            b.extend((jj + 1..i + n).map(|s| (parts[s % n], mids[s % n])));
            b.push((fwd, p));
        }
        (End::Mid(j), None) => {
            return Err(Error::Invalid(format!(
                "layout: the cut across face {f} to side {j} has no split of its halves"
            )))
        }
    }
    let [(ka, pa), (kb, pb)] = plan.faces;
    let mut faces = Vec::with_capacity(2);
    for (into, sides, k, placement) in [(Some(f), &a, ka, pa), (None, &b, kb, pb)] {
        let (sparts, smids): (Vec<(FaceSide, FaceSide)>, Vec<usize>) = sides.iter().copied().unzip();
        faces.push(CrossFace {
            corners: k,
            centre: placement.centre,
            straight: placement.straight,
            inverse: placement.inverse,
            min_angle: placement.min_angle(),
            angle_search: placement.search.clone(),
        });
        midpoint::apply(g, into, &sparts, &smids, placement, label);
    }
    let [fa, fb]: [CrossFace; 2] = faces.try_into().expect("two faces");
    let report = CrossCut {
        from: g.vertices[from],
        to: g.vertices[to],
        ends_on,
        straight: plan.straight,
        new_angles: plan.angles.map(f64::to_degrees),
        faces: [fa, fb],
        score: plan.score,
        midpoint_score,
        candidates: plan.candidates,
    };
    Ok((report, ka + kb))
}
