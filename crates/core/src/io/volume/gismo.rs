//! G+Smo XML volumes: exactly one `<Geometry>` of type `TensorBSpline3` (a
//! `TensorBSplineBasis3` of three `BSplineBasis` children, ordered by their `index`
//! attribute, 0 for `xi`) or `TensorNurbs3` (a `TensorNurbsBasis3` wrapping the tensor
//! basis and `<weights>`), with `<coefs geoDim="3">`, `xi` index fastest, then `eta`.
//! Knot domains are mapped to `[0, 1]`. The same guards as for planar files apply
//! (nesting depth, node count, value count).

use roxmltree::Node;

use crate::error::{Error, Result};
use crate::io::gismo::{
    basis_type, bspline_basis, children, nesting_exceeds, numbers, only_child, weights, xml_err, MAX_DEPTH, MAX_NODES,
};
use crate::io::normalized_knots;
use crate::spline::knots::KnotVector;
use crate::spline::volume::Volume;

/// A `TensorBSplineBasis3`: the three univariate bases ordered by `index`.
fn tensor_basis3(node: Node, ctx: &str) -> Result<[KnotVector; 3]> {
    if basis_type(&node) != "TensorBSplineBasis3" {
        return Err(xml_err(ctx, format!("expected a TensorBSplineBasis3, found type {:?}", basis_type(&node))));
    }
    let mut parts: Vec<Node> = children(node, "Basis").collect();
    if parts.len() != 3 {
        return Err(xml_err(ctx, format!("expected three univariate bases, found {}", parts.len())));
    }
    let index = |n: &Node| n.attribute("index").and_then(|i| i.trim().parse::<usize>().ok());
    if parts.iter().all(|p| index(p).is_some()) {
        parts.sort_by_key(|p| index(p));
    }
    let mut out = Vec::with_capacity(3);
    for (d, p) in parts.into_iter().enumerate() {
        out.push(bspline_basis(p, &format!("{ctx}.Basis[{d}]"))?);
    }
    out.try_into().map_err(|_| xml_err(ctx, "three bases expected"))
}

/// The `n` points in space of a `<coefs geoDim="3">` node (a volume's, or a face's of a
/// volume boundary), three numbers each.
pub(crate) fn points3(node: Node, n: usize, ctx: &str) -> Result<Vec<[f64; 3]>> {
    let vals = numbers(node, ctx)?;
    if vals.len() != 3 * n {
        return Err(Error::Length {
            context: ctx.to_string(),
            what: "coefficients (geoDim 3)".into(),
            found: vals.len(),
            expected: 3 * n,
        });
    }
    Ok(vals.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

fn volume(geom: Node, rational: bool, ctx: &str) -> Result<Volume> {
    let basis = only_child(geom, "Basis", ctx)?;
    let bctx = format!("{ctx}.Basis");
    let (kv, tensor_ctx) = if rational {
        if basis_type(&basis) != "TensorNurbsBasis3" {
            return Err(xml_err(&bctx, format!("expected a TensorNurbsBasis3, found type {:?}", basis_type(&basis))));
        }
        let inner = only_child(basis, "Basis", &bctx)?;
        (tensor_basis3(inner, &format!("{bctx}.Basis"))?, bctx.clone())
    } else {
        (tensor_basis3(basis, &bctx)?, bctx.clone())
    };
    let n = kv.iter().fold(1usize, |a, k| a.saturating_mul(k.num_basis()));
    crate::error::check_control_point_count(n, ctx)?;
    let w = if rational { Some(weights(basis, n, &tensor_ctx)?) } else { None };
    let node = only_child(geom, "coefs", ctx)?;
    let cctx = format!("{ctx}.coefs");
    if let Some(d) = node.attribute("geoDim").filter(|d| d.trim() != "3") {
        return Err(xml_err(&cctx, format!("geoDim {d:?}: a volume needs geoDim 3")));
    }
    let cps = points3(node, n, &cctx)?;
    let v = Volume::new(kv, cps, w).map_err(|e| e.within(ctx))?;
    let mut norm = Vec::with_capacity(3);
    for k in &v.knots {
        norm.push(normalized_knots(k).map_err(|e| e.within(ctx))?);
    }
    let knots: [KnotVector; 3] = norm.try_into().map_err(|_| xml_err(ctx, "three knot vectors expected"))?;
    Ok(Volume { knots, ..v })
}

/// Parse a G+Smo XML file holding one `TensorBSpline3` or `TensorNurbs3` geometry.
pub(crate) fn parse_gismo_volume(text: &str) -> Result<Volume> {
    if nesting_exceeds(text, MAX_DEPTH) {
        return Err(xml_err("", format!("elements are nested more than {MAX_DEPTH} levels deep")));
    }
    let opts = roxmltree::ParsingOptions { allow_dtd: false, nodes_limit: MAX_NODES };
    let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| xml_err("", e.to_string()))?;
    let mut found = Vec::new();
    for (i, g) in children(doc.root_element(), "Geometry").enumerate() {
        let ctx = format!("Geometry[{i}]");
        match g.attribute("type").unwrap_or("") {
            "TensorBSpline3" => found.push(volume(g, false, &ctx)?),
            "TensorNurbs3" => found.push(volume(g, true, &ctx)?),
            other => {
                return Err(xml_err(
                    &ctx,
                    format!("a volume file holds one TensorBSpline3/TensorNurbs3, found {other:?}"),
                ))
            }
        }
    }
    match found.len() {
        1 => Ok(found.remove(0)),
        n => Err(xml_err("", format!("expected one TensorBSpline3/TensorNurbs3 geometry, found {n}"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::gismo_writer::volume_to_gismo_xml;
    use crate::io::{parse_document, Document};
    use crate::testutil::Lcg;

    fn random(rational: bool, seed: u64) -> Volume {
        let mut rng = Lcg::new(seed);
        let k = [
            KnotVector::open_uniform(2, 3).with_inserted(&[0.1 + 0.3 * rng.uniform()]),
            KnotVector::open_uniform(1, 2),
            KnotVector::open_uniform(3, 2),
        ];
        let n: usize = k.iter().map(KnotVector::num_basis).product();
        let cps = (0..n).map(|_| [1e7 + rng.uniform() / 3.0, rng.uniform() * 1e-9, rng.uniform() - 0.5]).collect();
        let w = rational.then(|| (0..n).map(|_| 0.5 + rng.uniform()).collect());
        Volume::new(k, cps, w).unwrap()
    }

    /// Writing then reading gives the same volume bit for bit, B-spline and NURBS.
    #[test]
    fn round_trip_is_exact() {
        for rational in [false, true] {
            let v = random(rational, 3 + rational as u64);
            let xml = volume_to_gismo_xml(&v, "certified -- yes");
            assert!(xml.contains(if rational { "TensorNurbs3" } else { "TensorBSpline3" }));
            let Document::Volume { volume, .. } = parse_document(&xml).unwrap() else { panic!("not a volume") };
            assert_eq!(volume, v);
            let bits = |v: &Volume| v.control_points.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&volume), bits(&v));
        }
    }

    #[test]
    fn malformed_volumes_are_errors() {
        let v = random(false, 1);
        let xml = volume_to_gismo_xml(&v, "");
        let two_d = xml.replace("geoDim=\"3\"", "geoDim=\"2\"");
        assert!(matches!(parse_gismo_volume(&two_d), Err(Error::Xml { .. })));
        let short = xml.replace("<coefs geoDim=\"3\">", "<coefs geoDim=\"3\">1 2 3");
        assert!(matches!(parse_gismo_volume(&short), Err(Error::Length { .. })));
        let basis = xml.replace("TensorBSplineBasis3", "TensorBSplineBasis2");
        assert!(matches!(parse_gismo_volume(&basis), Err(Error::Xml { .. })));
        let planar = "<xml><Geometry type=\"TensorBSpline2\"/></xml>";
        assert!(!matches!(parse_document(planar), Ok(Document::Volume { .. })));
    }
}
