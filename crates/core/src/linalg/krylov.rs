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

    /// Whether one product costs far more than a few vector updates of the operator's
    /// size (a matrix-free product evaluated element by element at every quadrature
    /// point): `gmres` then forms each cycle's residual from the products it made in
    /// the cycle instead of one more product (see there). `false` unless overridden.
    fn costly(&self) -> bool {
        false
    }
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
///
/// The stopping test is on the true residual `r = b - A x`, not on the Arnoldi
/// recurrence's estimate `|g_k|` (which only ends a cycle): after each cycle `r` is
/// `b - A x` by one more product, or, for a [`MatVec::costly`] operator, updated from
/// the products of the cycle, `r ← r - Σ_j y_j (A z_j)` (the same vector by the
/// linearity of `A`, to rounding, without relying on the orthogonality of the basis
/// `v_j`; `k` more vectors of memory instead of a product).
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
    // the products A z_j of the cycle, kept for a costly operator
    let costly = a.costly();
    let mut az: Vec<Vec<f64>> = Vec::new();
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
            if costly {
                match az.get_mut(k) {
                    Some(p) => p.copy_from_slice(&w),
                    None => az.push(w.clone()),
                }
            }
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
        if costly {
            for (j, yj) in y.iter().enumerate() {
                for (ri, p) in r.iter_mut().zip(&az[j]) {
                    *ri -= yj * p;
                }
            }
        } else {
            a.mul_vec(&x, &mut w);
            for i in 0..n {
                r[i] = b[i] - w[i];
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A matrix whose products [`gmres`] treats as costly (the residual of a cycle from
    /// the cycle's products).
    struct Costly<'a>(&'a Csr);

    impl MatVec for Costly<'_> {
        fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
            self.0.mul_vec(x, y);
        }
        fn costly(&self) -> bool {
            true
        }
    }

    /// GMRES with the residual of each cycle from the cycle's products stops where the
    /// one with an extra product does (restarted every 4 and every 40 iterations, with
    /// and without a preconditioner): the same iterations, the same solution to
    /// rounding, and the true residual `|b - A x|` within the tolerance.
    #[test]
    fn the_residual_from_the_cycles_products_is_the_true_one() {
        let n = 120;
        let a = crate::testutil::poisson_1d(n);
        let b: Vec<f64> = (0..n).map(|i| (0.37 * i as f64).sin() + 0.1).collect();
        let jacobi = |r: &[f64], z: &mut [f64]| z.iter_mut().zip(r).for_each(|(z, r)| *z = r / 2.5);
        let identity = |r: &[f64], z: &mut [f64]| z.copy_from_slice(r);
        for restart in [4, 40] {
            for tol in [1e-6, 1e-10] {
                let (x1, it1) = gmres(&a, &b, jacobi, restart, tol, 2000).unwrap();
                let (x2, it2) = gmres(&Costly(&a), &b, jacobi, restart, tol, 2000).unwrap();
                let (x3, it3) = gmres(&a, &b, identity, restart, tol, 2000).unwrap();
                let (x4, it4) = gmres(&Costly(&a), &b, identity, restart, tol, 2000).unwrap();
                assert_eq!((it1, it3), (it2, it4), "restart {restart}, tol {tol}");
                if restart == 4 {
                    assert!(it1 > 3 * restart, "restarted: {it1} iterations");
                }
                let bn = dot(&b, &b).sqrt();
                for (x, y) in [(&x1, &x2), (&x3, &x4)] {
                    let err = x.iter().zip(y).fold(0.0f64, |e, (p, q)| e.max((p - q).abs()));
                    let xn = x.iter().fold(0.0f64, |e, p| e.max(p.abs()));
                    assert!(err <= 1e-12 * xn, "restart {restart}, tol {tol}: {err}");
                    let ax = a.apply(y);
                    let r = ax.iter().zip(&b).map(|(p, q)| (p - q) * (p - q)).sum::<f64>().sqrt();
                    assert!(r <= tol * bn * (1.0 + 1e-6), "restart {restart}, tol {tol}: |r| = {r}");
                }
            }
        }
    }
}
