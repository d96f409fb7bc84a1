//! Ring (O-type) domains (paper §11.1): two closed contours, the inner at `xi = 0` and
//! the outer at `xi = 1`, fitted on one periodic knot vector in `eta`, and the nested
//! hierarchy of bases `Ξ_k × H_k` (`H_k` periodic) the solver walks with periodic
//! `eta` ([`crate::discrete::topology::Topology::ring`]).
//!
//! **Parameterization.** Both contours are parameterized by arc length, `eta = s / L`
//! (eq. 38-39 for parametric contours, cord length eq. 36-37 for point clouds), so that
//! grid lines `eta = const` join points at equal fractions of the two perimeters.
//! **Seam (`eta = 0`).** The inner contour keeps its own start (`eta = 0` at its first
//! point or parameter); the outer contour's `eta = 0` is where the ray from the inner
//! contour's centroid through the inner start first crosses it (for concentric
//! circles starting at angle 0: both at angle 0). The outer arc-length fraction is
//! shifted by that crossing's fraction `s_0`: `eta_outer = (s - s_0) mod 1`.
//! **Narrow gaps.** Where the contours come close, facing points are matched at the same
//! `eta` by a monotone periodic reparameterization of the outer contour (§7.2 on closed
//! curves, the seam kept): `boundary::ring_reparam`.
//!
//! **Fit**, **normalisation** and the **hierarchy** of bases: [`crate::boundary::ring_fit`]
//! (adaptive and dyadic in `eta`, in unit coordinates).
use super::normalise::Similarity;
use super::{Analytic, SideCurve};
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};

/// A closed contour as given by the user.
#[derive(Debug, Clone)]
pub enum ClosedContour {
    /// A closed B-spline or NURBS curve: periodic, or clamped with equal ends.
    Spline(Curve),
    /// An ordered closed point cloud (the last point does not repeat the first).
    Points(Vec<Point>),
    /// A closed analytic curve `t in [0, 1] -> (x, y)`, `f(0) = f(1)` (library only).
    Analytic(Analytic),
}

/// A doubly connected domain between two closed counter-clockwise contours.
#[derive(Debug, Clone)]
pub struct Ring {
    /// Name of the geometry.
    pub name: String,
    /// The inner contour (`xi = 0`).
    pub inner: ClosedContour,
    /// The outer contour (`xi = 1`).
    pub outer: ClosedContour,
}

/// Samples of a contour at increasing arc-length fractions `s in [0, 1)`.
#[derive(Debug, Clone)]
pub(super) struct Samples {
    pub(super) s: Vec<f64>,
    pub(super) x: Vec<Point>,
}

/// Arc-length samples of a parametric contour (a B-spline, NURBS or analytic curve).
pub(crate) const DENSE: usize = 1 << 15;

pub(super) fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

impl ClosedContour {
    /// Evaluate a parametric contour at `t in [0, 1]`.
    fn eval(&self, t: f64) -> Point {
        match self {
            ClosedContour::Spline(c) => {
                let (a, b) = c.domain();
                c.eval(a + (b - a) * t)
            }
            ClosedContour::Analytic(f) => f.eval(t),
            ClosedContour::Points(p) => p[((t * p.len() as f64) as usize).min(p.len() - 1)],
        }
    }

    /// A dense closed polygon (last point not repeated) and its parameters.
    pub(super) fn polygon(&self) -> Vec<Point> {
        self.polygon_with(DENSE)
    }

    /// A closed polygon of at least `m` points of a parametric contour (64 per element
    /// of a spline), the points of a cloud.
    pub fn polygon_with(&self, m: usize) -> Vec<Point> {
        match self {
            ClosedContour::Points(p) => p.clone(),
            ClosedContour::Spline(c) => {
                let m = (64 * c.knots.num_elements()).max(m);
                (0..m).map(|k| self.eval(k as f64 / m as f64)).collect()
            }
            ClosedContour::Analytic(_) => (0..m).map(|k| self.eval(k as f64 / m as f64)).collect(),
        }
    }

    /// Check closedness, size and finiteness; `what` names the contour, `sim` maps the
    /// coordinates it is given in (normalised, [`Similarity`]) to the input's for the
    /// messages.
    pub(super) fn validate(&self, what: &str, diameter: f64, sim: &Similarity) -> Result<()> {
        let (a, b) = match self {
            ClosedContour::Points(p) => {
                if p.len() < 4 {
                    return Err(Error::TooFewPoints { side: what.into(), found: p.len(), needed: 4 });
                }
                if let Some(i) = p.iter().position(|q| !q[0].is_finite() || !q[1].is_finite()) {
                    return Err(Error::NonFinite { context: what.into(), what: format!("point {i}") });
                }
                return Ok(());
            }
            _ => (self.eval(0.0), self.eval(1.0)),
        };
        let gap = dist(a, b);
        if gap.is_nan() || gap > 1e-9 * diameter {
            let (a, b) = (sim.to_physical(a), sim.to_physical(b));
            return Err(Error::Invalid(format!(
                "the {what} contour is not closed: its ends ({}, {}) and ({}, {}) are {:.3e} apart (tolerance {:.3e})",
                a[0],
                a[1],
                b[0],
                b[1],
                sim.length(gap),
                sim.length(1e-9 * diameter)
            )));
        }
        Ok(())
    }

    /// Samples at arc-length fractions: the points themselves (cord length) for a point
    /// cloud, [`DENSE`] points at uniform fractions for a parametric contour.
    pub(super) fn arc_length_samples(&self) -> Samples {
        let poly = self.polygon();
        let n = poly.len();
        let mut cum = vec![0.0; n + 1];
        for k in 0..n {
            cum[k + 1] = cum[k] + dist(poly[k], poly[(k + 1) % n]);
        }
        let total = cum[n];
        if let ClosedContour::Points(p) = self {
            return Samples { s: cum[..n].iter().map(|c| c / total).collect(), x: p.clone() };
        }
        // invert the arc length of the dense polygon, then evaluate the exact curve
        let mut s = Vec::with_capacity(DENSE);
        let mut x = Vec::with_capacity(DENSE);
        let mut k = 0;
        for m in 0..DENSE {
            let target = total * m as f64 / DENSE as f64;
            while k + 1 < n && cum[k + 1] <= target {
                k += 1;
            }
            let frac = if cum[k + 1] > cum[k] { (target - cum[k]) / (cum[k + 1] - cum[k]) } else { 0.0 };
            s.push(m as f64 / DENSE as f64);
            x.push(self.eval((k as f64 + frac) / n as f64));
        }
        Samples { s, x }
    }

    /// The contour as a side of the cut-open boundary used for reports: a closed polygon
    /// for a point cloud (first point repeated at the end), the curve itself otherwise.
    pub(super) fn as_side(&self) -> SideCurve {
        match self {
            ClosedContour::Points(p) => {
                let mut q = p.clone();
                q.push(p[0]);
                SideCurve::Points(q)
            }
            ClosedContour::Spline(c) => SideCurve::Spline(c.clone()),
            ClosedContour::Analytic(f) => SideCurve::Analytic(f.clone()),
        }
    }
}

/// Signed area of a closed polygon (positive when counter-clockwise).
pub fn signed_area(poly: &[Point]) -> f64 {
    let n = poly.len();
    0.5 * (0..n).map(|k| poly[k][0] * poly[(k + 1) % n][1] - poly[(k + 1) % n][0] * poly[k][1]).sum::<f64>()
}

/// Whether `p` lies inside the closed polygon (winding number, non-zero rule).
pub(super) fn inside(poly: &[Point], p: Point) -> bool {
    let n = poly.len();
    let mut wind = 0i32;
    for k in 0..n {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        let cross = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
        if a[1] <= p[1] && b[1] > p[1] && cross > 0.0 {
            wind += 1;
        } else if a[1] > p[1] && b[1] <= p[1] && cross < 0.0 {
            wind -= 1;
        }
    }
    wind != 0
}

/// The parameter `u` of the crossing of the closed curve `c` with the ray `origin + t dir`
/// (`t > 0`) nearest to `near` (periodically): `g(u) = cross(dir, c(u) - origin) = 0`,
/// by Newton's method from `near` when it lands on the ray within one mean element of
/// `near`, else bracketed on `8` samples per element and refined by bisection to
/// rounding. `None` when the ray misses the curve. Used to keep a seam on a ray while the
/// curve turns (a sliding grid).
pub(crate) fn ray_parameter(c: &Curve, origin: Point, dir: Point, near: f64) -> Option<f64> {
    let (a, b) = c.domain();
    let l = b - a;
    let wrap = |u: f64| a + (u - a).rem_euclid(l);
    let mut u = near;
    for _ in 0..12 {
        let d = c.derivs(wrap(u), 1);
        let w = [d.x[0] - origin[0], d.x[1] - origin[1]];
        let (g, dg) = (dir[0] * w[1] - dir[1] * w[0], dir[0] * d.d1[1] - dir[1] * d.d1[0]);
        let du = g / dg;
        if !du.is_finite() {
            break;
        }
        u -= du;
        if du.abs() <= 1e-15 * l {
            let p = c.eval(wrap(u));
            let along = dir[0] * (p[0] - origin[0]) + dir[1] * (p[1] - origin[1]);
            if along > 0.0 && (u - near).abs() <= l / c.knots.num_elements().max(1) as f64 {
                return Some(wrap(u));
            }
            break;
        }
    }
    let g = |u: f64| {
        let p = c.eval(u);
        let w = [p[0] - origin[0], p[1] - origin[1]];
        (dir[0] * w[1] - dir[1] * w[0], dir[0] * w[0] + dir[1] * w[1])
    };
    let m = 8 * c.knots.num_elements().max(8);
    let us: Vec<f64> = (0..=m).map(|k| a + l * k as f64 / m as f64).collect();
    let gs: Vec<(f64, f64)> = us.iter().map(|&u| g(u)).collect();
    let near = a + (near - a).rem_euclid(l);
    let gap = |u: f64| {
        let d = (u - near).rem_euclid(l);
        d.min(l - d)
    };
    let mut best: Option<f64> = None;
    for k in 0..m {
        let ((g0, d0), (g1, d1)) = (gs[k], gs[k + 1]);
        if !(g0 <= 0.0 && g1 > 0.0 || g0 >= 0.0 && g1 < 0.0) || d0 + d1 <= 0.0 {
            continue;
        }
        let (mut lo, mut hi) = (us[k], us[k + 1]);
        let s0 = g0.signum();
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if g(mid).0.signum() == s0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let u = if g0 == 0.0 { us[k] } else { 0.5 * (lo + hi) };
        if g(u).1 > 0.0 && best.is_none_or(|v| gap(u) < gap(v)) {
            best = Some(u);
        }
    }
    best
}

impl ClosedContour {
    /// The contour turned rigidly by `angle` (radians, counter-clockwise) about `center`.
    pub fn rotated(&self, center: Point, angle: f64) -> ClosedContour {
        let (c, s) = (angle.cos(), angle.sin());
        self.mapped(move |p: Point| {
            let (x, y) = (p[0] - center[0], p[1] - center[1]);
            [center[0] + c * x - s * y, center[1] + s * x + c * y]
        })
    }

    /// The contour moved by the affine map `f` of the plane (control points, points or
    /// values mapped; the parameterization unchanged).
    pub fn mapped(&self, f: impl Fn(Point) -> Point + Send + Sync + Clone + 'static) -> ClosedContour {
        match self {
            ClosedContour::Spline(cv) => ClosedContour::Spline(Curve {
                control_points: cv.control_points.iter().map(|&p| f(p)).collect(),
                ..cv.clone()
            }),
            ClosedContour::Points(p) => ClosedContour::Points(p.iter().map(|&q| f(q)).collect()),
            ClosedContour::Analytic(a) => {
                let a = a.clone();
                ClosedContour::Analytic(Analytic::new(move |t| f(a.eval(t))))
            }
        }
    }

    /// The largest distance between this contour and `other` at their dense polygons'
    /// vertices (point clouds: their points), relative to the diameter of `other`'s
    /// bounding box; `None` when the two are sampled differently (different kinds or
    /// numbers of points).
    pub fn deviation_from(&self, other: &ClosedContour) -> Option<f64> {
        let (a, b) = (self.polygon(), other.polygon());
        if a.len() != b.len() || std::mem::discriminant(self) != std::mem::discriminant(other) {
            return None;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &b {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        let diameter = (hi[0] - lo[0]).hypot(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
        Some(a.iter().zip(&b).map(|(p, q)| dist(*p, *q)).fold(0.0, f64::max) / diameter)
    }

    /// The mean of the contour's arc-length samples (its centroid, for point clouds the
    /// mean of the points).
    pub fn centroid(&self) -> Point {
        let x = self.arc_length_samples().x;
        let m = x.len() as f64;
        [x.iter().map(|p| p[0]).sum::<f64>() / m, x.iter().map(|p| p[1]).sum::<f64>() / m]
    }
}
