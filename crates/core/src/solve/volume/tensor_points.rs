//! Sum factorisation on an element's tensor Gauss points: a B-spline volume's values,
//! gradients and Hessians at all points of an element, and the integrals against its
//! basis functions, one direction at a time from the univariate tables.
//!
//! On an element with `m = n₀ n₁ n₂` functions (`n_d = p_d + 1`) and `g₀ g₁ g₂` points,
//! `u(q) = Σ_abc u_abc X_a(x_q) Y_b(y_q) Z_c(z_q)` costs `m` per point through the tensor
//! basis table (`O(p^{2d})` per element and derivative); contracting `a`, then `b`, then
//! `c`,
//!
//! `U¹_cb(x) = Σ_a u_abc X_a(x)`, `U²_c(x, y) = Σ_b U¹_cb(x) Y_b(y)`,
//! `u(x, y, z) = Σ_c U²_c(x, y) Z_c(z)`,
//!
//! costs `n₀ n₁ n₂ g₀ + n₁ n₂ g₀ g₁ + n₂ g₀ g₁ g₂` (`O(p^{d+1})` per point), with any
//! derivative `∂^(i,j,k)` taken from the tables `X^(i)`, `Y^(j)`, `Z^(k)`. The test
//! integrals `Σ_q f_q R_a(q)` are the transpose, in the reverse order. Only for the
//! polynomial basis: a rational basis's `R = w N / W` is not a tensor product.

use super::assembly::Tables;

/// The derivative orders `(x, y, z)` of the ten rows of a point: the value, the
/// gradient, and the Hessian's entries in the order of `egg::PAIRS`
/// (`xx, yy, zz, xy, xz, yz`).
const ROWS: [[usize; 3]; 10] =
    [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [2, 0, 0], [0, 2, 0], [0, 0, 2], [1, 1, 0], [1, 0, 1], [0, 1, 1]];

/// The `(x, y)` derivative pairs needed by [`ROWS`], and each row's pair.
const PAIRS_XY: [[usize; 2]; 6] = [[0, 0], [1, 0], [0, 1], [2, 0], [0, 2], [1, 1]];
const ROW_PAIR: [usize; 10] = [0, 1, 2, 0, 3, 4, 0, 5, 1, 2];

/// The element's Gauss weights `w_q = w_x w_y w_z`, `q = (z g₁ + y) g₀ + x`.
pub(super) fn weights(t: [&Tables; 3]) -> Vec<f64> {
    let mut w = Vec::with_capacity(t[0].len() * t[1].len() * t[2].len());
    for (_, wz) in t[2] {
        for (_, wy) in t[1] {
            for (_, wx) in t[0] {
                w.push(wx * wy * wz);
            }
        }
    }
    w
}

/// The ten rows (value, gradient, Hessian, [`ROWS`]) at every point of the element of
/// the tables `t` of each of the `k = u.len() / m` coefficient vectors `u` (column `c` at
/// `u[c m..]`, functions `a` fastest, as `VolumeDiscretization::element_indices`), in
/// the layout `out[(10 c + row) n_q + q]`.
pub(super) fn values(t: [&Tables; 3], u: &[f64]) -> Vec<f64> {
    let n: [usize; 3] = std::array::from_fn(|d| t[d][0].0.degree + 1);
    let g: [usize; 3] = std::array::from_fn(|d| t[d].len());
    let m = n[0] * n[1] * n[2];
    let nq = g[0] * g[1] * g[2];
    let cols = u.len() / m;
    let mut out = vec![0.0; cols * 10 * nq];
    // U¹[dx][(c n₁ + b) g₀ + x], U²[pair][(c g₁ + y) g₀ + x]
    let mut u1 = vec![0.0; 3 * n[2] * n[1] * g[0]];
    let mut u2 = vec![0.0; 6 * n[2] * g[1] * g[0]];
    for (col, uc) in u.chunks_exact(m).enumerate() {
        let s1 = n[2] * n[1] * g[0];
        for dx in 0..3 {
            for cb in 0..n[2] * n[1] {
                let coef = &uc[cb * n[0]..(cb + 1) * n[0]];
                for (x, (tx, _)) in t[0].iter().enumerate() {
                    let row = &tx.d[dx][..n[0]];
                    u1[dx * s1 + cb * g[0] + x] = coef.iter().zip(row).map(|(a, b)| a * b).sum();
                }
            }
        }
        let s2 = n[2] * g[1] * g[0];
        for (pair, &[dx, dy]) in PAIRS_XY.iter().enumerate() {
            for c in 0..n[2] {
                for (y, (ty, _)) in t[1].iter().enumerate() {
                    let dst = &mut u2[pair * s2 + (c * g[1] + y) * g[0]..][..g[0]];
                    dst.fill(0.0);
                    for b in 0..n[1] {
                        let f = ty.d[dy][b];
                        let src = &u1[dx * s1 + (c * n[1] + b) * g[0]..][..g[0]];
                        for (o, s) in dst.iter_mut().zip(src) {
                            *o += f * s;
                        }
                    }
                }
            }
        }
        // each row's values over the points, a plane of (x, y) at a time (vectorised)
        let plane = g[1] * g[0];
        for (row, r) in ROWS.iter().enumerate() {
            let src = &u2[ROW_PAIR[row] * s2..(ROW_PAIR[row] + 1) * s2];
            let dst = &mut out[(col * 10 + row) * nq..(col * 10 + row + 1) * nq];
            for (z, (tz, _)) in t[2].iter().enumerate() {
                let dz = &mut dst[z * plane..(z + 1) * plane];
                for c in 0..n[2] {
                    let f = tz.d[r[2]][c];
                    for (o, s) in dz.iter_mut().zip(&src[c * plane..(c + 1) * plane]) {
                        *o += f * s;
                    }
                }
            }
        }
    }
    out
}

/// `r[k m + a] = Σ_q f[k n_q + q] R_a(q)` for each of the `k = f.len() / n_q` point
/// vectors `f` (the transpose of [`values`]' value row).
pub(super) fn integrals(t: [&Tables; 3], f: &[f64]) -> Vec<f64> {
    let n: [usize; 3] = std::array::from_fn(|d| t[d][0].0.degree + 1);
    let g: [usize; 3] = std::array::from_fn(|d| t[d].len());
    let (m, nq) = (n[0] * n[1] * n[2], g[0] * g[1] * g[2]);
    let cols = f.len() / nq;
    let mut r = vec![0.0; cols * m];
    // F²[(c g₁ + y) g₀ + x], F¹[(c n₁ + b) g₀ + x]
    let mut f2 = vec![0.0; n[2] * g[1] * g[0]];
    let mut f1 = vec![0.0; n[2] * n[1] * g[0]];
    for (col, fc) in f.chunks_exact(nq).enumerate() {
        f2.fill(0.0);
        let plane = g[1] * g[0];
        for (z, (tz, _)) in t[2].iter().enumerate() {
            let src = &fc[z * plane..(z + 1) * plane];
            for c in 0..n[2] {
                let w = tz.d[0][c];
                for (o, s) in f2[c * plane..(c + 1) * plane].iter_mut().zip(src) {
                    *o += w * s;
                }
            }
        }
        f1.fill(0.0);
        for c in 0..n[2] {
            for (y, (ty, _)) in t[1].iter().enumerate() {
                let src = &f2[(c * g[1] + y) * g[0]..][..g[0]];
                for b in 0..n[1] {
                    let w = ty.d[0][b];
                    for (o, s) in f1[(c * n[1] + b) * g[0]..][..g[0]].iter_mut().zip(src) {
                        *o += w * s;
                    }
                }
            }
        }
        let rc = &mut r[col * m..(col + 1) * m];
        for cb in 0..n[2] * n[1] {
            let src = &f1[cb * g[0]..(cb + 1) * g[0]];
            for a in 0..n[0] {
                rc[cb * n[0] + a] = t[0].iter().zip(src).map(|((tx, _), s)| tx.d[0][a] * s).sum();
            }
        }
    }
    r
}
