//! One untrusted input through every reader, the validator, the certificate and the
//! writers' round trips: the body shared by the coverage-guided fuzz targets (`fuzz/`)
//! and the structure-aware mutation test (`tests/mutation.rs`).
//!
//! Nothing here may panic on any input; a panic is the bug the callers look for. What
//! the readers refuse is collected in a [`Trace`] (each error with the stage that
//! returned it), together with *violations*: properties that must hold for every input
//! that is accepted (writers round-trip bit for bit, error messages say something).

use crate::boundary::validate::{inspect, validate, ValidationReport};
use crate::boundary::{Boundary, SideCurve};
use crate::error::Error;
use crate::io::{self, checked_boundary, gismo_writer, iges, json, Document, ReadOptions};
use crate::spline::surface::Surface;
use crate::verify::certificate::{certify, CertifyOptions};

/// Certificate options for fuzzing: few boxes, so that one input costs microseconds.
pub const FUZZ_CERTIFY: CertifyOptions = CertifyOptions { max_depth: 4, max_boxes: 16, excuse_corners: true };

/// Largest map (control points) that is certified and written back; bigger ones are
/// only read and validated, to keep one input cheap.
pub const MAX_CHECKED_MAP: usize = 4096;

/// The reader an input is given to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reader {
    /// [`io::parse_document`]: detection by content (JSON, G+Smo XML, IGES).
    Document,
    /// [`json::parse_json`]: boundary, contour or map document.
    Json,
    /// [`io::gismo::parse_gismo_xml`].
    Gismo,
    /// [`iges::parse_iges`].
    Iges,
}

/// What happened to one input.
#[derive(Debug, Default)]
pub struct Trace {
    /// Errors returned, with the stage that returned them (`"read"`, `"validate"`, ...).
    pub errors: Vec<(&'static str, Error)>,
    /// Properties that failed for an accepted input (each a sentence).
    pub violations: Vec<String>,
    /// Boundaries that reached validation.
    pub boundaries: usize,
    /// Maps that were read.
    pub maps: usize,
    /// Boundaries accepted by [`validate`].
    pub valid_boundaries: usize,
}

impl Trace {
    fn record<T>(&mut self, stage: &'static str, r: crate::error::Result<T>) -> Option<T> {
        match r {
            Ok(v) => Some(v),
            Err(e) => {
                if !informative(&e) {
                    self.violations.push(format!("{stage}: uninformative error message {:?} ({e:?})", e.to_string()));
                }
                self.errors.push((stage, e));
                None
            }
        }
    }
}

/// Whether an error's message says something: non-empty and not ending in a bare
/// prefix such as `"malformed JSON: "`.
pub fn informative(e: &Error) -> bool {
    let m = e.to_string();
    let t = m.trim_end();
    !t.is_empty() && !t.ends_with(':')
}

/// Read `text` with `reader` and exercise whatever it yields ([`exercise_document`]).
pub fn exercise_text(reader: Reader, text: &str) -> Trace {
    let mut trace = Trace::default();
    let doc = match reader {
        Reader::Document => io::parse_document(text),
        Reader::Json => json::parse_json(text),
        Reader::Gismo => io::gismo::parse_gismo_xml(text),
        Reader::Iges => iges::parse_iges(text).map(|map| Document::Map { name: String::new(), map }),
    };
    if let Some(doc) = trace.record("read", doc) {
        exercise_document(doc, &mut trace);
    }
    trace
}

/// Read `text` as a ring (O-type) document (`io::ring`) and validate and fit it coarsely
/// (`boundary::ring::fit_ring`: closed, counter-clockwise, nested contours); an accepted
/// ring counts as a valid boundary.
pub fn exercise_ring_text(text: &str) -> Trace {
    let mut trace = Trace::default();
    if let Some(Some(ring)) = trace.record("read", crate::io::ring::parse_ring_json(text)) {
        trace.boundaries += 1;
        if trace.record("fit", crate::boundary::ring_fit::fit_ring(&ring, 3, 1e-2, 64)).is_some() {
            trace.valid_boundaries += 1;
        }
    }
    trace
}

/// A boundary: validated; a map: certified, written and read back, and its boundary validated.
pub fn exercise_document(doc: Document, trace: &mut Trace) {
    match doc {
        Document::Boundary(b) => exercise_boundary(&b, trace),
        Document::Map { name, map } => {
            exercise_map(&name, &map, trace);
            // a ring map has no four-sided boundary
            if let Ok(b) = (Document::Map { name, map }).into_boundary() {
                exercise_boundary(&b, trace);
            }
        }
        // a domain: validated and laid out (never a panic)
        Document::Domain(mut d) => {
            trace.boundaries += 1;
            if trace.record("validate domain", crate::domain::validate_domain(&mut d)).is_some() {
                trace.valid_boundaries += 1;
                let opts = crate::domain::LayoutOptions { rings: 6, ..Default::default() };
                trace.record("layout", crate::domain::auto_layout(&d, &opts));
            }
        }
        // a plane graph: validated and laid out (never a panic)
        Document::Graph(g) => {
            trace.boundaries += 1;
            let opts = crate::domain::LayoutOptions { rings: 6, ..Default::default() };
            trace.record("graph layout", crate::domain::graph_layout(&g, &opts));
        }
        // rings have their own exerciser (`exercise_ring_text`); layouts and volumes none
        Document::Ring(_)
        | Document::Layout(_)
        | Document::Multipatch(_)
        | Document::Volume { .. }
        | Document::VolumeBoundary(_)
        | Document::Thb { .. } => {}
    }
}

/// [`inspect`], [`validate`] and [`checked_boundary`] (both orientations) of a boundary.
pub fn exercise_boundary(b: &Boundary, trace: &mut Trace) {
    trace.boundaries += 1;
    let Some(report) = trace.record("inspect", inspect(b)) else {
        return;
    };
    if trace.record("validate", validate(b)).is_some() {
        trace.valid_boundaries += 1;
    }
    let reoriented = trace.record("checked_boundary", checked_boundary(b.clone(), &ReadOptions { reorient: true }));
    if let Some((ccw, again)) = reoriented {
        let slack = area_slack(&report).max(area_slack(&again));
        if again.signed_area <= 0.0 || (again.signed_area - report.signed_area.abs()).abs() > slack {
            trace.violations.push(format!(
                "reorienting a contour of signed area {:e} gave signed area {:e} (allowed difference {slack:e})",
                report.signed_area, again.signed_area
            ));
        }
        let _ = validate(&ccw.transposed());
    }
}

/// How much the signed area of a contour may change when it is traversed the other way
/// round (transposed): the corner points are taken from the other side of each corner,
/// and moving a vertex by `g` changes the shoelace area by at most `g` times the
/// bounding-box diameter; plus the rounding of the shoelace sum (`n` products of
/// coordinates up to `M` in magnitude) and a relative `1e-9`.
fn area_slack(r: &ValidationReport) -> f64 {
    let m = [r.bbox_min, r.bbox_max].iter().flatten().fold(0.0f64, |a, &x| a.max(x.abs()));
    let n = r.polyline_points as f64;
    2.0 * r.corner_gaps.iter().sum::<f64>() * r.diameter + 8.0 * n * f64::EPSILON * m * m + 1e-9 * r.signed_area.abs()
}

/// A map as the weights of a polynomial map are stored after reading IGES (`None`
/// when all weights are 1).
fn without_unit_weights(map: &Surface) -> Surface {
    let mut m = map.clone();
    if m.weights.as_ref().is_some_and(|w| w.iter().all(|&x| x == 1.0)) {
        m.weights = None;
    }
    m
}

/// Certify a map and write it as JSON, G+Smo XML and IGES: each must read back as the
/// same map (G+Smo and IGES: transposed when its boundary runs clockwise).
pub fn exercise_map(name: &str, map: &Surface, trace: &mut Trace) {
    trace.maps += 1;
    if map.control_points.len() > MAX_CHECKED_MAP {
        return;
    }
    let _ = trace.record("certify", certify(map, &FUZZ_CERTIFY));
    let text = json::map_to_json(name, map, None).to_string();
    match json::parse_json(&text) {
        Ok(Document::Map { map: back, .. }) if back == *map => {}
        other => trace.violations.push(format!("JSON round trip of a map changed it: {other:?}")),
    }
    let expect = if io::surface_boundary_area(map) < 0.0 { map.transposed() } else { map.clone() };
    match io::gismo::parse_gismo_xml(&gismo_writer::surface_to_gismo_xml(map, "fuzz")) {
        Ok(Document::Map { map: back, .. }) if back == expect => {}
        other => trace.violations.push(format!("G+Smo XML round trip of a map changed it: {other:?}")),
    }
    match io::parse_document(&iges::surface_to_iges(map, "fuzz.igs", "fuzz")) {
        Ok(Document::Map { map: back, .. }) if back == without_unit_weights(&expect) => {}
        other => trace.violations.push(format!("IGES round trip of a map changed it: {other:?}")),
    }
}

/// Exercise a boundary built by the caller (fuzz targets that generate sides directly);
/// spline sides are taken as given, without [`crate::Curve::new`]'s checks.
pub fn exercise_sides(sides: [SideCurve; 4]) -> Trace {
    let mut trace = Trace::default();
    exercise_boundary(&Boundary { name: String::new(), sides }, &mut trace);
    trace
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uninformative_errors_are_violations() {
        let mut t = Trace::default();
        t.record::<()>("read", Err(Error::Json { context: String::new(), message: String::new() }));
        assert_eq!(t.violations.len(), 1, "{t:?}");
        t.record::<()>("read", Err(Error::Json { context: String::new(), message: "expected a value".into() }));
        assert_eq!((t.violations.len(), t.errors.len()), (1, 2));
    }

    #[test]
    fn a_valid_map_round_trips_and_certifies() {
        let text = r#"{"map":{"degree":[1,2],"knots":[[0,0,1,1],[0,0,0,1,1,1]],
          "control_points":[[1,0],[2,0],[1,1],[2,2],[0,1],[0,2]],"weights":[1,1,0.7,0.7,1,1]}}"#;
        let t = exercise_text(Reader::Document, text);
        assert!(t.errors.is_empty() && t.violations.is_empty(), "{t:?}");
        assert_eq!((t.maps, t.boundaries, t.valid_boundaries), (1, 1, 1));
    }
}
