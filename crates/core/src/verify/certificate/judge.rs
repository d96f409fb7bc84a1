//! An independent exact judge of the certificate (tests only): the Bernstein
//! coefficients of `det J` (of its numerator for rational maps) of a map in `D`
//! variables (a map of the plane, a volume) in exact rational arithmetic (`f64` data are
//! exact rationals), from blossoms of the B-splines, with exact de Casteljau
//! subdivision. It shares no floating-point code with the certificate.

use num_bigint::BigInt;
use num_rational::BigRational as Q;
use num_traits::{One, Signed, Zero};

use crate::spline::knots::KnotVector;
use crate::spline::surface::Surface;
use crate::spline::volume::Volume;

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

/// A tensor Bernstein polynomial in `D` variables: degrees and coefficients, direction 0
/// fastest.
#[derive(Clone)]
struct Poly<const D: usize> {
    d: [usize; D],
    c: Vec<Q>,
}

impl<const D: usize> Poly<D> {
    fn zero(d: [usize; D]) -> Self {
        Self { d, c: vec![Q::zero(); d.iter().map(|x| x + 1).product()] }
    }
    fn at(&self, k: [usize; D]) -> usize {
        (0..D).rev().fold(0, |i, dir| i * (self.d[dir] + 1) + k[dir])
    }
    fn index(&self, mut i: usize) -> [usize; D] {
        std::array::from_fn(|dir| {
            let k = i % (self.d[dir] + 1);
            i /= self.d[dir] + 1;
            k
        })
    }
    /// `Π_dir binom(d_dir, k_dir)` of coefficient `i`.
    fn binoms(&self, i: usize) -> Q {
        let k = self.index(i);
        (0..D).map(|dir| binom(self.d[dir], k[dir])).product()
    }
    fn mul(&self, o: &Self) -> Self {
        let mut r = Self::zero(std::array::from_fn(|dir| self.d[dir] + o.d[dir]));
        let scaled = |p: &Self| -> Vec<Q> { p.c.iter().enumerate().map(|(i, x)| x * p.binoms(i)).collect() };
        let (a, b) = (scaled(self), scaled(o));
        for (i, x) in a.iter().enumerate() {
            if x.is_zero() {
                continue;
            }
            let ka = self.index(i);
            for (j, y) in b.iter().enumerate() {
                let kb = o.index(j);
                let k = r.at(std::array::from_fn(|dir| ka[dir] + kb[dir]));
                r.c[k] += x * y;
            }
        }
        for i in 0..r.c.len() {
            r.c[i] = &r.c[i] / r.binoms(i);
        }
        r
    }
    fn add(&self, o: &Self, s: i32) -> Self {
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
    fn diff(&self, dir: usize) -> Self {
        let mut d = self.d;
        d[dir] -= 1;
        let mut r = Self::zero(d);
        for i in 0..r.c.len() {
            let k = r.index(i);
            let mut hi = k;
            hi[dir] += 1;
            r.c[i] = &self.c[self.at(hi)] - &self.c[self.at(k)];
        }
        r
    }
    /// Value at local `s` (de Casteljau along direction 0 on every line, then 1, ...).
    fn eval(&self, s: &[Q; D]) -> Q {
        let mut c = self.c.clone();
        for (dir, x) in s.iter().enumerate() {
            let n = self.d[dir];
            let one_x = Q::one() - x;
            c = c
                .chunks(n + 1)
                .map(|line| {
                    let mut r = line.to_vec();
                    for lv in 1..=n {
                        for k in 0..=n - lv {
                            r[k] = &one_x * &r[k] + x * &r[k + 1];
                        }
                    }
                    r[0].clone()
                })
                .collect();
        }
        c[0].clone()
    }
    /// Halves in direction `dir` (lower, upper).
    fn split(&self, dir: usize) -> (Self, Self) {
        let half = Q::new(BigInt::one(), BigInt::from(2));
        let (mut lo, mut hi) = (self.clone(), self.clone());
        let n = self.d[dir];
        for i in 0..self.c.len() {
            let base = self.index(i);
            if base[dir] != 0 {
                continue;
            }
            let idx = |r: usize| {
                let mut x = base;
                x[dir] = r;
                self.at(x)
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
        (lo, hi)
    }
    /// The `2^D` children (bisected in every direction, direction 0 first), in the order
    /// each judge has always visited them: the plane's quarters counter-clockwise from
    /// `(0, 0)`, in space direction 0 the most significant bit.
    fn children(&self) -> Vec<Self> {
        let mut cur = vec![self.clone()];
        for dir in 0..D {
            cur = cur
                .iter()
                .flat_map(|p| {
                    let (a, b) = p.split(dir);
                    [a, b]
                })
                .collect();
        }
        if D == 2 {
            [0, 2, 3, 1].into_iter().map(|i| cur[i].clone()).collect()
        } else {
            cur
        }
    }
    /// The coefficients at the corners (the values there).
    fn corners(&self) -> Vec<&Q> {
        (0..1usize << D).map(|b| &self.c[self.at(std::array::from_fn(|dir| ((b >> dir) & 1) * self.d[dir]))]).collect()
    }
}

/// Exact numerator of `det J` per element (positive factors `Π p / Π h` left out).
pub(super) struct Exact<const D: usize> {
    elements: [Vec<(usize, f64, f64)>; D],
    polys: Vec<Poly<D>>,
    /// Exact weight polynomial per element (rational maps).
    weights: Vec<Option<Poly<D>>>,
}

/// What the judge found.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Sign<const D: usize> {
    /// `det J > 0` everywhere, proven exactly.
    Positive,
    /// `det J < 0` at a point of element `e`.
    Negative { element: [usize; D] },
    /// Undecided within the budget.
    Unknown,
}

/// The judge of a volume.
pub(super) type Exact3 = Exact<3>;

/// The judge's finding on a volume.
pub(super) type Sign3 = Sign<3>;

/// `a × b` and `a · b` of vectors of polynomials.
fn cross<const D: usize>(a: &[Poly<D>], b: &[Poly<D>]) -> Vec<Poly<D>> {
    vec![
        a[1].mul(&b[2]).add(&a[2].mul(&b[1]), -1),
        a[2].mul(&b[0]).add(&a[0].mul(&b[2]), -1),
        a[0].mul(&b[1]).add(&a[1].mul(&b[0]), -1),
    ]
}

fn dot<const D: usize>(a: &[Poly<D>], b: &[Poly<D>]) -> Poly<D> {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1]), 1).add(&a[2].mul(&b[2]), 1)
}

impl<const D: usize> Exact<D> {
    /// The judge of the map with these knot vectors, control points (direction 0
    /// fastest) and weights.
    fn build(knots: &[KnotVector; D], points: &[[f64; D]], weights: Option<&[f64]>) -> Self {
        let deg = knots.each_ref().map(KnotVector::degree);
        let net_shape = knots.each_ref().map(KnotVector::num_basis);
        let elements = knots.each_ref().map(KnotVector::elements);
        let ops: [Vec<Vec<Vec<Q>>>; D] = std::array::from_fn(|d| {
            let t: Vec<Q> = knots[d].knots().iter().map(|&x| q(x)).collect();
            elements[d].iter().map(|&(s, a, b)| extraction(&t, deg[d], s, &q(a), &q(b))).collect()
        });
        let shape = elements.each_ref().map(Vec::len);
        let rational = weights.is_some();
        let local = Poly::<D>::zero(deg);
        let (mut polys, mut wpolys) = (Vec::new(), Vec::new());
        for n in 0..shape.iter().product() {
            let e: [usize; D] = Poly::<D>::zero(shape.map(|s| s - 1)).index(n);
            let first: [usize; D] = std::array::from_fn(|d| elements[d][e[d]].0 - deg[d]);
            let nets: Vec<Poly<D>> = (0..if rational { D + 1 } else { D })
                .map(|z| {
                    let mut net = Poly::zero(deg);
                    for i in 0..local.c.len() {
                        let k = local.index(i);
                        let lin = (0..D).rev().fold(0, |g, d| g * net_shape[d] + first[d] + k[d]);
                        let w = weights.map_or(Q::one(), |w| q(w[lin]));
                        let v = if z == D { w } else { &w * q(points[lin][z]) };
                        for m in 0..net.c.len() {
                            let km = net.index(m);
                            let f: Q = (0..D).map(|d| ops[d][e[d]][k[d]][km[d]].clone()).product();
                            net.c[m] += &v * f;
                        }
                    }
                    net
                })
                .collect();
            let dh: Vec<Vec<Poly<D>>> = (0..D).map(|dir| nets.iter().map(|n| n.diff(dir)).collect()).collect();
            let poly = if D == 2 {
                let (du, dv) = (&dh[0], &dh[1]);
                let cross2 = |a: usize, b: usize| du[a].mul(&dv[b]).add(&dv[a].mul(&du[b]), -1);
                if !rational {
                    cross2(0, 1)
                } else {
                    nets[2].mul(&cross2(0, 1)).add(&nets[0].mul(&cross2(1, 2)), 1).add(&nets[1].mul(&cross2(2, 0)), 1)
                }
            } else {
                let (du, dv, dw) = (&dh[0], &dh[1], &dh[2]);
                let c_vw = cross(&dv[..3], &dw[..3]);
                let d1 = dot(&du[..3], &c_vw);
                if !rational {
                    d1
                } else {
                    let x = &nets[..3];
                    let t_u = dot(x, &c_vw);
                    let t_v = dot(x, &cross(&dw[..3], &du[..3]));
                    let t_w = dot(x, &cross(&du[..3], &dv[..3]));
                    nets[3].mul(&d1).add(&du[3].mul(&t_u), -1).add(&dv[3].mul(&t_v), -1).add(&dw[3].mul(&t_w), -1)
                }
            };
            polys.push(poly);
            wpolys.push(rational.then(|| nets[D].clone()));
        }
        Self { elements, polys, weights: wpolys }
    }

    fn linear(&self, e: [usize; D]) -> usize {
        (0..D).rev().fold(0, |i, d| i * self.elements[d].len() + e[d])
    }

    /// Local coordinates of the parameter point `u` on element `e`, and `Π h_dir`.
    fn local(&self, e: [usize; D], u: [f64; D]) -> ([Q; D], Q) {
        let mut h = Q::one();
        let s = std::array::from_fn(|d| {
            let (_, a, b) = self.elements[d][e[d]];
            h *= q(b) - q(a);
            (q(u[d]) - q(a)) / (q(b) - q(a))
        });
        (s, h)
    }

    /// The sign of `det J` on the whole map by exact subdivision (at most `budget` boxes
    /// per element, depth `max_depth`); also the smallest exact value met at box corners
    /// (`det J` units with the factor `pq / Π h`, polynomial maps; rounded to `f64`).
    pub fn sign(&self, pq: usize, max_depth: usize, budget: usize) -> (Sign<D>, f64) {
        let mut unknown = false;
        let mut min_value = f64::INFINITY;
        for (n, poly) in self.polys.iter().enumerate() {
            let element: [usize; D] = Poly::<D>::zero(self.elements.each_ref().map(|x| x.len() - 1)).index(n);
            let hprod: f64 = (0..D).map(|d| self.elements[d][element[d]]).map(|(_, a, b)| b - a).product();
            let scale = pq as f64 / hprod;
            let rational = self.weights[n].is_some();
            let mut stack = vec![(poly.clone(), 0usize)];
            let mut boxes = 0;
            while let Some((pl, depth)) = stack.pop() {
                boxes += 1;
                let corners = pl.corners();
                if !rational {
                    for x in &corners {
                        min_value = min_value.min(to_f64(x) * scale);
                    }
                }
                if corners.iter().any(|x| x.is_negative()) {
                    return (Sign::Negative { element }, min_value);
                }
                if pl.c.iter().all(|x| x.is_positive()) {
                    continue;
                }
                if depth >= max_depth || boxes >= budget {
                    unknown = true;
                    continue;
                }
                for ch in pl.children() {
                    stack.push((ch, depth + 1));
                }
            }
        }
        (if unknown { Sign::Unknown } else { Sign::Positive }, min_value)
    }
}

impl Exact<2> {
    pub fn new(map: &Surface) -> Self {
        Self::build(&map.knots, &map.control_points, map.weights.as_deref())
    }

    /// Exact sign of `det J` on element `e` at the parameter point `(u, v)` (one-sided on
    /// the element's boundary).
    pub(crate) fn sign_at(&self, e: [usize; 2], u: f64, v: f64) -> std::cmp::Ordering {
        let (s, _) = self.local(e, [u, v]);
        self.polys[self.linear(e)].eval(&s).cmp(&Q::zero())
    }

    /// Exact `det J` on element `e` at `(u, v)`, rounded to `f64`.
    pub fn value_at(&self, e: [usize; 2], u: f64, v: f64, pq: usize) -> f64 {
        let (s, h) = self.local(e, [u, v]);
        let n = self.linear(e);
        let mut val = self.polys[n].eval(&s) * Q::from_integer(BigInt::from(pq)) / h;
        if let Some(w) = &self.weights[n] {
            let wv = w.eval(&s);
            val /= &wv * &wv * &wv;
        }
        to_f64(&val)
    }
}

impl Exact<3> {
    pub fn volume(vol: &Volume) -> Self {
        Self::build(&vol.knots, &vol.control_points, vol.weights.as_deref())
    }
}

fn to_f64(x: &Q) -> f64 {
    use num_traits::ToPrimitive;
    x.to_f64().unwrap_or(f64::NAN)
}
