//! Text and table output of the CLI: summaries, reports and tables (files are written
//! by `winslow::io::write`, see `files`).

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::Serialize;
use winslow::boundary::hierarchy::Hierarchy;
use winslow::boundary::validate::ValidationReport;
use winslow::solve::report::{Solution, Verdict};
use winslow::verify::certificate::Certificate;
use winslow::verify::poisson::PoissonReport;
use winslow::verify::quality::Quality;
use winslow::{Boundary, Side, SideCurve};

/// The short human summary after a solve.
pub fn summary(sol: &Solution) -> String {
    let r = &sol.report;
    let mut s = String::new();
    let last = r.solve.levels.last();
    if r.boundary.kept && !r.kinks_kept() {
        let rounded = r.boundary.kinks.iter().filter(|k| !k.kept).count();
        let dev = r.boundary.kinks.iter().filter(|k| !k.kept).fold(0.0f64, |m, k| m.max(k.deviation));
        let _ = writeln!(
            s,
            "{}: {}, but its boundary is NOT the input's: {rounded} kinks not kept (the C0 route failed; rounded by up \
             to {dev:.3e}, within the fit tolerance)",
            sol.name,
            verdict_word(r.outcome.verdict)
        );
    } else if r.boundary.kept {
        let _ = writeln!(s, "{}: {}", sol.name, verdict_word(r.outcome.verdict));
    } else {
        let dev = r.boundary.deviation.iter().fold(0.0f64, |m, &d| m.max(d));
        let rounded = r.boundary.kinks.iter().filter(|k| !k.kept).count();
        let _ = writeln!(
            s,
            "{}: {}, but its boundary is NOT the input's: deviation {dev:.3e} above the fit tolerance {:.3e}{}",
            sol.name,
            verdict_word(r.outcome.verdict),
            r.fit.fit_tolerance,
            if rounded > 0 { format!(" ({rounded} kinks not kept)") } else { String::new() }
        );
    }
    let _ = writeln!(s, "  {}", r.outcome.message);
    let _ = writeln!(s, "  backend: {}", r.setup.backend);
    if let Some(l) = last {
        let _ = writeln!(
            s,
            "  map: degree {:?}, {}x{} control points, {} levels, {} iterations on the finest level",
            r.setup.degree,
            l.shape[0],
            l.shape[1],
            r.solve.levels.len(),
            l.iterations
        );
    }
    let _ = writeln!(
        s,
        "  det J: min {:.4e} (interior {:.4e}), max {:.4e}; Winslow {}; time {:.3} s",
        r.det_j.min,
        r.det_j.min_interior,
        r.det_j.max,
        r.measures.winslow.map_or("infinite (det J <= 0)".to_string(), |w| format!("{w:.6}")),
        r.solve.seconds
    );
    certificate_lines(&mut s, &r.outcome.certificate, false);
    quality_lines(&mut s, &r.measures.quality);
    if let Some(p) = &r.measures.poisson {
        poisson_line(&mut s, p);
    }
    kink_lines(&mut s, r);
    if let Some(imp) = &r.solve.improvement {
        improvement_lines(&mut s, imp, r.solve.seconds);
    }
    for round in &r.solve.repair_rounds {
        let _ = writeln!(
            s,
            "  repair round {}: {} with {} offending element(s); bisected {}x{} spans -> {}x{} basis",
            round.round,
            round.verdict,
            round.offending_elements,
            round.spans_refined[0],
            round.spans_refined[1],
            round.shape[0],
            round.shape[1]
        );
    }
    let dev = r.boundary.deviation.iter().fold(0.0f64, |m, &d| m.max(d));
    let _ = writeln!(
        s,
        "  basis functions: {} ({} basis{}); boundary deviation from the input {:.3e} ({:.1e} of the diameter)",
        r.setup.basis_functions,
        r.setup.basis.used.name(),
        r.setup.basis.fallback.as_ref().map_or(String::new(), |why| format!(", input basis not used: {why}")),
        dev,
        dev / r.fit.diameter
    );
    let rp = &r.fit.reparam;
    let gap = |g: f64| if g.is_finite() { format!("{g:.2e}") } else { "-".into() };
    if sol.map.knots[1].is_periodic() {
        // a ring: one pair of contours, the gap over the outer contour's diameter
        let _ = writeln!(
            s,
            "  reparameterization: {} (requested {}); gap/diameter inner-outer {} (threshold {:.1e}); {} matched pairs",
            rp.used.name(),
            rp.requested.name(),
            gap(rp.gap_ratio[1]),
            rp.gap_threshold,
            rp.matches.len()
        );
    } else {
        let _ = writeln!(
        s,
        "  reparameterization: {} (requested {}); gap/length south-north {} ({}), west-east {} ({}); {} matched pairs",
        rp.used.name(),
        rp.requested.name(),
        gap(rp.gap_ratio[0]),
        rp.pair_methods[0].name(),
        gap(rp.gap_ratio[1]),
        rp.pair_methods[1].name(),
        rp.matches.len()
    );
    }
    for m in &rp.matches {
        let _ = writeln!(
            s,
            "    {}/{} at {:.6}: ({:.6}, {:.6}) - ({:.6}, {:.6})",
            m.sides[0], m.sides[1], m.parameter, m.points[0][0], m.points[0][1], m.points[1][0], m.points[1][1]
        );
    }
    s
}

pub fn verdict_word(v: Verdict) -> &'static str {
    match v {
        Verdict::Certified => "certified bijective (det J > 0 proven)",
        Verdict::DegenerateCorner => "best possible map: degenerate corner forced by the boundary",
        Verdict::Folded => "FOLDED",
        Verdict::Undecided => "UNDECIDED (certificate budget spent)",
        Verdict::NotConverged => "NOT CONVERGED",
    }
}

/// What `winslow check` reports.
#[derive(Debug, Serialize)]
pub struct CheckReport {
    /// Name of the map.
    pub name: String,
    /// Bijectivity certificate.
    pub certificate: Certificate,
    /// Functionals and cell statistics.
    pub quality: Quality,
    /// Largest deviation of the map's boundary from the input, per side (south, east,
    /// north, west), when a boundary was given.
    pub boundary_deviation: Option<[f64; 4]>,
    /// The Poisson benchmark, when asked for.
    pub poisson: Option<PoissonReport>,
}

fn quality_lines(s: &mut String, q: &Quality) {
    let f = &q.functionals;
    let _ = writeln!(
        s,
        "  functionals: Winslow {}, area orthogonality {:.6e}, Liao {:.6e}, uniformity {:.6e}, harmonic {:.6e}, area {:.6e}",
        if f.winslow.is_finite() { format!("{:.6}", f.winslow) } else { "infinite (det J <= 0)".into() },
        f.area_orthogonality,
        f.liao,
        f.uniformity,
        f.harmonic,
        f.area
    );
    let _ = writeln!(
        s,
        "  scaled Jacobian (per-element min): min {:.4}, mean {:.4}, max {:.4}; mean over the map {:.4}",
        q.scaled_jacobian.min, q.scaled_jacobian.mean, q.scaled_jacobian.max, q.scaled_jacobian_mean
    );
    let _ = writeln!(
        s,
        "  orthogonality (deviation from 90 deg, per-element max): max {:.2}, mean {:.2}; aspect ratio: max {:.3}, mean {:.3} ({} elements)",
        q.orthogonality_degrees.max, q.orthogonality_degrees.mean, q.aspect_ratio.max, q.aspect_ratio.mean, q.elements
    );
}

/// The kinks (kept or rounded, with the deviation at each) and the `C^0` route of §9.
fn kink_lines(s: &mut String, r: &winslow::Report) {
    if let Some(c) = &r.boundary.c0_route {
        let w = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.6}"));
        let _ = writeln!(
            s,
            "  C0 route (§9): {}; {} -> {} functions, {} damped step(s), {} Winslow iterations on {} unknowns{} (Winslow {} -> {}), {:.3} s",
            if c.kept { "kinks kept" } else { "kinks NOT kept" },
            c.smoothed_functions,
            c.functions,
            c.continuation_steps,
            c.iterations,
            c.unknowns,
            c.local_spans.map_or(String::new(), |k| format!(" within {k} span(s) of a kink")),
            w(c.winslow[0]),
            w(c.winslow[1]),
            c.seconds
        );
        if let Some(why) = c.failure.as_ref().filter(|_| !c.kept) {
            let _ = writeln!(s, "    why: {why}");
        }
    }
    for k in &r.boundary.kinks {
        let _ = writeln!(
            s,
            "    kink {} at {:.6} ({}, turns {:.1} deg) at ({:.6}, {:.6}): {}, deviation {:.2e} ({:.1e} of the diameter)",
            k.side,
            k.parameter,
            serde_json::to_value(k.kind).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default(),
            k.turning_degrees,
            k.point[0],
            k.point[1],
            if k.kept { "kept exactly" } else { "rounded" },
            k.deviation,
            k.deviation / r.fit.diameter
        );
    }
    for p in &r.outcome.certificate.excused_points {
        let _ = writeln!(
            s,
            "    {} side's zero-speed point ({:.6}, {:.6}): det J = 0 there for every map of this boundary; excused \
             neighbourhood {:.3e} x {:.3e} in (xi, eta)",
            p.side, p.point[0], p.point[1], p.extent[0], p.extent[1]
        );
    }
}

fn certificate_lines(s: &mut String, c: &Certificate, with_message: bool) {
    if with_message {
        let _ = writeln!(s, "  certificate: {}", c.message());
    }
    let _ = writeln!(
        s,
        "  certificate: det J degree {:?}, {} elements ({}x{}), {} Bernstein boxes, depth {}, {:.3} s",
        c.det_degree, c.elements, c.element_shape[0], c.element_shape[1], c.boxes, c.max_depth, c.seconds
    );
    for k in c.corners.iter().filter(|k| k.forbids_positivity) {
        let ext = match k.excused_extent {
            Some(e) => {
                format!("; excused neighbourhood {:.3e} x {:.3e} in (xi, eta), det J > 0 proven outside", e[0], e[1])
            }
            None => String::new(),
        };
        let _ = writeln!(
            s,
            "    corner {}: angle {:.8} deg forbids det J > 0 there (det J = {:.3e}){ext}",
            k.corner, k.angle_degrees, k.det_j
        );
    }
    for f in c.folds.iter().take(5) {
        let _ = writeln!(
            s,
            "    fold in element ({}, {}): det J = {:.4e} (rounding bound {:.1e}) at (xi, eta) = ({:.6}, {:.6}){}",
            f.element[0],
            f.element[1],
            f.value,
            f.error_bound,
            f.param[0],
            f.param[1],
            f.one_sided.as_ref().map(|o| format!(", {o}")).unwrap_or_default()
        );
    }
    for u in c.undecided_info.iter().take(5) {
        let why = if u.smallest_coefficient.abs() <= u.error_bound {
            "det J is zero within its rounding bound there"
        } else if u.reason == "box-budget" {
            "the box budget (--max-boxes) was spent"
        } else {
            "the bisection depth (--max-depth) was reached"
        };
        let _ = writeln!(
            s,
            "    undecided element ({}, {}): {why} (depth {}, {} boxes, smallest coefficient {:.3e}, rounding bound {:.1e})",
            u.element[0], u.element[1], u.depth, u.boxes, u.smallest_coefficient, u.error_bound
        );
    }
}

/// `winslow check` as text.
pub fn check_text(r: &CheckReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{}: {}", r.name, r.certificate.verdict.name());
    certificate_lines(&mut s, &r.certificate, true);
    quality_lines(&mut s, &r.quality);
    if let Some(d) = r.boundary_deviation {
        let _ = writeln!(
            s,
            "  boundary deviation: south {:.3e}, east {:.3e}, north {:.3e}, west {:.3e}",
            d[0], d[1], d[2], d[3]
        );
    }
    if let Some(p) = &r.poisson {
        poisson_line(&mut s, p);
    }
    s
}

pub(crate) fn poisson_line(s: &mut String, p: &PoissonReport) {
    let _ = writeln!(
        s,
        "  Poisson benchmark (a = {:.4}, {:.4}; {} unknowns): Q(x) = {:.6e}, L2 error {:.3e}, H1 error {:.3e}, {:.3} s",
        p.a[0], p.a[1], p.unknowns, p.q, p.errors.l2, p.errors.h1, p.seconds
    );
}

fn knot_list(k: &[f64]) -> String {
    let shown: Vec<String> = if k.len() <= 16 {
        k.iter().map(|v| format!("{v}")).collect()
    } else {
        k[..6]
            .iter()
            .map(|v| format!("{v}"))
            .chain(std::iter::once(format!("... ({} knots) ...", k.len())))
            .chain(k[k.len() - 6..].iter().map(|v| format!("{v}")))
            .collect()
    };
    format!("[{}]", shown.join(", "))
}

fn side_lines(s: &mut String, side: Side, c: &SideCurve) {
    let _ = writeln!(s, "  {side:<5}: {}", c.describe());
    if let SideCurve::Spline(c) = c {
        let _ = writeln!(s, "         knots {}", knot_list(c.knots.knots()));
    }
}

/// `winslow inspect` as text.
pub fn inspect_text(
    file: &Path,
    kind: &str,
    b: &Boundary,
    report: Option<&ValidationReport>,
    fit: Option<&Hierarchy>,
    problems: &[String],
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{} ({kind}): \"{}\"", file.display(), b.name);
    for side in Side::ALL {
        side_lines(&mut s, side, b.side(side));
    }
    if let Some(r) = report {
        let _ = writeln!(
            s,
            "  bounding box [{:.6}, {:.6}] x [{:.6}, {:.6}], diameter {:.6}",
            r.bbox_min[0], r.bbox_max[0], r.bbox_min[1], r.bbox_max[1], r.diameter
        );
        let _ = writeln!(s, "  orientation {:?} (signed area {:.6e})", r.orientation, r.signed_area);
        let names = ["south-west", "south-east", "north-east", "north-west"];
        for k in 0..4 {
            let warn = if r.corner_angles[k] >= 180.0 { "  <- >= 180 deg: det J cannot be positive here" } else { "" };
            let _ = writeln!(
                s,
                "  corner {:<10} ({:.6}, {:.6}) angle {:7.2} deg, gap {:.1e}{warn}",
                names[k], r.corners[k][0], r.corners[k][1], r.corner_angles[k], r.corner_gaps[k]
            );
        }
    }
    if let Some(h) = fit {
        let _ = writeln!(
            s,
            "  contour fit: tolerance {:.3e} (relative {:.1e} of the diameter), {} hierarchy levels",
            h.physical_tol_abs(),
            h.tol_abs / h.diameter,
            h.levels.len()
        );
        for side in Side::ALL {
            let f = &h.fits[side as usize];
            let last = f.levels.last();
            let _ = writeln!(
                s,
                "    {side:<5}: {} levels, finest {} elements (p={}), max error {:.3e}{}",
                f.levels.len(),
                last.map_or(0, |c| c.knots.num_elements()),
                last.map_or(0, |c| c.degree()),
                h.similarity.length(f.max_error.last().copied().unwrap_or(0.0)),
                if f.converged { "" } else { "  (tolerance NOT met)" }
            );
            if let Some(c) = last {
                let _ = writeln!(s, "           fitted knots {}", knot_list(c.knots.knots()));
            }
        }
        let rp = &h.reparam;
        let _ = writeln!(
            s,
            "  reparameterization: {} (requested {}); gap/length south-north {:.2e} ({}), west-east {:.2e} ({}); {} matched pairs",
            rp.used.name(),
            rp.requested.name(),
            rp.gap_ratio[0],
            rp.pair_methods[0].name(),
            rp.gap_ratio[1],
            rp.pair_methods[1].name(),
            rp.matches.len()
        );
        let sizes: Vec<String> =
            h.levels.iter().map(|l| format!("{}x{}", l.knots[0].num_basis(), l.knots[1].num_basis())).collect();
        let _ = writeln!(s, "    basis per level: {}", sizes.join(" -> "));
    }
    if problems.is_empty() {
        let _ = writeln!(s, "  no problems found");
    } else {
        for p in problems {
            let _ = writeln!(s, "  PROBLEM: {p}");
        }
    }
    s
}

/// `winslow inspect --json`.
pub fn inspect_json(
    b: &Boundary,
    report: Option<&ValidationReport>,
    fit: Option<&Hierarchy>,
    problems: &[String],
) -> serde_json::Value {
    let sides: Vec<serde_json::Value> =
        Side::ALL.iter().map(|&s| serde_json::json!({ "side": s.name(), "kind": b.side(s).describe() })).collect();
    let fits: Option<Vec<serde_json::Value>> = fit.map(|h| {
        Side::ALL
            .iter()
            .map(|&s| {
                let f = &h.fits[s as usize];
                serde_json::json!({
                    "side": s.name(),
                    "levels": f.levels.len(),
                    "elements": f.levels.last().map_or(0, |c| c.knots.num_elements()),
                    "max_error": f.max_error.last().map(|&e| h.similarity.length(e)),
                    "converged": f.converged,
                })
            })
            .collect()
    });
    serde_json::json!({
        "name": b.name,
        "sides": sides,
        "diameter": report.map(|r| r.diameter),
        "orientation": report.map(|r| format!("{:?}", r.orientation)),
        "signed_area": report.map(|r| r.signed_area),
        "corner_angles": report.map(|r| r.corner_angles),
        "fit_tolerance": fit.map(|h| h.tol_abs),
        "reparam": fit.map(|h| &h.reparam),
        "fit": fits,
        "problems": problems,
    })
}

/// One row of `winslow bench`.
#[derive(Debug, Serialize)]
pub struct BenchRow {
    /// Geometry.
    pub geometry: String,
    /// Extra refinements.
    pub refine: usize,
    /// Unknowns on the finest level.
    pub dofs: usize,
    /// Solved levels.
    pub levels: usize,
    /// Newton iterations on the finest level.
    pub newton: usize,
    /// Pseudo-time iterations on the finest level.
    pub pseudo: usize,
    /// Assembly seconds (all levels).
    pub assembly_s: f64,
    /// Linear-solve seconds (all levels).
    pub solve_s: f64,
    /// Total seconds including fitting and reporting.
    pub total_s: f64,
    /// Peak resident memory in MiB.
    pub peak_mib: f64,
    /// The solve's estimated peak in MiB (`winslow::solve::memory`), the figure
    /// `--max-memory` is checked against.
    pub estimated_mib: f64,
    /// Elements of the final map.
    pub elements: usize,
    /// Seconds to certify the final map.
    pub certify_s: f64,
    /// Seconds of one Newton iteration on the finest level (assembly plus linear solve,
    /// averaged over its iterations).
    pub newton_iteration_s: f64,
    /// GMRES iterations per linear solve (Newton step) on the finest level, mean
    /// (0 with direct solves).
    pub krylov_mean: f64,
    /// ... and the most of one solve.
    pub krylov_max: usize,
    /// Seconds of the finest level's linear solves spent assembling the preconditioner's
    /// metric Laplacian and factorizing.
    pub factor_s: f64,
    /// Peak resident memory per finest-level unknown, in bytes.
    pub peak_bytes_per_dof: f64,
    /// Verdict.
    pub verdict: Verdict,
    /// Tensor-product basis functions of the map.
    pub basis: usize,
    /// Winslow functional (`null` when det J <= 0 at a quadrature point).
    pub winslow: Option<f64>,
    /// Smallest scaled Jacobian on the sample grid.
    pub scaled_jacobian_min: f64,
    /// Reparameterization used.
    pub reparam: &'static str,
    /// Matched pairs.
    pub matches: usize,
    /// The back end (`report.backend`: the adapter, and under `--linear multigrid` the
    /// V-cycles its kernels ran so far in this process).
    pub backend: String,
}

impl BenchRow {
    /// Row from a solution.
    pub fn new(sol: &Solution, refine: usize, total_s: f64, estimated_bytes: u64) -> Self {
        let r = &sol.report;
        let last = r.solve.levels.last();
        Self {
            geometry: sol.name.clone(),
            refine,
            dofs: last.map_or(0, |l| l.unknowns),
            levels: r.solve.levels.len(),
            newton: last.map_or(0, |l| l.newton_iterations),
            pseudo: last.map_or(0, |l| l.pseudo_time_iterations),
            assembly_s: r.solve.levels.iter().map(|l| l.assembly_seconds).sum(),
            solve_s: r.solve.levels.iter().map(|l| l.linear_seconds).sum(),
            total_s,
            peak_mib: peak_memory_mib(),
            estimated_mib: estimated_bytes as f64 / (1u64 << 20) as f64,
            elements: r.outcome.certificate.elements,
            certify_s: r.outcome.certificate.seconds,
            newton_iteration_s: last
                .map_or(0.0, |l| (l.assembly_seconds + l.linear_seconds) / l.iterations.max(1) as f64),
            krylov_mean: last.map_or(0.0, |l| l.krylov_iterations as f64 / l.linear_solves.max(1) as f64),
            krylov_max: last.map_or(0, |l| l.krylov_max),
            factor_s: last.map_or(0.0, |l| l.factor_seconds),
            peak_bytes_per_dof: peak_memory_mib() * (1u64 << 20) as f64 / last.map_or(1, |l| l.unknowns.max(1)) as f64,
            verdict: r.outcome.verdict,
            basis: r.setup.basis_functions,
            winslow: r.measures.winslow,
            scaled_jacobian_min: r.measures.quality.scaled_jacobian.min,
            reparam: r.fit.reparam.used.name(),
            matches: r.fit.reparam.matches.len(),
            backend: r.setup.backend.clone(),
        }
    }
}

/// The improvement stage (`--improve`): before and after, iterations, time.
pub fn improvement_lines(s: &mut String, imp: &winslow::solve::improve::Improvement, total_s: f64) {
    let w = |v: Option<f64>| v.map_or("infinite".to_string(), |w| format!("{w:.8}"));
    let (b, a) = (&imp.before, &imp.after);
    let _ = writeln!(
        s,
        "  improvement ({}): {}; Winslow {} -> {}, min scaled Jacobian {:.4} -> {:.4}, orthogonality max {:.2} -> {:.2} deg (mean {:.2} -> {:.2})",
        imp.method,
        if imp.accepted { "map improved" } else { "map of the solve kept" },
        w(b.winslow),
        w(a.winslow),
        b.scaled_jacobian_min,
        a.scaled_jacobian_min,
        b.orthogonality_max_degrees,
        a.orthogonality_max_degrees,
        b.orthogonality_mean_degrees,
        a.orthogonality_mean_degrees,
    );
    let _ = writeln!(
        s,
        "    {} iterations ({}), max control-point move {:.3e} of the diameter, {:.3} s of {:.3} s in all",
        imp.iterations,
        if imp.converged { "converged".to_string() } else { imp.failure.clone().unwrap_or_default() },
        imp.max_displacement,
        imp.seconds,
        total_s
    );
    if !imp.accepted {
        let _ = writeln!(s, "    {}", imp.message);
    }
}

/// The table printed by `winslow bench`.
pub fn bench_table(rows: &[BenchRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| geometry | refine | DOFs | levels | Newton its | GMRES its/step (mean, max) | assembly s | solve s | factor s (finest) | total s | peak MiB | peak B/DOF | estimated MiB | elements | certify s | Newton it s | verdict | reparam (matches) | basis | Winslow | min scaled J |"
    );
    let _ = writeln!(
        s,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---:|---:|---:|"
    );
    for r in rows {
        let its = if r.pseudo > 0 { format!("{} (+{} pseudo-time)", r.newton, r.pseudo) } else { r.newton.to_string() };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {:.1}, {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.0} | {:.0} | {:.0} | {} | {:.4} | {:.4} | {:?} | {} ({}) | {} | {} | {:.4} |",
            r.geometry,
            r.refine,
            r.dofs,
            r.levels,
            its,
            r.krylov_mean,
            r.krylov_max,
            r.assembly_s,
            r.solve_s,
            r.factor_s,
            r.total_s,
            r.peak_mib,
            r.peak_bytes_per_dof,
            r.estimated_mib,
            r.elements,
            r.certify_s,
            r.newton_iteration_s,
            r.verdict,
            r.reparam,
            r.matches,
            r.basis,
            r.winslow.map_or("inf".to_string(), |w| format!("{w:.4}")),
            r.scaled_jacobian_min
        );
    }
    s
}

/// The quadrature throughput table of `winslow bench --backend gpu`: per size and
/// assembly (residual `F`, Jacobian `J` with `F`), the CPU and GPU seconds per call,
/// quadrature points per second, GB/s of control points in and results out, and where
/// the GPU time goes.
pub fn quadrature_table(backend: &str, rows: &[winslow_gpu::bench::QuadratureRow]) -> String {
    use winslow_gpu::bench::Measured;
    let mut s = String::new();
    let _ = writeln!(s, "quadrature throughput; back end {backend}");
    let _ = writeln!(
        s,
        "| DOFs | basis | qp | kind | CPU s | CPU Mqp/s | CPU GB/s | GPU s | GPU Mqp/s | GPU GB/s | upload s | dispatch s | readback s | CPU part s | scatter s | GPU setup s | max rel diff |"
    );
    let _ = writeln!(s, "|---:|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let f = |m: &Measured| format!("{:.3e} | {:.2} | {:.3}", m.seconds, m.qp_per_second / 1e6, m.gb_per_second);
    for r in rows {
        for (kind, cpu, gpu) in [("F", &r.cpu_residual, &r.gpu_residual), ("J", &r.cpu_jacobian, &r.gpu_jacobian)] {
            let g = match gpu {
                Some(g) => format!(
                    "{} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.3e}",
                    f(g),
                    g.upload,
                    g.dispatch,
                    g.readback,
                    g.cpu,
                    if kind == "J" { g.scatter } else { 0.0 }
                ),
                None => "- | - | - | - | - | - | - | -".to_string(),
            };
            let _ = writeln!(
                s,
                "| {} | {}x{} p={} | {} | {kind} | {} | {g} | {} | {} |",
                r.dofs,
                r.shape[0],
                r.shape[1],
                r.degree,
                r.quadrature_points,
                f(cpu),
                r.gpu_setup.map_or("-".into(), |v| format!("{v:.3}")),
                r.max_rel_diff.map_or("-".into(), |v| format!("{v:.1e}")),
            );
        }
    }
    s
}

/// Every JSON geometry under `tests/data` and `tests/data/gismo`.
pub fn default_bench_files() -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for dir in ["tests/data", "tests/data/gismo"] {
        let Ok(rd) = std::fs::read_dir(dir) else { continue };
        let mut v: Vec<PathBuf> = rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        v.sort();
        out.extend(v);
    }
    if out.is_empty() {
        anyhow::bail!("no geometry files given and none found under tests/data");
    }
    Ok(out)
}

/// Reset the kernel's peak-RSS counter (Linux; ignored elsewhere).
pub fn reset_peak_memory() {
    if let Ok(mut f) = std::fs::OpenOptions::new().write(true).open("/proc/self/clear_refs") {
        let _ = f.write_all(b"5");
    }
}

/// Peak resident set size in MiB since the last reset (Linux `VmHWM`; 0 elsewhere).
pub fn peak_memory_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

/// `-q`: the process prints nothing but errors (set once, by `main`).
static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Set `-q` for the process.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, std::sync::atomic::Ordering::Relaxed);
}

/// Whether `-q` was given.
pub fn quiet() -> bool {
    QUIET.load(std::sync::atomic::Ordering::Relaxed)
}

/// The exit code of a verdict: 0 certified or degenerate corner (the best map the
/// boundary allows), 3 folded, 4 not converged, 5 undecided.
/// The exit code of a solve: its verdict's ([`exit_code`]), but 6 for a bijective map
/// whose boundary is not the input's within the fit tolerance ([`BoundaryReport::kept`](winslow::solve::report::BoundaryReport::kept))
/// or whose kinks the `C^0` route could not keep ([`winslow::Report::kinks_kept`]).
pub fn solve_exit_code(r: &winslow::Report) -> i32 {
    match exit_code(r.outcome.verdict) {
        0 if !r.boundary.kept || !r.kinks_kept() => 6,
        code => code,
    }
}

/// The exit code of a verdict: 0 certified or degenerate corner, 3 folded, 4 not
/// converged, 5 undecided.
pub fn exit_code(v: Verdict) -> i32 {
    match v {
        Verdict::Certified | Verdict::DegenerateCorner => 0,
        Verdict::Folded => 3,
        Verdict::NotConverged => 4,
        Verdict::Undecided => 5,
    }
}

/// One nonlinear iterate as a progress line: iteration, method, `||F||`, the scaled
/// residual, step, damping, and the time step or objective when there is one.
pub fn iterate_line(it: &winslow::solve::newton::Iterate) -> String {
    format!(
        "{:>3} {:<11} |F| = {:.3e}  scaled {:.3e}  step {:.2e}  damping {:.3}{}{}",
        it.iteration,
        format!("{:?}", it.method),
        it.residual,
        it.scaled_residual,
        it.step,
        it.damping,
        it.dt.map(|d| format!("  dt {d:.2e}")).unwrap_or_default(),
        it.objective.map(|j| format!("  J {j:.6e}")).unwrap_or_default()
    )
}
