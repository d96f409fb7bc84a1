use super::*;
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// `J(c) = Σ (c_i - a_i)² / 2 - b ln c_i` on `c > 0` (`+∞` elsewhere), minimised at
/// `c_i = (a_i + sqrt(a_i² + 4 b)) / 2`; `F = -∇J`, `dF/dc = -diag(1 + b / c²)`.
/// As a root-finding problem (`minimize == false`) the same `F` with `c > 0` as the
/// admissible set.
struct Barrier {
    a: Vec<f64>,
    b: f64,
    minimize: bool,
    mass: Csr,
    /// Infeasible points the solver asked about.
    rejected: usize,
    /// Whether the residual was ever evaluated outside the feasible set.
    evaluated_outside: bool,
}

impl Barrier {
    fn new(a: Vec<f64>, b: f64, minimize: bool) -> Self {
        let n = a.len();
        Self { a, b, minimize, mass: Csr::identity(n), rejected: 0, evaluated_outside: false }
    }
    fn exact(&self) -> Vec<f64> {
        self.a.iter().map(|a| 0.5 * (a + (a * a + 4.0 * self.b).sqrt())).collect()
    }
}

impl DiscreteProblem for Barrier {
    fn size(&self) -> usize {
        self.a.len()
    }
    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        self.evaluated_outside |= c.iter().any(|&x| x <= 0.0);
        for ((f, &x), a) in f.iter_mut().zip(c).zip(&self.a) {
            *f = -(x - a - self.b / x);
        }
    }
    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        self.residual(c, f);
        let rows = c.iter().enumerate().map(|(i, &x)| vec![(i, -(1.0 + self.b / (x * x)))]).collect();
        *jac = Csr::from_rows(c.len(), rows);
    }
    fn mass(&mut self) -> &Csr {
        &self.mass
    }
    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        self.minimize.then(|| {
            if c.iter().any(|&x| x <= 0.0) {
                self.rejected += 1;
                return f64::INFINITY;
            }
            c.iter().zip(&self.a).map(|(&x, a)| 0.5 * (x - a) * (x - a) - self.b * x.ln()).sum()
        })
    }
    fn admissible(&mut self, c: &[f64]) -> bool {
        let ok = c.iter().all(|&x| x > 0.0);
        self.rejected += usize::from(!ok);
        ok
    }
    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        c.iter().map(|&x| [x, 0.0]).collect()
    }
}

/// Newton on a minimization problem and on a root-finding problem with an admissible
/// set: full steps would leave `c > 0` (the minimisers for negative `a_i` lie near
/// `b / |a_i|`), the line search backtracks instead, every accepted iterate stays
/// feasible, and both converge to the closed-form minimiser with a descending
/// objective.
#[test]
fn line_search_keeps_iterates_feasible() {
    let a: Vec<f64> = (0..12).map(|i| -3.0 + 0.5 * i as f64).collect();
    for minimize in [true, false] {
        let problem = Barrier::new(a.clone(), 1e-2, minimize);
        let exact = problem.exact();
        // a barrier slows damped Newton down near the boundary: allow the iterations
        let opts = NonlinearOptions { fallback: false, max_newton: 200, ..Default::default() };
        let mut solver = NonlinearSolver::new(problem, vec![1.0; a.len()], opts);
        let mut last = f64::INFINITY;
        for it in solver.by_ref() {
            let it = it.unwrap();
            if minimize {
                let j = it.objective.expect("a minimization method reports J");
                assert!(j <= last, "objective rose: {j} > {last}");
                last = j;
            } else {
                assert!(it.objective.is_none());
            }
        }
        assert_eq!(solver.status(), &Status::Converged, "minimize = {minimize}");
        let err = solver.solution().iter().zip(&exact).fold(0.0f64, |m, (x, e)| m.max((x - e).abs()));
        assert!(err < 1e-10, "minimize = {minimize}: error {err}");
        let (problem, _) = solver.into_parts();
        assert!(problem.rejected > 0, "the test must exercise infeasible trial steps");
        assert!(!problem.evaluated_outside, "F evaluated outside the admissible set");
    }
}

/// `J(c) = |c − a|² / 2 + (Σ c)² / 2`, presented as the sparse `−I` plus the rank-one
/// term `−1 1ᵀ`: quadratic, so one exact Newton step (Sherman-Morrison) lands on the
/// minimiser `c = a − (Σ a) / (n + 1)`.
struct RankOne {
    a: Vec<f64>,
    ones: Vec<f64>,
    mass: Csr,
}

impl DiscreteProblem for RankOne {
    fn size(&self) -> usize {
        self.a.len()
    }
    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        let s: f64 = c.iter().sum();
        for ((f, x), a) in f.iter_mut().zip(c).zip(&self.a) {
            *f = -(x - a) - s;
        }
    }
    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        self.residual(c, f);
        *jac = Csr::from_rows(c.len(), (0..c.len()).map(|i| vec![(i, -1.0)]).collect());
    }
    fn rank_one(&self) -> Option<(f64, &[f64])> {
        Some((-1.0, &self.ones))
    }
    fn mass(&mut self) -> &Csr {
        &self.mass
    }
    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        let s: f64 = c.iter().sum();
        Some(c.iter().zip(&self.a).map(|(x, a)| 0.5 * (x - a) * (x - a)).sum::<f64>() + 0.5 * s * s)
    }
    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        c.iter().map(|&x| [x, 0.0]).collect()
    }
}

#[test]
fn rank_one_term_gives_the_exact_newton_step() {
    let a: Vec<f64> = (0..7).map(|i| 0.3 * i as f64 - 1.0).collect();
    let n = a.len();
    let p = RankOne { a: a.clone(), ones: vec![1.0; n], mass: Csr::identity(n) };
    let mut solver = NonlinearSolver::new(p, vec![0.0; n], NonlinearOptions { fallback: false, ..Default::default() });
    let its: Vec<Iterate> = solver.by_ref().map(|i| i.unwrap()).collect();
    assert_eq!(solver.status(), &Status::Converged);
    assert_eq!(its.last().unwrap().iteration, 1, "one Newton step");
    assert_eq!(its.last().unwrap().damping, 1.0);
    let shift = a.iter().sum::<f64>() / (n as f64 + 1.0);
    for (x, a) in solver.solution().iter().zip(&a) {
        assert!((x - (a - shift)).abs() < 1e-13);
    }
}

/// Newton–chord (Shamanskii) on the root-finding barrier problem from a start where
/// Newton takes full steps: the same root to rounding, every iterate feasible, fewer
/// Jacobians than Newton (order 3 per Jacobian against 2).
#[test]
fn chord_steps_reach_the_root_with_fewer_jacobians() {
    let a: Vec<f64> = (0..12).map(|i| 0.5 + 0.25 * i as f64).collect();
    let mut jacobians = Vec::new();
    for chord in [false, true] {
        let problem = Barrier::new(a.clone(), 0.5, false);
        let exact = problem.exact();
        let opts = NonlinearOptions { fallback: false, chord, ..Default::default() };
        let mut solver = NonlinearSolver::new(problem, vec![1.0; a.len()], opts);
        let its: Vec<Iterate> = solver.by_ref().map(|i| i.unwrap()).collect();
        assert_eq!(solver.status(), &Status::Converged, "chord = {chord}");
        let err = solver.solution().iter().zip(&exact).fold(0.0f64, |m, (x, e)| m.max((x - e).abs()));
        assert!(err < 1e-10, "chord = {chord}: error {err}");
        assert!(its.last().unwrap().scaled_residual <= opts.tol, "the stopping rule holds at the kept iterate");
        assert_eq!(solver.chord_steps > 0, chord);
        let (problem, _) = solver.into_parts();
        assert!(!problem.evaluated_outside, "F evaluated outside the admissible set");
        jacobians.push(its.len() - 1);
    }
    assert!(jacobians[1] < jacobians[0], "Newton steps without / with chord steps: {jacobians:?}");
}

/// Newton–chord on the minimisation of the barrier functional with the decrement rule of
/// a local improvement: chord steps after the exact Newton steps, fewer Hessians, the
/// same minimiser (within the decrement rule's `1e-6` of its scale: control points to
/// 1e-7 here), `J` decreasing at every iterate, every point feasible.
#[test]
fn chord_steps_reach_the_minimiser_with_fewer_hessians() {
    let a: Vec<f64> = (0..12).map(|i| 0.5 + 0.25 * i as f64).collect();
    let mut hessians = Vec::new();
    for chord in [false, true] {
        let problem = Barrier::new(a.clone(), 0.5, true);
        let exact = problem.exact();
        let opts = NonlinearOptions { fallback: false, chord, decrement_tol: DECREMENT_TOL, ..Default::default() };
        let mut solver = NonlinearSolver::new(problem, vec![1.0; a.len()], opts);
        let its: Vec<Iterate> = solver.by_ref().map(|i| i.unwrap()).collect();
        assert_eq!(solver.status(), &Status::Converged, "chord = {chord}");
        let err = solver.solution().iter().zip(&exact).fold(0.0f64, |m, (x, e)| m.max((x - e).abs()));
        assert!(err < 1e-7, "chord = {chord}: error {err}");
        let j: Vec<f64> = its.iter().map(|i| i.objective.unwrap()).collect();
        assert!(j.windows(2).all(|w| w[1] < w[0]), "J must fall at every iterate: {j:?}");
        assert_eq!(solver.chord_steps > 0, chord);
        let (problem, _) = solver.into_parts();
        assert!(!problem.evaluated_outside, "F evaluated outside the feasible set");
        hessians.push(its.len() - 1);
    }
    assert!(hessians[1] < hessians[0], "Newton steps without / with chord steps: {hessians:?}");
}

/// The secant step along a direction: for `J(t) = -t + t² / (2 T)` (`g(t) = -1 + t /
/// T`) it is the minimiser `T`; none at or before the full step, at most
/// `EXTRAPOLATE_MAX`.
#[test]
fn extrapolated_step_is_the_secant_minimiser() {
    let g = |t: f64, big_t: f64| -1.0 + t / big_t;
    for big_t in [1.2, 2.0, 2.9] {
        let t = extrapolated_step(g(0.0, big_t), g(1.0, big_t)).unwrap();
        assert!((t - big_t).abs() < 1e-12, "{t} vs {big_t}");
    }
    assert_eq!(extrapolated_step(g(0.0, 1.0), g(1.0, 1.0)), None, "the full step is the minimiser");
    assert_eq!(extrapolated_step(g(0.0, 0.5), g(1.0, 0.5)), None, "J rises at the full step");
    assert_eq!(extrapolated_step(g(0.0, 1.05), g(1.0, 1.05)), None, "less than 10 % longer");
    assert_eq!(extrapolated_step(g(0.0, 10.0), g(1.0, 10.0)), Some(EXTRAPOLATE_MAX));
}

/// The model step along the direction for `F₁ = k F₀`: `|F(t)| ∝ |1 - t + k t²|`, smallest
/// at `t = 1 / (2k)` for `k > 1/4`; none where that is the full step (`k = 1/2`), in the
/// quadratic regime (`k <= 1/4`) or where `J` rises beyond the full step (`F₁ ⊥ F₀`).
#[test]
fn extrapolated_root_step_minimises_the_model() {
    let f0 = [1.0, -2.0, 0.5];
    let times = |k: f64| f0.map(|v| k * v);
    let t = extrapolated_root_step(&f0, &times(0.3)).unwrap();
    assert!((t - 5.0 / 3.0).abs() <= 0.05, "{t}");
    assert_eq!(extrapolated_root_step(&f0, &times(0.4)), Some(1.25));
    assert_eq!(extrapolated_root_step(&f0, &times(0.5)), None);
    assert_eq!(extrapolated_root_step(&f0, &times(0.1)), None);
    assert_eq!(extrapolated_root_step(&f0, &[1.0, 0.5, 0.0]), None);
}

/// A start outside the feasible set is refused, not iterated from.
#[test]
fn infeasible_start_fails() {
    let problem = Barrier::new(vec![1.0, 2.0], 1e-2, true);
    let mut solver = NonlinearSolver::new(problem, vec![1.0, -1.0], NonlinearOptions::default());
    for it in solver.by_ref() {
        it.unwrap();
    }
    assert!(matches!(solver.status(), Status::Failed(why) if why.contains("feasible")));
}

/// The EGG problem with its Jacobian offered only as a matrix
/// ([`DiscreteProblem::jacobian_operator`] left at its default).
struct MatrixOnly(crate::methods::egg::EggProblem);

impl DiscreteProblem for MatrixOnly {
    fn size(&self) -> usize {
        self.0.size()
    }
    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        self.0.residual(c, f)
    }
    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        self.0.jacobian(c, f, jac)
    }
    fn mass(&mut self) -> &Csr {
        self.0.mass()
    }
    fn preconditioner(&mut self, shift: f64) -> Option<&Csr> {
        self.0.preconditioner(shift)
    }
    fn ordering(&self) -> Option<&[usize]> {
        self.0.ordering()
    }
    fn transfers(&self) -> Vec<[Csr; 2]> {
        self.0.transfers()
    }
    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        self.0.control_points(c)
    }
}

/// With the multigrid preconditioner the Newton solve of EGG (eq. 12) multiplies with the
/// Jacobian's stencil storage rounded to single precision (`discrete::stencil::Stencil32`)
/// instead of the gathered matrix: on a curved, perturbed map (degrees 3 and 2, a double
/// knot, two levels below the basis) it takes as many Newton steps, its GMRES
/// iterations differ by at most one per step, and the solution is the matrix solve's to
/// the Newton tolerance (`1e-7` on a map of diameter 6; the residual `F` is exact in
/// both, only the Newton directions carry the rounding); neither the vector nor the
/// scalar pattern is built (`K` comes from its stencil storage).
#[test]
fn stencil_operator_newton_equals_matrix_newton() {
    use crate::discrete::assembly::{Discretization, Operator};
    use crate::methods::egg::{CpuAssembler, EggProblem};
    use crate::spline::knots::KnotVector;
    use std::sync::Arc;
    let kx = KnotVector::open_uniform(3, 48);
    let ky = KnotVector::open_uniform(2, 40).with_inserted(&[0.5]);
    let (gx, gy) = (kx.greville(), ky.greville());
    let mut rng = crate::testutil::Lcg::new(17);
    let mut cps = Vec::new();
    for (j, &v) in gy.iter().enumerate() {
        for (i, &u) in gx.iter().enumerate() {
            let r = 1.0 + 2.0 * v * v;
            let t = 1.3 * u + 0.2 * v * u;
            let inner = i > 0 && j > 0 && i + 1 < gx.len() && j + 1 < gy.len();
            let noise = if inner { 0.01 } else { 0.0 };
            cps.push([r * t.cos() + noise * (rng.uniform() - 0.5), r * t.sin() + noise * (rng.uniform() - 0.5)]);
        }
    }
    let disc = || Arc::new(Discretization::new([kx.clone(), ky.clone()]));
    let opts = NonlinearOptions { linear: LinearMethod::Multigrid, ..Default::default() };
    let (d_op, d_mat) = (disc(), disc());
    let op = EggProblem::new(d_op.clone(), cps.clone(), Operator::Scaled, Arc::new(CpuAssembler));
    let mat = MatrixOnly(EggProblem::new(d_mat.clone(), cps, Operator::Scaled, Arc::new(CpuAssembler)));
    assert!(op.transfers().len() >= 2, "two coarse levels");
    let c0 = op.unknowns();
    let mut a = NonlinearSolver::new(op, c0.clone(), opts);
    let mut b = NonlinearSolver::new(mat, c0, opts);
    let ia: Vec<Iterate> = a.by_ref().collect::<Result<_>>().unwrap();
    let ib: Vec<Iterate> = b.by_ref().collect::<Result<_>>().unwrap();
    assert_eq!((a.status(), b.status()), (&Status::Converged, &Status::Converged));
    assert!(ia.len() >= 3 && a.krylov_iterations() > 0, "{} iterates", ia.len());
    assert_eq!(ia.len(), ib.len());
    assert_eq!(ia[0], ib[0]);
    let steps = ia.len() - 1;
    assert!(
        a.krylov_iterations().abs_diff(b.krylov_iterations()) <= steps,
        "{} against {}",
        a.krylov_iterations(),
        b.krylov_iterations()
    );
    let gap = a.solution().iter().zip(b.solution()).fold(0.0f64, |g, (x, y)| g.max((x - y).abs()));
    // both stop at the scaled residual 1e-9 after different last steps (measured 8.9e-9
    // on a map of diameter 6)
    assert!(gap <= 1e-7, "the solutions differ by {gap:e}");
    assert!(!d_op.vector.is_built() && d_mat.vector.is_built());
    assert!(!d_op.scalar.is_built());
}
