//! A prolongation of tensor form `P = P_1 ⊗ P_0` between two grids of unknowns
//! numbered with direction 0 fastest (unknown `k = j n_0 + i`), held as its two 1D
//! factors: the spline hierarchy's knot insertion (`crate::discrete::transfers`) is of
//! this form, and its 2D matrix is never stored.
//!
//! `y = P x` is two 1D passes, `T = X P_0^T` (each coarse row of `x` prolonged in
//! direction 0) and `Y = P_1 T` (the columns in direction 1), `X` the coarse vector as an
//! `n^c_1 x n^c_0` array; the restriction `P^T r` is the same with the transposes. The
//! rows of `P` and `P^T` for the Galerkin product are generated from the factors:
//! `P_{(j, i), (J, I)} = (P_1)_{jJ} (P_0)_{iI}`.

use rayon::prelude::*;

use crate::linalg::sparse::Csr;

/// `P = P_1 ⊗ P_0` (see the module documentation).
#[derive(Debug, Clone, Default)]
pub(crate) struct TensorProlongation {
    /// `[P_0, P_1]`, each `n^f_d x n^c_d`.
    pub(super) factors: [Csr; 2],
    /// `[P_0^T, P_1^T]`.
    pub(super) transposes: [Csr; 2],
}

/// Rows per parallel task of a pass.
const ROWS: usize = 16;

impl TensorProlongation {
    /// `P = p1 ⊗ p0`.
    pub fn new(p0: Csr, p1: Csr) -> Self {
        let transposes = [p0.transpose(), p1.transpose()];
        Self { factors: [p0, p1], transposes }
    }

    /// Fine unknowns `n^f_0 n^f_1`.
    pub fn nrows(&self) -> usize {
        self.factors[0].nrows * self.factors[1].nrows
    }

    /// Coarse unknowns `n^c_0 n^c_1`.
    pub fn ncols(&self) -> usize {
        self.factors[0].ncols * self.factors[1].ncols
    }

    /// `y = P x` (two 1D passes).
    pub fn prolong(&self, x: &[f64], y: &mut [f64]) {
        kron_apply(&self.factors, x, y);
    }

    /// `y = P^T x` (two 1D passes).
    pub fn restrict(&self, x: &[f64], y: &mut [f64]) {
        kron_apply(&self.transposes, x, y);
    }

    /// Row `k` of `P`: `(column, value)` in increasing column order.
    pub fn row(&self, k: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        kron_row(&self.factors, k)
    }

    /// Row `k` of `P^T` (column `k` of `P`) in increasing column order.
    pub fn row_of_transpose(&self, k: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        kron_row(&self.transposes, k)
    }

    /// The 2D matrix `P_1 ⊗ P_0` (for tests).
    #[cfg(test)]
    pub fn matrix(&self) -> Csr {
        self.factors[1].kron(&self.factors[0])
    }
}

impl From<[Csr; 2]> for TensorProlongation {
    /// `P = p_1 ⊗ p_0` from `[p_0, p_1]`.
    fn from([p0, p1]: [Csr; 2]) -> Self {
        Self::new(p0, p1)
    }
}

/// Row `k = j m_0 + i` of `a_1 ⊗ a_0` (`m_0` the rows of `a_0`): `a_1[j, J] a_0[i, I]` at
/// column `J n_0 + I`, `J` outer, as [`Csr::kron`] orders and multiplies them.
fn kron_row(a: &[Csr; 2], k: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
    let m0 = a[0].nrows;
    let n0 = a[0].ncols;
    let (j, i) = (k / m0, k % m0);
    a[1].row(j).flat_map(move |(jj, v1)| a[0].row(i).map(move |(ii, v0)| (jj * n0 + ii, v1 * v0)))
}

/// `y = (a_1 ⊗ a_0) x` in two passes: `t = X a_0^T` (`n_1 x m_0`), `Y = a_1 t`.
fn kron_apply(a: &[Csr; 2], x: &[f64], y: &mut [f64]) {
    let (m0, n0, m1, n1) = (a[0].nrows, a[0].ncols, a[1].nrows, a[1].ncols);
    debug_assert_eq!(x.len(), n0 * n1);
    debug_assert_eq!(y.len(), m0 * m1);
    let mut t = vec![0.0; n1 * m0];
    t.par_chunks_mut(ROWS * m0).enumerate().for_each(|(c, ts)| {
        for (r, trow) in ts.chunks_mut(m0).enumerate() {
            let xrow = &x[(c * ROWS + r) * n0..][..n0];
            for (i, ti) in trow.iter_mut().enumerate() {
                *ti = a[0].row(i).map(|(ii, v)| v * xrow[ii]).sum();
            }
        }
    });
    y.par_chunks_mut(ROWS * m0).enumerate().for_each(|(c, ys)| {
        for (r, yrow) in ys.chunks_mut(m0).enumerate() {
            yrow.fill(0.0);
            for (jj, v) in a[1].row(c * ROWS + r) {
                for (yi, ti) in yrow.iter_mut().zip(&t[jj * m0..][..m0]) {
                    *yi += v * ti;
                }
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Lcg;

    /// A random sparse `m x n` matrix with a few entries per row.
    fn random(m: usize, n: usize, seed: u64) -> Csr {
        let mut rng = Lcg::new(seed);
        let mut t = Vec::new();
        for i in 0..m {
            for _ in 0..3 {
                let j = ((rng.uniform() * n as f64) as usize).min(n - 1);
                t.push((i, j, rng.uniform() - 0.5));
            }
        }
        Csr::from_triplets(m, n, &t)
    }

    /// The two 1D passes equal the stored 2D matrix `P` and its transpose times a vector
    /// to rounding, and the generated rows are those of the stored matrices.
    #[test]
    fn passes_and_rows_equal_the_stored_matrix() {
        let t = TensorProlongation::new(random(23, 11, 1), random(17, 9, 2));
        let (p, pt) = (t.matrix(), t.matrix().transpose());
        assert_eq!((t.nrows(), t.ncols()), (p.nrows, p.ncols));
        let mut rng = Lcg::new(3);
        let xc: Vec<f64> = (0..t.ncols()).map(|_| rng.uniform() - 0.5).collect();
        let xf: Vec<f64> = (0..t.nrows()).map(|_| rng.uniform() - 0.5).collect();
        let (mut y, mut z) = (vec![0.0; t.nrows()], vec![0.0; t.ncols()]);
        t.prolong(&xc, &mut y);
        t.restrict(&xf, &mut z);
        for (got, want) in [(y, p.apply(&xc)), (z, pt.apply(&xf))] {
            let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let err = got.iter().zip(&want).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(err <= 1e-14 * scale, "{err} against {scale}");
        }
        for k in 0..t.nrows() {
            assert!(t.row(k).eq(p.row(k)), "row {k} of P");
        }
        for k in 0..t.ncols() {
            assert!(t.row_of_transpose(k).eq(pt.row(k)), "row {k} of P^T");
        }
    }

    /// The Galerkin operator from the generated rows, without the intermediate `A P`,
    /// equals `P^T A P` of the stored matrices to rounding, with the same pattern.
    #[test]
    fn galerkin_equals_the_stored_triple_product() {
        let t = TensorProlongation::new(random(23, 11, 4), random(17, 9, 5));
        let a = random(t.nrows(), t.nrows(), 6);
        let p = t.matrix();
        let want = p.transpose().matmul(&a).matmul(&p);
        let got = super::super::galerkin(&a, &t);
        assert_eq!((got.row_ptr.clone(), got.col_idx.clone()), (want.row_ptr.clone(), want.col_idx.clone()));
        let scale = want.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = got.values.iter().zip(&want.values).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(err <= 1e-13 * scale, "{err} against {scale}");
    }
}
