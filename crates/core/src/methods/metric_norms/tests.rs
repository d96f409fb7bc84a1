use super::*;
use crate::discrete::dofs::DofMap;
use crate::methods::density::tests::{annulus_points, problem_fd};
use crate::solve::newton::{NonlinearOptions, NonlinearSolver, Status};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Surface;
use crate::testutil::Lcg;

const NORMS: [MetricNorm; 2] = [MetricNorm::Liao, MetricNorm::AreaOrthogonality];

/// A curved map (perturbed annulus sector) on a `(3, 2)` basis with `p + 2` Gauss points.
fn curved(seed: u64, noise: f64) -> (Arc<Discretization>, Vec<Point>) {
    let kx = KnotVector::open_uniform(3, 3);
    let ky = KnotVector::open_uniform(2, 3).with_inserted(&[0.3]);
    let cps = annulus_points(&kx, &ky, seed, noise);
    let dofs = DofMap::interior([kx.num_basis(), ky.num_basis()]);
    (Arc::new(Discretization::with_dofs([kx, ky], 5, dofs)), cps)
}

#[test]
fn density_derivatives_match_finite_differences() {
    for norm in NORMS {
        let e = [1.3, 0.4, -0.2, 0.9];
        let (w, g, h) = metric_density(norm, e);
        let (g11, g22, g12) = (1.69 + 0.04, 0.16 + 0.81, 0.52 - 0.18);
        let expect = g11 * g11 + g22 * g22 + if norm == MetricNorm::Liao { 2.0 * g12 * g12 } else { 0.0 };
        assert!((w - expect).abs() < 1e-14);
        let step = 1e-6;
        for i in 0..4 {
            let (mut ep, mut em) = (e, e);
            ep[i] += step;
            em[i] -= step;
            let (wp, gp, _) = metric_density(norm, ep);
            let (wm, gm, _) = metric_density(norm, em);
            assert!(((wp - wm) / (2.0 * step) - g[i]).abs() < 1e-8, "{norm:?} gradient {i}");
            for j in 0..4 {
                assert!(((gp[j] - gm[j]) / (2.0 * step) - h[j][i]).abs() < 1e-8, "{norm:?} Hessian ({j}, {i})");
                assert!((h[i][j] - h[j][i]).abs() < 1e-14);
            }
        }
    }
}

/// `F = -∇J` against central differences of the objective, `dF/dc = -∇²J` against
/// central differences of `F`; the objective is the report's functional (which takes
/// `q + 2 = 4` Gauss points in `η`, not exact for this degree-8 integrand: close, not equal).
#[test]
fn gradient_and_hessian_match_finite_differences() {
    for norm in NORMS {
        let (disc, cps) = curved(3, 0.1);
        let map = Surface::new(disc.knots.clone(), cps.clone(), None).unwrap();
        let mut prob = MetricNormProblem::new(norm, disc, cps);
        let c = prob.unknowns();
        let j0 = prob.objective(&c).unwrap();
        let q = crate::verify::quality::functionals(&map);
        let report = if norm == MetricNorm::Liao { q.liao } else { q.area_orthogonality };
        assert!((j0 - report).abs() < 1e-5 * report, "{norm:?}: {j0} vs {report}");
        let (err_g, err_h) = problem_fd(&mut prob, &c, 1e-6);
        assert!(err_g < 1e-7, "{norm:?} gradient: relative {err_g}");
        assert!(err_h < 1e-7, "{norm:?} Hessian: relative {err_h}");
    }
}

/// With an affine boundary the affine map is the minimizer (`∫ ∇w_i = 0` for interior
/// `w_i`, and `J` is convex): Newton from a perturbed interior returns it.
#[test]
fn minimiser_of_an_affine_boundary_is_the_affine_map() {
    for norm in NORMS {
        let k = KnotVector::open_uniform(3, 4);
        let g = k.greville();
        let exact: Vec<Point> =
            g.iter().flat_map(|&v| g.iter().map(move |&u| [2.0 * u + 0.5 * v + 1.0, -0.3 * u + 1.5 * v])).collect();
        let disc = Arc::new(Discretization::new([k.clone(), k]));
        let mut rng = Lcg::new(5);
        let mut cps = exact.clone();
        for &kk in disc.dofs.free() {
            for d in 0..2 {
                cps[kk][d] += 0.05 * (rng.uniform() - 0.5);
            }
        }
        let prob = MetricNormProblem::new(norm, disc.clone(), cps);
        let c0 = prob.unknowns();
        let m = disc.dofs.num_free();
        let method = MetricNormMethod(norm);
        let opts = NonlinearOptions { scale: method.residual_scale(2.5, m), fallback: false, ..Default::default() };
        let mut s = NonlinearSolver::new(prob, c0, opts);
        for it in s.by_ref() {
            it.unwrap();
        }
        assert_eq!(s.status(), &Status::Converged, "{norm:?}");
        let (prob, c) = s.into_parts();
        let err = prob
            .control_points(&c)
            .iter()
            .zip(&exact)
            .fold(0.0f64, |m, (a, b)| m.max((a[0] - b[0]).abs()).max((a[1] - b[1]).abs()));
        assert!(err < 1e-9, "{norm:?}: distance to the affine map {err}");
    }
}
