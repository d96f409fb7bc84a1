//! Sliding grids (paper §11.1, Fig. 22): a ring whose inner contour moves (turns
//! rigidly by a fixed angle per time step, or follows a given list of contours), the outer
//! contour fixed, solved frame after frame on one basis from extrapolated initial guesses.
//!
//! **Basis.** Frame 0 is a cold coarse-to-fine solve ([`Pipeline`]); its finest
//! basis `Ξ × H` (`H` periodic) serves every frame. `H` is uniform for a sliding seam
//! ([`EtaRefinement::Uniform`]: the parameter slides along the contour, and locally
//! refined elements would not follow the features they were refined for), adaptive for
//! [`Seam::Material`]. A sliding seam moves the parameter by `Δθ / 2π` of a period per
//! step; the prediction is good (one Newton step) while that is a small fraction of an
//! element (on the rotor at `Δθ = 0.003`, 128 elements: 0.06 of one). The grid is attached to the outer contour
//! (the casing): its control points, and so `eta = 0` at the material point `P = x(1, 0)`
//! of frame 0, never change.
//!
//! **The inner boundary of a turning contour** is computed from the frame-0 inner fit
//! `c_0(eta)` (the cold map's column `xi = 0`), never by refitting the turned input: a
//! refit to shifted samples moves the boundary control points non-smoothly in time (a
//! discrete least-squares sum whose samples cross knots is only `C^{p-1}` in the shift),
//! which capped the residual of the 5th-order prediction near `5e-6` on the rotor and
//! cost a second Newton iteration per frame. The boundary is `R(θ) c_0(eta + σ(θ))`,
//! `R(θ)` the rotation about the centre; where `eta = 0` sits is the choice of `σ`
//! ([`Seam`]):
//! - [`Seam::Slide`] (the default): `σ(θ) = -θ L / 2π`, the grid slides along the rotor
//!   at its mean angular rate (one period per turn), so `eta = 0` stays near the seam
//!   ray and the grid does not twist; on an `n`-fold symmetric rotor whose fit is
//!   symmetric the frames repeat after `2π / n`.
//! - [`Seam::Ray`] (the paper's literal choice, `c_r(eta)_y = 0`): `σ(θ)` puts `eta = 0`
//!   on the seam ray, the ray from the (turned) inner centroid in the frame-0 direction
//!   of `c_0(0)` (`ray_parameter`, tracked continuously). Where that ray grazes a lobe
//!   flank of a screw rotor, `σ` runs fast and the grid folds (the male rotor folds
//!   after about 40 degrees, see BENCHMARKS.md).
//! - [`Seam::Material`]: `σ = 0`, the control points of `c_0` turned: exact, `eta`
//!   moves with the rotor's material, and the grid lines twist by the angle turned.
//!
//! For `σ != 0` the shifted curve is not in the spline space (its knots moved by `-σ`);
//! the boundary is its exact `L2` projection (`PeriodicTranslate`), which is `C^{2p}`
//! in `σ`, so the boundary control points, and with them the interior ones, move
//! smoothly in time.
//!
//! A list of contours (non-rigid motion, [`Sweep::next_frame_contour`]) is fitted on `H`
//! by arc length with `eta = 0` on the seam ray from the contour's own centroid.
//!
//! **Reparameterization.** Every frame keeps frame 0's: the outer boundary is frame 0's
//! and the inner one is frame 0's moved as above. Frame 0 is fitted by arc length unless
//! the matching of narrow gaps (`boundary::ring_reparam`) is asked for
//! explicitly ([`Reparam::Constrained`]): `auto` reads as arc length here
//! ([`frame0_options`]). Matched pairs belong to one position of the inner contour; as it
//! turns, the outer parameter stays bunched where frame 0's lobe tips were (the rotor
//! rings have narrow tip gaps, so `auto` would match them; with `constrained` the male
//! rotor's 1000 frames are certified too, smallest det J 4.49 against 4.69 by arc
//! length, BENCHMARKS.md). The matching is not redone
//! per frame either: it is a discrete choice of pairs (§7.2, last paragraph: not a
//! continuous function of the shape), and redoing it would make the boundary control
//! points jump in time and spoil the extrapolation.
//!
//! **Predictor.** The interior control points of frame `n` are extrapolated in time from
//! the last `l <= 6` frames by the Lagrange polynomial of degree `l - 1` through
//! `(t_i, c_i)` (per control point and coordinate, any step sizes):
//! `c(t) = sum_i c_i prod_{j != i} (t - t_j) / (t_i - t_j)`, zeroth order (the previous
//! frame) for frame 1. Newton then starts from the prediction with the new boundary.
//!
//! **Stopping.** Each frame stops on the solver's scaled tolerance (`tol`, default
//! `1e-9`: `|F| sqrt(m) / diam`, absolute in that scaled sense), the same test as a cold
//! solve; a prediction already within it takes no Newton step. A prediction within
//! `sqrt(tol)` is in Newton's quadratic regime, and its one linear solve is carried to
//! `tol / (2 |F_0|)` ([`NonlinearSolver`](crate::solve::newton::NonlinearSolver)'s forcing term), so one step meets the
//! tolerance; the default first forcing term `1e-2` of a cold start had left `|F|`
//! about `1e-2 |F_0|` and cost a second iteration on every frame.

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use crate::boundary::normalise::Similarity;
use crate::boundary::reparam::Reparam;
use crate::boundary::ring::{ray_parameter, ClosedContour, Ring};
use crate::boundary::ring_fit::{fit_contour_seam, EtaRefinement};
use crate::discrete::assembly::Discretization;
use crate::error::{Error, Result};
use crate::methods::egg::EggMethod;
use crate::pipeline::{ring_options, Pipeline};
use crate::solve::fixed_basis::{scaled_options, FixedBasisSolve};
use crate::solve::options::SolveOptions;
use crate::solve::report::Solution;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Surface;
use crate::spline::translate::PeriodicTranslate;
use crate::verify::certificate::{certify, Finding};

/// Where `eta = 0` sits on a turning inner contour (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Seam {
    /// The grid slides along the inner contour at the mean angular rate:
    /// `σ(θ) = -θ L / 2π` (one period per turn); `eta = 0` stays near the seam ray.
    #[default]
    Slide,
    /// On the seam ray (the paper's `c_r(eta)_y = 0`): `σ(θ)` is the ray's crossing.
    Ray,
    /// On the inner contour's material point: the grid turns with it and twists.
    Material,
}

/// Options of a sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepOptions {
    /// Rotation of the inner contour per step, radians (counter-clockwise).
    pub step: f64,
    /// Number of frames after frame 0.
    pub steps: usize,
    /// Centre of rotation; the inner contour's centroid when `None`.
    pub center: Option<Point>,
    /// Highest order of the time extrapolation (at most 5: six frames).
    pub max_order: usize,
    /// Where `eta = 0` sits on the turning inner contour.
    pub seam: Seam,
}

impl Default for SweepOptions {
    fn default() -> Self {
        Self { step: 0.003, steps: 10, center: None, max_order: 5, seam: Seam::Slide }
    }
}

/// One row of the per-frame table.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct FrameReport {
    /// Frame index (0 is the cold solve).
    pub frame: usize,
    /// The frame's time: the rotation in radians for a turning contour, the given time
    /// for a list of contours.
    pub time: f64,
    /// Rotation of the inner contour, degrees (`null` for a list of contours).
    pub angle_degrees: Option<f64>,
    /// Order of the extrapolation that made the initial guess (`null` for the cold solve).
    pub predictor_order: Option<usize>,
    /// Newton iterations (on the finest level for frame 0).
    pub newton_iterations: usize,
    /// Linear systems solved: one per nonlinear iteration, all levels for frame 0.
    pub linear_solves: usize,
    /// `||F||` of the initial guess.
    pub residual_before: f64,
    /// `||F||` of the result.
    pub residual_after: f64,
    /// Whether the stopping rule was met.
    pub converged: bool,
    /// Largest deviation of the frame's inner boundary from the moved contour: from the
    /// turned frame-0 fit for a turning contour (sampled; frame 0's fit error comes on
    /// top), from the contour's samples for a list of contours, the fit for frame 0.
    pub inner_fit_error: f64,
    /// Parameter shift `σ` of the inner boundary (turning contour; 0 for [`Seam::Material`]).
    pub inner_shift: f64,
    /// Angle, degrees, from the seam ray to the inner point at `eta = 0`, seen from the
    /// ray's origin (0 for [`Seam::Ray`], the twist for [`Seam::Material`]).
    pub seam_offset_degrees: f64,
    /// Seconds (boundary, prediction, Newton, certificate).
    pub seconds: f64,
    /// Certificate verdict (`certified`, `folded`, ...).
    pub verdict: &'static str,
    /// Proven lower bound of `det J` when certified.
    pub det_j_lower_bound: Option<f64>,
}

/// The inner boundary of a frame and how it was made.
struct InnerBoundary {
    curve: Curve,
    /// See [`FrameReport::inner_fit_error`].
    fit_error: f64,
    /// See [`FrameReport::inner_shift`].
    shift: f64,
    /// The ray's origin (the turned inner centroid, or the contour's centroid).
    origin: Point,
}

/// A solved frame.
#[derive(Debug, Clone)]
pub struct Frame {
    /// The map.
    pub map: Surface,
    /// Its table row.
    pub report: FrameReport,
}

/// The Lagrange extrapolation (see the module documentation) of the control points
/// `values[i]` given at the distinct times `times[i]`, evaluated at `t`.
pub(crate) fn extrapolate(times: &[f64], values: &[&[Point]], t: f64) -> Vec<Point> {
    let n = values[0].len();
    let mut out = vec![[0.0; 2]; n];
    for (i, (&ti, vi)) in times.iter().zip(values).enumerate() {
        let w: f64 = times.iter().enumerate().filter(|&(j, _)| j != i).map(|(_, &tj)| (t - tj) / (ti - tj)).product();
        for (o, v) in out.iter_mut().zip(vi.iter()) {
            o[0] += w * v[0];
            o[1] += w * v[1];
        }
    }
    out
}

/// A sweep in progress: frame 0 solved, [`Sweep::next_frame`] (turning contour) or
/// [`Sweep::next_frame_contour`] (a given contour) solves the next one.
pub struct Sweep {
    opts: SolveOptions,
    sweep: SweepOptions,
    disc: Arc<Discretization>,
    knots: [KnotVector; 2],
    center: Point,
    centroid: Point,
    /// Direction of the seam ray (fixed in space).
    seam_dir: Point,
    /// The frame-0 inner boundary `c_0`.
    inner0: Curve,
    translate: PeriodicTranslate,
    /// Current shift `σ` (unwrapped) and the one before.
    sigma: [f64; 2],
    diameter: f64,
    /// Input coordinates from the sweep's (see [`Sweep::new`]).
    sim: Similarity,
    history: Vec<(f64, Vec<Point>)>,
    frame: usize,
}

impl std::fmt::Debug for Sweep {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sweep").field("frame", &self.frame).field("shape", &self.disc.shape()).finish()
    }
}

fn verdict(v: &Finding) -> (&'static str, Option<f64>) {
    match v {
        Finding::Certified { lower_bound, .. } => ("certified", Some(*lower_bound)),
        Finding::DegenerateCorner { .. } => ("degenerate-corner", None),
        Finding::Folded { .. } => ("folded", None),
        Finding::Undecided { .. } => ("undecided", None),
    }
}

fn rotate(p: Point, center: Point, angle: f64) -> Point {
    let (c, s) = (angle.cos(), angle.sin());
    let (x, y) = (p[0] - center[0], p[1] - center[1]);
    [center[0] + c * x - s * y, center[1] + s * x + c * y]
}

/// The options of frame 0's cold solve: `opts` with [`Reparam::Auto`] read as arc length
/// (see "Reparameterization" in the module documentation); an explicit request is kept.
pub fn frame0_options(opts: &SolveOptions) -> SolveOptions {
    let mut o = opts.clone();
    if o.fit.reparam.method == Reparam::Auto {
        o.fit.reparam.method = Reparam::ArcLength;
    }
    o
}

impl Sweep {
    /// Solve frame 0 cold ([`Pipeline`]) and set up the sweep on its basis. The frames
    /// are solved in the coordinates the cold solve ran in (`report.normalisation`, the
    /// identity for a well-placed ring) and mapped back; the certificate is that of the
    /// map written.
    pub fn new(ring: &Ring, opts: &SolveOptions, sweep: SweepOptions) -> Result<(Self, Solution, Frame)> {
        if !(sweep.step.is_finite() && sweep.max_order <= 5) {
            return Err(Error::Invalid(format!(
                "sweep: the step must be finite and the extrapolation order at most 5, got {} rad and order {}",
                sweep.step, sweep.max_order
            )));
        }
        let t0 = Instant::now();
        let refinement = match sweep.seam {
            Seam::Material => EtaRefinement::Adaptive,
            Seam::Slide | Seam::Ray => EtaRefinement::Uniform,
        };
        let sol = Pipeline::new(ring.clone(), frame0_options(opts)).eta_refinement(refinement).solve()?.into_map()?;
        let opts = ring_options(opts);
        // the sweep runs in the coordinates the cold solve ran in (normalised rings)
        let sim = sol.report.fit.normalisation.unwrap_or(Similarity::IDENTITY);
        let unit_cps: Vec<Point> = sol.map.control_points.iter().map(|&p| sim.to_unit(p)).collect();
        let map = &sol.map;
        let knots = map.knots.clone();
        let disc = Arc::new(Discretization::for_topology(knots.clone(), &opts.topology)?);
        let [nx, ny] = disc.shape();
        let inner0 = Curve::polynomial(knots[1].clone(), (0..ny).map(|j| unit_cps[j * nx]).collect());
        let centroid = sim.to_unit(ring.inner.centroid());
        let center = sweep.center.map_or(centroid, |c| sim.to_unit(c));
        let start = inner0.eval(knots[1].domain().0);
        let seam_dir = [start[0] - centroid[0], start[1] - centroid[1]];
        let (v, lb) = verdict(&sol.report.outcome.certificate.verdict);
        let levels = &sol.report.solve.levels;
        let last = levels.last();
        let report = FrameReport {
            frame: 0,
            time: 0.0,
            angle_degrees: Some(0.0),
            predictor_order: None,
            newton_iterations: last.map_or(0, |l| l.newton_iterations),
            linear_solves: levels.iter().map(|l| l.iterations + l.continuation_iterations).sum(),
            residual_before: last.and_then(|l| l.residuals.first().copied()).unwrap_or(f64::NAN),
            residual_after: last.and_then(|l| l.residuals.last().copied()).unwrap_or(f64::NAN),
            converged: last.is_some_and(|l| l.converged),
            inner_fit_error: sol.report.fit.sides[3].max_error,
            inner_shift: 0.0,
            seam_offset_degrees: 0.0,
            seconds: t0.elapsed().as_secs_f64(),
            verdict: v,
            det_j_lower_bound: lb,
        };
        let frame = Frame { map: map.clone(), report };
        let s = Self {
            translate: PeriodicTranslate::new(&knots[1])?,
            disc,
            center,
            centroid,
            seam_dir,
            inner0,
            sigma: [0.0; 2],
            diameter: sol.report.fit.diameter / sim.scale,
            history: vec![(0.0, unit_cps)],
            sim,
            knots,
            opts,
            sweep,
            frame: 0,
        };
        Ok((s, sol, frame))
    }

    /// The inner boundary turned by `angle` (see the module documentation).
    fn turned_inner(&mut self, angle: f64) -> Result<InnerBoundary> {
        let (c0, center) = (&self.inner0, self.center);
        let turn = |c: &Curve| Curve {
            control_points: c.control_points.iter().map(|&p| rotate(p, center, angle)).collect(),
            ..c.clone()
        };
        let origin = rotate(self.centroid, center, angle);
        if self.sweep.seam == Seam::Material {
            return Ok(InnerBoundary { curve: turn(c0), fit_error: 0.0, shift: 0.0, origin });
        }
        let l = c0.knots.length();
        let sigma = match self.sweep.seam {
            Seam::Slide => -angle / std::f64::consts::TAU * l,
            _ => {
                // in the frame of c_0: the ray from the centroid in direction R(-angle) seam_dir
                let dir = rotate(self.seam_dir, [0.0; 2], -angle);
                let [s1, s0] = self.sigma;
                let guess = s1 + (s1 - s0);
                let found = ray_parameter(c0, self.centroid, dir, guess).ok_or_else(|| {
                    Error::Invalid(format!(
                        "sweep: the seam ray misses the inner contour turned by {:.6} degrees",
                        angle.to_degrees()
                    ))
                })?;
                guess + ((found - guess) + 0.5 * l).rem_euclid(l) - 0.5 * l
            }
        };
        let q = self.translate.translate(c0, sigma)?;
        let (a, _) = c0.domain();
        let m = 4 * c0.knots.num_elements();
        let err = (0..m)
            .map(|k| {
                let u = a + l * (k as f64 + 0.5) / m as f64;
                let (x, y) = (q.eval(u), c0.eval(a + (u + sigma - a).rem_euclid(l)));
                (x[0] - y[0]).hypot(x[1] - y[1])
            })
            .fold(0.0, f64::max);
        self.sigma = [sigma, self.sigma[0]];
        Ok(InnerBoundary { curve: turn(&q), fit_error: err, shift: sigma, origin })
    }

    /// Solve the next frame of the turning contour from the extrapolated guess and
    /// certify it.
    pub fn next_frame(&mut self) -> Result<Frame> {
        let t0 = Instant::now();
        let angle = (self.frame + 1) as f64 * self.sweep.step;
        let inner = self.turned_inner(angle)?;
        self.solve_frame(t0, angle, true, inner)
    }

    /// Solve the next frame with `inner` as the inner contour at time `time` (after the
    /// previous frames' times; frame 0 is at time 0): the contour is fitted on the
    /// sweep's `eta` vector by arc length with `eta = 0` on the seam ray from its
    /// centroid, and the interior extrapolated in `time`.
    pub fn next_frame_contour(&mut self, inner: &ClosedContour, time: f64) -> Result<Frame> {
        let t0 = Instant::now();
        let last = self.history.last().map_or(0.0, |h| h.0);
        if !(time.is_finite() && time > last) {
            return Err(Error::Invalid(format!(
                "sweep: frame times must increase, got {time} after {last} at frame {}",
                self.frame + 1
            )));
        }
        let sim = self.sim;
        let inner = &inner.mapped(move |p| sim.to_unit(p));
        let c = inner.centroid();
        let toward = [c[0] + self.seam_dir[0], c[1] + self.seam_dir[1]];
        let (curve, fit_error) = fit_contour_seam(inner, &self.knots[1], c, toward)?;
        self.solve_frame(t0, time, false, InnerBoundary { curve, fit_error, shift: 0.0, origin: c })
    }

    fn solve_frame(&mut self, t0: Instant, time: f64, turned: bool, boundary: InnerBoundary) -> Result<Frame> {
        let inner = &boundary.curve;
        let p = inner.eval(inner.domain().0);
        let (d, o) = (self.seam_dir, boundary.origin);
        let w = [p[0] - o[0], p[1] - o[1]];
        let seam_offset = (d[0] * w[1] - d[1] * w[0]).atan2(d[0] * w[0] + d[1] * w[1]).to_degrees();
        let k = self.frame + 1;
        // predictor: Lagrange through the last up to max_order + 1 frames
        let l = self.history.len().min(self.sweep.max_order + 1);
        let recent = &self.history[self.history.len() - l..];
        let times: Vec<f64> = recent.iter().map(|h| h.0).collect();
        let values: Vec<&[Point]> = recent.iter().map(|h| h.1.as_slice()).collect();
        let mut cps = extrapolate(&times, &values, time);
        let [nx, ny] = self.disc.shape();
        let last = &self.history.last().expect("frame 0").1;
        for j in 0..ny {
            cps[j * nx] = inner.control_points[j];
            cps[j * nx + nx - 1] = last[j * nx + nx - 1];
        }
        let method = EggMethod::cpu(self.opts.operator);
        let nl = scaled_options(self.opts.nonlinear, &method, self.diameter, self.disc.dofs.num_free());
        self.disc.dofs.wrap(&mut cps);
        let solved = FixedBasisSolve::new(&method, self.disc.clone(), cps, nl).finish()?;
        let h = &solved.history;
        let (newton, solves) = (h.newton_iterations, h.newton_iterations + h.pseudo_time_iterations);
        let ((before, after), converged) = (h.residuals_before_after(), solved.converged());
        let unit = Surface { knots: self.knots.clone(), control_points: solved.control_points, weights: None };
        let map = self.sim.physical_surface(&unit)?;
        let cert = certify(&map, &self.opts.certify)?;
        let (v, lb) = verdict(&cert.verdict);
        self.history.push((time, unit.control_points));
        if self.history.len() > 6 {
            self.history.remove(0);
        }
        self.frame = k;
        let report = FrameReport {
            frame: k,
            time,
            angle_degrees: turned.then(|| time.to_degrees()),
            predictor_order: Some(l - 1),
            newton_iterations: newton,
            linear_solves: solves,
            residual_before: before,
            residual_after: after,
            converged,
            inner_fit_error: self.sim.length(boundary.fit_error),
            inner_shift: boundary.shift,
            seam_offset_degrees: seam_offset,
            seconds: t0.elapsed().as_secs_f64(),
            verdict: v,
            det_j_lower_bound: lb,
        };
        Ok(Frame { map, report })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::Analytic;
    use crate::testutil::Lcg;

    /// Extrapolation through `l` frames is exact for polynomials of degree `l - 1` in
    /// time, with uneven steps.
    #[test]
    fn extrapolation_is_exact_for_polynomials_of_its_order() {
        let mut rng = Lcg::new(4);
        for l in 1..=6 {
            let coef: Vec<[f64; 2]> = (0..l).map(|_| [rng.uniform() - 0.5, rng.uniform() - 0.5]).collect();
            let f = |t: f64| -> Point {
                let mut p = [0.0; 2];
                for (k, c) in coef.iter().enumerate() {
                    p[0] += c[0] * t.powi(k as i32);
                    p[1] += c[1] * t.powi(k as i32);
                }
                p
            };
            let mut t = 0.0;
            let mut times = Vec::new();
            for _ in 0..l {
                t += 0.5 + rng.uniform();
                times.push(t);
            }
            let vals: Vec<Vec<Point>> = times.iter().map(|&t| vec![f(t), f(2.0 * t)]).collect();
            let refs: Vec<&[Point]> = vals.iter().map(|v| v.as_slice()).collect();
            let tn = t + 0.7;
            let got = extrapolate(&times, &refs, tn);
            for (g, e) in got.iter().zip([f(tn), f(2.0 * tn)]) {
                assert!((g[0] - e[0]).abs() < 1e-9 && (g[1] - e[1]).abs() < 1e-9, "l={l}: {g:?} vs {e:?}");
            }
        }
    }

    fn circle(r: f64, c: Point) -> ClosedContour {
        let tau = std::f64::consts::TAU;
        ClosedContour::Analytic(Analytic::new(move |t| [c[0] + r * (tau * t).cos(), c[1] + r * (tau * t).sin()]))
    }

    /// A four-lobed contour `r = 0.35 (1 + 0.2 cos 4φ)` about `c` (a rotor-like inner).
    fn lobes(c: Point) -> ClosedContour {
        let tau = std::f64::consts::TAU;
        ClosedContour::Analytic(Analytic::new(move |t| {
            let r = 0.35 * (1.0 + 0.2 * (4.0 * tau * t).cos());
            [c[0] + r * (tau * t).cos(), c[1] + r * (tau * t).sin()]
        }))
    }

    fn fast() -> SolveOptions {
        let mut o = SolveOptions::default();
        o.fit.tol = 1e-3;
        o
    }

    /// The eccentric inner circle turning about the outer circle's centre, for each seam:
    /// every frame is certified, from six frames on one Newton iteration meets the
    /// tolerance, and the inner boundary is where the seam puts it: the turned frame-0
    /// boundary (material, exactly), shifted by `σ = -θ / 2π` (slide), or with
    /// `eta = 0` on the seam ray (ray).
    #[test]
    fn rotating_eccentric_ring_frames_certify_with_one_newton_step() {
        let ring = Ring { name: "ecc".into(), inner: circle(0.4, [0.25, 0.1]), outer: circle(1.0, [0.0; 2]) };
        for seam in [Seam::Slide, Seam::Ray, Seam::Material] {
            let so = SweepOptions { step: 0.01, steps: 9, center: Some([0.0, 0.0]), seam, ..Default::default() };
            let (mut sweep, _, f0) = Sweep::new(&ring, &fast(), so).unwrap();
            assert_eq!(f0.report.verdict, "certified");
            let [nx, ny] = f0.map.shape();
            let c0: Vec<Point> = (0..ny).map(|j| f0.map.control_points[j * nx]).collect();
            let (o0, s0) = (f0.map.eval(0.0, 0.0), f0.map.eval(1.0, 0.0));
            for k in 1..=9 {
                let f = sweep.next_frame().unwrap();
                let r = &f.report;
                assert!(r.verdict == "certified" && r.converged, "{seam:?} frame {k}: {r:?}");
                if k >= 6 {
                    assert!(r.newton_iterations <= 1 && r.linear_solves <= 2, "{seam:?} frame {k}: {r:?}");
                }
                let a = 0.01 * k as f64;
                // every inner point is on the turned circle; the outer column is unchanged
                let c = rotate([0.25, 0.1], [0.0; 2], a);
                for v in [0.0, 0.3, 0.77] {
                    let p = f.map.eval(0.0, v);
                    assert!(((p[0] - c[0]).hypot(p[1] - c[1]) - 0.4).abs() < 1e-3, "{seam:?} frame {k}");
                }
                assert_eq!(f.map.eval(1.0, 0.0), s0);
                let p = f.map.eval(0.0, 0.0);
                match seam {
                    Seam::Material => {
                        assert_eq!(r.inner_shift, 0.0);
                        for (j, q) in c0.iter().enumerate() {
                            let t = rotate(*q, [0.0; 2], a);
                            let g = f.map.control_points[j * nx];
                            assert!((g[0] - t[0]).abs() < 1e-14 && (g[1] - t[1]).abs() < 1e-14);
                        }
                    }
                    Seam::Slide => assert!((r.inner_shift + a / std::f64::consts::TAU).abs() < 1e-15),
                    Seam::Ray => {
                        // eta = 0 on the ray from the turned centre in the frame-0 direction
                        let d = [o0[0] - 0.25, o0[1] - 0.1];
                        let w = [p[0] - c[0], p[1] - c[1]];
                        assert!((d[0] * w[1] - d[1] * w[0]).abs() < 1e-3 && d[0] * w[0] + d[1] * w[1] > 0.0);
                    }
                }
            }
        }
    }

    /// A four-lobed inner contour turning about its centre (the rotor of §11.1 in
    /// miniature) at the paper's 0.003 rad per step: with the sliding seam, from six
    /// frames on one Newton iteration and one linear solve per frame, all certified.
    #[test]
    fn turning_lobes_slide_with_one_newton_step() {
        let ring = Ring { name: "lobes".into(), inner: lobes([0.1, 0.0]), outer: circle(1.0, [0.0; 2]) };
        let so = SweepOptions { step: 0.003, steps: 10, center: Some([0.1, 0.0]), ..Default::default() };
        let (mut sweep, _, f0) = Sweep::new(&ring, &fast(), so).unwrap();
        assert_eq!(f0.report.verdict, "certified");
        for k in 1..=10 {
            let r = sweep.next_frame().unwrap().report;
            assert!(r.verdict == "certified" && r.converged, "frame {k}: {r:?}");
            if k >= 6 {
                assert!(r.newton_iterations <= 1 && r.linear_solves <= 1, "frame {k}: {r:?}");
            }
        }
    }

    /// A breathing inner contour given frame by frame (non-rigid motion, uneven times):
    /// each frame's inner boundary is the given contour, every frame certified, and the
    /// prediction improves once more frames exist.
    #[test]
    fn contours_given_frame_by_frame() {
        let ring = Ring { name: "breathe".into(), inner: circle(0.4, [0.1, 0.0]), outer: circle(1.0, [0.0; 2]) };
        let (mut sweep, _, _) = Sweep::new(&ring, &fast(), SweepOptions::default()).unwrap();
        let mut t = 0.0;
        let mut before = Vec::new();
        for k in 1..=8 {
            t += if k % 2 == 0 { 0.01 } else { 0.015 };
            let r = 0.4 + 0.5 * t;
            let f = sweep.next_frame_contour(&circle(r, [0.1, 0.0]), t).unwrap();
            assert!(f.report.verdict == "certified" && f.report.converged, "frame {k}: {:?}", f.report);
            let p = f.map.eval(0.0, 0.41);
            assert!(((p[0] - 0.1).hypot(p[1]) - r).abs() < 1e-3, "frame {k}");
            before.push(f.report.residual_before);
        }
        assert!(before[7] < 1e-2 * before[0], "{before:?}");
        let e = sweep.next_frame_contour(&circle(0.5, [0.1, 0.0]), t).unwrap_err();
        assert!(e.to_string().contains("increase"), "{e}");
    }

    /// A ring far from the origin and large sweeps like the ring at the origin: the
    /// frames are solved in unit coordinates and mapped back.
    #[test]
    fn far_rings_sweep_like_rings_at_the_origin() {
        let ring = Ring { name: "ecc".into(), inner: circle(0.4, [0.25, 0.1]), outer: circle(1.0, [0.0; 2]) };
        let (c, s) = ([3.0e9, -1.0e9], 2.0f64.powi(30));
        let f = move |p: Point| [c[0] + s * p[0], c[1] + s * p[1]];
        let far = Ring { name: "far".into(), inner: ring.inner.mapped(f), outer: ring.outer.mapped(f) };
        let so = SweepOptions { step: 0.01, steps: 3, center: Some([0.1, 0.0]), ..Default::default() };
        let far_so = SweepOptions { center: Some(f([0.1, 0.0])), ..so };
        let (mut a, _, _) = Sweep::new(&ring, &fast(), so).unwrap();
        let (mut b, _, _) = Sweep::new(&far, &fast(), far_so).unwrap();
        for k in 1..=3 {
            let (fa, fb) = (a.next_frame().unwrap(), b.next_frame().unwrap());
            assert_eq!(fb.report.verdict, "certified", "frame {k}");
            assert_eq!(fa.report.newton_iterations, fb.report.newton_iterations);
            for (p, q) in fa.map.control_points.iter().zip(&fb.map.control_points) {
                let back = [(q[0] - c[0]) / s, (q[1] - c[1]) / s];
                assert!((p[0] - back[0]).abs() < 1e-6 && (p[1] - back[1]).abs() < 1e-6, "frame {k}: {p:?} {back:?}");
            }
        }
    }
}
