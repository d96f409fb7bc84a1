//! The boundary of a hexahedral volume: six faces, the images of the six sides of the
//! parameter cube (`formats-extensions.md`, "Volume boundary"). The face of the side `u_d = v`
//! (`d` the fixed direction, `v ∈ {0, 1}`) has as its parameters `(s, t)` the two other
//! cube parameters in their order, so `west(s, t) = x(0, s, t)`,
//! `south(s, t) = x(s, 0, t)`, `bottom(s, t) = x(s, t, 0)`.
//!
//! [`VolumeBoundary::validate`] checks what a volume needs of its faces: no degenerate
//! point on a face (`|f_s × f_t| > 10⁻⁹ diam²` on a sample grid), the twelve edges shared
//! by two faces equal as curves in the same direction (to `10⁻⁹ diam` at sample points),
//! and a right-handed parametrisation, i.e. a positive enclosed volume
//! `V = (1/3) Σ_faces σ ∫∫ f · (f_s × f_t) ds dt` (divergence theorem, `σ = ±1` the
//! orientation of the face's `(s, t)` relative to the outward normal of its cube side).

use crate::error::{Error, Result};
use crate::spline::face::Face;
use crate::spline::quadrature::GaussLegendre;
use crate::spline::volume::{triple, Point3};

/// A side of the parameter cube `[0, 1]³`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CubeSide {
    /// `ξ = 0`.
    West,
    /// `ξ = 1`.
    East,
    /// `η = 0`.
    South,
    /// `η = 1`.
    North,
    /// `ζ = 0`.
    Bottom,
    /// `ζ = 1`.
    Top,
}

impl CubeSide {
    /// The six sides in the order of [`VolumeBoundary::faces`].
    pub const ALL: [CubeSide; 6] =
        [CubeSide::West, CubeSide::East, CubeSide::South, CubeSide::North, CubeSide::Bottom, CubeSide::Top];

    /// The name used in documents.
    pub fn name(self) -> &'static str {
        ["west", "east", "south", "north", "bottom", "top"][self as usize]
    }

    /// The fixed direction `d` and its value `v`.
    pub fn fixed(self) -> (usize, f64) {
        let k = self as usize;
        (k / 2, (k % 2) as f64)
    }

    /// The side `u_d = v`.
    pub fn of(d: usize, v: usize) -> CubeSide {
        CubeSide::ALL[2 * d + v]
    }

    /// The cube directions of the face's `(s, t)`.
    pub fn params(self) -> [usize; 2] {
        match self.fixed().0 {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        }
    }

    /// `+1` when `f_s × f_t` of the identity cube points out of this side, else `-1`.
    pub(crate) fn outward_sign(self) -> f64 {
        let (d, v) = self.fixed();
        let positive_at_one = d != 1;
        if (v == 1.0) == positive_at_one {
            1.0
        } else {
            -1.0
        }
    }
}

/// Six faces of a hexahedral volume, knot domains `[0, 1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeBoundary {
    /// Name of the geometry.
    pub name: String,
    /// Faces in the order of [`CubeSide::ALL`] (west, east, south, north, bottom, top).
    pub faces: [Face; 6],
}

/// An edge of the cube: varying direction `a`, the other two directions fixed.
#[derive(Debug, Clone, Copy)]
struct CubeEdge {
    along: usize,
    fixed: [(usize, usize); 2],
}

impl CubeEdge {
    fn all() -> Vec<CubeEdge> {
        let mut out = Vec::with_capacity(12);
        for a in 0..3 {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let (b, c) = (b.min(c), b.max(c));
            for vb in 0..2 {
                for vc in 0..2 {
                    out.push(CubeEdge { along: a, fixed: [(b, vb), (c, vc)] });
                }
            }
        }
        out
    }

    fn name(&self) -> String {
        let n = ["xi", "eta", "zeta"];
        let [(b, vb), (c, vc)] = self.fixed;
        format!("{} = {vb}, {} = {vc} ({} from 0 to 1)", n[b], n[c], n[self.along])
    }

    /// The faces meeting at this edge and the point of each at parameter `τ` along it.
    fn on_face(&self, side: CubeSide, tau: f64) -> (f64, f64) {
        let mut u = [0.0; 3];
        u[self.along] = tau;
        for (d, v) in self.fixed {
            u[d] = v as f64;
        }
        let [ps, pt] = side.params();
        (u[ps], u[pt])
    }
}

fn dist(a: Point3, b: Point3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn cross(a: Point3, b: Point3) -> Point3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn face_error(face: &str, edge: &str, reason: String) -> Error {
    Error::VolumeBoundary { face: face.to_string(), edge: edge.to_string(), reason }
}

/// Sample parameters along an edge or a face direction.
const SAMPLES: usize = 33;

impl VolumeBoundary {
    /// The face of `side`.
    pub fn face(&self, side: CubeSide) -> &Face {
        &self.faces[side as usize]
    }

    /// The faces translated by minus the centre of their control points' bounding box.
    pub fn centred(&self) -> VolumeBoundary {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in self.faces.iter().flat_map(|f| &f.control_points) {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        let m: Point3 = std::array::from_fn(|c| 0.5 * (lo[c] + hi[c]));
        let faces = self.faces.clone().map(|f| Face {
            control_points: f.control_points.iter().map(|p| std::array::from_fn(|c| p[c] - m[c])).collect(),
            ..f
        });
        VolumeBoundary { name: self.name.clone(), faces }
    }

    /// The diagonal of the bounding box of every face's control points.
    pub fn diameter(&self) -> f64 {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in self.faces.iter().flat_map(|f| &f.control_points) {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        dist(lo, hi)
    }

    /// The volume enclosed by the faces, `(1/3) Σ σ ∫∫ f · (f_s × f_t)` (module doc):
    /// exact for polynomial faces (Gauss rule of `3 max(p, q)` points per element and
    /// direction), accurate to quadrature for rational ones.
    pub(crate) fn enclosed_volume(&self) -> f64 {
        let mut total = 0.0;
        for side in CubeSide::ALL {
            let f = self.face(side);
            let n = 3 * f.degrees().into_iter().max().unwrap_or(1) + 2;
            let g = GaussLegendre::new(n);
            let mut s_face = 0.0;
            for (_, a0, b0) in f.knots[0].elements() {
                for (_, a1, b1) in f.knots[1].elements() {
                    for (s, ws) in g.on(a0, b0) {
                        for (t, wt) in g.on(a1, b1) {
                            let (x, fs, ft) = f.derivs(s, t);
                            s_face += ws * wt * triple(x, fs, ft);
                        }
                    }
                }
            }
            total += side.outward_sign() * s_face;
        }
        total / 3.0
    }

    /// Check the faces (module doc); errors are [`Error::VolumeBoundary`] naming the face
    /// and, for mismatched edges, the edge.
    pub fn validate(&self) -> Result<()> {
        let diam = self.diameter();
        if diam.is_nan() || diam <= 0.0 {
            return Err(face_error("all", "", format!("the faces span no space (diameter {diam:e})")));
        }
        let tol = 1e-9 * diam;
        // evaluated relative to the centre of the bounding box: far from the origin,
        // absolute rounding would exceed the tolerance
        let centred = self.centred();
        for side in CubeSide::ALL {
            let f = centred.face(side);
            for i in 0..SAMPLES {
                for j in 0..SAMPLES {
                    let (s, t) = (i as f64 / (SAMPLES - 1) as f64, j as f64 / (SAMPLES - 1) as f64);
                    let (x, fs, ft) = f.derivs(s, t);
                    let n = cross(fs, ft);
                    let area = dist(n, [0.0; 3]);
                    if area.is_nan() || area <= 1e-9 * diam * diam {
                        return Err(face_error(
                            side.name(),
                            "",
                            format!(
                                "degenerate at (s, t) = ({s}, {t}), point ({:.6}, {:.6}, {:.6}): |f_s × f_t| = {area:.3e}",
                                x[0], x[1], x[2]
                            ),
                        ));
                    }
                }
            }
        }
        for edge in CubeEdge::all() {
            let [(b, vb), (c, vc)] = edge.fixed;
            let (fa, fb) = (CubeSide::of(b, vb), CubeSide::of(c, vc));
            let curve = |side: CubeSide, tau: f64| {
                let (s, t) = edge.on_face(side, tau);
                centred.face(side).eval(s, t)
            };
            let taus = (0..SAMPLES).map(|i| i as f64 / (SAMPLES - 1) as f64);
            let (gap, at) = taus
                .clone()
                .map(|tau| (dist(curve(fa, tau), curve(fb, tau)), tau))
                .fold((0.0, 0.0), |m, g| if g.0 > m.0 || g.0.is_nan() { g } else { m });
            if gap.is_nan() || gap > tol {
                let reversed = taus.map(|tau| dist(curve(fa, tau), curve(fb, 1.0 - tau))).fold(0.0, f64::max);
                let p = curve(fa, at);
                let reason = if reversed <= tol {
                    format!("the {} and {} faces run against each other along it", fa.name(), fb.name())
                } else {
                    format!(
                        "the {} and {} faces are {gap:.3e} apart at ({:.6}, {:.6}, {:.6}) (tolerance {tol:.3e})",
                        fa.name(),
                        fb.name(),
                        p[0],
                        p[1],
                        p[2]
                    )
                };
                return Err(face_error(&format!("{}/{}", fa.name(), fb.name()), &edge.name(), reason));
            }
        }
        let v = centred.enclosed_volume();
        if v.is_nan() || v <= 1e-9 * diam.powi(3) {
            return Err(face_error(
                "all",
                "",
                format!(
                    "the faces enclose the volume {v:.6e}: the parametrisation is {} (it must be right-handed: \
                     exchange west and east and reverse s of south, north, bottom and top to mirror it)",
                    if v < 0.0 { "left-handed" } else { "flat" }
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    /// The faces of the map `x(u)` given as a closure, each interpolated by bilinear
    /// faces through the cube's corners images (exact for trilinear maps).
    pub(crate) fn trilinear_faces(corner: impl Fn([f64; 3]) -> Point3) -> [Face; 6] {
        CubeSide::ALL.map(|side| {
            let (d, v) = side.fixed();
            let [ps, pt] = side.params();
            let cps = (0..4)
                .map(|q| {
                    let mut u = [0.0; 3];
                    u[d] = v;
                    u[ps] = (q % 2) as f64;
                    u[pt] = (q / 2) as f64;
                    corner(u)
                })
                .collect();
            Face::new([KnotVector::open_uniform(1, 1), KnotVector::open_uniform(1, 1)], cps, None).unwrap()
        })
    }

    fn cube() -> VolumeBoundary {
        VolumeBoundary { name: "cube".into(), faces: trilinear_faces(|u| [2.0 * u[0], u[1] + 0.1 * u[0], 3.0 * u[2]]) }
    }

    #[test]
    fn the_unit_cube_is_valid_and_its_volume_is_exact() {
        let b = cube();
        b.validate().unwrap();
        assert!((b.enclosed_volume() - 6.0).abs() < 1e-12, "{}", b.enclosed_volume());
    }

    #[test]
    fn bad_boundaries_name_face_and_edge() {
        // a moved corner of the top face: the top's edges no longer match
        let mut b = cube();
        b.faces[5].control_points[3][2] += 0.01;
        let e = b.validate().unwrap_err();
        assert!(
            matches!(&e, Error::VolumeBoundary { face, edge, .. } if face.contains("top") && !edge.is_empty()),
            "{e}"
        );
        // a reversed south face (s runs against xi): its edges with bottom and top run
        // against them
        let mut b = cube();
        let f = &mut b.faces[2];
        f.control_points = vec![f.control_points[1], f.control_points[0], f.control_points[3], f.control_points[2]];
        let e = b.validate().unwrap_err();
        assert!(e.to_string().contains("run against"), "{e}");
        // a mirrored cube: left-handed
        let b = VolumeBoundary { name: "m".into(), faces: trilinear_faces(|u| [-u[0], u[1], u[2]]) };
        let e = b.validate().unwrap_err();
        assert!(
            matches!(&e, Error::VolumeBoundary { face, .. } if face == "all") && e.to_string().contains("left-handed"),
            "{e}"
        );
        // a collapsed face: the bottom face's edge eta = 0 collapsed to a point
        let b = VolumeBoundary { name: "wedge".into(), faces: trilinear_faces(|u| [u[0] * u[1], u[1], u[2]]) };
        let e = b.validate().unwrap_err();
        assert!(matches!(&e, Error::VolumeBoundary { reason, .. } if reason.contains("degenerate")), "{e}");
    }
}
