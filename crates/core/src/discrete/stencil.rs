//! The product of a free-free Galerkin system with a vector straight from the stencil
//! storage the assemblers write, without a sparse matrix: on one patch every function
//! `k = j n_xi + i` couples to the `(2p + 1)(2q + 1)` functions
//! `k + (di - p) + n_xi (dj - q)` at slot `s = dj (2p + 1) + di` (see
//! [`super::pattern`]), so the column of an entry follows from its slot, and no column
//! index or gather map is stored.
//!
//! `y_{z m + f} = sum_d sum_s S[k, z, d, s] x_{d m + f(k_s)}` over the free neighbours
//! `k_s` of the free function `k` with free index `f`, components `z, d` (the EGG
//! Jacobian of eq. 12: `c = 2`; the metric Laplacian: `c = 1`).

use rayon::prelude::*;

use super::assembly::{Discretization, Operator};
use super::dofs::FIXED;
use crate::error::Result;
use crate::linalg::krylov::MatVec;
use crate::linalg::multigrid::GridStencil;

/// Functions of the stencil product per parallel task (their rows of every component).
const ROWS_PER_TASK: usize = 1024;

/// Stencil storage as [`Discretization::stencil_product`] reads it: entry `i` as `f64`.
pub(crate) trait StencilValues: Sync {
    /// Entry `i`.
    fn at(&self, i: usize) -> f64;
    /// Number of entries.
    fn entries(&self) -> usize;
}

impl StencilValues for [f64] {
    #[inline]
    fn at(&self, i: usize) -> f64 {
        self[i]
    }
    fn entries(&self) -> usize {
        self.len()
    }
}

/// Stencil storage rounded to single precision, two entries per 64-bit word (entry `i`
/// in the low half of word `i / 2` when `i` is even, the high half when odd): half the
/// storage and memory traffic of the `f64` storage the assemblers write. Made in place
/// from that storage ([`Stencil32::pack`]: no second array), so a Jacobian of eq. (12)
/// held for the Krylov iterations of a Newton step costs 392 B per unknown at degree 3
/// instead of 784; the product then multiplies with `A` rounded entrywise to `f32`
/// (relative change at most `2^-24` per entry) inside the `f64` Newton iteration, whose
/// residual `F` stays exact (BENCHMARKS.md, "Under 1 KiB per unknown").
#[derive(Debug, Clone, Default)]
pub struct Stencil32 {
    words: Vec<u64>,
    len: usize,
}

impl Stencil32 {
    /// `stencil` rounded to `f32`, in its own allocation (the words written over the
    /// entries already read, the unused half released).
    pub fn pack(stencil: Vec<f64>) -> Self {
        let len = stencil.len();
        // same size and alignment: collected in place
        let mut words: Vec<u64> = stencil.into_iter().map(f64::to_bits).collect();
        let half = len.div_ceil(2);
        let single = |w: u64| u64::from((f64::from_bits(w) as f32).to_bits());
        for j in 0..half {
            // entries 2j and 2j + 1 are read before word j (j <= 2j) is written
            let hi = if 2 * j + 1 < len { single(words[2 * j + 1]) } else { 0 };
            words[j] = single(words[2 * j]) | (hi << 32);
        }
        words.truncate(half);
        words.shrink_to_fit();
        Self { words, len }
    }

    /// The storage: entry `i` is `f32::from_bits` of the low 32 bits of word `i / 2`
    /// when `i` is even, of the high 32 bits when odd (in memory on a little-endian
    /// machine: the `f32` entries in order).
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are no entries.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl Stencil32 {
    /// An empty storage that [`Stencil32::extend`] fills up to `len` entries.
    fn with_capacity(len: usize) -> Self {
        Self { words: Vec::with_capacity(len.div_ceil(2)), len: 0 }
    }

    /// `entries` rounded to `f32` appended (in parallel; `entries` and the storage so far
    /// of even length): the words [`Stencil32::pack`] makes of them.
    fn extend(&mut self, entries: &[f64]) {
        debug_assert!(self.len.is_multiple_of(2) && entries.len().is_multiple_of(2));
        let single = |v: f64| u64::from((v as f32).to_bits());
        self.words.par_extend(entries.par_chunks(2).with_min_len(4096).map(|w| single(w[0]) | (single(w[1]) << 32)));
        self.len += entries.len();
    }
}

impl StencilValues for Stencil32 {
    #[inline]
    fn at(&self, i: usize) -> f64 {
        f64::from(f32::from_bits((self.words[i >> 1] >> ((i & 1) * 32)) as u32))
    }
    fn entries(&self) -> usize {
        self.len
    }
}

/// `sum_t terms[t]` added in the order of [`crate::linalg::sparse::Csr::mul_vec`]: four
/// partial sums over the first `4 floor(n / 4)` terms (term `t` into sum `t mod 4`),
/// combined as `(s_0 + s_1) + (s_2 + s_3)`, then the remaining terms one by one; the
/// stencil product of a row therefore has the bits of the gathered matrix's.
fn sum_as_csr(terms: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let chunks = terms.chunks_exact(4);
    let rest = chunks.remainder();
    for t in chunks {
        for (a, v) in acc.iter_mut().zip(t) {
            *a += v;
        }
    }
    let mut sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for t in rest {
        sum += t;
    }
    sum
}

impl Discretization {
    /// `y = A x` for the `ncomp`-component free-free system `A` whose stencil storage
    /// (length [`Discretization::stencil_len`]) is `stencil`: the product of the matrix
    /// [`super::pattern::SystemPattern::gather`] would build, computed from the stencil,
    /// with the same bits (the terms of a row in the matrix's column order, added as
    /// [`crate::linalg::sparse::Csr::mul_vec`] adds them). Periodic replicas are not
    /// summed: for a basis with replicas use the gathered matrix (this returns `false`
    /// and leaves `y` alone).
    pub(crate) fn stencil_product<S: StencilValues + ?Sized>(
        &self,
        ncomp: usize,
        stencil: &S,
        x: &[f64],
        y: &mut [f64],
    ) -> bool {
        if !self.dofs.replicas().is_empty() {
            return false;
        }
        let m = self.dofs.num_free();
        let (p, q) = self.degrees();
        let [nx, ny] = self.shape();
        let sw = self.stencil_width();
        let row_len = ncomp * ncomp * sw;
        let (wx, wy) = (2 * p + 1, 2 * q + 1);
        let free = self.dofs.free();
        let dofs = &self.dofs;
        // the free neighbours of free function `f` in the gathered matrix's column order
        // (by `dj`, then `di`): `(slot, free index)`, the same for every component pair
        let columns = |f: usize, cols: &mut Vec<(usize, usize)>| {
            let k = free[f];
            let (i, j) = (k % nx, k / nx);
            cols.clear();
            for dj in j.saturating_sub(q)..(j + q + 1).min(ny) {
                for di in i.saturating_sub(p)..(i + p + 1).min(nx) {
                    let fc = dofs.free_index(dj * nx + di);
                    if fc != FIXED {
                        cols.push(((dj + q - j) * wx + (di + p - i), fc));
                    }
                }
            }
        };
        // the products of row `z m + f` in the gathered matrix's column order
        // (component, then the neighbours), summed as the matrix does
        let row = |z: usize, f: usize, cols: &[(usize, usize)], terms: &mut Vec<f64>| -> f64 {
            let base = free[f] * row_len + z * ncomp * sw;
            terms.clear();
            for d in 0..ncomp {
                let (st, xd) = (base + d * sw, &x[d * m..][..m]);
                terms.extend(cols.iter().map(|&(s, fc)| stencil.at(st + s) * xd[fc]));
            }
            sum_as_csr(terms)
        };
        debug_assert!(wy * wx == sw && y.len() == ncomp * m && x.len() == ncomp * m);
        // each task: the rows of functions `c R .. (c + 1) R` of every component
        let mut tasks: Vec<Vec<&mut [f64]>> = (0..m.div_ceil(ROWS_PER_TASK)).map(|_| Vec::new()).collect();
        for part in y.chunks_mut(m.max(1)) {
            for (task, ys) in tasks.iter_mut().zip(part.chunks_mut(ROWS_PER_TASK)) {
                task.push(ys);
            }
        }
        tasks.into_par_iter().enumerate().for_each(|(c, mut parts)| {
            let (mut cols, mut terms) = (Vec::with_capacity(sw), Vec::with_capacity(ncomp * sw));
            for o in 0..parts.first().map_or(0, |ys| ys.len()) {
                let f = c * ROWS_PER_TASK + o;
                columns(f, &mut cols);
                for (z, ys) in parts.iter_mut().enumerate() {
                    ys[o] = row(z, f, &cols, &mut terms);
                }
            }
        });
        true
    }
}

/// Element rows per band of [`Discretization::egg_single`] (times `q + 1`): the band's
/// `q` element rows below it are assembled again (`q / (16 (q + 1))` of the work, 5 %
/// at degree 3) for the band's `f64` storage of about `16 (q + 1) + 2 q` function rows.
const BAND_ROWS: usize = 16;

impl Discretization {
    /// The EGG residual (eq. 8, into the full `res`) and the Jacobian (eq. 12) in stencil
    /// storage rounded to single precision, assembled by bands of element rows: each
    /// band's function rows in `f64`, those whose elements are all in the band then
    /// rounded into the [`Stencil32`] (the band carries the `q` element rows below it, so
    /// every entry gets its contributions in the whole assembly's order). The same bits
    /// as [`Discretization::egg`] followed by [`Stencil32::pack`], with the `f64`
    /// storage of one band at a time instead of the whole Jacobian's (784 B per unknown
    /// at degree 3, the peak of a Newton step at 10^6 unknowns).
    pub(crate) fn egg_single(&self, cps: &[[f64; 2]], op: Operator, res: &mut [f64]) -> Stencil32 {
        let (_, q) = self.degrees();
        let [nx, ny] = self.shape();
        let row_len = 4 * self.stencil_width();
        let first = &self.tables[1].first;
        let ney = self.tables[1].num_elements();
        let kernel = self.egg_kernel(cps, op, true);
        let mut out = Stencil32::with_capacity(self.stencil_len(2));
        let (mut band_res, mut band_st) = (Vec::new(), Vec::new());
        for e0 in (0..ney).step_by(BAND_ROWS * (q + 1)) {
            let e1 = (e0 + BAND_ROWS * (q + 1)).min(ney);
            // the function rows this band completes, and the element rows they have
            let (out0, out1) = (if e0 == 0 { 0 } else { first[e0] }, if e1 == ney { ny } else { first[e1] });
            let eb = first[..e0].partition_point(|&f| f + q < out0);
            let row0 = first[eb];
            let rows = first[e1 - 1] + q + 1 - row0;
            band_res.resize(rows * nx * 2, 0.0);
            band_st.resize(rows * nx * row_len, 0.0);
            self.assemble_band(2, eb..e1, &mut band_res, &mut band_st, &kernel);
            res[out0 * nx * 2..out1 * nx * 2]
                .copy_from_slice(&band_res[(out0 - row0) * nx * 2..(out1 - row0) * nx * 2]);
            out.extend(&band_st[(out0 - row0) * nx * row_len..(out1 - row0) * nx * row_len]);
        }
        debug_assert_eq!(out.len, self.stencil_len(2));
        out
    }
}

impl Discretization {
    /// The scalar system whose stencil storage is `stencil` (length
    /// [`Discretization::stencil_len`]`(1)`) as a grid stencil of its free functions
    /// ([`GridStencil`]: the free rows, the couplings to fixed functions zero), made in
    /// place in that storage: the entries of
    /// [`Discretization::stencil_diagonal_block`]'s matrix without the matrix. Only when
    /// the free functions are a rectangle of the basis grid (a patch whose boundary
    /// functions are fixed) without periodic replicas; `Err` gives the storage back
    /// otherwise.
    pub(crate) fn free_grid_stencil(&self, mut stencil: Vec<f64>) -> std::result::Result<GridStencil, Vec<f64>> {
        let (p, q) = self.degrees();
        let ([nx, _], sw, free) = (self.shape(), self.stencil_width(), self.dofs.free());
        let (Some(&k0), Some(&k1)) = (free.first(), free.last()) else { return Err(stencil) };
        let (i0, j0, i1, j1) = (k0 % nx, k0 / nx, k1 % nx + 1, k1 / nx + 1);
        let rectangle = i1 > i0
            && (i1 - i0) * (j1 - j0) == free.len()
            && free.iter().all(|&k| (i0..i1).contains(&(k % nx)) && (j0..j1).contains(&(k / nx)));
        if !rectangle || !self.dofs.replicas().is_empty() || stencil.len() != self.stencil_len(1) {
            return Err(stencil);
        }
        // the rows of the free functions moved down in order (row `f` from row `k >= f`)
        for (f, &k) in free.iter().enumerate() {
            stencil.copy_within(k * sw..(k + 1) * sw, f * sw);
        }
        stencil.truncate(free.len() * sw);
        stencil.shrink_to_fit();
        let (gx, gy) = (i1 - i0, j1 - j0);
        stencil.par_chunks_mut(sw).enumerate().with_min_len(ROWS_PER_TASK).for_each(|(f, row)| {
            let (fx, fy) = (f % gx, f / gx);
            for (s, v) in row.iter_mut().enumerate() {
                let (dx, dy) = ((fx + s % (2 * p + 1)).checked_sub(p), (fy + s / (2 * p + 1)).checked_sub(q));
                if dx.is_none_or(|x| x >= gx) || dy.is_none_or(|y| y >= gy) {
                    *v = 0.0;
                }
            }
        });
        Ok(GridStencil { nx: gx, ny: gy, half: [p, q], values: stencil })
    }

    /// The diagonal block `A_zz` (free-free, with the pattern of [`Discretization::scalar`])
    /// of the `ncomp`-component system whose stencil storage is `stencil`: the block the
    /// gathered matrix has in rows and columns `z m .. (z + 1) m`, entry for entry, built
    /// from the stencil storage alone (the free neighbours of each free function in slot
    /// order, the scalar pattern's columns; the pattern with its gather map is not
    /// needed). Only for a basis without periodic replicas (`None` otherwise).
    pub(crate) fn stencil_diagonal_block<S: StencilValues + ?Sized>(
        &self,
        ncomp: usize,
        stencil: &S,
        z: usize,
    ) -> Option<crate::linalg::sparse::Csr> {
        if !self.dofs.replicas().is_empty() || z >= ncomp || stencil.entries() != self.stencil_len(ncomp) {
            return None;
        }
        let (p, q) = self.degrees();
        let (sw, shape, m) = (self.stencil_width(), self.shape(), self.dofs.num_free());
        let free = self.dofs.free();
        // function `k`'s block (z, z) lies at `k ncomp² sw + (z ncomp + z) sw`; its row
        // holds the free neighbours in slot order
        let free_neighbours = |k: usize| {
            super::pattern::stencil_neighbours(shape, p, q, k)
                .map(move |(s, kk)| (s, self.dofs.free_index(kk)))
                .filter(|&(_, fc)| fc != FIXED)
        };
        // the row lengths, then each task's rows written into its part of the arrays
        let mut row_ptr = Vec::with_capacity(m + 1);
        row_ptr.push(0);
        let lengths: Vec<usize> =
            free.par_iter().with_min_len(ROWS_PER_TASK).map(|&k| free_neighbours(k).count()).collect();
        for len in lengths {
            row_ptr.push(row_ptr.last().copied().unwrap_or(0) + len);
        }
        let nnz = row_ptr[m];
        let (mut col_idx, mut values) = (vec![0; nnz], vec![0.0; nnz]);
        let mut parts = Vec::with_capacity(m.div_ceil(ROWS_PER_TASK));
        let (mut cols, mut vals) = (&mut col_idx[..], &mut values[..]);
        for first in (0..m).step_by(ROWS_PER_TASK) {
            let last = (first + ROWS_PER_TASK).min(m);
            let len = row_ptr[last] - row_ptr[first];
            let (c, rest_c) = std::mem::take(&mut cols).split_at_mut(len);
            let (v, rest_v) = std::mem::take(&mut vals).split_at_mut(len);
            (cols, vals) = (rest_c, rest_v);
            parts.push((first..last, c, v));
        }
        parts.into_par_iter().for_each(|(rows, c, v)| {
            let mut at = 0;
            for &k in &free[rows] {
                let row = k * ncomp * ncomp * sw + (z * ncomp + z) * sw;
                for (s, fc) in free_neighbours(k) {
                    c[at] = fc;
                    v[at] = stencil.at(row + s);
                    at += 1;
                }
            }
        });
        Some(crate::linalg::sparse::Csr { nrows: m, ncols: m, row_ptr, col_idx, values })
    }
}

/// The free-free system of `ncomp` components held as stencil storage (`f64`, or
/// [`Stencil32`]), as an operator for the Krylov methods ([`MatVec`]): the EGG Jacobian
/// of eq. (12) or the elasticity system without their CSR copies. Only for a basis
/// without periodic replicas ([`StencilOperator::new`] says `None` otherwise).
#[derive(Debug)]
pub(crate) struct StencilOperator<'a, S: StencilValues + ?Sized = [f64]> {
    disc: &'a Discretization,
    ncomp: usize,
    stencil: &'a S,
}

impl<'a, S: StencilValues + ?Sized> StencilOperator<'a, S> {
    /// The system of `ncomp` components whose stencil storage is `stencil` on `disc`;
    /// `None` when `disc` has periodic replicas or `stencil` has the wrong length.
    pub fn new(disc: &'a Discretization, ncomp: usize, stencil: &'a S) -> Option<Self> {
        (disc.dofs.replicas().is_empty() && stencil.entries() == disc.stencil_len(ncomp)).then_some(Self {
            disc,
            ncomp,
            stencil,
        })
    }
}

impl<S: StencilValues + ?Sized> MatVec for StencilOperator<'_, S> {
    fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        let done = self.disc.stencil_product(self.ncomp, self.stencil, x, y);
        debug_assert!(done, "checked in StencilOperator::new");
    }
}

/// The free-free system of `ncomp` components on `disc` held as its stencil storage in
/// single precision ([`Stencil32`]; the Newton Jacobian of eq. 12 that GMRES multiplies
/// with under the multigrid preconditioner): what an [`OperatorBackend`] uploads, and
/// the CPU's product with it ([`MatVec`]: `Discretization::stencil_product`, row
/// `z m + f` summed as `Csr::mul_vec` sums it), which the back end reproduces. Only for
/// a basis without periodic replicas.
#[derive(Debug, Clone, Copy)]
pub struct PackedSystem<'a> {
    disc: &'a Discretization,
    ncomp: usize,
    values: &'a Stencil32,
}

impl<'a> PackedSystem<'a> {
    /// The system of `ncomp` components with stencil storage `values` on `disc`; `None`
    /// when `disc` has periodic replicas or `values` has the wrong length
    /// ([`Discretization::stencil_len`]).
    pub fn new(disc: &'a Discretization, ncomp: usize, values: &'a Stencil32) -> Option<Self> {
        StencilOperator::new(disc, ncomp, values).map(|_| Self { disc, ncomp, values })
    }

    /// The basis: its shape, degrees (the stencil half widths) and free functions.
    pub fn discretization(&self) -> &'a Discretization {
        self.disc
    }

    /// Components `c`: entry `(k c^2 + z c + d) sw + s` couples component `z` of
    /// function `k` with component `d` of its neighbour in slot `s`
    /// (`sw = (2p + 1)(2q + 1)`, slot `dj (2p + 1) + di`).
    pub fn components(&self) -> usize {
        self.ncomp
    }

    /// The values.
    pub fn values(&self) -> &'a Stencil32 {
        self.values
    }

    /// Rows (and columns): `c m`.
    pub fn size(&self) -> usize {
        self.ncomp * self.disc.dofs.num_free()
    }
}

impl MatVec for PackedSystem<'_> {
    fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        let done = self.disc.stencil_product(self.ncomp, self.values, x, y);
        debug_assert!(done, "checked in PackedSystem::new");
    }
}

/// A back end that multiplies with a [`PackedSystem`] where its data lives (the GPU
/// crate's kernel): it uploads the system once (per Newton step) and applies it per
/// product; without one (the default) the CPU multiplies ([`MatVec`] of
/// [`PackedSystem`]).
pub trait OperatorBackend: Send + Sync + std::fmt::Debug {
    /// The system on the back end, or why it cannot go there (the caller then keeps the
    /// CPU product).
    ///
    /// Errors: the back end's, as [`crate::Error::LinearSolver`].
    fn upload(&self, system: &PackedSystem<'_>) -> Result<Box<dyn DeviceOperator>>;
}

/// A [`PackedSystem`] uploaded to a back end.
pub trait DeviceOperator: Send + Sync + std::fmt::Debug {
    /// `y = A x`, the product of [`PackedSystem`]'s [`MatVec`] (to rounding; its bits
    /// where the back end does the same operations in the same order).
    ///
    /// Errors: the back end's, as [`crate::Error::LinearSolver`] (the caller then
    /// multiplies on the CPU).
    fn apply(&self, x: &[f64], y: &mut [f64]) -> Result<()>;
}

#[cfg(test)]
mod tests {
    use crate::discrete::assembly::Operator;
    use crate::spline::knots::KnotVector;
    use crate::testutil::Lcg;

    use super::*;

    /// Control points of a curved map (a sheared annulus sector) at the Greville points of
    /// `kx`, `ky`, perturbed pseudo-randomly.
    fn curved_map(kx: &KnotVector, ky: &KnotVector, rng: &mut Lcg) -> Vec<[f64; 2]> {
        let (gx, gy) = (kx.greville(), ky.greville());
        gy.iter()
            .flat_map(|&v| gx.iter().map(move |&u| (u, v)))
            .map(|(u, v)| {
                let (r, t) = (1.0 + 2.0 * v, 1.3 * u + 0.1 * v * v);
                [r * t.cos() + 0.02 * (rng.uniform() - 0.5), r * t.sin() + 0.02 * (rng.uniform() - 0.5)]
            })
            .collect()
    }

    /// The Jacobian by row bands in single precision ([`Discretization::egg_single`]) is
    /// the whole assembly packed ([`Discretization::egg`], then [`Stencil32::pack`]) word
    /// for word, with the same residual bits, on a curved map of degrees (3, 2) with a
    /// double knot in each direction and element rows for three bands, the last shorter.
    #[test]
    fn banded_single_precision_jacobian_is_the_whole_assembly_packed() {
        let kx = KnotVector::open_uniform(3, 5).with_inserted(&[0.4]);
        let ky = KnotVector::open_uniform(2, 120).with_inserted(&[0.5]);
        let cps = curved_map(&kx, &ky, &mut Lcg::new(3));
        let disc = Discretization::new([kx, ky]);
        assert!(disc.tables[1].num_elements() > 2 * BAND_ROWS * 3);
        for op in [Operator::Plain, Operator::Scaled] {
            let (mut st, mut res) = (vec![0.0; disc.stencil_len(2)], vec![0.0; 2 * disc.dofs.num_total()]);
            disc.egg(&cps, op, &mut res, &mut st);
            let want = Stencil32::pack(st);
            let mut banded = vec![f64::NAN; res.len()];
            let got = disc.egg_single(&cps, op, &mut banded);
            assert_eq!((got.len, got.words.len()), (want.len, want.words.len()));
            let differ = got.words.iter().zip(&want.words).filter(|(a, b)| a != b).count();
            assert_eq!(differ, 0, "{op:?}: {differ} of {} words differ", want.words.len());
            assert!(res.iter().zip(&banded).all(|(a, b)| a.to_bits() == b.to_bits()), "{op:?}: residuals differ");
        }
    }

    /// `K` as a grid stencil of the free functions ([`Discretization::free_grid_stencil`])
    /// has the entries of its matrix ([`Discretization::stencil_diagonal_block`]), and the
    /// V-cycle set up from it without a matrix of the finest level
    /// (`Multigrid::factor_stencil`) is the one set up from the matrix: its output has the
    /// same bits.
    #[test]
    fn grid_stencil_is_the_matrix_and_sets_up_the_same_cycle() {
        use crate::linalg::multigrid::{Multigrid, TensorProlongation, MG_SMOOTHER, MG_SWEEPS};
        // 51 x 44 functions: two coarser spaces (the coarsest at most 400 functions)
        let kx = KnotVector::open_uniform(3, 48);
        let ky = KnotVector::open_uniform(3, 40).with_inserted(&[0.35]);
        let mut rng = Lcg::new(8);
        let cps = curved_map(&kx, &ky, &mut rng);
        let disc = Discretization::new([kx, ky]);
        let mut st = vec![0.0; disc.stencil_len(1)];
        disc.metric_laplace(&cps, Operator::Scaled, 0.0, &mut st);
        let k = disc.stencil_diagonal_block(1, &st[..], 0).expect("no replicas");
        let g = disc.free_grid_stencil(st).expect("the free functions are a rectangle");
        assert_eq!(g.to_csr(), k);
        let transfers: Vec<TensorProlongation> = crate::discrete::transfers::free_prolongation_factors(&disc)
            .expect("nested spaces")
            .into_iter()
            .map(TensorProlongation::from)
            .collect();
        assert!(transfers.len() >= 2);
        let (mut from_matrix, mut from_grid) = (
            Multigrid::new(transfers.clone(), MG_SMOOTHER, MG_SWEEPS),
            Multigrid::new(transfers, MG_SMOOTHER, MG_SWEEPS),
        );
        from_matrix.factor_owned(k).expect("SPD");
        from_grid.factor_stencil(g).expect("SPD");
        let b: Vec<f64> = (0..disc.dofs.num_free()).map(|_| rng.uniform() - 0.5).collect();
        let (mut x, mut y) = (vec![0.0; b.len()], vec![0.0; b.len()]);
        from_matrix.apply(&b, &mut x);
        from_grid.apply(&b, &mut y);
        assert!(x.iter().any(|v| *v != 0.0));
        assert!(x.iter().zip(&y).all(|(u, v)| u.to_bits() == v.to_bits()), "the cycles differ");
    }

    /// The stencil product equals the gathered EGG Jacobian (eq. 12) and metric
    /// Laplacian times a random vector bit for bit, on a curved map with unequal
    /// degrees and a double knot.
    #[test]
    fn stencil_product_equals_assembled_matrix() {
        let kx = KnotVector::open_uniform(3, 7).with_inserted(&[0.4]);
        let ky = KnotVector::open_uniform(2, 5).with_inserted(&[0.5]);
        let (gx, gy) = (kx.greville(), ky.greville());
        let mut rng = Lcg::new(5);
        let mut cps = Vec::new();
        for &v in &gy {
            for &u in &gx {
                let r = 1.0 + 2.0 * v;
                let t = 1.3 * u + 0.1 * v * v;
                cps.push([r * t.cos() + 0.02 * (rng.uniform() - 0.5), r * t.sin() + 0.02 * (rng.uniform() - 0.5)]);
            }
        }
        let disc = Discretization::new([kx, ky]);
        let m = disc.dofs.num_free();
        for (ncomp, pattern) in [(2, &*disc.vector), (1, &*disc.scalar)] {
            let mut st = vec![0.0; disc.stencil_len(ncomp)];
            if ncomp == 2 {
                let mut res = vec![0.0; 2 * disc.dofs.num_total()];
                disc.egg(&cps, Operator::Plain, &mut res, &mut st);
            } else {
                disc.metric_laplace(&cps, Operator::Plain, 0.0, &mut st);
            }
            let a = pattern.matrix(&st);
            let x: Vec<f64> = (0..ncomp * m).map(|_| rng.uniform() - 0.5).collect();
            let (mut y, mut z) = (vec![0.0; ncomp * m], vec![0.0; ncomp * m]);
            a.mul_vec(&x, &mut y);
            assert!(disc.stencil_product(ncomp, &st[..], &x, &mut z));
            let scale = y.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            assert!(scale > 0.0, "{ncomp} components: a zero product");
            // the same terms added in the same order: the same bits
            let differ = y.iter().zip(&z).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
            assert_eq!(differ, 0, "{ncomp} components: {differ} of {} entries differ", y.len());
            let op = StencilOperator::new(&disc, ncomp, &st[..]).expect("no replicas");
            MatVec::mul_vec(&op, &x, &mut z);
            assert_eq!(y, z);
        }
    }

    /// The single-precision storage: every entry is the `f64` entry rounded to `f32`
    /// (an odd length included), and the EGG Jacobian's product from it differs from the
    /// `f64` product by at most the rounding bound `2^-24 Σ_j |a_ij x_j|` per row.
    #[test]
    fn packed_product_is_the_product_rounded_to_single_precision() {
        let odd: Vec<f64> = (0..7).map(|i| 1.0 / (3.0 + i as f64) - 0.1).collect();
        let packed = Stencil32::pack(odd.clone());
        assert_eq!(packed.entries(), 7);
        for (i, v) in odd.iter().enumerate() {
            assert_eq!(packed.at(i), f64::from(*v as f32), "entry {i}");
        }
        let kx = KnotVector::open_uniform(3, 6);
        let ky = KnotVector::open_uniform(2, 5).with_inserted(&[0.5]);
        let mut rng = Lcg::new(9);
        let cps = curved_map(&kx, &ky, &mut rng);
        let disc = Discretization::new([kx, ky]);
        let m = disc.dofs.num_free();
        let mut st = vec![0.0; disc.stencil_len(2)];
        let mut res = vec![0.0; 2 * disc.dofs.num_total()];
        disc.egg(&cps, Operator::Scaled, &mut res, &mut st);
        let x: Vec<f64> = (0..2 * m).map(|_| rng.uniform() - 0.5).collect();
        let (mut y, mut z, mut bound) = (vec![0.0; 2 * m], vec![0.0; 2 * m], vec![0.0; 2 * m]);
        assert!(disc.stencil_product(2, &st[..], &x, &mut y));
        let abs: Vec<f64> = st.iter().map(|v| v.abs()).collect();
        let xabs: Vec<f64> = x.iter().map(|v| v.abs()).collect();
        assert!(disc.stencil_product(2, &abs[..], &xabs, &mut bound));
        let packed = Stencil32::pack(st);
        assert!(disc.stencil_product(2, &packed, &x, &mut z));
        let mut changed = 0;
        for i in 0..2 * m {
            // |fl32(a) - a| <= 2^-24 |a|, plus the rounding of the f64 sums
            let tol = 6.0e-8 * bound[i] + 1e-15 * bound[i];
            assert!((y[i] - z[i]).abs() <= tol, "row {i}: {} against {} (bound {tol:e})", z[i], y[i]);
            changed += usize::from(y[i] != z[i]);
        }
        assert!(changed > 0, "the product did not see the rounding");
    }
}
