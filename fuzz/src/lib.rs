//! Shared pieces of the fuzz targets: the check applied to every input's [`Trace`] and
//! the structured inputs (numbers, points, sides) of the targets that build boundaries
//! directly instead of parsing text.

use arbitrary::Arbitrary;
use winslow::boundary::{Analytic, SideCurve};
use winslow::spline::curve::{Curve, Point};
use winslow::spline::knots::KnotVector;
use winslow::testutil::exercise::{self, Reader, Trace};

/// Fail (panic, which libFuzzer reports as a crash) when an accepted input broke a
/// property or an error says nothing; a panic inside the library fails by itself.
pub fn check(trace: &Trace) {
    assert!(trace.violations.is_empty(), "violations: {:#?}", trace.violations);
}

/// Give the bytes to `reader` as text (invalid UTF-8 replaced, as a user's editor would).
pub fn fuzz_text(reader: Reader, data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    check(&exercise::exercise_text(reader, &text));
}

/// A coordinate: mostly small values on a grid of 1/16 (so that points coincide, sides
/// touch and cross), sometimes any `f64` or an extreme one.
#[derive(Debug, Clone, Copy, Arbitrary)]
pub enum Num {
    /// `k / 16`.
    Grid(i8),
    /// Any bit pattern.
    Raw(f64),
    /// One of [`SPECIAL`].
    Special(u8),
}

/// Extreme values a coordinate may take.
pub const SPECIAL: [f64; 14] = [
    0.0,
    -0.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::MAX,
    f64::MIN,
    f64::MIN_POSITIVE,
    5e-324,
    1e308,
    1e-308,
    1e9,
    1e-9,
    1.0 + f64::EPSILON,
];

impl Num {
    /// The value.
    pub fn value(self) -> f64 {
        match self {
            Num::Grid(k) => f64::from(k) / 16.0,
            Num::Raw(x) => x,
            Num::Special(k) => SPECIAL[usize::from(k) % SPECIAL.len()],
        }
    }
}

/// A point.
#[derive(Debug, Clone, Copy, Arbitrary)]
pub struct P(pub Num, pub Num);

impl P {
    /// `[x, y]`.
    pub fn point(self) -> Point {
        [self.0.value(), self.1.value()]
    }
}

/// Points of a list.
pub fn points(ps: &[P]) -> Vec<Point> {
    ps.iter().map(|p| p.point()).collect()
}

/// A side built directly (no reader): a point cloud, a spline curve whose control points
/// and weights are taken as given (lengths unchecked: the validator must check them),
/// or an analytic polyline.
#[derive(Debug, Clone, Arbitrary)]
pub enum SideIn {
    /// A point cloud.
    Points(Vec<P>),
    /// A spline: degree, knots, control points, weights.
    Spline { degree: u8, knots: Vec<Num>, control_points: Vec<P>, weights: Option<Vec<Num>> },
    /// A B-spline of the given degree on an open uniform knot vector with these
    /// control points (lengths consistent: reaches the geometric checks).
    Uniform { degree: u8, control_points: Vec<P> },
    /// The polyline through the points, parameterized uniformly on `[0, 1]`.
    Analytic(Vec<P>),
}

impl SideIn {
    /// The side, or `None` when its knot vector is refused (that error is the readers'
    /// business, fuzzed through the text targets).
    pub fn side(&self) -> Option<SideCurve> {
        Some(match self {
            SideIn::Points(p) => SideCurve::Points(points(p)),
            SideIn::Spline { degree, knots, control_points, weights } => {
                let kv = KnotVector::new(usize::from(*degree % 8), knots.iter().map(|k| k.value()).collect()).ok()?;
                SideCurve::Spline(Curve {
                    knots: kv,
                    control_points: points(control_points),
                    weights: weights.as_ref().map(|w| w.iter().map(|x| x.value()).collect()),
                })
            }
            SideIn::Uniform { degree, control_points } => {
                let p = 1 + usize::from(*degree % 5);
                if control_points.len() <= p {
                    return None;
                }
                let kv = KnotVector::open_uniform(p, control_points.len() - p);
                SideCurve::Spline(Curve::new(kv, points(control_points), None).ok()?)
            }
            SideIn::Analytic(p) => {
                let pts = points(p);
                if pts.is_empty() {
                    return None;
                }
                SideCurve::Analytic(Analytic::new(move |t| {
                    let s = t.clamp(0.0, 1.0) * (pts.len() - 1) as f64;
                    let i = (s.floor() as usize).min(pts.len() - 1);
                    let j = (i + 1).min(pts.len() - 1);
                    let f = s - i as f64;
                    [pts[i][0] + f * (pts[j][0] - pts[i][0]), pts[i][1] + f * (pts[j][1] - pts[i][1])]
                }))
            }
        })
    }
}
