//! Geometric multigrid for a symmetric positive definite scalar operator `A` on a
//! hierarchy of nested spaces given by its prolongations (for the spline hierarchy:
//! exact knot insertion, [`crate::discrete::transfers`]). Coarse operators are the
//! Galerkin products `A_{l+1} = P_l^T A_l P_l` (the variational coarse operator: the
//! bilinear form restricted to the coarse subspace, what rediscretization on the coarse
//! basis with the fine geometry would give); the coarsest is factorized densely.
//!
//! One application is a V(ν, ν)-cycle from a zero guess: on level `l`, ν pre-smoothing
//! sweeps, the restriction `r_{l+1} = P_l^T (b - A_l x)`, the cycle on level `l + 1`, the
//! correction `x += P_l x_{l+1}`, ν post-smoothing sweeps. The smoother
//! ([`Smoother`]) is symmetric Gauss–Seidel (forward before, backward after the
//! coarse correction: the cycle is a symmetric operator) or ILU(0) on the level's
//! pattern; see BENCHMARKS.md "Multigrid" for the measured choice.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::linalg::dense::DenseCholesky;
use crate::linalg::krylov::Ilu0;
use crate::linalg::sparse::Csr;

mod lines;

/// The smoother of every level but the coarsest.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Smoother {
    /// Gauss–Seidel in the unknowns' order before the coarse correction, in reverse
    /// order after it (compared with ILU(0) in the tests, BENCHMARKS.md "Multigrid").
    #[cfg_attr(not(test), allow(dead_code))]
    SymmetricGaussSeidel,
    /// `x += (LU)^{-1} (b - A x)` with the incomplete factors of the level's operator.
    Ilu0,
    /// Alternating line Gauss–Seidel: block Gauss–Seidel over the lines of direction 0,
    /// then over those of direction 1 (in reverse after the coarse correction).
    Lines,
}

/// A multigrid V-cycle for `A` (see the module documentation).
#[derive(Debug)]
pub struct Multigrid {
    /// `P_l` maps level `l + 1` to level `l` (level 0 the finest).
    prolongations: Vec<Csr>,
    restrictions: Vec<Csr>,
    /// `A_l`, finest first; the last is the coarsest.
    operators: Vec<Csr>,
    /// Position of the diagonal entry of each row of each operator.
    diagonals: Vec<Vec<usize>>,
    ilu: Vec<Ilu0>,
    lines: Vec<[lines::Lines; 2]>,
    /// Coarse corrections per level: 1 for a V-cycle, 2 for a W-cycle.
    gamma: usize,
    probe: bool,
    coarse: DenseCholesky,
    smoother: Smoother,
    sweeps: usize,
}

/// Diagnostics: a variant of the cycle named by `spec` (comma-separated: `ilu`, `sgs`,
/// `lines`, `w`, `2`, `3`).
fn variant(spec: &str, mut smoother: Smoother, mut sweeps: usize) -> (Smoother, usize, usize) {
    let mut gamma = 1;
    for part in spec.split(',') {
        match part {
            "ilu" => smoother = Smoother::Ilu0,
            "sgs" => smoother = Smoother::SymmetricGaussSeidel,
            "lines" => smoother = Smoother::Lines,
            "w" => gamma = 2,
            "2" => sweeps = 2,
            "3" => sweeps = 3,
            _ => {}
        }
    }
    (smoother, sweeps, gamma)
}

/// `P^T A P` with `pt = P^T`, rows in parallel, a dense accumulator per thread.
pub fn galerkin(pt: &Csr, a: &Csr, p: &Csr) -> Csr {
    let nc = p.ncols;
    let ap = {
        let rows: Vec<Vec<(usize, f64)>> = (0..a.nrows)
            .into_par_iter()
            .map_init(
                || (vec![0.0; nc], vec![false; nc], Vec::new()),
                |(acc, seen, touched), i| {
                    for (k, aik) in a.row(i) {
                        for (j, pkj) in p.row(k) {
                            if !seen[j] {
                                seen[j] = true;
                                touched.push(j);
                            }
                            acc[j] += aik * pkj;
                        }
                    }
                    gather_row(acc, seen, touched)
                },
            )
            .collect();
        Csr::from_rows(nc, rows)
    };
    let rows: Vec<Vec<(usize, f64)>> = (0..pt.nrows)
        .into_par_iter()
        .map_init(
            || (vec![0.0; nc], vec![false; nc], Vec::new()),
            |(acc, seen, touched), i| {
                for (k, pik) in pt.row(i) {
                    for (j, v) in ap.row(k) {
                        if !seen[j] {
                            seen[j] = true;
                            touched.push(j);
                        }
                        acc[j] += pik * v;
                    }
                }
                gather_row(acc, seen, touched)
            },
        )
        .collect();
    Csr::from_rows(nc, rows)
}

/// The accumulated row (sorted by column), the accumulator cleared.
fn gather_row(acc: &mut [f64], seen: &mut [bool], touched: &mut Vec<usize>) -> Vec<(usize, f64)> {
    touched.sort_unstable();
    let row = touched.iter().map(|&j| (j, acc[j])).collect();
    for &j in touched.iter() {
        acc[j] = 0.0;
        seen[j] = false;
    }
    touched.clear();
    row
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
    pub fn new(prolongations: Vec<Csr>, smoother: Smoother, sweeps: usize) -> Self {
        let restrictions = prolongations.iter().map(Csr::transpose).collect();
        let (smoother, sweeps, gamma) = match std::env::var("WINSLOW_MG") {
            Ok(v) => variant(&v, smoother, sweeps),
            Err(_) => (smoother, sweeps, 1),
        };
        let mut mg = Self::with(prolongations, restrictions, smoother, sweeps);
        mg.gamma = gamma;
        mg.probe = std::env::var_os("WINSLOW_MG_PROBE").is_some();
        mg
    }

    fn with(prolongations: Vec<Csr>, restrictions: Vec<Csr>, smoother: Smoother, sweeps: usize) -> Self {
        Self {
            prolongations,
            restrictions,
            operators: Vec::new(),
            diagonals: Vec::new(),
            ilu: Vec::new(),
            lines: Vec::new(),
            gamma: 1,
            probe: false,
            coarse: DenseCholesky::default(),
            smoother,
            sweeps: sweeps.max(1),
        }
    }

    /// Number of unknowns of the finest level.
    pub fn size(&self) -> usize {
        self.prolongations.first().map_or(self.coarse.size(), |p| p.nrows)
    }

    /// Number of levels (the finest included).
    pub fn levels(&self) -> usize {
        self.prolongations.len() + 1
    }

    /// Set up the cycle for the SPD `a` (of the finest level's size): the Galerkin coarse
    /// operators, the smoothers and the coarsest factorization. Reuses the storage of a
    /// previous set-up.
    ///
    /// Errors: [`Error::LinearSolver`] when `a`'s size does not match the hierarchy, a
    /// row has no diagonal entry, or the coarsest operator is not positive definite.
    pub fn factor(&mut self, a: &Csr) -> Result<()> {
        let n0 = self.prolongations.first().map_or(a.nrows, |p| p.nrows);
        if a.nrows != n0 || a.ncols != n0 {
            return Err(Error::LinearSolver(format!(
                "multigrid: a {} x {} operator on a hierarchy of {n0} fine unknowns",
                a.nrows, a.ncols
            )));
        }
        let mut operators = std::mem::take(&mut self.operators);
        operators.resize_with(self.levels(), Csr::default);
        operators[0].update(a);
        for l in 0..self.prolongations.len() {
            operators[l + 1] = galerkin(&self.restrictions[l], &operators[l], &self.prolongations[l]);
        }
        let smoothed = &operators[..operators.len() - 1];
        self.diagonals = smoothed.iter().map(diagonal_positions).collect::<Result<_>>()?;
        self.ilu = match self.smoother {
            Smoother::Ilu0 => smoothed.iter().map(Ilu0::new).collect::<Result<_>>()?,
            _ => Vec::new(),
        };
        self.lines = match self.smoother {
            Smoother::Lines => smoothed
                .iter()
                .map(|a| {
                    let nx = lines::grid_width(a);
                    Ok([lines::Lines::new(a, nx, 0)?, lines::Lines::new(a, nx, 1)?])
                })
                .collect::<Result<_>>()?,
            _ => Vec::new(),
        };
        self.coarse.factor(operators.last().expect("at least one level"), 1.0)?;
        self.operators = operators;
        if self.probe {
            self.print_probe();
        }
        Ok(())
    }

    /// Diagnostics: the level sizes and the residual reduction of the stationary
    /// iteration `x += B (b - A x)`, `b` pseudo-random, per cycle.
    fn print_probe(&self) {
        let spec = std::env::var("WINSLOW_MG_PROBE").unwrap_or_default();
        for v in spec.split(';').filter(|v| !v.is_empty()) {
            let (smoother, sweeps, gamma) = variant(v, self.smoother, self.sweeps);
            let mut mg = Self::with(self.prolongations.clone(), self.restrictions.clone(), smoother, sweeps);
            mg.gamma = gamma;
            match mg.factor(&self.operators[0]) {
                Ok(()) => mg.probe_one(v),
                Err(e) => eprintln!("MGPROBE {v}: {e}"),
            }
        }
    }

    fn probe_one(&self, name: &str) {
        let a = &self.operators[0];
        let n = a.nrows;
        let mut seed = 12345u64;
        let b: Vec<f64> = (0..n)
            .map(|_| {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let norm = |v: &[f64]| v.iter().map(|t| t * t).sum::<f64>().sqrt();
        let (mut x, mut r, mut z) = (vec![0.0; n], b.clone(), vec![0.0; n]);
        let r0 = norm(&r);
        let mut out = Vec::new();
        let mut prev = r0;
        for _ in 0..10 {
            self.apply(&r, &mut z);
            x.iter_mut().zip(&z).for_each(|(xi, zi)| *xi += zi);
            a.mul_vec(&x, &mut r);
            r.iter_mut().zip(&b).for_each(|(ri, bi)| *ri = bi - *ri);
            let nr = norm(&r);
            out.push(nr / prev);
            prev = nr;
        }
        let sizes: Vec<String> = self
            .operators
            .iter()
            .map(|o| format!("{}x{}", lines::grid_width(o), o.nrows / lines::grid_width(o).max(1)))
            .collect();
        let mean = (prev / r0).powf(0.1);
        eprintln!(
            "MGPROBE n={n} {name:<10} mean={mean:.4} levels=[{}] per-cycle=[{}]",
            sizes.join(" "),
            out.iter().map(|v| format!("{v:.3}")).collect::<Vec<_>>().join(" ")
        );
    }

    /// `x = B b`, one V-cycle from `x = 0` (`B ≈ A^{-1}`).
    pub fn apply(&self, b: &[f64], x: &mut [f64]) {
        x.fill(0.0);
        self.cycle(0, b, x);
    }

    fn cycle(&self, l: usize, b: &[f64], x: &mut [f64]) {
        if l + 1 == self.levels() {
            x.copy_from_slice(b);
            self.coarse.solve_columns(x);
            return;
        }
        let a = &self.operators[l];
        let mut r = vec![0.0; b.len()];
        for _ in 0..self.sweeps {
            self.smooth(l, b, x, &mut r, false);
        }
        a.mul_vec(x, &mut r);
        for (ri, bi) in r.iter_mut().zip(b) {
            *ri = bi - *ri;
        }
        let rc = self.restrictions[l].apply(&r);
        let mut xc = vec![0.0; rc.len()];
        self.cycle(l + 1, &rc, &mut xc);
        self.prolongations[l].mul_vec(&xc, &mut r);
        for (xi, ci) in x.iter_mut().zip(&r) {
            *xi += ci;
        }
        if self.gamma > 1 && l + 2 < self.levels() {
            a.mul_vec(x, &mut r);
            for (ri, bi) in r.iter_mut().zip(b) {
                *ri = bi - *ri;
            }
            let rc = self.restrictions[l].apply(&r);
            let mut xc = vec![0.0; rc.len()];
            self.cycle(l + 1, &rc, &mut xc);
            self.prolongations[l].mul_vec(&xc, &mut r);
            for (xi, ci) in x.iter_mut().zip(&r) {
                *xi += ci;
            }
        }
        for _ in 0..self.sweeps {
            self.smooth(l, b, x, &mut r, true);
        }
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
            Smoother::Lines => {
                let mut scratch = Vec::new();
                let [l0, l1] = &self.lines[l];
                if backward {
                    l1.sweep(a, b, x, true, &mut scratch);
                    l0.sweep(a, b, x, true, &mut scratch);
                } else {
                    l0.sweep(a, b, x, false, &mut scratch);
                    l1.sweep(a, b, x, false, &mut scratch);
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
