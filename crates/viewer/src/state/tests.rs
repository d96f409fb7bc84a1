//! Tests of [`ViewerState`](super::ViewerState): opening every document kind, solving, comparing, the views.

use super::*;
use crate::sampler::CpuSampler;
use winslow::solve::report::Verdict;

use winslow::testutil::data;

fn state() -> ViewerState {
    ViewerState::new(Arc::new(CpuSampler))
}

#[test]
fn opens_a_boundary_file() {
    let mut s = state();
    s.open(&data("quarter_annulus.json")).unwrap();
    let scene = s.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "boundary");
    assert!(scene.map.is_none());
    assert!(scene.boundary.problem.is_none(), "{:?}", scene.boundary.problem);
    // corners agree: south ends where east starts
    let (s_end, e_start) = (scene.boundary.polylines[0].last().unwrap(), scene.boundary.polylines[1][0]);
    assert!((s_end[0] - e_start[0]).abs() < 1e-9 && (s_end[1] - e_start[1]).abs() < 1e-9);
    assert!(s.can_solve());
    assert!(s.refit);
    assert!(s.colour_scale().is_none());
}

#[test]
fn bad_files_keep_the_scene_and_report() {
    let mut s = state();
    s.open(&data("quarter_annulus.json")).unwrap();
    let err = s.open(Path::new("/nonexistent/winslow/x.json")).unwrap_err();
    assert!(err.contains("x.json"), "{err}");
    assert_eq!(s.status.as_deref(), Some(err.as_str()));
    assert_eq!(s.scene.as_ref().unwrap().name, "quarter_annulus");
}

#[test]
fn solve_then_map_round_trip_through_a_file() {
    let mut s = state();
    s.open(&data("quarter_annulus.json")).unwrap();
    s.solve.min_elements = 4;
    assert!(s.start_solve(|| {}));
    assert!(s.solving() && !s.can_solve());
    s.wait_for_solve();
    assert!(!s.solving());
    let mv = s.scene.as_ref().unwrap().map.as_ref().unwrap();
    assert_eq!(mv.certificate.verdict, Verdict::Certified);
    assert!(mv.folds.is_empty());
    assert!(mv.quality.det_j_min > 0.0);
    // quarter annulus 1 <= r <= 2 (up to the fit): area 3 pi / 4
    assert!((mv.quality.functionals.area - 0.75 * std::f64::consts::PI).abs() < 1e-3);
    // the heat map's scale spans the sample
    let scale = s.colour_scale().unwrap();
    assert_eq!(scale.hi, mv.quality.det_j_max);

    // write the map as the CLI does and open it: same map, the stored verdict
    let report = serde_json::to_value(mv.report.as_ref().unwrap()).unwrap();
    let doc = winslow::io::map_to_json("qa", &mv.map, Some(serde_json::json!({ "report": report })));
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let path = dir.join("qa.json");
    winslow::io::write_json(&path, &doc).unwrap();
    let mut t = state();
    t.open(&path).unwrap();
    let scene = t.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "map");
    let mv2 = scene.map.as_ref().unwrap();
    assert_eq!(mv2.map, mv.map);
    assert_eq!(mv2.certificate.source, crate::certificate::CertificateSource::File);
    assert_eq!(mv2.certificate.verdict, Verdict::Certified);
    assert_eq!(mv2.exact_certificate.verdict, Verdict::Certified);

    // probes: parameter -> physical -> parameter
    for q in [[0.25, 0.75], [0.5, 0.5], [0.9, 0.1]] {
        let p = t.probe_parameter(q).unwrap();
        let back = t.probe_physical(p.point);
        let r = back.param.unwrap();
        assert!((r[0] - q[0]).abs() < 1e-8 && (r[1] - q[1]).abs() < 1e-8, "{r:?} {q:?}");
        assert!((back.det_j.unwrap() - p.det_j.unwrap()).abs() <= 1e-9 * p.det_j.unwrap().abs());
    }
    // the hole of the annulus is outside the map
    let hole = t.probe_physical([0.3, 0.3]);
    assert!(hole.param.is_none() && hole.det_j.is_none());
    assert!(hole.text().contains("outside"));
    assert!(t.probe_parameter([1.5, 0.5]).is_none());

    // changing the resolution resamples; the stored verdict stays
    let mut settings = t.settings;
    settings.resolution = Some(40);
    settings.density = 4;
    t.set_settings(settings);
    let mv3 = t.scene.as_ref().unwrap().map.as_ref().unwrap();
    assert_eq!(mv3.resolution(), 40);
    assert_eq!(mv3.sample.values.len(), 41 * 41);
    assert_eq!(mv3.iso.xi.len(), 3);
    assert_eq!(mv3.certificate.source, crate::certificate::CertificateSource::File);
}

#[test]
fn opens_a_gismo_patch_as_a_map() {
    let mut s = state();
    s.open(&data("gismo/xml/disk.xml")).unwrap();
    let scene = s.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "map");
    let mv = scene.map.as_ref().unwrap();
    // the sample is the core's, on the chosen grid, and the verdict is the core's exact
    // certificate: G+Smo's disk has four 180-degree corners
    let n = mv.resolution();
    assert_eq!(mv.sample.values.len(), (n + 1) * (n + 1));
    assert_eq!(mv.certificate.source, crate::certificate::CertificateSource::Exact);
    assert_eq!(mv.certificate.verdict, winslow::solve::report::Verdict::DegenerateCorner, "{}", mv.certificate.message);
    assert_eq!(mv.quality.det_j_min, mv.sample.min);
    // the map's own boundary can be solved again
    assert_eq!(scene.boundary.problem.is_none(), s.can_solve());
}

#[test]
fn opens_a_multipatch_file_with_all_patches() {
    let mut s = state();
    s.open(&data("gismo/xml/multipatch/TUDflame.xml")).unwrap();
    let scene = s.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "multipatch");
    assert_eq!(scene.maps().count(), 5);
    // the view spans every patch, the colour scale every patch's samples
    let b = scene.bounds();
    for mv in scene.maps() {
        assert!(mv.bounds[0][0] >= b[0][0] && mv.bounds[1][1] <= b[1][1]);
    }
    let hi = scene.maps().map(|m| m.quality.det_j_max).fold(0.0, f64::max);
    assert_eq!(s.colour_scale().unwrap().hi, hi);
    for mv in scene.maps() {
        assert!(mv.quality.det_j_max > 0.0 && mv.sample.values.len() == (mv.resolution() + 1).pow(2));
    }
    // G+Smo's patches are the input's maps: the layout solves from their sides
    let l = scene.layout.as_ref().expect("a layout to solve");
    assert_eq!(l.layout.patches.len(), 5);
    assert!(s.can_solve() && !s.can_compare());
    s.solve.min_elements = 4;
    assert!(s.start_solve(|| {}));
    s.wait_for_solve();
    let sum: f64 = s.scene.as_ref().unwrap().maps().map(|m| m.quality.functionals.area).sum();
    assert_eq!(check_solved_layout(&s, sum), 5);
    let area0: f64 = l_area(&data("gismo/xml/multipatch/TUDflame.xml"));
    assert!((sum - area0).abs() <= 1e-6 * area0, "{sum} vs {area0}");
}

/// The area of the maps of a multipatch file (exact quadrature of the core).
fn l_area(path: &Path) -> f64 {
    let mut t = state();
    t.open(path).unwrap();
    t.scene.as_ref().unwrap().maps().map(|m| m.quality.functionals.area).sum()
}

/// Every patch of a solved layout is drawn with its certificate, the patches cover the
/// area `area` and the irregular vertices stay; returns the number of patches drawn.
fn check_solved_layout(s: &ViewerState, area: f64) -> usize {
    let scene = s.scene.as_ref().unwrap();
    let l = scene.layout.as_ref().expect("the layout stays");
    let solved = l.solved.as_ref().expect("the layout's report");
    assert_eq!(solved.verdicts.len(), l.layout.patches.len());
    let maps: Vec<&crate::scene::MapView> = scene.maps().collect();
    assert_eq!(maps.len(), l.layout.patches.len());
    for (mv, v) in maps.iter().zip(&solved.verdicts) {
        assert_eq!(mv.certificate.verdict, *v);
        assert_eq!(mv.certificate.verdict, Verdict::Certified, "{}", mv.certificate.message);
        assert!(mv.quality.det_j_min > 0.0);
        assert_eq!(mv.sample.values.len(), (mv.resolution() + 1).pow(2));
    }
    // conforming interfaces, one colour scale over every patch
    assert_eq!(solved.interface_mismatch, 0.0);
    let hi = maps.iter().map(|m| m.sample.max).fold(0.0, f64::max);
    assert_eq!(s.colour_scale().unwrap().hi, hi);
    // the patches cover the domain: their areas (quadrature) sum to its area (polylines)
    let sum: f64 = maps.iter().map(|m| m.quality.functionals.area).sum();
    assert!((sum - area).abs() <= 1e-3 * area, "{sum} vs {area}");
    maps.len()
}

/// A `domain` document opens as its automatic layout (the core's, patch for patch,
/// with the same irregular vertices), solves in the background job as a layout and
/// shows every patch certified on one colour scale.
#[test]
fn opens_lays_out_and_solves_a_domain() {
    let path = data("domains/pentagon.json");
    let winslow::Document::Domain(d) = winslow::read(&path).unwrap() else { panic!("not a domain") };
    let auto = winslow::domain::auto_layout(&d, &Default::default()).unwrap();
    let mut s = state();
    s.open(&path).unwrap();
    let scene = s.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "domain");
    assert!(scene.map.is_none());
    let l = scene.layout.as_ref().unwrap();
    assert_eq!(l.layout.patches.len(), auto.layout.patches.len());
    assert_eq!(l.borders.len(), auto.layout.patches.len());
    // a pentagon: five quads around one vertex of valence 5
    assert_eq!(auto.report.irregular_vertices.len(), 1);
    assert_eq!(l.irregular().len(), 1);
    for (a, b) in l.irregular().iter().zip(&auto.report.irregular_vertices) {
        assert_eq!((a.point, a.valence), (b.point, b.valence));
    }
    assert_eq!(l.irregular()[0].valence, 5);
    // the outline is the five sides, each split at its midpoint: ten patch sides
    assert_eq!(l.outline.len(), 10);
    let b = scene.bounds();
    for p in l.outline.iter().flatten() {
        assert!(p[0] >= b[0][0] && p[0] <= b[1][0] && p[1] >= b[0][1] && p[1] <= b[1][1]);
    }
    assert!(s.can_solve() && !s.can_compare());
    s.solve.min_elements = 4;
    assert!(s.start_solve(|| {}));
    assert!(s.solving() && !s.can_solve());
    s.wait_for_solve();
    assert_eq!(check_solved_layout(&s, auto.report.area), 5);
    assert!(s.status.as_deref().unwrap().starts_with("solved"), "{:?}", s.status);
    assert_eq!(s.scene.as_ref().unwrap().layout.as_ref().unwrap().irregular().len(), 1);
    // a new resolution resamples every patch and keeps the solver's verdicts
    let mut settings = s.settings;
    settings.resolution = Some(24);
    s.set_settings(settings);
    for mv in s.scene.as_ref().unwrap().maps() {
        assert_eq!(mv.resolution(), 24);
        assert_eq!(mv.certificate.source, crate::certificate::CertificateSource::Solver);
    }
}

/// A `graph` document: a square cut by its diagonal into two triangles, each three
/// quads around a vertex of valence 3; a layout error goes to the status line.
#[test]
fn opens_lays_out_and_solves_a_graph() {
    let scratch = tempfile::tempdir().unwrap();
    let path = scratch.path().join("square.json");
    let doc = serde_json::json!({ "name": "square", "graph": {
        "vertices": [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        "edges": [{ "from": 0, "to": 1 }, { "from": 1, "to": 2 }, { "from": 2, "to": 3 }, { "from": 3, "to": 0 }, { "from": 0, "to": 2 }],
        "labels": [{ "name": "lower", "point": [0.7, 0.2] }, { "name": "upper", "point": [0.2, 0.7] }] } });
    winslow::io::file::write_bytes(&path, serde_json::to_vec(&doc).unwrap().as_slice()).unwrap();
    let winslow::Document::Graph(g) = winslow::read(&path).unwrap() else { panic!("not a graph") };
    let auto = winslow::domain::graph_layout(&g, &Default::default()).unwrap();
    let mut s = state();
    s.open(&path).unwrap();
    let scene = s.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "graph");
    let l = scene.layout.as_ref().unwrap();
    assert_eq!(l.layout.patches.len(), 6);
    assert_eq!(auto.layout.patches.len(), 6);
    let valences: Vec<usize> = l.irregular().iter().map(|v| v.valence).collect();
    assert_eq!(valences, auto.report.irregular_vertices.iter().map(|v| v.valence).collect::<Vec<_>>());
    assert_eq!(valences, [3, 3]);
    // the patches name their faces
    let faces: Vec<&str> = l.layout.patches.iter().filter_map(|p| p.face.as_deref()).collect();
    assert_eq!(faces.iter().filter(|&&f| f == "lower").count(), 3);
    assert_eq!(faces.iter().filter(|&&f| f == "upper").count(), 3);
    s.solve.min_elements = 4;
    assert!(s.start_solve(|| {}));
    s.wait_for_solve();
    assert_eq!(check_solved_layout(&s, 1.0), 6);

    // a dangling edge: the core's typed error on the status line, the scene stays
    let bad = scratch.path().join("bad.json");
    let doc = serde_json::json!({ "graph": {
        "vertices": [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [2.0, 2.0]],
        "edges": [{ "from": 0, "to": 1 }, { "from": 1, "to": 2 }, { "from": 2, "to": 3 }, { "from": 3, "to": 0 }, { "from": 2, "to": 4 }] } });
    winslow::io::file::write_bytes(&bad, serde_json::to_vec(&doc).unwrap().as_slice()).unwrap();
    let e = s.open(&bad).unwrap_err();
    assert_eq!(s.status.as_deref(), Some(e.as_str()));
    assert!(e.contains("bad.json") && e.contains("edge 4") && e.contains("dangles"), "{e}");
    assert_eq!(s.scene.as_ref().unwrap().kind, "graph");
}

/// The bundled motor-like section (a plane graph of many faces) opens as the core's
/// layout: the same patches, faces and irregular vertices.
#[test]
fn opens_the_bundled_motor_graph() {
    let path = data("domains/motor12.json");
    let winslow::Document::Graph(g) = winslow::read(&path).unwrap() else { panic!("not a graph") };
    let auto = winslow::domain::graph_layout(&g, &Default::default()).unwrap();
    let mut s = state();
    s.open(&path).unwrap();
    let scene = s.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "graph");
    let l = scene.layout.as_ref().unwrap();
    assert_eq!(l.layout.patches.len(), auto.layout.patches.len());
    let faces = |l: &winslow::multipatch::Layout| l.patches.iter().map(|p| p.face.clone()).collect::<Vec<_>>();
    assert_eq!(faces(&l.layout), faces(&auto.layout));
    let irregular =
        |v: &[winslow::domain::template::IrregularVertex]| v.iter().map(|v| (v.point, v.valence)).collect::<Vec<_>>();
    assert_eq!(irregular(l.irregular()), irregular(&auto.report.irregular_vertices));
    assert!(s.can_solve());
}

/// A multipatch layout of boundaries (G+Smo's plate with a hole, as JSON) opens as a
/// layout to solve and solves like a domain's layout.
#[test]
fn opens_and_solves_a_layout_of_boundaries() {
    let scratch = tempfile::tempdir().unwrap();
    let winslow::Document::Layout(layout) = winslow::read(&data("gismo/xml/multipatch/plateWithHoleMP.xml")).unwrap()
    else {
        panic!("not a layout")
    };
    let path = scratch.path().join("input.json");
    winslow::write(&path, &winslow::Output::Layout(&layout)).unwrap();
    let mut s = state();
    s.open(&path).unwrap();
    let scene = s.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "layout");
    let l = scene.layout.as_ref().unwrap();
    assert_eq!(l.layout.patches.len(), layout.patches.len());
    assert!(l.irregular().is_empty() && l.report.is_none());
    // the outline is every side on no interface
    let inner = 2 * layout.interfaces.len();
    assert_eq!(l.outline.len(), 4 * layout.patches.len() - inner);
    assert!(s.can_solve() && !s.can_compare());
    s.solve.min_elements = 4;
    assert!(s.start_solve(|| {}));
    s.wait_for_solve();
    let sum: f64 = s.scene.as_ref().unwrap().maps().map(|m| m.quality.functionals.area).sum();
    assert_eq!(check_solved_layout(&s, sum), layout.patches.len());
}

#[test]
fn views_fit_the_scene() {
    let mut s = state();
    s.open(&data("quarter_annulus.json")).unwrap();
    s.fit_views(Vec2::new(400.0, 300.0), Vec2::new(200.0, 200.0));
    assert!(!s.refit);
    // the quarter annulus spans [0, 2]^2: 270 px for 2 units
    assert!((s.physical.scale - 135.0).abs() < 0.1, "{}", s.physical.scale);
    assert!((s.parameter.scale - 176.0).abs() < 1e-6);
}

/// A ring document (paper §11.1) opens as its two contours and solves as a ring; the
/// map written as the CLI does reopens as a "ring map" with `eta` periodic, its det J
/// sampled across the seam and certified; an invalid ring shows its problem.
#[test]
fn opens_and_solves_a_ring() {
    let mut s = state();
    s.open(&data("rings/eccentric_annulus.json")).unwrap();
    let scene = s.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "ring");
    assert!(scene.ring.is_some() && scene.map.is_none());
    assert!(scene.boundary.problem.is_none(), "{:?}", scene.boundary.problem);
    // west is the inner circle r = 0.4 about (0.25, 0.1), closed
    let west = &scene.boundary.polylines[3];
    assert_eq!(west.first(), west.last());
    assert!(west.iter().all(|p| ((p[0] - 0.25).hypot(p[1] - 0.1) - 0.4).abs() < 1e-6));
    assert!(s.start_solve(|| {}));
    s.wait_for_solve();
    let mv = s.scene.as_ref().unwrap().map.as_ref().unwrap();
    assert!(mv.map.knots[1].is_periodic());
    assert_eq!(mv.certificate.verdict, Verdict::Certified, "{}", mv.certificate.message);
    // area of the ring pi (1 - 0.16), up to the fit
    assert!((mv.quality.functionals.area - std::f64::consts::PI * 0.84).abs() < 1e-3);
    assert!(mv.quality.det_j_min > 0.0);

    let doc = winslow::io::map_to_json("ecc", &mv.map, None);
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    winslow::io::write_json(&dir.join("ecc.json"), &doc).unwrap();
    let mut t = state();
    t.open(&dir.join("ecc.json")).unwrap();
    let scene = t.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "ring map");
    let mv2 = scene.map.as_ref().unwrap();
    assert_eq!(mv2.exact_certificate.verdict, Verdict::Certified);
    assert_eq!(mv2.sample.min, mv.sample.min);
    // the seam rows eta = 0 and eta = 1 of the sample agree (the map is periodic)
    let n = mv2.resolution();
    for i in 0..=n {
        let (a, b) = (mv2.sample.values[i], mv2.sample.values[n * (n + 1) + i]);
        assert!((a - b).abs() <= 1e-9 * a.abs(), "{i}: {a} vs {b}");
    }
    // solving the reopened map solves its ring again
    assert!(t.can_solve() && t.start_solve(|| {}));
    t.wait_for_solve();
    assert!(t.scene.as_ref().unwrap().map.as_ref().unwrap().map.knots[1].is_periodic());
    let bad = dir.join("bad.json");
    let text = r#"{"ring": {"inner": {"points": [[0,0],[2,0],[2,2],[0,2]]}, "outer": {"points": [[0.5,0.5],[1,0.5],[1,1],[0.5,1]]}}}"#;
    winslow::io::file::write_bytes(&bad, text.as_bytes()).unwrap();
    t.open(&bad).unwrap();
    let p = t.scene.as_ref().unwrap().boundary.problem.clone().unwrap();
    assert!(p.contains("not inside") && !t.can_solve(), "{p}");
}

/// A curved volume of degrees (2, 2, 1) with `det J > 0`, rational when `weights`.
fn curved_volume(rational: bool) -> winslow::spline::volume::Volume {
    use winslow::spline::knots::KnotVector;
    let k = [KnotVector::open_uniform(2, 2), KnotVector::open_uniform(2, 1), KnotVector::open_uniform(1, 2)];
    let shape = k.each_ref().map(KnotVector::num_basis);
    let n: usize = shape.iter().product();
    let cps = (0..n)
        .map(|q| {
            let (i, j, l) =
                ((q % shape[0]) as f64, (q / shape[0] % shape[1]) as f64, (q / (shape[0] * shape[1])) as f64);
            [i + 0.1 * j * l, j + 0.05 * i * i, 0.8 * l + 0.1 * i]
        })
        .collect();
    let w = rational.then(|| (0..n).map(|q| 1.0 + 0.2 * ((q * 5) % 3) as f64).collect());
    winslow::spline::volume::Volume::new(k, cps, w).unwrap()
}

/// A volume file opens as three slices; each slice's surface and samples are the volume
/// at the slice parameter (B-spline and NURBS), its heat map the volume's `det J`
/// there; moving a slider moves the slice; opening a map afterwards drops the volume.
#[test]
fn a_volume_opens_as_three_slices_of_the_volume() {
    let scratch = tempfile::tempdir().unwrap();
    for rational in [false, true] {
        let vol = curved_volume(rational);
        let path = scratch.path().join(format!("vol-{rational}.json"));
        let out = winslow::Output::Volume { name: "vol", volume: &vol, label: "", extra: None };
        winslow::write(&path, &out).unwrap();
        let mut s = state();
        s.open(&path).unwrap();
        assert!(s.scene.is_none());
        let v = s.volume.as_ref().unwrap();
        assert_eq!(v.verdict(), v.certificate.as_ref().unwrap().message());
        assert!(matches!(
            v.certificate.as_ref().unwrap().verdict,
            winslow::verify::certificate::volume::VolumeFinding::Certified { .. }
        ));
        let check = |s: &ViewerState, dir: usize, at: f64| {
            let v = s.volume.as_ref().unwrap();
            let slice = &v.slices[dir];
            assert_eq!((slice.dir, slice.at), (dir, at));
            let free = crate::volume_view::free_directions(dir);
            let at_u = |a: f64, b: f64| {
                let mut u = [at; 3];
                u[free[0]] = a;
                u[free[1]] = b;
                u
            };
            // the spline surface between the samples
            for &(a, b) in &[(0.13, 0.71), (0.5, 0.5), (0.97, 0.02), (0.0, 1.0)] {
                let (p, q) = (slice.surface.eval(a, b), v.volume.eval(at_u(a, b)));
                assert!((0..3).all(|c| (p[c] - q[c]).abs() < 1e-12), "{dir} {at} ({a}, {b}): {p:?} {q:?}");
            }
            // the samples and their det J
            let n = slice.n;
            assert_eq!(slice.points.len(), (n + 1) * (n + 1));
            for k in [0, 7, n * (n + 1) / 2, (n + 1) * (n + 1) - 1] {
                let (a, b) = ((k % (n + 1)) as f64 / n as f64, (k / (n + 1)) as f64 / n as f64);
                let q = v.volume.eval(at_u(a, b));
                assert!((0..3).all(|c| (slice.points[k][c] - q[c]).abs() < 1e-12));
                let d = v.volume.derivs(at_u(a, b)).det_j();
                assert!((slice.det_j[k] - d).abs() <= 1e-12 * d.abs());
                assert!(d > 0.0);
            }
        };
        for dir in 0..3 {
            check(&s, dir, 0.5);
        }
        assert!(s.set_volume_slice(1, 0.25) && !s.set_volume_slice(1, 0.25));
        assert!(s.set_volume_slice(2, 1.0) && s.set_volume_slice(0, 0.0));
        check(&s, 1, 0.25);
        check(&s, 2, 1.0);
        check(&s, 0, 0.0);
        // one colour scale over the three slices
        let scale = s.colour_scale().unwrap();
        let v = s.volume.as_ref().unwrap();
        let hi = v.slices.iter().flat_map(|s| s.det_j.iter().copied()).fold(0.0, f64::max);
        assert_eq!(scale.hi, hi);
        s.open(&data("quarter_annulus.json")).unwrap();
        assert!(s.volume.is_none() && s.scene.is_some() && !s.set_volume_slice(0, 0.3));
    }
}
