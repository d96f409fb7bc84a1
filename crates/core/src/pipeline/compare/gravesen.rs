//! Gravesen's methods as contenders of the comparison (paper §10.3, Table 3), on the
//! EGG run's basis:
//!
//! * [`MaxZRun`]: the feasible start of eq. (49), `max z` subject to `d(c) >= z 1`, from
//!   the Coons patch of the basis (the start of EGG and the other methods with one
//!   level), stopped as soon as `z > 0`; IT counts its LP subproblems.
//! * [`ConstrainedRun`]: the Liao, Winslow (eq. 16) or area-orthogonality functional
//!   minimised subject to `d(c) >= ε` from the EGG map `x_G` (start G, as
//!   `winslow optimise --from egg`); IT counts the QP subproblems of the SQP and the LPs of
//!   a feasibility restoration, if `x_G` needed one.
//!
//! `d(c)` are the Bernstein coefficients of `det J` ([`constrained`]): they need a
//! polynomial (B-spline) basis, and the SQP's Hessian is dense, so a rational basis or
//! one over [`constrained::MAX_UNKNOWNS`] unknowns is refused with the reason (an error
//! row of the comparison, no map). The verdict of a row is the comparison's certificate,
//! as for every method.

use super::{CompareContext, Contender, MethodRun};
use crate::error::{Error, Result};
use crate::solve::constrained::{self, ConstrainedOptions, Functional, Outcome, StartFrom};
use crate::solve::solver::Event;
use crate::spline::surface::Surface;

/// Eq. (49) alone from the Coons patch of the EGG basis (see the module documentation).
#[derive(Debug, Clone, Copy, Default)]
pub struct MaxZRun;

/// The constrained optimisation of `functional` from the EGG map (see the module
/// documentation).
#[derive(Debug, Clone)]
pub struct ConstrainedRun {
    name: String,
    functional: Functional,
}

impl ConstrainedRun {
    /// A run called `name` minimising `functional`.
    pub fn new(name: &str, functional: Functional) -> Self {
        Self { name: name.to_string(), functional }
    }
}

/// The EGG map of the context, checked to be polynomial: the basis of Gravesen's methods.
fn egg_map<'a>(ctx: &'a CompareContext<'_>, method: &str) -> Result<&'a Surface> {
    let reference = ctx
        .reference
        .ok_or_else(|| Error::Invalid(format!("not run: {method} needs the EGG run (x_G) for its basis")))?;
    if reference.map.weights.is_some() {
        return Err(Error::Invalid(format!(
            "not run: the EGG basis is rational (the input's NURBS basis) and {method} needs a polynomial one (det J's \
             Bernstein coefficients are bilinear in the control points only for B-splines): pass --basis fitted"
        )));
    }
    Ok(&reference.map)
}

/// Gravesen's options with the comparison's certificate options.
fn options(ctx: &CompareContext<'_>) -> ConstrainedOptions {
    ConstrainedOptions { certify: ctx.options.solve.certify, ..ctx.options.constrained }
}

/// The run of an [`Outcome`]: its iterations, stopping rule, map and the notes of the
/// stages that ran (a stage that stopped before its first subproblem is in the failure).
fn run_of(name: &str, o: Outcome, mut notes: Vec<String>) -> MethodRun {
    if let Some(z) = o.max_z.as_ref().filter(|z| z.converged || z.iterations > 0) {
        notes.push(format!(
            "max-z from the Coons patch: {} LPs, z {:.3e} -> {:.3e} of the mean det J ({})",
            z.iterations,
            z.z_history.first().copied().unwrap_or(f64::NAN),
            z.z_history.last().copied().unwrap_or(f64::NAN),
            z.why
        ));
    }
    if let Some(p) = &o.optimisation {
        if let Some(z) = p.restoration.as_ref().filter(|z| z.converged || z.iterations > 0) {
            notes.push(format!("restoration of x_G to d >= eps: {} LPs ({})", z.iterations, z.why));
        }
    }
    if let Some(p) = o.optimisation.as_ref().filter(|p| p.converged || p.iterations > 0) {
        notes.push(format!(
            "SQP: {} QPs, {} accepted, {} {:.6e} -> {:.6e}; {}; min coefficient {:.3e} of the mean det J (eps {:.1e})",
            p.iterations,
            p.accepted,
            p.functional.name(),
            p.objective_history.first().copied().unwrap_or(f64::NAN),
            p.objective_history.last().copied().unwrap_or(f64::NAN),
            p.why,
            p.min_coefficient,
            p.eps
        ));
    }
    MethodRun {
        method: name.to_string(),
        iterations: o.iterations,
        converged: o.converged,
        failure: (!o.converged).then(|| o.why.clone()),
        map: o.map,
        seconds: o.seconds,
        notes,
    }
}

impl Contender for MaxZRun {
    fn name(&self) -> &str {
        "maxz"
    }

    fn run(&self, ctx: &CompareContext<'_>, _: &mut dyn FnMut(&Event) -> bool) -> Result<Option<MethodRun>> {
        let egg = egg_map(ctx, self.name())?;
        let o = constrained::run_max_z(egg, &ctx.options.solve.topology, &options(ctx))?;
        Ok(Some(run_of(self.name(), o, Vec::new())))
    }
}

impl Contender for ConstrainedRun {
    fn name(&self) -> &str {
        &self.name
    }

    fn run(&self, ctx: &CompareContext<'_>, _: &mut dyn FnMut(&Event) -> bool) -> Result<Option<MethodRun>> {
        let egg = egg_map(ctx, &self.name)?;
        let topology = &ctx.options.solve.topology;
        let unknowns = 2 * constrained::discretization(egg, topology)?.dofs.num_free();
        if unknowns > constrained::MAX_UNKNOWNS {
            return Err(Error::Invalid(format!(
                "not run: {unknowns} unknowns, over the {} of the constrained optimisation (its QP Hessian is made \
                 definite densely): coarsen the basis (--fit-tol, --min-elements)",
                constrained::MAX_UNKNOWNS
            )));
        }
        let o = constrained::run(egg, StartFrom::Egg, self.functional, topology, &options(ctx))?;
        let from = format!("from x_G (the EGG map), {} subject to d(c) >= eps", self.functional.name());
        Ok(Some(run_of(&self.name, o, vec![from])))
    }
}
