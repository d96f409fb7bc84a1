//! `det J` of a volume on one element in trivariate Bernstein form, with a rigorous bound
//! of the rounding error of its coefficients (arithmetic in [`super::tensor`]).
//!
//! As for maps of the plane ([`super::super::element`]): the control points are taken
//! relative to the element's first one and scaled to unit size by a power of two (and so
//! are the weights), the extraction operators are the blossoms with entrywise relative
//! error `γ_{5p}`, and with `n₁ = h + 5(p + q + r) + 3 + (p + 1)(q + 1)(r + 1) + 3`
//! roundings per term the Bernstein net of each homogeneous coordinate is known to
//! `γ_{n₁} max|H|` (`h = 1` for a polynomial map, `2` for a rational one).
//!
//! **Polynomial map.** `det J = X_ξ · (X_η × X_ζ)`: the cross product is a sum of two
//! products per component, of degree `(2p, 2q - 1, 2r - 1)`, the dot product three more:
//! degree `(3p - 1, 3q - 1, 3r - 1)`.
//!
//! **Rational map** `x = X / W` (`X = Σ w c B`, `W = Σ w B`). With `x_a = (W X_a - W_a X) / W²`
//! and multilinearity of the determinant (terms with two columns `X` vanish),
//! `det J = N / W⁴`,
//! `N = W det[X_ξ, X_η, X_ζ] - W_ξ det[X, X_η, X_ζ] - W_η det[X_ξ, X, X_ζ] - W_ζ det[X_ξ, X_η, X]`,
//! which is `det[H, H_ξ, H_η, H_ζ]` of the homogeneous `H = (X, W)`, a polynomial of
//! degree `(4p - 1, 4q - 1, 4r - 1)`; since `W > 0` its sign is that of `det J`.
//!
//! The positive factor `p q r / (h_ξ h_η h_ζ)` of the derivatives and the cube of the
//! spatial scale are left out and applied when values are reported.

use super::super::bernstein::{amax, gamma, Binom, TINY};
use super::super::element::{pow2_unit, Extraction};
use super::tensor::{sum_of_products, Deg3, Poly3};
use crate::error::Result;
use crate::spline::volume::Volume;

/// `det J` (numerator for rational maps) of a volume per element in Bernstein form.
pub(super) struct DetJ3<'a> {
    pub vol: &'a Volume,
    pub ex: [Extraction; 3],
    pub binom: Binom,
    /// Degree of the `det J` polynomial (of its numerator).
    pub deg: Deg3,
}

/// The coefficients' companions.
#[derive(Debug, Clone)]
pub(super) struct Element3 {
    /// Coefficients of `det J` (numerator), scaled.
    pub c: Vec<f64>,
    /// `|ĉ_k - c_k| <= err`.
    pub err: f64,
    /// `det J = factor N / W⁴` (`W = 1` for polynomial maps).
    pub factor: f64,
    /// Upper bound of the scaled weight function on the element (1 if polynomial).
    pub wmax: f64,
    /// Bernstein net of the scaled weight function (rational maps).
    pub wnet: Option<Vec<f64>>,
}

fn cross(bn: &Binom, a: &[Poly3], b: &[Poly3]) -> [Poly3; 3] {
    [
        sum_of_products(bn, &[(&a[1], &b[2], 1.0), (&a[2], &b[1], -1.0)]),
        sum_of_products(bn, &[(&a[2], &b[0], 1.0), (&a[0], &b[2], -1.0)]),
        sum_of_products(bn, &[(&a[0], &b[1], 1.0), (&a[1], &b[0], -1.0)]),
    ]
}

fn dot(bn: &Binom, a: &[Poly3], b: &[Poly3]) -> Poly3 {
    sum_of_products(bn, &[(&a[0], &b[0], 1.0), (&a[1], &b[1], 1.0), (&a[2], &b[2], 1.0)])
}

impl<'a> DetJ3<'a> {
    pub fn new(vol: &'a Volume) -> Result<Self> {
        let ex = [
            Extraction::new(&vol.knots[0], "xi")?,
            Extraction::new(&vol.knots[1], "eta")?,
            Extraction::new(&vol.knots[2], "zeta")?,
        ];
        let [p, q, r] = vol.degrees();
        let k = if vol.weights.is_some() { 4 } else { 3 };
        let deg = Deg3([k * p - 1, k * q - 1, k * r - 1]);
        Ok(Self { vol, ex, binom: Binom::new(4 * p.max(q).max(r) + 2), deg })
    }

    pub fn shape(&self) -> [usize; 3] {
        self.ex.each_ref().map(|x| x.elements.len())
    }

    /// Element bounds per direction.
    pub fn bounds(&self, e: [usize; 3]) -> [[f64; 2]; 3] {
        std::array::from_fn(|d| {
            let (_, a, b) = self.ex[d].elements[e[d]];
            [a, b]
        })
    }

    /// Whether the map is only `C^0` (multiplicity `>= degree`) across the interior knot
    /// plane at the `end` (0: start, 1: end) of element `e` in direction `dir`.
    pub fn c0_plane(&self, dir: usize, e: usize, end: usize) -> bool {
        let i = e + end;
        let n = self.ex[dir].elements.len();
        i > 0 && i < n && self.ex[dir].break_mult[i] >= self.vol.degrees()[dir]
    }

    /// `det J` (its numerator for rational maps) on element `e`.
    pub fn coefficients(&self, e: [usize; 3]) -> Element3 {
        let vol = self.vol;
        let [p, q, r] = vol.degrees();
        let [nx, ny, _] = vol.shape();
        let spans = [0, 1, 2].map(|d| self.ex[d].elements[e[d]].0);
        let h = [0, 1, 2].map(|d| {
            let (_, a, b) = self.ex[d].elements[e[d]];
            b - a
        });
        let first = [spans[0] - p, spans[1] - q, spans[2] - r];
        let rational = vol.weights.is_some();
        let lin = |i: usize, j: usize, k: usize| ((first[2] + k) * ny + first[1] + j) * nx + first[0] + i;
        let o = vol.control_points[lin(0, 0, 0)];
        let n = (p + 1) * (q + 1) * (r + 1);
        let mut loc = Vec::with_capacity(n);
        let (mut dmax, mut wmax_in) = (0.0f64, 0.0f64);
        for k in 0..=r {
            for j in 0..=q {
                for i in 0..=p {
                    let l = lin(i, j, k);
                    let x = vol.control_points[l];
                    let w = vol.weights.as_ref().map_or(1.0, |w| w[l]);
                    let d = [x[0] - o[0], x[1] - o[1], x[2] - o[2]];
                    dmax = dmax.max(d[0].abs()).max(d[1].abs()).max(d[2].abs());
                    wmax_in = wmax_in.max(w);
                    loc.push([d[0], d[1], d[2], w]);
                }
            }
        }
        let sc = pow2_unit(dmax);
        let ws = if rational { pow2_unit(wmax_in) } else { 1.0 };
        for l in loc.iter_mut() {
            let w = l[3] * ws;
            *l = [w * (l[0] * sc), w * (l[1] * sc), w * (l[2] * sc), w];
        }
        let n1 = if rational { 2 } else { 1 } + 5 * (p + q + r) + 3 + n + 3;
        let ncomp = if rational { 4 } else { 3 };
        let ops = [0, 1, 2].map(|d| &self.ex[d].ops[e[d]]);
        let dn = Deg3([p, q, r]);
        let nets: Vec<Poly3> = (0..ncomp)
            .map(|z| {
                let mut net = vec![0.0; n];
                for k in 0..=r {
                    for j in 0..=q {
                        for i in 0..=p {
                            let v = loc[(k * (q + 1) + j) * (p + 1) + i][z];
                            if v == 0.0 {
                                continue;
                            }
                            for c in 0..=r {
                                let zc = v * ops[2][k * (r + 1) + c];
                                if zc == 0.0 {
                                    continue;
                                }
                                for b in 0..=q {
                                    let y = zc * ops[1][j * (q + 1) + b];
                                    if y == 0.0 {
                                        continue;
                                    }
                                    let row = (c * (q + 1) + b) * (p + 1);
                                    for a in 0..=p {
                                        net[row + a] += y * ops[0][i * (p + 1) + a];
                                    }
                                }
                            }
                        }
                    }
                }
                let hmax = loc.iter().fold(0.0f64, |m, l| m.max(l[z].abs()));
                Poly3 { c: net, d: dn, e: gamma(n1) * hmax + TINY }
            })
            .collect();
        let du: Vec<Poly3> = nets.iter().map(|x| x.diff(0)).collect();
        let dv: Vec<Poly3> = nets.iter().map(|x| x.diff(1)).collect();
        let dw: Vec<Poly3> = nets.iter().map(|x| x.diff(2)).collect();
        let bn = &self.binom;
        let factor = (p * q * r) as f64 / (h[0] * h[1] * h[2]) / (sc * sc * sc);
        let c_vw = cross(bn, &dv[..3], &dw[..3]);
        let d1 = dot(bn, &du[..3], &c_vw);
        if !rational {
            return Element3 { err: d1.e, c: d1.c, factor, wmax: 1.0, wnet: None };
        }
        let x = &nets[..3];
        let t_u = dot(bn, x, &c_vw);
        let t_v = dot(bn, x, &cross(bn, &dw[..3], &du[..3]));
        let t_w = dot(bn, x, &cross(bn, &du[..3], &dv[..3]));
        let num = sum_of_products(
            bn,
            &[(&nets[3], &d1, 1.0), (&du[3], &t_u, -1.0), (&dv[3], &t_v, -1.0), (&dw[3], &t_w, -1.0)],
        );
        let wmax = (amax(&nets[3].c) + nets[3].e) * (1.0 + 1e-6);
        Element3 { err: num.e, c: num.c, factor, wmax, wnet: Some(nets[3].c.clone()) }
    }
}
