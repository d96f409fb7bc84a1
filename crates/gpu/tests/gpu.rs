//! The GPU back end against the CPU: residual, Jacobian, mass, elasticity and `det J`
//! on shared geometries and several bases, in f64 (1e-12 relative) and f32 (1e-5), and a
//! full solve. With `WINSLOW_REQUIRE_GPU=1` (CI) a missing adapter fails the tests;
//! otherwise they print a note and return.

use std::sync::{Arc, OnceLock};

use winslow::boundary::fit::FitOptions;
use winslow::boundary::hierarchy::build_hierarchy;
use winslow::discrete::assembly::{Discretization, Operator};
use winslow::methods::egg::EggAssembler;
use winslow::solve::initial::coons;
use winslow::solve::options::SolveOptions;
use winslow::spline::curve::Point;
use winslow::spline::knots::KnotVector;
use winslow::testutil::data;
use winslow::verify::quality::sample_det_j;
use winslow::Pipeline;
use winslow::{read_boundary, ReadOptions, Surface};
use winslow_gpu::{gpu_required, Gpu, GpuAssembler, GpuOptions, Precision};

fn open(precision: Precision) -> Option<Arc<GpuAssembler>> {
    match Gpu::new(&GpuOptions { precision: Some(precision), hardware_only: false }) {
        Ok(g) => {
            eprintln!("using {}", g.describe());
            assert_eq!(g.precision(), precision);
            Some(Arc::new(GpuAssembler::new(Arc::new(g))))
        }
        Err(e) if gpu_required() => panic!("WINSLOW_REQUIRE_GPU=1 but no GPU for {}: {e}", precision.name()),
        Err(e) => {
            eprintln!("note: skipping the GPU test ({}): {e}", precision.name());
            None
        }
    }
}

/// One device per precision for the whole test binary (opening one takes a while).
fn gpu(precision: Precision) -> Option<Arc<GpuAssembler>> {
    static F64: OnceLock<Option<Arc<GpuAssembler>>> = OnceLock::new();
    static F32: OnceLock<Option<Arc<GpuAssembler>>> = OnceLock::new();
    match precision {
        Precision::F64 => F64.get_or_init(|| open(Precision::F64)).clone(),
        Precision::F32 => F32.get_or_init(|| open(Precision::F32)).clone(),
    }
}

/// A basis and control points: the Coons patch of a level of a shared geometry's fit
/// hierarchy, bent by a smooth interior perturbation (so the Jacobian is not that of a
/// converged map).
fn shared_case(file: &str, degree: usize, level: usize) -> (Discretization, Vec<Point>) {
    let b = read_boundary(&data(file), &ReadOptions::default()).expect("shared geometry");
    let mut fit = FitOptions::default();
    fit.degree = degree;
    let h = build_hierarchy(&b, &fit).expect("fit");
    let l = &h.levels[level.min(h.levels.len() - 1)];
    let mut cps = coons(&l.knots, &l.sides).expect("coons");
    let disc = Discretization::new(l.knots.clone());
    let [nx, _] = disc.shape();
    for (k, c) in cps.iter_mut().enumerate() {
        if disc.dofs.free_index(k) != winslow::discrete::dofs::FIXED {
            let (i, j) = ((k % nx) as f64, (k / nx) as f64);
            c[0] += 0.01 * h.diameter * (0.7 * i + 1.3 * j).sin();
            c[1] += 0.01 * h.diameter * (1.1 * i - 0.4 * j).cos();
        }
    }
    (disc, cps)
}

/// A non-uniform basis with a double interior knot (C^0 line, zero-length span
/// skipped) and different degrees per direction.
fn knotted_case() -> (Discretization, Vec<Point>) {
    let kx = KnotVector::open_uniform(3, 5).with_inserted(&[0.5, 0.13]);
    let ky = KnotVector::open_uniform(2, 4).with_inserted(&[0.6, 0.6]);
    let (gx, gy) = (kx.greville(), ky.greville());
    let cps = gy
        .iter()
        .flat_map(|&v| {
            gx.iter().map(move |&u| {
                let (r, t) = (1.0 + v, 1.3 * u);
                [r * t.cos() + 0.03 * (7.0 * u * v).sin(), r * t.sin() + 0.02 * (5.0 * u).cos() * v]
            })
        })
        .collect();
    (Discretization::new([kx, ky]), cps)
}

fn cases() -> Vec<(String, Discretization, Vec<Point>)> {
    let (d, c) = knotted_case();
    let mut out = vec![("knotted p=(3,2)".to_string(), d, c)];
    let (d, c) = winslow_gpu::bench::quadrature_case(3000, 3);
    out.push((format!("bent annulus p=3 {:?}", d.shape()), d, c));
    for (file, degree, level) in
        [("quarter_annulus.json", 3, 1), ("wavy_lid.json", 2, 2), ("gismo/duck.json", 3, 1), ("horseshoe.json", 4, 0)]
    {
        let (d, c) = shared_case(file, degree, level);
        out.push((format!("{file} p={degree} {:?}", d.shape()), d, c));
    }
    out
}

/// max |a - b| / max |b|, asserting that `b` is not all zeros.
fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0, "reference is zero");
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

#[test]
fn egg_residual_and_jacobian_match_the_cpu_in_f64() {
    let Some(g) = gpu(Precision::F64) else { return };
    for (name, disc, cps) in cases() {
        for op in [Operator::Plain, Operator::Scaled] {
            let n = disc.dofs.num_total();
            let (mut rc, mut sc) = (vec![0.0; 2 * n], vec![0.0; disc.stencil_len(2)]);
            disc.egg(&cps, op, &mut rc, &mut sc);
            let (mut rg, mut sg) = (vec![f64::NAN; 2 * n], vec![f64::NAN; disc.stencil_len(2)]);
            g.try_egg(&disc, &cps, op, &mut rg, &mut sg).expect("GPU assembly");
            let (er, es) = (rel_err(&rg, &rc), rel_err(&sg, &sc));
            eprintln!("{name} {op:?}: residual {er:.2e}, Jacobian {es:.2e}");
            assert!(er <= 1e-12, "{name} {op:?}: residual differs by {er:e}");
            assert!(es <= 1e-12, "{name} {op:?}: Jacobian differs by {es:e}");
            // the per-entry Jacobian kernel gives the same numbers
            let pe = GpuAssembler::new(g.gpu().clone()).with_per_entry_jacobian(true);
            let (mut r3, mut s3) = (vec![f64::NAN; 2 * n], vec![f64::NAN; disc.stencil_len(2)]);
            pe.try_egg(&disc, &cps, op, &mut r3, &mut s3).expect("per-entry kernel");
            let e3 = rel_err(&s3, &sc);
            eprintln!("{name} {op:?}: per-entry Jacobian {e3:.2e}");
            assert!(e3 <= 1e-12, "{name} {op:?}: per-entry Jacobian differs by {e3:e}");
            // the residual-only call gives the same residual
            let mut r2 = vec![f64::NAN; 2 * n];
            g.try_egg(&disc, &cps, op, &mut r2, &mut []).expect("GPU residual");
            assert_eq!(r2, rg, "{name}: residual-only call differs");
        }
    }
    let s = g.stats();
    assert!(s.egg_jacobian.calls > 0 && s.egg_jacobian.quadrature_points > 0 && s.fallbacks == 0, "{s:?}");
}

#[test]
fn egg_jacobian_matches_the_cpu_in_f32_with_an_f64_residual() {
    let Some(g) = gpu(Precision::F32) else { return };
    for (name, disc, cps) in cases().into_iter().take(3) {
        for op in [Operator::Plain, Operator::Scaled] {
            let n = disc.dofs.num_total();
            let (mut rc, mut sc) = (vec![0.0; 2 * n], vec![0.0; disc.stencil_len(2)]);
            disc.egg(&cps, op, &mut rc, &mut sc);
            let (mut rg, mut sg) = (vec![f64::NAN; 2 * n], vec![f64::NAN; disc.stencil_len(2)]);
            g.try_egg(&disc, &cps, op, &mut rg, &mut sg).expect("GPU assembly");
            // the residual is the CPU's, bit for bit
            assert_eq!(rg, rc, "{name}: the f32 path must compute the residual in f64");
            let es = rel_err(&sg, &sc);
            eprintln!("{name} {op:?}: f32 Jacobian {es:.2e}");
            assert!(es <= 1e-5, "{name} {op:?}: f32 Jacobian differs by {es:e}");
            // and it really ran in f32: not equal to f64 to round-off
            assert!(es > 1e-13, "{name}: the f32 Jacobian is suspiciously exact ({es:e})");
        }
    }
}

#[test]
fn mass_and_elasticity_match_the_cpu() {
    let Some(g) = gpu(Precision::F64) else { return };
    for (name, disc, cps) in cases() {
        let (mut mc, mut mg) = (vec![0.0; disc.stencil_len(1)], vec![f64::NAN; disc.stencil_len(1)]);
        disc.mass(&mut mc);
        g.try_mass(&disc, &mut mg).expect("GPU mass");
        let em = rel_err(&mg, &mc);
        let (lambda, mu) = winslow::solve::initial::LAME;
        let (mut ec, mut eg) = (vec![0.0; disc.stencil_len(2)], vec![f64::NAN; disc.stencil_len(2)]);
        disc.elasticity(&cps, lambda, mu, &mut ec);
        g.try_elasticity(&disc, &cps, lambda, mu, &mut eg).expect("GPU elasticity");
        let ee = rel_err(&eg, &ec);
        eprintln!("{name}: mass {em:.2e}, elasticity {ee:.2e}");
        assert!(em <= 1e-12, "{name}: mass differs by {em:e}");
        assert!(ee <= 1e-12, "{name}: elasticity differs by {ee:e}");
    }
    // the mass matrix integrates 1: sum of all entries = area of the parameter square
    let (_, disc, _) = cases().remove(0);
    let mut m = vec![0.0; disc.stencil_len(1)];
    g.try_mass(&disc, &mut m).expect("GPU mass");
    assert!((m.iter().sum::<f64>() - 1.0).abs() < 1e-12);
}

#[test]
fn det_j_samples_match_the_cpu_for_b_splines_and_nurbs() {
    let Some(g) = gpu(Precision::F64) else { return };
    let mut maps: Vec<(String, Surface)> = cases()
        .into_iter()
        .map(|(name, d, c)| (name, Surface { knots: d.knots.clone(), control_points: c, weights: None }))
        .collect();
    // an exact quarter annulus (rational in xi)
    let kx = KnotVector::open_uniform(2, 1);
    let ky = KnotVector::open_uniform(1, 1);
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let (r0, r1) = (1.0, 2.5);
    let cps = vec![[r0, 0.0], [r0, r0], [0.0, r0], [r1, 0.0], [r1, r1], [0.0, r1]];
    let annulus = Surface::new([kx, ky], cps, Some(vec![1.0, s, 1.0, 1.0, s, 1.0])).expect("NURBS");
    maps.push(("NURBS quarter annulus".into(), annulus.clone()));
    for (name, map) in &maps {
        for n in [1, 7, 64] {
            let c = sample_det_j(map, n);
            let gs = g.try_sample_det_j(map, n).expect("GPU det J");
            let e = rel_err(&gs.values, &c.values);
            assert!(e <= 1e-12, "{name} n={n}: det J differs by {e:e}");
            assert_eq!(gs.n, c.n);
            assert!((gs.min - c.min).abs() <= 1e-12 * c.max.abs() && (gs.max - c.max).abs() <= 1e-12 * c.max.abs());
            // n = 1 has only corners: both are +inf
            assert!(
                gs.min_interior == c.min_interior || (gs.min_interior - c.min_interior).abs() <= 1e-12 * c.max.abs(),
                "{name} n={n}: {} vs {}",
                gs.min_interior,
                c.min_interior
            );
        }
    }
    // exact geometry: the grid points of the rational map lie on the circles r(eta)
    let m = g.gpu().sample_map(&annulus, 16).expect("sample");
    for (k, p) in m.points.iter().enumerate() {
        let j = k / 17;
        let r = r0 + (r1 - r0) * j as f64 / 16.0;
        assert!((p[0].hypot(p[1]) - r).abs() < 1e-12, "point {k} off the circle of radius {r}");
    }
}

#[test]
fn gpu_render_equals_cpu_render_geometry() {
    let Some(g) = gpu(Precision::F64) else { return };
    let (_, d, c) = cases().remove(1);
    let map = Surface { knots: d.knots.clone(), control_points: c, weights: None };
    let opts = winslow::io::picture::PictureOptions { size: 200, resolution: 40, ..Default::default() };
    let cpu = winslow::io::picture::render(&map, &opts);
    let gpu = g.gpu().render(&map, &opts).expect("GPU render");
    assert_eq!((cpu.width, cpu.height), (gpu.width, gpu.height));
    // identical sampling up to round-off: at most a handful of pixels may round apart
    let differ = cpu.rgba.iter().zip(&gpu.rgba).filter(|(a, b)| a.abs_diff(**b) > 1).count();
    assert!(differ * 1000 < cpu.rgba.len(), "{differ} bytes differ");
}

#[test]
fn solve_on_the_gpu_gives_the_cpu_map() {
    let Some(g) = gpu(Precision::F64) else { return };
    let b = read_boundary(&data("quarter_annulus.json"), &ReadOptions::default()).expect("boundary");
    let mut opts = SolveOptions::default();
    opts.levels.min_elements = 6;
    let h = build_hierarchy(&b, &opts.fit).expect("fit");
    let cpu = Pipeline::new(b.clone(), opts.clone()).solve().and_then(|s| s.into_map()).unwrap();
    let gpu =
        Pipeline::new(b, opts).backend(g.clone() as Arc<dyn EggAssembler>).solve().and_then(|s| s.into_map()).unwrap();
    assert!(gpu.report.setup.backend.starts_with("gpu: "), "{}", gpu.report.setup.backend);
    assert!(!gpu.report.setup.backend.contains("fell back"), "{}", gpu.report.setup.backend);
    assert_eq!(cpu.map.knots, gpu.map.knots);
    let diam = h.diameter;
    let err = cpu
        .map
        .control_points
        .iter()
        .zip(&gpu.map.control_points)
        .fold(0.0f64, |m, (a, b)| m.max((a[0] - b[0]).abs()).max((a[1] - b[1]).abs()));
    assert!(err <= 1e-9 * diam, "maps differ by {err:e}");
    assert_eq!(cpu.report.outcome.verdict, gpu.report.outcome.verdict);
}

#[test]
fn chunked_assembly_equals_one_piece() {
    let Some(g) = gpu(Precision::F64) else { return };
    // a budget below one stencil row: one chunk per basis row
    let small = GpuAssembler::new(g.gpu().clone()).with_chunk_bytes(1 << 10);
    for (name, disc, cps) in cases().into_iter().take(3) {
        let n = disc.dofs.num_total();
        let (mut r1, mut s1) = (vec![0.0; 2 * n], vec![0.0; disc.stencil_len(2)]);
        let (mut r2, mut s2) = (vec![f64::NAN; 2 * n], vec![f64::NAN; disc.stencil_len(2)]);
        g.try_egg(&disc, &cps, Operator::Scaled, &mut r1, &mut s1).expect("one piece");
        small.try_egg(&disc, &cps, Operator::Scaled, &mut r2, &mut s2).expect("chunked");
        assert_eq!((r1, s1), (r2, s2), "{name}");
        let (mut m1, mut m2) = (vec![0.0; disc.stencil_len(1)], vec![f64::NAN; disc.stencil_len(1)]);
        g.try_mass(&disc, &mut m1).expect("mass");
        small.try_mass(&disc, &mut m2).expect("chunked mass");
        assert_eq!(m1, m2, "{name}");
        assert!(small.chunks(&disc) > 1 || disc.shape()[1] == 1, "{name}: not chunked");
    }
}

#[test]
fn backend_selection_follows_the_rules() {
    use winslow_gpu::{assembler, Backend, Selected};
    // cpu is always the CPU
    assert!(matches!(assembler(Backend::Cpu, None).unwrap(), Selected::Cpu));
    assert_eq!(assembler(Backend::Cpu, None).unwrap().describe(), "cpu");
    // auto never picks a software adapter, and picks f64 when it picks a GPU
    match assembler(Backend::Auto, None).expect("auto never fails for want of an adapter") {
        Selected::Cpu => {}
        Selected::Gpu(g) => {
            assert!(!g.gpu().is_software(), "{}", g.gpu().describe());
            assert_eq!(g.gpu().precision(), Precision::F64);
        }
    }
    // gpu with a forced precision reports it
    if gpu(Precision::F32).is_some() {
        let s = assembler(Backend::Gpu, Some(Precision::F32)).expect("gpu");
        assert!(s.describe().starts_with("gpu: ") && s.describe().ends_with("f32)"), "{}", s.describe());
    }
}
