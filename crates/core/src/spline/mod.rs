//! Splines: a geometry is a basis plus coefficients.
//!
//! | module | holds | paper |
//! |---|---|---|
//! | [`knots`] | [`KnotVector`](knots::KnotVector): open, uniform and periodic; spans, Greville points, dyadic halving, unions | §3 |
//! | [`basis`] | [`BasisDerivs`](basis::BasisDerivs): non-allocating B-spline values and derivatives (Piegl–Tiller) | §3 |
//! | [`curve`] | [`Curve`](curve::Curve): B-spline and NURBS curves | §3 |
//! | [`surface`] | [`Surface`](surface::Surface): tensor-product maps `x: [0,1]² → R²`, sides, inversion | §3, eq. (1) |
//! | [`face`] | [`Face`](face::Face): tensor-product surfaces in space (faces of a volume), insertion, elevation | §11.1 |
//! | `refine` | knot insertion and degree elevation as sparse prolongation matrices | §5.4, §6.3 |
//! | `bezier` | Bézier extraction of a tensor basis | §8.1 |
//! | [`hierarchical`] | [`HierarchicalBasis`](hierarchical::HierarchicalBasis), [`HierarchicalMap`](hierarchical::map::HierarchicalMap): truncated hierarchical B-splines (THB), local refinement | §4, §8 |
//! | `periodic` | periodic splines (wrapped control points): knot insertion, elevation and Bézier extraction by blossoming | §11.1 |
//! | `translate` | the `L2` projection of parameter translates onto a periodic space (the sliding boundary of a ring) | §11.1 |
//! | `quadrature` | Gauss–Legendre rules | §4 |
//! | [`loft`] | volumes from planar slices: one common basis, linear or `C²` cubic interpolation in `z` | §11.1, Fig. 23 |
//! | [`tensor`] | [`TensorSpline`](tensor::TensorSpline): the tensor-product core of surfaces, faces and volumes (`P` parameters into `R^D`): validation, evaluation, insertion, elevation | §3, §11.1 |
//! | [`volume`] | [`Volume`](volume::Volume): trivariate tensor-product maps `x: [0,1]³ → R³`, knot insertion, elevation, Bézier nets | §11.1 |

pub mod basis;
pub(crate) mod bezier;
pub mod curve;
pub mod face;
pub mod hierarchical;
pub mod knots;
pub mod loft;
pub(crate) mod periodic;
pub(crate) mod quadrature;
pub(crate) mod refine;
pub mod surface;
pub mod tensor;
pub(crate) mod translate;
pub mod volume;
