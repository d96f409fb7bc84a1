//! `winslow inspect RING.json`: a ring (O-type) document's two closed contours, checked
//! (closed, counter-clockwise, the inner inside the outer) and fitted on one dyadic
//! periodic knot vector in `eta` exactly as `winslow solve` fits them.

use std::fmt::Write as _;
use std::path::Path;

use winslow::boundary::fit::FitOptions;
use winslow::boundary::ring::{ClosedContour, Ring};
use winslow::boundary::ring_fit::{fit_ring_with, EtaRefinement};

fn describe(c: &ClosedContour) -> String {
    match c {
        ClosedContour::Spline(c) => format!(
            "{} p={}, {} control points{}",
            if c.is_rational() { "NURBS" } else { "B-spline" },
            c.degree(),
            c.control_points.len(),
            if c.knots.is_periodic() { ", periodic" } else { ", clamped, closed" }
        ),
        ClosedContour::Points(p) => format!("closed point cloud, {} points", p.len()),
        ClosedContour::Analytic(_) => "analytic closed curve".into(),
    }
}

/// Print (or with `json`, write as JSON) the ring's contours and fit; exit code 0, or 2
/// when the ring is invalid or its fit fails.
pub fn run(file: &Path, ring: &Ring, opts: &FitOptions, json: bool) -> anyhow::Result<i32> {
    let fit = fit_ring_with(ring, opts.degree, opts.tol, opts.max_elements, EtaRefinement::Adaptive, &opts.reparam);
    if json {
        let v = match &fit {
            Ok(f) => serde_json::json!({
                "file": file.display().to_string(),
                "kind": "ring",
                "inner": describe(&ring.inner),
                "outer": describe(&ring.outer),
                "diameter": f.similarity.length(f.diameter),
                "tolerance": f.similarity.length(f.tol_abs),
                "levels": f.levels.len(),
                "elements": f.levels.last().map_or(0, |l| l.knots.num_elements()),
                "max_error": f.levels.last().map(|l| l.max_error.map(|e| f.similarity.length(e))),
                "normalisation": (!f.similarity.is_identity()).then_some(f.similarity),
                "converged": f.converged,
                "outer_seam_shift": f.outer_shift.rem_euclid(1.0),
                "reparam": {
                    "used": f.reparam.used.name(),
                    "gap_ratio": f.reparam.gap_ratio[1],
                    "matches": f.reparam.matches.len(),
                },
                "problems": [],
            }),
            Err(e) => serde_json::json!({
                "file": file.display().to_string(),
                "kind": "ring",
                "inner": describe(&ring.inner),
                "outer": describe(&ring.outer),
                "problems": [e.to_string()],
            }),
        };
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(if fit.is_ok() { 0 } else { 2 });
    }
    let mut s = String::new();
    let _ = writeln!(s, "{} (ring, O-type: eta periodic): \"{}\"", file.display(), ring.name);
    let _ = writeln!(s, "  inner: {}", describe(&ring.inner));
    let _ = writeln!(s, "  outer: {}", describe(&ring.outer));
    let code = match &fit {
        Ok(f) => {
            let len = |l: f64| f.similarity.length(l);
            let _ = writeln!(s, "  closed, counter-clockwise, inner inside outer; diameter {:.6}", len(f.diameter));
            let last = f.levels.last();
            let _ = writeln!(
                s,
                "  contour fit: tolerance {:.3e} (relative {:.1e}), {} periodic levels, finest {} elements (p={}), max error inner {:.3e}, outer {:.3e}{}",
                len(f.tol_abs),
                f.tol_abs / f.diameter,
                f.levels.len(),
                last.map_or(0, |l| l.knots.num_elements()),
                opts.degree,
                last.map_or(0.0, |l| len(l.max_error[0])),
                last.map_or(0.0, |l| len(l.max_error[1])),
                if f.converged { "" } else { "  (tolerance NOT met)" }
            );
            let _ = writeln!(
                s,
                "  eta = 0 on the outer contour at arc-length fraction {:.6}",
                f.outer_shift.rem_euclid(1.0)
            );
            let _ = writeln!(
                s,
                "  reparameterization: {} (requested {}); gap/diameter {:.2e} (threshold {:.1e}); {} matched pairs",
                f.reparam.used.name(),
                f.reparam.requested.name(),
                f.reparam.gap_ratio[1],
                f.reparam.gap_threshold,
                f.reparam.matches.len()
            );
            let _ = writeln!(s, "  no problems found");
            0
        }
        Err(e) => {
            let _ = writeln!(s, "  PROBLEM: {e}");
            2
        }
    };
    say_raw!("{s}");
    Ok(code)
}
