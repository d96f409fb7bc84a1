//! Drawing a volume ([`crate::volume_view::VolumeView`]): its side panel (verdict, one
//! slider per parameter direction, the colour scale) and the three slices side by side,
//! each projected face on and painted with the `det J` heat map of the planar maps.

use super::*;
use crate::paint::heat_mesh_values;
use crate::view::bounds_of;
use crate::volume_view::{free_directions, VolumeSlice, DIRECTIONS};

impl ViewerApp {
    /// The side panel of a volume; true when a volume is shown.
    pub(super) fn volume_panel(&mut self, ui: &mut Ui) -> bool {
        let Some(v) = &self.state.volume else { return false };
        ui.heading(&v.name);
        let [p, q, r] = v.volume.degrees();
        let [a, b, c] = v.volume.shape();
        ui.label(format!("volume of degrees ({p}, {q}, {r}), {a} x {b} x {c} control points"));
        let verdict = v.verdict();
        let mut at = v.slices.each_ref().map(|s| s.at);
        section(ui, "Certificate", |ui| {
            ui.label(verdict);
        });
        section(ui, "Slices", |ui| {
            for (d, t) in at.iter_mut().enumerate() {
                ui.add(egui::Slider::new(t, 0.0..=1.0).text(format!("{} slice", DIRECTIONS[d])));
            }
        });
        for (d, t) in at.into_iter().enumerate() {
            self.state.set_volume_slice(d, t);
        }
        section(ui, "Display", |ui| {
            let d = &mut self.state.display;
            ui.horizontal(|ui| {
                ui.label("colour scale");
                ui.selectable_value(&mut d.scale, ScaleKind::Log, ScaleKind::Log.label());
                ui.selectable_value(&mut d.scale, ScaleKind::Linear, ScaleKind::Linear.label());
            });
        });
        true
    }

    /// The three slices and the colour bar; true when a volume is shown.
    pub(super) fn volume_views(&mut self, ui: &mut Ui, full: Rect) -> bool {
        let (Some(v), Some(scale)) = (&self.state.volume, self.state.colour_scale()) else { return false };
        let gap = 8.0;
        let title = 18.0;
        let w = ((full.width() - BAR_WIDTH - 3.0 * gap) / 3.0).max(10.0);
        let h = (full.height() - title).max(10.0).min(w);
        for (k, s) in v.slices.iter().enumerate() {
            let rect =
                Rect::from_min_size(Pos2::new(full.min.x + k as f32 * (w + gap), full.min.y + title), Vec2::new(w, h));
            paint_slice(ui, rect, s, &scale);
        }
        self.views_rect = Some(full);
        let bar = Rect::from_min_max(Pos2::new(full.max.x - BAR_WIDTH, full.min.y), full.max);
        self.colour_bar(ui, bar);
        true
    }
}

fn paint_slice(ui: &Ui, rect: Rect, s: &VolumeSlice, scale: &ColourScale) {
    let [a, b] = free_directions(s.dir);
    let xyz = ["x", "y", "z"];
    ui.painter().text(
        rect.left_top() + Vec2::new(2.0, -3.0),
        Align2::LEFT_BOTTOM,
        format!(
            "{} = {:.3} (over {}, {}), drawn in ({}, {})",
            DIRECTIONS[s.dir], s.at, DIRECTIONS[a], DIRECTIONS[b], xyz[s.axes[0]], xyz[s.axes[1]]
        ),
        FontId::proportional(13.0),
        ui.visuals().text_color(),
    );
    let projected = s.projected();
    let Some(bounds) = bounds_of(projected.iter()) else { return };
    let view = ViewTransform::fit(bounds, rect.size(), 0.05);
    let painter = ui.painter_at(rect);
    painter.rect_stroke(rect, 0.0, Stroke::new(1.0, Color32::from_gray(160)), egui::StrokeKind::Inside);
    painter.add(heat_mesh_values(s.n, &s.det_j, scale, |k| view.to_screen(rect, projected[k])));
}
