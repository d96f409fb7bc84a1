//! Edges shared by cells: the faces of the finite-volume view of a 2D mesh.

use rayon::prelude::*;
use winslow::Side;

use crate::error::{MeshError, Result};
use crate::Mesh;

/// An edge between two cells; `nodes` in the owner's counter-clockwise order, so that
/// its right normal `(dy, -dx)` points from `owner` into `neighbour`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InternalFace {
    /// End nodes (corner nodes of the cells).
    pub nodes: [usize; 2],
    /// The cell with the lower index.
    pub owner: usize,
    /// The cell with the higher index.
    pub neighbour: usize,
}

/// An edge on the boundary, in its cell's counter-clockwise order (outward right normal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BoundaryFace {
    /// End nodes.
    pub nodes: [usize; 2],
    /// The cell it bounds.
    pub owner: usize,
    /// Its side.
    pub side: Side,
}

/// All edges of a mesh (by corner nodes): internal ones sorted by `(owner, neighbour)`,
/// boundary ones in the order of [`Mesh::boundary`].
#[derive(Debug, Clone, Default)]
pub struct Faces {
    /// Edges between two cells.
    pub internal: Vec<InternalFace>,
    /// Edges on the boundary.
    pub boundary: Vec<BoundaryFace>,
}

fn key(a: usize, b: usize) -> u128 {
    ((a.min(b) as u128) << 64) | a.max(b) as u128
}

/// Build the faces; refuses edges shared by more than two cells, boundary edges of no
/// side and labelled edges that bound no cell.
pub fn faces(mesh: &Mesh) -> Result<Faces> {
    let k = mesh.kind.corners();
    let n = mesh.num_cells();
    let mut all: Vec<(u128, usize, usize, usize)> = (0..n)
        .into_par_iter()
        .flat_map_iter(|c| {
            let v = mesh.corners(c);
            (0..k).map(move |e| {
                let (a, b) = (v[e], v[(e + 1) % k]);
                (key(a, b), c, a, b)
            })
        })
        .collect();
    all.par_sort_unstable_by_key(|t| (t.0, t.1));
    let mut internal = Vec::with_capacity(all.len() / 2);
    let mut open = std::collections::HashMap::new();
    let mut i = 0;
    while i < all.len() {
        let mut j = i + 1;
        while j < all.len() && all[j].0 == all[i].0 {
            j += 1;
        }
        match j - i {
            1 => {
                open.insert(all[i].0, (all[i].1, [all[i].2, all[i].3]));
            }
            2 => internal.push(InternalFace { nodes: [all[i].2, all[i].3], owner: all[i].1, neighbour: all[i + 1].1 }),
            m => {
                return Err(MeshError::Triangulation(format!("edge {}-{} is shared by {m} cells", all[i].2, all[i].3)))
            }
        }
        i = j;
    }
    internal.par_sort_unstable_by_key(|f| (f.owner, f.neighbour));
    let mut boundary = Vec::with_capacity(mesh.boundary.len());
    for e in &mesh.boundary {
        let (a, b) = (e.nodes[0], e.nodes[1]);
        let Some((owner, nodes)) = open.remove(&key(a, b)) else {
            return Err(MeshError::Triangulation(format!("boundary edge {a}-{b} ({}) bounds no cell", e.side)));
        };
        boundary.push(BoundaryFace { nodes, owner, side: e.side });
    }
    if let Some((_, (c, nodes))) = open.iter().next() {
        return Err(MeshError::Triangulation(format!(
            "edge {}-{} of cell {c} is on the boundary but has no side label",
            nodes[0], nodes[1]
        )));
    }
    Ok(Faces { internal, boundary })
}
