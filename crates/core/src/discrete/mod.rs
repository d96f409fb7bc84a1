//! The discrete spaces every method assembles in: which tensor-product functions are
//! free, fixed (Dirichlet), shared (periodic) or interface DOFs, and the quadrature
//! tables, sparsity patterns and element kernels on one basis.
//!
//! | module | holds | paper |
//! |---|---|---|
//! | [`topology`] | [`Topology`](topology::Topology): the boundary condition of each side of a patch (Dirichlet, periodic, interface) | §4, §11.1, §11.2 |
//! | [`dofs`] | [`DofMap`](dofs::DofMap): free versus fixed DOFs, gather and scatter of the unknowns `c` | eq. (9)-(10) |
//! | `pattern` | [`SystemPattern`](pattern::SystemPattern): sparsity of the free-free systems, gather from stencil storage (periodic replicas summed) | |
//! | [`tables`] | [`DirTable`](tables::DirTable): the univariate basis at the Gauss points | §4 |
//! | `stencil` | the product of a system with a vector from its stencil storage (no sparse matrix); [`PackedSystem`]: the single-precision storage ([`Stencil32`]) a back end ([`OperatorBackend`]) multiplies with | eq. (12) |
//! | `transfers` | the nested knot-halving spaces below a basis and the prolongations of their free unknowns (multigrid) | §6.3 |
//! | `hierarchical` | `HierarchicalDiscretization`: a THB basis cell by cell (element extraction of the truncated functions at the Gauss points), its free/fixed split and patterns | §4 |
//! | [`assembly`] | [`Discretization`](assembly::Discretization): basis tables, patterns, the EGG residual and Jacobian kernels (eq. 8, 12, 23), mass, elasticity, metric Laplacian | §4, §6 |
//!
//! Symbolic work (tables, patterns, orderings) is done once per basis when a
//! [`Discretization`](assembly::Discretization) is made; numeric work (one pass over the
//! elements per Newton step) writes into storage requested up front.

pub mod assembly;
pub mod dofs;
pub(crate) mod hierarchical;
pub(crate) mod pattern;
pub(crate) mod stencil;
pub mod tables;
pub mod topology;
pub(crate) mod transfers;

pub use stencil::{DeviceOperator, OperatorBackend, PackedSystem, Stencil32};
