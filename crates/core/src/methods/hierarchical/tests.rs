//! The THB assembly against mathematics: exact reproduction of the tensor assembly on a
//! one-level basis and after uniform refinement, finite differences of the EGG
//! Jacobian and of the Winslow gradient and Hessian on a locally refined basis, and
//! Newton to the affine map (which solves eq. 8 and minimizes eq. 16).
use super::*;
use crate::discrete::assembly::Discretization;
use crate::linalg::linsolve::LinearMethod;
use crate::methods::density::tests::{affine, curved, problem_fd};
use crate::methods::jacobian_fd_mismatch;
use crate::methods::winslow::{winslow_gradient, winslow_objective};
use crate::solve::newton::{NonlinearOptions, NonlinearSolver, Status};
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::surface::Surface;

fn thb_of(disc: &Discretization, cps: &[Point]) -> HierarchicalMap {
    let s = Surface::new(disc.knots.clone(), cps.to_vec(), None).unwrap();
    HierarchicalMap::from_surface(&s).unwrap()
}

fn rel(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

/// A tensor map written as a one-level THB map has the tensor EGG residual and
/// Jacobian (both operators), Winslow value, gradient and Hessian, to rounding.
#[test]
fn one_level_reproduces_the_tensor_assembly() {
    let (disc, cps) = curved(3, 2, 7, 0.05);
    let map = thb_of(&disc, &cps);
    let hd = Arc::new(HierarchicalDiscretization::new(map.basis.clone()));
    assert_eq!(hd.num_free(), disc.dofs.num_free());
    assert_eq!(hd.free(), disc.dofs.free());
    let n = cps.len();
    for op in [Operator::Plain, Operator::Scaled] {
        let mut res = vec![0.0; 2 * n];
        let mut st = vec![0.0; disc.stencil_len(2)];
        disc.egg(&cps, op, &mut res, &mut st);
        let tensor_jac = disc.vector.matrix(&st).to_dense();
        let mut hres = vec![0.0; 2 * n];
        let mut vals = hd.vector.clone();
        hierarchical_egg(&hd, &cps, op, &mut hres, &mut vals.values);
        assert!(rel(&hres, &res) < 1e-13, "{op:?} residual {}", rel(&hres, &res));
        let hj = vals.to_dense();
        let (a, b): (Vec<f64>, Vec<f64>) = (hj.concat(), tensor_jac.concat());
        assert!(rel(&a, &b) < 1e-13, "{op:?} Jacobian {}", rel(&a, &b));
    }
    let (j, hj) = (winslow_objective(&disc, &cps), hierarchical_winslow_objective(&hd, &cps));
    assert!(j.is_finite() && ((j - hj) / j).abs() < 1e-14, "{j} {hj}");
    let mut res = vec![0.0; 2 * n];
    let mut st = vec![0.0; disc.stencil_len(2)];
    winslow_gradient(&disc, &cps, &mut res, &mut st);
    let tensor_hess = disc.vector.matrix(&st).to_dense().concat();
    let mut hres = vec![0.0; 2 * n];
    let mut vals = hd.vector.clone();
    hierarchical_winslow_gradient(&hd, &cps, 0.0, &mut hres, &mut vals.values);
    assert!(rel(&disc.restrict(&hres, 2), &disc.restrict(&res, 2)) < 1e-13);
    assert!(rel(&vals.to_dense().concat(), &tensor_hess) < 1e-13);
}

/// Refining every cell of a one-level THB map gives the tensor map on the halved knots
/// (prolongation exact): the same Winslow value and EGG residual as that tensor map on
/// its tensor discretization.
#[test]
fn uniform_refinement_reproduces_the_halved_tensor_map() {
    let (disc, cps) = curved(2, 3, 3, 0.04);
    let map = thb_of(&disc, &cps);
    let [nx, ny] = map.basis.cell_shape(0);
    let all: Vec<_> = (0..ny).flat_map(|j| (0..nx).map(move |i| (0, [i, j]))).collect();
    let fine = map.refined(&all, 2).unwrap();
    let tensor = fine.to_surface().unwrap();
    // the refined THB basis is the level-1 tensor basis, in the same order
    assert_eq!(tensor.control_points.len(), fine.control_points.len());
    for (a, b) in tensor.control_points.iter().zip(&fine.control_points) {
        assert!((a[0] - b[0]).abs() < 1e-13 && (a[1] - b[1]).abs() < 1e-13);
    }
    let tensor = Surface::new(tensor.knots.clone(), fine.control_points.clone(), None).unwrap();
    let td = Discretization::new(tensor.knots.clone());
    let hd = HierarchicalDiscretization::new(fine.basis.clone());
    let (j, hj) =
        (winslow_objective(&td, &tensor.control_points), hierarchical_winslow_objective(&hd, &fine.control_points));
    assert!(((j - hj) / j).abs() < 1e-14, "{j} {hj}");
    let n = tensor.control_points.len();
    let mut res = vec![0.0; 2 * n];
    td.egg(&tensor.control_points, Operator::Scaled, &mut res, &mut []);
    let mut hres = vec![0.0; 2 * n];
    hierarchical_egg(&hd, &fine.control_points, Operator::Scaled, &mut hres, &mut []);
    assert!(rel(&hres, &res) < 1e-13, "{}", rel(&hres, &res));
}

/// A curved map on a THB basis with three levels (truncated functions on every kind
/// of cell).
fn locally_refined(noise: f64) -> (Arc<HierarchicalDiscretization>, Vec<Point>) {
    let (disc, cps) = curved(3, 3, 11, 0.0);
    let map = thb_of(&disc, &cps).refined(&[(0, [1, 1]), (0, [2, 1])], 2).unwrap();
    let mut map = map.refined(&[(1, [3, 3]), (1, [2, 2])], 2).unwrap();
    assert!(map.basis.num_levels() == 3);
    let hd = Arc::new(HierarchicalDiscretization::new(map.basis.clone()));
    let mut rng = crate::testutil::Lcg::new(5);
    for &k in hd.free() {
        for d in 0..2 {
            map.control_points[k][d] += noise * (rng.uniform() - 0.5);
        }
    }
    (hd, map.control_points)
}

/// The EGG Jacobian on a locally refined THB basis against central differences of the
/// residual (both operators).
#[test]
fn egg_jacobian_matches_finite_differences() {
    let (hd, cps) = locally_refined(0.03);
    for op in [Operator::Plain, Operator::Scaled] {
        let mut prob = HierarchicalEggProblem::new(hd.clone(), cps.clone(), op);
        let c = prob.unknowns();
        let (err, scale) = jacobian_fd_mismatch(&mut prob, &c, 1e-6);
        assert!(err < 1e-6 * scale, "{op:?}: {err} vs {scale}");
    }
}

/// `F = -∇J` against central differences of the Winslow functional, `dF/dc = -∇²J`
/// against central differences of `F`, on a locally refined THB basis.
#[test]
fn winslow_derivatives_match_finite_differences() {
    let (hd, cps) = locally_refined(0.03);
    let mut prob = HierarchicalWinslowProblem::new(hd, cps);
    let c = prob.unknowns();
    assert!(prob.objective(&c).unwrap().is_finite());
    let (eg, eh) = problem_fd(&mut prob, &c, 1e-6);
    assert!(eg < 1e-7 && eh < 1e-6, "{eg} {eh}");
}

/// The affine map solves eq. (8) and minimizes eq. (16) (`∇x` constant, `L(x) = 0`, and
/// `W` convex along the affine maps): from a perturbed interior on a refined THB basis
/// Newton returns to it, for EGG and for Winslow.
#[test]
fn newton_recovers_the_affine_map_on_a_thb_basis() {
    let (disc, _, exact) = affine(3, 4, 1, 0.0);
    let map = thb_of(&disc, &exact).refined(&[(0, [1, 2]), (0, [2, 2])], 2).unwrap();
    let map = map.refined(&[(1, [3, 4])], 2).unwrap();
    let hd = Arc::new(HierarchicalDiscretization::new(map.basis.clone()));
    let mut cps = map.control_points.clone();
    let mut rng = crate::testutil::Lcg::new(9);
    for &k in hd.free() {
        for d in 0..2 {
            cps[k][d] += 0.05 * (rng.uniform() - 0.5);
        }
    }
    let opts = NonlinearOptions { fallback: false, linear: LinearMethod::Lu, ..Default::default() };
    let egg: Box<dyn DiscreteProblem + Send> =
        Box::new(HierarchicalEggProblem::new(hd.clone(), cps.clone(), Operator::Scaled));
    let win: Box<dyn DiscreteProblem + Send> = Box::new(HierarchicalWinslowProblem::new(hd.clone(), cps.clone()));
    for prob in [egg, win] {
        let c0 = hd.gather(&cps);
        let mut s = NonlinearSolver::new(prob, c0, NonlinearOptions { scale: 1.0, ..opts });
        for it in s.by_ref() {
            it.unwrap();
        }
        assert_eq!(s.status(), &Status::Converged);
        let (prob, c) = s.into_parts();
        let got = prob.control_points(&c);
        let err = got
            .iter()
            .zip(&map.control_points)
            .fold(0.0f64, |m, (a, b)| m.max((a[0] - b[0]).abs()).max((a[1] - b[1]).abs()));
        assert!(err < 1e-9, "{err}");
    }
}

/// On a one-level basis the THB metric Laplacian `K` (the preconditioner of the Newton
/// systems) is the tensor one, both operators, with and without the mass shift.
#[test]
fn one_level_metric_laplace_is_the_tensor_one() {
    let (disc, cps) = curved(3, 2, 7, 0.05);
    let hd = HierarchicalDiscretization::new(thb_of(&disc, &cps).basis);
    for op in [Operator::Plain, Operator::Scaled] {
        for shift in [0.0, 0.7] {
            let mut st = vec![0.0; disc.stencil_len(1)];
            disc.metric_laplace(&cps, op, shift, &mut st);
            let tensor = disc.scalar.matrix(&st).to_dense().concat();
            let mut k = hd.scalar.clone();
            hierarchical_metric_laplace(&hd, &cps, op, shift, &mut k.values);
            let thb = k.to_dense().concat();
            assert!(rel(&thb, &tensor) < 1e-13, "{op:?} {shift}: {}", rel(&thb, &tensor));
        }
    }
}

/// At an affine map (constant metric, zero second derivatives) the EGG Jacobian is
/// `-diag(K, K)` by integration by parts (the test functions vanish on the boundary and
/// are `C^1` across the cells of every level): on a three-level THB basis the
/// preconditioner the problem gives equals the negated Jacobian up to the `1e-10 tr A`
/// that keeps `K` definite, for both operators.
#[test]
fn at_an_affine_map_the_egg_jacobian_is_minus_the_metric_laplacian() {
    let (disc, _, exact) = affine(3, 4, 1, 0.0);
    let map = thb_of(&disc, &exact).refined(&[(0, [1, 2]), (0, [2, 2])], 2).unwrap();
    let map = map.refined(&[(1, [3, 4])], 2).unwrap();
    assert_eq!(map.basis.num_levels(), 3);
    let hd = Arc::new(HierarchicalDiscretization::new(map.basis.clone()));
    let m = hd.num_free();
    for op in [Operator::Plain, Operator::Scaled] {
        let mut prob = HierarchicalEggProblem::new(hd.clone(), map.control_points.clone(), op);
        let c = prob.unknowns();
        let mut f = vec![0.0; 2 * m];
        let mut jac = Csr::default();
        prob.jacobian(&c, &mut f, &mut jac);
        let j = jac.to_dense();
        let k = prob.preconditioner(0.0).unwrap().to_dense();
        let scale = k.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
        let mut err = 0.0f64;
        for r in 0..2 * m {
            for s in 0..2 * m {
                let want = if r / m == s / m { -k[r % m][s % m] } else { 0.0 };
                err = err.max((j[r][s] - want).abs());
            }
        }
        assert!(err < 1e-8 * scale, "{op:?}: {err} vs {scale}");
        // and K is symmetric positive definite: its Cholesky factorization succeeds
        let mut lin = crate::linalg::linsolve::LinearSolver::new(LinearMethod::Cholesky);
        lin.factor(prob.preconditioner(0.0).unwrap()).unwrap();
    }
}
