//! The rules a solver's mesh reader enforces, checked before a mesh is written: a mesh
//! that breaks one is refused with the reason, where, and what to change
//! ([`MeshError::Invalid`]), never written as valid.
//!
//! | rule | formats | what is checked |
//! |---|---|---|
//! | positive volumes | all | every cell's signed area (shoelace about its first corner) is positive and every corner turns left ([`Mesh::check`]; curved cells: their Jacobian) |
//! | one orientation | all | the two cells on an edge traverse it in opposite directions (no overlap, no fold), no edge has more than two cells, each boundary edge runs as its cell does |
//! | no duplicate nodes | all | no two nodes closer than `1e-13` of the mesh's diameter (a seam left open, a crack) |
//! | non-orthogonality | OpenFOAM | the angle between each internal face's normal and the line joining the two cell centroids is below 90° (`checkMesh` fails at 90°) |
//!
//! Centroids and areas are computed about each cell's first corner, so a first cell of
//! `1e-8` on coordinates of `36` keeps its digits (the shoelace with absolute
//! coordinates loses them and reports folded faces that are not there).

use std::collections::HashMap;

use glam::DVec2;
use rayon::prelude::*;

use crate::error::{MeshError, Result};
use crate::formats::Format;
use crate::topology::{faces, Faces};
use crate::Mesh;

/// OpenFOAM's limit on non-orthogonality, degrees.
pub const OPENFOAM_NON_ORTHOGONALITY: f64 = 90.0;

/// Signed area and centroid of the polygon `p`, both about `p[0]` (the centroid is
/// returned in absolute coordinates).
pub fn area_centroid(p: &[DVec2]) -> (f64, DVec2) {
    let o = p[0];
    let (mut a, mut c) = (0.0, DVec2::ZERO);
    for k in 1..p.len().saturating_sub(1) {
        let (u, v) = (p[k] - o, p[k + 1] - o);
        let w = u.perp_dot(v);
        a += w;
        c += (u + v) * w;
    }
    if a == 0.0 {
        (0.0, p.iter().copied().sum::<DVec2>() / p.len() as f64)
    } else {
        (0.5 * a, o + c / (3.0 * a))
    }
}

/// The centroid of every cell (corners only).
pub fn centroids(mesh: &Mesh) -> Vec<DVec2> {
    (0..mesh.num_cells())
        .into_par_iter()
        .map(|c| {
            let p: Vec<DVec2> = mesh.corners(c).iter().map(|&n| mesh.points[n]).collect();
            area_centroid(&p).1
        })
        .collect()
}

/// Non-orthogonality of an internal face, degrees: the angle between its right normal
/// (pointing from `owner` to `neighbour`) and `c_neighbour - c_owner`.
pub fn face_non_orthogonality(a: DVec2, b: DVec2, c_owner: DVec2, c_neighbour: DVec2) -> f64 {
    let normal = DVec2::new((b - a).y, -(b - a).x);
    let d = c_neighbour - c_owner;
    let cos = normal.dot(d) / (normal.length() * d.length());
    if cos.is_nan() {
        90.0
    } else {
        cos.clamp(-1.0, 1.0).acos().to_degrees()
    }
}

fn invalid(format: Format, rule: &str, count: usize, first: String, hint: &str) -> MeshError {
    MeshError::Invalid { format: format.name(), rule: rule.into(), count, first, hint: hint.into() }
}

/// Pairs of nodes closer than `1e-13` of the mesh's diameter (plus the round-off of the
/// coordinates' size): `(a, b)` with `a < b`.
pub fn duplicate_nodes(mesh: &Mesh) -> Vec<(usize, usize)> {
    let pts = &mesh.points;
    if pts.is_empty() {
        return Vec::new();
    }
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let mut size = 0.0f64;
    for p in pts {
        lo = lo.min(*p);
        hi = hi.max(*p);
        size = size.max(p.abs().max_element());
    }
    let tol = (1e-13 * (hi - lo).length()).max(4.0 * f64::EPSILON * size).max(f64::MIN_POSITIVE);
    // buckets of side `tol` about the lower corner: a pair within `tol` is in
    // neighbouring buckets
    let key = |p: DVec2| {
        let q = (p - lo) / tol;
        (q.x.floor() as i64, q.y.floor() as i64)
    };
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::with_capacity(pts.len());
    for (n, p) in pts.iter().enumerate() {
        grid.entry(key(*p)).or_default().push(n);
    }
    let mut out = Vec::new();
    for (n, p) in pts.iter().enumerate() {
        let (x, y) = key(*p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for &m in grid.get(&(x + dx, y + dy)).map(Vec::as_slice).unwrap_or(&[]) {
                    if m > n && pts[m].distance(*p) <= tol {
                        out.push((n, m));
                    }
                }
            }
        }
    }
    out
}

/// Edges that break one orientation: `(a, b, c1, c2)` where cells `c1` and `c2` both
/// traverse `a -> b` (they overlap), or a boundary edge that runs against its cell
/// (`c1 == c2`).
pub fn orientation_defects(mesh: &Mesh) -> Vec<(usize, usize, usize, usize)> {
    let k = mesh.kind.corners();
    let mut directed: HashMap<(usize, usize), usize> = HashMap::with_capacity(k * mesh.num_cells());
    let mut out = Vec::new();
    for c in 0..mesh.num_cells() {
        let v = mesh.corners(c);
        for e in 0..k {
            let (a, b) = (v[e], v[(e + 1) % k]);
            if let Some(&other) = directed.get(&(a, b)) {
                out.push((a, b, other, c));
            } else {
                directed.insert((a, b), c);
            }
        }
    }
    for e in &mesh.boundary {
        let (a, b) = (e.nodes[0], e.nodes[1]);
        if let (None, Some(&c)) = (directed.get(&(a, b)), directed.get(&(b, a))) {
            out.push((a, b, c, c));
        }
    }
    out
}

/// Internal faces whose non-orthogonality is `limit` degrees or more: `(face index in
/// faces.internal, angle)`.
pub fn non_orthogonal_faces(mesh: &Mesh, faces: &Faces, limit: f64) -> Vec<(usize, f64)> {
    let cen = centroids(mesh);
    faces
        .internal
        .par_iter()
        .enumerate()
        .filter_map(|(k, f)| {
            let (a, b) = (mesh.points[f.nodes[0]], mesh.points[f.nodes[1]]);
            let ang = face_non_orthogonality(a, b, cen[f.owner], cen[f.neighbour]);
            (ang >= limit || ang.is_nan()).then_some((k, ang))
        })
        .collect()
}

/// Check `mesh` against the rules of `format` (see the module table); the first rule
/// broken is the error.
pub fn validate(mesh: &Mesh, format: Format) -> Result<()> {
    mesh.check()?;
    let f = faces(mesh)?;
    let bad = orientation_defects(mesh);
    if let Some(&(a, b, c1, c2)) = bad.first() {
        let first = if c1 == c2 {
            format!("boundary edge {a}-{b} runs against its cell {c1}")
        } else {
            format!("cells {c1} and {c2} both traverse edge {a}-{b} (they overlap)")
        };
        return Err(invalid(
            format,
            "one orientation",
            bad.len(),
            first,
            "the mesh folds over itself: certify the map (`winslow check`) and mesh a bijective one",
        ));
    }
    let dup = duplicate_nodes(mesh);
    if let Some(&(a, b)) = dup.first() {
        let p = mesh.points[a];
        return Err(invalid(
            format,
            "no duplicate nodes",
            dup.len(),
            format!("nodes {a} and {b} coincide at ({}, {})", p.x, p.y),
            "a seam left open: two sides of the map meet but do not coincide within 1e-6 of the diameter, so they are not merged as a cut ring's seam (crates/mesh/src/seam.rs); solve the ring as a ring document, whose periodic seam is merged",
        ));
    }
    if format == Format::OpenFoam {
        let no = non_orthogonal_faces(mesh, &f, OPENFOAM_NON_ORTHOGONALITY);
        if let Some(&(k, ang)) = no.iter().max_by(|x, y| x.1.total_cmp(&y.1)) {
            let face = f.internal[k];
            let p = mesh.points[face.nodes[0]];
            return Err(invalid(
                format,
                "non-orthogonality below 90°",
                no.len(),
                format!(
                    "the face between cells {} and {} at ({}, {}) is at {ang:.2}°",
                    face.owner, face.neighbour, p.x, p.y
                ),
                "use more points along the walls or a smaller growth ratio, or a distribution without such thin cells",
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{side_names, BoundaryEdge, ElementKind, Side};

    /// A mesh of quads from corner lists; boundary edges are the edges used once, on
    /// side south.
    fn quads(points: &[[f64; 2]], cells: &[[usize; 4]]) -> Mesh {
        let mut count: HashMap<(usize, usize), usize> = HashMap::new();
        for c in cells {
            for e in 0..4 {
                let (a, b) = (c[e], c[(e + 1) % 4]);
                *count.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let mut boundary = Vec::new();
        for c in cells {
            for e in 0..4 {
                let (a, b) = (c[e], c[(e + 1) % 4]);
                if count[&(a.min(b), a.max(b))] == 1 {
                    boundary.push(BoundaryEdge { side: Side::South, nodes: vec![a, b] });
                }
            }
        }
        Mesh {
            points: points.iter().map(|&p| DVec2::from(p)).collect(),
            params: points.iter().map(|_| DVec2::splat(0.5)).collect(),
            kind: ElementKind::Quad,
            order: 1,
            cells: cells.iter().flatten().copied().collect(),
            boundary,
            structured: None,
            periodic: [false, false],
            names: side_names(),
            groups: None,
        }
    }

    fn rule(e: MeshError) -> String {
        match e {
            MeshError::Invalid { rule, .. } => rule,
            e => format!("{e}"),
        }
    }

    const ALL: [Format; 5] = [Format::Gmsh, Format::Vtu, Format::Su2, Format::Plot3d, Format::OpenFoam];

    #[test]
    fn two_squares_pass_every_format() {
        let m = quads(&[[0., 0.], [1., 0.], [2., 0.], [0., 1.], [1., 1.], [2., 1.]], &[[0, 1, 4, 3], [1, 2, 5, 4]]);
        for f in ALL {
            validate(&m, f).unwrap();
        }
        assert!(duplicate_nodes(&m).is_empty() && orientation_defects(&m).is_empty());
    }

    #[test]
    fn a_clockwise_cell_has_no_positive_volume() {
        let m = quads(&[[0., 0.], [1., 0.], [1., 1.], [0., 1.]], &[[0, 3, 2, 1]]);
        for f in ALL {
            assert!(matches!(validate(&m, f), Err(MeshError::Inverted { .. })));
        }
        let (a, _) = area_centroid(&[0, 3, 2, 1].map(|k| m.points[k]));
        assert_eq!(a, -1.0);
    }

    #[test]
    fn overlapping_cells_break_the_orientation() {
        // the second square lies on the first, shifted up by a half: both traverse 1 -> 4
        let m = quads(
            &[[0., 0.], [1., 0.], [1., 1.], [0., 1.], [1., 0.5], [1., 1.5], [0., 1.5], [0., 0.5]],
            &[[0, 1, 2, 3], [7, 4, 5, 6]],
        );
        assert!(orientation_defects(&m).is_empty(), "no shared edge yet");
        let m = quads(&[[0., 0.], [1., 0.], [1., 1.], [0., 1.], [0.5, 2.]], &[[0, 1, 2, 3], [0, 1, 2, 4]]);
        assert_eq!(orientation_defects(&m)[0], (0, 1, 0, 1));
        for f in ALL {
            assert_eq!(rule(validate(&m, f).unwrap_err()), "one orientation");
        }
        // a boundary edge listed against its cell
        let mut m = quads(&[[0., 0.], [1., 0.], [1., 1.], [0., 1.]], &[[0, 1, 2, 3]]);
        m.boundary[0].nodes.reverse();
        assert_eq!(rule(validate(&m, Format::Su2).unwrap_err()), "one orientation");
    }

    #[test]
    fn an_open_seam_has_duplicate_nodes() {
        // two squares whose shared side is two coinciding node pairs (a crack)
        let pts = [[0., 0.], [1., 0.], [1., 1.], [0., 1.], [1., 0.], [2., 0.], [2., 1.], [1., 1.]];
        let m = quads(&pts, &[[0, 1, 2, 3], [4, 5, 6, 7]]);
        assert_eq!(duplicate_nodes(&m), vec![(1, 4), (2, 7)]);
        for f in ALL {
            assert_eq!(rule(validate(&m, f).unwrap_err()), "no duplicate nodes");
        }
        // 1e-9 apart on a mesh of size 2 is not a duplicate (a thin cell may be that thin)
        let mut pts = pts;
        pts[4][0] += 1e-9;
        pts[7][0] += 1e-9;
        assert!(duplicate_nodes(&quads(&pts, &[[0, 1, 2, 3], [4, 5, 6, 7]])).is_empty());
    }

    #[test]
    fn non_orthogonality_is_measured_and_openfoam_refuses_90_degrees() {
        // parallelograms sheared by s: the face x = 1 + s y between the two cells has
        // non-orthogonality atan(s) exactly
        let s: f64 = 3.0;
        let m =
            quads(&[[0., 0.], [1., 0.], [2., 0.], [s, 1.], [1. + s, 1.], [2. + s, 1.]], &[[0, 1, 4, 3], [1, 2, 5, 4]]);
        let f = faces(&m).unwrap();
        let cen = centroids(&m);
        let ang = face_non_orthogonality(m.points[1], m.points[4], cen[0], cen[1]);
        assert!((ang - s.atan().to_degrees()).abs() < 1e-12, "{ang}");
        assert_eq!(non_orthogonal_faces(&m, &f, 70.0).len(), 1);
        assert!(non_orthogonal_faces(&m, &f, 72.0).is_empty());
        validate(&m, Format::OpenFoam).unwrap();
        // two convex cells have their centroids on either side of the face, so 90° is
        // reached only where round-off moves a centroid: see the next test
    }

    #[test]
    fn centroids_keep_their_digits_far_from_the_origin() {
        // a cell 1e-8 thick at x = 36: the centroid is exact to round-off of 36
        let (h, x) = (1e-8, 36.0);
        let p = [DVec2::new(x, 0.0), DVec2::new(x + h, 0.0), DVec2::new(x + h, 0.5), DVec2::new(x, 0.5)];
        let w = p[1].x - p[0].x; // the width as stored (exact by Sterbenz)
        let (a, c) = area_centroid(&p);
        assert!((a - 0.5 * w).abs() < 1e-12 * 0.5 * w, "{a}");
        assert!((c.x - (x + 0.5 * w)).abs() < 1e-14, "{}", c.x - x);
        // the shoelace about the origin loses the area to cancellation
        let origin: f64 = (0..4).map(|k| p[k].perp_dot(p[(k + 1) % 4])).sum::<f64>() * 0.5;
        assert!((origin - 0.5 * w).abs() > 1e-14 * w || origin == 0.5 * w);
    }
}
