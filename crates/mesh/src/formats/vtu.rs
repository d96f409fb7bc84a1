//! VTK XML unstructured grid (`.vtu`, ASCII), with the quality fields as cell data and
//! the parameters `(xi, eta)` as point data (patch-local on a multipatch mesh, which
//! also has the cell data `patch`: the index of each cell's patch, [`Mesh::cell_groups`]).
//!
//! Cell types: triangle 5, quad 9; quadratic triangle 22 and biquadratic quad 28 (node
//! order equal to Gmsh's 9 and 10); cubic Lagrange triangle 69 (Gmsh 21's order) and
//! quad 70, whose edges 2 and 3 run `3 -> 2` and `0 -> 3` and whose interior is
//! lexicographic, so Gmsh 36's nodes are permuted ([`QUAD16_FROM_GMSH`]).

use std::fmt::Write;

use crate::error::Result;
use crate::quality::quality;
use crate::{ElementKind, Mesh};

/// VTK Lagrange quadrilateral (order 3) node `k` is Gmsh type 36 node `QUAD16_FROM_GMSH[k]`.
pub const QUAD16_FROM_GMSH: [usize; 16] = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8, 11, 10, 12, 13, 15, 14];

/// VTK cell type of a kind and order.
pub fn cell_type(kind: ElementKind, order: usize) -> u8 {
    match (kind, order) {
        (ElementKind::Triangle, 1) => 5,
        (ElementKind::Triangle, 2) => 22,
        (ElementKind::Triangle, _) => 69,
        (ElementKind::Quad, 1) => 9,
        (ElementKind::Quad, 2) => 28,
        (ElementKind::Quad, _) => 70,
    }
}

/// The file's text.
pub fn to_string(mesh: &Mesh) -> Result<String> {
    let q = quality(mesh)?;
    let n = mesh.points.len();
    let cells = mesh.num_cells();
    let npc = mesh.nodes_per_cell();
    let mut s = String::with_capacity(60 * n + 20 * mesh.cells.len() + 150 * cells);
    let _ = write!(
        s,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{cells}\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n"
    );
    s.push_str(&super::par_text(n, |s, i| {
        let p = mesh.points[i];
        let _ = writeln!(s, "{} {} 0", p.x, p.y);
    }));
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    let cubic_quad = mesh.kind == ElementKind::Quad && mesh.order == 3;
    s.push_str(&super::par_text(cells, |s, c| {
        let v = mesh.cell(c);
        for k in 0..npc {
            let g = if cubic_quad { QUAD16_FROM_GMSH[k] } else { k };
            let _ = write!(s, "{} ", v[g]);
        }
        s.push('\n');
    }));
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for c in 1..=cells {
        let _ = writeln!(s, "{}", c * npc);
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    let t = cell_type(mesh.kind, mesh.order);
    for _ in 0..cells {
        let _ = writeln!(s, "{t}");
    }
    s.push_str("</DataArray>\n</Cells>\n<CellData Scalars=\"area\">\n");
    type Field = fn(&crate::CellQuality) -> f64;
    let fields: [(&str, Field); 7] = [
        ("area", |c| c.area),
        ("min_angle", |c| c.min_angle),
        ("max_angle", |c| c.max_angle),
        ("aspect_ratio", |c| c.aspect),
        ("skewness", |c| c.skewness),
        ("growth_ratio", |c| c.growth),
        ("non_orthogonality", |c| c.non_orthogonality),
    ];
    for (name, f) in fields {
        let _ = writeln!(s, "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">");
        s.push_str(&super::par_text(cells, |s, c| {
            let _ = writeln!(s, "{}", f(&q.per_cell[c]));
        }));
        s.push_str("</DataArray>\n");
    }
    if let Some(g) = &mesh.groups {
        // the cell group (patch) of each cell, numbered as in Mesh::cell_groups
        s.push_str("<DataArray type=\"Int32\" Name=\"patch\" format=\"ascii\">\n");
        s.push_str(&super::par_text(cells, |s, c| {
            let _ = writeln!(s, "{}", g.cell_group[c]);
        }));
        s.push_str("</DataArray>\n");
    }
    s.push_str("</CellData>\n<PointData>\n<DataArray type=\"Float64\" Name=\"parameter\" NumberOfComponents=\"2\" format=\"ascii\">\n");
    s.push_str(&super::par_text(n, |s, i| {
        let p = mesh.params[i];
        let _ = writeln!(s, "{} {}", p.x, p.y);
    }));
    s.push_str("</DataArray>\n</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    Ok(s)
}
