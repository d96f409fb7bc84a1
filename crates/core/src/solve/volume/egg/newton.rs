//! Newton's method on the 3D EGG equations `F(c) = 0` ([`super::EggVolume`]), the step
//! `F'(c) d = -F(c)` solved by sparse LU or, inexactly, by right-preconditioned GMRES.
//!
//! The GMRES preconditioner is `P = -diag(K, K, K)`, `K` the stiffness of the cofactor
//! metric ([`super::EggEvaluation::laplace`]): integrating the Jacobian's leading term
//! `∫ R_A (A : ∇²R_B) / tr A` by parts gives `-K_AB` (plus terms of lower order), in each
//! component, so `P` is the Jacobian's principal part, and `K` is SPD wherever
//! `det J ≠ 0` (`A = cof(J)ᵀ cof(J)`). `K` is one scalar system (a third of the unknowns,
//! a ninth of the Jacobian's entries), factorized by sparse Cholesky in single precision
//! ([`LinearSolver::factor_operator`]), in the nested dissection of the free control
//! points' grid and split at its top separator, the two halves on two threads
//! ([`LinearSolver::set_split_preconditioner`]; whole on one thread, the factorization
//! was one sequential stage of a 10^5-unknown solve), and kept over the Newton steps while GMRES
//! converges in few iterations with it (a frozen preconditioner,
//! [`LinearSolver::wants_preconditioner`]). GMRES stops at the forcing term of
//! Eisenstat and Walker (choice 2, as the planar Newton solver,
//! `crate::solve::newton`), which keeps Newton's quadratic convergence while the first
//! steps take few Krylov iterations.
//!
//! GMRES does not need the Jacobian as a matrix: each product `F'(c) v` is the
//! directional derivative of the residual, evaluated element by element at about the
//! cost of one residual ([`JacobianProduct`]), against an assembly of `9 m²` entries per
//! element of `m` functions (a dense `m x n_q` by `n_q x 9 m` product per element, and
//! the addition into the pattern). The Jacobian is assembled only for LU (`--linear lu`,
//! small systems, or after GMRES failed). The unknowns of the volume are interleaved
//! (`3 f + component`), those of `P`'s blocks are not: GMRES runs on the system in
//! component blocks (`component m + f`).

use crate::error::{Error, Result};
use crate::linalg::krylov::MatVec;
use crate::linalg::linsolve::{LinearMethod, LinearSolver, AUTO_LU_LIMIT, KRYLOV_TOL};
use crate::solve::newton::ETA_MAX;
use crate::spline::volume::Point3;

use super::{EggEvaluation, EggVolume};

/// Statistics of one EGG solve.
#[derive(Debug, Clone, Copy)]
pub(in crate::solve::volume) struct EggSolved {
    pub(in crate::solve::volume) iterations: usize,
    /// `|F|` of the result relative to that of the start.
    pub(in crate::solve::volume) relative_residual: f64,
    /// The linear solver of the last Newton step: [`LinearMethod::Lu`] or
    /// [`LinearMethod::Gmres`].
    pub(in crate::solve::volume) linear: LinearMethod,
    /// GMRES iterations of all Newton steps.
    pub(in crate::solve::volume) krylov_iterations: usize,
    /// The Winslow energy of the start and of the result ([`EggEvaluation::energy`],
    /// from the evaluations of the residual: `+∞` where `det J <= 0`).
    pub(in crate::solve::volume) energy_start: f64,
    pub(in crate::solve::volume) energy: f64,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The Jacobian `F'(c)` at the control points `cps` as the operator on the component
/// blocks (unknown `c m + f`, `m` free control points; the volume's unknowns are
/// interleaved, `3 f + c`): `y = Π F'(c) Πᵀ x`, each product without the Jacobian
/// ([`EggVolume::jacobian_times`]).
struct JacobianProduct<'a> {
    op: &'a EggVolume,
    cps: &'a [Point3],
}

/// `x` in component blocks (`c m + f`) to interleaved (`3 f + c`).
fn interleaved(x: &[f64]) -> Vec<f64> {
    let m = x.len() / 3;
    (0..x.len()).map(|k| x[(k % 3) * m + k / 3]).collect()
}

/// `x` interleaved (`3 f + c`) to component blocks (`c m + f`).
fn blocked(x: &[f64]) -> Vec<f64> {
    let m = x.len() / 3;
    (0..x.len()).map(|k| x[3 * (k % m) + k / m]).collect()
}

impl MatVec for JacobianProduct<'_> {
    fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        match self.op.jacobian_times(self.cps, &interleaved(x)) {
            Some(yi) => y.copy_from_slice(&blocked(&yi)),
            // `tr A = 0` at a point (not at a point whose residual was evaluated):
            // GMRES fails on the non-finite product
            None => y.fill(f64::NAN),
        }
    }

    /// A product is evaluated at every quadrature point of every element (about the
    /// cost of one residual): GMRES forms its residuals from the products it made.
    fn costly(&self) -> bool {
        true
    }
}

/// The linear solver of the Newton steps: LU, or GMRES with `P = -diag(K, K, K)` (module
/// doc) falling back to LU (for the rest of the solve) when `fallback` and GMRES fails.
struct Step {
    gmres: Option<LinearSolver>,
    lu: LinearSolver,
    fallback: bool,
    krylov_iterations: usize,
}

impl Step {
    /// For `n` unknowns and the user's `linear`: [`LinearMethod::Lu`] (and
    /// [`LinearMethod::Auto`] up to `AUTO_LU_LIMIT` unknowns) factorizes; the others run
    /// GMRES ([`LinearMethod::Multigrid`] has no hierarchy of volumes: GMRES with the
    /// factorized `K`), and `Auto` falls back to LU.
    ///
    /// `K` is factorized in the nested-dissection order of the free control points'
    /// grid (`VolumeDiscretization::ordering`), split at its top separator.
    fn new(op: &EggVolume, linear: LinearMethod) -> Self {
        let n = op.unknowns();
        let direct = match linear {
            LinearMethod::Lu | LinearMethod::Cholesky | LinearMethod::NegCholesky | LinearMethod::Pcg => true,
            LinearMethod::Auto => n <= AUTO_LU_LIMIT,
            LinearMethod::Gmres | LinearMethod::Multigrid => false,
        };
        let gmres = (!direct).then(|| {
            let mut g = LinearSolver::new(LinearMethod::Gmres);
            g.set_ordering(&op.disc.ordering());
            g.set_split_preconditioner();
            g
        });
        Self {
            gmres,
            lu: LinearSolver::new(LinearMethod::Lu),
            fallback: linear == LinearMethod::Auto,
            krylov_iterations: 0,
        }
    }

    /// Whether the next evaluation should assemble `K` (GMRES, and no frozen one).
    fn wants_laplace(&self, n: usize) -> bool {
        self.gmres.as_ref().is_some_and(|g| g.wants_preconditioner(n))
    }

    /// `d` of `F'(c) d = rhs` at the control points `cps` (`ev` evaluated there): GMRES
    /// to the relative residual `eta` with the Jacobian's products
    /// ([`JacobianProduct`], no Jacobian assembled) and the preconditioner
    /// `-diag(K, K, K)` of `ev.laplace` (`None`: the frozen one); LU of `ev.jacobian`
    /// (assembled here when `ev` has none, after a GMRES failure).
    fn solve(&mut self, op: &EggVolume, cps: &[Point3], ev: &EggEvaluation, rhs: &[f64], eta: f64) -> Result<Vec<f64>> {
        if let Some(g) = self.gmres.as_mut() {
            g.krylov_tol = eta;
            let before = g.krylov_iterations;
            let r = g
                .factor_operator(rhs.len(), ev.laplace.as_ref())
                .and_then(|()| g.solve_operator(&JacobianProduct { op, cps }, &blocked(rhs)));
            self.krylov_iterations += g.krylov_iterations - before;
            match r {
                Ok(d) => return Ok(interleaved(&d)),
                Err(e) if !self.fallback => return Err(e),
                Err(_) => self.gmres = None,
            }
        }
        let assembled;
        let jac = match ev.jacobian.as_ref() {
            Some(j) => j,
            None => {
                assembled = op.evaluate(cps, true).jacobian.ok_or_else(|| {
                    Error::LinearSolver("3D EGG: the cofactor metric vanishes at a quadrature point".into())
                })?;
                &assembled
            }
        };
        self.lu.factor(jac)?;
        self.lu.solve(rhs)
    }

    fn method(&self) -> LinearMethod {
        if self.gmres.is_some() {
            LinearMethod::Gmres
        } else {
            LinearMethod::Lu
        }
    }
}

/// The forcing term of the inexact Newton step (Eisenstat and Walker's choice 2, as
/// `crate::solve::newton`): `η = 0.9 (|F_k| / |F_(k-1)|)²`, safeguarded by `0.9 η_(k-1)²`
/// when that exceeds 0.1, `ETA_MAX` for the first step, within `[KRYLOV_TOL, ETA_MAX]`
/// and never tighter than `stop / (2 |F_k|)`, which suffices for the stopping test.
fn forcing(previous: Option<(f64, f64)>, fnorm: f64, stop: f64) -> f64 {
    let enough = 0.5 * stop / fnorm.max(f64::MIN_POSITIVE);
    let eta = match previous {
        None => ETA_MAX,
        Some((norm, eta)) => {
            let ew = 0.9 * (fnorm / norm).powi(2);
            let safeguard = 0.9 * eta * eta;
            if safeguard > 0.1 {
                ew.max(safeguard)
            } else {
                ew
            }
        }
    };
    eta.min(ETA_MAX).max(enough).clamp(KRYLOV_TOL, ETA_MAX)
}

/// Newton's method on `F(c) = 0` over the free control points of `cps` (the rest are
/// the Dirichlet data), the step by `linear` (module doc), halved while `|F|` does not
/// decrease (Armijo on `|F|`); stops when `|F| <= tolerance max(|F(start)|, 1)` (the
/// operator is of unit size in the unit frame the volume solve works in) or after
/// `max_iterations`.
pub(in crate::solve::volume) fn solve_egg(
    op: &EggVolume,
    cps: &mut [Point3],
    max_iterations: usize,
    tolerance: f64,
    linear: LinearMethod,
) -> Result<EggSolved> {
    let n = op.unknowns();
    let mut step = Step::new(op, linear);
    // GMRES multiplies with the Jacobian without assembling it (`Step::solve`)
    let mut ev = op.evaluate_with(cps, step.gmres.is_none(), step.wants_laplace(n));
    if ev.residual.is_empty() && n > 0 {
        return Err(Error::InfeasibleStart {
            method: "3D EGG".into(),
            reason: "the cofactor metric vanishes (J of rank 1 or less) at a quadrature point of the start".into(),
        });
    }
    let f0 = norm(&ev.residual);
    let energy_start = ev.energy;
    let stop = tolerance * f0.max(1.0);
    let mut x = op.disc.gather(cps);
    let mut iterations = 0;
    let mut fnorm = f0;
    let mut previous = None;
    while iterations < max_iterations && n > 0 && fnorm > stop {
        let (direct, laplace) = (step.gmres.is_none(), step.wants_laplace(n));
        if direct && ev.jacobian.is_none() || laplace && ev.laplace.is_none() {
            // the line search's residual at this point was enough to decide to go on
            ev = op.evaluate_with(cps, direct, laplace);
        }
        let rhs: Vec<f64> = ev.residual.iter().map(|f| -f).collect();
        let eta = forcing(previous, fnorm, stop);
        let d = step.solve(op, cps, &ev, &rhs, eta)?;
        if !d.iter().all(|v| v.is_finite()) {
            return Err(Error::NoConvergence("3D EGG: the Newton step is not finite".into()));
        }
        previous = Some((fnorm, eta));
        iterations += 1;
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..30 {
            let trial: Vec<f64> = x.iter().zip(&d).map(|(a, b)| a + alpha * b).collect();
            let mut c = cps.to_vec();
            op.disc.scatter(&mut c, &trial);
            let t = op.evaluate(&c, false);
            let tn = if t.residual.is_empty() { f64::INFINITY } else { norm(&t.residual) };
            if tn <= (1.0 - 1e-4 * alpha) * fnorm {
                accepted = Some((trial, c, t, tn));
                break;
            }
            alpha *= 0.5;
        }
        let Some((trial, c, t, tn)) = accepted else { break };
        x = trial;
        cps.copy_from_slice(&c);
        if let Some(j) = ev.jacobian.take() {
            op.disc.recycle(j);
        }
        (ev, fnorm) = (t, tn);
    }
    Ok(EggSolved {
        iterations,
        relative_residual: fnorm / f0.max(f64::MIN_POSITIVE),
        linear: step.method(),
        krylov_iterations: step.krylov_iterations,
        energy_start,
        energy: ev.energy,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;
    use crate::spline::volume::Volume;

    fn knots() -> [KnotVector; 3] {
        [
            KnotVector::open_uniform(3, 2),
            KnotVector::open_uniform(2, 3),
            KnotVector::open_from_breaks(2, &[0.0, 0.4, 1.0], 1),
        ]
    }

    /// At an affine map `x = M ξ + b` the metric `A` is constant and `∇²x = 0`, so the
    /// Jacobian is `δ_cd ∫ R_A (A : ∇²R_B) / tr A`, which is `-δ_cd K_AB` after
    /// integration by parts (the interior `R_A` vanish on the boundary, the quadrature is
    /// exact): the preconditioner `-diag(K, K, K)` is then the Jacobian itself; `K` is
    /// symmetric.
    #[test]
    fn the_jacobian_of_an_affine_map_is_minus_the_cofactor_stiffness() {
        let k = knots();
        let g: [Vec<f64>; 3] = std::array::from_fn(|d| k[d].greville());
        let shape = k.each_ref().map(KnotVector::num_basis);
        let m = [[1.2, 0.3, -0.1], [0.2, 0.9, 0.4], [-0.3, 0.1, 1.5]];
        let cps: Vec<Point3> = (0..shape.iter().product())
            .map(|lin| {
                let u = [g[0][lin % shape[0]], g[1][(lin / shape[0]) % shape[1]], g[2][lin / (shape[0] * shape[1])]];
                std::array::from_fn(|r| 0.5 + m[r][0] * u[0] + m[r][1] * u[1] + m[r][2] * u[2])
            })
            .collect();
        let vol = Volume::new(k, cps.clone(), None).unwrap();
        let op = EggVolume::new(&vol, 5);
        let ev = op.evaluate_with(&cps, true, true);
        assert!(ev.residual.iter().all(|f| f.abs() < 1e-13), "an affine map solves EGG");
        let (jac, lap) = (ev.jacobian.unwrap(), ev.laplace.unwrap());
        assert_eq!(3 * lap.nrows, jac.nrows);
        let scale = lap.values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for f in 0..lap.nrows {
            assert!(lap.get(f, f) > 0.0);
            for g in 0..lap.nrows {
                assert!((lap.get(f, g) - lap.get(g, f)).abs() < 1e-14 * scale, "K symmetric");
                for c in 0..3 {
                    for d in 0..3 {
                        let want = if c == d { -lap.get(f, g) } else { 0.0 };
                        let got = jac.get(3 * f + c, 3 * g + d);
                        assert!((got - want).abs() < 1e-12 * scale, "({f} {c}) ({g} {d}): {got} vs {want}");
                    }
                }
            }
        }
    }

    /// The Newton step solved by GMRES with `P = -diag(K, K, K)` to a tight tolerance is
    /// the one of sparse LU, on a rational curved volume far from a solution.
    #[test]
    fn the_gmres_step_is_the_lu_step() {
        let (vol, cps) = crate::solve::volume::tests::curved_rational_volume(knots());
        let op = EggVolume::new(&vol, 5);
        let ev = op.evaluate_with(&cps, true, true);
        let rhs: Vec<f64> = ev.residual.iter().map(|f| -f).collect();
        assert!(ev.jacobian.is_some());
        let mut lu = Step::new(&op, LinearMethod::Lu);
        let mut gmres = Step::new(&op, LinearMethod::Gmres);
        assert_eq!((lu.method(), gmres.method()), (LinearMethod::Lu, LinearMethod::Gmres));
        let a = lu.solve(&op, &cps, &ev, &rhs, 1e-12).unwrap();
        // GMRES with the Jacobian's products, no assembled Jacobian
        let ev = EggEvaluation { jacobian: None, ..ev };
        let b = gmres.solve(&op, &cps, &ev, &rhs, 1e-12).unwrap();
        assert_eq!(gmres.method(), LinearMethod::Gmres, "GMRES converged, no fallback");
        assert!(gmres.krylov_iterations >= 2, "{}", gmres.krylov_iterations);
        let (size, err) = (norm(&a), norm(&a.iter().zip(&b).map(|(x, y)| x - y).collect::<Vec<_>>()));
        assert!(size > 1e-3 && err < 1e-9 * size, "|d| = {size}, |d_gmres - d_lu| = {err}");
    }

    /// Newton's method with the GMRES step (forcing terms) reaches the map of the LU
    /// step within the tolerance, in as many iterations.
    #[test]
    fn gmres_and_lu_reach_the_same_egg_map() {
        let (vol, start) = crate::solve::volume::tests::curved_rational_volume(knots());
        let op = EggVolume::new(&vol, 5);
        let solve = |linear| {
            let mut cps = start.clone();
            let s = solve_egg(&op, &mut cps, 30, 1e-11, linear).unwrap();
            (s, cps)
        };
        let ((sl, lu), (sg, gm)) = (solve(LinearMethod::Lu), solve(LinearMethod::Gmres));
        assert_eq!((sl.linear, sg.linear), (LinearMethod::Lu, LinearMethod::Gmres));
        assert_eq!(sl.iterations, sg.iterations, "{sl:?} {sg:?}");
        // GMRES stops at what suffices for |F| <= 1e-11 max(|F(start)|, 1); LU overshoots
        assert!(sl.relative_residual < 1e-11 && sg.relative_residual < 1e-9, "{sl:?} {sg:?}");
        assert!(sg.krylov_iterations >= sg.iterations);
        let err = lu.iter().zip(&gm).fold(0.0f64, |e, (a, b)| (0..3).fold(e, |e, c| e.max((a[c] - b[c]).abs())));
        assert!(err < 1e-9, "{err}");
    }
}
