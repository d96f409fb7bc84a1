//! Multipatch domains (paper §11.2).
//!
//! | module | holds |
//! |---|---|
//! | [`layout`] | patches, interfaces, the boundary condition of every patch side |
//! | [`classes`] | the direction classes of the knot vectors: one knot vector per interface, propagated through chains of patches |
//! | [`gismo`] | G+Smo XML `<MultiPatch>` files, read and written with G+Smo's side numbering and orientation flags |
//! | [`check`] | validation of a layout: shared sides identical, orientations consistent, counter-clockwise patches, complete interfaces, no crossing boundaries |

pub mod check;
pub mod classes;
pub mod gismo;
pub mod layout;

pub use check::{validate_layout, LayoutReport};
pub use layout::{Interface, Layout, Patch, PatchSide};
