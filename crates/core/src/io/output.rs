//! What can be written ([`Output`]) and the one writer that picks the format by the
//! file's extension ([`write()`]), like meshio's `write`. Every file goes through the
//! atomic writer ([`super::file::write_with`]).
//!
//! | output | extensions |
//! |---|---|
//! | map | `.json` (map document with the extra fields), `.xml` (G+Smo), `.igs`/`.iges` (IGES 5.3 entity 128), `.vtu` (exact Bézier cells), `.vtk` (sampled structured grid) |
//! | THB map | `.json` (the `thb` map kind with the extra fields), `.xml` (G+Smo `THBSpline2`), `.vtu` (one exact Bézier cell per active cell), `.igs`/`.iges` and `.vtk` (the exact tensor form, by knot insertion) |
//! | volume | `.json`, `.xml` (G+Smo `TensorBSpline3`), `.vtu` (Bézier hexahedra), `.vtk` (sampled grid) |
//! | multipatch | `.json` (multipatch document), `.xml` (G+Smo `<MultiPatch>`), `.vtm` (VTK multiblock, one `.vtu` per patch in a folder beside it) |
//! | layout, boundary, ring | `.json` |
//! | volume boundary | `.json`, `.xml` (G+Smo `<MultiPatch>` of six faces, `geoDim="3"`) |
//! | picture | `.png` |
//!
//! A file without an extension is JSON (pictures excepted). Any other extension is an
//! [`Error::Extension`] naming the kind and the extensions it is written as.

use std::path::Path;

use serde_json::Value;

use super::file::{write_bytes, write_with};
use super::gismo_writer::{surface_to_gismo_xml, volume_to_gismo_xml};
use super::hierarchical::{thb_to_gismo_xml, thb_to_json};
use super::iges::surface_to_iges;
use super::json::{boundary_to_json, map_to_json, write_json};
use super::multipatch::json::layout_to_json;
use super::multipatch::Patches;
use super::picture::Image;
use super::ring::ring_to_json;
use super::volume::json::volume_to_json;
use super::volume::vtk::{volume_bezier_vtu, volume_structured_vtk};
use super::vtk::{bezier_vtu, structured_grid_vtk, thb_bezier_vtu};
use crate::boundary::ring::Ring;
use crate::boundary::Boundary;
use crate::domain::{Domain, PlaneGraph};
use crate::error::{Error, Result};
use crate::multipatch::Layout;
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::surface::Surface;
use crate::spline::volume::Volume;

/// Samples per direction of a map's `.vtk` grid.
const MAP_VTK_SAMPLES: usize = 128;

/// Something to write.
#[derive(Debug, Clone)]
pub enum Output<'a> {
    /// A planar map.
    Map {
        /// Name of the geometry (the JSON `name`).
        name: &'a str,
        /// The map.
        map: &'a Surface,
        /// One line (e.g. the verdict) for the file's comment, where the format has one.
        label: &'a str,
        /// Further top-level fields of the JSON document (e.g. `{"report": ...}`).
        extra: Option<Value>,
    },
    /// A THB map ([`super::hierarchical`]).
    Thb {
        /// Name of the geometry (the JSON `name`).
        name: &'a str,
        /// The map.
        map: &'a HierarchicalMap,
        /// One line (e.g. the verdict) for the file's comment, where the format has one.
        label: &'a str,
        /// Further top-level fields of the JSON document (e.g. `{"report": ...}`).
        extra: Option<Value>,
    },
    /// A trivariate map.
    Volume {
        /// Name of the geometry.
        name: &'a str,
        /// The volume.
        volume: &'a Volume,
        /// One line for the file's comment.
        label: &'a str,
        /// Further top-level fields of the JSON document.
        extra: Option<Value>,
    },
    /// Patch maps of a layout, e.g. a solved layout ([`Patches::of_solution`]).
    Multipatch(Patches<'a>),
    /// A multipatch layout as input: every patch by its four sides.
    Layout(&'a Layout),
    /// A four-sided boundary.
    Boundary(&'a Boundary),
    /// A ring (analytic contours become point clouds).
    Ring(&'a Ring),
    /// A general planar domain.
    Domain(&'a Domain),
    /// The six boundary faces of a hexahedral volume.
    VolumeBoundary(&'a crate::boundary::volume::VolumeBoundary),
    /// A plane graph.
    Graph(&'a PlaneGraph),
    /// A picture ([`super::picture::render`]).
    Picture(&'a Image),
}

impl Output<'_> {
    /// The kind, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Output::Map { .. } => "map",
            Output::Thb { .. } => "THB map",
            Output::Volume { .. } => "volume",
            Output::Multipatch(_) => "multipatch result",
            Output::Layout(_) => "multipatch layout",
            Output::Boundary(_) => "boundary",
            Output::Ring(_) => "ring",
            Output::Domain(_) => "domain",
            Output::VolumeBoundary(_) => "volume boundary",
            Output::Graph(_) => "graph",
            Output::Picture(_) => "picture",
        }
    }

    /// The extensions this kind is written as, for messages.
    fn accepted(&self) -> &'static str {
        match self {
            Output::Map { .. } => ".json, .xml, .igs, .iges, .vtu or .vtk",
            Output::Volume { .. } => ".json, .xml, .vtu or .vtk",
            Output::Multipatch(_) => ".json, .xml or .vtm",
            Output::Layout(_) | Output::Boundary(_) | Output::Ring(_) | Output::Domain(_) | Output::Graph(_) => ".json",
            Output::Thb { .. } => ".json, .xml, .vtu (a Bézier cell per active cell), .igs, .iges or .vtk",
            Output::VolumeBoundary(_) => ".json or .xml",
            Output::Picture(_) => ".png",
        }
    }
}

/// The extension of `path`, lower case, without the dot (empty when it has none).
fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Write `out` to `path` in the format of the path's extension (see the module
/// documentation).
pub fn write(path: &Path, out: &Output) -> Result<()> {
    write_as(path, &extension(path), out)
}

/// Write `out` to `path` in the format of `extension` (without the dot, e.g. `"xml"`),
/// whatever the path's own extension.
pub fn write_as(path: &Path, extension: &str, out: &Output) -> Result<()> {
    let ext = extension.to_ascii_lowercase();
    let refused = || Error::Extension {
        path: path.to_path_buf(),
        kind: out.kind().to_string(),
        extension: ext.clone(),
        accepted: out.accepted().to_string(),
    };
    let text = |s: String| write_bytes(path, s.as_bytes());
    match (out, ext.as_str()) {
        (Output::Map { name, map, extra, .. }, "json" | "") => write_json(path, &map_to_json(name, map, extra.clone())),
        (Output::Map { map, label, .. }, "xml") => text(surface_to_gismo_xml(map, label)),
        (Output::Map { name, map, label, .. }, "igs" | "iges") => {
            let file_name = path.file_name().map_or_else(|| name.to_string(), |f| f.to_string_lossy().into_owned());
            text(surface_to_iges(map, &file_name, label))
        }
        (Output::Map { map, label, .. }, "vtu") => text(bezier_vtu(map, label)?),
        (Output::Map { map, .. }, "vtk") => text(structured_grid_vtk(map, MAP_VTK_SAMPLES)),
        (Output::Thb { name, map, extra, .. }, "json" | "") => write_json(path, &thb_to_json(name, map, extra.clone())),
        (Output::Thb { map, label, .. }, "xml") if map.basis.given_levels().is_empty() => {
            text(thb_to_gismo_xml(map, label))
        }
        (Output::Thb { map, label, .. }, "vtu") => text(thb_bezier_vtu(map, label)?),
        // formats without hierarchical splines (and G+Smo's THBSplineBasis2, whose levels
        // halve, for a map on given levels): the exact tensor form (knot insertion)
        (Output::Thb { name, map, label, .. }, "igs" | "iges" | "vtk" | "xml") => {
            let tensor = map.to_surface()?;
            let label = format!("{label} (the THB map's exact tensor form)");
            write_as(path, &ext, &Output::Map { name, map: &tensor, label: &label, extra: None })
        }
        (Output::Volume { name, volume, extra, .. }, "json" | "") => {
            write_json(path, &volume_to_json(name, volume, extra.clone()))
        }
        (Output::Volume { volume, label, .. }, "xml") => text(volume_to_gismo_xml(volume, label)),
        (Output::Volume { volume, label, .. }, "vtu") => text(volume_bezier_vtu(volume, label)?),
        (Output::Volume { volume, .. }, "vtk") => {
            let samples = volume.knots.each_ref().map(|k| (4 * k.num_elements()).clamp(8, 256));
            text(volume_structured_vtk(volume, samples))
        }
        (Output::Multipatch(p), "json" | "") => write_json(path, &p.to_json()?),
        (Output::Multipatch(p), "xml") => text(p.to_gismo_xml()?),
        (Output::Multipatch(p), "vtm") => p.write_vtm(path).map(|_| ()),
        (Output::Layout(l), "json" | "") => write_json(path, &layout_to_json(l)),
        (Output::Boundary(b), "json" | "") => write_json(path, &boundary_to_json(b)),
        (Output::Ring(r), "json" | "") => write_json(path, &ring_to_json(r)),
        (Output::Domain(d), "json" | "") => write_json(path, &super::domain::domain_to_json(d)),
        (Output::VolumeBoundary(b), "json" | "") => write_json(path, &super::volume::volume_boundary_to_json(b)),
        (Output::VolumeBoundary(b), "xml") => text(super::volume::volume_boundary_to_gismo_xml(b, &b.name)),
        (Output::Graph(g), "json" | "") => write_json(path, &super::graph::graph_to_json(g)),
        (Output::Picture(img), "png") => write_png(path, img),
        _ => Err(refused()),
    }
}

/// Encode an RGBA image as PNG (8 bits per channel).
fn write_png(path: &Path, img: &Image) -> Result<()> {
    let (width, height) = (u32::try_from(img.width), u32::try_from(img.height));
    let (Ok(width), Ok(height)) = (width, height) else {
        return Err(Error::Invalid(format!("a picture of {} x {} pixels is too large", img.width, img.height)));
    };
    if img.rgba.len() != 4 * img.width * img.height {
        return Err(Error::Length {
            context: "picture".into(),
            what: "RGBA bytes".into(),
            found: img.rgba.len(),
            expected: 4 * img.width * img.height,
        });
    }
    write_with(path, |w| {
        let mut enc = png::Encoder::new(w, width, height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        writer.write_image_data(&img.rgba).map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    })
}

#[cfg(test)]
mod tests;
