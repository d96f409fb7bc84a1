//! Tensor-product B-spline / NURBS maps of the unit square: a geometry is a basis
//! (two knot vectors) plus control points, `x(xi, eta) = sum_ij c_ij N_i(xi) M_j(eta)`.

use crate::error::Result;
use crate::spline::basis::BasisDerivs;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::tensor::TensorSpline;

/// The four sides of the parameter square, in the order south, east, north, west.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// `eta = 0`, increasing `xi`.
    South = 0,
    /// `xi = 1`, increasing `eta`.
    East = 1,
    /// `eta = 1`, increasing `xi`.
    North = 2,
    /// `xi = 0`, increasing `eta`.
    West = 3,
}

impl Side {
    /// All sides in the order south, east, north, west.
    pub const ALL: [Side; 4] = [Side::South, Side::East, Side::North, Side::West];

    /// Lower-case name as in the JSON format.
    pub fn name(self) -> &'static str {
        match self {
            Side::South => "south",
            Side::East => "east",
            Side::North => "north",
            Side::West => "west",
        }
    }

    /// The opposite side (south and north, east and west).
    pub fn opposite(self) -> Side {
        match self {
            Side::South => Side::North,
            Side::East => Side::West,
            Side::North => Side::South,
            Side::West => Side::East,
        }
    }

    /// Parameter direction along the side: 0 (`xi`) for south/north, 1 (`eta`) for east/west.
    pub fn direction(self) -> usize {
        match self {
            Side::South | Side::North => 0,
            Side::East | Side::West => 1,
        }
    }
}

impl std::fmt::Display for Side {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A tensor-product map of the unit square into the plane; control point `(i, j)` is
/// stored at `j * n_xi + i`.
pub type Surface = TensorSpline<2, 2>;

/// Value, gradient and Hessian of a map at a parameter point.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SurfaceDerivs {
    /// `x`.
    pub x: Point,
    /// `x_xi`.
    pub xu: Point,
    /// `x_eta`.
    pub xv: Point,
    /// `x_xi_xi`.
    pub xuu: Point,
    /// `x_xi_eta`.
    pub xuv: Point,
    /// `x_eta_eta`.
    pub xvv: Point,
}

impl SurfaceDerivs {
    /// `det J = x_xi y_eta - x_eta y_xi` (paper eq. 43).
    pub fn det_j(&self) -> f64 {
        self.xu[0] * self.xv[1] - self.xv[0] * self.xu[1]
    }
}

impl Surface {
    /// Validate lengths, finiteness and weights, and that the control points of a
    /// periodic direction wrap (`spline::periodic`).
    pub fn new(knots: [KnotVector; 2], control_points: Vec<Point>, weights: Option<Vec<f64>>) -> Result<Self> {
        Self::checked(knots, control_points, weights)
    }

    /// The diameter of the control points' bounding box, which contains the map (convex
    /// hull property of the B-spline and NURBS basis): the length scale of a map.
    pub(crate) fn control_diameter(&self) -> f64 {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &self.control_points {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        (hi[0] - lo[0]).hypot(hi[1] - lo[1])
    }

    /// Control point `(i, j)`.
    pub fn cp(&self, i: usize, j: usize) -> Point {
        self.control_points[j * self.shape()[0] + i]
    }

    /// `x(u, v)`.
    pub fn eval(&self, u: f64, v: f64) -> Point {
        let bu = BasisDerivs::at(&self.knots[0], u, 0);
        let bv = BasisDerivs::at(&self.knots[1], v, 0);
        self.derivs_with(&bu, &bv, 0).x
    }

    /// Value and derivatives up to order `nd <= 2`.
    pub fn derivs(&self, u: f64, v: f64, nd: usize) -> SurfaceDerivs {
        let bu = BasisDerivs::at(&self.knots[0], u, nd);
        let bv = BasisDerivs::at(&self.knots[1], v, nd);
        self.derivs_with(&bu, &bv, nd)
    }

    /// Value and derivatives from precomputed univariate basis values.
    pub(crate) fn derivs_with(&self, bu: &BasisDerivs, bv: &BasisDerivs, nd: usize) -> SurfaceDerivs {
        // h[a][b] = d^a/du^a d^b/dv^b of (w x, w y, w), the orders up to nd first
        const ORDERS: [[usize; 2]; 6] = [[0, 0], [1, 0], [0, 1], [2, 0], [1, 1], [0, 2]];
        let mut sums = [([0.0; 2], 0.0); 6];
        let count = [1, 3, 6][nd];
        self.homogeneous_derivs([bu, bv], &ORDERS[..count], &mut sums[..count]);
        let mut h = [[[0.0f64; 3]; 3]; 3];
        for ([a, b], (p, w)) in ORDERS.into_iter().zip(sums) {
            h[a][b] = [p[0], p[1], w];
        }
        let pt = |a: usize, b: usize| [h[a][b][0], h[a][b][1]];
        if self.weights.is_none() {
            return SurfaceDerivs {
                x: pt(0, 0),
                xu: pt(1, 0),
                xv: pt(0, 1),
                xuu: pt(2, 0),
                xuv: pt(1, 1),
                xvv: pt(0, 2),
            };
        }
        let w = h[0][0][2];
        let (wu, wv, wuu, wuv, wvv) = (h[1][0][2], h[0][1][2], h[2][0][2], h[1][1][2], h[0][2][2]);
        let mut d = SurfaceDerivs::default();
        for c in 0..2 {
            let x = h[0][0][c] / w;
            let xu = (h[1][0][c] - wu * x) / w;
            let xv = (h[0][1][c] - wv * x) / w;
            d.x[c] = x;
            d.xu[c] = xu;
            d.xv[c] = xv;
            d.xuu[c] = (h[2][0][c] - 2.0 * wu * xu - wuu * x) / w;
            d.xuv[c] = (h[1][1][c] - wu * xv - wv * xu - wuv * x) / w;
            d.xvv[c] = (h[0][2][c] - 2.0 * wv * xv - wvv * x) / w;
        }
        d
    }

    /// The parameter point of a physical point: solves `x(u, v) = p` by Newton's method
    /// from `start`, `J (du, dv) = p - x` with `J = [x_u | x_v]` (`det J`, eq. 43, as in
    /// [`SurfaceDerivs::det_j`]), halving a step until `|p - x|` decreases and clamping
    /// to the parameter domain. Returns `None` when `|p - x| <= tol` is not reached: `p`
    /// lies outside the image, `J` is singular on the way, or `start` is too far off.
    /// On a folded map the answer is one of several preimages, the one Newton finds.
    pub fn invert(&self, p: Point, start: [f64; 2], tol: f64) -> Option<[f64; 2]> {
        let dom = [self.knots[0].domain(), self.knots[1].domain()];
        let clamp = |q: [f64; 2]| [q[0].clamp(dom[0].0, dom[0].1), q[1].clamp(dom[1].0, dom[1].1)];
        let residual = |q: [f64; 2]| {
            let x = self.eval(q[0], q[1]);
            [p[0] - x[0], p[1] - x[1]]
        };
        let norm = |r: [f64; 2]| r[0].hypot(r[1]);
        let mut q = clamp(start);
        let mut r = residual(q);
        for _ in 0..60 {
            let size = norm(r);
            if size.is_nan() {
                return None;
            }
            if size <= tol {
                return Some(q);
            }
            let d = self.derivs(q[0], q[1], 1);
            let det = d.det_j();
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            let step = [(r[0] * d.xv[1] - d.xv[0] * r[1]) / det, (d.xu[0] * r[1] - r[0] * d.xu[1]) / det];
            let mut lambda = 1.0;
            loop {
                let trial = clamp([q[0] + lambda * step[0], q[1] + lambda * step[1]]);
                let rt = residual(trial);
                if norm(rt) < norm(r) {
                    (q, r) = (trial, rt);
                    break;
                }
                lambda *= 0.5;
                if lambda < 1e-6 {
                    return None;
                }
            }
        }
        (norm(r) <= tol).then_some(q)
    }

    /// Linear indices of the control points on a side, in the side's orientation.
    pub(crate) fn side_indices(shape: [usize; 2], side: Side) -> Vec<usize> {
        let [nx, ny] = shape;
        match side {
            Side::South => (0..nx).collect(),
            Side::North => (0..nx).map(|i| (ny - 1) * nx + i).collect(),
            Side::West => (0..ny).map(|j| j * nx).collect(),
            Side::East => (0..ny).map(|j| j * nx + nx - 1).collect(),
        }
    }

    /// The boundary curve on `side` (exact for open knot vectors).
    pub fn boundary(&self, side: Side) -> Curve {
        let idx = Self::side_indices(self.shape(), side);
        let kv = self.knots[side.direction()].clone();
        Curve {
            knots: kv,
            control_points: idx.iter().map(|&k| self.control_points[k]).collect(),
            weights: self.weights.as_ref().map(|w| idx.iter().map(|&k| w[k]).collect()),
        }
    }
}

impl Surface {
    #[cfg(test)]
    /// The same map with both degrees raised by one.
    pub(crate) fn elevated(&self) -> Result<Surface> {
        let (kx, ex) = crate::spline::refine::elevation(&self.knots[0])?;
        let (ky, ey) = crate::spline::refine::elevation(&self.knots[1])?;
        let op = ey.kron(&ex);
        let (cp, w) = crate::spline::tensor::apply_homogeneous(&op, &self.control_points, self.weights.as_deref());
        Ok(Surface { knots: [kx, ky], control_points: cp, weights: w })
    }
}

/// `map` with every periodic direction written on its open knot vector
/// (`periodic_to_open`): the same map on its domain (weights kept, control points in
/// homogeneous form), for formats without periodic bases. Maps without a periodic
/// direction come back unchanged.
pub(crate) fn open_equivalent(map: &crate::spline::surface::Surface) -> Result<crate::spline::surface::Surface> {
    let mut out = map.clone();
    for dir in 0..2 {
        if !out.knots[dir].is_periodic() {
            continue;
        }
        let (open, c) = crate::spline::periodic::periodic_to_open(&out.knots[dir])?;
        let [nx, ny] = out.shape();
        let (n_old, n_new) = ([nx, ny][dir], open.num_basis());
        let idx = |i: usize, j: usize, n0: usize| if dir == 0 { j * n0 + i } else { i * nx + j };
        let other = [ny, nx][dir];
        let w = |k: usize| out.weights.as_ref().map_or(1.0, |w| w[k]);
        let mut cps = vec![[0.0; 2]; n_new * other];
        let mut ws = vec![0.0; n_new * other];
        let n0 = if dir == 0 { n_new } else { nx };
        for o in 0..other {
            for r in 0..n_new {
                let (mut x, mut y, mut wt) = (0.0, 0.0, 0.0);
                for (col, v) in c.row(r) {
                    let k = idx(col, o, nx);
                    x += v * w(k) * out.control_points[k][0];
                    y += v * w(k) * out.control_points[k][1];
                    wt += v * w(k);
                }
                let k = idx(r, o, n0);
                cps[k] = [x / wt, y / wt];
                ws[k] = wt;
            }
        }
        debug_assert_eq!(c.ncols, n_old);
        let mut knots = out.knots.clone();
        knots[dir] = open;
        let weights = out.weights.is_some().then_some(ws);
        out = crate::spline::surface::Surface::new(knots, cps, weights)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curved degree-2 map of the unit square (no fold): `x = u + 0.2 v^2 + ...`.
    fn warped() -> Surface {
        let kv = KnotVector::open_uniform(2, 3);
        let n = kv.num_basis();
        let g = kv.greville();
        let mut cps = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (u, v) = (g[i], g[j]);
                cps.push([2.0 * u + 0.3 * v * v, v + 0.2 * u * u]);
            }
        }
        Surface::new([kv.clone(), kv], cps, None).unwrap()
    }

    #[test]
    fn invert_recovers_parameters() {
        let s = warped();
        for &(u, v) in &[(0.3, 0.7), (0.0, 0.0), (1.0, 0.5), (0.91, 0.05), (0.5, 1.0)] {
            let p = s.eval(u, v);
            let q = s.invert(p, [0.5, 0.5], 1e-12).expect("inside");
            assert!((q[0] - u).abs() < 1e-10 && (q[1] - v).abs() < 1e-10, "{q:?} vs ({u}, {v})");
        }
    }

    #[test]
    fn invert_quarter_circle_nurbs() {
        // quarter annulus r in [1, 2], exact circular arcs (degree 2 NURBS in u)
        let ku = KnotVector::open_uniform(2, 1);
        let kv = KnotVector::open_uniform(1, 1);
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let mut cps = Vec::new();
        let mut ws = Vec::new();
        for r in [1.0, 2.0] {
            cps.extend([[r, 0.0], [r, r], [0.0, r]]);
            ws.extend([1.0, w, 1.0]);
        }
        let s = Surface::new([ku, kv], cps, Some(ws)).unwrap();
        // the point at radius 1.5, angle 30 degrees has v = 0.5
        let a = 30f64.to_radians();
        let q = s.invert([1.5 * a.cos(), 1.5 * a.sin()], [0.5, 0.5], 1e-13).expect("inside");
        assert!((q[1] - 0.5).abs() < 1e-12, "{q:?}");
        let x = s.eval(q[0], q[1]);
        assert!((x[1].atan2(x[0]) - a).abs() < 1e-12);
    }

    #[test]
    fn invert_rejects_points_outside() {
        let s = warped();
        assert_eq!(s.invert([-1.0, 0.5], [0.5, 0.5], 1e-10), None);
        assert_eq!(s.invert([1.0, 3.0], [0.5, 0.5], 1e-10), None);
        assert_eq!(s.invert([f64::NAN, 0.0], [0.5, 0.5], 1e-10), None);
    }
}
