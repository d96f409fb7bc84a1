//! Quadrature throughput, CPU versus GPU (`winslow bench --backend gpu` and the
//! criterion bench): quadrature points per second and bytes moved per second for the
//! EGG residual and Jacobian, with the split upload / dispatch / readback / scatter.

use std::time::Instant;

use serde::Serialize;
use winslow::discrete::assembly::{Discretization, Operator};
use winslow::spline::curve::Point;
use winslow::spline::knots::KnotVector;

use crate::assembler::GpuAssembler;
use crate::stats::Timings;

/// A tensor basis of degree `degree` with about `dofs / 2` functions (so about `dofs`
/// scalar coefficients), square, and the control points of a smooth curved map (an
/// annulus sector bent by a sine), free of folds.
pub fn quadrature_case(dofs: usize, degree: usize) -> (Discretization, Vec<Point>) {
    let per_dir = (((dofs.max(8) / 2) as f64).sqrt().round() as usize).max(degree + 1);
    let elements = per_dir - degree;
    let kv = KnotVector::open_uniform(degree, elements);
    let g = kv.greville();
    let cps = g
        .iter()
        .flat_map(|&v| {
            g.iter().map(move |&u| {
                let (r, t) = (1.0 + v + 0.05 * (3.0 * u).sin(), 1.2 * u);
                [r * t.cos(), r * t.sin()]
            })
        })
        .collect();
    (Discretization::new([kv.clone(), kv]), cps)
}

/// Mean cost of one call.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Measured {
    /// Seconds per call (all parts).
    pub seconds: f64,
    /// Of which: upload of control points.
    pub upload: f64,
    /// Kernels (submit to completion); for the CPU the whole assembly.
    pub dispatch: f64,
    /// Readback and conversion.
    pub readback: f64,
    /// CPU work of the GPU path (the f64 residual in f32 mode).
    pub cpu: f64,
    /// Gathering the stencil storage into the CSR matrix (CPU, shared by both paths).
    pub scatter: f64,
    /// Quadrature points per second.
    pub qp_per_second: f64,
    /// Bytes moved per call: control points in, results out.
    pub bytes: u64,
    /// `bytes / seconds / 1e9`.
    pub gb_per_second: f64,
}

/// One size of the quadrature benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct QuadratureRow {
    /// Scalar coefficients `2 n`.
    pub dofs: usize,
    /// Basis shape.
    pub shape: [usize; 2],
    /// Degree.
    pub degree: usize,
    /// Quadrature points per assembly.
    pub quadrature_points: u64,
    /// CPU residual.
    pub cpu_residual: Measured,
    /// CPU residual and Jacobian.
    pub cpu_jacobian: Measured,
    /// GPU residual.
    pub gpu_residual: Option<Measured>,
    /// GPU residual and Jacobian.
    pub gpu_jacobian: Option<Measured>,
    /// Seconds of the first GPU call beyond a later one (basis tables, buffers, kernel
    /// warm-up).
    pub gpu_setup: Option<f64>,
    /// Largest relative difference GPU versus CPU (residual and Jacobian).
    pub max_rel_diff: Option<f64>,
}

/// Repetitions: enough for about `budget` seconds, at least 1, at most 10.
fn reps(first: f64, budget: f64) -> usize {
    ((budget / first.max(1e-9)).ceil() as usize).clamp(1, 10)
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

fn finish(mut m: Measured, qps: u64, bytes: u64) -> Measured {
    m.bytes = bytes;
    m.qp_per_second = qps as f64 / m.seconds.max(1e-12);
    m.gb_per_second = bytes as f64 / m.seconds.max(1e-12) / 1e9;
    m
}

fn per_call(t: &Timings, calls: usize) -> Measured {
    let c = calls as f64;
    Measured {
        seconds: t.total() / c,
        upload: t.upload / c,
        dispatch: t.dispatch / c,
        readback: t.readback / c,
        cpu: t.cpu / c,
        ..Default::default()
    }
}

/// Measure one size: CPU always, GPU when given. `budget` is the time aimed at per
/// measurement (seconds).
pub fn measure(
    disc: &Discretization,
    cps: &[Point],
    op: Operator,
    gpu: Option<&GpuAssembler>,
    budget: f64,
) -> Result<QuadratureRow, crate::GpuError> {
    let n = disc.dofs.num_total();
    let nq = (disc.tables[0].nq * disc.tables[1].nq) as u64;
    let qps = disc.num_elements() as u64 * nq;
    let cp_bytes = (16 * n) as u64;
    let res_bytes = (16 * n) as u64;
    let st_bytes = (8 * disc.stencil_len(2)) as u64;
    let mut res = vec![0.0; 2 * n];
    let mut st = vec![0.0; disc.stencil_len(2)];
    let mut csr = disc.vector.clone();

    let time_cpu = |f: &mut dyn FnMut()| {
        let t0 = Instant::now();
        f();
        let first = t0.elapsed().as_secs_f64();
        let r = reps(first, budget);
        let t0 = Instant::now();
        for _ in 0..r {
            f();
        }
        t0.elapsed().as_secs_f64() / r as f64
    };
    let s = time_cpu(&mut || disc.egg(cps, op, &mut res, &mut []));
    let cpu_residual = finish(Measured { seconds: s, dispatch: s, ..Default::default() }, qps, cp_bytes + res_bytes);
    let s = time_cpu(&mut || disc.egg(cps, op, &mut res, &mut st));
    let scatter = time_cpu(&mut || csr.gather(&st));
    let cpu_jacobian = finish(
        Measured { seconds: s + scatter, dispatch: s, scatter, ..Default::default() },
        qps,
        cp_bytes + res_bytes + st_bytes,
    );
    let (cpu_res, cpu_st) = (res.clone(), st.clone());

    let (mut gpu_residual, mut gpu_jacobian, mut gpu_setup, mut max_rel_diff) = (None, None, None, None);
    if let Some(g) = gpu {
        let (mut gres, mut gst) = (vec![0.0; 2 * n], vec![0.0; disc.stencil_len(2)]);
        // first call: uploads the basis
        g.reset_stats();
        let t0 = Instant::now();
        g.try_egg(disc, cps, op, &mut gres, &mut gst)?;
        let first = t0.elapsed().as_secs_f64();
        max_rel_diff = Some(rel_diff(&gres, &cpu_res).max(rel_diff(&gst, &cpu_st)));
        // Jacobian
        g.reset_stats();
        let r = reps(first, budget);
        for _ in 0..r {
            g.try_egg(disc, cps, op, &mut gres, &mut gst)?;
        }
        let mut m = per_call(&g.stats().egg_jacobian, r);
        gpu_setup = Some((first - m.seconds).max(0.0));
        let scatter = time_cpu(&mut || csr.gather(&gst));
        m.scatter = scatter;
        m.seconds += scatter;
        let bytes = g.stats().egg_jacobian.bytes_up / r as u64 + g.stats().egg_jacobian.bytes_down / r as u64;
        gpu_jacobian = Some(finish(m, qps, bytes));
        // residual
        g.reset_stats();
        let t0 = Instant::now();
        g.try_egg(disc, cps, op, &mut gres, &mut [])?;
        let r = reps(t0.elapsed().as_secs_f64(), budget);
        g.reset_stats();
        for _ in 0..r {
            g.try_egg(disc, cps, op, &mut gres, &mut [])?;
        }
        let s = g.stats().egg_residual;
        let bytes = (s.bytes_up + s.bytes_down) / r as u64;
        gpu_residual = Some(finish(per_call(&s, r), qps, bytes));
    }
    Ok(QuadratureRow {
        dofs: 2 * n,
        shape: disc.shape(),
        degree: disc.degrees().0,
        quadrature_points: qps,
        cpu_residual,
        cpu_jacobian,
        gpu_residual,
        gpu_jacobian,
        gpu_setup,
        max_rel_diff,
    })
}
