//! Periodic seams: a parameter direction whose two ends are one curve of the domain.
//!
//! A ring map (`"periodic": [false, true]`) has a seam by construction: its periodic
//! knot vector makes `x(xi, 0) = x(xi, 1)`. A ring **cut** into a four-sided map (G+Smo's
//! `male_casing_ring`) has two opposite sides that coincide as curves, e.g. west and
//! east with `x(0, t) = x(1, t)` for every `t`. Both are meshed alike: one line of nodes
//! shared by the cells on both sides, not a boundary; the two remaining sides are the
//! walls, named `inner` and `outer` by the area they enclose ([`wall_names`]).
//!
//! Two sides coincide when
//! `max_k |x_start(t_k) - x_end(t_k)| <= SEAM_TOLERANCE * diameter` at
//! `t_k = k / SEAM_SAMPLES` (the diameter of the boundary's bounding box), and the mesh
//! confirms it at its own seam nodes ([`Seams::confirm`]). Sides that coincide in
//! opposite directions (`x_start(t) = x_end(1 - t)`) would glue the square into a
//! Möbius strip, which no map with `det J > 0` onto a planar domain is: refused.

use glam::DVec2;
use winslow::{Side, Surface};

use crate::error::{MeshError, Result};

/// Largest distance between the two sides of a cut seam, relative to the diameter of
/// the boundary (G+Smo's `male_casing_ring` has `2.2e-7`).
pub const SEAM_TOLERANCE: f64 = 1e-6;

/// Points per side at which coinciding sides are compared (`SEAM_SAMPLES + 1`).
pub const SEAM_SAMPLES: usize = 1024;

/// The seams of a map.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Seams {
    /// Directions whose two ends are one curve (`[false, true]`: south = north), from a
    /// periodic knot vector or from coinciding sides.
    pub dirs: [bool; 2],
    /// Directions whose knot vector is periodic (a ring map); the others of `dirs` are
    /// cut seams.
    pub periodic_knots: [bool; 2],
    /// Largest distance between the two sides of each cut seam at the samples (0 for a
    /// periodic direction and for no seam).
    pub gap: [f64; 2],
    /// Diameter of the boundary's bounding box (the unit of the tolerance).
    pub diameter: f64,
}

/// The sides at the start and end of direction `dir` (`west`/`east` for `xi`).
pub fn ends(dir: usize) -> [Side; 2] {
    if dir == 0 {
        [Side::West, Side::East]
    } else {
        [Side::South, Side::North]
    }
}

/// The point of side `side` at the parameter `t` along it, in the direction of the other
/// parameter (not counter-clockwise): `x(0, t)` for west, `x(t, 1)` for north.
fn on_side(map: &Surface, side: Side, t: f64) -> DVec2 {
    let p = match side {
        Side::South => map.eval(t, 0.0),
        Side::North => map.eval(t, 1.0),
        Side::West => map.eval(0.0, t),
        Side::East => map.eval(1.0, t),
    };
    DVec2::from(p)
}

fn samples(map: &Surface, side: Side) -> Vec<DVec2> {
    (0..=SEAM_SAMPLES).map(|k| on_side(map, side, k as f64 / SEAM_SAMPLES as f64)).collect()
}

/// Detect the seams of `map`: periodic directions, and directions whose two end sides
/// coincide point by point within [`SEAM_TOLERANCE`] of the diameter. Refuses sides that
/// coincide reversed (a Möbius strip) and a map periodic or cut in both directions (a
/// torus has no planar mesh).
pub fn seams(map: &Surface) -> Result<Seams> {
    let periodic_knots = crate::periodic_directions(map);
    let sides = Side::ALL.map(|s| samples(map, s));
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for p in sides.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let diameter = lo.distance(hi);
    let tol = SEAM_TOLERANCE * diameter;
    let mut out = Seams { dirs: periodic_knots, periodic_knots, gap: [0.0; 2], diameter };
    for dir in 0..2 {
        if periodic_knots[dir] {
            continue;
        }
        let [s0, s1] = ends(dir);
        let (a, b) = (&sides[s0 as usize], &sides[s1 as usize]);
        let length: f64 = a.windows(2).map(|w| w[0].distance(w[1])).sum();
        // a side (nearly) collapsed to a point is a degenerate corner, not a seam
        if length.is_nan() || length <= 100.0 * tol {
            continue;
        }
        let same = a.iter().zip(b).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max);
        let reversed = a.iter().zip(b.iter().rev()).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max);
        if same <= tol {
            out.dirs[dir] = true;
            out.gap[dir] = same;
        } else if reversed <= tol {
            return Err(MeshError::param(
                "map",
                format!(
                    "its {} and {} sides coincide in opposite directions ({:.3e} apart): glued they make a Möbius strip, which no planar map with det J > 0 is; check the map",
                    s0.name(),
                    s1.name(),
                    reversed
                ),
            ));
        }
    }
    if out.dirs == [true, true] {
        return Err(MeshError::param("map", "both directions are periodic or cut seams (a torus has no planar mesh)"));
    }
    Ok(out)
}

impl Seams {
    /// The seam direction, if any.
    pub fn dir(&self) -> Option<usize> {
        (0..2).find(|&d| self.dirs[d])
    }

    /// Whether the map is a ring cut into a four-sided map (a seam that is not periodic).
    pub fn cut(&self) -> Option<usize> {
        self.dir().filter(|&d| !self.periodic_knots[d])
    }

    /// Confirm a cut seam at the mesh's own seam nodes: `x` at the parameters `at` of
    /// the start side against `x` at the same parameters on the end side (`at` in the
    /// coordinate along the side); refuses a gap above the tolerance. Returns the largest
    /// gap (0 for a periodic seam).
    pub fn confirm(&self, map: &Surface, at: &[f64]) -> Result<f64> {
        let Some(dir) = self.cut() else { return Ok(0.0) };
        let [s0, s1] = ends(dir);
        let gap = at.iter().map(|&t| on_side(map, s0, t).distance(on_side(map, s1, t))).fold(0.0, f64::max);
        if gap.is_nan() || gap > SEAM_TOLERANCE * self.diameter {
            return Err(MeshError::param(
                "map",
                format!(
                    "its {} and {} sides coincide at the samples but are {gap:.3e} apart at a mesh node (tolerance {:.3e}); the seam cannot be merged",
                    s0.name(),
                    s1.name(),
                    SEAM_TOLERANCE * self.diameter
                ),
            ));
        }
        Ok(gap)
    }

    /// One line for reports: which sides were merged and how far apart they were.
    pub fn describe(&self) -> Option<String> {
        let dir = self.dir()?;
        let [s0, s1] = ends(dir);
        let walls = ends(1 - dir);
        Some(if self.periodic_knots[dir] {
            format!(
                "periodic seam ({} = {}, {} periodic) merged: one line of nodes, not a boundary; walls {} and {}",
                s0.name(),
                s1.name(),
                ["xi", "eta"][dir],
                walls[0].name(),
                walls[1].name()
            )
        } else {
            format!(
                "cut ring: {} and {} coincide (largest gap {:.3e}, {:.1e} of the diameter), merged into one line of nodes, not a boundary; walls {} and {}",
                s0.name(),
                s1.name(),
                self.gap[dir],
                self.gap[dir] / self.diameter,
                walls[0].name(),
                walls[1].name()
            )
        })
    }
}

/// Names of the walls of a map with a seam across `dir`: the sides at the start and end
/// of the other direction, `inner` for the one whose closed curve encloses less area
/// (shoelace of [`SEAM_SAMPLES`] points), `outer` for the other.
pub fn wall_names(map: &Surface, dir: usize) -> [&'static str; 2] {
    let walls = ends(1 - dir);
    let area = |side: Side| {
        let p = samples(map, side);
        let o = p[0];
        let twice: f64 = (0..p.len()).map(|k| (p[k] - o).perp_dot(p[(k + 1) % p.len()] - o)).sum();
        twice.abs()
    };
    if area(walls[0]) <= area(walls[1]) {
        ["inner", "outer"]
    } else {
        ["outer", "inner"]
    }
}
