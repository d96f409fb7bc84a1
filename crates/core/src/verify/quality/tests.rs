//! Tests of the quality functionals, the det J sample and the boundary deviation.

use super::*;
use crate::spline::knots::KnotVector;

/// The affine map `(xi, eta) -> (2 xi + eta, 3 eta)`: all functionals in closed form.
#[test]
fn functionals_and_cells_of_an_affine_map() {
    let k = KnotVector::open_uniform(2, 3);
    let g = k.greville();
    let cps = g.iter().flat_map(|&v| g.iter().map(move |&u| [2.0 * u + v, 3.0 * v])).collect();
    let map = Surface::new([k.clone(), k], cps, None).unwrap();
    let qy = quality(&map);
    let f = qy.functionals;
    // x_xi = (2, 0), x_eta = (1, 3): g11 = 4, g12 = 2, g22 = 10, det J = 6
    assert!((f.area - 6.0).abs() < 1e-12);
    assert!((f.winslow - 14.0 / 6.0).abs() < 1e-12);
    assert!((f.area_orthogonality - 116.0).abs() < 1e-11);
    assert!((f.liao - 124.0).abs() < 1e-11);
    assert!(f.uniformity.abs() < 1e-20 && f.harmonic.abs() < 1e-20);
    let sj = 6.0 / (2.0 * 10f64.sqrt());
    assert!((qy.scaled_jacobian.min - sj).abs() < 1e-12 && (qy.scaled_jacobian_mean - sj).abs() < 1e-12);
    let angle = (2.0 / (2.0 * 10f64.sqrt())).acos().to_degrees();
    assert!((qy.orthogonality_degrees.max - (90.0 - angle)).abs() < 1e-9);
    // element edges: 2/3 and sqrt(10)/3
    assert!((qy.aspect_ratio.mean - 10f64.sqrt() / 2.0).abs() < 1e-12);
    assert_eq!(qy.elements, 9);
    assert!((area(&map) - 6.0).abs() < 1e-12);
}

/// The area of a rational map (a quarter annulus with exact NURBS arcs, refined to 4 x
/// 3 elements) agrees with the functionals' area (same Gauss rule, other summation
/// order) to rounding and with `3 pi / 4` to the rule's accuracy.
#[test]
fn area_of_a_rational_map() {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let (mut cps, mut ws) = (Vec::new(), Vec::new());
    for r in [1.0, 2.0] {
        cps.extend([[r, 0.0], [r, r], [0.0, r]]);
        ws.extend([1.0, w, 1.0]);
    }
    let coarse = Surface::new([KnotVector::open_uniform(2, 1), KnotVector::open_uniform(1, 1)], cps, Some(ws)).unwrap();
    let map = coarse.refined(&[KnotVector::open_uniform(2, 4), KnotVector::open_uniform(1, 3)]).unwrap();
    let (a, f) = (area(&map), functionals(&map).area);
    // (the arcs run in xi, the radius in eta: a clockwise map, det J < 0)
    assert!((a - f).abs() < 1e-14 * f.abs(), "{a} vs {f}");
    assert!((a + 0.75 * std::f64::consts::PI).abs() < 1e-6, "{a}");
}

/// The boundary deviation is geometric: a side that is the input curve with another
/// parameterization (a quarter circle with Möbius-reweighted NURBS weights) deviates by
/// rounding only, a concentric arc of radius 1.1 by exactly 0.1, and a point cloud by
/// the distance to its polyline.
#[test]
fn boundary_deviation_is_the_distance_to_the_input_curve() {
    use crate::boundary::{Boundary, SideCurve};
    use crate::spline::curve::Curve;
    use crate::spline::surface::Side;
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let arc = |r: f64, c: f64| {
        Curve::new(KnotVector::open_uniform(2, 1), vec![[r, 0.0], [r, r], [0.0, r]], Some(vec![1.0, c * h, c * c]))
            .unwrap()
    };
    // the quarter annulus between radii 1 and 2, its inner arc reparameterized (c = 3)
    let (inner, outer) = (arc(1.0, 3.0), arc(2.0, 1.0));
    let cps = inner.control_points.iter().chain(&outer.control_points).copied().collect();
    let weights = inner.weights.clone().unwrap().into_iter().chain(outer.weights.clone().unwrap()).collect();
    let map =
        Surface::new([KnotVector::open_uniform(2, 1), KnotVector::open_uniform(1, 1)], cps, Some(weights)).unwrap();
    let south = map.boundary(Side::South);
    let t = 0.3;
    let (p, q) = (south.eval(t), arc(1.0, 1.0).eval(t));
    assert!((p[0] - q[0]).hypot(p[1] - q[1]) > 0.1, "the parameterizations differ");
    let with_south = |c: SideCurve| Boundary {
        name: "annulus".into(),
        sides: Side::ALL.map(|s| if s == Side::South { c.clone() } else { SideCurve::Spline(map.boundary(s)) }),
    };
    let d = boundary_deviation(&map, &with_south(SideCurve::Spline(arc(1.0, 1.0))), 400);
    assert!(d.iter().all(|&x| x < 1e-14), "{d:?}");
    let d = boundary_deviation(&map, &with_south(SideCurve::Spline(arc(1.1, 1.0))), 400);
    assert!((d[0] - 0.1).abs() < 1e-14, "{d:?}");
    assert!(d[1..].iter().all(|&x| x < 1e-14), "{d:?}");
    // a point cloud on the unit circle: the polyline's chords are within 1 - cos(π/4n)
    let n = 64;
    let cloud: Vec<[f64; 2]> = (0..=n)
        .map(|k| {
            let a = std::f64::consts::FRAC_PI_2 * k as f64 / n as f64;
            [a.cos(), a.sin()]
        })
        .collect();
    let d = boundary_deviation(&map, &with_south(SideCurve::Points(cloud)), 400);
    let sagitta = 1.0 - (std::f64::consts::FRAC_PI_4 / n as f64).cos();
    assert!(d[0] <= sagitta * (1.0 + 1e-9) && d[0] > 0.5 * sagitta, "{} {sagitta}", d[0]);
}

/// The distance to a circle of radius 2 (an exact NURBS quarter arc, reparameterized)
/// from points inside and outside it, at distances from 1e-13 to 0.3, is
/// `| |p| - 2 |` to rounding (Newton's foot point), and from points beyond the arc's
/// ends the distance to the end point (the golden section at the bracket's end).
#[test]
fn nearest_chord_from_any_guess_is_the_scan_of_every_chord() {
    use crate::boundary::SideCurve;
    use crate::spline::curve::Curve;
    use crate::testutil::Lcg;
    let mut rng = Lcg::new(11);
    // a wiggly spline side (many boxes of chords) and a dense point cloud with ties
    let cps: Vec<[f64; 2]> =
        (0..40).map(|i| [i as f64 / 39.0, 0.2 * (i as f64 * 0.9).sin() + 0.05 * rng.uniform()]).collect();
    let spline = SideCurve::Spline(Curve::new(KnotVector::open_uniform(3, 37), cps, None).unwrap());
    let cloud =
        SideCurve::Points((0..600).map(|i| [((i / 2) as f64 / 299.0), 0.1 * ((i / 2) as f64 * 0.05).cos()]).collect());
    for side in [&spline, &cloud] {
        let s = SideSamples::of(side);
        let chords = s.points.len() - 1;
        let scan = |p: [f64; 2]| {
            let mut best = (f64::INFINITY, 0);
            for i in 0..chords {
                let e = point_segment_offset(p, s.points[i].1, s.points[i + 1].1);
                if e[0].hypot(e[1]) < best.0 {
                    best = (e[0].hypot(e[1]), i);
                }
            }
            best
        };
        for _ in 0..300 {
            let p = [1.4 * rng.uniform() - 0.2, 0.8 * rng.uniform() - 0.4];
            let want = scan(p);
            for guess in [None, Some(0), Some(chords - 1), Some(want.1), Some((rng.uniform() * chords as f64) as usize)]
            {
                assert_eq!(s.nearest_chord(p, guess), want, "{p:?} from {guess:?}");
            }
        }
    }
}

#[test]
fn side_distance_is_the_closed_form_distance_to_a_circle() {
    use crate::boundary::SideCurve;
    use crate::spline::curve::Curve;
    use crate::testutil::Lcg;
    let (r, c, h) = (2.0, 3.0, std::f64::consts::FRAC_1_SQRT_2);
    let arc = SideCurve::Spline(
        Curve::new(KnotVector::open_uniform(2, 1), vec![[r, 0.0], [r, r], [0.0, r]], Some(vec![1.0, c * h, c * c]))
            .unwrap(),
    );
    let side = SideSamples::of(&arc);
    let distance = |p: [f64; 2]| side.distance_beyond(p, side.nearest_chord(p, None), f64::NEG_INFINITY);
    let mut rng = Lcg::new(5);
    for k in 0..400 {
        let a = std::f64::consts::FRAC_PI_2 * (0.01 + 0.98 * rng.uniform());
        let off = 10f64.powf(-13.0 + 12.5 * rng.uniform()) * if k % 2 == 0 { 1.0 } else { -1.0 };
        let rho = r + off;
        let p = [rho * a.cos(), rho * a.sin()];
        let exact = (p[0].hypot(p[1]) - r).abs();
        let d = distance(p);
        assert!((d - exact).abs() <= 4e-15 * r, "angle {a}, offset {off}: {d} vs {exact}");
    }
    // beyond the ends: the nearest point is the end point
    for p in [[2.5, -0.4], [1.0, -1e-3], [-0.3, 2.2], [-1e-9, 1.5]] {
        let end = if p[1] < 0.0 { [r, 0.0] } else { [0.0, r] };
        let exact = (p[0] - end[0]).hypot(p[1] - end[1]);
        assert!((distance(p) - exact).abs() <= 4e-15 * r, "{p:?}: {} vs {exact}", distance(p));
    }
}

/// The THB sample, cell by cell on the Bézier patches, is the map's own `det J` at every
/// grid point and the sample of its exact tensor form, on a genuine three-level THB map
/// (coefficients only the hierarchical space has).
#[test]
fn thb_sample_is_the_maps_det_j() {
    use crate::spline::hierarchical::map::HierarchicalMap;
    // a near-identity map with small wiggles on every active function
    let mut seed = 7u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let tensor0 = HierarchicalMap::from_surface(&identity(4)).unwrap();
    let map0 = tensor0.refined(&[(0, [1, 1]), (0, [2, 1]), (0, [1, 2])], 2).unwrap();
    let map0 = map0.refined(&[(1, [3, 3]), (1, [2, 3])], 2).unwrap();
    assert_eq!(map0.basis.num_levels(), 3);
    let cps = map0.control_points.iter().map(|p| [p[0] + 0.02 * rnd(), p[1] + 0.02 * rnd()]).collect();
    let map = HierarchicalMap::new(map0.basis.clone(), cps).unwrap();
    let n = 37;
    let s = sample_det_j_hierarchical(&map, n).unwrap();
    let tensor = sample_det_j(&map.to_surface().unwrap(), n);
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            let d = map.derivs(u, v);
            let exact = d.xu[0] * d.xv[1] - d.xv[0] * d.xu[1];
            let got = s.values[j * (n + 1) + i];
            assert!((got - exact).abs() < 1e-11, "({u}, {v}): {got} vs {exact}");
            assert!((got - tensor.values[j * (n + 1) + i]).abs() < 1e-11);
        }
    }
    assert!((s.min - tensor.min).abs() < 1e-11 && (s.max - tensor.max).abs() < 1e-11);
}

/// The identity of the unit square as a quadratic map with `e` elements per direction.
fn identity(e: usize) -> Surface {
    let k = KnotVector::open_uniform(2, e);
    let g = k.greville();
    let cps = g.iter().flat_map(|&v| g.iter().map(move |&u| [u, v])).collect();
    Surface::new([k.clone(), k], cps, None).unwrap()
}
