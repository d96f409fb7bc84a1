//! Inputs found by the coverage-guided fuzz targets (`fuzz/`, `scripts/fuzz.sh`), kept as
//! regression tests of the normal suite: each went wrong once and must now be handled
//! (a typed error or a consistent result, never a panic or a violated property of
//! `winslow::testutil::exercise`). Text inputs live under `tests/data/fuzz/TARGET/`;
//! structured ones (targets `point_cloud`, `validate`) are written out here.

use winslow::boundary::validate::validate;
use winslow::boundary::{Boundary, SideCurve};
use winslow::spline::curve::{Curve, Point};
use winslow::spline::knots::KnotVector;
use winslow::testutil::exercise::exercise_sides;

fn polyline(points: Vec<Point>) -> SideCurve {
    let kv = KnotVector::open_uniform(1, points.len() - 1);
    SideCurve::Spline(Curve::new(kv, points, None).unwrap())
}

/// Target `validate`, crash-f933775c: a contour of spikes 1e9 long around a cluster of
/// points within 3 of the origin. Its corner gaps are within the tolerance
/// (`1e-9` of the diameter, about 1.4) but as large as the cluster, so which side's end
/// stands for a corner moves a vertex by up to 1.4 at the foot of a 1e9 spike: the
/// signed area of the transposed contour differed from the original's by 4 %. The
/// property checked by `exercise` was too strict (relative 1e-9); it now allows the
/// change that corner gaps can cause (`2 * sum(gaps) * diameter` plus rounding), and the
/// orientation verdicts must still agree.
#[test]
fn validate_spikes_with_corner_gaps_as_large_as_the_domain() {
    let t = f64::MIN_POSITIVE;
    let e = 1.0 + f64::EPSILON;
    let g = |k: f64| k / 16.0;
    let south = polyline(vec![[t, t], [t, t], [1e9, g(41.)], [t, e]]);
    let east = polyline(vec![
        [t, t],
        [g(-81.), t],
        [t, t],
        [t, t],
        [t, 1e9],
        [g(41.), t],
        [1e-308, t],
        [t, t],
        [g(-81.), t],
        [t, t],
    ]);
    let north = polyline(vec![[t, t], [t, t], [0.0, g(41.)], [g(41.), g(41.)], [g(41.), t], [t, 1e-308]]);
    let west = SideCurve::Points(vec![
        [t, t],
        [t, e],
        [t, t],
        [t, t],
        [t, t],
        [t, t],
        [g(-42.), g(41.)],
        [t, t],
        [t, e],
        [t, t],
        [t, t],
        [t, g(32.)],
        [t, t],
        [t, t],
        [0.0, 0.0],
    ]);
    let b = Boundary { name: String::new(), sides: [south, east, north, west] };
    let trace = exercise_sides(b.sides.clone());
    assert!(trace.violations.is_empty(), "{trace:?}");
    // the situation of the crash: both orientations are read, with areas 4 % apart
    let transposed = validate(&b.transposed()).unwrap();
    let original = winslow::boundary::validate::inspect(&b).unwrap();
    assert!(original.signed_area < 0.0 && transposed.signed_area > 0.0);
    let relative = (transposed.signed_area + original.signed_area).abs() / transposed.signed_area;
    assert!(relative > 1e-2, "{relative}");
    assert!(original.corner_gaps.iter().sum::<f64>() > 0.1, "{:?}", original.corner_gaps);
}
