//! # winslow-mesh
//!
//! Classical meshes from a certified spline map `x(xi, eta)` (paper §11.3): the map is
//! sampled, never re-solved, so any density costs only function evaluations.
//!
//! | module | what lives there |
//! |---|---|
//! | [`distribution`] | point distributions per direction: uniform, arctan (eq. 50), tanh, geometric layers |
//! | [`equidistribution`] | points equidistributing boundary arc length or curvature (a chord tolerance with the fewest points) |
//! | [`structured`](mod@structured) | structured quadrilateral meshes at `xi_i x eta_j`, first-cell heights in physical units |
//! | [`unstructured`](mod@unstructured) | constrained Delaunay triangulations of the parameter square (spade), refined against physical sizes |
//! | [`high_order`] | curved quadratic and cubic elements with nodes on the map, their Jacobians checked |
//! | [`quality`] | cell areas, angles, aspect ratio, skewness, growth, non-orthogonality; the refusal of inverted cells |
//! | [`seam`] | periodic seams: a ring's periodic direction, or two coinciding sides of a ring cut into a four-sided map, merged into one line of nodes; walls named `inner`/`outer` |
//! | [`topology`] | edges shared by cells (faces of the finite-volume view) |
//! | [`multipatch`](mod@multipatch) | one conforming mesh of a multipatch result, structured or triangulated: nodes merged through the interfaces, a cell group per face, a boundary group per outer side |
//! | [`validate`] | the rules a solver's reader enforces (positive volumes, one orientation, no duplicate nodes, non-orthogonality below 90° for OpenFOAM), checked before every write |
//! | [`volume`] | structured hexahedral meshes of a trivariate map (a loft), corner Jacobians checked, the six sides named; `.vtu` and `.msh` |
//! | [`formats`] | writers: Gmsh MSH 4.1, VTK `.vtu`, SU2, PLOT3D, OpenFOAM `polyMesh` |
//!
//! Every mesh is a [`Mesh`]: nodes (physical and parameter coordinates), cells of one
//! [`ElementKind`] and order with nodes in Gmsh's ordering, and boundary edges labelled
//! by [`Side`] and named by [`Mesh::names`] (`inner`/`outer` on a ring). A periodic
//! direction of the map (a ring's `eta`), or one whose two end sides coincide (a cut
//! ring, [`seam`]), has one node per seam point and no boundary on its seam, in
//! structured and unstructured meshes alike. Writers refuse a mesh that breaks a rule of the format
//! ([`validate::validate`]).

pub mod distribution;
pub mod equidistribution;
pub mod error;
pub mod formats;
pub mod high_order;
pub mod multipatch;
pub mod quality;
pub mod rectangle;
pub mod seam;
pub mod structured;
pub mod topology;
pub mod unstructured;
pub mod validate;
pub mod volume;

pub use distribution::{Distribution, End};
pub use equidistribution::Equidistribution;
pub use error::{MeshError, Result};
pub use glam::DVec2;
pub use multipatch::{multipatch, multipatch_unstructured, MultipatchMesh, MultipatchTriangulation};
pub use quality::{CellQuality, Quality};
use rayon::prelude::*;
pub use structured::{structured, StructuredOptions};
pub use unstructured::{parameter_scale, unstructured, unstructured_with_stats, MeshingStats, UnstructuredOptions};
pub use winslow::Side;

/// The cell shape of a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElementKind {
    /// Triangles.
    Triangle,
    /// Quadrilaterals.
    Quad,
}

impl ElementKind {
    /// Corner count.
    pub fn corners(self) -> usize {
        match self {
            ElementKind::Triangle => 3,
            ElementKind::Quad => 4,
        }
    }

    /// Nodes of an element of order `p`: `(p + 1)(p + 2) / 2` or `(p + 1)^2`.
    pub fn nodes(self, order: usize) -> usize {
        match self {
            ElementKind::Triangle => (order + 1) * (order + 2) / 2,
            ElementKind::Quad => (order + 1) * (order + 1),
        }
    }

    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            ElementKind::Triangle => "triangle",
            ElementKind::Quad => "quadrilateral",
        }
    }
}

/// One boundary edge: its side and its nodes (the two ends in counter-clockwise order
/// around the domain, then the interior nodes from the first end on, as Gmsh orders
/// lines).
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryEdge {
    /// Side of the parameter square the edge lies on.
    pub side: Side,
    /// Node indices.
    pub nodes: Vec<usize>,
}

/// A mesh of the map's image.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Physical node coordinates `x(xi, eta)`.
    pub points: Vec<DVec2>,
    /// Parameter coordinates `(xi, eta)` of each node; boundary nodes lie exactly on
    /// `xi in {0, 1}` or `eta in {0, 1}`.
    pub params: Vec<DVec2>,
    /// Cell shape.
    pub kind: ElementKind,
    /// Polynomial order of the elements (1, 2 or 3).
    pub order: usize,
    /// Cell connectivity, `kind.nodes(order)` indices per cell in Gmsh's node ordering
    /// (corners counter-clockwise first).
    pub cells: Vec<usize>,
    /// Boundary edges, counter-clockwise around the domain.
    pub boundary: Vec<BoundaryEdge>,
    /// Points per direction `[nx, ny]` when the nodes are a structured grid stored
    /// `xi` fastest (linear structured meshes only); a periodic direction has as many
    /// points as cells (its seam is not repeated).
    pub structured: Option<[usize; 2]>,
    /// Periodic parameter directions (`[false, true]` for a ring, and for a ring cut
    /// into a four-sided map whose south and north coincide, [`seam`]): parameters in
    /// `[0, 1)`, cells wrap around the seam, no boundary edges on it.
    pub periodic: [bool; 2],
    /// Name of the boundary group of each side (indexed by `Side as usize`): the side
    /// names for a four-sided map, `inner`/`outer` for the walls of a ring.
    pub names: [String; 4],
    /// Named boundary and cell groups of a mesh of several patches ([`multipatch`](mod@multipatch));
    /// `None` for a mesh of one map, whose boundary groups are its sides ([`Mesh::names`])
    /// and whose cells are one group `domain`.
    pub groups: Option<Groups>,
}

/// Named groups of a mesh of several patches: boundary edges and cells by group index.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Groups {
    /// Name of each boundary group (`PATCH.SIDE` for an outer side of a patch).
    pub boundary: Vec<String>,
    /// Boundary group of each edge of [`Mesh::boundary`].
    pub edge_group: Vec<usize>,
    /// Name of each cell group (a patch's name).
    pub cells: Vec<String>,
    /// Cell group of each cell.
    pub cell_group: Vec<usize>,
}

/// The side names `south`, `east`, `north`, `west`.
pub fn side_names() -> [String; 4] {
    Side::ALL.map(|s| s.name().to_string())
}

/// The periodic directions of a map (those whose knot vector is periodic).
pub fn periodic_directions(map: &winslow::Surface) -> [bool; 2] {
    [map.knots[0].is_periodic(), map.knots[1].is_periodic()]
}

impl Mesh {
    /// Nodes per cell.
    pub fn nodes_per_cell(&self) -> usize {
        self.kind.nodes(self.order)
    }

    /// Number of cells.
    pub fn num_cells(&self) -> usize {
        self.cells.len() / self.nodes_per_cell()
    }

    /// The nodes of cell `c`.
    pub fn cell(&self, c: usize) -> &[usize] {
        let n = self.nodes_per_cell();
        &self.cells[c * n..(c + 1) * n]
    }

    /// The name of the boundary group of `side`.
    pub fn name(&self, side: Side) -> &str {
        &self.names[side as usize]
    }

    /// The boundary groups that hold edges: name and the indices into [`Mesh::boundary`]
    /// of its edges, in order (the sides south, east, north, west of a single map; the
    /// [`Groups`] of a multipatch mesh).
    pub fn boundary_groups(&self) -> Vec<(&str, Vec<usize>)> {
        match &self.groups {
            Some(g) => (0..g.boundary.len())
                .map(|k| {
                    let edges = (0..self.boundary.len()).filter(|&e| g.edge_group.get(e) == Some(&k)).collect();
                    (g.boundary[k].as_str(), edges)
                })
                .filter(|(_, e): &(&str, Vec<usize>)| !e.is_empty())
                .collect(),
            None => self
                .boundary_sides()
                .into_iter()
                .map(|s| (self.name(s), (0..self.boundary.len()).filter(|&e| self.boundary[e].side == s).collect()))
                .collect(),
        }
    }

    /// The cell groups: name and cell indices (one group `domain` of every cell for a
    /// single map; a group per patch of a multipatch mesh).
    pub fn cell_groups(&self) -> Vec<(&str, Vec<usize>)> {
        match &self.groups {
            Some(g) => (0..g.cells.len())
                .map(|k| (g.cells[k].as_str(), (0..self.num_cells()).filter(|&c| g.cell_group[c] == k).collect()))
                .collect(),
            None => vec![("domain", (0..self.num_cells()).collect())],
        }
    }

    /// The sides that carry boundary edges, in the order south, east, north, west.
    pub fn boundary_sides(&self) -> Vec<Side> {
        Side::ALL.into_iter().filter(|&s| self.boundary.iter().any(|e| e.side == s)).collect()
    }

    /// The corner nodes of cell `c`, counter-clockwise.
    pub fn corners(&self, c: usize) -> &[usize] {
        &self.cell(c)[..self.kind.corners()]
    }

    /// Refuse a mesh with an inverted or degenerate cell: every corner of every cell must
    /// turn left (`(b - a) x (c - b) > 0`), and curved elements must have a positive
    /// Jacobian at their nodes and quadrature points ([`high_order::check_jacobians`]).
    pub fn check(&self) -> Result<()> {
        let bad: Vec<usize> =
            (0..self.num_cells()).into_par_iter().filter(|&c| quality::corner_defect(self, c).is_some()).collect();
        if let Some(&cell) = bad.first() {
            let why = quality::corner_defect(self, cell).unwrap_or_default();
            return Err(MeshError::Inverted { cell, why, count: bad.len() });
        }
        if self.order > 1 {
            high_order::check_jacobians(self)?;
        }
        Ok(())
    }
}

/// The nodes of the map's image with parameters `params`.
pub fn map_points(map: &winslow::Surface, params: &[DVec2]) -> Vec<DVec2> {
    params.par_iter().map(|q| DVec2::from(map.eval(q.x, q.y))).collect()
}
