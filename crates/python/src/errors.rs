//! Errors as Python exceptions: every [`winslow::Error`] becomes a `winslow.WinslowError`
//! whose `kind` names the typed error's variant (`"corner_gap"`, `"knots"`, ...) and
//! whose `message` is the core's message; a stopped solve (`Error::Cancelled`) whose
//! cause was Ctrl-C is Python's `KeyboardInterrupt`.

use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use winslow::Error;

pyo3::create_exception!(
    winslow,
    WinslowError,
    PyException,
    "An error of winslow: `kind` names the typed error (e.g. `\"corner_gap\"`, `\"knots\"`, \"io\"), `message` is its message."
);

/// The variant of `e` in snake case: the exception's `kind`.
pub fn kind(e: &Error) -> &'static str {
    match e {
        Error::Knots { .. } => "knots",
        Error::Length { .. } => "length",
        Error::NonFinite { .. } => "non_finite",
        Error::Weight { .. } => "weight",
        Error::Degree { .. } => "degree",
        Error::Json { .. } => "json",
        Error::Xml { .. } => "xml",
        Error::Io { .. } => "io",
        Error::CornerGap { .. } => "corner_gap",
        Error::DegenerateSide { .. } => "degenerate_side",
        Error::TooFewPoints { .. } => "too_few_points",
        Error::SelfIntersection { .. } => "self_intersection",
        Error::Clockwise { .. } => "clockwise",
        Error::DegenerateContour { .. } => "degenerate_contour",
        Error::TooLarge { .. } => "too_large",
        Error::Corners { .. } => "corners",
        Error::Range { .. } => "range",
        Error::Invalid(_) => "invalid",
        Error::KnotMultiplicity { .. } => "knot_multiplicity",
        Error::LinearSolver(_) => "linear_solver",
        Error::NoConvergence(_) => "no_convergence",
        Error::Topology { .. } => "topology",
        Error::Slices { .. } => "slices",
        Error::SliceNotCertified { .. } => "slice_not_certified",
        Error::InfeasibleStart { .. } => "infeasible_start",
        Error::Layout { .. } => "layout",
        Error::Memory { .. } => "memory",
        Error::Domain { .. } => "domain",
        Error::Cancelled => "cancelled",
        Error::DocumentKind { .. } => "document_kind",
        Error::Extension { .. } => "extension",
        #[allow(unreachable_patterns)]
        _ => "other",
    }
}

/// The exception of `e`: a `WinslowError(message)` with `kind` and `message` set.
pub fn to_py(e: &Error) -> PyErr {
    let message = e.to_string();
    let err = WinslowError::new_err(message.clone());
    Python::attach(|py| {
        let value = err.value(py);
        // setting attributes on a fresh exception instance cannot fail but for memory
        let _ = value.setattr("kind", kind(e));
        let _ = value.setattr("message", message);
    });
    err
}

/// `Result<T, winslow::Error>` to `PyResult<T>`.
pub trait IntoPy<T> {
    /// The error as a `WinslowError`.
    fn py_err(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for Result<T, Error> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(|e| to_py(&e))
    }
}

/// A `WinslowError` of kind `invalid` (a bad argument), with the core's wording.
pub fn invalid(message: impl Into<String>) -> PyErr {
    to_py(&Error::Invalid(message.into()))
}

/// A mesher's error: a `WinslowError` of kind `mesh_parameter`, `mesh_layer`,
/// `mesh_inverted`, ... (the mesh error's variant), with its message.
pub fn mesh_error(e: &winslow_mesh::MeshError) -> PyErr {
    let message = e.to_string();
    let variant = format!("{e:?}");
    let name: String = variant.chars().take_while(|c| c.is_alphanumeric()).collect();
    let mut kind = String::from("mesh");
    for c in name.chars() {
        if c.is_uppercase() {
            kind.push('_');
        }
        kind.push(c.to_ascii_lowercase());
    }
    let err = WinslowError::new_err(message.clone());
    Python::attach(|py| {
        let value = err.value(py);
        let _ = value.setattr("kind", kind);
        let _ = value.setattr("message", message);
    });
    err
}
