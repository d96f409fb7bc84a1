//! The parameterization methods: each poses a discrete problem on one basis, behind one
//! interface that the solver, the hierarchy, the repair loop and the CLI talk to.
//!
//! | module | method | paper |
//! |---|---|---|
//! | [`egg`] | EGG, Galerkin form with the plain operator `L` or the scaled `L / (g11 + g22)`: [`EggMethod`](egg::EggMethod) | eq. (8), (12), (23) |
//! | `weak_form` | weak form `∫ ∇w_i · ∇ξ dx = 0`, `∫ ∇w_i · ∇η dx = 0` pulled back (first derivatives only: `C⁰` bases allowed), exact Jacobian, not admissible where `det J <= 0` at a quadrature point: `WeakFormMethod`, [`Start::Bijective`] | eq. (13), (14) |
//! | `flux` | the shared kernel of first-order forms `∫ ∇w_a · G(∇x)` with exact Jacobian (eq. 14 and the gradient of eq. 16) | eq. (14), (16) |
//! | `metric_norms` | Liao `∫ g11² + g22² + 2 g12²` and area orthogonality `∫ g11² + g22²`, minimized with exact gradient and Hessian (convex; the unconstrained minimizer may fold): `MetricNormMethod` | eq. (3), §10.3 |
//! | `density` | the shared kernel of functionals `∫ ψ(∇x, ∇²x)` with exact gradient and Hessian, and the Levenberg-Marquardt shift of indefinite Hessians | §10 |
//! | `harmonic` | variational harmonic method `∫ L(x)² + L(y)² + λ₁ (uniformity) + λ₂ (area orthogonality)`, Newton from any start: `VariationalHarmonicMethod` | eq. (46) |
//! | [`quasi_conformal`] | quasi-conformal functional `∫ (f − k²)²` with the eliminated scalar `k`, Newton from any start: `QuasiConformalMethod` | eq. (47), (48) |
//! | `hierarchical` | EGG (eq. 8) and the Winslow functional (eq. 16) on a THB discretization, with the same point kernels: `HierarchicalEggProblem`, `HierarchicalWinslowProblem` | §4, eq. (8), (16) |
//! | [`winslow`] | Winslow functional `∫ (x_ξ² + x_η² + y_ξ² + y_η²) / det J`, minimized with its exact gradient and Hessian (diagonal shift where not definite), `+∞` when `det J <= 0` at a quadrature point: [`WinslowMethod`](winslow::WinslowMethod), [`Start::Bijective`] | eq. (15), (16) |
//!
//! # The interface
//!
//! A [`Method`] is given a basis with its DOF map (a
//! [`Discretization`]) and all control points, the fixed ones holding the boundary
//! values and the free ones the start; it returns a [`DiscreteProblem`] in the unknowns
//! `c = (c^x, c^y)` of the free control points (eq. 9-10). There are two kinds:
//!
//! * **root-finding** methods (eq. 8, and the weak form eq. 14) provide `F(c)` and the
//!   Jacobian `dF/dc`;
//! * **minimization** methods (the Winslow functional eq. 16, the variational methods of
//!   §10) provide an objective `J(c)` through [`DiscreteProblem::objective`], and present
//!   `F = -∇J` with `dF/dc = -∇²J`.
//!
//! The sign convention makes both kinds look alike to the solver: near a solution the
//! Jacobian is negative definite, as for EGG, whose `L` behaves like the Laplacian, so
//! the pseudo-time flow `M dc/dt = F` (eq. 30) is dissipative for both and the Krylov
//! preconditioner `-diag(K, K)` of [`DiscreteProblem::preconditioner`] keeps its sign.
//! For a minimization method the Newton step of [`crate::solve::newton`] is then
//! `-∇²J δ = ∇J`, its line search asks for a sufficient decrease of `J` instead of `|F|`,
//! and convergence is measured on `|∇J|`.
//!
//! A method whose integrand needs `det J > 0` at every quadrature point (eq. 14, 16)
//! says so with [`Start::Bijective`]: the solver refuses a start that the certificate
//! does not prove bijective, and [`DiscreteProblem::admissible`] (for root-finding
//! methods) or an objective of `+∞` (for minimization) makes the line search reject
//! every step that leaves the feasible set.
//!
//! The quadrature back end (CPU here, WGSL in the GPU crate) sits behind the EGG method:
//! [`EggAssembler`](egg::EggAssembler).

pub(crate) mod density;
pub mod egg;
pub(crate) mod flux;
pub(crate) mod galerkin;
pub(crate) mod harmonic;
pub(crate) mod hierarchical;
pub(crate) mod metric_norms;
pub mod quasi_conformal;
pub(crate) mod weak_form;
pub mod winslow;

use std::sync::Arc;

use serde::Serialize;

use crate::discrete::assembly::Discretization;
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// What a method needs of its start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Start {
    /// Any start (a Coons patch, a prolonged map that folds): eq. (8) is defined for
    /// every map.
    Any,
    /// A start with `det J > 0` everywhere, proven by the certificate (eq. 14 and 16
    /// divide by `det J`).
    Bijective,
}

/// A nonlinear system `F(c) = 0` in the free unknowns of one basis, with its Jacobian,
/// a mass matrix (for pseudo time) and, for minimization methods, the objective whose
/// negative gradient `F` is (see the module documentation for the sign convention).
pub trait DiscreteProblem {
    /// Number of unknowns.
    fn size(&self) -> usize;
    /// `F(c)` into `f`.
    fn residual(&mut self, c: &[f64], f: &mut [f64]);
    /// `F(c)` into `f` and the Jacobian `dF/dc` into `jac`, which is empty or holds
    /// this problem's fixed pattern from an earlier call (then only the values are
    /// written: no allocation, no copy of the pattern per Newton step).
    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr);
    /// `F(c)` into `f` and the Jacobian `dF/dc` kept by the problem in a form that
    /// [`DiscreteProblem::jacobian_product`] multiplies with, no matrix built (the stencil
    /// storage of eq. 12, `discrete::stencil`); `false` (the default) when the
    /// problem has no such form: then call [`DiscreteProblem::jacobian`].
    fn jacobian_operator(&mut self, _c: &[f64], _f: &mut [f64]) -> bool {
        false
    }
    /// `y = (dF/dc) x` with the Jacobian of the last [`DiscreteProblem::jacobian_operator`]
    /// call that returned `true`: the product of the matrix [`DiscreteProblem::jacobian`]
    /// would give, with the same bits.
    fn jacobian_product(&self, _x: &[f64], _y: &mut [f64]) {}
    /// The block mass matrix `diag(M, M)` of eq. (30), in the Jacobian's pattern.
    fn mass(&mut self) -> &Csr;
    /// The objective `J(c)` of a minimization method (`F = -∇J`), `+∞` outside the
    /// feasible set; `None` for a root-finding method.
    fn objective(&mut self, _c: &[f64]) -> Option<f64> {
        None
    }
    /// Whether `c` is in the set where the method is defined (e.g. `det J > 0` at every
    /// quadrature point for eq. 14); the line search never accepts a step outside it.
    fn admissible(&mut self, _c: &[f64]) -> bool {
        true
    }
    /// For a minimization method whose last Jacobian gave a Newton direction `δ` that
    /// does not descend (`∇J·δ >= 0`, which proves `δᵀ ∇²J δ <= 0`): modify the presented
    /// Hessian towards a positive definite one (e.g. a larger diagonal shift) for the
    /// next [`DiscreteProblem::jacobian`] call at the same point. `false` when the
    /// problem has no (further) modification.
    fn raise_shift(&mut self) -> bool {
        false
    }
    /// Whether the last [`DiscreteProblem::jacobian`] presented a modified matrix (not
    /// the exact `dF/dc`, see [`DiscreteProblem::raise_shift`]): its Newton steps then
    /// converge no faster than linearly.
    fn modified(&self) -> bool {
        false
    }
    /// For a minimization method: the line search accepted a step with damping `delta`
    /// (1 for the full Newton step). A problem that modifies its Hessian (a
    /// Levenberg-Marquardt shift) may adapt the modification for the next point: a
    /// heavily damped step says the quadratic model was poor. The default ignores it.
    fn step_accepted(&mut self, _delta: f64) {}
    /// A symmetric rank-one term of the Jacobian that the sparse matrix of the last
    /// [`DiscreteProblem::jacobian`] call leaves out, `dF/dc = jac + σ u uᵀ`, as `(σ, u)`:
    /// a dense coupling of all unknowns, e.g. through a global scalar eliminated from the
    /// problem (the quasi-conformal method's `k`, eq. 47). The Newton solver applies it
    /// by the Sherman-Morrison formula. `None` (the default) for a sparse Jacobian.
    fn rank_one(&self) -> Option<(f64, &[f64])> {
        None
    }
    /// A symmetric positive definite scalar matrix `K` such that `-diag(K, K)`
    /// approximates the last Jacobian minus `shift` times the mass matrix (a
    /// preconditioner for Krylov solvers), or `None` when the problem has none.
    fn preconditioner(&mut self, _shift: f64) -> Option<&Csr> {
        None
    }
    /// [`DiscreteProblem::preconditioner`] handed over: the problem keeps no copy of `K`
    /// (a multigrid V-cycle then holds the only one). The default clones it.
    fn take_preconditioner(&mut self, shift: f64) -> Option<Csr> {
        self.preconditioner(shift).cloned()
    }
    /// [`DiscreteProblem::take_preconditioner`] as a grid stencil of the free functions
    /// (`linalg::multigrid::GridStencil`, no matrix: the V-cycle's set-up reads it),
    /// where the problem has one; `None` (the default) otherwise.
    fn take_preconditioner_grid(&mut self, _shift: f64) -> Option<crate::linalg::multigrid::GridStencil> {
        None
    }
    /// A fill-reducing order of the `m` scalar unknowns for sparse Cholesky
    /// factorizations (see `crate::linalg::linsolve::LinearSolver::set_ordering`).
    fn ordering(&self) -> Option<&[usize]> {
        None
    }
    /// The prolongations of the nested spaces below the problem's scalar space, finest
    /// first, for a multigrid preconditioner of [`DiscreteProblem::preconditioner`]'s
    /// `K` (see `crate::linalg::linsolve::LinearSolver::set_transfers`), each as the 1D
    /// factors `[P_0, P_1]` of `P = P_1 ⊗ P_0` (unknowns numbered direction 0 fastest);
    /// empty (the default) when the problem has none.
    fn transfers(&self) -> Vec<[Csr; 2]> {
        Vec::new()
    }
    /// Where the level work of a multigrid V-cycle over [`DiscreteProblem::transfers`]
    /// runs: the quadrature back end's kernels (the GPU crate's), or `None` (the
    /// default) for the CPU.
    fn cycle_backend(&self) -> Option<std::sync::Arc<dyn crate::linalg::multigrid_kernels::CycleBackend>> {
        None
    }
    /// All control points of the map with unknowns `c` (fixed ones as given).
    fn control_points(&self, c: &[f64]) -> Vec<Point>;
}

impl<P: DiscreteProblem + ?Sized> DiscreteProblem for Box<P> {
    fn size(&self) -> usize {
        (**self).size()
    }
    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        (**self).residual(c, f)
    }
    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        (**self).jacobian(c, f, jac)
    }
    fn jacobian_operator(&mut self, c: &[f64], f: &mut [f64]) -> bool {
        (**self).jacobian_operator(c, f)
    }
    fn jacobian_product(&self, x: &[f64], y: &mut [f64]) {
        (**self).jacobian_product(x, y)
    }
    fn mass(&mut self) -> &Csr {
        (**self).mass()
    }
    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        (**self).objective(c)
    }
    fn admissible(&mut self, c: &[f64]) -> bool {
        (**self).admissible(c)
    }
    fn raise_shift(&mut self) -> bool {
        (**self).raise_shift()
    }
    fn modified(&self) -> bool {
        (**self).modified()
    }
    fn step_accepted(&mut self, delta: f64) {
        (**self).step_accepted(delta)
    }
    fn rank_one(&self) -> Option<(f64, &[f64])> {
        (**self).rank_one()
    }
    fn preconditioner(&mut self, shift: f64) -> Option<&Csr> {
        (**self).preconditioner(shift)
    }
    fn take_preconditioner(&mut self, shift: f64) -> Option<Csr> {
        (**self).take_preconditioner(shift)
    }
    fn take_preconditioner_grid(&mut self, shift: f64) -> Option<crate::linalg::multigrid::GridStencil> {
        (**self).take_preconditioner_grid(shift)
    }
    fn ordering(&self) -> Option<&[usize]> {
        (**self).ordering()
    }
    fn transfers(&self) -> Vec<[Csr; 2]> {
        (**self).transfers()
    }
    fn cycle_backend(&self) -> Option<std::sync::Arc<dyn crate::linalg::multigrid_kernels::CycleBackend>> {
        (**self).cycle_backend()
    }
    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        (**self).control_points(c)
    }
}

/// A parameterization method: turns a basis, its DOF map and the control points (fixed
/// ones the boundary values, free ones the start) into a [`DiscreteProblem`].
pub trait Method: Send + Sync + std::fmt::Debug {
    /// Short name ("egg-scaled", ...), for reports and progress.
    fn name(&self) -> &'static str;
    /// What the start must satisfy.
    fn start(&self) -> Start {
        Start::Any
    }
    /// Typical size of `F` for a domain of diameter `diameter`, when the control points
    /// are off by about the domain size: `|F| sqrt(m) / residual_size` is the relative
    /// residual the stopping rule compares with the tolerance.
    fn residual_size(&self, diameter: f64) -> f64;
    /// The multiplier that turns `|F|` into the dimensionless residual the stopping
    /// rule compares with the tolerance, for `m` free functions: `sqrt(m) /
    /// residual_size` for forms `∫ w_i (...)` (`∫ w_i ~ 1/m`, the default); a form
    /// `∫ ∇w_i · G` whose `G` is dimensionless (eq. 14) or of size `1 / diameter`
    /// (eq. 16's gradient) has `|F| ~ 1 / diameter` at any `m` and overrides this.
    fn residual_scale(&self, diameter: f64, m: usize) -> f64 {
        (m.max(1) as f64).sqrt() / self.residual_size(diameter)
    }
    /// The discrete problem on `disc` starting from `control_points`.
    fn problem(&self, disc: Arc<Discretization>, control_points: Vec<Point>) -> Box<dyn DiscreteProblem + Send>;
    /// Whether its problems are root-finding ones that offer the multigrid hierarchy
    /// ([`DiscreteProblem::transfers`]) and the Jacobian as an operator on a patch whose
    /// boundary functions are all fixed, so that `--linear auto` may solve them by
    /// `--linear multigrid` (`crate::solve::memory::auto_linear`); `false` (the default)
    /// keeps the solver asked for.
    fn multigrid(&self) -> bool {
        false
    }
}

/// Largest difference between the Jacobian at `c` and central differences of the
/// residual with step `h`, and the largest difference quotient (its scale): the
/// finite-difference check every method's tests run.
#[cfg(test)]
pub(crate) fn jacobian_fd_mismatch(prob: &mut dyn DiscreteProblem, c: &[f64], h: f64) -> (f64, f64) {
    let n = c.len();
    let mut f = vec![0.0; n];
    let mut jac = Csr::default();
    prob.jacobian(c, &mut f, &mut jac);
    let mut dense = jac.to_dense();
    if let Some((sigma, u)) = prob.rank_one() {
        for (row, ui) in dense.iter_mut().zip(u) {
            for (v, uj) in row.iter_mut().zip(u) {
                *v += sigma * ui * uj;
            }
        }
    }
    let (mut err, mut scale) = (0.0f64, 0.0f64);
    for j in 0..n {
        let (mut cp, mut cm) = (c.to_vec(), c.to_vec());
        cp[j] += h;
        cm[j] -= h;
        let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
        prob.residual(&cp, &mut fp);
        prob.residual(&cm, &mut fm);
        for i in 0..n {
            let fd = (fp[i] - fm[i]) / (2.0 * h);
            err = err.max((fd - dense[i][j]).abs());
            scale = scale.max(fd.abs());
        }
    }
    (err, scale)
}
