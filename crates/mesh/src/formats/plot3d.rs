//! PLOT3D 2D whole grid (`.xyz`, ASCII, multi-block form with one block): the block
//! count, `IMAX JMAX`, then all `x` and all `y` with `i` fastest. Linear structured
//! meshes only.

use std::fmt::Write;

use crate::error::{MeshError, Result};
use crate::Mesh;

/// The file's text.
pub fn to_string(mesh: &Mesh) -> Result<String> {
    super::linear_only(mesh, "PLOT3D")?;
    let Some([nx, ny]) = mesh.structured else {
        return Err(MeshError::Unsupported {
            format: "PLOT3D",
            why: "an unstructured mesh; PLOT3D holds structured grids (use --structured)".into(),
        });
    };
    let mut s = String::with_capacity(50 * nx * ny);
    let _ = writeln!(s, "1\n{nx} {ny}");
    for c in 0..2 {
        for (k, p) in mesh.points.iter().enumerate() {
            let _ = write!(s, "{}{}", p[c], if (k + 1) % 4 == 0 { '\n' } else { ' ' });
        }
        s.push('\n');
    }
    Ok(s)
}
