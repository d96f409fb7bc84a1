//! The multigrid cycle's GPU kernels (`shaders/multigrid.wgsl`) against the CPU code of
//! the same operations (`winslow::linalg::multigrid_kernels::CpuLevels`) on random
//! vectors, and one whole V-cycle, on the solver's own hierarchy (the metric Laplacian
//! of a stretched quarter annulus: stencil levels) and on one whose levels are CSR
//! matrices (a coupling outside the stencils). With `WINSLOW_REQUIRE_GPU=1` (CI) a
//! missing adapter fails the tests; otherwise they print a note and return.
//!
//! Tolerance: `1e-12` of the largest magnitude of the compared vector. The kernels do
//! the CPU's `f64` operations in the CPU's order, so they differ only where the GPU's
//! compiler fuses a multiply and an add (one rounding fewer per term, at most `2^-53`
//! of the term); the line and coarsest solves carry such differences through
//! triangular solves of condition below `1e2` here. On lavapipe the results are the
//! CPU's bits (asserted separately where the adapter is a software one).

use std::sync::{Arc, OnceLock};

use winslow::linalg::multigrid_kernels::{CpuLevels, Cycle};
use winslow::testutil::{multigrid_cycle, Lcg};
use winslow_gpu::{gpu_required, Gpu, GpuCycles, GpuOptions, Operation, Precision, Vector};

fn gpu() -> Option<Arc<Gpu>> {
    static GPU: OnceLock<Option<Arc<Gpu>>> = OnceLock::new();
    GPU.get_or_init(|| match Gpu::new(&GpuOptions { precision: Some(Precision::F64), hardware_only: false }) {
        Ok(g) => {
            eprintln!("using {}", g.describe());
            Some(Arc::new(g))
        }
        Err(e) if gpu_required() => panic!("WINSLOW_REQUIRE_GPU=1 but no GPU with f64: {e}"),
        Err(e) => {
            eprintln!("note: skipping the GPU multigrid test: {e}");
            None
        }
    })
    .clone()
}

/// `max |a - b| / max(|a|, |b|)` over the entries, and whether the bits are equal.
fn compare(a: &[f64], b: &[f64]) -> (f64, bool) {
    assert_eq!(a.len(), b.len());
    let scale = a.iter().chain(b).fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
    let diff = a.iter().zip(b).fold(0.0f64, |m, (u, v)| m.max((u - v).abs()));
    (diff / scale, a.iter().zip(b).all(|(u, v)| u == v))
}

fn random(n: usize, rng: &mut Lcg) -> Vec<f64> {
    (0..n).map(|_| rng.uniform() - 0.5).collect()
}

/// Set every level's vectors to the same random values on both sides.
fn randomize(cpu: &mut CpuLevels<'_>, dev: &winslow_gpu::GpuCycle, rng: &mut Lcg) {
    for l in 0..cpu.b.len() {
        let (b, x) = (random(cpu.b[l].len(), rng), random(cpu.x[l].len(), rng));
        dev.write(Vector::B, l, &b).unwrap();
        dev.write(Vector::X, l, &x).unwrap();
        (cpu.b[l], cpu.x[l]) = (b, x);
        if l < cpu.r.len() {
            let r = random(cpu.r[l].len(), rng);
            dev.write(Vector::R, l, &r).unwrap();
            cpu.r[l] = r;
        }
    }
}

/// Every operation of every level on random vectors: the GPU's result equals the CPU's
/// (module documentation); returns whether all were bit-identical.
fn kernels_agree(cycle: &Cycle, g: &Arc<Gpu>) -> bool {
    let h = cycle.hierarchy();
    let dev = GpuCycles::new(g.clone()).expect("f64 kernels").try_upload(&h).expect("upload");
    let mut cpu = cycle.cpu_levels();
    let mut rng = Lcg::new(17);
    let smoothed = h.levels.len();
    let mut ops = vec![Operation::CoarseSolve];
    for l in 0..smoothed {
        for dir in [0, 1] {
            ops.extend([Operation::Smooth(l, dir, false), Operation::Smooth(l, dir, true)]);
        }
        ops.extend([Operation::Residual(l), Operation::Restrict(l), Operation::ProlongAdd(l)]);
    }
    let mut bits = true;
    for op in ops {
        randomize(&mut cpu, &dev, &mut rng);
        use winslow::linalg::multigrid_kernels::LevelKernels;
        // the vectors each operation writes
        let written: Vec<(Vector, usize)> = match op {
            Operation::Smooth(l, dir, backward) => {
                cpu.smooth(l, dir, backward);
                vec![(Vector::X, l)]
            }
            Operation::Residual(l) => {
                cpu.residual(l);
                vec![(Vector::R, l)]
            }
            Operation::Restrict(l) => {
                cpu.restrict(l);
                vec![(Vector::B, l + 1), (Vector::X, l + 1)]
            }
            Operation::ProlongAdd(l) => {
                cpu.prolong_add(l);
                vec![(Vector::X, l)]
            }
            Operation::CoarseSolve => {
                cpu.coarse_solve();
                vec![(Vector::X, smoothed)]
            }
        };
        dev.run(op).expect("kernel");
        for (v, l) in written {
            let want = match v {
                Vector::B => &cpu.b[l],
                Vector::X => &cpu.x[l],
                Vector::R => &cpu.r[l],
            };
            let (rel, same) = compare(&dev.read(v, l).unwrap(), want);
            assert!(rel <= 1e-12, "{op:?}, {v:?} of level {l}: relative difference {rel:e}");
            bits &= same;
        }
    }
    bits
}

/// Each kernel against the CPU on random data: the solver's hierarchy (stencil levels)
/// at three sizes (coarsest levels of 121 to 289 unknowns), on the narrow gap and the
/// mild map, and one with CSR levels.
#[test]
fn each_kernel_equals_the_cpu() {
    let Some(g) = gpu() else { return };
    for (ne, far, t) in [(32, false, 0.03), (24, false, 3.0), (40, false, 3.0), (24, true, 3.0)] {
        let cycle = multigrid_cycle(ne, t, far).unwrap();
        let bits = kernels_agree(&cycle, &g);
        eprintln!("{ne} elements, far coupling {far}: bit-identical {bits}");
        if g.is_software() {
            assert!(bits, "{ne} elements: lavapipe should give the CPU's bits");
        }
    }
}

/// One V-cycle on the GPU (uploaded once, only `b` up and `x` down) equals the CPU's
/// cycle, twice in a row (the device's vectors from the first cycle do not leak into
/// the second), on the narrow gap (`t = 0.03`).
#[test]
fn one_v_cycle_equals_the_cpu_cycle() {
    let Some(g) = gpu() else { return };
    for far in [false, true] {
        let cycle = multigrid_cycle(32, 0.03, far).unwrap();
        let h = cycle.hierarchy();
        let dev = GpuCycles::new(g.clone()).unwrap().try_upload(&h).unwrap();
        assert!(dev.dispatches() > 10);
        let mut rng = Lcg::new(5);
        for _ in 0..2 {
            let b = random(h.size(0), &mut rng);
            let mut got = vec![1.0; b.len()];
            dev.try_apply(&b, &mut got).unwrap();
            // the CPU's level operations in the cycle's order (`v_cycle`)
            let mut cpu = cycle.cpu_levels();
            cpu.b[0].copy_from_slice(&b);
            cpu.cycle();
            let (rel, same) = compare(&got, &cpu.x[0]);
            assert!(rel <= 1e-12, "far {far}: relative difference {rel:e}");
            if g.is_software() {
                assert!(same, "far {far}: lavapipe should give the CPU's bits");
            }
            // the solver's own cycle takes each residual from its first sweep (summed in
            // another order): the same to rounding carried on by the coarse corrections
            let mut want = vec![0.0; b.len()];
            cycle.apply(&b, &mut want);
            let (rel, _) = compare(&got, &want);
            assert!(rel <= 1e-7, "far {far}: relative difference to the solver's cycle {rel:e}");
        }
    }
}
