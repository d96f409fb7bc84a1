//! Tensor Bernstein polynomials in `D` variables (`D = 2`: maps of the plane, `D = 3`:
//! volumes) in floating point with a rigorous bound of their rounding error (running
//! error analysis with the standard constants of Higham, *Accuracy and Stability of
//! Numerical Algorithms*, §3.1).
//!
//! With the unit roundoff `u = 2^-53` every operation of round-to-nearest IEEE arithmetic
//! satisfies `fl(a op b) = (a op b)(1 + δ)`, `|δ| <= u`, away from underflow, and a
//! product of `n` such factors (or their inverses) is `1 + θ_n` with
//! `|θ_n| <= γ_n = n u / (1 - n u)`. A quantity computed as a sum of terms, each of which
//! passed through at most `n` roundings, therefore has the error bound
//! `|ŝ - s| <= γ_n Σ |t̂_i|`. Each array here carries one such bound `e` valid for all its
//! coefficients: `|ĉ_k - c_k| <= e`, where `c_k` is the exact coefficient of the exact
//! map. The operations propagate it:
//!
//! - product (`B_i^m B_j^n = Π_dir binom(m, i) binom(n, j) / binom(m + n, i + j) B_{i+j}^{m+n}`
//!   per direction, the weights `λ` of one output coefficient are positive and sum to
//!   one): `e_ab = e_a max|b̂| + (max|â| + e_a) e_b + γ_r max|â| max|b̂|`, with `r` the
//!   roundings of one term ([`mul_roundings`]: binomial products, the product, the final
//!   division) plus the accumulation;
//! - differences along a direction (the derivative nets): `2 e + u max|Δ̂|`;
//! - de Casteljau bisection at `1/2` in every direction (halving is exact; `Σ d_dir`
//!   additions per coefficient, convex weights): `e_child = e_parent + γ_{Σ d} max|ĉ_parent|`;
//! - evaluation at a point whose local coordinates `s`, `1 - s` are known with relative
//!   error `θ_k` (de Casteljau, convex weights, three roundings per level):
//!   `e = e_coeffs + γ_{(k+3) Σ d} max|ĉ|`.
//!
//! Underflow (possible only far below the element's scale, since every element's net is
//! scaled to unit size by a power of two, which is exact) adds at most `2^-1075` per
//! multiplication; the absolute term [`TINY`] added to every bound covers it with a wide
//! margin. `γ_n` itself is evaluated with a relative slack of `10^-6`, which covers the
//! rounding of the bound's own evaluation (`n u < 10^-10` for every `n` used here).

/// Unit roundoff of `f64`.
pub const U: f64 = f64::EPSILON / 2.0;

/// Absolute slack added to every error bound: covers underflow (see the module doc).
pub(crate) const TINY: f64 = 1e-290;

/// `γ_n = n u / (1 - n u)`, rounded up (relative slack `10^-6`, valid for `n u < 10^-7`).
pub(crate) fn gamma(n: usize) -> f64 {
    let nu = n as f64 * U;
    debug_assert!(nu < 1e-7);
    nu * (1.0 + 1e-6)
}

/// Largest magnitude of a slice.
pub fn amax(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The degrees `[d_0, .., d_{D-1}]` of a tensor Bernstein polynomial; coefficient
/// `(k_0, .., k_{D-1})` at `Σ_dir k_dir Π_{dir' < dir} (d_dir' + 1)` (direction 0
/// fastest).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Deg<const D: usize>(pub [usize; D]);

impl<const D: usize> Deg<D> {
    /// Number of coefficients.
    pub fn len(self) -> usize {
        self.0.iter().map(|d| d + 1).product()
    }
    /// Distance between neighbours in direction `dir` in the coefficient array.
    pub(crate) fn stride(self, dir: usize) -> usize {
        self.0[..dir].iter().map(|d| d + 1).product()
    }
    /// Linear index of the multi-index `k`.
    pub fn at(self, k: [usize; D]) -> usize {
        (0..D).rev().fold(0, |i, dir| i * (self.0[dir] + 1) + k[dir])
    }
    /// Multi-index of the linear index `i`.
    pub fn index(self, mut i: usize) -> [usize; D] {
        std::array::from_fn(|dir| {
            let k = i % (self.0[dir] + 1);
            i /= self.0[dir] + 1;
            k
        })
    }
    /// Step the multi-index `k` to the next one in the order of the coefficients, over
    /// the directions `from..D` (the others held; after the last one `k` is all zeros
    /// there).
    pub(crate) fn advance(self, k: &mut [usize; D], from: usize) {
        for dir in from..D {
            k[dir] += 1;
            if k[dir] <= self.0[dir] {
                return;
            }
            k[dir] = 0;
        }
    }
    /// Sum of the degrees of two polynomials (of their product).
    pub fn plus(self, o: Self) -> Self {
        Self(std::array::from_fn(|dir| self.0[dir] + o.0[dir]))
    }
    /// Degree after differencing in direction `dir`.
    pub(crate) fn minus_one(self, dir: usize) -> Self {
        let mut d = self.0;
        d[dir] -= 1;
        Self(d)
    }
    /// `Σ_dir d_dir`: the additions per coefficient of one bisection in every direction.
    pub fn total(self) -> usize {
        self.0.iter().sum()
    }
}

/// `binom(n, k)`: exact for the small `n` used here (every intermediate is an integer
/// below `2^53`).
fn binom(n: usize, k: usize) -> f64 {
    let mut r = 1.0;
    for i in 0..k {
        r = r * (n - i) as f64 / (i + 1) as f64;
    }
    r
}

/// Binomial coefficients `binom(n, k)` for `n <= maxn`.
#[derive(Debug)]
pub(crate) struct Binom {
    rows: Vec<Vec<f64>>,
}

impl Binom {
    /// Rows `0..=maxn`.
    pub fn new(maxn: usize) -> Self {
        Self { rows: (0..=maxn).map(|n| (0..=n).map(|k| binom(n, k)).collect()).collect() }
    }
    /// `binom(n, k)`.
    pub fn get(&self, n: usize, k: usize) -> f64 {
        self.rows[n][k]
    }
    /// `binom(n, k)` for `k = 0..=n`.
    fn row(&self, n: usize) -> &[f64] {
        &self.rows[n]
    }
    /// `Π_dir binom(d_dir, k_dir)`, multiplied in the order of the directions.
    fn product<const D: usize>(&self, d: Deg<D>, k: [usize; D]) -> f64 {
        (1..D).fold(self.get(d.0[0], k[0]), |r, dir| r * self.get(d.0[dir], k[dir]))
    }
}

/// Roundings of one term of [`mul_add`] (the accumulation is counted by the caller, see
/// [`terms_per_coefficient`]). `D = 2`: four binomial products, the product of the two
/// coefficients and the final division of [`normalize`] (the divisor
/// `binom(n_u, k) binom(n_v, l)` is exact for the degrees used); `D = 3`: three binomials
/// on each factor, the product, the two products of the divisor's three binomials and
/// the division.
pub(crate) const fn mul_roundings(d: usize) -> usize {
    if d == 2 {
        6
    } else {
        10
    }
}

/// At most how many terms one output coefficient of a product of degrees `da`, `db`
/// receives (each multi-index of `a` at most once).
pub(crate) fn terms_per_coefficient<const D: usize>(da: Deg<D>) -> usize {
    da.len()
}

/// `out += s * a * b` (Bernstein product, unnormalised: call [`normalize`] once after
/// all products of the same degree are accumulated); `s = ±1`. Each term is
/// `s a_i Π binom(da, i) · b_j Π binom(db, j)`; the order of its multiplications is the
/// one each certificate has always used (so that verdicts and bounds stay bit for bit
/// what they were): in the plane `((x binom(db_v, l)) b_j) binom(db_u, k)` with
/// `x = s a_i binom(da_u) binom(da_v)`, in space `x (b_j binom(db_u) binom(db_v) binom(db_w))`.
pub(crate) fn mul_add<const D: usize>(
    bn: &Binom,
    a: &[f64],
    da: Deg<D>,
    b: &[f64],
    db: Deg<D>,
    s: f64,
    out: &mut [f64],
) {
    let dn = da.plus(db);
    let wb = db.0[0] + 1;
    let lines = db.len() / wb;
    // b with its binomials (space)
    let mut bs = Vec::new();
    if D != 2 {
        let mut kb = [0; D];
        for &v in b {
            bs.push((0..D).fold(v, |r, dir| r * bn.get(db.0[dir], kb[dir])));
            db.advance(&mut kb, 0);
        }
    }
    let mut ka = [0; D];
    for &av in a {
        let x = (0..D).fold(av, |r, dir| r * bn.get(da.0[dir], ka[dir])) * s;
        if x != 0.0 {
            let mut kb = [0; D];
            for line in 0..lines {
                let row = dn.at(std::array::from_fn(|dir| ka[dir] + kb[dir]));
                let (bl, out) = (&b[line * wb..(line + 1) * wb], &mut out[row..row + wb]);
                if D == 2 {
                    let y = (1..D).fold(x, |r, dir| r * bn.get(db.0[dir], kb[dir]));
                    for ((o, &v), &bk) in out.iter_mut().zip(bl).zip(bn.row(db.0[0])) {
                        *o += y * v * bk;
                    }
                } else {
                    for (o, &v) in out.iter_mut().zip(&bs[line * wb..(line + 1) * wb]) {
                        *o += x * v;
                    }
                }
                db.advance(&mut kb, 1);
            }
        }
        da.advance(&mut ka, 0);
    }
}

/// Divide the accumulated products by `Π_dir binom(n_dir, k_dir)`.
pub(crate) fn normalize<const D: usize>(bn: &Binom, d: Deg<D>, out: &mut [f64]) {
    let mut k = [0; D];
    for o in out[..d.len()].iter_mut() {
        *o /= bn.product(d, k);
        d.advance(&mut k, 0);
    }
}

/// Error bound of one product term `a b` (see the module doc): `a` known to `ea`, `b` to
/// `eb`, `r` roundings per term.
pub(crate) fn product_error(amax_a: f64, ea: f64, amax_b: f64, eb: f64, r: usize) -> f64 {
    (ea * amax_b + (amax_a + ea) * eb + gamma(r) * amax_a * amax_b) * (1.0 + 1e-6)
}

/// A tensor Bernstein polynomial with the error bound of its coefficients.
#[derive(Debug, Clone)]
pub(crate) struct Poly<const D: usize> {
    /// Coefficients.
    pub c: Vec<f64>,
    /// Degrees.
    pub d: Deg<D>,
    /// `|ĉ_k - c_k| <= e`.
    pub e: f64,
}

impl<const D: usize> Poly<D> {
    /// Differences of the coefficients in direction `dir` (the derivative's net without
    /// its factor `degree / h`), and their bound `(2 e + u max|Δ̂|)(1 + 10^-6)` (without
    /// the absolute slack [`TINY`], which the caller adds where it is used).
    pub fn diff(&self, dir: usize) -> (Vec<f64>, f64) {
        let d = self.d.minus_one(dir);
        // slabs of n + 1 blocks of `step` values (a block: one index in `dir`)
        let (step, n) = (self.d.stride(dir), self.d.0[dir]);
        let mut c = vec![0.0; d.len()];
        for (slab, out) in self.c.chunks_exact(step * (n + 1)).zip(c.chunks_exact_mut(step * n)) {
            for (k, o) in out.iter_mut().enumerate() {
                *o = slab[k + step] - slab[k];
            }
        }
        let e = (2.0 * self.e + U * amax(&c)) * (1.0 + 1e-6);
        (c, e)
    }
}

/// A sum of products of the same degree, `Σ s a b`, accumulated unnormalised; its error
/// bound is `Σ product_error` with `mul_roundings + Σ terms` roundings per term.
pub(crate) struct Acc<'a, const D: usize> {
    bn: &'a Binom,
    d: Deg<D>,
    c: Vec<f64>,
    terms: usize,
    /// `(max|a|, e_a, max|b|, e_b)` of every product.
    parts: Vec<[f64; 4]>,
}

impl<'a, const D: usize> Acc<'a, D> {
    /// An empty sum of degree `d`.
    pub fn new(bn: &'a Binom, d: Deg<D>) -> Self {
        Self { bn, d, c: vec![0.0; d.len()], terms: 0, parts: Vec::new() }
    }

    /// `+= s a b` (`s = ±1`); `a.d + b.d` must be the sum's degree.
    pub fn add(&mut self, a: &Poly<D>, b: &Poly<D>, s: f64) {
        debug_assert_eq!(a.d.plus(b.d), self.d);
        mul_add(self.bn, &a.c, a.d, &b.c, b.d, s, &mut self.c);
        self.terms += terms_per_coefficient(a.d);
        self.parts.push([amax(&a.c), a.e, amax(&b.c), b.e]);
    }

    /// Normalise (divide by the output binomials) and bound the error.
    pub fn finish(mut self) -> Poly<D> {
        normalize(self.bn, self.d, &mut self.c);
        let r = mul_roundings(D) + self.terms;
        let e = self.parts.iter().map(|p| product_error(p[0], p[1], p[2], p[3], r)).sum::<f64>() + TINY;
        Poly { c: self.c, d: self.d, e }
    }
}

/// `Σ_i s_i a_i b_i` for pairs of equal product degree.
pub(crate) fn sum_of_products<const D: usize>(bn: &Binom, pairs: &[(&Poly<D>, &Poly<D>, f64)]) -> Poly<D> {
    let mut acc = Acc::new(bn, pairs[0].0.d.plus(pairs[0].1.d));
    for &(a, b, s) in pairs {
        acc.add(a, b, s);
    }
    acc.finish()
}

/// Split at `1/2` in direction `dir` (de Casteljau) into the lower and upper halves.
/// `tmp` holds at least `d.len()` values. The coefficient array is a sequence of slabs of
/// `d_dir + 1` blocks (a block: the coefficients with one index in `dir`), and each de
/// Casteljau level averages whole blocks at once; in direction 0, whose blocks are single
/// values, the net is first transposed so that the levels run over contiguous memory.
/// Every value is the same `(a + b) / 2` of the same operands as one line at a time.
pub fn split<const D: usize>(c: &[f64], d: Deg<D>, dir: usize, lo: &mut [f64], hi: &mut [f64], tmp: &mut [f64]) {
    let n = d.0[dir];
    let len = d.len();
    if dir == 0 {
        let (w, h) = (n + 1, len / (n + 1));
        // t[k h + l] = c[l w + k]
        let t = &mut tmp[..len];
        for (l, row) in c[..len].chunks_exact(w).enumerate() {
            for (k, &v) in row.iter().enumerate() {
                t[k * h + l] = v;
            }
        }
        for r in 0..=n {
            for l in 0..h {
                lo[l * w + r] = t[l];
                hi[l * w + n - r] = t[(n - r) * h + l];
            }
            average_blocks(t, h, n - r);
        }
        return;
    }
    let block = d.stride(dir);
    let slab = block * (n + 1);
    for s in (0..len).step_by(slab) {
        let t = &mut tmp[..slab];
        t.copy_from_slice(&c[s..s + slab]);
        for r in 0..=n {
            lo[s + r * block..s + (r + 1) * block].copy_from_slice(&t[..block]);
            hi[s + (n - r) * block..s + (n - r + 1) * block].copy_from_slice(&t[(n - r) * block..(n - r + 1) * block]);
            average_blocks(t, block, n - r);
        }
    }
}

/// One de Casteljau level at `1/2` on blocks of `block` values: block `k` becomes the
/// mean of blocks `k` and `k + 1`, for `k < count`.
fn average_blocks(t: &mut [f64], block: usize, count: usize) {
    for k in 0..count {
        let (a, b) = t[k * block..(k + 2) * block].split_at_mut(block);
        for (x, y) in a.iter_mut().zip(b.iter()) {
            *x = 0.5 * (*x + *y);
        }
    }
}

/// Error bound of the children of a box with coefficients `c` known to `e` (bisected in
/// every direction).
pub(crate) fn split_error<const D: usize>(c: &[f64], d: Deg<D>, e: f64) -> f64 {
    e + gamma(d.total()) * amax(c) + TINY
}

/// The `2^D` children of a box bisected in every direction (direction 0 first), indexed
/// by bits: child `b` is the upper half in direction `dir` when bit `dir` of `b` is set.
pub(crate) fn children<const D: usize>(c: &[f64], d: Deg<D>, tmp: &mut [f64]) -> Vec<Vec<f64>> {
    let n = d.len();
    let mut cur: Vec<Vec<f64>> = vec![c.to_vec()];
    for dir in 0..D {
        let mut next = Vec::with_capacity(2 * cur.len());
        for x in &cur {
            let (mut lo, mut hi) = (vec![0.0; n], vec![0.0; n]);
            split(x, d, dir, &mut lo, &mut hi, tmp);
            next.push(lo);
            next.push(hi);
        }
        cur = next;
    }
    // in `cur` direction 0 is the most significant bit
    let mut out = vec![Vec::new(); cur.len()];
    for (i, v) in cur.into_iter().enumerate() {
        let b = (0..D).fold(0, |b, dir| b | (((i >> (D - 1 - dir)) & 1) << dir));
        out[b] = v;
    }
    out
}

/// Value at the local point with coordinates given as pairs `(1 - s, s)` per direction
/// (de Casteljau along direction 0 on every line, then along direction 1, ...); `tmp`
/// holds at least `d.len()` values.
pub fn eval<const D: usize>(c: &[f64], d: Deg<D>, s: [[f64; 2]; D], tmp: &mut [f64]) -> f64 {
    let mut len = d.len();
    let buf = &mut tmp[..len];
    buf.copy_from_slice(&c[..len]);
    for (dir, w) in s.iter().enumerate() {
        let n = d.0[dir];
        len /= n + 1;
        for line in 0..len {
            let x = &mut buf[line * (n + 1)..(line + 1) * (n + 1)];
            for r in 1..=n {
                for k in 0..=n - r {
                    x[k] = w[0] * x[k] + w[1] * x[k + 1];
                }
            }
            buf[line] = buf[line * (n + 1)];
        }
    }
    buf[0]
}

/// Error bound of [`eval`] when the coefficients are known to `e` and the weights
/// `(1 - s, s)` to a relative `θ_k` each (`k = 0`: exact, as at dyadic points).
pub(crate) fn eval_error<const D: usize>(c: &[f64], d: Deg<D>, e: f64, k: usize) -> f64 {
    // per level: two products (each with its weight's θ_k) and one addition
    e + gamma((k + 3) * d.total()) * amax(c) + TINY
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Lcg;

    fn random<const D: usize>(rng: &mut Lcg, d: Deg<D>) -> Poly<D> {
        Poly { c: (0..d.len()).map(|_| rng.uniform() - 0.5).collect(), d, e: 0.0 }
    }

    fn at<const D: usize>(p: &Poly<D>, s: [f64; D]) -> f64 {
        let mut tmp = vec![0.0; p.d.len()];
        eval(&p.c, p.d, s.map(|x| [1.0 - x, x]), &mut tmp)
    }

    #[test]
    fn subdivision_reproduces_the_polynomial() {
        let mut rng = Lcg::new(5);
        let d = Deg([3, 5]);
        let c: Vec<f64> = (0..d.len()).map(|_| rng.uniform() - 0.5).collect();
        let mut tmp = vec![0.0; 64];
        let (mut l, mut r) = (vec![0.0; d.len()], vec![0.0; d.len()]);
        split(&c, d, 0, &mut l, &mut r, &mut tmp);
        let (mut lo, mut hi) = (vec![0.0; d.len()], vec![0.0; d.len()]);
        split(&r, d, 1, &mut lo, &mut hi, &mut tmp);
        for _ in 0..20 {
            let (s, t) = (rng.uniform(), rng.uniform());
            let ps = 0.5 + 0.5 * s;
            let a = eval(&c, d, [[1.0 - ps, ps], [1.0 - 0.5 * t, 0.5 * t]], &mut tmp);
            let b = eval(&lo, d, [[1.0 - s, s], [1.0 - t, t]], &mut tmp);
            assert!((a - b).abs() < 1e-14);
        }
    }

    #[test]
    fn binomials_are_exact_integers() {
        let bn = Binom::new(40);
        assert_eq!(bn.get(11, 5), 462.0);
        assert_eq!(bn.get(40, 20), 137_846_528_820.0);
        for n in 0..=40 {
            let row_sum: f64 = (0..=n).map(|k| bn.get(n, k)).sum();
            assert_eq!(row_sum, 2f64.powi(n as i32));
        }
    }

    #[test]
    fn gamma_bounds_the_classic_constant() {
        for n in [1usize, 10, 1000, 100_000] {
            let nu = n as f64 * U;
            assert!(gamma(n) >= nu / (1.0 - nu));
        }
    }

    #[test]
    fn products_and_differences_are_the_polynomials() {
        let mut rng = Lcg::new(3);
        let bn = Binom::new(20);
        let (a, b) = (random(&mut rng, Deg([2, 1, 3])), random(&mut rng, Deg([1, 3, 2])));
        let ab = sum_of_products(&bn, &[(&a, &b, 1.0)]);
        assert_eq!(ab.d, Deg([3, 4, 5]));
        for _ in 0..20 {
            let s = [rng.uniform(), rng.uniform(), rng.uniform()];
            assert!((at(&ab, s) - at(&a, s) * at(&b, s)).abs() < 1e-14);
            // derivative in direction 1: degree times the differences' polynomial
            let h = 1e-6;
            let (mut lo, mut hi) = (s, s);
            lo[1] -= h;
            hi[1] += h;
            let fd = (at(&a, hi) - at(&a, lo)) / (2.0 * h);
            let (c, _) = a.diff(1);
            assert!((fd - 1.0 * at(&Poly { c, d: a.d.minus_one(1), e: 0.0 }, s)).abs() < 1e-8);
        }
        assert!(ab.e > 0.0 && ab.e < 1e-13);
        // the plane's order of multiplication: the same polynomial
        let (a, b) = (random(&mut rng, Deg([2, 3])), random(&mut rng, Deg([3, 1])));
        let ab = sum_of_products(&bn, &[(&a, &b, 1.0)]);
        for _ in 0..20 {
            let s = [rng.uniform(), rng.uniform()];
            assert!((at(&ab, s) - at(&a, s) * at(&b, s)).abs() < 1e-14);
        }
    }

    #[test]
    fn children_reproduce_the_polynomial() {
        let mut rng = Lcg::new(7);
        let p = random(&mut rng, Deg([3, 2, 2]));
        let mut tmp = vec![0.0; p.d.len()];
        let kids = children(&p.c, p.d, &mut tmp);
        for (b, kid) in kids.iter().enumerate() {
            let child = Poly { c: kid.clone(), d: p.d, e: 0.0 };
            for _ in 0..5 {
                let s = [rng.uniform(), rng.uniform(), rng.uniform()];
                let parent = std::array::from_fn(|d| 0.5 * (s[d] + ((b >> d) & 1) as f64));
                assert!((at(&child, s) - at(&p, parent)).abs() < 1e-14, "child {b}");
            }
        }
    }
}
