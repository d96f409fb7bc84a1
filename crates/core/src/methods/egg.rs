//! Elliptic grid generation in Galerkin form (paper eq. 8): the residual `F(c)` of
//! eq. (12) and its exact Jacobian (eq. 23) in the free control points of one basis,
//! with the plain operator `L` or the scaled `L / (g11 + g22)`; [`EggMethod`] is the
//! method, [`EggProblem`] the problem on one level, [`EggAssembler`] the quadrature back
//! end (the CPU kernels of [`crate::discrete::assembly`], or the GPU crate's WGSL).

use std::sync::Arc;

use super::galerkin::GalerkinState;
use super::{DiscreteProblem, Method};

use crate::discrete::assembly::{Discretization, Operator};
use crate::discrete::stencil::{DeviceOperator, OperatorBackend, PackedSystem, Stencil32};
use crate::linalg::multigrid_kernels::CycleBackend;
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;
use crate::spline::surface::Surface;
use crate::verify::quality::{sample_det_j, DetJSample};

/// Quadrature back end of the solver (CPU here; the GPU crate implements it too): the
/// EGG residual and Jacobian, and the operators and samples the hierarchy uses (mass,
/// linear elasticity, `det J` on a grid). Every method writes exactly what the CPU
/// method of the same name writes (same vector and stencil layout), so patterns,
/// gathers and linear solvers are shared.
pub trait EggAssembler: Send + Sync {
    /// Residual (full, interleaved, length `2 n`) and, if `stencil` is non-empty, the
    /// Jacobian in stencil storage; see [`Discretization::egg`].
    fn egg(&self, disc: &Discretization, cps: &[Point], op: Operator, res: &mut [f64], stencil: &mut [f64]);
    /// Scalar mass matrix in stencil storage; see [`Discretization::mass`].
    fn mass(&self, disc: &Discretization, stencil: &mut [f64]) {
        disc.mass(stencil);
    }
    /// Linear elasticity on the domain of `cps`; see [`Discretization::elasticity`].
    fn elasticity(&self, disc: &Discretization, cps: &[Point], lambda: f64, mu: f64, stencil: &mut [f64]) {
        disc.elasticity(cps, lambda, mu, stencil);
    }
    /// `det J` on an `(n+1)^2` grid; see [`sample_det_j`].
    fn sample_det_j(&self, map: &Surface, n: usize) -> DetJSample {
        sample_det_j(map, n)
    }
    /// Human-readable name of the back end (`"cpu"`, `"gpu: <adapter>"`).
    fn name(&self) -> String;
    /// The kernels that run a multigrid V-cycle's level work on this back end
    /// ([`crate::linalg::multigrid_kernels`]); `None` (the default): the CPU.
    fn cycle_backend(&self) -> Option<Arc<dyn CycleBackend>> {
        None
    }
    /// The kernel that multiplies with the Newton Jacobian's single-precision stencil
    /// storage on this back end ([`OperatorBackend`]: GMRES's product under the
    /// multigrid preconditioner); `None` (the default): the CPU.
    fn operator_backend(&self) -> Option<Arc<dyn OperatorBackend>> {
        None
    }
    /// The residual (as [`EggAssembler::egg`]) and the Jacobian of eq. (23) assembled
    /// where the operator back end multiplies with it, in its single-precision stencil
    /// storage (the bits of [`Stencil32::pack`] of [`EggAssembler::egg`]'s), never
    /// crossing to the host: `Some` where this back end can (the GPU crate assembles
    /// into the product's buffers); `None` (the default, and when it fails): the caller
    /// assembles with [`EggAssembler::egg`] and uploads ([`OperatorBackend::upload`]).
    fn egg_operator(
        &self,
        _disc: &Discretization,
        _cps: &[Point],
        _op: Operator,
        _res: &mut [f64],
    ) -> Option<Box<dyn DeviceOperator>> {
        None
    }
    /// Whether [`EggAssembler::egg`] is [`Discretization::egg`] on the CPU: the Jacobian
    /// operator of `--linear multigrid` is then assembled by row bands straight into
    /// single precision (`Discretization::egg_single`, the same bits); `false` (the
    /// default): assembled by [`EggAssembler::egg`] in `f64`, then rounded.
    fn assembles_on_cpu(&self) -> bool {
        false
    }
}

/// The multi-threaded CPU assembler.
#[derive(Debug, Clone, Copy, Default)]
pub struct CpuAssembler;

impl EggAssembler for CpuAssembler {
    fn egg(&self, disc: &Discretization, cps: &[Point], op: Operator, res: &mut [f64], stencil: &mut [f64]) {
        disc.egg(cps, op, res, stencil);
    }
    fn name(&self) -> String {
        "cpu".into()
    }
    fn assembles_on_cpu(&self) -> bool {
        true
    }
}

/// The EGG method of eq. (8) with operator `operator`, its quadrature on `assembler`.
#[derive(Clone)]
pub struct EggMethod {
    /// Plain `L` or scaled `L / (g11 + g22)`.
    pub operator: Operator,
    /// Quadrature back end.
    pub assembler: Arc<dyn EggAssembler>,
}

impl std::fmt::Debug for EggMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EggMethod")
            .field("operator", &self.operator)
            .field("assembler", &self.assembler.name())
            .finish()
    }
}

impl EggMethod {
    /// EGG with `operator`, assembled on the CPU.
    pub fn cpu(operator: Operator) -> Self {
        Self { operator, assembler: Arc::new(CpuAssembler) }
    }
}

impl Method for EggMethod {
    fn name(&self) -> &'static str {
        match self.operator {
            Operator::Plain => "egg-plain",
            Operator::Scaled => "egg-scaled",
        }
    }

    /// `F_i = ∫ w_i L` with `L ~ diam^3` (plain) or `L / (g11 + g22) ~ diam` (scaled).
    fn residual_size(&self, diameter: f64) -> f64 {
        match self.operator {
            Operator::Plain => diameter.powi(3),
            Operator::Scaled => diameter,
        }
    }

    fn problem(&self, disc: Arc<Discretization>, control_points: Vec<Point>) -> Box<dyn DiscreteProblem + Send> {
        Box::new(EggProblem::new(disc, control_points, self.operator, self.assembler.clone()))
    }

    /// [`EggProblem`] offers the knot-halving hierarchy and the stencil operator.
    fn multigrid(&self) -> bool {
        true
    }
}

/// EGG on one level: the `GalerkinState` (discretization, control points, storage
/// requested once up front), the operator and the quadrature back end.
pub struct EggProblem {
    /// Basis, control points and storage.
    pub(crate) state: GalerkinState,
    /// Which operator.
    pub op: Operator,
    assembler: Arc<dyn EggAssembler>,
}

impl std::fmt::Debug for EggProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EggProblem").field("unknowns", &self.size()).field("op", &self.op).finish()
    }
}

impl EggProblem {
    /// Set up with all control points `cps` (free ones are the initial guess).
    pub fn new(disc: Arc<Discretization>, cps: Vec<Point>, op: Operator, assembler: Arc<dyn EggAssembler>) -> Self {
        Self { state: GalerkinState::new(disc, cps), op, assembler }
    }

    /// The current unknown vector.
    pub fn unknowns(&self) -> Vec<f64> {
        self.state.unknowns()
    }
}

impl DiscreteProblem for EggProblem {
    fn size(&self) -> usize {
        self.state.size()
    }

    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        let s = &mut self.state;
        s.load(c);
        self.assembler.egg(&s.disc, &s.cps, self.op, &mut s.res_full, &mut []);
        s.restrict_residual(f);
    }

    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        let s = &mut self.state;
        s.load_for_jacobian(c);
        self.assembler.egg(&s.disc, &s.cps, self.op, &mut s.res_full, &mut s.stencil);
        s.restrict_residual(f);
        s.gather_jacobian(jac);
    }

    /// The Jacobian kept as its stencil storage rounded to single precision
    /// (`discrete::stencil::Stencil32`, packed in place after the assembly; the last
    /// step's is freed before this one is assembled), or assembled on the operator back
    /// end itself ([`EggAssembler::egg_operator`]: no host copy): on a basis without
    /// periodic replicas.
    fn jacobian_operator(&mut self, c: &[f64], f: &mut [f64]) -> bool {
        let s = &mut self.state;
        if !s.disc.dofs.replicas().is_empty() {
            return false;
        }
        (s.packed, s.device, s.fallback) = (None, None, Default::default());
        s.point.clear();
        if !self.assembler.assembles_on_cpu() {
            // assembled where it is multiplied: the Jacobian never comes to the host
            s.load(c);
            if let Some(device) = self.assembler.egg_operator(&s.disc, &s.cps, self.op, &mut s.res_full) {
                s.restrict_residual(f);
                (s.device, s.point) = (Some(device), c.to_vec());
                return true;
            }
        }
        let packed = if self.assembler.assembles_on_cpu() {
            // by row bands straight into single precision (the same bits as below)
            s.load(c);
            let single = s.disc.egg_single(&s.cps, self.op, &mut s.res_full);
            s.restrict_residual(f);
            s.packed.insert(single)
        } else {
            s.load_for_jacobian(c);
            self.assembler.egg(&s.disc, &s.cps, self.op, &mut s.res_full, &mut s.stencil);
            s.restrict_residual(f);
            s.packed.insert(Stencil32::pack(std::mem::take(&mut s.stencil)))
        };
        // uploaded once per Newton step where the back end multiplies (the CPU product
        // otherwise, and where the upload fails: the back end says why)
        s.device = self
            .assembler
            .operator_backend()
            .zip(PackedSystem::new(&s.disc, 2, packed))
            .and_then(|(b, sys)| b.upload(&sys).ok());
        true
    }

    /// `y = J x` with the single-precision Jacobian of the last
    /// [`DiscreteProblem::jacobian_operator`]: on the operator back end where it was
    /// uploaded (the CPU's product where that fails), else on the CPU (the `f64` stencil
    /// storage when there is no packed one).
    fn jacobian_product(&self, x: &[f64], y: &mut [f64]) {
        let s = &self.state;
        if s.device.as_ref().is_some_and(|d| d.apply(x, y).is_ok()) {
            return;
        }
        match &s.packed {
            Some(j) => s.disc.stencil_product(2, j, x, y),
            // assembled on the back end, whose product failed: the CPU assembles it at
            // the same point once (`egg_single`: the bits of the back end's packing)
            None if !s.point.is_empty() => {
                let j = s.fallback.get_or_init(|| {
                    let mut res = vec![0.0; s.res_full.len()];
                    s.disc.egg_single(&s.control_points(&s.point), self.op, &mut res)
                });
                s.disc.stencil_product(2, j, x, y)
            }
            None => s.disc.stencil_product(2, &s.stencil[..], x, y),
        };
    }

    fn mass(&mut self) -> &Csr {
        let assembler = &self.assembler;
        self.state.mass(|disc, st| assembler.mass(disc, st))
    }

    fn ordering(&self) -> Option<&[usize]> {
        Some(&self.state.disc.ordering)
    }

    /// The knot-halving hierarchy below the basis (`discrete::transfers`).
    fn transfers(&self) -> Vec<[Csr; 2]> {
        crate::discrete::transfers::free_prolongation_factors(&self.state.disc).unwrap_or_default()
    }

    fn cycle_backend(&self) -> Option<Arc<dyn CycleBackend>> {
        self.assembler.cycle_backend()
    }

    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        self.state.control_points(c)
    }

    /// `K` of `Discretization::metric_laplace` on the current control points.
    fn preconditioner(&mut self, shift: f64) -> Option<&Csr> {
        let op = self.op;
        Some(self.state.preconditioner(|disc, cps, st| disc.metric_laplace(cps, op, shift, st)))
    }

    /// `K` as [`DiscreteProblem::preconditioner`], handed over (the state keeps neither
    /// it nor its stencil storage).
    fn take_preconditioner(&mut self, shift: f64) -> Option<Csr> {
        let op = self.op;
        Some(self.state.take_preconditioner(|disc, cps, st| disc.metric_laplace(cps, op, shift, st)))
    }

    /// `K` as [`DiscreteProblem::take_preconditioner`], as a grid stencil of the free
    /// functions (no matrix) where they are a rectangle of the basis grid.
    fn take_preconditioner_grid(&mut self, shift: f64) -> Option<crate::linalg::multigrid::GridStencil> {
        let op = self.op;
        self.state.take_preconditioner_grid(|disc, cps, st| disc.metric_laplace(cps, op, shift, st))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::newton::{NonlinearOptions, NonlinearSolver, Status};
    use crate::spline::knots::KnotVector;
    use crate::testutil::Lcg;

    /// A curved map: the bilinear-plus-bump image of Greville points, perturbed.
    fn setup(p: usize, ne: [usize; 2], seed: u64, noise: f64) -> (Discretization, Vec<Point>) {
        let kx = KnotVector::open_uniform(p, ne[0]);
        let ky = KnotVector::open_uniform(p, ne[1]).with_inserted(&[0.3]);
        let (gx, gy) = (kx.greville(), ky.greville());
        let mut rng = Lcg::new(seed);
        let mut cps = Vec::new();
        for &v in &gy {
            for &u in &gx {
                let r = 1.0 + v;
                let t = 1.2 * u;
                cps.push([r * t.cos() + noise * (rng.uniform() - 0.5), r * t.sin() + noise * (rng.uniform() - 0.5)]);
            }
        }
        (Discretization::new([kx, ky]), cps)
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        for op in [Operator::Plain, Operator::Scaled] {
            let (disc, cps) = setup(3, [4, 3], 11, 0.05);
            let mut prob = EggProblem::new(Arc::new(disc), cps, op, Arc::new(CpuAssembler));
            let c = prob.unknowns();
            let (max_err, max_val) = crate::methods::jacobian_fd_mismatch(&mut prob, &c, 1e-6);
            assert!(max_err < 1e-7 * max_val, "{op:?}: FD mismatch {max_err} (scale {max_val})");
        }
    }

    /// A back end whose Jacobian, "assembled where it is multiplied"
    /// ([`EggAssembler::egg_operator`]), cannot be multiplied with: a lost device.
    struct LostDevice;

    #[derive(Debug)]
    struct Lost;

    impl DeviceOperator for Lost {
        fn apply(&self, _: &[f64], _: &mut [f64]) -> crate::Result<()> {
            Err(crate::Error::LinearSolver("the device is lost".into()))
        }
    }

    impl EggAssembler for LostDevice {
        fn egg(&self, disc: &Discretization, cps: &[Point], op: Operator, res: &mut [f64], st: &mut [f64]) {
            disc.egg(cps, op, res, st);
        }
        fn name(&self) -> String {
            "lost".into()
        }
        fn egg_operator(
            &self,
            d: &Discretization,
            cps: &[Point],
            op: Operator,
            res: &mut [f64],
        ) -> Option<Box<dyn DeviceOperator>> {
            d.egg(cps, op, res, &mut []);
            Some(Box::new(Lost))
        }
    }

    /// A Jacobian assembled on its back end keeps no host copy; when its product fails
    /// there, the CPU assembles it once at the Newton point (not at the control points a
    /// later residual left) and gives the CPU path's product, bit for bit.
    #[test]
    fn a_failed_device_jacobian_is_assembled_again_at_its_point() {
        let (disc, cps) = setup(3, [5, 4], 3, 0.05);
        let disc = Arc::new(disc);
        let mut cpu = EggProblem::new(disc.clone(), cps.clone(), Operator::Scaled, Arc::new(CpuAssembler));
        let mut dev = EggProblem::new(disc, cps, Operator::Scaled, Arc::new(LostDevice));
        let c = cpu.unknowns();
        let n = c.len();
        let (mut f_cpu, mut f_dev) = (vec![0.0; n], vec![1.0; n]);
        assert!(cpu.jacobian_operator(&c, &mut f_cpu) && dev.jacobian_operator(&c, &mut f_dev));
        assert_eq!(f_cpu, f_dev);
        assert!(dev.state.packed.is_none() && dev.state.stencil.is_empty() && dev.state.fallback.get().is_none());
        dev.residual(&c.iter().map(|v| v + 0.01).collect::<Vec<_>>(), &mut f_dev);
        let x: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
        let (mut y_cpu, mut y_dev) = (vec![0.0; n], vec![1.0; n]);
        cpu.jacobian_product(&x, &mut y_cpu);
        dev.jacobian_product(&x, &mut y_dev);
        assert!(y_cpu.iter().zip(&y_dev).all(|(a, b)| a.to_bits() == b.to_bits()));
        assert!(dev.state.fallback.get().is_some());
    }

    /// Random positive weights in `[0.5, 2]` for a rational basis of `n` functions.
    fn weights(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = Lcg::new(seed);
        (0..n).map(|_| 0.5 + 1.5 * rng.uniform()).collect()
    }

    /// The exact Jacobian also holds on a rational (NURBS) basis, where every basis
    /// function and derivative goes through the quotient rule.
    #[test]
    fn jacobian_matches_finite_differences_on_a_rational_basis() {
        for op in [Operator::Plain, Operator::Scaled] {
            let (disc, cps) = setup(3, [4, 3], 11, 0.05);
            let n = disc.dofs.num_total();
            let disc = disc.with_weights(Some(weights(n, 5))).unwrap();
            assert!(disc.is_rational());
            let mut prob = EggProblem::new(Arc::new(disc), cps, op, Arc::new(CpuAssembler));
            let c = prob.unknowns();
            let (max_err, max_val) = crate::methods::jacobian_fd_mismatch(&mut prob, &c, 1e-6);
            assert!(max_err < 1e-7 * max_val, "{op:?}: FD mismatch {max_err} (scale {max_val})");
        }
    }

    /// The rational basis values of [`Discretization::tensor_basis`] summed with the
    /// control points give the NURBS surface (position from `Surface::eval`) and its first
    /// and second derivatives (central differences of it); the `R_b` sum to one.
    #[test]
    fn rational_basis_reproduces_the_nurbs_surface() {
        use crate::discrete::assembly::Scratch;
        use crate::spline::surface::Surface;
        let (disc, cps) = setup(2, [3, 4], 2, 0.1);
        let w = weights(disc.dofs.num_total(), 9);
        let disc = disc.with_weights(Some(w.clone())).unwrap();
        let map = Surface::new(disc.knots.clone(), cps.clone(), Some(w)).unwrap();
        let (p, q) = disc.degrees();
        let nx = disc.shape()[0];
        let mut s = Scratch::new(p, q, 1);
        let (h1, h) = (1e-6, 1e-4);
        for (ex, ey, ku, kv) in [(0, 0, 0, 1), (1, 2, 2, 0), (2, 3, 1, 2)] {
            disc.tensor_basis(ex, ey, ku, kv, &mut s);
            let (u, v) = (disc.tables[0].at(ex, ku).u, disc.tables[1].at(ey, kv).u);
            let (fx, fy) = (disc.tables[0].first[ex], disc.tables[1].first[ey]);
            let mut g = [[0.0; 2]; 6];
            let mut sum = [0.0; 6];
            for jb in 0..=q {
                for ib in 0..=p {
                    let b = s.b[jb * (p + 1) + ib];
                    let c = cps[(fy + jb) * nx + fx + ib];
                    for k in 0..6 {
                        sum[k] += b[k];
                        for d in 0..2 {
                            g[k][d] += b[k] * c[d];
                        }
                    }
                }
            }
            assert!((sum[0] - 1.0).abs() < 1e-14 && sum[1..].iter().all(|x| x.abs() < 1e-12), "{sum:?}");
            let e = |du: f64, dv: f64| map.eval(u + du, v + dv);
            for d in 0..2 {
                let want = [
                    e(0.0, 0.0)[d],
                    (e(h1, 0.0)[d] - e(-h1, 0.0)[d]) / (2.0 * h1),
                    (e(0.0, h1)[d] - e(0.0, -h1)[d]) / (2.0 * h1),
                    (e(h, 0.0)[d] - 2.0 * e(0.0, 0.0)[d] + e(-h, 0.0)[d]) / (h * h),
                    (e(h, h)[d] - e(h, -h)[d] - e(-h, h)[d] + e(-h, -h)[d]) / (4.0 * h * h),
                    (e(0.0, h)[d] - 2.0 * e(0.0, 0.0)[d] + e(0.0, -h)[d]) / (h * h),
                ];
                for k in 0..6 {
                    let tol = if k == 0 {
                        1e-13
                    } else if k < 3 {
                        1e-8
                    } else {
                        1e-5
                    };
                    assert!(
                        (g[k][d] - want[k]).abs() < tol * (1.0 + want[k].abs()),
                        "k {k} d {d}: {} vs {}",
                        g[k][d],
                        want[k]
                    );
                }
            }
        }
    }

    /// [`Discretization::tensor_basis_first`] gives the values and first derivatives of
    /// [`Discretization::tensor_basis`]: the same products on a polynomial basis (bit for
    /// bit), the same quotient rule to rounding on a rational one; from the table of a
    /// small basis as computed on a large one (40 x 40 elements: 14 400 points).
    #[test]
    fn first_order_tensor_basis_matches_the_full_one() {
        use crate::discrete::assembly::{Scratch, FIRST_ORDER_TABLE_POINTS};
        let (poly, _) = setup(2, [3, 4], 2, 0.1);
        let n = poly.dofs.num_total();
        let rational = setup(2, [3, 4], 2, 0.1).0.with_weights(Some(weights(n, 9))).unwrap();
        let large = setup(2, [40, 40], 2, 0.1).0;
        let n = large.dofs.num_total();
        let large = large.with_weights(Some(weights(n, 5))).unwrap();
        assert!(large.num_elements() * 9 >= FIRST_ORDER_TABLE_POINTS);
        for (disc, tol) in [(&poly, 0.0), (&rational, 4.0 * f64::EPSILON), (&large, 4.0 * f64::EPSILON)] {
            let (p, q) = disc.degrees();
            let (mut full, mut first) = (Scratch::new(p, q, 1), Scratch::new(p, q, 1));
            for ey in 0..disc.tables[1].num_elements() {
                for ex in 0..disc.tables[0].num_elements() {
                    for (ku, kv) in [(0, 0), (1, 2), (2, 1)] {
                        let w = disc.tensor_basis(ex, ey, ku, kv, &mut full);
                        assert_eq!(w, disc.tensor_basis_first(ex, ey, ku, kv, &mut first));
                        for (a, b) in full.b.iter().zip(&first.b) {
                            for k in 0..3 {
                                assert!((a[k] - b[k]).abs() <= tol * (1.0 + a[k].abs()), "{k}: {} vs {}", a[k], b[k]);
                            }
                        }
                    }
                }
            }
        }
    }

    /// `-diag(K, K)` of the metric Laplacian preconditions the Newton systems with
    /// GMRES iteration counts that do not grow under refinement, and GMRES reproduces
    /// the direct solution.
    #[test]
    fn metric_preconditioner_is_mesh_independent() {
        use crate::linalg::linsolve::{LinearMethod, LinearSolver};
        let mut counts = Vec::new();
        for ne in [8, 16, 32] {
            let (disc, cps) = setup(3, [ne, ne], 3, 0.0);
            let mut prob = EggProblem::new(Arc::new(disc), cps, Operator::Scaled, Arc::new(CpuAssembler));
            let c = prob.unknowns();
            let mut f = vec![0.0; c.len()];
            let mut jac = Csr::default();
            prob.jacobian(&c, &mut f, &mut jac);
            let b: Vec<f64> = (0..c.len()).map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.5).collect();
            let k = prob.preconditioner(0.0).expect("EGG has a preconditioner").clone();
            assert_eq!(2 * k.nrows, jac.nrows);
            let mut gm = LinearSolver::new(LinearMethod::Gmres);
            gm.factor_preconditioned(&jac, Some(&k)).unwrap();
            let x = gm.solve(&b).unwrap();
            let mut lu = LinearSolver::new(LinearMethod::Lu);
            lu.factor(&jac).unwrap();
            let y = lu.solve(&b).unwrap();
            let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let err = x.iter().zip(&y).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(err < 1e-7 * scale, "{ne}: GMRES vs LU {err} (scale {scale})");
            counts.push(gm.krylov_iterations);
        }
        // h-independent: 16x more unknowns, at most a few more iterations
        assert!(counts[2] <= counts[0] + 8, "iterations grow with refinement: {counts:?}");
        assert!(counts[2] < 40, "{counts:?}");
    }

    /// A ring `r = 1 + xi`, `θ = 2π eta` on a periodic `eta` basis (control points at the
    /// Greville points, free ones perturbed and wrapped).
    fn ring(p: usize, ne: [usize; 2], noise: f64) -> (Discretization, Vec<Point>) {
        let kx = KnotVector::open_uniform(p, ne[0]);
        let ky = KnotVector::periodic_uniform(p, ne[1]).with_inserted(&[0.3]);
        let t = crate::discrete::topology::Topology::ring();
        let disc = Discretization::for_topology([kx.clone(), ky.clone()], &t).unwrap();
        let (gx, gy) = (kx.greville(), ky.greville());
        let mut rng = Lcg::new(7);
        let mut cps: Vec<Point> = gy
            .iter()
            .flat_map(|&v| {
                gx.iter().map(move |&u| {
                    let th = 2.0 * std::f64::consts::PI * v;
                    [(1.0 + u) * th.cos(), (1.0 + u) * th.sin()]
                })
            })
            .collect();
        for &k in disc.dofs.free() {
            cps[k][0] += noise * (rng.uniform() - 0.5);
            cps[k][1] += noise * (rng.uniform() - 0.5);
        }
        disc.dofs.wrap(&mut cps);
        (disc, cps)
    }

    #[test]
    fn periodic_jacobian_matches_finite_differences() {
        for op in [Operator::Plain, Operator::Scaled] {
            let (disc, cps) = ring(3, [3, 6], 0.05);
            assert_eq!(disc.dofs.replicas().len(), 3 * disc.shape()[0]);
            let mut prob = EggProblem::new(Arc::new(disc), cps, op, Arc::new(CpuAssembler));
            let c = prob.unknowns();
            let (max_err, max_val) = crate::methods::jacobian_fd_mismatch(&mut prob, &c, 1e-6);
            assert!(max_err < 1e-7 * max_val, "{op:?}: FD mismatch {max_err} (scale {max_val})");
        }
    }

    #[test]
    fn affine_map_is_a_fixed_point() {
        let kx = KnotVector::open_uniform(3, 5);
        let ky = KnotVector::open_uniform(2, 4);
        let (gx, gy) = (kx.greville(), ky.greville());
        let cps: Vec<Point> =
            gy.iter().flat_map(|&v| gx.iter().map(move |&u| [2.0 * u + 0.5 * v + 1.0, -0.3 * u + 1.5 * v])).collect();
        let disc = Discretization::new([kx, ky]);
        let mut prob = EggProblem::new(Arc::new(disc), cps, Operator::Plain, Arc::new(CpuAssembler));
        let c = prob.unknowns();
        let mut f = vec![0.0; c.len()];
        prob.residual(&c, &mut f);
        assert!(f.iter().all(|v| v.abs() < 1e-13), "{:?}", f.iter().fold(0.0f64, |m, v| m.max(v.abs())));
    }

    #[test]
    fn newton_converges_quadratically_from_a_perturbed_map() {
        let (disc, cps) = setup(3, [6, 6], 5, 0.02);
        let opts = NonlinearOptions { scale: (disc.dofs.num_free() as f64).sqrt() / 27.0, ..Default::default() };
        let prob = EggProblem::new(Arc::new(disc), cps, Operator::Plain, Arc::new(CpuAssembler));
        let c0 = prob.unknowns();
        let mut s = NonlinearSolver::new(prob, c0, opts);
        let its: Vec<_> = s.by_ref().collect::<crate::Result<Vec<_>>>().unwrap();
        assert_eq!(s.status(), &Status::Converged, "{its:?}");
        assert!(its.len() <= 7, "{its:?}");
        // quadratic: the last reductions are much faster than linear
        let r: Vec<f64> = its.iter().map(|i| i.residual).collect();
        assert!(r[r.len() - 1] < 1e-6 * r[0]);
    }
}
