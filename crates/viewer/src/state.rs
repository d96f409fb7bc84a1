//! The viewer's state and everything it does that is not drawing: opening files,
//! the two view transforms, display settings, hovering, the solve job. The egui code in
//! [`crate::app`] reads and changes this state; the unit tests drive it directly.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use egui::Vec2;
use winslow::boundary::{BasisChoice, KinkMode};
use winslow::discrete::assembly::Operator;
use winslow::pipeline::compare::{CompareOptions, Comparison, MethodChoice};
use winslow::solve::options::{Refinement, SolveOptions};
use winslow::Point;

use crate::colour::{ColourScale, ScaleKind};
use crate::mesh_overlay::MeshOverlayState;
use crate::sampler::DetJSampler;
use crate::scene::{Scene, SceneSettings};
use crate::solve_job::{JobState, SolveJob};
use crate::view::ViewTransform;
use crate::volume_view::VolumeView;
use winslow::io::Document;

/// What a file opens as.
// one value per open: no boxing
#[allow(clippy::large_enum_variant)]
enum Opened {
    Scene(Scene),
    Volume(VolumeView),
}

/// What is drawn (no effect on what is computed).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DisplayOptions {
    /// `det J` heat map.
    pub heat: bool,
    /// Iso-lines of `xi` and `eta`.
    pub grid: bool,
    /// Control net of the map (control polygons of a boundary's spline sides).
    pub net: bool,
    /// Knot lines (element boundaries) in the parameter view.
    pub knots: bool,
    /// The input boundary over the map.
    pub boundary: bool,
    /// The active cells of the start of a THB solve's rounds (the report's `start`), in
    /// the parameter view.
    pub start: bool,
    /// Colour scale kind.
    pub scale: ScaleKind,
}

impl Default for DisplayOptions {
    fn default() -> Self {
        Self { heat: true, grid: true, net: false, knots: true, boundary: true, start: true, scale: ScaleKind::Log }
    }
}

/// The solver settings offered in the viewer (the rest are the core's defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveSettings {
    /// Operator of eq. (8).
    pub operator: Operator,
    /// Smallest number of elements per direction of the finest level.
    pub min_elements: usize,
    /// Extra uniform refinements of the finest level.
    pub refine: usize,
    /// Fit tolerance relative to the diameter.
    pub fit_tol: f64,
    /// The basis: auto (the input's own when certified), input or fitted.
    pub basis: BasisChoice,
    /// Kinks inside the sides kept exactly (paper §9): auto or none.
    pub kinks: KinkMode,
    /// How a folded map is repaired (paper §8.2): tensor (bisected knot spans), thb
    /// (refined THB cells around the folds: the solve ends with a THB map) or auto (THB
    /// on rounded point-cloud corners), as `winslow solve --refinement`.
    pub refinement: Refinement,
}

impl Default for SolveSettings {
    fn default() -> Self {
        let d = SolveOptions::default();
        Self {
            operator: d.operator,
            min_elements: d.levels.min_elements,
            refine: d.levels.refine,
            fit_tol: d.fit.tol,
            basis: d.fit.basis,
            kinks: d.fit.kinks,
            refinement: Refinement::Auto,
        }
    }
}

impl SolveSettings {
    /// The core's options with these settings.
    pub fn options(&self) -> SolveOptions {
        let mut o = SolveOptions::default();
        o.operator = self.operator;
        o.levels.min_elements = self.min_elements.max(1);
        o.levels.refine = self.refine;
        o.fit.tol = self.fit_tol;
        o.fit.basis = self.basis;
        o.fit.kinks = self.kinks;
        o.repair.refinement = self.refinement;
        o
    }
}

/// Which view the pointer is over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewKind {
    /// The physical domain, `(x, y)`.
    Physical,
    /// The parameter square, `(xi, eta)`.
    Parameter,
}

/// The point under the pointer in both spaces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// View the pointer is over.
    pub view: ViewKind,
    /// Parameter point, if the pointer is over the map's image (physical view) or the square.
    pub param: Option<[f64; 2]>,
    /// Physical point.
    pub point: Point,
    /// `det J` there.
    pub det_j: Option<f64>,
}

impl Probe {
    /// One line of text.
    pub fn text(&self) -> String {
        let [x, y] = self.point;
        match (self.param, self.det_j) {
            (Some([u, v]), Some(d)) => format!("ξ = {u:.4}, η = {v:.4}  <->  x = {x:.5}, y = {y:.5};  det J = {d:.4e}"),
            _ => format!("x = {x:.5}, y = {y:.5} (outside the map)"),
        }
    }
}

/// The viewer's whole state.
pub struct ViewerState {
    /// What is loaded.
    pub scene: Option<Scene>,
    /// A volume (trivariate map) loaded instead of a scene: three slices.
    pub volume: Option<VolumeView>,
    /// Resolution and iso-line density.
    pub settings: SceneSettings,
    /// What is drawn.
    pub display: DisplayOptions,
    /// Solver settings.
    pub solve: SolveSettings,
    /// The running or last solve.
    pub job: Option<SolveJob>,
    /// Physical view transform.
    pub physical: ViewTransform,
    /// Parameter view transform.
    pub parameter: ViewTransform,
    /// Fit both views to their rectangles at the next frame.
    pub refit: bool,
    /// Last message for the status line (errors, exports).
    pub status: Option<String>,
    /// The point under the pointer.
    pub probe: Option<Probe>,
    /// Index into the folded-element list of the highlighted element.
    pub selected_fold: Option<usize>,
    /// The mesh overlay (winslow-mesh): settings and the last build.
    pub mesh: MeshOverlayState,
    /// The last comparison of methods (paper §10) on the scene's boundary: one map per
    /// method, shown one at a time ([`ViewerState::select_method`]).
    pub comparison: Option<Comparison>,
    /// The row of `comparison` whose map the scene shows.
    pub selected_method: Option<usize>,
    /// Whether "Compare methods" adds Gravesen's methods (max-z, eq. 49, and the Liao,
    /// Winslow and area-orthogonality functionals subject to `d(c) >= ε` from `x_G`) to
    /// [`MethodChoice::DEFAULT`]; they need a polynomial basis of at most 3000 unknowns.
    pub compare_gravesen: bool,
    sampler: Arc<dyn DetJSampler>,
}

impl std::fmt::Debug for ViewerState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ViewerState")
            .field("scene", &self.scene.as_ref().map(|s| &s.name))
            .field("sampler", &self.sampler.name())
            .finish_non_exhaustive()
    }
}

impl ViewerState {
    /// An empty viewer sampling `det J` with `sampler`.
    pub fn new(sampler: Arc<dyn DetJSampler>) -> Self {
        Self {
            scene: None,
            volume: None,
            settings: SceneSettings::default(),
            display: DisplayOptions::default(),
            solve: SolveSettings::default(),
            job: None,
            physical: ViewTransform::default(),
            parameter: ViewTransform::default(),
            refit: true,
            status: None,
            probe: None,
            selected_fold: None,
            mesh: MeshOverlayState::default(),
            comparison: None,
            selected_method: None,
            compare_gravesen: false,
            sampler,
        }
    }

    /// The sampler's name.
    pub fn sampler_name(&self) -> &str {
        self.sampler.name()
    }

    /// Open a file; on failure the current scene stays and the error goes to the status
    /// line (and is returned).
    pub fn open(&mut self, path: &Path) -> Result<(), String> {
        use anyhow::Context;
        let opened = winslow::io::read_with_report(path)
            .with_context(|| format!("reading {}", path.display()))
            .and_then(|(doc, report)| match doc {
                Document::Volume { name, volume } => Ok(Opened::Volume(VolumeView::new(name, volume))),
                doc => Scene::from_read(path, doc, report, self.sampler.as_ref(), self.settings).map(Opened::Scene),
            });
        match opened {
            Ok(loaded) => {
                match loaded {
                    Opened::Scene(scene) => self.set_scene(scene),
                    Opened::Volume(volume) => self.set_volume(volume),
                }
                self.status = Some(format!(
                    "opened {}",
                    path.file_name().map_or(path.display().to_string(), |n| n.to_string_lossy().into_owned())
                ));
                Ok(())
            }
            Err(e) => {
                let msg = format!("{e:#}");
                self.status = Some(msg.clone());
                Err(msg)
            }
        }
    }

    /// Show a volume instead of the scene (cancels a running solve).
    pub fn set_volume(&mut self, volume: VolumeView) {
        if let Some(job) = self.job.as_mut() {
            job.cancel();
        }
        self.job = None;
        self.comparison = None;
        self.selected_method = None;
        self.scene = None;
        self.volume = Some(volume);
        self.probe = None;
        self.selected_fold = None;
    }

    /// Move the volume's slice of direction `dir` (0 `ξ`, 1 `η`, 2 `ζ`) to `at`
    /// ([`VolumeView::set_slice`]); false without a volume or when nothing moved.
    pub fn set_volume_slice(&mut self, dir: usize, at: f64) -> bool {
        self.volume.as_mut().is_some_and(|v| v.set_slice(dir, at))
    }

    /// Replace the scene (cancels a running solve).
    pub fn set_scene(&mut self, scene: Scene) {
        self.volume = None;
        if let Some(job) = self.job.as_mut() {
            job.cancel();
        }
        self.job = None;
        self.comparison = None;
        self.selected_method = None;
        self.scene = Some(scene);
        self.refit = true;
        self.probe = None;
        self.selected_fold = None;
    }

    /// Change resolution or density, recomputing the map's data.
    pub fn set_settings(&mut self, settings: SceneSettings) {
        if settings == self.settings {
            return;
        }
        self.settings = settings;
        if let Some(s) = self.scene.as_mut() {
            s.apply_settings(self.sampler.as_ref(), settings);
        }
        self.selected_fold = None;
    }

    /// Whether a solve can start: a valid boundary or a layout to solve, and no solve
    /// running. (An opened multipatch result is not solved again patch by patch.)
    pub fn can_solve(&self) -> bool {
        self.scene
            .as_ref()
            .is_some_and(|s| s.layout.is_some() || (s.boundary.problem.is_none() && s.patches.is_empty()))
            && !self.solving()
    }

    /// Whether a comparison of methods can start: a boundary (not a layout) to solve.
    pub fn can_compare(&self) -> bool {
        self.can_solve() && self.scene.as_ref().is_some_and(|s| s.layout.is_none())
    }

    /// Whether a solve is running.
    pub fn solving(&self) -> bool {
        self.job.as_ref().is_some_and(|j| j.is_active())
    }

    /// Start solving the scene's boundary; `notify` is called from the solving thread
    /// after each event (to wake the UI).
    pub fn start_solve(&mut self, notify: impl Fn() + Send + 'static) -> bool {
        if !self.can_solve() {
            return false;
        }
        let scene = self.scene.as_ref().expect("can_solve");
        self.job = Some(match (&scene.layout, &scene.ring) {
            (Some(l), _) => SolveJob::start_layout(l.layout.clone(), self.solve.options(), notify),
            (None, Some(ring)) => SolveJob::start_ring(ring.clone(), self.solve.options(), notify),
            (None, None) => SolveJob::start(scene.boundary.boundary.clone(), self.solve.options(), notify),
        });
        self.comparison = None;
        self.selected_method = None;
        self.status = Some(format!("solving {}", scene.name));
        true
    }

    /// Start comparing the methods of paper §10 (EGG, the variational harmonic method,
    /// the quasi-conformal functional, and Gravesen's with
    /// [`ViewerState::compare_gravesen`]) on the scene's boundary with the solver
    /// settings; `notify` as for [`ViewerState::start_solve`].
    pub fn start_compare(&mut self, notify: impl Fn() + Send + 'static) -> bool {
        if !self.can_compare() {
            return false;
        }
        let scene = self.scene.as_ref().expect("can_solve");
        let mut opts = CompareOptions::default();
        let base = self.solve.options();
        opts.solve.fit = base.fit;
        opts.solve.operator = base.operator;
        opts.solve.levels.min_elements = base.levels.min_elements;
        opts.solve.levels.refine = base.levels.refine;
        let methods = if self.compare_gravesen { MethodChoice::ALL.to_vec() } else { MethodChoice::DEFAULT.to_vec() };
        self.job = Some(SolveJob::start_compare(scene.boundary.boundary.clone(), methods, opts, notify));
        self.status = Some(format!("comparing methods on {}", scene.name));
        true
    }

    /// Show the map of row `index` of the comparison (the scene keeps its boundary);
    /// `false` when there is no such row or it has no map.
    pub fn select_method(&mut self, index: usize) -> bool {
        let Some(row) = self.comparison.as_ref().and_then(|c| c.rows.get(index)) else { return false };
        let (Some(map), Some(scene)) = (&row.map, self.scene.as_mut()) else { return false };
        scene.set_map(map.clone(), self.sampler.as_ref(), self.settings);
        self.status = Some(format!("showing the {} map: {}", row.method, row.bij()));
        self.selected_method = Some(index);
        self.selected_fold = None;
        true
    }

    /// Keep a finished comparison and show its first (EGG) map.
    fn set_comparison(&mut self, c: Comparison) {
        self.comparison = Some(c);
        self.select_method(0);
        self.refit = true;
    }

    /// Ask the running solve to stop.
    pub fn cancel_solve(&mut self) {
        if let Some(j) = self.job.as_mut() {
            j.cancel();
        }
    }

    /// Take the solve's messages; puts a finished map into the scene. Returns whether
    /// anything changed.
    pub fn poll_job(&mut self) -> bool {
        let Some(job) = self.job.as_mut() else { return false };
        let before = (job.state.clone(), job.progress.history.len());
        let solution = job.poll();
        if let Some(c) = job.take_comparison() {
            self.set_comparison(c);
            return true;
        }
        if let Some(l) = job.take_layout() {
            self.set_layout_solution(l);
            return true;
        }
        if let Some(t) = job.take_thb() {
            self.set_thb_solution(t);
            return true;
        }
        let Some(job) = self.job.as_mut() else { return false };
        let changed = solution.is_some() || before != (job.state.clone(), job.progress.history.len());
        match (&job.state, solution) {
            (JobState::Finished, Some(sol)) => {
                self.status = Some(format!("solved {}: {}", sol.name, sol.report.outcome.message));
                if let Some(scene) = self.scene.as_mut() {
                    scene.set_solution(sol, self.sampler.as_ref(), self.settings);
                    self.refit = true;
                    self.selected_fold = None;
                }
            }
            (JobState::Failed(e), _) if changed => self.status = Some(format!("solve failed: {e}")),
            (JobState::Cancelled, _) if changed => self.status = Some("solve cancelled".into()),
            _ => {}
        }
        changed
    }

    /// Put a solved layout into the scene (every patch's map on one colour scale).
    fn set_layout_solution(&mut self, sol: winslow::multipatch::MultipatchSolution) {
        self.status = Some(format!("solved {}: {}", sol.layout.name, sol.report.message));
        if let Some(scene) = self.scene.as_mut() {
            scene.set_layout_solution(sol, self.sampler.as_ref(), self.settings);
            self.refit = true;
            self.selected_fold = None;
        }
    }

    /// Put a THB solve's map into the scene.
    fn set_thb_solution(&mut self, sol: winslow::ThbSolution) {
        let name = sol.name.clone();
        let message = sol.report.message.clone();
        let Some(scene) = self.scene.as_mut() else { return };
        self.status = Some(match scene.set_thb_solution(sol, self.settings) {
            Ok(()) => format!("solved {name} (THB): {message}"),
            Err(e) => format!("solved {name} (THB), but its map cannot be drawn: {e:#}"),
        });
        self.refit = true;
        self.selected_fold = None;
    }

    /// Block until a running solve ends and take its result (for `--screenshot`).
    pub fn wait_for_solve(&mut self) {
        if let Some(job) = self.job.as_mut() {
            let solution = job.wait();
            if let Some(c) = job.take_comparison() {
                self.set_comparison(c);
            }
            if let Some(l) = self.job.as_mut().and_then(|j| j.take_layout()) {
                self.set_layout_solution(l);
            }
            if let Some(t) = self.job.as_mut().and_then(|j| j.take_thb()) {
                self.set_thb_solution(t);
            }
            if let Some(sol) = solution {
                self.status = Some(format!("solved {}: {}", sol.name, sol.report.outcome.message));
                if let Some(scene) = self.scene.as_mut() {
                    scene.set_solution(sol, self.sampler.as_ref(), self.settings);
                    self.refit = true;
                }
            }
        }
    }

    /// The colour scale of the current heat map.
    pub fn colour_scale(&self) -> Option<ColourScale> {
        if let Some(v) = &self.volume {
            return Some(v.colour_scale(self.display.scale));
        }
        let scene = self.scene.as_ref()?;
        let mv = scene.map.as_ref()?;
        if scene.patches.is_empty() {
            return Some(ColourScale::for_values(&mv.sample.values, self.display.scale));
        }
        // one scale over all patches of a layout
        let all: Vec<f64> = scene.maps().flat_map(|m| m.sample.values.iter().copied()).collect();
        Some(ColourScale::for_values(&all, self.display.scale))
    }

    /// Build the mesh overlay on the current map (the error goes to the overlay's panel
    /// and is returned).
    pub fn build_mesh(&mut self) -> Result<(), String> {
        let Some(mv) = self.scene.as_ref().and_then(|s| s.map.as_ref()) else {
            return Err("no map to mesh: solve the boundary first".into());
        };
        self.mesh.build(&mv.map);
        match &self.mesh.built {
            Some(Err(e)) => Err(e.clone()),
            _ => Ok(()),
        }
    }

    /// Fit both views to their rectangles.
    pub fn fit_views(&mut self, physical: Vec2, parameter: Vec2) {
        if let Some(s) = &self.scene {
            self.physical = ViewTransform::fit(s.bounds(), physical, 0.05);
        }
        self.parameter = ViewTransform::fit([[0.0, 0.0], [1.0, 1.0]], parameter, 0.06);
        self.refit = false;
    }

    /// The probe at a physical point (inverting the map).
    pub fn probe_physical(&self, p: Point) -> Probe {
        let mv = self.scene.as_ref().and_then(|s| s.map.as_ref());
        let param = mv.and_then(|m| m.invert(p));
        let det_j = match (mv, param) {
            (Some(m), Some(q)) => Some(m.probe(q).1),
            _ => None,
        };
        Probe { view: ViewKind::Physical, param, point: p, det_j }
    }

    /// The probe at a parameter point (`None` outside the square or without a map).
    pub fn probe_parameter(&self, q: [f64; 2]) -> Option<Probe> {
        let mv = self.scene.as_ref()?.map.as_ref()?;
        if !(0.0..=1.0).contains(&q[0]) || !(0.0..=1.0).contains(&q[1]) {
            return None;
        }
        let (x, d) = mv.probe(q);
        Some(Probe { view: ViewKind::Parameter, param: Some(q), point: x, det_j: Some(d) })
    }
}

/// Paths given on the command line or dropped on the window, first usable one.
pub fn first_path(paths: impl IntoIterator<Item = Option<PathBuf>>) -> Option<PathBuf> {
    paths.into_iter().flatten().next()
}

#[cfg(test)]
mod tests;
