//! Splitting a domain with its map (paper §11.2, Fig. 25): from a certified map and two
//! points on opposite sides, a splitting curve is the image under the map of a curve in
//! the parameter square between them, either the straight segment or a discrete
//! shortest path in the metric of the map (edge lengths measured in the physical
//! domain, so the path takes the short way through narrow gaps), fitted by a spline
//! curve within a tolerance. The map's boundary is cut at the two points, and the two
//! four-sided domains on either side of the curve share it as an interface: a layout
//! of two patches, ready for a conforming solve.

use serde::Serialize;

use super::check::validate_layout;
use super::layout::{Interface, Layout, Patch, PatchSide};
use crate::boundary::fit::{fit_side, FitOptions};
use crate::boundary::{Analytic, SideCurve};
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};
use crate::spline::surface::{Side, Surface};
use crate::verify::certificate::{Certificate, Finding};

/// The curve in the parameter square that is mapped to the splitting curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum SplitPath {
    /// The straight segment between the two parameter points.
    #[default]
    Straight,
    /// The shortest path in the metric of the map on a grid of the parameter square
    /// (16 neighbours per node), smoothed.
    Shortest,
}

/// A point on a side of the parameter square: side and parameter along it in `(0, 1)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SidePoint {
    /// The side.
    pub side: Side,
    /// Its parameter (with the side's orientation).
    pub t: f64,
}

impl SidePoint {
    /// The point of the parameter square.
    pub fn param(&self) -> [f64; 2] {
        match self.side {
            Side::South => [self.t, 0.0],
            Side::North => [self.t, 1.0],
            Side::West => [0.0, self.t],
            Side::East => [1.0, self.t],
        }
    }
}

/// Options of [`split_map`].
#[derive(Debug, Clone, Copy)]
pub struct SplitOptions {
    /// The parameter curve.
    pub path: SplitPath,
    /// Degree of the splitting curve.
    pub degree: usize,
    /// Fit tolerance of the splitting curve, relative to the map's diameter.
    pub tol: f64,
    /// Grid cells per direction of the shortest path.
    pub grid: usize,
}

impl Default for SplitOptions {
    fn default() -> Self {
        Self { path: SplitPath::Straight, degree: 3, tol: 1e-5, grid: 64 }
    }
}

/// What [`split_map`] did.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct SplitReport {
    /// The parameter curve used.
    pub path: SplitPath,
    /// The two ends.
    pub from: SidePoint,
    /// ...
    pub to: SidePoint,
    /// Length of the splitting curve.
    pub length: f64,
    /// Elements of the fitted splitting curve.
    pub elements: usize,
    /// Largest deviation of the fit from the image of the parameter curve.
    pub fit_error: f64,
    /// Area of each part.
    pub areas: [f64; 2],
}

/// The outcome of [`split_map`].
#[derive(Debug, Clone)]
pub struct Split {
    /// The splitting curve, from the first end to the second.
    pub curve: Curve,
    /// The parameter curve (a polyline in the unit square).
    pub param_path: Vec<[f64; 2]>,
    /// The two patches (as boundaries) and their interface.
    pub layout: Layout,
    /// The report.
    pub report: SplitReport,
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// `c` cut at parameter `t ∈ (0, 1)` into the parts on `[0, t]` and `[t, 1]`, each on
/// `[0, 1]` (knot insertion to full multiplicity: exact).
pub(crate) fn split_curve(c: &Curve, t: f64) -> Result<(Curve, Curve)> {
    if !(t > 0.0 && t < 1.0) {
        return Err(Error::Invalid(format!("cannot cut a curve at {t}: the parameter must be inside (0, 1)")));
    }
    let p = c.degree();
    let c = c.normalized();
    let m = c.knots.multiplicity(t);
    let fine = c.knots.with_inserted(&vec![t; p.saturating_sub(m)]);
    let r = c.refined(&fine)?;
    let k = r.knots.knots();
    let first = k.iter().position(|&x| (x - t).abs() <= 1e-14).expect("t was inserted");
    let last = k.iter().rposition(|&x| (x - t).abs() <= 1e-14).expect("t was inserted");
    let mut lk: Vec<f64> = k[..=last].to_vec();
    lk.push(t);
    let mut rk = vec![t];
    rk.extend_from_slice(&k[first..]);
    let (nl, nr) = (lk.len() - p - 1, rk.len() - p - 1);
    let n = r.control_points.len();
    let part = |knots: Vec<f64>, range: std::ops::Range<usize>| -> Result<Curve> {
        let kv = crate::spline::knots::KnotVector::new(p, knots)?;
        let w = r.weights.as_ref().map(|w| w[range.clone()].to_vec());
        Ok(Curve { knots: kv, control_points: r.control_points[range].to_vec(), weights: w }.normalized())
    };
    Ok((part(lk, 0..nl)?, part(rk, n - nr..n)?))
}

/// The boundary point of `map` nearest to `x`: its side and parameter, and the distance.
pub fn nearest_boundary_point(map: &Surface, x: Point) -> (SidePoint, f64) {
    let mut best = (SidePoint { side: Side::South, t: 0.0 }, f64::INFINITY);
    for side in Side::ALL {
        let c = map.boundary(side);
        let n = 2048;
        let (mut k0, mut d0) = (0usize, f64::INFINITY);
        for k in 0..=n {
            let d = dist(c.eval(k as f64 / n as f64), x);
            if d < d0 {
                (k0, d0) = (k, d);
            }
        }
        // golden-section refinement on the neighbouring samples
        let (mut a, mut b) = ((k0.saturating_sub(1)) as f64 / n as f64, ((k0 + 1).min(n)) as f64 / n as f64);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..60 {
            let (c1, c2) = (b - g * (b - a), a + g * (b - a));
            if dist(c.eval(c1), x) < dist(c.eval(c2), x) {
                b = c2;
            } else {
                a = c1;
            }
        }
        let t = 0.5 * (a + b);
        let d = dist(c.eval(t), x);
        if d < best.1 {
            best = (SidePoint { side, t }, d);
        }
    }
    best
}

/// The parameter polyline of the shortest path between `a` and `b` (on opposite sides)
/// in the metric of `map`, on a `grid x grid` lattice with 16 neighbours per node,
/// avoiding the boundary except at its ends, then smoothed by a few Laplacian passes.
fn shortest_path(map: &Surface, a: [f64; 2], b: [f64; 2], grid: usize) -> Vec<[f64; 2]> {
    let n = grid.max(4);
    let idx = |i: usize, j: usize| j * (n + 1) + i;
    let uv = |i: usize, j: usize| [i as f64 / n as f64, j as f64 / n as f64];
    let pts: Vec<Point> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| (i, j)))
        .map(|(i, j)| {
            let [u, v] = uv(i, j);
            map.eval(u, v)
        })
        .collect();
    let snap = |p: [f64; 2]| ((p[0] * n as f64).round() as usize, (p[1] * n as f64).round() as usize);
    let (s, t) = (snap(a), snap(b));
    let interior = |i: usize, j: usize| i > 0 && j > 0 && i < n && j < n;
    let mut dist_to = vec![f64::INFINITY; (n + 1) * (n + 1)];
    let mut prev = vec![usize::MAX; (n + 1) * (n + 1)];
    let mut heap = std::collections::BinaryHeap::new();
    dist_to[idx(s.0, s.1)] = 0.0;
    heap.push((std::cmp::Reverse(OrdF64(0.0)), idx(s.0, s.1)));
    let steps: [(isize, isize); 16] = [
        (1, 0),
        (-1, 0),
        (0, 1),
        (0, -1),
        (1, 1),
        (1, -1),
        (-1, 1),
        (-1, -1),
        (2, 1),
        (2, -1),
        (-2, 1),
        (-2, -1),
        (1, 2),
        (1, -2),
        (-1, 2),
        (-1, -2),
    ];
    let target = idx(t.0, t.1);
    while let Some((std::cmp::Reverse(OrdF64(d)), k)) = heap.pop() {
        if k == target {
            break;
        }
        if d > dist_to[k] {
            continue;
        }
        let (i, j) = (k % (n + 1), k / (n + 1));
        for (di, dj) in steps {
            let (ii, jj) = (i as isize + di, j as isize + dj);
            if ii < 0 || jj < 0 || ii > n as isize || jj > n as isize {
                continue;
            }
            let (ii, jj) = (ii as usize, jj as usize);
            let kk = idx(ii, jj);
            if kk != target && !interior(ii, jj) {
                continue;
            }
            let nd = d + dist(pts[k], pts[kk]);
            if nd < dist_to[kk] {
                dist_to[kk] = nd;
                prev[kk] = k;
                heap.push((std::cmp::Reverse(OrdF64(nd)), kk));
            }
        }
    }
    let mut path = Vec::new();
    let mut k = target;
    while k != usize::MAX {
        path.push(uv(k % (n + 1), k / (n + 1)));
        k = prev[k];
    }
    path.reverse();
    if path.len() < 2 {
        return vec![a, b];
    }
    let last = path.len() - 1;
    path[0] = a;
    path[last] = b;
    for _ in 0..8 {
        let old = path.clone();
        for k in 1..last {
            for d in 0..2 {
                path[k][d] = 0.25 * old[k - 1][d] + 0.5 * old[k][d] + 0.25 * old[k + 1][d];
            }
        }
    }
    path
}

/// A total order on non-NaN floats for the heap.
#[derive(Debug, Clone, Copy, PartialEq)]
struct OrdF64(f64);

impl PartialOrd for OrdF64 {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Eq for OrdF64 {}

impl Ord for OrdF64 {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The point at parameter `s ∈ [0, 1]` of the polyline `path` by its length.
fn along(path: &[[f64; 2]], cum: &[f64], s: f64) -> [f64; 2] {
    let total = cum[cum.len() - 1];
    let x = s.clamp(0.0, 1.0) * total;
    let k = cum.partition_point(|&c| c < x).clamp(1, cum.len() - 1);
    let (a, b) = (path[k - 1], path[k]);
    let seg = cum[k] - cum[k - 1];
    let f = if seg > 0.0 { (x - cum[k - 1]) / seg } else { 0.0 };
    [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
}

/// Split the domain of the certified map `map` by a curve from `from` to `to` (on
/// opposite sides; see the module documentation).
///
/// Errors: [`Error::InfeasibleStart`] when `certificate` does not prove the map
/// bijective, [`Error::Invalid`] when the ends are not on opposite sides or not inside
/// them, and an [`Error::Layout`] when the two parts are not a valid layout (the curve
/// leaves the domain or touches its boundary).
pub fn split_map(
    name: &str,
    map: &Surface,
    certificate: &Certificate,
    from: SidePoint,
    to: SidePoint,
    opts: &SplitOptions,
) -> Result<Split> {
    if !matches!(certificate.verdict, Finding::Certified { .. } | Finding::DegenerateCorner { .. }) {
        return Err(Error::InfeasibleStart { method: "split".into(), reason: certificate.message() });
    }
    if from.side.opposite() != to.side {
        return Err(Error::Invalid(format!(
            "the splitting curve must run between opposite sides, not from {} to {}",
            from.side, to.side
        )));
    }
    for e in [from, to] {
        if !(e.t > 1e-6 && e.t < 1.0 - 1e-6) {
            return Err(Error::Invalid(format!(
                "the end on the {} side is at {}: it must be inside the side (a part would have three corners)",
                e.side, e.t
            )));
        }
    }
    // from south to north, or from west to east
    let (a, b) = if matches!(from.side, Side::South | Side::West) { (from, to) } else { (to, from) };
    let (pa, pb) = (a.param(), b.param());
    let param_path = match opts.path {
        SplitPath::Straight => vec![pa, pb],
        SplitPath::Shortest => shortest_path(map, pa, pb, opts.grid),
    };
    let mut cum = vec![0.0];
    for w in param_path.windows(2) {
        cum.push(cum[cum.len() - 1] + dist(w[0], w[1]));
    }
    let (m2, path2, cum2) = (map.clone(), param_path.clone(), cum.clone());
    let image = SideCurve::Analytic(Analytic::new(move |s| {
        let [u, v] = along(&path2, &cum2, s);
        m2.eval(u, v)
    }));
    let (xa, xb) = (map.eval(pa[0], pa[1]), map.eval(pb[0], pb[1]));
    let diameter = map.control_diameter();
    let fo = FitOptions { degree: opts.degree, tol: opts.tol, ..Default::default() };
    let fit = fit_side(Side::East, &image, (xa, xb), &fo, opts.tol * diameter)?;
    let mut curve = fit.finest().clone();
    // the cut points of the sides, exactly
    let cut = |s: SidePoint| -> Result<(Curve, Curve)> { split_curve(&map.boundary(s.side), s.t) };
    let (a0, a1) = cut(a)?;
    let (b0, b1) = cut(b)?;
    let last = curve.control_points.len() - 1;
    curve.control_points[0] = a0.endpoints().1;
    curve.control_points[last] = b0.endpoints().1;
    let side = |s: Side| map.boundary(s).normalized();
    let (first, second, shared) = if a.side == Side::South {
        // left: south[0, u0], curve, north[0, u1], west; right: south[u0, 1], east, north[u1, 1], curve
        ([a0, curve.clone(), b0, side(Side::West)], [a1, side(Side::East), b1, curve.clone()], (Side::East, Side::West))
    } else {
        // bottom: south, east[0, v1], curve, west[0, v0]; top: curve, east[v1, 1], north, west[v0, 1]
        (
            [side(Side::South), b0, curve.clone(), a0],
            [curve.clone(), b1, side(Side::North), a1],
            (Side::North, Side::South),
        )
    };
    let layout = Layout {
        name: name.to_string(),
        patches: vec![Patch::from_sides(format!("{name}-a"), first), Patch::from_sides(format!("{name}-b"), second)],
        interfaces: vec![Interface {
            first: PatchSide { patch: 0, side: shared.0 },
            second: PatchSide { patch: 1, side: shared.1 },
            reversed: false,
        }],
    };
    let checked = validate_layout(&layout)?;
    let length = curve.sample(256).windows(2).map(|w| dist(w[0], w[1])).sum();
    let report = SplitReport {
        path: opts.path,
        from,
        to,
        length,
        elements: curve.knots.num_elements(),
        fit_error: fit.final_max_error(),
        areas: [checked.areas[0], checked.areas[1]],
    };
    Ok(Split { curve, param_path, layout, report })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;
    use crate::verify::certificate::{certify, CertifyOptions};

    /// A quarter annulus, xi radial (radius 1 + xi), eta along the arcs.
    fn annulus() -> Surface {
        let kx = KnotVector::open_uniform(3, 4);
        let ky = KnotVector::open_uniform(3, 8);
        let (gx, gy) = (kx.greville(), ky.greville());
        let cps = gy
            .iter()
            .flat_map(|&v| {
                gx.iter().map(move |&u| {
                    let (r, t) = (1.0 + u, std::f64::consts::FRAC_PI_2 * v);
                    [r * t.cos(), r * t.sin()]
                })
            })
            .collect();
        Surface::new([kx, ky], cps, None).unwrap()
    }

    #[test]
    fn cutting_a_curve_is_exact() {
        let c = annulus().boundary(Side::East);
        for t in [0.3, 0.5, 0.625] {
            let (l, r) = split_curve(&c, t).unwrap();
            for k in 0..=10 {
                let s = k as f64 / 10.0;
                assert!(dist(l.eval(s), c.eval(t * s)) < 1e-13);
                assert!(dist(r.eval(s), c.eval(t + (1.0 - t) * s)) < 1e-13);
            }
        }
        assert!(split_curve(&c, 0.0).is_err());
    }

    /// A straight cut at eta = 0.5 of a quarter annulus is the ray at 45 degrees; the two
    /// parts are a valid layout sharing it; the shortest path between the same ends is
    /// the same straight ray (the domain is convex in that direction).
    #[test]
    fn splitting_an_annulus_along_a_ray() {
        let map = annulus();
        let cert = certify(&map, &CertifyOptions::default()).unwrap();
        let from = SidePoint { side: Side::East, t: 0.5 };
        let to = SidePoint { side: Side::West, t: 0.5 };
        for path in [SplitPath::Straight, SplitPath::Shortest] {
            let opts = SplitOptions { path, ..Default::default() };
            let s = split_map("ring", &map, &cert, from, to, &opts).unwrap();
            for k in 0..=20 {
                let p = s.curve.eval(k as f64 / 20.0);
                // on the ray at 45 degrees, between radius 1 and 2
                assert!((p[0] - p[1]).abs() < 5e-4, "{path:?}: {p:?}");
                let r = p[0].hypot(p[1]);
                let (r0, r1) = (map.eval(0.0, 0.5), map.eval(1.0, 0.5));
                assert!((r0[0].hypot(r0[1]) - 1e-9..=r1[0].hypot(r1[1]) + 1e-9).contains(&r), "{r}");
            }
            // from the inner (west) to the outer (east) arc, the cut points exactly
            let (e0, e1) = s.curve.endpoints();
            assert!(dist(e0, map.eval(0.0, 0.5)) < 1e-12 && dist(e1, map.eval(1.0, 0.5)) < 1e-12, "{e0:?} {e1:?}");
            let quarter = 0.5 * crate::verify::quality::quality(&map).functionals.area;
            assert!(
                (s.report.areas[0] - quarter).abs() < 1e-3 && (s.report.areas[1] - quarter).abs() < 1e-3,
                "{:?}",
                s.report
            );
        }
        // ends on adjacent sides: refused
        let e = split_map("ring", &map, &cert, from, SidePoint { side: Side::South, t: 0.5 }, &SplitOptions::default());
        assert!(e.is_err());
    }
}
