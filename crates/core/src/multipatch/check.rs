//! Validation of a multipatch layout: every patch a valid counter-clockwise four-sided
//! boundary, every interface joining two sides that are one curve (the same points at
//! the same parameters, up to the interface's reversal) with the two patches on
//! opposite sides of it, no two sides coinciding without an interface, and no two patch
//! boundaries crossing or one patch inside another. Every failure is an
//! [`Error::Layout`] naming the patch and side.

use std::collections::HashSet;

use serde::Serialize;

use super::layout::{Layout, PatchSide};
use crate::boundary::normalise::Similarity;
use crate::boundary::validate::{inspect, sample_side, segment_hit, Orientation, CORNER_NEIGHBOURHOOD, FLATNESS};
use crate::boundary::{Boundary, SideCurve};
use crate::error::{Error, Result};
use crate::spline::curve::{Curve, Point};
use crate::spline::surface::Side;

/// Two interface sides must agree at equal parameters to this times the layout's
/// diameter (the corner tolerance of `formats.md`).
pub(crate) const SHARED_TOL: f64 = 1e-9;

/// What [`validate_layout`] measured.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct LayoutReport {
    /// Number of patches.
    pub patches: usize,
    /// Number of interfaces.
    pub interfaces: usize,
    /// Number of patch sides on the outer boundary.
    pub outer_sides: usize,
    /// Diameter of the layout's bounding box.
    pub diameter: f64,
    /// Largest distance between the two sides of an interface at equal parameters.
    pub interface_gap: f64,
    /// Area of each patch (signed, positive: counter-clockwise).
    pub areas: Vec<f64>,
    /// Total area.
    pub area: f64,
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Largest distance between `a(t)` and `b(t)` (`b(1 - t)` when `reversed`) at 8 points
/// per knot span of either curve.
pub(crate) fn parametric_gap(a: &Curve, b: &Curve, reversed: bool) -> f64 {
    let mut ts: Vec<f64> = Vec::new();
    for c in [a, b] {
        for (_, u0, u1) in c.knots.elements() {
            for k in 0..8 {
                let t = u0 + (u1 - u0) * k as f64 / 8.0;
                ts.push(if std::ptr::eq(c, b) && reversed { 1.0 - t } else { t });
            }
        }
    }
    ts.push(1.0);
    ts.iter().map(|&t| dist(a.eval(t), b.eval(if reversed { 1.0 - t } else { t }))).fold(0.0, f64::max)
}

/// Smallest distance from `p` to the polyline `poly`.
fn to_polyline(p: Point, poly: &[Point]) -> f64 {
    poly.windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let ab = [b[0] - a[0], b[1] - a[1]];
            let len2 = ab[0] * ab[0] + ab[1] * ab[1];
            let t =
                if len2 > 0.0 { (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / len2).clamp(0.0, 1.0) } else { 0.0 };
            dist(p, [a[0] + t * ab[0], a[1] + t * ab[1]])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether `p` is inside the closed polygon `poly` (crossing number).
fn inside(p: Point, poly: &[Point]) -> bool {
    let mut c = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if p[0] < x {
                c = !c;
            }
        }
    }
    c
}

/// A polyline's bounding box.
fn bbox(poly: &[Point]) -> (Point, Point) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in poly {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (lo, hi)
}

/// Validate `layout` (see the module documentation).
///
/// The checks run in the normalised coordinates of the layout's bounding box
/// (`Similarity`, as a four-sided boundary's and a ring's), so that a layout translated
/// far from the origin or scaled to an extreme size gets the verdicts it gets where it
/// is: far out, a NURBS side evaluated in raw coordinates is rounded to the position's
/// precision and two sides of one interface seem to differ. The report is in the
/// input's coordinates; the lengths of an error message in the normalised ones, which
/// it then says.
pub fn validate_layout(layout: &Layout) -> Result<LayoutReport> {
    let (lo, hi) = layout.bounding_box();
    let sim = Similarity::for_box(lo, hi, &format!("layout '{}'", layout.name))?;
    if sim.is_identity() {
        return validate_normalised(layout);
    }
    let mut r = validate_normalised(&layout.similar(&sim)).map_err(|e| match e {
        Error::Layout { patch, side, reason } => Error::Layout {
            patch,
            side,
            reason: format!(
                "{reason} (lengths in the normalised coordinates (x - c) / s, c = ({:e}, {:e}), s = {:e})",
                sim.centre[0], sim.centre[1], sim.scale
            ),
        },
        e => e,
    })?;
    r.diameter = layout.diameter();
    r.interface_gap = sim.length(r.interface_gap);
    for a in r.areas.iter_mut() {
        *a = sim.area(*a);
    }
    r.area = sim.area(r.area);
    Ok(r)
}

/// [`validate_layout`] in the coordinates given.
fn validate_normalised(layout: &Layout) -> Result<LayoutReport> {
    let n = layout.patches.len();
    if n == 0 {
        return Err(crate::error::Error::Layout {
            patch: "-".into(),
            side: String::new(),
            reason: "the layout has no patches".into(),
        });
    }
    let mut names = HashSet::new();
    for (p, patch) in layout.patches.iter().enumerate() {
        if !patch.name.is_empty() && !names.insert(patch.name.as_str()) {
            return Err(layout.error(p, None, format!("the name {:?} is used by another patch", patch.name)));
        }
    }
    let diameter = layout.diameter();
    if !(diameter.is_finite() && diameter > 0.0) {
        return Err(layout.error(0, None, format!("the layout's diameter is {diameter}")));
    }
    let tol = SHARED_TOL * diameter;
    // every patch on its own: a valid counter-clockwise four-sided boundary
    let mut areas = Vec::with_capacity(n);
    for (p, patch) in layout.patches.iter().enumerate() {
        let b = Boundary { name: patch.name.clone(), sides: patch.sides.clone().map(SideCurve::Spline) };
        let r = inspect(&b).map_err(|e| layout.error(p, None, e.to_string()))?;
        if r.orientation != Orientation::CounterClockwise {
            return Err(layout.error(
                p,
                None,
                format!(
                    "runs clockwise (signed area {:.6e}): every patch must be counter-clockwise (south, east, reversed north, reversed west)",
                    r.signed_area
                ),
            ));
        }
        areas.push(r.signed_area);
    }
    let interface_gap = check_interfaces(layout, tol)?;
    let polys: Vec<[Vec<Point>; 4]> = layout
        .patches
        .iter()
        .map(|p| p.sides.clone().map(|c| sample_side(&SideCurve::Spline(c), FLATNESS * diameter)))
        .collect();
    check_complete(layout, &polys, diameter)?;
    check_crossings(layout, &polys, diameter)?;
    Ok(LayoutReport {
        patches: n,
        interfaces: layout.interfaces.len(),
        outer_sides: layout.outer_sides().len(),
        diameter,
        interface_gap,
        area: areas.iter().sum(),
        areas,
    })
}

/// Each side in at most one interface; the two sides of an interface one curve, with
/// the patches on opposite sides of it. Returns the largest gap at equal parameters.
fn check_interfaces(layout: &Layout, tol: f64) -> Result<f64> {
    let n = layout.patches.len();
    let mut seen: HashSet<PatchSide> = HashSet::new();
    let mut worst = 0.0f64;
    for (k, i) in layout.interfaces.iter().enumerate() {
        for ps in [i.first, i.second] {
            if ps.patch >= n {
                return Err(crate::error::Error::Layout {
                    patch: ps.patch.to_string(),
                    side: ps.side.name().into(),
                    reason: format!("interface {k} names patch {}, but the layout has {n} patches", ps.patch),
                });
            }
            if !seen.insert(ps) {
                return Err(layout.error(ps.patch, Some(ps.side), "is in more than one interface"));
            }
        }
        if i.first.patch == i.second.patch {
            return Err(layout.error(
                i.first.patch,
                Some(i.first.side),
                format!(
                    "an interface with the {} side of the same patch (periodic patches are rings, not layouts)",
                    i.second.side
                ),
            ));
        }
        let a = layout.patches[i.first.patch].side(i.first.side);
        let b = layout.patches[i.second.patch].side(i.second.side);
        let (a0, a1) = a.endpoints();
        let (b0, b1) = b.endpoints();
        let (s0, s1) = if i.reversed { (b1, b0) } else { (b0, b1) };
        let here = |why: String| layout.error(i.first.patch, Some(i.first.side), why);
        let with = format!("the {} side of patch {}", i.second.side, layout.label(i.second.patch));
        if dist(a0, s0) > tol || dist(a1, s1) > tol {
            let (f0, f1) = if i.reversed { (b0, b1) } else { (b1, b0) };
            return Err(here(if dist(a0, f0) <= tol && dist(a1, f1) <= tol {
                format!(
                    "the interface with {with} says reversed = {}, but the two run {} (orientations inconsistent)",
                    i.reversed,
                    if i.reversed { "the same way" } else { "against each other" }
                )
            } else {
                format!(
                    "does not end where {with} ends: end points ({:.9}, {:.9})-({:.9}, {:.9}) against ({:.9}, {:.9})-({:.9}, {:.9})",
                    a0[0], a0[1], a1[0], a1[1], s0[0], s0[1], s1[0], s1[1]
                )
            }));
        }
        let gap = parametric_gap(a, b, i.reversed);
        if gap.is_nan() || gap > tol {
            return Err(here(format!(
                "is not the same curve as {with} at equal parameters: they differ by up to {gap:.3e} (tolerance {tol:.3e}); conforming patches need one parameterization of their shared side"
            )));
        }
        worst = worst.max(gap);
        // a counter-clockwise patch runs along south and east forwards, along north and
        // west backwards; two patches on opposite sides of one curve run along it in
        // opposite directions
        let forward = |s: Side| matches!(s, Side::South | Side::East);
        let same = forward(i.first.side) == (forward(i.second.side) != i.reversed);
        if same {
            return Err(here(format!(
                "and {with} put both patches on the same side of their shared curve (orientations inconsistent: the patches overlap)"
            )));
        }
    }
    Ok(worst)
}

/// No two sides coincide without an interface joining them.
fn check_complete(layout: &Layout, polys: &[[Vec<Point>; 4]], diameter: f64) -> Result<()> {
    let tol = SHARED_TOL * diameter;
    let near = 4.0 * FLATNESS * diameter;
    let sides: Vec<PatchSide> =
        (0..layout.patches.len()).flat_map(|p| Side::ALL.map(|side| PatchSide { patch: p, side })).collect();
    for (x, &a) in sides.iter().enumerate() {
        for &b in &sides[x + 1..] {
            if layout.across(a).is_some_and(|(_, o)| o == b) {
                continue;
            }
            let ca = layout.patches[a.patch].side(a.side);
            let cb = layout.patches[b.patch].side(b.side);
            let (a0, a1) = ca.endpoints();
            let (b0, b1) = cb.endpoints();
            let ends = (dist(a0, b0) <= tol && dist(a1, b1) <= tol) || (dist(a0, b1) <= tol && dist(a1, b0) <= tol);
            if !ends {
                continue;
            }
            let pa = &polys[a.patch][a.side as usize];
            let pb = &polys[b.patch][b.side as usize];
            if to_polyline(pa[pa.len() / 2], pb) <= near && to_polyline(pb[pb.len() / 2], pa) <= near {
                return Err(layout.error(
                    a.patch,
                    Some(a.side),
                    format!(
                        "coincides with the {} side of patch {}, but no interface joins them (interfaces incomplete)",
                        b.side,
                        layout.label(b.patch)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// No two patch boundaries cross (away from the corners they share) and no patch lies
/// inside another. Candidate pairs of segments come from a uniform grid over all sides'
/// segments (about as many cells as segments), so the cost is about linear.
fn check_crossings(layout: &Layout, polys: &[[Vec<Point>; 4]], diameter: f64) -> Result<()> {
    let radius = CORNER_NEIGHBOURHOOD * diameter;
    let n = layout.patches.len();
    let corners: Vec<[Point; 4]> = layout.patches.iter().map(|p| p.corners()).collect();
    // every segment: (patch, side, start, end)
    let segs: Vec<(usize, Side, Point, Point)> = (0..n)
        .flat_map(|p| Side::ALL.into_iter().map(move |s| (p, s)))
        .flat_map(|(p, s)| polys[p][s as usize].windows(2).map(move |w| (p, s, w[0], w[1])))
        .collect();
    let all: Vec<Point> = segs.iter().flat_map(|s| [s.2, s.3]).collect();
    let (lo, hi) = bbox(&all);
    let cells = segs.len().clamp(1, 1 << 22) as f64;
    let (w, h) = ((hi[0] - lo[0]).max(f64::MIN_POSITIVE), (hi[1] - lo[1]).max(f64::MIN_POSITIVE));
    let gx = ((cells * w / h).sqrt().ceil()).clamp(1.0, cells) as usize;
    let gy = ((cells / gx as f64).ceil()).clamp(1.0, cells) as usize;
    let (cw, ch) = (w / gx as f64, h / gy as f64);
    let cell = |x: f64, y: f64| {
        let i = (((x - lo[0]) / cw).floor().max(0.0) as usize).min(gx - 1);
        let j = (((y - lo[1]) / ch).floor().max(0.0) as usize).min(gy - 1);
        (i, j)
    };
    let mut entries: Vec<(usize, u32)> = Vec::with_capacity(2 * segs.len());
    for (k, &(_, _, a, b)) in segs.iter().enumerate() {
        let (i0, j0) = cell(a[0].min(b[0]) - radius, a[1].min(b[1]) - radius);
        let (i1, j1) = cell(a[0].max(b[0]) + radius, a[1].max(b[1]) + radius);
        for j in j0..=j1 {
            for i in i0..=i1 {
                entries.push((j * gx + i, k as u32));
            }
        }
    }
    entries.sort_unstable();
    let mut start = 0;
    while start < entries.len() {
        let mut end = start;
        while end < entries.len() && entries[end].0 == entries[start].0 {
            end += 1;
        }
        let group = &entries[start..end];
        for (x, &(_, k)) in group.iter().enumerate() {
            for &(_, l) in &group[x + 1..] {
                let (u, v) = (segs[k as usize], segs[l as usize]);
                if u.0 == v.0 {
                    continue;
                }
                let (a, b) = (PatchSide { patch: u.0, side: u.1 }, PatchSide { patch: v.0, side: v.1 });
                if layout.across(a).is_some_and(|(_, o)| o == b) {
                    continue;
                }
                if let Some(x) = segment_hit(u.2, u.3, v.2, v.3) {
                    let near = corners[u.0].iter().chain(&corners[v.0]).any(|&c| dist(x, c) <= radius);
                    if !near {
                        let (p, q) = if u.0 < v.0 { (u, v) } else { (v, u) };
                        return Err(layout.error(
                            p.0,
                            Some(p.1),
                            format!(
                                "meets the {} side of patch {} at ({:.6}, {:.6}), away from their corners: patches meet along whole sides (interfaces) or at corners, their boundaries do not cross",
                                q.1,
                                layout.label(q.0),
                                x[0],
                                x[1]
                            ),
                        ));
                    }
                }
            }
        }
        start = end;
    }
    // one patch inside another: a corner strictly inside another patch
    let closed: Vec<Vec<Point>> = polys
        .iter()
        .map(|ps| {
            let [s, e, nn, w] = ps;
            let mut v: Vec<Point> = s.clone();
            v.extend(e.iter().skip(1));
            v.extend(nn.iter().rev().skip(1));
            v.extend(w.iter().rev().skip(1));
            v
        })
        .collect();
    for p in 0..n {
        for q in 0..n {
            if p == q {
                continue;
            }
            for c in corners[q] {
                if inside(c, &closed[p]) && to_polyline(c, &closed[p]) > radius {
                    return Err(layout.error(
                        q,
                        None,
                        format!(
                            "its corner ({:.6}, {:.6}) lies inside patch {}: patches overlap",
                            c[0],
                            c[1],
                            layout.label(p)
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::multipatch::layout::{Interface, Patch};
    use crate::spline::knots::KnotVector;

    fn line(a: Point, b: Point) -> Curve {
        Curve::new(KnotVector::open_uniform(1, 1), vec![a, b], None).unwrap()
    }

    fn rect(name: &str, x0: f64, x1: f64, y0: f64, y1: f64) -> Patch {
        Patch::from_sides(
            name,
            [line([x0, y0], [x1, y0]), line([x1, y0], [x1, y1]), line([x0, y1], [x1, y1]), line([x0, y0], [x0, y1])],
        )
    }

    fn iface(a: usize, sa: Side, b: usize, sb: Side, reversed: bool) -> Interface {
        Interface { first: PatchSide { patch: a, side: sa }, second: PatchSide { patch: b, side: sb }, reversed }
    }

    fn pair() -> Layout {
        Layout {
            name: "pair".into(),
            patches: vec![rect("a", 0.0, 1.0, 0.0, 1.0), rect("b", 1.0, 2.0, 0.0, 1.0)],
            interfaces: vec![iface(0, Side::East, 1, Side::West, false)],
        }
    }

    #[test]
    fn a_valid_pair_passes() {
        let r = validate_layout(&pair()).unwrap();
        assert_eq!((r.patches, r.interfaces, r.outer_sides), (2, 1, 6));
        assert!((r.area - 2.0).abs() < 1e-12 && r.interface_gap == 0.0);
    }

    #[test]
    fn errors_name_patch_and_side() {
        // wrong reversal
        let mut l = pair();
        l.interfaces[0].reversed = true;
        let e = validate_layout(&l).unwrap_err().to_string();
        assert!(e.contains("patch 0 (a), east side") && e.contains("orientations inconsistent"), "{e}");
        // interface missing
        let mut l = pair();
        l.interfaces.clear();
        let e = validate_layout(&l).unwrap_err().to_string();
        assert!(e.contains("patch 0 (a), east side") && e.contains("no interface joins them"), "{e}");
        // both patches on the same side of the curve
        let mut l = pair();
        l.patches[1] = rect("b", 0.5, 1.0, 0.0, 1.0);
        l.interfaces = vec![iface(0, Side::East, 1, Side::East, false)];
        let e = validate_layout(&l).unwrap_err().to_string();
        assert!(e.contains("same side"), "{e}");
        // clockwise patch
        let mut l = pair();
        let p = &mut l.patches[1];
        p.sides = [p.sides[3].clone(), p.sides[2].clone(), p.sides[1].clone(), p.sides[0].clone()];
        let e = validate_layout(&l).unwrap_err().to_string();
        assert!(e.contains("patch 1 (b)") && e.contains("clockwise"), "{e}");
        // crossing boundaries
        let mut l = pair();
        l.patches[1] = rect("b", 0.5, 2.0, 0.25, 0.75);
        l.interfaces.clear();
        let e = validate_layout(&l).unwrap_err().to_string();
        assert!(e.contains("away from their corners"), "{e}");
        // a patch inside another
        let mut l = pair();
        l.patches[1] = rect("b", 0.25, 0.75, 0.25, 0.75);
        l.interfaces.clear();
        let e = validate_layout(&l).unwrap_err().to_string();
        assert!(e.contains("patch 1 (b)") && e.contains("inside patch 0"), "{e}");
        // the same side twice
        let mut l = pair();
        l.interfaces.push(iface(1, Side::West, 0, Side::East, false));
        let e = validate_layout(&l).unwrap_err().to_string();
        assert!(e.contains("more than one interface"), "{e}");
        // different curves
        let mut l = pair();
        let c = &mut l.patches[1].sides[Side::West as usize];
        *c = Curve::new(KnotVector::open_uniform(2, 1), vec![[1.0, 0.0], [1.2, 0.5], [1.0, 1.0]], None).unwrap();
        let e = validate_layout(&l).unwrap_err().to_string();
        assert!(e.contains("not the same curve"), "{e}");
    }
}
