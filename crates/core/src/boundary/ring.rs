//! Ring (O-type) domains (paper §11.1): two closed contours, the inner at `xi = 0` and
//! the outer at `xi = 1`, fitted on one periodic knot vector in `eta`, and the nested
//! hierarchy of bases `Ξ_k × H_k` (`H_k` periodic) the solver walks with periodic
//! `eta` ([`crate::discrete::topology::Topology::ring`]).
//!
//! **Parameterization.** Both contours are parameterized by arc length, `eta = s / L`
//! (eq. 38-39 for parametric contours, cord length eq. 36-37 for point clouds), so that
//! grid lines `eta = const` join points at equal fractions of the two perimeters.
//! **Seam (`eta = 0`).** The inner contour keeps its own start (`eta = 0` at its first
//! point or parameter); the outer contour's `eta = 0` is where the ray from the inner
//! contour's centroid through the inner start first crosses it (for concentric
//! circles starting at angle 0: both at angle 0). The outer arc-length fraction is
//! shifted by that crossing's fraction `s_0`: `eta_outer = (s - s_0) mod 1`.
//!
//! **Fit.** Least squares on periodic uniform vectors of `n = 4, 8, 16, ...` elements
//! (dyadic in `eta`, one vector for both contours): `min sum_k |C(eta_k) - x_k|^2` over
//! the `d = n` distinct control points (wrapped collocation matrix), until both
//! contours are within `tol * diameter` at every sample (§5).

use super::fit::{FitOptions, SideFit};
use super::hierarchy::{BasisReport, Hierarchy, Level};
use super::reparam::{Reparam, ReparamReport};
use super::{Analytic, Boundary, SideCurve};
use crate::error::{Error, Result};
use crate::spline::basis::BasisDerivs;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;

/// A closed contour as given by the user.
#[derive(Debug, Clone)]
pub enum ClosedContour {
    /// A closed B-spline or NURBS curve: periodic, or clamped with equal ends.
    Spline(Curve),
    /// An ordered closed point cloud (the last point does not repeat the first).
    Points(Vec<Point>),
    /// A closed analytic curve `t in [0, 1] -> (x, y)`, `f(0) = f(1)` (library only).
    Analytic(Analytic),
}

/// A doubly connected domain between two closed counter-clockwise contours.
#[derive(Debug, Clone)]
pub struct Ring {
    /// Name of the geometry.
    pub name: String,
    /// The inner contour (`xi = 0`).
    pub inner: ClosedContour,
    /// The outer contour (`xi = 1`).
    pub outer: ClosedContour,
}

/// Samples of a contour at increasing arc-length fractions `s in [0, 1)`.
#[derive(Debug, Clone)]
struct Samples {
    s: Vec<f64>,
    x: Vec<Point>,
}

const DENSE: usize = 4096;

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

impl ClosedContour {
    /// Evaluate a parametric contour at `t in [0, 1]`.
    fn eval(&self, t: f64) -> Point {
        match self {
            ClosedContour::Spline(c) => {
                let (a, b) = c.domain();
                c.eval(a + (b - a) * t)
            }
            ClosedContour::Analytic(f) => f.eval(t),
            ClosedContour::Points(p) => p[((t * p.len() as f64) as usize).min(p.len() - 1)],
        }
    }

    /// A dense closed polygon (last point not repeated) and its parameters.
    fn polygon(&self) -> Vec<Point> {
        match self {
            ClosedContour::Points(p) => p.clone(),
            ClosedContour::Spline(c) => {
                let m = (64 * c.knots.num_elements()).max(DENSE);
                (0..m).map(|k| self.eval(k as f64 / m as f64)).collect()
            }
            ClosedContour::Analytic(_) => (0..DENSE).map(|k| self.eval(k as f64 / DENSE as f64)).collect(),
        }
    }

    /// Check closedness, size and finiteness; `what` names the contour.
    fn validate(&self, what: &str, diameter: f64) -> Result<()> {
        let (a, b) = match self {
            ClosedContour::Points(p) => {
                if p.len() < 4 {
                    return Err(Error::TooFewPoints { side: what.into(), found: p.len(), needed: 4 });
                }
                if let Some(i) = p.iter().position(|q| !q[0].is_finite() || !q[1].is_finite()) {
                    return Err(Error::NonFinite { context: what.into(), what: format!("point {i}") });
                }
                return Ok(());
            }
            _ => (self.eval(0.0), self.eval(1.0)),
        };
        let gap = dist(a, b);
        if gap.is_nan() || gap > 1e-9 * diameter {
            return Err(Error::Invalid(format!(
                "the {what} contour is not closed: its ends ({}, {}) and ({}, {}) are {gap:.3e} apart (tolerance {:.3e})",
                a[0],
                a[1],
                b[0],
                b[1],
                1e-9 * diameter
            )));
        }
        Ok(())
    }

    /// Samples at arc-length fractions: the points themselves (cord length) for a point
    /// cloud, [`DENSE`] points at uniform fractions for a parametric contour.
    fn arc_length_samples(&self) -> Samples {
        let poly = self.polygon();
        let n = poly.len();
        let mut cum = vec![0.0; n + 1];
        for k in 0..n {
            cum[k + 1] = cum[k] + dist(poly[k], poly[(k + 1) % n]);
        }
        let total = cum[n];
        if let ClosedContour::Points(p) = self {
            return Samples { s: cum[..n].iter().map(|c| c / total).collect(), x: p.clone() };
        }
        // invert the arc length of the dense polygon, then evaluate the exact curve
        let mut s = Vec::with_capacity(DENSE);
        let mut x = Vec::with_capacity(DENSE);
        let mut k = 0;
        for m in 0..DENSE {
            let target = total * m as f64 / DENSE as f64;
            while k + 1 < n && cum[k + 1] <= target {
                k += 1;
            }
            let frac = if cum[k + 1] > cum[k] { (target - cum[k]) / (cum[k + 1] - cum[k]) } else { 0.0 };
            s.push(m as f64 / DENSE as f64);
            x.push(self.eval((k as f64 + frac) / n as f64));
        }
        Samples { s, x }
    }

    /// The contour as a side of the cut-open boundary used for reports: a closed polygon
    /// for a point cloud (first point repeated at the end), the curve itself otherwise.
    fn as_side(&self) -> SideCurve {
        match self {
            ClosedContour::Points(p) => {
                let mut q = p.clone();
                q.push(p[0]);
                SideCurve::Points(q)
            }
            ClosedContour::Spline(c) => SideCurve::Spline(c.clone()),
            ClosedContour::Analytic(f) => SideCurve::Analytic(f.clone()),
        }
    }
}

/// Signed area of a closed polygon (positive when counter-clockwise).
pub fn signed_area(poly: &[Point]) -> f64 {
    let n = poly.len();
    0.5 * (0..n).map(|k| poly[k][0] * poly[(k + 1) % n][1] - poly[(k + 1) % n][0] * poly[k][1]).sum::<f64>()
}

/// Whether `p` lies inside the closed polygon (winding number, non-zero rule).
fn inside(poly: &[Point], p: Point) -> bool {
    let n = poly.len();
    let mut wind = 0i32;
    for k in 0..n {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        let cross = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
        if a[1] <= p[1] && b[1] > p[1] && cross > 0.0 {
            wind += 1;
        } else if a[1] > p[1] && b[1] <= p[1] && cross < 0.0 {
            wind -= 1;
        }
    }
    wind != 0
}

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
}

/// Least-squares fit `min sum_k |C(s_k) - x_k|^2` of a periodic curve on `kv`.
fn fit_periodic(kv: &KnotVector, smp: &Samples) -> Result<(Curve, f64)> {
    let d = kv.dim();
    let mut n = vec![vec![0.0; d]; d];
    let mut rhs = vec![vec![0.0; 2]; d];
    for (&s, x) in smp.s.iter().zip(&smp.x) {
        let b = BasisDerivs::at(kv, s, 0);
        let v = b.ders(0);
        for (ja, &va) in v.iter().enumerate() {
            let a = (b.first() + ja) % d;
            rhs[a][0] += va * x[0];
            rhs[a][1] += va * x[1];
            for (jb, &vb) in v.iter().enumerate() {
                n[a][(b.first() + jb) % d] += va * vb;
            }
        }
    }
    let c = crate::linalg::linsolve::dense_solve(&n, &rhs);
    if c.iter().flatten().any(|v| !v.is_finite()) {
        return Err(Error::LinearSolver(format!("the periodic least-squares fit with {d} control points is singular")));
    }
    let cps: Vec<Point> = (0..kv.num_basis()).map(|k| [c[k % d][0], c[k % d][1]]).collect();
    let curve = Curve::polynomial(kv.clone(), cps);
    let err = smp.s.iter().zip(&smp.x).map(|(&s, &x)| dist(curve.eval(s), x)).fold(0.0, f64::max);
    Ok((curve, err))
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
pub fn fit_contour_seam(
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
    let mut pairs: Vec<(f64, Point)> =
        smp.s.iter().zip(&smp.x).map(|(&s, &x)| ((s - shift).rem_euclid(1.0), x)).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    fit_periodic(kv, &Samples { s: pairs.iter().map(|p| p.0).collect(), x: pairs.iter().map(|p| p.1).collect() })
}

/// The parameter `u` of the crossing of the closed curve `c` with the ray `origin + t dir`
/// (`t > 0`) nearest to `near` (periodically): `g(u) = cross(dir, c(u) - origin) = 0`,
/// by Newton's method from `near` when it lands on the ray within one mean element of
/// `near`, else bracketed on `8` samples per element and refined by bisection to
/// rounding. `None` when the ray misses the curve. Used to keep a seam on a ray while the
/// curve turns (a sliding grid).
pub fn ray_parameter(c: &Curve, origin: Point, dir: Point, near: f64) -> Option<f64> {
    let (a, b) = c.domain();
    let l = b - a;
    let wrap = |u: f64| a + (u - a).rem_euclid(l);
    let mut u = near;
    for _ in 0..12 {
        let d = c.derivs(wrap(u), 1);
        let w = [d.x[0] - origin[0], d.x[1] - origin[1]];
        let (g, dg) = (dir[0] * w[1] - dir[1] * w[0], dir[0] * d.d1[1] - dir[1] * d.d1[0]);
        let du = g / dg;
        if !du.is_finite() {
            break;
        }
        u -= du;
        if du.abs() <= 1e-15 * l {
            let p = c.eval(wrap(u));
            let along = dir[0] * (p[0] - origin[0]) + dir[1] * (p[1] - origin[1]);
            if along > 0.0 && (u - near).abs() <= l / c.knots.num_elements().max(1) as f64 {
                return Some(wrap(u));
            }
            break;
        }
    }
    let g = |u: f64| {
        let p = c.eval(u);
        let w = [p[0] - origin[0], p[1] - origin[1]];
        (dir[0] * w[1] - dir[1] * w[0], dir[0] * w[0] + dir[1] * w[1])
    };
    let m = 8 * c.knots.num_elements().max(8);
    let us: Vec<f64> = (0..=m).map(|k| a + l * k as f64 / m as f64).collect();
    let gs: Vec<(f64, f64)> = us.iter().map(|&u| g(u)).collect();
    let near = a + (near - a).rem_euclid(l);
    let gap = |u: f64| {
        let d = (u - near).rem_euclid(l);
        d.min(l - d)
    };
    let mut best: Option<f64> = None;
    for k in 0..m {
        let ((g0, d0), (g1, d1)) = (gs[k], gs[k + 1]);
        if !(g0 <= 0.0 && g1 > 0.0 || g0 >= 0.0 && g1 < 0.0) || d0 + d1 <= 0.0 {
            continue;
        }
        let (mut lo, mut hi) = (us[k], us[k + 1]);
        let s0 = g0.signum();
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if g(mid).0.signum() == s0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let u = if g0 == 0.0 { us[k] } else { 0.5 * (lo + hi) };
        if g(u).1 > 0.0 && best.is_none_or(|v| gap(u) < gap(v)) {
            best = Some(u);
        }
    }
    best
}

impl ClosedContour {
    /// The contour turned rigidly by `angle` (radians, counter-clockwise) about `center`.
    pub fn rotated(&self, center: Point, angle: f64) -> ClosedContour {
        let (c, s) = (angle.cos(), angle.sin());
        let rot = move |p: Point| {
            let (x, y) = (p[0] - center[0], p[1] - center[1]);
            [center[0] + c * x - s * y, center[1] + s * x + c * y]
        };
        match self {
            ClosedContour::Spline(cv) => ClosedContour::Spline(Curve {
                control_points: cv.control_points.iter().map(|&p| rot(p)).collect(),
                ..cv.clone()
            }),
            ClosedContour::Points(p) => ClosedContour::Points(p.iter().map(|&q| rot(q)).collect()),
            ClosedContour::Analytic(f) => {
                let f = f.clone();
                ClosedContour::Analytic(Analytic::new(move |t| rot(f.eval(t))))
            }
        }
    }

    /// The largest distance between this contour and `other` at their dense polygons'
    /// vertices (point clouds: their points), relative to the diameter of `other`'s
    /// bounding box; `None` when the two are sampled differently (different kinds or
    /// numbers of points).
    pub fn deviation_from(&self, other: &ClosedContour) -> Option<f64> {
        let (a, b) = (self.polygon(), other.polygon());
        if a.len() != b.len() || std::mem::discriminant(self) != std::mem::discriminant(other) {
            return None;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &b {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        let diameter = (hi[0] - lo[0]).hypot(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
        Some(a.iter().zip(&b).map(|(p, q)| dist(*p, *q)).fold(0.0, f64::max) / diameter)
    }

    /// The mean of the contour's arc-length samples (its centroid, for point clouds the
    /// mean of the points).
    pub fn centroid(&self) -> Point {
        let x = self.arc_length_samples().x;
        let m = x.len() as f64;
        [x.iter().map(|p| p[0]).sum::<f64>() / m, x.iter().map(|p| p[1]).sum::<f64>() / m]
    }
}

/// Validate a ring (closed contours, counter-clockwise, the inner inside the outer),
/// reparameterize both contours by arc length with the seam of the module
/// documentation, and fit them on dyadic periodic knot vectors of degree `degree`
/// until `tol * diameter` is met (at most `max_elements` elements, at most 1024).
pub fn fit_ring(ring: &Ring, degree: usize, tol: f64, max_elements: usize) -> Result<RingFit> {
    let outer_poly = ring.outer.polygon();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &outer_poly {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let diameter = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    if !(diameter.is_finite() && diameter > 0.0) {
        return Err(Error::Invalid(format!("ring '{}': the outer contour has diameter {diameter}", ring.name)));
    }
    ring.inner.validate("inner", diameter)?;
    ring.outer.validate("outer", diameter)?;
    let inner_poly = ring.inner.polygon();
    for (what, poly) in [("inner", &inner_poly), ("outer", &outer_poly)] {
        let area = signed_area(poly);
        if area <= 0.0 {
            return Err(Error::Invalid(format!(
                "the {what} contour runs clockwise (signed area {area:.6e}); both contours of a ring must run counter-clockwise"
            )));
        }
    }
    if let Some(p) = inner_poly.iter().find(|&&p| !inside(&outer_poly, p)) {
        return Err(Error::Invalid(format!(
            "the inner contour is not inside the outer one: its point ({}, {}) lies outside",
            p[0], p[1]
        )));
    }
    let inner = ring.inner.arc_length_samples();
    let mut outer = ring.outer.arc_length_samples();
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
    let mut pairs: Vec<(f64, Point)> =
        outer.s.iter().zip(&outer.x).map(|(&s, &x)| ((s - shift).rem_euclid(1.0), x)).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    outer = Samples { s: pairs.iter().map(|p| p.0).collect(), x: pairs.iter().map(|p| p.1).collect() };
    let tol_abs = tol * diameter;
    let cap = max_elements.min(1024);
    let min_points = inner.s.len().min(outer.s.len());
    let mut levels = Vec::new();
    let mut n = 4.max(degree + 1).next_power_of_two();
    loop {
        let kv = KnotVector::periodic_uniform(degree, n);
        let (ci, ei) = fit_periodic(&kv, &inner)?;
        let (co, eo) = fit_periodic(&kv, &outer)?;
        levels.push(RingLevel { knots: kv, curves: [ci, co], max_error: [ei, eo] });
        let done = ei <= tol_abs && eo <= tol_abs;
        if done || 2 * n > cap || 2 * n > min_points / 2 {
            return Ok(RingFit { levels, converged: done, tol_abs, diameter, outer_shift: shift });
        }
        n *= 2;
    }
}

/// The ring cut open along the seam, as a four-sided [`Boundary`] for reports: west the
/// inner and east the outer contour (as given), south and north the seam segment from
/// the inner to the outer contour at `eta = 0` (`seam`).
pub fn cut_open(ring: &Ring, seam: [Point; 2]) -> Boundary {
    let s = SideCurve::Points(seam.to_vec());
    Boundary { name: ring.name.clone(), sides: [s.clone(), ring.outer.as_side(), s, ring.inner.as_side()] }
}

/// The hierarchy of a ring for the solver (with `eta` periodic): one level per dyadic
/// fit of [`fit_ring`] (degree, tolerance and element cap from `opts`), basis
/// `Ξ × H_k` with `Ξ` one open element (the solver balances and refines it), west the
/// inner and east the outer fit, south and north the seam segment (not a boundary:
/// periodic sides are skipped by the initial guesses). Returns the hierarchy and the
/// cut-open boundary ([`cut_open`]) the report measures against.
pub fn ring_hierarchy(ring: &Ring, opts: &FitOptions) -> Result<(Hierarchy, Boundary)> {
    opts.validate()?;
    let fit = fit_ring(ring, opts.degree, opts.tol, opts.max_elements)?;
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
    let mut reparam = ReparamReport::native();
    reparam.requested = Reparam::ArcLength;
    reparam.used = Reparam::ArcLength;
    let h = Hierarchy {
        levels,
        fits,
        tol_abs: fit.tol_abs,
        diameter: fit.diameter,
        reparam,
        basis: BasisReport::fitted(),
        similarity: crate::boundary::normalise::Similarity::IDENTITY,
    };
    Ok((h, cut_open(ring, seam)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn circle(r: f64, c: Point, phase: f64) -> ClosedContour {
        ClosedContour::Analytic(Analytic::new(move |t| {
            [c[0] + r * (TAU * t + phase).cos(), c[1] + r * (TAU * t + phase).sin()]
        }))
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
}
