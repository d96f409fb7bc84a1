//! The map of a face `Ω` with `N` sides **onto** the regular `N`-gon `P`, and its
//! piecewise-linear inverse (Hinz & Buffa, arXiv 2307.06265, §3): the direction that is
//! one-to-one for every face, convex or not. [`super::harmonic`] maps `P` onto `Ω`,
//! which the Radó–Kneser–Choquet theorem makes a bijection only when `Ω` is convex; here
//! the target `P` is convex, so the map `u: Ω -> P` with `u` on side `k` of `Ω` at the
//! fraction `t` of its arc length equal to the point at the fraction `t` of side `k` of
//! `P` is a bijection, and the template's cuts in `P` (segments from the centre to the
//! side midpoints) are carried back to `Ω` by `u⁻¹`: they stay inside the face.
//!
//! Discretization: the boundary of `Ω` is sampled by arc length (about `per_side`
//! nodes a side, in proportion to its length) and triangulated (ear clipping, then
//! Lawson flips to the constrained Delaunay triangulation); every interior edge between
//! two boundary nodes (a dividing edge) is split at its midpoint, and the triangles are
//! refined `levels` times (each into four). The discrete map is Floater's
//! (Floater 2003, "Mean value coordinates"): at every interior node `i`
//! `Σ_j w_ij (u_i - u_j) = 0` with the mean value weights
//! `w_ij = (tan(α_ij/2) + tan(β_ij/2)) / |x_j - x_i|` (`α_ij`, `β_ij` the angles at
//! `x_i` of the two triangles beside the edge `ij`). The weights are positive on every
//! triangulation, so with the boundary mapped onto the convex polygon and no dividing
//! edge, the piecewise-linear map is one-to-one (Floater 2003, Tutte's theorem), every
//! image triangle positive; and they reproduce linear functions
//! (`Σ_j w_ij (x_j - x_i) = 0`), so when `Ω` is an affine image of `P` with straight
//! sides, `u` is that affine map's inverse up to rounding. The inverse is evaluated by
//! locating a point of `P` in the image triangulation and taking the same barycentric
//! combination of the face's nodes.

use super::harmonic::{polygon_vertex, ArcLength};
use crate::error::{Error, Result};
use crate::linalg::linsolve::{LinearMethod, LinearSolver};
use crate::linalg::sparse::Csr;
use crate::spline::curve::{Curve, Point};
use std::collections::HashMap;

/// Refinements of the triangulation of a face for its [`PolygonMap`].
pub(super) const POLYGON_MAP_LEVELS: usize = 2;

/// The piecewise-linear map of a face onto the regular polygon (see the module
/// documentation).
#[derive(Debug, Clone)]
pub(crate) struct PolygonMap {
    n: usize,
    /// Nodes in the face.
    pub nodes: Vec<Point>,
    /// Their images in the polygon (inscribed in the unit circle).
    pub images: Vec<Point>,
    /// Triangles, counter-clockwise in the face.
    pub triangles: Vec<[usize; 3]>,
    /// Buckets of the triangles over the face and over the polygon.
    grids: [Buckets; 2],
}

/// The triangles whose bounding boxes meet each cell of a uniform grid over the points'
/// bounding box (a point is looked up in its cell's list).
#[derive(Debug, Clone)]
struct Buckets {
    lo: Point,
    cell: Point,
    size: usize,
    lists: Vec<Vec<usize>>,
}

impl Buckets {
    fn new(p: &[Point], tris: &[[usize; 3]]) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for q in p {
            for d in 0..2 {
                lo[d] = lo[d].min(q[d]);
                hi[d] = hi[d].max(q[d]);
            }
        }
        let size = ((tris.len() as f64).sqrt().ceil() as usize).clamp(1, 512);
        let cell = [
            ((hi[0] - lo[0]) / size as f64).max(f64::MIN_POSITIVE),
            ((hi[1] - lo[1]) / size as f64).max(f64::MIN_POSITIVE),
        ];
        let mut b = Self { lo, cell, size, lists: vec![Vec::new(); size * size] };
        for (t, tri) in tris.iter().enumerate() {
            let (mut a, mut z) = ([usize::MAX; 2], [0usize; 2]);
            for &v in tri {
                let c = b.cell_of(p[v]);
                for d in 0..2 {
                    a[d] = a[d].min(c[d]);
                    z[d] = z[d].max(c[d]);
                }
            }
            for i in a[0]..=z[0] {
                for j in a[1]..=z[1] {
                    b.lists[i * size + j].push(t);
                }
            }
        }
        b
    }

    fn cell_of(&self, q: Point) -> [usize; 2] {
        let f = |d: usize| (((q[d] - self.lo[d]) / self.cell[d]).floor().max(0.0) as usize).min(self.size - 1);
        [f(0), f(1)]
    }

    fn list(&self, q: Point) -> &[usize] {
        let c = self.cell_of(q);
        &self.lists[c[0] * self.size + c[1]]
    }
}

fn cross(o: Point, a: Point, b: Point) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

fn lerp(a: Point, b: Point, t: f64) -> Point {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
}

/// Barycentric coordinates of `q` in the triangle `(a, b, c)`.
fn barycentric(a: Point, b: Point, c: Point, q: Point) -> [f64; 3] {
    let d = cross(a, b, c);
    if d == 0.0 {
        return [f64::NEG_INFINITY; 3];
    }
    let l1 = cross(q, b, c) / d;
    let l2 = cross(a, q, c) / d;
    [l1, l2, 1.0 - l1 - l2]
}

/// Triangulation of the simple counter-clockwise polygon `p` by ear clipping (the ear
/// of best shape first); an error when no ear is left (the polygon is not simple).
fn ear_clip(p: &[Point]) -> Result<Vec<[usize; 3]>> {
    let mut idx: Vec<usize> = (0..p.len()).collect();
    let mut out = Vec::with_capacity(p.len());
    while idx.len() > 3 {
        let m = idx.len();
        let mut best: Option<(usize, f64)> = None;
        for i in 0..m {
            let (a, b, c) = (idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]);
            let cr = cross(p[a], p[b], p[c]);
            if cr <= 0.0 {
                continue;
            }
            let blocked = idx.iter().any(|&v| {
                v != a && v != b && v != c && {
                    let l = barycentric(p[a], p[b], p[c], p[v]);
                    l.iter().all(|&x| x >= -1e-12)
                }
            });
            if blocked {
                continue;
            }
            let sq = |u: Point, v: Point| (u[0] - v[0]).powi(2) + (u[1] - v[1]).powi(2);
            let quality = cr / (sq(p[a], p[b]) + sq(p[b], p[c]) + sq(p[c], p[a]));
            if best.is_none_or(|(_, q)| quality > q) {
                best = Some((i, quality));
            }
        }
        let Some((i, _)) = best else {
            return Err(Error::Invalid("polygon map: the face's polyline has no ear (it is not simple)".into()));
        };
        out.push([idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]]);
        idx.remove(i);
    }
    if cross(p[idx[0]], p[idx[1]], p[idx[2]]) <= 0.0 {
        return Err(Error::Invalid("polygon map: the face's polyline is not simple".into()));
    }
    out.push([idx[0], idx[1], idx[2]]);
    Ok(out)
}

/// `d` strictly inside the circumcircle of the counter-clockwise triangle `(a, b, c)`.
fn in_circle(a: Point, b: Point, c: Point, d: Point) -> bool {
    let r = |p: Point| [p[0] - d[0], p[1] - d[1]];
    let (a, b, c) = (r(a), r(b), r(c));
    let s = |p: Point| p[0] * p[0] + p[1] * p[1];
    let det =
        (a[0] * b[1] - b[0] * a[1]) * s(c) + (b[0] * c[1] - c[0] * b[1]) * s(a) + (c[0] * a[1] - a[0] * c[1]) * s(b);
    let scale = s(a).max(s(b)).max(s(c));
    det > 1e-12 * scale * scale
}

/// Lawson flips of the edges shared by two triangles until every one is locally
/// Delaunay (the polygon's own edges, on one triangle, are never flipped).
fn flip_to_delaunay(p: &[Point], tris: &mut [[usize; 3]]) {
    let mut owner: HashMap<(usize, usize), usize> = HashMap::new();
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            owner.insert((tri[k], tri[(k + 1) % 3]), t);
        }
    }
    let max_flips = 50 * tris.len() * tris.len().max(1);
    let mut flips = 0;
    loop {
        let mut flipped = false;
        for t1 in 0..tris.len() {
            for k in 0..3 {
                let [a, b, c] = [tris[t1][k], tris[t1][(k + 1) % 3], tris[t1][(k + 2) % 3]];
                let Some(&t2) = owner.get(&(b, a)) else { continue };
                let d = tris[t2].into_iter().find(|&v| v != a && v != b).expect("a triangle has a third vertex");
                if !in_circle(p[a], p[b], p[c], p[d])
                    || cross(p[a], p[d], p[c]) <= 0.0
                    || cross(p[d], p[b], p[c]) <= 0.0
                {
                    continue;
                }
                tris[t1] = [a, d, c];
                tris[t2] = [d, b, c];
                owner.remove(&(a, b));
                owner.remove(&(b, a));
                for (e, t) in [((a, d), t1), ((d, c), t1), ((c, a), t1), ((d, b), t2), ((b, c), t2), ((c, d), t2)] {
                    owner.insert(e, t);
                }
                flipped = true;
                flips += 1;
                break;
            }
        }
        if !flipped || flips > max_flips {
            return;
        }
    }
}

/// The mesh under construction: nodes, images (boundary ones known), boundary flags.
struct Mesh {
    nodes: Vec<Point>,
    images: Vec<Point>,
    boundary: Vec<bool>,
    tris: Vec<[usize; 3]>,
}

impl Mesh {
    fn add_node(&mut self, x: Point, u: Point, boundary: bool) -> usize {
        self.nodes.push(x);
        self.images.push(u);
        self.boundary.push(boundary);
        self.nodes.len() - 1
    }

    /// Split every edge shared by two triangles whose ends are both boundary nodes at
    /// its midpoint (an interior node), each triangle beside it into two.
    fn split_dividing_edges(&mut self) {
        loop {
            let mut owner: HashMap<(usize, usize), usize> = HashMap::new();
            for (t, tri) in self.tris.iter().enumerate() {
                for k in 0..3 {
                    owner.insert((tri[k], tri[(k + 1) % 3]), t);
                }
            }
            // the dividing edge of the smallest node pair: the same mesh on every run (the
            // hash map's order of iteration is not)
            let found = owner
                .iter()
                .filter_map(|(&(a, b), &t1)| {
                    (a < b && self.boundary[a] && self.boundary[b]).then_some(())?;
                    owner.get(&(b, a)).map(|&t2| (a, b, t1, t2))
                })
                .min();
            let Some((a, b, t1, t2)) = found else { return };
            let m = self.add_node(lerp(self.nodes[a], self.nodes[b], 0.5), [0.0; 2], false);
            for (t, (x, y)) in [(t1, (a, b)), (t2, (b, a))] {
                let tri = self.tris[t];
                let k = (0..3).find(|&k| tri[k] == x && tri[(k + 1) % 3] == y).expect("the edge is in its triangle");
                let c = tri[(k + 2) % 3];
                self.tris[t] = [x, m, c];
                self.tris.push([m, y, c]);
            }
        }
    }

    /// Every triangle into four by the midpoints of its edges (a boundary edge's midpoint
    /// is a boundary node, its image the midpoint of the ends' images).
    fn refine(&mut self) {
        let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
        let mut edge_count: HashMap<(usize, usize), usize> = HashMap::new();
        for tri in &self.tris {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                *edge_count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let old = std::mem::take(&mut self.tris);
        for tri in old {
            let mut m = [0; 3];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[k] = match mid.get(&key) {
                    Some(&v) => v,
                    None => {
                        let on_boundary = edge_count[&key] == 1;
                        let u = if on_boundary { lerp(self.images[a], self.images[b], 0.5) } else { [0.0; 2] };
                        let v = self.add_node(lerp(self.nodes[a], self.nodes[b], 0.5), u, on_boundary);
                        mid.insert(key, v);
                        v
                    }
                };
            }
            self.tris.push([tri[0], m[0], m[2]]);
            self.tris.push([m[0], tri[1], m[1]]);
            self.tris.push([m[2], m[1], tri[2]]);
            self.tris.push([m[0], m[1], m[2]]);
        }
    }

    /// The interior images: Floater's mean value map (see the module documentation),
    /// by sparse LU.
    fn solve(&mut self) -> Result<()> {
        let n = self.nodes.len();
        let mut unknown = vec![usize::MAX; n];
        let mut count = 0;
        for i in 0..n {
            if !self.boundary[i] {
                unknown[i] = count;
                count += 1;
            }
        }
        if count == 0 {
            return Ok(());
        }
        let mut w: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for tri in &self.tris {
            for k in 0..3 {
                let (i, j, l) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                if self.boundary[i] {
                    continue;
                }
                let (x, a, b) = (self.nodes[i], self.nodes[j], self.nodes[l]);
                let u = [a[0] - x[0], a[1] - x[1]];
                let v = [b[0] - x[0], b[1] - x[1]];
                let (lu, lv) = (u[0].hypot(u[1]), v[0].hypot(v[1]));
                // tan(θ/2) = (|u||v| - u·v) / (u × v)
                let t = (lu * lv - (u[0] * v[0] + u[1] * v[1])) / (u[0] * v[1] - u[1] * v[0]);
                w[i].push((j, t / lu));
                w[i].push((l, t / lv));
            }
        }
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); count];
        let mut rhs = [vec![0.0; count], vec![0.0; count]];
        for i in 0..n {
            let r = unknown[i];
            if r == usize::MAX {
                continue;
            }
            let mut diag = 0.0;
            for &(j, wij) in &w[i] {
                if !(wij.is_finite() && wij > 0.0) {
                    return Err(Error::Invalid(format!(
                        "polygon map: a degenerate triangle at ({:.6}, {:.6})",
                        self.nodes[i][0], self.nodes[i][1]
                    )));
                }
                diag += wij;
                if self.boundary[j] {
                    rhs[0][r] += wij * self.images[j][0];
                    rhs[1][r] += wij * self.images[j][1];
                } else {
                    rows[r].push((unknown[j], -wij));
                }
            }
            rows[r].push((r, diag));
        }
        let a = Csr::from_rows(count, rows);
        let mut lu = LinearSolver::new(LinearMethod::Lu);
        lu.factor(&a)?;
        for (d, b) in rhs.iter().enumerate() {
            let x = lu.solve(b)?;
            for i in 0..n {
                if unknown[i] != usize::MAX {
                    self.images[i][d] = x[unknown[i]];
                }
            }
        }
        Ok(())
    }
}

impl PolygonMap {
    /// The map of the face whose sides (counter-clockwise, side `k` from corner `k` to
    /// corner `k + 1`) are `sides` onto the regular polygon with as many sides: about
    /// `per_side` boundary nodes a side, `levels` refinements.
    pub fn new(sides: &[Curve], per_side: usize, levels: usize) -> Result<Self> {
        let n = sides.len();
        if n < 3 {
            return Err(Error::Invalid(format!("polygon map: a face of {n} sides (3 or more needed)")));
        }
        let arcs: Vec<ArcLength> = sides.iter().map(ArcLength::new).collect();
        let total: f64 = arcs.iter().map(ArcLength::length).sum();
        if total.is_nan() || total <= 0.0 {
            return Err(Error::Invalid("polygon map: a face of zero perimeter".into()));
        }
        let mut mesh = Mesh { nodes: Vec::new(), images: Vec::new(), boundary: Vec::new(), tris: Vec::new() };
        for (k, c) in sides.iter().enumerate() {
            let m = ((per_side * n) as f64 * arcs[k].length() / total).round().max(4.0) as usize;
            let (a, b) = (polygon_vertex(n, k), polygon_vertex(n, k + 1));
            for j in 0..m {
                let t = j as f64 / m as f64;
                let x = if j == 0 { c.endpoints().0 } else { c.eval(arcs[k].param(t)) };
                mesh.add_node(x, lerp(a, b, t), true);
            }
        }
        mesh.tris = ear_clip(&mesh.nodes)?;
        flip_to_delaunay(&mesh.nodes, &mut mesh.tris);
        mesh.split_dividing_edges();
        for _ in 0..levels {
            mesh.refine();
        }
        mesh.solve()?;
        let grids = [Buckets::new(&mesh.nodes, &mesh.tris), Buckets::new(&mesh.images, &mesh.tris)];
        Ok(Self { n, nodes: mesh.nodes, images: mesh.images, triangles: mesh.tris, grids })
    }

    /// The point of `to` at the barycentric coordinates that `q` has in the triangle of
    /// `from` containing it (to `1e-9`), `None` when none does.
    fn carry(&self, grid: &Buckets, from: &[Point], to: &[Point], q: Point) -> Option<Point> {
        let mut best: Option<(usize, [f64; 3], f64)> = None;
        // the triangles of the point's cell first, every triangle when none contains it
        let candidates = grid.list(q).iter().copied().chain(0..self.triangles.len());
        for t in candidates {
            let tri = &self.triangles[t];
            let l = barycentric(from[tri[0]], from[tri[1]], from[tri[2]], q);
            let worst = l[0].min(l[1]).min(l[2]);
            if best.is_none_or(|b| worst > b.2) {
                best = Some((t, l, worst));
                if worst >= -1e-12 {
                    break;
                }
            }
        }
        let (t, l, worst) = best?;
        if worst < -1e-9 {
            return None;
        }
        let tri = self.triangles[t];
        let (a, b, c) = (to[tri[0]], to[tri[1]], to[tri[2]]);
        Some([l[0] * a[0] + l[1] * b[0] + l[2] * c[0], l[0] * a[1] + l[1] * b[1] + l[2] * c[1]])
    }

    /// Smallest ratio of image to face area over the triangles (positive: one-to-one).
    #[cfg(test)]
    fn min_area_ratio(&self) -> f64 {
        let (x, y) = (&self.nodes, &self.images);
        let ratio = |t: &[usize; 3]| cross(y[t[0]], y[t[1]], y[t[2]]) / cross(x[t[0]], x[t[1]], x[t[2]]);
        self.triangles.iter().map(ratio).fold(f64::INFINITY, f64::min)
    }

    /// The image of a point of the face (`None` outside its triangulation).
    #[cfg(test)]
    fn forward(&self, x: Point) -> Option<Point> {
        self.carry(&self.grids[0], &self.nodes, &self.images, x)
    }

    /// The point of the face whose image is `q` (`None` outside the polygon).
    pub fn inverse(&self, q: Point) -> Option<Point> {
        self.carry(&self.grids[1], &self.images, &self.nodes, q)
    }

    /// The preimage of the polygon's centre: the template's interior vertex.
    pub fn centre(&self) -> Option<Point> {
        self.inverse([0.0, 0.0])
    }

    /// The preimages of `samples + 1` evenly spaced points on the segment from the
    /// centre of the polygon to the midpoint of its side `s`.
    pub(crate) fn spoke(&self, s: usize, samples: usize) -> Option<Vec<Point>> {
        self.segment([0.0, 0.0], self.side_midpoint(s), samples)
    }

    /// The midpoint of the polygon's side `s` (the image of the arc-length midpoint of
    /// the face's side `s`).
    pub(crate) fn side_midpoint(&self, s: usize) -> Point {
        lerp(polygon_vertex(self.n, s), polygon_vertex(self.n, s + 1), 0.5)
    }

    /// The preimages of `samples + 1` evenly spaced points on the segment of the polygon
    /// from `a` to `b`.
    pub(crate) fn segment(&self, a: Point, b: Point, samples: usize) -> Option<Vec<Point>> {
        (0..=samples).map(|i| self.inverse(lerp(a, b, i as f64 / samples as f64))).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    fn line(a: Point, b: Point) -> Curve {
        Curve::new(KnotVector::open_uniform(1, 1), vec![a, b], None).unwrap()
    }

    fn close(a: Point, b: Point, tol: f64) -> bool {
        (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
    }

    /// On an affine image of the regular polygon (straight sides) the map is the inverse
    /// of the affine map at every node, to rounding.
    #[test]
    fn reproduces_affine_maps() {
        for n in [3, 4, 5, 6, 9] {
            let f = |p: Point| [2.0 * p[0] + 0.7 * p[1] + 3.0, -0.4 * p[0] + 1.3 * p[1] - 1.0];
            let sides: Vec<Curve> =
                (0..n).map(|s| line(f(polygon_vertex(n, s)), f(polygon_vertex(n, s + 1)))).collect();
            let m = PolygonMap::new(&sides, 8, 2).unwrap();
            assert!(m.nodes.len() > 8 * n, "{n}: {} nodes", m.nodes.len());
            for (x, u) in m.nodes.iter().zip(&m.images) {
                assert!(close(f(*u), *x, 1e-10), "{n}: f({u:?}) = {:?}, not {x:?}", f(*u));
            }
            assert!(m.min_area_ratio() > 0.0);
            assert!(close(m.centre().unwrap(), [3.0, -1.0], 1e-10));
        }
    }

    /// A non-convex face (a C shape with a curved inner side): every image triangle is
    /// positive, the inverse of the forward map returns every point, and the spokes stay
    /// inside the face.
    #[test]
    fn non_convex_faces_map_one_to_one_and_round_trip() {
        // a thin C: outer arc radius 1, inner arc radius 0.8, from -150 to 150 degrees,
        // as five sides (two ends and the outer arc in two, the inner arc as one polyline)
        let arc = |r: f64, a0: f64, a1: f64| -> Curve {
            let k = 24;
            let pts: Vec<Point> = (0..=k)
                .map(|i| {
                    let a = (a0 + (a1 - a0) * i as f64 / k as f64).to_radians();
                    [r * a.cos(), r * a.sin()]
                })
                .collect();
            Curve::new(KnotVector::open_uniform(1, k), pts, None).unwrap()
        };
        let sides = vec![
            arc(1.0, -150.0, 0.0),
            arc(1.0, 0.0, 150.0),
            line(
                [150f64.to_radians().cos(), 150f64.to_radians().sin()],
                [0.8 * 150f64.to_radians().cos(), 0.8 * 150f64.to_radians().sin()],
            ),
            arc(0.8, 150.0, -150.0),
            line(
                [0.8 * (-150f64).to_radians().cos(), 0.8 * (-150f64).to_radians().sin()],
                [(-150f64).to_radians().cos(), (-150f64).to_radians().sin()],
            ),
        ];
        let m = PolygonMap::new(&sides, 24, 2).unwrap();
        assert!(m.min_area_ratio() > 0.0, "{}", m.min_area_ratio());
        // the inner side is a polyline of 12.5-degree chords of the circle of radius 0.8,
        // which comes as near to the centre as 0.8 cos(6.25 degrees)
        let r_min = 0.8 * 6.25f64.to_radians().cos();
        let inside = |p: Point| {
            let r = p[0].hypot(p[1]);
            let a = p[1].atan2(p[0]).to_degrees().abs();
            (r_min - 1e-9..=1.0 + 1e-9).contains(&r) && a <= 150.0 + 1e-6
        };
        for s in 0..5 {
            for p in m.spoke(s, 64).unwrap() {
                assert!(inside(p), "spoke {s}: {p:?} leaves the face");
            }
        }
        // round trips: face -> polygon -> face, and polygon -> face -> polygon
        for i in 0..40 {
            let a = (-140.0 + 7.0 * i as f64).to_radians();
            let r = 0.81 + 0.18 * ((i * 7) % 10) as f64 / 10.0;
            let x = [r * a.cos(), r * a.sin()];
            let u = m.forward(x).unwrap();
            assert!(close(m.inverse(u).unwrap(), x, 1e-12), "{x:?}");
            let q = [0.6 * (0.3 * i as f64).cos(), 0.6 * (0.3 * i as f64).sin()];
            let y = m.inverse(q).unwrap();
            assert!(inside(y));
            assert!(close(m.forward(y).unwrap(), q, 1e-12), "{q:?}");
        }
        // outside the polygon: no preimage
        assert!(m.inverse([1.5, 0.0]).is_none());
    }

    #[test]
    fn a_face_of_two_sides_is_refused() {
        let sides = vec![line([0.0, 0.0], [1.0, 0.0]), line([1.0, 0.0], [0.0, 0.0])];
        assert!(PolygonMap::new(&sides, 8, 1).is_err());
    }

    /// The same face gives the same map to the last bit, whatever order the hash maps
    /// iterate in (every `HashMap` has its own random keys).
    #[test]
    fn the_map_is_the_same_on_every_build() {
        // an L-shaped hexagon: its ear clipping leaves dividing edges to split
        let p: [Point; 6] = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]];
        let sides: Vec<Curve> = (0..6).map(|k| line(p[k], p[(k + 1) % 6])).collect();
        let first = PolygonMap::new(&sides, 6, 1).unwrap();
        for _ in 0..8 {
            let again = PolygonMap::new(&sides, 6, 1).unwrap();
            assert_eq!(again.nodes, first.nodes);
            assert_eq!(again.images, first.images);
            assert_eq!(again.triangles, first.triangles);
        }
    }
}
