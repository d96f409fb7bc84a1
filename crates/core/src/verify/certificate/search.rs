//! The search on one element of a map in `D` variables (a map of the plane, a volume):
//! prove `det J > 0` box by box, find a fold witness, or (in the plane) shrink the
//! neighbourhood of a forced corner.
//!
//! A box with coefficients `ĉ` known to `e` is *proven* when `min ĉ - e > 0`. A fold
//! needs a witness: a box corner (its coefficient is the value there) or a dyadic point
//! near the smallest coefficient whose value is `< -e'`; the witness is then re-evaluated
//! from the element's coefficients at the reported (rounded) parameter point, with the
//! error of the local coordinates `(u - a) / (b - a)` bounded, and only reported when it
//! is still `< -(its bound)`. Otherwise the box is bisected in every direction (de
//! Casteljau), and when the budget is spent the element is undecided.
//!
//! At a *forced* corner (its `det J` coefficient, exact up to `e`, is not provably
//! positive: an angle of 180 degrees or more, or a vanishing tangent) the box touching
//! the corner is bisected; its other children must be proven positive, and the search
//! descends into the corner child, until the depth limit: the corner box left is the
//! excused neighbourhood, whose size is reported. When a sibling cannot be proven, the
//! current corner box is the neighbourhood, unless the sibling holds a fold witness and
//! the corner's `det J` is not provably negative (a straight corner, where no negative
//! value is forced): then it is a fold. Volumes have no forced corners (a lofted volume
//! has no forced corner edges when its slices are certified).

use super::bernstein::{self as bz, Deg};
use super::element::{ElementScale, Elements};
use super::{CertifyOptions, Fold, Undecided};

/// A sub-box of an element: coefficients, local ranges per direction, depth, error bound.
struct SubBox<const D: usize> {
    c: Vec<f64>,
    s: [[f64; 2]; D],
    depth: usize,
    err: f64,
}

/// Local corner `k` of a box as bits (bit `dir` set: the upper end in direction `dir`):
/// in the plane numbered like the domain's corners (south-west, south-east, north-east,
/// north-west), in space by the bits themselves.
fn corner_bits(d: usize, k: usize) -> usize {
    if d == 2 {
        [0, 1, 3, 2][k]
    } else {
        k
    }
}

/// Outcome of one element.
#[derive(Debug, Clone)]
pub(super) struct ElementResult<const D: usize> {
    pub fold: Option<Fold<D>>,
    pub undecided: Option<Undecided<D>>,
    /// Lower bound of `det J` over the proven boxes (`+inf` if none).
    pub lower: f64,
    /// Smallest value of `det J` met at box corners (polynomial maps; `+inf` otherwise).
    pub min_value: f64,
    pub boxes: usize,
    pub depth: usize,
    /// Parameter extent of the excused neighbourhood per domain corner (0..4) and per
    /// zero-speed boundary point at local corner `k - 4` of the element (4..8; the plane).
    pub excused: [Option<[f64; D]>; 8],
}

/// State of a search (a tentative one for the siblings of a corner box).
struct Search<const D: usize> {
    fold: Option<Fold<D>>,
    /// (reason, box error, smallest corner value) of the first box left open.
    open: Option<(&'static str, f64, f64)>,
    lower: f64,
    min_value: f64,
    boxes: usize,
    depth: usize,
    excused: [Option<[f64; D]>; 8],
}

impl<const D: usize> Search<D> {
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

/// One element's `det J` as the search sees it.
pub(super) struct ElementDet<'a> {
    /// Coefficients of `det J` (its numerator).
    pub c0: &'a [f64],
    pub sc: ElementScale,
    /// Weight net (rational maps).
    pub wnet: Option<&'a [f64]>,
    /// Per local corner (`2^D` of them): the domain corner (0..4) or zero-speed point
    /// (4..8) forced there.
    pub forced: [Option<usize>; 8],
    /// Per local corner: whether `det J < 0` is proven there.
    pub negative: [bool; 8],
}

struct Ctx<'a, 'b, const D: usize> {
    el: &'a Elements<'b, D>,
    opts: &'a CertifyOptions,
    e: [usize; D],
    bounds: [[f64; 2]; D],
    det: ElementDet<'a>,
}

impl<const D: usize> Ctx<'_, '_, D> {
    /// `det J` from a numerator value at local coordinates `s` (weights' value there;
    /// `W^(D+1)` multiplied out factor by factor).
    fn to_det(&self, v: f64, s: [[f64; 2]; D], tmp: &mut [f64]) -> f64 {
        let wv = self.det.wnet.map_or(1.0, |wn| bz::eval(wn, self.el.weight_deg(), s, tmp));
        self.det.sc.factor * v / (0..=D).fold(1.0, |r, _| r * wv)
    }

    /// Which forced corner a box touches, if any.
    fn touches(&self, b: &SubBox<D>) -> Option<usize> {
        (0..1 << D).find(|&k| {
            let bits = corner_bits(D, k);
            self.det.forced[k].is_some()
                && (0..D).all(|dir| if (bits >> dir) & 1 == 0 { b.s[dir][0] == 0.0 } else { b.s[dir][1] == 1.0 })
        })
    }

    /// Re-evaluate a witness at the local dyadic point `ls` from the element's
    /// coefficients at the rounded parameter point; `Some` when `det J < 0` there is proven.
    fn confirm(&self, ls: [f64; D], tmp: &mut [f64]) -> Option<Fold<D>> {
        let mut param = [0.0; D];
        let mut s = [[0.0; 2]; D];
        for d in 0..D {
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
        let deg = self.el.deg;
        let val = bz::eval(self.det.c0, deg, s, tmp);
        let bound = bz::eval_error(self.det.c0, deg, self.det.sc.err, 3);
        if val >= -bound {
            return None;
        }
        let mut sides = Vec::new();
        for (dir, name) in ["xi", "eta", "zeta"].into_iter().take(D).enumerate() {
            for (end, at_end) in [(0, ls[dir] == 0.0), (1, ls[dir] == 1.0)] {
                if at_end && self.el.c0_knot(dir, self.e[dir], end) {
                    let (knot, rel) = if end == 0 { (self.bounds[dir][0], ">") } else { (self.bounds[dir][1], "<") };
                    sides.push(format!(
                        "one-sided limit from {name} {rel} {knot} (the map is only C0 across {name} = {knot})"
                    ));
                }
            }
        }
        Some(Fold {
            element: self.e,
            param,
            value: self.to_det(val, s, tmp),
            error_bound: self.to_det(bound, s, tmp),
            one_sided: (!sides.is_empty()).then(|| sides.join("; ")),
        })
    }
}

/// The `2^D` children of a box, in the order of the local corners.
fn split<const D: usize>(b: &SubBox<D>, d: Deg<D>, tmp: &mut [f64]) -> Vec<SubBox<D>> {
    let err = bz::split_error(&b.c, d, b.err);
    let mut kids: Vec<Option<Vec<f64>>> = bz::children(&b.c, d, tmp).into_iter().map(Some).collect();
    (0..kids.len())
        .map(|k| {
            let bits = corner_bits(D, k);
            let s = std::array::from_fn(|dir| {
                let [lo, hi] = b.s[dir];
                let mid = 0.5 * (lo + hi);
                if (bits >> dir) & 1 == 0 {
                    [lo, mid]
                } else {
                    [mid, hi]
                }
            });
            SubBox { c: kids[bits].take().expect("each child once"), s, depth: b.depth + 1, err }
        })
        .collect()
}

/// Prove, refute or leave open the boxes of `stack`.
fn run<const D: usize>(ctx: &Ctx<'_, '_, D>, tmp: &mut [f64], mut stack: Vec<SubBox<D>>, st: &mut Search<D>) {
    let d = ctx.el.deg;
    let nc = 1 << D;
    while let Some(b) = stack.pop() {
        if let Some(k) = ctx.touches(&b) {
            corner(ctx, tmp, b, k, st);
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
        let idx = d.index(kmin);
        let dyadic = |k: usize, n: usize| if n > 0 { (16.0 * k as f64 / n as f64).round() / 16.0 } else { 0.5 };
        let g: [f64; D] = std::array::from_fn(|dir| dyadic(idx[dir], d.0[dir]));
        let gval = bz::eval(&b.c, d, g.map(|x| [1.0 - x, x]), tmp);
        let gerr = bz::eval_error(&b.c, d, b.err, 0);
        let mut cands: Vec<([f64; D], f64, f64)> = (0..nc)
            .map(|bits: usize| {
                let bit = |dir: usize| (bits >> dir) & 1;
                let k = d.at(std::array::from_fn(|dir| bit(dir) * d.0[dir]));
                (std::array::from_fn(|dir| bit(dir) as f64), b.c[k], b.err)
            })
            .collect();
        for c in &cands {
            st.min_value = st.min_value.min(c.1);
        }
        cands.push((g, gval, gerr));
        let mut best: Option<Fold<D>> = None;
        for (s, v, e) in cands {
            if v < -e {
                let ls = std::array::from_fn(|k| b.s[k][0] + s[k] * (b.s[k][1] - b.s[k][0]));
                if let Some(f) = ctx.confirm(ls, tmp) {
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
        let spent = st.boxes + stack.len() + nc > ctx.opts.max_boxes;
        if b.depth >= ctx.opts.max_depth || spent {
            if st.open.is_none() {
                let reason = if spent { "box-budget" } else { "max-depth" };
                st.open = Some((reason, b.err, cmin));
            }
            continue;
        }
        stack.extend(split(&b, d, tmp));
    }
}

/// Shrink the neighbourhood of forced corner `k` (local corner `k` of the element).
fn corner<const D: usize>(ctx: &Ctx<'_, '_, D>, tmp: &mut [f64], mut b: SubBox<D>, k: usize, st: &mut Search<D>) {
    let d = ctx.el.deg;
    let dom = ctx.det.forced[k].unwrap_or(k);
    loop {
        st.boxes += 1;
        st.depth = st.depth.max(b.depth);
        let spent = st.boxes + (1 << D) > ctx.opts.max_boxes;
        if b.depth >= ctx.opts.max_depth || spent {
            break;
        }
        let mut others = split(&b, d, tmp);
        let cc = others.remove(k);
        let mut sub = Search::new(st.boxes);
        run(ctx, tmp, others, &mut sub);
        st.boxes = sub.boxes;
        st.depth = st.depth.max(sub.depth);
        if sub.fold.is_none() && sub.open.is_none() {
            st.lower = st.lower.min(sub.lower);
            st.min_value = st.min_value.min(sub.min_value);
            for (a, x) in st.excused.iter_mut().zip(sub.excused) {
                *a = a.or(x);
            }
            b = cc;
            continue;
        }
        if sub.fold.is_some() && !ctx.det.negative[k] {
            st.fold = sub.fold;
            return;
        }
        break;
    }
    let ext = std::array::from_fn(|dir| (b.s[dir][1] - b.s[dir][0]) * (ctx.bounds[dir][1] - ctx.bounds[dir][0]));
    st.excused[dom] = Some(ext);
}

/// Examine element `e` whose `det J` is `det`; `tmp` holds at least `el.deg.len()` values.
pub(super) fn examine<const D: usize>(
    el: &Elements<'_, D>,
    e: [usize; D],
    det: ElementDet<'_>,
    opts: &CertifyOptions,
    tmp: &mut [f64],
) -> ElementResult<D> {
    let sc = det.sc;
    let root = SubBox { c: det.c0.to_vec(), s: [[0.0, 1.0]; D], depth: 0, err: sc.err };
    let ctx = Ctx { el, opts, e, bounds: el.bounds(e), det };
    let mut st = Search::new(0);
    run(&ctx, tmp, vec![root], &mut st);
    let to_det_bound = |v: f64| sc.factor * v / sc.wmax.powi(D as i32 + 1);
    let undecided = if st.fold.is_none() {
        st.open.map(|(reason, err, cmin)| Undecided {
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
    ElementResult {
        fold: st.fold,
        undecided,
        lower: if st.lower.is_finite() { to_det_bound(st.lower) * (1.0 - 1e-12) } else { f64::INFINITY },
        min_value: if el.rational() { f64::INFINITY } else { sc.factor * st.min_value },
        boxes: st.boxes,
        depth: st.depth,
        excused: st.excused,
    }
}

/// `∫ det J` over an element of a polynomial map: the mean of the Bernstein coefficients
/// times the factor and the element's parameter measure (multiplied as each certificate
/// always has).
fn integral<const D: usize>(c0: &[f64], factor: f64, bounds: [[f64; 2]; D]) -> f64 {
    let mean = c0.iter().sum::<f64>() / c0.len() as f64 * factor;
    if D == 2 {
        bounds.iter().fold(mean, |r, b| r * (b[1] - b[0]))
    } else {
        mean * bounds.iter().map(|b| b[1] - b[0]).product::<f64>()
    }
}

/// A planar element's outcome with the corners forced there.
pub(super) struct SurfaceElement {
    pub result: ElementResult<2>,
    /// Domain corners (bits) at this element where `det J > 0` is not provable.
    pub forced: u8,
    /// Integral of `det J` over the element (polynomial maps).
    pub integral: f64,
}

/// Examine element `e` of a map of the plane: its forced corners and zero-speed points,
/// then the search.
pub(super) fn examine_surface(
    el: &Elements<'_, 2>,
    e: [usize; 2],
    opts: &CertifyOptions,
    tmp: &mut [f64],
) -> SurfaceElement {
    let shape = el.shape();
    let sides = [e[1] == 0, e[0] + 1 == shape[0], e[1] + 1 == shape[1], e[0] == 0];
    examine_surface_on(el, e, sides, opts, tmp)
}

/// Examine element `e` of a map of the plane whose sides south, east, north, west
/// (`sides[k]`) lie on the domain's boundary or not: an element of a tensor map, or the
/// Bézier patch of one cell of a map that the patch only covers in part (a THB map's
/// active cell, [`super::hierarchical`]), where only the domain's corners and sides are
/// excused.
pub(super) fn examine_surface_on(
    el: &Elements<'_, 2>,
    e: [usize; 2],
    sides: [bool; 4],
    opts: &CertifyOptions,
    tmp: &mut [f64],
) -> SurfaceElement {
    let d = el.deg;
    let [du, dv] = d.0;
    let n = d.len();
    let mut c0 = vec![0.0; n];
    let (sc, nets) = el.coefficients(e, &mut c0);
    // domain corners at this element's local corners
    let (x0, x1) = (sides[3], sides[1]);
    let (y0, y1) = (sides[0], sides[2]);
    let at = [x0 && y0, x1 && y0, x1 && y1, x0 && y1];
    let corner_coef = [c0[0], c0[du], c0[n - 1], c0[dv * (du + 1)]];
    let mut forced = [None; 8];
    let mut negative = [false; 8];
    let mut forced_bits = 0u8;
    for k in 0..4 {
        if at[k] && corner_coef[k] <= sc.err {
            forced_bits |= 1 << k;
            if opts.excuse_corners {
                forced[k] = Some(k);
                negative[k] = corner_coef[k] < -sc.err;
            }
        } else if !at[k] && opts.excuse_corners && corner_coef[k] <= sc.err && zero_speed_point(el, &nets, sides, k) {
            // a point of a side where the side's own speed vanishes: det J = x_ξ × x_η = 0
            // there for every map of that boundary (not a negative value: a fold nearby
            // is still a fold)
            forced[k] = Some(4 + k);
        }
    }
    let bounds = el.bounds(e);
    let integral = if el.rational() { 0.0 } else { integral(&c0, sc.factor, bounds) };
    let wnet = nets.h.get(2).map(|w| w.c.as_slice());
    let result = examine(el, e, ElementDet { c0: &c0, sc, wnet, forced, negative }, opts, tmp);
    SurfaceElement { result, forced: forced_bits, integral }
}

/// Examine element `e` of a volume (no forced corners); also `∫ det J` over it
/// (polynomial maps).
pub(super) fn examine_volume(el: &Elements<'_, 3>, e: [usize; 3], opts: &CertifyOptions) -> (ElementResult<3>, f64) {
    let (c0, sc, wnet) = el.volume_coefficients(e);
    let mut tmp = vec![0.0; el.deg.len()];
    let integral = if el.rational() { 0.0 } else { integral(&c0, sc.factor, el.bounds(e)) };
    let det = ElementDet { c0: &c0, sc, wnet: wnet.as_deref(), forced: [None; 8], negative: [false; 8] };
    (examine(el, e, det, opts, &mut tmp), integral)
}

/// Whether local corner `k` of an element whose sides south, east, north, west lie on the
/// domain's boundary where `sides` says lies on a side of the domain (not at one of its
/// corners) where that side's tangent vanishes within rounding, one-sided from the element.
fn zero_speed_point(el: &Elements<'_, 2>, nets: &super::element::Nets<2>, sides: [bool; 4], k: usize) -> bool {
    let bits = corner_bits(2, k);
    let (s, t) = (bits & 1, bits >> 1);
    // on a side eta = const (south or north): the tangent is x_ξ; xi = const: x_η
    let on_eta_side = (t == 0 && sides[0]) || (t == 1 && sides[2]);
    let on_xi_side = (s == 0 && sides[3]) || (s == 1 && sides[1]);
    (on_eta_side && el.zero_tangent(nets, 0, s, t)) || (on_xi_side && el.zero_tangent(nets, 1, s, t))
}

/// Every element of a map with `shape` elements per direction, direction 0 fastest.
pub(super) fn all_elements<const D: usize>(shape: [usize; D]) -> Vec<[usize; D]> {
    (0..shape.iter().product())
        .map(|mut i| {
            std::array::from_fn(|d| {
                let k = i % shape[d];
                i /= shape[d];
                k
            })
        })
        .collect()
}

/// The elements' outcomes summed up, in the order of the elements.
pub(super) struct Totals<const D: usize> {
    /// Proven lower bound of `det J` over the proven boxes.
    pub lower_bound: f64,
    /// Smallest value of `det J` met (box corners of polynomial maps, fold witnesses).
    pub min_value_found: f64,
    pub boxes: usize,
    pub max_depth: usize,
    /// `∫ det J` (polynomial maps).
    pub integral: f64,
    pub folds: Vec<Fold<D>>,
    pub undecided: Vec<Undecided<D>>,
}

impl<const D: usize> Totals<D> {
    pub fn new() -> Self {
        Self {
            lower_bound: f64::INFINITY,
            min_value_found: f64::INFINITY,
            boxes: 0,
            max_depth: 0,
            integral: 0.0,
            folds: Vec::new(),
            undecided: Vec::new(),
        }
    }

    /// Add one element's outcome and its `∫ det J`.
    pub fn add(&mut self, r: ElementResult<D>, integral: f64) {
        self.boxes += r.boxes;
        self.max_depth = self.max_depth.max(r.depth);
        self.integral += integral;
        self.min_value_found = self.min_value_found.min(r.min_value);
        self.lower_bound = self.lower_bound.min(r.lower);
        if let Some(f) = r.fold {
            self.min_value_found = self.min_value_found.min(f.value);
            self.folds.push(f);
        } else if let Some(u) = r.undecided {
            self.undecided.push(u);
        }
    }

    /// The most negative fold found.
    pub(crate) fn worst_fold(&self) -> Option<&Fold<D>> {
        self.folds.iter().min_by(|a, b| a.value.total_cmp(&b.value))
    }

    /// The finding of these totals: the worst fold (its physical point by `eval`), else
    /// the undecided elements, else certified with `relative = lower bound / mean det J`
    /// (a map of the plane turns the last into `DegenerateCorner` where it excused some).
    pub(crate) fn finding(&self, eval: impl Fn([f64; D]) -> [f64; D], relative: f64) -> super::Finding<D> {
        use super::Finding;
        if let Some(f) = self.worst_fold() {
            Finding::Folded {
                param: f.param,
                point: eval(f.param),
                value: f.value,
                error_bound: f.error_bound,
                one_sided: f.one_sided.clone(),
            }
        } else if !self.undecided.is_empty() {
            Finding::Undecided { elements: self.undecided.iter().map(|u| u.element).collect() }
        } else {
            Finding::Certified { lower_bound: self.lower_bound, relative }
        }
    }
}
