//! # winslow
//!
//! Elliptic grid generation (EGG) discretized with isogeometric analysis: from the
//! boundary of a planar four-sided domain to a bijective tensor-product spline map of
//! the unit square (Hinz, Möller, Vuik, *Elliptic grid generation techniques in the
//! framework of isogeometric analysis applications*).
//!
//! A geometry is a basis plus coefficients: [`knots::KnotVector`] and
//! [`basis::BasisDerivs`] hold the univariate B-spline bases, [`curve::Curve`] and
//! [`surface::Surface`] the geometries, [`refine`] and [`bezier`] the exact changes of
//! basis. [`fit`] approximates the boundary contours adaptively and builds the nested
//! hierarchy of tensor-product bases (paper §5). [`io`] reads and writes the exchange formats (JSON, G+Smo XML) and
//! [`mod@validate`] checks boundaries.
//!
//! The solver (paper §4-§6): [`assembly`] discretizes eq. (8) on a tensor basis with the
//! free/fixed split of [`dofs`]; [`egg`] poses `F(c) = 0`; [`newton`] iterates (damped
//! Newton, pseudo time); [`initial`] makes initial guesses; [`solver`] walks the
//! hierarchy coarse to fine and yields its iterates, certifies the result with
//! [`certificate`] (exact Bernstein bounds of `det J`, §8.1) and repairs defects by local
//! refinement (§8.2); [`quality`], [`poisson`] (the grid-quality benchmark of §10) and
//! [`picture`] measure and draw the result.

pub mod assembly;
pub mod basis;
pub mod bezier;
pub mod boundary;
pub mod certificate;
pub mod curve;
pub mod dofs;
pub mod egg;
pub mod error;
pub mod fit;
pub mod initial;
pub mod io;
pub mod knots;
pub mod linsolve;
pub mod newton;
pub mod ordering;
pub mod picture;
pub mod poisson;
pub mod quadrature;
pub mod quality;
pub mod refine;
pub mod reparam;
pub mod solver;
pub mod sparse;
pub mod surface;
#[doc(hidden)]
pub mod testutil;
pub mod validate;

pub use boundary::{Analytic, Boundary, SideCurve};
pub use curve::{Curve, Point};
pub use error::{Error, Result};
pub use fit::{build_hierarchy, fit_side, hierarchy_from_fits, FitOptions, Hierarchy, Level, SideFit};
pub use io::{read_boundary, read_document, Document, ReadOptions};
pub use knots::KnotVector;
pub use surface::{Side, Surface};
pub use validate::{validate, ValidationReport};
