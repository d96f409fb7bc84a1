//! OpenFOAM `constant/polyMesh` for a 2D case: the mesh extruded one cell thick in `z`
//! (`0` to the thickness), the sides as `patch`es named by [`crate::Mesh::names`]
//! (`south`, `east`, `north`, `west`; `inner` and `outer` on a ring; the boundary groups
//! `PATCH.SIDE` of a multipatch mesh, whose patches are also the `cellZones`), and the
//! front and back faces as the `empty` patch `frontAndBack`.
//!
//! What OpenFOAM requires and this writer does: internal faces first, in upper-triangular
//! order (sorted by owner, then neighbour, with owner < neighbour), each face's normal
//! (right-hand rule on its node order) pointing out of its owner; then the boundary
//! faces grouped by patch in the order of the `boundary` file, `startFace` contiguous.
//! Linear cells only (quads become hexahedra, triangles prisms).

use std::fmt::Write;

use crate::error::Result;
use crate::topology::faces;
use crate::Mesh;

/// Options of the OpenFOAM writer.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OpenFoamOptions {
    /// Thickness in `z`; `None`: the square root of the mean cell area.
    pub thickness: Option<f64>,
}

fn header(class: &str, object: &str, note: &str) -> String {
    format!(
        "FoamFile\n{{\n    version     2.0;\n    format      ascii;\n    class       {class};\n    note        \"{note}\";\n    location    \"constant/polyMesh\";\n    object      {object};\n}}\n\n"
    )
}

/// The files `points`, `faces`, `owner`, `neighbour`, `boundary` (name, text).
pub fn files(mesh: &Mesh, opts: &OpenFoamOptions) -> Result<Vec<(&'static str, String)>> {
    super::linear_only(mesh, "OpenFOAM")?;
    let f = faces(mesh)?;
    let n = mesh.points.len();
    let cells = mesh.num_cells();
    let area: f64 = (0..cells)
        .map(|c| {
            let v = mesh.corners(c);
            let k = v.len();
            (0..k).map(|i| mesh.points[v[i]].perp_dot(mesh.points[v[(i + 1) % k]])).sum::<f64>() * 0.5
        })
        .sum();
    let dz = opts.thickness.unwrap_or((area / cells.max(1) as f64).sqrt());
    let n_int = f.internal.len();
    let n_faces = n_int + f.boundary.len() + 2 * cells;
    let note = format!("nPoints:{} nCells:{cells} nFaces:{n_faces} nInternalFaces:{n_int}", 2 * n);

    let mut points = header("vectorField", "points", "");
    let _ = writeln!(points, "{}\n(", 2 * n);
    for z in [0.0, dz] {
        for p in &mesh.points {
            let _ = writeln!(points, "({} {} {z})", p.x, p.y);
        }
    }
    points.push_str(")\n");

    let mut face_text = String::with_capacity(24 * n_faces);
    let mut owner_text = String::with_capacity(8 * n_faces);
    let mut neighbour_text = String::with_capacity(8 * n_int);
    let quad = |s: &mut String, [a, b]: [usize; 2]| {
        let _ = writeln!(s, "4({a} {b} {} {})", b + n, a + n);
    };
    for face in &f.internal {
        quad(&mut face_text, face.nodes);
        let _ = writeln!(owner_text, "{}", face.owner);
        let _ = writeln!(neighbour_text, "{}", face.neighbour);
    }
    let mut patches = Vec::new();
    let mut start = n_int;
    // topology::faces keeps the boundary faces in the order of mesh.boundary
    for (name, edges) in mesh.boundary_groups() {
        for &e in &edges {
            let face = f.boundary[e];
            quad(&mut face_text, face.nodes);
            let _ = writeln!(owner_text, "{}", face.owner);
        }
        patches.push((name, "patch", edges.len(), start));
        start += edges.len();
    }
    for c in 0..cells {
        let v = mesh.corners(c);
        // back (z = 0): clockwise seen from +z, normal -z; front: counter-clockwise
        let _ = write!(face_text, "{}(", v.len());
        for (i, x) in v.iter().rev().enumerate() {
            let _ = write!(face_text, "{}{x}", if i > 0 { " " } else { "" });
        }
        let _ = write!(face_text, ")\n{}(", v.len());
        for (i, x) in v.iter().enumerate() {
            let _ = write!(face_text, "{}{}", if i > 0 { " " } else { "" }, x + n);
        }
        face_text.push_str(")\n");
        let _ = writeln!(owner_text, "{c}\n{c}");
    }
    patches.push(("frontAndBack", "empty", 2 * cells, start));

    let wrap = |class: &str, object: &str, count: usize, body: String| {
        let mut s = header(class, object, &note);
        let _ = write!(s, "{count}\n(\n{body})\n");
        s
    };
    let mut boundary = header("polyBoundaryMesh", "boundary", "");
    let _ = writeln!(boundary, "{}\n(", patches.len());
    for (name, kind, count, start) in &patches {
        let group = if *kind == "empty" { "\n        inGroups        List<word> 1(empty);" } else { "" };
        let _ = writeln!(
            boundary,
            "    {name}\n    {{\n        type            {kind};{group}\n        nFaces          {count};\n        startFace       {start};\n    }}"
        );
    }
    boundary.push_str(")\n");
    let mut out = vec![
        ("points", points),
        ("faces", wrap("faceList", "faces", n_faces, face_text)),
        ("owner", wrap("labelList", "owner", n_faces, owner_text)),
        ("neighbour", wrap("labelList", "neighbour", n_int, neighbour_text)),
        ("boundary", boundary),
    ];
    if mesh.groups.is_some() {
        out.push(("cellZones", cell_zones(mesh)));
    }
    Ok(out)
}

/// The `cellZones` file: one zone per cell group of a multipatch mesh (its patch).
pub fn cell_zones(mesh: &Mesh) -> String {
    let mut s = header("regIOobject", "cellZones", "");
    let groups = mesh.cell_groups();
    let _ = writeln!(s, "{}\n(", groups.len());
    for (name, cells) in groups {
        let _ = writeln!(s, "{name}\n{{\n    type cellZone;\ncellLabels      List<label>\n{}\n(", cells.len());
        for c in cells {
            let _ = writeln!(s, "{c}");
        }
        s.push_str(")\n;\n}\n");
    }
    s.push_str(")\n");
    s
}
