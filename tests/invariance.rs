//! Similarity invariance of the solve (issue: reliability): a geometry translated by 1e9
//! times its size, or scaled by 1e±150, gives the same verdict, the same iteration
//! counts and the same map (transformed) as the original, up to the rounding of the
//! input's own coordinates; sizes whose `det J` leaves `f64`'s range get a typed error,
//! not a wrong diagnosis.

use winslow::boundary::validate::validate;
use winslow::boundary::{Boundary, SideCurve};
use winslow::io::{read_boundary, ReadOptions};
use winslow::solve;
use winslow::solve::options::SolveOptions;
use winslow::solve::report::Solution;
use winslow::{Error, Point, Surface, Verdict};

fn load(file: &str) -> Boundary {
    let path = winslow::testutil::data(file);
    read_boundary(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// `x ↦ a + s x` applied to every side (control points or points; weights kept).
fn similar(b: &Boundary, a: Point, s: f64) -> Boundary {
    let f = |p: &Point| [a[0] + s * p[0], a[1] + s * p[1]];
    let side = |c: &SideCurve| match c {
        SideCurve::Spline(c) => {
            let mut c = c.clone();
            c.control_points = c.control_points.iter().map(f).collect();
            SideCurve::Spline(c)
        }
        SideCurve::Points(p) => SideCurve::Points(p.iter().map(f).collect()),
        SideCurve::Analytic(_) => unreachable!("files hold no analytic sides"),
    };
    Boundary { name: b.name.clone(), sides: b.sides.each_ref().map(side) }
}

fn solved(b: &Boundary) -> Solution {
    solve(b, &SolveOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", b.name))
}

/// Same verdict, levels, bases and iteration counts; control points equal to the
/// transformed original's within `tol` of the diameter.
fn assert_same(file: &str, orig: &Solution, moved: &Solution, a: Point, s: f64, tol: f64) {
    let (r0, r1) = (&orig.report, &moved.report);
    let what = format!("{file} moved by {a:?}, scaled by {s:e}");
    assert_eq!(r1.outcome.verdict, r0.outcome.verdict, "{what}: {}", r1.outcome.message);
    assert_eq!(r1.solve.levels.len(), r0.solve.levels.len(), "{what}");
    for (l0, l1) in r0.solve.levels.iter().zip(&r1.solve.levels) {
        assert_eq!(l1.shape, l0.shape, "{what}");
        assert_eq!(l1.newton_iterations, l0.newton_iterations, "{what}: level {}", l0.level);
        assert_eq!(l1.pseudo_time_iterations, l0.pseudo_time_iterations, "{what}: level {}", l0.level);
    }
    let rel = |x: f64, y: f64| (x - y).abs() / (s.abs() * r0.fit.diameter);
    assert!(
        rel(r1.fit.diameter, s * r0.fit.diameter) < tol,
        "{what}: diameter {} vs {}",
        r1.fit.diameter,
        r0.fit.diameter
    );
    assert!(
        (r1.measures.area / (s * s * r0.measures.area) - 1.0).abs() < tol,
        "{what}: area {} vs {}",
        r1.measures.area,
        r0.measures.area
    );
    let dj = (r1.det_j.min / (s * s * r0.det_j.min) - 1.0).abs();
    assert!(dj < 1e-6_f64.max(100.0 * tol), "{what}: det J min {} vs {}", r1.det_j.min, r0.det_j.min);
    let (m0, m1) = (&orig.map, &moved.map);
    assert_eq!(m1.knots, m0.knots, "{what}");
    let worst = m0
        .control_points
        .iter()
        .zip(&m1.control_points)
        .map(|(p, q)| rel(q[0], a[0] + s * p[0]).max(rel(q[1], a[1] + s * p[1])))
        .fold(0.0, f64::max);
    assert!(worst < tol, "{what}: control points differ by {worst:.3e} of the diameter");
}

#[test]
fn translated_and_scaled_geometries_solve_alike() {
    for file in ["gismo/duck.json", "quarter_annulus.json", "gismo/puzzle3.json"] {
        let b = load(file);
        let orig = solved(&b);
        let d = orig.report.fit.diameter;
        // far from the origin: the input itself is rounded to ~1e9 eps of its size, and
        // the map can follow it no closer than that
        for (a, s, tol) in [
            ([1e9 * d, -3e9 * d], 1.0, 1e-5),
            ([-1e6 * d, 1e6 * d], 1.0, 1e-8),
            ([0.0, 0.0], 1e150, 1e-8),
            ([0.0, 0.0], 1e-150, 1e-8),
            ([7e158, 0.0], 1e150, 1e-5),
        ] {
            let moved = solved(&similar(&b, a, s));
            assert_same(file, &orig, &moved, a, s, tol);
        }
    }
}

#[test]
fn sizes_beyond_the_range_of_det_j_are_a_typed_error() {
    let b = load("quarter_annulus.json");
    for s in [1e300, 1e-300, 1e200, 1e-200] {
        let moved = similar(&b, [0.0, 0.0], s);
        for e in [validate(&moved).unwrap_err(), solve(&moved, &SolveOptions::default()).unwrap_err()] {
            assert!(matches!(e, Error::Range { .. }), "scale {s:e}: {e}");
        }
    }
}

#[test]
fn validation_reports_in_the_input_coordinates() {
    let b = load("gismo/duck.json");
    let r0 = validate(&b).unwrap();
    let (a, s) = ([5e-109, -2e-109], 1e-120);
    let r1 = validate(&similar(&b, a, s)).unwrap();
    assert_eq!(r1.orientation, r0.orientation);
    // the input itself is rounded to ~1e9 eps of its size at its position
    assert!((r1.diameter / (s * r0.diameter) - 1.0).abs() < 1e-6, "{} vs {}", r1.diameter, r0.diameter);
    assert!((r1.signed_area / (s * s * r0.signed_area) - 1.0).abs() < 1e-6);
    for k in 0..4 {
        for c in 0..2 {
            let want = a[c] + s * r0.corners[k][c];
            assert!((r1.corners[k][c] - want).abs() <= 1e-12 * want.abs(), "corner {k}: {:?}", r1.corners[k]);
        }
        assert!(
            (r1.corner_angles[k] - r0.corner_angles[k]).abs() < 1e-3,
            "{:?} vs {:?}",
            r1.corner_angles,
            r0.corner_angles
        );
    }
}

// ---- every document kind (issue 30): rings, layouts, sweeps and lofted volumes ----

use winslow::boundary::ring::Ring;
use winslow::io::multipatch::gismo::parse_gismo_multipatch;
use winslow::multipatch::{Functional, Interfaces, Layout, MultipatchSolution};
use winslow::pipeline::sweep::{Sweep, SweepOptions};
use winslow::solve::loft::{loft, LoftOptions, SliceBoundary};
use winslow::{Document, Pipeline, Solved};

/// The three similarities of `scripts/invariance.sh` for a domain of diameter `d`.
fn similarities(d: f64) -> [(Point, f64); 3] {
    [([1e9 * d, -2e9 * d], 1.0), ([0.0, 0.0], 1e150), ([0.0, 0.0], 1e-150)]
}

fn ring(file: &str) -> Ring {
    match winslow::read(&winslow::testutil::data(file)).unwrap_or_else(|e| panic!("{file}: {e}")) {
        Document::Ring(r) => r,
        other => panic!("{file}: {}", other.kind()),
    }
}

fn similar_ring(r: &Ring, a: Point, s: f64) -> Ring {
    let f = move |p: Point| [p[0] * s + a[0], p[1] * s + a[1]];
    Ring { name: r.name.clone(), inner: r.inner.mapped(f), outer: r.outer.mapped(f) }
}

/// Verdict and Newton iterations per level.
fn summary(sol: &Solution) -> (Verdict, Vec<usize>) {
    (sol.report.outcome.verdict, sol.report.solve.levels.iter().map(|l| l.newton_iterations).collect())
}

/// A ring translated by 1e9 times its size was refused as running clockwise (its signed
/// area computed from raw coordinates); now every similarity gives the same verdict and
/// iterations, and the map transformed within the input's own rounding.
#[test]
fn rings_translated_and_scaled_solve_alike() {
    for file in ["rings/eccentric_annulus.json", "rings/annulus_periodic.json"] {
        let r = ring(file);
        let orig = Pipeline::new(r.clone(), SolveOptions::default()).solve().and_then(Solved::into_map).unwrap();
        let d = orig.report.fit.diameter;
        for (a, s) in similarities(d) {
            let moved = Pipeline::new(similar_ring(&r, a, s), SolveOptions::default())
                .solve()
                .and_then(Solved::into_map)
                .unwrap_or_else(|e| panic!("{file} moved by {a:?}, scaled by {s:e}: {e}"));
            assert_eq!(summary(&moved), summary(&orig), "{file} moved by {a:?}, scaled by {s:e}");
            let worst = orig
                .map
                .control_points
                .iter()
                .zip(&moved.map.control_points)
                .map(|(p, q)| ((q[0] - a[0] - s * p[0]).abs()).max((q[1] - a[1] - s * p[1]).abs()) / (s * d))
                .fold(0.0, f64::max);
            assert!(worst < 1e-5, "{file} moved by {a:?}: control points differ by {worst:.3e} of the diameter");
        }
    }
}

/// The control points of a G+Smo XML text mapped by `x ↦ a + s x` (what
/// `scripts/similar_xml.py` does), so that the reader's orientation test sees them.
fn similar_xml(text: &str, a: Point, s: f64) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(i) = rest.find("<coefs geoDim=\"2\">") {
        let open = i + "<coefs geoDim=\"2\">".len();
        let close = open + rest[open..].find("</coefs>").expect("closed coefs");
        out.push_str(&rest[..open]);
        let v: Vec<f64> = rest[open..close].split_whitespace().map(|t| t.parse().unwrap()).collect();
        for p in v.chunks(2) {
            out.push_str(&format!("{:?} {:?}\n", p[0] * s + a[0], p[1] * s + a[1]));
        }
        rest = &rest[close..];
    }
    out.push_str(rest);
    out
}

/// The pipeline's solve of a layout with `opts`.
fn solve_layout(layout: &Layout, opts: &SolveOptions) -> winslow::Result<MultipatchSolution> {
    match Pipeline::new(layout.clone(), opts.clone()).solve()? {
        Solved::Layout { solution, .. } => Ok(*solution),
        other => panic!("a layout gave {:?}", other.verdict()),
    }
}

fn layout_summary(m: &MultipatchSolution) -> (Vec<Verdict>, Vec<Vec<usize>>, Option<usize>) {
    let its = m.patches.iter().map(|p| p.solve.solve.levels.iter().map(|l| l.newton_iterations).collect()).collect();
    (m.report.verdicts.clone(), its, m.report.free.as_ref().map(|f| f.iterations))
}

/// Layouts translated far away failed their interface check (NURBS sides evaluated at
/// 1e9 are rounded to 1e-7 of their size) and had their patches transposed by the
/// reader; the free interfaces took a number of iterations that depended on the scale.
#[test]
fn layouts_translated_and_scaled_solve_alike() {
    for file in ["gismo/xml/multipatch/plateWithHoleMP.xml", "gismo/xml/multipatch/circleMP.xml"] {
        let text = std::fs::read_to_string(winslow::testutil::data(file)).unwrap();
        for interfaces in [Interfaces::Fixed, Interfaces::Free] {
            let improve = (interfaces == Interfaces::Free).then_some(Functional::Winslow);
            let mut opts = SolveOptions::default();
            opts.improve = improve;
            let orig = solve_layout(&parse_gismo_multipatch(&text).unwrap(), &opts).unwrap();
            for (a, s) in similarities(orig.report.layout.diameter) {
                let what = format!("{file} {interfaces:?} moved by {a:?}, scaled by {s:e}");
                let layout =
                    parse_gismo_multipatch(&similar_xml(&text, a, s)).unwrap_or_else(|e| panic!("{what}: {e}"));
                let moved = solve_layout(&layout, &opts).unwrap_or_else(|e| panic!("{what}: {e}"));
                assert_eq!(layout_summary(&moved), layout_summary(&orig), "{what}");
                let area = moved.report.layout.area / (s * s * orig.report.layout.area);
                assert!((area - 1.0).abs() < 1e-6, "{what}: area ratio {area}");
            }
        }
    }
}

/// A sliding grid (three steps of 3 degrees about the inner circle's centre, mapped too)
/// and the volume lofted from its frames (heights mapped too): the same verdicts,
/// iterations and linear solves per frame, and the same loft.
#[test]
fn sweeps_and_lofts_translated_and_scaled_alike() {
    let r = ring("rings/eccentric_annulus.json");
    let mut opts = SolveOptions::default();
    opts.fit.tol = 1e-3;
    let run = |a: Point, s: f64| {
        let sweep = SweepOptions {
            step: 3f64.to_radians(),
            steps: 3,
            center: Some([0.25 * s + a[0], 0.1 * s + a[1]]),
            ..Default::default()
        };
        let (mut sw, _, first) = Sweep::new(&similar_ring(&r, a, s), &opts, sweep).unwrap();
        let mut frames = vec![first];
        for _ in 0..3 {
            frames.push(sw.next_frame().unwrap());
        }
        let rows: Vec<_> =
            frames.iter().map(|f| (f.report.verdict, f.report.newton_iterations, f.report.linear_solves)).collect();
        let maps: Vec<Surface> = frames.into_iter().map(|f| f.map).collect();
        let z: Vec<f64> = (0..maps.len()).map(|k| 1e9 * s + 0.05 * s * k as f64).collect();
        let l = loft(&maps, &z, &LoftOptions::default(), SliceBoundary::Interpolated).unwrap();
        let rounds: Vec<_> =
            l.report.rounds.iter().map(|r| (r.verdict, r.offending_elements, r.inserted_z.len())).collect();
        (rows, l.report.verdict, l.report.shape, rounds)
    };
    let orig = run([0.0, 0.0], 1.0);
    assert!(orig.0.iter().all(|f| f.0 == "certified"), "{orig:?}");
    for (a, s) in similarities(2.0) {
        assert_eq!(run(a, s), orig, "moved by {a:?}, scaled by {s:e}");
    }
}
