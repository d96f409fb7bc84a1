//! Volumes from planar slices (paper §11.1, Fig. 23): maps `x_i(ξ, η)` of the plane
//! given at heights `z_0 < z_1 < ... < z_{m-1}` become one trivariate map
//! `X(ξ, η, ζ) = (x(ξ, η, ζ), z(ζ))` with `X(ξ, η, ζ_i) = (x_i(ξ, η), z_i)`.
//!
//! **One basis.** The slices are first brought to one tensor basis, exactly: every slice
//! is degree-elevated to the largest degree per direction (continuity kept), then
//! refined by knot insertion to the union of all knot vectors (every break with its
//! largest multiplicity), `common_basis`. Periodic directions (ring maps) stay periodic.
//!
//! **In `z`.** The parameter of slice `i` is `ζ_i = (z_i - z_0) / (z_{m-1} - z_0)`, so
//! that `z(ζ)` is affine and `det J = (z_{m-1} - z_0) det J_xy` where the slices share
//! their weights (always for B-spline slices), `det J_xy` being the Jacobian of the
//! interpolated planar map at that `ζ`. The homogeneous control points
//! `(w x, w y, w z_i, w)` of the slices are interpolated in `ζ`:
//!
//! - [`Interpolation::Linear`] (the paper's first-order interpolation): degree 1 with a
//!   knot at every `ζ_i`; the slices are the control layers; `C^0` across each slice.
//! - [`Interpolation::Cubic`] (smooth, listed by the paper as not yet implemented): the
//!   `C²` cubic spline interpolant with the not-a-knot end conditions (knots
//!   `ζ_2, ..., ζ_{m-3}`, so that the first two and the last two intervals are single
//!   cubics); it reproduces every family of slices that is cubic in `z` exactly. With
//!   three slices it is the quadratic interpolant, with two the linear one.
//!
//! Rational slices with different weights are interpolated homogeneously: the sections
//! between slices are then rational blends, not planar (`z` depends on `ξ, η` there).

use crate::error::{Error, Result};
use crate::linalg::linsolve::dense_solve;
use crate::spline::basis::BasisDerivs;
use crate::spline::knots::KnotVector;
use crate::spline::surface::Surface;
use crate::spline::volume::Volume;

/// How the slices are joined in `z`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Interpolation {
    /// Piecewise linear in `ζ` (the paper's first-order interpolation): the default,
    /// because every piece only mixes two neighbouring slices, so a slice inserted where
    /// the volume is not certified changes nothing outside its two intervals.
    #[default]
    Linear,
    /// The `C²` cubic spline through the slices (not-a-knot ends).
    Cubic,
}

impl Interpolation {
    /// Lower-case name (`linear`, `cubic`).
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Linear => "linear",
            Interpolation::Cubic => "cubic",
        }
    }
}

fn slices_err(slice: Option<usize>, reason: String) -> Error {
    Error::Slices { slice, reason }
}

/// Check the heights: one per slice, at least two, finite, strictly increasing with gaps
/// above `1e-9` of the total height.
pub(crate) fn check_heights(z: &[f64], slices: usize) -> Result<()> {
    if z.len() != slices {
        return Err(slices_err(None, format!("{} heights for {slices} slices (one z per slice)", z.len())));
    }
    if slices < 2 {
        return Err(slices_err(None, format!("a volume needs at least two slices, got {slices}")));
    }
    if let Some(i) = z.iter().position(|x| !x.is_finite()) {
        return Err(slices_err(Some(i), format!("its height z = {} is not finite", z[i])));
    }
    let total = z[slices - 1] - z[0];
    for i in 1..slices {
        if z[i] - z[i - 1] <= 1e-9 * total.abs() || total <= 0.0 {
            return Err(slices_err(
                Some(i),
                format!("the heights must increase strictly: z = {} follows z = {}", z[i], z[i - 1]),
            ));
        }
    }
    Ok(())
}

/// The slices on one tensor basis (see the module doc); the maps are unchanged (to
/// rounding). Errors name the first slice that does not fit slice 0: a different
/// periodicity (a ring and a four-sided map) or parameter domain.
pub(crate) fn common_basis(slices: &[Surface]) -> Result<Vec<Surface>> {
    let Some(first) = slices.first() else {
        return Err(slices_err(None, "no slices".into()));
    };
    for (i, s) in slices.iter().enumerate() {
        for d in 0..2 {
            let (a, b) = (&first.knots[d], &s.knots[d]);
            let dir = ["xi", "eta"][d];
            if a.is_periodic() != b.is_periodic() {
                return Err(slices_err(
                    Some(i),
                    format!(
                        "{dir} is {} here and {} in slice 0: a ring map (no corners) and a four-sided map (four corners) cannot share a basis",
                        if b.is_periodic() { "periodic" } else { "open" },
                        if a.is_periodic() { "periodic" } else { "open" }
                    ),
                ));
            }
            if a.domain() != b.domain() {
                return Err(slices_err(
                    Some(i),
                    format!("the {dir} domain is {:?} here and {:?} in slice 0", b.domain(), a.domain()),
                ));
            }
        }
    }
    let target = [0, 1].map(|d| slices.iter().map(|s| s.knots[d].degree()).max().unwrap_or(1));
    let mut elevated = Vec::with_capacity(slices.len());
    for (i, s) in slices.iter().enumerate() {
        let mut e = s.clone();
        for d in 0..2 {
            while e.knots[d].degree() < target[d] {
                e = e.elevated_in(d).map_err(|err| slices_err(Some(i), format!("degree elevation failed: {err}")))?;
            }
        }
        elevated.push(e);
    }
    let mut union = elevated[0].knots.clone();
    for (i, e) in elevated.iter().enumerate().skip(1) {
        for d in 0..2 {
            union[d] = union[d].union(&e.knots[d]).map_err(|err| slices_err(Some(i), format!("knot union: {err}")))?;
        }
    }
    elevated
        .iter()
        .enumerate()
        .map(|(i, e)| {
            if e.knots == union {
                Ok(e.clone())
            } else {
                e.refined(&union).map_err(|err| slices_err(Some(i), format!("knot insertion failed: {err}")))
            }
        })
        .collect()
}

/// `ζ_i = (z_i - z_0) / (z_{m-1} - z_0)`, exactly 0 and 1 at the ends.
pub(crate) fn zeta_of(z: &[f64]) -> Vec<f64> {
    let (a, b) = (z[0], z[z.len() - 1]);
    let mut t: Vec<f64> = z.iter().map(|&x| (x - a) / (b - a)).collect();
    t[0] = 0.0;
    *t.last_mut().expect("two or more") = 1.0;
    t
}

/// The knot vector in `ζ` of an interpolation through parameters `zeta`.
pub(crate) fn zeta_knots(zeta: &[f64], interpolation: Interpolation) -> KnotVector {
    let m = zeta.len();
    let (degree, inner) = match (interpolation, m) {
        (Interpolation::Linear, _) | (_, 2) => (1, &zeta[1..m - 1]),
        (Interpolation::Cubic, 3) => (2, &zeta[1..1]),
        (Interpolation::Cubic, _) => (3, &zeta[2..m - 2]),
    };
    let mut knots = vec![0.0; degree + 1];
    knots.extend_from_slice(inner);
    knots.extend(std::iter::repeat_n(1.0, degree + 1));
    KnotVector::new(degree, knots).expect("strictly increasing parameters give a valid knot vector")
}

/// Interpolate slices that share one basis ([`common_basis`]) at heights `z`.
pub(crate) fn interpolate(slices: &[Surface], z: &[f64], interpolation: Interpolation) -> Result<Volume> {
    check_heights(z, slices.len())?;
    if let Some(i) = slices.iter().position(|s| s.knots != slices[0].knots) {
        return Err(slices_err(
            Some(i),
            "its basis differs from slice 0's (bring them to one with common_basis)".into(),
        ));
    }
    let zeta = zeta_of(z);
    let kz = zeta_knots(&zeta, interpolation);
    let m = slices.len();
    let n2 = slices[0].control_points.len();
    let rational = slices.iter().any(|s| s.weights.is_some());
    // data[i][4 c + comp]: homogeneous coordinates of control point c of slice i
    let data: Vec<Vec<f64>> = slices
        .iter()
        .zip(z)
        .map(|(s, &zi)| {
            let mut row = Vec::with_capacity(4 * n2);
            for (c, p) in s.control_points.iter().enumerate() {
                let w = s.weights.as_ref().map_or(1.0, |w| w[c]);
                row.extend([w * p[0], w * p[1], w * zi, w]);
            }
            row
        })
        .collect();
    let layers = if kz.degree() == 1 {
        data
    } else {
        // collocation A[i][j] = L_j(ζ_i): square (m functions), nonsingular by
        // Schoenberg–Whitney (t_j < ζ_j < t_{j+r+1} for the interior functions)
        let mut a = vec![vec![0.0; m]; m];
        for (i, &t) in zeta.iter().enumerate() {
            let b = BasisDerivs::at(&kz, t, 0);
            for (j, &v) in b.ders(0).iter().enumerate() {
                a[i][b.first() + j] = v;
            }
        }
        dense_solve(&a, &data)
    };
    let mut cps = Vec::with_capacity(m * n2);
    let mut weights = Vec::with_capacity(m * n2);
    for layer in &layers {
        for h in layer.chunks_exact(4) {
            cps.push([h[0] / h[3], h[1] / h[3], h[2] / h[3]]);
            weights.push(h[3]);
        }
    }
    let k = slices[0].knots.clone();
    Volume::new([k[0].clone(), k[1].clone(), kz], cps, rational.then_some(weights))
}

#[cfg(test)]
/// [`common_basis`] then [`interpolate`].
pub(crate) fn loft_slices(slices: &[Surface], z: &[f64], interpolation: Interpolation) -> Result<Volume> {
    check_heights(z, slices.len())?;
    interpolate(&common_basis(slices)?, z, interpolation)
}

/// The planar map at parameter `ζ` of a lofted volume: the section's control net with
/// `z` dropped (the initial guess of a slice inserted there).
pub(crate) fn planar_section(vol: &Volume, zeta: f64) -> Surface {
    let (pts, weights) = vol.section(2, zeta);
    Surface {
        knots: [vol.knots[0].clone(), vol.knots[1].clone()],
        control_points: pts.iter().map(|p| [p[0], p[1]]).collect(),
        weights,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Lcg;

    fn slice(rng: &mut Lcg, deg: [usize; 2], ne: [usize; 2], f: impl Fn(f64, f64) -> [f64; 2]) -> Surface {
        let k = [0, 1].map(|d| KnotVector::open_uniform(deg[d], ne[d]).with_inserted(&[0.1 + 0.8 * rng.uniform()]));
        let g = k.each_ref().map(KnotVector::greville);
        let cps = g[1].iter().flat_map(|&v| g[0].iter().map(move |&u| (u, v))).map(|(u, v)| f(u, v)).collect();
        Surface::new(k, cps, None).unwrap()
    }

    #[test]
    fn common_basis_keeps_every_slice() {
        let mut rng = Lcg::new(2);
        let a = slice(&mut rng, [2, 3], [3, 2], |u, v| [u + 0.1 * v * v, v - 0.2 * u * v]);
        let b = slice(&mut rng, [3, 2], [2, 4], |u, v| [2.0 * u, v + 0.3 * u * u]);
        let mut c = b.clone();
        c.weights = Some((0..c.control_points.len()).map(|i| 1.0 + 0.1 * (i % 3) as f64).collect());
        let common = common_basis(&[a.clone(), b.clone(), c.clone()]).unwrap();
        assert_eq!(common[0].degrees(), [3, 3]);
        assert!(common.iter().all(|s| s.knots == common[0].knots));
        for (orig, s) in [a, b, c].iter().zip(&common) {
            for _ in 0..20 {
                let (u, v) = (rng.uniform(), rng.uniform());
                let (x, y) = (orig.eval(u, v), s.eval(u, v));
                assert!((x[0] - y[0]).abs() < 1e-13 && (x[1] - y[1]).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn bad_slices_are_typed_errors() {
        let mut rng = Lcg::new(4);
        let a = slice(&mut rng, [2, 2], [2, 2], |u, v| [u, v]);
        let e = |r: Result<Volume>| match r {
            Err(Error::Slices { slice, reason }) => (slice, reason),
            other => panic!("{other:?}"),
        };
        let two = [a.clone(), a.clone()];
        assert!(e(loft_slices(&two, &[0.0, 0.0], Interpolation::Linear)).1.contains("increase strictly"));
        assert!(e(loft_slices(&two, &[1.0, 0.0], Interpolation::Linear)).1.contains("increase"));
        assert!(e(loft_slices(&two, &[0.0], Interpolation::Linear)).1.contains("one z per slice"));
        assert!(e(loft_slices(&two, &[0.0, f64::NAN], Interpolation::Linear)).1.contains("not finite"));
        assert!(e(loft_slices(&two[..1], &[0.0], Interpolation::Linear)).1.contains("at least two"));
        // a ring (periodic eta) with a four-sided map
        let kp = KnotVector::periodic_uniform(2, 4);
        let n = kp.num_basis();
        let ring_cps: Vec<[f64; 2]> = (0..2)
            .flat_map(|r| {
                (0..n).map(move |j| {
                    let t = std::f64::consts::TAU * (j % 4) as f64 / 4.0;
                    [(1.0 + r as f64) * t.cos(), (1.0 + r as f64) * t.sin()]
                })
            })
            .collect();
        let ko = KnotVector::open_uniform(1, 1);
        let ring = Surface::new([ko, kp], transpose_ring(&ring_cps, n), None).unwrap();
        let (slice, reason) = e(loft_slices(&[a, ring], &[0.0, 1.0], Interpolation::Linear));
        assert_eq!(slice, Some(1));
        assert!(reason.contains("periodic") && reason.contains("corners"), "{reason}");
    }

    /// Control points given radius-major to the `xi`-fastest layout of a ring map.
    fn transpose_ring(cps: &[[f64; 2]], n: usize) -> Vec<[f64; 2]> {
        (0..n).flat_map(|j| (0..2).map(move |r| cps[r * n + j])).collect()
    }

    /// Slices that depend on `z` as a cubic polynomial (per control point) are
    /// reproduced exactly by the cubic interpolation, with uneven heights; the linear
    /// one reproduces them only at the slices.
    #[test]
    fn cubic_interpolation_reproduces_cubic_families() {
        let mut rng = Lcg::new(6);
        let base = slice(&mut rng, [2, 2], [3, 3], |u, v| [u, v]);
        let family = |z: f64| -> Surface {
            let mut s = base.clone();
            for p in s.control_points.iter_mut() {
                let (u, v) = (p[0], p[1]);
                *p = [u * (1.0 + 0.3 * z - 0.2 * z * z * z) + 0.1 * z * z * v, v + 0.25 * z * z * z * u - 0.1 * z];
            }
            s
        };
        let z = [0.0, 0.3, 0.45, 1.0, 1.2, 1.9, 2.0];
        let slices: Vec<Surface> = z.iter().map(|&z| family(z)).collect();
        let cubic = loft_slices(&slices, &z, Interpolation::Cubic).unwrap();
        let linear = loft_slices(&slices, &z, Interpolation::Linear).unwrap();
        assert_eq!(cubic.degrees()[2], 3);
        let mut linear_error: f64 = 0.0;
        for _ in 0..100 {
            let zz = 2.0 * rng.uniform();
            let (u, v) = (rng.uniform(), rng.uniform());
            let t = zz / 2.0;
            let want = family(zz).eval(u, v);
            let got = cubic.eval([u, v, t]);
            assert!((got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12, "{got:?} vs {want:?}");
            assert!((got[2] - zz).abs() < 1e-13);
            let lin = linear.eval([u, v, t]);
            linear_error = linear_error.max((lin[0] - want[0]).abs());
        }
        assert!(linear_error > 1e-3, "the linear interpolation is not exact between slices: {linear_error}");
        for (i, &zi) in z.iter().enumerate() {
            let t = (zi - z[0]) / (z[6] - z[0]);
            for vol in [&cubic, &linear] {
                let x = vol.eval([0.3, 0.7, t]);
                let want = slices[i].eval(0.3, 0.7);
                assert!((x[0] - want[0]).abs() < 1e-12 && (x[2] - zi).abs() < 1e-12);
            }
        }
        // C2 across the interior knots of the cubic (second differences of ζ-derivative)
        let h = 1e-4;
        let knot = cubic.knots[2].knots()[5];
        let d = |t: f64| cubic.derivs([0.4, 0.6, t]).d[2][0];
        let (l, r) = ((d(knot) - d(knot - h)) / h, (d(knot + h) - d(knot)) / h);
        assert!((l - r).abs() < 1e-2 * (1.0 + l.abs()), "{l} vs {r}");
    }

    /// Identical slices give a cylinder: `det J = det J_2D (z_max - z_0)`.
    #[test]
    fn identical_slices_give_a_cylinder() {
        let mut rng = Lcg::new(8);
        let s = slice(&mut rng, [3, 2], [3, 4], |u, v| [u + 0.2 * v * v, v * (1.0 + 0.5 * u)]);
        let z = [-1.0, 0.5, 2.0, 3.0];
        for interp in [Interpolation::Linear, Interpolation::Cubic] {
            let vol = loft_slices(&vec![s.clone(); 4], &z, interp).unwrap();
            for _ in 0..30 {
                let u = [rng.uniform(), rng.uniform(), rng.uniform()];
                let d = vol.derivs(u);
                let want = s.derivs(u[0], u[1], 1).det_j() * 4.0;
                assert!((d.det_j() - want).abs() < 1e-11 * want.abs(), "{interp:?}: {} vs {want}", d.det_j());
                let x = s.eval(u[0], u[1]);
                assert!((d.x[0] - x[0]).abs() < 1e-13 && (d.x[2] - (-1.0 + 4.0 * u[2])).abs() < 1e-13);
            }
        }
    }
}
