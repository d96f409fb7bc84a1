//! Sparse linear algebra, below everything else: compressed sparse row storage, fill-
//! reducing orderings and the linear solvers (sparse LU and Cholesky through faer,
//! restarted flexible GMRES, conjugate gradients, ILU(0)).
//!
//! | module | holds |
//! |---|---|
//! | `banded` | `Banded`: symmetric banded matrices, banded Cholesky |
//! | `dense` | `DenseLu`: LU with partial pivoting of the small systems of tiny bases |
//! | [`sparse`] | [`Csr`](sparse::Csr): storage, products, pattern unions |
//! | [`ordering`] | nested dissection of a grid of points, interleaving of component blocks |
//! | [`linsolve`] | [`LinearSolver`](linsolve::LinearSolver): LU, Cholesky preconditioners (f32/f64), the choice of method |
//! | `krylov` | flexible GMRES, preconditioned CG, ILU(0) |
//! | `multigrid` | `Multigrid`: V-cycles on nested spaces given by their prolongations, Galerkin coarse operators |
//!
//! Why here and not in [`crate::discrete`]: the refinement operators of the spline layer
//! (knot insertion, degree elevation, `spline::refine`) are sparse matrices, so
//! sparse storage must sit below the splines; none of these modules knows what a spline is.

pub(crate) mod banded;
pub(crate) mod dense;
pub(crate) mod krylov;
pub mod linsolve;
pub(crate) mod multigrid;
pub mod ordering;
pub mod sparse;
pub mod split_cholesky;

pub use krylov::MatVec;
pub use multigrid::kernels as multigrid_kernels;
pub use multigrid::GridStencil;
