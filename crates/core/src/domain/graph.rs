//! The plane graph of a layout under construction: vertices, edges (spline curves from
//! one vertex to another) and faces (counter-clockwise cycles of edges, each traversed
//! forwards or backwards), with the two operations every layout step is made of:
//! splitting an edge at a point (both faces beside it get the new vertex) and splitting
//! a face by a new edge between two of its corners. A face whose sides are four edges is
//! a patch: its sides are the patch's south, east, reversed north and reversed west.

use crate::error::Result;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;

/// An edge: a curve on `[0, 1]` from vertex `a` to vertex `b`.
#[derive(Debug, Clone)]
pub(crate) struct Edge {
    /// The curve (normalised).
    pub curve: Curve,
    /// Start vertex.
    pub a: usize,
    /// End vertex.
    pub b: usize,
    /// On the domain's boundary (one face beside it).
    pub boundary: bool,
}

/// A side of a face: an edge and whether the face runs along it (`true`) or against it.
pub(crate) type FaceSide = (usize, bool);

/// A face: its sides counter-clockwise (the face to their left) and its label.
#[derive(Debug, Clone)]
pub struct Face {
    /// The sides in order; side `k` starts at corner `k`.
    pub sides: Vec<FaceSide>,
    /// The label of the region it belongs to (`"domain"`, or a graph face's label).
    pub label: String,
    /// Holes (before they are cut away by [`super::holes`]): closed cycles of sides
    /// with the face to their left (clockwise).
    pub holes: Vec<Vec<FaceSide>>,
}

impl Face {
    /// A face without holes.
    pub fn new(sides: Vec<FaceSide>, label: impl Into<String>) -> Self {
        Self { sides, label: label.into(), holes: Vec::new() }
    }
}

/// Vertices, edges and faces.
#[derive(Debug, Clone, Default)]
pub struct Graph {
    /// Vertex positions.
    pub vertices: Vec<Point>,
    /// Edges.
    pub edges: Vec<Edge>,
    /// Faces.
    pub faces: Vec<Face>,
}

/// `c` split at the parameter `u` strictly inside its domain: the curve before and after
/// (knot insertion up to multiplicity `p`, so both halves are exactly the curve and share
/// the control point at `u`), each normalised to `[0, 1]`.
pub(crate) fn split_curve(c: &Curve, u: f64) -> Result<(Curve, Curve)> {
    let p = c.degree();
    // a knot within the knot tolerance of u is where the curve is split
    let u = if c.knots.multiplicity(u) > 0 {
        c.knots.knots().iter().copied().min_by(|a, b| (a - u).abs().total_cmp(&(b - u).abs())).unwrap_or(u)
    } else {
        u
    };
    let have = c.knots.knots().iter().filter(|&&t| t == u).count();
    let fine = if have < p { c.knots.with_inserted(&vec![u; p - have]) } else { c.knots.clone() };
    let mut r = c.refined(&fine)?;
    // the clamped ends are interpolated: keep them bit for bit (the refinement rounds)
    let last = r.control_points.len() - 1;
    r.control_points[0] = c.control_points[0];
    r.control_points[last] = c.control_points[c.control_points.len() - 1];
    if let (Some(rw), Some(cw)) = (r.weights.as_mut(), c.weights.as_ref()) {
        rw[0] = cw[0];
        rw[last] = cw[cw.len() - 1];
    }
    let k = r.knots.knots();
    let i0 = k.partition_point(|&x| x < u);
    let mult = k[i0..].iter().take_while(|&&x| x == u).count();
    let mut left_knots = k[..i0].to_vec();
    left_knots.extend(std::iter::repeat_n(u, p + 1));
    let mut right_knots = vec![u; p + 1];
    right_knots.extend_from_slice(&k[i0 + mult..]);
    let piece = |knots: Vec<f64>, range: std::ops::Range<usize>| -> Result<Curve> {
        let kv = KnotVector::new(p, knots)?;
        let w = r.weights.as_ref().map(|w| w[range.clone()].to_vec());
        Ok(Curve::new(kv, r.control_points[range].to_vec(), w)?.normalized())
    };
    let n = r.control_points.len();
    Ok((standard_weights(piece(left_knots, 0..i0)?), standard_weights(piece(right_knots, i0 - 1..n)?)))
}

/// A rational Bézier curve (one segment) in standard form: the same curve with both end
/// weights 1, by the Möbius reparameterization `w_i -> w_i r^i / w_0`, `r = (w_0 /
/// w_p)^(1/p)` (Farin, *NURBS*, §13.4), so that the corners of the patches it bounds
/// carry one weight. Other curves are returned as they are.
fn standard_weights(mut c: Curve) -> Curve {
    let p = c.degree();
    let Some(w) = c.weights.as_mut() else { return c };
    if c.control_points.len() != p + 1 {
        return c;
    }
    let (w0, wp) = (w[0], w[p]);
    let r = (w0 / wp).powf(1.0 / p as f64);
    for (i, x) in w.iter_mut().enumerate() {
        *x *= r.powi(i as i32) / w0;
    }
    w[0] = 1.0;
    w[p] = 1.0;
    c
}

/// The angle in `[0, 2π)` by which the direction `a` turns counter-clockwise to `b`.
pub(crate) fn ccw_angle(a: Point, b: Point) -> f64 {
    let t = (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]);
    if t < 0.0 {
        t + 2.0 * std::f64::consts::PI
    } else {
        t
    }
}

fn unit(d: Point) -> Point {
    let l = d[0].hypot(d[1]);
    if l > 0.0 {
        [d[0] / l, d[1] / l]
    } else {
        d
    }
}

/// The unit tangent of `c` at its start (`end = false`) or end, in its direction (the
/// chord to a nearby point where the derivative vanishes).
pub(crate) fn end_tangent(c: &Curve, end: bool) -> Point {
    let u = if end { 1.0 } else { 0.0 };
    let d = c.derivs(u, 1).d1;
    if d[0].hypot(d[1]) > 0.0 && d[0].is_finite() && d[1].is_finite() {
        return unit(d);
    }
    let (p, q) = if end { (c.eval(1.0 - 1e-6), c.eval(1.0)) } else { (c.eval(0.0), c.eval(1e-6)) };
    unit([q[0] - p[0], q[1] - p[1]])
}

impl Graph {
    /// Add a vertex; returns its index.
    pub(crate) fn add_vertex(&mut self, p: Point) -> usize {
        self.vertices.push(p);
        self.vertices.len() - 1
    }

    /// Add an edge; returns its index.
    pub(crate) fn add_edge(&mut self, curve: Curve, a: usize, b: usize, boundary: bool) -> usize {
        self.edges.push(Edge { curve: curve.normalized(), a, b, boundary });
        self.edges.len() - 1
    }

    /// The curve of a face side in the face's direction.
    pub(crate) fn side_curve(&self, s: FaceSide) -> Curve {
        let c = &self.edges[s.0].curve;
        if s.1 {
            c.clone()
        } else {
            c.reversed().normalized()
        }
    }

    /// The vertex a face side ends at.
    pub fn end(&self, s: FaceSide) -> usize {
        self.start((s.0, !s.1))
    }

    /// The vertex a face side starts at.
    pub fn start(&self, s: FaceSide) -> usize {
        let e = &self.edges[s.0];
        if s.1 {
            e.a
        } else {
            e.b
        }
    }

    /// The corners of face `f` (the start of each side).
    pub fn corners(&self, f: usize) -> Vec<usize> {
        self.faces[f].sides.iter().map(|&s| self.start(s)).collect()
    }

    /// The interior angle (radians) of face `f` at its corner `i`.
    pub(crate) fn corner_angle(&self, f: usize, i: usize) -> f64 {
        let sides = &self.faces[f].sides;
        let n = sides.len();
        let t_in = end_tangent(&self.side_curve(sides[(i + n - 1) % n]), true);
        let t_out = end_tangent(&self.side_curve(sides[i]), false);
        if n == 1 {
            return std::f64::consts::PI;
        }
        ccw_angle(t_out, [-t_in[0], -t_in[1]])
    }

    /// The directions at corner `i` of face `f`: the outgoing side's tangent and the
    /// reversed incoming side's tangent (the interior lies counter-clockwise from the
    /// first to the second).
    pub(crate) fn corner_directions(&self, f: usize, i: usize) -> (Point, Point) {
        let sides = &self.faces[f].sides;
        let n = sides.len();
        let t_in = end_tangent(&self.side_curve(sides[(i + n - 1) % n]), true);
        let t_out = end_tangent(&self.side_curve(sides[i]), false);
        (t_out, [-t_in[0], -t_in[1]])
    }

    /// Split edge `e` at its parameter `u` in `(0, 1)`: `e` keeps the first part, a new
    /// edge the second, and every face along `e` gets the new vertex. Returns the new
    /// vertex and edge.
    pub(crate) fn split_edge(&mut self, e: usize, u: f64) -> Result<(usize, usize)> {
        let (left, right) = split_curve(&self.edges[e].curve, u)?;
        // the control point the two halves share (exactly the curve's point at u)
        let v = self.add_vertex(left.control_points[left.control_points.len() - 1]);
        let (b, boundary) = (self.edges[e].b, self.edges[e].boundary);
        self.edges[e].curve = left;
        self.edges[e].b = v;
        let e2 = self.edges.len();
        self.edges.push(Edge { curve: right, a: v, b, boundary });
        let replace = |cycle: &mut Vec<FaceSide>| {
            let mut out = Vec::with_capacity(cycle.len() + 1);
            for &(x, fwd) in cycle.iter() {
                if x != e {
                    out.push((x, fwd));
                } else if fwd {
                    out.extend([(e, true), (e2, true)]);
                } else {
                    out.extend([(e2, false), (e, false)]);
                }
            }
            *cycle = out;
        };
        for f in &mut self.faces {
            replace(&mut f.sides);
            f.holes.iter_mut().for_each(replace);
        }
        Ok((v, e2))
    }

    /// Split face `f` by the edge `cut`, which runs from its corner `i` to its corner
    /// `j`: `f` keeps the part from corner `i` to `j` (closed by the cut backwards), the
    /// new face the part from `j` to `i` (closed by the cut forwards). Returns the new
    /// face.
    pub(crate) fn split_face(&mut self, f: usize, i: usize, j: usize, cut: usize) -> usize {
        let sides = self.faces[f].sides.clone();
        let n = sides.len();
        let mut a: Vec<FaceSide> = (0..(j + n - i) % n).map(|k| sides[(i + k) % n]).collect();
        a.push((cut, false));
        let mut b: Vec<FaceSide> = (0..(i + n - j) % n).map(|k| sides[(j + k) % n]).collect();
        b.push((cut, true));
        let label = self.faces[f].label.clone();
        self.faces[f].sides = a;
        self.faces.push(Face::new(b, label));
        self.faces.len() - 1
    }

    /// Number of edges at every vertex.
    pub fn valences(&self) -> Vec<usize> {
        let mut v = vec![0; self.vertices.len()];
        for e in &self.edges {
            v[e.a] += 1;
            v[e.b] += 1;
        }
        v
    }

    /// Whether every vertex is on a boundary edge, per vertex.
    pub(crate) fn on_boundary(&self) -> Vec<bool> {
        let mut v = vec![false; self.vertices.len()];
        for e in self.edges.iter().filter(|e| e.boundary) {
            v[e.a] = true;
            v[e.b] = true;
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_curve_is_exact_and_shares_the_point() {
        let kv = KnotVector::new(3, vec![0., 0., 0., 0., 0.4, 1., 1., 1., 1.]).unwrap();
        let c = Curve::new(kv, vec![[0., 0.], [1., 2.], [2., -1.], [3., 1.], [4., 0.]], None).unwrap();
        for u in [0.25, 0.4, 0.4 + 1e-15, 0.7] {
            let (a, b) = split_curve(&c, u).unwrap();
            let last = |x: &Curve| x.control_points[x.control_points.len() - 1];
            assert_eq!(last(&a), b.control_points[0]);
            assert_eq!(a.control_points[0], c.control_points[0]);
            assert_eq!(last(&b), last(&c));
            for k in 0..=10 {
                let t = k as f64 / 10.0;
                let (pa, qa) = (a.eval(t), c.eval(t * u));
                let (pb, qb) = (b.eval(t), c.eval(u + t * (1.0 - u)));
                assert!((pa[0] - qa[0]).abs() + (pa[1] - qa[1]).abs() < 1e-13);
                assert!((pb[0] - qb[0]).abs() + (pb[1] - qb[1]).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn halves_of_a_rational_arc_have_end_weights_one() {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let kv = KnotVector::open_uniform(2, 1);
        let arc = Curve::new(kv, vec![[1., 0.], [1., 1.], [0., 1.]], Some(vec![1., w, 1.])).unwrap();
        let (a, b) = split_curve(&arc, 0.3).unwrap();
        for h in [&a, &b] {
            let ws = h.weights.as_ref().unwrap();
            assert_eq!((ws[0], ws[2]), (1.0, 1.0));
            // still on the unit circle
            for k in 0..=20 {
                let p = h.eval(k as f64 / 20.0);
                assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-14, "{p:?}");
            }
        }
        assert_eq!(a.control_points[2], b.control_points[0]);
        assert_eq!(a.control_points[0], [1.0, 0.0]);
    }

    #[test]
    fn angles_and_splits_of_a_square() {
        let line = |a: Point, b: Point| Curve::new(KnotVector::open_uniform(1, 1), vec![a, b], None).unwrap();
        let mut g = Graph::default();
        let pts = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        for p in pts {
            g.add_vertex(p);
        }
        let sides = (0..4).map(|k| (g.add_edge(line(pts[k], pts[(k + 1) % 4]), k, (k + 1) % 4, true), true)).collect();
        g.faces.push(Face::new(sides, "d"));
        for i in 0..4 {
            assert!((g.corner_angle(0, i) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        }
        let (v, _) = g.split_edge(0, 0.5).unwrap();
        assert_eq!(g.vertices[v], [0.5, 0.0]);
        assert_eq!(g.faces[0].sides.len(), 5);
        assert!((g.corner_angle(0, 1) - std::f64::consts::PI).abs() < 1e-12);
        // cut from the new vertex (corner 1) to corner 3 ([1, 1])
        let cut = g.add_edge(line([0.5, 0.0], [1.0, 1.0]), v, 2, false);
        let f2 = g.split_face(0, 1, 3, cut);
        assert_eq!(g.corners(0), vec![v, 1, 2]);
        assert_eq!(g.corners(f2), vec![2, 3, 0, v]);
    }
}
