//! The multigrid V-cycle's level work on the GPU ([`GpuCycles`], the core's
//! [`CycleBackend`]): the kernels of `shaders/multigrid.wgsl` (stencil residual, coloured
//! line Gauss–Seidel, the two 1D transfer passes, the coarsest dense solve).
//!
//! At each set-up of the cycle ([`CycleBackend::upload`]) the levels' stencils (`f32`,
//! as the CPU holds them), the CSR levels, line factors, 1D transfer factors and the
//! coarsest Cholesky factor (`f64`) go up once, written from the hierarchy's own storage
//! straight into the buffers' mappings (no host copy; the level vectors are zeroed on
//! the device), and the whole V-cycle is recorded once
//! as a list of dispatches ([`v_cycle`] over a recorder of the operations), each with its
//! parameter record in one uniform buffer (dynamic offsets). Per application only the
//! right-hand side goes up and `x_0` comes back: every level's `b`, `x`, `r` and the
//! transfer scratch stay on the device (`f64`), the dispatches run in one submission.
//! Needs `SHADER_F64` and seven storage bindings per stage: without them the cycle stays
//! on the CPU. The same kernels and buffers serve the Newton Jacobian's product
//! ([`crate::product`]).
//!
//! Precision per buffer: `stencil` `f32` (the CPU's `GridOperator` values, widened
//! before each product), split over up to four bindings of at most the adapter's
//! storage-binding limit each ([`StencilChunks`]: the finest stencil of 10^6 unknowns,
//! 262 MB, exceeds lavapipe's 128 MiB); `reals` (line factors, transfer factors, CSR level values,
//! coarsest factor) and `vecs` (level vectors) `f64`; every sum in `f64`, in the CPU's
//! order.

use std::marker::PhantomData;
use std::sync::{Arc, Mutex};

use winslow::linalg::multigrid_kernels::{v_cycle, CycleBackend, DeviceCycle, Hierarchy, LevelKernels};

use crate::device::Gpu;
use crate::stats::Timings;
use crate::{GpuError, Precision};

mod dispatch;
mod program;

pub(crate) use dispatch::{bind, read_back, Bound, Shared, StencilChunks, STORAGE_BINDINGS};
use program::{pack, Layout, Recorder, NONE};
pub(crate) use program::{Kernel, Params, Step};

/// Loop iterations one line's invocation may take on a software adapter: lavapipe cut
/// an invocation of about 65 000 short, while lines of about 33 000 (513 unknowns on the
/// stencil of degree 3, when the line's residual was in the same invocation) gave the
/// CPU's bits. The residual now has a dispatch of its own (`line_residual`), so a line's
/// invocation costs `2 (b + 1) + 1` iterations per unknown (bandwidth `b`): lines of up
/// to about 4 400 unknowns at degree 3. Longer lines keep the cycle on the CPU there.
const SOFTWARE_LINE_WORK: u64 = 40_000;

/// Bytes per parameter record in the uniform buffer (the dynamic-offset alignment).
const RECORD: u64 = 256;

/// The compiled kernels of `shaders/multigrid.wgsl`.
#[derive(Debug)]
pub(crate) struct MultigridKernels {
    layout: wgpu::BindGroupLayout,
    residual: wgpu::ComputePipeline,
    line_residual: wgpu::ComputePipeline,
    line_smooth: wgpu::ComputePipeline,
    transfer_rows: wgpu::ComputePipeline,
    transfer_cols: wgpu::ComputePipeline,
    coarse_solve: wgpu::ComputePipeline,
    system_product: wgpu::ComputePipeline,
}

/// Compile the kernels (f64 only; see the module documentation).
pub(crate) fn multigrid_kernels(device: &wgpu::Device) -> MultigridKernels {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("multigrid.wgsl"),
        source: wgpu::ShaderSource::Wgsl(crate::shader_source(crate::MULTIGRID_WGSL, Precision::F64).into()),
    });
    let buffer = |binding: u32, ty: wgpu::BufferBindingType, dynamic: bool| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: dynamic, min_binding_size: None },
        count: None,
    };
    let ro = wgpu::BufferBindingType::Storage { read_only: true };
    let entries = [
        buffer(0, wgpu::BufferBindingType::Uniform, true),
        buffer(1, ro, false),
        buffer(2, ro, false),
        buffer(3, ro, false),
        buffer(4, wgpu::BufferBindingType::Storage { read_only: false }, false),
        buffer(5, ro, false),
        buffer(6, ro, false),
        buffer(7, ro, false),
    ];
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("multigrid.wgsl"),
        entries: &entries,
    });
    let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("multigrid.wgsl"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = |entry: &str| {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&pl),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    };
    MultigridKernels {
        residual: pipeline("residual"),
        line_residual: pipeline("line_residual"),
        line_smooth: pipeline("line_smooth"),
        transfer_rows: pipeline("transfer_rows"),
        transfer_cols: pipeline("transfer_cols"),
        coarse_solve: pipeline("coarse_solve"),
        system_product: pipeline("system_product"),
        layout,
    }
}

/// One operation of the cycle, run on its own ([`GpuCycle::run`], for tests).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Operation {
    /// [`LevelKernels::smooth`]`(level, dir, backward)`.
    Smooth(usize, usize, bool),
    /// [`LevelKernels::residual`].
    Residual(usize),
    /// [`LevelKernels::restrict`].
    Restrict(usize),
    /// [`LevelKernels::prolong_add`].
    ProlongAdd(usize),
    /// [`LevelKernels::coarse_solve`].
    CoarseSolve,
}

/// A level's vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Vector {
    /// `b_l`.
    B,
    /// `x_l`.
    X,
    /// `r_l` (smoothed levels only).
    R,
}

/// The GPU's cycle back end, shared by the assembler that hands it to the solver; counts
/// the cycles run and the time they took ([`GpuBackend::stats`]).
pub type GpuCycles = GpuBackend<CycleKernels>;

/// Marks a [`GpuBackend`] that uploads multigrid cycles ([`GpuCycles`]).
#[derive(Debug)]
pub enum CycleKernels {}

/// A back end of the kernels of `shaders/multigrid.wgsl`, shared by the assembler that
/// hands it to the solver: the V-cycle ([`GpuCycles`]) or the Jacobian product
/// ([`crate::GpuProducts`]), counting the calls run on the GPU, their times and the ones
/// that fell back to the CPU.
#[derive(Debug)]
pub struct GpuBackend<K> {
    k: Shared,
    kind: PhantomData<fn() -> K>,
}

impl<K> GpuBackend<K> {
    /// The back end on `gpu`; `None` without `SHADER_F64` (the kernels need `f64`).
    pub fn new(gpu: Arc<Gpu>) -> Option<Self> {
        Shared::new(gpu).map(|k| Self { k, kind: PhantomData })
    }

    /// Bind the stencil values in chunks of at most `bytes` (the adapter's
    /// storage-binding limit otherwise; rounded down to a power of two entries), at most
    /// four: for tests of the split at small sizes.
    pub fn with_chunk_bytes(mut self, bytes: u64) -> Self {
        self.k.chunk_bytes = bytes;
        self
    }

    /// Calls run on the GPU (`calls`) and their upload, dispatch and readback seconds;
    /// set-ups or calls that ran on the CPU instead and the last reason.
    pub fn stats(&self) -> (Timings, u64, Option<String>) {
        self.k.stats()
    }

    /// Zero the statistics.
    pub fn reset_stats(&self) {
        self.k.reset();
    }

    pub(crate) fn shared(&self) -> &Shared {
        &self.k
    }
}

impl GpuCycles {
    /// Upload `h` (see the module documentation).
    ///
    /// Errors: [`GpuError`] when the hierarchy does not fit the adapter's limits or wgpu
    /// fails.
    pub fn try_upload(&self, h: &Hierarchy<'_>) -> Result<GpuCycle, GpuError> {
        let gpu = &self.k.gpu;
        let kernels = self.k.kernels()?;
        let (layout, packed) = pack(h)?;
        let max = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
        let t0 = std::time::Instant::now();
        for (what, bytes) in [
            ("level vectors", 8 * layout.vec_len as u64),
            ("factors", 8 * packed.reals_len as u64),
            ("indices", 4 * packed.idx.len() as u64),
        ] {
            if bytes > max {
                return Err(GpuError::TooLarge(format!("multigrid {what}: {bytes} bytes, the adapter binds {max}")));
            }
        }
        if gpu.is_software() {
            for at in &layout.levels {
                let Some(lines) = at.lines else { continue };
                for d in lines {
                    let per = 2 * (d.bw as u64 + 1) + 1;
                    if d.len as u64 * per > SOFTWARE_LINE_WORK {
                        return Err(GpuError::TooLarge(format!(
                            "multigrid lines of {} unknowns: more work than a software adapter runs in one invocation",
                            d.len
                        )));
                    }
                }
            }
        }
        let cycle = gpu.scoped(|| {
            let mut rec = Recorder { layout: &layout, steps: Vec::new() };
            let levels = layout.levels.len();
            v_cycle(&mut rec, levels, layout.smoothing, 0);
            let program = rec.steps;
            let (st, st_len) = (&packed.stencil, packed.stencil_len);
            let stencil = StencilChunks::upload(gpu, "multigrid stencils", st, st_len, self.k.chunk_bytes)?;
            let stencil_bindings = stencil.used(packed.stencil_len);
            let reals = gpu.storage_parts("multigrid reals", &packed.reals, 0, packed.reals_len)?;
            let idx = gpu.storage_init("multigrid indices", bytemuck::cast_slice(&packed.idx))?;
            // the level vectors start at zero on the device: nothing goes up
            let vecs = gpu.storage_zeroed("multigrid vectors", 8 * layout.vec_len as u64);
            let n0 = layout.levels[0].size as u64;
            let staging = gpu.staging(8 * n0);
            let bound = Bound { reals: &reals, idx: &idx, stencil: &stencil, vecs: &vecs };
            let (params, bind) = bind(gpu, kernels, &program, &bound);
            gpu.submit_wait(None)?;
            Ok(GpuCycle {
                k: self.k.clone(),
                layout,
                program,
                stencil_bindings,
                buffers: Mutex::new(Buffers { reals, idx, stencil, vecs, staging, _params: params, bind }),
            })
        })?;
        // what went up: the stencils, the factors and the indices (parameter records aside)
        let bytes = 4 * packed.stencil_len as u64 + 8 * packed.reals_len as u64 + 4 * packed.idx.len() as u64;
        self.k.record(|s| {
            s.0.setups += 1;
            s.0.upload += t0.elapsed().as_secs_f64();
            s.0.bytes_up += bytes;
            s.0.setup_bytes += bytes;
        });
        Ok(cycle)
    }
}

impl CycleBackend for GpuCycles {
    fn upload(&self, h: &Hierarchy<'_>) -> winslow::Result<Box<dyn DeviceCycle>> {
        match self.try_upload(h) {
            Ok(c) => Ok(Box::new(c)),
            Err(e) => Err(self.k.fallback("multigrid set-up", e)),
        }
    }
}

/// The device buffers of an uploaded cycle.
#[derive(Debug)]
struct Buffers {
    reals: wgpu::Buffer,
    idx: wgpu::Buffer,
    stencil: StencilChunks,
    vecs: wgpu::Buffer,
    staging: wgpu::Buffer,
    /// The parameter records `bind` reads.
    _params: wgpu::Buffer,
    bind: wgpu::BindGroup,
}

impl Buffers {
    fn bound(&self) -> Bound<'_> {
        Bound { reals: &self.reals, idx: &self.idx, stencil: &self.stencil, vecs: &self.vecs }
    }
}

/// A V-cycle uploaded to the GPU (see the module documentation).
#[derive(Debug)]
pub struct GpuCycle {
    k: Shared,
    layout: Layout,
    program: Vec<Step>,
    /// Bindings that hold stencil values.
    stencil_bindings: usize,
    /// Held while a call uses the buffers.
    buffers: Mutex<Buffers>,
}

impl GpuCycle {
    /// Dispatches of one V-cycle.
    pub fn dispatches(&self) -> usize {
        self.program.len()
    }

    /// Bindings the levels' stencil values were split over (1 when they fit one).
    pub fn stencil_bindings(&self) -> usize {
        self.stencil_bindings
    }

    fn lock(&self) -> Result<std::sync::MutexGuard<'_, Buffers>, GpuError> {
        self.buffers.lock().map_err(|e| GpuError::Wgpu(e.to_string()))
    }

    /// Offset and length of vector `v` of level `l`.
    fn place(&self, v: Vector, l: usize) -> Result<(u64, usize), GpuError> {
        let at = self.layout.levels.get(l).ok_or_else(|| GpuError::Wgpu(format!("no level {l}")))?;
        let off = match v {
            Vector::B => at.b,
            Vector::X => at.x,
            Vector::R => at.r,
        };
        if off == NONE {
            return Err(GpuError::Wgpu(format!("level {l} has no {v:?}")));
        }
        Ok((off as u64 * 8, at.size as usize))
    }

    /// Write vector `v` of level `l`.
    ///
    /// Errors: a level or vector that does not exist, a length that does not match.
    pub fn write(&self, v: Vector, l: usize, values: &[f64]) -> Result<(), GpuError> {
        let (off, n) = self.place(v, l)?;
        if values.len() != n {
            return Err(GpuError::Wgpu(format!("{} values for a level of {n}", values.len())));
        }
        let b = self.lock()?;
        self.k.gpu.queue.write_buffer(&b.vecs, off, bytemuck::cast_slice(values));
        self.k.gpu.submit_wait(None)
    }

    /// Read vector `v` of level `l`.
    ///
    /// Errors: as [`GpuCycle::write`], and wgpu's.
    pub fn read(&self, v: Vector, l: usize) -> Result<Vec<f64>, GpuError> {
        let (off, n) = self.place(v, l)?;
        let b = self.lock()?;
        let staging = self.k.gpu.staging(8 * n as u64);
        let mut out = vec![0.0; n];
        read_back(&self.k.gpu, &b.vecs, off, &staging, &mut out, None)?;
        Ok(out)
    }

    /// Run one operation on the vectors as they are on the device.
    ///
    /// Errors: wgpu's.
    pub fn run(&self, op: Operation) -> Result<(), GpuError> {
        let mut rec = Recorder { layout: &self.layout, steps: Vec::new() };
        match op {
            Operation::Smooth(l, dir, backward) => rec.smooth(l, dir, backward),
            Operation::Residual(l) => rec.residual(l),
            Operation::Restrict(l) => rec.restrict(l),
            Operation::ProlongAdd(l) => rec.prolong_add(l),
            Operation::CoarseSolve => rec.coarse_solve(),
        }
        let steps = rec.steps;
        let b = self.lock()?;
        let kernels = self.k.kernels()?;
        self.k.gpu.scoped(|| {
            let (_params, bind) = bind(&self.k.gpu, kernels, &steps, &b.bound());
            let mut enc = self.k.gpu.device.create_command_encoder(&Default::default());
            dispatch::encode(&self.k.gpu, &mut enc, &steps, &bind)?;
            self.k.gpu.submit_wait(Some(enc.finish()))
        })
    }

    /// `x = B b`: one V-cycle on the device from `x_0 = 0`.
    ///
    /// Errors: a length that does not match the finest level, and wgpu's.
    pub fn try_apply(&self, b: &[f64], x: &mut [f64]) -> Result<(), GpuError> {
        let at = self.layout.levels[0];
        let n = at.size as usize;
        if b.len() != n || x.len() != n {
            return Err(GpuError::Wgpu(format!("{} / {} values for a cycle of {n}", b.len(), x.len())));
        }
        let buf = self.lock()?;
        let (b_at, x_at) = (at.b as u64 * 8, at.x as u64 * 8);
        self.k.call(&buf.vecs, &buf.staging, &buf.bind, &self.program, b, x, (b_at, Some(x_at), x_at))
    }
}

impl DeviceCycle for GpuCycle {
    fn apply(&self, b: &[f64], x: &mut [f64]) -> winslow::Result<()> {
        self.try_apply(b, x).map_err(|e| self.k.fallback("multigrid cycle", e))
    }
}
