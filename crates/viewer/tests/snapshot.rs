//! Headless snapshots of the viewer's main views, rendered by egui_kittest through wgpu
//! (lavapipe on a machine without a GPU; run with `WGPU_BACKEND=vulkan`). Update the
//! images after an intended change with `UPDATE_SNAPSHOTS=1`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use egui::Vec2;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use winslow::io::Document;
use winslow::testutil::data;
use winslow_viewer::scene::Scene;
use winslow_viewer::state::ViewKind;
use winslow_viewer::{CpuSampler, ViewerApp};

const SIZE: Vec2 = Vec2::new(1180.0, 720.0);

fn harness(app: ViewerApp) -> Harness<'static, ViewerApp> {
    Harness::builder().with_size(SIZE).wgpu().build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), app)
}

/// The wavy-lid boundary solved in the viewer's background job (a second or two).
fn solved_wavy_lid() -> ViewerApp {
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("wavy_lid.json")).unwrap();
    assert!(app.state.start_solve(|| {}));
    app.state.wait_for_solve();
    app
}

#[test]
fn map_view_snapshot() {
    let mut app = solved_wavy_lid();
    app.state.settings.density = 16;
    let mut h = harness(app);
    h.run();
    let mv = h.state().state.scene.as_ref().unwrap().map.as_ref().unwrap();
    assert!(mv.quality.det_j_min > 0.0, "{}", mv.certificate.message);
    h.snapshot("map_view");
}

#[test]
fn mesh_overlay_snapshot() {
    // the Fig. 31 kind of mesh (eq. 50 in eta) over the det J heat map, with its quality
    // table in the side panel
    let mut app = solved_wavy_lid();
    app.state.display.grid = false;
    app.state.mesh.settings.points = [41, 13];
    app.state.build_mesh().unwrap();
    let o = app.state.mesh.drawn(&app.state.scene.as_ref().unwrap().map.as_ref().unwrap().map).expect("built");
    assert_eq!(o.mesh.num_cells(), 40 * 12);
    assert_eq!(o.quality.inverted, 0);
    let mut h = harness(app);
    h.run();
    // the quality table is on the panel
    h.get_by_label("inverted cells");
    h.snapshot("mesh_overlay");
}

#[test]
fn folded_map_snapshot() {
    // the solved quarter annulus with one interior control point dragged across its
    // neighbours: the fold is painted magenta and listed
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("quarter_annulus.json")).unwrap();
    app.state.solve.min_elements = 4;
    app.state.start_solve(|| {});
    app.state.wait_for_solve();
    let scene = app.state.scene.as_ref().unwrap();
    let mut map = scene.map.as_ref().unwrap().map.clone();
    let nx = map.shape()[0];
    let k = 2 * nx + 2;
    let [x, y] = map.control_points[k];
    map.control_points[k] = [x + 0.9, y + 0.9];
    let folded =
        Scene::from_document(Document::Map { name: "folded".into(), map }, &CpuSampler, app.state.settings, None)
            .unwrap();
    app.state.set_scene(folded);
    app.state.display.net = true;
    app.state.selected_fold = Some(0);
    let mv = app.state.scene.as_ref().unwrap().map.as_ref().unwrap();
    assert!(!mv.folds.is_empty());
    assert_eq!(mv.certificate.verdict, winslow::solve::report::Verdict::Folded);
    let mut h = harness(app);
    h.run();
    h.snapshot("folded_map");
}

#[test]
fn ring_view_snapshot() {
    // the Fig. 16-like rotor in its casing (paper §11.1) solved as an O-grid: the
    // periodic map's det J heat map and grid, seam included
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("rings/rotor_lobes_in_circle.json")).unwrap();
    assert_eq!(app.state.scene.as_ref().unwrap().kind, "ring");
    app.state.solve.fit_tol = 1e-3;
    assert!(app.state.start_solve(|| {}));
    app.state.wait_for_solve();
    let mv = app.state.scene.as_ref().unwrap().map.as_ref().unwrap();
    assert!(mv.map.knots[1].is_periodic());
    assert_eq!(mv.certificate.verdict, winslow::solve::report::Verdict::Certified, "{}", mv.certificate.message);
    let mut h = harness(app);
    h.run();
    h.get_by_label("ring");
    h.snapshot("ring_view");
}

#[test]
fn boundary_view_snapshot() {
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("horseshoe.json")).unwrap();
    app.state.display.net = true;
    let mut h = harness(app);
    h.run();
    h.snapshot("boundary_view");
}

#[test]
fn hover_zoom_and_export() {
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("quarter_annulus.json")).unwrap();
    app.state.solve.min_elements = 4;
    app.state.start_solve(|| {});
    app.state.wait_for_solve();
    let mut h = harness(app);
    h.run();
    // hover the image of (xi, eta) = (0.5, 0.5) in the physical view
    let target = h.state().state.scene.as_ref().unwrap().map.as_ref().unwrap().probe([0.5, 0.5]).0;
    let phys_rect = h.state().last_physical_rect().expect("drawn");
    let pos = h.state().state.physical.to_screen(phys_rect, target);
    h.event(egui::Event::PointerMoved(pos));
    h.run();
    let probe = h.state().state.probe.expect("a probe under the pointer");
    assert_eq!(probe.view, ViewKind::Physical);
    let q = probe.param.expect("inside the map");
    // one pixel of slack in the pointer position
    assert!((q[0] - 0.5).abs() < 0.02 && (q[1] - 0.5).abs() < 0.02, "{q:?}");

    // scrolling zooms about the pointer: the world point under it stays put
    let before = h.state().state.physical;
    h.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: Vec2::new(0.0, 120.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Unknown,
        modifiers: Default::default(),
    });
    h.run();
    let after = h.state().state.physical;
    assert!(after.scale > before.scale, "{before:?} -> {after:?}");
    let (w0, w1) = (before.to_world(phys_rect, pos), after.to_world(phys_rect, pos));
    assert!((w0[0] - w1[0]).abs() < 1e-3 && (w0[1] - w1[1]).abs() < 1e-3);

    // export the views to a PNG through the integration's screenshot
    let scratch = tempfile::tempdir().unwrap();
    let path = scratch.path().join("export.png");
    h.state_mut().export_views(path.clone());
    h.run_steps(8);
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).expect("exported")));
    let info = dec.read_info().unwrap().info().clone();
    // the views are narrower than the window (side panel) and not taller
    assert!(info.width > 300 && (info.width as f32) < SIZE.x && (info.height as f32) < SIZE.y, "{info:?}");
}

/// A file dropped on the window, as an integration would hand it over.
#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn dropping_a_file_opens_it() {
    let mut h = Harness::builder()
        .with_size(SIZE)
        .build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), ViewerApp::new(Arc::new(CpuSampler)));
    h.run();
    assert!(h.state().state.scene.is_none());
    h.input_mut().dropped_files.push(Arc::new(Dropped(data("horseshoe.json"))));
    h.run();
    let scene = h.state().state.scene.as_ref().expect("opened");
    assert_eq!(scene.name, "horseshoe");
    assert_eq!(scene.kind, "boundary");
    // a file that is not a geometry leaves the scene and says why
    h.input_mut().dropped_files.push(Arc::new(Dropped(data("../fit.rs"))));
    h.run();
    assert_eq!(h.state().state.scene.as_ref().unwrap().name, "horseshoe");
    assert!(h.state().state.status.as_deref().unwrap_or_default().contains("fit.rs"));
}

#[test]
fn ctrl_f_fits_the_views_again() {
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("horseshoe.json")).unwrap();
    let mut h = Harness::builder().with_size(SIZE).build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), app);
    h.run();
    let fitted = h.state().state.physical;
    h.state_mut().state.physical.pan(Vec2::new(40.0, -25.0));
    h.state_mut().state.physical.scale *= 2.0;
    h.run();
    assert_ne!(h.state().state.physical, fitted);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::F);
    h.run();
    assert_eq!(h.state().state.physical, fitted);
}

#[test]
fn the_mesh_section_builds_the_overlay() {
    // the buttons of the side panel's Mesh section, clicked as a user would
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("quarter_annulus.json")).unwrap();
    app.state.solve.min_elements = 4;
    app.state.start_solve(|| {});
    app.state.wait_for_solve();
    // tall enough for the whole side panel: clicks land where the widgets are drawn
    let mut h = Harness::builder()
        .with_size(Vec2::new(SIZE.x, 2400.0))
        .build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), app);
    h.run();
    assert!(h.state().state.mesh.built.is_none());
    h.get_by_label("Build mesh").click();
    h.run();
    let o = h.state().state.mesh.built.as_ref().unwrap().as_ref().expect("a structured mesh");
    let [nx, ny] = h.state().state.mesh.settings.points;
    assert_eq!(o.mesh.num_cells(), (nx - 1) * (ny - 1));
    h.get_by_label("inverted cells");
    // unstructured: the button offers a build again (settings changed)
    h.get_by_label("unstructured").click();
    h.run();
    h.get_by_label("Build mesh").click();
    h.run();
    let o = h.state().state.mesh.built.as_ref().unwrap().as_ref().expect("a triangulation");
    assert_eq!(o.mesh.kind, winslow_mesh::ElementKind::Triangle);
    assert!(o.inverted.is_empty());
    // drawn over the current map only
    let map = h.state().state.scene.as_ref().unwrap().map.as_ref().unwrap().map.clone();
    assert!(h.state().state.mesh.drawn(&map).is_some());
}

#[test]
fn multipatch_view_snapshot() {
    // G+Smo's TUDflame: five patches drawn in the physical view on one det J scale
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("gismo/xml/multipatch/TUDflame.xml")).unwrap();
    let scene = app.state.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "multipatch");
    assert_eq!(scene.patches.len(), 4);
    let mut h = harness(app);
    h.run();
    h.snapshot("multipatch_view");
}

#[test]
fn domain_layout_snapshot() {
    // the bundled plate with holes laid out automatically: patch borders, the outline and
    // the irregular vertices marked with their valence, before the solve
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("domains/plate_holes.json")).unwrap();
    let scene = app.state.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "domain");
    assert!(scene.map.is_none());
    let l = scene.layout.as_ref().unwrap();
    assert!(!l.irregular().is_empty());
    let mut h = harness(app);
    h.run();
    h.get_by_label("faces and templates");
    h.snapshot("domain_layout");
}

#[test]
fn solved_domain_layout_snapshot() {
    // the same layout solved in the viewer's background job: every patch's det J on one
    // scale, the irregular vertices kept
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("domains/plate_holes.json")).unwrap();
    app.state.solve.min_elements = 4;
    assert!(app.state.start_solve(|| {}));
    app.state.wait_for_solve();
    let scene = app.state.scene.as_ref().unwrap();
    let l = scene.layout.as_ref().unwrap();
    assert_eq!(scene.maps().count(), l.layout.patches.len());
    assert!(scene.maps().all(|m| m.quality.det_j_min > 0.0));
    let mut h = harness(app);
    h.run();
    h.snapshot("solved_domain_layout");
}

#[test]
fn thb_map_snapshot() {
    // puzzle4 solved in the viewer with THB refinement (paper §8.2 on THB cells): the det J
    // heat map sampled on the active cells, the cells' borders in both views, the THB
    // certificate's verdict in the side panel
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("gismo/puzzle4.json")).unwrap();
    app.state.solve.refinement = winslow::solve::options::Refinement::Thb;
    assert!(app.state.start_solve(|| {}));
    app.state.wait_for_solve();
    let mv = app.state.scene.as_ref().unwrap().map.as_ref().unwrap();
    let thb = mv.thb.as_ref().expect("a THB map");
    assert!(thb.levels() > 1);
    assert_eq!(thb.cells.len(), thb.map.basis.active_cells().len());
    assert_eq!(mv.certificate.verdict, winslow::solve::report::Verdict::Certified, "{}", mv.certificate.message);
    assert_eq!(mv.exact_certificate.verdict, winslow::solve::report::Verdict::Certified);
    let mut h = harness(app);
    h.run();
    h.snapshot("thb_map");
}

#[test]
fn thb_control_net_snapshot() {
    // the bundled THB sector with the control net on: the net of its active functions
    // (segments between neighbours of one level), not the net of its tensor form
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("thb/sector_thb.json")).unwrap();
    app.state.display.net = true;
    let mv = app.state.scene.as_ref().unwrap().map.as_ref().unwrap();
    let thb = mv.thb.as_ref().expect("a THB map");
    // fewer points than the tensor form draws: the THB map's own control points
    assert!(thb.map.control_points.len() < mv.map.control_points.len());
    assert!(!thb.map.control_net().is_empty());
    let mut h = harness(app);
    h.run();
    h.snapshot("thb_control_net");
}

#[test]
fn a_thb_file_opens_with_its_cells_and_det_j() {
    // the bundled THB sector: the viewer's det J (its heat map's samples and the probe)
    // is the library's evaluation of the THB map
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("thb/sector_thb.json")).unwrap();
    let scene = app.state.scene.as_ref().unwrap();
    assert_eq!(scene.kind, "THB map");
    let Document::Thb { map, .. } = winslow::read(&data("thb/sector_thb.json")).unwrap() else { panic!("a THB map") };
    let mv = scene.map.as_ref().unwrap();
    let thb = mv.thb.as_ref().expect("drawn as a THB map");
    assert_eq!(thb.cells.len(), map.basis.active_cells().len());
    assert!(thb.levels() >= 2);
    let n = mv.sample.n;
    for (i, j) in [(0, 0), (1, n - 1), (n / 3, n / 2), (n - 2, 3), (n, n)] {
        let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
        let exact = map.derivs(u, v).det_j();
        let scale = exact.abs().max(1e-300);
        assert!((mv.sample.values[j * (n + 1) + i] - exact).abs() <= 1e-12 * scale, "({u}, {v})");
        assert!((mv.probe([u, v]).1 - exact).abs() <= 1e-12 * scale);
    }
    // the verdict is the THB certificate's
    let c = winslow::verify::certificate::hierarchical::certify_hierarchical(&map, &Default::default()).unwrap();
    assert_eq!(mv.exact_certificate.verdict, winslow::solve::report::Verdict::of_finding(&c.verdict));
    // the settings change draws it again, still as a THB map
    app.state.set_settings(winslow_viewer::scene::SceneSettings { resolution: Some(40), density: 8 });
    let mv = app.state.scene.as_ref().unwrap().map.as_ref().unwrap();
    assert!(mv.thb.is_some());
    assert_eq!(mv.sample.n, 40);
}
