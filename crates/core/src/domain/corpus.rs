//! A seeded corpus of general domains for the automatic layout (issue 31): `N`-gons with
//! curved sides (`N = 3 ... 12`), L-, T-, U-, E- and plus-shaped brackets with sharp
//! or filleted reflex corners, plates with holes; and plane graphs ([`GraphFamily`]:
//! wiggly squares and motor-like sections, `families`). The same seed gives the same domains on every machine
//! (SplitMix64, as the hard corpus of [`crate::boundary::families`]).

use super::{Domain, Loop, PlaneGraph};
use crate::boundary::families::{between, Rng};
use crate::boundary::SideCurve;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;

/// A family of general domains.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum DomainFamily {
    /// A polygon of 3 to 12 jittered corners whose sides bulge in or out (quadratic).
    Ngon,
    /// An L: one reflex corner.
    L,
    /// A T: two reflex corners.
    T,
    /// A U: two reflex corners.
    U,
    /// An E: four reflex corners.
    E,
    /// A plus: four reflex corners.
    Plus,
    /// A rectangular plate with 1 to 5 holes (`families::plate`).
    Plate,
}

impl DomainFamily {
    /// Every family.
    pub const ALL: [DomainFamily; 7] = [
        DomainFamily::Ngon,
        DomainFamily::L,
        DomainFamily::T,
        DomainFamily::U,
        DomainFamily::E,
        DomainFamily::Plus,
        DomainFamily::Plate,
    ];

    /// Its name: `ngon`, `l`, `t`, `u`, `e`, `plus`, `plate`.
    pub fn name(self) -> &'static str {
        match self {
            DomainFamily::Ngon => "ngon",
            DomainFamily::L => "l",
            DomainFamily::T => "t",
            DomainFamily::U => "u",
            DomainFamily::E => "e",
            DomainFamily::Plus => "plus",
            DomainFamily::Plate => "plate",
        }
    }

    /// The family called `name`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The domain of this family for `seed`, named `FAMILY-SEED`.
    pub fn generate(self, seed: u64) -> Domain {
        let mut rng = Rng::new(seed.wrapping_mul(0x2545_F491).wrapping_add(self as u64 + 101));
        let sides = match self {
            DomainFamily::Plate => return super::families::plate(seed),
            DomainFamily::Ngon => ngon(&mut rng, 3 + (seed % 10) as usize),
            letter => {
                let pts = letter_polygon(letter, &mut rng);
                let fillet = rng.uniform() < 0.5;
                polygon_sides(&pts, fillet.then(|| between(&mut rng, 0.1, 0.3)))
            }
        };
        Domain { name: format!("{}-{seed}", self.name()), outer: Loop::new(sides), holes: Vec::new() }
    }
}

/// A family of plane graphs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum GraphFamily {
    /// The unit square cut by wiggly curves into 4 to 60 faces (`families::wiggly`).
    Wiggly,
    /// A motor-like section with 6 to 48 slots (`families::motor`).
    Motor,
}

impl GraphFamily {
    /// Every family.
    pub const ALL: [GraphFamily; 2] = [GraphFamily::Wiggly, GraphFamily::Motor];

    /// Its name: `wiggly`, `motor`.
    pub fn name(self) -> &'static str {
        match self {
            GraphFamily::Wiggly => "wiggly",
            GraphFamily::Motor => "motor",
        }
    }

    /// The family called `name`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The graph of this family for `seed`, named `FAMILY-SEED`.
    pub fn generate(self, seed: u64) -> PlaneGraph {
        match self {
            GraphFamily::Wiggly => super::families::wiggly(seed),
            GraphFamily::Motor => super::families::motor(seed),
        }
    }
}

/// `per_family` domains of every family in `families` (all when empty), seeds `seed,
/// seed + 1, ...`.
pub fn domain_corpus(families: &[DomainFamily], per_family: usize, seed: u64) -> Vec<(DomainFamily, Domain)> {
    DomainFamily::ALL
        .into_iter()
        .filter(|f| families.is_empty() || families.contains(f))
        .flat_map(|f| (0..per_family as u64).map(move |k| (f, f.generate(seed + k))))
        .collect()
}

fn line(a: Point, b: Point) -> SideCurve {
    SideCurve::Spline(Curve::polynomial(KnotVector::open_uniform(1, 1), vec![a, b]))
}

/// Corners on a circle at jittered angles and radii; each side a quadratic whose middle
/// control point is off the chord's midpoint by up to a fifth of its length (out) or an
/// eighth (in).
fn ngon(rng: &mut Rng, n: usize) -> Vec<SideCurve> {
    let step = 2.0 * std::f64::consts::PI / n as f64;
    let v: Vec<Point> = (0..n)
        .map(|k| {
            let a = step * (k as f64 + between(rng, -0.2, 0.2));
            let r = between(rng, 0.85, 1.15);
            [r * a.cos(), r * a.sin()]
        })
        .collect();
    (0..n)
        .map(|k| {
            let (a, b) = (v[k], v[(k + 1) % n]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let bulge = between(rng, -0.125, 0.2);
            // the outward normal of a counter-clockwise side is (dy, -dx)
            let m = [0.5 * (a[0] + b[0]) + bulge * dy, 0.5 * (a[1] + b[1]) - bulge * dx];
            SideCurve::Spline(Curve::polynomial(KnotVector::open_uniform(2, 1), vec![a, m, b]))
        })
        .collect()
}

/// The counter-clockwise corners of a letter with random arm lengths and widths.
fn letter_polygon(f: DomainFamily, rng: &mut Rng) -> Vec<Point> {
    let mut r = |lo: f64, hi: f64| between(rng, lo, hi);
    match f {
        DomainFamily::L => {
            let (w, h, a, b) = (r(1.5, 3.0), r(1.5, 3.0), r(0.4, 1.0), r(0.4, 1.0));
            vec![[0.0, 0.0], [w, 0.0], [w, b], [a, b], [a, h], [0.0, h]]
        }
        DomainFamily::T => {
            let (s, h, bw, t) = (r(0.4, 1.0), r(1.0, 2.5), r(2.0, 3.5), r(0.4, 1.0));
            vec![
                [-s / 2.0, 0.0],
                [s / 2.0, 0.0],
                [s / 2.0, h],
                [bw / 2.0, h],
                [bw / 2.0, h + t],
                [-bw / 2.0, h + t],
                [-bw / 2.0, h],
                [-s / 2.0, h],
            ]
        }
        DomainFamily::U => {
            let (w, h, a, b) = (r(2.0, 3.0), r(1.5, 3.0), r(0.3, 0.8), r(0.3, 0.8));
            vec![[0.0, 0.0], [w, 0.0], [w, h], [w - a, h], [w - a, b], [a, b], [a, h], [0.0, h]]
        }
        DomainFamily::E => {
            let (w, a, t, g) = (r(1.5, 2.5), r(0.3, 0.6), r(0.3, 0.5), r(0.3, 0.6));
            let w2 = r(0.7, 1.0) * w;
            vec![
                [0.0, 0.0],
                [w, 0.0],
                [w, t],
                [a, t],
                [a, t + g],
                [w2, t + g],
                [w2, 2.0 * t + g],
                [a, 2.0 * t + g],
                [a, 2.0 * t + 2.0 * g],
                [w, 2.0 * t + 2.0 * g],
                [w, 3.0 * t + 2.0 * g],
                [0.0, 3.0 * t + 2.0 * g],
            ]
        }
        DomainFamily::Plus | DomainFamily::Ngon | DomainFamily::Plate => {
            let (a, l1, l2, l3, l4) = (r(0.3, 0.6), r(1.0, 2.0), r(1.0, 2.0), r(1.0, 2.0), r(1.0, 2.0));
            vec![
                [-a, -l1],
                [a, -l1],
                [a, -a],
                [l2, -a],
                [l2, a],
                [a, a],
                [a, l3],
                [-a, l3],
                [-a, a],
                [-l4, a],
                [-l4, -a],
                [-a, -a],
            ]
        }
    }
}

/// The sides of a counter-clockwise polygon; with `fillet = Some(f)` every reflex corner
/// is rounded by a circular arc (a rational quadratic) of radius `f` times its shorter
/// side, whose ends are corners of the loop (where the tangent does not turn).
fn polygon_sides(pts: &[Point], fillet: Option<f64>) -> Vec<SideCurve> {
    let n = pts.len();
    let cross = |a: Point, b: Point, c: Point| (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]);
    let len = |a: Point, b: Point| (b[0] - a[0]).hypot(b[1] - a[1]);
    // per corner: the point where the side before ends and the one after begins, and the arc
    let mut ends: Vec<(Point, Point, Option<SideCurve>)> = Vec::with_capacity(n);
    for k in 0..n {
        let (p, v, q) = (pts[(k + n - 1) % n], pts[k], pts[(k + 1) % n]);
        match fillet {
            Some(f) if cross(p, v, q) < 0.0 => {
                let r = f * len(p, v).min(len(v, q));
                let (li, lo) = (len(p, v), len(v, q));
                let a = [v[0] - r * (v[0] - p[0]) / li, v[1] - r * (v[1] - p[1]) / li];
                let b = [v[0] + r * (q[0] - v[0]) / lo, v[1] + r * (q[1] - v[1]) / lo];
                // the arc between two perpendicular sides: weight cos(45°) at the corner
                let w = std::f64::consts::FRAC_1_SQRT_2;
                let arc = Curve::new(KnotVector::open_uniform(2, 1), vec![a, v, b], Some(vec![1.0, w, 1.0]))
                    .expect("a quarter circle");
                ends.push((a, b, Some(SideCurve::Spline(arc))));
            }
            _ => ends.push((v, v, None)),
        }
    }
    let mut sides = Vec::with_capacity(2 * n);
    for k in 0..n {
        if let Some(arc) = ends[k].2.clone() {
            sides.push(arc);
        }
        sides.push(line(ends[k].1, ends[(k + 1) % n].0));
    }
    sides
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::validate_domain;

    #[test]
    fn every_generated_domain_is_valid_and_seeded() {
        for (f, mut d) in domain_corpus(&[], 12, 1) {
            let r = validate_domain(&mut d).unwrap_or_else(|e| panic!("{}: {e}", d.name));
            assert!(r.reoriented.is_empty(), "{} ({f:?}) runs clockwise", d.name);
        }
        let a = DomainFamily::E.generate(7);
        let b = DomainFamily::E.generate(7);
        assert_eq!(format!("{:?}", a.outer.sides), format!("{:?}", b.outer.sides));
        assert_eq!(DomainFamily::Ngon.generate(9).outer.corners(), 12);
    }
}
