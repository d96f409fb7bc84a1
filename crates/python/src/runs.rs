//! The runs built on the pipeline, each calling the core entry its command uses: layouts
//! (`winslow layout`: [`auto_layout`], [`graph_layout`]; `winslow solve LAYOUT`: the
//! pipeline's [`Input::Layout`]), `improve` (`winslow solve --start MAP`: [`improve`]),
//! `compare` (`winslow compare`: [`compare`]) and `sweep` (`winslow sweep`: [`Sweep`]).

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde_json::{json, Value};
use winslow::domain::{auto_layout, graph_layout, LayoutOptions};
use winslow::io::multipatch::Patches;
use winslow::io::ReadOptions;
use winslow::methods::egg::EggMethod;
use winslow::methods::quasi_conformal::QcHessian;
use winslow::methods::Method;
use winslow::multipatch::{Layout, MultipatchSolution};
use winslow::pipeline::compare::{compare as core_compare, CompareEvent, CompareOptions, MethodChoice};
use winslow::pipeline::sweep::{Seam, Sweep, SweepOptions};
use winslow::solve::improve::Improve;
use winslow::{Document, Error, Output, Pipeline, Solved, Verdict};

use crate::convert::{json_to_py, to_py};
use crate::errors::{self, invalid, IntoPy};
use crate::geometry::{PyDocument, PyMap};
use crate::options::{self, Options};
use crate::solve::{document_arg, notify, outcome, PySolution};

/// A layout, or the layout made from a general domain or plane graph (with the report of
/// the automatic layout, as `winslow solve DOMAIN` puts it under `auto_layout`); the
/// other documents given back.
pub fn layout_of(doc: Document, opts: &Options) -> winslow::Result<Result<(Layout, Option<Value>), Document>> {
    let lo = LayoutOptions { fit: opts.solve.fit, ..Default::default() };
    let auto = match doc {
        Document::Layout(l) | Document::Multipatch(l) => return Ok(Ok((l, None))),
        Document::Domain(d) => auto_layout(&d, &lo)?,
        Document::Graph(g) => graph_layout(&g, &lo)?,
        doc => return Ok(Err(doc)),
    };
    let made = serde_json::to_value(&auto.report).map_err(|e| Error::Invalid(e.to_string()))?;
    Ok(Ok((auto.layout, Some(made))))
}

/// The solved maps of a layout with the report `winslow solve LAYOUT` writes.
#[pyclass(name = "LayoutSolution", module = "winslow", frozen)]
#[derive(Debug, Clone)]
pub struct PyLayoutSolution {
    sol: MultipatchSolution,
    report: Value,
}

impl PyLayoutSolution {
    fn patches(&self) -> winslow::Result<Output<'_>> {
        let mut p = Patches::of_solution(&self.sol)?;
        p.report = self.report.clone();
        Ok(Output::Multipatch(p))
    }
}

#[pymethods]
impl PyLayoutSolution {
    /// Name of the layout.
    #[getter]
    fn name(&self) -> &str {
        &self.sol.layout.name
    }

    /// The worst verdict over the patches.
    #[getter]
    fn verdict(&self) -> &'static str {
        self.sol.report.verdict.name()
    }

    /// Whether every patch is proven bijective.
    #[getter]
    fn certified(&self) -> bool {
        matches!(self.sol.report.verdict, Verdict::Certified | Verdict::DegenerateCorner)
    }

    /// One `Map` per patch, in the layout's order (named after the patches).
    #[getter]
    fn maps(&self) -> Vec<PyMap> {
        self.sol.patches.iter().map(|p| PyMap { name: p.name.clone(), map: p.map.clone() }).collect()
    }

    /// The report (as `winslow solve LAYOUT` writes it; `auto_layout` for a domain or
    /// plane graph) as a dict.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report)
    }

    /// The multipatch result as a `Document` (kind `"multipatch result"`).
    fn document(&self) -> PyDocument {
        let mut layout = self.sol.layout.clone();
        for (patch, s) in layout.patches.iter_mut().zip(&self.sol.patches) {
            patch.map = Some(s.map.clone());
        }
        PyDocument { doc: Document::Multipatch(layout) }
    }

    /// Write the multipatch result with its reports; `.json`, `.xml` (G+Smo) or `.vtm`.
    fn write(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        let out = self.patches().py_err()?;
        py.detach(|| winslow::write(&path, &out)).py_err()
    }

    /// The multipatch result document as JSON text.
    fn to_json(&self) -> PyResult<String> {
        let mut p = Patches::of_solution(&self.sol).py_err()?;
        p.report = self.report.clone();
        Ok(p.to_json().py_err()?.to_string())
    }

    fn __repr__(&self) -> String {
        format!(
            "LayoutSolution(name={:?}, patches={}, verdict={:?})",
            self.sol.layout.name,
            self.sol.patches.len(),
            self.verdict()
        )
    }
}

/// Solve a layout, or a domain or plane graph laid out by the pipeline, without the GIL
/// (`winslow solve LAYOUT`), its stages to `progress`.
pub fn solve_layout(
    py: Python<'_>,
    input: winslow::Input,
    opts: &Options,
    progress: Option<&Py<PyAny>>,
) -> PyResult<PyLayoutSolution> {
    let mut raised = None;
    let result = py.detach(|| {
        Pipeline::new(input, opts.solve.clone()).run(&mut |s| notify(progress, &mut raised, || crate::solve::event(s)))
    });
    let Solved::Layout { solution, laid_out } = outcome(raised, result)? else {
        return Err(invalid("the solve of a layout gave no multipatch result"));
    };
    PyLayoutSolution::of(*solution, laid_out.as_deref())
}

impl PyLayoutSolution {
    /// The solution of a layout with its report, and the automatic layout's report (under
    /// `auto_layout`, as `winslow solve DOMAIN` writes it) when the pipeline made the
    /// layout.
    pub fn of(sol: MultipatchSolution, laid_out: Option<&winslow::domain::LayoutReport>) -> PyResult<Self> {
        let mut report = serde_json::to_value(&sol.report).map_err(|e| Error::Invalid(e.to_string())).py_err()?;
        if let Some(m) = laid_out {
            report["auto_layout"] = serde_json::to_value(m).map_err(|e| Error::Invalid(e.to_string())).py_err()?;
        }
        Ok(Self { sol, report })
    }
}

/// Lay a general domain or plane graph out into four-sided patches (`winslow layout`):
/// `(layout, report)`, the layout a `Document` of kind `"multipatch layout"` whose
/// `patches()` are `Boundary`s, the report a dict. Fit options as keywords.
#[pyfunction]
#[pyo3(signature = (domain, **options))]
pub fn layout<'py>(
    py: Python<'py>,
    domain: Bound<'py, PyAny>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<(PyDocument, Bound<'py, PyAny>)> {
    let opts = options::parse(options)?;
    let doc = document_arg(py, &domain)?;
    if !matches!(doc, Document::Domain(_) | Document::Graph(_)) {
        return Err(errors::to_py(
            &doc.wrong_kind(None, "a general planar domain (\"domain\") or a plane graph (\"graph\") is needed"),
        ));
    }
    let laid = py.detach(|| layout_of(doc, &opts)).py_err()?;
    let Ok((layout, Some(report))) = laid else { return Err(invalid("no layout was made")) };
    Ok((PyDocument { doc: Document::Layout(layout) }, json_to_py(py, &report)?))
}

/// Improve a bijective map on its own basis, its boundary control points fixed, as
/// `winslow solve --start MAP --method METHOD` does: `method` `"winslow"` (eq. 16),
/// `"weak"` (eq. 14) or `"egg"` (eq. 8); the result is kept only when certified (the
/// start otherwise, the report says why). `boundary` (optional): the map's boundary
/// deviation from it is reported. Solver options as keywords.
#[pyfunction]
#[pyo3(signature = (map, *, method="winslow", boundary=None, **options))]
pub fn improve<'py>(
    py: Python<'py>,
    map: Bound<'py, PyAny>,
    method: &str,
    boundary: Option<Bound<'py, PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<PySolution> {
    let opts = options::parse(options)?.solve;
    let (name, map) = match document_arg(py, &map)? {
        Document::Map { name, map } => (name, map),
        doc => return Err(errors::to_py(&doc.wrong_kind(None, "improve needs a map"))),
    };
    let method: Arc<dyn Method> = match method {
        "winslow" => Improve::Winslow.method(),
        "weak" => Improve::WeakForm.method(),
        "egg" => Arc::new(EggMethod::cpu(opts.operator)),
        m => return Err(invalid(format!("method must be one of winslow, weak, egg, got {m:?}"))),
    };
    let boundary = match boundary {
        Some(b) => {
            let doc = document_arg(py, &b)?;
            Some(winslow::io::checked_boundary(doc.into_boundary().py_err()?, &ReadOptions::default()).py_err()?.0)
        }
        None => None,
    };
    let input = winslow::Input::Map { name, map, boundary };
    let solved = py.detach(|| Pipeline::new(input, opts).method(method).solve()).py_err()?;
    let Solved::Improved(out) = solved else { return Err(invalid("the improvement gave no map")) };
    let report = serde_json::to_value(&out.report).map_err(|e| Error::Invalid(e.to_string())).py_err()?;
    Ok(PySolution {
        name: out.name.clone(),
        verdict: out.report.verdict.name().to_string(),
        pipeline_seconds: out.report.seconds,
        map: PyMap { name: out.name, map: out.map },
        report,
    })
}

/// The methods of paper §10 on one basis (`winslow compare`): a dict with `name`,
/// `basis`, `degree`, `poisson_scales` and `rows` (one per method, EGG first: `method`,
/// `start`, `iterations`, `converged`, `failure`, `measures`, `q_ratio`, `seconds`,
/// `notes`, and `map`, the method's `Map` or `None`). `methods` by their command-line
/// names (`egg`, `vhm`, `qc`, `maxz`, `liao`, `winslow`, `ao`); the other
/// keywords as `winslow compare`'s flags (`levels=1`, `max_newton=200`, no repair by
/// default), solver options as in `solve`. `progress(event)` sees `started` and
/// `finished` per method.
#[pyfunction]
#[pyo3(signature = (
    boundary, methods=None, *, lambda1=0.0, lambda2=0.0, qc_hessian="gauss-newton", eps=None, max_sqp=None,
    max_newton=None, poisson_scales=None, progress=None, **options
))]
#[allow(clippy::too_many_arguments)]
pub fn compare<'py>(
    py: Python<'py>,
    boundary: Bound<'py, PyAny>,
    methods: Option<Vec<String>>,
    lambda1: f64,
    lambda2: f64,
    qc_hessian: &str,
    eps: Option<f64>,
    max_sqp: Option<usize>,
    max_newton: Option<usize>,
    poisson_scales: Option<(f64, f64)>,
    progress: Option<Py<PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let methods: Vec<MethodChoice> = match methods {
        Some(m) => m.iter().map(|m| MethodChoice::parse(m)).collect::<winslow::Result<_>>().py_err()?,
        None => MethodChoice::DEFAULT.to_vec(),
    };
    // the comparison's defaults (one level, no repair, its iteration limits) under the
    // options given, as `winslow compare` makes them
    let mut opts = CompareOptions::default();
    let max_pseudo = opts.solve.nonlinear.max_pseudo;
    let base = opts.solve.clone();
    let parsed = options::parse_onto(base, options)?;
    opts.solve = parsed.solve;
    opts.solve.nonlinear.max_newton = max_newton.unwrap_or(opts.solve.nonlinear.max_newton).max(1);
    opts.solve.nonlinear.max_pseudo = max_pseudo;
    for (name, v) in [("lambda1", lambda1), ("lambda2", lambda2)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(format!("{name} must be finite and not negative, got {v}")));
        }
    }
    (opts.lambda1, opts.lambda2) = (lambda1, lambda2);
    opts.qc_hessian = options::choice::<QcHessian>("qc_hessian", qc_hessian)?;
    if let Some(eps) = eps {
        if !(eps > 0.0 && eps < 1.0) {
            return Err(invalid(format!("eps must be in (0, 1) (a fraction of the mean det J), got {eps}")));
        }
        opts.constrained.eps = eps;
    }
    if let Some(n) = max_sqp {
        opts.constrained.max_iterations = n.max(1);
    }
    opts.poisson_scales = poisson_scales.map(|(a, b)| [a, b]);
    let doc = document_arg(py, &boundary)?;
    let b = winslow::io::checked_boundary(doc.into_boundary().py_err()?, &ReadOptions { reorient: parsed.reorient })
        .py_err()?
        .0;
    let mut raised = None;
    let result = py.detach(|| {
        core_compare(&b, &methods, &opts, Arc::new(winslow::CpuAssembler), &mut |e| match e {
            CompareEvent::Started { method, index, count } => notify(
                progress.as_ref(),
                &mut raised,
                || json!({ "stage": "started", "method": method, "index": index, "count": count }),
            ),
            CompareEvent::Finished(row) => notify(
                progress.as_ref(),
                &mut raised,
                || json!({ "stage": "finished", "method": row.method, "verdict": row.bij(), "seconds": row.seconds }),
            ),
            CompareEvent::Solver(_) => notify(None, &mut raised, || Value::Null),
        })
    });
    let cmp = outcome(raised, result)?.ok_or_else(|| errors::to_py(&Error::Cancelled))?;
    let d = to_py(py, &cmp)?.cast_into::<PyDict>().map_err(PyErr::from)?;
    let rows = d.get_item("rows")?.ok_or_else(|| invalid("rows"))?.cast_into::<PyList>().map_err(PyErr::from)?;
    for (row, r) in rows.iter().zip(&cmp.rows) {
        let map = r.map.clone().map(|map| PyMap { name: format!("{}-{}", cmp.name, r.method), map });
        row.set_item("map", map)?;
    }
    Ok(d)
}

/// A sliding grid (`winslow sweep`): a ring whose inner contour turns by `rotate_inner`
/// degrees per step for `steps` steps (or follows the inner contours of the ring
/// documents `inner_frames` at `times`), the outer contour fixed, frame after frame on
/// frame 0's basis from extrapolated starts. A list of frames, each a dict `map` (a
/// `Map`) and `report` (its row of `winslow sweep`'s table: `frame`, `time`,
/// `newton_iterations`, `verdict`, ...). `progress(row)` sees each frame's row.
#[pyfunction]
#[pyo3(signature = (
    ring, *, rotate_inner=None, steps=None, center=None, inner_frames=None, times=None, seam="slide",
    predictor_order=5, progress=None, **options
))]
#[allow(clippy::too_many_arguments)]
pub fn sweep<'py>(
    py: Python<'py>,
    ring: Bound<'py, PyAny>,
    rotate_inner: Option<f64>,
    steps: Option<usize>,
    center: Option<(f64, f64)>,
    inner_frames: Option<Vec<Bound<'py, PyAny>>>,
    times: Option<Vec<f64>>,
    seam: &str,
    predictor_order: usize,
    progress: Option<Py<PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyList>> {
    let opts = options::parse(options)?.solve;
    let ring = match document_arg(py, &ring)? {
        Document::Ring(r) => r,
        doc @ Document::Map { .. } if doc.is_ring_map() => doc.into_ring().py_err()?,
        doc => return Err(errors::to_py(&doc.wrong_kind(None, "sweep needs a ring document or a ring map"))),
    };
    let mut contours = Vec::new();
    for f in inner_frames.iter().flatten() {
        match document_arg(py, f)? {
            Document::Ring(r) => contours.push(r.inner),
            doc @ Document::Map { .. } if doc.is_ring_map() => contours.push(doc.into_ring().py_err()?.inner),
            doc => return Err(errors::to_py(&doc.wrong_kind(None, "inner_frames are ring documents"))),
        }
    }
    if rotate_inner.is_some() != contours.is_empty() {
        return Err(invalid("sweep needs exactly one of rotate_inner=DEGREES (with steps=N) and inner_frames=[...]"));
    }
    let (step, steps) = match (rotate_inner, steps) {
        (Some(d), _) if !d.is_finite() => {
            return Err(invalid(format!("rotate_inner must be a finite number of degrees, got {d}")))
        }
        (Some(d), Some(n)) => (d.to_radians(), n),
        (Some(_), None) => return Err(invalid("rotate_inner needs steps")),
        (None, n) => {
            contours.truncate(n.unwrap_or(usize::MAX));
            (0.0, contours.len())
        }
    };
    let times = times.unwrap_or_else(|| (1..=steps).map(|k| k as f64).collect());
    if !contours.is_empty() && times.len() != contours.len() {
        return Err(invalid(format!("times gives {} times for {} inner frames", times.len(), contours.len())));
    }
    if predictor_order > 5 {
        return Err(invalid(format!("predictor_order must be between 0 and 5, got {predictor_order}")));
    }
    let seam = options::choice::<Seam>("seam", seam)?;
    let so = SweepOptions { step, steps, center: center.map(|(x, y)| [x, y]), max_order: predictor_order, seam };
    let mut raised = None;
    let result = py.detach(|| -> winslow::Result<Vec<winslow::pipeline::sweep::Frame>> {
        let (mut sw, _, f0) = Sweep::new(&ring, &opts, so)?;
        let mut frames = vec![f0];
        for k in 1..=steps {
            let last = frames.last().map(|f| &f.report);
            let row = serde_json::to_value(last).unwrap_or(Value::Null);
            if !notify(progress.as_ref(), &mut raised, || row) {
                return Err(Error::Cancelled);
            }
            frames.push(match contours.get(k - 1) {
                Some(inner) => sw.next_frame_contour(inner, times[k - 1])?,
                None => sw.next_frame()?,
            });
        }
        let row = serde_json::to_value(frames.last().map(|f| &f.report)).unwrap_or(Value::Null);
        if !notify(progress.as_ref(), &mut raised, || row) {
            return Err(Error::Cancelled);
        }
        Ok(frames)
    });
    let frames = outcome(raised, result)?;
    let items = frames
        .into_iter()
        .map(|f| -> PyResult<Bound<'py, PyAny>> {
            let d = PyDict::new(py);
            d.set_item("map", PyMap { name: format!("{}_{:04}", ring.name, f.report.frame), map: f.map })?;
            d.set_item("report", to_py(py, &f.report)?)?;
            Ok(d.into_any())
        })
        .collect::<PyResult<Vec<_>>>()?;
    PyList::new(py, items)
}
