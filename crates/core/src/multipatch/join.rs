//! Joining two patches into one (paper §11.2, Fig. 27-28): two maps that share a whole
//! side become one map on the knot vectors joined with a `C⁰` knot at the interface
//! (multiplicity `p` in the joining direction), its control points the two nets side by
//! side with the shared column once. The joined map is exactly the two maps, so it is
//! bijective when they are; the former interface's control points are then interior
//! and float: the map is smoothed by the weak form (eq. 14) from this bijective start
//! (or by the Winslow functional, eq. 16), both of which allow the `C⁰` basis.
//!
//! Before joining, each map is turned by a rotation of its parameter square (which keeps
//! its orientation) so that the shared side is the east side of the first and the west
//! side of the second; both are brought to common degrees (exact elevation) and the
//! shared direction to one knot vector (exact insertion).

use serde::Serialize;

use super::check::SHARED_TOL;
use super::problem::Functional;
use crate::discrete::topology::Topology;
use crate::error::{Error, Result};
use crate::methods::weak_form::WeakFormMethod;
use crate::methods::winslow::WinslowMethod;
use crate::methods::Method;
use crate::solve::improve::{improve, Improvement};
use crate::solve::newton::NonlinearOptions;
use crate::spline::curve::Point;
use crate::spline::knots::KnotVector;
use crate::spline::surface::{Side, Surface};
use crate::verify::certificate::{certify, Certificate, CertifyOptions};

/// `map` with direction `d` reversed (`t -> 1 - t`).
pub(crate) fn reversed_dir(map: &Surface, d: usize) -> Surface {
    let [nx, ny] = map.shape();
    let src = |i: usize, j: usize| if d == 0 { j * nx + (nx - 1 - i) } else { (ny - 1 - j) * nx + i };
    let mut cps = Vec::with_capacity(nx * ny);
    let mut w = map.weights.as_ref().map(|_| Vec::with_capacity(nx * ny));
    for j in 0..ny {
        for i in 0..nx {
            cps.push(map.control_points[src(i, j)]);
            if let (Some(w), Some(ws)) = (w.as_mut(), map.weights.as_ref()) {
                w.push(ws[src(i, j)]);
            }
        }
    }
    let mut knots = map.knots.clone();
    knots[d] = super::classes::flipped(&map.knots[d]);
    Surface { knots, control_points: cps, weights: w }
}

/// `map` re-parameterized by a rotation of the parameter square so that its side `s`
/// becomes `target` (east or west); the orientation is kept.
pub fn turned(map: &Surface, s: Side, target: Side) -> Surface {
    match (target, s) {
        (Side::East, Side::East) | (Side::West, Side::West) => map.clone(),
        (Side::East, Side::West) | (Side::West, Side::East) => reversed_dir(&reversed_dir(map, 0), 1),
        (Side::East, Side::North) | (Side::West, Side::South) => reversed_dir(&map.transposed(), 1),
        (Side::East, Side::South) | (Side::West, Side::North) => reversed_dir(&map.transposed(), 0),
        _ => map.clone(),
    }
}

/// `map` with the degree of direction `d` raised to `p` (exactly).
pub(crate) fn elevated_in(map: &Surface, d: usize, p: usize) -> Result<Surface> {
    let mut m = map.clone();
    while m.knots[d].degree() < p {
        m = m.elevated_in(d)?;
    }
    Ok(m)
}

/// What `join_maps` did.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct JoinReport {
    /// The shared side of the first and of the second map.
    pub sides: [&'static str; 2],
    /// The parameter of the `C⁰` knot in the joined direction (the first map's share of
    /// the mean length of the sides across it).
    pub c0_knot: f64,
    /// Basis of the joined map.
    pub shape: [usize; 2],
    /// Turning angle of the joined map's boundary where the two maps meet (south and
    /// north side of the joined map), in degrees; 0 where it runs straight on.
    pub turn_degrees: [f64; 2],
    /// Largest distance between the two copies of the shared side at equal parameters.
    pub interface_gap: f64,
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn diameter(maps: &[&Surface]) -> f64 {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in maps.iter().flat_map(|m| &m.control_points) {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

/// Join `a` and `b` along their shared side into one map (see the module documentation):
/// `a` becomes `xi ∈ [0, s]`, `b` `xi ∈ [s, 1]`, with a `C⁰` knot at `s`.
///
/// Errors: [`Error::Invalid`] when the maps share no whole side (the same curve at equal
/// parameters, to `SHARED_TOL` of the diameter), lie on the same side of it, or have
/// weights along it that no scaling makes equal.
pub(crate) fn join_maps(a: &Surface, b: &Surface) -> Result<(Surface, JoinReport)> {
    if a.knots.iter().chain(&b.knots).any(KnotVector::is_periodic) {
        return Err(Error::Invalid("periodic maps (rings) cannot be joined".into()));
    }
    let tol = SHARED_TOL * diameter(&[a, b]);
    let mut found = None;
    'search: for sa in Side::ALL {
        for sb in Side::ALL {
            let (ea, eb) = (a.boundary(sa).endpoints(), b.boundary(sb).endpoints());
            if dist(ea.0, eb.0) <= tol && dist(ea.1, eb.1) <= tol || dist(ea.0, eb.1) <= tol && dist(ea.1, eb.0) <= tol
            {
                found = Some((sa, sb));
                break 'search;
            }
        }
    }
    let (sa, sb) = found.ok_or_else(|| {
        Error::Invalid(format!("the two maps share no whole side (no two sides end at the same points to {tol:.3e})"))
    })?;
    let a1 = turned(a, sa, Side::East);
    let b1 = turned(b, sb, Side::West);
    if dist(a1.boundary(Side::East).endpoints().0, b1.boundary(Side::West).endpoints().0) > tol {
        return Err(Error::Invalid(format!(
            "the {sa} side of the first map and the {sb} side of the second run the same way around their patches: the maps overlap"
        )));
    }
    let p = a1.knots[0].degree().max(b1.knots[0].degree());
    let q = a1.knots[1].degree().max(b1.knots[1].degree());
    let a2 = elevated_in(&elevated_in(&a1, 0, p)?, 1, q)?;
    let b2 = elevated_in(&elevated_in(&b1, 0, p)?, 1, q)?;
    let eta = a2.knots[1].union(&b2.knots[1])?;
    let a3 = a2.refined(&[a2.knots[0].clone(), eta.clone()])?;
    let mut b3 = b2.refined(&[b2.knots[0].clone(), eta.clone()])?;
    let (ea, eb) = (a3.boundary(Side::East), b3.boundary(Side::West));
    let gap = ea.control_points.iter().zip(&eb.control_points).map(|(x, y)| dist(*x, *y)).fold(0.0, f64::max);
    if gap.is_nan() || gap > tol {
        return Err(Error::Invalid(format!(
            "the shared {sa}/{sb} sides are not the same curve at equal parameters (control points differ by {gap:.3e}, tolerance {tol:.3e})"
        )));
    }
    // weights: scale b so that the shared column has a's weights
    let rational = a3.weights.is_some() || b3.weights.is_some();
    let wa = a3.weights.clone().unwrap_or_else(|| vec![1.0; a3.control_points.len()]);
    let mut wb = b3.weights.clone().unwrap_or_else(|| vec![1.0; b3.control_points.len()]);
    if rational {
        let [nxa, _] = a3.shape();
        let nxb = b3.shape()[0];
        let col_a: Vec<f64> = (0..eta.num_basis()).map(|j| wa[j * nxa + nxa - 1]).collect();
        let col_b: Vec<f64> = (0..eta.num_basis()).map(|j| wb[j * nxb]).collect();
        let lambda = col_a[0] / col_b[0];
        if col_a.iter().zip(&col_b).any(|(x, y)| (x - lambda * y).abs() > 1e-12 * x.abs()) {
            return Err(Error::Invalid(
                "the shared side's weights differ between the maps by more than a common factor".into(),
            ));
        }
        wb.iter_mut().for_each(|w| *w *= lambda);
        b3.weights = Some(wb.clone());
    }
    // the C0 knot: a's share of the mean length of the sides across the interface
    let len = |m: &Surface| {
        [Side::South, Side::North]
            .iter()
            .map(|&s| m.boundary(s).sample(64).windows(2).map(|w| dist(w[0], w[1])).sum::<f64>())
            .sum::<f64>()
    };
    let (la, lb) = (len(&a3), len(&b3));
    let s = (la / (la + lb)).clamp(0.05, 0.95);
    let mut knots = vec![0.0; p + 1];
    for &t in &a3.knots[0].knots()[p + 1..a3.knots[0].knots().len() - p - 1] {
        knots.push(s * t);
    }
    knots.extend(std::iter::repeat_n(s, p));
    for &t in &b3.knots[0].knots()[p + 1..b3.knots[0].knots().len() - p - 1] {
        knots.push(s + (1.0 - s) * t);
    }
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    let xi = KnotVector::new(p, knots)?;
    let [nxa, ny] = a3.shape();
    let nxb = b3.shape()[0];
    let mut cps = Vec::with_capacity((nxa + nxb - 1) * ny);
    let mut w = Vec::with_capacity(cps.capacity());
    for j in 0..ny {
        for i in 0..nxa {
            cps.push(a3.control_points[j * nxa + i]);
            w.push(wa[j * nxa + i]);
        }
        for i in 1..nxb {
            cps.push(b3.control_points[j * nxb + i]);
            w.push(wb[j * nxb + i]);
        }
    }
    let joined = Surface::new([xi, eta], cps, rational.then_some(w))?;
    // turning angles where the maps meet
    let turn = |s: Side| {
        let (ca, cb) = (a3.boundary(s), b3.boundary(s));
        let (ta, tb) = (ca.derivs(1.0, 1).d1, cb.derivs(0.0, 1).d1);
        let cross = ta[0] * tb[1] - ta[1] * tb[0];
        let dot = ta[0] * tb[0] + ta[1] * tb[1];
        cross.atan2(dot).to_degrees().abs()
    };
    let report = JoinReport {
        sides: [sa.name(), sb.name()],
        c0_knot: s,
        shape: joined.shape(),
        turn_degrees: [turn(Side::South), turn(Side::North)],
        interface_gap: gap,
    };
    Ok((joined, report))
}

/// A joined and smoothed map.
#[derive(Debug, Clone)]
pub struct Joined {
    /// The map (smoothed when the smoothing was accepted, else the joined map).
    pub map: Surface,
    /// Its certificate.
    pub certificate: Certificate,
    /// What the join did.
    pub join: JoinReport,
    /// The smoothing from the joined map (its boundary fixed, the former interface free).
    pub smoothing: Improvement,
}

/// `join_maps`, then smooth the joined map by `functional` (the weak form, eq. 14, as
/// in the paper, or the Winslow functional, eq. 16) from it, certified before and after
/// ([`crate::solve::improve::improve`]).
///
/// Errors: those of `join_maps`; [`Error::InfeasibleStart`] when the joined map is not
/// certified bijective (one of the two maps was not).
pub fn join_and_smooth(
    a: &Surface,
    b: &Surface,
    functional: Functional,
    nonlinear: NonlinearOptions,
    certify_opts: &CertifyOptions,
) -> Result<Joined> {
    let (map, join) = join_maps(a, b)?;
    let certificate = certify(&map, certify_opts)?;
    let method: Box<dyn Method> = match functional {
        Functional::Winslow => Box::new(WinslowMethod),
        Functional::WeakForm => Box::new(WeakFormMethod),
    };
    let d = diameter(&[&map]);
    let out = improve(&map, &certificate, &*method, &Topology::dirichlet(), nonlinear, certify_opts, d)?;
    Ok(Joined { map: out.map, certificate: out.certificate, join, smoothing: out.report })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curved map on `[x0, x0 + 1] x [0, 1]`: `(u, v) -> (x0 + u, v + 0.2 sin(pi u) v)`.
    fn block(x0: f64, p: usize, ne: usize, ky_extra: &[f64]) -> Surface {
        let kx = KnotVector::open_uniform(p, ne);
        let ky = KnotVector::open_uniform(2, 2).with_inserted(ky_extra);
        let (gx, gy) = (kx.greville(), ky.greville());
        let cps = gy.iter().flat_map(|&v| gx.iter().map(move |&u| [x0 + u, v * (1.0 + 0.2 * (x0 + u))])).collect();
        Surface::new([kx, ky], cps, None).unwrap()
    }

    #[test]
    fn rotations_keep_orientation_and_move_the_side() {
        let m = block(0.0, 2, 3, &[0.3]);
        for s in Side::ALL {
            for target in [Side::East, Side::West] {
                let t = turned(&m, s, target);
                assert!(t.derivs(0.4, 0.6, 1).det_j() > 0.0, "{s} -> {target}");
                let (a, b) = (m.boundary(s).endpoints(), t.boundary(target).endpoints());
                let same = |x: Point, y: Point| dist(x, y) < 1e-14;
                assert!((same(a.0, b.0) && same(a.1, b.1)) || (same(a.0, b.1) && same(a.1, b.0)), "{s} -> {target}");
            }
        }
    }

    /// Two maps sharing x = 1 (different degrees, different eta knots, the second one
    /// turned by 90 degrees): the joined map reproduces both exactly, with a C0 knot.
    #[test]
    fn joined_map_reproduces_both() {
        let a = block(0.0, 3, 2, &[0.5]);
        let b0 = block(1.0, 2, 3, &[0.25]);
        // hand b over with its shared side as north
        let b = turned(&b0, Side::West, Side::East);
        let b = reversed_dir(&b.transposed(), 0); // east -> north
        assert!(b.derivs(0.5, 0.5, 1).det_j() > 0.0);
        let (j, r) = join_maps(&a, &b).unwrap();
        assert_eq!(j.degrees(), [3, 2]);
        let s = r.c0_knot;
        assert_eq!(j.knots[0].multiplicity(s), 3);
        assert!(r.interface_gap < 1e-14 && r.turn_degrees[0] < 1e-6, "{r:?}");
        for k in 0..=20 {
            for l in 0..=20 {
                let (u, v) = (k as f64 / 20.0, l as f64 / 20.0);
                let x = j.eval(u, v);
                let y = if u <= s { a.eval(u / s, v) } else { b0.eval((u - s) / (1.0 - s), v) };
                assert!(dist(x, y) < 1e-12, "({u}, {v}): {x:?} {y:?}");
            }
        }
        // not sharing a side: an error
        let far = block(3.0, 2, 3, &[]);
        assert!(join_maps(&a, &far).is_err());
    }

    /// Two halves of a square split along a zig-zag interface: joined and smoothed by
    /// the weak form, the former interface floats, the map stays certified, and the
    /// Winslow value drops.
    #[test]
    fn joined_map_is_smoothed() {
        let k = KnotVector::open_uniform(2, 4);
        let g = k.greville();
        let zig = |v: f64| 1.0 + 0.25 * (std::f64::consts::PI * v).sin();
        let half = |left: bool| {
            let cps = g
                .iter()
                .flat_map(|&v| {
                    g.iter().map(move |&u| {
                        let (x0, x1) = if left { (0.0, zig(v)) } else { (zig(v), 2.0) };
                        [x0 + u * (x1 - x0), v]
                    })
                })
                .collect();
            Surface::new([k.clone(), k.clone()], cps, None).unwrap()
        };
        let opts = CertifyOptions::default();
        for functional in [Functional::WeakForm, Functional::Winslow] {
            let j = join_and_smooth(&half(true), &half(false), functional, NonlinearOptions::default(), &opts).unwrap();
            let r = &j.smoothing;
            assert!(r.accepted, "{functional:?}: {}", r.message);
            assert!(r.after.winslow.unwrap() < r.before.winslow.unwrap(), "{}", r.message);
            assert!(matches!(j.certificate.verdict, crate::verify::certificate::Finding::Certified { .. }));
            assert_eq!(j.map.knots[0].multiplicity(j.join.c0_knot), 2);
        }
    }
}
