//! Contour approximation (paper §5): each side of the boundary is approximated by a
//! polynomial B-spline curve of degree `p` on a dyadic knot vector over `[0, 1]`, with
//! the corner control points fixed, and the knot vector is refined adaptively until the
//! fit is within a tolerance. The refits form a nested sequence of spline spaces per side;
//! unifying the knot vectors of opposite sides gives the hierarchy of tensor-product bases
//! `Σ^0 ⊂ Σ^1 ⊂ ...` of §5.4, on which the later solves (and their initial guesses, §6.3)
//! are built.
//!
//! # The fit
//!
//! Given a knot vector `Ξ` with basis `{N_i}_{i=0}^{n-1}` and the two corners `c_0`,
//! `c_{n-1}` (constrained, paper §5.1), the free control points `c_1, ..., c_{n-2}`
//! minimize
//!
//! * for a spline or analytic side `f̄: [0,1] -> R^2` (§5.1, §5.2) the `L2` distance
//!   `∫_0^1 ||f(ξ) - f̄(ξ)||^2 dξ`, with `f = Σ c_i N_i`; the normal equations
//!   `Σ_j (∫ N_i N_j) c_j = ∫ N_i f̄` are assembled by Gauss quadrature over the common
//!   refinement of the fit's elements and the input's elements (its breakpoints), so that
//!   the integrand is smooth on every piece, with `p + q + 2` points per piece for an input
//!   of degree `q` (two more when it is rational, `p + 6` for analytic sides);
//! * for a point cloud `p_1, ..., p_K` (§5.3) the discrete distance (eq. 18)
//!   `E(f) = Σ_j ||f(ξ_j) - p_j||^2` at the cord-length abscissae `ξ_j` of eq. 36-37,
//!   plus a tiny smoothing term `λ Σ_e h_e^3 ∫_e ||f''||^2 dξ` (see `REGULARIZATION`):
//!   an element without points (or a side of two points) would otherwise leave the
//!   normal equations singular. The term vanishes on straight lines traversed with
//!   constant speed, so a two-point side becomes exactly that segment. There is no
//!   minimum number of points per element: elements may become smaller than the point
//!   spacing, which is what lets a fit follow a sharp corner of the cloud; an element
//!   without points has no measured error and is never bisected.
//!
//! The normal matrix is banded (half-bandwidth `p`) and symmetric positive definite once
//! the corner unknowns are eliminated; it is factorized by a banded Cholesky
//! decomposition, `O(n p^2)`.
//!
//! # Adaptive refinement
//!
//! Starting from `initial_elements` uniform elements, each fit is followed by the element
//! error indicators: for curves the element-wise average residual of eq. 17,
//! `η_e = (1/|e|) ∫_e ||f - f̄||^2 dξ`, together with the maximal deviation sampled on
//! the element; for point clouds the local contribution of eq. 18 (the points of the
//! element) and their maximal deviation. Every element whose RMS deviation `sqrt(η_e)` or
//! whose maximal deviation exceeds `tol_abs` is bisected (a knot at its midpoint, so all
//! knots stay dyadic, `k / (n_0 2^l)`) and the side is refit; each fit is one level. The
//! loop ends when no element is marked (`converged`) or when `max_levels` fits or
//! `max_elements` elements are reached. Marking also on the maximal deviation makes
//! `converged` imply that the reported `max_error` of the finest level is within
//! `tol_abs`.

use super::cord_length::cord_length_params;
use super::{BasisChoice, KinkMode};
use crate::boundary::reparam::{ParamMap, ReparamOptions, SideParam};
use crate::boundary::{Analytic, SideCurve};
use crate::error::{Error, Result, MAX_DEGREE};
use crate::linalg::banded::Banded;
use crate::spline::basis::BasisDerivs;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::quadrature::GaussLegendre;
use crate::spline::surface::Side;

/// Relative weight `ε` of the smoothing term of point-cloud fits: `λ = ε · tr(B^T B) /
/// tr(R)` on the free unknowns, with `B` the collocation matrix and `R` the matrix of
/// `Σ_e h_e^3 ∫_e N_i'' N_j''` (`λ = 1` when no point constrains a free unknown). The
/// factor `h_e^3` makes the term scale-free (like squared second differences of the
/// control points), so it stays negligible against the data on fine elements too.
pub(crate) const REGULARIZATION: f64 = 1e-10;

/// Samples per input piece and fit element used to estimate the maximal deviation of a
/// curve fit (the piece's end points included).
pub(crate) const SAMPLES_PER_PIECE: usize = 8;

/// A point cloud's fit stops refining when bisecting the marked elements keeps more than
/// this fraction of their points' squared deviation (an RMS ratio of 0.8) and that
/// deviation is uncorrelated ([`NOISE_LAG_ONE`]): the rest is noise ([`fit_side_with`]).
pub(crate) const NOISE_STALL: f64 = 0.64;

/// ... and when the residual's lag-one autocorrelation there is below this (white noise:
/// about 0; a smooth residual sampled densely: about 1).
pub(crate) const NOISE_LAG_ONE: f64 = 0.5;

/// ... judged only where the bisected elements hold this many points each on average
/// (fewer say nothing about noise: a cubic through a handful of points interpolates).
pub(crate) const NOISE_MIN_POINTS: usize = 12;

/// Options of the adaptive contour fit.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct FitOptions {
    /// Degree `p >= 2` of the fitted curves (and of the tensor basis). Default 3.
    pub degree: usize,
    /// Tolerance relative to the diameter of the boundary's bounding box. Default `1e-4`.
    pub tol: f64,
    /// Number of uniform elements of the coarsest fit. Default 1.
    pub initial_elements: usize,
    /// Largest number of fits (levels) per side. Default 14.
    pub max_levels: usize,
    /// Largest number of elements per side (safety cap). Default 4096.
    pub max_elements: usize,
    /// Reparameterization of the sides before the fit (paper §7). Default `auto`.
    pub reparam: ReparamOptions,
    /// The basis: `Auto` (default: the input's own basis, boundary kept exactly, when its
    /// map certifies, else fitted), `Fitted` or `Input` (`input_basis`, §5.2).
    pub basis: BasisChoice,
    /// Which kinks inside the sides are kept exactly (paper §9, [`super::kinks`]).
    pub kinks: KinkMode,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            degree: 3,
            tol: 1e-4,
            initial_elements: 1,
            max_levels: 14,
            max_elements: 4096,
            reparam: ReparamOptions::default(),
            basis: BasisChoice::Auto,
            kinks: KinkMode::Auto,
        }
    }
}

impl FitOptions {
    /// Check the ranges of all fields.
    pub fn validate(&self) -> Result<()> {
        if self.degree < 2 || self.degree > MAX_DEGREE {
            return Err(Error::Degree {
                context: "fit options".into(),
                degree: self.degree,
                reason: format!("the contour fit needs 2 <= p <= {MAX_DEGREE}"),
            });
        }
        if !(self.tol > 0.0 && self.tol < 1.0) {
            return Err(Error::Invalid(format!(
                "the fit tolerance (fit-tol, relative to the diameter) must be in (0, 1), got {}",
                self.tol
            )));
        }
        if self.initial_elements == 0 || self.max_levels == 0 {
            return Err(Error::Invalid(format!(
                "fit needs initial_elements >= 1 and max_levels >= 1, got {} and {}",
                self.initial_elements, self.max_levels
            )));
        }
        if self.max_elements < self.initial_elements {
            return Err(Error::Invalid(format!(
                "max_elements ({}) is below initial_elements ({})",
                self.max_elements, self.initial_elements
            )));
        }
        self.kinks.validate()?;
        self.reparam.validate()
    }
}

/// The error of a fit on one element of its knot vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementError {
    /// Span index of the element in the fit's knot vector.
    pub span: usize,
    /// Left end.
    pub a: f64,
    /// Right end.
    pub b: f64,
    /// Curves: `(1/|e|) ∫_e ||f - f̄||^2` (eq. 17, a mean squared deviation); point
    /// clouds: `Σ_{ξ_j ∈ e} ||f(ξ_j) - p_j||^2` (the element's part of eq. 18).
    pub indicator: f64,
    /// Largest deviation on the element (sampled for curves, at the points for clouds).
    pub max: f64,
    /// Point clouds: `Σ r_j · r_{j-1}` over consecutive points of the element, `r_j =
    /// f̄(ξ_j) - p_j` (the lag-one autocovariance of the residual: near
    /// [`ElementError::indicator`] for a smooth, unresolved shape, near zero for noise);
    /// curves: 0.
    pub lag_one: f64,
    /// Point clouds: the number of points on the element; curves: 0.
    pub points: usize,
}

/// One constrained least-squares fit on a given knot vector.
#[derive(Debug, Clone)]
pub struct Projection {
    /// The fitted polynomial curve; its end points are the corners.
    pub curve: Curve,
    /// Largest deviation (sampled for curves, exact at the points for clouds).
    pub max_error: f64,
    /// Curves: `sqrt(∫_0^1 ||f - f̄||^2)`; clouds: `sqrt(E(f) / K)` (eq. 18).
    pub rms_error: f64,
    /// Per-element errors, in the order of [`KnotVector::elements`].
    pub elements: Vec<ElementError>,
}

/// The adaptive fit of one side: the nested sequence of fits (levels).
#[derive(Debug, Clone)]
pub struct SideFit {
    /// Which side.
    pub side: Side,
    /// The fits, coarse to fine: `levels[k + 1].knots` contains `levels[k].knots`; all are
    /// polynomial curves of degree `p` on `[0, 1]` interpolating the two corners.
    pub levels: Vec<Curve>,
    /// Largest deviation of each level (absolute).
    pub max_error: Vec<f64>,
    /// RMS deviation of each level (absolute).
    pub rms_error: Vec<f64>,
    /// The abscissae of the points when the side is a point cloud: cord length (eq.
    /// 36-37) or the constrained cord length of §7.2.
    pub params: Option<Vec<f64>>,
    /// Whether the finest level is within the tolerance on every element.
    pub converged: bool,
}

impl SideFit {
    /// The finest (last) fit.
    pub fn finest(&self) -> &Curve {
        self.levels.last().expect("a side fit has at least one level")
    }

    /// Largest deviation of the finest fit.
    pub fn final_max_error(&self) -> f64 {
        *self.max_error.last().expect("a side fit has at least one level")
    }
}

/// The function (or data) being approximated on one side.
enum Target<'a> {
    /// A spline side, evaluated at `a + g(t) (b - a)` (`g` the identity unless the side
    /// is reparameterized); `breaks` are its element boundaries mapped to `[0, 1]` and
    /// pulled back by `g`, together with the breaks of `g`.
    Spline {
        curve: &'a Curve,
        a: f64,
        len: f64,
        breaks: Vec<f64>,
        nq: usize,
        g: Option<&'a ParamMap>,
    },
    /// An analytic side evaluated at `g(t)`; `breaks` are those of `g` (or empty).
    Analytic {
        f: &'a Analytic,
        nq: usize,
        g: Option<&'a ParamMap>,
        breaks: Vec<f64>,
    },
    Points {
        params: Vec<f64>,
        points: &'a [Point],
    },
}

impl<'a> Target<'a> {
    fn new(curve: &'a SideCurve, param: &'a SideParam, p: usize, side: &str) -> Result<Self> {
        let g = match param {
            SideParam::Map(g) => Some(g),
            _ => None,
        };
        let g_breaks = || g.map(ParamMap::breaks).unwrap_or_default();
        Ok(match curve {
            SideCurve::Spline(c) => {
                let (a, b) = c.domain();
                let len = b - a;
                let mut breaks: Vec<f64> = c
                    .knots
                    .breaks()
                    .into_iter()
                    .map(|u| {
                        let t = ((u - a) / len).clamp(0.0, 1.0);
                        g.map_or(t, |g| g.inverse(t))
                    })
                    .collect();
                breaks.extend(g_breaks());
                breaks.sort_by(f64::total_cmp);
                breaks.dedup();
                // a reparameterized side is only C^1 at the breaks of g: two more points
                let nq = p + c.degree() + 2 + if c.is_rational() { 2 } else { 0 } + if g.is_some() { 2 } else { 0 };
                Target::Spline { curve: c, a, len, breaks, nq, g }
            }
            SideCurve::Analytic(f) => Target::Analytic { f, nq: p + 6, g, breaks: g_breaks() },
            SideCurve::Points(pts) => {
                if pts.len() < 2 {
                    return Err(Error::TooFewPoints { side: side.to_string(), found: pts.len(), needed: 2 });
                }
                let params = match param {
                    SideParam::Abscissae(x) => {
                        if x.len() != pts.len()
                            || x.first() != Some(&0.0)
                            || x.last() != Some(&1.0)
                            || x.iter().any(|v| v.is_nan())
                            || x.windows(2).any(|w| w[1] < w[0])
                        {
                            return Err(Error::Invalid(format!(
                                "{side}: reparameterized abscissae must rise from 0 to 1, one per point"
                            )));
                        }
                        x.clone()
                    }
                    _ => cord_length_params(pts).ok_or_else(|| Error::DegenerateSide {
                        side: side.to_string(),
                        length: 0.0,
                        tol: 0.0,
                    })?,
                };
                Target::Points { params, points: pts }
            }
        })
    }

    /// `f̄(t)` for curve targets.
    fn eval(&self, t: f64) -> Point {
        match self {
            Target::Spline { curve, a, len, g, .. } => {
                let t = t.clamp(0.0, 1.0);
                curve.eval(a + g.map_or(t, |g| g.eval(t)) * len)
            }
            Target::Analytic { f, g, .. } => f.eval(g.map_or(t, |g| g.eval(t))),
            Target::Points { .. } => unreachable!("point clouds are not evaluated"),
        }
    }

    fn quad_points(&self) -> usize {
        match self {
            Target::Spline { nq, .. } | Target::Analytic { nq, .. } => *nq,
            Target::Points { .. } => 0,
        }
    }

    /// The pieces of `[a, b]` between consecutive input breakpoints.
    fn pieces(&self, a: f64, b: f64, out: &mut Vec<(f64, f64)>) {
        out.clear();
        let tol = 1e-13;
        let mut left = a;
        if let Target::Spline { breaks, .. } | Target::Analytic { breaks, .. } = self {
            let start = breaks.partition_point(|&u| u <= a + tol);
            for &u in &breaks[start..] {
                if u >= b - tol {
                    break;
                }
                out.push((left, u));
                left = u;
            }
        }
        out.push((left, b));
    }
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn dist2(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// The knot vector `kv` with every kink parameter `t` of `kinks` at multiplicity `p`
/// (an existing break within `1e-12` of the length is taken as `t`).
pub(crate) fn with_kink_knots(kv: &KnotVector, kinks: &[f64]) -> KnotVector {
    let p = kv.degree();
    let mut new = Vec::new();
    for &t in kinks {
        let t = kv.breaks().into_iter().find(|&u| (u - t).abs() <= 1e-12 * kv.length()).unwrap_or(t);
        let m = kv.knots().iter().filter(|&&u| u == t).count();
        new.extend(std::iter::repeat_n(t, p.saturating_sub(m)));
    }
    if new.is_empty() {
        return kv.clone();
    }
    kv.with_inserted(&new)
}

/// The control points a fit on `kv` keeps fixed: the two corners and, at each kink `t`
/// (a knot of multiplicity `p`, where the one function `N_i` with `N_i(t) = 1` is the
/// only one not zero), the kink's point; sorted by index.
fn fixed_points(kv: &KnotVector, corners: (Point, Point), kinks: &[(f64, Point)]) -> Vec<(usize, Point)> {
    let n = kv.num_basis();
    let mut fixed = vec![(0, corners.0), (n - 1, corners.1)];
    for &(t, x) in kinks {
        let tol = 1e-12 * kv.length();
        let first = kv.knots().iter().position(|&u| u >= t - tol).expect("a kink lies inside the domain");
        let t0 = kv.knots()[first];
        if kv.knots().iter().filter(|&&u| u == t0).count() >= kv.degree() && first >= 1 && first - 1 < n - 1 {
            fixed.push((first - 1, x));
        }
    }
    fixed.sort_by_key(|f| f.0);
    fixed.dedup_by_key(|f| f.0);
    fixed
}

/// Assemble and solve the constrained least-squares problem on `kv`, with the control
/// points of `kinks` (parameter and point, see [`fixed_points`]) fixed besides the corners.
fn solve_fit(target: &Target, kv: &KnotVector, corners: (Point, Point), kinks: &[(f64, Point)]) -> Result<Curve> {
    let p = kv.degree();
    let n = kv.num_basis();
    let mut mat = Banded::new(n, p);
    let mut rhs = vec![[0.0; 2]; n];
    let mut basis = BasisDerivs::default();
    match target {
        Target::Points { params, points } => {
            for (&t, &pt) in params.iter().zip(points.iter()) {
                basis.eval(kv, t, 0);
                let f = basis.first();
                for j in 0..=p {
                    let nj = basis.d[0][j];
                    rhs[f + j][0] += nj * pt[0];
                    rhs[f + j][1] += nj * pt[1];
                    for k in j..=p {
                        mat.add(f + j, f + k, nj * basis.d[0][k]);
                    }
                }
            }
            // Smoothing term Σ_e h_e^3 ∫_e ||f''||^2 (exact with p Gauss points).
            let mut reg = Banded::new(n, p);
            let g = GaussLegendre::new(p);
            for (s, a, b) in kv.elements() {
                let h3 = (b - a).powi(3);
                for (t, w) in g.on(a, b) {
                    basis.eval_in_span(kv, s, t, 2);
                    let f = basis.first();
                    for j in 0..=p {
                        for k in j..=p {
                            reg.add(f + j, f + k, w * h3 * basis.d[2][j] * basis.d[2][k]);
                        }
                    }
                }
            }
            let data_tr: f64 = (1..n - 1).map(|i| mat.band[i][0]).sum();
            let reg_tr: f64 = (1..n - 1).map(|i| reg.band[i][0]).sum();
            let lambda = if data_tr > 0.0 && reg_tr > 0.0 { REGULARIZATION * data_tr / reg_tr } else { 1.0 };
            for (row, rrow) in mat.band.iter_mut().zip(&reg.band) {
                for (x, r) in row.iter_mut().zip(rrow) {
                    *x += lambda * r;
                }
            }
        }
        _ => {
            let g = GaussLegendre::new(target.quad_points());
            let mut pieces = Vec::new();
            for (s, a, b) in kv.elements() {
                target.pieces(a, b, &mut pieces);
                for &(pa, pb) in &pieces {
                    for (t, w) in g.on(pa, pb) {
                        basis.eval_in_span(kv, s, t, 0);
                        let y = target.eval(t);
                        let f = basis.first();
                        for j in 0..=p {
                            let nj = w * basis.d[0][j];
                            rhs[f + j][0] += nj * y[0];
                            rhs[f + j][1] += nj * y[1];
                            for k in j..=p {
                                mat.add(f + j, f + k, nj * basis.d[0][k]);
                            }
                        }
                    }
                }
            }
        }
    }
    // Eliminate the fixed unknowns (corners c_0, c_{n-1} and the kinks' points); the
    // free ones between two fixed ones form independent blocks (a kink's knot of
    // multiplicity p separates them).
    let fixed = fixed_points(kv, corners, kinks);
    let mut cps = vec![[0.0; 2]; n];
    for &(k, x) in &fixed {
        cps[k] = x;
    }
    for w in fixed.windows(2) {
        let (lo, hi) = (w[0].0 + 1, w[1].0);
        if lo >= hi {
            continue;
        }
        let mut free: Vec<Point> = (lo..hi)
            .map(|i| {
                let mut r = rhs[i];
                for &(k, x) in &fixed {
                    let a = if k.abs_diff(i) <= p { mat.get(i, k) } else { 0.0 };
                    r = [r[0] - a * x[0], r[1] - a * x[1]];
                }
                r
            })
            .collect();
        mat.solve_block(lo, hi, &mut free)?;
        cps[lo..hi].copy_from_slice(&free);
    }
    if let Some(i) = cps.iter().position(|c| !(c[0].is_finite() && c[1].is_finite())) {
        return Err(Error::NonFinite {
            context: "contour fit".into(),
            what: format!("control point {i} (the input curve gives non-finite values?)"),
        });
    }
    Ok(Curve::polynomial(kv.clone(), cps))
}

/// Per-element and global errors of the fit `fit` of `target`.
fn fit_errors(target: &Target, fit: &Curve) -> Projection {
    let kv = &fit.knots;
    let elements = kv.elements();
    let mut errs: Vec<ElementError> = elements
        .iter()
        .map(|&(span, a, b)| ElementError { span, a, b, indicator: 0.0, max: 0.0, lag_one: 0.0, points: 0 })
        .collect();
    let mut basis = BasisDerivs::default();
    let (max_error, rms_error) = match target {
        Target::Points { params, points } => {
            let mut sum = 0.0;
            let mut max = 0.0f64;
            let mut last: Option<(usize, Point)> = None;
            for (&t, &pt) in params.iter().zip(points.iter()) {
                basis.eval(kv, t, 0);
                let x = fit.derivs_with(&basis, 0).x;
                let r = [x[0] - pt[0], x[1] - pt[1]];
                let d2 = dist2(x, pt);
                let d = d2.sqrt();
                sum += d2;
                max = max.max(d);
                // element of the span; a point on a break also counts for the left element
                let e = elements.partition_point(|el| el.0 < basis.span).min(elements.len() - 1);
                if let Some((le, lr)) = last.filter(|l| l.0 == e) {
                    errs[le].lag_one += r[0] * lr[0] + r[1] * lr[1];
                }
                last = Some((e, r));
                errs[e].points += 1;
                errs[e].indicator += d2;
                errs[e].max = errs[e].max.max(d);
                if e > 0 && t <= elements[e].1 {
                    errs[e - 1].max = errs[e - 1].max.max(d);
                }
            }
            (max, (sum / params.len() as f64).sqrt())
        }
        _ => {
            let g = GaussLegendre::new(target.quad_points());
            let mut pieces = Vec::new();
            let mut total = 0.0;
            let mut max = 0.0f64;
            for (e, &(s, a, b)) in elements.iter().enumerate() {
                target.pieces(a, b, &mut pieces);
                let mut int = 0.0;
                let mut emax = 0.0f64;
                for &(pa, pb) in &pieces {
                    for (t, w) in g.on(pa, pb) {
                        basis.eval_in_span(kv, s, t, 0);
                        int += w * dist2(fit.derivs_with(&basis, 0).x, target.eval(t));
                    }
                    for k in 0..=SAMPLES_PER_PIECE {
                        let t = pa + (pb - pa) * k as f64 / SAMPLES_PER_PIECE as f64;
                        basis.eval_in_span(kv, s, t, 0);
                        emax = emax.max(dist(fit.derivs_with(&basis, 0).x, target.eval(t)));
                    }
                }
                errs[e].indicator = int / (b - a);
                errs[e].max = emax;
                total += int;
                max = max.max(emax);
            }
            (max, total.sqrt())
        }
    };
    Projection { curve: fit.clone(), max_error, rms_error, elements: errs }
}

/// Constrained least-squares fit of one side on the fixed knot vector `knots` (an open
/// vector on `[0, 1]` of degree `>= 2`), with the first and last control points set to
/// `corners`; see the module documentation for the functionals. Point clouds are
/// parameterized by cord length (eq. 36-37).
pub fn project_side(curve: &SideCurve, knots: &KnotVector, corners: (Point, Point)) -> Result<Projection> {
    if knots.degree() < 2 || !knots.is_open() || knots.domain() != (0.0, 1.0) || knots.is_periodic() {
        return Err(Error::Invalid(format!(
            "contour fit needs an open knot vector of degree >= 2 on [0, 1], got degree {} on {:?}",
            knots.degree(),
            knots.domain()
        )));
    }
    let target = Target::new(curve, &SideParam::Native, knots.degree(), "side")?;
    let fit = solve_fit(&target, knots, corners, &[])?;
    Ok(fit_errors(&target, &fit))
}

/// Adaptive constrained least-squares fit of one side (paper §5.1-5.3): fit on
/// `initial_elements` uniform elements, bisect every element whose RMS deviation
/// `sqrt(η_e)` (eq. 17, or the points' part of eq. 18) or maximal deviation exceeds
/// `tol_abs`, refit, and repeat until no element is marked or `max_levels` /
/// `max_elements` is reached (then `converged` is false and the finest fit is the best
/// one). When more elements are marked than `max_elements` allows, the worst ones are
/// bisected first. A point cloud also stops at its noise floor (see `NOISE_STALL`;
/// `converged` is then false and the last fit is the one before the bisection that did
/// not help).
pub fn fit_side(
    side: Side,
    curve: &SideCurve,
    corners: (Point, Point),
    opts: &FitOptions,
    tol_abs: f64,
) -> Result<SideFit> {
    fit_side_with(side, curve, &SideParam::Native, corners, opts, tol_abs)
}

/// [`fit_side`] with the side parameterized by `param` (paper §7): point clouds at the
/// given abscissae, parametric sides as `f̄ ∘ g`.
pub(crate) fn fit_side_with(
    side: Side,
    curve: &SideCurve,
    param: &SideParam,
    corners: (Point, Point),
    opts: &FitOptions,
    tol_abs: f64,
) -> Result<SideFit> {
    fit_side_kinked(side, curve, param, corners, opts, tol_abs, &[])
}

/// [`fit_side_with`] keeping the kinks `(t, x)` exactly (paper §9): every fit's knot
/// vector holds `t` with multiplicity `p` and the control point there is fixed to `x`
/// (the curve interpolates `x` at `t`, only `C^0` there); the pieces between kinks are
/// fitted independently, and refinement bisects elements as usual, so the kinks stay.
/// `t` is in the fit's parameter (for a point cloud the abscissa of its vertex).
pub(crate) fn fit_side_kinked(
    side: Side,
    curve: &SideCurve,
    param: &SideParam,
    corners: (Point, Point),
    opts: &FitOptions,
    tol_abs: f64,
    kinks: &[(f64, Point)],
) -> Result<SideFit> {
    opts.validate()?;
    if let Some(&(t, _)) = kinks.iter().find(|k| !(k.0 > 0.0 && k.0 < 1.0)) {
        return Err(Error::Invalid(format!("{side}: a kink's parameter must lie inside (0, 1), got {t}")));
    }
    if !(tol_abs.is_finite() && tol_abs > 0.0) {
        return Err(Error::Invalid(format!("absolute fit tolerance must be positive and finite, got {tol_abs}")));
    }
    let target = Target::new(curve, param, opts.degree, side.name())?;
    let ts: Vec<f64> = kinks.iter().map(|k| k.0).collect();
    let mut kv = with_kink_knots(&KnotVector::open_uniform(opts.degree, opts.initial_elements), &ts);
    let mut out = SideFit {
        side,
        levels: Vec::new(),
        max_error: Vec::new(),
        rms_error: Vec::new(),
        params: match &target {
            Target::Points { params, .. } => Some(params.clone()),
            _ => None,
        },
        converged: false,
    };
    let points = matches!(target, Target::Points { .. });
    // the bisected elements of the last level (parameter intervals) and their points'
    // summed squared deviation, for the noise floor of point clouds
    let mut bisected: Option<(Vec<(f64, f64)>, f64)> = None;
    loop {
        let fit = solve_fit(&target, &kv, corners, kinks).map_err(|e| e.within(side.name()))?;
        let proj = fit_errors(&target, &fit);
        // Noise floor: when bisecting did not lower the squared deviation of the points
        // in the bisected elements below NOISE_STALL of what it was, and what is left is
        // uncorrelated from point to point (lag-one autocorrelation below NOISE_LAG_ONE, on
        // elements with NOISE_MIN_POINTS points or more),
        // it is noise, not shape (an unresolved feature's residual is smooth, so
        // correlated); fitting it would only grow the basis. Keep the coarser fit.
        if let Some((intervals, before)) = bisected.take() {
            let (after, lag_one, points, elements) = proj
                .elements
                .iter()
                .filter(|e| intervals.iter().any(|&(a, b)| e.a >= a && e.b <= b))
                .fold((0.0, 0.0, 0, 0), |(s, l, p, n), e| (s + e.indicator, l + e.lag_one, p + e.points, n + 1));
            let enough = points >= NOISE_MIN_POINTS * elements;
            if enough && before > 0.0 && after > NOISE_STALL * before && lag_one < NOISE_LAG_ONE * after {
                break;
            }
        }
        out.levels.push(proj.curve);
        out.max_error.push(proj.max_error);
        out.rms_error.push(proj.rms_error);
        // Marked elements with their error measure.
        let mut marked: Vec<(usize, f64)> = proj
            .elements
            .iter()
            .filter_map(|e| {
                let measure = if points { e.max } else { e.max.max(e.indicator.sqrt()) };
                (measure > tol_abs).then_some((e.span, measure))
            })
            .collect();
        if marked.is_empty() {
            out.converged = true;
            break;
        }
        let num_elements = proj.elements.len();
        if out.levels.len() >= opts.max_levels || num_elements >= opts.max_elements {
            break;
        }
        let room = opts.max_elements - num_elements;
        if marked.len() > room {
            marked.sort_by(|a, b| b.1.total_cmp(&a.1));
            marked.truncate(room);
            marked.sort_by_key(|m| m.0);
        }
        let spans: Vec<usize> = marked.iter().map(|m| m.0).collect();
        if points {
            let chosen = proj.elements.iter().filter(|e| spans.contains(&e.span));
            let (intervals, sse): (Vec<(f64, f64)>, Vec<f64>) = chosen.map(|e| ((e.a, e.b), e.indicator)).unzip();
            bisected = Some((intervals, sse.iter().sum()));
        }
        kv = kv.with_inserted(&kv.midpoints_of(&spans));
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
