//! VTK output of a map: a legacy structured grid of samples, and the exact map as
//! Bézier cells.
//!
//! [`bezier_vtu`] writes one `VTK_BEZIER_QUADRILATERAL` cell (type 77) per element, its
//! `(p + 1)(q + 1)` control points the element's Bézier net from the Bézier extraction
//! ([`crate::spline::bezier`]), homogeneous for NURBS (`RationalWeights` point data),
//! with the degrees in the `HigherOrderDegrees` cell data. ParaView and VTK (≥ 9)
//! then draw the true curved map, not a sampled approximation. `det_J` is given as the
//! point data of the same cells, i.e. as Bernstein coefficients of degree `(p, q)` on
//! each element: those interpolating `det J` at the element's `(p + 1) × (q + 1)`
//! uniformly spaced points (det J itself has degree `(2p - 1, 2q - 1)`, so it is exact
//! at those points, not between them).

use std::fmt::Write as _;

use crate::error::Result;
use crate::spline::basis::BasisDerivs;
use crate::spline::bezier::bernstein;
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::surface::Surface;
use crate::verify::quality::sample_det_j;

/// VTK cell type of a Bézier quadrilateral.
pub(crate) const VTK_BEZIER_QUADRILATERAL: u8 = 77;

/// Legacy-VTK structured grid of the map sampled on `(n + 1)²` points with `det J`.
pub(crate) fn structured_grid_vtk(map: &Surface, n: usize) -> String {
    let s = sample_det_j(map, n);
    let mut out = String::new();
    let _ = writeln!(out, "# vtk DataFile Version 3.0\nwinslow map\nASCII\nDATASET STRUCTURED_GRID");
    let _ = writeln!(out, "DIMENSIONS {} {} 1\nPOINTS {} double", n + 1, n + 1, (n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let p = map.eval(i as f64 / n as f64, j as f64 / n as f64);
            let _ = writeln!(out, "{:?} {:?} 0", p[0], p[1]);
        }
    }
    let _ = writeln!(out, "POINT_DATA {}\nSCALARS det_J double 1\nLOOKUP_TABLE default", (n + 1) * (n + 1));
    for v in &s.values {
        let _ = writeln!(out, "{v:?}");
    }
    out
}

/// VTK's index of the point `(i, j)` of a higher-order quadrilateral of orders
/// `(p, q)`: the four corners, then the edges `j = 0`, `i = p`, `j = q`, `i = 0` (each
/// with its free index increasing), then the interior with `i` fastest
/// (`vtkHigherOrderQuadrilateral::PointIndexFromIJK`).
pub(crate) fn vtk_quad_index(i: usize, j: usize, p: usize, q: usize) -> usize {
    let ib = i == 0 || i == p;
    let jb = j == 0 || j == q;
    match (ib, jb) {
        (true, true) => match (i > 0, j > 0) {
            (false, false) => 0,
            (true, false) => 1,
            (true, true) => 2,
            (false, true) => 3,
        },
        (false, true) => 4 + (i - 1) + if j > 0 { p - 1 + q - 1 } else { 0 },
        (true, false) => 4 + (j - 1) + if i > 0 { p - 1 } else { 2 * (p - 1) + q - 1 },
        (false, false) => 4 + 2 * (p - 1 + q - 1) + (i - 1) + (p - 1) * (j - 1),
    }
}

/// Inverse of the Bernstein collocation matrix `B[a][k] = B_k^p(a / p)` (row-major),
/// by Gauss–Jordan elimination with partial pivoting (the matrix is totally positive).
pub(super) fn bernstein_interpolation(p: usize) -> Vec<f64> {
    let n = p + 1;
    let mut a = vec![0.0; n * n];
    let mut b = vec![0.0; n];
    for r in 0..n {
        bernstein(p, if p == 0 { 0.0 } else { r as f64 / p as f64 }, &mut b);
        a[r * n..(r + 1) * n].copy_from_slice(&b[..n]);
    }
    let mut inv: Vec<f64> = (0..n * n).map(|k| if k / n == k % n { 1.0 } else { 0.0 }).collect();
    for c in 0..n {
        let piv = (c..n).max_by(|&x, &y| a[x * n + c].abs().total_cmp(&a[y * n + c].abs())).expect("non-empty");
        for k in 0..n {
            a.swap(c * n + k, piv * n + k);
            inv.swap(c * n + k, piv * n + k);
        }
        let d = a[c * n + c];
        for k in 0..n {
            a[c * n + k] /= d;
            inv[c * n + k] /= d;
        }
        for r in (0..n).filter(|&r| r != c) {
            let f = a[r * n + c];
            for k in 0..n {
                a[r * n + k] -= f * a[c * n + k];
                inv[r * n + k] -= f * inv[c * n + k];
            }
        }
    }
    inv
}

/// One Bézier element: control points (`xi` fastest), weights, `det J` coefficients.
struct BezierElement {
    points: Vec<[f64; 2]>,
    weights: Vec<f64>,
    det_j: Vec<f64>,
}

/// The Bézier elements of `map`, element rows in `eta`, `xi` fastest.
fn bezier_elements(map: &Surface) -> Result<Vec<BezierElement>> {
    let ex = map.extraction()?;
    let [p, q] = map.degrees();
    let (inv_u, inv_v) = (bernstein_interpolation(p), bernstein_interpolation(q));
    let mut out = Vec::with_capacity(ex[0].elements.len() * ex[1].elements.len());
    let (mut bu, mut bv) = (BasisDerivs::default(), BasisDerivs::default());
    for (e1, &(s1, v0, v1)) in ex[1].elements.iter().enumerate() {
        for (e0, &(s0, u0, u1)) in ex[0].elements.iter().enumerate() {
            let hom = map.bezier_net(&ex, [e0, e1]);
            // det J at the uniform nodes, evaluated inside this element's span
            let mut vals = vec![0.0; (p + 1) * (q + 1)];
            for b in 0..=q {
                let t = if q == 0 { 0.0 } else { b as f64 / q as f64 };
                bv.eval_in_span(&map.knots[1], s1, v0 + t * (v1 - v0), 1);
                for a in 0..=p {
                    let s = if p == 0 { 0.0 } else { a as f64 / p as f64 };
                    bu.eval_in_span(&map.knots[0], s0, u0 + s * (u1 - u0), 1);
                    // det J with respect to the element's local coordinates is the global
                    // one times the element's area; ParaView's det_J is the global one
                    vals[b * (p + 1) + a] = map.derivs_with(&bu, &bv, 1).det_j();
                }
            }
            // D = inv_u V inv_v^T with V[b][a] (rows eta)
            let mut tmp = vec![0.0; (p + 1) * (q + 1)];
            for b in 0..=q {
                for k in 0..=p {
                    tmp[b * (p + 1) + k] = (0..=p).map(|a| inv_u[k * (p + 1) + a] * vals[b * (p + 1) + a]).sum();
                }
            }
            let mut det_j = vec![0.0; (p + 1) * (q + 1)];
            for l in 0..=q {
                for k in 0..=p {
                    det_j[l * (p + 1) + k] = (0..=q).map(|b| inv_v[l * (q + 1) + b] * tmp[b * (p + 1) + k]).sum();
                }
            }
            out.push(BezierElement {
                points: hom.iter().map(|(h, w)| [h[0] / w, h[1] / w]).collect(),
                weights: hom.iter().map(|h| h.1).collect(),
                det_j,
            });
        }
    }
    Ok(out)
}

/// The map as a VTK XML unstructured grid of Bézier quadrilaterals (see the module
/// documentation). `comment` (e.g. the certificate's verdict) goes into an XML comment.
pub(crate) fn bezier_vtu(map: &Surface, comment: &str) -> Result<String> {
    Ok(elements_vtu(&bezier_elements(map)?, map.degrees(), map.weights.is_some(), comment))
}

/// A THB map as Bézier quadrilaterals: one cell per active cell, its net the cell's
/// Bézier patch ([`HierarchicalMap::bezier_patches`]; the THB map restricted to an
/// active cell is one polynomial piece of degree `(p, q)`, so the cells are the map
/// exactly), cells in the order of [`crate::spline::hierarchical::HierarchicalBasis::active_cells`].
pub(crate) fn thb_bezier_vtu(map: &HierarchicalMap, comment: &str) -> Result<String> {
    let mut elements = Vec::new();
    for (_, _, patch) in map.bezier_patches()? {
        elements.extend(bezier_elements(&patch)?);
    }
    Ok(elements_vtu(&elements, map.basis.degrees(), false, comment))
}

/// The VTU document of Bézier `elements` of degree `[p, q]`.
fn elements_vtu(elements: &[BezierElement], [p, q]: [usize; 2], rational: bool, comment: &str) -> String {
    let npe = (p + 1) * (q + 1);
    let (ne, np) = (elements.len(), elements.len() * npe);
    // VTK order of each element's points
    let mut order = vec![0usize; npe];
    for l in 0..=q {
        for k in 0..=p {
            order[vtk_quad_index(k, l, p, q)] = l * (p + 1) + k;
        }
    }
    let mut out = String::from("<?xml version=\"1.0\"?>\n");
    if !comment.is_empty() {
        let _ = writeln!(out, "<!-- {} -->", comment.replace("--", "- -"));
    }
    let _ = writeln!(out, "<VTKFile type=\"UnstructuredGrid\" version=\"2.2\" byte_order=\"LittleEndian\">");
    let _ = writeln!(out, "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{ne}\">");
    let attrs = if rational { " RationalWeights=\"RationalWeights\"" } else { "" };
    let _ = writeln!(out, "<PointData Scalars=\"det_J\"{attrs}>");
    let array = |out: &mut String, name: &str, f: &dyn Fn(&BezierElement, usize) -> f64| {
        let _ = writeln!(out, "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">");
        for e in elements {
            for &k in &order {
                let _ = write!(out, "{:?} ", f(e, k));
            }
            out.push('\n');
        }
        out.push_str("</DataArray>\n");
    };
    array(&mut out, "det_J", &|e, k| e.det_j[k]);
    if rational {
        array(&mut out, "RationalWeights", &|e, k| e.weights[k]);
    }
    let _ = writeln!(out, "</PointData>\n<CellData HigherOrderDegrees=\"HigherOrderDegrees\">");
    let _ = writeln!(
        out,
        "<DataArray type=\"Float64\" Name=\"HigherOrderDegrees\" NumberOfComponents=\"3\" format=\"ascii\">"
    );
    for _ in 0..ne {
        let _ = write!(out, "{p} {q} 0 ");
    }
    let _ = writeln!(out, "\n</DataArray>\n</CellData>\n<Points>");
    let _ = writeln!(out, "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">");
    for e in elements {
        for &k in &order {
            let _ = write!(out, "{:?} {:?} 0 ", e.points[k][0], e.points[k][1]);
        }
        out.push('\n');
    }
    let _ = writeln!(out, "</DataArray>\n</Points>");
    cells_and_end(&mut out, ne, npe, VTK_BEZIER_QUADRILATERAL);
    out
}

/// The `<Cells>` of `ne` cells of type `cell_type` with `npe` consecutive points each,
/// and the closing tags of the file.
pub(super) fn cells_and_end(out: &mut String, ne: usize, npe: usize, cell_type: u8) {
    let _ = writeln!(out, "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">");
    for c in 0..ne {
        let ids: Vec<String> = (c * npe..(c + 1) * npe).map(|i| i.to_string()).collect();
        let _ = writeln!(out, "{}", ids.join(" "));
    }
    let _ = writeln!(out, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">");
    let offsets: Vec<String> = (1..=ne).map(|c| (c * npe).to_string()).collect();
    let _ = writeln!(out, "{}", offsets.join(" "));
    let _ = writeln!(out, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">");
    let types: Vec<String> = (0..ne).map(|_| cell_type.to_string()).collect();
    let _ = writeln!(out, "{}", types.join(" "));
    let _ = writeln!(out, "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>");
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    /// Reads the arrays of a VTU written by [`bezier_vtu`] or the volume writer (a
    /// test-side parser).
    pub(crate) fn arrays(vtu: &str) -> std::collections::BTreeMap<String, Vec<f64>> {
        let doc = roxmltree::Document::parse(vtu).unwrap();
        let mut out = std::collections::BTreeMap::new();
        for a in doc.descendants().filter(|n| n.has_tag_name("DataArray")) {
            let name = a.attribute("Name").unwrap_or("Points").to_string();
            let v = a.text().unwrap_or("").split_whitespace().map(|t| t.parse().unwrap()).collect();
            out.insert(name, v);
        }
        out
    }

    /// A curved quadratic-by-cubic map with a non-uniform knot, rational when asked.
    fn curved(rational: bool) -> Surface {
        let kx = KnotVector::open_uniform(2, 2).with_inserted(&[0.3]);
        let ky = KnotVector::open_uniform(3, 2);
        let (gx, gy) = (kx.greville(), ky.greville());
        let cps: Vec<[f64; 2]> = gy
            .iter()
            .flat_map(|&v| {
                gx.iter().map(move |&u| {
                    let (r, a) = (1.0 + v, u * std::f64::consts::FRAC_PI_2);
                    [r * a.cos(), r * a.sin() + 0.1 * u * v]
                })
            })
            .collect();
        let weights = rational.then(|| (0..cps.len()).map(|k| 1.0 + 0.05 * (k % 3) as f64).collect());
        Surface::new([kx, ky], cps, weights).unwrap()
    }

    /// Every cell's Bézier net, evaluated as a rational Bézier patch, is the map on that
    /// element; the det_J coefficients reproduce det J at the uniform nodes; counts,
    /// offsets and types are consistent.
    #[test]
    fn cells_reproduce_the_map() {
        for rational in [false, true] {
            let map = curved(rational);
            let vtu = bezier_vtu(&map, "test -- comment").unwrap();
            let a = arrays(&vtu);
            let [p, q] = map.degrees();
            let npe = (p + 1) * (q + 1);
            let ex = map.extraction().unwrap();
            let ne = ex[0].elements.len() * ex[1].elements.len();
            assert_eq!(a["types"], vec![77.0; ne]);
            assert_eq!(a["offsets"].last().copied(), Some((ne * npe) as f64));
            assert_eq!(a["connectivity"].len(), ne * npe);
            assert_eq!(a["HigherOrderDegrees"][..3], [p as f64, q as f64, 0.0]);
            assert_eq!(a.contains_key("RationalWeights"), rational);
            let pts = &a["Points"];
            let (mut bs, mut bt) = (vec![0.0; p + 1], vec![0.0; q + 1]);
            for (e1, &(_, v0, v1)) in ex[1].elements.iter().enumerate() {
                for (e0, &(_, u0, u1)) in ex[0].elements.iter().enumerate() {
                    let cell = e1 * ex[0].elements.len() + e0;
                    for (s, t) in [(0.3, 0.7), (0.0, 1.0), (0.9, 0.1)] {
                        bernstein(p, s, &mut bs);
                        bernstein(q, t, &mut bt);
                        let (mut x, mut y, mut w, mut dj) = (0.0, 0.0, 0.0, 0.0);
                        for l in 0..=q {
                            for k in 0..=p {
                                let at = cell * npe + vtk_quad_index(k, l, p, q);
                                let wk = if rational { a["RationalWeights"][at] } else { 1.0 };
                                let b = bs[k] * bt[l];
                                x += b * wk * pts[3 * at];
                                y += b * wk * pts[3 * at + 1];
                                w += b * wk;
                                dj += b * a["det_J"][at];
                            }
                        }
                        let e = map.eval(u0 + s * (u1 - u0), v0 + t * (v1 - v0));
                        assert!((x / w - e[0]).abs() < 1e-13 && (y / w - e[1]).abs() < 1e-13, "cell {cell}");
                        // at the uniform nodes the det J field is exact
                        if (s * p as f64).fract() == 0.0 && (t * q as f64).fract() == 0.0 {
                            let d = map.derivs(u0 + s * (u1 - u0), v0 + t * (v1 - v0), 1).det_j();
                            assert!((dj - d).abs() < 1e-12 * d.abs().max(1.0), "cell {cell}: {dj} vs {d}");
                        }
                    }
                }
            }
        }
    }

    /// A THB map (three levels) as Bézier cells: one cell per active cell, in the order
    /// of `active_cells`, whose Bézier net is the THB map on that cell (points to
    /// rounding at interior and corner points) and whose det_J coefficients reproduce
    /// the THB map's det J at the uniform nodes.
    #[test]
    fn thb_cells_reproduce_the_thb_map() {
        let thb = HierarchicalMap::from_surface(&curved(false)).unwrap().refined(&[(0, [0, 0])], 2).unwrap();
        let (l, c) = thb.basis.cell_at(0.1, 0.1);
        let thb = thb.refined(&[(l, c)], 2).unwrap();
        assert_eq!(thb.basis.num_levels(), 3);
        let a = arrays(&thb_bezier_vtu(&thb, "").unwrap());
        let [p, q] = thb.basis.degrees();
        let npe = (p + 1) * (q + 1);
        let cells = thb.basis.active_cells();
        assert_eq!(a["types"], vec![77.0; cells.len()]);
        assert_eq!(a["connectivity"].len(), cells.len() * npe);
        let (mut bs, mut bt) = (vec![0.0; p + 1], vec![0.0; q + 1]);
        for (cell, &(l, c)) in cells.iter().enumerate() {
            let [[u0, u1], [v0, v1]] = thb.basis.cell_bounds(l, c);
            for (s, t) in [(0.3, 0.7), (0.0, 1.0), (0.5, 0.0), (1.0, 1.0)] {
                bernstein(p, s, &mut bs);
                bernstein(q, t, &mut bt);
                let (mut x, mut y, mut dj) = (0.0, 0.0, 0.0);
                for l in 0..=q {
                    for k in 0..=p {
                        let at = cell * npe + vtk_quad_index(k, l, p, q);
                        x += bs[k] * bt[l] * a["Points"][3 * at];
                        y += bs[k] * bt[l] * a["Points"][3 * at + 1];
                        dj += bs[k] * bt[l] * a["det_J"][at];
                    }
                }
                let (u, v) = (u0 + s * (u1 - u0), v0 + t * (v1 - v0));
                let e = thb.eval(u, v);
                assert!((x - e[0]).abs() < 1e-13 && (y - e[1]).abs() < 1e-13, "cell {cell} at {s}, {t}");
                if (s * p as f64).fract() == 0.0 && (t * q as f64).fract() == 0.0 {
                    let d = thb.derivs(u, v).det_j();
                    assert!((dj - d).abs() < 1e-12 * d.abs().max(1.0), "cell {cell}: {dj} vs {d}");
                }
            }
        }
    }

    /// The VTK index map is a bijection onto `0..(p+1)(q+1)` with VTK's corner order.
    #[test]
    fn vtk_point_order() {
        for (p, q) in [(1, 1), (2, 3), (3, 2), (4, 4)] {
            let mut seen = vec![false; (p + 1) * (q + 1)];
            for j in 0..=q {
                for i in 0..=p {
                    let k = vtk_quad_index(i, j, p, q);
                    assert!(!seen[k]);
                    seen[k] = true;
                }
            }
            assert_eq!([vtk_quad_index(0, 0, p, q), vtk_quad_index(p, 0, p, q)], [0, 1]);
            assert_eq!([vtk_quad_index(p, q, p, q), vtk_quad_index(0, q, p, q)], [2, 3]);
        }
        // the 2x2 interior of a bicubic cell comes last, i fastest
        assert_eq!([vtk_quad_index(1, 1, 3, 3), vtk_quad_index(2, 1, 3, 3), vtk_quad_index(1, 2, 3, 3)], [12, 13, 14]);
    }
}
