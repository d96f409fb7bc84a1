//! Tests of the 3D EGG operator: its Jacobian against finite differences, its matrix-free
//! product and the sum-factorised kernels against the assembled ones, the residual in
//! closed form.

use super::*;
use crate::spline::knots::KnotVector;
use crate::spline::volume::Volume;

/// A rational curved volume of degrees (3, 2, 2) with an interior wobble.
fn sample() -> (Volume, Vec<Point3>) {
    super::super::tests::curved_rational_volume([
        KnotVector::open_uniform(3, 2),
        KnotVector::open_uniform(2, 2),
        KnotVector::open_from_breaks(2, &[0.0, 0.4, 1.0], 1),
    ])
}

/// The assembled Jacobian against central differences of the residual, on a
/// rational curved volume.
#[test]
fn jacobian_matches_finite_differences() {
    let (vol, cps) = sample();
    let op = EggVolume::new(&vol, 5);
    let at = op.evaluate(&cps, true);
    assert_eq!(at.residual.len(), op.unknowns());
    assert!(at.residual.iter().any(|f| f.abs() > 1e-3), "a wobbled volume is not a solution");
    let x0 = op.disc.gather(&cps);
    let jac = at.jacobian.unwrap();
    let eps = 1e-6;
    for k in 0..x0.len() {
        let shifted = |s: f64| {
            let mut x = x0.clone();
            x[k] += s;
            let mut c = cps.clone();
            op.disc.scatter(&mut c, &x);
            op.evaluate(&c, false).residual
        };
        let (p, m) = (shifted(eps), shifted(-eps));
        for l in 0..x0.len() {
            let fd = (p[l] - m[l]) / (2.0 * eps);
            assert!((jac.get(l, k) - fd).abs() < 1e-7 * (1.0 + fd.abs()), "jac {l} {k}: {} vs {fd}", jac.get(l, k));
        }
    }
}

/// The Jacobian's product without the Jacobian ([`EggVolume::jacobian_times`]) equals
/// the assembled Jacobian times the vector to rounding, on a rational curved volume
/// and vectors of pseudo-random coefficients.
#[test]
fn the_matrix_free_product_is_the_assembled_one() {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    for (vol, cps) in [sample(), polynomial(), polynomial_223()] {
        let op = EggVolume::new(&vol, 5);
        let jac = op.evaluate(&cps, true).jacobian.unwrap();
        let n = op.unknowns();
        for _ in 0..4 {
            let v = random(&mut state, n);
            let mut want = vec![0.0; n];
            jac.mul_vec(&v, &mut want);
            let got = op.jacobian_times(&cps, &v).unwrap();
            // the size of the sums: |J| |v| row by row
            let scale = (0..n)
                .map(|r| (jac.row_ptr[r]..jac.row_ptr[r + 1]).map(|p| (jac.values[p] * v[jac.col_idx[p]]).abs()).sum())
                .fold(0.0f64, f64::max);
            let err = got.iter().zip(&want).fold(0.0f64, |e, (a, b)| e.max((a - b).abs()));
            assert!(scale > 1e-3 && err < 1e-13 * scale, "max difference {err} at scale {scale}");
        }
    }
}

/// `n` pseudo-random numbers in `[-0.5, 0.5)` (xorshift).
fn random(state: &mut u64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|_| {
            *state ^= *state << 13;
            *state ^= *state >> 7;
            *state ^= *state << 17;
            (*state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect()
}

/// [`sample`] without its weights: a polynomial curved volume.
fn polynomial() -> (Volume, Vec<Point3>) {
    let (vol, cps) = sample();
    (Volume::new(vol.knots.clone(), cps.clone(), None).unwrap(), cps)
}

/// A polynomial curved volume of degrees (2, 2, 3) (the twisted ducts' degrees): the
/// sum factorisation contracts `z` first, and numbers the points with `z` fastest.
fn polynomial_223() -> (Volume, Vec<Point3>) {
    let (vol, cps) = super::super::tests::curved_rational_volume([
        KnotVector::open_uniform(2, 2),
        KnotVector::open_from_breaks(2, &[0.0, 0.4, 1.0], 1),
        KnotVector::open_uniform(3, 2),
    ]);
    (Volume::new(vol.knots.clone(), cps.clone(), None).unwrap(), cps)
}

/// The sum-factorised values, gradients and Hessians at the Gauss points
/// ([`tensor_points::values`]) and integrals against the basis
/// ([`tensor_points::integrals`]) equal those through the tensor basis table, on
/// every element of a polynomial volume (degrees (3, 2, 2), contracted in the natural
/// order, and (2, 2, 3), `z` first), for pseudo-random coefficients, the points in the
/// order of [`tensor_points::points_in_natural_order`]; and so the residual through
/// them equals the one of [`EggVolume::element`].
#[test]
fn sum_factorisation_is_the_basis_table_product() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    for (vol, cps) in [polynomial(), polynomial_223()] {
        let op = EggVolume::new(&vol, 5);
        for e in 0..op.disc.elements() {
            let idx = op.disc.element_indices(e);
            let (weights, basis) = op.element_points(e, &idx);
            let tables = op.disc.element_tables(e);
            let nat = tensor_points::points_in_natural_order(tables);
            let mut seen = vec![false; nat.len()];
            nat.iter().for_each(|&q| seen[q] = true);
            assert!(seen.iter().all(|&s| s), "a permutation of the points");
            let w: Vec<f64> = nat.iter().map(|&q| weights[q]).collect();
            assert_eq!(tensor_points::weights(tables), w);
            let (m, nq) = (idx.len(), weights.len());
            let u = random(&mut state, 2 * m);
            let got = tensor_points::values(tables, &u);
            for col in 0..2 {
                for (row, q) in (0..10).flat_map(|row| (0..nq).map(move |q| (row, q))) {
                    let want: f64 = (0..m).map(|a| basis[(10 * nat[q] + row) * m + a] * u[col * m + a]).sum();
                    let g = got[(10 * col + row) * nq + q];
                    assert!((g - want).abs() < 1e-12 * (1.0 + want.abs()), "{e} {col} {row}: {g} vs {want}");
                }
            }
            let f = random(&mut state, 3 * nq);
            let got = tensor_points::integrals(tables, &f);
            for c in 0..3 {
                for a in 0..m {
                    let want: f64 = (0..nq).map(|q| basis[nat[q] * 10 * m + a] * f[c * nq + q]).sum();
                    assert!((got[c * m + a] - want).abs() < 1e-13, "{e} {c} {a}: {} vs {want}", got[c * m + a]);
                }
            }
        }
        let fast = op.evaluate(&cps, false).residual;
        let table = op.evaluate_with(&cps, false, true).residual;
        let err = fast.iter().zip(&table).fold(0.0f64, |e, (a, b)| e.max((a - b).abs()));
        assert!(fast.iter().any(|f| f.abs() > 1e-3) && err < 1e-13, "{err}");
    }
}

/// The sum-factorised stiffness ([`tensor_points::stiffness`]) equals
/// `Σ_q Σ_ij ∂_i R_a C_ij ∂_j R_b` through the tensor basis table, on every element of a
/// polynomial volume, for pseudo-random symmetric coefficients `C` (`C_ij = C_ji`, as the
/// cofactor metric's: the sum factorisation runs over the six pairs `i <= j`), and is
/// symmetric bit for bit; and the cofactor-metric stiffness `K` assembled through it
/// equals the one of the basis tables ([`EggVolume::element`]).
#[test]
fn sum_factorised_stiffness_is_the_basis_table_sum() {
    let mut state = 0x1234_5678_9abc_def1_u64;
    for (vol, cps) in [polynomial(), polynomial_223()] {
        let op = EggVolume::new(&vol, 5);
        for e in 0..op.disc.elements() {
            let idx = op.disc.element_indices(e);
            let (weights, basis) = op.element_points(e, &idx);
            let (m, nq) = (idx.len(), weights.len());
            let mut c = random(&mut state, 9 * nq);
            for (i, j) in [(1, 0), (2, 0), (2, 1)] {
                let (lower, upper) = c.split_at_mut((3 * i + j) * nq);
                upper[..nq].copy_from_slice(&lower[(3 * j + i) * nq..][..nq]);
            }
            let tables = op.disc.element_tables(e);
            let got = tensor_points::stiffness(tables, &c);
            assert!((0..m).all(|a| (0..m).all(|b| got[a * m + b] == got[b * m + a])), "symmetric");
            let nat = tensor_points::points_in_natural_order(tables);
            let grad = |q: usize, i: usize, a: usize| basis[(10 * nat[q] + 1 + i) * m + a];
            let mut scale = 0.0f64;
            for a in 0..m {
                for b in 0..m {
                    let mut want = 0.0;
                    for q in 0..nq {
                        for i in 0..3 {
                            for j in 0..3 {
                                want += grad(q, i, a) * c[(3 * i + j) * nq + q] * grad(q, j, b);
                            }
                        }
                    }
                    scale = scale.max(want.abs());
                    let g = got[b * m + a];
                    assert!((g - want).abs() < 1e-11 * (1.0 + want.abs()), "{e} ({a}, {b}): {g} vs {want}");
                }
            }
            assert!(scale > 1e-2, "{scale}");
        }
        let fast = op.evaluate_with(&cps, false, true);
        let table = op.evaluate_with(&cps, true, true);
        let (k, kt) = (fast.laplace.unwrap(), table.laplace.unwrap());
        assert_eq!((&k.row_ptr, &k.col_idx), (&kt.row_ptr, &kt.col_idx));
        let size = kt.values.iter().fold(0.0f64, |e, v| e.max(v.abs()));
        let err = k.values.iter().zip(&kt.values).fold(0.0f64, |e, (a, b)| e.max((a - b).abs()));
        assert!(size > 1e-2 && err < 1e-13 * size, "{err} at {size}");
    }
}

/// The Winslow energy that comes with the residual ([`EggEvaluation::energy`]) is that
/// of [`super::super::winslow::WinslowVolume`] on the same quadrature to rounding, on
/// the sum-factorised and the basis-table path, polynomial and rational; and `+∞` on a
/// volume folded by a reflected interior control point.
#[test]
fn the_residuals_winslow_energy_is_the_functionals() {
    for (vol, cps) in [sample(), polynomial(), polynomial_223()] {
        let op = EggVolume::new(&vol, 5);
        let want = super::super::winslow::WinslowVolume::new(&vol, 5).evaluate(&cps, false).energy;
        for (jacobian, laplace) in [(false, false), (false, true), (true, false)] {
            let got = op.evaluate_with(&cps, jacobian, laplace).energy;
            assert!(want.is_finite() && (got - want).abs() < 1e-13 * want, "{got} vs {want}");
        }
        let mut folded = cps.clone();
        let lin = (0..cps.len()).find(|&l| op.disc.free_index(l).is_some()).unwrap();
        folded[lin] = std::array::from_fn(|c| 3.0 * cps[lin][c] - 2.0 * cps[lin + 1][c]);
        assert_eq!(super::super::winslow::WinslowVolume::new(&vol, 5).evaluate(&folded, false).energy, f64::INFINITY);
        assert_eq!(op.evaluate(&folded, false).energy, f64::INFINITY);
    }
}

/// A Jacobian handed back and overwritten by the next assembly equals one assembled
/// into a new matrix (its old values are cleared, its pattern is the pattern), and
/// a matrix of another size is not taken.
#[test]
fn a_recycled_jacobian_is_assembled_afresh() {
    let (vol, cps) = sample();
    let op = EggVolume::new(&vol, 4);
    let mut moved = cps.clone();
    for (k, p) in moved.iter_mut().enumerate() {
        p[k % 3] += 0.01 * ((k % 7) as f64 - 3.0);
    }
    let first = op.evaluate(&cps, true).jacobian.unwrap();
    let fresh = op.evaluate(&moved, true).jacobian.unwrap();
    op.disc.recycle(first);
    let reused = op.evaluate(&moved, true).jacobian.unwrap();
    assert!(fresh.values.iter().any(|v| *v != 0.0));
    assert_eq!((&reused.row_ptr, &reused.col_idx), (&fresh.row_ptr, &fresh.col_idx));
    assert_eq!(reused.values, fresh.values, "the same sums in the same order");
    op.disc.recycle(Csr { nrows: 3, ncols: 3, row_ptr: vec![0, 0, 0, 0], col_idx: vec![], values: vec![] });
    assert_eq!(op.evaluate(&moved, true).jacobian.unwrap().values, fresh.values);
}

/// The residual against the operator evaluated directly: for the quadratic volume
/// `x = ξ + a ξη`, `y = η + b ζ²`, `z = ζ + c ξ²` (control points from its blossoms,
/// so the B-spline basis holds it exactly), `F_(A,c) = ∫ R_A L_c` with `L_c` from the
/// closed-form derivatives, summed over the same Gauss points.
#[test]
fn residual_matches_the_operator_in_closed_form() {
    let kv = KnotVector::open_uniform(2, 2);
    let k = [kv.clone(), kv.clone(), kv.clone()];
    let (a, b, c) = (0.3, -0.2, 0.25);
    let t = kv.knots();
    let g = kv.greville();
    let sq: Vec<f64> = (0..kv.num_basis()).map(|i| t[i + 1] * t[i + 2]).collect();
    let n = kv.num_basis();
    let cps: Vec<Point3> = (0..n * n * n)
        .map(|lin| {
            let (i, j, l) = (lin % n, (lin / n) % n, lin / (n * n));
            [g[i] + a * g[i] * g[j], g[j] + b * sq[l], g[l] + c * sq[i]]
        })
        .collect();
    let vol = Volume::new(k, cps.clone(), None).unwrap();
    for u in [[0.2, 0.7, 0.4], [0.9, 0.1, 0.55]] {
        let (x, want) = (vol.eval(u), [u[0] + a * u[0] * u[1], u[1] + b * u[2] * u[2], u[2] + c * u[0] * u[0]]);
        assert!((0..3).all(|i| (x[i] - want[i]).abs() < 1e-14), "{x:?} vs {want:?}");
    }
    let op = EggVolume::new(&vol, 4);
    let f = op.evaluate(&cps, false).residual;
    let l = |u: [f64; 3]| -> Point3 {
        let d = [[1.0 + a * u[1], 0.0, 2.0 * c * u[0]], [a * u[0], 1.0, 0.0], [0.0, 2.0 * b * u[2], 1.0]];
        // second derivatives per component, in the order of PAIRS
        let h = [[0.0, 0.0, 0.0, a, 0.0, 0.0], [0.0, 0.0, 2.0 * b, 0.0, 0.0, 0.0], [2.0 * c, 0.0, 0.0, 0.0, 0.0, 0.0]];
        let cof: [Point3; 3] = std::array::from_fn(|i| cross(d[(i + 1) % 3], d[(i + 2) % 3]));
        let am: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| dot(cof[i], cof[j])));
        let t = am[0][0] + am[1][1] + am[2][2];
        std::array::from_fn(|comp| contract(&am, &h[comp]) / t)
    };
    let rule = crate::spline::quadrature::GaussLegendre::new(4);
    let nodes: Vec<(f64, f64)> =
        kv.elements().into_iter().flat_map(|(_, lo, hi)| rule.on(lo, hi).collect::<Vec<_>>()).collect();
    let mut checked = 0;
    for lin in 0..cps.len() {
        let Some(fr) = op.disc.free_index(lin) else { continue };
        let ijk = [lin % n, (lin / n) % n, lin / (n * n)];
        let mut want = [0.0; 3];
        for &(x, wx) in &nodes {
            for &(y, wy) in &nodes {
                for &(z, wz) in &nodes {
                    let u = [x, y, z];
                    let r: f64 = (0..3).map(|d| crate::spline::basis::dense_values(&kv, u[d])[ijk[d]]).product();
                    let lv = l(u);
                    for comp in 0..3 {
                        want[comp] += wx * wy * wz * r * lv[comp];
                    }
                }
            }
        }
        for comp in 0..3 {
            let got = f[3 * fr + comp];
            assert!((got - want[comp]).abs() < 1e-13, "{lin} {comp}: {got} vs {}", want[comp]);
        }
        assert!(want.iter().any(|w| w.abs() > 1e-3), "a curved volume is not a solution");
        checked += 1;
    }
    assert_eq!(checked, 8);
}
