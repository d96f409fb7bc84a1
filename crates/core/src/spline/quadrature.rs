//! Gauss–Legendre quadrature of any order.

/// An `n`-point Gauss–Legendre rule on `[-1, 1]`: exact for polynomials of degree `2n - 1`.
#[derive(Debug, Clone)]
pub(crate) struct GaussLegendre {
    /// Abscissae in `(-1, 1)`, increasing.
    pub points: Vec<f64>,
    /// Positive weights summing to 2.
    pub weights: Vec<f64>,
}

impl GaussLegendre {
    /// The rule with `n >= 1` points. Nodes are the roots of the Legendre polynomial
    /// `P_n`, found by Newton's method from Chebyshev-like starting values; weights are
    /// `w_i = 2 / ((1 - x_i^2) P_n'(x_i)^2)`.
    pub fn new(n: usize) -> Self {
        assert!(n >= 1, "a Gauss rule needs at least one point");
        let mut points = vec![0.0; n];
        let mut weights = vec![0.0; n];
        let m = n.div_ceil(2);
        for i in 0..m {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            let mut last = f64::INFINITY;
            for _ in 0..100 {
                let (p, d) = legendre(n, x);
                dp = d;
                let dx = p / d;
                x -= dx;
                // converged: below the tolerance, or at the rounding floor, where the
                // quadratically shrinking steps stop shrinking
                if dx.abs() < 1e-16 || dx.abs() >= last {
                    break;
                }
                last = dx.abs();
            }
            let (_, d) = legendre(n, x);
            dp = if d != 0.0 { d } else { dp };
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            points[i] = -x;
            points[n - 1 - i] = x;
            weights[i] = w;
            weights[n - 1 - i] = w;
        }
        if n % 2 == 1 {
            points[n / 2] = 0.0;
        }
        Self { points, weights }
    }

    /// Points and weights mapped affinely to `[a, b]`.
    pub fn on(&self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let h = 0.5 * (b - a);
        let c = 0.5 * (a + b);
        self.points.iter().zip(&self.weights).map(move |(&x, &w)| (c + h * x, h * w))
    }
}

/// Gauss-Lobatto quadrature on `[-1, 1]`: the end points are nodes. `n >= 2` points
/// integrate polynomials of degree up to `2n - 3` exactly (two less than Gauss-Legendre's
/// `2n - 1`) and, unlike Gauss-Legendre, sample the integrand on the element's edges: on a
/// `C^0` knot line each element sees its own one-sided limit there.
#[derive(Debug, Clone)]
pub struct GaussLobatto {
    /// Abscissae in `[-1, 1]`, increasing, `-1` and `1` included.
    pub points: Vec<f64>,
    /// Positive weights summing to 2.
    pub weights: Vec<f64>,
}

impl GaussLobatto {
    /// The rule with `n >= 2` points (fewer are taken as 2): the interior nodes are the
    /// roots of `P_{n-1}'`, found by Newton's method from the Chebyshev-Lobatto points
    /// `cos(π i / (n - 1))` with `(1 - x²) P'' = 2x P' - m(m + 1) P` (`m = n - 1`); the
    /// weights are `w_i = 2 / (n (n - 1) P_{n-1}(x_i)²)`.
    pub fn new(n: usize) -> Self {
        let n = n.max(2);
        let m = n - 1;
        let mf = m as f64;
        let mut points = vec![0.0; n];
        for (i, x) in points.iter_mut().enumerate() {
            let mut t = -(std::f64::consts::PI * i as f64 / mf).cos();
            if i > 0 && i < m {
                for _ in 0..100 {
                    let (p, d) = legendre(m, t);
                    let dd = (2.0 * t * d - mf * (mf + 1.0) * p) / (1.0 - t * t);
                    let dx = d / dd;
                    t -= dx;
                    if dx.abs() < 1e-16 {
                        break;
                    }
                }
            }
            *x = t;
        }
        points[0] = -1.0;
        points[m] = 1.0;
        if n % 2 == 1 {
            points[n / 2] = 0.0;
        }
        let weights = points
            .iter()
            .map(|&x| {
                let (p, _) = legendre(m, x);
                2.0 / (n as f64 * mf * p * p)
            })
            .collect();
        Self { points, weights }
    }

    /// Points and weights mapped affinely to `[a, b]`.
    pub fn on(&self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let h = 0.5 * (b - a);
        let c = 0.5 * (a + b);
        self.points.iter().zip(&self.weights).map(move |(&x, &w)| (c + h * x, h * w))
    }
}

/// `(P_n(x), P_n'(x))` by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nodes are the roots of `P_n` to rounding: one more Newton step moves none by
    /// more than a few units in the last place.
    #[test]
    fn nodes_are_legendre_roots_to_rounding() {
        for n in 1..=40 {
            for &x in &GaussLegendre::new(n).points {
                let (p, d) = legendre(n, x);
                assert!((p / d).abs() <= 4.0 * f64::EPSILON * x.abs().max(1e-3), "n={n} x={x} step {}", p / d);
            }
        }
    }

    /// Gauss-Lobatto with `n` points: the end points are nodes, the interior nodes are
    /// roots of `P_{n-1}'`, and the rule integrates `x^k` on `[0.5, 1]` exactly for every
    /// `k <= 2n - 3` and not for `k = 2n - 2`.
    #[test]
    fn lobatto_is_exact_for_degree_2n_minus_3() {
        for n in 2..=16 {
            let g = GaussLobatto::new(n);
            assert_eq!((g.points[0], g.points[n - 1]), (-1.0, 1.0));
            assert!(g.points.windows(2).all(|w| w[0] < w[1]), "n={n}: {:?}", g.points);
            for &x in &g.points[1..n - 1] {
                assert!(legendre(n - 1, x).1.abs() <= 1e-12, "n={n} x={x}");
            }
            assert!((g.weights.iter().sum::<f64>() - 2.0).abs() < 1e-13);
            for k in 0..=(2 * n - 3) {
                let exact = (1.0 - 0.5f64.powi(k as i32 + 1)) / (k as f64 + 1.0);
                let q: f64 = g.on(0.5, 1.0).map(|(x, w)| w * x.powi(k as i32)).sum();
                assert!((q - exact).abs() < 1e-13, "n={n} k={k}: {q} against {exact}");
            }
            let k = 2 * n - 2;
            let exact = 2.0 / (k as f64 + 1.0);
            let q: f64 = g.on(-1.0, 1.0).map(|(x, w)| w * x.powi(k as i32)).sum();
            assert!((q - exact).abs() > 1e-12, "n={n}: exact at degree 2n - 2");
        }
    }

    #[test]
    fn exact_for_degree_2n_minus_1() {
        for n in 1..=20 {
            let g = GaussLegendre::new(n);
            assert!((g.weights.iter().sum::<f64>() - 2.0).abs() < 1e-13);
            for k in 0..(2 * n) {
                let exact = (1.0f64.powi(k as i32 + 1) - 0.5f64.powi(k as i32 + 1)) / (k as f64 + 1.0);
                let q: f64 = g.on(0.5, 1.0).map(|(x, w)| w * x.powi(k as i32)).sum();
                assert!((q - exact).abs() < 1e-13 * exact.abs().max(1.0), "n={n} k={k}");
            }
            // not exact at degree 2n
            let k = 2 * n;
            let exact = 2.0 / (k as f64 + 1.0);
            let q: f64 = g.on(-1.0, 1.0).map(|(x, w)| w * x.powi(k as i32)).sum();
            assert!((q - exact).abs() > 1e-15);
        }
    }
}
