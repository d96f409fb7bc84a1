use super::*;
use crate::spline::knots::KnotVector;
use crate::testutil::Lcg;

/// The map `(ξ, η) -> A (ξ, η) + b` on a cubic basis with `ne` elements per direction
/// (Greville interpolation reproduces it), interior control points moved by up to
/// `noise / 2` of the element size.
fn affine(ne: usize, seed: u64, noise: f64) -> (Arc<Discretization>, Vec<Point>, Vec<Point>) {
    let k = KnotVector::open_uniform(3, ne);
    let g = k.greville();
    let exact: Vec<Point> =
        g.iter().flat_map(|&v| g.iter().map(move |&u| [2.0 * u + 0.5 * v + 1.0, -0.3 * u + 1.5 * v])).collect();
    let disc = Arc::new(Discretization::new([k.clone(), k]));
    let mut rng = Lcg::new(seed);
    let mut cps = exact.clone();
    for &kk in disc.dofs.free() {
        for d in 0..2 {
            cps[kk][d] += noise / ne as f64 * (rng.uniform() - 0.5);
        }
    }
    (disc, cps, exact)
}

fn surface(disc: &Discretization, cps: &[Point]) -> Surface {
    Surface::new(disc.knots.clone(), cps.to_vec(), None).unwrap()
}

fn distance(a: &[Point], b: &[Point]) -> f64 {
    a.iter().zip(b).fold(0.0f64, |m, (p, q)| m.max((p[0] - q[0]).abs()).max((p[1] - q[1]).abs()))
}

/// A folded start of a convex domain (a parallelogram, interior control points thrown
/// about by up to 1.5 element sizes): eq. (49) reaches `z > 0`, and the certificate
/// proves the map bijective.
#[test]
fn max_z_unfolds_a_folded_start_of_a_convex_domain() {
    let (disc, cps, _) = affine(4, 7, 3.0);
    let folded = certify(&surface(&disc, &cps), &CertifyOptions::default()).unwrap();
    assert!(matches!(folded.verdict, Finding::Folded { .. }), "{}", folded.message());
    let z = max_z(&disc, &cps, 0.0, &ConstrainedOptions::default()).unwrap();
    let r = &z.report;
    assert!(r.converged, "{}", r.why);
    assert!(r.z_history[0] < 0.0 && *r.z_history.last().unwrap() > 0.0, "{:?}", r.z_history);
    assert!(r.z_history.windows(2).all(|w| w[1] > w[0]), "z increases: {:?}", r.z_history);
    let cert = certify(&surface(&disc, &z.control_points), &CertifyOptions::default()).unwrap();
    assert!(matches!(cert.verdict, Finding::Certified { .. }), "{}", cert.message());
    // the boundary stays
    for &k in disc.dofs.free() {
        assert_eq!(disc.dofs.free_index(k), disc.dofs.free().iter().position(|&x| x == k).unwrap());
    }
    let moved = cps.iter().zip(&z.control_points).enumerate().filter(|(_, (a, b))| a != b).map(|(k, _)| k);
    assert!(moved.into_iter().all(|k| disc.dofs.free().contains(&k)));
}

/// On an affine boundary the affine map minimises Liao, area orthogonality and Winslow
/// (interior `∫ ∇w_i = 0`), and satisfies `d = det J > ε`: the constrained optimisation
/// returns it, from a perturbed feasible start and from a folded one (restored first).
#[test]
fn constrained_optimisation_returns_the_affine_map() {
    let opts = ConstrainedOptions { tol: 1e-14, ..Default::default() };
    for f in [Functional::Liao, Functional::AreaOrthogonality, Functional::Winslow] {
        for noise in [0.3, 3.0] {
            let (disc, cps, exact) = affine(4, 3, noise);
            let o = optimise(&disc, &cps, f, &opts).unwrap();
            let r = &o.report;
            assert!(r.converged, "{f:?} noise {noise}: {}", r.why);
            assert_eq!(r.restoration.is_some(), noise > 1.0, "{f:?} noise {noise}");
            assert!(r.objective_history.windows(2).all(|w| w[1] <= w[0]), "{:?}", r.objective_history);
            let err = distance(&o.control_points, &exact);
            assert!(err < 1e-6, "{f:?} noise {noise}: distance to the affine map {err} ({} iterations)", r.iterations);
            assert!(r.iterations < 40, "{f:?}: {} iterations", r.iterations);
        }
    }
}

/// A boundary whose corner angle is 180 degrees fixes `det J = 0` there: no map has
/// positive coefficients, and max-z says so instead of iterating.
#[test]
fn a_straight_corner_is_reported() {
    let (disc, mut cps, _) = affine(3, 1, 0.1);
    // move the south side's second control point onto the line through the west side
    let nx = disc.shape()[0];
    let (c0, cw) = (cps[0], cps[nx]);
    cps[1] = [c0[0] - (cw[0] - c0[0]), c0[1] - (cw[1] - c0[1])];
    let z = max_z(&disc, &cps, 0.0, &ConstrainedOptions::default()).unwrap();
    assert!(!z.report.converged);
    assert!(z.report.why.contains("corner"), "{}", z.report.why);
}

/// [`run`] from G (the map itself) and from Z (Coons patch, then max-z) on a curved
/// domain: both certified, both converge.
#[test]
fn run_from_both_starts_is_certified() {
    let k = KnotVector::open_uniform(3, 4);
    let g = k.greville();
    // a quarter annulus (convex in the angle, curved sides), bijective polar map
    let map_cps: Vec<Point> = g
        .iter()
        .flat_map(|&v| {
            g.iter().map(move |&u| {
                let (r, t) = (1.0 + u, 1.4 * v);
                [r * t.cos(), r * t.sin()]
            })
        })
        .collect();
    let map = Surface::new([k.clone(), k], map_cps, None).unwrap();
    for from in [StartFrom::Egg, StartFrom::MaxZ] {
        let o = run(&map, from, Functional::Liao, &Topology::dirichlet(), &ConstrainedOptions::default()).unwrap();
        assert!(o.certified, "{from:?}: {}", o.certificate.message());
        assert!(o.converged, "{from:?}: {}", o.why);
        assert_eq!(o.max_z.is_some(), from == StartFrom::MaxZ);
    }
    let z = run_max_z(&map, &Topology::dirichlet(), &ConstrainedOptions::default()).unwrap();
    assert!(z.certified && z.converged, "{}", z.why);
}

/// Where the constraints are active (Liao on a quarter annulus folds without them), the
/// QP with the Lagrangian's Hessian and the default one reach the same constrained
/// minimiser, both certified, with `d >= ε` met.
#[test]
fn both_qp_hessians_reach_the_same_constrained_minimiser() {
    let k = KnotVector::open_uniform(3, 8);
    let g = k.greville();
    let cps: Vec<Point> = g
        .iter()
        .flat_map(|&v| {
            g.iter().map(move |&u| {
                let (r, t) = (1.0 + u, std::f64::consts::FRAC_PI_2 * v);
                [r * t.cos(), r * t.sin()]
            })
        })
        .collect();
    let disc = Arc::new(Discretization::new([k.clone(), k]));
    let mut values = Vec::new();
    for lagrangian_hessian in [false, true] {
        let opts = ConstrainedOptions { lagrangian_hessian, ..Default::default() };
        let o = optimise(&disc, &cps, Functional::Liao, &opts).unwrap();
        let r = &o.report;
        assert!(r.converged, "lagrangian {lagrangian_hessian}: {}", r.why);
        assert!((r.min_coefficient - opts.eps).abs() < 1e-6, "active: {}", r.min_coefficient);
        let cert = certify(&surface(&disc, &o.control_points), &CertifyOptions::default()).unwrap();
        assert!(matches!(cert.verdict, Finding::Certified { .. }), "{}", cert.message());
        values.push(*r.objective_history.last().unwrap());
    }
    assert!((values[0] - values[1]).abs() < 1e-7 * values[0], "{values:?}");
}
