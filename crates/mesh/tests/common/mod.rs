//! Maps with closed forms for the tests.
#![allow(dead_code)]

use winslow::{KnotVector, Surface};
use winslow_mesh::DVec2;

/// `x = b + A (u, v)` as a bilinear spline (degree 1, one element), and its closed form.
pub fn affine() -> (Surface, impl Fn(f64, f64) -> DVec2) {
    let (b, a1, a2) = (DVec2::new(0.5, -1.0), DVec2::new(3.0, 0.5), DVec2::new(0.75, 2.0));
    let kv = KnotVector::open_uniform(1, 1);
    let cps = vec![b, b + a1, b + a2, b + a1 + a2].into_iter().map(|p| [p.x, p.y]).collect();
    (Surface::new([kv.clone(), kv], cps, None).unwrap(), move |u, v| b + a1 * u + a2 * v)
}

/// Quarter annulus `1 <= r <= 2`: `u` radial (radius `1 + u`), `v` the angle along exact
/// NURBS circles, counter-clockwise (`det J > 0`).
pub fn annulus() -> Surface {
    let ku = KnotVector::open_uniform(1, 1);
    let kv = KnotVector::open_uniform(2, 1);
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let mut cps = Vec::new();
    let mut ws = Vec::new();
    for (c, wj) in [([1.0, 0.0], 1.0), ([1.0, 1.0], w), ([0.0, 1.0], 1.0)] {
        for r in [1.0, 2.0] {
            cps.push([r * c[0], r * c[1]]);
            ws.push(wj);
        }
    }
    Surface::new([ku, kv], cps, Some(ws)).unwrap()
}

/// A map that folds: one interior control point pulled across the domain.
pub fn folded() -> Surface {
    let kv = KnotVector::open_uniform(2, 1);
    let mut cps = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            cps.push([i as f64 * 0.5, j as f64 * 0.5]);
        }
    }
    cps[4] = [2.5, 2.5];
    Surface::new([kv.clone(), kv], cps, None).unwrap()
}

/// Twice the signed area of the corners of a cell.
pub fn signed_area(p: &[DVec2]) -> f64 {
    (0..p.len()).map(|k| p[k].perp_dot(p[(k + 1) % p.len()])).sum()
}

/// A full ring: `u` from an inner circle of radius 0.5 about `(0.3, 0)` (`u = 0`) to the
/// circle of radius 2 about the origin (`u = 1`), `v` periodic counter-clockwise (a
/// periodic cubic B-spline of 16 elements through control points on the circles), so
/// the gap between the walls varies from 1.2 to 1.8.
pub fn ring() -> Surface {
    let ku = KnotVector::open_uniform(1, 1);
    let kv = KnotVector::periodic_uniform(3, 16);
    let n = kv.num_basis();
    let mut cps = Vec::new();
    for j in 0..n {
        let t = 2.0 * std::f64::consts::PI * ((j % 16) as f64) / 16.0;
        for (c, r) in [(0.3, 0.5), (0.0, 2.0)] {
            cps.push([c + r * t.cos(), r * t.sin()]);
        }
    }
    Surface::new([ku, kv], cps, None).unwrap()
}

/// A ring cut into a four-sided map: between the circle of radius 0.5 about `(0.3, 0)`
/// and the circle of radius 2 about the origin, linear across, around along exact NURBS
/// circles (quadratic, four arcs, clamped knots) cut at angle 0, so two opposite sides
/// are the same segment `[0.8, 2] x {0}` (to `gap`: the end side is moved by `gap` in
/// `y`). `along_xi = false`: `xi` radial from the inner circle, `eta` counter-clockwise,
/// south = north (the seam), walls west (inner) and east (outer); `along_xi = true`:
/// `xi` counter-clockwise, `eta` from the outer circle inward (G+Smo's
/// `male_casing_ring`), west = east, walls south (outer) and north (inner).
pub fn cut_ring(along_xi: bool, gap: f64) -> Surface {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    // the nine control points and weights of a full circle of radius 1 about 0
    let circle: Vec<([f64; 2], f64)> = vec![
        ([1.0, 0.0], 1.0),
        ([1.0, 1.0], w),
        ([0.0, 1.0], 1.0),
        ([-1.0, 1.0], w),
        ([-1.0, 0.0], 1.0),
        ([-1.0, -1.0], w),
        ([0.0, -1.0], 1.0),
        ([1.0, -1.0], w),
        ([1.0, 0.0], 1.0),
    ];
    let around = KnotVector::new(2, vec![0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0]).unwrap();
    let across = KnotVector::open_uniform(1, 1);
    let wall = |k: usize, (c, r): (f64, f64)| {
        let (p, _) = circle[k];
        let dy = if k == 8 { gap } else { 0.0 };
        [c + r * p[0], r * p[1] + dy]
    };
    let (inner, outer) = ((0.3, 0.5), (0.0, 2.0));
    let mut cps = Vec::new();
    let mut ws = Vec::new();
    if along_xi {
        for wall_of in [outer, inner] {
            for (k, (_, wk)) in circle.iter().enumerate() {
                cps.push(wall(k, wall_of));
                ws.push(*wk);
            }
        }
        Surface::new([around, across], cps, Some(ws)).unwrap()
    } else {
        for (k, (_, wk)) in circle.iter().enumerate() {
            for wall_of in [inner, outer] {
                cps.push(wall(k, wall_of));
                ws.push(*wk);
            }
        }
        Surface::new([across, around], cps, Some(ws)).unwrap()
    }
}
