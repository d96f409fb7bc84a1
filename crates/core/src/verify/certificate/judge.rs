//! An independent exact judge of the certificate (tests only): the Bernstein
//! coefficients of `det J` (of its numerator for rational maps) in exact rational
//! arithmetic (`f64` data are exact rationals), from blossoms of the B-splines, with
//! exact de Casteljau subdivision. It shares no floating-point code with the certificate.

use num_bigint::BigInt;
use num_rational::BigRational as Q;
use num_traits::{One, Signed, Zero};

use crate::spline::surface::Surface;

pub(super) fn q(x: f64) -> Q {
    Q::from_float(x).expect("finite")
}

pub(super) fn binom(n: usize, k: usize) -> Q {
    let mut r = BigInt::one();
    for i in 0..k {
        r = r * BigInt::from(n - i) / BigInt::from(i + 1);
    }
    Q::from_integer(r)
}

/// Exact extraction operator of element `(s, a, b)`: `op[j][k]`.
pub(super) fn extraction(t: &[Q], p: usize, s: usize, a: &Q, b: &Q) -> Vec<Vec<Q>> {
    let mut op = vec![vec![Q::zero(); p + 1]; p + 1];
    for k in 0..=p {
        let mut d: Vec<Vec<Q>> =
            (0..=p).map(|i| (0..=p).map(|j| if i == j { Q::one() } else { Q::zero() }).collect()).collect();
        for r in 1..=p {
            let x = if r <= p - k { a } else { b };
            for i in (r..=p).rev() {
                let ti = &t[s - p + i];
                let tr = &t[s - p + i + p + 1 - r];
                let al = (x - ti) / (tr - ti);
                let be = Q::one() - &al;
                for j in 0..=p {
                    d[i][j] = &be * &d[i - 1][j] + &al * &d[i][j];
                }
            }
        }
        for j in 0..=p {
            op[j][k] = d[p][j].clone();
        }
    }
    op
}

/// A tensor Bernstein polynomial: degrees and coefficients `c[l][k]`.
#[derive(Clone)]
struct Poly {
    d: [usize; 2],
    c: Vec<Vec<Q>>,
}

impl Poly {
    fn zero(d: [usize; 2]) -> Self {
        Self { d, c: vec![vec![Q::zero(); d[0] + 1]; d[1] + 1] }
    }
    fn mul(&self, o: &Poly) -> Poly {
        let d = [self.d[0] + o.d[0], self.d[1] + o.d[1]];
        let mut r = Poly::zero(d);
        for l1 in 0..=self.d[1] {
            for k1 in 0..=self.d[0] {
                if self.c[l1][k1].is_zero() {
                    continue;
                }
                let x = &self.c[l1][k1] * binom(self.d[0], k1) * binom(self.d[1], l1);
                for l2 in 0..=o.d[1] {
                    for k2 in 0..=o.d[0] {
                        r.c[l1 + l2][k1 + k2] += &x * &o.c[l2][k2] * binom(o.d[0], k2) * binom(o.d[1], l2);
                    }
                }
            }
        }
        for l in 0..=d[1] {
            for k in 0..=d[0] {
                let den = binom(d[0], k) * binom(d[1], l);
                r.c[l][k] = &r.c[l][k] / den;
            }
        }
        r
    }
    fn sub(&self, o: &Poly) -> Poly {
        let mut r = self.clone();
        for (a, b) in r.c.iter_mut().flatten().zip(o.c.iter().flatten()) {
            *a -= b;
        }
        r
    }
    fn add(&self, o: &Poly) -> Poly {
        let mut r = self.clone();
        for (a, b) in r.c.iter_mut().flatten().zip(o.c.iter().flatten()) {
            *a += b;
        }
        r
    }
    /// Value at local `(s, t)`.
    fn eval(&self, s: &Q, t: &Q) -> Q {
        let one_s = Q::one() - s;
        let one_t = Q::one() - t;
        let col: Vec<Q> = self
            .c
            .iter()
            .map(|row| {
                let mut r = row.clone();
                for lv in 1..=self.d[0] {
                    for k in 0..=self.d[0] - lv {
                        r[k] = &one_s * &r[k] + s * &r[k + 1];
                    }
                }
                r[0].clone()
            })
            .collect();
        let mut c = col;
        for lv in 1..=self.d[1] {
            for l in 0..=self.d[1] - lv {
                c[l] = &one_t * &c[l] + t * &c[l + 1];
            }
        }
        c[0].clone()
    }
    /// The four quarters (order (0,0), (1,0), (1,1), (0,1)).
    fn split(&self) -> [Poly; 4] {
        let half = Q::new(BigInt::one(), BigInt::from(2));
        let split_rows = |c: &Vec<Vec<Q>>| -> (Vec<Vec<Q>>, Vec<Vec<Q>>) {
            let (mut l, mut r) = (Vec::new(), Vec::new());
            for row in c {
                let n = row.len() - 1;
                let mut t = row.clone();
                let (mut a, mut b) = (vec![Q::zero(); n + 1], vec![Q::zero(); n + 1]);
                for lv in 0..=n {
                    a[lv] = t[0].clone();
                    b[n - lv] = t[n - lv].clone();
                    for k in 0..n - lv {
                        t[k] = (&t[k] + &t[k + 1]) * &half;
                    }
                }
                l.push(a);
                r.push(b);
            }
            (l, r)
        };
        let tr = |c: &Vec<Vec<Q>>| -> Vec<Vec<Q>> {
            (0..c[0].len()).map(|k| c.iter().map(|row| row[k].clone()).collect()).collect()
        };
        let (l, r) = split_rows(&self.c);
        let (ll, lh) = split_rows(&tr(&l));
        let (rl, rh) = split_rows(&tr(&r));
        let mk = |c: Vec<Vec<Q>>| Poly { d: self.d, c: tr(&c) };
        [mk(ll), mk(rl), mk(rh), mk(lh)]
    }
}

/// Exact numerator of `det J` per element (positive factors `p q / (h_u h_v)` left out).
pub(super) struct Exact {
    elements: [Vec<(usize, f64, f64)>; 2],
    polys: Vec<Poly>,
    /// Exact weight polynomial per element (rational maps).
    weights: Vec<Option<Poly>>,
    nx: usize,
}

/// What the judge found.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Sign {
    /// `det J > 0` everywhere, proven exactly.
    Positive,
    /// `det J < 0` at a point of element `e`.
    Negative { element: [usize; 2] },
    /// Undecided within the budget.
    Unknown,
}

impl Exact {
    pub fn new(map: &Surface) -> Self {
        let [p, qd] = map.degrees();
        let t: [Vec<Q>; 2] = [0, 1].map(|d| map.knots[d].knots().iter().map(|&x| q(x)).collect());
        let elements = [map.knots[0].elements(), map.knots[1].elements()];
        let ops: [Vec<Vec<Vec<Q>>>; 2] = [0, 1].map(|d| {
            let deg = [p, qd][d];
            elements[d].iter().map(|&(s, a, b)| extraction(&t[d], deg, s, &q(a), &q(b))).collect()
        });
        let nx = map.shape()[0];
        let mut polys = Vec::new();
        let mut weights = Vec::new();
        for (ej, &(sv, _, _)) in elements[1].iter().enumerate() {
            for (ei, &(su, _, _)) in elements[0].iter().enumerate() {
                let ncomp = if map.weights.is_some() { 3 } else { 2 };
                let nets: Vec<Poly> = (0..ncomp)
                    .map(|z| {
                        let mut net = Poly::zero([p, qd]);
                        for j in 0..=qd {
                            for i in 0..=p {
                                let k = (sv - qd + j) * nx + su - p + i;
                                let wt = map.weights.as_ref().map_or(Q::one(), |w| q(w[k]));
                                let v = if z == 2 { wt } else { &wt * q(map.control_points[k][z]) };
                                for l in 0..=qd {
                                    for kk in 0..=p {
                                        net.c[l][kk] += &v * &ops[0][ei][i][kk] * &ops[1][ej][j][l];
                                    }
                                }
                            }
                        }
                        net
                    })
                    .collect();
                let du: Vec<Poly> = nets
                    .iter()
                    .map(|n| Poly {
                        d: [p - 1, qd],
                        c: n.c.iter().map(|row| (0..p).map(|k| &row[k + 1] - &row[k]).collect()).collect(),
                    })
                    .collect();
                let dv: Vec<Poly> = nets
                    .iter()
                    .map(|n| Poly {
                        d: [p, qd - 1],
                        c: (0..qd).map(|l| (0..=p).map(|k| &n.c[l + 1][k] - &n.c[l][k]).collect()).collect(),
                    })
                    .collect();
                let cross = |a: usize, b: usize| du[a].mul(&dv[b]).sub(&dv[a].mul(&du[b]));
                let poly = if ncomp == 2 {
                    cross(0, 1)
                } else {
                    nets[2].mul(&cross(0, 1)).add(&nets[0].mul(&cross(1, 2))).add(&nets[1].mul(&cross(2, 0)))
                };
                polys.push(poly);
                weights.push((ncomp == 3).then(|| nets[2].clone()));
            }
        }
        let ne = elements[0].len();
        Self { elements, polys, weights, nx: ne }
    }

    fn poly(&self, e: [usize; 2]) -> &Poly {
        &self.polys[e[1] * self.nx + e[0]]
    }

    /// Exact sign of `det J` on element `e` at the parameter point `(u, v)` (one-sided on
    /// the element's boundary).
    pub fn sign_at(&self, e: [usize; 2], u: f64, v: f64) -> std::cmp::Ordering {
        let (_, a, b) = self.elements[0][e[0]];
        let (_, c, d) = self.elements[1][e[1]];
        let s = (q(u) - q(a)) / (q(b) - q(a));
        let t = (q(v) - q(c)) / (q(d) - q(c));
        let val = self.poly(e).eval(&s, &t);
        val.cmp(&Q::zero())
    }

    /// Exact `det J` on element `e` at `(u, v)`, rounded to `f64` (polynomial maps).
    pub fn value_at(&self, e: [usize; 2], u: f64, v: f64, pq: usize) -> f64 {
        let (_, a, b) = self.elements[0][e[0]];
        let (_, c, d) = self.elements[1][e[1]];
        let s = (q(u) - q(a)) / (q(b) - q(a));
        let t = (q(v) - q(c)) / (q(d) - q(c));
        let mut val = self.poly(e).eval(&s, &t) * Q::from_integer(BigInt::from(pq)) / ((q(b) - q(a)) * (q(d) - q(c)));
        if let Some(w) = &self.weights[e[1] * self.nx + e[0]] {
            let wv = w.eval(&s, &t);
            val /= &wv * &wv * &wv;
        }
        to_f64(&val)
    }

    /// The sign of `det J` on the whole map by exact subdivision (at most `budget` boxes
    /// per element, depth `max_depth`); also the smallest exact value met at box corners
    /// (`det J` units, polynomial maps; rounded to `f64`).
    pub fn sign(&self, pq: usize, max_depth: usize, budget: usize) -> (Sign, f64) {
        let mut unknown = false;
        let mut min_value = f64::INFINITY;
        for (ej, &(_, c, d)) in self.elements[1].iter().enumerate() {
            for (ei, &(_, a, b)) in self.elements[0].iter().enumerate() {
                let scale = pq as f64 / ((b - a) * (d - c));
                let rational = self.weights[ej * self.nx + ei].is_some();
                let mut stack = vec![(self.poly([ei, ej]).clone(), 0usize)];
                let mut boxes = 0;
                while let Some((pl, depth)) = stack.pop() {
                    boxes += 1;
                    let [du, dv] = pl.d;
                    let corners = [&pl.c[0][0], &pl.c[0][du], &pl.c[dv][0], &pl.c[dv][du]];
                    if !rational {
                        for x in corners {
                            min_value = min_value.min(to_f64(x) * scale);
                        }
                    }
                    if corners.iter().any(|x| x.is_negative()) {
                        return (Sign::Negative { element: [ei, ej] }, min_value);
                    }
                    if pl.c.iter().flatten().all(|x| x.is_positive()) {
                        continue;
                    }
                    if depth >= max_depth || boxes >= budget {
                        unknown = true;
                        continue;
                    }
                    for ch in pl.split() {
                        stack.push((ch, depth + 1));
                    }
                }
            }
        }
        (if unknown { Sign::Unknown } else { Sign::Positive }, min_value)
    }
}

fn to_f64(x: &Q) -> f64 {
    use num_traits::ToPrimitive;
    x.to_f64().unwrap_or(f64::NAN)
}
