//! The trivariate discretization shared by the volume methods (the 3D Winslow
//! functional, [`super::winslow`], and EGG in Galerkin form, [`super::egg`]): univariate
//! quadrature tables per direction and element, the map from control points to free
//! unknowns (the interior control points; the boundary ones are the Dirichlet data),
//! the sparsity pattern of the element-coupling matrix, and the addition of element
//! vectors and matrices into it.
//!
//! Unknowns are interleaved, `3 f + component` for the free control point `f`; the
//! pattern's row `3 f + i` holds the columns `3 g + j` of every free `g` sharing an
//! element with `f` (`j = 0, 1, 2`), so the Winslow Hessian and the (unsymmetric) EGG
//! Jacobian share it.

use std::sync::Mutex;

use rayon::prelude::*;

use crate::linalg::sparse::Csr;
use crate::spline::basis::BasisDerivs;
use crate::spline::knots::KnotVector;
use crate::spline::quadrature::GaussLegendre;
use crate::spline::volume::{Point3, Volume};

/// The univariate tables of one element in one direction: the basis functions and
/// their first and second derivatives at the element's Gauss points, with the Gauss
/// weights.
pub(super) type Tables = Vec<(BasisDerivs, f64)>;

/// What one element adds: a scalar, a vector over its `m` basis functions (`3 a + i`),
/// a matrix whose entry for row `(a, i_a)` and column `(b, i_b)` is at
/// `b 9m + (3 i_b + i_a) m + a`, and a scalar matrix (one entry per pair of basis
/// functions, `(a, b)` at `b m + a`) (the matrices empty when not asked for).
pub(super) struct Local {
    pub(super) idx: Vec<usize>,
    pub(super) scalar: f64,
    pub(super) vector: Vec<f64>,
    pub(super) matrix: Vec<f64>,
    pub(super) scalar_matrix: Vec<f64>,
}

/// What [`VolumeDiscretization::assemble`] returns: the scalars added, the vector over
/// the free unknowns, the matrix on the pattern and the scalar matrix on the scalar
/// pattern (each matrix `None` when not asked for).
pub(super) type Assembled = (f64, Vec<f64>, Option<Csr>, Option<Csr>);

/// Basis, quadrature, free unknowns and pattern of volumes on one basis with the
/// weights fixed, the boundary control points fixed and the interior ones free.
///
/// Quadrature is stored as univariate tables per direction and element (the tensor
/// products are formed per element when it is evaluated, so memory grows with the
/// number of knot spans, not with elements x points x functions); the sparsity pattern
/// is held once, as the column indices of a matrix on it that its user hands back
/// ([`VolumeDiscretization::recycle`]) and the next assembly overwrites, so no
/// evaluation copies the pattern (the column indices are made again from the
/// neighbours only when no matrix was handed back).
#[derive(Debug)]
pub struct VolumeDiscretization {
    shape: [usize; 3],
    /// `tables[d][e]`: the tables of element `e` in direction `d`.
    tables: [Vec<Tables>; 3],
    /// Weights of the rational basis.
    pub(super) weights: Option<Vec<f64>>,
    /// Free index of each control point (`usize::MAX` for fixed ones).
    free_of: Vec<usize>,
    /// Number of free control points.
    free: usize,
    /// Row pointers of the pattern (see the module doc).
    row_ptr: Vec<usize>,
    /// A matrix on the pattern handed back by its user, to be overwritten by the next
    /// assembly.
    spare: Mutex<Option<Csr>>,
    /// The scalar pattern: row `f` holds the free control points sharing an element
    /// with `f` (values zero).
    scalar_pattern: Csr,
    /// Per free control point, the sorted free control points sharing an element with it.
    neighbours: Vec<Vec<usize>>,
}

impl VolumeDiscretization {
    /// The discretization on the basis of `vol` (its knots and weights), with `g` Gauss
    /// points per direction and element.
    pub fn new(vol: &Volume, g: usize) -> Self {
        let shape = vol.shape();
        let rule = GaussLegendre::new(g);
        let tables: [Vec<Tables>; 3] = std::array::from_fn(|d| {
            let kv: &KnotVector = &vol.knots[d];
            kv.elements()
                .into_iter()
                .map(|(s, a, b)| {
                    rule.on(a, b)
                        .map(|(u, w)| {
                            let mut bd = BasisDerivs::default();
                            bd.eval_in_span(kv, s, u, 2);
                            (bd, w)
                        })
                        .collect()
                })
                .collect()
        });
        let mut free_of = vec![usize::MAX; shape.iter().product()];
        let mut free = 0;
        for k in 1..shape[2] - 1 {
            for j in 1..shape[1] - 1 {
                for i in 1..shape[0] - 1 {
                    free_of[(k * shape[1] + j) * shape[0] + i] = free;
                    free += 1;
                }
            }
        }
        let mut e = Self {
            shape,
            tables,
            weights: vol.weights.clone(),
            free_of,
            free,
            row_ptr: Vec::new(),
            spare: Mutex::new(None),
            scalar_pattern: Csr::default(),
            neighbours: Vec::new(),
        };
        let mut neighbours = vec![Vec::new(); free];
        for el in 0..e.elements() {
            let fs: Vec<usize> = e.element_indices(el).into_iter().filter_map(|lin| e.free_index(lin)).collect();
            for &f in &fs {
                neighbours[f].extend_from_slice(&fs);
            }
        }
        neighbours.par_iter_mut().for_each(|r| {
            r.sort_unstable();
            r.dedup();
        });
        let mut row_ptr = Vec::with_capacity(3 * free + 1);
        row_ptr.push(0);
        for r in &neighbours {
            for _ in 0..3 {
                row_ptr.push(row_ptr[row_ptr.len() - 1] + 3 * r.len());
            }
        }
        e.row_ptr = row_ptr;
        let mut row_ptr = Vec::with_capacity(free + 1);
        row_ptr.push(0);
        for r in &neighbours {
            row_ptr.push(row_ptr[row_ptr.len() - 1] + r.len());
        }
        let col_idx: Vec<usize> = neighbours.concat();
        let nnz = col_idx.len();
        e.scalar_pattern = Csr { nrows: free, ncols: free, row_ptr, col_idx, values: vec![0.0; nnz] };
        e.neighbours = neighbours;
        e
    }

    /// A matrix on the pattern with every value zero: the one handed back, or a new one.
    fn pattern_matrix(&self) -> Csr {
        let spare = self.spare.lock().map(|mut s| s.take()).unwrap_or(None);
        if let Some(mut m) = spare {
            m.values.fill(0.0);
            return m;
        }
        let nnz = self.row_ptr[self.row_ptr.len() - 1];
        let mut col_idx = Vec::with_capacity(nnz);
        for r in &self.neighbours {
            for _ in 0..3 {
                for &g in r {
                    col_idx.extend([3 * g, 3 * g + 1, 3 * g + 2]);
                }
            }
        }
        let n = 3 * self.free;
        Csr { nrows: n, ncols: n, row_ptr: self.row_ptr.clone(), col_idx, values: vec![0.0; nnz] }
    }

    /// Hand back a matrix of [`VolumeDiscretization::assemble`] that is no longer
    /// needed: the next assembly of a matrix writes into it instead of making a new one.
    pub(super) fn recycle(&self, m: Csr) {
        if m.nrows == 3 * self.free && m.row_ptr == self.row_ptr {
            if let Ok(mut s) = self.spare.lock() {
                *s = Some(m);
            }
        }
    }

    /// Number of elements (knot spans per direction multiplied).
    pub(super) fn elements(&self) -> usize {
        self.tables.iter().map(Vec::len).product()
    }

    /// The element's tables per direction (element `e = (k n₁ + j) n₀ + i`).
    pub(super) fn element_tables(&self, e: usize) -> [&Tables; 3] {
        let (n0, n1) = (self.tables[0].len(), self.tables[1].len());
        [&self.tables[0][e % n0], &self.tables[1][(e / n0) % n1], &self.tables[2][e / (n0 * n1)]]
    }

    /// Global indices of the element's basis functions (`a` fastest).
    pub(super) fn element_indices(&self, e: usize) -> Vec<usize> {
        let [bx, by, bz] = self.element_tables(e);
        let (f, p) =
            ([bx[0].0.first(), by[0].0.first(), bz[0].0.first()], [bx[0].0.degree, by[0].0.degree, bz[0].0.degree]);
        let shape = self.shape;
        let mut idx = Vec::with_capacity((p[0] + 1) * (p[1] + 1) * (p[2] + 1));
        for c in 0..=p[2] {
            for b in 0..=p[1] {
                for a in 0..=p[0] {
                    idx.push(((f[2] + c) * shape[1] + f[1] + b) * shape[0] + f[0] + a);
                }
            }
        }
        idx
    }

    /// A nested-dissection order of the free control points
    /// ([`crate::linalg::ordering::nested_dissection`] of their grid, `shape - 2` points
    /// per direction, which couple up to `p_d` apart in direction `d`): separators of
    /// `p_d` layers of the grid, exact on this structured grid. The fill-reducing order
    /// of the sparse Cholesky factorization of a scalar matrix on the free control
    /// points (the EGG preconditioner `K`).
    pub(super) fn ordering(&self) -> Vec<usize> {
        let s = self.shape.map(|k| k.saturating_sub(2).max(1));
        let p: [usize; 3] =
            std::array::from_fn(|d| self.tables[d].first().and_then(|t| t.first()).map_or(1, |t| t.0.degree));
        let nodes: Vec<[usize; 3]> = (0..self.free).map(|f| [f % s[0], (f / s[0]) % s[1], f / (s[0] * s[1])]).collect();
        crate::linalg::ordering::nested_dissection(&nodes, p)
    }

    /// Number of free scalar unknowns (3 per interior control point).
    pub fn unknowns(&self) -> usize {
        3 * self.free
    }

    /// Free index of control point `lin`, if it is free.
    pub fn free_index(&self, lin: usize) -> Option<usize> {
        let f = self.free_of[lin];
        (f != usize::MAX).then_some(f)
    }

    /// The free coordinates of `cps` (`3 f + component`).
    pub fn gather(&self, cps: &[Point3]) -> Vec<f64> {
        let mut x = vec![0.0; self.unknowns()];
        for (lin, p) in cps.iter().enumerate() {
            if let Some(f) = self.free_index(lin) {
                x[3 * f..3 * f + 3].copy_from_slice(p);
            }
        }
        x
    }

    /// `cps` with the free coordinates set to `x`.
    pub fn scatter(&self, cps: &mut [Point3], x: &[f64]) {
        for (lin, p) in cps.iter_mut().enumerate() {
            if let Some(f) = self.free_index(lin) {
                p.copy_from_slice(&x[3 * f..3 * f + 3]);
            }
        }
    }

    /// The sum of the elements' [`Local`]s made by `element` (`None` when one of them
    /// is `None`): the scalars added, the vectors into the free unknowns, the matrices
    /// (when `matrix`) into the values of the pattern, the scalar matrices (when
    /// `scalar_matrix`) into those of the scalar pattern. Elements are evaluated in
    /// parallel in batches and added in element order (the same sums as a sequential
    /// loop), a batch while the next one is evaluated.
    pub(super) fn assemble<F>(&self, matrix: bool, scalar_matrix: bool, element: F) -> Option<Assembled>
    where
        F: Fn(usize) -> Option<Local> + Sync,
    {
        let n = self.unknowns();
        let ne = self.elements();
        let mut scalar = 0.0;
        let mut vector = vec![0.0; n];
        let mut out = matrix.then(|| self.pattern_matrix());
        let mut values = out.as_mut().map_or(Vec::new(), |m| std::mem::take(&mut m.values));
        let mut scalar_values = if scalar_matrix { vec![0.0; self.scalar_pattern.nnz()] } else { Vec::new() };
        let batch = 32 * rayon::current_num_threads().max(1);
        // the elements of a batch added on this thread while the next batch is evaluated
        let mut add = |locals: Vec<Local>| {
            for l in locals {
                scalar += l.scalar;
                let m = l.idx.len();
                for a in 0..m {
                    let Some(fa) = self.free_index(l.idx[a]) else { continue };
                    for ia in 0..3 {
                        vector[3 * fa + ia] += l.vector[3 * a + ia];
                    }
                    if !matrix && !scalar_matrix {
                        continue;
                    }
                    let row = &self.neighbours[fa];
                    // the element's free functions come in runs of consecutive free
                    // indices (`a` fastest), which are consecutive in the row
                    let mut last: Option<(usize, usize)> = None;
                    for b in 0..m {
                        let Some(fb) = self.free_index(l.idx[b]) else { continue };
                        let at = match last {
                            Some((g, at)) if g + 1 == fb && row.get(at + 1) == Some(&fb) => at + 1,
                            _ => row.binary_search(&fb).expect("the pattern holds every pair of an element"),
                        };
                        last = Some((fb, at));
                        if scalar_matrix {
                            scalar_values[self.scalar_pattern.row_ptr[fa] + at] += l.scalar_matrix[b * m + a];
                        }
                        if !matrix {
                            continue;
                        }
                        let at = 3 * at;
                        for ia in 0..3 {
                            let p = self.row_ptr[3 * fa + ia] + at;
                            for ib in 0..3 {
                                values[p + ib] += l.matrix[b * 9 * m + (3 * ib + ia) * m + a];
                            }
                        }
                    }
                }
            }
        };
        let mut pending: Option<Vec<Local>> = None;
        let mut start = 0;
        while start < ne || pending.is_some() {
            let range = start..(start + batch).min(ne);
            let evaluate = || range.into_par_iter().map(&element).collect::<Option<Vec<Local>>>();
            let ((), locals) = rayon::join(|| pending.take().map_or((), &mut add), evaluate);
            pending = if start < ne { Some(locals?) } else { None };
            start = (start + batch).min(ne);
        }
        let matrix = out.map(|m| Csr { values, ..m });
        let scalar_matrix = scalar_matrix.then(|| Csr { values: scalar_values, ..self.scalar_pattern.clone() });
        Some((scalar, vector, matrix, scalar_matrix))
    }
}
