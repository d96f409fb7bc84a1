//! Nonlinear solvers for `F(c) = 0` as objects that yield their iterates: the damped
//! (truncated) Newton method of paper §6.1 with a backtracking line search on `||F||`,
//! and pseudo time-stepping (§6.2, eq. 30-33) with the SER time-step rule, used
//! automatically when Newton stalls. Because `dF/dc` of eq. (8) is negative definite
//! (L behaves like the Laplacian), the pseudo-time flow is taken as `M dc/dt = F`, the
//! dissipative sign; eq. (28) states it for `G = -L`.
//!
//! The solver reads any [`DiscreteProblem`]: for a minimization method (`F = -∇J`,
//! [`DiscreteProblem::objective`]) the Newton direction solves `-∇²J δ = ∇J` and the line
//! search asks for the Armijo decrease `J(c + t δ) <= J(c) + 10^-4 t ∇J·δ`; convergence
//! is on `|F| = |∇J|` for both kinds, and for a minimization optionally also on a Newton
//! decrement negligible against `|J|` ([`NonlinearOptions::decrement_tol`]). Its Newton matrix is factorized by
//! Cholesky of `∇²J` unless another solver is asked for. A direction that does not descend (`∇J·δ >= 0`,
//! the Hessian is not positive definite along it) is solved again after
//! [`DiscreteProblem::raise_shift`]. Steps outside the feasible set (an objective of
//! `+∞`, or [`DiscreteProblem::admissible`] false) are never accepted.
//!
//! Two accelerations, off by default and on for a local improvement from a bijective
//! start ([`crate::solve::improve`]): a Newton step may be followed by chord steps with
//! the same factorization ([`NonlinearOptions::chord`], Shamanskii's method: one for
//! root finding, up to three for a minimisation), and a minimisation's full step by a
//! longer one along the same direction ([`NonlinearOptions::extrapolate`]).
//!
//! The minimisation's line search and chord steps are in `newton/descent.rs`, pseudo
//! time-stepping in `newton/pseudo_time.rs`.

use std::time::{Duration, Instant};

use serde::Serialize;

use crate::error::Result;
use crate::linalg::krylov::MatVec;
use crate::linalg::linsolve::{LinearMethod, LinearSolver, KRYLOV_TOL};
use crate::methods::DiscreteProblem;

/// The decrement tolerance of a local improvement ([`NonlinearOptions::decrement_tol`]):
/// after a full exact Newton step whose model predicted a decrease below `1e-6 |J|`, the
/// remaining decrease is negligible (on the shared geometries the Winslow value after that
/// step agrees with the minimum to about 1e-9 relative, the control points to about 1e-6
/// of the diameter), which saves one to three of the iterations the gradient test `|∇J|
/// diam <= tol` takes.
pub(crate) const DECREMENT_TOL: f64 = 1e-6;

/// Largest forcing term of the inexact Newton method (see `NonlinearSolver::forcing`).
pub(crate) const ETA_MAX: f64 = 1e-2;

/// Nonlinear iteration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum NonlinearMethod {
    /// Damped Newton with line search (§6.1), falling back to pseudo time on a stall.
    #[default]
    Newton,
    /// Pseudo time-stepping (§6.2) from the start.
    PseudoTime,
}

/// Stopping rules and limits.
#[derive(Debug, Clone, Copy)]
pub struct NonlinearOptions {
    /// Iteration to start with.
    pub method: NonlinearMethod,
    /// Converged when the scaled residual `||F|| * scale` is below this.
    pub tol: f64,
    /// ... or when `||F||` fell below `rtol` times the initial residual.
    pub rtol: f64,
    /// ... or when a full step is shorter than this (absolute, in length units) while the
    /// scaled residual is below `sqrt(tol)`.
    pub step_tol: f64,
    /// Multiplier turning `||F||` into the scaled residual.
    pub scale: f64,
    /// Newton iteration cap.
    pub max_newton: usize,
    /// Pseudo-time iteration cap.
    pub max_pseudo: usize,
    /// Switch to pseudo time when Newton stalls.
    pub fallback: bool,
    /// Linear solver.
    pub linear: LinearMethod,
    /// A minimisation stops after this many consecutive Newton steps whose Hessian had to
    /// be modified ([`DiscreteProblem::raise_shift`]: not positive definite at the
    /// iterate), with the last iterate and the reason: Newton is then far from a
    /// minimiser whose basin it could reach quadratically (a local improvement, §4.1, has
    /// done what it can cheaply). `None`: no limit.
    pub max_modified: Option<usize>,
    /// A minimisation has converged after a full Newton step with the exact Hessian
    /// whose decrement (the decrease its quadratic model predicts) is at most this
    /// fraction of `|J|` (see `DECREMENT_TOL`); 0: off.
    pub decrement_tol: f64,
    /// A root-finding Newton step whose line search fails on a GMRES direction is solved
    /// again once with sparse direct LU (kept for the rest of the solve) before the solver
    /// gives up: an inexact Krylov direction need not descend where GMRES's preconditioner
    /// is poor (cells of aspect ratio ~100). Off by default (EGG falls back to pseudo time
    /// instead); the improvement stage from a bijective start turns it on.
    pub direct_retry: bool,
    /// A full (or extrapolated) root-finding Newton step that does not meet the stopping
    /// rule is followed by one chord step: `F'(c_k) z = -F(c_{k+1})` with the Newton matrix of the
    /// step, still factorized (a back-substitution, or a Krylov solve with the same
    /// preconditioner), and `c_{k+1} + z` replaces `c_{k+1}` when it is admissible and
    /// lowers `|F|` by the Armijo fraction. Newton–chord (Shamanskii's method, Kelley 1995
    /// §5.4.3) converges with order 3 per Jacobian, against 2: from the EGG map the weak
    /// form (eq. 14) needs fewer Jacobians (wavy_lid 6 -> 4), each step one more residual
    /// and solve ([`NonlinearSolver::chord_steps`] counts the chord steps taken). The
    /// stopping rule is unchanged: it is tested on the residual of the iterate kept.
    ///
    /// For a minimisation, a full exact Newton step is followed by up to
    /// [`MAX_DESCENT_CHORDS`] chord steps with the step's Hessian, each kept on an Armijo
    /// decrease of `J` at a feasible point (`NonlinearSolver::descent_chord`); one whose
    /// decrement is below [`CHORD_DECREMENT_FACTOR`] times the decrement rule ends the
    /// iteration. From the EGG map (Winslow, eq. 16) this takes one Newton step (one
    /// Hessian assembly and factorization) fewer on 12 of the 19 shared geometries, with
    /// the same minimum to about `10⁻¹⁰` relative.
    pub chord: bool,
    /// A full Newton step (accepted by the line search) is followed by a trial of a longer
    /// step along the same direction, kept when it is admissible and lower: for a
    /// minimisation, when `J` still falls steeply at the full step, the secant step
    /// [`extrapolated_step`] (on the Winslow functional, eq. 16, from the EGG map the first
    /// Newton steps are too short: `J` falls to 1.3-2 times the full step), for a
    /// root-finding method the minimiser of a quadratic model of `F` along the direction,
    /// `extrapolated_root_step`.
    pub extrapolate: bool,
}

impl Default for NonlinearOptions {
    fn default() -> Self {
        Self {
            method: NonlinearMethod::Newton,
            tol: 1e-9,
            rtol: 1e-13,
            step_tol: 1e-13,
            scale: 1.0,
            max_newton: 30,
            max_pseudo: 400,
            fallback: true,
            linear: LinearMethod::Auto,
            max_modified: None,
            decrement_tol: 0.0,
            direct_retry: false,
            chord: false,
            extrapolate: false,
        }
    }
}

/// One iterate of the stream.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Iterate {
    /// Iteration number (0 is the initial guess).
    pub iteration: usize,
    /// Method that produced it.
    pub method: NonlinearMethod,
    /// `||F||_2`.
    pub residual: f64,
    /// Scaled residual `||F|| * scale` (dimensionless).
    pub scaled_residual: f64,
    /// The objective `J` of a minimization method; `None` for root-finding.
    pub objective: Option<f64>,
    /// Max-norm of the step taken.
    pub step: f64,
    /// Line-search damping `delta` (1 for a full step), eq. (25).
    pub damping: f64,
    /// Pseudo time step, eq. (33).
    pub dt: Option<f64>,
}

/// Where the iteration stands.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// More iterates to come.
    Running,
    /// Stopping rule met.
    Converged,
    /// Gave up, with the reason.
    Failed(String),
}

/// Timings collected by the solver.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Timings {
    /// Residual and Jacobian assembly.
    pub assembly: Duration,
    /// Factorizations and solves.
    pub linear: Duration,
    /// Of `linear`: assembling the preconditioner's SPD approximation and factorizing
    /// (the system matrix, or the preconditioner of a Krylov solve).
    pub factor: Duration,
}

/// An iterative solve in progress; `Iterator` over its [`Iterate`]s.
pub struct NonlinearSolver<P: DiscreteProblem> {
    problem: P,
    opts: NonlinearOptions,
    c: Vec<f64>,
    f: Vec<f64>,
    norm: f64,
    /// `J(c)` of a minimization method.
    objective: Option<f64>,
    r0: f64,
    /// `||F||` before the last Newton step and the forcing term used for it.
    previous: Option<(f64, f64)>,
    iteration: usize,
    newton_its: usize,
    /// Consecutive Newton steps of a minimisation whose Hessian had to be modified.
    modified: usize,
    pseudo_its: usize,
    method: NonlinearMethod,
    dt: f64,
    lin: LinearSolver,
    /// The last Newton matrix is the problem's Jacobian operator
    /// ([`DiscreteProblem::jacobian_operator`]), not a matrix in `lin`.
    operator: bool,
    status: Status,
    started: bool,
    /// Chord steps taken ([`NonlinearOptions::chord`]).
    pub chord_steps: usize,
    /// Timings so far.
    pub timings: Timings,
}

impl<P: DiscreteProblem> std::fmt::Debug for NonlinearSolver<P> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NonlinearSolver").field("iteration", &self.iteration).field("status", &self.status).finish()
    }
}

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl<P: DiscreteProblem> NonlinearSolver<P> {
    /// Start from `c0`.
    pub fn new(mut problem: P, c0: Vec<f64>, opts: NonlinearOptions) -> Self {
        let mut f = vec![0.0; problem.size()];
        let t = Instant::now();
        // the objective first: a problem may compute the gradient with it (the Winslow
        // functional, in one pass) and read it for the residual
        let objective = problem.objective(&c0);
        problem.residual(&c0, &mut f);
        let assembly = t.elapsed();
        let norm = norm2(&f);
        // a minimisation's Newton matrix is -∇²J: Cholesky of ∇²J (which fails exactly
        // when the Hessian is not positive definite, see `newton_step`) unless the caller
        // chose a solver
        let linear = match (objective, opts.linear) {
            (Some(_), LinearMethod::Auto) => LinearMethod::NegCholesky,
            (_, m) => m,
        };
        let mut lin = LinearSolver::new(linear);
        if let Some(order) = problem.ordering() {
            lin.set_ordering(order);
        }
        if linear == LinearMethod::Multigrid {
            lin.set_transfers(problem.transfers());
            lin.set_cycle_backend(problem.cycle_backend());
        }
        Self {
            problem,
            opts,
            c: c0,
            f,
            norm,
            objective,
            r0: norm,
            previous: None,
            iteration: 0,
            newton_its: 0,
            modified: 0,
            pseudo_its: 0,
            method: opts.method,
            dt: 0.0,
            lin,
            operator: false,
            status: Status::Running,
            started: false,
            chord_steps: 0,
            timings: Timings { assembly, linear: Duration::ZERO, factor: Duration::ZERO },
        }
    }

    /// Current status.
    pub fn status(&self) -> &Status {
        &self.status
    }

    /// Current unknowns.
    pub fn solution(&self) -> &[f64] {
        &self.c
    }

    /// Krylov (GMRES) iterations spent so far; 0 with direct solves.
    pub fn krylov_iterations(&self) -> usize {
        self.lin.krylov_iterations
    }

    /// The most Krylov iterations one linear solve took so far; 0 with direct solves.
    pub fn krylov_max(&self) -> usize {
        self.lin.krylov_max
    }

    /// Linear solves so far (Newton and chord steps, pseudo-time steps).
    pub fn linear_solves(&self) -> usize {
        self.lin.solves
    }

    /// The current objective `J` of a minimization method (`None` for root-finding).
    pub fn objective(&self) -> Option<f64> {
        self.objective
    }

    /// The residual `F` of the current iterate.
    pub(crate) fn residual_vector(&self) -> &[f64] {
        &self.f
    }

    /// Current `||F||`.
    pub fn residual(&self) -> f64 {
        self.norm
    }

    /// The problem (e.g. to read the control points back).
    pub fn problem(&self) -> &P {
        &self.problem
    }

    /// Consume, returning the problem and the unknowns.
    pub fn into_parts(self) -> (P, Vec<f64>) {
        (self.problem, self.c)
    }

    fn scaled(&self) -> f64 {
        self.norm * self.opts.scale
    }

    fn converged(&self, step: f64) -> bool {
        let s = self.scaled();
        s <= self.opts.tol
            || self.norm <= self.opts.rtol * self.r0
            || (step <= self.opts.step_tol && s <= self.opts.tol.sqrt())
    }

    fn iterate(&self, step: f64, damping: f64) -> Iterate {
        Iterate {
            iteration: self.iteration,
            method: self.method,
            residual: self.norm,
            scaled_residual: self.scaled(),
            objective: self.objective,
            step,
            damping,
            dt: (self.method == NonlinearMethod::PseudoTime).then_some(self.dt),
        }
    }

    /// Advance by one iteration; `Ok(None)` once converged or failed.
    pub fn step(&mut self) -> Result<Option<Iterate>> {
        if !self.started {
            self.started = true;
            if !self.norm.is_finite() {
                self.status = Status::Failed("non-finite initial residual".into());
            } else if self.objective.is_some_and(|j| !j.is_finite()) || !self.problem.admissible(&self.c) {
                self.status = Status::Failed("the start is outside the feasible set of the method".into());
            } else if self.converged(f64::INFINITY) {
                self.status = Status::Converged;
            }
            return Ok(Some(self.iterate(0.0, 1.0)));
        }
        if self.status != Status::Running {
            return Ok(None);
        }
        let it = match self.method {
            NonlinearMethod::Newton => self.newton_step()?,
            NonlinearMethod::PseudoTime => self.pseudo_step()?,
        };
        Ok(Some(it))
    }

    fn linear_step(&mut self, shift: Option<f64>) -> Result<Vec<f64>> {
        let n = self.c.len();
        // a multigrid V-cycle due for a new set-up is set up first, from `K` as a grid
        // stencil where the problem has one: the set-up's transient storage (`K` in
        // `f64`, the first coarse operator) and the Jacobian then never coexist
        let early = shift.is_none() && self.lin.method() == LinearMethod::Multigrid && self.lin.wants_preconditioner(n);
        let t = Instant::now();
        if early {
            self.lin.release_multigrid();
            if let Some(k) = self.problem.take_preconditioner_grid(0.0) {
                self.lin.factor_operator_grid(n, k)?;
            }
            crate::solve::memory::trace(|| format!("newton ({n} unknowns): preconditioner set up before the Jacobian"));
        }
        let early_s = t.elapsed();
        self.timings.factor += early_s;
        self.timings.linear += early_s;
        let t = Instant::now();
        let mut f = std::mem::take(&mut self.f);
        // with the multigrid preconditioner GMRES multiplies with the problem's Jacobian
        // operator (the stencil product: no matrix at all) ...
        self.operator = shift.is_none()
            && self.lin.method() == LinearMethod::Multigrid
            && self.problem.jacobian_operator(&self.c, &mut f);
        if !self.operator {
            // ... otherwise the problem writes the Jacobian straight into the linear
            // solver's matrix: no allocation and no copy per step (the pattern is written
            // on the first step only)
            self.problem.jacobian(&self.c, &mut f, self.lin.matrix_mut());
        }
        self.f = f;
        self.timings.assembly += t.elapsed();
        crate::solve::memory::trace(|| format!("newton ({n} unknowns): Jacobian assembled"));
        if let Some(dt) = shift {
            // F_i = int w_i L(x) and L is elliptic (like the Laplacian), so dF/dc is
            // negative definite near a solution; the dissipative pseudo-transient
            // form of eq. (30)-(32) is therefore M dc/dt = +F, i.e.
            // [M / dt - dF/dc] dc = F, written as [-(M / dt) + dF/dc] dc = -F.
            let m = self.problem.mass();
            for (v, mv) in self.lin.matrix_mut().values.iter_mut().zip(&m.values) {
                *v -= mv / dt;
            }
        }
        let t = Instant::now();
        self.lin.krylov_tol = if shift.is_some() { KRYLOV_TOL } else { self.forcing() };
        // the pseudo-time shift changes with every step: no frozen preconditioner then
        let refresh = shift.is_some() || self.lin.wants_preconditioner(n);
        if self.operator {
            // the V-cycle keeps the problem's `K` (no copy on either side), the old one
            // freed before the new one is built
            let k = refresh.then(|| self.lin.release_multigrid()).and_then(|()| self.problem.take_preconditioner(0.0));
            self.lin.factor_operator_owned(n, k)?;
        } else {
            let k = if refresh { self.problem.preconditioner(shift.map_or(0.0, |dt| 1.0 / dt)) } else { None };
            self.lin.factor_stored(k)?;
        }
        self.timings.factor += t.elapsed();
        crate::solve::memory::trace(|| format!("newton ({n} unknowns): preconditioner set up"));
        let rhs: Vec<f64> = self.f.iter().map(|v| -v).collect();
        let dx = self.newton_solve(&rhs);
        self.timings.linear += t.elapsed();
        crate::solve::memory::trace(|| format!("newton ({n} unknowns): linear solve"));
        dx
    }

    /// `x` of `F'(c) x = b` with the Newton matrix of the last [`Self::linear_step`] (the
    /// stored factorization or preconditioner, the matrix or the problem's Jacobian
    /// operator) and the problem's rank-one term.
    fn newton_solve(&mut self, b: &[f64]) -> Result<Vec<f64>> {
        let (lin, problem, operator) = (&mut self.lin, &self.problem, self.operator);
        let mut solve = |b: &[f64]| match operator {
            true => lin.solve_operator(&JacobianProduct(problem), b),
            false => lin.solve(b),
        };
        match (solve(b), problem.rank_one()) {
            (Ok(x), Some((sigma, u))) => sherman_morrison(solve, x, sigma, u),
            (x, _) => x,
        }
    }

    /// Forcing term `eta_k` of the inexact Newton method, the relative residual at which
    /// the Krylov solver stops: Eisenstat & Walker's choice 2, `eta_k = 0.9 (|F_k| /
    /// |F_{k-1}|)^2`, safeguarded by `0.9 eta_{k-1}^2` when that exceeds 0.1, within
    /// `[KRYLOV_TOL, ETA_MAX]`, and never tighter than needed to reach the tolerance:
    /// the step leaves `|F_{k+1}| ~ eta_k |F_k|`, so `eta_k >= tol / (2 |F_k|)` (scaled)
    /// suffices. Keeps the quadratic convergence of Newton's method while the first
    /// steps and the last one need few Krylov iterations. A first step from a start
    /// within `sqrt(tol)` (scaled; an extrapolated prediction, a prolonged solution) is
    /// in the quadratic regime, where the step's own error `O(|F|^2)` is below the
    /// tolerance: it is solved to `tol / (2 |F_0|)` so that one step suffices.
    fn forcing(&self) -> f64 {
        let enough = 0.5 * self.opts.tol / self.scaled().max(f64::MIN_POSITIVE);
        let eta = match self.previous {
            None if self.scaled() <= self.opts.tol.sqrt() => enough,
            None => ETA_MAX,
            Some((norm, eta)) => {
                let ew = 0.9 * (self.norm / norm).powi(2);
                let safeguard = 0.9 * eta * eta;
                if safeguard > 0.1 {
                    ew.max(safeguard)
                } else {
                    ew
                }
            }
        };
        eta.min(ETA_MAX).max(enough).clamp(KRYLOV_TOL, ETA_MAX)
    }

    fn eval(&mut self, c: &[f64], f: &mut [f64]) -> f64 {
        let t = Instant::now();
        self.problem.residual(c, f);
        self.timings.assembly += t.elapsed();
        norm2(f)
    }

    fn newton_step(&mut self) -> Result<Iterate> {
        self.iteration += 1;
        self.newton_its += 1;
        // a minimization method whose Hessian is not positive definite (its Cholesky
        // factorization fails) or not along dx (the direction does not descend): shift
        // the Hessian and solve again
        let minimizes = self.objective.is_some();
        let mut modified = false;
        let dx = loop {
            match self.linear_step(None) {
                Ok(dx) => {
                    let descends = self.f.iter().zip(&dx).map(|(f, d)| f * d).sum::<f64>() > 0.0;
                    if !minimizes || descends || !self.problem.raise_shift() {
                        break dx;
                    }
                }
                Err(e) => {
                    if !(minimizes && self.problem.raise_shift()) {
                        return Ok(self.stall(format!("Newton linear solve failed: {e}")));
                    }
                }
            }
            modified = true;
        };
        let modified = modified || self.problem.modified();
        self.modified = if modified { self.modified + 1 } else { 0 };
        self.previous = Some((self.norm, self.lin.krylov_tol));
        if let Some(j0) = self.objective {
            return Ok(self.descent_step(j0, &dx, !modified));
        }
        // Backtracking on phi = ||F||^2 / 2 with Armijo constant 1e-4; the slope along
        // the Newton direction is -||F||^2.
        let phi0 = 0.5 * self.norm * self.norm;
        let mut delta = 1.0;
        let mut trial = vec![0.0; self.c.len()];
        let mut ft = vec![0.0; self.c.len()];
        loop {
            for ((t, c), d) in trial.iter_mut().zip(&self.c).zip(&dx) {
                *t = c + delta * d;
            }
            let nt = if self.problem.admissible(&trial) { self.eval(&trial, &mut ft) } else { f64::NAN };
            let phi = 0.5 * nt * nt;
            if nt.is_finite() && phi <= phi0 * (1.0 - 2e-4 * delta) {
                let (mut delta, mut nt) = (delta, nt);
                if let Some(t) = extrapolated_root_step(&self.f, &ft).filter(|_| self.opts.extrapolate && delta == 1.0)
                {
                    let longer: Vec<f64> = self.c.iter().zip(&dx).map(|(c, d)| c + t * d).collect();
                    let mut fl = vec![0.0; self.c.len()];
                    let nl = if self.problem.admissible(&longer) { self.eval(&longer, &mut fl) } else { f64::NAN };
                    if nl < nt {
                        (trial, ft, delta, nt) = (longer, fl, t, nl);
                    }
                }
                let step = dx.iter().fold(0.0f64, |m, d| m.max((delta * d).abs()));
                std::mem::swap(&mut self.c, &mut trial);
                std::mem::swap(&mut self.f, &mut ft);
                self.norm = nt;
                let step = match self.opts.chord && delta >= 1.0 && !self.converged(step) {
                    true => self.chord_step().unwrap_or(step),
                    false => step,
                };
                if self.converged(step) {
                    self.status = Status::Converged;
                } else if self.newton_its >= self.opts.max_newton {
                    return Ok(self.stall_with(
                        format!("Newton reached {} iterations", self.opts.max_newton),
                        step,
                        delta,
                    ));
                }
                return Ok(self.iterate(step, delta));
            }
            // minimiser of the quadratic through phi0, slope -2 phi0 and phi(delta)
            let q = if nt.is_finite() {
                2.0 * phi0 * delta * delta / (2.0 * (phi - phi0 + 2.0 * phi0 * delta))
            } else {
                0.1 * delta
            };
            delta = q.clamp(0.1 * delta, 0.5 * delta);
            if delta < 1e-4 {
                if self.opts.direct_retry && self.lin.method() == LinearMethod::Gmres {
                    // the GMRES direction does not descend: this step again, solved directly
                    self.lin = LinearSolver::new(LinearMethod::Lu);
                    self.iteration -= 1;
                    self.newton_its -= 1;
                    return self.newton_step();
                }
                return Ok(self.stall("line search failed (no descent along the Newton direction)".into()));
            }
        }
    }

    /// `z` of `F'(c_prev) z = -F(c)` with the factorization of the last Newton step (and
    /// its rank-one term): the direction of a chord step; `None` when the solve fails.
    fn chord_direction(&mut self) -> Option<Vec<f64>> {
        let t = Instant::now();
        let rhs: Vec<f64> = self.f.iter().map(|v| -v).collect();
        let dz = self.newton_solve(&rhs);
        self.timings.linear += t.elapsed();
        dz.ok()
    }

    /// One chord step from the accepted iterate ([`NonlinearOptions::chord`]): `z` from
    /// `F'(c_prev) z = -F(c)` with the factorization of the last Newton step (and its
    /// rank-one term), kept when `c + z` is admissible and `|F(c + z)| <= (1 - 10^-4)
    /// |F(c)|`; the length `max |z_i|` of a kept step, `None` otherwise.
    fn chord_step(&mut self) -> Option<f64> {
        let dz = self.chord_direction()?;
        let z: Vec<f64> = self.c.iter().zip(&dz).map(|(c, d)| c + d).collect();
        if !self.problem.admissible(&z) {
            return None;
        }
        let mut fz = vec![0.0; self.c.len()];
        let nz = self.eval(&z, &mut fz);
        if !(nz.is_finite() && nz <= (1.0 - 1e-4) * self.norm) {
            return None;
        }
        self.c = z;
        self.f = fz;
        self.norm = nz;
        self.chord_steps += 1;
        Some(dz.iter().fold(0.0f64, |m, d| m.max(d.abs())))
    }

    fn stall(&mut self, why: String) -> Iterate {
        self.stall_with(why, 0.0, 0.0)
    }

    fn stall_with(&mut self, why: String, step: f64, damping: f64) -> Iterate {
        let it = self.iterate(step, damping);
        if self.opts.fallback && self.method == NonlinearMethod::Newton {
            self.method = NonlinearMethod::PseudoTime;
            self.dt = 0.0;
        } else {
            self.status = Status::Failed(why);
        }
        it
    }
}

/// The step factor `t > 1` along a Newton direction `δ` (`F'(c) δ = -F₀`) at which the
/// quadratic model of the residual through `F₀ = F(c)`, its derivative `-F₀` and the
/// residual `F₁ = F(c + δ)` of the full step, `F(c + t δ) ≈ (1 - t) F₀ + t² F₁`, has the
/// smallest norm: `|(1 - t) F₀ + t² F₁|² = A (1 - t)² + 2 B (1 - t) t² + C t⁴` (`A =
/// |F₀|²`, `B = F₀·F₁`, `C = |F₁|²`) minimised over `[1, EXTRAPOLATE_MAX]` on a grid of
/// `0.05`; proposed when `t >= 1.1` and the model's norm² is below `0.9 C`. Outside the
/// quadratic regime only (`|F₁| > |F₀| / 4`): `None` there.
pub(crate) fn extrapolated_root_step(f0: &[f64], f1: &[f64]) -> Option<f64> {
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
    let (a, b, c) = (dot(f0, f0), dot(f0, f1), dot(f1, f1));
    if !(a > 0.0 && c.is_finite() && c > 0.0625 * a) {
        return None;
    }
    let model = |t: f64| a * (1.0 - t) * (1.0 - t) + 2.0 * b * (1.0 - t) * t * t + c * t * t * t * t;
    let (t, m) = (20..=(20.0 * EXTRAPOLATE_MAX) as usize)
        .map(|k| k as f64 / 20.0)
        .map(|t| (t, model(t)))
        .fold((1.0, c), |best, x| if x.1 < best.1 { x } else { best });
    (t >= 1.1 && m < 0.9 * c).then_some(t)
}

/// Longest step factor [`extrapolated_step`] and [`extrapolated_root_step`] propose.
pub(crate) const EXTRAPOLATE_MAX: f64 = 3.0;

/// The Jacobian operator of a problem ([`DiscreteProblem::jacobian_product`]) for the
/// Krylov methods.
struct JacobianProduct<'a, P>(&'a P);

impl<P: DiscreteProblem> MatVec for JacobianProduct<'_, P> {
    fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        self.0.jacobian_product(x, y);
    }
}

/// `(A + σ u uᵀ)⁻¹ b` from `x = A⁻¹ b` and `solve`, which applies `A⁻¹` (the rank-one
/// term of [`DiscreteProblem::rank_one`]): `x − σ (uᵀx) / (1 + σ uᵀz) z` with `z = A⁻¹
/// u` (Sherman-Morrison); an error when `1 + σ uᵀz` vanishes (the updated matrix is
/// singular).
fn sherman_morrison(
    mut solve: impl FnMut(&[f64]) -> Result<Vec<f64>>,
    x: Vec<f64>,
    sigma: f64,
    u: &[f64],
) -> Result<Vec<f64>> {
    let z = solve(u)?;
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
    let (uz, ux) = (sigma * dot(u, &z), sigma * dot(u, &x));
    let denom = 1.0 + uz;
    if !denom.is_finite() || denom.abs() <= 1e-12 * (1.0 + uz.abs()) {
        return Err(crate::error::Error::LinearSolver("singular rank-one update (Sherman-Morrison)".into()));
    }
    let t = ux / denom;
    Ok(x.iter().zip(&z).map(|(xi, zi)| xi - t * zi).collect())
}

impl<P: DiscreteProblem> Iterator for NonlinearSolver<P> {
    type Item = Result<Iterate>;
    fn next(&mut self) -> Option<Self::Item> {
        self.step().transpose()
    }
}

mod descent;
mod pseudo_time;

pub use descent::{extrapolated_step, CHORD_DECREMENT_FACTOR, MAX_DESCENT_CHORDS};

#[cfg(test)]
mod tests;
