//! SU2 native mesh (`.su2`, ASCII): `NDIME= 2`, the cells as VTK types (5 triangle,
//! 9 quad) with their index, the points with their index, and one marker per side
//! named by [`Mesh::names`] (`MARKER_TAG= south`, ..., `inner`/`outer` on a ring) of line
//! elements (VTK type 3); a multipatch mesh has one marker per boundary group
//! ([`Mesh::boundary_groups`], `PATCH.SIDE`) and one zone (SU2 has no cell groups in a
//! single-zone file: the patches are not told apart). Linear cells only.

use std::fmt::Write;

use crate::error::Result;
use crate::{ElementKind, Mesh};

/// The file's text.
pub fn to_string(mesh: &Mesh) -> Result<String> {
    super::linear_only(mesh, "SU2")?;
    let cells = mesh.num_cells();
    let mut s = String::with_capacity(48 * mesh.points.len() + 24 * cells);
    let t = match mesh.kind {
        ElementKind::Triangle => 5,
        ElementKind::Quad => 9,
    };
    let _ = writeln!(s, "% winslow mesh\nNDIME= 2\nNELEM= {cells}");
    s.push_str(&super::par_text(cells, |s, c| {
        let _ = write!(s, "{t}");
        for v in mesh.cell(c) {
            let _ = write!(s, " {v}");
        }
        let _ = writeln!(s, " {c}");
    }));
    let _ = writeln!(s, "NPOIN= {}", mesh.points.len());
    s.push_str(&super::par_text(mesh.points.len(), |s, i| {
        let p = mesh.points[i];
        let _ = writeln!(s, "{} {} {i}", p.x, p.y);
    }));
    let groups = mesh.boundary_groups();
    let _ = writeln!(s, "NMARK= {}", groups.len());
    for (name, edges) in groups {
        let _ = writeln!(s, "MARKER_TAG= {name}\nMARKER_ELEMS= {}", edges.len());
        for e in edges {
            let e = &mesh.boundary[e];
            let _ = writeln!(s, "3 {} {}", e.nodes[0], e.nodes[1]);
        }
    }
    Ok(s)
}
