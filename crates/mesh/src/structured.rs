//! Structured quadrilateral meshes: the map sampled at `xi_i x eta_j` (paper §11.3, the
//! set-up of Fig. 31 is `Xi` uniform with 401 points and `H` from eq. (50) in `eta`).
//!
//! A first-cell height is a physical length: for layers at `eta = 0` it is the length of
//! the first grid edge off the wall, `|x(xi_i, eta_1^(i)) - x(xi_i, 0)|`, and it is met on
//! **every** grid line: each line `xi_i` gets its own parameter spacing `eta_1^(i)`
//! (bisection to round-off, from below, so the first cell never exceeds `H`) and its own
//! geometric layers, so the first heights equal `H` to round-off on a map whose
//! walls are far apart in one place and close in another (a rotor in its casing).
//! With layers in both directions the grid stays a tensor product and `H` is the
//! largest first cell of each wall ([`parameters`]).
//! Growth proceeds geometrically in the parameter along each line, which is the physical
//! growth for an affine map and its first-order approximation otherwise; the quality
//! report measures it and the first heights ([`first_heights`]).
//!
//! A periodic direction (a ring's `eta`) has as many points as cells, its parameters in
//! `[0, 1)`: the seam is one line of nodes shared by the cells on both sides, and it is
//! not a boundary. So has a direction whose two end sides coincide (a ring cut into a
//! four-sided map, [`crate::seam`]): the end side's nodes are those of the start side.
//! The two walls of a ring are named `inner` and `outer` (by the area they enclose,
//! [`crate::seam::wall_names`]).

use glam::DVec2;
use rayon::prelude::*;
use winslow::{Side, Surface};

use crate::distribution::{layer_sizes, points_from_sizes, Distribution};
use crate::equidistribution::equidistributed;
use crate::error::{MeshError, Result};
use crate::seam::{seams, wall_names, Seams};
use crate::{map_points, side_names, BoundaryEdge, ElementKind, Mesh};

/// Options of a structured mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct StructuredOptions {
    /// Points per direction `[nx, ny]` (at least 2 each, 3 in a periodic direction,
    /// where the seam is not repeated: as many points as cells).
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

/// The parameters of a structured grid: node `(i, j)` at `params[j * nx + i]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Points per direction.
    pub n: [usize; 2],
    /// Periodic directions (their last line is not the first repeated).
    pub periodic: [bool; 2],
    /// Parameter of each node, `xi` fastest.
    pub params: Vec<DVec2>,
}

/// Physical length of the first edge off `end` of direction `dir` along the grid line
/// at `o` of the other direction: `|x(.., t) - x(.., end)|`.
fn first_edge(map: &Surface, dir: usize, at_start: bool, t: f64, o: f64) -> f64 {
    let (t0, t1) = if at_start { (0.0, t) } else { (1.0, 1.0 - t) };
    let at = |s: f64| {
        let p = if dir == 0 { map.eval(s, o) } else { map.eval(o, s) };
        DVec2::from(p)
    };
    at(t0).distance(at(t1))
}

/// The parameter spacing whose first edge on the line at `o` has physical length `h`,
/// from below (bisection to round-off; the edge length grows with the spacing on a
/// bijective map): the first cell never exceeds `h`.
fn parameter_height(map: &Surface, dir: usize, at_start: bool, h: f64, g: f64, o: f64, side: &str) -> Result<f64> {
    let full = first_edge(map, dir, at_start, 1.0, o);
    if h.is_nan() || h >= full {
        let other = ["eta", "xi"][dir];
        return Err(MeshError::Layer {
            side: side.into(),
            height: h,
            growth: g,
            why: format!(
                "the height exceeds the whole extent {full:.4e} across the domain on the grid line {other} = {o}"
            ),
        });
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if first_edge(map, dir, at_start, mid, o) <= h {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(lo)
}

/// Sides at the start and end of direction `dir`.
fn sides(dir: usize) -> [Side; 2] {
    if dir == 0 {
        [Side::West, Side::East]
    } else {
        [Side::South, Side::North]
    }
}

/// Parameters of a direction that do not depend on the other: closed forms and
/// equidistributions (`n` points; in a periodic direction `n` points in `[0, 1)`).
fn common(map: &Surface, dir: usize, n: usize, d: &Distribution, periodic: bool) -> Result<Vec<f64>> {
    let m = if periodic { n + 1 } else { n };
    let mut p = match d {
        Distribution::Equidistributed(e) => equidistributed(map, dir, *e, m)?,
        Distribution::Layers { .. } => Distribution::Uniform.points(m - 1).unwrap_or_default(),
        d => d.points(m - 1).ok_or_else(|| MeshError::param(["xi", "eta"][dir], "a distribution without points"))?,
    };
    if periodic {
        p.pop();
    }
    Ok(p)
}

/// Layers of direction `dir` on each grid line `others[k]` of the other direction: the
/// first parameter spacing of each line meets the physical height on that line. With
/// `shared`, one spacing for all lines, the smallest (the height is met where the first
/// edge is longest and every other first cell is smaller).
fn layer_lines(
    map: &Surface,
    dir: usize,
    n: usize,
    d: &Distribution,
    others: &[f64],
    shared: bool,
    seam: &Seams,
) -> Result<Vec<Vec<f64>>> {
    let Distribution::Layers { start, end, growth } = *d else {
        return Err(MeshError::param(["xi", "eta"][dir], "layers expected"));
    };
    // the walls of a ring (the other direction a seam) are named inner and outer
    let [s0, s1] = if seam.dirs[1 - dir] { wall_names(map, 1 - dir) } else { sides(dir).map(Side::name) };
    let heights: Vec<(Option<f64>, Option<f64>)> = others
        .par_iter()
        .map(|&o| {
            let h0 = start.map(|h| parameter_height(map, dir, true, h, growth, o, s0)).transpose()?;
            let h1 = end.map(|h| parameter_height(map, dir, false, h, growth, o, s1)).transpose()?;
            Ok((h0, h1))
        })
        .collect::<Result<_>>()?;
    let heights = if shared {
        let least0 = heights.iter().filter_map(|h| h.0).reduce(f64::min);
        let least1 = heights.iter().filter_map(|h| h.1).reduce(f64::min);
        vec![(least0, least1); heights.len()]
    } else {
        heights
    };
    let names = [s0, s1];
    let all = |m: usize| heights.iter().all(|&(h0, h1)| layer_sizes(m, h0, h1, growth, names).is_ok());
    let mut out = Vec::with_capacity(others.len());
    for (&o, &(h0, h1)) in others.iter().zip(&heights) {
        let sizes = layer_sizes(n - 1, h0, h1, growth, names).map_err(|e| match e {
            MeshError::Layer { side, why, growth, .. } => {
                let height = if side == s0 { start.unwrap_or(0.0) } else { end.unwrap_or(0.0) };
                // the fewest points that would do on every line, when more points help
                let mut hint = String::new();
                if let Some(hi) = (0..24).map(|k| (n - 1) << k).find(|&m| all(m)) {
                    let (mut lo, mut hi) = (hi / 2, hi);
                    while hi - lo > 1 {
                        let mid = (lo + hi) / 2;
                        if all(mid) {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    hint = format!(" (at least {} points in {})", hi + 1, ["xi", "eta"][dir]);
                }
                let line = format!(" on the grid line {} = {o:.6}", ["eta", "xi"][dir]);
                MeshError::Layer { side, height, growth, why: format!("{why}{line}{hint}") }
            }
            e => e,
        })?;
        out.push(points_from_sizes(&sizes));
    }
    Ok(out)
}

/// The parameter of every node of a structured mesh. Closed-form and equidistributed
/// directions are one set of lines; a direction with first-cell heights has its own
/// points on every grid line of the other direction. When both directions have layers
/// the grid stays a tensor product (each direction's own points would move the other's
/// first edges off their lines): one spacing per wall, the height met where the first
/// edge is longest, a few fixed-point sweeps; the report gives the smallest first cell.
/// A periodic direction (or a cut seam, [`crate::seam`]) refuses layers: its ends are
/// the seam, not walls.
pub fn parameters(map: &Surface, opts: &StructuredOptions) -> Result<Grid> {
    let seam_of = seams(map)?;
    let periodic = seam_of.dirs;
    for (k, name) in ["xi", "eta"].iter().enumerate() {
        let least = if periodic[k] { 3 } else { 2 };
        if opts.points[k] < least {
            return Err(MeshError::param(
                format!("{name} points"),
                format!("need at least {least}, got {}", opts.points[k]),
            ));
        }
        opts.distribution[k].validate(name)?;
        if let (true, Distribution::Layers { start, end, growth }) = (periodic[k], &opts.distribution[k]) {
            let [s0, s1] = sides(k);
            let (seam, height) = match start {
                Some(h) => (s0, *h),
                None => (s1, end.unwrap_or(0.0)),
            };
            let walls = sides(1 - k);
            let names = wall_names(map, k);
            let what = if seam_of.periodic_knots[k] { "periodic" } else { "a cut seam: its ends coincide" };
            return Err(MeshError::Layer {
                side: seam.name().into(),
                height,
                growth: *growth,
                why: format!(
                    "{} is the seam of this ring ({name} is {what}), not a wall: the walls are {} ({}) and {} ({}); put the layers there",
                    seam.name(),
                    walls[0].name(),
                    names[0],
                    walls[1].name(),
                    names[1]
                ),
            });
        }
    }
    let n = opts.points;
    let base = [
        common(map, 0, n[0], &opts.distribution[0], periodic[0])?,
        common(map, 1, n[1], &opts.distribution[1], periodic[1])?,
    ];
    let n = [base[0].len(), base[1].len()];
    let layers = opts.distribution.clone().map(|d| matches!(d, Distribution::Layers { .. }));
    let mut lines: [Option<Vec<Vec<f64>>>; 2] = [None, None];
    let sweeps = if layers == [true, true] { 4 } else { 1 };
    // the mean line of each index of a direction (its own points when not per line)
    let mean = |lines: &Option<Vec<Vec<f64>>>, dir: usize| -> Vec<f64> {
        match lines {
            None => base[dir].clone(),
            Some(l) => (0..n[dir]).map(|k| l.iter().map(|v| v[k]).sum::<f64>() / l.len() as f64).collect(),
        }
    };
    for _ in 0..sweeps {
        for dir in 0..2 {
            if layers[dir] {
                let others = mean(&lines[1 - dir], 1 - dir);
                let shared = layers == [true, true];
                lines[dir] = Some(layer_lines(map, dir, n[dir], &opts.distribution[dir], &others, shared, &seam_of)?);
            }
        }
    }
    let coord = |dir: usize, along: usize, line: usize| match &lines[dir] {
        Some(l) => l[line][along],
        None => base[dir][along],
    };
    let params = (0..n[1])
        .flat_map(|j| (0..n[0]).map(move |i| (i, j)))
        .map(|(i, j)| DVec2::new(coord(0, i, j), coord(1, j, i)))
        .collect();
    let grid = Grid { n, periodic, params };
    // a cut seam is merged only where the two sides coincide at the mesh's own nodes
    if let Some(d) = seam_of.cut() {
        let along: Vec<f64> = if d == 1 {
            (0..n[0]).map(|i| grid.params[i].x).collect()
        } else {
            (0..n[1]).map(|j| grid.params[j * n[0]].y).collect()
        };
        seam_of.confirm(map, &along)?;
    }
    Ok(grid)
}

/// A linear structured mesh of `map`: nodes `x(xi_i, eta_j)` stored `xi` fastest, cells
/// counter-clockwise `(i, j), (i+1, j), (i+1, j+1), (i, j+1)` (wrapping around a periodic
/// or cut seam, [`crate::seam`]), boundary edges labelled by side. Not checked for inverted cells: see
/// [`Mesh::check`].
pub fn structured(map: &Surface, opts: &StructuredOptions) -> Result<Mesh> {
    let grid = parameters(map, opts)?;
    Ok(grid_mesh(map, &grid))
}

/// The structured mesh on given grid parameters.
pub fn grid_mesh(map: &Surface, grid: &Grid) -> Mesh {
    let [nx, ny] = grid.n;
    let params = grid.params.clone();
    let points = map_points(map, &params);
    let id = |i: usize, j: usize| (j % ny) * nx + (i % nx);
    let [cx, cy] = [0, 1].map(|d| if grid.periodic[d] { grid.n[d] } else { grid.n[d] - 1 });
    let mut cells = Vec::with_capacity(4 * cx * cy);
    for j in 0..cy {
        for i in 0..cx {
            cells.extend([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mut boundary = Vec::with_capacity(2 * (cx + cy));
    let edge = |side, a, b| BoundaryEdge { side, nodes: vec![a, b] };
    if !grid.periodic[1] {
        boundary.extend((0..cx).map(|i| edge(Side::South, id(i, 0), id(i + 1, 0))));
    }
    if !grid.periodic[0] {
        boundary.extend((0..cy).map(|j| edge(Side::East, id(nx - 1, j), id(nx - 1, j + 1))));
    }
    if !grid.periodic[1] {
        boundary.extend((0..cx).rev().map(|i| edge(Side::North, id(i + 1, ny - 1), id(i, ny - 1))));
    }
    if !grid.periodic[0] {
        boundary.extend((0..cy).rev().map(|j| edge(Side::West, id(0, j + 1), id(0, j))));
    }
    let mut names = side_names();
    for dir in 0..2 {
        if grid.periodic[dir] {
            // the walls are the ends of the other direction: inner encloses less area
            let [s0, s1] = sides(1 - dir);
            let [n0, n1] = wall_names(map, dir);
            names[s0 as usize] = n0.into();
            names[s1 as usize] = n1.into();
        }
    }
    Mesh {
        points,
        params,
        kind: ElementKind::Quad,
        order: 1,
        cells,
        boundary,
        structured: Some([nx, ny]),
        periodic: grid.periodic,
        names,
        groups: None,
    }
}

/// The first-cell heights of a linear structured mesh: for each wall side, the smallest
/// and largest length of the grid edge from a wall node to the next node inward
/// (`|x_(i,1) - x_(i,0)|` at south). Empty for other meshes.
pub fn first_heights(mesh: &Mesh) -> Vec<(Side, [f64; 2])> {
    let Some([nx, ny]) = mesh.structured else { return Vec::new() };
    if mesh.order != 1 || nx < 2 || ny < 2 {
        return Vec::new();
    }
    let p = |i: usize, j: usize| mesh.points[j * nx + i];
    mesh.boundary_sides()
        .into_iter()
        .map(|side| {
            let e: Vec<f64> = match side {
                Side::South => (0..nx).map(|i| p(i, 1).distance(p(i, 0))).collect(),
                Side::North => (0..nx).map(|i| p(i, ny - 2).distance(p(i, ny - 1))).collect(),
                Side::West => (0..ny).map(|j| p(1, j).distance(p(0, j))).collect(),
                Side::East => (0..ny).map(|j| p(nx - 2, j).distance(p(nx - 1, j))).collect(),
            };
            (side, [e.iter().copied().fold(f64::INFINITY, f64::min), e.iter().copied().fold(0.0, f64::max)])
        })
        .collect()
}
