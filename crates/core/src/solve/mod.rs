//! Solving: the nonlinear iterations, the initial guesses, the coarse-to-fine walk over
//! the hierarchy, defect correction, and the event stream that the CLI progress, the
//! viewer's live plot and the tests all read.
//!
//! | module | holds | paper |
//! |---|---|---|
//! | [`newton`] | [`NonlinearSolver`](newton::NonlinearSolver): damped Newton with line search, pseudo time-stepping with the SER rule; an `Iterator` of iterates | §6.1, §6.2, eq. (24)-(33) |
//! | `fixed_basis` | `FixedBasisSolve`: one solve on a fixed basis (scaled options, iterates recorded while they stream, the result taken back, "keep only if certified"), run by every stage below | §4.1, §6, §9, §11 |
//! | [`initial`] | Coons patch, prolongation plus linear elasticity, boundary continuation | §6.3, §9 |
//! | `levels` | which levels are solved: balancing, extra refinements, growth factor | §5.4, §6.3 |
//! | `graded` | the graded level before a multigrid finest level: the coarser level's knots with the finest level's inserted where the finest start's residual sits (a local defect that does not fall with `h`) | §6.3 |
//! | [`hierarchical`] | `repair_thb`: local defect correction on a THB basis, only the offending cells and a ring refined, EGG solved on the THB discretization (`--refinement thb`) | §4, §8.2 |
//! | `repair` | local defect correction around folded or undecided elements | §8.2 |
//! | [`memory`] | the peak memory of a solve estimated from its basis sizes, checked against [`MemoryLimit`](memory::MemoryLimit) (`--max-memory`) before it allocates | |
//! | [`options`] | [`SolveOptions`](options::SolveOptions) | |
//! | [`solver`] | [`EggSolver`](solver::EggSolver): the coarse-to-fine solve of any [`Method`](crate::methods::Method) as a stream of [`Event`](solver::Event)s | §6.3 |
//! | [`loft`] | [`loft`](loft::loft): a volume from planar slices, certified, with slices inserted (solved from interpolated guesses) where it is not | §11.1, Fig. 23 |
//! | [`volume`] | `solve_volume`: a volume from its six boundary faces (common bases, trivariate Coons start, 3D EGG (eq. 8) and/or 3D Winslow by Newton, boundary continuation), certified | §11.1 |
//! | [`improve`] | [`improve`](improve::improve): a certified map improved on its own basis by a method that needs a bijective start (Winslow, eq. 16), certified again, kept only when certified; the same stage on a layout (one patch: a one-patch layout) serves the free interfaces of [`multipatch`](crate::multipatch) | §4.1, §9, §11.2 |
//! | [`constrained`] | Gravesen's feasible start [`max_z`](constrained::max_z) (`max z`, `d(c) >= z 1`) and the constrained optimisation [`optimise`](constrained::optimise) of the Liao, Winslow or area-orthogonality functional subject to `d(c) >= ε` (SQP, Clarabel subproblems), from the EGG map or the max-z point: [`run`](constrained::run) | §10.3, eq. (49), Table 3 |
//! | `kinks` | `keep_kinks`: the `C^0` route, kinks kept exactly (EGG on `Σ¹`, elasticity to the kinked boundary, Winslow on `Σ⁰`) | §9 |
//! | [`warm`] | [`warm_start`](warm::warm_start): the previous map of a shape family moved onto the next boundary (elasticity) and solved on its basis as [`improve`](improve::improve) runs EGG, kept only when certified | §6.3, issue 34 |
//! | [`report`] | [`Solution`](report::Solution), [`Report`](report::Report) grouped by stage ([`SetupReport`](report::SetupReport), [`FitStage`](report::FitStage), [`SolveStage`](report::SolveStage), [`Outcome`](report::Outcome), [`DetJReport`](report::DetJReport), [`QualityReport`](report::QualityReport), [`BoundaryReport`](report::BoundaryReport)), [`Verdict`](report::Verdict), [`LevelReport`](report::LevelReport) | §8.1, §10 |

pub mod constrained;
pub(crate) mod fixed_basis;
pub(crate) mod graded;
pub mod hierarchical;
pub mod improve;
pub mod initial;
pub(crate) mod kinks;
pub(crate) mod levels;
pub mod loft;
pub mod memory;
pub mod newton;
pub mod options;
pub(crate) mod repair;
pub mod report;
pub mod solver;
pub mod volume;
pub mod warm;

pub use kinks::KinkStage;
pub use repair::RepairRound;
