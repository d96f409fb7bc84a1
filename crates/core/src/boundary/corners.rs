//! The singular points of a boundary, where the Jacobian determinant of any map is
//! forced: the four corners of the patch and the kinks inside a side.
//!
//! At a corner `det J = x_ξ × x_η` is the cross product of the two side tangents, so an
//! interior angle of 180° or more (or a vanishing tangent) forces `det J ≤ 0` there
//! whatever the interior control points; the certificate ([`crate::verify::certificate`])
//! excuses such corners and the report names them. A kink (a `C^0` break where the
//! tangent turns) forces `det J = 0` for every `C^1` map of the exact side; where they are
//! and how they are kept: [`super::kinks`].

use serde::Serialize;

use crate::spline::curve::{Curve, Point};
use crate::spline::surface::Side;

/// Angle of the domain at a corner and whether it forces `det J <= 0` there.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
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
pub(crate) const FORCED_ANGLE: f64 = 179.0;

/// A kink inside a side (paper §9, [`super::kinks`]): a spline side's `C^0` knot or
/// zero-speed knot, or a point cloud's corner; kept exactly by the `C^0` route or rounded
/// by the `C^1` fit.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct KinkReport {
    /// Side name.
    pub side: &'static str,
    /// Parameter on the input side, in `[0, 1]` (a point cloud's cord-length abscissa).
    pub parameter: f64,
    /// Physical point.
    pub point: [f64; 2],
    /// Turning angle of the tangent in degrees (180 for a cusp).
    pub turning_degrees: f64,
    /// `c0-knot`, `zero-speed` or `corner` (a point cloud's).
    pub kind: super::kinks::KinkKind,
    /// Whether the map keeps it exactly (a knot line of multiplicity `p` through it).
    pub kept: bool,
    /// Where it lies on the map's side (the knot line's parameter) when kept.
    pub map_parameter: Option<f64>,
    /// Distance of the map's boundary from the point: at `map_parameter` when kept
    /// (rounding level), else to the nearest point of the side (the rounding).
    pub deviation: f64,
}

/// Geometry of one corner of a patch: interior angle, `x_xi x x_eta` (det J there) and
/// `|x_xi| |x_eta|`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CornerGeometry {
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
pub(crate) fn corner_geometry(d: impl Fn(Side, bool) -> Point) -> [CornerGeometry; 4] {
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
