//! The constrained optimisation of Gravesen et al. (paper §10.3): `min J(c)` subject to
//! `d(c) >= ε`, by sequential quadratic programming with a trust region.
//!
//! At a feasible iterate `c` with multipliers `λ` (from the previous QP), the QP
//!
//! `min ∇Jᵀ δ + ½ δᵀ B δ` subject to `d_k + ∇d_k δ >= min(ε, d_k)`, `|δ_i| <= Δ`,
//!
//! is solved by Clarabel, with `B` the exact Hessian `∇²J` of the functional (its
//! eigenvalues replaced by their absolute values, floored at `10⁻⁸` of the largest: the
//! Liao and area-orthogonality Hessians are semidefinite already, Winslow's is not far
//! from its minimiser). The constraints' curvature (`∇²d` is constant: `d` is bilinear)
//! enters through the second-order correction below; with
//! [`ConstrainedOptions::lagrangian_hessian`] `B` is instead the Hessian of the Lagrangian
//! `∇²J - Σ_k λ_k ∇²d_k` made semidefinite by `ρ J_Aᵀ J_A` on the active constraints
//! (Newton's step on their tangent space; after a rejected step the next QP falls back to
//! `∇²J`). Measured on the shared geometries (BENCHMARKS.md) the Lagrangian model stalls
//! where hundreds of the coefficient constraints are active at once (more than there are
//! unknowns: the multipliers are not unique), so it is not the default. The step is
//! judged by the
//! //! ℓ₁ merit function `φ = J + μ Σ_k max(0, ε - d_k)`, `μ >= 2 max λ` (Fletcher's Sℓ₁QP):
//! accepted when the actual decrease of `φ` is at least a hundredth of the decrease the
//! model predicts, and never when a coefficient `d_k` becomes non-positive (every
//! accepted iterate has `det J > 0`) or `J` is infinite (Winslow at a fold). The radius
//! shrinks to half the step below a ratio `1/4` and doubles above `3/4` with the step on
//! the boundary. The iteration has converged when the predicted decrease is below
//! `tol |J|`. Unknowns are scaled by the control net's diameter, `d` by the mean `det J`
//! and `J` by its value at the start, so the QP data are of order one.

use std::sync::Arc;
use std::time::Instant;

use super::feasible::{climb, RADIUS_MAX, RADIUS_MIN};
use super::qp;
use super::{min_of, ConstrainedOptions, Constraints, Functional, OptimiseReport, Optimised};
use crate::discrete::assembly::Discretization;
use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;
use crate::methods::DiscreteProblem;
use crate::spline::curve::Point;

/// Largest number of unknowns (the Hessian is made definite by a dense eigendecomposition).
pub const MAX_UNKNOWNS: usize = 3000;

/// Minimise `functional` over the free control points of `disc` subject to
/// `d(c) >= ε` (`ε = opts.eps` times the mean `det J`), from the control points `start`
/// (made feasible first by [`super::max_z`] with target `ε` when some `d_k < ε`).
pub fn optimise(
    disc: &Arc<Discretization>,
    start: &[Point],
    functional: Functional,
    opts: &ConstrainedOptions,
) -> Result<Optimised> {
    let t0 = Instant::now();
    let n = 2 * disc.dofs.num_free();
    if n > MAX_UNKNOWNS {
        return Err(Error::TooLarge {
            context: "constrained optimisation".into(),
            what: "unknowns".into(),
            found: n,
            limit: MAX_UNKNOWNS,
        });
    }
    let cons = Constraints::new(disc, start)?;
    let (scale_d, scale_c) = (cons.mean, cons.diameter);
    let eps = opts.eps * scale_d;
    let mut report = OptimiseReport {
        name: functional.name(),
        functional,
        restoration: None,
        iterations: 0,
        accepted: 0,
        converged: false,
        why: String::new(),
        eps: opts.eps,
        objective_history: Vec::new(),
        min_coefficient: f64::NAN,
        seconds: 0.0,
    };
    let finish = |mut r: OptimiseReport, cps: Vec<Point>, why: String, ok: bool| {
        r.min_coefficient = min_of(&cons.values(&cps)) / scale_d;
        r.why = why;
        r.converged = ok;
        r.seconds = t0.elapsed().as_secs_f64();
        Optimised { report: r, control_points: cps }
    };
    let mut cps = start.to_vec();
    if min_of(&cons.values(&cps)) < eps || cons.boundary_obstruction().is_some() {
        let z = climb(&cons, cps, opts.eps, opts);
        cps = z.control_points;
        let (ok, why) = (z.report.converged, z.report.why.clone());
        report.restoration = Some(z.report);
        if !ok {
            return Ok(finish(report, cps, format!("no start with d >= eps: {why}"), false));
        }
    }
    let method = functional.method();
    let mut prob = method.problem(disc.clone(), cps.clone());
    let dofs = &disc.dofs;
    let mut c = dofs.gather(&cps);
    let Some(mut f) = prob.objective(&c) else {
        return Err(Error::Invalid(format!("{} is not a minimization method", method.name())));
    };
    if !f.is_finite() {
        return Ok(finish(report, cps, format!("the {} functional is infinite at the start", method.name()), false));
    }
    report.objective_history.push(f);
    let scale_f = f.abs().max(f64::MIN_POSITIVE);
    let (mut grad, mut hess) = derivatives(&mut *prob, &c);
    let mut d = cons.values(&cps);
    let mut jac = cons.jacobian(&cps);
    let mut lambda = vec![0.0; d.len()];
    let (mut mu, mut radius) = (scale_f / scale_d, opts.radius);
    let mut last_failure: Option<String> = None;
    let mut lagrangian_model = opts.lagrangian_hessian;
    let s = scale_c / scale_d;
    loop {
        if report.iterations >= opts.max_iterations {
            let why = format!("{} iterations without meeting the stopping rule", report.iterations);
            return Ok(finish(report, cps, why, false));
        }
        if radius < RADIUS_MIN {
            let why = format!(
                "the trust region collapsed{}",
                last_failure.as_ref().map(|e| format!(" (last subproblem: {e})")).unwrap_or_default()
            );
            return Ok(finish(report, cps, why, false));
        }
        // B: ∇²J (absolute eigenvalues), or ∇²J - Σ λ_k ∇²d_k made definite; scaled
        let mut dense = vec![0.0; n * n];
        let add = |m: &Csr, sign: f64, dense: &mut Vec<f64>| {
            for r in 0..m.nrows {
                for (col, v) in m.row(r) {
                    dense[r * n + col] += sign * v * scale_c * scale_c / scale_f;
                }
            }
        };
        add(&hess, 1.0, &mut dense);
        let functional_only = dense.clone();
        add(&cons.weighted_hessian(&lambda), -1.0, &mut dense);
        let rows: Vec<Vec<(usize, f64)>> =
            (0..jac.nrows).map(|r| jac.row(r).map(|(col, v)| (col, -v * s)).collect()).collect();
        // the constraints the last multipliers call active
        let lmax = lambda.iter().copied().fold(0.0, f64::max);
        let active: Vec<&Vec<(usize, f64)>> =
            rows.iter().zip(&lambda).filter(|(_, &l)| lmax > 0.0 && l > 1e-6 * lmax).map(|(r, _)| r).collect();
        let lagrangian = if lagrangian_model { definite_model(n, dense, &active)? } else { None };
        let used_lagrangian = lagrangian.is_some();
        let b = match lagrangian {
            Some(b) => b,
            None => {
                let (u, s) = eigen(n, &symmetric(n, functional_only))?;
                rebuild(n, &u, &s, true)
            }
        };
        let p_model = qp::upper_csc(n, &b);
        let q: Vec<f64> = grad.iter().map(|g| g * scale_c / scale_f).collect();
        let g = Csr::from_rows(n, rows);
        // d_k + ∇d_k δ >= ε; where a violated constraint cannot reach ε in the trust
        // region, >= min(ε, d_k) (no worse)
        report.iterations += 1;
        let mut sol = None;
        for relaxed in [false, true] {
            let h: Vec<f64> = d.iter().map(|&dk| (dk - if relaxed { eps.min(dk) } else { eps }) / scale_d).collect();
            match qp::solve(Some(p_model.clone()), &q, &g, &h, radius, n) {
                Ok(x) => {
                    sol = Some(x);
                    break;
                }
                Err(e) => last_failure = Some(e.0),
            }
        }
        let Some(sol) = sol else {
            radius *= 0.25;
            continue;
        };
        let x = &sol.x;
        let step = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // multipliers of this QP: the next model's, if its step is accepted
        let lambda_qp: Vec<f64> = sol.lambda.iter().map(|l| l.max(0.0) * scale_f / scale_d).collect();
        mu = mu.max(2.0 * lambda_qp.iter().copied().fold(0.0, f64::max));
        let bx: Vec<f64> = (0..n).map(|i| (0..n).map(|j| b[i * n + j] * x[j]).sum()).collect();
        let model: f64 =
            q.iter().zip(x).map(|(a, b)| a * b).sum::<f64>() + 0.5 * bx.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
        let delta: Vec<f64> = x.iter().map(|v| v * scale_c).collect();
        let jd = jac.apply(&delta);
        let viol = |d: &[f64]| d.iter().map(|&dk| (eps - dk).max(0.0)).sum::<f64>();
        let viol_now = viol(&d);
        let viol_lin: f64 = d.iter().zip(&jd).map(|(dk, j)| (eps - dk - j).max(0.0)).sum();
        // (the QP meets its constraints to its own tolerance: a violation it adds is noise)
        let pred = -model * scale_f + mu * (viol_now - viol_lin).max(0.0);
        if pred <= opts.tol * f.abs() {
            let why =
                format!("predicted decrease {pred:.2e} <= {:.0e} |J| (step {step:.2e} of the diameter)", opts.tol);
            return Ok(finish(report, cps, why, true));
        }
        // the trial point: (unknowns, control points, d, J, ratio of actual to predicted decrease)
        let evaluate = |delta: &[f64], prob: &mut Box<dyn DiscreteProblem + Send>| {
            let trial_c: Vec<f64> = c.iter().zip(delta).map(|(a, b)| a + b).collect();
            let mut trial = cps.clone();
            dofs.scatter(&trial_c, &mut trial);
            let dt = cons.values(&trial);
            let ft = if min_of(&dt) > 0.0 { prob.objective(&trial_c).unwrap_or(f64::INFINITY) } else { f64::INFINITY };
            let rho = if ft.is_finite() { (f + mu * viol_now - ft - mu * viol(&dt)) / pred } else { -1.0 };
            (trial_c, trial, dt, ft, rho)
        };
        let (mut trial_c, mut trial, mut dt, mut ft, mut rho) = evaluate(&delta, &mut prob);
        if rho < 0.25 && viol(&dt) > viol_lin {
            // second-order correction: the same QP with the constraints shifted by the
            // exact remainder r = d(c + δ) - d - ∇d δ (d is bilinear: r is the coefficients
            // of the map δ), so that its step δ' keeps d(c + δ') >= ε to third order
            let h: Vec<f64> = dt.iter().zip(&jd).map(|(t, j)| (t - j - eps) / scale_d).collect();
            report.iterations += 1;
            if let Ok(sol) = qp::solve(Some(p_model.clone()), &q, &g, &h, radius, n) {
                let delta2: Vec<f64> = sol.x.iter().map(|v| v * scale_c).collect();
                let second = evaluate(&delta2, &mut prob);
                if second.4 > rho {
                    (trial_c, trial, dt, ft, rho) = second;
                }
            }
        }
        if rho < 0.25 {
            radius = 0.5 * step.min(radius);
        } else if rho > 0.75 && step >= 0.9 * radius {
            radius = (2.0 * radius).min(RADIUS_MAX);
        }
        // a rejected step of the Lagrangian model: the next QP has the functional's Hessian
        lagrangian_model = opts.lagrangian_hessian && (rho > 0.01 || !used_lagrangian);
        if rho > 0.01 {
            c = trial_c;
            cps = trial;
            f = ft;
            d = dt;
            (grad, hess) = derivatives(&mut *prob, &c);
            jac = cons.jacobian(&cps);
            lambda = lambda_qp;
            report.accepted += 1;
            report.objective_history.push(f);
        }
    }
}

/// `∇J` and `∇²J` at `c` (the problem presents `-∇J` and `-∇²J`).
fn derivatives(prob: &mut dyn DiscreteProblem, c: &[f64]) -> (Vec<f64>, Csr) {
    let mut g = vec![0.0; c.len()];
    let mut h = Csr::default();
    prob.jacobian(c, &mut g, &mut h);
    g.iter_mut().for_each(|v| *v = -*v);
    h.values.iter_mut().for_each(|v| *v = -*v);
    (g, h)
}

/// A positive semidefinite model Hessian from the Lagrangian Hessian `a` (dense,
/// row-major, `n x n`): `a + ρ J_Aᵀ J_A` with the rows `J_A` of the active constraints and
/// the smallest `ρ` of `0, ρ₀, 10 ρ₀, ..., 10⁸ ρ₀` that makes it semidefinite (it equals
/// `a` on the tangent space `J_A δ = 0`, so the SQP step stays Newton's there, Finsler's
/// lemma giving such a `ρ` when the reduced Hessian is definite), eigenvalues floored at
/// `10⁻⁸` of the largest magnitude; `None` when no `ρ` does.
fn definite_model(n: usize, a: Vec<f64>, active: &[&Vec<(usize, f64)>]) -> Result<Option<Vec<f64>>> {
    let a = symmetric(n, a);
    let mut jtj = vec![0.0; n * n];
    for row in active {
        for &(i, vi) in row.iter() {
            for &(j, vj) in row.iter() {
                jtj[i * n + j] += vi * vj;
            }
        }
    }
    let diag_max = |m: &[f64]| (0..n).fold(0.0f64, |x, i| x.max(m[i * n + i].abs()));
    let rho0 = if active.is_empty() {
        0.0
    } else {
        diag_max(&a).max(f64::MIN_POSITIVE) / diag_max(&jtj).max(f64::MIN_POSITIVE)
    };
    for k in 0..10 {
        let rho = if k == 0 { 0.0 } else { rho0 * 10f64.powi(k - 1) };
        if k > 0 && rho0 == 0.0 {
            break;
        }
        let m: Vec<f64> = a.iter().zip(&jtj).map(|(x, y)| x + rho * y).collect();
        let (u, s) = eigen(n, &m)?;
        let largest = s.iter().fold(0.0f64, |x, v| x.max(v.abs()));
        if s.iter().all(|&v| v >= -1e-10 * largest) {
            return Ok(Some(rebuild(n, &u, &s, false)));
        }
    }
    Ok(None)
}

/// The symmetric part of the dense `n x n` matrix `a`.
fn symmetric(n: usize, mut a: Vec<f64>) -> Vec<f64> {
    for i in 0..n {
        for j in 0..i {
            let v = 0.5 * (a[i * n + j] + a[j * n + i]);
            a[i * n + j] = v;
            a[j * n + i] = v;
        }
    }
    a
}

/// Eigenvectors (column-major `n x n`) and eigenvalues of the symmetric `m`.
fn eigen(n: usize, m: &[f64]) -> Result<(Vec<f64>, Vec<f64>)> {
    let mat = faer::Mat::<f64>::from_fn(n, n, |i, j| m[i * n + j]);
    let evd = mat
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| Error::LinearSolver(format!("eigendecomposition of the Lagrangian Hessian: {e:?}")))?;
    let (u, s) = (evd.U(), evd.S().column_vector());
    Ok(((0..n * n).map(|k| u[(k % n, k / n)]).collect(), (0..n).map(|i| s[i]).collect()))
}

/// `U f(Λ) Uᵀ` with `f(λ) = max(λ, floor)` (or `max(|λ|, floor)` when `absolute`), `floor`
/// `10⁻⁸` of the largest magnitude.
fn rebuild(n: usize, u: &[f64], s: &[f64], absolute: bool) -> Vec<f64> {
    let largest = s.iter().fold(0.0f64, |x, v| x.max(v.abs()));
    let floor = (1e-8 * largest).max(f64::MIN_POSITIVE);
    let w = faer::Mat::<f64>::from_fn(n, n, |i, j| {
        let l = if absolute { s[j].abs() } else { s[j] };
        u[j * n + i] * l.max(floor).sqrt()
    });
    let p = &w * w.transpose();
    (0..n * n).map(|k| p[(k / n, k % n)]).collect()
}
