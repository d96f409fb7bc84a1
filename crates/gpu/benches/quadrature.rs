//! Criterion benchmarks of the quadrature, CPU versus GPU: the EGG residual and the
//! residual with its exact Jacobian (stencil storage), at 10^3 to 10^5 scalar DOFs
//! (throughput in quadrature points). Run with
//! `WGPU_BACKEND=vulkan cargo bench --workspace --bench quadrature`; without an adapter
//! only the CPU rows run (a note says so). `winslow bench --backend gpu` gives the
//! split upload / dispatch / readback / scatter and the 10^6 size.

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use winslow::discrete::assembly::Operator;
use winslow_gpu::bench::quadrature_case;
use winslow_gpu::{Gpu, GpuAssembler, GpuOptions};

fn bench(c: &mut Criterion) {
    let gpu = match Gpu::new(&GpuOptions::default()) {
        Ok(g) => {
            eprintln!("GPU: {}", g.describe());
            Some(GpuAssembler::new(Arc::new(g)))
        }
        Err(e) => {
            eprintln!("note: no GPU, CPU rows only: {e}");
            None
        }
    };
    let mut g = c.benchmark_group("quadrature");
    g.sample_size(10);
    for dofs in [1_000, 10_000, 100_000] {
        let (disc, cps) = quadrature_case(dofs, 3);
        let qp = disc.num_elements() * disc.tables[0].nq * disc.tables[1].nq;
        g.throughput(Throughput::Elements(qp as u64));
        let mut res = vec![0.0; 2 * disc.dofs.num_total()];
        let mut st = vec![0.0; disc.stencil_len(2)];
        let op = Operator::Scaled;
        g.bench_with_input(BenchmarkId::new("cpu-residual", dofs), &dofs, |b, _| {
            b.iter(|| disc.egg(&cps, op, &mut res, &mut []))
        });
        g.bench_with_input(BenchmarkId::new("cpu-jacobian", dofs), &dofs, |b, _| {
            b.iter(|| disc.egg(&cps, op, &mut res, &mut st))
        });
        if let Some(a) = &gpu {
            g.bench_with_input(BenchmarkId::new("gpu-residual", dofs), &dofs, |b, _| {
                b.iter(|| a.try_egg(&disc, &cps, op, &mut res, &mut []).expect("GPU residual"))
            });
            g.bench_with_input(BenchmarkId::new("gpu-jacobian", dofs), &dofs, |b, _| {
                b.iter(|| a.try_egg(&disc, &cps, op, &mut res, &mut st).expect("GPU Jacobian"))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
