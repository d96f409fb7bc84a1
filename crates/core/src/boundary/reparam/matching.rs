//! Constrained cord length (paper §7.2, eq. 40-42): closest-pair matching of two opposite
//! sides within a threshold, and the abscissae of the second side filled between the
//! matches.

use super::*;

pub(super) fn dist2(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Which opposite sides a search runs across; it fixes on which side of each the domain
/// lies (south: left of its direction, north: right; west: right, east: left).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Across {
    /// Side 1 south, side 2 north.
    SouthNorth,
    /// Side 1 west, side 2 east.
    WestEast,
}

/// The left normal (not normalised) of the polyline `p` at point `i`.
fn left_normal(p: &[Point], i: usize) -> Point {
    let (a, b) = (p[i.saturating_sub(1)], p[(i + 1).min(p.len() - 1)]);
    [a[1] - b[1], b[0] - a[0]]
}

/// Whether `p1[i]` and `p2[j]` face each other across the domain: the segment between
/// them leaves each side towards the domain, `s (p2_j − p1_i) · n1_i > 0` and `s (p2_j −
/// p1_i) · n2_j > 0` with `n` the left normals and `s = ±1` from [`Across`]. Points close
/// across the *outside* (the turns of a spiral channel, the two lips of a slot) are not a
/// narrow gap of the domain and are never matched.
pub fn facing(p1: &[Point], i: usize, p2: &[Point], j: usize, across: Across) -> bool {
    let d = [p2[j][0] - p1[i][0], p2[j][1] - p1[i][1]];
    let s = match across {
        Across::SouthNorth => 1.0,
        Across::WestEast => -1.0,
    };
    let (n1, n2) = (left_normal(p1, i), left_normal(p2, j));
    s * (d[0] * n1[0] + d[1] * n1[1]) > 0.0 && s * (d[0] * n2[0] + d[1] * n2[1]) > 0.0
}

/// Closest-pair matching of eq. 40, recursively: among `p1[i]`, `p2[j]` with `c1[i]` in
/// `(lo1, hi1)` and `c2[j]` in `(lo2, hi2)` (cord-length parameters of each side, the
/// open intervals shrunk by `sep` at both ends), the closest pair within `eps` is matched
/// and the search continues below and above it. Only pairs [`facing`] each other across
/// the domain count. Returns the pairs `(i, j)` ordered by `i` (and then also by `j`).
pub(crate) fn match_pairs(
    p1: &[Point],
    c1: &[f64],
    p2: &[Point],
    c2: &[f64],
    eps: f64,
    sep: f64,
    across: Across,
) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    // explicit stack of boxes (lo1, hi1, lo2, hi2) in parameter space
    let mut stack = vec![(0.0f64, 1.0f64, 0.0f64, 1.0f64)];
    let eps2 = eps * eps;
    while let Some((lo1, hi1, lo2, hi2)) = stack.pop() {
        let r1 = c1.partition_point(|&v| v <= lo1 + sep)..c1.partition_point(|&v| v < hi1 - sep);
        let r2 = c2.partition_point(|&v| v <= lo2 + sep)..c2.partition_point(|&v| v < hi2 - sep);
        if r1.is_empty() || r2.is_empty() {
            continue;
        }
        let mut best = (f64::INFINITY, 0, 0);
        for i in r1.clone() {
            for j in r2.clone() {
                let d = dist2(p1[i], p2[j]);
                if d < best.0 && facing(p1, i, p2, j, across) {
                    best = (d, i, j);
                }
            }
        }
        if best.0 > eps2 {
            continue;
        }
        let (_, i, j) = best;
        out.push((i, j));
        stack.push((lo1, c1[i], lo2, c2[j]));
        stack.push((c1[i], hi1, c2[j], hi2));
    }
    out.sort_unstable();
    out
}

/// Abscissae of the second side from matched values (eq. 41-42 or monotone cubic):
/// `known` holds `(index, ξ)` pairs with increasing index and strictly increasing `ξ`,
/// `c2` the side's own cord-length parameters. The ends are `ξ = 0` and `ξ = 1`.
pub(crate) fn fill_abscissae(c2: &[f64], known: &[(usize, f64)], fill: Fill) -> Result<Vec<f64>> {
    let m = c2.len();
    let mut anchors: Vec<(usize, f64)> = vec![(0, 0.0)];
    anchors.extend(known.iter().copied().filter(|&(j, _)| j > 0 && j + 1 < m));
    anchors.push((m - 1, 1.0));
    if anchors.windows(2).any(|w| w[1].0 <= w[0].0 || w[1].1 <= w[0].1) {
        return Err(Error::Invalid("constrained cord length: matched abscissae are not increasing".into()));
    }
    let mut xi = vec![0.0; m];
    match fill {
        Fill::CordLength => {
            for w in anchors.windows(2) {
                let ((a, xa), (b, xb)) = (w[0], w[1]);
                let span = c2[b] - c2[a];
                for j in a..=b {
                    // eq. 41: local cord length mapped onto [ξ_α, ξ_β]
                    let loc = if span > 0.0 { (c2[j] - c2[a]) / span } else { (j - a) as f64 / (b - a) as f64 };
                    xi[j] = xa + loc * (xb - xa);
                }
            }
        }
        Fill::MonotoneCubic => {
            // abscissa of the interpolant: the side's own cord length (strictly increasing
            // over the anchors; falls back to the index where points repeat)
            let x: Vec<f64> = anchors.iter().map(|&(j, _)| c2[j] + j as f64 * 1e-12).collect();
            let y: Vec<f64> = anchors.iter().map(|a| a.1).collect();
            let mc = MonotoneCubic::new(x, y)?;
            for (j, v) in xi.iter_mut().enumerate() {
                *v = mc.eval(c2[j] + j as f64 * 1e-12);
            }
        }
    }
    for &(j, v) in &anchors {
        xi[j] = v;
    }
    Ok(xi)
}

/// Abscissae of the two sides and the matched index pairs.
pub type Constrained = (Vec<f64>, Vec<f64>, Vec<(usize, usize)>);

/// The constrained cord-length abscissae of two opposite sides (§7.2): `Ξ_1` is the cord
/// length of `p1`; `Ξ_2` takes the value of `Ξ_1` at every matched pair (eq. 40, threshold
/// `eps`, minimum separation `sep`) and is filled in between by `fill`. Returns
/// `(Ξ_1, Ξ_2, matches)`.
pub(crate) fn constrained_params(
    p1: &[Point],
    p2: &[Point],
    eps: f64,
    sep: f64,
    fill: Fill,
    across: Across,
) -> Result<Constrained> {
    let c1 = cord_length_params(p1)
        .ok_or_else(|| Error::Invalid("constrained cord length: first side has zero length".into()))?;
    let c2 = cord_length_params(p2)
        .ok_or_else(|| Error::Invalid("constrained cord length: second side has zero length".into()))?;
    let pairs = match_clouds(p1, &c1, p2, &c2, eps, sep, across);
    let known: Vec<(usize, f64)> = pairs.iter().map(|&(i, j)| (j, c1[i])).collect();
    let xi2 = fill_abscissae(&c2, &known, fill)?;
    Ok((c1, xi2, pairs))
}

/// [`match_pairs`] on two whole clouds with parameters `c1`, `c2` (each increasing over
/// `[0, 1]`): the quadratic search runs on at most [`MAX_SEARCH_POINTS`] points of each
/// (every k-th point, ends kept), the pairs are returned as indices of the full clouds, and only
/// pairs with `c1` strictly increasing inside `(0, 1)` and `c2` strictly increasing are
/// kept (repeated points can give equal parameters). Shared by the four-sided
/// [`constrained_params`] and the ring matching (`boundary::ring_reparam`).
pub(crate) fn match_clouds(
    p1: &[Point],
    c1: &[f64],
    p2: &[Point],
    c2: &[f64],
    eps: f64,
    sep: f64,
    across: Across,
) -> Vec<(usize, usize)> {
    // the closest-pair search is quadratic: on very dense clouds it runs on every k-th point
    let (i1, i2) = (thinned(p1.len()), thinned(p2.len()));
    let pick = |idx: &[usize], v: &[Point]| idx.iter().map(|&k| v[k]).collect::<Vec<_>>();
    let pickc = |idx: &[usize], v: &[f64]| idx.iter().map(|&k| v[k]).collect::<Vec<_>>();
    let mut pairs: Vec<(usize, usize)> =
        match_pairs(&pick(&i1, p1), &pickc(&i1, c1), &pick(&i2, p2), &pickc(&i2, c2), eps, sep, across)
            .into_iter()
            .map(|(a, b)| (i1[a], i2[b]))
            .collect();
    let (mut last1, mut last2) = (0.0, f64::NEG_INFINITY);
    pairs.retain(|&(i, j)| {
        let ok = c1[i] > last1 && c1[i] < 1.0 && c2[j] > last2;
        if ok {
            (last1, last2) = (c1[i], c2[j]);
        }
        ok
    });
    pairs
}

/// Most points per side that the quadratic searches ([`match_pairs`], [`min_distance`])
/// look at; denser clouds are thinned to every k-th point (ends kept).
pub(crate) const MAX_SEARCH_POINTS: usize = 4096;

/// Indices `0, k, 2k, ..., n-1` with `k` the smallest stride leaving at most
/// [`MAX_SEARCH_POINTS`] points.
pub(super) fn thinned(n: usize) -> Vec<usize> {
    let k = n.div_ceil(MAX_SEARCH_POINTS).max(1);
    let mut v: Vec<usize> = (0..n).step_by(k).collect();
    if v.last() != Some(&(n - 1)) {
        v.push(n - 1);
    }
    v
}

/// Smallest distance between points of two opposite sides that are [`facing`] each
/// other across the domain (brute force on at most [`MAX_SEARCH_POINTS`] points of
/// each), used to detect narrow gaps; infinite when no pair faces.
pub(crate) fn min_distance(p1: &[Point], p2: &[Point], across: Across) -> f64 {
    let mut best = f64::INFINITY;
    for &i in &thinned(p1.len()) {
        for &j in &thinned(p2.len()) {
            let d = dist2(p1[i], p2[j]);
            if d < best && facing(p1, i, p2, j, across) {
                best = d;
            }
        }
    }
    best.sqrt()
}

pub(super) fn polyline_length(p: &[Point]) -> f64 {
    p.windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum()
}
