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
/// orientation verdicts must still agree. Since then the validator refuses a contour
/// whose area is within that bound of zero (`Error::DegenerateContour`): it has no
/// orientation to agree on.
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
    // the situation of the crash: the corner gaps can change the area by more than the
    // area itself, so the contour has no orientation; both readings now say so
    for r in [validate(&b.transposed()), winslow::boundary::validate::inspect(&b)] {
        match r {
            Err(winslow::Error::DegenerateContour { area, bound }) => assert!(area.abs() <= bound, "{area} {bound}"),
            other => panic!("expected a degenerate contour, got {other:?}"),
        }
    }
}
