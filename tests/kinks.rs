//! Kinks kept exactly (paper §9, `--kinks`): the `C^0` route (EGG on the smoothed basis
//! `Σ¹`, elasticity to the kinked boundary, Winslow on `Σ⁰`) on plate_with_hole's
//! zero-speed point, rotor_sector's `C^0` knots and a star-shaped polygon, on the input
//! and the fitted basis: the map passes through every kink (deviation at rounding level),
//! has a knot line of multiplicity `p` there, and is certified.

use winslow::boundary::kinks::{KinkKind, KinkMode};
use winslow::boundary::BasisChoice;
use winslow::io::{read_boundary, ReadOptions};
use winslow::solve;
use winslow::solve::options::{KinksLocal, SolveOptions};
use winslow::solve::report::{Solution, Verdict};
use winslow::verify::certificate::{certify, CertifyOptions, Finding};
use winslow::Boundary;

fn boundary(file: &str) -> Boundary {
    let path = winslow::testutil::data(file);
    read_boundary(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{file}: {e}"))
}

fn opts(basis: BasisChoice, kinks: KinkMode) -> SolveOptions {
    let mut o = SolveOptions::default();
    o.fit.basis = basis;
    o.fit.kinks = kinks;
    // coarse: these tests are about the kinks, not the resolution
    o.fit.tol = 1e-3;
    o
}

fn run(file: &str, o: &SolveOptions) -> (Boundary, Solution) {
    let b = boundary(file);
    let sol = solve(&b, o).unwrap_or_else(|e| panic!("{file}: {e}"));
    (b, sol)
}

/// Every kink of the report is kept, passes through its input point to `1e-12` of the
/// diameter, and the map's knot vector along it holds the kink with multiplicity `p`.
fn kinks_kept(sol: &Solution, expect: usize) {
    let r = &sol.report;
    assert_eq!(r.boundary.kinks.len(), expect, "{:#?}", r.boundary.kinks);
    assert!(r.boundary.c0_route.as_ref().is_some_and(|c| c.kept), "{}", r.outcome.message);
    for k in &r.boundary.kinks {
        assert!(k.kept, "{k:?}");
        assert!(k.deviation <= 1e-12 * r.fit.diameter, "{k:?}");
        let t = k.map_parameter.expect("a kept kink has its knot line");
        let d = if k.side == "south" || k.side == "north" { 0 } else { 1 };
        let kv = &sol.map.knots[d];
        assert_eq!(kv.multiplicity(t), kv.degree(), "{k:?}: knots {:?}", kv.knots());
    }
}

/// rotor_sector's south and north sides carry a `C^0` knot (35.8 degrees on north,
/// tangent-continuous on south): on the input basis the map keeps the input curves
/// exactly (boundary deviation at rounding level) with a `C^0` knot line there, certified.
#[test]
fn rotor_sector_keeps_its_c0_knots_on_the_input_basis() {
    let (_, sol) = run("gismo/rotor_sector.json", &opts(BasisChoice::Input, KinkMode::Auto));
    let r = &sol.report;
    assert_eq!(r.outcome.verdict, Verdict::Certified, "{}", r.outcome.message);
    assert_eq!(r.setup.basis.used, BasisChoice::Input);
    assert!(r.setup.basis.kinks.is_some());
    kinks_kept(&sol, 2);
    assert!(r.boundary.kinks.iter().any(|k| k.side == "north" && (k.turning_degrees - 35.83).abs() < 0.01));
    assert!(r.boundary.kinks.iter().all(|k| k.kind == KinkKind::C0Knot));
    let dev = r.boundary.deviation.iter().fold(0.0f64, |m, &d| m.max(d));
    assert!(dev <= 1e-12 * r.fit.diameter, "boundary deviation {dev}");
    // the Winslow stage on Σ⁰ lowered the functional from its start
    let c = r.boundary.c0_route.as_ref().unwrap();
    assert!(c.winslow[1].unwrap() <= c.winslow[0].unwrap(), "{c:?}");
    // `--kinks none` does not round them silently: the input basis is refused, and why
    let (_, none) = run("gismo/rotor_sector.json", &opts(BasisChoice::Input, KinkMode::None));
    assert_eq!(none.report.setup.basis.used, BasisChoice::Fitted);
    assert!(
        none.report.setup.basis.fallback.as_deref().is_some_and(|w| w.contains("C0")),
        "{:?}",
        none.report.setup.basis
    );
    let north = none.report.boundary.kinks.iter().find(|k| k.side == "north").expect("the rounded kink is reported");
    assert!(!north.kept && north.deviation > 1e-9, "{north:?}");
}

/// On the fitted basis rotor_sector's north kink is kept (south is tangent-continuous
/// there, nothing to keep on a fitted basis).
#[test]
fn rotor_sector_keeps_its_kink_on_the_fitted_basis() {
    let (_, sol) = run("gismo/rotor_sector.json", &opts(BasisChoice::Fitted, KinkMode::Auto));
    assert_eq!(sol.report.outcome.verdict, Verdict::Certified, "{}", sol.report.outcome.message);
    kinks_kept(&sol, 1);
}

/// plate_with_hole's north side turns 90 degrees where its speed vanishes (a repeated
/// control point). On the input basis every map of that parameterization has det J = 0
/// there: the kink is kept exactly and the certificate excuses only that point (proving
/// det J > 0 everywhere else); auto then prefers the fitted basis, which fits the side by
/// cord length, keeps the kink exactly and certifies.
#[test]
fn plate_with_hole_keeps_its_zero_speed_kink() {
    let (_, sol) = run("gismo/plate_with_hole.json", &opts(BasisChoice::Input, KinkMode::Auto));
    let r = &sol.report;
    assert_eq!(r.outcome.verdict, Verdict::DegenerateCorner, "{}", r.outcome.message);
    kinks_kept(&sol, 1);
    assert_eq!(r.boundary.kinks[0].kind, KinkKind::ZeroSpeed);
    let c = &r.outcome.certificate;
    assert_eq!(c.excused_points.len(), 1, "{:?}", c.excused_points);
    assert!((c.excused_points[0].point[0] + 4.0).abs() < 1e-12 && (c.excused_points[0].point[1] - 4.0).abs() < 1e-12);
    assert!(c.corners.iter().all(|k| k.excused_extent.is_none()));
    let ext = c.excused_points[0].extent;
    assert!(ext[0] < 1e-3 && ext[1] < 1e-3, "the excused neighbourhood shrinks: {ext:?}");
    let dev = r.boundary.deviation.iter().fold(0.0f64, |m, &d| m.max(d));
    assert!(dev <= 1e-12 * r.fit.diameter, "boundary deviation {dev}");

    let (_, auto) = run("gismo/plate_with_hole.json", &opts(BasisChoice::Auto, KinkMode::Auto));
    let r = &auto.report;
    assert_eq!(r.outcome.verdict, Verdict::Certified, "{}", r.outcome.message);
    assert_eq!(r.setup.basis.used, BasisChoice::Fitted);
    assert!(r.setup.basis.fallback.as_deref().is_some_and(|w| w.contains("zero speed")), "{:?}", r.setup.basis);
    kinks_kept(&auto, 1);
}

/// A fold next to a zero-speed point is still a fold: the point's excuse does not cover
/// a negative det J nearby (none is forced there).
#[test]
fn a_fold_next_to_a_zero_speed_point_is_a_fold() {
    let (_, sol) = run("gismo/plate_with_hole.json", &opts(BasisChoice::Input, KinkMode::Auto));
    let mut map = sol.map.clone();
    let [nx, ny] = map.shape();
    // the control point next to the kink's knot line, one row in from the north side,
    // pushed far out beyond the north-west corner of the plate
    let d = |i: usize| (map.cp(i, ny - 1)[0] + 4.0).hypot(map.cp(i, ny - 1)[1] - 4.0);
    let i = (0..nx).min_by(|&a, &b| d(a).total_cmp(&d(b))).unwrap();
    assert!(d(i) < 1e-12, "the kink's control point");
    map.control_points[(ny - 2) * nx + i] = [-6.0, 6.0];
    let c = certify(&map, &CertifyOptions::default()).unwrap();
    assert!(matches!(c.verdict, Finding::Folded { .. }), "{}", c.message());
}

/// An eight-pointed star given as a 16-vertex polygon (three interior kinks per side, six
/// per pair of opposite sides, like the paper's Fig. 16): certified with every vertex
/// kept exactly; with `--kinks none` the fit rounds them (far from the polygon).
#[test]
fn star_polygon_certifies_with_its_kinks_kept() {
    let (_, sol) = run("contours/star8.json", &opts(BasisChoice::Auto, KinkMode::Auto));
    let r = &sol.report;
    assert_eq!(r.outcome.verdict, Verdict::Certified, "{}", r.outcome.message);
    kinks_kept(&sol, 12);
    let dev = r.boundary.deviation.iter().fold(0.0f64, |m, &d| m.max(d));
    assert!(dev <= 1e-12 * r.fit.diameter, "the straight edges are exact: {dev}");
    let (_, none) = run("contours/star8.json", &opts(BasisChoice::Auto, KinkMode::None));
    assert!(none.report.boundary.kinks.iter().all(|k| !k.kept));
    let dev = none.report.boundary.deviation.iter().fold(0.0f64, |m, &d| m.max(d));
    assert!(dev > 1e-2 * none.report.fit.diameter, "without kinks the polygon is rounded: {dev}");
}

/// An L-shaped polygon: its reflex corner and the convex one opposite it are kinks inside
/// sides; the C0 route's elasticity continuation has to refine around the reflex corner
/// before its map on the kinked basis is certified. Both kinks kept exactly, certified.
/// (With extrapolated steps in the continuation's damped Winslow solves the map folded
/// between quadrature points near the corner and the kinks were dropped.)
#[test]
fn l_shape_certifies_with_its_reflex_corner_kept() {
    let (_, sol) = run("contours/l_shape.json", &opts(BasisChoice::Auto, KinkMode::Auto));
    let r = &sol.report;
    assert_eq!(r.outcome.verdict, Verdict::Certified, "{}", r.outcome.message);
    kinks_kept(&sol, 2);
    let c0 = r.boundary.c0_route.as_ref().expect("the C0 route ran");
    assert!(c0.failure.is_none(), "{}", c0.message);
}

/// `kinks_local` (§9, last paragraph): the final Winslow minimisation moves only the
/// control points near the kink. It runs on fewer unknowns from the same elasticity start,
/// over a subspace of the global one, so its Winslow value lies between the start's and
/// the global minimiser's; the kink is kept and the map certified all the same.
#[test]
fn the_local_winslow_stage_moves_only_the_control_points_near_the_kinks() {
    let global = opts(BasisChoice::Auto, KinkMode::Auto);
    let mut local = global.clone();
    local.kinks_local = KinksLocal::Spans(1);
    let (_, g) = run("notched_square.json", &global);
    let (_, l) = run("notched_square.json", &local);
    for sol in [&g, &l] {
        assert_eq!(sol.report.outcome.verdict, Verdict::Certified, "{}", sol.report.outcome.message);
        kinks_kept(sol, 1);
    }
    let (cg, cl) = (g.report.boundary.c0_route.as_ref().unwrap(), l.report.boundary.c0_route.as_ref().unwrap());
    assert_eq!((cg.local_spans, cl.local_spans), (None, Some(1)));
    assert!(0 < cl.unknowns && cl.unknowns < cg.unknowns / 2, "{} of {}", cl.unknowns, cg.unknowns);
    let ([start, wg], [start_l, wl]) = (cg.winslow.map(Option::unwrap), cl.winslow.map(Option::unwrap));
    assert_eq!(start, start_l, "the same elasticity start");
    assert!(wg <= wl + 1e-12 && wl < start, "global {wg}, local {wl}, start {start}");
}
