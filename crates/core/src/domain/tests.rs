//! Tests of the automatic layout against closed-form answers: affine images of regular
//! polygons (the template is the affine image of the polygon's), areas, reflex cuts.

use super::harmonic::polygon_vertex;
use super::*;
use crate::multipatch::check::validate_layout;
use crate::multipatch::Layout;
use crate::pipeline::{Pipeline, Solved};
use crate::solve::report::Verdict;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::quadrature::GaussLegendre;
use crate::spline::surface::Side;

fn line(a: Point, b: Point) -> SideCurve {
    SideCurve::Spline(Curve::new(KnotVector::open_uniform(1, 1), vec![a, b], None).unwrap())
}

fn polygon(pts: &[Point]) -> Domain {
    let n = pts.len();
    let outer = Loop::new((0..n).map(|k| line(pts[k], pts[(k + 1) % n])).collect());
    Domain { name: "poly".into(), outer, holes: Vec::new() }
}

fn affine(p: Point) -> Point {
    [1.7 * p[0] + 0.6 * p[1] + 4.0, -0.3 * p[0] + 1.1 * p[1] + 2.0]
}

/// `∫ (x y' - y x') / 2` along a polynomial curve by Gauss-Legendre per knot span
/// (exact up to rounding: the integrand is a polynomial of degree `2p - 1`).
fn green(c: &Curve) -> f64 {
    let rule = GaussLegendre::new(c.degree() + 1);
    let mut a = 0.0;
    for (_, lo, hi) in c.knots.elements() {
        for (t, w) in rule.on(lo, hi) {
            let d = c.derivs(t, 1);
            a += 0.5 * w * (d.x[0] * d.d1[1] - d.x[1] * d.d1[0]);
        }
    }
    a
}

/// Signed area enclosed by the four sides of a patch (Green's theorem).
fn patch_area(sides: &[Curve; 4]) -> f64 {
    green(&sides[0]) + green(&sides[1]) - green(&sides[2]) - green(&sides[3])
}

fn total_area(l: &Layout) -> f64 {
    l.patches.iter().map(|p| patch_area(&p.sides)).sum()
}

#[test]
fn midpoint_template_reproduces_affine_maps() {
    for n in 3..=12 {
        let pts: Vec<Point> = (0..n).map(|s| affine(polygon_vertex(n, s))).collect();
        let auto = auto_layout(&polygon(&pts), &LayoutOptions::default()).unwrap();
        let l = &auto.layout;
        let r = &auto.report;
        let want = if n == 4 { 1 } else { n };
        assert_eq!(l.patches.len(), want, "{n}");
        assert_eq!(l.interfaces.len(), if n == 4 { 0 } else { n }, "{n}");
        validate_layout(l).unwrap();
        assert!(l.patches.iter().all(|p| p.face.as_deref() == Some("domain")));
        if n == 4 {
            assert!(r.irregular_vertices.is_empty());
            continue;
        }
        // the interior vertex is the affine image of the centre, of valence n
        let c = affine([0.0, 0.0]);
        let v = &r.irregular_vertices;
        assert_eq!(v.len(), 1, "{n}");
        assert_eq!(v[0].valence, n);
        assert!((v[0].point[0] - c[0]).abs() < 1e-10 && (v[0].point[1] - c[1]).abs() < 1e-10, "{n}: {:?}", v[0]);
        // every cut is the straight segment from the centre to the image of a midpoint
        for p in &l.patches {
            let east = &p.sides[Side::East as usize];
            assert_eq!(east.degree(), 1, "{n}: a cut is not straight");
            let (a, b) = east.endpoints();
            assert_eq!(b, v[0].point);
            let mid = (0..n)
                .map(|s| {
                    let (x, y) = (polygon_vertex(n, s), polygon_vertex(n, s + 1));
                    affine([0.5 * (x[0] + y[0]), 0.5 * (x[1] + y[1])])
                })
                .fold(f64::INFINITY, |m, q| m.min((q[0] - a[0]).hypot(q[1] - a[1])));
            assert!(mid < 1e-9, "{n}: a cut does not end at a side's midpoint ({mid:.3e})");
        }
        // the patch areas sum to the polygon's
        let exact =
            (0..n).map(|k| 0.5 * (pts[k][0] * pts[(k + 1) % n][1] - pts[(k + 1) % n][0] * pts[k][1])).sum::<f64>();
        assert!((total_area(l) - exact).abs() < 1e-12 * exact, "{n}: {} vs {exact}", total_area(l));
    }
}

#[test]
fn an_l_shape_is_cut_at_its_reflex_corner() {
    let l_shape = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]];
    let auto = auto_layout(&polygon(&l_shape), &LayoutOptions::default()).unwrap();
    let r = &auto.report;
    // three rectangles: the reflex corner's two side extensions
    assert_eq!(r.cuts.len(), 2, "{:#?}", r.cuts);
    assert_eq!((r.cuts[0].from, r.cuts[1].from), ([1.0, 1.0], [1.0, 1.0]));
    assert_eq!(auto.layout.patches.len(), 3);
    assert!(r.irregular_vertices.is_empty());
    assert!((r.corner_angles[0] - 90.0).abs() < 1e-9 && (r.corner_angles[1] - 90.0).abs() < 1e-9);
    assert!((total_area(&auto.layout) - 3.0).abs() < 1e-12);
    assert!(r.corner_angles[1] < 180.0);
    // a T: four rectangles
    let t_shape = [[0.0, 0.0], [1.0, 0.0], [1.0, 2.0], [2.0, 2.0], [2.0, 3.0], [-1.0, 3.0], [-1.0, 2.0], [0.0, 2.0]];
    let auto = auto_layout(&polygon(&t_shape), &LayoutOptions::default()).unwrap();
    validate_layout(&auto.layout).unwrap();
    assert_eq!(auto.layout.patches.len(), 4, "{:#?}", auto.report.cuts);
    assert!((total_area(&auto.layout) - 5.0).abs() < 1e-12, "{}", total_area(&auto.layout));
    assert!((auto.report.corner_angles[0] - 90.0).abs() < 1e-9 && (auto.report.corner_angles[1] - 90.0).abs() < 1e-9);
}

#[test]
fn curved_pentagon_is_solved_conforming_and_certified() {
    // a pentagon whose sides bulge out (quadratic B-splines)
    let n = 5;
    let v: Vec<Point> = (0..n).map(|s| polygon_vertex(n, s)).collect();
    let sides = (0..n)
        .map(|k| {
            let (a, b) = (v[k], v[(k + 1) % n]);
            let m = [0.5 * (a[0] + b[0]) * 1.25, 0.5 * (a[1] + b[1]) * 1.25];
            SideCurve::Spline(Curve::new(KnotVector::open_uniform(2, 1), vec![a, m, b], None).unwrap())
        })
        .collect();
    let d = Domain { name: "bulge".into(), outer: Loop::new(sides), holes: Vec::new() };
    let auto = auto_layout(&d, &LayoutOptions::default()).unwrap();
    assert_eq!(auto.layout.patches.len(), 5);
    let Solved::Layout(sol) = Pipeline::new(auto.layout.clone(), Default::default()).solve().unwrap() else {
        panic!("a layout gave one map")
    };
    assert!(sol.report.verdicts.iter().all(|v| *v == Verdict::Certified), "{}", sol.report.message);
    assert_eq!(sol.report.interface_mismatch, 0.0);
    // the patch areas sum to the domain's
    let exact: f64 = d.outer.sides.iter().map(|s| if let SideCurve::Spline(c) = s { green(c) } else { 0.0 }).sum();
    let area: f64 = auto.layout.patches.iter().map(|p| patch_area(&p.sides)).sum();
    assert!((area - exact).abs() < 1e-12 * area, "{area} vs {exact}");
}

#[test]
fn domains_the_layout_refuses_are_typed_errors() {
    let two = Domain {
        name: "lens".into(),
        outer: Loop::new(vec![
            SideCurve::Spline(
                Curve::new(KnotVector::open_uniform(2, 1), vec![[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]], None).unwrap(),
            ),
            SideCurve::Spline(
                Curve::new(KnotVector::open_uniform(2, 1), vec![[2.0, 0.0], [1.0, -1.0], [0.0, 0.0]], None).unwrap(),
            ),
        ]),
        holes: Vec::new(),
    };
    let e = auto_layout(&two, &LayoutOptions::default()).unwrap_err();
    assert!(validate::names(&e, "outer loop") && e.to_string().contains("at least 3"), "{e}");
    let mut holed = polygon(&[[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]);
    holed.holes.push(polygon(&[[1.0, 1.0], [1.0, 2.0], [2.0, 2.0]]).outer);
    let e = auto_layout(&holed, &LayoutOptions::default()).unwrap_err();
    assert!(validate::names(&e, "hole 0"), "{e}");
}
