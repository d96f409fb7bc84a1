//! Trivariate tensor-product maps `x: [0,1]³ → R³` (volumes; paper §11.1, Fig. 23): a
//! basis (three knot vectors) plus control points,
//! `x(ξ, η, ζ) = Σ_ijk c_ijk N_i(ξ) M_j(η) L_k(ζ)`, or for NURBS
//! `x = Σ w_ijk c_ijk N_i M_j L_k / Σ w_ijk N_i M_j L_k`.
//!
//! Control point `(i, j, k)` is stored at `(k n_η + j) n_ξ + i` (`ξ` fastest, then `η`).
//! Knot insertion and degree elevation act on one direction at a time, on the
//! homogeneous coordinates `(w x, w y, w z, w)`, with the univariate operators of
//! `spline::refine` (so periodic directions work as for curves); the map is
//! reproduced exactly (to rounding). Bézier extraction per element is the tensor product
//! of the univariate operators of `spline::bezier`.

use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;
use crate::spline::basis::BasisDerivs;
use crate::spline::bezier::BezierExtraction;
use crate::spline::knots::KnotVector;
use crate::spline::refine::{elevation, prolongation};

/// A point or vector in space.
pub type Point3 = [f64; 3];

/// A trivariate tensor-product B-spline or NURBS map.
#[derive(Debug, Clone, PartialEq)]
pub struct Volume {
    /// Knot vectors in `ξ`, `η`, `ζ`.
    pub knots: [KnotVector; 3],
    /// Control points, `ξ` index fastest, then `η`.
    pub control_points: Vec<Point3>,
    /// Positive weights (NURBS) or `None`.
    pub weights: Option<Vec<f64>>,
}

/// Value and first derivatives of a volume at a parameter point.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct VolumeDerivs {
    /// `x`.
    pub x: Point3,
    /// `d[a] = ∂x/∂u_a` for `u = (ξ, η, ζ)`: the columns of `J`.
    pub d: [Point3; 3],
}

/// `a · (b × c)`, the determinant of the matrix with columns `a`, `b`, `c`.
pub fn triple(a: Point3, b: Point3, c: Point3) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0])
}

impl VolumeDerivs {
    /// `det J = x_ξ · (x_η × x_ζ)`.
    pub fn det_j(&self) -> f64 {
        triple(self.d[0], self.d[1], self.d[2])
    }
}

/// The homogeneous control net `(w x, w y, w z, w)` of a volume.
type Homogeneous = Vec<[f64; 4]>;

/// Apply the univariate operator `op` (`n_new x n_dir`) along direction `dir` of a
/// tensor array of shape `shape` (first index fastest).
fn apply_along(op: &Csr, dir: usize, shape: [usize; 3], h: &[[f64; 4]]) -> (Homogeneous, [usize; 3]) {
    let mut out_shape = shape;
    out_shape[dir] = op.nrows;
    let stride = |s: [usize; 3], d: usize| match d {
        0 => 1,
        1 => s[0],
        _ => s[0] * s[1],
    };
    let (si, so) = (stride(shape, dir), stride(out_shape, dir));
    let mut out = vec![[0.0; 4]; out_shape.iter().product()];
    // the two other directions
    let others: Vec<usize> = (0..3).filter(|&d| d != dir).collect();
    for a in 0..shape[others[0]] {
        for b in 0..shape[others[1]] {
            let base_in = a * stride(shape, others[0]) + b * stride(shape, others[1]);
            let base_out = a * stride(out_shape, others[0]) + b * stride(out_shape, others[1]);
            for r in 0..op.nrows {
                let mut acc = [0.0; 4];
                for (c, v) in op.row(r) {
                    let x = &h[base_in + c * si];
                    for z in 0..4 {
                        acc[z] += v * x[z];
                    }
                }
                out[base_out + r * so] = acc;
            }
        }
    }
    (out, out_shape)
}

impl Volume {
    /// Validate lengths, finiteness and weights, and that the control points of a
    /// periodic direction wrap (the last `p` layers repeat the first `p`, to `1e-12`
    /// relative to the largest coordinate).
    pub fn new(knots: [KnotVector; 3], control_points: Vec<Point3>, weights: Option<Vec<f64>>) -> Result<Self> {
        let shape = knots.each_ref().map(KnotVector::num_basis);
        let n: usize = shape.iter().product();
        if control_points.len() != n {
            return Err(Error::Length {
                context: String::new(),
                what: "control_points".into(),
                found: control_points.len(),
                expected: n,
            });
        }
        if let Some((i, p)) = control_points.iter().enumerate().find(|(_, p)| p.iter().any(|x| !x.is_finite())) {
            return Err(Error::NonFinite {
                context: String::new(),
                what: format!("control point {i} is ({}, {}, {})", p[0], p[1], p[2]),
            });
        }
        if let Some(w) = &weights {
            crate::spline::curve::check_weights(w, n)?;
        }
        let v = Self { knots, control_points, weights };
        for d in 0..3 {
            if v.knots[d].is_periodic() {
                v.check_wrapped(d)?;
            }
        }
        let weights = v.weights.filter(|w| w.iter().any(|&x| x != 1.0));
        Ok(Self { weights, ..v })
    }

    fn check_wrapped(&self, dir: usize) -> Result<()> {
        let shape = self.shape();
        let dim = self.knots[dir].dim();
        let scale = self.control_points.iter().flatten().fold(1.0f64, |m, x| m.max(x.abs()));
        for (lin, p) in self.control_points.iter().enumerate() {
            let mut idx = self.unindex(lin);
            if idx[dir] < dim {
                continue;
            }
            idx[dir] -= dim;
            let other = self.index(idx);
            let q = self.control_points[other];
            let gap = (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0, f64::max);
            let wgap = self.weights.as_ref().map_or(0.0, |w| (w[lin] - w[other]).abs() / w[other]);
            if gap > 1e-12 * scale || wgap > 1e-12 {
                return Err(Error::Invalid(format!(
                    "periodic control points must wrap in direction {dir}: stored point {lin} ({}, {}, {}) must repeat point {other} ({}, {}, {}) (the last p of {} layers repeat the first p)",
                    p[0], p[1], p[2], q[0], q[1], q[2], shape[dir]
                )));
            }
        }
        Ok(())
    }

    /// Number of basis functions per direction.
    pub fn shape(&self) -> [usize; 3] {
        self.knots.each_ref().map(KnotVector::num_basis)
    }

    /// Degrees per direction.
    pub fn degrees(&self) -> [usize; 3] {
        self.knots.each_ref().map(KnotVector::degree)
    }

    /// Linear index of control point `(i, j, k)`.
    pub fn index(&self, ijk: [usize; 3]) -> usize {
        let [nx, ny, _] = self.shape();
        (ijk[2] * ny + ijk[1]) * nx + ijk[0]
    }

    /// `(i, j, k)` of a linear index.
    pub fn unindex(&self, lin: usize) -> [usize; 3] {
        let [nx, ny, _] = self.shape();
        [lin % nx, (lin / nx) % ny, lin / (nx * ny)]
    }

    /// `x(ξ, η, ζ)`.
    pub fn eval(&self, u: [f64; 3]) -> Point3 {
        self.derivs_nd(u, 0).x
    }

    /// Value and first derivatives at `u`.
    pub fn derivs(&self, u: [f64; 3]) -> VolumeDerivs {
        self.derivs_nd(u, 1)
    }

    fn derivs_nd(&self, u: [f64; 3], nd: usize) -> VolumeDerivs {
        let b = [0, 1, 2].map(|d| BasisDerivs::at(&self.knots[d], u[d], nd));
        self.derivs_with(&b)
    }

    /// Value and first derivatives from precomputed univariate basis values (with at
    /// least first derivatives; the caller picks the spans, e.g. on element boundaries).
    pub fn derivs_with(&self, b: &[BasisDerivs; 3]) -> VolumeDerivs {
        let [nx, ny, _] = self.shape();
        // h[a] = (w x, w y, w z, w) and its derivative in direction a - 1
        let mut h = [[0.0f64; 4]; 4];
        for kc in 0..=b[2].degree {
            let k = b[2].first() + kc;
            for jb in 0..=b[1].degree {
                let j = b[1].first() + jb;
                for ia in 0..=b[0].degree {
                    let i = b[0].first() + ia;
                    let lin = (k * ny + j) * nx + i;
                    let w = self.weights.as_ref().map_or(1.0, |w| w[lin]);
                    let c = self.control_points[lin];
                    let vals = [
                        b[0].d[0][ia] * b[1].d[0][jb] * b[2].d[0][kc],
                        b[0].d[1][ia] * b[1].d[0][jb] * b[2].d[0][kc],
                        b[0].d[0][ia] * b[1].d[1][jb] * b[2].d[0][kc],
                        b[0].d[0][ia] * b[1].d[0][jb] * b[2].d[1][kc],
                    ];
                    for (hh, &n) in h.iter_mut().zip(&vals) {
                        let n = n * w;
                        hh[0] += n * c[0];
                        hh[1] += n * c[1];
                        hh[2] += n * c[2];
                        hh[3] += n;
                    }
                }
            }
        }
        let w = h[0][3];
        let x = [h[0][0] / w, h[0][1] / w, h[0][2] / w];
        let mut d = [[0.0; 3]; 3];
        for a in 0..3 {
            for c in 0..3 {
                d[a][c] = (h[a + 1][c] - h[a + 1][3] * x[c]) / w;
            }
        }
        VolumeDerivs { x, d }
    }

    fn homogeneous(&self) -> Homogeneous {
        self.control_points
            .iter()
            .enumerate()
            .map(|(k, c)| {
                let w = self.weights.as_ref().map_or(1.0, |w| w[k]);
                [w * c[0], w * c[1], w * c[2], w]
            })
            .collect()
    }

    fn from_homogeneous(knots: [KnotVector; 3], h: Homogeneous, rational: bool) -> Self {
        let control_points = h.iter().map(|p| [p[0] / p[3], p[1] / p[3], p[2] / p[3]]).collect();
        let weights = rational.then(|| h.iter().map(|p| p[3]).collect());
        Self { knots, control_points, weights }
    }

    /// The same map with the univariate operator `op` (onto the basis `kv`) applied in
    /// direction `dir`.
    fn mapped(&self, dir: usize, kv: KnotVector, op: &Csr) -> Self {
        let (h, _) = apply_along(op, dir, self.shape(), &self.homogeneous());
        let mut knots = self.knots.clone();
        knots[dir] = kv;
        Self::from_homogeneous(knots, h, self.weights.is_some())
    }

    /// Knot insertion in direction `dir`: the same map on the finer knot vector `fine`
    /// (which must contain this one's).
    pub fn refined_in(&self, dir: usize, fine: &KnotVector) -> Result<Self> {
        let op = prolongation(&self.knots[dir], fine)?;
        Ok(self.mapped(dir, fine.clone(), &op))
    }

    /// The same map on the finer tensor basis `fine` (knot insertion in every direction).
    pub fn refined(&self, fine: &[KnotVector; 3]) -> Result<Self> {
        let mut v = self.clone();
        for (d, kv) in fine.iter().enumerate() {
            if kv != &v.knots[d] {
                v = v.refined_in(d, kv)?;
            }
        }
        Ok(v)
    }

    /// The same map with the degree in direction `dir` raised by one (continuity kept).
    pub fn elevated_in(&self, dir: usize) -> Result<Self> {
        let (kv, op) = elevation(&self.knots[dir])?;
        Ok(self.mapped(dir, kv, &op))
    }

    /// The control net of the isoparametric surface `u_dir = t`: the control points
    /// `Σ_l B_l(t) c_(.., l, ..)` (homogeneously for NURBS) on the basis of the two other
    /// directions (in their order), with their weights.
    pub fn section(&self, dir: usize, t: f64) -> (Vec<Point3>, Option<Vec<f64>>) {
        let b = BasisDerivs::at(&self.knots[dir], t, 0);
        let rows: Vec<Vec<(usize, f64)>> =
            vec![b.ders(0).iter().enumerate().map(|(j, &v)| (b.first() + j, v)).collect()];
        let op = Csr::from_rows(self.shape()[dir], rows);
        let (h, _) = apply_along(&op, dir, self.shape(), &self.homogeneous());
        let pts = h.iter().map(|p| [p[0] / p[3], p[1] / p[3], p[2] / p[3]]).collect();
        let w = self.weights.as_ref().map(|_| h.iter().map(|p| p[3]).collect());
        (pts, w)
    }

    /// Bézier extraction: per direction, the univariate operators.
    pub(crate) fn extraction(&self) -> Result<[BezierExtraction; 3]> {
        Ok([
            BezierExtraction::new(&self.knots[0])?,
            BezierExtraction::new(&self.knots[1])?,
            BezierExtraction::new(&self.knots[2])?,
        ])
    }

    /// The homogeneous Bézier net `(w x, w y, w z, w)` of element `e` (indices of the
    /// element per direction), `(p + 1)(q + 1)(r + 1)` points, first index fastest:
    /// `H_abc = Σ_ijk h_ijk C^ξ_ia C^η_jb C^ζ_kc` with the extraction operators `C`.
    pub(crate) fn bezier_net(&self, ex: &[BezierExtraction; 3], e: [usize; 3]) -> Vec<[f64; 4]> {
        let [p, q, r] = self.degrees();
        let [nx, ny, _] = self.shape();
        let spans = [0, 1, 2].map(|d| ex[d].elements[e[d]].0);
        let first = [spans[0] - p, spans[1] - q, spans[2] - r];
        let ops = [0, 1, 2].map(|d| &ex[d].ops[e[d]]);
        let mut net = vec![[0.0; 4]; (p + 1) * (q + 1) * (r + 1)];
        for k in 0..=r {
            for j in 0..=q {
                for i in 0..=p {
                    let lin = ((first[2] + k) * ny + first[1] + j) * nx + first[0] + i;
                    let w = self.weights.as_ref().map_or(1.0, |w| w[lin]);
                    let c = self.control_points[lin];
                    let hv = [w * c[0], w * c[1], w * c[2], w];
                    for cc in 0..=r {
                        let z = ops[2][k * (r + 1) + cc];
                        if z == 0.0 {
                            continue;
                        }
                        for b in 0..=q {
                            let y = z * ops[1][j * (q + 1) + b];
                            if y == 0.0 {
                                continue;
                            }
                            for a in 0..=p {
                                let f = y * ops[0][i * (p + 1) + a];
                                let out = &mut net[(cc * (q + 1) + b) * (p + 1) + a];
                                for z in 0..4 {
                                    out[z] += f * hv[z];
                                }
                            }
                        }
                    }
                }
            }
        }
        net
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::bezier::bernstein;
    use crate::testutil::Lcg;

    /// A curved volume on open knot vectors with random interior knots, optionally rational.
    fn random_volume(rng: &mut Lcg, deg: [usize; 3], ne: [usize; 3], rational: bool) -> Volume {
        let knots = [0, 1, 2].map(|d| {
            let kv = KnotVector::open_uniform(deg[d], ne[d]);
            kv.with_inserted(&[0.05 + 0.9 * rng.uniform()])
        });
        let g = knots.each_ref().map(KnotVector::greville);
        let mut cps = Vec::new();
        for &z in &g[2] {
            for &y in &g[1] {
                for &x in &g[0] {
                    cps.push([
                        x + 0.1 * (rng.uniform() - 0.5) + 0.2 * y * z,
                        y + 0.1 * (rng.uniform() - 0.5) - 0.1 * x * x,
                        z + 0.1 * (rng.uniform() - 0.5) + 0.1 * x * y,
                    ]);
                }
            }
        }
        let w = rational.then(|| (0..cps.len()).map(|_| 0.6 + 0.8 * rng.uniform()).collect());
        Volume::new(knots, cps, w).unwrap()
    }

    fn close(a: Point3, b: Point3, tol: f64) -> bool {
        (0..3).all(|c| (a[c] - b[c]).abs() <= tol * (1.0 + a[c].abs()))
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let mut rng = Lcg::new(21);
        for rational in [false, true] {
            let v = random_volume(&mut rng, [2, 3, 1], [2, 2, 3], rational);
            for _ in 0..20 {
                let u = [0.05 + 0.9 * rng.uniform(), 0.05 + 0.9 * rng.uniform(), 0.05 + 0.9 * rng.uniform()];
                let d = v.derivs(u);
                for a in 0..3 {
                    let h = 1e-6;
                    let (mut lo, mut hi) = (u, u);
                    lo[a] -= h;
                    hi[a] += h;
                    let (xl, xh) = (v.eval(lo), v.eval(hi));
                    let fd = [0, 1, 2].map(|c| (xh[c] - xl[c]) / (2.0 * h));
                    // a knot between lo and hi makes the difference one-sided: skip those
                    let kv = &v.knots[a];
                    if kv.find_span(lo[a]) != kv.find_span(hi[a]) {
                        continue;
                    }
                    assert!(close(fd, d.d[a], 1e-6), "rational {rational} dir {a}: {fd:?} vs {:?}", d.d[a]);
                }
            }
        }
    }

    /// Knot insertion and degree elevation in every direction reproduce the map.
    #[test]
    fn insertion_and_elevation_reproduce_the_volume() {
        let mut rng = Lcg::new(5);
        for rational in [false, true] {
            let v = random_volume(&mut rng, [2, 2, 3], [2, 3, 2], rational);
            let fine = [
                v.knots[0].with_inserted(&[0.3, 0.3, 0.71]),
                v.knots[1].halved(),
                v.knots[2].with_inserted(&[0.123, 0.5]),
            ];
            let f = v.refined(&fine).unwrap();
            assert_eq!(f.shape(), fine.each_ref().map(KnotVector::num_basis));
            let e = v.elevated_in(1).unwrap().elevated_in(2).unwrap();
            assert_eq!(e.degrees(), [2, 3, 4]);
            for _ in 0..50 {
                let u = [rng.uniform(), rng.uniform(), rng.uniform()];
                let (a, b, c) = (v.derivs(u), f.derivs(u), e.derivs(u));
                assert!(close(a.x, b.x, 1e-13) && close(a.x, c.x, 1e-13), "{:?} {:?} {:?}", a.x, b.x, c.x);
                assert!((a.det_j() - b.det_j()).abs() < 1e-10 * (1.0 + a.det_j().abs()));
                assert!((a.det_j() - c.det_j()).abs() < 1e-10 * (1.0 + a.det_j().abs()));
            }
            assert!(v.refined_in(0, &v.knots[0].elevated()).is_err());
        }
    }

    #[test]
    fn bezier_nets_reproduce_the_volume() {
        let mut rng = Lcg::new(8);
        for rational in [false, true] {
            let v = random_volume(&mut rng, [2, 1, 3], [2, 2, 2], rational);
            let ex = v.extraction().unwrap();
            let [p, q, r] = v.degrees();
            let e = [1, 0, 2];
            let net = v.bezier_net(&ex, e);
            let bounds = [0, 1, 2].map(|d| (ex[d].elements[e[d]].1, ex[d].elements[e[d]].2));
            let (mut bu, mut bv, mut bw) = ([0.0; 8], [0.0; 8], [0.0; 8]);
            for _ in 0..10 {
                let s = [rng.uniform(), rng.uniform(), rng.uniform()];
                bernstein(p, s[0], &mut bu);
                bernstein(q, s[1], &mut bv);
                bernstein(r, s[2], &mut bw);
                let mut h = [0.0; 4];
                for c in 0..=r {
                    for b in 0..=q {
                        for a in 0..=p {
                            let f = bu[a] * bv[b] * bw[c];
                            for z in 0..4 {
                                h[z] += f * net[(c * (q + 1) + b) * (p + 1) + a][z];
                            }
                        }
                    }
                }
                let u = [0, 1, 2].map(|d| bounds[d].0 + s[d] * (bounds[d].1 - bounds[d].0));
                let x = v.eval(u);
                assert!(close([h[0] / h[3], h[1] / h[3], h[2] / h[3]], x, 1e-13));
            }
        }
    }

    #[test]
    fn periodic_direction_must_wrap() {
        let kv = KnotVector::periodic_uniform(2, 4);
        let open = KnotVector::open_uniform(1, 1);
        let n = kv.num_basis();
        let mut cps = Vec::new();
        for k in 0..2 {
            for j in 0..2 {
                for i in 0..n {
                    let t = std::f64::consts::TAU * (i % (n - 2)) as f64 / (n - 2) as f64;
                    cps.push([(1.0 + j as f64) * t.cos(), (1.0 + j as f64) * t.sin(), k as f64]);
                }
            }
        }
        let v = Volume::new([kv.clone(), open.clone(), open.clone()], cps.clone(), None).unwrap();
        let fine = [kv.halved(), open.clone(), open.clone()];
        let f = v.refined(&fine).unwrap();
        for s in [0.0, 0.13, 0.5, 0.99] {
            assert!(close(v.eval([s, 0.4, 0.6]), f.eval([s, 0.4, 0.6]), 1e-13));
        }
        cps[n - 1][0] += 0.1;
        assert!(matches!(Volume::new([kv, open.clone(), open], cps, None), Err(Error::Invalid(_))));
    }

    #[test]
    fn bad_inputs_are_errors() {
        let kv = KnotVector::open_uniform(1, 1);
        let k3 = [kv.clone(), kv.clone(), kv];
        assert!(matches!(Volume::new(k3.clone(), vec![[0.0; 3]; 7], None), Err(Error::Length { .. })));
        let mut cps = vec![[0.0; 3]; 8];
        cps[3][2] = f64::NAN;
        assert!(matches!(Volume::new(k3.clone(), cps, None), Err(Error::NonFinite { .. })));
        assert!(matches!(Volume::new(k3, vec![[0.0; 3]; 8], Some(vec![-1.0; 8])), Err(Error::Weight { .. })));
    }
}
