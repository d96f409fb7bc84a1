//! The EGG Galerkin form (eq. 8, 12, 23) and the Winslow functional (eq. 15-16) on a
//! THB discretization ([`HierarchicalDiscretization`], paper §4: "a (truncated)
//! hierarchical spline basis"), behind the same [`DiscreteProblem`] interface as on a
//! tensor basis.
//!
//! The integrands are the tensor assembly's, point by point: EGG's
//! [`egg_point`](crate::discrete::assembly) (the residual `∫ w_a L(z)` and the operands of
//! its exact Jacobian) and Winslow's [`winslow_density`] (`W`, `∂W/∂e`, `∂²W/∂e²`) with
//! [`projected_density_hessian`]; only the basis differs: at a Gauss point of an active
//! cell the test and trial functions are the THB functions non-zero on the cell, with
//! the values of their element extraction. On a one-level THB basis the residuals,
//! Jacobians and the functional equal the tensor ones (the same numbers summed in
//! another order).
//!
//! Unknowns `c = (c^x, c^y)` of the free THB functions (those whose trace on the
//! boundary is zero); the fixed ones keep the given control points (the Dirichlet data).

use std::sync::Arc;

use super::density::{lowered, raised, shift_diagonal};
use super::galerkin::block_mass;
use super::winslow::{projected_density_hessian, projection_lowered, projection_raised, winslow_density};
use super::DiscreteProblem;
use crate::discrete::assembly::{egg_point, element_product, EggRows, Geo, Operator};
use crate::discrete::hierarchical::{CellQuadrature, HierarchicalDiscretization};
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// Control points and storage of a problem on a THB discretization.
#[derive(Debug)]
pub(crate) struct HierarchicalState {
    /// The discretization.
    pub disc: Arc<HierarchicalDiscretization>,
    /// All control points; the free ones are overwritten from `c` on every call.
    pub cps: Vec<Point>,
    /// Residual of every THB function (interleaved, length `2 n`).
    pub res_full: Vec<f64>,
    mass: Option<Csr>,
    /// The scalar preconditioner `K` in the scalar pattern.
    prec: Option<Csr>,
}

impl HierarchicalState {
    /// Storage for `disc` with all control points `cps`.
    pub fn new(disc: Arc<HierarchicalDiscretization>, cps: Vec<Point>) -> Self {
        let n = disc.num_total();
        Self { res_full: vec![0.0; 2 * n], disc, cps, mass: None, prec: None }
    }

    fn load(&mut self, c: &[f64]) {
        self.disc.scatter(c, &mut self.cps);
    }

    fn restrict_residual(&self, f: &mut [f64]) {
        f.copy_from_slice(&self.disc.restrict(&self.res_full, 2));
    }

    /// `diag(M, M)` of eq. (30) in the vector pattern.
    fn mass(&mut self) -> &Csr {
        if self.mass.is_none() {
            let mut m = self.disc.scalar.clone();
            self.disc.assemble(1, &mut [], &mut m.values, |cell, _, ke| {
                let n = cell.len();
                for (k, &w) in cell.weights.iter().enumerate() {
                    let b = cell.at(k);
                    for a in 0..n {
                        for bb in 0..n {
                            ke[a * n + bb] += w * b[a][0] * b[bb][0];
                        }
                    }
                }
            });
            self.mass = Some(block_mass(&self.disc.vector, &m));
        }
        self.mass.as_ref().expect("set above")
    }

    /// The free control points from `c`, the fixed ones as stored.
    pub fn control_points(&self, c: &[f64]) -> Vec<Point> {
        let mut cps = self.cps.clone();
        self.disc.scatter(c, &mut cps);
        cps
    }
}

/// The map's derivatives at point `k` of `cell`.
fn geometry(cell: &CellQuadrature, k: usize, cps: &[Point]) -> Geo {
    let mut g = Geo::default();
    for (b, &f) in cell.at(k).iter().zip(&cell.funcs) {
        let c = cps[f];
        for d in 0..2 {
            g.xu[d] += b[1] * c[d];
            g.xv[d] += b[2] * c[d];
            g.xuu[d] += b[3] * c[d];
            g.xuv[d] += b[4] * c[d];
            g.xvv[d] += b[5] * c[d];
        }
    }
    g
}

/// `e = (x_ξ, x_η, y_ξ, y_η)` at point `k` of `cell`.
fn gradient(cell: &CellQuadrature, k: usize, cps: &[Point]) -> [f64; 4] {
    let mut e = [0.0; 4];
    for (b, &f) in cell.at(k).iter().zip(&cell.funcs) {
        let c = cps[f];
        e[0] += b[1] * c[0];
        e[1] += b[2] * c[0];
        e[2] += b[1] * c[1];
        e[3] += b[2] * c[1];
    }
    e
}

/// The EGG residual (eq. 8, full, interleaved) and, with a non-empty `values` (of the
/// vector pattern), its exact Jacobian (eq. 23) on a THB discretization.
pub(crate) fn hierarchical_egg(
    disc: &HierarchicalDiscretization,
    cps: &[Point],
    op: Operator,
    res: &mut [f64],
    values: &mut [f64],
) {
    let nqp = disc.nq * disc.nq;
    let want_mat = !values.is_empty();
    disc.assemble(2, res, values, |cell, re, ke| {
        let n = cell.len();
        let (mut wa, mut tz) = if want_mat { (vec![0.0; nqp * n], vec![0.0; 4 * nqp * n]) } else { (vec![], vec![]) };
        for (k, &wq) in cell.weights.iter().enumerate() {
            let g = geometry(cell, k, cps);
            let rows = want_mat.then(|| EggRows { wa: &mut wa[k * n..(k + 1) * n], tz: &mut tz, k, nqp });
            egg_point(cell.at(k), &g, wq, op, re, rows);
        }
        if want_mat {
            for zd in 0..4 {
                element_product(&mut ke[zd * n * n..(zd + 1) * n * n], &wa, &tz[zd * nqp * n..(zd + 1) * nqp * n], n);
            }
        }
    });
}

/// The symmetric principal part of the EGG Jacobian on a THB discretization (as the
/// tensor [`Discretization::metric_laplace`](crate::discrete::assembly::Discretization::metric_laplace)),
/// `K_ab = ∫ ∇w_a · A ∇w_b / s + shift ∫ w_a w_b` with `A = [[g22, -g12], [-g12, g11]]`
/// (`s = 1` plain, `s = g11 + g22` scaled; `1e-10 tr A` added to the diagonal of `A`), in
/// the values of the scalar pattern: `dF/dc = -diag(K, K) + B` with `B` of lower order, so
/// `-diag(K, K)` preconditions the Newton systems (GMRES).
pub fn hierarchical_metric_laplace(
    disc: &HierarchicalDiscretization,
    cps: &[Point],
    op: Operator,
    shift: f64,
    values: &mut [f64],
) {
    disc.assemble(1, &mut [], values, |cell, _, ke| {
        let n = cell.len();
        for (k, &wq) in cell.weights.iter().enumerate() {
            let (g11, g12, g22) = geometry(cell, k, cps).metric();
            let tr = g11 + g22;
            let scale = match op {
                Operator::Scaled if tr > 0.0 => 1.0 / tr,
                Operator::Plain | Operator::Scaled => 1.0,
            };
            let eps = 1e-10 * tr;
            let w = wq * scale;
            let (a11, a12, a22) = (w * (g22 + eps), -w * g12, w * (g11 + eps));
            let b = cell.at(k);
            for (a, ba) in b.iter().enumerate() {
                let (ga, gb, ma) = (a11 * ba[1] + a12 * ba[2], a12 * ba[1] + a22 * ba[2], wq * shift * ba[0]);
                let row = &mut ke[a * n..(a + 1) * n];
                for (r, bb) in row.iter_mut().zip(b) {
                    *r += ga * bb[1] + gb * bb[2] + ma * bb[0];
                }
            }
        }
    });
}

/// EGG (eq. 8) on a THB discretization, plain or scaled operator.
#[derive(Debug)]
pub(crate) struct HierarchicalEggProblem {
    /// Discretization, control points and storage.
    pub state: HierarchicalState,
    /// Which operator.
    pub op: Operator,
}

impl HierarchicalEggProblem {
    /// Set up with all control points `cps` (free ones are the initial guess).
    pub fn new(disc: Arc<HierarchicalDiscretization>, cps: Vec<Point>, op: Operator) -> Self {
        Self { state: HierarchicalState::new(disc, cps), op }
    }

    /// The current unknowns.
    #[cfg(test)]
    pub fn unknowns(&self) -> Vec<f64> {
        self.state.disc.gather(&self.state.cps)
    }
}

impl DiscreteProblem for HierarchicalEggProblem {
    fn size(&self) -> usize {
        2 * self.state.disc.num_free()
    }

    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        let s = &mut self.state;
        s.load(c);
        hierarchical_egg(&s.disc, &s.cps, self.op, &mut s.res_full, &mut []);
        s.restrict_residual(f);
    }

    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        let s = &mut self.state;
        s.load(c);
        if jac.values.len() != s.disc.vector.values.len() || jac.nrows != s.disc.vector.nrows {
            jac.assign(&s.disc.vector);
        }
        hierarchical_egg(&s.disc, &s.cps, self.op, &mut s.res_full, &mut jac.values);
        s.restrict_residual(f);
    }

    fn mass(&mut self) -> &Csr {
        self.state.mass()
    }

    fn preconditioner(&mut self, shift: f64) -> Option<&Csr> {
        let s = &mut self.state;
        let k = s.prec.get_or_insert_with(|| s.disc.scalar.clone());
        hierarchical_metric_laplace(&s.disc, &s.cps, self.op, shift, &mut k.values);
        s.prec.as_ref()
    }

    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        self.state.control_points(c)
    }
}

/// `J = ∫ W` (eq. 16) on a THB discretization, `+∞` when `det J <= 0` at a quadrature
/// point; summed cell by cell in order.
pub(crate) fn hierarchical_winslow_objective(disc: &HierarchicalDiscretization, cps: &[Point]) -> f64 {
    use rayon::prelude::*;
    let cells: Vec<f64> = disc
        .cells
        .par_iter()
        .map(|cell| {
            let mut v = 0.0;
            for (k, &wq) in cell.weights.iter().enumerate() {
                let [a, b, c, d] = gradient(cell, k, cps);
                let det = a * d - b * c;
                if det.is_nan() || det <= 0.0 {
                    return f64::INFINITY;
                }
                v += wq * (a * a + b * b + c * c + d * d) / det;
            }
            v
        })
        .collect();
    cells.iter().sum()
}

/// `F = -∇J` of eq. (16) (full, interleaved) and, with a non-empty `values` (of the
/// vector pattern), `dF/dc = -∇²J`, each point's `∂²W/∂e²` moved by the fraction
/// `projected` towards its positive semidefinite projection (as
/// [`winslow_gradient_with`](super::winslow::winslow_gradient_with)):
/// `∂F^z_a/∂c^d_b = -∫ Σ_ij ∂_i w_a (∂²W/∂e_{2z+i}∂e_{2d+j}) ∂_j w_b`.
pub(crate) fn hierarchical_winslow_gradient(
    disc: &HierarchicalDiscretization,
    cps: &[Point],
    projected: f64,
    res: &mut [f64],
    values: &mut [f64],
) {
    let want_mat = !values.is_empty();
    disc.assemble(2, res, values, |cell, re, ke| {
        let n = cell.len();
        for (k, &wq) in cell.weights.iter().enumerate() {
            let e = gradient(cell, k, cps);
            let (_, g, h) = winslow_density(e);
            let b = cell.at(k);
            for a in 0..n {
                let (bu, bv) = (b[a][1], b[a][2]);
                re[a] -= wq * (g[0] * bu + g[1] * bv);
                re[n + a] -= wq * (g[2] * bu + g[3] * bv);
            }
            if !want_mat {
                continue;
            }
            let h = if projected > 0.0 {
                let p = projected_density_hessian(e);
                std::array::from_fn(|i| std::array::from_fn(|j| h[i][j] + projected * (p[i][j] - h[i][j])))
            } else {
                h
            };
            for z in 0..2 {
                for d in 0..2 {
                    let blk = &mut ke[(z * 2 + d) * n * n..(z * 2 + d + 1) * n * n];
                    for a in 0..n {
                        let pa = [b[a][1], b[a][2]];
                        // (∂_i w_a H_{2z+i, 2d+j}) per j
                        let t: [f64; 2] = std::array::from_fn(|j| {
                            wq * (pa[0] * h[2 * z][2 * d + j] + pa[1] * h[2 * z + 1][2 * d + j])
                        });
                        for (bb, wb) in b.iter().enumerate() {
                            blk[a * n + bb] -= t[0] * wb[1] + t[1] * wb[2];
                        }
                    }
                }
            }
        }
    });
}

/// The Winslow functional (eq. 16) on a THB discretization, minimized from a bijective
/// start; the Hessian modified as [`WinslowProblem`](super::winslow::WinslowProblem)'s
/// (partial, then full projection of each point's density Hessian, then diagonal shifts)
/// where Newton finds it not definite.
#[derive(Debug)]
pub(crate) struct HierarchicalWinslowProblem {
    /// Discretization, control points and storage.
    pub state: HierarchicalState,
    diag: Vec<usize>,
    shift: f64,
    projected: f64,
    raised: bool,
}

impl HierarchicalWinslowProblem {
    /// Set up with all control points `cps` (free ones are the start).
    pub fn new(disc: Arc<HierarchicalDiscretization>, cps: Vec<Point>) -> Self {
        let pat = &disc.vector;
        let diag = (0..pat.nrows).map(|r| pat.position(r, r).expect("the pattern holds the diagonal")).collect();
        Self { state: HierarchicalState::new(disc, cps), diag, shift: 0.0, projected: 0.0, raised: false }
    }

    /// The current unknowns.
    #[cfg(test)]
    pub fn unknowns(&self) -> Vec<f64> {
        self.state.disc.gather(&self.state.cps)
    }
}

impl DiscreteProblem for HierarchicalWinslowProblem {
    fn size(&self) -> usize {
        2 * self.state.disc.num_free()
    }

    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        let s = &mut self.state;
        s.load(c);
        hierarchical_winslow_gradient(&s.disc, &s.cps, 0.0, &mut s.res_full, &mut []);
        s.restrict_residual(f);
    }

    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        if !std::mem::take(&mut self.raised) {
            // a new point: one stage back towards the exact Hessian
            self.shift = lowered(self.shift);
            self.projected = projection_lowered(self.projected);
        }
        let s = &mut self.state;
        s.load(c);
        if jac.values.len() != s.disc.vector.values.len() || jac.nrows != s.disc.vector.nrows {
            jac.assign(&s.disc.vector);
        }
        hierarchical_winslow_gradient(&s.disc, &s.cps, self.projected, &mut s.res_full, &mut jac.values);
        s.restrict_residual(f);
        shift_diagonal(self.shift, &self.diag, &mut jac.values);
    }

    fn mass(&mut self) -> &Csr {
        self.state.mass()
    }

    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        let cps = self.state.control_points(c);
        Some(hierarchical_winslow_objective(&self.state.disc, &cps))
    }

    fn modified(&self) -> bool {
        self.projected > 0.0 || self.shift > 0.0
    }

    fn raise_shift(&mut self) -> bool {
        self.raised = true;
        if self.projected < 1.0 {
            self.projected = projection_raised(self.projected);
            return true;
        }
        let Some(next) = raised(self.shift) else { return false };
        self.shift = next;
        true
    }

    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        self.state.control_points(c)
    }
}

#[cfg(test)]
mod tests;
