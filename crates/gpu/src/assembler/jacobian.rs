//! The Newton Jacobian of eq. (23) assembled where GMRES multiplies with it
//! ([`GpuAssembler::try_egg_operator`], the core's `EggAssembler::egg_operator`): the
//! assembly kernels write each chunk of basis rows' stencil storage (`f64`) on the
//! device as for `EggAssembler::egg`, and `shaders/pack.wgsl` rounds it to `f32` into
//! the split bindings of the product ([`crate::GpuProducts::on_device`]) before the next
//! chunk overwrites it: `Stencil32::pack` of the core done on the device. Only the
//! control points go up and the residual comes back; the Jacobian never crosses the bus
//! (before: its `f64` storage came back, 8 bytes per entry, and went up again as `f32`,
//! 4 bytes per entry, once per Newton step).

use std::time::Instant;

use winslow::discrete::assembly::{Discretization, Operator};
use winslow::spline::curve::Point;

use super::{op_code, GpuAssembler, StencilTo};
use crate::device::Gpu;
use crate::multigrid::StencilChunks;
use crate::product::GpuProduct;
use crate::stats::Timings;
use crate::{to_u32, GpuError, Precision};

/// The uniform block of `pack.wgsl` (all `u32`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    count: u32,
    src_off: u32,
    dst_off: u32,
    st_shift: u32,
    st_mask: u32,
    pad: [u32; 3],
}

/// The compiled kernel of `shaders/pack.wgsl`.
#[derive(Debug)]
pub(crate) struct PackKernel {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl PackKernel {
    /// Compile `pack.wgsl` (f64 only: the source's precision line as it is).
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        let ro = wgpu::BufferBindingType::Storage { read_only: true };
        let rw = wgpu::BufferBindingType::Storage { read_only: false };
        let types = [wgpu::BufferBindingType::Uniform, ro, rw, rw, rw, rw];
        let entries: Vec<wgpu::BindGroupLayoutEntry> = types
            .iter()
            .enumerate()
            .map(|(k, &ty)| wgpu::BindGroupLayoutEntry {
                binding: k as u32,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
                count: None,
            })
            .collect();
        let layout = device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("pack.wgsl"), entries: &entries });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("pack.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::PACK_WGSL.into()),
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("pack.wgsl"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("pack"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("pack"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { layout, pipeline }
    }
}

/// `pack.wgsl` bound to one source (the assembler's stencil chunk) and one set of
/// destination bindings.
pub(crate) struct Packer {
    params: wgpu::Buffer,
    bind: wgpu::BindGroup,
    shift: u32,
    mask: u32,
}

impl Packer {
    fn new(gpu: &Gpu, src: &wgpu::Buffer, dst: &StencilChunks) -> Result<Self, GpuError> {
        let k = gpu.pack.as_ref().ok_or_else(|| GpuError::NoAdapter(" with SHADER_F64 for the pack kernel".into()))?;
        let params = gpu.uniform("pack params", bytemuck::bytes_of(&Params::default()));
        let mut entries = vec![
            wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: src.as_entire_binding() },
        ];
        for (k, b) in dst.buffers().iter().enumerate() {
            entries.push(wgpu::BindGroupEntry { binding: 2 + k as u32, resource: b.as_entire_binding() });
        }
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pack"),
            layout: &k.layout,
            entries: &entries,
        });
        Ok(Self { params, bind, shift: dst.shift(), mask: dst.mask() })
    }

    /// Record `dst[lo + i] = f32(src[i])`, `i < len` (the parameters written for the
    /// next submission: one per chunk of rows).
    pub(super) fn record(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        lo: usize,
        len: usize,
    ) -> Result<(), GpuError> {
        let k = gpu.pack.as_ref().ok_or_else(|| GpuError::NoAdapter(" with SHADER_F64 for the pack kernel".into()))?;
        let p = Params {
            count: to_u32(len, "Jacobian entries per chunk")?,
            src_off: 0,
            dst_off: to_u32(lo, "Jacobian entries")?,
            st_shift: self.shift,
            st_mask: self.mask,
            ..Default::default()
        };
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        gpu.dispatch(enc, &k.pipeline, &self.bind, len as u64)
    }
}

impl GpuAssembler {
    /// The EGG residual into `res` (full, interleaved, length `2 n`) and the Jacobian in
    /// single-precision stencil storage on the device, as the product with it (see the
    /// module documentation). Needs `SHADER_F64` (the product's kernels).
    ///
    /// Errors: [`GpuError`] without the product's kernels, when the system does not fit
    /// the adapter's limits, or when wgpu fails.
    pub fn try_egg_operator(
        &self,
        disc: &Discretization,
        cps: &[Point],
        op: Operator,
        res: &mut [f64],
    ) -> Result<GpuProduct, GpuError> {
        let products = self.products.as_ref().filter(|_| self.gpu.precision() == Precision::F64);
        let products =
            products.ok_or_else(|| GpuError::NoAdapter(" with SHADER_F64 for the Jacobian product".into()))?;
        let t0 = Instant::now();
        let mut t = Timings { calls: 1, ..Default::default() };
        let len = disc.stencil_len(2);
        to_u32(len, "Jacobian entries")?;
        let stencil = {
            let _busy = self.busy.lock().map_err(|e| GpuError::Wgpu(e.to_string()))?;
            self.gpu.scoped(|| {
                let b = self.basis_with(disc, cps, &mut t)?;
                let chunk = products.shared().chunk_bytes;
                let stencil = StencilChunks::on_device(&self.gpu, "Jacobian stencil", len, chunk)?;
                let packer = Packer::new(&self.gpu, &b.out, &stencil)?;
                let kernels = self.egg_kernels(true, true);
                self.run_chunks(&b, op_code(op), true, &kernels, 2, res, StencilTo::Device(&packer), &mut t)?;
                Ok(stencil)
            })?
        };
        self.record(|s| s.egg_jacobian.add(&t));
        products.on_device(disc, 2, stencil, len, 0, t0)
    }

    /// Whether the Jacobian of `--linear multigrid` is assembled on the device
    /// ([`GpuAssembler::try_egg_operator`], the default) or read back, packed on the
    /// host and uploaded again (`false`: the path before, kept for measurement).
    pub fn set_device_jacobian(&self, on: bool) {
        self.device_jacobian.store(on, std::sync::atomic::Ordering::Relaxed);
    }

    /// See [`GpuAssembler::set_device_jacobian`].
    pub fn device_jacobian(&self) -> bool {
        self.device_jacobian.load(std::sync::atomic::Ordering::Relaxed)
    }
}
