//! `winslow compare BOUNDARY [--methods egg,vhm,qc,maxz,liao,winslow,ao]
//! [--json] [--png-dir DIR]`: the methods of paper §10 on one basis, one table row each
//! ([`winslow::pipeline::compare`]): iterations, the certificate's verdict, `Q(x) / Q(x_G)`,
//! the Winslow, Liao and area-orthogonality values, the smallest scaled Jacobian, time.

use super::*;
use winslow::methods::quasi_conformal::QcHessian;
use winslow::pipeline::compare::{compare, CompareEvent, CompareOptions, Comparison, MethodChoice};
use winslow::solve::constrained::ConstrainedOptions;

#[derive(Args, Debug)]
pub(super) struct CompareArgs {
    /// Boundary file (JSON boundary, contour or map document; G+Smo XML).
    boundary: PathBuf,
    /// Methods, comma-separated: egg (eq. 8, always run: its map is x_G), vhm (the
    /// variational harmonic method, eq. 46), qc (the quasi-conformal functional, eq.
    /// 47-48), and Gravesen's: maxz (eq. 49 from the Coons patch, stopped at z > 0), liao,
    /// winslow, ao (the Liao, Winslow eq. 16 or area-orthogonality functional
    /// minimised subject to d(c) >= eps from x_G, as `winslow optimise --from egg`).
    /// Gravesen's need a polynomial basis (--basis fitted where the input is NURBS) and
    /// the constrained ones at most 3000 unknowns (a coarse --fit-tol); else their rows
    /// are errors saying so.
    #[arg(long, value_delimiter = ',', default_value = "egg,vhm,qc")]
    methods: Vec<String>,
    /// Weight of the uniformity term of the variational harmonic method (eq. 46),
    /// dimensionless: applied as lambda1 * diameter^4.
    #[arg(long, default_value_t = 0.0)]
    lambda1: f64,
    /// Weight of the area-orthogonality term of the variational harmonic method,
    /// dimensionless: applied as lambda2 * diameter^2.
    #[arg(long, default_value_t = 0.0)]
    lambda2: f64,
    /// Hessian of the quasi-conformal iteration: the Gauss-Newton matrix
    /// (Levenberg-Marquardt, the default) or the exact Hessian (Newton's method).
    #[arg(long, value_enum, default_value = "gauss-newton")]
    qc_hessian: QcHessian,
    /// eps of the constraints d(c) >= eps of liao, winslow and ao, relative to
    /// the mean det J.
    #[arg(long, default_value_t = ConstrainedOptions::default().eps)]
    eps: f64,
    /// Most SQP iterations of liao, winslow and ao.
    #[arg(long, default_value_t = ConstrainedOptions::default().max_iterations)]
    max_sqp: usize,
    #[command(flatten)]
    fit: FitArgs,
    /// Nonlinear tolerance on each method's scaled residual.
    #[arg(long, default_value_t = 1e-9)]
    tol: f64,
    /// Newton iterations per level before the fall-back to pseudo time-stepping.
    #[arg(long, default_value_t = CompareOptions::default().solve.nonlinear.max_newton)]
    max_newton: usize,
    /// Levels of the hierarchy each method solves (the finest always): 1 starts every
    /// method from the Coons patch of the finest basis; more add the coarse-to-fine
    /// prolongations and continuation (§6.3, §9).
    #[arg(long, default_value_t = 1)]
    levels: usize,
    /// Minimum number of elements per direction on the finest level.
    #[arg(long, default_value_t = 8)]
    min_elements: usize,
    /// Extra uniform halvings of the finest level.
    #[arg(long, default_value_t = 0)]
    refine: usize,
    /// Basis growth factor between solved levels.
    #[arg(long, default_value_t = SolveOptions::default().levels.growth)]
    growth: f64,
    /// Operator of EGG: L of eq. (4) or L / (g11 + g22).
    #[arg(long, value_enum, default_value = "scaled")]
    operator: Operator,
    /// Linear solver: sparse LU, GMRES, or auto (LU up to 64 unknowns, GMRES above).
    #[arg(long, value_enum, default_value = "auto")]
    linear: LinearMethod,
    /// Rounds of defect correction per method (default 0: every method on the same
    /// basis; with rounds, each method may refine around its own folds).
    #[arg(long, default_value_t = 0)]
    repair: usize,
    /// Length scales a1,a2 of the Poisson benchmark's u* (default: half the bounding box
    /// extents of the EGG map), the same for every method.
    #[arg(long, value_name = "A1,A2", value_parser = super::parse_scales)]
    poisson_scales: Option<[f64; 2]>,
    /// Write one picture per method, DIR/NAME-METHOD.png (grid lines coloured by det J).
    #[arg(long)]
    png_dir: Option<PathBuf>,
    /// Remove the pictures of an earlier comparison of this geometry (DIR/NAME-*.png)
    /// from --png-dir first; without it, such files are an error (pictures of two runs
    /// never mix).
    #[arg(long, requires = "png_dir")]
    overwrite: bool,
    /// Print the comparison as JSON on stdout (progress goes to stderr).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    memory: MemoryArgs,
    /// Progress of every nonlinear iterate (residual, objective, damping).
    #[arg(short, long)]
    verbose: bool,
}

impl CompareArgs {
    fn options(&self) -> Result<(Vec<MethodChoice>, CompareOptions)> {
        let methods = self.methods.iter().map(|m| MethodChoice::parse(m)).collect::<winslow::Result<Vec<_>>>()?;
        let solver = SolverArgs {
            fit: self.fit.clone(),
            tol: self.tol,
            levels: Some(self.levels.max(1)),
            min_elements: self.min_elements,
            refine: self.refine,
            growth: self.growth,
            iteration: NonlinearMethod::Newton,
            method: MethodArg::Egg,
            operator: self.operator,
            linear: self.linear,
            repair: self.repair,
            no_repair: false,
            repair_freeze: None,
            refinement: Refinement::Tensor,
            improve: None,
            kinks_local: KinksLocal::All,
            memory: self.memory.clone(),
        };
        // the comparison's defaults (one level, no repair, its iteration limits), with the
        // fit, operator, sizes and tolerances of the flags
        let mut opts = CompareOptions::default();
        let max_pseudo = opts.solve.nonlinear.max_pseudo;
        opts.solve = solver.options()?;
        opts.solve.nonlinear.max_newton = self.max_newton.max(1);
        opts.solve.nonlinear.max_pseudo = max_pseudo;
        (opts.lambda1, opts.lambda2) = (self.lambda1, self.lambda2);
        opts.qc_hessian = self.qc_hessian;
        opts.constrained.eps = self.eps;
        opts.constrained.max_iterations = self.max_sqp;
        opts.poisson_scales = self.poisson_scales;
        // every value checked by the core, the same as for the library and Python
        opts.validate()?;
        Ok((methods, opts))
    }
}

pub(super) fn run(a: CompareArgs) -> Result<i32> {
    let (methods, opts) = a.options()?;
    crate::files::OutputPlan::new().input(&a.boundary).folder_maybe("--png-dir", a.png_dir.as_deref()).check()?;
    let boundary = load_boundary(&a.boundary, a.fit.reorient)?;
    if let Some(dir) = &a.png_dir {
        let ours =
            |f: &str| f.strip_prefix(boundary.name.as_str()).is_some_and(|r| r.starts_with('-') && r.ends_with(".png"));
        crate::files::claim_folder("--png-dir", dir, ours, a.overwrite)?;
    }
    let quiet = output::quiet() || a.json;
    let stderr = std::io::stderr();
    let mut progress = |e: CompareEvent| {
        if quiet {
            return true;
        }
        let mut err = stderr.lock();
        let _ = match e {
            CompareEvent::Started { method, index, count } => {
                writeln!(err, "[{}/{count}] {method}", index + 1)
            }
            CompareEvent::Solver(Event::LevelFinished(r)) => writeln!(
                err,
                "  level {}: {}x{} basis, {} iterations, {}",
                r.level + 1,
                r.shape[0],
                r.shape[1],
                r.iterations + r.continuation_iterations,
                if r.converged {
                    "converged".into()
                } else {
                    format!("not converged ({})", r.failure.unwrap_or_default())
                }
            ),
            CompareEvent::Solver(Event::Iterate { iterate, .. }) if a.verbose => {
                writeln!(err, "    {}", output::iterate_line(&iterate))
            }
            CompareEvent::Solver(_) => Ok(()),
            CompareEvent::Finished(row) => writeln!(err, "  {}: {}, {:.3} s", row.method, row.bij(), row.seconds),
        };
        true
    };
    let cmp = compare(&boundary, &methods, &opts, Arc::new(winslow::CpuAssembler), &mut progress)
        .with_context(|| format!("comparing methods on {}", a.boundary.display()))?
        .context("the comparison was cancelled")?;
    if let Some(dir) = &a.png_dir {
        for row in &cmp.rows {
            if let Some(map) = &row.map {
                let path = dir.join(format!("{}-{}.png", cmp.name, row.method));
                let image = render(map, &PictureOptions::default());
                crate::files::write(&path, &winslow::io::Output::Picture(&image))?;
            }
        }
    }
    if a.json {
        crate::files::print_json(serde_json::to_value(&cmp)?)?;
    } else {
        say_raw!("{}", table(&cmp));
    }
    Ok(0)
}

/// `x` in a fixed width, `-` when absent.
fn num(x: Option<f64>, prec: usize) -> String {
    match x {
        Some(v) if v.is_finite() && (v.abs() >= 1e4 || (v != 0.0 && v.abs() < 1e-2)) => format!("{v:.prec$e}"),
        Some(v) if v.is_finite() => format!("{v:.prec$}"),
        Some(_) => "inf".into(),
        None => "-".into(),
    }
}

/// The paper's columns (Tables 1-3) and ours, one row per method, notes below.
pub(super) fn table(c: &Comparison) -> String {
    let mut s = format!(
        "{}: {} basis, degree {}x{}, Poisson scales a = ({:.4}, {:.4})\n",
        c.name, c.basis, c.degree[0], c.degree[1], c.poisson_scales[0], c.poisson_scales[1]
    );
    if let Some(why) = &c.basis_fallback {
        s.push_str(&format!("  basis: {why}\n"));
    }
    let w = c.rows.iter().map(|r| r.method.len()).max().unwrap_or(0).max(6);
    s.push_str(&format!(
        "{:<w$} {:<9} {:>5} {:>5} {:<17} {:>9} {:>10} {:>10} {:>10} {:>10} {:>7} {:>9}\n",
        "method", "start", "IT", "conv", "BIJ", "Q/Q(x_G)", "W", "Liao", "AO", "min SJ", "basis", "time [s]"
    ));
    let mut notes = Vec::new();
    for r in &c.rows {
        let m = r.measures.as_ref();
        s.push_str(&format!(
            "{:<w$} {:<9} {:>5} {:>5} {:<17} {:>9} {:>10} {:>10} {:>10} {:>10} {:>7} {:>9.3}\n",
            r.method,
            r.start,
            r.iterations,
            if r.converged { "yes" } else { "no" },
            r.bij(),
            num(r.q_ratio, 3),
            num(m.and_then(|m| m.winslow).or(m.map(|_| f64::INFINITY)), 3),
            num(m.map(|m| m.liao), 3),
            num(m.map(|m| m.area_orthogonality), 3),
            num(m.map(|m| m.scaled_jacobian_min), 3),
            m.map_or("-".into(), |m| format!("{}x{}", m.shape[0], m.shape[1])),
            r.seconds
        ));
        for n in &r.notes {
            notes.push(format!("  {}: {n}", r.method));
        }
        match (&r.failure, m) {
            (Some(why), None) => notes.push(format!("  {}: no map: {why}", r.method)),
            (Some(why), Some(_)) => notes.push(format!("  {}: not converged: {why}", r.method)),
            (None, _) => {}
        }
        if let Some(m) = m.filter(|m| !matches!(m.verdict, Verdict::Certified | Verdict::DegenerateCorner)) {
            notes.push(format!(
                "  {}: the map is {} (its last iterate): {}",
                r.method,
                m.verdict.name(),
                m.certificate
            ));
        }
    }
    notes.push(
        "  start: coons = the Coons patch of the finest basis, hierarchy = coarse to fine from the coarsest, egg = x_G"
            .into(),
    );
    for n in notes {
        s.push_str(&n);
        s.push('\n');
    }
    s
}
