//! Pseudo time-stepping (paper §6.2, eq. 30-33) with the SER time-step rule: the
//! iteration [`NonlinearSolver`] falls back to when Newton stalls.

use super::{Iterate, NonlinearSolver, Status};
use crate::error::Result;
use crate::methods::DiscreteProblem;

/// The smallest growth of the pseudo time step after an accepted step that lowered the
/// residual. SER alone (eq. 33) grows `dt` by the residual's ratio, and where the residual
/// falls slowly `dt` crawls: jigsaw-14's second level (15 876 functions, Newton stalled
/// at a scaled residual of 0.195) took 49 pseudo-time steps, each lowering the residual by
/// 3 to 5 %, until `dt` was large enough for Newton's quadratic convergence; doubling at
/// least takes 15 (its CPU time 54.1 -> 35.7 s; BENCHMARKS.md "Where jigsaw-14's time
/// goes"). A step that raises the residual above 10 times its value is still rejected
/// and `dt` quartered, so the rule only decides how fast a working step grows.
const SER_MIN_GROWTH: f64 = 2.0;

impl<P: DiscreteProblem> NonlinearSolver<P> {
    pub(super) fn pseudo_step(&mut self) -> Result<Iterate> {
        self.iteration += 1;
        self.pseudo_its += 1;
        if self.dt == 0.0 {
            // initial pseudo time step: make M / dt comparable to the Jacobian
            let mut f = std::mem::take(&mut self.f);
            let jac = self.lin.matrix_mut();
            self.problem.jacobian(&self.c, &mut f, jac);
            let jmax = jac.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            self.f = f;
            let mmax = self.problem.mass().values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            self.dt = if jmax > 0.0 { mmax / jmax } else { 1.0 };
        }
        let mut attempts = 0;
        loop {
            let dx = self.linear_step(Some(self.dt));
            let mut trial = self.c.clone();
            let mut ft = vec![0.0; self.c.len()];
            let nt = match &dx {
                Ok(dx) => {
                    for (t, d) in trial.iter_mut().zip(dx) {
                        *t += d;
                    }
                    if self.problem.admissible(&trial) {
                        self.eval(&trial, &mut ft)
                    } else {
                        f64::NAN
                    }
                }
                Err(_) => f64::NAN,
            };
            // a minimization method must stay where its objective is finite
            let jt = if nt.is_finite() { self.problem.objective(&trial) } else { None };
            if nt.is_finite() && nt <= 10.0 * self.norm && jt.is_none_or(f64::is_finite) {
                let step = dx.as_ref().map_or(0.0, |dx| dx.iter().fold(0.0f64, |m, d| m.max(d.abs())));
                // SER rule, eq. (33), with the growth limited to a factor 10 per step and,
                // after a step that lowered the residual, at least [`SER_MIN_GROWTH`]
                let ratio = (self.norm / nt).clamp(0.1, 10.0);
                let ratio = if nt < self.norm { ratio.max(SER_MIN_GROWTH) } else { ratio };
                self.dt = (self.dt * ratio).min(1e30);
                self.c = trial;
                self.f = ft;
                self.norm = nt;
                self.objective = jt;
                if self.converged(step) {
                    self.status = Status::Converged;
                } else if self.pseudo_its >= self.opts.max_pseudo {
                    self.status =
                        Status::Failed(format!("pseudo time-stepping reached {} iterations", self.opts.max_pseudo));
                }
                return Ok(self.iterate(step, 1.0));
            }
            self.dt *= 0.25;
            attempts += 1;
            if attempts > 30 {
                self.status = Status::Failed("pseudo time-stepping could not reduce the residual".into());
                return Ok(self.iterate(0.0, 0.0));
            }
        }
    }
}
