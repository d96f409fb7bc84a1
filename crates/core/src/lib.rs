//! # winslow
//!
//! Elliptic grid generation (EGG) discretized with isogeometric analysis: from the
//! boundary of a planar four-sided domain to a bijective tensor-product spline map of
//! the unit square (Hinz, Möller, Vuik, *Elliptic grid generation techniques in the
//! framework of isogeometric analysis applications*; section and equation numbers below
//! are the paper's).
//!
//! ## The public API
//!
//! What a program needs is re-exported at the crate root; the module groups hold the rest
//! of the public surface, and every other module is internal (`pub(crate)`).
//!
//! | task | the front (at the crate root) | more in |
//! |---|---|---|
//! | read and write files | [`read()`] gives a [`Document`] (boundary, map, ring, multipatch layout or result, volume), [`write()`] writes an [`Output`] by the file's extension; [`read_boundary`] with [`ReadOptions`] reads a validated four-sided boundary | [`io`]: JSON, G+Smo XML, IGES, VTK and PNG; the atomic writer [`io::write_with`] |
//! | solve: the pipeline | [`Pipeline`]`::new(input, options).run(&mut observer)` owns fit, hierarchy, solve, certificate, fallback and improvement of an [`Input`] (boundary, ring, layout, domain, plane graph, volume boundary, map) and returns [`Solved`]; the observer sees every [`Stage`] and may stop the run; [`solve()`]: a boundary in one call | [`pipeline`]: the comparison of methods ([`pipeline::compare`]), the sliding grid ([`pipeline::sweep`]) |
//! | options | [`SolveOptions`] (one list for every stage), [`FitOptions`] (the contour fit) | [`solve::options`] |
//! | report | [`Solution`]: the map and its [`Report`] (the fit, every level, the certificate, quality and `det J`); [`Verdict`], the one verdict of every run (from the certificate) | [`solve::report`] |
//! | certify | [`certify()`] gives the [`Certificate`] of a map: `det J > 0` proven or refuted (§8.1, eq. 43) | [`verify`]: quality functionals, the Poisson benchmark, the certificates of THB maps and volumes |
//! | the main types | [`Boundary`] (four [`SideCurve`]s: an [`Analytic`] curve or a [`Curve`]), [`Curve`] and [`Surface`] (a [`KnotVector`] per direction and control [`Point`]s; [`Side`]), [`Volume`](spline::volume::Volume) | [`spline`], [`boundary`] |
//! | validate and fit a boundary | [`validate()`] gives a [`ValidationReport`], [`fit_side`] a [`SideFit`], [`build_hierarchy`] / [`hierarchy_from_fits`] the [`Hierarchy`] of nested [`Level`]s (§5.4) | [`boundary`] |
//! | methods and solvers | a [`Method`] gives a [`DiscreteProblem`]; EGG ([`EggMethod`], eq. 8) assembled by an [`EggAssembler`] ([`CpuAssembler`], or the GPU crate's), solved coarse to fine by an [`EggSolver`] (an `Iterator` of [`Event`]s) on a patch's [`Topology`] ([`SideCondition`] per side) | [`methods`], [`solve`](mod@solve), [`discrete`], [`linalg`] |
//! | several patches, general domains | | [`multipatch`]: layouts, conforming bases, interfaces, join and split (§11.2); [`domain`]: any number of corners and holes, the automatic quad layout |
//! | errors | [`Error`] (typed: what is wrong and where), [`Result`] | [`error`] |
//!
//! The module groups are layered in the order `error`, [`linalg`], [`spline`],
//! [`boundary`], [`discrete`], [`verify`], [`methods`], [`solve`](mod@solve),
//! [`multipatch`], [`domain`], [`pipeline`], [`io`]: each uses only groups before it
//! (`io` reads and writes boundaries, maps, layouts and their solutions, so it comes
//! last); no module imports a module that imports it back. Two places differ from a
//! plain "one folder per pipeline step": sparse storage sits in [`linalg`], *below*
//! [`spline`], because the refinement operators of the splines (knot insertion,
//! degree elevation) are sparse matrices; and the quadrature back end of EGG
//! ([`methods::egg::EggAssembler`], implemented by the GPU crate) lives with the method
//! it assembles, not in [`discrete`], because it also samples `det J` for the report
//! ([`verify::quality`]), which in turn uses the assembly kernels.
//!
//! ## Where is …
//!
//! | paper | what | where |
//! |---|---|---|
//! | §3, eq. (1) | B-splines, NURBS, tensor-product maps | [`spline::basis`], [`spline::curve`], [`spline::surface`] |
//! | §5.1-§5.3, eq. (17)-(18), (36)-(37) | contour fit of one side, cord length | [`boundary::fit`], [`boundary::cord_length`] |
//! | §5.4 | nested hierarchy of bases | [`boundary::hierarchy`], refinement operators in `spline::refine` |
//! | §4, eq. (8), (12), (23) | EGG Galerkin form, residual, exact Jacobian | [`methods::egg`], kernels in [`discrete::assembly`] |
//! | eq. (9)-(10) | free / fixed DOFs, unknowns `c` | [`discrete::dofs`], [`discrete::topology`] |
//! | eq. (14) | weak form with `det J` (needs a bijective start) | `methods::weak_form` ([`methods::Start::Bijective`]; residual and exact Jacobian in `methods::flux`) |
//! | eq. (15)-(16) | Winslow functional | value: [`verify::quality::functionals`]; as a minimization method: [`methods::winslow::WinslowMethod`] (objective, exact gradient and Hessian) |
//! | §6.1, eq. (24)-(27) | damped Newton, line search | [`solve::newton`] |
//! | §6.2, eq. (28)-(33) | pseudo time-stepping, SER | [`solve::newton`] |
//! | §6.3, §9 | Coons start, prolongation plus elasticity, continuation | [`solve::initial`], levels in `solve::levels`, the walk in [`solve::solver`] |
//! | §7, eq. (38)-(42) | reparameterization | [`boundary::reparam`] |
//! | §8.1, eq. (43) | bijectivity certificate | [`verify::certificate`]; corners that force `det J <= 0`: [`boundary::corners`] |
//! | §8.2 | local defect correction | `solve::repair` |
//! | §10, eq. (44)-(45) | Poisson benchmark `Q(x)` | [`verify::poisson`] |
//! | §10.3, eq. (49) | Bernstein coefficients `d(c)` of `det J` and `∂d/∂c`; max-z feasible start; constrained optimisation (Liao, Winslow, area orthogonality) | `verify::certificate::coefficients`, [`solve::constrained`], functionals in `methods::metric_norms` |
//! | §10.1, eq. (46) | variational harmonic method | `methods::harmonic` (kernel of second-derivative functionals: `methods::density`) |
//! | §10.2, eq. (47)-(48) | quasi-conformal functional, `k` eliminated | [`methods::quasi_conformal`] (rank-one term: [`methods::DiscreteProblem::rank_one`]) |
//! | §10, Tables 1-3 | the comparison of methods on one basis: EGG, VHM (eq. 46), quasi-conformal (eq. 47-48), max-z (eq. 49), constrained Liao / Winslow / area orthogonality from `x_G` | [`pipeline::compare`] |
//! | §2 | quality functionals, cell statistics | [`verify::quality`] |
//! | §11.1, Fig. 23 | volumes from planar slices: trivariate maps, their certificate, the loft | [`spline::volume`], [`verify::certificate::volume`], [`spline::loft`], [`solve::loft`], files through [`read()`] and [`write()`] (`io::volume`) |
//! | §11.2 | multipatch layouts, one knot vector per interface, fixed and free interfaces, joining and splitting | [`multipatch`] |
//!
//! A geometry is a basis plus coefficients ([`Surface`], [`Curve`]); one DOF map
//! ([`discrete::dofs::DofMap`], built from the patch's [`Topology`]) of free versus fixed
//! DOFs serves every assembler; symbolic work is done once per basis
//! ([`discrete::assembly::Discretization`]) and numeric work per Newton step; solvers
//! are objects that yield their iterates ([`EggSolver`] is an `Iterator` of
//! [`solve::solver::Event`]s).

// A small public API: every type a public signature or field shows can be named (no public
// item of a `pub(crate)` module leaks out unnamed; re-export it at its group instead).
#![warn(unnameable_types)]

pub mod boundary;
pub mod discrete;
pub mod domain;
pub mod error;
pub mod io;
pub mod linalg;
pub mod methods;
pub mod multipatch;
pub mod pipeline;
pub mod solve;
pub mod spline;
#[cfg(any(test, feature = "testutil"))]
#[doc(hidden)]
pub mod testutil;
pub mod verify;

pub use boundary::fit::{fit_side, FitOptions, SideFit};
pub use boundary::hierarchy::{build_hierarchy, hierarchy_from_fits, Hierarchy, Level};
pub use boundary::validate::{validate, ValidationReport};
pub use boundary::{Analytic, Boundary, SideCurve};
pub use discrete::topology::{SideCondition, Topology};
pub use error::{Error, Result};
pub use io::{read, read_boundary, write, Document, Output, ReadOptions};
pub use methods::egg::{CpuAssembler, EggAssembler, EggMethod};
pub use methods::{DiscreteProblem, Method};
pub use pipeline::{solve, Input, Pipeline, Solved, Stage, ThbReport, ThbSolution};
pub use solve::options::{LevelOptions, RepairOptions, ReportOptions, SolveOptions};
pub use solve::report::{Report, Solution, Verdict};
pub use solve::solver::{EggSolver, Event};
pub use spline::curve::{Curve, Point};
pub use spline::knots::KnotVector;
pub use spline::surface::{Side, Surface};
pub use verify::certificate::{certify, Certificate};
