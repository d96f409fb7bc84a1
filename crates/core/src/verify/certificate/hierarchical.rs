//! The certificate of a THB map ([`HierarchicalMap`], paper §4 and §8.1): on every active
//! cell the map is one polynomial of degree `(p, q)`, so `det J` is a polynomial of degree
//! `(2p - 1, 2q - 1)` there and its Bernstein form is exact, as on the elements of a
//! tensor map. Each active cell is extracted to its Bézier patch
//! (`HierarchicalMap::bezier_patches`) and examined by the same element search as a
//! tensor map's elements (proof box by box, fold witnesses, subdivision), with the
//! domain's corners and sides excused only where the cell touches them.
//!
//! **Rounding.** The search bounds the rounding of `det J` from the patch's `f64` Bézier
//! net on. The net itself is computed from the THB coefficients by the truncation
//! recursion and blossoming in floating point, whose rounding (a few units in the last
//! place of the net, relative to the control points) is not bounded: the verdict is
//! rigorous for the Bézier patches, the map up to that conversion.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use super::element::Elements;
use super::search::{self, Totals};
use super::{corner_info, folded_message, undecided_message, CertifyOptions, CornerInfo, ExcusedPoint, Finding};
use crate::error::Result;
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::hierarchical::Index2;
use crate::spline::surface::Side;

/// An active cell: its level and index per direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct CellIndex {
    /// Level.
    pub level: usize,
    /// Cell `(i, j)` of that level.
    pub cell: Index2,
}

/// A fold proven on an active cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellFold {
    /// The cell.
    #[serde(flatten)]
    pub at: CellIndex,
    /// Parameter point `(xi, eta)`.
    pub param: [f64; 2],
    /// `det J` there.
    pub value: f64,
    /// Its rounding bound (`value < -error_bound`).
    pub error_bound: f64,
}

/// The bijectivity certificate of a THB map, active cell by active cell.
#[derive(Debug, Clone, Serialize)]
pub struct HierarchicalCertificate {
    /// The verdict.
    pub verdict: Finding,
    /// Proven lower bound of `det J` over the proven cells (excused ones excluded).
    pub lower_bound: f64,
    /// Mean of `det J` over the parameter domain.
    pub mean_det_j: f64,
    /// Smallest value of `det J` met (sub-box corners and fold witnesses).
    pub min_value_found: f64,
    /// Degrees of the `det J` polynomial.
    pub det_degree: [usize; 2],
    /// The four corners of the domain.
    pub corners: Vec<CornerInfo>,
    /// Active cells examined.
    pub cells: usize,
    /// Levels of the hierarchy.
    pub levels: usize,
    /// THB functions (unknowns of the map).
    pub functions: usize,
    /// Sub-boxes examined in total.
    pub boxes: usize,
    /// Deepest bisection level used.
    pub max_depth: usize,
    /// Cells near forced corners or zero-speed points, not proven positive there.
    pub excused: Vec<CellIndex>,
    /// Zero-speed points of the sides excused like forced corners.
    pub excused_points: Vec<ExcusedPoint>,
    /// Cells with a proven fold.
    pub folds: Vec<CellFold>,
    /// Cells left undecided.
    pub undecided: Vec<CellIndex>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

impl HierarchicalCertificate {
    /// The cells a local defect correction should refine: folded and undecided ones.
    pub fn offending_cells(&self) -> Vec<CellIndex> {
        let mut v: Vec<CellIndex> = self.folds.iter().map(|f| f.at).chain(self.undecided.iter().copied()).collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// A sentence describing the verdict.
    pub fn message(&self) -> String {
        let where_ = format!("{} active cells of {} levels, {} THB functions", self.cells, self.levels, self.functions);
        match &self.verdict {
            Finding::Certified { lower_bound, relative } => format!(
                "certified bijective: det J >= {lower_bound:.4e} ({relative:.3e} of its mean) proven on all {where_} \
                 ({} Bernstein boxes, rounding bounded)",
                self.boxes
            ),
            Finding::DegenerateCorner { corners, lower_bound, .. } => format!(
                "degenerate corner: the boundary forces det J <= 0 at the {} corner(s) and {} zero-speed point(s); det \
                 J >= {lower_bound:.4e} is proven everywhere else ({where_})",
                corners.join(" and "),
                self.excused_points.len()
            ),
            Finding::Folded { param, point, value, error_bound, one_sided } => {
                format!(
                    "{} ({where_})",
                    folded_message(param, point, *value, *error_bound, one_sided, self.folds.len())
                )
            }
            Finding::Undecided { .. } => {
                let info: Vec<super::Undecided<2>> = Vec::new();
                format!(
                    "{} ({where_})",
                    undecided_message(self.undecided.len(), &info, self.max_depth, self.min_value_found)
                )
            }
        }
    }
}

/// Certify `det J > 0` on a THB map, active cell by active cell in parallel.
pub fn certify_hierarchical(map: &HierarchicalMap, opts: &CertifyOptions) -> Result<HierarchicalCertificate> {
    let t0 = Instant::now();
    let basis = &map.basis;
    let patches = map.bezier_patches()?;
    let dom = basis.knots(0).each_ref().map(|kv| kv.domain());
    let on = |x: f64, (a, b): (f64, f64)| [x == a, x == b];
    let results: Vec<_> = patches
        .par_iter()
        .map(|(l, c, patch)| -> Result<_> {
            let el = Elements::surface(patch)?;
            let [[a, b], [cc, dd]] = basis.cell_bounds(*l, *c);
            let sides = [on(cc, dom[1])[0], on(b, dom[0])[1], on(dd, dom[1])[1], on(a, dom[0])[0]];
            let mut tmp = vec![0.0; el.deg.len()];
            Ok((sides, search::examine_surface_on(&el, [0, 0], sides, opts, &mut tmp)))
        })
        .collect::<Result<_>>()?;
    let mut corners: Vec<CornerInfo> = Vec::new();
    let mut totals = Totals::new();
    let (mut excused, mut excused_points, mut folds, mut undecided) = (vec![], vec![], vec![], vec![]);
    let det_degree = basis.degrees().map(|p| 2 * p - 1);
    // the domain's corners from the patches of the cells at them
    let corner_of = |s: [bool; 4]| [s[0] && s[3], s[0] && s[1], s[2] && s[1], s[2] && s[3]];
    let mut slots: Vec<Option<CornerInfo>> = vec![None; 4];
    for ((l, c, patch), (sides, r)) in patches.iter().zip(results) {
        let at = CellIndex { level: *l, cell: *c };
        let at_corner = corner_of(sides);
        for k in 0..4 {
            if at_corner[k] {
                let mut info = corner_info(patch)[k].clone();
                info.forbids_positivity |= r.forced & (1 << k) != 0;
                info.excused_extent = r.result.excused[k];
                slots[k] = Some(info);
            }
            if let Some(ext) = r.result.excused[4 + k] {
                let [bu, bv] = basis.cell_bounds(*l, *c);
                let local = [(0, 0), (1, 0), (1, 1), (0, 1)][k];
                let param = [bu[local.0], bv[local.1]];
                let side = if local.1 == 0 && sides[0] {
                    Side::South
                } else if local.1 == 1 && sides[2] {
                    Side::North
                } else if local.0 == 0 && sides[3] {
                    Side::West
                } else {
                    Side::East
                };
                match excused_points.iter_mut().find(|p: &&mut ExcusedPoint| p.param == param) {
                    Some(p) => p.extent = [p.extent[0].max(ext[0]), p.extent[1].max(ext[1])],
                    None => excused_points.push(ExcusedPoint {
                        side: side.name(),
                        param,
                        point: map.eval(param[0], param[1]),
                        extent: ext,
                    }),
                }
            }
        }
        if r.result.excused.iter().any(Option::is_some) {
            excused.push(at);
        }
        if let Some(f) = &r.result.fold {
            folds.push(CellFold { at, param: f.param, value: f.value, error_bound: f.error_bound });
        } else if r.result.undecided.is_some() {
            undecided.push(at);
        }
        totals.add(r.result, r.integral);
    }
    corners.extend(slots.into_iter().flatten());
    let par_area = (dom[0].1 - dom[0].0) * (dom[1].1 - dom[1].0);
    let mean_det_j = totals.integral / par_area;
    let relative = totals.lower_bound / mean_det_j;
    let degenerate: Vec<&'static str> =
        corners.iter().filter(|c| c.excused_extent.is_some()).map(|c| c.corner).collect();
    let points: Vec<[f64; 2]> = excused_points.iter().map(|p| p.param).collect();
    let verdict = match totals.finding(|u| map.eval(u[0], u[1]), relative) {
        Finding::Certified { lower_bound, relative } if !degenerate.is_empty() || !points.is_empty() => {
            Finding::DegenerateCorner { corners: degenerate, points, lower_bound, relative }
        }
        found => found,
    };
    Ok(HierarchicalCertificate {
        verdict,
        lower_bound: totals.lower_bound,
        mean_det_j,
        min_value_found: totals.min_value_found,
        det_degree,
        corners,
        cells: patches.len(),
        levels: basis.num_levels(),
        functions: basis.len(),
        boxes: totals.boxes,
        max_depth: totals.max_depth,
        excused,
        excused_points,
        folds,
        undecided,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;
    use crate::spline::surface::Surface;
    use crate::testutil::Lcg;

    /// A curved, bijective tensor map (an annulus sector) refined around two cells.
    fn refined_sector() -> HierarchicalMap {
        let kv = |p: usize| KnotVector::open_uniform(p, 4);
        let knots = [kv(3), kv(2)];
        let [nx, ny] = [knots[0].num_basis(), knots[1].num_basis()];
        let (gx, gy) = (knots[0].greville(), knots[1].greville());
        let mut cps = Vec::new();
        for &v in gy.iter().take(ny) {
            for &u in gx.iter().take(nx) {
                let (r, t) = (1.0 + u, 0.3 + 1.2 * v);
                cps.push([r * t.cos(), r * t.sin()]);
            }
        }
        let s = Surface::new(knots, cps, None).unwrap();
        let map = HierarchicalMap::from_surface(&s).unwrap();
        let map = map.refined(&[(0, [1, 1]), (0, [3, 0])], 2).unwrap();
        let (l, c) = map.basis.cell_at(0.3, 0.3);
        map.refined(&[(l, c)], 2).unwrap()
    }

    #[test]
    fn bounds_per_cell_against_dense_sampling() {
        let map = refined_sector();
        let cert = certify_hierarchical(&map, &CertifyOptions::default()).unwrap();
        assert_eq!(cert.verdict.name(), "certified", "{}", cert.message());
        assert_eq!(cert.cells, map.basis.active_cells().len());
        assert!(cert.levels >= 3);
        let mut rng = Lcg::new(1);
        let mut min = f64::INFINITY;
        let mut sum = 0.0;
        let n = 20000;
        for _ in 0..n {
            let d = map.derivs(rng.uniform(), rng.uniform());
            min = min.min(d.det_j());
            sum += d.det_j();
        }
        assert!(cert.lower_bound <= min, "bound {} above a sampled value {min}", cert.lower_bound);
        assert!(cert.lower_bound > 0.5 * min, "bound {} far below the sampled minimum {min}", cert.lower_bound);
        assert!((cert.mean_det_j - sum / n as f64).abs() < 0.02 * cert.mean_det_j, "mean {}", cert.mean_det_j);
        // the same verdict as the tensor map it converts to
        let tensor =
            crate::verify::certificate::certify(&map.to_surface().unwrap(), &CertifyOptions::default()).unwrap();
        assert_eq!(tensor.verdict.name(), "certified");
        assert!((tensor.mean_det_j - cert.mean_det_j).abs() < 1e-12 * cert.mean_det_j);
        // per cell, the Bernstein bound is below dense samples of the cell
        for (l, c, patch) in map.bezier_patches().unwrap() {
            let one = crate::verify::certificate::certify(
                &patch,
                &CertifyOptions { excuse_corners: false, ..CertifyOptions::default() },
            )
            .unwrap();
            let [[a, b], [cc, dd]] = map.basis.cell_bounds(l, c);
            for i in 0..=8 {
                for j in 0..=8 {
                    let (u, v) = (a + (b - a) * i as f64 / 8.0, cc + (dd - cc) * j as f64 / 8.0);
                    assert!(one.lower_bound <= patch.derivs(u, v, 1).det_j() * (1.0 + 1e-12));
                    let (x, y) = (patch.eval(u, v), map.eval(u, v));
                    assert!((x[0] - y[0]).abs() < 1e-13 && (x[1] - y[1]).abs() < 1e-13);
                }
            }
        }
    }

    #[test]
    fn a_planted_fold_is_found_in_its_cell() {
        let mut map = refined_sector();
        // move the control point of a finest-level function far across its neighbours
        let finest = map.basis.num_levels() - 2;
        let interior = |&(l, f): &(usize, Index2)| {
            let (s, n) = (map.basis.support(l, f), map.basis.cell_shape(l));
            l == finest && (0..2).all(|d| s[d].start > 0 && s[d].end < n[d])
        };
        let k = map.basis.active_functions().iter().position(interior).unwrap();
        let (l, f) = map.basis.active_functions()[k];
        // the origin lies outside the sector (radii 1 to 2)
        map.control_points[k] = [0.0, 0.0];
        let cert = certify_hierarchical(&map, &CertifyOptions::default()).unwrap();
        assert_eq!(cert.verdict.name(), "folded", "{}", cert.message());
        let Finding::Folded { param, value, .. } = cert.verdict else { unreachable!() };
        assert!(value < 0.0);
        assert!(map.derivs(param[0], param[1]).det_j() < 0.0, "det J at the witness");
        // the folded cells lie in the moved function's support
        let [ri, rj] = map.basis.support(l, f);
        let [first, last] =
            [map.basis.cell_bounds(l, [ri.start, rj.start]), map.basis.cell_bounds(l, [ri.end - 1, rj.end - 1])];
        for fold in &cert.folds {
            assert!(fold.param[0] >= first[0][0] - 1e-12 && fold.param[0] <= last[0][1] + 1e-12, "{fold:?}");
            assert!(fold.param[1] >= first[1][0] - 1e-12 && fold.param[1] <= last[1][1] + 1e-12, "{fold:?}");
        }
        assert!(!cert.offending_cells().is_empty());
    }
}
