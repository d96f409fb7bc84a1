//! The map and `det J` on a grid (`shaders/det_j.wgsl`): the samples of
//! [`winslow::verify::quality::sample_det_j`] and [`winslow::io::picture::render`], for pictures,
//! the solver's positivity checks and the viewer.

use winslow::io::picture::{render_resolution, render_sampled, Image, PictureOptions};
use winslow::spline::basis::BasisDerivs;
use winslow::spline::curve::Point;
use winslow::spline::surface::Surface;
use winslow::verify::quality::{grid_abscissae, DetJSample};

use crate::device::Gpu;
use crate::GpuError;

/// Points and `det J` on the `(n+1)^2` grid `(i/n, j/n)`, row-major with `eta` outer.
#[derive(Debug, Clone)]
pub struct MapSample {
    /// Cells per direction.
    pub n: usize,
    /// `x(i/n, j/n)` at `j * (n + 1) + i`.
    pub points: Vec<Point>,
    /// `det J` at the same places.
    pub det: Vec<f64>,
}

/// The uniform block of `det_j.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    p: u32,
    q: u32,
    m: u32,
    nx: u32,
    rational: u32,
    tab_y: u32,
    pad0: u32,
    pad1: u32,
}

impl Gpu {
    /// Sample the map `map` on the `(n+1)^2` grid (`n >= 1`): the tensor sums on the GPU
    /// from univariate values tabulated by the core's [`BasisDerivs`] at the abscissae.
    pub fn sample_map(&self, map: &Surface, n: usize) -> Result<MapSample, GpuError> {
        let n = n.max(1);
        let m = n + 1;
        let [p, q] = map.degrees();
        let [nx, ny] = map.shape();
        if map.control_points.len() != nx * ny {
            return Err(GpuError::Wgpu(format!("{} control points for a {nx}x{ny} basis", map.control_points.len())));
        }
        let mut tab = Vec::with_capacity(2 * m * (p + q + 2));
        let mut first: Vec<u32> = Vec::with_capacity(2 * m);
        let mut b = BasisDerivs::default();
        for (dir, deg) in [(0, p), (1, q)] {
            for t in grid_abscissae(n) {
                b.eval(&map.knots[dir], t, 1);
                first.push(b.first() as u32);
                tab.extend_from_slice(&b.d[0][..=deg]);
                tab.extend_from_slice(&b.d[1][..=deg]);
            }
        }
        let cps: Vec<f64> = map
            .control_points
            .iter()
            .enumerate()
            .flat_map(|(k, c)| [c[0], c[1], map.weights.as_ref().map_or(1.0, |w| w[k])])
            .collect();
        let total = (m * m) as u64;
        if self.real_bytes(3 * total) > self.limits.max_storage_buffer_binding_size.min(self.limits.max_buffer_size) {
            return Err(GpuError::TooLarge(format!("a {m}x{m} sample grid")));
        }
        let params = Params {
            p: p as u32,
            q: q as u32,
            m: u32::try_from(m).map_err(|_| GpuError::TooLarge(format!("grid of {m} points")))?,
            nx: nx as u32,
            rational: map.weights.is_some() as u32,
            tab_y: (m * 2 * (p + 1)) as u32,
            ..Default::default()
        };
        let out = self.scoped(|| {
            let ubuf = self.uniform("det_j params", bytemuck::bytes_of(&params));
            let tbuf = self.storage_real("det_j tables", &tab)?;
            let fbuf = self.storage_init("det_j first", bytemuck::cast_slice(&first))?;
            let cbuf = self.storage_real("det_j control points", &cps)?;
            let obuf = self.storage_empty("det_j out", 3 * total);
            let staging = self.staging(self.real_bytes(3 * total));
            let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("det_j"),
                layout: &self.det_j.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: ubuf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: tbuf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: fbuf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: cbuf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: obuf.as_entire_binding() },
                ],
            });
            let mut enc = self.device.create_command_encoder(&Default::default());
            self.dispatch(&mut enc, &self.det_j.sample, &bind, total)?;
            self.submit_wait(Some(enc.finish()))?;
            let mut out = vec![0.0; 3 * total as usize];
            self.read_into(&obuf, &staging, out.len(), &mut out)?;
            Ok(out)
        })?;
        let points = out.chunks_exact(3).map(|c| [c[0], c[1]]).collect();
        let det = out.chunks_exact(3).map(|c| c[2]).collect();
        Ok(MapSample { n, points, det })
    }

    /// [`winslow::verify::quality::sample_det_j`] on the GPU.
    pub fn sample_det_j(&self, map: &Surface, n: usize) -> Result<DetJSample, GpuError> {
        let s = self.sample_map(map, n)?;
        Ok(DetJSample::from_values(s.n, s.det))
    }

    /// [`winslow::io::picture::render`] with the sampling on the GPU.
    pub fn render(&self, map: &Surface, opts: &PictureOptions) -> Result<Image, GpuError> {
        let s = self.sample_map(map, render_resolution(opts))?;
        Ok(render_sampled(s.n, &s.points, &s.det, opts))
    }
}
