//! Equidistribution of the structured mesh's points along the boundary (paper §11.3:
//! "the spacing of the evaluations can be locally tuned to reach the desired accuracy
//! with less elements").
//!
//! The points `t_0 = 0 < ... < t_{n-1} = 1` of one parameter direction equidistribute a
//! monitor `m(t) > 0` measured on the two sides that run along that direction (south and
//! north for `xi`, west and east for `eta`): `F(t_i) = i / (n - 1) F(1)` with
//! `F(t) = int_0^t m`. With `C_0, C_1` the two sides, `L_k` their lengths and `kappa_k`
//! their curvatures:
//!
//! - **arc length**: `m = (|C_0'| / L_0 + |C_1'| / L_1) / 2`, the mean of the two normalised
//!   arc lengths; where both sides are traversed at proportional speeds (a side and its
//!   offset, a straight side parameterized unevenly) the physical spacings are equal.
//! - **curvature** with a chord tolerance `delta`: `m = sum_k |C_k'| sqrt(kappa_k + kappa_0)`.
//!   A segment of length `h` on a curve of curvature `kappa` deviates from its chord by
//!   `kappa h^2 / 8` to leading order, so equal `h sqrt(kappa)` per segment makes the
//!   deviations equal; `kappa_0` (1e-6 of the mean curvature) keeps straight parts from
//!   collapsing. The point count is then the fewest (at least the count asked for) whose
//!   measured largest chord deviation on both sides is at most `delta`: doubling, then
//!   bisection on the count.
//!
//! `F` is integrated by 8-point Gauss-Legendre on each knot span cut into equal pieces
//! (512 pieces in all at least) and inverted by safeguarded Newton to `1e-14 F(1)`.

use winslow::{Curve, Side, Surface};

use crate::error::{MeshError, Result};

/// Gauss-Legendre nodes and weights on `[-1, 1]`, 8 points.
const GAUSS: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

/// Most points a curvature equidistribution may ask for.
pub const MAX_EQUIDISTRIBUTED_POINTS: usize = 20_000;

/// What a direction's points equidistribute.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Equidistribution {
    /// Arc length of the two sides along the direction.
    ArcLength,
    /// `sqrt(curvature)` times arc length, with the fewest points that keep every
    /// boundary segment within `tol` (physical units) of its side.
    Curvature {
        /// Chord tolerance.
        tol: f64,
    },
}

/// A side as a function of `t in [0, 1]`.
pub(crate) struct SideCurve {
    curve: Curve,
    a: f64,
    b: f64,
}

impl SideCurve {
    pub(crate) fn new(map: &Surface, side: Side) -> Self {
        let curve = map.boundary(side);
        let (a, b) = curve.domain();
        Self { curve, a, b }
    }

    fn point(&self, t: f64) -> [f64; 2] {
        self.curve.eval(self.a + (self.b - self.a) * t)
    }

    /// Speed `|dC/dt|` and curvature `|C' x C''| / |C'|^3` at `t`.
    fn speed_curvature(&self, t: f64) -> (f64, f64) {
        let d = self.curve.derivs(self.a + (self.b - self.a) * t, 2);
        let s = self.b - self.a;
        let (d1, d2) = ([d.d1[0] * s, d.d1[1] * s], [d.d2[0] * s * s, d.d2[1] * s * s]);
        let speed = d1[0].hypot(d1[1]);
        let cross = d1[0] * d2[1] - d1[1] * d2[0];
        let kappa = if speed > 0.0 { cross.abs() / speed.powi(3) } else { 0.0 };
        (speed, kappa)
    }
}

/// `int_a^b m` by 8-point Gauss.
fn gauss(m: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    GAUSS.iter().map(|&(x, w)| w * m(c + h * x)).sum::<f64>() * h
}

/// `F(t) = int_0^t m` on a partition, and its inverse.
struct Cumulative<'a> {
    m: &'a dyn Fn(f64) -> f64,
    edges: Vec<f64>,
    cum: Vec<f64>,
}

impl<'a> Cumulative<'a> {
    /// `breaks` in `[0, 1]` (with 0 and 1); each span cut into equal pieces.
    fn new(m: &'a dyn Fn(f64) -> f64, breaks: &[f64]) -> Self {
        let spans = breaks.len().saturating_sub(1).max(1);
        let pieces = 512usize.div_ceil(spans);
        let mut edges = vec![0.0];
        for w in breaks.windows(2) {
            for k in 1..=pieces {
                edges.push(if k == pieces { w[1] } else { w[0] + (w[1] - w[0]) * k as f64 / pieces as f64 });
            }
        }
        if edges.len() == 1 {
            edges.push(1.0);
        }
        let mut cum = vec![0.0; edges.len()];
        for k in 1..edges.len() {
            cum[k] = cum[k - 1] + gauss(m, edges[k - 1], edges[k]);
        }
        Self { m, edges, cum }
    }

    fn total(&self) -> f64 {
        self.cum[self.cum.len() - 1]
    }

    /// The `t` with `F(t) = target` (`0 <= target <= F(1)`).
    fn inverse(&self, target: f64) -> f64 {
        let k = self.cum.partition_point(|&c| c <= target).clamp(1, self.cum.len() - 1);
        let (mut lo, mut hi) = (self.edges[k - 1], self.edges[k]);
        let base = self.cum[k - 1];
        let tol = 1e-14 * self.total();
        let mut t = if self.cum[k] > base { lo + (hi - lo) * (target - base) / (self.cum[k] - base) } else { lo };
        for _ in 0..100 {
            let g = base + gauss(self.m, self.edges[k - 1], t) - target;
            if g.abs() <= tol {
                break;
            }
            if g > 0.0 {
                hi = t;
            } else {
                lo = t;
            }
            let d = (self.m)(t);
            let newton = t - g / d;
            t = if d > 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
            if hi - lo <= 1e-16 {
                break;
            }
        }
        t
    }

    /// `n` points equidistributing the monitor, ends exactly 0 and 1.
    fn points(&self, n: usize) -> Vec<f64> {
        let total = self.total();
        let mut t: Vec<f64> = (0..n).map(|i| self.inverse(total * i as f64 / (n - 1) as f64)).collect();
        t[0] = 0.0;
        t[n - 1] = 1.0;
        t
    }
}

/// Distance from `p` to the segment `[a, b]`.
fn to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let s = if l2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (p[0] - a[0] - s * dx).hypot(p[1] - a[1] - s * dy)
}

/// Largest distance between the side and the chord of one segment `[t0, t1]`: 17
/// samples, then golden-section search about the best one.
pub(crate) fn segment_deviation(c: &SideCurve, t0: f64, t1: f64) -> f64 {
    let (a, b) = (c.point(t0), c.point(t1));
    let f = |t: f64| to_segment(c.point(t), a, b);
    const M: usize = 16;
    let at = |k: usize| t0 + (t1 - t0) * k as f64 / M as f64;
    let (mut best, mut arg) = (0.0f64, 0);
    for k in 1..M {
        let v = f(at(k));
        if v > best {
            (best, arg) = (v, k);
        }
    }
    let (mut lo, mut hi) = (at(arg.saturating_sub(1)), at((arg + 1).min(M)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..40 {
        if f1 > f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    best.max(f1).max(f2)
}

/// The largest distance between a side of `map` and the chords of its segments at
/// parameters `t` (along the side's own direction, in `[0, 1]`).
pub fn chord_deviation(map: &Surface, side: Side, t: &[f64]) -> f64 {
    let c = SideCurve::new(map, side);
    t.windows(2).map(|w| segment_deviation(&c, w[0], w[1])).fold(0.0, f64::max)
}

/// The sides along direction `dir` (0: `xi`, 1: `eta`).
fn sides_along(dir: usize) -> [Side; 2] {
    if dir == 0 {
        [Side::South, Side::North]
    } else {
        [Side::West, Side::East]
    }
}

/// The points of direction `dir` (0: `xi`, 1: `eta`) equidistributing `e`; `n` points for
/// arc length, at least `n` for curvature.
pub fn equidistributed(map: &Surface, dir: usize, e: Equidistribution, n: usize) -> Result<Vec<f64>> {
    let what = ["xi", "eta"][dir];
    if n < 2 {
        return Err(MeshError::param(format!("{what} points"), format!("need at least 2, got {n}")));
    }
    let sides = sides_along(dir).map(|s| SideCurve::new(map, s));
    let kv = &map.knots[dir];
    let (a, b) = kv.domain();
    let breaks: Vec<f64> = kv.breaks().iter().map(|&u| ((u - a) / (b - a)).clamp(0.0, 1.0)).collect();
    let sr = &sides;
    let speed = |k: usize| move |t: f64| sr[k].speed_curvature(t).0;
    let (s0, s1) = (speed(0), speed(1));
    let lengths = [Cumulative::new(&s0, &breaks).total(), Cumulative::new(&s1, &breaks).total()];
    if !(lengths.iter().all(|l| l.is_finite() && *l > 0.0)) {
        return Err(MeshError::param(what, format!("the sides along {what} have lengths {lengths:?}")));
    }
    let arc = |t: f64| 0.5 * (sides[0].speed_curvature(t).0 / lengths[0] + sides[1].speed_curvature(t).0 / lengths[1]);
    match e {
        Equidistribution::ArcLength => Ok(Cumulative::new(&arc, &breaks).points(n)),
        Equidistribution::Curvature { tol } => {
            if !(tol.is_finite() && tol > 0.0) {
                return Err(MeshError::param(
                    format!("{what} chord tolerance"),
                    format!("must be positive, got {tol}"),
                ));
            }
            // total turning over total length: the mean curvature
            let turn = |t: f64| sides.iter().map(|c| c.speed_curvature(t)).map(|(s, k)| s * k).sum::<f64>();
            let kappa0 = 1e-6 * Cumulative::new(&turn, &breaks).total() / (lengths[0] + lengths[1]);
            let monitor = |t: f64| {
                sides
                    .iter()
                    .map(|c| {
                        let (s, k) = c.speed_curvature(t);
                        s * (k + kappa0).sqrt()
                    })
                    .sum::<f64>()
            };
            let straight = kappa0 == 0.0;
            let cum = if straight { Cumulative::new(&arc, &breaks) } else { Cumulative::new(&monitor, &breaks) };
            let meets = |m: usize| -> (bool, Vec<f64>) {
                let t = cum.points(m);
                let dev =
                    sides.iter().map(|c| t.windows(2).map(|w| segment_deviation(c, w[0], w[1])).fold(0.0, f64::max));
                (dev.fold(0.0, f64::max) <= tol, t)
            };
            let (ok, t) = meets(n);
            if ok {
                return Ok(t);
            }
            // doubling, then bisection: `lo` fails, `hi` meets the tolerance
            let (mut lo, mut hi) = (n, n);
            let mut best = None;
            while best.is_none() {
                lo = hi;
                hi = 2 * hi - 1;
                if hi > MAX_EQUIDISTRIBUTED_POINTS {
                    return Err(MeshError::param(
                        format!("{what} chord tolerance"),
                        format!("{tol:e} needs more than {MAX_EQUIDISTRIBUTED_POINTS} points along {what}"),
                    ));
                }
                let (ok, t) = meets(hi);
                if ok {
                    best = Some(t);
                }
            }
            let mut best = best.unwrap_or_default();
            while hi - lo > 1 {
                let mid = (lo + hi) / 2;
                let (ok, t) = meets(mid);
                if ok {
                    (hi, best) = (mid, t);
                } else {
                    lo = mid;
                }
            }
            Ok(best)
        }
    }
}
