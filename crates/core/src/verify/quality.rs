//! Map quality on samples and by quadrature: the Jacobian determinant (eq. 43) on a
//! grid, the quality functionals of paper §2 (eq. 3: area orthogonality, Liao,
//! uniformity, harmonic energy) with the Winslow functional (eq. 15-16), and the cell
//! measures used in the meshing literature: scaled Jacobian `det J / (|x_xi| |x_eta|)`,
//! orthogonality (the angle between `x_xi` and `x_eta`) and aspect ratio.

use rayon::prelude::*;
use serde::Serialize;

use crate::error::Result;
use crate::spline::basis::BasisDerivs;
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::quadrature::GaussLegendre;
use crate::spline::surface::Surface;

/// `det J` sampled on a uniform `(n+1) x (n+1)` grid of the parameter square.
#[derive(Debug, Clone, Serialize)]
pub struct DetJSample {
    /// Points per direction minus one.
    pub n: usize,
    /// Row-major values, `eta` outer: `values[j * (n + 1) + i]` at `(i/n, j/n)`.
    pub values: Vec<f64>,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Parameter point of the smallest value.
    pub argmin: [f64; 2],
    /// Smallest value away from the four corners (the corners may be forced to 0).
    pub min_interior: f64,
}

impl DetJSample {
    /// The summary of grid values `values[j * (n + 1) + i]` at `(i/n, j/n)`, `n >= 1`.
    pub fn from_values(n: usize, values: Vec<f64>) -> Self {
        debug_assert_eq!(values.len(), (n + 1) * (n + 1));
        let (mut min, mut max, mut argmin, mut min_interior) =
            (f64::INFINITY, f64::NEG_INFINITY, [0.0; 2], f64::INFINITY);
        for j in 0..=n {
            for i in 0..=n {
                let d = values[j * (n + 1) + i];
                if d < min {
                    min = d;
                    argmin = [i as f64 / n as f64, j as f64 / n as f64];
                }
                max = max.max(d);
                let corner = (i == 0 || i == n) && (j == 0 || j == n);
                if !corner {
                    min_interior = min_interior.min(d);
                }
            }
        }
        Self { n, values, min, max, argmin, min_interior }
    }
}

/// The grid abscissae `t_i = i / n`, `i = 0..=n`, of [`sample_det_j`] and
/// [`crate::io::picture::render`].
pub fn grid_abscissae(n: usize) -> impl Iterator<Item = f64> {
    (0..=n).map(move |i| i as f64 / n as f64)
}

/// Sample `det J` on an `(n+1)^2` grid (boundary included). The `xi` basis is
/// evaluated once per column; per row of the grid the homogeneous control net `(w x, w
/// y, w)` is first contracted with the `eta` basis and its derivative (`H_b[i] = Σ_j
/// N_j^(b)(η) (w x, w y, w)_{ij}`, `b = 0, 1`), so each point costs `p + 1` terms instead
/// of `(p + 1)^2`; `det J = x_ξ × x_η` by the quotient rule `x_ξ = (X_ξ - x W_ξ) / W`.
/// Rows run in parallel.
pub fn sample_det_j(map: &Surface, n: usize) -> DetJSample {
    /// Samples below which the rows run on the calling thread: a few thousand points
    /// cost less than waking the pool's workers (the initial guesses of tiny bases).
    const SEQUENTIAL_SAMPLE: usize = 4096;
    let n = n.max(1);
    let nx = map.shape()[0];
    let bu: Vec<BasisDerivs> = grid_abscissae(n).map(|u| BasisDerivs::at(&map.knots[0], u, 1)).collect();
    let weight = |k: usize| map.weights.as_ref().map_or(1.0, |w| w[k]);
    let mut values = vec![0.0; (n + 1) * (n + 1)];
    let fill_row = |h: &mut Vec<[[f64; 3]; 2]>, (row, v): (&mut [f64], f64)| {
        let bv = BasisDerivs::at(&map.knots[1], v, 1);
        for (i, hi) in h.iter_mut().enumerate() {
            *hi = [[0.0; 3]; 2];
            for jb in 0..=bv.degree {
                let k = (bv.first() + jb) * nx + i;
                let (w, c) = (weight(k), map.control_points[k]);
                let hom = [w * c[0], w * c[1], w];
                for (b, hb) in hi.iter_mut().enumerate() {
                    for (t, x) in hb.iter_mut().zip(hom) {
                        *t += bv.d[b][jb] * x;
                    }
                }
            }
        }
        for (d, bu) in row.iter_mut().zip(&bu) {
            // (X, X_ξ, X_η) in homogeneous coordinates
            let (mut x0, mut xu, mut xv) = ([0.0f64; 3], [0.0f64; 3], [0.0f64; 3]);
            for ia in 0..=bu.degree {
                let hi = &h[bu.first() + ia];
                for c in 0..3 {
                    x0[c] += bu.d[0][ia] * hi[0][c];
                    xu[c] += bu.d[1][ia] * hi[0][c];
                    xv[c] += bu.d[0][ia] * hi[1][c];
                }
            }
            let w = x0[2];
            let p = [x0[0] / w, x0[1] / w];
            let du = [(xu[0] - p[0] * xu[2]) / w, (xu[1] - p[1] * xu[2]) / w];
            let dv = [(xv[0] - p[0] * xv[2]) / w, (xv[1] - p[1] * xv[2]) / w];
            *d = du[0] * dv[1] - dv[0] * du[1];
        }
    };
    let rows = values.chunks_mut(n + 1).zip(grid_abscissae(n));
    if (n + 1) * (n + 1) < SEQUENTIAL_SAMPLE {
        let mut h = vec![[[0.0f64; 3]; 2]; nx];
        rows.for_each(|r| fill_row(&mut h, r));
    } else {
        rows.collect::<Vec<_>>().into_par_iter().for_each_init(|| vec![[[0.0f64; 3]; 2]; nx], fill_row);
    }
    DetJSample::from_values(n, values)
}

/// Sample `det J` of a THB map on the grid of [`sample_det_j`] (`t_i = i / n` across the
/// level-0 domain), active cell by active cell: every grid point is evaluated on the
/// Bézier patch of an active cell holding it (`HierarchicalMap::bezier_patches`: the
/// polynomial the THB certificate bounds, paper eq. 43 per cell); a point on a border
/// of cells by the first of them in `active_cells` order. Cells run in parallel.
pub fn sample_det_j_hierarchical(map: &HierarchicalMap, n: usize) -> Result<DetJSample> {
    let n = n.max(1);
    let k0 = map.basis.knots(0);
    let (du, dv) = (k0[0].domain(), k0[1].domain());
    let us: Vec<f64> = grid_abscissae(n).map(|t| du.0 + (du.1 - du.0) * t).collect();
    let vs: Vec<f64> = grid_abscissae(n).map(|t| dv.0 + (dv.1 - dv.0) * t).collect();
    // the grid indices in a closed interval [a, b]
    let within = |ts: &[f64], (a, b): (f64, f64)| ts.partition_point(|&t| t < a)..ts.partition_point(|&t| t <= b);
    let patches = map.bezier_patches()?;
    let per_cell: Vec<Vec<(usize, f64)>> = patches
        .par_iter()
        .map(|(_, _, patch)| {
            let (ri, rj) = (within(&us, patch.knots[0].domain()), within(&vs, patch.knots[1].domain()));
            rj.flat_map(|j| ri.clone().map(move |i| (j, i)))
                .map(|(j, i)| (j * (n + 1) + i, patch.derivs(us[i], vs[j], 1).det_j()))
                .collect()
        })
        .collect();
    let mut values = vec![f64::NAN; (n + 1) * (n + 1)];
    for (k, d) in per_cell.into_iter().flatten() {
        if values[k].is_nan() {
            values[k] = d;
        }
    }
    Ok(DetJSample::from_values(n, values))
}

/// Integrals of the map by Gauss quadrature on every element.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Functionals {
    /// Area `int det J`.
    pub area: f64,
    /// Winslow functional `int (g11 + g22) / det J` (eq. 15-16); infinite if `det J <= 0`
    /// at a quadrature point.
    pub winslow: f64,
    /// Harmonic energy `int L(x)^2 + L(y)^2` (eq. 3).
    pub harmonic: f64,
    /// Area orthogonality `int g11^2 + g22^2` (eq. 3).
    pub area_orthogonality: f64,
    /// Liao functional `int g11^2 + g22^2 + 2 g12^2` (eq. 3).
    pub liao: f64,
    /// Uniformity `int |x_xixi|^2 + |x_etaeta|^2 + |x_xieta|^2` (eq. 3).
    pub uniformity: f64,
    /// Smallest `det J` at the quadrature points.
    pub min_det_j_qp: f64,
}

/// Evaluate the functionals with `p + 2` Gauss points per direction and element; rows of
/// elements run in parallel and their sums are added in order (deterministic).
pub fn functionals(map: &Surface) -> Functionals {
    integrate(map).functionals
}

/// The `xi` basis of `map` and its derivatives to `order` at the points of `g` on every
/// element `(span, a, b)` of `ex`, with the quadrature weights, element by element.
fn tabulate_xi(map: &Surface, g: &GaussLegendre, ex: &[(usize, f64, f64)], order: usize) -> Vec<(BasisDerivs, f64)> {
    ex.iter()
        .flat_map(|&(sx, xa, xb)| {
            g.on(xa, xb).map(move |(u, wu)| {
                let mut b = BasisDerivs::default();
                b.eval_in_span(&map.knots[0], sx, u, order);
                (b, wu)
            })
        })
        .collect()
}

/// The area `∫ det J dξ dη` of `map` by the quadrature of [`functionals`] (`(p + 2) x
/// (q + 2)` Gauss points per element, rows of elements summed in order), from first
/// derivatives only: the certificate's mean `det J` of a rational map, where the
/// Bernstein coefficients of the numerator do not integrate to it.
pub fn area(map: &Surface) -> f64 {
    let [p, q] = map.degrees();
    let gx = GaussLegendre::new(p + 2);
    let gy = GaussLegendre::new(q + 2);
    let (ex, ey) = (map.knots[0].elements(), map.knots[1].elements());
    let bus = tabulate_xi(map, &gx, &ex, 1);
    let row = |&(sy, ya, yb): &(usize, f64, f64)| {
        let mut acc = 0.0;
        let mut bv = BasisDerivs::default();
        for (v, wv) in gy.on(ya, yb) {
            bv.eval_in_span(&map.knots[1], sy, v, 1);
            for (bu, wu) in &bus {
                acc += wu * wv * map.derivs_with(bu, &bv, 1).det_j();
            }
        }
        acc
    };
    // a few elements: no threads to wake
    let rows: Vec<f64> =
        if ex.len() * ey.len() < 64 { ey.iter().map(row).collect() } else { ey.par_iter().map(row).collect() };
    rows.iter().sum()
}

/// Everything one pass over the Gauss points of every element gives: the functionals
/// and the per-element cell measures of [`Quality`].
struct Pass {
    functionals: Functionals,
    /// Per element (row-major, `xi` fastest): scaled-Jacobian minimum, orthogonality
    /// maximum, aspect ratio.
    cells: Vec<[f64; 3]>,
    /// Integral of the scaled Jacobian over the parameter square, and its weight.
    sj_int: f64,
    wsum: f64,
}

/// One pass over `(p + 2) x (q + 2)` Gauss points per element; the `xi` basis is
/// tabulated once, rows of elements run in parallel and are summed in order.
fn integrate(map: &Surface) -> Pass {
    let [p, q] = map.degrees();
    let gx = GaussLegendre::new(p + 2);
    let gy = GaussLegendre::new(q + 2);
    let (ex, ey) = (map.knots[0].elements(), map.knots[1].elements());
    let nu = p + 2;
    let bus = tabulate_xi(map, &gx, &ex, 2);
    // per row: area, winslow, harmonic, area orthogonality, liao, uniformity, min det J,
    // scaled-Jacobian integral, weight; and the row's cells
    type Row = ([f64; 9], Vec<[f64; 3]>);
    let rows: Vec<Row> = ey
        .par_iter()
        .map(|&(sy, ya, yb)| {
            let mut acc = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, f64::INFINITY, 0.0, 0.0];
            let mut cells = Vec::with_capacity(ex.len());
            let bvs: Vec<(BasisDerivs, f64)> = gy
                .on(ya, yb)
                .map(|(v, wv)| {
                    let mut b = BasisDerivs::default();
                    b.eval_in_span(&map.knots[1], sy, v, 2);
                    (b, wv)
                })
                .collect();
            let (mut bu, mut bv) = (BasisDerivs::default(), BasisDerivs::default());
            for (e, &(sx, xa, xb)) in ex.iter().enumerate() {
                let (mut smin, mut omax) = (f64::INFINITY, 0.0f64);
                for (bv, wv) in &bvs {
                    for (bu, wu) in &bus[e * nu..(e + 1) * nu] {
                        let d = map.derivs_with(bu, bv, 2);
                        let det = d.det_j();
                        let w = wu * wv;
                        let g11 = d.xu[0] * d.xu[0] + d.xu[1] * d.xu[1];
                        let g12 = d.xu[0] * d.xv[0] + d.xu[1] * d.xv[1];
                        let g22 = d.xv[0] * d.xv[0] + d.xv[1] * d.xv[1];
                        acc[0] += w * det;
                        acc[1] += if det > 0.0 { w * (g11 + g22) / det } else { f64::INFINITY };
                        for c in 0..2 {
                            let l = g22 * d.xuu[c] - 2.0 * g12 * d.xuv[c] + g11 * d.xvv[c];
                            acc[2] += w * l * l;
                        }
                        acc[3] += w * (g11 * g11 + g22 * g22);
                        acc[4] += w * (g11 * g11 + g22 * g22 + 2.0 * g12 * g12);
                        let n2 = |a: [f64; 2]| a[0] * a[0] + a[1] * a[1];
                        acc[5] += w * (n2(d.xuu) + n2(d.xvv) + n2(d.xuv));
                        acc[6] = acc[6].min(det);
                        // cell measures
                        let ab = (g11 * g22).sqrt();
                        let sj = if ab > 0.0 { det / ab } else { 0.0 };
                        smin = smin.min(sj);
                        acc[7] += w * sj;
                        acc[8] += w;
                        let cos = if ab > 0.0 { g12 / ab } else { 1.0 };
                        omax = omax.max((cos.clamp(-1.0, 1.0).acos().to_degrees() - 90.0).abs());
                    }
                }
                let (uc, vc) = (0.5 * (xa + xb), 0.5 * (ya + yb));
                bu.eval_in_span(&map.knots[0], sx, uc, 1);
                bv.eval_in_span(&map.knots[1], sy, vc, 1);
                let d = map.derivs_with(&bu, &bv, 1);
                let (lx, ly) = (d.xu[0].hypot(d.xu[1]) * (xb - xa), d.xv[0].hypot(d.xv[1]) * (yb - ya));
                let aspect = if lx > 0.0 && ly > 0.0 { (lx / ly).max(ly / lx) } else { f64::INFINITY };
                cells.push([smin, omax, aspect]);
            }
            (acc, cells)
        })
        .collect();
    let mut t = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, f64::INFINITY, 0.0, 0.0];
    for (r, _) in &rows {
        for k in 0..9 {
            if k == 6 {
                t[6] = t[6].min(r[6]);
            } else {
                t[k] += r[k];
            }
        }
    }
    let cells = rows.into_iter().flat_map(|r| r.1).collect();
    Pass {
        functionals: Functionals {
            area: t[0],
            winslow: t[1],
            harmonic: t[2],
            area_orthogonality: t[3],
            liao: t[4],
            uniformity: t[5],
            min_det_j_qp: t[6],
        },
        cells,
        sj_int: t[7],
        wsum: t[8],
    }
}

/// Minimum, mean and maximum of a per-element quantity.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Stats {
    /// Smallest value.
    pub min: f64,
    /// Mean over the elements.
    pub mean: f64,
    /// Largest value.
    pub max: f64,
}

impl Stats {
    fn of(v: &[f64]) -> Self {
        let n = v.len().max(1) as f64;
        Self {
            min: v.iter().copied().fold(f64::INFINITY, f64::min),
            mean: v.iter().sum::<f64>() / n,
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// Cell quality of a map, per element, at the `(p + 2) x (q + 2)` Gauss points.
#[derive(Debug, Clone, Serialize)]
pub struct Quality {
    /// The functionals of eq. (3) and (15-16).
    pub functionals: Functionals,
    /// Scaled Jacobian `det J / (|x_xi| |x_eta|)` in `[-1, 1]` (1: orthogonal cell):
    /// statistics of the per-element minimum.
    pub scaled_jacobian: Stats,
    /// Mean scaled Jacobian over all quadrature points (area of parameter space weighted).
    pub scaled_jacobian_mean: f64,
    /// Deviation of the angle between `x_xi` and `x_eta` from 90 degrees: statistics of
    /// the per-element maximum, in degrees.
    pub orthogonality_degrees: Stats,
    /// Aspect ratio of the elements, `max(l_xi / l_eta, l_eta / l_xi)` with the physical
    /// element edge lengths `l_xi = |x_xi| h_xi`, `l_eta = |x_eta| h_eta` at the element
    /// centre.
    pub aspect_ratio: Stats,
    /// Number of elements.
    pub elements: usize,
}

/// Functionals and cell statistics of a map (rows of elements in parallel).
pub fn quality(map: &Surface) -> Quality {
    let pass = integrate(map);
    let column = |k: usize| pass.cells.iter().map(|c| c[k]).collect::<Vec<f64>>();
    Quality {
        functionals: pass.functionals,
        scaled_jacobian: Stats::of(&column(0)),
        scaled_jacobian_mean: pass.sj_int / pass.wsum,
        orthogonality_degrees: Stats::of(&column(1)),
        aspect_ratio: Stats::of(&column(2)),
        elements: pass.cells.len(),
    }
}

/// The boundary deviation of a map from its input boundary, per side (south, east,
/// north, west): the largest distance from a point of the map's side to the input side,
///
/// `d_s = max_k dist(x_s(t_k), Γ_s)`, `t_k = k / n`, `k = 0..=n`,
///
/// where `x_s` is the map's side `s` and `Γ_s` the input side (a spline or analytic
/// curve, or the polyline through a point cloud). A point within rounding (`64 ε` of the
/// side's coordinates) of `Γ_s` at the same parameter takes that distance (the map's side
/// is the input curve there, as on the input's own basis). Otherwise the distance to a
/// curve is found in two steps: the nearest chord of a sampling of `Γ_s`
/// (`SAMPLES_PER_SPAN` chords per knot span of a spline, `ANALYTIC_SAMPLES` of an
/// analytic side; runs of chords farther than a chord near the previous point are
/// skipped by their bounding boxes), then the curve's own nearest point: Newton's method
/// on the foot-point condition `C'(t)·(C(t) - x) = 0` of a spline side from the foot
/// point on that chord, and golden-section search on the parameters of the chord and its
/// two neighbours where Newton's method leaves them or on an analytic side. Every
/// distance is to a point *on* the curve, so `d_s` never understates the deviation, and
/// it is at rounding level when the map's side is the input curve, whatever its
/// parameterization. This is the one measure of the crate:
/// the solve report's `boundary_deviation` and `winslow check --boundary` both are this
/// with `n = 400`.
pub fn boundary_deviation(map: &Surface, boundary: &crate::boundary::Boundary, n: usize) -> [f64; 4] {
    use crate::spline::surface::Side;
    let n = n.max(1);
    Side::ALL.map(|s| {
        let side = SideSamples::of(boundary.side(s));
        let curve = map.boundary(s);
        // the nearest chord of every point first (cheap), then the curve's nearest points,
        // the points of the farthest chords first: a point whose distance is found not to
        // exceed the largest one so far stops early, which leaves the maximum exact
        // a point within rounding of the input side's point of the same parameter (the
        // map's side is the input curve, as on the input's own basis) takes that distance:
        // a point of the curve, so it does not understate, and it exceeds the distance by
        // rounding at most
        let rounding = 64.0 * f64::EPSILON * side.scale;
        let mut exact: f64 = 0.0;
        // consecutive points of the map's side lie near each other, so each point's search
        // starts from the previous point's nearest chord
        let mut previous = None;
        let mut near: Vec<([f64; 2], (f64, usize))> = (0..=n)
            .filter_map(|k| {
                let t = k as f64 / n as f64;
                let p = curve.eval(t);
                if let Some(q) = side.at_parameter(t) {
                    let d = (p[0] - q[0]).hypot(p[1] - q[1]);
                    if d <= rounding {
                        exact = exact.max(d);
                        return None;
                    }
                }
                let chord = side.nearest_chord(p, previous);
                previous = Some(chord.1);
                Some((p, chord))
            })
            .collect();
        near.sort_by(|a, b| b.1 .0.total_cmp(&a.1 .0));
        near.iter().fold(exact, |max: f64, &(p, chord)| max.max(side.distance_beyond(p, chord, max)))
    })
}

/// Chords per bounding box of [`SideSamples::nearest_chord`]'s pruning.
const CHORDS_PER_BOX: usize = 8;

/// An input side sampled at known parameters, for [`boundary_deviation`].
struct SideSamples<'a> {
    side: &'a crate::boundary::SideCurve,
    /// `(t, x(t))`, increasing `t` (for a point cloud `t` is the index).
    points: Vec<(f64, [f64; 2])>,
    /// The bounding box `[min, max]` of each run of [`CHORDS_PER_BOX`] consecutive chords.
    boxes: Vec<[[f64; 2]; 2]>,
    /// The side's `C^0` knots (a spline's knots of multiplicity at least its degree), where
    /// the distance need not be unimodal.
    kinks: Vec<f64>,
    /// The largest coordinate magnitude or extent of the samples: the scale of rounding.
    scale: f64,
}

impl<'a> SideSamples<'a> {
    fn of(side: &'a crate::boundary::SideCurve) -> Self {
        use crate::boundary::validate::{ANALYTIC_SAMPLES, SAMPLES_PER_SPAN};
        use crate::boundary::SideCurve;
        let points = match side {
            SideCurve::Points(p) => p.iter().enumerate().map(|(k, &x)| (k as f64, x)).collect(),
            SideCurve::Spline(c) => {
                let mut out = Vec::new();
                for (k, &(_, a, b)) in c.knots.elements().iter().enumerate() {
                    let first = if k == 0 { 0 } else { 1 };
                    for j in first..=SAMPLES_PER_SPAN {
                        let t =
                            if j == SAMPLES_PER_SPAN { b } else { a + (b - a) * j as f64 / SAMPLES_PER_SPAN as f64 };
                        out.push((t, c.eval(t)));
                    }
                }
                out
            }
            SideCurve::Analytic(f) => (0..=ANALYTIC_SAMPLES)
                .map(|k| {
                    let t = k as f64 / ANALYTIC_SAMPLES as f64;
                    (t, f.eval(t))
                })
                .collect(),
        };
        let kinks = match side {
            SideCurve::Spline(c) => c
                .knots
                .breaks_with_multiplicity()
                .into_iter()
                .filter(|&(_, m)| m >= c.knots.degree())
                .map(|(u, _)| u)
                .collect(),
            _ => Vec::new(),
        };
        let boxes = points
            .windows(2)
            .collect::<Vec<_>>()
            .chunks(CHORDS_PER_BOX)
            .map(|run| {
                run.iter()
                    .flat_map(|w| [w[0].1, w[1].1])
                    .fold([[f64::INFINITY; 2], [f64::NEG_INFINITY; 2]], |[lo, hi], q| {
                        [[lo[0].min(q[0]), lo[1].min(q[1])], [hi[0].max(q[0]), hi[1].max(q[1])]]
                    })
            })
            .collect();
        let scale = points.iter().flat_map(|q| [q.1[0].abs(), q.1[1].abs()]).fold(0.0, f64::max);
        Self { side, points, boxes, kinks, scale }
    }

    /// The side's point at the parameter `t` of `[0, 1]` mapped onto its own parameter
    /// domain (`None` for a point cloud).
    fn at_parameter(&self, t: f64) -> Option<[f64; 2]> {
        use crate::boundary::SideCurve;
        match self.side {
            SideCurve::Spline(c) => {
                let (a, b) = c.knots.domain();
                Some(c.eval(if t >= 1.0 { b } else { a + t * (b - a) }))
            }
            SideCurve::Analytic(f) => Some(f.eval(t)),
            SideCurve::Points(_) => None,
        }
    }

    fn eval(&self, t: f64) -> [f64; 2] {
        use crate::boundary::SideCurve;
        match self.side {
            SideCurve::Spline(c) => c.eval(t),
            SideCurve::Analytic(f) => f.eval(t),
            SideCurve::Points(_) => unreachable!("a point cloud is its polyline"),
        }
    }

    /// The distance from `p` to the nearest chord of the sampling and that chord's index
    /// (the first of equally near ones). `guess`, a chord near `p` (the previous point's),
    /// gives an upper bound `U` of the distance first: a run of chords whose bounding box
    /// is farther than `U` holds no nearest chord and is skipped, which leaves the result
    /// exactly that of a scan of every chord.
    fn nearest_chord(&self, p: [f64; 2], guess: Option<usize>) -> (f64, usize) {
        let pts = &self.points;
        if pts.len() < 2 {
            return (pts.first().map_or(f64::INFINITY, |q| (p[0] - q.1[0]).hypot(p[1] - q.1[1])), 0);
        }
        let squared = |e: [f64; 2]| e[0] * e[0] + e[1] * e[1];
        // `U²` with the same relative slack as the chords' own test below, which covers
        // the rounding of squares against `hypot` (a square that is not a normal number
        // prunes nothing)
        let bound = guess.filter(|&i| i + 1 < pts.len()).map_or(f64::INFINITY, |i| {
            let e = point_segment_offset(p, pts[i].1, pts[i + 1].1);
            e[0].hypot(e[1])
        });
        let u2 = bound * bound;
        let prune = u2.is_normal();
        // the nearest chord, the first of equally near ones; a chord whose squared
        // distance exceeds `best²` by more than rounding is farther and needs no `hypot`
        // (near ties and squares that are not normal numbers take the distance itself)
        let (mut best, mut at) = (f64::INFINITY, 0);
        for (b, [lo, hi]) in self.boxes.iter().enumerate() {
            if prune {
                let gap = [(lo[0] - p[0]).max(p[0] - hi[0]).max(0.0), (lo[1] - p[1]).max(p[1] - hi[1]).max(0.0)];
                if squared(gap) > u2 * (1.0 + 1e-10) {
                    continue;
                }
            }
            let first = b * CHORDS_PER_BOX;
            let last = (first + CHORDS_PER_BOX).min(pts.len() - 1);
            for i in first..last {
                let e = point_segment_offset(p, pts[i].1, pts[i + 1].1);
                let b2 = best * best;
                if b2.is_normal() && squared(e) > b2 * (1.0 + 1e-10) {
                    continue;
                }
                let d = e[0].hypot(e[1]);
                if d < best {
                    (best, at) = (d, i);
                }
            }
        }
        (best, at)
    }

    /// Distance from `p` to the side (see [`boundary_deviation`]), from its nearest chord
    /// `(best, at)` ([`SideSamples::nearest_chord`]) — exactly when it exceeds `floor`,
    /// otherwise some value at most `floor` (the search stops once the distance is known
    /// not to exceed it).
    fn distance_beyond(&self, p: [f64; 2], (best, at): (f64, usize), floor: f64) -> f64 {
        let pts = &self.points;
        if pts.len() < 2 || matches!(self.side, crate::boundary::SideCurve::Points(_)) {
            return best;
        }
        let dist = |t: f64| {
            let q = self.eval(t);
            (p[0] - q[0]).hypot(p[1] - q[1])
        };
        // golden section on the chord's parameters and its neighbours', on each piece
        // between the side's C0 knots there (across a kink the distance need not be
        // unimodal: on a narrow V-notch the search slid from a point of one flank to the
        // other flank)
        // (`min(fa, fb)` never grows, so once `min(found, fa, fb) <= floor` the result is
        // at most `floor`)
        //
        // On a spline side, once the bracket is a thousandth of the chord's, Newton's
        // method on `g(t) = C'(t)·(C(t) - p)` (the foot point's condition, `g' = |C'|² +
        // C''·(C - p)`) finishes in a few steps what the golden section would take some
        // fifty more for; every Newton iterate is a point of the curve, so the distance
        // still never understates. A step that leaves the bracket, or `g' <= 0`, hands
        // back to the golden section.
        let golden = |mut lo: f64, mut hi: f64| {
            let found = dist(lo).min(dist(hi));
            let r = 0.5 * (5f64.sqrt() - 1.0);
            let (mut a, mut b) = (hi - r * (hi - lo), lo + r * (hi - lo));
            let (mut fa, mut fb) = (dist(a), dist(b));
            let newton_below = 1e-3 * (hi - lo);
            let mut newton_tried = false;
            for _ in 0..80 {
                if found.min(fa).min(fb) <= floor {
                    break;
                }
                if !newton_tried && hi - lo <= newton_below {
                    newton_tried = true;
                    let start = if fa <= fb { a } else { b };
                    if let Some(d) = self.newton_foot(p, start, lo, hi) {
                        return found.min(fa).min(fb).min(d);
                    }
                }
                if fa <= fb {
                    (hi, b, fb) = (b, a, fa);
                    a = hi - r * (hi - lo);
                    fa = dist(a);
                } else {
                    (lo, a, fa) = (a, b, fb);
                    b = lo + r * (hi - lo);
                    fb = dist(b);
                }
                if hi - lo <= f64::EPSILON * lo.abs().max(hi.abs()) {
                    break;
                }
            }
            found.min(fa).min(fb)
        };
        // Newton's method first, from the foot point on the nearest chord (`t₀`, the
        // chord's parameters interpolated): on a smooth piece it converges in a few steps
        // to the foot point the golden section brackets; the golden section is the
        // fallback where it does not
        // the distance to the curve at a bracket's end: a sample's point where the end is
        // a sample (the same value `dist` would give), else the curve evaluated there
        let near = &pts[at.saturating_sub(1)..(at + 3).min(pts.len())];
        let end = |t: f64| match near.iter().find(|q| q.0 == t) {
            Some(&(_, q)) => (p[0] - q[0]).hypot(p[1] - q[1]),
            None => dist(t),
        };
        let first = |lo: f64, hi: f64| {
            let t0 = {
                let ((ta, a), (tb, b)) = (pts[at], pts[(at + 1).min(pts.len() - 1)]);
                let e = point_segment_offset(p, a, b);
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let l2 = dx * dx + dy * dy;
                let s = if l2 > 0.0 { ((p[0] - e[0] - a[0]) * dx + (p[1] - e[1] - a[1]) * dy) / l2 } else { 0.0 };
                (ta + s.clamp(0.0, 1.0) * (tb - ta)).clamp(lo, hi)
            };
            match self.newton_foot(p, t0, lo, hi) {
                // the bracket's ends too, as the golden section has them
                Some(d) => d.min(end(lo)).min(end(hi)),
                None => golden(lo, hi),
            }
        };
        let (lo, hi) = (pts[at.saturating_sub(1)].0, pts[(at + 2).min(pts.len() - 1)].0);
        let mut kinks = self.kinks.iter().copied().filter(|&u| u > lo && u < hi).peekable();
        if kinks.peek().is_none() {
            return first(lo, hi);
        }
        let mut ends = vec![lo];
        ends.extend(kinks);
        ends.push(hi);
        ends.windows(2).map(|w| first(w[0], w[1])).fold(f64::INFINITY, f64::min)
    }

    /// The distance from `p` to the spline side's foot point by Newton's method on
    /// `g(t) = C'(t)·(C(t) - p)` from `t` inside `[lo, hi]`: the smallest distance of its
    /// iterates once the steps fall to rounding, `None` (nothing concluded) on an analytic
    /// side, a step out of `[lo, hi]`, `g' <= 0`, or no convergence in 12 steps.
    fn newton_foot(&self, p: [f64; 2], mut t: f64, lo: f64, hi: f64) -> Option<f64> {
        let crate::boundary::SideCurve::Spline(c) = self.side else { return None };
        let mut best = f64::INFINITY;
        for _ in 0..12 {
            let d = c.derivs(t, 2);
            let e = [d.x[0] - p[0], d.x[1] - p[1]];
            best = best.min(e[0].hypot(e[1]));
            let g = d.d1[0] * e[0] + d.d1[1] * e[1];
            let dg = d.d1[0] * d.d1[0] + d.d1[1] * d.d1[1] + d.d2[0] * e[0] + d.d2[1] * e[1];
            if dg.is_nan() || dg <= 0.0 {
                return None;
            }
            let step = g / dg;
            let next = t - step;
            if !(lo..=hi).contains(&next) {
                return None;
            }
            if step.abs() <= 4.0 * f64::EPSILON * t.abs().max(next.abs()).max(hi - lo) || next == t {
                let q = c.eval(next);
                return Some(best.min((p[0] - q[0]).hypot(p[1] - q[1])));
            }
            t = next;
        }
        None
    }
}

/// `p - q`, where `q` is the point of the segment `[a, b]` nearest to `p`.
fn point_segment_offset(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
    [p[0] - a[0] - t * dx, p[1] - a[1] - t * dy]
}

#[cfg(test)]
mod tests;
