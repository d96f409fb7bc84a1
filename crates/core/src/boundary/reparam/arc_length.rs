//! Arc-length reparameterization of a parametric side (paper §7.1, eq. 38-39): the
//! monotone map `g` minimizing `∫ ||(f̄ ∘ g)'||²` by Gauss-Newton steps that keep its
//! coefficients increasing.

use super::*;

/// A parametric side on the normalized parameter `t ∈ [0, 1]`: value, first and second
/// derivative, and the breaks of its smoothness.
pub(super) struct Parametric<'a> {
    pub(super) side: &'a SideCurve,
    pub(super) breaks: Vec<f64>,
}

impl<'a> Parametric<'a> {
    pub(super) fn new(side: &'a SideCurve) -> Option<Self> {
        let breaks = match side {
            SideCurve::Spline(c) => {
                let (a, b) = c.domain();
                c.knots.breaks().into_iter().map(|u| ((u - a) / (b - a)).clamp(0.0, 1.0)).collect()
            }
            SideCurve::Analytic(_) => vec![0.0, 1.0],
            SideCurve::Points(_) => return None,
        };
        Some(Self { side, breaks })
    }

    pub(super) fn eval(&self, t: f64) -> Point {
        match self.side {
            SideCurve::Spline(c) => {
                let (a, b) = c.domain();
                c.eval(a + t.clamp(0.0, 1.0) * (b - a))
            }
            SideCurve::Analytic(f) => f.eval(t.clamp(0.0, 1.0)),
            SideCurve::Points(_) => unreachable!("point clouds are not parametric"),
        }
    }

    /// `(f, f', f'')` at `t`; analytic sides by central differences.
    pub(super) fn derivs(&self, t: f64) -> [Point; 3] {
        match self.side {
            SideCurve::Spline(c) => {
                let (a, b) = c.domain();
                let l = b - a;
                let d = c.derivs(a + t.clamp(0.0, 1.0) * l, 2);
                [d.x, [d.d1[0] * l, d.d1[1] * l], [d.d2[0] * l * l, d.d2[1] * l * l]]
            }
            SideCurve::Analytic(f) => {
                let h = 1e-4;
                let c = t.clamp(h, 1.0 - h);
                let (m, z, p) = (f.eval(c - h), f.eval(c), f.eval(c + h));
                let d1 = [(p[0] - m[0]) / (2.0 * h), (p[1] - m[1]) / (2.0 * h)];
                let d2 = [(p[0] - 2.0 * z[0] + m[0]) / (h * h), (p[1] - 2.0 * z[1] + m[1]) / (h * h)];
                let x = f.eval(t.clamp(0.0, 1.0));
                [x, [d1[0] + (t - c) * d2[0], d1[1] + (t - c) * d2[1]], d2]
            }
            SideCurve::Points(_) => unreachable!("point clouds are not parametric"),
        }
    }
}

/// Approximate arc-length reparameterization of a parametric side (eq. 38-39): `g` is a
/// cubic B-spline on `elements` uniform elements with `c_0 = 0`, `c_n = 1`, started from
/// the Schoenberg (variation-diminishing) approximation of the inverse cord length
/// `c_i = s^{-1}(γ_i)` at the Greville points `γ_i` (increasing, so `g' > 0`), then
/// improved by Gauss-Newton steps on `A(c) = ∫ ||f̄'(g) g'||^2 dξ`; a step is accepted
/// only when it lowers `A` and keeps the coefficients strictly increasing, so `g` stays
/// strictly monotone (its derivative is a spline with positive coefficients). Returns
/// `g` and `A / L^2 >= 1` (1 for exact arc length). `None` for point clouds.
pub(crate) fn arc_length_map(side: &SideCurve, elements: usize, samples: usize) -> Result<Option<(ParamMap, f64)>> {
    arc_length_iterations(side, elements, samples, 30)
}

/// [`arc_length_map`] with at most `iterations` Gauss-Newton steps.
pub(super) fn arc_length_iterations(
    side: &SideCurve,
    elements: usize,
    samples: usize,
    iterations: usize,
) -> Result<Option<(ParamMap, f64)>> {
    let Some(f) = Parametric::new(side) else { return Ok(None) };
    let sample = sample_side(side, samples);
    let t = sample.t.expect("parametric");
    let s = cord_length_params(&sample.points)
        .ok_or_else(|| Error::Invalid("arc-length reparameterization of a side of zero length".into()))?;
    let length: f64 = sample.points.windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum();
    let inv = interpolating_map(&s, &t)?;
    let kv = KnotVector::open_uniform(3, elements.max(1));
    let n = kv.num_basis();
    let mut c: Vec<f64> = kv.greville().iter().map(|&g| inv.eval(g)).collect();
    c[0] = 0.0;
    c[n - 1] = 1.0;
    if c.windows(2).any(|w| w[1] <= w[0]) {
        // a stationary stretch: fall back to uniform increments there
        for i in 1..n {
            c[i] = c[i].max(c[i - 1] + 1e-9);
        }
        let top = c[n - 1];
        c.iter_mut().for_each(|v| *v /= top);
    }
    let gauss = GaussLegendre::new(8);
    // A(c) and, when asked, the Gauss-Newton system on the free coefficients.
    // the Gauss-Newton matrix in band storage: `band[i][j + 3 - i] = (J^T J)_{ij}`
    let functional = |c: &[f64], sys: Option<(&mut Vec<[f64; 7]>, &mut Vec<f64>)>| -> f64 {
        let g = ParamMap::Spline { knots: kv.clone(), coefs: c.to_vec() };
        // pieces: g's breaks and the preimages of the side's breaks
        let mut br = g.breaks();
        br.extend(f.breaks.iter().map(|&u| g.inverse(u)));
        br.sort_by(f64::total_cmp);
        br.dedup_by(|a, b| (*a - *b).abs() < 1e-14);
        let mut total = 0.0;
        let mut sys = sys;
        let mut b = crate::spline::basis::BasisDerivs::default();
        for w in br.windows(2) {
            for (xi, wt) in gauss.on(w[0], w[1]) {
                b.eval(&kv, xi, 1);
                let first = b.first();
                let (mut gv, mut gd) = (0.0, 0.0);
                for j in 0..=3 {
                    gv += b.d[0][j] * c[first + j];
                    gd += b.d[1][j] * c[first + j];
                }
                let [_, d1, d2] = f.derivs(gv);
                let r = [d1[0] * gd, d1[1] * gd];
                total += wt * (r[0] * r[0] + r[1] * r[1]);
                if let Some((jtj, jtr)) = sys.as_mut() {
                    let mut jac = [[0.0; 2]; 4];
                    for j in 0..=3 {
                        for k in 0..2 {
                            jac[j][k] = d2[k] * gd * b.d[0][j] + d1[k] * b.d[1][j];
                        }
                    }
                    for j in 0..=3 {
                        let gj = first + j;
                        jtr[gj] += wt * (jac[j][0] * r[0] + jac[j][1] * r[1]);
                        for k in 0..=3 {
                            jtj[gj][k + 3 - j] += wt * (jac[j][0] * jac[k][0] + jac[j][1] * jac[k][1]);
                        }
                    }
                }
            }
        }
        total
    };
    let mut a = functional(&c, None);
    for _ in 0..iterations {
        let mut jtj = vec![[0.0; 7]; n];
        let mut jtr = vec![0.0; n];
        functional(&c, Some((&mut jtj, &mut jtr)));
        // free unknowns 1..n-1 (c_0 and c_n are fixed), with a tiny shift
        let m = n - 2;
        if m == 0 {
            break;
        }
        let mut mat: Vec<[f64; 7]> = jtj[1..n - 1].to_vec();
        for (i, row) in mat.iter_mut().enumerate() {
            for (d, v) in row.iter_mut().enumerate() {
                if i + d < 3 || i + d >= m + 3 {
                    *v = 0.0; // couplings to the fixed ends
                }
            }
        }
        let tr = mat.iter().map(|r| r[3]).sum::<f64>() / m as f64;
        mat.iter_mut().for_each(|r| r[3] += 1e-12 * tr);
        let mut rhs: Vec<f64> = (1..n - 1).map(|i| -jtr[i]).collect();
        if !solve_band(&mut mat, &mut rhs) {
            break;
        }
        let mut alpha = 1.0;
        let mut accepted = false;
        while alpha > 1e-6 {
            let mut trial = c.clone();
            for i in 0..m {
                trial[i + 1] += alpha * rhs[i];
            }
            if trial.windows(2).all(|w| w[1] > w[0]) {
                let at = functional(&trial, None);
                if at < a {
                    let rel = (a - at) / a;
                    c = trial;
                    a = at;
                    accepted = rel > 1e-12;
                    break;
                }
            }
            alpha *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    let ratio = if length > 0.0 { a / (length * length) } else { f64::NAN };
    Ok(Some((ParamMap::Spline { knots: kv, coefs: c }, ratio)))
}

/// Gaussian elimination without pivoting on a symmetric positive definite matrix of
/// half-bandwidth 3 in band storage (`a[i][j + 3 - i] = A_{ij}`); `false` on a
/// non-positive pivot.
pub(super) fn solve_band(a: &mut [[f64; 7]], b: &mut [f64]) -> bool {
    let n = b.len();
    for k in 0..n {
        let piv = a[k][3];
        if !(piv > 0.0 && piv.is_finite()) {
            return false;
        }
        for i in k + 1..n.min(k + 4) {
            let f = a[i][k + 3 - i] / piv;
            if f == 0.0 {
                continue;
            }
            for j in k..n.min(k + 4) {
                a[i][j + 3 - i] -= f * a[k][j + 3 - k];
            }
            b[i] -= f * b[k];
        }
    }
    for k in (0..n).rev() {
        let mut s = b[k];
        for j in k + 1..n.min(k + 4) {
            s -= a[k][j + 3 - k] * b[j];
        }
        b[k] = s / a[k][3];
    }
    true
}
