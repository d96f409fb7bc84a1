//! Certified bijectivity (paper §8.1): `det J` of a tensor-product map of degree
//! `(p, q)` is, on every element, a polynomial of degree `(2p - 1, 2q - 1)` (eq. 43).
//! We compute it *exactly* in Bernstein form: Bézier extraction gives the element's
//! control net, the derivatives `x_xi`, `x_eta` are differences of that net, and
//! products of Bernstein polynomials are Bernstein polynomials,
//! `B_i^m B_j^n = binom(m, i) binom(n, j) / binom(m + n, i + j) B_{i+j}^{m+n}`.
//! By the convex-hull property the smallest coefficient is a lower bound of `det J`
//! on the element and the corner coefficients are exact values. Elements that are
//! neither proven positive nor shown to fold are subdivided (de Casteljau), which
//! makes the coefficients converge to the values quadratically.
//!
//! For a rational map `x = X / W` (homogeneous `X = sum w c N`, `W = sum w N`),
//! `det J = N / W^3` with
//! `N = W (X_xi Y_eta - X_eta Y_xi) + X (Y_xi W_eta - Y_eta W_xi) + Y (X_eta W_xi - X_xi W_eta)`,
//! a polynomial of degree `(3p - 1, 3q - 1)`; since `W > 0` the numerator is certified.
//!
//! Corners whose angle is 180 degrees or more (or close to it, within the fit
//! tolerance) force `det J <= 0` at the corner for every `C^1` map; the elements within
//! [`CertifyOptions::corner_spans`] spans of such a corner are *excused*: when they
//! cannot be proven positive the verdict is [`Verdict::DegenerateCorner`] instead of a
//! fold, and the report names the corners.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::error::Result;
use crate::spline::bezier::BezierExtraction;
use crate::spline::surface::{Side, Surface};

/// Options of [`certify`].
#[derive(Debug, Clone, Copy)]
pub struct CertifyOptions {
    /// Most bisections (in both directions) of an element.
    pub max_depth: usize,
    /// Most sub-boxes examined per element.
    pub max_boxes: usize,
    /// Corner angles (degrees) at or above this count as forbidding positivity (the fit
    /// tolerance blurs an exact 180-degree corner).
    pub forced_angle: f64,
    /// Elements within this many spans (per direction) of a forced corner are excused
    /// (0: none, every corner must be proven positive).
    pub corner_spans: usize,
}

impl Default for CertifyOptions {
    fn default() -> Self {
        Self { max_depth: 16, max_boxes: 4096, forced_angle: 179.0, corner_spans: 2 }
    }
}

/// The outcome of [`certify`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Verdict {
    /// `det J > 0` on the whole parameter domain, proven.
    Certified {
        /// Proven lower bound of `det J`.
        lower_bound: f64,
        /// `lower_bound / mean det J`.
        relative: f64,
    },
    /// `det J > 0` proven everywhere except near corners whose angle forbids it.
    DegenerateCorner {
        /// The corners ("south-west", ...).
        corners: Vec<&'static str>,
        /// Proven lower bound of `det J` away from those corners.
        lower_bound: f64,
        /// `lower_bound / mean det J`.
        relative: f64,
    },
    /// A point with `det J <= 0` away from forced corners (the most negative found).
    Folded {
        /// Parameter point `(xi, eta)`.
        param: [f64; 2],
        /// Physical point `x(xi, eta)`.
        point: [f64; 2],
        /// `det J` there.
        value: f64,
    },
    /// The subdivision budget was spent before every element was decided.
    Undecided {
        /// Elements `(i, j)` (indices of the element in `xi` and `eta`) left open.
        elements: Vec<[usize; 2]>,
    },
}

impl Verdict {
    /// Short name (`certified`, `degenerate-corner`, `folded`, `undecided`).
    pub fn name(&self) -> &'static str {
        match self {
            Verdict::Certified { .. } => "certified",
            Verdict::DegenerateCorner { .. } => "degenerate-corner",
            Verdict::Folded { .. } => "folded",
            Verdict::Undecided { .. } => "undecided",
        }
    }
}

/// One corner of the map.
#[derive(Debug, Clone, Serialize)]
pub struct CornerInfo {
    /// "south-west", "south-east", "north-east", "north-west".
    pub corner: &'static str,
    /// Interior angle of the map's boundary in degrees.
    pub angle_degrees: f64,
    /// Exact `det J` at the corner (cross product of the two side tangents).
    pub det_j: f64,
    /// Whether the angle forbids `det J > 0` there (angle >= `forced_angle`, or a
    /// vanishing tangent).
    pub forbids_positivity: bool,
}

/// An element where `det J <= 0` was found.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct FoldInfo {
    /// Element `(i, j)`.
    pub element: [usize; 2],
    /// Parameter point.
    pub param: [f64; 2],
    /// `det J` there.
    pub value: f64,
}

/// The bijectivity certificate of a map.
#[derive(Debug, Clone, Serialize)]
pub struct Certificate {
    /// The verdict.
    pub verdict: Verdict,
    /// Proven lower bound of `det J` over the proven elements (excused ones excluded).
    pub lower_bound: f64,
    /// Mean of `det J` over the parameter domain (area / parameter area; exact for
    /// polynomial maps).
    pub mean_det_j: f64,
    /// Smallest exact value of `det J` met (corners of sub-boxes and test points).
    pub min_value_found: f64,
    /// Degrees of the `det J` polynomial (of its numerator for rational maps).
    pub det_degree: [usize; 2],
    /// The four corners.
    pub corners: Vec<CornerInfo>,
    /// Elements examined.
    pub elements: usize,
    /// Elements per direction.
    pub element_shape: [usize; 2],
    /// Sub-boxes examined in total (elements included).
    pub boxes: usize,
    /// Deepest bisection level used.
    pub max_depth: usize,
    /// Elements near forced corners that could not be proven positive.
    pub excused: Vec<[usize; 2]>,
    /// Elements where a non-positive value was found (away from forced corners).
    pub folds: Vec<FoldInfo>,
    /// Elements left undecided.
    pub undecided: Vec<[usize; 2]>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

impl Certificate {
    /// The elements a defect correction should refine: folded and undecided ones.
    pub fn offending_elements(&self) -> Vec<[usize; 2]> {
        let mut v: Vec<[usize; 2]> =
            self.folds.iter().map(|f| f.element).chain(self.undecided.iter().copied()).collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// A sentence describing the verdict.
    pub fn message(&self) -> String {
        match &self.verdict {
            Verdict::Certified { lower_bound, relative } => format!(
                "certified bijective: det J >= {lower_bound:.4e} ({relative:.3e} of its mean) proven on all {} elements \
                 ({} Bernstein boxes)",
                self.elements, self.boxes
            ),
            Verdict::DegenerateCorner { corners, lower_bound, relative } => {
                let why: Vec<String> = self
                    .corners
                    .iter()
                    .filter(|c| corners.contains(&c.corner))
                    .map(|c| format!("{} (angle {:.2} degrees, det J there {:.3e})", c.corner, c.angle_degrees, c.det_j))
                    .collect();
                let elsewhere = if lower_bound.is_finite() {
                    format!("det J >= {lower_bound:.4e} ({relative:.3e} of its mean) is proven everywhere else")
                } else {
                    "det J > 0 is proven everywhere else".to_string()
                };
                format!(
                    "degenerate corner: the boundary forces det J <= 0 at the {} corner; {elsewhere}: the best map this \
                     boundary admits",
                    why.join(" and ")
                )
            }
            Verdict::Folded { param, point, value } => format!(
                "FOLDED: det J = {value:.4e} <= 0 at (xi, eta) = ({:.6}, {:.6}), x = ({:.6}, {:.6}); {} element(s) fold",
                param[0],
                param[1],
                point[0],
                point[1],
                self.folds.len()
            ),
            Verdict::Undecided { elements } => format!(
                "undecided: {} element(s) neither proven positive nor shown to fold within {} bisections (smallest value \
                 found {:.4e})",
                elements.len(),
                self.max_depth,
                self.min_value_found
            ),
        }
    }
}

/// A tensor Bernstein polynomial of degree `d = [du, dv]`, coefficient `(k, l)` at
/// `l * (du + 1) + k`.
#[derive(Debug, Clone, Copy)]
struct Deg([usize; 2]);

impl Deg {
    fn len(self) -> usize {
        (self.0[0] + 1) * (self.0[1] + 1)
    }
}

fn binom(n: usize, k: usize) -> f64 {
    let mut r = 1.0;
    for i in 0..k {
        r = r * (n - i) as f64 / (i + 1) as f64;
    }
    r
}

/// Binomial coefficients `binom(n, k)` for `n <= MAXN`.
struct Binom {
    rows: Vec<Vec<f64>>,
}

impl Binom {
    fn new(maxn: usize) -> Self {
        Self { rows: (0..=maxn).map(|n| (0..=n).map(|k| binom(n, k)).collect()).collect() }
    }
    fn get(&self, n: usize, k: usize) -> f64 {
        self.rows[n][k]
    }
}

/// `out += s * a * b` (Bernstein product); `out` has degree `da + db`.
fn bern_mul_add(bn: &Binom, a: &[f64], da: Deg, b: &[f64], db: Deg, s: f64, out: &mut [f64]) {
    let [au, av] = da.0;
    let [bu, bv] = db.0;
    let (nu, nv) = (au + bu, av + bv);
    for l1 in 0..=av {
        for k1 in 0..=au {
            let x = a[l1 * (au + 1) + k1] * bn.get(au, k1) * bn.get(av, l1) * s;
            if x == 0.0 {
                continue;
            }
            for l2 in 0..=bv {
                let row = (l1 + l2) * (nu + 1) + k1;
                let y = x * bn.get(bv, l2);
                for k2 in 0..=bu {
                    out[row + k2] += y * b[l2 * (bu + 1) + k2] * bn.get(bu, k2);
                }
            }
        }
    }
    let _ = nv;
}

/// Divide the accumulated products by `binom(nu, k) binom(nv, l)`.
fn bern_normalize(bn: &Binom, d: Deg, out: &mut [f64]) {
    let [nu, nv] = d.0;
    for l in 0..=nv {
        for k in 0..=nu {
            out[l * (nu + 1) + k] /= bn.get(nu, k) * bn.get(nv, l);
        }
    }
}

/// Split at `u = 1/2` (de Casteljau) into the left and right halves.
fn split_u(c: &[f64], d: Deg, left: &mut [f64], right: &mut [f64], tmp: &mut [f64]) {
    let [du, dv] = d.0;
    let w = du + 1;
    for l in 0..=dv {
        let row = &c[l * w..(l + 1) * w];
        tmp[..w].copy_from_slice(row);
        for r in 0..=du {
            left[l * w + r] = tmp[0];
            right[l * w + du - r] = tmp[du - r];
            for k in 0..du - r {
                tmp[k] = 0.5 * (tmp[k] + tmp[k + 1]);
            }
        }
    }
}

/// Split at `v = 1/2`.
fn split_v(c: &[f64], d: Deg, left: &mut [f64], right: &mut [f64], tmp: &mut [f64]) {
    let [du, dv] = d.0;
    let w = du + 1;
    for k in 0..=du {
        for l in 0..=dv {
            tmp[l] = c[l * w + k];
        }
        for r in 0..=dv {
            left[r * w + k] = tmp[0];
            right[(dv - r) * w + k] = tmp[dv - r];
            for l in 0..dv - r {
                tmp[l] = 0.5 * (tmp[l] + tmp[l + 1]);
            }
        }
    }
}

/// Value at local `(s, t) in [0, 1]^2` (de Casteljau in `u` per row, then in `v`).
fn bern_eval(c: &[f64], d: Deg, s: f64, t: f64, tmp: &mut [f64]) -> f64 {
    let [du, dv] = d.0;
    let w = du + 1;
    let (col, row) = tmp.split_at_mut(dv + 1);
    for l in 0..=dv {
        row[..w].copy_from_slice(&c[l * w..(l + 1) * w]);
        for r in 1..=du {
            for k in 0..=du - r {
                row[k] = (1.0 - s) * row[k] + s * row[k + 1];
            }
        }
        col[l] = row[0];
    }
    for r in 1..=dv {
        for l in 0..=dv - r {
            col[l] = (1.0 - t) * col[l] + t * col[l + 1];
        }
    }
    col[0]
}

/// Exact `det J` (numerator for rational maps) of the map on one element in Bernstein
/// form, with everything needed to compute it reused between elements.
struct DetJElements<'a> {
    map: &'a Surface,
    ex: [BezierExtraction; 2],
    binom: Binom,
    deg: Deg,
}

/// Per-thread scratch.
struct Work {
    loc: Vec<[f64; 3]>,
    net: [Vec<f64>; 3],
    du: [Vec<f64>; 3],
    dv: [Vec<f64>; 3],
    tmp: Vec<f64>,
    prod: Vec<f64>,
}

impl<'a> DetJElements<'a> {
    fn new(map: &'a Surface) -> Result<Self> {
        let ex = [BezierExtraction::new(&map.knots[0])?, BezierExtraction::new(&map.knots[1])?];
        let [p, q] = map.degrees();
        let deg = if map.weights.is_some() { Deg([3 * p - 1, 3 * q - 1]) } else { Deg([2 * p - 1, 2 * q - 1]) };
        Ok(Self { map, ex, binom: Binom::new(3 * p.max(q) + 2), deg })
    }

    fn shape(&self) -> [usize; 2] {
        [self.ex[0].elements.len(), self.ex[1].elements.len()]
    }

    fn work(&self) -> Work {
        let [p, q] = self.map.degrees();
        let n = (p + 1) * (q + 1);
        let big = self.deg.len();
        Work {
            loc: vec![[0.0; 3]; n],
            net: std::array::from_fn(|_| vec![0.0; n]),
            du: std::array::from_fn(|_| vec![0.0; p * (q + 1)]),
            dv: std::array::from_fn(|_| vec![0.0; (p + 1) * q]),
            tmp: vec![0.0; 2 * (self.deg.0[0].max(self.deg.0[1]) + 2) + big],
            prod: vec![0.0; big],
        }
    }

    /// Element bounds `([u0, u1], [v0, v1])`.
    fn bounds(&self, e: [usize; 2]) -> ([f64; 2], [f64; 2]) {
        let (_, a, b) = self.ex[0].elements[e[0]];
        let (_, c, d) = self.ex[1].elements[e[1]];
        ([a, b], [c, d])
    }

    /// Coefficients of `det J` (or its numerator) on element `e` into `out`; returns a
    /// bound on their rounding error and the largest weight coefficient (1 if polynomial).
    fn coefficients(&self, e: [usize; 2], w: &mut Work, out: &mut [f64]) -> (f64, f64) {
        let [p, q] = self.map.degrees();
        let nx = self.map.shape()[0];
        let (su, a, b) = self.ex[0].elements[e[0]];
        let (sv, c, d) = self.ex[1].elements[e[1]];
        let (hu, hv) = (b - a, d - c);
        let (fu, fv) = (su - p, sv - q);
        let rational = self.map.weights.is_some();
        // local homogeneous control points (w x, w y, w)
        for j in 0..=q {
            for i in 0..=p {
                let k = (fv + j) * nx + fu + i;
                let c = self.map.control_points[k];
                let wt = self.map.weights.as_ref().map_or(1.0, |w| w[k]);
                w.loc[j * (p + 1) + i] = [wt * c[0], wt * c[1], wt];
            }
        }
        // Bernstein net: B[k][l] = sum_ij loc[i][j] opx[i][k] opy[j][l]
        let (ox, oy) = (&self.ex[0].ops[e[0]], &self.ex[1].ops[e[1]]);
        let ncomp = if rational { 3 } else { 2 };
        for z in 0..ncomp {
            let net = &mut w.net[z];
            net.fill(0.0);
            for j in 0..=q {
                for i in 0..=p {
                    let v = w.loc[j * (p + 1) + i][z];
                    if v == 0.0 {
                        continue;
                    }
                    for l in 0..=q {
                        let y = v * oy[j * (q + 1) + l];
                        if y == 0.0 {
                            continue;
                        }
                        for k in 0..=p {
                            net[l * (p + 1) + k] += y * ox[i * (p + 1) + k];
                        }
                    }
                }
            }
            // derivatives: degree (p - 1, q) and (p, q - 1)
            for l in 0..=q {
                for k in 0..p {
                    w.du[z][l * p + k] = p as f64 * (net[l * (p + 1) + k + 1] - net[l * (p + 1) + k]) / hu;
                }
            }
            for l in 0..q {
                for k in 0..=p {
                    w.dv[z][l * (p + 1) + k] = q as f64 * (net[(l + 1) * (p + 1) + k] - net[l * (p + 1) + k]) / hv;
                }
            }
        }
        let (du_deg, dv_deg, n_deg) = (Deg([p - 1, q]), Deg([p, q - 1]), Deg([p, q]));
        let amax = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let bn = &self.binom;
        out.fill(0.0);
        if !rational {
            bern_mul_add(bn, &w.du[0], du_deg, &w.dv[1], dv_deg, 1.0, out);
            bern_mul_add(bn, &w.dv[0], dv_deg, &w.du[1], du_deg, -1.0, out);
            bern_normalize(bn, self.deg, out);
            let scale = amax(&w.du[0]) * amax(&w.dv[1]) + amax(&w.dv[0]) * amax(&w.du[1]);
            let err = 16.0 * (self.deg.0[0] + self.deg.0[1] + 4) as f64 * f64::EPSILON * scale;
            return (err, 1.0);
        }
        // N = W (X_u Y_v - X_v Y_u) + X (Y_u W_v - Y_v W_u) + Y (X_v W_u - X_u W_v)
        let d2 = Deg([2 * p - 1, 2 * q - 1]);
        let tmp = &mut w.prod[..d2.len()];
        // (outer factor, [(component of the xi derivative, of the eta derivative, sign)])
        type Term = (usize, [(usize, usize, f64); 2]);
        let terms: [Term; 3] =
            [(2, [(0, 1, 1.0), (1, 0, -1.0)]), (0, [(1, 2, 1.0), (2, 1, -1.0)]), (1, [(2, 0, 1.0), (0, 2, -1.0)])];
        let mut scale = 0.0;
        for (outer, pair) in terms {
            tmp.fill(0.0);
            let mut s = 0.0;
            for (zu, zv, sign) in pair {
                // (du of zu) * (dv of zv)
                bern_mul_add(bn, &w.du[zu], du_deg, &w.dv[zv], dv_deg, sign, tmp);
                s += amax(&w.du[zu]) * amax(&w.dv[zv]);
            }
            bern_normalize(bn, d2, tmp);
            bern_mul_add(bn, &w.net[outer], n_deg, tmp, d2, 1.0, out);
            scale += amax(&w.net[outer]) * s;
        }
        bern_normalize(bn, self.deg, out);
        let err = 32.0 * (self.deg.0[0] + self.deg.0[1] + 4) as f64 * f64::EPSILON * scale;
        (err, amax(&w.net[2]))
    }
}

/// What happened on one element.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Status {
    Proven,
    Excused,
    Folded { param: [f64; 2], value: f64 },
    Undecided,
}

#[derive(Debug, Clone, Copy)]
struct ElementResult {
    status: Status,
    /// Smallest coefficient over the proven boxes (lower bound of the numerator).
    lower: f64,
    /// Smallest exact value met.
    min_value: f64,
    /// Integral of det J (numerator) over the element (mean coefficient times area).
    integral: f64,
    boxes: usize,
    depth: usize,
    wmax: f64,
    /// Forced corners (bit k: corner k) where `det J = 0` was shown to be the only
    /// non-positive value of the box touching them.
    zero_corners: u8,
}

/// A sub-box of an element: coefficients, local `u` and `v` ranges, depth.
type SubBox = (Vec<f64>, [f64; 2], [f64; 2], usize);

/// Examine one element: subdivide until proven, a non-positive value is found, or the
/// budget is spent.
/// `forced[c]` is the index of the forced domain corner at the element's local corner
/// `c` (0: `(0, 0)`, 1: `(1, 0)`, 2: `(1, 1)`, 3: `(0, 1)`), if any. `det J <= 0` exactly
/// at such a point is no fold; a box touching it whose only non-positive coefficient is
/// that corner's (zero within rounding) is proven positive except at the corner.
fn examine(
    dj: &DetJElements<'_>,
    e: [usize; 2],
    excused: bool,
    forced: [Option<usize>; 4],
    opts: &CertifyOptions,
    w: &mut Work,
    stack: &mut Vec<SubBox>,
) -> ElementResult {
    let d = dj.deg;
    let n = d.len();
    let (bu, bv) = dj.bounds(e);
    let mut coef = vec![0.0; n];
    let (err, wmax) = dj.coefficients(e, w, &mut coef);
    let integral = coef.iter().sum::<f64>() / n as f64 * (bu[1] - bu[0]) * (bv[1] - bv[0]);
    let mut res = ElementResult {
        status: Status::Proven,
        lower: f64::INFINITY,
        min_value: f64::INFINITY,
        integral,
        boxes: 0,
        depth: 0,
        wmax,
        zero_corners: 0,
    };
    let max_depth = if excused { opts.max_depth.min(6) } else { opts.max_depth };
    stack.clear();
    stack.push((coef, [0.0, 1.0], [0.0, 1.0], 0));
    let [du, dv] = d.0;
    let w_ = du + 1;
    let mut undecided = false;
    while let Some((c, su, sv, depth)) = stack.pop() {
        res.boxes += 1;
        res.depth = res.depth.max(depth);
        let (mut kmin, mut cmin) = (0, f64::INFINITY);
        for (k, &v) in c.iter().enumerate() {
            if v < cmin {
                cmin = v;
                kmin = k;
            }
        }
        if cmin > err {
            res.lower = res.lower.min(cmin);
            continue;
        }
        // exact values: the four corners of the box and the point under the smallest
        // coefficient (its Greville point)
        let (kk, ll) = (kmin % w_, kmin / w_);
        let gs = if du > 0 { kk as f64 / du as f64 } else { 0.5 };
        let gt = if dv > 0 { ll as f64 / dv as f64 } else { 0.5 };
        let cands = [
            (0.0, 0.0, c[0]),
            (1.0, 0.0, c[du]),
            (0.0, 1.0, c[dv * w_]),
            (1.0, 1.0, c[dv * w_ + du]),
            (gs, gt, bern_eval(&c, d, gs, gt, &mut w.tmp)),
        ];
        // which box corners are forced domain corners: (index into c, forced corner)
        let local = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let box_corner = |s: f64, t: f64| -> Option<usize> {
            let (ls, lt) = (if s == 0.0 { su[0] } else { su[1] }, if t == 0.0 { sv[0] } else { sv[1] });
            (0..4).find(|&k| local[k] == (ls, lt)).and_then(|k| forced[k])
        };
        let mut worst: Option<(f64, f64, f64)> = None;
        let mut at_forced: Option<(usize, usize)> = None;
        for (s, t, v) in cands {
            res.min_value = res.min_value.min(v);
            let on_corner = (s == 0.0 || s == 1.0) && (t == 0.0 || t == 1.0);
            if let Some(k) = box_corner(s, t).filter(|_| on_corner) {
                let ci = if t == 1.0 { dv * w_ } else { 0 } + if s == 1.0 { du } else { 0 };
                at_forced = Some((k, ci));
                continue;
            }
            if v <= 0.0 && worst.is_none_or(|x| v < x.2) {
                worst = Some((s, t, v));
            }
        }
        if let (None, Some((k, ci))) = (worst, at_forced) {
            // zero at the forced corner, positive elsewhere in the box
            let rest = c.iter().enumerate().filter(|&(i, _)| i != ci).all(|(_, &v)| v > err);
            if rest && c[ci] >= -err {
                res.zero_corners |= 1 << k;
                // a few more bisections bound det J away from the corner
                if depth >= 3 {
                    continue;
                }
            }
        }
        if let Some((s, t, v)) = worst {
            let (ls, lt) = (su[0] + s * (su[1] - su[0]), sv[0] + t * (sv[1] - sv[0]));
            let param = [bu[0] + ls * (bu[1] - bu[0]), bv[0] + lt * (bv[1] - bv[0])];
            res.status = if excused { Status::Excused } else { Status::Folded { param, value: v } };
            return res;
        }
        if depth >= max_depth || res.boxes + stack.len() >= opts.max_boxes {
            undecided = true;
            continue;
        }
        // four children
        let (mut l, mut r) = (vec![0.0; n], vec![0.0; n]);
        split_u(&c, d, &mut l, &mut r, &mut w.tmp);
        let mu = 0.5 * (su[0] + su[1]);
        let mv = 0.5 * (sv[0] + sv[1]);
        for (half, uu) in [(l, [su[0], mu]), (r, [mu, su[1]])] {
            let (mut lo, mut hi) = (vec![0.0; n], vec![0.0; n]);
            split_v(&half, d, &mut lo, &mut hi, &mut w.tmp);
            stack.push((lo, uu, [sv[0], mv], depth + 1));
            stack.push((hi, uu, [mv, sv[1]], depth + 1));
        }
    }
    if undecided {
        res.status = if excused { Status::Excused } else { Status::Undecided };
    }
    res
}

/// Angles and exact `det J` at the four corners, in the order south-west, south-east,
/// north-east, north-west.
pub fn corner_info(map: &Surface, forced_angle: f64) -> Vec<CornerInfo> {
    let sides = Side::ALL.map(|s| map.boundary(s));
    let d = |s: Side, end: bool| {
        let c = &sides[s as usize];
        let (a, b) = c.domain();
        c.derivs(if end { b } else { a }, 1).d1
    };
    crate::boundary::corners::corner_geometry(d)
        .into_iter()
        .map(|c| CornerInfo {
            corner: c.name,
            angle_degrees: c.angle_degrees,
            det_j: c.cross,
            forbids_positivity: c.speed == 0.0 || c.cross <= 1e-12 * c.speed || c.angle_degrees >= forced_angle,
        })
        .collect()
}

/// Certify `det J > 0` on the whole map, element by element in parallel.
pub fn certify(map: &Surface, opts: &CertifyOptions) -> Result<Certificate> {
    let t0 = Instant::now();
    let dj = DetJElements::new(map)?;
    let shape = dj.shape();
    let corners = corner_info(map, opts.forced_angle);
    let forced: Vec<bool> = corners.iter().map(|c| c.forbids_positivity).collect();
    let cs = opts.corner_spans;
    // forced corner k at element-index corner (ex_end, ey_end)
    let near = |e: [usize; 2]| -> Option<usize> {
        if cs == 0 {
            return None;
        }
        let ends = [(false, false), (true, false), (true, true), (false, true)];
        (0..4).find(|&k| {
            let (xe, ye) = ends[k];
            let inx = if xe { e[0] + cs >= shape[0] } else { e[0] < cs };
            let iny = if ye { e[1] + cs >= shape[1] } else { e[1] < cs };
            forced[k] && inx && iny
        })
    };
    // forced domain corners at the element's local corners (none in strict mode)
    let forced_local = |e: [usize; 2]| -> [Option<usize>; 4] {
        let (x0, x1) = (e[0] == 0, e[0] + 1 == shape[0]);
        let (y0, y1) = (e[1] == 0, e[1] + 1 == shape[1]);
        let at = [x0 && y0, x1 && y0, x1 && y1, x0 && y1];
        std::array::from_fn(|k| (cs > 0 && at[k] && forced[k]).then_some(k))
    };
    let near_all = |e: [usize; 2]| -> Vec<usize> {
        let ends = [(false, false), (true, false), (true, true), (false, true)];
        (0..4)
            .filter(|&k| {
                let (xe, ye) = ends[k];
                let inx = if xe { e[0] + cs >= shape[0] } else { e[0] < cs };
                let iny = if ye { e[1] + cs >= shape[1] } else { e[1] < cs };
                cs > 0 && forced[k] && inx && iny
            })
            .collect()
    };
    let all: Vec<[usize; 2]> = (0..shape[1]).flat_map(|j| (0..shape[0]).map(move |i| [i, j])).collect();
    let results: Vec<ElementResult> = all
        .par_iter()
        .map_init(
            || (dj.work(), Vec::new()),
            |(w, stack), &e| examine(&dj, e, near(e).is_some(), forced_local(e), opts, w, stack),
        )
        .collect();
    let rational = map.weights.is_some();
    let wmax = results.iter().fold(0.0f64, |m, r| m.max(r.wmax));
    // det J = N / W^3 >= N_min / W_max^3 where N_min > 0
    let to_det = |v: f64| if rational { v / wmax.powi(3) } else { v };
    let mut cert = Certificate {
        verdict: Verdict::Undecided { elements: Vec::new() },
        lower_bound: f64::INFINITY,
        mean_det_j: 0.0,
        min_value_found: f64::INFINITY,
        det_degree: dj.deg.0,
        corners,
        elements: all.len(),
        element_shape: shape,
        boxes: 0,
        max_depth: 0,
        excused: Vec::new(),
        folds: Vec::new(),
        undecided: Vec::new(),
        seconds: 0.0,
    };
    let mut integral = 0.0;
    let mut zero_corners = 0u8;
    for (e, r) in all.iter().zip(&results) {
        zero_corners |= r.zero_corners;
        cert.boxes += r.boxes;
        cert.max_depth = cert.max_depth.max(r.depth);
        integral += r.integral;
        if !rational {
            cert.min_value_found = cert.min_value_found.min(r.min_value);
        }
        match r.status {
            Status::Proven => cert.lower_bound = cert.lower_bound.min(to_det(r.lower)),
            Status::Excused => {
                if r.lower.is_finite() {
                    cert.lower_bound = cert.lower_bound.min(to_det(r.lower));
                }
                cert.excused.push(*e);
            }
            Status::Folded { param, value } => cert.folds.push(FoldInfo { element: *e, param, value }),
            Status::Undecided => {
                if r.lower.is_finite() {
                    cert.lower_bound = cert.lower_bound.min(to_det(r.lower));
                }
                cert.undecided.push(*e)
            }
        }
    }
    let (ua, ub) = map.knots[0].domain();
    let (va, vb) = map.knots[1].domain();
    let par_area = (ub - ua) * (vb - va);
    cert.mean_det_j =
        if rational { crate::verify::quality::functionals(map).area / par_area } else { integral / par_area };
    // exact values of the folds: recompute from the map (the rational numerator is not det J)
    for f in cert.folds.iter_mut() {
        f.value = map.derivs(f.param[0], f.param[1], 1).det_j();
        cert.min_value_found = cert.min_value_found.min(f.value);
    }
    let relative = cert.lower_bound / cert.mean_det_j;
    cert.verdict = if let Some(f) = cert.folds.iter().min_by(|a, b| a.value.total_cmp(&b.value)) {
        Verdict::Folded { param: f.param, point: map.eval(f.param[0], f.param[1]), value: f.value }
    } else if !cert.undecided.is_empty() {
        Verdict::Undecided { elements: cert.undecided.clone() }
    } else if !cert.excused.is_empty() || zero_corners != 0 {
        let mut names: Vec<&'static str> = cert
            .excused
            .iter()
            .flat_map(|&e| near_all(e))
            .chain((0..4).filter(|k| zero_corners & (1 << k) != 0))
            .map(|k| cert.corners[k].corner)
            .collect();
        names.dedup();
        names.sort_unstable();
        names.dedup();
        Verdict::DegenerateCorner { corners: names, lower_bound: cert.lower_bound, relative }
    } else {
        Verdict::Certified { lower_bound: cert.lower_bound, relative }
    };
    cert.seconds = t0.elapsed().as_secs_f64();
    Ok(cert)
}

/// The global minimum of `det J` by branch and bound on the Bernstein form: returns
/// `(lower, upper)` with `lower <= min det J <= upper`, `upper - lower <= tol` unless
/// `max_boxes` is reached; `upper` is an exact value (a sub-box corner). Polynomial maps
/// only (for rational maps the numerator is minimised).
pub fn det_j_min_bounds(map: &Surface, tol: f64, max_boxes: usize) -> Result<(f64, f64)> {
    let dj = DetJElements::new(map)?;
    let shape = dj.shape();
    let d = dj.deg;
    let n = d.len();
    let [du, dv] = d.0;
    let mut w = dj.work();
    let mut upper = f64::INFINITY;
    let mut heap: Vec<(f64, Vec<f64>, usize)> = Vec::new();
    for j in 0..shape[1] {
        for i in 0..shape[0] {
            let mut c = vec![0.0; n];
            dj.coefficients([i, j], &mut w, &mut c);
            let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
            heap.push((lo, c, 0));
        }
    }
    let mut boxes = 0;
    loop {
        // box with the smallest lower bound
        let Some(k) = (0..heap.len()).min_by(|&a, &b| heap[a].0.total_cmp(&heap[b].0)) else {
            return Ok((upper, upper));
        };
        let (lo, c, depth) = heap.swap_remove(k);
        for v in [c[0], c[du], c[dv * (du + 1)], c[n - 1]] {
            upper = upper.min(v);
        }
        if upper - lo <= tol || boxes >= max_boxes || depth > 40 {
            let global_lo = heap.iter().map(|h| h.0).fold(lo, f64::min);
            return Ok((global_lo.min(upper), upper));
        }
        boxes += 1;
        let (mut l, mut r) = (vec![0.0; n], vec![0.0; n]);
        split_u(&c, d, &mut l, &mut r, &mut w.tmp);
        for half in [l, r] {
            let (mut lo2, mut hi2) = (vec![0.0; n], vec![0.0; n]);
            split_v(&half, d, &mut lo2, &mut hi2, &mut w.tmp);
            for ch in [lo2, hi2] {
                let m = ch.iter().copied().fold(f64::INFINITY, f64::min);
                if m < upper {
                    heap.push((m, ch, depth + 1));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
