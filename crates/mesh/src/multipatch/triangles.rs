//! One conforming unstructured triangulation of a multipatch result (paper §11.2-11.3):
//! every patch triangulated in its own parameter rectangle
//! ([`crate::unstructured`]: constrained Delaunay, refined against physical sizes),
//! with the points on every interface shared by its two patches.
//!
//! The two patches of an interface are triangulated with the same boundary points (the
//! first patch's, at equal physical arc length, mapped to the second through
//! `reversed`: `t -> 1 - t`). Refinement may split a boundary segment (spade's
//! encroachment, the size and the chord criteria), so the points are then read back
//! from both meshes and made one set, the union (values within `1e-11` are one point),
//! and the patches whose interface points grew are triangulated again with it: the
//! points only grow, and the rounds stop when every interface's two sides hold the same
//! points (at most [`MAX_ROUNDS`]). The nodes are then identified through the interfaces
//! like the structured mesh's ([`super::merge`]), pairwise in order along the side, never
//! by a search for coinciding coordinates: a cell group per face, a boundary group per
//! outer side.

use glam::DVec2;
use rayon::prelude::*;
use winslow::multipatch::Layout;
use winslow::{Side, Surface};

use super::{merge, patch_maps, PatchMesh};
use crate::error::{MeshError, Result};
use crate::unstructured::{side_points, triangulate, MeshingStats, UnstructuredOptions};
use crate::{ElementKind, Mesh};

/// Most rounds of re-triangulating patches whose interface points grew.
pub const MAX_ROUNDS: usize = 64;

/// Parameter values closer than this along a side are one point.
const SAME: f64 = 1e-11;

/// A conforming triangulation of a multipatch result.
#[derive(Debug, Clone)]
pub struct MultipatchTriangulation {
    /// The conforming mesh, with its groups.
    pub mesh: Mesh,
    /// Rounds until every interface's two sides held the same points (1: the first
    /// triangulations agreed).
    pub rounds: usize,
    /// Triangles of each patch.
    pub patch_cells: Vec<usize>,
    /// Largest distance between the two evaluations of an interface node (physical
    /// units).
    pub interface_gap: f64,
    /// The patches' meshing times and rounds, summed over patches and rounds.
    pub stats: MeshingStats,
}

/// The coordinate along `side` of a parameter point (`xi` on south and north, `eta` on
/// west and east).
fn along(side: Side, q: DVec2) -> f64 {
    match side {
        Side::South | Side::North => q.x,
        Side::East | Side::West => q.y,
    }
}

/// The nodes of each side of a single-map mesh, sorted along the side, corners included.
fn side_nodes(mesh: &Mesh) -> [Vec<usize>; 4] {
    Side::ALL.map(|s| {
        let mut nodes: Vec<usize> =
            mesh.boundary.iter().filter(|e| e.side == s).flat_map(|e| e.nodes.clone()).collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes.sort_by(|&a, &b| along(s, mesh.params[a]).total_cmp(&along(s, mesh.params[b])));
        nodes
    })
}

/// The interior points of each side of a mesh, along the side.
fn side_values(mesh: &Mesh) -> [Vec<f64>; 4] {
    let nodes = side_nodes(mesh);
    Side::ALL.map(|s| {
        let n = &nodes[s as usize];
        n.iter().map(|&i| along(s, mesh.params[i])).filter(|&t| t > 0.0 && t < 1.0).collect()
    })
}

/// The union of two sorted point sets (one pass), a value of `a` kept where both have
/// one (within [`SAME`]).
fn union(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        match (a.get(i), b.get(j)) {
            (Some(&s), Some(&t)) if (s - t).abs() <= SAME => {
                out.push(s);
                i += 1;
                j += 1;
            }
            (Some(&s), Some(&t)) if s < t => {
                out.push(s);
                i += 1;
            }
            (Some(&s), None) => {
                out.push(s);
                i += 1;
            }
            (_, Some(&t)) => {
                out.push(t);
                j += 1;
            }
            (None, None) => break,
        }
    }
    out
}

/// `t -> 1 - t` (sorted) when `reversed`.
fn flip(t: &[f64], reversed: bool) -> Vec<f64> {
    if reversed {
        t.iter().rev().map(|t| 1.0 - t).collect()
    } else {
        t.to_vec()
    }
}

/// The conforming linear triangulation of `layout` (every patch a map) with the
/// options of a single map's ([`crate::unstructured()`]; `order` must be 1: curved cells
/// need one map per mesh). Not checked for inverted cells: the writers validate.
pub fn multipatch_unstructured(layout: &Layout, opts: &UnstructuredOptions) -> Result<MultipatchTriangulation> {
    if opts.order != 1 {
        return Err(MeshError::param("order", "a multipatch triangulation has linear cells only"));
    }
    if !(opts.size.is_finite() && opts.size > 0.0) {
        return Err(MeshError::param("size", format!("must be positive, got {}", opts.size)));
    }
    let maps: Vec<&Surface> = patch_maps(layout)?;
    let np = maps.len();
    for (k, itf) in layout.interfaces.iter().enumerate() {
        if itf.first.patch >= np || itf.second.patch >= np {
            return Err(MeshError::param(format!("interface {k}"), "names a patch that does not exist"));
        }
    }
    // the first boundary points: equal physical arc length on each side, an interface's
    // second side taking its first side's
    let interior = |map: &Surface, s: Side| -> Vec<f64> {
        let mut t: Vec<f64> = side_points(map, s, opts.size).iter().skip(1).map(|&q| along(s, q)).collect();
        t.sort_by(f64::total_cmp);
        t
    };
    let mut given: Vec<[Vec<f64>; 4]> = maps.iter().map(|m| Side::ALL.map(|s| interior(m, s))).collect();
    for itf in &layout.interfaces {
        let (a, b) = (itf.first, itf.second);
        given[b.patch][b.side as usize] = flip(&given[a.patch][a.side as usize], itf.reversed);
    }
    let mut meshes: Vec<Option<Mesh>> = vec![None; np];
    let mut todo: Vec<usize> = (0..np).collect();
    let mut stats = MeshingStats::default();
    let mut rounds = 0;
    while !todo.is_empty() {
        if rounds == MAX_ROUNDS {
            return Err(MeshError::Triangulation(format!(
                "the interface points of {} patches still grew after {MAX_ROUNDS} rounds; use a larger size",
                todo.len()
            )));
        }
        rounds += 1;
        let made: Vec<(usize, Result<(Mesh, MeshingStats)>)> =
            todo.par_iter().map(|&p| (p, triangulate(maps[p], opts, Some(&given[p])))).collect();
        for (p, r) in made {
            let (m, st) = r.map_err(|e| MeshError::param(format!("patch {}", layout.label(p)), e.to_string()))?;
            stats += st;
            // the points it ended with (an outer side keeps them: the next round starts there)
            given[p] = side_values(&m);
            meshes[p] = Some(m);
        }
        let mut again = vec![false; np];
        for itf in &layout.interfaces {
            let (a, b) = (itf.first, itf.second);
            let ta = given[a.patch][a.side as usize].clone();
            let tb = flip(&given[b.patch][b.side as usize], itf.reversed);
            let u = union(&ta, &tb);
            if u.len() != ta.len() {
                again[a.patch] = true;
                given[a.patch][a.side as usize] = u.clone();
            }
            if u.len() != tb.len() {
                again[b.patch] = true;
                given[b.patch][b.side as usize] = flip(&u, itf.reversed);
            }
        }
        todo = (0..np).filter(|&p| again[p]).collect();
    }
    let meshes: Vec<Mesh> = meshes.into_iter().flatten().collect();
    let patch_cells = meshes.iter().map(Mesh::num_cells).collect();
    let patches: Vec<PatchMesh> = meshes
        .into_iter()
        .map(|m| {
            let sides = side_nodes(&m);
            PatchMesh { points: m.points, params: m.params, cells: m.cells, sides }
        })
        .collect();
    let (mesh, interface_gap) = merge(layout, patches, ElementKind::Triangle)?;
    Ok(MultipatchTriangulation { mesh, rounds, patch_cells, interface_gap, stats })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_keeps_one_of_each_point_and_the_first_sets_values() {
        let a = [0.25, 0.5, 0.75];
        let b = [0.125, 0.5 + 1e-13, 0.625, 0.75, 0.875];
        assert_eq!(union(&a, &b), vec![0.125, 0.25, 0.5, 0.625, 0.75, 0.875]);
        assert_eq!(union(&b, &a)[2], 0.5 + 1e-13);
        assert_eq!(union(&a, &[]), a.to_vec());
        assert_eq!(union(&[], &a), a.to_vec());
        assert_eq!(flip(&[0.25, 0.5], true), vec![0.5, 0.75]);
    }
}
