//! Criterion benchmarks of the Winslow improvement stage (paper eq. 16, `--improve
//! winslow`) on shared geometries whose stage is short: the EGG solve it follows (`solve`,
//! at the default settings, as `winslow solve FILE`: fit, levels, certificate, report),
//! the whole stage from the certified EGG map (`improve`), and its passes, the Hessian
//! assembly (`winslow_gradient_with`) and the one-pass value and gradient
//! (`winslow_value_and_gradient`). On these 1-3 ms solves one process run times stage
//! and solve to about 10 %; warm and repeated, their ratio is resolved. Run with `cargo
//! bench --workspace --bench improve`.

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use winslow::discrete::assembly::Discretization;
use winslow::discrete::dofs::DofMap;
use winslow::methods::winslow::{winslow_gradient_with, winslow_value_and_gradient, WinslowMethod};
use winslow::solve::improve::improve;
use winslow::solve::newton::NonlinearOptions;
use winslow::solve::options::SolveOptions;
use winslow::verify::certificate::certify;
use winslow::{read_boundary, solve, ReadOptions, Topology};

const GEOMETRIES: [&str; 5] = ["gismo/cooks_membrane", "gismo/disk", "gismo/duck", "gismo/flapping_beam", "wavy_lid"];

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("winslow-stage");
    g.sample_size(20);
    let opts = SolveOptions::default();
    for name in GEOMETRIES {
        let path = winslow::testutil::data(&format!("{name}.json"));
        let boundary = read_boundary(&path, &ReadOptions::default()).expect("a shared geometry");
        let label = name.rsplit('/').next().unwrap_or(name);
        g.bench_with_input(BenchmarkId::new("egg-solve", label), &(), |b, _| {
            b.iter(|| solve(&boundary, &opts).expect("the EGG solve"))
        });
        let sol = solve(&boundary, &opts).expect("the EGG solve");
        let map = sol.map;
        let cert = certify(&map, &opts.certify).expect("the certificate");
        let diameter = sol.report.fit.diameter;
        let top = Topology::dirichlet();
        g.bench_with_input(BenchmarkId::new("stage", label), &(), |b, _| {
            b.iter(|| {
                improve(&map, &cert, &WinslowMethod, &top, NonlinearOptions::default(), &opts.certify, diameter)
                    .expect("the stage")
            })
        });
        // the stage's quadrature: (p + 2) points per direction
        let [p, q] = map.degrees();
        let dofs = DofMap::for_basis(&map.knots, &top).expect("the DOF map");
        let disc = Arc::new(
            Discretization::with_dofs(map.knots.clone(), p.max(q) + 2, dofs)
                .with_weights(map.weights.clone())
                .expect("the weights"),
        );
        let mut res = vec![0.0; 2 * map.control_points.len()];
        let mut st = vec![0.0; disc.stencil_len(2)];
        g.bench_with_input(BenchmarkId::new("hessian", label), &(), |b, _| {
            b.iter(|| winslow_gradient_with(&disc, &map.control_points, &mut res, &mut st, 0.0))
        });
        g.bench_with_input(BenchmarkId::new("value+gradient", label), &(), |b, _| {
            b.iter(|| winslow_value_and_gradient(&disc, &map.control_points, &mut res))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
