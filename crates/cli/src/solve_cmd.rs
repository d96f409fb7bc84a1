//! `winslow solve`: the coarse-to-fine solve with its progress on stderr, the map and
//! report writers, and `--start MAP` (improve a certified map on its own basis).

use super::*;
use crate::files;
use winslow::boundary::hierarchy::Hierarchy;
use winslow::boundary::ring::Ring;
use winslow::boundary::ring_fit::ring_hierarchy;
use winslow::solve::solver::ring_options;

/// Run the solver stream, printing progress.
pub(super) fn run_solver(
    boundary: &Boundary,
    opts: &SolveOptions,
    assembler: Arc<dyn EggAssembler>,
    quiet: bool,
) -> Result<Solution> {
    let h = build_hierarchy(boundary, &opts.fit).context("fitting the boundary")?;
    let sol = drive(boundary, &h, opts, assembler.clone(), quiet)?;
    let Some((fitted, why)) = winslow::solve::solver::auto_fallback(&sol, &opts.fit) else { return Ok(sol) };
    if !quiet {
        eprintln!("basis auto: {why}");
    }
    let opts = SolveOptions { fit: fitted, ..opts.clone() };
    let h = build_hierarchy(boundary, &opts.fit).context("fitting the boundary")?;
    let again = drive(boundary, &h, &opts, assembler, quiet)?;
    Ok(winslow::solve::solver::auto_choice(sol, again, why))
}

/// Fit a ring's contours on one periodic knot vector and solve with `eta` periodic
/// (`winslow solve ring.json`, paper §11.1), printing progress.
pub(super) fn run_ring_solver(
    ring: &Ring,
    opts: &SolveOptions,
    assembler: Arc<dyn EggAssembler>,
    quiet: bool,
) -> Result<Solution> {
    let (h, cut) = ring_hierarchy(ring, &opts.fit).context("fitting the ring's contours")?;
    if !quiet {
        let rp = &h.reparam;
        eprintln!(
            "{}: ring (O-grid, eta periodic), contours fitted on {} periodic levels up to {} elements in eta, {}",
            ring.name,
            h.levels.len(),
            h.finest().knots[1].num_elements(),
            if rp.matches.is_empty() { "by arc length" } else { "arc length with the narrow gap matched (§7.2)" }
        );
        eprintln!(
            "  reparameterization: {} (requested {}); gap/diameter {:.2e} (threshold {:.1e}); {} matched pairs",
            rp.used.name(),
            rp.requested.name(),
            rp.gap_ratio[1],
            rp.gap_threshold,
            rp.matches.len()
        );
        let (s, e) = (&cut.sides[Side::West as usize], &cut.sides[Side::East as usize]);
        eprintln!("  inner: {}; outer: {}", s.describe(), e.describe());
        let seam = cut.side(Side::South).endpoints();
        eprintln!(
            "  eta = 0 from ({:.6}, {:.6}) on the inner to ({:.6}, {:.6}) on the outer contour",
            seam.0[0], seam.0[1], seam.1[0], seam.1[1]
        );
        for (s, what) in [(Side::West, "inner"), (Side::East, "outer")] {
            let f = &h.fits[s as usize];
            if !f.converged {
                eprintln!(
                    "  warning: the {what} contour's fit did not reach the tolerance {:.3e} (max error {:.3e} on {} elements)",
                    h.physical_tol_abs(),
                    f.final_max_error(),
                    h.finest().knots[1].num_elements()
                );
            }
        }
    }
    drive(&cut, &h, &ring_options(opts), assembler, quiet)
}

/// Run the solver stream over the hierarchy `h` of `boundary`, printing progress.
fn drive(
    boundary: &Boundary,
    h: &Hierarchy,
    opts: &SolveOptions,
    assembler: Arc<dyn EggAssembler>,
    quiet: bool,
) -> Result<Solution> {
    if !quiet && !opts.topology.eta_periodic() {
        let tol = h.physical_tol_abs();
        eprintln!(
            "{}: {} hierarchy levels (fit tolerance {tol:.3e}, diameter {:.4})",
            boundary.name,
            h.levels.len(),
            h.physical_diameter()
        );
        match (&h.basis.fallback, h.basis.used) {
            (Some(why), _) => eprintln!("  basis: fitted (the input basis cannot be used: {why})"),
            (None, BasisChoice::Auto) => {}
            (None, BasisChoice::Input) => eprintln!(
                "  basis: input, {}x{} functions, boundary kept exactly",
                h.finest().knots[0].num_basis(),
                h.finest().knots[1].num_basis()
            ),
            (None, BasisChoice::Fitted) => {}
        }
        if let Some(k) = &h.basis.kinks {
            eprintln!("  kinks: {k}");
        }
        let rp = &h.reparam;
        eprintln!(
            "  reparameterization: {} (requested {}), {} matched pairs",
            rp.used.name(),
            rp.requested.name(),
            rp.matches.len()
        );
        for s in Side::ALL {
            let f = &h.fits[s as usize];
            if !f.converged {
                eprintln!(
                    "  warning: {s} side fit did not reach the tolerance (max error {:.3e})",
                    f.max_error.last().copied().unwrap_or(0.0)
                );
            }
        }
    }
    let mut solver = EggSolver::new(h, opts.clone(), assembler)?;
    if !quiet {
        let m = solver.method();
        eprintln!("  method: {} (start: {:?})", m.name(), m.start());
    }
    let stderr = std::io::stderr();
    for event in solver.by_ref() {
        let event = event?;
        if quiet {
            continue;
        }
        let mut e = stderr.lock();
        match event {
            Event::LevelStarted { level, levels, shape, unknowns, initial_guess } => {
                writeln!(
                    e,
                    "level {}/{levels}: {}x{} basis, {unknowns} unknowns, initial guess {initial_guess:?}",
                    level + 1,
                    shape[0],
                    shape[1]
                )?;
            }
            Event::Iterate { iterate: it, .. } => {
                writeln!(
                    e,
                    "  {:>3} {:<11} |F| = {:.3e}  scaled {:.3e}  step {:.2e}  damping {:.3}{}{}",
                    it.iteration,
                    format!("{:?}", it.method),
                    it.residual,
                    it.scaled_residual,
                    it.step,
                    it.damping,
                    it.dt.map(|d| format!("  dt {d:.2e}")).unwrap_or_default(),
                    it.objective.map(|j| format!("  J {j:.6e}")).unwrap_or_default()
                )?;
            }
            Event::LevelFinished(r) => {
                writeln!(
                    e,
                    "  level done: {} iterations, {}, initial det J min {:.3e}, {:.3} s",
                    r.iterations,
                    if r.converged {
                        "converged".to_string()
                    } else {
                        format!("NOT converged ({})", r.failure.unwrap_or_default())
                    },
                    r.initial_det_j_min,
                    r.seconds
                )?;
            }
        }
    }
    Ok(solver.finish(boundary, h)?)
}

pub(super) fn solve(a: SolveArgs) -> Result<i32> {
    let wants_mesh = a.mesh_spec.structured.is_some() || a.mesh_spec.unstructured;
    if wants_mesh != a.mesh.is_some() {
        bail!("--mesh OUT and one of --structured NXxNY / --unstructured --size H go together");
    }
    if let Some(out) = &a.mesh {
        winslow_mesh::formats::Format::from_path(out)?;
    }
    if let Some(start) = &a.start {
        return solve_from_start(&a, start);
    }
    let mut opts = a.solver.options()?;
    opts.poisson = a.poisson;
    let path = a.boundary.as_ref().context("a boundary file is needed without --start")?;
    let doc = files::read(path)?;
    let sel = a.backend.select(a.quiet || a.json)?;
    let sol = match doc {
        Document::Layout(layout) | Document::Multipatch(layout) => return super::multipatch_cmd::solve(layout, &a),
        Document::Ring(ring) => run_ring_solver(&ring, &opts, sel.as_assembler(), a.quiet || a.json)?,
        doc => {
            let boundary = files::boundary_of(doc, path)?;
            let (boundary, _) = checked_boundary(boundary, &ReadOptions { reorient: a.solver.fit.reorient })
                .with_context(|| format!("validating {}", path.display()))?;
            run_solver(&boundary, &opts, sel.as_assembler(), a.quiet || a.json)?
        }
    };
    let report = serde_json::to_value(&sol.report)?;
    let label = format!("verdict {:?}: {}", sol.report.verdict, sol.report.message);
    let extra = Some(serde_json::json!({ "report": report }));
    let map = Output::Map { name: &sol.name, map: &sol.map, label: &label, extra };
    files::write(&a.output, &map)?;
    for (path, ext) in [(&a.gismo, "xml"), (&a.iges, "igs"), (&a.vtu, "vtu")] {
        if let Some(p) = path {
            files::write_as(p, ext, &map)?;
        }
    }
    if let Some(p) = &a.png {
        let segments = if a.no_png_matches { Vec::new() } else { sol.report.reparam.segments() };
        let kinks = sol.report.kinks.iter().map(|k| (k.point, k.kept)).collect();
        let image = picture(&sel, &sol.map, &PictureOptions { segments, kinks, ..Default::default() })?;
        files::write(p, &Output::Picture(&image))?;
    }
    if let Some(p) = &a.vtk {
        files::write_as(p, "vtk", &map)?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", output::summary(&sol, &a.output, a.png.as_deref()));
    }
    if let Some(out) = &a.mesh {
        // a folded map gives inverted cells, which the writers refuse
        mesh::make_and_write(&sol.map, &a.mesh_spec, out, a.json)?;
    }
    Ok(exit_code(sol.report.verdict))
}

/// `winslow solve --start MAP.json --method winslow|weak|egg [BOUNDARY]`: improve a
/// certified map on its own basis (its boundary fixed), certify the result, keep it
/// only when certified.
pub(super) fn solve_from_start(a: &SolveArgs, start: &Path) -> Result<i32> {
    let opts = a.solver.options()?;
    let (name, map) = files::map_of(files::read(start)?, start, "--start needs a map")?;
    let method: Arc<dyn Method> = match a.solver.method {
        MethodArg::Winslow => Improve::Winslow.method(),
        MethodArg::Weak => Improve::WeakForm.method(),
        MethodArg::Egg => Arc::new(EggMethod::cpu(opts.operator)),
        MethodArg::Newton | MethodArg::PseudoTime => {
            bail!("--start needs --method winslow, weak or egg (use --iteration for newton or pseudo-time)")
        }
    };
    let boundary = match &a.boundary {
        Some(p) => Some(load_boundary(p, a.solver.fit.reorient)?),
        None => None,
    };
    let diameter = {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &map.control_points {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        (hi[0] - lo[0]).hypot(hi[1] - lo[1])
    };
    let t0 = std::time::Instant::now();
    let cert = certify(&map, &opts.certify).context("certifying the start")?;
    let out = improve(&map, &cert, &*method, &opts.topology, opts.nonlinear, &opts.certify, diameter)
        .with_context(|| format!("improving {}", start.display()))?;
    let deviation = boundary.as_ref().map(|b| boundary_deviation(&out.map, b, 400));
    let verdict = match out.certificate.verdict {
        CertVerdict::Certified { .. } => Verdict::Certified,
        CertVerdict::DegenerateCorner { .. } => Verdict::DegenerateCorner,
        CertVerdict::Folded { .. } => Verdict::Folded,
        CertVerdict::Undecided { .. } => Verdict::Undecided,
    };
    let q = quality(&out.map);
    let w = q.functionals.winslow;
    let report = serde_json::json!({
        "version": env!("CARGO_PKG_VERSION"),
        "start": start.display().to_string(),
        "method": method.name(),
        "verdict": verdict,
        "message": format!("{}; {}", out.certificate.message(), out.report.message),
        "certificate": out.certificate,
        "quality": q,
        "winslow": w.is_finite().then_some(w),
        "boundary_deviation": deviation,
        "improvement": out.report,
        "seconds": t0.elapsed().as_secs_f64(),
    });
    let label = format!("verdict {verdict:?}: {}", out.certificate.message());
    let extra = Some(serde_json::json!({ "report": report }));
    let map = Output::Map { name: &name, map: &out.map, label: &label, extra };
    files::write(&a.output, &map)?;
    for (path, ext) in [(&a.gismo, "xml"), (&a.iges, "igs"), (&a.vtu, "vtu"), (&a.vtk, "vtk")] {
        if let Some(p) = path {
            files::write_as(p, ext, &map)?;
        }
    }
    if let Some(p) = &a.png {
        let sel = a.backend.select(a.quiet || a.json)?;
        files::write(p, &Output::Picture(&picture(&sel, &out.map, &PictureOptions::default())?))?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        let mut s = format!(
            "{name}: {} from {}\n  {}\n",
            output::verdict_word(verdict),
            start.display(),
            out.certificate.message()
        );
        output::improvement_lines(&mut s, &out.report, t0.elapsed().as_secs_f64());
        if let Some(d) = deviation {
            s.push_str(&format!(
                "  boundary deviation from {} (S, E, N, W): {:.3e} {:.3e} {:.3e} {:.3e}\n",
                a.boundary.as_ref().map_or(String::new(), |p| p.display().to_string()),
                d[0],
                d[1],
                d[2],
                d[3]
            ));
        }
        s.push_str(&format!("  wrote {}\n", a.output.display()));
        print!("{s}");
    }
    Ok(exit_code(verdict))
}

/// 0 certified or degenerate corner, 3 folded, 4 not converged, 5 undecided.
fn exit_code(v: Verdict) -> i32 {
    match v {
        Verdict::Certified | Verdict::DegenerateCorner => 0,
        Verdict::Folded => 3,
        Verdict::NotConverged => 4,
        Verdict::Undecided => 5,
    }
}
