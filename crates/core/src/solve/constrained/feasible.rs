//! Gravesen's feasible start (paper eq. 49): `max z` subject to `d(c) >= z 1`, by
//! sequential linear programming with a trust region.
//!
//! At the iterate `c` with `z(c) = min_k d_k(c)` the LP
//!
//! `max t` subject to `d_k(c) + ∇d_k(c) δ >= t` for every constraint, `|δ_i| <= Δ`,
//!
//! (in units of the mean `det J` for `d` and `t`, of the control net's diameter for `δ`)
//! predicts the gain `t - z`; the step is accepted when the actual gain `z(c + δ) - z(c)`
//! is at least a hundredth of it, and the radius `Δ` shrinks when the ratio is below
//! `1/4` (to half the step) and doubles when it is above `3/4` with the step on the
//! boundary. The iteration stops as soon as `z` exceeds the target, when the LP
//! predicts no gain (a local maximum of `z` below the target), or when the radius
//! collapses.

use std::time::Instant;

use super::qp;
use super::{min_of, ConstrainedOptions, Constraints, MaxZ, MaxZReport};
use crate::discrete::assembly::Discretization;
use crate::error::Result;
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// Largest trust-region radius, relative to the diameter.
pub(super) const RADIUS_MAX: f64 = 1.0;
/// Smallest radius before the iteration gives up.
pub(super) const RADIUS_MIN: f64 = 1e-10;

/// Maximise `z` (eq. 49) over the free control points of `disc` from the control points
/// `start` until `z > target` (relative to the mean `det J`; `0` for a bijective map).
pub fn max_z(disc: &Discretization, start: &[Point], target: f64, opts: &ConstrainedOptions) -> Result<MaxZ> {
    let cons = Constraints::new(disc, start)?;
    Ok(climb(&cons, start.to_vec(), target, opts))
}

/// [`max_z`] on prepared constraints.
pub(super) fn climb(cons: &Constraints, start: Vec<Point>, target: f64, opts: &ConstrainedOptions) -> MaxZ {
    let t0 = Instant::now();
    let (scale_d, scale_c) = (cons.mean, cons.diameter);
    let dofs = &cons.dofs;
    let mut cps = start;
    let mut c = dofs.gather(&cps);
    let n = c.len();
    let mut z = min_of(&cons.values(&cps)) / scale_d;
    let mut report = MaxZReport {
        name: "maxz",
        iterations: 0,
        converged: false,
        why: String::new(),
        target,
        z_history: vec![z],
        seconds: 0.0,
    };
    let finish = |mut r: MaxZReport, cps: Vec<Point>, why: String, ok: bool| {
        r.why = why;
        r.converged = ok;
        r.seconds = t0.elapsed().as_secs_f64();
        MaxZ { report: r, control_points: cps }
    };
    if let Some(why) = cons.boundary_obstruction() {
        return finish(report, cps, why, false);
    }
    if cons.rows.is_empty() {
        let why = "no coefficient depends on the free control points".to_string();
        return finish(report, cps, why, true);
    }
    let mut radius = opts.radius;
    let mut last_failure: Option<String> = None;
    let mut jac: Option<Csr> = None;
    loop {
        if z > target {
            let why = format!("z = {z:.4e} > {target:.1e} (of the mean det J)");
            return finish(report, cps, why, true);
        }
        if report.iterations >= opts.max_z_iterations {
            let why = format!("{} iterations, z = {z:.4e} <= {target:.1e}", report.iterations);
            return finish(report, cps, why, false);
        }
        if radius < RADIUS_MIN {
            let why = format!(
                "the trust region collapsed at z = {z:.4e} <= {target:.1e}{}",
                last_failure.as_ref().map(|e| format!(" (last subproblem: {e})")).unwrap_or_default()
            );
            return finish(report, cps, why, false);
        }
        let d = cons.values(&cps);
        let j = jac.get_or_insert_with(|| cons.jacobian(&cps));
        // G [δ̂; t] <= d̂: rows -Ĵ_k δ̂ + t <= d̂_k
        let s = scale_c / scale_d;
        let rows: Vec<Vec<(usize, f64)>> =
            (0..j.nrows).map(|r| j.row(r).map(|(col, v)| (col, -v * s)).chain([(n, 1.0)]).collect()).collect();
        let g = Csr::from_rows(n + 1, rows);
        let h: Vec<f64> = d.iter().map(|v| v / scale_d).collect();
        let mut q = vec![0.0; n + 1];
        q[n] = -1.0;
        report.iterations += 1;
        let sol = match qp::solve(None, &q, &g, &h, radius, n) {
            Ok(s) => s,
            Err(e) => {
                last_failure = Some(e.0);
                radius *= 0.25;
                continue;
            }
        };
        let pred = sol.x[n] - z;
        if pred <= 1e-12 {
            let why = format!("a local maximum of z (no LP gain): z = {z:.4e} <= {target:.1e}");
            return finish(report, cps, why, false);
        }
        let step = sol.x[..n].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let trial_c: Vec<f64> = c.iter().zip(&sol.x[..n]).map(|(a, b)| a + scale_c * b).collect();
        let mut trial = cps.clone();
        dofs.scatter(&trial_c, &mut trial);
        let zt = min_of(&cons.values(&trial)) / scale_d;
        let rho = (zt - z) / pred;
        if rho < 0.25 {
            radius = 0.5 * step.min(radius);
        } else if rho > 0.75 && step >= 0.9 * radius {
            radius = (2.0 * radius).min(RADIUS_MAX);
        }
        if rho > 0.01 {
            c = trial_c;
            cps = trial;
            z = zt;
            jac = None;
            report.z_history.push(z);
        }
    }
}
