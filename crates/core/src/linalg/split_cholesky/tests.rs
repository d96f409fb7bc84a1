use super::*;
use crate::linalg::ordering::{interleave, nested_dissection};
use crate::testutil::Lcg;

/// A symmetric matrix of 2 components on an `nx x ny` grid of points (unknown `c m + k`
/// is component `c` of point `k`) coupling points up to 3 apart, as a cubic spline
/// system does: random off-diagonal entries and, with `dominance` 1, a diagonal one more
/// than the absolute row sum (positive definite); its nested-dissection order.
fn grid_matrix(nx: usize, ny: usize, seed: u64) -> (Csr, Vec<usize>) {
    let m = nx * ny;
    let n = 2 * m;
    let mut rng = Lcg::new(seed);
    let mut dense = vec![vec![0.0; n]; n];
    let nodes: Vec<[usize; 2]> = (0..ny).flat_map(|j| (0..nx).map(move |i| [i, j])).collect();
    for a in 0..m {
        for b in 0..=a {
            let ([ia, ja], [ib, jb]) = (nodes[a], nodes[b]);
            if ia.abs_diff(ib) > 3 || ja.abs_diff(jb) > 3 {
                continue;
            }
            for ca in 0..2 {
                for cb in 0..2 {
                    let (r, c) = (ca * m + a, cb * m + b);
                    if r != c && (a != b || ca > cb) {
                        let v = rng.uniform() - 0.5;
                        dense[r][c] = v;
                        dense[c][r] = v;
                    }
                }
            }
        }
    }
    for r in 0..n {
        dense[r][r] = dense[r].iter().map(|v| v.abs()).sum::<f64>() + 1.0;
    }
    let (mut row_ptr, mut col_idx, mut values) = (vec![0], Vec::new(), Vec::new());
    for (r, row) in dense.iter().enumerate() {
        for (c, &v) in row.iter().enumerate() {
            let a = (r % m, c % m);
            let ([ia, ja], [ib, jb]) = (nodes[a.0], nodes[a.1]);
            if ia.abs_diff(ib) <= 3 && ja.abs_diff(jb) <= 3 {
                col_idx.push(c);
                values.push(v);
            }
        }
        row_ptr.push(col_idx.len());
    }
    let order = interleave(&nested_dissection(&nodes, [3, 3]), 2);
    (Csr { nrows: n, ncols: n, row_ptr, col_idx, values }, order)
}

fn matvec(a: &Csr, x: &[f64]) -> Vec<f64> {
    (0..a.nrows).map(|r| a.row(r).map(|(c, v)| v * x[c]).sum()).collect()
}

fn shifted(a: &Csr, mu: f64) -> Csr {
    let mut b = a.clone();
    for r in 0..b.nrows {
        let k = b.position(r, r).expect("diagonal");
        b.values[k] -= mu;
    }
    b
}

#[test]
fn finds_the_top_separator() {
    // 40 x 20 points: cut across x, 18 columns | 3 | 19 columns, 2 components each
    let (a, order) = grid_matrix(40, 20, 1);
    assert_eq!(top_split(&a, &order), Some([2 * 18 * 20, 2 * 19 * 20, 2 * 3 * 20]));
    // the natural order has no two uncoupled halves ahead of a separator
    let natural: Vec<usize> = (0..a.nrows).collect();
    assert_eq!(top_split(&a, &natural), None);
}

#[test]
fn solves_like_the_whole_factorization() {
    let (a, order) = grid_matrix(30, 17, 2);
    let mut split = SplitCholesky::<f64>::analyze(&a, &order).expect("a split");
    split.factor(&a).unwrap();
    let n = a.nrows;
    let mut rng = Lcg::new(7);
    let b: Vec<f64> = (0..2 * n).map(|_| rng.uniform() - 0.5).collect();
    let mut x = b.clone();
    split.solve_columns(&mut x);
    for (xc, bc) in x.chunks(n).zip(b.chunks(n)) {
        let r = matvec(&a, xc);
        let err = r.iter().zip(bc).map(|(p, q)| (p - q).powi(2)).sum::<f64>().sqrt();
        let norm = bc.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(err <= 1e-12 * norm, "residual {err:e} of {norm:e}");
    }
    // refactorized with other values on the same pattern
    let b2 = shifted(&a, -3.0);
    split.factor(&b2).unwrap();
    let mut y = b[..n].to_vec();
    split.solve_columns(&mut y);
    let r = matvec(&b2, &y);
    assert!(r.iter().zip(&b).all(|(p, q)| (p - q).abs() <= 1e-12));
}

/// `A - μ I` factorizes exactly when `μ` is below the smallest eigenvalue of `A`, on
/// either side of it by 0.1 %: whether the halves or the separator's Schur complement
/// fail first, a failure is a proof.
#[test]
fn fails_exactly_when_not_positive_definite() {
    let (a, order) = grid_matrix(16, 12, 3);
    let n = a.nrows;
    let dense = Mat::<f64>::from_fn(n, n, |i, j| a.position(i, j).map_or(0.0, |k| a.values[k]));
    let eig = dense.self_adjoint_eigenvalues(Side::Lower).unwrap();
    let lmin = eig.iter().fold(f64::INFINITY, |m, &v| m.min(v));
    let lmax = eig.iter().fold(0.0f64, |m, &v| m.max(v));
    assert!(lmin > 0.0);
    let mut split = SplitCholesky::<f64>::analyze(&a, &order).expect("a split");
    for (mu, definite) in
        [(0.999 * lmin, true), (1.001 * lmin, false), (0.5 * (lmin + lmax), false), (1.01 * lmax, false)]
    {
        let r = split.factor(&shifted(&a, mu));
        assert_eq!(r.is_ok(), definite, "mu = {mu} (eigenvalues {lmin} .. {lmax}): {r:?}");
    }
    // and it recovers on a definite matrix after failures
    split.factor(&a).unwrap();
}

/// In single precision (the factor of a preconditioner) the split solves as the whole
/// factorization does: the residual of the solution is at the rounding of `f32` times
/// the condition (here below 1e-4 of the right-hand side; 1e-12 in double precision
/// above), and the factor's entries are `f32`.
#[test]
fn solves_in_single_precision() {
    let (a, order) = grid_matrix(30, 17, 4);
    let mut split = SplitCholesky::<f32>::analyze(&a, &order).expect("a split");
    split.factor(&a).unwrap();
    let n = a.nrows;
    let mut rng = Lcg::new(9);
    let b: Vec<f64> = (0..3 * n).map(|_| rng.uniform() - 0.5).collect();
    let mut x = b.clone();
    split.solve_columns(&mut x);
    let mut exact = b.clone();
    let mut double = SplitCholesky::<f64>::analyze(&a, &order).expect("a split");
    double.factor(&a).unwrap();
    double.solve_columns(&mut exact);
    for ((xc, bc), ec) in x.chunks(n).zip(b.chunks(n)).zip(exact.chunks(n)) {
        let r = matvec(&a, xc);
        let norm = |v: &[f64]| v.iter().map(|t| t * t).sum::<f64>().sqrt();
        let err: Vec<f64> = r.iter().zip(bc).map(|(p, q)| p - q).collect();
        assert!(norm(&err) <= 1e-4 * norm(bc), "residual {:e} of {:e}", norm(&err), norm(bc));
        // not the double-precision solution: the f32 factor rounds
        let diff: Vec<f64> = xc.iter().zip(ec).map(|(p, q)| p - q).collect();
        assert!(norm(&diff) > 1e-12 * norm(ec) && norm(&diff) <= 1e-4 * norm(ec));
    }
    assert!(format!("{split:?}").contains("bytes: 4"));
}
