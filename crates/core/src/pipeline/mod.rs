//! The one observable entry of a solve: an [`Input`], the grouped [`SolveOptions`] and a
//! quadrature back end, run with an observer that sees every stage and may stop it.
//!
//! ```text
//! boundary, ring: fit (§5, §7) → hierarchy (§5.4) → coarse-to-fine solve (§6.3)
//!   → defect correction (§8.2) → kinks kept (§9) → improvement (§4.1)
//!   → certificate (§8.1) → report
//!   → with `--refinement thb` and a folded or undecided map: THB defect correction (§8.2
//!     on a THB basis, [`thb`](mod@thb)), a THB map
//!   → with `--basis auto`: solved again on the fitted basis when the input basis' map is
//!     not certified
//! layout (§11.2): conforming bases → every patch solved as above on them, in parallel
//!   → layout refinement around the patches not certified → free interfaces (improvement)
//! domain, plane graph: automatic layout (crate::domain) → as a layout
//! volume boundary: common bases → Coons start → 3D Winslow (Newton) → trivariate
//!   certificate → halving while not certified
//! ```
//!
//! ```no_run
//! use winslow::pipeline::{Pipeline, Stage};
//! # fn main() -> winslow::Result<()> {
//! let boundary = winslow::io::read_boundary("tests/data/wavy_lid.json".as_ref(), &Default::default())?;
//! let solution = Pipeline::new(boundary, Default::default()).run(&mut |stage: &Stage<'_>| {
//!     if let Stage::Solver(e) = stage {
//!         eprintln!("{e:?}");
//!     }
//!     true // go on; `false` stops the solve (`Error::Cancelled`)
//! })?;
//! println!("{}", solution.verdict().name());
//! # Ok(())
//! # }
//! ```
//!
//! The CLI's `solve`, the viewer's solve job, [`compare`], [`sweep`] and the core's
//! [`solve`] all run this; they only render its stages. The runs built on it live beside
//! it: the comparison of methods on one basis ([`compare`], paper §10) and the sliding
//! O-grid ([`sweep`], §11.1).

pub mod compare;
mod input;
pub(crate) mod start;
pub mod sweep;
mod thb;

pub use input::{Input, Solved};
pub use start::{Improved, ImprovedReport};
pub use thb::{ThbReport, ThbSolution};

use std::sync::Arc;

use crate::boundary::fit::FitOptions;
use crate::boundary::hierarchy::{build_hierarchy, Hierarchy};
use crate::boundary::ring_fit::{ring_hierarchy_with, EtaRefinement};
use crate::boundary::{BasisChoice, Boundary};
use crate::discrete::topology::Topology;
use crate::domain::{auto_layout, graph_layout, AutoLayout, LayoutOptions};
use crate::error::{Error, Result};
use crate::methods::egg::{CpuAssembler, EggAssembler};
use crate::methods::Method;
use crate::multipatch::{solve_multipatch, LayoutEvent};
use crate::solve::hierarchical::ThbRound;
use crate::solve::memory::MemoryEstimate;
use crate::solve::options::SolveOptions;
use crate::solve::report::WarmNote;
use crate::solve::report::{Solution, Verdict};
use crate::solve::solver::{EggSolver, Event};
use crate::solve::volume::{solve_volume, VolumeOptions};
use crate::solve::warm::{warm_start, Warm, WarmStart};
use crate::spline::surface::Surface;

/// A stage of the pipeline, as the observer sees it.
#[derive(Debug)]
#[non_exhaustive]
pub enum Stage<'a> {
    /// The input was fitted: the hierarchy of nested bases (§5.4) that the solve walks,
    /// and the four-sided boundary it solves (a ring's is cut at its seam, `eta = 0`).
    Fitted {
        /// The input.
        input: &'a Input,
        /// The four-sided boundary solved, in the input's coordinates.
        boundary: &'a Boundary,
        /// The hierarchy (in normalised coordinates, see [`Hierarchy::similarity`]).
        hierarchy: &'a Hierarchy,
        /// The method solved on every level.
        method: &'a dyn Method,
    },
    /// An event of the coarse-to-fine solver: a level starts, an iterate, a level ends.
    Solver(&'a Event),
    /// With [`BasisChoice::Auto`]: the map on the input basis is not certified, the input
    /// is solved again on the fitted basis; the stages of that solve follow.
    Fallback {
        /// Why.
        reason: &'a str,
    },
    /// THB refinement left the map folded or undecided after its rounds: the input is
    /// solved again with the tensor repair; the stages of that solve follow.
    ThbFallback {
        /// What the THB rounds ended with.
        thb: &'a crate::solve::report::ThbFallback,
    },
    /// A general domain or a plane graph was laid out automatically: the layout solved
    /// next and what the layout did.
    LaidOut(&'a AutoLayout),
    /// An event of a layout's solve: its bases, a round of patch solves, the
    /// free-interface stage.
    Layout(&'a LayoutEvent),
    /// A warm start was asked for ([`Pipeline::warm_start`]): whether it was used, and
    /// why not (the cold solve's stages follow).
    WarmStart {
        /// Whether the shape is solved from the previous map.
        used: bool,
        /// Why not, when not.
        reason: Option<&'a str>,
    },
    /// A map given as the input is improved by `method` on its own basis
    /// (`start`).
    Improve {
        /// The method.
        method: &'a dyn Method,
    },
    /// A round of the THB defect correction finished ([`Solved::Thb`]): the offending
    /// cells of the map it started from, the cells refined, the solve on the refined
    /// basis.
    ThbRound(&'a ThbRound),
    /// A volume boundary's solve starts (common bases, Coons start, trivariate EGG and/or
    /// the Winslow minimisation, its certificate; `solve_volume`).
    Volume {
        /// The options it runs with, made from the pipeline's.
        options: &'a VolumeOptions,
    },
}

/// The observer of a run: sees every [`Stage`]; returns `false` to stop the solve.
pub type Observer<'o> = dyn FnMut(&Stage<'_>) -> bool + 'o;

/// The pipeline of one input (see the module documentation).
pub struct Pipeline {
    input: Input,
    opts: SolveOptions,
    assembler: Arc<dyn EggAssembler>,
    method: Option<Arc<dyn Method>>,
    eta_refinement: EtaRefinement,
    warm: Option<Surface>,
}

impl std::fmt::Debug for Pipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pipeline")
            .field("input", &self.input.name())
            .field("backend", &self.assembler.name())
            .field("method", &self.method.as_ref().map(|m| m.name()))
            .finish_non_exhaustive()
    }
}

impl Pipeline {
    /// The pipeline of `input` with `opts`, on the CPU back end.
    pub fn new(input: impl Into<Input>, opts: SolveOptions) -> Self {
        Self {
            input: input.into(),
            opts,
            assembler: Arc::new(CpuAssembler),
            method: None,
            eta_refinement: EtaRefinement::Adaptive,
            warm: None,
        }
    }

    /// Start a boundary's solve from `previous`, the map of the previous shape of a family
    /// ([`crate::solve::warm`]: the new sides knot-inserted onto its basis, the elasticity
    /// correction, EGG on that fixed basis, the certificate): [`Solved::Warm`] when that
    /// applies and is bijective; otherwise the solve runs cold and its report's
    /// `warm_start` says why not ([`Stage::WarmStart`] tells the observer either way).
    pub fn warm_start(mut self, previous: Surface) -> Self {
        self.warm = Some(previous);
        self
    }

    /// Assemble on `assembler` (the GPU crate's, or the CPU's, the default).
    pub fn backend(mut self, assembler: Arc<dyn EggAssembler>) -> Self {
        self.assembler = assembler;
        self
    }

    /// Solve `method` on every level instead of EGG (eq. 8) with the options' operator
    /// (a boundary or a ring; a layout solves EGG on every patch).
    pub fn method(mut self, method: Arc<dyn Method>) -> Self {
        self.method = Some(method);
        self
    }

    /// A ring's contour fit refines `eta` as `refinement` says (the sliding grid's frames
    /// keep frame 0's uniform knots).
    pub fn eta_refinement(mut self, refinement: EtaRefinement) -> Self {
        self.eta_refinement = refinement;
        self
    }

    /// Solve without watching.
    pub fn solve(self) -> Result<Solved> {
        self.run(&mut |_| true)
    }

    /// Solve, every stage to `observer`; [`Error::Cancelled`] when it returned `false`.
    pub fn run(mut self, observer: &mut Observer<'_>) -> Result<Solved> {
        match &self.input {
            Input::Boundary(_) | Input::Ring(_) => {
                let why = match self.warm.take() {
                    Some(previous) => match self.try_warm(&previous, observer)? {
                        Ok(w) => return Ok(Solved::Warm(w)),
                        Err(why) => Some(why),
                    },
                    None => None,
                };
                let opts = self.opts.clone();
                let tensor = self.with_tensor_repair();
                let (mut sol, hierarchy) = self.run_keeping_hierarchy(observer)?;
                sol.report.solve.warm_start = why.map(|reason| WarmNote { used: false, reason: Some(reason) });
                if thb::repairs(&sol, &opts) {
                    let t = thb::repair(sol, Some(&hierarchy), &opts, observer)?;
                    return thb::or_tensor_repair(t, tensor, observer);
                }
                Ok(Solved::Map(Box::new(sol)))
            }
            Input::Layout(_) => self.run_layout(None, observer),
            Input::Domain(_) | Input::Graph(_) => {
                self.opts.validate()?;
                let auto = self.lay_out()?;
                if !observer(&Stage::LaidOut(&auto)) {
                    return Err(Error::Cancelled);
                }
                self.input = Input::Layout(auto.layout);
                self.run_layout(Some(Box::new(auto.report)), observer)
            }
            Input::Volume(b) => {
                self.opts.validate()?;
                self.refuse_method("a volume")?;
                let options = volume_options(&self.opts)?;
                if !observer(&Stage::Volume { options: &options }) {
                    return Err(Error::Cancelled);
                }
                solve_volume(b, &options).map(|v| Solved::Volume(Box::new(v)))
            }
            Input::Map { name, map, boundary } => {
                self.opts.validate()?;
                let method = self.method.clone().unwrap_or_else(|| crate::solve::improve::Improve::Winslow.method());
                if !observer(&Stage::Improve { method: &*method }) {
                    return Err(Error::Cancelled);
                }
                start::improve_start(name, map, boundary.as_ref(), &*method, &self.opts)
                    .map(|m| Solved::Improved(Box::new(m)))
            }
        }
    }

    /// The warm start from `previous` ([`Pipeline::warm_start`]): the solved shape, or
    /// why it is solved cold; [`Stage::WarmStart`] to the observer.
    fn try_warm(
        &self,
        previous: &Surface,
        observer: &mut Observer<'_>,
    ) -> Result<std::result::Result<Box<WarmStart>, String>> {
        self.opts.validate()?;
        let out = match &self.input {
            Input::Boundary(b) => match warm_start(previous, b, &self.opts) {
                Ok(Warm::Solved(w)) => Ok(w),
                Ok(Warm::Cold(reason)) => Err(reason),
                Err(e) => Err(format!("the warm start failed: {e}")),
            },
            other => Err(format!("a {} is solved cold", other.kind())),
        };
        let reason = out.as_ref().err().map(String::as_str);
        if !observer(&Stage::WarmStart { used: out.is_ok(), reason }) {
            return Err(Error::Cancelled);
        }
        Ok(out)
    }

    /// The automatic layout of a domain or a graph, with the options' fit.
    fn lay_out(&self) -> Result<AutoLayout> {
        let opts = LayoutOptions { fit: self.opts.fit, ..Default::default() };
        match &self.input {
            Input::Domain(d) => auto_layout(d, &opts),
            Input::Graph(g) => graph_layout(g, &opts),
            other => Err(Error::Invalid(format!("a {} is not laid out", other.kind()))),
        }
    }

    /// [`Error::Invalid`] when a method was set: `what` solves its own.
    fn refuse_method(&self, what: &str) -> Result<()> {
        match &self.method {
            Some(_) => Err(Error::Invalid(format!(
                "{what} solves its own method; the method replaces EGG on the levels of a boundary or a ring"
            ))),
            None => Ok(()),
        }
    }

    /// The conforming solve of the layout input, `laid_out` the report of the automatic
    /// layout that made it.
    fn run_layout(
        self,
        laid_out: Option<Box<crate::domain::LayoutReport>>,
        observer: &mut Observer<'_>,
    ) -> Result<Solved> {
        let Input::Layout(layout) = &self.input else {
            return Err(Error::Invalid(format!("a {} is not a layout", self.input.kind())));
        };
        self.opts.validate()?;
        self.refuse_method("a layout (EGG on every patch; its free-interface stage is the options' improvement)")?;
        let assembler = self.assembler.clone();
        solve_multipatch(layout, &self.opts, assembler, &mut |e| observer(&Stage::Layout(e)))
            .map(|s| Solved::Layout { solution: Box::new(s), laid_out })
    }

    /// The same pipeline with the tensor repair ([`Refinement::Tensor`]): the fallback of
    /// a THB defect correction that does not end certified ([`thb::or_tensor_repair`]).
    fn with_tensor_repair(&self) -> Self {
        let mut opts = self.opts.clone();
        opts.repair.refinement = crate::solve::options::Refinement::Tensor;
        Self {
            input: self.input.clone(),
            opts,
            assembler: self.assembler.clone(),
            method: self.method.clone(),
            eta_refinement: self.eta_refinement,
            warm: None,
        }
    }

    /// [`Pipeline::run`] of a boundary or a ring, with the hierarchy the solution was
    /// solved on (the fitted one after a fallback): the comparison of methods solves the
    /// others on it.
    pub(crate) fn run_keeping_hierarchy(self, observer: &mut Observer<'_>) -> Result<(Solution, Arc<Hierarchy>)> {
        self.opts.validate()?;
        let first = self.attempt(&self.opts, observer)?;
        // with THB refinement a folded or undecided map on the input basis is repaired
        // locally ([`thb`](mod@thb)), on the input basis
        let fallback = if thb::repairs(&first.0, &self.opts) { None } else { auto_fallback(&first.0, &self.opts.fit) };
        let Some((fitted, why)) = fallback else { return Ok(first) };
        if !observer(&Stage::Fallback { reason: &why }) {
            return Err(Error::Cancelled);
        }
        let opts = SolveOptions { fit: fitted, ..self.opts.clone() };
        let (again, h) = self.attempt(&opts, observer)?;
        Ok((auto_choice(first.0, again, why), h))
    }

    /// The estimated peak memory of the solve ([`MemoryEstimate`]): the input fitted and
    /// its levels planned as [`Pipeline::run`] does (with `--basis auto`, those of the
    /// first attempt; of a layout, the conforming bases of all patches), nothing solved. `winslow bench` prints it next to the measured peak.
    pub fn estimate(&self) -> Result<MemoryEstimate> {
        self.opts.validate()?;
        match &self.input {
            Input::Layout(layout) => return crate::multipatch::solve::layout_estimate(layout, &self.opts),
            Input::Domain(_) | Input::Graph(_) => {
                return crate::multipatch::solve::layout_estimate(&self.lay_out()?.layout, &self.opts)
            }
            Input::Volume(_) | Input::Map { .. } => {
                return Err(Error::Invalid(format!(
                    "the memory estimate of a {} is not modelled yet",
                    self.input.kind()
                )))
            }
            Input::Boundary(_) | Input::Ring(_) => {}
        }
        let (_, _, solver) = self.plan(&self.opts)?;
        Ok(solver.estimate())
    }

    /// The fit of the input and the solver of its levels (nothing large allocated yet).
    fn plan(&self, opts: &SolveOptions) -> Result<(Boundary, Arc<Hierarchy>, EggSolver)> {
        let (boundary, hierarchy, opts) = match &self.input {
            Input::Boundary(b) => (b.clone(), build_hierarchy(b, &opts.fit)?, opts.clone()),
            Input::Ring(r) => {
                let (h, cut) = ring_hierarchy_with(r, &opts.fit, self.eta_refinement)?;
                (cut, h, ring_options(opts))
            }
            other => return Err(Error::Invalid(format!("a {} has no one hierarchy", other.kind()))),
        };
        let hierarchy = Arc::new(hierarchy);
        let solver = match &self.method {
            Some(m) => EggSolver::with_method(&boundary, hierarchy.clone(), opts, self.assembler.clone(), m.clone())?,
            None => EggSolver::new(&boundary, hierarchy.clone(), opts, self.assembler.clone())?,
        };
        Ok((boundary, hierarchy, solver))
    }

    /// One fit and coarse-to-fine solve with `opts`; refused with [`Error::Memory`] when
    /// its estimated peak exceeds `opts.max_memory`.
    fn attempt(&self, opts: &SolveOptions, observer: &mut Observer<'_>) -> Result<(Solution, Arc<Hierarchy>)> {
        let (boundary, hierarchy, mut solver) = self.plan(opts)?;
        let estimate = solver.estimate();
        opts.max_memory.check(&estimate, opts.levels.refine, &format!("solving '{}'", self.input.name()))?;
        let fitted =
            Stage::Fitted { input: &self.input, boundary: &boundary, hierarchy: &hierarchy, method: solver.method() };
        if !observer(&fitted) {
            return Err(Error::Cancelled);
        }
        for event in solver.by_ref() {
            if !observer(&Stage::Solver(&event?)) {
                return Err(Error::Cancelled);
            }
        }
        Ok((solver.finish()?, hierarchy))
    }
}

/// Fit `boundary`, then solve coarse to fine on the CPU ([`Pipeline::solve`]).
pub fn solve(boundary: &Boundary, opts: &SolveOptions) -> Result<Solution> {
    Pipeline::new(boundary.clone(), opts.clone()).solve()?.into_map()
}

/// The options of a volume solve made from the pipeline's: `refine` extra halvings of
/// the common bases, at most `repair` further halvings while the map is not certified,
/// the certificate's options.
/// The volume solve of `opts`: EGG (eq. 8 in 3D), followed by the Winslow functional
/// with `improve = Some(Winslow)`; the weak form (eq. 14) has no volume analogue here.
pub(crate) fn volume_options(opts: &SolveOptions) -> Result<VolumeOptions> {
    use crate::solve::improve::Improve;
    use crate::solve::volume::VolumeMethod;
    let method = match opts.improve {
        None => VolumeMethod::Egg,
        Some(Improve::Winslow) => VolumeMethod::EggWinslow,
        Some(Improve::WeakForm) => {
            return Err(Error::Invalid(
                "a volume is solved by EGG (eq. 8 in 3D) and improved by the Winslow functional only: \
                 use --improve winslow or no improvement"
                    .into(),
            ))
        }
    };
    if opts.operator != crate::discrete::assembly::Operator::Scaled {
        return Err(Error::Invalid(
            "a volume's EGG operator is the scaled one (sum A_ij d_i d_j x / tr A, A = cof(J)^T cof(J)): \
             --operator plain is for planar maps"
                .into(),
        ));
    }
    Ok(VolumeOptions {
        method,
        refine: opts.levels.refine,
        max_refinements: opts.repair.rounds,
        linear: opts.nonlinear.linear,
        ..Default::default()
    })
}

/// With [`BasisChoice::Auto`], after [`auto_fallback`] asked to solve `first` (input
/// basis) again as `again` (fitted basis) for the reason `why`: `again`, with the reason
/// in its report; but a `degenerate-corner` map on the input basis stands when the fitted
/// one is not certified either (its boundary is the exact one). The time of both solves
/// counts.
fn auto_choice(first: Solution, mut again: Solution, why: String) -> Solution {
    if first.report.outcome.verdict == Verdict::DegenerateCorner && again.report.outcome.verdict != Verdict::Certified {
        let mut first = first;
        first.report.solve.seconds += again.report.solve.seconds;
        first.report.outcome.message.push_str(&format!(
            "; solved again on the fitted basis too, where the map is {}: the input basis' map is kept",
            again.report.outcome.verdict.name()
        ));
        return first;
    }
    again.report.setup.basis.requested = BasisChoice::Auto;
    again.report.setup.basis.fallback = Some(why);
    again.report.solve.seconds += first.report.solve.seconds;
    again
}

/// With [`BasisChoice::Auto`]: when `sol` was solved on the input basis and its map is
/// not certified (folded, undecided or not converged; `degenerate-corner` at corners of
/// the domain is the best map such a boundary allows and is kept, but not when only
/// zero-speed points of the input's parameterization are excused: the fitted basis
/// reparameterizes them, see [`auto_choice`]), the fit options of the fitted basis and
/// the reason to solve again with them. `None` when `sol` stands.
fn auto_fallback(sol: &Solution, fit: &FitOptions) -> Option<(FitOptions, String)> {
    let r = &sol.report;
    if r.setup.basis.requested != BasisChoice::Auto || r.setup.basis.used != BasisChoice::Input {
        return None;
    }
    let zero_speed_only = r.outcome.verdict == Verdict::DegenerateCorner
        && !r.outcome.certificate.excused_points.is_empty()
        && r.outcome.certificate.corners.iter().all(|c| c.excused_extent.is_none());
    if r.outcome.verdict == Verdict::Certified || (r.outcome.verdict == Verdict::DegenerateCorner && !zero_speed_only) {
        return None;
    }
    let why = if zero_speed_only {
        format!(
            "on the input basis ({} functions) det J = 0 where the input's parameterization has zero speed; solved \
             again on the fitted basis, which reparameterizes the side there",
            r.setup.basis_functions
        )
    } else {
        format!(
            "on the input basis ({} functions, {} repair rounds) the map is {}; solved again on the fitted basis",
            r.setup.basis_functions,
            r.solve.repairs,
            r.outcome.verdict.name()
        )
    };
    Some((FitOptions { basis: BasisChoice::Fitted, ..*fit }, why))
}

/// The options of a ring solve (§11.1) made from `opts`: `eta` periodic
/// ([`Topology::ring`]), and no corner of the parameter square excused by the certificate
/// (a ring has no corners).
pub(crate) fn ring_options(opts: &SolveOptions) -> SolveOptions {
    let mut o = opts.clone();
    o.topology = Topology::ring();
    o.certify.excuse_corners = false;
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{read_boundary, ReadOptions};
    use crate::testutil::data;

    fn puzzle4() -> Boundary {
        read_boundary(&data("gismo/puzzle4.json"), &ReadOptions::default()).expect("puzzle4")
    }

    /// The stages in order: fitted, the solver's stream, the fallback with the reason the
    /// report gives, the fitted basis' stages; the result is `solve`'s bit for bit, and the
    /// observer saw every iterate the report records.
    #[test]
    fn the_observer_sees_every_stage_of_a_fallback() {
        // puzzle4's input basis folds after one repair round: solved again on the fitted basis
        let mut opts = SolveOptions::default();
        opts.repair.rounds = 1;
        let mut seen = Vec::new();
        let mut residuals = Vec::new();
        let sol = Pipeline::new(puzzle4(), opts.clone())
            .run(&mut |stage| {
                seen.push(match stage {
                    Stage::Fitted { hierarchy, .. } => format!("fitted {:?}", hierarchy.basis.used),
                    Stage::Fallback { reason } => format!("fallback {reason}"),
                    Stage::Solver(Event::Iterate { iterate, .. }) => {
                        residuals.push(iterate.residual);
                        "iterate".into()
                    }
                    Stage::Solver(_) => "level".into(),
                    other => panic!("a boundary's run saw {other:?}"),
                });
                true
            })
            .and_then(Solved::into_map)
            .unwrap();
        let r = &sol.report;
        assert_eq!((r.setup.basis.requested, r.setup.basis.used), (BasisChoice::Auto, BasisChoice::Fitted));
        let fallback = seen.iter().position(|s| s.starts_with("fallback")).expect("a fallback stage");
        assert_eq!(seen[0], "fitted Input");
        assert_eq!(seen[fallback + 1], "fitted Fitted");
        assert_eq!(seen[fallback], format!("fallback {}", r.setup.basis.fallback.as_deref().unwrap()));
        assert_eq!(seen.iter().filter(|s| s.starts_with("fitted")).count(), 2);
        // the fitted basis' iterates are the report's, in order
        let recorded: Vec<f64> = r.solve.levels.iter().flat_map(|l| l.residuals.clone()).collect();
        assert_eq!(residuals[residuals.len() - recorded.len()..], recorded[..]);
        let again = solve(&puzzle4(), &opts).unwrap();
        assert_eq!(again.map.control_points, sol.map.control_points);
        assert_eq!(again.report.outcome.verdict, r.outcome.verdict);
    }

    /// The observer stops the solve at its first iterate: `Error::Cancelled`, and nothing
    /// after the stage that said stop.
    #[test]
    fn the_observer_stops_the_solve() {
        let mut stages = 0;
        let out = Pipeline::new(puzzle4(), SolveOptions::default()).run(&mut |stage| {
            stages += 1;
            !matches!(stage, Stage::Solver(Event::Iterate { .. }))
        });
        assert!(matches!(out, Err(Error::Cancelled)), "{out:?}");
        // fitted, the first level's start, its first iterate
        assert_eq!(stages, 3);
    }

    /// A memory limit below the estimated peak: [`Error::Memory`] with the estimate and
    /// the limit, before any stage; [`Pipeline::estimate`] gives the same estimate.
    #[test]
    fn a_solve_above_the_memory_limit_is_refused_before_it_starts() {
        let mut opts = SolveOptions::default();
        opts.levels.refine = 2;
        let estimate = Pipeline::new(puzzle4(), opts.clone()).estimate().unwrap();
        assert!(estimate.bytes > crate::solve::memory::BASE && estimate.unknowns > 0);
        // below the factorization's estimate but above multigrid's, `--linear auto` solves
        // the finest level by multigrid instead of refusing (`solve::memory::auto_linear`)
        let mut multigrid = opts.clone();
        multigrid.nonlinear.linear = crate::linalg::linsolve::LinearMethod::Multigrid;
        let multigrid = Pipeline::new(puzzle4(), multigrid).estimate().unwrap();
        assert!(multigrid.bytes < estimate.bytes - 1, "{multigrid:?} against {estimate:?}");
        let between =
            SolveOptions { max_memory: crate::solve::memory::MemoryLimit::Bytes(estimate.bytes - 1), ..opts.clone() };
        let solved = Pipeline::new(puzzle4(), between).solve().unwrap().into_map().unwrap();
        assert_eq!(solved.report.outcome.verdict, Verdict::Certified);
        // below both: refused, with the factorization's estimate as the need
        let limit = multigrid.bytes - 1;
        let opts = SolveOptions { max_memory: crate::solve::memory::MemoryLimit::Bytes(limit), ..opts };
        let mut stages = 0;
        let out = Pipeline::new(puzzle4(), opts.clone()).run(&mut |_| {
            stages += 1;
            true
        });
        match out {
            Err(Error::Memory { needed, available, ref advice, .. }) => {
                assert_eq!((needed, available), (estimate.bytes, limit));
                assert!(advice.contains("--refine 1"), "{advice}");
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(stages, 0);
        let opts = SolveOptions { max_memory: crate::solve::memory::MemoryLimit::Bytes(estimate.bytes), ..opts };
        assert!(Pipeline::new(puzzle4(), opts).solve().is_ok());
    }

    /// Options are checked before anything runs, with a message naming the option.
    #[test]
    fn invalid_options_are_refused_before_the_fit() {
        for (what, opts) in [
            ("nonlinear tolerance", {
                let mut o = SolveOptions::default();
                o.nonlinear.tol = 0.0;
                o
            }),
            ("growth", {
                let mut o = SolveOptions::default();
                o.levels.growth = f64::NAN;
                o
            }),
            ("fit tolerance", {
                let mut o = SolveOptions::default();
                o.fit.tol = 1.5;
                o
            }),
        ] {
            let mut stages = 0;
            let out = Pipeline::new(puzzle4(), opts).run(&mut |_| {
                stages += 1;
                true
            });
            let Err(e) = out else { panic!("{what}: accepted") };
            assert!(e.to_string().contains(what), "{what}: {e}");
            assert_eq!(stages, 0, "{what}");
        }
    }

    /// A layout's peak is estimated over all its patches (their conforming bases) and a
    /// limit below it is refused before the first event; the estimate grows about 4x per
    /// uniform halving, like a single map's.
    #[test]
    fn a_layout_above_the_memory_limit_is_refused_before_it_starts() {
        use crate::solve::memory::{MemoryLimit, BASE};
        let layout = match crate::io::read(&data("gismo/xml/multipatch/TUDflame.xml")).unwrap() {
            crate::io::Document::Layout(l) => l,
            other => panic!("TUDflame is a {}", other.kind()),
        };
        let refined = |refine| {
            let mut o = SolveOptions::default();
            o.levels.refine = refine;
            o
        };
        let at = |refine| Pipeline::new(layout.clone(), refined(refine)).estimate();
        let (e1, e2) = (at(1).unwrap(), at(2).unwrap());
        let ratio = (e2.bytes - BASE) as f64 / (e1.bytes - BASE) as f64;
        assert!((3.0..5.0).contains(&ratio) && e2.unknowns > 3 * e1.unknowns, "{e1:?} {e2:?}");
        // the free-interface stage factors all patches at once: twice the fixed stage's terms
        let free = SolveOptions { improve: Some(crate::solve::improve::Improve::Winslow), ..refined(2) };
        let e2_free = Pipeline::new(layout.clone(), free).estimate().unwrap();
        assert_eq!(e2_free.bytes - BASE, 2 * (e2.bytes - BASE));
        let opts = SolveOptions { max_memory: MemoryLimit::Bytes(e2.bytes - 1), ..refined(2) };
        let mut events = 0;
        match Pipeline::new(layout.clone(), opts).run(&mut |_| {
            events += 1;
            true
        }) {
            Err(Error::Memory { needed, ref what, .. }) => {
                assert_eq!(needed, e2.bytes);
                assert!(what.contains("TUDflame") && what.contains("5 patches"), "{what}");
            }
            other => panic!("{:?}", other.map(|s| s.verdict())),
        }
        assert_eq!(events, 0);
    }

    /// A layout runs through the same entry: its events in order (the conforming bases,
    /// one round per layout refinement, then the free-interface stage of its
    /// improvement), a multipatch result, and the observer's stop.
    #[test]
    fn a_layout_runs_through_the_pipeline() {
        let layout = match crate::io::read(&data("gismo/xml/multipatch/plateWithHoleMP.xml")).unwrap() {
            crate::io::Document::Layout(l) => l,
            other => panic!("plateWithHoleMP is a {}", other.kind()),
        };
        let opts = SolveOptions { improve: Some(crate::solve::improve::Improve::Winslow), ..Default::default() };
        let mut events = Vec::new();
        let solved = Pipeline::new(layout.clone(), opts.clone())
            .run(&mut |stage| {
                match stage {
                    Stage::Layout(e) => events.push((*e).clone()),
                    other => panic!("a layout's run saw {other:?}"),
                }
                true
            })
            .unwrap();
        let verdict = solved.verdict();
        let Solved::Layout { solution: sol, laid_out: None } = solved else { panic!("a layout gave one map") };
        assert_eq!((sol.report.interfaces, verdict), ("free", Verdict::Certified), "{}", sol.report.message);
        assert!(matches!(events[0], LayoutEvent::Bases { patches, .. } if patches == layout.patches.len()));
        let rounds = events.iter().filter(|e| matches!(e, LayoutEvent::Round { .. })).count();
        assert_eq!(rounds, sol.report.layout_refinements + 1);
        assert!(matches!(events.last(), Some(LayoutEvent::Free { functional: "winslow" })), "{events:?}");
        assert!(matches!(events[rounds], LayoutEvent::Round { ref failing, .. } if failing.is_empty()));
        // one map is not what a layout gives
        let solved = Solved::Layout { solution: sol, laid_out: None };
        assert!(matches!(solved.into_map(), Err(Error::DocumentKind { .. })));
        // stopped at its first event
        let out = Pipeline::new(layout.clone(), opts).run(&mut |_| false);
        assert!(matches!(out, Err(Error::Cancelled)), "{out:?}");
        // a method replaces EGG on a boundary's levels, not on a layout's patches
        let out = Pipeline::new(layout, SolveOptions::default())
            .method(Arc::new(crate::methods::egg::EggMethod::cpu(Default::default())))
            .solve();
        assert!(matches!(out, Err(Error::Invalid(_))), "{out:?}");
    }

    /// A fit stopped short of its tolerance (one level of a few elements for a wavy side):
    /// the map may be bijective, but its boundary is not the input's within the tolerance,
    /// so the report says so and it is not a success; with the fit's own levels it is.
    #[test]
    fn a_boundary_off_by_more_than_its_tolerance_is_not_a_success() {
        let b = read_boundary(&data("wavy_lid.json"), &ReadOptions::default()).unwrap();
        let mut opts = SolveOptions::default();
        opts.fit.basis = BasisChoice::Fitted;
        opts.fit.tol = 1e-6;
        let good = solve(&b, &opts).unwrap();
        assert!(good.report.boundary.kept && good.report.success(), "{}", good.report.outcome.message);
        opts.fit.max_levels = 1;
        let short = solve(&b, &opts).unwrap();
        let r = &short.report;
        let deviation = r.boundary.deviation.iter().fold(0.0f64, |m, &d| m.max(d));
        assert!(deviation > r.fit.fit_tolerance, "{deviation:e} <= {:e}", r.fit.fit_tolerance);
        assert!(!r.boundary.kept && !r.success(), "{}", r.outcome.message);
        assert!(r.outcome.message.contains("NOT the input's"), "{}", r.outcome.message);
    }
}
