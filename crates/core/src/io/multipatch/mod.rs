//! Multipatch files (paper §11.2): the JSON multipatch document of `formats.md` with
//! named curves ([`mod@json`]), G+Smo XML `<MultiPatch>` files with G+Smo's side numbering
//! and orientation flags ([`mod@gismo`]), and the output of a set of patch maps
//! ([`Patches`]: the JSON document, G+Smo XML, a VTK multiblock file `.vtm` referencing
//! one exact Bézier `.vtu` per patch, one JSON map document per patch).
//!
//! Layouts and results are read by [`crate::io::read`] and written by
//! [`crate::io::write`] ([`crate::io::Output::Multipatch`]).

pub mod gismo;
pub mod json;

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use self::gismo::multipatch_to_gismo_xml;
use self::json::multipatch_to_json;
use crate::error::{Error, Result};
use crate::io::vtk::bezier_vtu;
use crate::io::{map_to_json, write_bytes, write_json};
use crate::multipatch::solve::{MultipatchSolution, PatchSolution};
use crate::multipatch::Layout;
use crate::spline::surface::Surface;

/// Patch maps of a layout with what is written beside them: the content of a multipatch
/// output file.
#[derive(Debug, Clone)]
pub struct Patches<'a> {
    /// The layout (names, interfaces, outer sides).
    pub layout: &'a Layout,
    /// One map per patch, in the layout's order.
    pub maps: Vec<Surface>,
    /// One report per patch (`null` for none): the `report` of each patch in JSON.
    pub reports: Vec<Value>,
    /// One line per patch (its certificate's message): the comment of its `.vtu`.
    pub messages: Vec<String>,
    /// The report of the whole: the top-level `report` in JSON.
    pub report: Value,
    /// One line for the whole: the comment of the G+Smo file.
    pub message: String,
}

impl<'a> Patches<'a> {
    /// The patches of a solved layout with their reports (`patch_report`).
    pub fn of_solution(sol: &'a MultipatchSolution) -> Result<Self> {
        Ok(Self {
            layout: &sol.layout,
            maps: sol.maps(),
            reports: sol.patches.iter().map(patch_report).collect(),
            messages: sol.patches.iter().map(|p| p.certificate.message()).collect(),
            report: serde_json::to_value(&sol.report).map_err(|e| Error::Invalid(e.to_string()))?,
            message: sol.report.message.clone(),
        })
    }

    /// The JSON multipatch document (`formats.md`).
    pub fn to_json(&self) -> Result<Value> {
        multipatch_to_json(self.layout, &self.maps, self.reports.clone(), self.report.clone())
    }

    /// The G+Smo XML multipatch document.
    pub(crate) fn to_gismo_xml(&self) -> Result<String> {
        let comment = format!("winslow {}: {}", env!("CARGO_PKG_VERSION"), self.message);
        multipatch_to_gismo_xml(self.layout, &self.maps, &comment)
    }

    fn check(&self) -> Result<()> {
        let n = self.layout.patches.len();
        if [self.maps.len(), self.reports.len(), self.messages.len()].iter().any(|&m| m != n) {
            return Err(Error::Invalid(format!(
                "{} maps, {} reports and {} messages for {} patches",
                self.maps.len(),
                self.reports.len(),
                self.messages.len(),
                n
            )));
        }
        Ok(())
    }

    /// A VTK multiblock file `path` (`.vtm`) whose blocks are the patches, each an exact
    /// Bézier `.vtu` in the folder next to it named after the file stem; returns the
    /// paths written (the `.vtm` first). Every file goes through the atomic writer.
    pub(crate) fn write_vtm(&self, path: &Path) -> Result<Vec<PathBuf>> {
        self.check()?;
        let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "layout".into());
        let dir = path.with_file_name(&stem);
        let mut blocks = String::new();
        let mut written = vec![path.to_path_buf()];
        for (k, (p, map)) in self.layout.patches.iter().zip(&self.maps).enumerate() {
            let file = format!("{}.vtu", file_safe(&p.name));
            let text = bezier_vtu(map, &format!("patch {} of {}: {}", p.name, self.layout.name, self.messages[k]))?;
            let fp = dir.join(&file);
            write_bytes(&fp, text.as_bytes())?;
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
        write_bytes(path, vtm.as_bytes())?;
        Ok(written)
    }
}

/// The report of one patch: its verdict, certificate and Winslow value (of the final
/// map) and the report of its fixed-interface solve.
pub(crate) fn patch_report(p: &PatchSolution) -> Value {
    let w = crate::verify::quality::quality(&p.map).functionals.winslow;
    json!({
        "verdict": p.verdict,
        "message": p.certificate.message(),
        "certificate": p.certificate,
        "winslow": w.is_finite().then_some(w),
        "solve": p.solve,
    })
}

/// One JSON map document per patch, `DIR/NAME.json` for each patch `NAME`, with the
/// patch's report; returns the paths written.
pub fn write_patch_maps(sol: &MultipatchSolution, dir: &Path) -> Result<Vec<PathBuf>> {
    // two patch names that differ only in characters a file name cannot hold would
    // write one file twice: refused before anything is written
    let mut taken: std::collections::HashMap<String, &str> = std::collections::HashMap::new();
    for p in &sol.patches {
        if let Some(other) = taken.insert(file_safe(&p.name), &p.name) {
            return Err(crate::error::Error::Invalid(format!(
                "patches '{other}' and '{}' would both be written to {}.json in {}",
                p.name,
                file_safe(&p.name),
                dir.display()
            )));
        }
    }
    let mut out = Vec::new();
    for p in &sol.patches {
        let path = dir.join(format!("{}.json", file_safe(&p.name)));
        let doc = map_to_json(&p.name, &p.map, Some(json!({ "report": patch_report(p) })));
        write_json(&path, &doc)?;
        out.push(path);
    }
    Ok(out)
}

/// `name` with every character outside `[A-Za-z0-9._-]` replaced by `_`.
fn file_safe(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || "._-".contains(c) { c } else { '_' }).collect()
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
