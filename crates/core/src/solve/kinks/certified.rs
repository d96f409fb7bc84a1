//! The certified maps as the feasible set of a minimisation.
//!
//! The Winslow functional (16) sees `det J` only at its quadrature points, so its
//! minimiser may fold between them, or at a point of a kinked side where a zero of
//! `det J` costs the integral nothing finite (module `kinks`). [`Certified`] wraps a
//! [`DiscreteProblem`] so that its line search accepts only maps the certificate proves
//! bijective: every iterate of a minimisation from a certified start is then certified,
//! and the last one is a certified map with `J` no larger than the start's (the line
//! search's Armijo rule, eq. 25).

use crate::discrete::assembly::Discretization;
use crate::linalg::sparse::Csr;
use crate::methods::DiscreteProblem;
use crate::solve::fixed_basis::bijective;
use crate::spline::curve::Point;
use crate::spline::surface::Surface;
use crate::verify::certificate::{certify, CertifyOptions};

/// `inner` with the feasible set cut down to the unknowns whose map on `knots` (with
/// `weights`) the certificate proves bijective ([`bijective`]).
pub struct Certified<P> {
    inner: P,
    disc: std::sync::Arc<Discretization>,
    weights: Option<Vec<f64>>,
    opts: CertifyOptions,
    /// Certificates asked for (line-search trial points).
    pub certificates: usize,
}

impl<P: DiscreteProblem> Certified<P> {
    /// `inner` posed on `disc` (whose knots the control points live on), maps with
    /// `weights`, certified with `opts`.
    pub fn new(
        inner: P,
        disc: std::sync::Arc<Discretization>,
        weights: Option<Vec<f64>>,
        opts: CertifyOptions,
    ) -> Self {
        Self { inner, disc, weights, opts, certificates: 0 }
    }

    /// Whether the map of the unknowns `c` is certified bijective (an error of the
    /// certificate counts as not).
    pub fn certified(&mut self, c: &[f64]) -> bool {
        self.certificates += 1;
        let map = Surface {
            knots: self.disc.knots.clone(),
            control_points: self.inner.control_points(c),
            weights: self.weights.clone(),
        };
        certify(&map, &self.opts).is_ok_and(|cert| bijective(&cert))
    }
}

impl<P: DiscreteProblem> DiscreteProblem for Certified<P> {
    fn size(&self) -> usize {
        self.inner.size()
    }
    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        self.inner.residual(c, f)
    }
    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        self.inner.jacobian(c, f, jac)
    }
    fn jacobian_operator(&mut self, c: &[f64], f: &mut [f64]) -> bool {
        self.inner.jacobian_operator(c, f)
    }
    fn jacobian_product(&self, x: &[f64], y: &mut [f64]) {
        self.inner.jacobian_product(x, y)
    }
    fn mass(&mut self) -> &Csr {
        self.inner.mass()
    }
    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        self.inner.objective(c)
    }
    /// The inner problem's feasible set, and certified bijective.
    fn admissible(&mut self, c: &[f64]) -> bool {
        self.inner.admissible(c) && self.certified(c)
    }
    fn raise_shift(&mut self) -> bool {
        self.inner.raise_shift()
    }
    fn modified(&self) -> bool {
        self.inner.modified()
    }
    fn step_accepted(&mut self, delta: f64) {
        self.inner.step_accepted(delta)
    }
    fn rank_one(&self) -> Option<(f64, &[f64])> {
        self.inner.rank_one()
    }
    fn preconditioner(&mut self, shift: f64) -> Option<&Csr> {
        self.inner.preconditioner(shift)
    }
    fn ordering(&self) -> Option<&[usize]> {
        self.inner.ordering()
    }
    fn take_preconditioner(&mut self, shift: f64) -> Option<Csr> {
        self.inner.take_preconditioner(shift)
    }

    fn transfers(&self) -> Vec<[Csr; 2]> {
        self.inner.transfers()
    }
    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        self.inner.control_points(c)
    }
}

#[cfg(test)]
mod tests {
    use super::Certified;
    use crate::discrete::assembly::Discretization;
    use crate::discrete::dofs::DofMap;
    use crate::methods::winslow::WinslowMethod;
    use crate::methods::{DiscreteProblem, Method};
    use crate::solve::fixed_basis::bijective;
    use crate::spline::curve::Point;
    use crate::spline::knots::KnotVector;
    use crate::spline::surface::Surface;
    use crate::verify::certificate::{certify, CertifyOptions};
    use std::sync::Arc;

    /// A degree-2 net on `[0, 1]²` whose south side turns at the `C^0` knot `ξ = 1/2`
    /// by -100 degrees (a reflex kink, 260 degrees inside), with the control point above
    /// the kink, `P_1`, at `φ` degrees past the edge of the kink's wedge (the direction
    /// `-t_+` of the outgoing tangent, turned counterclockwise): `det J` at the kink from
    /// the right is
    /// `det(t_+, P_1 - P_0) = -|t_+| |P_1 - P_0| sin φ < 0`, a fold at one boundary point
    /// and in a sliver next to it. For small `φ` the Winslow functional (16) on `p + 2`
    /// Gauss points per direction is finite (no quadrature point in the sliver), while
    /// [`Certified`] refuses the map and so does Gauss-Lobatto quadrature, whose points
    /// include the kink's one-sided limits.
    #[test]
    fn certified_set_refuses_a_fold_at_a_kink_that_gauss_points_miss() {
        let knots =
            [KnotVector::new(2, vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0]).unwrap(), KnotVector::open_uniform(2, 2)];
        let (gu, gv) = (knots[0].greville(), knots[1].greville());
        let (nx, ny) = (gu.len(), gv.len());
        let mut cps: Vec<Point> = gv.iter().flat_map(|&v| gu.iter().map(move |&u| [u, v])).collect();
        let a = (-100f64).to_radians();
        let tangent = [a.cos(), a.sin()];
        cps[3] = [0.5 + 0.25 * tangent[0], 0.25 * tangent[1]];
        let dofs = || DofMap::from_predicate([nx, ny], |i, j| i > 0 && i + 1 < nx && j > 0 && j + 1 < ny);
        let gauss = Arc::new(Discretization::with_dofs(knots.clone(), 4, dofs()));
        let lobatto = Arc::new(Discretization::with_dofs_lobatto(knots.clone(), 4, dofs()));
        let above = nx + 2;
        let mut missed = 0;
        for phi in [0.5f64, 1.0, 2.0, 4.0] {
            let b = (a + std::f64::consts::PI + phi.to_radians()).sin_cos();
            let mut net = cps.clone();
            net[above] = [0.5 + 0.3 * b.1, 0.3 * b.0];
            let map = Surface { knots: knots.clone(), control_points: net.clone(), weights: None };
            let right = map.derivs(0.5 + 1e-12, 0.0, 1).det_j();
            assert!(right < 0.0, "phi {phi}: det J {right} from the right at the kink");
            let cert = certify(&map, &CertifyOptions::default()).unwrap();
            assert!(!bijective(&cert), "phi {phi}: {}", cert.message());
            let c = gauss.dofs.gather(&net);
            let mut on_gauss = WinslowMethod.problem(gauss.clone(), net.clone());
            let mut on_lobatto = WinslowMethod.problem(lobatto.clone(), net.clone());
            assert!(on_lobatto.objective(&c).is_some_and(|j| j == f64::INFINITY), "phi {phi}: Lobatto sees the fold");
            let mut guarded = Certified::new(
                WinslowMethod.problem(gauss.clone(), net.clone()),
                gauss.clone(),
                None,
                CertifyOptions::default(),
            );
            assert!(!guarded.admissible(&c) && guarded.certificates == 1, "phi {phi}");
            if on_gauss.objective(&c).is_some_and(f64::is_finite) {
                missed += 1;
            }
        }
        // the quadrature barrier misses the fold at least at the smallest angle
        assert!(missed >= 1, "the Gauss points saw every fold");
        // and the wrapper admits a certified map: P_1 along the wedge's bisector
        let mut net = cps.clone();
        // n_- + n_+, the left normals of t_- = (1, 0) and t_+
        let n = [-tangent[1], 1.0 + tangent[0]];
        let l = n[0].hypot(n[1]);
        net[above] = [0.5 + 0.3 * n[0] / l, 0.3 * n[1] / l];
        let map = Surface { knots: knots.clone(), control_points: net.clone(), weights: None };
        let cert = certify(&map, &CertifyOptions::default()).unwrap();
        let c = gauss.dofs.gather(&net);
        let mut guarded =
            Certified::new(WinslowMethod.problem(gauss.clone(), net.clone()), gauss, None, CertifyOptions::default());
        assert_eq!(guarded.admissible(&c), bijective(&cert), "{}", cert.message());
    }
}
