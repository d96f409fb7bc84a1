//! Multipatch layouts (paper §11.2) from the command line: `winslow solve` on a G+Smo
//! `<MultiPatch>` file or a JSON multipatch document (`--interfaces fixed|free`), and
//! the `split` and `join` commands.

use super::*;
use winslow::io::picture::render_layout;
use winslow::multipatch::output::{solution_to_gismo_xml, solution_to_json, write_patch_maps, write_vtm};
use winslow::multipatch::{solve_multipatch, Functional, Interfaces, Layout, MultipatchOptions, MultipatchSolution};

/// The options of `winslow solve` that only a multipatch layout reads.
#[derive(Args, Debug, Clone)]
pub(super) struct MultipatchArgs {
    /// Multipatch input: keep the interfaces where they are (each patch solved with its
    /// four sides as Dirichlet data, conforming bases), or, after that, free the interior
    /// control points of the interfaces and solve one problem over all patches.
    #[arg(long, value_enum, default_value = "fixed")]
    interfaces: InterfacesArg,
    /// The problem over all patches with `--interfaces free`: the Winslow functional
    /// (eq. 16) or the weak form (eq. 14).
    #[arg(long, value_enum, default_value = "winslow")]
    functional: FunctionalArg,
    /// Multipatch input: also write one JSON map document per patch into this directory.
    #[arg(long, value_name = "DIR")]
    patch_maps: Option<PathBuf>,
    /// Multipatch input: also write a VTK multiblock file (.vtm) with one exact Bézier
    /// .vtu per patch (in a directory named after the file).
    #[arg(long, value_name = "FILE.vtm")]
    vtm: Option<PathBuf>,
}

#[derive(ValueEnum, Debug, Clone, Copy)]
enum InterfacesArg {
    Fixed,
    Free,
}

#[derive(ValueEnum, Debug, Clone, Copy)]
enum FunctionalArg {
    Winslow,
    Weak,
}

/// The options of a layout solve from the arguments of `winslow solve`.
fn options(a: &SolveArgs) -> Result<MultipatchOptions> {
    let solve = a.solver.options()?;
    if solve.improve.is_some() {
        bail!(
            "--improve and --method weak|winslow improve one patch; for a multipatch layout use --interfaces free (with --functional winslow|weak)"
        );
    }
    Ok(MultipatchOptions {
        interfaces: match a.multipatch.interfaces {
            InterfacesArg::Fixed => Interfaces::Fixed,
            InterfacesArg::Free => Interfaces::Free,
        },
        functional: match a.multipatch.functional {
            FunctionalArg::Winslow => Functional::Winslow,
            FunctionalArg::Weak => Functional::WeakForm,
        },
        refine: solve.refine,
        // a layout refinement refines whole chains of patches: at most three rounds
        repair: solve.repair.min(3),
        solve,
    })
}

/// `winslow solve LAYOUT`: solve, write, summarize; the exit code of the worst verdict.
pub(super) fn solve(layout: Layout, a: &SolveArgs) -> Result<i32> {
    let opts = options(a)?;
    if !(a.quiet || a.json) {
        eprintln!(
            "{}: multipatch layout, {} patches, {} interfaces; interfaces {}",
            layout.name,
            layout.patches.len(),
            layout.interfaces.len(),
            opts.interfaces.name()
        );
    }
    let sol = solve_multipatch(&layout, &opts).with_context(|| format!("solving the layout {}", layout.name))?;
    write(&sol, a)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&sol.report)?);
    } else {
        print!("{}", summary(&sol));
    }
    Ok(exit_code(sol.report.verdict))
}

/// Write the solution where `a` asks: `-o` (.xml: G+Smo, else the JSON document),
/// `--gismo`, `--png` (the whole layout), `--vtm`, `--patch-maps`.
fn write(sol: &MultipatchSolution, a: &SolveArgs) -> Result<()> {
    let xml = |p: &Path| -> Result<()> {
        output::ensure_parent(p)?;
        std::fs::write(p, solution_to_gismo_xml(sol)?).with_context(|| format!("writing {}", p.display()))
    };
    let ext = a.output.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "xml" => xml(&a.output)?,
        "json" | "" => {
            output::ensure_parent(&a.output)?;
            winslow::io::write_json(&a.output, &solution_to_json(sol)?)?;
        }
        other => bail!("a multipatch layout is written as .json or .xml (G+Smo), not .{other}; see --vtm and --png"),
    }
    if let Some(p) = &a.gismo {
        xml(p)?;
    }
    if let Some(p) = &a.png {
        output::write_png(p, &render_layout(&sol.maps(), &PictureOptions::default()))?;
    }
    if let Some(p) = &a.multipatch.vtm {
        output::ensure_parent(p)?;
        write_vtm(sol, p)?;
    }
    if let Some(d) = &a.multipatch.patch_maps {
        write_patch_maps(sol, d)?;
    }
    for (flag, given) in [
        ("--iges", a.iges.is_some()),
        ("--vtu", a.vtu.is_some()),
        ("--vtk", a.vtk.is_some()),
        ("--mesh", a.mesh.is_some()),
    ] {
        if given {
            eprintln!("note: {flag} writes one map; for a multipatch layout use --vtm, --patch-maps or --gismo");
        }
    }
    Ok(())
}

/// The text summary of a layout solve.
pub(super) fn summary(sol: &MultipatchSolution) -> String {
    let r = &sol.report;
    let mut s = format!("{}: {}\n  {}\n", r.name, output::verdict_word(r.verdict), r.message);
    for (p, v) in sol.patches.iter().zip(&r.verdicts) {
        let [nx, ny] = p.map.shape();
        let last = p.solve.levels.last();
        s.push_str(&format!(
            "  patch {:<10} {:>3}x{:<3} functions, {} Newton iterations: {} ({})\n",
            p.name,
            nx,
            ny,
            last.map_or(0, |l| l.newton_iterations),
            v.name(),
            p.certificate.message()
        ));
    }
    for c in &r.classes {
        s.push_str(&format!("  knot class p={} {} elements: {}\n", c.degree, c.elements, c.members.join(" ")));
    }
    let w = r.winslow.map_or("undefined".into(), |w| format!("{w:.6}"));
    s.push_str(&format!("  total Winslow value {w}; {:.3} s (fixed interfaces {:.3} s)\n", r.seconds, r.fixed_seconds));
    s
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
