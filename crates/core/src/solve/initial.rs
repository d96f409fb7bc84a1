//! Initial guesses (paper §6.3, §9): transfinite (Coons) interpolation of the boundary
//! control points on the coarsest level, and prolongation plus a linear-elasticity
//! correction of the boundary discrepancy on finer levels, with a continuation in the
//! boundary displacement when that guess is not positive.

use std::sync::Arc;

use super::fixed_basis::FixedBasisSolve;
use super::newton::NonlinearOptions;
use crate::discrete::assembly::Discretization;
use crate::discrete::stencil::{Stencil32, StencilOperator};
use crate::error::{Error, Result};
use crate::linalg::linsolve::{LinearMethod, LinearSolver};
use crate::methods::egg::{CpuAssembler, EggAssembler};
use crate::methods::Method;
use crate::spline::curve::{Curve, Point};
use crate::spline::surface::{Side, Surface};

/// Write the four side curves' control points into the boundary positions of a
/// control net of shape `shape`. The curves must live on the net's knot vectors. When
/// west and east live on a periodic vector (a ring, §11.1), `eta` is periodic: south and
/// north are no boundary and are skipped.
pub(crate) fn set_boundary(shape: [usize; 2], sides: &[Curve; 4], cps: &mut [Point]) -> Result<()> {
    let eta_periodic = sides[Side::West as usize].knots.is_periodic();
    for s in Side::ALL {
        if eta_periodic && s.direction() == 0 {
            continue;
        }
        let idx = Surface::side_indices(shape, s);
        let c = &sides[s as usize];
        if c.control_points.len() != idx.len() {
            return Err(Error::Invalid(format!(
                "{s} side has {} control points, the basis needs {}",
                c.control_points.len(),
                idx.len()
            )));
        }
        for (k, p) in idx.into_iter().zip(&c.control_points) {
            cps[k] = *p;
        }
    }
    Ok(())
}

/// Discrete Coons patch at the Greville abscissae `(u_i, v_j)`:
/// `c_ij = (1-u) W_j + u E_j + (1-v) S_i + v N_i - [(1-u)(1-v) SW + u(1-v) SE + (1-u)v NW + uv NE]`.
/// Reproduces every bilinear map exactly. With `eta` periodic (a ring) it is the linear
/// interpolation in `xi` between west and east, `c_ij = (1-u) W_j + u E_j`.
pub fn coons(knots: &[crate::spline::knots::KnotVector; 2], sides: &[Curve; 4]) -> Result<Vec<Point>> {
    let shape = [knots[0].num_basis(), knots[1].num_basis()];
    let [nx, ny] = shape;
    let (gu, gv) = (knots[0].greville(), knots[1].greville());
    let (a0, a1) = knots[0].domain();
    if knots[1].is_periodic() {
        let mut cps = vec![[0.0; 2]; nx * ny];
        set_boundary(shape, sides, &mut cps)?;
        let (w, e) = (&sides[Side::West as usize].control_points, &sides[Side::East as usize].control_points);
        for j in 0..ny {
            for i in 1..nx - 1 {
                let u = (gu[i] - a0) / (a1 - a0);
                cps[j * nx + i] = [(1.0 - u) * w[j][0] + u * e[j][0], (1.0 - u) * w[j][1] + u * e[j][1]];
            }
        }
        return Ok(cps);
    }
    let (b0, b1) = knots[1].domain();
    let s = &sides[Side::South as usize].control_points;
    let n = &sides[Side::North as usize].control_points;
    let w = &sides[Side::West as usize].control_points;
    let e = &sides[Side::East as usize].control_points;
    let mut cps = vec![[0.0; 2]; nx * ny];
    set_boundary(shape, sides, &mut cps)?;
    let (sw, se, nw, ne) = (s[0], s[nx - 1], n[0], n[nx - 1]);
    for j in 1..ny - 1 {
        let v = (gv[j] - b0) / (b1 - b0);
        for i in 1..nx - 1 {
            let u = (gu[i] - a0) / (a1 - a0);
            let mut c = [0.0; 2];
            for d in 0..2 {
                c[d] = (1.0 - u) * w[j][d] + u * e[j][d] + (1.0 - v) * s[i][d] + v * n[i][d]
                    - ((1.0 - u) * (1.0 - v) * sw[d] + u * (1.0 - v) * se[d] + (1.0 - u) * v * nw[d] + u * v * ne[d]);
            }
            cps[j * nx + i] = c;
        }
    }
    Ok(cps)
}

/// Unknowns above which the elasticity system is solved by CG ([`LinearMethod::Pcg`]).
pub(crate) const ITERATIVE_ELASTICITY: usize = 20_000;

/// Relative residual of the iterative elasticity solve. The displacement is only an
/// initial guess, and the boundary control points are Dirichlet data set exactly, so
/// this error reaches the interior only.
pub(crate) const ELASTICITY_TOL: f64 = 1e-8;

/// Lamé constants of the elasticity prolongation (E = 1, nu = 0.3).
pub const LAME: (f64, f64) = (0.3 / (1.3 * 0.4), 1.0 / 2.6);

/// Linear-elasticity displacement (§6.3): the interior displacement `u_f` with
/// `K_ff u_f = -K_fb (target - base)_b` on the physical domain of `base`, returned for
/// every control point (the fixed ones carry `target - base`). It is linear in the
/// boundary displacement, so `base + alpha u` moves the boundary by `alpha`.
pub(crate) fn elasticity_displacement(disc: &Discretization, base: &[Point], target: &[Point]) -> Result<Vec<Point>> {
    elasticity_displacement_with(&CpuAssembler, disc, base, target, LinearMethod::Auto)
}

/// [`elasticity_displacement`] with the elasticity operator assembled by `assembler`; under
/// `linear` = [`LinearMethod::Multigrid`] (the level's Newton solver) above
/// [`ITERATIVE_ELASTICITY`] unknowns the system is solved by [`multigrid_elasticity`].
pub(crate) fn elasticity_displacement_with(
    assembler: &dyn EggAssembler,
    disc: &Discretization,
    base: &[Point],
    target: &[Point],
    linear: LinearMethod,
) -> Result<Vec<Point>> {
    let mut diff = vec![[0.0; 2]; base.len()];
    let mut moved = false;
    for k in 0..base.len() {
        if disc.dofs.free_index(k) == crate::discrete::dofs::FIXED {
            diff[k] = [target[k][0] - base[k][0], target[k][1] - base[k][1]];
            moved |= diff[k] != [0.0, 0.0];
        }
    }
    if disc.dofs.num_free() == 0 || !moved {
        return Ok(diff);
    }
    let assemble = || {
        let mut st = vec![0.0; disc.stencil_len(2)];
        assembler.elasticity(disc, base, LAME.0, LAME.1, &mut st);
        st
    };
    let mut st = assemble();
    let rhs: Vec<f64> = disc.apply_to_fixed(&st, &diff).into_iter().map(|v| -v).collect();
    if linear == LinearMethod::Multigrid && rhs.len() > ITERATIVE_ELASTICITY {
        if let Some(u) = multigrid_elasticity(disc, st, &rhs) {
            disc.dofs.scatter(&u, &mut diff);
            return Ok(diff);
        }
        // CG did not converge (or there is no hierarchy): the system again, solved as below
        st = assemble();
    }
    let u = match stencil_elasticity(disc, &st, &rhs) {
        Some(u) => u,
        None => matrix_elasticity(disc, &st, &rhs)?,
    };
    disc.dofs.scatter(&u, &mut diff);
    Ok(diff)
}

/// The elasticity system of stencil storage `st` solved as [`matrix_elasticity`] solves
/// it above [`ITERATIVE_ELASTICITY`] unknowns (block-Jacobi CG), with the product taken
/// from the stencil storage ([`StencilOperator`]: no matrix, no vector pattern) and the
/// diagonal blocks gathered alone: the same iterates bit for bit. `None` below that size,
/// on a basis with periodic replicas, or when CG does not converge (the matrix path
/// then decides).
fn stencil_elasticity(disc: &Discretization, st: &[f64], rhs: &[f64]) -> Option<Vec<f64>> {
    if rhs.len() <= ITERATIVE_ELASTICITY {
        return None;
    }
    let op = StencilOperator::new(disc, 2, st)?;
    let blocks = (0..2).map(|z| disc.stencil_diagonal_block(2, st, z)).collect::<Option<Vec<_>>>()?;
    let mut lin = LinearSolver::new(LinearMethod::Pcg);
    lin.set_ordering(&disc.ordering);
    lin.krylov_tol = ELASTICITY_TOL;
    lin.factor_blocks(&blocks).ok()?;
    lin.solve_operator(&op, rhs).ok()
}

/// The elasticity system of stencil storage `st` solved by CG under `--linear multigrid`
/// (all above [`ITERATIVE_ELASTICITY`] unknowns): the stencil storage rounded to single
/// precision in place ([`Stencil32`]: half its memory) is the operator, and the
/// preconditioner is block Jacobi with a symmetric multigrid V-cycle for each diagonal
/// block (`LinearSolver::factor_block_multigrid`, the blocks gathered one at a time)
/// instead of their Cholesky factors, whose fill grows as `m log m`. The result solves
/// the single-precision system to [`ELASTICITY_TOL`]: an initial guess, whose boundary
/// (the fixed control points) is exact. `None` on a basis without a multigrid hierarchy or
/// when CG does not converge.
fn multigrid_elasticity(disc: &Discretization, st: Vec<f64>, rhs: &[f64]) -> Option<Vec<f64>> {
    let transfers = crate::discrete::transfers::free_prolongation_factors(disc).ok()?;
    if transfers.is_empty() || !disc.dofs.replicas().is_empty() {
        return None;
    }
    let packed = Stencil32::pack(st);
    let mut lin = LinearSolver::new(LinearMethod::Pcg);
    lin.set_transfers(transfers);
    lin.krylov_tol = ELASTICITY_TOL;
    for z in 0..2 {
        lin.factor_block_multigrid(disc.stencil_diagonal_block(2, &packed, z)?).ok()?;
    }
    crate::solve::memory::trace(|| format!("elasticity ({} unknowns): multigrid set up", rhs.len()));
    let op = StencilOperator::new(disc, 2, &packed)?;
    lin.solve_operator(&op, rhs).ok()
}

/// The elasticity system of stencil storage `st` gathered into a matrix and solved.
fn matrix_elasticity(disc: &Discretization, st: &[f64], rhs: &[f64]) -> Result<Vec<f64>> {
    let k = disc.vector.matrix(st);
    // symmetric positive definite: Cholesky, or block-Jacobi CG on large systems (whose
    // vector Cholesky factor costs 8 times a scalar one), with LU/GMRES as a safety net
    let method = if k.nrows > ITERATIVE_ELASTICITY { LinearMethod::Pcg } else { LinearMethod::Cholesky };
    let mut lin = LinearSolver::new(method);
    lin.set_ordering(&disc.ordering);
    lin.krylov_tol = ELASTICITY_TOL;
    if lin.factor(&k).is_err() {
        lin = LinearSolver::new(LinearMethod::Auto);
        lin.factor(&k)?;
    }
    lin.solve(rhs)
}

/// `base + alpha u` for a displacement `u` from [`elasticity_displacement`].
pub(crate) fn displaced(base: &[Point], u: &[Point], alpha: f64) -> Vec<Point> {
    base.iter().zip(u).map(|(b, d)| [b[0] + alpha * d[0], b[1] + alpha * d[1]]).collect()
}

/// Linear-elasticity correction (§6.3): move the fixed (boundary) control points of
/// `base` to those of `target` and spread the displacement into the interior
/// ([`elasticity_displacement`]). Returns `base + u`.
pub(crate) fn elasticity_correction(disc: &Discretization, base: &[Point], target: &[Point]) -> Result<Vec<Point>> {
    let u = elasticity_displacement(disc, base, target)?;
    Ok(displaced(base, &u, 1.0))
}

#[cfg(test)]
/// Prolong `coarse` onto the basis of `disc` and correct the boundary discrepancy with
/// linear elasticity (§6.3): with `x_p = P c` and the fitted boundary `b`, the result is
/// [`elasticity_correction`]`(x_p, b)`.
pub(crate) fn elasticity_prolongation(
    coarse: &Surface,
    disc: &Discretization,
    sides: &[Curve; 4],
) -> Result<Vec<Point>> {
    let fine = coarse.refined(&disc.knots)?;
    let mut target = fine.control_points.clone();
    set_boundary(disc.shape(), sides, &mut target)?;
    elasticity_correction(disc, &fine.control_points, &target)
}

/// Bookkeeping of the boundary continuation of one level.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct Continuation {
    /// Damped boundary solves.
    pub steps: usize,
    /// Nonlinear iterations spent in them.
    pub iterations: usize,
}

/// Smallest `det J` on a sample of `2 max(n_xi, n_eta)` points per direction, away
/// from the corners.
pub fn det_j_min(assembler: &dyn EggAssembler, disc: &Discretization, cps: &[Point]) -> f64 {
    let shape = disc.shape();
    let map = Surface { knots: disc.knots.clone(), control_points: cps.to_vec(), weights: disc.weights.clone() };
    assembler.sample_det_j(&map, 2 * shape[0].max(shape[1])).min_interior
}

/// Smallest fraction of the boundary displacement tried in one continuation step.
pub(crate) const MIN_CONTINUATION_STEP: f64 = 1.0 / 64.0;

/// Most damped boundary solves per level.
pub(crate) const MAX_CONTINUATION_STEPS: usize = 24;

/// The outcome of [`continuation_with`].
#[derive(Debug, Clone)]
pub(crate) struct Continued {
    /// The guess with the full target boundary (positive unless the steps ran out).
    pub guess: Vec<Point>,
    /// The last positive map reached (the start, or the solution of the last damped
    /// solve that succeeded), whose boundary is moved by `alpha` of the way.
    pub base: Vec<Point>,
    /// The fraction of the boundary displacement `base` has reached.
    pub alpha: f64,
}

/// Initial guess of a finer level (§6.3, §9): the elasticity correction of the
/// prolonged map `base` towards the fitted boundary `target`. When that guess is not
/// `positive` (the sampled `det J` of a level, [`det_j_min`]; the certificate for the
/// `C^0` route of §9, whose Winslow solves need a bijective start), the boundary
/// displacement is damped by `alpha < 1`, the equations are solved with the damped
/// boundary from the (positive) elasticity guess, and the remaining displacement is
/// applied from that solution, until the target contour is reached (at most
/// [`MAX_CONTINUATION_STEPS`] damped solves, steps no shorter than
/// [`MIN_CONTINUATION_STEP`]). Also returns the last positive map reached, from which a
/// caller may go on on a refined basis.
///
/// `method` poses the damped solves, `assembler` assembles the elasticity operator; `nl`
/// are the level's nonlinear options (scaled as the level's final solve), `diameter` the
/// domain's.
pub(crate) fn continuation_with(
    method: &dyn Method,
    assembler: &dyn EggAssembler,
    disc: &Arc<Discretization>,
    base: Vec<Point>,
    target: &[Point],
    nl: NonlinearOptions,
    diameter: f64,
    cont: &mut Continuation,
    positive: &dyn Fn(&[Point]) -> bool,
) -> Result<Continued> {
    let tol = 1e-12 * diameter;
    if base.iter().zip(target).all(|(b, t)| (b[0] - t[0]).abs() <= tol && (b[1] - t[1]).abs() <= tol) {
        // same boundary (e.g. a refinement of the previous level): nothing to move
        return Ok(Continued { guess: base.clone(), base, alpha: 1.0 });
    }
    let mut base = base;
    let (mut done, mut step) = (0.0f64, 1.0f64);
    // displacement from `base` to the full target; linear in the boundary motion, so
    // a fraction `f` of the remaining motion is `f * u`
    let mut u = elasticity_displacement_with(assembler, disc, &base, target, nl.linear)?;
    if !positive(&base) {
        // the prolonged map itself is not positive on this level's (denser) sample:
        // damping the boundary motion cannot make the guess positive, Newton starts
        // from the full elasticity guess
        return Ok(Continued { guess: displaced(&base, &u, 1.0), base, alpha: 0.0 });
    }
    loop {
        let a = (done + step).min(1.0);
        let f = (a - done) / (1.0 - done);
        let guess = displaced(&base, &u, f);
        let guess_positive = positive(&guess);
        let exhausted = step <= MIN_CONTINUATION_STEP || cont.steps >= MAX_CONTINUATION_STEPS;
        if a >= 1.0 && (guess_positive || exhausted) {
            return Ok(Continued { guess, base, alpha: done });
        }
        if !guess_positive && !exhausted {
            step *= 0.5;
            continue;
        }
        // solve with the damped boundary
        let solved = FixedBasisSolve::new(method, disc.clone(), guess.clone(), nl).finish()?;
        cont.steps += 1;
        // a minimisation only lowers its objective from a feasible start: a positive
        // result is a better base even before its stopping rule is met
        let converged = solved.converged() || solved.objective.is_some_and(f64::is_finite);
        let sol = solved.control_points;
        cont.iterations += solved.history.iterations;
        if converged && positive(&sol) {
            base = sol;
            done = a;
            step = (2.0 * step).min(1.0 - done).max(MIN_CONTINUATION_STEP);
            u = elasticity_displacement_with(assembler, disc, &base, target, nl.linear)?;
        } else if exhausted {
            // out of steps: the full boundary from the last positive map (the damped
            // guess would carry a wrong boundary into the level's solve)
            return Ok(Continued { guess: displaced(&base, &u, 1.0), base, alpha: done });
        } else {
            step *= 0.5;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    #[test]
    fn coons_reproduces_bilinear_maps() {
        let k = [KnotVector::open_uniform(3, 4), KnotVector::open_uniform(2, 3)];
        let f = |u: f64, v: f64| [1.0 + 2.0 * u + 0.3 * v + 0.5 * u * v, -1.0 + 0.2 * u + 1.7 * v - 0.4 * u * v];
        let (gu, gv) = (k[0].greville(), k[1].greville());
        let mk = |dir: usize, fixed: f64| {
            let g = if dir == 0 { &gu } else { &gv };
            let pts = g.iter().map(|&t| if dir == 0 { f(t, fixed) } else { f(fixed, t) }).collect();
            Curve::polynomial(k[dir].clone(), pts)
        };
        let sides = [mk(0, 0.0), mk(1, 1.0), mk(0, 1.0), mk(1, 0.0)];
        let cps = coons(&k, &sides).unwrap();
        let nx = gu.len();
        for (j, &v) in gv.iter().enumerate() {
            for (i, &u) in gu.iter().enumerate() {
                let e = f(u, v);
                let c = cps[j * nx + i];
                assert!((c[0] - e[0]).abs() < 1e-14 && (c[1] - e[1]).abs() < 1e-14);
            }
        }
    }

    /// Linear elasticity reproduces affine displacements exactly (constant strain, so
    /// `div sigma = 0`): prolonging an affine map `A` onto a finer basis whose boundary is
    /// that of another affine map `B` gives `B` itself.
    #[test]
    fn elasticity_prolongation_reproduces_affine_maps() {
        let coarse_k = [KnotVector::open_uniform(3, 2), KnotVector::open_uniform(3, 2)];
        let fine_k = [coarse_k[0].halved().halved(), coarse_k[1].halved()];
        let affine = |m: [f64; 6], k: &[KnotVector; 2]| -> Vec<Point> {
            let (gu, gv) = (k[0].greville(), k[1].greville());
            gv.iter()
                .flat_map(|&v| gu.iter().map(move |&u| [m[0] + m[1] * u + m[2] * v, m[3] + m[4] * u + m[5] * v]))
                .collect()
        };
        let a = [0.0, 2.0, 0.3, 1.0, -0.2, 1.5];
        let b = [0.1, 2.4, 0.1, 0.9, 0.3, 1.2];
        let coarse = Surface {
            knots: coarse_k,
            control_points: affine(a, &[KnotVector::open_uniform(3, 2), KnotVector::open_uniform(3, 2)]),
            weights: None,
        };
        let target = Surface { knots: fine_k.clone(), control_points: affine(b, &fine_k), weights: None };
        let sides = Side::ALL.map(|s| target.boundary(s));
        let disc = Discretization::new(fine_k);
        let cps = elasticity_prolongation(&coarse, &disc, &sides).unwrap();
        for (c, t) in cps.iter().zip(&target.control_points) {
            assert!((c[0] - t[0]).abs() < 1e-12 && (c[1] - t[1]).abs() < 1e-12, "{c:?} vs {t:?}");
        }
    }
}
