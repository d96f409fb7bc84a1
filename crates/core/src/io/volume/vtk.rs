//! VTK output of a volume: a legacy structured grid of samples with `det J`
//! ([`volume_structured_vtk`]), and the exact map as `VTK_BEZIER_HEXAHEDRON` cells (type
//! 79, [`volume_bezier_vtu`]): one cell per element, its `(p+1)(q+1)(r+1)` points the
//! element's Bézier net from the Bézier extraction, homogeneous for NURBS
//! (`RationalWeights`), the degrees in `HigherOrderDegrees`, and `det J` as point data:
//! Bernstein coefficients of degree `(p, q, r)` interpolating `det J` at the element's
//! uniformly spaced nodes (exact there; `det J` itself has degree `(3p-1, 3q-1, 3r-1)`).
//!
//! Points are ordered as `vtkHigherOrderHexahedron::PointIndexFromIJK` does in VTK ≥ 9.1
//! for files of version 2.2 (written here): corners, then the edges along `i`, `j`, `k`
//! (the `k` edges at corners 0, 1, 2, 3), then the faces, then the interior, `i` fastest.

use std::fmt::Write as _;

use crate::error::Result;
use crate::io::vtk::{bernstein_interpolation, cells_and_end};
use crate::spline::basis::BasisDerivs;
use crate::spline::volume::Volume;

/// VTK cell type of a Bézier hexahedron.
pub(crate) const VTK_BEZIER_HEXAHEDRON: u8 = 79;

/// Legacy-VTK structured grid of the volume sampled on `(n_ξ+1)(n_η+1)(n_ζ+1)` points
/// with `det J`.
pub(crate) fn volume_structured_vtk(vol: &Volume, samples: [usize; 3]) -> String {
    let n = samples.map(|s| s.max(1));
    let total = (n[0] + 1) * (n[1] + 1) * (n[2] + 1);
    let mut out = String::new();
    let _ = writeln!(out, "# vtk DataFile Version 3.0\nwinslow volume\nASCII\nDATASET STRUCTURED_GRID");
    let _ = writeln!(out, "DIMENSIONS {} {} {}\nPOINTS {total} double", n[0] + 1, n[1] + 1, n[2] + 1);
    let mut dets = Vec::with_capacity(total);
    for k in 0..=n[2] {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                let d = vol.derivs([i as f64 / n[0] as f64, j as f64 / n[1] as f64, k as f64 / n[2] as f64]);
                let _ = writeln!(out, "{:?} {:?} {:?}", d.x[0], d.x[1], d.x[2]);
                dets.push(d.det_j());
            }
        }
    }
    let _ = writeln!(out, "POINT_DATA {total}\nSCALARS det_J double 1\nLOOKUP_TABLE default");
    for v in dets {
        let _ = writeln!(out, "{v:?}");
    }
    out
}

/// VTK's index of point `(i, j, k)` of a higher-order hexahedron of orders `o`.
pub(crate) fn vtk_hex_index(i: usize, j: usize, k: usize, o: [usize; 3]) -> usize {
    let (ib, jb, kb) = (i == 0 || i == o[0], j == 0 || j == o[1], k == 0 || k == o[2]);
    let nb = ib as usize + jb as usize + kb as usize;
    let corner = |i: usize, j: usize| match (i > 0, j > 0) {
        (false, false) => 0,
        (true, false) => 1,
        (true, true) => 2,
        (false, true) => 3,
    };
    if nb == 3 {
        return corner(i, j) + if k > 0 { 4 } else { 0 };
    }
    let (a, b, c) = (o[0] - 1, o[1] - 1, o[2] - 1);
    let mut off = 8;
    if nb == 2 {
        let up = if k > 0 { 2 * (a + b) } else { 0 };
        if !ib {
            return off + (i - 1) + if j > 0 { a + b } else { 0 } + up;
        }
        if !jb {
            return off + (j - 1) + if i > 0 { a } else { 2 * a + b } + up;
        }
        off += 4 * a + 4 * b;
        return off + (k - 1) + c * corner(i, j);
    }
    off += 4 * (a + b + c);
    if nb == 1 {
        if ib {
            return off + (j - 1) + b * (k - 1) + if i > 0 { b * c } else { 0 };
        }
        off += 2 * b * c;
        if jb {
            return off + (i - 1) + a * (k - 1) + if j > 0 { c * a } else { 0 };
        }
        off += 2 * c * a;
        return off + (i - 1) + a * (j - 1) + if k > 0 { a * b } else { 0 };
    }
    off += 2 * (b * c + c * a + a * b);
    off + (i - 1) + a * ((j - 1) + b * (k - 1))
}

/// Apply the 1-D operator `m` (`(n+1) x (n+1)`, row-major) along direction `dir` of a
/// tensor array of degrees `d`.
fn along(m: &[f64], d: [usize; 3], dir: usize, v: &[f64]) -> Vec<f64> {
    let n = d[dir] + 1;
    let strides = [1, d[0] + 1, (d[0] + 1) * (d[1] + 1)];
    let mut out = vec![0.0; v.len()];
    for (lin, o) in out.iter_mut().enumerate() {
        let idx = [lin % (d[0] + 1), (lin / (d[0] + 1)) % (d[1] + 1), lin / ((d[0] + 1) * (d[1] + 1))];
        let base = lin - idx[dir] * strides[dir];
        *o = (0..n).map(|a| m[idx[dir] * n + a] * v[base + a * strides[dir]]).sum();
    }
    out
}

/// The volume as a VTK XML unstructured grid of Bézier hexahedra (see the module doc).
pub(crate) fn volume_bezier_vtu(vol: &Volume, comment: &str) -> Result<String> {
    let ex = vol.extraction()?;
    let deg = vol.degrees();
    let npe = (deg[0] + 1) * (deg[1] + 1) * (deg[2] + 1);
    let inv = deg.map(bernstein_interpolation);
    let ne: usize = ex.iter().map(|x| x.elements.len()).product();
    let mut order = vec![0usize; npe];
    for k in 0..=deg[2] {
        for j in 0..=deg[1] {
            for i in 0..=deg[0] {
                order[vtk_hex_index(i, j, k, deg)] = (k * (deg[1] + 1) + j) * (deg[0] + 1) + i;
            }
        }
    }
    let rational = vol.weights.is_some();
    let (mut pts, mut wts, mut dets) = (String::new(), String::new(), String::new());
    let mut b: [BasisDerivs; 3] = Default::default();
    for ek in 0..ex[2].elements.len() {
        for ej in 0..ex[1].elements.len() {
            for ei in 0..ex[0].elements.len() {
                let e = [ei, ej, ek];
                let net = vol.bezier_net(&ex, e);
                // det J at the uniform nodes of the element, inside its spans
                let mut vals = vec![0.0; npe];
                for (lin, v) in vals.iter_mut().enumerate() {
                    let idx =
                        [lin % (deg[0] + 1), (lin / (deg[0] + 1)) % (deg[1] + 1), lin / ((deg[0] + 1) * (deg[1] + 1))];
                    for d in 0..3 {
                        let (s, a, bb) = ex[d].elements[e[d]];
                        let t = idx[d] as f64 / deg[d] as f64;
                        b[d].eval_in_span(&vol.knots[d], s, a + t * (bb - a), 1);
                    }
                    *v = vol.derivs_with(&b).det_j();
                }
                let coef = along(&inv[2], deg, 2, &along(&inv[1], deg, 1, &along(&inv[0], deg, 0, &vals)));
                for &k in &order {
                    let (h, w) = net[k];
                    let _ = write!(pts, "{:?} {:?} {:?} ", h[0] / w, h[1] / w, h[2] / w);
                    let _ = write!(wts, "{:?} ", w);
                    let _ = write!(dets, "{:?} ", coef[k]);
                }
                pts.push('\n');
                wts.push('\n');
                dets.push('\n');
            }
        }
    }
    let mut out = String::from("<?xml version=\"1.0\"?>\n");
    if !comment.is_empty() {
        let _ = writeln!(out, "<!-- {} -->", comment.replace("--", "- -"));
    }
    let _ = writeln!(out, "<VTKFile type=\"UnstructuredGrid\" version=\"2.2\" byte_order=\"LittleEndian\">");
    let _ = writeln!(out, "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{ne}\">", ne * npe);
    let attrs = if rational { " RationalWeights=\"RationalWeights\"" } else { "" };
    let _ = writeln!(out, "<PointData Scalars=\"det_J\"{attrs}>");
    let _ = writeln!(out, "<DataArray type=\"Float64\" Name=\"det_J\" format=\"ascii\">\n{dets}</DataArray>");
    if rational {
        let _ =
            writeln!(out, "<DataArray type=\"Float64\" Name=\"RationalWeights\" format=\"ascii\">\n{wts}</DataArray>");
    }
    let _ = writeln!(out, "</PointData>\n<CellData HigherOrderDegrees=\"HigherOrderDegrees\">");
    let _ = writeln!(
        out,
        "<DataArray type=\"Float64\" Name=\"HigherOrderDegrees\" NumberOfComponents=\"3\" format=\"ascii\">"
    );
    for _ in 0..ne {
        let _ = write!(out, "{} {} {} ", deg[0], deg[1], deg[2]);
    }
    let _ = writeln!(out, "\n</DataArray>\n</CellData>\n<Points>");
    let _ = writeln!(out, "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n{pts}</DataArray>");
    let _ = writeln!(out, "</Points>");
    cells_and_end(&mut out, ne, npe, VTK_BEZIER_HEXAHEDRON);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::vtk::tests::arrays;
    use crate::spline::bezier::bernstein;
    use crate::spline::knots::KnotVector;

    fn curved(rational: bool) -> Volume {
        let k = [KnotVector::open_uniform(2, 2), KnotVector::open_uniform(1, 2), KnotVector::open_uniform(3, 1)];
        let g = k.each_ref().map(KnotVector::greville);
        let mut cps = Vec::new();
        for &z in &g[2] {
            for &y in &g[1] {
                for &x in &g[0] {
                    cps.push([x + 0.1 * y * z, y + 0.2 * x * x, z * (1.0 + 0.3 * x)]);
                }
            }
        }
        let w = rational.then(|| (0..cps.len()).map(|i| 1.0 + 0.1 * (i % 3) as f64).collect());
        Volume::new(k, cps, w).unwrap()
    }

    /// Every cell's net, evaluated as a rational Bézier hexahedron through the VTK point
    /// order, is the volume on that element; `det_J` is exact at the uniform nodes.
    #[test]
    fn cells_reproduce_the_volume() {
        for rational in [false, true] {
            let vol = curved(rational);
            let a = arrays(&volume_bezier_vtu(&vol, "x -- y").unwrap());
            let deg = vol.degrees();
            let npe = (deg[0] + 1) * (deg[1] + 1) * (deg[2] + 1);
            let ex = vol.extraction().unwrap();
            let ne: usize = ex.iter().map(|x| x.elements.len()).product();
            assert_eq!(a["types"], vec![79.0; ne]);
            assert_eq!(a["connectivity"].len(), ne * npe);
            let (mut b0, mut b1, mut b2) = (vec![0.0; 4], vec![0.0; 4], vec![0.0; 4]);
            let cell = 3; // element (1, 1, 0)
            let e = [1, 1, 0];
            for s in [[0.3, 0.7, 0.2], [0.0, 0.5, 1.0], [0.5, 0.5, 2.0 / 3.0]] {
                bernstein(deg[0], s[0], &mut b0);
                bernstein(deg[1], s[1], &mut b1);
                bernstein(deg[2], s[2], &mut b2);
                let (mut h, mut dj) = ([0.0; 4], 0.0);
                for k in 0..=deg[2] {
                    for j in 0..=deg[1] {
                        for i in 0..=deg[0] {
                            let at = cell * npe + vtk_hex_index(i, j, k, deg);
                            let w = if rational { a["RationalWeights"][at] } else { 1.0 };
                            let f = b0[i] * b1[j] * b2[k];
                            for c in 0..3 {
                                h[c] += f * w * a["Points"][3 * at + c];
                            }
                            h[3] += f * w;
                            dj += f * a["det_J"][at];
                        }
                    }
                }
                let u: [f64; 3] = std::array::from_fn(|d| {
                    let (_, lo, hi) = ex[d].elements[e[d]];
                    lo + s[d] * (hi - lo)
                });
                let x = vol.eval(u);
                assert!((0..3).all(|c| (h[c] / h[3] - x[c]).abs() < 1e-13), "{h:?} {x:?}");
                if (0..3).all(|d| (s[d] * deg[d] as f64).fract().abs() < 1e-12) {
                    let d = vol.derivs(u).det_j();
                    assert!((dj - d).abs() < 1e-11 * d.abs().max(1.0), "{dj} vs {d}");
                }
            }
        }
    }

    /// The index map is a bijection with VTK's corners first and the interior last.
    #[test]
    fn vtk_hex_point_order() {
        for o in [[1, 1, 1], [2, 3, 1], [3, 2, 4]] {
            let n = (o[0] + 1) * (o[1] + 1) * (o[2] + 1);
            let mut seen = vec![false; n];
            for k in 0..=o[2] {
                for j in 0..=o[1] {
                    for i in 0..=o[0] {
                        let x = vtk_hex_index(i, j, k, o);
                        assert!(!seen[x]);
                        seen[x] = true;
                    }
                }
            }
            assert_eq!(vtk_hex_index(o[0], o[1], o[2], o), 6);
            assert_eq!(vtk_hex_index(0, o[1], 0, o), 3);
        }
        // quadratic: the k edge at corner 2 (i = j = 2) is edge 10, point 8 + 10 = 18
        assert_eq!(vtk_hex_index(2, 2, 1, [2, 2, 2]), 18);
        assert_eq!(vtk_hex_index(1, 1, 1, [2, 2, 2]), 26);
    }

    #[test]
    fn structured_grid_has_every_sample() {
        let vol = curved(false);
        let s = volume_structured_vtk(&vol, [2, 3, 4]);
        assert!(s.contains("DIMENSIONS 3 4 5") && s.contains("POINTS 60 double") && s.contains("POINT_DATA 60"));
        assert_eq!(s.lines().count(), 6 + 60 + 3 + 60);
    }
}
