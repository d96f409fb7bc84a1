//! Criterion benchmarks of the EGG assembly (residual, residual + exact Jacobian) and of
//! one Newton iteration (assembly + sparse LU), on a quarter annulus at several sizes.
//! Run with `cargo bench --workspace --bench assembly`.

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use winslow::discrete::assembly::{Discretization, Operator};
use winslow::linalg::linsolve::{LinearMethod, LinearSolver};
use winslow::methods::egg::{CpuAssembler, EggProblem};
use winslow::methods::DiscreteProblem;
use winslow::KnotVector;

fn annulus(ne: usize) -> (Arc<Discretization>, Vec<[f64; 2]>) {
    let k = KnotVector::open_uniform(3, ne);
    let g = k.greville();
    let cps = g
        .iter()
        .flat_map(|&v| g.iter().map(move |&u| [(1.0 + v) * (1.5 * u).cos(), (1.0 + v) * (1.5 * u).sin()]))
        .collect();
    (Arc::new(Discretization::new([k.clone(), k])), cps)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("egg");
    g.sample_size(10);
    for ne in [16, 64, 128] {
        let (disc, cps) = annulus(ne);
        let qp = disc.num_elements() * disc.tables[0].nq * disc.tables[1].nq;
        g.throughput(Throughput::Elements(qp as u64));
        let mut res = vec![0.0; 2 * disc.dofs.num_total()];
        let mut st = vec![0.0; disc.stencil_len(2)];
        g.bench_with_input(BenchmarkId::new("residual", ne), &ne, |b, _| {
            b.iter(|| disc.egg(&cps, Operator::Plain, &mut res, &mut []))
        });
        g.bench_with_input(BenchmarkId::new("residual+jacobian", ne), &ne, |b, _| {
            b.iter(|| disc.egg(&cps, Operator::Plain, &mut res, &mut st))
        });
        if ne <= 64 {
            let mut prob = EggProblem::new(disc.clone(), cps.clone(), Operator::Plain, Arc::new(CpuAssembler));
            let c0 = prob.unknowns();
            let mut f = vec![0.0; c0.len()];
            let mut lin = LinearSolver::new(LinearMethod::Lu);
            let mut j = winslow::linalg::sparse::Csr::default();
            g.bench_with_input(BenchmarkId::new("newton-iteration-lu", ne), &ne, |b, _| {
                b.iter(|| {
                    prob.jacobian(&c0, &mut f, &mut j);
                    lin.factor(&j).unwrap();
                    lin.solve(&f).unwrap()
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
