//! PLOT3D 2D whole grid (`.xyz`, ASCII, multi-block form with one block): the block
//! count, `IMAX JMAX`, then all `x` and all `y` with `i` fastest. Linear structured
//! meshes only. A periodic direction (a ring's `eta`) is written as an O-grid closed
//! the way PLOT3D readers expect: its first line repeated as the last (`JMAX = ny + 1`),
//! the only format here in which a seam node appears twice.

use std::fmt::Write;

use crate::error::{MeshError, Result};
use crate::Mesh;

/// The file's text.
pub fn to_string(mesh: &Mesh) -> Result<String> {
    super::linear_only(mesh, "PLOT3D")?;
    if mesh.groups.is_some() {
        return Err(MeshError::Unsupported {
            format: "PLOT3D",
            why: "a mesh of several patches joined at their interfaces; this writer holds one structured block (use .msh, .vtu, .su2 or an OpenFOAM directory)".into(),
        });
    }
    let Some([nx, ny]) = mesh.structured else {
        return Err(MeshError::Unsupported {
            format: "PLOT3D",
            why: "an unstructured mesh; PLOT3D holds structured grids (use --structured)".into(),
        });
    };
    let [mx, my] = [nx + usize::from(mesh.periodic[0]), ny + usize::from(mesh.periodic[1])];
    let mut s = String::with_capacity(50 * mx * my);
    let _ = writeln!(s, "1\n{mx} {my}");
    for c in 0..2 {
        let mut k = 0;
        for j in 0..my {
            for i in 0..mx {
                let p = mesh.points[(j % ny) * nx + i % nx];
                k += 1;
                let _ = write!(s, "{}{}", p[c], if k % 4 == 0 { '\n' } else { ' ' });
            }
        }
        s.push('\n');
    }
    Ok(s)
}
