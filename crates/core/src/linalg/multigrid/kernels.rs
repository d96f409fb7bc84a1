//! The level work of the multigrid V-cycle (`Multigrid` with a coloured line
//! smoother, both directions on each side or one on each side, the solver's) as operations on vectors owned by the levels, so that a back
//! end other than the CPU (the GPU crate's WGSL kernels) can run the whole cycle where
//! its data lives, and the CPU implementation ([`CpuLevels`], today's code) is the
//! reference it is tested against.
//!
//! Each smoothed level `l` owns three vectors `b_l`, `x_l`, `r_l`; the coarsest owns `b_L`
//! and `x_L`. The operations ([`LevelKernels`]) are
//! - `smooth(l, dir, backward)`: one coloured line Gauss–Seidel sweep over the lines of
//!   direction `dir` for `A_l x_l = b_l` (colours in reverse order when `backward`); the
//!   lines of one colour do not couple, so each line's correction
//!   `A_LL^{-1} (b - A x)_L` (its banded Cholesky factor computed at set-up) is
//!   independent of the others of its colour;
//! - `residual(l)`: `r_l = b_l - A_l x_l` (the level's stencil, `f32` values summed in
//!   `f64`, or its CSR matrix);
//! - `restrict(l)`: `b_{l+1} = P_l^T r_l` and `x_{l+1} = 0` (two 1D passes);
//! - `prolong_add(l)`: `x_l += P_l x_{l+1}` (two 1D passes);
//! - `coarse_solve()`: `x_L = A_L^{-1} b_L` (the dense Cholesky factor).
//!
//! [`v_cycle`] strings them together as `Multigrid::apply` does (in its order; the
//! solver's cycle takes the residual from its first sweep where it can, which is the
//! same to rounding), and
//! [`Hierarchy`] is the read-only view of a set-up cycle that a back end uploads once per
//! set-up ([`CycleBackend::upload`]); the resulting [`DeviceCycle`] then applies the
//! whole V-cycle to a right-hand side per call.

use std::sync::Arc;

use super::grid::GridOperator;
use super::lines::Lines;
use super::{Multigrid, Smoother, TensorProlongation};
use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;

/// The operations of one V-cycle on the vectors owned by the levels (see the module
/// documentation).
pub trait LevelKernels {
    /// One coloured line Gauss–Seidel sweep for `A_l x_l = b_l` over the lines of
    /// direction `dir` (0: rows of unknowns, 1: columns), colours backward when asked.
    fn smooth(&mut self, l: usize, dir: usize, backward: bool);
    /// `r_l = b_l - A_l x_l`.
    fn residual(&mut self, l: usize);
    /// `b_{l+1} = P_l^T r_l`, `x_{l+1} = 0`.
    fn restrict(&mut self, l: usize);
    /// `x_l += P_l x_{l+1}`.
    fn prolong_add(&mut self, l: usize);
    /// `x_L = A_L^{-1} b_L` on the coarsest level `L`.
    fn coarse_solve(&mut self);
}

/// How a V-cycle smooths: `sweeps` (ν) sweeps on each side of the coarse correction,
/// of both line directions (`split = false`: direction 0 then 1 forward before, 1 then 0
/// backward after; `Smoother::ColouredLines`), or of one direction each (`split = true`:
/// direction 0 forward before, direction 1 backward after; `Smoother::SplitColouredLines`,
/// the solver's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Smoothing {
    /// Sweeps before and after each coarse correction.
    pub sweeps: usize,
    /// One line direction on each side of the coarse correction.
    pub split: bool,
}

/// The V(ν, ν)-cycle on level `l` of `levels` (the coarsest included) from `x_l = 0`:
/// the sweeps of `s` before the coarse correction, the residual, its restriction, the
/// cycle below, the prolonged correction, the sweeps of `s` after it ([`Smoothing`]):
/// `Multigrid::apply` in the order of its operations (the solver's cycle takes the
/// residual from its first sweep where it can, the same to rounding).
pub fn v_cycle<K: LevelKernels + ?Sized>(k: &mut K, levels: usize, s: Smoothing, l: usize) {
    if l + 1 >= levels {
        k.coarse_solve();
        return;
    }
    for _ in 0..s.sweeps {
        k.smooth(l, 0, false);
        if !s.split {
            k.smooth(l, 1, false);
        }
    }
    k.residual(l);
    k.restrict(l);
    v_cycle(k, levels, s, l + 1);
    k.prolong_add(l);
    for _ in 0..s.sweeps {
        k.smooth(l, 1, true);
        if !s.split {
            k.smooth(l, 0, true);
        }
    }
}

/// A level's operator `A_l` as the cycle holds it.
#[derive(Debug, Clone, Copy)]
pub enum LevelOperator<'a> {
    /// A tensor stencil without column indices: row `i = ix + nx iy` couples with
    /// `i + dx + nx dy`, `|dx| <= half[0]`, `|dy| <= half[1]`, its value at
    /// `(i w_y + dy + half[1]) w_x + dx + half[0]` (`w = 2 half + 1`), in `f32`; a row's
    /// product is summed in `f64` per stencil row `dy` (in `dx` order, the coupled
    /// unknowns inside the grid only), the stencil rows' sums added in `dy` order.
    Stencil {
        /// Unknowns per grid row.
        nx: usize,
        /// Grid rows.
        ny: usize,
        /// Half widths `[b_x, b_y]`.
        half: [usize; 2],
        /// The values, `nx ny (2 b_x + 1)(2 b_y + 1)`.
        values: &'a [f32],
    },
    /// A CSR matrix in `f64` (levels too small for a stencil to pay); a row's product is
    /// summed in four partial sums over the row's entries `4 k + s`, added as
    /// `(s_0 + s_1) + (s_2 + s_3)`, then the remaining entries in order.
    Csr(&'a Csr),
}

impl LevelOperator<'_> {
    /// Rows (and columns).
    pub fn size(&self) -> usize {
        match self {
            Self::Stencil { nx, ny, .. } => nx * ny,
            Self::Csr(a) => a.nrows,
        }
    }
}

/// The lines of one direction of a level and their banded Cholesky factors.
#[derive(Debug, Clone, Copy)]
pub struct LineBlocks<'a> {
    /// First unknown of each line.
    pub starts: &'a [usize],
    /// Distance between consecutive unknowns of a line.
    pub stride: usize,
    /// Unknowns per line.
    pub len: usize,
    /// Bandwidth `w - 1` of each line's block.
    pub bandwidth: usize,
    /// The factors, line after line: `factors[(L len + t) w + d] = L[t][t - d]`,
    /// `w = bandwidth + 1`; the solve is `L y = r` forward, then `L^T d = y` backward, each
    /// row's terms subtracted in order of `d`.
    pub factors: &'a [f64],
    /// Colours: line `k` has colour `k mod colours`.
    pub colours: usize,
}

/// The prolongation `P_l = P_1 ⊗ P_0` from level `l + 1` to level `l` and its transpose,
/// each as two 1D factors (unknowns numbered direction 0 fastest). `y = (a_1 ⊗ a_0) x`
/// is `t = X a_0^T` (each row of the `n_1 x n_0` array `X` times `a_0`, a row's products
/// summed in order), then `Y = a_1 t` (each output accumulated from zero over the entries
/// of `a_1`'s row in order).
#[derive(Debug, Clone, Copy)]
pub struct Transfer<'a> {
    /// `[P_0, P_1]`.
    pub prolongation: [&'a Csr; 2],
    /// `[P_0^T, P_1^T]`.
    pub restriction: [&'a Csr; 2],
}

/// A set-up V-cycle, read-only: what a back end uploads (see the module documentation).
#[derive(Debug, Clone)]
pub struct Hierarchy<'a> {
    /// The smoothed levels, finest first: their operators and the lines of both
    /// directions.
    pub levels: Vec<(LevelOperator<'a>, [LineBlocks<'a>; 2])>,
    /// `transfers[l]` between level `l + 1` and level `l`.
    pub transfers: Vec<Transfer<'a>>,
    /// Size `n` of the coarsest level and its dense Cholesky factor `L` (row-major
    /// `n x n`, lower triangle): `L y = b` with each row's products summed in order, then
    /// `L^T x = y` subtracting `L[k][i] x_k` for `k = i + 1, ...` in order.
    pub coarse: (usize, &'a [f64]),
    /// How each level is smoothed.
    pub smoothing: Smoothing,
}

impl Hierarchy<'_> {
    /// Number of levels, the coarsest included.
    pub fn num_levels(&self) -> usize {
        self.levels.len() + 1
    }

    /// Unknowns of level `l` (the coarsest at `l = levels.len()`).
    pub fn size(&self, l: usize) -> usize {
        self.levels.get(l).map_or(self.coarse.0, |(a, _)| a.size())
    }
}

/// A back end that runs the V-cycle's level work (the GPU crate's kernels): it uploads a
/// set-up cycle and applies it.
pub trait CycleBackend: Send + Sync + std::fmt::Debug {
    /// The cycle `h` on the back end, or why it cannot run there (the caller then keeps
    /// the CPU cycle).
    ///
    /// Errors: the back end's, as [`Error::LinearSolver`].
    fn upload(&self, h: &Hierarchy<'_>) -> Result<Box<dyn DeviceCycle>>;
}

/// A V-cycle uploaded to a back end.
pub trait DeviceCycle: Send + Sync + std::fmt::Debug {
    /// `x = B b`, one V-cycle from `x = 0` ([`v_cycle`]).
    ///
    /// Errors: the back end's, as [`Error::LinearSolver`] (the caller then runs the CPU
    /// cycle).
    fn apply(&self, b: &[f64], x: &mut [f64]) -> Result<()>;
}

/// A multigrid V-cycle with the solver's smoother and sweeps, for back ends and their
/// tests: the cycle of `LinearMethod::Multigrid` (the solver's smoother and sweeps).
#[derive(Debug)]
pub struct Cycle {
    mg: Multigrid,
}

impl Cycle {
    /// The cycle for the SPD `a` on the hierarchy `prolongations` (`[P_0, P_1]` from
    /// level `l + 1` to level `l`, finest first; `a` of the finest size), set up.
    ///
    /// Errors: as the solver's set-up ([`Error::LinearSolver`]: sizes that do not
    /// match, a coarsest operator or a line block not positive definite).
    pub fn new(prolongations: Vec<[Csr; 2]>, a: Csr) -> Result<Self> {
        let p: Vec<TensorProlongation> = prolongations.into_iter().map(TensorProlongation::from).collect();
        for w in p.windows(2) {
            if w[0].ncols() != w[1].nrows() {
                return Err(Error::LinearSolver("multigrid: prolongations do not chain".into()));
            }
        }
        let mut mg = Multigrid::new(p, super::MG_SMOOTHER, super::MG_SWEEPS);
        mg.factor_owned(a)?;
        Ok(Self { mg })
    }

    /// The read-only view for a back end.
    pub fn hierarchy(&self) -> Hierarchy<'_> {
        self.mg.hierarchy().expect("set up with the coloured line smoother")
    }

    /// `x = B b` on the CPU (`Multigrid::apply`).
    pub fn apply(&self, b: &[f64], x: &mut [f64]) {
        self.mg.apply_cpu(b, x);
    }

    /// The level operations on the CPU, the levels' vectors zero.
    pub fn cpu_levels(&self) -> CpuLevels<'_> {
        CpuLevels::new(&self.mg)
    }
}

/// [`LevelKernels`] on the CPU: the code of `Multigrid::apply`, on vectors owned
/// by the levels.
#[derive(Debug)]
pub struct CpuLevels<'a> {
    mg: &'a Multigrid,
    /// `b_l` of every level, the coarsest included.
    pub b: Vec<Vec<f64>>,
    /// `x_l` of every level, the coarsest included.
    pub x: Vec<Vec<f64>>,
    /// `r_l` of every smoothed level.
    pub r: Vec<Vec<f64>>,
}

impl<'a> CpuLevels<'a> {
    fn new(mg: &'a Multigrid) -> Self {
        let sizes: Vec<usize> = (0..mg.levels()).map(|l| mg.level_size(l)).collect();
        let zeros = |s: &[usize]| s.iter().map(|&n| vec![0.0; n]).collect::<Vec<_>>();
        Self { mg, b: zeros(&sizes), x: zeros(&sizes), r: zeros(&sizes[..sizes.len() - 1]) }
    }

    /// Run the whole cycle: `x_0 = B b_0` from `x_0 = 0`.
    pub fn cycle(&mut self) {
        self.x[0].fill(0.0);
        let levels = self.mg.levels();
        v_cycle(self, levels, self.mg.smoothing(), 0);
    }
}

impl LevelKernels for CpuLevels<'_> {
    fn smooth(&mut self, l: usize, dir: usize, backward: bool) {
        let mg = self.mg;
        let lines = &mg.lines[l][dir];
        let a: &dyn super::grid::Rows = match mg.grid(l) {
            Some(g) => g,
            None => &mg.operators[l],
        };
        let mut scratch = Vec::new();
        let sweep = if mg.smoother == Smoother::Lines { Lines::sweep } else { Lines::sweep_coloured };
        sweep(lines, a, &self.b[l], &mut self.x[l], backward, &mut scratch);
    }

    fn residual(&mut self, l: usize) {
        let mg = self.mg;
        let r = &mut self.r[l];
        match mg.grid(l) {
            Some(g) => g.mul_vec(&self.x[l], r),
            None => mg.operators[l].mul_vec(&self.x[l], r),
        }
        for (ri, bi) in r.iter_mut().zip(&self.b[l]) {
            *ri = bi - *ri;
        }
    }

    fn restrict(&mut self, l: usize) {
        self.mg.prolongations[l].restrict(&self.r[l], &mut self.b[l + 1]);
        self.x[l + 1].fill(0.0);
    }

    fn prolong_add(&mut self, l: usize) {
        let r = &mut self.r[l];
        self.mg.prolongations[l].prolong(&self.x[l + 1], r);
        for (xi, ci) in self.x[l].iter_mut().zip(r.iter()) {
            *xi += ci;
        }
    }

    fn coarse_solve(&mut self) {
        let c = self.b.len() - 1;
        self.x[c].copy_from_slice(&self.b[c]);
        self.mg.coarse.solve_columns(&mut self.x[c]);
    }
}

impl Multigrid {
    /// How the cycle smooths ([`Smoothing`]; the line smoothers' order).
    pub(super) fn smoothing(&self) -> Smoothing {
        Smoothing { sweeps: self.sweeps, split: self.smoother == Smoother::SplitColouredLines }
    }

    /// Unknowns of level `l`.
    fn level_size(&self, l: usize) -> usize {
        match l {
            0 => self.size(),
            _ => self.prolongations[l - 1].ncols(),
        }
    }

    /// The read-only view of the set-up cycle for a back end: `None` unless the smoother
    /// is [`Smoother::ColouredLines`] or [`Smoother::SplitColouredLines`] and the cycle
    /// is set up.
    pub(super) fn hierarchy(&self) -> Option<Hierarchy<'_>> {
        let coloured = matches!(self.smoother, Smoother::ColouredLines | Smoother::SplitColouredLines);
        if !coloured || self.lines.len() + 1 != self.levels() {
            return None;
        }
        let levels = (0..self.lines.len())
            .map(|l| {
                let op = match self.grid(l) {
                    Some(g) => stencil_view(g),
                    None => LevelOperator::Csr(&self.operators[l]),
                };
                (op, [line_view(&self.lines[l][0]), line_view(&self.lines[l][1])])
            })
            .collect();
        let transfers = self
            .prolongations
            .iter()
            .map(|p| Transfer {
                prolongation: [&p.factors[0], &p.factors[1]],
                restriction: [&p.transposes[0], &p.transposes[1]],
            })
            .collect();
        Some(Hierarchy {
            levels,
            transfers,
            coarse: (self.coarse.size(), self.coarse.factor_values()),
            smoothing: self.smoothing(),
        })
    }

    /// Set the back end the level work runs on after each set-up (`None`: the CPU).
    pub(crate) fn set_backend(&mut self, backend: Option<Arc<dyn CycleBackend>>) {
        self.backend = backend;
        self.device = None;
    }

    /// Upload the set-up cycle to the back end, if there is one; where that fails the
    /// cycle stays on the CPU (the back end reports why).
    pub(super) fn upload(&mut self) {
        self.device = match (&self.backend, self.hierarchy()) {
            (Some(b), Some(h)) => b.upload(&h).ok(),
            _ => None,
        };
    }
}

fn stencil_view(g: &GridOperator) -> LevelOperator<'_> {
    LevelOperator::Stencil { nx: g.nx, ny: g.ny, half: g.half, values: &g.values }
}

fn line_view(l: &Lines) -> LineBlocks<'_> {
    LineBlocks {
        starts: &l.starts,
        stride: l.stride,
        len: l.len,
        bandwidth: l.bw,
        factors: &l.factors,
        colours: l.colours,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{banded_spd, Lcg};

    /// A symmetric, diagonally dominant tensor operator `T_y ⊗ T_x + S` (bandwidth 3 per
    /// direction) on an `n x n` grid, and the knot-insertion-like hierarchy of averaging
    /// prolongations down to a few unknowns.
    fn case(n: usize) -> (Vec<[Csr; 2]>, Csr) {
        let mut rng = Lcg::new(11);
        let a = banded_spd(n, &mut rng).kron(&banded_spd(n, &mut rng));
        // P: fine m = 2 c - 1 from coarse c, (1/2, 1, 1/2) weights
        let mut ps = Vec::new();
        let mut m = n;
        while m > 9 {
            let c = m.div_ceil(2);
            let mut t = Vec::new();
            for j in 0..c {
                t.push((2 * j, j, 1.0));
                if 2 * j + 1 < m {
                    t.push((2 * j + 1, j, 0.5));
                }
                if j > 0 {
                    t.push((2 * j - 1, j, 0.5));
                }
            }
            let p = Csr::from_triplets(m, c, &t);
            ps.push([p.clone(), p]);
            m = c;
        }
        (ps, a)
    }

    /// The cycle strung together from the level operations on the CPU gives the bits of
    /// the solver's V-cycle ([`super::super::Multigrid::apply`]).
    #[test]
    fn v_cycle_of_the_level_operations_is_the_solver_cycle() {
        let (ps, a) = case(41);
        let cycle = Cycle::new(ps, a).unwrap();
        let h = cycle.hierarchy();
        assert_eq!(h.num_levels(), 4);
        assert!(matches!(h.levels[0].0, LevelOperator::Stencil { .. }));
        let mut rng = Lcg::new(3);
        let b: Vec<f64> = (0..h.size(0)).map(|_| rng.uniform() - 0.5).collect();
        let mut want = vec![1.0; b.len()];
        cycle.apply(&b, &mut want);
        let mut levels = cycle.cpu_levels();
        levels.b[0].copy_from_slice(&b);
        levels.cycle();
        // the same operations in the same order, but the solver's cycle takes each
        // level's residual from its first sweep (`Lines::sweep_from_zero`, summed in
        // another order, equal to 1e-13), and the coarse corrections carry that rounding
        // on (2.8e-9 of the largest value measured here): equal to rounding, not bit for
        // bit; a cycle in another order differs in the first digits
        assert!(h.smoothing.split && h.smoothing.sweeps == 1);
        let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = levels.x[0].iter().zip(&want).fold(0.0f64, |m, (u, v)| m.max((u - v).abs()));
        assert!(err <= 1e-7 * scale, "{err} against {scale}");
    }
}
