//! `det J` of a tensor-product map in `D` variables (`D = 2`: a map of the plane, `D = 3`:
//! a volume) on one Bézier element in Bernstein form, with a rigorous bound of the
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
//! **Nets.** With `n₁ = h + 5 Σ p_dir + D + Π (p_dir + 1) + 3` roundings per term of the
//! net (`h = 1` for a polynomial map, `2` for a rational one), the Bernstein net of each
//! homogeneous coordinate `H = (w x, w)` is known to `e_net = γ_{n₁} max|H|` (the
//! extraction operators are a partition of unity), its differences to
//! `2 e_net + u max|Δ|`.
//!
//! **Plane** (degree `(p, q)`, paper §8.1, eq. 43): `det J = x_ξ × x_η`, of degree
//! `(2p - 1, 2q - 1)`; for a rational map `x = X / W`, `det J = N / W³` with
//! `N = W (X_ξ Y_η - X_η Y_ξ) + X (Y_ξ W_η - Y_η W_ξ) + Y (X_η W_ξ - X_ξ W_η)`, of degree
//! `(3p - 1, 3q - 1)`. The products of [`super::bernstein::product_error`] give the bound
//! `e` of the coefficients.
//!
//! **Space** (degree `(p, q, r)`, paper §11.1): `det J = X_ξ · (X_η × X_ζ)`, of degree
//! `(3p - 1, 3q - 1, 3r - 1)`; for a rational map, with `x_a = (W X_a - W_a X) / W²` and
//! multilinearity of the determinant, `det J = N / W⁴`,
//! `N = W det[X_ξ, X_η, X_ζ] - W_ξ det[X, X_η, X_ζ] - W_η det[X_ξ, X, X_ζ] - W_ζ det[X_ξ, X_η, X]`
//! (`det[H, H_ξ, H_η, H_ζ]` of the homogeneous `H`), of degree `(4p - 1, 4q - 1, 4r - 1)`.
//!
//! Since `W > 0` the numerator is certified. The positive factor
//! `Π p_dir / Π h_dir` of the derivatives and the power `D` of the spatial scale are left
//! out and applied when values are reported.

use super::bernstein::{self as bz, amax, gamma, product_error, sum_of_products, Binom, Deg, Poly, TINY};
use crate::error::{Error, Result};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Surface;
use crate::spline::volume::Volume;

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

/// `det J` (numerator for rational maps) of a map in `D` variables per element in
/// Bernstein form.
pub(super) struct Elements<'a, const D: usize> {
    /// Extraction per direction.
    pub ex: [Extraction; D],
    /// Degrees of the map.
    pub degrees: [usize; D],
    /// Control points (direction 0 fastest) and their number per direction.
    points: &'a [[f64; D]],
    net_shape: [usize; D],
    /// Weights of a rational map.
    weights: Option<&'a [f64]>,
    pub binom: Binom,
    /// Degree of the `det J` polynomial (of its numerator).
    pub deg: Deg<D>,
}

/// The coefficients' companions: error bound and the factors that turn them into `det J`.
#[derive(Debug, Clone, Copy)]
pub(super) struct ElementScale {
    /// `|ĉ_k - c_k| <= err` for every coefficient.
    pub err: f64,
    /// `det J = factor * N / W^(D+1)` (`W = 1` for polynomial maps).
    pub factor: f64,
    /// Upper bound of the (scaled) weight function `W` on the element (1 if polynomial).
    pub wmax: f64,
}

/// The Bernstein nets of an element's homogeneous coordinates and their differences.
pub(super) struct Nets<const D: usize> {
    /// `h[z]`: `w (x_z - o_z)` (scaled) for `z < D`, then `w` (rational maps only).
    pub h: Vec<Poly<D>>,
    /// `dh[dir][z]`: the differences of `h[z]` in direction `dir` (bound without [`TINY`]).
    pub dh: Vec<Vec<Poly<D>>>,
    /// `Π p_dir / Π h_dir / scale^D`: `det J = factor N / W^(D+1)`.
    pub factor: f64,
}

impl<'a, const D: usize> Elements<'a, D> {
    /// The elements of the map with these knot vectors, control points (direction 0
    /// fastest) and weights; a typed error for an interior knot of multiplicity above the
    /// degree.
    pub fn new(knots: &[KnotVector; D], points: &'a [[f64; D]], weights: Option<&'a [f64]>) -> Result<Self> {
        let names = ["xi", "eta", "zeta"];
        let mut ex = Vec::with_capacity(D);
        for (kv, name) in knots.iter().zip(names) {
            ex.push(Extraction::new(kv, name)?);
        }
        let ex: [Extraction; D] = ex.try_into().unwrap_or_else(|_| unreachable!("one per direction"));
        let degrees = knots.each_ref().map(KnotVector::degree);
        let k = if weights.is_some() { D + 1 } else { D };
        let deg = Deg(degrees.map(|p| k * p - 1));
        let pmax = degrees.into_iter().max().unwrap_or(1);
        let net_shape = knots.each_ref().map(KnotVector::num_basis);
        Ok(Self { ex, degrees, points, net_shape, weights, binom: Binom::new((D + 1) * pmax + 2), deg })
    }

    /// Whether the map is rational.
    pub fn rational(&self) -> bool {
        self.weights.is_some()
    }

    /// Degree of the weight function.
    pub(crate) fn weight_deg(&self) -> Deg<D> {
        Deg(self.degrees)
    }

    /// Elements per direction.
    pub fn shape(&self) -> [usize; D] {
        self.ex.each_ref().map(|x| x.elements.len())
    }

    /// Element bounds per direction.
    pub fn bounds(&self, e: [usize; D]) -> [[f64; 2]; D] {
        std::array::from_fn(|d| {
            let (_, a, b) = self.ex[d].elements[e[d]];
            [a, b]
        })
    }

    /// Whether the map is only `C^0` (multiplicity `>= p`) across the knot line (plane) at
    /// the `end` (0: start, 1: end) of element `e` in direction `dir`, the line being
    /// interior.
    pub fn c0_knot(&self, dir: usize, e: usize, end: usize) -> bool {
        let i = e + end;
        let n = self.ex[dir].elements.len();
        i > 0 && i < n && self.ex[dir].break_mult[i] >= self.degrees[dir]
    }

    /// The nets of element `e` (see the module doc).
    pub(crate) fn nets(&self, e: [usize; D]) -> Nets<D> {
        let degrees = self.degrees;
        let dn = Deg(degrees);
        let n = dn.len();
        let spans: [(usize, f64, f64); D] = std::array::from_fn(|d| self.ex[d].elements[e[d]]);
        let first: [usize; D] = std::array::from_fn(|d| spans[d].0 - degrees[d]);
        let net_deg = Deg(self.net_shape.map(|s| s - 1));
        let rational = self.rational();
        let o = self.points[net_deg.at(first)];
        // local coordinates relative to o, then the weight: loc[i * (D + 1) + z]
        let mut loc = Vec::with_capacity(n * (D + 1));
        let (mut dmax, mut wmax_in) = (0.0f64, 0.0f64);
        let mut ki = [0; D];
        for _ in 0..n {
            let k = net_deg.at(std::array::from_fn(|d| first[d] + ki[d]));
            dn.advance(&mut ki, 0);
            let x = self.points[k];
            let wt = self.weights.map_or(1.0, |w| w[k]);
            for z in 0..D {
                let d = x[z] - o[z];
                dmax = dmax.max(d.abs());
                loc.push(d);
            }
            wmax_in = wmax_in.max(wt);
            loc.push(wt);
        }
        let sc = pow2_unit(dmax);
        let ws = if rational { pow2_unit(wmax_in) } else { 1.0 };
        for l in loc.chunks_exact_mut(D + 1) {
            let wt = l[D] * ws;
            for x in &mut l[..D] {
                *x = wt * (*x * sc);
            }
            l[D] = wt;
        }
        let h_round = if rational { 2 } else { 1 };
        let n1 = h_round + 5 * degrees.iter().sum::<usize>() + D + n + 3;
        let ops: [&Vec<f64>; D] = std::array::from_fn(|d| &self.ex[d].ops[e[d]]);
        let (w0, lines) = (degrees[0] + 1, n / (degrees[0] + 1));
        let h: Vec<Poly<D>> = (0..if rational { D + 1 } else { D })
            .map(|z| {
                // net[m] = Σ_i loc[i][z] Π_dir op_dir[i_dir][m_dir]
                let mut net = vec![0.0; n];
                let mut ki = [0; D];
                for i in 0..n {
                    let v = loc[i * (D + 1) + z];
                    if v != 0.0 {
                        let mut km = [0; D];
                        for line in 0..lines {
                            let y = (1..D).rev().fold(v, |y, d| y * ops[d][ki[d] * (degrees[d] + 1) + km[d]]);
                            dn.advance(&mut km, 1);
                            if y == 0.0 {
                                continue;
                            }
                            let row = &mut net[line * w0..(line + 1) * w0];
                            for (x, &b) in row.iter_mut().zip(&ops[0][ki[0] * w0..(ki[0] + 1) * w0]) {
                                *x += y * b;
                            }
                        }
                    }
                    dn.advance(&mut ki, 0);
                }
                let hmax = (0..n).fold(0.0f64, |m, i| m.max(loc[i * (D + 1) + z].abs()));
                Poly { c: net, d: dn, e: gamma(n1) * hmax + TINY }
            })
            .collect();
        let dh = (0..D)
            .map(|dir| {
                h.iter()
                    .map(|x| {
                        let (c, e) = x.diff(dir);
                        Poly { c, d: dn.minus_one(dir), e }
                    })
                    .collect()
            })
            .collect();
        let hprod: f64 = spans.iter().map(|&(_, a, b)| b - a).product();
        let scale = (0..D).fold(1.0, |r, _| r * sc);
        let factor = degrees.iter().product::<usize>() as f64 / hprod / scale;
        Nets { h, dh, factor }
    }

    /// Upper bound of the weight function on an element from its net (each coefficient
    /// known to `e`); 1 for polynomial maps.
    fn wmax(&self, nets: &Nets<D>) -> f64 {
        nets.h.get(D).map_or(1.0, |w| (amax(&w.c) + w.e) * (1.0 + 1e-6))
    }
}

impl<'a> Elements<'a, 2> {
    /// The elements of a map of the plane.
    pub fn surface(map: &'a Surface) -> Result<Self> {
        Self::new(&map.knots, &map.control_points, map.weights.as_deref())
    }

    /// Coefficients of `det J` (numerator for rational maps, see the module doc) on
    /// element `e` into `out`, with their error bound and scale, and the nets.
    pub fn coefficients(&self, e: [usize; 2], out: &mut [f64]) -> (ElementScale, Nets<2>) {
        let [p, q] = self.degrees;
        let nets = self.nets(e);
        let (du, dv) = (&nets.dh[0], &nets.dh[1]);
        let (du_deg, dv_deg, n_deg) = (Deg([p - 1, q]), Deg([p, q - 1]), Deg([p, q]));
        let bn = &self.binom;
        let factor = nets.factor;
        out.fill(0.0);
        let r2 = bz::mul_roundings(2) + bz::terms_per_coefficient(du_deg) + bz::terms_per_coefficient(dv_deg);
        let pair_err = |zu: usize, zv: usize| product_error(amax(&du[zu].c), du[zu].e, amax(&dv[zv].c), dv[zv].e, r2);
        if !self.rational() {
            bz::mul_add(bn, &du[0].c, du_deg, &dv[1].c, dv_deg, 1.0, out);
            bz::mul_add(bn, &dv[0].c, dv_deg, &du[1].c, du_deg, -1.0, out);
            bz::normalize(bn, self.deg, out);
            let err = pair_err(0, 1) + pair_err(1, 0) + TINY;
            return (ElementScale { err, factor, wmax: 1.0 }, nets);
        }
        // N = W (X_u Y_v - X_v Y_u) + X (Y_u W_v - Y_v W_u) + Y (X_v W_u - X_u W_v)
        let d2 = Deg([2 * p - 1, 2 * q - 1]);
        // (outer factor, [(component of the xi derivative, of the eta derivative, sign)])
        type Term = (usize, [(usize, usize, f64); 2]);
        let terms: [Term; 3] =
            [(2, [(0, 1, 1.0), (1, 0, -1.0)]), (0, [(1, 2, 1.0), (2, 1, -1.0)]), (1, [(2, 0, 1.0), (0, 2, -1.0)])];
        let r3 = bz::mul_roundings(2) + 3 * bz::terms_per_coefficient(n_deg);
        let mut err = TINY;
        let mut tmp = vec![0.0; d2.len()];
        for (outer, pair) in terms {
            let mut e_tmp = TINY;
            tmp.fill(0.0);
            for (zu, zv, sign) in pair {
                bz::mul_add(bn, &du[zu].c, du_deg, &dv[zv].c, dv_deg, sign, &mut tmp);
            }
            bz::normalize(bn, d2, &mut tmp);
            for (zu, zv, _) in pair {
                e_tmp += pair_err(zu, zv);
            }
            let h = &nets.h[outer];
            bz::mul_add(bn, &h.c, n_deg, &tmp, d2, 1.0, out);
            err += product_error(amax(&h.c), h.e, amax(&tmp), e_tmp, r3);
        }
        bz::normalize(bn, self.deg, out);
        // W <= max of its Bernstein coefficients (each known to e_net)
        let wmax = self.wmax(&nets);
        (ElementScale { err, factor, wmax }, nets)
    }

    /// Whether the tangent of the domain boundary along side `dir` (0: a side `eta =
    /// const`, whose tangent is `x_ξ`; 1: `xi = const`, tangent `x_η`) vanishes within its
    /// rounding bound at local corner `(s, t)` (`0` or `1` each) of the element with these
    /// nets: one-sided from this element, from the differences of the Bernstein net (for a
    /// rational map, of `X' W - X W'`, whose bound is taken to first order).
    pub(crate) fn zero_tangent(&self, nets: &Nets<2>, dir: usize, s: usize, t: usize) -> bool {
        let [p, q] = self.degrees;
        let d = &nets.dh[dir];
        // index of the difference at the corner, and of the net value there
        let k = if dir == 0 { t * q * p + s * (p - 1) } else { t * (q - 1) * (p + 1) + s * p };
        let at = t * q * (p + 1) + s * p;
        if !self.rational() {
            return (0..2).all(|z| d[z].c[k].abs() <= d[z].e);
        }
        let h = &nets.h;
        let (wv, wd) = (h[2].c[at], d[2].c[k]);
        (0..2).all(|z| {
            let v = d[z].c[k] * wv - h[z].c[at] * wd;
            let bound = d[z].e * wv.abs() + d[z].c[k].abs() * h[2].e + h[z].c[at].abs() * d[2].e + wd.abs() * h[z].e;
            v.abs() <= 2.0 * bound
        })
    }
}

impl<'a> Elements<'a, 3> {
    /// The elements of a volume.
    pub fn volume(vol: &'a Volume) -> Result<Self> {
        Self::new(&vol.knots, &vol.control_points, vol.weights.as_deref())
    }

    /// `det J` (its numerator for rational maps) on element `e`: coefficients, their
    /// bound and scale, and the weight function's net (rational maps).
    pub(crate) fn volume_coefficients(&self, e: [usize; 3]) -> (Vec<f64>, ElementScale, Option<Vec<f64>>) {
        let nets = self.nets(e);
        // the differences with the absolute slack
        let d: Vec<Vec<Poly<3>>> = nets
            .dh
            .iter()
            .map(|dir| dir.iter().map(|x| Poly { c: x.c.clone(), d: x.d, e: x.e + TINY }).collect())
            .collect();
        let (du, dv, dw) = (&d[0], &d[1], &d[2]);
        let bn = &self.binom;
        let factor = nets.factor;
        let c_vw = cross(bn, &dv[..3], &dw[..3]);
        let d1 = dot(bn, &du[..3], &c_vw);
        if !self.rational() {
            return (d1.c, ElementScale { err: d1.e, factor, wmax: 1.0 }, None);
        }
        let (x, w) = (&nets.h[..3], &nets.h[3]);
        let t_u = dot(bn, x, &c_vw);
        let t_v = dot(bn, x, &cross(bn, &dw[..3], &du[..3]));
        let t_w = dot(bn, x, &cross(bn, &du[..3], &dv[..3]));
        let num =
            sum_of_products(bn, &[(w, &d1, 1.0), (&du[3], &t_u, -1.0), (&dv[3], &t_v, -1.0), (&dw[3], &t_w, -1.0)]);
        let wmax = self.wmax(&nets);
        (num.c, ElementScale { err: num.e, factor, wmax }, Some(w.c.clone()))
    }
}

/// `a × b` of vectors of Bernstein polynomials.
fn cross(bn: &Binom, a: &[Poly<3>], b: &[Poly<3>]) -> [Poly<3>; 3] {
    [
        sum_of_products(bn, &[(&a[1], &b[2], 1.0), (&a[2], &b[1], -1.0)]),
        sum_of_products(bn, &[(&a[2], &b[0], 1.0), (&a[0], &b[2], -1.0)]),
        sum_of_products(bn, &[(&a[0], &b[1], 1.0), (&a[1], &b[0], -1.0)]),
    ]
}

/// `a · b` of vectors of Bernstein polynomials.
fn dot(bn: &Binom, a: &[Poly<3>], b: &[Poly<3>]) -> Poly<3> {
    sum_of_products(bn, &[(&a[0], &b[0], 1.0), (&a[1], &b[1], 1.0), (&a[2], &b[2], 1.0)])
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
