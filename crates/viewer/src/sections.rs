//! The side panel's read-only sections: the file, the verdict, the map's quality
//! numbers, the folded-element list, the residual plot of a solve and a multipatch
//! layout's patches, templates and irregular vertices.

use egui::{Color32, RichText, Ui};
use egui_plot::{Line, Plot, PlotPoints};

use crate::certificate::{verdict_is_good, Certificate};
use crate::layout_view::LayoutView;
use crate::scene::{MapView, Scene};

/// Folded elements listed at most.
const MAX_LISTED_FOLDS: usize = 200;

/// A collapsible section of the side panel, open by default.
pub(crate) fn section(ui: &mut Ui, title: &str, body: impl FnOnce(&mut Ui)) {
    egui::CollapsingHeader::new(RichText::new(title).heading()).default_open(true).show(ui, body);
}

pub(crate) fn file_section(ui: &mut Ui, scene: &Scene) {
    ui.heading(&scene.name);
    egui::Grid::new("file").num_columns(2).show(ui, |ui| {
        ui.label("kind");
        ui.label(scene.kind);
        ui.end_row();
        if let Some(p) = &scene.path {
            ui.label("file");
            let name = p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned());
            ui.label(name).on_hover_text(p.display().to_string());
            ui.end_row();
        }
        if let Some(mv) = &scene.map {
            let [p, q] = mv.map.degrees();
            let [nx, ny] = mv.map.shape();
            ui.label("map");
            match &mv.thb {
                Some(t) => ui.label(format!(
                    "THB, p = ({p}, {q}), {} functions,\n{} active cells of {} levels\n(tensor form {nx}x{ny})",
                    t.map.basis.len(),
                    t.cells.len(),
                    t.levels()
                )),
                None => ui.label(format!(
                    "p = ({p}, {q}), {nx}x{ny} control points,\n{}x{} elements{}",
                    mv.map.knots[0].num_elements(),
                    mv.map.knots[1].num_elements(),
                    if mv.map.weights.is_some() { ", rational" } else { "" }
                )),
            };
            ui.end_row();
        }
    });
    if scene.layout.is_some() {
        // a layout's patches are in its own section
        return;
    }
    egui::CollapsingHeader::new("boundary sides").default_open(scene.map.is_none()).show(ui, |ui| {
        for (s, side) in winslow::Side::ALL.iter().zip(&scene.boundary.boundary.sides) {
            ui.label(format!("{s}: {}", side.describe()));
        }
        if scene.boundary.reoriented {
            ui.label("the contour was clockwise: transposed to counter-clockwise");
        }
    });
    if let Some(p) = &scene.boundary.problem {
        ui.colored_label(Color32::from_rgb(200, 40, 40), p);
    }
}

/// A multipatch layout: patches and interfaces; for an automatic layout its cuts, the
/// template of every face and the irregular vertices with their valence; once solved,
/// the verdicts over the patches.
pub(crate) fn layout_section(ui: &mut Ui, view: &LayoutView) {
    let l = &view.layout;
    egui::Grid::new("layout").num_columns(2).show(ui, |ui| {
        ui.label("patches");
        ui.label(l.patches.len().to_string());
        ui.end_row();
        ui.label("interfaces");
        ui.label(l.interfaces.len().to_string());
        ui.end_row();
        if let Some(r) = &view.report {
            ui.label("area");
            ui.label(format!("{:.6}", r.area));
            ui.end_row();
            ui.label("cuts");
            ui.label(format!("{} from holes, {} from reflex corners", r.hole_cuts.len(), r.cuts.len()));
            ui.end_row();
            ui.label("corner angles");
            ui.label(format!("{:.1} to {:.1} degrees", r.corner_angles[0], r.corner_angles[1]));
            ui.end_row();
            ui.label("irregular vertices");
            ui.label(r.irregular_vertices.len().to_string());
            ui.end_row();
        }
    });
    if let Some(r) = &view.report {
        egui::CollapsingHeader::new("faces and templates").default_open(false).show(ui, |ui| {
            for f in &r.faces {
                ui.label(format!("{} ({} corners): {}, {} patches", f.label, f.corners, f.template, f.patches));
            }
        });
        egui::CollapsingHeader::new("irregular vertices").default_open(true).show(ui, |ui| {
            for v in &r.irregular_vertices {
                ui.label(format!("valence {} at ({:.5}, {:.5})", v.valence, v.point[0], v.point[1]));
            }
        });
    }
    if let Some(s) = &view.solved {
        let good = s.verdicts.iter().filter(|&&v| verdict_is_good(v)).count();
        let colour =
            if verdict_is_good(s.verdict) { Color32::from_rgb(20, 130, 40) } else { Color32::from_rgb(200, 40, 40) };
        ui.colored_label(
            colour,
            format!("{good} of {} patches certified; worst: {}", s.verdicts.len(), s.verdict.name()),
        );
        ui.label(format!("interface mismatch {:.2e}", s.interface_mismatch));
        ui.label(&s.message);
    }
}

pub(crate) fn verdict_colour(c: &Certificate) -> Color32 {
    match c.verdict {
        winslow::solve::report::Verdict::Certified => Color32::from_rgb(20, 140, 50),
        winslow::solve::report::Verdict::DegenerateCorner => Color32::from_rgb(190, 130, 0),
        _ => Color32::from_rgb(200, 30, 30),
    }
}

/// The verdict, in one place: the solver's or the stored report, and the exact certificate.
pub(crate) fn certificate_section(ui: &mut Ui, mv: &MapView) {
    let c = &mv.certificate;
    ui.label(
        RichText::new(format!("{} {}", if verdict_is_good(c.verdict) { "OK:" } else { "BAD:" }, c.verdict.name()))
            .color(verdict_colour(c))
            .strong()
            .size(16.0),
    );
    ui.label(&c.message);
    ui.label(RichText::new(format!("from the {}", c.source.label())).weak());
    if !c.details.is_empty() {
        egui::Grid::new("cert-details").num_columns(2).show(ui, |ui| {
            for (k, v) in &c.details {
                ui.label(k);
                ui.label(v);
                ui.end_row();
            }
        });
    }
    if c.source != mv.exact_certificate.source {
        let s = &mv.exact_certificate;
        ui.label(
            RichText::new(format!("exact certificate: {} ({})", s.verdict.name(), s.message)).color(verdict_colour(s)),
        );
    }
}

pub(crate) fn quality_section(ui: &mut Ui, mv: &MapView) {
    let q = &mv.quality;
    let f = &q.functionals;
    let grid = format!("{0}x{0}", q.sample_n + 1);
    egui::Grid::new("quality").num_columns(2).striped(true).show(ui, |ui| {
        let mut row = |k: &str, v: String| {
            ui.label(k);
            ui.monospace(v);
            ui.end_row();
        };
        row("det J min", format!("{:.4e}", q.det_j_min));
        row("  at (ξ, η)", format!("({:.4}, {:.4})", q.det_j_argmin[0], q.det_j_argmin[1]));
        row("det J max", format!("{:.4e}", q.det_j_max));
        row("min / max", format!("{:.3e}", q.det_j_min / q.det_j_max));
        row("min away from corners", format!("{:.4e}", q.det_j_min_interior));
        row("min away from forced corners", format!("{:.4e}", q.det_j_min_away_from_forced_corners));
        row("det J min at Gauss points", format!("{:.4e}", f.min_det_j_qp));
        row("area", format!("{:.6}", f.area));
        row(
            "Winslow functional",
            if f.winslow.is_finite() { format!("{:.6}", f.winslow) } else { "infinite (det J <= 0)".into() },
        );
        row("harmonic energy", format!("{:.4e}", f.harmonic));
        row("sample", format!("{grid} ({})", mv.sampler));
    });
    egui::CollapsingHeader::new("corners").default_open(false).show(ui, |ui| {
        for c in &q.corners {
            ui.label(format!(
                "{}: {:.1}°{}",
                c.corner,
                c.angle_degrees,
                if c.forces_nonpositive_det_j { " (forces det J <= 0)" } else { "" }
            ));
        }
    });
}

/// The folded-element list; returns the index clicked.
pub(crate) fn folds_section(ui: &mut Ui, mv: &MapView, selected: Option<usize>) -> Option<usize> {
    let forced = mv.folds.iter().filter(|f| f.forced_corner).count();
    if forced > 0 {
        ui.label(format!("{forced} element(s) at corners whose angle forces det J <= 0"));
    }
    if mv.folds.is_empty() {
        ui.label("none: det J > 0 on every sample");
        return None;
    }
    let mut clicked = None;
    egui::ScrollArea::vertical().id_salt("folds").max_height(160.0).show(ui, |ui| {
        for (k, f) in mv.folds.iter().enumerate().take(MAX_LISTED_FOLDS) {
            let text = format!(
                "({:>3}, {:>3})  ξ [{:.3}, {:.3}]  η [{:.3}, {:.3}]  min {:.2e}{}",
                f.element[0],
                f.element[1],
                f.xi[0],
                f.xi[1],
                f.eta[0],
                f.eta[1],
                f.min_det_j,
                if f.forced_corner { "  corner" } else { "" }
            );
            if ui.selectable_label(selected == Some(k), RichText::new(text).monospace().size(11.0)).clicked() {
                clicked = Some(k);
            }
        }
        if mv.folds.len() > MAX_LISTED_FOLDS {
            ui.label(format!("… and {} more", mv.folds.len() - MAX_LISTED_FOLDS));
        }
    });
    clicked
}

/// `log10` of the scaled residual against the iterate number, one line per level.
pub(crate) fn residual_plot(ui: &mut Ui, history: &[crate::solve_job::ResidualPoint]) {
    if history.is_empty() {
        return;
    }
    let plot = Plot::new("residuals")
        .height(170.0)
        .width((ui.available_width() - 12.0).max(120.0))
        .allow_scroll(false)
        .allow_zoom(false)
        .allow_drag(false)
        .x_axis_label("iterate")
        .y_axis_label("scaled |F|")
        .y_axis_formatter(|mark, _| format!("1e{}", mark.value.round() as i64));
    plot.show(ui, |p| {
        let mut start = 0;
        while start < history.len() {
            let level = history[start].level;
            let end = history[start..].iter().position(|h| h.level != level).map_or(history.len(), |k| start + k);
            let pts: Vec<[f64; 2]> = history[start..end]
                .iter()
                .filter(|h| h.scaled_residual > 0.0)
                .map(|h| [h.step as f64, h.scaled_residual.log10()])
                .collect();
            p.line(Line::new(format!("level {}", level + 1), PlotPoints::from(pts)));
            start = end;
        }
    });
}
