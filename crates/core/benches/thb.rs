//! Criterion benchmark of THB refinement (issue 35: G+Smo's tracker reports about 100 s to
//! refine one cell at level 10): a cubic 8 x 8 map refined ten times towards the point
//! (0.3, 0.7) (admissibility class 2), then one active cell of level 10 refined: the basis
//! alone ([`HierarchicalBasis::refine`]) and the map with its exact new coefficients
//! ([`HierarchicalMap::refined`]). Run with
//! `cargo bench -p winslow --bench thb --profile dev` (the dev profile optimises winslow
//! with opt-level 3).

use criterion::{criterion_group, criterion_main, Criterion};
use winslow::spline::hierarchical::map::HierarchicalMap;
use winslow::{KnotVector, Surface};

fn map_at_level_10() -> HierarchicalMap {
    let k = KnotVector::open_uniform(3, 8);
    let g = k.greville();
    let cps = g.iter().flat_map(|&v| g.iter().map(move |&u| [u + 0.1 * v * v, v - 0.05 * u * u])).collect();
    let s = Surface::new([k.clone(), k], cps, None).expect("valid map");
    let mut map = HierarchicalMap::from_surface(&s).expect("polynomial map");
    for _ in 0..10 {
        let (l, c) = map.basis.cell_at(0.3, 0.7);
        map = map.refined(&[(l, c)], 2).expect("refinable");
    }
    assert_eq!(map.basis.cell_at(0.3, 0.7).0, 10);
    map
}

fn bench(c: &mut Criterion) {
    let map = map_at_level_10();
    let cell = map.basis.cell_at(0.3, 0.7);
    eprintln!(
        "THB map: {} functions, {} active cells, {} levels; refining cell {:?}",
        map.basis.len(),
        map.basis.active_cells().len(),
        map.basis.num_levels(),
        cell
    );
    let mut g = c.benchmark_group("thb");
    g.sample_size(20);
    g.bench_function("refine one level-10 cell (basis)", |b| {
        b.iter(|| {
            let mut basis = map.basis.clone();
            basis.refine(&[cell], 2).expect("refinable");
            basis.len()
        })
    });
    g.bench_function("refine one level-10 cell (map, exact coefficients)", |b| {
        b.iter(|| map.refined(&[cell], 2).expect("refinable").basis.len())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
