//! `winslow optimise`: the constrained quality optimisation of Gravesen et al. (paper
//! §10.3, Table 3) on the basis of the EGG map: minimise the Liao, Winslow or
//! area-orthogonality functional subject to positive Bernstein coefficients of det J,
//! started from the EGG map (G) or from the max-z point of eq. (49) (Z); or eq. (49)
//! alone (`--maxz-only`).

use std::fmt::Write as _;

use serde::Serialize;

use super::*;
use winslow::methods::egg::CpuAssembler;
use winslow::solve::constrained::{self, ConstrainedOptions, Functional, Outcome, StartFrom};
use winslow::verify::quality::functionals;

#[derive(Args, Debug)]
pub(super) struct OptimiseArgs {
    /// Boundary file (JSON boundary, contour or map document; G+Smo XML).
    boundary: PathBuf,
    /// The functional minimised subject to d(c) >= eps: Liao (int g11^2 + g22^2 + 2 g12^2),
    /// Winslow (eq. 16) or area orthogonality (int g11^2 + g22^2).
    #[arg(long, value_enum, default_value = "liao")]
    functional: Functional,
    /// Start: the EGG map (G), the max-z point of eq. (49) reached from the Coons patch
    /// (Z), or both (one row of the paper's Table 3; -o then writes the result from G).
    #[arg(long, value_enum, default_value = "egg")]
    from: FromArg,
    /// Only eq. (49): maximise z subject to d(c) >= z 1 from the Coons patch, stopped at
    /// z > 0 (a certified start).
    #[arg(long)]
    maxz_only: bool,
    /// eps of the constraints d(c) >= eps, relative to the mean det J.
    #[arg(long, default_value_t = ConstrainedOptions::default().eps)]
    eps: f64,
    /// Most SQP iterations.
    #[arg(long, default_value_t = ConstrainedOptions::default().max_iterations)]
    max_iterations: usize,
    /// Stop when the predicted decrease is below this fraction of the functional.
    #[arg(long, default_value_t = ConstrainedOptions::default().tol)]
    opt_tol: f64,
    /// QP Hessian of the Lagrangian (exact constraint curvature, made semidefinite on the
    /// active constraints) instead of the functional's.
    #[arg(long)]
    lagrangian_hessian: bool,
    /// Output map file (JSON with the report; .xml, .igs, .vtu, .vtk by extension).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Write a picture of the result.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// The EGG solve that gives the basis and start G (`--basis auto` means `fitted`
    /// here: the constraints need a polynomial basis; a coarse --fit-tol keeps the
    /// constraint count small).
    #[command(flatten)]
    solver: SolverArgs,
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
enum FromArg {
    Egg,
    Maxz,
    Both,
}

/// The functionals of a map (`None` where infinite).
#[derive(Debug, Serialize)]
struct Values {
    liao: f64,
    winslow: Option<f64>,
    area_orthogonality: f64,
}

impl Values {
    fn of(map: &Surface) -> Self {
        let f = functionals(map);
        Self {
            liao: f.liao,
            winslow: f.winslow.is_finite().then_some(f.winslow),
            area_orthogonality: f.area_orthogonality,
        }
    }
}

/// One run with the functionals of its start and result.
#[derive(Debug, Serialize)]
struct Row {
    #[serde(flatten)]
    outcome: Outcome,
    start_values: Values,
    values: Values,
}

pub(super) fn run(a: OptimiseArgs) -> Result<i32> {
    let mut opts = a.solver.options()?;
    if opts.fit.basis == BasisChoice::Auto {
        opts.fit.basis = BasisChoice::Fitted;
    }
    if opts.fit.basis == BasisChoice::Input {
        bail!("--basis input may be rational: the det J coefficient constraints need --basis fitted");
    }
    let copts = ConstrainedOptions {
        eps: a.eps,
        max_iterations: a.max_iterations,
        tol: a.opt_tol,
        lagrangian_hessian: a.lagrangian_hessian,
        certify: opts.certify,
        ..Default::default()
    };
    // checked by the core before the EGG solve it starts from
    copts.validate()?;
    let quiet = output::quiet() || a.json;
    crate::files::OutputPlan::new()
        .input(&a.boundary)
        .maybe("-o", a.output.as_deref(), "map", crate::files::ext::MAP)
        .maybe("--png", a.png.as_deref(), "picture", crate::files::ext::PNG)
        .check()?;
    let boundary = load_boundary(&a.boundary, a.solver.fit.reorient)?;
    let sol = solve_cmd::run_pipeline(boundary.clone(), &opts, Arc::new(CpuAssembler), quiet)?.into_map()?;
    let egg = &sol.map;
    let functional = a.functional;
    let starts = match a.from {
        FromArg::Egg => vec![StartFrom::Egg],
        FromArg::Maxz => vec![StartFrom::MaxZ],
        FromArg::Both => vec![StartFrom::Egg, StartFrom::MaxZ],
    };
    let mut rows = Vec::new();
    if a.maxz_only {
        let o = constrained::run_max_z(egg, &opts.topology, &copts).context("eq. (49)")?;
        rows.push(Row { start_values: Values::of(&o.start_map), values: Values::of(&o.map), outcome: o });
    } else {
        for from in starts {
            let o = constrained::run(egg, from, functional, &opts.topology, &copts)
                .with_context(|| format!("constrained optimisation from {}", from.name()))?;
            rows.push(Row { start_values: Values::of(&o.start_map), values: Values::of(&o.map), outcome: o });
        }
    }
    let egg_iterations: usize = sol.report.solve.levels.iter().map(|l| l.iterations).sum();
    let [nx, ny] = egg.shape();
    let unknowns = constrained::discretization(egg, &opts.topology)?.dofs.num_free() * 2;
    let first = &rows[0].outcome;
    let report = serde_json::json!({
        "version": env!("CARGO_PKG_VERSION"),
        "boundary": a.boundary.display().to_string(),
        "basis": [nx, ny],
        "degree": egg.degrees(),
        "unknowns": unknowns,
        "eps": a.eps,
        "egg": {
            "iterations": egg_iterations,
            "verdict": sol.report.outcome.verdict,
            "values": Values::of(egg),
        },
        "runs": &rows,
    });
    if let Some(out) = &a.output {
        let label = format!("{}: {}", first.name, first.certificate.message());
        let extra = Some(serde_json::json!({ "report": report }));
        crate::files::write(out, &Output::Map { name: &sol.name, map: &first.map, label: &label, extra })?;
    }
    if let Some(p) = &a.png {
        crate::files::write(p, &Output::Picture(&render(&first.map, &PictureOptions::default())))?;
    }
    if a.json {
        crate::files::print_json(report)?;
    } else {
        let mut s = format!(
            "{}: {nx}x{ny} basis of degree {:?}, {unknowns} unknowns, eps {:.1e} of the mean det J\n  EGG: {egg_iterations} \
             Newton iterations, {}\n",
            sol.name,
            egg.degrees(),
            a.eps,
            output::verdict_word(sol.report.outcome.verdict)
        );
        for r in &rows {
            row_text(&mut s, r);
        }
        say_raw!("{s}");
    }
    Ok(if rows.iter().all(|r| r.outcome.certified) { 0 } else { 3 })
}

fn row_text(s: &mut String, r: &Row) {
    let o = &r.outcome;
    let _ = writeln!(
        s,
        "  {}: {} iterations, {}",
        o.name,
        o.iterations,
        if o.converged { "converged" } else { "NOT converged" }
    );
    if let Some(z) = &o.max_z {
        let _ = writeln!(
            s,
            "    max-z from the Coons patch: {} LPs, z {:.3e} -> {:.3e} ({})",
            z.iterations,
            z.z_history.first().copied().unwrap_or(f64::NAN),
            z.z_history.last().copied().unwrap_or(f64::NAN),
            z.why
        );
    }
    if let Some(p) = &o.optimisation {
        if let Some(z) = &p.restoration {
            let _ = writeln!(s, "    restoration to d >= eps: {} LPs ({})", z.iterations, z.why);
        }
        let _ = writeln!(
            s,
            "    SQP: {} QPs, {} accepted; {}; min coefficient {:.3e} of the mean det J",
            p.iterations, p.accepted, p.why, p.min_coefficient
        );
    }
    let w = |v: Option<f64>| v.map_or("inf".to_string(), |v| format!("{v:.6}"));
    let _ = writeln!(
        s,
        "    Liao {:.6} -> {:.6}, Winslow {} -> {}, AO {:.6} -> {:.6}",
        r.start_values.liao,
        r.values.liao,
        w(r.start_values.winslow),
        w(r.values.winslow),
        r.start_values.area_orthogonality,
        r.values.area_orthogonality
    );
    let _ = writeln!(s, "    {} ({:.2} s)", o.certificate.message(), o.seconds);
}
