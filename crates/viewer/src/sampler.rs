//! Where the heat map's numbers come from: one small trait, so that the core's CPU
//! sampler can be swapped for another back end (the GPU crate) without touching the
//! viewer. The viewer never computes `det J` samples itself.

use winslow::quality::DetJSample;
use winslow::Surface;

/// Samples `det J = x_xi y_eta - x_eta y_xi` (paper eq. 43) of a map on the uniform
/// `(n+1) x (n+1)` grid of the parameter square, in the layout of
/// [`winslow::quality::sample_det_j`] (`eta` outer, boundary included).
pub trait DetJSampler: Send + Sync {
    /// Short name shown in the viewer ("cpu", "gpu", ...).
    fn name(&self) -> &str;
    /// The sample; `n >= 1`.
    fn sample(&self, map: &Surface, n: usize) -> DetJSample;
}

/// The core's sampler, [`winslow::quality::sample_det_j`].
#[derive(Debug, Clone, Copy, Default)]
pub struct CpuSampler;

impl DetJSampler for CpuSampler {
    fn name(&self) -> &str {
        "cpu"
    }

    fn sample(&self, map: &Surface, n: usize) -> DetJSample {
        winslow::quality::sample_det_j(map, n)
    }
}
