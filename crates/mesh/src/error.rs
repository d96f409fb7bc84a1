//! The crate's error type: every refusal names what and where.

/// Errors of mesh generation, checking and writing.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// A distribution or mesh parameter out of range.
    #[error("invalid parameter {what}: {why}")]
    Parameter {
        /// Which parameter.
        what: String,
        /// Why it is refused.
        why: String,
    },
    /// A first-cell height that the given number of cells and growth limit cannot meet.
    #[error("{side}: first-cell height {height:e} with growth limit {growth}: {why}")]
    Layer {
        /// The side the layer grows from.
        side: String,
        /// Requested first-cell height in physical units.
        height: f64,
        /// Growth-ratio limit.
        growth: f64,
        /// What fails and what would work.
        why: String,
    },
    /// A cell of the mesh is inverted or degenerate; such a mesh is never written.
    #[error("cell {cell} is inverted or degenerate ({why}); {count} such cells in all")]
    Inverted {
        /// Index of the first offending cell (0-based, in the mesh's element order).
        cell: usize,
        /// What was measured.
        why: String,
        /// Number of offending cells.
        count: usize,
    },
    /// A mesh that breaks a rule of the format it is written in ([`crate::validate`]);
    /// nothing is written.
    #[error("{format} would reject this mesh: rule \"{rule}\" fails at {count} place(s), the first: {first}; {hint}")]
    Invalid {
        /// The file format.
        format: &'static str,
        /// The rule broken.
        rule: String,
        /// How many places break it.
        count: usize,
        /// The first (or worst) place.
        first: String,
        /// What to change.
        hint: String,
    },
    /// A format that cannot hold this mesh (element kind or structure).
    #[error("{format} cannot hold this mesh: {why}")]
    Unsupported {
        /// The file format.
        format: &'static str,
        /// Why.
        why: String,
    },
    /// The triangulation failed.
    #[error("triangulation: {0}")]
    Triangulation(String),
    /// Writing a file (through `winslow::io`'s atomic writer, whose error names the
    /// file and its cause).
    #[error(transparent)]
    File(winslow::Error),
}

impl MeshError {
    pub(crate) fn param(what: impl Into<String>, why: impl Into<String>) -> Self {
        MeshError::Parameter { what: what.into(), why: why.into() }
    }
}

/// Result with [`MeshError`].
pub type Result<T, E = MeshError> = std::result::Result<T, E>;
