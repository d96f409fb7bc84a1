//! Symmetric positive definite banded systems (the contour fit's normal equations,
//! [`crate::boundary::fit`]), solved by banded Cholesky.

use crate::error::{Error, Result};

/// Symmetric banded matrix, `band[i][d] = A[i][i + d]` for `d <= bw`: the normal
/// equations of a least-squares fit in a B-spline basis of degree `p` have bandwidth `p`.
#[derive(Debug, Clone)]
pub(crate) struct Banded {
    /// Bandwidth.
    pub bw: usize,
    /// `band[i][d] = A[i][i + d]`.
    pub band: Vec<Vec<f64>>,
}

impl Banded {
    pub fn new(n: usize, bw: usize) -> Self {
        Self { bw, band: vec![vec![0.0; bw + 1]; n] }
    }

    /// Add `w` to `A[i][j]` (and implicitly `A[j][i]`), `i <= j <= i + bw`.
    pub fn add(&mut self, i: usize, j: usize, w: f64) {
        self.band[i][j - i] += w;
    }

    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if i <= j { (i, j) } else { (j, i) };
        if j - i > self.bw {
            0.0
        } else {
            self.band[i][j - i]
        }
    }

    /// Solve `A[lo..hi, lo..hi] x = rhs` (`rhs.len() == hi - lo`, two right-hand sides,
    /// the `x` and `y` coordinates) by banded Cholesky `A = L Lᵀ`, `O(n bw²)`.
    pub(crate) fn solve_block(&self, lo: usize, hi: usize, rhs: &mut [[f64; 2]]) -> Result<()> {
        let n = hi - lo;
        let bw = self.bw;
        // l[i][d] = L(i, i - d)
        let mut l = vec![vec![0.0; bw + 1]; n];
        for i in 0..n {
            for d in (0..=bw.min(i)).rev() {
                let j = i - d;
                let mut s = self.band[lo + j][d];
                for k in i.saturating_sub(bw)..j {
                    s -= l[i][i - k] * l[j][j - k];
                }
                if d == 0 {
                    if !(s > 0.0 && s.is_finite()) {
                        return Err(Error::LinearSolver(format!(
                            "contour fit: normal matrix not positive definite at unknown {} of {n} (pivot {s:e})",
                            i + 1
                        )));
                    }
                    l[i][0] = s.sqrt();
                } else {
                    l[i][d] = s / l[j][0];
                }
            }
        }
        for i in 0..n {
            let mut s = rhs[i];
            for k in i.saturating_sub(bw)..i {
                for c in 0..2 {
                    s[c] -= l[i][i - k] * rhs[k][c];
                }
            }
            rhs[i] = [s[0] / l[i][0], s[1] / l[i][0]];
        }
        for i in (0..n).rev() {
            let mut s = rhs[i];
            for k in i + 1..n.min(i + bw + 1) {
                for c in 0..2 {
                    s[c] -= l[k][k - i] * rhs[k][c];
                }
            }
            rhs[i] = [s[0] / l[i][0], s[1] / l[i][0]];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn banded_cholesky_matches_dense() {
        let n = 9;
        let bw = 2;
        let mut m = Banded::new(n, bw);
        for i in 0..n {
            m.add(i, i, 4.0 + i as f64);
            if i + 1 < n {
                m.add(i, i + 1, -1.0);
            }
            if i + 2 < n {
                m.add(i, i + 2, 0.5);
            }
        }
        let b: Vec<[f64; 2]> = (0..n).map(|i| [i as f64, 1.0 - i as f64 * 0.1]).collect();
        let mut x = b[2..7].to_vec();
        m.solve_block(2, 7, &mut x).unwrap();
        for i in 2..7 {
            for c in 0..2 {
                let r: f64 = (2..7).map(|j| m.get(i, j) * x[j - 2][c]).sum();
                assert!((r - b[i][c]).abs() < 1e-13);
            }
        }
    }
}
