//! The boundary of a four-sided domain and everything made from it before a solve:
//! the boundary types (this module), their validation, the singular points, the
//! reparameterization (§7), the contour fit (§5) and the nested hierarchy (§5.4).
//!
//! | module | holds | paper |
//! |---|---|---|
//! | this module | [`Boundary`], [`SideCurve`], [`Analytic`], `bounding_box`, [`diameter`], [`BasisChoice`] | §5, §5.2 |
//! | [`families`] | seeded families of hard domains (the hard corpus) | |
//! | `normalise` | the similarity to unit size at the origin, and back | |
//! | [`mod@validate`] | corner gaps, orientation, self-intersections, degenerate sides | |
//! | [`corners`] | corner angles and the `det J` they force, kinks inside sides | §8.1 |
//! | [`cord_length`] | cord-length abscissae of point clouds | eq. (36)-(37) |
//! | [`reparam`] | arc-length and constrained cord-length reparameterization | §7, eq. (38)-(42) |
//! | [`fit`] | adaptive least-squares fit of one side | §5.1-§5.3, eq. (17)-(18) |
//! | `level` | one level: a tensor basis, the four sides on it, its rational weights | §5.4, §5.2 |
//! | [`hierarchy`] | the nested tensor-product bases from the four fits | §5.4 |
//! | [`kinks`] | interior `C^0` points of the sides (`C^0` knots, zero speed, polygon corners), the smoothed basis `Σ¹` | §9 |
//! | [`ring`] | ring (O-type) domains: two closed contours fitted on one periodic knot vector by arc length, and their hierarchy | §11.1 |
//! | `volume` | `VolumeBoundary`: the six faces of a hexahedral volume, their validation | §11.1 |
//! | `hexahedron` | six faces in any order and orientation identified as the sides of the parameter cube | |
//! | `input_basis` | the input's own basis, boundary kept exactly, with an artificial coarse hierarchy | §5.2, §6.3 |
//!
//! The arrows point one way: `fit` uses `reparam` (a reparameterized side is fitted as
//! `f ∘ g`), both use `cord_length`; `input_basis` uses `fit` (its coarse levels are
//! projections); `kinks` uses `fit` and `level`; `hierarchy` uses all of them.
//!
//! Sides are oriented as in `formats.md`: south `eta = 0` and north `eta = 1` run with
//! increasing `xi`, west `xi = 0` and east `xi = 1` with increasing `eta`.

pub mod cord_length;
pub mod corners;
pub mod families;
pub mod fit;
pub(crate) mod hexahedron;
pub mod hierarchy;
pub(crate) mod input_basis;
pub mod kinks;
pub(crate) mod level;
pub(crate) mod normalise;
pub mod reparam;
pub mod ring;
pub mod ring_fit;
pub(crate) mod ring_reparam;
pub mod validate;
pub(crate) mod volume;

pub use normalise::Similarity;
pub use volume::{CubeSide, VolumeBoundary};

use std::sync::Arc;

use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};
use crate::spline::surface::Side;

/// The basis a map is solved in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum BasisChoice {
    /// The input basis when the sides allow it and its map is certified, else the fitted
    /// basis ([`crate::pipeline::Pipeline`] solves again): the boundary is kept exactly
    /// wherever that gives a certified map (BASIS.md table in BENCHMARKS.md).
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(help = "The input's own basis when the sides allow it and its map is certified, else the fitted basis")
    )]
    Auto,
    /// Dyadic `C^{p-1}` bases fitted to the boundary within a tolerance (§5).
    #[cfg_attr(feature = "clap", value(help = "Dyadic bases fitted to the boundary within --fit-tol (§5)"))]
    Fitted,
    /// The basis of the input's spline sides, boundary kept exactly (§5.2).
    #[cfg_attr(
        feature = "clap",
        value(
            help = "The input's own basis, boundary kept exactly (§5.2), falling back to fitted only when the sides have no usable basis"
        )
    )]
    Input,
}

impl BasisChoice {
    /// `"auto"`, `"fitted"` or `"input"`.
    pub fn name(self) -> &'static str {
        match self {
            BasisChoice::Auto => "auto",
            BasisChoice::Fitted => "fitted",
            BasisChoice::Input => "input",
        }
    }
}

/// Which interior `C^0` points of the sides are kept exactly (`--kinks`).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum KinkMode {
    /// Spline sides: every `C^0` knot and zero-speed knot whose tangent turns more than
    /// [`SPLINE_KINK_DEGREES`]; point clouds: every corner turning at least
    /// [`CLOUD_CORNER_DEGREES`]. On the input basis every `C^0` knot in any case (the
    /// basis is `C^0` there).
    #[default]
    Auto,
    /// None: the fit rounds them (within the tolerance) and the report names them; on the
    /// input basis a side with a `C^0` knot falls back to the fitted basis.
    None,
    /// Every kink (spline or point cloud) whose tangent turns at least this many degrees
    /// (on the input basis every `C^0` knot in any case).
    Angle(f64),
}

impl KinkMode {
    /// `"auto"`, `"none"` or the angle.
    pub fn name(self) -> String {
        match self {
            KinkMode::Auto => "auto".into(),
            KinkMode::None => "none".into(),
            KinkMode::Angle(a) => format!("{a}"),
        }
    }

    /// `auto`, `none` or an angle in degrees in `(0, 180]`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(KinkMode::Auto),
            "none" => Some(KinkMode::None),
            _ => s.parse::<f64>().ok().filter(|a| *a > 0.0 && *a <= 180.0).map(KinkMode::Angle),
        }
    }

    /// Check the angle.
    pub fn validate(self) -> Result<()> {
        match self {
            KinkMode::Angle(a) if !(a > 0.0 && a <= 180.0) => {
                Err(Error::Invalid(format!("the kink angle must be in (0, 180] degrees, got {a}")))
            }
            _ => Ok(()),
        }
    }

    /// Smallest turning (degrees) of a spline kink kept; `None`: none kept.
    pub(crate) fn spline_threshold(self) -> Option<f64> {
        match self {
            KinkMode::Auto => Some(SPLINE_KINK_DEGREES),
            KinkMode::None => None,
            KinkMode::Angle(a) => Some(a),
        }
    }

    /// Smallest turning (degrees) of a point-cloud corner kept; `None`: none kept.
    pub(crate) fn cloud_threshold(self) -> Option<f64> {
        match self {
            KinkMode::Auto => Some(CLOUD_CORNER_DEGREES),
            KinkMode::None => None,
            KinkMode::Angle(a) => Some(a),
        }
    }
}

impl std::fmt::Display for KinkMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

/// A spline side's tangent turning more than this (degrees) at a knot is a kink (the
/// report names it; `--kinks auto` keeps it).
pub const SPLINE_KINK_DEGREES: f64 = 1.0;

/// A point cloud's turning of at least this (degrees), measured by `kinks::cloud_corners`, is a
/// corner (`--kinks auto` keeps it, the report names it otherwise). A sampled smooth
/// curve turns less at the scale of `CORNER_WINDOW` unless its radius of curvature is
/// below about twice the window.
pub const CLOUD_CORNER_DEGREES: f64 = 30.0;

/// An analytic side `t in [0, 1] -> (x, y)` given as a Rust closure.
#[derive(Clone)]
pub struct Analytic(pub Arc<dyn Fn(f64) -> Point + Send + Sync>);

impl Analytic {
    /// Wrap a closure.
    pub fn new(f: impl Fn(f64) -> Point + Send + Sync + 'static) -> Self {
        Self(Arc::new(f))
    }
    /// Evaluate at `t in [0, 1]`.
    pub fn eval(&self, t: f64) -> Point {
        (self.0)(t)
    }
}

impl std::fmt::Debug for Analytic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Analytic(<closure>)")
    }
}

/// One side of the boundary as given by the user.
#[derive(Debug, Clone)]
pub enum SideCurve {
    /// A B-spline or NURBS curve; its domain is mapped to `[0, 1]`.
    Spline(Curve),
    /// An ordered point cloud from one corner to the next.
    Points(Vec<Point>),
    /// An analytic curve on `[0, 1]` (library only).
    Analytic(Analytic),
}

impl SideCurve {
    /// Start and end point.
    pub fn endpoints(&self) -> (Point, Point) {
        match self {
            SideCurve::Spline(c) => c.endpoints(),
            SideCurve::Points(p) => (p[0], p[p.len() - 1]),
            SideCurve::Analytic(f) => (f.eval(0.0), f.eval(1.0)),
        }
    }

    /// The same side traversed backwards.
    pub fn reversed(&self) -> SideCurve {
        match self {
            SideCurve::Spline(c) => SideCurve::Spline(c.reversed()),
            SideCurve::Points(p) => SideCurve::Points(p.iter().rev().copied().collect()),
            SideCurve::Analytic(f) => {
                let f = f.clone();
                SideCurve::Analytic(Analytic::new(move |t| f.eval(1.0 - t)))
            }
        }
    }

    /// Short description of the kind of side ("B-spline p=3, 10 control points", ...).
    pub fn describe(&self) -> String {
        match self {
            SideCurve::Spline(c) => format!(
                "{} p={}, {} control points, {} elements",
                if c.is_rational() { "NURBS" } else { "B-spline" },
                c.degree(),
                c.control_points.len(),
                c.knots.num_elements()
            ),
            SideCurve::Points(p) => format!("point cloud, {} points", p.len()),
            SideCurve::Analytic(_) => "analytic curve".to_string(),
        }
    }
}

/// A four-sided boundary: `sides[Side::South as usize]`, etc.
#[derive(Debug, Clone)]
pub struct Boundary {
    /// Name of the geometry.
    pub name: String,
    /// South, east, north, west.
    pub sides: [SideCurve; 4],
}

impl Boundary {
    /// The side `s`.
    pub fn side(&self, s: Side) -> &SideCurve {
        &self.sides[s as usize]
    }

    /// Swap `xi` and `eta`: new south = old west, new east = old north, new north = old
    /// east, new west = old south. Reverses the orientation of the contour.
    pub fn transposed(&self) -> Boundary {
        let [s, e, n, w] = self.sides.clone();
        Boundary { name: self.name.clone(), sides: [w, n, e, s] }
    }
}

/// Lower-left and upper-right corner of a bounding box of the boundary: point clouds
/// exactly, spline sides sampled at 16 points per input element, analytic sides at 1025
/// points.
pub(crate) fn bounding_box(boundary: &Boundary) -> (Point, Point) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let mut add = |p: Point| {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    };
    for side in &boundary.sides {
        match side {
            SideCurve::Points(pts) => pts.iter().for_each(|&p| add(p)),
            SideCurve::Spline(c) => {
                for (_, a, b) in c.knots.elements() {
                    for k in 0..=16 {
                        add(c.eval(a + (b - a) * k as f64 / 16.0));
                    }
                }
            }
            SideCurve::Analytic(f) => (0..=1024).for_each(|k| add(f.eval(k as f64 / 1024.0))),
        }
    }
    (lo, hi)
}

/// Diameter of `bounding_box`.
pub fn diameter(boundary: &Boundary) -> f64 {
    let (lo, hi) = bounding_box(boundary);
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}
