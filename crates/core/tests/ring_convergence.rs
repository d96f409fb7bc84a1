//! The concentric annulus `r_in = 1 < r < r_out = 2` given as two circles, solved with a
//! periodic `eta` basis, converges to the closed-form EGG solution: the inverse map has
//! the harmonic components `xi = ln(r / r_in) / ln(r_out / r_in)`, `eta = θ / 2π`, so
//! `x(xi, eta) = r_in (r_out / r_in)^xi (cos 2π eta, sin 2π eta)` (paper eq. 2-4). The
//! error under uniform refinement decays at the spline order. And the shared ring test
//! cases (`tests/data/rings`) solve to certified maps.

use std::f64::consts::TAU;
use std::sync::Arc;

use winslow::boundary::ring::ClosedContour;
use winslow::boundary::ring_fit::fit_contour;
use winslow::boundary::Analytic;
use winslow::discrete::assembly::{Discretization, Operator};
use winslow::discrete::topology::Topology;
use winslow::methods::egg::{CpuAssembler, EggProblem};
use winslow::methods::DiscreteProblem;
use winslow::solve::initial::coons;
use winslow::solve::newton::{NonlinearOptions, NonlinearSolver, Status};
use winslow::spline::curve::Curve;
use winslow::spline::knots::KnotVector;
use winslow::spline::surface::Surface;

const R_IN: f64 = 1.0;
const R_OUT: f64 = 2.0;

fn exact(xi: f64, eta: f64) -> [f64; 2] {
    let r = R_IN * (R_OUT / R_IN).powf(xi);
    [r * (TAU * eta).cos(), r * (TAU * eta).sin()]
}

fn circle(r: f64) -> ClosedContour {
    ClosedContour::Analytic(Analytic::new(move |t| [r * (TAU * t).cos(), r * (TAU * t).sin()]))
}

/// Max error of the EGG solution on `ne` elements in `xi` and `4 ne` in `eta`, degree `p`.
fn error(p: usize, ne: usize) -> f64 {
    let kx = KnotVector::open_uniform(p, ne);
    let ky = KnotVector::periodic_uniform(p, 4 * ne);
    let (inner, _) = fit_contour(&circle(R_IN), &ky).unwrap();
    let (outer, _) = fit_contour(&circle(R_OUT), &ky).unwrap();
    let g = kx.greville();
    let line = Curve::polynomial(kx.clone(), g.iter().map(|&u| exact(u, 0.0)).collect());
    let sides = [line.clone(), outer, line, inner];
    let knots = [kx, ky];
    let cps = coons(&knots, &sides).unwrap();
    let disc = Arc::new(Discretization::for_topology(knots.clone(), &Topology::ring()).unwrap());
    let m = disc.dofs.num_free();
    let opts = NonlinearOptions { scale: (m as f64).sqrt() / 27.0, tol: 1e-13, ..Default::default() };
    let prob = EggProblem::new(disc, cps, Operator::Plain, Arc::new(CpuAssembler));
    let c0 = prob.unknowns();
    let mut s = NonlinearSolver::new(prob, c0, opts);
    for it in s.by_ref() {
        it.unwrap();
    }
    assert_eq!(s.status(), &Status::Converged, "p={p} ne={ne}");
    let (prob, c) = s.into_parts();
    let map = Surface::new(knots, prob.control_points(&c), None).unwrap();
    let mut err = 0.0f64;
    for i in 0..=40 {
        for j in 0..=160 {
            let (u, v) = (i as f64 / 40.0, j as f64 / 160.0);
            let (x, y) = (map.eval(u, v), exact(u, v));
            err = err.max((x[0] - y[0]).hypot(x[1] - y[1]));
        }
    }
    err
}

#[test]
fn concentric_annulus_converges_at_the_spline_order() {
    for p in [2, 3] {
        let errs: Vec<f64> = [2, 4, 8, 16].iter().map(|&ne| error(p, ne)).collect();
        let rates: Vec<f64> = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        let show = |v: &[f64], f: &dyn Fn(f64) -> String| v.iter().map(|&x| f(x)).collect::<Vec<_>>().join(" ");
        eprintln!(
            "p={p}: max errors {}, rates {}",
            show(&errs, &|x| format!("{x:.3e}")),
            show(&rates, &|x| format!("{x:.2}"))
        );
        // order p + 1 in the maximum norm (at least p + 0.7 on the finer pairs)
        assert!(rates[1..].iter().all(|&r| r > p as f64 + 0.7), "p={p}: {errs:?} {rates:?}");
        assert!(errs[3] < 1e-3);
    }
}

/// The male screw rotor inside its casing (G+Smo's `male_bdry2`, seam closed) and the
/// eccentric annulus: read as ring documents, fitted on one periodic vector, solved with
/// `eta` periodic, certified.
#[test]
fn shared_rings_solve_and_certify() {
    use winslow::solve::options::SolveOptions;
    use winslow::solve::report::Verdict;
    let dir = winslow::testutil::data("rings");
    for (name, fit_tol) in [("male_rotor_in_casing", 1e-3), ("eccentric_annulus", 1e-4)] {
        let winslow::Document::Ring(ring) = winslow::read(&dir.join(format!("{name}.json"))).unwrap() else {
            panic!("{name} is not a ring document")
        };
        let mut opts = SolveOptions::default();
        opts.fit.tol = fit_tol;
        let sol = winslow::Pipeline::new(ring, opts.clone()).solve().and_then(|s| s.into_map()).unwrap();
        assert_eq!(sol.report.outcome.verdict, Verdict::Certified, "{name}: {}", sol.report.outcome.message);
        let dev = sol.report.boundary.deviation;
        assert!(
            dev[1] < 2.0 * fit_tol * sol.report.fit.diameter && dev[3] < 2.0 * fit_tol * sol.report.fit.diameter,
            "{name}: {dev:?}"
        );
    }
}
