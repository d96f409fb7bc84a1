//! `winslow solve VOLUME_BOUNDARY.json -o volume.json`: a volume from its six boundary
//! faces (`formats.md`, "Volume boundary"; [`winslow::solve::volume`]): common bases,
//! the trivariate Coons patch as the start, the 3D Winslow functional minimised by
//! Newton, the verdict of the trivariate certificate. Exit codes as for a map: 0
//! certified, 3 folded, 5 undecided, 6 certified but the faces not kept.

use super::*;
use crate::files;
use winslow::boundary::volume::VolumeBoundary;
use winslow::solve::volume::{solve_volume, VolumeOptions};

/// Solve the volume bounded by `b` (read from `path`) with the options of `solve` that
/// apply to volumes: `--refine` (halvings of the common bases), `--repair` /
/// `--no-repair` (further halvings while not certified), `-o`, `--vtk`, `--vtu`,
/// `--gismo`, `--json`.
pub(super) fn solve(b: VolumeBoundary, a: &solve_cmd::SolveArgs, path: &Path) -> Result<i32> {
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
        .check()?;
    let opts = VolumeOptions {
        refine: a.solver.refine,
        max_refinements: if a.solver.no_repair { 0 } else { a.solver.repair },
        ..Default::default()
    };
    let out = solve_volume(&b, &opts).with_context(|| format!("solving the volume bounded by {}", path.display()))?;
    let (cert, report) = (&out.certificate, &out.report);
    let label = format!("volume certificate: {}", cert.message());
    let extra = Some(serde_json::json!({ "report": report, "certificate": cert }));
    let doc = Output::Volume { name: &b.name, volume: &out.volume, label: &label, extra };
    files::write(&a.output, &doc)?;
    for (p, e) in [(&a.vtk, "vtk"), (&a.vtu, "vtu"), (&a.gismo, "xml")] {
        if let Some(p) = p {
            files::write_as(p, e, &doc)?;
        }
    }
    if a.json {
        files::print_json(serde_json::json!({ "report": report, "certificate": cert }))?;
    } else {
        let (d, s) = (report.degrees, report.shape);
        say!(
            "{}: volume of degrees ({}, {}, {}), {} x {} x {} control points, {} unknowns; start {} ({} continuation step(s)), \
             {} Newton iteration(s), Winslow energy {:.6e}",
            b.name,
            d[0],
            d[1],
            d[2],
            s[0],
            s[1],
            s[2],
            report.unknowns,
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
