//! One solve on a fixed basis, run by every stage that solves on one basis (the levels
//! of §6.3 and their continuation, the improvement of §4.1, the `C⁰` route of §9, sweep
//! frames and loft slices of §11.1, the free interfaces of §11.2): a [`DiscreteProblem`]
//! run by the [`NonlinearSolver`] from a start with options scaled by the geometry
//! ([`scaled_options`]), its iterates recorded while they stream ([`History`]), the
//! unknowns taken back as control points ([`Solved`]); the certificate rules of "keep
//! only if certified" are [`bijective`] and [`as_well_certified`] (an improvement on a
//! layout applies them to every patch, [`crate::solve::improve`]).

use std::sync::Arc;

use super::newton::{Iterate, NonlinearMethod, NonlinearOptions, NonlinearSolver, Status, Timings};
use crate::discrete::assembly::Discretization;
use crate::error::Result;
use crate::methods::{DiscreteProblem, Method};
use crate::spline::curve::Point;
use crate::verify::certificate::{Certificate, Finding};

/// `nonlinear` for `method` on a basis with `m` free functions of a geometry of diameter
/// `diameter`: the residual made dimensionless by [`Method::residual_scale`] (for EGG
/// `|F| sqrt(m) / residual_size`, eq. 8 with `∫ w_i ~ 1/m`) and the step tolerance
/// `max(step_tol, 10⁻¹³) diameter` in length units.
pub(crate) fn scaled_options(
    nonlinear: NonlinearOptions,
    method: &dyn Method,
    diameter: f64,
    m: usize,
) -> NonlinearOptions {
    let mut nl = nonlinear;
    nl.scale = method.residual_scale(diameter, m);
    nl.step_tol = nonlinear.step_tol.max(1e-13) * diameter;
    nl
}

/// Whether a certificate proves a map bijective, so that a method needing `det J > 0`
/// may start from it: certified, or positive away from corners the boundary forces to
/// `det J = 0` (degenerate corner).
pub fn bijective(c: &Certificate) -> bool {
    matches!(c.verdict, Finding::Certified { .. } | Finding::DegenerateCorner { .. })
}

/// Whether `after` is at least as well certified as `before`: a certified start needs a
/// certified result, a degenerate-corner start a [`bijective`] one.
pub(crate) fn as_well_certified(before: &Certificate, after: &Certificate) -> bool {
    match before.verdict {
        Finding::Certified { .. } => matches!(after.verdict, Finding::Certified { .. }),
        _ => bijective(after),
    }
}

/// The iterates of one solve, recorded as they come.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct History {
    /// The number of the last iterate (0: the start met the stopping rule or failed).
    pub iterations: usize,
    /// Iterates after the start produced by Newton steps.
    pub newton_iterations: usize,
    /// Iterates after the start produced by pseudo time steps.
    pub pseudo_time_iterations: usize,
    /// `|F|` per iterate, start first.
    pub residuals: Vec<f64>,
    /// Scaled `|F|` per iterate, start first.
    pub scaled_residuals: Vec<f64>,
    /// The objective `J` per iterate, start first (a minimisation only).
    pub objectives: Vec<f64>,
}

impl History {
    fn record(&mut self, it: &Iterate) {
        self.residuals.push(it.residual);
        self.scaled_residuals.push(it.scaled_residual);
        self.objectives.extend(it.objective);
        if it.iteration > 0 {
            self.iterations = it.iteration;
            match it.method {
                NonlinearMethod::Newton => self.newton_iterations += 1,
                NonlinearMethod::PseudoTime => self.pseudo_time_iterations += 1,
            }
        }
    }

    /// `|F|` at the start and at the last iterate (NaN before the first iterate).
    pub(crate) fn residuals_before_after(&self) -> (f64, f64) {
        let at = |r: Option<&f64>| r.copied().unwrap_or(f64::NAN);
        (at(self.residuals.first()), at(self.residuals.last()))
    }
}

/// A solve on a fixed basis in progress; an `Iterator` over its [`Iterate`]s (each one
/// recorded in its [`History`]), finished by [`FixedBasisSolve::finish`].
pub(crate) struct FixedBasisSolve<P: DiscreteProblem = Box<dyn DiscreteProblem + Send>> {
    solver: NonlinearSolver<P>,
    history: History,
    start_objective: Option<f64>,
}

impl<P: DiscreteProblem> std::fmt::Debug for FixedBasisSolve<P> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FixedBasisSolve").field("solver", &self.solver).field("history", &self.history).finish()
    }
}

impl FixedBasisSolve {
    /// `method` on `disc` from the control points `start` (the fixed ones are kept, the
    /// free ones gathered as the first iterate), with the options `nonlinear` as given
    /// (see [`scaled_options`]).
    pub fn new(method: &dyn Method, disc: Arc<Discretization>, start: Vec<Point>, nonlinear: NonlinearOptions) -> Self {
        let c0 = disc.dofs.gather(&start);
        Self::with_problem(method.problem(disc, start), c0, nonlinear)
    }
}

impl<P: DiscreteProblem> FixedBasisSolve<P> {
    /// `problem` from the unknowns `c0`.
    pub(crate) fn with_problem(problem: P, c0: Vec<f64>, nonlinear: NonlinearOptions) -> Self {
        let solver = NonlinearSolver::new(problem, c0, nonlinear);
        let start_objective = solver.objective();
        Self { solver, history: History::default(), start_objective }
    }

    /// The objective `J` at the start (`None` for a root-finding method).
    pub(crate) fn start_objective(&self) -> Option<f64> {
        self.start_objective
    }

    /// The residual `F` of the current iterate.
    pub(crate) fn residual_vector(&self) -> &[f64] {
        self.solver.residual_vector()
    }

    /// `||F||` of the current iterate.
    pub(crate) fn residual(&self) -> f64 {
        self.solver.residual()
    }

    /// The next iterate, recorded; `Ok(None)` once converged or failed.
    pub fn step(&mut self) -> Result<Option<Iterate>> {
        let it = self.solver.step()?;
        if let Some(it) = &it {
            self.history.record(it);
        }
        Ok(it)
    }

    /// Run the remaining iterations.
    pub(crate) fn drain(&mut self) -> Result<()> {
        while self.step()?.is_some() {}
        Ok(())
    }

    /// Run the remaining iterations and take the result back.
    pub fn finish(mut self) -> Result<Solved> {
        self.drain()?;
        let (status, objective, timings) = (self.solver.status().clone(), self.solver.objective(), self.solver.timings);
        let (chord_steps, krylov_iterations) = (self.solver.chord_steps, self.solver.krylov_iterations());
        let (krylov_max, linear_solves) = (self.solver.krylov_max(), self.solver.linear_solves());
        let (problem, c) = self.solver.into_parts();
        Ok(Solved {
            control_points: problem.control_points(&c),
            status,
            history: self.history,
            start_objective: self.start_objective,
            objective,
            timings,
            chord_steps,
            krylov_iterations,
            krylov_max,
            linear_solves,
        })
    }
}

impl<P: DiscreteProblem> Iterator for FixedBasisSolve<P> {
    type Item = Result<Iterate>;
    fn next(&mut self) -> Option<Self::Item> {
        self.step().transpose()
    }
}

/// The result of a [`FixedBasisSolve`].
#[derive(Debug, Clone)]
pub struct Solved {
    /// The control points of the last iterate (the fixed ones as given).
    pub control_points: Vec<Point>,
    /// Converged, or why not.
    pub status: Status,
    /// The iterates.
    pub history: History,
    /// The objective `J` at the start (a minimisation only).
    pub start_objective: Option<f64>,
    /// The objective `J` at the last iterate (a minimisation only).
    pub objective: Option<f64>,
    /// Assembly and linear-algebra time.
    pub timings: Timings,
    /// Chord steps taken ([`NonlinearOptions::chord`]).
    pub chord_steps: usize,
    /// Krylov iterations spent (0 with direct solves).
    pub krylov_iterations: usize,
    /// The most Krylov iterations of one linear solve (0 with direct solves).
    pub krylov_max: usize,
    /// Linear solves (Newton, chord and pseudo-time steps).
    pub linear_solves: usize,
}

impl Solved {
    /// Whether the stopping rule was met.
    pub fn converged(&self) -> bool {
        self.status == Status::Converged
    }

    /// Why the solver gave up, if it did.
    pub fn failure(&self) -> Option<&str> {
        match &self.status {
            Status::Failed(why) => Some(why),
            _ => None,
        }
    }
}
