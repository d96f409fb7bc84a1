//! The tensor core against closed forms: polynomials and a rational map reproduced
//! exactly after knot insertion and degree elevation, in 2 and 3 parameters;
//! derivatives against central differences.

use super::*;

/// The Bézier form on one element of `(u², v, w)` scaled per coordinate: degree 2 in
/// `u`, 1 in `v` and `w`, coefficients `b_i(u²) b_j(v)` etc. (`u² = B_2`, `v = B_1`).
fn polynomial3() -> TensorSpline<3, 3> {
    let knots = [KnotVector::open_uniform(2, 1), KnotVector::open_uniform(1, 1), KnotVector::open_uniform(1, 1)];
    let (sq, lin) = ([0.0, 0.0, 1.0], [0.0, 1.0]);
    let mut cps = Vec::new();
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..3 {
                // x = u² v + w, y = u + 2 v w, z = v
                cps.push([sq[i] * lin[j] + lin[k], i as f64 / 2.0 + 2.0 * lin[j] * lin[k], lin[j]]);
            }
        }
    }
    TensorSpline::checked(knots, cps, None).unwrap()
}

fn exact3(u: [f64; 3]) -> [f64; 3] {
    [u[0] * u[0] * u[1] + u[2], u[0] + 2.0 * u[1] * u[2], u[1]]
}

/// A quarter annulus `r ∈ [1, 2]` (exact circular arcs, degree 2 NURBS in `u`).
fn annulus() -> TensorSpline<2, 2> {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let knots = [KnotVector::open_uniform(2, 1), KnotVector::open_uniform(1, 1)];
    let cps = [1.0, 2.0].iter().flat_map(|&r| [[r, 0.0], [r, r], [0.0, r]]).collect();
    TensorSpline::checked(knots, cps, Some(vec![1.0, w, 1.0, 1.0, w, 1.0])).unwrap()
}

/// The annulus extruded along `z ∈ [0, 1]`: a shell of a cylinder, rational in `u`.
fn shell() -> TensorSpline<3, 3> {
    let a = annulus();
    let [k0, k1] = a.knots.clone();
    let cps = [0.0, 1.0].iter().flat_map(|&z| a.control_points.iter().map(move |p| [p[0], p[1], z])).collect();
    let w = a.weights.as_ref().unwrap();
    TensorSpline::checked([k0, k1, KnotVector::open_uniform(1, 1)], cps, Some([w.clone(), w.clone()].concat())).unwrap()
}

fn value<const P: usize, const D: usize>(t: &TensorSpline<P, D>, u: [f64; P]) -> ([f64; D], [[f64; D]; P]) {
    let b: [BasisDerivs; P] = std::array::from_fn(|d| BasisDerivs::at(&t.knots[d], u[d], 1));
    t.first_derivs(b.each_ref())
}

const POINTS: [[f64; 3]; 5] = [[0.0, 0.0, 0.0], [0.3, 0.7, 0.2], [0.55, 0.1, 0.9], [1.0, 1.0, 1.0], [0.81, 0.42, 0.5]];

#[test]
fn insertion_and_elevation_reproduce_a_trivariate_polynomial() {
    let t = polynomial3();
    let fine = [t.knots[0].with_inserted(&[0.3, 0.3, 0.6]), t.knots[1].halved(), t.knots[2].with_inserted(&[0.25])];
    let variants =
        [t.refined(&fine).unwrap(), t.elevated_in(1).unwrap().elevated_in(0).unwrap().refined_in(2, &fine[2]).unwrap()];
    for v in &variants {
        for u in POINTS {
            let (x, _) = value(v, u);
            let e = exact3(u);
            assert!((0..3).all(|c| (x[c] - e[c]).abs() < 1e-14), "{x:?} vs {e:?} at {u:?}");
        }
    }
    assert_eq!(variants[1].degrees(), [3, 2, 1]);
    assert_eq!(variants[0].shape(), fine.each_ref().map(KnotVector::num_basis));
}

#[test]
fn insertion_and_elevation_keep_a_rational_map_exact() {
    let a = annulus();
    let fine = [a.knots[0].with_inserted(&[0.2, 0.5, 0.5]), a.knots[1].with_inserted(&[0.4])];
    for v in [
        a.refined(&fine).unwrap(),
        a.elevated_in(0).unwrap().elevated_in(1).unwrap(),
        a.refined_in(1, &fine[1]).unwrap(),
    ] {
        for [s, t, _] in POINTS {
            // radius 1 + t, at the angle of the original map
            let (x, _) = value(&v, [s, t]);
            let (y, _) = value(&a, [s, t]);
            assert!((x[0].hypot(x[1]) - (1.0 + t)).abs() < 1e-14, "{x:?}");
            assert!((x[1].atan2(x[0]) - y[1].atan2(y[0])).abs() < 1e-14);
        }
    }
}

#[test]
fn insertion_and_elevation_keep_a_rational_volume_exact() {
    let v = shell();
    let fine = [v.knots[0].with_inserted(&[0.5, 0.7]), v.knots[1].clone(), v.knots[2].with_inserted(&[0.3, 0.3])];
    for f in [v.refined(&fine).unwrap(), v.elevated_in(2).unwrap().elevated_in(0).unwrap()] {
        assert!(f.weights.is_some());
        for u in POINTS {
            let (x, _) = value(&f, u);
            let (y, _) = value(&v, u);
            assert!((x[0].hypot(x[1]) - (1.0 + u[1])).abs() < 1e-14 && (x[2] - u[2]).abs() < 1e-14, "{x:?} at {u:?}");
            assert!((x[1].atan2(x[0]) - y[1].atan2(y[0])).abs() < 1e-14);
        }
    }
}

#[test]
fn first_derivatives_match_closed_forms_and_differences() {
    let t = polynomial3();
    for u in POINTS {
        let (_, d) = value(&t, u);
        let e = [[2.0 * u[0] * u[1], 1.0, 0.0], [u[0] * u[0], 2.0 * u[2], 1.0], [1.0, 2.0 * u[1], 0.0]];
        assert!((0..3).all(|a| (0..3).all(|c| (d[a][c] - e[a][c]).abs() < 1e-14)), "{d:?} vs {e:?}");
    }
    let a = annulus().refined_in(0, &KnotVector::open_uniform(2, 1).with_inserted(&[0.4])).unwrap();
    let h = 1e-6;
    for [s, t, _] in POINTS.map(|p| p.map(|x| 0.05 + 0.9 * x)) {
        let (_, d) = value(&a, [s, t]);
        let fd = |dir: usize| {
            let (mut lo, mut hi) = ([s, t], [s, t]);
            lo[dir] -= h;
            hi[dir] += h;
            let (xl, xh) = (value(&a, lo).0, value(&a, hi).0);
            [0, 1].map(|c| (xh[c] - xl[c]) / (2.0 * h))
        };
        for dir in 0..2 {
            assert!((0..2).all(|c| (fd(dir)[c] - d[dir][c]).abs() < 1e-7), "{:?} vs {:?}", fd(dir), d[dir]);
        }
    }
}

#[test]
fn indices_and_validation() {
    let t = polynomial3();
    for lin in 0..t.control_points.len() {
        assert_eq!(t.index(t.unindex(lin)), lin);
    }
    assert_eq!(t.unindex(7), [1, 0, 1]);
    let (knots, cps) = (t.knots.clone(), t.control_points.clone());
    let e = TensorSpline::checked(knots.clone(), cps[1..].to_vec(), None).unwrap_err();
    assert!(matches!(e, Error::Length { .. }), "{e}");
    let mut bad = cps.clone();
    bad[5][2] = f64::INFINITY;
    assert!(matches!(TensorSpline::checked(knots.clone(), bad, None), Err(Error::NonFinite { .. })));
    assert!(matches!(
        TensorSpline::checked(knots.clone(), cps.clone(), Some(vec![0.0; 12])),
        Err(Error::Weight { .. })
    ));
    assert_eq!(TensorSpline::checked(knots, cps, Some(vec![1.0; 12])).unwrap().weights, None);
}
