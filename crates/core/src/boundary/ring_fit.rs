//! The contour fit of a ring (paper §5 on closed contours, §11.1): both contours of a
//! [`Ring`] on one periodic knot vector in `eta`, parameterized by arc length with the
//! seam of [`crate::boundary::ring`] (narrow gaps matched by
//! `boundary::ring_reparam`), and the hierarchy of bases the solver walks.
//!
//! **Fit.** Least squares `min sum_k |C(eta_k) - x_k|^2` over the `d` distinct control
//! points (wrapped collocation matrix) on one periodic knot vector for both contours, at
//! `DENSE` arc-length samples of a parametric contour (the points of a cloud), refined
//! adaptively and dyadically in `eta` as in §5: from `n_0 = 4` uniform elements (at least
//! `p + 1`), every element where either contour deviates by more than `tol * diameter`
//! at a sample is bisected (knots stay dyadic, `k / (n_0 2^l)`), and both contours are
//! refitted; each fit is one level of the hierarchy. An element is bisected only when
//! each half keeps at least `p + 1` samples of every contour that misses the tolerance
//! there (more elements cannot bring a sparse cloud closer); the other contour's fit
//! stays well posed on elements without samples by the tiny smoothing term of the
//! four-sided point fits (`REGULARIZATION`, `λ Σ_e h_e^3 ∫_e |f''|^2`). The loop ends
//! when no element is marked or the next level would pass the element cap.
//!
//! **Rounded corners of a cloud** (roundings by the rule of `boundary::kinks`, no kinks):
//! near them the chords are sampled too and elements are bisected below `p + 1` samples,
//! so that the fit follows a fillet resolved by a few points to its tolerance
//! (`ring_fit/roundings.rs`).
//!
//! **Normalisation.** Like a four-sided boundary
//! (`boundary::normalise::Similarity`), a ring far from the origin or of extreme
//! size is fitted and solved in the coordinates `(x - c) / s` of its outer contour's
//! bounding box and mapped back; [`RingFit`] lives in those coordinates.
mod roundings;

use super::fit::{FitOptions, SideFit, REGULARIZATION};
use super::hierarchy::{BasisReport, Hierarchy, Level};
use super::normalise::Similarity;
use super::reparam::{ReparamOptions, ReparamReport};
use super::ring::{dist, inside, signed_area, ClosedContour, Ring, Samples};
use super::ring_reparam::{ring_reparam, wrapped};
use super::{Boundary, SideCurve};
use crate::error::{Error, Result};
use crate::linalg::linsolve::{LinearMethod, LinearSolver};
use crate::linalg::sparse::Csr;
use crate::spline::basis::BasisDerivs;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::quadrature::GaussLegendre;
use crate::spline::surface::Side;
use roundings::{along_roundings, rounded_elements};

/// Arc-length fraction of the first crossing of the ray `o + t dir`, `t > 0`, with the
/// closed polygon whose vertices have fractions `s` (`None` when it misses).
fn ray_crossing(poly: &[Point], s: &[f64], o: Point, dir: Point) -> Option<f64> {
    let n = poly.len();
    let mut best: Option<(f64, f64)> = None;
    for k in 0..n {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        let e = [b[0] - a[0], b[1] - a[1]];
        let den = dir[0] * e[1] - dir[1] * e[0];
        if den == 0.0 {
            continue;
        }
        let w = [a[0] - o[0], a[1] - o[1]];
        let t = (w[0] * e[1] - w[1] * e[0]) / den;
        let u = (w[0] * dir[1] - w[1] * dir[0]) / den;
        if t > 0.0 && (0.0..1.0).contains(&u) && best.is_none_or(|(bt, _)| t < bt) {
            let s1 = if k + 1 < n { s[k + 1] } else { 1.0 };
            best = Some((t, s[k] + u * (s1 - s[k])));
        }
    }
    best.map(|b| b.1)
}

/// One fit of both contours on a periodic knot vector.
#[derive(Debug, Clone)]
pub struct RingLevel {
    /// Periodic knot vector in `eta` on `[0, 1]`.
    pub knots: KnotVector,
    /// The inner and outer contour on `knots` (wrapped control points).
    pub curves: [Curve; 2],
    /// Largest deviation at the samples, inner and outer.
    pub max_error: [f64; 2],
}

/// The dyadic fits of a ring (see the module documentation).
#[derive(Debug, Clone)]
pub struct RingFit {
    /// Coarse to fine.
    pub levels: Vec<RingLevel>,
    /// Whether the finest level meets the tolerance on both contours.
    pub converged: bool,
    /// Absolute tolerance.
    pub tol_abs: f64,
    /// Diameter of the outer contour's bounding box.
    pub diameter: f64,
    /// Arc-length fraction of the outer contour at `eta = 0`.
    pub outer_shift: f64,
    /// The input's coordinates from the fit's: `x = c + s x̂` (the identity for a
    /// well-placed ring); lengths above are in the fit's coordinates.
    pub similarity: Similarity,
    /// The reparameterization: arc length, or the matching of narrow gaps
    /// (`boundary::ring_reparam`); matched points in the fit's coordinates.
    pub reparam: ReparamReport,
}

/// Least-squares fit `min sum_k |C(s_k) - x_k|^2` of a periodic curve on `kv` (normal
/// equations, cyclically banded, by a sparse Cholesky factorization), its largest
/// deviation at the samples, and the largest per element of `kv` (in the order of
/// [`KnotVector::elements`]).
fn fit_periodic_elements(kv: &KnotVector, smp: &Samples) -> Result<(Curve, f64, Vec<f64>)> {
    let d = kv.dim();
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); d];
    let mut rhs = vec![[0.0; 2]; d];
    let mut b = BasisDerivs::default();
    for (&s, x) in smp.s.iter().zip(&smp.x) {
        b.eval(kv, s, 0);
        let v = b.ders(0);
        for (ja, &va) in v.iter().enumerate() {
            let a = (b.first() + ja) % d;
            rhs[a][0] += va * x[0];
            rhs[a][1] += va * x[1];
            for (jb, &vb) in v.iter().enumerate() {
                add_entry(&mut rows[a], (b.first() + jb) % d, va * vb);
            }
        }
    }
    // the smoothing term of the four-sided point fits, `λ Σ_e h_e^3 ∫_e |f''|^2` with
    // `λ = REGULARIZATION tr(B^T B) / tr(R)`: elements without samples stay well posed
    let mut reg: Vec<Vec<(usize, f64)>> = vec![Vec::new(); d];
    let gauss = GaussLegendre::new(kv.degree() + 1);
    for (span, lo, hi) in kv.elements() {
        let h3 = (hi - lo).powi(3);
        for (u, w) in gauss.on(lo, hi) {
            b.eval_in_span(kv, span, u, 2);
            let v = b.ders(2);
            for (ja, &va) in v.iter().enumerate() {
                for (jb, &vb) in v.iter().enumerate() {
                    add_entry(&mut reg[(b.first() + ja) % d], (b.first() + jb) % d, h3 * w * va * vb);
                }
            }
        }
    }
    let trace = |m: &[Vec<(usize, f64)>]| {
        m.iter().enumerate().flat_map(|(i, r)| r.iter().filter(move |e| e.0 == i)).map(|e| e.1).sum::<f64>()
    };
    let (data_tr, reg_tr) = (trace(&rows), trace(&reg));
    if reg_tr > 0.0 {
        let lambda = if data_tr > 0.0 { REGULARIZATION * data_tr / reg_tr } else { 1.0 };
        for (r, g) in rows.iter_mut().zip(&reg) {
            for &(c, v) in g {
                add_entry(r, c, lambda * v);
            }
        }
    }
    for r in &mut rows {
        r.sort_by_key(|e| e.0);
    }
    let singular =
        || Error::LinearSolver(format!("the periodic least-squares fit with {d} control points is singular"));
    let mut chol = LinearSolver::new(LinearMethod::Cholesky);
    chol.factor(&Csr::from_rows(d, rows)).map_err(|_| singular())?;
    let mut cols = [vec![0.0; d], vec![0.0; d]];
    for (k, col) in cols.iter_mut().enumerate() {
        *col = chol.solve(&rhs.iter().map(|r| r[k]).collect::<Vec<f64>>()).map_err(|_| singular())?;
    }
    if cols.iter().flatten().any(|v| !v.is_finite()) {
        return Err(singular());
    }
    let cps: Vec<Point> = (0..kv.num_basis()).map(|k| [cols[0][k % d], cols[1][k % d]]).collect();
    let curve = Curve::polynomial(kv.clone(), cps);
    let elements = kv.elements();
    let mut per = vec![0.0f64; elements.len()];
    let mut err = 0.0f64;
    for (&s, &x) in smp.s.iter().zip(&smp.x) {
        let e = dist(curve.eval(s), x);
        err = err.max(e);
        let k = elements.partition_point(|el| el.2 <= s).min(elements.len() - 1);
        per[k] = per[k].max(e);
    }
    Ok((curve, err, per))
}

/// `row[c] += v` in a sparse row.
fn add_entry(row: &mut Vec<(usize, f64)>, c: usize, v: f64) {
    match row.iter_mut().find(|e| e.0 == c) {
        Some(e) => e.1 += v,
        None => row.push((c, v)),
    }
}

/// [`fit_periodic_elements`] without the per-element errors.
fn fit_periodic(kv: &KnotVector, smp: &Samples) -> Result<(Curve, f64)> {
    fit_periodic_elements(kv, smp).map(|(c, e, _)| (c, e))
}

/// Samples per element of `kv` (elements in the order of [`KnotVector::elements`]).
fn samples_per_element(kv: &KnotVector, smp: &Samples) -> Vec<usize> {
    let elements = kv.elements();
    let mut n = vec![0; elements.len()];
    for &s in &smp.s {
        n[elements.partition_point(|el| el.2 <= s).min(elements.len() - 1)] += 1;
    }
    n
}

/// The least-squares fit of `contour`, parameterized by arc length from its own start,
/// on the periodic vector `kv` (on `[0, 1]`), and its largest deviation at the samples.
pub fn fit_contour(contour: &ClosedContour, kv: &KnotVector) -> Result<(Curve, f64)> {
    if !kv.is_periodic() || kv.domain() != (0.0, 1.0) {
        return Err(Error::Invalid(format!(
            "a closed contour is fitted on a periodic knot vector on [0, 1], got periodic {} on {:?}",
            kv.is_periodic(),
            kv.domain()
        )));
    }
    fit_periodic(kv, &contour.arc_length_samples())
}

/// Like [`fit_contour`], with `eta = 0` put where the ray from `origin` towards `toward`
/// first crosses the contour (the arc-length parameter shifted by that crossing's
/// fraction; the contour's own start when the ray misses it).
pub(crate) fn fit_contour_seam(
    contour: &ClosedContour,
    kv: &KnotVector,
    origin: Point,
    toward: Point,
) -> Result<(Curve, f64)> {
    let smp = contour.arc_length_samples();
    let dir = [toward[0] - origin[0], toward[1] - origin[1]];
    let shift = ray_crossing(&smp.x, &smp.s, origin, dir).unwrap_or(0.0);
    fit_contour_shifted(kv, smp, shift)
}

fn fit_contour_shifted(kv: &KnotVector, smp: Samples, shift: f64) -> Result<(Curve, f64)> {
    fit_periodic(kv, &wrapped(smp.s.iter().map(|s| s - shift), &smp.x))
}

/// Validate a ring (closed contours, counter-clockwise, the inner inside the outer),
/// bring it to unit size (`Similarity`), reparameterize both contours by arc length
/// with the seam of the module documentation (and match narrow gaps: the default
/// [`ReparamOptions`], `auto`, see `boundary::ring_reparam`), and fit them
/// adaptively on dyadic periodic knot vectors of degree `degree` until `tol * diameter`
/// is met (at most `max_elements` elements).
#[cfg(any(test, feature = "testutil"))]
pub(crate) fn fit_ring(ring: &Ring, degree: usize, tol: f64, max_elements: usize) -> Result<RingFit> {
    fit_ring_with(ring, degree, tol, max_elements, EtaRefinement::Adaptive, &ReparamOptions::default())
}

/// Check a ring: both contours closed and finite, counter-clockwise, the inner inside
/// the outer (on polygons of about 4096 points). Returns the outer contour's
/// bounding box `[lo, hi]`.
///
/// Like a four-sided boundary's validation, the checks run in the normalised
/// coordinates of the outer contour's box (`Similarity`) and report in the input's:
/// far from the origin, `Σ x_k y_{k+1} − x_{k+1} y_k` of the raw coordinates cancels
/// every digit of the area (a ring of size 1 at `1e9` got a signed area of `−4e3`), and
/// the closure gap of a spline evaluated there is rounding of the position, not of the
/// curve. A well-placed ring (the identity) is checked on its own coordinates as before.
pub fn check_ring(ring: &Ring) -> Result<[Point; 2]> {
    // validation on polygons of about 4096 points (the nesting test is quadratic)
    let raw_outer = ring.outer.polygon_with(CHECK);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &raw_outer {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let diameter = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    if !(diameter.is_finite() && diameter > 0.0) {
        return Err(Error::Invalid(format!("ring '{}': the outer contour has diameter {diameter}", ring.name)));
    }
    let sim = Similarity::for_box(lo, hi, &format!("ring '{}'", ring.name))?;
    let unit = |c: &ClosedContour| if sim.is_identity() { c.clone() } else { c.mapped(move |p| sim.to_unit(p)) };
    let (inner, outer) = (unit(&ring.inner), unit(&ring.outer));
    let unit_diameter = diameter / sim.scale;
    inner.validate("inner", unit_diameter, &sim)?;
    outer.validate("outer", unit_diameter, &sim)?;
    let outer_poly = if sim.is_identity() { raw_outer } else { outer.polygon_with(CHECK) };
    let inner_poly = inner.polygon_with(CHECK);
    for (what, poly) in [("inner", &inner_poly), ("outer", &outer_poly)] {
        let area = signed_area(poly);
        if area <= 0.0 {
            return Err(Error::Invalid(format!(
                "the {what} contour runs clockwise (signed area {:.6e}); both contours of a ring must run counter-clockwise",
                sim.area(area)
            )));
        }
    }
    let stride = inner_poly.len().div_ceil(CHECK);
    if let Some(p) = inner_poly.iter().step_by(stride).find(|&&p| !inside(&outer_poly, p)) {
        let p = sim.to_physical(*p);
        return Err(Error::Invalid(format!(
            "the inner contour is not inside the outer one: its point ({}, {}) lies outside",
            p[0], p[1]
        )));
    }
    Ok([lo, hi])
}

/// Points of the polygons a ring is validated on (closed, oriented, nested).
const CHECK: usize = 4096;

/// How the ring fit refines its knot vector in `eta`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EtaRefinement {
    /// Bisect the elements that miss the tolerance (§5; the module documentation).
    #[default]
    Adaptive,
    /// Halve every element while any misses it: uniform knots, whose space is invariant
    /// under shifts by whole elements (a sliding grid moves the parameter along the
    /// contour, where locally refined elements would not follow the features).
    Uniform,
}

/// `fit_ring` with the refinement in `eta` and the reparameterization chosen.
pub fn fit_ring_with(
    ring: &Ring,
    degree: usize,
    tol: f64,
    max_elements: usize,
    refinement: EtaRefinement,
    reparam: &ReparamOptions,
) -> Result<RingFit> {
    let [lo, hi] = check_ring(ring)?;
    let diameter = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    let similarity = Similarity::for_box(lo, hi, &format!("ring '{}'", ring.name))?;
    let unit =
        |c: &ClosedContour| if similarity.is_identity() { c.clone() } else { c.mapped(move |p| similarity.to_unit(p)) };
    let (inner_c, outer_c) = (unit(&ring.inner), unit(&ring.outer));
    let diameter = diameter / similarity.scale;
    let inner = inner_c.arc_length_samples();
    let mut outer = outer_c.arc_length_samples();
    // the seam: the ray from the inner centroid through the inner start
    let m = inner.x.len() as f64;
    let c = [inner.x.iter().map(|p| p[0]).sum::<f64>() / m, inner.x.iter().map(|p| p[1]).sum::<f64>() / m];
    let start = inner.x[0];
    let dir = [start[0] - c[0], start[1] - c[1]];
    let shift = ray_crossing(&outer.x, &outer.s, c, dir).unwrap_or_else(|| {
        // no crossing (degenerate direction): the outer point nearest to the inner start
        let k = (0..outer.x.len()).min_by(|&a, &b| dist(outer.x[a], start).total_cmp(&dist(outer.x[b], start)));
        outer.s[k.unwrap_or(0)]
    });
    outer = wrapped(outer.s.iter().map(|s| s - shift), &outer.x);
    // narrow gaps: matched pairs at the same eta (the inner keeps arc length)
    let (matched, report) = ring_reparam(&inner, &outer, diameter, reparam)?;
    if let Some(m) = matched {
        outer = m;
    }
    // rounded corners of a cloud: the chords there sampled too, refined below p + 1
    // samples per element
    let (inner, near_i) = along_roundings(&inner_c, inner);
    let (outer, near_o) = along_roundings(&outer_c, outer);
    let near = [near_i, near_o];
    let tol_abs = tol * diameter;
    let mut levels = Vec::new();
    let mut kv = KnotVector::periodic_uniform(degree, 4.max(degree + 1).next_power_of_two());
    loop {
        let (ci, ei, per_i) = fit_periodic_elements(&kv, &inner)?;
        let (co, eo, per_o) = fit_periodic_elements(&kv, &outer)?;
        levels.push(RingLevel { knots: kv.clone(), curves: [ci, co], max_error: [ei, eo] });
        let done = ei <= tol_abs && eo <= tol_abs;
        let finish = |levels| {
            let reparam = report.clone();
            Ok(RingFit { levels, converged: done, tol_abs, diameter, outer_shift: shift, similarity, reparam })
        };
        if done {
            return finish(levels);
        }
        // bisect the elements off by more than the tolerance whose halves keep p + 1
        // samples of both contours
        let halves = kv.halved();
        let (ni, no) = (samples_per_element(&halves, &inner), samples_per_element(&halves, &outer));
        let rounded = [rounded_elements(&kv, &inner, &near[0]), rounded_elements(&kv, &outer, &near[1])];
        let uniform = refinement == EtaRefinement::Uniform;
        let marked: Vec<usize> = (0..per_i.len())
            .filter(|&e| uniform || per_i[e].max(per_o[e]) > tol_abs)
            .filter(|&e| {
                // a contour that misses the tolerance here needs samples in both halves,
                // or one sample in each near a rounded corner
                let enough = |per: &[f64], n: &[usize], rounded: &[bool]| {
                    let least = if rounded[e] { 0 } else { degree };
                    per[e] <= tol_abs || (2 * e..2 * e + 2).all(|h| n[h] > least)
                };
                enough(&per_i, &ni, &rounded[0]) && enough(&per_o, &no, &rounded[1])
            })
            .collect();
        if marked.is_empty()
            || (uniform && marked.len() < per_i.len())
            || kv.num_elements() + marked.len() > max_elements
        {
            return finish(levels);
        }
        kv = kv.with_inserted(&kv.midpoints_of(&marked.iter().map(|&e| kv.elements()[e].0).collect::<Vec<_>>()));
    }
}

/// The ring cut open along the seam, as a four-sided [`Boundary`] for reports: west the
/// inner and east the outer contour (as given), south and north the seam segment from
/// the inner to the outer contour at `eta = 0` (`seam`).
pub fn cut_open(ring: &Ring, seam: [Point; 2]) -> Boundary {
    let s = SideCurve::Points(seam.to_vec());
    Boundary { name: ring.name.clone(), sides: [s.clone(), ring.outer.as_side(), s, ring.inner.as_side()] }
}

/// [`ring_hierarchy`] with the refinement in `eta` chosen.
pub(crate) fn ring_hierarchy_with(
    ring: &Ring,
    opts: &FitOptions,
    refinement: EtaRefinement,
) -> Result<(Hierarchy, Boundary)> {
    opts.validate()?;
    let fit = fit_ring_with(ring, opts.degree, opts.tol, opts.max_elements, refinement, &opts.reparam)?;
    let p = opts.degree;
    let xi = KnotVector::open_uniform(p, 1);
    let finest = &fit.levels.last().expect("at least one fit").curves;
    let seam = [finest[0].eval(0.0), finest[1].eval(0.0)];
    let line = {
        let g = xi.greville();
        let cps = g.iter().map(|&u| [(1.0 - u) * seam[0][0] + u * seam[1][0], (1.0 - u) * seam[0][1] + u * seam[1][1]]);
        Curve::polynomial(xi.clone(), cps.collect())
    };
    let levels = fit
        .levels
        .iter()
        .map(|l| Level {
            knots: [xi.clone(), l.knots.clone()],
            sides: [line.clone(), l.curves[1].clone(), line.clone(), l.curves[0].clone()],
        })
        .collect();
    let side_fit = |side: Side, k: Option<usize>| SideFit {
        side,
        levels: match k {
            Some(k) => fit.levels.iter().map(|l| l.curves[k].clone()).collect(),
            None => vec![line.clone()],
        },
        max_error: match k {
            Some(k) => fit.levels.iter().map(|l| l.max_error[k]).collect(),
            None => vec![0.0],
        },
        rms_error: vec![0.0; k.map_or(1, |_| fit.levels.len())],
        params: None,
        converged: k.is_none_or(|k| fit.levels.last().is_some_and(|l| l.max_error[k] <= fit.tol_abs)),
    };
    let fits = [
        side_fit(Side::South, None),
        side_fit(Side::East, Some(1)),
        side_fit(Side::North, None),
        side_fit(Side::West, Some(0)),
    ];
    let cut = cut_open(ring, seam.map(|p| fit.similarity.to_physical(p)));
    // on the cut-open boundary, in the input's coordinates (the report measures there)
    let (detected, roundings) =
        crate::boundary::kinks::detect_with_roundings(&cut, crate::boundary::KinkMode::Auto, false);
    let h = Hierarchy {
        levels,
        fits,
        tol_abs: fit.tol_abs,
        diameter: fit.diameter,
        reparam: fit.reparam.clone(),
        basis: BasisReport::fitted(),
        kinked: None,
        similarity: fit.similarity,
        detected,
        roundings,
    };
    Ok((h, cut))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::Analytic;
    use std::f64::consts::TAU;

    fn circle(r: f64, c: Point, phase: f64) -> ClosedContour {
        ClosedContour::Analytic(Analytic::new(move |t| {
            [c[0] + r * (TAU * t + phase).cos(), c[1] + r * (TAU * t + phase).sin()]
        }))
    }

    pub(super) use crate::testutil::rounded_square;

    /// A ring whose outer contour is a cloud with rounded corners (four points to each
    /// quarter circle, as the jigsaw necks): its report lists them as roundings, not as
    /// kinks (a kink not kept would make the solve's exit code say "kinks not kept"); the
    /// same corners sharp are kinks.
    #[test]
    fn rounded_corners_of_a_cloud_contour_are_roundings_not_kinks() {
        let opts = FitOptions::default();
        let ring = |outer| Ring { name: "rounded".into(), inner: circle(1.0, [0.0; 2], 0.3), outer };
        let rounded = ring(ClosedContour::Points(rounded_square(0.05, 0.02)));
        let (h, cut) = ring_hierarchy_with(&rounded, &opts, EtaRefinement::default()).unwrap();
        assert!(h.detected.is_empty(), "{:?}", h.detected);
        assert_eq!(h.roundings.len(), 4, "{:?}", h.roundings);
        assert!(h.roundings.iter().all(|r| r.radius > 0.02 && r.radius < 0.2), "{:?}", h.roundings);
        // without the rounding rule the same corners were kinks
        assert_eq!(crate::boundary::kinks::detect(&cut, crate::boundary::KinkMode::Auto, false).len(), 4);
        let sharp = ring(ClosedContour::Points(rounded_square(0.0, 0.02)));
        let (h, _) = ring_hierarchy_with(&sharp, &opts, EtaRefinement::default()).unwrap();
        assert_eq!((h.detected.len(), h.roundings.len()), (4, 0), "{:?}", h.roundings);
    }

    #[test]
    fn circles_fit_on_one_periodic_vector_with_aligned_seam() {
        let ring =
            Ring { name: "annulus".into(), inner: circle(1.0, [0.0; 2], 0.0), outer: circle(2.0, [0.0; 2], 1.0) };
        let f = fit_ring(&ring, 3, 1e-6, 4096).unwrap();
        assert!(f.converged);
        let last = f.levels.last().unwrap();
        // the outer start (phase 1 rad) is shifted so that eta = 0 is at angle 0
        assert!((f.outer_shift - (1.0 - 1.0 / TAU)).abs() < 1e-3, "{}", f.outer_shift);
        let p = last.curves[1].eval(0.0);
        assert!(p[1].abs() < 1e-5 && (p[0] - 2.0).abs() < 1e-5, "{p:?}");
        // arc length: eta = 0.25 is at a quarter turn on both
        for c in &last.curves {
            let q = c.eval(0.25);
            assert!(q[0].abs() < 1e-5 * 2.0, "{q:?}");
        }
        // errors halve by about 2^4 per level (cubic)
        let e: Vec<f64> = f.levels.iter().map(|l| l.max_error[0]).collect();
        assert!(e.windows(2).all(|w| w[1] < w[0] / 8.0), "{e:?}");
    }

    #[test]
    fn bad_rings_are_typed_errors() {
        let swapped = Ring { name: "x".into(), inner: circle(2.0, [0.0; 2], 0.0), outer: circle(1.0, [0.0; 2], 0.0) };
        assert!(fit_ring(&swapped, 3, 1e-4, 64).unwrap_err().to_string().contains("inside"));
        let cw = ClosedContour::Analytic(Analytic::new(|t| [(TAU * t).cos(), -(TAU * t).sin()]));
        let r = Ring { name: "x".into(), inner: cw, outer: circle(2.0, [0.0; 2], 0.0) };
        assert!(fit_ring(&r, 3, 1e-4, 64).unwrap_err().to_string().contains("clockwise"));
        let open = ClosedContour::Analytic(Analytic::new(|t| [(6.0 * t).cos(), (6.0 * t).sin()]));
        let r = Ring { name: "x".into(), inner: open, outer: circle(2.0, [0.0; 2], 0.0) };
        assert!(fit_ring(&r, 3, 1e-4, 64).unwrap_err().to_string().contains("not closed"));
        let few = ClosedContour::Points(vec![[0.0, 0.0], [1.0, 0.0]]);
        let r = Ring { name: "x".into(), inner: few, outer: circle(2.0, [0.0; 2], 0.0) };
        assert!(matches!(fit_ring(&r, 3, 1e-4, 64), Err(Error::TooFewPoints { .. })));
    }

    /// A contour with one narrow bump: the adaptive fit meets the tolerance with fewer
    /// elements than the uniform one, its levels are nested and dyadic, and the small
    /// elements sit at the bump.
    #[test]
    fn adaptive_fit_is_local_nested_and_dyadic() {
        let bump = ClosedContour::Analytic(Analytic::new(|t| {
            let r = 1.0 + 0.3 * (-((t - 0.3) / 0.01).powi(2)).exp();
            [r * (TAU * t).cos(), r * (TAU * t).sin()]
        }));
        let ring = Ring { name: "bump".into(), inner: bump, outer: circle(3.0, [0.0; 2], 0.0) };
        let o = ReparamOptions::default();
        let a = fit_ring_with(&ring, 3, 1e-4, 4096, EtaRefinement::Adaptive, &o).unwrap();
        let u = fit_ring_with(&ring, 3, 1e-4, 4096, EtaRefinement::Uniform, &o).unwrap();
        assert!(a.converged && u.converged);
        let (ka, ku) = (&a.levels.last().unwrap().knots, &u.levels.last().unwrap().knots);
        assert!(2 * ka.num_elements() < ku.num_elements(), "{} vs {}", ka.num_elements(), ku.num_elements());
        for w in a.levels.windows(2) {
            assert!(w[1].knots.contains(&w[0].knots) && w[1].knots.is_periodic());
        }
        let h = ka.elements().iter().map(|e| e.2 - e.1).collect::<Vec<_>>();
        for &x in &h {
            let k = -x.log2();
            assert!((k - k.round()).abs() < 1e-12, "element of length {x} is not dyadic");
        }
        // the smallest element is near the bump (its arc-length fraction is about 0.3)
        let small = ka.elements().into_iter().min_by(|x, y| (x.2 - x.1).total_cmp(&(y.2 - y.1))).unwrap();
        assert!((0.5 * (small.1 + small.2) - 0.3).abs() < 0.15, "smallest element at {small:?}");
        assert!(a.levels.last().unwrap().max_error.iter().all(|&e| e <= a.tol_abs));
    }

    /// A ring far from the origin and large is fitted in unit coordinates: the same
    /// levels and, mapped back, the same curves as the ring at the origin.
    #[test]
    fn far_rings_are_normalised() {
        let ring = Ring { name: "ecc".into(), inner: circle(0.4, [0.25, 0.1], 0.0), outer: circle(1.0, [0.0; 2], 0.0) };
        let f = fit_ring(&ring, 3, 1e-4, 4096).unwrap();
        assert!(f.similarity.is_identity());
        let (c, s) = ([3.0e9, -1.0e9], 2.0f64.powi(30));
        let far = Ring {
            name: "far".into(),
            inner: ring.inner.mapped(move |p| [c[0] + s * p[0], c[1] + s * p[1]]),
            outer: ring.outer.mapped(move |p| [c[0] + s * p[0], c[1] + s * p[1]]),
        };
        let g = fit_ring(&far, 3, 1e-4, 4096).unwrap();
        assert!(!g.similarity.is_identity());
        assert_eq!(f.levels.len(), g.levels.len());
        let (lf, lg) = (f.levels.last().unwrap(), g.levels.last().unwrap());
        for k in 0..2 {
            for (p, q) in lf.curves[k].control_points.iter().zip(&lg.curves[k].control_points) {
                let q = g.similarity.to_physical(*q);
                let back = [(q[0] - c[0]) / s, (q[1] - c[1]) / s];
                assert!((p[0] - back[0]).abs() < 1e-6 && (p[1] - back[1]).abs() < 1e-6, "{p:?} vs {back:?}");
            }
        }
    }
}
