//! Similarity invariance of the solve (issue: reliability): a geometry translated by 1e9
//! times its size, or scaled by 1e±150, gives the same verdict, the same iteration
//! counts and the same map (transformed) as the original, up to the rounding of the
//! input's own coordinates; sizes whose `det J` leaves `f64`'s range get a typed error,
//! not a wrong diagnosis.

use winslow::boundary::validate::validate;
use winslow::boundary::{Boundary, SideCurve};
use winslow::io::{read_boundary, ReadOptions};
use winslow::solve;
use winslow::solve::options::SolveOptions;
use winslow::solve::report::Solution;
use winslow::{Error, Point};

fn load(file: &str) -> Boundary {
    let path = winslow::testutil::data(file);
    read_boundary(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// `x ↦ a + s x` applied to every side (control points or points; weights kept).
fn similar(b: &Boundary, a: Point, s: f64) -> Boundary {
    let f = |p: &Point| [a[0] + s * p[0], a[1] + s * p[1]];
    let side = |c: &SideCurve| match c {
        SideCurve::Spline(c) => {
            let mut c = c.clone();
            c.control_points = c.control_points.iter().map(f).collect();
            SideCurve::Spline(c)
        }
        SideCurve::Points(p) => SideCurve::Points(p.iter().map(f).collect()),
        SideCurve::Analytic(_) => unreachable!("files hold no analytic sides"),
    };
    Boundary { name: b.name.clone(), sides: b.sides.each_ref().map(side) }
}

fn solved(b: &Boundary) -> Solution {
    solve(b, &SolveOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", b.name))
}

/// Same verdict, levels, bases and iteration counts; control points equal to the
/// transformed original's within `tol` of the diameter.
fn assert_same(file: &str, orig: &Solution, moved: &Solution, a: Point, s: f64, tol: f64) {
    let (r0, r1) = (&orig.report, &moved.report);
    let what = format!("{file} moved by {a:?}, scaled by {s:e}");
    assert_eq!(r1.verdict, r0.verdict, "{what}: {}", r1.message);
    assert_eq!(r1.levels.len(), r0.levels.len(), "{what}");
    for (l0, l1) in r0.levels.iter().zip(&r1.levels) {
        assert_eq!(l1.shape, l0.shape, "{what}");
        assert_eq!(l1.newton_iterations, l0.newton_iterations, "{what}: level {}", l0.level);
        assert_eq!(l1.pseudo_time_iterations, l0.pseudo_time_iterations, "{what}: level {}", l0.level);
    }
    let rel = |x: f64, y: f64| (x - y).abs() / (s.abs() * r0.diameter);
    assert!(rel(r1.diameter, s * r0.diameter) < tol, "{what}: diameter {} vs {}", r1.diameter, r0.diameter);
    assert!((r1.area / (s * s * r0.area) - 1.0).abs() < tol, "{what}: area {} vs {}", r1.area, r0.area);
    let dj = (r1.det_j_min / (s * s * r0.det_j_min) - 1.0).abs();
    assert!(dj < 1e-6_f64.max(100.0 * tol), "{what}: det J min {} vs {}", r1.det_j_min, r0.det_j_min);
    let (m0, m1) = (&orig.map, &moved.map);
    assert_eq!(m1.knots, m0.knots, "{what}");
    let worst = m0
        .control_points
        .iter()
        .zip(&m1.control_points)
        .map(|(p, q)| rel(q[0], a[0] + s * p[0]).max(rel(q[1], a[1] + s * p[1])))
        .fold(0.0, f64::max);
    assert!(worst < tol, "{what}: control points differ by {worst:.3e} of the diameter");
}

#[test]
fn translated_and_scaled_geometries_solve_alike() {
    for file in ["gismo/duck.json", "quarter_annulus.json", "gismo/puzzle3.json"] {
        let b = load(file);
        let orig = solved(&b);
        let d = orig.report.diameter;
        // far from the origin: the input itself is rounded to ~1e9 eps of its size, and
        // the map can follow it no closer than that
        for (a, s, tol) in [
            ([1e9 * d, -3e9 * d], 1.0, 1e-5),
            ([-1e6 * d, 1e6 * d], 1.0, 1e-8),
            ([0.0, 0.0], 1e150, 1e-8),
            ([0.0, 0.0], 1e-150, 1e-8),
            ([7e158, 0.0], 1e150, 1e-5),
        ] {
            let moved = solved(&similar(&b, a, s));
            assert_same(file, &orig, &moved, a, s, tol);
        }
    }
}

#[test]
fn sizes_beyond_the_range_of_det_j_are_a_typed_error() {
    let b = load("quarter_annulus.json");
    for s in [1e300, 1e-300, 1e200, 1e-200] {
        let moved = similar(&b, [0.0, 0.0], s);
        for e in [validate(&moved).unwrap_err(), solve(&moved, &SolveOptions::default()).unwrap_err()] {
            assert!(matches!(e, Error::Range { .. }), "scale {s:e}: {e}");
        }
    }
}

#[test]
fn validation_reports_in_the_input_coordinates() {
    let b = load("gismo/duck.json");
    let r0 = validate(&b).unwrap();
    let (a, s) = ([5e-109, -2e-109], 1e-120);
    let r1 = validate(&similar(&b, a, s)).unwrap();
    assert_eq!(r1.orientation, r0.orientation);
    // the input itself is rounded to ~1e9 eps of its size at its position
    assert!((r1.diameter / (s * r0.diameter) - 1.0).abs() < 1e-6, "{} vs {}", r1.diameter, r0.diameter);
    assert!((r1.signed_area / (s * s * r0.signed_area) - 1.0).abs() < 1e-6);
    for k in 0..4 {
        for c in 0..2 {
            let want = a[c] + s * r0.corners[k][c];
            assert!((r1.corners[k][c] - want).abs() <= 1e-12 * want.abs(), "corner {k}: {:?}", r1.corners[k]);
        }
        assert!(
            (r1.corner_angles[k] - r0.corner_angles[k]).abs() < 1e-3,
            "{:?} vs {:?}",
            r1.corner_angles,
            r0.corner_angles
        );
    }
}
