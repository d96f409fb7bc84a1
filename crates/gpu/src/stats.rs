//! What the GPU back end counts: seconds and bytes per kind of call ([`Timings`],
//! [`Stats`]), and the bytes that crossed the bus per Newton step and per GMRES
//! iteration ([`Stats::bus`], appended to the back end's name in `report.backend`).

/// Where the time of one kind of call went, summed over calls.
#[derive(Debug, Clone, Copy, Default)]
pub struct Timings {
    /// Calls.
    pub calls: u64,
    /// Set-ups (uploads of a multigrid hierarchy or a Jacobian for the product, counted
    /// apart from the calls that use them).
    pub setups: u64,
    /// Bytes of the set-ups (also in `bytes_up`).
    pub setup_bytes: u64,
    /// Quadrature points evaluated (elements times points per element, per call).
    pub quadrature_points: u64,
    /// Seconds writing control points (and, on first use of a basis, its tables).
    pub upload: f64,
    /// Seconds in kernels (submit to completion).
    pub dispatch: f64,
    /// Seconds copying results back and converting them.
    pub readback: f64,
    /// Seconds on the CPU (the f64 residual of the f32 path).
    pub cpu: f64,
    /// Bytes sent to the GPU.
    pub bytes_up: u64,
    /// Bytes read back.
    pub bytes_down: u64,
}

impl Timings {
    /// Total seconds.
    pub fn total(&self) -> f64 {
        self.upload + self.dispatch + self.readback + self.cpu
    }

    pub(crate) fn add(&mut self, o: &Timings) {
        self.calls += o.calls;
        self.setups += o.setups;
        self.setup_bytes += o.setup_bytes;
        self.quadrature_points += o.quadrature_points;
        self.upload += o.upload;
        self.dispatch += o.dispatch;
        self.readback += o.readback;
        self.cpu += o.cpu;
        self.bytes_up += o.bytes_up;
        self.bytes_down += o.bytes_down;
    }
}

/// [`Timings`] per kind of call, and the calls that fell back to the CPU.
#[derive(Debug, Clone, Default)]
pub struct Stats {
    /// EGG residual only.
    pub egg_residual: Timings,
    /// EGG residual and Jacobian.
    pub egg_jacobian: Timings,
    /// Mass matrices.
    pub mass: Timings,
    /// Elasticity matrices.
    pub elasticity: Timings,
    /// `det J` samples.
    pub det_j: Timings,
    /// Multigrid V-cycles run on the GPU (`calls`) under `--linear multigrid`
    /// ([`crate::GpuCycles`]).
    pub multigrid: Timings,
    /// Multigrid set-ups or cycles that ran on the CPU instead (GPU errors).
    pub multigrid_fallbacks: u64,
    /// Products with the Newton Jacobian run on the GPU (`calls`; `upload` and
    /// `bytes_up` include the Jacobian's upload once per Newton step) under
    /// `--linear multigrid` ([`crate::GpuProducts`]).
    pub jacobian_products: Timings,
    /// Jacobian uploads or products that ran on the CPU instead (GPU errors).
    pub jacobian_product_fallbacks: u64,
    /// Calls that failed on the GPU and were done by the CPU instead.
    pub fallbacks: u64,
    /// The last GPU error.
    pub last_error: Option<String>,
}

/// Bytes up and down of some kinds of call, averaged over `count` of something.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BusShare {
    /// What it is averaged over (Newton steps, GMRES iterations).
    pub count: u64,
    /// Bytes sent to the GPU per one of them.
    pub up: u64,
    /// Bytes read back per one of them.
    pub down: u64,
}

impl Stats {
    fn kinds(&self) -> [&Timings; 7] {
        [
            &self.egg_residual,
            &self.egg_jacobian,
            &self.mass,
            &self.elasticity,
            &self.det_j,
            &self.multigrid,
            &self.jacobian_products,
        ]
    }

    /// Bytes sent to the GPU and read back, over all calls and set-ups.
    pub fn bytes(&self) -> (u64, u64) {
        self.kinds().iter().fold((0, 0), |(u, d), t| (u + t.bytes_up, d + t.bytes_down))
    }

    /// Per Newton step: the Jacobian's assembly (control points up, residual down, and
    /// the Jacobian's stencil storage where it comes back to the host), its hand-over to
    /// the product ([`crate::GpuProducts`]: indices, and the stencil where it goes up
    /// from the host) and the multigrid set-ups ([`crate::GpuCycles`]: the levels'
    /// stencils, factors, indices), averaged over the Jacobians assembled on the GPU.
    pub fn per_newton_step(&self) -> Option<BusShare> {
        let count = self.egg_jacobian.calls;
        let up = self.egg_jacobian.bytes_up + self.jacobian_products.setup_bytes + self.multigrid.setup_bytes;
        (count > 0).then(|| BusShare { count, up: up / count, down: self.egg_jacobian.bytes_down / count })
    }

    /// Per GMRES iteration (one product with the Jacobian each): `x` up and `y` down
    /// for the product, `b` up and `x` down for each V-cycle, averaged over the
    /// products run on the GPU.
    pub fn per_gmres_iteration(&self) -> Option<BusShare> {
        let count = self.jacobian_products.calls;
        let calls = [&self.jacobian_products, &self.multigrid];
        let up = calls.iter().map(|t| t.bytes_up - t.setup_bytes).sum::<u64>();
        let down = calls.iter().map(|t| t.bytes_down).sum::<u64>();
        (count > 0).then(|| BusShare { count, up: up / count, down: down / count })
    }

    /// `"; bus: U B up, D B down in all[; per Newton step (N): u B up, d B down][; per
    /// GMRES iteration (P): u B up, d B down]"`; empty when nothing crossed it.
    pub fn bus(&self) -> String {
        let (up, down) = self.bytes();
        if up + down == 0 {
            return String::new();
        }
        let mut s = format!("; bus: {up} B up, {down} B down in all");
        let share = |what: &str, b: BusShare| format!("; per {what} ({}): {} B up, {} B down", b.count, b.up, b.down);
        if let Some(b) = self.per_newton_step() {
            s.push_str(&share("Newton step", b));
        }
        if let Some(b) = self.per_gmres_iteration() {
            s.push_str(&share("GMRES iteration", b));
        }
        s
    }
}
