//! Ring (O-type) documents of `formats.md`: `{"name", "ring": {"inner": CLOSED,
//! "outer": CLOSED}}`, read into a [`Ring`] and written back.
//!
//! `CLOSED` is a periodic Curve (`"periodic": true`, the last `degree` control points
//! repeating the first), a clamped Curve whose two ends coincide (accepted in addition:
//! a closed loop exported by CAD systems, e.g. the G+Smo loops), or `{"points": [...]}`,
//! an ordered closed point cloud; a last point equal to the first (within `1e-12` of
//! the cloud's extent) is dropped. Closedness, orientation and nesting are checked by
//! [`crate::boundary::ring_fit::check_ring`].

use serde_json::{json, Value};

use super::json::{CurveJson, PointsJson};
use crate::boundary::ring::{ClosedContour, Ring};
use crate::error::{check_point_count, Error, Result};

fn closed(v: Value, ctx: &str) -> Result<ClosedContour> {
    let jerr = |e: serde_json::Error| Error::Json { context: ctx.into(), message: e.to_string() };
    match &v {
        Value::Object(o) if o.contains_key("points") => {
            let mut p: PointsJson = serde_json::from_value(v).map_err(jerr)?;
            check_point_count(p.points.len(), ctx)?;
            let extent = p.points.iter().fold(0.0f64, |m, q| m.max(q[0].abs()).max(q[1].abs()));
            if p.points.len() > 1 {
                let (a, b) = (p.points[0], p.points[p.points.len() - 1]);
                if (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) <= 1e-12 * extent {
                    p.points.pop();
                }
            }
            Ok(ClosedContour::Points(p.points))
        }
        Value::Object(_) => {
            let c: CurveJson = serde_json::from_value(v).map_err(jerr)?;
            Ok(ClosedContour::Spline(c.into_curve().map_err(|e| e.within(ctx))?))
        }
        other => Err(Error::Json {
            context: ctx.into(),
            message: format!("a closed contour must be a Curve object or {{\"points\": [...]}}, found {other}"),
        }),
    }
}

/// The ring of a JSON document with a top-level `"ring"` field, `None` for any other
/// document. Errors name the place (`ring.inner.knots`, ...). (Files are read by
/// [`crate::io::read`]; the tests and the fuzz exercisers parse text with this.)
#[cfg(any(test, feature = "testutil"))]
pub(crate) fn parse_ring_json(text: &str) -> Result<Option<Ring>> {
    let text = text.trim_start_matches('\u{feff}').trim_start();
    if !text.starts_with('{') {
        return Ok(None);
    }
    let v: Value =
        serde_json::from_str(text).map_err(|e| Error::Json { context: String::new(), message: e.to_string() })?;
    if v.get("ring").is_none() {
        return Ok(None);
    }
    ring_of_json(v).map(Some)
}

/// The ring of a JSON document known to have a top-level `"ring"` field.
pub(crate) fn ring_of_json(v: Value) -> Result<Ring> {
    let Value::Object(mut obj) = v else {
        return Err(Error::Json { context: String::new(), message: "the document must be an object".into() });
    };
    let r = obj.remove("ring").unwrap_or(Value::Null);
    let name = match obj.remove("name") {
        Some(Value::String(s)) => s,
        _ => String::new(),
    };
    let Value::Object(mut r) = r else {
        return Err(Error::Json { context: "ring".into(), message: "must be an object with inner and outer".into() });
    };
    let mut take = |k: &str| {
        r.remove(k).ok_or_else(|| Error::Json { context: "ring".into(), message: format!("missing contour \"{k}\"") })
    };
    let (inner, outer) = (take("inner")?, take("outer")?);
    Ok(Ring { name, inner: closed(inner, "ring.inner")?, outer: closed(outer, "ring.outer")? })
}

/// The JSON form of a ring; analytic contours become point clouds of 1024 points.
pub(crate) fn ring_to_json(ring: &Ring) -> Value {
    let c = |c: &ClosedContour| match c {
        ClosedContour::Spline(c) => serde_json::to_value(CurveJson::from_curve(c)).expect("serializable"),
        ClosedContour::Points(p) => json!({ "points": p }),
        ClosedContour::Analytic(f) => {
            json!({ "points": (0..1024).map(|k| f.eval(k as f64 / 1024.0)).collect::<Vec<_>>() })
        }
    };
    json!({ "name": ring.name, "ring": { "inner": c(&ring.inner), "outer": c(&ring.outer) } })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::curve::Curve;
    use crate::spline::knots::KnotVector;

    #[test]
    fn rings_round_trip_and_errors_name_the_place() {
        let kv = KnotVector::periodic_uniform(2, 4);
        let d = kv.dim();
        let base = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
        let cps = (0..kv.num_basis()).map(|k| base[k % d]).collect();
        let inner = Curve::new(kv, cps, None).unwrap();
        let ring = Ring {
            name: "r".into(),
            inner: ClosedContour::Spline(inner.clone()),
            outer: ClosedContour::Points(vec![[3.0, 0.0], [0.0, 3.0], [-3.0, 0.0], [0.0, -3.0]]),
        };
        let text = ring_to_json(&ring).to_string();
        let back = parse_ring_json(&text).unwrap().unwrap();
        match (&back.inner, &back.outer) {
            (ClosedContour::Spline(c), ClosedContour::Points(p)) => {
                assert_eq!(c, &inner);
                assert_eq!(p.len(), 4);
            }
            other => panic!("{other:?}"),
        }
        assert!(parse_ring_json(r#"{"boundary": {}}"#).unwrap().is_none());
        let e = parse_ring_json(r#"{"ring": {"inner": {"points": [[0,0]]}}}"#).unwrap_err().to_string();
        assert!(e.contains("outer"), "{e}");
        let bad = r#"{"ring": {"inner": {"degree": 2, "knots": [0,1,2,3,4,5,7], "control_points": [[0,0],[1,0],[1,1],[0,0]], "periodic": true},
                      "outer": {"points": [[0,0],[1,0],[1,1]]}}}"#;
        let e = parse_ring_json(bad).unwrap_err().to_string();
        assert!(e.contains("ring.inner") && e.contains("periodic"), "{e}");
    }
}
