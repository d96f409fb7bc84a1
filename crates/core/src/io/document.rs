//! Every kind of document a file can hold ([`Document`]), and the one reader that
//! decides the kind by content ([`read`], [`parse_document`]), like meshio's `read`.
//!
//! | content | document |
//! |---|---|
//! | JSON with `map` of kind `"thb"` | [`Document::Thb`] |
//! | JSON with `patches`, every patch a `map` | [`Document::Multipatch`] (a solved result) |
//! | JSON with `patches` | [`Document::Layout`] |
//! | JSON with `ring` | [`Document::Ring`] |
//! | JSON with `volume_boundary` | [`Document::VolumeBoundary`] (validated) |
//! | JSON with `map` of three degrees | [`Document::Volume`] |
//! | JSON with `map` | [`Document::Map`] |
//! | JSON with `boundary` or `contour` | [`Document::Boundary`] |
//! | JSON with `domain` | [`Document::Domain`] (not validated: [`crate::domain::validate_domain`]) |
//! | JSON with `graph` | [`Document::Graph`] (not validated: [`crate::domain::plane::build_graph`]) |
//! | XML with a `THBSpline2` geometry | [`Document::Thb`] |
//! | XML with `TensorBSpline3` / `TensorNurbs3` | [`Document::Volume`] |
//! | XML with a `<MultiPatch>` of surfaces in space (`geoDim="3"`, not all in one plane `z = const`) | [`Document::VolumeBoundary`] (faces identified, validated) |
//! | XML with a `<MultiPatch>` of surfaces (two patches or more, or interfaces) | [`Document::Layout`] |
//! | XML with four curves / one tensor patch | [`Document::Boundary`] / [`Document::Map`] |
//! | IGES (entity 128) | [`Document::Map`] |
//!
//! The first matching row wins. A document without a name is named after the file stem.

use std::path::Path;

use serde_json::Value;

use super::domain::domain_of_json;
use super::gismo::parse_gismo_xml;
use super::graph::graph_of_json;
use super::json::parse_json;
use super::multipatch::gismo::{is_gismo_multipatch, parse_gismo_multipatch};
use super::multipatch::json::parse_json_multipatch;
use super::ring::ring_of_json;
use super::volume::boundary::parse_volume_boundary_json;
use super::volume::boundary_gismo::parse_gismo_faces;
use super::volume::gismo::parse_gismo_volume;
use super::volume::json::parse_volume_json;
use super::{iges, read_text, surface_boundary_area};
use crate::boundary::ring::{signed_area, ClosedContour, Ring};
use crate::boundary::volume::VolumeBoundary;
use crate::boundary::{Boundary, SideCurve};
use crate::domain::{Domain, PlaneGraph};
use crate::error::{Error, Result};
use crate::multipatch::Layout;
use crate::pipeline::Input;
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::surface::{Side, Surface};
use crate::spline::volume::Volume;

/// A document read from a file.
// documents are few and short-lived: no boxing
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum Document {
    /// A boundary: a boundary or contour JSON document, or four G+Smo curves.
    Boundary(Boundary),
    /// A tensor-product map: a map JSON document, one G+Smo tensor patch, or IGES. A ring
    /// map is one with `eta` periodic.
    Map {
        /// Name of the geometry.
        name: String,
        /// The map, knot domains mapped to `[0, 1]`.
        map: Surface,
    },
    /// A ring (O-type) domain: two closed contours.
    Ring(Ring),
    /// A multipatch layout (input): a JSON document with `patches` of which at least one
    /// is given by its boundary, or a G+Smo `<MultiPatch>` (whose patches keep their
    /// maps in [`crate::multipatch::Patch::map`]). Not validated.
    Layout(Layout),
    /// A solved multipatch result: a JSON document with `patches`, every patch a `map`
    /// (each in [`crate::multipatch::Patch::map`]).
    Multipatch(Layout),
    /// A general planar domain: an outer loop with any number of corners and holes
    /// (`formats.md`, "General planar domain").
    Domain(Domain),
    /// A plane graph: vertices, edges and labelled faces (`formats.md`, "Plane graph").
    Graph(PlaneGraph),
    /// A trivariate map: a JSON map with three degrees, or G+Smo
    /// `TensorBSpline3` / `TensorNurbs3`.
    Volume {
        /// Name of the geometry.
        name: String,
        /// The volume, knot domains mapped to `[0, 1]`.
        volume: Volume,
    },
    /// The six boundary faces of a hexahedral volume (`formats-extensions.md`, "Volume boundary"),
    /// validated.
    VolumeBoundary(VolumeBoundary),
    /// A THB map (`formats-extensions.md`, "THB map"): a JSON map of kind `"thb"`, or G+Smo
    /// `THBSpline2` ([`super::hierarchical`]).
    Thb {
        /// Name of the geometry.
        name: String,
        /// The map.
        map: HierarchicalMap,
    },
}

impl Document {
    /// The kind, for messages: `"boundary"`, `"map"`, `"ring map"` (a map with `eta`
    /// periodic), `"ring"`, `"multipatch layout"`, `"multipatch result"`, `"domain"`,
    /// `"graph"`, `"volume"`, `"volume boundary"`, `"THB map"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Document::Boundary(_) => "boundary",
            Document::Map { map, .. } if map.knots[1].is_periodic() => "ring map",
            Document::Map { .. } => "map",
            Document::Ring(_) => "ring",
            Document::Layout(_) => "multipatch layout",
            Document::Multipatch(_) => "multipatch result",
            Document::Domain(_) => "domain",
            Document::Graph(_) => "graph",
            Document::Volume { .. } => "volume",
            Document::VolumeBoundary(_) => "volume boundary",
            Document::Thb { .. } => "THB map",
        }
    }

    /// Name of the geometry (empty when the file gave none).
    pub fn name(&self) -> &str {
        match self {
            Document::Boundary(b) => &b.name,
            Document::Ring(r) => &r.name,
            Document::Layout(l) | Document::Multipatch(l) => &l.name,
            Document::Domain(d) => &d.name,
            Document::VolumeBoundary(b) => &b.name,
            Document::Graph(g) => &g.name,
            Document::Map { name, .. } | Document::Volume { name, .. } | Document::Thb { name, .. } => name,
        }
    }

    fn name_mut(&mut self) -> &mut String {
        match self {
            Document::Boundary(b) => &mut b.name,
            Document::Ring(r) => &mut r.name,
            Document::Layout(l) | Document::Multipatch(l) => &mut l.name,
            Document::Domain(d) => &mut d.name,
            Document::VolumeBoundary(b) => &mut b.name,
            Document::Graph(g) => &mut g.name,
            Document::Map { name, .. } | Document::Volume { name, .. } | Document::Thb { name, .. } => name,
        }
    }

    /// The error "this is a `kind()` document, where `needed`".
    pub fn wrong_kind(&self, path: Option<&Path>, needed: impl Into<String>) -> Error {
        Error::DocumentKind { path: path.map(Path::to_path_buf), found: self.kind().to_string(), needed: needed.into() }
    }

    /// The boundary: itself, or the four boundary curves of a map (`Surface::boundary`;
    /// a side whose weights are all 1 becomes a polynomial curve, as in `Curve::new`).
    /// Any other kind is an [`Error::DocumentKind`].
    pub fn into_boundary(self) -> Result<Boundary> {
        match self {
            Document::Boundary(b) => Ok(b),
            Document::Map { name, map } if !map.knots[1].is_periodic() => {
                let side = |s: Side| {
                    let mut c = map.boundary(s);
                    if c.weights.as_ref().is_some_and(|w| w.iter().all(|&x| x == 1.0)) {
                        c.weights = None;
                    }
                    SideCurve::Spline(c)
                };
                Ok(Boundary { name, sides: Side::ALL.map(side) })
            }
            other => Err(other.wrong_kind(None, "a four-sided boundary or map is needed")),
        }
    }

    /// Whether this is a ring map: a map periodic in `eta`.
    pub fn is_ring_map(&self) -> bool {
        matches!(self, Document::Map { map, .. } if map.knots[1].is_periodic())
    }

    /// The ring: itself, or the two contours of a ring map (a map periodic in `eta`):
    /// its `xi = 0` side as the inner contour and its `xi = 1` side as the outer, each
    /// turned counter-clockwise. Any other kind is an [`Error::DocumentKind`].
    pub fn into_ring(self) -> Result<Ring> {
        match self {
            Document::Ring(r) => Ok(r),
            Document::Map { name, map } if map.knots[1].is_periodic() => {
                let contour = |s: Side| {
                    let mut c = map.boundary(s);
                    if c.weights.as_ref().is_some_and(|w| w.iter().all(|&x| x == 1.0)) {
                        c.weights = None;
                    }
                    let closed = ClosedContour::Spline(c.clone());
                    if signed_area(&closed.polygon_with(256)) < 0.0 {
                        ClosedContour::Spline(c.reversed())
                    } else {
                        closed
                    }
                };
                Ok(Ring { name, inner: contour(Side::West), outer: contour(Side::East) })
            }
            other => Err(other.wrong_kind(None, "a ring or a ring map is needed")),
        }
    }

    /// The pipeline input this document is ([`Input`]): a boundary (validated and, with
    /// `opts.reorient`, turned counter-clockwise; a map stands for its boundary), a ring
    /// or a ring map (its two contours), a multipatch layout or result (solved again from
    /// its patches' sides), a domain, a plane graph, or a volume boundary. A volume or a
    /// THB map, which have nothing left to solve, are an [`Error::DocumentKind`].
    pub fn into_input(self, opts: &super::ReadOptions) -> Result<Input> {
        Ok(match self {
            Document::Layout(l) | Document::Multipatch(l) => Input::Layout(l),
            Document::Domain(d) => Input::Domain(d),
            Document::Graph(g) => Input::Graph(g),
            Document::VolumeBoundary(v) => Input::Volume(Box::new(v)),
            doc @ (Document::Ring(_) | Document::Map { .. })
                if doc.is_ring_map() || matches!(doc, Document::Ring(_)) =>
            {
                Input::Ring(doc.into_ring()?)
            }
            doc @ Document::Volume { .. } => {
                return Err(doc.wrong_kind(
                    None,
                    "a boundary, ring, layout, domain, graph or volume boundary is needed (a volume is already solved)",
                ))
            }
            doc @ Document::Thb { .. } => return Err(doc.wrong_kind(
                None,
                "a boundary, ring, layout, domain, graph or volume boundary is needed (a THB map is already solved: \
                     `winslow check` certifies it, `winslow convert` turns it into a tensor map)",
            )),
            doc => Input::Boundary(super::checked_boundary(doc.into_boundary()?, opts)?.0),
        })
    }
}

fn json_document(body: &str) -> Result<Document> {
    let v: Value =
        serde_json::from_str(body).map_err(|e| Error::Json { context: String::new(), message: e.to_string() })?;
    let Value::Object(obj) = &v else { return parse_json(body) };
    if super::hierarchical::is_thb_json(&v) {
        let (name, map) = super::hierarchical::thb_of_json(v)?;
        return Ok(Document::Thb { name, map });
    }
    if let Some(Value::Array(patches)) = obj.get("patches") {
        let solved = !patches.is_empty() && patches.iter().all(|p| p.get("map").is_some());
        let layout = parse_json_multipatch(body)?;
        return Ok(if solved { Document::Multipatch(layout) } else { Document::Layout(layout) });
    }
    if obj.contains_key("volume_boundary") {
        return parse_volume_boundary_json(v).map(Document::VolumeBoundary);
    }
    if obj.contains_key("ring") {
        return ring_of_json(v).map(Document::Ring);
    }
    if obj.contains_key("domain") && !["map", "boundary", "contour"].iter().any(|k| obj.contains_key(*k)) {
        return domain_of_json(v).map(Document::Domain);
    }
    if obj.contains_key("graph") && !["map", "boundary", "contour"].iter().any(|k| obj.contains_key(*k)) {
        return graph_of_json(v).map(Document::Graph);
    }
    let volume = obj.get("map").and_then(|m| m.get("degree")).and_then(Value::as_array).is_some_and(|d| d.len() == 3);
    if volume {
        let (name, volume) = parse_volume_json(v)?;
        return Ok(Document::Volume { name, volume });
    }
    parse_json(body)
}

fn xml_document(body: &str) -> Result<Document> {
    if body.contains("\"THBSpline2\"") {
        return Ok(Document::Thb { name: String::new(), map: super::hierarchical::parse_thb_xml(body)? });
    }
    if body.contains("TensorBSpline3") || body.contains("TensorNurbs3") {
        return Ok(Document::Volume { name: String::new(), volume: parse_gismo_volume(body)? });
    }
    if is_gismo_multipatch(body) {
        if let Some(b) = parse_gismo_faces(body)? {
            return Ok(Document::VolumeBoundary(b));
        }
        let layout = parse_gismo_multipatch(body)?;
        // G+Smo wraps single patches in <MultiPatch> too: that is a map
        if layout.patches.len() != 1 || !layout.interfaces.is_empty() {
            return Ok(Document::Layout(layout));
        }
    }
    parse_gismo_xml(body)
}

/// Parse a document from text, its kind decided by content (see the module
/// documentation): JSON when it starts with `{`, XML when it starts with `<` (after a
/// byte-order mark and white space), IGES when its first record has the Start-section
/// letter in column 73 (a map, transposed when its boundary runs clockwise, as for
/// G+Smo patches). The name is left as the document gives it.
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
        Some('{') => json_document(body),
        Some('<') => xml_document(body),
        Some(c) => Err(Error::Invalid(format!(
            "the input is neither a JSON object nor an XML document nor IGES (it starts with {c:?})"
        ))),
        None => Err(Error::Invalid("the input is empty".into())),
    }
}

/// `e` with the file's path, when it is an [`Error::DocumentKind`] without one.
pub(crate) fn at_path(e: Error, path: &Path) -> Error {
    match e {
        Error::DocumentKind { path: None, found, needed } => {
            Error::DocumentKind { path: Some(path.to_path_buf()), found, needed }
        }
        e => e,
    }
}

/// Read any document of `formats.md`, G+Smo XML or IGES from a file (see the module
/// documentation). A document without a name is named after the file stem.
pub fn read(path: &Path) -> Result<Document> {
    read_with_report(path).map(|(doc, _)| doc)
}

/// [`read`], and the top-level `report` of a JSON document when it has one (what
/// `winslow solve` stores beside a map: verdict, matched pairs, kinks, ...); the file is
/// read once.
pub fn read_with_report(path: &Path) -> Result<(Document, Option<Value>)> {
    let text = read_text(path)?;
    let mut doc = parse_document(&text).map_err(|e| at_path(e, path))?;
    let name = doc.name_mut();
    if name.is_empty() {
        *name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    }
    let body = text.trim_start_matches('\u{feff}').trim_start();
    let report = if body.starts_with('{') && body.contains("\"report\"") {
        serde_json::from_str::<Value>(body).ok().and_then(|mut v| v.get_mut("report").map(Value::take))
    } else {
        None
    };
    Ok((doc, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ring map's ring is its two contours, turned counter-clockwise: the annulus
    /// between radii 1 and 2 whose `eta` runs clockwise gives its contours of radius 1
    /// (inner) and 2 (outer), counter-clockwise; a four-sided map is not a ring map.
    #[test]
    fn a_ring_map_gives_its_ring() {
        use crate::spline::knots::KnotVector;
        let kv = KnotVector::periodic_uniform(2, 8);
        let d = kv.dim();
        let angle = |k: usize| -std::f64::consts::TAU * (k % d) as f64 / d as f64;
        let cps =
            (0..kv.num_basis()).flat_map(|k| [1.0, 2.0].map(|r| [r * angle(k).cos(), r * angle(k).sin()])).collect();
        let map = Surface::new([KnotVector::open_uniform(1, 1), kv], cps, None).unwrap();
        let doc = Document::Map { name: "annulus".into(), map };
        assert!(doc.is_ring_map());
        let ring = doc.into_ring().unwrap();
        let area = |c: &ClosedContour| signed_area(&c.polygon_with(64));
        let (inner, outer) = (area(&ring.inner), area(&ring.outer));
        // a quadratic periodic spline inside the circle's octagon (area 2 sqrt(2) r^2),
        // the outer one the inner scaled by 2
        assert!(inner > 0.8 * std::f64::consts::PI && inner < 2.0 * 2f64.sqrt(), "{inner}");
        assert!((outer / inner - 4.0).abs() < 1e-12, "{inner} {outer}");
        let square = Surface::new(
            [KnotVector::open_uniform(1, 1), KnotVector::open_uniform(1, 1)],
            vec![[0., 0.], [1., 0.], [0., 1.], [1., 1.]],
            None,
        )
        .unwrap();
        let doc = Document::Map { name: "square".into(), map: square };
        assert!(!doc.is_ring_map());
        let e = doc.into_ring().unwrap_err();
        assert!(matches!(&e, Error::DocumentKind { found, .. } if found == "map"), "{e}");
    }

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
        let e = read(Path::new("/nonexistent/winslow/nothing.json")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }));
        assert!(e.to_string().contains("nothing.json"));
    }

    #[test]
    fn domains_and_graphs_are_read() {
        let domain = r#"{"name": "bracket", "domain": {"outer": {"points": [[0,0],[1,0],[1,1]], "corners": [0, 1, 2]}, "holes": []}}"#;
        let doc = parse_document(domain).unwrap();
        assert_eq!((doc.kind(), doc.name()), ("domain", "bracket"));
        assert!(matches!(&doc, Document::Domain(d) if d.outer.corners() == 3));
        let graph = r#"{"graph": {"vertices": [[0,0],[1,0]], "edges": [{"from": 0, "to": 1}]}}"#;
        let doc = parse_document(graph).unwrap();
        assert!(matches!(&doc, Document::Graph(g) if g.edges.len() == 1 && g.vertices.len() == 2), "{doc:?}");
        let e = parse_document(r#"{"nothing": 1}"#).unwrap_err();
        assert!(matches!(e, Error::Json { .. }), "{e}");
    }

    #[test]
    fn a_ring_is_not_a_boundary() {
        let ring = r#"{"ring": {"inner": {"points": [[1,0],[0,1],[-1,0],[0,-1]]},
                                "outer": {"points": [[3,0],[0,3],[-3,0],[0,-3]]}}}"#;
        let doc = parse_document(ring).unwrap();
        assert_eq!(doc.kind(), "ring");
        let e = doc.into_boundary().unwrap_err();
        assert!(matches!(&e, Error::DocumentKind { found, .. } if found == "ring"), "{e}");
        assert!(e.to_string().contains("a ring document, where a four-sided boundary"), "{e}");
    }
}
