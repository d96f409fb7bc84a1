//! Tests of the Winslow functional: density, gradient and Hessian against finite
//! differences, the projection onto semidefinite matrices, the problem's line search.
use super::*;
use crate::methods::density::tests::{affine, problem_fd};
use crate::methods::density::SHIFT_MIN;
use crate::solve::newton::{NonlinearOptions, NonlinearSolver, Status};
use crate::spline::knots::KnotVector;

/// A curved map (a perturbed annulus sector) on a `(3, 2)` basis.
fn curved(seed: u64, noise: f64) -> (Arc<Discretization>, Vec<Point>) {
    let (disc, cps) = crate::methods::density::tests::curved(3, 2, seed, noise);
    (Arc::new(disc), cps)
}

fn max_abs(v: impl IntoIterator<Item = f64>) -> f64 {
    v.into_iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

#[test]
fn density_derivatives_match_finite_differences() {
    let e = [1.3, 0.4, -0.2, 0.9];
    let (w, g, h) = winslow_density(e);
    assert!((w - (1.69 + 0.16 + 0.04 + 0.81) / (1.17 + 0.08)).abs() < 1e-14);
    let step = 1e-6;
    for i in 0..4 {
        let (mut ep, mut em) = (e, e);
        ep[i] += step;
        em[i] -= step;
        let (wp, gp, _) = winslow_density(ep);
        let (wm, gm, _) = winslow_density(em);
        assert!(((wp - wm) / (2.0 * step) - g[i]).abs() < 1e-8, "gradient {i}");
        for j in 0..4 {
            assert!(((gp[j] - gm[j]) / (2.0 * step) - h[j][i]).abs() < 1e-7, "Hessian ({j}, {i})");
            assert!((h[i][j] - h[j][i]).abs() < 1e-14 * w);
        }
    }
}

/// `F = -∇J` against central differences of the objective, `dF/dc` against central
/// differences of `F`, on a curved map with every kind of basis function.
#[test]
fn gradient_and_hessian_match_finite_differences() {
    let (disc, cps) = curved(7, 0.05);
    let mut prob = WinslowProblem::new(disc, cps);
    let c = prob.unknowns();
    let n = c.len();
    let mut f = vec![0.0; n];
    let mut jac = Csr::default();
    prob.jacobian(&c, &mut f, &mut jac);
    assert_eq!(prob.shift(), 0.0);
    let dense = jac.to_dense();
    let j0 = prob.objective(&c).unwrap();
    assert!(j0.is_finite() && j0 > 2.0, "J = {j0}");
    let (err_g, err_h) = problem_fd(&mut prob, &c, 1e-6);
    assert!(err_g < 1e-7, "gradient: relative {err_g}");
    assert!(err_h < 1e-7, "Hessian: relative {err_h}");
    let scale_h = max_abs(dense.iter().flatten().copied());
    // symmetric
    for (i, row) in dense.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            assert!((v - dense[j][i]).abs() <= 1e-12 * scale_h, "({i}, {j})");
        }
    }
}

/// The affine map is a critical point, and Newton from a perturbed interior
/// converges to it (the minimiser of eq. 16 with an affine boundary).
#[test]
fn minimiser_of_an_affine_boundary_is_the_affine_map() {
    for p in [2, 3] {
        let (disc, cps, exact) = affine(p, 5, 3, 0.04);
        let mut at_exact = WinslowProblem::new(disc.clone(), exact.clone());
        let ce = at_exact.unknowns();
        let mut f = vec![0.0; ce.len()];
        at_exact.residual(&ce, &mut f);
        assert!(max_abs(f.iter().copied()) < 1e-13, "p = {p}: |∇J| = {}", max_abs(f));
        let prob = WinslowProblem::new(disc.clone(), cps);
        let c0 = prob.unknowns();
        let m = disc.dofs.num_free();
        let opts = NonlinearOptions { scale: (m as f64).sqrt() * 2.5, fallback: false, ..Default::default() };
        let mut s = NonlinearSolver::new(prob, c0, opts);
        let mut last = f64::INFINITY;
        for it in s.by_ref() {
            let j = it.unwrap().objective.unwrap();
            assert!(j <= last);
            last = j;
        }
        assert_eq!(s.status(), &Status::Converged);
        let (prob, c) = s.into_parts();
        let err = max_abs(prob.control_points(&c).iter().zip(&exact).flat_map(|(a, b)| [a[0] - b[0], a[1] - b[1]]));
        assert!(err < 1e-9, "p = {p}: distance to the affine map {err}");
    }
}

/// The unit square with its interior twisted by `θ(ξ, η) = alpha 16 ξ(1-ξ)η(1-η)`
/// about the centre: bijective, far from the minimiser (the identity).
fn twisted(p: usize, ne: usize, alpha: f64) -> (Arc<Discretization>, Vec<Point>, Vec<Point>) {
    let k = KnotVector::open_uniform(p, ne);
    let g = k.greville();
    let exact: Vec<Point> = g.iter().flat_map(|&v| g.iter().map(move |&u| [u, v])).collect();
    let disc = Arc::new(Discretization::new([k.clone(), k]));
    let mut cps = exact.clone();
    for &kk in disc.dofs.free() {
        let [u, v] = exact[kk];
        let th = alpha * 16.0 * u * (1.0 - u) * v * (1.0 - v);
        let (x, y) = (u - 0.5, v - 0.5);
        cps[kk] = [0.5 + th.cos() * x - th.sin() * y, 0.5 + th.sin() * x + th.cos() * y];
    }
    (disc, cps, exact)
}

/// Counts the trial points whose objective is `+∞` (folded at a quadrature point).
struct Counting {
    inner: WinslowProblem,
    infeasible: usize,
}

impl DiscreteProblem for Counting {
    fn size(&self) -> usize {
        self.inner.size()
    }
    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        self.inner.residual(c, f)
    }
    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        self.inner.jacobian(c, f, jac)
    }
    fn mass(&mut self) -> &Csr {
        self.inner.mass()
    }
    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        let j = self.inner.objective(c);
        self.infeasible += usize::from(j.is_some_and(|j| j.is_infinite()));
        j
    }
    fn raise_shift(&mut self) -> bool {
        self.inner.raise_shift()
    }
    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        self.inner.control_points(c)
    }
}

/// From a strongly twisted square the first full Newton step folds the map (checked
/// here: `J = +∞` there although the direction descends); the line search rejects it
/// and every accepted iterate stays bijective, down to the identity map.
#[test]
fn line_search_rejects_a_folding_step() {
    use crate::linalg::linsolve::{LinearMethod, LinearSolver};
    let (disc, cps, exact) = twisted(2, 6, 1.65);
    let mut prob = WinslowProblem::new(disc.clone(), cps);
    let c = prob.unknowns();
    assert!(prob.objective(&c).unwrap().is_finite(), "the start is bijective");
    let mut f = vec![0.0; c.len()];
    let mut jac = Csr::default();
    prob.jacobian(&c, &mut f, &mut jac);
    let mut lu = LinearSolver::new(LinearMethod::Lu);
    lu.factor(&jac).unwrap();
    let dx = lu.solve(&f.iter().map(|v| -v).collect::<Vec<_>>()).unwrap();
    assert!(f.iter().zip(&dx).map(|(a, b)| a * b).sum::<f64>() > 0.0, "a descent direction");
    let full: Vec<f64> = c.iter().zip(&dx).map(|(a, b)| a + b).collect();
    assert_eq!(prob.objective(&full), Some(f64::INFINITY), "the full step folds the map");

    let m = disc.dofs.num_free();
    let opts = NonlinearOptions { scale: (m as f64).sqrt(), fallback: false, ..Default::default() };
    let mut s = NonlinearSolver::new(Counting { inner: prob, infeasible: 0 }, c, opts);
    for it in s.by_ref() {
        let it = it.unwrap();
        assert!(it.objective.unwrap().is_finite(), "iterate {} folds", it.iteration);
    }
    assert_eq!(s.status(), &Status::Converged);
    let (prob, c) = s.into_parts();
    assert!(prob.infeasible > 0, "the line search met folded trial points");
    let err = max_abs(prob.control_points(&c).iter().zip(&exact).flat_map(|(a, b)| [a[0] - b[0], a[1] - b[1]]));
    assert!(err < 1e-9, "distance to the identity {err}");
}

/// The preconditioner's block is the eigenvalue-floored mean of the Hessian's
/// diagonal blocks: equal to it where that is definite, definite always.
#[test]
fn preconditioner_block_is_the_definite_mean_block() {
    for e in [[1.3, 0.4, -0.2, 0.9], [2.0, 0.0, 0.0, 0.5], [1.0, 3.0, -0.1, 0.4]] {
        let (_, _, h) = winslow_density(e);
        let [a11, a12, a22] = definite_mean_block(e);
        assert!(a11 > 0.0 && a22 > 0.0 && a11 * a22 - a12 * a12 > 0.0, "{e:?}");
        let m = [0.5 * (h[0][0] + h[2][2]), 0.5 * (h[0][1] + h[2][3]), 0.5 * (h[1][1] + h[3][3])];
        if m[0] > 0.0 && m[0] * m[2] - m[1] * m[1] > 1e-3 * (m[0] + m[2]).powi(2) {
            for (x, y) in [a11, a12, a22].iter().zip(m) {
                assert!((x - y).abs() < 1e-12 * (m[0] + m[2]), "{e:?}: {x} vs {y}");
            }
        }
    }
}

/// `raise_shift` first re-presents the Hessian with every point's density Hessian
/// projected (in three steps, the last one fully) onto the semidefinite matrices (so
/// `-dF/dc` is semidefinite), then adds
/// `τ |H_ii|` to the diagonal of that (no other entry changes, no reassembly needed),
/// `τ` growing tenfold per call; a new point keeps the modification of a point where it
/// was raised, and steps back one stage towards the exact Hessian otherwise.
#[test]
fn raised_shift_projects_then_adds_to_the_diagonal() {
    let (disc, cps, _) = twisted(2, 4, 1.0);
    let mut prob = WinslowProblem::new(disc, cps);
    let c = prob.unknowns();
    let n = c.len();
    let (mut f, mut exact, mut proj, mut jac1) = (vec![0.0; n], Csr::default(), Csr::default(), Csr::default());
    prob.jacobian(&c, &mut f, &mut exact);
    assert!(prob.raise_shift() && prob.raise_shift() && prob.raise_shift());
    assert_eq!(prob.projected, 1.0);
    prob.jacobian(&c, &mut f, &mut proj);
    assert_eq!(prob.shift(), 0.0);
    let (de, dp) = (exact.to_dense(), proj.to_dense());
    assert!(
        de.iter().flatten().zip(dp.iter().flatten()).any(|(a, b)| (a - b).abs() > 1e-9),
        "a twisted map is not conformal"
    );
    let mut rng = crate::testutil::Lcg::new(5);
    for _ in 0..50 {
        let x: Vec<f64> = (0..n).map(|_| rng.uniform() - 0.5).collect();
        let q: f64 = (0..n).map(|i| x[i] * (0..n).map(|j| dp[i][j] * x[j]).sum::<f64>()).sum();
        assert!(q <= 1e-12 * n as f64, "-dF/dc projected is semidefinite: {q}");
    }
    assert!(prob.raise_shift() && prob.raise_shift());
    prob.jacobian(&c, &mut f, &mut jac1);
    let tau = prob.shift();
    assert!((tau - 10.0 * SHIFT_MIN).abs() < 1e-18, "{tau}");
    let d1 = jac1.to_dense();
    for i in 0..n {
        for j in 0..n {
            let expect = if i == j { dp[i][i] - tau * dp[i][i].abs() } else { dp[i][j] };
            assert!((d1[i][j] - expect).abs() <= 1e-14 * dp[i][i].abs(), "({i}, {j})");
        }
    }
    // a new point after one where the modification was raised: the same modification
    // (the stages that failed are not tried again) ...
    let mut c2 = c.clone();
    c2[0] += 1e-3;
    prob.jacobian(&c2, &mut f, &mut jac1);
    assert!(prob.shift() == tau && prob.projected == 1.0 && prob.modified());
    // ... then one step back towards the exact Hessian per new point, which comes back
    // after three
    c2[0] += 1e-3;
    prob.jacobian(&c2, &mut f, &mut jac1);
    assert!(prob.shift() < tau && prob.projected == 3.0 * PROJECTION_FIRST && prob.modified());
    for k in 0..2 {
        c2[0] += 1e-3;
        prob.jacobian(&c2, &mut f, &mut jac1);
        assert_eq!(prob.modified(), k == 0);
    }
    assert_eq!(prob.projected, 0.0);
    // a point that needed no raise passes nothing on
    assert!(prob.raise_shift());
    prob.jacobian(&c2, &mut f, &mut jac1);
    c2[0] += 1e-3;
    prob.jacobian(&c2, &mut f, &mut jac1);
    assert_eq!(prob.projected, PROJECTION_FIRST, "raised at the last point: kept");
    c2[0] += 1e-3;
    prob.jacobian(&c2, &mut f, &mut jac1);
    assert_eq!(prob.projected, 0.0, "not raised at the last point: one stage back");
}

/// The closed-form projection of the density Hessian equals the projection by Jacobi
/// rotations, at random gradients with `D > 0` (conformal ones included).
#[test]
fn closed_form_projection_matches_jacobi() {
    let mut rng = crate::testutil::Lcg::new(3);
    let mut points = vec![[1.0, -0.5, 0.5, 1.0], [2.0, 0.0, 0.0, 0.5], [0.3, 0.0, 0.0, 0.3]];
    while points.len() < 200 {
        let e: [f64; 4] = std::array::from_fn(|_| 4.0 * rng.uniform() - 2.0);
        if e[0] * e[3] - e[1] * e[2] > 1e-3 {
            points.push(e);
        }
    }
    for e in points {
        let (w, _, h) = winslow_density(e);
        let (a, b) = (projected_density_hessian(e), project_psd(h));
        let scale = h.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..4 {
            for j in 0..4 {
                assert!(
                    (a[i][j] - b[i][j]).abs() <= 1e-9 * scale,
                    "{e:?} (W = {w}): ({i}, {j}) {} vs {}",
                    a[i][j],
                    b[i][j]
                );
            }
        }
    }
}

/// The projection keeps a semidefinite matrix, and of an indefinite one keeps the
/// eigenvectors: `P` is semidefinite, `h - P` negative semidefinite, `P (h - P) = 0`.
#[test]
fn psd_projection_of_the_density_hessian() {
    let (_, _, conformal) = winslow_density([1.0, -0.5, 0.5, 1.0]);
    let p = project_psd(conformal);
    for i in 0..4 {
        for j in 0..4 {
            assert!((p[i][j] - conformal[i][j]).abs() < 1e-12, "a conformal point's Hessian is semidefinite");
        }
    }
    let (_, _, h) = winslow_density([1.3, 0.4, -0.2, 0.9]);
    let p = project_psd(h);
    let r: [[f64; 4]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| h[i][j] - p[i][j]));
    assert!(r.iter().flatten().any(|v| v.abs() > 1e-6), "this point's Hessian is indefinite");
    let mut rng = crate::testutil::Lcg::new(9);
    for _ in 0..200 {
        let x: [f64; 4] = std::array::from_fn(|_| rng.uniform() - 0.5);
        let quad = |m: &[[f64; 4]; 4]| (0..4).map(|i| x[i] * (0..4).map(|j| m[i][j] * x[j]).sum::<f64>()).sum::<f64>();
        assert!(quad(&p) >= -1e-12 && quad(&r) <= 1e-12);
    }
    for i in 0..4 {
        for j in 0..4 {
            let pr: f64 = (0..4).map(|k| p[i][k] * r[k][j]).sum();
            assert!(pr.abs() < 1e-10, "P (h - P) = 0: {pr}");
        }
    }
}

/// The one-pass value and gradient: the value is [`winslow_objective`]'s bit for bit (the
/// same quadrature, summed per element and then in order), the gradient
/// [`winslow_gradient`]'s to rounding, on a polynomial and a rational basis; a folded map
/// has the value `+∞`; and the problem's residual at the point of its last objective is
/// the gradient of that pass.
#[test]
fn value_and_gradient_in_one_pass() {
    let (disc, cps) = curved(7, 0.05);
    let n = disc.dofs.num_total();
    let weights: Vec<f64> = (0..n).map(|i| 1.0 + 0.3 * ((i * 7 % 11) as f64 / 11.0)).collect();
    let rational = Arc::new((*disc).clone().with_weights(Some(weights)).unwrap());
    for d in [&disc, &rational] {
        let (mut one, mut two) = (vec![0.0; 2 * n], vec![0.0; 2 * n]);
        let j = winslow_value_and_gradient(d, &cps, &mut one);
        assert_eq!(j.to_bits(), winslow_objective(d, &cps).to_bits());
        winslow_gradient(d, &cps, &mut two, &mut []);
        let scale = max_abs(two.iter().copied());
        assert!(max_abs(one.iter().zip(&two).map(|(a, b)| a - b)) <= 1e-13 * scale);
    }
    // a control point pulled across the map folds it
    let mut folded = cps.clone();
    let nx = disc.shape()[0];
    folded[nx + 1] = [folded[nx + 1][0] + 10.0, folded[nx + 1][1] - 10.0];
    assert_eq!(winslow_value_and_gradient(&disc, &folded, &mut vec![0.0; 2 * n]), f64::INFINITY);
    assert_eq!(winslow_objective(&disc, &folded), f64::INFINITY);
    // the residual after the objective is read from the pass
    let mut problem = WinslowProblem::new(disc.clone(), cps.clone());
    let c = problem.unknowns();
    let (mut cached, mut fresh) = (vec![0.0; c.len()], vec![0.0; c.len()]);
    problem.objective(&c);
    problem.residual(&c, &mut cached);
    let mut other = WinslowProblem::new(disc, cps);
    other.residual(&c, &mut fresh);
    let scale = max_abs(fresh.iter().copied());
    assert!(max_abs(cached.iter().zip(&fresh).map(|(a, b)| a - b)) <= 1e-13 * scale);
}
