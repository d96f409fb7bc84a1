//! The documents as Python objects: `Map` (a tensor-product B-spline or NURBS map),
//! `Curve`, `Boundary` (four sides), and `Document` for the kinds held whole (rings,
//! layouts, multipatch results, domains, volumes). Knots, control points and weights are
//! numpy arrays.

use numpy::{PyArray1, PyArray2, PyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyList;
use winslow::boundary::{Boundary, SideCurve};
use winslow::io::multipatch::Patches;
use winslow::{Curve, Document, KnotVector, Output, Side, Surface};

use crate::convert::{parameters, points, points_array, shaped, vector, vector_array};
use crate::errors::{invalid, IntoPy};

/// A planar tensor-product B-spline or NURBS map `x(u, v)` of the unit square
/// (`x = sum_ij w_ij N_i(u) M_j(v) P_ij / sum_ij w_ij N_i(u) M_j(v)`).
///
/// `Map(knots, degrees, control_points, weights=None, name="")`: `knots` a pair of
/// knot vectors (open, on any interval; mapped to `[0, 1]`), `control_points` of shape
/// `(n_u * n_v, 2)` with the `u` index fastest, `weights` of length `n_u * n_v`.
#[pyclass(name = "Map", module = "winslow", frozen)]
#[derive(Debug, Clone)]
pub struct PyMap {
    pub name: String,
    pub map: Surface,
}

#[pymethods]
impl PyMap {
    #[new]
    #[pyo3(signature = (knots, degrees, control_points, weights=None, name=String::new()))]
    fn new(
        py: Python<'_>,
        knots: (Bound<'_, PyAny>, Bound<'_, PyAny>),
        degrees: (usize, usize),
        control_points: Bound<'_, PyAny>,
        weights: Option<Bound<'_, PyAny>>,
        name: String,
    ) -> PyResult<Self> {
        let ku = KnotVector::new(degrees.0, vector(py, &knots.0, "knots[0]")?).py_err()?;
        let kv = KnotVector::new(degrees.1, vector(py, &knots.1, "knots[1]")?).py_err()?;
        let cps = points(py, &control_points, "control_points")?;
        let w = weights.map(|w| vector(py, &w, "weights")).transpose()?;
        let map = Surface::new([ku.normalized(), kv.normalized()], cps, w).py_err()?;
        Ok(Self { name, map })
    }

    /// Name of the geometry.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Degrees `(p_u, p_v)`.
    #[getter]
    fn degrees(&self) -> (usize, usize) {
        let d = self.map.degrees();
        (d[0], d[1])
    }

    /// Number of basis functions per direction `(n_u, n_v)`.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        let s = self.map.shape();
        (s[0], s[1])
    }

    /// Whether each direction is periodic (a ring map: `(False, True)`).
    #[getter]
    fn periodic(&self) -> (bool, bool) {
        (self.map.knots[0].is_periodic(), self.map.knots[1].is_periodic())
    }

    /// The two knot vectors (on `[0, 1]`).
    #[getter]
    fn knots<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        (vector_array(py, self.map.knots[0].knots()), vector_array(py, self.map.knots[1].knots()))
    }

    /// Control points, shape `(n_u * n_v, 2)`, the `u` index fastest.
    #[getter]
    fn control_points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        points_array(py, &self.map.control_points)
    }

    /// Weights (length `n_u * n_v`), or `None` for a polynomial map.
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.map.weights.as_ref().map(|w| vector_array(py, w))
    }

    /// `x(u, v)` for arrays `u`, `v` of one shape `S`: an array of shape `S + (2,)`.
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        u: Bound<'py, PyAny>,
        v: Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (uv, shape) = parameters(py, &u, &v)?;
        let values = py.detach(|| uv.iter().flat_map(|p| self.map.eval(p[0], p[1])).collect());
        shaped(py, values, &shape, &[2])
    }

    /// The Jacobian `J = [[x_u, x_v], [y_u, y_v]]` for arrays `u`, `v` of one shape
    /// `S`: shape `S + (2, 2)`, `J[..., i, j] = d x_i / d u_j`.
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        u: Bound<'py, PyAny>,
        v: Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (uv, shape) = parameters(py, &u, &v)?;
        let values = py.detach(|| {
            uv.iter()
                .flat_map(|p| {
                    let d = self.map.derivs(p[0], p[1], 1);
                    [d.xu[0], d.xv[0], d.xu[1], d.xv[1]]
                })
                .collect()
        });
        shaped(py, values, &shape, &[2, 2])
    }

    /// `det J = x_u y_v - x_v y_u` for arrays `u`, `v` of one shape `S`: shape `S`.
    fn det_j<'py>(
        &self,
        py: Python<'py>,
        u: Bound<'py, PyAny>,
        v: Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (uv, shape) = parameters(py, &u, &v)?;
        let values = py.detach(|| uv.iter().map(|p| self.map.derivs(p[0], p[1], 1).det_j()).collect());
        shaped(py, values, &shape, &[])
    }

    /// The four boundary curves (south, east, north, west) as a `Boundary`.
    fn boundary(&self) -> PyResult<PyBoundary> {
        let doc = Document::Map { name: self.name.clone(), map: self.map.clone() };
        Ok(PyBoundary { boundary: doc.into_boundary().py_err()? })
    }

    /// Write the map; the format by the extension (`.json`, `.xml`, `.igs`, `.vtu`, `.vtk`).
    fn write(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        let out = Output::Map { name: &self.name, map: &self.map, label: "", extra: None };
        py.detach(|| winslow::write(&path, &out)).py_err()
    }

    /// The map document as JSON text (`docs/formats.md`; `winslow.parse` reads it back
    /// bit for bit).
    fn to_json(&self) -> String {
        winslow::io::json::map_to_json(&self.name, &self.map, None).to_string()
    }

    /// Pickled as its JSON text (for `multiprocessing`, Dask, Ray).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((py.import("winslow")?.getattr("parse")?, (self.to_json(),)))
    }

    /// The map as a pygismo `gsTensorBSpline2` (`gsTensorNurbs2` when rational); needs
    /// pygismo (`winslow.interop`).
    fn to_gismo<'py>(slf: Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        slf.py().import("winslow.interop")?.call_method1("to_gismo", (slf,))
    }

    /// A `Map` from a pygismo `gsTensorBSpline2`/`gsTensorNurbs2` (or the first patch
    /// of a `gsMultiPatch`); `winslow.interop`.
    #[staticmethod]
    fn from_gismo<'py>(py: Python<'py>, obj: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        py.import("winslow.interop")?.call_method1("from_gismo", (obj,))
    }

    /// The map as a splinepy `BSpline` (`NURBS` when rational); needs splinepy
    /// (`winslow.interop`).
    fn to_splinepy<'py>(slf: Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        slf.py().import("winslow.interop")?.call_method1("to_splinepy", (slf,))
    }

    /// A `Map` from a splinepy `BSpline` or `NURBS` of parametric and physical
    /// dimension 2; `winslow.interop`.
    #[staticmethod]
    fn from_splinepy<'py>(py: Python<'py>, obj: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        py.import("winslow.interop")?.call_method1("from_splinepy", (obj,))
    }

    fn __repr__(&self) -> String {
        let (s, d) = (self.map.shape(), self.map.degrees());
        format!(
            "Map(name={:?}, degrees=({}, {}), shape=({}, {}), rational={})",
            self.name,
            d[0],
            d[1],
            s[0],
            s[1],
            self.map.weights.is_some()
        )
    }
}

/// A planar B-spline or NURBS curve on `[0, 1]`.
///
/// `Curve(knots, degree, control_points, weights=None)`.
#[pyclass(name = "Curve", module = "winslow", frozen)]
#[derive(Debug, Clone)]
pub struct PyCurve {
    pub curve: Curve,
}

#[pymethods]
impl PyCurve {
    #[new]
    #[pyo3(signature = (knots, degree, control_points, weights=None))]
    fn new(
        py: Python<'_>,
        knots: Bound<'_, PyAny>,
        degree: usize,
        control_points: Bound<'_, PyAny>,
        weights: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let k = KnotVector::new(degree, vector(py, &knots, "knots")?).py_err()?;
        let cps = points(py, &control_points, "control_points")?;
        let w = weights.map(|w| vector(py, &w, "weights")).transpose()?;
        Ok(Self { curve: Curve::new(k, cps, w).py_err()? })
    }

    /// Degree.
    #[getter]
    fn degree(&self) -> usize {
        self.curve.degree()
    }

    /// Knot vector.
    #[getter]
    fn knots<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.curve.knots.knots())
    }

    /// Control points, shape `(n, 2)`.
    #[getter]
    fn control_points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        points_array(py, &self.curve.control_points)
    }

    /// Weights, or `None`.
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.curve.weights.as_ref().map(|w| vector_array(py, w))
    }

    /// `x(t)` for an array `t` of shape `S` (in the knot vector's domain): shape `S + (2,)`.
    fn evaluate<'py>(&self, py: Python<'py>, t: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let a = crate::convert::f64_array(py, &t)?;
        let a = a.as_array();
        let (lo, hi) = self.curve.domain();
        if let Some(x) = a.iter().find(|x| !(lo..=hi).contains(*x)) {
            return Err(crate::errors::to_py(&winslow::Error::Range {
                what: format!("the parameter {x} is outside the curve's domain [{lo}, {hi}]"),
            }));
        }
        let values = a.iter().flat_map(|&x| self.curve.eval(x)).collect();
        shaped(py, values, a.shape(), &[2])
    }

    fn __repr__(&self) -> String {
        format!("Curve(degree={}, points={})", self.curve.degree(), self.curve.control_points.len())
    }
}

/// A four-sided boundary: sides south, east, north, west, each a `Curve` or an `(n, 2)`
/// point cloud from one corner to the next (south and north run in `+u`, east and west
/// in `+v`).
///
/// `Boundary(sides, name="")`.
#[pyclass(name = "Boundary", module = "winslow", frozen)]
#[derive(Debug, Clone)]
pub struct PyBoundary {
    pub boundary: Boundary,
}

#[pymethods]
impl PyBoundary {
    #[new]
    #[pyo3(signature = (sides, name=String::new()))]
    fn new(py: Python<'_>, sides: Vec<Bound<'_, PyAny>>, name: String) -> PyResult<Self> {
        if sides.len() != 4 {
            return Err(invalid(format!("a boundary has four sides (south, east, north, west), got {}", sides.len())));
        }
        let mut out = Vec::with_capacity(4);
        for (s, side) in Side::ALL.iter().zip(&sides) {
            out.push(match side.cast::<PyCurve>() {
                Ok(c) => SideCurve::Spline(c.get().curve.clone()),
                Err(_) => SideCurve::Points(points(py, side, &format!("the {s} side"))?),
            });
        }
        let sides: [SideCurve; 4] = out.try_into().map_err(|_| invalid("four sides"))?;
        Ok(Self { boundary: Boundary { name, sides } })
    }

    /// Name of the geometry.
    #[getter]
    fn name(&self) -> &str {
        &self.boundary.name
    }

    /// The four sides (south, east, north, west): each a `Curve` or an `(n, 2)` array.
    #[getter]
    fn sides<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let items = self
            .boundary
            .sides
            .iter()
            .map(|s| -> PyResult<Bound<'py, PyAny>> {
                Ok(match s {
                    SideCurve::Spline(c) => Bound::new(py, PyCurve { curve: c.clone() })?.into_any(),
                    SideCurve::Points(p) => points_array(py, p).into_any(),
                    SideCurve::Analytic(a) => {
                        let p: Vec<_> = (0..=200).map(|i| (a.0)(i as f64 / 200.0)).collect();
                        points_array(py, &p).into_any()
                    }
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, items)
    }

    /// Write the boundary document (`.json`).
    fn write(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        py.detach(|| winslow::write(&path, &Output::Boundary(&self.boundary))).py_err()
    }

    /// The boundary document as JSON text (`winslow.parse` reads it back).
    fn to_json(&self) -> String {
        winslow::io::json::boundary_to_json(&self.boundary).to_string()
    }

    /// Pickled as its JSON text.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((py.import("winslow")?.getattr("parse")?, (self.to_json(),)))
    }

    fn __repr__(&self) -> String {
        let kinds: Vec<&str> = self
            .boundary
            .sides
            .iter()
            .map(|s| match s {
                SideCurve::Spline(_) => "curve",
                SideCurve::Points(_) => "points",
                SideCurve::Analytic(_) => "analytic",
            })
            .collect();
        format!("Boundary(name={:?}, sides={kinds:?})", self.boundary.name)
    }
}

/// A document held whole: a ring, a multipatch layout or result, a general domain or a
/// volume (`kind` says which). Read with `winslow.read`, written with `write`, solved
/// with `winslow.solve` (a ring).
#[pyclass(name = "Document", module = "winslow", frozen)]
#[derive(Debug, Clone)]
pub struct PyDocument {
    pub doc: Document,
}

#[pymethods]
impl PyDocument {
    /// The kind: `"ring"`, `"multipatch layout"`, `"multipatch result"`, `"domain"`,
    /// `"volume"`.
    #[getter]
    fn kind(&self) -> &'static str {
        self.doc.kind()
    }

    /// Name of the geometry.
    #[getter]
    fn name(&self) -> &str {
        self.doc.name()
    }

    /// The patch maps of a multipatch result or of a G+Smo layout (a `Map` per patch);
    /// `None` when a patch has no map or the document is of another kind.
    fn maps(&self) -> Option<Vec<PyMap>> {
        match &self.doc {
            Document::Layout(l) | Document::Multipatch(l) => {
                l.patches.iter().map(|p| p.map.clone().map(|map| PyMap { name: p.name.clone(), map })).collect()
            }
            _ => None,
        }
    }

    /// The patches of a layout or multipatch result, each a `Boundary` (its four sides,
    /// named after the patch); `None` for the other kinds.
    fn patches(&self) -> Option<Vec<PyBoundary>> {
        match &self.doc {
            Document::Layout(l) | Document::Multipatch(l) => Some(
                l.patches
                    .iter()
                    .map(|p| PyBoundary {
                        boundary: Boundary { name: p.name.clone(), sides: p.sides.clone().map(SideCurve::Spline) },
                    })
                    .collect(),
            ),
            _ => None,
        }
    }

    /// Write the document; the format by the extension.
    fn write(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        py.detach(|| write_document(&path, &self.doc)).py_err()
    }

    fn __repr__(&self) -> String {
        format!("Document(kind={:?}, name={:?})", self.doc.kind(), self.doc.name())
    }
}

/// Write any document as it was read.
pub fn write_document(path: &std::path::Path, doc: &Document) -> winslow::Result<()> {
    match doc {
        Document::Boundary(b) => winslow::write(path, &Output::Boundary(b)),
        Document::Map { name, map } => winslow::write(path, &Output::Map { name, map, label: "", extra: None }),
        Document::Ring(r) => winslow::write(path, &Output::Ring(r)),
        Document::Layout(l) => winslow::write(path, &Output::Layout(l)),
        Document::Multipatch(l) => {
            let maps: Option<Vec<Surface>> = l.patches.iter().map(|p| p.map.clone()).collect();
            let maps = maps.ok_or_else(|| doc.wrong_kind(None, "every patch of a multipatch result has a map"))?;
            let n = maps.len();
            let patches = Patches {
                layout: l,
                maps,
                reports: vec![serde_json::Value::Null; n],
                messages: vec![String::new(); n],
                report: serde_json::Value::Null,
                message: String::new(),
            };
            winslow::write(path, &Output::Multipatch(patches))
        }
        Document::Domain(d) => winslow::write(path, &Output::Domain(d)),
        Document::VolumeBoundary(b) => winslow::write(path, &Output::VolumeBoundary(b)),
        Document::Graph(g) => winslow::write(path, &Output::Graph(g)),
        Document::Volume { name, volume } => {
            winslow::write(path, &Output::Volume { name, volume, label: "", extra: None })
        }
        Document::Thb { name, map } => winslow::write(path, &Output::Thb { name, map, label: "", extra: None }),
    }
}

/// A document as its Python object: `Map`, `Boundary` or `Document`.
pub fn document_to_py(py: Python<'_>, doc: Document) -> PyResult<Bound<'_, PyAny>> {
    Ok(match doc {
        Document::Map { name, map } => Bound::new(py, PyMap { name, map })?.into_any(),
        Document::Boundary(boundary) => Bound::new(py, PyBoundary { boundary })?.into_any(),
        doc => Bound::new(py, PyDocument { doc })?.into_any(),
    })
}

/// Whatever Python object holds a document, as the core's document.
pub fn document_of(obj: &Bound<'_, PyAny>) -> PyResult<Document> {
    if let Ok(m) = obj.cast::<PyMap>() {
        let m = m.get();
        return Ok(Document::Map { name: m.name.clone(), map: m.map.clone() });
    }
    if let Ok(b) = obj.cast::<PyBoundary>() {
        return Ok(Document::Boundary(b.get().boundary.clone()));
    }
    if let Ok(d) = obj.cast::<PyDocument>() {
        return Ok(d.get().doc.clone());
    }
    if let Ok(s) = obj.cast::<crate::solve::PySolution>() {
        let s = s.get();
        return Ok(Document::Map { name: s.name.clone(), map: s.map.map.clone() });
    }
    Err(pyo3::exceptions::PyTypeError::new_err(format!(
        "expected a winslow Map, Boundary, Document or Solution, got {}",
        obj.get_type().name()?
    )))
}
