//! The JSON multipatch document of `formats.md`, with named curves as an addition:
//!
//! ```json
//! { "name": "two-squares",
//!   "curves": [ { "name": "mid", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 0], [1, 1]] } ],
//!   "patches": [ { "name": "a", "boundary": { "south": SIDE, "east": SIDE, "north": SIDE, "west": SIDE } },
//!                { "name": "b", "sides": { "south": "bs", "east": "be", "north": "bn",
//!                                          "west": { "curve": "mid", "reversed": false } } },
//!                { "name": "c", "map": { ... } } ],
//!   "interfaces": [ { "patches": ["a", "b"], "sides": ["east", "west"], "reversed": false } ] }
//! ```
//!
//! A patch is a four-sided `boundary` (its SIDEs B-spline or NURBS curves), a `map`
//! (its boundary curves are the sides), or `sides` naming a curve of the top-level
//! `curves` list per side (a string, or `{"curve", "reversed"}` when the side runs
//! against the curve). A curve named by two sides is one object: the two sides are an
//! interface (reversed when exactly one of them runs against the curve). `interfaces`
//! lists further pairs of coinciding sides by patch name (or index) and side; a pair
//! that a shared curve already implies may be repeated and must agree. Every other
//! field is ignored. On output every patch is a `map` with its own `report`, and the
//! document carries the interfaces and a top-level `report`.

use std::collections::HashMap;

use serde_json::{json, Map, Value};

use crate::error::{Error, Result};
use crate::io::json::{CurveJson, MapJson};
use crate::multipatch::layout::{Interface, Layout, Patch, PatchSide};
use crate::spline::curve::Curve;
use crate::spline::surface::{Side, Surface};

fn jerr(context: impl Into<String>, message: impl Into<String>) -> Error {
    Error::Json { context: context.into(), message: message.into() }
}

fn side_named(name: &str) -> Option<Side> {
    Side::ALL.into_iter().find(|s| s.name() == name)
}

fn curve_of(v: Value, ctx: &str) -> Result<Curve> {
    let c: CurveJson = serde_json::from_value(v).map_err(|e| jerr(ctx, e.to_string()))?;
    if c.periodic {
        return Err(jerr(ctx, "a periodic curve cannot be a patch side"));
    }
    c.into_curve().map_err(|e| e.within(ctx))
}

/// Parse a multipatch document (see the module documentation); the layout is not
/// validated here ([`crate::multipatch::check::validate_layout`]).
pub fn parse_json_multipatch(text: &str) -> Result<Layout> {
    let v: Value = serde_json::from_str(text.trim_start_matches('\u{feff}')).map_err(|e| jerr("", e.to_string()))?;
    let Value::Object(mut obj) = v else { return Err(jerr("", "the document must be an object")) };
    let name = match obj.remove("name") {
        Some(Value::String(s)) => s,
        None | Some(Value::Null) => String::new(),
        Some(_) => return Err(jerr("name", "must be a string")),
    };
    // named curves
    let mut curves: HashMap<String, Curve> = HashMap::new();
    if let Some(list) = obj.remove("curves") {
        let Value::Array(list) = list else { return Err(jerr("curves", "must be a list of named curves")) };
        for (k, item) in list.into_iter().enumerate() {
            let ctx = format!("curves[{k}]");
            let Value::Object(mut o) = item else { return Err(jerr(ctx, "must be a curve object with a name")) };
            let Some(Value::String(n)) = o.remove("name") else { return Err(jerr(ctx, "needs a \"name\" string")) };
            let c = curve_of(Value::Object(o), &ctx)?;
            if curves.insert(n.clone(), c).is_some() {
                return Err(jerr(ctx, format!("the curve name {n:?} is used twice")));
            }
        }
    }
    let Some(Value::Array(list)) = obj.remove("patches") else {
        return Err(jerr("patches", "a multipatch document needs a \"patches\" list"));
    };
    let mut patches = Vec::with_capacity(list.len());
    // (curve name, patch side, reversed) of every side that names a curve
    let mut uses: Vec<(String, PatchSide, bool)> = Vec::new();
    for (k, item) in list.into_iter().enumerate() {
        let ctx = format!("patches[{k}]");
        let Value::Object(mut o) = item else { return Err(jerr(ctx, "must be an object")) };
        let pname = match o.remove("name") {
            Some(Value::String(s)) => s,
            None | Some(Value::Null) => format!("p{k}"),
            Some(_) => return Err(jerr(format!("{ctx}.name"), "must be a string")),
        };
        let patch = if let Some(m) = o.remove("map") {
            let m: MapJson = serde_json::from_value(m).map_err(|e| jerr(format!("{ctx}.map"), e.to_string()))?;
            let map = m.to_surface().map_err(|e| e.within(&format!("{ctx}.map")))?;
            if map.knots.iter().any(|k| k.is_periodic()) {
                return Err(jerr(format!("{ctx}.map"), "a periodic map (a ring) cannot be a patch of a layout"));
            }
            Patch::from_map(pname, map)
        } else if let Some(b) = o.remove("boundary") {
            let Value::Object(mut b) = b else { return Err(jerr(format!("{ctx}.boundary"), "must be an object")) };
            let mut sides = Vec::with_capacity(4);
            for s in Side::ALL {
                let sctx = format!("{ctx}.boundary.{s}");
                let v = b.remove(s.name()).ok_or_else(|| jerr(&sctx, "missing"))?;
                if v.get("points").is_some() {
                    return Err(Error::Layout {
                        patch: format!("{k} ({pname})"),
                        side: s.name().into(),
                        reason: "is a point cloud: the sides of a multipatch layout are B-spline or NURBS curves (fit it first, e.g. with `winslow solve` on that patch alone)".into(),
                    });
                }
                sides.push(curve_of(v, &sctx)?);
            }
            Patch::from_sides(pname, sides.try_into().expect("four sides"))
        } else if let Some(s) = o.remove("sides") {
            let Value::Object(mut so) = s else { return Err(jerr(format!("{ctx}.sides"), "must be an object")) };
            let mut sides = Vec::with_capacity(4);
            for s in Side::ALL {
                let sctx = format!("{ctx}.sides.{s}");
                let (cname, rev) = match so.remove(s.name()) {
                    Some(Value::String(n)) => (n, false),
                    Some(Value::Object(r)) => {
                        let n = r.get("curve").and_then(Value::as_str).ok_or_else(|| jerr(&sctx, "needs \"curve\""))?;
                        let rev = match r.get("reversed") {
                            None | Some(Value::Null) => false,
                            Some(Value::Bool(b)) => *b,
                            Some(_) => return Err(jerr(&sctx, "\"reversed\" must be a boolean")),
                        };
                        (n.to_string(), rev)
                    }
                    _ => {
                        return Err(jerr(&sctx, "must name a curve: \"name\" or {\"curve\": name, \"reversed\": bool}"))
                    }
                };
                let c = curves.get(&cname).ok_or_else(|| jerr(&sctx, format!("no curve named {cname:?}")))?;
                sides.push(if rev { c.reversed() } else { c.clone() });
                uses.push((cname, PatchSide { patch: k, side: s }, rev));
            }
            Patch::from_sides(pname, sides.try_into().expect("four sides"))
        } else {
            return Err(jerr(ctx, "a patch needs a \"boundary\", a \"map\" or \"sides\""));
        };
        let mut patch = patch;
        patch.face = match o.remove("face") {
            None | Some(Value::Null) => None,
            Some(Value::String(s)) => Some(s),
            Some(Value::Number(x)) => Some(x.to_string()),
            Some(_) => return Err(jerr(format!("{ctx}.face"), "must be a string or a number")),
        };
        patches.push(patch);
    }
    let mut layout = Layout { name, patches, interfaces: Vec::new() };
    // interfaces implied by shared curves
    let mut by_curve: HashMap<&str, Vec<(PatchSide, bool)>> = HashMap::new();
    for (c, ps, r) in &uses {
        by_curve.entry(c.as_str()).or_default().push((*ps, *r));
    }
    for (c, ps, _) in &uses {
        let users = &by_curve[c.as_str()];
        if users.len() > 2 {
            return Err(layout.error(
                ps.patch,
                Some(ps.side),
                format!(
                    "names the curve {c:?}, which {} sides name: a curve is one side of at most two patches",
                    users.len()
                ),
            ));
        }
        if users.len() == 2 && users[0].0 == *ps {
            let ((a, ra), (b, rb)) = (users[0], users[1]);
            layout.interfaces.push(Interface { first: a, second: b, reversed: ra != rb });
        }
    }
    if let Some(list) = obj.remove("interfaces") {
        let Value::Array(list) = list else { return Err(jerr("interfaces", "must be a list")) };
        for (k, item) in list.into_iter().enumerate() {
            let ctx = format!("interfaces[{k}]");
            let pair = |key: &str| -> Result<[Value; 2]> {
                match item.get(key) {
                    Some(Value::Array(a)) if a.len() == 2 => Ok([a[0].clone(), a[1].clone()]),
                    _ => Err(jerr(&ctx, format!("needs \"{key}\": a list of two"))),
                }
            };
            let [pa, pb] = pair("patches")?;
            let [sa, sb] = pair("sides")?;
            let patch = |v: &Value| -> Result<usize> {
                match v {
                    Value::String(n) => {
                        layout.patch_index(n).ok_or_else(|| jerr(&ctx, format!("no patch named {n:?}")))
                    }
                    Value::Number(x) => x
                        .as_u64()
                        .map(|x| x as usize)
                        .filter(|&x| x < layout.patches.len())
                        .ok_or_else(|| jerr(&ctx, format!("no patch {x}"))),
                    _ => Err(jerr(&ctx, "a patch is named by its name or index")),
                }
            };
            let side = |v: &Value| -> Result<Side> {
                v.as_str()
                    .and_then(side_named)
                    .ok_or_else(|| jerr(&ctx, format!("{v} is not south, east, north or west")))
            };
            let reversed = match item.get("reversed") {
                None | Some(Value::Null) => false,
                Some(Value::Bool(b)) => *b,
                Some(_) => return Err(jerr(&ctx, "\"reversed\" must be a boolean")),
            };
            let first = PatchSide { patch: patch(&pa)?, side: side(&sa)? };
            let second = PatchSide { patch: patch(&pb)?, side: side(&sb)? };
            match layout.across(first) {
                Some((i, o)) if o == second => {
                    if i.reversed != reversed {
                        return Err(layout.error(
                            first.patch,
                            Some(first.side),
                            format!("{ctx} says reversed = {reversed}, but the shared curve says {}", i.reversed),
                        ));
                    }
                }
                _ => layout.interfaces.push(Interface { first, second, reversed }),
            }
        }
    }
    Ok(layout)
}

/// An interface as JSON: `{"patches": [names], "sides": [..], "reversed"}`.
pub(crate) fn interface_json(layout: &Layout, i: &Interface) -> Value {
    json!({
        "patches": [layout.patches[i.first.patch].name, layout.patches[i.second.patch].name],
        "sides": [i.first.side.name(), i.second.side.name()],
        "reversed": i.reversed,
    })
}

/// The multipatch output document: every patch a `map` with its `report` (the values
/// of `reports`, one per patch, `null` for none), the interfaces, and `report` at the
/// top level.
pub(crate) fn multipatch_to_json(
    layout: &Layout,
    maps: &[Surface],
    reports: Vec<Value>,
    report: Value,
) -> Result<Value> {
    if maps.len() != layout.patches.len() || reports.len() != maps.len() {
        return Err(Error::Invalid(format!(
            "{} maps and {} reports for {} patches",
            maps.len(),
            reports.len(),
            layout.patches.len()
        )));
    }
    let patches: Vec<Value> = layout
        .patches
        .iter()
        .zip(maps)
        .zip(reports)
        .map(|((p, m), r)| {
            let mut o = Map::new();
            o.insert("name".into(), json!(p.name));
            if let Some(f) = &p.face {
                o.insert("face".into(), json!(f));
            }
            o.insert("map".into(), json!(MapJson::from_surface(m)));
            if !r.is_null() {
                o.insert("report".into(), r);
            }
            Value::Object(o)
        })
        .collect();
    let interfaces: Vec<Value> = layout.interfaces.iter().map(|i| interface_json(layout, i)).collect();
    Ok(json!({ "name": layout.name, "patches": patches, "interfaces": interfaces, "report": report }))
}

/// The input document of `layout` with every patch a `boundary` of its four sides
/// (the interfaces listed): what [`parse_json_multipatch`] reads back as the same
/// layout.
pub(crate) fn layout_to_json(layout: &Layout) -> Value {
    let patches: Vec<Value> = layout
        .patches
        .iter()
        .map(|p| {
            let s = |side: Side| json!(CurveJson::from_curve(p.side(side)));
            let mut o = json!({ "name": p.name, "boundary": {
                "south": s(Side::South), "east": s(Side::East), "north": s(Side::North), "west": s(Side::West) } });
            if let Some(f) = &p.face {
                o["face"] = json!(f);
            }
            o
        })
        .collect();
    let interfaces: Vec<Value> = layout.interfaces.iter().map(|i| interface_json(layout, i)).collect();
    json!({ "name": layout.name, "patches": patches, "interfaces": interfaces })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::multipatch::check::validate_layout;

    const DOC: &str = r#"{ "name": "two",
      "curves": [
        { "name": "mid", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 0], [1, 1]] },
        { "name": "s0", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [1, 0]] },
        { "name": "n0", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 1], [1, 1]] },
        { "name": "w0", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 1], [0, 0]] } ],
      "patches": [
        { "name": "a", "sides": { "south": "s0", "east": "mid", "north": "n0", "west": { "curve": "w0", "reversed": true } } },
        { "name": "b", "boundary": {
            "south": { "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 0], [2, 0]] },
            "east": { "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[2, 0], [2, 1]] },
            "north": { "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 1], [2, 1]] },
            "west": { "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 0], [1, 1]] } } } ],
      "interfaces": [ { "patches": ["a", "b"], "sides": ["east", "west"], "reversed": false } ] }"#;

    #[test]
    fn named_curves_and_listed_interfaces() {
        let l = parse_json_multipatch(DOC).unwrap();
        assert_eq!(l.patches.len(), 2);
        assert_eq!(l.interfaces.len(), 1);
        validate_layout(&l).unwrap();
        // written as boundaries and read back: the same layout
        let back = parse_json_multipatch(&layout_to_json(&l).to_string()).unwrap();
        assert_eq!(back.interfaces, l.interfaces);
        for (a, b) in back.patches.iter().zip(&l.patches) {
            assert_eq!(a.sides, b.sides);
        }
    }

    #[test]
    fn a_curve_shared_by_two_patches_is_an_interface() {
        let doc = r#"{ "curves": [
            { "name": "mid", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 1], [1, 0]] },
            { "name": "s0", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [1, 0]] },
            { "name": "n0", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 1], [1, 1]] },
            { "name": "w0", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [0, 1]] },
            { "name": "s1", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 0], [2, 0]] },
            { "name": "n1", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 1], [2, 1]] },
            { "name": "e1", "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[2, 0], [2, 1]] } ],
          "patches": [
            { "name": "a", "sides": { "south": "s0", "east": { "curve": "mid", "reversed": true }, "north": "n0", "west": "w0" } },
            { "name": "b", "sides": { "south": "s1", "east": "e1", "north": "n1", "west": { "curve": "mid", "reversed": true } } } ] }"#;
        let l = parse_json_multipatch(doc).unwrap();
        assert_eq!(l.interfaces.len(), 1);
        let i = l.interfaces[0];
        assert_eq!(
            (i.first, i.second, i.reversed),
            (PatchSide { patch: 0, side: Side::East }, PatchSide { patch: 1, side: Side::West }, false)
        );
        validate_layout(&l).unwrap();
        // repeated in "interfaces", it must agree
        let listed = doc.replace(
            r#"] }"#,
            r#"], "interfaces": [ { "patches": [0, 1], "sides": ["east", "west"], "reversed": true } ] }"#,
        );
        let e = parse_json_multipatch(&listed).unwrap_err().to_string();
        assert!(e.contains("shared curve says false"), "{e}");
        // a third user of the curve
        let three = doc.replace(r#""e1", "north""#, r#""mid", "north""#);
        assert!(parse_json_multipatch(&three).unwrap_err().to_string().contains("3 sides name"));
    }

    #[test]
    fn bad_documents_are_errors() {
        let only = DOC.replace(
            r#""interfaces": [ { "patches": ["a", "b"], "sides": ["east", "west"], "reversed": false } ]"#,
            r#""interfaces": []"#,
        );
        let l = parse_json_multipatch(&only).unwrap();
        let e = validate_layout(&l).unwrap_err().to_string();
        assert!(e.contains("no interface joins them"), "{e}");
        let wrong = DOC.replace(r#""reversed": false } ] }"#, r#""reversed": true } ] }"#);
        let l = parse_json_multipatch(&wrong).unwrap();
        assert!(validate_layout(&l).unwrap_err().to_string().contains("orientations inconsistent"));
        let cloud = DOC.replace(
            r#""south": { "degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 0], [2, 0]] }"#,
            r#""south": { "points": [[1, 0], [2, 0]] }"#,
        );
        let e = parse_json_multipatch(&cloud).unwrap_err().to_string();
        assert!(e.contains("patch 1 (b), south side") && e.contains("point cloud"), "{e}");
        for (bad, want) in [
            (DOC.replace(r#""east": "mid""#, r#""east": "nope""#), "no curve named"),
            (DOC.replace(r#""sides": ["east", "west"]"#, r#""sides": ["east", "up"]"#), "is not south"),
            (DOC.replace(r#""patches": ["a", "b"]"#, r#""patches": ["a", "z"]"#), "no patch named"),
            ("{\"patches\": 3}".to_string(), "\"patches\" list"),
        ] {
            let e = parse_json_multipatch(&bad).unwrap_err().to_string();
            assert!(e.contains(want), "{want}: {e}");
        }
    }
}
