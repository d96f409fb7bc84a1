//! Boundary reparameterization (paper §7): the parametric speed of the four contours is
//! a Dirichlet condition of eq. (8), so it decides whether hard geometries (narrow gaps,
//! extreme aspect ratios) come out bijective at all.
//!
//! * **Arc length** (§7.1). Point clouds get the cord-length abscissae of eq. 36-37
//!   ([`crate::boundary::cord_length::cord_length_params`]). A parametric side `f̄: [0,1] -> R^2` gets a
//!   monotone reparameterization `g(ξ) = Σ_i c_i B_i(ξ)` (eq. 38) on a cubic B-spline
//!   basis with `c_0 = 0`, `c_n = 1`, minimizing (eq. 39)
//!   `A(c) = ∫_0^1 ||(f̄ ∘ g)'(ξ)||^2 dξ`; by Cauchy-Schwarz `A >= L^2` (`L` the length of
//!   the side) with equality exactly for the arc-length parameterization. See
//!   `arc_length_map`. The contour is then re-fitted in the solver's basis as
//!   `f̄ ∘ g` ([`crate::boundary::fit`]).
//! * **Constrained cord length** (§7.2, eq. 40-42). For two opposite sides `P_1` (cord
//!   length, `Ξ_1`) and `P_2`, the closest pair `(p^1_i, p^2_j)` within the threshold
//!   distance `ε` is matched (eq. 40) and gets `ξ^2_j = ξ^1_i`; the search recurses on the
//!   index ranges below and above the match, after removing the points within a minimum
//!   cord-length separation `δ` of it. The unmatched abscissae of `P_2` are filled either
//!   by a Fritsch-Carlson monotone cubic through the matched values or by piecewise cord
//!   length between consecutive matches (eq. 41-42). See `constrained_params`.
//!
//! Rings (closed contours, `eta` periodic) use the same matching on the two contours
//! cut open at the seam: `boundary::ring_reparam`.
//!
//! Parametric sides are turned into point clouds by dense sampling
//! ([`sample_side`]); the resulting abscissae `ξ_k` of the samples `t_k` define
//! `g` as the monotone cubic through `(ξ_k, t_k)`.

mod arc_length;
mod matching;
mod monotone_cubic;

pub(crate) use arc_length::*;
pub(crate) use matching::*;
pub use monotone_cubic::MonotoneCubic;

use serde::Serialize;

use crate::boundary::cord_length::cord_length_params;
use crate::boundary::{Boundary, SideCurve};
use crate::error::{Error, Result};
use crate::spline::curve::Point;
use crate::spline::knots::KnotVector;
use crate::spline::quadrature::GaussLegendre;
use crate::spline::surface::Side;

/// Which reparameterization the contour fit applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Reparam {
    /// The input's own parameterization (cord length for point clouds).
    None,
    /// Arc length: cord length for point clouds, eq. 38-39 for parametric sides.
    #[cfg_attr(feature = "clap", value(name = "arclength"))]
    ArcLength,
    /// Constrained cord length on both pairs of opposite sides (eq. 40-42).
    Constrained,
    /// Constrained cord length on every pair of opposite sides that come closer than
    /// [`ReparamOptions::gap`] times their mean length; `None` elsewhere.
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Constrained cord length on opposite sides closer than --reparam-gap times their mean length, none elsewhere"
        )
    )]
    Auto,
}

impl Reparam {
    /// Lower-case name, as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Reparam::None => "none",
            Reparam::ArcLength => "arclength",
            Reparam::Constrained => "constrained",
            Reparam::Auto => "auto",
        }
    }
}

/// How the unmatched abscissae of the second side are filled (§7.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Fill {
    /// Cord length between consecutive matches (eq. 41-42).
    #[default]
    CordLength,
    /// Fritsch-Carlson monotone cubic through the matched `(cord length of P_2, ξ)`.
    MonotoneCubic,
}

/// Options of the reparameterization.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ReparamOptions {
    /// The method. Default [`Reparam::Auto`].
    pub method: Reparam,
    /// Threshold distance `ε` of eq. 40 relative to the mean length of the two opposite
    /// sides; `Auto` uses constrained cord length on a pair whose distance is below it.
    /// Default `0.02`.
    pub gap: f64,
    /// Minimum separation of two matches, in the cord-length parameter of each side.
    /// Default `0.01`.
    pub separation: f64,
    /// Fill of the unmatched abscissae. Default [`Fill::CordLength`].
    pub fill: Fill,
    /// Samples per input element (spline sides) used to turn a parametric side into a
    /// point cloud; analytic sides get `64` times as many in total. Default 16.
    pub samples: usize,
}

impl Default for ReparamOptions {
    fn default() -> Self {
        Self { method: Reparam::Auto, gap: 0.02, separation: 0.01, fill: Fill::CordLength, samples: 16 }
    }
}

impl ReparamOptions {
    /// Check the ranges.
    pub fn validate(&self) -> Result<()> {
        if !(self.gap.is_finite() && self.gap > 0.0) {
            return Err(Error::Invalid(format!("reparameterization gap must be positive, got {}", self.gap)));
        }
        if !(self.separation.is_finite() && self.separation >= 0.0 && self.separation < 0.5) {
            return Err(Error::Invalid(format!(
                "reparameterization separation must be in [0, 0.5), got {}",
                self.separation
            )));
        }
        if self.samples < 2 {
            return Err(Error::Invalid(format!(
                "reparameterization needs >= 2 samples per element, got {}",
                self.samples
            )));
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------
// Reparameterization functions of parametric sides
// ---------------------------------------------------------------------------------------

/// A strictly increasing map `g: [0, 1] -> [0, 1]` from the new parameter `ξ` to the
/// input's (normalized) parameter `t`; the side is re-fitted as `f̄ ∘ g`.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamMap {
    /// Monotone cubic through `(ξ_k, t_k)` (constrained cord length of a sampled side).
    Monotone(MonotoneCubic),
    /// `g = Σ c_i B_i` with increasing `c`, `c_0 = 0`, `c_n = 1` (eq. 38).
    Spline {
        /// The basis of `g`.
        knots: KnotVector,
        /// The coefficients `c_i`.
        coefs: Vec<f64>,
    },
}

impl ParamMap {
    /// `g(ξ)`.
    pub fn eval(&self, xi: f64) -> f64 {
        self.eval_d(xi).0
    }

    /// `g(ξ)` and `g'(ξ)`.
    pub(crate) fn eval_d(&self, xi: f64) -> (f64, f64) {
        match self {
            ParamMap::Monotone(m) => m.eval_d(xi),
            ParamMap::Spline { knots, coefs } => {
                let b = crate::spline::basis::BasisDerivs::at(knots, xi.clamp(0.0, 1.0), 1);
                let f = b.first();
                let (mut v, mut d) = (0.0, 0.0);
                for j in 0..=knots.degree() {
                    v += b.d[0][j] * coefs[f + j];
                    d += b.d[1][j] * coefs[f + j];
                }
                (v, d)
            }
        }
    }

    /// The breaks of `g` (where it is only finitely smooth), `0` and `1` included.
    pub fn breaks(&self) -> Vec<f64> {
        match self {
            ParamMap::Monotone(m) => m.nodes().to_vec(),
            ParamMap::Spline { knots, .. } => knots.breaks(),
        }
    }

    /// `g^{-1}(t)` by bisection.
    pub fn inverse(&self, t: f64) -> f64 {
        if let ParamMap::Monotone(m) = self {
            return m.inverse(t);
        }
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.eval(mid) < t {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}

/// Dense samples of a side: its points and, for parametric sides, their parameters
/// `t_k ∈ [0, 1]` (strictly increasing, every input break included).
#[derive(Debug, Clone)]
pub struct SideSample {
    /// Parameters of the samples (`None` for point clouds).
    pub t: Option<Vec<f64>>,
    /// The points.
    pub points: Vec<Point>,
}

/// Sample a side: point clouds as they are, spline sides at `per_element` points per
/// input element (breaks included), analytic sides at `64 per_element` uniform points.
pub fn sample_side(side: &SideCurve, per_element: usize) -> SideSample {
    let Some(f) = Parametric::new(side) else {
        let SideCurve::Points(p) = side else { unreachable!() };
        return SideSample { t: None, points: p.clone() };
    };
    let per = per_element.max(2);
    let mut t = vec![0.0];
    let pieces: Vec<(f64, f64)> = if matches!(side, SideCurve::Analytic(_)) {
        let n = 64 * per;
        (0..n).map(|k| (k as f64 / n as f64, (k + 1) as f64 / n as f64)).collect()
    } else {
        f.breaks.windows(2).filter(|w| w[1] > w[0]).map(|w| (w[0], w[1])).collect()
    };
    let sub = if matches!(side, SideCurve::Analytic(_)) { 1 } else { per };
    for (a, b) in pieces {
        for k in 1..=sub {
            t.push(if k == sub { b } else { a + (b - a) * k as f64 / sub as f64 });
        }
    }
    let points = t.iter().map(|&u| f.eval(u)).collect();
    SideSample { t: Some(t), points }
}

/// Monotone map `g` with `g(ξ_k) = t_k` from abscissae `ξ_k` of samples at parameters
/// `t_k` (both non-decreasing, from 0 to 1); samples whose `ξ` or `t` repeats the previous
/// one are dropped (a stationary stretch of the curve).
pub(crate) fn interpolating_map(xi: &[f64], t: &[f64]) -> Result<ParamMap> {
    let (mut x, mut y) = (Vec::with_capacity(xi.len()), Vec::with_capacity(xi.len()));
    for (&a, &b) in xi.iter().zip(t) {
        if let (Some(&pa), Some(&pb)) = (x.last(), y.last()) {
            if a <= pa || b <= pb {
                continue;
            }
        }
        x.push(a);
        y.push(b);
    }
    // make sure the ends are exactly 0 and 1
    if let (Some(lx), Some(ly)) = (x.last_mut(), y.last_mut()) {
        *lx = 1.0;
        *ly = 1.0;
    }
    Ok(ParamMap::Monotone(MonotoneCubic::new(x, y)?))
}

// ---------------------------------------------------------------------------------------
// The plan for a boundary
// ---------------------------------------------------------------------------------------

/// How one side is parameterized for the fit.
#[derive(Debug, Clone, PartialEq)]
pub enum SideParam {
    /// The input's own parameterization (cord length for point clouds).
    Native,
    /// Abscissae of the points of a point-cloud side.
    Abscissae(Vec<f64>),
    /// A parametric side re-fitted as `f̄ ∘ g`.
    Map(ParamMap),
}

/// A matched pair of points on two opposite sides, at the same parameter.
#[derive(Debug, Clone, Serialize)]
pub struct Match {
    /// The two sides ("south", "north") or ("west", "east"); ("inner", "outer") on a ring.
    pub sides: [&'static str; 2],
    /// The common parameter (`xi` for south/north, `eta` for west/east).
    pub parameter: f64,
    /// The physical points on the two sides.
    pub points: [Point; 2],
}

/// What the reparameterization did, for the solve report.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ReparamReport {
    /// The requested method.
    pub requested: Reparam,
    /// The method applied: `constrained` when any pair was constrained, else the request
    /// (`none` for `auto` without narrow gaps).
    pub used: Reparam,
    /// Per pair (south/north, west/east): smallest distance between the two sides over
    /// their mean length (a ring: `[null, inner/outer distance over the diameter]`).
    pub gap_ratio: [f64; 2],
    /// Per pair: the method applied to it.
    pub pair_methods: [Reparam; 2],
    /// Threshold of `auto` and of the matching, relative to the mean length of a pair
    /// (a ring: to the outer contour's diameter).
    pub gap_threshold: f64,
    /// Fill of the unmatched abscissae.
    pub fill: Fill,
    /// For arc length on parametric sides: `A / L^2` per side (south, east, north, west;
    /// 1 is exact arc length); `null` where not applicable.
    pub arc_length_ratio: [Option<f64>; 4],
    /// The matched pairs.
    pub matches: Vec<Match>,
}

impl ReparamReport {
    /// The report of the input's own parameterization.
    pub fn native() -> Self {
        Self {
            requested: Reparam::None,
            used: Reparam::None,
            gap_ratio: [f64::NAN; 2],
            pair_methods: [Reparam::None; 2],
            gap_threshold: 0.0,
            fill: Fill::CordLength,
            arc_length_ratio: [None; 4],
            matches: Vec::new(),
        }
    }

    /// The matched pairs as segments (for pictures).
    pub fn segments(&self) -> Vec<(Point, Point)> {
        self.matches.iter().map(|m| (m.points[0], m.points[1])).collect()
    }
}

/// The matched point pairs stored in a map document's `"report"` (the JSON of
/// [`ReparamReport`] under `reparam.matches[].points`); malformed entries are skipped.
pub fn matches_in_report(report: &serde_json::Value) -> Vec<(Point, Point)> {
    let Some(matches) = report["reparam"]["matches"].as_array() else { return Vec::new() };
    matches
        .iter()
        .filter_map(|m| {
            let p: [[f64; 2]; 2] = serde_json::from_value(m["points"].clone()).ok()?;
            Some((p[0], p[1]))
        })
        .collect()
}

/// The parameterization of all four sides and its report.
#[derive(Debug, Clone)]
pub struct ReparamPlan {
    /// South, east, north, west.
    pub sides: [SideParam; 4],
    /// What was done.
    pub report: ReparamReport,
}

/// Decide and compute the reparameterization of `boundary` (sides south, east, north,
/// west): for each opposite pair (south/north in `xi`, west/east in `eta`) the sides are
/// sampled ([`sample_side`]), their smallest distance over their mean length is the
/// pair's gap ratio, and the pair is treated by `opts.method` (`auto`: constrained when
/// the gap ratio is below `opts.gap`, else native). Side 1 of a pair is south or west.
pub fn plan(boundary: &Boundary, opts: &ReparamOptions) -> Result<ReparamPlan> {
    opts.validate()?;
    let mut sides = [SideParam::Native, SideParam::Native, SideParam::Native, SideParam::Native];
    let mut report = ReparamReport {
        requested: opts.method,
        used: if opts.method == Reparam::Auto { Reparam::None } else { opts.method },
        gap_ratio: [f64::NAN; 2],
        pair_methods: [Reparam::None; 2],
        gap_threshold: opts.gap,
        fill: opts.fill,
        arc_length_ratio: [None; 4],
        matches: Vec::new(),
    };
    let pairs = [(Side::South, Side::North, Across::SouthNorth), (Side::West, Side::East, Across::WestEast)];
    for (k, (s1, s2, across)) in pairs.into_iter().enumerate() {
        let (a, b) = (boundary.side(s1), boundary.side(s2));
        let (sa, sb) = (sample_side(a, opts.samples), sample_side(b, opts.samples));
        let mean = 0.5 * (polyline_length(&sa.points) + polyline_length(&sb.points));
        let gap = min_distance(&sa.points, &sb.points, across);
        let ratio = if mean > 0.0 { gap / mean } else { f64::INFINITY };
        report.gap_ratio[k] = ratio;
        let method = match opts.method {
            Reparam::Auto if ratio < opts.gap => Reparam::Constrained,
            Reparam::Auto => Reparam::None,
            m => m,
        };
        report.pair_methods[k] = method;
        match method {
            Reparam::None | Reparam::Auto => {}
            Reparam::ArcLength => {
                for s in [s1, s2] {
                    let side = boundary.side(s);
                    let elements = match side {
                        SideCurve::Spline(c) => (2 * c.knots.num_elements()).clamp(8, 2048),
                        _ => 64,
                    };
                    if let Some((g, r)) = arc_length_map(side, elements, opts.samples)? {
                        sides[s as usize] = SideParam::Map(g);
                        report.arc_length_ratio[s as usize] = Some(r);
                    }
                }
            }
            Reparam::Constrained => {
                let eps = opts.gap * mean;
                let (x1, x2, pairs) =
                    constrained_params(&sa.points, &sb.points, eps, opts.separation, opts.fill, across)
                        .map_err(|e| e.within(&format!("{}/{} reparameterization", s1.name(), s2.name())))?;
                for (i, j) in pairs {
                    report.matches.push(Match {
                        sides: [s1.name(), s2.name()],
                        parameter: x1[i],
                        points: [sa.points[i], sb.points[j]],
                    });
                }
                for (s, smp, x) in [(s1, &sa, x1), (s2, &sb, x2)] {
                    sides[s as usize] = match &smp.t {
                        None => SideParam::Abscissae(x),
                        Some(t) => SideParam::Map(interpolating_map(&x, t)?),
                    };
                }
            }
        }
    }
    if opts.method == Reparam::Auto && report.pair_methods.contains(&Reparam::Constrained) {
        report.used = Reparam::Constrained;
    }
    Ok(ReparamPlan { sides, report })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::Analytic;
    use crate::spline::curve::Curve;

    fn strictly_monotone_onto(f: impl Fn(f64) -> f64, n: usize) {
        assert!(f(0.0).abs() < 1e-14 && (f(1.0) - 1.0).abs() < 1e-14, "ends {} {}", f(0.0), f(1.0));
        let mut prev = f(0.0);
        for k in 1..=n {
            let v = f(k as f64 / n as f64);
            assert!(v > prev, "not strictly increasing at {}: {prev} then {v}", k as f64 / n as f64);
            prev = v;
        }
    }

    #[test]
    fn monotone_cubic_is_monotone_and_interpolates() {
        // data with a flat part and steep jumps: a plain cubic spline would overshoot
        let x = vec![0.0, 0.1, 0.2, 0.5, 0.55, 0.9, 1.0];
        let y = vec![0.0, 0.0, 0.01, 0.02, 0.9, 0.95, 1.0];
        let m = MonotoneCubic::new(x.clone(), y.clone()).unwrap();
        for (a, b) in x.iter().zip(&y) {
            assert!((m.eval(*a) - b).abs() < 1e-15);
        }
        let mut prev = -1.0;
        for k in 0..=10000 {
            let v = m.eval(k as f64 / 10000.0);
            assert!(v >= prev - 1e-15 && (-1e-15..=1.0 + 1e-15).contains(&v));
            prev = v;
        }
        // flat where the data are flat
        assert_eq!(m.eval(0.05), 0.0);
        // strictly increasing data: strictly increasing interpolant, exact on lines
        let y2 = vec![0.0, 0.05, 0.3, 0.4, 0.8, 0.85, 1.0];
        let m2 = MonotoneCubic::new(x.clone(), y2).unwrap();
        strictly_monotone_onto(|t| m2.eval(t), 20000);
        let lin = MonotoneCubic::new(x.clone(), x.iter().map(|v| 2.0 * v + 1.0).collect()).unwrap();
        assert!((lin.eval(0.37) - 1.74).abs() < 1e-14 && (lin.eval_d(0.61).1 - 2.0).abs() < 1e-13);
        assert!((m2.inverse(m2.eval(0.333)) - 0.333).abs() < 1e-12);
        assert!(MonotoneCubic::new(vec![0.0, 0.0], vec![0.0, 1.0]).is_err());
        assert!(MonotoneCubic::new(vec![0.0, 1.0], vec![1.0, 0.0]).is_err());
    }

    #[test]
    fn arc_length_map_is_monotone_and_nearly_arc_length() {
        // a quarter circle traversed with uneven speed (1 : 5.7): angle (pi/2)(0.3t + 0.7t^2)
        let side = SideCurve::Analytic(Analytic::new(|t| {
            let a = std::f64::consts::FRAC_PI_2 * (0.3 * t + 0.7 * t * t);
            [a.cos(), a.sin()]
        }));
        let (g, ratio) = arc_length_map(&side, 16, 16).unwrap().unwrap();
        strictly_monotone_onto(|x| g.eval(x), 5000);
        // A / L^2 = 1 for exact arc length; the native parameterization has 9/5
        assert!((1.0 - 1e-9..1.0 + 1e-5).contains(&ratio), "A/L^2 = {ratio}");
        // speed of f(g(xi)) is close to the length pi/2 everywhere
        for k in 1..100 {
            let xi = k as f64 / 100.0;
            let (gv, gd) = g.eval_d(xi);
            let speed = std::f64::consts::FRAC_PI_2 * (0.3 + 1.4 * gv) * gd;
            assert!((speed / std::f64::consts::FRAC_PI_2 - 1.0).abs() < 0.02, "speed {speed} at {xi}");
        }
        // a spline side: same statement through the spline derivatives
        let kv = KnotVector::new(3, vec![0., 0., 0., 0., 0.1, 1., 1., 1., 1.]).unwrap();
        let c = Curve::new(kv, vec![[0., 0.], [0.01, 0.0], [0.02, 0.01], [1.0, 0.5], [2.0, 0.0]], None).unwrap();
        // (its speed varies by orders of magnitude near t = 0: A/L^2 ~ 1e-3 above 1)
        let side = SideCurve::Spline(c);
        let (g, ratio) = arc_length_map(&side, 16, 16).unwrap().unwrap();
        let (_, start) = arc_length_iterations(&side, 16, 16, 0).unwrap().unwrap();
        strictly_monotone_onto(|x| g.eval(x), 5000);
        assert!(ratio >= 1.0 - 1e-9 && ratio <= start && ratio < 1.01, "A/L^2 = {ratio} (start {start})");
    }

    #[test]
    fn gauss_newton_improves_on_the_initial_guess() {
        // x = t^4 has g = xi^(1/4) as exact arc length, which no spline reproduces: the
        // Greville start is coarse and the Gauss-Newton steps must lower A; A / L^2 stays
        // above 1 and approaches it under refinement
        let side = SideCurve::Analytic(Analytic::new(|t| [t.powi(4), 0.0]));
        for n in [4, 16] {
            let (_, start) = arc_length_iterations(&side, n, 16, 0).unwrap().unwrap();
            let (g, opt) = arc_length_map(&side, n, 16).unwrap().unwrap();
            assert!(opt < start && opt > 1.0, "{n} elements: {start} -> {opt}");
            strictly_monotone_onto(|x| g.eval(x), 2000);
        }
        let (_, r4) = arc_length_map(&side, 4, 16).unwrap().unwrap();
        let (_, r16) = arc_length_map(&side, 16, 16).unwrap().unwrap();
        assert!(r16 < r4 && r16 < 1.02, "{r4} {r16}");
    }

    /// A synthetic tube: south is the line y = 0 from x = 0 to 10; north runs at height 1
    /// except for two narrow constrictions down to y = 0.05 at x = 3 and x = 7, and is
    /// wavy on `x < 2` so that cord length alone puts the constrictions at other
    /// parameters than south's; north is also sampled unevenly.
    fn tube() -> (Vec<Point>, Vec<Point>) {
        let south: Vec<Point> = (0..=400).map(|k| [10.0 * k as f64 / 400.0, 0.0]).collect();
        let height = |x: f64| {
            let wave = if x < 2.0 { 0.3 * (5.0 * std::f64::consts::PI * x).sin() } else { 0.0 };
            1.0 + wave - 0.95 * (-((x - 3.0) / 0.15).powi(2)).exp() - 0.95 * (-((x - 7.0) / 0.15).powi(2)).exp()
        };
        let north: Vec<Point> = (0..=600)
            .map(|k| {
                let s = k as f64 / 600.0;
                let x = 10.0 * s * s; // dense near x = 0
                [x, height(x)]
            })
            .collect();
        (south, north)
    }

    #[test]
    fn synthetic_tube_matches_at_the_gaps() {
        let (south, north) = tube();
        let mean = 0.5 * (polyline_length(&south) + polyline_length(&north));
        let eps = 0.02 * mean;
        for fill in [Fill::CordLength, Fill::MonotoneCubic] {
            let (x1, x2, pairs) = constrained_params(&south, &north, eps, 0.01, fill, Across::SouthNorth).unwrap();
            assert!(!pairs.is_empty());
            // every match is within the threshold and close to one of the constrictions
            for &(i, j) in &pairs {
                let d = dist2(south[i], north[j]).sqrt();
                assert!(d <= eps);
                assert!((south[i][0] - 3.0).abs() < 0.2 || (south[i][0] - 7.0).abs() < 0.2, "{:?}", south[i]);
                // the pair is at the same parameter on both sides
                assert_eq!(x1[i], x2[j]);
            }
            // the closest points of the constrictions are matched
            for gx in [3.0, 7.0] {
                let best = pairs
                    .iter()
                    .map(|&(i, j)| (south[i][0] - gx).abs() + (north[j][0] - gx).abs())
                    .fold(f64::INFINITY, f64::min);
                assert!(best < 0.06, "no match at x = {gx}: {best}");
            }
            // strictly increasing abscissae from 0 to 1 on both sides
            for x in [&x1, &x2] {
                assert!(x[0] == 0.0 && *x.last().unwrap() == 1.0);
                assert!(x.windows(2).all(|w| w[1] > w[0]));
            }
            // without constraints the constriction of north would be elsewhere
            let c2 = cord_length_params(&north).unwrap();
            let (i, j) = pairs[0];
            assert!((c2[j] - x1[i]).abs() > 0.05);
        }
        // minimum separation: matches are at least `sep` apart in cord length
        let (x1, _, pairs) =
            constrained_params(&south, &north, eps, 0.05, Fill::CordLength, Across::SouthNorth).unwrap();
        for w in pairs.windows(2) {
            assert!(x1[w[1].0] - x1[w[0].0] >= 0.05);
        }
        // nothing closer than the threshold: plain cord length, no matches
        let (_, x2, pairs) =
            constrained_params(&south, &north, 0.01, 0.01, Fill::CordLength, Across::SouthNorth).unwrap();
        assert!(pairs.is_empty());
        assert_eq!(x2, cord_length_params(&north).unwrap());
    }

    #[test]
    fn dense_clouds_are_thinned_for_the_search() {
        assert_eq!(thinned(5), vec![0, 1, 2, 3, 4]);
        let t = thinned(3 * MAX_SEARCH_POINTS + 7);
        assert!(t.len() <= MAX_SEARCH_POINTS + 1 && t[0] == 0 && *t.last().unwrap() == 3 * MAX_SEARCH_POINTS + 6);
        // a dense tube: matches still lie at the gap and at equal abscissae
        let n = 3 * MAX_SEARCH_POINTS;
        let south: Vec<Point> = (0..=n).map(|k| [10.0 * k as f64 / n as f64, 0.0]).collect();
        let north: Vec<Point> = (0..=n)
            .map(|k| {
                let x = 10.0 * k as f64 / n as f64;
                [x, 1.0 - 0.95 * (-((x - 6.0) / 0.2).powi(2)).exp()]
            })
            .collect();
        let (x1, x2, pairs) =
            constrained_params(&south, &north, 0.1, 0.01, Fill::CordLength, Across::SouthNorth).unwrap();
        assert!(!pairs.is_empty());
        for &(i, j) in &pairs {
            assert_eq!(x1[i], x2[j]);
            assert!((south[i][0] - 6.0).abs() < 0.3 && dist2(south[i], north[j]).sqrt() <= 0.1);
        }
    }

    #[test]
    fn constrained_curves_keep_shape_and_match_parameters() {
        // the tube's sides as analytic curves: g maps onto [0,1] monotonically and the
        // matched physical points are f(g(xi)) on both sides at the common xi
        let height = |x: f64| 1.0 - 0.95 * (-((x - 4.0) / 0.2).powi(2)).exp();
        let south = SideCurve::Analytic(Analytic::new(|t| [10.0 * t, 0.0]));
        let north = SideCurve::Analytic(Analytic::new(move |t| {
            let x = 10.0 * t * t;
            [x, height(x)]
        }));
        let west = SideCurve::Points(vec![[0.0, 0.0], [0.0, 1.0]]);
        let east = SideCurve::Points(vec![[10.0, 0.0], [10.0, 1.0]]);
        let b = Boundary { name: "tube".into(), sides: [south.clone(), east, north.clone(), west] };
        let p = plan(&b, &ReparamOptions::default()).unwrap();
        assert_eq!(p.report.used, Reparam::Constrained);
        assert_eq!(p.report.pair_methods, [Reparam::Constrained, Reparam::None]);
        assert!(!p.report.matches.is_empty());
        let (SideParam::Map(gs), SideParam::Map(gn)) = (&p.sides[0], &p.sides[2]) else { panic!("maps") };
        strictly_monotone_onto(|x| gs.eval(x), 4000);
        strictly_monotone_onto(|x| gn.eval(x), 4000);
        let (Some(fs), Some(fn_)) = (Parametric::new(&south), Parametric::new(&north)) else { panic!() };
        for m in &p.report.matches {
            let (a, c) = (fs.eval(gs.eval(m.parameter)), fn_.eval(gn.eval(m.parameter)));
            assert!(dist2(a, m.points[0]).sqrt() < 1e-9 && dist2(c, m.points[1]).sqrt() < 1e-9, "{m:?}");
            assert!((a[0] - 4.0).abs() < 0.5);
        }
        // the shape is unchanged: every point of f(g(xi)) lies on the curve, and f(g)
        // runs through all of it (the image of a fine xi grid is dense on the curve)
        let mut prev = fn_.eval(0.0);
        for k in 1..=2000 {
            let q = fn_.eval(gn.eval(k as f64 / 2000.0));
            assert!((q[1] - height(q[0])).abs() < 1e-12);
            assert!(dist2(prev, q).sqrt() < 0.1);
            prev = q;
        }
    }

    /// Points close across the outside of the domain (the turns of a spiral) are no
    /// narrow gap: neither measured by `min_distance` nor matched.
    #[test]
    fn only_points_facing_across_the_domain_count() {
        let line = |y: f64, n: usize| (0..=n).map(|k| [k as f64 / n as f64, y]).collect::<Vec<Point>>();
        let south = line(0.0, 50);
        // north above the south side: the domain lies between them
        assert!(facing(&south, 10, &line(0.2, 50), 10, Across::SouthNorth));
        assert!((min_distance(&south, &line(0.2, 50), Across::SouthNorth) - 0.2).abs() < 1e-12);
        // a "north" 0.01 below the south side lies across the outside
        let below = line(-0.01, 50);
        assert!(!facing(&south, 10, &below, 10, Across::SouthNorth));
        assert_eq!(min_distance(&south, &below, Across::SouthNorth), f64::INFINITY);
        let c: Vec<f64> = (0..=50).map(|k| k as f64 / 50.0).collect();
        assert!(match_pairs(&south, &c, &below, &c, 0.1, 0.01, Across::SouthNorth).is_empty());
        // west/east: west at x = 0 and east at x = 0.3, both running up
        let up = |x: f64| (0..=20).map(|k| [x, k as f64 / 20.0]).collect::<Vec<Point>>();
        assert!(facing(&up(0.0), 5, &up(0.3), 5, Across::WestEast));
        assert!(!facing(&up(0.3), 5, &up(0.0), 5, Across::WestEast));
    }
}
