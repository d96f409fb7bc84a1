//! Linear solvers behind one interface: sparse LU (faer; the symbolic factorization is
//! computed once per sparsity pattern and reused for every numeric factorization; dense
//! LU for systems of at most `DENSE_LIMIT` unknowns, `linalg::dense`), sparse
//! Cholesky for symmetric positive definite systems, and restarted GMRES for systems past
//! what LU handles, preconditioned either by the problem's own SPD approximation
//! `-diag(K, K)` of the Jacobian (a sparse Cholesky of the scalar `K`, see
//! `crate::discrete::assembly::Discretization::metric_laplace`) or by ILU(0).
//!
//! The Cholesky factorizations follow the problem's fill-reducing order when it gives one
//! (`LinearSolver::set_ordering`, nested dissection of the spline grid, see
//! [`crate::linalg::ordering`]), approximate minimum degree otherwise; their symbolic analysis,
//! numeric storage and scratch memory are allocated once and reused by every
//! refactorization and solve.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::linalg::dense::{DenseCholesky, DenseLu, DENSE_LIMIT};
use crate::linalg::krylov::{cg, gmres, Ilu0, MatVec};
use crate::linalg::multigrid::kernels::CycleBackend;
use crate::linalg::multigrid::{GridStencil, Multigrid, Smoother, TensorProlongation};
use crate::linalg::ordering;
use crate::linalg::sparse::Csr;

use cholesky::{Cholesky, Direct, Scalar};

/// Which linear solver the nonlinear solvers use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum LinearMethod {
    /// Sparse direct LU; dense (`DenseLu`) up to `DENSE_LIMIT` unknowns.
    #[default]
    #[cfg_attr(feature = "clap", value(help = "Sparse direct LU"))]
    Lu,
    /// Restarted flexible GMRES(50), relative tolerance 1e-10, preconditioned by the problem's
    /// SPD approximation when it offers one, by ILU(0) otherwise.
    #[cfg_attr(feature = "clap", value(help = "GMRES, preconditioned by the metric Laplacian"))]
    Gmres,
    /// LU up to `AUTO_LU_LIMIT` unknowns, GMRES above; GMRES falls back to LU when it
    /// does not converge within `AUTO_MAX_KRYLOV` iterations. The solve pipeline resolves
    /// it per level for EGG on a patch: [`LinearMethod::Multigrid`] from
    /// `solve::memory::AUTO_MULTIGRID_UNKNOWNS` unknowns on, and on a level whose
    /// estimated peak with the factorization exceeds the memory limit
    /// (`solve::memory::auto_linear`).
    #[cfg_attr(
        feature = "clap",
        value(
            help = "LU up to 64 unknowns, GMRES above (LU again when GMRES needs 500 iterations); multigrid from 800 000 unknowns on, or where the factorization would not fit in --max-memory"
        )
    )]
    Auto,
    /// Restarted flexible GMRES as [`LinearMethod::Gmres`], preconditioned by
    /// `-diag(B, B)` with `B` one multigrid V-cycle for the problem's SPD approximation
    /// `K` on the nested spaces set with `LinearSolver::set_transfers`
    /// (`linalg::multigrid`); without them as [`LinearMethod::Gmres`].
    #[cfg_attr(
        feature = "clap",
        value(help = "GMRES, preconditioned by a multigrid V-cycle on the knot-halving hierarchy")
    )]
    Multigrid,
    /// Sparse Cholesky `L L^T` (symmetric positive definite systems only).
    #[cfg_attr(feature = "clap", value(skip))]
    Cholesky,
    /// Sparse Cholesky of `-A` (symmetric negative definite systems: `A = -∇²J` of a
    /// minimisation near its minimiser). Factorizing fails, with a typed error, exactly
    /// when `-A` is not positive definite: the caller then modifies `A` (a larger
    /// diagonal shift) and factorizes again.
    #[cfg_attr(feature = "clap", value(skip))]
    NegCholesky,
    /// Conjugate gradients for symmetric positive definite systems of `c` components
    /// (`c m` unknowns in component blocks, `m` the length of the ordering given with
    /// `LinearSolver::set_ordering`), preconditioned by the single-precision Cholesky
    /// factors of the `c` diagonal blocks (block Jacobi: for linear elasticity the
    /// iteration count is bounded by Korn's inequality, not by the mesh size). Falls
    /// back to [`LinearMethod::Cholesky`] when CG does not converge in `MAX_PCG`
    /// iterations.
    #[cfg_attr(feature = "clap", value(skip))]
    Pcg,
}

/// Iterations after which [`LinearMethod::Pcg`] gives up for a direct factorization.
pub(crate) const MAX_PCG: usize = 500;

/// Largest system that [`LinearMethod::Auto`] factorizes directly. Preconditioned GMRES
/// overtakes faer's sparse LU on the EGG Jacobian at about 64 unknowns (measured on the
/// shared G+Smo geometries on their input bases: 96 unknowns 1.9 against 2.1 ms per
/// solve, 384: 5.1 against 12 ms, 988: 29 against 71 ms; 32-50 unknowns: LU faster by
/// 0.1-0.6 ms).
pub(crate) const AUTO_LU_LIMIT: usize = 64;

/// Default relative residual at which GMRES stops.
pub(crate) const KRYLOV_TOL: f64 = 1e-10;

/// GMRES iterations per solve after which [`LinearMethod::Gmres`] gives up.
pub(crate) const MAX_KRYLOV: usize = 2000;

/// GMRES iterations per solve after which [`LinearMethod::Auto`] factorizes the system
/// by LU instead (for the rest of the solve); `n / 8` (at least 100) for `n < 4000`
/// unknowns, where LU is cheap: with the problem's SPD preconditioner an EGG solve takes
/// at most 30 iterations on the shared geometries; one that takes this many has a
/// preconditioner that does not fit the operator (the weak form, eq. 14, on cells of
/// aspect ratio ~100: 2000 iterations per Newton step), and LU is cheaper.
pub(crate) const AUTO_MAX_KRYLOV: usize = 500;

pub(crate) use super::multigrid::{MG_SMOOTHER, MG_SWEEPS};

/// GMRES iterations above which a frozen SPD preconditioner is rebuilt.
pub(crate) const REFRESH_KRYLOV: usize = 30;

/// A GMRES preconditioner.
#[derive(Debug)]
enum Preconditioner {
    Ilu(Ilu0),
    /// `P = -diag(K, ..., K)`, `K = L L^T` in single precision (whole, or split at the
    /// top separator: [`LinearSolver::set_split_preconditioner`]) ...
    NegBlock32(Box<Direct<f32>>),
    /// ... or in double precision.
    NegBlock(Box<Cholesky<f64>>),
    /// `P = diag(K_11, ..., K_cc)`, the diagonal blocks of the matrix (block Jacobi).
    BlockJacobi(Vec<Cholesky<f32>>),
    /// `P = -diag(B, ..., B)`, `B` a multigrid V-cycle for `K`.
    NegMultigrid(Box<Multigrid>),
    /// `P = diag(B_1, ..., B_c)`, `B_z` a symmetric multigrid V-cycle for the diagonal
    /// block `A_zz` (block Jacobi with V-cycles, for CG).
    BlockMultigrid(Vec<Multigrid>),
}

impl Preconditioner {
    /// `x = P^{-1} b`.
    fn apply(&mut self, b: &[f64], x: &mut [f64]) {
        let negate = |x: &mut [f64]| {
            for (xi, bi) in x.iter_mut().zip(b) {
                *xi = -bi;
            }
        };
        match self {
            Self::Ilu(ilu) => ilu.apply(b, x),
            Self::NegBlock32(k) => {
                negate(x);
                k.solve_columns(x);
            }
            Self::NegBlock(k) => {
                negate(x);
                k.solve_columns(x);
            }
            Self::BlockJacobi(blocks) => {
                x.copy_from_slice(b);
                let m = x.len() / blocks.len();
                blocks.par_iter_mut().zip(x.par_chunks_mut(m)).for_each(|(k, xs)| k.solve_columns(xs));
            }
            Self::NegMultigrid(mg) => {
                let m = mg.size();
                // the components on their own threads
                b.par_chunks(m).zip(x.par_chunks_mut(m)).for_each(|(bs, xs)| {
                    mg.apply(bs, xs);
                    xs.iter_mut().for_each(|v| *v = -*v);
                });
            }
            Self::BlockMultigrid(cycles) => {
                let m = x.len() / cycles.len().max(1);
                cycles.par_iter().zip(b.par_chunks(m).zip(x.par_chunks_mut(m))).for_each(|(mg, (bs, xs))| {
                    mg.apply(bs, xs);
                });
            }
        }
    }

    fn is_block(&self) -> bool {
        matches!(self, Self::NegBlock32(..) | Self::NegBlock(..) | Self::NegMultigrid(..))
    }
}

/// A factorization-capable solver bound to one sparsity pattern.
#[derive(Debug)]
pub struct LinearSolver {
    method: LinearMethod,
    symbolic: Option<SymbolicLu<usize>>,
    lu: Option<Lu<usize, f64>>,
    /// LU of a system of at most [`DENSE_LIMIT`] unknowns (dense, no symbolic analysis).
    dense: Option<DenseLu>,
    /// Cholesky of a system of at most [`DENSE_LIMIT`] unknowns (of `-A` for
    /// [`LinearMethod::NegCholesky`]).
    dense_llt: Option<DenseCholesky>,
    llt: Option<Direct>,
    precond: Option<Preconditioner>,
    matrix: Option<Csr>,
    /// Fill-reducing order of the `m` scalar unknowns (see [`LinearSolver::set_ordering`]).
    order: Option<Vec<usize>>,
    /// The prolongations of the multigrid hierarchy (see [`LinearSolver::set_transfers`]).
    transfers: Vec<TensorProlongation>,
    /// Where the multigrid cycle's level work runs (see [`LinearSolver::set_cycle_backend`]).
    cycle_backend: Option<std::sync::Arc<dyn CycleBackend>>,
    /// Total GMRES iterations spent (diagnostics).
    pub krylov_iterations: usize,
    /// The most GMRES iterations one solve took (diagnostics).
    pub krylov_max: usize,
    /// Solves so far (diagnostics).
    pub solves: usize,
    last_krylov: usize,
    /// The preconditioner was factorized for the next solve.
    fresh: bool,
    /// The single-precision preconditioner failed: factorize in double precision.
    double: bool,
    /// Factorize the single-precision preconditioner `K` split at its top separator
    /// (see [`LinearSolver::set_split_preconditioner`]).
    split_preconditioner: bool,
    fallback: bool,
    /// Relative residual at which GMRES stops.
    pub krylov_tol: f64,
    /// `-A` for [`LinearMethod::NegCholesky`] (pattern copied once).
    negated: Csr,
    /// The symbolic analysis of a [`LinearMethod::NegCholesky`] factorization that failed
    /// (reused by the next one).
    analysed: Option<Direct>,
}

impl LinearSolver {
    /// A solver using `method`.
    pub fn new(method: LinearMethod) -> Self {
        let fallback = method == LinearMethod::Auto;
        Self {
            method,
            symbolic: None,
            lu: None,
            dense: None,
            dense_llt: None,
            llt: None,
            precond: None,
            matrix: None,
            order: None,
            transfers: Vec::new(),
            cycle_backend: None,
            krylov_iterations: 0,
            krylov_max: 0,
            solves: 0,
            last_krylov: 0,
            fresh: false,
            double: false,
            split_preconditioner: false,
            fallback,
            krylov_tol: KRYLOV_TOL,
            negated: Csr::default(),
            analysed: None,
        }
    }

    /// Use `order` (`order[new] = old`, a permutation of the `m` scalar unknowns, e.g.
    /// [`crate::linalg::ordering::nested_dissection`] of the spline grid) for the Cholesky
    /// factorizations: of the scalar preconditioner `K` (size `m`) directly, of a system
    /// of `c` component blocks (size `c m`) point by point ([`crate::linalg::ordering::interleave`]).
    /// Without it, approximate minimum degree.
    pub(crate) fn set_ordering(&mut self, order: &[usize]) {
        self.order = Some(order.to_vec());
    }

    /// Factorize the single-precision preconditioner `K` of [`LinearMethod::Gmres`] split
    /// at the top separator of the order given with [`LinearSolver::set_ordering`], the
    /// two halves at once on two threads ([`crate::linalg::split_cholesky`], from
    /// `SPLIT_MIN` unknowns), instead of whole on one. For volumes: the factorization of
    /// their `K` is one sequential stage of the solve (BENCHMARKS.md, issue 33). The
    /// planar solves keep the whole factor (and the results measured with it).
    pub(crate) fn set_split_preconditioner(&mut self) {
        self.split_preconditioner = true;
    }

    /// The nested spaces of [`LinearMethod::Multigrid`]: `transfers[l] = [P_0, P_1]` maps
    /// the free scalar unknowns of space `l + 1` to those of space `l` by `P_1 ⊗ P_0`,
    /// space 0 the one of the problem's `m` scalar unknowns (see `discrete::transfers`).
    pub(crate) fn set_transfers(&mut self, transfers: Vec<[Csr; 2]>) {
        self.transfers = transfers.into_iter().map(TensorProlongation::from).collect();
    }

    /// Run the level work of [`LinearMethod::Multigrid`]'s cycle on `backend` (the GPU
    /// crate's kernels) instead of the CPU, where it takes the cycle.
    pub(crate) fn set_cycle_backend(&mut self, backend: Option<std::sync::Arc<dyn CycleBackend>>) {
        self.cycle_backend = backend;
    }

    /// A multigrid cycle on the hierarchy and back end of this solver.
    fn new_multigrid(&self) -> Box<Multigrid> {
        let mut mg = Multigrid::new(self.transfers.clone(), MG_SMOOTHER, MG_SWEEPS);
        mg.set_backend(self.cycle_backend.clone());
        Box::new(mg)
    }

    /// The fill-reducing order for a matrix of `n` unknowns, if one is known.
    fn order_for(&self, n: usize) -> Option<Vec<usize>> {
        let order = self.order.as_ref()?;
        let m = order.len();
        (m > 0 && n.is_multiple_of(m)).then(|| ordering::interleave(order, n / m))
    }

    /// Factorize the SPD `a` into `slot`, reusing its analysis when the size matches.
    fn cholesky<T: Scalar>(&self, a: &Csr, slot: Option<Cholesky<T>>) -> Result<Cholesky<T>> {
        let mut chol = match slot {
            Some(c) if c.dim() == a.nrows => c,
            _ => Cholesky::analyze(a, self.order_for(a.nrows).as_deref())?,
        };
        chol.factor(a)?;
        Ok(chol)
    }

    /// `-diag(K, K)` factorized, reusing the analysis of `previous`: in single precision
    /// while that works (definite, and GMRES converging within [`REFRESH_KRYLOV`]
    /// iterations right after a factorization), in double precision after that, ILU(0)
    /// of `a` when `K` is not definite.
    fn block_preconditioner(
        &mut self,
        a: Option<&Csr>,
        k: &Csr,
        previous: Option<Preconditioner>,
    ) -> Result<Preconditioner> {
        let (slot32, slot64) = match previous {
            Some(Preconditioner::NegBlock32(c)) => (Some(c), None),
            Some(Preconditioner::NegBlock(c)) => (None, Some(*c)),
            _ => (None, None),
        };
        if !self.double {
            let mut chol = match slot32 {
                Some(c) if c.dim() == k.nrows => c,
                _ if self.split_preconditioner => Box::new(Direct::analyze(k, self.order_for(k.nrows).as_deref())?),
                _ => Box::new(Direct::Whole(Box::new(Cholesky::analyze(k, self.order_for(k.nrows).as_deref())?))),
            };
            match chol.factor(k) {
                Ok(()) => return Ok(Preconditioner::NegBlock32(chol)),
                Err(_) => self.double = true,
            }
        }
        Ok(match (self.cholesky::<f64>(k, slot64), a) {
            (Ok(c), _) => Preconditioner::NegBlock(Box::new(c)),
            (Err(_), Some(a)) => Preconditioner::Ilu(Ilu0::new(a)?),
            (Err(e), None) => return Err(e),
        })
    }

    /// The method in use ([`LinearMethod::Auto`] until the first factorization).
    pub fn method(&self) -> LinearMethod {
        self.method
    }

    /// Whether [`LinearSolver::factor_preconditioned`] needs a (new) SPD approximation
    /// for a system of `n` unknowns: only GMRES uses one, and it keeps the last one
    /// (a frozen preconditioner across Newton steps) while GMRES needs at most
    /// [`REFRESH_KRYLOV`] iterations with it.
    pub(crate) fn wants_preconditioner(&self, n: usize) -> bool {
        let fresh = !self.precond.as_ref().is_some_and(Preconditioner::is_block) || self.last_krylov > REFRESH_KRYLOV;
        match self.method {
            LinearMethod::Gmres | LinearMethod::Multigrid => fresh,
            LinearMethod::Auto => n > AUTO_LU_LIMIT,
            LinearMethod::Lu | LinearMethod::Cholesky | LinearMethod::NegCholesky | LinearMethod::Pcg => false,
        }
    }

    /// Factorize (LU, Cholesky) or precondition (GMRES, with ILU(0)) the matrix `a`.
    pub fn factor(&mut self, a: &Csr) -> Result<()> {
        self.factor_preconditioned(a, None)
    }

    /// As [`LinearSolver::factor`]; GMRES uses `P = -diag(K, K)` as preconditioner when
    /// `k` (SPD, `a.nrows` a multiple of its size) is given.
    pub(crate) fn factor_preconditioned(&mut self, a: &Csr, k: Option<&Csr>) -> Result<()> {
        self.resolve(a.nrows);
        if matches!(self.method, LinearMethod::Gmres | LinearMethod::Multigrid | LinearMethod::Pcg) {
            // the Krylov methods multiply with `a`: keep it
            self.matrix_mut().update(a);
            self.factor_stored(k)
        } else {
            self.factor_matrix(a, k)
        }
    }

    /// Resolve [`LinearMethod::Auto`] for a system of `n` unknowns.
    fn resolve(&mut self, n: usize) {
        if self.method == LinearMethod::Auto {
            self.method = if n <= AUTO_LU_LIMIT { LinearMethod::Lu } else { LinearMethod::Gmres };
        }
    }

    /// The solver's storage of the system matrix: fill it (with
    /// [`Csr::update`] the pattern is copied once) and call
    /// [`LinearSolver::factor_stored`], without a copy of the matrix per factorization.
    pub(crate) fn matrix_mut(&mut self) -> &mut Csr {
        self.matrix.get_or_insert_with(Csr::default)
    }

    /// Factorize (LU, Cholesky) or precondition (GMRES) the matrix in
    /// [`LinearSolver::matrix_mut`]; GMRES uses `P = -diag(K, K)` as preconditioner when
    /// `k` (SPD, `a.nrows` a multiple of its size) is given. The CSR storage of `a` is
    /// the CSC storage of `a^T`; faer factors `a^T` and we solve with its transpose.
    pub(crate) fn factor_stored(&mut self, k: Option<&Csr>) -> Result<()> {
        let a = self.matrix.take().ok_or_else(|| Error::LinearSolver("no matrix to factor".into()))?;
        let r = self.factor_matrix(&a, k);
        self.matrix = Some(a);
        r
    }

    fn factor_matrix(&mut self, a: &Csr, k: Option<&Csr>) -> Result<()> {
        self.resolve(a.nrows);
        match self.method {
            LinearMethod::Lu if a.nrows <= DENSE_LIMIT => {
                let mut lu = self.dense.take().unwrap_or_default();
                lu.factor(a)?;
                self.dense = Some(lu);
            }
            LinearMethod::Lu => {
                self.dense = None;
                let sym = SymbolicSparseColMatRef::new_checked(a.ncols, a.nrows, &a.row_ptr, None, &a.col_idx);
                if self.symbolic.is_none() {
                    self.symbolic =
                        Some(SymbolicLu::try_new(sym).map_err(|e| Error::LinearSolver(format!("symbolic LU: {e:?}")))?);
                }
                let symbolic = self.symbolic.clone().expect("set above");
                let mat = SparseColMatRef::new(sym, &a.values);
                self.lu = Some(
                    Lu::try_new_with_symbolic(symbolic, mat)
                        .map_err(|e| Error::LinearSolver(format!("numeric LU: {e:?}")))?,
                );
            }
            LinearMethod::Cholesky | LinearMethod::NegCholesky if a.nrows <= DENSE_LIMIT => {
                let sign = if self.method == LinearMethod::NegCholesky { -1.0 } else { 1.0 };
                // a failed factorization leaves no factor to solve with
                let mut llt = self.dense_llt.take().unwrap_or_default();
                llt.factor(a, sign)?;
                self.dense_llt = Some(llt);
            }
            LinearMethod::Cholesky => {
                let mut chol = match self.llt.take() {
                    Some(c) if c.dim() == a.nrows => c,
                    _ => Direct::analyze(a, self.order_for(a.nrows).as_deref())?,
                };
                chol.factor(a)?;
                self.llt = Some(chol);
            }
            LinearMethod::NegCholesky => {
                let mut neg = std::mem::take(&mut self.negated);
                neg.update(a);
                for v in neg.values.iter_mut() {
                    *v = -*v;
                }
                // a failed numeric factorization (not positive definite: a minimisation
                // then modifies its Hessian and factorizes again) keeps the analysis
                let chol = match self.llt.take().or_else(|| self.analysed.take()) {
                    Some(c) if c.dim() == neg.nrows => Ok(c),
                    _ => Direct::analyze(&neg, self.order_for(neg.nrows).as_deref()),
                };
                let r = match chol {
                    Ok(mut c) => match c.factor(&neg) {
                        Ok(()) => Ok(c),
                        Err(e) => {
                            self.analysed = Some(c);
                            Err(e)
                        }
                    },
                    Err(e) => Err(e),
                };
                self.negated = neg;
                self.llt = Some(r?);
            }
            LinearMethod::Gmres | LinearMethod::Multigrid => self.factor_krylov(a.nrows, Some(a), k)?,
            LinearMethod::Pcg => {
                let blocks = self.order.as_ref().map_or(1, |o| a.nrows / o.len().max(1)).max(1);
                let m = a.nrows / blocks;
                let factors = (0..blocks)
                    .into_par_iter()
                    .map(|z| self.cholesky::<f32>(&diagonal_block(a, z * m, m), None))
                    .collect::<Result<Vec<_>>>()?;
                self.precond = Some(Preconditioner::BlockJacobi(factors));
            }
            LinearMethod::Auto => unreachable!("resolved above"),
        }
        Ok(())
    }

    /// As [`LinearSolver::factor_stored`] for a system of `n` unknowns that is held as an
    /// operator, not a matrix ([`LinearSolver::solve_operator`] multiplies with it): sets
    /// up the preconditioner of [`LinearMethod::Gmres`] or [`LinearMethod::Multigrid`]
    /// from `k` (`P = -diag(K, K)` or its V-cycle), or keeps the frozen one when `k` is
    /// `None`.
    ///
    /// Errors: [`Error::LinearSolver`] for the other methods, and when there is no
    /// preconditioner to keep or `k` is not definite (ILU(0) would need the matrix).
    pub(crate) fn factor_operator(&mut self, n: usize, k: Option<&Csr>) -> Result<()> {
        self.resolve(n);
        if !matches!(self.method, LinearMethod::Gmres | LinearMethod::Multigrid) {
            return Err(Error::LinearSolver(format!("{:?} needs the matrix, not an operator", self.method)));
        }
        self.factor_krylov(n, None, k)
    }

    /// As [`LinearSolver::factor_operator`] with `k` handed over: the multigrid V-cycle
    /// of [`LinearMethod::Multigrid`] keeps it as its finest operator (no copy), the other
    /// preconditioners are set up from it as from a borrowed one.
    ///
    /// Errors: as [`LinearSolver::factor_operator`].
    pub(crate) fn factor_operator_owned(&mut self, n: usize, k: Option<Csr>) -> Result<()> {
        self.resolve(n);
        let fits = |k: &Csr| self.transfers.first().is_some_and(|p| p.nrows() == k.nrows && n.is_multiple_of(k.nrows));
        match k {
            Some(k) if self.method == LinearMethod::Multigrid && fits(&k) => {
                self.set_up_multigrid(|mg| mg.factor_owned(k))
            }
            k => self.factor_operator(n, k.as_ref()),
        }
    }

    /// The multigrid preconditioner (the last one's cycle reused) set up by `factor`.
    fn set_up_multigrid(&mut self, factor: impl FnOnce(&mut Multigrid) -> Result<()>) -> Result<()> {
        let mut mg = match self.precond.take() {
            Some(Preconditioner::NegMultigrid(mg)) => mg,
            _ => self.new_multigrid(),
        };
        factor(&mut mg)?;
        self.precond = Some(Preconditioner::NegMultigrid(mg));
        self.fresh = true;
        self.last_krylov = 0;
        Ok(())
    }

    /// As [`LinearSolver::factor_operator_owned`] with `K` as a grid stencil
    /// (`Multigrid::factor_stencil`: no CSR matrix of `K`); a method other than
    /// [`LinearMethod::Multigrid`], or a hierarchy of another size, gets its CSR matrix.
    ///
    /// Errors: as [`LinearSolver::factor_operator`].
    pub(crate) fn factor_operator_grid(&mut self, n: usize, k: GridStencil) -> Result<()> {
        self.resolve(n);
        let m = k.nx * k.ny;
        if self.method != LinearMethod::Multigrid
            || m == 0
            || !n.is_multiple_of(m)
            || self.transfers.first().is_none_or(|p| p.nrows() != m)
        {
            return self.factor_operator_owned(n, Some(k.to_csr()));
        }
        self.set_up_multigrid(|mg| mg.factor_stencil(k))
    }

    /// Free the operators of a multigrid preconditioner that is about to be set up again
    /// ([`LinearSolver::wants_preconditioner`]), before its new operator is built; the
    /// other preconditioners are kept (their analysis is reused).
    pub(crate) fn release_multigrid(&mut self) {
        if matches!(self.precond, Some(Preconditioner::NegMultigrid(..))) {
            self.precond = None;
        }
    }

    /// [`LinearMethod::Pcg`] for a system held as an operator: the block-Jacobi
    /// preconditioner from the diagonal blocks `blocks` of the system (each SPD, of the
    /// size of the ordering given with [`LinearSolver::set_ordering`]), factorized in
    /// single precision as [`LinearSolver::factor`] of the whole matrix factorizes them;
    /// [`LinearSolver::solve_operator`] then runs CG with the operator.
    ///
    /// Errors: [`Error::LinearSolver`] for the other methods, or when a block is not
    /// positive definite.
    pub(crate) fn factor_blocks(&mut self, blocks: &[Csr]) -> Result<()> {
        if self.method != LinearMethod::Pcg {
            return Err(Error::LinearSolver(format!("{:?} has no block-Jacobi preconditioner", self.method)));
        }
        let factors = blocks.par_iter().map(|b| self.cholesky::<f32>(b, None)).collect::<Result<Vec<_>>>()?;
        self.precond = Some(Preconditioner::BlockJacobi(factors));
        Ok(())
    }

    /// [`LinearMethod::Pcg`] for a system held as an operator, preconditioned by
    /// symmetric multigrid V-cycles of its diagonal blocks (`diag(B_1, ..., B_c)`, block
    /// Jacobi with each block's cycle on the hierarchy of [`LinearSolver::set_transfers`],
    /// alternating coloured line Gauss–Seidel before and its adjoint after the coarse
    /// correction: a symmetric cycle, as CG needs): this adds the cycle of the next
    /// block, which it keeps as its finest operator (the blocks handed over one at a time,
    /// so that one block's matrix exists at a time). [`LinearSolver::solve_operator`]
    /// then runs CG with the operator.
    ///
    /// Errors: [`Error::LinearSolver`] for the other methods, without a hierarchy of the
    /// block's size, or as `Multigrid::factor_owned`.
    pub(crate) fn factor_block_multigrid(&mut self, block: Csr) -> Result<()> {
        if self.method != LinearMethod::Pcg || self.transfers.first().is_none_or(|p| p.nrows() != block.nrows) {
            return Err(Error::LinearSolver("no multigrid hierarchy for this block".into()));
        }
        let mut mg = Multigrid::new(self.transfers.clone(), Smoother::ColouredLines, MG_SWEEPS);
        mg.factor_owned(block)?;
        match &mut self.precond {
            Some(Preconditioner::BlockMultigrid(cycles)) => cycles.push(mg),
            _ => self.precond = Some(Preconditioner::BlockMultigrid(vec![mg])),
        }
        Ok(())
    }

    /// The preconditioner of the GMRES methods for a system of `n` unknowns, the matrix
    /// `a` when there is one (for ILU(0)).
    fn factor_krylov(&mut self, n: usize, a: Option<&Csr>, k: Option<&Csr>) -> Result<()> {
        let block = k.filter(|k| k.nrows > 0 && n.is_multiple_of(k.nrows));
        let previous = self.precond.take();
        let multigrid = self.method == LinearMethod::Multigrid
            && block.is_some_and(|k| self.transfers.first().is_some_and(|p| p.nrows() == k.nrows));
        let no_matrix = || Error::LinearSolver("ILU(0) needs the matrix: no preconditioner for an operator".into());
        self.precond = match (block, previous) {
            // the multigrid hierarchy set up (again) for the new approximation
            (Some(k), previous) if multigrid => {
                let mut mg = match previous {
                    Some(Preconditioner::NegMultigrid(mg)) => mg,
                    _ => self.new_multigrid(),
                };
                mg.factor_owned(k.clone())?;
                Some(Preconditioner::NegMultigrid(mg))
            }
            // a new approximation: refactor in place (same pattern), in single
            // precision unless that failed before or was not definite ...
            (Some(k), previous) => Some(self.block_preconditioner(a, k, previous)?),
            // ... or keep the previous one (frozen preconditioner)
            (None, Some(p)) if p.is_block() => Some(p),
            // none at all: ILU(0)
            (None, _) => Some(Preconditioner::Ilu(Ilu0::new(a.ok_or_else(no_matrix)?)?)),
        };
        self.fresh = true;
        self.last_krylov = 0;
        Ok(())
    }

    /// Solve `a x = b` with the last factorized `a`.
    pub fn solve(&mut self, b: &[f64]) -> Result<Vec<f64>> {
        self.solve_with(None, b)
    }

    /// Solve `a x = b` by GMRES (CG for [`LinearMethod::Pcg`]) with the operator `a` (the
    /// system [`LinearSolver::factor_operator`] or [`LinearSolver::factor_blocks`] set up
    /// the preconditioner for): the same iterates as [`LinearSolver::solve`] with the
    /// matrix whose product `a` computes, without its fallback to a direct factorization
    /// (an error instead).
    pub(crate) fn solve_operator(&mut self, a: &dyn MatVec, b: &[f64]) -> Result<Vec<f64>> {
        if !matches!(self.method, LinearMethod::Gmres | LinearMethod::Multigrid | LinearMethod::Pcg) {
            return Err(Error::LinearSolver(format!("{:?} solves with a matrix, not an operator", self.method)));
        }
        self.solve_with(Some(a), b)
    }

    /// [`LinearSolver::solve`], with the operator `op` instead of the stored matrix for
    /// the GMRES methods when given.
    fn solve_with(&mut self, op: Option<&dyn MatVec>, b: &[f64]) -> Result<Vec<f64>> {
        self.solves += 1;
        let x = match self.method {
            LinearMethod::Lu if self.dense.is_some() => self.dense.as_ref().expect("checked").solve(b),
            LinearMethod::Lu => {
                let lu = self.lu.as_ref().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?;
                let mut x = faer::Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
                lu.solve_transpose_in_place(x.as_mut());
                (0..b.len()).map(|i| x[(i, 0)]).collect::<Vec<_>>()
            }
            LinearMethod::Cholesky | LinearMethod::NegCholesky if self.dense_llt.is_some() => {
                // (-A) x = -b for NegCholesky, whose factor is that of -A
                let sign = if self.method == LinearMethod::NegCholesky { -1.0 } else { 1.0 };
                let mut x: Vec<f64> = b.iter().map(|v| sign * v).collect();
                self.dense_llt.as_ref().expect("checked").solve_columns(&mut x);
                x
            }
            LinearMethod::Cholesky => {
                let llt = self.llt.as_mut().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?;
                let mut x = b.to_vec();
                llt.solve_columns(&mut x);
                x
            }
            LinearMethod::NegCholesky => {
                // A x = b  <=>  (-A) x = -b
                let llt = self.llt.as_mut().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?;
                let mut x: Vec<f64> = b.iter().map(|v| -v).collect();
                llt.solve_columns(&mut x);
                x
            }
            LinearMethod::Gmres | LinearMethod::Multigrid => {
                let a: &dyn MatVec = match op {
                    Some(op) => op,
                    None => self.matrix.as_ref().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?,
                };
                let pc = self.precond.as_mut().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?;
                // a direct factorization of a small system costs few GMRES iterations
                let cap = if self.fallback { (b.len() / 8).clamp(100, AUTO_MAX_KRYLOV) } else { MAX_KRYLOV };
                match gmres(a, b, |r, z| pc.apply(r, z), 50, self.krylov_tol, cap) {
                    Ok((x, it)) => {
                        self.krylov_iterations += it;
                        self.krylov_max = self.krylov_max.max(it);
                        self.last_krylov = it;
                        if std::mem::take(&mut self.fresh)
                            && it > REFRESH_KRYLOV
                            && matches!(self.precond, Some(Preconditioner::NegBlock32(..)))
                        {
                            self.double = true;
                        }
                        x
                    }
                    Err(e) if self.fallback && op.is_none() => {
                        // GMRES did not converge: factorize this matrix directly instead
                        self.method = LinearMethod::Lu;
                        self.fallback = false;
                        self.factor_stored(None).map_err(|f| Error::LinearSolver(format!("{e}; LU fallback: {f}")))?;
                        self.solves -= 1;
                        return self.solve(b);
                    }
                    Err(e) => return Err(e),
                }
            }
            LinearMethod::Pcg => {
                let a: &dyn MatVec = match op {
                    Some(op) => op,
                    None => self.matrix.as_ref().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?,
                };
                let pc = self.precond.as_mut().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?;
                match cg(a, b, |r, z| pc.apply(r, z), self.krylov_tol, MAX_PCG) {
                    Ok((x, it)) => {
                        self.krylov_iterations += it;
                        x
                    }
                    Err(e) if op.is_some() => return Err(e),
                    Err(_) => {
                        // slow convergence (a thin domain has a poor Korn constant):
                        // factorize the whole system instead
                        self.method = LinearMethod::Cholesky;
                        self.precond = None;
                        self.factor_stored(None)?;
                        self.solves -= 1;
                        return self.solve(b);
                    }
                }
            }
            LinearMethod::Auto => unreachable!("resolved in factor"),
        };
        if x.iter().any(|v| !v.is_finite()) {
            return Err(Error::LinearSolver("singular system (non-finite solution)".into()));
        }
        Ok(x)
    }
}

/// The diagonal block of `a` with rows and columns `first..first + m`.
fn diagonal_block(a: &Csr, first: usize, m: usize) -> Csr {
    let mut row_ptr = Vec::with_capacity(m + 1);
    row_ptr.push(0);
    let (mut col_idx, mut values) = (Vec::new(), Vec::new());
    for r in first..first + m {
        for (c, v) in a.row(r) {
            if (first..first + m).contains(&c) {
                col_idx.push(c - first);
                values.push(v);
            }
        }
        row_ptr.push(col_idx.len());
    }
    Csr { nrows: m, ncols: m, row_ptr, col_idx, values }
}

/// Dense solve `A X = B` (`A` is `n x n`, row-major; `B` is `n x m`) by faer's LU with
/// partial pivoting.
pub(crate) fn dense_solve(a: &[Vec<f64>], b: &[Vec<f64>]) -> Vec<Vec<f64>> {
    use faer::linalg::solvers::Solve;
    let n = a.len();
    let m = b.first().map_or(0, |r| r.len());
    let am = faer::Mat::<f64>::from_fn(n, n, |i, j| a[i][j]);
    let bm = faer::Mat::<f64>::from_fn(n, m, |i, j| b[i][j]);
    let x = am.partial_piv_lu().solve(&bm);
    (0..n).map(|i| (0..m).map(|j| x[(i, j)]).collect()).collect()
}

mod cholesky;
#[cfg(test)]
mod tests;
