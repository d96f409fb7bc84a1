//! The `L2` projection of parameter translates of a closed curve onto its periodic spline
//! space (the boundary of a ring whose parameter slides, §11.1): [`PeriodicTranslate`].

use crate::error::{Error, Result};
use crate::linalg::sparse::Csr;
use crate::spline::basis::BasisDerivs;
use crate::spline::knots::KnotVector;
use crate::spline::periodic::add_wrapped;

/// The `L2` projection of parameter translates onto a periodic spline space `V` (knots
/// `t`, period `L`): for a curve `s(u) = sum_k c_k N_k(u)` in `V` and a shift `sigma`,
///
/// `P s_sigma = sum_i x_i N_i`, `M x = b`, `M_ij = ∫ N_i N_j du`, `b_i = ∫ N_i(u) s(u + sigma) du`,
///
/// integrals over one period with wrapped indices, computed exactly by `p + 1`-point Gauss
/// rules on the pieces between the period's knots and the knots moved by `-sigma` (both
/// factors are polynomials there). `P` is linear in the control points and reproduces
/// constants, so it commutes with affine maps of the plane (a rigid motion of the curve
/// moves its projection the same way); `sigma = 0`, and a shift that maps the knots onto
/// themselves (a multiple of `h` on a uniform vector), give the curve back exactly.
///
/// **Smoothness in `sigma`.** `b_i(sigma) = sum_k c_k ∫ N_i(u) N_k(u + sigma) du` is a
/// cross-correlation of two degree-`p` B-splines: piecewise polynomial of degree `2p + 1`
/// and `C^{2p}` in `sigma` (the `(p+1)`-th derivatives are sums of Dirac masses). A
/// parameter that slides along a curve (the sliding grid of §11.1) then moves the control
/// points smoothly in time, and the time extrapolation of `pipeline::sweep` keeps its
/// order; a refit to shifted samples would only be `C^{p-1}`.
#[derive(Debug)]
pub(crate) struct PeriodicTranslate {
    kv: KnotVector,
    mass: crate::linalg::linsolve::LinearSolver,
    gauss: crate::spline::quadrature::GaussLegendre,
}

impl PeriodicTranslate {
    /// The projector onto the periodic space of `kv` (its mass matrix factored once).
    pub fn new(kv: &KnotVector) -> Result<Self> {
        if !kv.is_periodic() {
            return Err(Error::Invalid("a translate projection needs a periodic knot vector".into()));
        }
        let (p, d) = (kv.degree(), kv.dim());
        let gauss = crate::spline::quadrature::GaussLegendre::new(p + 1);
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); d];
        for (span, a, b) in kv.elements() {
            for (u, w) in gauss.on(a, b) {
                let mut nd = BasisDerivs::default();
                nd.eval_in_span(kv, span, u, 0);
                for (ja, &va) in nd.ders(0).iter().enumerate() {
                    for (jb, &vb) in nd.ders(0).iter().enumerate() {
                        add_wrapped(&mut rows[(span - p + ja) % d], (span - p + jb) as isize, d, w * va * vb);
                    }
                }
            }
        }
        for r in &mut rows {
            r.sort_by_key(|e| e.0);
        }
        let m = Csr::from_rows(d, rows);
        let mut mass = crate::linalg::linsolve::LinearSolver::new(crate::linalg::linsolve::LinearMethod::Cholesky);
        mass.factor(&m)?;
        Ok(Self { kv: kv.clone(), mass, gauss })
    }

    /// `P s_sigma` (see the type) for a polynomial curve `s` on this projector's knots.
    pub(crate) fn translate(
        &mut self,
        s: &crate::spline::curve::Curve,
        sigma: f64,
    ) -> Result<crate::spline::curve::Curve> {
        if s.knots != self.kv || s.is_rational() || !sigma.is_finite() {
            return Err(Error::Invalid(format!(
                "a translate projection needs a polynomial curve on the projector's knots and a finite shift (rational {}, same knots {}, shift {sigma})",
                s.is_rational(),
                s.knots == self.kv
            )));
        }
        let kv = &self.kv;
        let (p, d) = (kv.degree(), kv.dim());
        let (a, l) = (kv.domain().0, kv.length());
        let wrap = |u: f64| a + (u - a).rem_euclid(l);
        let shift = (sigma / l).fract() * l;
        let mut cuts: Vec<f64> = kv.period_knots().iter().flat_map(|&t| [t, wrap(t - shift)]).collect();
        cuts.push(a + l);
        cuts.sort_by(f64::total_cmp);
        cuts.dedup_by(|x, y| (*x - *y).abs() <= 1e-14 * l);
        let mut b = vec![[0.0f64; 2]; d];
        let mut nd = BasisDerivs::default();
        for w2 in cuts.windows(2) {
            let (lo, hi) = (w2[0], w2[1]);
            if hi <= lo {
                continue;
            }
            let span = kv.find_span(0.5 * (lo + hi));
            for (u, w) in self.gauss.on(lo, hi) {
                nd.eval_in_span(kv, span, u, 0);
                let x = s.eval(wrap(u + shift));
                for (j, &v) in nd.ders(0).iter().enumerate() {
                    let i = (span - p + j) % d;
                    b[i][0] += w * v * x[0];
                    b[i][1] += w * v * x[1];
                }
            }
        }
        let mut cols = [vec![0.0; d], vec![0.0; d]];
        for (c, col) in cols.iter_mut().enumerate() {
            let rhs: Vec<f64> = b.iter().map(|v| v[c]).collect();
            *col = self.mass.solve(&rhs)?;
        }
        let cps = (0..kv.num_basis()).map(|k| [cols[0][k % d], cols[1][k % d]]).collect();
        Ok(crate::spline::curve::Curve::polynomial(kv.clone(), cps))
    }
}
