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

use winslow::discrete::assembly::{Discretization, Operator};
use winslow::discrete::{PackedSystem, Stencil32};
use winslow::linalg::multigrid_kernels::{CpuLevels, Cycle};
use winslow::linalg::MatVec;
use winslow::spline::knots::KnotVector;
use winslow::testutil::{multigrid_cycle, Lcg};
use winslow_gpu::{gpu_required, Gpu, GpuAssembler, GpuCycles, GpuOptions, GpuProducts, Operation, Precision, Vector};

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

/// One V-cycle of `b` on the device (from a result buffer of ones: it must be
/// overwritten) against the CPU's level operations in the cycle's order (`v_cycle`): the
/// GPU's result, the relative difference and whether the bits are equal.
fn gpu_against_cpu_levels(cycle: &Cycle, dev: &winslow_gpu::GpuCycle, b: &[f64]) -> (Vec<f64>, f64, bool) {
    let mut got = vec![1.0; b.len()];
    dev.try_apply(b, &mut got).unwrap();
    let mut cpu = cycle.cpu_levels();
    cpu.b[0].copy_from_slice(b);
    cpu.cycle();
    let (rel, same) = compare(&got, &cpu.x[0]);
    (got, rel, same)
}

/// Every operation of every level on random vectors: the GPU's result equals the CPU's
/// (module documentation); returns whether all were bit-identical.
fn kernels_agree(cycle: &Cycle, backend: &GpuCycles) -> bool {
    let h = cycle.hierarchy();
    let dev = backend.try_upload(&h).expect("upload");
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
        let bits = kernels_agree(&cycle, &GpuCycles::new(g.clone()).expect("f64 kernels"));
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
            let (got, rel, same) = gpu_against_cpu_levels(&cycle, &dev, &b);
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

/// The levels' stencil values split over all four bindings (chunks of 2^14 entries: 64 KiB
/// instead of the adapter's limit) give the CPU's results, kernel by kernel and for a
/// whole V-cycle: the split that lets the finest stencil of 10^6 unknowns (262 MB) up
/// on lavapipe (128 MiB per binding), tested at a size CI runs.
#[test]
fn stencil_split_over_bindings_equals_the_cpu() {
    let Some(g) = gpu() else { return };
    let cycle = multigrid_cycle(32, 0.03, false).unwrap();
    let h = cycle.hierarchy();
    let backend = GpuCycles::new(g.clone()).unwrap().with_chunk_bytes(1 << 16);
    let dev = backend.try_upload(&h).unwrap();
    assert_eq!(dev.stencil_bindings(), 4, "the case should need four chunks of 2^14 entries");
    let bits = kernels_agree(&cycle, &backend);
    let mut rng = Lcg::new(9);
    let b = random(h.size(0), &mut rng);
    let (_, rel, same) = gpu_against_cpu_levels(&cycle, &dev, &b);
    assert!(rel <= 1e-12, "relative difference {rel:e}");
    if g.is_software() {
        assert!(bits && same, "lavapipe should give the CPU's bits with the split stencil");
    }
    // more than four chunks do not fit the bindings: a typed error, no upload
    let tiny = GpuCycles::new(g.clone()).unwrap().with_chunk_bytes(1 << 15);
    assert!(matches!(tiny.try_upload(&h), Err(winslow_gpu::GpuError::TooLarge(_))));
}

/// The EGG Jacobian (eq. 12, plain and scaled operator) of a curved map with unequal
/// degrees and a double knot, its stencil storage rounded to `f32`: the GPU's product
/// equals the CPU's (`PackedSystem`'s `MatVec`, which the core tests against the
/// assembled matrix) on random vectors, twice in a row on one upload, with the values in
/// one binding and split over two; the CPU's bits on lavapipe.
#[test]
fn jacobian_product_equals_the_cpu_product() {
    let Some(g) = gpu() else { return };
    let (disc, cps, mut rng) = curved_case();
    let n = 2 * disc.dofs.num_free();
    assert!(disc.dofs.num_free() < disc.dofs.num_total(), "the case should have fixed functions");
    for op in [Operator::Plain, Operator::Scaled] {
        let mut st = vec![0.0; disc.stencil_len(2)];
        let mut res = vec![0.0; 2 * disc.dofs.num_total()];
        disc.egg(&cps, op, &mut res, &mut st);
        let packed = Stencil32::pack(st);
        let sys = PackedSystem::new(&disc, 2, &packed).expect("no periodic replicas");
        // 16 x 12 functions, 4 x 35 entries each: 26 880 entries, two chunks of 2^14
        for (chunk, bindings) in [(u64::MAX, 1), (1 << 16, 2)] {
            let backend = GpuProducts::new(g.clone()).unwrap().with_chunk_bytes(chunk);
            let dev = backend.try_upload(&sys).unwrap();
            assert_eq!(dev.stencil_bindings(), bindings, "{} entries in chunks of {chunk} bytes", packed.len());
            for _ in 0..2 {
                let x = random(n, &mut rng);
                let (mut want, mut got) = (vec![0.0; n], vec![1.0; n]);
                sys.mul_vec(&x, &mut want);
                dev.try_apply(&x, &mut got).unwrap();
                let (rel, same) = compare(&got, &want);
                assert!(rel <= 1e-12, "{op:?}, chunks of {chunk} bytes: relative difference {rel:e}");
                if g.is_software() {
                    assert!(same, "{op:?}, chunks of {chunk} bytes: lavapipe should give the CPU's bits");
                }
            }
            assert_eq!(backend.stats().0.calls, 2);
        }
    }
}

/// A curved map (a perturbed annulus sector) on a bicubic-by-biquadratic basis of 16 x 12
/// functions with fixed boundary functions, and the random generator after it.
fn curved_case() -> (Discretization, Vec<[f64; 2]>, Lcg) {
    let kx = KnotVector::open_uniform(3, 12).with_inserted(&[0.4]);
    let ky = KnotVector::open_uniform(2, 9).with_inserted(&[0.5]);
    let (gx, gy) = (kx.greville(), ky.greville());
    let mut rng = Lcg::new(21);
    let mut cps = Vec::new();
    for &v in &gy {
        for &u in &gx {
            let (r, t) = (1.0 + 2.0 * v, 1.3 * u + 0.1 * v * v);
            cps.push([r * t.cos() + 0.02 * (rng.uniform() - 0.5), r * t.sin() + 0.02 * (rng.uniform() - 0.5)]);
        }
    }
    (Discretization::new([kx, ky]), cps, rng)
}

/// The entries of `s` as `f32`.
fn entries(s: &Stencil32) -> Vec<f32> {
    (0..s.len()).map(|i| f32::from_bits((s.words()[i >> 1] >> ((i & 1) * 32)) as u32)).collect()
}

/// The Newton Jacobian assembled on the device and rounded there into the product's
/// bindings (`GpuAssembler::try_egg_operator`) is the CPU's packed stencil
/// (`Stencil32::pack` of `Discretization::egg`): its bits on lavapipe, to `f32`
/// rounding (2^-24 of the largest entry) elsewhere; in one binding and split over two,
/// assembled in one chunk of basis rows and in one chunk per row. Its residual and its
/// product are the CPU's, and the bus carried the control points up and the residual
/// down for the assembly and the indices up for the product, where the host path (the
/// path before: `try_egg` into host storage, packed, `try_upload`) also brought the `f64`
/// stencil down (8 bytes per entry) and sent it up as `f32` (4 bytes per entry).
#[test]
fn jacobian_assembled_on_the_device_is_the_cpu_packing() {
    let Some(g) = gpu() else { return };
    let (disc, cps, mut rng) = curved_case();
    let (n, total, len) = (2 * disc.dofs.num_free(), disc.dofs.num_total(), disc.stencil_len(2));
    for op in [Operator::Plain, Operator::Scaled] {
        let mut st = vec![0.0; len];
        let mut res = vec![0.0; 2 * total];
        disc.egg(&cps, op, &mut res, &mut st);
        let packed = Stencil32::pack(st);
        let want = entries(&packed);
        let sys = PackedSystem::new(&disc, 2, &packed).expect("no periodic replicas");
        let scale = want.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        // 16 x 12 functions, 4 x 35 entries each: 26 880 entries, two bindings of 2^14;
        // 1024 bytes per assembly chunk: one basis row each
        for (rows, product_chunk, bindings) in [(u64::MAX, u64::MAX, 1), (1024, 1 << 16, 2)] {
            let asm = GpuAssembler::new(g.clone()).with_chunk_bytes(rows).with_product_chunk_bytes(product_chunk);
            let case = format!("{op:?}, {} assembly chunks, {bindings} bindings", asm.chunks(&disc));
            asm.reset_stats();
            let mut got_res = vec![0.0; 2 * total];
            let dev = asm.try_egg_operator(&disc, &cps, op, &mut got_res).unwrap();
            assert_eq!(dev.stencil_bindings(), bindings, "{case}");
            let got = dev.read_stencil().unwrap();
            assert_eq!(got.len(), want.len(), "{case}");
            let worst = got.iter().zip(&want).fold(0.0f32, |m, (a, b)| m.max((a - b).abs()));
            assert!(worst <= scale * 2f32.powi(-24) * 2.0, "{case}: entries differ by {worst:e} of {scale:e}");
            let (rel, same_res) = compare(&got_res, &res);
            assert!(rel <= 1e-12, "{case}: residuals differ by {rel:e}");
            let x = random(n, &mut rng);
            let (mut y_cpu, mut y_gpu) = (vec![0.0; n], vec![1.0; n]);
            sys.mul_vec(&x, &mut y_cpu);
            dev.try_apply(&x, &mut y_gpu).unwrap();
            let (rel, same_y) = compare(&y_gpu, &y_cpu);
            assert!(rel <= 1e-6, "{case}: products differ by {rel:e}");
            if g.is_software() {
                let same = got.iter().zip(&want).all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same && same_res && same_y, "{case}: lavapipe should give the CPU's bits");
            }
            // the bus: the residual down, the indices up; nothing of the stencil
            let s = asm.stats();
            assert_eq!(s.egg_jacobian.bytes_down, 16 * total as u64, "{case}");
            let indices = 4 * (n / 2 + total) as u64;
            assert_eq!((s.jacobian_products.setups, s.jacobian_products.setup_bytes), (1, indices), "{case}");
            // the path before, on the same assembler: the stencil down in f64 and up in f32
            asm.reset_stats();
            let mut host = vec![0.0; len];
            asm.try_egg(&disc, &cps, op, &mut got_res, &mut host).unwrap();
            let host = Stencil32::pack(host);
            let host_worst = entries(&host).iter().zip(&got).fold(0.0f32, |m, (a, b)| m.max((a - b).abs()));
            assert!(host_worst <= scale * 2f32.powi(-23), "{case}: the host's packing differs by {host_worst:e}");
            if g.is_software() {
                assert_eq!(host_worst, 0.0, "{case}: lavapipe should pack as the host packs");
            }
            let products = GpuProducts::new(g.clone()).unwrap();
            products.try_upload(&PackedSystem::new(&disc, 2, &host).unwrap()).unwrap();
            let s = asm.stats();
            assert_eq!(s.egg_jacobian.bytes_down, 16 * total as u64 + 8 * len as u64, "{case}");
            assert_eq!(products.stats().0.setup_bytes, indices + 4 * len as u64, "{case}");
        }
    }
}

/// Lines of 643 unknowns (640 elements of degree 3: 413 449 unknowns on the finest
/// level), longer than a software adapter ran in one invocation while each line's
/// residual shared it (lavapipe stopped at about 615): with the residual in a dispatch of
/// its own the cycle uploads there too and equals the CPU's cycle (its bits on
/// lavapipe).
#[test]
fn long_lines_run_on_the_gpu() {
    let Some(g) = gpu() else { return };
    let cycle = multigrid_cycle(640, 3.0, false).unwrap();
    let h = cycle.hierarchy();
    let dev = GpuCycles::new(g.clone()).unwrap().try_upload(&h).expect("lines of 643 unknowns upload");
    let mut rng = Lcg::new(13);
    let b = random(h.size(0), &mut rng);
    let (_, rel, same) = gpu_against_cpu_levels(&cycle, &dev, &b);
    assert!(rel <= 1e-12, "relative difference {rel:e}");
    if g.is_software() {
        assert!(same, "lavapipe should give the CPU's bits");
    }
}
