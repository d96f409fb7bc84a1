//! Bézier extraction: on each element the B-splines are linear combinations of the
//! Bernstein polynomials, `N^e = C^e B` (Borden et al. 2011). `C^e` is read off the
//! prolongation onto the knot vector in which every break has multiplicity `p`.

use crate::error::{Error, Result};
use crate::spline::knots::KnotVector;
use crate::spline::refine::prolongation;

/// Bernstein polynomials `B_k^p(t) = binom(p, k) t^k (1 - t)^(p - k)`, `k = 0..=p`, at `t`.
pub(crate) fn bernstein(p: usize, t: f64, out: &mut [f64]) {
    out[0] = 1.0;
    let s = 1.0 - t;
    for j in 1..=p {
        let mut saved = 0.0;
        for k in 0..j {
            let tmp = out[k];
            out[k] = saved + s * tmp;
            saved = t * tmp;
        }
        out[j] = saved;
    }
}

/// Per-element extraction operators of a univariate basis.
#[derive(Debug, Clone)]
pub(crate) struct BezierExtraction {
    /// Elements as `(span, a, b)`.
    pub elements: Vec<(usize, f64, f64)>,
    /// For element `e`, `ops[e][j * (p + 1) + k]` is the coefficient of Bernstein `k`
    /// in the local B-spline `N_{span - p + j}`.
    pub ops: Vec<Vec<f64>>,
}

impl BezierExtraction {
    /// Extraction operators of an open knot vector with interior multiplicities `<= p`.
    /// Periodic vectors are extracted by blossoming
    /// ([`crate::spline::periodic::periodic_extraction`]).
    pub fn new(kv: &KnotVector) -> Result<Self> {
        let p = kv.degree();
        if kv.is_periodic() {
            let (elements, ops) = crate::spline::periodic::periodic_extraction(kv);
            return Ok(Self { elements, ops });
        }
        let bm = kv.breaks_with_multiplicity();
        if let Some(&(u, m)) = bm[1..bm.len() - 1].iter().find(|&&(_, m)| m > p) {
            return Err(Error::Invalid(format!(
                "Bézier extraction needs interior multiplicities <= p: knot {u} has multiplicity {m} > {p}"
            )));
        }
        let inner: Vec<f64> = bm[1..bm.len() - 1].iter().flat_map(|&(u, m)| std::iter::repeat_n(u, p - m)).collect();
        let bez = kv.with_inserted(&inner);
        let pm = prolongation(kv, &bez)?;
        let elements = kv.elements();
        let mut ops = Vec::with_capacity(elements.len());
        for (e, &(span, _, _)) in elements.iter().enumerate() {
            let mut op = vec![0.0; (p + 1) * (p + 1)];
            for k in 0..=p {
                for (col, v) in pm.row(e * p + k) {
                    if col + p >= span && col <= span {
                        op[(col + p - span) * (p + 1) + k] = v;
                    }
                }
            }
            ops.push(op);
        }
        Ok(Self { elements, ops })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::basis::BasisDerivs;

    #[test]
    fn extraction_reproduces_bsplines() {
        let kv = KnotVector::new(3, vec![0., 0., 0., 0., 0.2, 0.5, 0.5, 0.7, 0.7, 0.7, 1., 1., 1., 1.]).unwrap();
        let ex = BezierExtraction::new(&kv).unwrap();
        let p = 3;
        let mut b = [0.0; 4];
        for (e, &(span, a, bb)) in ex.elements.iter().enumerate() {
            for k in 0..=10 {
                let u = a + (bb - a) * (k as f64 + 0.5) / 11.0;
                let nd = {
                    let mut d = BasisDerivs::default();
                    d.eval_in_span(&kv, span, u, 0);
                    d
                };
                bernstein(p, (u - a) / (bb - a), &mut b);
                for j in 0..=p {
                    let v: f64 = (0..=p).map(|k| ex.ops[e][j * (p + 1) + k] * b[k]).sum();
                    assert!((v - nd.d[0][j]).abs() < 1e-14, "e={e} j={j}");
                }
            }
        }
    }

    #[test]
    fn bernstein_partition_of_unity() {
        let mut b = [0.0; 8];
        bernstein(7, 0.37, &mut b);
        assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!((b[0] - 0.63f64.powi(7)).abs() < 1e-16);
    }
}
