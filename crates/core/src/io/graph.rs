//! Plane graph documents of `formats.md`: `{"name", "graph": {"vertices": [[x, y], ...],
//! "edges": [{"from": i, "to": j, "curve": SIDE}, ...], "labels": [{"name", "point"},
//! ...], "voids": [[x, y], ...]}}`, read into a [`PlaneGraph`] (not yet validated:
//! [`crate::domain::plane::build_graph`]). `curve` (optional, a straight segment when
//! absent) is a Curve or a point cloud as a side of a four-sided boundary; `voids`
//! (optional) are points inside regions that are not part of the domain.

use serde_json::Value;

use super::json::{side_to_json, SideJson};
use crate::boundary::SideCurve;
use crate::domain::{PlaneEdge, PlaneGraph, PlaneLabel};
use crate::error::{check_point_count, Error, Result};
use crate::spline::curve::Point;

fn jerr(context: impl Into<String>, message: impl Into<String>) -> Error {
    Error::Json { context: context.into(), message: message.into() }
}

fn points(v: Value, ctx: &str) -> Result<Vec<Point>> {
    let p: Vec<Point> = serde_json::from_value(v).map_err(|e| jerr(ctx, e.to_string()))?;
    check_point_count(p.len(), ctx)?;
    if let Some(k) = p.iter().position(|q| !q[0].is_finite() || !q[1].is_finite()) {
        return Err(Error::NonFinite { context: format!("{ctx}[{k}]"), what: "a point".into() });
    }
    Ok(p)
}

fn index(o: &serde_json::Map<String, Value>, key: &str, ctx: &str) -> Result<usize> {
    o.get(key)
        .and_then(Value::as_u64)
        .map(|i| i as usize)
        .ok_or_else(|| jerr(format!("{ctx}.{key}"), "must be a vertex index (a non-negative integer)"))
}

fn edge(v: Value, ctx: &str) -> Result<PlaneEdge> {
    let Value::Object(mut o) = v else { return Err(jerr(ctx, "an edge is {\"from\", \"to\", \"curve\"}")) };
    let (from, to) = (index(&o, "from", ctx)?, index(&o, "to", ctx)?);
    let curve = match o.remove("curve") {
        None | Some(Value::Null) => None,
        Some(c) => {
            let cctx = format!("{ctx}.curve");
            Some(match SideJson::from_value(c).map_err(|e| jerr(&cctx, e.to_string()))? {
                SideJson::Points(p) => {
                    check_point_count(p.points.len(), &cctx)?;
                    if p.points.len() < 2 {
                        return Err(Error::TooFewPoints { side: cctx, found: p.points.len(), needed: 2 });
                    }
                    SideCurve::Points(p.points)
                }
                SideJson::Curve(c) => {
                    if c.periodic {
                        return Err(jerr(&cctx, "a periodic curve cannot be an edge (split it at two vertices)"));
                    }
                    SideCurve::Spline(c.into_curve().map_err(|e| e.within(&cctx))?)
                }
            })
        }
    };
    Ok(PlaneEdge { from, to, curve })
}

/// The plane graph of a JSON document with a top-level `"graph"` field (see the module
/// documentation). Errors name the place (`graph.edges[3].curve`, ...).
pub(crate) fn graph_of_json(v: Value) -> Result<PlaneGraph> {
    let Value::Object(mut obj) = v else { return Err(jerr("", "the document must be an object")) };
    let name = match obj.remove("name") {
        Some(Value::String(s)) => s,
        None | Some(Value::Null) => String::new(),
        Some(_) => return Err(jerr("name", "must be a string")),
    };
    let Some(Value::Object(mut g)) = obj.remove("graph") else {
        return Err(jerr("graph", "must be an object with \"vertices\" and \"edges\""));
    };
    let vertices = points(g.remove("vertices").ok_or_else(|| jerr("graph.vertices", "missing"))?, "graph.vertices")?;
    let Some(Value::Array(list)) = g.remove("edges") else { return Err(jerr("graph.edges", "must be a list")) };
    let edges =
        list.into_iter().enumerate().map(|(k, e)| edge(e, &format!("graph.edges[{k}]"))).collect::<Result<_>>()?;
    let labels = match g.remove("labels") {
        None | Some(Value::Null) => Vec::new(),
        Some(Value::Array(list)) => list
            .into_iter()
            .enumerate()
            .map(|(k, l)| {
                let ctx = format!("graph.labels[{k}]");
                let Value::Object(o) = l else { return Err(jerr(&ctx, "a label is {\"name\", \"point\"}")) };
                let Some(Value::String(name)) = o.get("name").cloned() else {
                    return Err(jerr(format!("{ctx}.name"), "must be a string"));
                };
                let p = points(
                    Value::Array(vec![o.get("point").cloned().unwrap_or(Value::Null)]),
                    &format!("{ctx}.point"),
                )?;
                Ok(PlaneLabel { name, point: p[0] })
            })
            .collect::<Result<_>>()?,
        Some(_) => return Err(jerr("graph.labels", "must be a list")),
    };
    let voids = match g.remove("voids") {
        None | Some(Value::Null) => Vec::new(),
        Some(v) => points(v, "graph.voids")?,
    };
    Ok(PlaneGraph { name, vertices, edges, labels, voids })
}

/// The graph document of `g`: what [`graph_of_json`] reads back as the same graph.
pub(crate) fn graph_to_json(g: &PlaneGraph) -> Value {
    let edges: Vec<Value> = g
        .edges
        .iter()
        .map(|e| {
            let mut o = serde_json::json!({ "from": e.from, "to": e.to });
            if let Some(c) = &e.curve {
                o["curve"] = side_to_json(c);
            }
            o
        })
        .collect();
    let labels: Vec<Value> = g.labels.iter().map(|l| serde_json::json!({ "name": l.name, "point": l.point })).collect();
    let mut graph = serde_json::json!({ "vertices": g.vertices, "edges": edges, "labels": labels });
    if !g.voids.is_empty() {
        graph["voids"] = serde_json::json!(g.voids);
    }
    serde_json::json!({ "name": g.name, "graph": graph })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<PlaneGraph> {
        graph_of_json(serde_json::from_str(s).unwrap())
    }

    #[test]
    fn a_graph_reads_and_writes_back() {
        let g = parse(
            r#"{"name": "two", "graph": {"vertices": [[0,0],[1,0],[1,1],[0,1],[2,0],[2,1]],
               "edges": [{"from": 0, "to": 1}, {"from": 1, "to": 2}, {"from": 2, "to": 3}, {"from": 3, "to": 0},
                         {"from": 1, "to": 4}, {"from": 4, "to": 5, "curve": {"points": [[2,0],[2.2,0.5],[2,1]]}},
                         {"from": 5, "to": 2, "curve": {"degree": 1, "knots": [0,0,1,1], "control_points": [[2,1],[1,1]]}}],
               "labels": [{"name": "left", "point": [0.5, 0.5]}], "voids": [[9, 9]]}}"#,
        )
        .unwrap();
        assert_eq!(
            (g.name.as_str(), g.vertices.len(), g.edges.len(), g.labels.len(), g.voids.len()),
            ("two", 6, 7, 1, 1)
        );
        assert!(matches!(&g.edges[5].curve, Some(SideCurve::Points(p)) if p.len() == 3));
        let back = graph_of_json(graph_to_json(&g)).unwrap();
        assert_eq!(format!("{:?}", back), format!("{:?}", g));
    }

    #[test]
    fn malformed_graphs_are_errors() {
        for (doc, want) in [
            (r#"{"graph": {"edges": []}}"#, "graph.vertices"),
            (r#"{"graph": {"vertices": [[0,0]], "edges": 3}}"#, "graph.edges"),
            (r#"{"graph": {"vertices": [[0,0]], "edges": [{"from": -1, "to": 0}]}}"#, "graph.edges[0].from"),
            (
                r#"{"graph": {"vertices": [[0,0]], "edges": [{"from": 0, "to": 0, "curve": 5}]}}"#,
                "graph.edges[0].curve",
            ),
            (r#"{"graph": {"vertices": [[0,0]], "edges": [], "labels": [{"point": [0,0]}]}}"#, "graph.labels[0].name"),
            (
                r#"{"graph": {"vertices": [[0,0]], "edges": [], "labels": [{"name": "a", "point": [0]}]}}"#,
                "graph.labels[0].point",
            ),
        ] {
            let e = parse(doc).unwrap_err().to_string();
            assert!(e.contains(want), "{want}: {e}");
        }
    }
}
