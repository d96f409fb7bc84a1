//! Multipatch domains (paper §11.2) on the shared G+Smo multipatch files
//! (`tests/data/gismo/xml/multipatch/`): reading, validation, conforming bases, solves
//! with fixed and free interfaces, and the round trip of the G+Smo multipatch writer.

use std::path::PathBuf;

use winslow::io::multipatch::gismo::{multipatch_to_gismo_xml, parse_gismo_multipatch};
use winslow::multipatch::classes::LayoutBases;
use winslow::multipatch::{validate_layout, Functional, Interfaces, Layout, MultipatchSolution};
use winslow::multipatch::{Interface, Patch, PatchSide};
use winslow::solve::report::Verdict;
use winslow::{Curve, KnotVector, Point, Side};
use winslow::{Pipeline, SolveOptions, Solved};

fn data(rel: &str) -> PathBuf {
    winslow::testutil::data("gismo/xml/multipatch").join(rel)
}

fn read(name: &str) -> Layout {
    let text = std::fs::read_to_string(data(name)).unwrap();
    parse_gismo_multipatch(&text).unwrap()
}

#[test]
fn shared_multipatch_files_are_valid_layouts() {
    for (name, patches, interfaces) in [("TUDflame.xml", 5, 4), ("circleMP.xml", 5, 8), ("plateWithHoleMP.xml", 2, 1)] {
        let l = read(name);
        let r = validate_layout(&l).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((r.patches, r.interfaces), (patches, interfaces), "{name}");
        assert!(r.interface_gap < 1e-9 * r.diameter, "{name}: {}", r.interface_gap);
        let b = LayoutBases::new(&l).unwrap();
        let sides = b.conforming_sides(&l).unwrap();
        for i in &l.interfaces {
            let a = &sides[i.first.patch][i.first.side as usize];
            let c = &sides[i.second.patch][i.second.side as usize];
            let mut cps = c.control_points.clone();
            if i.reversed {
                cps.reverse();
            }
            assert_eq!(a.control_points, cps, "{name}");
        }
    }
}

#[test]
fn gismo_multipatch_round_trip_is_exact() {
    for name in ["TUDflame.xml", "circleMP.xml", "plateWithHoleMP.xml"] {
        let l = read(name);
        let maps: Vec<_> = l.patches.iter().map(|p| p.map.clone().unwrap()).collect();
        let xml = multipatch_to_gismo_xml(&l, &maps, "round trip").unwrap();
        let back = parse_gismo_multipatch(&xml).unwrap();
        assert_eq!(back.interfaces, l.interfaces, "{name}");
        for (a, b) in back.patches.iter().zip(&l.patches) {
            assert_eq!(a.map, b.map, "{name}");
        }
        validate_layout(&back).unwrap();
    }
}

/// The pipeline's solve of `layout`, improved (free interfaces) by `functional`.
fn solve_layout(layout: &Layout, functional: Option<Functional>) -> MultipatchSolution {
    let mut opts = SolveOptions::default();
    opts.improve = functional;
    match Pipeline::new(layout.clone(), opts).solve() {
        Ok(Solved::Layout { solution, .. }) => *solution,
        other => panic!("{}: {other:?}", layout.name),
    }
}

fn solve(name: &str, interfaces: Interfaces) -> MultipatchSolution {
    solve_layout(&read(name), (interfaces == Interfaces::Free).then_some(Functional::Winslow))
}

#[test]
fn shared_files_certify_with_fixed_and_free_interfaces() {
    for name in ["TUDflame.xml", "circleMP.xml", "plateWithHoleMP.xml"] {
        for mode in [Interfaces::Fixed, Interfaces::Free] {
            let s = solve(name, mode);
            let r = &s.report;
            eprintln!("{name} {mode:?}: {} ({:.3} s) winslow {:?}", r.message, r.seconds, r.winslow);
            assert!(matches!(r.verdict, Verdict::Certified), "{name} {mode:?}: {}", r.message);
            assert_eq!(r.interface_mismatch, 0.0, "{name}");
            if mode == Interfaces::Free {
                let f = r.free.as_ref().unwrap();
                assert!(f.accepted, "{name}: {}", f.message);
                assert!(f.winslow_after.unwrap() <= f.winslow_before.unwrap());
            }
        }
    }
}

/// A straight segment from `a` to `b` as a degree-2 spline with `ne` elements, cps at the
/// Greville abscissae (linear parameterization).
fn segment(a: Point, b: Point, ne: usize) -> Curve {
    let kv = KnotVector::open_uniform(2, ne);
    let cps = kv.greville().iter().map(|&t| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]).collect();
    Curve::new(kv, cps, None).unwrap()
}

/// Two unit squares side by side whose interface, from (1, 0) to (1, 1), is bent to
/// `x = 1 + bend sin(pi t)`.
fn bent_pair(bend: f64) -> Layout {
    let kv = KnotVector::open_uniform(2, 4);
    let mid_cps: Vec<Point> =
        kv.greville().iter().map(|&t| [1.0 + bend * (std::f64::consts::PI * t).sin(), t]).collect();
    let mid = Curve::new(kv, mid_cps, None).unwrap();
    let a = Patch::from_sides(
        "a",
        [
            segment([0.0, 0.0], [1.0, 0.0], 3),
            mid.clone(),
            segment([0.0, 1.0], [1.0, 1.0], 3),
            segment([0.0, 0.0], [0.0, 1.0], 4),
        ],
    );
    let b = Patch::from_sides(
        "b",
        [
            segment([1.0, 0.0], [2.0, 0.0], 3),
            segment([2.0, 0.0], [2.0, 1.0], 4),
            segment([1.0, 1.0], [2.0, 1.0], 3),
            mid,
        ],
    );
    Layout {
        name: "bent".into(),
        patches: vec![a, b],
        interfaces: vec![Interface {
            first: PatchSide { patch: 0, side: Side::East },
            second: PatchSide { patch: 1, side: Side::West },
            reversed: false,
        }],
    }
}

/// An interface bent on purpose: with free interfaces the Winslow functional moves it
/// back to the straight line x = 1, where both patches are the identity (W = 2 per unit
/// area, the global minimum 4); the fixed solve keeps the bend.
#[test]
fn free_interfaces_straighten_a_bent_interface() {
    let l = bent_pair(0.3);
    let fixed = solve_layout(&l, None);
    assert_eq!(fixed.report.verdict, Verdict::Certified, "{}", fixed.report.message);
    let w_fixed = fixed.report.winslow.unwrap();
    assert!(w_fixed > 4.1, "{w_fixed}");
    for functional in [Functional::Winslow, Functional::WeakForm] {
        let free = solve_layout(&l, Some(functional));
        straight(&free, w_fixed);
    }
}

fn straight(free: &winslow::multipatch::MultipatchSolution, w_fixed: f64) {
    let r = &free.report;
    assert_eq!(r.verdict, Verdict::Certified, "{}", r.message);
    let f = r.free.as_ref().unwrap();
    assert!(f.accepted && f.converged, "{}", f.message);
    assert!((f.winslow_before.unwrap() - w_fixed).abs() < 1e-12);
    let w = r.winslow.unwrap();
    assert!((w - 4.0).abs() < 1e-8, "total Winslow {w}");
    // the interface is straight again, shared bit for bit
    assert_eq!(r.interface_mismatch, 0.0);
    let east = free.patches[0].map.boundary(Side::East);
    for p in &east.control_points {
        assert!((p[0] - 1.0).abs() < 1e-7, "{p:?}");
    }
    assert!(f.max_interface_displacement > 0.1);
}

/// G+Smo wraps single domains in `<MultiPatch>` too: four boundary curves as
/// `<MultiPatch parDim="1">`, one surface as a one-patch `<MultiPatch>`. Those are
/// boundary and map documents for the ordinary readers and solve, not layouts; the
/// shared multipatch files are layouts.
#[test]
fn single_domain_gismo_files_are_not_layouts() {
    let dir = winslow::testutil::data("gismo/xml");
    let mut single = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "xml") {
            let doc = winslow::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(matches!(doc.kind(), "boundary" | "map"), "{} read as a {}", path.display(), doc.kind());
            single += 1;
        }
    }
    assert!(single >= 10, "{single} single-domain files");
    for name in ["TUDflame.xml", "circleMP.xml", "plateWithHoleMP.xml"] {
        let doc = winslow::read(&data(name)).unwrap();
        assert!(matches!(&doc, winslow::Document::Layout(l) if l.patches.len() > 1), "{name}: {}", doc.kind());
    }
}
