//! The singular points of a boundary, where the Jacobian determinant of any map is
//! forced: the four corners of the patch and the kinks inside a side.
//!
//! At a corner `det J = x_ξ × x_η` is the cross product of the two side tangents, so an
//! interior angle of 180° or more (or a vanishing tangent) forces `det J ≤ 0` there
//! whatever the interior control points; the certificate ([`crate::verify::certificate`])
//! excuses such corners and the report names them. A kink (a `C^0` break where the
//! tangent turns) forces `det J = 0` for every `C^1` map of the exact side.

use serde::Serialize;

use super::Boundary;
use crate::spline::basis::BasisDerivs;
use crate::spline::curve::{Curve, Point};
use crate::spline::surface::Side;

/// Angle of the domain at a corner and whether it forces `det J <= 0` there.
#[derive(Debug, Clone, Serialize)]
pub struct CornerReport {
    /// "south-west", ...
    pub corner: &'static str,
    /// Interior angle in degrees (from the fitted sides' tangents).
    pub angle_degrees: f64,
    /// `det J` at the corner equals the cross product of the two side tangents; it is
    /// `<= 0` whenever the angle is `>= 180` degrees or a tangent vanishes.
    pub forces_nonpositive_det_j: bool,
}

/// Corner angles at or above this (degrees) force `det J <= 0` up to the fit tolerance.
pub const FORCED_ANGLE: f64 = 179.0;

/// A kink inside a spline side: a break of continuity `C^0` where the tangent turns.
#[derive(Debug, Clone, Serialize)]
pub struct KinkReport {
    /// Side name.
    pub side: &'static str,
    /// Parameter on the side, in `[0, 1]`.
    pub parameter: f64,
    /// Physical point.
    pub point: [f64; 2],
    /// Turning angle of the tangent in degrees (180 for a cusp or zero speed).
    pub turning_degrees: f64,
}

/// Kinks of the input's spline sides: at every interior knot the one-sided tangent
/// directions are compared (just off the knot, so that a zero speed at the knot, as
/// with coincident control points, still shows its turn); a turn of more than one
/// degree is a kink. Any `C^1` map of the exact boundary has zero speed, so
/// `det J = 0`, at such a point; the fitted boundary rounds it within the tolerance.
pub fn boundary_kinks(boundary: &Boundary) -> Vec<KinkReport> {
    let mut out = Vec::new();
    for s in Side::ALL {
        let super::SideCurve::Spline(c) = boundary.side(s) else { continue };
        let bm = c.knots.breaks_with_multiplicity();
        let spans: Vec<(usize, f64, f64)> = c.knots.elements();
        for &(u, _) in &bm[1..bm.len().saturating_sub(1)] {
            let left = spans.iter().find(|e| e.2 == u);
            let right = spans.iter().find(|e| e.1 == u);
            let (Some(l), Some(r)) = (left, right) else { continue };
            // one-sided tangent directions just off the break (robust to zero speed at it)
            let mut b = BasisDerivs::default();
            let dl = {
                b.eval_in_span(&c.knots, l.0, u - 1e-9 * (l.2 - l.1), 1);
                c.derivs_with(&b, 1).d1
            };
            let dr = {
                b.eval_in_span(&c.knots, r.0, u + 1e-9 * (r.2 - r.1), 1);
                c.derivs_with(&b, 1).d1
            };
            let (sl, sr) = (dl[0].hypot(dl[1]), dr[0].hypot(dr[1]));
            let turning = if sl == 0.0 || sr == 0.0 {
                180.0
            } else {
                (dl[0] * dr[1] - dl[1] * dr[0]).atan2(dl[0] * dr[0] + dl[1] * dr[1]).to_degrees().abs()
            };
            if turning > 1.0 {
                let (a, bb) = c.domain();
                out.push(KinkReport {
                    side: s.name(),
                    parameter: (u - a) / (bb - a),
                    point: c.eval(u),
                    turning_degrees: turning,
                });
            }
        }
    }
    out
}

/// Geometry of one corner of a patch: interior angle, `x_xi x x_eta` (det J there) and
/// `|x_xi| |x_eta|`.
#[derive(Debug, Clone, Copy)]
pub struct CornerGeometry {
    /// "south-west", "south-east", "north-east" or "north-west".
    pub name: &'static str,
    /// Interior angle in degrees.
    pub angle_degrees: f64,
    /// `x_ξ × x_η`, which is `det J` at the corner.
    pub cross: f64,
    /// `|x_ξ| |x_η|`.
    pub speed: f64,
}

/// The four corners (south-west, south-east, north-east, north-west) from the side
/// tangents `d(side, at_end)`: the interior angle is 180 degrees minus the turning angle
/// between the incoming and outgoing tangents of the counter-clockwise traversal (south,
/// east, reversed north, reversed west).
pub fn corner_geometry(d: impl Fn(Side, bool) -> Point) -> [CornerGeometry; 4] {
    // (name, x_xi, x_eta) at the corner; det J = x_xi x x_eta.
    let corners = [
        ("south-west", d(Side::South, false), d(Side::West, false)),
        ("south-east", d(Side::South, true), d(Side::East, false)),
        ("north-east", d(Side::North, true), d(Side::East, true)),
        ("north-west", d(Side::North, false), d(Side::West, true)),
    ];
    std::array::from_fn(|k| {
        let (name, a, b) = corners[k];
        let (din, dout) = match k {
            0 => ([-b[0], -b[1]], a),
            1 => (a, b),
            2 => (b, [-a[0], -a[1]]),
            _ => ([-a[0], -a[1]], [-b[0], -b[1]]),
        };
        let turn = (din[0] * dout[1] - din[1] * dout[0]).atan2(din[0] * dout[0] + din[1] * dout[1]).to_degrees();
        CornerGeometry {
            name,
            angle_degrees: 180.0 - turn,
            cross: a[0] * b[1] - a[1] * b[0],
            speed: a[0].hypot(a[1]) * b[0].hypot(b[1]),
        }
    })
}

/// Corners in the order south-west, south-east, north-east, north-west with their
/// angles, from the side curves of a level.
pub fn corner_report(sides: &[Curve; 4]) -> Vec<CornerReport> {
    let d = |s: Side, end: bool| sides[s as usize].derivs(if end { 1.0 } else { 0.0 }, 1).d1;
    corner_geometry(d)
        .into_iter()
        .map(|c| CornerReport {
            corner: c.name,
            angle_degrees: c.angle_degrees,
            // 180 degrees within the fit tolerance also counts: det J -> 0 there
            forces_nonpositive_det_j: c.speed == 0.0 || c.cross <= 1e-10 * c.speed || c.angle_degrees >= FORCED_ANGLE,
        })
        .collect()
}
