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

use super::assembly::Discretization;
use super::dofs::FIXED;
use crate::linalg::krylov::MatVec;

/// Functions of the stencil product per parallel task (their rows of every component).
const ROWS_PER_TASK: usize = 1024;

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
    pub(crate) fn stencil_product(&self, ncomp: usize, stencil: &[f64], x: &[f64], y: &mut [f64]) -> bool {
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
                let (st, xd) = (&stencil[base + d * sw..][..sw], &x[d * m..][..m]);
                terms.extend(cols.iter().map(|&(s, fc)| st[s] * xd[fc]));
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

impl Discretization {
    /// The diagonal block `A_zz` (free-free, in the scalar pattern [`Discretization::scalar`])
    /// of the `ncomp`-component system whose stencil storage is `stencil`: the block the
    /// gathered matrix has in rows and columns `z m .. (z + 1) m`, entry for entry. Only
    /// for a basis without periodic replicas (`None` otherwise).
    pub(crate) fn stencil_diagonal_block(
        &self,
        ncomp: usize,
        stencil: &[f64],
        z: usize,
    ) -> Option<crate::linalg::sparse::Csr> {
        if !self.dofs.replicas().is_empty() || z >= ncomp || stencil.len() != self.stencil_len(ncomp) {
            return None;
        }
        let sw = self.stencil_width();
        let mut block = self.scalar.csr.clone();
        // the scalar pattern reads function `k`'s slot `s` at `k sw + s`; the block
        // (z, z) of the system stores it at `k ncomp² sw + (z ncomp + z) sw + s`
        for (v, &src) in block.values.iter_mut().zip(&self.scalar.src) {
            let (k, s) = (src / sw, src % sw);
            *v = stencil[k * ncomp * ncomp * sw + (z * ncomp + z) * sw + s];
        }
        Some(block)
    }
}

/// The free-free system of `ncomp` components held as stencil storage, as an operator
/// for the Krylov methods ([`MatVec`]): the EGG Jacobian of eq. (12) without its CSR
/// copies. Only for a basis without periodic replicas
/// ([`StencilOperator::new`] says `None` otherwise).
#[derive(Debug, Clone, Copy)]
pub(crate) struct StencilOperator<'a> {
    disc: &'a Discretization,
    ncomp: usize,
    stencil: &'a [f64],
}

impl<'a> StencilOperator<'a> {
    /// The system of `ncomp` components whose stencil storage is `stencil` on `disc`;
    /// `None` when `disc` has periodic replicas or `stencil` has the wrong length.
    pub fn new(disc: &'a Discretization, ncomp: usize, stencil: &'a [f64]) -> Option<Self> {
        (disc.dofs.replicas().is_empty() && stencil.len() == disc.stencil_len(ncomp)).then_some(Self {
            disc,
            ncomp,
            stencil,
        })
    }
}

impl MatVec for StencilOperator<'_> {
    fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        let done = self.disc.stencil_product(self.ncomp, self.stencil, x, y);
        debug_assert!(done, "checked in StencilOperator::new");
    }
}

#[cfg(test)]
mod tests {
    use crate::discrete::assembly::Operator;
    use crate::spline::knots::KnotVector;
    use crate::testutil::Lcg;

    use super::*;

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
        for (ncomp, pattern) in [(2, &*disc.vector), (1, &disc.scalar)] {
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
            assert!(disc.stencil_product(ncomp, &st, &x, &mut z));
            let scale = y.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            assert!(scale > 0.0, "{ncomp} components: a zero product");
            // the same terms added in the same order: the same bits
            let differ = y.iter().zip(&z).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
            assert_eq!(differ, 0, "{ncomp} components: {differ} of {} entries differ", y.len());
            let op = StencilOperator::new(&disc, ncomp, &st).expect("no replicas");
            MatVec::mul_vec(&op, &x, &mut z);
            assert_eq!(y, z);
        }
    }
}
