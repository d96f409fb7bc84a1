//! Drawing: the egui user interface over [`ViewerState`]. A side panel with the file,
//! the display settings, the verdict, the quality numbers, the folded elements and the
//! solver; the physical view, the parameter view and the colour bar in the centre; a
//! status line with the point under the pointer.

use std::path::PathBuf;
use std::sync::mpsc::{channel, Receiver};
use std::sync::{Arc, Mutex};

use egui::epaint::{Mesh, Vertex, WHITE_UV};
use egui::{Align2, Color32, ColorImage, FontId, Pos2, Rect, RichText, Sense, Shape, Stroke, Ui, Vec2};
use egui_plot::{Line, Plot, PlotPoints};
use winslow::discrete::assembly::Operator;
use winslow::Point;

use crate::certificate::{verdict_is_good, verdict_name, Certificate};
use crate::colour::{colour_at, fold_colour, is_positive, ColourScale, ScaleKind};
use crate::sampler::DetJSampler;
use crate::scene::{MapView, Scene, RESOLUTION_RANGE};
use crate::solve_job::JobState;
use crate::state::{Probe, ViewKind, ViewerState};
use crate::view::ViewTransform;

/// Width of the colour bar strip in points.
const BAR_WIDTH: f32 = 96.0;
/// Width of the side panel in points.
const PANEL_WIDTH: f32 = 340.0;
/// Folded elements listed at most.
const MAX_LISTED_FOLDS: usize = 200;

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
                ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                    ui.label(RichText::new(s).weak());
                });
            }
        });
    }

    // ---------------------------------------------------------------- side panel

    fn side_panel(&mut self, ui: &mut Ui) {
        ui.add_space(4.0);
        let Some(scene) = &self.state.scene else {
            ui.label("Open a boundary or map file: File > Open, drag and drop, or a path on the command line.");
            return;
        };
        file_section(ui, scene);
        if let Some(mv) = self.state.scene.as_ref().and_then(|s| s.map.as_ref()) {
            section(ui, "Certificate", |ui| certificate_section(ui, mv));
            let folds = mv.folds.iter().filter(|f| !f.forced_corner).count();
            let mut clicked = None;
            section(ui, &format!("Folded elements: {folds}"), |ui| {
                clicked = folds_section(ui, mv, self.state.selected_fold);
            });
            if let Some(k) = clicked {
                self.state.selected_fold = if self.state.selected_fold == Some(k) { None } else { Some(k) };
            }
        }
        section(ui, "Solve", |ui| self.solve_section(ui));
        section(ui, "Display", |ui| self.display_section(ui));
        if let Some(mv) = self.state.scene.as_ref().and_then(|s| s.map.as_ref()) {
            section(ui, "Quality", |ui| quality_section(ui, mv));
        }
    }

    fn display_section(&mut self, ui: &mut Ui) {
        let d = &mut self.state.display;
        ui.horizontal_wrapped(|ui| {
            ui.checkbox(&mut d.heat, "det J heat map");
            ui.checkbox(&mut d.grid, "grid lines");
            ui.checkbox(&mut d.net, "control net");
            ui.checkbox(&mut d.knots, "knot lines");
            ui.checkbox(&mut d.boundary, "input boundary");
        });
        ui.horizontal(|ui| {
            ui.label("colour scale");
            ui.selectable_value(&mut d.scale, ScaleKind::Log, ScaleKind::Log.label());
            ui.selectable_value(&mut d.scale, ScaleKind::Linear, ScaleKind::Linear.label());
        });
        // while a slider is dragged the new value waits: resampling is not free
        let mut settings = self.pending_settings.unwrap_or(self.state.settings);
        let current = self.state.scene.as_ref().and_then(|s| s.map.as_ref()).map(|m| m.resolution());
        let mut density = settings.density;
        let r1 = ui.add(egui::Slider::new(&mut density, 2..=64).text("grid lines per direction"));
        let mut res = settings.resolution.or(current).unwrap_or(128);
        let r2 = ui.add(egui::Slider::new(&mut res, RESOLUTION_RANGE.0..=RESOLUTION_RANGE.1).text("heat-map cells"));
        if r2.changed() {
            settings.resolution = Some(res);
        }
        settings.density = density;
        if r1.dragged() || r2.dragged() {
            self.pending_settings = Some(settings);
        } else {
            self.pending_settings = None;
            self.state.set_settings(settings);
        }
    }

    fn solve_section(&mut self, ui: &mut Ui) {
        let Some(scene) = &self.state.scene else { return };
        if let Some(p) = &scene.boundary.problem {
            ui.colored_label(Color32::from_rgb(200, 40, 40), format!("cannot solve: {p}"));
            return;
        }
        let running = self.state.solving();
        ui.add_enabled_ui(!running, |ui| {
            let s = &mut self.state.solve;
            ui.horizontal(|ui| {
                ui.label("operator");
                ui.selectable_value(&mut s.operator, Operator::Scaled, "scaled");
                ui.selectable_value(&mut s.operator, Operator::Plain, "plain");
            });
            ui.add(egui::Slider::new(&mut s.min_elements, 1..=64).text("min elements"));
            ui.add(egui::Slider::new(&mut s.refine, 0..=4).text("extra refinements"));
            ui.add(egui::Slider::new(&mut s.fit_tol, 1e-7..=1e-2).logarithmic(true).text("fit tolerance"));
        });
        ui.horizontal(|ui| {
            if ui.add_enabled(self.state.can_solve(), egui::Button::new("Solve")).clicked() {
                let ctx = ui.ctx().clone();
                self.state.start_solve(move || ctx.request_repaint());
            }
            if ui.add_enabled(running, egui::Button::new("Cancel")).clicked() {
                self.state.cancel_solve();
            }
            if running {
                ui.spinner();
            }
        });
        let Some(job) = &self.state.job else { return };
        let state = match &job.state {
            JobState::Running => "running".to_string(),
            JobState::Cancelling => "cancelling (at the next event)".to_string(),
            JobState::Finished => "finished".to_string(),
            JobState::Failed(e) => format!("failed: {e}"),
            JobState::Cancelled => "cancelled".to_string(),
        };
        ui.label(format!("{}: {state}", job.name));
        ui.label(job.progress.text());
        residual_plot(ui, &job.progress.history);
    }

    // ---------------------------------------------------------------- views

    fn central(&mut self, ui: &mut Ui) {
        let full = ui.available_rect_before_wrap();
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
            let scale = ColourScale::for_values(&mv.sample.values, d.scale);
            if d.heat {
                painter.add(heat_mesh(mv, &scale, |k| to(mv.positions[k])));
            }
            if d.grid {
                let stroke = Stroke::new(0.8, Color32::from_black_alpha(150));
                for line in mv.iso.xi.iter().chain(&mv.iso.eta) {
                    painter.add(Shape::line(line.iter().map(|&p| to(p)).collect(), stroke));
                }
            }
            if d.net {
                control_net(&painter, &mv.map, &to);
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
        if d.boundary || scene.map.is_none() {
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
                if d.knots {
                    let stroke = Stroke::new(0.6, Color32::from_black_alpha(70));
                    for &u in &mv.breaks[0] {
                        painter.line_segment([to([u, 0.0]), to([u, 1.0])], stroke);
                    }
                    for &v in &mv.breaks[1] {
                        painter.line_segment([to([0.0, v]), to([1.0, v])], stroke);
                    }
                }
                if d.grid {
                    let stroke = Stroke::new(0.8, Color32::from_black_alpha(150));
                    let m = mv.iso.density;
                    for k in 1..m {
                        let t = k as f64 / m as f64;
                        painter.line_segment([to([t, 0.0]), to([t, 1.0])], stroke);
                        painter.line_segment([to([0.0, t]), to([1.0, t])], stroke);
                    }
                }
                for f in &mv.folds {
                    let r = Rect::from_two_pos(to([f.xi[0], f.eta[0]]), to([f.xi[1], f.eta[1]]));
                    painter.rect_stroke(r, 0.0, Stroke::new(1.0, fold_colour()), egui::StrokeKind::Inside);
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
                    "no map yet: solve the boundary",
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

/// A collapsible section of the side panel, open by default.
fn section(ui: &mut Ui, title: &str, body: impl FnOnce(&mut Ui)) {
    egui::CollapsingHeader::new(RichText::new(title).heading()).default_open(true).show(ui, body);
}

/// Colours of the sides south, east, north, west.
fn side_colours() -> [Color32; 4] {
    [
        Color32::from_rgb(200, 40, 40),
        Color32::from_rgb(40, 140, 40),
        Color32::from_rgb(40, 70, 200),
        Color32::from_rgb(200, 140, 0),
    ]
}

fn crosshair(painter: &egui::Painter, c: Pos2) {
    let s = Stroke::new(1.5, Color32::RED);
    painter.line_segment([c - Vec2::new(8.0, 0.0), c + Vec2::new(8.0, 0.0)], s);
    painter.line_segment([c - Vec2::new(0.0, 8.0), c + Vec2::new(0.0, 8.0)], s);
    painter.circle_stroke(c, 4.0, s);
}

/// The heat map over the sample grid: Gouraud-shaded cells with the colours of the
/// samples at their corners, and every cell with a non-positive corner painted flat in
/// the fold colour on top (no blend of fold and scale colours).
fn heat_mesh(mv: &MapView, scale: &ColourScale, pos: impl Fn(usize) -> Pos2) -> Shape {
    let n = mv.sample.n;
    let values = &mv.sample.values;
    let mut mesh = Mesh::default();
    mesh.vertices.reserve((n + 1) * (n + 1));
    for (k, &v) in values.iter().enumerate() {
        mesh.vertices.push(Vertex { pos: pos(k), uv: WHITE_UV, color: scale.colour(v) });
    }
    let idx = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut folded = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let ks = [idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)];
            if ks.iter().any(|&k| !is_positive(values[k as usize])) {
                folded.push(ks);
                continue;
            }
            mesh.add_triangle(ks[0], ks[1], ks[2]);
            mesh.add_triangle(ks[0], ks[2], ks[3]);
        }
    }
    let fold = fold_colour();
    for ks in folded {
        let base = mesh.vertices.len() as u32;
        for k in ks {
            mesh.vertices.push(Vertex { pos: pos(k as usize), uv: WHITE_UV, color: fold });
        }
        mesh.add_triangle(base, base + 1, base + 2);
        mesh.add_triangle(base, base + 2, base + 3);
    }
    Shape::mesh(mesh)
}

fn control_net(painter: &egui::Painter, map: &winslow::Surface, to: &impl Fn(Point) -> Pos2) {
    let [nx, ny] = map.shape();
    let stroke = Stroke::new(0.8, Color32::from_rgb(90, 90, 90));
    for j in 0..ny {
        painter.add(Shape::line((0..nx).map(|i| to(map.cp(i, j))).collect(), stroke));
    }
    for i in 0..nx {
        painter.add(Shape::line((0..ny).map(|j| to(map.cp(i, j))).collect(), stroke));
    }
    for p in &map.control_points {
        painter.circle_filled(to(*p), 2.0, Color32::from_rgb(60, 60, 60));
    }
}

/// The image of an element's boundary (core evaluation of the map).
fn element_outline(mv: &MapView, xi: [f64; 2], eta: [f64; 2]) -> Vec<Point> {
    let m = 24;
    let mut out = Vec::with_capacity(4 * m);
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    for k in 0..m {
        out.push(mv.map.eval(lerp(xi[0], xi[1], k as f64 / m as f64), eta[0]));
    }
    for k in 0..m {
        out.push(mv.map.eval(xi[1], lerp(eta[0], eta[1], k as f64 / m as f64)));
    }
    for k in 0..m {
        out.push(mv.map.eval(lerp(xi[1], xi[0], k as f64 / m as f64), eta[1]));
    }
    for k in 0..m {
        out.push(mv.map.eval(xi[0], lerp(eta[1], eta[0], k as f64 / m as f64)));
    }
    out
}

fn file_section(ui: &mut Ui, scene: &Scene) {
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
            ui.label(format!(
                "p = ({p}, {q}), {nx}x{ny} control points,\n{}x{} elements{}",
                mv.map.knots[0].num_elements(),
                mv.map.knots[1].num_elements(),
                if mv.map.weights.is_some() { ", rational" } else { "" }
            ));
            ui.end_row();
        }
    });
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

fn verdict_colour(c: &Certificate) -> Color32 {
    match c.verdict {
        winslow::solve::report::Verdict::Certified => Color32::from_rgb(20, 140, 50),
        winslow::solve::report::Verdict::DegenerateCorner => Color32::from_rgb(190, 130, 0),
        _ => Color32::from_rgb(200, 30, 30),
    }
}

/// The verdict, in one place: the solver's or the stored report, and the exact certificate.
fn certificate_section(ui: &mut Ui, mv: &MapView) {
    let c = &mv.certificate;
    ui.label(
        RichText::new(format!(
            "{} {}",
            if verdict_is_good(c.verdict) { "OK:" } else { "BAD:" },
            verdict_name(c.verdict)
        ))
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
            RichText::new(format!("exact certificate: {} ({})", verdict_name(s.verdict), s.message))
                .color(verdict_colour(s)),
        );
    }
}

fn quality_section(ui: &mut Ui, mv: &MapView) {
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
fn folds_section(ui: &mut Ui, mv: &MapView, selected: Option<usize>) -> Option<usize> {
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
fn residual_plot(ui: &mut Ui, history: &[crate::solve_job::ResidualPoint]) {
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

/// Crop (in pixels) and write a screenshot as PNG.
pub fn write_png(path: &std::path::Path, image: &ColorImage, crop: Option<Rect>) -> anyhow::Result<()> {
    let (x0, y0, w, h) = crop_box(image.size, crop);
    let mut rgba = Vec::with_capacity(4 * w * h);
    for y in y0..y0 + h {
        for x in x0..x0 + w {
            rgba.extend_from_slice(&image.pixels[y * image.size[0] + x].to_srgba_unmultiplied());
        }
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut enc = png::Encoder::new(file, w as u32, h as u32);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header()?.write_image_data(&rgba)?;
    Ok(())
}

/// The pixel box `(x, y, width, height)` of `crop` within an image of `size`, clamped
/// (the whole image without a crop or when the crop misses it).
pub fn crop_box(size: [usize; 2], crop: Option<Rect>) -> (usize, usize, usize, usize) {
    let whole = (0, 0, size[0], size[1]);
    let Some(r) = crop else { return whole };
    let clamp = |v: f32, hi: usize| (v.round().max(0.0) as usize).min(hi);
    let (x0, x1) = (clamp(r.min.x, size[0]), clamp(r.max.x, size[0]));
    let (y0, y1) = (clamp(r.min.y, size[1]), clamp(r.max.y, size[1]));
    if x1 <= x0 || y1 <= y0 {
        return whole;
    }
    (x0, y0, x1 - x0, y1 - y0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crop_boxes_are_clamped() {
        assert_eq!(crop_box([100, 50], None), (0, 0, 100, 50));
        let r = Rect::from_min_max(Pos2::new(10.2, 5.0), Pos2::new(60.0, 80.0));
        assert_eq!(crop_box([100, 50], Some(r)), (10, 5, 50, 45));
        let off = Rect::from_min_max(Pos2::new(200.0, 5.0), Pos2::new(300.0, 80.0));
        assert_eq!(crop_box([100, 50], Some(off)), (0, 0, 100, 50));
    }

    #[test]
    fn png_round_trip() {
        let mut img = ColorImage::filled([4, 3], Color32::from_rgb(10, 20, 30));
        img.pixels[4 + 2] = fold_colour();
        let path = std::env::temp_dir().join(format!("winslow-viewer-png-{}.png", std::process::id()));
        let crop = Rect::from_min_max(Pos2::new(1.0, 1.0), Pos2::new(3.0, 3.0));
        write_png(&path, &img, Some(crop)).unwrap();
        let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let mut reader = dec.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (2, 2));
        // pixel (2, 1) of the image is (1, 0) of the crop
        assert_eq!(&buf[4..8], &[255, 0, 255, 255]);
        assert_eq!(&buf[0..4], &[10, 20, 30, 255]);
        std::fs::remove_file(&path).ok();
    }
}
