//! The comparison of paper §10 (Tables 1-3): several parameterization methods run on the
//! same boundary, the same hierarchy of bases and the same starts, and every resulting
//! map judged by the same measures: the nonlinear iterations (IT), bijectivity by the
//! certificate (BIJ, §8.1), the Poisson benchmark `Q(x) / Q(x_G)` of eq. (44)-(45) with
//! `x_G` the EGG map, the Winslow value `W` (eq. 16), the Liao and area-orthogonality
//! functionals (eq. 3), the smallest scaled Jacobian and the time.
//!
//! # Methods and the extension point
//!
//! [`MethodChoice`] is the registry of the methods `compare` knows by name; each gives a
//! `Contender`, which runs on a `CompareContext` (boundary, hierarchy, options, the
//! EGG reference run) and returns a `MethodRun`: its name, nonlinear iterations,
//! whether it converged and why not, the map, the seconds. The measures are computed here,
//! uniformly, from the map alone ([`Measures::of`]); a contender never reports its own
//! verdict. A new method is a new [`MethodChoice`] variant and a `Contender`
//! implementation (a minimization or root-finding [`Method`] can use `HierarchyRun`).
//!
//! EGG always runs first: its map is `x_G`, and with the basis `auto` its run decides
//! the basis (the input's own basis when its map is certified, else the fitted one, as
//! `winslow solve` does); every other method then runs on that basis, from the same
//! start: by default the Coons patch of the finest basis ([`CompareOptions::default`]),
//! with more levels the coarse-to-fine walk of §6.3 (`HierarchyRun`). Defect
//! correction (§8.2) is off by default: it would refine each method's basis differently.
//!
//! | name | method | start | IT counts |
//! |------|--------|-------|-----------|
//! | `egg` | EGG, eq. (8) (`x_G`) | Coons patch | Newton / pseudo-time iterations |
//! | `vhm` | variational harmonic, eq. (46) | Coons patch | Newton iterations |
//! | `qc` | quasi-conformal, eq. (47)-(48) | Coons patch | Levenberg-Marquardt / Newton iterations |
//! | `maxz` | Gravesen's feasible start, eq. (49), stopped at `z > 0` | Coons patch | LPs |
//! | `liao` | Liao functional (eq. 3) subject to `d(c) >= ε` | `x_G` | QPs of the SQP (+ restoration LPs) |
//! | `winslow` | Winslow functional (eq. 16) subject to `d(c) >= ε` | `x_G` | QPs (+ LPs) |
//! | `ao` | area orthogonality (eq. 3) subject to `d(c) >= ε` | `x_G` | QPs (+ LPs) |
//!
//! Gravesen's methods (the last four, [`ConstrainedRun`], [`MaxZRun`]) need a polynomial
//! basis, the constrained ones at most [`MAX_UNKNOWNS`](crate::solve::constrained::MAX_UNKNOWNS) unknowns: on
//! another basis their rows are errors that say so. [`MethodChoice::DEFAULT`] leaves
//! them out.
//!
//! Nothing ends silently folded: a method that does not converge, or whose map the
//! certificate does not prove bijective, is reported as such with its last iterate; a
//! method that fails outright is a row with the error and no measures.

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

mod gravesen;

pub use gravesen::{ConstrainedRun, MaxZRun};

use crate::boundary::hierarchy::Hierarchy;
use crate::boundary::{BasisChoice, Boundary};
use crate::error::{Error, Result};
use crate::methods::egg::{EggAssembler, EggMethod};
use crate::methods::harmonic::VariationalHarmonicMethod;
use crate::methods::quasi_conformal::{QcHessian, QuasiConformalMethod};
use crate::methods::Method;
use crate::pipeline::{Pipeline, Stage};
use crate::solve::constrained::{ConstrainedOptions, Functional};
use crate::solve::options::SolveOptions;
use crate::solve::report::{Solution, Verdict};
use crate::solve::solver::{EggSolver, Event};
use crate::spline::surface::Surface;
use crate::verify::certificate::certify;
use crate::verify::poisson::{default_scales, poisson_benchmark};
use crate::verify::quality::quality;

/// The methods `compare` knows by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MethodChoice {
    /// Elliptic grid generation, eq. (8) (the reference `x_G`).
    Egg,
    /// The variational harmonic method, eq. (46).
    Vhm,
    /// The quasi-conformal functional, eq. (47)-(48).
    Qc,
    /// Gravesen's feasible start, eq. (49), alone: `max z` subject to `d(c) >= z 1` from
    /// the Coons patch of the EGG basis, stopped at `z > 0` ([`run_max_z`](crate::solve::constrained::run_max_z)).
    #[serde(rename = "maxz")]
    MaxZ,
    /// The Liao functional (eq. 3) minimised subject to `d(c) >= ε` from `x_G`
    /// ([`run`](crate::solve::constrained::run)).
    Liao,
    /// The Winslow functional (eq. 16) minimised subject to `d(c) >= ε` from `x_G`.
    Winslow,
    /// The area-orthogonality functional (eq. 3) minimised subject to `d(c) >= ε` from `x_G`.
    Ao,
}

impl MethodChoice {
    /// Every registered method, in table order.
    pub const ALL: [MethodChoice; 7] = [
        MethodChoice::Egg,
        MethodChoice::Vhm,
        MethodChoice::Qc,
        MethodChoice::MaxZ,
        MethodChoice::Liao,
        MethodChoice::Winslow,
        MethodChoice::Ao,
    ];

    /// The default selection (`winslow compare` without `--methods`, the viewer without
    /// Gravesen's methods): the methods that run on any basis. Gravesen's need a
    /// polynomial basis of at most [`MAX_UNKNOWNS`](crate::solve::constrained::MAX_UNKNOWNS) unknowns.
    pub const DEFAULT: [MethodChoice; 3] = [MethodChoice::Egg, MethodChoice::Vhm, MethodChoice::Qc];

    /// The name in tables, reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            MethodChoice::Egg => "egg",
            MethodChoice::Vhm => "vhm",
            MethodChoice::Qc => "qc",
            MethodChoice::MaxZ => "maxz",
            MethodChoice::Liao => "liao",
            MethodChoice::Winslow => "winslow",
            MethodChoice::Ao => "ao",
        }
    }

    /// Where the method starts with `opts`: `coons` (the Coons patch of the finest
    /// basis), `hierarchy` (coarse to fine from the Coons patch of the coarsest level,
    /// more than one level) or `egg` (the EGG map `x_G`).
    pub fn start(self, opts: &CompareOptions) -> &'static str {
        match self {
            MethodChoice::Egg | MethodChoice::Vhm | MethodChoice::Qc if opts.solve.levels.max_levels != Some(1) => {
                "hierarchy"
            }
            MethodChoice::Egg | MethodChoice::Vhm | MethodChoice::Qc | MethodChoice::MaxZ => "coons",
            MethodChoice::Liao | MethodChoice::Winslow | MethodChoice::Ao => "egg",
        }
    }

    /// The method called `name` (`winslow-functional`, the name of earlier versions, is
    /// `winslow`: the same functional as `winslow optimise --functional winslow`);
    /// [`Error::Invalid`] listing the known names otherwise.
    pub fn parse(name: &str) -> Result<Self> {
        let name = name.trim().to_ascii_lowercase();
        if name == "winslow-functional" {
            return Ok(MethodChoice::Winslow);
        }
        Self::ALL.into_iter().find(|m| m.name() == name).ok_or_else(|| {
            let known: Vec<&str> = Self::ALL.iter().map(|m| m.name()).collect();
            Error::Invalid(format!("unknown method '{name}' (known: {})", known.join(", ")))
        })
    }

    /// The contender that runs this method with `opts`.
    pub(crate) fn contender(self, opts: &CompareOptions) -> Box<dyn Contender> {
        match self {
            MethodChoice::Egg => Box::new(HierarchyRun::new(self.name(), None)),
            MethodChoice::Vhm => {
                let vhm = VariationalHarmonicMethod { lambda1: opts.lambda1, lambda2: opts.lambda2, length: 1.0 };
                Box::new(HierarchyRun::new(self.name(), Some(Arc::new(vhm))))
            }
            MethodChoice::Qc => Box::new(HierarchyRun::new(
                self.name(),
                Some(Arc::new(QuasiConformalMethod { hessian: opts.qc_hessian })),
            )),
            MethodChoice::MaxZ => Box::new(MaxZRun),
            MethodChoice::Liao => Box::new(ConstrainedRun::new(self.name(), Functional::Liao)),
            MethodChoice::Winslow => Box::new(ConstrainedRun::new(self.name(), Functional::Winslow)),
            MethodChoice::Ao => Box::new(ConstrainedRun::new(self.name(), Functional::AreaOrthogonality)),
        }
    }
}

/// Options of a comparison.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CompareOptions {
    /// Fit, levels, nonlinear iteration, certificate (shared by every method); the EGG
    /// operator.
    pub solve: SolveOptions,
    /// `λ₁` of the variational harmonic method (dimensionless, relative to the domain's
    /// diameter; see `methods::harmonic`).
    pub lambda1: f64,
    /// `λ₂` of the variational harmonic method.
    pub lambda2: f64,
    /// The Hessian of the quasi-conformal iteration (Gauss-Newton by default).
    pub qc_hessian: QcHessian,
    /// Length scales of the Poisson benchmark's `u*` (default: `default_scales` of the
    /// EGG map), the same for every method.
    pub poisson_scales: Option<[f64; 2]>,
    /// `ε`, iteration limits and tolerances of Gravesen's methods (max-z and the
    /// constrained optimisations); their certificate options are `solve.certify`.
    pub constrained: ConstrainedOptions,
}

impl CompareOptions {
    /// The solve's options ([`SolveOptions::validate`]), `λ₁` and `λ₂` finite and not
    /// negative, the Poisson scales positive and finite, Gravesen's options
    /// ([`ConstrainedOptions::validate`]); [`Error::Invalid`] naming the option otherwise.
    pub fn validate(&self) -> Result<()> {
        self.solve.validate()?;
        for (name, v) in [("lambda1", self.lambda1), ("lambda2", self.lambda2)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::Invalid(format!("{name} must be finite and not negative, got {v}")));
            }
        }
        if let Some(s) = self.poisson_scales {
            if !s.iter().all(|v| v.is_finite() && *v > 0.0) {
                return Err(Error::Invalid(format!(
                    "the Poisson scales must be positive and finite, got {}, {}",
                    s[0], s[1]
                )));
            }
        }
        self.constrained.validate()
    }
}

impl Default for CompareOptions {
    /// The solver's defaults, except: one level (every method starts from the Coons patch
    /// of the finest basis: one start and one basis for all, as in the paper's Table 3;
    /// more levels add the elasticity prolongations and the boundary continuation of
    /// §6.3 and §9, whose damped solves a slowly converging method repeats), no defect
    /// correction (it would refine each method's basis differently), room for 200
    /// Newton iterations (the variational methods need tens to hundreds where EGG needs a
    /// handful: the quasi-conformal functional converges linearly, its minimizers being
    /// degenerate) and 100 pseudo-time steps after them.
    fn default() -> Self {
        let mut solve = SolveOptions::default();
        solve.repair.rounds = 0;
        solve.levels.max_levels = Some(1);
        solve.nonlinear.max_newton = 200;
        solve.nonlinear.max_pseudo = 100;
        Self {
            solve,
            lambda1: 0.0,
            lambda2: 0.0,
            qc_hessian: QcHessian::default(),
            poisson_scales: None,
            constrained: ConstrainedOptions::default(),
        }
    }
}

/// What a contender sees.
pub(crate) struct CompareContext<'a> {
    /// The boundary.
    pub boundary: &'a Boundary,
    /// The hierarchy of bases every method uses (EGG's).
    pub hierarchy: &'a Arc<Hierarchy>,
    /// Shared options.
    pub options: &'a CompareOptions,
    /// Quadrature back end of the hierarchy's operators.
    pub assembler: Arc<dyn EggAssembler>,
    /// The EGG run (`x_G`), for methods that start from it; `None` while EGG runs.
    pub reference: Option<&'a MethodRun>,
}

impl std::fmt::Debug for CompareContext<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompareContext").field("boundary", &self.boundary.name).finish_non_exhaustive()
    }
}

/// What a contender returns: the measures are computed from `map` by the comparison.
#[derive(Debug, Clone)]
pub(crate) struct MethodRun {
    /// Method name.
    pub method: String,
    /// Nonlinear iterations in all, continuation solves included.
    pub iterations: usize,
    /// Whether the method met its stopping rule on the finest level.
    pub converged: bool,
    /// Why it did not, if it did not.
    pub failure: Option<String>,
    /// The map (the last iterate when not converged), in the input's coordinates.
    pub map: Surface,
    /// Wall-clock seconds of the run.
    pub seconds: f64,
    /// What the run did beyond its iterations (stages, the start's and result's values).
    pub notes: Vec<String>,
}

impl MethodRun {
    /// The run of a coarse-to-fine solve.
    pub fn of_solution(method: &str, sol: &Solution, seconds: f64) -> Self {
        let levels = &sol.report.solve.levels;
        let last = levels.last();
        Self {
            method: method.to_string(),
            iterations: levels.iter().map(|l| l.iterations + l.continuation_iterations).sum(),
            converged: last.is_some_and(|l| l.converged),
            failure: last.and_then(|l| l.failure.clone()),
            map: sol.map.clone(),
            seconds,
            notes: Vec::new(),
        }
    }
}

/// A method of the comparison (see the module documentation).
pub(crate) trait Contender: Send + Sync + std::fmt::Debug {
    /// Name in tables and reports.
    fn name(&self) -> &str;
    /// Run on the context's hierarchy; `progress` sees the solver's events and returns
    /// `false` to cancel (then `Ok(None)`).
    fn run(&self, ctx: &CompareContext<'_>, progress: &mut dyn FnMut(&Event) -> bool) -> Result<Option<MethodRun>>;
}

/// A [`Method`] solved coarse to fine over the hierarchy ([`EggSolver::with_method`]),
/// from the Coons patch and the elasticity prolongations, as EGG is; `None` is EGG with
/// the options' operator and the context's assembler.
#[derive(Debug, Clone)]
pub(crate) struct HierarchyRun {
    name: String,
    method: Option<Arc<dyn MethodFactory>>,
}

/// Makes the method of a [`HierarchyRun`] for one hierarchy.
pub(crate) trait MethodFactory: Send + Sync + std::fmt::Debug {
    /// The method for `hierarchy`.
    fn method(&self, hierarchy: &Hierarchy) -> Arc<dyn Method>;
}

impl MethodFactory for QuasiConformalMethod {
    fn method(&self, _: &Hierarchy) -> Arc<dyn Method> {
        Arc::new(*self)
    }
}

/// The reference length of the weights is the domain's diameter (dimensionless `λ`).
impl MethodFactory for VariationalHarmonicMethod {
    fn method(&self, h: &Hierarchy) -> Arc<dyn Method> {
        Arc::new(VariationalHarmonicMethod { length: h.diameter, ..*self })
    }
}

impl HierarchyRun {
    /// A run called `name` of `method` (`None`: EGG).
    pub fn new(name: &str, method: Option<Arc<dyn MethodFactory>>) -> Self {
        Self { name: name.to_string(), method }
    }

    /// The coarse-to-fine solve on `h`, events to `progress`; `None` when cancelled.
    fn solve(
        &self,
        ctx: &CompareContext<'_>,
        h: &Arc<Hierarchy>,
        progress: &mut dyn FnMut(&Event) -> bool,
    ) -> Result<Option<Solution>> {
        let opts = ctx.options.solve.clone();
        let assembler = ctx.assembler.clone();
        let method: Arc<dyn Method> = match &self.method {
            Some(f) => f.method(h),
            None => Arc::new(EggMethod { operator: opts.operator, assembler: assembler.clone() }),
        };
        let mut solver = EggSolver::with_method(ctx.boundary, h.clone(), opts, assembler, method)?;
        for e in solver.by_ref() {
            if !progress(&e?) {
                return Ok(None);
            }
        }
        Ok(Some(solver.finish()?))
    }
}

impl Contender for HierarchyRun {
    fn name(&self) -> &str {
        &self.name
    }

    fn run(&self, ctx: &CompareContext<'_>, progress: &mut dyn FnMut(&Event) -> bool) -> Result<Option<MethodRun>> {
        let t0 = Instant::now();
        let sol = self.solve(ctx, ctx.hierarchy, progress)?;
        Ok(sol.map(|s| MethodRun::of_solution(&self.name, &s, t0.elapsed().as_secs_f64())))
    }
}

/// The measures of one map, computed the same way for every method.
#[derive(Debug, Clone, Serialize)]
pub struct Measures {
    /// The certificate's verdict (BIJ).
    pub verdict: Verdict,
    /// The certificate's message.
    pub certificate: String,
    /// `Q(x)` of eq. (45); `None` when the benchmark could not be solved on the map.
    pub q: Option<f64>,
    /// Winslow functional (eq. 16); `None` when `det J <= 0` at a quadrature point.
    pub winslow: Option<f64>,
    /// Liao functional `∫ g₁₁² + g₂₂² + 2 g₁₂²` (eq. 3).
    pub liao: f64,
    /// Area orthogonality `∫ g₁₁² + g₂₂²` (eq. 3).
    pub area_orthogonality: f64,
    /// Smallest per-element minimum of the scaled Jacobian `det J / (|x_ξ| |x_η|)`.
    pub scaled_jacobian_min: f64,
    /// Basis functions per direction of the map.
    pub shape: [usize; 2],
}

impl Measures {
    /// Certificate, functionals and the Poisson benchmark with length scales `scales`.
    pub fn of(map: &Surface, opts: &CompareOptions, scales: [f64; 2]) -> Result<Self> {
        let cert = certify(map, &opts.solve.certify)?;
        let q = quality(map);
        let f = q.functionals;
        Ok(Self {
            verdict: Verdict::of_certificate(&cert),
            certificate: cert.message(),
            q: poisson_benchmark(map, Some(scales)).ok().map(|p| p.q).filter(|v| v.is_finite()),
            winslow: f.winslow.is_finite().then_some(f.winslow),
            liao: f.liao,
            area_orthogonality: f.area_orthogonality,
            scaled_jacobian_min: q.scaled_jacobian.min,
            shape: map.shape(),
        })
    }
}

/// One row of the comparison.
#[derive(Debug, Clone, Serialize)]
pub struct CompareRow {
    /// Method name.
    pub method: String,
    /// Where it started ([`MethodChoice::start`]): `coons`, `hierarchy` or `egg`.
    pub start: &'static str,
    /// Nonlinear iterations (IT), continuation solves included; for Gravesen's methods
    /// the LP / QP subproblems solved.
    pub iterations: usize,
    /// Whether the method met its stopping rule.
    pub converged: bool,
    /// Why it did not converge, or the error that stopped it.
    pub failure: Option<String>,
    /// The measures of its map; `None` when the method failed without a map.
    pub measures: Option<Measures>,
    /// `Q(x) / Q(x_G)`.
    pub q_ratio: Option<f64>,
    /// Seconds of the run (measures not included).
    pub seconds: f64,
    /// What the run did beyond its iterations (`MethodRun::notes`).
    pub notes: Vec<String>,
    /// The map, when there is one.
    #[serde(skip)]
    pub map: Option<Surface>,
}

impl CompareRow {
    /// One word for the BIJ column: the certificate's verdict, `error` without a map.
    pub fn bij(&self) -> &'static str {
        self.measures.as_ref().map_or("error", |m| m.verdict.name())
    }
}

/// The outcome of [`compare`].
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// Name of the geometry.
    pub name: String,
    /// The basis every method used: `input` or `fitted`.
    pub basis: &'static str,
    /// Why the input basis was left for the fitted one (basis `auto`), if it was.
    pub basis_fallback: Option<String>,
    /// Degrees of the maps.
    pub degree: [usize; 2],
    /// Length scales of the Poisson benchmark.
    pub poisson_scales: [f64; 2],
    /// One row per method, EGG first.
    pub rows: Vec<CompareRow>,
}

impl Comparison {
    /// The row of `method`.
    pub fn row(&self, method: &str) -> Option<&CompareRow> {
        self.rows.iter().find(|r| r.method == method)
    }
}

/// What [`compare`] reports while it runs.
#[derive(Debug, Clone)]
pub enum CompareEvent {
    /// A method starts (`index` of `count`).
    Started {
        /// Method name.
        method: String,
        /// Its position.
        index: usize,
        /// Number of methods.
        count: usize,
    },
    /// An event of the method's solver.
    Solver(Event),
    /// A method's row is complete.
    Finished(Box<CompareRow>),
}

/// Run EGG and then each of `methods` (EGG is always first, listed or not; repeats are
/// dropped) on `boundary` with `opts` (module documentation). `progress` sees every
/// event and returns `false` to cancel: then `Ok(None)`.
pub fn compare(
    boundary: &Boundary,
    methods: &[MethodChoice],
    opts: &CompareOptions,
    assembler: Arc<dyn EggAssembler>,
    progress: &mut dyn FnMut(CompareEvent) -> bool,
) -> Result<Option<Comparison>> {
    opts.validate()?;
    let mut order = vec![MethodChoice::Egg];
    for &m in methods {
        if !order.contains(&m) {
            order.push(m);
        }
    }
    let count = order.len();
    if !progress(CompareEvent::Started { method: MethodChoice::Egg.name().into(), index: 0, count }) {
        return Ok(None);
    }
    // EGG decides the basis, as `winslow solve` does: the pipeline, with its fallback
    let t0 = Instant::now();
    let mut fallback = None;
    let egg = Pipeline::new(boundary.clone(), opts.solve.clone()).backend(assembler.clone()).run_keeping_hierarchy(
        &mut |stage| match stage {
            Stage::Solver(e) => progress(CompareEvent::Solver((*e).clone())),
            Stage::Fallback { reason } => {
                fallback = Some(reason.to_string());
                true
            }
            _ => true,
        },
    );
    let (sol, h) = match egg {
        Ok(out) => out,
        Err(Error::Cancelled) => return Ok(None),
        Err(e) => return Err(e),
    };
    let reference = MethodRun::of_solution(MethodChoice::Egg.name(), &sol, t0.elapsed().as_secs_f64());
    let scales = opts.poisson_scales.unwrap_or_else(|| default_scales(&reference.map));
    let basis = match h.basis.used {
        BasisChoice::Input => "input",
        BasisChoice::Fitted | BasisChoice::Auto => "fitted",
    };
    let mut out = Comparison {
        name: boundary.name.clone(),
        basis,
        basis_fallback: fallback,
        degree: reference.map.degrees(),
        poisson_scales: scales,
        rows: Vec::new(),
    };
    for (index, choice) in order.into_iter().enumerate() {
        let run = if choice == MethodChoice::Egg {
            Ok(Some(reference.clone()))
        } else {
            if !progress(CompareEvent::Started { method: choice.name().into(), index, count }) {
                return Ok(None);
            }
            let ctx = CompareContext {
                boundary,
                hierarchy: &h,
                options: opts,
                assembler: assembler.clone(),
                reference: Some(&reference),
            };
            let t = Instant::now();
            let run = choice.contender(opts).run(&ctx, &mut |e| progress(CompareEvent::Solver(e.clone())));
            run.map(|r| r.map(|r| MethodRun { seconds: t.elapsed().as_secs_f64(), ..r }))
        };
        let row = match run {
            Ok(None) => return Ok(None),
            Ok(Some(r)) => row_of(r, choice.start(opts), opts, scales, out.rows.first())?,
            Err(e) => CompareRow {
                method: choice.name().into(),
                start: choice.start(opts),
                iterations: 0,
                converged: false,
                failure: Some(e.to_string()),
                measures: None,
                q_ratio: None,
                seconds: 0.0,
                notes: Vec::new(),
                map: None,
            },
        };
        if !progress(CompareEvent::Finished(Box::new(row.clone()))) {
            return Ok(None);
        }
        out.rows.push(row);
    }
    Ok(Some(out))
}

/// The row of a run: its measures and `Q / Q(x_G)` against the reference row.
fn row_of(
    r: MethodRun,
    start: &'static str,
    opts: &CompareOptions,
    scales: [f64; 2],
    reference: Option<&CompareRow>,
) -> Result<CompareRow> {
    let measures = Measures::of(&r.map, opts, scales)?;
    let q_ref = match reference {
        Some(row) => row.measures.as_ref().and_then(|m| m.q),
        None => measures.q,
    };
    let q_ratio = match (measures.q, q_ref) {
        (Some(q), Some(g)) if g > 0.0 => Some(q / g),
        _ => None,
    };
    Ok(CompareRow {
        method: r.method,
        start,
        iterations: r.iterations,
        converged: r.converged,
        failure: r.failure,
        measures: Some(measures),
        q_ratio,
        seconds: r.seconds,
        notes: r.notes,
        map: Some(r.map),
    })
}

#[cfg(test)]
mod tests;
