use super::*;
use crate::spline::knots::KnotVector;
use crate::spline::volume::triple;

/// A curved, certified map of a four-sided domain around the origin (degree 2, 4 x 4
/// elements): a square with a bulging south side.
fn base() -> Surface {
    let k = KnotVector::open_uniform(2, 4);
    let g = k.greville();
    let mut cps = Vec::new();
    for &v in &g {
        for &u in &g {
            let bulge = 0.2 * (std::f64::consts::PI * u).sin() * (1.0 - v);
            cps.push([2.0 * u - 1.0 + 0.1 * v * v, 2.0 * v - 1.0 - bulge]);
        }
    }
    Surface::new([k.clone(), k], cps, None).unwrap()
}

fn rotated(s: &Surface, angle: f64) -> Surface {
    let (c, si) = (angle.cos(), angle.sin());
    let mut r = s.clone();
    for p in r.control_points.iter_mut() {
        *p = [c * p[0] - si * p[1], si * p[0] + c * p[1]];
    }
    r
}

/// A half turn between two slices collapses the linear interpolation at the middle;
/// with the family's boundary (the domain turned by `π z`) one inserted slice, solved
/// from the interpolated guess, makes the volume certified.
#[test]
fn a_slice_is_inserted_where_the_twist_collapses_the_volume() {
    let s = base();
    let pi = std::f64::consts::PI;
    let family = |z: f64, _guess: &Surface| Ok(rotated(&s, pi * z));
    let opts = LoftOptions::default();
    let slices = [s.clone(), rotated(&s, pi)];
    let out = loft(&slices, &[0.0, 1.0], &opts, SliceBoundary::Family(&family)).unwrap();
    assert_eq!(out.report.rounds.len(), 2, "{:?}", out.report.rounds);
    assert_ne!(out.report.rounds[0].verdict, "certified");
    assert_eq!(out.report.rounds[0].inserted_z, vec![0.5]);
    assert_eq!(out.report.verdict, "certified");
    assert!(matches!(out.certificate.verdict, VolumeFinding::Certified { .. }));
    assert_eq!(out.z, vec![0.0, 0.5, 1.0]);
    let r = &out.report.slices[1];
    assert_eq!((r.given, r.boundary), (None, Some("family")));
    assert!(
        r.residual_after.unwrap() < 1e-6 * r.residual_before.unwrap().max(1e-300) || r.residual_after.unwrap() < 1e-12
    );
    // the inserted slice has the turned boundary, and the volume passes through it
    let want = rotated(&s, pi / 2.0);
    let mid = &out.slices[1];
    for side in crate::spline::surface::Side::ALL {
        for (a, b) in mid.boundary(side).control_points.iter().zip(&want.boundary(side).control_points) {
            assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12);
        }
    }
    let x = out.volume.eval([0.3, 0.8, 0.5]);
    let y = mid.eval(0.3, 0.8);
    assert!((x[0] - y[0]).abs() < 1e-12 && (x[1] - y[1]).abs() < 1e-12 && (x[2] - 0.5).abs() < 1e-14);
    // the same with only the maps: the interpolated boundary at the middle is a point
    let e = loft(&slices, &[0.0, 1.0], &opts, SliceBoundary::Interpolated);
    assert!(e.is_err(), "{:?}", e.map(|l| l.report.verdict));
}

/// Identical slices: certified, with the proven bound below the cylinder's `det J`.
#[test]
fn identical_slices_loft_to_a_certified_cylinder() {
    let s = base();
    let out = loft(
        &[s.clone(), s.clone(), s.clone()],
        &[0.0, 0.5, 2.0],
        &LoftOptions::default(),
        SliceBoundary::Interpolated,
    )
    .unwrap();
    let VolumeFinding::Certified { lower_bound, .. } = out.certificate.verdict else {
        panic!("{:?}", out.certificate.verdict)
    };
    let m = crate::verify::quality::sample_det_j(&s, 64).min * 2.0;
    assert!(lower_bound > 0.0 && lower_bound <= m, "{lower_bound} vs {m}");
    assert_eq!(out.report.rounds.len(), 1);
    let d = out.volume.derivs([0.2, 0.9, 0.7]);
    assert!((d.det_j() - 2.0 * s.derivs(0.2, 0.9, 1).det_j()).abs() < 1e-11);
    assert!((triple(d.d[0], d.d[1], d.d[2]) - d.det_j()).abs() == 0.0);
}

#[test]
fn an_uncertified_slice_is_refused() {
    let s = base();
    let mut bad = s.clone();
    let [nx, _] = bad.shape();
    bad.control_points[2 * nx + 2][0] += 3.0;
    match loft(&[s.clone(), bad, s], &[0.0, 1.0, 2.0], &LoftOptions::default(), SliceBoundary::Interpolated) {
        Err(Error::SliceNotCertified { slice, z, verdict, .. }) => {
            assert_eq!((slice, z), (1, 1.0));
            assert_ne!(verdict, "certified");
        }
        other => panic!("{:?}", other.map(|l| l.report.verdict)),
    }
}

/// Ring slices (`η` periodic): an annulus whose inner circle moves; the volume keeps `η`
/// periodic and certifies.
#[test]
fn ring_slices_loft_with_a_periodic_direction() {
    let kp = KnotVector::periodic_uniform(2, 8);
    let ko = KnotVector::open_uniform(1, 1);
    let n = kp.num_basis();
    let ring = |shift: f64| {
        let mut cps = Vec::new();
        for j in 0..n {
            let t = std::f64::consts::TAU * (j % 8) as f64 / 8.0;
            cps.push([shift + t.cos(), t.sin()]);
            cps.push([3.0 * t.cos(), 3.0 * t.sin()]);
        }
        Surface::new([ko.clone(), kp.clone()], cps, None).unwrap()
    };
    let slices = [ring(0.0), ring(0.4), ring(0.8)];
    for interpolation in [Interpolation::Linear, Interpolation::Cubic] {
        let opts = LoftOptions { interpolation, ..Default::default() };
        let out = loft(&slices, &[0.0, 1.0, 2.0], &opts, SliceBoundary::Interpolated).unwrap();
        assert!(out.volume.knots[1].is_periodic());
        assert_eq!(out.report.verdict, "certified", "{interpolation:?}: {}", out.certificate.message());
    }
}

/// The unit square's identity on a degree-3 basis with its interior turned by the
/// swirl `φ(r) = a (1 - r / 0.5)²` about the centre (`r <= 0.5`; the boundary stays).
fn swirl(a: f64) -> Surface {
    let k = KnotVector::open_uniform(3, 16);
    let g = k.greville();
    let mut cps = Vec::new();
    for &v in &g {
        for &u in &g {
            let (x, y) = (u - 0.5, v - 0.5);
            let r = x.hypot(y);
            let phi = if r < 0.5 { a * (1.0 - r / 0.5).powi(2) } else { 0.0 };
            let (c, s) = (phi.cos(), phi.sin());
            cps.push([0.5 + c * x - s * y, 0.5 + s * x + c * y]);
        }
    }
    Surface::new([k.clone(), k], cps, None).unwrap()
}

/// Two swirls of opposite sense with the same boundary: each slice is bijective, their
/// average turns the centre by `cos φ < 0` and folds. With only the maps given, the
/// slice inserted in the middle takes the interpolated (here: the common) boundary, EGG
/// gives it no swirl, and the volume certifies.
#[test]
fn an_inserted_slice_with_the_interpolated_boundary_unfolds_opposite_swirls() {
    let a = 2.8; // 160 degrees at the centre
    let slices = [swirl(a), swirl(-a)];
    let out = loft(&slices, &[0.0, 1.0], &LoftOptions::default(), SliceBoundary::Interpolated).unwrap();
    assert_eq!(out.report.rounds[0].verdict, "folded", "{:?}", out.report.rounds);
    assert_eq!(out.report.verdict, "certified", "{:?}", out.report.rounds);
    assert!(out.z.len() >= 3 && out.report.slices.iter().any(|s| s.boundary == Some("interpolated")));
    // the inserted middle slice has (nearly) no swirl left: its centre stays put
    let mid = &out.slices[out.z.iter().position(|&z| z == 0.5).expect("a slice at 0.5")];
    let c = mid.eval(0.5, 0.5);
    assert!((c[0] - 0.5).abs() < 1e-6 && (c[1] - 0.5).abs() < 1e-6, "{c:?}");
}

/// The opposite swirls translated by 1e9 times their size or scaled by 1e±150 (heights
/// too): the same rounds, inserted heights (mapped), Newton iterations of the inserted
/// slices and verdict; the inserted slice is solved in normalised coordinates.
#[test]
fn inserted_slices_are_solved_alike_far_away_and_at_extreme_sizes() {
    let a = 2.8;
    let run = |t: crate::spline::curve::Point, s: f64| {
        let moved = |m: Surface| Surface {
            control_points: m.control_points.iter().map(|p| [t[0] + s * p[0], t[1] + s * p[1]]).collect(),
            ..m
        };
        let slices = [moved(swirl(a)), moved(swirl(-a))];
        let z0 = 3e9 * s;
        let out = loft(&slices, &[z0, z0 + s], &LoftOptions::default(), SliceBoundary::Interpolated).unwrap();
        let rounds: Vec<_> =
            out.report.rounds.iter().map(|r| (r.verdict, r.offending_elements, r.inserted_z.len())).collect();
        let its: Vec<_> = out.report.slices.iter().map(|r| r.newton_iterations).collect();
        (rounds, its, out.report.verdict)
    };
    let orig = run([0.0, 0.0], 1.0);
    assert!(orig.1.iter().any(|i| i.is_some()), "{orig:?}");
    for (t, s) in [([1.4e9, -2.8e9], 1.0), ([0.0, 0.0], 1e150), ([0.0, 0.0], 1e-150)] {
        assert_eq!(run(t, s), orig, "moved by {t:?}, scaled by {s:e}");
    }
}
