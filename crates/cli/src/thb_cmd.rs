//! THB maps (`winslow::spline::hierarchical`) in `winslow check`, `winslow convert` and
//! `winslow solve --refinement thb`: a file holding a THB map (read by `winslow::read` as
//! `Document::Thb`) is certified active cell by active cell, and converted to the tensor
//! map on the knot lines of its active cells (exact knot insertion) or, with `--thb`,
//! written as a THB map again; the pipeline's THB result (`Solved::Thb`) is written with
//! its report.

use std::path::Path;

use anyhow::{Context, Result};
use winslow::io::picture::{render_thb, PictureOptions};
use winslow::io::Output;
use winslow::spline::hierarchical::map::HierarchicalMap;
use winslow::verify::certificate::hierarchical::certify_hierarchical;
use winslow::verify::certificate::{certify, CertifyOptions, Finding};
use winslow::ThbSolution;

use crate::files;
use crate::solve_cmd::SolveArgs;

/// 0 certified or degenerate corner, 3 folded, 5 undecided.
fn exit_code(v: &Finding) -> i32 {
    match v {
        Finding::Certified { .. } | Finding::DegenerateCorner { .. } => 0,
        Finding::Folded { .. } => 3,
        Finding::Undecided { .. } => 5,
    }
}

/// `winslow check THB`: the certificate of a THB map, per active cell.
pub(crate) fn check(name: &str, map: &HierarchicalMap, opts: &CertifyOptions, json: bool) -> Result<i32> {
    let c = certify_hierarchical(map, opts).context("certifying the THB map")?;
    if json {
        let report = serde_json::json!({ "name": name, "kind": "thb", "certificate": &c });
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        say!("{name}: {}", c.message());
    }
    Ok(exit_code(&c.verdict))
}

/// `winslow convert THB -o OUT [--thb]`: the tensor map (certified again, the verdict in
/// the file) by the output's extension, or the THB map itself (`.json`, `.xml`, `.vtu`).
pub(crate) fn convert(name: &str, map: &HierarchicalMap, input: &Path, output: &Path, thb: bool) -> Result<i32> {
    if thb {
        files::OutputPlan::new().input(input).file("-o", output, "THB map", &["json", "xml", "vtu"]).check()?;
        let c = certify_hierarchical(map, &CertifyOptions::default()).context("certifying the THB map")?;
        let extra = Some(serde_json::json!({ "report": { "certificate": &c } }));
        let label = format!("certificate: {}", c.message());
        files::write(output, &Output::Thb { name, map, label: &label, extra })?;
        say!("certificate: {}", c.message());
        return Ok(exit_code(&c.verdict));
    }
    files::OutputPlan::new().input(input).file("-o", output, "map", files::ext::MAP).check()?;
    let tensor = map.to_surface().context("converting the THB map to a tensor map")?;
    let certificate = certify(&tensor, &CertifyOptions::default()).context("certifying the map")?;
    let label = format!("certificate: {}", certificate.message());
    let extra = Some(serde_json::json!({ "certificate": &certificate }));
    files::write(output, &Output::Map { name, map: &tensor, label: &label, extra })?;
    say!(
        "{} THB functions on {} levels -> tensor map of {} x {} control points; {label}",
        map.basis.len(),
        map.basis.num_levels(),
        tensor.shape()[0],
        tensor.shape()[1]
    );
    Ok(exit_code(&certificate.verdict))
}

/// `winslow solve --refinement thb|auto` when the pipeline repaired the map by THB
/// defect correction: the THB map written with its report (the certificate, the rounds
/// and the tensor solve's report), which `--json` prints: `-o` and `--gismo`
/// (`THBSpline2`) as a THB map, `--vtu` with a Bézier cell per active cell, `--iges`
/// and `--vtk` as its exact tensor form (`winslow::io` picks by extension).
pub(crate) fn finish(out: &ThbSolution, a: &SolveArgs) -> Result<i32> {
    let json = a.json;
    let report = serde_json::to_value(&out.report)?;
    let c = &out.report.certificate;
    let label = format!("verdict {:?}: {}", out.report.verdict, out.report.message);
    let extra = Some(serde_json::json!({ "report": &report }));
    let thb = Output::Thb { name: &out.name, map: &out.map, label: &label, extra };
    files::write(&a.output, &thb)?;
    for (path, ext) in [(&a.gismo, "xml"), (&a.iges, "igs"), (&a.vtu, "vtu"), (&a.vtk, "vtk")] {
        if let Some(p) = path {
            files::write_as(p, ext, &thb)?;
        }
    }
    if json {
        files::print_json(report)?;
    } else {
        say!(
            "{}: tensor solve {:?} without repair; {} THB round(s) -> {} functions on {} levels ({} unknowns)",
            out.name,
            out.report.solve.outcome.verdict,
            out.report.thb_rounds.len(),
            out.map.basis.len(),
            out.map.basis.num_levels(),
            out.report.unknowns
        );
        let st = &out.report.start;
        match &st.reason {
            None => say!(
                "THB start: the contour fit's THB basis ({} functions on {} levels, each side refined along \
                 itself only), EGG in {} Newton iteration(s): {:?}",
                st.functions,
                st.levels,
                st.iterations,
                st.verdict
            ),
            Some(why) => say!("THB start: the tensor map ({} functions): {why}", st.functions),
        }
        say!("certificate: {}", c.message());
        if let Some(imp) = &out.report.improvement {
            say!("improvement: {}", imp.message);
        }
        if let Some(p) = &out.report.poisson {
            let mut s = String::new();
            crate::output::poisson_line(&mut s, p);
            say_raw!("{s}");
        }
    }
    if let Some(p) = &a.png {
        let image = render_thb(&out.map, &PictureOptions::default()).context("drawing the THB map")?;
        files::write(p, &Output::Picture(&image))?;
    }
    if let Some(p) = &a.mesh {
        // a folded map gives inverted cells, which the writers refuse
        crate::mesh::make_and_write_thb(&out.map, &a.mesh_spec, p, json)?;
    }
    // as for a tensor map: 6 for a bijective map whose boundary is not the input's or
    // whose kinks the C0 route could not keep (the THB rounds start from its map)
    let r = &out.report.solve;
    Ok(match exit_code(&c.verdict) {
        0 if !r.boundary.kept || !r.kinks_kept() => 6,
        code => code,
    })
}
