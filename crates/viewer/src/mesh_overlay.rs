//! The mesh overlay: a classical mesh made from the current map with `winslow-mesh`
//! (paper §11.3), structured (`NX x NY` points with a clustering of `eta`) or
//! unstructured (spade, a target edge length), drawn as lines over the `det J` heat map
//! in both views, with its quality table.
//!
//! [`MeshSettings`] and [`MeshOverlay`] are state (unit-tested without drawing);
//! [`mesh_section`] and [`paint_overlay`] are the egui side panel and the painter.

use std::time::Instant;

use egui::{Color32, Pos2, RichText, Stroke, Ui};
use winslow::Surface;
use winslow_mesh::quality::{corner_defect, quality, Quality};
use winslow_mesh::topology::faces;
use winslow_mesh::{
    structured, unstructured, Distribution, Equidistribution, Mesh, Side, StructuredOptions, UnstructuredOptions,
};

/// Most vertices of an unstructured overlay (it is built in the UI thread).
pub const MAX_OVERLAY_VERTICES: usize = 200_000;
/// Most points per direction of a structured overlay.
pub const MAX_OVERLAY_POINTS: usize = 1000;

/// Structured or unstructured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OverlayKind {
    /// `NX x NY` points at `xi_i x eta_j`.
    Structured,
    /// A refined constrained Delaunay triangulation.
    Unstructured,
}

/// The clustering of the structured mesh's `eta` points (`xi` stays uniform, as in the
/// paper's Fig. 31).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clustering {
    /// Uniform.
    Uniform,
    /// Eq. (50), clustered at both ends, strength `a`.
    Arctan,
    /// Two-sided tanh, strength `d`.
    Tanh,
    /// Geometric layers at south and north whose first cell is `strength` times the
    /// map's diameter long (growth limit 1.2).
    Layers,
    /// Equal arc length along the west and east sides.
    ArcLength,
    /// Curvature equidistribution with a chord tolerance of `strength` times the
    /// diameter (the fewest points, at least NY, that meet it).
    Curvature,
}

impl Clustering {
    /// Name in the panel.
    pub fn label(self) -> &'static str {
        match self {
            Clustering::Uniform => "uniform",
            Clustering::Arctan => "arctan (eq. 50)",
            Clustering::Tanh => "tanh",
            Clustering::Layers => "first-cell height",
            Clustering::ArcLength => "arc length",
            Clustering::Curvature => "curvature",
        }
    }
}

/// What overlay to build.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshSettings {
    /// Draw the overlay.
    pub show: bool,
    /// Structured or unstructured.
    pub kind: OverlayKind,
    /// Points per direction of a structured mesh.
    pub points: [usize; 2],
    /// Clustering of `eta`.
    pub clustering: Clustering,
    /// Strength of arctan / tanh; first-cell height over the diameter for layers.
    pub strength: f64,
    /// Target edge length of an unstructured mesh over the map's diameter.
    pub size: f64,
    /// Smallest angle of the unstructured mesh (parameter rectangle), degrees.
    pub min_angle: f64,
}

impl Default for MeshSettings {
    fn default() -> Self {
        Self {
            show: true,
            kind: OverlayKind::Structured,
            points: [41, 17],
            clustering: Clustering::Arctan,
            strength: 6.0,
            size: 0.04,
            min_angle: 28.0,
        }
    }
}

/// Diagonal of the map's image (of its control points, a bound of the image).
fn diameter(map: &Surface) -> f64 {
    let b = crate::view::bounds_of(&map.control_points).unwrap_or([[0.0, 0.0], [1.0, 1.0]]);
    (b[1][0] - b[0][0]).hypot(b[1][1] - b[0][1])
}

impl MeshSettings {
    /// The structured mesh's options (the `eta` distribution from the clustering; `xi`
    /// on a ring, whose `eta` is periodic).
    pub fn structured_options(&self, map: &Surface) -> StructuredOptions {
        let eta = match self.clustering {
            Clustering::Uniform => Distribution::Uniform,
            Clustering::Arctan => Distribution::Arctan { strength: self.strength },
            Clustering::Tanh => Distribution::TanhTwoSided { strength: self.strength },
            Clustering::Layers => {
                let h = self.strength * diameter(map);
                Distribution::Layers { start: Some(h), end: Some(h), growth: 1.2 }
            }
            Clustering::ArcLength => Distribution::Equidistributed(Equidistribution::ArcLength),
            Clustering::Curvature => {
                Distribution::Equidistributed(Equidistribution::Curvature { tol: self.strength * diameter(map) })
            }
        };
        // a ring's eta runs around it (periodic, its ends are the seam): the clustering
        // goes across the gap, in xi, between the inner and outer walls
        if winslow_mesh::periodic_directions(map)[1] {
            return StructuredOptions { points: self.points, distribution: [eta, Distribution::Uniform] };
        }
        StructuredOptions { points: self.points, distribution: [Distribution::Uniform, eta] }
    }

    /// The unstructured mesh's options (size in physical units).
    pub fn unstructured_options(&self, map: &Surface) -> UnstructuredOptions {
        UnstructuredOptions {
            size: self.size * diameter(map),
            min_angle: self.min_angle,
            max_vertices: MAX_OVERLAY_VERTICES,
            ..Default::default()
        }
    }

    /// Build the mesh these settings ask for on `map`; the error as text for the panel.
    pub fn build(&self, map: &Surface) -> Result<MeshOverlay, String> {
        let t = Instant::now();
        let mesh = match self.kind {
            OverlayKind::Structured => {
                if self.points.iter().any(|&n| n > MAX_OVERLAY_POINTS) {
                    return Err(format!("at most {MAX_OVERLAY_POINTS} points per direction in the viewer"));
                }
                structured(map, &self.structured_options(map))
            }
            OverlayKind::Unstructured => unstructured(map, &self.unstructured_options(map)),
        }
        .map_err(|e| e.to_string())?;
        let quality = quality(&mesh).map_err(|e| e.to_string())?;
        let f = faces(&mesh).map_err(|e| e.to_string())?;
        let mut edges: Vec<[usize; 2]> = f.internal.iter().map(|e| e.nodes).collect();
        let boundary = f.boundary.iter().map(|e| (e.side, e.nodes)).collect();
        edges.shrink_to_fit();
        let inverted = (0..mesh.num_cells()).filter(|&c| corner_defect(&mesh, c).is_some()).collect();
        Ok(MeshOverlay {
            settings: *self,
            map: map.clone(),
            mesh,
            quality,
            edges,
            boundary,
            inverted,
            seconds: t.elapsed().as_secs_f64(),
        })
    }
}

/// A built overlay.
#[derive(Debug, Clone)]
pub struct MeshOverlay {
    /// The settings it was built with.
    pub settings: MeshSettings,
    /// The map it was built on (the overlay is drawn only over this map).
    pub map: Surface,
    /// The mesh.
    pub mesh: Mesh,
    /// Its quality table.
    pub quality: Quality,
    /// Internal edges (corner nodes), each once.
    pub edges: Vec<[usize; 2]>,
    /// Boundary edges with their sides.
    pub boundary: Vec<(Side, [usize; 2])>,
    /// Inverted or degenerate cells (the CLI would refuse to write this mesh).
    pub inverted: Vec<usize>,
    /// Time to build, seconds.
    pub seconds: f64,
}

impl MeshOverlay {
    /// Whether it was built with `settings` on `map` (else the panel offers a rebuild).
    pub fn is_current(&self, settings: &MeshSettings, map: &Surface) -> bool {
        let same =
            |a: &MeshSettings, b: &MeshSettings| MeshSettings { show: true, ..*a } == MeshSettings { show: true, ..*b };
        same(&self.settings, settings) && self.map == *map
    }

    /// One line: what it is.
    pub fn summary(&self) -> String {
        let m = &self.mesh;
        format!("{} {}s, {} nodes, built in {:.3} s", m.num_cells(), m.kind.name(), m.points.len(), self.seconds)
    }
}

/// The overlay's settings and the last build.
#[derive(Debug, Clone, Default)]
pub struct MeshOverlayState {
    /// What to build.
    pub settings: MeshSettings,
    /// The last build (or why it failed).
    pub built: Option<Result<MeshOverlay, String>>,
}

impl MeshOverlayState {
    /// Build on `map`; returns whether a mesh came out.
    pub fn build(&mut self, map: &Surface) -> bool {
        let r = self.settings.build(map);
        let ok = r.is_ok();
        self.built = Some(r);
        ok
    }

    /// The overlay to draw over `map`: shown, built, and built on this map.
    pub fn drawn(&self, map: &Surface) -> Option<&MeshOverlay> {
        match &self.built {
            Some(Ok(o)) if self.settings.show && o.map == *map => Some(o),
            _ => None,
        }
    }
}

/// The "Mesh" section of the side panel: kind, counts, clustering, the build button,
/// the quality table. `map` is the current map.
pub fn mesh_section(ui: &mut Ui, st: &mut MeshOverlayState, map: &Surface) {
    let s = &mut st.settings;
    ui.checkbox(&mut s.show, "overlay the mesh");
    ui.horizontal(|ui| {
        ui.selectable_value(&mut s.kind, OverlayKind::Structured, "structured");
        ui.selectable_value(&mut s.kind, OverlayKind::Unstructured, "unstructured");
    });
    match s.kind {
        OverlayKind::Structured => {
            ui.add(egui::Slider::new(&mut s.points[0], 2..=401).text("NX (ξ points)"));
            ui.add(egui::Slider::new(&mut s.points[1], 2..=201).text("NY (η points)"));
            ui.horizontal_wrapped(|ui| {
                ui.label("η:");
                for c in [
                    Clustering::Uniform,
                    Clustering::Arctan,
                    Clustering::Tanh,
                    Clustering::Layers,
                    Clustering::ArcLength,
                    Clustering::Curvature,
                ] {
                    if ui.selectable_value(&mut s.clustering, c, c.label()).changed() {
                        s.strength = match c {
                            Clustering::Layers | Clustering::Curvature => 1e-3,
                            _ => 6.0,
                        };
                    }
                }
            });
            match s.clustering {
                Clustering::Uniform | Clustering::ArcLength => {}
                Clustering::Curvature => {
                    ui.add(
                        egui::Slider::new(&mut s.strength, 1e-6..=1e-1)
                            .logarithmic(true)
                            .text("chord tolerance / diameter"),
                    );
                }
                Clustering::Arctan | Clustering::Tanh => {
                    ui.add(egui::Slider::new(&mut s.strength, 0.1..=20.0).text("strength"));
                }
                Clustering::Layers => {
                    ui.add(
                        egui::Slider::new(&mut s.strength, 1e-6..=1e-1).logarithmic(true).text("first cell / diameter"),
                    );
                }
            }
        }
        OverlayKind::Unstructured => {
            ui.add(egui::Slider::new(&mut s.size, 0.005..=0.3).logarithmic(true).text("size / diameter"));
            ui.add(egui::Slider::new(&mut s.min_angle, 0.0..=30.0).text("min angle (°)"));
        }
    }
    let stale = match &st.built {
        Some(Ok(o)) => !o.is_current(&st.settings, map),
        _ => true,
    };
    ui.horizontal(|ui| {
        if ui.button(if stale { "Build mesh" } else { "Rebuild" }).clicked() {
            st.build(map);
        }
        if stale && matches!(st.built, Some(Ok(_))) {
            ui.label(RichText::new("settings or map changed").weak());
        }
    });
    match &st.built {
        None => {}
        Some(Err(e)) => {
            ui.colored_label(Color32::from_rgb(200, 40, 40), e);
        }
        Some(Ok(o)) => {
            ui.label(o.summary());
            if !o.inverted.is_empty() {
                ui.colored_label(
                    Color32::from_rgb(200, 40, 40),
                    format!("{} inverted cells (outlined red): the CLI refuses to write this mesh", o.inverted.len()),
                );
            }
            egui::Grid::new("mesh-quality").num_columns(2).striped(true).show(ui, |ui| {
                for (k, v) in o.quality.rows() {
                    ui.label(k);
                    ui.monospace(v);
                    ui.end_row();
                }
            });
        }
    }
}

/// Draw the overlay's edges with `to` (a node index to a screen point): internal edges
/// thin and dark, boundary edges in the side colours, inverted cells outlined red.
pub fn paint_overlay(painter: &egui::Painter, o: &MeshOverlay, side_colours: [Color32; 4], to: impl Fn(usize) -> Pos2) {
    let pos: Vec<Pos2> = (0..o.mesh.points.len()).map(&to).collect();
    let thin = Stroke::new(0.6, Color32::from_black_alpha(170));
    painter.extend(o.edges.iter().map(|&[a, b]| egui::Shape::line_segment([pos[a], pos[b]], thin)));
    painter.extend(o.boundary.iter().map(|&(side, [a, b])| {
        egui::Shape::line_segment([pos[a], pos[b]], Stroke::new(1.4, side_colours[side as usize]))
    }));
    let red = Stroke::new(1.5, Color32::RED);
    for &c in &o.inverted {
        let pts = o.mesh.corners(c).iter().map(|&k| pos[k]).collect();
        painter.add(egui::Shape::closed_line(pts, red));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The affine map `x = (2 xi, 1 + eta)` (degree 1, one element).
    fn affine() -> Surface {
        let kv = winslow::KnotVector::open_uniform(1, 1);
        Surface::new([kv.clone(), kv], vec![[0.0, 1.0], [2.0, 1.0], [0.0, 2.0], [2.0, 2.0]], None).expect("affine")
    }

    #[test]
    fn structured_overlay_is_the_sampled_grid() {
        let map = affine();
        let s = MeshSettings { points: [9, 5], clustering: Clustering::Arctan, strength: 6.0, ..Default::default() };
        let o = s.build(&map).unwrap();
        let (nx, ny) = (9, 5);
        assert_eq!(o.mesh.num_cells(), (nx - 1) * (ny - 1));
        // every edge once: (nx - 1) ny + nx (ny - 1) in all, 2 (nx - 1) + 2 (ny - 1) on the boundary
        assert_eq!(o.edges.len() + o.boundary.len(), (nx - 1) * ny + nx * (ny - 1));
        assert_eq!(o.boundary.len(), 2 * (nx - 1) + 2 * (ny - 1));
        // eta follows eq. (50) and the nodes lie on the affine map
        let a = 6.0f64;
        for j in 0..ny {
            let t = j as f64 / (ny - 1) as f64;
            let eta = 0.5 * ((a * (t - 0.5)).atan() / (0.5 * a).atan() + 1.0);
            let p = o.mesh.points[j * nx + 3];
            assert!((p.x - 2.0 * 3.0 / 8.0).abs() < 1e-14 && (p.y - 1.0 - eta).abs() < 1e-14, "{p:?}");
        }
        assert!(o.inverted.is_empty());
        assert_eq!(o.quality.inverted, 0);
        // area of the image: 2
        let area: f64 = o.quality.per_cell.iter().map(|c| c.area).sum();
        assert!((area - 2.0).abs() < 1e-13, "{area}");
        assert!(o.quality.rows().iter().any(|(k, v)| *k == "inverted cells" && v == "0"));
        assert!(o.is_current(&s, &map));
        // arc length on the affine map: equal spacings (uniform eta)
        let a = MeshSettings { points: [3, 5], clustering: Clustering::ArcLength, ..Default::default() }
            .build(&map)
            .unwrap();
        for j in 0..5 {
            assert!((a.mesh.points[3 * j].y - 1.0 - j as f64 / 4.0).abs() < 1e-12);
        }
        assert!(!o.is_current(&MeshSettings { points: [9, 6], ..s }, &map));
    }

    #[test]
    fn unstructured_overlay_is_a_triangulated_disk() {
        let map = affine();
        let s = MeshSettings { kind: OverlayKind::Unstructured, size: 0.05, ..Default::default() };
        let o = s.build(&map).unwrap();
        let (v, f) = (o.mesh.points.len(), o.mesh.num_cells());
        // Euler for a disk: V - E + F = 1
        assert_eq!(v + f, o.edges.len() + o.boundary.len() + 1);
        assert!(o.inverted.is_empty());
        // edges no longer than the size, up to spade's boundary split (physical length
        // of the size times the diameter sqrt(5))
        let h = 0.05 * 5f64.sqrt();
        for &[a, b] in &o.edges {
            assert!(o.mesh.points[a].distance(o.mesh.points[b]) <= h * (1.0 + 1e-9));
        }
        assert!(o.quality.angle[0] > 20.0, "{:?}", o.quality.angle);
    }

    #[test]
    fn bad_settings_are_reported_not_panicked() {
        let map = affine();
        let mut st = MeshOverlayState::default();
        st.settings.points = [1, 5];
        assert!(!st.build(&map));
        assert!(matches!(&st.built, Some(Err(e)) if e.contains("xi points")), "{:?}", st.built);
        assert!(st.drawn(&map).is_none());
        st.settings = MeshSettings { clustering: Clustering::Layers, strength: 0.9, ..Default::default() };
        assert!(!st.build(&map));
        st.settings = MeshSettings { kind: OverlayKind::Unstructured, size: 0.0, ..Default::default() };
        assert!(!st.build(&map));
        // a good build is drawn over its map only
        st.settings = MeshSettings::default();
        assert!(st.build(&map));
        assert!(st.drawn(&map).is_some());
        let mut other = map.clone();
        other.control_points[3] = [2.5, 2.5];
        assert!(st.drawn(&other).is_none());
        st.settings.show = false;
        assert!(st.drawn(&map).is_none());
    }
}
