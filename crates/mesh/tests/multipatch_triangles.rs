//! One conforming triangulation of a multipatch layout: every interface's points shared
//! by its two patches (every interior edge in two triangles, nothing but the outer sides
//! on the boundary), the groups of the structured mesh, the area converging to the sum of
//! the patch areas, and the Gmsh file read back.

use std::path::PathBuf;

use winslow::io::Document;
use winslow::multipatch::Layout;
use winslow_mesh::formats::{write, Format};
use winslow_mesh::topology::faces;
use winslow_mesh::validate::{area_centroid, duplicate_nodes, validate};
use winslow_mesh::{multipatch_unstructured, DVec2, MeshError, UnstructuredOptions};

fn layout(name: &str) -> Layout {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/gismo/xml/multipatch").join(name);
    match winslow::io::read(&path).unwrap() {
        Document::Layout(l) | Document::Multipatch(l) => l,
        d => panic!("{name}: a {} document", d.kind()),
    }
}

fn opts(size: f64) -> UnstructuredOptions {
    UnstructuredOptions { size, ..Default::default() }
}

/// Layouts whose patches are certified maps (G+Smo's TUDflame as given has a folded patch,
/// `p0`: see `a_folded_patch_gives_inverted_triangles`).
const CASES: [&str; 2] = ["plateWithHoleMP.xml", "circleMP.xml"];

#[test]
fn conforming_triangles_with_the_outer_sides_as_boundary() {
    for name in CASES {
        let l = layout(name);
        let size = l.diameter() / 12.0;
        let mt = multipatch_unstructured(&l, &opts(size)).unwrap();
        let m = &mt.mesh;
        validate(m, Format::Gmsh).unwrap();
        m.check().unwrap();
        assert!(duplicate_nodes(m).is_empty(), "{name}");
        assert_eq!(mt.patch_cells.iter().sum::<usize>(), m.num_cells(), "{name}");
        assert!(mt.interface_gap <= 1e-9 * l.diameter(), "{name}: gap {}", mt.interface_gap);
        // every edge of a triangle is interior (two triangles, opposite directions) or on a
        // labelled outer side: `faces` refuses anything else, e.g. an interface whose two
        // sides kept different points
        let f = faces(m).unwrap();
        assert_eq!(3 * m.num_cells(), 2 * f.internal.len() + f.boundary.len(), "{name}");
        assert_eq!(f.boundary.len(), m.boundary.len(), "{name}");
        // a closed boundary: every boundary node starts one boundary edge and ends one
        let mut starts: Vec<usize> = m.boundary.iter().map(|e| e.nodes[0]).collect();
        let mut ends: Vec<usize> = m.boundary.iter().map(|e| e.nodes[1]).collect();
        starts.sort_unstable();
        ends.sort_unstable();
        assert_eq!(starts, ends, "{name}");
        // the boundary groups are the outer sides, named PATCH.SIDE; a cell group per patch
        let groups: Vec<String> = m.boundary_groups().iter().map(|g| g.0.to_string()).collect();
        let names: Vec<String> =
            l.outer_sides().iter().map(|ps| format!("{}.{}", l.patches[ps.patch].name, ps.side.name())).collect();
        assert_eq!(groups, names, "{name}");
        let cg = m.cell_groups();
        assert_eq!(cg.len(), l.patches.len(), "{name}");
        for (p, (g, c)) in cg.iter().enumerate() {
            assert_eq!(*g, l.patches[p].name);
            assert_eq!(c.len(), mt.patch_cells[p], "{name}");
        }
        // the edges are about the size asked for (the size criterion splits longer ones)
        let longest =
            f.internal.iter().map(|e| m.points[e.nodes[0]].distance(m.points[e.nodes[1]])).fold(0.0f64, f64::max);
        assert!(longest <= size * (1.0 + 1e-9), "{name}: edge {longest} against size {size}");
    }
}

/// The triangles' area converges to the sum of the patch areas at second order in the
/// size (straight chords of curved sides, deviating by `kappa h^2 / 8`).
#[test]
fn area_converges_to_the_sum_of_the_patch_areas() {
    for name in CASES {
        let l = layout(name);
        let total: f64 = winslow::multipatch::validate_layout(&l).unwrap().areas.iter().sum();
        let err = |size: f64| {
            let m = multipatch_unstructured(&l, &opts(size)).unwrap().mesh;
            let a: f64 = (0..m.num_cells())
                .map(|c| area_centroid(&m.corners(c).iter().map(|&n| m.points[n]).collect::<Vec<DVec2>>()).0)
                .sum();
            (a - total).abs() / total
        };
        let d = l.diameter();
        let (coarse, fine) = (err(d / 8.0), err(d / 32.0));
        assert!(fine < 1e-3, "{name}: relative area error {fine}");
        assert!(fine < coarse / 4.0, "{name}: area errors {coarse} -> {fine} (size / 4)");
    }
}

#[test]
fn bad_requests_are_typed_errors() {
    let l = layout("circleMP.xml");
    assert!(matches!(multipatch_unstructured(&l, &opts(0.0)), Err(MeshError::Parameter { .. })));
    let curved = UnstructuredOptions { order: 2, ..opts(0.1) };
    assert!(matches!(multipatch_unstructured(&l, &curved), Err(MeshError::Parameter { .. })));
    let mut unsolved = l.clone();
    unsolved.patches[1].map = None;
    let e = multipatch_unstructured(&unsolved, &opts(0.1)).unwrap_err();
    assert!(matches!(&e, MeshError::Parameter { what, .. } if what.starts_with("patch 1")), "{e}");
    // a gap at an interface: its nodes are evaluated on both patches
    let mut gap = l.clone();
    let itf = gap.interfaces[0];
    for q in &mut gap.patches[itf.first.patch].map.as_mut().unwrap().control_points {
        q[0] += 1e-3;
    }
    let e = multipatch_unstructured(&gap, &opts(l.diameter() / 8.0)).unwrap_err();
    assert!(matches!(&e, MeshError::Parameter { what, .. } if what.starts_with("interface")), "{e}");
}

#[test]
fn the_gmsh_file_has_the_groups_and_every_triangle() {
    let l = layout("plateWithHoleMP.xml");
    let m = multipatch_unstructured(&l, &opts(l.diameter() / 10.0)).unwrap().mesh;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("m.msh");
    write(&m, &p, Format::Gmsh).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    for (g, _) in m.boundary_groups().iter().chain(m.cell_groups().iter()) {
        assert!(text.contains(&format!("\"{g}\"")), "{g}");
    }
    // element blocks: dimension, entity, type, count; the triangles (type 2) all there
    let body = text.split("$Elements\n").nth(1).unwrap().split("$EndElements").next().unwrap();
    let lines: Vec<Vec<usize>> =
        body.lines().map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect()).collect();
    let (mut k, mut triangles) = (1, 0);
    while k < lines.len() {
        let n = lines[k][3];
        if lines[k][2] == 2 {
            triangles += n;
        }
        k += 1 + n;
    }
    assert_eq!(triangles, m.num_cells());
}

/// G+Smo's TUDflame as given: patch `p0` folds (`winslow check`: det J < 0 on 6 elements).
/// Its triangles there are inverted, and the check every writer runs refuses the mesh.
#[test]
fn a_folded_patch_gives_inverted_triangles() {
    let l = layout("TUDflame.xml");
    let m = multipatch_unstructured(&l, &opts(1.0)).unwrap().mesh;
    let e = m.check().unwrap_err();
    assert!(matches!(e, MeshError::Inverted { .. }), "{e}");
    let dir = tempfile::tempdir().unwrap();
    assert!(write(&m, &dir.path().join("m.msh"), Format::Gmsh).is_err());
    assert!(!dir.path().join("m.msh").exists());
}
