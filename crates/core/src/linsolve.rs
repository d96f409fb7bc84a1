//! Linear solvers behind one interface: sparse LU (faer; the symbolic factorization is
//! computed once per sparsity pattern and reused for every numeric factorization), sparse
//! Cholesky for symmetric positive definite systems, and restarted GMRES for systems past
//! what LU handles, preconditioned either by the problem's own SPD approximation
//! `-diag(K, K)` of the Jacobian (a sparse Cholesky of the scalar `K`, see
//! [`crate::assembly::Discretization::metric_laplace`]) or by ILU(0).

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, Lu, SymbolicLlt, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::Side;

use crate::error::{Error, Result};
use crate::sparse::Csr;

/// Which linear solver the nonlinear solvers use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearMethod {
    /// Sparse direct LU.
    #[default]
    Lu,
    /// Restarted GMRES(50), relative tolerance 1e-10, preconditioned by the problem's
    /// SPD approximation when it offers one, by ILU(0) otherwise.
    Gmres,
    /// LU up to [`AUTO_LU_LIMIT`] unknowns, GMRES above; GMRES falls back to LU when it
    /// does not converge.
    Auto,
    /// Sparse Cholesky `L L^T` (symmetric positive definite systems only).
    Cholesky,
}

/// Largest system that [`LinearMethod::Auto`] factorizes directly.
pub const AUTO_LU_LIMIT: usize = 5_000;

/// Default relative residual at which GMRES stops.
pub const KRYLOV_TOL: f64 = 1e-10;

/// GMRES iterations above which a frozen SPD preconditioner is rebuilt.
pub const REFRESH_KRYLOV: usize = 30;

/// A GMRES preconditioner.
#[derive(Debug)]
enum Preconditioner {
    Ilu(Ilu0),
    /// `P = -diag(K, ..., K)`, `K = L L^T`.
    NegBlockLlt(Llt<usize, f64>, usize),
}

impl Preconditioner {
    /// `x = P^{-1} b`.
    fn apply(&self, b: &[f64], x: &mut [f64]) {
        match self {
            Self::Ilu(ilu) => ilu.apply(b, x),
            Self::NegBlockLlt(llt, m) => {
                let nb = b.len() / m;
                let mut rhs = faer::Mat::<f64>::from_fn(*m, nb, |i, j| b[j * m + i]);
                llt.solve_in_place(rhs.as_mut());
                for j in 0..nb {
                    for i in 0..*m {
                        x[j * m + i] = -rhs[(i, j)];
                    }
                }
            }
        }
    }
}

/// A factorization-capable solver bound to one sparsity pattern.
#[derive(Debug)]
pub struct LinearSolver {
    method: LinearMethod,
    symbolic: Option<SymbolicLu<usize>>,
    symbolic_llt: Option<SymbolicLlt<usize>>,
    lu: Option<Lu<usize, f64>>,
    llt: Option<Llt<usize, f64>>,
    precond: Option<Preconditioner>,
    matrix: Option<Csr>,
    /// Total GMRES iterations spent (diagnostics).
    pub krylov_iterations: usize,
    last_krylov: usize,
    fallback: bool,
    /// Relative residual at which GMRES stops.
    pub krylov_tol: f64,
}

/// `L L^T` of the SPD matrix `a` (only its lower triangle is read), reusing `symbolic`.
fn cholesky(a: &Csr, symbolic: &mut Option<SymbolicLlt<usize>>) -> Result<Llt<usize, f64>> {
    // CSR of a symmetric matrix = CSC of the same matrix
    let sym = SymbolicSparseColMatRef::new_checked(a.nrows, a.ncols, &a.row_ptr, None, &a.col_idx);
    if symbolic.is_none() {
        *symbolic = Some(
            SymbolicLlt::try_new(sym, Side::Lower)
                .map_err(|e| Error::LinearSolver(format!("symbolic Cholesky: {e:?}")))?,
        );
    }
    let s = symbolic.clone().expect("set above");
    Llt::try_new_with_symbolic(s, SparseColMatRef::new(sym, &a.values), Side::Lower)
        .map_err(|e| Error::LinearSolver(format!("Cholesky: matrix not positive definite ({e:?})")))
}

impl LinearSolver {
    /// A solver using `method`.
    pub fn new(method: LinearMethod) -> Self {
        let fallback = method == LinearMethod::Auto;
        Self {
            method,
            symbolic: None,
            symbolic_llt: None,
            lu: None,
            llt: None,
            precond: None,
            matrix: None,
            krylov_iterations: 0,
            last_krylov: 0,
            fallback,
            krylov_tol: KRYLOV_TOL,
        }
    }

    /// The method in use ([`LinearMethod::Auto`] until the first factorization).
    pub fn method(&self) -> LinearMethod {
        self.method
    }

    /// Whether [`LinearSolver::factor_preconditioned`] needs a (new) SPD approximation
    /// for a system of `n` unknowns: only GMRES uses one, and it keeps the last one
    /// (a frozen preconditioner across Newton steps) while GMRES needs at most
    /// [`REFRESH_KRYLOV`] iterations with it.
    pub fn wants_preconditioner(&self, n: usize) -> bool {
        let fresh = !matches!(self.precond, Some(Preconditioner::NegBlockLlt(..))) || self.last_krylov > REFRESH_KRYLOV;
        match self.method {
            LinearMethod::Gmres => fresh,
            LinearMethod::Auto => n > AUTO_LU_LIMIT,
            LinearMethod::Lu | LinearMethod::Cholesky => false,
        }
    }

    /// Factorize (LU, Cholesky) or precondition (GMRES, with ILU(0)) the matrix `a`.
    pub fn factor(&mut self, a: &Csr) -> Result<()> {
        self.factor_preconditioned(a, None)
    }

    /// As [`LinearSolver::factor`]; GMRES uses `P = -diag(K, K)` as preconditioner when
    /// `k` (SPD, `a.nrows` a multiple of its size) is given. The CSR storage of `a` is
    /// the CSC storage of `a^T`; faer factors `a^T` and we solve with its transpose.
    pub fn factor_preconditioned(&mut self, a: &Csr, k: Option<&Csr>) -> Result<()> {
        if self.method == LinearMethod::Auto {
            self.method = if a.nrows <= AUTO_LU_LIMIT { LinearMethod::Lu } else { LinearMethod::Gmres };
        }
        match self.method {
            LinearMethod::Lu => {
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
            LinearMethod::Cholesky => self.llt = Some(cholesky(a, &mut self.symbolic_llt)?),
            LinearMethod::Gmres => {
                let block = k.filter(|k| k.nrows > 0 && a.nrows.is_multiple_of(k.nrows));
                let spd = block.map(|k| cholesky(k, &mut self.symbolic_llt).map(|l| (l, k.nrows)));
                self.precond = match (spd, self.precond.take()) {
                    (Some(Ok((llt, m))), _) => Some(Preconditioner::NegBlockLlt(llt, m)),
                    // no new approximation: keep the previous one (frozen preconditioner)
                    (None, Some(p @ Preconditioner::NegBlockLlt(..))) => Some(p),
                    // none at all (or not definite): ILU(0)
                    _ => Some(Preconditioner::Ilu(Ilu0::new(a)?)),
                };
                self.last_krylov = 0;
                self.matrix.get_or_insert_with(Csr::default).assign(a);
            }
            LinearMethod::Auto => unreachable!("resolved above"),
        }
        Ok(())
    }

    /// Solve `a x = b` with the last factorized `a`.
    pub fn solve(&mut self, b: &[f64]) -> Result<Vec<f64>> {
        let x = match self.method {
            LinearMethod::Lu => {
                let lu = self.lu.as_ref().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?;
                let mut x = faer::Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
                lu.solve_transpose_in_place(x.as_mut());
                (0..b.len()).map(|i| x[(i, 0)]).collect::<Vec<_>>()
            }
            LinearMethod::Cholesky => {
                let llt = self.llt.as_ref().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?;
                let mut x = faer::Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
                llt.solve_in_place(x.as_mut());
                (0..b.len()).map(|i| x[(i, 0)]).collect::<Vec<_>>()
            }
            LinearMethod::Gmres => {
                let a = self.matrix.as_ref().ok_or_else(|| Error::LinearSolver("solve before factor".into()))?;
                let pc = self.precond.as_ref().expect("set with matrix");
                match gmres(a, b, |r, z| pc.apply(r, z), 50, self.krylov_tol, 2000) {
                    Ok((x, it)) => {
                        self.krylov_iterations += it;
                        self.last_krylov = it;
                        x
                    }
                    Err(e) if self.fallback => {
                        // GMRES did not converge: factorize this matrix directly instead
                        let a = self.matrix.take().expect("set above");
                        self.method = LinearMethod::Lu;
                        self.fallback = false;
                        self.factor(&a).map_err(|f| Error::LinearSolver(format!("{e}; LU fallback: {f}")))?;
                        return self.solve(b);
                    }
                    Err(e) => return Err(e),
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

/// Incomplete LU factorization with zero fill-in on the pattern of `a`.
#[derive(Debug, Clone)]
pub struct Ilu0 {
    lu: Csr,
    diag: Vec<usize>,
}

impl Ilu0 {
    /// Factorize (IKJ variant); fails on a zero pivot.
    pub fn new(a: &Csr) -> Result<Self> {
        let mut lu = a.clone();
        let n = a.nrows;
        let mut diag = vec![usize::MAX; n];
        for i in 0..n {
            diag[i] =
                lu.position(i, i).ok_or_else(|| Error::LinearSolver(format!("ILU(0): no diagonal in row {i}")))?;
        }
        let mut pos = vec![usize::MAX; n];
        for i in 0..n {
            let (rs, re) = (lu.row_ptr[i], lu.row_ptr[i + 1]);
            for k in rs..re {
                pos[lu.col_idx[k]] = k;
            }
            for kk in rs..re {
                let k = lu.col_idx[kk];
                if k >= i {
                    break;
                }
                let piv = lu.values[diag[k]];
                if piv == 0.0 {
                    return Err(Error::LinearSolver(format!("ILU(0): zero pivot in row {k}")));
                }
                let lik = lu.values[kk] / piv;
                lu.values[kk] = lik;
                for kj in diag[k] + 1..lu.row_ptr[k + 1] {
                    let j = lu.col_idx[kj];
                    let p = pos[j];
                    if p != usize::MAX {
                        lu.values[p] -= lik * lu.values[kj];
                    }
                }
            }
            for k in rs..re {
                pos[lu.col_idx[k]] = usize::MAX;
            }
        }
        Ok(Self { lu, diag })
    }

    /// `x = (LU)^{-1} b`.
    pub fn apply(&self, b: &[f64], x: &mut [f64]) {
        let n = b.len();
        for i in 0..n {
            let mut s = b[i];
            for k in self.lu.row_ptr[i]..self.diag[i] {
                s -= self.lu.values[k] * x[self.lu.col_idx[k]];
            }
            x[i] = s;
        }
        for i in (0..n).rev() {
            let mut s = x[i];
            for k in self.diag[i] + 1..self.lu.row_ptr[i + 1] {
                s -= self.lu.values[k] * x[self.lu.col_idx[k]];
            }
            x[i] = s / self.lu.values[self.diag[i]];
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Right-preconditioned restarted GMRES(`restart`) for `a x = b` from `x = 0`, stopping
/// at `||b - a x|| <= tol ||b||`; `m(r, z)` applies the preconditioner `z = P^{-1} r`.
/// Returns the solution and the iteration count.
pub fn gmres(
    a: &Csr,
    b: &[f64],
    m: impl Fn(&[f64], &mut [f64]),
    restart: usize,
    tol: f64,
    max_iter: usize,
) -> Result<(Vec<f64>, usize)> {
    let n = b.len();
    let bnorm = dot(b, b).sqrt();
    let mut x = vec![0.0; n];
    if bnorm == 0.0 {
        return Ok((x, 0));
    }
    let mut total = 0;
    let mut r = b.to_vec();
    let mut w = vec![0.0; n];
    let mut z = vec![0.0; n];
    loop {
        let beta = dot(&r, &r).sqrt();
        if beta <= tol * bnorm {
            return Ok((x, total));
        }
        let mut v: Vec<Vec<f64>> = vec![r.iter().map(|t| t / beta).collect()];
        let mut h = vec![vec![0.0; restart]; restart + 1];
        let (mut cs, mut sn) = (vec![0.0; restart], vec![0.0; restart]);
        let mut g = vec![0.0; restart + 1];
        g[0] = beta;
        let mut k = 0;
        while k < restart {
            m(&v[k], &mut z);
            a.mul_vec(&z, &mut w);
            for i in 0..=k {
                h[i][k] = dot(&w, &v[i]);
                for (wj, vj) in w.iter_mut().zip(&v[i]) {
                    *wj -= h[i][k] * vj;
                }
            }
            h[k + 1][k] = dot(&w, &w).sqrt();
            for i in 0..k {
                let t = cs[i] * h[i][k] + sn[i] * h[i + 1][k];
                h[i + 1][k] = -sn[i] * h[i][k] + cs[i] * h[i + 1][k];
                h[i][k] = t;
            }
            let den = h[k][k].hypot(h[k + 1][k]);
            cs[k] = if den == 0.0 { 1.0 } else { h[k][k] / den };
            sn[k] = if den == 0.0 { 0.0 } else { h[k + 1][k] / den };
            let hk1 = h[k + 1][k];
            h[k][k] = cs[k] * h[k][k] + sn[k] * hk1;
            h[k + 1][k] = 0.0;
            g[k + 1] = -sn[k] * g[k];
            g[k] *= cs[k];
            total += 1;
            let next: Vec<f64> = if hk1 != 0.0 { w.iter().map(|t| t / hk1).collect() } else { vec![0.0; n] };
            v.push(next);
            k += 1;
            if g[k].abs() <= tol * bnorm || total >= max_iter || hk1 == 0.0 {
                break;
            }
        }
        // back substitution
        let mut y = vec![0.0; k];
        for i in (0..k).rev() {
            let mut s = g[i];
            for j in i + 1..k {
                s -= h[i][j] * y[j];
            }
            y[i] = s / h[i][i];
        }
        let mut dx = vec![0.0; n];
        for (j, yj) in y.iter().enumerate() {
            for (d, vj) in dx.iter_mut().zip(&v[j]) {
                *d += yj * vj;
            }
        }
        m(&dx, &mut z);
        for (xi, zi) in x.iter_mut().zip(&z) {
            *xi += zi;
        }
        a.mul_vec(&x, &mut w);
        for i in 0..n {
            r[i] = b[i] - w[i];
        }
        if total >= max_iter {
            let rn = dot(&r, &r).sqrt();
            if rn <= 1e3 * tol * bnorm {
                return Ok((x, total));
            }
            return Err(Error::LinearSolver(format!("GMRES: residual {:.3e} after {total} iterations", rn / bnorm)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn poisson_1d(n: usize) -> Csr {
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, 2.5));
            if i > 0 {
                t.push((i, i - 1, -1.0));
            }
            if i + 1 < n {
                t.push((i, i + 1, -1.2));
            }
        }
        Csr::from_triplets(n, n, &t)
    }

    #[test]
    fn lu_and_gmres_agree() {
        let a = poisson_1d(200);
        let b: Vec<f64> = (0..200).map(|i| (i as f64 * 0.1).sin()).collect();
        let mut lu = LinearSolver::new(LinearMethod::Lu);
        lu.factor(&a).unwrap();
        let x1 = lu.solve(&b).unwrap();
        let mut gm = LinearSolver::new(LinearMethod::Gmres);
        gm.factor(&a).unwrap();
        let x2 = gm.solve(&b).unwrap();
        let r = a.apply(&x1);
        for i in 0..200 {
            assert!((r[i] - b[i]).abs() < 1e-12);
            assert!((x1[i] - x2[i]).abs() < 1e-8);
        }
        // an SPD system through Cholesky
        let spd = Csr::from_triplets(
            200,
            200,
            &(0..200)
                .flat_map(|i| {
                    let mut t = vec![(i, i, 2.5)];
                    if i > 0 {
                        t.push((i, i - 1, -1.0));
                    }
                    if i + 1 < 200 {
                        t.push((i, i + 1, -1.0));
                    }
                    t
                })
                .collect::<Vec<_>>(),
        );
        let mut ch = LinearSolver::new(LinearMethod::Cholesky);
        ch.factor(&spd).unwrap();
        let x4 = ch.solve(&b).unwrap();
        let r4 = spd.apply(&x4);
        assert!(r4.iter().zip(&b).all(|(r, b)| (r - b).abs() < 1e-12));
        // a negative definite matrix has no Cholesky factor: typed error
        let mut neg = spd.clone();
        neg.values.iter_mut().for_each(|v| *v = -*v);
        assert!(LinearSolver::new(LinearMethod::Cholesky).factor(&neg).is_err());
        // a second numeric factorization reuses the symbolic one
        let mut a2 = a.clone();
        a2.values.iter_mut().for_each(|v| *v *= 2.0);
        lu.factor(&a2).unwrap();
        let x3 = lu.solve(&b).unwrap();
        assert!((x3[7] - 0.5 * x1[7]).abs() < 1e-12);
    }
}
