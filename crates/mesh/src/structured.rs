//! Structured quadrilateral meshes: the map sampled at `xi_i x eta_j` (paper §11.3, the
//! set-up of Fig. 31 is `Xi` uniform with 401 points and `H` from eq. (50) in `eta`).
//!
//! A first-cell height is a physical length: for layers at `eta = 0` it is the length of
//! the first grid edge off the wall, `|x(xi_i, eta_1) - x(xi_i, 0)|`, and the parameter
//! spacing `eta_1` is chosen so that its **largest** value over the grid lines `xi_i`
//! equals the height asked for (so `y+` stays below its target everywhere). Growth then
//! proceeds geometrically in the parameter, which is the physical growth for an affine
//! map and its first-order approximation otherwise; the quality report measures it.

use glam::DVec2;
use winslow::{Side, Surface};

use crate::distribution::{layer_sizes, points_from_sizes, Distribution};
use crate::equidistribution::equidistributed;
use crate::error::{MeshError, Result};
use crate::{map_points, BoundaryEdge, ElementKind, Mesh};

/// Options of a structured mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct StructuredOptions {
    /// Points per direction `[nx, ny]` (at least 2 each).
    pub points: [usize; 2],
    /// Distribution of `xi` and of `eta`.
    pub distribution: [Distribution; 2],
}

impl StructuredOptions {
    /// Uniform `nx x ny` points.
    pub fn uniform(nx: usize, ny: usize) -> Self {
        Self { points: [nx, ny], distribution: [Distribution::Uniform, Distribution::Uniform] }
    }
}

/// Physical length of the first edge off `end` of direction `dir`, largest over the
/// grid lines at `others` of the other direction: `max_k |x(.., t) - x(.., end)|`.
fn first_edge(map: &Surface, dir: usize, at_start: bool, t: f64, others: &[f64]) -> f64 {
    let (t0, t1) = if at_start { (0.0, t) } else { (1.0, 1.0 - t) };
    let at = |s: f64, o: f64| {
        let p = if dir == 0 { map.eval(s, o) } else { map.eval(o, s) };
        DVec2::from(p)
    };
    others.iter().map(|&o| at(t0, o).distance(at(t1, o))).fold(0.0, f64::max)
}

/// The parameter spacing whose first edge has physical length `h` (bisection to
/// round-off; the edge length grows with the spacing on a bijective map).
fn parameter_height(map: &Surface, dir: usize, at_start: bool, h: f64, others: &[f64], side: Side) -> Result<f64> {
    let full = first_edge(map, dir, at_start, 1.0, others);
    if h.is_nan() || h >= full {
        return Err(MeshError::Layer {
            side: side.name().into(),
            height: h,
            growth: f64::NAN,
            why: format!("the height exceeds the whole extent {full:.4e} across the domain"),
        });
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if first_edge(map, dir, at_start, mid, others) < h {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // the end nearer to h
    let (el, eh) = (first_edge(map, dir, at_start, lo, others), first_edge(map, dir, at_start, hi, others));
    Ok(if (h - el).abs() <= (eh - h).abs() { lo } else { hi })
}

/// Sides at the start and end of direction `dir`.
fn sides(dir: usize) -> [Side; 2] {
    if dir == 0 {
        [Side::West, Side::East]
    } else {
        [Side::South, Side::North]
    }
}

/// Parameters of direction `dir`, layers measured along the lines at `others`.
fn direction(map: &Surface, dir: usize, n: usize, d: &Distribution, others: &[f64]) -> Result<Vec<f64>> {
    if let Some(p) = d.points(n - 1) {
        return Ok(p);
    }
    let (start, end, growth) = match d {
        Distribution::Layers { start, end, growth } => (start, end, growth),
        Distribution::Equidistributed(e) => return equidistributed(map, dir, *e, n),
        _ => return Err(MeshError::param(["xi", "eta"][dir], "a closed-form distribution without points")),
    };
    let [s0, s1] = sides(dir);
    let h0 = start.map(|h| parameter_height(map, dir, true, h, others, s0)).transpose()?;
    let h1 = end.map(|h| parameter_height(map, dir, false, h, others, s1)).transpose()?;
    let names = [s0.name(), s1.name()];
    let sizes = layer_sizes(n - 1, h0, h1, *growth, names).map_err(|e| match e {
        MeshError::Layer { side, why, growth, .. } => {
            let height = if side == s0.name() { start.unwrap_or(0.0) } else { end.unwrap_or(0.0) };
            // the fewest points that would do, when more points help
            let fits = |m: usize| layer_sizes(m, h0, h1, growth, names).is_ok();
            let mut hint = String::new();
            if let Some(hi) = (0..24).map(|k| (n - 1) << k).find(|&m| fits(m)) {
                let (mut lo, mut hi) = (hi / 2, hi);
                while hi - lo > 1 {
                    let mid = (lo + hi) / 2;
                    if fits(mid) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                hint = format!(" (at least {} points in {})", hi + 1, ["xi", "eta"][dir]);
            }
            MeshError::Layer { side, height, growth, why: format!("{why}{hint}") }
        }
        e => e,
    })?;
    Ok(points_from_sizes(&sizes))
}

/// The parameter points `[xi, eta]` of a structured mesh. Directions with physical
/// first-cell heights are measured along the other direction's final lines (a few
/// fixed-point sweeps when both directions have layers).
pub fn parameters(map: &Surface, opts: &StructuredOptions) -> Result<[Vec<f64>; 2]> {
    for (k, name) in ["xi", "eta"].iter().enumerate() {
        if opts.points[k] < 2 {
            return Err(MeshError::param(format!("{name} points"), format!("need at least 2, got {}", opts.points[k])));
        }
        opts.distribution[k].validate(name)?;
    }
    let uniform = |n: usize| Distribution::Uniform.points(n - 1).unwrap_or_default();
    let mut p = [
        opts.distribution[0].points(opts.points[0] - 1).unwrap_or_else(|| uniform(opts.points[0])),
        opts.distribution[1].points(opts.points[1] - 1).unwrap_or_else(|| uniform(opts.points[1])),
    ];
    let physical = [opts.distribution[0].eval(0.0).is_none(), opts.distribution[1].eval(0.0).is_none()];
    let layers = opts.distribution.iter().filter(|d| matches!(d, Distribution::Layers { .. })).count();
    let sweeps = if layers == 2 { 4 } else { 1 };
    for _ in 0..sweeps {
        for dir in 0..2 {
            if physical[dir] {
                p[dir] = direction(map, dir, opts.points[dir], &opts.distribution[dir], &p[1 - dir])?;
            }
        }
    }
    Ok(p)
}

/// A linear structured mesh of `map`: nodes `x(xi_i, eta_j)` stored `xi` fastest, cells
/// counter-clockwise `(i, j), (i+1, j), (i+1, j+1), (i, j+1)`, boundary edges labelled
/// by side. Not checked for inverted cells: see [`Mesh::check`].
pub fn structured(map: &Surface, opts: &StructuredOptions) -> Result<Mesh> {
    let [xi, eta] = parameters(map, opts)?;
    Ok(grid_mesh(map, &xi, &eta))
}

/// The structured mesh on given parameter lines.
pub fn grid_mesh(map: &Surface, xi: &[f64], eta: &[f64]) -> Mesh {
    let (nx, ny) = (xi.len(), eta.len());
    let params: Vec<DVec2> = eta.iter().flat_map(|&v| xi.iter().map(move |&u| DVec2::new(u, v))).collect();
    let points = map_points(map, &params);
    let id = |i: usize, j: usize| j * nx + i;
    let mut cells = Vec::with_capacity(4 * (nx - 1) * (ny - 1));
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            cells.extend([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mut boundary = Vec::with_capacity(2 * (nx + ny));
    let edge = |side, a, b| BoundaryEdge { side, nodes: vec![a, b] };
    boundary.extend((0..nx - 1).map(|i| edge(Side::South, id(i, 0), id(i + 1, 0))));
    boundary.extend((0..ny - 1).map(|j| edge(Side::East, id(nx - 1, j), id(nx - 1, j + 1))));
    boundary.extend((0..nx - 1).rev().map(|i| edge(Side::North, id(i + 1, ny - 1), id(i, ny - 1))));
    boundary.extend((0..ny - 1).rev().map(|j| edge(Side::West, id(0, j + 1), id(0, j))));
    Mesh { points, params, kind: ElementKind::Quad, order: 1, cells, boundary, structured: Some([nx, ny]) }
}
