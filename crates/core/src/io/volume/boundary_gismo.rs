//! The six boundary faces of a volume as a G+Smo `<MultiPatch parDim="2">` of surfaces in
//! space (`TensorBSpline2` / `TensorNurbs2` with `<coefs geoDim="3">`), read and written.
//!
//! Reading: a multipatch whose patches all have three coordinates and are not all in one
//! plane `z = const` is a face set (a planar one stays a multipatch layout). The faces
//! may come in any order and orientation: [`crate::boundary::hexahedron::assemble`] finds
//! which is which side of the parameter cube from the edges they share and turns each
//! one; errors name the face as `patch k (Geometry id N)`. When the file lists
//! `<interfaces>` (`p1 s1 p2 s2 m0 m1 o0 o1`, sides `1..4` of each face's own `(u, v)`
//! as in [`crate::io::multipatch::gismo`]), every interface must join two sides that
//! are one edge of the hexahedron; `<boundary>` must list no side (the faces close).
//!
//! Writing ([`volume_boundary_to_gismo_xml`]): the faces as geometries with ids `0..5`
//! in the order west, east, south, north, bottom, top, each in its own orientation (the
//! side's `(s, t)` as `(u, v)`), `<MultiPatch parDim="2" geoDim="3">` with
//! `<patches type="id_range">0 5</patches>` and the twelve interfaces, `m` and `o` in
//! full (the two faces along a cube edge both run with the edge's cube parameter, so the
//! tangential `o` is 1). Read back it is the same boundary, bit for bit.

use std::fmt::Write as _;

use roxmltree::Node;

use crate::boundary::hexahedron::{assemble, FaceSet};
use crate::boundary::volume::{CubeSide, VolumeBoundary};
use crate::error::{Error, Result};
use crate::io::gismo::{children, nesting_exceeds, only_child, tensor_basis2, xml_err, MAX_DEPTH, MAX_NODES};
use crate::io::gismo_writer::{knot_vector, number};
use crate::io::multipatch::gismo::{integers, interface_rows, patch_ids};
use crate::io::normalized_knots;
use crate::io::volume::gismo::points3;
use crate::spline::face::Face;
use crate::spline::knots::KnotVector;

/// A `TensorBSpline2` / `TensorNurbs2` with `geoDim="3"` as a face (knot domains mapped
/// to `[0, 1]`); `None` when its coefficients are not three-dimensional.
fn face(geom: Node, ctx: &str) -> Result<Option<Face>> {
    let rational = match geom.attribute("type").unwrap_or("") {
        "TensorBSpline2" => false,
        "TensorNurbs2" => true,
        _ => return Ok(None),
    };
    let coefs = only_child(geom, "coefs", ctx)?;
    if coefs.attribute("geoDim").map(str::trim) != Some("3") {
        return Ok(None);
    }
    let (kv, w, n) = tensor_basis2(geom, rational, ctx)?;
    let cps = points3(coefs, n, &format!("{ctx}.coefs"))?;
    let mut knots = Vec::with_capacity(2);
    for (d, k) in kv.iter().enumerate() {
        knots.push(normalized_knots(k).map_err(|e| e.within(&format!("{ctx}.Basis[{d}]")))?);
    }
    let knots: [KnotVector; 2] = knots.try_into().map_err(|_| xml_err(ctx, "two knot vectors expected"))?;
    Face::new(knots, cps, w).map(Some).map_err(|e| e.within(ctx))
}

/// Parse a G+Smo `<MultiPatch>` of surfaces in space as the six faces of a volume
/// (module doc); `Ok(None)` when the file is not one (a patch with two coordinates, or
/// every patch in one plane `z = const`), so that it is read as a multipatch layout.
pub(crate) fn parse_gismo_faces(text: &str) -> Result<Option<VolumeBoundary>> {
    if nesting_exceeds(text, MAX_DEPTH) {
        return Err(xml_err("", format!("elements are nested more than {MAX_DEPTH} levels deep")));
    }
    let opts = roxmltree::ParsingOptions { allow_dtd: false, nodes_limit: MAX_NODES };
    let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| xml_err("", e.to_string()))?;
    let root = doc.root_element();
    let Some(mp) = children(root, "MultiPatch").next() else { return Ok(None) };
    if mp.attribute("parDim").is_some_and(|d| d.trim() != "2") {
        return Ok(None);
    }
    let ids = patch_ids(mp)?;
    let mut faces = Vec::with_capacity(ids.len());
    let mut names = Vec::with_capacity(ids.len());
    for (k, &id) in ids.iter().enumerate() {
        let ctx = format!("Geometry (id {id})");
        let Some(g) = children(root, "Geometry")
            .find(|g| g.attribute("id").and_then(|i| i.trim().parse::<i64>().ok()) == Some(id))
        else {
            return Err(xml_err("MultiPatch.patches", format!("no <Geometry> with id {id}")));
        };
        let Some(f) = face(g, &ctx)? else { return Ok(None) };
        faces.push(f);
        names.push(format!("patch {k} (Geometry id {id})"));
    }
    let z0 = faces.first().and_then(|f| f.control_points.first()).map_or(0.0, |p| p[2]);
    if faces.iter().flat_map(|f| &f.control_points).all(|p| p[2] == z0) {
        return Ok(None);
    }
    let set = FaceSet::new(&faces, &names)?;
    let index = |id: i64, ctx: &str| {
        ids.iter().position(|&i| i == id).ok_or_else(|| xml_err(ctx, format!("patch id {id} is not in <patches>")))
    };
    for (k, r) in interface_rows(mp)?.iter().enumerate() {
        let ctx = format!("MultiPatch.interfaces[{k}]");
        let (a, b) = (index(r[0], &ctx)?, index(r[2], &ctx)?);
        let side = |s: i64| {
            usize::try_from(s - 1).ok().filter(|&s| s < 4).ok_or_else(|| xml_err(&ctx, format!("side {s} (1 to 4)")))
        };
        let (sa, sb) = (side(r[1])?, side(r[3])?);
        if set.edge_of(a, sa) != set.edge_of(b, sb) {
            return Err(Error::VolumeBoundary {
                face: format!("{}/{}", names[a], names[b]),
                edge: format!("interface {k}: sides {} and {}", r[1], r[3]),
                reason: "the interface joins two sides that do not meet: their end points differ".into(),
            });
        }
    }
    if let Some(node) = children(mp, "boundary").next() {
        let v = integers(node, "MultiPatch.boundary")?;
        if let [p, s, ..] = v[..] {
            return Err(xml_err(
                "MultiPatch.boundary",
                format!("side {s} of patch {p} is listed as boundary: the six faces of a volume close, none has a free side"),
            ));
        }
    }
    let (b, _) = assemble("", &faces, &names)?;
    Ok(Some(b))
}

/// The G+Smo number (1 to 4: `u = 0`, `u = 1`, `v = 0`, `v = 1`) of the side of the
/// face of `side` on which the cube direction `d` has the value `v`.
fn face_side(side: CubeSide, d: usize, v: usize) -> usize {
    let [ps, _] = side.params();
    if ps == d {
        1 + v
    } else {
        3 + v
    }
}

/// The G+Smo multipatch document of the six faces (module doc).
pub fn volume_boundary_to_gismo_xml(b: &VolumeBoundary, comment: &str) -> String {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<xml>\n");
    if !comment.is_empty() {
        let _ = writeln!(out, "  <!-- {} -->", comment.replace("--", "- -"));
    }
    for (k, side) in CubeSide::ALL.into_iter().enumerate() {
        let f = b.face(side);
        let rational = f.weights.is_some();
        let (d, v) = side.fixed();
        let _ = writeln!(
            out,
            "  <!-- {}: the side of the parameter cube where {} = {v} -->",
            side.name(),
            ["xi", "eta", "zeta"][d]
        );
        let geo = if rational { "TensorNurbs2" } else { "TensorBSpline2" };
        let _ = writeln!(out, "  <Geometry type=\"{geo}\" id=\"{k}\">");
        let mut indent = "    ".to_string();
        if rational {
            let _ = writeln!(out, "{indent}<Basis type=\"TensorNurbsBasis2\">");
            indent.push_str("  ");
        }
        let _ = writeln!(out, "{indent}<Basis type=\"TensorBSplineBasis2\">");
        for d in 0..2 {
            knot_vector(&mut out, &f.knots[d], d, &format!("{indent}  "));
        }
        let _ = writeln!(out, "{indent}</Basis>");
        if let Some(w) = &f.weights {
            let w: Vec<String> = w.iter().map(|&v| number(v)).collect();
            let _ = writeln!(out, "{indent}<weights>{}</weights>", w.join(" "));
            let _ = writeln!(out, "    </Basis>");
        }
        let _ = writeln!(out, "    <coefs geoDim=\"3\">");
        for p in &f.control_points {
            let _ = writeln!(out, "      {} {} {}", number(p[0]), number(p[1]), number(p[2]));
        }
        let _ = writeln!(out, "    </coefs>\n  </Geometry>");
    }
    out.push_str("  <MultiPatch parDim=\"2\" geoDim=\"3\" id=\"6\">\n    <patches type=\"id_range\">0 5</patches>\n");
    out.push_str("    <interfaces>\n");
    for da in 0..3 {
        for db in da + 1..3 {
            for va in 0..2 {
                for vb in 0..2 {
                    let (a, b) = (CubeSide::of(da, va), CubeSide::of(db, vb));
                    let (sa, sb) = (face_side(a, db, vb), face_side(b, da, va));
                    // G+Smo's direction numbers: 0 = u (normal of sides 1, 2), 1 = v
                    let normal = |s: usize| usize::from(s >= 3);
                    let at_end = |s: usize| s.is_multiple_of(2);
                    let (mut m, mut o) = ([0usize; 2], [1u8; 2]);
                    m[normal(sa)] = normal(sb);
                    m[1 - normal(sa)] = 1 - normal(sb);
                    o[normal(sa)] = u8::from(at_end(sa) == at_end(sb));
                    let _ = writeln!(
                        out,
                        "      {} {sa} {} {sb} {} {} {} {}",
                        a as usize, b as usize, m[0], m[1], o[0], o[1]
                    );
                }
            }
        }
    }
    out.push_str("    </interfaces>\n  </MultiPatch>\n</xml>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::hexahedron::SquareSymmetry;
    use crate::boundary::volume::tests::trilinear_faces;
    use crate::io::{parse_document, Document};

    /// Curved faces far from the origin with digits a short format would lose, one face
    /// rational, one on a finer basis.
    fn sample() -> VolumeBoundary {
        let mut faces = trilinear_faces(|u| [1e7 + u[0] + 0.2 * u[1] * u[2], u[1] / 3.0 + 1e-17, u[2] + 0.1 * u[0]]);
        // weights 1 on the edges keep them; the middle control point weighs 2
        let top = faces[5].elevated_in(0).unwrap().elevated_in(1).unwrap();
        let w: Vec<f64> = (0..9).map(|k| if k == 4 { 2.0 } else { 1.0 }).collect();
        faces[5] = Face::new(top.knots, top.control_points, Some(w)).unwrap();
        faces[2] = faces[2].refined_in(1, &KnotVector::open_from_breaks(1, &[0.0, 0.3, 1.0], 0)).unwrap();
        let b = VolumeBoundary { name: String::new(), faces };
        b.validate().unwrap();
        b
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let b = sample();
        let xml = volume_boundary_to_gismo_xml(&b, "six faces -- test");
        assert!(xml.contains("TensorNurbs2") && xml.contains("geoDim=\"3\""));
        let Document::VolumeBoundary(back) = parse_document(&xml).unwrap() else { panic!("not a volume boundary") };
        assert_eq!(back, b);
        let bits = |b: &VolumeBoundary| {
            b.faces.iter().flat_map(|f| f.control_points.iter().flatten().map(|x| x.to_bits())).collect::<Vec<_>>()
        };
        assert_eq!(bits(&back), bits(&b));
    }

    /// Two faces exchanged and three turned, written without interfaces: identified and
    /// turned back, bit for bit; a wrong interface, a listed boundary side and five
    /// faces are errors.
    #[test]
    fn shuffled_faces_and_bad_interfaces() {
        let b = sample();
        // west and top exchanged, two faces turned
        let order = [5, 1, 2, 3, 4, 0];
        let syms: Vec<SquareSymmetry> = SquareSymmetry::all().collect();
        let shuffled: Vec<Face> = order
            .iter()
            .enumerate()
            .map(|(k, &s)| syms[if k % 2 == 0 { 0 } else { k + 1 }].apply(&b.faces[s]).unwrap())
            .collect();
        let faces: [Face; 6] = shuffled.try_into().unwrap();
        let xml = volume_boundary_to_gismo_xml(&VolumeBoundary { name: String::new(), faces }, "");
        let start = xml.find("    <interfaces>").unwrap();
        let end = xml.find("</interfaces>\n").unwrap() + "</interfaces>\n".len();
        let plain = format!("{}{}", &xml[..start], &xml[end..]);
        let Document::VolumeBoundary(back) = parse_document(&plain).unwrap() else { panic!("not a volume boundary") };
        assert_eq!(back, b);
        let wrong = plain.replace(
            "<patches type=\"id_range\">0 5</patches>",
            "<patches type=\"id_range\">0 5</patches><interfaces>0 1 1 1 0 1 1 1</interfaces>",
        );
        let e = parse_document(&wrong).unwrap_err();
        assert!(matches!(&e, Error::VolumeBoundary { edge, .. } if edge.starts_with("interface 0")), "{e}");
        let bnd = plain.replace("</patches>", "</patches><boundary>2 3</boundary>");
        assert!(matches!(parse_document(&bnd), Err(Error::Xml { .. })));
        // five faces
        let five = xml.replace("<patches type=\"id_range\">0 5</patches>", "<patches type=\"id_range\">0 4</patches>");
        let e = parse_document(&five.replace("<interfaces>", "<!--").replace("</interfaces>", "-->")).unwrap_err();
        assert!(matches!(&e, Error::VolumeBoundary { reason, .. } if reason.contains("5 faces")), "{e}");
    }

    /// A planar multipatch with three coordinates stays a layout.
    #[test]
    fn planar_patches_are_a_layout() {
        let flat = trilinear_faces(|u| [u[0], u[1], 0.0 * u[2]]);
        let b = VolumeBoundary { name: String::new(), faces: flat };
        let xml = volume_boundary_to_gismo_xml(&b, "");
        assert!(parse_gismo_faces(&xml).unwrap().is_none());
    }
}
