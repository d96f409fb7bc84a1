//! Knot vectors: open (clamped), uniform and periodic; spans, multiplicities,
//! Greville abscissae and dyadic refinement.

use crate::error::{Error, Result, MAX_CONTROL_POINTS, MAX_DEGREE};

/// Tolerance under which two knots count as equal (relative to the domain length).
pub(crate) const KNOT_TOL: f64 = 1e-12;

/// A non-decreasing knot vector `t_0 <= ... <= t_{n+p}` of a degree-`p` spline space
/// with `n` basis functions; the parameter domain is `[t_p, t_n]`.
///
/// An *open* vector has `p + 1` equal knots at each end. A *periodic* one carries the
/// full (unclamped) knots; its last `p` basis functions are identified with the first `p`
/// by the caller's control points.
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector {
    degree: usize,
    knots: Vec<f64>,
    periodic: bool,
}

impl KnotVector {
    /// Validate and wrap a full knot vector.
    pub fn new(degree: usize, knots: Vec<f64>) -> Result<Self> {
        Self::with_periodic(degree, knots, false)
    }

    /// Validate and wrap a knot vector, marking it periodic or not.
    pub(crate) fn with_periodic(degree: usize, knots: Vec<f64>, periodic: bool) -> Result<Self> {
        let bad = |reason: String| Error::Knots { context: String::new(), reason };
        if degree == 0 || degree > MAX_DEGREE {
            return Err(Error::Degree {
                context: String::new(),
                degree,
                reason: format!("must be between 1 and {MAX_DEGREE}"),
            });
        }
        if knots.len() > MAX_CONTROL_POINTS + degree + 1 {
            return Err(Error::TooLarge {
                context: String::new(),
                what: "knot vector length".into(),
                found: knots.len(),
                limit: MAX_CONTROL_POINTS + degree + 1,
            });
        }
        if knots.len() < 2 * degree + 2 {
            return Err(bad(format!("{} knots for degree {degree}: need at least {}", knots.len(), 2 * degree + 2)));
        }
        if let Some(i) = knots.iter().position(|k| !k.is_finite()) {
            return Err(Error::NonFinite { context: String::new(), what: format!("knot {i} is {}", knots[i]) });
        }
        if let Some(i) = (1..knots.len()).find(|&i| knots[i] < knots[i - 1]) {
            return Err(bad(format!("knots decrease at index {i}: {} after {}", knots[i], knots[i - 1])));
        }
        let n = knots.len() - degree - 1;
        if knots[n] - knots[degree] <= 0.0 {
            return Err(bad(format!("empty parameter domain [{}, {}]", knots[degree], knots[n])));
        }
        // No interior knot may exceed multiplicity p + 1 (basis would be discontinuous and singular).
        let kv = Self { degree, knots, periodic };
        if periodic {
            kv.check_periodic()?;
        }
        for (u, m) in kv.breaks_with_multiplicity() {
            if m > degree + 1 {
                return Err(bad(format!("knot {u} has multiplicity {m} > degree + 1 = {}", degree + 1)));
            }
        }
        Ok(kv)
    }

    /// Open (clamped) uniform knot vector on `[0, 1]` with `elements` elements and
    /// maximal smoothness `C^{p-1}`.
    pub fn open_uniform(degree: usize, elements: usize) -> Self {
        let breaks: Vec<f64> = (0..=elements).map(|i| i as f64 / elements as f64).collect();
        Self::open_from_breaks(degree, &breaks, 1)
    }

    /// Open knot vector with the given strictly increasing breakpoints; every interior
    /// break gets multiplicity `interior_mult` (1 gives `C^{p-1}`).
    pub(crate) fn open_from_breaks(degree: usize, breaks: &[f64], interior_mult: usize) -> Self {
        assert!(breaks.len() >= 2);
        let mut knots = vec![breaks[0]; degree + 1];
        for &b in &breaks[1..breaks.len() - 1] {
            knots.extend(std::iter::repeat_n(b, interior_mult));
        }
        knots.extend(std::iter::repeat_n(*breaks.last().unwrap(), degree + 1));
        Self { degree, knots, periodic: false }
    }

    /// Periodic uniform knot vector on `[0, 1]` with `elements` elements: the knots
    /// continue with spacing `1 / elements` past both ends; `elements + p` basis
    /// functions, of which the last `p` wrap onto the first `p`.
    pub fn periodic_uniform(degree: usize, elements: usize) -> Self {
        let h = 1.0 / elements as f64;
        let knots = (0..(elements + 2 * degree + 1)).map(|i| (i as f64 - degree as f64) * h).collect();
        Self { degree, knots, periodic: true }
    }

    /// A periodic knot vector from the knots of one period: `period_knots` are
    /// `t_p <= ... <= t_{p + d - 1}` in `[a, a + period)` with `t_p = a`, `d` of them (the
    /// dimension of the periodic space); the stored vector continues them periodically,
    /// `t_{k + d} = t_k + period`, `p` knots past both ends (`d + 2p + 1` knots in all).
    pub(crate) fn periodic_from_period(degree: usize, period_knots: &[f64], period: f64) -> Result<Self> {
        let d = period_knots.len();
        if d == 0 || period.is_nan() || period <= 0.0 {
            return Err(Error::Knots {
                context: String::new(),
                reason: format!("a periodic knot vector needs knots in one period and a period > 0, got {d} knots and period {period}"),
            });
        }
        let ext = |k: isize| {
            let (q, r) = (k.div_euclid(d as isize), k.rem_euclid(d as isize) as usize);
            period_knots[r] + q as f64 * period
        };
        let p = degree as isize;
        let knots: Vec<f64> = (-p..(d as isize) + p + 1).map(ext).collect();
        Self::with_periodic(degree, knots, true)
    }

    /// For a periodic vector: `t_{k + d} - t_k` equals the period `t_{p+d} - t_p` for every
    /// stored `k` (to [`KNOT_TOL`]), `d = n - p >= 1`.
    fn check_periodic(&self) -> Result<()> {
        let (p, n) = (self.degree, self.num_basis());
        let bad = |reason: String| Err(Error::Knots { context: String::new(), reason });
        if n <= p {
            return bad(format!("periodic degree-{p} vector with {n} basis functions: need more than {p}"));
        }
        let d = n - p;
        let period = self.knots[p + d] - self.knots[p];
        for k in 0..self.knots.len() - d {
            let gap = self.knots[k + d] - self.knots[k];
            if (gap - period).abs() > KNOT_TOL * period.abs().max(1.0) * 16.0 {
                return bad(format!("not periodic: knots {k} and {} differ by {gap}, the period is {period}", k + d));
            }
        }
        Ok(())
    }

    /// Dimension of the spline space: `n` for an open vector, `n - p` distinct
    /// functions for a periodic one (the last `p` of the `n` stored functions repeat the
    /// first `p`: control point `k >= n - p` equals control point `k - (n - p)`).
    pub fn dim(&self) -> usize {
        if self.periodic {
            self.num_basis() - self.degree
        } else {
            self.num_basis()
        }
    }

    /// The knots of one period of a periodic vector, `t_p, ..., t_{p + d - 1}`.
    pub(crate) fn period_knots(&self) -> &[f64] {
        &self.knots[self.degree..self.degree + self.dim()]
    }

    /// The bi-infinite periodic continuation `t_k` for any integer `k` of a periodic
    /// vector (`t_{k + d} = t_k + L`), equal to the stored knot for `0 <= k < len`.
    pub(crate) fn extended(&self, k: isize) -> f64 {
        if !self.periodic || (k >= 0 && (k as usize) < self.knots.len()) {
            return self.knots[k.clamp(0, self.knots.len() as isize - 1) as usize];
        }
        let d = self.dim() as isize;
        let p = self.degree as isize;
        let j = k - p;
        let (q, r) = (j.div_euclid(d), j.rem_euclid(d));
        self.knots[(r + p) as usize] + q as f64 * self.length()
    }

    /// Polynomial degree `p`.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// All knots, repeated ones included.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Whether the vector was declared periodic.
    pub fn is_periodic(&self) -> bool {
        self.periodic
    }

    /// Number of basis functions `n = len - p - 1`.
    pub fn num_basis(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// Parameter domain `[t_p, t_n]`.
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.num_basis()])
    }

    /// Whether both ends are clamped (`p + 1` equal knots).
    pub(crate) fn is_open(&self) -> bool {
        let p = self.degree;
        let k = &self.knots;
        let n = k.len();
        k[..=p].iter().all(|&t| t == k[0]) && k[n - p - 1..].iter().all(|&t| t == k[n - 1])
    }

    /// Knot span index `s` with `t_s <= u < t_{s+1}`, `p <= s < n`; the right end of the
    /// domain belongs to the last non-empty span. Values outside are clamped.
    pub(crate) fn find_span(&self, u: f64) -> usize {
        let p = self.degree;
        let n = self.num_basis();
        let k = &self.knots;
        if u >= k[n] {
            let mut s = n - 1;
            while s > p && k[s] == k[n] {
                s -= 1;
            }
            return s;
        }
        if u <= k[p] {
            let mut s = p;
            while s + 1 < n && k[s + 1] == k[p] {
                s += 1;
            }
            return s;
        }
        // binary search in [p, n)
        let (mut lo, mut hi) = (p, n);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if u < k[mid] {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }

    /// Multiplicity of the value `u` in the vector (0 when it is not a knot).
    pub fn multiplicity(&self, u: f64) -> usize {
        let tol = KNOT_TOL * self.length();
        self.knots.iter().filter(|&&t| (t - u).abs() <= tol).count()
    }

    #[cfg(test)]
    /// Continuity `C^{p - m}` of the basis at the knot `u` of multiplicity `m`.
    pub(crate) fn continuity_at(&self, u: f64) -> isize {
        self.degree as isize - self.multiplicity(u) as isize
    }

    /// Length of the parameter domain.
    pub fn length(&self) -> f64 {
        let (a, b) = self.domain();
        b - a
    }

    /// Distinct knots inside the domain (the element boundaries), with multiplicities.
    pub fn breaks_with_multiplicity(&self) -> Vec<(f64, usize)> {
        let (a, b) = self.domain();
        let mut out: Vec<(f64, usize)> = Vec::new();
        for &t in &self.knots {
            if t < a || t > b {
                continue;
            }
            match out.last_mut() {
                Some((u, m)) if *u == t => *m += 1,
                _ => out.push((t, 1)),
            }
        }
        out
    }

    /// Distinct knots inside the domain: the element boundaries.
    pub fn breaks(&self) -> Vec<f64> {
        self.breaks_with_multiplicity().into_iter().map(|(u, _)| u).collect()
    }

    /// Number of non-empty elements in the domain.
    pub fn num_elements(&self) -> usize {
        self.breaks().len() - 1
    }

    /// The elements as `(span, a, b)`: span index `s` with `[t_s, t_{s+1}] = [a, b]`, `a < b`.
    pub fn elements(&self) -> Vec<(usize, f64, f64)> {
        let (p, n) = (self.degree, self.num_basis());
        (p..n).filter(|&s| self.knots[s + 1] > self.knots[s]).map(|s| (s, self.knots[s], self.knots[s + 1])).collect()
    }

    /// Greville abscissae `(t_{i+1} + ... + t_{i+p}) / p`, one per basis function.
    pub fn greville(&self) -> Vec<f64> {
        let p = self.degree;
        (0..self.num_basis()).map(|i| self.knots[i + 1..=i + p].iter().sum::<f64>() / p as f64).collect()
    }

    /// A copy with the knots `new` inserted (kept sorted). In a periodic vector each new
    /// knot is inserted once per period (`u` taken modulo the period).
    pub fn with_inserted(&self, new: &[f64]) -> Self {
        if self.periodic {
            let (a, l) = (self.domain().0, self.length());
            let mut period: Vec<f64> = self.period_knots().to_vec();
            for &u in new {
                let w = a + (u - a).rem_euclid(l);
                period.push(if w >= a + l { a } else { w });
            }
            period.sort_by(f64::total_cmp);
            return Self::periodic_from_period(self.degree, &period, l)
                .expect("inserting keeps a valid periodic vector");
        }
        let mut knots = self.knots.clone();
        knots.extend_from_slice(new);
        knots.sort_by(f64::total_cmp);
        Self { degree: self.degree, knots, periodic: self.periodic }
    }

    /// The knots to insert to bisect the given elements (by span index).
    pub(crate) fn midpoints_of(&self, spans: &[usize]) -> Vec<f64> {
        spans.iter().map(|&s| 0.5 * (self.knots[s] + self.knots[s + 1])).collect()
    }

    /// Dyadic refinement: every non-empty element halved.
    pub fn halved(&self) -> Self {
        let spans: Vec<usize> = self.elements().iter().map(|e| e.0).collect();
        self.with_inserted(&self.midpoints_of(&spans))
    }

    /// The same vector mapped affinely so that its domain is `[0, 1]`.
    pub fn normalized(&self) -> Self {
        let (a, b) = self.domain();
        let knots = self
            .knots
            .iter()
            .map(|&t| {
                if t == a {
                    0.0
                } else if t == b {
                    1.0
                } else {
                    (t - a) / (b - a)
                }
            })
            .collect();
        Self { degree: self.degree, knots, periodic: self.periodic }
    }

    /// Union of two open vectors of the same degree and domain: every break with the
    /// larger of its two multiplicities (knots closer than [`KNOT_TOL`] merge).
    pub(crate) fn union(&self, other: &Self) -> Result<Self> {
        if self.degree != other.degree || self.domain() != other.domain() || self.periodic != other.periodic {
            return Err(Error::Invalid(format!(
                "knot union needs equal degree and domain, got p={} on {:?} and p={} on {:?}",
                self.degree,
                self.domain(),
                other.degree,
                other.domain()
            )));
        }
        let a = self.breaks_with_multiplicity();
        let b = other.breaks_with_multiplicity();
        let tol = KNOT_TOL * self.length();
        let (mut i, mut j) = (0, 0);
        let mut merged: Vec<(f64, usize)> = Vec::new();
        while i < a.len() || j < b.len() {
            if j >= b.len() || (i < a.len() && a[i].0 < b[j].0 - tol) {
                merged.push(a[i]);
                i += 1;
            } else if i >= a.len() || b[j].0 < a[i].0 - tol {
                merged.push(b[j]);
                j += 1;
            } else {
                merged.push((a[i].0, a[i].1.max(b[j].1)));
                i += 1;
                j += 1;
            }
        }
        let p = self.degree;
        if self.periodic {
            // the end break repeats the start break of the period
            let period: Vec<f64> =
                merged[..merged.len() - 1].iter().flat_map(|&(u, m)| std::iter::repeat_n(u, m)).collect();
            return Self::periodic_from_period(p, &period, self.length());
        }
        let mut knots = Vec::new();
        let last = merged.len() - 1;
        for (k, (u, m)) in merged.into_iter().enumerate() {
            let m = if k == 0 || k == last { p + 1 } else { m };
            knots.extend(std::iter::repeat_n(u, m));
        }
        Ok(Self { degree: p, knots, periodic: false })
    }

    /// Whether every knot of `coarse` (with multiplicity) occurs in `self`: the coarse
    /// spline space is then nested in this one.
    pub fn contains(&self, coarse: &Self) -> bool {
        if coarse.degree != self.degree || coarse.periodic != self.periodic {
            return false;
        }
        let tol = KNOT_TOL * self.length().max(coarse.length());
        if self.periodic && (self.domain().0 != coarse.domain().0 || (self.length() - coarse.length()).abs() > tol) {
            return false;
        }
        let (mine, theirs) = self.compared_knots(coarse);
        let mut j = 0;
        for &t in theirs {
            while j < mine.len() && mine[j] < t - tol {
                j += 1;
            }
            if j >= mine.len() || (mine[j] - t).abs() > tol {
                return false;
            }
            j += 1;
        }
        true
    }

    /// The knots that nesting compares: all stored knots of open vectors, one period of
    /// periodic ones.
    fn compared_knots<'a>(&'a self, coarse: &'a Self) -> (&'a [f64], &'a [f64]) {
        if self.periodic {
            (self.period_knots(), coarse.period_knots())
        } else {
            (&self.knots, &coarse.knots)
        }
    }

    /// Multiset difference `self \ coarse`: the knots to insert into `coarse` to obtain
    /// `self` (one period of them for periodic vectors), or `None` when `coarse` is not
    /// contained in `self`.
    pub fn difference(&self, coarse: &Self) -> Option<Vec<f64>> {
        if !self.contains(coarse) {
            return None;
        }
        let tol = KNOT_TOL * self.length().max(coarse.length());
        let (mine, theirs) = self.compared_knots(coarse);
        let mut out = Vec::new();
        let mut j = 0;
        for &t in mine {
            if j < theirs.len() && (theirs[j] - t).abs() <= tol {
                j += 1;
            } else {
                out.push(t);
            }
        }
        Some(out)
    }

    /// The vector of degree `p + 1` spanning the degree-elevated space: every break's
    /// multiplicity raised by one (continuity is kept).
    pub(crate) fn elevated(&self) -> Self {
        let mut knots = Vec::with_capacity(self.knots.len() + self.num_elements() + 1);
        let bm = self.breaks_with_multiplicity();
        let p = self.degree;
        if self.periodic {
            // one more copy of every distinct knot of the period
            let mut period = Vec::with_capacity(2 * self.dim());
            let mut prev = f64::NAN;
            for &t in self.period_knots() {
                if t != prev {
                    period.push(t);
                    prev = t;
                }
                period.push(t);
            }
            return Self::periodic_from_period(p + 1, &period, self.length()).expect("elevation keeps periodicity");
        }
        if !self.is_open() {
            // Raise every distinct knot (also those outside the domain).
            let mut prev = f64::NAN;
            for &t in &self.knots {
                if t != prev {
                    knots.push(t);
                    prev = t;
                }
                knots.push(t);
            }
            return Self { degree: p + 1, knots, periodic: self.periodic };
        }
        let last = bm.len() - 1;
        for (k, (u, m)) in bm.into_iter().enumerate() {
            let m = if k == 0 || k == last { p + 2 } else { m + 1 };
            knots.extend(std::iter::repeat_n(u, m));
        }
        Self { degree: p + 1, knots, periodic: false }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_and_multiplicities() {
        let kv = KnotVector::new(2, vec![0., 0., 0., 0.25, 0.5, 0.5, 1., 1., 1.]).unwrap();
        assert_eq!(kv.num_basis(), 6);
        assert_eq!(kv.find_span(0.0), 2);
        assert_eq!(kv.find_span(0.3), 3);
        assert_eq!(kv.find_span(0.5), 5);
        assert_eq!(kv.find_span(1.0), 5);
        assert_eq!(kv.multiplicity(0.5), 2);
        assert_eq!(kv.continuity_at(0.5), 0);
        assert_eq!(kv.breaks(), vec![0., 0.25, 0.5, 1.]);
        assert_eq!(kv.elements().len(), 3);
        let g = kv.greville();
        assert_eq!(g[0], 0.0);
        assert_eq!(*g.last().unwrap(), 1.0);
        assert!(g.windows(2).all(|w| w[0] <= w[1]));
    }

    #[test]
    fn halving_doubles_elements_and_nests() {
        let kv = KnotVector::open_uniform(3, 5);
        let h = kv.halved();
        assert_eq!(h.num_elements(), 10);
        assert!(h.contains(&kv));
        assert_eq!(h.difference(&kv).unwrap().len(), 5);
        assert!(!kv.contains(&h));
    }

    #[test]
    fn union_takes_max_multiplicity() {
        let a = KnotVector::new(2, vec![0., 0., 0., 0.5, 1., 1., 1.]).unwrap();
        let b = KnotVector::new(2, vec![0., 0., 0., 0.25, 0.5, 0.5, 1., 1., 1.]).unwrap();
        let u = a.union(&b).unwrap();
        assert_eq!(u.knots(), b.knots());
    }

    #[test]
    fn rejects_bad_vectors() {
        assert!(matches!(KnotVector::new(0, vec![0., 1.]), Err(Error::Degree { .. })));
        assert!(matches!(KnotVector::new(1, vec![0., 0., 1.]), Err(Error::Knots { .. })));
        assert!(matches!(KnotVector::new(1, vec![0., 0.5, 0.2, 1.]), Err(Error::Knots { .. })));
        assert!(matches!(KnotVector::new(1, vec![0., 0., f64::NAN, 1., 1.]), Err(Error::NonFinite { .. })));
        assert!(matches!(KnotVector::new(1, vec![0., 0., 0., 0.]), Err(Error::Knots { .. })));
    }

    #[test]
    fn periodic_uniform_has_wrapping_basis() {
        let kv = KnotVector::periodic_uniform(3, 6);
        assert_eq!(kv.num_basis(), 9);
        assert_eq!(kv.domain(), (0.0, 1.0));
        assert!(kv.is_periodic());
        assert!(!kv.is_open());
    }
}
