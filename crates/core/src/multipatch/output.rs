//! Writing a solved layout: the JSON multipatch document (every patch a map with its
//! report, [`super::json`]), one JSON map document per patch, G+Smo XML
//! ([`super::gismo`]), a VTK multiblock file (`.vtm`) referencing one exact Bézier
//! `.vtu` per patch ([`crate::io::vtk::bezier_vtu`]), and the reading of any multipatch
//! file ([`read_layout`]).

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use super::gismo::{is_gismo_multipatch, multipatch_to_gismo_xml, parse_gismo_multipatch};
use super::json::{is_json_multipatch, multipatch_to_json, parse_json_multipatch};
use super::layout::Layout;
use super::solve::{MultipatchSolution, PatchSolution};
use crate::error::{Error, Result};
use crate::io::vtk::bezier_vtu;
use crate::io::{map_to_json, read_text};

/// A layout from a multipatch file (G+Smo XML with a `<MultiPatch>`, or a JSON document
/// with `patches`), named after the file stem when it has no name; `None` when the file
/// is not a multipatch document or is a G+Smo file of one patch without interfaces (G+Smo
/// writes single maps that way; they are read as maps by [`crate::io::read_document`]).
pub fn read_layout(path: &Path) -> Result<Option<Layout>> {
    let text = read_text(path)?;
    let mut layout = if is_gismo_multipatch(&text) {
        let layout = parse_gismo_multipatch(&text)?;
        if layout.patches.len() == 1 && layout.interfaces.is_empty() {
            // G+Smo wraps single patches in <MultiPatch> too: that is a map, read by
            // `io::read_document` (and solved with its own options, e.g. `--basis auto`)
            return Ok(None);
        }
        layout
    } else if is_json_multipatch(&text) {
        parse_json_multipatch(&text)?
    } else {
        return Ok(None);
    };
    if layout.name.is_empty() {
        layout.name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    }
    Ok(Some(layout))
}

/// The report of one patch: its verdict, certificate and Winslow value (of the final
/// map) and the report of its fixed-interface solve.
pub fn patch_report(p: &PatchSolution) -> Value {
    let w = crate::verify::quality::quality(&p.map).functionals.winslow;
    json!({
        "verdict": p.verdict,
        "message": p.certificate.message(),
        "certificate": p.certificate,
        "winslow": w.is_finite().then_some(w),
        "solve": p.solve,
    })
}

/// The JSON multipatch document of a solution (`formats.md`).
pub fn solution_to_json(sol: &MultipatchSolution) -> Result<Value> {
    let maps = sol.maps();
    let reports = sol.patches.iter().map(patch_report).collect();
    let report = serde_json::to_value(&sol.report).map_err(|e| Error::Invalid(e.to_string()))?;
    multipatch_to_json(&sol.layout, &maps, reports, report)
}

/// The G+Smo XML multipatch document of a solution.
pub fn solution_to_gismo_xml(sol: &MultipatchSolution) -> Result<String> {
    let comment = format!("winslow {}: {}", env!("CARGO_PKG_VERSION"), sol.report.message);
    multipatch_to_gismo_xml(&sol.layout, &sol.maps(), &comment)
}

/// One JSON map document per patch, `DIR/NAME.json` for each patch `NAME`, with the
/// patch's report; returns the paths written.
pub fn write_patch_maps(sol: &MultipatchSolution, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io { path: dir.to_path_buf(), source })?;
    let mut out = Vec::new();
    for p in &sol.patches {
        let path = dir.join(format!("{}.json", file_safe(&p.name)));
        let doc = map_to_json(&p.name, &p.map, Some(json!({ "report": patch_report(p) })));
        crate::io::write_json(&path, &doc)?;
        out.push(path);
    }
    Ok(out)
}

/// `name` with every character outside `[A-Za-z0-9._-]` replaced by `_`.
fn file_safe(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || "._-".contains(c) { c } else { '_' }).collect()
}

/// A VTK multiblock file `path` (`.vtm`) whose blocks are the patches, each an exact
/// Bézier `.vtu` in the directory next to it named after the file stem; returns the
/// paths written (the `.vtm` first).
pub fn write_vtm(sol: &MultipatchSolution, path: &Path) -> Result<Vec<PathBuf>> {
    let io = |p: &Path| {
        let p = p.to_path_buf();
        move |source| Error::Io { path: p, source }
    };
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "layout".into());
    let dir = path.with_file_name(&stem);
    std::fs::create_dir_all(&dir).map_err(io(&dir))?;
    let mut blocks = String::new();
    let mut written = vec![path.to_path_buf()];
    for (k, p) in sol.patches.iter().enumerate() {
        let file = format!("{}.vtu", file_safe(&p.name));
        let text =
            bezier_vtu(&p.map, &format!("patch {} of {}: {}", p.name, sol.layout.name, p.certificate.message()))?;
        let fp = dir.join(&file);
        std::fs::write(&fp, text).map_err(io(&fp))?;
        blocks.push_str(&format!(
            "    <DataSet index=\"{k}\" name=\"{}\" file=\"{}/{}\"/>\n",
            xml_escape(&p.name),
            xml_escape(&stem),
            xml_escape(&file)
        ));
        written.push(fp);
    }
    let vtm = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <vtkMultiBlockDataSet>\n{blocks}  </vtkMultiBlockDataSet>\n</VTKFile>\n"
    );
    std::fs::write(path, vtm).map_err(io(path))?;
    Ok(written)
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
