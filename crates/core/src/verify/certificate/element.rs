//! `det J` of a map on one element in Bernstein form, with a rigorous bound of the
//! rounding error of every coefficient (see [`super::bernstein`] for the arithmetic).
//!
//! **Local origin and scale.** On element `e` the control points are taken relative to
//! the element's first control point `o`: `d_i = fl(x_i - o)`, `|d_i - (x_i - o)| <= u |x_i - o|`
//! (exact by Sterbenz's lemma when `x_i` and `o` are within a factor two), so the
//! rounding is relative to the element's extent, not to `|x|`: a map translated by
//! `10^10` times its size keeps its accuracy. The net is then scaled to unit size by a
//! power of two (exact), and so are the weights of a rational map; `det J` changes by a
//! positive factor, which is divided out when values are reported.
//!
//! **Extraction.** The Bernstein coefficient `k` of the B-spline `N_{s-p+j}` on the
//! element `[a, b] = [t_s, t_{s+1}]` is its blossom at `(a^{p-k}, b^k)`, computed by
//! de Boor's triangle with the convex weights `α = (x_r - t_i) / (t_{i+p+1-r} - t_i)` and
//! `1 - α = (t_{i+p+1-r} - x_r) / (t_{i+p+1-r} - t_i)` (both evaluated directly, both
//! `>= 0`): five roundings per level, so every entry has relative error at most `γ_{5p}`.
//!
//! **Coefficients.** With `n₁ = h + 5p + 5q + 2 + (p+1)(q+1)` roundings per term of the
//! net (`h = 1` for a polynomial map, `2` for a rational one), the Bernstein net of each
//! homogeneous coordinate is known to `e_net = γ_{n₁+3} max|H|` (the extraction
//! operators are a partition of unity), its differences to `2 e_net + u max|Δ|`, and the
//! products of [`super::bernstein::product_error`] give the bound `e` of the `det J`
//! coefficients (of the numerator `N` of `det J = N / W³` for a rational map). The
//! factor `p q / (h_ξ h_η)` of the derivatives is left out (positive) and applied when
//! values are reported.

use super::bernstein::{self as bz, amax, gamma, product_error, Binom, Deg, TINY, U};
use crate::error::{Error, Result};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Surface;

/// Per-direction extraction operators computed by blossoming, entrywise relative error
/// `<= γ_{5p}`.
pub(super) struct Extraction {
    /// Elements `(span, a, b)`.
    pub elements: Vec<(usize, f64, f64)>,
    /// `ops[e][j * (p + 1) + k]`: Bernstein coefficient `k` of the local B-spline `j`.
    pub ops: Vec<Vec<f64>>,
    /// Multiplicity of the knot at the left end of each element, and at the right end of
    /// the last one (`elements.len() + 1` entries).
    pub break_mult: Vec<usize>,
}

impl Extraction {
    /// Typed error for interior knots of multiplicity `> p` (the map is discontinuous
    /// there): names the direction, the knot and its multiplicity.
    pub fn new(kv: &KnotVector, direction: &str) -> Result<Self> {
        let p = kv.degree();
        let bm = kv.breaks_with_multiplicity();
        if let Some(&(knot, m)) = bm[1..bm.len().saturating_sub(1)].iter().find(|&&(_, m)| m > p) {
            return Err(Error::KnotMultiplicity { direction: direction.to_string(), knot, multiplicity: m, degree: p });
        }
        let t = kv.knots();
        let elements = kv.elements();
        let mut ops = Vec::with_capacity(elements.len());
        let mut d = vec![0.0; (p + 1) * (p + 1)];
        for &(s, a, b) in &elements {
            let mut op = vec![0.0; (p + 1) * (p + 1)];
            for k in 0..=p {
                // d[i][j]: de Boor point i (i = 0..=p, for t index s - p + i) of basis j
                d.fill(0.0);
                for i in 0..=p {
                    d[i * (p + 1) + i] = 1.0;
                }
                for r in 1..=p {
                    let x = if r <= p - k { a } else { b };
                    for i in (r..=p).rev() {
                        let ti = t[s - p + i];
                        let tr = t[s - p + i + p + 1 - r];
                        let den = tr - ti;
                        let (al, be) = ((x - ti) / den, (tr - x) / den);
                        for j in 0..=p {
                            d[i * (p + 1) + j] = be * d[(i - 1) * (p + 1) + j] + al * d[i * (p + 1) + j];
                        }
                    }
                }
                for j in 0..=p {
                    op[j * (p + 1) + k] = d[p * (p + 1) + j];
                }
            }
            ops.push(op);
        }
        let mut break_mult: Vec<usize> = bm.iter().map(|&(_, m)| m).collect();
        break_mult.truncate(elements.len() + 1);
        Ok(Self { elements, ops, break_mult })
    }
}

/// `det J` (numerator for rational maps) of a map per element in Bernstein form.
pub(super) struct DetJElements<'a> {
    pub map: &'a Surface,
    pub ex: [Extraction; 2],
    pub binom: Binom,
    /// Degree of the `det J` polynomial (of its numerator).
    pub deg: Deg,
}

/// Per-thread scratch.
pub(super) struct Work {
    loc: Vec<[f64; 3]>,
    pub net: [Vec<f64>; 3],
    du: [Vec<f64>; 3],
    dv: [Vec<f64>; 3],
    /// Rounding bounds of `net`, `du` and `dv` per homogeneous component.
    e_net: [f64; 3],
    e_du: [f64; 3],
    e_dv: [f64; 3],
    pub tmp: Vec<f64>,
    prod: Vec<f64>,
}

/// The coefficients' companions: error bound and the factors that turn them into `det J`.
#[derive(Debug, Clone, Copy)]
pub(super) struct ElementScale {
    /// `|ĉ_k - c_k| <= err` for every coefficient.
    pub err: f64,
    /// `det J = factor * N / W³` (`W = 1` for polynomial maps).
    pub factor: f64,
    /// Upper bound of the (scaled) weight function `W` on the element (1 if polynomial).
    pub wmax: f64,
}

impl<'a> DetJElements<'a> {
    pub fn new(map: &'a Surface) -> Result<Self> {
        let ex = [Extraction::new(&map.knots[0], "xi")?, Extraction::new(&map.knots[1], "eta")?];
        let [p, q] = map.degrees();
        let deg = if map.weights.is_some() { Deg([3 * p - 1, 3 * q - 1]) } else { Deg([2 * p - 1, 2 * q - 1]) };
        Ok(Self { map, ex, binom: Binom::new(3 * p.max(q) + 2), deg })
    }

    pub fn shape(&self) -> [usize; 2] {
        [self.ex[0].elements.len(), self.ex[1].elements.len()]
    }

    pub fn work(&self) -> Work {
        let [p, q] = self.map.degrees();
        let n = (p + 1) * (q + 1);
        let big = self.deg.len();
        Work {
            loc: vec![[0.0; 3]; n],
            net: std::array::from_fn(|_| vec![0.0; n]),
            du: std::array::from_fn(|_| vec![0.0; p * (q + 1)]),
            dv: std::array::from_fn(|_| vec![0.0; (p + 1) * q]),
            e_net: [0.0; 3],
            e_du: [0.0; 3],
            e_dv: [0.0; 3],
            tmp: vec![0.0; 2 * (self.deg.0[0].max(self.deg.0[1]) + 2) + big],
            prod: vec![0.0; big],
        }
    }

    /// Element bounds `([u0, u1], [v0, v1])`.
    pub fn bounds(&self, e: [usize; 2]) -> ([f64; 2], [f64; 2]) {
        let (_, a, b) = self.ex[0].elements[e[0]];
        let (_, c, d) = self.ex[1].elements[e[1]];
        ([a, b], [c, d])
    }

    /// Whether the map is only `C^0` (multiplicity `>= p`) across the knot line at the
    /// `end` (0: start, 1: end) of element `e` in direction `dir`, the line being interior.
    pub fn c0_line(&self, dir: usize, e: usize, end: usize) -> bool {
        let i = e + end;
        let n = self.ex[dir].elements.len();
        i > 0 && i < n && self.ex[dir].break_mult[i] >= self.map.degrees()[dir]
    }

    /// Coefficients of `det J` (numerator for rational maps, see the module doc) on
    /// element `e` into `out`, with their error bound and scale.
    pub fn coefficients(&self, e: [usize; 2], w: &mut Work, out: &mut [f64]) -> ElementScale {
        let [p, q] = self.map.degrees();
        let nx = self.map.shape()[0];
        let (su, a, b) = self.ex[0].elements[e[0]];
        let (sv, c, d) = self.ex[1].elements[e[1]];
        let (hu, hv) = (b - a, d - c);
        let (fu, fv) = (su - p, sv - q);
        let rational = self.map.weights.is_some();
        let o = self.map.control_points[fv * nx + fu];
        // local coordinates relative to o; weights
        let mut dmax = 0.0f64;
        let mut wmax_in = 0.0f64;
        for j in 0..=q {
            for i in 0..=p {
                let k = (fv + j) * nx + fu + i;
                let x = self.map.control_points[k];
                let wt = self.map.weights.as_ref().map_or(1.0, |w| w[k]);
                let dd = [x[0] - o[0], x[1] - o[1]];
                dmax = dmax.max(dd[0].abs()).max(dd[1].abs());
                wmax_in = wmax_in.max(wt);
                w.loc[j * (p + 1) + i] = [dd[0], dd[1], wt];
            }
        }
        let sc = pow2_unit(dmax);
        let ws = if rational { pow2_unit(wmax_in) } else { 1.0 };
        for l in w.loc.iter_mut() {
            let wt = l[2] * ws;
            *l = [wt * (l[0] * sc), wt * (l[1] * sc), wt];
        }
        let h_round = if rational { 2 } else { 1 };
        let n1 = h_round + 5 * p + 5 * q + 2 + (p + 1) * (q + 1) + 3;
        // Bernstein net: net[k][l] = sum_ij loc[i][j] opx[i][k] opy[j][l]
        let (ox, oy) = (&self.ex[0].ops[e[0]], &self.ex[1].ops[e[1]]);
        let ncomp = if rational { 3 } else { 2 };
        let mut e_net = [0.0; 3];
        let mut e_du = [0.0; 3];
        let mut e_dv = [0.0; 3];
        for z in 0..ncomp {
            let hmax = w.loc.iter().fold(0.0f64, |m, h| m.max(h[z].abs()));
            e_net[z] = gamma(n1) * hmax + TINY;
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
            // differences: degree (p - 1, q) and (p, q - 1); the factors p / h_u, q / h_v
            // are left out
            for l in 0..=q {
                for k in 0..p {
                    w.du[z][l * p + k] = net[l * (p + 1) + k + 1] - net[l * (p + 1) + k];
                }
            }
            for l in 0..q {
                for k in 0..=p {
                    w.dv[z][l * (p + 1) + k] = net[(l + 1) * (p + 1) + k] - net[l * (p + 1) + k];
                }
            }
            e_du[z] = (2.0 * e_net[z] + U * amax(&w.du[z])) * (1.0 + 1e-6);
            e_dv[z] = (2.0 * e_net[z] + U * amax(&w.dv[z])) * (1.0 + 1e-6);
        }
        (w.e_net, w.e_du, w.e_dv) = (e_net, e_du, e_dv);
        let (du_deg, dv_deg, n_deg) = (Deg([p - 1, q]), Deg([p, q - 1]), Deg([p, q]));
        let bn = &self.binom;
        let factor = (p * q) as f64 / (hu * hv) / (sc * sc);
        out.fill(0.0);
        let r2 = bz::MUL_ROUNDINGS + bz::terms_per_coefficient(du_deg) + bz::terms_per_coefficient(dv_deg);
        let pair_err =
            |w: &Work, zu: usize, zv: usize| product_error(amax(&w.du[zu]), e_du[zu], amax(&w.dv[zv]), e_dv[zv], r2);
        if !rational {
            bz::mul_add(bn, &w.du[0], du_deg, &w.dv[1], dv_deg, 1.0, out);
            bz::mul_add(bn, &w.dv[0], dv_deg, &w.du[1], du_deg, -1.0, out);
            bz::normalize(bn, self.deg, out);
            let err = pair_err(w, 0, 1) + pair_err(w, 1, 0) + TINY;
            return ElementScale { err, factor, wmax: 1.0 };
        }
        // N = W (X_u Y_v - X_v Y_u) + X (Y_u W_v - Y_v W_u) + Y (X_v W_u - X_u W_v)
        let d2 = Deg([2 * p - 1, 2 * q - 1]);
        // (outer factor, [(component of the xi derivative, of the eta derivative, sign)])
        type Term = (usize, [(usize, usize, f64); 2]);
        let terms: [Term; 3] =
            [(2, [(0, 1, 1.0), (1, 0, -1.0)]), (0, [(1, 2, 1.0), (2, 1, -1.0)]), (1, [(2, 0, 1.0), (0, 2, -1.0)])];
        let r3 = bz::MUL_ROUNDINGS + 3 * bz::terms_per_coefficient(n_deg);
        let mut err = TINY;
        for (outer, pair) in terms {
            let mut e_tmp = TINY;
            {
                let tmp = &mut w.prod[..d2.len()];
                tmp.fill(0.0);
                for (zu, zv, sign) in pair {
                    bz::mul_add(bn, &w.du[zu], du_deg, &w.dv[zv], dv_deg, sign, tmp);
                }
                bz::normalize(bn, d2, tmp);
            }
            for (zu, zv, _) in pair {
                e_tmp += pair_err(w, zu, zv);
            }
            let tmp = &w.prod[..d2.len()];
            bz::mul_add(bn, &w.net[outer], n_deg, tmp, d2, 1.0, out);
            err += product_error(amax(&w.net[outer]), e_net[outer], amax(tmp), e_tmp, r3);
        }
        bz::normalize(bn, self.deg, out);
        // W <= max of its Bernstein coefficients (each known to e_net[2])
        let wmax = (amax(&w.net[2]) + e_net[2]) * (1.0 + 1e-6);
        ElementScale { err, factor, wmax }
    }
}

impl DetJElements<'_> {
    /// Whether the tangent of the domain boundary along side `dir` (0: a side `eta =
    /// const`, whose tangent is `x_ξ`; 1: `xi = const`, tangent `x_η`) vanishes within its
    /// rounding bound at local corner `(s, t)` (`0` or `1` each) of the element whose net
    /// [`DetJElements::coefficients`] left in `w`: one-sided from this element, from the
    /// differences of the Bernstein net (for a rational map, of `X' W - X W'`, whose bound
    /// is taken to first order).
    pub fn zero_tangent(&self, w: &Work, dir: usize, s: usize, t: usize) -> bool {
        let [p, q] = self.map.degrees();
        let (d, e_d) = if dir == 0 { (&w.du, &w.e_du) } else { (&w.dv, &w.e_dv) };
        // index of the difference at the corner, and of the net value there
        let k = if dir == 0 { t * q * p + s * (p - 1) } else { t * (q - 1) * (p + 1) + s * p };
        let at = t * q * (p + 1) + s * p;
        if self.map.weights.is_none() {
            return (0..2).all(|z| d[z][k].abs() <= e_d[z]);
        }
        let (wv, wd) = (w.net[2][at], d[2][k]);
        (0..2).all(|z| {
            let v = d[z][k] * wv - w.net[z][at] * wd;
            let bound =
                e_d[z] * wv.abs() + d[z][k].abs() * w.e_net[2] + w.net[z][at].abs() * e_d[2] + wd.abs() * w.e_net[z];
            v.abs() <= 2.0 * bound
        })
    }
}

/// The power of two `2^k` with `x 2^k` in `[0.5, 1)` (1 for `x = 0`; `k` clamped to
/// `±1000` so that the factor itself is a normal number).
pub(super) fn pow2_unit(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return 1.0;
    }
    let k = (-(x.log2().floor() as i64) - 1).clamp(-1000, 1000);
    2f64.powi(k as i32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::bezier::BezierExtraction;

    #[test]
    fn blossom_extraction_matches_knot_insertion() {
        let kv = KnotVector::new(3, vec![0., 0., 0., 0., 0.2, 0.5, 0.5, 0.7, 0.7, 0.7, 1., 1., 1., 1.]).unwrap();
        let a = Extraction::new(&kv, "xi").unwrap();
        let b = BezierExtraction::new(&kv).unwrap();
        assert_eq!(a.elements, b.elements);
        for (x, y) in a.ops.iter().zip(&b.ops) {
            for (u, v) in x.iter().zip(y) {
                assert!((u - v).abs() < 1e-14 && *u >= 0.0, "{u} vs {v}");
            }
        }
        assert_eq!(a.break_mult, vec![4, 1, 2, 3, 4]);
    }

    #[test]
    fn multiplicity_above_degree_is_named() {
        let kv = KnotVector::new(2, vec![0., 0., 0., 0.25, 0.5, 0.5, 0.5, 1., 1., 1.]).unwrap();
        match Extraction::new(&kv, "eta") {
            Err(Error::KnotMultiplicity { direction, knot, multiplicity, degree }) => {
                assert_eq!((direction.as_str(), knot, multiplicity, degree), ("eta", 0.5, 3, 2));
            }
            other => panic!("{:?}", other.map(|_| ())),
        }
    }

    #[test]
    fn unit_scaling_is_a_power_of_two() {
        for x in [1e-300, 3e-7, 0.75, 1.0, 1e10, 7e300] {
            let s = pow2_unit(x);
            assert!((0.5..1.0).contains(&(x * s)), "{x}");
            assert_eq!(s.log2().fract(), 0.0);
        }
    }
}
