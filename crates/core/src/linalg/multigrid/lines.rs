//! Line smoothing for a scalar operator on a tensor grid of unknowns (`nx` per row,
//! numbered `i + nx j`): block Gauss–Seidel over the lines of one direction, each line's
//! block `A_LL` (banded: a spline function couples with `p` neighbours on each side along
//! a line) factorized once by banded Cholesky. Lines along the direction of strong
//! coupling solve that coupling exactly, which pointwise smoothers cannot (the stiff
//! direction of a stretched map, `g11 >> g22` or the reverse).
//!
//! The lines are visited either one after the other ([`Lines::sweep`], lexicographic
//! block Gauss–Seidel) or by colours ([`Lines::sweep_coloured`]): line `l` has colour
//! `l mod c` with `c = w + 1`, `w` the farthest coupling between lines (`w = q` for the
//! `(2p + 1)(2q + 1)` stencil of degree `q` across the lines), so the lines of one colour
//! do not couple with each other. Their corrections `A_LL^{-1} (b - A x)_L` all use the
//! same `x` and are computed in parallel; the colours follow one another (multicolour
//! line Gauss–Seidel, the "zebra" ordering for `c = 2`).

use rayon::prelude::*;

use super::grid::{GridOperator, Rows, SparseRows};
use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;

/// Rows per parallel task of the residual of [`Lines::sweep_from_zero`].
const RESIDUAL_ROWS: usize = 2048;

/// Rows per parallel task of the scans of [`Lines::new`].
const SETUP_ROWS: usize = 4096;

/// The lines of one direction of an `nx x ny` grid: line `j` of direction 0 holds the
/// unknowns `j nx + t`, `t < nx`; line `i` of direction 1 holds `i + t nx`, `t < ny`.
#[derive(Debug, Clone)]
pub struct Lines {
    /// First unknown of each line.
    pub(super) starts: Vec<usize>,
    /// Distance between consecutive unknowns of a line.
    pub(super) stride: usize,
    /// Unknowns per line.
    pub(super) len: usize,
    /// Bandwidth of each line's block.
    pub(super) bw: usize,
    /// Banded Cholesky factors, line after line: `l[(L len + t)(bw + 1) + d] = L[t][t - d]`.
    pub(super) factors: Vec<f64>,
    /// Colours of [`Lines::sweep_coloured`]: one more than the farthest coupling between
    /// two lines (at most the number of lines).
    pub(super) colours: usize,
    /// The direction of the lines (0: the grid's rows, 1: its columns).
    dir: usize,
}

impl Lines {
    /// The lines of direction `dir` of the `nx x (n / nx)` grid of `a`, their blocks
    /// factorized.
    ///
    /// Errors: [`Error::LinearSolver`] when a block is not positive definite.
    pub fn new<A: SparseRows>(a: &A, nx: usize, dir: usize) -> Result<Self> {
        let n = a.n_rows();
        let ny = n / nx.max(1);
        let (starts, stride, len): (Vec<usize>, usize, usize) = match dir {
            0 => ((0..ny).map(|j| j * nx).collect(), 1, nx),
            _ => ((0..nx).collect(), nx, ny),
        };
        // bandwidth: the farthest coupling along a line; and across the lines (maxima:
        // the same whatever the split of the rows between threads)
        let line_of = |i: usize| if dir == 0 { i / nx.max(1) } else { i % nx.max(1) };
        let (bw, across) = (0..n)
            .into_par_iter()
            .with_min_len(SETUP_ROWS)
            .map(|i| {
                a.entries(i).fold((0, 0), |(bw, across), (c, _)| {
                    let d = along(i, c, stride, nx, dir).map_or(0, isize::unsigned_abs);
                    (bw.max(d), across.max(line_of(i).abs_diff(line_of(c))))
                })
            })
            .reduce(|| (0, 0), |x, y| (x.0.max(y.0), x.1.max(y.1)));
        let colours = (across + 1).min(starts.len()).max(1);
        let w = bw + 1;
        let mut factors = vec![0.0; starts.len() * len * w];
        // each line's block factorized on its own (in parallel: the lines are independent)
        factors.par_chunks_mut((len * w).max(1)).zip(starts.par_iter()).enumerate().try_for_each(
            |(li, (f, &s0))| {
                for t in 0..len {
                    let i = s0 + t * stride;
                    for (c, v) in a.entries(i) {
                        if let Some(d) = along(i, c, stride, nx, dir) {
                            if d <= 0 && (-d) as usize <= t {
                                f[t * w + (-d) as usize] = v;
                            }
                        }
                    }
                }
                // banded Cholesky in place: row t holds L[t][t - d], d = 0..=bw
                for t in 0..len {
                    for d in (1..=bw.min(t)).rev() {
                        let j = t - d;
                        let mut s = f[t * w + d];
                        for e in 1..=bw.min(j) {
                            // L[t][j - e] L[j][j - e], j - e >= t - bw
                            let k = d + e;
                            if k <= bw {
                                s -= f[t * w + k] * f[j * w + e];
                            }
                        }
                        f[t * w + d] = s / f[j * w];
                    }
                    let mut s = f[t * w];
                    for d in 1..=bw.min(t) {
                        s -= f[t * w + d] * f[t * w + d];
                    }
                    if s.is_nan() || s <= 0.0 {
                        return Err(Error::LinearSolver(format!("line smoother: block {li} not definite at {t}")));
                    }
                    f[t * w] = s.sqrt();
                }
                Ok(())
            },
        )?;
        Ok(Self { starts, stride, len, bw, factors, colours, dir })
    }

    /// The correction of line `li`, `r = A_LL^{-1} (b - A x)_L` (`r` of the line's length).
    fn correction(&self, li: usize, a: &dyn Rows, b: &[f64], x: &[f64], r: &mut [f64]) {
        let s0 = self.starts[li];
        for (t, rt) in r.iter_mut().enumerate() {
            *rt = a.residual_at(b, x, s0 + t * self.stride);
        }
        self.solve_line(li, r);
    }

    /// `r = A_LL^{-1} r` on line `li` (the two banded triangular solves).
    fn solve_line(&self, li: usize, r: &mut [f64]) {
        let (len, w) = (self.len, self.bw + 1);
        let f = &self.factors[li * len * w..(li + 1) * len * w];
        // L y = r, L^T d = y
        for t in 0..len {
            let mut s = r[t];
            for d in 1..w.min(t + 1) {
                s -= f[t * w + d] * r[t - d];
            }
            r[t] = s / f[t * w];
        }
        for t in (0..len).rev() {
            let mut s = r[t];
            for d in 1..w.min(len - t) {
                s -= f[(t + d) * w + d] * r[t + d];
            }
            r[t] = s / f[t * w];
        }
    }

    /// `x_L += r` on line `li`.
    fn add(&self, li: usize, r: &[f64], x: &mut [f64]) {
        let s0 = self.starts[li];
        for (t, rt) in r.iter().enumerate() {
            x[s0 + t * self.stride] += rt;
        }
    }

    /// One block Gauss–Seidel sweep over the lines (in reverse order when `backward`):
    /// `x_L += A_LL^{-1} (b - A x)_L` line after line.
    pub fn sweep(&self, a: &dyn Rows, b: &[f64], x: &mut [f64], backward: bool, r: &mut Vec<f64>) {
        r.resize(self.len, 0.0);
        let mut line = |li: usize| {
            self.correction(li, a, b, x, r);
            self.add(li, r, x);
        };
        if backward {
            (0..self.starts.len()).rev().for_each(&mut line);
        } else {
            (0..self.starts.len()).for_each(&mut line);
        }
    }

    /// One multicolour block Gauss–Seidel sweep (the colours in reverse order when
    /// `backward`): for each colour, the corrections `A_LL^{-1} (b - A x)_L` of all its
    /// lines from the same `x`, in parallel, then added. Since lines of one colour do not
    /// couple, this is the lexicographic sweep over the lines in the order of their
    /// colours. `r` is scratch.
    pub fn sweep_coloured(&self, a: &dyn Rows, b: &[f64], x: &mut [f64], backward: bool, r: &mut Vec<f64>) {
        let (lines, c, len) = (self.starts.len(), self.colours, self.len);
        if len == 0 {
            return;
        }
        let mut colour = |k: usize| {
            // the lines k, k + c, k + 2c, ...
            let count = (lines - k).div_ceil(c);
            r.resize(count * len, 0.0);
            let xs: &[f64] = x;
            r.par_chunks_mut(len).enumerate().for_each(|(q, rq)| self.correction(k + q * c, a, b, xs, rq));
            for (q, rq) in r.chunks(len).enumerate() {
                self.add(k + q * c, rq, x);
            }
        };
        if backward {
            (0..c).rev().for_each(&mut colour);
        } else {
            (0..c).for_each(&mut colour);
        }
    }

    /// One sweep from `x = 0` (`x` must be zero on entry), lexicographic ([`Lines::sweep`])
    /// or coloured ([`Lines::sweep_coloured`]), forward or `backward`, on the grid
    /// operator `a`, with the residual `b - A x` after it written to `residual` when given.
    ///
    /// The lines not yet visited are zero, so a line's `(b - A x)_L` reads only the
    /// couplings to the lines visited before it (for the first colour none: `A_LL^{-1}
    /// b_L`); the same `x` as the full sweep, bit for bit. Line `L` then solves `A_LL x_L
    /// = b_L - Σ_{L' before L} A_LL' x_L'`, so after the sweep `(b - A x)_L = -Σ_{L' not
    /// before L, L' ≠ L} A_LL' x_L'` (the couplings to the lines visited after it): the
    /// residual costs the other part of the stencil. Together the sweep and the residual
    /// read each row's stencil once, without its line's own block, where a sweep and a
    /// residual from a nonzero guess read it twice. (The block `A_LL` is solved with the
    /// `f64` values of the set-up and the stencil holds it in `f32`: the residual is that
    /// of the operator with the `f64` blocks, `2^-24` relative from the stencil's.)
    #[allow(clippy::too_many_arguments)]
    pub fn sweep_from_zero(
        &self,
        a: &GridOperator,
        b: &[f64],
        x: &mut [f64],
        coloured: bool,
        backward: bool,
        residual: Option<&mut [f64]>,
        scratch: &mut Vec<f64>,
    ) {
        let (lines, len, dir) = (self.starts.len(), self.len, self.dir);
        if len == 0 || lines == 0 {
            return;
        }
        let h = a.across(dir) as isize;
        // lines visited in groups (a colour, or one line): group k holds k, k + c, ...
        let c = if coloured { self.colours } else { lines };
        // the visit order's key of a line: its colour, or the line itself; the mask of
        // the lines at offsets -h..=h before (or not before) a line depends on the line
        // only through its colour (coloured) or not at all (lexicographic)
        let classes = if coloured { self.colours } else { 1 };
        let key = |line: isize| {
            let k = if coloured { line.rem_euclid(c as isize) } else { line };
            if backward {
                -k
            } else {
                k
            }
        };
        let mask = |li: usize, after: bool| {
            let mut m = 0u64;
            for d in (-h..=h).filter(|&d| d != 0) {
                let (kd, k0) = (key(li as isize + d), key(li as isize));
                if (kd < k0) != after {
                    m |= 1 << (d + h);
                }
            }
            m
        };
        let mut visit = |k: usize| {
            let count = (lines - k).div_ceil(c);
            let before = mask(k, false);
            scratch.resize(count * len, 0.0);
            let xs: &[f64] = x;
            let line = |q: usize, rq: &mut [f64]| {
                let li = k + q * c;
                let s0 = self.starts[li];
                for (t, rt) in rq.iter_mut().enumerate() {
                    let i = s0 + t * self.stride;
                    *rt = b[i] - a.masked_product(xs, i, dir, before);
                }
                self.solve_line(li, rq);
            };
            if count > 1 {
                scratch.par_chunks_mut(len).enumerate().for_each(|(q, rq)| line(q, rq));
            } else {
                line(0, &mut scratch[..len]);
            }
            for (q, rq) in scratch.chunks(len).enumerate() {
                self.add(k + q * c, rq, x);
            }
        };
        if backward {
            (0..c).rev().for_each(&mut visit);
        } else {
            (0..c).for_each(&mut visit);
        }
        if let Some(res) = residual {
            let after: Vec<u64> = (0..classes).map(|k| mask(k, true)).collect();
            let nx = if dir == 0 { len } else { self.stride };
            let xs: &[f64] = x;
            res.par_chunks_mut(RESIDUAL_ROWS).enumerate().for_each(|(ci, rs)| {
                for (o, ri) in rs.iter_mut().enumerate() {
                    let i = ci * RESIDUAL_ROWS + o;
                    let li = if dir == 0 { i / nx } else { i % nx };
                    *ri = -a.masked_product(xs, i, dir, after[li % classes]);
                }
            });
        }
    }

    /// Number of colours of [`Lines::sweep_coloured`].
    #[cfg(test)]
    pub fn colours(&self) -> usize {
        self.colours
    }
}

/// Signed offset along the line of unknown `i` of the coupling `c`, or `None` when `c`
/// is on another line.
fn along(i: usize, c: usize, stride: usize, nx: usize, dir: usize) -> Option<isize> {
    match dir {
        0 => (i / nx == c / nx).then(|| c as isize - i as isize),
        _ => (i % nx == c % nx).then(|| (c as isize - i as isize) / stride as isize),
    }
}

/// The width `nx` of the grid of `a`'s unknowns, read from the pattern of its first row
/// (the couplings `i + nx j` of a tensor stencil: the first gap in its columns). Where
/// the first row has no gap (`nx` at most `p + 1`, or a single row of unknowns) this is
/// `a.nrows`: one line holding every unknown, solved exactly as a banded block of
/// bandwidth at most `(p + 1) nx`, and lines of one unknown in the other direction (still
/// a convergent block Gauss–Seidel).
pub fn grid_width(a: &Csr) -> usize {
    let cols: Vec<usize> = a.row(0).map(|(c, _)| c).collect();
    cols.windows(2).find(|w| w[1] != w[0] + 1).map_or(a.nrows, |w| w[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric positive definite banded matrix of size `n` and bandwidth 3 (the
    /// bandwidth of a cubic spline line), diagonally dominant, pseudo-random.
    fn banded(n: usize, seed: u64) -> Csr {
        crate::testutil::banded_spd(n, &mut crate::testutil::Lcg::new(seed))
    }

    fn residual(a: &Csr, b: &[f64], x: &[f64]) -> f64 {
        let ax = a.apply(x);
        ax.iter().zip(b).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max)
    }

    /// Without couplings between the lines of a direction, one block Gauss–Seidel sweep
    /// over them is the exact solve: `A = I ⊗ T` (lines of direction 0) and `A = T ⊗ I`
    /// (direction 1), `T` banded SPD.
    #[test]
    fn one_sweep_solves_uncoupled_lines_exactly() {
        let (nx, ny) = (11, 7);
        let mut rng = crate::testutil::Lcg::new(5);
        let b: Vec<f64> = (0..nx * ny).map(|_| rng.uniform() - 0.5).collect();
        for (dir, a) in [(0, Csr::identity(ny).kron(&banded(nx, 1))), (1, banded(ny, 2).kron(&Csr::identity(nx)))] {
            let lines = Lines::new(&a, nx, dir).unwrap();
            assert_eq!(lines.bw, 3);
            for backward in [false, true] {
                let mut x = vec![0.0; nx * ny];
                lines.sweep(&a, &b, &mut x, backward, &mut Vec::new());
                assert!(residual(&a, &b, &x) < 1e-13, "direction {dir}: {}", residual(&a, &b, &x));
            }
        }
    }

    /// The grid width read from the pattern of a tensor stencil `T_y ⊗ T_x`, and the
    /// block Gauss–Seidel iteration over coupled lines converging to the solution.
    #[test]
    fn grid_width_and_convergence_on_a_tensor_stencil() {
        let (nx, ny) = (13, 9);
        let a = banded(ny, 3).kron(&banded(nx, 4));
        assert_eq!(grid_width(&a), nx);
        let mut rng = crate::testutil::Lcg::new(6);
        let b: Vec<f64> = (0..nx * ny).map(|_| rng.uniform() - 0.5).collect();
        let lines = [Lines::new(&a, nx, 0).unwrap(), Lines::new(&a, nx, 1).unwrap()];
        let mut x = vec![0.0; nx * ny];
        let r0 = residual(&a, &b, &x);
        for _ in 0..20 {
            lines[0].sweep(&a, &b, &mut x, false, &mut Vec::new());
            lines[1].sweep(&a, &b, &mut x, false, &mut Vec::new());
        }
        assert!(residual(&a, &b, &x) < 1e-12 * r0, "{}", residual(&a, &b, &x) / r0);
    }

    /// On a tensor stencil of bandwidth 3 across the lines, four colours; the coloured
    /// sweep (corrections of a colour's lines in parallel from the same `x`) equals the
    /// sequential block Gauss–Seidel sweep over the lines in the order of their colours
    /// (`0, 4, 8, ..., 1, 5, ...`; reversed colours backward), in both directions.
    #[test]
    fn coloured_sweep_is_gauss_seidel_in_colour_order() {
        let (nx, ny) = (13, 10);
        let a = banded(ny, 7).kron(&banded(nx, 8));
        let mut rng = crate::testutil::Lcg::new(9);
        let b: Vec<f64> = (0..nx * ny).map(|_| rng.uniform() - 0.5).collect();
        let x0: Vec<f64> = (0..nx * ny).map(|_| rng.uniform() - 0.5).collect();
        for dir in [0, 1] {
            let lines = Lines::new(&a, nx, dir).unwrap();
            assert_eq!(lines.colours(), 4);
            let n_lines = lines.starts.len();
            for backward in [false, true] {
                let mut coloured = x0.clone();
                lines.sweep_coloured(&a, &b, &mut coloured, backward, &mut Vec::new());
                let mut order: Vec<usize> = (0..4).flat_map(|c| (c..n_lines).step_by(4)).collect();
                if backward {
                    order = (0..4).rev().flat_map(|c| (c..n_lines).step_by(4)).collect();
                }
                let mut sequential = x0.clone();
                let mut r = vec![0.0; lines.len];
                for li in order {
                    lines.correction(li, &a, &b, &sequential, &mut r);
                    lines.add(li, &r, &mut sequential);
                }
                let err = coloured.iter().zip(&sequential).fold(0.0f64, |m, (u, v)| m.max((u - v).abs()));
                assert!(err <= 1e-15, "direction {dir}, backward {backward}: {err}");
                assert!(residual(&a, &b, &coloured) < residual(&a, &b, &x0), "direction {dir}: no reduction");
            }
        }
    }

    /// From `x = 0` the sweep that reads only the lines visited before each line
    /// ([`Lines::sweep_from_zero`]) gives the full sweep's `x` bit for bit, and its
    /// residual equals `b - A x` to rounding, lexicographic and coloured, forward and
    /// backward, in both directions (the values multiples of `2^-10`, so that the stencil's
    /// `f32` values and the line blocks' `f64` values are the same matrix).
    #[test]
    fn sweep_from_zero_is_the_sweep_and_gives_its_residual() {
        let (nx, ny) = (13, 10);
        let mut a = banded(ny, 11).kron(&banded(nx, 12));
        a.values.iter_mut().for_each(|v| *v = (*v * 1024.0).round() / 1024.0);
        let g = GridOperator::from_csr(&a, nx).expect("a tensor stencil");
        let mut rng = crate::testutil::Lcg::new(13);
        let b: Vec<f64> = (0..nx * ny).map(|_| rng.uniform() - 0.5).collect();
        for dir in [0, 1] {
            let lines = Lines::new(&a, nx, dir).unwrap();
            for coloured in [false, true] {
                for backward in [false, true] {
                    let mut full = vec![0.0; nx * ny];
                    let sweep = if coloured { Lines::sweep_coloured } else { Lines::sweep };
                    sweep(&lines, &g, &b, &mut full, backward, &mut Vec::new());
                    let (mut x, mut res) = (vec![0.0; nx * ny], vec![f64::NAN; nx * ny]);
                    lines.sweep_from_zero(&g, &b, &mut x, coloured, backward, Some(&mut res), &mut Vec::new());
                    let case = format!("direction {dir}, coloured {coloured}, backward {backward}");
                    assert!(x.iter().zip(&full).all(|(u, v)| u.to_bits() == v.to_bits()), "{case}: x differs");
                    let ax = a.apply(&x);
                    let err = (0..nx * ny).fold(0.0f64, |m, i| m.max((res[i] - (b[i] - ax[i])).abs()));
                    assert!(err <= 1e-13, "{case}: residual off by {err}");
                    assert!(res.iter().any(|v| v.abs() > 1e-3), "{case}: a zero residual");
                }
            }
        }
    }
}
