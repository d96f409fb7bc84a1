//! Trivariate tensor-product maps `x: [0,1]³ → R³` (volumes; paper §11.1, Fig. 23): a
//! basis (three knot vectors) plus control points,
//! `x(ξ, η, ζ) = Σ_ijk c_ijk N_i(ξ) M_j(η) L_k(ζ)`, or for NURBS
//! `x = Σ w_ijk c_ijk N_i M_j L_k / Σ w_ijk N_i M_j L_k`.
//!
//! Control point `(i, j, k)` is stored at `(k n_η + j) n_ξ + i` (`ξ` fastest, then `η`).
//! Validation, indexing, evaluation, knot insertion and degree elevation are those of the
//! tensor core [`TensorSpline`] (one direction at a time, on the homogeneous coordinates
//! `(w x, w y, w z, w)`, periodic directions included), Bézier extraction per element
//! too (`TensorSpline::bezier_net`, the tensor product of the univariate operators of
//! `spline::bezier`).

use crate::error::Result;
use crate::linalg::sparse::Csr;
use crate::spline::basis::BasisDerivs;
use crate::spline::knots::KnotVector;
use crate::spline::tensor::{apply_along, projected, TensorSpline};

/// A point or vector in space.
pub type Point3 = [f64; 3];

/// A trivariate tensor-product B-spline or NURBS map.
pub type Volume = TensorSpline<3, 3>;

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

impl Volume {
    /// Validate lengths, finiteness and weights, and that the control points of a
    /// periodic direction wrap (the last `p` layers repeat the first `p`, to `1e-12`
    /// relative to the largest coordinate).
    pub fn new(knots: [KnotVector; 3], control_points: Vec<Point3>, weights: Option<Vec<f64>>) -> Result<Self> {
        Self::checked(knots, control_points, weights)
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
    pub(crate) fn derivs_with(&self, b: &[BasisDerivs; 3]) -> VolumeDerivs {
        let (x, d) = self.first_derivs(b.each_ref());
        VolumeDerivs { x, d }
    }

    /// The control net of the isoparametric surface `u_dir = t`: the control points
    /// `Σ_l B_l(t) c_(.., l, ..)` (homogeneously for NURBS) on the basis of the two other
    /// directions (in their order), with their weights.
    pub fn section(&self, dir: usize, t: f64) -> (Vec<Point3>, Option<Vec<f64>>) {
        let b = BasisDerivs::at(&self.knots[dir], t, 0);
        let rows: Vec<Vec<(usize, f64)>> =
            vec![b.ders(0).iter().enumerate().map(|(j, &v)| (b.first() + j, v)).collect()];
        let op = Csr::from_rows(self.shape()[dir], rows);
        let h = apply_along(&op, dir, self.shape(), &self.homogeneous());
        (projected(&h), self.weights.as_ref().map(|_| h.iter().map(|p| p.1).collect()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;
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
                                let (x, w) = net[(c * (q + 1) + b) * (p + 1) + a];
                                h[z] += f * if z < 3 { x[z] } else { w };
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
