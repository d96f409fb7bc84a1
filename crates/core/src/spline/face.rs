//! Tensor-product surfaces in space, `f: [0,1]² → R³` (the faces of a volume):
//! `f(s, t) = Σ_ij c_ij N_i(s) M_j(t)`, or for NURBS
//! `f = Σ w_ij c_ij N_i M_j / Σ w_ij N_i M_j`; control point `(i, j)` is stored at
//! `j n_s + i` (`s` fastest).
//!
//! Validation, evaluation, knot insertion and degree elevation are those of the tensor
//! core [`TensorSpline`] (exact, on homogeneous coordinates).

use crate::error::{Error, Result};
use crate::spline::basis::BasisDerivs;
use crate::spline::knots::KnotVector;
use crate::spline::tensor::TensorSpline;
use crate::spline::volume::Point3;

/// A tensor-product B-spline or NURBS surface in space.
pub type Face = TensorSpline<2, 3>;

/// Value and first derivatives `(f, f_s, f_t)` of a face.
pub(crate) type FaceDerivs = (Point3, Point3, Point3);

impl Face {
    /// Validate lengths, finiteness and weights (open knot vectors only: a face is one
    /// side of a hexahedral volume).
    pub fn new(knots: [KnotVector; 2], control_points: Vec<Point3>, weights: Option<Vec<f64>>) -> Result<Self> {
        if knots.iter().any(KnotVector::is_periodic) {
            return Err(Error::Invalid("a face of a volume boundary cannot be periodic".into()));
        }
        Self::checked(knots, control_points, weights)
    }

    /// `f(s, t)` and its first derivatives.
    pub fn derivs(&self, s: f64, t: f64) -> FaceDerivs {
        let b = [BasisDerivs::at(&self.knots[0], s, 1), BasisDerivs::at(&self.knots[1], t, 1)];
        let (x, [ds, dt]) = self.first_derivs(b.each_ref());
        (x, ds, dt)
    }

    /// `f(s, t)`.
    pub fn eval(&self, s: f64, t: f64) -> Point3 {
        self.derivs(s, t).0
    }

    /// The same surface with direction `dir` reversed on its domain `[a, b]`:
    /// `g(.., u_dir, ..) = f(.., a + b - u_dir, ..)` (knots `a + b - u` in reverse order,
    /// control points reversed in that direction).
    pub(crate) fn reversed_in(&self, dir: usize) -> Result<Self> {
        let kv = &self.knots[dir];
        let (a, b) = kv.domain();
        let knots: Vec<f64> = kv
            .knots()
            .iter()
            .rev()
            .map(|&u| {
                if u == a {
                    b
                } else if u == b {
                    a
                } else {
                    a + b - u
                }
            })
            .collect();
        let mut out_knots = self.knots.clone();
        out_knots[dir] = KnotVector::new(kv.degree(), knots)?;
        let [ns, nt] = self.shape();
        let perm = |k: usize| {
            let (i, j) = (k % ns, k / ns);
            if dir == 0 {
                j * ns + (ns - 1 - i)
            } else {
                (nt - 1 - j) * ns + i
            }
        };
        Ok(Self {
            knots: out_knots,
            control_points: (0..ns * nt).map(|k| self.control_points[perm(k)]).collect(),
            weights: self.weights.as_ref().map(|w| (0..ns * nt).map(|k| w[perm(k)]).collect()),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(rational: bool) -> Face {
        let k = [KnotVector::open_from_breaks(2, &[0.0, 0.3, 1.0], 1), KnotVector::open_uniform(3, 2)];
        let [ns, nt] = k.each_ref().map(KnotVector::num_basis);
        let cps = (0..ns * nt)
            .map(|q| {
                let (i, j) = ((q % ns) as f64, (q / ns) as f64);
                [i + 0.1 * j * j, j - 0.2 * i, (0.3 * i * j).sin()]
            })
            .collect();
        let w = rational.then(|| (0..ns * nt).map(|q| 1.0 + 0.3 * ((q * 7) % 5) as f64).collect());
        Face::new(k, cps, w).unwrap()
    }

    /// Elevation and insertion reproduce the surface and its derivatives; derivatives
    /// agree with central differences.
    #[test]
    fn refinement_is_exact_and_derivatives_are_consistent() {
        for rational in [false, true] {
            let f = sample(rational);
            let fine = f.knots[1].with_inserted(&[0.2, 0.2]);
            let g = f.elevated_in(0).unwrap().refined_in(1, &fine).unwrap();
            for &(s, t) in &[(0.1, 0.7), (0.5, 0.5), (0.93, 0.02), (0.0, 1.0)] {
                let (a, b) = (f.derivs(s, t), g.derivs(s, t));
                for c in 0..3 {
                    assert!((a.0[c] - b.0[c]).abs() < 1e-12);
                    assert!((a.1[c] - b.1[c]).abs() < 1e-10);
                    assert!((a.2[c] - b.2[c]).abs() < 1e-10);
                }
            }
            let h = 1e-6;
            let (_, ds, dt) = f.derivs(0.4, 0.6);
            let (p, m) = (f.eval(0.4 + h, 0.6), f.eval(0.4 - h, 0.6));
            let (q, n) = (f.eval(0.4, 0.6 + h), f.eval(0.4, 0.6 - h));
            for c in 0..3 {
                assert!((ds[c] - (p[c] - m[c]) / (2.0 * h)).abs() < 1e-6);
                assert!((dt[c] - (q[c] - n[c]) / (2.0 * h)).abs() < 1e-6);
            }
        }
    }

    /// Transposition and reversal are the surface composed with `(s, t) -> (t, s)` and
    /// `s -> 1 - s` / `t -> 1 - t`, B-spline and NURBS; twice is the identity.
    #[test]
    fn symmetries_compose_the_parameters() {
        for rational in [false, true] {
            let f = sample(rational);
            let (tr, r0, r1) = (f.transposed(), f.reversed_in(0).unwrap(), f.reversed_in(1).unwrap());
            for &(s, t) in &[(0.1, 0.7), (0.5, 0.25), (0.93, 0.02), (0.0, 1.0)] {
                let close = |a: Point3, b: Point3| (0..3).all(|c| (a[c] - b[c]).abs() < 1e-12);
                assert!(close(tr.eval(t, s), f.eval(s, t)));
                assert!(close(r0.eval(1.0 - s, t), f.eval(s, t)));
                assert!(close(r1.eval(s, 1.0 - t), f.eval(s, t)));
            }
            assert_eq!(tr.transposed(), f);
            assert_eq!(r1.reversed_in(1).unwrap().control_points, f.control_points);
        }
    }

    #[test]
    fn bad_faces_are_typed_errors() {
        let k = [KnotVector::open_uniform(1, 1), KnotVector::open_uniform(1, 1)];
        let e = Face::new(k.clone(), vec![[0.0; 3]; 3], None).unwrap_err();
        assert!(matches!(e, Error::Length { .. }), "{e}");
        let e = Face::new(k.clone(), vec![[0.0; 3]; 4], Some(vec![1.0, -1.0, 1.0, 1.0])).unwrap_err();
        assert!(matches!(e, Error::Weight { .. }), "{e}");
        let e = Face::new(k, vec![[f64::NAN; 3]; 4], None).unwrap_err();
        assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    }
}
