//! Geometric multigrid for a symmetric positive definite scalar operator `A` on a
//! hierarchy of nested spaces given by its prolongations (for the spline hierarchy:
//! exact knot insertion, [`crate::discrete::transfers`], held as the two 1D factors of
//! `P = P_eta ⊗ P_xi` and applied in two 1D passes, [`TensorProlongation`]; no 2D
//! transfer matrix is stored). Coarse operators are the
//! Galerkin products `A_{l+1} = P_l^T A_l P_l` (the variational coarse operator: the
//! bilinear form restricted to the coarse subspace, what rediscretization on the coarse
//! basis with the fine geometry would give); the coarsest is factorized densely.
//!
//! One application is a V(ν, ν)-cycle from a zero guess: on level `l`, ν pre-smoothing
//! sweeps, the restriction `r_{l+1} = P_l^T (b - A_l x)`, the cycle on level `l + 1`, the
//! correction `x += P_l x_{l+1}`, ν post-smoothing sweeps. The smoother
//! ([`Smoother`]) is alternating line Gauss–Seidel (the lines of both directions of the
//! tensor grid, each line's banded block solved exactly: robust where the metric makes
//! one direction stiff, `g11 >> g22` in a narrow gap; the lines of one direction
//! either one after the other or by colours, each colour's lines in parallel), symmetric Gauss–Seidel or ILU(0)
//! on the level's pattern, each forward before and backward after the coarse correction;
//! BENCHMARKS.md "Multigrid" has the measured choice (ILU(0) diverges as a smoother on
//! the metrics of puzzle4's necks). Under the line smoothers the operators of the
//! smoothed levels are held as stencils of `f32` values without column indices
//! ([`grid`]), a quarter of the CSR storage and of the memory traffic of a sweep. On
//! those levels the first sweep starts from `x = 0` and reads only the couplings to the
//! lines visited before each line; where it is the only sweep before the coarse
//! correction ([`Smoother::SplitColouredLines`]) the residual `b - A x` after it is the
//! couplings to the lines visited after each line ([`lines::Lines::sweep_from_zero`]):
//! one read of the stencil for both.

use std::sync::Arc;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::linalg::dense::DenseCholesky;
use crate::linalg::krylov::Ilu0;
use crate::linalg::sparse::Csr;

mod grid;
pub mod kernels;
mod lines;
mod tensor;

pub use grid::GridStencil;
use grid::{GridOperator, Rows, SparseRows};
use kernels::{CycleBackend, DeviceCycle};
use lines::{grid_width, Lines};
pub(crate) use tensor::TensorProlongation;

/// The smoother of every level but the coarsest.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Smoother {
    /// Gauss–Seidel in the unknowns' order before the coarse correction, in reverse
    /// order after it (compared with ILU(0) in the tests, BENCHMARKS.md "Multigrid").
    #[cfg_attr(not(test), allow(dead_code))]
    SymmetricGaussSeidel,
    /// `x += (LU)^{-1} (b - A x)` with the incomplete factors of the level's operator
    /// (compared in the tests; not convergent on strongly stretched metrics).
    #[cfg_attr(not(test), allow(dead_code))]
    Ilu0,
    /// Alternating line Gauss–Seidel: block Gauss–Seidel over the lines of direction 0,
    /// then over those of direction 1 (the reverse after the coarse correction), each
    /// line's block `A_LL` factorized once ([`lines`]).
    #[cfg_attr(not(test), allow(dead_code))]
    Lines,
    /// [`Smoother::Lines`] with the lines of each direction in colours (line `l` of colour
    /// `l mod (w + 1)`, `w` the farthest coupling across the lines: 4 colours at degree
    /// 3): the lines of one colour do not couple, their corrections are computed in
    /// parallel ([`lines::Lines::sweep_coloured`]). Its cycle is symmetric (the
    /// post-smoother is the pre-smoother's adjoint): the CG preconditioner of the
    /// elasticity prolongation under `--linear multigrid`.
    ColouredLines,
    /// [`Smoother::ColouredLines`] with one direction on each side of the coarse
    /// correction: the lines of direction 0 (forward) before it, those of direction 1
    /// (backward) after it, half the sweeps of the alternating order. The cycle is then
    /// not symmetric (its pre-smoother is not the adjoint of its post-smoother): a
    /// preconditioner for flexible GMRES, not for CG.
    SplitColouredLines,
}

/// Smoother of `LinearMethod::Multigrid`: alternating line Gauss–Seidel, the lines of
/// each direction by colours (the lines of one colour in parallel). On the metric
/// Laplacians of the Newton solves themselves (puzzle4 at 3 600, 57 600 and 230 400
/// scalar unknowns) the V(1,1)-cycle with ILU(0) reduced the residual by 0.078, 0.78 and
/// 2.9 per cycle (divergent: ILU(0) of these non-M-matrices is not a convergent
/// smoother), with symmetric Gauss–Seidel by 0.91 at every size, with the lines by 0.18,
/// 0.42, 0.53; the lines solve the stiff direction of a narrow gap exactly. The coloured
/// order gives the lexicographic one's GMRES iterations per Newton step within 0.4 and
/// its CPU time within 1-3 % on 2 threads (where the two components of `-diag(B, B)`
/// already fill both), and uses more threads where there are more (BENCHMARKS.md
/// "Multigrid", the test
/// `discrete::transfers::tests::multigrid_reduction_is_independent_of_h`). One direction's
/// lines on each side of the coarse correction ([`Smoother::SplitColouredLines`]: 13/7
/// passes over each level's stencil per cycle against 5) took 0.78-0.93 times the CPU of
/// both directions on each side at refine 4 of wavy_lid, male_rotor and puzzle4, with
/// 0-33 % more GMRES iterations (BENCHMARKS.md "Half the sweeps"); its cycle is not
/// symmetric, which flexible GMRES, the only Krylov method it preconditions, allows.
pub(crate) const MG_SMOOTHER: Smoother = Smoother::SplitColouredLines;

/// Smoothing sweeps before and after each coarse correction of `LinearMethod::Multigrid`.
pub(crate) const MG_SWEEPS: usize = 1;

/// A multigrid V-cycle for `A` (see the module documentation).
#[derive(Debug)]
pub(crate) struct Multigrid {
    /// `P_l` maps level `l + 1` to level `l` (level 0 the finest); `P_l^T` restricts.
    prolongations: Vec<TensorProlongation>,
    /// `A_l`, finest first; the last is the coarsest (`A_0` is the operator handed to
    /// [`Multigrid::factor_owned`]: the cycle holds the only copy). Empty for a level held
    /// in `grids`.
    operators: Vec<Csr>,
    /// Under the line smoothers, `A_l` of each smoothed level in stencil form where it
    /// fits ([`GridOperator`], `f32` values without column indices), read by the
    /// smoother and the residual instead of the CSR matrix, which is dropped.
    grids: Vec<Option<GridOperator>>,
    /// Position of the diagonal entry of each row of each operator.
    diagonals: Vec<Vec<usize>>,
    ilu: Vec<Ilu0>,
    /// The lines of both directions of each smoothed level ([`Smoother::Lines`]).
    lines: Vec<[Lines; 2]>,
    coarse: DenseCholesky,
    smoother: Smoother,
    sweeps: usize,
    /// Where the level work runs after each set-up ([`kernels`]; `None`: the CPU) ...
    backend: Option<Arc<dyn CycleBackend>>,
    /// ... and the cycle uploaded there.
    device: Option<Box<dyn DeviceCycle>>,
}

/// `P^T A P`, one coarse row at a time (in parallel): `t = (P^T)_i A`, a sparse row of
/// the fine level, then `t P`; the rows of `P` and `P^T` generated from the 1D factors.
/// No intermediate matrix (`A P` would be a fine-by-coarse matrix of about half the
/// entries of `A`) is formed.
pub(crate) fn galerkin<A: SparseRows>(a: &A, p: &TensorProlongation) -> Csr {
    let (nf, nc) = (a.n_rows(), p.ncols());
    let rows: Vec<Vec<(usize, f64)>> = (0..nc)
        .into_par_iter()
        .map_init(
            || (Accumulator::new(nf), Accumulator::new(nc)),
            |(fine, coarse), i| {
                for (k, pik) in p.row_of_transpose(i) {
                    for (m, akm) in a.entries(k) {
                        fine.add(m, pik * akm);
                    }
                }
                for (m, t) in fine.drain() {
                    for (j, pmj) in p.row(m) {
                        coarse.add(j, t * pmj);
                    }
                }
                coarse.sorted_row()
            },
        )
        .collect();
    Csr::from_rows(nc, rows)
}

/// A dense accumulator of a sparse row: the values, which entries are set, and those
/// entries in the order first touched.
struct Accumulator {
    acc: Vec<f64>,
    seen: Vec<bool>,
    touched: Vec<usize>,
}

impl Accumulator {
    fn new(n: usize) -> Self {
        Self { acc: vec![0.0; n], seen: vec![false; n], touched: Vec::new() }
    }

    fn add(&mut self, j: usize, v: f64) {
        if !self.seen[j] {
            self.seen[j] = true;
            self.touched.push(j);
        }
        self.acc[j] += v;
    }

    /// The entries in the order first touched, the accumulator cleared.
    fn drain(&mut self) -> Vec<(usize, f64)> {
        let row = self.touched.iter().map(|&j| (j, self.acc[j])).collect();
        self.clear();
        row
    }

    /// The entries sorted by column, the accumulator cleared.
    fn sorted_row(&mut self) -> Vec<(usize, f64)> {
        self.touched.sort_unstable();
        self.drain()
    }

    fn clear(&mut self) {
        for &j in &self.touched {
            self.acc[j] = 0.0;
            self.seen[j] = false;
        }
        self.touched.clear();
    }
}

fn diagonal_positions(a: &Csr) -> Result<Vec<usize>> {
    (0..a.nrows)
        .map(|i| a.position(i, i).ok_or_else(|| Error::LinearSolver(format!("multigrid: no diagonal in row {i}"))))
        .collect()
}

impl Multigrid {
    /// A cycle on the hierarchy `prolongations` (`P_l`: level `l + 1` to level `l`, finest
    /// first), with `sweeps` smoothing sweeps before and after each coarse correction;
    /// [`Multigrid::factor`] gives it its operator.
    pub fn new(prolongations: Vec<TensorProlongation>, smoother: Smoother, sweeps: usize) -> Self {
        Self {
            prolongations,
            operators: Vec::new(),
            grids: Vec::new(),
            diagonals: Vec::new(),
            ilu: Vec::new(),
            lines: Vec::new(),
            coarse: DenseCholesky::default(),
            smoother,
            sweeps: sweeps.max(1),
            backend: None,
            device: None,
        }
    }

    /// Number of unknowns of the finest level.
    pub fn size(&self) -> usize {
        self.prolongations.first().map_or(self.coarse.size(), TensorProlongation::nrows)
    }

    /// Number of levels (the finest included).
    pub fn levels(&self) -> usize {
        self.prolongations.len() + 1
    }

    /// Set up the cycle for the SPD `a` (of the finest level's size): a copy of `a`, then
    /// [`Multigrid::factor_owned`].
    ///
    /// Errors: as [`Multigrid::factor_owned`].
    #[cfg(test)]
    pub fn factor(&mut self, a: &Csr) -> Result<()> {
        self.factor_owned(a.clone())
    }

    /// Set up the cycle for the SPD `a` (of the finest level's size), which it keeps as
    /// its finest operator: the Galerkin coarse operators, the smoothers and the coarsest
    /// factorization. The operators of a previous set-up are dropped first.
    ///
    /// Errors: [`Error::LinearSolver`] when `a`'s size does not match the hierarchy, a
    /// row has no diagonal entry, or the coarsest operator is not positive definite.
    pub fn factor_owned(&mut self, a: Csr) -> Result<()> {
        let n0 = self.prolongations.first().map_or(a.nrows, TensorProlongation::nrows);
        if a.nrows != n0 || a.ncols != n0 {
            return Err(Error::LinearSolver(format!(
                "multigrid: a {} x {} operator on a hierarchy of {n0} fine unknowns",
                a.nrows, a.ncols
            )));
        }
        // the previous operators and smoothers go before the new ones are built
        self.release();
        self.setup(a, Vec::with_capacity(self.levels()), Vec::new(), Vec::new())
    }

    /// [`Multigrid::factor_owned`] for the operator held as a grid stencil (`K` from
    /// its stencil storage): the finest level's lines, stencil form and Galerkin product
    /// read it directly, and it goes after them, so no CSR matrix of the finest level is
    /// built. The cycle is the one [`Multigrid::factor_owned`] sets up for its CSR matrix
    /// (the same coarse operators, factors and `f32` stencil); where that one would keep
    /// the finest level in CSR (a grid too small for a stencil to pay, another smoother)
    /// the matrix is made and handed to it.
    ///
    /// Errors: as [`Multigrid::factor_owned`].
    pub fn factor_stencil(&mut self, a: GridStencil) -> Result<()> {
        let [bx, by] = a.half;
        let n = a.n_rows();
        // couplings inside the grid per direction: the CSR matrix's nonzeros are their product
        let inside = |len: usize, b: usize| (0..len).map(|i| (i + b + 1).min(len) - i.saturating_sub(b)).sum::<usize>();
        let as_csr = a.nx <= bx + 1
            || a.ny <= by
            || (2 * bx + 1) * (2 * by + 1) * n > 4 * inside(a.nx, bx) * inside(a.ny, by)
            || !matches!(self.smoother, Smoother::Lines | Smoother::ColouredLines | Smoother::SplitColouredLines)
            || self.prolongations.first().is_none_or(|p| p.nrows() != n);
        if as_csr {
            return self.factor_owned(a.to_csr());
        }
        self.release();
        let p = &self.prolongations[0];
        let (coarse, ((l0, l1), grid)) = rayon::join(
            || galerkin(&a, p),
            || {
                rayon::join(
                    || rayon::join(|| Lines::new(&a, a.nx, 0), || Lines::new(&a, a.nx, 1)),
                    || GridOperator::from_stencil(&a),
                )
            },
        );
        drop(a);
        let mut operators = Vec::with_capacity(self.levels());
        operators.push(Csr::default());
        self.setup(coarse, operators, vec![[l0?, l1?]], vec![Some(grid)])
    }

    /// The levels from `operators.len()` on, `a` the operator of that level (the finer
    /// levels' operators, lines and stencil forms given).
    fn setup(
        &mut self,
        a: Csr,
        mut operators: Vec<Csr>,
        mut lines: Vec<[Lines; 2]>,
        mut grids: Vec<Option<GridOperator>>,
    ) -> Result<()> {
        // level by level: the coarse operator, then the level's smoother and stencil
        // form, after which its CSR matrix goes (only one fine matrix exists at a time)
        let lines_smoother =
            matches!(self.smoother, Smoother::Lines | Smoother::ColouredLines | Smoother::SplitColouredLines);
        let (mut diagonals, mut ilu) = (Vec::new(), Vec::new());
        let mut current = a;
        for p in &self.prolongations[operators.len()..] {
            let coarse = galerkin(&current, p);
            match self.smoother {
                Smoother::SymmetricGaussSeidel => diagonals.push(diagonal_positions(&current)?),
                Smoother::Ilu0 => ilu.push(Ilu0::new(&current)?),
                Smoother::Lines | Smoother::ColouredLines | Smoother::SplitColouredLines => {
                    let nx = grid_width(&current);
                    // the two directions' lines and the stencil form side by side
                    let ((l0, l1), grid) = rayon::join(
                        || rayon::join(|| Lines::new(&current, nx, 0), || Lines::new(&current, nx, 1)),
                        || GridOperator::from_csr(&current, nx),
                    );
                    lines.push([l0?, l1?]);
                    if grid.is_some() {
                        current = Csr::default();
                    }
                    grids.push(grid);
                }
            }
            operators.push(std::mem::replace(&mut current, coarse));
        }
        self.coarse.factor(&current, 1.0)?;
        operators.push(current);
        debug_assert!(!lines_smoother || grids.len() + 1 == operators.len());
        (self.diagonals, self.ilu, self.lines, self.grids) = (diagonals, ilu, lines, grids);
        self.operators = operators;
        self.upload();
        Ok(())
    }

    /// Drop the operators and smoothers of the last set-up (the hierarchy stays).
    fn release(&mut self) {
        self.operators = Vec::new();
        self.grids = Vec::new();
        self.lines = Vec::new();
        self.ilu = Vec::new();
        self.diagonals = Vec::new();
        self.device = None;
    }

    /// `x = B b`, one V-cycle from `x = 0` (`B ≈ A^{-1}`): on the back end the cycle
    /// was uploaded to, the CPU where there is none or it fails.
    pub fn apply(&self, b: &[f64], x: &mut [f64]) {
        if self.device.as_ref().is_some_and(|d| d.apply(b, x).is_ok()) {
            return;
        }
        self.apply_cpu(b, x);
    }

    /// [`Multigrid::apply`] on the CPU.
    fn apply_cpu(&self, b: &[f64], x: &mut [f64]) {
        x.fill(0.0);
        self.cycle(0, b, x);
    }

    fn cycle(&self, l: usize, b: &[f64], x: &mut [f64]) {
        if l + 1 == self.levels() {
            x.copy_from_slice(b);
            self.coarse.solve_columns(x);
            return;
        }
        let mut r = vec![0.0; b.len()];
        // the first pre-smoothing sweep starts from x = 0: on a stencil level its lines
        // read only the lines visited before them, and where it is the only sweep before
        // the coarse correction the residual comes with it ([`Lines::sweep_from_zero`])
        let split = self.smoother == Smoother::SplitColouredLines;
        let mut fused = false;
        let mut pre = self.sweeps;
        if let Some(g) = self.grid(l).filter(|g| self.lines.len() > l && g.across(0) < 32 && g.across(1) < 32) {
            let coloured = self.smoother != Smoother::Lines;
            let [l0, l1] = &self.lines[l];
            let mut scratch = Vec::new();
            fused = split && self.sweeps == 1;
            l0.sweep_from_zero(g, b, x, coloured, false, fused.then_some(&mut r[..]), &mut scratch);
            if !split {
                let sweep = if coloured { Lines::sweep_coloured } else { Lines::sweep };
                sweep(l1, g, b, x, false, &mut scratch);
            }
            pre -= 1;
        }
        for _ in 0..pre {
            self.smooth(l, b, x, &mut r, false);
        }
        if !fused {
            match self.grid(l) {
                Some(g) => g.mul_vec(x, &mut r),
                None => self.operators[l].mul_vec(x, &mut r),
            }
            for (ri, bi) in r.iter_mut().zip(b) {
                *ri = bi - *ri;
            }
        }
        let p = &self.prolongations[l];
        let mut rc = vec![0.0; p.ncols()];
        p.restrict(&r, &mut rc);
        let mut xc = vec![0.0; rc.len()];
        self.cycle(l + 1, &rc, &mut xc);
        p.prolong(&xc, &mut r);
        for (xi, ci) in x.iter_mut().zip(&r) {
            *xi += ci;
        }
        for _ in 0..self.sweeps {
            self.smooth(l, b, x, &mut r, true);
        }
    }

    /// The stencil form of level `l`'s operator, if it is held so.
    fn grid(&self, l: usize) -> Option<&GridOperator> {
        self.grids.get(l).and_then(Option::as_ref)
    }

    /// One smoothing sweep on level `l` (`r` scratch of the level's size).
    fn smooth(&self, l: usize, b: &[f64], x: &mut [f64], r: &mut [f64], backward: bool) {
        let a = &self.operators[l];
        match self.smoother {
            Smoother::SymmetricGaussSeidel => {
                let diag = &self.diagonals[l];
                let mut relax = |i: usize| {
                    let mut s = b[i];
                    for k in a.row_ptr[i]..a.row_ptr[i + 1] {
                        s -= a.values[k] * x[a.col_idx[k]];
                    }
                    x[i] += s / a.values[diag[i]];
                };
                if backward {
                    (0..a.nrows).rev().for_each(&mut relax);
                } else {
                    (0..a.nrows).for_each(&mut relax);
                }
            }
            Smoother::Lines | Smoother::ColouredLines | Smoother::SplitColouredLines => {
                let mut scratch = Vec::new();
                let [l0, l1] = &self.lines[l];
                let a: &dyn Rows = match self.grid(l) {
                    Some(g) => g,
                    None => a,
                };
                let sweep = if self.smoother == Smoother::Lines { Lines::sweep } else { Lines::sweep_coloured };
                if self.smoother == Smoother::SplitColouredLines {
                    // direction 0 before the coarse correction, direction 1 after it
                    let (lines, backward) = if backward { (l1, true) } else { (l0, false) };
                    sweep(lines, a, b, x, backward, &mut scratch);
                } else if backward {
                    sweep(l1, a, b, x, true, &mut scratch);
                    sweep(l0, a, b, x, true, &mut scratch);
                } else {
                    sweep(l0, a, b, x, false, &mut scratch);
                    sweep(l1, a, b, x, false, &mut scratch);
                }
            }
            Smoother::Ilu0 => {
                a.mul_vec(x, r);
                for (ri, bi) in r.iter_mut().zip(b) {
                    *ri = bi - *ri;
                }
                let mut z = vec![0.0; r.len()];
                self.ilu[l].apply(r, &mut z);
                for (xi, zi) in x.iter_mut().zip(&z) {
                    *xi += zi;
                }
            }
        }
    }
}
