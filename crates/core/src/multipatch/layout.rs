//! The layout of a multipatch domain (paper §11.2): patches, each four-sided with its
//! sides as spline curves in the orientation of `formats.md` (south and north with
//! increasing `xi`, west and east with increasing `eta`), and the interfaces between
//! pairs of patch sides. The boundary conditions of every patch side follow from it
//! (`Layout::topologies`: [`SideCondition::Interface`] on shared sides, Dirichlet on the
//! outer boundary), and so do the direction classes of the knot vectors
//! ([`super::classes`]) and the global numbering of shared control points
//! (`dofs`).

use serde::Serialize;

use crate::boundary::normalise::Similarity;
use crate::discrete::topology::{SideCondition, Topology};
use crate::error::Error;
use crate::spline::curve::{Curve, Point};
use crate::spline::surface::{Side, Surface};

/// A side of a patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct PatchSide {
    /// Patch index.
    pub patch: usize,
    /// Its side.
    #[serde(serialize_with = "side_name")]
    pub side: Side,
}

fn side_name<S: serde::Serializer>(s: &Side, ser: S) -> std::result::Result<S::Ok, S::Error> {
    ser.serialize_str(s.name())
}

/// Two patch sides that are one curve: `second` runs along `first` (`reversed` when in
/// the opposite direction of the side parameters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Interface {
    /// The first side (its curve is the interface's representative).
    pub first: PatchSide,
    /// The second side.
    pub second: PatchSide,
    /// Whether the second runs against the first.
    pub reversed: bool,
}

impl Interface {
    /// The side of the interface that is not `ps`, if `ps` is one of its sides.
    pub fn other(&self, ps: PatchSide) -> Option<PatchSide> {
        if ps == self.first {
            Some(self.second)
        } else if ps == self.second {
            Some(self.first)
        } else {
            None
        }
    }
}

/// One patch: a name, its four sides (south, east, north, west) as B-spline or NURBS
/// curves on `[0, 1]`, and the tensor map it came with, if any (a G+Smo patch or a map
/// document: only its boundary is data for a solve; the interior is kept for output
/// and for starts).
#[derive(Debug, Clone)]
pub struct Patch {
    /// Name (unique in the layout).
    pub name: String,
    /// South, east, north, west.
    pub sides: [Curve; 4],
    /// The map the patch was given as, if any.
    pub map: Option<Surface>,
    /// The region it covers (`"face"` of `formats.md`): the label of a graph face or
    /// `"domain"`, for layouts made from a general domain or plane graph.
    pub face: Option<String>,
}

impl Patch {
    /// A patch from its four sides.
    pub fn from_sides(name: impl Into<String>, sides: [Curve; 4]) -> Self {
        Self { name: name.into(), sides: sides.map(|c| c.normalized()), map: None, face: None }
    }

    /// A patch from a tensor map: its boundary curves are the sides.
    pub(crate) fn from_map(name: impl Into<String>, map: Surface) -> Self {
        let sides = Side::ALL.map(|s| map.boundary(s).normalized());
        Self { name: name.into(), sides, map: Some(map), face: None }
    }

    /// The side `s`.
    pub fn side(&self, s: Side) -> &Curve {
        &self.sides[s as usize]
    }

    /// The four corners south-west, south-east, north-east, north-west.
    pub fn corners(&self) -> [Point; 4] {
        let (sw, se) = self.side(Side::South).endpoints();
        let (nw, ne) = self.side(Side::North).endpoints();
        [sw, se, ne, nw]
    }
}

/// A multipatch domain: patches and the interfaces between their sides. Every side that
/// is in no interface is outer boundary.
#[derive(Debug, Clone)]
pub struct Layout {
    /// Name of the geometry.
    pub name: String,
    /// The patches.
    pub patches: Vec<Patch>,
    /// The interfaces.
    pub interfaces: Vec<Interface>,
}

impl Layout {
    /// The layout with every control point in the normalised coordinates `sim.to_unit`
    /// (weights, knots and interfaces unchanged; a clone for the identity).
    pub fn similar(&self, sim: &Similarity) -> Layout {
        if sim.is_identity() {
            return self.clone();
        }
        let unit = |c: &Curve| Curve {
            control_points: c.control_points.iter().map(|&p| sim.to_unit(p)).collect(),
            ..c.clone()
        };
        Layout {
            name: self.name.clone(),
            patches: self
                .patches
                .iter()
                .map(|p| Patch {
                    name: p.name.clone(),
                    sides: p.sides.each_ref().map(unit),
                    map: None,
                    face: p.face.clone(),
                })
                .collect(),
            interfaces: self.interfaces.clone(),
        }
    }

    /// `"2 (p2)"`: a patch's index and name, for errors.
    pub fn label(&self, patch: usize) -> String {
        match self.patches.get(patch) {
            Some(p) if !p.name.is_empty() => format!("{patch} ({})", p.name),
            _ => patch.to_string(),
        }
    }

    /// The error [`Error::Layout`] at `patch` (and `side`, if any).
    pub fn error(&self, patch: usize, side: Option<Side>, reason: impl Into<String>) -> Error {
        Error::Layout {
            patch: self.label(patch),
            side: side.map_or(String::new(), |s| s.name().to_string()),
            reason: reason.into(),
        }
    }

    /// The interface at patch side `ps`, and the side across it.
    pub fn across(&self, ps: PatchSide) -> Option<(&Interface, PatchSide)> {
        self.interfaces.iter().find_map(|i| i.other(ps).map(|o| (i, o)))
    }

    /// The boundary condition of every side of every patch: `Interface` with the patch
    /// side across (and whether it runs against this one) where an interface joins it,
    /// `Dirichlet` (outer boundary) elsewhere.
    pub(crate) fn topologies(&self) -> Vec<Topology> {
        (0..self.patches.len())
            .map(|p| {
                let mut t = Topology::dirichlet();
                for s in Side::ALL {
                    if let Some((i, o)) = self.across(PatchSide { patch: p, side: s }) {
                        t.sides[s as usize] =
                            SideCondition::Interface { patch: o.patch, side: o.side, reversed: i.reversed };
                    }
                }
                t
            })
            .collect()
    }

    /// The sides that are in no interface (the outer boundary), patch by patch.
    pub fn outer_sides(&self) -> Vec<PatchSide> {
        let mut out = Vec::new();
        for p in 0..self.patches.len() {
            for s in Side::ALL {
                let ps = PatchSide { patch: p, side: s };
                if self.across(ps).is_none() {
                    out.push(ps);
                }
            }
        }
        out
    }

    /// Lower-left and upper-right corner of the control points of all sides.
    pub(crate) fn bounding_box(&self) -> (Point, Point) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for c in self.patches.iter().flat_map(|p| &p.sides) {
            for q in &c.control_points {
                for d in 0..2 {
                    lo[d] = lo[d].min(q[d]);
                    hi[d] = hi[d].max(q[d]);
                }
            }
        }
        (lo, hi)
    }

    /// Diameter of `Layout::bounding_box`.
    pub fn diameter(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        (hi[0] - lo[0]).hypot(hi[1] - lo[1])
    }

    /// The index of the patch called `name`.
    pub(crate) fn patch_index(&self, name: &str) -> Option<usize> {
        self.patches.iter().position(|p| p.name == name)
    }
}

/// A side of a patch whose knot vector runs the other way than the curve's: the same
/// control points and weights in reverse order on the given knot vector `knots`.
pub(crate) fn reversed_on(c: &Curve, knots: crate::spline::knots::KnotVector) -> Curve {
    let mut control_points = c.control_points.clone();
    control_points.reverse();
    let weights = c.weights.as_ref().map(|w| w.iter().rev().copied().collect());
    Curve { knots, control_points, weights }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    fn line(a: Point, b: Point) -> Curve {
        Curve::new(KnotVector::open_uniform(1, 1), vec![a, b], None).unwrap()
    }

    /// Two unit squares side by side: the east side of the first is the west of the second.
    pub(crate) fn two_squares() -> Layout {
        let sq = |x: f64| {
            Patch::from_sides(
                format!("s{x}"),
                [
                    line([x, 0.0], [x + 1.0, 0.0]),
                    line([x + 1.0, 0.0], [x + 1.0, 1.0]),
                    line([x, 1.0], [x + 1.0, 1.0]),
                    line([x, 0.0], [x, 1.0]),
                ],
            )
        };
        Layout {
            name: "two".into(),
            patches: vec![sq(0.0), sq(1.0)],
            interfaces: vec![Interface {
                first: PatchSide { patch: 0, side: Side::East },
                second: PatchSide { patch: 1, side: Side::West },
                reversed: false,
            }],
        }
    }

    #[test]
    fn topologies_mark_interfaces() {
        let l = two_squares();
        let t = l.topologies();
        assert_eq!(t[0].side(Side::East), SideCondition::Interface { patch: 1, side: Side::West, reversed: false });
        assert_eq!(t[1].side(Side::West), SideCondition::Interface { patch: 0, side: Side::East, reversed: false });
        assert!(t[0].is_dirichlet(Side::West) && t[1].is_dirichlet(Side::East));
        assert!(t[0].validate(Some(0)).is_ok() && t[1].validate(Some(1)).is_ok());
        assert_eq!(l.outer_sides().len(), 6);
        let e = l.error(1, Some(Side::North), "bad").to_string();
        assert!(e.contains("patch 1 (s1), north side: bad"), "{e}");
    }
}
