//! The JSON exchange formats of `formats.md`: Curve, boundary document, contour
//! document and map document, as serde types, with readers and writers.
//!
//! Numbers are written by `serde_json` (shortest representation that round-trips, ryu)
//! and read with its `float_roundtrip` parser, so `Surface -> JSON -> Surface` is exact.
//! Unknown fields are ignored on read; knot domains are mapped to `[0, 1]`.

use std::path::Path;

use serde::{Deserialize, Deserializer, Serialize};
use serde_json::{json, Value};

use super::{normalized_curve, normalized_knots, Document};
use crate::boundary::{Boundary, SideCurve};
use crate::error::{Error, Result, MAX_CONTROL_POINTS};
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::surface::{Side, Surface};

/// Number of points an analytic side is sampled with when written (`t = k / 1024`).
pub(crate) const ANALYTIC_WRITE_POINTS: usize = 1025;

fn is_false(b: &bool) -> bool {
    !*b
}

/// A Curve: `{"degree", "knots", "control_points", "weights", "periodic"?}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CurveJson {
    /// Polynomial degree `p >= 1`.
    pub degree: usize,
    /// Full non-decreasing knot vector, `control_points.len() + degree + 1` entries.
    pub knots: Vec<f64>,
    /// Control points `[x, y]`.
    pub control_points: Vec<[f64; 2]>,
    /// One positive weight per control point (NURBS), or `null`/absent.
    #[serde(default)]
    pub weights: Option<Vec<f64>>,
    /// Whether the knot vector is periodic (unclamped); written only when true.
    #[serde(default, skip_serializing_if = "is_false")]
    pub periodic: bool,
}

/// A point-cloud side: `{"points": [[x, y], ...]}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointsJson {
    /// Ordered points from one corner to the next.
    pub points: Vec<[f64; 2]>,
}

/// A SIDE of a boundary document: a point cloud (an object with a `points` field) or a
/// Curve (any other object).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum SideJson {
    /// `{"points": ...}`.
    Points(PointsJson),
    /// A Curve.
    Curve(CurveJson),
}

impl SideJson {
    /// Decide by the presence of a `points` field.
    pub fn from_value(v: Value) -> std::result::Result<Self, serde_json::Error> {
        match &v {
            Value::Object(o) if o.contains_key("points") => serde_json::from_value(v).map(SideJson::Points),
            Value::Object(_) => serde_json::from_value(v).map(SideJson::Curve),
            other => Err(serde::de::Error::custom(format!(
                "a side must be a Curve object or {{\"points\": [...]}}, found {}",
                kind_of(other)
            ))),
        }
    }
}

impl<'de> Deserialize<'de> for SideJson {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = Value::deserialize(d)?;
        SideJson::from_value(v).map_err(serde::de::Error::custom)
    }
}

/// The four sides of a boundary document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SidesJson {
    /// `eta = 0`, increasing `xi`.
    pub south: SideJson,
    /// `xi = 1`, increasing `eta`.
    pub east: SideJson,
    /// `eta = 1`, increasing `xi`.
    pub north: SideJson,
    /// `xi = 0`, increasing `eta`.
    pub west: SideJson,
}

/// `{"name", "boundary": {"south", "east", "north", "west"}}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoundaryDoc {
    /// Name of the geometry.
    #[serde(default)]
    pub name: String,
    /// The sides.
    pub boundary: SidesJson,
}

/// The closed polygon of a contour document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContourJson {
    /// One closed counter-clockwise polygon (the first point may be repeated at the end).
    pub points: Vec<[f64; 2]>,
    /// Indices of the south-west, south-east, north-east and north-west corners.
    pub corners: [usize; 4],
}

/// `{"name", "contour": {"points", "corners"}}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContourDoc {
    /// Name of the geometry.
    #[serde(default)]
    pub name: String,
    /// The polygon.
    pub contour: ContourJson,
}

/// The `map` object of a map document; control points `xi` index fastest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapJson {
    /// Degrees in `xi` and `eta`.
    pub degree: [usize; 2],
    /// Full knot vectors in `xi` and `eta`.
    pub knots: [Vec<f64>; 2],
    /// Control point `(i, j)` at position `j * n_xi + i`.
    pub control_points: Vec<[f64; 2]>,
    /// Positive weights in the same order, or `null`.
    #[serde(default)]
    pub weights: Option<Vec<f64>>,
    /// Periodicity per direction.
    #[serde(default)]
    pub periodic: [bool; 2],
}

/// `{"name", "map": {...}}`, plus any further top-level fields (ignored on read).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapDoc {
    /// Name of the geometry.
    #[serde(default)]
    pub name: String,
    /// The map.
    pub map: MapJson,
}

fn too_large(what: &str, found: usize) -> Error {
    Error::TooLarge { context: String::new(), what: what.into(), found, limit: MAX_CONTROL_POINTS }
}

impl CurveJson {
    /// The JSON form of a curve.
    pub(crate) fn from_curve(c: &Curve) -> Self {
        CurveJson {
            degree: c.degree(),
            knots: c.knots.knots().to_vec(),
            control_points: c.control_points.clone(),
            weights: c.weights.clone(),
            periodic: c.knots.is_periodic(),
        }
    }

    /// Validate (lengths, knots, degree, finiteness, weights) and map the domain to `[0, 1]`.
    pub(crate) fn into_curve(self) -> Result<Curve> {
        crate::error::check_control_point_count(self.control_points.len(), "")?;
        let kv = KnotVector::with_periodic(self.degree, self.knots, self.periodic).map_err(|e| e.within("knots"))?;
        let c = Curve::new(kv, self.control_points, self.weights)?;
        normalized_curve(&c)
    }
}

impl SideJson {
    /// The JSON form of a side; analytic sides become point clouds of
    /// [`ANALYTIC_WRITE_POINTS`] points at uniform parameters.
    pub(crate) fn from_side(s: &SideCurve) -> Self {
        match s {
            SideCurve::Spline(c) => SideJson::Curve(CurveJson::from_curve(c)),
            SideCurve::Points(p) => SideJson::Points(PointsJson { points: p.clone() }),
            SideCurve::Analytic(f) => {
                let m = ANALYTIC_WRITE_POINTS - 1;
                SideJson::Points(PointsJson { points: (0..=m).map(|k| f.eval(k as f64 / m as f64)).collect() })
            }
        }
    }

    /// Convert to a side: curves are validated and normalized to `[0, 1]`; point clouds
    /// are only checked for size here (the rest is [`crate::boundary::validate::validate`]'s job).
    pub(crate) fn into_side(self) -> Result<SideCurve> {
        match self {
            SideJson::Curve(c) => c.into_curve().map(SideCurve::Spline),
            SideJson::Points(p) => {
                crate::error::check_point_count(p.points.len(), "")?;
                Ok(SideCurve::Points(p.points))
            }
        }
    }
}

impl ContourDoc {
    /// Split the polygon into the four sides ([`split_contour`]).
    pub(crate) fn into_boundary(self) -> Result<Boundary> {
        let sides = split_contour(&self.contour.points, self.contour.corners)?;
        Ok(Boundary { name: self.name, sides: sides.map(SideCurve::Points) })
    }
}

impl MapJson {
    /// The JSON form of a map.
    pub fn from_surface(s: &Surface) -> Self {
        MapJson {
            degree: s.degrees(),
            knots: s.knots.each_ref().map(|k| k.knots().to_vec()),
            control_points: s.control_points.clone(),
            weights: s.weights.clone(),
            periodic: s.knots.each_ref().map(KnotVector::is_periodic),
        }
    }

    /// Validate and map both knot domains to `[0, 1]`.
    pub fn to_surface(self) -> Result<Surface> {
        crate::error::check_control_point_count(self.control_points.len(), "")?;
        let [k0, k1] = self.knots;
        let kv0 = KnotVector::with_periodic(self.degree[0], k0, self.periodic[0]).map_err(|e| e.within("knots[0]"))?;
        let kv1 = KnotVector::with_periodic(self.degree[1], k1, self.periodic[1]).map_err(|e| e.within("knots[1]"))?;
        let s = Surface::new([kv0, kv1], self.control_points, self.weights)?;
        let knots = [
            normalized_knots(&s.knots[0]).map_err(|e| e.within("knots[0]"))?,
            normalized_knots(&s.knots[1]).map_err(|e| e.within("knots[1]"))?,
        ];
        Ok(Surface { knots, ..s })
    }
}

fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

fn json_err(context: &str) -> impl Fn(serde_json::Error) -> Error + '_ {
    move |e| Error::Json { context: context.to_string(), message: e.to_string() }
}

/// Parse a boundary, contour or map document (see `formats.md`). The kind is decided by
/// the top-level field present: `map`, else `boundary`, else `contour`; every other
/// top-level field is ignored. Errors carry the location, e.g. `boundary.south.knots`.
pub fn parse_json(text: &str) -> Result<Document> {
    let v: Value = serde_json::from_str(text).map_err(json_err(""))?;
    let Value::Object(mut obj) = v else {
        return Err(Error::Json {
            context: String::new(),
            message: format!("the document must be an object, found {}", kind_of(&v)),
        });
    };
    let name = match obj.remove("name") {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(s)) => s,
        Some(other) => {
            return Err(Error::Json {
                context: "name".into(),
                message: format!("must be a string, found {}", kind_of(&other)),
            })
        }
    };
    if let Some(m) = obj.remove("map") {
        let map: MapJson = serde_json::from_value(m).map_err(json_err("map"))?;
        let map = map.to_surface().map_err(|e| e.within("map"))?;
        return Ok(Document::Map { name, map });
    }
    if let Some(b) = obj.remove("boundary") {
        let Value::Object(mut sides) = b else {
            return Err(Error::Json {
                context: "boundary".into(),
                message: format!("must be an object with south, east, north and west, found {}", kind_of(&b)),
            });
        };
        let mut out = Vec::with_capacity(4);
        for s in Side::ALL {
            let ctx = format!("boundary.{s}");
            let v = sides
                .remove(s.name())
                .ok_or_else(|| Error::Json { context: "boundary".into(), message: format!("missing side \"{s}\"") })?;
            let side = SideJson::from_value(v).map_err(json_err(&ctx))?;
            out.push(side.into_side().map_err(|e| e.within(&ctx))?);
        }
        let sides: [SideCurve; 4] = out.try_into().map_err(|_| Error::Invalid("four sides expected".into()))?;
        return Ok(Document::Boundary(Boundary { name, sides }));
    }
    if let Some(c) = obj.remove("contour") {
        let contour: ContourJson = serde_json::from_value(c).map_err(json_err("contour"))?;
        return ContourDoc { name, contour }.into_boundary().map(Document::Boundary);
    }
    Err(Error::Json {
        context: String::new(),
        message: "no document field: expected \"boundary\", \"contour\", \"map\", \"ring\" or \"patches\" (formats.md)"
            .into(),
    })
}

/// Split a closed polygon at its corners `[i_sw, i_se, i_ne, i_nw]` into the sides of
/// `formats.md`: south = `sw..se`, east = `se..ne`, north = reverse of `ne..nw`, west =
/// reverse of `nw..sw`, every run taken forwards with cyclic indices and both corners
/// included. A last point equal to the first (within `1e-9` times the bounding-box
/// diameter) closes the polygon and is dropped; a corner index pointing at it means
/// index 0. The corners must be distinct and in this order along the polygon.
pub fn split_contour(points: &[Point], corners: [usize; 4]) -> Result<[Vec<Point>; 4]> {
    let bad = |reason: String| Error::Corners { reason };
    if points.len() > MAX_CONTROL_POINTS {
        return Err(too_large("number of contour points", points.len()).within("contour"));
    }
    let len = points.len();
    if let Some(&i) = corners.iter().find(|&&i| i >= len) {
        return Err(bad(format!("corner index {i} is out of range for {len} points")));
    }
    let mut n = len;
    if n >= 2 {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points {
            for c in 0..2 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        let diam = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        let (a, b) = (points[0], points[n - 1]);
        if a == b || (a[0] - b[0]).hypot(a[1] - b[1]) <= 1e-9 * diam {
            n -= 1;
        }
    }
    if n < 4 {
        return Err(bad(format!("a contour needs at least 4 distinct points, found {n}")));
    }
    let c = corners.map(|i| if i == n { 0 } else { i });
    let off = |i: usize| (c[i] + n - c[0]) % n;
    if !(0 < off(1) && off(1) < off(2) && off(2) < off(3)) {
        return Err(bad(format!(
            "corners {corners:?} must be distinct and follow each other along the polygon in the order south-west, south-east, north-east, north-west"
        )));
    }
    let run = |a: usize, b: usize| -> Vec<Point> {
        let m = (b + n - a) % n;
        (0..=m).map(|k| points[(a + k) % n]).collect()
    };
    let south = run(c[0], c[1]);
    let east = run(c[1], c[2]);
    let mut north = run(c[2], c[3]);
    north.reverse();
    let mut west = run(c[3], c[0]);
    west.reverse();
    Ok([south, east, north, west])
}

/// The JSON form of a curve (a Curve object of `formats.md`).
pub fn curve_to_json(c: &Curve) -> Value {
    json!(CurveJson::from_curve(c))
}

pub(crate) fn side_to_json(s: &SideCurve) -> Value {
    json!(SideJson::from_side(s))
}

/// A boundary document `{"name", "boundary": {...}}`; analytic sides are written as
/// point clouds of `ANALYTIC_WRITE_POINTS` points.
pub fn boundary_to_json(b: &Boundary) -> Value {
    json!({
        "name": b.name,
        "boundary": {
            "south": side_to_json(b.side(Side::South)),
            "east": side_to_json(b.side(Side::East)),
            "north": side_to_json(b.side(Side::North)),
            "west": side_to_json(b.side(Side::West)),
        }
    })
}

/// A contour document: the sides concatenated counter-clockwise (south, east, reversed
/// north, reversed west, shared corners once, first point not repeated). Spline and
/// analytic sides are sampled at `ANALYTIC_WRITE_POINTS` uniform parameters.
pub fn boundary_to_contour_json(b: &Boundary) -> Value {
    let pts: Vec<Vec<Point>> = b
        .sides
        .iter()
        .map(|s| match s {
            SideCurve::Points(p) => p.clone(),
            SideCurve::Spline(c) => c.sample(ANALYTIC_WRITE_POINTS - 1),
            SideCurve::Analytic(f) => {
                let m = ANALYTIC_WRITE_POINTS - 1;
                (0..=m).map(|k| f.eval(k as f64 / m as f64)).collect()
            }
        })
        .collect();
    let mut poly: Vec<Point> = pts[0].clone();
    let se = poly.len().saturating_sub(1);
    poly.extend(pts[1].iter().skip(1));
    let ne = poly.len().saturating_sub(1);
    poly.extend(pts[2].iter().rev().skip(1));
    let nw = poly.len().saturating_sub(1);
    let w = &pts[3];
    poly.extend(w.iter().rev().skip(1).take(w.len().saturating_sub(2)));
    json!({ "name": b.name, "contour": { "points": poly, "corners": [0, se, ne, nw] } })
}

/// A map document `{"name", "map": {...}}`; the fields of `extra` (when it is an object,
/// e.g. `{"report": ...}`) are added at the top level unless they would replace `name`
/// or `map`; any other `extra` value is stored under `"extra"`.
pub fn map_to_json(name: &str, map: &Surface, extra: Option<Value>) -> Value {
    let mut doc = serde_json::Map::new();
    doc.insert("name".into(), Value::String(name.to_string()));
    doc.insert("map".into(), json!(MapJson::from_surface(map)));
    match extra {
        Some(Value::Object(fields)) => {
            for (k, v) in fields {
                if k != "name" && k != "map" {
                    doc.insert(k, v);
                }
            }
        }
        Some(Value::Null) | None => {}
        Some(other) => {
            doc.insert("extra".into(), other);
        }
    }
    Value::Object(doc)
}

/// Write a JSON value to a file (pretty-printed, numbers round-trip exactly) through the
/// atomic writer ([`super::file::write_with`]).
pub fn write_json(path: &Path, value: &Value) -> Result<()> {
    super::file::write_with(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_map() -> Surface {
        let kv = KnotVector::open_uniform(2, 3);
        let n = kv.num_basis();
        let g = kv.greville();
        let cps = (0..n * n).map(|k| [g[k % n] + 0.1 * (k as f64).sin(), g[k / n] * 1.0 / 3.0]).collect();
        Surface::new([kv.clone(), kv], cps, None).unwrap()
    }

    #[test]
    fn map_round_trip_is_bit_exact() {
        let mut s = unit_map();
        s.weights = Some((0..s.control_points.len()).map(|k| 1.0 + 0.1 / (k as f64 + 3.0)).collect());
        let v = map_to_json("m", &s, Some(json!({"report": {"iterations": 3}, "name": "ignored"})));
        assert_eq!(v["report"]["iterations"], 3);
        assert_eq!(v["name"], "m");
        let text = serde_json::to_string(&v).unwrap();
        let Document::Map { name, map } = parse_json(&text).unwrap() else { panic!("not a map") };
        assert_eq!(name, "m");
        assert_eq!(map, s);
        let again = serde_json::to_string(&map_to_json("m", &map, Some(json!({"report": {"iterations": 3}})))).unwrap();
        assert_eq!(again, text);
    }

    #[test]
    fn map_domain_is_normalized() {
        let text = r#"{"name":"x","map":{"degree":[1,1],"knots":[[2,2,4,4],[-1,-1,0,1,1]],
            "control_points":[[0,0],[1,0],[0,1],[1,1],[0,2],[1,2]],"weights":null}}"#;
        let Document::Map { map, .. } = parse_json(text).unwrap() else { panic!() };
        assert_eq!(map.knots[0].knots(), &[0., 0., 1., 1.]);
        assert_eq!(map.knots[1].knots(), &[0., 0., 0.5, 1., 1.]);
        assert!(!map.knots[0].is_periodic());
    }

    #[test]
    fn map_errors_name_the_place() {
        let text =
            r#"{"map":{"degree":[1,1],"knots":[[0,0,1,1],[0,1,0.5,1]],"control_points":[[0,0],[1,0],[0,1],[1,1]]}}"#;
        let e = parse_json(text).unwrap_err();
        assert!(matches!(e, Error::Knots { .. }), "{e}");
        assert!(e.to_string().contains("map.knots[1]"), "{e}");
        let text = r#"{"map":{"degree":[1,1],"knots":[[0,0,1,1],[0,0,1,1]],"control_points":[[0,0],[1,0],[0,1]]}}"#;
        assert!(matches!(parse_json(text), Err(Error::Length { .. })));
    }

    #[test]
    fn contour_split_orientation() {
        // square with 8 points, corners at the vertices; the last point repeats the first
        let pts: Vec<Point> =
            vec![[0., 0.], [0.5, 0.], [1., 0.], [1., 0.5], [1., 1.], [0.5, 1.], [0., 1.], [0., 0.5], [0., 0.]];
        let [s, e, n, w] = split_contour(&pts, [0, 2, 4, 6]).unwrap();
        assert_eq!(s, vec![[0., 0.], [0.5, 0.], [1., 0.]]);
        assert_eq!(e, vec![[1., 0.], [1., 0.5], [1., 1.]]);
        assert_eq!(n, vec![[0., 1.], [0.5, 1.], [1., 1.]]);
        assert_eq!(w, vec![[0., 0.], [0., 0.5], [0., 1.]]);
        // same without the repeated point, rotated start: corners cyclic
        let open = &pts[..8];
        let rot: Vec<Point> = open[3..].iter().chain(&open[..3]).copied().collect();
        let [s2, e2, n2, w2] = split_contour(&rot, [5, 7, 1, 3]).unwrap();
        assert_eq!((s2, e2, n2, w2), (s, e, n, w));
        // corner index pointing at the repeated closing point is index 0
        assert!(split_contour(&pts, [8, 2, 4, 6]).is_ok());
    }

    #[test]
    fn contour_corner_errors() {
        let pts: Vec<Point> = vec![[0., 0.], [1., 0.], [1., 1.], [0., 1.]];
        assert!(matches!(split_contour(&pts, [0, 1, 2, 4]), Err(Error::Corners { .. })));
        assert!(matches!(split_contour(&pts, [0, 2, 1, 3]), Err(Error::Corners { .. })));
        assert!(matches!(split_contour(&pts, [0, 0, 2, 3]), Err(Error::Corners { .. })));
        assert!(matches!(split_contour(&pts[..3], [0, 1, 2, 2]), Err(Error::Corners { .. })));
        assert!(split_contour(&pts, [1, 2, 3, 0]).is_ok());
    }

    #[test]
    fn side_json_dispatch() {
        let p: SideJson = serde_json::from_str(r#"{"points": [[0, 0], [1, 2]]}"#).unwrap();
        assert!(matches!(p, SideJson::Points(_)));
        let c: SideJson =
            serde_json::from_str(r#"{"degree": 1, "knots": [0,0,1,1], "control_points": [[0,0],[1,1]]}"#).unwrap();
        assert!(matches!(c, SideJson::Curve(CurveJson { weights: None, periodic: false, .. })));
        assert!(serde_json::from_str::<SideJson>("[1, 2]").is_err());
        assert_eq!(serde_json::to_value(&p).unwrap(), json!({"points": [[0.0, 0.0], [1.0, 2.0]]}));
    }
}
