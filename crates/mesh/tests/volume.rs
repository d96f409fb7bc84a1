//! Hexahedral meshes of trivariate maps: exact volumes of an affine map, second-order
//! convergence on a curved one, outward boundary faces (the divergence theorem), the
//! six sides, inverted maps refused, the files read back.

use winslow::spline::volume::Volume;
use winslow::KnotVector;
use winslow_mesh::formats::Format;
use winslow_mesh::volume::{hex_volume, hexahedra, write_hex, SIDES};
use winslow_mesh::MeshError;

use glam::DVec3;

/// `x = b + A u` on one trilinear element.
fn affine(a: [[f64; 3]; 3]) -> (Volume, f64) {
    let b = DVec3::new(1.0, -2.0, 0.5);
    let col = |k: usize| DVec3::new(a[0][k], a[1][k], a[2][k]);
    let kv = KnotVector::open_uniform(1, 1);
    let mut cps = Vec::new();
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..2 {
                let p = b + col(0) * i as f64 + col(1) * j as f64 + col(2) * k as f64;
                cps.push(p.to_array());
            }
        }
    }
    let det = col(0).dot(col(1).cross(col(2)));
    (Volume::new([kv.clone(), kv.clone(), kv], cps, None).unwrap(), det)
}

/// The quarter annulus `1 <= r <= 2` (exact NURBS circles in `eta`) extruded to
/// `0 <= z <= 1`: volume `3 pi / 4`.
fn annulus_slab() -> Volume {
    let ku = KnotVector::open_uniform(1, 1);
    let kv = KnotVector::open_uniform(2, 1);
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let (mut cps, mut ws) = (Vec::new(), Vec::new());
    for z in [0.0, 1.0] {
        for (c, wj) in [([1.0, 0.0], 1.0), ([1.0, 1.0], w), ([0.0, 1.0], 1.0)] {
            for r in [1.0, 2.0] {
                cps.push([r * c[0], r * c[1], z]);
                ws.push(wj);
            }
        }
    }
    Volume::new([ku.clone(), kv, ku], cps, Some(ws)).unwrap()
}

fn total(m: &winslow_mesh::volume::HexMesh) -> f64 {
    (0..m.cells.len()).map(|c| hex_volume(&m.corners(c))).sum()
}

/// `1/3 sum x . n dA` over the boundary quads (two triangles each): the enclosed volume
/// when the faces point outward.
fn flux(m: &winslow_mesh::volume::HexMesh) -> f64 {
    let tri = |a: DVec3, b: DVec3, c: DVec3| a.dot(b.cross(c)) / 6.0;
    m.faces
        .iter()
        .map(|(_, q)| {
            let p = q.map(|n| m.points[n]);
            tri(p[0], p[1], p[2]) + tri(p[0], p[2], p[3])
        })
        .sum()
}

#[test]
fn affine_volumes_are_exact_and_faces_point_out() {
    let (v, det) = affine([[2.0, 0.3, 0.1], [0.2, 1.5, -0.4], [0.0, 0.25, 0.8]]);
    let m = hexahedra(&v, [4, 3, 5]).unwrap();
    m.check().unwrap();
    assert_eq!((m.points.len(), m.cells.len()), (60, 3 * 2 * 4));
    assert!((total(&m) - det).abs() < 1e-12 * det, "{} vs {det}", total(&m));
    assert!((flux(&m) - det).abs() < 1e-12 * det, "{} vs {det}", flux(&m));
    // faces per side: the cells on that side
    let count = |s: usize| m.faces.iter().filter(|f| f.0 == s).count();
    assert_eq!([0, 1, 2, 3, 4, 5].map(count), [8, 8, 12, 12, 6, 6]);
    // a left-handed map is refused
    let (v, _) = affine([[-2.0, 0.3, 0.1], [0.2, 1.5, -0.4], [0.0, 0.25, 0.8]]);
    let e = hexahedra(&v, [3, 3, 3]).unwrap().check().unwrap_err();
    assert!(matches!(e, MeshError::Inverted { count: 8, .. }), "{e}");
    assert!(hexahedra(&v, [1, 3, 3]).is_err());
}

#[test]
fn curved_volume_converges_at_second_order() {
    let exact = 0.75 * std::f64::consts::PI;
    let err = |n: usize| {
        let m = hexahedra(&annulus_slab(), [3, n, 2]).unwrap();
        m.check().unwrap();
        assert!((flux(&m) - total(&m)).abs() < 1e-12, "closed, outward boundary");
        (total(&m) - exact).abs() / exact
    };
    let (e1, e2) = (err(9), err(17));
    let rate = (e1 / e2).log2();
    assert!(e2 < 5e-3 && rate > 1.9, "{e1} -> {e2}, rate {rate}");
}

#[test]
fn files_read_back() {
    let m = hexahedra(&annulus_slab(), [3, 5, 2]).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("v.msh");
    write_hex(&m, &p, Format::Gmsh).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    for (k, s) in SIDES.iter().enumerate() {
        assert!(text.contains(&format!("2 {} \"{s}\"\n", k + 1)), "{s}");
    }
    let body = text.split("$Elements\n").nth(1).unwrap();
    let hexes: Vec<Vec<usize>> = body
        .split("\n3 1 5 ")
        .nth(1)
        .unwrap()
        .lines()
        .skip(1)
        .take_while(|l| !l.starts_with('$'))
        .map(|l| l.split_whitespace().skip(1).map(|t| t.parse::<usize>().unwrap() - 1).collect())
        .collect();
    assert_eq!(hexes, m.cells.iter().map(|c| c.to_vec()).collect::<Vec<_>>());
    let p = dir.path().join("v.vtu");
    write_hex(&m, &p, Format::Vtu).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    let body = text.split("Name=\"volume\" format=\"ascii\">\n").nth(1).unwrap().split("</DataArray>").next().unwrap();
    let vols: Vec<f64> = body.lines().map(|l| l.parse().unwrap()).collect();
    assert_eq!(vols.len(), m.cells.len());
    assert!((vols.iter().sum::<f64>() - total(&m)).abs() < 1e-12);
    let p = dir.path().join("v.su2");
    assert!(matches!(write_hex(&m, &p, Format::Su2), Err(MeshError::Unsupported { .. })));
    assert!(!p.exists());
}
