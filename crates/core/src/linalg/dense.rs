//! Dense LU with partial pivoting and dense Cholesky for the small systems of tiny bases.
//!
//! `P A = L U` (Doolittle, row pivoting: at step `k` the row with the largest `|a_ik|`,
//! `i >= k`, is swapped into place; `L` unit lower triangular, stored below the diagonal
//! of the same array as `U`). A system of a few dozen unknowns (a G+Smo input basis of 9
//! to 36 functions has 2 to 64) costs `2n³/3` flops, a few microseconds, where a sparse
//! LU's symbolic analysis and its dispatch alone cost tens of microseconds:
//! [`LinearSolver`](super::linsolve::LinearSolver) factorizes systems up to
//! [`DENSE_LIMIT`] unknowns here (LU, and Cholesky for the symmetric definite ones: the
//! Hessians of the Winslow functional, eq. 16, on the C0 route of tiny bases).

use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;

/// Largest system that [`LinearSolver`](super::linsolve::LinearSolver) factorizes
/// densely (`n x n` storage: 32 KiB at 64 unknowns), the limit up to which the automatic
/// choice factorizes at all ([`AUTO_LU_LIMIT`](super::linsolve::AUTO_LU_LIMIT)). Measured
/// on the EGG solves of the shared G+Smo geometries on their input bases (a Newton step:
/// assembly, factorization, solve, line search): lake, 32 unknowns, 85 -> 58 µs per step
/// and 334 -> 171 µs for the first (faer's symbolic analysis); cooks_membrane, 2
/// unknowns, 8 -> 4.6 µs (time stamps around each step, a throwaway probe;
/// BENCHMARKS.md, "Same-basis race against G+Smo").
pub(crate) const DENSE_LIMIT: usize = 64;

/// The factors `P A = L U` of a square matrix, row-major.
#[derive(Debug, Clone, Default)]
pub(crate) struct DenseLu {
    n: usize,
    /// `L` (strictly below the diagonal, unit diagonal implied) and `U` (on and above).
    lu: Vec<f64>,
    /// `perm[k]`: the row of `A` in row `k` of `P A`.
    perm: Vec<usize>,
}

impl DenseLu {
    /// Factorize the square `a` (CSR; entries not stored are zero), reusing this storage.
    ///
    /// Errors: [`Error::LinearSolver`] when `a` is not square, or a pivot is zero or not
    /// finite (`a` singular to working precision, or holding NaN).
    pub fn factor(&mut self, a: &Csr) -> Result<()> {
        if a.nrows != a.ncols {
            return Err(Error::LinearSolver(format!("dense LU of a {} x {} matrix", a.nrows, a.ncols)));
        }
        let n = a.nrows;
        self.n = n;
        self.lu.clear();
        self.lu.resize(n * n, 0.0);
        for i in 0..n {
            for (j, v) in a.row(i) {
                self.lu[i * n + j] += v;
            }
        }
        self.perm.clear();
        self.perm.extend(0..n);
        let lu = &mut self.lu;
        for k in 0..n {
            let (mut p, mut big) = (k, lu[k * n + k].abs());
            for i in k + 1..n {
                let v = lu[i * n + k].abs();
                if v > big {
                    (p, big) = (i, v);
                }
            }
            if big == 0.0 || !big.is_finite() {
                return Err(Error::LinearSolver(format!(
                    "dense LU: pivot {k} of {n} is {big} (singular or not finite)"
                )));
            }
            if p != k {
                for j in 0..n {
                    lu.swap(k * n + j, p * n + j);
                }
                self.perm.swap(k, p);
            }
            let (top, rest) = lu.split_at_mut((k + 1) * n);
            let pivot_row = &top[k * n..];
            let inv = 1.0 / pivot_row[k];
            for row in rest.chunks_exact_mut(n) {
                let l = row[k] * inv;
                row[k] = l;
                if l != 0.0 {
                    for (r, u) in row[k + 1..].iter_mut().zip(&pivot_row[k + 1..]) {
                        *r -= l * u;
                    }
                }
            }
        }
        Ok(())
    }

    /// `x = A^{-1} b`: forward substitution with `L` on `P b`, back substitution with `U`.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        assert_eq!(b.len(), n, "right-hand side of length {} for a system of {n}", b.len());
        let mut x: Vec<f64> = self.perm.iter().map(|&i| b[i]).collect();
        for i in 0..n {
            let row = &self.lu[i * n..i * n + i];
            let s: f64 = row.iter().zip(&x[..i]).map(|(l, y)| l * y).sum();
            x[i] -= s;
        }
        for i in (0..n).rev() {
            let row = &self.lu[i * n..(i + 1) * n];
            let s: f64 = row[i + 1..].iter().zip(&x[i + 1..]).map(|(u, y)| u * y).sum();
            x[i] = (x[i] - s) / row[i];
        }
        x
    }
}

/// The Cholesky factor `A = L Lᵀ` of a symmetric positive definite matrix (or of `-A`,
/// see [`DenseCholesky::factor`]), `L` lower triangular, row-major.
#[derive(Debug, Clone, Default)]
pub(crate) struct DenseCholesky {
    n: usize,
    l: Vec<f64>,
}

impl DenseCholesky {
    /// Factorize `sign * a` (`sign` = 1 or -1; `a` symmetric, its entries on and above
    /// the diagonal are read, as the sparse factorization reads them), reusing this
    /// storage: `l_jj = sqrt(a_jj - Σ_{k<j} l_jk²)`, `l_ij = (a_ij - Σ_{k<j} l_ik l_jk) /
    /// l_jj`.
    ///
    /// Errors: [`Error::LinearSolver`] when a pivot is not positive (the matrix is not
    /// positive definite, to working precision) or not finite: exactly when the sparse
    /// Cholesky fails, so a minimisation's Newton solver modifies its Hessian alike.
    pub fn factor(&mut self, a: &Csr, sign: f64) -> Result<()> {
        if a.nrows != a.ncols {
            return Err(Error::LinearSolver(format!("dense Cholesky of a {} x {} matrix", a.nrows, a.ncols)));
        }
        let n = a.nrows;
        self.n = n;
        let l = &mut self.l;
        l.clear();
        l.resize(n * n, 0.0);
        for r in 0..n {
            for (c, v) in a.row(r) {
                if c >= r {
                    l[c * n + r] += sign * v;
                }
            }
        }
        for j in 0..n {
            let row_j = &mut l[j * n..(j + 1) * n];
            let d = row_j[j] - row_j[..j].iter().map(|x| x * x).sum::<f64>();
            if !(d > 0.0 && d.is_finite()) {
                return Err(Error::LinearSolver(format!(
                    "Cholesky: matrix not positive definite (pivot {j} of {n} is {d})"
                )));
            }
            let ljj = d.sqrt();
            row_j[j] = ljj;
            let (top, below) = l.split_at_mut((j + 1) * n);
            let row_j = &top[j * n..j * n + j];
            for row_i in below.chunks_exact_mut(n) {
                let s: f64 = row_i[..j].iter().zip(row_j).map(|(a, b)| a * b).sum();
                row_i[j] = (row_i[j] - s) / ljj;
            }
        }
        Ok(())
    }

    /// Size of the factorized system.
    pub fn size(&self) -> usize {
        self.n
    }

    /// `L`, row-major `n x n` (the upper triangle zero).
    pub fn factor_values(&self) -> &[f64] {
        &self.l
    }

    /// Overwrite each length-`n` column of `x` with `(sign A)^{-1}` times it: forward
    /// substitution with `L`, back substitution with `Lᵀ`.
    pub fn solve_columns(&self, x: &mut [f64]) {
        let n = self.n;
        assert!(n > 0 && x.len().is_multiple_of(n), "{} values for columns of {n}", x.len());
        for col in x.chunks_exact_mut(n) {
            for i in 0..n {
                let row = &self.l[i * n..i * n + i];
                let s: f64 = row.iter().zip(&col[..i]).map(|(a, b)| a * b).sum();
                col[i] = (col[i] - s) / self.l[i * n + i];
            }
            for i in (0..n).rev() {
                let mut s = col[i];
                for k in i + 1..n {
                    s -= self.l[k * n + i] * col[k];
                }
                col[i] = s / self.l[i * n + i];
            }
        }
    }
}

/// `out[a][b] = sum_k w[k][a] t[k][b]` for `nloc x nloc` element blocks (`w`, `t` with
/// `nqp` rows of `nloc`): the quadrature sum of an element matrix as one matrix
/// product, each output row accumulated in registers for the common sizes.
pub(crate) fn element_product(out: &mut [f64], w: &[f64], t: &[f64], nloc: usize) {
    fn fixed<const N: usize>(out: &mut [f64], w: &[f64], t: &[f64]) {
        for (a, row) in out.chunks_exact_mut(N).enumerate() {
            let mut acc = [0.0f64; N];
            for (wk, tk) in w.chunks_exact(N).zip(t.chunks_exact(N)) {
                let wa = wk[a];
                let tk: &[f64; N] = tk.try_into().expect("chunk of N");
                for (r, v) in acc.iter_mut().zip(tk) {
                    *r += wa * v;
                }
            }
            row.copy_from_slice(&acc);
        }
    }
    match nloc {
        9 => fixed::<9>(out, w, t),
        16 => fixed::<16>(out, w, t),
        25 => fixed::<25>(out, w, t),
        36 => fixed::<36>(out, w, t),
        _ => {
            out.fill(0.0);
            for (wk, tk) in w.chunks_exact(nloc).zip(t.chunks_exact(nloc)) {
                for (row, &wa) in out.chunks_exact_mut(nloc).zip(wk) {
                    for (r, v) in row.iter_mut().zip(tk) {
                        *r += wa * v;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Lcg;

    fn csr(n: usize, dense: &[f64]) -> Csr {
        let mut row_ptr = vec![0];
        let (mut col_idx, mut values) = (Vec::new(), Vec::new());
        for i in 0..n {
            for j in 0..n {
                if dense[i * n + j] != 0.0 {
                    col_idx.push(j);
                    values.push(dense[i * n + j]);
                }
            }
            row_ptr.push(col_idx.len());
        }
        Csr { nrows: n, ncols: n, row_ptr, col_idx, values }
    }

    /// A nonsymmetric matrix whose first pivot is zero (pivoting is needed) solves
    /// `A x = b` for a known `x` to rounding, and the residual of a random system is at
    /// rounding level.
    #[test]
    fn solves_with_pivoting() {
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 4.0];
        let x = [1.0, -2.0, 0.5];
        let b: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[i * 3 + j] * x[j]).sum()).collect();
        let mut lu = DenseLu::default();
        lu.factor(&csr(3, &a)).unwrap();
        let y = lu.solve(&b);
        for (u, v) in y.iter().zip(x) {
            assert!((u - v).abs() < 1e-15, "{y:?}");
        }
        // a 40 x 40 system with a pseudo-random nonsymmetric matrix
        let n = 40;
        let mut rng = Lcg::new(12345);
        let mut rnd = || rng.uniform() - 0.5;
        let a: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
        let b: Vec<f64> = (0..n).map(|_| rnd()).collect();
        lu.factor(&csr(n, &a)).unwrap();
        let x = lu.solve(&b);
        let r = (0..n).map(|i| (b[i] - (0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>()).abs()).fold(0.0, f64::max);
        assert!(r < 1e-12, "residual {r}");
    }

    /// Cholesky of a symmetric positive definite matrix (and of the negative of one,
    /// `sign = -1`) solves two columns at once to rounding; an indefinite matrix is
    /// refused with a typed error.
    #[test]
    fn cholesky_solves_and_refuses_indefinite() {
        let n = 30;
        // A = B Bᵀ + n I with B pseudo-random
        let mut rng = Lcg::new(777);
        let mut rnd = || rng.uniform() - 0.5;
        let b: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
        let a: Vec<f64> = (0..n * n)
            .map(|ij| {
                let (i, j) = (ij / n, ij % n);
                (0..n).map(|k| b[i * n + k] * b[j * n + k]).sum::<f64>() + if i == j { n as f64 } else { 0.0 }
            })
            .collect();
        let x: Vec<f64> = (0..2 * n).map(|_| rnd()).collect();
        let rhs: Vec<f64> = (0..2 * n)
            .map(|k| {
                let (c, i) = (k / n, k % n);
                (0..n).map(|j| a[i * n + j] * x[c * n + j]).sum()
            })
            .collect();
        let mut llt = DenseCholesky::default();
        llt.factor(&csr(n, &a), 1.0).unwrap();
        let mut y = rhs.clone();
        llt.solve_columns(&mut y);
        let err = y.iter().zip(&x).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max);
        assert!(err < 1e-13, "error {err}");
        // -A with sign -1: the same factor
        let neg: Vec<f64> = a.iter().map(|v| -v).collect();
        llt.factor(&csr(n, &neg), -1.0).unwrap();
        let mut z = rhs.clone();
        llt.solve_columns(&mut z);
        assert!(z.iter().zip(&y).all(|(u, v)| u == v));
        // indefinite: diag(1, -1)
        assert!(matches!(llt.factor(&csr(2, &[1.0, 0.0, 0.0, -1.0]), 1.0), Err(Error::LinearSolver(_))));
        assert!(matches!(llt.factor(&csr(2, &[1.0, 0.0, 0.0, 1.0]), -1.0), Err(Error::LinearSolver(_))));
    }

    /// A singular matrix and one holding NaN are refused with a typed error.
    #[test]
    fn refuses_singular_and_nan() {
        let mut lu = DenseLu::default();
        let singular = [1.0, 2.0, 2.0, 4.0];
        assert!(matches!(lu.factor(&csr(2, &singular)), Err(Error::LinearSolver(_))));
        let nan = [1.0, 0.0, f64::NAN, 1.0];
        assert!(matches!(lu.factor(&csr(2, &nan)), Err(Error::LinearSolver(_))));
    }
}
