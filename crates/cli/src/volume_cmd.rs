//! `winslow solve VOLUME_BOUNDARY.json -o volume.json`: a volume from its six boundary
//! faces (`formats-extensions.md`, "Volume boundary"), run by the pipeline
//! ([`winslow::Input::Volume`], [`winslow::solve::volume`]): common bases,
//! the trivariate Coons patch as the start, EGG in Galerkin form (eq. 8 in 3D) by
//! Newton (`--improve winslow`: then the 3D Winslow functional minimised from it), the
//! verdict of the trivariate certificate. Exit codes as for a map: 0
//! certified, 3 folded, 5 undecided, 6 certified but the faces not kept.

use super::*;
use crate::files;
use winslow::solve::volume::VolumeSolve;

/// Check the options of `solve` for a volume boundary read from `path`: the flags that
/// apply to planar maps only are refused; the outputs `-o`, `--vtk`, `--vtu`, `--gismo`
/// are checked before the solve. The solve itself is the pipeline's
/// ([`winslow::Input::Volume`]: `--refine` halvings of the common bases, `--repair` /
/// `--no-repair` further halvings while not certified).
pub(super) fn plan(a: &solve_cmd::SolveArgs, path: &Path) -> Result<()> {
    let unsupported = [
        ("--png", a.png.is_some()),
        ("--iges", a.iges.is_some()),
        ("--mesh", a.mesh.is_some()),
        ("--poisson", a.poisson),
    ];
    if let Some((flag, _)) = unsupported.iter().find(|(_, on)| *on) {
        bail!("{flag} applies to planar maps; a volume is meshed by `winslow mesh VOLUME.json` after the solve");
    }
    use files::ext;
    files::OutputPlan::new()
        .input(path)
        .file("-o", &a.output, "volume", ext::VOLUME)
        .maybe("--vtk", a.vtk.as_deref(), "VTK grid", ext::VTK)
        .maybe("--vtu", a.vtu.as_deref(), "VTK Bézier file", ext::VTU)
        .maybe("--gismo", a.gismo.as_deref(), "G+Smo XML file", ext::XML)
        .check()
}

/// Write the solved volume `out` of the geometry `name` where `a` asks, summarise it;
/// the exit code of its certificate (6 when certified but the faces not kept).
pub(super) fn finish(name: &str, out: VolumeSolve, a: &solve_cmd::SolveArgs) -> Result<i32> {
    let (cert, report) = (&out.certificate, &out.report);
    let label = format!("volume certificate: {}", cert.message());
    let extra = Some(serde_json::json!({ "report": report, "certificate": cert }));
    let doc = Output::Volume { name, volume: &out.volume, label: &label, extra };
    files::write(&a.output, &doc)?;
    for (p, e) in [(&a.vtk, "vtk"), (&a.vtu, "vtu"), (&a.gismo, "xml")] {
        if let Some(p) = p {
            files::write_as(p, e, &doc)?;
        }
    }
    if a.json {
        files::print_json(serde_json::json!({ "report": report, "certificate": cert }))?;
    } else {
        say!(
            "{}: volume of {}, {} unknowns; method {}, start {} ({} continuation step(s)), {} Newton iteration(s), \
             Winslow energy {:.6e}",
            name,
            degrees_and_shape(report.degrees, report.shape),
            report.unknowns,
            report.method,
            report.start,
            report.continuation_steps,
            report.newton_iterations,
            report.energy
        );
        say!("{}", cert.message());
        say!("faces kept to {:.3e}; total {:.3} s", report.boundary_deviation, report.seconds);
    }
    let code = output::exit_code(Verdict::of_finding(&cert.verdict));
    Ok(if code == 0 && !report.boundary_kept { 6 } else { code })
}

/// `degrees (p, q, r), n x m x l control points`: the basis of a volume in the printed
/// summaries of `volume` and `loft`.
pub(crate) fn degrees_and_shape(d: [usize; 3], s: [usize; 3]) -> String {
    format!("degrees ({}, {}, {}), {} x {} x {} control points", d[0], d[1], d[2], s[0], s[1], s[2])
}
