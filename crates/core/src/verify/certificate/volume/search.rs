//! The search on one element of a volume: prove `det J > 0` box by box, or find a fold
//! witness, as for maps of the plane ([`super::super::search`]) but without excused
//! corners (a lofted volume has no forced corner edges when its slices are certified).
//!
//! A box with coefficients `ĉ` known to `e` is *proven* when `min ĉ - e > 0`. A fold
//! needs a witness: one of the eight box corners (their coefficients are the values
//! there) or a dyadic point near the smallest coefficient, whose value is `< -e'`; it is
//! re-evaluated from the element's coefficients at the reported (rounded) parameter
//! point with the error of the local coordinates bounded, and reported only when still
//! `< -(its bound)`. Otherwise the box is bisected in all three directions, and when the
//! budget (depth, boxes) is spent the element is undecided.

use super::element::{DetJ3, Element3};
use super::tensor::{eval, eval_error, scratch_len, split8, Deg3};
use super::{VolumeFold, VolumeUndecided};
use crate::verify::certificate::CertifyOptions;

/// A sub-box: coefficients, local ranges per direction, depth, error bound.
struct Box3 {
    c: Vec<f64>,
    s: [[f64; 2]; 3],
    depth: usize,
    err: f64,
}

/// Outcome of one element.
#[derive(Debug, Clone)]
pub(super) struct ElementResult3 {
    pub fold: Option<VolumeFold>,
    pub undecided: Option<VolumeUndecided>,
    /// Proven lower bound of `det J` over the proven boxes (`+inf` if none).
    pub lower: f64,
    /// Smallest `det J` at box corners (polynomial maps; `+inf` otherwise).
    pub min_value: f64,
    /// Integral of `det J` over the element (polynomial maps).
    pub integral: f64,
    pub boxes: usize,
    pub depth: usize,
}

struct Ctx<'a, 'b> {
    dj: &'a DetJ3<'b>,
    e: [usize; 3],
    bounds: [[f64; 2]; 3],
    el: &'a Element3,
}

impl Ctx<'_, '_> {
    /// `det J` from a numerator value at local coordinates `s`.
    fn to_det(&self, v: f64, s: [[f64; 2]; 3], tmp: &mut [f64]) -> f64 {
        let [p, q, r] = self.dj.vol.degrees();
        let w = self.el.wnet.as_ref().map_or(1.0, |wn| eval(wn, Deg3([p, q, r]), s, tmp));
        self.el.factor * v / (w * w * w * w)
    }

    /// Re-evaluate a witness at the local dyadic point `ls` from the element's
    /// coefficients at the rounded parameter point; `Some` when `det J < 0` is proven.
    fn confirm(&self, ls: [f64; 3], tmp: &mut [f64]) -> Option<VolumeFold> {
        let mut param = [0.0; 3];
        let mut s = [[0.0; 2]; 3];
        for d in 0..3 {
            let [a, b] = self.bounds[d];
            (param[d], s[d]) = if ls[d] == 0.0 {
                (a, [1.0, 0.0])
            } else if ls[d] == 1.0 {
                (b, [0.0, 1.0])
            } else {
                let u = (a + ls[d] * (b - a)).clamp(a, b);
                let h = b - a;
                (u, [(b - u) / h, (u - a) / h])
            };
        }
        let deg = self.dj.deg;
        let val = eval(&self.el.c, deg, s, tmp);
        let bound = eval_error(&self.el.c, deg, self.el.err, 3);
        if val >= -bound {
            return None;
        }
        let mut sides = Vec::new();
        for (dir, name) in ["xi", "eta", "zeta"].into_iter().enumerate() {
            for (end, at_end) in [(0, ls[dir] == 0.0), (1, ls[dir] == 1.0)] {
                if at_end && self.dj.c0_plane(dir, self.e[dir], end) {
                    let (knot, rel) = if end == 0 { (self.bounds[dir][0], ">") } else { (self.bounds[dir][1], "<") };
                    sides.push(format!(
                        "one-sided limit from {name} {rel} {knot} (the map is only C0 across {name} = {knot})"
                    ));
                }
            }
        }
        Some(VolumeFold {
            element: self.e,
            param,
            value: self.to_det(val, s, tmp),
            error_bound: self.to_det(bound, s, tmp),
            one_sided: (!sides.is_empty()).then(|| sides.join("; ")),
        })
    }
}

/// Examine element `e`.
pub(super) fn examine(dj: &DetJ3<'_>, e: [usize; 3], opts: &CertifyOptions) -> ElementResult3 {
    let d = dj.deg;
    let [du, dv, dw] = d.0;
    let el = dj.coefficients(e);
    let bounds = dj.bounds(e);
    let ctx = Ctx { dj, e, bounds, el: &el };
    let mut tmp = vec![0.0; scratch_len(d) + 8];
    let mut stack = vec![Box3 { c: el.c.clone(), s: [[0.0, 1.0]; 3], depth: 0, err: el.err }];
    let (mut lower, mut min_value) = (f64::INFINITY, f64::INFINITY);
    let (mut boxes, mut depth) = (0usize, 0usize);
    let mut open: Option<(&'static str, f64, f64)> = None;
    let mut fold: Option<VolumeFold> = None;
    let corners: Vec<([f64; 3], usize)> = (0..8)
        .map(|b: usize| {
            let bit = |k: usize| (b >> k) & 1;
            ([bit(0) as f64, bit(1) as f64, bit(2) as f64], d.at(bit(0) * du, bit(1) * dv, bit(2) * dw))
        })
        .collect();
    while let Some(b) = stack.pop() {
        boxes += 1;
        depth = depth.max(b.depth);
        let (kmin, cmin) =
            b.c.iter().enumerate().fold((0, f64::INFINITY), |m, (k, &v)| if v < m.1 { (k, v) } else { m });
        if cmin - b.err > 0.0 {
            lower = lower.min(cmin - b.err);
            continue;
        }
        // witnesses: the box corners (values known to b.err) and a dyadic point near the
        // smallest coefficient's Greville point
        let idx = [kmin % (du + 1), (kmin / (du + 1)) % (dv + 1), kmin / ((du + 1) * (dv + 1))];
        let dyadic = |k: usize, n: usize| if n > 0 { (16.0 * k as f64 / n as f64).round() / 16.0 } else { 0.5 };
        let g = [dyadic(idx[0], du), dyadic(idx[1], dv), dyadic(idx[2], dw)];
        let gval = eval(&b.c, d, g.map(|x| [1.0 - x, x]), &mut tmp);
        let gerr = eval_error(&b.c, d, b.err, 0);
        let mut cands: Vec<([f64; 3], f64, f64)> = corners.iter().map(|&(s, k)| (s, b.c[k], b.err)).collect();
        for c in &cands {
            min_value = min_value.min(c.1);
        }
        cands.push((g, gval, gerr));
        for (s, v, err) in cands {
            if v < -err {
                let ls = std::array::from_fn(|k| b.s[k][0] + s[k] * (b.s[k][1] - b.s[k][0]));
                if let Some(f) = ctx.confirm(ls, &mut tmp) {
                    if fold.as_ref().is_none_or(|x| f.value < x.value) {
                        fold = Some(f);
                    }
                }
            }
        }
        if fold.is_some() {
            break;
        }
        let spent = boxes + stack.len() + 8 > opts.max_boxes;
        if b.depth >= opts.max_depth || spent {
            if open.is_none() {
                open = Some((if spent { "box-budget" } else { "max-depth" }, b.err, cmin));
            }
            continue;
        }
        let (kids, err) = split8(&b.c, d, b.err, &mut tmp);
        for (i, c) in kids.into_iter().enumerate() {
            let s = std::array::from_fn(|k| {
                let [lo, hi] = b.s[k];
                let mid = 0.5 * (lo + hi);
                if (i >> k) & 1 == 0 {
                    [lo, mid]
                } else {
                    [mid, hi]
                }
            });
            stack.push(Box3 { c, s, depth: b.depth + 1, err });
        }
    }
    let w4 = el.wmax.powi(4);
    let to_det_bound = |v: f64| el.factor * v / w4;
    let rational = el.wnet.is_some();
    let undecided = if fold.is_none() {
        open.map(|(reason, err, cmin)| VolumeUndecided {
            element: e,
            reason,
            depth,
            boxes,
            smallest_coefficient: to_det_bound(cmin),
            error_bound: to_det_bound(err),
        })
    } else {
        None
    };
    let vol = (0..3).map(|k| bounds[k][1] - bounds[k][0]).product::<f64>();
    ElementResult3 {
        fold,
        undecided,
        lower: if lower.is_finite() { to_det_bound(lower) * (1.0 - 1e-12) } else { f64::INFINITY },
        min_value: if rational { f64::INFINITY } else { el.factor * min_value },
        integral: if rational { 0.0 } else { el.c.iter().sum::<f64>() / el.c.len() as f64 * el.factor * vol },
        boxes,
        depth,
    }
}
