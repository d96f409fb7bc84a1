//! The Newton Jacobian's product on the GPU ([`GpuProducts`], the core's
//! [`OperatorBackend`]): under `--linear multigrid` GMRES multiplies with the Jacobian of
//! eq. (12) held as its single-precision stencil storage
//! ([`winslow::discrete::PackedSystem`]); here that storage goes up once per Newton step
//! (split over up to four bindings, [`StencilChunks`]) with the free functions' indices,
//! and each product `y = J x` is one dispatch of `system_product`
//! (`shaders/multigrid.wgsl`, one invocation per row, the CPU's terms added in the
//! CPU's order: on lavapipe the CPU product's bits). Per product `x` goes up and `y`
//! comes back (`8 c m` bytes each way); GMRES's basis and the rest of its iteration stay
//! on the CPU.

use std::sync::Mutex;
use std::time::Instant;

use winslow::discrete::dofs::FIXED;
use winslow::discrete::{DeviceOperator, OperatorBackend, PackedSystem};

use crate::multigrid::{bind, Bound, GpuBackend, Kernel, Params, Shared, StencilChunks, Step};
use crate::{to_u32, GpuError};

/// The GPU's product back end, shared by the assembler that hands it to the solver;
/// counts the products and their times ([`GpuBackend::stats`]; the Jacobian's uploads
/// count in `upload` and `bytes_up`).
pub type GpuProducts = GpuBackend<ProductKernels>;

/// Marks a [`GpuBackend`] that uploads Galerkin systems ([`GpuProducts`]).
#[derive(Debug)]
pub enum ProductKernels {}

/// The values of `s` as `f32` (in place on a little-endian machine).
fn values<'a>(s: &PackedSystem<'a>) -> std::borrow::Cow<'a, [f32]> {
    let v = s.values();
    if cfg!(target_endian = "little") {
        std::borrow::Cow::Borrowed(&bytemuck::cast_slice::<u64, f32>(v.words())[..v.len()])
    } else {
        let at = |i: usize| f32::from_bits((v.words()[i >> 1] >> ((i & 1) * 32)) as u32);
        std::borrow::Cow::Owned((0..v.len()).map(at).collect())
    }
}

impl GpuProducts {
    /// Upload `sys`: the free functions' global indices, every function's free index,
    /// the values.
    ///
    /// Errors: [`GpuError`] when the system does not fit the adapter's limits or wgpu
    /// fails.
    pub fn try_upload(&self, sys: &PackedSystem<'_>) -> Result<GpuProduct, GpuError> {
        let gpu = &self.shared().gpu;
        let kernels = self.shared().kernels()?;
        let t0 = Instant::now();
        let disc = sys.discretization();
        let dofs = &disc.dofs;
        let (m, n) = (dofs.num_free(), sys.size());
        let [nx, ny] = disc.shape();
        let (p, q) = disc.degrees();
        let mut idx = Vec::with_capacity(m + dofs.num_total());
        for &k in dofs.free() {
            idx.push(to_u32(k, "system product function")?);
        }
        for k in 0..dofs.num_total() {
            idx.push(match dofs.free_index(k) {
                FIXED => u32::MAX,
                f => to_u32(f, "system product free index")?,
            });
        }
        to_u32(sys.values().len(), "system product stencil entries")?;
        let max = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
        for (what, bytes) in [("vectors", 16 * n as u64), ("indices", 4 * idx.len() as u64)] {
            if bytes > max {
                return Err(GpuError::TooLarge(format!(
                    "system product {what}: {bytes} bytes, the adapter binds {max}"
                )));
            }
        }
        let params = Params {
            count: to_u32(n, "rows")?,
            nx: to_u32(nx, "shape")?,
            ny: to_u32(ny, "shape")?,
            bx: to_u32(p, "degree")?,
            by: to_u32(q, "degree")?,
            x_off: 0,
            r_off: to_u32(n, "rows")?,
            s_free: 0,
            s_free_of: to_u32(m, "free functions")?,
            s_m: to_u32(m, "free functions")?,
            s_comp: to_u32(sys.components(), "components")?,
            ..Default::default()
        };
        let step = [Step { kernel: Kernel::SystemProduct, params }];
        let values = values(sys);
        let device = gpu.scoped(|| {
            let stencil = StencilChunks::upload(gpu, "system stencil", &values, self.shared().chunk_bytes)?;
            let stencil_bindings = stencil.used(values.len());
            let idx = gpu.storage_init("system indices", bytemuck::cast_slice(&idx));
            let reals = gpu.storage_init("system reals", &[0u8; 16]);
            let vecs = gpu.storage_empty("system vectors", 2 * n as u64);
            let staging = gpu.staging(8 * n as u64);
            let bound = Bound { reals: &reals, idx: &idx, stencil: &stencil, vecs: &vecs };
            let (params, bind) = bind(gpu, kernels, &step, &bound);
            gpu.submit_wait(None)?;
            Ok(GpuProduct {
                k: self.shared().clone(),
                n,
                step,
                stencil_bindings,
                buffers: Mutex::new(Buffers {
                    _stencil: stencil,
                    _idx: idx,
                    _reals: reals,
                    vecs,
                    staging,
                    _params: params,
                    bind,
                }),
            })
        })?;
        let bytes = 4 * values.len() as u64 + 4 * (m + dofs.num_total()) as u64;
        self.shared().record(|s| {
            s.0.upload += t0.elapsed().as_secs_f64();
            s.0.bytes_up += bytes;
        });
        Ok(device)
    }
}

impl OperatorBackend for GpuProducts {
    fn upload(&self, system: &PackedSystem<'_>) -> winslow::Result<Box<dyn DeviceOperator>> {
        match self.try_upload(system) {
            Ok(p) => Ok(Box::new(p)),
            Err(e) => Err(self.shared().fallback("Jacobian product set-up", e)),
        }
    }
}

/// The device buffers of an uploaded system.
#[derive(Debug)]
struct Buffers {
    /// The values, indices and placeholder the bind group reads.
    _stencil: StencilChunks,
    _idx: wgpu::Buffer,
    _reals: wgpu::Buffer,
    /// `x` (the first `n` values) and `y`.
    vecs: wgpu::Buffer,
    staging: wgpu::Buffer,
    _params: wgpu::Buffer,
    bind: wgpu::BindGroup,
}

/// A system uploaded to the GPU (see the module documentation).
#[derive(Debug)]
pub struct GpuProduct {
    k: Shared,
    n: usize,
    step: [Step; 1],
    stencil_bindings: usize,
    /// Held while a product uses the buffers.
    buffers: Mutex<Buffers>,
}

impl GpuProduct {
    /// Bindings the values were split over (1 when they fit one).
    pub fn stencil_bindings(&self) -> usize {
        self.stencil_bindings
    }

    /// `y = A x` on the device.
    ///
    /// Errors: lengths that do not match the system, and wgpu's.
    pub fn try_apply(&self, x: &[f64], y: &mut [f64]) -> Result<(), GpuError> {
        let n = self.n;
        if x.len() != n || y.len() != n {
            return Err(GpuError::Wgpu(format!("{} / {} values for a system of {n}", x.len(), y.len())));
        }
        let buf = self.buffers.lock().map_err(|e| GpuError::Wgpu(e.to_string()))?;
        self.k.call(&buf.vecs, &buf.staging, &buf.bind, &self.step, x, y, (0, None, 8 * n as u64))
    }
}

impl DeviceOperator for GpuProduct {
    fn apply(&self, x: &[f64], y: &mut [f64]) -> winslow::Result<()> {
        self.try_apply(x, y).map_err(|e| self.k.fallback("Jacobian product", e))
    }
}
