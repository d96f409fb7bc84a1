//! Seeded families of hard four-sided domains, the kinds of input real users bring
//! (issue: reliability), in the spirit of G+Smo's `gsNurbsCreator`: the hard corpus that
//! `winslow corpus` writes, `scripts/hard-corpus.sh` solves and the test suite samples.
//!
//! | family | what makes it hard |
//! |---|---|
//! | `clearance` | gaps of `3e-3` to `1e-2` of the length alternating with wide parts (rotor tips) |
//! | `spiral` | a channel of one to two and a half turns |
//! | `sharp-corner` | a corner of 15° to 35° |
//! | `puzzle` | one or two rounded jigsaw tabs per side, in or out |
//! | `strip` | a wavy strip of aspect ratio 20 to 200 |
//! | `cad` | B-spline/NURBS sides: non-uniform non-dyadic knots, an exact circular arc, an interior `C0` kink, different degrees on opposite sides |
//! | `cad-kinks` | degree-2 B-spline sides with `C0` knots: rectangular steps (reflex kinks turning back by 90°) and V-notches turning 30° to 130° at the tip, one to three per side, into the domain or out of it (not in the default corpus: `winslow corpus --families cad-kinks`) |
//! | `jigsaw` | unit-square jigsaw pieces: one to three tabs per side, in or out, on narrow necks whose corners are rounded at 1/30 to 1/8 of the tab radius, every side a dense point cloud (1500 to 3000 points; not in the default corpus) |
//! | `pinched` | a channel of length 1 whose walls close in to a gap of `3e-4` of its length, dense point clouds (not in the default corpus) |
//! | `noisy-cloud` | 1000 to 3000 points per side with noise `1e-4` |
//! | `sparse-cloud` | 8 to 15 points per side |
//!
//! Every domain is a deterministic function of `(family, seed)` and is a valid,
//! counter-clockwise boundary (tested).

use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;

use super::{Boundary, SideCurve};

/// A family of hard domains.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Family {
    /// Narrow clearance gaps between wide parts.
    Clearance,
    /// A spiral channel.
    Spiral,
    /// One sharp corner.
    SharpCorner,
    /// Jigsaw tabs on every side.
    Puzzle,
    /// A long thin wavy strip.
    Strip,
    /// CAD-like spline sides.
    Cad,
    /// Dense noisy point clouds.
    NoisyCloud,
    /// Degree-2 spline sides with steps and V-notches at `C0` knots.
    CadKinks,
    /// Very sparse point clouds.
    SparseCloud,
    /// Jigsaw pieces with narrow, barely rounded necks, as dense point clouds.
    Jigsaw,
    /// A channel pinched to a hair-thin gap.
    Pinched,
}

impl Family {
    /// All families.
    pub const ALL: [Family; 8] = [
        Family::Clearance,
        Family::Spiral,
        Family::SharpCorner,
        Family::Puzzle,
        Family::Strip,
        Family::Cad,
        Family::NoisyCloud,
        Family::SparseCloud,
    ];

    /// Families generated only on request (`winslow corpus --families`), not part of the
    /// default corpus of [`Family::ALL`].
    pub const EXTRA: [Family; 3] = [Family::CadKinks, Family::Jigsaw, Family::Pinched];

    /// Kebab-case name.
    pub fn name(self) -> &'static str {
        match self {
            Family::Clearance => "clearance",
            Family::Spiral => "spiral",
            Family::SharpCorner => "sharp-corner",
            Family::Puzzle => "puzzle",
            Family::Strip => "strip",
            Family::Cad => "cad",
            Family::NoisyCloud => "noisy-cloud",
            Family::CadKinks => "cad-kinks",
            Family::SparseCloud => "sparse-cloud",
            Family::Jigsaw => "jigsaw",
            Family::Pinched => "pinched",
        }
    }

    /// The family called `name`.
    pub fn parse(name: &str) -> Option<Family> {
        Self::ALL.into_iter().chain(Self::EXTRA).find(|f| f.name() == name)
    }

    /// The domain of this family for `seed`, named `"{family}-{seed}"`.
    pub fn generate(self, seed: u64) -> Boundary {
        let mut rng = Rng::new(seed.wrapping_mul(31).wrapping_add(self as u64 + 1));
        let sides = match self {
            Family::Clearance => clearance(&mut rng),
            Family::Spiral => spiral(&mut rng),
            Family::SharpCorner => sharp_corner(&mut rng),
            Family::Puzzle => puzzle(&mut rng),
            Family::Strip => strip(&mut rng),
            Family::Cad => cad(&mut rng),
            Family::CadKinks => cad_kinks(&mut rng),
            Family::Jigsaw => jigsaw(&mut rng),
            Family::Pinched => pinched(&mut rng),
            Family::NoisyCloud => {
                let n = 1000 + (rng.uniform() * 2000.0) as usize;
                deformed_square(&mut rng, n, 1e-4)
            }
            Family::SparseCloud => {
                let n = 8 + (rng.uniform() * 8.0) as usize;
                deformed_square(&mut rng, n, 0.0)
            }
        };
        Boundary { name: format!("{}-{seed}", self.name()), sides }
    }
}

/// `per_family` domains of every family of [`Family::ALL`], seeds `seed, seed + 1, ...`.
pub fn corpus(per_family: usize, seed: u64) -> Vec<(Family, Boundary)> {
    corpus_of(&Family::ALL, per_family, seed)
}

/// `per_family` domains of each of `families`, seeds `seed, seed + 1, ...`.
pub fn corpus_of(families: &[Family], per_family: usize, seed: u64) -> Vec<(Family, Boundary)> {
    families.iter().flat_map(|&f| (0..per_family as u64).map(move |k| (f, f.generate(seed + k)))).collect()
}

/// SplitMix64 (Steele, Lea, Flood 2014): a tiny seeded generator, enough for shapes.
#[derive(Debug, Clone)]
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }
    /// Uniform in `[0, 1)`.
    pub(crate) fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

pub(crate) fn between(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.uniform()
}

/// `n + 1` points `f(k / n)`.
fn sample(n: usize, f: impl Fn(f64) -> Point) -> Vec<Point> {
    (0..=n).map(|k| f(k as f64 / n as f64)).collect()
}

fn segment(a: Point, b: Point) -> SideCurve {
    SideCurve::Points(vec![a, b])
}

/// A channel `[0, 1] × [bottom, top]` whose walls close in to gaps `g` at bumps of width
/// `w`, alternately from the top and from the bottom.
fn clearance(rng: &mut Rng) -> [SideCurve; 4] {
    let h = between(rng, 0.3, 0.5);
    let bumps = 1 + (rng.uniform() * 3.0) as usize;
    let gap = 10f64.powf(between(rng, 3e-3f64.log10(), 1e-2f64.log10()));
    let width = between(rng, 0.12, 0.25) / bumps as f64;
    let centres: Vec<f64> = (0..bumps).map(|k| (k as f64 + 0.5 + between(rng, -0.1, 0.1)) / bumps as f64).collect();
    let bump = |x: f64, parity: usize| {
        centres
            .iter()
            .enumerate()
            .filter(|(k, _)| k % 2 == parity)
            .map(|(_, c)| (-((x - c) / width).powi(2)).exp())
            .fold(0.0, f64::max)
    };
    let top = |x: f64| h - (h - gap) * bump(x, 0);
    let bottom = |x: f64| (h - gap) * bump(x, 1);
    let n = 1200;
    let south = sample(n, |x| [x, bottom(x)]);
    let north = sample(n, |x| [x, top(x)]);
    let (sw, se, nw, ne) = (south[0], south[n], north[0], north[n]);
    [SideCurve::Points(south), segment(se, ne), SideCurve::Points(north), segment(sw, nw)]
}

/// The channel between the spirals `r = a + P θ/2π` (inner) and that plus `t < P`
/// (outer), `θ ∈ [0, 2π T]`: south the outer wall, north the inner one.
fn spiral(rng: &mut Rng) -> [SideCurve; 4] {
    let turns = between(rng, 1.0, 2.5);
    let pitch = between(rng, 0.5, 1.0);
    let a = pitch * between(rng, 1.0, 2.0);
    let t = pitch * between(rng, 0.3, 0.7);
    let theta = 2.0 * std::f64::consts::PI * turns;
    let wall = |off: f64| {
        move |s: f64| {
            let th = s * theta;
            let r = a + pitch * th / (2.0 * std::f64::consts::PI) + off;
            [r * th.cos(), r * th.sin()]
        }
    };
    let n = (200.0 * turns) as usize + 50;
    let south = sample(n, wall(t));
    let north = sample(n, wall(0.0));
    let (sw, se, nw, ne) = (south[0], south[n], north[0], north[n]);
    [SideCurve::Points(south), segment(se, ne), SideCurve::Points(north), segment(sw, nw)]
}

/// A kite with the south-west corner of angle `α ∈ [15°, 35°]`, its sides bent a little.
fn sharp_corner(rng: &mut Rng) -> [SideCurve; 4] {
    let alpha = between(rng, 15.0, 35.0).to_radians();
    let rho = between(rng, 1.25, 1.55);
    let (sw, se) = ([0.0, 0.0], [1.0, 0.0]);
    let nw = [alpha.cos(), alpha.sin()];
    let ne = [rho * (0.5 * alpha).cos(), rho * (0.5 * alpha).sin()];
    let mut bent = |a: Point, b: Point| {
        let amp = between(rng, -0.02, 0.02);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        SideCurve::Points(sample(100, |t| {
            let s = amp * (std::f64::consts::PI * t).sin();
            [a[0] + t * dx - s * dy, a[1] + t * dy + s * dx]
        }))
    };
    [bent(sw, se), bent(se, ne), bent(nw, ne), bent(sw, nw)]
}

/// One side of the unit square with jigsaw tabs, in local coordinates `(s, h)`: `s`
/// along the side, `h` towards the inside.
fn tabbed_side(rng: &mut Rng) -> Vec<[f64; 2]> {
    let tabs = 1 + (rng.uniform() * 2.0) as usize;
    let size = 1.0 / tabs as f64;
    let mut pts = vec![[0.0, 0.0]];
    for k in 0..tabs {
        let dir = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
        let c = (k as f64 + 0.5 + between(rng, -0.05, 0.05)) * size;
        let r = between(rng, 0.09, 0.12) * size;
        let n = between(rng, 0.5, 0.75) * r;
        let neck = between(rng, 0.04, 0.06) * size;
        let delta = (n / r).asin();
        let yc = neck + r * delta.cos();
        pts.push([c - n, 0.0]);
        pts.push([c - n, dir * neck]);
        let (a0, a1) = (-std::f64::consts::FRAC_PI_2 - delta, -2.5 * std::f64::consts::PI + delta);
        for j in 1..16 {
            let a = a0 + (a1 - a0) * j as f64 / 16.0;
            pts.push([c + r * a.cos(), dir * (yc + r * a.sin())]);
        }
        pts.push([c + n, dir * neck]);
        pts.push([c + n, 0.0]);
    }
    pts.push([1.0, 0.0]);
    // baseline segments sampled like the tabs
    let mut out = vec![pts[0]];
    for w in pts.windows(2) {
        let m = ((w[1][0] - w[0][0]).abs() / 0.04).ceil().max(1.0) as usize;
        for j in 1..=m {
            let t = j as f64 / m as f64;
            out.push([w[0][0] + t * (w[1][0] - w[0][0]), w[0][1] + t * (w[1][1] - w[0][1])]);
        }
    }
    // rounded like a cut piece: five rounds of Chaikin's corner cutting (the ends kept)
    for _ in 0..5 {
        let mut cut = vec![out[0]];
        for w in out.windows(2) {
            let at = |t: f64| [w[0][0] + t * (w[1][0] - w[0][0]), w[0][1] + t * (w[1][1] - w[0][1])];
            cut.push(at(0.25));
            cut.push(at(0.75));
        }
        cut.push(out[out.len() - 1]);
        out = cut;
    }
    out
}

/// The unit square with rounded jigsaw tabs on every side.
fn puzzle(rng: &mut Rng) -> [SideCurve; 4] {
    let south = tabbed_side(rng);
    let east = tabbed_side(rng).into_iter().map(|[s, h]| [1.0 - h, s]).collect();
    let north = tabbed_side(rng).into_iter().map(|[s, h]| [s, 1.0 - h]).collect();
    let west = tabbed_side(rng).into_iter().map(|[s, h]| [h, s]).collect();
    [SideCurve::Points(south), SideCurve::Points(east), SideCurve::Points(north), SideCurve::Points(west)]
}

/// A strip of length 1 and width `1/R`, `R ∈ [20, 200]`, around `y = A sin(π k x)`.
fn strip(rng: &mut Rng) -> [SideCurve; 4] {
    let ratio = 20.0 * 10f64.powf(rng.uniform());
    let w = 1.0 / ratio;
    let amp = between(rng, 0.03, 0.13);
    let k = if rng.uniform() < 0.5 { 1.0 } else { 2.0 };
    let pk = std::f64::consts::PI * k;
    let wall = move |off: f64| {
        move |x: f64| {
            let (y, dy) = (amp * (pk * x).sin(), amp * pk * (pk * x).cos());
            let norm = dy.hypot(1.0);
            [x - off * dy / norm, y + off / norm]
        }
    };
    let n = 800;
    let south = sample(n, wall(-0.5 * w));
    let north = sample(n, wall(0.5 * w));
    let (sw, se, nw, ne) = (south[0], south[n], north[0], north[n]);
    [SideCurve::Points(south), segment(se, ne), SideCurve::Points(north), segment(sw, nw)]
}

fn spline(degree: usize, knots: Vec<f64>, cps: Vec<Point>, weights: Option<Vec<f64>>) -> SideCurve {
    let kv = KnotVector::new(degree, knots).expect("valid generated knots");
    SideCurve::Spline(Curve { knots: kv, control_points: cps, weights })
}

/// CAD-like sides on the unit square: south a cubic with non-uniform non-dyadic knots,
/// east an exact circular arc (rational quadratic), north a quadratic with a double knot
/// (a `C0` kink), west a line.
fn cad(rng: &mut Rng) -> [SideCurve; 4] {
    // south: p = 3, three interior knots at least 0.12 apart; horizontal at both ends,
    // so that the corners with the arc stay below 180 degrees (a four-sided CAD patch)
    let mut k = [between(rng, 0.1, 0.3), between(rng, 0.42, 0.58), between(rng, 0.7, 0.9)];
    k.sort_by(f64::total_cmp);
    let knots = [vec![0.0; 4], k.to_vec(), vec![1.0; 4]].concat();
    let kv = KnotVector::new(3, knots.clone()).expect("valid");
    let g = kv.greville();
    let cps: Vec<Point> = g
        .iter()
        .enumerate()
        .map(|(i, &x)| [x, if i <= 1 || i + 2 >= g.len() { 0.0 } else { between(rng, -0.08, 0.08) }])
        .collect();
    let south = spline(3, knots, cps, None);
    // east: arc from (1, 0) to (1, 1) of half-angle phi bulging outwards
    let phi = between(rng, 20.0, 50.0).to_radians();
    let east = spline(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![[1.0, 0.0], [1.0 + 0.5 * phi.tan(), 0.5], [1.0, 1.0]],
        Some(vec![1.0, phi.cos(), 1.0]),
    );
    // north: p = 2 with a double knot at a, the kink at control point 2
    let a = between(rng, 0.3, 0.7);
    let north = spline(
        2,
        vec![0.0, 0.0, 0.0, a, a, 1.0, 1.0, 1.0],
        vec![
            [0.0, 1.0],
            [0.5 * a, 1.0 + between(rng, -0.06, 0.06)],
            [a, 1.0 + between(rng, -0.12, 0.12)],
            [0.5 * (1.0 + a), 1.0 + between(rng, -0.06, 0.06)],
            [1.0, 1.0],
        ],
        None,
    );
    let west = spline(1, vec![0.0, 0.0, 1.0, 1.0], vec![[0.0, 0.0], [0.0, 1.0]], None);
    [south, east, north, west]
}

/// The degree-2 B-spline through the polyline `vertices`: one quadratic piece per segment
/// (its middle control point at the segment's midpoint), a knot of multiplicity 2 (`C0`)
/// at every inner vertex, uniform in the segment index.
fn kinked_polyline(vertices: &[Point]) -> SideCurve {
    let n = vertices.len() - 1;
    let mut knots = vec![0.0; 3];
    let mut cps = vec![vertices[0]];
    for (k, w) in vertices.windows(2).enumerate() {
        cps.push([0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][1] + w[1][1])]);
        cps.push(w[1]);
        let t = (k + 1) as f64 / n as f64;
        if k + 1 == n {
            knots.extend_from_slice(&[1.0; 3]);
        } else {
            knots.extend_from_slice(&[t, t]);
        }
    }
    spline(2, knots, cps, None)
}

/// The vertices of a side from `(0, 0)` to `(1, 0)` with one to three features at least
/// 0.05 apart: a rectangular step (width 0.08 to 0.2, height 0.05 to 0.2) or a V-notch
/// (width 0.06 to 0.2, the tangent turning 30 to 130 degrees at the tip, height 0.2 at most), into the domain
/// (`+y`) or out of it.
fn kinked_side(rng: &mut Rng) -> Vec<Point> {
    let count = 1 + (rng.uniform() * 3.0) as usize;
    let slot = 0.8 / count as f64;
    let mut v = vec![[0.0, 0.0]];
    for k in 0..count {
        let sign = if rng.uniform() < 0.6 { 1.0 } else { -1.0 };
        let a = 0.1 + slot * k as f64;
        if rng.uniform() < 0.4 {
            let w = between(rng, 0.08, 0.2f64.min(slot - 0.05));
            let x = a + between(rng, 0.0, slot - 0.05 - w);
            let h = sign * between(rng, 0.05, 0.2);
            v.extend([[x, 0.0], [x, h], [x + w, h], [x + w, 0.0]]);
        } else {
            // the tangent turns by `turn` at the tip (each flank rises at `turn / 2`, so it
            // turns by half that at the base), the height 0.2 at most (narrower where needed)
            let turn = between(rng, 30.0, 130.0).to_radians();
            let slope = (0.5 * turn).tan();
            let w = between(rng, 0.06, 0.2f64.min(slot - 0.05)).min(0.4 / slope);
            let x = a + between(rng, 0.0, slot - 0.05 - w);
            let h = 0.5 * w * slope;
            v.extend([[x, 0.0], [x + 0.5 * w, sign * h], [x + w, 0.0]]);
        }
    }
    v.push([1.0, 0.0]);
    v
}

/// The unit square with kinked degree-2 spline sides ([`kinked_side`]): the south side
/// always, the north side (mirrored, features from `y = 1`) in half the domains.
fn cad_kinks(rng: &mut Rng) -> [SideCurve; 4] {
    let south = kinked_polyline(&kinked_side(rng));
    let north = if rng.uniform() < 0.5 {
        kinked_polyline(&kinked_side(rng).iter().map(|p| [p[0], 1.0 - p[1]]).collect::<Vec<_>>())
    } else {
        spline(1, vec![0.0, 0.0, 1.0, 1.0], vec![[0.0, 1.0], [1.0, 1.0]], None)
    };
    let east = spline(1, vec![0.0, 0.0, 1.0, 1.0], vec![[1.0, 0.0], [1.0, 1.0]], None);
    let west = spline(1, vec![0.0, 0.0, 1.0, 1.0], vec![[0.0, 0.0], [0.0, 1.0]], None);
    [south, east, north, west]
}

/// The sharp outline of one jigsaw side in local coordinates `(s, h)` (`s` along the side,
/// `h` towards the inside): straight pieces and tab circles, as a dense polyline, with the
/// tabs' radii.
fn jigsaw_outline(rng: &mut Rng) -> (Vec<[f64; 2]>, Vec<f64>) {
    let tabs = 1 + (rng.uniform() * 3.0) as usize;
    let size = 1.0 / tabs as f64;
    let mut pts = vec![[0.0, 0.0]];
    let mut radii = Vec::new();
    for k in 0..tabs {
        let dir = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
        let c = (k as f64 + 0.5 + between(rng, -0.05, 0.05)) * size;
        let r = between(rng, 0.09, 0.12) * size;
        // the neck's half-width and height
        let n = between(rng, 0.45, 0.7) * r;
        let neck = between(rng, 0.3, 0.6) * r;
        let delta = (n / r).asin();
        let yc = neck + r * delta.cos();
        pts.push([c - n, 0.0]);
        pts.push([c - n, dir * neck]);
        let (a0, a1) = (-std::f64::consts::FRAC_PI_2 - delta, -2.5 * std::f64::consts::PI + delta);
        for j in 1..256 {
            let a = a0 + (a1 - a0) * j as f64 / 256.0;
            pts.push([c + r * a.cos(), dir * (yc + r * a.sin())]);
        }
        pts.push([c + n, dir * neck]);
        pts.push([c + n, 0.0]);
        radii.push(r);
    }
    pts.push([1.0, 0.0]);
    (pts, radii)
}

/// `m + 1` points evenly spaced in arc length along the polyline `pts`.
fn resample(pts: &[[f64; 2]], m: usize) -> Vec<[f64; 2]> {
    let mut s = vec![0.0];
    for w in pts.windows(2) {
        s.push(s[s.len() - 1] + (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]));
    }
    let total = s[s.len() - 1];
    let mut i = 0;
    (0..=m)
        .map(|k| {
            let t = total * k as f64 / m as f64;
            while i + 2 < s.len() && s[i + 1] < t {
                i += 1;
            }
            let f = if s[i + 1] > s[i] { ((t - s[i]) / (s[i + 1] - s[i])).clamp(0.0, 1.0) } else { 0.0 };
            [pts[i][0] + f * (pts[i + 1][0] - pts[i][0]), pts[i][1] + f * (pts[i + 1][1] - pts[i][1])]
        })
        .collect()
}

/// One jigsaw side ([`jigsaw_outline`]) as a cloud of 1500 to 3000 points evenly spaced in
/// arc length, its corners rounded at `ρ = r / k`, `k ∈ [8, 30]` (`r` the smallest tab's
/// radius): two passes of a moving average over the arc length `±ρ` (a straight piece is
/// kept exactly, the ends stay), which turns a corner into a curve of extent about `2ρ`.
fn jigsaw_side(rng: &mut Rng) -> Vec<[f64; 2]> {
    let (sharp, radii) = jigsaw_outline(rng);
    let rho = radii.iter().fold(f64::INFINITY, |a, &b| a.min(b)) / between(rng, 8.0, 30.0);
    let m = 1500 + (rng.uniform() * 1500.0) as usize;
    // the averaging runs on a grid eight times finer than the cloud
    let fine = resample(&sharp, 8 * m);
    let mut s = vec![0.0];
    for w in fine.windows(2) {
        s.push(s[s.len() - 1] + (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]));
    }
    let half = ((rho / (s[s.len() - 1] / (8 * m) as f64)).round() as usize).max(1);
    let mut out = fine;
    for _ in 0..2 {
        let n = out.len();
        let mut prefix = vec![[0.0, 0.0]; n + 1];
        for j in 0..n {
            prefix[j + 1] = [prefix[j][0] + out[j][0], prefix[j][1] + out[j][1]];
        }
        out = (0..n)
            .map(|j| {
                let w = half.min(j).min(n - 1 - j);
                let (a, b) = (j - w, j + w + 1);
                let c = (b - a) as f64;
                [(prefix[b][0] - prefix[a][0]) / c, (prefix[b][1] - prefix[a][1]) / c]
            })
            .collect();
    }
    out.into_iter().step_by(8).collect()
}

/// The unit square with a jigsaw side ([`jigsaw_side`]) on every side.
fn jigsaw(rng: &mut Rng) -> [SideCurve; 4] {
    let south = jigsaw_side(rng);
    let east = jigsaw_side(rng).into_iter().map(|[s, h]| [1.0 - h, s]).collect();
    let north = jigsaw_side(rng).into_iter().map(|[s, h]| [s, 1.0 - h]).collect();
    let west = jigsaw_side(rng).into_iter().map(|[s, h]| [h, s]).collect();
    [SideCurve::Points(south), SideCurve::Points(east), SideCurve::Points(north), SideCurve::Points(west)]
}

/// The smallest gap of `pinched`, relative to the channel's length.
pub(crate) const PINCH_GAP: f64 = 3e-4;

/// A channel `[0, 1] × [0, w]`, `w ∈ [0.1, 0.2]`, whose walls close in by the Gaussian
/// bumps `(w - g) / 2 · exp(-((x - x0) / σ)²)` to the gap `g` = [`PINCH_GAP`] at `x0 ∈
/// [0.35, 0.65]`, `σ ∈ [0.03, 0.1]`; walls of 2001 points evenly spaced in `x`.
fn pinched(rng: &mut Rng) -> [SideCurve; 4] {
    let w = between(rng, 0.1, 0.2);
    let x0 = between(rng, 0.35, 0.65);
    let sigma = between(rng, 0.03, 0.1);
    let bump = move |x: f64| 0.5 * (w - PINCH_GAP) * (-((x - x0) / sigma).powi(2)).exp();
    let n = 2000;
    let xs: Vec<f64> = (0..=n).map(|k| k as f64 / n as f64).collect();
    let south: Vec<Point> = xs.iter().map(|&x| [x, bump(x)]).collect();
    let north: Vec<Point> = xs.iter().map(|&x| [x, w - bump(x)]).collect();
    let (sw, se, nw, ne) = (south[0], south[n], north[0], north[n]);
    [SideCurve::Points(south), segment(se, ne), SideCurve::Points(north), segment(sw, nw)]
}

/// The image of the unit square's sides under `x = u + e1 sin(2π v + φ1)`, `y = v + e2
/// sin(2π u + φ2)` (bijective: `|e1 e2| 4π² < 1`), `n` points per side, each moved by
/// Gaussian noise of standard deviation `noise` along the normal, except the corners.
fn deformed_square(rng: &mut Rng, n: usize, noise: f64) -> [SideCurve; 4] {
    let tau = 2.0 * std::f64::consts::PI;
    let (e1, e2) = (between(rng, -0.08, 0.08), between(rng, -0.08, 0.08));
    let (f1, f2) = (between(rng, 0.0, tau), between(rng, 0.0, tau));
    let d = move |u: f64, v: f64| [u + e1 * (tau * v + f1).sin(), v + e2 * (tau * u + f2).sin()];
    // noise along the normal only: tangential noise would reorder the dense points
    let mut side = |f: &dyn Fn(f64) -> Point| {
        let pts = (0..n)
            .map(|k| {
                let t = k as f64 / (n - 1) as f64;
                let p = f(t);
                if k == 0 || k + 1 == n {
                    return p;
                }
                let (a, b) = (f(t - 1e-6), f(t + 1e-6));
                let (tx, ty) = (b[0] - a[0], b[1] - a[1]);
                let e = noise * gaussian(rng) / tx.hypot(ty);
                [p[0] - e * ty, p[1] + e * tx]
            })
            .collect();
        SideCurve::Points(pts)
    };
    [side(&|t| d(t, 0.0)), side(&|t| d(1.0, t)), side(&|t| d(t, 1.0)), side(&|t| d(0.0, t))]
}

/// A standard normal number (Box–Muller).
fn gaussian(rng: &mut Rng) -> f64 {
    let u = rng.uniform().max(1e-300);
    let v = rng.uniform();
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::validate::validate;

    #[test]
    fn every_generated_domain_is_a_valid_counter_clockwise_boundary() {
        for (family, b) in corpus(12, 0).into_iter().chain(corpus_of(&Family::EXTRA, 24, 0)) {
            let r = validate(&b).unwrap_or_else(|e| panic!("{}: {e}", b.name));
            assert!(r.signed_area > 0.0, "{family:?}");
        }
    }

    #[test]
    fn generation_is_deterministic_and_seeds_differ() {
        for f in Family::ALL.into_iter().chain(Family::EXTRA) {
            let (a, b, c) = (f.generate(7), f.generate(7), f.generate(8));
            let pts = |b: &Boundary| format!("{:?}", b.sides[0]);
            assert_eq!(pts(&a), pts(&b), "{f:?}");
            assert_ne!(pts(&a), pts(&c), "{f:?}");
            assert_eq!(Family::parse(f.name()), Some(f));
        }
    }

    #[test]
    fn the_families_have_their_defining_features() {
        for seed in 0..12 {
            let b = Family::SharpCorner.generate(seed);
            let r = validate(&b).unwrap();
            assert!((14.0..=36.0).contains(&r.corner_angles[0]), "sharp corner {}", r.corner_angles[0]);
            let r = validate(&Family::Strip.generate(seed)).unwrap();
            let ratio = r.side_lengths[0] / r.side_lengths[1];
            assert!((19.0..=250.0).contains(&ratio), "strip aspect ratio {ratio}");
            let SideCurve::Points(p) = &Family::SparseCloud.generate(seed).sides[0] else { panic!() };
            assert!((8..=15).contains(&p.len()));
            let SideCurve::Points(p) = &Family::NoisyCloud.generate(seed).sides[0] else { panic!() };
            assert!((1000..=3000).contains(&p.len()));
        }
        // cad-kinks: every vertex of the south side a C0 knot, the tangent turning 30 to
        // 130 degrees at V-tips, half that at their bases, 90 at steps
        for seed in 0..24 {
            let b = Family::CadKinks.generate(seed);
            let SideCurve::Spline(c) = &b.sides[0] else { panic!() };
            assert_eq!(c.knots.degree(), 2);
            let inner = &c.knots.breaks_with_multiplicity()[1..];
            let inner = &inner[..inner.len() - 1];
            assert!(inner.len() >= 2 && inner.iter().all(|&(_, m)| m == 2));
            let v: Vec<Point> = c.control_points.iter().step_by(2).copied().collect();
            for w in v.windows(3) {
                let (d0, d1) = ([w[1][0] - w[0][0], w[1][1] - w[0][1]], [w[2][0] - w[1][0], w[2][1] - w[1][1]]);
                let turn = (d0[0] * d1[1] - d0[1] * d1[0]).atan2(d0[0] * d1[0] + d0[1] * d1[1]).abs().to_degrees();
                assert!((14.9..=130.1).contains(&turn) || turn < 1e-9, "turn {turn}");
            }
        }
        // jigsaw: 1501 to 3001 points per side, the necks rounded: where a sharp outline
        // turns by 90 degrees at one point, no point of the cloud turns by more than 45
        let turn = |a: Point, b: Point, c: Point| {
            let (d0, d1) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
            (d0[0] * d1[1] - d0[1] * d1[0]).atan2(d0[0] * d1[0] + d0[1] * d1[1]).abs().to_degrees()
        };
        for seed in 0..12 {
            for side in &Family::Jigsaw.generate(seed).sides {
                let SideCurve::Points(p) = side else { panic!() };
                assert!((1501..=3001).contains(&p.len()), "{}", p.len());
                let sharpest = p.windows(3).map(|w| turn(w[0], w[1], w[2])).fold(0.0f64, f64::max);
                assert!((1.0..=45.0).contains(&sharpest), "jigsaw-{seed}: a point turns by {sharpest} degrees");
            }
        }
        // pinched: the narrowest gap between the walls is PINCH_GAP (to the sampling)
        for seed in 0..12 {
            let b = Family::Pinched.generate(seed);
            let (SideCurve::Points(s), SideCurve::Points(n)) = (&b.sides[0], &b.sides[2]) else { panic!() };
            let gap = s.iter().zip(n).map(|(a, b)| b[1] - a[1]).fold(f64::INFINITY, f64::min);
            assert!((PINCH_GAP..=1.1 * PINCH_GAP).contains(&gap), "gap {gap}");
        }
        // the clearance gaps: the narrowest vertical extent is between 3e-3 and 1e-2
        for seed in 0..12 {
            let b = Family::Clearance.generate(seed);
            let (SideCurve::Points(s), SideCurve::Points(n)) = (&b.sides[0], &b.sides[2]) else { panic!() };
            let gap = s.iter().zip(n).map(|(a, b)| b[1] - a[1]).fold(f64::INFINITY, f64::min);
            assert!((2.9e-3..=1.01e-2).contains(&gap), "gap {gap}");
        }
    }
}
