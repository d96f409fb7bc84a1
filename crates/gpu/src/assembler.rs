//! [`GpuAssembler`]: the core's [`EggAssembler`] on the kernels of
//! `shaders/assembly.wgsl`.
//!
//! Per basis (cached, keyed by the knot vectors and the number of Gauss points) the
//! univariate tables of [`DirTable`], the first function of every element and the
//! element range of every function are uploaded once, and the work buffers allocated.
//! Per call only the control points go up; the residual and the stencil storage come
//! back, exactly in the CPU's layout. Problems whose buffers exceed
//! [`crate::device::CHUNK_BYTES`] run in chunks of basis rows `eta`.

use std::sync::{Arc, Mutex};
use std::time::Instant;

use winslow::discrete::assembly::{Discretization, Operator};
use winslow::discrete::tables::DirTable;
use winslow::discrete::{DeviceOperator, OperatorBackend};
use winslow::linalg::multigrid_kernels::CycleBackend;
use winslow::methods::egg::{CpuAssembler, EggAssembler};
use winslow::spline::curve::Point;
use winslow::spline::surface::Surface;
use winslow::verify::quality::DetJSample;

use crate::device::Gpu;
use crate::multigrid::GpuCycles;
use crate::product::GpuProducts;
use crate::stats::{Stats, Timings};
use crate::{to_u32, GpuError, Precision};

mod jacobian;
pub(crate) use jacobian::PackKernel;

/// The uniform block of `assembly.wgsl` (all `u32`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    p: u32,
    q: u32,
    nq_u: u32,
    nq_v: u32,
    nx: u32,
    ny: u32,
    nex: u32,
    ney: u32,
    tab_x: u32,
    tab_y: u32,
    first_x: u32,
    first_y: u32,
    range_x: u32,
    range_y: u32,
    ey0: u32,
    ey1: u32,
    j0: u32,
    j1: u32,
    op: u32,
    lame: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
    pad3: u32,
}

/// Function rows `[j0, j1)` and the element rows `[ey0, ey1)` they touch.
#[derive(Debug, Clone, Copy)]
struct Chunk {
    j0: usize,
    j1: usize,
    ey0: usize,
    ey1: usize,
}

/// Everything uploaded or allocated once per basis.
#[derive(Debug)]
struct BasisData {
    key: (Vec<f64>, usize, Vec<f64>, usize, usize, usize),
    params: Params,
    chunks: Vec<Chunk>,
    n: usize,
    sw: usize,
    qp_per_call: u64,
    params_buf: wgpu::Buffer,
    tab: wgpu::Buffer,
    cps: wgpu::Buffer,
    out: wgpu::Buffer,
    res: wgpu::Buffer,
    staging: wgpu::Buffer,
    bind: wgpu::BindGroup,
    upload_bytes: u64,
}

/// Values per quadrature point written by the `geometry` kernel (`GEO` in the shader).
const GEO: usize = 17;

/// What a kernel of a chunk writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Out {
    /// The residual, one invocation per basis function.
    Residual,
    /// Stencil storage, one invocation per (function, slot).
    Stencil,
    /// Element matrices (kept on the GPU), one workgroup per element.
    Element,
}

/// Where the stencil storage a kernel writes goes.
enum StencilTo<'a> {
    /// Read back into the host's stencil storage (`f64`).
    Host(&'a mut [f64]),
    /// Rounded to `f32` into the Jacobian product's bindings on the device
    /// ([`jacobian::Packer`]): nothing comes back.
    Device(&'a jacobian::Packer),
}

/// The operator's code in `assembly.wgsl`.
fn op_code(op: Operator) -> u32 {
    match op {
        Operator::Plain => 0,
        Operator::Scaled => 1,
    }
}

/// Cached bases (the solver alternates between at most two or three).
const CACHE: usize = 4;

/// The GPU quadrature back end; see the crate documentation.
#[derive(Debug)]
pub struct GpuAssembler {
    gpu: Arc<Gpu>,
    cache: Mutex<Vec<Arc<BasisData>>>,
    stats: Mutex<Stats>,
    /// Held while a call uses the cached buffers (parameters, control points, outputs).
    busy: Mutex<()>,
    /// Largest buffer bound at once (bytes).
    chunk_bytes: u64,
    /// Jacobian by the per-entry kernel instead of element matrices.
    per_entry: bool,
    /// The multigrid cycle's kernels (`None` without `SHADER_F64`).
    cycles: Option<Arc<GpuCycles>>,
    /// The Newton Jacobian's product (`None` without `SHADER_F64`).
    products: Option<Arc<GpuProducts>>,
    /// The Newton Jacobian assembled into the product's buffers (the default).
    device_jacobian: std::sync::atomic::AtomicBool,
}

fn key_of(disc: &Discretization) -> (Vec<f64>, usize, Vec<f64>, usize, usize, usize) {
    (
        disc.knots[0].knots().to_vec(),
        disc.knots[0].degree(),
        disc.knots[1].knots().to_vec(),
        disc.knots[1].degree(),
        disc.tables[0].nq,
        disc.tables[1].nq,
    )
}

/// Per table: `[w, N(0..=p), N'(0..=p), N''(0..=p)]` for every (element, point).
fn pack_table(t: &DirTable, out: &mut Vec<f64>) {
    for qp in &t.qp {
        out.push(qp.w);
        for k in 0..3 {
            out.extend_from_slice(&qp.n[k][..=t.p]);
        }
    }
}

/// Inclusive element range of every function of a direction (from the first function
/// per element, which is non-decreasing).
fn element_ranges(t: &DirTable, nfun: usize) -> Vec<u32> {
    let mut r = vec![(u32::MAX, 0u32); nfun];
    for (e, &f) in t.first.iter().enumerate() {
        for i in f..=(f + t.p).min(nfun - 1) {
            r[i].0 = r[i].0.min(e as u32);
            r[i].1 = r[i].1.max(e as u32);
        }
    }
    r.into_iter().flat_map(|(lo, hi)| if lo == u32::MAX { [1, 0] } else { [lo, hi] }).collect()
}

impl GpuAssembler {
    /// An assembler on `gpu`.
    pub fn new(gpu: Arc<Gpu>) -> Self {
        let chunk_bytes = gpu.chunk_bytes();
        Self {
            cache: Mutex::new(Vec::new()),
            stats: Mutex::new(Stats::default()),
            busy: Mutex::new(()),
            chunk_bytes,
            per_entry: false,
            cycles: GpuCycles::new(gpu.clone()).map(Arc::new),
            products: GpuProducts::new(gpu.clone()).map(Arc::new),
            device_jacobian: true.into(),
            gpu,
        }
    }

    /// Bind at most `bytes` per buffer (default 256 MiB or the adapter's limit): larger
    /// problems run in more chunks of basis rows.
    pub fn with_chunk_bytes(mut self, bytes: u64) -> Self {
        self.chunk_bytes = bytes.clamp(1024, self.gpu.chunk_bytes());
        self
    }

    /// Bind the Newton Jacobian's stencil values for the product in chunks of at most
    /// `bytes` ([`crate::GpuBackend::with_chunk_bytes`]): for tests of the split at
    /// small sizes.
    pub fn with_product_chunk_bytes(mut self, bytes: u64) -> Self {
        self.products = GpuProducts::new(self.gpu.clone()).map(|p| Arc::new(p.with_chunk_bytes(bytes)));
        self
    }

    /// Assemble the EGG Jacobian with the per-entry kernel (`egg_stencil`: every stencil
    /// entry integrates its own terms) instead of the default element matrices
    /// (`egg_element`, one workgroup per element sharing the terms of each quadrature
    /// point, then `egg_gather`). Both give the CPU's numbers; kept for measurement.
    pub fn with_per_entry_jacobian(mut self, per_entry: bool) -> Self {
        self.per_entry = per_entry;
        self
    }

    /// Number of chunks `disc` runs in (uploads its basis if needed).
    pub fn chunks(&self, disc: &Discretization) -> usize {
        let mut t = Timings::default();
        self.basis(disc, &mut t).map_or(0, |b| b.chunks.len())
    }

    /// The device.
    pub fn gpu(&self) -> &Arc<Gpu> {
        &self.gpu
    }

    /// Timings so far.
    pub fn stats(&self) -> Stats {
        let mut s = self.stats.lock().map(|s| s.clone()).unwrap_or_default();
        if let Some(c) = &self.cycles {
            let (t, fallbacks, last) = c.stats();
            (s.multigrid, s.multigrid_fallbacks) = (t, fallbacks);
            s.last_error = s.last_error.or(last);
        }
        if let Some(p) = &self.products {
            let (t, fallbacks, last) = p.stats();
            (s.jacobian_products, s.jacobian_product_fallbacks) = (t, fallbacks);
            s.last_error = s.last_error.or(last);
        }
        s
    }

    /// Zero the timings.
    pub fn reset_stats(&self) {
        if let Ok(mut s) = self.stats.lock() {
            *s = Stats::default();
        }
        if let Some(c) = &self.cycles {
            c.reset_stats();
        }
        if let Some(p) = &self.products {
            p.reset_stats();
        }
    }

    /// The multigrid cycle's kernels on this GPU (`None` without `SHADER_F64`).
    pub fn cycles(&self) -> Option<&Arc<GpuCycles>> {
        self.cycles.as_ref()
    }

    fn record(&self, f: impl FnOnce(&mut Stats)) {
        if let Ok(mut s) = self.stats.lock() {
            f(&mut s);
        }
    }

    /// The cached data of `disc`'s basis, uploading it on first use (the upload time
    /// and bytes go to `t`).
    fn basis(&self, disc: &Discretization, t: &mut Timings) -> Result<Arc<BasisData>, GpuError> {
        let key = key_of(disc);
        if let Ok(cache) = self.cache.lock() {
            if let Some(b) = cache.iter().find(|b| b.key == key) {
                return Ok(b.clone());
            }
        }
        let t0 = Instant::now();
        let data = Arc::new(self.upload_basis(disc, key)?);
        t.upload += t0.elapsed().as_secs_f64();
        t.bytes_up += data.upload_bytes;
        if let Ok(mut cache) = self.cache.lock() {
            if cache.len() >= CACHE {
                cache.remove(0);
            }
            cache.push(data.clone());
        }
        Ok(data)
    }

    fn upload_basis(
        &self,
        disc: &Discretization,
        key: (Vec<f64>, usize, Vec<f64>, usize, usize, usize),
    ) -> Result<BasisData, GpuError> {
        let gpu = &self.gpu;
        let (tx, ty) = (&disc.tables[0], &disc.tables[1]);
        let [nx, ny] = disc.shape();
        let (p, q) = disc.degrees();
        let (nex, ney) = (tx.num_elements(), ty.num_elements());
        let sw = (2 * p + 1) * (2 * q + 1);
        // tables: xi, eta, then the Lame constants
        let mut tab = Vec::new();
        pack_table(tx, &mut tab);
        let tab_y = tab.len();
        pack_table(ty, &mut tab);
        let lame = tab.len();
        tab.extend_from_slice(&[0.0, 0.0]);
        // indices: first per element (x, y), ranges per function (x, y)
        let mut idx: Vec<u32> = Vec::new();
        let first_x = idx.len();
        for &f in &tx.first {
            idx.push(to_u32(f, "first function")?);
        }
        let first_y = idx.len();
        for &f in &ty.first {
            idx.push(to_u32(f, "first function")?);
        }
        let range_x = idx.len();
        idx.extend(element_ranges(tx, nx));
        let range_y = idx.len();
        idx.extend(element_ranges(ty, ny));
        let ry = element_ranges(ty, ny);

        // chunks of function rows: the stencil of a 2-component system per row and the
        // geometry of the element rows they touch must fit the binding budget
        let budget = self.chunk_bytes;
        let row_bytes = gpu.real_bytes((nx * 4 * sw) as u64);
        let geo_row_bytes = gpu.real_bytes((nex * tx.nq * ty.nq * GEO) as u64);
        let rows_by_stencil = (budget / row_bytes.max(1)) as usize;
        let rows_by_geo = ((budget / geo_row_bytes.max(1)) as usize).saturating_sub(q + 1);
        let nloc = (p + 1) * (q + 1);
        let elm_row_bytes = gpu.real_bytes((nex * 4 * nloc * nloc) as u64);
        let rows_by_elm = ((budget / elm_row_bytes.max(1)) as usize).saturating_sub(q + 1);
        let rows = rows_by_stencil.min(rows_by_geo).min(rows_by_elm).clamp(1, ny.max(1));
        let mut chunks = Vec::new();
        let mut j0 = 0;
        while j0 < ny {
            let j1 = (j0 + rows).min(ny);
            let ey0 = (j0..j1).map(|j| ry[2 * j] as usize).min().unwrap_or(0);
            let ey1 = (j0..j1).map(|j| ry[2 * j + 1] as usize + 1).max().unwrap_or(0).max(ey0);
            chunks.push(Chunk { j0, j1, ey0, ey1 });
            j0 = j1;
        }
        let max_rows = chunks.iter().map(|c| c.j1 - c.j0).max().unwrap_or(0);
        let max_erows = chunks.iter().map(|c| c.ey1 - c.ey0).max().unwrap_or(0);
        let out_len = (max_rows * nx * 4 * sw) as u64;
        let res_len = (max_rows * nx * 2) as u64;
        let geo_len = (max_erows * nex * tx.nq * ty.nq * GEO) as u64;
        let elm_len = (max_erows * nex * 4 * nloc * nloc) as u64;
        let max_binding = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
        for (what, len) in [
            ("stencil chunk", out_len),
            ("geometry chunk", geo_len),
            ("element matrices", elm_len),
            ("tables", tab.len() as u64),
        ] {
            if gpu.real_bytes(len) > max_binding {
                return Err(GpuError::TooLarge(format!(
                    "{what} needs {} bytes, the adapter binds at most {max_binding}",
                    gpu.real_bytes(len)
                )));
            }
        }
        let params = Params {
            p: to_u32(p, "degree")?,
            q: to_u32(q, "degree")?,
            nq_u: to_u32(tx.nq, "points")?,
            nq_v: to_u32(ty.nq, "points")?,
            nx: to_u32(nx, "basis size")?,
            ny: to_u32(ny, "basis size")?,
            nex: to_u32(nex, "elements")?,
            ney: to_u32(ney, "elements")?,
            tab_x: 0,
            tab_y: to_u32(tab_y, "table size")?,
            first_x: to_u32(first_x, "index size")?,
            first_y: to_u32(first_y, "index size")?,
            range_x: to_u32(range_x, "index size")?,
            range_y: to_u32(range_y, "index size")?,
            lame: to_u32(lame, "table size")?,
            ..Default::default()
        };
        to_u32(max_rows * nx * 4 * sw, "stencil entries per chunk")?;
        to_u32(max_erows * nex * tx.nq * ty.nq * GEO, "geometry values per chunk")?;
        let upload_bytes = gpu.real_bytes(tab.len() as u64) + 4 * idx.len() as u64;
        let tab_buf = gpu.storage_real("tables", &tab)?;
        let idx_buf = gpu.storage_init("indices", bytemuck::cast_slice(&idx))?;
        let cps = gpu.storage_empty("control points", 2 * (nx * ny) as u64);
        let geo = gpu.storage_empty("geometry", geo_len);
        let out = gpu.storage_empty("stencil", out_len);
        let res = gpu.storage_empty("residual", res_len);
        let elm = gpu.storage_empty("element matrices", elm_len);
        let staging = gpu.staging(gpu.real_bytes(out_len.max(res_len)));
        let params_buf = gpu.uniform("params", bytemuck::bytes_of(&params));
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("assembly"),
            layout: &gpu.assembly.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: tab_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: idx_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: cps.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: geo.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: out.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 6, resource: res.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 7, resource: elm.as_entire_binding() },
            ],
        });
        gpu.submit_wait(None)?;
        Ok(BasisData {
            key,
            params,
            chunks,
            n: nx * ny,
            sw,
            qp_per_call: (nex * ney * tx.nq * ty.nq) as u64,
            params_buf,
            tab: tab_buf,
            cps,
            out,
            res,
            staging,
            bind,
            upload_bytes,
        })
    }

    fn upload_cps(&self, b: &BasisData, cps: &[Point], t: &mut Timings) -> Result<(), GpuError> {
        let t0 = Instant::now();
        let flat: Vec<f64> = cps.iter().flat_map(|c| [c[0], c[1]]).collect();
        let bytes = self.gpu.to_bytes(&flat);
        self.gpu.queue.write_buffer(&b.cps, 0, &bytes);
        self.gpu.submit_wait(None)?;
        t.upload += t0.elapsed().as_secs_f64();
        t.bytes_up += bytes.len() as u64;
        Ok(())
    }

    /// Run the kernels for every chunk; `geometry` first when `geometry`, then each of
    /// `kernels` with its output (the stencil of `ncomp` components, the residual, or
    /// element matrices kept on the GPU), reading the residual into `res` and sending
    /// the stencil where `stencil` says.
    #[allow(clippy::type_complexity, clippy::too_many_arguments)]
    fn run_chunks(
        &self,
        b: &BasisData,
        op: u32,
        geometry: bool,
        kernels: &[(&wgpu::ComputePipeline, Out)],
        ncomp: usize,
        res: &mut [f64],
        mut stencil: StencilTo<'_>,
        t: &mut Timings,
    ) -> Result<(), GpuError> {
        let gpu = &self.gpu;
        let nx = b.params.nx as usize;
        let nqp = (b.params.nq_u * b.params.nq_v) as u64;
        let row_len = ncomp * ncomp * b.sw;
        for c in &b.chunks {
            let t0 = Instant::now();
            let params =
                Params { ey0: c.ey0 as u32, ey1: c.ey1 as u32, j0: c.j0 as u32, j1: c.j1 as u32, op, ..b.params };
            gpu.queue.write_buffer(&b.params_buf, 0, bytemuck::bytes_of(&params));
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            let rows = ((c.j1 - c.j0) * nx) as u64;
            if geometry {
                let n = (c.ey1 - c.ey0) as u64 * b.params.nex as u64 * nqp;
                gpu.dispatch(&mut enc, &gpu.assembly.geometry, &b.bind, n)?;
            }
            for &(k, out) in kernels {
                let n = match out {
                    Out::Residual => rows,
                    Out::Stencil => rows * b.sw as u64,
                    Out::Element => (c.ey1 - c.ey0) as u64 * b.params.nex as u64 * 64,
                };
                gpu.dispatch(&mut enc, k, &b.bind, n)?;
                if let (Out::Stencil, StencilTo::Device(packer)) = (out, &stencil) {
                    // rounded into the product's bindings before the next chunk overwrites it
                    let (lo, len) = (c.j0 * nx * row_len, (c.j1 - c.j0) * nx * row_len);
                    packer.record(gpu, &mut enc, lo, len)?;
                }
            }
            gpu.submit_wait(Some(enc.finish()))?;
            t.dispatch += t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            for &(_, out) in kernels {
                if out == Out::Element {
                    continue;
                }
                if out == Out::Stencil {
                    let StencilTo::Host(stencil) = &mut stencil else { continue };
                    let (lo, len) = (c.j0 * nx * row_len, (c.j1 - c.j0) * nx * row_len);
                    gpu.read_into(&b.out, &b.staging, len, &mut stencil[lo..lo + len])?;
                    t.bytes_down += gpu.real_bytes(len as u64);
                } else {
                    let (lo, len) = (c.j0 * nx * 2, (c.j1 - c.j0) * nx * 2);
                    gpu.read_into(&b.res, &b.staging, len, &mut res[lo..lo + len])?;
                    t.bytes_down += gpu.real_bytes(len as u64);
                }
            }
            t.readback += t1.elapsed().as_secs_f64();
        }
        Ok(())
    }

    fn check_lengths(disc: &Discretization, b: &BasisData, cps: &[Point]) -> Result<(), GpuError> {
        if cps.len() != b.n || disc.dofs.num_total() != b.n {
            return Err(GpuError::Wgpu(format!("{} control points for a basis of {}", cps.len(), b.n)));
        }
        Ok(())
    }

    /// The basis of `disc` with `cps` uploaded, counted as one call's quadrature.
    fn basis_with(&self, disc: &Discretization, cps: &[Point], t: &mut Timings) -> Result<Arc<BasisData>, GpuError> {
        let b = self.basis(disc, t)?;
        Self::check_lengths(disc, &b, cps)?;
        t.quadrature_points += b.qp_per_call;
        self.upload_cps(&b, cps, t)?;
        Ok(b)
    }

    /// The EGG kernels: the residual's when `res`, the Jacobian's when `mat` (the
    /// per-entry kernel, or element matrices and their gather).
    fn egg_kernels(&self, res: bool, mat: bool) -> Vec<(&wgpu::ComputePipeline, Out)> {
        let a = &self.gpu.assembly;
        let mut kernels = Vec::new();
        if res {
            kernels.push((&a.egg_residual, Out::Residual));
        }
        if mat && self.per_entry {
            kernels.push((&a.egg_stencil, Out::Stencil));
        } else if mat {
            kernels.push((&a.egg_element, Out::Element));
            kernels.push((&a.egg_gather, Out::Stencil));
        }
        kernels
    }

    /// EGG residual (full, interleaved, length `2 n`, or empty) and, when `stencil` is
    /// non-empty, the Jacobian in stencil storage: [`Discretization::egg`] on the GPU.
    /// In f32 the residual is computed by the CPU in f64.
    pub fn try_egg(
        &self,
        disc: &Discretization,
        cps: &[Point],
        op: Operator,
        res: &mut [f64],
        stencil: &mut [f64],
    ) -> Result<(), GpuError> {
        let want_mat = !stencil.is_empty();
        let mut want_res = !res.is_empty();
        let mut t = Timings { calls: 1, ..Default::default() };
        let op_code = op_code(op);
        if self.gpu.precision() == Precision::F32 && want_res {
            let t0 = Instant::now();
            disc.egg(cps, op, res, &mut []);
            t.cpu += t0.elapsed().as_secs_f64();
            want_res = false;
        }
        if want_res || want_mat {
            let _busy = self.busy.lock().map_err(|e| GpuError::Wgpu(e.to_string()))?;
            self.gpu.scoped(|| {
                let b = self.basis_with(disc, cps, &mut t)?;
                let kernels = self.egg_kernels(want_res, want_mat);
                self.run_chunks(&b, op_code, true, &kernels, 2, res, StencilTo::Host(stencil), &mut t)
            })?;
        }
        self.record(|s| if want_mat { s.egg_jacobian.add(&t) } else { s.egg_residual.add(&t) });
        Ok(())
    }

    /// Scalar mass matrix in stencil storage: [`Discretization::mass`] on the GPU.
    pub fn try_mass(&self, disc: &Discretization, stencil: &mut [f64]) -> Result<(), GpuError> {
        let mut t = Timings { calls: 1, ..Default::default() };
        let _busy = self.busy.lock().map_err(|e| GpuError::Wgpu(e.to_string()))?;
        self.gpu.scoped(|| {
            let b = self.basis(disc, &mut t)?;
            t.quadrature_points += b.qp_per_call;
            let k = [(&self.gpu.assembly.mass_stencil, Out::Stencil)];
            self.run_chunks(&b, 0, false, &k, 1, &mut [], StencilTo::Host(stencil), &mut t)
        })?;
        self.record(|s| s.mass.add(&t));
        Ok(())
    }

    /// Linear elasticity in stencil storage: [`Discretization::elasticity`] on the GPU.
    pub fn try_elasticity(
        &self,
        disc: &Discretization,
        cps: &[Point],
        lambda: f64,
        mu: f64,
        stencil: &mut [f64],
    ) -> Result<(), GpuError> {
        let mut t = Timings { calls: 1, ..Default::default() };
        let _busy = self.busy.lock().map_err(|e| GpuError::Wgpu(e.to_string()))?;
        self.gpu.scoped(|| {
            let b = self.basis(disc, &mut t)?;
            Self::check_lengths(disc, &b, cps)?;
            t.quadrature_points += b.qp_per_call;
            let lame = self.gpu.to_bytes(&[lambda, mu]);
            self.gpu.queue.write_buffer(&b.tab, self.gpu.real_bytes(b.params.lame as u64), &lame);
            self.upload_cps(&b, cps, &mut t)?;
            let k = [(&self.gpu.assembly.elasticity_stencil, Out::Stencil)];
            self.run_chunks(&b, 0, true, &k, 2, &mut [], StencilTo::Host(stencil), &mut t)
        })?;
        self.record(|s| s.elasticity.add(&t));
        Ok(())
    }

    /// `det J` on the `(n+1)^2` grid of [`winslow::verify::quality::sample_det_j`], on the GPU.
    pub fn try_sample_det_j(&self, map: &Surface, n: usize) -> Result<DetJSample, GpuError> {
        let t0 = Instant::now();
        let s = self.gpu.sample_map(map, n)?;
        self.record(|st| {
            st.det_j.calls += 1;
            st.det_j.dispatch += t0.elapsed().as_secs_f64();
        });
        Ok(DetJSample::from_values(s.n, s.det))
    }

    fn fallback(&self, what: &str, e: GpuError) {
        let msg = format!("{what}: {e}");
        eprintln!("warning: GPU {msg}; computing it on the CPU");
        self.record(|s| {
            s.fallbacks += 1;
            s.last_error = Some(msg);
        });
    }
}

/// The WGSL kernels tabulate polynomial B-splines; a rational basis
/// ([`Discretization::with_weights`], NURBS sides on the input basis) is assembled on the
/// CPU, whose kernels apply the quotient rule.
impl EggAssembler for GpuAssembler {
    fn egg(&self, disc: &Discretization, cps: &[Point], op: Operator, res: &mut [f64], stencil: &mut [f64]) {
        if disc.is_rational() {
            return CpuAssembler.egg(disc, cps, op, res, stencil);
        }
        if let Err(e) = self.try_egg(disc, cps, op, res, stencil) {
            self.fallback("EGG assembly", e);
            CpuAssembler.egg(disc, cps, op, res, stencil);
        }
    }

    fn mass(&self, disc: &Discretization, stencil: &mut [f64]) {
        if disc.is_rational() {
            return disc.mass(stencil);
        }
        if let Err(e) = self.try_mass(disc, stencil) {
            self.fallback("mass assembly", e);
            disc.mass(stencil);
        }
    }

    fn elasticity(&self, disc: &Discretization, cps: &[Point], lambda: f64, mu: f64, stencil: &mut [f64]) {
        if disc.is_rational() {
            return disc.elasticity(cps, lambda, mu, stencil);
        }
        if let Err(e) = self.try_elasticity(disc, cps, lambda, mu, stencil) {
            self.fallback("elasticity assembly", e);
            disc.elasticity(cps, lambda, mu, stencil);
        }
    }

    fn sample_det_j(&self, map: &Surface, n: usize) -> DetJSample {
        match self.try_sample_det_j(map, n) {
            Ok(s) => s,
            Err(e) => {
                self.fallback("det J sampling", e);
                winslow::verify::quality::sample_det_j(map, n)
            }
        }
    }

    fn name(&self) -> String {
        let s = self.stats();
        let mut name = self.gpu.describe();
        if s.fallbacks > 0 {
            name.push_str(&format!(" ({} calls fell back to the CPU)", s.fallbacks));
        }
        if s.multigrid.calls > 0 || s.multigrid_fallbacks > 0 {
            name.push_str(&format!("; multigrid V-cycles on the GPU: {}", s.multigrid.calls));
        }
        if s.multigrid_fallbacks > 0 {
            name.push_str(&format!(" ({} on the CPU after GPU errors)", s.multigrid_fallbacks));
        }
        if s.jacobian_products.calls > 0 || s.jacobian_product_fallbacks > 0 {
            name.push_str(&format!("; Jacobian products on the GPU: {}", s.jacobian_products.calls));
        }
        if s.jacobian_product_fallbacks > 0 {
            name.push_str(&format!(" ({} on the CPU after GPU errors)", s.jacobian_product_fallbacks));
        }
        name.push_str(&s.bus());
        name
    }

    /// The GPU runs the level work of `--linear multigrid`'s V-cycle ([`GpuCycles`]),
    /// where the adapter has `SHADER_F64`.
    fn cycle_backend(&self) -> Option<Arc<dyn CycleBackend>> {
        self.cycles.clone().map(|c| c as Arc<dyn CycleBackend>)
    }

    /// The GPU multiplies with the Newton Jacobian under `--linear multigrid`
    /// ([`GpuProducts`]), where the adapter has `SHADER_F64`.
    fn operator_backend(&self) -> Option<Arc<dyn OperatorBackend>> {
        self.products.clone().map(|p| p as Arc<dyn OperatorBackend>)
    }

    /// The Newton Jacobian assembled into the product's buffers, where the adapter has
    /// `SHADER_F64` ([`GpuAssembler::try_egg_operator`]); `None` on a rational basis
    /// (assembled on the CPU), with `--gpu-jacobian host`, and after a failure (counted
    /// as a fallback of the product).
    fn egg_operator(
        &self,
        disc: &Discretization,
        cps: &[Point],
        op: Operator,
        res: &mut [f64],
    ) -> Option<Box<dyn DeviceOperator>> {
        let products = self.products.as_ref()?;
        if disc.is_rational() || !self.device_jacobian() || self.gpu.precision() != Precision::F64 {
            return None;
        }
        match self.try_egg_operator(disc, cps, op, res) {
            Ok(p) => Some(Box::new(p)),
            Err(e) => {
                // the core assembles with `egg` and uploads instead
                let _ = products.shared().fallback("Jacobian assembly on the device", e);
                None
            }
        }
    }
}
