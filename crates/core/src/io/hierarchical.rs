//! THB maps ([`HierarchicalMap`]) in files: the JSON map kind `"thb"` (`formats-extensions.md`,
//! "THB map") and G+Smo XML `THBSpline2` (a `THBSplineBasis2` over the level-0
//! `TensorBSplineBasis2`, one `<box level="l">` per refined region), read as
//! [`Document::Thb`](super::Document::Thb) by [`read`](super::read) and written as
//! [`Output::Thb`](super::Output::Thb) by [`write`](super::write()). Both writers and
//! readers round-trip bit for bit: numbers in the shortest round-trip form, the refined
//! cells listed level by level, the control points in the order of the active functions
//! (by level, then the `eta` index, then the `xi` index: G+Smo's order too).
//!
//! **G+Smo boxes.** A box `<box level="l">i0 j0 i1 j1</box>` holds the level-`l` cells
//! `i0 <= i < i1`, `j0 <= j < j1` (indices of the level's distinct knots), which G+Smo
//! makes part of `Ω^l` together with their ancestors. Here a level-`l` box must consist
//! of whole children of level-`(l - 1)` cells (even corners), since the hierarchy refines
//! cells dyadically; the writer writes one box per refined cell.

use std::fmt::Write as _;

use roxmltree::Node;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::gismo::{children, only_child, tensor_basis, xml_err, MAX_DEPTH, MAX_NODES};
use super::gismo_writer::number;
use crate::error::{Error, Result};
use crate::spline::curve::Point;
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::hierarchical::{HierarchicalBasis, Index2};
use crate::spline::knots::KnotVector;

/// The `map` object of a THB map document.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ThbJson {
    /// Always `"thb"`.
    pub kind: String,
    /// `[p, q]`.
    pub degree: [usize; 2],
    /// Level-0 knot vectors `[xi, eta]` (open).
    pub knots: [Vec<f64>; 2],
    /// The knot vectors `[xi, eta]` of the given finer levels `1, 2, ...` (each splitting
    /// every element of the level below in two at one new simple knot; the levels past
    /// them halve the last one); absent when every level halves the one below.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub levels: Vec<[Vec<f64>; 2]>,
    /// `refined[l]`: the refined cells `[i, j]` of level `l` (each split into four cells
    /// of level `l + 1`).
    pub refined: Vec<Vec<Index2>>,
    /// One control point per active THB function, in the order of the module doc.
    pub control_points: Vec<Point>,
    /// Always `null` (THB maps are polynomial).
    #[serde(default)]
    pub weights: Option<Vec<f64>>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct ThbDoc {
    #[serde(default)]
    name: String,
    map: ThbJson,
}

/// Whether a JSON value is a THB map document (`map.kind == "thb"`).
pub(crate) fn is_thb_json(v: &Value) -> bool {
    v.get("map").and_then(|m| m.get("kind")).and_then(Value::as_str) == Some("thb")
}

fn map_of(map: ThbJson, ctx: &str) -> Result<HierarchicalMap> {
    let bad = |m: String| Error::Json { context: ctx.to_string(), message: m };
    if map.kind != "thb" {
        return Err(bad(format!("map kind {:?} is not \"thb\"", map.kind)));
    }
    if map.weights.is_some() {
        return Err(bad("a THB map is polynomial: weights must be null".into()));
    }
    let level = |[kx, ky]: [Vec<f64>; 2]| -> Result<[KnotVector; 2]> {
        Ok([KnotVector::new(map.degree[0], kx)?, KnotVector::new(map.degree[1], ky)?])
    };
    let mut levels = vec![level(map.knots)?];
    for kv in map.levels {
        levels.push(level(kv)?);
    }
    let basis = HierarchicalBasis::from_refined_levels(levels, &map.refined).map_err(|e| e.within(ctx))?;
    HierarchicalMap::new(basis, map.control_points).map_err(|e| e.within(ctx))
}

#[cfg(test)]
/// Parse a THB map document (JSON or G+Smo XML): its name (empty when none) and map.
pub(crate) fn parse_thb(text: &str) -> Result<(String, HierarchicalMap)> {
    let body = text.trim_start_matches('\u{feff}').trim_start();
    if body.starts_with('<') {
        return Ok((String::new(), parse_thb_xml(body)?));
    }
    let v: Value =
        serde_json::from_str(body).map_err(|e| Error::Json { context: "THB map".into(), message: e.to_string() })?;
    thb_of_json(v)
}

/// The name (empty when none) and map of a THB map document given as JSON; further
/// top-level fields (e.g. `report`) are ignored.
pub(crate) fn thb_of_json(v: Value) -> Result<(String, HierarchicalMap)> {
    let doc: ThbDoc =
        serde_json::from_value(v).map_err(|e| Error::Json { context: "THB map".into(), message: e.to_string() })?;
    Ok((doc.name, map_of(doc.map, "map")?))
}

/// The JSON document of a THB map; `extra` (e.g. `{"report": ...}`) is merged at the top.
pub(crate) fn thb_to_json(name: &str, map: &HierarchicalMap, extra: Option<Value>) -> Value {
    let b = &map.basis;
    let refined = b.refined_lists();
    let m = ThbJson {
        kind: "thb".into(),
        degree: b.degrees(),
        knots: b.knots(0).each_ref().map(|k| k.knots().to_vec()),
        levels: b.given_levels().iter().map(|kv| kv.each_ref().map(|k| k.knots().to_vec())).collect(),
        refined,
        control_points: map.control_points.clone(),
        weights: None,
    };
    let mut v = serde_json::to_value(ThbDoc { name: name.to_string(), map: m }).unwrap_or(Value::Null);
    if let (Value::Object(o), Some(Value::Object(e))) = (&mut v, extra) {
        o.extend(e);
    }
    v
}

/// The G+Smo XML document (`THBSpline2`) of a THB map; `comment` goes into an XML comment.
pub(crate) fn thb_to_gismo_xml(map: &HierarchicalMap, comment: &str) -> String {
    let b = &map.basis;
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<xml>\n");
    if !comment.is_empty() {
        let _ = writeln!(out, "  <!-- {} -->", comment.replace("--", "- -"));
    }
    out.push_str("  <Geometry type=\"THBSpline2\" id=\"0\">\n");
    out.push_str("    <Basis type=\"THBSplineBasis2\" manualLevels=\"false\">\n");
    out.push_str("      <Basis type=\"TensorBSplineBasis2\">\n");
    for (d, kv) in b.knots(0).iter().enumerate() {
        let knots: Vec<String> = kv.knots().iter().map(|&k| number(k)).collect();
        let _ = writeln!(out, "        <Basis type=\"BSplineBasis\" index=\"{d}\">");
        let _ = writeln!(out, "          <KnotVector degree=\"{}\">{}</KnotVector>", kv.degree(), knots.join(" "));
        out.push_str("        </Basis>\n");
    }
    out.push_str("      </Basis>\n");
    for l in 0..b.num_levels() {
        for [i, j] in b.refined_list(l) {
            let _ =
                writeln!(out, "      <box level=\"{}\">{} {} {} {}</box>", l + 1, 2 * i, 2 * j, 2 * i + 2, 2 * j + 2);
        }
    }
    out.push_str("    </Basis>\n    <coefs geoDim=\"2\">\n");
    for p in &map.control_points {
        let _ = writeln!(out, "      {} {}", number(p[0]), number(p[1]));
    }
    out.push_str("    </coefs>\n  </Geometry>\n</xml>\n");
    out
}

/// Integers of an element's text.
fn integers(node: Node, ctx: &str) -> Result<Vec<usize>> {
    let text = node.text().unwrap_or("");
    text.split_whitespace()
        .map(|t| t.parse::<usize>().map_err(|_| xml_err(ctx, format!("not a non-negative integer: {t:?}"))))
        .collect()
}

/// Parse a G+Smo XML document with one `THBSpline2` geometry.
pub(crate) fn parse_thb_xml(text: &str) -> Result<HierarchicalMap> {
    if super::gismo::nesting_exceeds(text, MAX_DEPTH) {
        return Err(xml_err("", format!("elements are nested more than {MAX_DEPTH} levels deep")));
    }
    let opts = roxmltree::ParsingOptions { allow_dtd: false, nodes_limit: MAX_NODES };
    let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| xml_err("", e.to_string()))?;
    let geoms: Vec<Node> =
        children(doc.root_element(), "Geometry").filter(|g| g.attribute("type") == Some("THBSpline2")).collect();
    let [geom] = geoms[..] else {
        return Err(xml_err("", format!("expected one THBSpline2 geometry, found {}", geoms.len())));
    };
    let ctx = "Geometry (THBSpline2)";
    let basis = only_child(geom, "Basis", ctx)?;
    let bctx = format!("{ctx}.Basis");
    if basis.attribute("type") != Some("THBSplineBasis2") {
        return Err(xml_err(&bctx, format!("expected a THBSplineBasis2, found type {:?}", basis.attribute("type"))));
    }
    if basis.attribute("manualLevels") == Some("true") {
        return Err(xml_err(&bctx, "manual levels are not supported: levels must halve every element"));
    }
    let knots = tensor_basis(only_child(basis, "Basis", &bctx)?, &format!("{bctx}.Basis"))?;
    let mut refined: Vec<Vec<Index2>> = Vec::new();
    for (k, bx) in children(basis, "box").enumerate() {
        let ctx = format!("{bctx}.box[{k}]");
        let level: usize = bx
            .attribute("level")
            .and_then(|l| l.trim().parse().ok())
            .ok_or_else(|| xml_err(&ctx, "missing or bad attribute level"))?;
        let c = integers(bx, &ctx)?;
        let [i0, j0, i1, j1] = c[..] else {
            return Err(xml_err(&ctx, format!("a box has 4 indices, found {}", c.len())));
        };
        if level == 0 || level > crate::spline::hierarchical::MAX_LEVELS || i0 >= i1 || j0 >= j1 {
            return Err(xml_err(&ctx, format!("empty box or bad level {level}")));
        }
        if [i0, j0, i1, j1].iter().any(|x| x % 2 != 0) {
            return Err(xml_err(&ctx, "box corners must be even (whole children of coarser cells)"));
        }
        // the box's parents and all their ancestors are refined
        for m in (0..level).rev() {
            let s = level - 1 - m; // shift from the parent level
            if refined.len() <= m {
                refined.resize(m + 1, Vec::new());
            }
            for j in (j0 / 2) >> s..((j1 / 2 - 1) >> s) + 1 {
                for i in (i0 / 2) >> s..((i1 / 2 - 1) >> s) + 1 {
                    if !refined[m].contains(&[i, j]) {
                        refined[m].push([i, j]);
                    }
                }
            }
        }
    }
    let b = HierarchicalBasis::from_refined(knots, &refined).map_err(|e| e.within(&bctx))?;
    let node = only_child(geom, "coefs", ctx)?;
    let vals = super::gismo::numbers(node, &format!("{ctx}.coefs"))?;
    if node.attribute("geoDim").is_some_and(|d| d.trim() != "2") || vals.len() != 2 * b.len() {
        return Err(Error::Length {
            context: format!("{ctx}.coefs"),
            what: "coefficients (geoDim 2)".into(),
            found: vals.len(),
            expected: 2 * b.len(),
        });
    }
    HierarchicalMap::new(b, vals.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::surface::Surface;
    use crate::testutil::Lcg;

    fn sample() -> HierarchicalMap {
        let kv = |p| KnotVector::open_from_breaks(p, &[0.0, 0.3, 0.55, 1.0], 1);
        let knots = [kv(2), kv(3)];
        let n = knots[0].num_basis() * knots[1].num_basis();
        let mut rng = Lcg::new(5);
        let cps = (0..n).map(|_| [rng.uniform() * 1e3, rng.uniform() / 3.0]).collect();
        let s = Surface::new(knots, cps, None).unwrap();
        let map = HierarchicalMap::from_surface(&s).unwrap().refined(&[(0, [1, 1]), (0, [0, 2])], 2).unwrap();
        let (l, c) = map.basis.cell_at(0.4, 0.4);
        map.refined(&[(l, c)], 2).unwrap()
    }

    #[test]
    fn json_round_trip_is_bit_for_bit() {
        let map = sample();
        let text = serde_json::to_string_pretty(&thb_to_json("t", &map, None)).unwrap();
        let (name, back) = parse_thb(&text).unwrap();
        assert_eq!(name, "t");
        assert_eq!(back.basis.active_functions(), map.basis.active_functions());
        assert_eq!(back.control_points, map.control_points);
        let again = serde_json::to_string_pretty(&thb_to_json("t", &back, None)).unwrap();
        assert_eq!(again, text);
    }

    /// A map on given levels (not halvings) keeps them through JSON: the same hierarchy,
    /// the same map; without them (the halvings read instead) the map would differ.
    #[test]
    fn json_round_trip_keeps_given_levels() {
        let kv = |p| KnotVector::open_from_breaks(p, &[0.0, 0.3, 0.55, 1.0], 1);
        let coarse = [kv(2), kv(3)];
        let fine = [coarse[0].with_inserted(&[0.1, 0.5, 0.9]), coarse[1].with_inserted(&[0.2, 0.4, 0.6])];
        let basis = HierarchicalBasis::with_levels(vec![coarse, fine]).unwrap();
        let mut rng = Lcg::new(8);
        let cps = (0..basis.len()).map(|_| [rng.uniform(), rng.uniform()]).collect();
        let map = HierarchicalMap::new(basis, cps).unwrap().refined(&[(0, [1, 1]), (0, [0, 2])], 2).unwrap();
        let v = thb_to_json("t", &map, None);
        assert_eq!(v["map"]["levels"].as_array().map(Vec::len), Some(1));
        let text = serde_json::to_string_pretty(&v).unwrap();
        let (_, back) = parse_thb(&text).unwrap();
        assert_eq!(back.basis.given_levels(), map.basis.given_levels());
        assert_eq!(back.basis.active_functions(), map.basis.active_functions());
        assert_eq!(serde_json::to_string_pretty(&thb_to_json("t", &back, None)).unwrap(), text);
        let (u, w) = (0.45, 0.35);
        assert_eq!(back.eval(u, w), map.eval(u, w));
        // the same document without its levels is another map (the levels halved)
        let mut halved = v.clone();
        halved["map"].as_object_mut().unwrap().remove("levels");
        let (_, other) = thb_of_json(halved).unwrap();
        assert_ne!(other.eval(u, w), map.eval(u, w));
    }

    #[test]
    fn gismo_xml_round_trip_is_bit_for_bit() {
        let map = sample();
        let xml = thb_to_gismo_xml(&map, "");
        let back = parse_thb_xml(&xml).unwrap();
        assert_eq!(back.basis.active_functions(), map.basis.active_functions());
        assert_eq!(back.control_points, map.control_points);
        assert_eq!(thb_to_gismo_xml(&back, ""), xml);
        // a G+Smo box over several cells at a level, given once: the same hierarchy as the cells one by one
        let b = &map.basis;
        let boxes: String = (0..b.num_levels())
            .flat_map(|l| b.refined_list(l).into_iter().map(move |c| (l, c)))
            .map(|(l, [i, j])| {
                format!("<box level=\"{}\">{} {} {} {}</box>", l + 1, 2 * i, 2 * j, 2 * i + 2, 2 * j + 2)
            })
            .collect();
        assert!(xml.contains(&boxes.replace("><", ">\n      <")));
    }

    /// The bundled example `tests/data/thb/sector_thb.json` (an annulus sector refined
    /// around two cells) is what this writer writes for it: rewritten with
    /// `WINSLOW_BLESS=1`.
    #[test]
    fn bundled_example_is_the_writers_output() {
        let kv = |p: usize| KnotVector::open_uniform(p, 4);
        let knots = [kv(3), kv(2)];
        let (gx, gy) = (knots[0].greville(), knots[1].greville());
        let cps = gy
            .iter()
            .flat_map(|&v| {
                gx.iter().map(move |&u| {
                    let (r, t) = (1.0 + u, 0.3 + 1.2 * v);
                    [r * t.cos(), r * t.sin()]
                })
            })
            .collect();
        let s = Surface::new(knots, cps, None).unwrap();
        let map = HierarchicalMap::from_surface(&s).unwrap().refined(&[(0, [1, 1]), (0, [3, 0])], 2).unwrap();
        let (l, c) = map.basis.cell_at(0.3, 0.3);
        let map = map.refined(&[(l, c)], 2).unwrap();
        let text = serde_json::to_string_pretty(&thb_to_json("sector_thb", &map, None)).unwrap() + "\n";
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/thb/sector_thb.json");
        if std::env::var_os("WINSLOW_BLESS").is_some() {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            crate::io::write_bytes(&path, text.as_bytes()).unwrap();
        }
        assert_eq!(std::fs::read_to_string(&path).unwrap(), text, "run with WINSLOW_BLESS=1 to rewrite");
    }

    #[test]
    fn bad_documents_are_typed_errors() {
        let map = sample();
        let xml = thb_to_gismo_xml(&map, "");
        let odd = xml.replacen("<box level=\"1\">2 2 4 4</box>", "<box level=\"1\">1 2 4 4</box>", 1);
        assert!(odd != xml && parse_thb_xml(&odd).is_err());
        let short = xml.replacen("    </coefs>", "    1 2\n    </coefs>", 1);
        assert!(matches!(parse_thb_xml(&short), Err(Error::Length { .. })));
        let mut v = thb_to_json("t", &map, None);
        v["map"]["refined"] = serde_json::json!([[[99, 0]]]);
        assert!(parse_thb(&v.to_string()).is_err());
        let mut v = thb_to_json("t", &map, None);
        v["map"]["weights"] = serde_json::json!([1.0]);
        assert!(parse_thb(&v.to_string()).is_err());
        let mut v = thb_to_json("t", &map, None);
        v["map"]["control_points"][0] = serde_json::json!([f64::MAX, 1e308]);
        v["map"]["control_points"].as_array_mut().unwrap().pop();
        assert!(parse_thb(&v.to_string()).is_err());
    }
}
