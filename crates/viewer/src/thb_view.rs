//! A THB map as drawn (paper §4: a map in a truncated hierarchical basis; issue 35): the
//! `det J` heat map sampled on the THB map itself, active cell by active cell
//! ([`sample_det_j_hierarchical`]: each grid point on the Bézier patch of its active
//! cell, the polynomial the certificate bounds), the active cells in the parameter
//! square and their borders in the physical domain (the PNG's geometry,
//! [`active_cell_borders`]), the control net of the active functions
//! ([`HierarchicalMap::control_net`], drawn by the app), and the verdict of the THB
//! certificate ([`certify_hierarchical`], active cell by active cell). Everything else a
//! map view shows (iso-lines, inversion under the pointer, the mesh overlay) is
//! read off the THB map's exact tensor form ([`HierarchicalMap::to_surface`]: knot
//! insertion on the lines of all active cells, the same polynomial on every cell).

use winslow::io::picture::active_cell_borders;
use winslow::pipeline::ThbReport;
use winslow::solve::report::Verdict;
use winslow::spline::hierarchical::map::HierarchicalMap;
use winslow::verify::certificate::hierarchical::{certify_hierarchical, HierarchicalCertificate};
use winslow::verify::certificate::CertifyOptions;
use winslow::verify::quality::sample_det_j_hierarchical;
use winslow::Point;

use crate::certificate::{det_j_details, Certificate, CertificateSource};
use crate::scene::{MapView, RESOLUTION_RANGE};

/// What a map view holds beyond the tensor form when the map is a THB map.
#[derive(Debug, Clone)]
pub struct ThbView {
    /// The THB map.
    pub map: HierarchicalMap,
    /// The active cells: level and parameter box `[[ξ_0, ξ_1], [η_0, η_1]]`.
    pub cells: Vec<(usize, [[f64; 2]; 2])>,
    /// The images of the active cells' edges (polylines of 9 points).
    pub borders: Vec<Vec<Point>>,
    /// Where the THB rounds started (the report's `start`), when the map came from a
    /// THB solve.
    pub start: Option<ThbStartView>,
}

/// The start of a THB solve's rounds as drawn: the contour fit's THB basis or the tensor
/// map (the report's `start`), its active cells on the levels of the final map.
#[derive(Debug, Clone, PartialEq)]
pub struct ThbStartView {
    /// `"contour"` or `"tensor"`.
    pub basis: String,
    /// THB functions of the start.
    pub functions: usize,
    /// Its verdict (before the rounds).
    pub verdict: String,
    /// Its active cells: level and parameter box (as [`ThbView::cells`]).
    pub cells: Vec<(usize, [[f64; 2]; 2])>,
}

impl ThbStartView {
    /// The start with the refined cells `refined` (per level) on the levels of `map`.
    pub fn new(
        map: &HierarchicalMap,
        basis: &str,
        functions: usize,
        verdict: &str,
        refined: &[Vec<[usize; 2]>],
    ) -> anyhow::Result<Self> {
        let b = map.basis.with_refined(refined)?;
        let cells = b.active_cells().into_iter().map(|(l, c)| (l, b.cell_bounds(l, c))).collect();
        Ok(Self { basis: basis.to_string(), functions, verdict: verdict.to_string(), cells })
    }

    /// The start of a THB report (`start`) as `winslow solve --refinement thb` writes it
    /// beside the map; `None` without one or when it does not fit the map.
    pub fn from_report(map: &HierarchicalMap, report: &serde_json::Value) -> Option<Self> {
        let s = report.get("start")?;
        let refined: Vec<Vec<[usize; 2]>> = serde_json::from_value(s.get("refined")?.clone()).ok()?;
        let functions = s.get("functions")?.as_u64()? as usize;
        Self::new(map, s.get("basis")?.as_str()?, functions, s.get("verdict")?.as_str()?, &refined).ok()
    }
}

impl ThbView {
    /// Levels of the hierarchy.
    pub fn levels(&self) -> usize {
        self.map.basis.num_levels()
    }
}

/// Default heat-map resolution of a THB map: eight cells per finest-level cell in the
/// finer direction, within `[96, 256]` (as [`crate::scene::default_resolution`]).
pub fn default_thb_resolution(map: &HierarchicalMap) -> usize {
    let l = map.basis.num_levels().saturating_sub(1);
    let e = map.basis.knots(l).each_ref().map(|k| k.num_elements());
    (8 * e[0].max(e[1])).clamp(96, 256)
}

impl Certificate {
    /// The verdict of the THB certificate of a map.
    pub fn of_thb(c: &HierarchicalCertificate) -> Self {
        let verdict = Verdict::of_finding(&c.verdict);
        let mut details = det_j_details(verdict, c.lower_bound, c.min_value_found, c.mean_det_j);
        details.extend([
            ("THB functions".to_string(), c.functions.to_string()),
            ("active cells / levels".to_string(), format!("{} / {}", c.cells, c.levels)),
            ("folded / undecided cells".to_string(), format!("{} / {}", c.folds.len(), c.undecided.len())),
        ]);
        Self { verdict, message: c.message(), source: CertificateSource::Exact, details }
    }

    /// The verdict of a THB solve run in the viewer (its certificate, rounds and the tensor
    /// solve it started from).
    pub fn from_thb_report(r: &ThbReport) -> Self {
        let mut c = Self::of_thb(&r.certificate);
        c.source = CertificateSource::Solver;
        c.message.clone_from(&r.message);
        c.details.push(("THB rounds".to_string(), r.thb_rounds.len().to_string()));
        c.details.push(("unknowns of the last round".to_string(), r.unknowns.to_string()));
        c
    }
}

impl MapView {
    /// Sample and prepare a THB map (see the module documentation); `certificate` is the
    /// verdict of a report if there is one, the THB certificate's otherwise.
    pub fn thb(
        map: HierarchicalMap,
        resolution: usize,
        density: usize,
        certificate: Option<Certificate>,
    ) -> anyhow::Result<Self> {
        use anyhow::Context;
        let n = resolution.clamp(RESOLUTION_RANGE.0, RESOLUTION_RANGE.1);
        let tensor = map.to_surface().context("the exact tensor form of the THB map")?;
        let sample = sample_det_j_hierarchical(&map, n).context("sampling det J on the THB cells")?;
        let exact = match certify_hierarchical(&map, &CertifyOptions::default()) {
            Ok(c) => Certificate::of_thb(&c),
            Err(e) => Certificate {
                verdict: Verdict::Undecided,
                message: format!("the THB certificate could not be computed: {e}"),
                source: CertificateSource::Exact,
                details: Vec::new(),
            },
        };
        let cells = map.basis.active_cells().into_iter().map(|(l, c)| (l, map.basis.cell_bounds(l, c))).collect();
        let borders = active_cell_borders(&map, &tensor);
        let mut mv = MapView::sampled(tensor, "cpu: THB cells".into(), sample, density, certificate, |_, _| exact);
        mv.thb = Some(ThbView { map, cells, borders, start: None });
        Ok(mv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use winslow::KnotVector;
    use winslow::Surface;

    /// An annulus sector as a quadratic map, refined near one corner into three levels.
    fn sector() -> HierarchicalMap {
        let k = KnotVector::open_uniform(2, 4);
        let g = k.greville();
        let cps =
            g.iter().flat_map(|&v| g.iter().map(move |&u| [(1.0 + v) * (1.3 * u).cos(), -(1.0 + v) * (1.3 * u).sin()]));
        let s = Surface::new([k.clone(), k], cps.collect(), None).unwrap();
        let m = HierarchicalMap::from_surface(&s).unwrap();
        let m = m.refined(&[(0, [0, 0]), (0, [1, 0])], 2).unwrap();
        m.refined(&[(1, [0, 0])], 2).unwrap()
    }

    #[test]
    fn a_thb_map_view_has_its_cells_borders_and_certificate() {
        let map = sector();
        let cells = map.basis.active_cells().len();
        let mv = MapView::thb(map.clone(), 64, 8, None).unwrap();
        let t = mv.thb.as_ref().unwrap();
        assert_eq!(t.cells.len(), cells);
        assert_eq!(t.levels(), 3);
        // every cell box lies in the unit square and they tile it: areas add up to one
        let area: f64 = t.cells.iter().map(|(_, b)| (b[0][1] - b[0][0]) * (b[1][1] - b[1][0])).sum();
        assert!((area - 1.0).abs() < 1e-12, "{area}");
        // one polyline per distinct cell edge
        assert!(t.borders.len() >= 2 * cells);
        for line in &t.borders {
            assert_eq!(line.len(), 9);
        }
        // the certified sector
        assert_eq!(mv.certificate.verdict, Verdict::Certified, "{}", mv.certificate.message);
        assert_eq!(mv.certificate.source, CertificateSource::Exact);
        // the sample is the THB map's det J: the probe and the grid agree with the library
        let n = mv.sample.n;
        for (i, j) in [(0, 0), (3, 5), (n / 2, n / 3), (n, n)] {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            let d = map.derivs(u, v);
            let det = d.xu[0] * d.xv[1] - d.xv[0] * d.xu[1];
            assert!((mv.sample.values[j * (n + 1) + i] - det).abs() < 1e-12 * det.abs().max(1.0));
            let (x, dj) = mv.probe([u, v]);
            assert!((dj - det).abs() < 1e-12 * det.abs().max(1.0));
            assert!((x[0] - d.x[0]).abs() < 1e-13 && (x[1] - d.x[1]).abs() < 1e-13);
        }
    }

    /// The start of a THB solve (puzzle4 on its input basis: the contour start on the
    /// input's coarsened levels) as the viewer draws it, from the solve's report and from
    /// the report as written beside the map (JSON): the same cells, as many as the
    /// report's `cells_per_level` say, tiling the unit square, each active cell of the
    /// repaired map inside one of them (the rounds only refine).
    #[test]
    fn the_start_of_a_thb_solve_is_drawn_from_its_report() {
        use winslow::io::{read_boundary, ReadOptions};
        use winslow::solve::options::{Refinement, SolveOptions};
        let b = read_boundary(&winslow::testutil::data("gismo/puzzle4.json"), &ReadOptions::default()).unwrap();
        let mut opts = SolveOptions::default();
        opts.repair.refinement = Refinement::Thb;
        let winslow::Solved::Thb(sol) = winslow::Pipeline::new(b, opts).solve().unwrap() else {
            panic!("puzzle4 is repaired by THB rounds")
        };
        let st = &sol.report.start;
        assert_eq!(st.basis, "contour");
        let view = ThbStartView::new(&sol.map, st.basis, st.functions, st.verdict.name(), &st.refined).unwrap();
        let json = serde_json::to_value(&sol.report).unwrap();
        assert_eq!(ThbStartView::from_report(&sol.map, &json).as_ref(), Some(&view));
        assert_eq!(view.cells.len(), st.cells_per_level.iter().sum::<usize>());
        assert_eq!(view.functions, st.functions_per_level.iter().sum::<usize>());
        let area: f64 = view.cells.iter().map(|(_, b)| (b[0][1] - b[0][0]) * (b[1][1] - b[1][0])).sum();
        assert!((area - 1.0).abs() < 1e-12, "{area}");
        let mv = MapView::thb(sol.map.clone(), 64, 8, None).unwrap();
        let t = mv.thb.as_ref().unwrap();
        assert!(t.cells.len() > view.cells.len());
        let inside = |c: &[[f64; 2]; 2], s: &[[f64; 2]; 2]| (0..2).all(|d| s[d][0] <= c[d][0] && c[d][1] <= s[d][1]);
        for (l, c) in &t.cells {
            let n = view.cells.iter().filter(|(ls, s)| ls <= l && inside(c, s)).count();
            assert_eq!(n, 1, "cell {c:?} of level {l}");
        }
        // a report without a start (or not of this map) gives none
        assert!(ThbStartView::from_report(&sol.map, &serde_json::json!({"verdict": "certified"})).is_none());
    }
}
