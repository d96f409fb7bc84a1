//! Six faces in any order and orientation put together as the boundary of a hexahedron
//! ([`assemble`]): which face is which side of the parameter cube, and how each face's
//! `(s, t)` must be turned to be that side's parameters (`boundary::volume`).
//!
//! The faces meet at their corners (control points at the corners of clamped knot
//! vectors): these must coincide in eight vertices, each the corner of three faces, to
//! `10⁻⁹` of the diameter; a face's four sides are then edges between two vertices, and
//! each of the twelve edges must be a side of exactly two faces, so that every face is
//! adjacent to four others and shares no edge with the sixth, its opposite. A map `φ`
//! from the cube's vertices `(a, b, c) ∈ {0, 1}³` onto the eight vertices that sends
//! every side of the cube onto a face is a candidate; there are 48 (the symmetries of the
//! cube), half of them right-handed (a positive enclosed volume: the sign of a candidate
//! is that of the first times the determinant of the cube symmetry between them,
//! `sign(π) (-1)^{flips}`). Of the right-handed ones the one that moves and turns the
//! fewest faces is taken, so that faces given in the order and orientation of
//! `formats-extensions.md` stay exactly as they are. Each face is turned by one of the
//! eight symmetries of the square ([`SquareSymmetry`]); the result is validated
//! ([`VolumeBoundary::validate`]: shared edges as curves, no degenerate point, positive
//! volume). Every failure is an [`Error::VolumeBoundary`] naming the face (by the name
//! the caller gave it) and the edge or corner.

use std::collections::HashMap;

use crate::boundary::volume::{CubeSide, VolumeBoundary};
use crate::error::{Error, Result};
use crate::spline::face::Face;
use crate::spline::volume::Point3;

/// One of the eight symmetries of the unit square, as the map of the turned face's
/// parameters onto the given face's: `g(s, t) = f(σ(s, t))` with `(a, b) = (t, s)` when
/// `swap`, else `(s, t)`, and `σ = (a or 1 - a, b or 1 - b)` by `flip`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SquareSymmetry {
    /// Exchange `s` and `t`.
    pub swap: bool,
    /// Reverse the first / second parameter of `f` (after the exchange).
    pub flip: [bool; 2],
}

impl SquareSymmetry {
    /// The identity.
    pub(crate) const IDENTITY: SquareSymmetry = SquareSymmetry { swap: false, flip: [false, false] };

    /// All eight, the identity first.
    pub fn all() -> impl Iterator<Item = SquareSymmetry> {
        (0..8).map(|k| SquareSymmetry { swap: k & 4 != 0, flip: [k & 1 != 0, k & 2 != 0] })
    }

    /// `σ` on a corner `(s, t) ∈ {0, 1}²` numbered `s + 2 t`.
    fn corner(self, c: usize) -> usize {
        let (s, t) = (c & 1, c >> 1);
        let (a, b) = if self.swap { (t, s) } else { (s, t) };
        (a ^ usize::from(self.flip[0])) + 2 * (b ^ usize::from(self.flip[1]))
    }

    /// The turned face `g = f ∘ σ`: reversed by `flip`, then transposed by `swap`.
    pub fn apply(self, f: &Face) -> Result<Face> {
        let mut g = f.clone();
        for d in 0..2 {
            if self.flip[d] {
                g = g.reversed_in(d)?;
            }
        }
        Ok(if self.swap { g.transposed() } else { g })
    }
}

/// Where an input face went: the cube side it is, and how it was turned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Placement {
    /// Index of the face in the input.
    pub input: usize,
    /// The side of the cube it is the image of.
    pub side: CubeSide,
    /// The face as that side is `input ∘ symmetry`.
    pub symmetry: SquareSymmetry,
}

/// The sides of a face's own parameter square, G+Smo's numbering minus one: `s = 0`,
/// `s = 1`, `t = 0`, `t = 1`, as pairs of corners `s + 2 t`.
pub(crate) const FACE_SIDES: [(&str, [usize; 2]); 4] =
    [("s = 0", [0, 2]), ("s = 1", [1, 3]), ("t = 0", [0, 1]), ("t = 1", [2, 3])];

fn err(face: impl Into<String>, edge: impl Into<String>, reason: String) -> Error {
    Error::VolumeBoundary { face: face.into(), edge: edge.into(), reason }
}

fn corner_point(f: &Face, c: usize) -> Point3 {
    let [ns, nt] = f.shape();
    let (i, j) = ((c & 1) * (ns - 1), (c >> 1) * (nt - 1));
    f.control_points[j * ns + i]
}

fn dist(a: Point3, b: Point3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The combinatorics of six faces: their corners as vertex ids, and the faces' sides
/// on each edge.
#[derive(Debug, Clone)]
pub(crate) struct FaceSet {
    /// Vertex id of corner `s + 2 t` of each face.
    pub corners: Vec<[usize; 4]>,
    /// For each edge (sorted pair of vertex ids) the faces' sides on it: `(face, side)`
    /// with `side` an index into [`FACE_SIDES`].
    pub edges: HashMap<(usize, usize), Vec<(usize, usize)>>,
}

impl FaceSet {
    /// The edge of side `side` of face `f`.
    pub(crate) fn edge_of(&self, f: usize, side: usize) -> (usize, usize) {
        let [a, b] = FACE_SIDES[side].1.map(|c| self.corners[f][c]);
        (a.min(b), a.max(b))
    }

    /// Find the vertices and edges of `faces` (module doc); errors name the face (by
    /// `names`) and its corner or side.
    pub fn new(faces: &[Face], names: &[String]) -> Result<FaceSet> {
        if faces.len() != 6 {
            return Err(err("all", "", format!("{} faces: the boundary of a hexahedral volume has six", faces.len())));
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in faces.iter().flat_map(|f| &f.control_points) {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        let tol = 1e-9 * dist(lo, hi);
        let mut vertices: Vec<(Point3, usize)> = Vec::new();
        let mut corners = Vec::with_capacity(6);
        for f in faces {
            let mut ids = [0; 4];
            for (c, id) in ids.iter_mut().enumerate() {
                let p = corner_point(f, c);
                *id = match vertices.iter().position(|(v, _)| dist(*v, p) <= tol) {
                    Some(k) => k,
                    None => {
                        vertices.push((p, 0));
                        vertices.len() - 1
                    }
                };
                vertices[*id].1 += 1;
            }
            corners.push(ids);
        }
        let corner_name = |c: usize| format!("corner (s, t) = ({}, {})", c & 1, c >> 1);
        for (f, ids) in corners.iter().enumerate() {
            for a in 0..4 {
                if let Some(b) = (a + 1..4).find(|&b| ids[b] == ids[a]) {
                    return Err(err(
                        &names[f],
                        corner_name(a),
                        format!("it coincides with {}: the face is degenerate", corner_name(b)),
                    ));
                }
            }
        }
        // the corner of the vertex shared by the fewest faces, if not three
        let odd = corners
            .iter()
            .enumerate()
            .flat_map(|(f, ids)| (0..4).map(move |c| (f, c, ids[c])))
            .filter(|&(_, _, v)| vertices[v].1 != 3)
            .min_by_key(|&(_, _, v)| vertices[v].1);
        if let Some((f, c, v)) = odd {
            let p = vertices[v].0;
            return Err(err(
                &names[f],
                corner_name(c),
                format!(
                    "the corner ({:.6}, {:.6}, {:.6}) is a corner of {} face(s); each corner of a hexahedron is one of \
                     three (tolerance {tol:.3e})",
                    p[0], p[1], p[2], vertices[v].1
                ),
            ));
        }
        let mut set = FaceSet { corners, edges: HashMap::new() };
        for f in 0..6 {
            for side in 0..4 {
                let e = set.edge_of(f, side);
                set.edges.entry(e).or_default().push((f, side));
            }
        }
        for f in 0..6 {
            for side in 0..4 {
                let on = &set.edges[&set.edge_of(f, side)];
                if on.len() != 2 {
                    return Err(err(
                        &names[f],
                        FACE_SIDES[side].0,
                        format!("the side is an edge of {} face(s); each edge of a hexahedron is one of two", on.len()),
                    ));
                }
            }
            let mut neighbours: Vec<usize> = (0..4)
                .map(|side| set.edges[&set.edge_of(f, side)].iter().find(|&&(g, _)| g != f).map_or(f, |&(g, _)| g))
                .collect();
            neighbours.sort_unstable();
            if let Some(w) = neighbours.windows(2).find(|w| w[0] == w[1]) {
                return Err(err(
                    format!("{}/{}", names[f], names[w[0]]),
                    "",
                    "the two faces share more than one edge: each face of a hexahedron meets four others along one \
                     edge each, and its opposite face not at all"
                        .into(),
                ));
            }
        }
        Ok(set)
    }

    /// The face with corners `a, b, c` (vertex ids) among its four, and its fourth.
    fn fourth(&self, a: usize, b: usize, c: usize) -> Option<usize> {
        self.corners.iter().find_map(|ids| {
            (ids.contains(&a) && ids.contains(&b) && ids.contains(&c))
                .then(|| ids.iter().copied().find(|v| ![a, b, c].contains(v)))
                .flatten()
        })
    }

    fn neighbours(&self, v: usize) -> Vec<usize> {
        let mut n: Vec<usize> =
            self.edges.keys().filter_map(|&(a, b)| if a == v { Some(b) } else { (b == v).then_some(a) }).collect();
        n.sort_unstable();
        n
    }

    /// The placement of every face for the cube-vertex map `phi`, if `phi` sends every
    /// side of the cube onto a face.
    fn placements(&self, phi: &[usize; 8]) -> Option<[Placement; 6]> {
        let mut out = Vec::with_capacity(6);
        for side in CubeSide::ALL {
            let (d, v) = side.fixed();
            let [ps, pt] = side.params();
            let target: [usize; 4] = std::array::from_fn(|c| {
                let mut u = [0usize; 3];
                u[d] = v as usize;
                u[ps] = c & 1;
                u[pt] = c >> 1;
                phi[u[0] + 2 * u[1] + 4 * u[2]]
            });
            let input = self.corners.iter().position(|ids| target.iter().all(|t| ids.contains(t)))?;
            let symmetry =
                SquareSymmetry::all().find(|g| (0..4).all(|c| self.corners[input][g.corner(c)] == target[c]))?;
            out.push(Placement { input, side, symmetry });
        }
        out.try_into().ok()
    }

    /// The cube-vertex map with `φ(0, 0, 0) = v0`, `φ(1, 0, 0) = a`, `φ(0, 1, 0) = b`,
    /// `φ(0, 0, 1) = c`, the other four the faces' fourth corners.
    fn completed(&self, v0: usize, a: usize, b: usize, c: usize) -> Option<[usize; 8]> {
        let ab = self.fourth(v0, a, b)?;
        let ac = self.fourth(v0, a, c)?;
        let bc = self.fourth(v0, b, c)?;
        let abc = self.fourth(a, ab, ac)?;
        Some([v0, a, b, ab, c, ac, bc, abc])
    }

    /// Every cube-vertex map `φ` that sends the cube's sides onto the faces (module doc).
    fn candidates(&self) -> Vec<[usize; 8]> {
        let mut out = Vec::new();
        let perms = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
        for v0 in 0..8 {
            let n = self.neighbours(v0);
            if n.len() != 3 {
                continue;
            }
            for p in perms {
                let (a, b, c) = (n[p[0]], n[p[1]], n[p[2]]);
                if let Some(phi) = self.completed(v0, a, b, c) {
                    out.push(phi);
                }
            }
        }
        out
    }
}

/// `det` of the cube symmetry `ψ` (on vertices `a + 2b + 4c`): `sign(π) (-1)^{flips}`,
/// `None` when `ψ` is not one.
fn symmetry_sign(psi: &[usize; 8]) -> Option<f64> {
    let f = psi[0];
    let axes: Vec<usize> = (0..3).map(|e| psi[1 << e] ^ f).collect();
    let pi: Vec<usize> = axes.iter().map(|&a| [1, 2, 4].iter().position(|&b| b == a)).collect::<Option<_>>()?;
    let inversions = (0..3).flat_map(|i| (i + 1..3).map(move |j| (i, j))).filter(|&(i, j)| pi[i] > pi[j]).count();
    let flips = f.count_ones() as usize;
    Some(if (inversions + flips).is_multiple_of(2) { 1.0 } else { -1.0 })
}

/// Six faces in any order and orientation as a validated [`VolumeBoundary`] named
/// `name` (module doc), and where each face went. `names` name the faces in errors.
pub(crate) fn assemble(name: &str, faces: &[Face], names: &[String]) -> Result<(VolumeBoundary, [Placement; 6])> {
    let set = FaceSet::new(faces, names)?;
    let candidates: Vec<([usize; 8], [Placement; 6])> =
        set.candidates().into_iter().filter_map(|phi| set.placements(&phi).map(|p| (phi, p))).collect();
    let Some((phi0, first)) = candidates.first() else {
        return Err(err(
            "all",
            "",
            "the faces meet in eight corners and twelve edges but not as the sides of a cube".into(),
        ));
    };
    let build = |placements: &[Placement; 6]| -> Result<VolumeBoundary> {
        let mut turned = Vec::with_capacity(6);
        for p in placements {
            turned.push(p.symmetry.apply(&faces[p.input]).map_err(|e| e.within(&names[p.input]))?);
        }
        let faces: [Face; 6] = turned.try_into().map_err(|_| Error::Invalid("six faces expected".into()))?;
        Ok(VolumeBoundary { name: name.to_string(), faces })
    };
    let v0 = build(first)?.centred().enclosed_volume();
    let inverse: HashMap<usize, usize> = phi0.iter().enumerate().map(|(k, &v)| (v, k)).collect();
    let cost = |p: &[Placement; 6]| {
        p.iter()
            .map(|q| 2 * usize::from(q.input != q.side as usize) + usize::from(q.symmetry != SquareSymmetry::IDENTITY))
            .sum::<usize>()
    };
    let chosen = candidates
        .iter()
        .filter(|(phi, _)| {
            let psi: [usize; 8] = std::array::from_fn(|k| inverse[&phi[k]]);
            symmetry_sign(&psi).is_some_and(|s| s * v0 > 0.0)
        })
        .min_by_key(|(_, p)| cost(p))
        .map_or(first, |(_, p)| p);
    let b = build(chosen)?;
    b.validate().map_err(|e| match e {
        Error::VolumeBoundary { face, edge, reason } => {
            let named = face
                .split('/')
                .map(|s| match chosen.iter().find(|p| p.side.name() == s) {
                    Some(p) => format!("{s} ({})", names[p.input]),
                    None => s.to_string(),
                })
                .collect::<Vec<_>>()
                .join("/");
            Error::VolumeBoundary { face: named, edge, reason }
        }
        e => e,
    })?;
    Ok((b, *chosen))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::volume::tests::trilinear_faces;
    use crate::spline::knots::KnotVector;

    /// A curved boundary: the faces of `x(u) = (u0 + 0.2 u1 u2, u1 + 0.1 sin-like bulge,
    /// u2)`, each face a biquadratic with an interior control point moved, so that every
    /// face is different from its turned versions.
    fn curved() -> VolumeBoundary {
        let mut faces = trilinear_faces(|u| [u[0] + 0.2 * u[1] * u[2], u[1] + 0.1 * u[0] * u[2], u[2] + 0.05 * u[0]]);
        for (k, f) in faces.iter_mut().enumerate() {
            let g = f.elevated_in(0).unwrap().elevated_in(1).unwrap();
            let fine = KnotVector::open_from_breaks(2, &[0.0, 0.5, 1.0], 1);
            let mut g = g.refined_in(0, &fine).unwrap();
            // the interior control point (1, 1) of the 4 x 3 net
            g.control_points[4 + 1][k % 3] += 0.03 * (k as f64 + 1.0);
            *f = g;
        }
        let b = VolumeBoundary { name: "curved".into(), faces };
        b.validate().unwrap();
        b
    }

    fn names(n: usize) -> Vec<String> {
        (0..n).map(|k| format!("patch {k}")).collect()
    }

    #[test]
    fn canonical_faces_stay_as_they_are() {
        let b = curved();
        let (back, placed) = assemble("curved", &b.faces, &names(6)).unwrap();
        assert_eq!(back, b);
        for (k, p) in placed.iter().enumerate() {
            assert_eq!((p.input, p.side as usize, p.symmetry), (k, k, SquareSymmetry::IDENTITY));
        }
    }

    /// Two faces exchanged and three turned, the others as given: found and turned
    /// back, bit for bit (knots `0, 0.5, 1` reflect exactly).
    #[test]
    fn permuted_and_flipped_faces_are_identified() {
        let b = curved();
        let order = [0, 1, 3, 2, 4, 5];
        let turn = [
            SquareSymmetry { swap: true, flip: [false, true] },
            SquareSymmetry::IDENTITY,
            SquareSymmetry { swap: false, flip: [true, false] },
            SquareSymmetry::IDENTITY,
            SquareSymmetry { swap: true, flip: [true, true] },
            SquareSymmetry::IDENTITY,
        ];
        let given: Vec<Face> = order.iter().zip(turn).map(|(&side, g)| g.apply(&b.faces[side]).unwrap()).collect();
        let (back, placed) = assemble("curved", &given, &names(6)).unwrap();
        assert_eq!(back, b);
        for (k, &side) in order.iter().enumerate() {
            let p = placed.iter().find(|p| p.input == k).unwrap();
            assert_eq!(p.side as usize, side);
        }
    }

    /// The point of the boundary `b` at the cube point `u` (on a side).
    fn on_boundary(b: &VolumeBoundary, u: [f64; 3]) -> Point3 {
        let side = CubeSide::ALL.into_iter().find(|s| u[s.fixed().0] == s.fixed().1).unwrap();
        let [ps, pt] = side.params();
        b.face(side).eval(u[ps], u[pt])
    }

    /// Every face shuffled and turned: the faces in the order given say nothing about
    /// which is west, so the result is the same boundary up to a rotation of the cube
    /// `ψ`: `back(u) = b(ψ(u))` on every side, `ψ` one of the 24 proper symmetries.
    #[test]
    fn shuffled_faces_give_the_boundary_up_to_a_rotation() {
        let b = curved();
        let order = [4, 0, 5, 2, 1, 3];
        let syms: Vec<SquareSymmetry> = SquareSymmetry::all().collect();
        let given: Vec<Face> =
            order.iter().enumerate().map(|(k, &side)| syms[(k + 3) % 8].apply(&b.faces[side]).unwrap()).collect();
        let (back, _) = assemble("curved", &given, &names(6)).unwrap();
        let perms = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
        let samples = [(0.2, 0.7), (0.5, 0.5), (0.9, 0.1), (0.0, 1.0)];
        let found = perms.iter().flat_map(|&p| (0..8).map(move |f| (p, f))).find(|&(p, f)| {
            let psi = |u: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|j| if f >> j & 1 == 1 { 1.0 - u[p[j]] } else { u[p[j]] })
            };
            CubeSide::ALL.into_iter().all(|side| {
                let (d, v) = side.fixed();
                let [ps, pt] = side.params();
                samples.iter().all(|&(s, t)| {
                    let mut u = [v; 3];
                    u[d] = v;
                    u[ps] = s;
                    u[pt] = t;
                    let (x, y) = (back.face(side).eval(s, t), on_boundary(&b, psi(u)));
                    (0..3).all(|c| (x[c] - y[c]).abs() < 1e-12)
                })
            })
        });
        let (p, f) = found.expect("the assembled boundary is the given one up to a symmetry of the cube");
        let mut psi = [0usize; 8];
        for (k, out) in psi.iter_mut().enumerate() {
            let bit = |j: usize| ((k >> p[j]) & 1) ^ ((f >> j) & 1);
            *out = bit(0) + 2 * bit(1) + 4 * bit(2);
        }
        assert_eq!(symmetry_sign(&psi), Some(1.0), "a rotation, not a mirror: {p:?} {f}");
    }

    #[test]
    fn bad_face_sets_name_the_face_and_edge() {
        let b = curved();
        let e = assemble("five", &b.faces[..5], &names(5)).unwrap_err();
        assert!(matches!(&e, Error::VolumeBoundary { reason, .. } if reason.contains("5 faces")), "{e}");
        // a moved corner of patch 5 (top): its corner is one face's only
        let mut faces = b.faces.to_vec();
        let last = faces[5].control_points.len() - 1;
        faces[5].control_points[last][2] += 0.01;
        let e = assemble("moved", &faces, &names(6)).unwrap_err();
        assert!(
            matches!(&e, Error::VolumeBoundary { face, edge, .. } if face == "patch 5" && edge == "corner (s, t) = (1, 1)"),
            "{e}"
        );
        // an edge's middle control point moved (corners kept): the edge xi = 0, eta = 0
        // of west (patch 0) and south (patch 2) no longer matches
        let mut faces = b.faces.to_vec();
        faces[0].control_points[4][0] += 0.01; // west's point (i, j) = (0, 1): on s = 0, eta = 0
        let e = assemble("edge", &faces, &names(6)).unwrap_err();
        assert!(
            matches!(&e, Error::VolumeBoundary { face, edge, .. }
                if face.contains("west (patch 0)") && edge.contains("xi = 0, eta = 0")),
            "{e}"
        );
        // a face twice: the set is not a hexahedron
        let mut faces = b.faces.to_vec();
        faces[1] = faces[0].clone();
        assert!(matches!(assemble("twice", &faces, &names(6)), Err(Error::VolumeBoundary { .. })));
    }

    /// The sign of a cube symmetry: the identity and a rotation are `+1`, a mirror `-1`.
    #[test]
    fn symmetry_signs() {
        let id: [usize; 8] = std::array::from_fn(|k| k);
        let mirror: [usize; 8] = std::array::from_fn(|k| k ^ 1);
        // a quarter turn about zeta: (a, b) -> (1 - b, a)
        let turn: [usize; 8] = std::array::from_fn(|k| {
            let (a, b, c) = (k & 1, (k >> 1) & 1, k >> 2);
            (1 - b) + 2 * a + 4 * c
        });
        assert_eq!(symmetry_sign(&id), Some(1.0));
        assert_eq!(symmetry_sign(&mirror), Some(-1.0));
        assert_eq!(symmetry_sign(&turn), Some(1.0));
    }
}
