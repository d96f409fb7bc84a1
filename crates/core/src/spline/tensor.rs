//! Tensor-product B-spline and NURBS maps with `P` parameters and values in `R^D`, the
//! one core under [`Surface`](crate::spline::surface::Surface) (`P = D = 2`, paper eq. 1),
//! [`Face`](crate::spline::face::Face) (`P = 2`, `D = 3`) and
//! [`Volume`](crate::spline::volume::Volume) (`P = D = 3`, §11.1):
//! `x(u) = Σ_i w_i c_i Π_d N^d_{i_d}(u_d) / Σ_i w_i Π_d N^d_{i_d}(u_d)` (`w = 1` for
//! B-splines). Control point `i = (i_0, .., i_{P-1})` is stored at
//! `Σ_d i_d Π_{e<d} n_e` (first index fastest).
//!
//! Knot insertion and degree elevation apply the univariate operators of
//! `spline::refine` (periodic directions included) to the homogeneous
//! coordinates `(w c, w)`, so the map is kept exactly (to rounding). Maps into the plane
//! keep the rounding of the planar operators (weights through [`Csr::apply`], polynomial
//! nets not divided by the transformed unit weights); maps into space sum `(w c, w)`
//! together and always divide. The two differ only in rounding; each is kept so that
//! solves stay bit-identical.

use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;
use crate::spline::basis::BasisDerivs;
use crate::spline::bezier::BezierExtraction;
use crate::spline::knots::KnotVector;
use crate::spline::refine::{elevation, prolongation};

/// Every coordinate of every point finite ([`Error::NonFinite`] naming `what` and its index).
pub(crate) fn check_points<const D: usize>(pts: &[[f64; D]], what: &str) -> Result<()> {
    for (i, p) in pts.iter().enumerate() {
        if p.iter().any(|x| !x.is_finite()) {
            let p = p.map(|x| x.to_string()).join(", ");
            return Err(Error::NonFinite { context: String::new(), what: format!("{what} {i} is ({p})") });
        }
    }
    Ok(())
}

/// `expected` weights, finite and positive ([`Error::Length`], [`Error::NonFinite`],
/// [`Error::Weight`]).
pub(crate) fn check_weights(w: &[f64], expected: usize) -> Result<()> {
    if w.len() != expected {
        return Err(Error::Length { context: String::new(), what: "weights".into(), found: w.len(), expected });
    }
    for (i, &x) in w.iter().enumerate() {
        if !x.is_finite() {
            return Err(Error::NonFinite { context: String::new(), what: format!("weight {i} is {x}") });
        }
        if x <= 0.0 {
            return Err(Error::Weight { context: String::new(), index: i, value: x });
        }
    }
    Ok(())
}

/// A tensor-product B-spline or NURBS map `[0,1]^P → R^D` (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct TensorSpline<const P: usize, const D: usize> {
    /// Knot vectors, one per parameter direction.
    pub knots: [KnotVector; P],
    /// Control points, first index fastest.
    pub control_points: Vec<[f64; D]>,
    /// Positive weights (NURBS) or `None`.
    pub weights: Option<Vec<f64>>,
}

/// A homogeneous point `(w c, w)`.
pub(crate) type Homogeneous<const D: usize> = ([f64; D], f64);

/// For every periodic direction of a basis of dimension `d` with `n` stored functions:
/// the stored control points (and weights) `i_dir >= d` must repeat `i_dir - d`
/// (wrapped indices, see [`crate::spline::periodic`]), to `1e-12` relative to the
/// largest coordinate.
pub(crate) fn check_wrapped<const D: usize>(
    knots: &[KnotVector],
    pts: &[[f64; D]],
    weights: Option<&[f64]>,
) -> Result<()> {
    let shape: Vec<usize> = knots.iter().map(KnotVector::num_basis).collect();
    let scale = pts.iter().flatten().fold(1.0f64, |m, x| m.max(x.abs()));
    let show = |p: &[f64; D]| p.map(|x| x.to_string()).join(", ");
    for (dir, kv) in knots.iter().enumerate().filter(|(_, kv)| kv.is_periodic()) {
        let (stride, n, d) = (shape[..dir].iter().product::<usize>(), shape[dir], kv.dim());
        for (a, p) in pts.iter().enumerate().filter(|(a, _)| (a / stride) % n >= d) {
            let b = a - d * stride;
            let gap = (0..D).map(|c| (p[c] - pts[b][c]).abs()).fold(0.0, f64::max);
            let wgap = weights.map_or(0.0, |w| (w[a] - w[b]).abs() / w[b]);
            if gap > 1e-12 * scale || wgap > 1e-12 {
                return Err(Error::Invalid(format!(
                    "periodic control points must wrap in direction {dir}: stored point {a} ({}) must repeat point {b} ({}) (the last p of {n} repeat the first p)",
                    show(p),
                    show(&pts[b])
                )));
            }
        }
    }
    Ok(())
}

/// `op` applied to the homogeneous coordinates `(w c, w)` of a (possibly rational) net,
/// the weights through [`Csr::apply`]; a polynomial net is mapped as it is.
pub(crate) fn apply_homogeneous<const D: usize>(
    op: &Csr,
    cps: &[[f64; D]],
    weights: Option<&[f64]>,
) -> (Vec<[f64; D]>, Option<Vec<f64>>) {
    let rows = |x: &[[f64; D]]| -> Vec<[f64; D]> {
        (0..op.nrows)
            .map(|i| {
                let mut p = [0.0; D];
                for (j, v) in op.row(i) {
                    for c in 0..D {
                        p[c] += v * x[j][c];
                    }
                }
                p
            })
            .collect()
    };
    match weights {
        None => (rows(cps), None),
        Some(w) => {
            let wc: Vec<[f64; D]> = cps.iter().zip(w).map(|(c, &w)| c.map(|x| x * w)).collect();
            let wn = op.apply(w);
            let cn = rows(&wc).into_iter().zip(&wn).map(|(c, &w)| c.map(|x| x / w)).collect();
            (cn, Some(wn))
        }
    }
}

/// `op` (`n_new x n_dir`) applied along direction `dir` of a homogeneous tensor net of
/// shape `shape` (first index fastest), `(w c, w)` summed together row by row.
pub(crate) fn apply_along<const P: usize, const D: usize>(
    op: &Csr,
    dir: usize,
    shape: [usize; P],
    h: &[Homogeneous<D>],
) -> Vec<Homogeneous<D>> {
    let inner: usize = shape[..dir].iter().product();
    let outer: usize = shape[dir + 1..].iter().product();
    let mut out = vec![([0.0; D], 0.0); inner * op.nrows * outer];
    for o in 0..outer {
        for i in 0..inner {
            let (base_in, base_out) = (o * inner * shape[dir] + i, o * inner * op.nrows + i);
            for r in 0..op.nrows {
                let mut acc = ([0.0; D], 0.0);
                for (c, v) in op.row(r) {
                    let x = &h[base_in + c * inner];
                    for z in 0..D {
                        acc.0[z] += v * x.0[z];
                    }
                    acc.1 += v * x.1;
                }
                out[base_out + r * inner] = acc;
            }
        }
    }
    out
}

/// The points `c = (w c) / w` of a homogeneous net.
pub(crate) fn projected<const D: usize>(h: &[Homogeneous<D>]) -> Vec<[f64; D]> {
    h.iter().map(|(p, w)| p.map(|x| x / w)).collect()
}

impl<const P: usize, const D: usize> TensorSpline<P, D> {
    /// Validate lengths, finiteness and weights, and that the control points of a periodic
    /// direction wrap ([`crate::spline::periodic`]); weights that are all 1 are dropped.
    pub(crate) fn checked(
        knots: [KnotVector; P],
        control_points: Vec<[f64; D]>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self> {
        let n: usize = knots.iter().map(KnotVector::num_basis).product();
        if control_points.len() != n {
            return Err(Error::Length {
                context: String::new(),
                what: "control_points".into(),
                found: control_points.len(),
                expected: n,
            });
        }
        check_points(&control_points, "control point")?;
        if let Some(w) = &weights {
            check_weights(w, n)?;
        }
        check_wrapped(&knots, &control_points, weights.as_deref())?;
        let weights = weights.filter(|w| w.iter().any(|&x| x != 1.0));
        Ok(Self { knots, control_points, weights })
    }

    /// Number of basis functions per direction.
    pub fn shape(&self) -> [usize; P] {
        self.knots.each_ref().map(KnotVector::num_basis)
    }

    /// Degrees per direction.
    pub fn degrees(&self) -> [usize; P] {
        self.knots.each_ref().map(KnotVector::degree)
    }

    /// Linear index `Σ_d i_d Π_{e<d} n_e` of control point `i`.
    pub fn index(&self, i: [usize; P]) -> usize {
        let shape = self.shape();
        (0..P).rev().fold(0, |lin, d| lin * shape[d] + i[d])
    }

    #[cfg(test)]
    /// The multi-index of a linear index.
    pub(crate) fn unindex(&self, mut lin: usize) -> [usize; P] {
        let shape = self.shape();
        std::array::from_fn(|d| {
            let i = lin % shape[d];
            lin /= shape[d];
            i
        })
    }

    /// Bézier extraction: per direction, the univariate operators of `spline::bezier`
    /// (`N_i = Σ_k C_ik B_k^p` on each element).
    pub(crate) fn extraction(&self) -> Result<[BezierExtraction; P]> {
        let ex = self.knots.iter().map(BezierExtraction::new).collect::<Result<Vec<_>>>()?;
        ex.try_into().map_err(|_| Error::Invalid("one extraction per direction".into()))
    }

    /// The homogeneous Bézier net `(w x, w)` of element `e` (indices of the element per
    /// direction), `Π_d (p_d + 1)` points, first index fastest:
    /// `H_a = Σ_i (w_i c_i, w_i) Π_d C^d_{i_d a_d}` with the extraction operators `C^d`
    /// of [`TensorSpline::extraction`]. The control points are visited first index
    /// fastest and each product is formed from the last direction down.
    pub(crate) fn bezier_net(&self, ex: &[BezierExtraction; P], e: [usize; P]) -> Vec<Homogeneous<D>> {
        let deg = self.degrees();
        let n: [usize; P] = std::array::from_fn(|d| deg[d] + 1);
        let first: [usize; P] = std::array::from_fn(|d| ex[d].elements[e[d]].0 - deg[d]);
        let ops: [&[f64]; P] = std::array::from_fn(|d| ex[d].ops[e[d]].as_slice());
        let len: usize = n.iter().product();
        let local: Vec<[usize; P]> = (0..len)
            .map(|mut lin| {
                std::array::from_fn(|d| {
                    let i = lin % n[d];
                    lin /= n[d];
                    i
                })
            })
            .collect();
        let mut net = vec![([0.0; D], 0.0); len];
        for i in &local {
            let g = self.index(std::array::from_fn(|d| first[d] + i[d]));
            let (c, w) = (self.control_points[g], self.weight(g));
            let h: [f64; D] = std::array::from_fn(|k| w * c[k]);
            for (out, a) in net.iter_mut().zip(&local) {
                let f = (0..P).rev().fold(1.0, |f, d| f * ops[d][i[d] * n[d] + a[d]]);
                if f == 0.0 {
                    continue;
                }
                for k in 0..D {
                    out.0[k] += f * h[k];
                }
                out.1 += f * w;
            }
        }
        net
    }

    /// Weight of control point `k` (1 for B-splines).
    pub fn weight(&self, k: usize) -> f64 {
        self.weights.as_ref().map_or(1.0, |w| w[k])
    }

    /// The same map with knot domains mapped to `[0, 1]`.
    pub fn normalized(&self) -> Self {
        Self { knots: self.knots.each_ref().map(KnotVector::normalized), ..self.clone() }
    }

    /// The sums `h_m = ∂^m Σ_i (w_i c_i, w_i) Π_d N^d_{i_d}` for the derivative orders
    /// `m ∈ orders` (`m_d <= 2`), from precomputed univariate basis values; the functions
    /// are visited first index fastest and each product is formed from direction 0 up.
    pub(crate) fn homogeneous_derivs(&self, b: [&BasisDerivs; P], orders: &[[usize; P]], h: &mut [Homogeneous<D>]) {
        let (shape, first) = (self.shape(), b.map(BasisDerivs::first));
        let mut local = [0usize; P];
        'points: loop {
            let lin = (0..P).rev().fold(0, |lin, d| lin * shape[d] + first[d] + local[d]);
            let (w, c) = (self.weight(lin), self.control_points[lin]);
            for (m, hm) in orders.iter().zip(h.iter_mut()) {
                let mut n = b[0].d[m[0]][local[0]];
                for d in 1..P {
                    n *= b[d].d[m[d]][local[d]];
                }
                let n = n * w;
                for z in 0..D {
                    hm.0[z] += n * c[z];
                }
                hm.1 += n;
            }
            for d in 0..P {
                if local[d] < b[d].degree {
                    local[d] += 1;
                    continue 'points;
                }
                local[d] = 0;
            }
            return;
        }
    }

    /// `x` and its first derivatives `x_{u_d}` by the quotient rule
    /// `x_{u_d} = (∂_d (w x) - w_{u_d} x) / w`, from precomputed basis values (with at least
    /// first derivatives).
    pub(crate) fn first_derivs(&self, b: [&BasisDerivs; P]) -> ([f64; D], [[f64; D]; P]) {
        let orders: [[usize; P]; 4] = std::array::from_fn(|a| std::array::from_fn(|d| usize::from(a == d + 1)));
        let mut h = [([0.0; D], 0.0); 4];
        self.homogeneous_derivs(b, &orders[..=P], &mut h[..=P]);
        let w = h[0].1;
        let x = h[0].0.map(|v| v / w);
        (x, std::array::from_fn(|a| std::array::from_fn(|c| (h[a + 1].0[c] - h[a + 1].1 * x[c]) / w)))
    }

    /// The homogeneous control net `(w c, w)`.
    pub(crate) fn homogeneous(&self) -> Vec<Homogeneous<D>> {
        self.control_points.iter().enumerate().map(|(k, c)| (c.map(|x| self.weight(k) * x), self.weight(k))).collect()
    }

    /// The same map with the univariate operator `op` (onto the basis `kv`) applied in
    /// direction `dir` (planar rounding for `D = 2`, see the module docs).
    fn mapped(&self, dir: usize, kv: KnotVector, op: &Csr) -> Self {
        let mut knots = self.knots.clone();
        knots[dir] = kv;
        if D == 2 {
            let shape = self.shape();
            let (inner, outer) = (shape[..dir].iter().product(), shape[dir + 1..].iter().product());
            let full = Csr::identity(outer).kron(op).kron(&Csr::identity(inner));
            let (control_points, weights) = apply_homogeneous(&full, &self.control_points, self.weights.as_deref());
            return Self { knots, control_points, weights };
        }
        let h = apply_along(op, dir, self.shape(), &self.homogeneous());
        let weights = self.weights.as_ref().map(|_| h.iter().map(|p| p.1).collect());
        Self { knots, control_points: projected(&h), weights }
    }

    /// Knot insertion in direction `dir`: the same map on the finer knot vector `fine`
    /// (which must contain this one's).
    pub(crate) fn refined_in(&self, dir: usize, fine: &KnotVector) -> Result<Self> {
        let op = prolongation(&self.knots[dir], fine)?;
        Ok(self.mapped(dir, fine.clone(), &op))
    }

    /// The same map with the degree in direction `dir` raised by one (continuity kept).
    pub(crate) fn elevated_in(&self, dir: usize) -> Result<Self> {
        let (kv, op) = elevation(&self.knots[dir])?;
        Ok(self.mapped(dir, kv, &op))
    }

    /// The prolongation `P_{P-1} ⊗ .. ⊗ P_0` from this map's basis to the finer tensor
    /// basis `fine`.
    pub(crate) fn prolongation_to(&self, fine: &[KnotVector; P]) -> Result<Csr> {
        let mut op = prolongation(&self.knots[P - 1], &fine[P - 1])?;
        for d in (0..P - 1).rev() {
            op = op.kron(&prolongation(&self.knots[d], &fine[d])?);
        }
        Ok(op)
    }

    /// The same map on the finer tensor basis `fine` (knot insertion in every direction;
    /// for `D = 2` with the whole `Self::prolongation_to` at once).
    pub fn refined(&self, fine: &[KnotVector; P]) -> Result<Self> {
        if D == 2 {
            let op = self.prolongation_to(fine)?;
            let (control_points, weights) = apply_homogeneous(&op, &self.control_points, self.weights.as_deref());
            return Ok(Self { knots: fine.clone(), control_points, weights });
        }
        let mut v = self.clone();
        for (d, kv) in fine.iter().enumerate() {
            if kv != &v.knots[d] {
                v = v.refined_in(d, kv)?;
            }
        }
        Ok(v)
    }
}

impl<const D: usize> TensorSpline<2, D> {
    /// The same map with the parameters exchanged, `g(s, t) = f(t, s)` (control point
    /// `(i, j)` becomes `(j, i)`); flips the orientation.
    pub fn transposed(&self) -> Self {
        let [ns, nt] = self.shape();
        let perm = |k: usize| (k % nt) * ns + k / nt;
        Self {
            knots: [self.knots[1].clone(), self.knots[0].clone()],
            control_points: (0..ns * nt).map(|k| self.control_points[perm(k)]).collect(),
            weights: self.weights.as_ref().map(|w| (0..ns * nt).map(|k| w[perm(k)]).collect()),
        }
    }
}

#[cfg(test)]
mod tests;
