//! The viewer's state and everything it does that is not drawing: opening files,
//! the two view transforms, display settings, hovering, the solve job. The egui code in
//! [`crate::app`] reads and changes this state; the unit tests drive it directly.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use egui::Vec2;
use winslow::boundary::{BasisChoice, KinkMode};
use winslow::discrete::assembly::Operator;
use winslow::pipeline::compare::{CompareOptions, Comparison, MethodChoice};
use winslow::solve::options::SolveOptions;
use winslow::Point;

use crate::colour::{ColourScale, ScaleKind};
use crate::mesh_overlay::MeshOverlayState;
use crate::sampler::DetJSampler;
use crate::scene::{Scene, SceneSettings};
use crate::solve_job::{JobState, SolveJob};
use crate::view::ViewTransform;

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
    /// Colour scale kind.
    pub scale: ScaleKind,
}

impl Default for DisplayOptions {
    fn default() -> Self {
        Self { heat: true, grid: true, net: false, knots: true, boundary: true, scale: ScaleKind::Log }
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
}

impl Default for SolveSettings {
    fn default() -> Self {
        let d = SolveOptions::default();
        Self {
            operator: d.operator,
            min_elements: d.min_elements,
            refine: d.refine,
            fit_tol: d.fit.tol,
            basis: d.fit.basis,
            kinks: d.fit.kinks,
        }
    }
}

impl SolveSettings {
    /// The core's options with these settings.
    pub fn options(&self) -> SolveOptions {
        let mut o = SolveOptions {
            operator: self.operator,
            min_elements: self.min_elements.max(1),
            refine: self.refine,
            ..Default::default()
        };
        o.fit.tol = self.fit_tol;
        o.fit.basis = self.basis;
        o.fit.kinks = self.kinks;
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
        match Scene::open(path, self.sampler.as_ref(), self.settings) {
            Ok(scene) => {
                self.set_scene(scene);
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

    /// Replace the scene (cancels a running solve).
    pub fn set_scene(&mut self, scene: Scene) {
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
        opts.solve.min_elements = base.min_elements;
        opts.solve.refine = base.refine;
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
        let Some(job) = self.job.as_mut() else { return false };
        let changed = solution.is_some() || before != (job.state.clone(), job.progress.history.len());
        match (&job.state, solution) {
            (JobState::Finished, Some(sol)) => {
                self.status = Some(format!("solved {}: {}", sol.name, sol.report.message));
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
            if let Some(sol) = solution {
                self.status = Some(format!("solved {}: {}", sol.name, sol.report.message));
                if let Some(scene) = self.scene.as_mut() {
                    scene.set_solution(sol, self.sampler.as_ref(), self.settings);
                    self.refit = true;
                }
            }
        }
    }

    /// The colour scale of the current heat map.
    pub fn colour_scale(&self) -> Option<ColourScale> {
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
mod tests {
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
        assert_eq!(
            mv.certificate.verdict,
            winslow::solve::report::Verdict::DegenerateCorner,
            "{}",
            mv.certificate.message
        );
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
        let irregular = |v: &[winslow::domain::template::IrregularVertex]| {
            v.iter().map(|v| (v.point, v.valence)).collect::<Vec<_>>()
        };
        assert_eq!(irregular(l.irregular()), irregular(&auto.report.irregular_vertices));
        assert!(s.can_solve());
    }

    /// A multipatch layout of boundaries (G+Smo's plate with a hole, as JSON) opens as a
    /// layout to solve and solves like a domain's layout.
    #[test]
    fn opens_and_solves_a_layout_of_boundaries() {
        let scratch = tempfile::tempdir().unwrap();
        let winslow::Document::Layout(layout) =
            winslow::read(&data("gismo/xml/multipatch/plateWithHoleMP.xml")).unwrap()
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
        std::fs::write(&bad, r#"{"ring": {"inner": {"points": [[0,0],[2,0],[2,2],[0,2]]}, "outer": {"points": [[0.5,0.5],[1,0.5],[1,1],[0.5,1]]}}}"#).unwrap();
        t.open(&bad).unwrap();
        let p = t.scene.as_ref().unwrap().boundary.problem.clone().unwrap();
        assert!(p.contains("not inside") && !t.can_solve(), "{p}");
    }
}
