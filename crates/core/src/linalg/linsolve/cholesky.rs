//! The sparse Cholesky factors of [`super::LinearSolver`]: `A = L L^T` with the symbolic
//! analysis once per pattern and the numeric factorization into storage allocated up
//! front, in double precision (direct solves, whole or split at the top separator) or
//! single precision (the preconditioner `-diag(K, K)`).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Par, Side};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::linalg::ordering;
use crate::linalg::sparse::Csr;
pub(super) use crate::linalg::split_cholesky::Scalar;
use crate::linalg::split_cholesky::{SplitCholesky, SPLIT_MIN};

/// The parallelism of the numeric Cholesky factorizations: sequential. faer's
/// rayon-parallel supernodal factorization was 2-3x slower on 2 cores at every size
/// measured (the Winslow Hessian of jigsaw01, 9984 unknowns: 0.24 s against 0.11 s of
/// factorizations; the EGG preconditioner of the quarter annulus at 230 k unknowns:
/// whole solve 3.8 s against 2.0 s), and its idle workers spinning slowed the parallel
/// assembly around it. The parallelism of a solve is in its element loops, and in the
/// two halves of a direct factorization split at its top separator ([`Direct`]).
const CHOLESKY_PAR: Par = Par::Seq;

/// Sparse Cholesky `A = L L^T` of an SPD matrix with a fixed sparsity pattern: symbolic
/// analysis (ordering, elimination tree, supernodes) once, then numeric factorizations
/// and solves into storage allocated up front.
pub(super) struct Cholesky<T: Scalar> {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<T>,
    factor_scratch: MemBuffer,
    /// The matrix entries in `T` (empty for `f64`).
    entries: Vec<T>,
    /// One scratch and one conversion buffer per right-hand side, so that columns are
    /// solved in parallel.
    solve_scratch: Vec<(MemBuffer, Vec<T>)>,
}

impl<T: Scalar> std::fmt::Debug for Cholesky<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cholesky")
            .field("n", &self.symbolic.nrows())
            .field("nnz_l", &self.values.len())
            .field("bytes", &std::mem::size_of::<T>())
            .finish()
    }
}

/// The pattern of the symmetric `a` as faer's column storage (CSR of a symmetric matrix
/// is the CSC of the same matrix).
fn symmetric_pattern(a: &Csr) -> SymbolicSparseColMatRef<'_, usize> {
    SymbolicSparseColMatRef::new_checked(a.nrows, a.ncols, &a.row_ptr, None, &a.col_idx)
}

impl<T: Scalar> Cholesky<T> {
    /// Symbolic analysis of the SPD pattern of `a` (only its lower triangle is read) in
    /// the fill-reducing order `order` (`order[new] = old`), or approximate minimum degree.
    pub(super) fn analyze(a: &Csr, order: Option<&[usize]>) -> Result<Self> {
        let inverse = order.map(ordering::inverse);
        let ord = match (order, &inverse) {
            (Some(fwd), Some(inv)) => SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, a.nrows)),
            _ => SymmetricOrdering::Amd,
        };
        let symbolic =
            factorize_symbolic_cholesky(symmetric_pattern(a), Side::Lower, ord, CholeskySymbolicParams::default())
                .map_err(|e| Error::LinearSolver(format!("symbolic Cholesky: {e:?}")))?;
        let scratch = symbolic.factorize_numeric_llt_scratch::<T>(CHOLESKY_PAR, Default::default());
        let factor_scratch =
            MemBuffer::try_new(scratch).map_err(|_| Error::LinearSolver("Cholesky: out of memory".into()))?;
        let values = vec![T::zero_impl(); symbolic.len_val()];
        Ok(Self { values, symbolic, factor_scratch, entries: Vec::new(), solve_scratch: Vec::new() })
    }

    /// Numeric factorization of `a` (same pattern as analyzed).
    pub(super) fn factor(&mut self, a: &Csr) -> Result<()> {
        let entries = T::cast(&a.values, &mut self.entries);
        self.symbolic
            .factorize_numeric_llt(
                &mut self.values,
                SparseColMatRef::new(symmetric_pattern(a), entries),
                Side::Lower,
                Default::default(),
                CHOLESKY_PAR,
                MemStack::new(&mut self.factor_scratch),
                Default::default(),
            )
            .map(|_| ())
            .map_err(|e| Error::LinearSolver(format!("Cholesky: matrix not positive definite ({e:?})")))
    }

    /// Overwrite each of the columns `x = [x_0, x_1, ...]` (each of length `n`) with
    /// `A^{-1} x_j`, the columns in parallel. A supernodal triangular solve is bound by
    /// memory bandwidth and gains nothing from threads inside one column; two columns on
    /// two threads take the time of one.
    pub(super) fn solve_columns(&mut self, x: &mut [f64]) {
        let n = self.symbolic.nrows();
        let cols = x.len() / n;
        while self.solve_scratch.len() < cols {
            let scratch = MemBuffer::new(self.symbolic.solve_in_place_scratch::<T>(1, Par::Seq));
            self.solve_scratch.push((scratch, Vec::with_capacity(n)));
        }
        let llt = LltRef::new(&self.symbolic, &self.values);
        x.par_chunks_mut(n).zip(self.solve_scratch.par_iter_mut()).for_each(|(col, (scratch, buf))| {
            T::solve(llt, col, buf, scratch);
        });
    }

    pub(super) fn dim(&self) -> usize {
        self.symbolic.nrows()
    }
}

/// A Cholesky factor whole, or, from [`SPLIT_MIN`] unknowns in a nested-dissection
/// order on two threads or more, split at the order's top separator with the halves
/// factorized at once ([`SplitCholesky`]): in double precision the factor of a direct
/// solve (on the Winslow Hessian of jigsaw01, 9984 unknowns, BENCHMARKS.md), in single
/// precision the preconditioner `K` of a volume (`LinearSolver::set_split_preconditioner`).
#[derive(Debug)]
pub(super) enum Direct<T: Scalar = f64> {
    Whole(Box<Cholesky<T>>),
    Split(Box<SplitCholesky<T>>),
}

impl<T: Scalar> Direct<T> {
    pub(super) fn analyze(a: &Csr, order: Option<&[usize]>) -> Result<Self> {
        let split = order
            .filter(|_| a.nrows >= SPLIT_MIN && rayon::current_num_threads() >= 2)
            .and_then(|o| SplitCholesky::analyze(a, o));
        Ok(match split {
            Some(s) => Self::Split(Box::new(s)),
            None => Self::Whole(Box::new(Cholesky::analyze(a, order)?)),
        })
    }

    pub(super) fn factor(&mut self, a: &Csr) -> Result<()> {
        match self {
            Self::Whole(c) => c.factor(a),
            Self::Split(c) => c.factor(a),
        }
    }

    pub(super) fn solve_columns(&mut self, x: &mut [f64]) {
        match self {
            Self::Whole(c) => c.solve_columns(x),
            Self::Split(c) => c.solve_columns(x),
        }
    }

    pub(super) fn dim(&self) -> usize {
        match self {
            Self::Whole(c) => c.dim(),
            Self::Split(c) => c.dim(),
        }
    }
}
