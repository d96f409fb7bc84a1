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

impl Discretization {
    /// `y = A x` for the `ncomp`-component free-free system `A` whose stencil storage
    /// (length [`Discretization::stencil_len`]) is `stencil`: the product of the matrix
    /// [`super::pattern::SystemPattern::gather`] would build, computed from the stencil.
    /// Periodic replicas are not summed: for a basis with replicas use the gathered
    /// matrix (this returns `false` and leaves `y` alone).
    pub fn stencil_product(&self, ncomp: usize, stencil: &[f64], x: &[f64], y: &mut [f64]) -> bool {
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
        let row = |z: usize, f: usize| -> f64 {
            let k = free[f];
            let (i, j) = (k % nx, k / nx);
            let base = k * row_len + z * ncomp * sw;
            let mut sum = 0.0;
            for dj in j.saturating_sub(q)..(j + q + 1).min(ny) {
                for di in i.saturating_sub(p)..(i + p + 1).min(nx) {
                    let fc = dofs.free_index(dj * nx + di);
                    if fc == FIXED {
                        continue;
                    }
                    let s = (dj + q - j) * wx + (di + p - i);
                    for d in 0..ncomp {
                        sum += stencil[base + d * sw + s] * x[d * m + fc];
                    }
                }
            }
            sum
        };
        debug_assert!(wy * wx == sw && y.len() == ncomp * m && x.len() == ncomp * m);
        y.par_chunks_mut(1024).enumerate().for_each(|(c, ys)| {
            for (o, yi) in ys.iter_mut().enumerate() {
                let r = c * 1024 + o;
                *yi = row(r / m, r % m);
            }
        });
        true
    }
}

#[cfg(test)]
mod tests {
    use crate::discrete::assembly::Operator;
    use crate::spline::knots::KnotVector;
    use crate::testutil::Lcg;

    use super::*;

    /// The stencil product equals the gathered EGG Jacobian (eq. 12) and metric
    /// Laplacian times a random vector to rounding, on a curved map with unequal
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
        for (ncomp, pattern) in [(2, &disc.vector), (1, &disc.scalar)] {
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
            let err = y.iter().zip(&z).fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
            assert!(scale > 0.0 && err <= 1e-13 * scale, "{ncomp} components: {err} against {scale}");
        }
    }
}
