//! Compressed sparse row matrices: prolongation operators, assembled operators and
//! their fixed sparsity patterns. Factorizations go through faer.

use rayon::prelude::*;

/// A real CSR matrix with sorted, unique column indices per row.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Csr {
    /// Number of rows.
    pub nrows: usize,
    /// Number of columns.
    pub ncols: usize,
    /// Row `i` occupies `row_ptr[i]..row_ptr[i+1]` of `col_idx` and `values`.
    pub row_ptr: Vec<usize>,
    /// Column index of each stored entry.
    pub col_idx: Vec<usize>,
    /// Value of each stored entry.
    pub values: Vec<f64>,
}

impl Csr {
    /// Build from `(row, col, value)` triplets; duplicates are summed.
    pub(crate) fn from_triplets(nrows: usize, ncols: usize, triplets: &[(usize, usize, f64)]) -> Self {
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); nrows];
        for &(i, j, v) in triplets {
            debug_assert!(i < nrows && j < ncols);
            rows[i].push((j, v));
        }
        Self::from_rows(ncols, rows)
    }

    /// Build from per-row lists of `(col, value)`; duplicates are summed.
    pub(crate) fn from_rows(ncols: usize, rows: Vec<Vec<(usize, f64)>>) -> Self {
        let nrows = rows.len();
        // at most this many entries: no growth by doubling (up to twice the matrix)
        let entries = rows.iter().map(Vec::len).sum();
        let mut row_ptr = Vec::with_capacity(nrows + 1);
        let mut col_idx = Vec::with_capacity(entries);
        let mut values = Vec::with_capacity(entries);
        row_ptr.push(0);
        for mut r in rows {
            r.sort_by_key(|e| e.0);
            let start = col_idx.len();
            for (j, v) in r {
                if col_idx.len() > start && *col_idx.last().unwrap() == j {
                    *values.last_mut().unwrap() += v;
                } else {
                    col_idx.push(j);
                    values.push(v);
                }
            }
            row_ptr.push(col_idx.len());
        }
        Self { nrows, ncols, row_ptr, col_idx, values }
    }

    /// The identity of size `n`.
    pub fn identity(n: usize) -> Self {
        Self { nrows: n, ncols: n, row_ptr: (0..=n).collect(), col_idx: (0..n).collect(), values: vec![1.0; n] }
    }

    /// Number of stored entries.
    pub(crate) fn nnz(&self) -> usize {
        self.col_idx.len()
    }

    /// Stored entries of row `i` as `(col, value)`.
    pub fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.row_ptr[i]..self.row_ptr[i + 1];
        self.col_idx[r.clone()].iter().copied().zip(self.values[r].iter().copied())
    }

    /// Entry `(i, j)` (zero when not stored).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let r = self.row_ptr[i]..self.row_ptr[i + 1];
        match self.col_idx[r.clone()].binary_search(&j) {
            Ok(k) => self.values[r.start + k],
            Err(_) => 0.0,
        }
    }

    /// Position of entry `(i, j)` in `values`, if it is in the pattern.
    pub fn position(&self, i: usize, j: usize) -> Option<usize> {
        let r = self.row_ptr[i]..self.row_ptr[i + 1];
        self.col_idx[r.clone()].binary_search(&j).ok().map(|k| r.start + k)
    }

    /// Overwrite with a copy of `src`, reusing this matrix's allocations.
    pub(crate) fn assign(&mut self, src: &Csr) {
        self.nrows = src.nrows;
        self.ncols = src.ncols;
        self.row_ptr.clone_from(&src.row_ptr);
        self.col_idx.clone_from(&src.col_idx);
        self.values.clone_from(&src.values);
    }

    /// Overwrite with the values of `src` when it has this matrix's pattern (the fixed
    /// pattern of one problem, recognised by its row pointers; the column indices are
    /// compared in debug builds only), with a full [`Csr::assign`] otherwise. Copies a
    /// third of what `assign` copies.
    pub(crate) fn update(&mut self, src: &Csr) {
        if self.ncols == src.ncols && self.values.len() == src.values.len() && self.row_ptr == src.row_ptr {
            debug_assert_eq!(self.col_idx, src.col_idx);
            self.values.copy_from_slice(&src.values);
        } else {
            self.assign(src);
        }
    }

    /// `y = A x`; rows in parallel above `2^16` entries.
    pub(crate) fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        debug_assert_eq!(x.len(), self.ncols);
        const CHUNK: usize = 2048;
        if self.nnz() < 1 << 16 {
            self.mul_rows(0, x, y);
            return;
        }
        y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, ys)| self.mul_rows(c * CHUNK, x, ys));
    }

    /// `y_k = (A x)_{first + k}` ([`Csr::row_dot`] per row).
    fn mul_rows(&self, first: usize, x: &[f64], y: &mut [f64]) {
        for (k, yi) in y.iter_mut().enumerate() {
            *yi = self.row_dot(first + k, x);
        }
    }

    /// `(A x)_i`: the row's entries as slices, four partial sums (the additions of one row
    /// do not wait on each other), the remainder added last.
    pub(crate) fn row_dot(&self, i: usize, x: &[f64]) -> f64 {
        let r = self.row_ptr[i]..self.row_ptr[i + 1];
        let (cols, vals) = (&self.col_idx[r.clone()], &self.values[r]);
        let mut acc = [0.0f64; 4];
        let (c4, v4) = (cols.chunks_exact(4), vals.chunks_exact(4));
        let (cr, vr) = (c4.remainder(), v4.remainder());
        for (c, v) in c4.zip(v4) {
            for l in 0..4 {
                acc[l] += v[l] * x[c[l]];
            }
        }
        let mut sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
        for (c, v) in cr.iter().zip(vr) {
            sum += v * x[*c];
        }
        sum
    }

    /// `A x` as a new vector.
    pub fn apply(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.nrows];
        self.mul_vec(x, &mut y);
        y
    }

    /// The transpose.
    pub fn transpose(&self) -> Self {
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); self.ncols];
        for i in 0..self.nrows {
            for (j, v) in self.row(i) {
                rows[j].push((i, v));
            }
        }
        Self::from_rows(self.nrows, rows)
    }

    /// Kronecker product `self ⊗ other`: entry `(i1*m + i2, j1*n + j2) = a[i1,j1] b[i2,j2]`.
    /// For tensor-product bases with `xi` fastest, the 2-D prolongation is `P_eta ⊗ P_xi`.
    pub(crate) fn kron(&self, other: &Self) -> Self {
        let nrows = self.nrows * other.nrows;
        let ncols = self.ncols * other.ncols;
        let mut row_ptr = Vec::with_capacity(nrows + 1);
        let mut col_idx = Vec::with_capacity(self.nnz() * other.nnz());
        let mut values = Vec::with_capacity(self.nnz() * other.nnz());
        row_ptr.push(0);
        for i1 in 0..self.nrows {
            for i2 in 0..other.nrows {
                for (j1, a) in self.row(i1) {
                    for (j2, b) in other.row(i2) {
                        col_idx.push(j1 * other.ncols + j2);
                        values.push(a * b);
                    }
                }
                row_ptr.push(col_idx.len());
            }
        }
        Self { nrows, ncols, row_ptr, col_idx, values }
    }

    #[cfg(test)]
    /// Product `self * other`.
    pub(crate) fn matmul(&self, other: &Self) -> Self {
        assert_eq!(self.ncols, other.nrows);
        let rows = (0..self.nrows)
            .map(|i| {
                let mut r = Vec::new();
                for (k, a) in self.row(i) {
                    for (j, b) in other.row(k) {
                        r.push((j, a * b));
                    }
                }
                r
            })
            .collect();
        Self::from_rows(other.ncols, rows)
    }

    #[cfg(test)]
    /// A dense copy (row-major), for tests and small problems.
    pub(crate) fn to_dense(&self) -> Vec<Vec<f64>> {
        let mut d = vec![vec![0.0; self.ncols]; self.nrows];
        for i in 0..self.nrows {
            for (j, v) in self.row(i) {
                d[i][j] = v;
            }
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kron_and_transpose() {
        let a = Csr::from_triplets(2, 2, &[(0, 0, 1.0), (0, 1, 2.0), (1, 1, 3.0)]);
        let b = Csr::from_triplets(2, 1, &[(0, 0, 4.0), (1, 0, 5.0)]);
        let k = a.kron(&b);
        assert_eq!(k.nrows, 4);
        assert_eq!(k.ncols, 2);
        assert_eq!(k.get(1, 1), 10.0);
        assert_eq!(k.get(3, 1), 15.0);
        assert_eq!(k.get(2, 0), 0.0);
        assert_eq!(k.transpose().transpose(), k);
        let m = a.matmul(&Csr::identity(2));
        assert_eq!(m, a);
    }
}
