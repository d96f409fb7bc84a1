//! Multipatch domains (paper §11.2): the mathematics. Multipatch files (JSON, G+Smo
//! `<MultiPatch>`, VTK multiblock) are read and written in [`crate::io::multipatch`].
//!
//! | module | holds |
//! |---|---|
//! | [`layout`] | patches, interfaces, the boundary condition of every patch side |
//! | [`classes`] | the direction classes of the knot vectors: one knot vector per interface, propagated through chains of patches |
//! | `dofs` | the global numbering of shared control points over all patches |
//! | `problem` | one discrete problem over all patches (Winslow functional eq. 16, weak form eq. 14) on the shared numbering |
//! | [`solve`](mod@solve) | the conforming solve with fixed interfaces, patch by patch, and the layout's refinement |
//! | `free` | the free-interface stage: one global problem from the certified fixed solve |
//! | [`join`] | two patches sharing a whole side joined into one map with a `C⁰` knot |
//! | [`split`] | a domain split by the image of a parameter curve (straight or shortest in the map's metric) into two patches |
//! | `check` | validation of a layout: shared sides identical, orientations consistent, counter-clockwise patches, complete interfaces, no crossing boundaries |

pub(crate) mod check;
pub mod classes;
pub(crate) mod dofs;
pub(crate) mod free;
pub mod join;
pub mod layout;
pub(crate) mod problem;
pub mod solve;
pub mod split;

pub use check::{validate_layout, LayoutReport};
pub use free::FreeReport;
pub use layout::{Interface, Layout, Patch, PatchSide};
pub use problem::Functional;
pub(crate) use solve::solve_multipatch;
pub use solve::{interfaces_of, Interfaces, LayoutEvent, MultipatchSolution, LAYOUT_REPAIR};
