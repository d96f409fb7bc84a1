//! Structured hexahedral meshes of a trivariate map `x(xi, eta, zeta)` (a loft, paper
//! §11.1): nodes at uniform `xi_i x eta_j x zeta_k`, stored `xi` fastest, then `eta`;
//! cells `(i, j, k) .. (i+1, j+1, k+1)` in VTK's and Gmsh's hexahedron order (the
//! bottom quad `zeta_k` counter-clockwise in `(xi, eta)`, then the top). A periodic
//! direction has as many points as cells and wraps (no boundary on its seam).
//!
//! Boundary faces are named by the six sides in G+Smo's convention: `west` (`xi = 0`),
//! `east` (`xi = 1`), `south` (`eta = 0`), `north` (`eta = 1`), `front` (`zeta = 0`),
//! `back` (`zeta = 1`); each boundary quad is ordered so its right-hand normal points
//! out of the volume.
//!
//! Before writing, every hexahedron is checked for a positive volume the way solvers'
//! readers do: the triple product of the three edges leaving each of its eight corners
//! (the corner Jacobian of the trilinear cell) must be positive ([`HexMesh::check`]).

use std::fmt::Write;
use std::path::{Path, PathBuf};

use glam::DVec3;
use rayon::prelude::*;
use winslow::spline::volume::Volume;

use crate::error::{MeshError, Result};
use crate::formats::Format;

/// The six sides of a volume, in the order west, east, south, north, front, back.
pub const SIDES: [&str; 6] = ["west", "east", "south", "north", "front", "back"];

/// A structured hexahedral mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct HexMesh {
    /// Node positions, `xi` fastest, then `eta`.
    pub points: Vec<DVec3>,
    /// Points per direction (a periodic direction: as many as cells).
    pub n: [usize; 3],
    /// Periodic directions.
    pub periodic: [bool; 3],
    /// Hexahedra, 8 nodes each (VTK / Gmsh order).
    pub cells: Vec<[usize; 8]>,
    /// Boundary quads: the side (index into [`SIDES`]) and the nodes, outward normal.
    pub faces: Vec<(usize, [usize; 4])>,
}

/// The structured mesh of `volume` with `points` `[nx, ny, nz]` (at least 2 per
/// direction, 3 in a periodic one).
pub fn hexahedra(volume: &Volume, points: [usize; 3]) -> Result<HexMesh> {
    let periodic = [0, 1, 2].map(|d| volume.knots[d].is_periodic());
    for d in 0..3 {
        let least = if periodic[d] { 3 } else { 2 };
        if points[d] < least {
            return Err(MeshError::param(
                format!("{} points", ["xi", "eta", "zeta"][d]),
                format!("need at least {least}, got {}", points[d]),
            ));
        }
    }
    let n = points;
    let t = |d: usize, i: usize| if periodic[d] { i as f64 / n[d] as f64 } else { i as f64 / (n[d] - 1) as f64 };
    let total = n[0] * n[1] * n[2];
    let pts: Vec<DVec3> = (0..total)
        .into_par_iter()
        .map(|m| {
            let (i, j, k) = (m % n[0], (m / n[0]) % n[1], m / (n[0] * n[1]));
            DVec3::from(volume.eval([t(0, i), t(1, j), t(2, k)]))
        })
        .collect();
    let id = |i: usize, j: usize, k: usize| ((k % n[2]) * n[1] + (j % n[1])) * n[0] + (i % n[0]);
    let c = [0, 1, 2].map(|d| if periodic[d] { n[d] } else { n[d] - 1 });
    let mut cells = Vec::with_capacity(c[0] * c[1] * c[2]);
    for k in 0..c[2] {
        for j in 0..c[1] {
            for i in 0..c[0] {
                cells.push([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
            }
        }
    }
    // boundary quads, outward: a face at the start of direction d runs against the
    // positive orientation of the two other directions, at the end with it
    let mut faces = Vec::new();
    for d in 0..3 {
        if periodic[d] {
            continue;
        }
        let (a, b) = ((d + 1) % 3, (d + 2) % 3);
        for end in [0, 1] {
            let at = if end == 0 { 0 } else { n[d] - 1 };
            for q in 0..c[b] {
                for p in 0..c[a] {
                    let node = |pa: usize, pb: usize| {
                        let mut ijk = [0; 3];
                        ijk[d] = at;
                        ijk[a] = pa;
                        ijk[b] = pb;
                        id(ijk[0], ijk[1], ijk[2])
                    };
                    // (a, b, d) is a cyclic, right-handed order: (a, b) counter-clockwise
                    // has normal +d
                    let ccw = [node(p, q), node(p + 1, q), node(p + 1, q + 1), node(p, q + 1)];
                    let quad = if end == 1 { ccw } else { [ccw[0], ccw[3], ccw[2], ccw[1]] };
                    faces.push((2 * d + end, quad));
                }
            }
        }
    }
    Ok(HexMesh { points: pts, n, periodic, cells, faces })
}

/// The corner Jacobians of a hexahedron: at each corner, the triple product of its
/// three edges in the order `xi`, `eta`, `zeta`.
pub fn corner_jacobians(p: &[DVec3; 8]) -> [f64; 8] {
    // the neighbours along xi, eta, zeta of each corner (VTK order) and the sign of
    // the direction from that corner
    const NB: [[usize; 3]; 8] =
        [[1, 3, 4], [0, 2, 5], [3, 1, 6], [2, 0, 7], [5, 7, 0], [4, 6, 1], [7, 5, 2], [6, 4, 3]];
    let mut out = [0.0; 8];
    for (c, nb) in NB.iter().enumerate() {
        let e = nb.map(|m| p[m] - p[c]);
        // an edge from a corner at the upper end of its direction runs against it
        let s = [[true, false, false, true][c % 4], c % 4 < 2, c < 4];
        let e = [0, 1, 2].map(|k| if s[k] { e[k] } else { -e[k] });
        out[c] = e[0].dot(e[1].cross(e[2]));
    }
    out
}

/// Volume of a hexahedron: six tetrahedra about the diagonal `0 - 6` (exact for a
/// parallelepiped).
pub fn hex_volume(p: &[DVec3; 8]) -> f64 {
    const TETS: [[usize; 4]; 6] = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]];
    TETS.iter().map(|t| (p[t[1]] - p[t[0]]).dot((p[t[2]] - p[t[0]]).cross(p[t[3]] - p[t[0]])) / 6.0).sum()
}

impl HexMesh {
    /// The corner positions of cell `c`.
    pub fn corners(&self, c: usize) -> [DVec3; 8] {
        self.cells[c].map(|n| self.points[n])
    }

    /// Refuse a hexahedron with a corner Jacobian that is not positive (inverted or
    /// degenerate), naming the first and the count.
    pub fn check(&self) -> Result<()> {
        let bad: Vec<(usize, f64)> = (0..self.cells.len())
            .into_par_iter()
            .filter_map(|c| {
                let j = corner_jacobians(&self.corners(c));
                let least = j.iter().copied().fold(f64::INFINITY, f64::min);
                (least.is_nan() || least <= 0.0).then_some((c, least))
            })
            .collect();
        if let Some(&(cell, least)) = bad.first() {
            let [nx, ny, _] = self.n;
            let cx = if self.periodic[0] { nx } else { nx - 1 };
            let cy = if self.periodic[1] { ny } else { ny - 1 };
            let (i, j, k) = (cell % cx, (cell / cx) % cy, cell / (cx * cy));
            return Err(MeshError::Inverted {
                cell,
                why: format!("hexahedron ({i}, {j}, {k}) has corner Jacobian {least:e}, not positive"),
                count: bad.len(),
            });
        }
        Ok(())
    }
}

/// VTK XML unstructured grid: hexahedra (type 12) with their volume as cell data.
pub fn vtu(mesh: &HexMesh) -> String {
    let (n, cells) = (mesh.points.len(), mesh.cells.len());
    let mut s = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{cells}\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n"
    );
    s.push_str(&crate::formats::par_text(n, |s, i| {
        let p = mesh.points[i];
        let _ = writeln!(s, "{} {} {}", p.x, p.y, p.z);
    }));
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    s.push_str(&crate::formats::par_text(cells, |s, c| {
        let v = mesh.cells[c];
        let _ = writeln!(s, "{} {} {} {} {} {} {} {}", v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]);
    }));
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for c in 1..=cells {
        let _ = writeln!(s, "{}", 8 * c);
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in 0..cells {
        s.push_str("12\n");
    }
    s.push_str("</DataArray>\n</Cells>\n<CellData Scalars=\"volume\">\n<DataArray type=\"Float64\" Name=\"volume\" format=\"ascii\">\n");
    s.push_str(&crate::formats::par_text(cells, |s, c| {
        let _ = writeln!(s, "{}", hex_volume(&mesh.corners(c)));
    }));
    s.push_str("</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// Gmsh MSH 4.1: a surface entity and physical group (dimension 2, tags 1-6) per side
/// that has faces, named by [`SIDES`]; one volume entity, physical group 7 `domain`;
/// every node on the volume entity; quads (type 3) on the sides, hexahedra (type 5).
pub fn gmsh(mesh: &HexMesh) -> String {
    let sides: Vec<usize> = (0..6).filter(|&s| mesh.faces.iter().any(|f| f.0 == s)).collect();
    let mut s = format!("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n{}\n", sides.len() + 1);
    for &k in &sides {
        let _ = writeln!(s, "2 {} \"{}\"", k + 1, SIDES[k]);
    }
    s.push_str("3 7 \"domain\"\n$EndPhysicalNames\n");
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in &mesh.points {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let bbox = format!("{} {} {} {} {} {}", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    let _ = writeln!(s, "$Entities\n0 0 {} 1", sides.len());
    for &k in &sides {
        let _ = writeln!(s, "{} {bbox} 1 {} 0", k + 1, k + 1);
    }
    let _ = write!(s, "1 {bbox} 1 7 {}", sides.len());
    for &k in &sides {
        let _ = write!(s, " {}", k + 1);
    }
    let n = mesh.points.len();
    let _ = write!(s, "\n$EndEntities\n$Nodes\n1 {n} 1 {n}\n3 1 0 {n}\n");
    s.push_str(&crate::formats::par_text(n, |s, i| {
        let _ = writeln!(s, "{}", i + 1);
    }));
    s.push_str(&crate::formats::par_text(n, |s, i| {
        let p = mesh.points[i];
        let _ = writeln!(s, "{} {} {}", p.x, p.y, p.z);
    }));
    let total = mesh.faces.len() + mesh.cells.len();
    let _ = write!(s, "$EndNodes\n$Elements\n{} {total} 1 {total}\n", sides.len() + 1);
    let mut tag = 0;
    for &k in &sides {
        let quads: Vec<&[usize; 4]> = mesh.faces.iter().filter(|f| f.0 == k).map(|f| &f.1).collect();
        let _ = writeln!(s, "2 {} 3 {}", k + 1, quads.len());
        for q in quads {
            tag += 1;
            let _ = writeln!(s, "{tag} {} {} {} {}", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
        }
    }
    let _ = writeln!(s, "3 1 5 {}", mesh.cells.len());
    s.push_str(&crate::formats::par_text(mesh.cells.len(), |s, c| {
        let v = mesh.cells[c];
        let _ = write!(s, "{}", tag + c + 1);
        for x in v {
            let _ = write!(s, " {}", x + 1);
        }
        s.push('\n');
    }));
    s.push_str("$EndElements\n");
    s
}

/// Check the mesh ([`HexMesh::check`]) and write it as `.vtu` or `.msh`; other formats
/// are refused (they hold planar meshes here). Returns the files written.
pub fn write_hex(mesh: &HexMesh, path: &Path, format: Format) -> Result<Vec<PathBuf>> {
    let text = match format {
        Format::Vtu => {
            mesh.check()?;
            vtu(mesh)
        }
        Format::Gmsh => {
            mesh.check()?;
            gmsh(mesh)
        }
        f => {
            return Err(MeshError::Unsupported {
                format: f.name(),
                why: "a hexahedral volume mesh; this writer holds planar meshes (write .vtu or .msh)".into(),
            })
        }
    };
    winslow::io::write_bytes(path, text.as_bytes()).map_err(MeshError::File)?;
    Ok(vec![path.to_path_buf()])
}
