//! Matching of narrow gaps on a ring (paper §7.2, eq. 40-42, adapted to closed curves):
//! where the inner and outer contours of a [`Ring`](super::ring::Ring) come close, facing
//! points of the two contours get the same `eta`, so that the grid lines `eta = const`
//! cross the gap straight instead of running obliquely through it.
//!
//! **Cut at the seam.** Both contours are cut open at `eta = 0` (the seam of
//! [`crate::boundary::ring`], fixed as for arc length) into polylines running once around
//! counter-clockwise, `P_1` the inner contour with its arc-length fractions `s^1_i`
//! (`0` at its start, `1` back at it) and `P_2` the outer one with its fractions
//! `s^2_j` shifted to the seam (`s^2_0 >= 0` the first sample after the seam,
//! `s^2_0 + 1` back at it). A monotone matching of the two open polylines is then a
//! matching of the closed contours in cyclic order that keeps the seam where it is.
//!
//! **Gap.** The gap ratio is the smallest distance between points of the two contours that
//! face each other across the domain ([`min_distance`], with the inner contour in the role
//! of the west and the outer of the east side: the domain lies right of the
//! counter-clockwise inner and left of the counter-clockwise outer contour) over the outer
//! contour's diameter `D` (the bounding-box diagonal). `auto` matches when it is below
//! [`ReparamOptions::gap`], `constrained` always; `arclength` and `none` keep arc length.
//!
//! **Matching** ([`match_clouds`], eq. 40): the closest facing pair `(p^1_i, p^2_j)` within
//! `ε = gap D` is matched, and the search recurses on the parameter boxes below and above
//! it, shrunk by the minimum separation [`ReparamOptions::separation`] (so no match lies
//! within it of the seam). The inner contour keeps its arc-length parameter; the outer
//! one gets `eta^2_j = s^1_i` at every matched pair and, between consecutive matches
//! (and the seam at both ends), cord length mapped onto the interval of the two matched
//! values (eq. 41-42, [`fill_abscissae`]; or a Fritsch-Carlson monotone cubic with
//! [`Fill::MonotoneCubic`](super::reparam::Fill::MonotoneCubic)). The new outer parameter is strictly increasing from `s^2_0`
//! to `s^2_0 + 1`: a monotone periodic map of the outer contour onto itself, equal to
//! arc length when nothing is matched (then the samples are left untouched, bit for bit).
//! The contours are then fitted on one periodic knot vector as before
//! ([`crate::boundary::ring_fit`]), at these parameters.
use super::reparam::{
    fill_abscissae, match_clouds, min_distance, Across, Match, Reparam, ReparamOptions, ReparamReport,
};
use super::ring::Samples;
use crate::error::Result;

/// Outer samples `(s, x)` sorted by `s mod 1` (`s` wrapped into `[0, 1)`).
pub(super) fn wrapped(s: impl IntoIterator<Item = f64>, x: &[crate::spline::curve::Point]) -> Samples {
    let mut pairs: Vec<(f64, crate::spline::curve::Point)> =
        s.into_iter().zip(x).map(|(s, &x)| (s.rem_euclid(1.0), x)).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    Samples { s: pairs.iter().map(|p| p.0).collect(), x: pairs.iter().map(|p| p.1).collect() }
}

/// The matching of the module documentation on the inner and outer arc-length samples
/// (the outer already shifted to the seam), `diameter` the outer contour's. Returns the
/// outer samples at their new parameters (`None` when nothing is matched: arc length is
/// kept) and the report (matched points in the samples' coordinates).
pub(super) fn ring_reparam(
    inner: &Samples,
    outer: &Samples,
    diameter: f64,
    opts: &ReparamOptions,
) -> Result<(Option<Samples>, ReparamReport)> {
    opts.validate()?;
    let closed = |smp: &Samples| {
        let mut p = smp.x.clone();
        p.push(smp.x[0]);
        let mut c = smp.s.clone();
        c.push(1.0 + smp.s[0]);
        (p, c)
    };
    let ((p1, c1), (p2, c2)) = (closed(inner), closed(outer));
    let ratio = min_distance(&p1, &p2, Across::WestEast) / diameter;
    let mut report = ReparamReport::native();
    report.requested = opts.method;
    report.used = Reparam::ArcLength;
    report.gap_ratio = [f64::NAN, ratio];
    report.pair_methods = [Reparam::None, Reparam::ArcLength];
    report.gap_threshold = opts.gap;
    report.fill = opts.fill;
    let matching = match opts.method {
        Reparam::Auto => ratio < opts.gap,
        Reparam::Constrained => true,
        Reparam::None | Reparam::ArcLength => false,
    };
    if !matching {
        return Ok((None, report));
    }
    let s0 = c2[0];
    let pairs: Vec<(usize, usize)> =
        match_clouds(&p1, &c1, &p2, &c2, opts.gap * diameter, opts.separation, Across::WestEast)
            .into_iter()
            .filter(|&(i, j)| c1[i] > s0 && c1[i] < 1.0 && j > 0 && j + 1 < c2.len())
            .collect();
    if pairs.is_empty() {
        return Ok((None, report));
    }
    // eq. 41-42 on the outer polyline from the seam (parameters shifted by s0 onto [0, 1])
    let local: Vec<f64> = c2.iter().map(|c| c - s0).collect();
    let known: Vec<(usize, f64)> = pairs.iter().map(|&(i, j)| (j, c1[i] - s0)).collect();
    let xi = fill_abscissae(&local, &known, opts.fill)?;
    let n = outer.x.len();
    let moved = wrapped(xi[..n].iter().map(|v| v + s0), &outer.x);
    report.used = Reparam::Constrained;
    report.pair_methods[1] = Reparam::Constrained;
    report.matches = pairs
        .iter()
        .map(|&(i, j)| Match { sides: ["inner", "outer"], parameter: c1[i], points: [p1[i], p2[j]] })
        .collect();
    Ok((Some(moved), report))
}

/// The test ring of `tests/data/rings/lobed_gap.json`: a three-lobed inner contour
/// `r = 0.35 (1 + 0.2 cos 3θ)` about `(0.578, 0)`, starting at `θ = π/2`, in the unit
/// circle; its lobe tip at `θ = 0` comes within `0.002` (1e-3 of the circle's
/// diameter) of the circle.
#[cfg(test)]
pub(crate) fn lobed_gap() -> super::ring::Ring {
    lobed_gap_from(std::f64::consts::FRAC_PI_2)
}

/// [`lobed_gap`] with the inner contour starting at `θ = start`.
#[cfg(test)]
pub(crate) fn lobed_gap_from(start: f64) -> super::ring::Ring {
    use super::ring::ClosedContour;
    use std::f64::consts::TAU;
    let inner = ClosedContour::Analytic(super::Analytic::new(move |t| {
        let th = start + TAU * t;
        let r = 0.35 * (1.0 + 0.2 * (3.0 * th).cos());
        [0.578 + r * th.cos(), r * th.sin()]
    }));
    let outer = ClosedContour::Analytic(super::Analytic::new(|t| [(TAU * t).cos(), (TAU * t).sin()]));
    super::ring::Ring { name: "lobed_gap".into(), inner, outer }
}

#[cfg(test)]
mod tests {
    use super::super::reparam::Fill;
    use super::super::ring::{ClosedContour, Ring};
    use super::super::ring_fit::{fit_ring_with, EtaRefinement, RingFit};
    use super::*;
    use crate::boundary::Analytic;
    use crate::spline::curve::Point;
    use std::f64::consts::TAU;

    fn circle(r: f64, c: Point) -> ClosedContour {
        ClosedContour::Analytic(Analytic::new(move |t| [c[0] + r * (TAU * t).cos(), c[1] + r * (TAU * t).sin()]))
    }

    fn fit(ring: &Ring, method: Reparam, fill: Fill) -> RingFit {
        let o = ReparamOptions { method, fill, ..Default::default() };
        fit_ring_with(ring, 3, 1e-4, 4096, EtaRefinement::Adaptive, &o).unwrap()
    }

    fn dist(a: Point, b: Point) -> f64 {
        (a[0] - b[0]).hypot(a[1] - b[1])
    }

    /// The narrow gap is detected and matched: each matched pair sits at one `eta` on both
    /// fitted contours (to the fit tolerance), close to the gap, in cyclic order; with arc
    /// length the outer contour at the inner point's `eta` is far from the facing point.
    #[test]
    fn narrow_gap_pairs_share_eta() {
        let ring = lobed_gap();
        for fill in [Fill::CordLength, Fill::MonotoneCubic] {
            let f = fit(&ring, Reparam::Auto, fill);
            let r = &f.reparam;
            assert!(f.converged);
            assert_eq!((r.requested, r.used), (Reparam::Auto, Reparam::Constrained));
            // gap 0.002 over the bounding-box diagonal 2 sqrt 2
            assert!((r.gap_ratio[1] - 0.002 / 8f64.sqrt()).abs() < 2e-5, "{:?}", r.gap_ratio);
            assert!(r.matches.len() >= 3, "{} matches", r.matches.len());
            let last = f.levels.last().unwrap();
            for m in &r.matches {
                let (a, b) = (last.curves[0].eval(m.parameter), last.curves[1].eval(m.parameter));
                assert!(dist(a, m.points[0]) <= f.tol_abs && dist(b, m.points[1]) <= f.tol_abs, "{m:?}");
                assert!(dist(m.points[0], m.points[1]) <= 0.02 * f.diameter);
                assert!(m.points[1][0] > 0.9, "match away from the gap: {m:?}");
            }
            assert!(r.matches.windows(2).all(|w| w[1].parameter - w[0].parameter >= 0.01));
            // the pair closest to the gap crosses it nearly straight: its segment is within
            // a few degrees of the outer circle's normal there
            let m = r
                .matches
                .iter()
                .min_by(|a, b| dist(a.points[0], a.points[1]).total_cmp(&dist(b.points[0], b.points[1])));
            let m = m.unwrap();
            let (d, n) = ([m.points[1][0] - m.points[0][0], m.points[1][1] - m.points[0][1]], m.points[1]);
            let cos = (d[0] * n[0] + d[1] * n[1]) / (d[0].hypot(d[1]) * n[0].hypot(n[1]));
            assert!(cos > 0.99, "{m:?}: cos {cos}");
        }
        // arc length: the outer point at the gap tip's eta is far away from the tip
        let a = fit(&ring, Reparam::ArcLength, Fill::CordLength);
        assert!(a.reparam.matches.is_empty() && a.reparam.used == Reparam::ArcLength);
        let f = fit(&ring, Reparam::Auto, Fill::CordLength);
        let m = &f.reparam.matches[f.reparam.matches.len() / 2];
        let last = a.levels.last().unwrap();
        assert!(dist(last.curves[0].eval(m.parameter), m.points[0]) <= a.tol_abs);
        assert!(dist(last.curves[1].eval(m.parameter), m.points[1]) > 0.2);
    }

    /// The seam through the gap (the inner contour starts at the lobe tip): `eta = 0`
    /// stays where arc length puts it, the matches keep the separation from it on both
    /// sides of the period and are in cyclic order.
    #[test]
    fn seam_through_the_gap_stays_fixed() {
        let ring = lobed_gap_from(0.0);
        let (f, a) = (fit(&ring, Reparam::Auto, Fill::CordLength), fit(&ring, Reparam::ArcLength, Fill::CordLength));
        assert!(f.converged && f.reparam.used == Reparam::Constrained && !f.reparam.matches.is_empty());
        let (lf, la) = (f.levels.last().unwrap(), a.levels.last().unwrap());
        for k in 0..2 {
            assert!(dist(lf.curves[k].eval(0.0), la.curves[k].eval(0.0)) <= 2.0 * f.tol_abs);
        }
        let t: Vec<f64> = f.reparam.matches.iter().map(|m| m.parameter).collect();
        assert!(t.windows(2).all(|w| w[1] > w[0]) && t[0] > 0.01 && *t.last().unwrap() < 0.99, "{t:?}");
        // matched on both sides of the seam
        assert!(t[0] < 0.1 && *t.last().unwrap() > 0.9, "{t:?}");
        for m in &f.reparam.matches {
            assert!(dist(lf.curves[1].eval(m.parameter), m.points[1]) <= f.tol_abs, "{m:?}");
        }
    }

    /// Without a narrow gap `auto` is arc length, bit for bit; `constrained` on a ring
    /// whose contours stay farther apart than the threshold matches nothing either.
    #[test]
    fn wide_rings_keep_arc_length_bit_for_bit() {
        let ring = Ring { name: "ecc".into(), inner: circle(0.4, [0.25, 0.1]), outer: circle(1.0, [0.0; 2]) };
        let a = fit(&ring, Reparam::ArcLength, Fill::CordLength);
        for method in [Reparam::Auto, Reparam::Constrained, Reparam::None] {
            let f = fit(&ring, method, Fill::CordLength);
            assert_eq!(f.reparam.used, Reparam::ArcLength);
            assert!(f.reparam.matches.is_empty() && f.reparam.gap_ratio[1] > 0.1);
            assert_eq!(f.levels.len(), a.levels.len());
            for (l, m) in f.levels.iter().zip(&a.levels) {
                assert_eq!(l.knots, m.knots);
                for k in 0..2 {
                    assert_eq!(l.curves[k].control_points, m.curves[k].control_points);
                }
            }
        }
    }
}
