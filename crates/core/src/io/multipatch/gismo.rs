//! G+Smo XML `<MultiPatch>` files, read and written with G+Smo's own conventions
//! (`gsXml<gsMultiPatch>`, `boundaryInterface` in `gsCore/gsBoundary.h`):
//!
//! * `<patches type="id_range">first last</patches>` (or `type="id_index"` with a list
//!   of ids) names the `<Geometry>` elements (`TensorBSpline2`, `TensorNurbs2`) that
//!   are the patches, in order;
//! * sides are numbered `1` = west (`u = 0`), `2` = east (`u = 1`), `3` = south
//!   (`v = 0`), `4` = north (`v = 1`); `u` is the first tensor direction (`index="0"`),
//!   stored fastest, which is this crate's `xi`;
//! * an interface is `p1 s1 p2 s2 m0 m1 o0 o1`: patch sides `(p1, s1)` and `(p2, s2)`,
//!   the direction map `m` (direction `i` of patch `p1` runs along direction `m_i` of
//!   patch `p2`) and the orientation flags `o` (`o_i = 1` when direction `i` of `p1` and
//!   direction `m_i` of `p2` increase the same way). G+Smo overwrites the entries of the
//!   normal direction of `s1` (`m = dir(s2)`, `o = [par(s1) == par(s2)]`), so only the
//!   tangential direction `t = 1 - dir(s1)` carries data: `m_t` must be `1 - dir(s2)`,
//!   and the two sides run against each other exactly when `o_t = 0`;
//! * `<boundary>` lists `p s` pairs: the sides on the outer boundary.
//!
//! Patch indices in `<interfaces>` and `<boundary>` are geometry ids, mapped through
//! `<patches>` as G+Smo does. A patch whose boundary runs clockwise (G+Smo allows
//! left-handed patches; TUDflame has four) is transposed (`u <-> v`, sides west <->
//! south, east <-> north, orientations along the sides unchanged), so that every patch
//! of the layout is counter-clockwise. The writer puts each patch as a geometry with id
//! `k`, the patches as `id_range 0 n-1`, the interfaces with `m` and `o` in full, and
//! the outer sides: a file written here reads back as the same layout, bit for bit, and
//! G+Smo reads it as a `gsMultiPatch`.

use std::collections::HashMap;
use std::fmt::Write as _;

use crate::error::{Error, Result};
use crate::io::gismo::{children, nesting_exceeds, patch, xml_err, MAX_DEPTH, MAX_NODES};
use crate::io::gismo_writer::surface_to_gismo_xml;
use crate::multipatch::layout::{Interface, Layout, Patch, PatchSide};
use crate::spline::surface::{Side, Surface};

/// Whether `text` is a G+Smo XML document with a `<MultiPatch>` element of surfaces: one
/// whose `parDim` is not 1 (G+Smo stores the four boundary curves of a single domain as a
/// `<MultiPatch parDim="1">`; that is a boundary document, read by
/// [`crate::io::read`]).
pub(crate) fn is_gismo_multipatch(text: &str) -> bool {
    let body = text.trim_start_matches('\u{feff}').trim_start();
    body.starts_with('<')
        && body.match_indices("<MultiPatch").any(|(k, _)| {
            let tag = &body[k..];
            let tag = &tag[..tag.find('>').unwrap_or(tag.len())];
            let compact: String = tag.chars().filter(|c| !c.is_whitespace()).collect();
            !(compact.contains("parDim=\"1\"") || compact.contains("parDim='1'"))
        })
}

/// G+Smo's side number (1 west, 2 east, 3 south, 4 north) as a [`Side`].
pub(crate) fn side_of_gismo(k: i64) -> Option<Side> {
    match k {
        1 => Some(Side::West),
        2 => Some(Side::East),
        3 => Some(Side::South),
        4 => Some(Side::North),
        _ => None,
    }
}

/// The G+Smo number of a [`Side`].
pub(crate) fn gismo_of_side(s: Side) -> u8 {
    match s {
        Side::West => 1,
        Side::East => 2,
        Side::South => 3,
        Side::North => 4,
    }
}

/// Whether side `s` is at the end (`u = 1` or `v = 1`) of its normal direction.
fn at_end(s: Side) -> bool {
    matches!(s, Side::East | Side::North)
}

/// A side after the patch is transposed (`u <-> v`).
fn transposed_side(s: Side) -> Side {
    match s {
        Side::West => Side::South,
        Side::South => Side::West,
        Side::East => Side::North,
        Side::North => Side::East,
    }
}

/// The rows of a `<MultiPatch>`'s `<interfaces>` (none without one): eight integers each,
/// `p1 s1 p2 s2 m0 m1 o0 o1` (patch ids, sides 1 west, 2 east, 3 south, 4 north (5, 6
/// bottom, top), the matching and orientation flags).
pub(crate) fn interface_rows(mp: roxmltree::Node) -> Result<Vec<[i64; 8]>> {
    let Some(node) = children(mp, "interfaces").next() else { return Ok(Vec::new()) };
    let v = integers(node, "MultiPatch.interfaces")?;
    if v.len() % 8 != 0 {
        return Err(xml_err(
            "MultiPatch.interfaces",
            format!("{} numbers: 8 per interface (p1 s1 p2 s2 m0 m1 o0 o1)", v.len()),
        ));
    }
    Ok(v.chunks_exact(8).map(|r| std::array::from_fn(|i| r[i])).collect())
}

pub(crate) fn integers(node: roxmltree::Node, ctx: &str) -> Result<Vec<i64>> {
    let mut out = Vec::new();
    for t in node.descendants().filter(|n| n.is_text()) {
        for tok in t.text().unwrap_or("").split_whitespace() {
            if out.len() > 1 << 22 {
                return Err(xml_err(ctx, "too many numbers"));
            }
            out.push(tok.parse::<i64>().map_err(|_| xml_err(ctx, format!("not an integer: {tok:?}")))?);
        }
    }
    Ok(out)
}

/// The geometry ids of the patches of a `<MultiPatch>` element, in order (`<patches>`
/// of type `id_range` or `id_index`).
pub(crate) fn patch_ids(mp: roxmltree::Node) -> Result<Vec<i64>> {
    let pnode = children(mp, "patches").next().ok_or_else(|| xml_err("MultiPatch", "missing <patches>"))?;
    Ok(match pnode.attribute("type").unwrap_or("") {
        "id_range" => match integers(pnode, "MultiPatch.patches")?.as_slice() {
            &[first, last] if first <= last && last - first < 1 << 16 => (first..=last).collect(),
            other => return Err(xml_err("MultiPatch.patches", format!("id_range needs 'first last', got {other:?}"))),
        },
        "id_index" => integers(pnode, "MultiPatch.patches")?,
        other => return Err(xml_err("MultiPatch.patches", format!("unknown type {other:?} (id_range or id_index)"))),
    })
}

/// Parse a G+Smo multipatch file into a layout (see the module documentation); the
/// layout is not validated here ([`crate::multipatch::check::validate_layout`]), its name is empty.
pub fn parse_gismo_multipatch(text: &str) -> Result<Layout> {
    if nesting_exceeds(text, MAX_DEPTH) {
        return Err(xml_err("", format!("elements are nested more than {MAX_DEPTH} levels deep")));
    }
    let opts = roxmltree::ParsingOptions { allow_dtd: false, nodes_limit: MAX_NODES };
    let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| xml_err("", e.to_string()))?;
    let root = doc.root_element();
    let mut mps = children(root, "MultiPatch");
    let mp = mps.next().ok_or_else(|| xml_err("", "no <MultiPatch> element"))?;
    if mps.next().is_some() {
        return Err(xml_err("MultiPatch", "more than one <MultiPatch> element"));
    }
    if let Some(d) = mp.attribute("parDim") {
        if d.trim() != "2" {
            return Err(xml_err("MultiPatch", format!("parDim {d:?}: only planar patches (parDim 2) are supported")));
        }
    }
    // the geometries by id
    let mut by_id: HashMap<i64, roxmltree::Node> = HashMap::new();
    for g in children(root, "Geometry") {
        if let Some(id) = g.attribute("id").and_then(|i| i.trim().parse::<i64>().ok()) {
            by_id.insert(id, g);
        }
    }
    let ids = patch_ids(mp)?;
    let index: HashMap<i64, usize> = ids.iter().enumerate().map(|(k, &id)| (id, k)).collect();
    let mut patches = Vec::with_capacity(ids.len());
    let mut transposed = Vec::with_capacity(ids.len());
    for &id in &ids {
        let ctx = format!("Geometry (id {id})");
        let g = by_id.get(&id).ok_or_else(|| xml_err("MultiPatch.patches", format!("no <Geometry> with id {id}")))?;
        let rational = match g.attribute("type").unwrap_or("") {
            "TensorBSpline2" => false,
            "TensorNurbs2" => true,
            other => {
                return Err(xml_err(&ctx, format!("a patch must be a TensorBSpline2 or TensorNurbs2, found {other:?}")))
            }
        };
        let mut map = patch(*g, rational, &ctx)?;
        let flip = crate::io::surface_boundary_area(&map) < 0.0;
        if flip {
            map = map.transposed();
        }
        transposed.push(flip);
        patches.push(Patch::from_map(format!("p{id}"), map));
    }
    let patch_side = |id: i64, s: i64, ctx: &str| -> Result<PatchSide> {
        let p = *index.get(&id).ok_or_else(|| xml_err(ctx, format!("patch id {id} is not in <patches>")))?;
        let side =
            side_of_gismo(s).ok_or_else(|| xml_err(ctx, format!("side {s} (1 west, 2 east, 3 south, 4 north)")))?;
        Ok(PatchSide { patch: p, side: if transposed[p] { transposed_side(side) } else { side } })
    };
    let mut interfaces = Vec::new();
    for (k, r) in interface_rows(mp)?.iter().enumerate() {
        let ctx = format!("MultiPatch.interfaces[{k}]");
        let (s1, s2) = (
            side_of_gismo(r[1]).ok_or_else(|| xml_err(&ctx, format!("side {}", r[1])))?,
            side_of_gismo(r[3]).ok_or_else(|| xml_err(&ctx, format!("side {}", r[3])))?,
        );
        let (m, o) = ([r[4], r[5]], [r[6], r[7]]);
        if m.iter().any(|&x| !(0..2).contains(&x)) || o.iter().any(|&x| !(0..2).contains(&x)) {
            return Err(xml_err(&ctx, format!("direction map {m:?} and orientation {o:?} must be 0 or 1")));
        }
        // G+Smo's direction numbers: 0 = u (normal of west/east), 1 = v
        let normal = |s: Side| usize::from(matches!(s, Side::South | Side::North));
        let t = 1 - normal(s1);
        if m[t] != (1 - normal(s2)) as i64 {
            return Err(xml_err(
                &ctx,
                format!(
                    "direction map {m:?} sends the direction along side {} ({}) to direction {}, which is not the direction along side {} ({})",
                    r[1],
                    ["u", "v"][t],
                    m[t],
                    r[3],
                    ["u", "v"][1 - normal(s2)]
                ),
            ));
        }
        let first = patch_side(r[0], r[1], &ctx)?;
        let second = patch_side(r[2], r[3], &ctx)?;
        interfaces.push(Interface { first, second, reversed: o[t] == 0 });
    }
    let layout = Layout { name: String::new(), patches, interfaces };
    if let Some(node) = children(mp, "boundary").next() {
        let v = integers(node, "MultiPatch.boundary")?;
        if v.len() % 2 != 0 {
            return Err(xml_err("MultiPatch.boundary", "pairs 'patch side' expected"));
        }
        let mut outer = Vec::new();
        for (k, r) in v.chunks_exact(2).enumerate() {
            outer.push(patch_side(r[0], r[1], &format!("MultiPatch.boundary[{k}]"))?);
        }
        for p in 0..layout.patches.len() {
            for s in Side::ALL {
                let ps = PatchSide { patch: p, side: s };
                let listed = outer.contains(&ps);
                match (listed, layout.across(ps).is_some()) {
                    (true, true) => {
                        return Err(layout.error(p, Some(s), "is listed in <boundary> and in an interface"));
                    }
                    (false, false) => {
                        return Err(layout.error(
                            p,
                            Some(s),
                            "is neither in an interface nor in <boundary> (interfaces incomplete)",
                        ));
                    }
                    _ => {}
                }
            }
        }
    }
    Ok(layout)
}

/// The G+Smo multipatch document of the patch maps `maps` with the interfaces and outer
/// sides of `layout` (one map per patch, in order). `comment` goes into an XML comment.
pub fn multipatch_to_gismo_xml(layout: &Layout, maps: &[Surface], comment: &str) -> Result<String> {
    if maps.len() != layout.patches.len() {
        return Err(Error::Invalid(format!("{} maps for {} patches", maps.len(), layout.patches.len())));
    }
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<xml>\n");
    if !comment.is_empty() {
        let _ = writeln!(out, "  <!-- {} -->", comment.replace("--", "- -"));
    }
    for (k, map) in maps.iter().enumerate() {
        let single = surface_to_gismo_xml(map, "");
        let start = single.find("  <Geometry").ok_or_else(|| Error::Invalid("no geometry written".into()))?;
        let end = single.rfind("</Geometry>").ok_or_else(|| Error::Invalid("no geometry written".into()))?;
        let g = &single[start..end + "</Geometry>".len()];
        out.push_str(&g.replacen("id=\"0\"", &format!("id=\"{k}\""), 1));
        out.push('\n');
    }
    let n = layout.patches.len();
    let _ = writeln!(out, "  <MultiPatch parDim=\"2\" id=\"{n}\">");
    let _ = writeln!(out, "    <patches type=\"id_range\">0 {}</patches>", n.saturating_sub(1));
    if !layout.interfaces.is_empty() {
        out.push_str("    <interfaces>\n");
        for i in &layout.interfaces {
            let (a, b) = (i.first, i.second);
            let normal = |s: Side| usize::from(matches!(s, Side::South | Side::North));
            // directions map: the normal of a onto the normal of b, the tangents likewise
            let mut m = [0usize; 2];
            let mut o = [false; 2];
            m[normal(a.side)] = normal(b.side);
            m[1 - normal(a.side)] = 1 - normal(b.side);
            o[normal(a.side)] = at_end(a.side) == at_end(b.side);
            o[1 - normal(a.side)] = !i.reversed;
            let _ = writeln!(
                out,
                "      {} {} {} {} {} {} {} {}",
                a.patch,
                gismo_of_side(a.side),
                b.patch,
                gismo_of_side(b.side),
                m[0],
                m[1],
                u8::from(o[0]),
                u8::from(o[1])
            );
        }
        out.push_str("    </interfaces>\n");
    }
    out.push_str("    <boundary>\n");
    for ps in layout.outer_sides() {
        let _ = writeln!(out, "      {} {}", ps.patch, gismo_of_side(ps.side));
    }
    out.push_str("    </boundary>\n  </MultiPatch>\n</xml>\n");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::multipatch::check::validate_layout;

    /// A bilinear G+Smo patch with corners `c(u, v)` at `(0,0), (1,0), (0,1), (1,1)`.
    fn bilinear(id: usize, c: impl Fn(f64, f64) -> [f64; 2]) -> String {
        let pts: Vec<String> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
            .iter()
            .map(|&(u, v)| format!("{} {}", c(u, v)[0], c(u, v)[1]))
            .collect();
        format!(
            r#"<Geometry type="TensorBSpline2" id="{id}"><Basis type="TensorBSplineBasis2">
<Basis type="BSplineBasis" index="0"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
<Basis type="BSplineBasis" index="1"><KnotVector degree="1">0 0 1 1</KnotVector></Basis></Basis>
<coefs geoDim="2">{}</coefs></Geometry>"#,
            pts.join(" ")
        )
    }

    /// The eight symmetries of the unit square, `(u, v) -> (a, b)`.
    type Symmetry = fn(f64, f64) -> (f64, f64);

    const SYMMETRIES: [Symmetry; 8] = [
        |u, v| (u, v),
        |u, v| (1.0 - v, u),
        |u, v| (1.0 - u, 1.0 - v),
        |u, v| (v, 1.0 - u),
        |u, v| (v, u),
        |u, v| (1.0 - u, v),
        |u, v| (u, 1.0 - v),
        |u, v| (1.0 - v, 1.0 - u),
    ];

    /// The side of the square `(u, v)` that side `k` (G+Smo number) is, as end points.
    fn ends(k: i64) -> [(f64, f64); 2] {
        match k {
            1 => [(0.0, 0.0), (0.0, 1.0)],
            2 => [(1.0, 0.0), (1.0, 1.0)],
            3 => [(0.0, 0.0), (1.0, 0.0)],
            _ => [(0.0, 1.0), (1.0, 1.0)],
        }
    }

    /// Patch 0 is the unit square; patch 1 is the square to its right, parameterized in
    /// each of the eight symmetries (four of them clockwise, which the reader
    /// transposes). For each, with patch 0 or patch 1 first in the interface line and
    /// with the orientation flag right or wrong: the right flag gives a valid layout whose
    /// interface is reversed exactly when the two sides run against each other, the wrong
    /// one a layout whose validation says the orientations are inconsistent.
    #[test]
    fn orientation_flags_in_every_combination() {
        let mut checked = 0;
        for g in SYMMETRIES {
            let b = |u: f64, v: f64| {
                let (a, bb) = g(u, v);
                [1.0 + a, bb]
            };
            // the side of patch 1 on x = 1, and whether it runs up (as patch 0's east)
            let k = (1..=4).find(|&k| ends(k).iter().all(|&(u, v)| g(u, v).0 == 0.0)).unwrap();
            let [e0, e1] = ends(k);
            let up = g(e1.0, e1.1).1 > g(e0.0, e0.1).1;
            let others: Vec<String> = (1..=4).filter(|&s| s != k).map(|s| format!("1 {s}")).collect();
            for first_is_zero in [true, false] {
                for flag in [0, 1] {
                    let normal = |s: i64| usize::from(s >= 3);
                    let (p1, s1, p2, s2) = if first_is_zero { (0, 2, 1, k) } else { (1, k, 0, 2) };
                    let mut m = [0; 2];
                    let mut o = [0; 2];
                    m[normal(s1)] = normal(s2);
                    m[1 - normal(s1)] = 1 - normal(s2);
                    o[normal(s1)] = i32::from((s1 % 2 == 0) == (s2 % 2 == 0));
                    o[1 - normal(s1)] = flag;
                    let xml = format!(
                        "<xml>{}{}<MultiPatch parDim=\"2\" id=\"2\"><patches type=\"id_range\">0 1</patches>\
                         <interfaces>{p1} {s1} {p2} {s2} {} {} {} {}</interfaces><boundary>0 1 0 3 0 4 {}</boundary></MultiPatch></xml>",
                        bilinear(0, |u, v| [u, v]),
                        bilinear(1, b),
                        m[0],
                        m[1],
                        o[0],
                        o[1],
                        others.join(" ")
                    );
                    let layout = parse_gismo_multipatch(&xml).unwrap();
                    let right = (flag == 1) == up;
                    let v = validate_layout(&layout);
                    if right {
                        v.unwrap_or_else(|e| panic!("side {k}, flag {flag}: {e}"));
                        assert_eq!(layout.interfaces[0].reversed, !up);
                    } else {
                        let e = v.unwrap_err().to_string();
                        assert!(e.contains("orientations inconsistent"), "side {k}, flag {flag}: {e}");
                    }
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 32);
    }

    #[test]
    fn malformed_multipatch_files_are_errors() {
        let two = format!("{}{}", bilinear(0, |u, v| [u, v]), bilinear(1, |u, v| [1.0 + u, v]));
        let doc = |mp: &str| format!("<xml>{two}<MultiPatch parDim=\"2\" id=\"2\">{mp}</MultiPatch></xml>");
        let cases = [
            ("<patches type=\"id_range\">0 5</patches>", "no <Geometry> with id"),
            ("<patches type=\"id_range\">0 1</patches><interfaces>0 2 1 1 0 1 1</interfaces>", "8 per interface"),
            ("<patches type=\"id_range\">0 1</patches><interfaces>0 2 1 7 0 1 1 1</interfaces>", "side 7"),
            ("<patches type=\"id_range\">0 1</patches><interfaces>0 2 1 1 1 0 1 1</interfaces>", "direction map"),
            (
                "<patches type=\"id_range\">0 1</patches><interfaces>0 2 1 1 0 1 1 1</interfaces><boundary>0 1 0 3</boundary>",
                "interfaces incomplete",
            ),
            ("<patches type=\"list\">0 1</patches>", "unknown type"),
        ];
        for (mp, want) in cases {
            let e = parse_gismo_multipatch(&doc(mp)).unwrap_err().to_string();
            assert!(e.contains(want), "{mp}: {e}");
        }
        let ok = parse_gismo_multipatch(&doc(
            "<patches type=\"id_index\">1 0</patches><interfaces>0 2 1 1 0 1 1 1</interfaces>",
        ))
        .unwrap();
        // id_index: patch 0 of the layout is geometry 1
        assert_eq!(ok.patches[0].name, "p1");
        assert_eq!(ok.interfaces[0].first, PatchSide { patch: 1, side: Side::East });
        validate_layout(&ok).unwrap();
    }
}
