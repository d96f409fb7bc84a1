//! Knot insertion (Boehm), refinement with the prolongation operator as a sparse
//! matrix, and degree elevation. Both keep the geometry exactly: the coarse space is a
//! subspace of the fine one, so `c_fine = P c_coarse` reproduces the same map.

use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;
use crate::spline::basis::BasisDerivs;
use crate::spline::knots::KnotVector;

type SparseRow = Vec<(usize, f64)>;

fn combine(a: &SparseRow, wa: f64, b: &SparseRow, wb: f64) -> SparseRow {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        if j >= b.len() || (i < a.len() && a[i].0 < b[j].0) {
            out.push((a[i].0, wa * a[i].1));
            i += 1;
        } else if i >= a.len() || b[j].0 < a[i].0 {
            out.push((b[j].0, wb * b[j].1));
            j += 1;
        } else {
            out.push((a[i].0, wa * a[i].1 + wb * b[j].1));
            i += 1;
            j += 1;
        }
    }
    out
}

/// The prolongation `P` (`n_fine x n_coarse`) with `N_coarse_j = sum_i P_ij N_fine_i`,
/// so that coarse control points `c` become `P c` on the fine basis. `fine` must contain
/// every knot of `coarse`; the knots are inserted one by one with Boehm's algorithm.
/// Periodic vectors go to [`crate::spline::periodic::periodic_prolongation`].
pub fn prolongation(coarse: &KnotVector, fine: &KnotVector) -> Result<Csr> {
    if coarse.is_periodic() || fine.is_periodic() {
        return crate::spline::periodic::periodic_prolongation(coarse, fine);
    }
    let new = fine.difference(coarse).ok_or_else(|| {
        Error::Invalid(format!(
            "fine knot vector (p={}, {} knots) does not contain the coarse one (p={}, {} knots)",
            fine.degree(),
            fine.knots().len(),
            coarse.degree(),
            coarse.knots().len()
        ))
    })?;
    let p = coarse.degree();
    let (a, b) = coarse.domain();
    let mut t: Vec<f64> = coarse.knots().to_vec();
    let mut rows: Vec<SparseRow> = (0..coarse.num_basis()).map(|i| vec![(i, 1.0)]).collect();
    for &u in &new {
        if u <= a || u >= b {
            return Err(Error::Invalid(format!("cannot insert knot {u} outside the open domain ({a}, {b})")));
        }
        // k: last index with t[k] <= u
        let k = t.partition_point(|&x| x <= u) - 1;
        let n = rows.len();
        let mut next: Vec<SparseRow> = Vec::with_capacity(n + 1);
        for i in 0..=n {
            if i + p <= k {
                next.push(rows[i].clone());
            } else if i <= k {
                let alpha = (u - t[i]) / (t[i + p] - t[i]);
                next.push(combine(&rows[i], alpha, &rows[i - 1], 1.0 - alpha));
            } else {
                next.push(rows[i - 1].clone());
            }
        }
        rows = next;
        t.insert(k + 1, u);
    }
    Ok(Csr::from_rows(coarse.num_basis(), rows))
}

/// The operator `E` (`n_elevated x n`) that writes a degree-`p` spline in the basis of
/// degree `p + 1` with the same continuity (knot multiplicities raised by one). It is
/// obtained by interpolation at the Greville abscissae of the elevated space, which is
/// exact because the spaces are nested. Periodic vectors go to
/// [`crate::spline::periodic::periodic_elevation`].
pub(crate) fn elevation(kv: &KnotVector) -> Result<(KnotVector, Csr)> {
    if kv.is_periodic() {
        return crate::spline::periodic::periodic_elevation(kv);
    }
    let fine = kv.elevated();
    let g = fine.greville();
    let n_f = fine.num_basis();
    let n_c = kv.num_basis();
    let mut a = vec![vec![0.0; n_f]; n_f];
    let mut bmat = vec![vec![0.0; n_c]; n_f];
    for (i, &u) in g.iter().enumerate() {
        let bf = BasisDerivs::at(&fine, u, 0);
        for (j, &v) in bf.ders(0).iter().enumerate() {
            a[i][bf.first() + j] = v;
        }
        let bc = BasisDerivs::at(kv, u, 0);
        for (j, &v) in bc.ders(0).iter().enumerate() {
            bmat[i][bc.first() + j] = v;
        }
    }
    let x = crate::linalg::linsolve::dense_solve(&a, &bmat);
    let rows = x.into_iter().map(|r| r.into_iter().enumerate().filter(|(_, v)| v.abs() > 1e-15).collect()).collect();
    Ok((fine, Csr::from_rows(n_c, rows)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::curve::Curve;
    use crate::testutil::Lcg;

    fn random_curve(rng: &mut Lcg, p: usize, ne: usize, rational: bool) -> Curve {
        let kv = KnotVector::open_uniform(p, ne);
        let n = kv.num_basis();
        let cp = (0..n).map(|_| [rng.uniform(), rng.uniform()]).collect();
        let w = rational.then(|| (0..n).map(|_| 0.5 + rng.uniform()).collect());
        Curve::new(kv, cp, w).unwrap()
    }

    #[test]
    fn refinement_reproduces_curves() {
        let mut rng = Lcg::new(3);
        for p in 1..=5 {
            for rational in [false, true] {
                let c = random_curve(&mut rng, p, 4, rational);
                let mut fine = c.knots.halved();
                fine = fine.with_inserted(&[0.3, 0.3, 0.61]);
                let f = c.refined(&fine).unwrap();
                for k in 0..=97 {
                    let u = k as f64 / 97.0;
                    let (a, b) = (c.derivs(u, 2), f.derivs(u, 2));
                    for i in 0..2 {
                        assert!((a.x[i] - b.x[i]).abs() < 1e-13);
                        assert!((a.d1[i] - b.d1[i]).abs() < 1e-11 * (1.0 + a.d1[i].abs()));
                    }
                }
                let e = c.elevated().unwrap();
                assert_eq!(e.degree(), p + 1);
                for k in 0..=97 {
                    let u = k as f64 / 97.0;
                    let (a, b) = (c.eval(u), e.eval(u));
                    assert!((a[0] - b[0]).abs() < 1e-13 && (a[1] - b[1]).abs() < 1e-13, "p={p} {a:?} {b:?}");
                }
            }
        }
    }

    #[test]
    fn prolongation_rows_sum_to_one() {
        let kv = KnotVector::open_uniform(3, 3);
        let p = prolongation(&kv, &kv.halved().halved()).unwrap();
        for i in 0..p.nrows {
            let s: f64 = p.row(i).map(|e| e.1).sum();
            assert!((s - 1.0).abs() < 1e-14);
        }
        assert!(prolongation(&kv.halved(), &kv).is_err());
    }
}
