//! Kinks inside a side kept exactly (paper §9): where they are, and the smoothed basis
//! `Σ¹` the Galerkin form (8) is solved on.
//!
//! A side may carry interior `C^0` points, where any `C^1` map of the exact side has
//! `det J = 0` (its tangent turns, or its speed vanishes):
//! * a **`C^0` knot** of a spline side (multiplicity at least the degree);
//! * a **zero-speed knot** (repeated control points, e.g. plate_with_hole's north side):
//!   the curve is `C^1` in its own parameter but its tangent turns where the speed
//!   vanishes;
//! * a **corner of a point cloud** (a polygon vertex), found by `cloud_corners`.
//!
//! To keep them, the basis gets a knot of multiplicity `p` at each kink's parameter
//! (`Σ⁰`; the knot line runs through the domain, so the opposite side's knot vector
//! holds it too, as a regular knot line of a smooth curve); `Σ¹` is `Σ⁰` with that
//! multiplicity lowered by one and the contour projected onto it (`smoothed_level`).
//! The solver solves (8) on `Σ¹`, prolongs to `Σ⁰` and imposes the difference of the
//! boundary control points by the damped elasticity step, then minimises the Winslow
//! functional (16) on `Σ⁰` (`solve::kinks`).

use serde::Serialize;

use super::fit::project_side;
use super::level::Level;
use super::{Boundary, SideCurve};
pub use super::{KinkMode, CLOUD_CORNER_DEGREES, SPLINE_KINK_DEGREES};
use crate::error::{Error, Result};
use crate::spline::basis::BasisDerivs;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;

/// The window of [`cloud_corners`], relative to the side's length.
pub(crate) const CORNER_WINDOW: f64 = 0.01;

/// What makes a kink.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum KinkKind {
    /// A knot of multiplicity at least the degree of a spline side.
    C0Knot,
    /// A knot of a spline side where its speed vanishes (repeated control points).
    ZeroSpeed,
    /// A corner of a point cloud (polygon vertex).
    Corner,
}

/// An interior `C^0` point of a side.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Kink {
    /// The side.
    pub side: Side,
    /// Parameter on the input side in `[0, 1]`: the normalised knot of a spline side, the
    /// cord-length abscissa (eq. 36-37) of a point cloud's vertex.
    pub parameter: f64,
    /// The point (the input's, exactly).
    pub point: Point,
    /// Turning angle of the tangent in degrees (180 for a cusp).
    pub turning_degrees: f64,
    /// What makes it a kink.
    pub kind: KinkKind,
    /// The vertex of a point cloud.
    #[serde(skip)]
    pub index: Option<usize>,
    /// Where the knot of multiplicity `p` lies in the map's parameter along the side (set
    /// when the hierarchy places it; the input parameter pulled back through a
    /// reparameterization, §7).
    pub map_parameter: Option<f64>,
}

/// One interior knot of a spline side: the turning of the tangent (one-sided directions
/// just off the knot, robust to a zero speed at it), whether the speed vanishes there and
/// whether the basis is only `C^0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct KnotKink {
    /// The knot in the curve's own parameter.
    pub u: f64,
    /// The knot normalised to `[0, 1]`.
    pub t: f64,
    /// The curve's point there.
    pub point: Point,
    /// Turning of the tangent in degrees.
    pub turning_degrees: f64,
    /// A one-sided speed at the knot is zero (relative `1e-10` of the control polygon's
    /// length over the parameter domain).
    pub zero_speed: bool,
    /// Multiplicity at least the degree.
    pub c0_knot: bool,
}

/// The interior knots of `c` that are `C^0` knots or where the tangent turns more than
/// [`SPLINE_KINK_DEGREES`].
pub(crate) fn spline_kinks(c: &Curve) -> Vec<KnotKink> {
    let p = c.degree();
    let (a, b) = c.domain();
    let bm = c.knots.breaks_with_multiplicity();
    let spans = c.knots.elements();
    let polygon: f64 =
        c.control_points.windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum::<f64>() / (b - a);
    let mut out = Vec::new();
    let mut basis = BasisDerivs::default();
    let mut d1 = |span: usize, u: f64| {
        basis.eval_in_span(&c.knots, span, u, 1);
        c.derivs_with(&basis, 1).d1
    };
    for &(u, m) in &bm[1..bm.len().saturating_sub(1)] {
        let (Some(l), Some(r)) = (spans.iter().find(|e| e.2 == u), spans.iter().find(|e| e.1 == u)) else {
            continue;
        };
        let (tl, tr) = (d1(l.0, u - 1e-9 * (l.2 - l.1)), d1(r.0, u + 1e-9 * (r.2 - r.1)));
        let (sl, sr) = (d1(l.0, u), d1(r.0, u));
        let zero_speed = sl[0].hypot(sl[1]) <= 1e-10 * polygon || sr[0].hypot(sr[1]) <= 1e-10 * polygon;
        let turning = if tl[0].hypot(tl[1]) == 0.0 || tr[0].hypot(tr[1]) == 0.0 {
            180.0
        } else {
            (tl[0] * tr[1] - tl[1] * tr[0]).atan2(tl[0] * tr[0] + tl[1] * tr[1]).to_degrees().abs()
        };
        let c0_knot = m >= p;
        if c0_knot || turning > SPLINE_KINK_DEGREES {
            out.push(KnotKink {
                u,
                t: (u - a) / (b - a),
                point: c.eval(u),
                turning_degrees: turning,
                zero_speed,
                c0_knot,
            });
        }
    }
    out
}

/// Turning angle (degrees) of the chords `p_i → p_j → p_k` with `p_i` the last point at
/// least `w` (cord length) before `p_j` and `p_k` the first at least `w` after it (the
/// ends when there is none); `s` the cumulative cord length.
fn chord_turning(points: &[Point], s: &[f64], j: usize, w: f64) -> f64 {
    let n = points.len();
    let i = (0..j).rev().find(|&i| s[j] - s[i] >= w).unwrap_or(0);
    let k = (j + 1..n).find(|&k| s[k] - s[j] >= w).unwrap_or(n - 1);
    let (a, b) = (
        [points[j][0] - points[i][0], points[j][1] - points[i][1]],
        [points[k][0] - points[j][0], points[k][1] - points[j][1]],
    );
    if a[0].hypot(a[1]) == 0.0 || b[0].hypot(b[1]) == 0.0 {
        return 0.0;
    }
    (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]).to_degrees().abs()
}

/// Corners of a point cloud: interior vertices `j` where the chords to the points a
/// window `w` (= [`CORNER_WINDOW`] of the length) before and after turn at least
/// `threshold` degrees, and so do the chords at the window `w / 4` (a corner turns at
/// every scale; a bend of a sampled smooth curve turns less at the smaller one, and noise
/// of amplitude `ε` moves the angles by about `ε / w` only). Of neighbouring candidates
/// (closer than `w`) the one turning most at the window `w` is the vertex: at a polygon's
/// vertex both chords lie along its edges. Returns `(index, turning degrees)`.
pub(crate) fn cloud_corners(points: &[Point], threshold: f64) -> Vec<(usize, f64)> {
    CornerTurnings::of(points, threshold).corners(threshold)
}

/// The turnings of a point cloud's interior vertices that [`cloud_corners`] measures, for
/// every vertex turning at least `floor` degrees at the window `w`: the corners for any
/// threshold `>= floor` follow without measuring again ([`CornerTurnings::corners`]).
#[derive(Debug, Clone, Default)]
struct CornerTurnings {
    /// The window `w`.
    w: f64,
    /// `(index, cumulative cord length, turning at w, turning at w / 4)`.
    at: Vec<(usize, f64, f64, f64)>,
}

impl CornerTurnings {
    fn of(points: &[Point], floor: f64) -> Self {
        let n = points.len();
        if n < 3 {
            return Self::default();
        }
        let mut s = vec![0.0; n];
        for j in 1..n {
            s[j] = s[j - 1] + (points[j][0] - points[j - 1][0]).hypot(points[j][1] - points[j - 1][1]);
        }
        let w = CORNER_WINDOW * s[n - 1];
        let mut at = Vec::new();
        for j in 1..n - 1 {
            if s[j] == s[j - 1] || s[j + 1] == s[j] {
                continue;
            }
            let turn = chord_turning(points, &s, j, w);
            if turn < floor {
                continue;
            }
            at.push((j, s[j], turn, chord_turning(points, &s, j, 0.25 * w)));
        }
        Self { w, at }
    }

    /// The corners turning at least `threshold` at both windows, of neighbours (closer
    /// than `w`) the one turning most at `w` (see [`cloud_corners`]).
    fn corners(&self, threshold: f64) -> Vec<(usize, f64)> {
        let mut out: Vec<(usize, f64, f64)> = Vec::new();
        for &(j, sj, turn, quarter) in &self.at {
            if turn < threshold || quarter < threshold {
                continue;
            }
            match out.last_mut() {
                Some(last) if sj - last.2 < self.w => {
                    if turn > last.1 {
                        *last = (j, turn, sj);
                    }
                }
                _ => out.push((j, turn, sj)),
            }
        }
        out.into_iter().map(|(j, turn, _)| (j, turn)).collect()
    }
}

/// A corner of a point cloud that the cloud resolves as a rounding (`rounding_of`):
/// not a kink, the `C^1` fit follows it (the report's `roundings`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rounding {
    /// The side.
    pub side: Side,
    /// The cord-length abscissa of the vertex turning most, in `[0, 1]`.
    pub parameter: f64,
    /// That vertex (in the coordinates the hierarchy was built in).
    pub point: Point,
    /// Turning of the chords at the detection's window `w`, degrees.
    pub turning_degrees: f64,
    /// The radius of the circular fillet with the same turning at the same scale.
    pub radius: f64,
    /// Its sagitta `R (1 / cos(θ / 2) - 1)`: how far inside the sharp corner the cloud
    /// passes.
    pub sagitta: f64,
    /// Points of the cloud within the half-turn window `v` of the vertex per direction.
    pub points: usize,
}

/// The share of a corner's turning that the chords to the neighbours of a polygon's vertex
/// turn by at least ([`rounding_of`]): a vertex sampled on both legs turns by all of it
/// (up to noise); the sharpest jigsaw roundings, resolved by two points, by 48 to 59 %
/// (BENCHMARKS.md "Puzzle necks and hair-thin gaps").
pub(crate) const VERTEX_SHARE: f64 = 0.9;

/// Whether the corner of a point cloud at vertex `j` (turning `θ` at the window `w`) is a
/// rounding the cloud resolves, and its size: with `h` the mean point spacing, the
/// smallest window `v = m h` at which the chords turn by at least `θ / 2`. A polygon's
/// vertex turns by all of `θ` between its neighbours: a kink where the chords to the
/// neighbours turn by at least [`VERTEX_SHARE`] of `θ`, or where `θ` is within a degree of
/// a cusp (`None`). Otherwise the cloud resolves the corner as a curve over two or more
/// chords, and the `C^1` fit either follows it or rounds it within its tolerance: a
/// rounding, no kink (BENCHMARKS.md "Puzzle necks and hair-thin gaps": keeping such
/// corners as kinks made the jigsaw pieces time out, and a 36-degree one whose sagitta
/// is below the tolerance sent jigsaw-4 through a `C^0` route that failed).
/// `Some((R, s, m))`: a circular fillet of radius `R` turns by `v / R` at the window `v`
/// (both chords on the arc), so half of `θ` at `v = R θ / 2`: `R ≈ 2 v / θ`, and the
/// cloud passes `s = R (1 / cos(θ / 2) - 1)` inside the sharp corner (the sagitta, to
/// compare with the fit tolerance: above it the fit follows the rounding).
pub(crate) fn rounding_of(points: &[Point], j: usize, w: f64) -> Option<(f64, f64, usize)> {
    let n = points.len();
    if n < 3 || j == 0 || j + 1 >= n {
        return None;
    }
    let mut s = vec![0.0; n];
    for q in 1..n {
        s[q] = s[q - 1] + (points[q][0] - points[q - 1][0]).hypot(points[q][1] - points[q - 1][1]);
    }
    let h = s[n - 1] / (n - 1) as f64;
    let theta = chord_turning(points, &s, j, w).to_radians();
    if !(theta > 0.0 && h > 0.0) || theta >= std::f64::consts::PI - 1f64.to_radians() {
        return None;
    }
    // the turning between the neighbours' chords, then the window at which half of it is
    // reached; 0.999: a point spacing of the window itself counts
    let at = |m: usize| chord_turning(points, &s, j, 0.999 * m as f64 * h).to_radians();
    if at(1) >= VERTEX_SHARE * theta {
        return None;
    }
    let mut m = 1;
    while at(m) < 0.5 * theta {
        m += 1;
        if m as f64 * h >= w {
            break;
        }
    }
    let radius = 2.0 * m as f64 * h / theta;
    let sagitta = radius * (1.0 / (0.5 * theta).cos() - 1.0);
    Some((radius, sagitta, m))
}

/// The kinks of `boundary` that `mode` keeps (south, east, north, west, each by
/// parameter), or that the report names when `mode` is [`KinkMode::None`] and `report`
/// is set (then with the thresholds of [`KinkMode::Auto`]). `input_basis`: every `C^0`
/// knot of a spline side counts whatever its angle (the input basis is `C^0` there).
/// Analytic sides have none. [`Candidates`] finds them once for several modes.
pub(crate) fn detect(boundary: &Boundary, mode: KinkMode, input_basis: bool) -> Vec<Kink> {
    match mode.cloud_threshold() {
        Some(floor) => Candidates::find(boundary, floor).kinks(mode, input_basis),
        None => Vec::new(),
    }
}

/// The rounded corners of a closed point cloud (a ring's contour, opened at its first
/// point as the ring's report does): the corners turning at least
/// [`CLOUD_CORNER_DEGREES`] that [`rounding_of`] finds resolved, as
/// `(vertex index, radius R, points m)`.
pub(crate) fn closed_cloud_roundings(points: &[Point]) -> Vec<(usize, f64, usize)> {
    let mut open = points.to_vec();
    open.extend(points.first().copied());
    let turnings = CornerTurnings::of(&open, CLOUD_CORNER_DEGREES);
    let corners = turnings.corners(CLOUD_CORNER_DEGREES);
    corners.into_iter().filter_map(|(j, _)| rounding_of(&open, j, turnings.w).map(|(r, _, m)| (j, r, m))).collect()
}

/// [`detect`] with a point cloud's rounded corners taken out as roundings
/// ([`Candidates::with_roundings`]): the kinks and the roundings, as the hierarchy of a
/// four-sided boundary reports them (a ring's report uses it too).
pub(crate) fn detect_with_roundings(
    boundary: &Boundary,
    mode: KinkMode,
    input_basis: bool,
) -> (Vec<Kink>, Vec<Rounding>) {
    match mode.cloud_threshold() {
        Some(floor) => {
            let found = Candidates::find(boundary, floor).with_roundings();
            (found.kinks(mode, input_basis), found.roundings(mode))
        }
        None => (Vec::new(), Vec::new()),
    }
}

/// The candidate kinks of a boundary's sides, measured once ([`Candidates::find`]): the
/// interior knots of spline sides that [`spline_kinks`] lists, and the turnings of point
/// clouds' vertices; [`Candidates::kinks`] gives the kinks of any mode from them, as
/// [`detect`] does (the hierarchy keeps those of `--kinks`, the report names those of
/// [`KinkMode::Auto`] that were rounded).
#[derive(Debug, Clone, Default)]
pub(crate) struct Candidates {
    sides: [SideCandidates; 4],
    /// With [`Candidates::with_roundings`]: a point cloud's rounded corner is not a kink
    /// ([`rounding_of`]).
    roundings: bool,
}

#[derive(Debug, Clone, Default)]
enum SideCandidates {
    #[default]
    None,
    Spline(Vec<KnotKink>),
    Cloud {
        params: Vec<f64>,
        points: Vec<Point>,
        turnings: CornerTurnings,
    },
}

impl Candidates {
    /// Measure the sides of `boundary`; point-cloud vertices turning less than `floor`
    /// degrees at the window `w` are not kept (no mode below it is asked for later).
    pub fn find(boundary: &Boundary, floor: f64) -> Self {
        let side = |s: Side| match boundary.side(s) {
            SideCurve::Spline(c) => SideCandidates::Spline(spline_kinks(c)),
            SideCurve::Points(pts) => match crate::boundary::cord_length::cord_length_params(pts) {
                Some(params) => {
                    SideCandidates::Cloud { params, points: pts.clone(), turnings: CornerTurnings::of(pts, floor) }
                }
                None => SideCandidates::None,
            },
            SideCurve::Analytic(_) => SideCandidates::None,
        };
        Self { sides: Side::ALL.map(side), roundings: false }
    }

    /// The same candidates, a point cloud's corner that the cloud resolves as a rounding
    /// no kink in any mode ([`rounding_of`]; [`Candidates::roundings`] lists them).
    pub fn with_roundings(mut self) -> Self {
        self.roundings = true;
        self
    }

    /// Whether the corner at vertex `j` of `points` is a rounding (never without
    /// [`Candidates::with_roundings`]).
    fn rounding(&self, points: &[Point], turnings: &CornerTurnings, j: usize) -> Option<(f64, f64, usize)> {
        if self.roundings {
            rounding_of(points, j, turnings.w)
        } else {
            None
        }
    }

    /// The corners of the point clouds turning at least the threshold of `mode` that are
    /// roundings, not kinks ([`Candidates::with_roundings`]); none without it.
    pub fn roundings(&self, mode: KinkMode) -> Vec<Rounding> {
        let mut out = Vec::new();
        let Some(cloud_min) = mode.cloud_threshold() else { return out };
        for (s, side) in Side::ALL.into_iter().zip(&self.sides) {
            if let SideCandidates::Cloud { params, points, turnings } = side {
                for (j, turn) in turnings.corners(cloud_min) {
                    if let Some((radius, sagitta, m)) = self.rounding(points, turnings, j) {
                        out.push(Rounding {
                            side: s,
                            parameter: params[j],
                            point: points[j],
                            turning_degrees: turn,
                            radius,
                            sagitta,
                            points: m,
                        });
                    }
                }
            }
        }
        out
    }

    /// The kinks `mode` keeps, as [`detect`] with the same arguments finds them (a mode
    /// whose point-cloud threshold is below the floor of [`Candidates::find`] misses the
    /// corners between the two).
    pub fn kinks(&self, mode: KinkMode, input_basis: bool) -> Vec<Kink> {
        let mut out = Vec::new();
        let (Some(spline_min), Some(cloud_min)) = (mode.spline_threshold(), mode.cloud_threshold()) else {
            return out;
        };
        for (s, side) in Side::ALL.into_iter().zip(&self.sides) {
            match side {
                SideCandidates::Spline(list) => {
                    for k in list.iter().filter(|k| (input_basis && k.c0_knot) || k.turning_degrees > spline_min) {
                        out.push(Kink {
                            side: s,
                            parameter: k.t,
                            point: k.point,
                            turning_degrees: k.turning_degrees,
                            kind: if k.zero_speed { KinkKind::ZeroSpeed } else { KinkKind::C0Knot },
                            index: None,
                            map_parameter: None,
                        });
                    }
                }
                SideCandidates::Cloud { params, points, turnings } => {
                    for (j, turn) in turnings.corners(cloud_min) {
                        if self.rounding(points, turnings, j).is_some() {
                            continue;
                        }
                        out.push(Kink {
                            side: s,
                            parameter: params[j],
                            point: points[j],
                            turning_degrees: turn,
                            kind: KinkKind::Corner,
                            index: Some(j),
                            map_parameter: None,
                        });
                    }
                }
                SideCandidates::None => {}
            }
        }
        out
    }
}

impl Kink {
    /// The kink's point on `boundary`'s side: the vertex of its index on a point cloud,
    /// the side at its knot on a spline (the knot whose normalised value is
    /// [`Kink::parameter`]); exactly the point [`detect`] gives on `boundary` when the
    /// kink was found on a boundary with the same knots and vertex count (e.g. its
    /// normalised copy, [`Similarity::unit_boundary`](crate::boundary::normalise::Similarity::unit_boundary)).
    /// `None` when the side has no such vertex or knot.
    pub(crate) fn point_on(&self, boundary: &Boundary) -> Option<Point> {
        match boundary.side(self.side) {
            SideCurve::Points(pts) => self.index.and_then(|j| pts.get(j).copied()),
            SideCurve::Spline(c) => {
                let (a, b) = c.domain();
                let breaks = c.knots.breaks_with_multiplicity();
                breaks.iter().map(|&(u, _)| u).find(|&u| (u - a) / (b - a) == self.parameter).map(|u| c.eval(u))
            }
            SideCurve::Analytic(_) => None,
        }
    }
}

/// The kinks stored in a map document's `"report"` (`kinks[].point` and `kinks[].kept`
/// of the solve report): points and whether the map keeps them; malformed entries are
/// skipped.
pub fn kinks_in_report(report: &serde_json::Value) -> Vec<(Point, bool)> {
    let Some(kinks) = report["kinks"].as_array() else { return Vec::new() };
    kinks
        .iter()
        .filter_map(|k| {
            let p: Point = serde_json::from_value(k["point"].clone()).ok()?;
            Some((p, k["kept"].as_bool().unwrap_or(false)))
        })
        .collect()
}

/// Every interior break of `kv` of multiplicity at least `p` (a kink's knot line) lowered
/// to `p - 1` (paper §9: `Σ¹` from `Σ⁰`).
pub fn lowered(kv: &KnotVector) -> KnotVector {
    let p = kv.degree();
    let bm = kv.breaks_with_multiplicity();
    let last = bm.len() - 1;
    let mut knots = Vec::with_capacity(kv.knots().len());
    for (k, &(u, m)) in bm.iter().enumerate() {
        let m = if k == 0 || k == last { p + 1 } else { m.min(p - 1) };
        knots.extend(std::iter::repeat_n(u, m));
    }
    KnotVector::new(p, knots).expect("lowering multiplicities keeps an open knot vector")
}

/// The least-squares projection (§5.2, corners kept) of `c` onto the space of `kv`; a
/// rational curve is projected in homogeneous coordinates (`w x`, `w y` and `w`), so a
/// curve that lies in the space is reproduced with its weights.
pub(crate) fn project_curve(c: &Curve, kv: &KnotVector) -> Result<Curve> {
    let Some(w) = &c.weights else {
        let ends = c.endpoints();
        return Ok(project_side(&SideCurve::Spline(c.clone()), kv, ends)?.curve);
    };
    let homogeneous =
        Curve::polynomial(c.knots.clone(), c.control_points.iter().zip(w).map(|(p, w)| [w * p[0], w * p[1]]).collect());
    let weight = Curve::polynomial(c.knots.clone(), w.iter().map(|&w| [w, 0.0]).collect());
    let ends = |c: &Curve| c.endpoints();
    let h = project_side(&SideCurve::Spline(homogeneous.clone()), kv, ends(&homogeneous))?.curve;
    let wt = project_side(&SideCurve::Spline(weight.clone()), kv, ends(&weight))?.curve;
    let weights: Vec<f64> = wt.control_points.iter().map(|p| p[0]).collect();
    if let Some(k) = weights.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(Error::Invalid(format!(
            "the smoothed rational side has weight {} at control point {k}: a rational side cannot be smoothed there",
            weights[k]
        )));
    }
    let cps = h.control_points.iter().zip(&weights).map(|(p, w)| [p[0] / w, p[1] / w]).collect();
    Curve::new(kv.clone(), cps, Some(weights))
}

/// `Σ¹` of a level (paper §9): the kink lines' multiplicity lowered by one
/// ([`lowered`]) and every side whose knot vector changed projected onto it
/// ([`project_curve`]: a smooth side, in the space already, is reproduced; a kinked one is
/// rounded).
pub(crate) fn smoothed_level(level: &Level) -> Result<Level> {
    let knots = [lowered(&level.knots[0]), lowered(&level.knots[1])];
    if knots == level.knots {
        return Ok(level.clone());
    }
    let mut sides = level.sides.clone();
    for s in Side::ALL {
        let d = s.direction();
        if knots[d] != level.knots[d] {
            sides[s as usize] = project_curve(level.side(s), &knots[d])?;
        }
    }
    Ok(Level { knots, sides })
}

/// Every level smoothed ([`smoothed_level`]); levels that end up with equal knot vectors
/// are merged (the finer one's sides kept).
pub(crate) fn smoothed_levels(levels: &[Level]) -> Result<Vec<Level>> {
    let mut out: Vec<Level> = Vec::with_capacity(levels.len());
    for l in levels {
        let l = smoothed_level(l)?;
        match out.last_mut() {
            Some(prev) if prev.knots == l.knots => *prev = l,
            _ => out.push(l),
        }
    }
    Ok(out)
}

/// `Σ⁰` with the kinks and what they are: the level the map ends on.
#[derive(Debug, Clone)]
pub struct KinkedLevel {
    /// The `C^0` basis (a knot of multiplicity `p` at each kink) with the sides, exact at
    /// the kinks.
    pub level: Level,
    /// The kinks kept, with their [`Kink::map_parameter`] set.
    pub kinks: Vec<Kink>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A polygon sampled densely with noise-free points: its vertices, and nothing else;
    /// a densely sampled circle arc has none.
    #[test]
    fn cloud_corners_find_polygon_vertices() {
        let verts: [Point; 4] = [[0.0, 0.0], [1.0, 0.0], [1.5, 0.8], [2.5, 0.9]];
        let mut pts = Vec::new();
        for w in verts.windows(2) {
            for k in 0..40 {
                let t = k as f64 / 40.0;
                pts.push([w[0][0] + t * (w[1][0] - w[0][0]), w[0][1] + t * (w[1][1] - w[0][1])]);
            }
        }
        pts.push(verts[3]);
        let c = cloud_corners(&pts, 30.0);
        assert_eq!(c.iter().map(|c| c.0).collect::<Vec<_>>(), vec![40, 80], "{c:?}");
        let t1 = (0.8f64).atan2(0.5).to_degrees();
        assert!((c[0].1 - t1).abs() < 1e-9, "{c:?}");
        // sparse: the vertices alone
        let c = cloud_corners(&verts, 30.0);
        assert_eq!(c.iter().map(|c| c.0).collect::<Vec<_>>(), vec![1, 2]);
        // an arc of 90 degrees in 200 points: no corner
        let arc: Vec<Point> = (0..=200)
            .map(|k| {
                let t = std::f64::consts::FRAC_PI_2 * k as f64 / 200.0;
                [t.cos(), t.sin()]
            })
            .collect();
        assert!(cloud_corners(&arc, 30.0).is_empty());
    }

    /// Two legs of length 1 meeting at a right angle, the corner replaced by a circular
    /// fillet of radius `r`, sampled every `h` of arc length.
    fn filleted_corner(r: f64, h: f64) -> Vec<Point> {
        let arc = std::f64::consts::FRAC_PI_2 * r;
        let total = 2.0 * (1.0 - r) + arc;
        let n = (total / h).round() as usize;
        (0..=n)
            .map(|k| {
                let s = total * k as f64 / n as f64;
                if s <= 1.0 - r {
                    [s, 0.0]
                } else if s <= 1.0 - r + arc {
                    let a = (s - (1.0 - r)) / r;
                    [1.0 - r + r * a.sin(), r - r * a.cos()]
                } else {
                    [1.0, r + s - (1.0 - r + arc)]
                }
            })
            .collect()
    }

    /// The detection's scale (a window `w` of 1 % of the side's length, here 0.02, and
    /// `w / 4`) on a right-angled corner rounded by a fillet of radius `R` and sampled
    /// every `5e-4`: the chords at `w / 4` on the fillet turn by `w / (4R)` radians, so a
    /// fillet counts as a corner up to `R` of about `w / 2` (30 degrees): one resolved by
    /// three points (`R = 1e-3`, arc `1.6e-3`) turns by nearly 90 degrees at the window
    /// `w`, one of 16 points (`R = 5e-3`, arc `7.9e-3`) by about 81; one of 31 points
    /// (`R = 1e-2`) is not a corner (the chords at `w / 4` turn by 0.5 radians), nor is
    /// one of radius `0.05`.
    #[test]
    fn cloud_corners_resolve_fillets_shorter_than_the_window() {
        for (r, least) in [(1e-3, Some(85.0)), (5e-3, Some(78.0)), (1e-2, None), (5e-2, None)] {
            let pts = filleted_corner(r, 5e-4);
            let c = cloud_corners(&pts, CLOUD_CORNER_DEGREES);
            if let Some(least) = least {
                assert_eq!(c.len(), 1, "radius {r}: {c:?}");
                let p = pts[c[0].0];
                // the vertex found lies on the fillet, and the turning is nearly the corner's
                assert!((p[0] - 1.0).hypot(p[1]) <= r * 2f64.sqrt() + 5e-4, "radius {r}: {p:?}");
                assert!(c[0].1 > least && c[0].1 <= 90.0 + 1e-9, "radius {r}: {c:?}");
            } else {
                assert!(c.is_empty(), "radius {r}: {c:?}");
            }
        }
    }

    /// The rounding rule ([`rounding_of`]) on the closed-form fillet of radius `R` (a
    /// right-angled corner, sampled every `h = 5e-4`): the fillet turns by `v / R` at the
    /// window `v`, so the half-turn window is `R π / 4` up to one spacing, and the
    /// estimated radius is `R` within `2 h / θ` (`θ = π / 2`); its sagitta is `R (√2 - 1)`.
    /// A polygon's vertex (all of the turning between its neighbours) is a kink, and so is
    /// a fillet narrower than the spacing.
    #[test]
    fn a_fillet_the_cloud_resolves_is_a_rounding() {
        let h = 5e-4;
        let theta = std::f64::consts::FRAC_PI_2;
        for r in [1e-3, 2e-3, 5e-3] {
            let pts = filleted_corner(r, h);
            let total: f64 = pts.windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum();
            let w = CORNER_WINDOW * total;
            let c = cloud_corners(&pts, CLOUD_CORNER_DEGREES);
            assert_eq!(c.len(), 1, "radius {r}: {c:?}");
            let (radius, s, m) = rounding_of(&pts, c[0].0, w).expect("a rounding");
            assert!((radius - r).abs() <= 2.0 * h / theta * 1.01, "radius {r}: estimated {radius}");
            // the turning measured at the window w is 80 to 90 degrees
            let sag = |deg: f64| radius * (1.0 / (0.5 * deg.to_radians()).cos() - 1.0);
            assert!(s >= sag(80.0) && s <= sag(90.0) * (1.0 + 1e-12), "radius {r}: sagitta {s}");
            let half = r * theta / 2.0;
            assert!((m as f64 * h - half).abs() <= h, "radius {r}: half-turn window {m} points against {half}");
        }
        // a sharp vertex, and a fillet a fifth of the spacing: all of the turning (or
        // nearly) between the neighbours
        for r in [0.0, 1e-4] {
            let sharp = filleted_corner(r, h);
            let c = cloud_corners(&sharp, CLOUD_CORNER_DEGREES);
            assert_eq!(c.len(), 1);
            assert_eq!(rounding_of(&sharp, c[0].0, 0.02), None, "radius {r}");
        }
    }

    #[test]
    fn kinks_are_read_from_a_stored_report() {
        let r = serde_json::json!({ "kinks": [
            { "side": "north", "point": [-4.0, 4.0], "kept": true },
            { "side": "east", "point": [1.0, 2.0], "kept": false },
            { "side": "east", "point": "malformed" }
        ] });
        assert_eq!(kinks_in_report(&r), vec![([-4.0, 4.0], true), ([1.0, 2.0], false)]);
        assert!(kinks_in_report(&serde_json::json!({ "verdict": "certified" })).is_empty());
    }

    /// `C^0` knots and zero-speed knots of spline sides, with their turning.
    #[test]
    fn spline_kinks_are_c0_and_zero_speed_knots() {
        // quadratic with a double knot at 0.5: C0, turning 90 degrees
        let kv = KnotVector::new(2, vec![0., 0., 0., 0.5, 0.5, 1., 1., 1.]).unwrap();
        let c = Curve::polynomial(kv, vec![[0., 0.], [0.5, 0.], [1., 0.], [1., 0.5], [1., 1.]]);
        let k = spline_kinks(&c);
        assert_eq!(k.len(), 1);
        assert!(k[0].c0_knot && !k[0].zero_speed && (k[0].turning_degrees - 90.0).abs() < 1e-6, "{k:?}");
        // plate_with_hole's north side: a repeated control point, speed zero at 0.5
        let kv = KnotVector::new(2, vec![0., 0., 0., 0.5, 1., 1., 1.]).unwrap();
        let c = Curve::polynomial(kv, vec![[-4., 0.], [-4., 4.], [-4., 4.], [0., 4.]]);
        let k = spline_kinks(&c);
        assert_eq!(k.len(), 1);
        assert!(!k[0].c0_knot && k[0].zero_speed && (k[0].turning_degrees - 90.0).abs() < 1e-6, "{k:?}");
        assert_eq!(k[0].point, [-4., 4.]);
        // a smooth cubic with simple knots: none
        let kv = KnotVector::open_uniform(3, 4);
        let c = Curve::polynomial(kv, (0..7).map(|i| [i as f64, (i as f64).sin()]).collect());
        assert!(spline_kinks(&c).is_empty());
    }

    /// Lowering the multiplicity and projecting: a smooth curve refined onto `Σ⁰` is
    /// reproduced on `Σ¹` (knot removal is exact in the space), a kinked one is rounded.
    #[test]
    fn smoothing_reproduces_smooth_sides_and_rounds_kinks() {
        let kv0 = KnotVector::new(3, vec![0., 0., 0., 0., 0.4, 0.4, 0.4, 1., 1., 1., 1.]).unwrap();
        let kv1 = lowered(&kv0);
        assert_eq!(kv1.multiplicity(0.4), 2);
        let smooth =
            Curve::polynomial(KnotVector::open_uniform(3, 1), vec![[0., 0.], [0.3, 0.2], [0.7, -0.1], [1., 0.]]);
        let on0 = smooth.refined(&kv0).unwrap();
        let p = project_curve(&on0, &kv1).unwrap();
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            let (a, b) = (p.eval(t), smooth.eval(t));
            assert!((a[0] - b[0]).abs() < 1e-13 && (a[1] - b[1]).abs() < 1e-13);
        }
        let kinked = Curve::polynomial(
            kv0.clone(),
            vec![[0., 0.], [0.1, 0.], [0.3, 0.], [0.4, 0.], [0.4, 0.2], [0.4, 0.4], [0.4, 0.6]],
        );
        let r = project_curve(&kinked, &kv1).unwrap();
        let at = r.eval(0.4);
        assert!((at[0] - 0.4).abs() + at[1].abs() > 1e-3, "the kink is rounded on Σ¹: {at:?}");
        // a rational arc (quarter circle) on a refined basis is reproduced with its weights
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let arc = Curve::new(KnotVector::open_uniform(2, 1), vec![[1., 0.], [1., 1.], [0., 1.]], Some(vec![1., s, 1.]))
            .unwrap();
        let kv = KnotVector::new(2, vec![0., 0., 0., 0.5, 0.5, 1., 1., 1.]).unwrap();
        let on0 = arc.refined(&kv).unwrap();
        let r = project_curve(&on0, &lowered(&kv)).unwrap();
        for k in 0..=20 {
            let x = r.eval(k as f64 / 20.0);
            assert!((x[0].hypot(x[1]) - 1.0).abs() < 1e-12, "{x:?}");
        }
    }
}
