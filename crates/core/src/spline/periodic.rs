//! Periodic splines: knot insertion, degree elevation and Bézier extraction on a
//! periodic knot vector (paper §11.1, the `eta` direction of an O-grid).
//!
//! # Representation
//!
//! A periodic knot vector of degree `p` and period `L` stores `d + 2p + 1` knots
//! `t_0 <= ... <= t_{d+2p}` with `t_{k+d} = t_k + L` and domain `[t_p, t_{p+d}] =
//! [a, a + L]`; it has `n = d + p` (unwrapped) B-splines `N_0, ..., N_{n-1}`, and the
//! periodic space has dimension `d`. A periodic curve stores `n` control points with the
//! last `p` repeating the first `p` (*wrapped indices*):
//!
//! `C(u) = sum_{k=0}^{n-1} c_{k mod d} N_k(u)`, `u in [a, a + L]`,
//!
//! so the stored vector and control points are an ordinary (unclamped) B-spline that
//! every evaluator reads unchanged, and the `d` distinct control points `c_0..c_{d-1}`
//! are the degrees of freedom. This is the layout of `formats.md` (`control_points.len()
//! + degree + 1 = knots.len()`). Continuing `t_k` to all integers `k`
//! ([`KnotVector::extended`]) makes `N_k` the bi-infinite periodic family.
//!
//! # Knot insertion and degree elevation
//!
//! The operators are computed by blossoming: the coefficient of the fine B-spline `N'_i`
//! (knots `tau`) of a spline `s` of degree `p` is its blossom (polar form) at the
//! fine knots, `c'_i = B_s(tau_{i+1}, ..., tau_{i+p})` (de Boor–Fix / Ramshaw), evaluated
//! on any polynomial piece of `s` on an interval `[t_j, t_{j+1}] ⊂ [tau_i, tau_{i+p+1}]`
//! by the de Boor recurrence with argument `x_r = tau_{i+r}` at level `r`:
//!
//! `d_j^r = (1 - α) d_{j-1}^{r-1} + α d_j^{r-1}`, `α = (x_r - t_j) / (t_{j+p+1-r} - t_j)`.
//!
//! Applied to unit coefficient vectors this gives row `i` of the prolongation `P`
//! (`c' = P c`); columns are taken modulo `d` (wrapped). Degree elevation interpolates
//! at the `d'` Greville abscissae of the elevated periodic space (nested spaces, so the
//! interpolant is the curve itself). Bézier extraction is the blossom at
//! `(a^{p-k}, b^k)` on each element `[a, b]`: the `k`-th Bernstein coefficient.

use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;
use crate::spline::basis::BasisDerivs;
use crate::spline::knots::KnotVector;

/// The weights `w_0..=w_p` with `B(x_1, ..., x_p) = sum_j w_j c_{s-p+j}` for the
/// polynomial piece of a degree-`p` spline on the non-empty interval `[t_s, t_{s+1}]`,
/// `t` given by `knot(k)` for integer `k` (see the module documentation).
pub(crate) fn blossom_weights(knot: impl Fn(isize) -> f64, p: usize, s: isize, x: &[f64]) -> Vec<f64> {
    let mut d: Vec<Vec<f64>> = (0..=p).map(|j| (0..=p).map(|k| if k == j { 1.0 } else { 0.0 }).collect()).collect();
    for r in 1..=p {
        for jj in (r..=p).rev() {
            let j = s - p as isize + jj as isize;
            let (tj, tk) = (knot(j), knot(j + (p + 1 - r) as isize));
            let alpha = (x[r - 1] - tj) / (tk - tj);
            let (lo, hi) = d.split_at_mut(jj);
            for (v, &prev) in hi[0].iter_mut().zip(&lo[jj - 1]) {
                *v = (1.0 - alpha) * prev + alpha * *v;
            }
        }
    }
    d.swap_remove(p)
}

/// The extended span `s` with `t_s <= u < t_{s+1}` of a periodic vector, for any real `u`
/// (`t_s < t_{s+1}`).
fn extended_span(kv: &KnotVector, u: f64) -> isize {
    let (a, l) = (kv.domain().0, kv.length());
    let q = ((u - a) / l).floor();
    let mut w = u - q * l;
    let mut q = q as isize;
    if w >= a + l {
        w -= l;
        q += 1;
    }
    let s = kv.find_span(w.max(a)) as isize;
    s + q * kv.dim() as isize
}

/// Append `w` to the sparse row `row` at wrapped column `col mod d`.
pub(super) fn add_wrapped(row: &mut Vec<(usize, f64)>, col: isize, d: usize, w: f64) {
    let c = col.rem_euclid(d as isize) as usize;
    match row.iter_mut().find(|e| e.0 == c) {
        Some(e) => e.1 += w,
        None => row.push((c, w)),
    }
}

/// Expand the `d'` rows of a periodic operator to the `n' = d' + p'` stored fine
/// functions (row `k` is row `k mod d'`), columns the `n` stored coarse functions.
fn expand(rows: Vec<Vec<(usize, f64)>>, n_fine: usize, n_coarse: usize) -> Csr {
    let d = rows.len();
    let all = (0..n_fine)
        .map(|k| {
            let mut r = rows[k % d].clone();
            r.sort_by_key(|e| e.0);
            r.retain(|e| e.1 != 0.0);
            r
        })
        .collect();
    Csr::from_rows(n_coarse, all)
}

/// The prolongation `P` (`n_fine x n_coarse`, stored functions) between two periodic
/// vectors of one degree and period with `fine ⊇ coarse` (one period of knots); the
/// columns of the `p` repeated coarse functions are zero, so `P c` is right for wrapped
/// control points. Exact: `sum_k (P c)_k N'_k = sum_k c_k N_k`.
pub(crate) fn periodic_prolongation(coarse: &KnotVector, fine: &KnotVector) -> Result<Csr> {
    if !coarse.is_periodic() || !fine.is_periodic() || !fine.contains(coarse) {
        return Err(Error::Invalid(format!(
            "periodic refinement needs two periodic vectors of one degree and period with the fine one containing the coarse one (p={} on {:?}, periodic {}; p={} on {:?}, periodic {})",
            coarse.degree(),
            coarse.domain(),
            coarse.is_periodic(),
            fine.degree(),
            fine.domain(),
            fine.is_periodic()
        )));
    }
    let p = coarse.degree();
    let (d, df) = (coarse.dim(), fine.dim());
    let mut rows = Vec::with_capacity(df);
    for i in 0..df as isize {
        // the longest fine interval inside the support of N'_i picks the coarse piece
        let k = (i..=i + p as isize)
            .max_by(|&a, &b| {
                let la = fine.extended(a + 1) - fine.extended(a);
                let lb = fine.extended(b + 1) - fine.extended(b);
                la.total_cmp(&lb)
            })
            .expect("p + 1 candidates");
        let mid = 0.5 * (fine.extended(k) + fine.extended(k + 1));
        let s = extended_span(coarse, mid);
        let x: Vec<f64> = (1..=p as isize).map(|r| fine.extended(i + r)).collect();
        let w = blossom_weights(|j| coarse.extended(j), p, s, &x);
        let mut row = Vec::with_capacity(p + 1);
        for (jj, &wj) in w.iter().enumerate() {
            add_wrapped(&mut row, s - p as isize + jj as isize, d, wj);
        }
        rows.push(row);
    }
    Ok(expand(rows, fine.num_basis(), coarse.num_basis()))
}

/// Degree elevation of a periodic vector: the elevated vector (every distinct knot one
/// more time, [`KnotVector::elevated`]) and `E` (`n' x n`, stored functions) by
/// interpolation at the `d'` Greville abscissae of the elevated periodic space, reduced
/// to `[a, a + L)`.
pub(crate) fn periodic_elevation(kv: &KnotVector) -> Result<(KnotVector, Csr)> {
    if !kv.is_periodic() {
        return Err(Error::Invalid("periodic_elevation needs a periodic knot vector".into()));
    }
    let fine = kv.elevated();
    let (a, l) = (kv.domain().0, kv.length());
    let (d, df) = (kv.dim(), fine.dim());
    let g = fine.greville();
    let mut am = vec![vec![0.0; df]; df];
    let mut bm = vec![vec![0.0; d]; df];
    for i in 0..df {
        let u = a + (g[i] - a).rem_euclid(l);
        let bf = BasisDerivs::at(&fine, u, 0);
        for (j, &v) in bf.ders(0).iter().enumerate() {
            am[i][(bf.first() + j) % df] += v;
        }
        let bc = BasisDerivs::at(kv, u, 0);
        for (j, &v) in bc.ders(0).iter().enumerate() {
            bm[i][(bc.first() + j) % d] += v;
        }
    }
    let x = crate::linalg::linsolve::dense_solve(&am, &bm);
    let rows = x.into_iter().map(|r| r.into_iter().enumerate().filter(|(_, v)| v.abs() > 1e-15).collect()).collect();
    Ok((fine.clone(), expand(rows, fine.num_basis(), kv.num_basis())))
}

/// The open (clamped) knot vector on the domain `[a, a + L]` of a periodic `kv` (its
/// interior knots, both ends `p + 1` times) and the operator `C` (`n_open x n` stored
/// functions) with `sum_i (C c)_i N^open_i = sum_k c_k N_k` on `[a, a + L]`: the same
/// curve as an ordinary clamped spline whose first and last control points coincide (the
/// seam's continuity is no longer built into the basis). Coefficients by blossoming, as
/// in [`periodic_prolongation`].
pub(crate) fn periodic_to_open(kv: &KnotVector) -> Result<(KnotVector, Csr)> {
    if !kv.is_periodic() {
        return Err(Error::Invalid("periodic_to_open needs a periodic knot vector".into()));
    }
    let (p, d) = (kv.degree(), kv.dim());
    let (a, b) = kv.domain();
    let mut knots = vec![a; p + 1];
    knots.extend(kv.knots().iter().copied().filter(|&t| t > a && t < b));
    knots.extend(std::iter::repeat_n(b, p + 1));
    let open = KnotVector::new(p, knots)?;
    let t = open.knots();
    let rows = (0..open.num_basis())
        .map(|i| {
            let k = (i..=i + p).max_by(|&x, &y| (t[x + 1] - t[x]).total_cmp(&(t[y + 1] - t[y]))).expect("p + 1");
            let s = extended_span(kv, 0.5 * (t[k] + t[k + 1]));
            let w = blossom_weights(|j| kv.extended(j), p, s, &t[i + 1..=i + p]);
            let mut row = Vec::with_capacity(p + 1);
            for (jj, &wj) in w.iter().enumerate() {
                add_wrapped(&mut row, s - p as isize + jj as isize, d, wj);
            }
            row.sort_by_key(|e| e.0);
            row
        })
        .collect();
    Ok((open, Csr::from_rows(kv.num_basis(), rows)))
}

/// An element `(span, a, b)`: `[t_span, t_span+1] = [a, b]`.
pub type Element = (usize, f64, f64);

/// Bézier extraction operators of a periodic vector, per element `(span, a, b)` of the
/// domain: `ops[e][j * (p + 1) + k]` is the `k`-th Bernstein coefficient on `[a, b]` of
/// the stored B-spline `N_{span - p + j}`, the blossom at `(a^{p-k}, b^k)`.
pub(crate) fn periodic_extraction(kv: &KnotVector) -> (Vec<Element>, Vec<Vec<f64>>) {
    let p = kv.degree();
    let elements = kv.elements();
    let ops = elements
        .iter()
        .map(|&(span, a, b)| {
            let mut op = vec![0.0; (p + 1) * (p + 1)];
            for k in 0..=p {
                let x: Vec<f64> = (0..p).map(|r| if r < p - k { a } else { b }).collect();
                let w = blossom_weights(|j| kv.extended(j), p, span as isize, &x);
                for (j, &v) in w.iter().enumerate() {
                    op[j * (p + 1) + k] = v;
                }
            }
            op
        })
        .collect();
    (elements, ops)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::bezier::{bernstein, BezierExtraction};
    use crate::spline::curve::{Curve, Point};
    use crate::spline::translate::PeriodicTranslate;
    use crate::testutil::Lcg;

    /// A random closed curve on a periodic vector of `d` non-uniform knots per period
    /// (with one double knot) on `[a, a + l]`.
    fn random_closed(rng: &mut Lcg, p: usize, d: usize, rational: bool) -> Curve {
        let (a, l) = (0.2, 1.7);
        let mut period: Vec<f64> = vec![a];
        for _ in 1..d {
            period.push(a + l * (0.05 + 0.9 * rng.uniform()));
        }
        period.sort_by(f64::total_cmp);
        if p >= 2 {
            period[d / 2 + 1] = period[d / 2];
        }
        let kv = KnotVector::periodic_from_period(p, &period, l).unwrap();
        let dim = kv.dim();
        let free: Vec<Point> = (0..dim).map(|_| [rng.uniform(), rng.uniform()]).collect();
        let cps = (0..kv.num_basis()).map(|k| free[k % dim]).collect();
        let w = rational.then(|| {
            let w: Vec<f64> = (0..dim).map(|_| 0.5 + rng.uniform()).collect();
            (0..kv.num_basis()).map(|k| w[k % dim]).collect()
        });
        Curve::new(kv, cps, w).unwrap()
    }

    /// Parameters across the domain, the seam included from both sides.
    fn params(c: &Curve) -> Vec<f64> {
        let (a, b) = c.domain();
        let mut u: Vec<f64> = (0..=211).map(|k| a + (b - a) * k as f64 / 211.0).collect();
        u.extend([a + 1e-9, b - 1e-9, a + 1e-3 * (b - a), b - 1e-3 * (b - a)]);
        u
    }

    fn assert_same(c: &Curve, f: &Curve, what: &str) {
        for u in params(c) {
            let (x, y) = (c.derivs(u, 2), f.derivs(u, 2));
            for i in 0..2 {
                assert!((x.x[i] - y.x[i]).abs() < 1e-13, "{what}: u={u} {:?} vs {:?}", x.x, y.x);
                assert!((x.d1[i] - y.d1[i]).abs() < 1e-10 * (1.0 + x.d1[i].abs()), "{what}: d1 at {u}");
            }
        }
    }

    /// The curve is closed with the continuity `C^{p-m}` of the seam knot (multiplicity
    /// `m`): values and the first `min(p - m, 2)` derivatives agree at both ends.
    fn assert_closed(c: &Curve) {
        let (a, b) = c.domain();
        let (x, y) = (c.derivs(a, 2), c.derivs(b, 2));
        let p = (c.knots.continuity_at(a) + 1).max(1) as usize;
        for i in 0..2 {
            assert!((x.x[i] - y.x[i]).abs() < 1e-13);
            if p >= 2 {
                assert!((x.d1[i] - y.d1[i]).abs() < 1e-10 * (1.0 + x.d1[i].abs()), "{:?} {:?}", x.d1, y.d1);
            }
            if p >= 3 {
                assert!((x.d2[i] - y.d2[i]).abs() < 1e-8 * (1.0 + x.d2[i].abs()), "{:?} {:?}", x.d2, y.d2);
            }
        }
    }

    #[test]
    fn periodic_insertion_reproduces_closed_curves() {
        let mut rng = Lcg::new(17);
        for p in 1..=5 {
            for rational in [false, true] {
                let c = random_closed(&mut rng, p, 6, rational);
                assert_closed(&c);
                let (a, b) = c.domain();
                // halving, a double knot, and knots right at both sides of the seam
                let fine = c.knots.halved().with_inserted(&[a + 0.3, a + 0.3, b - 1e-3, a + 2e-3]);
                assert!(fine.is_periodic() && fine.contains(&c.knots) && !c.knots.contains(&fine));
                assert_eq!(fine.dim(), c.knots.dim() + c.knots.num_elements() + 4);
                let f = c.refined(&fine).unwrap();
                assert_same(&c, &f, &format!("refine p={p}"));
                assert_closed(&f);
                // the refined control points wrap
                let d = fine.dim();
                for k in d..f.control_points.len() {
                    assert_eq!(f.control_points[k], f.control_points[k - d]);
                }
            }
        }
    }

    #[test]
    fn periodic_elevation_reproduces_closed_curves() {
        let mut rng = Lcg::new(29);
        for p in 1..=4 {
            for rational in [false, true] {
                let c = random_closed(&mut rng, p, 7, rational);
                let e = c.elevated().unwrap();
                assert_eq!(e.degree(), p + 1);
                assert!(e.knots.is_periodic());
                assert_eq!(e.knots.dim(), c.knots.dim() + c.knots.breaks().len() - 1);
                assert_same(&c, &e, &format!("elevate p={p}"));
                assert_closed(&e);
                let e2 = e.elevated().unwrap().refined(&e.elevated().unwrap().knots.halved()).unwrap();
                assert_same(&c, &e2, &format!("elevate twice and refine p={p}"));
            }
        }
    }

    #[test]
    fn periodic_bezier_extraction_reproduces_bsplines() {
        let mut rng = Lcg::new(5);
        for p in 1..=5 {
            let c = random_closed(&mut rng, p, 5, false);
            let kv = &c.knots;
            let ex = BezierExtraction::new(kv).unwrap();
            assert_eq!(ex.elements.len(), kv.num_elements());
            let mut b = [0.0; 8];
            for (e, &(span, a, bb)) in ex.elements.iter().enumerate() {
                for k in 0..=12 {
                    let u = a + (bb - a) * k as f64 / 12.0;
                    let mut nd = BasisDerivs::default();
                    nd.eval_in_span(kv, span, u, 0);
                    bernstein(p, (u - a) / (bb - a), &mut b);
                    for j in 0..=p {
                        let v: f64 = (0..=p).map(|k| ex.ops[e][j * (p + 1) + k] * b[k]).sum();
                        assert!((v - nd.d[0][j]).abs() < 1e-13, "p={p} e={e} j={j}: {v} vs {}", nd.d[0][j]);
                    }
                }
            }
        }
    }

    #[test]
    fn periodic_vectors_are_validated() {
        assert!(KnotVector::with_periodic(2, vec![0., 1., 2., 3., 4., 5., 6.5], true).is_err());
        assert!(KnotVector::with_periodic(2, vec![0., 1., 2., 3., 4., 5., 6.], true).is_ok());
        let kv = KnotVector::periodic_uniform(2, 4);
        assert_eq!(kv.dim(), 4);
        let bad: Vec<Point> = (0..kv.num_basis()).map(|k| [k as f64, 0.0]).collect();
        let e = Curve::new(kv, bad, None).unwrap_err().to_string();
        assert!(e.contains("wrap"), "{e}");
    }

    /// The translate projection: `sigma = 0` and whole-span shifts of a uniform vector are
    /// exact, rotations commute with it, and it agrees with a brute-force projection.
    #[test]
    fn translate_projection_is_exact_where_it_must_be() {
        let mut rng = Lcg::new(41);
        let c = random_closed(&mut rng, 3, 9, false);
        let mut pr = PeriodicTranslate::new(&c.knots).unwrap();
        let same = pr.translate(&c, 0.0).unwrap();
        assert_same(&c, &same, "sigma = 0");
        // uniform vector: a shift by 3 spans is a cyclic shift of the control points
        let kv = KnotVector::periodic_uniform(3, 12);
        let free: Vec<Point> = (0..12).map(|_| [rng.uniform(), rng.uniform()]).collect();
        let u = Curve::polynomial(kv.clone(), (0..15).map(|k| free[k % 12]).collect());
        let mut pu = PeriodicTranslate::new(&kv).unwrap();
        let sh = pu.translate(&u, 3.0 / 12.0 + 2.0).unwrap();
        for x in 0..=50 {
            let t = x as f64 / 50.0;
            let (a, b) = (sh.eval(t), u.eval((t + 0.25).rem_euclid(1.0)));
            assert!((a[0] - b[0]).abs() < 1e-13 && (a[1] - b[1]).abs() < 1e-13, "{t}: {a:?} {b:?}");
        }
        // a general shift: the projection of the rotated curve is the rotated projection,
        // and it matches the L2 projection computed with dense midpoint sums
        let sigma = 0.377;
        let (ca, sa) = (0.6f64.cos(), 0.6f64.sin());
        let rot = |p: Point| [ca * p[0] - sa * p[1] + 1.0, sa * p[0] + ca * p[1] - 2.0];
        let cr = Curve { control_points: c.control_points.iter().map(|&q| rot(q)).collect(), ..c.clone() };
        let (p1, p2) = (pr.translate(&c, sigma).unwrap(), pr.translate(&cr, sigma).unwrap());
        for (q1, q2) in p1.control_points.iter().zip(&p2.control_points) {
            let r = rot(*q1);
            assert!((r[0] - q2[0]).abs() < 1e-12 && (r[1] - q2[1]).abs() < 1e-12);
        }
        let (a, l) = (c.domain().0, c.knots.length());
        let d = c.knots.dim();
        let m = 200_000;
        let mut mm = vec![vec![0.0; d]; d];
        let mut bb = vec![vec![0.0; 2]; d];
        for k in 0..m {
            let u = a + l * (k as f64 + 0.5) / m as f64;
            let nd = BasisDerivs::at(&c.knots, u, 0);
            let x = c.eval(a + (u + sigma - a).rem_euclid(l));
            for (ja, &va) in nd.ders(0).iter().enumerate() {
                let i = (nd.first() + ja) % d;
                bb[i][0] += va * x[0];
                bb[i][1] += va * x[1];
                for (jb, &vb) in nd.ders(0).iter().enumerate() {
                    mm[i][(nd.first() + jb) % d] += va * vb;
                }
            }
        }
        let x = crate::linalg::linsolve::dense_solve(&mm, &bb);
        for (k, xk) in x.iter().enumerate() {
            let q = p1.control_points[k];
            assert!((q[0] - xk[0]).abs() < 1e-6 && (q[1] - xk[1]).abs() < 1e-6, "{k}: {q:?} vs {xk:?}");
        }
    }

    /// `sigma -> P s_sigma` is `C^{2p}` (see [`PeriodicTranslate`]): a degree-5 Lagrange
    /// extrapolation in `sigma` across knots keeps its order, the error falls like
    /// `Δ^6` when the step halves, where a `C^{p-1}` function would fall like `Δ^p`.
    #[test]
    fn translates_are_smooth_in_the_shift() {
        let mut rng = Lcg::new(3);
        let c = random_closed(&mut rng, 3, 8, false);
        let mut pr = PeriodicTranslate::new(&c.knots).unwrap();
        let knot = c.knots.period_knots()[3] - c.knots.period_knots()[0];
        let mut err = |h: f64| {
            // six shifts before, one after a knot crossing at `knot`
            let s0 = knot - 3.5 * h;
            let pts: Vec<Curve> = (0..7).map(|k| pr.translate(&c, s0 + k as f64 * h).unwrap()).collect();
            let mut e: f64 = 0.0;
            for j in 0..c.control_points.len() {
                for x in 0..2 {
                    // Lagrange at k = 6 through k = 0..5: weights (-1)^(k+1) C(6, k)
                    let w = [-1.0, 6.0, -15.0, 20.0, -15.0, 6.0];
                    let pred: f64 = (0..6).map(|k| w[k] * pts[k].control_points[j][x]).sum();
                    e = e.max((pred - pts[6].control_points[j][x]).abs());
                }
            }
            e
        };
        let (e1, e2) = (err(2e-2), err(1e-2));
        assert!(e2 < e1 / 30.0, "ratio {} ({e1:e} -> {e2:e})", e1 / e2);
    }

    /// The open equivalent of a periodic curve is the same curve on its domain, for every
    /// degree, with a double knot, rational too.
    #[test]
    fn periodic_curves_open_exactly() {
        let mut rng = Lcg::new(23);
        for p in 1..=5 {
            for rational in [false, true] {
                let c = random_closed(&mut rng, p, 7, rational);
                let (open, op) = periodic_to_open(&c.knots).unwrap();
                assert!(open.is_open() && open.domain() == c.knots.domain());
                let w = |k: usize| c.weights.as_ref().map_or(1.0, |w| w[k]);
                let hom: Vec<[f64; 3]> = (0..op.nrows)
                    .map(|r| {
                        op.row(r).fold([0.0; 3], |a, (k, v)| {
                            let q = c.control_points[k];
                            [a[0] + v * w(k) * q[0], a[1] + v * w(k) * q[1], a[2] + v * w(k)]
                        })
                    })
                    .collect();
                let cps = hom.iter().map(|h| [h[0] / h[2], h[1] / h[2]]).collect();
                let weights = rational.then(|| hom.iter().map(|h| h[2]).collect());
                let o = Curve::new(open, cps, weights).unwrap();
                assert_same(&c, &o, &format!("open p={p} rational={rational}"));
            }
        }
    }
}
