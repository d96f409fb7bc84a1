//! `winslow sweep RING --rotate-inner DEG --steps N [--center X,Y] -o DIR`: the sliding
//! O-grid of paper §11.1 ([`winslow::solve::sweep`]): one map per frame (JSON with the
//! frame's row, and VTK Bézier cells), a ParaView `.pvd` series, and the per-frame table
//! (`sweep.csv`, `sweep.json`, and on stdout).

use super::*;
use winslow::io::ring::read_ring;
use winslow::solve::sweep::{FrameReport, Sweep, SweepOptions};

#[derive(Args, Debug)]
pub(super) struct SweepArgs {
    /// Ring document (two closed contours, see formats.md).
    ring: PathBuf,
    /// Rotation of the inner contour per step, degrees (counter-clockwise).
    #[arg(long, allow_negative_numbers = true)]
    rotate_inner: f64,
    /// Number of steps after frame 0.
    #[arg(long)]
    steps: usize,
    /// Centre of rotation `x,y` (default: the inner contour's centroid).
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    center: Option<[f64; 2]>,
    /// Highest order of the time extrapolation of the control points (0 to 5).
    #[arg(long, default_value_t = 5)]
    order: usize,
    /// Output directory: frame_NNNN.json, frame_NNNN.vtu, sweep.pvd, sweep.csv, sweep.json.
    #[arg(short, long)]
    output: PathBuf,
    /// No per-frame lines on stderr.
    #[arg(long)]
    quiet: bool,
    #[command(flatten)]
    solver: SolverArgs,
}

fn parse_point(s: &str) -> std::result::Result<[f64; 2], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().map_err(|e| format!("{t:?}: {e}")))
        .collect::<std::result::Result<_, _>>()?;
    match v[..] {
        [x, y] if x.is_finite() && y.is_finite() => Ok([x, y]),
        _ => Err(format!("expected two finite numbers x,y, got {s:?}")),
    }
}

fn row(r: &FrameReport) -> String {
    format!(
        "{},{:.6},{},{},{},{:.3e},{:.3e},{},{:.3e},{:.4},{},{}",
        r.frame,
        r.angle_degrees,
        r.predictor_order.map_or("cold".into(), |o| o.to_string()),
        r.newton_iterations,
        r.linear_solves,
        r.residual_before,
        r.residual_after,
        r.converged,
        r.inner_fit_error,
        r.seconds,
        r.verdict,
        r.det_j_lower_bound.map_or(String::new(), |b| format!("{b:.6e}"))
    )
}

pub(super) fn run(a: SweepArgs) -> Result<i32> {
    if a.order > 5 {
        bail!("--order must be between 0 and 5, got {}", a.order);
    }
    if !a.rotate_inner.is_finite() {
        bail!("--rotate-inner must be a finite number of degrees, got {}", a.rotate_inner);
    }
    let opts = a.solver.options()?;
    let ring = read_ring(&a.ring).with_context(|| format!("reading {}", a.ring.display()))?.with_context(|| {
        format!("{} is not a ring document (a \"ring\" with inner and outer contours)", a.ring.display())
    })?;
    std::fs::create_dir_all(&a.output).with_context(|| format!("creating {}", a.output.display()))?;
    let so = SweepOptions { step: a.rotate_inner.to_radians(), steps: a.steps, center: a.center, max_order: a.order };
    let (mut sweep, sol, f0) = Sweep::new(&ring, &opts, so).context("solving frame 0")?;
    let header = "frame,angle_deg,predictor,newton,linear_solves,residual_before,residual_after,converged,inner_fit_error,seconds,verdict,det_j_lower_bound";
    if !a.quiet {
        eprintln!(
            "{}: frame 0 solved cold ({}x{} basis, {:.3} s, {}); {} frames at {} degrees per step",
            ring.name,
            sol.map.shape()[0],
            sol.map.shape()[1],
            f0.report.seconds,
            f0.report.verdict,
            a.steps,
            a.rotate_inner
        );
        eprintln!("{header}");
    }
    let mut rows = Vec::new();
    let mut pvd =
        String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n");
    let mut failures = 0;
    let mut frame = f0;
    loop {
        let r = &frame.report;
        let stem = format!("frame_{:04}", r.frame);
        let label = format!("frame {} at {:.6} degrees: {}", r.frame, r.angle_degrees, r.verdict);
        let report = serde_json::to_value(r)?;
        let json =
            || map_to_json(&format!("{}-{stem}", ring.name), &frame.map, Some(serde_json::json!({ "frame": report })));
        output::write_map_as(&a.output.join(format!("{stem}.json")), "json", &ring.name, &frame.map, &label, json)?;
        output::write_map_as(&a.output.join(format!("{stem}.vtu")), "vtu", &ring.name, &frame.map, &label, json)?;
        pvd.push_str(&format!("    <DataSet timestep=\"{}\" part=\"0\" file=\"{stem}.vtu\"/>\n", r.angle_degrees));
        if r.verdict != "certified" || !r.converged {
            failures += 1;
        }
        if !a.quiet {
            eprintln!("{}", row(r));
        }
        rows.push(frame.report.clone());
        if rows.len() > a.steps {
            break;
        }
        frame = sweep.next_frame().with_context(|| format!("solving frame {}", rows.len()))?;
    }
    pvd.push_str("  </Collection>\n</VTKFile>\n");
    std::fs::write(a.output.join("sweep.pvd"), pvd)?;
    let csv: String = std::iter::once(header.to_string()).chain(rows.iter().map(row)).collect::<Vec<_>>().join("\n");
    std::fs::write(a.output.join("sweep.csv"), csv + "\n")?;
    let cold = rows[0].seconds;
    let later: Vec<&FrameReport> = rows.iter().skip(6).collect();
    let summary = serde_json::json!({
        "name": ring.name,
        "step_degrees": a.rotate_inner,
        "frames": rows,
        "cold_seconds": cold,
        "failures": failures,
        "from_frame_6": {
            "max_newton": later.iter().map(|r| r.newton_iterations).max(),
            "max_linear_solves": later.iter().map(|r| r.linear_solves).max(),
            "mean_seconds": (!later.is_empty()).then(|| later.iter().map(|r| r.seconds).sum::<f64>() / later.len() as f64),
        },
    });
    winslow::io::write_json(&a.output.join("sweep.json"), &summary)?;
    println!(
        "{}: {} frames, {} not certified or not converged; cold solve {:.3} s; from frame 6: at most {} Newton iterations and {} linear solves per frame, mean {:.4} s; wrote {}",
        ring.name,
        rows.len(),
        failures,
        cold,
        later.iter().map(|r| r.newton_iterations).max().unwrap_or(0),
        later.iter().map(|r| r.linear_solves).max().unwrap_or(0),
        if later.is_empty() { f64::NAN } else { later.iter().map(|r| r.seconds).sum::<f64>() / later.len() as f64 },
        a.output.display()
    );
    Ok(if failures == 0 { 0 } else { 3 })
}
