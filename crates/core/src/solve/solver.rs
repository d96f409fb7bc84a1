//! The coarse-to-fine solver (paper §6.3) as an object that yields its iterates: level
//! starts, nonlinear iterates and level summaries come out of one stream that the CLI
//! progress, the viewer's live plot and the tests all read.
//!
//! The solver talks to the discrete problem only through [`Method`] and
//! [`DiscreteProblem`](crate::methods::DiscreteProblem): EGG (eq. 8) by default, any
//! other method through `EggSolver::with_method`. The patch's boundary conditions are
//! data ([`SolveOptions::topology`]), read by the DOF map of every level.

use std::sync::Arc;
use std::time::Instant;

use super::fixed_basis::{bijective, scaled_options, FixedBasisSolve};
use super::graded::{graded_level, GRADED_MIN_RESIDUAL};
use super::improve::{improve, Improvement};
use super::initial::{continuation_with, coons, det_j_min, set_boundary, Continuation};
use super::kinks::{keep_kinks, kink_reports, KinkStage};
use super::levels::{graded_at_roundings, prepare_levels, select_levels, DIRECT_REFINED_MAX_FUNCTIONS};
use super::memory::{auto_linear, trace, MemoryEstimate};
use super::newton::{Iterate, NonlinearOptions};
use super::options::{Refinement, SolveOptions};
use super::repair::{frozen_discretization, plan_repair, RepairRound};
use super::report::{InitialGuess, LevelReport, ReportContext, Solution};
use crate::boundary::hierarchy::{Hierarchy, Level};
use crate::boundary::kinks::smoothed_levels;
use crate::boundary::normalise::Similarity;
use crate::boundary::BasisChoice;
use crate::boundary::Boundary;
use crate::discrete::assembly::Discretization;
use crate::discrete::topology::Topology;
use crate::error::{Error, Result};
use crate::linalg::linsolve::LinearMethod;
use crate::methods::egg::{EggAssembler, EggMethod};
use crate::methods::{Method, Start};
use crate::spline::surface::{Side, Surface};
use crate::verify::certificate::{certify, Certificate};
use crate::verify::quality::boundary_deviation;

/// One item of the solver's stream.
#[derive(Debug, Clone)]
pub enum Event {
    /// A level begins.
    LevelStarted {
        /// Index among the solved levels.
        level: usize,
        /// Number of levels that will be solved.
        levels: usize,
        /// Basis shape.
        shape: [usize; 2],
        /// Scalar unknowns.
        unknowns: usize,
        /// Initial guess.
        initial_guess: InitialGuess,
    },
    /// A nonlinear iterate.
    Iterate {
        /// Level index.
        level: usize,
        /// The iterate.
        iterate: Iterate,
    },
    /// A level is done.
    LevelFinished(LevelReport),
}

struct Active {
    level: usize,
    solver: FixedBasisSolve,
    report: LevelReport,
    started: Instant,
    /// The level's rational weights ([`Level::weights`]), `None` when polynomial.
    weights: Option<Vec<f64>>,
}

/// The coarse-to-fine solver; an `Iterator` over [`Event`]s. Drop it to cancel.
pub struct EggSolver {
    plan: Vec<Level>,
    opts: SolveOptions,
    /// The discrete problem on every level.
    method: Arc<dyn Method>,
    /// Quadrature back end of the hierarchy's operators (elasticity, mass, `det J`
    /// samples).
    assembler: Arc<dyn EggAssembler>,
    diameter: f64,
    /// The input's coordinates from the normalised ones the solve runs in: the
    /// certificates judge the map as it will be written.
    sim: Similarity,
    next_level: usize,
    active: Option<Active>,
    previous: Option<Surface>,
    reports: Vec<LevelReport>,
    started: Instant,
    failed: bool,
    repairs: usize,
    rounds: Vec<RepairRound>,
    /// Certificate of the last solved map (the finest level so far).
    certificate: Option<Certificate>,
    /// For repair levels solved with frozen DOFs: plan index and the parameter boxes
    /// `[u0, u1, v0, v1]` whose control points stay free.
    free_boxes: Vec<(usize, Vec<[f64; 4]>)>,
    /// With kinks kept (§9): the finest `C^0` level `Σ⁰` (balanced and refined like the
    /// plan, whose levels are its smoothing `Σ¹`).
    c0: Option<Level>,
    /// The boundary solved (a ring's cut at its seam), in the input's coordinates: the
    /// report measures the map against it.
    boundary: Boundary,
    /// The hierarchy the plan was made from: its similarity, kinks and basis report.
    hierarchy: Arc<Hierarchy>,
    /// The memory limit (`opts.max_memory` resolved when the solver was made), bytes:
    /// `--linear auto` solves a level whose direct preconditioner would not fit with
    /// multigrid ([`auto_linear`]).
    memory_limit: Option<u64>,
    /// A [`graded_level`] was put before the finest level.
    graded: bool,
}

impl std::fmt::Debug for EggSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EggSolver").field("levels", &self.plan.len()).field("next_level", &self.next_level).finish()
    }
}

impl EggSolver {
    /// A solver of EGG (eq. 8, `opts.operator`) over the levels of `hierarchy` (the fit of
    /// `boundary`, extended and selected by `opts`), assembled on `assembler`.
    pub fn new(
        boundary: &Boundary,
        hierarchy: Arc<Hierarchy>,
        opts: SolveOptions,
        assembler: Arc<dyn EggAssembler>,
    ) -> Result<Self> {
        let method = Arc::new(EggMethod { operator: opts.operator, assembler: assembler.clone() });
        Self::with_method(boundary, hierarchy, opts, assembler, method)
    }

    /// A solver of `method` over the levels of `hierarchy` (the fit of `boundary`);
    /// `assembler` assembles the hierarchy's operators (elasticity, continuation samples).
    pub(crate) fn with_method(
        boundary: &Boundary,
        hierarchy: Arc<Hierarchy>,
        opts: SolveOptions,
        assembler: Arc<dyn EggAssembler>,
        method: Arc<dyn Method>,
    ) -> Result<Self> {
        opts.topology.validate(None)?;
        // `--basis input` is solved as given (only `refine` halves it): no balancing and
        // no minimum element count, which would change the basis the user chose; `auto`
        // balances the input basis as it does fitted ones, by exact knot insertion, so the
        // boundary stays the input's
        let (min_elements, aspect) = match (hierarchy.basis.requested, hierarchy.basis.used) {
            (BasisChoice::Input, BasisChoice::Input) => (1, f64::INFINITY),
            _ => (opts.levels.min_elements, opts.levels.aspect),
        };
        let mut levels = prepare_levels(hierarchy.levels.clone(), min_elements, opts.levels.refine, aspect)?;
        // rounded point-cloud corners: the finest level graded towards their sides, and
        // `Refinement::Auto` is THB
        let mut opts = opts;
        opts.repair.refinement = opts.repair.refinement.resolved(!hierarchy.roundings.is_empty());
        if let Some(last) = levels.last_mut().filter(|_| !hierarchy.roundings.is_empty()) {
            *last = graded_at_roundings(last, &hierarchy.roundings, hierarchy.diameter)?;
        }
        // kinks kept (§9): the levels hold them at multiplicity p (Σ⁰); solve on Σ¹, the
        // finest prepared Σ⁰ is where the C0 route ends
        let (levels, c0) = match hierarchy.kinked {
            Some(_) => (smoothed_levels(&levels)?, levels.last().cloned()),
            None => (levels, None),
        };
        let sizes: Vec<usize> = levels.iter().map(|l| l.num_basis()).collect();
        // a tiny input basis refined (`refine`) is solved directly from the Coons patch
        let direct_max = match hierarchy.basis.used {
            BasisChoice::Input => DIRECT_REFINED_MAX_FUNCTIONS,
            BasisChoice::Fitted | BasisChoice::Auto => 0,
        };
        let chosen = select_levels(&sizes, opts.levels.growth, opts.levels.max_levels, direct_max);
        let plan = chosen.into_iter().map(|k| levels[k].clone()).collect();
        let memory_limit = opts.max_memory.resolve().map(|(bytes, _)| bytes);
        Ok(Self {
            plan,
            opts,
            method,
            assembler,
            diameter: hierarchy.diameter,
            sim: hierarchy.similarity,
            next_level: 0,
            active: None,
            previous: None,
            reports: Vec::new(),
            started: Instant::now(),
            failed: false,
            repairs: 0,
            rounds: Vec::new(),
            certificate: None,
            free_boxes: Vec::new(),
            c0,
            boundary: boundary.clone(),
            hierarchy,
            memory_limit,
            graded: false,
        })
    }

    /// The levels that will be solved.
    pub fn plan(&self) -> &[Level] {
        &self.plan
    }

    /// The method solved on every level.
    pub fn method(&self) -> &dyn Method {
        &*self.method
    }

    /// Nonlinear options of a level with `m` free functions whose Newton systems are
    /// solved by `linear`: the residual made dimensionless (`F_i = ∫ w_i L` with `∫ w_i ~
    /// 1/m`, so `||F|| sqrt(m)` divided by [`Method::residual_size`] is the relative
    /// residual) and the step tolerance in length units.
    fn level_options(&self, m: usize, linear: LinearMethod) -> NonlinearOptions {
        let mut nl = scaled_options(self.opts.nonlinear, &*self.method, self.diameter, m);
        nl.linear = linear;
        nl
    }

    /// The linear solver of a level with basis `knots` and DOF map `interior` (every
    /// boundary function fixed, the multigrid hierarchy's condition): `--linear auto`
    /// resolved by [`auto_linear`] for EGG (multigrid on large levels and on those whose
    /// direct preconditioner would not fit in the memory limit), the option as given
    /// otherwise.
    fn linear_for(&self, knots: &[crate::spline::knots::KnotVector; 2], interior: bool) -> LinearMethod {
        let requested = self.opts.nonlinear.linear;
        if !interior || !self.method.multigrid() {
            return requested;
        }
        auto_linear(knots, requested, self.memory_limit)
    }

    /// The estimated peak of the solve ([`MemoryEstimate`]): the largest of its levels',
    /// each with the linear solver it will use ([`EggSolver::linear_for`]).
    pub(crate) fn estimate(&self) -> MemoryEstimate {
        let plain = self.opts.topology == Topology::dirichlet();
        let level = |l: &Level| MemoryEstimate::for_knots_with(&l.knots, self.linear_for(&l.knots, plain));
        self.plan.iter().map(level).max_by_key(|e| e.bytes).unwrap_or(MemoryEstimate {
            functions: 0,
            unknowns: 0,
            nonzeros: 0,
            bytes: super::memory::BASE,
        })
    }

    /// A method that needs a bijective start gets one the certificate proves (or one
    /// positive away from corners the boundary forces to `det J <= 0`).
    fn check_start(
        &self,
        level: &Level,
        weights: &Option<Vec<f64>>,
        cps: &[crate::spline::curve::Point],
    ) -> Result<()> {
        if self.method.start() != Start::Bijective {
            return Ok(());
        }
        let map = Surface { knots: level.knots.clone(), control_points: cps.to_vec(), weights: weights.clone() };
        let cert = certify(&map, &self.opts.certify)?;
        if !bijective(&cert) {
            return Err(Error::InfeasibleStart { method: self.method.name().into(), reason: cert.message() });
        }
        Ok(())
    }

    fn start_level(&mut self, k: usize) -> Result<Event> {
        let t0 = Instant::now();
        let level = &self.plan[k];
        let interior = self.opts.topology == Topology::dirichlet() && !self.free_boxes.iter().any(|(i, _)| *i == k);
        let linear = self.linear_for(&level.knots, interior);
        // the level's estimated peak reserved and released: a limit the pipeline's check
        // did not see (an address-space limit) is a typed error here, not an abort later
        crate::solve::memory::reserve(
            MemoryEstimate::for_knots_with(&level.knots, linear).bytes,
            &format!("level {k} ({} x {} functions)", level.knots[0].dim(), level.knots[1].dim()),
        )?;
        trace(|| format!("level {k}: start ({linear:?})"));
        let topology = &self.opts.topology;
        let weights = level.weights()?;
        let disc = Arc::new(
            match self.free_boxes.iter().find(|(i, _)| *i == k) {
                Some((_, boxes)) => frozen_discretization(&level.knots, boxes, topology)?,
                None => Discretization::for_topology(level.knots.clone(), topology)?,
            }
            .with_weights(weights.clone())?,
        );
        let mut cont = Continuation::default();
        let (cps, guess) = match &self.previous {
            None => (coons(&level.knots, &level.sides)?, InitialGuess::Coons),
            Some(prev) => {
                let fine = prev.refined(&level.knots)?.control_points;
                let mut target = fine.clone();
                set_boundary(disc.shape(), &level.sides, &mut target)?;
                let nl = self.level_options(disc.dofs.num_free(), linear);
                let (method, assembler) = (&*self.method, &*self.assembler);
                let positive = |c: &[crate::spline::curve::Point]| det_j_min(assembler, &disc, c) > 0.0;
                let out =
                    continuation_with(method, assembler, &disc, fine, &target, nl, self.diameter, &mut cont, &positive);
                let cps = out?.guess;
                (cps, InitialGuess::Elasticity)
            }
        };
        let shape = disc.shape();
        let initial_det_j_min = det_j_min(&*self.assembler, &disc, &cps);
        self.check_start(level, &weights, &cps)?;
        let m = disc.dofs.num_free();
        trace(|| format!("level {k}: initial guess"));
        let dofs = disc.dofs.clone();
        let nl = self.level_options(m, linear);
        let solver = FixedBasisSolve::new(&*self.method, disc, cps, nl);
        if self.grades(k, linear) && solver.residual() * nl.scale > GRADED_MIN_RESIDUAL {
            if let Some(g) = graded_level(&self.plan[k - 1], &self.plan[k], &dofs, solver.residual_vector())? {
                trace(|| {
                    format!("level {k}: graded level of {} x {} functions first", g.knots[0].dim(), g.knots[1].dim())
                });
                drop(solver);
                self.graded = true;
                self.plan.insert(k, g);
                return self.start_level(k);
            }
        }
        let report = LevelReport {
            level: k,
            shape,
            elements: [level.knots[0].num_elements(), level.knots[1].num_elements()],
            unknowns: 2 * m,
            initial_guess: guess,
            graded: self.graded && k + 2 == self.plan.len(),
            initial_det_j_min,
            continuation_steps: cont.steps,
            continuation_iterations: cont.iterations,
            iterations: 0,
            newton_iterations: 0,
            pseudo_time_iterations: 0,
            converged: false,
            failure: None,
            residuals: Vec::new(),
            scaled_residuals: Vec::new(),
            assembly_seconds: 0.0,
            linear_seconds: 0.0,
            factor_seconds: 0.0,
            krylov_iterations: 0,
            krylov_max: 0,
            linear_solves: 0,
            seconds: 0.0,
        };
        self.active = Some(Active { level: k, solver, report, started: t0, weights });
        Ok(Event::LevelStarted { level: k, levels: self.plan.len(), shape, unknowns: 2 * m, initial_guess: guess })
    }

    /// Whether level `k` of the plan, solved by `linear`, is first preceded by a
    /// [`graded_level`]: the finest level (no defect correction yet) solved by multigrid
    /// from a solved level below, once per solve.
    fn grades(&self, k: usize, linear: LinearMethod) -> bool {
        !self.graded
            && k > 0
            && k + 1 == self.plan.len()
            && self.repairs == 0
            && linear == LinearMethod::Multigrid
            && self.previous.is_some()
    }

    fn finish_level(&mut self) -> Result<Event> {
        let mut a = self.active.take().expect("active level");
        let solved = a.solver.finish()?;
        (a.report.converged, a.report.failure) = (solved.converged(), solved.failure().map(str::to_string));
        let h = solved.history;
        (a.report.iterations, a.report.newton_iterations) = (h.iterations, h.newton_iterations);
        a.report.pseudo_time_iterations = h.pseudo_time_iterations;
        (a.report.residuals, a.report.scaled_residuals) = (h.residuals, h.scaled_residuals);
        a.report.assembly_seconds = solved.timings.assembly.as_secs_f64();
        a.report.linear_seconds = solved.timings.linear.as_secs_f64();
        a.report.factor_seconds = solved.timings.factor.as_secs_f64();
        a.report.krylov_iterations = solved.krylov_iterations;
        (a.report.krylov_max, a.report.linear_solves) = (solved.krylov_max, solved.linear_solves);
        a.report.seconds = a.started.elapsed().as_secs_f64();
        let knots = self.plan[a.level].knots.clone();
        self.previous = Some(Surface { knots, control_points: solved.control_points, weights: a.weights });
        self.reports.push(a.report.clone());
        trace(|| format!("level {}: solved", a.level));
        Ok(Event::LevelFinished(a.report))
    }

    /// Finish: the map of the finest level and the full report, in the input's
    /// coordinates (the solve ran in the normalised ones of
    /// [`Hierarchy::similarity`]; a map brought back is certified again). Runs the
    /// remaining iterations first if the stream was not drained.
    pub fn finish(mut self) -> Result<Solution> {
        for e in self.by_ref() {
            e?;
        }
        let hierarchy = self.hierarchy.clone();
        let (boundary, hierarchy) = (&self.boundary, &*hierarchy);
        let mut map = self.previous.clone().ok_or_else(|| Error::Invalid("no level was solved".into()))?;
        // the certificate of the map in the input's coordinates; the verdict is the same in
        // the normalised ones (a similarity), which the stages below read
        let sim = hierarchy.similarity;
        let mut certificate = match self.certificate.take() {
            Some(c) => c,
            None => certify(&sim.physical_surface(&map)?, &self.opts.certify)?,
        };
        // whether `certificate` is that of `map` brought back (else `map` changed since)
        let mut physical = true;
        // the C0 route of §9: the kinks kept exactly on Σ⁰ from the Σ¹ map
        let mut c0_level = None;
        let c0_route = match (&hierarchy.kinked, &self.c0) {
            (Some(kinked), Some(level)) => {
                let functions = map.knots[0].num_basis() * map.knots[1].num_basis();
                if !self.reports.last().is_some_and(|l| l.converged) {
                    Some(KinkStage::skipped(
                        kinked,
                        functions,
                        "the solve on the smoothed basis did not converge".into(),
                    ))
                } else if !bijective(&certificate) {
                    let why = format!("the map on the smoothed basis is not certified ({})", certificate.message());
                    Some(KinkStage::skipped(kinked, functions, why))
                } else {
                    let out = keep_kinks(&map, level, kinked, &self.opts, &*self.assembler, self.diameter)?;
                    if let (Some(m), Some(c), Some(l)) = (out.map, out.certificate, out.level) {
                        map = m;
                        certificate = c;
                        c0_level = Some(l);
                        physical = false;
                    }
                    Some(out.report)
                }
            }
            _ => None,
        };
        let improvement = match self.opts.improve {
            None => None,
            Some(imp) => {
                let method = imp.method();
                if self.reports.last().is_some_and(|l| l.converged) {
                    let (topology, certify_opts) = (&self.opts.topology, &self.opts.certify);
                    let nl = self.opts.nonlinear;
                    match improve(&map, &certificate, &*method, topology, nl, certify_opts, self.diameter) {
                        Ok(out) => {
                            if out.report.accepted {
                                map = out.map;
                                certificate = out.certificate;
                                physical = false;
                            }
                            Some(out.report)
                        }
                        Err(Error::InfeasibleStart { reason, .. }) => {
                            Some(Improvement::skipped(&*method, &map, format!("the map is not certified ({reason})")))
                        }
                        Err(e) => return Err(e),
                    }
                } else {
                    Some(Improvement::skipped(&*method, &map, "the solve did not converge".into()))
                }
            }
        };
        // back to the input's coordinates; the verdict is that of the map written
        if !sim.is_identity() {
            map = sim.physical_surface(&map)?;
            if !physical {
                certificate = certify(&map, &self.opts.certify)?;
            }
            for l in &mut self.reports {
                l.initial_det_j_min = sim.area(l.initial_det_j_min);
            }
        }
        // the solve ends here (levels, repair, improvement, certificate); what follows
        // measures the map for the report and is not part of `report.seconds`
        let elapsed = self.started.elapsed();
        let kept = c0_level.is_some();
        let finest = c0_level.as_ref().unwrap_or_else(|| self.plan.last().expect("non-empty plan"));
        let sides = finest.sides.each_ref().map(|c| sim.physical_curve(c));
        let ctx = ReportContext {
            hierarchy,
            sides: &sides,
            kinks: kink_reports(boundary, hierarchy, &map, kept),
            c0_route,
            boundary_deviation: {
                // the one measure (`verify::quality::boundary_deviation`), as `check --boundary`
                let mut dev = boundary_deviation(&map, boundary, 400);
                if self.opts.topology.eta_periodic() {
                    // south and north are the seam of a ring, not boundary
                    dev[Side::South as usize] = 0.0;
                    dev[Side::North as usize] = 0.0;
                }
                dev
            },
            opts: &self.opts,
            backend: self.assembler.name(),
            repairs: self.repairs,
            rounds: self.rounds.clone(),
            certificate,
            improvement,
            elapsed,
        };
        let solution = Solution::new(&boundary.name, map, self.reports, ctx);
        trace(|| "report".into());
        Ok(solution)
    }

    /// The hierarchy the solver was made from.
    pub fn hierarchy(&self) -> &Arc<Hierarchy> {
        &self.hierarchy
    }

    /// Certify the last solved map (once) and, when it folds or is undecided and rounds
    /// are left, append the defect-correction level of [`plan_repair`]. Returns
    /// `Ok(true)` when a level was added.
    fn repair(&mut self) -> Result<bool> {
        let (Some(map), Some(last)) = (&self.previous, self.plan.last()) else { return Ok(false) };
        if self.certificate.is_none() {
            // in the input's coordinates: the certificate of the map as it is written,
            // reused by `finish` when no later stage changes the map
            self.certificate = Some(certify(&self.sim.physical_surface(map)?, &self.opts.certify)?);
            trace(|| "certificate".into());
        }
        let cert = self.certificate.as_ref().expect("set above");
        // THB refinement repairs the unrepaired map afterwards (`solve::hierarchical`)
        if self.repairs >= self.opts.repair.rounds || self.opts.repair.refinement == Refinement::Thb {
            return Ok(false);
        }
        let (halo, freeze) = (self.opts.repair.halo, self.opts.repair.freeze);
        let Some(r) = plan_repair(last, cert, self.repairs + 1, halo, freeze)? else { return Ok(false) };
        if let Some(boxes) = r.free_boxes {
            self.free_boxes.push((self.plan.len(), boxes));
        }
        self.rounds.push(r.round);
        self.plan.push(r.level);
        self.repairs += 1;
        self.certificate = None;
        Ok(true)
    }
}

impl Iterator for EggSolver {
    type Item = Result<Event>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        if let Some(a) = self.active.as_mut() {
            match a.solver.step() {
                Ok(Some(it)) => return Some(Ok(Event::Iterate { level: a.level, iterate: it })),
                Ok(None) => {
                    let r = self.finish_level();
                    self.failed = r.is_err();
                    return Some(r);
                }
                Err(e) => {
                    self.failed = true;
                    return Some(Err(e));
                }
            }
        }
        if self.next_level == self.plan.len() && !self.plan.is_empty() && self.previous.is_some() {
            // defect correction (§8.2): certify, refine around the defects, solve again
            if let Err(e) = self.repair() {
                self.failed = true;
                return Some(Err(e));
            }
        }
        if self.next_level < self.plan.len() {
            let k = self.next_level;
            self.next_level += 1;
            let r = self.start_level(k);
            if r.is_err() {
                self.failed = true;
            }
            return Some(r);
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::{Analytic, SideCurve};
    use crate::pipeline::{solve, Pipeline};
    use crate::solve::report::Verdict;

    fn annulus(r0: f64, r1: f64, angle: f64) -> Boundary {
        let arc =
            move |r: f64| SideCurve::Analytic(Analytic::new(move |t| [r * (angle * t).cos(), r * (angle * t).sin()]));
        let ray = move |a: f64| {
            SideCurve::Analytic(Analytic::new(move |t| {
                [(r0 + (r1 - r0) * t) * a.cos(), (r0 + (r1 - r0) * t) * a.sin()]
            }))
        };
        // south: inner radius? use south = ray at angle 0, north = ray at `angle`,
        // west = inner arc, east = outer arc (counter-clockwise).
        Boundary { name: "annulus".into(), sides: [ray(0.0), arc(r1), ray(angle), arc(r0)] }
    }

    #[test]
    fn quarter_annulus_solves_and_is_positive() {
        let b = annulus(1.0, 2.0, std::f64::consts::FRAC_PI_2);
        let sol = solve(&b, &SolveOptions::default()).unwrap();
        let r = &sol.report;
        assert_eq!(r.outcome.verdict, Verdict::Certified, "{}", r.outcome.message);
        let last = r.solve.levels.last().unwrap();
        assert!(last.converged && last.newton_iterations <= 5, "{last:?}");
        assert!(
            (r.measures.area - 0.75 * std::f64::consts::PI).abs() < 10.0 * r.fit.fit_tolerance * r.fit.diameter,
            "area {}",
            r.measures.area
        );
    }

    /// wavy_lid refined twice under `--linear multigrid`: the start of the finest level
    /// (prolonged from the level 16 times smaller) has its residual in the rows along the
    /// wavy lid (scaled 3.5), so a graded level goes before it, nested between the two;
    /// it takes that defect (its start is above 1), and the finest level starts from its
    /// solution below 0.2 and converges in at most 3 Newton iterations (5 from the level
    /// below, BENCHMARKS.md "Finest-level Newton"), certified.
    #[test]
    fn the_finest_multigrid_level_starts_from_the_graded_level() {
        let b = crate::io::read_boundary(&crate::testutil::data("wavy_lid.json"), &Default::default()).unwrap();
        let mut opts = SolveOptions::default();
        opts.levels.refine = 2;
        opts.nonlinear.linear = LinearMethod::Multigrid;
        let sol = solve(&b, &opts).unwrap();
        let r = &sol.report;
        assert_eq!(r.outcome.verdict, Verdict::Certified, "{}", r.outcome.message);
        let levels = &r.solve.levels;
        let n = levels.len();
        assert!(n >= 3 && levels.iter().enumerate().all(|(k, l)| l.graded == (k + 2 == n)), "{levels:?}");
        let (coarse, graded, finest) = (&levels[n - 3], &levels[n - 2], &levels[n - 1]);
        assert!(coarse.elements[0] < graded.elements[0] && graded.elements[0] <= finest.elements[0]);
        assert!(coarse.elements[1] < graded.elements[1] && graded.elements[1] < finest.elements[1]);
        assert!(graded.scaled_residuals[0] > 1.0, "{:?}", graded.scaled_residuals);
        assert!(finest.scaled_residuals[0] < 0.2, "{:?}", finest.scaled_residuals);
        assert!(finest.converged && finest.newton_iterations <= 3, "{finest:?}");
        // the default solver (a factorization below 800 000 unknowns) grades nothing
        let plain = solve(&b, &SolveOptions { levels: opts.levels.clone(), ..SolveOptions::default() }).unwrap();
        assert!(plain.report.solve.levels.iter().all(|l| !l.graded) && plain.report.solve.levels.len() == n - 1);
    }

    fn circle(r: f64, c: [f64; 2]) -> crate::boundary::ring::ClosedContour {
        let tau = std::f64::consts::TAU;
        crate::boundary::ring::ClosedContour::Analytic(Analytic::new(move |t| {
            [c[0] + r * (tau * t).cos(), c[1] + r * (tau * t).sin()]
        }))
    }

    #[test]
    fn eccentric_annulus_ring_certifies() {
        let ring = crate::boundary::ring::Ring {
            name: "eccentric".into(),
            inner: circle(0.4, [0.25, 0.1]),
            outer: circle(1.0, [0.0; 2]),
        };
        let sol = Pipeline::new(ring, SolveOptions::default()).solve().and_then(|s| s.into_map()).unwrap();
        let r = &sol.report;
        assert_eq!(r.outcome.verdict, Verdict::Certified, "{}", r.outcome.message);
        assert!(sol.map.knots[1].is_periodic() && !sol.map.knots[0].is_periodic());
        let area = std::f64::consts::PI * (1.0 - 0.16);
        assert!((r.measures.area - area).abs() < 1e-3, "area {} vs {area}", r.measures.area);
        assert!(
            r.boundary.deviation[1] < 10.0 * r.fit.fit_tolerance
                && r.boundary.deviation[3] < 10.0 * r.fit.fit_tolerance
        );
        assert!(r.boundary.corners.is_empty());
    }

    /// A ring with a narrow gap (the lobe tip 1e-3 of the casing's diameter from it,
    /// [`crate::boundary::ring_reparam`]): `auto` matches the gap, both maps are certified,
    /// and the matched map's cells are closer to orthogonal.
    #[test]
    fn narrow_gap_ring_matches_and_certifies() {
        use crate::boundary::reparam::Reparam;
        let ring = crate::boundary::ring_reparam::lobed_gap();
        let mut q = Vec::new();
        let mut gap_eta = 0.0;
        for method in [Reparam::Auto, Reparam::ArcLength] {
            let mut opts = SolveOptions::default();
            opts.fit.reparam.method = method;
            let sol = Pipeline::new(ring.clone(), opts).solve().and_then(|s| s.into_map()).unwrap();
            let r = &sol.report;
            assert_eq!(r.fit.reparam.used == Reparam::Constrained, method == Reparam::Auto);
            assert_eq!(r.fit.reparam.matches.is_empty(), method == Reparam::ArcLength);
            if let Some(m) = r.fit.reparam.matches.iter().min_by(|a, b| {
                let d = |m: &crate::boundary::reparam::Match| {
                    (m.points[0][0] - m.points[1][0]).hypot(m.points[0][1] - m.points[1][1])
                };
                d(a).total_cmp(&d(b))
            }) {
                // the inner contour keeps arc length: the gap is at this eta in both maps
                gap_eta = m.parameter;
            }
            // near the gap: scaled Jacobian det J / (|x_xi| |x_eta|) on a grid of
            // 41 x 61 points with |eta - gap_eta| <= 0.03
            let mut local = f64::INFINITY;
            for i in 0..=40 {
                for j in 0..=60 {
                    let (u, v) = (i as f64 / 40.0, (gap_eta - 0.03 + 0.06 * j as f64 / 60.0).rem_euclid(1.0));
                    let d = sol.map.derivs(u, v, 1);
                    local = local.min(d.det_j() / (d.xu[0].hypot(d.xu[1]) * d.xv[0].hypot(d.xv[1])));
                }
            }
            q.push((
                r.outcome.verdict,
                r.measures.quality.scaled_jacobian.min,
                r.measures.quality.orthogonality_degrees.max,
                local,
            ));
        }
        // measured (BENCHMARKS.md): matched min scaled J 0.38, orthogonality 67 degrees,
        // near the gap 0.90; arc length 0.003, 89.8 degrees, near the gap 0.0035 (its
        // cells at the gap are sheared almost flat)
        let ((v, sj, orth, near), (_, sj_arc, orth_arc, near_arc)) = (q[0], q[1]);
        eprintln!("near the gap: scaled J >= {near} matched, {near_arc} arc length");
        assert_eq!(v, Verdict::Certified);
        assert!(sj > 0.2 && sj > 10.0 * sj_arc, "min scaled J {sj} (arc length {sj_arc})");
        assert!(near > 10.0 * near_arc.max(0.0), "near the gap {near} (arc length {near_arc})");
        assert!(orth + 10.0 < orth_arc, "orthogonality {orth} (arc length {orth_arc}) degrees");
    }
}
