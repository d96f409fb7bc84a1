//! Tests of the contour fit.

use super::*;
use crate::boundary::cord_length::cord_length_params;
use std::f64::consts::PI;

fn uniform_fit_errors(f: &SideCurve, p: usize, sizes: &[usize]) -> Vec<f64> {
    sizes
        .iter()
        .map(|&ne| {
            let kv = KnotVector::open_uniform(p, ne);
            let (a, b) = f.endpoints();
            project_side(f, &kv, (a, b)).unwrap().max_error
        })
        .collect()
}

#[test]
fn polynomials_are_reproduced() {
    // a cubic B-spline on one element and a quadratic curve with an inner knot at 0.3
    let kv = KnotVector::new(3, vec![0., 0., 0., 0., 1., 1., 1., 1.]).unwrap();
    let c = Curve::new(kv, vec![[0., 0.], [0.3, 0.4], [0.7, -0.2], [1., 0.1]], None).unwrap();
    let side = SideCurve::Spline(c.clone());
    for p in 3..=5 {
        let fit =
            fit_side(Side::South, &side, c.endpoints(), &FitOptions { degree: p, ..Default::default() }, 1e-6).unwrap();
        assert_eq!(fit.levels.len(), 1);
        assert!(fit.converged);
        assert!(fit.max_error[0] < 1e-13, "p={p}: {}", fit.max_error[0]);
    }
    let an = SideCurve::Analytic(Analytic::new(|t| [t, 2.0 * t * t - t]));
    let fit =
        fit_side(Side::West, &an, ([0., 0.], [1., 1.]), &FitOptions { degree: 2, ..Default::default() }, 1e-8).unwrap();
    assert_eq!(fit.levels.len(), 1);
    assert!(fit.max_error[0] < 1e-13);
}

#[test]
fn convergence_order_is_p_plus_one() {
    let f = SideCurve::Analytic(Analytic::new(|t| [t, (2.0 * PI * t).sin()]));
    for p in 2..=4 {
        let sizes = [8, 16, 32, 64];
        let e = uniform_fit_errors(&f, p, &sizes);
        let orders: Vec<f64> = e.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        let last = *orders.last().unwrap();
        assert!((last - (p + 1) as f64).abs() < 0.5, "p={p} errors {e:?} orders {orders:?}");
    }
}

#[test]
fn two_point_cloud_is_a_uniform_segment() {
    let side = SideCurve::Points(vec![[0., 0.], [2., 1.]]);
    let fit = fit_side(Side::East, &side, ([0., 0.], [2., 1.]), &FitOptions::default(), 1e-6).unwrap();
    assert!(fit.converged);
    let c = fit.finest();
    for k in 0..=10 {
        let t = k as f64 / 10.0;
        let x = c.eval(t);
        assert!((x[0] - 2.0 * t).abs() < 1e-12 && (x[1] - t).abs() < 1e-12, "{t} {x:?}");
    }
    assert_eq!(fit.params.as_deref(), Some(&[0.0, 1.0][..]));
}

#[test]
fn bad_options_and_inputs_are_errors() {
    let side = SideCurve::Points(vec![[0., 0.]]);
    let o = FitOptions::default();
    assert!(matches!(fit_side(Side::South, &side, ([0., 0.], [0., 0.]), &o, 1e-3), Err(Error::TooFewPoints { .. })));
    let side = SideCurve::Points(vec![[0., 0.], [0., 0.]]);
    assert!(matches!(fit_side(Side::South, &side, ([0., 0.], [0., 0.]), &o, 1e-3), Err(Error::DegenerateSide { .. })));
    let side = SideCurve::Points(vec![[0., 0.], [1., 0.]]);
    for bad in [
        FitOptions { degree: 1, ..o },
        FitOptions { tol: 0.0, ..o },
        FitOptions { tol: f64::NAN, ..o },
        FitOptions { initial_elements: 0, ..o },
        FitOptions { max_levels: 0, ..o },
    ] {
        assert!(fit_side(Side::South, &side, ([0., 0.], [1., 0.]), &bad, 1e-3).is_err());
    }
    let nan = SideCurve::Analytic(Analytic::new(|t| [t, if t > 0.5 { f64::NAN } else { 0.0 }]));
    assert!(fit_side(Side::South, &nan, ([0., 0.], [1., 0.]), &o, 1e-3).is_err());
}

#[test]
fn adaptive_refinement_is_local_and_nested() {
    // a curve with a sharp feature near t = 0.8 (a narrow Gaussian bump)
    let f = SideCurve::Analytic(Analytic::new(|t| [t, 0.2 * (-((t - 0.8) / 0.03).powi(2)).exp()]));
    let fit = fit_side(Side::South, &f, f.endpoints(), &FitOptions::default(), 1e-5).unwrap();
    assert!(fit.converged);
    assert!(fit.final_max_error() <= 1e-5);
    for w in fit.levels.windows(2) {
        assert!(w[1].knots.contains(&w[0].knots));
    }
    let el = fit.finest().knots.elements();
    let h_min = el.iter().map(|e| e.2 - e.1).fold(1.0, f64::min);
    let h_max = el.iter().map(|e| e.2 - e.1).fold(0.0, f64::max);
    assert!(h_max >= 8.0 * h_min, "refinement should be local: h in [{h_min}, {h_max}]");
    // dyadic knots
    for &u in fit.finest().knots.knots() {
        let s = u * 65536.0;
        assert_eq!(s, s.round());
    }
}

#[test]
fn element_cap_stops_refinement() {
    let f = SideCurve::Analytic(Analytic::new(|t| [t, (40.0 * t).sin()]));
    let o = FitOptions { max_elements: 6, ..Default::default() };
    let fit = fit_side(Side::South, &f, f.endpoints(), &o, 1e-9).unwrap();
    assert!(!fit.converged);
    assert!(fit.finest().knots.num_elements() <= 6);
}

/// A polygon given as a point cloud, fitted with its interior vertices as kinks: the fit
/// has a knot of multiplicity `p` at each vertex's abscissa, its control point there is
/// the vertex (bit for bit), so the curve passes through it to rounding, and it follows
/// the edges (sampled points on segments).
#[test]
fn kinked_polygon_keeps_its_vertices_exactly() {
    let verts: [Point; 5] = [[0.0, 0.0], [1.0, 0.2], [1.6, 1.0], [2.5, 0.7], [3.0, 0.0]];
    let mut pts = Vec::new();
    for w in verts.windows(2) {
        for k in 0..10 {
            let t = k as f64 / 10.0;
            pts.push([w[0][0] + t * (w[1][0] - w[0][0]), w[0][1] + t * (w[1][1] - w[0][1])]);
        }
    }
    pts.push(verts[4]);
    let params = cord_length_params(&pts).unwrap();
    let kinks: Vec<(f64, Point)> = [10, 20, 30].iter().map(|&j| (params[j], pts[j])).collect();
    let side = SideCurve::Points(pts.clone());
    let o = FitOptions::default();
    let fit = fit_side_kinked(Side::South, &side, &SideParam::Native, (verts[0], verts[4]), &o, 1e-6, &kinks).unwrap();
    assert!(fit.converged);
    let c = fit.finest();
    for &(t, x) in &kinks {
        assert_eq!(c.knots.multiplicity(t), 3, "knots {:?}", c.knots.knots());
        assert!(c.control_points.contains(&x), "the vertex is a control point");
        let y = c.eval(t);
        assert!((y[0] - x[0]).abs() <= 1e-15 * 3.0 && (y[1] - x[1]).abs() <= 1e-15 * 3.0, "{y:?} vs {x:?}");
    }
    // straight edges: every point of the cloud (on the segments) lies on the fit
    for (&t, p) in params.iter().zip(&pts) {
        let y = c.eval(t);
        assert!((y[0] - p[0]).hypot(y[1] - p[1]) < 1e-9, "{t}: {y:?} vs {p:?}");
    }
    // without kinks the vertices are rounded
    let smooth = fit_side(Side::South, &side, (verts[0], verts[4]), &o, 1e-6).unwrap();
    assert!(smooth.finest().knots.breaks_with_multiplicity().iter().all(|b| b.1 < 3 || b.0 == 0.0 || b.0 == 1.0));
}
