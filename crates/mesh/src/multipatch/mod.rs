//! One conforming mesh of a multipatch result (paper §11.2-11.3), structured
//! (quadrilaterals, below) or triangulated ([`multipatch_unstructured`]).
//!
//! The structured mesh: every
//! patch's map sampled on its own grid, the nodes of neighbouring patches merged
//! through the layout's interfaces (patch side to patch side, with `reversed`), never by
//! a search for coinciding coordinates.
//!
//! Conformity needs the same number of points on both sides of every interface. The
//! patch directions linked through interfaces form classes
//! ([`winslow::multipatch::classes::direction_classes`]: a direction of a patch runs
//! through its opposite side into the next patch); each class gets one count, the
//! largest asked of its members (`NX` for a member that is some patch's `xi`, `NY` for
//! an `eta`), so every patch has about the asked size and all interfaces match.
//! Parameters are uniform, `t_k = k / (n - 1)`; a side that runs against its neighbour
//! is paired end to start.
//!
//! Groups ([`crate::Groups`]): a cell group per face (the patches' `face`, the label of
//! the graph face or `domain` an automatic layout gives them: the physical groups of
//! a plane graph's materials), or per patch (named by the patch) when no patch names a
//! face; and a boundary group per outer side (`PATCH.SIDE`); interfaces are interior. Each node
//! keeps the parameters of the first patch it was sampled on ([`Mesh::params`] are
//! patch-local), and the nodes of an interface are evaluated on both sides and must
//! agree to `1e-9` of the layout's diameter (the patches share their interface
//! control points), else the interface is named in the error.

mod triangles;

pub use triangles::{multipatch_unstructured, MultipatchTriangulation, MAX_ROUNDS};

use glam::DVec2;
use rayon::prelude::*;
use winslow::multipatch::classes::direction_classes;
use winslow::multipatch::{Layout, PatchSide};
use winslow::{Side, Surface};

use crate::error::{MeshError, Result};
use crate::{side_names, BoundaryEdge, ElementKind, Groups, Mesh};

/// A multipatch mesh and the resolution it was made at.
#[derive(Debug, Clone)]
pub struct MultipatchMesh {
    /// The conforming mesh, with its groups.
    pub mesh: Mesh,
    /// Points of each direction class.
    pub class_points: Vec<usize>,
    /// Points per direction `[nx, ny]` of each patch.
    pub patch_points: Vec<[usize; 2]>,
    /// Largest distance between the two evaluations of an interface node (physical
    /// units).
    pub interface_gap: f64,
}

/// Union-find over the patch-local node indices.
fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Local indices `(i, j)` of the nodes of side `s` of an `[nx, ny]` grid, in the side's
/// parameter direction (south and north with increasing `xi`, west and east with `eta`).
fn side_nodes(s: Side, [nx, ny]: [usize; 2]) -> Vec<[usize; 2]> {
    match s {
        Side::South => (0..nx).map(|i| [i, 0]).collect(),
        Side::North => (0..nx).map(|i| [i, ny - 1]).collect(),
        Side::West => (0..ny).map(|j| [0, j]).collect(),
        Side::East => (0..ny).map(|j| [nx - 1, j]).collect(),
    }
}

/// The name of patch `p` for groups (its index when it has no name).
fn patch_name(layout: &Layout, p: usize) -> String {
    match layout.patches[p].name.as_str() {
        "" => format!("patch{p}"),
        n => n.to_string(),
    }
}

/// The cell groups of `layout`: their names and the group of every patch; one per
/// face (in the order of first appearance) when some patch names its face (a patch
/// without one is a group of its own), else one per patch.
pub fn cell_groups(layout: &Layout) -> (Vec<String>, Vec<usize>) {
    let mut names: Vec<String> = Vec::new();
    let mut of = Vec::with_capacity(layout.patches.len());
    let by_face = layout.patches.iter().any(|p| p.face.is_some());
    for (p, patch) in layout.patches.iter().enumerate() {
        let name = match (&patch.face, by_face) {
            (Some(f), true) => f.clone(),
            _ => patch_name(layout, p),
        };
        of.push(names.iter().position(|n| *n == name).unwrap_or_else(|| {
            names.push(name);
            names.len() - 1
        }));
    }
    (names, of)
}

/// The map of every patch; an error names a patch given by its boundary only (not
/// solved) or with a periodic direction.
pub(crate) fn patch_maps(layout: &Layout) -> Result<Vec<&Surface>> {
    if layout.patches.is_empty() {
        return Err(MeshError::param("layout", "no patches"));
    }
    layout
        .patches
        .iter()
        .enumerate()
        .map(|(p, patch)| {
            let map = patch.map.as_ref().ok_or_else(|| {
                MeshError::param(
                    format!("patch {}", layout.label(p)),
                    "is given by its boundary, not a map: solve the layout first (`winslow solve`)",
                )
            })?;
            if map.knots[0].is_periodic() || map.knots[1].is_periodic() {
                return Err(MeshError::param(format!("patch {}", layout.label(p)), "a periodic patch map"));
            }
            Ok(map)
        })
        .collect()
}

/// The conforming linear mesh of `layout` (every patch a map) with about `points`
/// `[nx, ny]` per patch (see the module documentation for how the counts are made to
/// agree across interfaces). Not checked for inverted cells: the writers validate.
pub fn multipatch(layout: &Layout, points: [usize; 2]) -> Result<MultipatchMesh> {
    if points[0] < 2 || points[1] < 2 {
        return Err(MeshError::param(
            "points",
            format!("need at least 2 per direction, got {}x{}", points[0], points[1]),
        ));
    }
    let maps = patch_maps(layout)?;
    let classes = direction_classes(layout);
    let mut class_points = vec![0usize; classes.len()];
    for m in &classes.member {
        for (d, &(c, _)) in m.iter().enumerate() {
            class_points[c] = class_points[c].max(points[d]);
        }
    }
    let patch_points: Vec<[usize; 2]> =
        classes.member.iter().map(|m| [class_points[m[0].0], class_points[m[1].0]]).collect();
    // every patch's grid: its nodes `xi` fastest, its quadrilaterals, its sides' nodes
    let grids: Vec<PatchMesh> = (0..maps.len())
        .into_par_iter()
        .map(|p| {
            let [nx, ny] = patch_points[p];
            let map = maps[p];
            let params: Vec<DVec2> = (0..ny)
                .flat_map(|j| (0..nx).map(move |i| DVec2::new(i as f64 / (nx - 1) as f64, j as f64 / (ny - 1) as f64)))
                .collect();
            let points = params.iter().map(|q| DVec2::from(map.eval(q.x, q.y))).collect();
            let id = |[i, j]: [usize; 2]| j * nx + i;
            let mut cells = Vec::with_capacity(4 * (nx - 1) * (ny - 1));
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    cells.extend([id([i, j]), id([i + 1, j]), id([i + 1, j + 1]), id([i, j + 1])]);
                }
            }
            let sides = Side::ALL.map(|s| side_nodes(s, [nx, ny]).into_iter().map(id).collect());
            PatchMesh { points, params, cells, sides }
        })
        .collect();
    let (mesh, interface_gap) = merge(layout, grids, ElementKind::Quad)?;
    Ok(MultipatchMesh { mesh, class_points, patch_points, interface_gap })
}

/// One patch's mesh before the merge: its nodes, its cells (local node indices, corners
/// counter-clockwise) and the nodes of each side in the side's parameter direction
/// (south and north with increasing `xi`, west and east with `eta`), corners included.
#[derive(Debug, Clone)]
pub(crate) struct PatchMesh {
    /// Physical node coordinates.
    pub points: Vec<DVec2>,
    /// Patch-local parameters of the nodes.
    pub params: Vec<DVec2>,
    /// Cell connectivity, local indices.
    pub cells: Vec<usize>,
    /// The nodes of each side (indexed by `Side as usize`), along the side.
    pub sides: [Vec<usize>; 4],
}

/// The conforming mesh of the patches' meshes: the nodes of every interface's two sides
/// identified pairwise (same count, the second side's order reversed when the interface
/// is), never by a search for coinciding coordinates; a node keeps its first patch's
/// position and parameters. The cells are grouped by face ([`cell_groups`]) and the
/// outer sides' edges by `PATCH.SIDE`, counter-clockwise around their patch. Also
/// returns the largest distance between the two evaluations of an interface node; more
/// than `1e-9` of the layout's diameter is an error naming the interface.
pub(crate) fn merge(layout: &Layout, patches: Vec<PatchMesh>, kind: ElementKind) -> Result<(Mesh, f64)> {
    let mut offset = Vec::with_capacity(patches.len() + 1);
    offset.push(0usize);
    for m in &patches {
        offset.push(offset.last().copied().unwrap_or(0) + m.points.len());
    }
    let total = offset[patches.len()];
    let at = |x: usize| {
        let p = offset.partition_point(|&o| o <= x) - 1;
        (p, x - offset[p])
    };
    let mut parent: Vec<usize> = (0..total).collect();
    let diameter = layout.diameter();
    let mut gap = 0.0f64;
    for (k, itf) in layout.interfaces.iter().enumerate() {
        let (a, b) = (itf.first, itf.second);
        if a.patch >= patches.len() || b.patch >= patches.len() {
            return Err(MeshError::param(format!("interface {k}"), "names a patch that does not exist"));
        }
        let na = &patches[a.patch].sides[a.side as usize];
        let mut nb = patches[b.patch].sides[b.side as usize].clone();
        let name = |ps: PatchSide| format!("{}.{}", patch_name(layout, ps.patch), ps.side.name());
        if na.len() != nb.len() {
            return Err(MeshError::param(
                format!("interface {} - {}", name(a), name(b)),
                format!("{} and {} points on its two sides (the patches' meshes disagree)", na.len(), nb.len()),
            ));
        }
        if itf.reversed {
            nb.reverse();
        }
        let mut worst = 0.0f64;
        for (&u, &v) in na.iter().zip(&nb) {
            let (x, y) = (offset[a.patch] + u, offset[b.patch] + v);
            worst = worst.max(patches[a.patch].points[u].distance(patches[b.patch].points[v]));
            let (rx, ry) = (find(&mut parent, x), find(&mut parent, y));
            if rx != ry {
                // the smaller index represents: the node keeps its first patch's sample
                parent[rx.max(ry)] = rx.min(ry);
            }
        }
        if worst > 1e-9 * diameter || worst.is_nan() {
            return Err(MeshError::param(
                format!("interface {} - {}", name(a), name(b)),
                format!(
                    "its two sides are {worst:e} apart (diameter {diameter:e}); neighbouring patches must share their interface control points"
                ),
            ));
        }
        gap = gap.max(worst);
    }
    // global numbering of the representatives, in order of first appearance
    let mut global = vec![usize::MAX; total];
    let (mut pts, mut params) = (Vec::new(), Vec::new());
    for x in 0..total {
        let r = find(&mut parent, x);
        if global[r] == usize::MAX {
            global[r] = pts.len();
            let (p, i) = at(r);
            pts.push(patches[p].points[i]);
            params.push(patches[p].params[i]);
        }
        global[x] = global[r];
    }
    let id = |p: usize, i: usize| global[offset[p] + i];
    let (group_names, group_of) = cell_groups(layout);
    let corners = kind.corners();
    let mut cells = Vec::new();
    let mut cell_group = Vec::new();
    for (p, m) in patches.iter().enumerate() {
        cells.extend(m.cells.iter().map(|&i| id(p, i)));
        cell_group.extend(std::iter::repeat_n(group_of[p], m.cells.len() / corners));
    }
    // the outer sides, each counter-clockwise around its patch
    let mut boundary = Vec::new();
    let mut edge_group = Vec::new();
    let mut boundary_names = Vec::new();
    for ps in layout.outer_sides() {
        let nodes = &patches[ps.patch].sides[ps.side as usize];
        let mut edges: Vec<BoundaryEdge> = nodes
            .windows(2)
            .map(|w| BoundaryEdge { side: ps.side, nodes: vec![id(ps.patch, w[0]), id(ps.patch, w[1])] })
            .collect();
        if matches!(ps.side, Side::North | Side::West) {
            edges.reverse();
            for e in &mut edges {
                e.nodes.reverse();
            }
        }
        edge_group.extend(std::iter::repeat_n(boundary_names.len(), edges.len()));
        boundary.extend(edges);
        boundary_names.push(format!("{}.{}", patch_name(layout, ps.patch), ps.side.name()));
    }
    let groups = Groups { boundary: boundary_names, edge_group, cells: group_names, cell_group };
    let mesh = Mesh {
        points: pts,
        params,
        kind,
        order: 1,
        cells,
        boundary,
        structured: None,
        periodic: [false, false],
        names: side_names(),
        groups: Some(groups),
    };
    Ok((mesh, gap))
}
