use super::*;
use crate::testutil::poisson_1d;

/// `A = -(T + s I)` with the symmetric `T = tridiag(-1, 2, -1)` (eigenvalues in
/// `(0, 4)`): negative definite for `s = 0.1`, indefinite for `s = -1`.
fn shifted_laplacian(n: usize, s: f64) -> Csr {
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i, i, -(2.0 + s)));
        if i > 0 {
            t.push((i, i - 1, 1.0));
        }
        if i + 1 < n {
            t.push((i, i + 1, 1.0));
        }
    }
    Csr::from_triplets(n, n, &t)
}

/// A negated Cholesky factorization fails exactly when `-A` is not positive definite
/// and keeps its symbolic analysis for the next one, which then solves `A x = b`.
#[test]
fn neg_cholesky_after_a_failure_solves() {
    // past the dense limit: the sparse factorization with its symbolic analysis
    let n = 2 * DENSE_LIMIT;
    let mut lin = LinearSolver::new(LinearMethod::NegCholesky);
    assert!(lin.factor(&shifted_laplacian(n, -1.0)).is_err(), "-A is indefinite");
    assert!(lin.analysed.is_some() && lin.llt.is_none(), "the analysis is kept, no factor");
    assert!(lin.solve(&vec![1.0; n]).is_err(), "no solve after a failed factorization");
    let a = shifted_laplacian(n, 0.1);
    lin.factor(&a).unwrap();
    assert!(lin.analysed.is_none() && lin.llt.is_some());
    let b: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos()).collect();
    let x = lin.solve(&b).unwrap();
    for (r, b) in a.apply(&x).iter().zip(&b) {
        assert!((r - b).abs() < 1e-12, "{r} vs {b}");
    }
    // within the dense limit likewise: no factor after a failure, a solve after success
    let n = DENSE_LIMIT / 2;
    let mut lin = LinearSolver::new(LinearMethod::NegCholesky);
    assert!(lin.factor(&shifted_laplacian(n, -1.0)).is_err(), "-A is indefinite");
    assert!(lin.solve(&vec![1.0; n]).is_err(), "no solve after a failed factorization");
    let a = shifted_laplacian(n, 0.1);
    lin.factor(&a).unwrap();
    let x = lin.solve(&b[..n]).unwrap();
    for (r, b) in a.apply(&x).iter().zip(&b) {
        assert!((r - b).abs() < 1e-12, "{r} vs {b}");
    }
}

/// Dense (up to `DENSE_LIMIT` unknowns) and sparse LU give the same solution of a
/// nonsymmetric system to rounding.
#[test]
fn dense_and_sparse_lu_agree() {
    let n = DENSE_LIMIT;
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i, i, 3.0 + (i as f64 * 0.7).sin()));
        if i > 0 {
            t.push((i, i - 1, -1.2));
        }
        if i + 2 < n {
            t.push((i, i + 2, 0.5));
        }
    }
    let a = Csr::from_triplets(n, n, &t);
    let b: Vec<f64> = (0..n).map(|i| (0.2 * i as f64).cos()).collect();
    let mut dense = LinearSolver::new(LinearMethod::Lu);
    dense.factor(&a).unwrap();
    let x = dense.solve(&b).unwrap();
    assert!(dense.dense.is_some() && dense.lu.is_none(), "dense within the limit");
    let mut big = t.clone();
    big.push((n, n, 1.0));
    let mut sparse = LinearSolver::new(LinearMethod::Lu);
    sparse.factor(&Csr::from_triplets(n + 1, n + 1, &big)).unwrap();
    assert!(sparse.dense.is_none() && sparse.lu.is_some(), "sparse past the limit");
    let mut bb = b.clone();
    bb.push(0.0);
    let y = sparse.solve(&bb).unwrap();
    for (u, v) in x.iter().zip(&y) {
        assert!((u - v).abs() < 1e-13, "{u} vs {v}");
    }
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

/// The 9-point Laplacian-like SPD matrix of an `nx x ny` grid (unknown `j nx + i`),
/// anisotropic by `ax`, and the grid points.
fn grid_spd(nx: usize, ny: usize, ax: f64) -> (Csr, Vec<[usize; 2]>) {
    let mut t = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let k = j * nx + i;
            t.push((k, k, 4.0 * (1.0 + ax) + 2.01));
            for (di, dj, v) in [(1, 0, -2.0 * ax), (0, 1, -2.0), (1, 1, -0.5), (-1, 1, -0.5)] {
                let (ii, jj) = (i as i64 + di, j as i64 + dj);
                if ii >= 0 && (ii as usize) < nx && (jj as usize) < ny {
                    let kk = jj as usize * nx + ii as usize;
                    t.push((k, kk, v));
                    t.push((kk, k, v));
                }
            }
        }
    }
    let pts = (0..ny).flat_map(|j| (0..nx).map(move |i| [i, j])).collect();
    (Csr::from_triplets(nx * ny, nx * ny, &t), pts)
}

/// Cholesky in nested-dissection order (scalar, and a two-component block system
/// point by point) solves to rounding, like the default minimum-degree order.
#[test]
fn cholesky_in_nested_dissection_order() {
    let (k, pts) = grid_spd(37, 23, 3.0);
    let order = ordering::nested_dissection(&pts, [1, 1]);
    let n = k.nrows;
    let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 17) as f64 - 8.0).collect();
    let mut nd = LinearSolver::new(LinearMethod::Cholesky);
    nd.set_ordering(&order);
    nd.factor(&k).unwrap();
    let x = nd.solve(&b).unwrap();
    let r = k.apply(&x);
    let bn = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    let rn = r.iter().zip(&b).map(|(r, b)| (r - b) * (r - b)).sum::<f64>().sqrt();
    assert!(rn < 1e-12 * bn, "scalar residual {rn}");
    // diag(K, 2K): components in blocks, ordered point by point
    let mut t = Vec::new();
    for r in 0..n {
        for (c, v) in k.row(r) {
            t.push((r, c, v));
            t.push((n + r, n + c, 2.0 * v));
        }
    }
    let kk = Csr::from_triplets(2 * n, 2 * n, &t);
    let bb: Vec<f64> = b.iter().chain(&b).copied().collect();
    let mut nd2 = LinearSolver::new(LinearMethod::Cholesky);
    nd2.set_ordering(&order);
    nd2.factor(&kk).unwrap();
    let xx = nd2.solve(&bb).unwrap();
    for i in 0..n {
        assert!((xx[i] - x[i]).abs() < 1e-10 * (1.0 + x[i].abs()));
        assert!((xx[n + i] - 0.5 * x[i]).abs() < 1e-10 * (1.0 + x[i].abs()));
    }
}

/// Flexible GMRES with the single-precision block preconditioner reaches a relative
/// residual of 1e-12, far below single precision, on a nonsymmetric perturbation of
/// `-diag(K, K)`.
#[test]
fn single_precision_preconditioner_reaches_double_accuracy() {
    let (k, pts) = grid_spd(30, 30, 10.0);
    let n = k.nrows;
    let mut t = Vec::new();
    for r in 0..n {
        for (c, v) in k.row(r) {
            t.push((r, c, -v));
            t.push((n + r, n + c, -v));
            // lower-order coupling between the components
            if c == r + 1 {
                t.push((r, n + c, 0.3));
                t.push((n + c, r, -0.2));
            }
        }
    }
    let a = Csr::from_triplets(2 * n, 2 * n, &t);
    let b: Vec<f64> = (0..2 * n).map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.5).collect();
    let mut gm = LinearSolver::new(LinearMethod::Gmres);
    gm.set_ordering(&ordering::nested_dissection(&pts, [1, 1]));
    gm.krylov_tol = 1e-12;
    gm.factor_preconditioned(&a, Some(&k)).unwrap();
    assert!(matches!(gm.precond, Some(Preconditioner::NegBlock32(..))));
    let x = gm.solve(&b).unwrap();
    let r = a.apply(&x);
    let bn = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    let rn = r.iter().zip(&b).map(|(r, b)| (r - b) * (r - b)).sum::<f64>().sqrt();
    assert!(rn < 2e-12 * bn, "relative residual {}", rn / bn);
    assert!(gm.krylov_iterations < 40, "{} iterations", gm.krylov_iterations);
}

/// Block-Jacobi CG agrees with the direct Cholesky solve on a coupled two-component
/// SPD system, within a mesh-independent number of iterations.
#[test]
fn block_jacobi_cg_matches_cholesky() {
    let mut counts = Vec::new();
    for ne in [20, 40] {
        let (k, pts) = grid_spd(ne, ne, 2.0);
        let n = k.nrows;
        let mut t = Vec::new();
        for r in 0..n {
            for (c, v) in k.row(r) {
                t.push((r, c, v));
                t.push((n + r, n + c, 2.0 * v));
            }
            // symmetric coupling of the components, kept definite by the unit shift
            t.push((r, r, 1.0));
            t.push((n + r, n + r, 1.0));
            t.push((r, n + r, 0.5));
            t.push((n + r, r, 0.5));
        }
        let a = Csr::from_triplets(2 * n, 2 * n, &t);
        let b: Vec<f64> = (0..2 * n).map(|i| ((i * 31) % 23) as f64 - 11.0).collect();
        let order = ordering::nested_dissection(&pts, [1, 1]);
        let mut direct = LinearSolver::new(LinearMethod::Cholesky);
        direct.set_ordering(&order);
        direct.factor(&a).unwrap();
        let x0 = direct.solve(&b).unwrap();
        let mut cg = LinearSolver::new(LinearMethod::Pcg);
        cg.set_ordering(&order);
        cg.krylov_tol = 1e-10;
        cg.factor(&a).unwrap();
        assert!(matches!(&cg.precond, Some(Preconditioner::BlockJacobi(blocks)) if blocks.len() == 2));
        let x = cg.solve(&b).unwrap();
        assert_eq!(cg.method(), LinearMethod::Pcg, "CG fell back to the direct solver");
        let scale = x0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = x.iter().zip(&x0).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err < 1e-8 * scale, "CG error {err} (scale {scale})");
        counts.push(cg.krylov_iterations);
    }
    assert!(counts[1] <= counts[0] + 3, "iterations grow with the mesh: {counts:?}");
}
