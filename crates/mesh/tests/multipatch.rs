//! One conforming mesh of a multipatch layout: nodes merged through the interfaces,
//! every interior edge in two cells, the boundary exactly the outer sides, the area the
//! sum of the patch areas (to O(h^2), checked by its convergence), groups per patch,
//! and every writer's file read back.

use std::collections::HashMap;
use std::path::PathBuf;

use winslow::io::Document;
use winslow::multipatch::Layout;
use winslow_mesh::formats::{write, Format};
use winslow_mesh::topology::faces;
use winslow_mesh::validate::{area_centroid, duplicate_nodes, validate};
use winslow_mesh::{multipatch, DVec2, Mesh, MeshError};

fn layout(name: &str) -> Layout {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/gismo/xml/multipatch").join(name);
    match winslow::io::read(&path).unwrap() {
        Document::Layout(l) | Document::Multipatch(l) => l,
        d => panic!("{name}: a {} document", d.kind()),
    }
}

fn cell_area(mesh: &Mesh, c: usize) -> f64 {
    let p: Vec<DVec2> = mesh.corners(c).iter().map(|&n| mesh.points[n]).collect();
    area_centroid(&p).0
}

const CASES: [&str; 3] = ["plateWithHoleMP.xml", "circleMP.xml", "TUDflame.xml"];

#[test]
fn the_cases_have_interfaces_that_run_against_each_other() {
    // a reversed interface paired start to start would fold or leave duplicate nodes
    let reversed: usize = CASES.iter().map(|c| layout(c).interfaces.iter().filter(|i| i.reversed).count()).sum();
    assert!(reversed > 0);
}

#[test]
fn conforming_with_the_outer_sides_as_boundary() {
    for name in CASES {
        let l = layout(name);
        let mp = multipatch(&l, [9, 7]).unwrap();
        let m = &mp.mesh;
        validate(m, Format::Gmsh).unwrap();
        assert!(duplicate_nodes(m).is_empty(), "{name}");
        // every interface has as many points on both sides
        for itf in &l.interfaces {
            let len = |ps: winslow::multipatch::PatchSide| mp.patch_points[ps.patch][ps.side as usize % 2];
            assert_eq!(len(itf.first), len(itf.second), "{name}: {itf:?}");
        }
        // cells and nodes: each patch's grid, the interface nodes counted once
        let cells: usize = mp.patch_points.iter().map(|n| (n[0] - 1) * (n[1] - 1)).sum();
        assert_eq!(m.num_cells(), cells, "{name}");
        let local: usize = mp.patch_points.iter().map(|n| n[0] * n[1]).sum();
        assert!(m.points.len() < local, "{name}: interfaces merged");
        // every edge of a cell is either interior (two cells, opposite directions) or on
        // a labelled outer side: `faces` refuses anything else
        let f = faces(m).unwrap();
        assert_eq!(4 * cells, 2 * f.internal.len() + f.boundary.len(), "{name}");
        let outer = l.outer_sides();
        let expect: usize = outer.iter().map(|ps| mp.patch_points[ps.patch][ps.side as usize % 2] - 1).sum();
        assert_eq!(m.boundary.len(), expect, "{name}");
        // the boundary groups are the outer sides, named PATCH.SIDE
        let groups: Vec<String> = m.boundary_groups().iter().map(|g| g.0.to_string()).collect();
        let names: Vec<String> =
            outer.iter().map(|ps| format!("{}.{}", l.patches[ps.patch].name, ps.side.name())).collect();
        assert_eq!(groups, names, "{name}");
        // a closed boundary: every boundary node starts one boundary edge and ends one
        let mut starts: Vec<usize> = m.boundary.iter().map(|e| e.nodes[0]).collect();
        let mut ends: Vec<usize> = m.boundary.iter().map(|e| e.nodes[1]).collect();
        starts.sort_unstable();
        ends.sort_unstable();
        assert_eq!(starts, ends, "{name}");
        // a cell group per patch with its grid's cells
        let cg = m.cell_groups();
        assert_eq!(cg.len(), l.patches.len());
        for (p, (g, c)) in cg.iter().enumerate() {
            assert_eq!(*g, l.patches[p].name);
            assert_eq!(c.len(), (mp.patch_points[p][0] - 1) * (mp.patch_points[p][1] - 1));
        }
    }
}

/// The mesh's area converges to the sum of the patch areas at second order (bilinear
/// cells under a smooth map), patch by patch.
#[test]
fn area_is_the_sum_of_the_patch_areas() {
    for name in CASES {
        let l = layout(name);
        let areas = winslow::multipatch::validate_layout(&l).unwrap().areas;
        let err = |n: usize| -> Vec<f64> {
            let m = multipatch(&l, [n, n]).unwrap().mesh;
            m.cell_groups()
                .iter()
                .enumerate()
                .map(|(p, (_, cells))| {
                    let a: f64 = cells.iter().map(|&c| cell_area(&m, c)).sum();
                    (a - areas[p]).abs() / areas[p]
                })
                .collect()
        };
        let (coarse, fine) = (err(9), err(17));
        for p in 0..areas.len() {
            assert!(fine[p] < 1e-2, "{name} patch {p}: relative area error {}", fine[p]);
            if coarse[p] > 1e-12 {
                let rate = (coarse[p] / fine[p]).log2();
                assert!(rate > 1.8, "{name} patch {p}: area errors {} -> {}, rate {rate}", coarse[p], fine[p]);
            }
        }
        let total: f64 = areas.iter().sum();
        let m = multipatch(&l, [33, 33]).unwrap().mesh;
        let a: f64 = (0..m.num_cells()).map(|c| cell_area(&m, c)).sum();
        assert!((a - total).abs() < 1e-3 * total, "{name}: {a} vs {total}");
    }
}

#[test]
fn a_gap_at_an_interface_and_a_patch_without_map_are_refused() {
    let mut l = layout("plateWithHoleMP.xml");
    let itf = l.interfaces[0];
    let map = l.patches[itf.first.patch].map.as_mut().unwrap();
    // move every control point of the patch: its interface side leaves the neighbour's
    for q in &mut map.control_points {
        q[0] += 1e-3;
    }
    let e = multipatch(&l, [5, 5]).unwrap_err();
    assert!(matches!(&e, MeshError::Parameter { what, .. } if what.starts_with("interface")), "{e}");
    let mut l = layout("plateWithHoleMP.xml");
    l.patches[1].map = None;
    let e = multipatch(&l, [5, 5]).unwrap_err();
    assert!(matches!(&e, MeshError::Parameter { what, .. } if what.starts_with("patch 1")), "{e}");
    assert!(multipatch(&layout("circleMP.xml"), [1, 5]).is_err());
    // curved cells need one map per patch: refused
    let l = layout("circleMP.xml");
    let m = multipatch(&l, [5, 5]).unwrap().mesh;
    let map = l.patches[0].map.as_ref().unwrap();
    assert!(winslow_mesh::high_order::elevate(&m, map, 2).is_err());
    assert_eq!(winslow_mesh::high_order::elevate(&m, map, 1).unwrap(), m);
}

/// The Gmsh physical groups: name -> (dimension, tag).
fn msh_groups(text: &str) -> HashMap<String, (usize, usize)> {
    let body = text.split("$PhysicalNames\n").nth(1).unwrap().split("$EndPhysicalNames").next().unwrap();
    body.lines()
        .skip(1)
        .map(|l| {
            let t: Vec<&str> = l.splitn(3, ' ').collect();
            (t[2].trim_matches('"').to_string(), (t[0].parse().unwrap(), t[1].parse().unwrap()))
        })
        .collect()
}

#[test]
fn every_writer_round_trips_the_groups() {
    let l = layout("plateWithHoleMP.xml");
    let mp = multipatch(&l, [7, 5]).unwrap();
    let m = &mp.mesh;
    let dir = tempfile::tempdir().unwrap();
    let bgroups = m.boundary_groups();
    let cgroups = m.cell_groups();

    // Gmsh: physical groups per boundary group and per patch; nodes and elements back
    let p = dir.path().join("m.msh");
    write(m, &p, Format::Gmsh).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    let phys = msh_groups(&text);
    assert_eq!(phys.len(), bgroups.len() + cgroups.len());
    for (k, (g, _)) in bgroups.iter().enumerate() {
        assert_eq!(phys[*g], (1, k + 1));
    }
    for (k, (g, _)) in cgroups.iter().enumerate() {
        assert_eq!(phys[*g], (2, bgroups.len() + k + 1));
    }
    let section = |name: &str| -> Vec<Vec<f64>> {
        let body = text.split(&format!("${name}\n")).nth(1).unwrap().split(&format!("$End{name}")).next().unwrap();
        body.lines().map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect()).collect()
    };
    let nodes = section("Nodes");
    let mut xy: HashMap<usize, DVec2> = HashMap::new();
    let mut k = 1;
    while k < nodes.len() {
        let n = nodes[k][3] as usize;
        for i in 0..n {
            xy.insert(nodes[k + 1 + i][0] as usize, DVec2::new(nodes[k + 1 + n + i][0], nodes[k + 1 + n + i][1]));
        }
        k += 1 + 2 * n;
    }
    assert_eq!(xy.len(), m.points.len());
    for (i, p) in m.points.iter().enumerate() {
        assert_eq!(xy[&(i + 1)], *p);
    }
    let elements = section("Elements");
    let (mut k, mut per_entity) = (1, HashMap::new());
    while k < elements.len() {
        let h = &elements[k];
        let n = h[3] as usize;
        let cells: Vec<Vec<usize>> =
            elements[k + 1..k + 1 + n].iter().map(|l| l[1..].iter().map(|&t| t as usize - 1).collect()).collect();
        per_entity.insert((h[0] as usize, h[1] as usize), cells);
        k += 1 + n;
    }
    for (k, (_, edges)) in bgroups.iter().enumerate() {
        let back = &per_entity[&(1, k + 1)];
        let want: Vec<Vec<usize>> = edges.iter().map(|&e| m.boundary[e].nodes.clone()).collect();
        assert_eq!(*back, want);
    }
    for (k, (_, cells)) in cgroups.iter().enumerate() {
        let back = &per_entity[&(2, k + 1)];
        let want: Vec<Vec<usize>> = cells.iter().map(|&c| m.cell(c).to_vec()).collect();
        assert_eq!(*back, want);
    }

    // SU2: one marker per boundary group with its edges
    let p = dir.path().join("m.su2");
    write(m, &p, Format::Su2).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    let markers: Vec<(String, usize)> = text
        .lines()
        .zip(text.lines().skip(1))
        .filter_map(|(a, b)| {
            let tag = a.strip_prefix("MARKER_TAG= ")?;
            Some((tag.to_string(), b.strip_prefix("MARKER_ELEMS= ")?.parse().unwrap()))
        })
        .collect();
    let want: Vec<(String, usize)> = bgroups.iter().map(|(g, e)| (g.to_string(), e.len())).collect();
    assert_eq!(markers, want);
    assert!(text.contains(&format!("NPOIN= {}\n", m.points.len())));

    // VTU: the patch of each cell
    let p = dir.path().join("m.vtu");
    write(m, &p, Format::Vtu).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    let body = text.split("Name=\"patch\" format=\"ascii\">\n").nth(1).unwrap().split("</DataArray>").next().unwrap();
    let patch: Vec<usize> = body.lines().map(|l| l.parse().unwrap()).collect();
    assert_eq!(patch, m.groups.as_ref().unwrap().cell_group);

    // OpenFOAM: a patch per boundary group, a cellZone per patch
    let case = dir.path().join("case");
    let files = write(m, &case, Format::OpenFoam).unwrap();
    assert!(files.iter().any(|f| f.ends_with("cellZones")));
    let poly = case.join("constant/polyMesh");
    let boundary = std::fs::read_to_string(poly.join("boundary")).unwrap();
    for (g, e) in &bgroups {
        let at = boundary.find(&format!("    {g}\n")).unwrap_or_else(|| panic!("{g} in boundary"));
        assert!(boundary[at..].contains(&format!("nFaces          {};", e.len())));
    }
    let zones = std::fs::read_to_string(poly.join("cellZones")).unwrap();
    for (g, cells) in &cgroups {
        let at = zones.find(&format!("{g}\n{{")).unwrap_or_else(|| panic!("{g} in cellZones"));
        let rest = &zones[at..];
        let n: usize = rest.lines().nth(4).unwrap().parse().unwrap();
        assert_eq!(n, cells.len());
        let labels: Vec<usize> = rest.lines().skip(6).take(n).map(|l| l.parse().unwrap()).collect();
        assert_eq!(labels, *cells);
    }

    // PLOT3D holds one block: refused, nothing written
    let p = dir.path().join("m.xyz");
    let e = write(m, &p, Format::Plot3d).unwrap_err();
    assert!(matches!(e, MeshError::Unsupported { format: "PLOT3D", .. }), "{e}");
    assert!(!p.exists());
}
