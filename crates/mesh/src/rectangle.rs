//! The rectangle an unstructured mesh is triangulated in: the parameter square
//! stretched in each direction by a monotone function, `X = s_xi(xi)`, `Y = s_eta(eta)`,
//! so that triangles well shaped in the rectangle are about well shaped in physical space.
//!
//! - A four-sided map: both stretches linear, `s(u) = L u` with `L` the mean physical
//!   length of the two sides along that direction ([`crate::parameter_scale`]), so that
//!   a channel much longer than wide does not turn well-shaped triangles into slivers.
//! - A ring (seam across direction `d`): across, linear with the mean width `W` (area over
//!   the mean length around); around, the arc length of the local aspect,
//!
//!   `s_d(u) = c W ∫_0^u l(u') / w(u') du'`,
//!
//!   where `l(u) du` is the mean physical length around of the strip `[u, u + du]` and
//!   `w(u)` the physical length of the iso-curve across at `u` (the ring's local width).
//!   A square of side `h` in the rectangle at `u` is then about `h w(u) / W` wide in
//!   physical space in **both** directions: where the ring narrows a hundredfold, the
//!   triangles shrink with it instead of becoming slivers of aspect 100 (which the size
//!   criterion cannot mend, since it splits only long edges). The constant `c` in
//!   `[2^{-1/2}, 2^{1/2}]` makes the extent around a power of two (spade splits a segment
//!   at `w0 a + w1 b` with `w0 = 1 - w1`, exactly `L` for `a = b = L = 2^k`, so the seam's
//!   end side keeps its points bit for bit).
//!
//! The warped stretch is piecewise linear on [`WARP_CELLS`] cells of equal parameter
//! length; it and its inverse map `0` and `1` to `0` and `L` exactly.

use glam::DVec2;
use spade::Point2;
use winslow::Surface;

/// Cells of equal parameter length on which a ring's stretch around is piecewise linear.
pub const WARP_CELLS: usize = 1024;

/// Chords of each iso-curve across (its physical length, the ring's local width).
const ACROSS_CHORDS: usize = 32;

/// One direction's stretch `s: [0, 1] -> [0, L]`.
#[derive(Debug, Clone, PartialEq)]
enum Stretch {
    /// `s(u) = L u`.
    Linear(f64),
    /// `s(k / M) = t[k]`, linear in between; `t[0] = 0`, `t[M] = L`.
    Warped(Vec<f64>),
}

impl Stretch {
    fn len(&self) -> f64 {
        match self {
            Stretch::Linear(l) => *l,
            Stretch::Warped(t) => t[t.len() - 1],
        }
    }

    fn forward(&self, u: f64) -> f64 {
        match self {
            Stretch::Linear(l) => u * l,
            Stretch::Warped(t) => {
                let m = t.len() - 1;
                if u >= 1.0 {
                    return t[m];
                }
                if u <= 0.0 {
                    return 0.0;
                }
                let x = u * m as f64;
                let k = (x.floor() as usize).min(m - 1);
                let f = x - k as f64;
                t[k] + f * (t[k + 1] - t[k])
            }
        }
    }

    fn inverse(&self, x: f64) -> f64 {
        match self {
            Stretch::Linear(l) => x / l,
            Stretch::Warped(t) => {
                let m = t.len() - 1;
                if x >= t[m] {
                    return 1.0;
                }
                if x <= 0.0 {
                    return 0.0;
                }
                // the cell [t[k], t[k + 1]) holding x
                let k = t.partition_point(|&v| v <= x).clamp(1, m) - 1;
                let f = if t[k + 1] > t[k] { (x - t[k]) / (t[k + 1] - t[k]) } else { 0.0 };
                ((k as f64 + f.clamp(0.0, 1.0)) / m as f64).min(1.0)
            }
        }
    }
}

/// The triangulation's rectangle `[0, L_xi] x [0, L_eta]` and its map from the
/// parameter square.
#[derive(Debug, Clone, PartialEq)]
pub struct Rectangle {
    axes: [Stretch; 2],
    /// Expected vertex count of triangles of physical edge `size`, per `1 / size^2`
    /// (sum over the warp's cells of rectangle area over the local triangle area);
    /// `None` for a linear rectangle (the physical area is the yardstick).
    density: Option<f64>,
}

impl Rectangle {
    /// Both directions linear, `X = L_xi xi`, `Y = L_eta eta`.
    pub fn linear(scale: DVec2) -> Self {
        Self { axes: [Stretch::Linear(scale.x), Stretch::Linear(scale.y)], density: None }
    }

    /// A ring with its seam across direction `d` (`d` runs around): across, the mean
    /// width `width`; around, the arc length of the local aspect (module docs).
    /// Falls back to the linear stretch `[length around, width]` when the map gives no
    /// finite positive widths (a degenerate map, refused later by the checks).
    pub fn ring(map: &Surface, d: usize, length: f64, width: f64) -> Self {
        let m = WARP_CELLS;
        let point = |u: f64, v: f64| {
            let (xi, eta) = if d == 0 { (u, v) } else { (v, u) };
            DVec2::from(map.eval(xi, eta))
        };
        // the iso-curves across at u_k = k / M, sampled at v_j = j / ACROSS_CHORDS
        let curves: Vec<Vec<DVec2>> = (0..=m)
            .map(|k| (0..=ACROSS_CHORDS).map(|j| point(k as f64 / m as f64, j as f64 / ACROSS_CHORDS as f64)).collect())
            .collect();
        let widths: Vec<f64> = curves.iter().map(|c| c.windows(2).map(|w| w[0].distance(w[1])).sum()).collect();
        let mut t = vec![0.0; m + 1];
        let mut cells = Vec::with_capacity(m);
        for k in 0..m {
            // the strip's mean length around, and its mean width
            let l = curves[k].iter().zip(&curves[k + 1]).map(|(a, b)| a.distance(*b)).sum::<f64>()
                / (ACROSS_CHORDS + 1) as f64;
            let w = 0.5 * (widths[k] + widths[k + 1]);
            if !(w.is_finite() && w > 0.0 && l.is_finite()) {
                return Self::linear(if d == 0 { DVec2::new(length, width) } else { DVec2::new(width, length) });
            }
            t[k + 1] = t[k] + width * l / w;
            cells.push((t[k + 1] - t[k], w));
        }
        // the extent around a power of two (the seam's bits, module docs)
        let total = t[m];
        if !(total.is_finite() && total > 0.0) {
            return Self::linear(if d == 0 { DVec2::new(length, width) } else { DVec2::new(width, length) });
        }
        let target = 2f64.powi(total.log2().round() as i32);
        let c = target / total;
        for v in t.iter_mut() {
            *v *= c;
        }
        t[m] = target;
        // physical per rectangle length: across r = w / W, around l / (c W l / w) = r / c
        let mut density = 0.0;
        for &(dt, w) in &cells {
            let r = w / width;
            // triangles of physical edge 1 have rectangle edge about 1 / r here
            density += c * dt * width * r * r / 0.433 / 2.0;
        }
        let across = Stretch::Linear(width);
        let around = Stretch::Warped(t);
        let axes = if d == 0 { [around, across] } else { [across, around] };
        Self { axes, density: Some(density) }
    }

    /// `(L_xi, L_eta)`.
    pub fn extent(&self) -> DVec2 {
        DVec2::new(self.axes[0].len(), self.axes[1].len())
    }

    /// The rectangle's point of parameter `q`.
    pub fn point(&self, q: DVec2) -> Point2<f64> {
        Point2::new(self.axes[0].forward(q.x), self.axes[1].forward(q.y))
    }

    /// The parameter of the rectangle's point `p` (exactly `0` and `1` on its sides).
    pub fn param(&self, p: Point2<f64>) -> DVec2 {
        DVec2::new(self.axes[0].inverse(p.x), self.axes[1].inverse(p.y))
    }

    /// Vertices expected of triangles of physical edge `size` (`None`: linear; the
    /// physical area is the yardstick).
    pub fn expected_vertices(&self, size: f64) -> Option<f64> {
        self.density.map(|d| d / (size * size))
    }

    /// Whether the rectangle is warped (a ring's).
    pub fn is_warped(&self) -> bool {
        self.density.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warped_stretch_and_its_inverse_agree_and_keep_the_ends_exact() {
        let m = 8;
        // s(u) = u^2 scaled to L = 4 at the cell ends
        let t: Vec<f64> = (0..=m).map(|k| 4.0 * (k as f64 / m as f64).powi(2)).collect();
        let s = Stretch::Warped(t);
        assert_eq!(s.forward(0.0), 0.0);
        assert_eq!(s.forward(1.0), 4.0);
        assert_eq!(s.inverse(0.0), 0.0);
        assert_eq!(s.inverse(4.0), 1.0);
        for i in 0..=100 {
            let u = i as f64 / 100.0;
            let x = s.forward(u);
            assert!((s.inverse(x) - u).abs() < 1e-14, "u {u}: {}", s.inverse(x));
            // piecewise linear interpolation of 4 u^2 on cells of 1/8: error at most 4 h^2 / 4
            assert!((x - 4.0 * u * u).abs() <= 4.0 / 64.0 / 4.0 + 1e-15);
        }
    }

    #[test]
    fn linear_stretch_is_the_product() {
        let r = Rectangle::linear(DVec2::new(3.0, 0.5));
        let q = DVec2::new(0.3, 0.7);
        let p = r.point(q);
        assert_eq!((p.x, p.y), (0.3 * 3.0, 0.7 * 0.5));
        assert_eq!(r.param(p), DVec2::new(p.x / 3.0, p.y / 0.5));
        assert_eq!(r.expected_vertices(0.1), None);
    }

    /// A periodic ring between circles of radius 1 and 2 about the origin, across
    /// linear in `xi`, around periodic in `eta`.
    fn annulus() -> Surface {
        let ku = winslow::KnotVector::open_uniform(1, 1);
        let kv = winslow::KnotVector::periodic_uniform(3, 32);
        let mut cps = Vec::new();
        for j in 0..kv.num_basis() {
            let t = 2.0 * std::f64::consts::PI * ((j % 32) as f64) / 32.0;
            for r in [1.0, 2.0] {
                cps.push([r * t.cos(), r * t.sin()]);
            }
        }
        Surface::new([ku, kv], cps, None).unwrap()
    }

    #[test]
    fn a_ring_of_constant_width_is_stretched_linearly_to_a_power_of_two() {
        let map = annulus();
        // mean width 1, mean length around 3 pi: the aspect's arc length is 3 pi, about
        // 9.42, rounded to 8
        let r = Rectangle::ring(&map, 1, 3.0 * std::f64::consts::PI, 1.0);
        assert_eq!(r.extent(), DVec2::new(1.0, 8.0));
        assert_eq!(r.point(DVec2::new(1.0, 1.0)), Point2::new(1.0, 8.0));
        assert_eq!(r.param(Point2::new(1.0, 8.0)), DVec2::new(1.0, 1.0));
        // constant width and speed (to the B-spline circle's wobble): linear around
        for k in 0..=64 {
            let u = k as f64 / 64.0;
            let p = r.point(DVec2::new(0.5, u));
            assert!((p.y - 8.0 * u).abs() < 1e-3 * 8.0, "u {u}: {}", p.y);
            assert!((r.param(p).y - u).abs() < 1e-12);
        }
        // equilateral triangles of edge `size` over the area 3 pi, halved, times the
        // rounding's factor (the rectangle's area counts); the cubic B-spline circles lie
        // inside their control points' circles by (1 - cos(2 pi / 32)) / 3 = 0.6 %, so the
        // area is 1.3 % less
        let c = 8.0 / (3.0 * std::f64::consts::PI);
        let expected = 3.0 * std::f64::consts::PI * c / (0.433 * 0.01) / 2.0;
        let e = r.expected_vertices(0.1).unwrap();
        assert!((e / expected - 1.0 + 0.013).abs() < 2e-3, "{e} against {expected}");
    }
}
