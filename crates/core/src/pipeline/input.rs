//! What the pipeline takes ([`Input`]) and gives back ([`Solved`]): every input kind of
//! `formats.md` that has an interior to parameterize (and a map to improve), and the
//! result of each. A document
//! read from a file becomes an input through [`crate::io::Document::into_input`].

use crate::boundary::ring::Ring;
use crate::boundary::volume::VolumeBoundary;
use crate::boundary::Boundary;
use crate::domain::{Domain, LayoutReport, PlaneGraph};
use crate::error::{Error, Result};
use crate::multipatch::{Layout, MultipatchSolution};
use crate::solve::report::{Solution, Verdict};
use crate::solve::volume::VolumeSolve;
use crate::solve::warm::WarmStart;
use crate::spline::surface::Surface;

use super::start::Improved;
use super::thb::ThbSolution;

/// What the pipeline solves.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Input {
    /// A four-sided boundary: the map of the unit square onto the domain it bounds.
    Boundary(Boundary),
    /// A ring (paper §11.1): an O-grid between two closed contours, `eta` periodic.
    Ring(Ring),
    /// A multipatch layout (§11.2): four-sided patches and the interfaces between them,
    /// solved conforming ([`multipatch::solve`](mod@crate::multipatch::solve); free interfaces when the options ask for
    /// an improvement).
    Layout(Layout),
    /// A general planar domain (any number of corners, holes): laid out automatically
    /// into four-sided patches ([`crate::domain::auto_layout`]), then solved as a layout.
    Domain(Domain),
    /// A plane graph: every face laid out ([`crate::domain::graph_layout`]), conforming
    /// across shared edges, then solved as one layout.
    Graph(PlaneGraph),
    /// The six boundary faces of a hexahedral volume: the trivariate EGG solve from the
    /// Coons start, the Winslow functional after it with `improve`
    /// (`solve_volume`).
    Volume(Box<VolumeBoundary>),
    /// A certified map, improved on its own basis by the pipeline's method (the Winslow
    /// functional by default) with its boundary fixed, and kept only when certified
    /// (`start`).
    Map {
        /// Name of the geometry.
        name: String,
        /// The start.
        map: Surface,
        /// The boundary the map's sides are measured against, when given.
        boundary: Option<Boundary>,
    },
}

impl Input {
    /// Name of the geometry.
    pub fn name(&self) -> &str {
        match self {
            Input::Boundary(b) => &b.name,
            Input::Ring(r) => &r.name,
            Input::Layout(l) => &l.name,
            Input::Domain(d) => &d.name,
            Input::Graph(g) => &g.name,
            Input::Volume(v) => &v.name,
            Input::Map { name, .. } => name,
        }
    }

    /// What kind of input this is, for messages: `"boundary"`, `"ring"`, `"multipatch
    /// layout"`, `"domain"`, `"graph"`, `"volume boundary"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Input::Boundary(_) => "boundary",
            Input::Ring(_) => "ring",
            Input::Layout(_) => "multipatch layout",
            Input::Domain(_) => "domain",
            Input::Graph(_) => "graph",
            Input::Volume(_) => "volume boundary",
            Input::Map { .. } => "map",
        }
    }

    /// Whether the result is one map per patch ([`Solved::Layout`]).
    pub fn is_multipatch(&self) -> bool {
        matches!(self, Input::Layout(_) | Input::Domain(_) | Input::Graph(_))
    }
}

impl From<Boundary> for Input {
    fn from(b: Boundary) -> Self {
        Input::Boundary(b)
    }
}

impl From<Ring> for Input {
    fn from(r: Ring) -> Self {
        Input::Ring(r)
    }
}

impl From<Layout> for Input {
    fn from(l: Layout) -> Self {
        Input::Layout(l)
    }
}

impl From<Domain> for Input {
    fn from(d: Domain) -> Self {
        Input::Domain(d)
    }
}

impl From<PlaneGraph> for Input {
    fn from(g: PlaneGraph) -> Self {
        Input::Graph(g)
    }
}

impl From<VolumeBoundary> for Input {
    fn from(v: VolumeBoundary) -> Self {
        Input::Volume(Box::new(v))
    }
}

/// What the pipeline gives back: one map, a conforming map per patch, or a volume.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Solved {
    /// The map of a boundary or a ring.
    Map(Box<Solution>),
    /// The maps of a layout; of a domain or a graph, with the report of its automatic
    /// layout (`laid_out`).
    Layout {
        /// The patches' maps and the layout's report.
        solution: Box<MultipatchSolution>,
        /// What the automatic layout did (a domain or a graph; `None` for a layout given
        /// as such).
        laid_out: Option<Box<LayoutReport>>,
    },
    /// The trivariate map of a volume boundary.
    Volume(Box<VolumeSolve>),
    /// A map improved from a start ([`Input::Map`]).
    Improved(Box<Improved>),
    /// A boundary solved from the previous shape's map ([`super::Pipeline::warm_start`]).
    Warm(Box<WarmStart>),
    /// With [`Refinement::Thb`](crate::solve::options::Refinement::Thb): the map of a
    /// boundary or a ring that folded, repaired by THB defect correction.
    Thb(Box<ThbSolution>),
}

impl Solved {
    /// The verdict (for a layout the worst over its patches; for a volume that of its
    /// trivariate certificate).
    pub fn verdict(&self) -> Verdict {
        match self {
            Solved::Map(s) => s.report.outcome.verdict,
            Solved::Layout { solution, .. } => solution.report.verdict,
            Solved::Volume(v) => Verdict::of_finding(&v.certificate.verdict),
            Solved::Improved(m) => m.report.verdict,
            Solved::Warm(w) => w.verdict,
            Solved::Thb(t) => t.report.verdict,
        }
    }

    /// The one map of a boundary or a ring; any other result is the error
    /// [`Error::DocumentKind`].
    pub fn into_map(self) -> Result<Solution> {
        match self {
            Solved::Map(s) => Ok(*s),
            other => {
                Err(Error::DocumentKind { path: None, found: other.kind().into(), needed: "one map is needed".into() })
            }
        }
    }

    /// The kind of result, for messages: `"map"`, `"multipatch result"`, `"volume"`,
    /// `"improved map"`, `"warm-started map"`, `"THB map"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Solved::Map(_) => "map",
            Solved::Layout { .. } => "multipatch result",
            Solved::Volume(_) => "volume",
            Solved::Improved(_) => "improved map",
            Solved::Warm(_) => "warm-started map",
            Solved::Thb(_) => "THB map",
        }
    }
}
