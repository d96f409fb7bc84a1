//! What is loaded, with everything the views draw computed once: the boundary as
//! polylines, and for a map its `det J` sample (from a [`DetJSampler`]), the images of
//! the sample grid and of the iso-lines of `xi` and `eta`, the control net, the folded
//! elements, the quality numbers and the verdict.

use std::path::{Path, PathBuf};

use winslow::boundary::ring::{ClosedContour, Ring};
use winslow::boundary::ring_fit::{check_ring, cut_open};
use winslow::boundary::validate::sample_side;
use winslow::domain::{auto_layout, graph_layout, LayoutOptions};
use winslow::io::{checked_boundary, read_with_report, Document, ReadOptions};
use winslow::multipatch::MultipatchSolution;
use winslow::pipeline::ThbSolution;
use winslow::solve::report::Solution;
use winslow::verify::quality::DetJSample;
use winslow::{Boundary, Point, Side, SideCurve, Surface};

use crate::certificate::{Certificate, Quality};
use crate::folds::{folded_elements, FoldedElement};
use crate::layout_view::LayoutView;
use crate::sampler::DetJSampler;
use crate::thb_view::{default_thb_resolution, ThbStartView, ThbView};
use crate::view::{bounds_of, Bounds};

/// Heat-map resolution bounds (cells per direction).
pub const RESOLUTION_RANGE: (usize, usize) = (16, 512);

/// A boundary as drawn: four polylines and the control polygons of spline sides.
#[derive(Debug, Clone)]
pub struct BoundaryView {
    /// The boundary (validated and counter-clockwise when `problem` is `None`).
    pub boundary: Boundary,
    /// South, east, north, west as polylines.
    pub polylines: [Vec<Point>; 4],
    /// Control polygons of the spline sides.
    pub control_polygons: Vec<Vec<Point>>,
    /// Why the boundary cannot be solved (validation error), if so.
    pub problem: Option<String>,
    /// Whether a clockwise input was transposed to make it counter-clockwise.
    pub reoriented: bool,
}

impl BoundaryView {
    /// Validate (transposing a clockwise contour) and sample a boundary.
    pub fn new(boundary: Boundary) -> Self {
        let (boundary, problem, reoriented) = match checked_boundary(boundary.clone(), &ReadOptions { reorient: true })
        {
            Ok((b, _)) => {
                let reoriented = !same_corners(&b, &boundary);
                (b, None, reoriented)
            }
            Err(e) => (boundary, Some(e.to_string()), false),
        };
        let polylines = Side::ALL.map(|s| sample_side(boundary.side(s), f64::INFINITY));
        let control_polygons = boundary
            .sides
            .iter()
            .filter_map(|s| match s {
                SideCurve::Spline(c) => Some(c.control_points.clone()),
                _ => None,
            })
            .collect();
        Self { boundary, polylines, control_polygons, problem, reoriented }
    }

    /// Bounds of the polylines.
    pub fn bounds(&self) -> Option<Bounds> {
        bounds_of(self.polylines.iter().flatten())
    }
}

impl BoundaryView {
    /// A ring's two closed contours (paper §11.1): west the inner and east the outer one,
    /// south and north the seam segment between their starts; the problem is the ring's
    /// check ([`check_ring`]: closed, counter-clockwise, nested).
    pub fn ring(ring: &Ring) -> Self {
        let problem = check_ring(ring).err().map(|e| e.to_string());
        let closed = |c: &ClosedContour| {
            let mut p = c.polygon_with(512);
            if let Some(&q) = p.first() {
                p.push(q);
            }
            p
        };
        let (inner, outer) = (closed(&ring.inner), closed(&ring.outer));
        let seam: Vec<Point> = inner.first().into_iter().chain(outer.first()).copied().collect();
        let control_polygons = [&ring.inner, &ring.outer]
            .into_iter()
            .filter_map(|c| match c {
                ClosedContour::Spline(s) => Some(s.control_points.clone()),
                _ => None,
            })
            .collect();
        let boundary =
            cut_open(ring, [seam.first().copied().unwrap_or_default(), seam.last().copied().unwrap_or_default()]);
        Self { boundary, polylines: [seam.clone(), outer, seam, inner], control_polygons, problem, reoriented: false }
    }
}

fn same_corners(a: &Boundary, b: &Boundary) -> bool {
    a.side(Side::South).endpoints() == b.side(Side::South).endpoints()
}

/// Iso-lines of a map: images of `xi = const` and `eta = const`.
#[derive(Debug, Clone, Default)]
pub struct IsoLines {
    /// Lines per direction (the parameter square is cut into this many strips).
    pub density: usize,
    /// `xi = k / density`, `k = 1 .. density - 1`: curves along `eta`.
    pub xi: Vec<Vec<Point>>,
    /// `eta = k / density`: curves along `xi`.
    pub eta: Vec<Vec<Point>>,
}

impl IsoLines {
    /// Evaluate `density - 1` interior iso-lines per direction with `points` points each.
    pub fn new(map: &Surface, density: usize, points: usize) -> Self {
        let points = points.max(2);
        let (du, dv) = (map.knots[0].domain(), map.knots[1].domain());
        let at = |d: (f64, f64), t: f64| d.0 + (d.1 - d.0) * t;
        let line = |fixed_xi: Option<f64>, fixed_eta: Option<f64>| -> Vec<Point> {
            (0..points)
                .map(|k| {
                    let t = k as f64 / (points - 1) as f64;
                    let u = fixed_xi.unwrap_or_else(|| at(du, t));
                    let v = fixed_eta.unwrap_or_else(|| at(dv, t));
                    map.eval(u, v)
                })
                .collect()
        };
        let ts: Vec<f64> = (1..density).map(|k| k as f64 / density as f64).collect();
        Self {
            density,
            xi: ts.iter().map(|&t| line(Some(at(du, t)), None)).collect(),
            eta: ts.iter().map(|&t| line(None, Some(at(dv, t)))).collect(),
        }
    }
}

/// A map as drawn.
#[derive(Debug, Clone)]
pub struct MapView {
    /// The map.
    pub map: Surface,
    /// Name of the sampler that produced `sample`.
    pub sampler: String,
    /// `det J` on the `(n+1)^2` grid.
    pub sample: DetJSample,
    /// `x` at the same grid points (same layout).
    pub positions: Vec<Point>,
    /// Bounds of the image.
    pub bounds: Bounds,
    /// The map's four sides as polylines (south, east, north, west).
    pub sides: [Vec<Point>; 4],
    /// Iso-lines.
    pub iso: IsoLines,
    /// Interior knot lines in the parameter square, `xi` then `eta`.
    pub breaks: [Vec<f64>; 2],
    /// Elements with `det J <= 0` samples.
    pub folds: Vec<FoldedElement>,
    /// Quality numbers.
    pub quality: Quality,
    /// The verdict shown.
    pub certificate: Certificate,
    /// The core's exact certificate of this map (shown too when `certificate` is from a report).
    pub exact_certificate: Certificate,
    /// The solver's level reports, when the map was solved in the viewer.
    pub report: Option<winslow::solve::report::Report>,
    /// Matched point pairs of the constrained reparameterization (paper §7.2), from the
    /// solver's report or the one stored in the map file.
    pub matches: Vec<(Point, Point)>,
    /// Kinks of the boundary (paper §9) and whether the map keeps them exactly, from the
    /// solver's report or the one stored in the map file.
    pub kinks: Vec<(Point, bool)>,
    /// The THB map this view shows (`map` is then its exact tensor form): its active
    /// cells, their borders and the THB certificate ([`crate::thb_view`]).
    pub thb: Option<ThbView>,
}

/// The matched pairs stored in a map file's `"report"` (`reparam.matches[].points`).
pub fn stored_matches(report: &serde_json::Value) -> Vec<(Point, Point)> {
    winslow::boundary::reparam::matches_in_report(report)
}

/// Default heat-map resolution: eight cells per element in the finer direction, within
/// `[96, 256]`.
pub fn default_resolution(map: &Surface) -> usize {
    let e = map.knots[0].num_elements().max(map.knots[1].num_elements());
    (8 * e).clamp(96, 256)
}

impl MapView {
    /// Sample and prepare `map`; `certificate` is the verdict of a report if there is one.
    pub fn new(
        map: Surface,
        sampler: &dyn DetJSampler,
        resolution: usize,
        density: usize,
        certificate: Option<Certificate>,
    ) -> Self {
        let n = resolution.clamp(RESOLUTION_RANGE.0, RESOLUTION_RANGE.1);
        let sample = sampler.sample(&map, n);
        Self::sampled(map, sampler.name().to_string(), sample, density, certificate, Certificate::exact)
    }

    /// Prepare `map` with its `det J` sample (made by `sampler`); `exact` gives the exact
    /// certificate of the map from its quality numbers.
    pub(crate) fn sampled(
        map: Surface,
        sampler: String,
        sample: DetJSample,
        density: usize,
        certificate: Option<Certificate>,
        exact: impl FnOnce(&Surface, &Quality) -> Certificate,
    ) -> Self {
        let n = sample.n;
        let (du, dv) = (map.knots[0].domain(), map.knots[1].domain());
        let mut positions = Vec::with_capacity((n + 1) * (n + 1));
        for j in 0..=n {
            let v = dv.0 + (dv.1 - dv.0) * j as f64 / n as f64;
            for i in 0..=n {
                positions.push(map.eval(du.0 + (du.1 - du.0) * i as f64 / n as f64, v));
            }
        }
        let bounds = bounds_of(&positions).unwrap_or([[0.0, 0.0], [1.0, 1.0]]);
        let sides = Side::ALL.map(|s| map.boundary(s).sample(4 * n));
        let iso = IsoLines::new(&map, density, 2 * n + 1);
        let inner = |b: Vec<f64>| b[1..b.len().saturating_sub(1)].to_vec();
        let breaks = [inner(map.knots[0].breaks()), inner(map.knots[1].breaks())];
        let quality = Quality::of(&map, &sample);
        let folds = folded_elements(&map, &sample, quality.forced_corners());
        let exact_certificate = exact(&map, &quality);
        let certificate = certificate.unwrap_or_else(|| exact_certificate.clone());
        Self {
            map,
            sampler,
            sample,
            positions,
            bounds,
            sides,
            iso,
            breaks,
            folds,
            quality,
            certificate,
            exact_certificate,
            report: None,
            matches: Vec::new(),
            kinks: Vec::new(),
            thb: None,
        }
    }

    /// Heat-map cells per direction.
    pub fn resolution(&self) -> usize {
        self.sample.n
    }

    /// `det J` and `x` at a parameter point (core evaluation; of a THB map, on its
    /// active cell).
    pub fn probe(&self, q: [f64; 2]) -> (Point, f64) {
        let d = match &self.thb {
            Some(t) => t.map.derivs(q[0], q[1]),
            None => self.map.derivs(q[0], q[1], 1),
        };
        (d.x, d.det_j())
    }

    /// The parameter point of a physical point, if it lies in the image: Newton
    /// inversion ([`Surface::invert`]) started from the nearest sample-grid point.
    pub fn invert(&self, p: Point) -> Option<[f64; 2]> {
        let n = self.sample.n;
        let (mut best, mut arg) = (f64::INFINITY, 0);
        for (k, x) in self.positions.iter().enumerate() {
            let d = (x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2);
            if d < best {
                (best, arg) = (d, k);
            }
        }
        let start = [(arg % (n + 1)) as f64 / n as f64, (arg / (n + 1)) as f64 / n as f64];
        let diam = (self.bounds[1][0] - self.bounds[0][0]).hypot(self.bounds[1][1] - self.bounds[0][1]);
        self.map.invert(p, start, 1e-10 * diam.max(f64::MIN_POSITIVE))
    }
}

/// Everything loaded from one file (or solved in the viewer).
#[derive(Debug, Clone)]
pub struct Scene {
    /// Geometry name.
    pub name: String,
    /// File it came from.
    pub path: Option<PathBuf>,
    /// What the file was ("boundary", "map", "THB map", "multipatch", "ring", "ring map", "domain",
    /// "graph", "layout").
    pub kind: &'static str,
    /// The ring (O-grid, `eta` periodic) a solve fits: of a ring document, or the two
    /// contours of a map with `eta` periodic.
    pub ring: Option<Ring>,
    /// The boundary (of a boundary file, or the sides of a map): what `solve` uses.
    pub boundary: BoundaryView,
    /// The map, if any.
    pub map: Option<MapView>,
    /// The other patches of a multipatch layout (paper §11.2): `map` is the first patch
    /// (the one the side panel and the parameter view describe), these are drawn beside
    /// it in the physical view, on one colour scale.
    pub patches: Vec<MapView>,
    /// A multipatch layout to solve (a laid-out domain or plane graph, or a layout of
    /// boundaries): its borders, outline and irregular vertices; what `solve` uses.
    pub layout: Option<LayoutView>,
}

/// Display settings that change what the scene computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneSettings {
    /// Heat-map cells per direction (`None`: [`default_resolution`]).
    pub resolution: Option<usize>,
    /// Iso-lines per direction.
    pub density: usize,
}

impl Default for SceneSettings {
    fn default() -> Self {
        Self { resolution: None, density: 16 }
    }
}

impl Scene {
    /// Read any document [`winslow::io::read`] reads that has something to draw: a
    /// boundary, a map (with the report a solve stored beside it), a ring, a multipatch
    /// layout or result.
    pub fn open(path: &Path, sampler: &dyn DetJSampler, settings: SceneSettings) -> anyhow::Result<Self> {
        use anyhow::Context;
        let (doc, report) = read_with_report(path).with_context(|| format!("reading {}", path.display()))?;
        Self::from_read(path, doc, report, sampler, settings)
    }

    /// [`Scene::open`] of a document already read from `path` with its stored report.
    pub fn from_read(
        path: &Path,
        doc: Document,
        report: Option<serde_json::Value>,
        sampler: &dyn DetJSampler,
        settings: SceneSettings,
    ) -> anyhow::Result<Self> {
        use anyhow::Context;
        // a map file may carry the solver's report
        let report = report.filter(|_| matches!(doc, Document::Map { .. } | Document::Thb { .. }));
        let stored = report.as_ref().and_then(Certificate::from_stored);
        let mut scene = Self::from_document(doc, sampler, settings, stored)
            .with_context(|| format!("opening {}", path.display()))?;
        if let (Some(mv), Some(r)) = (scene.map.as_mut(), &report) {
            mv.matches = stored_matches(r);
            mv.kinks = winslow::boundary::kinks::kinks_in_report(r);
            if let Some(t) = mv.thb.as_mut() {
                t.start = ThbStartView::from_report(&t.map, r);
            }
        }
        scene.path = Some(path.to_path_buf());
        Ok(scene)
    }

    /// A scene of a ring document: its contours, solved as a ring.
    pub fn from_ring(ring: Ring) -> Self {
        let boundary = BoundaryView::ring(&ring);
        Self {
            name: ring.name.clone(),
            path: None,
            kind: "ring",
            boundary,
            map: None,
            patches: Vec::new(),
            ring: Some(ring),
            layout: None,
        }
    }

    /// A scene of a document; a volume is an error (the viewer draws planar documents).
    pub fn from_document(
        doc: Document,
        sampler: &dyn DetJSampler,
        settings: SceneSettings,
        certificate: Option<Certificate>,
    ) -> anyhow::Result<Self> {
        use anyhow::Context;
        Ok(match doc {
            Document::Boundary(b) => Self {
                name: b.name.clone(),
                path: None,
                kind: "boundary",
                boundary: BoundaryView::new(b),
                map: None,
                patches: Vec::new(),
                ring: None,
                layout: None,
            },
            Document::Map { name, map } => {
                let res = settings.resolution.unwrap_or_else(|| default_resolution(&map));
                // a map with eta periodic (an O-grid) is bounded by two closed contours
                let ring = map.knots[1].is_periodic().then(|| Ring {
                    name: name.clone(),
                    inner: ClosedContour::Spline(map.boundary(Side::West)),
                    outer: ClosedContour::Spline(map.boundary(Side::East)),
                });
                let (kind, boundary) = match &ring {
                    Some(r) => ("ring map", BoundaryView::ring(r)),
                    None => ("map", BoundaryView::new(Document::Map { name: name.clone(), map: map.clone() }.into_boundary()?)),
                };
                Self {
                    name,
                    path: None,
                    kind,
                    boundary,
                    map: Some(MapView::new(map, sampler, res, settings.density, certificate)),
                    patches: Vec::new(),
                    ring,
                    layout: None,
                }
            }
            Document::Ring(ring) => Self::from_ring(ring),
            // a layout as given (G+Smo's patches are maps, the input's initial ones) is
            // solved from its patches' sides; a result is only shown
            Document::Layout(layout) => {
                let view = LayoutView::new(layout.clone(), None);
                let mut scene = Self::from_layout(layout, sampler, settings)?;
                scene.layout.get_or_insert(view);
                scene
            }
            Document::Multipatch(layout) => Self::from_layout(layout, sampler, settings)?,
            Document::Domain(d) => {
                let auto = auto_layout(&d, &LayoutOptions::default())
                    .with_context(|| format!("laying out the domain {}", d.name))?;
                Self::from_layout_view(LayoutView::of_auto(auto), "domain")?
            }
            Document::Graph(g) => {
                let auto = graph_layout(&g, &LayoutOptions::default())
                    .with_context(|| format!("laying out the plane graph {}", g.name))?;
                Self::from_layout_view(LayoutView::of_auto(auto), "graph")?
            }
            doc @ (Document::Volume { .. } | Document::VolumeBoundary(_)) => {
                return Err(doc
                    .wrong_kind(None, "a planar document here (the viewer opens a volume file as three slices; the faces of a volume are solved by `winslow solve`)")
                    .into())
            }
            Document::Thb { name, map } => {
                let res = settings.resolution.unwrap_or_else(|| default_thb_resolution(&map));
                let mv = MapView::thb(map, res, settings.density, certificate)?;
                let sides = Document::Map { name: name.clone(), map: mv.map.clone() }.into_boundary()?;
                Self {
                    name,
                    path: None,
                    kind: "THB map",
                    boundary: BoundaryView::new(sides),
                    map: Some(mv),
                    patches: Vec::new(),
                    ring: None,
                    layout: None,
                }
            }
        })
    }

    /// A scene of a layout to solve (kind `kind`): its borders, outline and irregular
    /// vertices, no map until it is solved ([`Scene::set_layout_solution`]). The boundary
    /// is the first patch's (drawn only through the borders).
    pub fn from_layout_view(view: LayoutView, kind: &'static str) -> anyhow::Result<Self> {
        let layout = &view.layout;
        let Some(first) = layout.patches.first() else {
            anyhow::bail!("the multipatch layout {} has no patches", layout.name)
        };
        let boundary = Boundary { name: first.name.clone(), sides: first.sides.clone().map(SideCurve::Spline) };
        Ok(Self {
            name: format!("{} ({} patches)", layout.name, layout.patches.len()),
            path: None,
            kind,
            boundary: BoundaryView::new(boundary),
            map: None,
            patches: Vec::new(),
            ring: None,
            layout: Some(view),
        })
    }

    /// A scene of a multipatch layout. Patches that are maps (a G+Smo multipatch file,
    /// or the output of `winslow solve` on a layout): the first patch is `map`, the
    /// others are `patches`; each is judged by the exact certificate. A layout with a
    /// patch given by its boundary (an input document) is a layout to solve
    /// ([`Scene::from_layout_view`]).
    pub fn from_layout(
        layout: winslow::multipatch::Layout,
        sampler: &dyn DetJSampler,
        settings: SceneSettings,
    ) -> anyhow::Result<Self> {
        if layout.patches.is_empty() || layout.patches.iter().any(|p| p.map.is_none()) {
            return Self::from_layout_view(LayoutView::new(layout, None), "layout");
        }
        let mut views = Vec::with_capacity(layout.patches.len());
        for map in layout.patches.iter().filter_map(|p| p.map.as_ref()) {
            let res = settings.resolution.unwrap_or_else(|| default_resolution(map));
            views.push(MapView::new(map.clone(), sampler, res, settings.density, None));
        }
        let first = views.remove(0);
        let doc = Document::Map { name: layout.patches[0].name.clone(), map: first.map.clone() };
        Ok(Self {
            name: format!("{} ({} patches)", layout.name, layout.patches.len()),
            path: None,
            kind: "multipatch",
            boundary: BoundaryView::new(doc.into_boundary()?),
            map: Some(first),
            patches: views,
            ring: None,
            layout: None,
        })
    }

    /// Put a solved layout into the scene: every patch's map with its certificate from
    /// the layout solve, the first as `map`, on one colour scale; the layout's borders,
    /// outline and irregular vertices stay.
    pub fn set_layout_solution(
        &mut self,
        solution: MultipatchSolution,
        sampler: &dyn DetJSampler,
        settings: SceneSettings,
    ) {
        let mut views: Vec<MapView> = solution
            .patches
            .into_iter()
            .map(|p| {
                let res = settings.resolution.unwrap_or_else(|| default_resolution(&p.map));
                let cert = Certificate::of_patch(&p);
                let mut mv = MapView::new(p.map, sampler, res, settings.density, Some(cert));
                mv.report = Some(p.solve);
                mv
            })
            .collect();
        if views.is_empty() {
            return;
        }
        self.map = Some(views.remove(0));
        self.patches = views;
        if let Some(l) = self.layout.as_mut() {
            l.solved = Some(solution.report);
        }
    }

    /// Every map of the scene: the map, then the other patches.
    pub fn maps(&self) -> impl Iterator<Item = &MapView> {
        self.map.iter().chain(&self.patches)
    }

    /// Put a solver's map into the scene (keeps the input boundary).
    pub fn set_solution(&mut self, solution: Solution, sampler: &dyn DetJSampler, settings: SceneSettings) {
        let res = settings.resolution.unwrap_or_else(|| default_resolution(&solution.map));
        let cert = Certificate::from_report(&solution.report);
        let mut mv = MapView::new(solution.map, sampler, res, settings.density, Some(cert));
        mv.matches = solution.report.fit.reparam.segments();
        mv.kinks = solution.report.boundary.kinks.iter().map(|k| (k.point, k.kept)).collect();
        mv.report = Some(solution.report);
        self.map = Some(mv);
    }

    /// Put a THB solve's map into the scene (keeps the input boundary): its verdict from
    /// the THB certificate, the report of the tensor solve it started from.
    pub fn set_thb_solution(&mut self, solution: ThbSolution, settings: SceneSettings) -> anyhow::Result<()> {
        let res = settings.resolution.unwrap_or_else(|| default_thb_resolution(&solution.map));
        let cert = Certificate::from_thb_report(&solution.report);
        let mut mv = MapView::thb(solution.map, res, settings.density, Some(cert))?;
        if let Some(t) = mv.thb.as_mut() {
            let st = &solution.report.start;
            let v = ThbStartView::new(&t.map, st.basis, st.functions, st.verdict.name(), &st.refined)?;
            t.start = Some(v);
        }
        mv.kinks = solution.report.solve.boundary.kinks.iter().map(|k| (k.point, k.kept)).collect();
        mv.report = Some(solution.report.solve);
        self.map = Some(mv);
        Ok(())
    }

    /// Put a map without a solver report into the scene (a method of a comparison): its
    /// verdict is the core's exact certificate; the input boundary stays.
    pub fn set_map(&mut self, map: Surface, sampler: &dyn DetJSampler, settings: SceneSettings) {
        let res = settings.resolution.unwrap_or_else(|| default_resolution(&map));
        self.map = Some(MapView::new(map, sampler, res, settings.density, None));
    }

    /// Recompute what depends on the settings (after a change of resolution or density).
    pub fn apply_settings(&mut self, sampler: &dyn DetJSampler, settings: SceneSettings) {
        let again = |mv: MapView| {
            let res = settings.resolution.unwrap_or_else(|| default_resolution(&mv.map));
            let (report, matches, kinks) = (mv.report, mv.matches, mv.kinks);
            use crate::certificate::CertificateSource;
            let cert = matches!(mv.certificate.source, CertificateSource::Solver | CertificateSource::File)
                .then_some(mv.certificate);
            let mut new = match mv.thb {
                Some(t) => {
                    let res = settings.resolution.unwrap_or_else(|| default_thb_resolution(&t.map));
                    // drawn before, so it draws again; were it to fail, the tensor form's sample
                    match MapView::thb(t.map.clone(), res, settings.density, cert.clone()) {
                        Ok(mut v) => {
                            if let Some(n) = v.thb.as_mut() {
                                n.start = t.start;
                            }
                            v
                        }
                        Err(_) => {
                            MapView { thb: Some(t), ..MapView::new(mv.map, sampler, res, settings.density, cert) }
                        }
                    }
                }
                None => MapView::new(mv.map, sampler, res, settings.density, cert),
            };
            new.report = report;
            new.matches = matches;
            new.kinks = kinks;
            new
        };
        self.patches = std::mem::take(&mut self.patches).into_iter().map(again).collect();
        self.map = self.map.take().map(again);
    }

    /// Bounds of what is drawn in the physical view.
    pub fn bounds(&self) -> Bounds {
        let b = match &self.layout {
            Some(l) => l.bounds(),
            None => self.boundary.bounds(),
        };
        let b = self.patches.iter().fold(b, |acc, m| match acc {
            Some(a) => Some([
                [a[0][0].min(m.bounds[0][0]), a[0][1].min(m.bounds[0][1])],
                [a[1][0].max(m.bounds[1][0]), a[1][1].max(m.bounds[1][1])],
            ]),
            None => Some(m.bounds),
        });
        match (&self.map, b) {
            (Some(m), Some(b)) => [
                [m.bounds[0][0].min(b[0][0]), m.bounds[0][1].min(b[0][1])],
                [m.bounds[1][0].max(b[1][0]), m.bounds[1][1].max(b[1][1])],
            ],
            (Some(m), None) => m.bounds,
            (None, Some(b)) => b,
            (None, None) => [[0.0, 0.0], [1.0, 1.0]],
        }
    }
}

#[cfg(test)]
mod matches_tests {
    use super::stored_matches;

    #[test]
    fn matches_are_read_from_a_stored_report() {
        let r = serde_json::json!({ "reparam": { "matches": [
            { "sides": ["south", "north"], "parameter": 0.5, "points": [[0.0, 1.0], [0.0, 1.1]] },
            { "sides": ["south", "north"], "parameter": 0.7, "points": "malformed" }
        ] } });
        assert_eq!(stored_matches(&r), vec![([0.0, 1.0], [0.0, 1.1])]);
        assert!(stored_matches(&serde_json::json!({ "verdict": "certified" })).is_empty());
    }
}
