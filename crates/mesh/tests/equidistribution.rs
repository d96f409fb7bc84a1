//! Equidistribution along the boundary and the unstructured refinement criteria, against
//! closed forms: straight sides parameterized unevenly, circular arcs.

mod common;

use common::annulus;
use std::f64::consts::FRAC_PI_2;
use winslow::{KnotVector, Side, Surface};
use winslow_mesh::equidistribution::{chord_deviation, equidistributed};
use winslow_mesh::{structured, unstructured, Distribution, Equidistribution, StructuredOptions, UnstructuredOptions};

/// The rectangle `[0, 1] x [0, 1]` with `x(xi) = 0.2 xi (1 - xi) + xi^2` (quadratic,
/// control points 0, 0.1, 1): straight sides traversed at uneven speed.
fn uneven_rectangle() -> Surface {
    let ku = KnotVector::open_uniform(2, 1);
    let kv = KnotVector::open_uniform(1, 1);
    let mut cps = Vec::new();
    for y in [0.0, 1.0] {
        for x in [0.0, 0.1, 1.0] {
            cps.push([x, y]);
        }
    }
    Surface::new([ku, kv], cps, None).unwrap()
}

fn equi(e: Equidistribution) -> Distribution {
    Distribution::Equidistributed(e)
}

#[test]
fn equal_arc_length_gives_equal_spacings_on_a_straight_side_parameterized_unevenly() {
    let map = uneven_rectangle();
    let opts =
        StructuredOptions { points: [11, 3], distribution: [equi(Equidistribution::ArcLength), Distribution::Uniform] };
    let mesh = structured(&map, &opts).unwrap();
    // uniform xi would give x(0.1) = 0.028: far from 0.1
    for j in 0..3 {
        for i in 0..11 {
            let p = mesh.points[j * 11 + i];
            assert!((p.x - i as f64 / 10.0).abs() < 1e-10, "node ({i}, {j}) at {p}");
        }
    }
}

#[test]
fn equal_arc_length_on_circular_arcs_gives_equal_chords() {
    // the quarter annulus: eta runs along the arcs r = 1 (west) and r = 2 (east), whose
    // rational parameterization is not by arc length
    let map = annulus();
    let n = 9;
    let eta = equidistributed(&map, 1, Equidistribution::ArcLength, n).unwrap();
    assert_eq!(eta.len(), n);
    for (u, r) in [(0.0, 1.0), (1.0, 2.0)] {
        let chord = 2.0 * r * (FRAC_PI_2 / (n - 1) as f64 / 2.0).sin();
        for w in eta.windows(2) {
            let (a, b) = (map.eval(u, w[0]), map.eval(u, w[1]));
            let d = (a[0] - b[0]).hypot(a[1] - b[1]);
            assert!((d - chord).abs() < 1e-10, "r = {r}: chord {d} against {chord}");
        }
    }
    // uniform eta is visibly uneven there
    let (a, b) = (map.eval(0.0, 0.0), map.eval(0.0, 0.125));
    assert!(((a[0] - b[0]).hypot(a[1] - b[1]) - 2.0 * (FRAC_PI_2 / 16.0).sin()).abs() > 1e-3);
}

#[test]
fn curvature_equidistribution_meets_the_chord_tolerance_with_the_fewest_points() {
    let map = annulus();
    for tol in [1e-2, 1e-3, 2e-5] {
        // equal angles are optimal on both arcs; the outer arc (r = 2) deviates by
        // 2 (1 - cos(phi / 2)) for an angle step phi: the fewest points that meet tol
        let dev = |m: usize| 2.0 * (1.0 - (FRAC_PI_2 / (m - 1) as f64 / 2.0).cos());
        let fewest = (2..).find(|&m| dev(m) <= tol).unwrap();
        let opts = StructuredOptions {
            points: [3, 2],
            distribution: [Distribution::Uniform, equi(Equidistribution::Curvature { tol })],
        };
        let mesh = structured(&map, &opts).unwrap();
        let ny = mesh.structured.unwrap()[1];
        assert_eq!(ny, fewest, "tol {tol}");
        let eta: Vec<f64> = (0..ny).map(|j| mesh.params[j * 3].y).collect();
        let east = chord_deviation(&map, Side::East, &eta);
        let west = chord_deviation(&map, Side::West, &eta);
        assert!(east <= tol && (east - dev(ny)).abs() < 1e-9, "tol {tol}: east {east} against {}", dev(ny));
        assert!((west - dev(ny) / 2.0).abs() < 1e-9, "west {west}");
        // one point fewer, equidistributed, misses the tolerance
        let fewer = equidistributed(&map, 1, Equidistribution::ArcLength, ny - 1).unwrap();
        assert!(chord_deviation(&map, Side::East, &fewer) > tol);
    }
    // a count larger than needed is kept (a lower bound)
    let opts = StructuredOptions {
        points: [3, 40],
        distribution: [Distribution::Uniform, equi(Equidistribution::Curvature { tol: 1e-2 })],
    };
    assert_eq!(structured(&map, &opts).unwrap().structured.unwrap()[1], 40);
    // straight sides deviate by nothing: two points do
    let opts = StructuredOptions {
        points: [2, 2],
        distribution: [equi(Equidistribution::Curvature { tol: 1e-9 }), Distribution::Uniform],
    };
    assert_eq!(structured(&map, &opts).unwrap().structured.unwrap()[0], 2);
}

#[test]
fn bad_equidistribution_is_an_error() {
    let map = annulus();
    for tol in [0.0, -1.0, f64::NAN] {
        let opts = StructuredOptions {
            points: [3, 3],
            distribution: [Distribution::Uniform, equi(Equidistribution::Curvature { tol })],
        };
        assert!(structured(&map, &opts).is_err(), "{tol}");
    }
    assert!(equidistributed(&map, 1, Equidistribution::ArcLength, 1).is_err());
    // too fine for the point limit
    assert!(equidistributed(&map, 1, Equidistribution::Curvature { tol: 1e-14 }, 2).is_err());
}

#[test]
fn unstructured_boundary_meets_the_chord_tolerance_and_det_j_the_ratio() {
    let map = annulus();
    let (size, tol, ratio) = (0.4, 2e-3, 1.3);
    let opts = UnstructuredOptions { size, chord_tol: Some(tol), det_j_ratio: Some(ratio), ..Default::default() };
    let mesh = unstructured(&map, &opts).unwrap();
    // boundary curvature: on the arcs a segment spanning the angle phi deviates from its
    // chord by r (1 - cos(phi / 2))
    let mut arcs = 0;
    for e in &mesh.boundary {
        let (a, b) = (mesh.points[e.nodes[0]], mesh.points[e.nodes[1]]);
        match e.side {
            Side::West | Side::East => {
                let r = a.length();
                let phi = a.angle_to(b).abs();
                assert!(r * (1.0 - (phi / 2.0).cos()) <= tol * (1.0 + 1e-9), "{:?}: {a} {b}", e.side);
                arcs += 1;
            }
            _ => {}
        }
    }
    // size alone would put about (pi/2) (1 + 2) / 0.4 = 12 segments on the arcs;
    // the tolerance needs r (1 - cos(phi / 2)) <= tol: phi <= 2 acos(1 - tol / r)
    let need = |r: f64| (FRAC_PI_2 / (2.0 * (1.0 - tol / r).acos())).ceil() as usize;
    assert!(arcs >= need(1.0) + need(2.0), "{arcs} arc segments");
    // det J: where a triangle is longer than size / 8, its vertices' det J differ by at
    // most the ratio (det J = r |d theta / d eta| (pi/2-scaled) on the annulus)
    for c in 0..mesh.num_cells() {
        let v = mesh.corners(c);
        let x = v.iter().map(|&k| mesh.points[k]).collect::<Vec<_>>();
        let longest = (0..3).map(|k| x[k].distance(x[(k + 1) % 3])).fold(0.0, f64::max);
        if longest > size / 8.0 {
            let d: Vec<f64> = v.iter().map(|&k| map.derivs(mesh.params[k].x, mesh.params[k].y, 1).det_j()).collect();
            let (lo, hi) = (d.iter().copied().fold(f64::INFINITY, f64::min), d.iter().copied().fold(0.0, f64::max));
            assert!(hi <= ratio * lo * (1.0 + 1e-12), "cell {c}: det J {d:?}");
        }
    }
}
