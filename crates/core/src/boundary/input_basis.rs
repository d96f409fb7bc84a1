//! The input basis (paper §5.2, and the artificial hierarchy of §6.3's last paragraph):
//! the map is discretized in the basis of the given spline sides, so that its boundary
//! *is* the input, not a fit of it.
//!
//! Opposite sides are brought to one degree (`p = max(p_south, p_north, 2)` in `xi`,
//! `q = max(p_west, p_east, 2)` in `eta`) by exact degree elevation and to one knot vector
//! (the union of the two, each mapped to `[0, 1]`) by exact knot insertion; the finest
//! level of the hierarchy is that tensor basis with the sides' control points as its
//! boundary. Coarser levels are made by removing every other distinct interior break of
//! each direction, down to one element, and projecting each side onto the coarse space by
//! the constrained least squares of [`super::fit::project_side`] (corners kept), so the
//! solve walks coarse to fine with the elasticity prolongation exactly as on fitted
//! hierarchies, and its finest level has the input boundary exactly (knot insertion by
//! `--refine` or by defect correction keeps it exact). Small input bases
//! ([`DIRECT_SOLVE_MAX_FUNCTIONS`]) are solved directly from the Coons patch.
//!
//! Not every input can be kept this way; [`input_levels`] says why and the caller
//! falls back to the fitted basis:
//! * point clouds and analytic sides have no basis;
//! * NURBS sides whose corner weights cannot be made to agree by scaling each side's
//!   weights (a rational curve is unchanged when all its weights are scaled): the corner
//!   control point has one weight in the tensor basis;
//! * an interior knot whose multiplicity reaches the degree (after elevation) makes the
//!   side only `C^0` there: the Galerkin form (8) needs `C^1`, and a kink must not be
//!   rounded silently. Unless kinks are not kept (`--kinks none`), such a knot, and a
//!   zero-speed knot where the tangent turns, is kept by the `C^0` route of §9
//!   ([`super::kinks`]): the levels built here hold it at multiplicity `p` (`Σ⁰`), the
//!   hierarchy smooths them to `Σ¹` for the Galerkin form. A rational side with a kink is
//!   refused (its smoothed side would need other weights).

use super::fit::{project_side, SideFit};
use super::kinks::Kink;
use super::{Boundary, SideCurve};
use crate::error::Result;
use crate::spline::curve::Curve;
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;

/// The side as a B-spline or NURBS curve on `[0, 1]` of degree at least `degree`, or why
/// not. `kept`: the parameters (in `[0, 1]`) of the side's kinks kept by the `C^0` route
/// (§9, [`super::kinks`]): there the knot is raised to multiplicity `p` (exact
/// insertion: a zero-speed knot becomes a `C^0` knot of the same curve); any other `C^0`
/// knot is refused.
fn spline_side(side: &SideCurve, s: Side, degree: usize, kept: &[f64]) -> std::result::Result<Curve, String> {
    let c = match side {
        SideCurve::Spline(c) => c,
        SideCurve::Points(_) => return Err(format!("the {s} side is a point cloud, which has no basis")),
        SideCurve::Analytic(_) => return Err(format!("the {s} side is analytic, which has no basis")),
    };
    let mut c = c.normalized();
    if c.weights.as_ref().is_some_and(|w| w.iter().all(|&x| x == 1.0)) {
        c.weights = None;
    }
    while c.degree() < degree {
        c = c.elevated().map_err(|e| format!("the {s} side could not be elevated: {e}"))?;
    }
    let p = c.degree();
    let is_kept = |u: f64| kept.iter().any(|&t| (t - u).abs() <= 1e-12);
    let interior = c.knots.breaks_with_multiplicity();
    let interior = &interior[1..interior.len() - 1];
    if let Some(&(u, m)) = interior.iter().find(|b| b.1 > p || (b.1 == p && !is_kept(b.0))) {
        let why = if m > p { "the curve is discontinuous there" } else { "kinks are not kept (--kinks none)" };
        return Err(format!(
            "the {s} side is only C0 at its interior knot {u} (multiplicity {m} at degree {p}): \
             the Galerkin form (8) needs C1 and a kink is not rounded silently ({why})"
        ));
    }
    if !kept.is_empty() && c.weights.is_some() {
        return Err(format!(
            "the {s} side is rational with a kink inside: its smoothed basis would need other weights than the \
             C0 one, so the C0 route of §9 is taken on the fitted basis"
        ));
    }
    let raise: Vec<f64> =
        interior.iter().filter(|b| is_kept(b.0)).flat_map(|&(u, m)| std::iter::repeat_n(u, p - m)).collect();
    if !raise.is_empty() {
        c = c.refined(&c.knots.with_inserted(&raise)).map_err(|e| format!("the {s} side: {e}"))?;
    }
    Ok(c)
}

/// Scale each side's weights (which leaves its curve unchanged) so that the two sides
/// meeting at a corner give its control point one weight: south is kept, west and east
/// take south's corner weights, north takes west's; then north's east end must agree
/// with east's north end (to 1e-12), else the corners' weights are inconsistent.
fn harmonise_corner_weights(sides: &mut [Curve]) -> std::result::Result<(), String> {
    if sides.iter().all(|c| c.weights.is_none()) {
        return Ok(());
    }
    let ends = |c: &Curve| match &c.weights {
        Some(w) => (w[0], w[w.len() - 1]),
        None => (1.0, 1.0),
    };
    let [s, e, n, w] = [0, 1, 2, 3].map(|k| ends(&sides[k]));
    let lambda_w = s.0 / w.0;
    let lambda_e = s.1 / e.0;
    let lambda_n = lambda_w * w.1 / n.0;
    let (ne_north, ne_east) = (lambda_n * n.1, lambda_e * e.1);
    if (ne_north - ne_east).abs() > 1e-12 * ne_north.abs().max(ne_east.abs()) {
        return Err(format!(
            "the NURBS sides' corner weights cannot be made to agree by scaling (north-east corner: {ne_north} \
             from north, {ne_east} from east): the corner control point has one weight in a tensor basis"
        ));
    }
    for (k, lambda) in [(1, lambda_e), (2, lambda_n), (3, lambda_w)] {
        if lambda != 1.0 {
            let c = &mut sides[k];
            let w = c.weights.get_or_insert_with(|| vec![1.0; c.control_points.len()]);
            w.iter_mut().for_each(|x| *x *= lambda);
        }
    }
    Ok(())
}

/// Input bases with at most this many functions are solved directly from the Coons patch,
/// without the coarse levels of §6.3: on the shared geometries the direct solve converges
/// and certifies wherever the hierarchy does (same verdicts, same repair rounds), in
/// 1.3–2.9x less time up to about a thousand functions (duck 80: 0.007 s against 0.018 s,
/// butterfly 625: 0.24 s against 0.69 s), while from a few thousand functions on the
/// hierarchy is faster (butterfly at 8281: 3.0 s against 8.3 s, puzzle3 at 17161: 4.0 s
/// against 9.5 s): `bash scripts/bench-basis.sh`, BENCHMARKS.md.
pub(crate) const DIRECT_SOLVE_MAX_FUNCTIONS: usize = 1024;

/// Remove every other distinct interior break (with all its multiplicity).
fn coarsened(kv: &KnotVector) -> KnotVector {
    let bm = kv.breaks_with_multiplicity();
    let p = kv.degree();
    let last = bm.len() - 1;
    let mut knots = Vec::new();
    for (k, &(u, m)) in bm.iter().enumerate() {
        let keep = k == 0 || k == last || k % 2 == 0;
        if keep {
            knots.extend(std::iter::repeat_n(u, if k == 0 || k == last { p + 1 } else { m }));
        }
    }
    KnotVector::new(p, knots).expect("a subsequence of an open knot vector is one")
}

/// The sequence `coarsest, ..., kv`, each a subset of the next, the coarsest with one
/// element.
fn coarsening(kv: &KnotVector) -> Vec<KnotVector> {
    let mut out = vec![kv.clone()];
    while out.last().expect("non-empty").num_elements() > 1 {
        let c = coarsened(out.last().expect("non-empty"));
        out.push(c);
    }
    out.reverse();
    out
}

/// The levels on the input basis, coarse to fine, and the four sides' sequences of
/// projections (the last one exact).
#[derive(Debug, Clone)]
pub(crate) struct InputLevels {
    /// Knot vectors (`xi`, `eta`) and the four sides (south, east, north, west) on them.
    pub levels: Vec<([KnotVector; 2], [Curve; 4])>,
    /// Per side: the projections onto the coarse levels and the exact side last, with
    /// their deviations (0 for the exact one).
    pub fits: [SideFit; 4],
}

/// The levels on the input basis (see the module documentation), or the reason why the
/// boundary cannot be kept in it.
pub(crate) fn input_levels(boundary: &Boundary) -> Result<std::result::Result<InputLevels, String>> {
    input_levels_with(boundary, DIRECT_SOLVE_MAX_FUNCTIONS, &[])
}

/// [`input_levels`] with the coarse levels built only above `direct_max` functions, and
/// the kinks `kept` (their knots at multiplicity `p` on every level that holds them: the
/// `C^0` bases `Σ⁰` of §9, smoothed by the caller).
pub(crate) fn input_levels_with(
    boundary: &Boundary,
    direct_max: usize,
    kept: &[Kink],
) -> Result<std::result::Result<InputLevels, String>> {
    let side_degree = |s: Side| match boundary.side(s) {
        SideCurve::Spline(c) => c.degree(),
        _ => 0,
    };
    let degree = [Side::South, Side::East]
        .map(|s| side_degree(s).max(side_degree(s.opposite())).clamp(2, crate::error::MAX_DEGREE));
    let mut exact: Vec<Curve> = Vec::with_capacity(4);
    for s in Side::ALL {
        let at: Vec<f64> = kept.iter().filter(|k| k.side == s).map(|k| k.parameter).collect();
        match spline_side(boundary.side(s), s, degree[s.direction()], &at) {
            Ok(c) => exact.push(c),
            Err(why) => return Ok(Err(why)),
        }
    }
    if let Err(why) = harmonise_corner_weights(&mut exact) {
        return Ok(Err(why));
    }
    let union = |a: Side, b: Side| exact[a as usize].knots.union(&exact[b as usize].knots);
    let finest = [union(Side::South, Side::North)?, union(Side::West, Side::East)?];
    let functions = finest[0].num_basis() * finest[1].num_basis();
    let chains = if functions <= direct_max {
        [vec![finest[0].clone()], vec![finest[1].clone()]]
    } else {
        [coarsening(&finest[0]), coarsening(&finest[1])]
    };
    let m = chains[0].len().max(chains[1].len());
    // level k of a direction with fewer levels stays at its coarsest
    let pick = |d: usize, k: usize| chains[d][k.saturating_sub(m - chains[d].len())].clone();
    let mut levels = Vec::with_capacity(m);
    let mut fit_levels: [Vec<Curve>; 4] = Default::default();
    let mut max_error: [Vec<f64>; 4] = Default::default();
    let mut rms_error: [Vec<f64>; 4] = Default::default();
    for k in 0..m {
        let knots = [pick(0, k), pick(1, k)];
        let mut sides = Vec::with_capacity(4);
        for s in Side::ALL {
            let kv = &knots[s.direction()];
            let c = &exact[s as usize];
            let (curve, max, rms) = if k + 1 == m {
                (c.refined(kv)?, 0.0, 0.0)
            } else {
                let pr = project_side(&SideCurve::Spline(c.clone()), kv, c.endpoints())?;
                (pr.curve, pr.max_error, pr.rms_error)
            };
            fit_levels[s as usize].push(curve.clone());
            max_error[s as usize].push(max);
            rms_error[s as usize].push(rms);
            sides.push(curve);
        }
        let sides: [Curve; 4] = sides.try_into().expect("four sides");
        levels.push((knots, sides));
    }
    let fits = Side::ALL.map(|s| SideFit {
        side: s,
        levels: std::mem::take(&mut fit_levels[s as usize]),
        max_error: std::mem::take(&mut max_error[s as usize]),
        rms_error: std::mem::take(&mut rms_error[s as usize]),
        params: None,
        converged: true,
    });
    Ok(Ok(InputLevels { levels, fits }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::Analytic;

    fn side(p: usize, knots: Vec<f64>, cps: Vec<[f64; 2]>) -> SideCurve {
        SideCurve::Spline(Curve::polynomial(KnotVector::new(p, knots).unwrap(), cps))
    }

    /// A square with a cubic wavy south side on a non-uniform knot vector, a quadratic
    /// north side on another domain, linear east and west sides.
    fn boundary() -> Boundary {
        let south = side(
            3,
            vec![0., 0., 0., 0., 0.3, 0.55, 1., 1., 1., 1.],
            vec![[0., 0.], [0.2, 0.1], [0.4, -0.1], [0.6, 0.12], [0.8, 0.0], [1., 0.]],
        );
        let north = side(2, vec![2., 2., 2., 2.5, 3., 3., 3.], vec![[0., 1.], [0.3, 1.2], [0.7, 0.9], [1., 1.]]);
        let east = side(1, vec![0., 0., 1., 1.], vec![[1., 0.], [1., 1.]]);
        let west = side(1, vec![0., 0., 1., 1.], vec![[0., 0.], [0., 1.]]);
        Boundary { name: "wavy".into(), sides: [south, east, north, west] }
    }

    /// The finest level's sides are the input curves exactly (same curve after elevation
    /// and insertion: equal at every sample to rounding), the levels are nested and
    /// coarsen to one element, and degrees are raised to 2 at least.
    #[test]
    fn finest_level_is_the_input() {
        let b = boundary();
        assert_eq!(input_levels(&b).unwrap().unwrap().levels.len(), 1, "a small basis is solved directly");
        let h = input_levels_with(&b, 0, &[]).unwrap().unwrap();
        let (knots, sides) = h.levels.last().unwrap();
        assert_eq!([knots[0].degree(), knots[1].degree()], [3, 2]);
        for s in Side::ALL {
            let SideCurve::Spline(c) = b.side(s) else { unreachable!() };
            let (a, bb) = c.domain();
            for k in 0..=50 {
                let t = k as f64 / 50.0;
                let (x, y) = (c.eval(a + t * (bb - a)), sides[s as usize].eval(t));
                assert!((x[0] - y[0]).abs() < 1e-14 && (x[1] - y[1]).abs() < 1e-14, "{s} at {t}: {x:?} vs {y:?}");
            }
        }
        for w in h.levels.windows(2) {
            assert!(w[1].0[0].contains(&w[0].0[0]) && w[1].0[1].contains(&w[0].0[1]));
        }
        assert_eq!(h.levels[0].0[0].num_elements(), 1);
        assert_eq!(h.fits[0].max_error.last(), Some(&0.0));
        assert!(h.fits[0].max_error[0] > 0.0, "a coarse projection of the wavy side is not exact");
    }

    /// Knot removal then insertion: a spline that lies in the coarse space (here: a
    /// coarse curve refined by insertion onto the fine knots) is reproduced exactly by the
    /// coarse level's projection, and the coarse knots are a subset of the fine ones.
    #[test]
    fn knot_removal_then_insertion_reproduces_coarse_splines() {
        let fine = KnotVector::new(3, vec![0., 0., 0., 0., 0.1, 0.25, 0.3, 0.55, 0.7, 0.9, 1., 1., 1., 1.]).unwrap();
        let chain = coarsening(&fine);
        assert_eq!(chain.last(), Some(&fine));
        assert_eq!(chain[0].num_elements(), 1);
        for coarse in &chain[..chain.len() - 1] {
            assert!(fine.contains(coarse));
            let cps: Vec<[f64; 2]> =
                (0..coarse.num_basis()).map(|i| [i as f64, ((i * 7) % 5) as f64 - 2.0 + 0.1 * i as f64]).collect();
            let c = Curve::polynomial(coarse.clone(), cps.clone());
            let on_fine = c.refined(&fine).unwrap();
            let pr = project_side(&SideCurve::Spline(on_fine), coarse, c.endpoints()).unwrap();
            for (a, b) in pr.curve.control_points.iter().zip(&cps) {
                assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12, "{a:?} vs {b:?}");
            }
            assert!(pr.max_error < 1e-12, "{}", pr.max_error);
        }
    }

    #[test]
    fn unsuitable_sides_say_why() {
        let mut b = boundary();
        b.sides[1] = SideCurve::Points(vec![[1., 0.], [1., 1.]]);
        assert!(input_levels(&b).unwrap().unwrap_err().contains("east side is a point cloud"));
        let mut b = boundary();
        b.sides[3] = SideCurve::Analytic(Analytic::new(|t| [0.0, t]));
        assert!(input_levels(&b).unwrap().unwrap_err().contains("analytic"));
        let mut b = boundary();
        let SideCurve::Spline(c) = &b.sides[2] else { unreachable!() };
        b.sides[2] = SideCurve::Spline(Curve { weights: Some(vec![2.0, 0.8, 1.2, 1.0]), ..c.clone() });
        let why = input_levels(&b).unwrap().unwrap_err();
        assert!(why.contains("NURBS") && why.contains("corner weights"), "{why}");
        // a C0 knot (multiplicity 3 at degree 3) is not rounded silently
        let mut b = boundary();
        b.sides[0] = side(
            3,
            vec![0., 0., 0., 0., 0.5, 0.5, 0.5, 1., 1., 1., 1.],
            vec![[0., 0.], [0.2, 0.1], [0.4, -0.1], [0.5, 0.0], [0.6, 0.12], [0.8, 0.0], [1., 0.]],
        );
        let why = input_levels(&b).unwrap().unwrap_err();
        assert!(why.contains("south") && why.contains("C0") && why.contains("0.5"), "{why}");
    }
}
