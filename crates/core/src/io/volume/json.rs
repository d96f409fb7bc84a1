//! The trivariate map document (`formats.md`, "Trivariate map"):
//!
//! ```json
//! { "name": "swept-volume",
//!   "map": { "degree": [p, q, r],
//!            "knots": [[...xi...], [...eta...], [...zeta...]],
//!            "control_points": [[x, y, z], ...],
//!            "weights": null,
//!            "periodic": [false, true, false] } }
//! ```
//!
//! Point `(i, j, k)` is at `(k n_eta + j) n_xi + i`. `periodic` is an added field
//! (absent: all open), as for planar maps; further top-level fields (a `"report"`, a
//! `"certificate"`) are ignored on read. Knot domains are mapped to `[0, 1]`; numbers
//! round-trip exactly (`serde_json` with `float_roundtrip`).

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

use crate::error::{Error, Result};
use crate::io::normalized_knots;
use crate::spline::knots::KnotVector;
use crate::spline::volume::Volume;

/// The `map` object of a trivariate map document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct VolumeJson {
    /// Degrees in `xi`, `eta`, `zeta`.
    pub degree: [usize; 3],
    /// Full knot vectors in `xi`, `eta`, `zeta`.
    pub knots: [Vec<f64>; 3],
    /// Control point `(i, j, k)` at position `(k n_eta + j) n_xi + i`.
    pub control_points: Vec<[f64; 3]>,
    /// Positive weights in the same order, or `null`.
    #[serde(default)]
    pub weights: Option<Vec<f64>>,
    /// Periodicity per direction.
    #[serde(default)]
    pub periodic: [bool; 3],
}

impl VolumeJson {
    /// The JSON form of a volume.
    pub(crate) fn from_volume(v: &Volume) -> Self {
        VolumeJson {
            degree: v.degrees(),
            knots: v.knots.each_ref().map(|k| k.knots().to_vec()),
            control_points: v.control_points.clone(),
            weights: v.weights.clone(),
            periodic: v.knots.each_ref().map(KnotVector::is_periodic),
        }
    }

    /// Validate and map the knot domains to `[0, 1]`; errors name the field.
    pub(crate) fn into_volume(self) -> Result<Volume> {
        crate::error::check_control_point_count(self.control_points.len(), "")?;
        let mut kvs = Vec::with_capacity(3);
        for (d, k) in self.knots.into_iter().enumerate() {
            let ctx = format!("knots[{d}]");
            let kv = KnotVector::with_periodic(self.degree[d], k, self.periodic[d]).map_err(|e| e.within(&ctx))?;
            kvs.push(kv);
        }
        let knots: [KnotVector; 3] =
            kvs.try_into().map_err(|_| Error::Invalid("three knot vectors expected".into()))?;
        let v = Volume::new(knots, self.control_points, self.weights)?;
        let mut norm = Vec::with_capacity(3);
        for (d, k) in v.knots.iter().enumerate() {
            norm.push(normalized_knots(k).map_err(|e| e.within(&format!("knots[{d}]")))?);
        }
        let knots: [KnotVector; 3] =
            norm.try_into().map_err(|_| Error::Invalid("three knot vectors expected".into()))?;
        Ok(Volume { knots, ..v })
    }
}

/// Parse a trivariate map document (already known to be one): its name (empty when it
/// has none) and its volume.
pub(crate) fn parse_volume_json(mut v: Value) -> Result<(String, Volume)> {
    let name = match v.get("name") {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(s)) => s.clone(),
        Some(_) => return Err(Error::Json { context: "name".into(), message: "must be a string".into() }),
    };
    let map = v.get_mut("map").map(Value::take).unwrap_or(Value::Null);
    let vj: VolumeJson =
        serde_json::from_value(map).map_err(|e| Error::Json { context: "map".into(), message: e.to_string() })?;
    Ok((name, vj.into_volume().map_err(|e| e.within("map"))?))
}

/// A trivariate map document `{"name", "map": {...}}`; the fields of `extra` (an object,
/// e.g. `{"certificate": ...}`) are added at the top level unless they would replace
/// `name` or `map`.
pub(crate) fn volume_to_json(name: &str, v: &Volume, extra: Option<Value>) -> Value {
    let mut doc = serde_json::Map::new();
    doc.insert("name".into(), Value::String(name.to_string()));
    doc.insert("map".into(), json!(VolumeJson::from_volume(v)));
    if let Some(Value::Object(fields)) = extra {
        for (k, val) in fields {
            if k != "name" && k != "map" {
                doc.insert(k, val);
            }
        }
    }
    Value::Object(doc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{parse_document, Document};

    fn sample(rational: bool) -> Volume {
        let k = [KnotVector::open_uniform(2, 2), KnotVector::open_uniform(1, 3), KnotVector::open_uniform(3, 1)];
        let shape = k.each_ref().map(KnotVector::num_basis);
        let n: usize = shape.iter().product();
        let cps = (0..n).map(|i| [i as f64 / 3.0, (i % 7) as f64 * 0.1 + 1e-17, 1e8 + (i / 12) as f64]).collect();
        let w = rational.then(|| (0..n).map(|i| 1.0 + 1.0 / (3.0 + i as f64)).collect());
        Volume::new(k, cps, w).unwrap()
    }

    #[test]
    fn round_trip_is_bit_exact() {
        for rational in [false, true] {
            let v = sample(rational);
            let doc = volume_to_json("vol", &v, Some(json!({"certificate": {"kind": "certified"}, "map": 1})));
            let text = serde_json::to_string(&doc).unwrap();
            let Document::Volume { name, volume } = parse_document(&text).unwrap() else { panic!("not a volume") };
            assert_eq!(name, "vol");
            assert_eq!(volume, v);
        }
    }

    #[test]
    fn planar_maps_are_not_volumes_and_errors_name_the_field() {
        let planar =
            r#"{"map":{"degree":[1,1],"knots":[[0,0,1,1],[0,0,1,1]],"control_points":[[0,0],[1,0],[0,1],[1,1]]}}"#;
        assert!(matches!(parse_document(planar), Ok(Document::Map { .. })));
        let bad = r#"{"map":{"degree":[1,1,1],"knots":[[0,0,1,1],[0,0,1,1],[0,1,0,1]],"control_points":[]}}"#;
        let e = parse_document(bad).unwrap_err();
        assert!(e.to_string().contains("map.knots[2]"), "{e}");
        let short = r#"{"map":{"degree":[1,1,1],"knots":[[0,0,1,1],[0,0,1,1],[0,0,1,1]],"control_points":[[0,0,0]]}}"#;
        assert!(matches!(parse_document(short), Err(Error::Length { .. })));
        let wrong = r#"{"map":{"degree":[1,1,1],"knots":[[0,0,1,1],[0,0,1,1],[0,0,1,1]],"control_points":[[0,0]]}}"#;
        assert!(matches!(parse_document(wrong), Err(Error::Json { .. })));
    }
}
