//! A solve in a background thread: the stages of the core's [`Pipeline`] (the fit, the
//! solver's event stream) are forwarded over a channel to the UI, which keeps the
//! progress (level, iteration, residual) and the residual history for the live plot. A
//! cancel flag is checked at every stage; the observer then stops the pipeline. The same job runs a comparison of methods (paper §10,
//! [`compare`]): every method's solver events stream the same way, and the comparison,
//! one map per method, arrives at the end. A multipatch layout (§11.2; a laid-out domain
//! or plane graph) streams the layout solve's events and ends with every patch's map.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, TryRecvError};
use std::sync::Arc;
use std::thread::JoinHandle;

use winslow::boundary::ring::Ring;
use winslow::methods::egg::CpuAssembler;
use winslow::multipatch::layout::Layout;
use winslow::multipatch::solve::{LayoutEvent, MultipatchSolution};
use winslow::pipeline::compare::{compare, CompareEvent, CompareOptions, Comparison, MethodChoice};
use winslow::pipeline::{Solved, ThbSolution};
use winslow::solve::hierarchical::ThbRound;
use winslow::solve::options::SolveOptions;
use winslow::solve::report::InitialGuess;
use winslow::solve::report::Solution;
use winslow::solve::solver::Event;
use winslow::{Boundary, Input, Pipeline, Stage};

/// A message from the solving thread.
#[derive(Debug)]
pub enum Msg {
    /// The boundary was fitted: this many hierarchy levels, at this absolute tolerance.
    Fitted {
        /// Hierarchy levels of the fit.
        levels: usize,
        /// Absolute fit tolerance.
        tolerance: f64,
    },
    /// An event of the solver stream.
    Event(Event),
    /// A method of a comparison starts (`index` of `count`).
    Method {
        /// Method name.
        method: String,
        /// Its position.
        index: usize,
        /// Number of methods.
        count: usize,
    },
    /// A round of the THB defect correction finished (its offending and marked cells,
    /// functions, Newton iterations).
    ThbRound(ThbRound),
    /// An event of a layout's solve (its bases, a round of patch solves, the free stage).
    Layout(LayoutEvent),
    /// The solve finished.
    Finished(Box<Solution>),
    /// The solve finished with a THB map (`--refinement thb`, or `auto` on rounded
    /// point-cloud corners: the THB defect correction of paper §8.2 ran).
    FinishedThb(Box<ThbSolution>),
    /// The solve of a layout finished: every patch's map, certificate and the report.
    SolvedLayout(Box<MultipatchSolution>),
    /// The comparison finished.
    Compared(Box<Comparison>),
    /// The solve failed.
    Failed(String),
    /// The cancel flag was seen; the solver was dropped.
    Cancelled,
}

/// Run the pipeline on `input` (a boundary, a ring: paper §11.1, or a multipatch layout:
/// §11.2), sending every stage to `send`; checks `cancel` before the fit and at every
/// stage. Always ends with `Finished` (`SolvedLayout` for a layout), `Failed` or
/// `Cancelled`. With the default basis `auto`, a map on the input
/// basis that is not certified is solved again on the fitted basis, as the CLI does.
pub fn run(input: Input, opts: &SolveOptions, cancel: &AtomicBool, send: &mut dyn FnMut(Msg)) {
    let cancelled = || cancel.load(Ordering::Relaxed);
    if cancelled() {
        return send(Msg::Cancelled);
    }
    let out = Pipeline::new(input, opts.clone()).run(&mut |stage| {
        match stage {
            Stage::Fitted { hierarchy, .. } => {
                send(Msg::Fitted { levels: hierarchy.levels.len(), tolerance: hierarchy.physical_tol_abs() })
            }
            Stage::Solver(e) => send(Msg::Event((*e).clone())),
            Stage::Layout(e) => send(Msg::Layout((*e).clone())),
            Stage::ThbRound(r) => send(Msg::ThbRound((*r).clone())),
            _ => {}
        }
        !cancelled()
    });
    match out {
        Ok(Solved::Map(sol)) => send(Msg::Finished(sol)),
        Ok(Solved::Layout { solution, .. }) => send(Msg::SolvedLayout(solution)),
        Ok(Solved::Thb(t)) => send(Msg::FinishedThb(t)),
        Ok(other) => send(Msg::Failed(format!(
            "the pipeline returned a result the viewer does not draw (verdict {})",
            other.verdict().name()
        ))),
        Err(winslow::Error::Cancelled) => send(Msg::Cancelled),
        Err(e) => send(Msg::Failed(e.to_string())),
    }
}

/// Compare `methods` on `boundary` (EGG first, then each on EGG's basis), sending every
/// solver event and each method's start to `send`; checks `cancel` between events.
/// Always ends with `Compared`, `Failed` or `Cancelled`.
pub fn run_compare(
    boundary: &Boundary,
    methods: &[MethodChoice],
    opts: &CompareOptions,
    cancel: &AtomicBool,
    send: &mut dyn FnMut(Msg),
) {
    let mut progress = |e: CompareEvent| {
        if cancel.load(Ordering::Relaxed) {
            return false;
        }
        match e {
            CompareEvent::Started { method, index, count } => send(Msg::Method { method, index, count }),
            CompareEvent::Solver(e) => send(Msg::Event(e)),
            CompareEvent::Finished(_) => {}
        }
        true
    };
    let out = compare(boundary, methods, opts, Arc::new(CpuAssembler), &mut progress);
    match out {
        Ok(Some(c)) => send(Msg::Compared(Box::new(c))),
        Ok(None) => send(Msg::Cancelled),
        Err(e) => send(Msg::Failed(format!("comparing methods: {e}"))),
    }
}

/// One point of the residual history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualPoint {
    /// Iterate number over the whole solve (for the plot's x axis).
    pub step: usize,
    /// Level index.
    pub level: usize,
    /// Iteration within the level (0 = initial guess).
    pub iteration: usize,
    /// `||F||`.
    pub residual: f64,
    /// Scaled (dimensionless) residual.
    pub scaled_residual: f64,
}

/// Where the solve stands.
#[derive(Debug, Clone, Default)]
pub struct Progress {
    /// Fit levels, once fitted.
    pub fit_levels: Option<usize>,
    /// Current level index and the number of levels.
    pub level: Option<(usize, usize)>,
    /// Basis shape and unknowns of the current level.
    pub shape: [usize; 2],
    /// Scalar unknowns of the current level.
    pub unknowns: usize,
    /// Initial guess of the current level.
    pub initial_guess: Option<InitialGuess>,
    /// Every iterate so far.
    pub history: Vec<ResidualPoint>,
    /// Levels finished (converged or not).
    pub levels_done: usize,
    /// In a comparison: the method being solved, its position and the number of methods.
    pub method: Option<(String, usize, usize)>,
    /// In a layout's solve: the last stage, in words.
    pub layout: Option<String>,
    /// In a THB defect correction: the last round, in words.
    pub thb: Option<String>,
}

impl Progress {
    /// Take one message into account.
    pub fn apply(&mut self, msg: &Msg) {
        match msg {
            Msg::Fitted { levels, .. } => self.fit_levels = Some(*levels),
            Msg::Event(Event::LevelStarted { level, levels, shape, unknowns, initial_guess }) => {
                self.level = Some((*level, *levels));
                self.shape = *shape;
                self.unknowns = *unknowns;
                self.initial_guess = Some(*initial_guess);
            }
            Msg::Event(Event::Iterate { level, iterate }) => self.history.push(ResidualPoint {
                step: self.history.len(),
                level: *level,
                iteration: iterate.iteration,
                residual: iterate.residual,
                scaled_residual: iterate.scaled_residual,
            }),
            Msg::Event(Event::LevelFinished(_)) => self.levels_done += 1,
            Msg::Method { method, index, count } => {
                self.method = Some((method.clone(), *index, *count));
                self.level = None;
            }
            Msg::Layout(e) => self.layout = Some(layout_text(e)),
            Msg::ThbRound(r) => {
                self.thb = Some(format!(
                    "THB round {}: {} offending cells, {} marked; {} functions on {} levels, {} iterations",
                    r.round, r.offending_cells, r.marked_cells, r.functions, r.levels, r.iterations
                ))
            }
            Msg::Finished(_)
            | Msg::FinishedThb(_)
            | Msg::SolvedLayout(_)
            | Msg::Compared(_)
            | Msg::Failed(_)
            | Msg::Cancelled => {}
        }
    }

    /// The last iterate.
    pub fn last(&self) -> Option<&ResidualPoint> {
        self.history.last()
    }

    /// One line of text: the method of a comparison, level, iteration, residual.
    pub fn text(&self) -> String {
        match &self.method {
            Some((m, index, count)) => format!("method {m} ({}/{count}): {}", index + 1, self.level_text()),
            None => self.level_text(),
        }
    }

    fn level_text(&self) -> String {
        if let Some(l) = self.layout.as_ref().or(self.thb.as_ref()) {
            return l.clone();
        }
        let Some((level, levels)) = self.level else {
            return match self.fit_levels {
                Some(n) => format!("fitted {n} hierarchy levels; starting"),
                None => "fitting the boundary".to_string(),
            };
        };
        let mut s = format!(
            "level {}/{levels}: {}x{} basis, {} unknowns",
            level + 1,
            self.shape[0],
            self.shape[1],
            self.unknowns
        );
        if let Some(p) = self.last().filter(|p| p.level == level) {
            s.push_str(&format!(
                "; iteration {}, |F| = {:.3e} (scaled {:.3e})",
                p.iteration, p.residual, p.scaled_residual
            ));
        }
        s
    }
}

/// One line on a layout solve's event.
fn layout_text(e: &LayoutEvent) -> String {
    match e {
        LayoutEvent::Bases { patches, classes, basis_functions } => {
            format!("{patches} patches, {classes} interface classes, {basis_functions} basis functions; solving the patches")
        }
        LayoutEvent::Round { round, solved, failing } if failing.is_empty() => {
            format!("round {round}: {solved} patches solved, all certified")
        }
        LayoutEvent::Round { round, solved, failing } => {
            format!("round {round}: {solved} patches solved; not certified: {}", failing.join(", "))
        }
        LayoutEvent::Free { functional } => format!("free interfaces ({functional})"),
        _ => "solving the layout".to_string(),
    }
}

/// State of a solve job.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum JobState {
    /// The thread is working.
    Running,
    /// Cancel was asked; waiting for the thread to see it.
    Cancelling,
    /// Finished with a map (taken by [`SolveJob::poll`]).
    Finished,
    /// Failed with this message.
    Failed(String),
    /// Cancelled.
    Cancelled,
}

/// A background solve.
#[derive(Debug)]
pub struct SolveJob {
    /// Name of the geometry.
    pub name: String,
    /// Where it stands.
    pub state: JobState,
    /// Progress and residual history.
    pub progress: Progress,
    rx: Receiver<Msg>,
    cancel: Arc<AtomicBool>,
    handle: Option<JoinHandle<()>>,
    /// A finished comparison, until taken ([`SolveJob::take_comparison`]).
    comparison: Option<Comparison>,
    /// A finished layout solve, until taken ([`SolveJob::take_layout`]).
    layout: Option<MultipatchSolution>,
    /// A finished THB solve, until taken ([`SolveJob::take_thb`]).
    thb: Option<ThbSolution>,
}

impl SolveJob {
    /// Start solving `boundary` in a new thread; `notify` is called after every message
    /// (the UI passes `request_repaint`).
    pub fn start(boundary: Boundary, opts: SolveOptions, notify: impl Fn() + Send + 'static) -> Self {
        let name = boundary.name.clone();
        Self::spawn(name, notify, move |cancel, send| run(Input::Boundary(boundary), &opts, cancel, send))
    }

    /// Start comparing `methods` on `boundary` in a new thread ([`run_compare`]); the
    /// comparison is taken with [`SolveJob::take_comparison`] once finished.
    pub fn start_compare(
        boundary: Boundary,
        methods: Vec<MethodChoice>,
        opts: CompareOptions,
        notify: impl Fn() + Send + 'static,
    ) -> Self {
        let name = boundary.name.clone();
        Self::spawn(name, notify, move |cancel, send| run_compare(&boundary, &methods, &opts, cancel, send))
    }

    /// Start solving a ring ([`run`]) in a new thread.
    pub fn start_ring(ring: Ring, opts: SolveOptions, notify: impl Fn() + Send + 'static) -> Self {
        let name = ring.name.clone();
        Self::spawn(name, notify, move |cancel, send| run(Input::Ring(ring), &opts, cancel, send))
    }

    /// Start solving a multipatch layout ([`run`]) in a new thread; the solution is
    /// taken with [`SolveJob::take_layout`] once finished.
    pub fn start_layout(layout: Layout, opts: SolveOptions, notify: impl Fn() + Send + 'static) -> Self {
        let name = layout.name.clone();
        Self::spawn(name, notify, move |cancel, send| run(Input::Layout(layout), &opts, cancel, send))
    }

    fn spawn(
        name: String,
        notify: impl Fn() + Send + 'static,
        work: impl FnOnce(&AtomicBool, &mut dyn FnMut(Msg)) + Send + 'static,
    ) -> Self {
        let (tx, rx) = channel();
        let cancel = Arc::new(AtomicBool::new(false));
        let flag = cancel.clone();
        let handle = std::thread::Builder::new()
            .name("winslow-solve".into())
            .spawn(move || {
                work(&flag.clone(), &mut |m| {
                    // the UI may have gone away: then nobody listens and we stop at the next check
                    if tx.send(m).is_err() {
                        flag.store(true, Ordering::Relaxed);
                    }
                    notify();
                })
            })
            .ok();
        let state =
            if handle.is_some() { JobState::Running } else { JobState::Failed("could not start a thread".into()) };
        Self {
            name,
            state,
            progress: Progress::default(),
            rx,
            cancel,
            handle,
            comparison: None,
            layout: None,
            thb: None,
        }
    }

    /// The comparison, once, after a comparison job finished.
    pub fn take_comparison(&mut self) -> Option<Comparison> {
        self.comparison.take()
    }

    /// The layout's solution, once, after a layout job finished.
    pub fn take_layout(&mut self) -> Option<MultipatchSolution> {
        self.layout.take()
    }

    /// The THB map, once, after a solve that ended with one ([`Msg::FinishedThb`]).
    pub fn take_thb(&mut self) -> Option<ThbSolution> {
        self.thb.take()
    }

    /// Ask the thread to stop at the next event.
    pub fn cancel(&mut self) {
        if self.state == JobState::Running {
            self.cancel.store(true, Ordering::Relaxed);
            self.state = JobState::Cancelling;
        }
    }

    /// Whether the thread is still at work.
    pub fn is_active(&self) -> bool {
        matches!(self.state, JobState::Running | JobState::Cancelling)
    }

    /// Apply one message of the solver thread; the solution when it is the last one.
    fn take(&mut self, msg: Msg) -> Option<Solution> {
        self.progress.apply(&msg);
        match msg {
            Msg::Finished(s) => {
                self.state = JobState::Finished;
                return Some(*s);
            }
            Msg::Compared(c) => {
                self.state = JobState::Finished;
                self.comparison = Some(*c);
            }
            Msg::SolvedLayout(s) => {
                self.state = JobState::Finished;
                self.layout = Some(*s);
            }
            Msg::FinishedThb(s) => {
                self.state = JobState::Finished;
                self.thb = Some(*s);
            }
            Msg::Failed(e) => self.state = JobState::Failed(e),
            Msg::Cancelled => self.state = JobState::Cancelled,
            _ => {}
        }
        None
    }

    /// Take the messages that arrived; returns the solution once, when it arrives.
    pub fn poll(&mut self) -> Option<Solution> {
        let mut solution = None;
        loop {
            match self.rx.try_recv() {
                Ok(msg) => {
                    if let Some(sol) = self.take(msg) {
                        solution = Some(sol);
                    }
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => {
                    if self.is_active() {
                        self.state = JobState::Failed("the solver thread stopped without a result".into());
                    }
                    break;
                }
            }
        }
        if !self.is_active() {
            if let Some(h) = self.handle.take() {
                let _ = h.join();
            }
        }
        solution
    }

    /// Block until the job ends (tests, `--screenshot`), then [`Self::poll`].
    pub fn wait(&mut self) -> Option<Solution> {
        let mut solution = None;
        while self.is_active() {
            match self.rx.recv() {
                Ok(msg) => {
                    if let Some(sol) = self.take(msg) {
                        solution = Some(sol);
                    }
                }
                Err(_) => {
                    self.state = JobState::Failed("the solver thread stopped without a result".into());
                }
            }
        }
        solution.or_else(|| self.poll())
    }
}

impl Drop for SolveJob {
    fn drop(&mut self) {
        // stop the thread at its next event; it ends on its own
        self.cancel.store(true, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use winslow::boundary::{Analytic, SideCurve};
    use winslow::solve::report::Verdict;

    /// Quarter annulus `1 <= r <= 2`, a solve of a fraction of a second.
    fn annulus() -> Boundary {
        let arc = |r: f64| {
            SideCurve::Analytic(Analytic::new(move |t| {
                let a = std::f64::consts::FRAC_PI_2 * t;
                [r * a.cos(), r * a.sin()]
            }))
        };
        let ray = |a: f64| SideCurve::Analytic(Analytic::new(move |t| [(1.0 + t) * a.cos(), (1.0 + t) * a.sin()]));
        Boundary { name: "annulus".into(), sides: [ray(0.0), arc(2.0), ray(std::f64::consts::FRAC_PI_2), arc(1.0)] }
    }

    fn quick() -> SolveOptions {
        let mut o = SolveOptions::default();
        o.levels.min_elements = 4;
        o.report.sample = 64;
        o
    }

    #[test]
    fn run_streams_levels_iterates_and_the_solution() {
        let mut msgs = Vec::new();
        run(annulus().into(), &quick(), &AtomicBool::new(false), &mut |m| msgs.push(m));
        assert!(matches!(msgs.first(), Some(Msg::Fitted { levels, .. }) if *levels >= 1));
        assert!(matches!(msgs.get(1), Some(Msg::Event(Event::LevelStarted { level: 0, .. }))));
        let Some(Msg::Finished(sol)) = msgs.last() else { panic!("{:?}", msgs.last()) };
        assert_eq!(sol.report.outcome.verdict, Verdict::Certified);
        let mut p = Progress::default();
        for m in &msgs {
            p.apply(m);
        }
        // the history is the solver's own residual record, level by level
        let recorded: Vec<f64> = sol.report.solve.levels.iter().flat_map(|l| l.residuals.clone()).collect();
        let streamed: Vec<f64> = p.history.iter().map(|h| h.residual).collect();
        assert_eq!(streamed, recorded);
        assert_eq!(p.levels_done, sol.report.solve.levels.len());
        assert!(p.history.windows(2).all(|w| w[1].step == w[0].step + 1));
        // converged: the last scaled residual is below the tolerance
        assert!(p.last().unwrap().scaled_residual < quick().nonlinear.tol);
        assert!(p.text().starts_with(&format!(
            "level {}/{}",
            sol.report.solve.levels.len(),
            sol.report.solve.levels.len()
        )));
    }

    #[test]
    fn cancel_flag_stops_between_events() {
        let cancel = AtomicBool::new(false);
        let mut msgs = Vec::new();
        run(annulus().into(), &quick(), &cancel, &mut |m| {
            if matches!(m, Msg::Event(Event::Iterate { .. })) {
                cancel.store(true, Ordering::Relaxed);
            }
            msgs.push(m);
        });
        // exactly one iterate got through, then the flag was seen
        let iterates = msgs.iter().filter(|m| matches!(m, Msg::Event(Event::Iterate { .. }))).count();
        assert_eq!(iterates, 1);
        assert!(matches!(msgs.last(), Some(Msg::Cancelled)));
        assert!(!msgs.iter().any(|m| matches!(m, Msg::Finished(_))));
    }

    /// A comparison streams each method's start and solver events, and ends with one
    /// row per method, EGG first; the progress line names the method.
    #[test]
    fn run_compare_streams_methods_and_the_comparison() {
        let mut opts = CompareOptions::default();
        opts.solve = quick();
        let mut msgs = Vec::new();
        run_compare(&annulus(), &[MethodChoice::Vhm], &opts, &AtomicBool::new(false), &mut |m| msgs.push(m));
        let started: Vec<String> = msgs
            .iter()
            .filter_map(|m| if let Msg::Method { method, .. } = m { Some(method.clone()) } else { None })
            .collect();
        assert_eq!(started, ["egg", "vhm"]);
        let Some(Msg::Compared(c)) = msgs.last() else { panic!("{:?}", msgs.last()) };
        let names: Vec<&str> = c.rows.iter().map(|r| r.method.as_str()).collect();
        assert_eq!(names, ["egg", "vhm"]);
        let mut p = Progress::default();
        for m in &msgs {
            p.apply(m);
        }
        assert!(p.text().starts_with("method vhm (2/2): level"), "{}", p.text());
        // cancelled at the first event
        let cancel = AtomicBool::new(true);
        let mut msgs = Vec::new();
        run_compare(&annulus(), &[MethodChoice::Vhm], &opts, &cancel, &mut |m| msgs.push(m));
        assert!(matches!(msgs.last(), Some(Msg::Cancelled)), "{msgs:?}");
    }

    /// The automatic layout of the bundled pentagon (five patches).
    fn pentagon() -> Layout {
        let winslow::Document::Domain(d) = winslow::read(&winslow::testutil::data("domains/pentagon.json")).unwrap()
        else {
            panic!("not a domain")
        };
        winslow::domain::auto_layout(&d, &Default::default()).unwrap().layout
    }

    /// A layout streams its bases and rounds and ends with every patch's map; the
    /// progress line is the last stage; the cancel flag stops it at the first event.
    #[test]
    fn run_streams_a_layout_solve() {
        let mut msgs = Vec::new();
        run(Input::Layout(pentagon()), &quick(), &AtomicBool::new(false), &mut |m| msgs.push(m));
        assert!(matches!(msgs.first(), Some(Msg::Layout(LayoutEvent::Bases { patches: 5, .. }))), "{msgs:?}");
        let Some(Msg::SolvedLayout(sol)) = msgs.last() else { panic!("{:?}", msgs.last()) };
        assert_eq!(sol.patches.len(), 5);
        assert_eq!(sol.report.verdict, Verdict::Certified);
        let mut p = Progress::default();
        for m in &msgs {
            p.apply(m);
        }
        assert!(p.text().contains("all certified") || p.text().starts_with("free interfaces"), "{}", p.text());

        let cancel = AtomicBool::new(false);
        let mut msgs = Vec::new();
        run(Input::Layout(pentagon()), &quick(), &cancel, &mut |m| {
            cancel.store(true, Ordering::Relaxed);
            msgs.push(m);
        });
        assert_eq!(msgs.len(), 2, "{msgs:?}");
        assert!(matches!(msgs.last(), Some(Msg::Cancelled)), "{msgs:?}");

        let mut job = SolveJob::start_layout(pentagon(), quick(), || {});
        assert!(job.wait().is_none(), "a layout's solution is not one map");
        assert_eq!(job.state, JobState::Finished);
        assert_eq!(job.take_layout().map(|s| s.patches.len()), Some(5));
        assert!(job.take_layout().is_none(), "handed out once");
    }

    #[test]
    fn fit_failure_is_reported() {
        // a side that is not a curve: all four corners at one point
        let dot = SideCurve::Analytic(Analytic::new(|_| [0.0, 0.0]));
        let b = Boundary { name: "dot".into(), sides: [dot.clone(), dot.clone(), dot.clone(), dot] };
        let mut msgs = Vec::new();
        run(b.into(), &quick(), &AtomicBool::new(false), &mut |m| msgs.push(m));
        assert!(matches!(msgs.last(), Some(Msg::Failed(_))), "{msgs:?}");
    }

    #[test]
    fn job_state_machine() {
        let mut job = SolveJob::start(annulus(), quick(), || {});
        assert!(job.is_active());
        let sol = job.wait().expect("a solution");
        assert_eq!(job.state, JobState::Finished);
        assert_eq!(sol.name, "annulus");
        assert!(job.poll().is_none(), "the solution is handed out once");
        // cancel after the end changes nothing
        job.cancel();
        assert_eq!(job.state, JobState::Finished);

        let mut refined = quick();
        refined.levels.refine = 2;
        let mut job = SolveJob::start(annulus(), refined, || {});
        job.cancel();
        assert_eq!(job.state, JobState::Cancelling);
        // the flag is set long before a refined solve could end
        assert!(job.wait().is_none());
        assert_eq!(job.state, JobState::Cancelled);
        assert!(!job.is_active());
    }
}
