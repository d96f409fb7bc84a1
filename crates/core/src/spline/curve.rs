//! B-spline and NURBS curves in the plane: a basis (knot vector) plus control points.

use crate::error::Result;
use crate::spline::basis::BasisDerivs;
use crate::spline::knots::KnotVector;
use crate::spline::refine::{elevation, prolongation};
use crate::spline::tensor::{apply_homogeneous, TensorSpline};
pub(crate) use crate::spline::tensor::{check_points, check_weights};

/// A point or vector in the plane.
pub type Point = [f64; 2];

/// A planar B-spline curve `C(u) = sum_i c_i N_i(u)`, or NURBS curve
/// `C(u) = sum_i w_i c_i N_i(u) / sum_i w_i N_i(u)` when weights are given.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// The basis.
    pub knots: KnotVector,
    /// One control point per basis function.
    pub control_points: Vec<Point>,
    /// Positive weights (NURBS) or `None` (polynomial).
    pub weights: Option<Vec<f64>>,
}

/// Value and first two derivatives of a curve at a parameter.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CurveDerivs {
    /// `C(u)`.
    pub x: Point,
    /// `C'(u)`.
    pub d1: Point,
    /// `C''(u)`.
    pub d2: Point,
}

impl Curve {
    /// Validate lengths, finiteness and weights; for a periodic knot vector, that the
    /// last `p` control points repeat the first `p` (`spline::periodic`).
    pub fn new(knots: KnotVector, control_points: Vec<Point>, weights: Option<Vec<f64>>) -> Result<Self> {
        let TensorSpline { knots: [knots], control_points, weights } =
            TensorSpline::checked([knots], control_points, weights)?;
        Ok(Self { knots, control_points, weights })
    }

    /// A polynomial curve (no validation beyond lengths; for internal use).
    pub fn polynomial(knots: KnotVector, control_points: Vec<Point>) -> Self {
        debug_assert_eq!(knots.num_basis(), control_points.len());
        Self { knots, control_points, weights: None }
    }

    /// Degree.
    pub fn degree(&self) -> usize {
        self.knots.degree()
    }

    /// Whether the curve is rational.
    pub fn is_rational(&self) -> bool {
        self.weights.is_some()
    }

    /// Parameter domain.
    pub fn domain(&self) -> (f64, f64) {
        self.knots.domain()
    }

    /// The same curve with its parameter domain mapped affinely onto `[0, 1]`.
    pub fn normalized(&self) -> Self {
        Self { knots: self.knots.normalized(), ..self.clone() }
    }

    /// The same point set traversed backwards: `C_rev(u) = C(a + b - u)`.
    pub fn reversed(&self) -> Self {
        let (a, b) = self.domain();
        let mut k: Vec<f64> = self.knots.knots().iter().rev().map(|&t| a + b - t).collect();
        for t in &mut k {
            if (*t - a).abs() < 1e-15 * (b - a) {
                *t = a;
            }
        }
        let knots =
            KnotVector::with_periodic(self.degree(), k, self.knots.is_periodic()).expect("reversal keeps validity");
        let mut cp = self.control_points.clone();
        cp.reverse();
        let weights = self.weights.clone().map(|mut w| {
            w.reverse();
            w
        });
        Self { knots, control_points: cp, weights }
    }

    /// `C(u)`.
    pub fn eval(&self, u: f64) -> Point {
        self.derivs(u, 0).x
    }

    /// Value and derivatives up to order `nd <= 2` at `u`.
    pub fn derivs(&self, u: f64, nd: usize) -> CurveDerivs {
        let b = BasisDerivs::at(&self.knots, u, nd);
        self.derivs_with(&b, nd)
    }

    /// Value and derivatives from precomputed basis values.
    pub(crate) fn derivs_with(&self, b: &BasisDerivs, nd: usize) -> CurveDerivs {
        let first = b.first();
        let p = b.degree;
        let mut a = [[0.0f64; 3]; 3]; // a[k] = k-th derivative of (w x, w y, w)
        for k in 0..=nd {
            for j in 0..=p {
                let i = first + j;
                let w = self.weights.as_ref().map_or(1.0, |w| w[i]);
                let n = b.d[k][j] * w;
                a[k][0] += n * self.control_points[i][0];
                a[k][1] += n * self.control_points[i][1];
                a[k][2] += n;
            }
        }
        if self.weights.is_none() {
            return CurveDerivs { x: [a[0][0], a[0][1]], d1: [a[1][0], a[1][1]], d2: [a[2][0], a[2][1]] };
        }
        let w = a[0][2];
        let x = [a[0][0] / w, a[0][1] / w];
        let d1 = [(a[1][0] - a[1][2] * x[0]) / w, (a[1][1] - a[1][2] * x[1]) / w];
        let d2 = [
            (a[2][0] - 2.0 * a[1][2] * d1[0] - a[2][2] * x[0]) / w,
            (a[2][1] - 2.0 * a[1][2] * d1[1] - a[2][2] * x[1]) / w,
        ];
        CurveDerivs { x, d1, d2 }
    }

    /// First and last points `C(a)`, `C(b)`.
    pub fn endpoints(&self) -> (Point, Point) {
        let (a, b) = self.domain();
        (self.eval(a), self.eval(b))
    }

    /// `m + 1` points at uniformly spaced parameters.
    pub fn sample(&self, m: usize) -> Vec<Point> {
        let (a, b) = self.domain();
        (0..=m).map(|k| self.eval(a + (b - a) * k as f64 / m as f64)).collect()
    }
}

impl Curve {
    /// The same curve on the finer knot vector `fine` (which must contain this one's).
    pub fn refined(&self, fine: &KnotVector) -> Result<Curve> {
        let p = prolongation(&self.knots, fine)?;
        let (cp, w) = apply_homogeneous(&p, &self.control_points, self.weights.as_deref());
        Ok(Curve { knots: fine.clone(), control_points: cp, weights: w })
    }

    /// The same curve with its degree raised by one.
    pub(crate) fn elevated(&self) -> Result<Curve> {
        let (kv, e) = elevation(&self.knots)?;
        let (cp, w) = apply_homogeneous(&e, &self.control_points, self.weights.as_deref());
        Ok(Curve { knots: kv, control_points: cp, weights: w })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    #[test]
    fn nurbs_quarter_circle_is_exact() {
        let kv = KnotVector::new(2, vec![0., 0., 0., 1., 1., 1.]).unwrap();
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let c = Curve::new(kv, vec![[1., 0.], [1., 1.], [0., 1.]], Some(vec![1., s, 1.])).unwrap();
        for k in 0..=20 {
            let u = k as f64 / 20.0;
            let d = c.derivs(u, 2);
            assert!((d.x[0].hypot(d.x[1]) - 1.0).abs() < 1e-14);
            // tangent is orthogonal to the radius
            assert!((d.x[0] * d.d1[0] + d.x[1] * d.d1[1]).abs() < 1e-13);
            // finite-difference check of d1 and d2
            let h = 1e-5;
            if u > h && u < 1.0 - h {
                let (lo, hi) = (c.derivs(u - h, 1), c.derivs(u + h, 1));
                for i in 0..2 {
                    assert!(((hi.x[i] - lo.x[i]) / (2.0 * h) - d.d1[i]).abs() < 1e-8);
                    assert!(((hi.d1[i] - lo.d1[i]) / (2.0 * h) - d.d2[i]).abs() < 1e-7);
                }
            }
        }
        let r = c.reversed();
        assert!((r.eval(0.3)[0] - c.eval(0.7)[0]).abs() < 1e-14);
    }

    #[test]
    fn rejects_bad_weights_and_lengths() {
        let kv = KnotVector::new(1, vec![0., 0., 1., 1.]).unwrap();
        assert!(matches!(Curve::new(kv.clone(), vec![[0., 0.]], None), Err(Error::Length { .. })));
        assert!(matches!(
            Curve::new(kv.clone(), vec![[0., 0.], [1., 0.]], Some(vec![1., 0.])),
            Err(Error::Weight { .. })
        ));
        assert!(matches!(Curve::new(kv, vec![[0., f64::INFINITY], [1., 0.]], None), Err(Error::NonFinite { .. })));
    }
}
