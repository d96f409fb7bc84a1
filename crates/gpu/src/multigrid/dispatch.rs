//! What the multigrid cycle ([`super::GpuCycle`]) and the system product
//! ([`crate::product`]) share on the device: the stencil values split over several
//! bindings ([`StencilChunks`]), the bind group over the kernels' buffers ([`bind`]), the
//! recording of dispatches ([`encode`]) and the readback of `f64` vectors ([`read_back`]).

use std::sync::{Arc, Mutex};
use std::time::Instant;

use super::program::{Kernel, Params, Step};
use super::{MultigridKernels, RECORD};
use crate::device::Gpu;
use crate::stats::Timings;
use crate::GpuError;

/// Calls run on the GPU with their times, set-ups or calls that fell back to the CPU,
/// and the last GPU error.
pub(crate) type CycleStats = (Timings, u64, Option<String>);

/// What a back end of these kernels ([`super::GpuCycles`], [`crate::GpuProducts`]) and
/// the objects it uploads share: the device, the statistics, the largest binding of
/// stencil values.
#[derive(Debug, Clone)]
pub(crate) struct Shared {
    pub(crate) gpu: Arc<Gpu>,
    stats: Arc<Mutex<CycleStats>>,
    pub(crate) chunk_bytes: u64,
}

impl Shared {
    /// On `gpu`; `None` without the kernels (`SHADER_F64`, seven storage bindings).
    pub(crate) fn new(gpu: Arc<Gpu>) -> Option<Self> {
        gpu.multigrid.as_ref()?;
        Some(Self { gpu, stats: Arc::new(Mutex::new((Timings::default(), 0, None))), chunk_bytes: u64::MAX })
    }

    /// The kernels.
    pub(crate) fn kernels(&self) -> Result<&MultigridKernels, GpuError> {
        self.gpu
            .multigrid
            .as_ref()
            .ok_or_else(|| GpuError::NoAdapter(" with SHADER_F64 for the multigrid kernels".into()))
    }

    pub(crate) fn stats(&self) -> CycleStats {
        self.stats.lock().map(|s| s.clone()).unwrap_or_default()
    }

    pub(crate) fn reset(&self) {
        self.record(|s| *s = Default::default());
    }

    pub(crate) fn record(&self, f: impl FnOnce(&mut CycleStats)) {
        if let Ok(mut s) = self.stats.lock() {
            f(&mut s);
        }
    }

    /// `e` of `what` counted as a fallback to the CPU, said on stderr, as the core's error.
    pub(crate) fn fallback(&self, what: &str, e: GpuError) -> winslow::Error {
        eprintln!("warning: GPU {what}: {e}; it runs on the CPU");
        self.record(|s| {
            s.1 += 1;
            s.2 = Some(e.to_string());
        });
        winslow::Error::LinearSolver(format!("GPU {what}: {e}"))
    }

    /// One call: `input` written at byte `at.0` of `vecs`, the `n` reals at byte `at.1`
    /// zeroed, `steps` run, `output` read from byte `at.2` through `staging`; counted with
    /// its times.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn call(
        &self,
        vecs: &wgpu::Buffer,
        staging: &wgpu::Buffer,
        bind: &wgpu::BindGroup,
        steps: &[Step],
        input: &[f64],
        output: &mut [f64],
        at: (u64, Option<u64>, u64),
    ) -> Result<(), GpuError> {
        let gpu = &self.gpu;
        let mut t = Timings { calls: 1, ..Default::default() };
        let t0 = Instant::now();
        gpu.scoped(|| {
            gpu.queue.write_buffer(vecs, at.0, bytemuck::cast_slice(input));
            t.bytes_up += 8 * input.len() as u64;
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            if let Some(zero) = at.1 {
                enc.clear_buffer(vecs, zero, Some(8 * output.len() as u64));
            }
            encode(gpu, &mut enc, steps, bind)?;
            gpu.submit_wait(Some(enc.finish()))?;
            t.dispatch += t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            read_back(gpu, vecs, at.2, staging, output, None)?;
            t.readback += t1.elapsed().as_secs_f64();
            t.bytes_down += 8 * output.len() as u64;
            Ok(())
        })?;
        self.record(|s| s.0.add(&t));
        Ok(())
    }
}

/// Bindings of the stencil values (`stencil0` .. `stencil3` of `shaders/multigrid.wgsl`).
pub(crate) const STENCIL_BINDINGS: usize = 4;

/// Storage buffers the kernels bind (`reals`, `idx`, `vecs` and the stencil chunks): the
/// kernels are compiled only where the adapter allows this many per shader stage.
pub(crate) const STORAGE_BINDINGS: u32 = 3 + STENCIL_BINDINGS as u32;

/// Single-precision stencil values in up to [`STENCIL_BINDINGS`] buffers of `2^shift`
/// entries each (the last one shorter; unused bindings get a 16-byte placeholder), so
/// that no binding exceeds the adapter's storage-binding limit: entry `g` lies in
/// buffer `g >> shift` at `g & (2^shift - 1)` (`st_at` of the shader).
#[derive(Debug)]
pub(crate) struct StencilChunks {
    buffers: Vec<wgpu::Buffer>,
    shift: u32,
}

impl StencilChunks {
    /// The chunk size (`2^shift` entries) for `len` values in chunks of at most
    /// `max_bytes` (and the adapter's binding and buffer limits), rounded down to a power
    /// of two entries, and the number of chunks.
    ///
    /// Errors: [`GpuError::TooLarge`] when more than [`STENCIL_BINDINGS`] chunks are
    /// needed.
    fn split(gpu: &Gpu, what: &str, len: usize, max_bytes: u64) -> Result<(u32, usize), GpuError> {
        let limit = max_bytes.min(gpu.limits.max_storage_buffer_binding_size).min(gpu.limits.max_buffer_size);
        let entries = (limit / 4).max(1);
        let shift = (63 - entries.leading_zeros()).min(31);
        let chunk = 1usize << shift;
        let parts = len.div_ceil(chunk).max(1);
        if parts > STENCIL_BINDINGS {
            return Err(GpuError::TooLarge(format!(
                "{what}: {} bytes of stencil values, {STENCIL_BINDINGS} bindings of {} bytes",
                4 * len,
                4 * chunk
            )));
        }
        Ok((shift, parts))
    }

    /// Upload the concatenation of `parts` (`len` values in all) in chunks of at most
    /// `max_bytes` ([`StencilChunks::split`]), each chunk written in place into its
    /// buffer's mapping ([`Gpu::storage_parts`]: no host copy of the values).
    ///
    /// Errors: [`GpuError::TooLarge`] when more than [`STENCIL_BINDINGS`] chunks are
    /// needed, and wgpu's.
    pub(crate) fn upload(
        gpu: &Gpu,
        what: &str,
        parts: &[&[f32]],
        len: usize,
        max_bytes: u64,
    ) -> Result<Self, GpuError> {
        let (shift, count) = Self::split(gpu, what, len, max_bytes)?;
        let chunk = 1usize << shift;
        let mut buffers = Vec::with_capacity(STENCIL_BINDINGS);
        for k in 0..count {
            let lo = k * chunk;
            buffers.push(gpu.storage_parts(what, parts, lo, chunk.min(len - lo.min(len)))?);
        }
        Ok(Self::padded(gpu, what, buffers, shift))
    }

    /// Chunks for `len` values that a kernel writes on the device (nothing goes up).
    ///
    /// Errors: as [`StencilChunks::upload`].
    pub(crate) fn on_device(gpu: &Gpu, what: &str, len: usize, max_bytes: u64) -> Result<Self, GpuError> {
        let (shift, count) = Self::split(gpu, what, len, max_bytes)?;
        let chunk = 1usize << shift;
        let buffers = (0..count).map(|k| gpu.storage_zeroed(what, 4 * chunk.min(len - k * chunk) as u64)).collect();
        Ok(Self::padded(gpu, what, buffers, shift))
    }

    /// `buffers` with 16-byte placeholders for the unused bindings.
    fn padded(gpu: &Gpu, what: &str, mut buffers: Vec<wgpu::Buffer>, shift: u32) -> Self {
        while buffers.len() < STENCIL_BINDINGS {
            buffers.push(gpu.storage_zeroed(what, 16));
        }
        Self { buffers, shift }
    }

    /// The buffers, placeholders included (bindings `stencil0` .. `stencil3`).
    pub(crate) fn buffers(&self) -> &[wgpu::Buffer] {
        &self.buffers
    }

    /// `log2` of the entries per chunk.
    pub(crate) fn shift(&self) -> u32 {
        self.shift
    }

    /// Buffers holding values (the placeholders not counted).
    pub(crate) fn used(&self, len: usize) -> usize {
        len.div_ceil(1usize << self.shift).max(1)
    }

    /// `2^shift - 1`: an entry's place in its chunk.
    pub(crate) fn mask(&self) -> u32 {
        ((1u64 << self.shift) - 1) as u32
    }

    /// `p` with the chunk size of these buffers.
    fn params(&self, mut p: Params) -> Params {
        p.st_shift = self.shift;
        p.st_mask = self.mask();
        p
    }
}

/// The buffers of one bind group of the kernels.
pub(crate) struct Bound<'a> {
    pub(crate) reals: &'a wgpu::Buffer,
    pub(crate) idx: &'a wgpu::Buffer,
    pub(crate) stencil: &'a StencilChunks,
    pub(crate) vecs: &'a wgpu::Buffer,
}

/// The uniform buffer of `steps`' parameter records (each with the chunk size of
/// `b.stencil`) and the bind group over it and `b`.
pub(crate) fn bind(
    gpu: &Gpu,
    kernels: &MultigridKernels,
    steps: &[Step],
    b: &Bound<'_>,
) -> (wgpu::Buffer, wgpu::BindGroup) {
    let mut bytes = vec![0u8; (RECORD as usize) * steps.len().max(1)];
    for (k, s) in steps.iter().enumerate() {
        let params = b.stencil.params(s.params);
        let p = bytemuck::bytes_of(&params);
        bytes[k * RECORD as usize..][..p.len()].copy_from_slice(p);
    }
    let params = gpu.uniform("multigrid params", &bytes);
    fn whole(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }
    }
    let st = &b.stencil.buffers;
    let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("multigrid"),
        layout: &kernels.layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &params,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
                }),
            },
            whole(1, b.reals),
            whole(2, b.idx),
            whole(3, &st[0]),
            whole(4, b.vecs),
            whole(5, &st[1]),
            whole(6, &st[2]),
            whole(7, &st[3]),
        ],
    });
    (params, bind)
}

/// Record `steps` (each with its record of `bind`), each dispatch in its own compute
/// pass (so that it sees the writes of the ones before it).
pub(crate) fn encode(
    gpu: &Gpu,
    enc: &mut wgpu::CommandEncoder,
    steps: &[Step],
    bind: &wgpu::BindGroup,
) -> Result<(), GpuError> {
    let k = gpu.multigrid.as_ref().ok_or_else(|| GpuError::Wgpu("multigrid kernels missing".into()))?;
    let max = gpu.limits.max_compute_workgroups_per_dimension.max(1) as u64;
    for (n, s) in steps.iter().enumerate() {
        let count = s.params.count as u64;
        if count == 0 {
            continue;
        }
        let (pipeline, per_group) = match s.kernel {
            Kernel::Residual => (&k.residual, 64),
            Kernel::LineResidual => (&k.line_residual, 64),
            Kernel::LineSmooth => (&k.line_smooth, 64),
            Kernel::TransferRows => (&k.transfer_rows, 64),
            Kernel::TransferCols => (&k.transfer_cols, 64),
            Kernel::CoarseSolve => (&k.coarse_solve, 1),
            Kernel::SystemProduct => (&k.system_product, 64),
        };
        let groups = count.div_ceil(per_group);
        let x = groups.min(max);
        let y = groups.div_ceil(x);
        if y > max {
            return Err(GpuError::TooLarge(format!("{count} invocations in one dispatch")));
        }
        // a pass per dispatch: the writes of one are visible to the next
        let mut pass =
            enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("multigrid"), timestamp_writes: None });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind, &[(n as u64 * RECORD) as u32]);
        pass.dispatch_workgroups(x as u32, y as u32, 1);
    }
    Ok(())
}

/// Copy `out.len()` reals (`f64`) at byte `off` of `src` into `out` through `staging`,
/// after `enc`'s commands when given.
pub(crate) fn read_back(
    gpu: &Gpu,
    src: &wgpu::Buffer,
    off: u64,
    staging: &wgpu::Buffer,
    out: &mut [f64],
    enc: Option<wgpu::CommandEncoder>,
) -> Result<(), GpuError> {
    let bytes = 8 * out.len() as u64;
    if bytes == 0 {
        return Ok(());
    }
    let slice = gpu.copy_and_map(enc, src, off, staging, bytes)?;
    {
        let view = slice.get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
        let data = &view[..bytes as usize];
        match bytemuck::try_cast_slice::<u8, f64>(data) {
            Ok(v) => out.copy_from_slice(v),
            Err(_) => out.copy_from_slice(&bytemuck::pod_collect_to_vec::<u8, f64>(data)),
        }
    }
    staging.unmap();
    Ok(())
}
