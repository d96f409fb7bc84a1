//! The volume boundary document (`formats-extensions.md`, "Volume boundary"):
//!
//! ```json
//! { "name": "twisted-duct",
//!   "volume_boundary": { "west": FACE, "east": FACE, "south": FACE,
//!                        "north": FACE, "bottom": FACE, "top": FACE } }
//! ```
//!
//! with `FACE = {"degree": [p, q], "knots": [[...s...], [...t...]],
//! "control_points": [[x, y, z], ...], "weights": null}`, point `(i, j)` at
//! `j n_s + i`. Knot domains are mapped to `[0, 1]`; the faces are validated
//! ([`VolumeBoundary::validate`]) on read; numbers round-trip exactly.

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

use crate::boundary::volume::{CubeSide, VolumeBoundary};
use crate::error::{Error, Result};
use crate::io::normalized_knots;
use crate::spline::face::Face;
use crate::spline::knots::KnotVector;

/// One face of a volume boundary document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct FaceJson {
    /// Degrees in `s` and `t`.
    pub degree: [usize; 2],
    /// Full open knot vectors in `s` and `t`.
    pub knots: [Vec<f64>; 2],
    /// Control point `(i, j)` at position `j n_s + i`.
    pub control_points: Vec<[f64; 3]>,
    /// Positive weights in the same order, or `null`.
    #[serde(default)]
    pub weights: Option<Vec<f64>>,
}

impl FaceJson {
    /// The JSON form of a face.
    pub(crate) fn from_face(f: &Face) -> Self {
        FaceJson {
            degree: f.degrees(),
            knots: f.knots.each_ref().map(|k| k.knots().to_vec()),
            control_points: f.control_points.clone(),
            weights: f.weights.clone(),
        }
    }

    /// Validate and map the knot domains to `[0, 1]`; errors name the field.
    pub(crate) fn into_face(self) -> Result<Face> {
        crate::error::check_control_point_count(self.control_points.len(), "")?;
        let mut kvs = Vec::with_capacity(2);
        for (d, k) in self.knots.into_iter().enumerate() {
            let ctx = format!("knots[{d}]");
            let kv = KnotVector::new(self.degree[d], k).map_err(|e| e.within(&ctx))?;
            kvs.push(normalized_knots(&kv).map_err(|e| e.within(&ctx))?);
        }
        let knots: [KnotVector; 2] = kvs.try_into().map_err(|_| Error::Invalid("two knot vectors expected".into()))?;
        Face::new(knots, self.control_points, self.weights)
    }
}

/// Parse a volume boundary document (already known to be one) and validate it.
pub(crate) fn parse_volume_boundary_json(mut v: Value) -> Result<VolumeBoundary> {
    let name = match v.get("name") {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(s)) => s.clone(),
        Some(_) => return Err(Error::Json { context: "name".into(), message: "must be a string".into() }),
    };
    let mut body = v.get_mut("volume_boundary").map(Value::take).unwrap_or(Value::Null);
    let Some(obj) = body.as_object_mut() else {
        return Err(Error::Json {
            context: "volume_boundary".into(),
            message: "must be an object of six faces".into(),
        });
    };
    if let Some(k) = obj.keys().find(|k| !CubeSide::ALL.iter().any(|s| s.name() == k.as_str())) {
        return Err(Error::Json {
            context: "volume_boundary".into(),
            message: format!("unknown face {k:?} (the faces are west, east, south, north, bottom, top)"),
        });
    }
    let mut faces = Vec::with_capacity(6);
    for side in CubeSide::ALL {
        let ctx = format!("volume_boundary.{}", side.name());
        let f = obj
            .get_mut(side.name())
            .map(Value::take)
            .ok_or_else(|| Error::Json { context: ctx.clone(), message: "missing face".into() })?;
        let fj: FaceJson =
            serde_json::from_value(f).map_err(|e| Error::Json { context: ctx.clone(), message: e.to_string() })?;
        faces.push(fj.into_face().map_err(|e| e.within(&ctx))?);
    }
    let faces: [Face; 6] = faces.try_into().map_err(|_| Error::Invalid("six faces expected".into()))?;
    let b = VolumeBoundary { name, faces };
    b.validate()?;
    Ok(b)
}

/// The volume boundary document of `b`.
pub fn volume_boundary_to_json(b: &VolumeBoundary) -> Value {
    let mut faces = serde_json::Map::new();
    for side in CubeSide::ALL {
        faces.insert(side.name().into(), json!(FaceJson::from_face(b.face(side))));
    }
    json!({ "name": b.name, "volume_boundary": Value::Object(faces) })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::volume::tests::trilinear_faces;
    use crate::io::{parse_document, Document};

    fn sample() -> VolumeBoundary {
        let mut faces = trilinear_faces(|u| [u[0] + 0.2 * u[1] * u[2], u[1] - 1e-17, 1e8 + u[2] / 3.0]);
        // one face on another basis, with unit weights given (read as a B-spline)
        let top = faces[5].elevated_in(0).unwrap();
        let n = top.control_points.len();
        faces[5] = Face::new(top.knots, top.control_points, Some(vec![1.0; n])).unwrap();
        VolumeBoundary { name: "vb".into(), faces }
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let b = sample();
        let text = serde_json::to_string(&volume_boundary_to_json(&b)).unwrap();
        let Document::VolumeBoundary(back) = parse_document(&text).unwrap() else { panic!("not a volume boundary") };
        assert_eq!(back, b);
    }

    #[test]
    fn bad_documents_are_typed_errors_naming_the_face() {
        let good = volume_boundary_to_json(&sample());
        let with = |f: &dyn Fn(&mut Value)| {
            let mut v = good.clone();
            f(&mut v);
            parse_document(&v.to_string()).unwrap_err()
        };
        let e = with(&|v| {
            v["volume_boundary"].as_object_mut().unwrap().remove("north");
        });
        assert!(matches!(&e, Error::Json { context, .. } if context == "volume_boundary.north"), "{e}");
        let e = with(&|v| v["volume_boundary"]["extra"] = json!(1));
        assert!(matches!(&e, Error::Json { context, .. } if context == "volume_boundary"), "{e}");
        let e = with(&|v| v["volume_boundary"]["south"]["knots"][0] = json!([0, 1, 0, 1]));
        assert!(matches!(&e, Error::Knots { context, .. } if context == "volume_boundary.south.knots[0]"), "{e}");
        let e = with(&|v| v["volume_boundary"]["east"]["weights"] = json!([1, 1, 0, 1]));
        assert!(matches!(&e, Error::Weight { context, .. } if context.contains("east")), "{e}");
        let e = with(&|v| v["volume_boundary"]["west"]["control_points"][3] = json!([0, 1.5, 1e8 + 1.0]));
        assert!(
            matches!(&e, Error::VolumeBoundary { face, edge, .. } if face.contains("west") && !edge.is_empty()),
            "{e}"
        );
        let e = with(&|v| v["volume_boundary"]["bottom"]["control_points"] = json!([[0, 0, 0]]));
        assert!(matches!(&e, Error::Length { .. }), "{e}");
    }
}
