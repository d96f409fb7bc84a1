//! Adaptive contour fitting and the hierarchy of tensor bases (paper §5) on the shared
//! geometries (copies under `tests/data/`).

use std::f64::consts::PI;

use serde_json::Value;
use winslow::boundary::cord_length::cord_length_params;
use winslow::boundary::fit::project_side;
use winslow::testutil::data_dir;
use winslow::{build_hierarchy, Analytic, Boundary, Curve, FitOptions, Hierarchy, KnotVector, Point, Side, SideCurve};

fn point(v: &Value) -> Point {
    let a = v.as_array().expect("point is an array");
    [a[0].as_f64().unwrap(), a[1].as_f64().unwrap()]
}

/// A tiny reader of the boundary documents of `formats.md` (test-only).
fn side_from_json(v: &Value) -> SideCurve {
    if let Some(pts) = v.get("points") {
        return SideCurve::Points(pts.as_array().unwrap().iter().map(point).collect());
    }
    let degree = v["degree"].as_u64().unwrap() as usize;
    let knots = v["knots"].as_array().unwrap().iter().map(|k| k.as_f64().unwrap()).collect();
    let kv = KnotVector::new(degree, knots).unwrap().normalized();
    let cps = v["control_points"].as_array().unwrap().iter().map(point).collect();
    let weights = v.get("weights").and_then(|w| w.as_array()).map(|w| w.iter().map(|x| x.as_f64().unwrap()).collect());
    SideCurve::Spline(Curve::new(kv, cps, weights).unwrap())
}

fn load(rel: &str) -> Boundary {
    let path = data_dir().join(rel);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let doc: Value = serde_json::from_str(&text).unwrap();
    let b = &doc["boundary"];
    let sides = ["south", "east", "north", "west"].map(|s| side_from_json(&b[s]));
    Boundary { name: doc["name"].as_str().unwrap_or(rel).to_string(), sides }
}

const GEOMETRIES: [&str; 19] = [
    "horseshoe.json",
    "narrow_tube.json",
    "notched_square.json",
    "quarter_annulus.json",
    "spiral_channel.json",
    "wavy_lid.json",
    "gismo/butterfly.json",
    "gismo/cooks_membrane.json",
    "gismo/disk.json",
    "gismo/duck.json",
    "gismo/flapping_beam.json",
    "gismo/jigsaw01.json",
    "gismo/lake.json",
    "gismo/male_casing_ring.json",
    "gismo/male_rotor.json",
    "gismo/plate_with_hole.json",
    "gismo/puzzle3.json",
    "gismo/puzzle4.json",
    "gismo/rotor_sector.json",
];

/// The fitted basis (§5): what these tests are about (the default `Auto` keeps spline
/// sides in their own basis).
/// The fitted basis with the dyadic `C^{p-1}` fits of §5 only: these tests are about the
/// fit itself (kinks kept by knots of multiplicity p: tests/kinks.rs).
fn fitted() -> FitOptions {
    let mut o = FitOptions::default();
    o.basis = winslow::boundary::BasisChoice::Fitted;
    o.kinks = winslow::boundary::KinkMode::None;
    o
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn check_hierarchy(name: &str, b: &Boundary, h: &Hierarchy) {
    let tol_corner = 1e-9 * h.diameter;
    for fit in &h.fits {
        let s = fit.side;
        assert!(fit.converged, "{name} {s}: not converged, errors {:?}", fit.max_error);
        assert!(fit.final_max_error() <= h.tol_abs, "{name} {s}: {} > {}", fit.final_max_error(), h.tol_abs);
        assert_eq!(fit.levels.len(), fit.max_error.len());
        assert_eq!(fit.levels.len(), fit.rms_error.len());
        for w in fit.levels.windows(2) {
            assert!(w[1].knots.contains(&w[0].knots), "{name} {s}: side levels not nested");
        }
        let (a, e) = b.side(s).endpoints();
        for c in &fit.levels {
            assert_eq!(c.degree(), 3);
            assert!(!c.is_rational());
            assert_eq!(c.domain(), (0.0, 1.0));
            // exact corner interpolation: the end control points are the corners
            assert!(
                dist(c.control_points[0], a) <= tol_corner && dist(*c.control_points.last().unwrap(), e) <= tol_corner
            );
        }
    }
    // all four corners are shared exactly by adjacent sides on every level
    for (k, lvl) in h.levels.iter().enumerate() {
        let [s, e, n, w] = lvl.sides.each_ref().map(|c| (c.control_points[0], *c.control_points.last().unwrap()));
        assert_eq!(s.0, w.0, "{name} level {k}: SW corner");
        assert_eq!(s.1, e.0, "{name} level {k}: SE corner");
        assert_eq!(n.1, e.1, "{name} level {k}: NE corner");
        assert_eq!(n.0, w.1, "{name} level {k}: NW corner");
        // opposite sides share one knot vector
        assert_eq!(lvl.side(Side::South).knots, lvl.knots[0]);
        assert_eq!(lvl.side(Side::North).knots, lvl.knots[0]);
        assert_eq!(lvl.side(Side::East).knots, lvl.knots[1]);
        assert_eq!(lvl.side(Side::West).knots, lvl.knots[1]);
        if k > 0 {
            let prev = &h.levels[k - 1];
            assert!(
                lvl.knots[0].contains(&prev.knots[0]) && lvl.knots[1].contains(&prev.knots[1]),
                "{name}: levels not nested"
            );
            assert_ne!(lvl.knots, prev.knots, "{name}: duplicate level {k}");
            assert!(lvl.num_basis() > prev.num_basis());
        }
    }
    // the finest level's sides are the finest fits, exactly (prolongation keeps the curve)
    let fin = h.finest();
    for fit in &h.fits {
        let (c, f) = (fit.finest(), fin.side(fit.side));
        for i in 0..=50 {
            let t = i as f64 / 50.0;
            assert!(dist(c.eval(t), f.eval(t)) < 1e-12 * h.diameter, "{name}: prolongation changed {}", fit.side);
        }
    }
}

#[test]
fn shared_geometries_fit_within_tolerance() {
    let opts = fitted();
    let mut table = String::from("geometry            levels  basis sizes (n_xi x n_eta) per level\n");
    for rel in GEOMETRIES {
        let b = load(rel);
        let h = build_hierarchy(&b, &opts).unwrap_or_else(|e| panic!("{rel}: {e}"));
        check_hierarchy(rel, &b, &h);
        let sizes: Vec<String> =
            h.levels.iter().map(|l| format!("{}x{}", l.knots[0].num_basis(), l.knots[1].num_basis())).collect();
        table.push_str(&format!("{:<20}{:>6}  {}\n", b.name, h.levels.len(), sizes.join(" ")));
    }
    println!("{table}");
}

#[test]
fn point_clouds_use_cord_length_and_meet_tolerance() {
    // without reparameterization (the default `auto` would constrain the narrow pairs)
    let mut opts = fitted();
    opts.reparam.method = winslow::boundary::reparam::Reparam::None;
    for rel in ["narrow_tube.json", "notched_square.json", "spiral_channel.json"] {
        let b = load(rel);
        let h = build_hierarchy(&b, &opts).unwrap();
        for fit in &h.fits {
            let SideCurve::Points(pts) = b.side(fit.side) else {
                assert!(fit.params.is_none());
                continue;
            };
            let params = fit.params.as_ref().expect("point clouds report their abscissae");
            // eq. 36-37, computed independently
            let total: f64 = pts.windows(2).map(|w| dist(w[0], w[1])).sum();
            let mut l = 0.0;
            for (j, &xi) in params.iter().enumerate() {
                if j > 0 {
                    l += dist(pts[j - 1], pts[j]);
                }
                assert!((xi - l / total).abs() < 1e-14, "{rel} {}: abscissa {j}", fit.side);
            }
            assert_eq!(params.first(), Some(&0.0));
            assert_eq!(params.last(), Some(&1.0));
            assert_eq!(cord_length_params(pts).as_ref(), Some(params));
            // the reported error is the deviation at those abscissae
            let c = fit.finest();
            let max = params.iter().zip(pts).map(|(&t, &p)| dist(c.eval(t), p)).fold(0.0, f64::max);
            assert!((max - fit.final_max_error()).abs() <= 1e-15 * h.diameter);
            assert!(max <= h.tol_abs, "{rel} {}: {max} > {}", fit.side, h.tol_abs);
        }
    }
}

#[test]
fn convergence_orders_under_uniform_halving() {
    let curves = [
        ("sine", SideCurve::Analytic(Analytic::new(|t| [t, (2.0 * PI * t).sin()]))),
        ("arc", SideCurve::Analytic(Analytic::new(|t| [(0.5 * PI * t).cos(), (0.5 * PI * t).sin()]))),
    ];
    for (name, f) in &curves {
        for p in 2..=4 {
            let mut kv = KnotVector::open_uniform(p, 4);
            let mut errors = Vec::new();
            for _ in 0..5 {
                errors.push(project_side(f, &kv, f.endpoints()).unwrap().max_error);
                kv = kv.halved();
            }
            let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
            let es: Vec<String> = errors.iter().map(|e| format!("{e:.3e}")).collect();
            println!("{name} p={p}: max errors {es:?}, observed orders {orders:.2?}");
            let last = orders[orders.len() - 1];
            assert!((last - (p + 1) as f64).abs() < 0.5, "{name} p={p}: orders {orders:?}");
        }
    }
}

#[test]
fn low_degree_sides_are_reproduced_on_the_coarsest_level() {
    // A cubic NURBS-free spline side with two inner knots: a degree-3 fit needs refinement,
    // but a straight segment and a single cubic segment are exact at level 0.
    let seg = KnotVector::new(3, vec![0., 0., 0., 0., 1., 1., 1., 1.]).unwrap();
    let south = Curve::new(seg.clone(), vec![[0., 0.], [0.4, -0.1], [0.7, 0.1], [1., 0.]], None).unwrap();
    let east = Curve::new(KnotVector::new(1, vec![0., 0., 1., 1.]).unwrap(), vec![[1., 0.], [1., 1.]], None).unwrap();
    let north = Curve::new(
        KnotVector::new(2, vec![0., 0., 0., 1., 1., 1.]).unwrap(),
        vec![[0., 1.], [0.5, 1.3], [1., 1.]],
        None,
    )
    .unwrap();
    let west = SideCurve::Analytic(Analytic::new(|t| [0.1 * t * (1.0 - t), t]));
    let b = Boundary {
        name: "polynomial".into(),
        sides: [SideCurve::Spline(south), SideCurve::Spline(east), SideCurve::Spline(north), west],
    };
    let h = build_hierarchy(&b, &fitted()).unwrap();
    assert_eq!(h.levels.len(), 1);
    assert_eq!(h.finest().num_basis(), 16);
    for fit in &h.fits {
        assert_eq!(fit.levels.len(), 1);
        assert!(fit.max_error[0] < 1e-13, "{}: {}", fit.side, fit.max_error[0]);
    }
}

#[test]
fn other_degrees_and_initial_meshes_converge() {
    for (p, ie) in [(2, 1), (4, 3), (5, 2)] {
        let mut opts = fitted();
        (opts.degree, opts.initial_elements) = (p, ie);
        for rel in GEOMETRIES {
            let h = build_hierarchy(&load(rel), &opts).unwrap();
            assert!(h.converged(), "{rel} p={p} ie={ie}");
            assert!(h.max_error() <= h.tol_abs, "{rel} p={p} ie={ie}");
            assert!(h.levels.iter().all(|l| l.knots[0].degree() == p && l.knots[1].degree() == p));
            assert!(h.levels[0].knots.iter().all(|k| k.num_elements() == ie));
        }
    }
}

#[test]
fn point_cloud_fits_stay_near_the_polyline_between_points() {
    // Between the points nothing is measured; the fit should still follow the polyline.
    // Smooth clouds stay within the tolerance; at the sharp V of the notched square the
    // smooth fit overshoots the polyline slightly (a few tolerances).
    for (rel, factor) in [("narrow_tube.json", 1.0), ("spiral_channel.json", 1.0), ("notched_square.json", 4.0)] {
        let b = load(rel);
        let h = build_hierarchy(&b, &fitted()).unwrap();
        for fit in &h.fits {
            let SideCurve::Points(pts) = b.side(fit.side) else {
                continue;
            };
            let params = fit.params.as_ref().unwrap();
            let c = fit.finest();
            let mut worst = 0.0f64;
            for i in 0..=8000 {
                let t = i as f64 / 8000.0;
                let x = c.eval(t);
                let j = params.partition_point(|&u| u <= t).clamp(1, pts.len() - 1) - 1;
                let lo = j.saturating_sub(4);
                let hi = (j + 5).min(pts.len() - 1);
                let d = (lo..hi).map(|k| seg_dist(x, pts[k], pts[k + 1])).fold(f64::INFINITY, f64::min);
                worst = worst.max(d);
            }
            assert!(worst <= factor * h.tol_abs, "{rel} {}: {worst:e} vs tol {:e}", fit.side, h.tol_abs);
        }
    }
}

fn seg_dist(x: Point, a: Point, b: Point) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let t = if l2 > 0.0 { (((x[0] - a[0]) * d[0] + (x[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0) } else { 0.0 };
    dist(x, [a[0] + t * d[0], a[1] + t * d[1]])
}
