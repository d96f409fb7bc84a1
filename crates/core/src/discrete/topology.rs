//! Topology beside geometry: the boundary condition of each side of a patch.
//!
//! The geometry of a patch is its basis and control points; its topology says what each
//! of the four sides is: a *Dirichlet* side carries given control points (the fitted
//! boundary; eq. (8) tests only with functions vanishing there, `Σ_0`), a *periodic* side
//! is glued to the opposite side of the same patch (an O-grid with a periodic knot vector
//! across, §11.1), an *interface* side is shared with a side of another patch (§11.2).
//! [`DofMap::for_topology`](super::dofs::DofMap::for_topology) turns it into the free /
//! fixed split every assembler reads, so methods and solvers see data, not cases.
//!
//! The single-patch solver supports four Dirichlet sides, and periodic pairs on a basis
//! whose knot vector across is periodic ([`Topology::ring`]: the O-grid of §11.1, `eta`
//! periodic, `xi = 0` inner and `xi = 1` outer contour), numbered with shared DOFs by
//! [`DofMap::for_basis`](super::dofs::DofMap::for_basis). Interfaces are checked for
//! consistency here and refused with a typed error by this single-patch DOF map; the
//! multipatch layouts of `crate::multipatch` give every patch side its condition and
//! number the shared control points of interfaces once over all patches
//! (`crate::multipatch::dofs::GlobalDofs`).

use serde::Serialize;

use crate::error::{Error, Result};
use crate::spline::surface::Side;

/// What one side of a patch is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SideCondition {
    /// The side's control points are given (Dirichlet data) and fixed.
    Dirichlet,
    /// The side is the opposite side of the same patch (periodic direction, §11.1);
    /// comes in opposite pairs.
    Periodic,
    /// The side is shared with `side` of patch `patch` (§11.2); `reversed` when the two
    /// run in opposite directions.
    Interface {
        /// Index of the neighbouring patch.
        patch: usize,
        /// Its side.
        side: Side,
        /// Whether the two sides run in opposite directions.
        reversed: bool,
    },
}

/// The boundary conditions of the four sides of a patch (south, east, north, west).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Topology {
    /// South, east, north, west.
    pub sides: [SideCondition; 4],
}

impl Default for Topology {
    fn default() -> Self {
        Self::dirichlet()
    }
}

impl Topology {
    /// Four Dirichlet sides: one patch whose whole boundary is given.
    pub fn dirichlet() -> Self {
        Self { sides: [SideCondition::Dirichlet; 4] }
    }

    /// An O-grid (§11.1): south and north periodic (`eta` periodic), west (`xi = 0`, the
    /// inner contour) and east (`xi = 1`, the outer contour) Dirichlet.
    pub fn ring() -> Self {
        let mut t = Self::dirichlet();
        t.sides[Side::South as usize] = SideCondition::Periodic;
        t.sides[Side::North as usize] = SideCondition::Periodic;
        t
    }

    /// Whether the `eta` direction is periodic (south and north glued).
    pub(crate) fn eta_periodic(&self) -> bool {
        self.side(Side::South) == SideCondition::Periodic
    }

    /// The condition of side `s`.
    pub fn side(&self, s: Side) -> SideCondition {
        self.sides[s as usize]
    }

    /// Whether side `s` is Dirichlet.
    pub(crate) fn is_dirichlet(&self, s: Side) -> bool {
        self.side(s) == SideCondition::Dirichlet
    }

    /// Consistency: periodic sides come in opposite pairs; an interface names a side of
    /// another patch (`own` is this patch's index, `None` for a lone patch).
    pub fn validate(&self, own: Option<usize>) -> Result<()> {
        for s in Side::ALL {
            match self.side(s) {
                SideCondition::Periodic if self.side(s.opposite()) != SideCondition::Periodic => {
                    return Err(Error::Topology {
                        side: s.name().into(),
                        reason: format!("periodic, but the opposite {} side is not", s.opposite().name()),
                    });
                }
                SideCondition::Interface { patch, .. } if own.is_none_or(|o| o == patch) => {
                    return Err(Error::Topology {
                        side: s.name().into(),
                        reason: format!(
                            "an interface with patch {patch}, but {}",
                            own.map_or("this is a single patch".into(), |o| format!("that is this patch ({o})"))
                        ),
                    });
                }
                _ => {}
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_side() {
        assert!(Topology::dirichlet().validate(None).is_ok());
        let mut t = Topology::dirichlet();
        t.sides[Side::North as usize] = SideCondition::Periodic;
        let e = t.validate(None).unwrap_err().to_string();
        assert!(e.contains("north") && e.contains("south"), "{e}");
        t.sides[Side::South as usize] = SideCondition::Periodic;
        assert!(t.validate(None).is_ok());
        let i = SideCondition::Interface { patch: 2, side: Side::West, reversed: false };
        t.sides[Side::East as usize] = i;
        assert!(t.validate(None).unwrap_err().to_string().contains("east"));
        assert!(t.validate(Some(2)).is_err());
        assert!(t.validate(Some(0)).is_ok());
    }
}
