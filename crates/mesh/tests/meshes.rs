//! Structured, unstructured and curved meshes checked against closed forms.

mod common;

use common::{affine, annulus, folded, ring, signed_area};
use winslow_mesh::distribution::End;
use winslow_mesh::formats::Format;
use winslow_mesh::high_order::elevate;
use winslow_mesh::quality::quality;
use winslow_mesh::topology::faces;
use winslow_mesh::validate::validate;
use winslow_mesh::{
    structured, unstructured, DVec2, Distribution, MeshError, Side, StructuredOptions, UnstructuredOptions,
};

fn close(a: DVec2, b: DVec2, tol: f64) -> bool {
    a.distance(b) <= tol * (1.0 + b.length())
}

#[test]
fn affine_map_reproduces_the_affine_grid() {
    let (map, exact) = affine();
    for dist in [
        [Distribution::Uniform, Distribution::Arctan { strength: 6.0 }],
        [Distribution::TanhTwoSided { strength: 3.0 }, Distribution::TanhOneSided { strength: 2.0, at: End::Start }],
    ] {
        let opts = StructuredOptions { points: [17, 9], distribution: dist.clone() };
        let mesh = structured(&map, &opts).unwrap();
        let xi = dist[0].points(16).unwrap();
        let eta = dist[1].points(8).unwrap();
        assert_eq!(mesh.points.len(), 17 * 9);
        assert_eq!(mesh.num_cells(), 16 * 8);
        for j in 0..9 {
            for i in 0..17 {
                let p = mesh.points[j * 17 + i];
                assert!(close(p, exact(xi[i], eta[j]), 4e-16), "({i}, {j}): {p} vs {}", exact(xi[i], eta[j]));
            }
        }
        mesh.check().unwrap();
        // a parallelogram grid: every angle equals the angle between the two columns of A
        let q = quality(&mesh).unwrap();
        let a = (DVec2::new(3.0, 0.5).angle_to(DVec2::new(0.75, 2.0))).to_degrees();
        assert!((q.angle[0] - a).abs() < 1e-9 && (q.angle[1] - (180.0 - a)).abs() < 1e-9, "{:?}", q.angle);
        assert_eq!(q.inverted, 0);
        assert_eq!(mesh.boundary.len(), 2 * (16 + 8));
    }
}

#[test]
fn first_cell_height_and_growth_are_met_on_an_affine_map() {
    let (map, _) = affine();
    let (h, g) = (1e-3, 1.12);
    let opts = StructuredOptions {
        points: [41, 90],
        distribution: [
            Distribution::Layers { start: None, end: Some(2e-3), growth: 1.2 },
            Distribution::Layers { start: Some(h), end: Some(h), growth: g },
        ],
    };
    let mesh = structured(&map, &opts).unwrap();
    let [nx, ny] = mesh.structured.unwrap();
    let p = |i: usize, j: usize| mesh.points[j * nx + i];
    // lengths are of order 1 here: heights to 1e-12 absolute, ratios to 1e-12 relative
    for i in 0..nx {
        // south and north: the first edge off the wall is H
        assert!((p(i, 1).distance(p(i, 0)) - h).abs() < 1e-12);
        assert!((p(i, ny - 1).distance(p(i, ny - 2)) - h).abs() < 1e-12);
        let e: Vec<f64> = (0..ny - 1).map(|j| p(i, j + 1).distance(p(i, j))).collect();
        assert!((e[1] / e[0] - g).abs() < 1e-12 * g, "{}", e[1] / e[0]);
        for w in e.windows(2) {
            assert!((w[1] / w[0]).max(w[0] / w[1]) <= g * (1.0 + 1e-12));
        }
    }
    for j in 0..ny {
        let e = p(nx - 1, j).distance(p(nx - 2, j));
        assert!((e - 2e-3).abs() < 1e-12, "{e}");
    }
    mesh.check().unwrap();
    let q = quality(&mesh).unwrap();
    assert!(q.max_growth <= 1.2 * (1.0 + 1e-9), "{}", q.max_growth);
}

#[test]
fn first_cell_height_on_a_curved_map() {
    let map = annulus();
    let h = 2e-3;
    let layers = |start| Distribution::Layers { start: Some(start), end: None, growth: 1.3 };
    // layers in eta only: the chord of the first eta step is h on every radius 1 + u
    let mesh =
        structured(&map, &StructuredOptions { points: [31, 25], distribution: [Distribution::Uniform, layers(h)] })
            .unwrap();
    let [nx, ny] = mesh.structured.unwrap();
    let p = |i: usize, j: usize| mesh.points[j * nx + i];
    for i in 0..nx {
        let e = p(i, 1).distance(p(i, 0));
        assert!(e <= h * (1.0 + 1e-14) && e >= h * (1.0 - 1e-12), "line {i}: {e}");
    }
    // layers in both directions: a tensor grid, h the largest first chord (the outer
    // radius 2 against the inner 1: the smallest is h / 2); xi-lines are radial and the
    // xi height is the radius step on all of them
    let mesh =
        structured(&map, &StructuredOptions { points: [31, 25], distribution: [layers(5e-3), layers(h)] }).unwrap();
    let p = |i: usize, j: usize| mesh.points[j * nx + i];
    let first: Vec<f64> = (0..nx).map(|i| p(i, 1).distance(p(i, 0))).collect();
    let hi = first.iter().copied().fold(0.0, f64::max);
    assert!((hi - h).abs() < 1e-12 * h, "{hi}");
    assert!((first[0] - h / 2.0).abs() < 1e-9 * h, "{}", first[0]);
    for j in 0..ny {
        let e = p(1, j).distance(p(0, j));
        assert!((e - 5e-3).abs() < 1e-12 * 5e-3, "line {j}: {e}");
    }
    let q = quality(&mesh).unwrap();
    let south = q.first_heights.iter().find(|(n, _)| n == "south").unwrap().1;
    assert!((south[0] - first[0]).abs() < 1e-15 && south[1] == hi, "{south:?}");
    assert_eq!(q.first_heights.len(), 4);
}

#[test]
fn a_ring_has_one_node_per_seam_point_and_walls_named_inner_and_outer() {
    let map = ring();
    let mesh = structured(&map, &StructuredOptions::uniform(9, 40)).unwrap();
    assert_eq!(mesh.points.len(), 9 * 40);
    assert_eq!(mesh.num_cells(), 8 * 40);
    assert!(winslow_mesh::validate::duplicate_nodes(&mesh).is_empty());
    assert_eq!(mesh.boundary_sides(), [Side::East, Side::West]);
    assert_eq!((mesh.name(Side::West), mesh.name(Side::East)), ("inner", "outer"));
    // the seam is interior: 8 x 40 radial edges and 9 x 40 ring edges, 2 x 40 on walls
    let f = faces(&mesh).unwrap();
    assert_eq!((f.internal.len(), f.boundary.len()), (8 * 40 + 9 * 40 - 80, 80));
    // the seam nodes are those of eta = 0; the cells of the last row use them
    assert!(mesh.params.iter().all(|q| (0.0..1.0).contains(&q.y)));
    let last = mesh.cell(mesh.num_cells() - 1);
    assert_eq!((last[2], last[3]), (8, 7));
    for format in [Format::Gmsh, Format::Su2, Format::OpenFoam, Format::Vtu, Format::Plot3d] {
        validate(&mesh, format).unwrap();
    }
    // the walls are closed curves: every wall node on one wall edge start and one end
    for side in [Side::East, Side::West] {
        let mut starts: Vec<usize> = mesh.boundary.iter().filter(|e| e.side == side).map(|e| e.nodes[0]).collect();
        let mut ends: Vec<usize> = mesh.boundary.iter().filter(|e| e.side == side).map(|e| e.nodes[1]).collect();
        starts.sort_unstable();
        ends.sort_unstable();
        assert_eq!(starts, ends);
        assert_eq!(starts.len(), 40);
    }
}

#[test]
fn first_cell_heights_on_a_ring_lie_within_h_over_g_and_h() {
    // the gap between the walls varies from 1.2 to 1.8: one spacing for all lines
    // would leave some first cells below h / 1.2
    let map = ring();
    let (h, g) = (1e-3, 1.2);
    let opts = StructuredOptions {
        points: [60, 64],
        distribution: [Distribution::Layers { start: Some(h), end: Some(h), growth: g }, Distribution::Uniform],
    };
    let mesh = structured(&map, &opts).unwrap();
    let heights = winslow_mesh::structured::first_heights(&mesh);
    assert_eq!(heights.len(), 2);
    for (side, [lo, hi]) in heights {
        assert!(lo >= h / g && hi <= h * (1.0 + 1e-14), "{side}: {lo} {hi}");
        assert!(lo >= h * (1.0 - 1e-12), "{side}: {lo}");
    }
    // the radial lines are straight and evenly parametrized: the growth is exact
    let [nx, ny] = mesh.structured.unwrap();
    for j in 0..ny {
        let e: Vec<f64> = (0..nx - 1).map(|i| mesh.points[j * nx + i + 1].distance(mesh.points[j * nx + i])).collect();
        for w in e.windows(2) {
            assert!((w[1] / w[0]).max(w[0] / w[1]) <= g * (1.0 + 1e-9), "line {j}");
        }
    }
    for format in [Format::Gmsh, Format::Su2, Format::OpenFoam] {
        validate(&mesh, format).unwrap();
    }
    // layers on the seam are refused, naming the walls
    let seam = StructuredOptions {
        points: [60, 64],
        distribution: [Distribution::Uniform, Distribution::Layers { start: Some(h), end: None, growth: g }],
    };
    match structured(&map, &seam) {
        Err(MeshError::Layer { side, why, .. }) => assert!(side == "south" && why.contains("seam"), "{why}"),
        other => panic!("{other:?}"),
    }
    // an unstructured mesh shares the seam (tests/seams.rs): no boundary on it
    let tri = unstructured(&map, &UnstructuredOptions { size: 0.3, ..Default::default() }).unwrap();
    assert_eq!(tri.boundary_sides(), [Side::East, Side::West]);
}

#[test]
fn impossible_layers_are_refused() {
    let (map, _) = affine();
    let opts = StructuredOptions {
        points: [5, 6],
        distribution: [Distribution::Uniform, Distribution::Layers { start: Some(1e-5), end: None, growth: 1.1 }],
    };
    assert!(matches!(structured(&map, &opts), Err(MeshError::Layer { .. })));
    let opts = StructuredOptions {
        points: [5, 6],
        distribution: [Distribution::Uniform, Distribution::Layers { start: Some(50.0), end: None, growth: 1.1 }],
    };
    assert!(matches!(structured(&map, &opts), Err(MeshError::Layer { .. })));
}

#[test]
fn a_folded_map_gives_a_mesh_that_is_refused() {
    let mesh = structured(&folded(), &StructuredOptions::uniform(41, 41)).unwrap();
    let err = mesh.check().unwrap_err();
    assert!(matches!(err, MeshError::Inverted { count, .. } if count > 0), "{err}");
    assert!(quality(&mesh).unwrap().inverted > 0);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("folded.msh");
    let r = winslow_mesh::formats::write(&mesh, &path, winslow_mesh::formats::Format::Gmsh);
    assert!(matches!(r, Err(MeshError::Inverted { .. })));
    assert!(!path.exists());
}

/// Interior angle at each corner of a triangle.
fn angles(p: [DVec2; 3]) -> [f64; 3] {
    let ang = |a: DVec2, b: DVec2, c: DVec2| (b - a).angle_to(c - a).abs().to_degrees();
    [ang(p[0], p[1], p[2]), ang(p[1], p[2], p[0]), ang(p[2], p[0], p[1])]
}

#[test]
fn triangulation_meets_the_angle_in_parameter_space_and_the_size_in_physical_space() {
    let map = annulus();
    let opts = UnstructuredOptions { size: 0.08, min_angle: 28.0, ..Default::default() };
    let mesh = unstructured(&map, &opts).unwrap();
    mesh.check().unwrap();
    // the triangulation's own space: the square stretched by the mean side lengths
    let scale = winslow_mesh::parameter_scale(&map);
    assert!((scale.x - 1.0).abs() < 1e-12 && (scale.y - 0.75 * std::f64::consts::PI).abs() < 1e-5, "{scale}");
    let (mut pmin, mut xmin) = (f64::INFINITY, f64::INFINITY);
    for c in 0..mesh.num_cells() {
        let v = mesh.corners(c);
        let q = [mesh.params[v[0]] * scale, mesh.params[v[1]] * scale, mesh.params[v[2]] * scale];
        let x = [mesh.points[v[0]], mesh.points[v[1]], mesh.points[v[2]]];
        assert!(signed_area(&q) > 0.0 && signed_area(&x) > 0.0, "cell {c} is not counter-clockwise");
        pmin = angles(q).into_iter().fold(pmin, f64::min);
        xmin = angles(x).into_iter().fold(xmin, f64::min);
        for k in 0..3 {
            assert!(x[k].distance(x[(k + 1) % 3]) <= opts.size * (1.0 + 1e-12));
        }
    }
    assert!(pmin >= 28.0 - 1e-6, "parameter-space min angle {pmin}");
    let q = quality(&mesh).unwrap();
    assert!((q.angle[0] - xmin).abs() < 1e-9, "report {} vs {xmin}", q.angle[0]);
    // nodes are the map's: on the annulus |x| = 1 + v
    for (x, p) in mesh.points.iter().zip(&mesh.params) {
        assert!((x.length() - (1.0 + p.x)).abs() < 1e-13);
    }
    // boundary labels: every labelled edge lies on its side, and the sides are closed
    for side in Side::ALL {
        let edges: Vec<_> = mesh.boundary.iter().filter(|e| e.side == side).collect();
        assert!(!edges.is_empty());
        for e in &edges {
            for &n in &e.nodes {
                let p = mesh.params[n];
                let on = match side {
                    Side::South => p.y == 0.0,
                    Side::East => p.x == 1.0,
                    Side::North => p.y == 1.0,
                    Side::West => p.x == 0.0,
                };
                assert!(on, "{side}: node {n} at {p}");
            }
        }
        for w in edges.windows(2) {
            assert_eq!(w[0].nodes[1], w[1].nodes[0], "{side} edges are not consecutive");
        }
    }
    // Euler: V - E + F = 1 for a disc
    let e = (3 * mesh.num_cells() + mesh.boundary.len()) / 2;
    assert_eq!(mesh.points.len() + mesh.num_cells(), e + 1);
}

#[test]
fn curved_elements_have_their_nodes_on_the_map() {
    let map = annulus();
    let lin = [
        structured(&map, &StructuredOptions::uniform(9, 5)).unwrap(),
        unstructured(&map, &UnstructuredOptions { size: 0.3, ..Default::default() }).unwrap(),
    ];
    for mesh in &lin {
        for p in [2, 3] {
            let hi = elevate(mesh, &map, p).unwrap();
            assert_eq!(hi.order, p);
            assert_eq!(hi.nodes_per_cell(), hi.kind.nodes(p));
            hi.check().unwrap();
            for (x, q) in hi.points.iter().zip(&hi.params) {
                assert_eq!(*x, DVec2::from(map.eval(q.x, q.y)));
                assert!((x.length() - (1.0 + q.x)).abs() < 1e-13);
            }
            // edge nodes shared: each interior edge's nodes appear in two cells
            let mut uses = vec![0usize; hi.points.len()];
            for &n in &hi.cells {
                uses[n] += 1;
            }
            for b in &hi.boundary {
                assert_eq!(b.nodes.len(), p + 1);
                for &n in &b.nodes[2..] {
                    assert_eq!(uses[n], 1, "a boundary edge node belongs to one cell");
                }
            }
            let r = quality(&hi).unwrap().min_jacobian_ratio.unwrap();
            assert!(r > 0.0 && r <= 1.0);
        }
    }
    // a folded map gives curved elements that are refused
    let f = structured(&folded(), &StructuredOptions::uniform(3, 3)).unwrap();
    if f.check().is_ok() {
        assert!(elevate(&f, &folded(), 3).unwrap().check().is_err());
    }
}
