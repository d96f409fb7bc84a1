//! `solve` and `solve_many`: the pipeline ([`Pipeline::run`]) with the GIL released, its
//! stages to an optional Python callback, Ctrl-C stopping the run through the observer;
//! many shapes on a pool of `workers` threads.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use serde_json::{json, Value};
use winslow::domain::LayoutReport;
use winslow::io::ReadOptions;
use winslow::multipatch::MultipatchSolution;
use winslow::pipeline::Observer;
use winslow::solve::report::Solution;
use winslow::solve::warm::WarmStart;
use winslow::{Document, Error, Input, Output, Pipeline, Stage, Surface};

use crate::convert::{json_to_py, to_py};
use crate::errors::{self, IntoPy};
use crate::geometry::{document_of, PyMap};
use crate::options::{self, Options};
use crate::runs::PyLayoutSolution;

/// A solved map with its report.
#[pyclass(name = "Solution", module = "winslow", frozen)]
#[derive(Debug, Clone)]
pub struct PySolution {
    pub name: String,
    pub map: PyMap,
    pub report: Value,
    pub verdict: String,
    /// Wall seconds of the pipeline's run inside Rust (fit to certificate).
    pub pipeline_seconds: f64,
}

/// How one shape was solved: cold by the pipeline (with the reason a warm start asked
/// for did not apply), from the previous map ([`Pipeline::warm_start`]), or as a layout
/// (a multipatch layout, domain or plane graph: one map per patch).
#[derive(Debug)]
pub enum Outcome {
    /// The pipeline's solution (its report's `warm_start` says why a start given was not
    /// used).
    Cold(Box<Solution>),
    /// Solved from the previous map; the shape's name.
    Warm(Box<WarmStart>, String),
    /// A layout's maps, with the automatic layout's report when the pipeline made it.
    Layout(Box<MultipatchSolution>, Option<Box<LayoutReport>>),
}

impl Outcome {
    /// The map to start the next shape of a family from: this one's, when bijective.
    pub fn start_for_next(&self) -> Option<&Surface> {
        match self {
            Outcome::Cold(s) => {
                matches!(s.report.outcome.verdict, winslow::Verdict::Certified | winslow::Verdict::DegenerateCorner)
                    .then_some(&s.map)
            }
            Outcome::Warm(w, _) => Some(&w.map),
            Outcome::Layout(..) => None,
        }
    }
}

/// Solve `input`: from `start` (the previous map of its family) when given and the warm
/// start applies and is certified ([`warm_start`]), else by the pipeline, every stage
/// to `observer`. A layout, domain or plane graph is solved cold (`start` does not
/// apply to one map per patch).
pub fn solve_input(
    input: Input,
    start: Option<&Surface>,
    opts: &winslow::SolveOptions,
    observer: &mut Observer<'_>,
) -> winslow::Result<Outcome> {
    let name = input.name().to_string();
    let multipatch = input.is_multipatch();
    let mut pipeline = Pipeline::new(input, opts.clone());
    if let Some(prev) = start.filter(|_| !multipatch) {
        pipeline = pipeline.warm_start(prev.clone());
    }
    match pipeline.run(observer)? {
        winslow::Solved::Warm(w) => Ok(Outcome::Warm(w, name)),
        winslow::Solved::Layout { solution, laid_out } => Ok(Outcome::Layout(solution, laid_out)),
        solved => Ok(Outcome::Cold(Box::new(solved.into_map()?))),
    }
}

impl PySolution {
    /// The solution of an [`Outcome`] that took `seconds`: a warm one's report is the
    /// [`WarmStart`] (with `"warm_start": {"used": true}`), a cold one's the pipeline's
    /// (with `"warm_start": {"used": false, "reason": ...}` when a start was given).
    pub fn of_outcome(outcome: Outcome, seconds: f64) -> PyResult<Self> {
        match outcome {
            Outcome::Cold(sol) => Self::of((*sol, seconds)),
            Outcome::Layout(..) => Err(errors::invalid("a layout's solution is a LayoutSolution, not a Solution")),
            Outcome::Warm(w, name) => {
                let report = serde_json::to_value(&*w).map_err(|e| Error::Invalid(e.to_string())).py_err()?;
                let verdict = w.verdict.name().to_string();
                Ok(Self {
                    name: name.clone(),
                    map: PyMap { name, map: w.map },
                    report,
                    verdict,
                    pipeline_seconds: seconds,
                })
            }
        }
    }

    fn of((sol, pipeline_seconds): (Solution, f64)) -> PyResult<Self> {
        let report = serde_json::to_value(&sol.report).map_err(|e| Error::Invalid(e.to_string())).py_err()?;
        let verdict = report["verdict"].as_str().unwrap_or_default().to_string();
        Ok(Self {
            name: sol.name.clone(),
            map: PyMap { name: sol.name, map: sol.map },
            report,
            verdict,
            pipeline_seconds,
        })
    }

    /// Write the map with its report (`.json`), or in another map format by extension.
    pub fn write_to(&self, path: &std::path::Path) -> winslow::Result<()> {
        let label = format!("verdict {}: {}", self.verdict, self.report["message"].as_str().unwrap_or_default());
        let extra = Some(json!({ "report": self.report }));
        winslow::write(path, &Output::Map { name: &self.name, map: &self.map.map, label: &label, extra })
    }
}

#[pymethods]
impl PySolution {
    /// Name of the geometry.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// The map of the finest level.
    #[getter]
    fn map(&self) -> PyMap {
        self.map.clone()
    }

    /// The verdict of the certificate: `"certified"`, `"degenerate-corner"`, `"folded"`,
    /// `"undecided"` or `"not-converged"`.
    #[getter]
    fn verdict(&self) -> &str {
        &self.verdict
    }

    /// Whether the map is proven bijective (certified, or degenerate only at corners the
    /// boundary forces).
    #[getter]
    fn certified(&self) -> bool {
        matches!(self.verdict.as_str(), "certified" | "degenerate-corner")
    }

    /// Wall seconds of the pipeline inside Rust (fit, solve, certificate; the progress
    /// callback included, the Python call around it not): the call's overhead is the
    /// rest of its time.
    #[getter]
    fn pipeline_seconds(&self) -> f64 {
        self.pipeline_seconds
    }

    /// The report (as `winslow solve` writes it) as a dict.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report)
    }

    /// Write the map with its report; the format by the extension.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.write_to(&path)).py_err()
    }

    /// The map document with its report as JSON text (what `write` puts in a `.json`).
    fn to_json(&self) -> String {
        let extra = Some(json!({ "report": self.report }));
        winslow::io::json::map_to_json(&self.name, &self.map.map, extra).to_string()
    }

    /// Pickled as its JSON text (for `multiprocessing`, Dask, Ray).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((py.import("winslow._native")?.getattr("solution_from_json")?, (self.to_json(),)))
    }

    fn __repr__(&self) -> String {
        format!("Solution(name={:?}, verdict={:?}, seconds={})", self.name, self.verdict, self.report["seconds"])
    }
}

/// The pipeline's input of a Python object: a `Boundary`, a `Map` (its boundary), a
/// ring `Document`, or a path to any of those.
pub fn input_of(py: Python<'_>, obj: &Bound<'_, PyAny>, reorient: bool) -> PyResult<Input> {
    input_of_document(document_arg(py, obj)?, reorient).py_err()
}

/// The document of an argument: a winslow object, or a path read (without the GIL).
pub fn document_arg(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Document> {
    match obj.extract::<PathBuf>() {
        Ok(path) if !obj.is_instance_of::<pyo3::types::PyBytes>() => py.detach(|| winslow::read(&path)).py_err(),
        _ => document_of(obj),
    }
}

/// The pipeline's input of a document for `solve_many` ([`Document::into_input`]: a
/// boundary checked as the CLI does, a map's boundary, a ring, a multipatch layout, a
/// domain or a plane graph); volume boundaries are refused (`winslow.solve` solves those
/// one at a time).
pub fn input_of_document(doc: Document, reorient: bool) -> winslow::Result<Input> {
    let kind = doc.kind();
    match doc.into_input(&ReadOptions { reorient })? {
        input @ (Input::Boundary(_) | Input::Ring(_)) => Ok(input),
        input if input.is_multipatch() => Ok(input),
        _ => Err(Error::DocumentKind {
            path: None,
            found: kind.into(),
            needed: "solve_many takes boundaries, maps, rings, layouts, domains and plane graphs \
                     (winslow.solve solves the others one at a time)"
                .into(),
        }),
    }
}

/// One stage as a JSON event for the progress callback.
pub fn event(stage: &Stage<'_>) -> Value {
    use winslow::Event;
    match stage {
        Stage::Fitted { input, hierarchy, method, .. } => json!({
            "stage": "fitted", "name": input.name(), "levels": hierarchy.levels.len(), "method": method.name(),
        }),
        Stage::Solver(Event::LevelStarted { level, levels, shape, unknowns, .. }) => json!({
            "stage": "level_started", "level": level, "levels": levels, "shape": shape, "unknowns": unknowns,
        }),
        Stage::Solver(Event::Iterate { level, iterate }) => {
            json!({ "stage": "iterate", "level": level, "iterate": iterate })
        }
        Stage::Solver(Event::LevelFinished(r)) => json!({ "stage": "level_finished", "report": r }),
        Stage::Fallback { reason } => json!({ "stage": "fallback", "reason": reason }),
        Stage::Layout(e) => json!({ "stage": "layout", "event": format!("{e:?}") }),
        Stage::LaidOut(auto) => json!({ "stage": "laid_out", "report": auto.report }),
        Stage::WarmStart { used, reason } => json!({ "stage": "warm_start", "used": used, "reason": reason }),
        Stage::Improve { method } => json!({ "stage": "improve", "method": method.name() }),
        Stage::ThbRound(r) => json!({ "stage": "thb_round", "round": r }),
        Stage::ThbFallback { thb } => json!({ "stage": "thb_fallback", "thb": thb }),
        _ => json!({ "stage": "other" }),
    }
}

/// One stage of a run for Python (called without the GIL): takes the GIL, checks pending
/// signals (Ctrl-C stops the run), hands `json()` to `progress` (a return value of
/// `False` stops the run). An exception goes to `raised` and stops the run. Whether to
/// go on.
pub fn notify(progress: Option<&Py<PyAny>>, raised: &mut Option<PyErr>, json: impl FnOnce() -> Value) -> bool {
    Python::attach(|py| {
        if let Err(e) = py.check_signals() {
            *raised = Some(e);
            return false;
        }
        let Some(cb) = progress else { return true };
        let ev = match json_to_py(py, &json()) {
            Ok(ev) => ev,
            Err(e) => {
                *raised = Some(e);
                return false;
            }
        };
        match cb.call1(py, (ev,)) {
            Ok(r) => !r.bind(py).is(pyo3::types::PyBool::new(py, false).to_owned()),
            Err(e) => {
                *raised = Some(e);
                false
            }
        }
    })
}

/// The result of a run whose stages went through [`notify`]: the exception raised
/// there first, then the run's own error.
pub fn outcome<T>(raised: Option<PyErr>, result: winslow::Result<T>) -> PyResult<T> {
    match raised {
        Some(e) => Err(e),
        None => result.py_err(),
    }
}

/// [`solve_input`] without the GIL, its stages as [`event`]s through [`notify`]; the
/// seconds it took.
fn run(
    py: Python<'_>,
    input: Input,
    start: Option<&Surface>,
    opts: &Options,
    progress: Option<&Py<PyAny>>,
) -> PyResult<(Outcome, f64)> {
    let mut raised = None;
    let t0 = Instant::now();
    let result =
        py.detach(|| solve_input(input, start, &opts.solve, &mut |s| notify(progress, &mut raised, || event(s))));
    let seconds = t0.elapsed().as_secs_f64();
    Ok((outcome(raised, result)?, seconds))
}

/// Solve the map of a boundary, map (its boundary) or ring: fit, coarse-to-fine EGG
/// solve, certificate, fallback (`winslow solve`). The GIL is released during the
/// solve; `progress(event: dict)` is called for every stage (returning `False` stops the
/// solve with a `WinslowError` of kind `"cancelled"`); Ctrl-C stops it with
/// `KeyboardInterrupt`. Options as keywords (see `winslow.SOLVE_OPTIONS`).
///
/// `start` (a `Map` or `Solution`: the previous shape of a family) solves a boundary on
/// that map's basis from the map moved onto the new boundary (`report["warm_start"]`
/// says whether it was used, and why not); a layout, domain or plane graph gives a
/// `LayoutSolution`.
#[pyfunction]
#[pyo3(signature = (input, *, start=None, progress=None, **options))]
pub fn solve<'py>(
    py: Python<'py>,
    input: Bound<'py, PyAny>,
    start: Option<Bound<'py, PyAny>>,
    progress: Option<Py<PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let opts = options::parse(options)?;
    let input = document_arg(py, &input)?.into_input(&ReadOptions { reorient: opts.reorient }).py_err()?;
    if input.is_multipatch() {
        if start.is_some() {
            return Err(errors::invalid("start= is for a boundary; a layout is solved cold"));
        }
        return Ok(Bound::new(py, crate::runs::solve_layout(py, input, &opts, progress.as_ref())?)?.into_any());
    }
    let start = start.map(|s| start_map(&s)).transpose()?;
    let (outcome, seconds) = run(py, input, start.as_ref(), &opts, progress.as_ref())?;
    Ok(Bound::new(py, PySolution::of_outcome(outcome, seconds)?)?.into_any())
}

/// The map of a `start=` argument (a `Map` or `Solution`).
fn start_map(obj: &Bound<'_, PyAny>) -> PyResult<Surface> {
    match document_of(obj)? {
        Document::Map { map, .. } => Ok(map),
        doc => Err(errors::to_py(&doc.wrong_kind(None, "start= needs a map"))),
    }
}

/// Solve many shapes on `workers` threads (default: all cores), the GIL released:
/// `inputs` any iterable of shapes (a list, or a generator of a family); a list in the
/// order of `inputs`, each a `Solution` (a `LayoutSolution` for a multipatch layout, a
/// domain or a plane graph, solved cold) or the `WinslowError` of that shape (not
/// raised). `on_result(index, result)` is called (with the GIL) as each finishes.
/// Ctrl-C stops the shapes not yet started and raises `KeyboardInterrupt`.
///
/// `same_basis=True` (a family of shapes whose sides share their bases): every shape is
/// solved on its input's basis (`basis="input"`, the boundary kept exactly), and a
/// solved map whose knot vectors differ from the first solved map's is replaced by a
/// `WinslowError` of kind `"invalid"`: the solutions returned are comparable coefficient
/// by coefficient.
///
/// `warm_start=True` (a family in sequence): the inputs are cut into `workers`
/// contiguous chains, each solved in order, every shape from the previous shape's map
/// (`solve(..., start=previous)`; the first of a chain, and a shape after one that is
/// not bijective, cold).
#[pyfunction]
#[pyo3(signature = (inputs, *, workers=None, on_result=None, same_basis=false, warm_start=false, **options))]
#[allow(clippy::too_many_arguments)]
pub fn solve_many<'py>(
    py: Python<'py>,
    inputs: Bound<'py, PyAny>,
    workers: Option<usize>,
    on_result: Option<Py<PyAny>>,
    same_basis: bool,
    warm_start: bool,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyList>> {
    // any iterable of shapes (a list, a generator of a family), but not one path
    if inputs.is_instance_of::<pyo3::types::PyString>()
        || inputs.is_instance_of::<pyo3::types::PyBytes>()
        || inputs.hasattr("__fspath__")?
    {
        return Err(errors::invalid(
            "inputs must be an iterable of shapes (boundaries, maps, rings or paths), not one path",
        ));
    }
    let inputs: Vec<Bound<'py, PyAny>> = inputs.try_iter()?.collect::<PyResult<_>>()?;
    let mut opts = options::parse(options)?;
    if same_basis {
        if options.is_some_and(|o| o.contains("basis").unwrap_or(false)) {
            return Err(errors::invalid("same_basis=True solves on the input basis: leave out basis="));
        }
        opts.solve.fit.basis = winslow::boundary::BasisChoice::Input;
    }
    // inputs that cannot be read are failures of their shape, like a failed solve
    let prepared: Vec<Result<Input, PyErr>> = inputs.iter().map(|i| input_of(py, i, opts.reorient)).collect();
    let n = prepared.len();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(workers.unwrap_or(0))
        .build()
        .map_err(|e| errors::invalid(format!("cannot start {workers:?} workers: {e}")))?;
    let stop = AtomicBool::new(false);
    let jobs: Vec<(usize, Input)> =
        prepared.iter().enumerate().filter_map(|(i, p)| p.as_ref().ok().map(|x| (i, x.clone()))).collect();
    let mut results: Vec<Option<PyResult<Solved1>>> = prepared.into_iter().map(|p| p.err().map(Err)).collect();
    let mut interrupted = None;
    // one chain per worker (warm start), else one job per shape
    let chains = if warm_start { pool.current_num_threads().max(1) } else { jobs.len().max(1) };
    let per = jobs.len().div_ceil(chains).max(1);
    let mut chunks: Vec<Vec<(usize, Input)>> = Vec::new();
    let mut jobs = jobs.into_iter().peekable();
    while jobs.peek().is_some() {
        chunks.push(jobs.by_ref().take(per).collect());
    }
    py.detach(|| {
        let (tx, rx) = mpsc::channel::<(usize, winslow::Result<(Outcome, f64)>)>();
        std::thread::scope(|s| {
            let (stop, opts) = (&stop, &opts.solve);
            s.spawn(move || {
                pool.install(|| {
                    chunks.into_par_iter().for_each_with(tx, |tx, chain| {
                        let mut prev: Option<Surface> = None;
                        for (i, input) in chain {
                            if stop.load(Ordering::Relaxed) {
                                let _ = tx.send((i, Err(Error::Cancelled)));
                                continue;
                            }
                            let t0 = Instant::now();
                            let r = solve_input(input, prev.as_ref(), opts, &mut |_| !stop.load(Ordering::Relaxed));
                            if warm_start {
                                if let Ok(o) = &r {
                                    prev = o.start_for_next().cloned().or(prev.take());
                                }
                            }
                            // the receiver lives until every sender is dropped
                            let _ = tx.send((i, r.map(|o| (o, t0.elapsed().as_secs_f64()))));
                        }
                    });
                });
            });
            loop {
                match rx.recv_timeout(Duration::from_millis(50)) {
                    Ok((i, r)) => {
                        let r = r.map_err(|e| errors::to_py(&e)).and_then(|(o, t)| Solved1::of(o, t));
                        if let Some(cb) = &on_result {
                            Python::attach(|py| -> PyResult<()> {
                                let arg = match &r {
                                    Ok(s) => s.clone().into_py(py)?,
                                    Err(e) => e.value(py).clone().into_any(),
                                };
                                cb.call1(py, (i, arg))?;
                                Ok(())
                            })
                            .unwrap_or_else(|e| {
                                stop.store(true, Ordering::Relaxed);
                                interrupted.get_or_insert(e);
                            });
                        }
                        results[i] = Some(r);
                    }
                    Err(mpsc::RecvTimeoutError::Timeout) => {
                        if let Err(e) = Python::attach(|py| py.check_signals()) {
                            stop.store(true, Ordering::Relaxed);
                            interrupted.get_or_insert(e);
                        }
                    }
                    Err(mpsc::RecvTimeoutError::Disconnected) => break,
                }
            }
        });
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    if same_basis {
        one_basis(&mut results);
    }
    let items = results
        .into_iter()
        .take(n)
        .map(|r| -> PyResult<Bound<'py, PyAny>> {
            match r {
                Some(Ok(s)) => s.into_py(py),
                Some(Err(e)) => Ok(e.value(py).clone().into_any()),
                None => Ok(errors::to_py(&Error::Cancelled).value(py).clone().into_any()),
            }
        })
        .collect::<PyResult<Vec<_>>>()?;
    PyList::new(py, items)
}

/// One result of `solve_many`: a map's [`PySolution`], or a layout's
/// [`PyLayoutSolution`].
#[derive(Debug, Clone)]
enum Solved1 {
    Map(Box<PySolution>),
    Layout(Box<PyLayoutSolution>),
}

impl Solved1 {
    fn of(outcome: Outcome, seconds: f64) -> PyResult<Self> {
        match outcome {
            Outcome::Layout(sol, laid_out) => {
                Ok(Self::Layout(Box::new(PyLayoutSolution::of(*sol, laid_out.as_deref())?)))
            }
            o => PySolution::of_outcome(o, seconds).map(|s| Self::Map(Box::new(s))),
        }
    }

    fn into_py(self, py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
        Ok(match self {
            Self::Map(s) => Bound::new(py, *s)?.into_any(),
            Self::Layout(s) => Bound::new(py, *s)?.into_any(),
        })
    }
}

/// Replace every solution whose knot vectors differ from the first solution's by an
/// error naming the difference, and every layout's (one map per patch has no one basis).
fn one_basis(results: &mut [Option<PyResult<Solved1>>]) {
    for (i, r) in results.iter_mut().enumerate() {
        if let Some(Ok(Solved1::Layout(_))) = r {
            let message =
                format!("same_basis: shape {i} is a layout (one map per patch), not one map on a shared basis");
            *r = Some(Err(errors::invalid(message)));
        }
    }
    let first = results.iter().find_map(|r| match r {
        Some(Ok(Solved1::Map(s))) => Some((s.name.clone(), s.map.map.knots.clone())),
        _ => None,
    });
    let Some((name, knots)) = first else { return };
    for r in results.iter_mut() {
        if let Some(Ok(Solved1::Map(s))) = r {
            if s.map.map.knots != knots {
                let [a, b] = s.map.map.shape();
                let message = format!(
                    "same_basis: the map of {} ({a}x{b} functions) is not on the basis of {name}'s map ({}x{} functions)",
                    s.name,
                    knots[0].num_basis(),
                    knots[1].num_basis()
                );
                *r = Some(Err(errors::invalid(message)));
            }
        }
    }
}

/// The certificate of a map (`winslow check`): `{"verdict": ..., "certificate": {...}}`.
#[pyfunction]
pub fn check<'py>(py: Python<'py>, map: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let doc = document_of(&map)?;
    let Document::Map { map, .. } = doc else {
        return Err(errors::to_py(&doc.wrong_kind(None, "check certifies a map")));
    };
    let cert = py.detach(|| winslow::certify(&map, &Default::default())).py_err()?;
    let verdict = winslow::Verdict::of_certificate(&cert);
    to_py(py, &json!({ "verdict": verdict, "certificate": cert }))
}

/// A `Solution` from the JSON text of a map document with its report (`Solution.to_json`).
#[pyfunction]
pub fn solution_from_json(text: &str) -> PyResult<PySolution> {
    let doc = winslow::io::parse_document(text).py_err()?;
    let value: Value = serde_json::from_str(text).map_err(|e| Error::Invalid(e.to_string())).py_err()?;
    let Document::Map { name, map } = doc else {
        return Err(errors::to_py(&doc.wrong_kind(None, "a solution is a map with its report")));
    };
    let report = value.get("report").cloned().unwrap_or(Value::Null);
    let verdict = report["verdict"].as_str().unwrap_or_default().to_string();
    Ok(PySolution { name: name.clone(), map: PyMap { name, map }, report, verdict, pipeline_seconds: f64::NAN })
}
