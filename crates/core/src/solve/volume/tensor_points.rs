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
//! derivative `∂^(i,j,k)` taken from the tables `X^(i)`, `Y^(j)`, `Z^(k)`. The roles
//! `a, b, c` go to the directions by decreasing number of functions (the one with the
//! most first, [`contraction_order`]), and the element's points are numbered with the
//! direction contracted first fastest (the same order in every function here). The test
//! integrals `Σ_q f_q R_a(q)` are the transpose, in the reverse order. Only for the
//! polynomial basis: a rational basis's `R = w N / W` is not a tensor product.

use super::assembly::Tables;

/// The derivative orders `(x, y, z)` of the ten rows of a point: the value, the
/// gradient, and the Hessian's entries in the order of `egg::PAIRS`
/// (`xx, yy, zz, xy, xz, yz`).
const ROWS: [[usize; 3]; 10] =
    [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [2, 0, 0], [0, 2, 0], [0, 0, 2], [1, 1, 0], [1, 0, 1], [0, 1, 1]];

/// The derivative pairs of the first two contracted directions needed by [`ROWS`] (the
/// same six pairs in any order of the directions).
const PAIRS_XY: [[usize; 2]; 6] = [[0, 0], [1, 0], [0, 1], [2, 0], [0, 2], [1, 1]];

/// The contraction order of [`values`]: the directions by decreasing number of
/// functions `n_d = p_d + 1` (ties in their natural order). Contracting the direction
/// with the most functions first makes the passes cheaper: `n₀ n₁ n₂ g₀ + n₁ n₂ g₀ g₁ +
/// n₂ g₀ g₁ g₂` per derivative is smallest with `n₂`, the multiplier of the largest
/// term, the smallest (for degrees `(2, 2, 3)` and 5 points: 5,640 multiply-adds per
/// coefficient vector instead of 7,340 in the natural order).
fn contraction_order(t: [&Tables; 3]) -> [usize; 3] {
    let mut o = [0, 1, 2];
    o.sort_by_key(|&d| std::cmp::Reverse(t[d][0].0.degree));
    o
}

/// `f(i)` for the multi-indices `i = [i_x, i_y, i_z]` of a box of `g` (points or
/// functions) with the direction `o₀` fastest, then `o₁`, then `o₂`.
fn in_order<T>(g: [usize; 3], o: [usize; 3], mut f: impl FnMut([usize; 3]) -> T) -> Vec<T> {
    let mut out = Vec::with_capacity(g[0] * g[1] * g[2]);
    let mut i = [0; 3];
    for k2 in 0..g[o[2]] {
        i[o[2]] = k2;
        for k1 in 0..g[o[1]] {
            i[o[1]] = k1;
            for k0 in 0..g[o[0]] {
                i[o[0]] = k0;
                out.push(f(i));
            }
        }
    }
    out
}

/// An element's tables in the [`contraction_order`] `o`, with the numbers of functions
/// `nat` per direction, and `n` and of points `g` in that order.
struct Ordered<'a> {
    o: [usize; 3],
    nat: [usize; 3],
    t: [&'a Tables; 3],
    n: [usize; 3],
    g: [usize; 3],
}

impl<'a> Ordered<'a> {
    fn of(t: [&'a Tables; 3]) -> Self {
        let o = contraction_order(t);
        let nat: [usize; 3] = std::array::from_fn(|d| t[d][0].0.degree + 1);
        let t = [t[o[0]], t[o[1]], t[o[2]]];
        Self { o, nat, t, n: std::array::from_fn(|d| nat[o[d]]), g: std::array::from_fn(|d| t[d].len()) }
    }
}

/// [`in_order`]'s multi-indices as indices `(i_z g_y + i_y) g_x + i_x` of the natural
/// order.
fn natural_index(g: [usize; 3], o: [usize; 3]) -> Vec<usize> {
    in_order(g, o, |i| (i[2] * g[1] + i[1]) * g[0] + i[0])
}

/// The order of the element's Gauss points in [`weights`], [`values`], [`integrals`]
/// and [`stiffness`]: for each point `q`, its index `(i_z g_y + i_y) g_x + i_x` in the
/// natural order (the order of `EggVolume::element_points`). Points are numbered with
/// the direction contracted first by [`values`] fastest ([`contraction_order`]).
#[cfg(test)]
pub(super) fn points_in_natural_order(t: [&Tables; 3]) -> Vec<usize> {
    natural_index(std::array::from_fn(|d| t[d].len()), contraction_order(t))
}

/// The element's Gauss weights `w_q = w_x w_y w_z`, in the order of
/// [`points_in_natural_order`].
pub(super) fn weights(t: [&Tables; 3]) -> Vec<f64> {
    let g: [usize; 3] = std::array::from_fn(|d| t[d].len());
    in_order(g, contraction_order(t), |i| t[0][i[0]].1 * t[1][i[1]].1 * t[2][i[2]].1)
}

/// The ten rows (value, gradient, Hessian, [`ROWS`]) at every point of the element of
/// the tables `t` of each of the `k = u.len() / m` coefficient vectors `u` (column `c` at
/// `u[c m..]`, functions `a` fastest, as `VolumeDiscretization::element_indices`), in
/// the layout `out[(10 c + row) n_q + q]`, the points in the order of
/// [`points_in_natural_order`].
///
/// The directions are contracted in the [`contraction_order`] `o` (the one with the most
/// functions first). The first pass runs over all columns at once; the second leaves
/// each column's `(o₁, o₀)` plane of points contiguous, so that the last pass writes each
/// row of the output one plane at a time, each point's sum over the last direction's
/// functions taken whole (`((f₀ s₀ + f₁ s₁) + f₂ s₂)`, in one loop over the plane), with
/// no intermediate buffer or reordering of the result.
pub(super) fn values(t: [&Tables; 3], u: &[f64]) -> Vec<f64> {
    // the tables, sizes, coefficients and derivative orders in the contraction order
    let Ordered { o, nat, t, n, g } = Ordered::of(t);
    let m = n[0] * n[1] * n[2];
    let nq = g[0] * g[1] * g[2];
    let cols = u.len() / m;
    let permuted;
    let u = if o == [0, 1, 2] {
        u
    } else {
        let f = natural_index(nat, o);
        let mut p = Vec::with_capacity(u.len());
        for uc in u.chunks_exact(m) {
            p.extend(f.iter().map(|&a| uc[a]));
        }
        permuted = p;
        &permuted[..]
    };
    let rows: [[usize; 3]; 10] = std::array::from_fn(|row| std::array::from_fn(|d| ROWS[row][o[d]]));
    let row_pair: [usize; 10] =
        std::array::from_fn(|row| PAIRS_XY.iter().position(|p| p[..] == rows[row][..2]).unwrap_or(0));
    // U¹[dx][((c n₁ + b) cols + col) g₀ + x] (every buffer written in order or from its
    // first term, without a zero fill first)
    let s1 = n[2] * n[1] * cols * g[0];
    let mut u1 = Vec::with_capacity(3 * s1);
    for dx in 0..3 {
        for cb in 0..n[2] * n[1] {
            for col in 0..cols {
                let coef = &u[col * m + cb * n[0]..][..n[0]];
                u1.extend(
                    t[0].iter().map(|(tx, _)| coef.iter().zip(&tx.d[dx][..n[0]]).map(|(a, b)| a * b).sum::<f64>()),
                );
            }
        }
    }
    // U²[pair][((c cols + col) g₁ + y) g₀ + x]: a plane of (y, x) per (c, col)
    let plane = g[1] * g[0];
    let s2 = n[2] * cols * plane;
    let mut u2 = Vec::with_capacity(6 * s2);
    for &[dx, dy] in &PAIRS_XY {
        for c in 0..n[2] {
            for col in 0..cols {
                let src = |b: usize| &u1[dx * s1 + ((c * n[1] + b) * cols + col) * g[0]..][..g[0]];
                for (ty, _) in t[1] {
                    let f = &ty.d[dy][..n[1]];
                    let start = u2.len();
                    u2.extend(src(0).iter().map(|s| f[0] * s));
                    let dst = &mut u2[start..];
                    for (b, &fb) in f.iter().enumerate().skip(1) {
                        for (o, s) in dst.iter_mut().zip(src(b)) {
                            *o += fb * s;
                        }
                    }
                }
            }
        }
    }
    // out[(10 col + row) n_q + (z g₁ + y) g₀ + x], a plane at a time
    let mut out = Vec::with_capacity(cols * 10 * nq);
    for col in 0..cols {
        for (row, r) in rows.iter().enumerate() {
            let src = |c: usize| &u2[row_pair[row] * s2 + (c * cols + col) * plane..][..plane];
            for (tz, _) in t[2] {
                let f = &tz.d[r[2]][..n[2]];
                let start = out.len();
                out.extend(src(0).iter().map(|s| f[0] * s));
                let dst = &mut out[start..];
                for (c, &fc) in f.iter().enumerate().skip(1) {
                    for (o, s) in dst.iter_mut().zip(src(c)) {
                        *o += fc * s;
                    }
                }
            }
        }
    }
    out
}

/// `r[k m + a] = Σ_q f[k n_q + q] R_a(q)` for each of the `k = f.len() / n_q` point
/// vectors `f` (the points in the order of [`points_in_natural_order`]; the transpose of
/// [`values`]' value row), the functions `a` in the element's natural order.
///
/// The transpose of [`values`]' passes in the reverse order: the direction with the
/// fewest functions is contracted first, which is the cheapest order here.
pub(super) fn integrals(t: [&Tables; 3], f: &[f64]) -> Vec<f64> {
    let Ordered { o, nat, t, n, g } = Ordered::of(t);
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
    if o == [0, 1, 2] {
        return r;
    }
    // to the natural order of the functions
    let mut out = vec![0.0; cols * m];
    let f = natural_index(nat, o);
    for (oc, rc) in out.chunks_exact_mut(m).zip(r.chunks_exact(m)) {
        for (&a, &v) in f.iter().zip(rc) {
            oc[a] = v;
        }
    }
    out
}

/// The stiffness `K[b m + a] = Σ_q Σ_ij ∂_i R_a(q) C_ij(q) ∂_j R_b(q)` of the
/// coefficients `C_ij` at the points (`c[(3 i + j) n_q + q]`, the Gauss weights
/// included), sum factorised: `∂_i R_a = X^(δ_i0)_(a₀) Y^(δ_i1)_(a₁) Z^(δ_i2)_(a₂)`, so
/// for each `(i, j)`
///
/// `T¹_(a₀ b₀)(y, z) = Σ_x X^(δ_i0)_(a₀) X^(δ_j0)_(b₀) C_ij`,
/// `T²_(a₁ b₁ a₀ b₀)(z) = Σ_y Y^(δ_i1)_(a₁) Y^(δ_j1)_(b₁) T¹`,
///
/// the `T²` of the pairs with the same `z` derivatives `(δ_i2, δ_j2)` added (three
/// groups, see below), and `Σ_z Z^(δ_i2)_(a₂) Z^(δ_j2)_(b₂) T²` per group: `O(p^{d+1})`
/// per entry and point instead of `O(p^d)` per entry times `n_q` for the dense product
/// `Σ_q`. Only for the polynomial basis, as [`values`]. The points of `c` in the order of
/// [`points_in_natural_order`].
///
/// `C` is symmetric (`C_ij = C_ji`, the cofactor metric), so the pair `(j, i)` gives the
/// transpose of the pair `(i, j)`: the passes run over six pairs, for `Q = Σ_i S_ii / 2 +
/// Σ_(i<j) S_ij` (`S_ij` the pair's term, each off-diagonal pair oriented so that the
/// `z` derivative is not on `a` alone, [`symmetric_pairs`]), and `K = Q + Qᵀ`, symmetric
/// bit for bit; 6 of 9 pairs in the first two passes and 3 of 4 groups in the last. (The
/// entries move at rounding against the sum over all nine pairs.)
///
/// The roles `x, y, z` above go to the directions by increasing number of functions
/// (ties in their natural order), the cheapest order here (the first pass costs
/// `n_x²` per point, the second `n_x² n_y²` per `(y, z)` point); `c` is moved to that
/// order of the points first.
pub(super) fn stiffness(t: [&Tables; 3], c: &[f64]) -> Vec<f64> {
    let nat: [usize; 3] = std::array::from_fn(|d| t[d][0].0.degree + 1);
    let gn: [usize; 3] = std::array::from_fn(|d| t[d].len());
    let mut so = [0, 1, 2];
    so.sort_by_key(|&d| nat[d]);
    let o = contraction_order(t);
    let moved;
    let c = if so == o {
        c
    } else {
        // position of each point of the order `o` in the order `so`
        let (from, to) = (natural_index(gn, o), natural_index(gn, so));
        let mut at = vec![0; from.len()];
        for (q, &nq) in to.iter().enumerate() {
            at[nq] = q;
        }
        let nq = from.len();
        let mut v = vec![0.0; c.len()];
        for (dst, src) in v.chunks_exact_mut(nq).zip(c.chunks_exact(nq)) {
            for (&nat_q, &x) in from.iter().zip(src) {
                dst[at[nat_q]] = x;
            }
        }
        moved = v;
        &moved[..]
    };
    let t = [t[so[0]], t[so[1]], t[so[2]]];
    let n: [usize; 3] = std::array::from_fn(|d| nat[so[d]]);
    let g: [usize; 3] = std::array::from_fn(|d| t[d].len());
    let (m, nq) = (n[0] * n[1] * n[2], g[0] * g[1] * g[2]);
    // blocks (a₀, b₀), then [a₁][b₁][a₀ b₀]
    let b0 = n[0] * n[0];
    let b1 = n[1] * n[1] * b0;
    // T²[group][z][a₁][b₁][a₀ b₀], group 2 δ_i2 + δ_j2
    let mut t2 = vec![0.0; 4 * g[2] * b1];
    let mut t1 = vec![0.0; g[2] * g[1] * b0];
    for (i, j, half) in symmetric_pairs(so[2]) {
        let cij = &c[(3 * i + j) * nq..(3 * i + j + 1) * nq];
        let da: [usize; 3] = std::array::from_fn(|d| usize::from(so[d] == i));
        let db: [usize; 3] = std::array::from_fn(|d| usize::from(so[d] == j));
        for (dst, cz) in t1.chunks_exact_mut(b0).zip(cij.chunks_exact(g[0])) {
            for a0 in 0..n[0] {
                for bb in 0..n[0] {
                    dst[a0 * n[0] + bb] =
                        t[0].iter().zip(cz).map(|((tx, _), &cq)| tx.d[da[0]][a0] * tx.d[db[0]][bb] * cq).sum();
                }
            }
        }
        let group = &mut t2[(2 * da[2] + db[2]) * g[2] * b1..][..g[2] * b1];
        for (z, gz) in group.chunks_exact_mut(b1).enumerate() {
            for (ab, dst) in gz.chunks_exact_mut(b0).enumerate() {
                let (a1, bb) = (ab / n[1], ab % n[1]);
                for (y, (ty, _)) in t[1].iter().enumerate() {
                    let f = half * (ty.d[da[1]][a1] * ty.d[db[1]][bb]);
                    for (o, s) in dst.iter_mut().zip(&t1[(z * g[1] + y) * b0..][..b0]) {
                        *o += f * s;
                    }
                }
            }
        }
    }
    // Kᵇ[a₂][b₂][a₁][b₁][a₀ b₀]
    let mut kb = vec![0.0; n[2] * n[2] * b1];
    for (group, t2g) in t2.chunks_exact(g[2] * b1).enumerate() {
        let (dza, dzb) = (group / 2, group % 2);
        if group == 2 {
            // empty: no pair has the `z` derivative on `a` alone (`symmetric_pairs`)
            continue;
        }
        for (ab, dst) in kb.chunks_exact_mut(b1).enumerate() {
            let (a2, bb) = (ab / n[2], ab % n[2]);
            for ((tz, _), src) in t[2].iter().zip(t2g.chunks_exact(b1)) {
                let f = tz.d[dza][a2] * tz.d[dzb][bb];
                for (o, s) in dst.iter_mut().zip(src) {
                    *o += f * s;
                }
            }
        }
    }
    // to K[b m + a], `a` the natural index of the function `(a₂ n₁ + a₁) n₀ + a₀`
    let f = natural_index(nat, so);
    let mut k = vec![0.0; m * m];
    for (i, v) in kb.into_iter().enumerate() {
        let (a0b0, a1b1, a2b2) = (i % b0, (i / b0) % (n[1] * n[1]), i / b1);
        let (a0, bb0, a1, bb1, a2, bb2) =
            (a0b0 / n[0], a0b0 % n[0], a1b1 / n[1], a1b1 % n[1], a2b2 / n[2], a2b2 % n[2]);
        k[f[(bb2 * n[1] + bb1) * n[0] + bb0] * m + f[(a2 * n[1] + a1) * n[0] + a0]] = v;
    }
    // K = Q + Qᵀ (symmetric bit for bit)
    for a in 0..m {
        for b in 0..a {
            let v = k[a * m + b] + k[b * m + a];
            k[a * m + b] = v;
            k[b * m + a] = v;
        }
        k[a * m + a] += k[a * m + a];
    }
    k
}

/// The pairs `(i, j, s)` of [`stiffness`]'s half `Q = Σ_i C_ii / 2 + Σ_(i<j) C_ij`
/// (`K = Q + Qᵀ` as `C_ij = C_ji`): `s = 1/2` on the diagonal (exact), and each pair
/// off it oriented so that the direction `z` (contracted last) is not its first, so that
/// its `z` derivatives `(δ_iz, δ_jz)` fall in three groups, not four.
fn symmetric_pairs(z: usize) -> [(usize, usize, f64); 6] {
    let pair = |i: usize, j: usize| if i == z { (j, i, 1.0) } else { (i, j, 1.0) };
    [(0, 0, 0.5), pair(0, 1), pair(0, 2), (1, 1, 0.5), pair(1, 2), (2, 2, 0.5)]
}
