//! Seconds per multigrid V-cycle on the CPU and on the GPU (`winslow_gpu::GpuCycles`),
//! for the metric Laplacian of the stretched quarter annulus (`winslow::testutil::
//! multigrid_cycle`, degree 3) at the element counts given (default 64 and 128), and the
//! largest relative difference between the two cycles' results:
//!
//! ```sh
//! WGPU_BACKEND=vulkan cargo run -p winslow-gpu --example multigrid_cycle -- 64 128
//! ```
//!
//! Each cycle is applied `CYCLES` times after one warm-up; the GPU time is wall time of
//! `GpuCycle::try_apply` (upload of `b`, the dispatches, readback of `x`).

use std::sync::Arc;
use std::time::Instant;

use winslow::testutil::{multigrid_cycle, Lcg};
use winslow_gpu::{Gpu, GpuCycles, GpuOptions, Precision};

const CYCLES: usize = 5;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let sizes: Vec<usize> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let sizes = if sizes.is_empty() { vec![64, 128] } else { sizes };
    let gpu = Arc::new(Gpu::new(&GpuOptions { precision: Some(Precision::F64), hardware_only: false })?);
    println!("{}", gpu.describe());
    println!("| elements | unknowns | levels | dispatches | CPU s/cycle | GPU s/cycle | GPU upload s | max rel diff |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    let backend = GpuCycles::new(gpu.clone()).ok_or("no f64 kernels")?;
    for ne in sizes {
        let cycle = multigrid_cycle(ne, 3.0, false)?;
        let h = cycle.hierarchy();
        let t0 = Instant::now();
        let dev = backend.try_upload(&h)?;
        let upload = t0.elapsed().as_secs_f64();
        let mut rng = Lcg::new(1);
        let b: Vec<f64> = (0..h.size(0)).map(|_| rng.uniform() - 0.5).collect();
        let (mut xc, mut xg) = (vec![0.0; b.len()], vec![0.0; b.len()]);
        cycle.apply(&b, &mut xc);
        dev.try_apply(&b, &mut xg)?;
        let t = Instant::now();
        for _ in 0..CYCLES {
            cycle.apply(&b, &mut xc);
        }
        let cpu = t.elapsed().as_secs_f64() / CYCLES as f64;
        let t = Instant::now();
        for _ in 0..CYCLES {
            dev.try_apply(&b, &mut xg)?;
        }
        let gpu_s = t.elapsed().as_secs_f64() / CYCLES as f64;
        let scale = xc.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = xc.iter().zip(&xg).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        println!(
            "| {ne} | {} | {} | {} | {cpu:.3e} | {gpu_s:.3e} | {upload:.3e} | {:.1e} |",
            h.size(0),
            h.num_levels(),
            dev.dispatches(),
            diff / scale
        );
    }
    Ok(())
}
