//! Reading and writing every format, like meshio's `read` and `write`: [`read`] decides
//! the kind of a file by its content and returns a [`Document`] (boundary, map, ring,
//! multipatch layout or result, volume); [`write()`] writes an [`Output`] in the format of
//! the file's extension, every file through one atomic writer ([`file::write_with`]).
//!
//! | module | holds |
//! |---|---|
//! | `document` | the kinds of document and the reader that tells them apart |
//! | [`output`] | what can be written, and the dispatch by extension |
//! | [`mod@file`] | reading text with a size limit; the atomic writer |
//! | [`json`] | the JSON exchange formats of `formats.md`: boundary, contour, map |
//! | `ring` | ring (O-type) documents |
//! | [`multipatch`] | multipatch layouts and results: JSON, G+Smo `<MultiPatch>`, VTK multiblock |
//! | `volume` | trivariate maps: JSON, G+Smo `TensorBSpline3`, VTK |
//! | `gismo` / `gismo_writer` | G+Smo XML, read and written |
//! | `iges` | IGES 5.3 rational B-spline surfaces (entity 128), both ways |
//! | `vtk` | a sampled structured grid, and the exact map as Bézier cells |
//! | [`picture`] | pictures of a map, grid lines coloured by `det J`, encoded as PNG |
//!
//! [`read_boundary`] turns any document with a four-sided boundary into a validated,
//! counter-clockwise [`Boundary`]. All inputs are untrusted: every malformed file gives
//! an [`Error`] naming what is wrong and where, never a panic.

pub(crate) mod document;
pub(crate) mod domain;
pub mod file;
pub(crate) mod gismo;
pub(crate) mod gismo_writer;
pub(crate) mod graph;
pub mod hierarchical;
pub(crate) mod iges;
pub mod json;
pub mod multipatch;
pub mod output;
pub mod picture;
pub(crate) mod ring;
pub(crate) mod volume;
pub(crate) mod vtk;

use std::path::Path;

use crate::boundary::validate::{inspect, validate, Orientation, ValidationReport};
use crate::boundary::{Boundary, SideCurve};
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::surface::{Side, Surface};

pub use document::{parse_document, read, read_with_report, Document};
pub use file::{read_text, write_bytes, write_with, MAX_FILE_BYTES};
pub use gismo::parse_gismo_xml;
pub use json::{
    boundary_to_contour_json, boundary_to_json, curve_to_json, map_to_json, parse_json, split_contour, write_json,
    BoundaryDoc, ContourDoc, ContourJson, CurveJson, MapDoc, MapJson, PointsJson, SideJson, SidesJson,
};
pub use multipatch::Patches;
pub use output::{write, Output};

/// Options of [`read_boundary`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Accept a clockwise contour and return it transposed (`Boundary::transposed`,
    /// which is counter-clockwise) instead of failing with [`Error::Clockwise`].
    pub reorient: bool,
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
    let doc = read(path)?;
    let boundary = doc.into_boundary().map_err(|e| document::at_path(e, path))?;
    checked_boundary(boundary, opts).map(|(b, _)| b)
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
    // relative to a point of the patch: far from the origin the products of raw
    // coordinates cancel every digit of the area (translation invariance)
    let o = s.control_points.first().copied().unwrap_or([0.0; 2]);
    let mut area = 0.0;
    for (k, side) in sides.iter().enumerate() {
        let poly = crate::boundary::validate::sample_side(side, f64::INFINITY);
        let sign = if k < 2 { 1.0 } else { -1.0 };
        area += sign * shoelace(&poly, o);
    }
    0.5 * area
}

/// `Σ (x_k − o) × (x_{k+1} − o)` over the polyline `poly`: twice the signed area it
/// sweeps about `o`.
pub(crate) fn shoelace(poly: &[Point], o: Point) -> f64 {
    poly.windows(2).map(|w| (w[0][0] - o[0]) * (w[1][1] - o[1]) - (w[0][1] - o[1]) * (w[1][0] - o[0])).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reversal_matches_curve_reversed() {
        let kv = KnotVector::new(2, vec![0., 0., 0., 0.3, 1., 1., 1.]).unwrap();
        let c = Curve::new(kv, vec![[0., 0.], [1., 2.], [2., 0.], [3., 1.]], Some(vec![1., 2., 1., 1.])).unwrap();
        assert_eq!(reversed_curve(&c).unwrap(), c.reversed());
    }
}
