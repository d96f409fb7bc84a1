//! Curved quadratic and cubic elements whose nodes lie on the map.
//!
//! Node orderings are Gmsh's (`MSH` element types 9, 21 for triangles and 10, 36 for
//! quadrilaterals; lines 8 and 26 on the boundary): corners counter-clockwise, then the
//! interior nodes of each edge `0-1, 1-2, ...` walked from its first corner, then the
//! interior nodes (for the cubic quadrilateral a small quadrilateral in the same
//! order). A node sits at the lattice point `(i, j) / p` of the reference element
//! (`[0, 1]^2` or the unit triangle); its parameter is the bilinear (linear) image of that
//! point under the element's corner parameters, and its position is `x` there.
//!
//! Each element's own Jacobian, `det dX/d(r, s)` of the Lagrange interpolant
//! `X = sum_k phi_k(r, s) x_k`, is checked positive at its nodes and at Gauss points
//! (`(p + 1)^2` tensor points, collapsed onto the triangle).

use std::collections::HashMap;
use std::ops::{Add, Mul, Sub};

use glam::DVec2;
use winslow::Surface;

use crate::error::{MeshError, Result};
use crate::{BoundaryEdge, ElementKind, Mesh};

/// Lattice coordinates `(i, j)` of the nodes of the reference element of order `p`, in
/// Gmsh's ordering.
pub fn lattice(kind: ElementKind, p: usize) -> Vec<[usize; 2]> {
    let corners: Vec<[usize; 2]> = match kind {
        ElementKind::Quad => vec![[0, 0], [p, 0], [p, p], [0, p]],
        ElementKind::Triangle => vec![[0, 0], [p, 0], [0, p]],
    };
    let mut out = corners.clone();
    let k = corners.len();
    for e in 0..k {
        let (a, b) = (corners[e], corners[(e + 1) % k]);
        for m in 1..p {
            let f = |x: usize, y: usize| ((x * (p - m) + y * m) / p, (x * (p - m) + y * m) % p);
            let (x, rx) = f(a[0], b[0]);
            let (y, ry) = f(a[1], b[1]);
            debug_assert!(rx == 0 && ry == 0);
            out.push([x, y]);
        }
    }
    match (kind, p) {
        (ElementKind::Quad, 2) | (ElementKind::Triangle, 3) => out.push([1, 1]),
        (ElementKind::Quad, 3) => out.extend([[1, 1], [2, 1], [2, 2], [1, 2]]),
        _ => {}
    }
    out
}

/// A number with its two partial derivatives (forward mode).
#[derive(Debug, Clone, Copy)]
struct Dual {
    v: f64,
    d: [f64; 2],
}

impl Dual {
    fn c(v: f64) -> Self {
        Dual { v, d: [0.0; 2] }
    }
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual { v: self.v + o.v, d: [self.d[0] + o.d[0], self.d[1] + o.d[1]] }
    }
}

impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual { v: self.v - o.v, d: [self.d[0] - o.d[0], self.d[1] - o.d[1]] }
    }
}

impl Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual { v: self.v * o.v, d: [self.d[0] * o.v + self.v * o.d[0], self.d[1] * o.v + self.v * o.d[1]] }
    }
}

/// `prod_{q < m} (z - q) / (q + 1)`: 1 at `z = m`, 0 at `z = 0..m-1`.
fn silvester(z: Dual, m: usize) -> Dual {
    (0..m).fold(Dual::c(1.0), |acc, q| acc * (z - Dual::c(q as f64)) * Dual::c(1.0 / (q + 1) as f64))
}

/// 1D Lagrange polynomial of lattice node `i` of order `p` at `z = p t`.
fn lagrange1(z: Dual, i: usize, p: usize) -> Dual {
    (0..=p)
        .filter(|&q| q != i)
        .fold(Dual::c(1.0), |acc, q| acc * (z - Dual::c(q as f64)) * Dual::c(1.0 / (i as f64 - q as f64)))
}

/// Shape functions with their `(r, s)` derivatives at a reference point.
fn shapes(kind: ElementKind, p: usize, lat: &[[usize; 2]], r: f64, s: f64) -> Vec<Dual> {
    let pr = Dual { v: p as f64 * r, d: [p as f64, 0.0] };
    let ps = Dual { v: p as f64 * s, d: [0.0, p as f64] };
    lat.iter()
        .map(|&[i, j]| match kind {
            ElementKind::Quad => lagrange1(pr, i, p) * lagrange1(ps, j, p),
            ElementKind::Triangle => {
                let pl = Dual::c(p as f64) - pr - ps;
                silvester(pr, i) * silvester(ps, j) * silvester(pl, p - i - j)
            }
        })
        .collect()
}

/// Gauss-Legendre points and weights on `[0, 1]` (1 to 4 points).
fn gauss(n: usize) -> Vec<f64> {
    let g: &[f64] = match n {
        1 => &[0.0],
        2 => &[-0.577_350_269_189_625_8, 0.577_350_269_189_625_8],
        3 => &[-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4],
        _ => &[-0.861_136_311_594_052_6, -0.339_981_043_584_856_3, 0.339_981_043_584_856_3, 0.861_136_311_594_052_6],
    };
    g.iter().map(|x| 0.5 * (x + 1.0)).collect()
}

/// Reference points where the Jacobian is checked: the nodes and the Gauss points.
fn check_points(kind: ElementKind, p: usize) -> Vec<[f64; 2]> {
    let mut pts: Vec<[f64; 2]> =
        lattice(kind, p).iter().map(|&[i, j]| [i as f64 / p as f64, j as f64 / p as f64]).collect();
    let g = gauss(p + 1);
    for &a in &g {
        for &b in &g {
            pts.push(match kind {
                ElementKind::Quad => [a, b],
                // collapsed (Duffy) map of the square onto the triangle
                ElementKind::Triangle => [a * (1.0 - b), b],
            });
        }
    }
    pts
}

/// The Jacobian of a curved element of one kind and order at its check points (nodes
/// and Gauss points), shape-function derivatives tabulated once.
#[derive(Debug, Clone)]
pub struct JacobianProbe {
    kind: ElementKind,
    order: usize,
    lattice: Vec<[usize; 2]>,
    derivs: Vec<Vec<[f64; 2]>>,
}

impl JacobianProbe {
    /// Tabulate for elements of `kind` and order `p`.
    pub fn new(kind: ElementKind, p: usize) -> Self {
        let lattice = lattice(kind, p);
        let derivs = check_points(kind, p)
            .iter()
            .map(|&[r, s]| shapes(kind, p, &lattice, r, s).iter().map(|f| f.d).collect())
            .collect();
        Self { kind, order: p, lattice, derivs }
    }

    /// Smallest and largest `det dX/d(r, s)` over the check points of the element with
    /// node positions `x` (Gmsh order).
    pub fn range(&self, x: &[DVec2]) -> [f64; 2] {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for d in &self.derivs {
            let (mut xr, mut xs) = (DVec2::ZERO, DVec2::ZERO);
            for (k, p) in d.iter().zip(x) {
                xr += *p * k[0];
                xs += *p * k[1];
            }
            let det = xr.perp_dot(xs);
            let det = if det.is_nan() { f64::NEG_INFINITY } else { det };
            lo = lo.min(det);
            hi = hi.max(det);
        }
        [lo, hi]
    }

    /// Smallest Jacobian of the curved element with corner parameters `q` whose nodes
    /// are evaluated on `map` (what [`elevate`] would make of that cell).
    pub fn curved_min(&self, map: &Surface, q: &[DVec2]) -> f64 {
        let p = self.order as f64;
        let x: Vec<DVec2> = self
            .lattice
            .iter()
            .map(|&[i, j]| {
                let t = reference_to_parameter(self.kind, q, i as f64 / p, j as f64 / p);
                DVec2::from(map.eval(t.x, t.y))
            })
            .collect();
        self.range(&x)[0]
    }
}

/// Smallest and largest `det dX/d(r, s)` of element `c` over its check points.
fn element_det_range(mesh: &Mesh, c: usize, probe: &JacobianProbe) -> [f64; 2] {
    let x: Vec<DVec2> = mesh.cell(c).iter().map(|&n| mesh.points[n]).collect();
    probe.range(&x)
}

/// Refuse a curved mesh with an element whose Jacobian is not positive at a node or a
/// Gauss point.
pub fn check_jacobians(mesh: &Mesh) -> Result<()> {
    let probe = JacobianProbe::new(mesh.kind, mesh.order);
    let mut first = None;
    let mut count = 0;
    for c in 0..mesh.num_cells() {
        let [lo, _] = element_det_range(mesh, c, &probe);
        if lo.is_nan() || lo <= 0.0 {
            count += 1;
            first.get_or_insert((c, lo));
        }
    }
    match first {
        Some((cell, lo)) => Err(MeshError::Inverted {
            cell,
            why: format!("curved element Jacobian {lo:.3e} at a node or Gauss point"),
            count,
        }),
        None => Ok(()),
    }
}

/// Smallest `min det / max det` of an element's Jacobian over the mesh.
pub fn min_jacobian_ratio(mesh: &Mesh) -> f64 {
    let probe = JacobianProbe::new(mesh.kind, mesh.order);
    (0..mesh.num_cells())
        .map(|c| {
            let [lo, hi] = element_det_range(mesh, c, &probe);
            lo / hi
        })
        .fold(f64::INFINITY, f64::min)
}

/// The parameter of reference point `(r, s)` of a cell with corner parameters `q`.
fn reference_to_parameter(kind: ElementKind, q: &[DVec2], r: f64, s: f64) -> DVec2 {
    match kind {
        ElementKind::Quad => {
            q[0] * ((1.0 - r) * (1.0 - s)) + q[1] * (r * (1.0 - s)) + q[2] * (r * s) + q[3] * ((1.0 - r) * s)
        }
        ElementKind::Triangle => q[0] + (q[1] - q[0]) * r + (q[2] - q[0]) * s,
    }
}

/// Raise a linear mesh to order `p` (2 or 3): edge nodes shared between neighbours,
/// every new node evaluated on `map`. Order 1 returns the mesh unchanged.
pub fn elevate(mesh: &Mesh, map: &Surface, p: usize) -> Result<Mesh> {
    if mesh.order != 1 {
        return Err(MeshError::param("order", format!("can only elevate a linear mesh, got order {}", mesh.order)));
    }
    if !(1..=3).contains(&p) {
        return Err(MeshError::param("order", format!("must be 1, 2 or 3, got {p}")));
    }
    if p == 1 {
        return Ok(mesh.clone());
    }
    if mesh.groups.is_some() {
        // its parameters are patch-local: one map cannot place the new nodes
        return Err(MeshError::param("order", format!("{p} on a mesh of several patches: only linear cells so far")));
    }
    let lat = lattice(mesh.kind, p);
    let k = mesh.kind.corners();
    let periodic = mesh.periodic;
    // across a periodic seam a cell's corner parameters are unwrapped next to `o`, and
    // the new nodes' parameters wrapped back into [0, 1)
    let unwrap = move |o: DVec2, q: DVec2| {
        let mut q = q;
        for d in 0..2 {
            if periodic[d] {
                q[d] -= (q[d] - o[d]).round();
            }
        }
        q
    };
    let wrap = move |q: DVec2| {
        let mut q = q;
        for d in 0..2 {
            if periodic[d] {
                q[d] = q[d].rem_euclid(1.0);
                if q[d] >= 1.0 {
                    q[d] = 0.0;
                }
            }
        }
        q
    };
    let mut params = mesh.params.clone();
    let mut edge_nodes: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    let mut cells = Vec::with_capacity(mesh.num_cells() * lat.len());
    // the interior nodes of edge a-b, from a
    let mut edge = |a: usize, b: usize, params: &mut Vec<DVec2>| -> Vec<usize> {
        let (lo, hi) = (a.min(b), a.max(b));
        let ids = edge_nodes
            .entry((lo, hi))
            .or_insert_with(|| {
                (1..p)
                    .map(|m| {
                        let t = m as f64 / p as f64;
                        let (a, b) = (params[lo], unwrap(params[lo], params[hi]));
                        params.push(wrap(a * (1.0 - t) + b * t));
                        params.len() - 1
                    })
                    .collect()
            })
            .clone();
        if a == lo {
            ids
        } else {
            ids.into_iter().rev().collect()
        }
    };
    for c in 0..mesh.num_cells() {
        let v = mesh.corners(c).to_vec();
        let q: Vec<DVec2> = v.iter().map(|&n| unwrap(mesh.params[v[0]], mesh.params[n])).collect();
        cells.extend(&v);
        for e in 0..k {
            let ids = edge(v[e], v[(e + 1) % k], &mut params);
            cells.extend(ids);
        }
        for &[i, j] in &lat[k + k * (p - 1)..] {
            params.push(wrap(reference_to_parameter(mesh.kind, &q, i as f64 / p as f64, j as f64 / p as f64)));
            cells.push(params.len() - 1);
        }
    }
    let boundary = mesh
        .boundary
        .iter()
        .map(|b| {
            let (a, c) = (b.nodes[0], b.nodes[1]);
            let mut nodes = vec![a, c];
            nodes.extend(edge(a, c, &mut params));
            BoundaryEdge { side: b.side, nodes }
        })
        .collect();
    let mut points = mesh.points.clone();
    points.extend(crate::map_points(map, &params[mesh.points.len()..]));
    Ok(Mesh {
        points,
        params,
        kind: mesh.kind,
        order: p,
        cells,
        boundary,
        structured: None,
        periodic: mesh.periodic,
        names: mesh.names.clone(),
        groups: mesh.groups.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_functions_are_a_partition_of_unity_and_interpolate() {
        for kind in [ElementKind::Quad, ElementKind::Triangle] {
            for p in 1..=3 {
                let lat = lattice(kind, p);
                assert_eq!(lat.len(), kind.nodes(p));
                for (a, &[i, j]) in lat.iter().enumerate() {
                    let sh = shapes(kind, p, &lat, i as f64 / p as f64, j as f64 / p as f64);
                    for (b, f) in sh.iter().enumerate() {
                        assert!((f.v - if a == b { 1.0 } else { 0.0 }).abs() < 1e-13, "{kind:?} p={p}");
                    }
                }
                let sh = shapes(kind, p, &lat, 0.3, 0.2);
                assert!((sh.iter().map(|f| f.v).sum::<f64>() - 1.0).abs() < 1e-13);
                assert!(sh.iter().map(|f| f.d[0]).sum::<f64>().abs() < 1e-12);
            }
        }
        // Gmsh's cubic quadrilateral: edge 2-3 walks from corner 2, interior like a quad
        assert_eq!(lattice(ElementKind::Quad, 3)[8..12], [[2, 3], [1, 3], [0, 2], [0, 1]]);
        assert_eq!(lattice(ElementKind::Quad, 3)[12..], [[1, 1], [2, 1], [2, 2], [1, 2]]);
        assert_eq!(lattice(ElementKind::Triangle, 3)[7..], [[0, 2], [0, 1], [1, 1]]);
    }
}
