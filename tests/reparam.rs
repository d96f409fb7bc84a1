//! Boundary reparameterization (paper §7) on the shared geometries: the default `auto`
//! choice picks constrained cord length where opposite sides come close, the matched
//! pairs lie at the same parameter on both fitted sides, and the maps are certified
//! bijective (exact Bernstein bounds of det J), which a dense sample confirms.

use winslow::boundary::reparam::Reparam;
use winslow::io::{read_boundary, ReadOptions};
use winslow::solve;
use winslow::solve::options::SolveOptions;
use winslow::solve::report::{Solution, Verdict};
use winslow::verify::quality::sample_det_j;
use winslow::{build_hierarchy, Boundary, FitOptions, Side};

fn boundary(file: &str) -> Boundary {
    let path = winslow::testutil::data(file);
    read_boundary(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// The fitted basis, where the reparameterization (§7) applies (the default `Auto` keeps
/// spline sides in their own basis, parameterization included).
fn fitted() -> SolveOptions {
    let mut o = SolveOptions::default();
    o.fit.basis = winslow::boundary::BasisChoice::Fitted;
    o
}

fn with(method: Reparam) -> SolveOptions {
    let mut o = fitted();
    o.fit.reparam.method = method;
    o
}

fn assert_positive(file: &str, sol: &Solution) {
    let r = &sol.report;
    assert_eq!(r.outcome.verdict, Verdict::Certified, "{file}: {}", r.outcome.message);
    let s = sample_det_j(&sol.map, 600);
    assert!(s.min_interior > 0.0, "{file}: det J min {} at {:?}", s.min_interior, s.argmin);
    assert!(r.measures.quality.scaled_jacobian.min > 0.0);
    // the contour is preserved: the map's boundary is the input's to the fit tolerance
    // (measured against the input's polyline, whose corners a smooth fit may cut a little)
    let dev = r.boundary.deviation.iter().cloned().fold(0.0, f64::max);
    assert!(
        dev <= 4.0 * r.fit.fit_tolerance,
        "{file}: boundary deviation {dev:.3e}, tolerance {:.3e}",
        r.fit.fit_tolerance
    );
}

/// Matched pairs lie at the same parameter on the two fitted sides: evaluating both
/// fitted curves at the match's parameter gives the matched points, to the fit tolerance.
fn assert_matches_on_fit(b: &Boundary, opts: &FitOptions) -> usize {
    let h = build_hierarchy(b, opts).unwrap();
    for m in &h.reparam.matches {
        let (s1, s2) = match m.sides {
            ["south", "north"] => (Side::South, Side::North),
            ["west", "east"] => (Side::West, Side::East),
            other => panic!("unexpected pair {other:?}"),
        };
        for (s, p) in [(s1, m.points[0]), (s2, m.points[1])] {
            let q = h.fits[s as usize].finest().eval(m.parameter);
            let d = (q[0] - p[0]).hypot(q[1] - p[1]);
            assert!(d <= 1.5 * h.tol_abs, "{} {s}: {d:e} > tol {:e}", b.name, h.tol_abs);
        }
    }
    h.reparam.matches.len()
}

#[test]
fn narrow_tube_auto_is_constrained_and_bijective() {
    let b = boundary("narrow_tube.json");
    let sol = solve(&b, &fitted()).unwrap();
    let r = &sol.report;
    assert_eq!(r.fit.reparam.requested, Reparam::Auto);
    assert_eq!(r.fit.reparam.used, Reparam::Constrained, "gap ratios {:?}", r.fit.reparam.gap_ratio);
    assert!(!r.fit.reparam.matches.is_empty());
    assert_positive("narrow_tube", &sol);
    assert!(assert_matches_on_fit(&b, &fitted().fit) > 0);
}

#[test]
fn spiral_channel_auto_is_bijective() {
    let b = boundary("spiral_channel.json");
    let sol = solve(&b, &fitted()).unwrap();
    assert_positive("spiral_channel", &sol);
    assert_matches_on_fit(&b, &fitted().fit);
}

/// A geometry without narrow gaps keeps its own parameterization under `auto`.
#[test]
fn auto_leaves_wide_geometries_alone() {
    let b = boundary("quarter_annulus.json");
    let h = build_hierarchy(&b, &fitted().fit).unwrap();
    assert_eq!(h.reparam.used, Reparam::None);
    assert!(h.reparam.matches.is_empty());
    let h0 = build_hierarchy(&b, &with(Reparam::None).fit).unwrap();
    assert_eq!(h.finest().sides, h0.finest().sides);
}

/// Arc length on a spline geometry: the fitted sides still follow the contour, and the
/// map is bijective.
#[test]
fn arc_length_on_spline_sides() {
    let b = boundary("gismo/rotor_sector.json");
    let sol = solve(&b, &with(Reparam::ArcLength)).unwrap();
    let r = &sol.report;
    assert_eq!(r.fit.reparam.used, Reparam::ArcLength);
    assert!(
        r.fit.reparam.arc_length_ratio.iter().flatten().all(|&a| (1.0 - 1e-9..1.01).contains(&a)),
        "{:?}",
        r.fit.reparam
    );
    let dev = r.boundary.deviation.iter().cloned().fold(0.0, f64::max);
    assert!(dev <= 2.0 * r.fit.fit_tolerance, "deviation {dev:e}");
    assert_positive("rotor_sector", &sol);
}

/// male_casing_ring (G+Smo): a ring cut open with clearances of 1e-3 of the diameter;
/// with `--reparam none` it does not finish within minutes (BENCHMARKS.md).
#[test]
fn male_casing_ring_auto_is_bijective() {
    let b = boundary("gismo/male_casing_ring.json");
    let sol = solve(&b, &fitted()).unwrap();
    assert_eq!(sol.report.fit.reparam.used, Reparam::Constrained);
    assert_positive("male_casing_ring", &sol);
}

/// The scaled Jacobian of a sheared square `x = xi + s eta, y = eta` is
/// `1 / sqrt(1 + s^2)` everywhere (the sine of the angle between the grid lines).
#[test]
fn scaled_jacobian_of_a_shear() {
    let kv = winslow::KnotVector::open_uniform(1, 1);
    let s = 0.75;
    let map = winslow::Surface {
        knots: [kv.clone(), kv],
        control_points: vec![[0.0, 0.0], [1.0, 0.0], [s, 1.0], [1.0 + s, 1.0]],
        weights: None,
    };
    let v = winslow::verify::quality::quality(&map).scaled_jacobian.min;
    assert!((v - 1.0 / (1.0f64 + s * s).sqrt()).abs() < 1e-14, "{v}");
    // folded: the mirrored map has det J < 0 and a negative scaled Jacobian
    let mut folded = map.clone();
    folded.control_points.iter_mut().for_each(|p| p[0] = -p[0]);
    assert!(
        (winslow::verify::quality::quality(&folded).scaled_jacobian.min + 1.0 / (1.0f64 + s * s).sqrt()).abs() < 1e-14
    );
}
