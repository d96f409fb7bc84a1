//! Adapter selection, device, compiled kernels and the buffer plumbing they share.

use wgpu::util::DeviceExt;

use crate::{shader_source, GpuError, Precision, ASSEMBLY_WGSL, DET_J_WGSL};

/// How to pick the adapter.
#[derive(Debug, Clone, Copy, Default)]
pub struct GpuOptions {
    /// Force a precision (default: f64 if the adapter offers `SHADER_F64`, else f32).
    pub precision: Option<Precision>,
    /// Refuse software adapters (lavapipe, llvmpipe, WARP).
    pub hardware_only: bool,
}

/// Largest buffer the kernels bind at once (bytes); bigger problems run in chunks of
/// basis rows. Keeps host memory moderate on software adapters.
pub(crate) const CHUNK_BYTES: u64 = 256 << 20;

/// The kernels of `shaders/assembly.wgsl`.
#[derive(Debug)]
pub(crate) struct AssemblyKernels {
    pub layout: wgpu::BindGroupLayout,
    pub geometry: wgpu::ComputePipeline,
    pub egg_residual: wgpu::ComputePipeline,
    pub egg_stencil: wgpu::ComputePipeline,
    pub egg_element: wgpu::ComputePipeline,
    pub egg_gather: wgpu::ComputePipeline,
    pub elasticity_stencil: wgpu::ComputePipeline,
    pub mass_stencil: wgpu::ComputePipeline,
}

/// The kernel of `shaders/det_j.wgsl`.
#[derive(Debug)]
pub(crate) struct DetJKernel {
    pub layout: wgpu::BindGroupLayout,
    pub sample: wgpu::ComputePipeline,
}

/// An opened GPU with the compiled kernels.
#[derive(Debug)]
pub struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    precision: Precision,
    pub(crate) limits: wgpu::Limits,
    pub(crate) assembly: AssemblyKernels,
    pub(crate) det_j: DetJKernel,
    /// The multigrid cycle's kernels (f64 only: `None` in f32).
    pub(crate) multigrid: Option<crate::multigrid::MultigridKernels>,
    /// The kernel rounding the device Jacobian into the product's bindings (with the
    /// multigrid kernels).
    pub(crate) pack: Option<crate::assembler::PackKernel>,
}

fn is_software(info: &wgpu::AdapterInfo) -> bool {
    info.device_type == wgpu::DeviceType::Cpu
}

impl Gpu {
    /// Find an adapter (the backends in `WGPU_BACKEND`, default all), preferring f64
    /// support, then hardware, then Vulkan; open it and compile the kernels.
    pub fn new(opts: &GpuOptions) -> Result<Self, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        let seen: Vec<String> =
            adapters.iter().map(|a| a.get_info()).map(|i| format!("{} ({:?})", i.name, i.backend)).collect();
        let score = |a: &wgpu::Adapter| {
            let info = a.get_info();
            let f64_ok = a.features().contains(wgpu::Features::SHADER_F64);
            (f64_ok as u8) * 4 + (!is_software(&info) as u8) * 2 + (info.backend == wgpu::Backend::Vulkan) as u8
        };
        let adapter = adapters
            .into_iter()
            .filter(|a| !opts.hardware_only || !is_software(&a.get_info()))
            .filter(|a| opts.precision != Some(Precision::F64) || a.features().contains(wgpu::Features::SHADER_F64))
            .max_by_key(score)
            .ok_or_else(|| {
                let what = match (opts.precision, opts.hardware_only) {
                    (Some(Precision::F64), true) => " (hardware, with SHADER_F64)",
                    (Some(Precision::F64), false) => " with SHADER_F64",
                    (_, true) => " (hardware)",
                    _ => "",
                };
                let seen = if seen.is_empty() { "none".to_string() } else { seen.join(", ") };
                GpuError::NoAdapter(format!("{what}; adapters seen: {seen}"))
            })?;
        let has_f64 = adapter.features().contains(wgpu::Features::SHADER_F64);
        let precision = opts.precision.unwrap_or(if has_f64 { Precision::F64 } else { Precision::F32 });
        let features = if precision == Precision::F64 { wgpu::Features::SHADER_F64 } else { wgpu::Features::empty() };
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("winslow"),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let assembly = assembly_kernels(&device, precision);
        let det_j = det_j_kernel(&device, precision);
        // the multigrid kernels bind seven storage buffers (`multigrid::STORAGE_BINDINGS`)
        let bindings = limits.max_storage_buffers_per_shader_stage >= crate::multigrid::STORAGE_BINDINGS;
        let multigrid = (precision == Precision::F64 && bindings).then(|| crate::multigrid::multigrid_kernels(&device));
        let pack = multigrid.is_some().then(|| crate::assembler::PackKernel::new(&device));
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Wgpu(e.to_string()));
        }
        Ok(Self { device, queue, info: adapter.get_info(), precision, limits, assembly, det_j, multigrid, pack })
    }

    /// The adapter's name, driver and wgpu back end.
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// Precision of the kernels.
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// Whether the adapter is a software rasteriser (lavapipe).
    pub fn is_software(&self) -> bool {
        is_software(&self.info)
    }

    /// One line: `"gpu: <adapter> (<backend>, <type>, f64)"`.
    pub fn describe(&self) -> String {
        let i = &self.info;
        let kind = match i.device_type {
            wgpu::DeviceType::DiscreteGpu => "discrete",
            wgpu::DeviceType::IntegratedGpu => "integrated",
            wgpu::DeviceType::VirtualGpu => "virtual",
            wgpu::DeviceType::Cpu => "software",
            wgpu::DeviceType::Other => "other",
        };
        format!("gpu: {} ({:?}, {kind}, {})", i.name, i.backend, self.precision.name())
    }

    /// Run `f` inside validation and out-of-memory error scopes: wgpu's errors become
    /// [`GpuError::Wgpu`] instead of the default panic.
    pub(crate) fn scoped<T>(&self, f: impl FnOnce() -> Result<T, GpuError>) -> Result<T, GpuError> {
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let val = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let out = f();
        let e1 = pollster::block_on(val.pop());
        let e2 = pollster::block_on(oom.pop());
        if let Some(e) = e1.or(e2) {
            return Err(GpuError::Wgpu(e.to_string()));
        }
        out
    }

    /// Largest binding size the chunking aims for.
    pub(crate) fn chunk_bytes(&self) -> u64 {
        CHUNK_BYTES.min(self.limits.max_storage_buffer_binding_size).min(self.limits.max_buffer_size)
    }

    /// A storage buffer holding `values` in the kernels' precision (at least 16 bytes).
    ///
    /// Errors: as [`Gpu::storage_parts`].
    pub(crate) fn storage_real(&self, label: &str, values: &[f64]) -> Result<wgpu::Buffer, GpuError> {
        let bytes = self.to_bytes(values);
        self.storage_init(label, &bytes)
    }

    /// A storage buffer holding `bytes` (at least 16, zero-padded to a multiple of 8).
    ///
    /// Errors: as [`Gpu::storage_parts`].
    pub(crate) fn storage_init(&self, label: &str, bytes: &[u8]) -> Result<wgpu::Buffer, GpuError> {
        self.storage_parts(label, &[bytes], 0, bytes.len())
    }

    /// A storage buffer holding `len` elements of the concatenation of `parts`, from
    /// element `skip` on (at least 16 bytes, zero-padded to a multiple of 8), written in
    /// place into the buffer's mapping at creation (`mapped_at_creation`: wgpu's staging
    /// memory, copied to the device on unmap): no host copy of the parts is made, and the
    /// bytes cross the bus once.
    ///
    /// Errors: [`GpuError::Wgpu`] when the mapping cannot be had.
    pub(crate) fn storage_parts<T: bytemuck::Pod>(
        &self,
        label: &str,
        parts: &[&[T]],
        mut skip: usize,
        len: usize,
    ) -> Result<wgpu::Buffer, GpuError> {
        let size = std::mem::size_of::<T>();
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: ((len * size) as u64).max(16).next_multiple_of(8),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: true,
        });
        {
            // the mapping at creation is zeroed: only the parts are written
            let mut view = buffer.get_mapped_range_mut(..).map_err(|e| GpuError::Wgpu(e.to_string()))?;
            let (mut at, mut left) = (0usize, len);
            for part in parts {
                if left == 0 {
                    break;
                }
                if skip >= part.len() {
                    skip -= part.len();
                    continue;
                }
                let take = (part.len() - skip).min(left);
                let bytes: &[u8] = bytemuck::cast_slice(&part[skip..skip + take]);
                view.slice(at..at + bytes.len()).copy_from_slice(bytes);
                (at, left, skip) = (at + bytes.len(), left - take, 0);
            }
        }
        buffer.unmap();
        Ok(buffer)
    }

    /// A storage buffer of `bytes` (at least 16, rounded up to a multiple of 8) that the
    /// kernels fill: nothing crosses the bus (wgpu zeroes it on the device).
    pub(crate) fn storage_zeroed(&self, label: &str, bytes: u64) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(16).next_multiple_of(8),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    }

    /// An uninitialised storage buffer of `len` reals (at least 16 bytes).
    pub(crate) fn storage_empty(&self, label: &str, len: u64) -> wgpu::Buffer {
        self.storage_zeroed(label, len * self.precision.bytes())
    }

    pub(crate) fn staging(&self, bytes: u64) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("staging"),
            size: bytes.max(16).next_multiple_of(8),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    pub(crate) fn uniform(&self, label: &str, bytes: &[u8]) -> wgpu::Buffer {
        self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytes,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        })
    }

    /// `values` in the kernels' precision, as bytes.
    pub(crate) fn to_bytes(&self, values: &[f64]) -> Vec<u8> {
        match self.precision {
            Precision::F64 => bytemuck::cast_slice(values).to_vec(),
            Precision::F32 => {
                let v: Vec<f32> = values.iter().map(|&x| x as f32).collect();
                bytemuck::cast_slice(&v).to_vec()
            }
        }
    }

    /// Size in bytes of `len` reals.
    pub(crate) fn real_bytes(&self, len: u64) -> u64 {
        len * self.precision.bytes()
    }

    /// Submit and wait for completion.
    pub(crate) fn submit_wait(&self, cmd: Option<wgpu::CommandBuffer>) -> Result<(), GpuError> {
        let index = self.queue.submit(cmd);
        self.device
            .poll(wgpu::PollType::Wait { submission_index: Some(index), timeout: None })
            .map_err(|e| GpuError::Wgpu(e.to_string()))?;
        Ok(())
    }

    /// Copy `bytes` of `src` from offset `off` into `staging` (after `enc`'s commands when
    /// given), wait for it, and map `staging`'s first `bytes` for reading: the caller reads
    /// the returned slice's mapped range, then unmaps `staging`.
    pub(crate) fn copy_and_map<'a>(
        &self,
        enc: Option<wgpu::CommandEncoder>,
        src: &wgpu::Buffer,
        off: u64,
        staging: &'a wgpu::Buffer,
        bytes: u64,
    ) -> Result<wgpu::BufferSlice<'a>, GpuError> {
        let mut enc = enc.unwrap_or_else(|| self.device.create_command_encoder(&Default::default()));
        enc.copy_buffer_to_buffer(src, off, staging, 0, bytes);
        self.submit_wait(Some(enc.finish()))?;
        let slice = staging.slice(0..bytes);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            // the receiver lives until after the poll below
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::Wait { submission_index: None, timeout: None })
            .map_err(|e| GpuError::Wgpu(e.to_string()))?;
        rx.recv().map_err(|e| GpuError::Readback(e.to_string()))?.map_err(|e| GpuError::Readback(e.to_string()))?;
        Ok(slice)
    }

    /// Copy `len` reals from `src` (offset 0) through `staging` into `out` as f64.
    pub(crate) fn read_into(
        &self,
        src: &wgpu::Buffer,
        staging: &wgpu::Buffer,
        len: usize,
        out: &mut [f64],
    ) -> Result<(), GpuError> {
        if len == 0 {
            return Ok(());
        }
        let bytes = self.real_bytes(len as u64);
        let slice = self.copy_and_map(None, src, 0, staging, bytes.next_multiple_of(4))?;
        {
            let view = slice.get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
            let data = &view[..bytes as usize];
            match self.precision {
                // A mapped range is aligned to `wgpu::MAP_ALIGNMENT` (8 bytes), so the reals are
                // read in place; the copying fallback only serves an unaligned mapping.
                Precision::F64 => match bytemuck::try_cast_slice::<u8, f64>(data) {
                    Ok(v) => out[..len].copy_from_slice(v),
                    Err(_) => out[..len].copy_from_slice(&bytemuck::pod_collect_to_vec::<u8, f64>(data)),
                },
                Precision::F32 => {
                    let widen = |o: &mut [f64], v: &[f32]| o.iter_mut().zip(v).for_each(|(o, &x)| *o = x as f64);
                    match bytemuck::try_cast_slice::<u8, f32>(data) {
                        Ok(v) => widen(&mut out[..len], v),
                        Err(_) => widen(&mut out[..len], &bytemuck::pod_collect_to_vec::<u8, f32>(data)),
                    }
                }
            }
        }
        staging.unmap();
        Ok(())
    }

    /// Record one dispatch of `pipeline` over `invocations` threads (64 per group, a 2-D
    /// grid of groups when there are more than the per-dimension limit).
    pub(crate) fn dispatch(
        &self,
        enc: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::ComputePipeline,
        bind: &wgpu::BindGroup,
        invocations: u64,
    ) -> Result<(), GpuError> {
        if invocations == 0 {
            return Ok(());
        }
        let groups = invocations.div_ceil(64);
        let max = self.limits.max_compute_workgroups_per_dimension.max(1) as u64;
        let x = groups.min(max);
        let y = groups.div_ceil(x);
        if y > max {
            return Err(GpuError::TooLarge(format!("{invocations} invocations in one dispatch")));
        }
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: None, timestamp_writes: None });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind, &[]);
        pass.dispatch_workgroups(x as u32, y as u32, 1);
        Ok(())
    }
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// The shader module of `source` and its bind-group and pipeline layouts: binding 0 a
/// uniform, then one storage buffer per entry of `read_only`.
fn module_and_layouts(
    device: &wgpu::Device,
    label: &str,
    source: String,
    read_only: &[bool],
) -> (wgpu::ShaderModule, wgpu::BindGroupLayout, wgpu::PipelineLayout) {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let entries: Vec<wgpu::BindGroupLayoutEntry> = std::iter::once(uniform_entry(0))
        .chain(read_only.iter().enumerate().map(|(k, &ro)| storage_entry(k as u32 + 1, ro)))
        .collect();
    let layout =
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries });
    let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    (module, layout, pl)
}

fn assembly_kernels(device: &wgpu::Device, precision: Precision) -> AssemblyKernels {
    let (module, layout, pl) = module_and_layouts(
        device,
        "assembly.wgsl",
        shader_source(ASSEMBLY_WGSL, precision),
        &[true, true, true, false, false, false, false],
    );
    AssemblyKernels {
        geometry: pipeline(device, &pl, &module, "geometry"),
        egg_residual: pipeline(device, &pl, &module, "egg_residual"),
        egg_stencil: pipeline(device, &pl, &module, "egg_stencil"),
        egg_element: pipeline(device, &pl, &module, "egg_element"),
        egg_gather: pipeline(device, &pl, &module, "egg_gather"),
        elasticity_stencil: pipeline(device, &pl, &module, "elasticity_stencil"),
        mass_stencil: pipeline(device, &pl, &module, "mass_stencil"),
        layout,
    }
}

fn det_j_kernel(device: &wgpu::Device, precision: Precision) -> DetJKernel {
    let (module, layout, pl) =
        module_and_layouts(device, "det_j.wgsl", shader_source(DET_J_WGSL, precision), &[true, true, true, false]);
    DetJKernel { sample: pipeline(device, &pl, &module, "sample"), layout }
}
