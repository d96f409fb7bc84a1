//! THB maps (`winslow::spline::hierarchical`) in `winslow check` and `winslow convert`:
//! a file holding a THB map (the JSON map kind `"thb"` or G+Smo `THBSpline2`) is certified
//! active cell by active cell, and converted to the tensor map on the knot lines of its
//! active cells (exact knot insertion) or, with `--thb`, written as a THB map again.

use std::path::Path;

use anyhow::{Context, Result};
use winslow::io::hierarchical::{read_thb, write_thb};
use winslow::io::Output;
use winslow::solve::hierarchical::{repair_thb, ThbRepairOptions};
use winslow::solve::options::SolveOptions;
use winslow::solve::report::Solution;
use winslow::spline::hierarchical::map::HierarchicalMap;
use winslow::verify::certificate::hierarchical::certify_hierarchical;
use winslow::verify::certificate::{certify, CertifyOptions, Finding};

use crate::files;

/// The THB map in `path`, `None` when the file holds another kind of document.
pub(crate) fn read(path: &Path) -> Result<Option<(String, HierarchicalMap)>> {
    // named once, as every command's read names its file (`files::named`)
    read_thb(path).map_err(|e| files::named(e, "reading", path))
}

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
/// the file) by the output's extension, or the THB map itself (`.json`, `.xml`).
pub(crate) fn convert(name: &str, map: &HierarchicalMap, input: &Path, output: &Path, thb: bool) -> Result<i32> {
    if thb {
        files::OutputPlan::new().input(input).file("-o", output, "THB map", &["json", "xml"]).check()?;
        let c = certify_hierarchical(map, &CertifyOptions::default()).context("certifying the THB map")?;
        let extra = Some(serde_json::json!({ "report": { "certificate": &c } }));
        write_thb(output, name, map, extra).with_context(|| format!("writing {}", output.display()))?;
        files::record(output);
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

/// `winslow solve --refinement thb`: the pipeline's map folds or is undecided without
/// tensor repair; the THB defect correction ([`repair_thb`]) refines only around the
/// offending cells, and the THB map is written (`-o`, and `--gismo` as `THBSpline2`) with
/// its certificate, the rounds and the tensor solve's report.
pub(crate) fn repair(
    sol: &Solution,
    opts: &SolveOptions,
    output: &Path,
    gismo: Option<&Path>,
    json: bool,
) -> Result<i32> {
    let t0 = std::time::Instant::now();
    let start = HierarchicalMap::from_surface(&sol.map).context("THB refinement of the solved map")?;
    let topts = ThbRepairOptions {
        rounds: opts.repair.rounds,
        ring: opts.repair.halo,
        operator: opts.operator,
        nonlinear: opts.nonlinear,
        certify: opts.certify,
        ..Default::default()
    };
    let out = repair_thb(start, &topts).context("THB defect correction")?;
    let c = &out.certificate;
    let unknowns = out.rounds.last().map_or(0, |r| r.unknowns);
    let report = serde_json::json!({
        "refinement": "thb",
        "verdict": c.verdict.name(),
        "message": c.message(),
        "certificate": c,
        "functions": out.map.basis.len(),
        "levels": out.map.basis.num_levels(),
        "unknowns": unknowns,
        "thb_rounds": &out.rounds,
        "thb_seconds": t0.elapsed().as_secs_f64(),
        "solve": &sol.report,
    });
    let extra = Some(serde_json::json!({ "report": &report }));
    write_thb(output, &sol.name, &out.map, extra.clone()).with_context(|| format!("writing {}", output.display()))?;
    files::record(output);
    if let Some(p) = gismo {
        write_thb(p, &sol.name, &out.map, extra).with_context(|| format!("writing {}", p.display()))?;
        files::record(p);
    }
    if json {
        files::print_json(report)?;
    } else {
        say!(
            "{}: tensor solve {:?} without repair; {} THB round(s) -> {} functions on {} levels ({unknowns} unknowns)",
            sol.name,
            sol.report.verdict,
            out.rounds.len(),
            out.map.basis.len(),
            out.map.basis.num_levels()
        );
        say!("certificate: {}", c.message());
    }
    Ok(exit_code(&c.verdict))
}
