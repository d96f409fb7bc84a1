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
//! basis. [`io`] reads and writes the exchange formats (JSON, G+Smo XML) and
//! [`mod@validate`] checks boundaries.

pub mod basis;
pub mod bezier;
pub mod boundary;
pub mod curve;
pub mod error;
pub mod io;
pub mod knots;
pub mod quadrature;
pub mod refine;
pub mod sparse;
pub mod surface;
#[doc(hidden)]
pub mod testutil;
pub mod validate;

pub use boundary::{Analytic, Boundary, SideCurve};
pub use curve::{Curve, Point};
pub use error::{Error, Result};
pub use io::{read_boundary, read_document, Document, ReadOptions};
pub use knots::KnotVector;
pub use surface::{Side, Surface};
pub use validate::{validate, ValidationReport};
