//! Certified bijectivity (paper §8.1): `det J` of a tensor-product map of degree
//! `(p, q)` is, on every element, a polynomial of degree `(2p - 1, 2q - 1)` (eq. 43).
//! We compute it in Bernstein form: Bézier extraction gives the element's control net,
//! the derivatives `x_xi`, `x_eta` are differences of that net, and products of
//! Bernstein polynomials are Bernstein polynomials,
//! `B_i^m B_j^n = binom(m, i) binom(n, j) / binom(m + n, i + j) B_{i+j}^{m+n}`.
//! By the convex-hull property the smallest coefficient is a lower bound of `det J`
//! on the element and the corner coefficients are exact values. Elements that are
//! neither proven positive nor shown to fold are subdivided (de Casteljau), which
//! makes the coefficients converge to the values quadratically.
//!
//! For a rational map `x = X / W` (homogeneous `X = sum w c N`, `W = sum w N`),
//! `det J = N / W^3` with
//! `N = W (X_xi Y_eta - X_eta Y_xi) + X (Y_xi W_eta - Y_eta W_xi) + Y (X_eta W_xi - X_xi W_eta)`,
//! a polynomial of degree `(3p - 1, 3q - 1)`; since `W > 0` the numerator is certified.
//!
//! **Rounding.** The verdict holds for the exact map given by the `f64` data, not for
//! its floating-point image: every coefficient `ĉ_k` comes with a bound `e` of its
//! rounding error, `|ĉ_k - c_k| <= e`, by running error analysis with the constants
//! `γ_n = n u / (1 - n u)`, `u = 2^-53` (module `bernstein`): the net is taken relative to
//! the element's first control point (so the rounding scales with the element, not
//! with `|x|`) and scaled to unit size by a power of two (module `element`); de Casteljau
//! bisection adds `γ_{du+dv} max|ĉ|` per level. A box is proven when
//! `min_k ĉ_k - e > 0`; a fold is reported only at a point where the value is
//! `< -(its bound)`, re-evaluated at the reported parameter point (module `search`); what is
//! neither is bisected, and left `undecided` when the budget is spent.
//!
//! **Corners.** A corner whose `det J` coefficient (exact up to `e`) is not provably
//! positive (an angle of 180 degrees or more, or a vanishing tangent) forces
//! `det J <= 0` there for every map: positivity is proven on everything except a
//! neighbourhood of that corner found by bisection, whose parameter extent is reported
//! ([`CornerInfo::excused_extent`]); the verdict is then
//! [`Finding::DegenerateCorner`]. Nothing is excused at any other corner. A point of a
//! side where the side's own tangent vanishes within rounding (a zero-speed knot, e.g.
//! repeated control points, where `det J = x_ξ × x_η = 0` for every map of the boundary)
//! is excused the same way when it is a corner of elements ([`ExcusedPoint`]); there no
//! negative value is forced, so a fold next to it is a fold.
//!
//! **Volumes.** Trivariate maps have their own entry and report,
//! [`volume::certify_volume`], on the same machinery: the modules `bernstein` (tensor
//! Bernstein polynomials and their rounding bounds), `element` (extraction, local net,
//! `det J` per element) and `search` (proof, fold witnesses, corner neighbourhoods) are
//! generic over the number of parameters `D` (2 or 3), and so are the per-element
//! reports [`Fold`] and [`Undecided`].

mod bernstein;
pub(crate) mod coefficients;
mod element;
pub mod hierarchical;
mod search;
pub mod volume;

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::error::Result;
use crate::spline::surface::{Side, Surface};
use element::Elements;

/// Options of [`certify`].
#[derive(Debug, Clone, Copy)]
pub struct CertifyOptions {
    /// Most bisections (in both directions) of an element; also the depth of the
    /// neighbourhood of a forced corner, whose extent is then `2^-max_depth` of the
    /// element's.
    pub max_depth: usize,
    /// Most sub-boxes examined per element.
    pub max_boxes: usize,
    /// Excuse a neighbourhood of each corner where `det J > 0` is not provable (angle of
    /// 180 degrees or more, vanishing tangent), shrunk by bisection; `false`: every
    /// corner must be proven positive.
    pub excuse_corners: bool,
}

impl Default for CertifyOptions {
    fn default() -> Self {
        Self { max_depth: 16, max_boxes: 4096, excuse_corners: true }
    }
}

/// What [`certify`] found, with its evidence: a proven lower bound of `det J`, a point
/// where it is proven negative, or the elements left undecided; `D` parameters (2: a map
/// of the plane; 3: a volume, [`volume::VolumeFinding`], which has no excused corner). The
/// one verdict of a solve, which adds "not converged", is [`crate::Verdict`]
/// ([`Verdict::of_certificate`](crate::Verdict::of_certificate)).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
#[serde(bound(serialize = "[usize; D]: Serialize, [f64; D]: Serialize"))]
pub enum Finding<const D: usize = 2> {
    /// `det J > 0` on the whole parameter domain, proven.
    Certified {
        /// Proven lower bound of `det J`.
        lower_bound: f64,
        /// `lower_bound / mean det J`.
        relative: f64,
    },
    /// `det J > 0` proven everywhere except near corners whose angle forbids it, and near
    /// points of a side where the side's speed vanishes (a kink kept with its input
    /// parameterization, [`ExcusedPoint`]).
    DegenerateCorner {
        /// The corners ("south-west", ...).
        corners: Vec<&'static str>,
        /// The zero-speed points of the sides, in the parameter domain (`(xi, eta)`).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        points: Vec<[f64; D]>,
        /// Proven lower bound of `det J` away from those corners.
        lower_bound: f64,
        /// `lower_bound / mean det J`.
        relative: f64,
    },
    /// A point with `det J < 0` proven (value below minus its rounding bound) away from
    /// forced corners (the most negative found).
    Folded {
        /// Parameter point `(xi, eta)` (`(xi, eta, zeta)`).
        param: [f64; D],
        /// Physical point `x(xi, eta)`.
        point: [f64; D],
        /// `det J` there (on a `C^0` knot line or plane: the one-sided value of the folding side).
        value: f64,
        /// Rounding bound of `value`.
        error_bound: f64,
        /// On a knot line where the map is only `C^0`: which one-sided limit `value` is.
        one_sided: Option<String>,
    },
    /// The subdivision budget was spent before every element was decided.
    Undecided {
        /// Elements `(i, j)` (`(i, j, k)`: indices of the element per direction) left open.
        elements: Vec<[usize; D]>,
    },
}

impl<const D: usize> Finding<D> {
    /// Short name (`certified`, `degenerate-corner`, `folded`, `undecided`).
    pub fn name(&self) -> &'static str {
        match self {
            Finding::Certified { .. } => "certified",
            Finding::DegenerateCorner { .. } => "degenerate-corner",
            Finding::Folded { .. } => "folded",
            Finding::Undecided { .. } => "undecided",
        }
    }
}

/// One corner of the map.
#[derive(Debug, Clone, Serialize)]
pub struct CornerInfo {
    /// "south-west", "south-east", "north-east", "north-west".
    pub corner: &'static str,
    /// Interior angle of the map's boundary in degrees.
    pub angle_degrees: f64,
    /// `det J` at the corner (cross product of the two side tangents).
    pub det_j: f64,
    /// Whether `det J > 0` at the corner is not provable (its Bernstein coefficient, exact
    /// up to its rounding bound, is not positive: an angle of 180 degrees or more, or a
    /// vanishing tangent).
    pub forbids_positivity: bool,
    /// Parameter extent `(xi, eta)` of the neighbourhood of this corner excused from the
    /// proof (found by bisection; `None`: nothing excused here).
    pub excused_extent: Option<[f64; 2]>,
}

/// A point of a side (not a corner of the domain) where the side's own tangent vanishes,
/// so `det J = x_ξ × x_η = 0` there for every map with that boundary (a zero-speed kink
/// kept exactly, e.g. repeated control points): excused like a forced corner, by a
/// neighbourhood shrunk by bisection.
#[derive(Debug, Clone, Serialize)]
pub struct ExcusedPoint {
    /// Side ("south", ...).
    pub side: &'static str,
    /// Parameter point `(xi, eta)`.
    pub param: [f64; 2],
    /// Physical point.
    pub point: [f64; 2],
    /// Parameter extent `(xi, eta)` of the excused neighbourhood (the largest over the
    /// elements meeting there).
    pub extent: [f64; 2],
}

/// An element where `det J < 0` was proven at a point (`D = 2`: of a map of the plane,
/// `FoldInfo`; `D = 3`: of a volume, `volume::VolumeFold`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(bound(serialize = "[usize; D]: Serialize, [f64; D]: Serialize"))]
pub struct Fold<const D: usize> {
    /// Element (`(i, j)`, `(i, j, k)`: its indices per direction).
    pub element: [usize; D],
    /// Parameter point.
    pub param: [f64; D],
    /// `det J` there, evaluated on this element (one-sided on a `C^0` knot line or plane).
    pub value: f64,
    /// Rounding bound of `value` (`value < -error_bound`).
    pub error_bound: f64,
    /// On a knot line (plane) where the map is only `C^0`: which one-sided limit `value` is.
    pub one_sided: Option<String>,
}

/// A fold of a map of the plane.
pub(crate) type FoldInfo = Fold<2>;

/// An element neither proven positive nor shown to fold (`D = 2`: of a map of the plane,
/// `UndecidedInfo`; `D = 3`: of a volume, `volume::VolumeUndecided`).
#[derive(Debug, Clone, Serialize)]
#[serde(bound(serialize = "[usize; D]: Serialize"))]
pub struct Undecided<const D: usize> {
    /// Element (its indices per direction).
    pub element: [usize; D],
    /// Why the search stopped: `max-depth` or `box-budget`.
    pub reason: &'static str,
    /// Deepest bisection level reached on the element.
    pub depth: usize,
    /// Boxes examined on the element.
    pub boxes: usize,
    /// Smallest `det J` coefficient of the first box left open (scaled like `det J`).
    pub smallest_coefficient: f64,
    /// Its rounding bound: when `|smallest_coefficient| <= error_bound`, `det J` is zero
    /// within rounding there.
    pub error_bound: f64,
}

/// An undecided element of a map of the plane.
pub(crate) type UndecidedInfo = Undecided<2>;

/// The bijectivity certificate of a map.
#[derive(Debug, Clone, Serialize)]
pub struct Certificate {
    /// The verdict.
    pub verdict: Finding,
    /// Proven lower bound of `det J` over the proven elements (excused ones excluded).
    pub lower_bound: f64,
    /// Mean of `det J` over the parameter domain (area / parameter area; exact for
    /// polynomial maps).
    pub mean_det_j: f64,
    /// Smallest exact value of `det J` met (corners of sub-boxes and test points).
    pub min_value_found: f64,
    /// Degrees of the `det J` polynomial (of its numerator for rational maps).
    pub det_degree: [usize; 2],
    /// The four corners.
    pub corners: Vec<CornerInfo>,
    /// Elements examined.
    pub elements: usize,
    /// Elements per direction.
    pub element_shape: [usize; 2],
    /// Sub-boxes examined in total (elements included).
    pub boxes: usize,
    /// Deepest bisection level used.
    pub max_depth: usize,
    /// Elements near forced corners that could not be proven positive.
    pub excused: Vec<[usize; 2]>,
    /// Zero-speed points of the sides excused like forced corners.
    pub excused_points: Vec<ExcusedPoint>,
    /// Elements where a non-positive value was found (away from forced corners).
    pub folds: Vec<FoldInfo>,
    /// Elements left undecided.
    pub undecided: Vec<[usize; 2]>,
    /// Why each undecided element is open.
    pub undecided_info: Vec<UndecidedInfo>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

impl Certificate {
    /// The elements a defect correction should refine: folded and undecided ones.
    pub fn offending_elements(&self) -> Vec<[usize; 2]> {
        offending(&self.folds, self.undecided.iter().copied())
    }

    /// A sentence describing the verdict.
    pub fn message(&self) -> String {
        match &self.verdict {
            Finding::Certified { lower_bound, relative } => {
                certified_message(*lower_bound, *relative, self.elements, self.boxes)
            }
            Finding::DegenerateCorner { corners, lower_bound, relative, .. } => {
                let why: Vec<String> = self
                    .corners
                    .iter()
                    .filter(|c| corners.contains(&c.corner))
                    .map(|c| {
                        let ext = c
                            .excused_extent
                            .map(|e| format!("; excused neighbourhood {:.3e} x {:.3e} in (xi, eta)", e[0], e[1]))
                            .unwrap_or_default();
                        format!("{} (angle {:.8} degrees, det J there {:.3e}{ext})", c.corner, c.angle_degrees, c.det_j)
                    })
                    .collect();
                let points: Vec<String> = self
                    .excused_points
                    .iter()
                    .map(|p| {
                        format!(
                            "the {} side's point ({:.6}, {:.6}) where its speed vanishes (det J = 0 there for every map of \
                             this boundary; excused neighbourhood {:.3e} x {:.3e} in (xi, eta))",
                            p.side, p.point[0], p.point[1], p.extent[0], p.extent[1]
                        )
                    })
                    .collect();
                let mut what = Vec::new();
                if !why.is_empty() {
                    what.push(format!("the {} corner", why.join(" and ")));
                }
                what.extend(points);
                let elsewhere = if lower_bound.is_finite() {
                    format!("det J >= {lower_bound:.4e} ({relative:.3e} of its mean) is proven everywhere else")
                } else {
                    "det J > 0 is proven everywhere else".to_string()
                };
                format!(
                    "degenerate corner: the boundary forces det J <= 0 at {}; {elsewhere}: the best map this boundary \
                     admits",
                    what.join(" and ")
                )
            }
            Finding::Folded { param, point, value, error_bound, one_sided } => {
                folded_message(param, point, *value, *error_bound, one_sided, self.folds.len())
            }
            Finding::Undecided { elements } => {
                undecided_message(elements.len(), &self.undecided_info, self.max_depth, self.min_value_found)
            }
        }
    }
}

/// The elements of `folds` and `undecided`, sorted, each once.
fn offending<const D: usize>(folds: &[Fold<D>], undecided: impl Iterator<Item = [usize; D]>) -> Vec<[usize; D]> {
    let mut v: Vec<[usize; D]> = folds.iter().map(|f| f.element).chain(undecided).collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// The sentence of a certified verdict.
fn certified_message(lower_bound: f64, relative: f64, elements: usize, boxes: usize) -> String {
    format!(
        "certified bijective: det J >= {lower_bound:.4e} ({relative:.3e} of its mean) proven on all {elements} elements \
         ({boxes} Bernstein boxes, rounding bounded)"
    )
}

/// The sentence of a folded verdict: `det J = value` at the parameter point `param`
/// (`(xi, eta)` or `(xi, eta, zeta)`), the physical point `point`.
fn folded_message<const D: usize>(
    param: &[f64; D],
    point: &[f64; D],
    value: f64,
    error_bound: f64,
    one_sided: &Option<String>,
    folds: usize,
) -> String {
    let names = ["xi", "eta", "zeta"][..D].join(", ");
    let list = |v: &[f64; D]| v.iter().map(|x| format!("{x:.6}")).collect::<Vec<_>>().join(", ");
    format!(
        "FOLDED: det J = {value:.4e} < 0 (rounding bound {error_bound:.1e}) at ({names}) = ({}), x = ({}){}; {folds} \
         element(s) fold",
        list(param),
        list(point),
        one_sided.as_ref().map(|s| format!(", {s}")).unwrap_or_default(),
    )
}

/// The sentence of an undecided verdict: `open` elements left open, why each.
fn undecided_message<const D: usize>(
    open: usize,
    undecided: &[Undecided<D>],
    max_depth: usize,
    min_value_found: f64,
) -> String {
    let rounding = undecided.iter().filter(|u| u.smallest_coefficient.abs() <= u.error_bound).count();
    let budget = undecided.iter().filter(|u| u.reason == "box-budget").count();
    format!(
        "undecided: {open} element(s) neither proven positive nor shown to fold within {max_depth} bisections \
         ({rounding} with det J zero within its rounding bound, {budget} stopped by the box budget; smallest value \
         found {min_value_found:.4e})"
    )
}

/// Record the excused neighbourhood of extent `ext` around local corner `k` of element
/// `e` (a zero-speed point of a side), merged with the record of a neighbouring element.
fn excuse_point(
    out: &mut Vec<ExcusedPoint>,
    map: &Surface,
    dj: &Elements<'_, 2>,
    e: [usize; 2],
    k: usize,
    ext: [f64; 2],
) {
    let [bu, bv] = dj.bounds(e);
    let local = [(0, 0), (1, 0), (1, 1), (0, 1)][k];
    let param = [bu[local.0], bv[local.1]];
    if let Some(p) = out.iter_mut().find(|p| p.param == param) {
        p.extent = [p.extent[0].max(ext[0]), p.extent[1].max(ext[1])];
        return;
    }
    let shape = dj.shape();
    let side = if local.1 == 0 && e[1] == 0 {
        Side::South
    } else if local.1 == 1 && e[1] + 1 == shape[1] {
        Side::North
    } else if local.0 == 0 && e[0] == 0 {
        Side::West
    } else {
        Side::East
    };
    out.push(ExcusedPoint { side: side.name(), param, point: map.eval(param[0], param[1]), extent: ext });
}

/// Angles and `det J` (cross product of the side tangents) at the four corners, in the
/// order south-west, south-east, north-east, north-west; `forbids_positivity` and
/// `excused_extent` are filled in by [`certify`].
pub(crate) fn corner_info(map: &Surface) -> Vec<CornerInfo> {
    let sides = Side::ALL.map(|s| map.boundary(s));
    let d = |s: Side, end: bool| {
        let c = &sides[s as usize];
        let (a, b) = c.domain();
        c.derivs(if end { b } else { a }, 1).d1
    };
    crate::boundary::corners::corner_geometry(d)
        .into_iter()
        .map(|c| CornerInfo {
            corner: c.name,
            angle_degrees: c.angle_degrees,
            det_j: c.cross,
            forbids_positivity: c.speed == 0.0 || c.cross <= 0.0,
            excused_extent: None,
        })
        .collect()
}

/// Certify `det J > 0` on the whole map, element by element in parallel. A map whose
/// knot vectors hold an interior knot of multiplicity above the degree is a typed
/// error ([`crate::error::Error::KnotMultiplicity`]).
pub fn certify(map: &Surface, opts: &CertifyOptions) -> Result<Certificate> {
    let t0 = Instant::now();
    let dj = Elements::surface(map)?;
    let shape = dj.shape();
    let mut corners = corner_info(map);
    let all = search::all_elements(shape);
    let results: Vec<search::SurfaceElement> = all
        .par_iter()
        .map_init(|| vec![0.0; dj.deg.len()], |tmp, &e| search::examine_surface(&dj, e, opts, tmp))
        .collect();
    let mut totals = search::Totals::new();
    let (mut excused, mut excused_points) = (Vec::new(), Vec::new());
    for (e, search::SurfaceElement { result: r, forced, integral }) in all.iter().zip(results) {
        for k in 0..4 {
            if forced & (1 << k) != 0 {
                corners[k].forbids_positivity = true;
            }
            if let Some(x) = r.excused[k] {
                corners[k].excused_extent = Some(x);
            }
            if let Some(x) = r.excused[4 + k] {
                excuse_point(&mut excused_points, map, &dj, *e, k, x);
            }
        }
        if r.excused.iter().any(Option::is_some) {
            excused.push(*e);
        }
        totals.add(r, integral);
    }
    let (ua, ub) = map.knots[0].domain();
    let (va, vb) = map.knots[1].domain();
    let par_area = (ub - ua) * (vb - va);
    let mean_det_j =
        if map.weights.is_some() { crate::verify::quality::area(map) / par_area } else { totals.integral / par_area };
    let relative = totals.lower_bound / mean_det_j;
    let degenerate: Vec<&'static str> =
        corners.iter().filter(|c| c.excused_extent.is_some()).map(|c| c.corner).collect();
    let points: Vec<[f64; 2]> = excused_points.iter().map(|p: &ExcusedPoint| p.param).collect();
    let verdict = match totals.finding(|u| map.eval(u[0], u[1]), relative) {
        Finding::Certified { lower_bound, relative } if !degenerate.is_empty() || !points.is_empty() => {
            Finding::DegenerateCorner { corners: degenerate, points, lower_bound, relative }
        }
        found => found,
    };
    Ok(Certificate {
        verdict,
        lower_bound: totals.lower_bound,
        mean_det_j,
        min_value_found: totals.min_value_found,
        det_degree: dj.deg.0,
        corners,
        elements: all.len(),
        element_shape: shape,
        boxes: totals.boxes,
        max_depth: totals.max_depth,
        excused,
        excused_points,
        folds: totals.folds,
        undecided: totals.undecided.iter().map(|u| u.element).collect(),
        undecided_info: totals.undecided,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
/// The global minimum of `det J` by branch and bound on the Bernstein form, in floating
/// point (no rounding bound: a diagnostic, not a proof): returns `(lower, upper)` with
/// `lower <= min det J <= upper` up to rounding, `upper - lower <= tol` unless
/// `max_boxes` is reached; `upper` is a value at a sub-box corner. Polynomial maps only
/// (for rational maps the numerator is minimised, scaled per element).
pub(crate) fn det_j_min_bounds(map: &Surface, tol: f64, max_boxes: usize) -> Result<(f64, f64)> {
    let dj = Elements::surface(map)?;
    let shape = dj.shape();
    let d = dj.deg;
    let n = d.len();
    let [du, dv] = d.0;
    let mut tmp = vec![0.0; n];
    let mut upper = f64::INFINITY;
    let mut heap: Vec<(f64, Vec<f64>, usize)> = Vec::new();
    for j in 0..shape[1] {
        for i in 0..shape[0] {
            let mut c = vec![0.0; n];
            let (sc, _) = dj.coefficients([i, j], &mut c);
            for x in c.iter_mut() {
                *x *= sc.factor;
            }
            let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
            heap.push((lo, c, 0));
        }
    }
    let mut boxes = 0;
    loop {
        // box with the smallest lower bound
        let Some(k) = (0..heap.len()).min_by(|&a, &b| heap[a].0.total_cmp(&heap[b].0)) else {
            return Ok((upper, upper));
        };
        let (lo, c, depth) = heap.swap_remove(k);
        for v in [c[0], c[du], c[dv * (du + 1)], c[n - 1]] {
            upper = upper.min(v);
        }
        if upper - lo <= tol || boxes >= max_boxes || depth > 40 {
            let global_lo = heap.iter().map(|h| h.0).fold(lo, f64::min);
            return Ok((global_lo.min(upper), upper));
        }
        boxes += 1;
        let (mut l, mut r) = (vec![0.0; n], vec![0.0; n]);
        bernstein::split(&c, d, 0, &mut l, &mut r, &mut tmp);
        for half in [l, r] {
            let (mut lo2, mut hi2) = (vec![0.0; n], vec![0.0; n]);
            bernstein::split(&half, d, 1, &mut lo2, &mut hi2, &mut tmp);
            for ch in [lo2, hi2] {
                let m = ch.iter().copied().fold(f64::INFINITY, f64::min);
                if m < upper {
                    heap.push((m, ch, depth + 1));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod judge;
#[cfg(test)]
mod rounding_tests;
