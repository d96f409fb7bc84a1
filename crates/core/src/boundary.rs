//! The boundary of a four-sided domain: four sides, each a spline curve, an ordered
//! point cloud or an analytic curve (paper §5), in the orientation of `formats.md`:
//! south `eta = 0` and north `eta = 1` run with increasing `xi`, west `xi = 0` and east
//! `xi = 1` with increasing `eta`.

use std::sync::Arc;

use crate::curve::{Curve, Point};
use crate::surface::Side;

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
