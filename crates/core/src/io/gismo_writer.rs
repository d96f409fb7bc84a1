//! Writing a map as G+Smo XML: a `TensorBSpline2` (or `TensorNurbs2` with its weights;
//! volumes: `TensorBSpline3` / `TensorNurbs3`, [`volume_to_gismo_xml`])
//! in exactly the layout [`super::gismo`] reads, so that a map written here and read
//! back is the same map, bit for bit (knots, control points, weights), and G+Smo
//! (`gsReadFile`) loads it as a patch.
//!
//! Numbers are written in Rust's shortest round-trip form, so no digit is lost.

use std::fmt::Write as _;

use crate::spline::knots::KnotVector;
use crate::spline::surface::open_equivalent;
use crate::spline::surface::Surface;

/// A finite `f64` as the shortest text that parses back to the same value: plain
/// decimal for moderate magnitudes, scientific notation otherwise.
pub fn number(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-4..1e15).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

pub(crate) fn knot_vector(out: &mut String, kv: &KnotVector, index: usize, indent: &str) {
    let knots: Vec<String> = kv.knots().iter().map(|&k| number(k)).collect();
    let _ = writeln!(out, "{indent}<Basis type=\"BSplineBasis\" index=\"{index}\">");
    let _ = writeln!(out, "{indent}  <KnotVector degree=\"{}\">{}</KnotVector>", kv.degree(), knots.join(" "));
    let _ = writeln!(out, "{indent}</Basis>");
}

/// The G+Smo XML document of `map` (`xi` index fastest, as G+Smo stores tensor
/// coefficients). `comment` (e.g. the certificate's verdict) goes into an XML comment
/// at the top; `--` in it is replaced, as XML comments forbid it.
///
/// A map with a periodic direction (a ring's `eta`) is written as the same map on the
/// open, clamped knot vector of its domain ([`open_equivalent`]), with a comment saying
/// so: G+Smo's XML has no periodic B-spline basis, and a clamped tensor patch is what
/// every reader (G+Smo, IGES, ParaView) takes as a patch; the seam becomes two
/// coinciding rows of control points, and the continuity across it, no longer in the
/// basis, is that of the map.
pub(crate) fn surface_to_gismo_xml(map: &Surface, comment: &str) -> String {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<xml>\n");
    if !comment.is_empty() {
        let _ = writeln!(out, "  <!-- {} -->", comment.replace("--", "- -"));
    }
    let periodic = map.knots.iter().any(KnotVector::is_periodic);
    let opened = periodic.then(|| open_equivalent(map).ok()).flatten();
    let map = match &opened {
        Some(m) => {
            let dirs: Vec<&str> =
                ["xi", "eta"].into_iter().zip(&map.knots).filter(|(_, k)| k.is_periodic()).map(|(n, _)| n).collect();
            let _ = writeln!(
                out,
                "  <!-- periodic in {}: written as the equivalent clamped map on the open knot vector of its domain (the seam's two rows of control points coincide) -->",
                dirs.join(" and ")
            );
            m
        }
        None => map,
    };
    let rational = map.weights.is_some();
    let (geo, basis) = if rational { ("TensorNurbs2", "TensorNurbsBasis2") } else { ("TensorBSpline2", "") };
    let _ = writeln!(out, "  <Geometry type=\"{geo}\" id=\"0\">");
    let mut indent = "    ".to_string();
    if rational {
        let _ = writeln!(out, "{indent}<Basis type=\"{basis}\">");
        indent.push_str("  ");
    }
    let _ = writeln!(out, "{indent}<Basis type=\"TensorBSplineBasis2\">");
    for d in 0..2 {
        knot_vector(&mut out, &map.knots[d], d, &format!("{indent}  "));
    }
    let _ = writeln!(out, "{indent}</Basis>");
    if let Some(w) = &map.weights {
        let w: Vec<String> = w.iter().map(|&v| number(v)).collect();
        let _ = writeln!(out, "{indent}<weights>{}</weights>", w.join(" "));
        indent.truncate(4);
        let _ = writeln!(out, "{indent}</Basis>");
    }
    let _ = writeln!(out, "    <coefs geoDim=\"2\">");
    for p in &map.control_points {
        let _ = writeln!(out, "      {} {}", number(p[0]), number(p[1]));
    }
    let _ = writeln!(out, "    </coefs>\n  </Geometry>\n</xml>");
    out
}

/// The G+Smo XML document of a trivariate map: a `TensorBSpline3` (or `TensorNurbs3`
/// with its weights), three `BSplineBasis` children of a `TensorBSplineBasis3` (`index`
/// 0, 1, 2 for `xi`, `eta`, `zeta`), coefficients `xi` fastest then `eta`, `geoDim="3"`
/// — the layout [`crate::io::volume`] reads back bit for bit.
pub(crate) fn volume_to_gismo_xml(vol: &crate::spline::volume::Volume, comment: &str) -> String {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<xml>\n");
    if !comment.is_empty() {
        let _ = writeln!(out, "  <!-- {} -->", comment.replace("--", "- -"));
    }
    let rational = vol.weights.is_some();
    let geo = if rational { "TensorNurbs3" } else { "TensorBSpline3" };
    let _ = writeln!(out, "  <Geometry type=\"{geo}\" id=\"0\">");
    let mut indent = "    ".to_string();
    if rational {
        let _ = writeln!(out, "{indent}<Basis type=\"TensorNurbsBasis3\">");
        indent.push_str("  ");
    }
    let _ = writeln!(out, "{indent}<Basis type=\"TensorBSplineBasis3\">");
    for d in 0..3 {
        knot_vector(&mut out, &vol.knots[d], d, &format!("{indent}  "));
    }
    let _ = writeln!(out, "{indent}</Basis>");
    if let Some(w) = &vol.weights {
        let w: Vec<String> = w.iter().map(|&v| number(v)).collect();
        let _ = writeln!(out, "{indent}<weights>{}</weights>", w.join(" "));
        indent.truncate(4);
        let _ = writeln!(out, "{indent}</Basis>");
    }
    let _ = writeln!(out, "    <coefs geoDim=\"3\">");
    for p in &vol.control_points {
        let _ = writeln!(out, "      {} {} {}", number(p[0]), number(p[1]), number(p[2]));
    }
    let _ = writeln!(out, "    </coefs>\n  </Geometry>\n</xml>");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{parse_document, Document};
    use crate::spline::curve::Point;
    use crate::testutil::Lcg;

    fn random_map(rational: bool, seed: u64) -> Surface {
        let mut rng = Lcg::new(seed);
        let kx = KnotVector::open_uniform(3, 4).with_inserted(&[0.1 + 0.3 * rng.uniform()]);
        let ky = KnotVector::open_uniform(2, 3);
        let (gx, gy) = (kx.greville(), ky.greville());
        let mut cps = Vec::new();
        for &v in &gy {
            for &u in &gx {
                // curved but positive, with digits that a short format would lose
                cps.push([1e7 + u + 0.01 * rng.uniform() / 3.0, v * (1.0 + 0.3 * u) + 1e-9 * rng.uniform()]);
            }
        }
        let weights = rational.then(|| (0..cps.len()).map(|_| 0.5 + rng.uniform()).collect());
        Surface { knots: [kx, ky], control_points: cps, weights }
    }

    /// Writing then reading gives the same map bit for bit, B-spline and NURBS.
    #[test]
    fn round_trip_is_exact() {
        for rational in [false, true] {
            let map = random_map(rational, 7 + rational as u64);
            let xml = surface_to_gismo_xml(&map, "verdict: certified -- test");
            assert!(xml.contains(if rational { "TensorNurbs2" } else { "TensorBSpline2" }));
            assert!(!xml.contains("certified -- test"), "'--' must not appear inside an XML comment");
            let Document::Map { map: back, .. } = parse_document(&xml).unwrap() else { panic!("not read as a map") };
            assert_eq!(back.knots, map.knots);
            assert_eq!(back.weights, map.weights);
            let bits = |s: &Surface| {
                s.control_points.iter().flat_map(|p| [p[0].to_bits(), p[1].to_bits()]).collect::<Vec<_>>()
            };
            assert_eq!(bits(&back), bits(&map));
        }
    }

    #[test]
    fn numbers_round_trip() {
        for x in
            [0.0, -0.0, 1.0, 0.1, 1.0 / 3.0, 1e-300, 5e-324, 1e300, -2.5e15, 123456.789, f64::MAX, f64::MIN_POSITIVE]
        {
            assert_eq!(number(x).parse::<f64>().unwrap().to_bits(), x.to_bits(), "{x}");
        }
    }

    /// A periodic (ring) map, B-spline and NURBS, is written as its clamped equivalent:
    /// read back it is the same map at every parameter, with open knots, and the seam's
    /// rows of control points coincide.
    #[test]
    fn periodic_maps_are_written_clamped() {
        let mut rng = Lcg::new(11);
        for rational in [false, true] {
            let kx = KnotVector::open_uniform(3, 2);
            let ky = KnotVector::periodic_from_period(3, &[0.0, 0.1, 0.3, 0.3, 0.55, 0.7, 0.85], 1.0).unwrap();
            let (nx, d) = (kx.num_basis(), ky.dim());
            let free: Vec<Point> = (0..nx * d)
                .map(|k| {
                    let (i, j) = (k % nx, k / nx);
                    let (r, t) = (1.0 + i as f64 / nx as f64, std::f64::consts::TAU * j as f64 / d as f64);
                    [r * t.cos() + 0.01 * rng.uniform(), r * t.sin()]
                })
                .collect();
            let cps: Vec<Point> = (0..nx * ky.num_basis()).map(|k| free[(k / nx % d) * nx + k % nx]).collect();
            let weights = rational.then(|| {
                let w: Vec<f64> = (0..nx * d).map(|_| 0.5 + rng.uniform()).collect();
                (0..cps.len()).map(|k| w[(k / nx % d) * nx + k % nx]).collect()
            });
            let map = Surface::new([kx, ky], cps, weights).unwrap();
            let xml = surface_to_gismo_xml(&map, "ring");
            assert!(xml.contains("periodic in eta"), "{xml}");
            let Document::Map { map: back, .. } = parse_document(&xml).unwrap() else { panic!("not read as a map") };
            assert!(back.knots[1].is_open() && !back.knots[1].is_periodic());
            assert_eq!(back.knots[1].domain(), map.knots[1].domain());
            for a in 0..=12 {
                for b in 0..=40 {
                    let (u, v) = (a as f64 / 12.0, b as f64 / 40.0);
                    let (p, q) = (map.eval(u, v), back.eval(u, v));
                    assert!((p[0] - q[0]).abs() < 1e-13 && (p[1] - q[1]).abs() < 1e-13, "({u}, {v}): {p:?} {q:?}");
                }
            }
            let [bx, by] = back.shape();
            for i in 0..bx {
                let (s, n) = (back.control_points[i], back.control_points[(by - 1) * bx + i]);
                assert!((s[0] - n[0]).abs() < 1e-13 && (s[1] - n[1]).abs() < 1e-13);
            }
        }
    }
}
