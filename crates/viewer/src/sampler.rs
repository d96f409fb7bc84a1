//! Where the heat map's numbers come from: one small trait, so that the core's CPU
//! sampler can be swapped for another back end (the GPU crate) without touching the
//! viewer. The viewer never computes `det J` samples itself.

use winslow::verify::quality::DetJSample;
use winslow::Surface;

/// Samples `det J = x_xi y_eta - x_eta y_xi` (paper eq. 43) of a map on the uniform
/// `(n+1) x (n+1)` grid of the parameter square, in the layout of
/// [`winslow::verify::quality::sample_det_j`] (`eta` outer, boundary included).
pub trait DetJSampler: Send + Sync {
    /// Short name shown in the viewer ("cpu", "gpu", ...).
    fn name(&self) -> &str;
    /// The sample; `n >= 1`.
    fn sample(&self, map: &Surface, n: usize) -> DetJSample;
}

/// The core's sampler, [`winslow::verify::quality::sample_det_j`].
#[derive(Debug, Clone, Copy, Default)]
pub struct CpuSampler;

impl DetJSampler for CpuSampler {
    fn name(&self) -> &str {
        "cpu"
    }

    fn sample(&self, map: &Surface, n: usize) -> DetJSample {
        winslow::verify::quality::sample_det_j(map, n)
    }
}

/// The GPU crate's sampler ([`winslow_gpu::Gpu::sample_det_j`], the WGSL kernel of
/// `shaders/det_j.wgsl`); a failing GPU call falls back to the core's sampler and says so
/// in its name.
#[derive(Debug)]
pub struct GpuSampler {
    gpu: std::sync::Arc<winslow_gpu::Gpu>,
    name: String,
}

impl GpuSampler {
    /// A sampler on an opened GPU.
    pub fn new(gpu: std::sync::Arc<winslow_gpu::Gpu>) -> Self {
        let name = format!("gpu: {}", gpu.describe());
        Self { gpu, name }
    }
}

impl DetJSampler for GpuSampler {
    fn name(&self) -> &str {
        &self.name
    }

    fn sample(&self, map: &Surface, n: usize) -> DetJSample {
        match self.gpu.sample_det_j(map, n) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("warning: GPU det J sampling failed ({e}); sampled on the CPU instead");
                winslow::verify::quality::sample_det_j(map, n)
            }
        }
    }
}

/// The sampler for a back end: `cpu`, `gpu` (any adapter; none is an error) or `auto`
/// (a hardware GPU with f64 shaders, else the CPU), as in the CLI's `--backend`.
pub fn sampler_for(backend: winslow_gpu::Backend) -> Result<std::sync::Arc<dyn DetJSampler>, winslow_gpu::GpuError> {
    Ok(match winslow_gpu::assembler(backend, None)?.gpu() {
        Some(gpu) => std::sync::Arc::new(GpuSampler::new(gpu.clone())),
        None => std::sync::Arc::new(CpuSampler),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use winslow::KnotVector;

    /// A curved cubic map (a perturbed annulus sector).
    fn map() -> Surface {
        let k = KnotVector::open_uniform(3, 4);
        let g = k.greville();
        let cps = g
            .iter()
            .flat_map(|&v| {
                g.iter().map(move |&u| [(1.0 + v) * (1.2 * u).cos() + 0.05 * u * v, (1.0 + v) * (1.2 * u).sin()])
            })
            .collect();
        Surface::new([k.clone(), k], cps, None).unwrap()
    }

    /// The GPU sampler gives the core's samples (f64 kernels); runs where an adapter is
    /// found and fails where `WINSLOW_REQUIRE_GPU=1` demands one (CI, on lavapipe).
    #[test]
    fn gpu_sampler_matches_the_core() {
        let s = match sampler_for(winslow_gpu::Backend::Gpu) {
            Ok(s) => s,
            Err(e) if !winslow_gpu::gpu_required() => return eprintln!("note: skipped, no GPU: {e}"),
            Err(e) => panic!("WINSLOW_REQUIRE_GPU=1 but no GPU: {e}"),
        };
        assert!(s.name().starts_with("gpu"), "{}", s.name());
        let m = map();
        let (a, b) = (s.sample(&m, 40), CpuSampler.sample(&m, 40));
        let scale = b.max.abs();
        for (x, y) in a.values.iter().zip(&b.values) {
            assert!((x - y).abs() <= 1e-12 * scale, "{x} vs {y}");
        }
        assert_eq!(a.argmin, b.argmin);
    }
}
