//! Python bindings of winslow (module `winslow`, built by maturin from
//! `crates/python/pyproject.toml`): documents as objects whose knots, control points and
//! weights are numpy arrays, `read`/`write` of every document, `solve` (the pipeline,
//! GIL released, progress callback, Ctrl-C), `solve_many` (a thread pool), `check` (the
//! certificate), `mesh`, and the runs built on the pipeline (`layout`, `improve`,
//! `compare`, `sweep`; layouts, domains and plane graphs in `solve`). The user guide is `docs/python.md`; the Python layer
//! (`python/winslow/__init__.py`) adds the `meshio.Mesh` of a mesh.
//!
//! The crate never embeds an interpreter: cargo builds it as an extension module
//! (`.cargo/config.toml` sets `PYO3_BUILD_EXTENSION_MODULE`), so a machine without
//! Python builds, lints and tests the workspace; the bindings are tested by pytest
//! (`crates/python/tests`, run by `scripts/test.sh`).

mod convert;
mod errors;
mod geometry;
mod options;
mod runs;
mod solve;

use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use winslow::Document;
use winslow_mesh::structured::{structured, StructuredOptions};
use winslow_mesh::unstructured::{unstructured, UnstructuredOptions};

use crate::errors::{invalid, IntoPy};
use crate::geometry::{document_of, document_to_py, write_document, PyBoundary, PyCurve, PyDocument, PyMap};
use crate::solve::PySolution;

/// Read any document of `docs/formats.md` (JSON, G+Smo XML, IGES): a `Map`, a
/// `Boundary`, or a `Document` (ring, layout, multipatch result, domain, volume).
#[pyfunction]
fn read(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let doc = py.detach(|| winslow::read(&path)).py_err()?;
    document_to_py(py, doc)
}

/// Parse a document from its text (JSON or G+Smo XML), as `read` does a file.
#[pyfunction]
fn parse<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    let doc = py.detach(|| winslow::io::parse_document(text)).py_err()?;
    document_to_py(py, doc)
}

/// Write a `Map`, `Boundary`, `Document` or `Solution` to `path` (atomically); the
/// format by the extension (`docs/formats.md`).
#[pyfunction]
fn write(py: Python<'_>, path: PathBuf, document: Bound<'_, PyAny>) -> PyResult<()> {
    if let Ok(s) = document.cast::<PySolution>() {
        let s = s.get().clone();
        return py.detach(|| s.write_to(&path)).py_err();
    }
    let doc: Document = document_of(&document)?;
    py.detach(|| write_document(&path, &doc)).py_err()
}

/// A mesh of a map (`winslow mesh`): `structured=(nx, ny)` points per direction, or an
/// unstructured triangulation of element size `size` (of order `order`). A dict of
/// `points` `(n, 2)`, `params` `(n, 2)`, `cells` `(m, k)` (Gmsh node order, corners
/// counter-clockwise first), `cell_type` (`"quad"`, `"triangle"`, ...) and `order`.
#[pyfunction]
#[pyo3(signature = (map, *, structured=None, size=None, order=1))]
fn mesh_arrays<'py>(
    py: Python<'py>,
    map: Bound<'py, PyAny>,
    structured: Option<(usize, usize)>,
    size: Option<f64>,
    order: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let doc = document_of(&map)?;
    let Document::Map { map, .. } = doc else {
        return Err(errors::to_py(&doc.wrong_kind(None, "mesh needs a map")));
    };
    if structured.is_some() == size.is_some() {
        return Err(invalid("mesh needs exactly one of structured=(nx, ny) and size=h"));
    }
    let mesh = py
        .detach(|| match structured {
            Some((nx, ny)) => self::structured(&map, &StructuredOptions::uniform(nx, ny)),
            None => unstructured(&map, &UnstructuredOptions { size: size.unwrap_or(0.1), order, ..Default::default() }),
        })
        .map_err(|e| errors::mesh_error(&e))?;
    let k = mesh.nodes_per_cell();
    let pts: Vec<f64> = mesh.points.iter().flat_map(|p| [p.x, p.y]).collect();
    let prm: Vec<f64> = mesh.params.iter().flat_map(|p| [p.x, p.y]).collect();
    let cells: Vec<i64> = mesh.cells.iter().map(|&c| c as i64).collect();
    let shape_err = |e: numpy::ndarray::ShapeError| invalid(e.to_string());
    let d = PyDict::new(py);
    d.set_item("points", Array2::from_shape_vec((mesh.points.len(), 2), pts).map_err(shape_err)?.into_pyarray(py))?;
    d.set_item("params", Array2::from_shape_vec((mesh.params.len(), 2), prm).map_err(shape_err)?.into_pyarray(py))?;
    d.set_item("cells", Array2::from_shape_vec((mesh.num_cells(), k), cells).map_err(shape_err)?.into_pyarray(py))?;
    let cell_type = match (mesh.kind, k) {
        (winslow_mesh::ElementKind::Quad, 4) => "quad",
        (winslow_mesh::ElementKind::Quad, 9) => "quad9",
        (winslow_mesh::ElementKind::Triangle, 3) => "triangle",
        (winslow_mesh::ElementKind::Triangle, 6) => "triangle6",
        (winslow_mesh::ElementKind::Triangle, _) => "triangle_high_order",
        (winslow_mesh::ElementKind::Quad, _) => "quad_high_order",
    };
    d.set_item("cell_type", cell_type)?;
    d.set_item("order", mesh.order)?;
    Ok(d)
}

/// The native module `winslow._native` (re-exported by the package `winslow`).
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("WinslowError", m.py().get_type::<errors::WinslowError>())?;
    m.add("SOLVE_OPTIONS", options::KNOWN.to_vec())?;
    m.add_class::<PyMap>()?;
    m.add_class::<PyCurve>()?;
    m.add_class::<PyBoundary>()?;
    m.add_class::<PyDocument>()?;
    m.add_class::<PySolution>()?;
    m.add_class::<runs::PyLayoutSolution>()?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(parse, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add_function(wrap_pyfunction!(solve::solve, m)?)?;
    m.add_function(wrap_pyfunction!(solve::solve_many, m)?)?;
    m.add_function(wrap_pyfunction!(solve::check, m)?)?;
    m.add_function(wrap_pyfunction!(solve::solution_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(runs::layout, m)?)?;
    m.add_function(wrap_pyfunction!(runs::improve, m)?)?;
    m.add_function(wrap_pyfunction!(runs::compare, m)?)?;
    m.add_function(wrap_pyfunction!(runs::sweep, m)?)?;
    Ok(())
}
