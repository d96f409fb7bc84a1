//! The comparison of methods in the viewer (paper §10): the side panel's "Compare
//! methods" runs EGG, the variational harmonic method and the quasi-conformal functional
//! in the background job, and the "Methods" section switches the views between their
//! maps, as a user clicks them (egui_kittest, no GPU needed).

use std::sync::Arc;

use egui::Vec2;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use winslow::testutil::data;
use winslow_viewer::{CpuSampler, ViewerApp};

#[test]
fn compare_button_runs_the_methods_and_the_selector_switches_maps() {
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("quarter_annulus.json")).unwrap();
    app.state.solve.min_elements = 4;
    // tall enough for the whole side panel: clicks land where the widgets are drawn
    let mut h = Harness::builder()
        .with_size(Vec2::new(1180.0, 2400.0))
        .build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), app);
    h.run();
    assert!(h.state().state.comparison.is_none());
    h.get_by_label("Compare methods").click();
    // one frame starts the job (the spinner then repaints until it ends)
    h.step();
    assert!(h.state().state.solving());
    h.state_mut().state.wait_for_solve();
    h.run();
    let state = &h.state().state;
    let cmp = state.comparison.as_ref().expect("a comparison");
    let names: Vec<&str> = cmp.rows.iter().map(|r| r.method.as_str()).collect();
    assert_eq!(names, ["egg", "vhm", "qc"]);
    // the EGG map is shown first
    assert_eq!(state.selected_method, Some(0));
    let shown = |h: &Harness<'_, ViewerApp>| h.state().state.scene.as_ref().unwrap().map.as_ref().unwrap().map.clone();
    assert_eq!(&shown(&h), cmp.rows[0].map.as_ref().unwrap());
    // every row's verdict is the certificate's; the quarter annulus certifies for all
    for r in &cmp.rows {
        assert_eq!(r.bij(), "certified", "{}: {:?}", r.method, r.failure);
    }
    let (qc_map, vhm_map) = (cmp.rows[2].map.clone().unwrap(), cmp.rows[1].map.clone().unwrap());
    assert_ne!(qc_map, vhm_map, "two methods, two maps");
    // click the quasi-conformal method: its map is drawn, with its own exact certificate
    h.get_by_label("qc").click();
    h.run();
    assert_eq!(h.state().state.selected_method, Some(2));
    assert_eq!(shown(&h), qc_map);
    let mv = h.state().state.scene.as_ref().unwrap().map.as_ref().unwrap();
    assert_eq!(mv.certificate.source, winslow_viewer::certificate::CertificateSource::Exact);
    assert!(mv.report.is_none());
    h.get_by_label("vhm").click();
    h.run();
    assert_eq!(shown(&h), vhm_map);
    // a plain solve replaces the comparison
    h.get_by_role_and_label(egui::Role::Button, "Solve").click();
    h.step();
    h.state_mut().state.wait_for_solve();
    h.run();
    assert!(h.state().state.comparison.is_none());
    assert!(h.state().state.scene.as_ref().unwrap().map.as_ref().unwrap().report.is_some());
}

/// The "with Gravesen's" box adds max-z and the constrained optimisations from `x_G`
/// (on the fitted B-spline basis), and the selector shows their maps like any other row.
#[test]
fn gravesens_methods_join_the_comparison_when_ticked() {
    let mut app = ViewerApp::new(Arc::new(CpuSampler));
    app.state.open(&data("quarter_annulus.json")).unwrap();
    app.state.solve.min_elements = 4;
    app.state.solve.fit_tol = 1e-2;
    app.state.solve.basis = winslow::boundary::BasisChoice::Fitted;
    let mut h = Harness::builder()
        .with_size(Vec2::new(1180.0, 2400.0))
        .build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), app);
    h.run();
    h.get_by_label("with Gravesen's").click();
    h.run();
    assert!(h.state().state.compare_gravesen);
    h.get_by_label("Compare methods").click();
    h.step();
    h.state_mut().state.wait_for_solve();
    h.run();
    let cmp = h.state().state.comparison.clone().expect("a comparison");
    let names: Vec<&str> = cmp.rows.iter().map(|r| r.method.as_str()).collect();
    assert_eq!(names, ["egg", "vhm", "qc", "maxz", "liao", "winslow", "ao"]);
    for r in &cmp.rows {
        assert_eq!(r.bij(), "certified", "{}: {:?}", r.method, r.failure);
    }
    h.get_by_label("liao").click();
    h.run();
    assert_eq!(h.state().state.selected_method, Some(4));
    let shown = h.state().state.scene.as_ref().unwrap().map.as_ref().unwrap().map.clone();
    assert_eq!(&shown, cmp.rows[4].map.as_ref().unwrap());
}
