//! The paper's grid-quality benchmark (§10, eq. 44-45): the scalar Poisson problem
//! `-Δu = f` in `Ω`, `u = g` on `∂Ω`, solved by IGA on the mapped geometry, and the
//! relative `L2` error `Q(x)` of its solution for the manufactured solution
//! `u* = sin(π x / a1) sin(π y / a2)`.
//!
//! The weak form `int_Ω grad u . grad v dx = int_Ω f v dx` is pulled back to the
//! parameter square with `grad_x w = J^{-T} grad_xi w` and `dx = |det J| dxi`; the
//! discrete space is the map's tensor B-spline basis (free = interior functions, the
//! boundary coefficients interpolate `g` at the Greville points of each side). The
//! assembly reuses the EGG machinery of [`crate::discrete::assembly`]: basis tables, the scalar
//! [`crate::discrete::assembly::SystemPattern`] and stencil storage.

use std::time::Instant;

use serde::Serialize;

use crate::discrete::assembly::Discretization;
use crate::error::{Error, Result};
use crate::linalg::linsolve::{LinearMethod, LinearSolver};
use crate::spline::basis::BasisDerivs;
use crate::spline::quadrature::GaussLegendre;
use crate::spline::surface::{Side, Surface};

/// Geometry of a (possibly rational) map at one quadrature point from the tensor basis
/// values `b[a] = (w, w_u, w_v, ..)` and the element's control points.
fn geometry(map: &Surface, disc: &Discretization, ex: usize, ey: usize, b: &[[f64; 6]]) -> ([f64; 2], [[f64; 2]; 2]) {
    let (p, q) = disc.degrees();
    let nx = disc.shape()[0];
    let (fx, fy) = (disc.tables[0].first[ex], disc.tables[1].first[ey]);
    // homogeneous sums (w x, w y, w) and their xi, eta derivatives
    let mut h = [[0.0f64; 3]; 3];
    for jb in 0..=q {
        for ib in 0..=p {
            let k = (fy + jb) * nx + fx + ib;
            let c = map.control_points[k];
            let w = map.weights.as_ref().map_or(1.0, |w| w[k]);
            let bb = &b[jb * (p + 1) + ib];
            for (r, d) in h.iter_mut().zip([bb[0], bb[1], bb[2]]) {
                r[0] += d * w * c[0];
                r[1] += d * w * c[1];
                r[2] += d * w;
            }
        }
    }
    let w = h[0][2];
    let x = [h[0][0] / w, h[0][1] / w];
    let mut jac = [[0.0; 2]; 2]; // jac[c] = (x^c_xi, x^c_eta)
    for c in 0..2 {
        jac[c][0] = (h[1][c] - h[1][2] * x[c]) / w;
        jac[c][1] = (h[2][c] - h[2][2] * x[c]) / w;
    }
    (x, jac)
}

/// Physical gradient `J^{-T} (w_u, w_v)` and `det J`.
fn phys_grad(jac: &[[f64; 2]; 2], wu: f64, wv: f64) -> ([f64; 2], f64) {
    let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
    ([(jac[1][1] * wu - jac[1][0] * wv) / det, (-jac[0][1] * wu + jac[0][0] * wv) / det], det)
}

/// Coefficients of the interpolant of `g(x(.))` at the Greville points of one side.
fn side_interpolant(map: &Surface, side: Side, g: &dyn Fn([f64; 2]) -> f64) -> Vec<f64> {
    let curve = map.boundary(side);
    let kv = &curve.knots;
    let gr = kv.greville();
    let n = gr.len();
    let mut a = vec![vec![0.0; n]; n];
    let mut rhs = vec![vec![0.0]; n];
    for (i, &u) in gr.iter().enumerate() {
        let b = BasisDerivs::at(kv, u, 0);
        for (j, &v) in b.ders(0).iter().enumerate() {
            a[i][b.first() + j] = v;
        }
        rhs[i][0] = g(curve.eval(u));
    }
    crate::linalg::linsolve::dense_solve(&a, &rhs).into_iter().map(|r| r[0]).collect()
}

/// Solve `-Δu = f` in the mapped domain with `u = g` on its boundary; returns the
/// coefficients of `u_h` on the map's tensor basis (`xi` index fastest). The map must
/// have `det J != 0` at the quadrature points.
pub(crate) fn solve_poisson(
    map: &Surface,
    f: &(dyn Fn([f64; 2]) -> f64 + Sync),
    g: &dyn Fn([f64; 2]) -> f64,
) -> Result<Vec<f64>> {
    let disc = Discretization::new(map.knots.clone());
    let n = disc.dofs.num_total();
    let [nx, ny] = disc.shape();
    if disc.dofs.num_free() == 0 {
        return Err(Error::Invalid("the Poisson benchmark needs interior basis functions".into()));
    }
    // Dirichlet data
    let mut u = vec![0.0; n];
    for side in Side::ALL {
        let vals = side_interpolant(map, side, g);
        for (k, v) in Surface::side_indices([nx, ny], side).into_iter().zip(vals) {
            u[k] = v;
        }
    }
    let nq = [disc.tables[0].nq, disc.tables[1].nq];
    let mut res = vec![0.0; n];
    let mut stencil = vec![0.0; disc.stencil_len(1)];
    disc.assemble(1, &mut res, &mut stencil, |ex, ey, s| {
        let nloc = s.nloc;
        s.re.fill(0.0);
        s.ke.fill(0.0);
        for kv in 0..nq[1] {
            for ku in 0..nq[0] {
                let wq = disc.tensor_basis(ex, ey, ku, kv, s);
                let (x, jac) = geometry(map, &disc, ex, ey, &s.b);
                let (_, det) = phys_grad(&jac, 0.0, 0.0);
                let dx = wq * det.abs();
                for a in 0..nloc {
                    let (g, _) = phys_grad(&jac, s.b[a][1], s.b[a][2]);
                    s.t[a] = [g[0], g[1], 0.0, 0.0];
                }
                let fx = f(x);
                for a in 0..nloc {
                    s.re[a] += dx * fx * s.b[a][0];
                    let ga = s.t[a];
                    let row = &mut s.ke[a * nloc..(a + 1) * nloc];
                    for (r, gb) in row.iter_mut().zip(&s.t) {
                        *r += dx * (ga[0] * gb[0] + ga[1] * gb[1]);
                    }
                }
            }
        }
    });
    let k = disc.scalar.matrix(&stencil);
    let lift = disc.apply_to_fixed_scalar(&stencil, &u);
    let rhs: Vec<f64> = disc.restrict(&res, 1).iter().zip(&lift).map(|(r, l)| r - l).collect();
    // the stiffness matrix is symmetric positive definite: sparse Cholesky, exact to rounding
    let mut ls = LinearSolver::new(LinearMethod::Cholesky);
    ls.factor(&k)?;
    let c = ls.solve(&rhs)?;
    for (fi, &kk) in disc.dofs.free().iter().enumerate() {
        u[kk] = c[fi];
    }
    Ok(u)
}

/// Errors of a discrete solution against an exact one.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct PoissonErrors {
    /// `||u_h - u||_L2(Ω)`.
    pub l2: f64,
    /// `|u_h - u|_H1(Ω)`.
    pub h1: f64,
    /// `||u||_L2(Ω)`.
    pub l2_exact: f64,
}

/// `L2` and `H1`-seminorm errors of `u_h` (coefficients on the map's basis) against
/// `exact(x) = (u, grad u)`, with `p + 3` Gauss points per direction and element.
pub(crate) fn poisson_errors(map: &Surface, uh: &[f64], exact: &dyn Fn([f64; 2]) -> (f64, [f64; 2])) -> PoissonErrors {
    let [p, q] = map.degrees();
    let nx = map.shape()[0];
    let gx = GaussLegendre::new(p + 3);
    let gy = GaussLegendre::new(q + 3);
    let (mut bu, mut bv) = (BasisDerivs::default(), BasisDerivs::default());
    let (mut l2, mut h1, mut ex2) = (0.0, 0.0, 0.0);
    for (sy, ya, yb) in map.knots[1].elements() {
        for (v, wv) in gy.on(ya, yb) {
            bv.eval_in_span(&map.knots[1], sy, v, 1);
            for (sx, xa, xb) in map.knots[0].elements() {
                for (u, wu) in gx.on(xa, xb) {
                    bu.eval_in_span(&map.knots[0], sx, u, 1);
                    let d = map.derivs_with(&bu, &bv, 1);
                    let jac = [[d.xu[0], d.xv[0]], [d.xu[1], d.xv[1]]];
                    let (mut val, mut du, mut dv) = (0.0, 0.0, 0.0);
                    for jb in 0..=q {
                        for ib in 0..=p {
                            let c = uh[(bv.first() + jb) * nx + bu.first() + ib];
                            val += c * bu.d[0][ib] * bv.d[0][jb];
                            du += c * bu.d[1][ib] * bv.d[0][jb];
                            dv += c * bu.d[0][ib] * bv.d[1][jb];
                        }
                    }
                    let (g, det) = phys_grad(&jac, du, dv);
                    let (ue, ge) = exact(d.x);
                    let w = wu * wv * det.abs();
                    l2 += w * (val - ue).powi(2);
                    h1 += w * ((g[0] - ge[0]).powi(2) + (g[1] - ge[1]).powi(2));
                    ex2 += w * ue * ue;
                }
            }
        }
    }
    PoissonErrors { l2: l2.sqrt(), h1: h1.sqrt(), l2_exact: ex2.sqrt() }
}

/// Result of the grid-quality benchmark.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct PoissonReport {
    /// Length scales `a1, a2` of `u*`.
    pub a: [f64; 2],
    /// Scalar unknowns (interior basis functions).
    pub unknowns: usize,
    /// Errors of the IGA solution.
    pub errors: PoissonErrors,
    /// `Q(x) = ||u_h - u*|| / ||u*||` (eq. 45).
    pub q: f64,
    /// Seconds.
    pub seconds: f64,
}

/// The manufactured solution `u* = sin(π x / a1) sin(π y / a2)` with its gradient, and
/// `-Δu* = π² (1/a1² + 1/a2²) u*`.
#[allow(clippy::type_complexity)]
pub(crate) fn manufactured(a: [f64; 2]) -> (impl Fn([f64; 2]) -> (f64, [f64; 2]), impl Fn([f64; 2]) -> f64 + Sync) {
    use std::f64::consts::PI;
    let (k1, k2) = (PI / a[0], PI / a[1]);
    let exact = move |x: [f64; 2]| {
        let (s1, c1) = (k1 * x[0]).sin_cos();
        let (s2, c2) = (k2 * x[1]).sin_cos();
        (s1 * s2, [k1 * c1 * s2, k2 * s1 * c2])
    };
    let f = move |x: [f64; 2]| (k1 * k1 + k2 * k2) * (k1 * x[0]).sin() * (k2 * x[1]).sin();
    (exact, f)
}

/// Default length scales: half the extents of the map's bounding box (so that `u*`
/// makes one full period across the domain in each direction).
pub(crate) fn default_scales(map: &Surface) -> [f64; 2] {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for s in Side::ALL {
        for p in map.boundary(s).sample(64) {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
    }
    let diam = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    [0, 1].map(|d| (0.5 * (hi[d] - lo[d])).max(0.05 * diam))
}

/// Run the benchmark of eq. (44)-(45) on `map` with length scales `a` (default:
/// `default_scales`).
pub fn poisson_benchmark(map: &Surface, a: Option<[f64; 2]>) -> Result<PoissonReport> {
    let t0 = Instant::now();
    let a = a.unwrap_or_else(|| default_scales(map));
    if !(a[0] > 0.0 && a[1] > 0.0 && a[0].is_finite() && a[1].is_finite()) {
        return Err(Error::Invalid(format!("Poisson length scales must be positive, got {a:?}")));
    }
    let (exact, f) = manufactured(a);
    let g = |x: [f64; 2]| exact(x).0;
    let uh = solve_poisson(map, &f, &g)?;
    let errors = poisson_errors(map, &uh, &exact);
    let unknowns = Discretization::new(map.knots.clone()).dofs.num_free();
    Ok(PoissonReport { a, unknowns, errors, q: errors.l2 / errors.l2_exact, seconds: t0.elapsed().as_secs_f64() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    /// A polynomial map of degree 2 (exact on every refinement) or the identity.
    fn map(p: usize, ne: usize, curved: bool) -> Surface {
        let bez = KnotVector::open_uniform(2, 1);
        let b1 = [0.0, 0.5, 1.0];
        let b2 = [0.0, 0.0, 1.0];
        let mut cps = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                let (u, v) = (b1[i], b1[j]);
                if curved {
                    // x = u + 0.3 v^2, y = v + 0.2 u^2 + 0.1 u v: det J > 0 on [0, 1]^2
                    cps.push([u + 0.3 * b2[j], v + 0.2 * b2[i] + 0.1 * b1[i] * b1[j]]);
                } else {
                    cps.push([u, v]);
                }
            }
        }
        let mut s = Surface::new([bez.clone(), bez], cps, None).unwrap();
        for _ in 2..p {
            s = s.elevated().unwrap();
        }
        let k = KnotVector::open_uniform(p, ne);
        s.refined(&[k.clone(), k]).unwrap()
    }

    fn rates(p: usize, curved: bool) -> Vec<(f64, f64)> {
        let errs: Vec<PoissonErrors> = [4, 8, 16]
            .iter()
            .map(|&ne| {
                let m = map(p, ne, curved);
                let (exact, f) = manufactured([0.7, 0.9]);
                let uh = solve_poisson(&m, &f, &|x| exact(x).0).unwrap();
                poisson_errors(&m, &uh, &exact)
            })
            .collect();
        errs.windows(2).map(|w| ((w[0].l2 / w[1].l2).log2(), (w[0].h1 / w[1].h1).log2())).collect()
    }

    #[test]
    fn optimal_rates_on_the_identity_map() {
        for p in [2, 3] {
            let r = rates(p, false);
            let last = r.last().unwrap();
            assert!((last.0 - (p + 1) as f64).abs() < 0.3, "p={p} L2 rates {r:?}");
            assert!((last.1 - p as f64).abs() < 0.3, "p={p} H1 rates {r:?}");
        }
    }

    #[test]
    fn optimal_rates_on_a_curved_map() {
        for p in [2, 3] {
            let r = rates(p, true);
            let last = r.last().unwrap();
            assert!((last.0 - (p + 1) as f64).abs() < 0.3, "p={p} L2 rates {r:?}");
            assert!((last.1 - p as f64).abs() < 0.3, "p={p} H1 rates {r:?}");
        }
    }

    #[test]
    fn benchmark_reports_q() {
        let m = map(3, 8, true);
        let r = poisson_benchmark(&m, None).unwrap();
        assert!(r.q > 0.0 && r.q < 1e-3, "{r:?}");
        assert!((r.q - r.errors.l2 / r.errors.l2_exact).abs() < 1e-15);
        assert_eq!(r.unknowns, 9 * 9);
        // the exact solution of a quadratic in the space: u = x is reproduced
        let uh = solve_poisson(&m, &|_| 0.0, &|x| x[0]).unwrap();
        let e = poisson_errors(&m, &uh, &|x| (x[0], [1.0, 0.0]));
        assert!(e.l2 < 1e-12 && e.h1 < 1e-11, "{e:?}");
    }
}
