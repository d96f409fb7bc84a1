//! The previous map of a shape family as the start of the next shape (issue 34; the
//! time extrapolation of [`crate::pipeline::sweep`] at order zero, for four-sided
//! boundaries): a family of boundaries that differ by parameters (shape optimisation,
//! data sets) is solved on the basis of the previous shape's map, from that map moved
//! onto the new boundary, instead of coarse to fine from a Coons patch.
//!
//! With `x⁻` the previous map (control points `c⁻` on the basis `Ξ × H`) and the new
//! boundary's sides refined onto `Ξ` and `H` by knot insertion (exact: the new map's
//! boundary is the input's), the start is the linear-elasticity correction of §6.3,
//! `c⁰ = c⁻ + u` with `K_ff u_f = -K_fb (b - c⁻)_b` (`elasticity_correction`); from
//! there EGG (eq. 8) runs on the fixed basis as a sweep frame does (`FixedBasisSolve`
//! on the discretization of the pipeline's levels, [`Discretization::for_topology`],
//! with the options scaled by the map's size, `scaled_options`), so that on the same
//! basis the result is the cold solve's map within the solver's tolerance. The map is
//! certified; the options' improvement (`--improve`) follows as after a cold solve
//! ([`improve`], kept only when certified).
//!
//! A shape the warm start does not apply to ([`Warm::Cold`]: a rational map, a side that
//! is a point cloud or whose knots are not in the previous basis, a solve that did not
//! converge, a map the certificate does not prove bijective) is the caller's to solve
//! cold ([`crate::Pipeline`]); the reason says which.

use std::time::Instant;

use serde::Serialize;

use std::sync::Arc;

use super::fixed_basis::{bijective, scaled_options, FixedBasisSolve};
use super::improve::{improve, Improvement};
use super::initial::{elasticity_correction, set_boundary};
use super::options::SolveOptions;
use super::report::{Verdict, WarmNote};
use crate::boundary::{Boundary, SideCurve};
use crate::discrete::assembly::Discretization;
use crate::error::Result;
use crate::methods::egg::EggMethod;
use crate::spline::curve::Curve;
use crate::spline::surface::{Side, Surface};
use crate::verify::certificate::{certify, Certificate};
use crate::verify::quality::{quality, Quality};

/// A shape solved from the previous shape's map.
#[derive(Debug, Clone, Serialize)]
pub struct WarmStart {
    /// The map (on the previous map's basis).
    #[serde(skip)]
    pub map: Surface,
    /// `{"used": true}`.
    pub warm_start: WarmNote,
    /// `"certified"` or `"degenerate-corner"` (a warm start is kept only when bijective).
    pub verdict: Verdict,
    /// The certificate's message and the solve's.
    pub message: String,
    /// The certificate of the map.
    pub certificate: Certificate,
    /// Cell quality of the map.
    pub quality: Quality,
    /// The EGG solve from the start (the previous map moved onto the new boundary).
    pub solve: WarmSolve,
    /// The options' improvement after it (`--improve`), when asked for.
    pub improvement: Option<Improvement>,
    /// Unknowns of the solve (two per free control point).
    pub unknowns: usize,
    /// Basis functions per direction.
    pub shape: [usize; 2],
    /// Wall seconds (start, solve, certificates).
    pub seconds: f64,
}

/// The EGG solve of a warm start.
#[derive(Debug, Clone, Serialize)]
pub struct WarmSolve {
    /// Nonlinear iterations.
    pub iterations: usize,
    /// Of those, Newton steps.
    pub newton_iterations: usize,
    /// `|F|` at the start and at the result.
    pub residual_before: f64,
    /// `|F|` at the result.
    pub residual_after: f64,
    /// Largest control point displacement from the start, relative to the diameter.
    pub max_displacement: f64,
    /// Seconds of the elasticity start and the solve.
    pub seconds: f64,
}

/// The outcome of [`warm_start`].
#[derive(Debug, Clone)]
pub enum Warm {
    /// Solved from the previous map.
    Solved(Box<WarmStart>),
    /// Not applicable or not kept: solve this shape cold; why.
    Cold(String),
}

/// The new boundary's sides on the basis of `prev` (knot insertion), or why not.
fn sides_on(prev: &Surface, boundary: &Boundary) -> std::result::Result<[Curve; 4], String> {
    let mut out = Vec::with_capacity(4);
    for s in Side::ALL {
        let c = match boundary.side(s) {
            SideCurve::Spline(c) => c.normalized(),
            _ => return Err(format!("the {s} side is not a spline curve")),
        };
        if c.weights.is_some() {
            return Err(format!("the {s} side is rational"));
        }
        let fine = &prev.knots[s.direction()];
        let c = c.refined(fine).map_err(|e| format!("the {s} side is not on the previous map's basis: {e}"))?;
        out.push(c);
    }
    out.try_into().map_err(|_| "four sides".to_string())
}

/// Solve the shape of `boundary` from `prev`, the map of the previous shape of its family
/// (see the module documentation), with the nonlinear, certificate, operator and
/// improvement options of `opts`.
pub fn warm_start(prev: &Surface, boundary: &Boundary, opts: &SolveOptions) -> Result<Warm> {
    let t0 = Instant::now();
    if prev.weights.is_some() {
        return Ok(Warm::Cold("the previous map is rational".into()));
    }
    if opts.topology.eta_periodic() {
        return Ok(Warm::Cold("a ring is solved cold".into()));
    }
    let sides = match sides_on(prev, boundary) {
        Ok(s) => s,
        Err(why) => return Ok(Warm::Cold(why)),
    };
    let shape = prev.shape();
    let mut target = prev.control_points.clone();
    set_boundary(shape, &sides, &mut target)?;
    let disc = Arc::new(Discretization::for_topology(prev.knots.clone(), &opts.topology)?);
    let start = elasticity_correction(&disc, &prev.control_points, &target)?;
    let diameter = Surface { control_points: start.clone(), ..prev.clone() }.control_diameter();
    let egg = EggMethod::cpu(opts.operator);
    let nl = scaled_options(opts.nonlinear, &egg, diameter, disc.dofs.num_free());
    let solved = FixedBasisSolve::new(&egg, disc.clone(), start.clone(), nl).finish()?;
    if !solved.converged() {
        return Ok(Warm::Cold(format!(
            "the solve from the previous map did not converge ({})",
            solved.failure().unwrap_or("stopped")
        )));
    }
    let h = &solved.history;
    let (before, after) = h.residuals_before_after();
    let max_displacement =
        solved.control_points.iter().zip(&start).fold(0.0f64, |d, (a, b)| d.max((a[0] - b[0]).hypot(a[1] - b[1])))
            / diameter;
    let solve = WarmSolve {
        iterations: h.iterations,
        newton_iterations: h.newton_iterations,
        residual_before: before,
        residual_after: after,
        max_displacement,
        seconds: t0.elapsed().as_secs_f64(),
    };
    let mut map = Surface { control_points: solved.control_points, ..prev.clone() };
    let mut cert = certify(&map, &opts.certify)?;
    if !bijective(&cert) {
        return Ok(Warm::Cold(format!("the map solved from the previous map is not bijective: {}", cert.message())));
    }
    let mut improvement = None;
    if let Some(m) = opts.improve {
        let imp = improve(&map, &cert, &*m.method(), &opts.topology, opts.nonlinear, &opts.certify, diameter)?;
        (map, cert) = (imp.map, imp.certificate);
        improvement = Some(imp.report);
    }
    let verdict = Verdict::of_certificate(&cert);
    let mut message = format!(
        "{}; warm start: EGG from the previous map in {} iterations, |F| {:.3e} -> {:.3e}",
        cert.message(),
        solve.iterations,
        before,
        after
    );
    if let Some(imp) = &improvement {
        message.push_str(&format!("; improvement: {}", imp.message));
    }
    let unknowns = 2 * disc.dofs.num_free();
    Ok(Warm::Solved(Box::new(WarmStart {
        quality: quality(&map),
        map,
        warm_start: WarmNote { used: true, reason: None },
        verdict,
        message,
        certificate: cert,
        solve,
        improvement,
        unknowns,
        shape,
        seconds: t0.elapsed().as_secs_f64(),
    })))
}
