//! An independent exact judge of the volume certificate (tests only): the trivariate
//! Bernstein coefficients of `det J` (of `det[H, H_ξ, H_η, H_ζ]` for rational maps) in
//! exact rational arithmetic from the exact blossoms of the bivariate judge, and exact
//! de Casteljau subdivision. It shares no floating-point code with the certificate.

use num_bigint::BigInt;
use num_rational::BigRational as Q;
use num_traits::{One, Signed, Zero};

use super::super::judge::{binom, extraction, q};
use crate::spline::volume::Volume;

/// A trivariate Bernstein polynomial, coefficient `(k, l, m)` at `(m (dv+1) + l)(du+1) + k`.
#[derive(Clone)]
struct P3 {
    d: [usize; 3],
    c: Vec<Q>,
}

impl P3 {
    fn zero(d: [usize; 3]) -> Self {
        Self { d, c: vec![Q::zero(); (d[0] + 1) * (d[1] + 1) * (d[2] + 1)] }
    }
    fn at(&self, k: usize, l: usize, m: usize) -> usize {
        (m * (self.d[1] + 1) + l) * (self.d[0] + 1) + k
    }
    fn mul(&self, o: &P3) -> P3 {
        let d = [self.d[0] + o.d[0], self.d[1] + o.d[1], self.d[2] + o.d[2]];
        let mut r = P3::zero(d);
        let scaled = |p: &P3| -> Vec<Q> {
            let mut v = p.c.clone();
            for m in 0..=p.d[2] {
                for l in 0..=p.d[1] {
                    for k in 0..=p.d[0] {
                        let i = p.at(k, l, m);
                        v[i] = &v[i] * binom(p.d[0], k) * binom(p.d[1], l) * binom(p.d[2], m);
                    }
                }
            }
            v
        };
        let (a, b) = (scaled(self), scaled(o));
        for m1 in 0..=self.d[2] {
            for l1 in 0..=self.d[1] {
                for k1 in 0..=self.d[0] {
                    let x = &a[self.at(k1, l1, m1)];
                    if x.is_zero() {
                        continue;
                    }
                    for m2 in 0..=o.d[2] {
                        for l2 in 0..=o.d[1] {
                            for k2 in 0..=o.d[0] {
                                let i = r.at(k1 + k2, l1 + l2, m1 + m2);
                                r.c[i] += x * &b[o.at(k2, l2, m2)];
                            }
                        }
                    }
                }
            }
        }
        for m in 0..=d[2] {
            for l in 0..=d[1] {
                for k in 0..=d[0] {
                    let i = r.at(k, l, m);
                    r.c[i] = &r.c[i] / (binom(d[0], k) * binom(d[1], l) * binom(d[2], m));
                }
            }
        }
        r
    }
    fn add(&self, o: &P3, s: i32) -> P3 {
        let mut r = self.clone();
        for (a, b) in r.c.iter_mut().zip(&o.c) {
            if s > 0 {
                *a += b;
            } else {
                *a -= b;
            }
        }
        r
    }
    fn diff(&self, dir: usize) -> P3 {
        let mut d = self.d;
        d[dir] -= 1;
        let mut r = P3::zero(d);
        for m in 0..=d[2] {
            for l in 0..=d[1] {
                for k in 0..=d[0] {
                    let mut hi = [k, l, m];
                    hi[dir] += 1;
                    let i = r.at(k, l, m);
                    r.c[i] = &self.c[self.at(hi[0], hi[1], hi[2])] - &self.c[self.at(k, l, m)];
                }
            }
        }
        r
    }
    /// Halves in direction `dir` (lower, upper).
    fn split(&self, dir: usize) -> (P3, P3) {
        let half = Q::new(BigInt::one(), BigInt::from(2));
        let (mut lo, mut hi) = (self.clone(), self.clone());
        let n = self.d[dir];
        let mut range = self.d;
        range[dir] = 0;
        for m in 0..=range[2] {
            for l in 0..=range[1] {
                for k in 0..=range[0] {
                    let idx = |r: usize| {
                        let mut x = [k, l, m];
                        x[dir] = r;
                        self.at(x[0], x[1], x[2])
                    };
                    let mut t: Vec<Q> = (0..=n).map(|r| self.c[idx(r)].clone()).collect();
                    for lv in 0..=n {
                        lo.c[idx(lv)] = t[0].clone();
                        hi.c[idx(n - lv)] = t[n - lv].clone();
                        for x in 0..n - lv {
                            t[x] = (&t[x] + &t[x + 1]) * &half;
                        }
                    }
                }
            }
        }
        (lo, hi)
    }
    fn corners(&self) -> Vec<&Q> {
        let mut v = Vec::new();
        for m in [0, self.d[2]] {
            for l in [0, self.d[1]] {
                for k in [0, self.d[0]] {
                    v.push(&self.c[self.at(k, l, m)]);
                }
            }
        }
        v
    }
}

fn cross(a: &[P3], b: &[P3]) -> Vec<P3> {
    vec![
        a[1].mul(&b[2]).add(&a[2].mul(&b[1]), -1),
        a[2].mul(&b[0]).add(&a[0].mul(&b[2]), -1),
        a[0].mul(&b[1]).add(&a[1].mul(&b[0]), -1),
    ]
}

fn dot(a: &[P3], b: &[P3]) -> P3 {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1]), 1).add(&a[2].mul(&b[2]), 1)
}

/// What the judge found.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Sign3 {
    /// `det J > 0` everywhere, proven exactly.
    Positive,
    /// `det J < 0` at a point of element `e`.
    Negative { element: [usize; 3] },
    /// Undecided within the budget.
    Unknown,
}

/// Exact numerators of `det J` per element.
pub(super) struct Exact3 {
    shape: [usize; 3],
    polys: Vec<P3>,
}

impl Exact3 {
    pub fn new(vol: &Volume) -> Self {
        let deg = vol.degrees();
        let [nx, ny, _] = vol.shape();
        let elements = [0, 1, 2].map(|d| vol.knots[d].elements());
        let ops: [Vec<Vec<Vec<Q>>>; 3] = [0, 1, 2].map(|d| {
            let t: Vec<Q> = vol.knots[d].knots().iter().map(|&x| q(x)).collect();
            elements[d].iter().map(|&(s, a, b)| extraction(&t, deg[d], s, &q(a), &q(b))).collect()
        });
        let rational = vol.weights.is_some();
        let mut polys = Vec::new();
        for (ek, &(sw, _, _)) in elements[2].iter().enumerate() {
            for (ej, &(sv, _, _)) in elements[1].iter().enumerate() {
                for (ei, &(su, _, _)) in elements[0].iter().enumerate() {
                    let first = [su - deg[0], sv - deg[1], sw - deg[2]];
                    let nets: Vec<P3> = (0..if rational { 4 } else { 3 })
                        .map(|z| {
                            let mut net = P3::zero(deg);
                            for k in 0..=deg[2] {
                                for j in 0..=deg[1] {
                                    for i in 0..=deg[0] {
                                        let lin = ((first[2] + k) * ny + first[1] + j) * nx + first[0] + i;
                                        let w = vol.weights.as_ref().map_or(Q::one(), |w| q(w[lin]));
                                        let v = if z == 3 { w } else { &w * q(vol.control_points[lin][z]) };
                                        for c in 0..=deg[2] {
                                            for b in 0..=deg[1] {
                                                for a in 0..=deg[0] {
                                                    let idx = net.at(a, b, c);
                                                    net.c[idx] +=
                                                        &v * &ops[0][ei][i][a] * &ops[1][ej][j][b] * &ops[2][ek][k][c];
                                                }
                                            }
                                        }
                                    }
                                }
                            }
                            net
                        })
                        .collect();
                    let du: Vec<P3> = nets.iter().map(|n| n.diff(0)).collect();
                    let dv: Vec<P3> = nets.iter().map(|n| n.diff(1)).collect();
                    let dw: Vec<P3> = nets.iter().map(|n| n.diff(2)).collect();
                    let c_vw = cross(&dv[..3], &dw[..3]);
                    let d1 = dot(&du[..3], &c_vw);
                    let poly = if !rational {
                        d1
                    } else {
                        let x = &nets[..3];
                        let t_u = dot(x, &c_vw);
                        let t_v = dot(x, &cross(&dw[..3], &du[..3]));
                        let t_w = dot(x, &cross(&du[..3], &dv[..3]));
                        nets[3].mul(&d1).add(&du[3].mul(&t_u), -1).add(&dv[3].mul(&t_v), -1).add(&dw[3].mul(&t_w), -1)
                    };
                    polys.push(poly);
                }
            }
        }
        Self { shape: elements.each_ref().map(Vec::len), polys }
    }

    /// The sign of `det J` on the whole volume by exact subdivision (at most `budget`
    /// boxes per element, depth `max_depth`).
    pub fn sign(&self, max_depth: usize, budget: usize) -> Sign3 {
        let mut unknown = false;
        for (n, poly) in self.polys.iter().enumerate() {
            let [sx, sy, _] = self.shape;
            let element = [n % sx, (n / sx) % sy, n / (sx * sy)];
            let mut stack = vec![(poly.clone(), 0usize)];
            let mut boxes = 0;
            while let Some((pl, depth)) = stack.pop() {
                boxes += 1;
                if pl.corners().iter().any(|x| x.is_negative()) {
                    return Sign3::Negative { element };
                }
                if pl.c.iter().all(|x| x.is_positive()) {
                    continue;
                }
                if depth >= max_depth || boxes >= budget {
                    unknown = true;
                    continue;
                }
                let (a, b) = pl.split(0);
                for h in [a, b] {
                    let (c, d) = h.split(1);
                    for g in [c, d] {
                        let (e, f) = g.split(2);
                        stack.push((e, depth + 1));
                        stack.push((f, depth + 1));
                    }
                }
            }
        }
        if unknown {
            Sign3::Unknown
        } else {
            Sign3::Positive
        }
    }
}
