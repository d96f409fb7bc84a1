//! Fritsch-Carlson monotone cubic interpolation: the reparameterization maps of sampled
//! sides (constrained cord length, paper §7.2).

use crate::error::{Error, Result};

/// Monotone piecewise cubic Hermite interpolant (Fritsch and Carlson 1980) of data
/// `(x_k, y_k)` with strictly increasing `x` and non-decreasing `y`. Node slopes are the
/// weighted harmonic means of the adjacent secants (zero where a secant is zero) and are
/// then scaled so that `α^2 + β^2 <= 9` on every interval, the Fritsch-Carlson sufficient
/// condition for monotonicity; strictly increasing data give a strictly increasing
/// interpolant.
#[derive(Debug, Clone, PartialEq)]
pub struct MonotoneCubic {
    x: Vec<f64>,
    y: Vec<f64>,
    m: Vec<f64>,
}

impl MonotoneCubic {
    /// The interpolant; errors unless `x` strictly and `y` weakly increase (>= 2 points).
    pub fn new(x: Vec<f64>, y: Vec<f64>) -> Result<Self> {
        let n = x.len();
        if n < 2 || y.len() != n {
            return Err(Error::Invalid(format!(
                "monotone cubic needs >= 2 points and equal lengths, got {n} and {}",
                y.len()
            )));
        }
        if x.iter().chain(&y).any(|v| !v.is_finite()) {
            return Err(Error::Invalid("monotone cubic: non-finite data".into()));
        }
        if x.windows(2).any(|w| w[1] <= w[0]) || y.windows(2).any(|w| w[1] < w[0]) {
            return Err(Error::Invalid("monotone cubic needs strictly increasing x and non-decreasing y".into()));
        }
        let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
        let d: Vec<f64> = (0..n - 1).map(|k| (y[k + 1] - y[k]) / h[k]).collect();
        let mut m = vec![0.0; n];
        if n == 2 {
            m[0] = d[0];
            m[1] = d[0];
        } else {
            for k in 1..n - 1 {
                if d[k - 1] > 0.0 && d[k] > 0.0 {
                    let (w1, w2) = (2.0 * h[k] + h[k - 1], h[k] + 2.0 * h[k - 1]);
                    m[k] = (w1 + w2) / (w1 / d[k - 1] + w2 / d[k]);
                }
            }
            // one-sided three-point ends, kept within [0, 3 d]
            let end = |h0: f64, h1: f64, d0: f64, d1: f64| {
                let v = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
                if v <= 0.0 || d0 <= 0.0 {
                    if d0 > 0.0 {
                        0.5 * d0
                    } else {
                        0.0
                    }
                } else {
                    v.min(3.0 * d0)
                }
            };
            m[0] = end(h[0], h[1], d[0], d[1]);
            m[n - 1] = end(h[n - 2], h[n - 3], d[n - 2], d[n - 3]);
        }
        // Fritsch-Carlson step 5: restrict (α, β) to the disc of radius 3.
        for k in 0..n - 1 {
            if d[k] == 0.0 {
                m[k] = 0.0;
                m[k + 1] = 0.0;
                continue;
            }
            let (a, b) = (m[k] / d[k], m[k + 1] / d[k]);
            let s = a * a + b * b;
            if s > 9.0 {
                let t = 3.0 / s.sqrt();
                m[k] = t * a * d[k];
                m[k + 1] = t * b * d[k];
            }
        }
        Ok(Self { x, y, m })
    }

    /// The nodes `x_k` (the breaks of the interpolant).
    pub fn nodes(&self) -> &[f64] {
        &self.x
    }

    /// The data values `y_k`.
    pub fn values(&self) -> &[f64] {
        &self.y
    }

    fn interval(&self, t: f64) -> usize {
        self.x.partition_point(|&v| v <= t).clamp(1, self.x.len() - 1) - 1
    }

    /// Value at `t` (clamped to `[x_0, x_{n-1}]`).
    pub fn eval(&self, t: f64) -> f64 {
        self.eval_d(t).0
    }

    /// Value and first derivative at `t` (clamped).
    pub(crate) fn eval_d(&self, t: f64) -> (f64, f64) {
        let n = self.x.len();
        let t = t.clamp(self.x[0], self.x[n - 1]);
        let k = self.interval(t);
        let h = self.x[k + 1] - self.x[k];
        let s = (t - self.x[k]) / h;
        let (y0, y1, m0, m1) = (self.y[k], self.y[k + 1], self.m[k] * h, self.m[k + 1] * h);
        let (s2, s3) = (s * s, s * s * s);
        let v =
            (2.0 * s3 - 3.0 * s2 + 1.0) * y0 + (s3 - 2.0 * s2 + s) * m0 + (-2.0 * s3 + 3.0 * s2) * y1 + (s3 - s2) * m1;
        let dv = ((6.0 * s2 - 6.0 * s) * y0
            + (3.0 * s2 - 4.0 * s + 1.0) * m0
            + (-6.0 * s2 + 6.0 * s) * y1
            + (3.0 * s2 - 2.0 * s) * m1)
            / h;
        (v, dv)
    }

    /// The `t` with `eval(t) = y` (bisection; the interpolant is monotone).
    pub fn inverse(&self, y: f64) -> f64 {
        let n = self.x.len();
        let k = self.y.partition_point(|&v| v < y).clamp(1, n - 1) - 1;
        let (mut lo, mut hi) = (self.x[k], self.x[k + 1]);
        if y <= self.y[k] {
            return lo;
        }
        if y >= self.y[k + 1] {
            return hi;
        }
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.eval(mid) < y {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}
