//! Reading and writing: the JSON exchange formats of `formats.md` ([`json`]), G+Smo
//! XML files ([`gismo`] reads, [`gismo_writer`] writes), IGES 5.3 rational B-spline
//! surfaces ([`iges`], both ways), VTK files ([`vtk`]: a sampled structured grid, and the
//! exact map as Bézier cells) and pictures of a map, grid lines coloured by `det J`
//! ([`picture`], PNG through the CLI); ring (O-type) documents ([`ring`]); trivariate
//! maps (volumes) in JSON, G+Smo XML and VTK ([`volume`]).
//!
//! [`read_document`] detects the kind of file by its content (a JSON object or an XML
//! document); [`read_boundary`] turns any accepted document into a validated,
//! counter-clockwise [`Boundary`]. All inputs are untrusted: every malformed file gives
//! an [`Error`] naming what is wrong and where, never a panic.

pub mod gismo;
pub mod gismo_writer;
pub mod iges;
pub mod json;
pub mod picture;
pub mod ring;
pub mod volume;
pub mod vtk;

use std::io::Read;
use std::path::Path;

use crate::boundary::validate::{inspect, validate, Orientation, ValidationReport};
use crate::boundary::{Boundary, SideCurve};
use crate::error::{Error, Result};
use crate::spline::curve::Curve;
use crate::spline::knots::KnotVector;
use crate::spline::surface::{Side, Surface};

pub use gismo::parse_gismo_xml;
pub use json::{
    boundary_to_contour_json, boundary_to_json, curve_to_json, map_to_json, parse_json, split_contour, write_json,
    BoundaryDoc, ContourDoc, ContourJson, CurveJson, MapDoc, MapJson, PointsJson, SideJson, SidesJson,
};

/// Largest file [`read_document`] accepts: 256 MiB.
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// A document read from a file.
// A boundary is not much larger than a map and documents are few: no boxing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum Document {
    /// A boundary: a boundary or contour JSON document, or four G+Smo curves.
    Boundary(Boundary),
    /// A tensor-product map: a map JSON document or one G+Smo tensor patch.
    Map {
        /// Name of the geometry.
        name: String,
        /// The map, knot domains mapped to `[0, 1]`.
        map: Surface,
    },
}

impl Document {
    /// Name of the geometry (empty when the file gave none).
    pub fn name(&self) -> &str {
        match self {
            Document::Boundary(b) => &b.name,
            Document::Map { name, .. } => name,
        }
    }

    fn set_name_if_empty(&mut self, fallback: &str) {
        let name = match self {
            Document::Boundary(b) => &mut b.name,
            Document::Map { name, .. } => name,
        };
        if name.is_empty() {
            *name = fallback.to_string();
        }
    }

    /// The boundary: itself, or the four boundary curves of a map (`Surface::boundary`;
    /// a side whose weights are all 1 becomes a polynomial curve, as in `Curve::new`).
    pub fn into_boundary(self) -> Boundary {
        match self {
            Document::Boundary(b) => b,
            Document::Map { name, map } => {
                let side = |s: Side| {
                    let mut c = map.boundary(s);
                    if c.weights.as_ref().is_some_and(|w| w.iter().all(|&x| x == 1.0)) {
                        c.weights = None;
                    }
                    SideCurve::Spline(c)
                };
                Boundary { name, sides: Side::ALL.map(side) }
            }
        }
    }
}

/// Options of [`read_boundary`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Accept a clockwise contour and return it transposed (`Boundary::transposed`,
    /// which is counter-clockwise) instead of failing with [`Error::Clockwise`].
    pub reorient: bool,
}

/// Read a whole file as UTF-8 text, refusing files above [`MAX_FILE_BYTES`].
pub fn read_text(path: &Path) -> Result<String> {
    let io = |source: std::io::Error| Error::Io { path: path.to_path_buf(), source };
    let file = std::fs::File::open(path).map_err(io)?;
    let too_large = |found: u64| Error::TooLarge {
        context: path.display().to_string(),
        what: "file size in bytes".into(),
        found: usize::try_from(found).unwrap_or(usize::MAX),
        limit: MAX_FILE_BYTES as usize,
    };
    if let Ok(meta) = file.metadata() {
        if meta.len() > MAX_FILE_BYTES {
            return Err(too_large(meta.len()));
        }
    }
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|e| Error::Invalid(format!("{} is not UTF-8 text: {e}", path.display())))
}

/// Parse a document from text: JSON when it starts with `{`, G+Smo XML when it starts
/// with `<` (after a byte-order mark and white space), IGES when its first record has the
/// Start-section letter in column 73 (a map, transposed when its boundary runs
/// clockwise, as for G+Smo patches).
pub fn parse_document(text: &str) -> Result<Document> {
    if iges::is_iges(text) {
        let mut map = iges::parse_iges(text)?;
        if surface_boundary_area(&map) < 0.0 {
            map = map.transposed();
        }
        return Ok(Document::Map { name: String::new(), map });
    }
    let body = text.trim_start_matches('\u{feff}').trim_start();
    match body.chars().next() {
        Some('{') => parse_json(body),
        Some('<') => parse_gismo_xml(body),
        Some(c) => Err(Error::Invalid(format!(
            "the input is neither a JSON object nor an XML document (it starts with {c:?})"
        ))),
        None => Err(Error::Invalid("the input is empty".into())),
    }
}

/// Read a boundary, contour or map JSON document or a G+Smo XML file, detected by
/// content. A document without a name is named after the file stem.
pub fn read_document(path: &Path) -> Result<Document> {
    let text = read_text(path)?;
    let mut doc = parse_document(&text)?;
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    doc.set_name_if_empty(&stem);
    Ok(doc)
}

/// Validate a boundary read from somewhere and orient it: a clockwise contour is an
/// [`Error::Clockwise`] unless `opts.reorient`, which transposes it. Returns the
/// (possibly transposed) boundary and its validation report.
pub fn checked_boundary(boundary: Boundary, opts: &ReadOptions) -> Result<(Boundary, ValidationReport)> {
    let report = inspect(&boundary)?;
    if report.orientation == Orientation::CounterClockwise {
        return Ok((boundary, report));
    }
    if !opts.reorient {
        return Err(Error::Clockwise { area: report.signed_area });
    }
    let t = boundary.transposed();
    let report = validate(&t)?;
    Ok((t, report))
}

/// Read a boundary from any accepted document (boundary, contour or map JSON; G+Smo
/// XML with four curves or one patch), validate it ([`crate::boundary::validate::validate`]) and
/// return it counter-clockwise (see [`ReadOptions::reorient`]).
pub fn read_boundary(path: &Path, opts: &ReadOptions) -> Result<Boundary> {
    let doc = read_document(path)?;
    checked_boundary(doc.into_boundary(), opts).map(|(b, _)| b)
}

/// Re-validate a knot vector after mapping its domain to `[0, 1]` (the affine map can
/// overflow for absurd knots outside the domain, or merge knots closer than an ulp).
pub(crate) fn normalized_knots(kv: &KnotVector) -> Result<KnotVector> {
    let n = kv.normalized();
    KnotVector::with_periodic(n.degree(), n.knots().to_vec(), n.is_periodic())
}

/// A curve with its domain mapped to `[0, 1]`, re-validated.
pub(crate) fn normalized_curve(c: &Curve) -> Result<Curve> {
    Ok(Curve { knots: normalized_knots(&c.knots)?, ..c.clone() })
}

/// `Curve::reversed` without the possibility of a panic on unusual knots.
pub(crate) fn reversed_curve(c: &Curve) -> Result<Curve> {
    let (a, b) = c.domain();
    let knots: Vec<f64> = c
        .knots
        .knots()
        .iter()
        .rev()
        .map(|&t| {
            let r = a + b - t;
            if (r - a).abs() < 1e-15 * (b - a) {
                a
            } else {
                r
            }
        })
        .collect();
    let kv = KnotVector::with_periodic(c.degree(), knots, c.knots.is_periodic())?;
    let mut control_points = c.control_points.clone();
    control_points.reverse();
    let weights = c.weights.as_ref().map(|w| w.iter().rev().copied().collect());
    Ok(Curve { knots: kv, control_points, weights })
}

/// Signed area enclosed by south, east, reversed north, reversed west of a map's boundary
/// (shoelace on a coarse sampling); positive when the map preserves orientation.
pub(crate) fn surface_boundary_area(s: &Surface) -> f64 {
    let sides = Side::ALL.map(|side| SideCurve::Spline(s.boundary(side)));
    let mut area = 0.0;
    for (k, side) in sides.iter().enumerate() {
        let poly = crate::boundary::validate::sample_side(side, f64::INFINITY);
        let sign = if k < 2 { 1.0 } else { -1.0 };
        area += sign * poly.windows(2).map(|w| w[0][0] * w[1][1] - w[0][1] * w[1][0]).sum::<f64>();
    }
    0.5 * area
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detects_kind_by_content() {
        assert!(matches!(parse_document(""), Err(Error::Invalid(_))));
        assert!(matches!(parse_document("hello"), Err(Error::Invalid(_))));
        assert!(matches!(parse_document("\u{feff} {"), Err(Error::Json { .. })));
        assert!(matches!(parse_document("  <xml"), Err(Error::Xml { .. })));
    }

    #[test]
    fn deep_json_nesting_is_an_error() {
        let text = format!("{{\"boundary\": {}", "[".repeat(100_000));
        assert!(matches!(parse_document(&text), Err(Error::Json { .. })));
    }

    #[test]
    fn missing_file_is_io_error() {
        let e = read_document(Path::new("/nonexistent/winslow/nothing.json")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }));
        assert!(e.to_string().contains("nothing.json"));
    }

    #[test]
    fn reversal_matches_curve_reversed() {
        let kv = KnotVector::new(2, vec![0., 0., 0., 0.3, 1., 1., 1.]).unwrap();
        let c = Curve::new(kv, vec![[0., 0.], [1., 2.], [2., 0.], [3., 1.]], Some(vec![1., 2., 1., 1.])).unwrap();
        assert_eq!(reversed_curve(&c).unwrap(), c.reversed());
    }
}
