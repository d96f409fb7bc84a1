//! The line search of a minimisation along a Newton direction (Armijo on `J`, feasible
//! points only, the decrement rule) and its chord steps ([`NonlinearOptions::chord`]).

use std::time::Instant;

#[cfg(doc)]
use super::NonlinearOptions;
use super::{Iterate, NonlinearSolver, Status, EXTRAPOLATE_MAX};
use crate::methods::DiscreteProblem;

/// Chord steps of a minimisation after one exact Newton step at most
/// ([`NonlinearOptions::chord`]).
pub const MAX_DESCENT_CHORDS: usize = 3;

/// A minimisation's chord step ends the iteration when its decrement is below this
/// fraction of [`NonlinearOptions::decrement_tol`]` |J|`: its model has the Hessian of an
/// earlier point, so the chord iteration contracts linearly (by `ρ ~ |c_{k+1} - c_k|`)
/// where Newton's contracts quadratically, and leaves `ρ` times its decrement; the
/// fraction keeps the control points as close to the minimiser as after a Newton step of
/// negligible decrement (about `10⁻⁶` of the diameter).
pub const CHORD_DECREMENT_FACTOR: f64 = 1e-3;

impl<P: DiscreteProblem> NonlinearSolver<P> {
    /// The line search of a minimization method along the Newton direction `dx`:
    /// backtracking (quadratic interpolation, factors within `[0.1, 0.5]`) until the
    /// Armijo condition `J(c + t dx) <= J(c) + 10^-4 t ∇J·dx` holds at a feasible point.
    ///
    /// With the exact Hessian (`exact`), `-∇J·dx / 2` is the Newton decrement, the decrease
    /// of the quadratic model to its minimum: when it is below
    /// [`NonlinearOptions::decrement_tol`]` |J|` and the full step is taken, the iteration
    /// has converged.
    pub(super) fn descent_step(&mut self, j0: f64, dx: &[f64], exact: bool) -> Iterate {
        // ∇J·dx = -F·dx; the Newton direction of a positive definite Hessian descends
        let slope = -self.f.iter().zip(dx).map(|(f, d)| f * d).sum::<f64>();
        let negligible = exact && -0.5 * slope <= self.opts.decrement_tol * j0.abs();
        if slope.is_nan() || slope >= 0.0 {
            return self.stall("the Newton direction does not descend (Hessian not positive definite)".into());
        }
        let mut delta = 1.0;
        let mut trial = vec![0.0; self.c.len()];
        let mut ft = vec![0.0; self.c.len()];
        loop {
            for ((t, c), d) in trial.iter_mut().zip(&self.c).zip(dx) {
                *t = c + delta * d;
            }
            let t0 = Instant::now();
            let jt = match self.problem.admissible(&trial) {
                true => self.problem.objective(&trial).unwrap_or(f64::NAN),
                false => f64::INFINITY,
            };
            self.timings.assembly += t0.elapsed();
            if jt.is_finite() && jt <= j0 + 1e-4 * delta * slope {
                let mut nt = self.eval(&trial, &mut ft);
                let (mut delta, mut jt) = (delta, jt);
                let g1 = -ft.iter().zip(dx).map(|(f, d)| f * d).sum::<f64>();
                if let Some(t) = extrapolated_step(slope, g1).filter(|_| self.opts.extrapolate && delta == 1.0) {
                    let longer: Vec<f64> = self.c.iter().zip(dx).map(|(c, d)| c + t * d).collect();
                    let t0 = Instant::now();
                    let jl = match self.problem.admissible(&longer) {
                        true => self.problem.objective(&longer).unwrap_or(f64::NAN),
                        false => f64::INFINITY,
                    };
                    self.timings.assembly += t0.elapsed();
                    if jl < jt {
                        let mut fl = vec![0.0; self.c.len()];
                        nt = self.eval(&longer, &mut fl);
                        (trial, ft, delta, jt) = (longer, fl, t, jl);
                    }
                }
                let step = dx.iter().fold(0.0f64, |m, d| m.max((delta * d).abs()));
                std::mem::swap(&mut self.c, &mut trial);
                std::mem::swap(&mut self.f, &mut ft);
                self.norm = nt;
                self.objective = Some(jt);
                self.problem.step_accepted(delta);
                let mut done = self.converged(step) || (negligible && delta == 1.0);
                let mut step = step;
                if exact && delta == 1.0 && self.opts.chord {
                    for _ in 0..MAX_DESCENT_CHORDS {
                        if done {
                            break;
                        }
                        let Some((chord, negligible)) = self.descent_chord() else { break };
                        step = chord;
                        done = negligible || self.converged(step);
                    }
                }
                if done {
                    self.status = Status::Converged;
                } else if self.newton_its >= self.opts.max_newton {
                    return self.stall_with(format!("Newton reached {} iterations", self.opts.max_newton), step, delta);
                } else if self.opts.max_modified.is_some_and(|m| self.modified >= m) {
                    return self.stall_with(
                        format!(
                            "stopped after {} consecutive steps with a modified Hessian (not positive definite at the \
                             iterates: no minimiser within Newton's quadratic reach)",
                            self.modified
                        ),
                        step,
                        delta,
                    );
                }
                return self.iterate(step, delta);
            }
            // minimiser of the quadratic through J(0) = j0, J'(0) = slope and J(delta)
            let q =
                if jt.is_finite() { -slope * delta * delta / (2.0 * (jt - j0 - slope * delta)) } else { 0.1 * delta };
            delta = q.clamp(0.1 * delta, 0.5 * delta);
            if delta < 1e-10 {
                return self
                    .stall("line search failed (no decrease of the objective along the Newton direction)".into());
            }
        }
    }

    /// One chord step of a minimisation from the point a full exact Newton step reached
    /// ([`NonlinearOptions::chord`]): `z` from the Hessian of that step, still factorized,
    /// and the new gradient, `-∇²J(c_k) z = ∇J(c_{k+1})`; `c_{k+1} + z` replaces
    /// `c_{k+1}` when `z` descends, the point is feasible and `J` falls by the Armijo
    /// fraction `J(c_{k+1} + z) <= J(c_{k+1}) + 10^-4 ∇J·z` (a full step only). Returns
    /// the step length `max |z_i|` of a kept step and whether its decrement `-∇J·z / 2`
    /// (the model's, with the Hessian of `c_k`) is negligible
    /// ([`NonlinearOptions::decrement_tol`]): the minimisation has then converged, as after
    /// a full Newton step of negligible decrement. `None` when the step is not kept.
    fn descent_chord(&mut self) -> Option<(f64, bool)> {
        let j0 = self.objective?;
        let dz = self.chord_direction()?;
        let slope = -self.f.iter().zip(&dz).map(|(f, d)| f * d).sum::<f64>();
        if slope.is_nan() || slope >= 0.0 {
            return None;
        }
        let z: Vec<f64> = self.c.iter().zip(&dz).map(|(c, d)| c + d).collect();
        if !self.problem.admissible(&z) {
            return None;
        }
        let t0 = Instant::now();
        let jz = self.problem.objective(&z).unwrap_or(f64::NAN);
        self.timings.assembly += t0.elapsed();
        if !(jz.is_finite() && jz <= j0 + 1e-4 * slope) {
            return None;
        }
        let mut fz = vec![0.0; self.c.len()];
        self.norm = self.eval(&z, &mut fz);
        self.c = z;
        self.f = fz;
        self.objective = Some(jz);
        self.chord_steps += 1;
        let negligible = -0.5 * slope <= CHORD_DECREMENT_FACTOR * self.opts.decrement_tol * j0.abs();
        Some((dz.iter().fold(0.0f64, |m, d| m.max(d.abs())), negligible))
    }
}

/// The step factor `t > 1` along a descent direction `δ` at which the derivative of `J`
/// along it, `g(t) = ∇J(c + t δ)·δ`, interpolated linearly through `g(0) = g₀ < 0` and
/// `g(1) = g₁`, vanishes: `t = g₀ / (g₀ - g₁)`, the minimiser of the quadratic through
/// `J'(0)` and `J'(1)` (the secant step). Proposed when `g₀ < g₁ < 0` (`J` still falls
/// at the full step, less steeply than at 0) and `t >= 1.1`; at most `EXTRAPOLATE_MAX`.
/// Near a minimiser the full Newton step is exact to second order, `g₁ ≈ 0`: `None`.
pub fn extrapolated_step(g0: f64, g1: f64) -> Option<f64> {
    if !(g0 < g1 && g1 < 0.0) {
        return None;
    }
    let t = (g0 / (g0 - g1)).min(EXTRAPOLATE_MAX);
    (t >= 1.1).then_some(t)
}
