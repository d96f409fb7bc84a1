use super::rounding_tests::perturbed;
use super::*;
use crate::spline::knots::KnotVector;
use crate::testutil::Lcg;

fn dense_min(map: &Surface, n: usize) -> f64 {
    crate::verify::quality::sample_det_j(map, n).min
}

#[test]
fn bernstein_det_j_equals_det_j() {
    let mut rng = Lcg::new(11);
    for (p, q) in [(2, 2), (3, 2), (2, 4), (3, 3)] {
        for rational in [false, true] {
            let map = perturbed(&mut rng, p, q, [3, 2], 0.8, rational);
            let dj = Elements::surface(&map).unwrap();
            let mut tmp = vec![0.0; dj.deg.len()];
            let mut c = vec![0.0; dj.deg.len()];
            for j in 0..2 {
                for i in 0..3 {
                    let (sc, nets) = dj.coefficients([i, j], &mut c);
                    let [bu, bv] = dj.bounds([i, j]);
                    for _ in 0..10 {
                        let (s, t) = (rng.uniform(), rng.uniform());
                        let (u, v) = (bu[0] + s * (bu[1] - bu[0]), bv[0] + t * (bv[1] - bv[0]));
                        let exact = map.derivs(u, v, 1).det_j();
                        let st = [[1.0 - s, s], [1.0 - t, t]];
                        let mut val = sc.factor * bernstein::eval(&c, dj.deg, st, &mut tmp);
                        if rational {
                            let wt = bernstein::eval(&nets.h[2].c, bernstein::Deg([p, q]), st, &mut tmp);
                            val /= wt.powi(3);
                        }
                        assert!(
                            (val - exact).abs() < 1e-11 * (1.0 + exact.abs()),
                            "p={p} q={q} r={rational}: {val} vs {exact}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn certificate_agrees_with_dense_sampling_on_smooth_maps() {
    // smooth, mildly distorted maps: always positive, and the bound is below the sample
    let mut rng = Lcg::new(3);
    for (p, q) in [(2, 2), (3, 3), (4, 2)] {
        for rational in [false, true] {
            for _ in 0..10 {
                let map = perturbed(&mut rng, p, q, [4, 5], 0.1, rational);
                let c = certify(&map, &CertifyOptions::default()).unwrap();
                let m = dense_min(&map, 200);
                assert!(m > 0.0);
                match c.verdict {
                    Finding::Certified { lower_bound, relative } => {
                        assert!(lower_bound > 0.0 && lower_bound <= m * (1.0 + 1e-12), "{lower_bound} vs {m}");
                        assert!((relative - lower_bound / c.mean_det_j).abs() < 1e-12);
                    }
                    v => panic!("p={p} q={q}: {v:?}"),
                }
                // area = 1 up to the perturbation of the boundary
                assert!((c.mean_det_j - crate::verify::quality::functionals(&map).area).abs() < 1e-10);
            }
        }
    }
}

#[test]
fn planted_folds_are_found_and_located() {
    let mut rng = Lcg::new(9);
    for (p, q) in [(2, 2), (3, 3), (2, 3)] {
        for rational in [false, true] {
            for _ in 0..20 {
                let ne = [6, 6];
                let mut map = perturbed(&mut rng, p, q, ne, 0.0, rational);
                let [nx, ny] = map.shape();
                // push an interior control point across its neighbour in xi
                let (i, j) = (2 + rng.below(nx - 4), 2 + rng.below(ny - 4));
                let k = j * nx + i;
                let next = map.control_points[k + 1];
                let prev = map.control_points[k - 1];
                let dx = next[0] - prev[0];
                map.control_points[k][0] = next[0] + (3.0 + rng.uniform()) * dx;
                let c = certify(&map, &CertifyOptions::default()).unwrap();
                let Finding::Folded { param, value, point, .. } = c.verdict.clone() else {
                    panic!("planted fold missed: {:?}", c.verdict)
                };
                assert!(value < 0.0);
                assert!(map.derivs(param[0], param[1], 1).det_j() <= 0.0);
                let x = map.eval(param[0], param[1]);
                assert!((x[0] - point[0]).abs() < 1e-12 && (x[1] - point[1]).abs() < 1e-12);
                // inside the support of the moved function
                let (kx, ky) = (&map.knots[0], &map.knots[1]);
                let sx = (kx.knots()[i], kx.knots()[i + p + 1]);
                let sy = (ky.knots()[j], ky.knots()[j + q + 1]);
                assert!(param[0] >= sx.0 && param[0] <= sx.1 && param[1] >= sy.0 && param[1] <= sy.1, "{param:?}");
                assert!(!c.offending_elements().is_empty());
                assert!(c.folds.iter().all(|f| map.derivs(f.param[0], f.param[1], 1).det_j() <= 0.0));
            }
        }
    }
}

/// At least 10^4 randomly perturbed maps: a `certified` verdict is never wrong (checked
/// against a dense sample and an exact branch-and-bound minimum on the Bernstein form),
/// a `folded` one always names a point where `det J <= 0`.
#[test]
fn certified_is_never_wrong_on_random_maps() {
    let mut rng = Lcg::new(2024);
    let (mut certified, mut folded, mut undecided) = (0, 0, 0);
    let opts = CertifyOptions { excuse_corners: false, ..Default::default() };
    for k in 0..10_000 {
        let (p, q) = [(2, 2), (3, 3), (2, 3), (3, 2)][k % 4];
        let amp = 0.2 + 1.2 * rng.uniform();
        let map = perturbed(&mut rng, p, q, [3, 3], amp, false);
        let c = certify(&map, &opts).unwrap();
        match c.verdict {
            Finding::Certified { lower_bound, .. } => {
                certified += 1;
                let (lo, hi) = det_j_min_bounds(&map, 1e-9, 20_000).unwrap();
                assert!(hi > 0.0, "map {k}: certified but det J = {hi} somewhere");
                assert!(lower_bound <= hi + 1e-12, "map {k}: bound {lower_bound} above a value {hi}");
                assert!(lo > -1e-9);
                assert!(dense_min(&map, 24) > 0.0, "map {k}");
            }
            Finding::Folded { param, .. } => {
                folded += 1;
                let v = map.derivs(param[0], param[1], 1).det_j();
                assert!(v <= 1e-13, "map {k}: folded at a positive value {v}");
            }
            Finding::Undecided { .. } => undecided += 1,
            Finding::DegenerateCorner { .. } => unreachable!("no forced corners in this test"),
        }
    }
    assert!(certified > 2000 && folded > 2000, "certified {certified} folded {folded} undecided {undecided}");
    assert!(undecided < 50, "undecided {undecided}");
}

/// The same for rational maps (random weights): the numerator `N` of `det J = N / W^3`
/// is certified; a `certified` verdict is checked against a dense sample and the
/// branch-and-bound minimum of `N` (same sign as `det J`).
#[test]
fn certified_is_never_wrong_on_random_rational_maps() {
    let mut rng = Lcg::new(77);
    let (mut certified, mut folded) = (0, 0);
    let opts = CertifyOptions { excuse_corners: false, ..Default::default() };
    for k in 0..3000 {
        let (p, q) = [(2, 2), (3, 2)][k % 2];
        let amp = 0.2 + 1.2 * rng.uniform();
        let map = perturbed(&mut rng, p, q, [3, 3], amp, true);
        let c = certify(&map, &opts).unwrap();
        match c.verdict {
            Finding::Certified { lower_bound, .. } => {
                certified += 1;
                let (_, hi) = det_j_min_bounds(&map, 1e-9, 20_000).unwrap();
                assert!(hi > 0.0, "map {k}: certified but the numerator is {hi} somewhere");
                let m = dense_min(&map, 24);
                assert!(m > 0.0 && lower_bound <= m * (1.0 + 1e-12), "map {k}: bound {lower_bound}, sample {m}");
            }
            Finding::Folded { param, .. } => {
                folded += 1;
                assert!(map.derivs(param[0], param[1], 1).det_j() <= 1e-13, "map {k}");
            }
            _ => {}
        }
    }
    assert!(certified > 500 && folded > 500, "certified {certified} folded {folded}");
}

/// A map whose south-west corner has an angle of exactly 180 degrees: `det J = 0`
/// there, positive elsewhere; it is a degenerate corner, not a fold.
#[test]
fn straight_corner_is_degenerate_not_folded() {
    // half-disk-like: x(xi, eta) built from a polar-ish polynomial map
    // x = (1 - eta) * (2 xi - 1)... use the map (u, v) -> (u^2 - v^2 ... ) instead:
    // the conformal map z -> z^2 turns the right angle at 0 into 180 degrees.
    let p = 4;
    let kx = KnotVector::open_uniform(p, 4);
    let ky = KnotVector::open_uniform(p, 4);
    // interpolate f(u, v) = ((u+0.0)^2 - v^2, 2 u v) exactly: it is a polynomial of
    // degree 2, so its B-spline coefficients come from the quasi-interpolant on a
    // single Bezier patch refined to the knots
    let bez = KnotVector::open_uniform(2, 1);
    let sq = |u: f64, v: f64| [u * u - v * v + 2.0 * u, 2.0 * u * v + 2.0 * v];
    // Bernstein coefficients of u, u^2 on [0, 1]: [0, 1/2, 1], [0, 0, 1]
    let b1 = [0.0, 0.5, 1.0];
    let b2 = [0.0, 0.0, 1.0];
    let mut cps = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            let (u, u2, v, v2, uv) = (b1[i], b2[i], b1[j], b2[j], b1[i] * b1[j]);
            cps.push([u2 - v2 + 2.0 * u, 2.0 * uv + 2.0 * v]);
        }
    }
    let _ = sq;
    let coarse = Surface::new([bez.clone(), bez], cps, None).unwrap();
    let fine = coarse.elevated().unwrap().elevated().unwrap().refined(&[kx, ky]).unwrap();
    for (u, v) in [(0.3, 0.7), (0.9, 0.1)] {
        let (a, b) = (coarse.eval(u, v), fine.eval(u, v));
        assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12);
    }
    // w = z^2 + 2 z: w' = 2 z + 2 vanishes at z = -1, outside; corner angles 90 degrees
    let c = certify(&fine, &CertifyOptions::default()).unwrap();
    assert!(matches!(c.verdict, Finding::Certified { .. }), "{:?}", c.verdict);
    // (u, v) -> (u - v, u^2 + v^2): injective, det J = 2 (u + v), zero at the
    // south-west corner, where the sides' tangents (1, 0) and (-1, 0) make 180 degrees
    let mut cps = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            cps.push([b1[i] - b1[j], b2[i] + b2[j]]);
        }
    }
    let bez = KnotVector::open_uniform(2, 1);
    let coarse = Surface::new([bez.clone(), bez], cps, None).unwrap();
    let fine = coarse.refined(&[KnotVector::open_uniform(2, 5), KnotVector::open_uniform(2, 5)]).unwrap();
    let c = certify(&fine, &CertifyOptions::default()).unwrap();
    assert!((c.corners[0].angle_degrees - 180.0).abs() < 1e-9, "{:?}", c.corners[0]);
    assert!(c.corners[0].forbids_positivity && c.corners[0].det_j.abs() < 1e-12);
    match &c.verdict {
        Finding::DegenerateCorner { corners, lower_bound, .. } => {
            assert_eq!(corners, &vec!["south-west"]);
            assert!(*lower_bound > 0.0);
        }
        v => panic!("{v:?}"),
    }
    // the excused neighbourhood is the corner box of the deepest level
    let ext = c.corners[0].excused_extent.expect("neighbourhood reported");
    let h = 1.0 / 5.0 / 2f64.powi(CertifyOptions::default().max_depth as i32);
    assert!((ext[0] - h).abs() < 1e-15 && (ext[1] - h).abs() < 1e-15, "{ext:?}");
    assert!(c.corners[1..].iter().all(|c| c.excused_extent.is_none() && !c.forbids_positivity));
    // without the corner exemption: det J = 0 at a point is neither provably positive nor
    // a fold (a fold needs a value below minus its rounding bound)
    let strict = CertifyOptions { excuse_corners: false, ..Default::default() };
    let c = certify(&fine, &strict).unwrap();
    match &c.verdict {
        Finding::Undecided { elements } => assert_eq!(elements, &vec![[0, 0]]),
        v => panic!("{v:?}"),
    }
}

/// A positive map whose proof needs bisections is `undecided` when the budget forbids
/// them, naming the elements left open; the defect correction would refine those.
#[test]
fn spent_budget_is_undecided() {
    let mut rng = Lcg::new(31);
    let found = (0..2000).find_map(|_| {
        let amp = 0.4 + 0.8 * rng.uniform();
        let map = perturbed(&mut rng, 3, 3, [3, 3], amp, false);
        let c = certify(&map, &CertifyOptions { excuse_corners: false, ..Default::default() }).unwrap();
        (matches!(c.verdict, Finding::Certified { .. }) && c.max_depth >= 2).then_some((map, c))
    });
    let (map, full) = found.expect("a map that needs two bisections");
    let c = certify(&map, &CertifyOptions { excuse_corners: false, max_depth: 1, ..Default::default() }).unwrap();
    let Finding::Undecided { elements } = &c.verdict else { panic!("{:?}", c.verdict) };
    assert!(!elements.is_empty() && elements.len() < c.elements);
    assert_eq!(&c.offending_elements(), elements);
    assert!(c.folds.is_empty());
    // the full certificate's bound is below every exact value the truncated one met
    let Finding::Certified { lower_bound, .. } = full.verdict else { unreachable!() };
    assert!(lower_bound <= c.min_value_found);
}

/// A ring `r = r0 + (1 - r0) xi`, `θ = 2π eta` on a periodic `eta` basis, perturbed by
/// `amp` (wrapped); `fold` pulls one interior control row across its neighbour.
fn ring_map(rng: &mut Lcg, p: usize, ne: [usize; 2], amp: f64, fold: bool) -> Surface {
    let kx = KnotVector::open_uniform(p, ne[0]);
    let ky = KnotVector::periodic_uniform(p, ne[1]);
    let (gx, gy) = (kx.greville(), ky.greville());
    let d = ky.dim();
    let nx = gx.len();
    let noise: Vec<[f64; 2]> =
        (0..nx * d).map(|_| [amp * (rng.uniform() - 0.5), amp * (rng.uniform() - 0.5)]).collect();
    let mut cps = Vec::new();
    for (j, &v) in gy.iter().enumerate() {
        for (i, &u) in gx.iter().enumerate() {
            let mut r = 0.5 + 0.5 * u;
            if fold && i == 1 && j % d == 2 {
                r = 0.5 + 0.5 * gx[3];
            }
            let th = 2.0 * std::f64::consts::PI * v;
            let e = if i == 0 || i + 1 == nx { [0.0; 2] } else { noise[(j % d) * nx + i] };
            cps.push([r * th.cos() + e[0], r * th.sin() + e[1]]);
        }
    }
    Surface::new([kx, ky], cps, None).unwrap()
}

/// Periodic `eta`: the certificate extracts the periodic direction, proves a ring
/// positive with a bound below the dense sample (and above zero), and finds the fold
/// of a folded ring, its witness confirmed by evaluation.
#[test]
fn periodic_rings_certify_and_folds_are_found() {
    let mut rng = Lcg::new(3);
    for p in [2, 3] {
        let map = ring_map(&mut rng, p, [4, 9], 0.02, false);
        let cert = certify(&map, &CertifyOptions { excuse_corners: false, ..Default::default() }).unwrap();
        let dense = dense_min(&map, 200);
        match cert.verdict {
            Finding::Certified { lower_bound, .. } => {
                assert!(lower_bound > 0.0 && lower_bound <= dense, "{lower_bound} vs {dense}")
            }
            v => panic!("p={p}: ring not certified: {v:?}"),
        }
        let folded = ring_map(&mut rng, p, [4, 9], 0.0, true);
        let cert = certify(&folded, &CertifyOptions { excuse_corners: false, ..Default::default() }).unwrap();
        match cert.verdict {
            Finding::Folded { param, value, .. } => {
                assert!(value < 0.0);
                assert!(folded.derivs(param[0], param[1], 1).det_j() < 0.0);
                assert!(dense_min(&folded, 200) < 0.0);
            }
            v => panic!("p={p}: folded ring not found: {v:?}"),
        }
    }
}
