//! The fixed sparsity pattern of a free-free Galerkin system on a tensor basis and the
//! gather map from the dense *stencil* storage the assemblers write (entry `(k, k + di +
//! n_xi dj)` of stored function `k` at slot `dj (2p + 1) + di`). With periodic replicas
//! ([`DofMap`]) a row sums the stencil rows of every stored copy of its function and an
//! entry may collect several stencil slots (`extra`).

use rayon::prelude::*;

use crate::discrete::dofs::{DofMap, FIXED};
use crate::linalg::sparse::Csr;

/// The basis functions whose supports overlap that of function `k` (tensor index
/// `(i, j)`): `(s, kk)` with the stencil slot `s = dj (2p + 1) + di` of
/// `kk = (j + dj - q) n_xi + (i + di - p)`, for all offsets inside the basis.
pub(crate) fn stencil_neighbours(
    shape: [usize; 2],
    p: usize,
    q: usize,
    k: usize,
) -> impl Iterator<Item = (usize, usize)> {
    let [nx, ny] = shape;
    let (i, j) = (k % nx, k / nx);
    (0..=2 * q).flat_map(move |dj| (0..=2 * p).map(move |di| (di, dj))).filter_map(move |(di, dj)| {
        let (ii, jj) = ((i + di).checked_sub(p)?, (j + dj).checked_sub(q)?);
        (ii < nx && jj < ny).then_some((dj * (2 * p + 1) + di, jj * nx + ii))
    })
}

/// Fixed sparsity pattern of a free-free system with `ncomp` components per basis
/// function (unknown `z * m + f`), and the gather map from stencil storage.
#[derive(Debug, Clone)]
pub struct SystemPattern {
    /// Components (1 scalar, 2 vector).
    pub ncomp: usize,
    /// Pattern (values are overwritten by [`SystemPattern::gather`]).
    pub csr: Csr,
    /// For each CSR entry, its position in the stencil storage.
    pub src: Vec<usize>,
    /// Further `(entry, stencil position)` sources added to an entry: the rows and
    /// columns of periodic replicas (empty without a periodic direction).
    pub extra: Vec<(usize, usize)>,
}

impl SystemPattern {
    pub(crate) fn new(dofs: &DofMap, p: usize, q: usize, ncomp: usize) -> Self {
        if !dofs.replicas().is_empty() {
            return Self::shared(dofs, p, q, ncomp);
        }
        let m = dofs.num_free();
        let sw = (2 * p + 1) * (2 * q + 1);
        let row_len = ncomp * ncomp * sw;
        let mut row_ptr = vec![0];
        let mut col_idx = Vec::new();
        let mut src = Vec::new();
        for z in 0..ncomp {
            for &k in dofs.free() {
                for d in 0..ncomp {
                    for (s, kk) in stencil_neighbours(dofs.shape(), p, q, k) {
                        let fc = dofs.free_index(kk);
                        if fc != FIXED {
                            col_idx.push(d * m + fc);
                            src.push(k * row_len + (z * ncomp + d) * sw + s);
                        }
                    }
                }
                row_ptr.push(col_idx.len());
            }
        }
        let nnz = col_idx.len();
        let csr = Csr { nrows: ncomp * m, ncols: ncomp * m, row_ptr, col_idx, values: vec![0.0; nnz] };
        Self { ncomp, csr, src, extra: Vec::new() }
    }

    /// The pattern with periodic replicas: row `f` sums the stencil rows of every stored
    /// function with free index `f` ([`summed_pattern`] on one basis).
    fn shared(dofs: &DofMap, p: usize, q: usize, ncomp: usize) -> Self {
        let mut stored: Vec<Vec<(usize, usize)>> = dofs.free().iter().map(|&k| vec![(0, k)]).collect();
        for &(k, _) in dofs.replicas() {
            let f = dofs.free_index(k);
            if f != FIXED {
                stored[f].push((0, k));
            }
        }
        let basis = StencilBasis { shape: dofs.shape(), degrees: [p, q], offset: 0 };
        summed_pattern(ncomp, &stored, |_| basis, |_, kk| dofs.free_index(kk))
    }

    /// Copy the stencil storage into the CSR values.
    pub fn gather(&mut self, stencil: &[f64]) {
        let mut values = std::mem::take(&mut self.csr.values);
        self.gather_into(stencil, &mut values);
        self.csr.values = values;
    }

    /// Copy the stencil storage into `values` (this pattern's entries), in parallel.
    pub(crate) fn gather_into(&self, stencil: &[f64], values: &mut [f64]) {
        const CHUNK: usize = 1 << 14;
        values.par_chunks_mut(CHUNK).zip(self.src.par_chunks(CHUNK)).for_each(|(v, src)| {
            for (v, &s) in v.iter_mut().zip(src) {
                *v = stencil[s];
            }
        });
        for &(e, s) in &self.extra {
            values[e] += stencil[s];
        }
    }

    /// A fresh matrix with the values gathered from `stencil`.
    pub fn matrix(&self, stencil: &[f64]) -> Csr {
        let mut m = self.csr.clone();
        for (v, &s) in m.values.iter_mut().zip(&self.src) {
            *v = stencil[s];
        }
        for &(e, s) in &self.extra {
            m.values[e] += stencil[s];
        }
        m
    }
}

/// A [`SystemPattern`] built on first use: `Deref` builds it from the DOF map and the
/// degrees it keeps. The vector pattern of a basis ([`super::assembly::Discretization`]'s
/// `vector`) is the largest array of a discretization (three words per nonzero of the
/// two-component system) and a solve that multiplies with the stencil storage
/// (`discrete::stencil::StencilOperator`) never needs it.
#[derive(Debug, Clone)]
pub struct LazyPattern {
    dofs: DofMap,
    degrees: [usize; 2],
    ncomp: usize,
    cell: std::sync::OnceLock<SystemPattern>,
}

impl LazyPattern {
    /// The pattern of `ncomp` components for `dofs` on a basis of degrees `(p, q)`, not
    /// built yet.
    pub(crate) fn new(dofs: &DofMap, p: usize, q: usize, ncomp: usize) -> Self {
        Self { dofs: dofs.clone(), degrees: [p, q], ncomp, cell: std::sync::OnceLock::new() }
    }

    #[cfg(test)]
    /// Whether the pattern has been built.
    pub(crate) fn is_built(&self) -> bool {
        self.cell.get().is_some()
    }

    fn build(&self) -> SystemPattern {
        SystemPattern::new(&self.dofs, self.degrees[0], self.degrees[1], self.ncomp)
    }
}

impl std::ops::Deref for LazyPattern {
    type Target = SystemPattern;
    fn deref(&self) -> &SystemPattern {
        self.cell.get_or_init(|| self.build())
    }
}

impl std::ops::DerefMut for LazyPattern {
    fn deref_mut(&mut self) -> &mut SystemPattern {
        if self.cell.get().is_none() {
            let built = self.build();
            let _ = self.cell.set(built);
        }
        self.cell.get_mut().expect("built above")
    }
}

/// Where one tensor basis's stencil storage lies in the storage a [`summed_pattern`]
/// reads: its basis shape, degrees and first position.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StencilBasis {
    /// Basis functions per direction.
    pub shape: [usize; 2],
    /// Degrees `[p, q]`.
    pub degrees: [usize; 2],
    /// Position of the basis's first stencil entry in the concatenated storage.
    pub offset: usize,
}

/// The pattern of the `ncomp`-component system whose row `z m + f` sums the stencil rows
/// of every stored copy `(b, k)` (function `k` of basis `b`) in `rows[f]`, `m =
/// rows.len()`: a periodic replica on one basis ([`SystemPattern`] with replicas), or a
/// control point shared by the patches of a layout. `free_index(b, kk)` is the free index
/// of function `kk` of basis `b` ([`FIXED`] when fixed); each column collects every
/// neighbour with the same free index (sorted columns; first source in `src`, the others
/// in `extra`), sources are positions in the bases' concatenated stencil storage.
pub(crate) fn summed_pattern(
    ncomp: usize,
    rows: &[Vec<(usize, usize)>],
    basis: impl Fn(usize) -> StencilBasis,
    free_index: impl Fn(usize, usize) -> usize,
) -> SystemPattern {
    let m = rows.len();
    let mut row_ptr = vec![0];
    let (mut col_idx, mut src, mut extra) = (Vec::new(), Vec::new(), Vec::new());
    for z in 0..ncomp {
        for copies in rows {
            let mut row: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
            for &(b, k) in copies {
                let StencilBasis { shape, degrees: [p, q], offset } = basis(b);
                let sw = (2 * p + 1) * (2 * q + 1);
                let row_len = ncomp * ncomp * sw;
                for d in 0..ncomp {
                    for (s, kk) in stencil_neighbours(shape, p, q, k) {
                        let fc = free_index(b, kk);
                        if fc != FIXED {
                            row.entry(d * m + fc).or_default().push(offset + k * row_len + (z * ncomp + d) * sw + s);
                        }
                    }
                }
            }
            for (col, sources) in row {
                extra.extend(sources[1..].iter().map(|&st| (col_idx.len(), st)));
                col_idx.push(col);
                src.push(sources[0]);
            }
            row_ptr.push(col_idx.len());
        }
    }
    let nnz = col_idx.len();
    let csr = Csr { nrows: ncomp * m, ncols: ncomp * m, row_ptr, col_idx, values: vec![0.0; nnz] };
    SystemPattern { ncomp, csr, src, extra }
}
