//! Criterion benchmark of the bijectivity certificate against the residual + exact
//! Jacobian assembly on the same map (a lower bound of one Newton iteration, which adds a
//! linear solve and line-search residuals): quarter annuli of 128² and 320² (10⁵)
//! elements, p = 3. Run with `cargo bench --workspace --bench certificate`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use winslow::discrete::assembly::{Discretization, Operator};
use winslow::verify::certificate::{certify, CertifyOptions};
use winslow::{KnotVector, Surface};

fn annulus(ne: usize) -> Surface {
    let k = KnotVector::open_uniform(3, ne);
    let g = k.greville();
    let cps = g
        .iter()
        // xi radial, eta angular: det J > 0 (the angular-first order folds everywhere)
        .flat_map(|&v| g.iter().map(move |&u| [(1.0 + u) * (1.5 * v).cos(), (1.0 + u) * (1.5 * v).sin()]))
        .collect();
    Surface::new([k.clone(), k], cps, None).expect("valid map")
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("certificate");
    g.sample_size(10);
    for ne in [128, 320] {
        let map = annulus(ne);
        let opts = CertifyOptions::default();
        assert_eq!(certify(&map, &opts).unwrap().verdict.name(), "certified");
        g.bench_with_input(BenchmarkId::new("certify", ne), &ne, |b, _| b.iter(|| certify(&map, &opts).unwrap()));
        let disc = Discretization::new(map.knots.clone());
        let mut res = vec![0.0; 2 * disc.dofs.num_total()];
        let mut st = vec![0.0; disc.stencil_len(2)];
        g.bench_with_input(BenchmarkId::new("residual+jacobian", ne), &ne, |b, _| {
            b.iter(|| disc.egg(&map.control_points, Operator::Plain, &mut res, &mut st))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
