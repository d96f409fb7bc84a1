//! The harmonic map `x: P -> Ω` of the regular `N`-gon `P` onto a face `Ω` with `N`
//! sides (Hinz & Buffa, arXiv 2307.06265, §3: the template's quad layout is fixed on a
//! convex parametric polygon and pulled back to the face by a harmonic map): `Δx = 0`
//! in `P`, and on the boundary side `k` of `P` at the fraction `t` of its length goes to
//! side `k` of `Ω` at the fraction `t` of its arc length. By the Radó–Kneser–Choquet
//! theorem `x` is a bijection when `Ω` is convex; for a convex polygon with straight sides
//! that is an affine image of `P`, `x` is that affine map.
//!
//! Discretization: P1 finite elements on the structured triangulation of `P` by `m`
//! rings around its centre (ring `r` a polygon of `r·N` nodes, each sector `(c, v_s,
//! v_{s+1})` split into `m²` triangles), the stiffness `K_ij = ∫ ∇φ_i·∇φ_j` of the
//! piecewise-linear hat functions, the Dirichlet values on ring `m`, and the interior
//! values by conjugate gradients preconditioned by the diagonal. P1 reproduces affine
//! maps exactly, so the affine case above is exact up to rounding.

use crate::spline::curve::{Curve, Point};

/// Arc-length abscissae of a curve on `[0, 1]`, tabulated on a uniform parameter grid:
/// the parameter at a fraction `t` of the length by linear interpolation in the table.
#[derive(Debug, Clone)]
pub struct ArcLength {
    s: Vec<f64>,
}

/// Parameter samples of the arc-length table.
const ARC_SAMPLES: usize = 512;

impl ArcLength {
    /// The table of `c` (normalised to `[0, 1]`).
    pub fn new(c: &Curve) -> Self {
        let pts = c.sample(ARC_SAMPLES);
        let mut s = vec![0.0; pts.len()];
        for k in 1..pts.len() {
            s[k] = s[k - 1] + (pts[k][0] - pts[k - 1][0]).hypot(pts[k][1] - pts[k - 1][1]);
        }
        Self { s }
    }

    /// Length of the curve (of its polyline of 512 chords).
    pub fn length(&self) -> f64 {
        self.s[self.s.len() - 1]
    }

    /// The parameter in `[0, 1]` at the fraction `t` of the length.
    pub fn param(&self, t: f64) -> f64 {
        let total = self.length();
        if total <= 0.0 {
            return t;
        }
        let target = t.clamp(0.0, 1.0) * total;
        let k = self.s.partition_point(|&x| x < target).clamp(1, self.s.len() - 1);
        let (a, b) = (self.s[k - 1], self.s[k]);
        let f = if b > a { (target - a) / (b - a) } else { 0.0 };
        ((k - 1) as f64 + f) / ARC_SAMPLES as f64
    }
}

/// The discrete harmonic map of the regular `n`-gon onto a face.
#[derive(Debug, Clone)]
pub(crate) struct HarmonicMap {
    n: usize,
    m: usize,
    /// Image of every node (ring by ring, the centre first).
    pub values: Vec<Point>,
    /// Smallest signed area of an image triangle over its parameter area (negative:
    /// the discrete map folds there).
    pub min_area_ratio: f64,
}

fn offset(n: usize, r: usize) -> usize {
    if r == 0 {
        0
    } else {
        1 + n * r * (r - 1) / 2
    }
}

/// Node `(r, k)` (ring `r`, index `k` modulo `r·n`).
fn node(n: usize, r: usize, k: usize) -> usize {
    if r == 0 {
        0
    } else {
        offset(n, r) + k % (r * n)
    }
}

/// Vertex `s` of the regular `n`-gon inscribed in the unit circle.
pub(crate) fn polygon_vertex(n: usize, s: usize) -> Point {
    let a = 2.0 * std::f64::consts::PI * (s % n) as f64 / n as f64;
    [a.cos(), a.sin()]
}

fn position(n: usize, m: usize, r: usize, k: usize) -> Point {
    if r == 0 {
        return [0.0, 0.0];
    }
    let (s, j) = (k / r, k % r);
    let (a, b) = (polygon_vertex(n, s), polygon_vertex(n, s + 1));
    let t = j as f64 / r as f64;
    let f = r as f64 / m as f64;
    [f * (a[0] + t * (b[0] - a[0])), f * (a[1] + t * (b[1] - a[1]))]
}

/// The triangles of the structured triangulation, counter-clockwise.
fn triangles(n: usize, m: usize) -> Vec<[usize; 3]> {
    let mut out = Vec::with_capacity(n * m * m);
    for s in 0..n {
        for r in 0..m {
            let a = |j: usize| node(n, r, s * r + j);
            let b = |j: usize| node(n, r + 1, s * (r + 1) + j);
            for j in 0..=r {
                out.push([a(j), b(j), b(j + 1)]);
            }
            for j in 0..r {
                out.push([a(j), b(j + 1), a(j + 1)]);
            }
        }
    }
    out
}

fn area(p: Point, q: Point, r: Point) -> f64 {
    0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1]))
}

impl HarmonicMap {
    /// Solve for the map onto the face whose sides (counter-clockwise, side `k` from
    /// corner `k` to corner `k + 1`) are `sides`, on `m` rings.
    pub fn new(sides: &[Curve], m: usize) -> Self {
        let n = sides.len();
        let m = m.max(2);
        let nodes = offset(n, m) + m * n;
        let pos: Vec<Point> =
            (0..=m).flat_map(|r| (0..(r * n).max(1)).map(move |k| (r, k))).map(|(r, k)| position(n, m, r, k)).collect();
        debug_assert_eq!(pos.len(), nodes);
        let tris = triangles(n, m);
        // stiffness rows (sorted adjacency with values)
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); nodes];
        for t in &tris {
            let p = t.map(|i| pos[i]);
            let a2 = 2.0 * area(p[0], p[1], p[2]);
            let b = [p[1][1] - p[2][1], p[2][1] - p[0][1], p[0][1] - p[1][1]];
            let c = [p[2][0] - p[1][0], p[0][0] - p[2][0], p[1][0] - p[0][0]];
            for i in 0..3 {
                for j in 0..3 {
                    let k = (b[i] * b[j] + c[i] * c[j]) / (2.0 * a2);
                    match rows[t[i]].iter_mut().find(|e| e.0 == t[j]) {
                        Some(e) => e.1 += k,
                        None => rows[t[i]].push((t[j], k)),
                    }
                }
            }
        }
        let boundary = offset(n, m);
        let mut x = vec![[0.0; 2]; nodes];
        let arcs: Vec<ArcLength> = sides.iter().map(ArcLength::new).collect();
        for k in 0..m * n {
            let (s, j) = (k / m, k % m);
            let c = &sides[s];
            x[boundary + k] = if j == 0 { c.endpoints().0 } else { c.eval(arcs[s].param(j as f64 / m as f64)) };
        }
        // start: the mean of the boundary values (the centre) scaled out along the rays
        let mean = x[boundary..].iter().fold([0.0; 2], |a, p| [a[0] + p[0], a[1] + p[1]]);
        let mean = [mean[0] / (m * n) as f64, mean[1] / (m * n) as f64];
        for r in 0..m {
            for k in 0..(r * n).max(1) {
                let f = r as f64 / m as f64;
                let (s, j) = k.checked_div(r).map_or((0, 0), |s| (s, k % r));
                let kb = s * m + (j * m) / r.max(1);
                let q = x[boundary + kb % (m * n)];
                x[node(n, r, k)] = [mean[0] + f * (q[0] - mean[0]), mean[1] + f * (q[1] - mean[1])];
            }
        }
        cg(&rows, &mut x, boundary);
        let mut min_area_ratio = f64::INFINITY;
        for t in &tris {
            let a0 = area(pos[t[0]], pos[t[1]], pos[t[2]]);
            let a1 = area(x[t[0]], x[t[1]], x[t[2]]);
            min_area_ratio = min_area_ratio.min(a1 / a0);
        }
        Self { n, m, values: x, min_area_ratio }
    }

    /// The image of the centre of the polygon.
    pub fn centre(&self) -> Point {
        self.values[0]
    }

    /// The images of `m + 1` points on the segment from the centre of the polygon to the
    /// midpoint of its side `s` (ring by ring: on an odd ring the midpoint of the
    /// element edge the segment crosses, where the P1 map is the mean of its ends).
    pub(crate) fn spoke(&self, s: usize) -> Vec<Point> {
        let (n, m) = (self.n, self.m);
        (0..=m)
            .map(|r| {
                if r == 0 {
                    self.values[0]
                } else if r % 2 == 0 {
                    self.values[node(n, r, s * r + r / 2)]
                } else {
                    let (a, b) = (self.values[node(n, r, s * r + r / 2)], self.values[node(n, r, s * r + r / 2 + 1)]);
                    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
                }
            })
            .collect()
    }
}

/// Conjugate gradients for the interior nodes (`< boundary`) of `K x = 0` with the
/// boundary values fixed, preconditioned by the diagonal; both coordinates at once.
/// Returns the iterations.
fn cg(rows: &[Vec<(usize, f64)>], x: &mut [Point], boundary: usize) -> usize {
    let apply = |v: &[Point], out: &mut [Point], interior_only: bool| {
        for i in 0..boundary {
            let mut s = [0.0; 2];
            for &(j, k) in &rows[i] {
                if !interior_only || j < boundary {
                    s[0] += k * v[j][0];
                    s[1] += k * v[j][1];
                }
            }
            out[i] = s;
        }
    };
    let diag: Vec<f64> = (0..boundary).map(|i| rows[i].iter().find(|e| e.0 == i).map_or(1.0, |e| e.1)).collect();
    let mut r = vec![[0.0; 2]; boundary];
    apply(x, &mut r, false);
    for v in r.iter_mut() {
        *v = [-v[0], -v[1]];
    }
    let norm0 = r.iter().map(|v| v[0] * v[0] + v[1] * v[1]).sum::<f64>().sqrt();
    let scale = x.iter().fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs())).max(f64::MIN_POSITIVE);
    let mut z: Vec<Point> = r.iter().zip(&diag).map(|(v, d)| [v[0] / d, v[1] / d]).collect();
    let mut p = vec![[0.0; 2]; x.len()];
    p[..boundary].copy_from_slice(&z);
    let mut rz = [0.0; 2];
    for i in 0..boundary {
        rz[0] += r[i][0] * z[i][0];
        rz[1] += r[i][1] * z[i][1];
    }
    let mut q = vec![[0.0; 2]; boundary];
    let max_it = 10 * boundary + 100;
    for it in 0..max_it {
        let res = r.iter().map(|v| v[0] * v[0] + v[1] * v[1]).sum::<f64>().sqrt();
        if res <= 1e-14 * scale || res <= 1e-13 * norm0 {
            return it;
        }
        apply(&p, &mut q, true);
        for d in 0..2 {
            let pq: f64 = (0..boundary).map(|i| p[i][d] * q[i][d]).sum();
            if pq <= 0.0 || rz[d] == 0.0 {
                continue;
            }
            let alpha = rz[d] / pq;
            for i in 0..boundary {
                x[i][d] += alpha * p[i][d];
                r[i][d] -= alpha * q[i][d];
                z[i][d] = r[i][d] / diag[i];
            }
            let rz_new: f64 = (0..boundary).map(|i| r[i][d] * z[i][d]).sum();
            let beta = rz_new / rz[d];
            rz[d] = rz_new;
            for i in 0..boundary {
                p[i][d] = z[i][d] + beta * p[i][d];
            }
        }
    }
    max_it
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    fn line(a: Point, b: Point) -> Curve {
        Curve::new(KnotVector::open_uniform(1, 1), vec![a, b], None).unwrap()
    }

    /// An affine image of the regular polygon: the discrete harmonic map is the affine
    /// map at every node.
    #[test]
    fn reproduces_affine_maps() {
        for n in [3, 5, 6, 12] {
            let f = |p: Point| [2.0 * p[0] + 0.7 * p[1] + 3.0, -0.4 * p[0] + 1.3 * p[1] - 1.0];
            let sides: Vec<Curve> =
                (0..n).map(|s| line(f(polygon_vertex(n, s)), f(polygon_vertex(n, s + 1)))).collect();
            let h = HarmonicMap::new(&sides, 12);
            let m = 12;
            for r in 0..=m {
                for k in 0..(r * n).max(1) {
                    let want = f(position(n, m, r, k));
                    let got = h.values[node(n, r, k)];
                    assert!(
                        (got[0] - want[0]).abs() < 1e-11 && (got[1] - want[1]).abs() < 1e-11,
                        "{n}: {got:?} {want:?}"
                    );
                }
            }
            assert!(h.min_area_ratio > 0.0);
            let c = h.centre();
            assert!((c[0] - 3.0).abs() < 1e-11 && (c[1] + 1.0).abs() < 1e-11);
            // the spoke ends at the side's midpoint
            let sp = h.spoke(1);
            let mid = f([
                0.5 * (polygon_vertex(n, 1)[0] + polygon_vertex(n, 2)[0]),
                0.5 * (polygon_vertex(n, 1)[1] + polygon_vertex(n, 2)[1]),
            ]);
            let e = sp[sp.len() - 1];
            assert!((e[0] - mid[0]).abs() < 1e-9 && (e[1] - mid[1]).abs() < 1e-9, "{e:?} {mid:?}");
        }
    }

    #[test]
    fn arc_length_of_a_line_is_its_parameter() {
        let c = Curve::new(KnotVector::open_uniform(2, 1), vec![[0.0, 0.0], [0.5, 0.0], [1.0, 0.0]], None).unwrap();
        let a = ArcLength::new(&c);
        assert!((a.length() - 1.0).abs() < 1e-14);
        assert!((a.param(0.3) - 0.3).abs() < 1e-12);
    }
}
