//! The univariate basis at the quadrature points, computed once per basis ([`DirTable`]:
//! Gauss points and weights per element, the non-zero functions and their derivatives
//! there); the assembly forms their tensor products (`Discretization::tensor_basis`, up to
//! second derivatives for the EGG form, eq. 8; `Discretization::tensor_basis_first`,
//! values and gradients for the first-order forms, eq. 14 and 16), rational (NURBS) by
//! the quotient rule.

use crate::error::MAX_DEGREE;
use crate::spline::basis::BasisDerivs;
use crate::spline::knots::KnotVector;
use crate::spline::quadrature::{GaussLegendre, GaussLobatto};

const W: usize = MAX_DEGREE + 1;

/// Univariate basis values at one quadrature point: weight (times element length),
/// abscissa, and `n[k][j]` = `k`-th derivative of the `j`-th non-zero function.
#[derive(Debug, Clone, Copy)]
pub struct QpTab {
    /// Quadrature weight scaled to the element.
    pub w: f64,
    /// Abscissa.
    pub u: f64,
    /// Values and derivatives.
    pub n: [[f64; W]; 3],
}

/// Basis tables of one direction: per element its first non-zero function and its
/// quadrature points.
#[derive(Debug, Clone)]
pub struct DirTable {
    /// Degree.
    pub p: usize,
    /// Points per element.
    pub nq: usize,
    /// First non-zero basis function per element.
    pub first: Vec<usize>,
    /// Element bounds.
    pub bounds: Vec<(f64, f64)>,
    /// `qp[e * nq + k]`.
    pub qp: Vec<QpTab>,
}

impl DirTable {
    /// Tabulate `kv` at `nq` Gauss points per element.
    pub fn new(kv: &KnotVector, nq: usize) -> Self {
        let g = GaussLegendre::new(nq);
        Self::with_rule(kv, nq, |a, b| g.on(a, b).collect())
    }

    /// Tabulate `kv` at `nq` Gauss-Lobatto points per element (the element's ends
    /// included: each element sees its own one-sided limit on a `C^0` knot).
    pub fn lobatto(kv: &KnotVector, nq: usize) -> Self {
        let g = GaussLobatto::new(nq);
        Self::with_rule(kv, g.points.len(), |a, b| g.on(a, b).collect())
    }

    /// Tabulate `kv` at the points and weights `rule(a, b)` gives on each element `[a, b]`
    /// (`nq` of them), the basis of the element's span at each (one-sided at its ends).
    fn with_rule(kv: &KnotVector, nq: usize, rule: impl Fn(f64, f64) -> Vec<(f64, f64)>) -> Self {
        let mut first = Vec::new();
        let mut bounds = Vec::new();
        let mut qp = Vec::new();
        let mut b = BasisDerivs::default();
        for (span, a, bb) in kv.elements() {
            first.push(span - kv.degree());
            bounds.push((a, bb));
            for (u, w) in rule(a, bb) {
                b.eval_in_span(kv, span, u, 2);
                qp.push(QpTab { w, u, n: b.d });
            }
        }
        Self { p: kv.degree(), nq, first, bounds, qp }
    }

    /// Number of elements.
    pub fn num_elements(&self) -> usize {
        self.first.len()
    }

    /// Table of point `k` of element `e`.
    pub fn at(&self, e: usize, k: usize) -> &QpTab {
        &self.qp[e * self.nq + k]
    }
}
