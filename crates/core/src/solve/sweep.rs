//! Sliding grids (paper §11.1, Fig. 22): a ring whose inner contour turns rigidly by a
//! fixed angle per time step, the outer contour fixed, solved frame after frame on one
//! basis from extrapolated initial guesses.
//!
//! **Basis and seam.** Frame 0 is a cold coarse-to-fine solve ([`solve_ring`]); its
//! finest basis `Ξ × H` (`H` periodic) serves every frame. The grid is attached to the
//! outer contour (the casing): its control points, and so `eta = 0` at the material point
//! `P = x(1, 0)` of frame 0, never change. The inner contour of frame `k` (turned by
//! `k Δθ` about the centre) is fitted on `H` by arc length with `eta = 0` where the ray
//! from its (turned) centroid towards `P` crosses it — the paper's choice
//! `c_r(eta)_y = 0` when `P` lies on the `x` axis through the centre. At frame 0 this is
//! where the cold solve put it (that ray passes through the inner start).
//!
//! **Predictor.** The interior control points of frame `n` are extrapolated in time from
//! the last `l <= 6` frames by the Lagrange polynomial of degree `l - 1` through
//! `(t_i, c_i)` (per control point and coordinate, any step sizes):
//! `c(t) = sum_i c_i prod_{j != i} (t - t_j) / (t_i - t_j)`, zeroth order (the previous
//! frame) for frame 1. Newton then starts from the prediction with the new boundary.

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use super::newton::{NonlinearMethod, NonlinearOptions, NonlinearSolver, Status};
use super::options::SolveOptions;
use super::report::Solution;
use super::solver::{ring_options, solve_ring};
use crate::boundary::ring::{fit_contour_seam, Ring};
use crate::discrete::assembly::Discretization;
use crate::error::{Error, Result};
use crate::methods::egg::EggMethod;
use crate::methods::Method;
use crate::spline::curve::Point;
use crate::spline::surface::Surface;
use crate::verify::certificate::{certify, Verdict as CertVerdict};

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
}

impl Default for SweepOptions {
    fn default() -> Self {
        Self { step: 0.003, steps: 10, center: None, max_order: 5 }
    }
}

/// One row of the per-frame table.
#[derive(Debug, Clone, Serialize)]
pub struct FrameReport {
    /// Frame index (0 is the cold solve).
    pub frame: usize,
    /// Rotation of the inner contour, degrees.
    pub angle_degrees: f64,
    /// Order of the extrapolation that made the initial guess (`null` for the cold solve).
    pub predictor_order: Option<usize>,
    /// Newton iterations (on the finest level for frame 0).
    pub newton_iterations: usize,
    /// Linear systems solved: one per nonlinear iteration, all levels for frame 0.
    pub linear_solves: usize,
    /// `||F||` of the initial guess and of the result.
    pub residual_before: f64,
    /// `||F||` of the result.
    pub residual_after: f64,
    /// Whether the stopping rule was met.
    pub converged: bool,
    /// Largest deviation of the fitted inner contour from the turned input.
    pub inner_fit_error: f64,
    /// Seconds (fit, prediction, Newton, certificate).
    pub seconds: f64,
    /// Certificate verdict (`certified`, `folded`, ...).
    pub verdict: &'static str,
    /// Proven lower bound of `det J` when certified.
    pub det_j_lower_bound: Option<f64>,
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
pub fn extrapolate(times: &[f64], values: &[&[Point]], t: f64) -> Vec<Point> {
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

/// A sweep in progress: frame 0 solved, [`Sweep::next_frame`] solves the next one.
pub struct Sweep {
    ring: Ring,
    opts: SolveOptions,
    sweep: SweepOptions,
    disc: Arc<Discretization>,
    knots: [crate::spline::knots::KnotVector; 2],
    center: Point,
    centroid: Point,
    anchor: Point,
    diameter: f64,
    history: Vec<(f64, Vec<Point>)>,
    frame: usize,
}

impl std::fmt::Debug for Sweep {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sweep").field("frame", &self.frame).field("shape", &self.disc.shape()).finish()
    }
}

fn verdict(v: &CertVerdict) -> (&'static str, Option<f64>) {
    match v {
        CertVerdict::Certified { lower_bound, .. } => ("certified", Some(*lower_bound)),
        CertVerdict::DegenerateCorner { .. } => ("degenerate-corner", None),
        CertVerdict::Folded { .. } => ("folded", None),
        CertVerdict::Undecided { .. } => ("undecided", None),
    }
}

impl Sweep {
    /// Solve frame 0 cold ([`solve_ring`]) and set up the sweep on its basis.
    pub fn new(ring: &Ring, opts: &SolveOptions, sweep: SweepOptions) -> Result<(Self, Solution, Frame)> {
        if !(sweep.step.is_finite() && sweep.max_order <= 5) {
            return Err(Error::Invalid(format!(
                "sweep: the step must be finite and the extrapolation order at most 5, got {} rad and order {}",
                sweep.step, sweep.max_order
            )));
        }
        let t0 = Instant::now();
        let sol = solve_ring(ring, opts)?;
        let opts = ring_options(opts);
        let map = &sol.map;
        let knots = map.knots.clone();
        let disc = Arc::new(Discretization::for_topology(knots.clone(), &opts.topology)?);
        let centroid = ring.inner.centroid();
        let center = sweep.center.unwrap_or(centroid);
        let (v, lb) = verdict(&sol.report.certificate.verdict);
        let levels = &sol.report.levels;
        let last = levels.last();
        let report = FrameReport {
            frame: 0,
            angle_degrees: 0.0,
            predictor_order: None,
            newton_iterations: last.map_or(0, |l| l.newton_iterations),
            linear_solves: levels.iter().map(|l| l.iterations + l.continuation_iterations).sum(),
            residual_before: last.and_then(|l| l.residuals.first().copied()).unwrap_or(f64::NAN),
            residual_after: last.and_then(|l| l.residuals.last().copied()).unwrap_or(f64::NAN),
            converged: last.is_some_and(|l| l.converged),
            inner_fit_error: sol.report.fit[3].max_error,
            seconds: t0.elapsed().as_secs_f64(),
            verdict: v,
            det_j_lower_bound: lb,
        };
        let frame = Frame { map: map.clone(), report };
        let s = Self {
            ring: ring.clone(),
            disc,
            center,
            centroid,
            anchor: map.eval(1.0, 0.0),
            diameter: sol.report.diameter,
            history: vec![(0.0, map.control_points.clone())],
            knots,
            opts,
            sweep,
            frame: 0,
        };
        Ok((s, sol, frame))
    }

    /// Solve the next frame from the extrapolated guess and certify it.
    pub fn next_frame(&mut self) -> Result<Frame> {
        let t0 = Instant::now();
        let k = self.frame + 1;
        let angle = k as f64 * self.sweep.step;
        let inner = self.ring.inner.rotated(self.center, angle);
        let (c, s) = (angle.cos(), angle.sin());
        let (x, y) = (self.centroid[0] - self.center[0], self.centroid[1] - self.center[1]);
        let centroid = [self.center[0] + c * x - s * y, self.center[1] + s * x + c * y];
        let (curve, fit_err) = fit_contour_seam(&inner, &self.knots[1], centroid, self.anchor)?;
        // predictor: Lagrange through the last up to max_order + 1 frames
        let l = self.history.len().min(self.sweep.max_order + 1);
        let recent = &self.history[self.history.len() - l..];
        let times: Vec<f64> = recent.iter().map(|h| h.0).collect();
        let values: Vec<&[Point]> = recent.iter().map(|h| h.1.as_slice()).collect();
        let mut cps = extrapolate(&times, &values, angle);
        let [nx, ny] = self.disc.shape();
        let last = &self.history.last().expect("frame 0").1;
        for j in 0..ny {
            cps[j * nx] = curve.control_points[j];
            cps[j * nx + nx - 1] = last[j * nx + nx - 1];
        }
        let method = EggMethod::cpu(self.opts.operator);
        let m = self.disc.dofs.num_free();
        let mut nl: NonlinearOptions = self.opts.nonlinear;
        nl.scale = method.residual_scale(self.diameter, m);
        nl.step_tol = self.opts.nonlinear.step_tol.max(1e-13) * self.diameter;
        self.disc.dofs.wrap(&mut cps);
        let c0 = self.disc.dofs.gather(&cps);
        let problem = method.problem(self.disc.clone(), cps);
        let mut solver = NonlinearSolver::new(problem, c0, nl);
        let (mut before, mut after, mut newton, mut solves) = (f64::NAN, f64::NAN, 0, 0);
        for it in solver.by_ref() {
            let it = it?;
            if it.iteration == 0 {
                before = it.residual;
            } else {
                solves += 1;
                if it.method == NonlinearMethod::Newton {
                    newton += 1;
                }
            }
            after = it.residual;
        }
        let converged = solver.status() == &Status::Converged;
        let (problem, c) = solver.into_parts();
        let map = Surface { knots: self.knots.clone(), control_points: problem.control_points(&c), weights: None };
        let cert = certify(&map, &self.opts.certify)?;
        let (v, lb) = verdict(&cert.verdict);
        self.history.push((angle, map.control_points.clone()));
        if self.history.len() > 6 {
            self.history.remove(0);
        }
        self.frame = k;
        let report = FrameReport {
            frame: k,
            angle_degrees: angle.to_degrees(),
            predictor_order: Some(l - 1),
            newton_iterations: newton,
            linear_solves: solves,
            residual_before: before,
            residual_after: after,
            converged,
            inner_fit_error: fit_err,
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
    use crate::boundary::ring::ClosedContour;
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

    /// The eccentric inner circle turning about the outer circle's centre: every frame is
    /// certified, and with the 5th-order predictor one Newton iteration per frame meets
    /// the tolerance.
    #[test]
    fn rotating_eccentric_ring_frames_certify_with_one_newton_step() {
        let tau = std::f64::consts::TAU;
        let circle = move |r: f64, c: Point| {
            ClosedContour::Analytic(Analytic::new(move |t| [c[0] + r * (tau * t).cos(), c[1] + r * (tau * t).sin()]))
        };
        let ring = Ring { name: "ecc".into(), inner: circle(0.4, [0.25, 0.1]), outer: circle(1.0, [0.0; 2]) };
        let so = SweepOptions { step: 0.01, steps: 9, center: Some([0.0, 0.0]), max_order: 5 };
        let (mut sweep, _, f0) = Sweep::new(&ring, &SolveOptions::default(), so).unwrap();
        assert_eq!(f0.report.verdict, "certified");
        for k in 1..=9 {
            let f = sweep.next_frame().unwrap();
            assert_eq!(f.report.verdict, "certified", "frame {k}");
            assert!(f.report.converged, "frame {k}: {:?}", f.report);
            if k >= 6 {
                assert!(f.report.newton_iterations <= 1 && f.report.linear_solves <= 2, "frame {k}: {:?}", f.report);
            }
            // the inner contour moved: its seam point is on the turned circle
            let p = f.map.eval(0.0, 0.3);
            let a = 0.01 * k as f64;
            let c = [0.25 * a.cos() - 0.1 * a.sin(), 0.25 * a.sin() + 0.1 * a.cos()];
            assert!(((p[0] - c[0]).hypot(p[1] - c[1]) - 0.4).abs() < 1e-4, "frame {k}");
        }
    }
}
