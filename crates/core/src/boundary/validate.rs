//! Validation of a four-sided boundary (see `formats.md`, "Corner consistency and
//! tolerances") and the facts about it that an `inspect` command reports.
//!
//! [`inspect`] checks everything that makes a boundary unusable (non-finite numbers,
//! too few points, corner gaps, zero-length sides, self-intersections) and measures the
//! rest (bounding box, corners, corner angles, signed area, orientation); [`validate`]
//! additionally rejects clockwise contours.
//!
//! The contour is checked on a polyline: point clouds as given, spline sides sampled
//! adaptively ([`sample_side`]) with at least `SAMPLES_PER_SPAN` points per knot span
//! and chords within `FLATNESS` times the bounding-box diameter of the curve, so that
//! chords cannot create false crossings in narrow gaps (two sides `g` apart can only
//! appear to cross when `g < 2 * FLATNESS * diameter`).

use crate::boundary::normalise::Similarity;
use crate::boundary::{Boundary, SideCurve};
use crate::error::{check_point_count, Error, Result};
use crate::spline::curve::{check_points, check_weights, Curve, Point};
use crate::spline::surface::Side;

/// Corner gaps and side lengths are compared against this times the bounding-box diameter.
pub(crate) const CORNER_TOL: f64 = 1e-9;
/// Largest distance between a sampled chord's midpoint and the curve point at the
/// parameter midpoint, relative to the bounding-box diameter.
pub(crate) const FLATNESS: f64 = 1e-5;
/// Contacts of the contour with itself closer than this times the bounding-box diameter
/// to one of the four corner points are not reported: they are the shared corners, or
/// pinches and seams below the resolution of the data (`male_casing_ring` is a ring cut
/// open along a seam whose two sides meet at one corner and cross within `3e-8` of the
/// diameter of another).
pub(crate) const CORNER_NEIGHBOURHOOD: f64 = 1e-6;
/// Minimum number of chords per non-empty knot span when sampling a spline side.
pub(crate) const SAMPLES_PER_SPAN: usize = 16;
/// Number of initial chords on an analytic side (refined adaptively).
pub(crate) const ANALYTIC_SAMPLES: usize = 256;
/// Deepest bisection of one initial chord during adaptive sampling.
const MAX_BISECTIONS: u32 = 10;
/// Budget of initial chords for one spline side (huge inputs get fewer per span).
const MAX_INITIAL_CHORDS: usize = 1 << 22;

/// Direction in which south, east, reversed north, reversed west run around the domain.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Orientation {
    /// Positive signed area: the required orientation.
    CounterClockwise,
    /// Negative (or zero) signed area.
    Clockwise,
}

/// What [`inspect`] found out about a boundary.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ValidationReport {
    /// Lower-left corner of the bounding box of the sampled contour.
    pub bbox_min: Point,
    /// Upper-right corner of the bounding box.
    pub bbox_max: Point,
    /// Diameter (diagonal length) of the bounding box.
    pub diameter: f64,
    /// Corner tolerance `CORNER_TOL * diameter`.
    pub tolerance: f64,
    /// Corner points south-west, south-east, north-east, north-west (the first side's end
    /// of each pair: `south(0)`, `south(1)`, `east(1)`, `north(0)`).
    pub corners: [Point; 4],
    /// Distance between the two sides' ends at each corner.
    pub corner_gaps: [f64; 4],
    /// Interior angle of the domain at each corner in degrees, from the one-sided
    /// tangents: `180 - turn` where `turn` is the signed turning angle of the contour
    /// (for the actual orientation). An angle of 180 or more forbids `det J > 0` there.
    pub corner_angles: [f64; 4],
    /// Length of the sampled polyline of each side (south, east, north, west).
    pub side_lengths: [f64; 4],
    /// Signed area of the contour south, east, reversed north, reversed west (shoelace
    /// formula on the sampled polyline); positive for counter-clockwise.
    pub signed_area: f64,
    /// Orientation from the sign of the area.
    pub orientation: Orientation,
    /// Number of vertices of the closed polyline used for the checks.
    pub polyline_points: usize,
}

fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross(a: Point, b: Point) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn finite(p: Point) -> bool {
    p[0].is_finite() && p[1].is_finite()
}

/// Check one side on its own: sizes, finiteness, spline consistency.
fn check_side(side: &SideCurve) -> Result<()> {
    match side {
        SideCurve::Points(p) => {
            check_point_count(p.len(), "")?;
            check_points(p, "point")
        }
        SideCurve::Spline(c) => check_curve(c),
        SideCurve::Analytic(_) => Ok(()),
    }
}

/// The checks of [`Curve::new`] on a curve whose public fields may have been set directly.
pub(crate) fn check_curve(c: &Curve) -> Result<()> {
    let n = c.knots.num_basis();
    if c.control_points.len() != n {
        return Err(Error::Length {
            context: String::new(),
            what: "control_points".into(),
            found: c.control_points.len(),
            expected: n,
        });
    }
    check_points(&c.control_points, "control point")?;
    if let Some(w) = &c.weights {
        check_weights(w, n)?;
    }
    Ok(())
}

/// Push the adaptive samples of `f` on `(t0, t1]` onto `out`: the chord is bisected while
/// the curve point at the parameter midpoint is farther than `tol` from the chord's midpoint.
fn refine(
    f: &dyn Fn(f64) -> Point,
    t0: f64,
    p0: Point,
    t1: f64,
    p1: Point,
    tol: f64,
    depth: u32,
    out: &mut Vec<Point>,
) {
    if depth < MAX_BISECTIONS && tol.is_finite() {
        let tm = 0.5 * (t0 + t1);
        let pm = f(tm);
        let mid = [0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1])];
        // A non-finite sample ends the refinement; the caller reports it.
        if finite(pm) && dist(pm, mid) > tol {
            refine(f, t0, p0, tm, pm, tol, depth + 1, out);
            refine(f, tm, pm, t1, p1, tol, depth + 1, out);
            return;
        }
    }
    out.push(p1);
}

/// Sample a side into a polyline from its start to its end.
///
/// Point clouds are returned as given. A spline side gets at least `SAMPLES_PER_SPAN`
/// chords per non-empty knot span (fewer only on curves with more than 2^18 spans, to
/// bound the work), an analytic side `ANALYTIC_SAMPLES` chords; each chord
/// is then bisected (at most 10 times) until the curve point at its parameter midpoint is
/// within `flat_tol` of the chord's midpoint. `flat_tol = f64::INFINITY` gives the
/// uniform initial sampling.
pub fn sample_side(side: &SideCurve, flat_tol: f64) -> Vec<Point> {
    match side {
        SideCurve::Points(p) => p.clone(),
        SideCurve::Spline(c) => {
            let elements = c.knots.elements();
            let per = (MAX_INITIAL_CHORDS / elements.len().max(1)).clamp(1, SAMPLES_PER_SPAN);
            let f = |t: f64| c.eval(t);
            let mut out = Vec::with_capacity(elements.len() * per + 1);
            let Some(&(_, a0, _)) = elements.first() else {
                return out;
            };
            let mut prev = (a0, f(a0));
            out.push(prev.1);
            for &(_, a, b) in &elements {
                for k in 1..=per {
                    let t = if k == per { b } else { a + (b - a) * k as f64 / per as f64 };
                    let p = f(t);
                    refine(&f, prev.0, prev.1, t, p, flat_tol, 0, &mut out);
                    prev = (t, p);
                }
            }
            out
        }
        SideCurve::Analytic(g) => {
            let f = |t: f64| g.eval(t);
            let m = ANALYTIC_SAMPLES;
            let mut prev = (0.0, f(0.0));
            let mut out = vec![prev.1];
            for k in 1..=m {
                let t = k as f64 / m as f64;
                let p = f(t);
                refine(&f, prev.0, prev.1, t, p, flat_tol, 0, &mut out);
                prev = (t, p);
            }
            out
        }
    }
}

/// Unit-free tangent direction of a side at its start (`at_end = false`) or end, in the
/// side's own orientation. Uses the exact derivative of spline sides; falls back to the
/// chord to the nearest distinct sample when the derivative vanishes.
fn end_tangent(side: &SideCurve, poly: &[Point], at_end: bool) -> Point {
    if let SideCurve::Spline(c) = side {
        let (a, b) = c.domain();
        let d = c.derivs(if at_end { b } else { a }, 1).d1;
        if finite(d) && d[0].hypot(d[1]) > 0.0 {
            return d;
        }
    }
    if let SideCurve::Analytic(f) = side {
        let h = 1e-7;
        let d = if at_end { sub(f.eval(1.0), f.eval(1.0 - h)) } else { sub(f.eval(h), f.eval(0.0)) };
        if finite(d) && d[0].hypot(d[1]) > 0.0 {
            return d;
        }
    }
    if at_end {
        let q = poly[poly.len() - 1];
        poly.iter().rev().find(|&&p| p != q).map_or([0.0, 0.0], |&p| sub(q, p))
    } else {
        let q = poly[0];
        poly.iter().find(|&&p| p != q).map_or([0.0, 0.0], |&p| sub(p, q))
    }
}

/// Interior angle in degrees between the incoming and outgoing directions of a contour
/// with the given orientation sign (+1 counter-clockwise).
fn interior_angle(incoming: Point, outgoing: Point, sign: f64) -> f64 {
    let turn = cross(incoming, outgoing).atan2(dot(incoming, outgoing));
    (std::f64::consts::PI - sign * turn).to_degrees()
}

fn within_side(e: Error, s: Side) -> Error {
    e.within(&format!("boundary.{}", s.name()))
}

/// Check a boundary and measure it; only the orientation is not judged (see [`validate`]).
///
/// Errors: [`Error::TooLarge`], [`Error::TooFewPoints`], [`Error::NonFinite`],
/// [`Error::Length`]/[`Error::Weight`] (spline sides built by hand), [`Error::CornerGap`]
/// (gap above `CORNER_TOL` times the bounding-box diameter), [`Error::DegenerateSide`]
/// (side shorter than that tolerance), [`Error::SelfIntersection`],
/// [`Error::DegenerateContour`] (no area, so no orientation) and [`Error::Range`]
/// (a size whose `det J` leaves `f64`'s range). The geometry is measured in the
/// normalised coordinates of `Similarity` and reported in the input's.
pub fn inspect(boundary: &Boundary) -> Result<ValidationReport> {
    for s in Side::ALL {
        let side = boundary.side(s);
        check_side(side).map_err(|e| within_side(e, s))?;
        if let SideCurve::Points(p) = side {
            if p.len() < 2 {
                return Err(Error::TooFewPoints { side: s.name().into(), found: p.len(), needed: 2 });
            }
        }
    }
    // Measured in normalised coordinates (exact lengths and areas back: `s = 2^k`), so
    // that a domain far from the origin or of extreme size is judged as at unit size.
    let sim = Similarity::for_boundary(boundary)?;
    if sim.is_identity() {
        return measure(boundary);
    }
    let r = measure(&sim.unit_boundary(boundary)).map_err(|e| physical_error(e, &sim))?;
    Ok(ValidationReport {
        bbox_min: sim.to_physical(r.bbox_min),
        bbox_max: sim.to_physical(r.bbox_max),
        diameter: sim.length(r.diameter),
        tolerance: sim.length(r.tolerance),
        corners: r.corners.map(|p| sim.to_physical(p)),
        corner_gaps: r.corner_gaps.map(|g| sim.length(g)),
        corner_angles: r.corner_angles,
        side_lengths: r.side_lengths.map(|l| sim.length(l)),
        signed_area: sim.area(r.signed_area),
        orientation: r.orientation,
        polyline_points: r.polyline_points,
    })
}

/// An error of [`measure`] on the normalised boundary with its lengths and points in
/// the input's coordinates.
fn physical_error(e: Error, sim: &Similarity) -> Error {
    let at = |x: f64, y: f64| sim.to_physical([x, y]);
    match e {
        Error::CornerGap { side_a, side_b, gap, tol, x, y } => {
            let [x, y] = at(x, y);
            Error::CornerGap { side_a, side_b, gap: sim.length(gap), tol: sim.length(tol), x, y }
        }
        Error::DegenerateSide { side, length, tol } => {
            Error::DegenerateSide { side, length: sim.length(length), tol: sim.length(tol) }
        }
        Error::SelfIntersection { side_a, side_b, x, y } => {
            let [x, y] = at(x, y);
            Error::SelfIntersection { side_a, side_b, x, y }
        }
        Error::DegenerateContour { area, bound } => {
            Error::DegenerateContour { area: sim.area(area), bound: sim.area(bound) }
        }
        e => e,
    }
}

/// The measurements of [`inspect`] in the boundary's own coordinates.
fn measure(boundary: &Boundary) -> Result<ValidationReport> {
    // Coarse sampling to size the problem, then adaptive sampling relative to it.
    let coarse: Vec<Vec<Point>> = Side::ALL.iter().map(|&s| sample_side(boundary.side(s), f64::INFINITY)).collect();
    for (k, poly) in coarse.iter().enumerate() {
        if let Some(i) = poly.iter().position(|&p| !finite(p)) {
            let p = poly[i];
            return Err(within_side(
                Error::NonFinite {
                    context: String::new(),
                    what: format!("sample {i} of the side is ({}, {})", p[0], p[1]),
                },
                Side::ALL[k],
            ));
        }
    }
    let (lo, hi) = bbox(coarse.iter().flatten());
    let coarse_diam = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    if !coarse_diam.is_finite() {
        return Err(Error::NonFinite {
            context: "boundary".into(),
            what: format!("bounding-box diameter is {coarse_diam}"),
        });
    }
    let flat = FLATNESS * coarse_diam;
    let polys: Vec<Vec<Point>> = Side::ALL
        .iter()
        .zip(&coarse)
        .map(|(&s, c)| {
            if matches!(boundary.side(s), SideCurve::Points(_)) {
                c.clone()
            } else {
                sample_side(boundary.side(s), flat)
            }
        })
        .collect();
    let (bbox_min, bbox_max) = bbox(polys.iter().flatten());
    let diameter = (bbox_max[0] - bbox_min[0]).hypot(bbox_max[1] - bbox_min[1]);
    let tol = CORNER_TOL * diameter;

    // Zero-length sides.
    let mut side_lengths = [0.0; 4];
    for (k, poly) in polys.iter().enumerate() {
        side_lengths[k] = poly.windows(2).map(|w| dist(w[0], w[1])).sum();
        if side_lengths[k].is_nan() || side_lengths[k] <= tol {
            return Err(Error::DegenerateSide { side: Side::ALL[k].name().into(), length: side_lengths[k], tol });
        }
    }

    // Corners: (side a, its end?, side b, its end?) for SW, SE, NE, NW.
    let ends: Vec<(Point, Point)> = polys.iter().map(|p| (p[0], p[p.len() - 1])).collect();
    let pick = |s: Side, end: bool| {
        if end {
            ends[s as usize].1
        } else {
            ends[s as usize].0
        }
    };
    const PAIRS: [(Side, bool, Side, bool); 4] = [
        (Side::South, false, Side::West, false),
        (Side::South, true, Side::East, false),
        (Side::East, true, Side::North, true),
        (Side::North, false, Side::West, true),
    ];
    let mut corners = [[0.0; 2]; 4];
    let mut corner_gaps = [0.0; 4];
    for (k, &(a, ea, b, eb)) in PAIRS.iter().enumerate() {
        let (pa, pb) = (pick(a, ea), pick(b, eb));
        let gap = dist(pa, pb);
        corners[k] = pa;
        corner_gaps[k] = gap;
        if gap.is_nan() || gap > tol {
            return Err(Error::CornerGap {
                side_a: a.name().into(),
                side_b: b.name().into(),
                gap,
                tol,
                x: pa[0],
                y: pa[1],
            });
        }
    }

    // Closed polyline south, east, reversed north, reversed west; the corner points are
    // shared (each side after the first contributes its points after the corner).
    let (pts, owner) = closed_polyline(&polys);
    let signed_area = shoelace(&pts);
    let orientation = if signed_area > 0.0 { Orientation::CounterClockwise } else { Orientation::Clockwise };
    check_self_intersection(&pts, &owner, &corners, CORNER_NEIGHBOURHOOD * diameter)?;
    // Which end stands for a corner moves a vertex by up to its gap, which changes the
    // area by up to gap × diameter; an area within that (and the shoelace's rounding) of
    // zero has no orientation.
    let bound =
        2.0 * corner_gaps.iter().sum::<f64>() * diameter + 8.0 * f64::EPSILON * pts.len() as f64 * diameter * diameter;
    if signed_area.is_nan() || signed_area.abs() <= bound {
        return Err(Error::DegenerateContour { area: signed_area, bound });
    }

    // Corner angles from the one-sided tangents in the traversal direction.
    let t = |s: Side, end: bool| end_tangent(boundary.side(s), &polys[s as usize], end);
    let neg = |p: Point| [-p[0], -p[1]];
    let sign = if orientation == Orientation::CounterClockwise { 1.0 } else { -1.0 };
    let corner_angles = [
        interior_angle(neg(t(Side::West, false)), t(Side::South, false), sign),
        interior_angle(t(Side::South, true), t(Side::East, false), sign),
        interior_angle(t(Side::East, true), neg(t(Side::North, true)), sign),
        interior_angle(neg(t(Side::North, false)), neg(t(Side::West, true)), sign),
    ];

    Ok(ValidationReport {
        bbox_min,
        bbox_max,
        diameter,
        tolerance: tol,
        corners,
        corner_gaps,
        corner_angles,
        side_lengths,
        signed_area,
        orientation,
        polyline_points: pts.len(),
    })
}

/// [`inspect`], and reject a clockwise contour with [`Error::Clockwise`].
pub fn validate(boundary: &Boundary) -> Result<ValidationReport> {
    let report = inspect(boundary)?;
    if report.orientation == Orientation::Clockwise {
        return Err(Error::Clockwise { area: report.signed_area });
    }
    Ok(report)
}

fn bbox<'a>(pts: impl IntoIterator<Item = &'a Point>) -> (Point, Point) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in pts {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    (lo, hi)
}

/// The closed contour (first point not repeated) and, for each segment `i` from vertex
/// `i` to vertex `i + 1` (cyclically), the side it belongs to. Repeated consecutive
/// points are dropped.
fn closed_polyline(polys: &[Vec<Point>]) -> (Vec<Point>, Vec<Side>) {
    let total: usize = polys.iter().map(Vec::len).sum();
    // Each vertex is tagged with the side of the segment that ends there.
    let mut verts: Vec<(Point, Side)> = Vec::with_capacity(total);
    let mut push = |p: Point, s: Side| {
        if verts.last().is_none_or(|&(q, _)| q != p) {
            verts.push((p, s));
        }
    };
    let [south, east, north, west] = [&polys[0], &polys[1], &polys[2], &polys[3]];
    push(south[0], Side::West);
    south.iter().skip(1).for_each(|&p| push(p, Side::South));
    east.iter().skip(1).for_each(|&p| push(p, Side::East));
    north.iter().rev().skip(1).for_each(|&p| push(p, Side::North));
    // The west side ends (reversed) at the south-west corner, which is vertex 0.
    west.iter().rev().skip(1).take(west.len().saturating_sub(2)).for_each(|&p| push(p, Side::West));
    while verts.len() > 1 && verts.last().map(|v| v.0) == verts.first().map(|v| v.0) {
        verts.pop();
    }
    let n = verts.len();
    let pts = verts.iter().map(|v| v.0).collect();
    let owner = (0..n).map(|i| verts[(i + 1) % n].1).collect();
    (pts, owner)
}

/// Signed area of a closed polygon (shoelace formula, relative to the first vertex to
/// limit cancellation).
fn shoelace(pts: &[Point]) -> f64 {
    if pts.len() < 3 {
        return 0.0;
    }
    let o = pts[0];
    let mut a = 0.0;
    for i in 1..pts.len() - 1 {
        a += cross(sub(pts[i], o), sub(pts[i + 1], o));
    }
    0.5 * a
}

/// Where segments `ab` and `cd` meet (touching counts), if they do.
pub(crate) fn segment_hit(a: Point, b: Point, c: Point, d: Point) -> Option<Point> {
    let d1 = cross(sub(b, a), sub(c, a));
    let d2 = cross(sub(b, a), sub(d, a));
    let d3 = cross(sub(d, c), sub(a, c));
    let d4 = cross(sub(d, c), sub(b, c));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        let t = d3 / (d3 - d4);
        return Some([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
    }
    let on = |p: Point, q: Point, r: Point| {
        // r on segment pq, given collinearity
        r[0] >= p[0].min(q[0]) && r[0] <= p[0].max(q[0]) && r[1] >= p[1].min(q[1]) && r[1] <= p[1].max(q[1])
    };
    if d1 == 0.0 && on(a, b, c) {
        return Some(c);
    }
    if d2 == 0.0 && on(a, b, d) {
        return Some(d);
    }
    if d3 == 0.0 && on(c, d, a) {
        return Some(a);
    }
    if d4 == 0.0 && on(c, d, b) {
        return Some(b);
    }
    None
}

/// Reject a closed polyline that crosses or touches itself, except within `radius` of
/// one of the `corners`.
///
/// Neighbouring segments share a vertex and are only checked for folding back onto each
/// other; every other pair is tested with orientation predicates. Candidate pairs come
/// from a uniform grid of about as many cells as segments, each segment registered in
/// the cells its line passes through, so the cost is about linear for contours whose
/// segments are short compared with the domain.
fn check_self_intersection(pts: &[Point], owner: &[Side], corners: &[Point; 4], radius: f64) -> Result<()> {
    let near_corner = |p: Point| corners.iter().any(|&c| dist(p, c) <= radius);
    let n = pts.len();
    if n < 3 {
        return Ok(());
    }
    let seg = |i: usize| (pts[i], pts[(i + 1) % n]);
    let report = |i: usize, j: usize, p: Point| Error::SelfIntersection {
        side_a: owner[i].name().into(),
        side_b: owner[j].name().into(),
        x: p[0],
        y: p[1],
    };
    // Neighbours folding back onto each other (a spike).
    for i in 0..n {
        let j = (i + 1) % n;
        let (a, b) = seg(i);
        let (_, c) = seg(j);
        let (u, v) = (sub(b, a), sub(c, b));
        if cross(u, v) == 0.0 && dot(u, v) < 0.0 && !near_corner(b) {
            return Err(report(i, j, b));
        }
    }
    if n == 3 {
        return Ok(());
    }
    // Uniform grid over the bounding box.
    let (lo, hi) = bbox(pts.iter());
    let (w, h) = ((hi[0] - lo[0]).max(f64::MIN_POSITIVE), (hi[1] - lo[1]).max(f64::MIN_POSITIVE));
    let cells = n.clamp(1, 1 << 22) as f64;
    let gx = ((cells * w / h).sqrt().ceil()).clamp(1.0, cells) as usize;
    let gy = ((cells / gx as f64).ceil()).clamp(1.0, cells) as usize;
    let (cw, ch) = (w / gx as f64, h / gy as f64);
    let col = |x: f64| (((x - lo[0]) / cw).floor().max(0.0) as usize).min(gx - 1);
    let row = |y: f64| (((y - lo[1]) / ch).floor().max(0.0) as usize).min(gy - 1);
    let mut entries: Vec<(usize, u32)> = Vec::with_capacity(3 * n);
    for i in 0..n {
        let (a, b) = seg(i);
        let (p, q) = if a[0] <= b[0] { (a, b) } else { (b, a) };
        let (c0, c1) = (col(p[0] - 1e-9 * cw), col(q[0] + 1e-9 * cw));
        for cx in c0..=c1 {
            // y-range of the segment inside this column (conservatively widened)
            let (xa, xb) = ((lo[0] + cx as f64 * cw).max(p[0]), (lo[0] + (cx + 1) as f64 * cw).min(q[0]));
            let y_at = |x: f64| {
                if q[0] > p[0] {
                    p[1] + (x - p[0]) * (q[1] - p[1]) / (q[0] - p[0])
                } else {
                    p[1]
                }
            };
            let (ya, yb) = if q[0] > p[0] { (y_at(xa), y_at(xb)) } else { (p[1], q[1]) };
            let (y0, y1) = (ya.min(yb) - 1e-9 * ch, ya.max(yb) + 1e-9 * ch);
            for cy in row(y0)..=row(y1) {
                entries.push((cy * gx + cx, i as u32));
            }
        }
    }
    entries.sort_unstable();
    let mut start = 0;
    while start < entries.len() {
        let cell = entries[start].0;
        let mut end = start;
        while end < entries.len() && entries[end].0 == cell {
            end += 1;
        }
        let group = &entries[start..end];
        for (k, &(_, i)) in group.iter().enumerate() {
            for &(_, j) in &group[k + 1..] {
                let (i, j) = (i.min(j) as usize, i.max(j) as usize);
                if i == j || j == i + 1 || (i == 0 && j == n - 1) {
                    continue;
                }
                let ((a, b), (c, d)) = (seg(i), seg(j));
                if let Some(p) = segment_hit(a, b, c, d) {
                    if !near_corner(p) {
                        return Err(report(i, j, p));
                    }
                }
            }
        }
        start = end;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::Analytic;
    use crate::spline::knots::KnotVector;

    fn line(a: Point, b: Point) -> SideCurve {
        SideCurve::Spline(Curve::new(KnotVector::new(1, vec![0., 0., 1., 1.]).unwrap(), vec![a, b], None).unwrap())
    }

    fn square() -> Boundary {
        Boundary {
            name: "square".into(),
            sides: [
                line([0., 0.], [1., 0.]),
                line([1., 0.], [1., 1.]),
                line([0., 1.], [1., 1.]),
                line([0., 0.], [0., 1.]),
            ],
        }
    }

    /// A contour as thin as its corner gaps encloses nothing: no orientation is guessed.
    #[test]
    fn a_contour_as_thin_as_its_corner_gaps_is_degenerate() {
        let (h, g) = (1.5e-9, 9e-10);
        let b = Boundary {
            name: "sliver".into(),
            sides: [
                line([0., 0.], [1., 0.]),
                line([1., g], [1., h + g]),
                line([0., h], [1., h + g]),
                line([0., g], [0., h + g]),
            ],
        };
        let e = validate(&b).unwrap_err();
        assert!(matches!(e, Error::DegenerateContour { .. }), "{e}");
        assert!(matches!(inspect(&b.transposed()), Err(Error::DegenerateContour { .. })));
        // the same sliver with closed corners and 100x the thickness is a domain
        let h = 1.5e-7;
        let b = Boundary {
            name: "strip".into(),
            sides: [line([0., 0.], [1., 0.]), line([1., 0.], [1., h]), line([0., h], [1., h]), line([0., 0.], [0., h])],
        };
        assert!(validate(&b).is_ok());
    }

    #[test]
    fn unit_square_report() {
        let r = validate(&square()).unwrap();
        assert_eq!(r.orientation, Orientation::CounterClockwise);
        assert!((r.signed_area - 1.0).abs() < 1e-14);
        assert!((r.diameter - 2f64.sqrt()).abs() < 1e-14);
        for a in r.corner_angles {
            assert!((a - 90.0).abs() < 1e-9, "{a}");
        }
        assert_eq!(r.corners, [[0., 0.], [1., 0.], [1., 1.], [0., 1.]]);
    }

    #[test]
    fn transposed_square_is_clockwise() {
        let t = square().transposed();
        let r = inspect(&t).unwrap();
        assert_eq!(r.orientation, Orientation::Clockwise);
        for a in r.corner_angles {
            assert!((a - 90.0).abs() < 1e-9, "{a}");
        }
        assert!(matches!(validate(&t), Err(Error::Clockwise { area }) if area < 0.0));
    }

    #[test]
    fn half_disk_corners_are_straight_or_right() {
        // south: diameter; east/west: tiny vertical pieces; north: half circle
        let arc = Analytic::new(|t| {
            let a = std::f64::consts::PI * (1.0 - t);
            [a.cos(), 1.0 + a.sin()]
        });
        let b = Boundary {
            name: "half".into(),
            sides: [
                line([-1., 0.], [1., 0.]),
                line([1., 0.], [1., 1.]),
                SideCurve::Analytic(arc),
                line([-1., 0.], [-1., 1.]),
            ],
        };
        let r = validate(&b).unwrap();
        assert!((r.corner_angles[2] - 180.0).abs() < 1e-4, "{:?}", r.corner_angles);
        assert!((r.corner_angles[0] - 90.0).abs() < 1e-9);
    }

    #[test]
    fn bow_tie_crosses() {
        let b = Boundary {
            name: "bow".into(),
            sides: [
                line([0., 0.], [1., 1.]),
                line([1., 1.], [1., 0.]),
                line([0., 1.], [1., 0.]),
                line([0., 0.], [0., 1.]),
            ],
        };
        let e = inspect(&b).unwrap_err();
        assert!(matches!(e, Error::SelfIntersection { .. }), "{e}");
        let msg = e.to_string();
        assert!(msg.contains("south") && msg.contains("north"), "{msg}");
    }

    #[test]
    fn spike_folding_back_is_an_intersection() {
        let b = Boundary {
            name: "spike".into(),
            sides: [
                SideCurve::Points(vec![[0., 0.], [0.5, 0.], [0.5, 0.5], [0.5, 0.2], [1., 0.]]),
                line([1., 0.], [1., 1.]),
                line([0., 1.], [1., 1.]),
                line([0., 0.], [0., 1.]),
            ],
        };
        assert!(matches!(inspect(&b), Err(Error::SelfIntersection { .. })));
    }

    #[test]
    fn many_segments_are_fast() {
        // a thin annulus sector with 40000 points per long side, gap 1e-3
        let m = 40_000;
        let arc = |r: f64| -> Vec<Point> {
            (0..=m)
                .map(|k| {
                    let a = 1.5 * std::f64::consts::PI * k as f64 / m as f64;
                    [r * a.cos(), r * a.sin()]
                })
                .collect()
        };
        let inner = arc(1.0);
        let outer = arc(1.001);
        let b = Boundary {
            name: "thin".into(),
            sides: [
                SideCurve::Points(vec![inner[0], outer[0]]),
                SideCurve::Points(outer.clone()),
                SideCurve::Points(vec![inner[m], outer[m]]),
                SideCurve::Points(inner.clone()),
            ],
        };
        // south runs inner->outer at angle 0, east runs along the outer arc: the contour
        // south, east, rev north, rev west is counter-clockwise.
        let t = std::time::Instant::now();
        let r = validate(&b).unwrap();
        assert!(t.elapsed().as_secs_f64() < 5.0);
        assert_eq!(r.polyline_points, 2 * (m + 1));
    }
}
