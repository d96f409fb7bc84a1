//! General planar domain documents of `formats.md`: `{"name", "domain": {"outer": LOOP,
//! "holes": [LOOP, ...]}}`, read into a [`Domain`] (not yet validated:
//! [`crate::domain::validate_domain`]).
//!
//! `LOOP` is `{"curves": [SIDE, ...]}` (a closed chain of Curves or point clouds), or
//! `{"points": [...], "corners": [i, ...]}` (a closed point cloud, last point not
//! repeating the first, with the indices of its corners; without `"corners"` the corners
//! are found where the contour turns by at least the point-cloud kink threshold, as for
//! kinks, and listed in the report). A periodic Curve (a loop without corners) is refused
//! with an error that says so: the automatic layout needs corners.

use serde_json::Value;

use super::json::{side_to_json, SideJson};
use crate::boundary::kinks::cloud_corners;
use crate::boundary::{KinkMode, SideCurve};
use crate::domain::{Domain, Loop};
use crate::error::{check_point_count, Error, Result};
use crate::spline::curve::Point;

fn jerr(context: impl Into<String>, message: impl Into<String>) -> Error {
    Error::Json { context: context.into(), message: message.into() }
}

fn side(v: Value, ctx: &str) -> Result<SideCurve> {
    match SideJson::from_value(v).map_err(|e| jerr(ctx, e.to_string()))? {
        SideJson::Points(p) => {
            check_point_count(p.points.len(), ctx)?;
            Ok(SideCurve::Points(p.points))
        }
        SideJson::Curve(c) => {
            if c.periodic {
                return Err(jerr(ctx, "a periodic curve cannot be one side of a loop (give it as the whole loop)"));
            }
            Ok(SideCurve::Spline(c.into_curve().map_err(|e| e.within(ctx))?))
        }
    }
}

/// The corners of a closed point cloud found where it turns (both halves of the loop are
/// searched as open polylines, so a corner at the first point is found too).
fn detect_corners(points: &[Point]) -> Vec<usize> {
    let n = points.len();
    let threshold = KinkMode::Auto.cloud_threshold().unwrap_or(30.0);
    let mut out: Vec<usize> = Vec::new();
    for shift in [0, n / 2] {
        let rotated: Vec<Point> = (0..=n).map(|k| points[(k + shift) % n]).collect();
        for (i, _) in cloud_corners(&rotated, threshold) {
            let k = (i + shift) % n;
            let near = |a: usize, b: usize| a.abs_diff(b).min(n - a.abs_diff(b)) <= 1;
            if !out.iter().any(|&o| near(o, k)) {
                out.push(k);
            }
        }
    }
    out.sort_unstable();
    out
}

fn closed_cloud(o: &serde_json::Map<String, Value>, ctx: &str) -> Result<Loop> {
    let points: Vec<Point> =
        serde_json::from_value(o["points"].clone()).map_err(|e| jerr(format!("{ctx}.points"), e.to_string()))?;
    let n = points.len();
    check_point_count(n, ctx)?;
    if n < 3 {
        return Err(Error::TooFewPoints { side: ctx.into(), found: n, needed: 3 });
    }
    if points.iter().any(|p| !p[0].is_finite() || !p[1].is_finite()) {
        return Err(Error::NonFinite { context: ctx.into(), what: "a point".into() });
    }
    let (corners, detected) = match o.get("corners") {
        None | Some(Value::Null) => (detect_corners(&points), true),
        Some(v) => {
            let mut c: Vec<usize> =
                serde_json::from_value(v.clone()).map_err(|e| jerr(format!("{ctx}.corners"), e.to_string()))?;
            if let Some(&bad) = c.iter().find(|&&i| i >= n) {
                return Err(Error::Corners {
                    reason: format!("{ctx}: corner index {bad} is not below the {n} points"),
                });
            }
            c.sort_unstable();
            if c.windows(2).any(|w| w[0] == w[1]) {
                return Err(Error::Corners { reason: format!("{ctx}: a corner index is listed twice") });
            }
            (c, false)
        }
    };
    if corners.is_empty() {
        return Err(Error::Corners {
            reason: format!("{ctx}: the closed point cloud has no corners (none listed, none found where it turns)"),
        });
    }
    let m = corners.len();
    let sides = (0..m)
        .map(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % m]);
            let len = if b > a { b - a } else { b + n - a };
            SideCurve::Points((0..=len).map(|j| points[(a + j) % n]).collect())
        })
        .collect();
    let mut l = Loop::new(sides);
    if detected {
        l.detected_corners = corners.iter().map(|&i| points[i]).collect();
    }
    Ok(l)
}

fn loop_of(v: Value, ctx: &str) -> Result<Loop> {
    let Value::Object(o) = v else { return Err(jerr(ctx, "a loop must be an object")) };
    if let Some(c) = o.get("curves") {
        let Value::Array(list) = c.clone() else { return Err(jerr(format!("{ctx}.curves"), "must be a list")) };
        let sides = list
            .into_iter()
            .enumerate()
            .map(|(k, s)| side(s, &format!("{ctx}.curves[{k}]")))
            .collect::<Result<Vec<_>>>()?;
        if sides.is_empty() {
            return Err(jerr(format!("{ctx}.curves"), "a loop needs at least one curve"));
        }
        return Ok(Loop::new(sides));
    }
    if o.contains_key("points") {
        return closed_cloud(&o, ctx);
    }
    if o.get("periodic").and_then(Value::as_bool) == Some(true) {
        return Err(Error::Domain {
            at: ctx.replace("domain.", ""),
            reason: "is a periodic curve without corners: this version lays out loops with corners (give it as \"curves\" split at three or more corners)".into(),
        });
    }
    Err(jerr(ctx, "a loop is {\"curves\": [...]}, {\"points\": [...], \"corners\": [...]} or a periodic Curve"))
}

/// The domain document of `d` (every loop as `"curves"`): what [`domain_of_json`]
/// reads back as the same domain.
pub(crate) fn domain_to_json(d: &Domain) -> Value {
    let lp = |l: &Loop| serde_json::json!({ "curves": l.sides.iter().map(side_to_json).collect::<Vec<_>>() });
    serde_json::json!({
        "name": d.name,
        "domain": { "outer": lp(&d.outer), "holes": d.holes.iter().map(lp).collect::<Vec<_>>() },
    })
}

/// The domain of a JSON document with a top-level `"domain"` field (see the module
/// documentation). Errors name the place (`domain.outer.curves[2].knots`, ...).
pub(crate) fn domain_of_json(v: Value) -> Result<Domain> {
    let Value::Object(mut obj) = v else { return Err(jerr("", "the document must be an object")) };
    let name = match obj.remove("name") {
        Some(Value::String(s)) => s,
        None | Some(Value::Null) => String::new(),
        Some(_) => return Err(jerr("name", "must be a string")),
    };
    let Some(Value::Object(mut d)) = obj.remove("domain") else {
        return Err(jerr("domain", "must be an object with \"outer\" and optional \"holes\""));
    };
    let outer = loop_of(d.remove("outer").ok_or_else(|| jerr("domain.outer", "missing"))?, "domain.outer")?;
    let holes = match d.remove("holes") {
        None | Some(Value::Null) => Vec::new(),
        Some(Value::Array(list)) => list
            .into_iter()
            .enumerate()
            .map(|(k, h)| loop_of(h, &format!("domain.holes[{k}]")))
            .collect::<Result<Vec<_>>>()?,
        Some(_) => return Err(jerr("domain.holes", "must be a list of loops")),
    };
    Ok(Domain { name, outer, holes })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<Domain> {
        domain_of_json(serde_json::from_str(s).unwrap())
    }

    #[test]
    fn loops_of_curves_and_of_points() {
        let d = parse(
            r#"{"name": "tri", "domain": {"outer": {"curves": [
                {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [2, 0]]},
                {"points": [[2, 0], [1.5, 0.8], [1, 1.7]]},
                {"degree": 2, "knots": [0, 0, 0, 1, 1, 1], "control_points": [[1, 1.7], [0.4, 1], [0, 0]]}]}}}"#,
        )
        .unwrap();
        assert_eq!((d.name.as_str(), d.outer.corners(), d.holes.len()), ("tri", 3, 0));
        // a square cloud, corners listed or found
        let sq = r#"{"domain": {"outer": {"points": [[0,0],[1,0],[2,0],[2,1],[2,2],[1,2],[0,2],[0,1]] CORNERS}}}"#;
        let listed = parse(&sq.replace("CORNERS", r#", "corners": [6, 0, 2, 4]"#)).unwrap();
        assert_eq!(listed.outer.corners(), 4);
        assert!(
            matches!(&listed.outer.sides[0], SideCurve::Points(p) if p == &vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
        );
        let found = parse(&sq.replace("CORNERS", "")).unwrap();
        assert_eq!(found.outer.detected_corners, vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]);
    }

    #[test]
    fn written_domains_read_back() {
        for (_, d) in crate::domain::corpus::domain_corpus(&[], 2, 3) {
            let back = domain_of_json(domain_to_json(&d)).unwrap();
            assert_eq!(back.name, d.name);
            assert_eq!(format!("{:?}", back.outer.sides), format!("{:?}", d.outer.sides));
        }
    }

    #[test]
    fn malformed_loops_are_errors() {
        for (doc, want) in [
            (r#"{"domain": {"outer": {"points": [[0,0],[1,0],[1,1]], "corners": [0, 5]}}}"#, "not below"),
            (r#"{"domain": {"outer": {"points": [[0,0],[1,0]]}}}"#, "too few points"),
            (r#"{"domain": {"outer": {"curves": []}}}"#, "at least one curve"),
            (r#"{"domain": {"outer": {"curves": [3]}}}"#, "domain.outer.curves[0]"),
            (r#"{"domain": {"holes": []}}"#, "domain.outer"),
            (
                r#"{"domain": {"outer": {"degree": 1, "knots": [0,1,2,3,4], "control_points": [[0,0],[1,0],[0,0]], "periodic": true}}}"#,
                "periodic curve without corners",
            ),
        ] {
            let e = parse(doc).unwrap_err().to_string();
            assert!(e.contains(want), "{want}: {e}");
        }
    }
}
