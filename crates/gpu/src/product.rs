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

use winslow::discrete::assembly::Discretization;
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
    /// Upload `sys`: the values (`StencilChunks::upload`, written in place into the
    /// buffers' mappings), then as `GpuProducts::on_device`.
    ///
    /// Errors: [`GpuError`] when the system does not fit the adapter's limits or wgpu
    /// fails.
    pub fn try_upload(&self, sys: &PackedSystem<'_>) -> Result<GpuProduct, GpuError> {
        let gpu = &self.shared().gpu;
        let t0 = Instant::now();
        let values = values(sys);
        to_u32(values.len(), "system product stencil entries")?;
        let chunk = self.shared().chunk_bytes;
        let stencil = gpu.scoped(|| StencilChunks::upload(gpu, "system stencil", &[&values], values.len(), chunk))?;
        let disc = sys.discretization();
        self.on_device(disc, sys.components(), stencil, values.len(), 4 * values.len() as u64, t0)
    }

    /// The product with the system of `ncomp` components on `disc` whose `len` stencil
    /// values are in `stencil` already (uploaded by [`GpuProducts::try_upload`], or
    /// assembled there: [`crate::GpuAssembler`]'s device Jacobian): the free functions'
    /// global indices and every function's free index go up. Counted as a set-up with
    /// `bytes` (the values' upload, if any) and the indices, from `t0`.
    ///
    /// Errors: [`GpuError`] when the system does not fit the adapter's limits or wgpu
    /// fails.
    pub(crate) fn on_device(
        &self,
        disc: &Discretization,
        ncomp: usize,
        stencil: StencilChunks,
        len: usize,
        bytes: u64,
        t0: Instant,
    ) -> Result<GpuProduct, GpuError> {
        let gpu = &self.shared().gpu;
        let kernels = self.shared().kernels()?;
        let dofs = &disc.dofs;
        let (m, n) = (dofs.num_free(), ncomp * dofs.num_free());
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
            s_comp: to_u32(ncomp, "components")?,
            ..Default::default()
        };
        let step = [Step { kernel: Kernel::SystemProduct, params }];
        let device = gpu.scoped(|| {
            let stencil_bindings = stencil.used(len);
            let idx = gpu.storage_init("system indices", bytemuck::cast_slice(&idx))?;
            let reals = gpu.storage_zeroed("system reals", 16);
            let vecs = gpu.storage_empty("system vectors", 2 * n as u64);
            let staging = gpu.staging(8 * n as u64);
            let bound = Bound { reals: &reals, idx: &idx, stencil: &stencil, vecs: &vecs };
            let (params, bind) = bind(gpu, kernels, &step, &bound);
            gpu.submit_wait(None)?;
            Ok(GpuProduct {
                k: self.shared().clone(),
                n,
                len,
                step,
                stencil_bindings,
                buffers: Mutex::new(Buffers {
                    stencil,
                    _idx: idx,
                    _reals: reals,
                    vecs,
                    staging,
                    _params: params,
                    bind,
                }),
            })
        })?;
        let bytes = bytes + 4 * (m + dofs.num_total()) as u64;
        self.shared().record(|s| {
            s.0.setups += 1;
            s.0.upload += t0.elapsed().as_secs_f64();
            s.0.bytes_up += bytes;
            s.0.setup_bytes += bytes;
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
    stencil: StencilChunks,
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
    /// Stencil entries.
    len: usize,
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

    /// The stencil values as they are on the device, read back (for tests and
    /// diagnosis: the solver never reads them).
    ///
    /// Errors: wgpu's.
    pub fn read_stencil(&self) -> Result<Vec<f32>, GpuError> {
        let gpu = &self.k.gpu;
        let buf = self.buffers.lock().map_err(|e| GpuError::Wgpu(e.to_string()))?;
        let chunk = 1usize << buf.stencil.shift();
        let mut out = Vec::with_capacity(self.len);
        for (k, b) in buf.stencil.buffers().iter().enumerate().take(self.stencil_bindings) {
            let n = chunk.min(self.len - k * chunk);
            if n == 0 {
                break;
            }
            let bytes = 4 * n as u64;
            let staging = gpu.staging(bytes);
            let slice = gpu.copy_and_map(None, b, 0, &staging, bytes)?;
            {
                let view = slice.get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
                out.extend_from_slice(&bytemuck::pod_collect_to_vec::<u8, f32>(&view[..bytes as usize]));
            }
            staging.unmap();
        }
        Ok(out)
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
