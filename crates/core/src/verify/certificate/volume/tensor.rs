//! Trivariate tensor Bernstein polynomials in floating point, each carrying one rigorous
//! bound `e` of the rounding error of all its coefficients, `|ĉ_k - c_k| <= e`, with the
//! arithmetic and constants of the bivariate certificate (`γ_n = n u / (1 - n u)`,
//! [`super::super::bernstein`]):
//!
//! - product: `B_i^m B_j^n = Π_dir binom(m, i) binom(n, j) / binom(m + n, i + j) B_{i+j}^{m+n}`
//!   per direction, convex weights; one term passes through [`MUL_ROUNDINGS`] roundings
//!   (three binomials on each factor, the product, the three binomials of the divisor and
//!   the division), and an output coefficient that accumulates `T` terms (of one or more
//!   products) gets `e_a max|b̂| + (max|â| + e_a) e_b + γ_{MUL + T} max|â| max|b̂|` per
//!   product (`product_error`);
//! - differences along a direction (the derivative nets): `2 e + u max|Δ̂|`;
//! - de Casteljau bisection at `1/2` in all three directions (halving is exact, convex
//!   weights, `du + dv + dw` additions): `e + γ_{du+dv+dw} max|ĉ|`;
//! - evaluation at local coordinates known to a relative `θ_k`:
//!   `e + γ_{(k+3)(du+dv+dw)} max|ĉ|`.

use super::super::bernstein::{amax, gamma, product_error, Binom, TINY, U};

/// Roundings of one term of a product (see the module doc).
pub const MUL_ROUNDINGS: usize = 10;

/// Degrees `[du, dv, dw]`; coefficient `(k, l, m)` at `(m (dv + 1) + l) (du + 1) + k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Deg3(pub [usize; 3]);

impl Deg3 {
    /// Number of coefficients.
    pub fn len(self) -> usize {
        (self.0[0] + 1) * (self.0[1] + 1) * (self.0[2] + 1)
    }
    /// Linear index of `(k, l, m)`.
    pub fn at(self, k: usize, l: usize, m: usize) -> usize {
        (m * (self.0[1] + 1) + l) * (self.0[0] + 1) + k
    }
    /// Sum of the degrees of two polynomials (of their product).
    pub fn plus(self, o: Deg3) -> Deg3 {
        Deg3([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
    /// Degree after differencing in direction `dir`.
    pub fn minus_one(self, dir: usize) -> Deg3 {
        let mut d = self.0;
        d[dir] -= 1;
        Deg3(d)
    }
    fn total(self) -> usize {
        self.0.iter().sum()
    }
}

/// A trivariate Bernstein polynomial with the error bound of its coefficients.
#[derive(Debug, Clone)]
pub struct Poly3 {
    /// Coefficients.
    pub c: Vec<f64>,
    /// Degrees.
    pub d: Deg3,
    /// `|ĉ_k - c_k| <= e`.
    pub e: f64,
}

impl Poly3 {
    /// Differences of the coefficients in direction `dir` (the derivative's net without
    /// its factor `degree / h`).
    pub fn diff(&self, dir: usize) -> Poly3 {
        let d = self.d.minus_one(dir);
        let [du, dv, dw] = d.0;
        let step = [1, self.d.0[0] + 1, (self.d.0[0] + 1) * (self.d.0[1] + 1)][dir];
        let mut c = Vec::with_capacity(d.len());
        for m in 0..=dw {
            for l in 0..=dv {
                for k in 0..=du {
                    let i = self.d.at(k, l, m);
                    c.push(self.c[i + step] - self.c[i]);
                }
            }
        }
        let e = (2.0 * self.e + U * amax(&c)) * (1.0 + 1e-6) + TINY;
        Poly3 { c, d, e }
    }
}

/// A sum of products of the same degree, `Σ s a b`, accumulated unnormalised.
pub struct Acc<'a> {
    bn: &'a Binom,
    d: Deg3,
    c: Vec<f64>,
    terms: usize,
    /// `(max|a|, e_a, max|b|, e_b)` of every product.
    parts: Vec<[f64; 4]>,
}

impl<'a> Acc<'a> {
    /// An empty sum of degree `d`.
    pub fn new(bn: &'a Binom, d: Deg3) -> Self {
        Self { bn, d, c: vec![0.0; d.len()], terms: 0, parts: Vec::new() }
    }

    /// `+= s a b` (`s = ±1`); `a.d + b.d` must be the sum's degree.
    pub fn add(&mut self, a: &Poly3, b: &Poly3, s: f64) {
        debug_assert_eq!(a.d.plus(b.d), self.d);
        let bn = self.bn;
        let [au, av, aw] = a.d.0;
        let [bu, bv, bw] = b.d.0;
        let [nu, nv, _] = self.d.0;
        // b with its binomials
        let mut bs = Vec::with_capacity(b.c.len());
        for m in 0..=bw {
            for l in 0..=bv {
                for k in 0..=bu {
                    bs.push(b.c[b.d.at(k, l, m)] * bn.get(bu, k) * bn.get(bv, l) * bn.get(bw, m));
                }
            }
        }
        for m1 in 0..=aw {
            for l1 in 0..=av {
                for k1 in 0..=au {
                    let x = a.c[a.d.at(k1, l1, m1)] * bn.get(au, k1) * bn.get(av, l1) * bn.get(aw, m1) * s;
                    if x == 0.0 {
                        continue;
                    }
                    for m2 in 0..=bw {
                        for l2 in 0..=bv {
                            let row = ((m1 + m2) * (nv + 1) + l1 + l2) * (nu + 1) + k1;
                            let brow = (m2 * (bv + 1) + l2) * (bu + 1);
                            let out = &mut self.c[row..row + bu + 1];
                            for (o, &y) in out.iter_mut().zip(&bs[brow..brow + bu + 1]) {
                                *o += x * y;
                            }
                        }
                    }
                }
            }
        }
        self.terms += a.d.len();
        self.parts.push([amax(&a.c), a.e, amax(&b.c), b.e]);
    }

    /// Normalise (divide by the output binomials) and bound the error.
    pub fn finish(mut self) -> Poly3 {
        let bn = self.bn;
        let [nu, nv, nw] = self.d.0;
        for m in 0..=nw {
            for l in 0..=nv {
                for k in 0..=nu {
                    self.c[self.d.at(k, l, m)] /= bn.get(nu, k) * bn.get(nv, l) * bn.get(nw, m);
                }
            }
        }
        let r = MUL_ROUNDINGS + self.terms;
        let e = self.parts.iter().map(|p| product_error(p[0], p[1], p[2], p[3], r)).sum::<f64>() + TINY;
        Poly3 { c: self.c, d: self.d, e }
    }
}

/// `Σ_i s_i a_i b_i` for pairs of equal product degree.
pub fn sum_of_products(bn: &Binom, pairs: &[(&Poly3, &Poly3, f64)]) -> Poly3 {
    let d = pairs[0].0.d.plus(pairs[0].1.d);
    let mut acc = Acc::new(bn, d);
    for &(a, b, s) in pairs {
        acc.add(a, b, s);
    }
    acc.finish()
}

/// Split a coefficient line (`n + 1` values at `stride`) at `1/2` into two halves.
fn split_line(c: &[f64], n: usize, stride: usize, base: usize, lo: &mut [f64], hi: &mut [f64], tmp: &mut [f64]) {
    for (r, t) in tmp[..=n].iter_mut().enumerate() {
        *t = c[base + r * stride];
    }
    for r in 0..=n {
        lo[base + r * stride] = tmp[0];
        hi[base + (n - r) * stride] = tmp[n - r];
        for k in 0..n - r {
            tmp[k] = 0.5 * (tmp[k] + tmp[k + 1]);
        }
    }
}

/// Split in direction `dir` at `1/2` (de Casteljau) into the lower and upper halves.
pub fn split(c: &[f64], d: Deg3, dir: usize, lo: &mut [f64], hi: &mut [f64], tmp: &mut [f64]) {
    let [du, dv, dw] = d.0;
    let n = d.0[dir];
    let stride = [1, du + 1, (du + 1) * (dv + 1)][dir];
    for m in 0..=(if dir == 2 { 0 } else { dw }) {
        for l in 0..=(if dir == 1 { 0 } else { dv }) {
            for k in 0..=(if dir == 0 { 0 } else { du }) {
                split_line(c, n, stride, d.at(k, l, m), lo, hi, tmp);
            }
        }
    }
}

/// The eight children of a box (child `b` is the lower half in direction `dir` when bit
/// `dir` of `b` is clear), with their error bound.
pub fn split8(c: &[f64], d: Deg3, e: f64, tmp: &mut [f64]) -> ([Vec<f64>; 8], f64) {
    let n = d.len();
    let err = e + gamma(d.total()) * amax(c) + TINY;
    let mut cur: Vec<Vec<f64>> = vec![c.to_vec()];
    for dir in 0..3 {
        let mut next = Vec::with_capacity(2 * cur.len());
        for x in &cur {
            let (mut lo, mut hi) = (vec![0.0; n], vec![0.0; n]);
            split(x, d, dir, &mut lo, &mut hi, tmp);
            next.push(lo);
            next.push(hi);
        }
        cur = next;
    }
    // cur index bits: dir 0 is the most significant; reorder so that bit `dir` of the
    // child index is direction `dir`
    let mut out: [Vec<f64>; 8] = Default::default();
    for (i, v) in cur.into_iter().enumerate() {
        let (b0, b1, b2) = ((i >> 2) & 1, (i >> 1) & 1, i & 1);
        out[b0 | (b1 << 1) | (b2 << 2)] = v;
    }
    (out, err)
}

/// Value at the local point with coordinates given as pairs `(1 - s, s)` per direction
/// (de Casteljau along `u`, then `v`, then `w`).
pub fn eval(c: &[f64], d: Deg3, s: [[f64; 2]; 3], tmp: &mut [f64]) -> f64 {
    let [du, dv, dw] = d.0;
    let (plane, rest) = tmp.split_at_mut((dv + 1) * (dw + 1));
    let (line, row) = rest.split_at_mut(dw + 1);
    for m in 0..=dw {
        for l in 0..=dv {
            let base = d.at(0, l, m);
            row[..=du].copy_from_slice(&c[base..base + du + 1]);
            for r in 1..=du {
                for k in 0..=du - r {
                    row[k] = s[0][0] * row[k] + s[0][1] * row[k + 1];
                }
            }
            plane[m * (dv + 1) + l] = row[0];
        }
    }
    for m in 0..=dw {
        let col = &mut plane[m * (dv + 1)..(m + 1) * (dv + 1)];
        for r in 1..=dv {
            for l in 0..=dv - r {
                col[l] = s[1][0] * col[l] + s[1][1] * col[l + 1];
            }
        }
        line[m] = col[0];
    }
    for r in 1..=dw {
        for m in 0..=dw - r {
            line[m] = s[2][0] * line[m] + s[2][1] * line[m + 1];
        }
    }
    line[0]
}

/// Scratch length needed by [`eval`] and [`split`] for degree `d`.
pub fn scratch_len(d: Deg3) -> usize {
    let [du, dv, dw] = d.0;
    (dv + 1) * (dw + 1) + (dw + 1) + du + 1 + du.max(dv).max(dw) + 1
}

/// Error bound of [`eval`] when the coefficients are known to `e` and the local
/// coordinates to a relative `θ_k` (`k = 0`: exact, as at dyadic points).
pub fn eval_error(c: &[f64], d: Deg3, e: f64, k: usize) -> f64 {
    e + gamma((k + 3) * d.total()) * amax(c) + TINY
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Lcg;

    fn random(rng: &mut Lcg, d: Deg3) -> Poly3 {
        Poly3 { c: (0..d.len()).map(|_| rng.uniform() - 0.5).collect(), d, e: 0.0 }
    }

    fn at(p: &Poly3, s: [f64; 3]) -> f64 {
        let mut tmp = vec![0.0; scratch_len(p.d)];
        eval(&p.c, p.d, s.map(|x| [1.0 - x, x]), &mut tmp)
    }

    #[test]
    fn products_and_differences_are_the_polynomials() {
        let mut rng = Lcg::new(3);
        let bn = Binom::new(20);
        let (a, b) = (random(&mut rng, Deg3([2, 1, 3])), random(&mut rng, Deg3([1, 3, 2])));
        let ab = sum_of_products(&bn, &[(&a, &b, 1.0)]);
        assert_eq!(ab.d, Deg3([3, 4, 5]));
        for _ in 0..20 {
            let s = [rng.uniform(), rng.uniform(), rng.uniform()];
            assert!((at(&ab, s) - at(&a, s) * at(&b, s)).abs() < 1e-14);
            // derivative in direction 1: degree times the differences' polynomial
            let h = 1e-6;
            let (mut lo, mut hi) = (s, s);
            lo[1] -= h;
            hi[1] += h;
            let fd = (at(&a, hi) - at(&a, lo)) / (2.0 * h);
            assert!((fd - 1.0 * at(&a.diff(1), s)).abs() < 1e-8);
        }
        assert!(ab.e > 0.0 && ab.e < 1e-13);
    }

    #[test]
    fn children_reproduce_the_polynomial() {
        let mut rng = Lcg::new(7);
        let p = random(&mut rng, Deg3([3, 2, 2]));
        let mut tmp = vec![0.0; scratch_len(p.d) + p.d.len()];
        let (kids, _) = split8(&p.c, p.d, 0.0, &mut tmp);
        for (b, kid) in kids.iter().enumerate() {
            let child = Poly3 { c: kid.clone(), d: p.d, e: 0.0 };
            for _ in 0..5 {
                let s = [rng.uniform(), rng.uniform(), rng.uniform()];
                let parent = std::array::from_fn(|d| 0.5 * (s[d] + ((b >> d) & 1) as f64));
                assert!((at(&child, s) - at(&p, parent)).abs() < 1e-14, "child {b}");
            }
        }
    }
}
