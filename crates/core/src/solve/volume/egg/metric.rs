//! The cofactor metric `A = cof(J)ᵀ cof(J)` at all Gauss points of an element, and the
//! scaled EGG operator `L_c = (A : ∇²x_c) / tr A` and its directional derivative from
//! it (the per-point work of [`super::EggVolume::element_linear`]; the formulas in the
//! parent module's doc and at [`residual`], [`linearised`]).
//!
//! The points are the lanes: every input is a row over the element's points (the
//! layout `x[(10 c + row) n_q + q]` of `tensor_points::values`: value, gradient and the
//! Hessian's entries in the order of `egg::PAIRS`, per coefficient column `c`), every
//! output a row over the points, and the loop over the points has no branch and no
//! reduction in it (the validity of `tr A` is an `and` over the points, the Winslow
//! energy's sum is taken afterwards in point order), so that the compiler can vectorise
//! it over the points. The operations at a point are those of the scalar formulas in
//! the same order: the results do not depend on how it is vectorised.

/// `((a₀ b₀ + a₁ b₁) + a₂ b₂)`.
#[inline(always)]
pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline(always)]
pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `A : H` for the symmetric `A` given by its six entries `[a₀₀, a₁₁, a₂₂, a₀₁, a₀₂,
/// a₁₂]` (the order of `egg::PAIRS`) and `H` by its six: `Σ_(i<=j) (2 - δ_ij) a_ij h_ij`,
/// summed in that order.
#[inline(always)]
fn contract(a: [f64; 6], h: [f64; 6]) -> f64 {
    a[0] * h[0] + a[1] * h[1] + a[2] * h[2] + 2.0 * a[3] * h[3] + 2.0 * a[4] * h[4] + 2.0 * a[5] * h[5]
}

/// `a + b`.
#[inline(always)]
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// The columns `d_j = ∂_j x` of `J` and the components' Hessians `∇²x_c` (entries in
/// the order of `egg::PAIRS`) at point `q` of the coefficient columns `first..first +
/// 3` of the rows `x` (array literals and a macro, not `std::array::from_fn` or
/// closures, which the compiler left as calls in the loop over the points: the closure
/// of a Hessian was called six times per point of `linearised`, 3 % of a 10^5 solve).
#[inline(always)]
fn jacobian_at(x: &[&[f64]; 60], first: usize, q: usize) -> ([[f64; 3]; 3], [[f64; 6]; 3]) {
    macro_rules! v {
        ($c:expr, $k:expr) => {
            x[10 * (first + $c) + $k][q]
        };
    }
    macro_rules! h {
        ($c:expr) => {
            [v!($c, 4), v!($c, 5), v!($c, 6), v!($c, 7), v!($c, 8), v!($c, 9)]
        };
    }
    let d = [[v!(0, 1), v!(1, 1), v!(2, 1)], [v!(0, 2), v!(1, 2), v!(2, 2)], [v!(0, 3), v!(1, 3), v!(2, 3)]];
    (d, [h!(0), h!(1), h!(2)])
}

/// The cofactor columns `c_i = d_(i+1) × d_(i+2)` and the six entries of `A_ij = c_i ·
/// c_j`.
#[inline(always)]
fn cofactor_metric(d: &[[f64; 3]; 3]) -> ([[f64; 3]; 3], [f64; 6]) {
    let c = [cross(d[1], d[2]), cross(d[2], d[0]), cross(d[0], d[1])];
    let a = [dot(c[0], c[0]), dot(c[1], c[1]), dot(c[2], c[2]), dot(c[0], c[1]), dot(c[0], c[2]), dot(c[1], c[2])];
    (c, a)
}

/// The rows of the `cols` coefficient columns of `x` (`x[(10 c + row) n_q + q]`), each
/// of length `n_q` (empty past `cols`).
#[inline(always)]
fn rows(x: &[f64], nq: usize, cols: usize) -> [&[f64]; 60] {
    std::array::from_fn(|k| if k < 10 * cols { &x[k * nq..(k + 1) * nq] } else { &[][..] })
}

/// At every point `q` (weights `w`) of the rows `x` of `x` itself (three columns): the
/// weighted operator `f[c n_q + q] = w_q (A : ∇²x_c / T)`, `T = tr A`, the weighted
/// Winslow density `density[q] = w_q T / det J` (`+∞` where `det J = d₀ · c₀ <= 0`),
/// and when `coef` is not empty the weighted metric `coef[(3 i + j) n_q + q] = w_q A_ij /
/// T`. `false` when `T` is not positive (or NaN) at a point (the outputs are then
/// meaningless).
pub(in crate::solve::volume) fn residual(
    w: &[f64],
    x: &[f64],
    f: &mut [f64],
    density: &mut [f64],
    coef: &mut [f64],
) -> bool {
    let metric = !coef.is_empty();
    let nq = w.len();
    let x = rows(x, nq, 3);
    let density = &mut density[..nq];
    let (f0, rest) = f.split_at_mut(nq);
    let (f1, f2) = rest.split_at_mut(nq);
    let (f1, f2) = (&mut f1[..nq], &mut f2[..nq]);
    let mut chunks = coef.chunks_exact_mut(nq.max(1));
    let coef: [&mut [f64]; 9] = std::array::from_fn(|_| chunks.next().map_or(&mut [][..], |c| &mut c[..nq]));
    let mut ok = true;
    for q in 0..nq {
        let wq = w[q];
        let (d, h) = jacobian_at(&x, 0, q);
        let (cof, a) = cofactor_metric(&d);
        let t = a[0] + a[1] + a[2];
        ok &= t > 0.0;
        f0[q] = wq * (contract(a, h[0]) / t);
        f1[q] = wq * (contract(a, h[1]) / t);
        f2[q] = wq * (contract(a, h[2]) / t);
        let det = dot(d[0], cof[0]);
        density[q] = wq * if det > 0.0 { t / det } else { f64::INFINITY };
        if metric {
            // A_ij in the order (3 i + j)
            let full = [a[0], a[3], a[4], a[3], a[1], a[5], a[4], a[5], a[2]];
            for k in 0..9 {
                coef[k][q] = wq * full[k] / t;
            }
        }
    }
    ok
}

/// At every point `q` (weights `w`) of the rows `x` of `x` (columns 0..3) and of a
/// displacement `δx` (columns 3..6): the weighted directional derivative of the
/// operator,
///
/// `f[c n_q + q] = w_q (δA : X_c + A : δX_c - L_c δT) / T`, `L_c = A : X_c / T`,
/// `δA_ij = δc_i · c_j + c_i · δc_j`, `δc_i = δd_(i+1) × d_(i+2) + d_(i+1) × δd_(i+2)`,
/// `δT = tr δA`
///
/// (`X_c = ∇²x_c`, `δX_c = ∇²δx_c`, `δd_j = ∂_j δx`). `false` when `T = tr A` is not
/// positive (or NaN) at a point.
pub(in crate::solve::volume) fn linearised(w: &[f64], x: &[f64], f: &mut [f64]) -> bool {
    linearised_points(w, x, f)
}

#[inline(always)]
fn linearised_points(w: &[f64], x: &[f64], f: &mut [f64]) -> bool {
    let nq = w.len();
    let x = rows(x, nq, 6);
    let (f0, rest) = f.split_at_mut(nq);
    let (f1, f2) = rest.split_at_mut(nq);
    let (f1, f2) = (&mut f1[..nq], &mut f2[..nq]);
    let mut ok = true;
    for q in 0..nq {
        let wq = w[q];
        let (d, h) = jacobian_at(&x, 0, q);
        let (dd, dh) = jacobian_at(&x, 3, q);
        let (cof, a) = cofactor_metric(&d);
        let t = a[0] + a[1] + a[2];
        ok &= t > 0.0;
        let dcof = [
            add(cross(dd[1], d[2]), cross(d[1], dd[2])),
            add(cross(dd[2], d[0]), cross(d[2], dd[0])),
            add(cross(dd[0], d[1]), cross(d[0], dd[1])),
        ];
        let da = |i: usize, j: usize| dot(dcof[i], cof[j]) + dot(cof[i], dcof[j]);
        let da = [da(0, 0), da(1, 1), da(2, 2), da(0, 1), da(0, 2), da(1, 2)];
        let dt = da[0] + da[1] + da[2];
        let out = |c: usize| {
            let l = contract(a, h[c]) / t;
            wq * ((contract(da, h[c]) + contract(a, dh[c]) - l * dt) / t)
        };
        (f0[q], f1[q], f2[q]) = (out(0), out(1), out(2));
    }
    ok
}
