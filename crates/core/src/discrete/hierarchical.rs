//! The discrete space of a THB basis ([`HierarchicalBasis`], paper §4: "a (truncated)
//! hierarchical spline basis"): per active cell the THB functions non-zero there with
//! their values and derivatives at the cell's Gauss points (element extraction), the
//! free/fixed split of the THB functions and the sparsity patterns of the free-free
//! systems.
//!
//! **Element extraction.** On an active cell `Q` of level `l` every THB function is a
//! polynomial: with the `(p + 1)(q + 1)` level-`l` B-splines `τ_a` non-zero on `Q`,
//! `Trunc β_k |_Q = Σ_a C^Q_{ak} τ_a`, where row `a` of `C^Q` is the level coefficient
//! `d^l_{τ_a}` of the unit combination of [`LevelCoefficients`] (the restriction of the
//! truncation recursion to `Q`). The values and derivatives of the THB functions at a
//! Gauss point of `Q` are then `Σ_a C^Q_{ak} (τ_a, ∂_ξ τ_a, ∂_η τ_a, ∂_ξξ τ_a, ∂_ξη τ_a,
//! ∂_ηη τ_a)`, the univariate factors read from the tables of level `l`
//! ([`DirTable`](crate::discrete::tables::DirTable)); on a one-level basis `C^Q` is the identity and the values are those of
//! the tensor assembly, bit for bit.
//!
//! **Fixed functions.** A THB function is fixed (Dirichlet) when its trace on the
//! boundary of the unit square is not zero: on a boundary cell the only level-`l`
//! B-splines non-zero on a side are those of the first (last) local row, so the trace of
//! `Trunc β_k` there is `Σ_{a on the side} C^Q_{ak} τ_a|_side`, non-zero exactly when one
//! of those `C^Q_{ak}` is (the level coefficients of a unit combination are sums of
//! non-negative terms, so no cancellation makes one vanish by rounding). The Dirichlet
//! data are the control points of the fixed functions as given (for a map refined from a
//! tensor map, the boundary's exact coefficients in the THB basis).

use std::collections::BTreeSet;

use rayon::prelude::*;

use crate::discrete::dofs::FIXED;
use crate::discrete::tables::QpTab;
use crate::linalg::sparse::Csr;
use crate::spline::basis::BasisDerivs;
use crate::spline::curve::Point;
use crate::spline::hierarchical::truncation::{LevelCoefficients, Sparse};
use crate::spline::hierarchical::{HierarchicalBasis, Index2};
use crate::spline::quadrature::GaussLegendre;

/// [`HierarchicalDiscretization`]'s offset of a pair of functions not both free.
const NOT_FREE: u32 = u32::MAX;

/// One active cell: its THB functions and their values at the Gauss points.
#[derive(Debug, Clone)]
pub(crate) struct CellQuadrature {
    /// THB functions non-zero on the cell (indices into the active functions, increasing).
    pub funcs: Vec<usize>,
    /// Quadrature weight (times the cell's area) per point, `ξ` fastest.
    pub weights: Vec<f64>,
    /// `(w, w_ξ, w_η, w_ξξ, w_ξη, w_ηη)` of function `funcs[a]` at point `k` at
    /// `k * funcs.len() + a`.
    pub values: Vec<[f64; 6]>,
}

impl CellQuadrature {
    /// Number of THB functions on the cell.
    pub fn len(&self) -> usize {
        self.funcs.len()
    }

    /// The values of every function at point `k`.
    pub fn at(&self, k: usize) -> &[[f64; 6]] {
        let n = self.funcs.len();
        &self.values[k * n..(k + 1) * n]
    }
}

/// Everything computed once per THB basis: cells with their quadrature, DOF map and the
/// patterns of the scalar (`m x m`) and vector (`2m x 2m`, unknowns `c = (c^x, c^y)`)
/// free-free systems.
#[derive(Debug, Clone)]
pub(crate) struct HierarchicalDiscretization {
    /// Gauss points per cell and direction.
    pub nq: usize,
    /// The active cells (in [`HierarchicalBasis::active_cells`] order).
    pub cells: Vec<CellQuadrature>,
    /// `(level, cell)` of every entry of `cells`.
    keys: Vec<(usize, Index2)>,
    /// The extraction rows of every cell (see the module documentation), kept for
    /// [`Self::refined`].
    nets: Vec<Vec<Sparse>>,
    /// The active functions `(level, index)` of the basis.
    functions: Vec<(usize, Index2)>,
    /// Per cell, for every pair `(a, b)` of its functions (`a * n + b`) both free, the
    /// position of column `b` in the scalar pattern's row of `a`, relative to the row's
    /// start ([`NOT_FREE`] otherwise): the scatter of [`Self::assemble`] without searches.
    offsets: Vec<Vec<u32>>,
    /// Free index of every THB function, or [`FIXED`].
    free_of: Vec<usize>,
    /// THB functions of the free unknowns, increasing.
    free: Vec<usize>,
    /// Scalar pattern.
    pub scalar: Csr,
    /// Vector pattern: row `z m + f` holds the columns of scalar row `f`, then the same
    /// plus `m`.
    pub vector: Csr,
}

/// The univariate tables of one cell `c` of level `l`: per direction its Gauss points with
/// the level's B-splines there, as [`DirTable`](crate::discrete::tables::DirTable) tabulates the cell's element (the same
/// computation, so the same numbers), without tabulating the whole level (a deep level
/// has `2^l` times the elements of level 0, of which few are active).
fn cell_tables(basis: &HierarchicalBasis, l: usize, c: Index2, g: &GaussLegendre) -> [Vec<QpTab>; 2] {
    let (spans, bounds, kv) = (basis.cell_spans(l, c), basis.cell_bounds(l, c), basis.knots(l));
    std::array::from_fn(|d| {
        let mut b = BasisDerivs::default();
        g.on(bounds[d][0], bounds[d][1])
            .map(|(u, w)| {
                b.eval_in_span(&kv[d], spans[d], u, 2);
                QpTab { w, u, n: b.d }
            })
            .collect()
    })
}

/// Gauss points per direction of a THB discretization: `max(p, q) + 1`.
fn gauss_points(basis: &HierarchicalBasis) -> usize {
    let [p, q] = basis.degrees();
    p.max(q) + 1
}

impl HierarchicalDiscretization {
    /// The discretization of `basis` with `max(p, q) + 1` Gauss points per direction (as
    /// the tensor [`Discretization::new`](crate::discrete::assembly::Discretization::new)),
    /// fixed functions those with a non-zero trace on the boundary.
    pub fn new(basis: HierarchicalBasis) -> Self {
        let nq = gauss_points(&basis);
        let g = GaussLegendre::new(nq);
        let active = basis.active_cells();
        let mut lc = LevelCoefficients::<Sparse>::new(&basis, |k| vec![(k, 1.0)]);
        let nets: Vec<Vec<Sparse>> = active.iter().map(|&(l, c)| lc.cell_net(l, c)).collect();
        drop(lc);
        let degrees = basis.degrees();
        let cells: Vec<CellQuadrature> = active
            .par_iter()
            .zip(nets.par_iter())
            .map(|(&(l, c), net)| cell_quadrature(&cell_tables(&basis, l, c, &g), net, degrees, nq))
            .collect();
        Self::assembled(&basis, nq, active, nets, cells)
    }

    /// The discretization of `basis`, a refinement of `before` (the basis of `self`):
    /// equal to [`Self::new`]`(basis)`, but the element extraction and the quadrature
    /// values are computed again only on the active cells that are new or whose
    /// extraction the refinement may change
    /// ([`HierarchicalBasis::extraction_changed`]); the other cells keep theirs, the
    /// THB functions renumbered. When `basis` is no refinement of `before`, everything
    /// is computed again.
    pub fn refined(&self, before: &HierarchicalBasis, basis: HierarchicalBasis) -> Self {
        let nq = gauss_points(&basis);
        let Some(newly) = basis.newly_refined(before) else { return Self::new(basis) };
        if nq != self.nq || before.active_functions() != self.functions.as_slice() {
            return Self::new(basis);
        }
        let renumber: Vec<Option<usize>> = self.functions.iter().map(|&(l, f)| basis.index_of(l, f)).collect();
        let old: std::collections::HashMap<(usize, Index2), usize> =
            self.keys.iter().enumerate().map(|(k, &key)| (key, k)).collect();
        let active = basis.active_cells();
        // a kept cell: its old position and its net in the new numbering
        let kept: Vec<Option<(usize, Vec<Sparse>)>> = active
            .par_iter()
            .map(|&(l, c)| {
                let &k = old.get(&(l, c))?;
                if basis.extraction_changed(&newly, l, c) {
                    return None;
                }
                let net = self.nets[k]
                    .iter()
                    .map(|row| row.iter().map(|&(f, v)| renumber[f].map(|g| (g, v))).collect::<Option<Sparse>>())
                    .collect::<Option<Vec<Sparse>>>()?;
                Some((k, net))
            })
            .collect();
        let mut lc = LevelCoefficients::<Sparse>::new(&basis, |k| vec![(k, 1.0)]);
        let (from, nets): (Vec<Option<usize>>, Vec<Vec<Sparse>>) = active
            .iter()
            .zip(kept)
            .map(|(&(l, c), kept)| match kept {
                Some((k, net)) => (Some(k), net),
                None => (None, lc.cell_net(l, c)),
            })
            .unzip();
        drop(lc);
        let g = GaussLegendre::new(nq);
        let degrees = basis.degrees();
        let cells: Vec<CellQuadrature> = active
            .par_iter()
            .zip(nets.par_iter())
            .zip(&from)
            .map(|((&(l, c), net), from)| match from {
                // the same rows, renumbered (monotone: the order of the functions is kept)
                Some(k) => {
                    let cell = &self.cells[*k];
                    let funcs = cell.funcs.iter().map(|&f| renumber[f].expect("renumbered above")).collect();
                    CellQuadrature { funcs, weights: cell.weights.clone(), values: cell.values.clone() }
                }
                None => cell_quadrature(&cell_tables(&basis, l, c, &g), net, degrees, nq),
            })
            .collect();
        Self::assembled(&basis, nq, active, nets, cells)
    }

    /// The fixed functions, the DOF map and the patterns from the cells of `basis` and
    /// their extraction rows.
    fn assembled(
        basis: &HierarchicalBasis,
        nq: usize,
        keys: Vec<(usize, Index2)>,
        nets: Vec<Vec<Sparse>>,
        cells: Vec<CellQuadrature>,
    ) -> Self {
        let [p, q] = basis.degrees();
        let mut on_boundary = vec![false; basis.len()];
        for (&(l, c), net) in keys.iter().zip(&nets) {
            let shape = basis.cell_shape(l);
            for (a, row) in net.iter().enumerate() {
                let (ia, ja) = (a % (p + 1), a / (p + 1));
                let side = (c[0] == 0 && ia == 0)
                    || (c[0] + 1 == shape[0] && ia == p)
                    || (c[1] == 0 && ja == 0)
                    || (c[1] + 1 == shape[1] && ja == q);
                if side {
                    for &(k, v) in row {
                        if v != 0.0 {
                            on_boundary[k] = true;
                        }
                    }
                }
            }
        }
        let mut free_of = vec![FIXED; basis.len()];
        let mut free = Vec::new();
        for (k, &b) in on_boundary.iter().enumerate() {
            if !b {
                free_of[k] = free.len();
                free.push(k);
            }
        }
        let m = free.len();
        let mut rows: Vec<Vec<usize>> = vec![Vec::new(); m];
        for cell in &cells {
            let fs: Vec<usize> = cell.funcs.iter().map(|&k| free_of[k]).filter(|&f| f != FIXED).collect();
            for &a in &fs {
                rows[a].extend_from_slice(&fs);
            }
        }
        rows.par_iter_mut().for_each(|r| {
            r.sort_unstable();
            r.dedup();
        });
        let scalar = Csr::from_rows(m, rows.iter().map(|r| r.iter().map(|&c| (c, 0.0)).collect()).collect());
        let vrows: Vec<Vec<(usize, f64)>> = (0..2)
            .flat_map(|_| rows.iter())
            .map(|r| r.iter().map(|&c| (c, 0.0)).chain(r.iter().map(|&c| (m + c, 0.0))).collect())
            .collect();
        let vector = Csr::from_rows(2 * m, vrows);
        let offsets = cells
            .par_iter()
            .map(|cell| {
                let fr: Vec<usize> = cell.funcs.iter().map(|&k| free_of[k]).collect();
                let mut out = vec![NOT_FREE; fr.len() * fr.len()];
                for (a, &fa) in fr.iter().enumerate().filter(|e| *e.1 != FIXED) {
                    let cols = &scalar.col_idx[scalar.row_ptr[fa]..scalar.row_ptr[fa + 1]];
                    for (b, &fb) in fr.iter().enumerate().filter(|e| *e.1 != FIXED) {
                        let off = cols.binary_search(&fb).expect("the pattern holds every coupling of a cell");
                        out[a * fr.len() + b] = u32::try_from(off).expect("a row of a cell pattern is short");
                    }
                }
                out
            })
            .collect();
        let functions = basis.active_functions().to_vec();
        Self { nq, cells, keys, nets, functions, offsets, free_of, free, scalar, vector }
    }

    /// Number of THB functions.
    pub fn num_total(&self) -> usize {
        self.free_of.len()
    }

    /// Number of free functions `m` (unknowns `2 m`).
    pub fn num_free(&self) -> usize {
        self.free.len()
    }

    /// THB functions of the free unknowns.
    #[cfg(test)]
    pub fn free(&self) -> &[usize] {
        &self.free
    }

    /// The unknowns `c = (c^x, c^y)` of control points `cps`.
    pub fn gather(&self, cps: &[Point]) -> Vec<f64> {
        let m = self.num_free();
        let mut c = vec![0.0; 2 * m];
        for (f, &k) in self.free.iter().enumerate() {
            c[f] = cps[k][0];
            c[m + f] = cps[k][1];
        }
        c
    }

    /// Write the unknowns `c` into the free control points.
    pub fn scatter(&self, c: &[f64], cps: &mut [Point]) {
        let m = self.num_free();
        for (f, &k) in self.free.iter().enumerate() {
            cps[k] = [c[f], c[m + f]];
        }
    }

    /// Run `kernel(cell, re, ke)` on every cell (in parallel) and add the element vectors
    /// `re` (`ncomp` blocks of `cell.len()`, component-major) into the full
    /// component-interleaved `res` (length `ncomp n`, may be empty) and the element
    /// matrices `ke` (`ncomp²` blocks `(z, d)` of `cell.len()²`, row-major) into the free
    /// rows and columns of `matrix` (the values of [`Self::scalar`] for `ncomp = 1`, of
    /// [`Self::vector`] for `ncomp = 2`; may be empty). The kernel gets zeroed storage; the
    /// sums run in cell order (deterministic).
    pub(crate) fn assemble<K>(&self, ncomp: usize, res: &mut [f64], matrix: &mut [f64], kernel: K)
    where
        K: Fn(&CellQuadrature, &mut [f64], &mut [f64]) + Sync,
    {
        let want_res = !res.is_empty();
        let want_mat = !matrix.is_empty();
        res.fill(0.0);
        matrix.fill(0.0);
        let pattern = if ncomp == 1 { &self.scalar } else { &self.vector };
        let srow = &self.scalar;
        let m = self.num_free();
        const CHUNK: usize = 256;
        for (chunk, offsets) in self.cells.chunks(CHUNK).zip(self.offsets.chunks(CHUNK)) {
            let local: Vec<(Vec<f64>, Vec<f64>)> = chunk
                .par_iter()
                .map(|cell| {
                    let n = cell.len();
                    let mut re = vec![0.0; ncomp * n];
                    let mut ke = if want_mat { vec![0.0; ncomp * ncomp * n * n] } else { Vec::new() };
                    kernel(cell, &mut re, &mut ke);
                    (re, ke)
                })
                .collect();
            for ((cell, (re, ke)), off) in chunk.iter().zip(local).zip(offsets) {
                let n = cell.len();
                if want_res {
                    for (a, &k) in cell.funcs.iter().enumerate() {
                        for z in 0..ncomp {
                            res[k * ncomp + z] += re[z * n + a];
                        }
                    }
                }
                if !want_mat {
                    continue;
                }
                for (a, &k) in cell.funcs.iter().enumerate() {
                    let fa = self.free_of[k];
                    if fa == FIXED {
                        continue;
                    }
                    let (r0, r1) = (srow.row_ptr[fa], srow.row_ptr[fa + 1]);
                    for (b, &o) in off[a * n..(a + 1) * n].iter().enumerate() {
                        if o == NOT_FREE {
                            continue;
                        }
                        let off = o as usize;
                        for z in 0..ncomp {
                            let row = z * m + fa;
                            for d in 0..ncomp {
                                let pos = pattern.row_ptr[row] + d * (r1 - r0) + off;
                                matrix[pos] += ke[((z * ncomp + d) * n + a) * n + b];
                            }
                        }
                    }
                }
            }
        }
    }

    /// Restrict a full component-interleaved vector (length `ncomp n`) to the free
    /// unknowns `(z m + f)`.
    pub(crate) fn restrict(&self, full: &[f64], ncomp: usize) -> Vec<f64> {
        let m = self.num_free();
        let mut out = vec![0.0; ncomp * m];
        for (f, &k) in self.free.iter().enumerate() {
            for z in 0..ncomp {
                out[z * m + f] = full[k * ncomp + z];
            }
        }
        out
    }
}

/// Values and derivatives of the THB functions of one active cell at its Gauss points,
/// from the cell's extraction rows `net` (see the module documentation).
fn cell_quadrature(tables: &[Vec<QpTab>; 2], net: &[Sparse], [p, q]: [usize; 2], nq: usize) -> CellQuadrature {
    let funcs: Vec<usize> = net.iter().flatten().map(|e| e.0).collect::<BTreeSet<_>>().into_iter().collect();
    let n = funcs.len();
    // extraction rows in local function indices
    let rows: Vec<Vec<(usize, f64)>> = net
        .iter()
        .map(|row| row.iter().map(|&(k, v)| (funcs.binary_search(&k).expect("listed above"), v)).collect())
        .collect();
    let mut weights = Vec::with_capacity(nq * nq);
    let mut values = vec![[0.0; 6]; nq * nq * n];
    for kv in 0..nq {
        for ku in 0..nq {
            let k = kv * nq + ku;
            let (tu, tv) = (&tables[0][ku], &tables[1][kv]);
            weights.push(tu.w * tv.w);
            let out = &mut values[k * n..(k + 1) * n];
            for jb in 0..=q {
                for ib in 0..=p {
                    let (u0, u1, u2) = (tu.n[0][ib], tu.n[1][ib], tu.n[2][ib]);
                    let (v0, v1, v2) = (tv.n[0][jb], tv.n[1][jb], tv.n[2][jb]);
                    let b = [u0 * v0, u1 * v0, u0 * v1, u2 * v0, u1 * v1, u0 * v2];
                    for &(a, c) in &rows[jb * (p + 1) + ib] {
                        for (o, x) in out[a].iter_mut().zip(b) {
                            *o += c * x;
                        }
                    }
                }
            }
        }
    }
    CellQuadrature { funcs, weights, values }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    fn basis(p: usize, n: usize) -> HierarchicalBasis {
        let kv = KnotVector::open_uniform(p, n);
        HierarchicalBasis::new([kv.clone(), kv]).unwrap()
    }

    /// Refined round by round (cells of several levels, admissibility pulling coarser
    /// cells along, degrees 2 and 3, classes 2 and 3), the discretization updated by
    /// [`HierarchicalDiscretization::refined`] equals the one made from scratch bit for bit
    /// (cells, their functions, weights and values, free functions, patterns), while it
    /// kept the extraction of some cells from the round before.
    #[test]
    fn the_refined_discretization_equals_a_new_one() {
        for (p, m) in [(3, 2), (2, 2), (3, 3)] {
            let mut b = basis(p, 7);
            let mut disc = HierarchicalDiscretization::new(b.clone());
            let mut seed = 12345u64;
            let mut kept_total = 0;
            for round in 0..6 {
                let active = b.active_cells();
                // a few cells, the finest more often (where a repair refines)
                let finest = active.iter().map(|c| c.0).max().unwrap();
                let mut marked = Vec::new();
                for _ in 0..3 {
                    seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    let pick = (seed >> 33) as usize;
                    let pool: Vec<_> = active.iter().filter(|c| round % 3 == 0 || c.0 == finest).collect();
                    let c = *pool[pick % pool.len()];
                    if !marked.contains(&c) {
                        marked.push(c);
                    }
                }
                let before = b.clone();
                b.refine(&marked, m).unwrap();
                let newly = b.newly_refined(&before).unwrap();
                let old: BTreeSet<_> = before.active_cells().into_iter().collect();
                let kept = b
                    .active_cells()
                    .into_iter()
                    .filter(|&(l, c)| old.contains(&(l, c)) && !b.extraction_changed(&newly, l, c))
                    .count();
                kept_total += kept;
                let updated = disc.refined(&before, b.clone());
                let fresh = HierarchicalDiscretization::new(b.clone());
                assert_eq!(updated.cells.len(), fresh.cells.len());
                for (k, (u, f)) in updated.cells.iter().zip(&fresh.cells).enumerate() {
                    assert_eq!(u.funcs, f.funcs, "p {p} round {round} cell {k}");
                    assert_eq!(u.weights, f.weights, "p {p} round {round} cell {k}");
                    assert_eq!(u.values, f.values, "p {p} round {round} cell {k}");
                }
                assert_eq!(updated.keys, fresh.keys);
                assert_eq!(updated.nets, fresh.nets);
                assert_eq!((&updated.free_of, &updated.free), (&fresh.free_of, &fresh.free));
                for (a, c) in [(&updated.scalar, &fresh.scalar), (&updated.vector, &fresh.vector)] {
                    assert_eq!((&a.row_ptr, &a.col_idx, a.nrows), (&c.row_ptr, &c.col_idx, c.nrows));
                }
                disc = updated;
            }
            assert!(kept_total > 0, "p {p}: no cell kept its extraction");
        }
        // not a refinement: made from scratch
        let b = basis(3, 7);
        let mut r = b.clone();
        r.refine(&[(0, [3, 3])], 2).unwrap();
        let d = HierarchicalDiscretization::new(r.clone()).refined(&r, b.clone());
        assert_eq!(d.cells.len(), b.active_cells().len());
        assert_eq!(d.free, HierarchicalDiscretization::new(b).free);
    }

    /// On every cell the extracted THB functions sum to one with zero derivatives
    /// (partition of unity), and the values agree with [`HierarchicalBasis::eval_basis`]
    /// at the Gauss points; the quadrature weights sum to the area of the square.
    #[test]
    fn extraction_matches_evaluation() {
        let mut b = basis(3, 4);
        b.refine(&[(0, [1, 1]), (0, [2, 1])], 2).unwrap();
        b.refine(&[(1, [3, 3])], 2).unwrap();
        let disc = HierarchicalDiscretization::new(b.clone());
        let area: f64 = disc.cells.iter().flat_map(|c| c.weights.iter()).sum();
        assert!((area - 1.0).abs() < 1e-13, "{area}");
        let g = crate::spline::quadrature::GaussLegendre::new(disc.nq);
        for (cell, &(level, index)) in disc.cells.iter().zip(&b.active_cells()) {
            let [[a, bb], [c, d]] = b.cell_bounds(level, index);
            let pts_u: Vec<f64> = g.on(a, bb).map(|x| x.0).collect();
            let pts_v: Vec<f64> = g.on(c, d).map(|x| x.0).collect();
            for (kv, &v) in pts_v.iter().enumerate() {
                for (ku, &u) in pts_u.iter().enumerate() {
                    let vals = cell.at(kv * disc.nq + ku);
                    let sum: [f64; 6] = std::array::from_fn(|i| vals.iter().map(|x| x[i]).sum());
                    assert!((sum[0] - 1.0).abs() < 1e-13 && sum[1..].iter().all(|s| s.abs() < 1e-10), "{sum:?}");
                    let direct = b.eval_basis(u, v);
                    for (k, dv) in direct {
                        let a = cell.funcs.binary_search(&k).expect("same support");
                        for i in 0..3 {
                            assert!((vals[a][i] - dv[i]).abs() < 1e-12, "{k} {i} {} {}", vals[a][i], dv[i]);
                        }
                    }
                }
            }
        }
        // fixed exactly when the function's trace on the boundary is not zero
        let mut trace = vec![0.0f64; b.len()];
        for i in 0..=400 {
            let t = i as f64 / 400.0;
            for (u, v) in [(t, 0.0), (t, 1.0), (0.0, t), (1.0, t)] {
                for (k, val) in b.eval_basis(u, v) {
                    trace[k] = trace[k].max(val[0].abs());
                }
            }
        }
        assert!(disc.num_free() > 0 && disc.num_free() < b.len());
        for (k, &t) in trace.iter().enumerate() {
            assert_eq!(disc.free_of[k] == FIXED, t > 1e-12, "function {k}: trace {t}");
        }
    }
}
