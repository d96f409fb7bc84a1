//! Validation of a general planar domain (`formats.md`): every loop closed (each side
//! ends where the next begins, to `1e-9` of the diameter), no loop crossing itself,
//! the holes strictly inside the outer loop and apart from it and from each other, and
//! no loop of zero area. The outer loop is made counter-clockwise and the holes
//! clockwise (the domain lies to the left of every loop); each reorientation is in the
//! report. Crossings are found on polylines of the sides (`sample_side` at the flatness
//! tolerance), by a sweep over the segments sorted by their left ends.

use serde::Serialize;

use super::{domain_error, Domain, Loop, LoopId};
use crate::boundary::validate::{sample_side, CORNER_TOL, FLATNESS};
use crate::boundary::SideCurve;
#[cfg(test)]
use crate::error::Error;
use crate::error::Result;
use crate::spline::curve::Point;

/// What the validation measured.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct DomainReport {
    /// Corners of the outer loop.
    pub outer_corners: usize,
    /// Corners of every hole.
    pub hole_corners: Vec<usize>,
    /// Area of the domain (outer loop minus the holes), from the polylines.
    pub area: f64,
    /// Diameter of the outer loop's bounding box.
    pub diameter: f64,
    /// Loops that were traversed the other way than `formats.md` asks and were reversed.
    pub reoriented: Vec<String>,
    /// Corners found on point clouds given without `corners`.
    pub detected_corners: Vec<Point>,
}

/// A closed polyline of a loop and, per segment, the side it samples.
struct Polyline {
    pts: Vec<Point>,
    owner: Vec<usize>,
}

fn polyline(l: &Loop, flat: f64) -> Polyline {
    let mut pts = Vec::new();
    let mut owner = Vec::new();
    for (k, s) in l.sides.iter().enumerate() {
        let p = sample_side(s, flat);
        for q in &p[..p.len().saturating_sub(1)] {
            pts.push(*q);
            owner.push(k);
        }
    }
    Polyline { pts, owner }
}

fn shoelace(p: &[Point]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i][0] * p[(i + 1) % n][1] - p[(i + 1) % n][0] * p[i][1]).sum::<f64>() * 0.5
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Distance between the segments `ab` and `cd` (0 when they cross), and a point where
/// they are closest.
pub(crate) fn segment_distance(a: Point, b: Point, c: Point, d: Point) -> (f64, Point) {
    let cross = |o: Point, p: Point, q: Point| (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0]);
    let (d1, d2, d3, d4) = (cross(c, d, a), cross(c, d, b), cross(a, b, c), cross(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        let t = d1 / (d1 - d2);
        return (0.0, [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
    }
    let to_seg = |p: Point, s: Point, e: Point| {
        let (vx, vy) = (e[0] - s[0], e[1] - s[1]);
        let l2 = vx * vx + vy * vy;
        let t = if l2 > 0.0 { (((p[0] - s[0]) * vx + (p[1] - s[1]) * vy) / l2).clamp(0.0, 1.0) } else { 0.0 };
        let q = [s[0] + t * vx, s[1] + t * vy];
        (dist(p, q), p)
    };
    [to_seg(a, c, d), to_seg(b, c, d), to_seg(c, a, b), to_seg(d, a, b)].into_iter().fold((f64::INFINITY, a), |m, x| {
        if x.0 < m.0 {
            x
        } else {
            m
        }
    })
}

/// The chord nearest to `q` among the polylines `lines` (a closed polyline's chords
/// include the one from its last point back to its first): the polyline's index and the
/// index of the chord's first point; `None` when no polyline has a chord. A cut's end on
/// a curved side is made a vertex of the side's sampled polyline by inserting it there:
/// it lies on the curve, not on the chords, and where the side bulges away from the cut
/// the chord passes between the cut and its end (by the sagitta `h² / 8R` of a chord of
/// length `h` on a circle of radius `R`), so the cut would seem to cross it.
pub(crate) fn nearest_chord(lines: &[Vec<Point>], closed: bool, q: Point) -> Option<(usize, usize)> {
    let mut best: Option<(f64, usize, usize)> = None;
    for (l, p) in lines.iter().enumerate() {
        let n = p.len();
        let chords = if closed && n > 1 { n } else { n.saturating_sub(1) };
        for i in 0..chords {
            let d = segment_distance(p[i], p[(i + 1) % n], q, q).0;
            if best.is_none_or(|b| d < b.0) {
                best = Some((d, l, i));
            }
        }
    }
    best.map(|b| (b.1, b.2))
}

/// A segment of some loop: (loop index, segment index).
type Seg = (usize, usize);

/// The first pair of segments closer than `tol` that `skip` does not excuse, by a sweep
/// in `x`.
fn close_pair(lines: &[Polyline], tol: f64, skip: impl Fn(Seg, Seg) -> bool) -> Option<(Seg, Seg, Point)> {
    let seg = |(l, i): Seg| {
        let p = &lines[l].pts;
        (p[i], p[(i + 1) % p.len()])
    };
    let mut all: Vec<(f64, f64, Seg)> = Vec::new();
    for (l, line) in lines.iter().enumerate() {
        for i in 0..line.pts.len() {
            let (a, b) = seg((l, i));
            all.push((a[0].min(b[0]) - tol, a[0].max(b[0]) + tol, (l, i)));
        }
    }
    all.sort_by(|x, y| x.0.total_cmp(&y.0));
    for (k, &(_, hi, s)) in all.iter().enumerate() {
        let (a, b) = seg(s);
        let (ylo, yhi) = (a[1].min(b[1]) - tol, a[1].max(b[1]) + tol);
        for &(lo2, _, t) in &all[k + 1..] {
            if lo2 > hi {
                break;
            }
            let (c, d) = seg(t);
            if c[1].max(d[1]) < ylo || c[1].min(d[1]) > yhi || skip(s, t) {
                continue;
            }
            let (dd, at) = segment_distance(a, b, c, d);
            if dd <= tol {
                return Some((s, t, at));
            }
        }
    }
    None
}

/// Whether `p` lies inside the closed polyline `poly` (crossing number).
pub(crate) fn inside(poly: &[Point], p: Point) -> bool {
    let n = poly.len();
    let mut c = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x > p[0] {
                c = !c;
            }
        }
    }
    c
}

fn check_loop_sides(id: LoopId, l: &Loop, tol: f64) -> Result<()> {
    if l.sides.is_empty() {
        return Err(domain_error(id, None, "has no sides"));
    }
    for (k, s) in l.sides.iter().enumerate() {
        match s {
            SideCurve::Points(p) if p.len() < 2 => {
                return Err(domain_error(
                    id,
                    Some(k),
                    format!("is a point cloud of {} points, at least 2 needed", p.len()),
                ))
            }
            SideCurve::Points(p) if p.iter().any(|q| !q[0].is_finite() || !q[1].is_finite()) => {
                return Err(domain_error(id, Some(k), "has a non-finite point"))
            }
            _ => {}
        }
        let next = (k + 1) % l.sides.len();
        let (_, end) = s.endpoints();
        let (start, _) = l.sides[next].endpoints();
        let gap = dist(end, start);
        if gap.is_nan() || gap > tol {
            return Err(domain_error(
                id,
                Some(k),
                format!(
                    "ends at ({:.6}, {:.6}) but curve {next} begins at ({:.6}, {:.6}): the loop is not closed (gap {gap:.3e}, tolerance {tol:.3e})",
                    end[0], end[1], start[0], start[1]
                ),
            ));
        }
        let (a, b) = s.endpoints();
        if l.sides.len() > 1 && dist(a, b) <= tol && sample_side(s, f64::INFINITY).iter().all(|q| dist(*q, a) <= tol) {
            return Err(domain_error(id, Some(k), "has zero length"));
        }
    }
    Ok(())
}

/// Check `domain` (see the module documentation), orient its loops and report what was
/// measured. Errors are [`crate::Error::Domain`] naming the loop and curve.
pub fn validate_domain(domain: &mut Domain) -> Result<DomainReport> {
    let ids: Vec<LoopId> = domain.loops().map(|(id, _)| id).collect();
    // the tolerance is relative to the outer loop's extent
    let outer_pts: Vec<Point> = domain.outer.sides.iter().flat_map(|s| sample_side(s, f64::INFINITY)).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &outer_pts {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let diameter = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    if !(diameter.is_finite() && diameter > 0.0) {
        return Err(domain_error(LoopId::Outer, None, format!("has no extent (diameter {diameter})")));
    }
    let tol = CORNER_TOL * diameter;
    for &id in &ids {
        check_loop_sides(id, domain.loop_of(id), tol)?;
    }
    // crossings: two segments of one loop that are not neighbours, or of two loops
    let lines: Vec<Polyline> = ids.iter().map(|&id| polyline(domain.loop_of(id), FLATNESS * diameter)).collect();
    let n_of = |l: usize| lines[l].pts.len();
    let hit = close_pair(&lines, tol, |(l1, i1), (l2, i2)| {
        if l1 != l2 {
            return false;
        }
        let n = n_of(l1);
        i1 == i2 || (i1 + 1) % n == i2 || (i2 + 1) % n == i1
    });
    if let Some((s1, s2, at)) = hit {
        let ((l1, i1), (l2, i2)) = if s1.0 <= s2.0 { (s1, s2) } else { (s2, s1) };
        let (c1, c2) = (lines[l1].owner[i1], lines[l2].owner[i2]);
        let reason = if l1 == l2 {
            format!("crosses itself near ({:.6}, {:.6}): curve {c1} meets curve {c2}", at[0], at[1])
        } else {
            let what = if l1 == 0 { "the outer loop" } else { "another hole" };
            format!("touches or crosses {what} ({}, curve {c1}) near ({:.6}, {:.6})", ids[l1], at[0], at[1])
        };
        return Err(domain_error(ids[l1.max(l2)], Some(if l1 == l2 { c1.max(c2) } else { c2 }), reason));
    }
    let mut lines: Vec<Polyline> = ids.iter().map(|&id| polyline(domain.loop_of(id), FLATNESS * diameter)).collect();
    let mut reoriented = Vec::new();
    let mut area = 0.0;
    for (k, &id) in ids.iter().enumerate() {
        let a = shoelace(&lines[k].pts);
        if a.abs() <= tol * diameter {
            return Err(domain_error(id, None, format!("encloses no area (signed area {a:.3e})")));
        }
        let want_ccw = id == LoopId::Outer;
        if (a > 0.0) != want_ccw {
            let l = domain.loop_of(id).reversed();
            match id {
                LoopId::Outer => domain.outer = l,
                LoopId::Hole(h) => domain.holes[h] = l,
            }
            lines[k] = polyline(domain.loop_of(id), FLATNESS * diameter);
            reoriented.push(format!("{id} ran {}: reversed", if want_ccw { "clockwise" } else { "counter-clockwise" }));
        }
        area += a.abs() * if want_ccw { 1.0 } else { -1.0 };
    }
    // nesting: every hole inside the outer loop, no hole inside another
    for (k, &id) in ids.iter().enumerate().skip(1) {
        let p = lines[k].pts[0];
        if !inside(&lines[0].pts, p) {
            return Err(domain_error(id, None, "lies outside the outer loop"));
        }
        for (j, &other) in ids.iter().enumerate().skip(1) {
            if j != k && inside(&lines[j].pts, p) {
                return Err(domain_error(id, None, format!("lies inside {other}")));
            }
        }
    }
    if area <= tol * diameter {
        return Err(domain_error(LoopId::Outer, None, format!("the holes leave no area ({area:.3e})")));
    }
    Ok(DomainReport {
        outer_corners: domain.outer.corners(),
        hole_corners: domain.holes.iter().map(Loop::corners).collect(),
        area,
        diameter,
        reoriented,
        detected_corners: domain.loops().flat_map(|(_, l)| l.detected_corners.clone()).collect(),
    })
}

/// `Err` unless `e` is an [`Error::Domain`] whose place contains `at` (for tests).
#[cfg(test)]
pub(crate) fn names(e: &Error, at: &str) -> bool {
    matches!(e, Error::Domain { at: a, .. } if a.contains(at))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn poly(pts: &[Point]) -> Loop {
        let n = pts.len();
        Loop::new((0..n).map(|i| SideCurve::Points(vec![pts[i], pts[(i + 1) % n]])).collect())
    }

    fn domain(outer: &[Point], holes: &[&[Point]]) -> Domain {
        Domain { name: "t".into(), outer: poly(outer), holes: holes.iter().map(|h| poly(h)).collect() }
    }

    const SQUARE: [Point; 4] = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]];

    #[test]
    fn a_square_with_a_hole_is_valid_and_oriented() {
        let hole: &[Point] = &[[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]];
        let mut d = domain(&SQUARE, &[hole]);
        let r = validate_domain(&mut d).unwrap();
        assert_eq!(r.outer_corners, 4);
        assert!((r.area - 15.0).abs() < 1e-12, "{}", r.area);
        assert_eq!(r.reoriented, vec!["hole 0 ran counter-clockwise: reversed".to_string()]);
        // now clockwise: validating again changes nothing
        assert!(validate_domain(&mut d).unwrap().reoriented.is_empty());
    }

    #[test]
    fn every_bad_input_names_its_loop() {
        // not closed
        let mut d = domain(&SQUARE, &[]);
        d.outer.sides[2] = SideCurve::Points(vec![[4.0, 4.0], [0.0, 4.5]]);
        let e = validate_domain(&mut d).unwrap_err();
        assert!(names(&e, "outer loop, curve 2") && e.to_string().contains("not closed"), "{e}");
        // self-intersection (a bow tie)
        let mut d = domain(&[[0.0, 0.0], [4.0, 4.0], [4.0, 0.0], [0.0, 4.0]], &[]);
        let e = validate_domain(&mut d).unwrap_err();
        assert!(names(&e, "outer loop") && e.to_string().contains("crosses itself"), "{e}");
        // a hole crossing the outer loop
        let mut d = domain(&SQUARE, &[&[[3.0, 1.0], [5.0, 1.0], [5.0, 2.0], [3.0, 2.0]]]);
        let e = validate_domain(&mut d).unwrap_err();
        assert!(names(&e, "hole 0") && e.to_string().contains("outer loop"), "{e}");
        // a hole touching the outer loop at a point
        let mut d = domain(&SQUARE, &[&[[0.0, 2.0], [1.0, 1.0], [1.0, 3.0]]]);
        let e = validate_domain(&mut d).unwrap_err();
        assert!(names(&e, "hole 0") && e.to_string().contains("touches"), "{e}");
        // two holes crossing
        let a: &[Point] = &[[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]];
        let b: &[Point] = &[[1.5, 1.5], [3.0, 1.5], [3.0, 3.0], [1.5, 3.0]];
        let e = validate_domain(&mut domain(&SQUARE, &[a, b])).unwrap_err();
        assert!(names(&e, "hole 1") && e.to_string().contains("another hole"), "{e}");
        // a hole inside a hole, a hole outside
        let inner: &[Point] = &[[1.2, 1.2], [1.8, 1.2], [1.8, 1.8], [1.2, 1.8]];
        let e = validate_domain(&mut domain(&SQUARE, &[a, inner])).unwrap_err();
        assert!(names(&e, "hole 1") && e.to_string().contains("inside hole 0"), "{e}");
        let far: &[Point] = &[[11.0, 1.0], [12.0, 1.0], [12.0, 2.0]];
        let e = validate_domain(&mut domain(&SQUARE, &[far])).unwrap_err();
        assert!(names(&e, "hole 0") && e.to_string().contains("outside"), "{e}");
        // zero area
        let e = validate_domain(&mut domain(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], &[])).unwrap_err();
        assert!(names(&e, "outer loop") && e.to_string().contains("no area"), "{e}");
        // a one-point cloud
        let mut d = domain(&SQUARE, &[]);
        d.outer.sides[1] = SideCurve::Points(vec![[4.0, 0.0]]);
        assert!(names(&validate_domain(&mut d).unwrap_err(), "outer loop, curve 1"));
    }
}
