//! Rings meshed without a seam: a periodic ring map and a ring cut into a four-sided map
//! (two coinciding sides), structured and unstructured. Every mesh is an annulus: no two
//! nodes coincide, every interior edge is shared by exactly two cells, boundary edges
//! lie only on the two walls (closed curves `inner` and `outer`), every cell is
//! counter-clockwise, and `V - E + F = 0` (Euler characteristic of an annulus).

mod common;

use std::collections::{HashMap, HashSet};

use common::{cut_ring, ring, signed_area};
use winslow::Surface;
use winslow_mesh::formats::Format;
use winslow_mesh::seam::{seams, SEAM_TOLERANCE};
use winslow_mesh::structured::first_heights;
use winslow_mesh::topology::faces;
use winslow_mesh::validate::validate;
use winslow_mesh::{
    structured, unstructured, DVec2, Distribution, Mesh, MeshError, Side, StructuredOptions, UnstructuredOptions,
};

/// Checks a mesh of an annulus whose walls are `walls` (sides, named inner then outer);
/// returns the number of edges.
fn assert_annulus(mesh: &Mesh, walls: [Side; 2]) -> usize {
    // distinct coordinates
    let distinct: HashSet<(u64, u64)> = mesh.points.iter().map(|p| (p.x.to_bits(), p.y.to_bits())).collect();
    assert_eq!(distinct.len(), mesh.points.len(), "duplicate nodes");
    assert!(winslow_mesh::validate::duplicate_nodes(mesh).is_empty());
    // every edge by its cells
    let mut uses: HashMap<(usize, usize), usize> = HashMap::new();
    for c in 0..mesh.num_cells() {
        let v = mesh.corners(c);
        let p: Vec<DVec2> = v.iter().map(|&i| mesh.points[i]).collect();
        assert!(signed_area(&p) > 0.0, "cell {c} is not counter-clockwise");
        for e in 0..v.len() {
            let (a, b) = (v[e], v[(e + 1) % v.len()]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    assert!(uses.values().all(|&n| n == 1 || n == 2), "an edge used by more than two cells");
    let open: HashSet<(usize, usize)> = uses.iter().filter(|(_, &n)| n == 1).map(|(&e, _)| e).collect();
    let labelled: HashSet<(usize, usize)> = mesh
        .boundary
        .iter()
        .map(|e| {
            let (a, b) = (e.nodes[0], e.nodes[1]);
            (a.min(b), a.max(b))
        })
        .collect();
    // the edges used once are exactly the boundary edges, and those lie on the walls
    assert_eq!(open, labelled);
    assert_eq!(mesh.boundary_sides().len(), 2);
    assert!(mesh.boundary.iter().all(|e| walls.contains(&e.side)));
    assert_eq!((mesh.name(walls[0]), mesh.name(walls[1])), ("inner", "outer"));
    // each wall is one closed curve: every node starts one edge and ends one
    for side in walls {
        let mut starts: Vec<usize> = mesh.boundary.iter().filter(|e| e.side == side).map(|e| e.nodes[0]).collect();
        let mut ends: Vec<usize> = mesh.boundary.iter().filter(|e| e.side == side).map(|e| e.nodes[1]).collect();
        starts.sort_unstable();
        ends.sort_unstable();
        assert_eq!(starts, ends, "{side:?} is not closed");
    }
    // the faces of the finite-volume view agree, and V - E + F = 0
    let f = faces(mesh).unwrap();
    assert_eq!(f.internal.len() + f.boundary.len(), uses.len());
    let (v, e, c) = (mesh.points.len() as i64, uses.len() as i64, mesh.num_cells() as i64);
    assert_eq!(v - e + c, 0, "Euler characteristic of an annulus");
    for format in [Format::Gmsh, Format::Su2, Format::OpenFoam, Format::Vtu] {
        validate(mesh, format).unwrap();
    }
    uses.len()
}

/// The nodes of a mesh lie on the map: `x(params)`.
fn assert_on_map(mesh: &Mesh, map: &Surface) {
    for (p, q) in mesh.points.iter().zip(&mesh.params) {
        assert!(p.distance(DVec2::from(map.eval(q.x, q.y))) < 1e-12);
        assert!((0.0..=1.0).contains(&q.x) && (0.0..=1.0).contains(&q.y));
    }
}

#[test]
fn coinciding_sides_are_found_within_the_tolerance_and_reversed_ones_refused() {
    let s = seams(&cut_ring(false, 0.0)).unwrap();
    assert_eq!((s.dirs, s.periodic_knots, s.cut()), ([false, true], [false, false], Some(1)));
    assert_eq!(s.gap, [0.0, 0.0]);
    // the diameter is the bounding box's diagonal, 4 sqrt(2)
    assert!((s.diameter - 4.0 * 2f64.sqrt()).abs() < 1e-12);
    let s = seams(&cut_ring(true, 0.0)).unwrap();
    assert_eq!((s.dirs, s.cut()), ([true, false], Some(0)));
    // G+Smo's cut ring is 2.2e-7 of its diameter open: a gap below the tolerance merges
    let d = 4.0 * 2f64.sqrt();
    let s = seams(&cut_ring(true, 0.5 * SEAM_TOLERANCE * d)).unwrap();
    assert_eq!(s.dirs, [true, false]);
    assert!((s.gap[0] - 0.5 * SEAM_TOLERANCE * d).abs() < 1e-15, "{}", s.gap[0]);
    // twice the tolerance: four sides, no seam
    let s = seams(&cut_ring(true, 2.0 * SEAM_TOLERANCE * d)).unwrap();
    assert_eq!(s.dirs, [false, false]);
    // the periodic ring: a seam from its knots
    let s = seams(&ring()).unwrap();
    assert_eq!((s.dirs, s.periodic_knots, s.cut()), ([false, true], [false, true], None));
    // sides that coincide reversed would glue the square into a Möbius strip
    let m = cut_ring(false, 0.0);
    let [nu, nv] = [m.knots[0].num_basis(), m.knots[1].num_basis()];
    let mut cps = m.control_points.clone();
    let last = (nv - 1) * nu;
    cps.swap(last, last + 1);
    let weights = m.weights.clone();
    let mobius = Surface::new(m.knots.clone(), cps, weights).unwrap();
    assert!(matches!(seams(&mobius), Err(MeshError::Parameter { .. })));
    // a square has no seam
    let (square, _) = common::affine();
    assert_eq!(seams(&square).unwrap().dirs, [false, false]);
}

#[test]
fn a_cut_ring_is_meshed_like_the_ring_structured() {
    // seam south = north: eta around, 40 points make 40 cells; walls west and east
    let map = cut_ring(false, 0.0);
    let mesh = structured(&map, &StructuredOptions::uniform(9, 40)).unwrap();
    assert_eq!((mesh.points.len(), mesh.num_cells(), mesh.periodic), (9 * 40, 8 * 40, [false, true]));
    let edges = assert_annulus(&mesh, [Side::West, Side::East]);
    assert_eq!(edges, 8 * 40 + 9 * 40);
    assert_on_map(&mesh, &map);
    // the nodes are the ring's: the last row's cells close on the first row
    let last = mesh.cell(mesh.num_cells() - 1);
    assert_eq!((last[2], last[3]), (8, 7));
    // seam west = east: xi around (the outer wall is south, G+Smo's layout)
    let map = cut_ring(true, 0.0);
    let mesh = structured(&map, &StructuredOptions::uniform(40, 9)).unwrap();
    assert_eq!((mesh.points.len(), mesh.num_cells(), mesh.periodic), (40 * 9, 40 * 8, [true, false]));
    assert_annulus(&mesh, [Side::North, Side::South]);
    assert_on_map(&mesh, &map);
    // a gap within the tolerance: merged, the seam nodes are the start side's
    let gap = 0.5 * SEAM_TOLERANCE * 4.0 * 2f64.sqrt();
    let mesh = structured(&cut_ring(true, gap), &StructuredOptions::uniform(40, 9)).unwrap();
    assert_annulus(&mesh, [Side::North, Side::South]);
}

#[test]
fn first_cell_heights_on_the_walls_of_a_cut_ring_lie_within_h_over_g_and_h() {
    let map = cut_ring(true, 0.0);
    let (h, g) = (1e-3, 1.2);
    let opts = StructuredOptions {
        points: [64, 61],
        distribution: [Distribution::Uniform, Distribution::Layers { start: Some(h), end: Some(h), growth: g }],
    };
    let mesh = structured(&map, &opts).unwrap();
    assert_annulus(&mesh, [Side::North, Side::South]);
    let fh = first_heights(&mesh);
    assert_eq!(fh.iter().map(|f| f.0).collect::<Vec<_>>(), [Side::South, Side::North]);
    for (side, [lo, hi]) in fh {
        assert!(lo >= h / g && hi <= h * (1.0 + 1e-9), "{side:?}: {lo} .. {hi}");
        assert!((hi - h).abs() < 1e-9 * h, "{side:?}: largest first cell {hi}");
    }
    // layers on the seam are refused, naming the walls
    let opts = StructuredOptions {
        points: [64, 61],
        distribution: [Distribution::Layers { start: Some(h), end: None, growth: g }, Distribution::Uniform],
    };
    match structured(&map, &opts) {
        Err(MeshError::Layer { side, why, .. }) => {
            assert_eq!(side, "west");
            assert!(why.contains("south (outer)") && why.contains("north (inner)"), "{why}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn rings_are_triangulated_with_the_seam_shared() {
    for (map, walls, dir) in [
        (ring(), [Side::West, Side::East], 1),
        (cut_ring(false, 0.0), [Side::West, Side::East], 1),
        (cut_ring(true, 0.0), [Side::North, Side::South], 0),
    ] {
        let mesh = unstructured(&map, &UnstructuredOptions { size: 0.2, ..Default::default() }).unwrap();
        assert!(mesh.periodic[dir]);
        assert_annulus(&mesh, walls);
        assert_on_map(&mesh, &map);
        // no node on the end side of the seam, and seam nodes on the start side shared by
        // triangles on both sides of it
        assert!(mesh.params.iter().all(|q| q[dir] < 1.0));
        let seam: Vec<usize> = (0..mesh.points.len()).filter(|&i| mesh.params[i][dir] == 0.0).collect();
        assert!(seam.len() >= 3);
        let mut below = HashSet::new();
        let mut above = HashSet::new();
        for c in 0..mesh.num_cells() {
            let v = mesh.corners(c);
            for &i in v {
                if mesh.params[i][dir] == 0.0 {
                    // a cell beyond the seam has its other corners near 1
                    if v.iter().any(|&k| mesh.params[k][dir] > 0.5) {
                        above.insert(i);
                    } else {
                        below.insert(i);
                    }
                }
            }
        }
        for i in &seam {
            assert!(below.contains(i) && above.contains(i), "seam node {i} on one side only");
        }
        // the edges are about `size` long
        let longest = (0..mesh.num_cells())
            .flat_map(|c| {
                let v = mesh.corners(c).to_vec();
                (0..3).map(move |e| (v[e], v[(e + 1) % 3]))
            })
            .map(|(a, b)| mesh.points[a].distance(mesh.points[b]))
            .fold(0.0, f64::max);
        assert!(longest <= 0.2 * (1.0 + 1e-9), "longest edge {longest}");
        // the walls are split as finely as their length asks: their lengths are about
        // 2 pi 0.5 and 2 pi 2 (within 10 % on the B-spline ring), over edges of 0.2
        for (side, r) in walls.iter().zip([0.5, 2.0]) {
            let n = mesh.boundary.iter().filter(|e| e.side == *side).count() as f64;
            assert!(n >= 0.9 * 2.0 * std::f64::consts::PI * r / 0.2, "{side:?}: {n} edges");
        }
    }
}

#[test]
fn curved_elements_of_a_triangulated_ring_keep_the_seam() {
    let map = cut_ring(false, 0.0);
    let mesh = unstructured(&map, &UnstructuredOptions { size: 0.3, order: 3, ..Default::default() }).unwrap();
    let cubic = winslow_mesh::high_order::elevate(&mesh, &map, 3).unwrap();
    cubic.check().unwrap();
    // the edge nodes of cells at the seam lie on the map between their corners
    for (p, q) in cubic.points.iter().zip(&cubic.params) {
        assert!(p.distance(DVec2::from(map.eval(q.x, q.y))) < 1e-12);
    }
    let distinct: HashSet<(u64, u64)> = cubic.points.iter().map(|p| (p.x.to_bits(), p.y.to_bits())).collect();
    assert_eq!(distinct.len(), cubic.points.len());
    validate(&cubic, Format::Gmsh).unwrap();
}

/// A periodic ring in polar form: the outer wall the circle of radius 2, the inner wall
/// at radius `r(t) = 1 + 0.97 (1 + cos t) / 2`, across along the rays: 0.03 wide at angle
/// 0 and 1 wide at angle pi, a width varying 33-fold around (the rotor in its casing
/// varies 250-fold).
fn narrowing_ring() -> Surface {
    let ku = winslow::KnotVector::open_uniform(1, 1);
    let kv = winslow::KnotVector::periodic_uniform(3, 64);
    let mut cps = Vec::new();
    for j in 0..kv.num_basis() {
        let t = 2.0 * std::f64::consts::PI * ((j % 64) as f64) / 64.0;
        for r in [1.0 + 0.485 * (1.0 + t.cos()), 2.0] {
            cps.push([r * t.cos(), r * t.sin()]);
        }
    }
    Surface::new([ku, kv], cps, None).unwrap()
}

#[test]
fn a_ring_narrowing_thirtyfold_is_triangulated_without_slivers() {
    let map = narrowing_ring();
    for size in [0.2, 0.05] {
        let mesh = unstructured(&map, &UnstructuredOptions { size, ..Default::default() }).unwrap();
        assert_annulus(&mesh, [Side::West, Side::East]);
        assert_on_map(&mesh, &map);
        // physical angles: the rectangle stretched by the local aspect around keeps the
        // triangles in the narrow part about as wide as the ring is there (a rectangle of
        // the mean width made 0.9 to 177.8 degrees and aspect ratios of 43 at size 0.2;
        // now 21.7 to 120.3 and 2.4)
        let q = winslow_mesh::quality::quality(&mesh).unwrap();
        assert!(q.angle[0] > 15.0 && q.angle[1] < 140.0, "size {size}: angles {:?}", q.angle);
    }
}

#[test]
fn a_size_beyond_the_vertex_guard_is_refused_before_refinement() {
    // size 0.05 makes about 6 000 vertices (above); 0.01 about 25 times as many
    let map = narrowing_ring();
    let opts = UnstructuredOptions { size: 0.01, max_vertices: 20_000, ..Default::default() };
    match unstructured(&map, &opts) {
        Err(MeshError::Triangulation(why)) => {
            assert!(why.contains("vertices expected") && why.contains("limit of 20000"), "{why}")
        }
        other => panic!("{other:?}"),
    }
    // a size the guard admits is not refused up front
    let opts = UnstructuredOptions { size: 0.05, max_vertices: 20_000, ..Default::default() };
    assert!(unstructured(&map, &opts).unwrap().points.len() < 20_000);
}
