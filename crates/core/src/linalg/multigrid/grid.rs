//! A scalar operator on a tensor grid of unknowns (`nx` per row, unknown `i = ix + nx iy`)
//! held as its stencil: every row couples to the `(2 b_x + 1)(2 b_y + 1)` unknowns
//! `i + dx + nx dy`, `|dx| <= b_x`, `|dy| <= b_y` (for the metric Laplacian of degree
//! `(p, q)` on a single patch and its Galerkin coarse operators: `b = (p, q)`), so a row
//! stores its values only, in single precision, with no column index: 4 B per entry
//! where a CSR matrix holds 16 (`f64` value and `usize` column). The multigrid smoother
//! and residuals read the operator once per sweep, so this quarters their memory traffic
//! and the operator's storage; in an `f64` outer iteration (flexible GMRES over the
//! Jacobian) the cycle then smooths `A` rounded to `f32` (relative change `2^-24` per
//! entry), a preconditioner as good as the exact one.

use rayon::prelude::*;

use crate::linalg::sparse::Csr;

/// An operator whose rows give `(b - A x)_i` and the product `A x`.
pub(crate) trait Rows: Sync {
    /// `(b - A x)_i`.
    fn residual_at(&self, b: &[f64], x: &[f64], i: usize) -> f64;
}

impl Rows for Csr {
    /// The row's products in four partial sums ([`Csr::row_dot`]).
    fn residual_at(&self, b: &[f64], x: &[f64], i: usize) -> f64 {
        b[i] - self.row_dot(i, x)
    }
}

/// The rows of a sparse scalar operator, as the cycle's set-up reads them (the Galerkin
/// product, the line factors): a CSR matrix, or the finest level's [`GridStencil`].
pub(crate) trait SparseRows: Sync {
    /// Number of rows (and columns).
    fn n_rows(&self) -> usize;
    /// The entries `(column, value)` of row `i`, by ascending column.
    fn entries(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_;
}

impl SparseRows for Csr {
    fn n_rows(&self) -> usize {
        self.nrows
    }
    fn entries(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.row(i)
    }
}

/// A scalar operator on an `nx x ny` grid of unknowns in double precision, stored as
/// the V-cycle's `f32` grid operator stores it (`(2 b_x + 1)(2 b_y + 1)` values per row, coupling `(dx,
/// dy)` at `(dy + b_y) w_x + dx + b_x`, the couplings outside the grid zero): the
/// metric Laplacian `K` straight from its stencil storage (its free rows, the couplings
/// to fixed functions left out), handed to the V-cycle with no CSR matrix
/// (`Multigrid::factor_stencil`). Its entries are those of the CSR matrix with the
/// pattern of the grid's tensor stencil.
#[derive(Debug, Clone)]
pub struct GridStencil {
    /// Unknowns per grid row ...
    pub nx: usize,
    /// ... and grid rows.
    pub ny: usize,
    /// Half widths `[b_x, b_y]`.
    pub half: [usize; 2],
    /// The values, row after row.
    pub values: Vec<f64>,
}

impl GridStencil {
    /// The couplings of row `i` inside the grid: `(column, slot)` by ascending column.
    fn slots(&self, i: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        let [bx, by] = self.half;
        let (ix, iy) = (i % self.nx, i / self.nx);
        let (x0, x1) = (ix.saturating_sub(bx), (ix + bx + 1).min(self.nx));
        (iy.saturating_sub(by)..(iy + by + 1).min(self.ny)).flat_map(move |jy| {
            (x0..x1).map(move |jx| (jy * self.nx + jx, (jy + by - iy) * (2 * bx + 1) + jx + bx - ix))
        })
    }

    /// The CSR matrix of the same entries.
    pub fn to_csr(&self) -> Csr {
        let n = self.nx * self.ny;
        let w = (2 * self.half[0] + 1) * (2 * self.half[1] + 1);
        let rows = (0..n).map(|i| self.slots(i).map(|(c, s)| (c, self.values[i * w + s])).collect()).collect();
        Csr::from_rows(n, rows)
    }
}

impl SparseRows for GridStencil {
    fn n_rows(&self) -> usize {
        self.nx * self.ny
    }
    fn entries(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let w = (2 * self.half[0] + 1) * (2 * self.half[1] + 1);
        self.slots(i).map(move |(c, s)| (c, self.values[i * w + s]))
    }
}

/// A grid operator (see the module documentation).
#[derive(Debug, Clone)]
pub(crate) struct GridOperator {
    pub(super) nx: usize,
    pub(super) ny: usize,
    /// Half widths `[b_x, b_y]` of the stencil.
    pub(super) half: [usize; 2],
    /// Row `i`'s value of the coupling `(dx, dy)` at `(i w_y + dy + b_y) w_x + dx + b_x`.
    pub(super) values: Vec<f32>,
}

/// Rows per parallel task of [`GridOperator::mul_vec`].
const ROWS: usize = 2048;

impl GridOperator {
    /// `a` on the grid of width `nx`, when its rows fit a stencil no larger than four
    /// times its mean row length (each entry then costs at most the 16 B of the CSR
    /// storage); `None` otherwise (`nx` not dividing the size, or a grid too small for a
    /// stencil to pay: the coarsest levels, one line of unknowns).
    pub fn from_csr(a: &Csr, nx: usize) -> Option<Self> {
        let n = a.nrows;
        if nx == 0 || n == 0 || !n.is_multiple_of(nx) || a.ncols != n {
            return None;
        }
        let ny = n / nx;
        // the half widths (maxima: the same whatever the split of the rows)
        let (hx, hy) = (0..n)
            .into_par_iter()
            .with_min_len(ROWS)
            .map(|i| {
                a.row(i).fold((0, 0), |(hx, hy), (c, _)| {
                    (hx.max((i % nx).abs_diff(c % nx)), hy.max((i / nx).abs_diff(c / nx)))
                })
            })
            .reduce(|| (0, 0), |x, y| (x.0.max(y.0), x.1.max(y.1)));
        let half = [hx, hy];
        let (wx, wy) = (2 * half[0] + 1, 2 * half[1] + 1);
        if wx * wy * n > 4 * a.nnz() {
            return None;
        }
        let mut values = vec![0.0f32; n * wx * wy];
        values.par_chunks_mut(wx * wy).enumerate().with_min_len(ROWS).for_each(|(i, row)| {
            let (ix, iy) = (i % nx, i / nx);
            for (c, v) in a.row(i) {
                let (dx, dy) = (c % nx + half[0] - ix, c / nx + half[1] - iy);
                row[dy * wx + dx] = v as f32;
            }
        });
        Some(Self { nx, ny, half, values })
    }

    /// `a` rounded to single precision: the operator [`GridOperator::from_csr`] makes of
    /// the CSR matrix of the same entries.
    pub fn from_stencil(a: &GridStencil) -> Self {
        let values = a.values.par_iter().with_min_len(ROWS).map(|&v| v as f32).collect();
        Self { nx: a.nx, ny: a.ny, half: a.half, values }
    }

    /// Number of rows (and columns).
    #[cfg(test)]
    pub fn size(&self) -> usize {
        self.nx * self.ny
    }

    /// `(A x)_i`: per stencil row `dy`, the products with the contiguous unknowns
    /// `i + dx + nx dy` inside the grid, summed in `f64` (eight partial sums by `dx`
    /// measured 20 % slower end to end than this sum of each stencil row).
    fn row_product(&self, x: &[f64], i: usize) -> f64 {
        let [bx, by] = self.half;
        let (wx, wy) = (2 * bx + 1, 2 * by + 1);
        let (ix, iy) = (i % self.nx, i / self.nx);
        let (x0, x1) = (ix.saturating_sub(bx), (ix + bx + 1).min(self.nx));
        let vals = &self.values[i * wx * wy..][..wx * wy];
        let mut sum = 0.0;
        for jy in iy.saturating_sub(by)..(iy + by + 1).min(self.ny) {
            let row = &vals[(jy + by - iy) * wx + (x0 + bx - ix)..][..x1 - x0];
            let xs = &x[jy * self.nx + x0..jy * self.nx + x1];
            sum += row.iter().zip(xs).map(|(v, xv)| f64::from(*v) * xv).sum::<f64>();
        }
        sum
    }

    /// Half width of the stencil across the lines of direction `dir` (direction 0: the
    /// lines are the grid's rows, `b_y`; direction 1: its columns, `b_x`).
    pub fn across(&self, dir: usize) -> usize {
        self.half[1 - dir.min(1)]
    }

    /// `Σ_j a_ij x_j` over the couplings `j` of row `i` that lie on the lines at offset
    /// `d` from `i`'s line (direction `dir`, see [`GridOperator::across`]) with bit
    /// `d + b` of `mask` set: the part of `(A x)_i` from those lines. Each stencil row is
    /// summed in [`GridOperator::row_product`]'s order without the terms left out, so
    /// where the left-out `x_j` are zero the result has `(A x)_i`'s bits.
    pub fn masked_product(&self, x: &[f64], i: usize, dir: usize, mask: u64) -> f64 {
        if mask == 0 {
            return 0.0;
        }
        let [bx, by] = self.half;
        let (wx, wy) = (2 * bx + 1, 2 * by + 1);
        let (ix, iy) = (i % self.nx, i / self.nx);
        let (x0, x1) = (ix.saturating_sub(bx), (ix + bx + 1).min(self.nx));
        let vals = &self.values[i * wx * wy..][..wx * wy];
        let mut sum = 0.0;
        for jy in iy.saturating_sub(by)..(iy + by + 1).min(self.ny) {
            if dir == 0 && mask & (1 << (jy + by - iy)) == 0 {
                continue;
            }
            let row = &vals[(jy + by - iy) * wx + (x0 + bx - ix)..][..x1 - x0];
            let xs = &x[jy * self.nx + x0..jy * self.nx + x1];
            sum += if dir == 0 {
                row.iter().zip(xs).map(|(v, xv)| f64::from(*v) * xv).sum::<f64>()
            } else {
                row.iter()
                    .zip(xs)
                    .enumerate()
                    .filter(|(t, _)| mask & (1 << (x0 + t + bx - ix)) != 0)
                    .map(|(_, (v, xv))| f64::from(*v) * xv)
                    .sum::<f64>()
            };
        }
        sum
    }

    /// `y = A x` (rows in parallel).
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(ROWS).enumerate().for_each(|(c, ys)| {
            for (o, yi) in ys.iter_mut().enumerate() {
                *yi = self.row_product(x, c * ROWS + o);
            }
        });
    }
}

impl Rows for GridOperator {
    fn residual_at(&self, b: &[f64], x: &[f64], i: usize) -> f64 {
        b[i] - self.row_product(x, i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Lcg;

    /// The entries of a symmetric matrix with the pattern of a `(2 bx + 1)(2 by + 1)` tensor stencil on
    /// an `nx x ny` grid, random values.
    fn stencil_triplets(nx: usize, ny: usize, bx: usize, by: usize, seed: u64) -> Vec<(usize, usize, f64)> {
        let mut rng = Lcg::new(seed);
        let mut t = Vec::new();
        for iy in 0..ny {
            for ix in 0..nx {
                let i = ix + nx * iy;
                for jy in iy.saturating_sub(by)..(iy + by + 1).min(ny) {
                    for jx in ix.saturating_sub(bx)..(ix + bx + 1).min(nx) {
                        let j = jx + nx * jy;
                        if j >= i {
                            let v = if j == i { 10.0 } else { rng.uniform() - 0.5 };
                            t.push((i, j, v));
                            if j != i {
                                t.push((j, i, v));
                            }
                        }
                    }
                }
            }
        }
        t
    }

    /// The grid operator's product and residuals equal the CSR matrix's to the rounding
    /// of its values to `f32` (`2^-24` relative per entry), on stencils of half widths
    /// (3, 3) and (3, 2); a matrix with a coupling far outside a stencil is refused.
    #[test]
    fn grid_product_equals_csr_product_to_single_rounding() {
        for (nx, ny, bx, by) in [(17, 12, 3, 3), (9, 14, 3, 2)] {
            let a = Csr::from_triplets(nx * ny, nx * ny, &stencil_triplets(nx, ny, bx, by, 4));
            let g = GridOperator::from_csr(&a, nx).expect("a tensor stencil");
            assert_eq!((g.size(), g.half), (nx * ny, [bx, by]));
            let mut rng = Lcg::new(5);
            let x: Vec<f64> = (0..nx * ny).map(|_| rng.uniform() - 0.5).collect();
            let b: Vec<f64> = (0..nx * ny).map(|_| rng.uniform() - 0.5).collect();
            let want = a.apply(&x);
            let mut got = vec![0.0; nx * ny];
            g.mul_vec(&x, &mut got);
            for i in 0..nx * ny {
                // |sum_j (fl32(a_ij) - a_ij) x_j| <= 2^-24 sum_j |a_ij x_j|
                let bound: f64 = a.row(i).map(|(j, v)| (v * x[j]).abs()).sum::<f64>() * 1.2e-7;
                assert!((got[i] - want[i]).abs() <= bound, "row {i}: {} against {}", got[i], want[i]);
                let r = (b[i] - want[i], g.residual_at(&b, &x, i), a.residual_at(&b, &x, i));
                assert!((r.0 - r.1).abs() <= bound && (r.0 - r.2).abs() <= 1e-14, "row {i}: {r:?}");
            }
        }
        let mut far = stencil_triplets(20, 20, 1, 1, 6);
        far.push((0, 399, 1.0));
        far.push((399, 0, 1.0));
        assert!(GridOperator::from_csr(&Csr::from_triplets(400, 400, &far), 20).is_none());
    }
}
