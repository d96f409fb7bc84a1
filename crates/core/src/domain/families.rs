//! Seeded generators of the corpus families with holes and of plane graphs (issue 31):
//!
//! | family | what |
//! |---|---|
//! | `plate` | a rectangle with 1 to 5 holes (circles, ellipses, squares), on odd seeds one circle within 1–5 % of the shorter side from the outer contour and another as near to it |
//! | `wiggly` | the unit square cut by wiggly cubic curves along a jittered `a × b` grid into 4 to 60 faces, some interior edges removed (faces of 5 to 8 corners, flat and reflex corners) |
//! | `motor` | a motor-like section: a shaft bore (a void), the rotor, the air gap, `S = 6, 12, ..., 48` stator slots and as many teeth, and the yoke; `2 S + 3` labelled faces |
//!
//! Circles are exact: rational quadratic arcs (weight `cos(Δ/2)` for an arc of angle `Δ`).

use super::{Domain, Loop, PlaneEdge, PlaneGraph, PlaneLabel};
use crate::boundary::families::{between, Rng};
use crate::boundary::fit::FitOptions;
use crate::boundary::SideCurve;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;

/// The arc of the ellipse `(cx + a cos t, cy + b sin t)` from angle `t0` to `t1` (less
/// than π apart; clockwise when `t1 < t0`): a rational quadratic, the affine image of
/// the circular arc.
pub fn arc(c: Point, a: f64, b: f64, t0: f64, t1: f64) -> Curve {
    let h = 0.5 * (t1 - t0);
    let m = 0.5 * (t0 + t1);
    let r = 1.0 / h.cos();
    let p = |t: f64, s: f64| [c[0] + s * a * t.cos(), c[1] + s * b * t.sin()];
    Curve::new(KnotVector::open_uniform(2, 1), vec![p(t0, 1.0), p(m, r), p(t1, 1.0)], Some(vec![1.0, h.cos(), 1.0]))
        .expect("an arc is a valid curve")
}

fn seg(a: Point, b: Point) -> SideCurve {
    SideCurve::Spline(Curve::polynomial(KnotVector::open_uniform(1, 1), vec![a, b]))
}

/// A hole of the plate: its centre, half extents, shape (0 circle, 1 ellipse, 2 square).
struct Hole {
    c: Point,
    a: f64,
    b: f64,
    shape: u8,
}

impl Hole {
    fn radius(&self) -> f64 {
        if self.shape == 2 {
            self.a * std::f64::consts::SQRT_2
        } else {
            self.a.max(self.b)
        }
    }

    fn to_loop(&self) -> Loop {
        let (c, a, b) = (self.c, self.a, self.b);
        let sides = if self.shape == 2 {
            // clockwise
            let p = [[c[0] - a, c[1] - a], [c[0] - a, c[1] + a], [c[0] + a, c[1] + a], [c[0] + a, c[1] - a]];
            (0..4).map(|k| seg(p[k], p[(k + 1) % 4])).collect()
        } else {
            // clockwise, corners at 45°, 135°, ... (so that no corner is an extreme)
            let q = std::f64::consts::FRAC_PI_4;
            (0..4)
                .map(|k| {
                    let t0 = q - 2.0 * q * k as f64;
                    SideCurve::Spline(arc(c, a, b, t0, t0 - 2.0 * q))
                })
                .collect()
        };
        Loop::new(sides)
    }
}

/// The plate of `seed`: `w × h`, `1 + seed % 5` holes.
pub fn plate(seed: u64) -> Domain {
    let mut rng = Rng::new(seed.wrapping_mul(0x9E37_79B9).wrapping_add(977));
    let (w, h) = (between(&mut rng, 3.0, 5.0), between(&mut rng, 2.0, 3.0));
    let k = 1 + (seed % 5) as usize;
    let near = seed % 2 == 1;
    let gap_min = 0.01 * h;
    let mut holes: Vec<Hole> = Vec::new();
    let fits = |holes: &[Hole], o: &Hole, gap: f64| {
        let r = o.radius();
        o.c[0] - r >= gap
            && o.c[0] + r <= w - gap
            && o.c[1] - r >= gap
            && o.c[1] + r <= h - gap
            && holes.iter().all(|x| (x.c[0] - o.c[0]).hypot(x.c[1] - o.c[1]) - x.radius() - r >= gap)
    };
    if near {
        // a circle within 1-5 % of the shorter side from the bottom, another as near to it
        let r = between(&mut rng, 0.15, 0.3) * h;
        let g = between(&mut rng, 0.01, 0.05) * h;
        let first = Hole { c: [between(&mut rng, 0.3, 0.5) * w, r + g], a: r, b: r, shape: 0 };
        let r2 = between(&mut rng, 0.1, 0.2) * h;
        let g2 = between(&mut rng, 0.01, 0.05) * h;
        let t = between(&mut rng, 0.2, 1.2);
        let d = r + r2 + g2;
        let second = Hole { c: [first.c[0] + d * t.cos(), first.c[1] + d * t.sin()], a: r2, b: r2, shape: 0 };
        holes.push(first);
        if k > 1 && fits(&holes, &second, gap_min) {
            holes.push(second);
        }
    }
    for _ in 0..400 {
        if holes.len() >= k {
            break;
        }
        let shape = (rng.uniform() * 3.0) as u8;
        let a = between(&mut rng, 0.08, 0.22) * h;
        let b = if shape == 1 { a * between(&mut rng, 0.5, 0.9) } else { a };
        let o = Hole { c: [between(&mut rng, 0.0, w), between(&mut rng, 0.0, h)], a, b, shape };
        if fits(&holes, &o, 0.05 * h) {
            holes.push(o);
        }
    }
    let outer = Loop::new(vec![
        seg([0.0, 0.0], [w, 0.0]),
        seg([w, 0.0], [w, h]),
        seg([w, h], [0.0, h]),
        seg([0.0, h], [0.0, 0.0]),
    ]);
    Domain { name: format!("plate-{seed}"), outer, holes: holes.iter().map(Hole::to_loop).collect() }
}

/// The wiggly square of `seed` (see the module documentation).
pub fn wiggly(seed: u64) -> PlaneGraph {
    let mut rng = Rng::new(seed.wrapping_mul(0x2545_F491).wrapping_add(4099));
    let a = 2 + (rng.uniform() * 6.0) as usize;
    let b_max = (60 / a).clamp(2, 8);
    let b = 2 + (rng.uniform() * (b_max - 1) as f64) as usize;
    let (a, b) = (a.min(8), b.min(b_max));
    let id = |i: usize, j: usize| j * (a + 1) + i;
    let mut vertices = Vec::new();
    for j in 0..=b {
        for i in 0..=a {
            let inner_x = i > 0 && i < a;
            let inner_y = j > 0 && j < b;
            let dx = if inner_x { between(&mut rng, -0.2, 0.2) / a as f64 } else { 0.0 };
            let dy = if inner_y { between(&mut rng, -0.2, 0.2) / b as f64 } else { 0.0 };
            vertices.push([i as f64 / a as f64 + dx, j as f64 / b as f64 + dy]);
        }
    }
    // (from, to, interior)
    let mut pairs: Vec<(usize, usize, bool)> = Vec::new();
    for j in 0..=b {
        for i in 0..a {
            pairs.push((id(i, j), id(i + 1, j), j > 0 && j < b));
        }
    }
    for i in 0..=a {
        for j in 0..b {
            pairs.push((id(i, j), id(i, j + 1), i > 0 && i < a));
        }
    }
    // remove about a sixth of the interior edges, keeping every interior vertex on 3 or more
    let mut valence = vec![0usize; vertices.len()];
    for &(p, q, _) in &pairs {
        valence[p] += 1;
        valence[q] += 1;
    }
    let on_side = |v: usize| {
        let (i, j) = (v % (a + 1), v / (a + 1));
        i == 0 || i == a || j == 0 || j == b
    };
    let mut keep = vec![true; pairs.len()];
    for (k, &(p, q, interior)) in pairs.iter().enumerate() {
        let ok = |v: usize| on_side(v) || valence[v] > 3;
        if interior && rng.uniform() < 0.17 && ok(p) && ok(q) && !on_side(p) && !on_side(q) {
            keep[k] = false;
            valence[p] -= 1;
            valence[q] -= 1;
        }
    }
    // each interior edge a cubic bulging by up to `bulge` of its length to either side;
    // when two bulges cross (the graph is refused by `build_graph`), the bulges are drawn
    // again at half the amplitude (the first draw, and so every valid seed, unchanged)
    let mut bulge = 0.15;
    loop {
        let edges = pairs
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(&(from, to, interior), _)| {
                let curve = interior.then(|| {
                    let (p, q) = (vertices[from], vertices[to]);
                    let d = [q[0] - p[0], q[1] - p[1]];
                    let n = [-d[1], d[0]];
                    let (s1, s2) = (between(&mut rng, -bulge, bulge), between(&mut rng, -bulge, bulge));
                    let c1 = [p[0] + d[0] / 3.0 + s1 * n[0], p[1] + d[1] / 3.0 + s1 * n[1]];
                    let c2 = [p[0] + 2.0 * d[0] / 3.0 + s2 * n[0], p[1] + 2.0 * d[1] / 3.0 + s2 * n[1]];
                    SideCurve::Spline(Curve::polynomial(KnotVector::open_uniform(3, 1), vec![p, c1, c2, q]))
                });
                PlaneEdge { from, to, curve }
            })
            .collect();
        let g = PlaneGraph {
            name: format!("wiggly-{seed}"),
            vertices: vertices.clone(),
            edges,
            labels: Vec::new(),
            voids: Vec::new(),
        };
        if bulge < 0.01 || super::plane::build_graph(&g, &FitOptions::default()).is_ok() {
            return g;
        }
        bulge *= 0.5;
    }
}

/// The motor-like section of `seed`: `S = 6 (1 + seed % 8)` slots (see the module
/// documentation).
pub fn motor(seed: u64) -> PlaneGraph {
    motor_with_slots(6 * (1 + (seed % 8) as usize), seed)
}

/// A motor-like section with `slots` stator slots (an even number), proportions from
/// `seed`: shaft radius `r0`, rotor `r1`, air gap to `r2`, slots and teeth to `r3`,
/// yoke to 1; every circle has vertices at the `2 S` angles of the slots' sides.
/// Faces labelled `rotor`, `airgap`, `slot-J`, `tooth-J`, `yoke`.
pub(crate) fn motor_with_slots(slots: usize, seed: u64) -> PlaneGraph {
    let mut rng = Rng::new(seed.wrapping_mul(0x5851_F42D).wrapping_add(31));
    let s = slots.max(2);
    let r0 = between(&mut rng, 0.12, 0.22);
    let r1 = between(&mut rng, 0.45, 0.55);
    let r2 = r1 + between(&mut rng, 0.01, 0.03);
    let r3 = between(&mut rng, 0.75, 0.85);
    let frac = between(&mut rng, 0.4, 0.6);
    let tau = 2.0 * std::f64::consts::PI;
    let mut vertices: Vec<Point> = Vec::new();
    let mut edges: Vec<PlaneEdge> = Vec::new();
    let o = [0.0, 0.0];
    // a circle of radius r through vertices at the angles `angles` (increasing)
    let mut circle = |r: f64, angles: &[f64], vertices: &mut Vec<Point>| -> Vec<usize> {
        let first = vertices.len();
        let n = angles.len();
        vertices.extend(angles.iter().map(|t| [r * t.cos(), r * t.sin()]));
        for k in 0..n {
            let (t0, mut t1) = (angles[k], angles[(k + 1) % n]);
            if t1 <= t0 {
                t1 += tau;
            }
            let mut c = arc(o, r, r, t0, t1);
            let last = c.control_points.len() - 1;
            c.control_points[0] = vertices[first + k];
            c.control_points[last] = vertices[first + (k + 1) % n];
            edges.push(PlaneEdge { from: first + k, to: first + (k + 1) % n, curve: Some(SideCurve::Spline(c)) });
        }
        (first..first + n).collect()
    };
    // every circle through the same 2 S angles, so that the radial cuts of the rings
    // (shaft to rotor, air gap, yoke) end at vertices
    let stator: Vec<f64> =
        (0..s).flat_map(|j| [tau * j as f64 / s as f64, tau * (j as f64 + frac) / s as f64]).collect();
    circle(r0, &stator, &mut vertices);
    circle(r1, &stator, &mut vertices);
    let inner = circle(r2, &stator, &mut vertices);
    let outer = circle(r3, &stator, &mut vertices);
    circle(1.0, &stator, &mut vertices);
    for k in 0..2 * s {
        edges.push(PlaneEdge { from: inner[k], to: outer[k], curve: None });
    }
    let at = |r: f64, t: f64| [r * t.cos(), r * t.sin()];
    let mut labels = vec![
        PlaneLabel { name: "rotor".into(), point: at(0.5 * (r0 + r1), 0.3) },
        PlaneLabel { name: "airgap".into(), point: at(0.5 * (r1 + r2), 0.3) },
        PlaneLabel { name: "yoke".into(), point: at(0.5 * (r3 + 1.0), 0.3) },
    ];
    let rm = 0.5 * (r2 + r3);
    for j in 0..s {
        let t = tau * j as f64 / s as f64;
        labels.push(PlaneLabel { name: format!("slot-{j}"), point: at(rm, t + 0.5 * frac * tau / s as f64) });
        labels.push(PlaneLabel { name: format!("tooth-{j}"), point: at(rm, t + (0.5 + 0.5 * frac) * tau / s as f64) });
    }
    PlaneGraph { name: format!("motor-{seed}"), vertices, edges, labels, voids: vec![o] }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::plane::build_graph;
    use crate::domain::validate_domain;

    #[test]
    fn generated_plates_and_graphs_are_valid() {
        for seed in 0..10 {
            let mut d = plate(seed);
            validate_domain(&mut d).unwrap_or_else(|e| panic!("{}: {e}", d.name));
            assert!((1..=5).contains(&d.holes.len()), "{}", d.name);
            let g = wiggly(seed);
            let (_, r) = build_graph(&g, &FitOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", g.name));
            assert!((4..=60).contains(&r.faces.len()), "{}: {} faces", g.name, r.faces.len());
            assert!((r.area - 1.0).abs() < 1e-9, "{}: area {}", g.name, r.area);
        }
        // seed 16 drew two bulges that cross: drawn again at half the amplitude
        for seed in 10..=20 {
            let g = wiggly(seed);
            build_graph(&g, &FitOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", g.name));
        }
        let m = motor_with_slots(24, 3);
        let (_, r) = build_graph(&m, &FitOptions::default()).unwrap();
        assert_eq!(r.faces.len(), 51);
        assert!(r.faces.iter().any(|f| f.label == "airgap" && f.holes == 1));
        assert!(r.faces.iter().any(|f| f.label == "slot-23"));
    }
}
