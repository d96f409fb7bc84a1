//! The search on one element: prove `det J > 0` box by box, find a fold witness, or
//! shrink the neighbourhood of a forced corner.
//!
//! A box with coefficients `ĉ` known to `e` is *proven* when `min ĉ - e > 0`. A fold
//! needs a witness: a box corner (its coefficient is the value there) or a dyadic point
//! near the smallest coefficient whose value is `< -e'`; the witness is then re-evaluated
//! from the element's coefficients at the reported (rounded) parameter point, with the
//! error of the local coordinates `(u - a) / (b - a)` bounded, and only reported when it
//! is still `< -(its bound)`. Otherwise the box is bisected (de Casteljau), and when the
//! budget is spent the element is undecided.
//!
//! At a *forced* corner (its `det J` coefficient, exact up to `e`, is not provably
//! positive: an angle of 180 degrees or more, or a vanishing tangent) the box touching
//! the corner is bisected; its three other children must be proven positive, and the
//! search descends into the corner child, until the depth limit: the corner box left is
//! the excused neighbourhood, whose size is reported. When a sibling cannot be proven,
//! the current corner box is the neighbourhood, unless the sibling holds a fold witness
//! and the corner's `det J` is not provably negative (a straight corner, where no
//! negative value is forced): then it is a fold.

use super::bernstein::{self as bz, amax, Deg};
use super::element::{DetJElements, ElementScale, Work};
use super::{CertifyOptions, FoldInfo, UndecidedInfo};

/// A sub-box of an element: coefficients, local ranges, depth, error bound.
pub(super) struct SubBox {
    c: Vec<f64>,
    su: [f64; 2],
    sv: [f64; 2],
    depth: usize,
    err: f64,
}

/// Local corners `(s, t)` of an element, numbered like the domain corners.
const LOCAL: [(f64, f64); 4] = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];

/// Outcome of one element.
#[derive(Debug, Clone)]
pub(super) struct ElementResult {
    pub fold: Option<FoldInfo>,
    pub undecided: Option<UndecidedInfo>,
    /// Lower bound of `det J` over the proven boxes (`+inf` if none).
    pub lower: f64,
    /// Smallest value of `det J` met at box corners (polynomial maps; `+inf` otherwise).
    pub min_value: f64,
    /// Integral of `det J` over the element (polynomial maps).
    pub integral: f64,
    pub boxes: usize,
    pub depth: usize,
    /// Domain corners (bits) at this element where `det J > 0` is not provable.
    pub forced: u8,
    /// Parameter extent of the excused neighbourhood per domain corner (0..4) and per
    /// zero-speed boundary point at local corner `k - 4` of the element (4..8).
    pub excused: [Option<[f64; 2]>; 8],
}

/// State of a search (a tentative one for the siblings of a corner box).
struct Search {
    fold: Option<FoldInfo>,
    /// (reason, box error, smallest corner value) of the first box left open.
    open: Option<(&'static str, f64, f64)>,
    lower: f64,
    min_value: f64,
    boxes: usize,
    depth: usize,
    excused: [Option<[f64; 2]>; 8],
}

impl Search {
    fn new(boxes: usize) -> Self {
        Self {
            fold: None,
            open: None,
            lower: f64::INFINITY,
            min_value: f64::INFINITY,
            boxes,
            depth: 0,
            excused: [None; 8],
        }
    }
}

struct Ctx<'a, 'b> {
    dj: &'a DetJElements<'b>,
    opts: &'a CertifyOptions,
    e: [usize; 2],
    bu: [f64; 2],
    bv: [f64; 2],
    c0: &'a [f64],
    sc: ElementScale,
    /// Weight net (rational maps).
    wnet: Option<Vec<f64>>,
    /// Domain corner forced at each local corner.
    forced: [Option<usize>; 4],
    /// Whether `det J < 0` is proven at that local corner.
    negative: [bool; 4],
}

impl Ctx<'_, '_> {
    fn deg(&self) -> Deg {
        self.dj.deg
    }

    /// `det J` from a numerator value at local `(s, t)` (weights' value there).
    fn to_det(&self, v: f64, s: [f64; 2], t: [f64; 2], tmp: &mut [f64]) -> f64 {
        let [p, q] = self.dj.map.degrees();
        let wv = self.wnet.as_ref().map_or(1.0, |wn| bz::eval(wn, Deg([p, q]), s, t, tmp));
        self.sc.factor * v / (wv * wv * wv)
    }

    /// Which forced corner a box touches, if any.
    fn touches(&self, b: &SubBox) -> Option<usize> {
        (0..4).find(|&k| {
            let (s, t) = LOCAL[k];
            self.forced[k].is_some()
                && (if s == 0.0 { b.su[0] == 0.0 } else { b.su[1] == 1.0 })
                && (if t == 0.0 { b.sv[0] == 0.0 } else { b.sv[1] == 1.0 })
        })
    }

    /// Re-evaluate a witness at local dyadic `(ls, lt)` from the element's coefficients
    /// at the rounded parameter point; `Some` when `det J < 0` there is proven.
    fn confirm(&self, ls: f64, lt: f64, tmp: &mut [f64]) -> Option<FoldInfo> {
        let at = |x: f64, r: [f64; 2]| -> (f64, [f64; 2]) {
            if x == 0.0 {
                (r[0], [1.0, 0.0])
            } else if x == 1.0 {
                (r[1], [0.0, 1.0])
            } else {
                let u = r[0] + x * (r[1] - r[0]);
                let u = u.clamp(r[0], r[1]);
                let h = r[1] - r[0];
                (u, [(r[1] - u) / h, (u - r[0]) / h])
            }
        };
        let (u, s) = at(ls, self.bu);
        let (v, t) = at(lt, self.bv);
        let val = bz::eval(self.c0, self.deg(), s, t, tmp);
        let bound = bz::eval_error(self.c0, self.deg(), self.sc.err, 3);
        if val >= -bound {
            return None;
        }
        let mut sides = Vec::new();
        for (dir, x, r, name) in [(0, ls, self.bu, "xi"), (1, lt, self.bv, "eta")] {
            for (end, at_end) in [(0, x == 0.0), (1, x == 1.0)] {
                if at_end && self.dj.c0_line(dir, self.e[dir], end) {
                    let (knot, rel) = if end == 0 { (r[0], ">") } else { (r[1], "<") };
                    sides.push(format!(
                        "one-sided limit from {name} {rel} {knot} (the map is only C0 across {name} = {knot})"
                    ));
                }
            }
        }
        Some(FoldInfo {
            element: self.e,
            param: [u, v],
            value: self.to_det(val, s, t, tmp),
            error_bound: self.to_det(bound, s, t, tmp),
            one_sided: (!sides.is_empty()).then(|| sides.join("; ")),
        })
    }
}

fn split4(b: &SubBox, d: Deg, tmp: &mut [f64]) -> [SubBox; 4] {
    let n = d.len();
    let err = bz::split_error(&b.c, d, b.err);
    let mut halves = vec![0.0; 2 * n];
    let (l, r) = halves.split_at_mut(n);
    bz::split_u(&b.c, d, l, r, tmp);
    let mu = 0.5 * (b.su[0] + b.su[1]);
    let mv = 0.5 * (b.sv[0] + b.sv[1]);
    let (mut ll, mut lh) = (vec![0.0; n], vec![0.0; n]);
    bz::split_v(l, d, &mut ll, &mut lh, tmp);
    let (mut rl, mut rh) = (vec![0.0; n], vec![0.0; n]);
    bz::split_v(r, d, &mut rl, &mut rh, tmp);
    let depth = b.depth + 1;
    [
        SubBox { c: ll, su: [b.su[0], mu], sv: [b.sv[0], mv], depth, err },
        SubBox { c: rl, su: [mu, b.su[1]], sv: [b.sv[0], mv], depth, err },
        SubBox { c: rh, su: [mu, b.su[1]], sv: [mv, b.sv[1]], depth, err },
        SubBox { c: lh, su: [b.su[0], mu], sv: [mv, b.sv[1]], depth, err },
    ]
}

/// Prove, refute or leave open the boxes of `stack`.
fn run(ctx: &Ctx<'_, '_>, w: &mut Work, mut stack: Vec<SubBox>, st: &mut Search) {
    let d = ctx.deg();
    let [du, dv] = d.0;
    let wd = du + 1;
    while let Some(b) = stack.pop() {
        if let Some(k) = ctx.touches(&b) {
            corner(ctx, w, b, k, st);
            if st.fold.is_some() {
                return;
            }
            continue;
        }
        st.boxes += 1;
        st.depth = st.depth.max(b.depth);
        let (mut kmin, mut cmin) = (0, f64::INFINITY);
        for (k, &v) in b.c.iter().enumerate() {
            if v < cmin {
                cmin = v;
                kmin = k;
            }
        }
        if cmin - b.err > 0.0 {
            st.lower = st.lower.min(cmin - b.err);
            continue;
        }
        // witnesses: the box corners (values known to b.err) and a dyadic point near the
        // smallest coefficient's Greville point
        let (kk, ll) = (kmin % wd, kmin / wd);
        let dyadic = |k: usize, n: usize| if n > 0 { (16.0 * k as f64 / n as f64).round() / 16.0 } else { 0.5 };
        let (gs, gt) = (dyadic(kk, du), dyadic(ll, dv));
        let gval = bz::eval(&b.c, d, [1.0 - gs, gs], [1.0 - gt, gt], &mut w.tmp);
        let gerr = bz::eval_error(&b.c, d, b.err, 0);
        let cands = [
            (0.0, 0.0, b.c[0], b.err),
            (1.0, 0.0, b.c[du], b.err),
            (0.0, 1.0, b.c[dv * wd], b.err),
            (1.0, 1.0, b.c[dv * wd + du], b.err),
            (gs, gt, gval, gerr),
        ];
        for &(s, t, v, _) in &cands[..4] {
            st.min_value = st.min_value.min(v);
            let _ = (s, t);
        }
        let mut best: Option<FoldInfo> = None;
        for (s, t, v, e) in cands {
            if v < -e {
                let ls = b.su[0] + s * (b.su[1] - b.su[0]);
                let lt = b.sv[0] + t * (b.sv[1] - b.sv[0]);
                if let Some(f) = ctx.confirm(ls, lt, &mut w.tmp) {
                    if best.as_ref().is_none_or(|x| f.value < x.value) {
                        best = Some(f);
                    }
                }
            }
        }
        if best.is_some() {
            st.fold = best;
            return;
        }
        let spent = st.boxes + stack.len() + 4 > ctx.opts.max_boxes;
        if b.depth >= ctx.opts.max_depth || spent {
            if st.open.is_none() {
                let reason = if spent { "box-budget" } else { "max-depth" };
                st.open = Some((reason, b.err, cmin));
            }
            continue;
        }
        stack.extend(split4(&b, d, &mut w.tmp));
    }
}

/// Shrink the neighbourhood of forced corner `k` (local corner `k` of the element).
fn corner(ctx: &Ctx<'_, '_>, w: &mut Work, mut b: SubBox, k: usize, st: &mut Search) {
    let d = ctx.deg();
    let dom = ctx.forced[k].unwrap_or(k);
    loop {
        st.boxes += 1;
        st.depth = st.depth.max(b.depth);
        let spent = st.boxes + 4 > ctx.opts.max_boxes;
        if b.depth >= ctx.opts.max_depth || spent {
            break;
        }
        let children = split4(&b, d, &mut w.tmp);
        let mut others = Vec::with_capacity(3);
        let mut cc = None;
        for (i, c) in children.into_iter().enumerate() {
            if i == k {
                cc = Some(c);
            } else {
                others.push(c);
            }
        }
        let mut sub = Search::new(st.boxes);
        run(ctx, w, others, &mut sub);
        st.boxes = sub.boxes;
        st.depth = st.depth.max(sub.depth);
        if sub.fold.is_none() && sub.open.is_none() {
            st.lower = st.lower.min(sub.lower);
            st.min_value = st.min_value.min(sub.min_value);
            for (a, x) in st.excused.iter_mut().zip(sub.excused) {
                *a = a.or(x);
            }
            b = cc.expect("four children");
            continue;
        }
        if sub.fold.is_some() && !ctx.negative[k] {
            st.fold = sub.fold;
            return;
        }
        break;
    }
    let ext = [(b.su[1] - b.su[0]) * (ctx.bu[1] - ctx.bu[0]), (b.sv[1] - b.sv[0]) * (ctx.bv[1] - ctx.bv[0])];
    st.excused[dom] = Some(ext);
}

/// Whether local corner `k` of element `e` lies on a side of the domain (not at one of
/// its corners) where that side's tangent vanishes within rounding, one-sided from `e`.
fn zero_speed_point(dj: &DetJElements<'_>, w: &Work, e: [usize; 2], k: usize) -> bool {
    let shape = dj.shape();
    let (s, t) = LOCAL[k];
    let (s, t) = (s as usize, t as usize);
    // on a side eta = const (south or north): the tangent is x_ξ; xi = const: x_η
    let on_eta_side = (t == 0 && e[1] == 0) || (t == 1 && e[1] + 1 == shape[1]);
    let on_xi_side = (s == 0 && e[0] == 0) || (s == 1 && e[0] + 1 == shape[0]);
    (on_eta_side && dj.zero_tangent(w, 0, s, t)) || (on_xi_side && dj.zero_tangent(w, 1, s, t))
}

/// Examine element `e`.
pub(super) fn examine(dj: &DetJElements<'_>, e: [usize; 2], opts: &CertifyOptions, w: &mut Work) -> ElementResult {
    let d = dj.deg;
    let [du, dv] = d.0;
    let n = d.len();
    let (bu, bv) = dj.bounds(e);
    let mut c0 = vec![0.0; n];
    let sc = dj.coefficients(e, w, &mut c0);
    let wnet = dj.map.weights.is_some().then(|| w.net[2].clone());
    let shape = dj.shape();
    // domain corners at this element's local corners
    let (x0, x1) = (e[0] == 0, e[0] + 1 == shape[0]);
    let (y0, y1) = (e[1] == 0, e[1] + 1 == shape[1]);
    let at = [x0 && y0, x1 && y0, x1 && y1, x0 && y1];
    let corner_coef = [c0[0], c0[du], c0[n - 1], c0[dv * (du + 1)]];
    let mut forced = [None; 4];
    let mut negative = [false; 4];
    let mut forced_bits = 0u8;
    for k in 0..4 {
        if at[k] && corner_coef[k] <= sc.err {
            forced_bits |= 1 << k;
            if opts.excuse_corners {
                forced[k] = Some(k);
                negative[k] = corner_coef[k] < -sc.err;
            }
        } else if !at[k] && opts.excuse_corners && corner_coef[k] <= sc.err && zero_speed_point(dj, w, e, k) {
            // a point of a side where the side's own speed vanishes: det J = x_ξ × x_η = 0
            // there for every map of that boundary (not a negative value: a fold nearby
            // is still a fold)
            forced[k] = Some(4 + k);
        }
    }
    let integral = if dj.map.weights.is_none() {
        c0.iter().sum::<f64>() / n as f64 * sc.factor * (bu[1] - bu[0]) * (bv[1] - bv[0])
    } else {
        0.0
    };
    let ctx = Ctx { dj, opts, e, bu, bv, c0: &c0, sc, wnet, forced, negative };
    let mut st = Search::new(0);
    let root = SubBox { c: c0.clone(), su: [0.0, 1.0], sv: [0.0, 1.0], depth: 0, err: sc.err };
    run(&ctx, w, vec![root], &mut st);
    let to_det_bound = |v: f64| sc.factor * v / (sc.wmax * sc.wmax * sc.wmax);
    let rational = dj.map.weights.is_some();
    let undecided = if st.fold.is_none() {
        st.open.map(|(reason, err, cmin)| UndecidedInfo {
            element: e,
            reason,
            depth: st.depth,
            boxes: st.boxes,
            smallest_coefficient: to_det_bound(cmin),
            error_bound: to_det_bound(err),
        })
    } else {
        None
    };
    let _ = amax;
    ElementResult {
        fold: st.fold,
        undecided,
        lower: if st.lower.is_finite() { to_det_bound(st.lower) * (1.0 - 1e-12) } else { f64::INFINITY },
        min_value: if rational { f64::INFINITY } else { sc.factor * st.min_value },
        integral,
        boxes: st.boxes,
        depth: st.depth,
        forced: forced_bits,
        excused: st.excused,
    }
}
