//! The outline of a multipatch layout as a general planar domain: the patch sides that
//! are in no interface, oriented with the layout to their left and chained into closed
//! loops (the outer loop counter-clockwise, every hole clockwise), with consecutive
//! sides merged into one curve where they join tangentially. This is the input a user
//! has who was never given the layout's cuts: the automatic layout
//! ([`super::auto_layout`]) of [`outline`] can be compared with the hand-made layout
//! (`winslow convert LAYOUT --outline`).
//!
//! Orientation: a patch's boundary runs south (`xi` increasing), east (`eta`
//! increasing), north and west backwards; the patch lies to the left of that loop when
//! its signed area `∮ (x dy - y dx) / 2` is positive (`det J > 0`), to the right
//! otherwise, and its outer sides are taken in the direction that has the patch on the
//! left.
//!
//! Merging: where a side ends and the next begins with tangent directions `t_1`,
//! `t_2` whose angle `∠(t_1, t_2)` is below the threshold, the two become one curve
//! (degrees raised to the larger one; a NURBS side's weights scaled so that the joint's
//! weight agrees, which leaves the curve unchanged; the joint a knot of multiplicity
//! `p` at the parameter `L_1 / (L_1 + L_2)` of the arc lengths, so every point of both
//! curves is kept exactly). Where a merged joint is not tangent to rounding (a kink of
//! a fraction of a degree between two hand-made patches), the `C^0` knot could not be
//! a patch side's knot in a conforming basis, so that side is written as a point cloud
//! sampled from the exact curves and fitted by the layout like any point-cloud side. A
//! loop keeps at least two sides (the domain document's rule: one periodic curve
//! without corners is not laid out).

use crate::boundary::SideCurve;
use crate::error::{Error, Result};
use crate::multipatch::{Layout, PatchSide};
use crate::spline::curve::{Curve, Point};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;

use super::{Domain, Loop};

/// Samples per curve for arc lengths and signed areas.
const SAMPLES: usize = 64;

/// The outline of `layout` (see the module documentation): its outer boundary and
/// holes as a [`Domain`] named after it, consecutive sides merged where they turn by
/// less than `smooth_below_degrees` (`0`: none merged).
pub fn outline(layout: &Layout, smooth_below_degrees: f64) -> Result<Domain> {
    if !(0.0..180.0).contains(&smooth_below_degrees) {
        return Err(Error::Invalid(format!(
            "the angle below which sides are merged must lie in [0, 180) degrees, got {smooth_below_degrees}"
        )));
    }
    let sides: Vec<(PatchSide, Curve)> = layout
        .outer_sides()
        .into_iter()
        .map(|ps| {
            let c = layout.patches[ps.patch].side(ps.side).normalized();
            let forward = matches!(ps.side, Side::South | Side::East) == (patch_area(layout, ps.patch) > 0.0);
            (ps, if forward { c } else { c.reversed() })
        })
        .collect();
    if sides.is_empty() {
        return Err(Error::Invalid(format!("the layout {} has no outer side", layout.name)));
    }
    let tol = 1e-7 * layout.diameter();
    let mut used = vec![false; sides.len()];
    let mut loops: Vec<Vec<SideCurve>> = Vec::new();
    while let Some(first) = used.iter().position(|u| !u) {
        let mut chain = vec![first];
        used[first] = true;
        let start = sides[first].1.endpoints().0;
        loop {
            let (ps, c) = &sides[*chain.last().expect("the chain has a first side")];
            let end = c.endpoints().1;
            if dist(end, start) <= tol && chain.len() > 1 {
                break;
            }
            let next: Vec<usize> =
                (0..sides.len()).filter(|&k| !used[k] && dist(sides[k].1.endpoints().0, end) <= tol).collect();
            match next.as_slice() {
                [k] => {
                    used[*k] = true;
                    chain.push(*k);
                }
                [] if dist(end, start) <= tol => break,
                [] => {
                    return Err(layout.error(
                        ps.patch,
                        Some(ps.side),
                        format!(
                            "the outer boundary ends at ({:.6}, {:.6}), where no other outer side begins: the boundary is not closed",
                            end[0], end[1]
                        ),
                    ))
                }
                _ => {
                    return Err(layout.error(
                        ps.patch,
                        Some(ps.side),
                        format!(
                            "{} outer sides begin at ({:.6}, {:.6}), where it ends: the boundary loops touch there",
                            next.len(),
                            end[0],
                            end[1]
                        ),
                    ))
                }
            }
        }
        let curves: Vec<Curve> = chain.iter().map(|&k| sides[k].1.clone()).collect();
        loops.push(merge_smooth(curves, smooth_below_degrees.to_radians())?);
    }
    let areas: Vec<f64> = loops.iter().map(|l| side_loop_area(l)).collect();
    let outer: Vec<usize> = (0..loops.len()).filter(|&k| areas[k] > 0.0).collect();
    let [o] = outer.as_slice() else {
        return Err(Error::Invalid(format!(
            "the layout {} has {} counter-clockwise boundary loops: its patches do not form one connected region",
            layout.name,
            outer.len()
        )));
    };
    let to_loop = |l: &Vec<SideCurve>| Loop::new(l.clone());
    Ok(Domain {
        name: layout.name.clone(),
        outer: to_loop(&loops[*o]),
        holes: loops.iter().enumerate().filter(|&(k, _)| k != *o).map(|(_, l)| to_loop(l)).collect(),
    })
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// `∮ (x dy - y dx) / 2` along the sampled polyline of `curves` in order.
fn loop_area(curves: &[Curve]) -> f64 {
    let pts: Vec<Point> = curves.iter().flat_map(|c| c.sample(SAMPLES).into_iter().skip(1)).collect();
    let n = pts.len();
    (0..n).map(|i| pts[i][0] * pts[(i + 1) % n][1] - pts[(i + 1) % n][0] * pts[i][1]).sum::<f64>() / 2.0
}

/// `∮ (x dy - y dx) / 2` along the sampled polyline of the sides `l` in order.
fn side_loop_area(l: &[SideCurve]) -> f64 {
    let pts: Vec<Point> = l
        .iter()
        .flat_map(|s| match s {
            SideCurve::Spline(c) => c.sample(SAMPLES),
            SideCurve::Points(p) => p.clone(),
            SideCurve::Analytic(_) => Vec::new(),
        })
        .collect();
    let n = pts.len();
    (0..n).map(|i| pts[i][0] * pts[(i + 1) % n][1] - pts[(i + 1) % n][0] * pts[i][1]).sum::<f64>() / 2.0
}

/// Signed area of patch `p` bounded by south, east, north reversed, west reversed.
fn patch_area(layout: &Layout, p: usize) -> f64 {
    let s = |side: Side| layout.patches[p].side(side).normalized();
    loop_area(&[s(Side::South), s(Side::East), s(Side::North).reversed(), s(Side::West).reversed()])
}

/// Arc length of the sampled polyline of `c`.
fn length(c: &Curve) -> f64 {
    c.sample(SAMPLES).windows(2).map(|w| dist(w[0], w[1])).sum()
}

/// The angle between the end tangent of `a` and the start tangent of `b` (radians).
fn turn(a: &Curve, b: &Curve) -> f64 {
    let ta = a.derivs(a.domain().1, 1).d1;
    let tb = b.derivs(b.domain().0, 1).d1;
    let cross = ta[0] * tb[1] - ta[1] * tb[0];
    let dot = ta[0] * tb[0] + ta[1] * tb[1];
    cross.atan2(dot).abs()
}

/// A joint turning by less than this (radians) is tangent: the merged curve is kept as
/// a spline; otherwise it becomes a point cloud (see [`merge_smooth`]).
const TANGENT: f64 = 1e-9;

/// Points per knot span of a merged side written as a point cloud.
const CLOUD_PER_SPAN: usize = 32;

/// The loop `curves` with every joint turning by less than `below` (radians) merged,
/// the smoothest joint first, while more than two sides remain. A merged side whose
/// joints are all tangent (to [`TANGENT`]) stays a spline; one with a joint that turns
/// (a small kink) becomes a point cloud sampled from the exact curves, which the layout
/// fits like any point-cloud side (to `--fit-tol`): a spline side with a `C^0` knot
/// cannot be a patch side in a conforming multipatch basis.
fn merge_smooth(curves: Vec<Curve>, below: f64) -> Result<Vec<SideCurve>> {
    let mut curves: Vec<(Curve, bool)> = curves.into_iter().map(|c| (c, false)).collect();
    while curves.len() > 2 {
        let n = curves.len();
        let best = (0..n)
            .map(|k| (k, turn(&curves[k].0, &curves[(k + 1) % n].0)))
            .filter(|&(_, t)| t < below)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let Some((k, t)) = best else { break };
        let j = (k + 1) % n;
        let joined = (join(&curves[k].0, &curves[j].0)?, curves[k].1 || curves[j].1 || t > TANGENT);
        if j == 0 {
            // the joint of the last side and the first: the merged side comes first
            curves.pop();
            curves[0] = joined;
        } else {
            curves[k] = joined;
            curves.remove(j);
        }
    }
    Ok(curves
        .into_iter()
        .map(|(c, cloud)| {
            if cloud {
                SideCurve::Points(c.sample(CLOUD_PER_SPAN * c.knots.num_elements().max(1)))
            } else {
                SideCurve::Spline(c)
            }
        })
        .collect())
}

/// `a` followed by `b` (which begins where `a` ends) as one curve on `[0, 1]`: both at
/// the larger degree `p`, the joint at `s = L_a / (L_a + L_b)` a knot of multiplicity
/// `p` whose control point is `a`'s last (= `b`'s first), `b`'s weights scaled by
/// `w_a,last / w_b,first` (see the module documentation).
pub(crate) fn join(a: &Curve, b: &Curve) -> Result<Curve> {
    let (mut a, mut b) = (a.normalized(), b.normalized());
    while a.degree() < b.degree() {
        a = a.elevated()?;
    }
    while b.degree() < a.degree() {
        b = b.elevated()?;
    }
    let p = a.degree();
    let (la, lb) = (length(&a), length(&b));
    let s = if la + lb > 0.0 { la / (la + lb) } else { 0.5 };
    let (na, nb) = (a.control_points.len(), b.control_points.len());
    let mut knots: Vec<f64> = a.knots.knots()[..na].iter().map(|t| t * s).collect();
    knots.extend(std::iter::repeat_n(s, p));
    knots.extend(b.knots.knots()[p + 1..].iter().map(|t| s + t * (1.0 - s)));
    let mut cp = a.control_points.clone();
    cp.extend_from_slice(&b.control_points[1..]);
    let weights = match (&a.weights, &b.weights) {
        (None, None) => None,
        (wa, wb) => {
            let wa = wa.clone().unwrap_or_else(|| vec![1.0; na]);
            let wb = wb.clone().unwrap_or_else(|| vec![1.0; nb]);
            let scale = wa[na - 1] / wb[0];
            let mut w = wa;
            w.extend(wb[1..].iter().map(|x| x * scale));
            Some(w)
        }
    };
    Curve::new(KnotVector::new(p, knots)?, cp, weights)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::validate_domain;
    use crate::io::{read, Document};
    use crate::spline::surface::Surface;
    use crate::testutil::data;

    fn layout(rel: &str) -> Layout {
        match read(&data(rel)).unwrap() {
            Document::Layout(l) | Document::Multipatch(l) => l,
            _ => panic!("{rel} is no layout"),
        }
    }

    /// The sum of the patches' signed areas (every patch of these files is positive).
    fn layout_area(l: &Layout) -> f64 {
        (0..l.patches.len()).map(|p| patch_area(l, p)).sum()
    }

    #[test]
    fn a_joined_curve_keeps_every_point_of_both() {
        // a quarter circle (NURBS, weight 1/sqrt 2) and a cubic polynomial side
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let arc = Curve::new(
            KnotVector::open_uniform(2, 1),
            vec![[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            Some(vec![1.0, w, 1.0]),
        )
        .unwrap();
        let cubic = Curve::new(
            KnotVector::open_uniform(3, 2),
            vec![[0.0, 1.0], [-0.5, 1.0], [-1.0, 1.2], [-1.5, 0.9], [-2.0, 1.0]],
            None,
        )
        .unwrap();
        let j = join(&arc, &cubic).unwrap();
        assert_eq!(j.degree(), 3);
        let s = length(&arc) / (length(&arc) + length(&cubic));
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            let on_arc = j.eval(s * t);
            let want = arc.eval(t);
            assert!(dist(on_arc, want) < 1e-13, "{on_arc:?} {want:?}");
            // on the circle of radius 1
            assert!((on_arc[0].hypot(on_arc[1]) - 1.0).abs() < 1e-13);
            let on_cubic = j.eval(s + (1.0 - s) * t);
            assert!(dist(on_cubic, cubic.eval(t)) < 1e-13, "{t}");
        }
    }

    #[test]
    fn the_plate_with_a_hole_has_five_corners_and_the_layouts_area() {
        let l = layout("gismo/xml/multipatch/plateWithHoleMP.xml");
        // the quarter plate [-4, 0] x [0, 4] without the unit disc
        let area = 16.0 - std::f64::consts::PI / 4.0;
        // every side kept: the arc's two halves meet at a flat joint
        let mut d = outline(&l, 0.0).unwrap();
        assert_eq!(d.outer.sides.len(), 6);
        assert!(d.holes.is_empty());
        let r = validate_domain(&mut d).unwrap();
        assert!(r.reoriented.is_empty(), "{:?}", r.reoriented);
        assert!((r.area - area).abs() < 1e-3 * area, "{} {area}", r.area);
        // the arc merged: five corners, each of 90 degrees, at the plate's corners
        let d = outline(&l, 5.0).unwrap();
        assert_eq!(d.outer.sides.len(), 5);
        let mut corners: Vec<Point> = d.outer.sides.iter().map(|s| s.endpoints().0).collect();
        corners.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let want = [[-4.0, 0.0], [-4.0, 4.0], [-1.0, 0.0], [0.0, 1.0], [0.0, 4.0]];
        for (c, w) in corners.iter().zip(want) {
            assert!(dist(*c, w) < 1e-12, "{c:?} {w:?}");
        }
        // the merged arc is the quarter circle of radius 1 (exactly, up to rounding)
        let arc = d
            .outer
            .sides
            .iter()
            .find_map(|s| match s {
                SideCurve::Spline(c) if c.is_rational() => Some(c.clone()),
                _ => None,
            })
            .unwrap();
        for p in arc.sample(40) {
            assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-12, "{p:?}");
        }
        assert!((side_loop_area(&outline(&l, 5.0).unwrap().outer.sides) - area).abs() < 1e-3 * area);
        assert!((layout_area(&l) - area).abs() < 1e-3 * area);
    }

    #[test]
    fn the_tud_flame_keeps_its_four_corners_and_the_kink() {
        let l = layout("gismo/xml/multipatch/TUDflame.xml");
        let mut d = outline(&l, 5.0).unwrap();
        // twelve outer sides; seven tangent joints merged; four corners and one kink of
        // about 11 degrees left
        assert_eq!(d.outer.sides.len(), 5);
        // the joints turn by 0.1 to 0.7 degrees: the merged sides are point clouds
        assert!(d.outer.sides.iter().any(|s| matches!(s, SideCurve::Points(_))));
        let r = validate_domain(&mut d).unwrap();
        assert!((r.area - layout_area(&l)).abs() < 1e-3 * r.area, "{} {}", r.area, layout_area(&l));
        assert_eq!(outline(&l, 0.0).unwrap().outer.sides.len(), 12);
        assert_eq!(outline(&l, 20.0).unwrap().outer.sides.len(), 4);
    }

    #[test]
    fn a_ring_of_four_patches_gives_a_hole() {
        // the annulus 1 < r < 2 as four quarter-ring patches (bilinear in r, NURBS in angle)
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let quarter = |k: usize| {
            let rot = |p: Point| {
                let (s, c) = (k as f64 * std::f64::consts::FRAC_PI_2).sin_cos();
                [c * p[0] - s * p[1], s * p[0] + c * p[1]]
            };
            let cp: Vec<Point> =
                [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]].into_iter().map(rot).collect();
            let m = Surface::new(
                [KnotVector::open_uniform(2, 1), KnotVector::open_uniform(1, 1)],
                cp,
                Some(vec![1.0, w, 1.0, 1.0, w, 1.0]),
            )
            .unwrap();
            crate::multipatch::Patch::from_map(format!("q{k}"), m)
        };
        let patches: Vec<_> = (0..4).map(quarter).collect();
        let interfaces = (0..4)
            .map(|k| crate::multipatch::Interface {
                first: PatchSide { patch: k, side: Side::West },
                second: PatchSide { patch: (k + 3) % 4, side: Side::East },
                reversed: false,
            })
            .collect();
        let l = Layout { name: "ring".into(), patches, interfaces };
        let mut d = outline(&l, 5.0).unwrap();
        assert_eq!(d.holes.len(), 1);
        // two sides per loop at least (a circle is not one periodic side)
        assert_eq!(d.outer.sides.len(), 2);
        assert_eq!(d.holes[0].sides.len(), 2);
        let r = validate_domain(&mut d).unwrap();
        assert!(r.reoriented.is_empty(), "{:?}", r.reoriented);
        let area = 3.0 * std::f64::consts::PI;
        assert!((r.area - area).abs() < 1e-3 * area, "{} {area}", r.area);
    }
}
