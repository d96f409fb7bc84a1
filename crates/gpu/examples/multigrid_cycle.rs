//! Seconds per multigrid V-cycle on the CPU and on the GPU (`winslow_gpu::GpuCycles`),
//! for the metric Laplacian of the stretched quarter annulus (`winslow::testutil::
//! multigrid_cycle`, degree 3) at the element counts given (default 64 and 128), and the
//! largest relative difference between the two cycles' results; then seconds per
//! product with the EGG Jacobian of the same map (eq. 12, its stencil storage in `f32`,
//! `2 m` unknowns) on the CPU (`winslow::discrete::PackedSystem`) and on the GPU
//! (`winslow_gpu::GpuProducts`), its upload, and their largest relative difference:
//!
//! ```sh
//! WGPU_BACKEND=vulkan cargo run -p winslow-gpu --example multigrid_cycle -- 64 128
//! ```
//!
//! Each cycle and product is applied `CYCLES` times after one warm-up; the GPU time is
//! wall time of `GpuCycle::try_apply` / `GpuProduct::try_apply` (upload of the input, the
//! dispatches, readback of the output). "max rel diff" compares with the solver's CPU
//! cycle (which takes each level's residual from its first sweep, summed in another
//! order: equal to rounding), "CPU levels" with the level operations on the CPU in the
//! GPU's order (`CpuLevels::cycle`: 0 where the adapter fuses no multiply-adds, as
//! lavapipe). A size that does not fit the adapter prints the reason in its row
//! (`too large`) and the others still run.

use std::sync::Arc;
use std::time::Instant;

use winslow::discrete::assembly::Operator;
use winslow::discrete::{PackedSystem, Stencil32};
use winslow::linalg::MatVec;
use winslow::testutil::{multigrid_cycle, stretched_map, Lcg};
use winslow_gpu::{Gpu, GpuCycles, GpuError, GpuOptions, GpuProducts, Precision};

const CYCLES: usize = 5;

/// `max |a - b| / max |a|`.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter().zip(b).fold(0.0f64, |m, (u, v)| m.max((u - v).abs())) / scale
}

/// Mean seconds of `CYCLES` calls of `f` after one warm-up.
fn seconds<E>(mut f: impl FnMut() -> Result<(), E>) -> Result<f64, E> {
    f()?;
    let t = Instant::now();
    for _ in 0..CYCLES {
        f()?;
    }
    Ok(t.elapsed().as_secs_f64() / CYCLES as f64)
}

/// Seconds per call on the CPU and on the GPU (each as [`seconds`]) of one operation on
/// the same random input of length `n` (from `seed`), with the input and both results.
#[allow(clippy::type_complexity)]
fn race(
    n: usize,
    seed: u64,
    mut cpu: impl FnMut(&[f64], &mut [f64]),
    mut gpu: impl FnMut(&[f64], &mut [f64]) -> Result<(), GpuError>,
) -> Result<(f64, f64, Vec<f64>, Vec<f64>, Vec<f64>), GpuError> {
    let mut rng = Lcg::new(seed);
    let input: Vec<f64> = (0..n).map(|_| rng.uniform() - 0.5).collect();
    let (mut on_cpu, mut on_gpu) = (vec![0.0; n], vec![0.0; n]);
    let cpu_s = seconds(|| {
        cpu(&input, &mut on_cpu);
        Ok::<(), GpuError>(())
    })?;
    let gpu_s = seconds(|| gpu(&input, &mut on_gpu))?;
    Ok((cpu_s, gpu_s, input, on_cpu, on_gpu))
}

/// One row of the cycle table.
fn cycle_row(backend: &GpuCycles, ne: usize) -> Result<String, Box<dyn std::error::Error>> {
    let cycle = multigrid_cycle(ne, 3.0, false)?;
    let h = cycle.hierarchy();
    let n = h.size(0);
    let t0 = Instant::now();
    let dev = match backend.try_upload(&h) {
        Ok(d) => d,
        Err(e @ GpuError::TooLarge(_)) => return Ok(format!("| {ne} | {n} | {} | too large: {e} |", h.num_levels())),
        Err(e) => return Err(e.into()),
    };
    let upload = t0.elapsed().as_secs_f64();
    let (cpu, gpu_s, b, xc, xg) = race(n, 1, |b, x| cycle.apply(b, x), |b, x| dev.try_apply(b, x))?;
    // the level operations on the CPU in the GPU's order (`CpuLevels`): the same bits
    // where the adapter fuses no multiply-adds
    let mut levels = cycle.cpu_levels();
    levels.b[0].copy_from_slice(&b);
    levels.cycle();
    Ok(format!(
        "| {ne} | {n} | {} | {} | {} | {cpu:.3e} | {gpu_s:.3e} | {upload:.3e} | {:.1e} | {:.1e} |",
        h.num_levels(),
        dev.dispatches(),
        dev.stencil_bindings(),
        rel_diff(&xc, &xg),
        rel_diff(&levels.x[0], &xg)
    ))
}

/// One row of the product table.
fn product_row(backend: &GpuProducts, ne: usize) -> Result<String, Box<dyn std::error::Error>> {
    let (disc, cps) = stretched_map(ne, 3.0);
    let mut st = vec![0.0; disc.stencil_len(2)];
    let mut res = vec![0.0; 2 * disc.dofs.num_total()];
    disc.egg(&cps, Operator::Scaled, &mut res, &mut st);
    let packed = Stencil32::pack(st);
    let sys = PackedSystem::new(&disc, 2, &packed).ok_or("no stencil product on this basis")?;
    let n = sys.size();
    let t0 = Instant::now();
    let dev = match backend.try_upload(&sys) {
        Ok(d) => d,
        Err(e @ GpuError::TooLarge(_)) => return Ok(format!("| {ne} | {n} | too large: {e} |")),
        Err(e) => return Err(e.into()),
    };
    let upload = t0.elapsed().as_secs_f64();
    let (cpu, gpu_s, _, yc, yg) = race(n, 2, |x, y| sys.mul_vec(x, y), |x, y| dev.try_apply(x, y))?;
    Ok(format!(
        "| {ne} | {n} | {:.0} | {} | {cpu:.3e} | {gpu_s:.3e} | {upload:.3e} | {:.1e} |",
        4.0 * packed.len() as f64 / 1e6,
        dev.stencil_bindings(),
        rel_diff(&yc, &yg)
    ))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let sizes: Vec<usize> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let sizes = if sizes.is_empty() { vec![64, 128] } else { sizes };
    let gpu = Arc::new(Gpu::new(&GpuOptions { precision: Some(Precision::F64), hardware_only: false })?);
    println!("{}", gpu.describe());
    let cycles = GpuCycles::new(gpu.clone()).ok_or("no f64 kernels")?;
    let products = GpuProducts::new(gpu.clone()).ok_or("no f64 kernels")?;
    println!();
    println!("V-cycle (metric Laplacian, degree 3)");
    println!();
    println!(
        "| elements | unknowns | levels | dispatches | stencil bindings | CPU s/cycle | GPU s/cycle | GPU upload s | max rel diff | max rel diff, CPU levels |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for &ne in &sizes {
        println!("{}", cycle_row(&cycles, ne)?);
    }
    println!();
    println!("Jacobian product (EGG, eq. 12, f32 stencil storage)");
    println!();
    println!(
        "| elements | unknowns | stencil MB | stencil bindings | CPU s/product | GPU s/product | GPU upload s | max rel diff |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    for &ne in &sizes {
        println!("{}", product_row(&products, ne)?);
    }
    Ok(())
}
