//! NURBS sides on the input basis (paper §5.2): the rational tensor basis whose boundary
//! weights are the sides' weights and whose interior weights are the Coons blend of them
//! ([`Level::weights`]). Exact arcs stay exact arcs, the blend is the tensor product
//! where it should be, and it commutes with knot insertion.

use std::f64::consts::FRAC_1_SQRT_2;

use winslow::boundary::hierarchy::Level;
use winslow::boundary::BasisChoice;
use winslow::io::{read_boundary, ReadOptions};
use winslow::solve;
use winslow::solve::options::SolveOptions;
use winslow::solve::report::Verdict;
use winslow::spline::curve::Curve;
use winslow::spline::knots::KnotVector;
use winslow::spline::surface::Surface;
use winslow::{Boundary, Side, SideCurve};

fn input_basis() -> SolveOptions {
    let mut opts = SolveOptions::default();
    opts.fit.basis = BasisChoice::Input;
    opts
}

/// A quarter circle of radius `r` from angle `a0` to `a0 + 90°` (counter-clockwise) or
/// back (`reverse`): the exact rational quadratic arc, weights `(1, 1/√2, 1)`.
fn arc(r: f64, a0: f64, reverse: bool) -> Curve {
    let p = |a: f64| [r * a.cos(), r * a.sin()];
    let a1 = a0 + std::f64::consts::FRAC_PI_2;
    let mid = [r * (a0.cos() + a1.cos()), r * (a0.sin() + a1.sin())];
    let mut cps = vec![p(a0), mid, p(a1)];
    if reverse {
        cps.reverse();
    }
    Curve::new(KnotVector::new(2, vec![0., 0., 0., 1., 1., 1.]).unwrap(), cps, Some(vec![1.0, FRAC_1_SQRT_2, 1.0]))
        .unwrap()
}

fn line(a: [f64; 2], b: [f64; 2]) -> Curve {
    Curve::new(KnotVector::new(1, vec![0., 0., 1., 1.]).unwrap(), vec![a, b], None).unwrap()
}

/// The quarter annulus `1 <= r <= 2`, `0 <= θ <= 90°` with its two arcs exact: west the
/// inner arc, east the outer one, south and north radial lines.
fn exact_quarter_annulus() -> Boundary {
    Boundary {
        name: "exact quarter annulus".into(),
        sides: [
            SideCurve::Spline(line([1.0, 0.0], [2.0, 0.0])),
            SideCurve::Spline(arc(2.0, 0.0, false)),
            SideCurve::Spline(line([0.0, 1.0], [0.0, 2.0])),
            SideCurve::Spline(arc(1.0, 0.0, false)),
        ],
    }
}

/// `|x|` on `n + 1` points of each side of `map` and the radius each side should have.
fn radius_error(map: &Surface, side: Side, r: f64) -> f64 {
    let c = map.boundary(side);
    let (a, b) = c.domain();
    (0..=200).map(|k| c.eval(a + (b - a) * k as f64 / 200.0)).map(|x| (x[0].hypot(x[1]) - r).abs()).fold(0.0, f64::max)
}

/// Two exact arcs: the map is certified on the rational input basis, its weights are the
/// tensor product `w_j` of the arcs' weights (the Coons blend of `w^W = w^E`, `w^S = w^N
/// = 1`), its arcs are circles to rounding, and refinement (`--refine`) keeps all that.
#[test]
fn exact_arcs_stay_circles() {
    for refine in [0, 2] {
        let mut opts = input_basis();
        opts.levels.refine = refine;
        let sol = solve(&exact_quarter_annulus(), &opts).unwrap();
        let r = &sol.report;
        assert_eq!(r.outcome.verdict, Verdict::Certified, "{}", r.outcome.message);
        assert_eq!((r.setup.basis.used, r.setup.basis.fallback.as_deref()), (BasisChoice::Input, None));
        let map = &sol.map;
        let w = map.weights.as_ref().expect("a rational map");
        let [nx, ny] = map.shape();
        let west = map.boundary(Side::West).weights.unwrap();
        for j in 0..ny {
            for i in 0..nx {
                assert!((w[j * nx + i] - west[j]).abs() < 1e-15, "weight ({i}, {j}): {} vs {}", w[j * nx + i], west[j]);
            }
        }
        assert!(radius_error(map, Side::West, 1.0) < 4e-16, "inner arc {:e}", radius_error(map, Side::West, 1.0));
        assert!(radius_error(map, Side::East, 2.0) < 8e-16, "outer arc {:e}", radius_error(map, Side::East, 2.0));
        let dev = r.boundary.deviation.iter().cloned().fold(0.0, f64::max);
        assert!(dev < 1e-14, "boundary deviation {dev:e}");
        // area of the quarter annulus, 3π/4, by the report's Gauss rule (not exact for the
        // rational integrand: 3e-5 relative on one element)
        let area = sol.report.measures.area;
        assert!((area / (0.75 * std::f64::consts::PI) - 1.0).abs() < 1e-4, "area {area}");
    }
}

/// The disk of G+Smo's examples (`disk.xml`: one biquadratic NURBS patch whose sides are
/// four exact quarter circles) solved on its own rational basis: the boundary is the
/// circle to rounding, the side weights are the input's, and the map is certified up to
/// the four corners, where the circle's straight angle forces `det J = 0`.
#[test]
fn disk_keeps_its_arcs() {
    let path = winslow::testutil::data("gismo/xml/disk.xml");
    let b = read_boundary(&path, &ReadOptions::default()).unwrap();
    let sol = solve(&b, &input_basis()).unwrap();
    let r = &sol.report;
    assert_eq!(r.outcome.verdict, Verdict::DegenerateCorner, "{}", r.outcome.message);
    assert_eq!(r.setup.basis.used, BasisChoice::Input);
    let c = sol.map.boundary(Side::South).eval(0.0);
    let radius = c[0].hypot(c[1]);
    for s in Side::ALL {
        let e = radius_error(&sol.map, s, radius);
        assert!(e < 1e-15 * radius.max(1.0), "{s}: radius error {e:e}");
        let SideCurve::Spline(input) = b.side(s) else { panic!("spline sides") };
        let (mine, theirs) = (sol.map.boundary(s).weights.unwrap(), input.weights.clone().unwrap());
        let scale = mine[0] / theirs[0];
        for (a, b) in mine.iter().zip(&theirs) {
            assert!((a - scale * b).abs() < 1e-15, "{s}: weights {mine:?} vs {theirs:?}");
        }
    }
}

/// The Coons blend of the boundary weights is the continuous Coons interpolant of the
/// boundary weight functions, so blending after knot insertion gives the weights of the
/// refined rational surface (homogeneous insertion) to rounding.
#[test]
fn weight_blend_commutes_with_knot_insertion() {
    let b = Boundary {
        name: "mixed".into(),
        sides: [
            SideCurve::Spline(
                Curve::new(
                    KnotVector::new(2, vec![0., 0., 0., 0.4, 1., 1., 1.]).unwrap(),
                    vec![[0., 0.], [0.3, -0.2], [0.7, 0.1], [1., 0.]],
                    Some(vec![1.0, 1.6, 0.7, 1.0]),
                )
                .unwrap(),
            ),
            SideCurve::Spline(arc(1.0, -std::f64::consts::FRAC_PI_2, false).clone()),
            SideCurve::Spline(line([0.0, 1.0], [1.0, 1.0])),
            SideCurve::Spline(line([0.0, 0.0], [0.0, 1.0])),
        ],
    };
    // bend the east arc onto the corners (1, 0) -> (1, 1): an arc of radius 1/2
    let mut b = b;
    let east = Curve::new(
        KnotVector::new(2, vec![0., 0., 0., 1., 1., 1.]).unwrap(),
        vec![[1.0, 0.0], [1.5, 0.5], [1.0, 1.0]],
        Some(vec![1.0, 0.5, 1.0]),
    )
    .unwrap();
    b.sides[1] = SideCurve::Spline(east);
    let h = winslow::build_hierarchy(&b, &input_basis().fit).unwrap();
    assert_eq!(h.basis.used, BasisChoice::Input, "{:?}", h.basis);
    let level: &Level = h.finest();
    let w = level.weights().unwrap().expect("rational sides give weights");
    let coarse = Surface::new(level.knots.clone(), vec![[0.0; 2]; w.len()], Some(w)).unwrap();
    let fine_knots = [level.knots[0].halved(), level.knots[1].halved().with_inserted(&[0.37])];
    let refined = coarse.refined(&fine_knots).unwrap();
    let sides = Side::ALL.map(|s| level.side(s).refined(&fine_knots[s.direction()]).unwrap());
    let fine = Level { knots: fine_knots, sides };
    let blended = fine.weights().unwrap().unwrap();
    let inserted = refined.weights.unwrap();
    for (k, (a, b)) in blended.iter().zip(&inserted).enumerate() {
        assert!((a - b).abs() < 1e-14, "weight {k}: blend {a} vs insertion {b}");
    }
}
