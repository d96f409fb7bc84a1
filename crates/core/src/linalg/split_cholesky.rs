//! Sparse Cholesky of a symmetric positive definite matrix in nested-dissection order,
//! split at its top separator so that the two halves are factorized at once, on two
//! threads (faer's supernodal factorization runs its supernodes one after another, and its
//! threads inside the dense blocks were slower on 2 cores, see `linsolve`).
//!
//! In nested-dissection order ([`crate::linalg::ordering`]) the matrix is
//! `A = [[A₁, 0, C₁ᵀ], [0, A₂, C₂ᵀ], [C₁, C₂, A₃]]`, the halves uncoupled, and its factor is
//! `L = [[L₁, 0, 0], [0, L₂, 0], [W₁ᵀ, W₂ᵀ, L₃]]` with `L_h L_hᵀ = A_h`, `W_h = L_h⁻¹ C_hᵀ`
//! and `L₃ L₃ᵀ = S = A₃ - X₁ - X₂`, `X_h = W_hᵀ W_h = C_h A_h⁻¹ C_hᵀ`.
//!
//! Each half is factorized with its separator bordered by `τ I`,
//! `M_h = [[A_h, C_hᵀ], [C_h, τ I]] = [[L_h, 0], [W_hᵀ, R_h]] [[L_h, 0], [W_hᵀ, R_h]]ᵀ`,
//! `R_h R_hᵀ = τ I - X_h`: one supernodal factorization per half gives `L_h`, `W_h` and
//! `X_h = τ I - R_h R_hᵀ`, then a dense Cholesky of `S` (the separator's size `s` is
//! `O(√n)` on a spline grid). With `τ` the largest absolute row sum of `A₃`, `τ >=
//! λ_max(A₃)`, and where `A` is positive definite `A₃ > X₁ + X₂` gives `τ I - X_h > X_other
//! >= 0`: each `M_h` is definite. A failure of either factorization, or of the dense one,
//! therefore proves `A` not positive definite, as the whole factorization's would.
//!
//! A solve runs both halves at once too: forward through `M_h` on `[b_h; 0]` gives `[y_h;
//! t_h]` with `y_h = L_h⁻¹ b_h` and `W_hᵀ y_h = -R_h t_h`; `x₃ = S⁻¹ (b₃ - W₁ᵀ y₁ - W₂ᵀ
//! y₂)`; backward through `M_h` on `[y_h; R_hᵀ x₃]` gives `[x_h; x₃]`.
//!
//! The factor is held in double or single precision ([`Scalar`]): `f64` for direct
//! solves, `f32` for a preconditioner (the right-hand sides and solutions are `f64`,
//! rounded to `T` on the way in and widened on the way out).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::linalg::matmul::triangular::{matmul, BlockStructure};
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Accum, Conj, Mat, MatMut, Par, Side};

use crate::error::{Error, Result};
use crate::linalg::ordering;
use crate::linalg::sparse::Csr;

/// Floating-point type of a Cholesky factor: `f64` for direct solves, `f32` for the
/// preconditioners, whose triangular solves are bound by memory bandwidth and take 30 %
/// less time in single precision (the GMRES iteration counts are unchanged on the
/// shared geometries; flexible GMRES absorbs the rounding of the preconditioner).
pub trait Scalar:
    faer::traits::RealField
    + faer::traits::ComplexField<Real = Self>
    + Copy
    + Send
    + Sync
    + std::ops::Add<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::SubAssign
    + std::ops::AddAssign
    + std::ops::Neg<Output = Self>
    + std::iter::Sum
    + 'static
{
    /// `v` rounded to `Self`.
    fn of(v: f64) -> Self;
    /// `self` as `f64` (exact).
    fn wide(self) -> f64;
    /// `v` as `Self`, `buf` as storage when a conversion is needed.
    fn cast<'a>(v: &'a [f64], buf: &'a mut Vec<Self>) -> &'a [Self];
    /// Overwrite `x` with `A^{-1} x` through the factor `llt`.
    fn solve(llt: LltRef<'_, usize, Self>, x: &mut [f64], buf: &mut Vec<Self>, scratch: &mut MemBuffer);
}

fn solve_in_place<T: Scalar>(llt: LltRef<'_, usize, T>, x: &mut [T], scratch: &mut MemBuffer) {
    let n = x.len();
    llt.solve_in_place_with_conj(
        Conj::No,
        MatMut::from_column_major_slice_mut(x, n, 1),
        Par::Seq,
        MemStack::new(scratch),
    );
}

impl Scalar for f64 {
    fn of(v: f64) -> Self {
        v
    }
    fn wide(self) -> f64 {
        self
    }
    fn cast<'a>(v: &'a [f64], _: &'a mut Vec<Self>) -> &'a [Self] {
        v
    }
    fn solve(llt: LltRef<'_, usize, Self>, x: &mut [f64], _: &mut Vec<Self>, scratch: &mut MemBuffer) {
        solve_in_place(llt, x, scratch);
    }
}

impl Scalar for f32 {
    fn of(v: f64) -> Self {
        v as f32
    }
    fn wide(self) -> f64 {
        f64::from(self)
    }
    fn cast<'a>(v: &'a [f64], buf: &'a mut Vec<Self>) -> &'a [Self] {
        buf.clear();
        buf.extend(v.iter().map(|&t| t as f32));
        buf
    }
    fn solve(llt: LltRef<'_, usize, Self>, x: &mut [f64], buf: &mut Vec<Self>, scratch: &mut MemBuffer) {
        Self::cast(x, buf);
        solve_in_place(llt, buf, scratch);
        for (xi, &b) in x.iter_mut().zip(buf.iter()) {
            *xi = f64::from(b);
        }
    }
}

/// Smallest system that is split. Measured on the Winslow Hessians of the shared
/// geometries (factorization and one solve, whole against split, 2 cores): 1058 unknowns
/// 1.63 / 0.07 ms against 1.59 / 0.14 ms (the solve's two threads cost more than they
/// save), 2520: 5.40 / 0.36 against 4.12 / 0.39 ms, 4590: 6.81 / 0.66 against 4.52 /
/// 0.48 ms, 9984 (jigsaw01): 18.9 / 1.51 against 9.78 / 1.07 ms.
pub const SPLIT_MIN: usize = 2048;

/// Marks the entries of `M_h` that are the border `τ` (not read from `A`).
const BORDER: usize = usize::MAX;

/// One half `M_h` of the split: its pattern (lower triangle, local numbering: the half's
/// unknowns in order, then the separator's), where each entry comes from in `A`, the
/// symbolic analysis, the factor and `X_h`.
struct Half<T: Scalar> {
    /// First unknown of the half in the nested-dissection order, and its length `n_h`.
    first: usize,
    len: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Position of each entry in `A`'s values ([`BORDER`] for `τ` on the separator's diagonal).
    src: Vec<usize>,
    entries: Vec<T>,
    symbolic: SymbolicCholesky<usize>,
    values: Vec<T>,
    factor_scratch: MemBuffer,
    solve_scratch: MemBuffer,
    /// `R_h` (lower triangle of the factor's separator block), then `X_h = τ I - R_h R_hᵀ`
    /// (lower triangle).
    r: Mat<T>,
    x: Mat<T>,
    /// A right-hand side of `M_h`.
    rhs: Vec<T>,
}

/// See the module documentation; the factor in the precision `T`.
pub struct SplitCholesky<T: Scalar = f64> {
    /// `order[new] = old`.
    order: Vec<usize>,
    halves: [Half<T>; 2],
    /// First unknown of the separator in the order, and its size `s`.
    sep: usize,
    s: usize,
    /// `(i, j, position in A)` of the separator block's lower triangle, local indices.
    a3: Vec<(usize, usize, usize)>,
    /// `S`, then its Cholesky factor `L₃` (lower triangle), and whether it holds one.
    s3: Mat<T>,
    factored: bool,
    dense_scratch: MemBuffer,
    /// Storage of one permuted column.
    work: Vec<T>,
}

impl<T: Scalar> std::fmt::Debug for SplitCholesky<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SplitCholesky")
            .field("n", &self.order.len())
            .field("halves", &[self.halves[0].len, self.halves[1].len])
            .field("separator", &self.s)
            .field("bytes", &std::mem::size_of::<T>())
            .finish()
    }
}

/// The top-level split of the nested-dissection order `order` of the symmetric pattern
/// `a`, found from the pattern: the longest leading part `[0, t)` of the order whose
/// unknowns form exactly two connected components, `[0, k)` and `[k, t)` (the halves),
/// the rest `[t, n)` being the separator. `None` when the order has no such part, or the
/// halves are unbalanced (each at least `n / 8`) or the separator large (over `n / 4`).
pub(crate) fn top_split(a: &Csr, order: &[usize]) -> Option<[usize; 3]> {
    let n = order.len();
    let inv = ordering::inverse(order);
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let add = |parent: &mut [usize], t: usize| -> usize {
        let mut merges = 0;
        for (c, _) in a.row(order[t]) {
            let j = inv[c];
            if j < t {
                let (ri, rj) = (find(parent, t), find(parent, j));
                if ri != rj {
                    parent[ri] = rj;
                    merges += 1;
                }
            }
        }
        merges
    };
    // components of [0, t) for every t, then the largest t with two
    let mut components = 0usize;
    let mut two = None;
    for t in 0..n {
        components = components + 1 - add(&mut parent, t);
        if components == 2 {
            two = Some(t + 1);
        }
    }
    let t = two.filter(|&t| t < n)?;
    let mut parent: Vec<usize> = (0..n).collect();
    for i in 0..t {
        add(&mut parent, i);
    }
    let first = find(&mut parent, 0);
    let k = (0..t).find(|&i| find(&mut parent, i) != first)?;
    let second = find(&mut parent, k);
    let contiguous = (0..k).all(|i| find(&mut parent, i) == first) && (k..t).all(|i| find(&mut parent, i) == second);
    let (n1, n2, s) = (k, t - k, n - t);
    (contiguous && n1.min(n2) >= n / 8 && s <= n / 4).then_some([n1, n2, s])
}

impl<T: Scalar> SplitCholesky<T> {
    /// Symbolic analysis of the SPD pattern of `a` in the nested-dissection order `order`
    /// (`order[new] = old`); `None` when `top_split` finds no split or faer's analysis
    /// of a half is not supernodal. (Worth it from [`SPLIT_MIN`] unknowns on two threads
    /// or more: the caller decides.)
    pub fn analyze(a: &Csr, order: &[usize]) -> Option<Self> {
        let n = a.nrows;
        if order.len() != n {
            return None;
        }
        let [n1, n2, s] = top_split(a, order)?;
        let sep = n1 + n2;
        let inv = ordering::inverse(order);
        let half = |first: usize, len: usize| -> Option<Half<T>> {
            // local index of a new index in this half or the separator
            let local = |j: usize| match j {
                j if (first..first + len).contains(&j) => Some(j - first),
                j if j >= sep => Some(len + j - sep),
                _ => None,
            };
            let m = len + s;
            let (mut col_ptr, mut row_idx, mut src) = (vec![0], Vec::new(), Vec::new());
            let mut col: Vec<(usize, usize)> = Vec::new();
            for jl in 0..m {
                col.clear();
                if jl < len {
                    let old = order[first + jl];
                    for k in a.row_ptr[old]..a.row_ptr[old + 1] {
                        if let Some(il) = local(inv[a.col_idx[k]]).filter(|&il| il >= jl) {
                            col.push((il, k));
                        }
                    }
                    col.sort_unstable();
                } else {
                    col.push((jl, BORDER));
                }
                row_idx.extend(col.iter().map(|e| e.0));
                src.extend(col.iter().map(|e| e.1));
                col_ptr.push(row_idx.len());
            }
            // faer's analysis in the identity order reads the upper triangle (the numeric
            // factorization then the lower one): the transpose of the lower pattern
            let mut up_ptr = vec![0usize; m + 1];
            for &i in &row_idx {
                up_ptr[i + 1] += 1;
            }
            for i in 0..m {
                up_ptr[i + 1] += up_ptr[i];
            }
            let mut next = up_ptr.clone();
            let mut up_idx = vec![0usize; row_idx.len()];
            for j in 0..m {
                for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                    up_idx[next[i]] = j;
                    next[i] += 1;
                }
            }
            let pattern = SymbolicSparseColMatRef::new_checked(m, m, &up_ptr, None, &up_idx);
            let params = CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            let symbolic =
                factorize_symbolic_cholesky(pattern, Side::Upper, SymmetricOrdering::Identity, params).ok()?;
            let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else { return None };
            let solve_scratch = MemBuffer::try_new(sn.solve_in_place_scratch::<T>(1, Par::Seq)).ok()?;
            let factor_scratch =
                MemBuffer::try_new(symbolic.factorize_numeric_llt_scratch::<T>(Par::Seq, Default::default())).ok()?;
            Some(Half {
                first,
                len,
                entries: vec![T::of(0.0); src.len()],
                col_ptr,
                row_idx,
                src,
                values: vec![T::of(0.0); symbolic.len_val()],
                symbolic,
                factor_scratch,
                solve_scratch,
                r: Mat::zeros(s, s),
                x: Mat::zeros(s, s),
                rhs: vec![T::of(0.0); m],
            })
        };
        let (h1, h2) = rayon::join(|| half(0, n1), || half(n1, n2));
        let halves = [h1?, h2?];
        let mut a3 = Vec::new();
        for il in 0..s {
            let old = order[sep + il];
            for k in a.row_ptr[old]..a.row_ptr[old + 1] {
                let j = inv[a.col_idx[k]];
                if j >= sep && j - sep <= il {
                    a3.push((il, j - sep, k));
                }
            }
        }
        let dense_scratch =
            MemBuffer::try_new(llt::factor::cholesky_in_place_scratch::<T>(s, Par::Seq, Default::default())).ok()?;
        Some(Self {
            order: order.to_vec(),
            halves,
            sep,
            s,
            a3,
            s3: Mat::zeros(s, s),
            factored: false,
            dense_scratch,
            work: vec![T::of(0.0); n],
        })
    }

    /// Numeric factorization of `a` (the pattern analyzed); an error when `a` is not
    /// positive definite.
    pub fn factor(&mut self, a: &Csr) -> Result<()> {
        let s = self.s;
        // τ: the largest absolute row sum of A₃ (both triangles: the lower one twice
        // off the diagonal)
        let mut rows = vec![0.0f64; s];
        for &(i, j, k) in &self.a3 {
            let v = a.values[k].abs();
            rows[i] += v;
            if i != j {
                rows[j] += v;
            }
        }
        let tau = T::of(rows.iter().fold(0.0f64, |m, &v| m.max(v)).max(f64::MIN_POSITIVE));
        let [h1, h2] = &mut self.halves;
        let (r1, r2) = rayon::join(|| h1.factor(a, tau), || h2.factor(a, tau));
        r1?;
        r2?;
        // S = A₃ - X₁ - X₂ (lower triangle)
        self.factored = false;
        let sm = &mut self.s3;
        for j in 0..s {
            for i in j..s {
                sm[(i, j)] = -(self.halves[0].x[(i, j)] + self.halves[1].x[(i, j)]);
            }
        }
        for &(i, j, k) in &self.a3 {
            sm[(i, j)] += T::of(a.values[k]);
        }
        llt::factor::cholesky_in_place(
            sm.as_mut(),
            Default::default(),
            Par::Seq,
            MemStack::new(&mut self.dense_scratch),
            Default::default(),
        )
        .map_err(|e| Error::LinearSolver(format!("Cholesky: matrix not positive definite (separator: {e:?})")))?;
        self.factored = true;
        Ok(())
    }

    /// Overwrite each column of `x` (columns of length `n`, one after another) with
    /// `A⁻¹ x`.
    pub fn solve_columns(&mut self, x: &mut [f64]) {
        let n = self.order.len();
        if !self.factored {
            return;
        }
        let sep = self.sep;
        for col in x.chunks_mut(n) {
            for (w, &old) in self.work.iter_mut().zip(&self.order) {
                *w = T::of(col[old]);
            }
            let (body, b3) = self.work.split_at_mut(sep);
            let [h1, h2] = &mut self.halves;
            let rhs: &[T] = body;
            let (g1, g2) = rayon::join(|| h1.forward(rhs), || h2.forward(rhs));
            for (i, b) in b3.iter_mut().enumerate() {
                *b -= g1[i] + g2[i];
            }
            let x3 = MatMut::from_column_major_slice_mut(b3, self.s, 1);
            llt::solve::solve_in_place_with_conj(self.s3.as_ref(), Conj::No, x3, Par::Seq, MemStack::new(&mut []));
            let x3: &[T] = b3;
            let (lo, hi) = body.split_at_mut(h2.first);
            rayon::join(|| h1.backward(lo, x3), || h2.backward(hi, x3));
            for (w, &old) in self.work.iter().zip(&self.order) {
                col[old] = w.wide();
            }
        }
    }

    /// Size of the system.
    pub fn dim(&self) -> usize {
        self.order.len()
    }
}

/// The supernodal factor of a half (its analysis is supernodal: checked in
/// [`SplitCholesky::analyze`]).
fn supernodal<'a, T: Scalar>(symbolic: &'a SymbolicCholesky<usize>, values: &'a [T]) -> SupernodalLltRef<'a, usize, T> {
    let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else { unreachable!("checked in analyze") };
    SupernodalLltRef::new(sn, values)
}

impl<T: Scalar> Half<T> {
    /// Factorize `M_h` with border `tau`, then `R_h` and `X_h = τ I - R_h R_hᵀ`.
    fn factor(&mut self, a: &Csr, tau: T) -> Result<()> {
        for (e, &k) in self.entries.iter_mut().zip(&self.src) {
            *e = if k == BORDER { tau } else { T::of(a.values[k]) };
        }
        let m = self.col_ptr.len() - 1;
        let pattern = SymbolicSparseColMatRef::new_checked(m, m, &self.col_ptr, None, &self.row_idx);
        self.symbolic
            .factorize_numeric_llt(
                &mut self.values,
                SparseColMatRef::new(pattern, &self.entries),
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut self.factor_scratch),
                Default::default(),
            )
            .map_err(|e| Error::LinearSolver(format!("Cholesky: matrix not positive definite ({e:?})")))?;
        // R_h: the separator columns of the factor (the last supernodes)
        let len = self.len;
        let Self { symbolic, values, r, x, .. } = self;
        let l = supernodal(symbolic, values);
        for k in 0..l.symbolic().n_supernodes() {
            let node = l.supernode(k);
            let (start, val) = (node.start(), node.val());
            let ncols = val.ncols();
            if start + ncols <= len {
                continue;
            }
            for jc in (len.max(start) - start)..ncols {
                let j = start + jc - len;
                for ic in jc..ncols {
                    r[(start + ic - len, j)] = val[(ic, jc)];
                }
                for (p, &row) in node.pattern().iter().enumerate() {
                    r[(row - len, j)] = val[(ncols + p, jc)];
                }
            }
        }
        matmul(
            x.as_mut(),
            BlockStructure::TriangularLower,
            Accum::Replace,
            r.as_ref(),
            BlockStructure::TriangularLower,
            r.as_ref().transpose(),
            BlockStructure::TriangularUpper,
            T::of(-1.0),
            Par::Seq,
        );
        for i in 0..m - len {
            x[(i, i)] += tau;
        }
        Ok(())
    }

    /// Forward solve through `M_h` on `[b_h; 0]` (`body` holds all halves' right-hand
    /// sides): `y_h = L_h⁻¹ b_h` kept in `rhs`, `W_hᵀ y_h = -R_h t_h` returned.
    fn forward(&mut self, body: &[T]) -> Vec<T> {
        let len = self.len;
        self.rhs[..len].copy_from_slice(&body[self.first..self.first + len]);
        self.rhs[len..].fill(T::of(0.0));
        let m = self.rhs.len();
        let Self { symbolic, values, solve_scratch, rhs, r, .. } = self;
        supernodal(symbolic, values).l_solve_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, m, 1),
            Par::Seq,
            MemStack::new(solve_scratch),
        );
        let t = &rhs[len..];
        (0..t.len()).map(|i| -(0..=i).map(|j| r[(i, j)] * t[j]).sum::<T>()).collect()
    }

    /// Backward solve through `M_h` on `[y_h; R_hᵀ x₃]`: `x_h` into `out`.
    fn backward(&mut self, out: &mut [T], x3: &[T]) {
        let (len, s) = (self.len, x3.len());
        let m = self.rhs.len();
        let Self { symbolic, values, solve_scratch, rhs, r, .. } = self;
        for j in 0..s {
            rhs[len + j] = (j..s).map(|i| r[(i, j)] * x3[i]).sum();
        }
        supernodal(symbolic, values).l_transpose_solve_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, m, 1),
            Par::Seq,
            MemStack::new(solve_scratch),
        );
        out[..len].copy_from_slice(&rhs[..len]);
    }
}

#[cfg(test)]
mod tests;
