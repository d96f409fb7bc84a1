//! `winslow solve`: the coarse-to-fine solve with its progress on stderr, the map and
//! report writers, and `--start MAP` (improve a certified map on its own basis).

use super::*;
use crate::files;
use winslow::multipatch::LayoutEvent;
use winslow::{Input, Pipeline, Solved, Stage};

/// Run the pipeline on `input`, printing its stages on stderr unless `quiet`.
pub(super) fn run_pipeline(
    input: impl Into<Input>,
    opts: &SolveOptions,
    assembler: Arc<dyn EggAssembler>,
    quiet: bool,
) -> Result<Solved> {
    let pipeline = Pipeline::new(input, opts.clone()).backend(assembler);
    let stderr = std::io::stderr();
    let mut failed = None;
    let out = pipeline.run(&mut |stage| {
        if quiet {
            return true;
        }
        match print_stage(&mut stderr.lock(), stage) {
            Ok(()) => true,
            Err(e) => {
                failed = Some(e);
                false
            }
        }
    });
    if let Some(e) = failed {
        return Err(e).context("writing the progress");
    }
    Ok(out?)
}

/// One stage of the pipeline as progress lines.
fn print_stage(e: &mut impl Write, stage: &Stage<'_>) -> std::io::Result<()> {
    match stage {
        Stage::Fitted { input: Input::Ring(ring), boundary: cut, hierarchy: h, method } => {
            let rp = &h.reparam;
            writeln!(
                e,
                "{}: ring (O-grid, eta periodic), contours fitted on {} periodic levels up to {} elements in eta, {}",
                ring.name,
                h.levels.len(),
                h.finest().knots[1].num_elements(),
                if rp.matches.is_empty() { "by arc length" } else { "arc length with the narrow gap matched (§7.2)" }
            )?;
            writeln!(
                e,
                "  reparameterization: {} (requested {}); gap/diameter {:.2e} (threshold {:.1e}); {} matched pairs",
                rp.used.name(),
                rp.requested.name(),
                rp.gap_ratio[1],
                rp.gap_threshold,
                rp.matches.len()
            )?;
            let (s, w) = (&cut.sides[Side::West as usize], &cut.sides[Side::East as usize]);
            writeln!(e, "  inner: {}; outer: {}", s.describe(), w.describe())?;
            let seam = cut.side(Side::South).endpoints();
            writeln!(
                e,
                "  eta = 0 from ({:.6}, {:.6}) on the inner to ({:.6}, {:.6}) on the outer contour",
                seam.0[0], seam.0[1], seam.1[0], seam.1[1]
            )?;
            for (s, what) in [(Side::West, "inner"), (Side::East, "outer")] {
                let f = &h.fits[s as usize];
                if !f.converged {
                    writeln!(
                        e,
                        "  warning: the {what} contour's fit did not reach the tolerance {:.3e} (max error {:.3e} on {} elements)",
                        h.physical_tol_abs(),
                        f.final_max_error(),
                        h.finest().knots[1].num_elements()
                    )?;
                }
            }
            writeln!(e, "  method: {} (start: {:?})", method.name(), method.start())
        }
        Stage::Fitted { boundary, hierarchy: h, method, .. } => {
            let tol = h.physical_tol_abs();
            writeln!(
                e,
                "{}: {} hierarchy levels (fit tolerance {tol:.3e}, diameter {:.4})",
                boundary.name,
                h.levels.len(),
                h.physical_diameter()
            )?;
            match (&h.basis.fallback, h.basis.used) {
                (Some(why), _) => writeln!(e, "  basis: fitted (the input basis cannot be used: {why})")?,
                (None, BasisChoice::Input) => writeln!(
                    e,
                    "  basis: input, {}x{} functions, boundary kept exactly",
                    h.finest().knots[0].num_basis(),
                    h.finest().knots[1].num_basis()
                )?,
                (None, BasisChoice::Auto | BasisChoice::Fitted) => {}
            }
            if let Some(k) = &h.basis.kinks {
                writeln!(e, "  kinks: {k}")?;
            }
            let rp = &h.reparam;
            writeln!(
                e,
                "  reparameterization: {} (requested {}), {} matched pairs",
                rp.used.name(),
                rp.requested.name(),
                rp.matches.len()
            )?;
            for s in Side::ALL {
                let f = &h.fits[s as usize];
                if !f.converged {
                    writeln!(
                        e,
                        "  warning: {s} side fit did not reach the tolerance (max error {:.3e})",
                        f.max_error.last().copied().unwrap_or(0.0)
                    )?;
                }
            }
            writeln!(e, "  method: {} (start: {:?})", method.name(), method.start())
        }
        Stage::Fallback { reason } => writeln!(e, "basis auto: {reason}"),
        Stage::LaidOut(auto) => {
            write!(e, "{}", super::domain_cmd::summary(auto))?;
            let l = &auto.layout;
            writeln!(e, "{}: multipatch layout, {} patches, {} interfaces", l.name, l.patches.len(), l.interfaces.len())
        }
        Stage::Volume { options } => writeln!(
            e,
            "volume: common bases halved {} time(s), Coons start, {} by Newton (at most {} iterations), \
             up to {} further halving(s) while not certified",
            options.refine,
            options.method.name(),
            options.max_iterations,
            options.max_refinements
        ),
        Stage::Layout(LayoutEvent::Bases { patches, classes, basis_functions }) => {
            writeln!(
                e,
                "  conforming bases: {classes} knot classes, {basis_functions} functions over {patches} patches"
            )
        }
        Stage::Layout(LayoutEvent::Round { round, solved, failing }) => writeln!(
            e,
            "  {}: {solved} patches solved; {}",
            if *round == 0 { "fixed interfaces".to_string() } else { format!("layout refinement {round}") },
            if failing.is_empty() {
                "all certified".to_string()
            } else {
                format!("not certified: {}", failing.join(", "))
            }
        ),
        Stage::Layout(LayoutEvent::Free { functional }) => writeln!(e, "  free interfaces: {functional}"),
        Stage::Solver(Event::LevelStarted { level, levels, shape, unknowns, initial_guess }) => writeln!(
            e,
            "level {}/{levels}: {}x{} basis, {unknowns} unknowns, initial guess {initial_guess:?}",
            level + 1,
            shape[0],
            shape[1]
        ),
        Stage::Solver(Event::Iterate { iterate, .. }) => writeln!(e, "  {}", output::iterate_line(iterate)),
        Stage::ThbRound(r) => writeln!(
            e,
            "THB round {}: {} offending cell(s) of a {} map, {} refined -> {} functions on {} levels; {} Newton \
             iterations{}, {:.3} s",
            r.round,
            r.offending_cells,
            r.verdict,
            r.marked_cells,
            r.functions,
            r.levels,
            r.iterations,
            if r.converged { "" } else { " (NOT converged)" },
            r.seconds
        ),
        Stage::ThbFallback { thb } => writeln!(
            e,
            "THB refinement left the map {} after {} round(s) ({} offending cell(s), {} functions): solving again with \
             the tensor repair",
            format!("{:?}", thb.verdict).to_lowercase(),
            thb.rounds,
            thb.offending_cells,
            thb.functions
        ),
        Stage::Solver(Event::LevelFinished(r)) => writeln!(
            e,
            "  level done: {} iterations, {}, initial det J min {:.3e}, {:.3} s",
            r.iterations,
            if r.converged {
                "converged".to_string()
            } else {
                format!("NOT converged ({})", r.failure.clone().unwrap_or_default())
            },
            r.initial_det_j_min,
            r.seconds
        ),
        _ => Ok(()),
    }
}

/// `winslow solve INPUT`: the input read as whatever it is ([`Document::into_input`]:
/// boundary, map, ring, ring map, layout, domain, graph, volume boundary), every output
/// path checked, the pipeline run with its stages on stderr, then the result written and
/// summarised by the writer of its kind.
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
    let path = a.boundary.as_ref().context("a boundary file is needed without --start")?;
    let input = files::input_of(files::read(path)?, path, a.solver.fit.reorient)?;
    let mut opts = if input.is_multipatch() { super::multipatch_cmd::options(&a)? } else { a.solver.options()? };
    opts.report.poisson = a.poisson;
    if !input.is_multipatch() {
        opts.repair.refinement = a.solver.refinement;
    }
    if a.solver.refinement == Refinement::Thb && input.is_multipatch() {
        bail!("--refinement thb solves a single patch: a layout is repaired by tensor refinement");
    }
    match &input {
        Input::Volume(_) => super::volume_cmd::plan(&a, path)?,
        input => output_plan(&a, &[path], input.is_multipatch())?,
    }
    let quiet = output::quiet() || a.json;
    if let (Input::Layout(layout), false) = (&input, quiet) {
        super::multipatch_cmd::announce(layout, &opts);
    }
    let sel = a.backend.select(quiet)?;
    let (name, what) = (input.name().to_string(), input.kind());
    let solved =
        run_pipeline(input, &opts, sel.as_assembler(), quiet).with_context(|| format!("solving the {what} {name}"))?;
    let sol = match solved {
        Solved::Layout { solution, laid_out } => {
            let made = laid_out.map(|r| serde_json::to_value(&*r)).transpose()?;
            return super::multipatch_cmd::finish(*solution, &a, made);
        }
        Solved::Volume(v) => return super::volume_cmd::finish(&name, *v, &a),
        Solved::Thb(t) => return super::thb_cmd::finish(&t, &a),
        solved => solved.into_map()?,
    };
    let report = serde_json::to_value(&sol.report)?;
    let label = format!("verdict {:?}: {}", sol.report.outcome.verdict, sol.report.outcome.message);
    let extra = Some(serde_json::json!({ "report": report }));
    let map = Output::Map { name: &sol.name, map: &sol.map, label: &label, extra };
    files::write(&a.output, &map)?;
    for (path, ext) in [(&a.gismo, "xml"), (&a.iges, "igs"), (&a.vtu, "vtu")] {
        if let Some(p) = path {
            files::write_as(p, ext, &map)?;
        }
    }
    if let Some(p) = &a.png {
        let segments = if a.no_png_matches { Vec::new() } else { sol.report.fit.reparam.segments() };
        let kinks = sol.report.boundary.kinks.iter().map(|k| (k.point, k.kept)).collect();
        let image = picture(&sel, &sol.map, &PictureOptions { segments, kinks, ..Default::default() })?;
        files::write(p, &Output::Picture(&image))?;
    }
    if let Some(p) = &a.vtk {
        files::write_as(p, "vtk", &map)?;
    }
    if !a.json {
        say_raw!("{}", output::summary(&sol));
    }
    if let Some(out) = &a.mesh {
        // a folded map gives inverted cells, which the writers refuse
        mesh::make_and_write(&sol.map, &a.mesh_spec, out, a.json)?;
    }
    if a.json {
        files::print_json(report)?;
    }
    Ok(output::solve_exit_code(&sol.report))
}

/// `winslow solve --start MAP.json --method winslow|weak|egg [BOUNDARY]`: the pipeline
/// on the map ([`Input::Map`]): improved on its own basis (its boundary fixed),
/// certified, kept only when certified.
pub(super) fn solve_from_start(a: &SolveArgs, start: &Path) -> Result<i32> {
    let opts = a.solver.options()?;
    let (name, map) = files::map_of(files::read(start)?, start, "--start needs a map")?;
    let inputs: Vec<&Path> = std::iter::once(start).chain(a.boundary.as_deref()).collect();
    output_plan(a, &inputs, false)?;
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
    let input = Input::Map { name, map, boundary };
    let solved =
        Pipeline::new(input, opts).method(method).solve().with_context(|| format!("improving {}", start.display()))?;
    let Solved::Improved(out) = solved else { bail!("the pipeline gave a {} for a start map", solved.kind()) };
    let r = &out.report;
    let mut report = serde_json::to_value(r)?;
    report["start"] = serde_json::Value::String(start.display().to_string());
    let label = format!("verdict {:?}: {}", r.verdict, r.certificate.message());
    let extra = Some(serde_json::json!({ "report": report }));
    let map = Output::Map { name: &out.name, map: &out.map, label: &label, extra };
    files::write(&a.output, &map)?;
    for (path, ext) in [(&a.gismo, "xml"), (&a.iges, "igs"), (&a.vtu, "vtu"), (&a.vtk, "vtk")] {
        if let Some(p) = path {
            files::write_as(p, ext, &map)?;
        }
    }
    if let Some(p) = &a.png {
        let sel = a.backend.select(output::quiet() || a.json)?;
        files::write(p, &Output::Picture(&picture(&sel, &out.map, &PictureOptions::default())?))?;
    }
    if a.json {
        files::print_json(report)?;
    } else {
        let mut s = format!(
            "{}: {} from {}\n  {}\n",
            out.name,
            output::verdict_word(r.verdict),
            start.display(),
            r.certificate.message()
        );
        output::improvement_lines(&mut s, &r.improvement, r.seconds);
        if let Some(d) = r.boundary_deviation {
            s.push_str(&format!(
                "  boundary deviation from {} (S, E, N, W): {:.3e} {:.3e} {:.3e} {:.3e}\n",
                a.boundary.as_ref().map_or(String::new(), |p| p.display().to_string()),
                d[0],
                d[1],
                d[2],
                d[3]
            ));
        }
        say_raw!("{s}");
    }
    Ok(output::exit_code(r.verdict))
}

/// Check every output of `solve` before the work ([`files::OutputPlan`]): a single map's
/// files, or a layout's (`multipatch`), none of them an input.
fn output_plan(a: &SolveArgs, inputs: &[&Path], multipatch: bool) -> Result<()> {
    use files::ext;
    let mut plan = inputs.iter().fold(files::OutputPlan::new(), |p, i| p.input(i));
    plan = if multipatch {
        plan.file("-o", &a.output, "multipatch result", ext::MULTIPATCH)
            .maybe("--vtm", a.multipatch.vtm.as_deref(), "VTK multiblock file", ext::VTM)
            .folder_maybe("--patch-maps", a.multipatch.patch_maps.as_deref())
    } else {
        plan.file("-o", &a.output, "map", ext::MAP)
            .maybe("--vtk", a.vtk.as_deref(), "VTK grid", ext::VTK)
            .maybe("--iges", a.iges.as_deref(), "IGES file", ext::IGES)
            .maybe("--vtu", a.vtu.as_deref(), "VTK Bézier file", ext::VTU)
            .mesh_maybe("--mesh", a.mesh.as_deref())?
    };
    plan.maybe("--gismo", a.gismo.as_deref(), "G+Smo XML file", ext::XML)
        .maybe("--png", a.png.as_deref(), "picture", ext::PNG)
        .check()?;
    match &a.multipatch.patch_maps {
        // the patch maps of an earlier run (another layout) are not mixed with this one's
        Some(dir) if multipatch => {
            files::claim_folder("--patch-maps", dir, |n| n.ends_with(".json"), a.multipatch.overwrite)
        }
        _ => Ok(()),
    }
}

#[derive(Args, Debug)]
pub(crate) struct SolveArgs {
    /// Input file: a four-sided boundary, a ring, a multipatch layout, a general domain or
    /// plane graph (laid out automatically), or the six boundary faces of a volume (with
    /// `--start`: an optional boundary, the map's boundary deviation from it is reported).
    #[arg(required_unless_present = "start")]
    pub(crate) boundary: Option<PathBuf>,
    /// Start from this map document (made by `winslow solve` or another tool) instead of
    /// solving from the boundary: the certificate must prove it bijective, its boundary
    /// control points stay fixed, `--method` (winslow, weak or egg) runs on its basis,
    /// and the result is kept only when certified.
    #[arg(long)]
    pub(crate) start: Option<PathBuf>,
    /// Output map file: JSON with a "report" (default), or by extension G+Smo XML
    /// (.xml), IGES (.igs, .iges), VTK Bézier cells (.vtu) or a sampled VTK grid (.vtk).
    /// A multipatch input (G+Smo `<MultiPatch>` or a JSON document with "patches") is
    /// written as a JSON multipatch document or G+Smo XML (.xml).
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) solver: SolverArgs,
    /// Write a picture of the map (grid lines coloured by det J; the matched pairs of
    /// the constrained reparameterization drawn as segments).
    #[arg(long)]
    pub(crate) png: Option<PathBuf>,
    /// Do not draw the matched pairs into the PNG.
    #[arg(long)]
    pub(crate) no_png_matches: bool,
    /// Write a VTK structured grid with det J.
    #[arg(long)]
    pub(crate) vtk: Option<PathBuf>,
    /// Also write the map as G+Smo XML (TensorBSpline2 / TensorNurbs2).
    #[arg(long)]
    pub(crate) gismo: Option<PathBuf>,
    /// Also write the map as IGES 5.3 (rational B-spline surface, entity 128).
    #[arg(long)]
    pub(crate) iges: Option<PathBuf>,
    /// Also write the exact map as VTK Bézier quadrilaterals (.vtu, det J as point data).
    #[arg(long)]
    pub(crate) vtu: Option<PathBuf>,
    /// Print the report as JSON on stdout (progress goes to stderr).
    #[arg(long)]
    pub(crate) json: bool,
    /// Also solve the grid-quality benchmark (paper eq. 44-45) on the map; Q(x) goes
    /// into the report.
    #[arg(long)]
    pub(crate) poisson: bool,
    #[command(flatten)]
    pub(crate) backend: BackendArgs,
    /// Also write a mesh of the solved map (same options as `winslow mesh`): .msh,
    /// .su2, .xyz, .vtu or a directory (OpenFOAM); of a layout, one conforming mesh of
    /// all patches (structured or triangulated), a cell group per face.
    #[arg(long, value_name = "OUT")]
    pub(crate) mesh: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) mesh_spec: mesh::MeshSpec,
    #[command(flatten)]
    pub(crate) multipatch: multipatch_cmd::MultipatchArgs,
}
