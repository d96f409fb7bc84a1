//! Mesh files: each writer refuses a mesh that breaks a rule of its format
//! ([`crate::validate::validate`]: positive volumes, one orientation, no duplicate nodes,
//! and for OpenFOAM non-orthogonality below 90°) and a mesh its format cannot hold.
//!
//! | format | module | holds |
//! |---|---|---|
//! | Gmsh MSH 4.1 ASCII | [`gmsh`] | triangles and quadrilaterals of order 1-3, physical groups per side |
//! | VTK XML unstructured grid `.vtu` | [`vtu`] | order 1-3 (types 5, 9, 22, 28, 69, 70), quality fields |
//! | SU2 native `.su2` | [`su2`] | linear cells, one marker per side |
//! | PLOT3D 2D `.xyz` | [`plot3d`] | linear structured meshes |
//! | OpenFOAM `polyMesh` | [`openfoam`] | linear cells extruded one cell thick |

pub mod gmsh;
pub mod openfoam;
pub mod plot3d;
pub mod su2;
pub mod vtu;

use std::path::{Path, PathBuf};

use crate::error::{MeshError, Result};
use crate::Mesh;

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Gmsh MSH 4.1 ASCII (`.msh`).
    Gmsh,
    /// VTK XML unstructured grid (`.vtu`).
    Vtu,
    /// SU2 native (`.su2`).
    Su2,
    /// PLOT3D 2D whole grid (`.xyz`).
    Plot3d,
    /// OpenFOAM `constant/polyMesh` in a case directory.
    OpenFoam,
}

impl Format {
    /// The format a path asks for: by extension, or OpenFOAM for a path ending in `/`
    /// or an existing directory or a path without extension.
    pub fn from_path(path: &Path) -> Result<Format> {
        let s = path.to_string_lossy();
        if s.ends_with('/') || path.is_dir() {
            return Ok(Format::OpenFoam);
        }
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("msh") => Ok(Format::Gmsh),
            Some("vtu") => Ok(Format::Vtu),
            Some("su2") => Ok(Format::Su2),
            Some("xyz") | Some("x") => Ok(Format::Plot3d),
            None => Ok(Format::OpenFoam),
            Some(e) => Err(MeshError::param(
                "output",
                format!(
                    "unknown mesh format .{e} of {}: use .msh, .vtu, .su2, .xyz or a directory (OpenFOAM)",
                    path.display()
                ),
            )),
        }
    }

    /// Name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::Gmsh => "Gmsh MSH 4.1",
            Format::Vtu => "VTK unstructured grid",
            Format::Su2 => "SU2",
            Format::Plot3d => "PLOT3D",
            Format::OpenFoam => "OpenFOAM polyMesh",
        }
    }
}

/// Write `mesh` to `path` in `format`; returns the files written. The mesh is validated
/// first against the format's rules ([`crate::validate::validate`]): a mesh that breaks
/// one is an error naming the rule and the place, and nothing is written.
pub fn write(mesh: &Mesh, path: &Path, format: Format) -> Result<Vec<PathBuf>> {
    crate::validate::validate(mesh, format)?;
    // every file through the atomic writer: never a half-written mesh under its name
    let file = |p: &Path, text: String| winslow::io::write_bytes(p, text.as_bytes()).map_err(MeshError::File);
    let single = |text: String| -> Result<Vec<PathBuf>> {
        file(path, text)?;
        Ok(vec![path.to_path_buf()])
    };
    match format {
        Format::Gmsh => single(gmsh::to_string(mesh)?),
        Format::Vtu => single(vtu::to_string(mesh)?),
        Format::Su2 => single(su2::to_string(mesh)?),
        Format::Plot3d => single(plot3d::to_string(mesh)?),
        Format::OpenFoam => {
            let dir = path.join("constant").join("polyMesh");
            let mut out = Vec::new();
            for (name, text) in openfoam::files(mesh, &openfoam::OpenFoamOptions::default())? {
                let p = dir.join(name);
                file(&p, text)?;
                out.push(p);
            }
            Ok(out)
        }
    }
}

/// The text of items `0..n`, each written by `item` (which appends to the string),
/// formatted in parallel chunks and concatenated in order: float formatting dominates
/// writing a large mesh.
pub(crate) fn par_text(n: usize, item: impl Fn(&mut String, usize) + Sync) -> String {
    use rayon::prelude::*;
    const CHUNK: usize = 1 << 14;
    let parts: Vec<String> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut s = String::with_capacity(48 * CHUNK);
            for i in c * CHUNK..((c + 1) * CHUNK).min(n) {
                item(&mut s, i);
            }
            s
        })
        .collect();
    parts.concat()
}

/// Refuse curved elements in a format that holds only linear ones.
pub(crate) fn linear_only(mesh: &Mesh, format: &'static str) -> Result<()> {
    if mesh.order != 1 {
        return Err(MeshError::Unsupported {
            format,
            why: format!("order {} elements; write .msh or .vtu for curved elements", mesh.order),
        });
    }
    Ok(())
}
