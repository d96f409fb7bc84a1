//! Typed errors of the core crate. Every message says what is wrong and where.

use std::path::PathBuf;

/// Result alias of the core crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Every way a call into the core can fail.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A knot vector violates the rules of `formats.md`.
    #[error("invalid knot vector{}: {reason}", at(.context))]
    Knots { context: String, reason: String },
    /// Control points, weights or knots have inconsistent lengths.
    #[error("wrong length{}: {what} has {found}, expected {expected}", at(.context))]
    Length { context: String, what: String, found: usize, expected: usize },
    /// A number is NaN or infinite.
    #[error("non-finite number{}: {what}", at(.context))]
    NonFinite { context: String, what: String },
    /// A NURBS weight is zero, negative or non-finite.
    #[error("non-positive weight{}: weight {index} is {value}", at(.context))]
    Weight { context: String, index: usize, value: f64 },
    /// A degree below 1 (or above the supported maximum).
    #[error("invalid degree{}: {degree} ({reason})", at(.context))]
    Degree { context: String, degree: usize, reason: String },
    /// A JSON document could not be parsed or has the wrong shape.
    #[error("malformed JSON{}: {message}", at(.context))]
    Json { context: String, message: String },
    /// A G+Smo XML document could not be parsed or has the wrong shape.
    #[error("malformed G+Smo XML{}: {message}", at(.context))]
    Xml { context: String, message: String },
    /// Reading or writing a file failed. The cause is part of the message and not
    /// also a `source()`, so that a chain of errors prints it once.
    #[error("I/O error on {path}: {cause}")]
    Io { path: PathBuf, cause: std::io::Error },
    /// Adjacent sides do not meet at their common corner.
    #[error("corner gap between {side_a} and {side_b}: the ends are {gap:.3e} apart (tolerance {tol:.3e}) at ({x:.6}, {y:.6})")]
    CornerGap { side_a: String, side_b: String, gap: f64, tol: f64, x: f64, y: f64 },
    /// A side has (numerically) zero length.
    #[error("degenerate side {side}: its length is {length:.3e}, below {tol:.3e}")]
    DegenerateSide { side: String, length: f64, tol: f64 },
    /// A point cloud has too few points.
    #[error("too few points on {side}: {found}, need at least {needed}")]
    TooFewPoints { side: String, found: usize, needed: usize },
    /// The boundary crosses itself.
    #[error("self-intersecting contour: {side_a} near ({x:.6}, {y:.6}) crosses {side_b}")]
    SelfIntersection { side_a: String, side_b: String, x: f64, y: f64 },
    /// The boundary is traversed clockwise (signed area negative).
    #[error("clockwise contour (signed area {area:.6e}): south, east, reversed north, reversed west must run counter-clockwise; pass the reorient option to flip it")]
    Clockwise { area: f64 },
    /// The contour encloses (numerically) no area: its orientation is undetermined.
    #[error("degenerate contour: signed area {area:.3e} is within {bound:.3e} of zero (the corner gaps times the diameter, and rounding), so it encloses no domain and has no orientation")]
    DegenerateContour { area: f64, bound: f64 },
    /// An input exceeds the sizes the library accepts.
    #[error("absurd size{}: {what} is {found}, the limit is {limit}", at(.context))]
    TooLarge { context: String, what: String, found: usize, limit: usize },
    /// A contour document's corner indices are unusable.
    #[error("invalid corners: {reason}")]
    Corners { reason: String },
    /// Coordinates whose size or position leaves the range `f64` can compute with (see
    /// `boundary::normalise`).
    #[error("coordinates out of range: {what}")]
    Range { what: String },
    /// A parameter is outside the domain or a request is inconsistent.
    #[error("invalid argument: {0}")]
    Invalid(String),
    /// A knot of a map repeated more than the degree inside the domain: the map is
    /// discontinuous across that knot line, so `det J` is undefined there.
    #[error("knot {knot} in the {direction} direction has multiplicity {multiplicity} > degree {degree}: the map is discontinuous across it (split it into patches there, or lower the multiplicity to at most {degree})")]
    KnotMultiplicity { direction: String, knot: f64, multiplicity: usize, degree: usize },
    /// A linear system could not be solved (singular, or not converged).
    #[error("linear solver failed: {0}")]
    LinearSolver(String),
    /// The nonlinear solver gave up.
    #[error("no convergence: {0}")]
    NoConvergence(String),
    /// A side's boundary condition is inconsistent or not supported by the caller.
    #[error("boundary condition of the {side} side: {reason}")]
    Topology { side: String, reason: String },
    /// Planar slices that cannot be lofted into one volume (paper §11.1): heights that
    /// are not strictly increasing or not one per slice, bases that cannot be brought to
    /// one (a ring and a four-sided slice, different parameter domains), a slice given
    /// twice.
    #[error("cannot loft the slices{}: {reason}", .slice.map(|s| format!(" (slice {s})")).unwrap_or_default())]
    Slices { slice: Option<usize>, reason: String },
    /// A slice of a loft (given, or inserted where the volume was not certified) whose
    /// planar certificate is not `certified`.
    #[error("slice {slice} at z = {z} is not certified ({verdict}): {message}")]
    SliceNotCertified { slice: usize, z: f64, verdict: String, message: String },
    /// A method that needs a bijective start (paper eq. 14, 16) was given a map that is
    /// not certified.
    #[error("{method} needs a bijective start: {reason}")]
    InfeasibleStart { method: String, reason: String },
    /// A multipatch layout (paper §11.2) is inconsistent: `patch` names the patch (index
    /// and name), `side` its side (empty for the patch as a whole).
    #[error("multipatch layout, patch {patch}{}: {reason}", side_of(.side))]
    Layout { patch: String, side: String, reason: String },
    /// A solve whose estimated peak memory exceeds the limit (`--max-memory`, by default
    /// the memory available), or an allocation the allocator refused
    /// (`crate::solve::memory`): refused before it starts, never an abort.
    #[error("not enough memory for {what}: about {} needed, {} available ({limit}); {advice}", human(*.needed), human(*.available))]
    Memory { what: String, needed: u64, available: u64, limit: String, advice: String },
    /// A general planar domain or plane graph (`formats.md`) is invalid: `at` names the
    /// loop and curve (`"outer loop, curve 3"`, `"hole 1"`) or the edge.
    #[error("domain, {at}: {reason}")]
    Domain { at: String, reason: String },
    /// The observer of a [`Pipeline`](crate::pipeline::Pipeline) run stopped it.
    #[error("stopped before the solve finished")]
    Cancelled,
    /// A document of one kind (`crate::io::Document::kind`) where another is needed, or
    /// a kind of `formats.md` that this version does not read (`needed` then says so).
    #[error("{}a {found} document, where {needed}", .path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default())]
    DocumentKind { path: Option<PathBuf>, found: String, needed: String },
    /// An output file whose extension does not fit the kind of what is written.
    #[error("{path}: a {kind} cannot be written as {}; it is written as {accepted}", extension_name(.extension))]
    Extension { path: PathBuf, kind: String, extension: String, accepted: String },
    /// The six faces of a volume boundary (`formats-extensions.md`, "Volume boundary") do not bound
    /// a hexahedral volume: `face` names the face (or the two faces of an edge, or `all`),
    /// `edge` the edge of the parameter cube (empty when none).
    #[error("volume boundary, {face} face{}: {reason}", edge_of(.edge))]
    VolumeBoundary { face: String, edge: String, reason: String },
}

fn extension_name(ext: &str) -> String {
    if ext.is_empty() {
        "a file without an extension".into()
    } else {
        format!(".{ext}")
    }
}

fn edge_of(edge: &str) -> String {
    if edge.is_empty() {
        String::new()
    } else {
        format!(", edge {edge}")
    }
}

fn side_of(side: &str) -> String {
    if side.is_empty() {
        String::new()
    } else {
        format!(", {side} side")
    }
}

fn at(context: &str) -> String {
    if context.is_empty() {
        String::new()
    } else {
        format!(" in {context}")
    }
}

impl Error {
    /// Prefix the location `ctx` (e.g. `"boundary.south"`) to the error's context.
    pub fn within(mut self, ctx: &str) -> Self {
        let push = |c: &mut String| {
            *c = if c.is_empty() { ctx.to_string() } else { format!("{ctx}.{c}") };
        };
        match &mut self {
            Error::Knots { context, .. }
            | Error::Length { context, .. }
            | Error::NonFinite { context, .. }
            | Error::Weight { context, .. }
            | Error::Degree { context, .. }
            | Error::Json { context, .. }
            | Error::Xml { context, .. }
            | Error::TooLarge { context, .. } => push(context),
            _ => {}
        }
        self
    }
}

/// Largest polynomial degree accepted anywhere (evaluation uses fixed scratch).
pub(crate) const MAX_DEGREE: usize = 12;
/// Largest number of control points per direction accepted from a file.
pub const MAX_CONTROL_POINTS: usize = 1 << 20;

/// `n` bytes as `1.23 GiB`, `512 MiB`, ...
pub fn human(n: u64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = n as f64;
    let mut k = 0;
    while v >= 1024.0 && k + 1 < units.len() {
        v /= 1024.0;
        k += 1;
    }
    if k == 0 {
        format!("{n} B")
    } else {
        format!("{v:.3} {}", units[k])
    }
}

/// `n` (the `what` read at `context`) within [`MAX_CONTROL_POINTS`], or the error
/// [`Error::TooLarge`] naming it.
fn check_count(n: usize, context: &str, what: &str) -> Result<()> {
    if n > MAX_CONTROL_POINTS {
        return Err(Error::TooLarge {
            context: context.into(),
            what: what.into(),
            found: n,
            limit: MAX_CONTROL_POINTS,
        });
    }
    Ok(())
}

/// A point cloud of `n` points read at `context` within [`MAX_CONTROL_POINTS`].
pub(crate) fn check_point_count(n: usize, context: &str) -> Result<()> {
    check_count(n, context, "number of points")
}

/// A spline of `n` control points (curve, map, face or volume) read at `context` within
/// [`MAX_CONTROL_POINTS`].
pub(crate) fn check_control_point_count(n: usize, context: &str) -> Result<()> {
    check_count(n, context, "number of control points")
}
