//! Integral functionals `J(c) = ∫ ψ(E) dξ` of the map's first and second derivatives,
//! with their exact gradient and Hessian in the free control points: the shared kernel
//! of the variational methods of §10 (the variational harmonic method, eq. 46, and the
//! quasi-conformal functional, eq. 47-48), written into the same vector pattern and
//! stencil storage as EGG.
//!
//! # The jet
//!
//! At a quadrature point the density reads the *jet*
//! `E = (x_ξ, x_η, x_ξξ, x_ξη, x_ηη, y_ξ, y_η, y_ξξ, y_ξη, y_ηη)`: slot `5 z + i` holds
//! derivative `i` of component `z`. The jet is linear in the control points,
//! `∂E_{5z+i}/∂c^d_b = δ_zd B_{b,i}` with `B_b = (w_b,ξ, w_b,η, w_b,ξξ, w_b,ξη, w_b,ηη)`, so
//!
//! * `∂J/∂c^z_a = ∫ Σ_i (∂ψ/∂E_{5z+i}) B_{a,i}`,
//! * `∂²J/∂c^z_a ∂c^d_b = ∫ Σ_ij B_{a,i} (∂²ψ/∂E_{5z+i} ∂E_{5d+j}) B_{b,j}`,
//!
//! one element-matrix product per block `(z, d)` with `n_d` rows per quadrature point
//! (`n_d = 2` for a density of first derivatives, [`Order::First`]; 5 for
//! [`Order::Second`]). As everywhere in [`crate::methods`], the problem presents
//! `F = -∇J` and `dF/dc = -∇²J`.
//!
//! # Indefinite Hessians
//!
//! The densities of §10 are not convex, so `∇²J` need not be positive definite away from
//! a minimizer. [`ShiftedHessian`] adds `τ diag(|∇²J_ii|)` when the Newton solver finds a
//! direction that does not descend ([`super::DiscreteProblem::raise_shift`]), `τ = 10⁻⁴,
//! 10⁻³, ...`, and lowers `τ` tenfold per new point, back to the exact Hessian (and
//! quadratic convergence) near the minimizer: Newton's method globalised by a
//! Levenberg-Marquardt shift and the Armijo line search of [`crate::solve::newton`].

use rayon::prelude::*;

use crate::discrete::assembly::{element_product, Discretization, Scratch};
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// Length of the jet `E` (module documentation).
pub(crate) const JET: usize = 10;

/// The jet `E` of the map at one point (module documentation).
pub(crate) type Jet = [f64; JET];

/// A `JET x JET` matrix (the Hessian of a density in the jet).
pub(crate) type JetMatrix = [[f64; JET]; JET];

/// Which derivatives a density reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// First derivatives only (slots `5 z`, `5 z + 1` of the jet).
    First,
    /// First and second derivatives.
    Second,
}

impl Order {
    /// Derivative slots per component.
    pub fn slots(self) -> usize {
        match self {
            Order::First => 2,
            Order::Second => 5,
        }
    }
}

/// The jet at the point of element `(ex, ey)` whose tensor basis is in `s.b` (slots
/// beyond `nd` per component left zero).
pub(crate) fn jet_at(disc: &Discretization, ex: usize, ey: usize, cps: &[Point], s: &Scratch, nd: usize) -> Jet {
    let (p, q) = disc.degrees();
    let nx = disc.shape()[0];
    let (fx, fy) = (disc.tables[0].first[ex], disc.tables[1].first[ey]);
    let mut e = [0.0; JET];
    for jb in 0..=q {
        for ib in 0..=p {
            let c = cps[(fy + jb) * nx + fx + ib];
            let b = &s.b[jb * (p + 1) + ib];
            for i in 0..nd {
                e[i] += b[1 + i] * c[0];
                e[5 + i] += b[1 + i] * c[1];
            }
        }
    }
    e
}

/// The first derivatives `(x_ξ, x_η, y_ξ, y_η)` held in a jet (its slots 0, 1, 5, 6).
pub(crate) fn first_derivatives(e: &Jet) -> [f64; 4] {
    [e[0], e[1], e[5], e[6]]
}

/// `Σ_q w_q ψ(E_q)` over the quadrature points of `disc` for the map with control points
/// `cps`; `+∞` when `ψ` is not finite at a point (outside the density's domain). Rows of
/// elements in parallel, summed in order (deterministic).
pub(crate) fn integrate<F>(disc: &Discretization, cps: &[Point], order: Order, psi: F) -> f64
where
    F: Fn(&Jet) -> f64 + Sync,
{
    let (p, q) = disc.degrees();
    let nd = order.slots();
    let nq = [disc.tables[0].nq, disc.tables[1].nq];
    let (nex, ney) = (disc.tables[0].num_elements(), disc.tables[1].num_elements());
    let rows: Vec<f64> = (0..ney)
        .into_par_iter()
        .map_init(
            || Scratch::new(p, q, 1),
            |s, ey| {
                let mut sum = 0.0;
                for ex in 0..nex {
                    // per element, then the elements in order (as in
                    // `winslow::winslow_value_and_gradient`, bit for bit)
                    let mut cell = 0.0;
                    for kv in 0..nq[1] {
                        for ku in 0..nq[0] {
                            let wq = match order {
                                Order::First => disc.tensor_basis_first(ex, ey, ku, kv, s),
                                Order::Second => disc.tensor_basis(ex, ey, ku, kv, s),
                            };
                            let v = psi(&jet_at(disc, ex, ey, cps, s, nd));
                            if !v.is_finite() {
                                return f64::INFINITY;
                            }
                            cell += wq * v;
                        }
                    }
                    sum += cell;
                }
                sum
            },
        )
        .collect();
    rows.iter().sum()
}

/// `F = -∇J` into `res` (full, component-interleaved, length `2 n`) and, when `stencil`
/// is non-empty, `dF/dc = -∇²J` into the vector stencil storage of `disc`, for
/// `J = ∫ ψ(E)`. `dpsi(E, hessian)` returns `∂ψ/∂E` and, when `hessian` is true,
/// `∂²ψ/∂E²` (only the slots of `order` are read).
pub(crate) fn assemble<F>(
    disc: &Discretization,
    cps: &[Point],
    order: Order,
    res: &mut [f64],
    stencil: &mut [f64],
    dpsi: F,
) where
    F: Fn(&Jet, bool) -> (Jet, JetMatrix) + Sync,
{
    let nd = order.slots();
    let nq = [disc.tables[0].nq, disc.tables[1].nq];
    let nqp = nq[0] * nq[1];
    let want_mat = !stencil.is_empty();
    disc.assemble(2, res, stencil, |ex, ey, s| {
        let nloc = s.nloc;
        s.re.fill(0.0);
        if want_mat {
            // per block (z, d): rows (j, k) of test weights; shared rows (j, k) of B_b,j
            s.reserve_products(4 * nd * nqp * nloc, nd * nqp * nloc);
        }
        for kv in 0..nq[1] {
            for ku in 0..nq[0] {
                let k = kv * nq[0] + ku;
                let wq = match order {
                    Order::First => disc.tensor_basis_first(ex, ey, ku, kv, s),
                    Order::Second => disc.tensor_basis(ex, ey, ku, kv, s),
                };
                let e = jet_at(disc, ex, ey, cps, s, nd);
                let (g, h) = dpsi(&e, want_mat);
                for a in 0..nloc {
                    let b = &s.b[a];
                    let (mut gx, mut gy) = (0.0, 0.0);
                    for i in 0..nd {
                        gx += g[i] * b[1 + i];
                        gy += g[5 + i] * b[1 + i];
                    }
                    s.re[a] -= wq * gx;
                    s.re[nloc + a] -= wq * gy;
                }
                if !want_mat {
                    continue;
                }
                for a in 0..nloc {
                    let b = s.b[a];
                    for j in 0..nd {
                        s.tz[(j * nqp + k) * nloc + a] = b[1 + j];
                    }
                    for z in 0..2 {
                        for d in 0..2 {
                            let zd = 2 * z + d;
                            for j in 0..nd {
                                let mut v = 0.0;
                                for i in 0..nd {
                                    v += b[1 + i] * h[5 * z + i][5 * d + j];
                                }
                                s.wa[((zd * nd + j) * nqp + k) * nloc + a] = -wq * v;
                            }
                        }
                    }
                }
            }
        }
        if want_mat {
            let rows = nd * nqp * nloc;
            for zd in 0..4 {
                let w = &s.wa[zd * rows..(zd + 1) * rows];
                element_product(&mut s.ke[zd * nloc * nloc..(zd + 1) * nloc * nloc], w, &s.tz, nloc);
            }
        }
    });
}

/// Smallest relative diagonal shift `τ` of a presented Hessian.
pub(crate) const SHIFT_MIN: f64 = 1e-4;
/// Largest relative diagonal shift `τ`.
pub(crate) const SHIFT_MAX: f64 = 1e8;

/// The Levenberg-Marquardt shift of a minimization problem's Hessian (module
/// documentation): `-∇²J - τ diag(max(|∇²J_ii|, 10⁻⁸ mean))` presented as the Jacobian.
/// At one point `τ` is raised tenfold per [`ShiftedHessian::raise`] (the direction did
/// not descend); from point to point it follows the line search, as the trust-region
/// radius of a Levenberg-Marquardt method follows the ratio of actual to predicted
/// decrease ([`ShiftedHessian::accepted`]): a full step lowers `τ` tenfold (to zero below
/// [`SHIFT_MIN`]: exact Newton steps near the minimizer), a step the line search had to
/// shorten ([`POOR_MODEL`]) raises it fourfold, to at least [`FIRST_RAISE`] (the
/// quadratic model was poor: a degenerate or indefinite Hessian gave a long step). The
/// factors were chosen on the quasi-conformal method, whose Hessian is singular at its
/// minimizers: tenfold raises and a raise only below a damping of 0.1 took 48, 22 and
/// 21 iterations on the quarter annulus, Cook's membrane and the horseshoe, these take
/// 34, 23 and 19. The stencil's point
/// is remembered, so that a raised shift is applied without assembling again.
#[derive(Debug, Clone)]
pub(crate) struct ShiftedHessian {
    /// Positions of the diagonal entries in the vector pattern's values.
    diag: Vec<usize>,
    shift: f64,
    raised: bool,
    /// `τ` for the next point, set by the last accepted step.
    next: f64,
    /// The stencil holds the Hessian at this point.
    assembled: Option<Vec<f64>>,
}

/// An accepted damping at or below this raises the shift for the next point (the line
/// search's first backtrack is at most 0.5: any backtracking).
pub(crate) const POOR_MODEL: f64 = 0.5;
/// The shift a poor model raises a zero shift to.
pub(crate) const FIRST_RAISE: f64 = 1e-3;

impl ShiftedHessian {
    /// For the vector pattern of `disc`.
    pub fn new(disc: &Discretization) -> Self {
        let pat = &disc.vector.csr;
        let diag = (0..pat.nrows).map(|r| pat.position(r, r).expect("the pattern holds the diagonal")).collect();
        Self { diag, shift: 0.0, raised: false, next: 0.0, assembled: None }
    }

    /// The relative shift `τ` of the last presented Hessian.
    pub fn shift(&self) -> f64 {
        self.shift
    }

    /// Before presenting the Hessian at `c`: the shift for a new point (set by the last
    /// accepted step, or lowered tenfold without one) unless it was just raised at this
    /// point; returns whether the Hessian at `c` must be assembled (the stencil does not
    /// hold it). The caller assembles and then calls [`ShiftedHessian::assembled_at`].
    pub fn prepare(&mut self, c: &[f64]) -> bool {
        if !std::mem::take(&mut self.raised) {
            self.shift = self.next;
            self.next = lowered(self.shift);
        }
        self.assembled.as_deref() != Some(c)
    }

    /// The line search accepted a step with damping `delta` from the point of the last
    /// Hessian: sets the shift of the next point (see the type's documentation).
    pub fn accepted(&mut self, delta: f64) {
        self.next = if delta >= 1.0 {
            lowered(self.shift)
        } else if delta <= POOR_MODEL {
            (4.0 * self.shift).clamp(FIRST_RAISE, SHIFT_MAX)
        } else {
            self.shift
        };
    }

    /// The stencil now holds the Hessian at `c`.
    pub(crate) fn assembled_at(&mut self, c: &[f64]) {
        self.assembled = Some(c.to_vec());
    }

    /// The stencil's storage was overwritten (a residual evaluation elsewhere).
    pub(crate) fn invalidate(&mut self) {
        self.assembled = None;
    }

    /// Add the shift to the diagonal of the presented Jacobian `jac = -∇²J`.
    pub fn apply(&self, jac: &mut Csr) {
        shift_diagonal(self.shift, &self.diag, &mut jac.values);
    }

    /// Raise `τ` tenfold (to [`SHIFT_MIN`] from zero); `false` past [`SHIFT_MAX`].
    pub(crate) fn raise(&mut self) -> bool {
        let Some(next) = raised(self.shift) else { return false };
        self.shift = next;
        self.next = lowered(next);
        self.raised = true;
        true
    }
}

/// `τ / 10`, zero below [`SHIFT_MIN`]: the shift one stage back.
pub(crate) fn lowered(shift: f64) -> f64 {
    if shift > 10.0 * SHIFT_MIN {
        0.1 * shift
    } else {
        0.0
    }
}

/// `10 τ` ([`SHIFT_MIN`] from zero): the shift one stage up; `None` past [`SHIFT_MAX`].
pub(crate) fn raised(shift: f64) -> Option<f64> {
    let next = if shift == 0.0 { SHIFT_MIN } else { 10.0 * shift };
    (next <= SHIFT_MAX).then_some(next)
}

/// The relative diagonal shift `τ` of a Hessian presented as the Newton matrix `-H` (the
/// positions `diag` of its diagonal in `values`): `H_ii + τ max(|H_ii|, 10⁻⁸ mean_j
/// |H_jj|)`; the one rule of every minimisation problem (on one patch, or over a layout,
/// [`crate::multipatch::problem::MultipatchProblem`]).
pub(crate) fn shift_diagonal(shift: f64, diag: &[usize], values: &mut [f64]) {
    if shift == 0.0 {
        return;
    }
    let mean = diag.iter().map(|&k| values[k].abs()).sum::<f64>() / diag.len().max(1) as f64;
    for &k in diag {
        values[k] -= shift * values[k].abs().max(1e-8 * mean);
    }
}

/// The outer product `u vᵀ` of two jet vectors.
pub fn outer(u: &Jet, v: &Jet) -> JetMatrix {
    std::array::from_fn(|i| std::array::from_fn(|j| u[i] * v[j]))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::methods::DiscreteProblem;
    use crate::spline::knots::KnotVector;
    use crate::testutil::Lcg;
    use std::sync::Arc;

    /// Central differences of a density's value against its gradient, and of its
    /// gradient against its Hessian, at `e`; returns the largest relative mismatches.
    pub(crate) fn density_fd(
        psi: impl Fn(&Jet) -> f64,
        dpsi: impl Fn(&Jet, bool) -> (Jet, JetMatrix),
        e: &Jet,
        slots: &[usize],
    ) -> (f64, f64) {
        let (g, h) = dpsi(e, true);
        let step = 1e-6;
        let (mut eg, mut eh, mut sg, mut sh) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for &i in slots {
            let (mut ep, mut em) = (*e, *e);
            ep[i] += step;
            em[i] -= step;
            let fd = (psi(&ep) - psi(&em)) / (2.0 * step);
            eg = eg.max((fd - g[i]).abs());
            sg = sg.max(fd.abs());
            let (gp, _) = dpsi(&ep, false);
            let (gm, _) = dpsi(&em, false);
            for &j in slots {
                let fd = (gp[j] - gm[j]) / (2.0 * step);
                eh = eh.max((fd - h[j][i]).abs());
                sh = sh.max(fd.abs());
                assert!((h[i][j] - h[j][i]).abs() <= 1e-12 * (1.0 + h[i][j].abs()), "Hessian not symmetric");
            }
        }
        (eg / sg.max(1e-300), eh / sh.max(1e-300))
    }

    /// A curved map (a perturbed annulus sector) on a `p`, `q` basis with an inner knot.
    pub(crate) fn curved(p: usize, q: usize, seed: u64, noise: f64) -> (Discretization, Vec<Point>) {
        let kx = KnotVector::open_uniform(p, 4);
        let ky = KnotVector::open_uniform(q, 3).with_inserted(&[0.3]);
        let cps = annulus_points(&kx, &ky, seed, noise);
        (Discretization::new([kx, ky]), cps)
    }

    /// The control points of a perturbed annulus sector on the basis `kx x ky`: the
    /// Greville points `(u, v)` mapped to radius `1 + u`, angle `1.2 v`, each moved by
    /// up to `noise / 2` per coordinate (positively oriented for small `noise`).
    pub(crate) fn annulus_points(kx: &KnotVector, ky: &KnotVector, seed: u64, noise: f64) -> Vec<Point> {
        let (gx, gy) = (kx.greville(), ky.greville());
        let mut rng = Lcg::new(seed);
        let mut cps = Vec::new();
        for &v in &gy {
            for &u in &gx {
                let (r, t) = (1.0 + u, 1.2 * v);
                cps.push([r * t.cos() + noise * (rng.uniform() - 0.5), r * t.sin() + noise * (rng.uniform() - 0.5)]);
            }
        }
        cps
    }

    /// The affine map `(ξ, η) -> (2ξ + 0.5η + 1, -0.3ξ + 1.5η)` on a `p`, `ne` basis
    /// (Greville interpolation reproduces it) and a copy with the interior control points
    /// moved by up to `noise / 2`: `(disc, perturbed, exact)`.
    pub(crate) fn affine(p: usize, ne: usize, seed: u64, noise: f64) -> (Arc<Discretization>, Vec<Point>, Vec<Point>) {
        let kx = KnotVector::open_uniform(p, ne);
        let ky = KnotVector::open_uniform(p, ne).with_inserted(&[0.37]);
        let (gx, gy) = (kx.greville(), ky.greville());
        let exact: Vec<Point> =
            gy.iter().flat_map(|&v| gx.iter().map(move |&u| [2.0 * u + 0.5 * v + 1.0, -0.3 * u + 1.5 * v])).collect();
        let disc = Discretization::new([kx, ky]);
        let mut rng = Lcg::new(seed);
        let mut cps = exact.clone();
        for &k in disc.dofs.free() {
            for d in 0..2 {
                cps[k][d] += noise * (rng.uniform() - 0.5);
            }
        }
        (Arc::new(disc), cps, exact)
    }

    /// `F = -∇J` of a minimization problem against central differences of its objective,
    /// and `dF/dc` (with its rank-one term) against central differences of `F`: the
    /// largest mismatches relative to the largest difference quotients.
    pub(crate) fn problem_fd(prob: &mut dyn DiscreteProblem, c: &[f64], h: f64) -> (f64, f64) {
        let n = c.len();
        let mut f = vec![0.0; n];
        prob.residual(c, &mut f);
        let (mut eg, mut sg) = (0.0f64, 0.0f64);
        for j in 0..n {
            let (mut cp, mut cm) = (c.to_vec(), c.to_vec());
            cp[j] += h;
            cm[j] -= h;
            let fd = -(prob.objective(&cp).unwrap() - prob.objective(&cm).unwrap()) / (2.0 * h);
            eg = eg.max((fd - f[j]).abs());
            sg = sg.max(fd.abs());
        }
        let (eh, sh) = crate::methods::jacobian_fd_mismatch(prob, c, h);
        (eg / sg, eh / sh)
    }

    /// Newton's method (no pseudo-time fallback) on `prob` from its own start, the
    /// objective never rising; returns whether it converged, the iterations and the
    /// largest distance of the control points from `exact`.
    pub(crate) fn newton_to(
        prob: Box<dyn DiscreteProblem + Send>,
        c0: Vec<f64>,
        scale: f64,
        exact: &[Point],
    ) -> (bool, usize, f64) {
        use crate::solve::newton::{NonlinearOptions, NonlinearSolver, Status};
        let opts = NonlinearOptions { scale, fallback: false, max_newton: 200, ..Default::default() };
        let mut s = NonlinearSolver::new(prob, c0, opts);
        let (mut last, mut its) = (f64::INFINITY, 0);
        for it in s.by_ref() {
            let it = it.unwrap();
            let j = it.objective.unwrap();
            assert!(j <= last, "objective rose: {j} > {last}");
            last = j;
            its = it.iteration;
        }
        let converged = s.status() == &Status::Converged;
        let (prob, c) = s.into_parts();
        let cps = prob.control_points(&c);
        let err = cps.iter().zip(exact).fold(0.0f64, |m, (a, b)| m.max((a[0] - b[0]).abs()).max((a[1] - b[1]).abs()));
        (converged, its, err)
    }

    /// `ψ = Σ_k a_k E_k + (Σ_k b_k E_k)³`: the assembled gradient and Hessian of `∫ ψ`
    /// against central differences of [`integrate`], for both orders.
    #[test]
    fn assembled_derivatives_match_finite_differences() {
        let a: Jet = std::array::from_fn(|k| 0.3 + 0.1 * k as f64);
        let b: Jet = std::array::from_fn(|k| 0.2 - 0.05 * k as f64);
        for order in [Order::First, Order::Second] {
            let nd = order.slots();
            let used = |k: usize| k % 5 < nd;
            let lin = move |e: &Jet| (0..JET).filter(|&k| used(k)).map(|k| b[k] * e[k]).sum::<f64>();
            let psi = move |e: &Jet| (0..JET).filter(|&k| used(k)).map(|k| a[k] * e[k]).sum::<f64>() + lin(e).powi(3);
            let dpsi = move |e: &Jet, _h: bool| {
                let l = lin(e);
                let g: Jet = std::array::from_fn(|k| if used(k) { a[k] + 3.0 * l * l * b[k] } else { 0.0 });
                let h: JetMatrix = std::array::from_fn(|i| {
                    std::array::from_fn(|j| if used(i) && used(j) { 6.0 * l * b[i] * b[j] } else { 0.0 })
                });
                (g, h)
            };
            let (disc, cps) = curved(3, 2, 3, 0.05);
            let n = disc.dofs.num_total();
            let mut res = vec![0.0; 2 * n];
            let mut st = vec![0.0; disc.stencil_len(2)];
            assemble(&disc, &cps, order, &mut res, &mut st, dpsi);
            let f = disc.restrict(&res, 2);
            let jac = disc.vector.matrix(&st).to_dense();
            let m = disc.dofs.num_free();
            let h = 1e-6;
            let (mut eg, mut eh, mut sg, mut sh) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
            for col in 0..2 * m {
                let (z, fi) = (col / m, col % m);
                let k = disc.dofs.free()[fi];
                let (mut cp, mut cm) = (cps.clone(), cps.clone());
                cp[k][z] += h;
                cm[k][z] -= h;
                let fd = -(integrate(&disc, &cp, order, psi) - integrate(&disc, &cm, order, psi)) / (2.0 * h);
                eg = eg.max((fd - f[col]).abs());
                sg = sg.max(fd.abs());
                let (mut rp, mut rm) = (vec![0.0; 2 * n], vec![0.0; 2 * n]);
                assemble(&disc, &cp, order, &mut rp, &mut [], dpsi);
                assemble(&disc, &cm, order, &mut rm, &mut [], dpsi);
                let (fp, fm) = (disc.restrict(&rp, 2), disc.restrict(&rm, 2));
                for row in 0..2 * m {
                    let fd = (fp[row] - fm[row]) / (2.0 * h);
                    eh = eh.max((fd - jac[row][col]).abs());
                    sh = sh.max(fd.abs());
                }
            }
            assert!(eg < 1e-7 * sg, "{order:?}: gradient {eg} (scale {sg})");
            assert!(eh < 1e-7 * sh, "{order:?}: Hessian {eh} (scale {sh})");
        }
    }

    #[test]
    fn shift_is_raised_at_a_point_and_follows_the_line_search() {
        let (disc, _) = curved(2, 2, 1, 0.0);
        let mut s = ShiftedHessian::new(&disc);
        let c = vec![0.0; 4];
        assert!(s.prepare(&c));
        s.assembled_at(&c);
        assert_eq!(s.shift(), 0.0);
        assert!(s.raise() && s.raise() && s.raise());
        assert!(!s.prepare(&c), "the stencil holds the Hessian at c");
        assert!((s.shift() - 100.0 * SHIFT_MIN).abs() < 1e-18);
        // no step reported: lowered tenfold per new point, then back to the exact Hessian
        let c2 = vec![1.0; 4];
        assert!(s.prepare(&c2));
        assert!((s.shift() - 10.0 * SHIFT_MIN).abs() < 1e-18);
        assert!(s.prepare(&c2));
        assert_eq!(s.shift(), 0.0);
        // a shortened step raises the shift of the next point, a full step lowers it
        s.accepted(0.01);
        s.prepare(&c);
        assert_eq!(s.shift(), FIRST_RAISE);
        s.accepted(0.5);
        s.prepare(&c2);
        assert!((s.shift() - 4.0 * FIRST_RAISE).abs() < 1e-18);
        s.accepted(1.0);
        s.prepare(&c);
        assert!((s.shift() - 0.4 * FIRST_RAISE).abs() < 1e-18);
        s.invalidate();
    }
}
