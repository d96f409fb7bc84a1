//! # winslow-gpu
//!
//! The quadrature of winslow's solver on the GPU: wgpu compute shaders written in WGSL
//! (`shaders/*.wgsl` at the workspace root), running on real GPUs and on Mesa's lavapipe
//! (a CPU Vulkan driver) in CI.
//!
//! [`GpuAssembler`] implements [`winslow::methods::egg::EggAssembler`], the back-end hook of the
//! core solver: the EGG residual and exact Jacobian of paper eq. (8), the mass matrix of
//! eq. (30), linear elasticity (§6.3) and `det J` sampling (eq. 43). It writes exactly
//! the vectors and *stencil storage* of the CPU assembler ([`winslow::discrete::assembly`]), so
//! the sparsity patterns, gathers and linear solvers are shared, and the two back ends
//! are interchangeable. The univariate basis tables come from the core
//! ([`winslow::discrete::tables::DirTable`], [`winslow::spline::basis::BasisDerivs`]) and are uploaded
//! once per basis; the GPU only runs the tensor-product sums.
//!
//! [`GpuCycles`] implements [`winslow::linalg::multigrid_kernels::CycleBackend`]: under
//! `--linear multigrid` the multigrid V-cycle's level work (stencil residual, coloured
//! line Gauss–Seidel, the two 1D transfer passes, the coarsest solve;
//! `shaders/multigrid.wgsl`) runs on the GPU with the level data uploaded once per
//! set-up, giving the CPU cycle's bits on lavapipe. [`GpuProducts`] implements
//! [`winslow::discrete::OperatorBackend`]: GMRES's product with the Newton Jacobian
//! (its single-precision stencil storage, assembled on the GPU and rounded there into
//! the product's buffers by `shaders/pack.wgsl`: [`GpuAssembler::try_egg_operator`])
//! runs on the GPU too, also with the CPU's bits on lavapipe. [`Stats::bus`] counts the
//! bytes that cross the bus per Newton step and per GMRES iteration. [`GpuAssembler`] hands both to the solver
//! where the adapter has `SHADER_F64`; the levels' and the Jacobian's stencil values are
//! split over up to four bindings, so that neither is limited by one storage binding.
//!
//! Precision: f64 where the adapter offers `SHADER_F64` (lavapipe does); otherwise (or
//! on request) the matrices run in f32 and the residual on the CPU in f64, so Newton
//! still converges to the f64 tolerance. [`Gpu::describe`] says which ran.
//!
//! ```no_run
//! use std::sync::Arc;
//! use winslow_gpu::{Gpu, GpuAssembler, GpuOptions};
//! let gpu = Arc::new(Gpu::new(&GpuOptions::default())?);
//! println!("{}", gpu.describe());
//! let assembler = Arc::new(GpuAssembler::new(gpu));
//! // winslow::Pipeline::new(boundary, opts).backend(assembler).solve()?
//! # Ok::<(), winslow_gpu::GpuError>(())
//! ```

mod assembler;
pub mod bench;
mod device;
mod multigrid;
mod product;
mod sample;
mod stats;

pub use assembler::GpuAssembler;
pub use device::{Gpu, GpuOptions};
pub use multigrid::{CycleKernels, GpuBackend, GpuCycle, GpuCycles, Operation, Vector};
pub use product::{GpuProduct, GpuProducts, ProductKernels};
pub use sample::MapSample;
pub use stats::{BusShare, Stats, Timings};

use std::sync::Arc;

use winslow::methods::egg::{CpuAssembler, EggAssembler};

/// WGSL source of the assembly kernels (f64; see [`shader_source`]).
pub const ASSEMBLY_WGSL: &str = include_str!("../../../shaders/assembly.wgsl");
/// WGSL source of the `det J` sampling kernel (f64; see [`shader_source`]).
pub const DET_J_WGSL: &str = include_str!("../../../shaders/det_j.wgsl");

/// WGSL source of the multigrid cycle's level kernels (f64 only; see [`GpuCycles`]).
pub const MULTIGRID_WGSL: &str = include_str!("../../../shaders/multigrid.wgsl");

/// WGSL source of the kernel rounding the device Jacobian into the product's bindings
/// (f64 only; see [`GpuAssembler::try_egg_operator`]).
pub const PACK_WGSL: &str = include_str!("../../../shaders/pack.wgsl");

/// The first line of every shader, selecting f64.
pub const F64_ALIAS: &str = "alias real = f64;";
/// Its f32 replacement.
pub const F32_ALIAS: &str = "alias real = f32;";

/// Floating-point precision of the shaders.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// Everything in f64 (needs `SHADER_F64`).
    F64,
    /// Matrices in f32; residuals on the CPU in f64.
    F32,
}

impl Precision {
    /// "f64" or "f32".
    pub fn name(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }

    fn bytes(self) -> u64 {
        match self {
            Precision::F64 => 8,
            Precision::F32 => 4,
        }
    }
}

/// A shader's source in the given precision: the f64 source with its precision line
/// (`alias real = f64;`) replaced for f32.
pub fn shader_source(f64_source: &str, precision: Precision) -> String {
    match precision {
        Precision::F64 => f64_source.to_string(),
        Precision::F32 => f64_source.replacen(F64_ALIAS, F32_ALIAS, 1),
    }
}

/// `v` as the kernels' `u32` index, or [`GpuError::TooLarge`] naming `what`.
pub(crate) fn to_u32(v: usize, what: &str) -> Result<u32, GpuError> {
    u32::try_from(v).map_err(|_| GpuError::TooLarge(format!("{what} = {v} exceeds 32 bits")))
}

/// Which quadrature back end a command uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Backend {
    /// The multi-threaded CPU assembler of the core.
    #[default]
    Cpu,
    /// A GPU adapter (any, software rasterisers such as lavapipe included); failing to
    /// find one is an error.
    Gpu,
    /// A hardware GPU with `SHADER_F64` if there is one, else the CPU (a software
    /// adapter is slower than the CPU path, so `auto` does not pick it).
    Auto,
}

/// Errors of the GPU back end.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter (with the required features) was found.
    #[error("no GPU adapter found{0} (on Linux install Mesa's lavapipe, `mesa-vulkan-drivers`, and set WGPU_BACKEND=vulkan)")]
    NoAdapter(String),
    /// The device could not be opened.
    #[error("requesting the GPU device failed: {0}")]
    Device(String),
    /// wgpu reported an error (validation, out of memory, lost device).
    #[error("GPU error: {0}")]
    Wgpu(String),
    /// Mapping a buffer for readback failed.
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// The problem does not fit the adapter's limits.
    #[error("problem too large for the GPU: {0}")]
    TooLarge(String),
}

/// The assembler for `backend` and the adapter found, if any: `Cpu` gives the core's
/// [`CpuAssembler`]; `Gpu` a [`GpuAssembler`] or an error; `Auto` a hardware GPU with
/// f64 or else the CPU. `precision` forces the GPU precision (default: f64 if offered).
pub fn assembler(backend: Backend, precision: Option<Precision>) -> Result<Selected, GpuError> {
    match backend {
        Backend::Cpu => Ok(Selected::Cpu),
        Backend::Gpu => {
            let gpu = Gpu::new(&GpuOptions { precision, hardware_only: false })?;
            Ok(Selected::Gpu(Arc::new(GpuAssembler::new(Arc::new(gpu)))))
        }
        Backend::Auto => {
            let want = precision.unwrap_or(Precision::F64);
            match Gpu::new(&GpuOptions { precision: Some(want), hardware_only: true }) {
                Ok(gpu) => Ok(Selected::Gpu(Arc::new(GpuAssembler::new(Arc::new(gpu))))),
                Err(GpuError::NoAdapter(_)) => Ok(Selected::Cpu),
                Err(e) => Err(e),
            }
        }
    }
}

/// The outcome of [`assembler`].
#[derive(Debug, Clone)]
pub enum Selected {
    /// The CPU.
    Cpu,
    /// A GPU.
    Gpu(Arc<GpuAssembler>),
}

impl Selected {
    /// As the core's back-end hook.
    pub fn as_assembler(&self) -> Arc<dyn EggAssembler> {
        match self {
            Selected::Cpu => Arc::new(CpuAssembler),
            Selected::Gpu(g) => g.clone(),
        }
    }

    /// The GPU, if one was selected.
    pub fn gpu(&self) -> Option<&Arc<Gpu>> {
        match self {
            Selected::Cpu => None,
            Selected::Gpu(g) => Some(g.gpu()),
        }
    }

    /// "cpu" or the GPU's description.
    pub fn describe(&self) -> String {
        self.as_assembler().name()
    }
}

/// Whether the environment demands a GPU (`WINSLOW_REQUIRE_GPU=1`, as in CI): tests that
/// need one then fail instead of skipping.
pub fn gpu_required() -> bool {
    std::env::var("WINSLOW_REQUIRE_GPU").is_ok_and(|v| v == "1" || v.eq_ignore_ascii_case("true"))
}
