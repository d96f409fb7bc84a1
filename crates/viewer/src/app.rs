//! Drawing: the egui user interface over [`ViewerState`]. A side panel with the file,
//! the display settings, the verdict, the quality numbers, the folded elements and the
//! solver; the physical view, the parameter view and the colour bar in the centre; a
//! status line with the point under the pointer.

use std::path::PathBuf;
use std::sync::mpsc::{channel, Receiver};
use std::sync::{Arc, Mutex};

use egui::epaint::Mesh;
use egui::{Align2, Color32, ColorImage, FontId, Pos2, Rect, RichText, Sense, Shape, Stroke, Ui, Vec2};
use winslow::boundary::{BasisChoice, KinkMode};
use winslow::discrete::assembly::Operator;
use winslow::solve::options::Refinement;
use winslow::Point;

use crate::colour::{colour_at, fold_colour, is_positive, ColourScale, ScaleKind};
use crate::export::write_png;
use crate::mesh_overlay::{mesh_section, paint_overlay};
use crate::paint::{
    control_net, crosshair, element_outline, heat_mesh, irregular_colour, side_colours, thb_control_net,
};
use crate::sampler::DetJSampler;
use crate::scene::RESOLUTION_RANGE;
use crate::sections::{
    certificate_section, file_section, folds_section, layout_section, quality_section, residual_plot, section,
};
use crate::solve_job::JobState;
use crate::state::{Probe, ViewKind, ViewerState};
use crate::view::ViewTransform;

mod side_panel;
mod volume;

/// Width of the colour bar strip in points.
const BAR_WIDTH: f32 = 96.0;
/// Width of the side panel in points.
const PANEL_WIDTH: f32 = 340.0;

/// A screenshot in progress: where to write it and which part of the window to keep.
#[derive(Debug)]
struct PendingShot {
    path: PathBuf,
    /// Keep only the views (export) or the whole window (`--screenshot`).
    views_only: bool,
    /// Close the window once written.
    exit: bool,
    /// Requested from the integration (the slot will be filled).
    requested: bool,
}

/// The egui application.
pub struct ViewerApp {
    /// State and logic.
    pub state: ViewerState,
    open_dialog: Option<Receiver<Option<PathBuf>>>,
    export_dialog: Option<Receiver<Option<PathBuf>>>,
    shot: Option<PendingShot>,
    shot_slot: Arc<Mutex<Option<Arc<ColorImage>>>>,
    /// Screen rectangle of the views and the colour bar (last frame), for exports.
    views_rect: Option<Rect>,
    /// Screen rectangle of the physical view (last frame).
    physical_rect: Option<Rect>,
    /// Screen rectangle of the parameter view (last frame).
    parameter_rect: Option<Rect>,
    /// Display settings being dragged, applied on release.
    pending_settings: Option<crate::scene::SceneSettings>,
    /// For `--screenshot`: frames to draw after everything is ready before the shot.
    settle_frames: usize,
}

impl std::fmt::Debug for ViewerApp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ViewerApp").field("state", &self.state).finish_non_exhaustive()
    }
}

impl ViewerApp {
    /// A viewer sampling `det J` with `sampler`.
    pub fn new(sampler: Arc<dyn DetJSampler>) -> Self {
        Self {
            state: ViewerState::new(sampler),
            open_dialog: None,
            export_dialog: None,
            shot: None,
            shot_slot: Arc::new(Mutex::new(None)),
            views_rect: None,
            physical_rect: None,
            parameter_rect: None,
            pending_settings: None,
            settle_frames: 0,
        }
    }

    /// Write a PNG of the window to `path` once nothing is pending (no solve running),
    /// then close the window: the `--screenshot` flag.
    pub fn screenshot_and_exit(&mut self, path: PathBuf) {
        self.shot = Some(PendingShot { path, views_only: false, exit: true, requested: false });
        self.settle_frames = 3;
    }

    /// Export the current views (and colour bar) to a PNG at the next frame.
    pub fn export_views(&mut self, path: PathBuf) {
        self.shot = Some(PendingShot { path, views_only: true, exit: false, requested: false });
        self.settle_frames = 1;
    }

    /// Screen rectangle of the physical view in the last frame.
    pub fn last_physical_rect(&self) -> Option<Rect> {
        self.physical_rect
    }

    /// Draw one frame.
    pub fn show(&mut self, ui: &mut Ui) {
        let ctx = ui.ctx().clone();
        self.handle_inputs(&ctx);
        if self.state.poll_job() {
            ctx.request_repaint();
        }
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::bottom("status").show(ui, |ui| self.status_line(ui));
        egui::Panel::left("side").exact_size(PANEL_WIDTH).resizable(false).show(ui, |ui| {
            egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
                ui.set_max_width(PANEL_WIDTH - 28.0);
                self.side_panel(ui)
            });
        });
        egui::CentralPanel::default().show(ui, |ui| self.central(ui));
        self.screenshots(&ctx);
    }

    fn handle_inputs(&mut self, ctx: &egui::Context) {
        // drag and drop
        let dropped: Vec<Option<PathBuf>> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| Some(f.path().to_path_buf()).filter(|p| !p.as_os_str().is_empty()))
                .collect()
        });
        if let Some(path) = crate::state::first_path(dropped) {
            let _ = self.state.open(&path);
        }
        // keyboard: Ctrl+O open, Ctrl+E export, Ctrl+F fit the views
        let (open, export, fit) = ctx.input_mut(|i| {
            (
                i.consume_key(egui::Modifiers::COMMAND, egui::Key::O),
                i.consume_key(egui::Modifiers::COMMAND, egui::Key::E),
                i.consume_key(egui::Modifiers::COMMAND, egui::Key::F),
            )
        });
        if open && self.open_dialog.is_none() {
            self.pick_file(ctx);
        }
        if export && self.export_dialog.is_none() && self.state.scene.is_some() {
            self.pick_export(ctx);
        }
        if fit {
            self.state.refit = true;
        }
        // file dialogs run in their own threads
        if let Some(rx) = &self.open_dialog {
            if let Ok(r) = rx.try_recv() {
                self.open_dialog = None;
                if let Some(path) = r {
                    let _ = self.state.open(&path);
                }
            }
        }
        if let Some(rx) = &self.export_dialog {
            if let Ok(r) = rx.try_recv() {
                self.export_dialog = None;
                if let Some(path) = r {
                    self.export_views(path);
                }
            }
        }
        if self.open_dialog.is_some() || self.export_dialog.is_some() {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
        // the point under the pointer, in the views as laid out in the last frame
        let pointer = ctx.input(|i| i.pointer.hover_pos());
        let st = &self.state;
        self.state.probe = match (pointer, self.physical_rect, self.parameter_rect) {
            (Some(p), Some(r), _) if r.contains(p) && st.scene.is_some() => {
                Some(st.probe_physical(st.physical.to_world(r, p)))
            }
            (Some(p), _, Some(r)) if r.contains(p) && st.scene.is_some() => {
                st.probe_parameter(st.parameter.to_world(r, p))
            }
            _ => None,
        };
    }

    fn pick_file(&mut self, ctx: &egui::Context) {
        let (tx, rx) = channel();
        let ctx = ctx.clone();
        std::thread::spawn(move || {
            let path = rfd::FileDialog::new()
                .set_title("Open a boundary or map")
                .add_filter("winslow geometry", &["json", "xml"])
                .add_filter("all files", &["*"])
                .pick_file();
            let _ = tx.send(path);
            ctx.request_repaint();
        });
        self.open_dialog = Some(rx);
    }

    fn pick_export(&mut self, ctx: &egui::Context) {
        let name = self.state.scene.as_ref().map_or("view".to_string(), |s| format!("{}-view.png", s.name));
        let (tx, rx) = channel();
        let ctx = ctx.clone();
        std::thread::spawn(move || {
            let path = rfd::FileDialog::new()
                .set_title("Export the view")
                .set_file_name(name)
                .add_filter("PNG", &["png"])
                .save_file();
            let _ = tx.send(path);
            ctx.request_repaint();
        });
        self.export_dialog = Some(rx);
    }

    fn screenshots(&mut self, ctx: &egui::Context) {
        let Some(shot) = self.shot.as_mut() else { return };
        if !shot.requested {
            // wait for a running solve and let the layout settle
            if self.state.solving() || self.state.refit {
                ctx.request_repaint();
                return;
            }
            if self.settle_frames > 0 {
                self.settle_frames -= 1;
                ctx.request_repaint();
                return;
            }
            let slot = self.shot_slot.clone();
            ctx.request_screenshot(move |image| {
                if let Ok(mut s) = slot.lock() {
                    *s = Some(image);
                }
            });
            shot.requested = true;
            ctx.request_repaint();
            return;
        }
        let image = self.shot_slot.lock().ok().and_then(|mut s| s.take());
        let Some(image) = image else {
            ctx.request_repaint();
            return;
        };
        let shot = self.shot.take().expect("pending");
        let ppp = ctx.pixels_per_point();
        let crop = if shot.views_only { self.views_rect.map(|r| r * ppp) } else { None };
        match write_png(&shot.path, &image, crop) {
            Ok(()) => self.state.status = Some(format!("wrote {}", shot.path.display())),
            Err(e) => self.state.status = Some(format!("writing {}: {e:#}", shot.path.display())),
        }
        if shot.exit {
            if let Some(s) = &self.state.status {
                eprintln!("{s}");
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    fn menu_bar(&mut self, ui: &mut Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.add(egui::Button::new("Open…").shortcut_text("Ctrl+O")).clicked() {
                    self.pick_file(ui.ctx());
                    ui.close();
                }
                let has_scene = self.state.scene.is_some();
                if ui.add_enabled(has_scene, egui::Button::new("Export view as PNG…").shortcut_text("Ctrl+E")).clicked()
                {
                    self.pick_export(ui.ctx());
                    ui.close();
                }
                if ui.button("Quit").clicked() {
                    ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
                }
            });
            ui.menu_button("View", |ui| {
                if ui.add(egui::Button::new("Fit views").shortcut_text("Ctrl+F")).clicked() {
                    self.state.refit = true;
                    ui.close();
                }
            });
            ui.separator();
            match &self.state.scene {
                Some(s) => ui.label(RichText::new(&s.name).strong()),
                None => ui.label("no file"),
            };
        });
    }

    fn status_line(&mut self, ui: &mut Ui) {
        ui.horizontal(|ui| {
            match &self.state.probe {
                Some(p) => ui.monospace(p.text()),
                None => ui.label(
                    "hover a view for (ξ, η) <-> (x, y) and det J; drag to pan, scroll to zoom, double-click to fit",
                ),
            };
            if let Some(s) = &self.state.status {
                // elided to the width the hint leaves (the full text is on hover)
                ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                    ui.add(egui::Label::new(RichText::new(s).weak()).truncate());
                });
            }
        });
    }

    fn central(&mut self, ui: &mut Ui) {
        let full = ui.available_rect_before_wrap();
        if self.volume_views(ui, full) {
            self.drop_hint(ui, full);
            return;
        }
        if self.state.scene.is_none() {
            ui.painter().text(
                full.center(),
                Align2::CENTER_CENTER,
                "drop a boundary or map file here",
                FontId::proportional(18.0),
                ui.visuals().weak_text_color(),
            );
            self.drop_hint(ui, full);
            return;
        }
        let gap = 8.0;
        let title = 18.0;
        let full_views = Rect::from_min_max(full.min + Vec2::new(0.0, title), full.max);
        let views_w = (full.width() - BAR_WIDTH - gap).max(10.0);
        let param_w = (0.4 * views_w).min(full.height());
        let phys = Rect::from_min_size(full_views.min, Vec2::new(views_w - param_w - gap, full_views.height()));
        let side = param_w.min(full_views.height());
        let param = Rect::from_min_size(Pos2::new(phys.max.x + gap, full_views.min.y), Vec2::new(param_w, side));
        let label = |ui: &Ui, r: Rect, text: &str| {
            ui.painter().text(
                r.left_top() + Vec2::new(2.0, -3.0),
                Align2::LEFT_BOTTOM,
                text,
                FontId::proportional(13.0),
                ui.visuals().text_color(),
            );
        };
        label(ui, phys, "physical domain (x, y)");
        label(ui, param, "parameter square (ξ, η)");
        let bar = Rect::from_min_max(Pos2::new(full.max.x - BAR_WIDTH, full.min.y), full.max);
        self.views_rect = Some(full);
        self.physical_rect = Some(phys);
        self.parameter_rect = Some(param);
        if self.state.refit {
            self.state.fit_views(phys.size(), param.size());
        }
        self.physical_view(ui, phys);
        self.parameter_view(ui, param);
        self.colour_bar(ui, bar);
        self.drop_hint(ui, full);
    }

    fn drop_hint(&self, ui: &Ui, rect: Rect) {
        if ui.ctx().input(|i| !i.raw.hovered_files.is_empty()) {
            ui.painter().rect_filled(rect, 4.0, Color32::from_black_alpha(120));
            ui.painter().text(
                rect.center(),
                Align2::CENTER_CENTER,
                "drop to open",
                FontId::proportional(24.0),
                Color32::WHITE,
            );
        }
    }

    /// Pan, zoom and fit of one view; returns the response.
    fn interact(ui: &mut Ui, rect: Rect, id: &str, view: &mut ViewTransform, refit: &mut bool) -> egui::Response {
        let resp = ui.interact(rect, ui.scope_id().with(id), Sense::click_and_drag());
        if resp.dragged() {
            view.pan(resp.drag_delta());
        }
        if resp.double_clicked() {
            *refit = true;
        }
        if let Some(pos) = resp.hover_pos() {
            let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            let factor = zoom as f64 * (scroll as f64 / 200.0).exp();
            if factor != 1.0 {
                view.zoom_about(rect, pos, factor);
            }
        }
        resp
    }

    /// The physical domain.
    fn physical_view(&mut self, ui: &mut Ui, rect: Rect) {
        Self::interact(ui, rect, "physical", &mut self.state.physical, &mut self.state.refit);
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 2.0, Color32::from_gray(250));
        let view = self.state.physical;
        let to = |p: Point| view.to_screen(rect, p);
        let scene = self.state.scene.as_ref().expect("scene");
        let d = self.state.display;
        if let Some(mv) = &scene.map {
            let scale =
                self.state.colour_scale().unwrap_or_else(|| ColourScale::for_values(&mv.sample.values, d.scale));
            // the other patches of a multipatch layout, under the first one's overlays
            for other in &scene.patches {
                if d.heat {
                    painter.add(heat_mesh(other, &scale, |k| to(other.positions[k])));
                }
                let stroke = Stroke::new(0.8, Color32::from_black_alpha(150));
                for line in other.iso.xi.iter().chain(&other.iso.eta).filter(|_| d.grid) {
                    painter.add(Shape::line(line.iter().map(|&p| to(p)).collect(), stroke));
                }
                for side in &other.sides {
                    painter.add(Shape::line(side.iter().map(|&p| to(p)).collect(), Stroke::new(1.6, Color32::BLACK)));
                }
            }
            if d.heat {
                painter.add(heat_mesh(mv, &scale, |k| to(mv.positions[k])));
            }
            if d.grid {
                // a THB map's active cells where a tensor map has iso-lines (as its PNG)
                let stroke = Stroke::new(0.8, Color32::from_black_alpha(150));
                let lines = match &mv.thb {
                    Some(t) => &t.borders[..],
                    None => &[],
                };
                let iso = mv.iso.xi.iter().chain(&mv.iso.eta).filter(|_| mv.thb.is_none());
                for line in lines.iter().chain(iso) {
                    painter.add(Shape::line(line.iter().map(|&p| to(p)).collect(), stroke));
                }
            }
            if let Some(o) = self.state.mesh.drawn(&mv.map) {
                paint_overlay(&painter, o, side_colours(), |k| to(o.mesh.points[k].to_array()));
            }
            if d.net {
                // a THB map's own net (its active functions), not its tensor form's
                match &mv.thb {
                    Some(t) => thb_control_net(&painter, &t.map, &to),
                    None => control_net(&painter, &mv.map, &to),
                }
            }
            for side in &mv.sides {
                painter.add(Shape::line(side.iter().map(|&p| to(p)).collect(), Stroke::new(1.6, Color32::BLACK)));
            }
            // matched pairs of the constrained reparameterization (§7.2)
            for &(a, b) in &mv.matches {
                painter.line_segment([to(a), to(b)], Stroke::new(1.4, Color32::from_rgb(30, 90, 220)));
                painter.circle_filled(to(a), 2.2, Color32::from_rgb(30, 90, 220));
                painter.circle_filled(to(b), 2.2, Color32::from_rgb(30, 90, 220));
            }
            // kinks (§9): a diagonal cross where the map keeps them, an upright one where
            // the fit rounds them
            for &(x, kept) in &mv.kinks {
                let (c, r) = (to(x), 5.0);
                let (colour, arms) = if kept {
                    (Color32::from_rgb(200, 0, 0), [egui::vec2(r, r), egui::vec2(r, -r)])
                } else {
                    (Color32::from_rgb(240, 140, 0), [egui::vec2(r, 0.0), egui::vec2(0.0, r)])
                };
                for a in arms {
                    painter.line_segment([c - a, c + a], Stroke::new(2.0, colour));
                }
            }
            if let Some(f) = self.state.selected_fold.and_then(|k| mv.folds.get(k)) {
                let edge = element_outline(mv, f.xi, f.eta);
                painter.add(Shape::closed_line(edge.iter().map(|&p| to(p)).collect(), Stroke::new(2.5, Color32::RED)));
            }
            if !is_positive(mv.quality.det_j_min) {
                let (x, _) = mv.probe(mv.quality.det_j_argmin);
                let c = to(x);
                painter.circle_stroke(c, 6.0, Stroke::new(2.0, Color32::RED));
            }
            match self.state.probe {
                Some(Probe { view: ViewKind::Parameter, point, .. }) => crosshair(&painter, to(point)),
                Some(Probe { view: ViewKind::Physical, point, param: Some(_), .. }) => {
                    painter.circle_stroke(to(point), 3.0, Stroke::new(1.5, Color32::RED));
                }
                _ => {}
            }
        }
        if let Some(l) = &scene.layout {
            // patch borders, the domain's outline and the irregular vertices
            if d.boundary || scene.map.is_none() {
                let border = Stroke::new(if scene.map.is_some() { 1.0 } else { 1.4 }, Color32::from_gray(90));
                for line in l.borders.iter().flatten() {
                    painter.add(Shape::line(line.iter().map(|&p| to(p)).collect(), border));
                }
            }
            for line in &l.outline {
                painter.add(Shape::line(line.iter().map(|&p| to(p)).collect(), Stroke::new(2.2, Color32::BLACK)));
            }
            for v in l.irregular() {
                let c = to(v.point);
                painter.circle_filled(c, 5.0, irregular_colour(v.valence));
                painter.circle_stroke(c, 5.0, Stroke::new(1.0, Color32::BLACK));
                painter.text(
                    c + egui::vec2(7.0, -7.0),
                    Align2::LEFT_BOTTOM,
                    v.valence.to_string(),
                    FontId::proportional(12.0),
                    Color32::BLACK,
                );
            }
        }
        if scene.layout.is_none() && (d.boundary || scene.map.is_none()) {
            let colours = side_colours();
            for (k, line) in scene.boundary.polylines.iter().enumerate() {
                let w = if scene.map.is_some() { 1.0 } else { 2.0 };
                painter.add(Shape::line(line.iter().map(|&p| to(p)).collect(), Stroke::new(w, colours[k])));
            }
            if d.net && scene.map.is_none() {
                for poly in &scene.boundary.control_polygons {
                    let pts: Vec<Pos2> = poly.iter().map(|&p| to(p)).collect();
                    painter.extend(Shape::dashed_line(&pts, Stroke::new(0.8, Color32::GRAY), 4.0, 3.0));
                    for p in pts {
                        painter.circle_filled(p, 2.5, Color32::DARK_GRAY);
                    }
                }
            }
        }
    }

    /// The parameter square.
    fn parameter_view(&mut self, ui: &mut Ui, rect: Rect) {
        Self::interact(ui, rect, "parameter", &mut self.state.parameter, &mut self.state.refit);
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 2.0, Color32::from_gray(250));
        let view = self.state.parameter;
        let to = |q: [f64; 2]| view.to_screen(rect, q);
        let scene = self.state.scene.as_ref().expect("scene");
        let d = self.state.display;
        let square = Rect::from_two_pos(to([0.0, 0.0]), to([1.0, 1.0]));
        match &scene.map {
            Some(mv) => {
                let scale = ColourScale::for_values(&mv.sample.values, d.scale);
                let n = mv.sample.n;
                if d.heat {
                    painter.add(heat_mesh(mv, &scale, |k| {
                        to([(k % (n + 1)) as f64 / n as f64, (k / (n + 1)) as f64 / n as f64])
                    }));
                }
                if let Some(s) = mv.thb.as_ref().and_then(|t| t.start.as_ref()).filter(|_| d.start) {
                    // the start of the THB rounds: its active cells, under the map's
                    let stroke = Stroke::new(2.2, Color32::from_rgba_unmultiplied(30, 90, 220, 170));
                    for (_, [[a, b], [c, e]]) in &s.cells {
                        let r = Rect::from_two_pos(to([*a, *c]), to([*b, *e]));
                        painter.rect_stroke(r, 0.0, stroke, egui::StrokeKind::Middle);
                    }
                }
                if let Some(t) = mv.thb.as_ref().filter(|_| d.knots || d.grid) {
                    // the active cells of a THB map (in place of knot lines and iso-lines)
                    let stroke = Stroke::new(0.8, Color32::from_black_alpha(150));
                    for (_, [[a, b], [c, e]]) in &t.cells {
                        let r = Rect::from_two_pos(to([*a, *c]), to([*b, *e]));
                        painter.rect_stroke(r, 0.0, stroke, egui::StrokeKind::Middle);
                    }
                } else if d.knots && mv.thb.is_none() {
                    let stroke = Stroke::new(0.6, Color32::from_black_alpha(70));
                    for &u in &mv.breaks[0] {
                        painter.line_segment([to([u, 0.0]), to([u, 1.0])], stroke);
                    }
                    for &v in &mv.breaks[1] {
                        painter.line_segment([to([0.0, v]), to([1.0, v])], stroke);
                    }
                }
                if d.grid && mv.thb.is_none() {
                    let stroke = Stroke::new(0.8, Color32::from_black_alpha(150));
                    let m = mv.iso.density;
                    for k in 1..m {
                        let t = k as f64 / m as f64;
                        painter.line_segment([to([t, 0.0]), to([t, 1.0])], stroke);
                        painter.line_segment([to([0.0, t]), to([1.0, t])], stroke);
                    }
                }
                if let Some(o) = self.state.mesh.drawn(&mv.map) {
                    paint_overlay(&painter, o, side_colours(), |k| to(o.mesh.params[k].to_array()));
                }
                for f in &mv.folds {
                    let r = Rect::from_two_pos(to([f.xi[0], f.eta[0]]), to([f.xi[1], f.eta[1]]));
                    painter.rect_stroke(r, 0.0, Stroke::new(1.0, fold_colour()), egui::StrokeKind::Inside);
                }
                // kinks (§9): a diagonal cross where the map keeps them, an upright one where
                // the fit rounds them
                for &(x, kept) in &mv.kinks {
                    let (c, r) = (to(x), 5.0);
                    let (colour, arms) = if kept {
                        (Color32::from_rgb(200, 0, 0), [egui::vec2(r, r), egui::vec2(r, -r)])
                    } else {
                        (Color32::from_rgb(240, 140, 0), [egui::vec2(r, 0.0), egui::vec2(0.0, r)])
                    };
                    for a in arms {
                        painter.line_segment([c - a, c + a], Stroke::new(2.0, colour));
                    }
                }
                if let Some(f) = self.state.selected_fold.and_then(|k| mv.folds.get(k)) {
                    let r = Rect::from_two_pos(to([f.xi[0], f.eta[0]]), to([f.xi[1], f.eta[1]]));
                    painter.rect_stroke(r, 0.0, Stroke::new(2.5, Color32::RED), egui::StrokeKind::Outside);
                }
                if let Some(Probe { view: ViewKind::Physical, param: Some(q), .. }) = self.state.probe {
                    crosshair(&painter, to(q));
                }
            }
            None => {
                painter.text(
                    square.center(),
                    Align2::CENTER_CENTER,
                    if scene.layout.is_some() {
                        "no maps yet: solve the layout"
                    } else {
                        "no map yet: solve the boundary"
                    },
                    FontId::proportional(14.0),
                    Color32::GRAY,
                );
            }
        }
        let colours = side_colours();
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        for (k, (a, b)) in [(0, 1), (1, 2), (3, 2), (0, 3)].into_iter().enumerate() {
            painter.line_segment([to(corners[a]), to(corners[b])], Stroke::new(1.6, colours[k]));
        }
    }

    fn colour_bar(&self, ui: &mut Ui, rect: Rect) {
        let Some(scale) = self.state.colour_scale() else { return };
        let painter = ui.painter_at(rect);
        let top = rect.top() + 24.0;
        let bottom = rect.bottom() - 48.0;
        if bottom - top < 40.0 {
            return;
        }
        let bar = Rect::from_min_max(Pos2::new(rect.left() + 6.0, top), Pos2::new(rect.left() + 26.0, bottom));
        let mut mesh = Mesh::default();
        let steps = 64;
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let y = bottom - (bottom - top) * t as f32;
            let c = colour_at(t);
            mesh.colored_vertex(Pos2::new(bar.left(), y), c);
            mesh.colored_vertex(Pos2::new(bar.right(), y), c);
            if k > 0 {
                let i = 2 * k as u32;
                mesh.add_triangle(i - 2, i - 1, i);
                mesh.add_triangle(i - 1, i + 1, i);
            }
        }
        painter.add(mesh);
        painter.rect_stroke(bar, 0.0, Stroke::new(1.0, Color32::DARK_GRAY), egui::StrokeKind::Outside);
        let text = ui.visuals().text_color();
        painter.text(
            Pos2::new(rect.left() + 4.0, rect.top() + 4.0),
            Align2::LEFT_TOP,
            format!("det J ({})", scale.kind.label()),
            FontId::proportional(12.0),
            text,
        );
        for (t, v) in scale.ticks(6) {
            let y = bottom - (bottom - top) * t as f32;
            painter.line_segment([Pos2::new(bar.right(), y), Pos2::new(bar.right() + 4.0, y)], Stroke::new(1.0, text));
            painter.text(
                Pos2::new(bar.right() + 6.0, y),
                Align2::LEFT_CENTER,
                format!("{v:.2e}"),
                FontId::monospace(11.0),
                text,
            );
        }
        let swatch = Rect::from_min_size(Pos2::new(bar.left(), bottom + 14.0), Vec2::new(20.0, 14.0));
        painter.rect_filled(swatch, 0.0, fold_colour());
        painter.text(
            Pos2::new(swatch.right() + 6.0, swatch.center().y),
            Align2::LEFT_CENTER,
            "<= 0 (fold)",
            FontId::proportional(12.0),
            text,
        );
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut Ui, _frame: &mut eframe::Frame) {
        self.show(ui);
    }
}
