//! The subproblems of the sequential LP / QP loops, solved by Clarabel (an
//! interior-point conic solver, Goulart and Chen 2024): `min ½ xᵀ P x + qᵀ x` subject
//! to `G x <= h` and a box `|x_i| <= r` on the first `n_box` variables (the trust
//! region), in Clarabel's form `A x + s = b`, `s >= 0`, with `A = [G; I; -I]`.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};

use crate::linalg::sparse::Csr;

/// A solved subproblem.
#[derive(Debug, Clone)]
pub(super) struct QpSolution {
    /// The minimizer.
    pub x: Vec<f64>,
    /// Multipliers `λ >= 0` of the rows of `G x <= h` (stationarity `P x + q + Gᵀ λ + ... = 0`).
    pub lambda: Vec<f64>,
}

/// Why a subproblem has no usable solution.
#[derive(Debug, Clone)]
pub(super) struct QpFailure(pub String);

/// The upper triangle of a dense symmetric matrix (row-major `n x n`) in CSC form.
pub(super) fn upper_csc(n: usize, dense: &[f64]) -> CscMatrix<f64> {
    let mut colptr = Vec::with_capacity(n + 1);
    let (mut rowval, mut nzval) = (Vec::new(), Vec::new());
    colptr.push(0);
    for j in 0..n {
        for i in 0..=j {
            let v = dense[i * n + j];
            if v != 0.0 {
                rowval.push(i);
                nzval.push(v);
            }
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(n, n, colptr, rowval, nzval)
}

/// Solve `min ½ xᵀ P x + qᵀ x`, `G x <= h`, `|x_i| <= radius` for `i < n_box`; `p = None`
/// for a linear program. `G` has `q.len()` columns.
pub(super) fn solve(
    p: Option<CscMatrix<f64>>,
    q: &[f64],
    g: &Csr,
    h: &[f64],
    radius: f64,
    n_box: usize,
) -> Result<QpSolution, QpFailure> {
    let n = q.len();
    debug_assert_eq!(g.ncols, n);
    let m = g.nrows + 2 * n_box;
    let mut trip: Vec<(usize, usize, f64)> = Vec::with_capacity(g.nnz() + 2 * n_box);
    for r in 0..g.nrows {
        for (c, v) in g.row(r) {
            trip.push((r, c, v));
        }
    }
    for i in 0..n_box {
        trip.push((g.nrows + i, i, 1.0));
        trip.push((g.nrows + n_box + i, i, -1.0));
    }
    let (ii, jj, vv) = trip.into_iter().fold((Vec::new(), Vec::new(), Vec::new()), |mut acc, (i, j, v)| {
        acc.0.push(i);
        acc.1.push(j);
        acc.2.push(v);
        acc
    });
    let a = CscMatrix::new_from_triplets(m, n, ii, jj, vv);
    let mut b = h.to_vec();
    b.resize(m, radius);
    let p = p.unwrap_or_else(|| CscMatrix::zeros((n, n)));
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(200)
        .build()
        .map_err(|e| QpFailure(format!("Clarabel settings: {e}")))?;
    let cones = [NonnegativeConeT(m)];
    let mut solver =
        DefaultSolver::new(&p, q, &a, &b, &cones, settings).map_err(|e| QpFailure(format!("Clarabel setup: {e}")))?;
    solver.solve();
    let sol = &solver.solution;
    match sol.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            Ok(QpSolution { x: sol.x.clone(), lambda: sol.z[..g.nrows].to_vec() })
        }
        s => Err(QpFailure(format!("Clarabel: {s:?}"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `min (x - 2)² + (y - 1)²` s.t. `x + y <= 2`, `|x|, |y| <= 10`: `x = 1.5`, `y = 0.5`,
    /// multiplier `1`; with the box `|x_i| <= 1`: `x = 1` (the box), `y = 1`, where the
    /// half-plane is active with a zero multiplier (degenerate: an interior-point method
    /// approaches such a point only to about the square root of its gap tolerance).
    #[test]
    fn a_small_qp_and_its_multiplier() {
        let p = upper_csc(2, &[2.0, 0.0, 0.0, 2.0]);
        let g = Csr::from_triplets(1, 2, &[(0, 0, 1.0), (0, 1, 1.0)]);
        let s = solve(Some(p), &[-4.0, -2.0], &g, &[2.0], 10.0, 2).unwrap();
        assert!((s.x[0] - 1.5).abs() < 1e-7 && (s.x[1] - 0.5).abs() < 1e-7, "{:?}", s.x);
        assert!((s.lambda[0] - 1.0).abs() < 1e-6, "{:?}", s.lambda);
        // the box binds x: x = 1, then y = 1 (half-plane), multiplier 0 of the box in y
        let p = upper_csc(2, &[2.0, 0.0, 0.0, 2.0]);
        let s = solve(Some(p), &[-4.0, -2.0], &g, &[2.0], 1.0, 2).unwrap();
        assert!((s.x[0] - 1.0).abs() < 1e-7 && (s.x[1] - 1.0).abs() < 1e-3, "{:?}", s.x);
    }

    /// An LP: `max t` s.t. `t <= 1 + x`, `t <= 3 - x`, `|x| <= 5`: `x = 1`, `t = 2`.
    #[test]
    fn a_small_lp() {
        let g = Csr::from_triplets(2, 2, &[(0, 0, -1.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 1.0)]);
        let s = solve(None, &[0.0, -1.0], &g, &[1.0, 3.0], 5.0, 1).unwrap();
        assert!((s.x[0] - 1.0).abs() < 1e-7 && (s.x[1] - 2.0).abs() < 1e-7, "{:?}", s.x);
    }
}
