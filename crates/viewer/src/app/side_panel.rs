//! The side panel of [`ViewerApp`]: the file, the layout, the certificate and its folded
//! elements, the solve, the methods of a comparison, the display, quality and mesh sections.

use super::*;

impl ViewerApp {
    pub(super) fn side_panel(&mut self, ui: &mut Ui) {
        ui.add_space(4.0);
        if self.volume_panel(ui) {
            return;
        }
        let Some(scene) = &self.state.scene else {
            ui.label("Open a boundary, ring, map, domain, graph, multipatch or volume file: File > Open, drag and drop, or a path on the command line.");
            return;
        };
        file_section(ui, scene);
        if let Some(l) = &scene.layout {
            section(ui, "Layout", |ui| layout_section(ui, l));
        }
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
        if self.state.comparison.is_some() {
            section(ui, "Methods", |ui| self.methods_section(ui));
        }
        section(ui, "Display", |ui| self.display_section(ui));
        if let Some(mv) = self.state.scene.as_ref().and_then(|s| s.map.as_ref()) {
            section(ui, "Quality", |ui| quality_section(ui, mv));
            section(ui, "Mesh", |ui| mesh_section(ui, &mut self.state.mesh, &mv.map));
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
        if let Some(st) =
            self.state.scene.as_ref().and_then(|s| s.map.as_ref()).and_then(|m| m.thb.as_ref()?.start.as_ref())
        {
            ui.checkbox(&mut d.start, "THB start's cells (blue)").on_hover_text(format!(
                "where the THB rounds started: the {} start, {} functions, {} active cells, {}",
                st.basis,
                st.functions,
                st.cells.len(),
                st.verdict
            ));
        }
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
            ui.horizontal(|ui| {
                ui.label("basis").on_hover_text(
                    "auto: the input's own basis (boundary exact) when its map is certified, else fitted; \
                     input: always the input's basis; fitted: fits within the tolerance",
                );
                for b in [BasisChoice::Auto, BasisChoice::Input, BasisChoice::Fitted] {
                    ui.selectable_value(&mut s.basis, b, b.name());
                }
            });
            ui.horizontal(|ui| {
                ui.label("kinks").on_hover_text(
                    "auto: C0 knots, zero-speed knots and polygon corners inside the sides are kept exactly \
                     (paper §9: EGG on the smoothed basis, Winslow on the C0 one); none: rounded by the fit",
                );
                ui.selectable_value(&mut s.kinks, KinkMode::Auto, "auto");
                ui.selectable_value(&mut s.kinks, KinkMode::None, "none");
            });
            ui.horizontal(|ui| {
                ui.label("refinement").on_hover_text(
                    "how a folded map is repaired (paper §8.2): tensor bisects whole knot spans; thb refines \
                     THB cells around the folds only and ends with a THB map (active cells drawn); auto: thb \
                     on rounded point-cloud corners, tensor elsewhere",
                );
                for (r, name) in [(Refinement::Auto, "auto"), (Refinement::Tensor, "tensor"), (Refinement::Thb, "thb")]
                {
                    ui.selectable_value(&mut s.refinement, r, name);
                }
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
        let compare = ui
            .horizontal(|ui| {
                let b = ui
                    .add_enabled(self.state.can_compare(), egui::Button::new("Compare methods"))
                    .on_hover_text("EGG, the variational harmonic method (eq. 46) and the quasi-conformal functional (eq. 47-48) on one basis; switch between their maps below");
                ui.checkbox(&mut self.state.compare_gravesen, "with Gravesen's").on_hover_text(
                    "also max-z (eq. 49) from the Coons patch and the Liao, Winslow and area-orthogonality functionals subject to d(c) >= eps from the EGG map; they need the fitted (polynomial) basis with at most 3000 unknowns",
                );
                b
            })
            .inner;
        if compare.clicked() {
            let ctx = ui.ctx().clone();
            self.state.start_compare(move || ctx.request_repaint());
        }
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

    /// The comparison's rows (paper §10's columns); clicking a method shows its map.
    fn methods_section(&mut self, ui: &mut Ui) {
        let Some(c) = &self.state.comparison else { return };
        let mut clicked = None;
        ui.label(format!("{} basis; Q(x_G) from the EGG map", c.basis));
        egui::Grid::new("methods").striped(true).show(ui, |ui| {
            for h in ["method", "IT", "BIJ", "Q/Q(x_G)", "W", "s"] {
                ui.label(RichText::new(h).strong());
            }
            ui.end_row();
            for (i, r) in c.rows.iter().enumerate() {
                let selected = self.state.selected_method == Some(i);
                if ui.add_enabled(r.map.is_some(), egui::Button::selectable(selected, &r.method)).clicked() {
                    clicked = Some(i);
                }
                ui.label(format!("{}{}", r.iterations, if r.converged { "" } else { " (no)" }));
                ui.label(r.bij());
                ui.label(r.q_ratio.map_or("-".into(), |q| format!("{q:.3}")));
                let w = r.measures.as_ref().and_then(|m| m.winslow);
                ui.label(w.map_or("inf".into(), |w| format!("{w:.3}")));
                ui.label(format!("{:.2}", r.seconds));
                ui.end_row();
            }
        });
        for r in c.rows.iter().filter(|r| !r.converged) {
            ui.label(format!("{}: not converged: {}", r.method, r.failure.clone().unwrap_or_default()));
        }
        if let Some(i) = clicked {
            self.state.select_method(i);
        }
    }

    // ---------------------------------------------------------------- views
}
