//! G+Smo XML geometry files (<https://github.com/gismo/gismo>), read with `roxmltree`.
//!
//! Accepted: a root element holding `<Geometry>` children of type
//!
//! - `BSpline`: `<Basis type="BSplineBasis"><KnotVector degree="p">knots</KnotVector></Basis>`
//!   and `<coefs geoDim="2|3">x y [z] ...</coefs>`;
//! - `Nurbs`: `<Basis type="NurbsBasis">` wrapping a `BSplineBasis` and `<weights>`;
//! - `TensorBSpline2`: `<Basis type="TensorBSplineBasis2">` with two `BSplineBasis`
//!   children (`index="0"` for `xi`, `"1"` for `eta`), coefficients `xi` index fastest;
//! - `TensorNurbs2`: `<Basis type="TensorNurbsBasis2">` wrapping a `TensorBSplineBasis2`
//!   and `<weights>`.
//!
//! `z` of `geoDim="3"` is dropped; comments and other elements (`MultiPatch`, ...) are
//! ignored. A file with exactly four curves is a boundary whose sides are assigned by
//! matching endpoints ([`assign_sides`]); a file with one tensor patch is a map, transposed
//! when its boundary runs clockwise.

use roxmltree::Node;

use super::{normalized_curve, normalized_knots, reversed_curve, surface_boundary_area, Document};
use crate::boundary::validate::sample_side;
use crate::boundary::{Boundary, SideCurve};
use crate::error::{Error, Result, MAX_CONTROL_POINTS};
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Surface;

/// Largest number of XML nodes parsed (a guard against absurd inputs).
pub(crate) const MAX_NODES: u32 = 1 << 24;
/// Deepest element nesting accepted (G+Smo files nest about six levels; the XML parser
/// recurses per level, so absurd nesting must be refused before parsing).
pub(crate) const MAX_DEPTH: usize = 256;
/// Relative corner tolerance used to *choose* the side assignment of four curves; the
/// stricter check of `formats.md` is done by validation afterwards.
pub(crate) const ASSIGN_TOL: f64 = 1e-6;

pub(crate) fn xml_err(context: &str, message: impl Into<String>) -> Error {
    Error::Xml { context: context.to_string(), message: message.into() }
}

fn is(node: &Node, name: &str) -> bool {
    node.is_element() && node.tag_name().name() == name
}

/// Element children with the given tag name.
pub(crate) fn children<'a, 'i>(node: Node<'a, 'i>, name: &'a str) -> impl Iterator<Item = Node<'a, 'i>> + 'a {
    node.children().filter(move |c| is(c, name))
}

pub(super) fn only_child<'a, 'i>(node: Node<'a, 'i>, name: &str, ctx: &str) -> Result<Node<'a, 'i>> {
    let mut it = node.children().filter(|c| is(c, name));
    match (it.next(), it.next()) {
        (Some(c), None) => Ok(c),
        (None, _) => Err(xml_err(ctx, format!("missing <{name}>"))),
        (Some(_), Some(_)) => Err(xml_err(ctx, format!("more than one <{name}>"))),
    }
}

/// All text inside an element (comments skipped), as whitespace-separated numbers.
pub(super) fn numbers(node: Node, ctx: &str) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    for t in node.descendants().filter(|n| n.is_text()) {
        for tok in t.text().unwrap_or("").split_whitespace() {
            if out.len() >= 3 * MAX_CONTROL_POINTS + 64 {
                return Err(Error::TooLarge {
                    context: ctx.to_string(),
                    what: "number of values".into(),
                    found: out.len() + 1,
                    limit: 3 * MAX_CONTROL_POINTS + 64,
                });
            }
            let x: f64 = tok.parse().map_err(|_| xml_err(ctx, format!("not a number: {tok:?}")))?;
            if !x.is_finite() {
                return Err(Error::NonFinite {
                    context: ctx.to_string(),
                    what: format!("value {} is {tok}", out.len()),
                });
            }
            out.push(x);
        }
    }
    Ok(out)
}

pub(super) fn basis_type<'a>(node: &Node<'a, '_>) -> &'a str {
    node.attribute("type").unwrap_or("")
}

/// `<Basis type="BSplineBasis"><KnotVector degree="p">...</KnotVector></Basis>`.
pub(super) fn bspline_basis(node: Node, ctx: &str) -> Result<KnotVector> {
    if basis_type(&node) != "BSplineBasis" {
        return Err(xml_err(ctx, format!("expected a BSplineBasis, found type {:?}", basis_type(&node))));
    }
    let kv = only_child(node, "KnotVector", ctx)?;
    let ctx = format!("{ctx}.KnotVector");
    let deg = kv.attribute("degree").ok_or_else(|| xml_err(&ctx, "missing attribute degree"))?;
    let degree: usize =
        deg.trim().parse().map_err(|_| xml_err(&ctx, format!("degree {deg:?} is not a non-negative integer")))?;
    let knots = numbers(kv, &ctx)?;
    KnotVector::new(degree, knots).map_err(|e| e.within(&ctx))
}

/// `<coefs geoDim="d">`: `n` points of `d` coordinates, `z` dropped.
fn coefs(geom: Node, n: usize, ctx: &str) -> Result<Vec<Point>> {
    let node = only_child(geom, "coefs", ctx)?;
    let ctx = format!("{ctx}.coefs");
    let vals = numbers(node, &ctx)?;
    let dim = match node.attribute("geoDim") {
        Some(d) => d.trim().parse::<usize>().map_err(|_| xml_err(&ctx, format!("geoDim {d:?} is not an integer")))?,
        None if n > 0 && vals.len() % n == 0 => vals.len() / n,
        None => return Err(xml_err(&ctx, "missing attribute geoDim")),
    };
    if dim != 2 && dim != 3 {
        return Err(xml_err(&ctx, format!("geoDim {dim} is not supported (planar geometries only: 2 or 3)")));
    }
    if vals.len() != n * dim {
        return Err(Error::Length {
            context: ctx,
            what: format!("coefficients (geoDim {dim})"),
            found: vals.len(),
            expected: n * dim,
        });
    }
    Ok(vals.chunks_exact(dim).map(|c| [c[0], c[1]]).collect())
}

pub(super) fn weights(basis: Node, n: usize, ctx: &str) -> Result<Vec<f64>> {
    let node = only_child(basis, "weights", ctx)?;
    let ctx = format!("{ctx}.weights");
    let w = numbers(node, &ctx)?;
    if w.len() != n {
        return Err(Error::Length { context: ctx, what: "weights".into(), found: w.len(), expected: n });
    }
    Ok(w)
}

/// A `BSpline` or `Nurbs` geometry.
fn curve(geom: Node, rational: bool, ctx: &str) -> Result<Curve> {
    let basis = only_child(geom, "Basis", ctx)?;
    let bctx = format!("{ctx}.Basis");
    let (kv, w) = if rational {
        if basis_type(&basis) != "NurbsBasis" {
            return Err(xml_err(&bctx, format!("expected a NurbsBasis, found type {:?}", basis_type(&basis))));
        }
        let kv = bspline_basis(only_child(basis, "Basis", &bctx)?, &format!("{bctx}.Basis"))?;
        let w = weights(basis, kv.num_basis(), &bctx)?;
        (kv, Some(w))
    } else {
        (bspline_basis(basis, &bctx)?, None)
    };
    let cps = coefs(geom, kv.num_basis(), ctx)?;
    let c = Curve::new(kv, cps, w).map_err(|e| e.within(ctx))?;
    normalized_curve(&c).map_err(|e| e.within(ctx))
}

/// A `TensorBSplineBasis2`: the two univariate bases ordered by their `index` attribute.
pub(super) fn tensor_basis(node: Node, ctx: &str) -> Result<[KnotVector; 2]> {
    if basis_type(&node) != "TensorBSplineBasis2" {
        return Err(xml_err(ctx, format!("expected a TensorBSplineBasis2, found type {:?}", basis_type(&node))));
    }
    let parts: Vec<Node> = children(node, "Basis").collect();
    if parts.len() != 2 {
        return Err(xml_err(ctx, format!("expected two univariate bases, found {}", parts.len())));
    }
    let index = |n: &Node| n.attribute("index").and_then(|i| i.trim().parse::<usize>().ok());
    let (a, b) = match (index(&parts[0]), index(&parts[1])) {
        (Some(1), Some(0)) => (parts[1], parts[0]),
        _ => (parts[0], parts[1]),
    };
    Ok([bspline_basis(a, &format!("{ctx}.Basis[0]"))?, bspline_basis(b, &format!("{ctx}.Basis[1]"))?])
}

/// The basis of a `TensorBSpline2` (`rational` false) or `TensorNurbs2` geometry: its
/// two knot vectors (as given), its weights when rational, and its number of functions
/// (checked against the control-point limit). Planar patches and the faces of a volume
/// boundary (`io::volume::boundary_gismo`) read their bases with it.
pub(crate) fn tensor_basis2(
    geom: Node,
    rational: bool,
    ctx: &str,
) -> Result<([KnotVector; 2], Option<Vec<f64>>, usize)> {
    let basis = only_child(geom, "Basis", ctx)?;
    let bctx = format!("{ctx}.Basis");
    let (kv, w) = if rational {
        if basis_type(&basis) != "TensorNurbsBasis2" {
            return Err(xml_err(&bctx, format!("expected a TensorNurbsBasis2, found type {:?}", basis_type(&basis))));
        }
        let kv = tensor_basis(only_child(basis, "Basis", &bctx)?, &format!("{bctx}.Basis"))?;
        let n = kv[0].num_basis().saturating_mul(kv[1].num_basis());
        let w = weights(basis, n, &bctx)?;
        (kv, Some(w))
    } else {
        (tensor_basis(basis, &bctx)?, None)
    };
    let n = kv[0].num_basis().saturating_mul(kv[1].num_basis());
    crate::error::check_control_point_count(n, ctx)?;
    Ok((kv, w, n))
}

/// A `TensorBSpline2` or `TensorNurbs2` geometry, knot domains mapped to `[0, 1]`.
pub(crate) fn patch(geom: Node, rational: bool, ctx: &str) -> Result<Surface> {
    let (kv, w, n) = tensor_basis2(geom, rational, ctx)?;
    let cps = coefs(geom, n, ctx)?;
    let s = Surface::new(kv, cps, w).map_err(|e| e.within(ctx))?;
    let knots = [normalized_knots(&s.knots[0])?, normalized_knots(&s.knots[1])?];
    Ok(Surface { knots, ..s })
}

/// Parse a G+Smo XML file: four curves give a [`Document::Boundary`] (sides assigned by
/// `assign_sides`), one planar tensor patch gives a [`Document::Map`] (transposed when
/// the signed area enclosed by its boundary is negative, so that it preserves
/// orientation). The name is left empty.
pub fn parse_gismo_xml(text: &str) -> Result<Document> {
    if nesting_exceeds(text, MAX_DEPTH) {
        return Err(xml_err("", format!("elements are nested more than {MAX_DEPTH} levels deep")));
    }
    let opts = roxmltree::ParsingOptions { allow_dtd: false, nodes_limit: MAX_NODES };
    let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| xml_err("", e.to_string()))?;
    let root = doc.root_element();
    let mut curves = Vec::new();
    let mut patches = Vec::new();
    for (i, g) in children(root, "Geometry").enumerate() {
        let ctx = match g.attribute("id") {
            Some(id) => format!("Geometry[{i}] (id {id})"),
            None => format!("Geometry[{i}]"),
        };
        match g.attribute("type").unwrap_or("") {
            "BSpline" => curves.push(curve(g, false, &ctx)?),
            "Nurbs" => curves.push(curve(g, true, &ctx)?),
            "TensorBSpline2" => patches.push(patch(g, false, &ctx)?),
            "TensorNurbs2" => patches.push(patch(g, true, &ctx)?),
            other => return Err(xml_err(&ctx, format!("unsupported geometry type {other:?}"))),
        }
    }
    match (curves.len(), patches.len()) {
        (4, 0) => {
            let four: [Curve; 4] = curves.try_into().map_err(|_| xml_err("", "four curves expected"))?;
            assign_sides(four).map(Document::Boundary)
        }
        (0, 1) => {
            let mut map = patches.remove(0);
            if surface_boundary_area(&map) < 0.0 {
                map = map.transposed();
            }
            Ok(Document::Map { name: String::new(), map })
        }
        (c, p) => Err(xml_err(
            "",
            format!("expected four BSpline/Nurbs curves or one TensorBSpline2/TensorNurbs2 patch, found {c} curves and {p} patches"),
        )),
    }
}

/// Assign four curves (in file order) to south, east, north, west.
///
/// An assignment picks a curve and a direction for each side; it is admissible when its
/// four corners match (`south(0) = west(0)`, `south(1) = east(0)`, `north(0) = west(1)`,
/// `north(1) = east(1)`) within [`ASSIGN_TOL`] times the diameter of the control points'
/// bounding box. Among all `4! * 2^4` admissible assignments the one with the smallest
/// largest corner gap is chosen, preferring the G+Smo box-side order (curve 0 = west,
/// 1 = east, 2 = south, 3 = north, as stored; transposed when it runs clockwise), then
/// counter-clockwise ones, then the fewest reversed curves; a clockwise choice is
/// transposed. (All eight assignments describing one closed loop have the same gaps.)
pub(crate) fn assign_sides(curves: [Curve; 4]) -> Result<Boundary> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in curves.iter().flat_map(|c| &c.control_points) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let tol = ASSIGN_TOL * (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    let ends: Vec<(Point, Point)> = curves.iter().map(Curve::endpoints).collect();
    // Twice the signed area swept by each curve as stored about the box's centre
    // (shoelace terms of its polyline; about the origin, products of coordinates far from
    // it cancel every digit of the area).
    let o = [0.5 * lo[0] + 0.5 * hi[0], 0.5 * lo[1] + 0.5 * hi[1]];
    let sweep: Vec<f64> =
        curves.iter().map(|c| super::shoelace(&sample_side(&SideCurve::Spline(c.clone()), f64::INFINITY), o)).collect();
    let d = |a: Point, b: Point| (a[0] - b[0]).hypot(a[1] - b[1]);
    // sides[k] = (curve index, reversed) for south, east, north, west
    let gap_of = |sides: Assignment| {
        let e = |k: usize| {
            let (i, r) = sides[k];
            if r {
                (ends[i].1, ends[i].0)
            } else {
                ends[i]
            }
        };
        let (s, ea, n, w) = (e(0), e(1), e(2), e(3));
        d(s.0, w.0).max(d(s.1, ea.0)).max(d(n.0, w.1)).max(d(n.1, ea.1))
    };
    let area_of = |sides: Assignment| {
        let sign = [1.0, 1.0, -1.0, -1.0];
        (0..4).map(|k| sign[k] * if sides[k].1 { -sweep[sides[k].0] } else { sweep[sides[k].0] }).sum::<f64>() * 0.5
    };
    let build = |sides: Assignment, transpose: bool| -> Result<Boundary> {
        let mut out = Vec::with_capacity(4);
        for (i, r) in sides {
            out.push(SideCurve::Spline(if r { reversed_curve(&curves[i])? } else { curves[i].clone() }));
        }
        let sides: [SideCurve; 4] = out.try_into().map_err(|_| xml_err("", "four sides expected"))?;
        let b = Boundary { name: String::new(), sides };
        Ok(if transpose { b.transposed() } else { b })
    };

    let mut best: Option<(f64, bool, u32, Assignment)> = None;
    for perm in permutations4() {
        for mask in 0u32..16 {
            let sides: Assignment = std::array::from_fn(|k| (perm[k], mask >> k & 1 == 1));
            let gap = gap_of(sides);
            if gap.is_nan() || gap > tol {
                continue;
            }
            let key = (gap, clockwise(area_of(sides)), mask.count_ones());
            if best.is_none_or(|b| key < (b.0, b.1, b.2)) {
                best = Some((key.0, key.1, key.2, sides));
            }
        }
    }
    // The G+Smo box-side order wins whenever it fits as well as the best assignment.
    let gismo = [(2, false), (1, false), (3, false), (0, false)];
    if let Some((gap, ..)) = best {
        if gap_of(gismo) <= gap {
            return build(gismo, clockwise(area_of(gismo)));
        }
    }
    match best {
        Some((_, cw, _, sides)) => build(sides, cw),
        None => {
            let smallest = permutations4()
                .flat_map(|perm| (0u32..16).map(move |mask| std::array::from_fn(|k| (perm[k], mask >> k & 1 == 1))))
                .map(gap_of)
                .fold(f64::INFINITY, f64::min);
            Err(xml_err(
                "",
                format!(
                    "the four curves do not form a closed four-sided contour: every assignment to south/east/north/west leaves a corner gap of at least {smallest:.3e} (tolerance {tol:.3e})"
                ),
            ))
        }
    }
}

/// Whether elements nest deeper than `limit` (a conservative scan: comments, CDATA,
/// processing instructions, declarations and quoted attribute values are skipped;
/// self-closing tags do not count).
pub(crate) fn nesting_exceeds(text: &str, limit: usize) -> bool {
    let b = text.as_bytes();
    let find =
        |from: usize, pat: &[u8]| b[from.min(b.len())..].windows(pat.len()).position(|w| w == pat).map(|k| from + k);
    let (mut i, mut depth) = (0, 0usize);
    while i < b.len() {
        if b[i] != b'<' {
            i += 1;
            continue;
        }
        let rest = &b[i..];
        let skip_to = |pat: &[u8]| find(i, pat).map_or(b.len(), |k| k + pat.len());
        if rest.starts_with(b"<!--") {
            i = skip_to(b"-->");
        } else if rest.starts_with(b"<![CDATA[") {
            i = skip_to(b"]]>");
        } else if rest.starts_with(b"<?") {
            i = skip_to(b"?>");
        } else if rest.starts_with(b"<!") {
            i = skip_to(b">");
        } else if rest.starts_with(b"</") {
            depth = depth.saturating_sub(1);
            i = skip_to(b">");
        } else {
            // a start tag: find its end outside quoted attribute values
            let mut j = i + 1;
            let mut quote = None;
            while j < b.len() {
                match (quote, b[j]) {
                    (None, b'"' | b'\'') => quote = Some(b[j]),
                    (Some(q), c) if c == q => quote = None,
                    (None, b'>') => break,
                    _ => {}
                }
                j += 1;
            }
            if !(j > i + 1 && j < b.len() && b[j - 1] == b'/') {
                depth += 1;
                if depth > limit {
                    return true;
                }
            }
            i = j + 1;
        }
    }
    false
}

/// A side assignment: `(curve index, reversed)` for south, east, north, west.
type Assignment = [(usize, bool); 4];

/// Whether a signed area means a clockwise (or degenerate) contour.
fn clockwise(area: f64) -> bool {
    area.is_nan() || area <= 0.0
}

/// The 24 permutations of `0..4`.
fn permutations4() -> impl Iterator<Item = [usize; 4]> {
    (0..256usize).filter_map(|code| {
        let p = [code & 3, code >> 2 & 3, code >> 4 & 3, code >> 6 & 3];
        let distinct = (0..4).all(|i| (i + 1..4).all(|j| p[i] != p[j]));
        distinct.then_some(p)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::surface::Side;

    const SQUARE_CURVES: &str = r#"<?xml version="1.0"?>
<xml>
 <!-- a comment -->
 <Geometry type="BSpline" id="0"><Basis type="BSplineBasis"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
  <coefs geoDim="2">0 0 0 1</coefs></Geometry>
 <Geometry type="BSpline" id="1"><Basis type="BSplineBasis"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
  <coefs geoDim="2">1 0 1 1</coefs></Geometry>
 <Geometry type="BSpline" id="2"><Basis type="BSplineBasis"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
  <coefs geoDim="3">0 0 0 <!-- inside --> 1 0 0</coefs></Geometry>
 <Geometry type="Nurbs" id="3"><Basis type="NurbsBasis"><Basis type="BSplineBasis"><KnotVector degree="1">0 0 2 2</KnotVector></Basis>
  <weights>1 1</weights></Basis>
  <coefs geoDim="2">0 1 1 1</coefs></Geometry>
</xml>"#;

    #[test]
    fn four_curves_in_box_order() {
        let Document::Boundary(b) = parse_gismo_xml(SQUARE_CURVES).unwrap() else { panic!() };
        assert_eq!(b.side(Side::South).endpoints(), ([0., 0.], [1., 0.]));
        assert_eq!(b.side(Side::East).endpoints(), ([1., 0.], [1., 1.]));
        assert_eq!(b.side(Side::North).endpoints(), ([0., 1.], [1., 1.]));
        assert_eq!(b.side(Side::West).endpoints(), ([0., 0.], [0., 1.]));
        let SideCurve::Spline(n) = b.side(Side::North) else { panic!() };
        assert_eq!(n.domain(), (0.0, 1.0));
    }

    #[test]
    fn shuffled_and_reversed_curves_are_assigned() {
        // north reversed and listed first, then south, west reversed, east
        let xml = SQUARE_CURVES
            .replace("<coefs geoDim=\"2\">0 1 1 1</coefs>", "<coefs geoDim=\"2\">1 1 0 1</coefs>")
            .replace("<coefs geoDim=\"2\">0 0 0 1</coefs>", "<coefs geoDim=\"2\">0 1 0 0</coefs>");
        let Document::Boundary(b) = parse_gismo_xml(&xml).unwrap() else { panic!() };
        let r = crate::boundary::validate::validate(&b).unwrap();
        assert!((r.signed_area - 1.0).abs() < 1e-12);
    }

    #[test]
    fn clockwise_box_order_is_transposed() {
        // swap the roles: curve 0/1 horizontal, 2/3 vertical -> box order runs clockwise
        let c = |a: Point, b: Point| {
            Curve::new(KnotVector::new(1, vec![0., 0., 1., 1.]).unwrap(), vec![a, b], None).unwrap()
        };
        let b =
            assign_sides([c([0., 0.], [1., 0.]), c([0., 1.], [1., 1.]), c([0., 0.], [0., 1.]), c([1., 0.], [1., 1.])])
                .unwrap();
        assert!(crate::boundary::validate::validate(&b).is_ok());
        assert_eq!(b.side(Side::South).endpoints(), ([0., 0.], [1., 0.]));
    }

    #[test]
    fn open_contour_is_rejected() {
        let xml = SQUARE_CURVES.replace("1 0 1 1", "1 0 1 2");
        let e = parse_gismo_xml(&xml).unwrap_err();
        assert!(matches!(e, Error::Xml { .. }), "{e}");
    }

    #[test]
    fn patch_is_read_xi_fastest() {
        let xml = r#"<xml><Geometry type="TensorBSpline2"><Basis type="TensorBSplineBasis2">
          <Basis type="BSplineBasis" index="1"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
          <Basis type="BSplineBasis" index="0"><KnotVector degree="1">0 0 0.5 1 1</KnotVector></Basis></Basis>
          <coefs geoDim="2">0 0  1 0  2 0  0 1  1 1  2 1</coefs></Geometry></xml>"#;
        let Document::Map { map, .. } = parse_gismo_xml(xml).unwrap() else { panic!() };
        assert_eq!(map.shape(), [3, 2]);
        assert_eq!(map.cp(2, 0), [2., 0.]);
        // clockwise patch: transposed
        let cw = xml.replace("0 0  1 0  2 0  0 1  1 1  2 1", "0 0  1 0  2 0  0 -1  1 -1  2 -1");
        let Document::Map { map, .. } = parse_gismo_xml(&cw).unwrap() else { panic!() };
        assert_eq!(map.shape(), [2, 3]);
        assert!(map.derivs(0.5, 0.5, 1).det_j() > 0.0);
    }

    #[test]
    fn malformed_inputs_are_errors() {
        let cases = [
            "<xml>",
            "<xml><Geometry type=\"BSpline\"></Geometry></xml>",
            "<xml><Geometry type=\"TensorBSpline3\"/></xml>",
            "<!DOCTYPE x [<!ENTITY a \"aaaa\">]><xml>&a;</xml>",
            "",
        ];
        for c in cases {
            assert!(matches!(parse_gismo_xml(c), Err(Error::Xml { .. })), "{c}");
        }
        let bad_num = SQUARE_CURVES.replace("0 0 0 1</coefs>", "0 0 x 1</coefs>");
        assert!(matches!(parse_gismo_xml(&bad_num), Err(Error::Xml { .. })));
        let inf = SQUARE_CURVES.replace("0 0 0 1</coefs>", "0 0 inf 1</coefs>");
        assert!(matches!(parse_gismo_xml(&inf), Err(Error::NonFinite { .. })));
        let short = SQUARE_CURVES.replace("0 0 0 1</coefs>", "0 0 0</coefs>");
        assert!(matches!(parse_gismo_xml(&short), Err(Error::Length { .. })));
        let deg0 = SQUARE_CURVES.replacen("degree=\"1\"", "degree=\"0\"", 1);
        assert!(matches!(parse_gismo_xml(&deg0), Err(Error::Degree { .. })));
        let w0 = SQUARE_CURVES.replace("<weights>1 1</weights>", "<weights>1 0</weights>");
        assert!(matches!(parse_gismo_xml(&w0), Err(Error::Weight { .. })));
        let decreasing = SQUARE_CURVES.replacen("0 0 1 1", "0 1 0 1", 1);
        assert!(matches!(parse_gismo_xml(&decreasing), Err(Error::Knots { .. })));
    }

    #[test]
    fn deep_nesting_does_not_overflow() {
        let depth = 100_000;
        let xml = format!("<xml>{}{}</xml>", "<a>".repeat(depth), "</a>".repeat(depth));
        assert!(matches!(parse_gismo_xml(&xml), Err(Error::Xml { .. })));
        // unclosed tags count too
        assert!(parse_gismo_xml(&"<a x='/>'>".repeat(depth)).is_err());
        // siblings, self-closing tags and comments do not
        let flat = format!("<xml>{}<!-- <a><a><a> --></xml>", "<a/><b></b><c t=\"/\"/>".repeat(depth));
        assert!(!nesting_exceeds(&flat, 3));
        assert!(nesting_exceeds("<a><b><c><d>", 3));
    }
}
