//! One knot vector per interface, propagated through the layout: a knot in direction
//! `d` of a patch is a knot line across the whole patch, so it runs through the opposite
//! side into the next patch, and from there on. The patch directions `(patch, d)` fall
//! into equivalence classes (joined across every interface, with the relative
//! orientation of the two side parameters), and every class gets one degree and one
//! knot vector: the union of the knot vectors of all its sides, each brought to the
//! class's orientation ([`LayoutBases`]). Opposite sides of a patch are one direction,
//! so they share the class's vector; the two sides of an interface are members of one
//! class, so the interface has one knot vector on both sides (C0-conforming patches).
//!
//! A class may contain a direction in both orientations (a chord of the layout that
//! crosses itself with a flip); its knot vector is then made symmetric (`t` and `1 - t`).

use std::collections::HashMap;

use serde::Serialize;

use super::dofs::find;
use super::layout::{reversed_on, Layout, PatchSide};
use crate::error::Result;
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::{KnotVector, KNOT_TOL};
use crate::spline::surface::Side;

/// The equivalence classes of the patch directions.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Classes {
    /// For patch `p` and direction `d` (0 = `xi`, 1 = `eta`): its class and whether its
    /// parameter runs against the class's orientation.
    pub member: Vec<[(usize, bool); 2]>,
    /// Per class: whether it holds a direction in both orientations.
    pub self_dual: Vec<bool>,
}

impl Classes {
    /// Number of classes.
    pub fn len(&self) -> usize {
        self.self_dual.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.self_dual.is_empty()
    }

    /// The patch directions in class `c`, with their flips.
    pub fn members(&self, c: usize) -> Vec<(usize, usize, bool)> {
        let mut out = Vec::new();
        for (p, m) in self.member.iter().enumerate() {
            for (d, &(k, f)) in m.iter().enumerate() {
                if k == c {
                    out.push((p, d, f));
                }
            }
        }
        out
    }
}

/// Union-find with the parity of each node relative to its parent.
struct Parity {
    parent: Vec<usize>,
    parity: Vec<bool>,
    dual: Vec<bool>,
}

impl Parity {
    fn find(&mut self, x: usize) -> (usize, bool) {
        let p = self.parent[x];
        if p == x {
            return (x, false);
        }
        let (r, pp) = self.find(p);
        self.parent[x] = r;
        self.parity[x] ^= pp;
        (r, self.parity[x])
    }

    fn union(&mut self, a: usize, b: usize, flip: bool) {
        let (ra, pa) = self.find(a);
        let (rb, pb) = self.find(b);
        if ra == rb {
            if pa ^ pb != flip {
                self.dual[ra] = true;
            }
            return;
        }
        self.parent[rb] = ra;
        self.parity[rb] = pa ^ pb ^ flip;
        self.dual[ra] |= self.dual[rb];
    }
}

/// The direction classes of `layout` (see the module documentation), numbered in the
/// order of their first patch direction.
pub fn direction_classes(layout: &Layout) -> Classes {
    let n = 2 * layout.patches.len();
    let mut uf = Parity { parent: (0..n).collect(), parity: vec![false; n], dual: vec![false; n] };
    for i in &layout.interfaces {
        let a = 2 * i.first.patch + i.first.side.direction();
        let b = 2 * i.second.patch + i.second.side.direction();
        uf.union(a, b, i.reversed);
    }
    let mut number: HashMap<usize, usize> = HashMap::new();
    let mut self_dual = Vec::new();
    let mut member = vec![[(0, false); 2]; layout.patches.len()];
    for x in 0..n {
        let (r, f) = uf.find(x);
        let next = number.len();
        let c = *number.entry(r).or_insert_with(|| {
            self_dual.push(false);
            next
        });
        self_dual[c] = uf.dual[r];
        member[x / 2][x % 2] = (c, f);
    }
    Classes { member, self_dual }
}

/// `t -> 1 - t` on a knot vector of `[0, 1]` (ends snapped).
pub fn flipped(kv: &KnotVector) -> KnotVector {
    let knots: Vec<f64> = kv
        .knots()
        .iter()
        .rev()
        .map(|&t| {
            let r = 1.0 - t;
            if r.abs() < 1e-15 {
                0.0
            } else {
                r
            }
        })
        .collect();
    KnotVector::new(kv.degree(), knots).expect("the mirror image of an open knot vector is one")
}

/// `c` raised to degree `p` (exactly) on `[0, 1]`.
fn elevated_to(c: &Curve, p: usize) -> Result<Curve> {
    let mut c = c.normalized();
    while c.degree() < p {
        c = c.elevated()?;
    }
    Ok(c)
}

/// The bases of a layout: per direction class a degree and a knot vector.
#[derive(Debug, Clone)]
pub struct LayoutBases {
    /// The classes.
    pub classes: Classes,
    /// Per class: its knot vector on `[0, 1]` in the class's orientation.
    pub knots: Vec<KnotVector>,
    /// Per patch and direction: the breaks of its own sides, to which the knots of
    /// [`LayoutBases::knots_of`] are snapped (so that `1 - (1 - t)` gives back `t`).
    own: Vec<[Vec<f64>; 2]>,
}

impl LayoutBases {
    /// Degree per class `max(2, degrees of its sides)`, knot vector the union of its
    /// sides' (see the module documentation).
    pub fn new(layout: &Layout) -> Result<Self> {
        let classes = direction_classes(layout);
        let mut degree = vec![2usize; classes.len()];
        for (p, patch) in layout.patches.iter().enumerate() {
            for s in Side::ALL {
                let c = classes.member[p][s.direction()].0;
                degree[c] = degree[c].max(patch.side(s).degree());
            }
        }
        let mut knots: Vec<Option<KnotVector>> = vec![None; classes.len()];
        let mut own: Vec<[Vec<f64>; 2]> = vec![Default::default(); layout.patches.len()];
        for (p, patch) in layout.patches.iter().enumerate() {
            for s in Side::ALL {
                let (c, flip) = classes.member[p][s.direction()];
                let side = elevated_to(patch.side(s), degree[c])?;
                own[p][s.direction()].extend(side.knots.breaks());
                let kv = if flip { flipped(&side.knots) } else { side.knots };
                knots[c] = Some(match knots[c].take() {
                    None => kv,
                    Some(k) => k.union(&kv)?,
                });
            }
        }
        let mut knots: Vec<KnotVector> = knots.into_iter().map(|k| k.expect("every class has a side")).collect();
        for (c, k) in knots.iter_mut().enumerate() {
            if classes.self_dual[c] {
                *k = k.union(&flipped(k))?;
            }
        }
        for o in own.iter_mut().flat_map(|o| o.iter_mut()) {
            o.sort_by(f64::total_cmp);
            o.dedup();
        }
        Ok(Self { classes, knots, own })
    }

    /// The knot vector of direction `d` of patch `p`.
    pub(crate) fn knots_of(&self, p: usize, d: usize) -> KnotVector {
        let (c, flip) = self.classes.member[p][d];
        let kv = if flip { flipped(&self.knots[c]) } else { self.knots[c].clone() };
        let own = &self.own[p][d];
        let snapped: Vec<f64> = kv
            .knots()
            .iter()
            .map(|&t| {
                let k = own.partition_point(|&b| b < t);
                [k.checked_sub(1), Some(k)]
                    .into_iter()
                    .flatten()
                    .filter_map(|k| own.get(k).copied())
                    .find(|&b| (b - t).abs() <= KNOT_TOL)
                    .unwrap_or(t)
            })
            .collect();
        KnotVector::new(kv.degree(), snapped).expect("snapping within the merge tolerance keeps the order")
    }

    /// The two knot vectors of patch `p`.
    pub(crate) fn patch_knots(&self, p: usize) -> [KnotVector; 2] {
        [self.knots_of(p, 0), self.knots_of(p, 1)]
    }

    /// Every knot span of the classes `which` halved (all classes when `None`).
    pub fn refined(&self, which: Option<&[usize]>) -> Self {
        let knots = self
            .knots
            .iter()
            .enumerate()
            .map(|(c, k)| if which.is_none_or(|w| w.contains(&c)) { k.halved() } else { k.clone() })
            .collect();
        Self { classes: self.classes.clone(), knots, own: self.own.clone() }
    }

    /// Basis functions over all patches (interface functions counted once per patch).
    pub fn num_basis(&self) -> usize {
        (0..self.classes.member.len()).map(|p| self.knots_of(p, 0).num_basis() * self.knots_of(p, 1).num_basis()).sum()
    }

    /// The sides of every patch on these bases, conforming: each side refined exactly
    /// onto its direction's knot vector, every end control point the same point for all
    /// sides that meet at that corner of the layout, and the second side of every
    /// interface the first one's control points (reversed where the interface is), bit
    /// for bit.
    pub fn conforming_sides(&self, layout: &Layout) -> Result<Vec<[Curve; 4]>> {
        let mut sides: Vec<Vec<Curve>> = Vec::with_capacity(layout.patches.len());
        for (p, patch) in layout.patches.iter().enumerate() {
            let mut four = Vec::with_capacity(4);
            for s in Side::ALL {
                let kv = self.knots_of(p, s.direction());
                let c = elevated_to(patch.side(s), kv.degree())?;
                four.push(c.refined(&kv).map_err(|e| layout.error(p, Some(s), e.to_string()))?);
            }
            sides.push(four);
        }
        // one point per corner of the layout: the first patch corner of its group
        let vertices = vertex_points(layout);
        for (p, four) in sides.iter_mut().enumerate() {
            let [sw, se, ne, nw] = vertices[p];
            for (s, (a, b)) in Side::ALL.into_iter().zip([(sw, se), (se, ne), (nw, ne), (sw, nw)]) {
                let cps = &mut four[s as usize].control_points;
                let last = cps.len() - 1;
                cps[0] = a;
                cps[last] = b;
            }
        }
        for i in &layout.interfaces {
            let rep = sides[i.first.patch][i.first.side as usize].clone();
            let kv = self.knots_of(i.second.patch, i.second.side.direction());
            let c = if i.reversed {
                reversed_on(&rep, kv)
            } else {
                Curve { knots: kv, control_points: rep.control_points, weights: rep.weights }
            };
            sides[i.second.patch][i.second.side as usize] = c;
        }
        Ok(sides.into_iter().map(|v| v.try_into().expect("four sides")).collect())
    }
}

/// The corner points of every patch (south-west, south-east, north-east, north-west),
/// with the corners that are one point of the layout (joined through interfaces) given
/// the value of the first of them.
pub(crate) fn vertex_points(layout: &Layout) -> Vec<[Point; 4]> {
    let groups = vertex_groups(layout);
    let mut first: HashMap<usize, Point> = HashMap::new();
    let mut out = Vec::with_capacity(layout.patches.len());
    for (p, patch) in layout.patches.iter().enumerate() {
        let c = patch.corners();
        out.push(std::array::from_fn(|k| *first.entry(groups[4 * p + k]).or_insert(c[k])));
    }
    out
}

/// For corner `k` (south-west, south-east, north-east, north-west) of patch `p`, at
/// `4 p + k`: the number of the layout vertex it is.
pub(crate) fn vertex_groups(layout: &Layout) -> Vec<usize> {
    let n = 4 * layout.patches.len();
    let mut parent: Vec<usize> = (0..n).collect();
    // the corners at the start and end of a side
    let ends = |ps: PatchSide| -> (usize, usize) {
        let b = 4 * ps.patch;
        match ps.side {
            Side::South => (b, b + 1),
            Side::East => (b + 1, b + 2),
            Side::North => (b + 3, b + 2),
            Side::West => (b, b + 3),
        }
    };
    for i in &layout.interfaces {
        let (a0, a1) = ends(i.first);
        let (b0, b1) = ends(i.second);
        let (b0, b1) = if i.reversed { (b1, b0) } else { (b0, b1) };
        for (x, y) in [(a0, b0), (a1, b1)] {
            let (rx, ry) = (find(&mut parent, x), find(&mut parent, y));
            parent[ry] = rx;
        }
    }
    let mut number = HashMap::new();
    (0..n)
        .map(|x| {
            let r = find(&mut parent, x);
            let next = number.len();
            *number.entry(r).or_insert(next)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::multipatch::layout::{Interface, Patch};

    fn line(a: Point, b: Point, breaks: &[f64]) -> Curve {
        let kv = KnotVector::open_from_breaks(2, breaks, 1);
        let g = kv.greville();
        let cps = g.iter().map(|&t| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]).collect();
        Curve::new(kv, cps, None).unwrap()
    }

    /// A rectangle patch with given breaks on its south/north and west/east sides.
    fn rect(x0: f64, y0: f64, bx: &[f64], by: &[f64]) -> Patch {
        let (x1, y1) = (x0 + 1.0, y0 + 1.0);
        Patch::from_sides(
            format!("r{x0}{y0}"),
            [
                line([x0, y0], [x1, y0], bx),
                line([x1, y0], [x1, y1], by),
                line([x0, y1], [x1, y1], bx),
                line([x0, y0], [x0, y1], by),
            ],
        )
    }

    fn iface(a: usize, sa: Side, b: usize, sb: Side, reversed: bool) -> Interface {
        Interface { first: PatchSide { patch: a, side: sa }, second: PatchSide { patch: b, side: sb }, reversed }
    }

    /// A 2x2 grid: a knot placed in one patch's `xi` reaches the patch above it, and a
    /// knot in one `eta` reaches the patch beside it; the two others are untouched.
    #[test]
    fn knots_propagate_through_a_2x2_grid() {
        let u = [0.0, 1.0];
        let layout = Layout {
            name: "2x2".into(),
            patches: vec![
                rect(0.0, 0.0, &[0.0, 0.3, 1.0], &u), // 0: xi knot 0.3
                rect(1.0, 0.0, &u, &[0.0, 0.6, 1.0]), // 1: eta knot 0.6
                rect(0.0, 1.0, &u, &u),               // 2 above 0
                rect(1.0, 1.0, &u, &u),               // 3 above 1
            ],
            interfaces: vec![
                iface(0, Side::East, 1, Side::West, false),
                iface(0, Side::North, 2, Side::South, false),
                iface(1, Side::North, 3, Side::South, false),
                iface(2, Side::East, 3, Side::West, false),
            ],
        };
        let b = LayoutBases::new(&layout).unwrap();
        assert_eq!(b.classes.len(), 4);
        assert_eq!(b.classes.member[0][0].0, b.classes.member[2][0].0);
        assert_eq!(b.classes.member[0][1].0, b.classes.member[1][1].0);
        assert_ne!(b.classes.member[0][0].0, b.classes.member[1][0].0);
        assert_eq!(b.knots_of(2, 0).breaks(), vec![0.0, 0.3, 1.0]);
        assert_eq!(b.knots_of(0, 1).breaks(), vec![0.0, 0.6, 1.0]);
        assert_eq!(b.knots_of(1, 0).breaks(), vec![0.0, 1.0]);
        assert_eq!(b.knots_of(3, 1).breaks(), vec![0.0, 1.0]);
        let sides = b.conforming_sides(&layout).unwrap();
        assert_eq!(sides[0][Side::East as usize].control_points, sides[1][Side::West as usize].control_points);
        assert_eq!(sides[2][Side::South as usize].knots.breaks(), vec![0.0, 0.3, 1.0]);
    }

    /// An L of three patches whose middle patch is turned: patch 1's `eta` runs along
    /// patch 0's `xi` backwards, so a knot at 0.25 in patch 0's `xi` is at 0.75 in patch 1's
    /// `eta`, and from there it runs on into patch 2's `eta` (same orientation).
    #[test]
    fn knots_propagate_through_an_l_with_a_turned_patch() {
        // patch 0: [0,1]^2; patch 1 above it, rotated by 90 degrees (its xi runs down,
        // its eta runs right... expressed by side curves); patch 2 right of patch 1.
        let p0 = rect(0.0, 0.0, &[0.0, 0.25, 1.0], &[0.0, 1.0]);
        // patch 1 on [0,1]x[1,2], turned: south = left edge top-down, east = bottom edge
        // left to right, north = right edge top-down, west = top edge left to right
        let p1 = Patch::from_sides(
            "turned",
            [
                line([0.0, 2.0], [0.0, 1.0], &[0.0, 1.0]),
                line([0.0, 1.0], [1.0, 1.0], &[0.0, 0.5, 1.0]),
                line([1.0, 2.0], [1.0, 1.0], &[0.0, 1.0]),
                line([0.0, 2.0], [1.0, 2.0], &[0.0, 0.5, 1.0]),
            ],
        );
        let p2 = rect(1.0, 1.0, &[0.0, 1.0], &[0.0, 0.1, 1.0]);
        let layout = Layout {
            name: "L".into(),
            patches: vec![p0, p1, p2],
            interfaces: vec![
                // patch 0 north (xi, left to right) = patch 1 east (eta, left to right)
                iface(0, Side::North, 1, Side::East, false),
                // patch 1 north (xi, top-down) = patch 2 west (eta, bottom-up): reversed
                iface(1, Side::North, 2, Side::West, true),
            ],
        };
        crate::multipatch::check::validate_layout(&layout).unwrap();
        let b = LayoutBases::new(&layout).unwrap();
        // patch 0's xi, patch 1's eta: one class
        assert_eq!(b.classes.member[0][0].0, b.classes.member[1][1].0);
        // patch 1's xi, patch 2's eta: one class, flipped against each other
        let (c1, f1) = b.classes.member[1][0];
        let (c2, f2) = b.classes.member[2][1];
        assert!(c1 == c2 && f1 != f2);
        assert_eq!(b.knots_of(1, 1).breaks(), vec![0.0, 0.25, 0.5, 1.0]);
        assert_eq!(b.knots_of(0, 0).breaks(), vec![0.0, 0.25, 0.5, 1.0]);
        // 0.1 of patch 2's eta is 0.9 of patch 1's xi
        let k1 = b.knots_of(1, 0).breaks();
        assert_eq!(k1.len(), 3);
        assert!((k1[1] - 0.9).abs() < 1e-15, "{k1:?}");
        assert_eq!(b.knots_of(2, 1).breaks(), vec![0.0, 0.1, 1.0]);
        // the interface's control points are one set, reversed on the second side
        let sides = b.conforming_sides(&layout).unwrap();
        let a = &sides[1][Side::North as usize].control_points;
        let mut c = sides[2][Side::West as usize].control_points.clone();
        c.reverse();
        assert_eq!(a, &c);
        // every side of patch 1 is on its knot vectors
        for s in Side::ALL {
            assert_eq!(sides[1][s as usize].knots, b.knots_of(1, s.direction()));
        }
    }
}
