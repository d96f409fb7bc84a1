//! General planar domains (`formats.md`, "General planar domain"): an outer loop of any
//! number of corners and zero or more holes, each loop a closed chain of sides whose
//! joints are its corners; their validation, and the automatic quad layout that turns
//! such a domain into a conforming multipatch [`Layout`](crate::multipatch::Layout)
//! (issue 31; Hinz & Buffa, arXiv 2307.06265; Hinz, arXiv 2406.01347).
//!
//! | module | holds |
//! |---|---|
//! | [`corpus`] | a seeded corpus: `N`-gons with curved sides, L, T, U, E and plus shapes with sharp or filleted reflex corners, plates with holes, plane graphs |
//! | `families` | the generators of plates with holes, wiggly squares and motor-like sections |
//! | `validate` | closed loops, no self-intersections, holes inside the outer loop and apart, orientation, area: typed errors naming the loop and curve |
//! | `harmonic` | the discrete harmonic map of a regular `N`-gon onto a face (P1 finite elements), which places the template's vertices and cuts |
//! | `polygon_map` | the map of a face onto the regular `N`-gon (Floater's mean value map, one-to-one on every face) and its piecewise-linear inverse, which places the template's vertices and cuts where the harmonic map's layout is not valid |
//! | `plane` | plane graphs (`formats.md`, "Plane graph"): validation, their faces, holes, voids and labels |
//! | `cycles` | the faces of a plane graph as cycles of half-edges |
//! | `graph` | the faces, edges and vertices of a layout under construction: edges split at a point, faces split by a new edge |
//! | `holes` | cuts from every hole to the outer boundary or another hole |
//! | `reflex` | cuts from reflex corners into the face |
//! | `spokes` | the spokes of the midpoint template, the patch corner angles they make, and the interior vertex searched where one is near 0° or 180° |
//! | `midpoint` | the midpoint template (`N` quads around one interior vertex): its placement by the harmonic map, the map onto the polygon, a star centre or the searched vertex, and its quads |
//! | `crosscut` | the cut across a thin face whose midpoint template keeps a corner near 0° or 180°: corner to opposite corner (or side midpoint), two faces with fewer corners |
//! | `outline` | the outer boundary and holes of a multipatch layout as a domain (the input of a comparison with the hand-made layout) |
//! | [`template`] | the quadrangulation of every face by its template (the midpoint template, a face split in two, a face cut across), placed by the harmonic map or the map onto the polygon |
//! | [`layout`] | the automatic layout as a whole: the sides into a graph of faces, the cuts, the tries (searches of the cuts' ends, directions of the hole cuts, the maps onto the polygons), its report and the multipatch layout |
//!
//! Files are read by [`crate::io::read`] ([`crate::io::Document::Domain`]).

pub mod corpus;
pub(crate) mod crosscut;
pub(crate) mod cycles;
pub(crate) mod families;
pub(crate) mod graph;
pub(crate) mod harmonic;
pub(crate) mod holes;
pub mod layout;
pub(crate) mod midpoint;
pub(crate) mod outline;
pub(crate) mod plane;
pub(crate) mod polygon_map;
pub(crate) mod reflex;
pub(crate) mod spokes;
pub mod template;
pub(crate) mod validate;

use crate::boundary::SideCurve;
use crate::error::Error;
use crate::spline::curve::Point;

pub use holes::HoleCut;
pub use layout::{auto_layout, graph_layout, AutoLayout, LayoutOptions, LayoutReport};
pub use outline::outline;
pub use plane::{GraphFace, GraphReport, PlaneEdge, PlaneGraph, PlaneLabel};
pub use reflex::CutReport;
pub use validate::{validate_domain, DomainReport};

/// A closed loop: a chain of sides, each starting where the previous one ends (the last
/// ending where the first starts). The joints (the start of every side) are the loop's
/// corners.
#[derive(Debug, Clone)]
pub struct Loop {
    /// The sides in order (B-spline or NURBS curves, or point clouds).
    pub sides: Vec<SideCurve>,
    /// Corners that were detected (a point cloud without `corners`), for the report.
    pub detected_corners: Vec<Point>,
}

impl Loop {
    /// A loop of the given sides.
    pub fn new(sides: Vec<SideCurve>) -> Self {
        Self { sides, detected_corners: Vec::new() }
    }

    /// Number of corners (one per side).
    pub fn corners(&self) -> usize {
        self.sides.len()
    }

    /// The same loop traversed the other way.
    pub fn reversed(&self) -> Self {
        Self {
            sides: self.sides.iter().rev().map(SideCurve::reversed).collect(),
            detected_corners: self.detected_corners.clone(),
        }
    }
}

/// Which loop of a domain: the outer one or a hole (by index).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LoopId {
    /// The outer loop.
    Outer,
    /// Hole `k`.
    Hole(usize),
}

impl std::fmt::Display for LoopId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LoopId::Outer => f.write_str("outer loop"),
            LoopId::Hole(k) => write!(f, "hole {k}"),
        }
    }
}

/// A general planar domain: the region inside `outer` and outside every hole.
#[derive(Debug, Clone)]
pub struct Domain {
    /// Name of the geometry.
    pub name: String,
    /// The outer loop (counter-clockwise after [`validate_domain`]).
    pub outer: Loop,
    /// The holes (clockwise after [`validate_domain`]).
    pub holes: Vec<Loop>,
}

impl Domain {
    /// The loop `id`.
    pub(crate) fn loop_of(&self, id: LoopId) -> &Loop {
        match id {
            LoopId::Outer => &self.outer,
            LoopId::Hole(k) => &self.holes[k],
        }
    }

    /// Every loop with its id, the outer one first.
    pub(crate) fn loops(&self) -> impl Iterator<Item = (LoopId, &Loop)> {
        std::iter::once((LoopId::Outer, &self.outer))
            .chain(self.holes.iter().enumerate().map(|(k, l)| (LoopId::Hole(k), l)))
    }
}

/// The error [`Error::Domain`] at loop `id` (and curve `curve`, if any).
pub(crate) fn domain_error(id: LoopId, curve: Option<usize>, reason: impl Into<String>) -> Error {
    let at = match curve {
        Some(c) => format!("{id}, curve {c}"),
        None => id.to_string(),
    };
    Error::Domain { at, reason: reason.into() }
}

#[cfg(test)]
mod tests;
