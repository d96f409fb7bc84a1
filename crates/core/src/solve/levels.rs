//! The levels a solve walks through (paper §5.4, §6.3): the fitted hierarchy balanced
//! so that elements are not much longer in one direction than in the other, extended by
//! uniform refinements, and thinned to levels that grow by a factor (the paper advises
//! 4), always ending with the finest.

use crate::boundary::hierarchy::Level;
use crate::boundary::kinks::Rounding;
use crate::error::{Error, Result};
use crate::spline::curve::Curve;
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;

/// At most this many halvings of an end span by [`graded_at_roundings`].
pub(crate) const MAX_GRADING: usize = 8;

/// `level` graded towards the sides with rounded point-cloud corners
/// ([`Rounding`]): at such a side the knot vector across it (`xi` at west and east,
/// `eta` at south and north) has its end span halved until it is at most `R / (2 d)`
/// wide (`R` the smallest rounding radius on the side, `d` the boundary's diameter, both
/// in the hierarchy's coordinates), at most [`MAX_GRADING`] times; the sides refined
/// exactly (the boundary is unchanged). A rounded reflex corner (a jigsaw tab's
/// shoulder) bends the map within about `R` of the side, and a bulb behind a neck is
/// squeezed into a thin layer along it: one span across was measured to fold at the
/// side, five halvings of it certify (BENCHMARKS.md "Puzzle necks and hair-thin gaps").
pub(crate) fn graded_at_roundings(level: &Level, roundings: &[Rounding], diameter: f64) -> Result<Level> {
    let mut knots = level.knots.clone();
    for side in Side::ALL {
        let Some(radius) = roundings.iter().filter(|r| r.side == side).map(|r| r.radius).min_by(f64::total_cmp) else {
            continue;
        };
        let target = radius / (2.0 * diameter);
        let d = 1 - side.direction();
        let at_start = matches!(side, Side::South | Side::West);
        for _ in 0..MAX_GRADING {
            let elems = knots[d].elements();
            let Some(&(_, a, b)) = (if at_start { elems.first() } else { elems.last() }) else { break };
            if b - a <= target {
                break;
            }
            knots[d] = knots[d].with_inserted(&[0.5 * (a + b)]);
        }
    }
    if knots == level.knots {
        return Ok(level.clone());
    }
    let sides = Side::ALL.map(|s| level.sides[s as usize].refined(&knots[s.direction()]));
    let sides: [Curve; 4] = sides.into_iter().collect::<Result<Vec<_>>>()?.try_into().expect("four sides");
    Ok(Level { knots, sides })
}

/// Choose the levels to solve: from the coarsest, each next one at least `growth` times
/// larger, always ending with the finest. A level of nearly the finest's size (less than
/// [`SAME_SIZE`] times smaller) is replaced by the finest: solving twice at one size
/// costs a full solve and gains nothing. The coarsest level always stays, unless the
/// finest has at most `direct_max` functions: then it is solved alone (see
/// [`DIRECT_REFINED_MAX_FUNCTIONS`]; 0: never).
pub(crate) fn select_levels(sizes: &[usize], growth: f64, max_levels: Option<usize>, direct_max: usize) -> Vec<usize> {
    let last = sizes.len() - 1;
    if sizes[last] <= direct_max {
        return vec![last];
    }
    let mut out = vec![0];
    for (k, &s) in sizes.iter().enumerate().skip(1) {
        let previous = *out.last().expect("non-empty");
        if s as f64 >= growth * sizes[previous] as f64 {
            out.push(k);
        } else if k == last {
            if out.len() > 1 && (s as f64) < SAME_SIZE * sizes[previous] as f64 {
                out.pop();
            }
            out.push(k);
        }
    }
    if let Some(m) = max_levels {
        let m = m.max(1);
        while out.len() > m {
            out.remove(out.len() - 2);
        }
    }
    out
}

/// An input basis refined uniformly to at most this many functions is solved on its
/// finest level only, from the Coons patch (an unrefined input basis of up to
/// [`DIRECT_SOLVE_MAX_FUNCTIONS`](crate::boundary::input_basis::DIRECT_SOLVE_MAX_FUNCTIONS)
/// functions is anyway): at most 64 unknowns, factorized densely, a level costs mostly
/// its set-up (discretization, start, elasticity prolongation), and the coarse level
/// saves no fine Newton step. Measured on the shared G+Smo geometries refined once and
/// twice (16 to 60 functions: disk, cooks_membrane, flapping_beam, lake, plate_with_hole;
/// `bash scripts/bench-peers.sh`, BENCHMARKS.md): the same verdicts in 10-40 % less time
/// (cooks_membrane refined once 168 -> 97 µs); at 81 (lake) and 252 functions (duck) the
/// coarse level saves one or two fine Newton steps and the hierarchy is faster.
pub(crate) const DIRECT_REFINED_MAX_FUNCTIONS: usize = 64;

/// Size ratio below which two levels count as one size in [`select_levels`].
pub(crate) const SAME_SIZE: f64 = 1.5;

fn polyline_length(c: &Curve) -> f64 {
    let n = 16 * c.knots.num_elements().max(4);
    c.sample(n).windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum()
}

/// Two sides count as a seam (see [`prepare_levels`]) when the mean distance between
/// the other two sides exceeds their mean length by this factor.
pub(crate) const SEAM_FACTOR: f64 = 4.0;

/// Mean distance `|b(t) - a(t)|` between two opposite sides at equal parameters: the
/// mean length of the straight lines joining them, which is the extent of the domain
/// across them when the sides joining them are much shorter (a ring cut along a seam).
fn mean_gap(a: &Curve, b: &Curve) -> f64 {
    let n = 16 * a.knots.num_elements().max(b.knots.num_elements()).max(4);
    (0..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let (p, q) = (a.eval(t), b.eval(t));
            (p[0] - q[0]).hypot(p[1] - q[1])
        })
        .sum::<f64>()
        / (n + 1) as f64
}

/// Prepare the hierarchy for solving (paper §5.4 builds each level from the side fits
/// alone, so a straight side keeps a single element however fine its opposite is):
/// 1. *balance* every level, halving a direction until its elements are on average no
///    more than `aspect` times longer (physically) than those of the other direction
///    (the extent of a direction is the mean length of its two sides, or the mean
///    distance between the two other sides at equal parameters when that is more than
///    [`SEAM_FACTOR`] times larger: a ring cut open along a seam),
///    and until it has `min_elements` elements; each level then takes the union with
///    the coarser one so the hierarchy stays nested;
/// 2. append `refine` uniformly halved copies of the finest level.
///
/// Sides are refined exactly (knot insertion), so the fitted contours are unchanged.
pub(crate) fn prepare_levels(
    mut levels: Vec<Level>,
    min_elements: usize,
    refine: usize,
    aspect: f64,
) -> Result<Vec<Level>> {
    let last = levels.last().ok_or_else(|| Error::Invalid("empty hierarchy".into()))?;
    // mean physical length of the xi sides (south, north) and of the eta sides (west, east)
    let len_xi =
        0.5 * (polyline_length(&last.sides[Side::South as usize]) + polyline_length(&last.sides[Side::North as usize]));
    let len_eta =
        0.5 * (polyline_length(&last.sides[Side::West as usize]) + polyline_length(&last.sides[Side::East as usize]));
    // a seam (short sides joining long ones far apart) understates the extent across:
    // there the mean distance between the other two sides is used instead
    let across = |len: f64, gap: f64| if gap > SEAM_FACTOR * len { gap } else { len };
    let len_xi = across(len_xi, mean_gap(&last.sides[Side::West as usize], &last.sides[Side::East as usize]));
    let len_eta = across(len_eta, mean_gap(&last.sides[Side::South as usize], &last.sides[Side::North as usize]));
    let mut previous: Option<[KnotVector; 2]> = None;
    for level in levels.iter_mut() {
        let mut knots = level.knots.clone();
        // balance the mean physical element sizes of the two directions ...
        loop {
            let h = [len_xi / knots[0].num_elements() as f64, len_eta / knots[1].num_elements() as f64];
            let d = if h[1] > aspect * h[0] {
                1
            } else if h[0] > aspect * h[1] {
                0
            } else {
                break;
            };
            knots[d] = knots[d].halved();
        }
        // ... then give each direction its minimum number of elements
        for kv in knots.iter_mut() {
            while kv.num_elements() < min_elements {
                *kv = kv.halved();
            }
        }
        let size = knots[0].num_basis() * knots[1].num_basis();
        if size > MAX_BASIS {
            return Err(Error::TooLarge {
                context: "solver hierarchy".into(),
                what: "tensor basis size".into(),
                found: size,
                limit: MAX_BASIS,
            });
        }
        // contain the coarser level: keeps the hierarchy nested
        if let Some(prev) = &previous {
            for d in 0..2 {
                knots[d] = knots[d].union(&prev[d])?;
            }
        }
        if knots != level.knots {
            for s in Side::ALL {
                level.sides[s as usize] = level.sides[s as usize].refined(&knots[s.direction()])?;
            }
            level.knots = knots.clone();
        }
        previous = Some(knots);
    }
    for _ in 0..refine {
        let last = levels.last().expect("non-empty");
        let knots = [last.knots[0].halved(), last.knots[1].halved()];
        let mut sides = last.sides.clone();
        for s in Side::ALL {
            sides[s as usize] = sides[s as usize].refined(&knots[s.direction()])?;
        }
        levels.push(Level { knots, sides });
    }
    // levels made identical by balancing: keep the last of each run, whose sides are
    // the most accurate fits on that basis
    let mut out: Vec<Level> = Vec::with_capacity(levels.len());
    for l in levels {
        match out.last_mut() {
            Some(prev) if prev.knots == l.knots => *prev = l,
            _ => out.push(l),
        }
    }
    Ok(out)
}

/// Largest tensor basis the solver accepts (about 8 million unknowns).
pub(crate) const MAX_BASIS: usize = 1 << 22;

#[cfg(test)]
mod tests {
    use super::*;

    /// [`graded_at_roundings`] on the unit square (8 elements per direction, degree 3)
    /// with a rounding of radius `R = 0.01` on the west side, the diameter `√2`: the
    /// `xi` end span at `xi = 0` halved until at most `R / (2 d)` wide (0.125 → 0.001953125,
    /// six halvings), nothing else refined, and the sides the same curves.
    #[test]
    fn grading_halves_the_span_across_a_rounded_side() {
        let kv = KnotVector::open_uniform(3, 8);
        let line = |a: [f64; 2], b: [f64; 2]| {
            let cps = kv.greville().into_iter().map(|t| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            Curve::new(kv.clone(), cps.collect(), None).unwrap()
        };
        let sides = [
            line([0.0, 0.0], [1.0, 0.0]),
            line([1.0, 0.0], [1.0, 1.0]),
            line([0.0, 1.0], [1.0, 1.0]),
            line([0.0, 0.0], [0.0, 1.0]),
        ];
        let level = Level { knots: [kv.clone(), kv.clone()], sides };
        let rounding = Rounding {
            side: Side::West,
            parameter: 0.5,
            point: [0.0, 0.5],
            turning_degrees: 90.0,
            radius: 0.01,
            sagitta: 0.004,
            points: 5,
        };
        let d = 2f64.sqrt();
        let graded = graded_at_roundings(&level, &[rounding], d).unwrap();
        let xi = graded.knots[0].elements();
        assert_eq!(xi.len(), 8 + 6);
        assert_eq!((xi[0].1, xi[0].2), (0.0, 0.001953125));
        assert!(xi[0].2 <= 0.01 / (2.0 * d) && 2.0 * xi[0].2 > 0.01 / (2.0 * d));
        assert_eq!(xi.last().map(|e| e.2 - e.1), Some(0.125));
        assert_eq!(graded.knots[1], kv);
        for (a, b) in level.sides.iter().zip(&graded.sides) {
            for k in 0..=50 {
                let t = k as f64 / 50.0;
                let (p, q) = (a.eval(t), b.eval(t));
                assert!((p[0] - q[0]).abs() < 1e-14 && (p[1] - q[1]).abs() < 1e-14);
            }
        }
        // no rounding: the level as it is
        assert_eq!(graded_at_roundings(&level, &[], d).unwrap().knots, level.knots);
    }

    #[test]
    fn level_selection_quadruples() {
        // 310 replaces 300: both would be solved at nearly one size
        assert_eq!(select_levels(&[16, 20, 64, 70, 300, 310], 4.0, None, 0), vec![0, 2, 5]);
        assert_eq!(select_levels(&[16, 20, 64, 70, 300], 4.0, None, 0), vec![0, 2, 4]);
        assert_eq!(select_levels(&[16, 20], 4.0, None, 0), vec![0, 1]);
        // a finest level well above the previous one (here 1.67 times) keeps it
        assert_eq!(select_levels(&[162, 1122, 1870], 4.0, None, 0), vec![0, 1, 2]);
        assert_eq!(select_levels(&[16], 4.0, None, 0), vec![0]);
        assert_eq!(select_levels(&[16, 64, 256, 1024], 4.0, Some(2), 0), vec![0, 3]);
        // a finest level within `direct_max` alone; above it the hierarchy
        assert_eq!(select_levels(&[9, 16], 4.0, None, DIRECT_REFINED_MAX_FUNCTIONS), vec![1]);
        assert_eq!(select_levels(&[16, 36, 100], 4.0, None, DIRECT_REFINED_MAX_FUNCTIONS), vec![0, 2]);
    }
}
