use super::*;
use crate::spline::surface::Surface;
use crate::testutil::Lcg;
use crate::verify::certificate::bernstein::eval;
use crate::verify::certificate::element::Elements;

/// A perturbed identity on an open basis with one inner knot of multiplicity two.
fn map(rng: &mut Lcg, p: usize, q: usize, amp: f64) -> Surface {
    let kx = KnotVector::open_uniform(p, 3).with_inserted(&[0.4]);
    let ky = KnotVector::open_uniform(q, 2);
    let (gx, gy) = (kx.greville(), ky.greville());
    let mut cps = Vec::new();
    for &y in &gy {
        for &x in &gx {
            cps.push([1.5 * x + 0.3 * y + amp * (rng.uniform() - 0.5), y + amp * (rng.uniform() - 0.5)]);
        }
    }
    Surface::new([kx, ky], cps, None).unwrap()
}

#[test]
fn coefficients_are_the_certificates_and_interpolate_det_j() {
    let mut rng = Lcg::new(4);
    for (p, q) in [(2, 2), (3, 2), (2, 4), (3, 3)] {
        let s = map(&mut rng, p, q, 0.3);
        let dc = DetCoefficients::new(&s.knots).unwrap();
        let d = dc.values(&s.control_points);
        assert_eq!(d.len(), dc.len());
        let dj = Elements::surface(&s).unwrap();
        assert_eq!(dj.deg.0, dc.degree());
        let mut tmp = vec![0.0; dj.deg.len()];
        let mut c = vec![0.0; dj.deg.len()];
        let [n, m] = dc.shape();
        let per = dc.per_element();
        for j in 0..m {
            for i in 0..n {
                let (sc, _) = dj.coefficients([i, j], &mut c);
                let mine = &d[(j * n + i) * per..(j * n + i + 1) * per];
                let scale = mine.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                for (a, b) in mine.iter().zip(&c) {
                    assert!((a - sc.factor * b).abs() < 1e-12 * scale, "p={p} q={q}: {a} vs {}", sc.factor * b);
                }
                let [bu, bv] = dj.bounds([i, j]);
                for _ in 0..5 {
                    let (x, y) = (rng.uniform(), rng.uniform());
                    let exact = s.derivs(bu[0] + x * (bu[1] - bu[0]), bv[0] + y * (bv[1] - bv[0]), 1).det_j();
                    let val = eval(mine, Deg(dc.degree()), [[1.0 - x, x], [1.0 - y, y]], &mut tmp);
                    assert!((val - exact).abs() < 1e-12 * scale, "{val} vs {exact}");
                }
            }
        }
        let area = crate::verify::quality::functionals(&s).area;
        assert!((dc.area(&d) - area).abs() < 1e-12 * area, "{} vs {area}", dc.area(&d));
    }
}

/// `∂d/∂c` against central differences (exact for a bilinear map up to rounding), on
/// the unknowns of the interior DOF map.
#[test]
fn jacobian_matches_finite_differences() {
    let mut rng = Lcg::new(9);
    for (p, q) in [(2, 3), (3, 3)] {
        let s = map(&mut rng, p, q, 0.2);
        let dofs = DofMap::interior(s.shape());
        let dc = DetCoefficients::new(&s.knots).unwrap();
        let jac = dc.jacobian(&s.control_points, &dofs).to_dense();
        let c = dofs.gather(&s.control_points);
        let h = 1e-5;
        let (mut err, mut scale) = (0.0f64, 0.0f64);
        for j in 0..c.len() {
            let (mut cp, mut cm) = (s.control_points.clone(), s.control_points.clone());
            let (mut up, mut um) = (c.clone(), c.clone());
            up[j] += h;
            um[j] -= h;
            dofs.scatter(&up, &mut cp);
            dofs.scatter(&um, &mut cm);
            let (dp, dm) = (dc.values(&cp), dc.values(&cm));
            for i in 0..dc.len() {
                let fd = (dp[i] - dm[i]) / (2.0 * h);
                err = err.max((fd - jac[i][j]).abs());
                scale = scale.max(fd.abs());
            }
        }
        assert!(scale > 1.0 && err < 1e-8 * scale, "p={p} q={q}: {err} (scale {scale})");
    }
}

/// `Σ λ_k ∇²d_k` against central differences of `λᵀ ∂d/∂c`.
#[test]
fn weighted_hessian_matches_finite_differences() {
    let mut rng = Lcg::new(2);
    let s = map(&mut rng, 3, 2, 0.2);
    let dofs = DofMap::interior(s.shape());
    let dc = DetCoefficients::new(&s.knots).unwrap();
    let lambda: Vec<f64> = (0..dc.len()).map(|k| if k % 3 == 0 { 0.0 } else { rng.uniform() }).collect();
    let hess = dc.weighted_hessian(&lambda, &dofs).to_dense();
    let c = dofs.gather(&s.control_points);
    let grad = |c: &[f64]| {
        let mut cps = s.control_points.clone();
        dofs.scatter(c, &mut cps);
        let jt = dc.jacobian(&cps, &dofs).transpose();
        jt.apply(&lambda)
    };
    let h = 1e-5;
    let (mut err, mut scale) = (0.0f64, 0.0f64);
    for j in 0..c.len() {
        let (mut up, mut um) = (c.clone(), c.clone());
        up[j] += h;
        um[j] -= h;
        let (gp, gm) = (grad(&up), grad(&um));
        for i in 0..c.len() {
            let fd = (gp[i] - gm[i]) / (2.0 * h);
            err = err.max((fd - hess[i][j]).abs());
            scale = scale.max(fd.abs());
            assert!((hess[i][j] - hess[j][i]).abs() < 1e-12 * (1.0 + scale.abs()));
        }
    }
    assert!(scale > 1.0 && err < 1e-8 * scale, "{err} (scale {scale})");
}

/// With the sides fixed, exactly the four corner coefficients (`det J` at the corners of
/// the square, set by the boundary tangents) do not depend on the unknowns.
#[test]
fn only_the_corner_coefficients_are_fixed_by_the_boundary() {
    let mut rng = Lcg::new(1);
    for (p, q) in [(2, 2), (3, 2)] {
        let s = map(&mut rng, p, q, 0.1);
        let dc = DetCoefficients::new(&s.knots).unwrap();
        let free = dc.depends_on_unknowns(&DofMap::interior(s.shape()));
        let [n, m] = dc.shape();
        let [du, dv] = dc.degree();
        let per = dc.per_element();
        let corners = [0, (n - 1) * per + du, ((m - 1) * n) * per + dv * (du + 1), n * m * per - 1];
        let fixed: Vec<usize> = (0..dc.len()).filter(|&k| !free[k]).collect();
        assert_eq!(fixed, corners.to_vec(), "p={p} q={q}");
        // a DOF map with every control point fixed leaves nothing free
        let none = DofMap::from_predicate(s.shape(), |_, _| false);
        assert!(dc.depends_on_unknowns(&none).iter().all(|f| !f));
    }
}
