//! The similarity that brings a boundary to unit size at the origin before it is fitted
//! and solved, and the map back to the user's coordinates.
//!
//! EGG (eq. 8) and the certificate are invariant under similarities `x ↦ c + s x`
//! (`det J` scales by `s²`, the Laplacians of the inverse by `1/s²`), but floating point is
//! not: far from the origin every difference of control points cancels digits (a domain
//! of size 1 at `1e9` keeps 7 of its 16), and at sizes of `1e±200` products such as
//! `det J = x_ξ y_η − x_η y_ξ` over- or underflow. So the pipeline works in the
//! normalised coordinates
//!
//! ```text
//! x̂ = (x − c) / s,    x = c + s x̂,
//! ```
//!
//! with `c` the centre of the bounding box and `s = 2^k` the power of two nearest to its
//! half-width: multiplication by `s` is exact, so lengths, tolerances and `det J` values
//! convert back without rounding, and only the translation rounds (to the precision the
//! input itself has at its position). The transform is the identity, and the pipeline's
//! results bit-for-bit those of the raw coordinates, when the domain is already well
//! placed: its centre within [`TRANSLATE_ABOVE`] half-widths of the origin and its
//! half-width within `2^±`[`SCALE_OUTSIDE_LOG2`].
//!
//! Half-widths outside `[2^-`[`MAX_LOG2`]`, 2^`[`MAX_LOG2`]`]` are refused with
//! [`Error::Range`]: `det J ~ s²` of the physical map would leave the normal range of
//! `f64` (it is about `2^±1022`), so neither the written map's certificate nor its report
//! could be computed.

use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};
use crate::spline::surface::Surface;

use super::{bounding_box, Analytic, Boundary, SideCurve};

/// The centre is moved to the origin when it lies more than this many half-widths away.
pub(crate) const TRANSLATE_ABOVE: f64 = 16.0;
/// The size is scaled when the half-width is outside `[2^-20, 2^20]`.
pub(crate) const SCALE_OUTSIDE_LOG2: i32 = 20;
/// Largest accepted `|log2(half-width)|`.
pub(crate) const MAX_LOG2: i32 = 508;

/// `x = centre + scale · x̂`, `scale` a power of two.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Similarity {
    /// `c`: the physical point that becomes the origin.
    pub centre: Point,
    /// `s = 2^k`: the physical length that becomes 1.
    pub scale: f64,
}

impl Default for Similarity {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Similarity {
    /// `c = 0`, `s = 1`.
    pub(crate) const IDENTITY: Similarity = Similarity { centre: [0.0, 0.0], scale: 1.0 };

    /// Whether this is the identity (the pipeline then runs on the raw coordinates).
    pub fn is_identity(&self) -> bool {
        *self == Self::IDENTITY
    }

    /// The normalisation of `boundary` (see the module documentation). A boundary whose
    /// sampled points are not all finite, or whose bounding box has zero size, gets the
    /// identity: the validator names the side that is at fault.
    ///
    /// Errors: [`Error::Range`] when the half-width is outside `2^±MAX_LOG2` (`MAX_LOG2 = 508`).
    pub(crate) fn for_boundary(boundary: &Boundary) -> Result<Self> {
        let (lo, hi) = bounding_box(boundary);
        Self::for_box(lo, hi, &format!("boundary '{}'", boundary.name))
    }

    /// The normalisation of the box `[lo, hi]`; `what` names it in errors.
    pub(crate) fn for_box(lo: Point, hi: Point, what: &str) -> Result<Self> {
        if !(lo.iter().chain(&hi).all(|v| v.is_finite())) {
            return Ok(Self::IDENTITY);
        }
        // halves first: `hi - lo` itself may overflow
        let centre = [0.5 * lo[0] + 0.5 * hi[0], 0.5 * lo[1] + 0.5 * hi[1]];
        let half = (0.5 * hi[0] - 0.5 * lo[0]).max(0.5 * hi[1] - 0.5 * lo[1]);
        if half.is_nan() || half <= 0.0 {
            return Ok(Self::IDENTITY);
        }
        let k = half.log2().round() as i32;
        if k.abs() > MAX_LOG2 {
            return Err(Error::Range {
                what: format!(
                    "{what} has half-width {half:.3e}, outside [2^-{MAX_LOG2}, 2^{MAX_LOG2}] = [{:.1e}, {:.1e}]: det J of a map \
                     of it (~ size²) over- or underflows f64; scale the input",
                    pow2(-MAX_LOG2),
                    pow2(MAX_LOG2)
                ),
            });
        }
        let far = centre[0].abs().max(centre[1].abs()) > TRANSLATE_ABOVE * half;
        Ok(Similarity {
            centre: if far { centre } else { [0.0, 0.0] },
            scale: if k.abs() > SCALE_OUTSIDE_LOG2 { pow2(k) } else { 1.0 },
        })
    }

    /// `x̂ = (x − c) / s`.
    pub(crate) fn to_unit(self, p: Point) -> Point {
        [(p[0] - self.centre[0]) / self.scale, (p[1] - self.centre[1]) / self.scale]
    }

    /// `x = c + s x̂`.
    pub(crate) fn to_physical(self, p: Point) -> Point {
        [self.centre[0] + self.scale * p[0], self.centre[1] + self.scale * p[1]]
    }

    /// A physical length (exact: `s` is a power of two).
    pub fn length(&self, l: f64) -> f64 {
        self.scale * l
    }

    /// A physical area or `det J` value (exact).
    pub fn area(&self, a: f64) -> f64 {
        self.scale * self.scale * a
    }

    /// The boundary in normalised coordinates (control points and samples mapped; NURBS
    /// weights and parameterizations unchanged, so every side is the same curve).
    pub(crate) fn unit_boundary(&self, boundary: &Boundary) -> Boundary {
        if self.is_identity() {
            return boundary.clone();
        }
        let sim = *self;
        let side = |s: &SideCurve| match s {
            SideCurve::Spline(c) => SideCurve::Spline(self.map_curve(c, |p| sim.to_unit(p))),
            SideCurve::Points(p) => SideCurve::Points(p.iter().map(|&q| sim.to_unit(q)).collect()),
            SideCurve::Analytic(f) => {
                let f = f.clone();
                SideCurve::Analytic(Analytic::new(move |t| sim.to_unit(f.eval(t))))
            }
        };
        Boundary { name: boundary.name.clone(), sides: boundary.sides.each_ref().map(side) }
    }

    /// A curve of the normalised problem in physical coordinates.
    pub(crate) fn physical_curve(&self, c: &Curve) -> Curve {
        let sim = *self;
        self.map_curve(c, |p| sim.to_physical(p))
    }

    /// A map of the normalised problem in physical coordinates. Errors:
    /// [`Error::Range`] when a control point overflows.
    pub(crate) fn physical_surface(&self, map: &Surface) -> Result<Surface> {
        if self.is_identity() {
            return Ok(map.clone());
        }
        let control_points: Vec<Point> = map.control_points.iter().map(|&p| self.to_physical(p)).collect();
        if let Some(i) = control_points.iter().position(|p| !(p[0].is_finite() && p[1].is_finite())) {
            return Err(Error::Range {
                what: format!(
                    "control point {i} of the solved map overflows in the input's coordinates (normalised {:?}, scale {:e})",
                    map.control_points[i], self.scale
                ),
            });
        }
        Ok(Surface { knots: map.knots.clone(), control_points, weights: map.weights.clone() })
    }

    fn map_curve(&self, c: &Curve, f: impl Fn(Point) -> Point) -> Curve {
        if self.is_identity() {
            return c.clone();
        }
        Curve {
            knots: c.knots.clone(),
            control_points: c.control_points.iter().map(|&p| f(p)).collect(),
            weights: c.weights.clone(),
        }
    }
}

/// `2^k` for `|k| <= 1022`, exactly.
fn pow2(k: i32) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(lo: f64, size: f64) -> Boundary {
        let seg = |a: Point, b: Point| SideCurve::Points(vec![a, b]);
        let (a, b, c, d) = ([lo, lo], [lo + size, lo], [lo + size, lo + size], [lo, lo + size]);
        Boundary { name: "square".into(), sides: [seg(a, b), seg(b, c), seg(d, c), seg(a, d)] }
    }

    #[test]
    fn powers_of_two_are_exact() {
        assert_eq!(pow2(0), 1.0);
        assert_eq!(pow2(-3), 0.125);
        assert_eq!(pow2(508), 2f64.powi(508));
        assert_eq!(pow2(-508), 2f64.powi(-508));
    }

    #[test]
    fn well_placed_boundaries_are_left_alone() {
        for (lo, size) in [(0.0, 1.0), (-3.0, 2.0), (5.0, 1.0), (0.0, 1e5), (0.0, 1e-5)] {
            let s = Similarity::for_boundary(&square(lo, size)).unwrap();
            assert!(s.is_identity(), "{lo} {size}: {s:?}");
        }
    }

    #[test]
    fn far_and_extreme_boundaries_are_normalised_and_mapped_back() {
        for (lo, size) in [(1e9, 1.0), (-1e12, 3.0), (0.0, 1e150), (1e-150, 1e-150), (5e149, 1e149)] {
            let b = square(lo, size);
            let s = Similarity::for_boundary(&b).unwrap();
            assert!(!s.is_identity(), "{lo} {size}");
            let u = s.unit_boundary(&b);
            let (ulo, uhi) = bounding_box(&u);
            // half-width within 2^±(SCALE_OUTSIDE_LOG2 + 1), centre within
            // TRANSLATE_ABOVE half-widths of the origin
            let half = 0.5 * (uhi[0] - ulo[0]).max(uhi[1] - ulo[1]);
            let limit = pow2(SCALE_OUTSIDE_LOG2 + 1);
            assert!(half > 1.0 / limit && half < limit, "{lo} {size}: unit box {ulo:?} {uhi:?}");
            for c in 0..2 {
                let bound = (TRANSLATE_ABOVE + 1.0) * half;
                assert!(ulo[c] >= -bound && uhi[c] <= bound, "{lo} {size}: unit box {ulo:?} {uhi:?}");
            }
            // the map back is the inverse to rounding at the input's own position
            let p = [lo + 0.3 * size, lo + 0.7 * size];
            let q = s.to_physical(s.to_unit(p));
            for c in 0..2 {
                assert!((q[c] - p[c]).abs() <= 4.0 * f64::EPSILON * p[c].abs(), "{p:?} -> {q:?}");
            }
            // lengths and areas scale exactly
            assert_eq!(s.length(1.0) / s.scale, 1.0);
            assert_eq!(s.area(3.0), 3.0 * s.scale * s.scale);
        }
    }

    #[test]
    fn out_of_range_sizes_are_a_typed_error() {
        for size in [1e300, 1e-300, 1e200, 1e-200] {
            let e = Similarity::for_boundary(&square(0.0, size)).unwrap_err();
            assert!(matches!(e, Error::Range { .. }), "{size}: {e}");
            assert!(e.to_string().contains("half-width"), "{e}");
        }
    }

    #[test]
    fn non_finite_or_empty_boxes_are_left_to_the_validator() {
        assert!(Similarity::for_boundary(&square(0.0, 0.0)).unwrap().is_identity());
        assert!(Similarity::for_box([0.0, f64::NAN], [1.0, 1.0], "x").unwrap().is_identity());
    }
}
