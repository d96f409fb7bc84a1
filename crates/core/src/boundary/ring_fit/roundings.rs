//! Rounded corners of a ring's point-cloud contour in the ring fit
//! ([`super::fit_ring_with`]): a corner that the cloud resolves over a few points (a
//! rounding by `boundary::kinks::rounding_of`, not a kink) is a fillet the fit must
//! follow to its tolerance, measured as the report's boundary deviation measures it,
//! against the polyline through the cloud.
//!
//! Two things change near such a corner (within [`ROUNDING_REACH`] points of its vertex)
//! and nowhere else: the chords between the cloud's points there are sampled at
//! [`CHORD_POINTS`] interior points too ([`along_roundings`]), and the fit may bisect an
//! element there although its halves hold fewer than `p + 1` samples
//! ([`rounded_elements`]). Elsewhere the fit is the one of §5 unchanged, bit for bit.
//! Measured (BENCHMARKS.md "Rings with tight fillets"): a square's corners rounded at
//! radius `R` on 2 to 4 points of a cloud were left `4.2e-3` from the cloud (tolerance
//! `5.7e-4`); with both changes every one is within the tolerance.
use crate::boundary::ring::{ClosedContour, Samples};
use crate::spline::knots::KnotVector;

/// Samples of `contour` (a point cloud; `smp` its samples at their fit parameters, in any
/// order) within [`ROUNDING_REACH`] points of a rounded corner's vertex
/// (`kinks::closed_cloud_roundings`), or within `m` points when the cloud resolves the
/// rounding's half turn over more: there the fit may bisect elements below `p + 1`
/// samples (see [`super::fit_ring_with`]). All `false` for a parametric contour or a cloud
/// without roundings.
pub(super) fn near_roundings(contour: &ClosedContour, smp: &Samples) -> Vec<bool> {
    let mut near = vec![false; smp.x.len()];
    let ClosedContour::Points(points) = contour else { return near };
    let n = points.len();
    for (j, _, m) in crate::boundary::kinks::closed_cloud_roundings(points) {
        let reach = m.max(ROUNDING_REACH).min(n / 2);
        for k in 0..=2 * reach {
            let q = points[(j + n + k - reach) % n];
            if let Some(i) = smp.x.iter().position(|&x| x == q) {
                near[i] = true;
            }
        }
    }
    near
}

/// `smp` with the chords between consecutive samples near a rounded corner
/// ([`near_roundings`]) sampled at [`CHORD_POINTS`] interior points too (parameters and
/// positions interpolated linearly), and which samples are near one. The fit's error is
/// then measured as the report's boundary deviation measures it, against the polyline
/// through the cloud: a fit through the points alone follows the fillet's arc, which
/// passes outside the chords of a fillet resolved by a few points by more than the
/// tolerance (a quarter circle of radius `R` on 3 chords: `R (1 - cos 15°) = 0.034 R`).
pub(super) fn along_roundings(contour: &ClosedContour, smp: Samples) -> (Samples, Vec<bool>) {
    let near = near_roundings(contour, &smp);
    if !near.contains(&true) {
        return (smp, near);
    }
    let n = smp.s.len();
    let mut out = Samples { s: Vec::with_capacity(n), x: Vec::with_capacity(n) };
    let mut flags = Vec::with_capacity(n);
    for k in 0..n {
        out.s.push(smp.s[k]);
        out.x.push(smp.x[k]);
        flags.push(near[k]);
        let next = (k + 1) % n;
        if !(near[k] || near[next]) {
            continue;
        }
        let (s0, s1) = (smp.s[k], if next == 0 { smp.s[0] + 1.0 } else { smp.s[next] });
        let (a, b) = (smp.x[k], smp.x[next]);
        for j in 1..=CHORD_POINTS {
            let t = j as f64 / (CHORD_POINTS + 1) as f64;
            out.s.push((s0 + t * (s1 - s0)).rem_euclid(1.0));
            out.x.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            flags.push(true);
        }
    }
    // the chord after the last sample wraps past eta = 1: keep the parameters increasing
    let mut order: Vec<usize> = (0..out.s.len()).collect();
    order.sort_by(|&i, &j| out.s[i].total_cmp(&out.s[j]));
    let smp = Samples { s: order.iter().map(|&i| out.s[i]).collect(), x: order.iter().map(|&i| out.x[i]).collect() };
    (smp, order.iter().map(|&i| flags[i]).collect())
}

/// Interior points per chord near a rounded corner at which the ring fit measures its
/// error too ([`along_roundings`]).
const CHORD_POINTS: usize = 3;

/// Points on either side of a rounded corner's vertex where the ring fit may refine past
/// the `p + 1` samples per element ([`near_roundings`]): a fillet the cloud resolves by a
/// few points, and the straight parts next to it where a cubic overshoots.
const ROUNDING_REACH: usize = 4;

/// Whether each element of `kv` holds a sample flagged in `near` ([`near_roundings`]).
pub(super) fn rounded_elements(kv: &KnotVector, smp: &Samples, near: &[bool]) -> Vec<bool> {
    let elements = kv.elements();
    let mut out = vec![false; elements.len()];
    for (&s, _) in smp.s.iter().zip(near).filter(|(_, &n)| n) {
        out[elements.partition_point(|el| el.2 <= s).min(elements.len() - 1)] = true;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::tests::rounded_square;
    use super::super::{fit_ring, Ring};
    use super::*;
    use crate::spline::curve::Point;

    /// Distance from `p` to the closed polyline through `poly`.
    fn to_polyline(poly: &[Point], p: Point) -> f64 {
        (0..poly.len())
            .map(|k| {
                let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                let e = [b[0] - a[0], b[1] - a[1]];
                let t = (((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / (e[0] * e[0] + e[1] * e[1])).clamp(0.0, 1.0);
                (p[0] - a[0] - t * e[0]).hypot(p[1] - a[1] - t * e[1])
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The chords are sampled near the four rounded corners only: `3` points on each of
    /// the `2 ROUNDING_REACH + 2` chords around each vertex, on the chord, at increasing
    /// parameters; a cloud without rounded corners (a circle) is left as it is.
    #[test]
    fn chords_are_sampled_near_rounded_corners_only() {
        let pts = rounded_square(0.05, 0.02);
        let n = pts.len();
        let mut s = vec![0.0];
        for k in 1..n {
            s.push(s[k - 1] + (pts[k][0] - pts[k - 1][0]).hypot(pts[k][1] - pts[k - 1][1]));
        }
        let total = s[n - 1] + (pts[0][0] - pts[n - 1][0]).hypot(pts[0][1] - pts[n - 1][1]);
        let smp = Samples { s: s.iter().map(|v| v / total).collect(), x: pts.clone() };
        let (dense, near) = along_roundings(&ClosedContour::Points(pts.clone()), smp);
        assert_eq!(dense.s.len(), n + 4 * (2 * ROUNDING_REACH + 2) * CHORD_POINTS);
        assert_eq!(
            near.iter().filter(|&&b| b).count(),
            4 * ((2 * ROUNDING_REACH + 1) + (2 * ROUNDING_REACH + 2) * CHORD_POINTS)
        );
        assert!(dense.s.windows(2).all(|w| w[0] < w[1]) && dense.s[0] >= 0.0 && *dense.s.last().unwrap() < 1.0);
        assert!(dense.x.iter().all(|&p| to_polyline(&pts, p) < 1e-12));
        let circle: Vec<Point> = (0..200).map(|k| [(k as f64 * 0.0314).cos(), (k as f64 * 0.0314).sin()]).collect();
        let smp = Samples { s: (0..200).map(|k| k as f64 / 200.0).collect(), x: circle.clone() };
        let (same, near) = along_roundings(&ClosedContour::Points(circle), smp.clone());
        assert_eq!((same.s, same.x), (smp.s, smp.x));
        assert!(!near.contains(&true));
    }

    /// The ring fit of a square whose corners are rounded on 2, 3 and 4 points of the
    /// cloud converges, and its outer curve stays within the tolerance of the polyline
    /// through the cloud everywhere (sampled at 20 000 parameters, not only at the points).
    #[test]
    fn tight_fillets_are_fitted_within_the_tolerance_of_the_polyline() {
        use crate::boundary::Analytic;
        use std::f64::consts::TAU;
        for r in [0.02, 0.03, 0.05] {
            let pts = rounded_square(r, 0.02);
            let inner = ClosedContour::Analytic(Analytic::new(|t| [(TAU * t + 0.3).cos(), (TAU * t + 0.3).sin()]));
            let ring = Ring { name: "fillets".into(), inner, outer: ClosedContour::Points(pts.clone()) };
            let f = fit_ring(&ring, 3, 1e-4, 4096).unwrap();
            assert!(f.converged, "R = {r}");
            let outer = &f.levels.last().unwrap().curves[1];
            let worst = (0..20_000).map(|k| to_polyline(&pts, outer.eval(k as f64 / 20_000.0))).fold(0.0, f64::max);
            assert!(worst <= f.tol_abs, "R = {r}: {worst:e} from the polyline, tolerance {:e}", f.tol_abs);
        }
    }
}
