//! Non-zero B-spline basis functions and their derivatives at a point
//! (Piegl & Tiller, *The NURBS Book*, algorithms A2.2 and A2.3), without heap allocation.

use crate::error::MAX_DEGREE;
use crate::spline::knots::KnotVector;

/// Highest derivative order evaluated by [`BasisDerivs`].
pub(crate) const MAX_DERIV: usize = 2;
const W: usize = MAX_DEGREE + 1;

/// The `p + 1` non-zero basis functions `N_{s-p..=s}` at one point and their first
/// `nd <= 2` derivatives: `d[k][j] = N^{(k)}_{s-p+j}(u)`.
#[derive(Debug, Clone, Copy)]
pub struct BasisDerivs {
    /// Span index `s` (first non-zero function is `s - p`).
    pub span: usize,
    /// Degree `p`.
    pub degree: usize,
    /// `d[k][j]`: `k`-th derivative of the `j`-th non-zero function.
    pub d: [[f64; W]; MAX_DERIV + 1],
}

impl Default for BasisDerivs {
    fn default() -> Self {
        Self { span: 0, degree: 0, d: [[0.0; W]; MAX_DERIV + 1] }
    }
}

impl BasisDerivs {
    /// Evaluate at `u` (clamped to the domain) with derivatives up to order `nd <= 2`.
    pub fn at(kv: &KnotVector, u: f64, nd: usize) -> Self {
        let mut out = Self::default();
        out.eval(kv, u, nd);
        out
    }

    /// Evaluate in place at `u` in the span found by `KnotVector::find_span`.
    pub fn eval(&mut self, kv: &KnotVector, u: f64, nd: usize) {
        let span = kv.find_span(u);
        self.eval_in_span(kv, span, u, nd);
    }

    /// Evaluate in place at `u` in the given span (useful on element boundaries, where the
    /// caller picks the element). Implements A2.3 of Piegl & Tiller.
    pub(crate) fn eval_in_span(&mut self, kv: &KnotVector, span: usize, u: f64, nd: usize) {
        let p = kv.degree();
        let t = kv.knots();
        debug_assert!(nd <= MAX_DERIV && p <= MAX_DEGREE);
        self.span = span;
        self.degree = p;
        if nd == 0 {
            self.values_in_span(t, span, u);
            return;
        }
        let mut ndu = [[0.0f64; W]; W];
        let mut left = [0.0f64; W];
        let mut right = [0.0f64; W];
        ndu[0][0] = 1.0;
        for j in 1..=p {
            left[j] = u - t[span + 1 - j];
            right[j] = t[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                // lower triangle: knot differences
                ndu[j][r] = right[r + 1] + left[j - r];
                let temp = ndu[r][j - 1] / ndu[j][r];
                // upper triangle: basis functions
                ndu[r][j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j][j] = saved;
        }
        for j in 0..=p {
            self.d[0][j] = ndu[j][p];
        }
        let nd = nd.min(p);
        if nd == 0 {
            // `p = 0`: only the value
            for k in 1..=MAX_DERIV {
                self.d[k][..=p].fill(0.0);
            }
            return;
        }
        let mut a = [[0.0f64; W]; 2];
        for r in 0..=p {
            let (mut s1, mut s2) = (0usize, 1usize);
            a[0][0] = 1.0;
            for k in 1..=nd {
                let mut dk = 0.0;
                let rk = r as isize - k as isize;
                let pk = p - k;
                if r >= k {
                    a[s2][0] = a[s1][0] / ndu[pk + 1][rk as usize];
                    dk = a[s2][0] * ndu[rk as usize][pk];
                }
                let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
                let j2 = if (r as isize - 1) <= pk as isize { k - 1 } else { p - r };
                for j in j1..=j2 {
                    let idx = (rk + j as isize) as usize;
                    a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                    dk += a[s2][j] * ndu[idx][pk];
                }
                if r <= pk {
                    a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                    dk += a[s2][k] * ndu[r][pk];
                }
                self.d[k][r] = dk;
                std::mem::swap(&mut s1, &mut s2);
            }
        }
        let mut fac = p as f64;
        for k in 1..=nd {
            for j in 0..=p {
                self.d[k][j] *= fac;
            }
            fac *= (p - k) as f64;
        }
        for k in nd + 1..=MAX_DERIV {
            self.d[k][..=p].fill(0.0);
        }
    }

    /// The values alone (A2.2 of Piegl & Tiller): the same operations, in the same order,
    /// as the upper triangle of A2.3's table `ndu`, so the values are bit-identical to
    /// those of [`BasisDerivs::eval_in_span`] with derivatives, without filling the
    /// `(MAX_DEGREE + 1)²` table (most of the cost of a value at low degree).
    fn values_in_span(&mut self, t: &[f64], span: usize, u: f64) {
        let p = self.degree;
        let mut left = [0.0f64; W];
        let mut right = [0.0f64; W];
        let n = &mut self.d[0];
        n[0] = 1.0;
        for j in 1..=p {
            left[j] = u - t[span + 1 - j];
            right[j] = t[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                let temp = n[r] / (right[r + 1] + left[j - r]);
                n[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            n[j] = saved;
        }
        for k in 1..=MAX_DERIV {
            self.d[k][..=p].fill(0.0);
        }
    }

    /// Index of the first non-zero basis function, `span - p`.
    pub fn first(&self) -> usize {
        self.span - self.degree
    }

    /// The `k`-th derivatives of the non-zero functions.
    pub(crate) fn ders(&self, k: usize) -> &[f64] {
        &self.d[k][..=self.degree]
    }
}

#[cfg(test)]
/// Values of all `n` basis functions at `u` (dense; for tests and small fits).
pub(crate) fn dense_values(kv: &KnotVector, u: f64) -> Vec<f64> {
    let b = BasisDerivs::at(kv, u, 0);
    let mut v = vec![0.0; kv.num_basis()];
    for (j, &x) in b.ders(0).iter().enumerate() {
        v[b.first() + j] = x;
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Lcg;

    fn random_kv(rng: &mut Lcg, p: usize) -> KnotVector {
        let ne = 1 + rng.below(7);
        let mut breaks = vec![0.0];
        for _ in 0..ne {
            breaks.push(breaks.last().unwrap() + 0.1 + rng.uniform());
        }
        let mut kv = KnotVector::open_from_breaks(p, &breaks, 1);
        // random extra multiplicities (keep <= p)
        let inner: Vec<f64> = breaks[1..breaks.len() - 1].to_vec();
        for &b in &inner {
            let extra = rng.below(p);
            kv = kv.with_inserted(&vec![b; extra]);
        }
        kv
    }

    #[test]
    fn partition_of_unity_and_fd_derivatives() {
        let mut rng = Lcg::new(7);
        for p in 1..=6 {
            for _ in 0..20 {
                let kv = random_kv(&mut rng, p);
                let (a, b) = kv.domain();
                for _ in 0..20 {
                    let u = a + (b - a) * rng.uniform();
                    let bd = BasisDerivs::at(&kv, u, 2);
                    let s: f64 = bd.ders(0).iter().sum();
                    assert!((s - 1.0).abs() < 1e-14, "p={p} sum={s}");
                    assert!(bd.ders(0).iter().all(|&x| x >= -1e-15));
                    let d1: f64 = bd.ders(1).iter().sum();
                    let d2: f64 = bd.ders(2).iter().sum();
                    assert!(d1.abs() < 1e-10 && d2.abs() < 1e-8, "derivs of unity {d1} {d2}");
                    // central differences inside the same span
                    let h = 1e-6 * (b - a);
                    let s0 = kv.knots()[bd.span];
                    let s1 = kv.knots()[bd.span + 1];
                    if u - h <= s0 || u + h >= s1 {
                        continue;
                    }
                    let mut lo = BasisDerivs::default();
                    let mut hi = BasisDerivs::default();
                    lo.eval_in_span(&kv, bd.span, u - h, 2);
                    hi.eval_in_span(&kv, bd.span, u + h, 2);
                    for j in 0..=p {
                        let fd1 = (hi.d[0][j] - lo.d[0][j]) / (2.0 * h);
                        let fd2 = (hi.d[1][j] - lo.d[1][j]) / (2.0 * h);
                        let scale = 1.0 + bd.d[1][j].abs();
                        assert!((fd1 - bd.d[1][j]).abs() < 1e-6 * scale, "p={p} d1 {fd1} vs {}", bd.d[1][j]);
                        let scale2 = 1.0 + bd.d[2][j].abs();
                        assert!((fd2 - bd.d[2][j]).abs() < 1e-5 * scale2, "p={p} d2 {fd2} vs {}", bd.d[2][j]);
                    }
                }
            }
        }
    }

    /// The values alone (A2.2) are the values of A2.3 to the last bit, at every degree,
    /// on knots with repeated entries, at knots and between them.
    #[test]
    fn values_alone_are_the_values_with_derivatives_bit_for_bit() {
        let mut rng = Lcg::new(11);
        for p in 0..=MAX_DEGREE {
            for _ in 0..10 {
                let kv =
                    if p == 0 { KnotVector::open_from_breaks(0, &[0.0, 0.3, 1.0], 1) } else { random_kv(&mut rng, p) };
                let (a, b) = kv.domain();
                let knots: Vec<f64> = kv.knots().to_vec();
                let params = (0..30).map(|_| a + (b - a) * rng.uniform()).chain(knots);
                for u in params {
                    let (v, d) = (BasisDerivs::at(&kv, u, 0), BasisDerivs::at(&kv, u, 2));
                    assert_eq!(v.span, d.span);
                    let bits = |x: &[f64]| x.iter().map(|y| y.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(v.ders(0)), bits(d.ders(0)), "p = {p}, u = {u}");
                    assert!(v.ders(1).iter().chain(v.ders(2)).all(|&x| x == 0.0));
                }
            }
        }
    }

    #[test]
    fn linear_precision_at_greville() {
        // sum_i g_i N_i(u) = u for the Greville abscissae g_i
        let kv = KnotVector::open_from_breaks(3, &[0.0, 0.2, 0.7, 1.0], 1);
        let g = kv.greville();
        for k in 0..=50 {
            let u = k as f64 / 50.0;
            let v = dense_values(&kv, u);
            let x: f64 = v.iter().zip(&g).map(|(a, b)| a * b).sum();
            assert!((x - u).abs() < 1e-14);
        }
    }
}
