//! Krylov methods and the incomplete factorization they fall back to: restarted
//! flexible GMRES (right-preconditioned, keeping the preconditioned basis so that an
//! inexact preconditioner does not limit the attainable accuracy), preconditioned
//! conjugate gradients for SPD systems, and ILU(0) on the CSR pattern. The linear
//! solver of the Newton iterations ([`super::linsolve::LinearSolver`]) chooses among
//! them.

use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;

/// A square linear operator `y = A x` as the Krylov methods use it: an assembled sparse
/// matrix ([`Csr`]) or a product computed without one (the stencil product of a Galerkin
/// system, `discrete::stencil`).
pub trait MatVec {
    /// `y = A x` (`x` and `y` of the operator's size).
    fn mul_vec(&self, x: &[f64], y: &mut [f64]);
}

impl MatVec for Csr {
    fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        Csr::mul_vec(self, x, y);
    }
}

/// Incomplete LU factorization with zero fill-in on the pattern of `a`.
#[derive(Debug, Clone)]
pub(crate) struct Ilu0 {
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

/// Preconditioned conjugate gradients for the SPD system `a x = b` from `x = 0`,
/// stopping at `||b - a x|| <= tol ||b||`; `m(r, z)` applies `z = P^{-1} r` (SPD).
/// Returns the solution and the iteration count, an error after `max_iter` iterations.
pub fn cg<A: MatVec + ?Sized>(
    a: &A,
    b: &[f64],
    mut m: impl FnMut(&[f64], &mut [f64]),
    tol: f64,
    max_iter: usize,
) -> Result<(Vec<f64>, usize)> {
    let n = b.len();
    let (bnorm, mut x) = krylov_start(b);
    if bnorm == 0.0 {
        return Ok((x, 0));
    }
    let mut r = b.to_vec();
    let mut z = vec![0.0; n];
    m(&r, &mut z);
    let mut p = z.clone();
    let mut q = vec![0.0; n];
    let mut rz = dot(&r, &z);
    for it in 1..=max_iter {
        a.mul_vec(&p, &mut q);
        let pq = dot(&p, &q);
        if pq <= 0.0 {
            return Err(Error::LinearSolver("CG: matrix not positive definite".into()));
        }
        let alpha = rz / pq;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
        }
        if dot(&r, &r).sqrt() <= tol * bnorm {
            return Ok((x, it));
        }
        m(&r, &mut z);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
    }
    Err(Error::LinearSolver(format!("CG: no convergence in {max_iter} iterations")))
}

/// `||b||` and the start `x = 0` of the Krylov methods.
fn krylov_start(b: &[f64]) -> (f64, Vec<f64>) {
    (dot(b, b).sqrt(), vec![0.0; b.len()])
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Flexible (right-preconditioned) restarted GMRES(`restart`) for `a x = b` from
/// `x = 0` (Saad 1993), stopping at `||b - a x|| <= tol ||b||`; `m(r, z)` applies the
/// preconditioner `z = P^{-1} r`. The preconditioned directions `z_k` are kept and the
/// update is `x += Z y`, so a preconditioner that is applied with rounding (single
/// precision) or that changes between iterations does not limit the attainable
/// accuracy. Krylov vectors are allocated in the first cycle and reused by the next.
/// Returns the solution and the iteration count.
pub fn gmres<A: MatVec + ?Sized>(
    a: &A,
    b: &[f64],
    mut m: impl FnMut(&[f64], &mut [f64]),
    restart: usize,
    tol: f64,
    max_iter: usize,
) -> Result<(Vec<f64>, usize)> {
    let n = b.len();
    let (bnorm, mut x) = krylov_start(b);
    if bnorm == 0.0 {
        return Ok((x, 0));
    }
    let mut total = 0;
    let mut r = b.to_vec();
    let mut w = vec![0.0; n];
    let mut v: Vec<Vec<f64>> = Vec::new();
    let mut z: Vec<Vec<f64>> = Vec::new();
    let mut h = vec![vec![0.0; restart]; restart + 1];
    let (mut cs, mut sn) = (vec![0.0; restart], vec![0.0; restart]);
    let mut g = vec![0.0; restart + 1];
    loop {
        let beta = dot(&r, &r).sqrt();
        if beta <= tol * bnorm {
            return Ok((x, total));
        }
        if v.is_empty() {
            v.push(vec![0.0; n]);
        }
        for (vi, ri) in v[0].iter_mut().zip(&r) {
            *vi = ri / beta;
        }
        g.fill(0.0);
        g[0] = beta;
        let mut k = 0;
        while k < restart {
            if z.len() <= k {
                z.push(vec![0.0; n]);
            }
            m(&v[k], &mut z[k]);
            a.mul_vec(&z[k], &mut w);
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
            if v.len() <= k + 1 {
                v.push(vec![0.0; n]);
            }
            let inv = if hk1 != 0.0 { 1.0 / hk1 } else { 0.0 };
            for (vn, wj) in v[k + 1].iter_mut().zip(&w) {
                *vn = wj * inv;
            }
            k += 1;
            if g[k].abs() <= tol * bnorm || total >= max_iter || hk1 == 0.0 {
                break;
            }
        }
        // back substitution, then x += Z y
        let mut y = vec![0.0; k];
        for i in (0..k).rev() {
            let mut s = g[i];
            for j in i + 1..k {
                s -= h[i][j] * y[j];
            }
            y[i] = s / h[i][i];
        }
        for (j, yj) in y.iter().enumerate() {
            for (xi, zj) in x.iter_mut().zip(&z[j]) {
                *xi += yj * zj;
            }
        }
        a.mul_vec(&x, &mut w);
        for i in 0..n {
            r[i] = b[i] - w[i];
        }
        if total >= max_iter {
            // a tight tolerance missed by a little still gives a usable solution; a
            // loose one (an inexact Newton forcing term) must be met within 10 %
            let rn = dot(&r, &r).sqrt();
            if rn <= (1e3 * tol).min(0.1) * bnorm {
                return Ok((x, total));
            }
            return Err(Error::LinearSolver(format!("GMRES: residual {:.3e} after {total} iterations", rn / bnorm)));
        }
    }
}
