//! Trivariate maps (volumes, [`Volume`]) in files: the JSON map document with three
//! degrees and knot vectors ([`json`], the format of `formats.md`'s "Trivariate map",
//! plus a `periodic` field), G+Smo XML `TensorBSpline3` / `TensorNurbs3` (read here in
//! [`gismo`], written by [`crate::io::gismo_writer::volume_to_gismo_xml`]) and VTK
//! ([`vtk`]: a sampled structured grid with `det J`, and the exact map as Bézier
//! hexahedra).
//!
//! [`parse_volume_document`] decides by content whether a document is a volume (a JSON
//! `map` whose `degree` has three entries, or an XML file with a `TensorBSpline3` /
//! `TensorNurbs3` geometry) and answers `None` for every other document, which the
//! planar readers ([`crate::io::read_document`]) then handle.

pub mod gismo;
pub mod json;
pub mod vtk;

use std::path::Path;

use serde_json::Value;

use crate::error::{Error, Result};
use crate::spline::volume::Volume;
pub use json::{volume_to_json, VolumeJson};

/// A volume read from a document.
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeDocument {
    /// Name of the geometry (the file stem when the document has none).
    pub name: String,
    /// The volume, knot domains mapped to `[0, 1]`.
    pub volume: Volume,
}

/// Whether a JSON value is a trivariate map document: `map.degree` has three entries.
fn is_volume_json(v: &Value) -> bool {
    v.get("map").and_then(|m| m.get("degree")).and_then(Value::as_array).is_some_and(|d| d.len() == 3)
}

/// The volume of a document, or `None` when the document is not a volume (see the module
/// documentation). A document that claims to be a volume but is malformed is an error.
pub fn parse_volume_document(text: &str) -> Result<Option<VolumeDocument>> {
    let body = text.trim_start_matches('\u{feff}').trim_start();
    match body.chars().next() {
        Some('{') => {
            let v: Value = serde_json::from_str(body)
                .map_err(|e| Error::Json { context: String::new(), message: e.to_string() })?;
            if !is_volume_json(&v) {
                return Ok(None);
            }
            json::parse_volume_json(v).map(Some)
        }
        Some('<') if body.contains("TensorBSpline3") || body.contains("TensorNurbs3") => {
            let volume = gismo::parse_gismo_volume(body)?;
            Ok(Some(VolumeDocument { name: String::new(), volume }))
        }
        _ => Ok(None),
    }
}

/// Read a volume from a file (JSON or G+Smo XML), `None` when it holds no volume. A
/// document without a name is named after the file stem.
pub fn read_volume(path: &Path) -> Result<Option<VolumeDocument>> {
    let text = super::read_text(path)?;
    let mut doc = parse_volume_document(&text)?;
    if let Some(d) = doc.as_mut().filter(|d| d.name.is_empty()) {
        d.name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    }
    Ok(doc)
}
