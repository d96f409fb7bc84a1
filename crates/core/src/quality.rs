//! Map quality on samples and by quadrature: the Jacobian determinant (eq. 43) on a
//! grid, and the Winslow functional (eq. 15-16).

use serde::Serialize;

use crate::basis::BasisDerivs;
use crate::quadrature::GaussLegendre;
use crate::surface::Surface;

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

/// Sample `det J` on an `(n+1)^2` grid (boundary included).
pub fn sample_det_j(map: &Surface, n: usize) -> DetJSample {
    let n = n.max(1);
    let mut values = Vec::with_capacity((n + 1) * (n + 1));
    let (mut bu, mut bv) = (BasisDerivs::default(), BasisDerivs::default());
    let (mut min, mut max, mut argmin, mut min_interior) = (f64::INFINITY, f64::NEG_INFINITY, [0.0; 2], f64::INFINITY);
    for j in 0..=n {
        let v = j as f64 / n as f64;
        bv.eval(&map.knots[1], v, 1);
        for i in 0..=n {
            let u = i as f64 / n as f64;
            bu.eval(&map.knots[0], u, 1);
            let d = map.derivs_with(&bu, &bv, 1).det_j();
            values.push(d);
            if d < min {
                min = d;
                argmin = [u, v];
            }
            max = max.max(d);
            let corner = (i == 0 || i == n) && (j == 0 || j == n);
            if !corner {
                min_interior = min_interior.min(d);
            }
        }
    }
    DetJSample { n, values, min, max, argmin, min_interior }
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
    /// Smallest `det J` at the quadrature points.
    pub min_det_j_qp: f64,
}

/// Evaluate the functionals with `p + 2` Gauss points per direction and element.
pub fn functionals(map: &Surface) -> Functionals {
    let [p, q] = map.degrees();
    let gx = GaussLegendre::new(p + 2);
    let gy = GaussLegendre::new(q + 2);
    let (mut area, mut winslow, mut harmonic, mut min_det) = (0.0, 0.0, 0.0, f64::INFINITY);
    let (mut bu, mut bv) = (BasisDerivs::default(), BasisDerivs::default());
    for (sy, ya, yb) in map.knots[1].elements() {
        for (v, wv) in gy.on(ya, yb) {
            bv.eval_in_span(&map.knots[1], sy, v, 2);
            for (sx, xa, xb) in map.knots[0].elements() {
                for (u, wu) in gx.on(xa, xb) {
                    bu.eval_in_span(&map.knots[0], sx, u, 2);
                    let d = map.derivs_with(&bu, &bv, 2);
                    let det = d.det_j();
                    let w = wu * wv;
                    let g11 = d.xu[0] * d.xu[0] + d.xu[1] * d.xu[1];
                    let g12 = d.xu[0] * d.xv[0] + d.xu[1] * d.xv[1];
                    let g22 = d.xv[0] * d.xv[0] + d.xv[1] * d.xv[1];
                    area += w * det;
                    winslow += if det > 0.0 { w * (g11 + g22) / det } else { f64::INFINITY };
                    for c in 0..2 {
                        let l = g22 * d.xuu[c] - 2.0 * g12 * d.xuv[c] + g11 * d.xvv[c];
                        harmonic += w * l * l;
                    }
                    min_det = min_det.min(det);
                }
            }
        }
    }
    Functionals { area, winslow, harmonic, min_det_j_qp: min_det }
}

/// Largest distance from the map's boundary to the input boundary, per side (south,
/// east, north, west): each side of the map is sampled at `n + 1` points and the
/// distance to the input side's polyline (chords within `1e-6` of the diameter) taken.
pub fn boundary_deviation(map: &Surface, boundary: &crate::boundary::Boundary, n: usize) -> [f64; 4] {
    use crate::surface::Side;
    let diam = {
        let pts: Vec<[f64; 2]> =
            Side::ALL.iter().flat_map(|&s| crate::validate::sample_side(boundary.side(s), f64::INFINITY)).collect();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &pts {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        (hi[0] - lo[0]).hypot(hi[1] - lo[1])
    };
    Side::ALL.map(|s| {
        let poly = crate::validate::sample_side(boundary.side(s), 1e-6 * diam);
        let curve = map.boundary(s);
        let mut worst: f64 = 0.0;
        for k in 0..=n {
            let p = curve.eval(k as f64 / n as f64);
            let mut best = f64::INFINITY;
            for w in poly.windows(2) {
                best = best.min(point_segment_distance(p, w[0], w[1]));
            }
            worst = worst.max(best);
        }
        worst
    })
}

fn point_segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

/// Smallest scaled Jacobian `det J / (|x_ξ| |x_η|)` (the sine of the angle between the
/// grid lines; 1 for orthogonal lines, `<= 0` where the map folds) on a uniform
/// `(n+1) x (n+1)` grid, boundary included and corners excluded (a corner of the domain
/// may force it to 0). Points where a tangent vanishes count as 0.
pub fn min_scaled_jacobian(map: &Surface, n: usize) -> f64 {
    let n = n.max(1);
    let (mut bu, mut bv) = (BasisDerivs::default(), BasisDerivs::default());
    let mut min = f64::INFINITY;
    for j in 0..=n {
        bv.eval(&map.knots[1], j as f64 / n as f64, 1);
        for i in 0..=n {
            if (i == 0 || i == n) && (j == 0 || j == n) {
                continue;
            }
            bu.eval(&map.knots[0], i as f64 / n as f64, 1);
            let d = map.derivs_with(&bu, &bv, 1);
            let s = d.xu[0].hypot(d.xu[1]) * d.xv[0].hypot(d.xv[1]);
            min = min.min(if s > 0.0 { d.det_j() / s } else { 0.0 });
        }
    }
    min
}
