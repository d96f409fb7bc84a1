//! First-order forms `F^z_a = ∫ ∇w_a · G_z(∇x) dξ` on a tensor basis, with their exact
//! Jacobian: the shared kernel of the weak form (eq. 14) and the Winslow gradient
//! (eq. 16), written into the same vector pattern and stencil storage as EGG.
//!
//! With `e = (x_ξ, x_η, y_ξ, y_η)` and a flux `G(e) = (G_0, G_1, G_2, G_3)` (component
//! `z` of the form pairs `(w_ξ, w_η)` with `(G_{2z}, G_{2z+1})`), `e` is linear in the
//! control points (`∂(e_{2d}, e_{2d+1})/∂c^d_b = (w_b,ξ, w_b,η)`), so
//!
//! `∂F^z_a/∂c^d_b = ∫ Σ_ij ∂_i w_a (∂G_{2z+i}/∂e_{2d+j}) ∂_j w_b`,
//!
//! one element-matrix product per block `(z, d)` with two rows per quadrature point.

use rayon::prelude::*;

use crate::discrete::assembly::{element_product, Discretization, Scratch};
use crate::spline::curve::Point;

/// `e = (x_ξ, x_η, y_ξ, y_η)` at the point of element `(ex, ey)` whose tensor basis is in
/// `s.b`.
pub(crate) fn gradient_at(disc: &Discretization, ex: usize, ey: usize, cps: &[Point], s: &Scratch) -> [f64; 4] {
    let (p, q) = disc.degrees();
    let nx = disc.shape()[0];
    let (fx, fy) = (disc.tables[0].first[ex], disc.tables[1].first[ey]);
    let mut e = [0.0; 4];
    for jb in 0..=q {
        for ib in 0..=p {
            let c = cps[(fy + jb) * nx + fx + ib];
            let b = &s.b[jb * (p + 1) + ib];
            e[0] += b[1] * c[0];
            e[1] += b[2] * c[0];
            e[2] += b[1] * c[1];
            e[3] += b[2] * c[1];
        }
    }
    e
}

/// The first-order form of the module documentation: `F` into `res` (full,
/// component-interleaved, length `2 n`) and, when `stencil` is non-empty, `dF/dc` into
/// the vector stencil storage. `flux(e)` returns `G(e)` and `∂G/∂e`.
pub(crate) fn flux_form<G>(disc: &Discretization, cps: &[Point], res: &mut [f64], stencil: &mut [f64], flux: G)
where
    G: Fn([f64; 4]) -> ([f64; 4], [[f64; 4]; 4]) + Sync,
{
    flux_form_with(disc, cps, res, stencil, false, flux);
}

/// [`flux_form`]; with `symmetric` (`∂G/∂e` symmetric, as for the gradient of a
/// functional) the block `(1, 0)` of the Jacobian is the transpose of block `(0, 1)`
/// and is not computed: a quarter of the element products saved.
pub(crate) fn flux_form_with<G>(
    disc: &Discretization,
    cps: &[Point],
    res: &mut [f64],
    stencil: &mut [f64],
    symmetric: bool,
    flux: G,
) where
    G: Fn([f64; 4]) -> ([f64; 4], [[f64; 4]; 4]) + Sync,
{
    let nq = [disc.tables[0].nq, disc.tables[1].nq];
    let nqp = nq[0] * nq[1];
    let want_mat = !stencil.is_empty();
    disc.assemble(2, res, stencil, |ex, ey, s| {
        let nloc = s.nloc;
        s.re.fill(0.0);
        if want_mat {
            // per block (z, d): rows (j, k) of test weights; rows (j, k) of w_b,j
            s.reserve_products(8 * nqp * nloc, 2 * nqp * nloc);
        }
        for kv in 0..nq[1] {
            for ku in 0..nq[0] {
                let k = kv * nq[0] + ku;
                let wq = disc.tensor_basis_first(ex, ey, ku, kv, s);
                let e = gradient_at(disc, ex, ey, cps, s);
                let (g, h) = flux(e);
                for a in 0..nloc {
                    let (bu, bv) = (s.b[a][1], s.b[a][2]);
                    s.re[a] += wq * (g[0] * bu + g[1] * bv);
                    s.re[nloc + a] += wq * (g[2] * bu + g[3] * bv);
                }
                if !want_mat {
                    continue;
                }
                for a in 0..nloc {
                    let phi = [s.b[a][1], s.b[a][2]];
                    s.tz[k * nloc + a] = phi[0];
                    s.tz[(nqp + k) * nloc + a] = phi[1];
                    for z in 0..2 {
                        for d in 0..2 {
                            if symmetric && (z, d) == (1, 0) {
                                continue;
                            }
                            let zd = z * 2 + d;
                            for j in 0..2 {
                                let v = phi[0] * h[2 * z][2 * d + j] + phi[1] * h[2 * z + 1][2 * d + j];
                                s.wa[((2 * zd + j) * nqp + k) * nloc + a] = wq * v;
                            }
                        }
                    }
                }
            }
        }
        if want_mat {
            for zd in 0..4 {
                if symmetric && zd == 2 {
                    continue;
                }
                let w = &s.wa[2 * zd * nqp * nloc..2 * (zd + 1) * nqp * nloc];
                element_product(&mut s.ke[zd * nloc * nloc..(zd + 1) * nloc * nloc], w, &s.tz, nloc);
            }
            if symmetric {
                // block (1, 0) = block (0, 1) transposed
                let (lo, hi) = s.ke.split_at_mut(2 * nloc * nloc);
                let (b01, b10) = (&lo[nloc * nloc..], &mut hi[..nloc * nloc]);
                for a in 0..nloc {
                    for b in 0..nloc {
                        b10[a * nloc + b] = b01[b * nloc + a];
                    }
                }
            }
        }
    });
}

/// Smallest `det J` over the quadrature points of `disc` (rows of elements in parallel).
pub fn min_det_j(disc: &Discretization, cps: &[Point]) -> f64 {
    let (p, q) = disc.degrees();
    let nq = [disc.tables[0].nq, disc.tables[1].nq];
    let (nex, ney) = (disc.tables[0].num_elements(), disc.tables[1].num_elements());
    (0..ney)
        .into_par_iter()
        .map_init(
            || Scratch::new(p, q, 1),
            |s, ey| {
                let mut m = f64::INFINITY;
                for ex in 0..nex {
                    for kv in 0..nq[1] {
                        for ku in 0..nq[0] {
                            disc.tensor_basis_first(ex, ey, ku, kv, s);
                            let [a, b, c, d] = gradient_at(disc, ex, ey, cps, s);
                            let det = a * d - b * c;
                            m = if det.is_nan() { f64::NEG_INFINITY } else { m.min(det) };
                        }
                    }
                }
                m
            },
        )
        .reduce(|| f64::INFINITY, f64::min)
}
