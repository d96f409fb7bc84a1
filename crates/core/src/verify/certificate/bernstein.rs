//! Tensor Bernstein polynomials in floating point with a rigorous bound of their
//! rounding error (running error analysis with the standard constants of Higham,
//! *Accuracy and Stability of Numerical Algorithms*, §3.1).
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
//! - product (`B_i^m B_j^n = binom(m,i) binom(n,j) / binom(m+n,i+j) B_{i+j}^{m+n}`, the
//!   weights `λ` of one output coefficient are positive and sum to one):
//!   `e_ab = e_a max|b̂| + (max|â| + e_a) e_b + γ_r max|â| max|b̂|`, with `r` the roundings
//!   of one term (binomial products, the accumulation, the final division);
//! - de Casteljau bisection at `1/2` (halving is exact; `du + dv` additions per
//!   coefficient, convex weights): `e_child = e_parent + γ_{du+dv} max|ĉ_parent|`;
//! - evaluation at a point whose local coordinates `s`, `1 - s` are known with relative
//!   error `θ_k` (de Casteljau, convex weights, three roundings per level):
//!   `e = e_coeffs + γ_{(k+3)(du+dv)} max|ĉ|`.
//!
//! Underflow (possible only far below the element's scale, since every element's net is
//! scaled to unit size by a power of two, which is exact) adds at most `2^-1075` per
//! multiplication; the absolute term [`TINY`] added to every bound covers it with a wide
//! margin. `γ_n` itself is evaluated with a relative slack of `10^-6`, which covers the
//! rounding of the bound's own evaluation (`n u < 10^-10` for every `n` used here).

/// Unit roundoff of `f64`.
pub const U: f64 = f64::EPSILON / 2.0;

/// Absolute slack added to every error bound: covers underflow (see the module doc).
pub const TINY: f64 = 1e-290;

/// `γ_n = n u / (1 - n u)`, rounded up (relative slack `10^-6`, valid for `n u < 10^-7`).
pub fn gamma(n: usize) -> f64 {
    let nu = n as f64 * U;
    debug_assert!(nu < 1e-7);
    nu * (1.0 + 1e-6)
}

/// Largest magnitude of a slice.
pub fn amax(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// A tensor Bernstein polynomial of degree `d = [du, dv]`, coefficient `(k, l)` at
/// `l * (du + 1) + k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Deg(pub [usize; 2]);

impl Deg {
    /// Number of coefficients.
    pub fn len(self) -> usize {
        (self.0[0] + 1) * (self.0[1] + 1)
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
pub struct Binom {
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
}

/// Roundings of one term of [`mul_add`]: four binomial products, the product of the two
/// coefficients, and the final division of [`normalize`] (the accumulation is counted by
/// the caller, see [`terms_per_coefficient`]).
pub const MUL_ROUNDINGS: usize = 6;

/// At most how many terms one output coefficient of a product of degrees `da`, `db`
/// receives (each `(k1, l1)` of `a` at most once).
pub fn terms_per_coefficient(da: Deg) -> usize {
    da.len()
}

/// `out += s * a * b` (Bernstein product, unnormalised: call [`normalize`] once after
/// all products of the same degree are accumulated); `s = ±1`.
pub fn mul_add(bn: &Binom, a: &[f64], da: Deg, b: &[f64], db: Deg, s: f64, out: &mut [f64]) {
    let [au, av] = da.0;
    let [bu, bv] = db.0;
    let nu = au + bu;
    for l1 in 0..=av {
        for k1 in 0..=au {
            let x = a[l1 * (au + 1) + k1] * bn.get(au, k1) * bn.get(av, l1) * s;
            if x == 0.0 {
                continue;
            }
            for l2 in 0..=bv {
                let row = (l1 + l2) * (nu + 1) + k1;
                let y = x * bn.get(bv, l2);
                for k2 in 0..=bu {
                    out[row + k2] += y * b[l2 * (bu + 1) + k2] * bn.get(bu, k2);
                }
            }
        }
    }
}

/// Divide the accumulated products by `binom(nu, k) binom(nv, l)`.
pub fn normalize(bn: &Binom, d: Deg, out: &mut [f64]) {
    let [nu, nv] = d.0;
    for l in 0..=nv {
        for k in 0..=nu {
            out[l * (nu + 1) + k] /= bn.get(nu, k) * bn.get(nv, l);
        }
    }
}

/// Error bound of one product term `a b` (see the module doc): `a` known to `ea`, `b` to
/// `eb`, `r` roundings per term.
pub fn product_error(amax_a: f64, ea: f64, amax_b: f64, eb: f64, r: usize) -> f64 {
    (ea * amax_b + (amax_a + ea) * eb + gamma(r) * amax_a * amax_b) * (1.0 + 1e-6)
}

/// Split at `u = 1/2` (de Casteljau) into the left and right halves. `tmp` holds at
/// least `d.len()` values: the rows run side by side (the net transposed, so that each
/// de Casteljau level is one pass over contiguous memory); every value is the same
/// `(a + b) / 2` of the same operands as one row at a time.
pub fn split_u(c: &[f64], d: Deg, left: &mut [f64], right: &mut [f64], tmp: &mut [f64]) {
    let [du, dv] = d.0;
    let (w, h) = (du + 1, dv + 1);
    // t[k h + l] = c[l w + k]
    let t = &mut tmp[..w * h];
    for (l, row) in c[..w * h].chunks_exact(w).enumerate() {
        for (k, &v) in row.iter().enumerate() {
            t[k * h + l] = v;
        }
    }
    for r in 0..=du {
        for l in 0..h {
            left[l * w + r] = t[l];
            right[l * w + du - r] = t[(du - r) * h + l];
        }
        for k in 0..du - r {
            let (a, b) = t[k * h..(k + 2) * h].split_at_mut(h);
            for (x, y) in a.iter_mut().zip(b.iter()) {
                *x = 0.5 * (*x + *y);
            }
        }
    }
}

/// Split at `v = 1/2`; `tmp` holds at least `d.len()` values (whole rows of the net
/// are averaged at once).
pub fn split_v(c: &[f64], d: Deg, left: &mut [f64], right: &mut [f64], tmp: &mut [f64]) {
    let [du, dv] = d.0;
    let (w, h) = (du + 1, dv + 1);
    let t = &mut tmp[..w * h];
    t.copy_from_slice(&c[..w * h]);
    for r in 0..=dv {
        left[r * w..(r + 1) * w].copy_from_slice(&t[..w]);
        right[(dv - r) * w..(dv - r + 1) * w].copy_from_slice(&t[(dv - r) * w..(dv - r + 1) * w]);
        for l in 0..dv - r {
            let (a, b) = t[l * w..(l + 2) * w].split_at_mut(w);
            for (x, y) in a.iter_mut().zip(b.iter()) {
                *x = 0.5 * (*x + *y);
            }
        }
    }
}

/// Error bound of the four children of a box with coefficients `c` known to `e`.
pub fn split_error(c: &[f64], d: Deg, e: f64) -> f64 {
    e + gamma(d.0[0] + d.0[1]) * amax(c) + TINY
}

/// Value at the local point with coordinates given as pairs `(1 - s, s)`, `(1 - t, t)`
/// (de Casteljau in `u` per row, then in `v`).
pub fn eval(c: &[f64], d: Deg, s: [f64; 2], t: [f64; 2], tmp: &mut [f64]) -> f64 {
    let [du, dv] = d.0;
    let w = du + 1;
    let (col, row) = tmp.split_at_mut(dv + 1);
    for l in 0..=dv {
        row[..w].copy_from_slice(&c[l * w..(l + 1) * w]);
        for r in 1..=du {
            for k in 0..=du - r {
                row[k] = s[0] * row[k] + s[1] * row[k + 1];
            }
        }
        col[l] = row[0];
    }
    for r in 1..=dv {
        for l in 0..=dv - r {
            col[l] = t[0] * col[l] + t[1] * col[l + 1];
        }
    }
    col[0]
}

/// Error bound of [`eval`] when the coefficients are known to `e` and the weights
/// `(1 - s, s)`, `(1 - t, t)` to a relative `θ_k` each (`k = 0`: exact, as at dyadic
/// points).
pub fn eval_error(c: &[f64], d: Deg, e: f64, k: usize) -> f64 {
    // per level: two products (each with its weight's θ_k) and one addition
    e + gamma((k + 3) * (d.0[0] + d.0[1])) * amax(c) + TINY
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Lcg;

    #[test]
    fn subdivision_reproduces_the_polynomial() {
        let mut rng = Lcg::new(5);
        let d = Deg([3, 5]);
        let c: Vec<f64> = (0..d.len()).map(|_| rng.uniform() - 0.5).collect();
        let mut tmp = vec![0.0; 64];
        let (mut l, mut r) = (vec![0.0; d.len()], vec![0.0; d.len()]);
        split_u(&c, d, &mut l, &mut r, &mut tmp);
        let (mut lo, mut hi) = (vec![0.0; d.len()], vec![0.0; d.len()]);
        split_v(&r, d, &mut lo, &mut hi, &mut tmp);
        for _ in 0..20 {
            let (s, t) = (rng.uniform(), rng.uniform());
            let ps = 0.5 + 0.5 * s;
            let a = eval(&c, d, [1.0 - ps, ps], [1.0 - 0.5 * t, 0.5 * t], &mut tmp);
            let b = eval(&lo, d, [1.0 - s, s], [1.0 - t, t], &mut tmp);
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
}
