//! Mesh quality, measured on the straight-sided cells through the corner nodes.
//!
//! Per cell: signed area (shoelace), interior angles, aspect ratio (longest over
//! shortest edge), equiangular skewness `max((t_max - t_e) / (180 - t_e), (t_e - t_min) / t_e)`
//! with `t_e` = 90° (quads) or 60° (triangles), growth (largest area ratio to an edge
//! neighbour, >= 1) and non-orthogonality (largest angle between an edge's normal and
//! the line joining the centroids of the cells on either side, OpenFOAM's measure).

use glam::DVec2;
use rayon::prelude::*;

use crate::error::Result;
use crate::topology::Faces;
use crate::Mesh;

/// Quality of one cell.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CellQuality {
    /// Signed area (positive for counter-clockwise cells).
    pub area: f64,
    /// Smallest interior angle, degrees.
    pub min_angle: f64,
    /// Largest interior angle, degrees.
    pub max_angle: f64,
    /// Longest over shortest edge.
    pub aspect: f64,
    /// Equiangular skewness in `[0, 1]`.
    pub skewness: f64,
    /// Largest area ratio to an edge neighbour (>= 1).
    pub growth: f64,
    /// Largest non-orthogonality of the cell's internal edges, degrees.
    pub non_orthogonality: f64,
}

/// The mesh's quality table.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Quality {
    /// Number of nodes.
    pub nodes: usize,
    /// Number of cells.
    pub cells: usize,
    /// Smallest and largest cell area.
    pub area: [f64; 2],
    /// Smallest and largest interior angle, degrees.
    pub angle: [f64; 2],
    /// Largest aspect ratio.
    pub max_aspect: f64,
    /// Largest skewness.
    pub max_skewness: f64,
    /// Largest growth ratio between neighbours.
    pub max_growth: f64,
    /// Largest and mean non-orthogonality over internal edges, degrees.
    pub non_orthogonality: [f64; 2],
    /// Internal faces at 90° or more (OpenFOAM refuses them; see [`crate::validate`]).
    pub faces_over_90: usize,
    /// Smallest and largest first-cell height at each wall of a structured mesh, by
    /// boundary group name ([`crate::structured::first_heights`]).
    pub first_heights: Vec<(String, [f64; 2])>,
    /// Cells that are inverted or degenerate (see [`Mesh::check`]).
    pub inverted: usize,
    /// Smallest ratio `min det J / max det J` of a curved element's own Jacobian over
    /// its nodes and quadrature points (order > 1 only).
    pub min_jacobian_ratio: Option<f64>,
    /// Per-cell values.
    pub per_cell: Vec<CellQuality>,
}

fn cross(a: DVec2, b: DVec2) -> f64 {
    a.perp_dot(b)
}

/// Signed area and centroid of a polygon, about its first corner
/// ([`crate::validate::area_centroid`]).
fn area_centroid(p: &[DVec2]) -> (f64, DVec2) {
    crate::validate::area_centroid(p)
}

/// Why cell `c` is inverted or degenerate, if it is: a corner that does not turn left.
pub fn corner_defect(mesh: &Mesh, c: usize) -> Option<String> {
    let v = mesh.corners(c);
    let k = v.len();
    for i in 0..k {
        let (a, b, d) = (mesh.points[v[(i + k - 1) % k]], mesh.points[v[i]], mesh.points[v[(i + 1) % k]]);
        let t = cross(b - a, d - b);
        if t.is_nan() || t <= 0.0 {
            return Some(format!("corner {i} (node {}) at ({}, {}) has turn {t:.3e}", v[i], b.x, b.y));
        }
    }
    None
}

/// Quality of every cell and the table (the faces of `faces` give growth and
/// non-orthogonality).
pub fn quality_with(mesh: &Mesh, faces: &Faces) -> Quality {
    let n = mesh.num_cells();
    let k = mesh.kind.corners();
    let ideal = if k == 3 { 60.0 } else { 90.0 };
    // per cell, in parallel: its quality, centroid and whether it is inverted
    let cells: Vec<(CellQuality, DVec2, bool)> = (0..n)
        .into_par_iter()
        .map(|c| {
            let mut pts = [DVec2::ZERO; 4];
            let v = mesh.corners(c);
            for i in 0..k {
                pts[i] = mesh.points[v[i]];
            }
            let p = &pts[..k];
            let (area, cen) = area_centroid(p);
            let (mut amin, mut amax, mut emin, mut emax) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
            for i in 0..k {
                let (prev, cur, next) = (p[(i + k - 1) % k], p[i], p[(i + 1) % k]);
                let (e1, e0) = (next - cur, prev - cur);
                let mut ang = cross(e1, e0).atan2(e1.dot(e0)).to_degrees();
                if ang < 0.0 {
                    ang += 360.0;
                }
                amin = amin.min(ang);
                amax = amax.max(ang);
                let len = e1.length();
                emin = emin.min(len);
                emax = emax.max(len);
            }
            let skewness = ((amax - ideal) / (180.0 - ideal)).max((ideal - amin) / ideal).max(0.0);
            let q = CellQuality {
                area,
                min_angle: amin,
                max_angle: amax,
                aspect: emax / emin,
                skewness,
                growth: 1.0,
                non_orthogonality: 0.0,
            };
            (q, cen, corner_defect(mesh, c).is_some())
        })
        .collect();
    let inverted = cells.iter().filter(|c| c.2).count();
    let centroid: Vec<DVec2> = cells.iter().map(|c| c.1).collect();
    let mut per: Vec<CellQuality> = cells.into_iter().map(|c| c.0).collect();
    // per internal edge, in parallel: non-orthogonality and the area ratio; then each
    // cell takes the largest of its edges
    let edge: Vec<(f64, f64)> = faces
        .internal
        .par_iter()
        .map(|f| {
            let (o, nb) = (f.owner, f.neighbour);
            let (a, b) = (mesh.points[f.nodes[0]], mesh.points[f.nodes[1]]);
            let ang = crate::validate::face_non_orthogonality(a, b, centroid[o], centroid[nb]);
            let (ao, an) = (per[o].area.abs(), per[nb].area.abs());
            let g = ao.max(an) / ao.min(an);
            (ang, if g.is_nan() { f64::INFINITY } else { g })
        })
        .collect();
    let (mut no_max, mut no_sum, mut over) = (0.0f64, 0.0, 0);
    for (f, &(ang, g)) in faces.internal.iter().zip(&edge) {
        no_max = no_max.max(ang);
        over += usize::from(ang >= 90.0);
        no_sum += ang;
        for c in [f.owner, f.neighbour] {
            per[c].growth = per[c].growth.max(g);
            per[c].non_orthogonality = per[c].non_orthogonality.max(ang);
        }
    }
    let fold = |f: fn(&CellQuality) -> f64, init: f64, op: fn(f64, f64) -> f64| per.iter().map(f).fold(init, op);
    Quality {
        nodes: mesh.points.len(),
        cells: n,
        area: [fold(|q| q.area, f64::INFINITY, f64::min), fold(|q| q.area, f64::NEG_INFINITY, f64::max)],
        angle: [fold(|q| q.min_angle, f64::INFINITY, f64::min), fold(|q| q.max_angle, 0.0, f64::max)],
        max_aspect: fold(|q| q.aspect, 0.0, f64::max),
        max_skewness: fold(|q| q.skewness, 0.0, f64::max),
        max_growth: fold(|q| q.growth, 1.0, f64::max),
        non_orthogonality: [no_max, if faces.internal.is_empty() { 0.0 } else { no_sum / faces.internal.len() as f64 }],
        faces_over_90: over,
        first_heights: crate::structured::first_heights(mesh)
            .into_iter()
            .map(|(side, h)| (mesh.name(side).to_string(), h))
            .collect(),
        inverted,
        min_jacobian_ratio: None,
        per_cell: per,
    }
}

/// Quality of a mesh (faces built here; curved elements also get their Jacobian ratio).
pub fn quality(mesh: &Mesh) -> Result<Quality> {
    let faces = crate::topology::faces(mesh)?;
    let mut q = quality_with(mesh, &faces);
    if mesh.order > 1 {
        q.min_jacobian_ratio = Some(crate::high_order::min_jacobian_ratio(mesh));
    }
    Ok(q)
}

impl Quality {
    /// The quality table as `(name, value)` rows (the CLI prints them, the viewer shows
    /// them in a grid).
    pub fn rows(&self) -> Vec<(&'static str, String)> {
        let mut rows = vec![
            ("nodes / cells", format!("{} / {}", self.nodes, self.cells)),
            ("cell area min / max", format!("{:.4e} / {:.4e}", self.area[0], self.area[1])),
            ("angle min / max (deg)", format!("{:.2} / {:.2}", self.angle[0], self.angle[1])),
            ("max aspect ratio", format!("{:.3}", self.max_aspect)),
            ("max skewness", format!("{:.4}", self.max_skewness)),
            ("max growth ratio", format!("{:.4}", self.max_growth)),
            (
                "non-orthogonality max / mean",
                format!("{:.2} / {:.2} deg", self.non_orthogonality[0], self.non_orthogonality[1]),
            ),
        ];
        if self.faces_over_90 > 0 {
            rows.push(("faces at 90 deg or more", format!("{}", self.faces_over_90)));
        }
        if let Some(r) = self.min_jacobian_ratio {
            rows.push(("min det J ratio (curved)", format!("{r:.4}")));
        }
        rows.push(("inverted cells", format!("{}", self.inverted)));
        rows
    }

    /// The smallest and largest first cell of each wall, as rows `(name, value)`.
    pub fn first_height_rows(&self) -> Vec<(String, String)> {
        self.first_heights
            .iter()
            .map(|(name, [lo, hi])| (format!("first cell {name} min / max"), format!("{lo:.4e} / {hi:.4e}")))
            .collect()
    }

    /// The quality table as text, the first cells of the walls last.
    pub fn table(&self) -> String {
        let mut rows: Vec<(String, String)> = self.rows().into_iter().map(|(k, v)| (k.to_string(), v)).collect();
        rows.extend(self.first_height_rows());
        rows.iter().map(|(k, v)| format!("  {k:<28} {v}\n")).collect()
    }
}
