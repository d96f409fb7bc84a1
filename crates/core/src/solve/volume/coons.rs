//! The faces of a volume boundary on one tensor basis, and the trivariate Coons patch
//! (transfinite interpolation) of them as the start of a solve.
//!
//! **Common bases.** Direction `d` of the cube is a parameter of four faces; each is
//! raised to the largest of their degrees in it (exact degree elevation), the union of
//! their knot vectors is taken (every knot with its largest multiplicity), optionally
//! halved `refine` times, and each face is brought onto it by exact knot insertion
//! ([`Face::elevated_in`], [`Face::refined_in`]). The faces then share their edge control
//! points (to rounding of the input's edge mismatch, at most `10⁻⁹ diam`).
//!
//! **Coons patch.** On the control net `H_ijk = (w c, w)` (homogeneous), with the
//! Greville abscissae `α_i, β_j, γ_k` as blending parameters, the Boolean sum
//! `P = P₁ ⊕ P₂ ⊕ P₃ = P₁ + P₂ + P₃ - P₁P₂ - P₁P₃ - P₂P₃ + P₁P₂P₃` with
//! `P₁H_ijk = (1 - α_i) H_0jk + α_i H_(n-1)jk` (and likewise in `η`, `ζ`) fills the
//! interior from the boundary net. `P` reproduces every net that is affine in one of
//! the blending parameters, so the control net of a trilinear map (its control points
//! are the map at the Greville points) is reproduced exactly.

use crate::boundary::volume::{CubeSide, VolumeBoundary};
use crate::error::{Error, Result};
use crate::spline::face::Face;
use crate::spline::knots::KnotVector;
use crate::spline::volume::Volume;

/// The faces on common knot vectors `knots` (in `ξ`, `η`, `ζ`).
#[derive(Debug, Clone)]
pub(crate) struct CommonFaces {
    /// The volume's knot vectors.
    pub knots: [KnotVector; 3],
    /// The faces on them, in the order of [`CubeSide::ALL`].
    pub faces: [Face; 6],
}

/// Bring the faces of `b` to common knot vectors per direction, each element halved
/// `refine` times and then the knots `extra[d]` inserted in direction `d` (local
/// defect correction; each strictly inside a span of the vector it is inserted into)
/// (module doc).
pub(crate) fn common_faces(b: &VolumeBoundary, refine: usize, extra: &[Vec<f64>; 3]) -> Result<CommonFaces> {
    let mut faces = b.faces.clone();
    let mut knots = Vec::with_capacity(3);
    for d in 0..3 {
        let users: Vec<(usize, usize)> = CubeSide::ALL
            .iter()
            .enumerate()
            .filter_map(|(k, s)| s.params().iter().position(|&p| p == d).map(|q| (k, q)))
            .collect();
        let p = users.iter().map(|&(k, q)| faces[k].degrees()[q]).max().unwrap_or(1);
        for &(k, q) in &users {
            while faces[k].degrees()[q] < p {
                faces[k] = faces[k].elevated_in(q)?;
            }
        }
        let mut kv = faces[users[0].0].knots[users[0].1].clone();
        for &(k, q) in &users[1..] {
            kv = kv.union(&faces[k].knots[q])?;
        }
        for _ in 0..refine {
            kv = kv.halved();
        }
        // a knot already there (a later halving's midpoint) is not inserted twice
        let new: Vec<f64> = extra[d].iter().copied().filter(|u| !kv.knots().contains(u)).collect();
        if !new.is_empty() {
            kv = kv.with_inserted(&new);
        }
        for &(k, q) in &users {
            if faces[k].knots[q] != kv {
                faces[k] = faces[k].refined_in(q, &kv)?;
            }
        }
        knots.push(kv);
    }
    let knots: [KnotVector; 3] = knots.try_into().map_err(|_| Error::Invalid("three knot vectors".into()))?;
    Ok(CommonFaces { knots, faces })
}

impl CommonFaces {
    /// Basis functions per direction.
    pub fn shape(&self) -> [usize; 3] {
        self.knots.each_ref().map(KnotVector::num_basis)
    }

    /// Whether any face is rational.
    pub fn rational(&self) -> bool {
        self.faces.iter().any(|f| f.weights.is_some())
    }

    /// The homogeneous boundary net `(w c, w)` on the volume's control net (interior
    /// points zero), every boundary point from the face(s) it lies on; the weights of the
    /// faces meeting at an edge must agree (to `10⁻¹²` relative).
    pub(crate) fn boundary_net(&self) -> Result<Vec<[f64; 4]>> {
        let shape = self.shape();
        let n: usize = shape.iter().product();
        let mut h = vec![[0.0; 4]; n];
        let mut from: Vec<Option<CubeSide>> = vec![None; n];
        for side in CubeSide::ALL {
            let (d, v) = side.fixed();
            let f = &self.faces[side as usize];
            let [ps, pt] = side.params();
            let ns = f.shape()[0];
            for jt in 0..shape[pt] {
                for is in 0..shape[ps] {
                    let mut ijk = [0; 3];
                    ijk[d] = if v == 0.0 { 0 } else { shape[d] - 1 };
                    ijk[ps] = is;
                    ijk[pt] = jt;
                    let lin = (ijk[2] * shape[1] + ijk[1]) * shape[0] + ijk[0];
                    let q = jt * ns + is;
                    let w = f.weight(q);
                    if let Some(other) = from[lin] {
                        if (h[lin][3] - w).abs() > 1e-12 * w {
                            return Err(Error::VolumeBoundary {
                                face: format!("{}/{}", other.name(), side.name()),
                                edge: String::new(),
                                reason: format!(
                                    "the faces' weights differ along their common edge at control point {ijk:?} ({} and {w}): \
                                     give both faces the same weights there",
                                    h[lin][3]
                                ),
                            });
                        }
                        continue;
                    }
                    let c = f.control_points[q];
                    h[lin] = [w * c[0], w * c[1], w * c[2], w];
                    from[lin] = Some(side);
                }
            }
        }
        Ok(h)
    }

    /// The trivariate Coons patch of the faces (module doc).
    #[cfg(test)]
    pub fn coons(&self) -> Result<Volume> {
        let h = self.boundary_net()?;
        let h = coons_fill(&self.knots, h);
        Ok(volume_of(self.knots.clone(), &h, self.rational()))
    }
}

/// The volume of the homogeneous net `h` on `knots`.
pub(crate) fn volume_of(knots: [KnotVector; 3], h: &[[f64; 4]], rational: bool) -> Volume {
    let control_points = h.iter().map(|p| [p[0] / p[3], p[1] / p[3], p[2] / p[3]]).collect();
    let weights = rational.then(|| h.iter().map(|p| p[3]).collect());
    Volume { knots, control_points, weights }
}

/// Fill the interior of the net `h` (of the tensor basis `knots`, boundary given) by
/// the discrete Coons patch of its boundary (module doc); works on any number of
/// components per point.
pub(crate) fn coons_fill<const C: usize>(knots: &[KnotVector; 3], mut h: Vec<[f64; C]>) -> Vec<[f64; C]> {
    let shape = knots.each_ref().map(KnotVector::num_basis);
    let g: [Vec<f64>; 3] = std::array::from_fn(|d| {
        let gr = knots[d].greville();
        let (a, b) = knots[d].domain();
        gr.iter().map(|x| (x - a) / (b - a)).collect()
    });
    let idx = |i: usize, j: usize, k: usize| (k * shape[1] + j) * shape[0] + i;
    let last = shape.map(|n| n - 1);
    for k in 1..last[2] {
        for j in 1..last[1] {
            for i in 1..last[0] {
                let (a, b, c) = (g[0][i], g[1][j], g[2][k]);
                let wa = [1.0 - a, a];
                let wb = [1.0 - b, b];
                let wc = [1.0 - c, c];
                let ia = [0, last[0]];
                let jb = [0, last[1]];
                let kc = [0, last[2]];
                let mut out = [0.0; C];
                let mut add = |s: f64, p: &[f64; C]| {
                    for z in 0..C {
                        out[z] += s * p[z];
                    }
                };
                for e in 0..2 {
                    add(wa[e], &h[idx(ia[e], j, k)]);
                    add(wb[e], &h[idx(i, jb[e], k)]);
                    add(wc[e], &h[idx(i, j, kc[e])]);
                    for f in 0..2 {
                        add(-wa[e] * wb[f], &h[idx(ia[e], jb[f], k)]);
                        add(-wa[e] * wc[f], &h[idx(ia[e], j, kc[f])]);
                        add(-wb[e] * wc[f], &h[idx(i, jb[e], kc[f])]);
                        for q in 0..2 {
                            add(wa[e] * wb[f] * wc[q], &h[idx(ia[e], jb[f], kc[q])]);
                        }
                    }
                }
                h[idx(i, j, k)] = out;
            }
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::volume::tests::trilinear_faces;

    fn trilinear(u: [f64; 3]) -> [f64; 3] {
        let [a, b, c] = u;
        [1.0 + 2.0 * a + 0.3 * a * b, b + 0.2 * a * b * c - 0.1 * c, 0.5 * c + 0.4 * a * c + 0.1 * b]
    }

    /// A trilinear volume is reproduced exactly from its bilinear faces, on the faces'
    /// bases (linear) and on elevated, refined and mixed ones.
    #[test]
    fn a_trilinear_volume_is_reproduced_exactly() {
        let mut faces = trilinear_faces(trilinear);
        // the top face elevated to degree 3 in s and refined in t: the common basis is
        // cubic in xi and refined in eta for every face
        faces[5] = faces[5].elevated_in(0).unwrap().elevated_in(0).unwrap();
        let fine = faces[5].knots[1].with_inserted(&[0.25, 0.6]);
        faces[5] = faces[5].refined_in(1, &fine).unwrap();
        let b = VolumeBoundary { name: "t".into(), faces };
        b.validate().unwrap();
        for refine in [0, 2] {
            let c = common_faces(&b, refine, &Default::default()).unwrap();
            assert_eq!(c.knots[0].degree(), 3);
            let v = c.coons().unwrap();
            for &u in &[[0.1, 0.2, 0.3], [0.5, 0.5, 0.5], [0.9, 0.33, 0.71], [0.0, 1.0, 0.4]] {
                let (x, y) = (v.eval(u), trilinear(u));
                for z in 0..3 {
                    assert!((x[z] - y[z]).abs() < 1e-13, "{u:?} {x:?} {y:?}");
                }
            }
        }
    }
}
