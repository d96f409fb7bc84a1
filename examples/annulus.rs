//! Library use in a dozen lines: an annulus sector given by analytic sides (Rust
//! closures), run through the pipeline while printing its stages (the solver's stream of
//! levels and iterates).
//!
//! `cargo run --example annulus`; `cargo test --workspace` runs it as a test too.

use std::f64::consts::PI;

use winslow::solve::options::SolveOptions;
use winslow::solve::report::Verdict;
use winslow::solve::solver::Event;
use winslow::{Analytic, Boundary, Pipeline, SideCurve, Stage};

fn annulus(r0: f64, r1: f64, angle: f64) -> Boundary {
    let arc = move |r: f64| SideCurve::Analytic(Analytic::new(move |t| [r * (angle * t).cos(), r * (angle * t).sin()]));
    let ray = move |a: f64| {
        SideCurve::Analytic(Analytic::new(move |t| [(r0 + (r1 - r0) * t) * a.cos(), (r0 + (r1 - r0) * t) * a.sin()]))
    };
    // south: ray at angle 0, east: outer arc, north: ray at `angle`, west: inner arc
    Boundary { name: "annulus-sector".into(), sides: [ray(0.0), arc(r1), ray(angle), arc(r0)] }
}

fn run() -> winslow::Result<(Verdict, f64)> {
    let boundary = annulus(1.0, 2.0, 1.5 * PI);
    let solution = Pipeline::new(boundary, SolveOptions::default())
        .run(&mut |stage| {
            match stage {
                Stage::Fitted { hierarchy, .. } => println!("fitted: {} levels", hierarchy.levels.len()),
                Stage::Solver(Event::LevelStarted { level, shape, .. }) => {
                    println!("level {level}: {}x{} basis", shape[0], shape[1])
                }
                Stage::Solver(Event::Iterate { iterate, .. }) => {
                    println!("  {:>2}  |F| = {:.3e}", iterate.iteration, iterate.residual)
                }
                Stage::Solver(Event::LevelFinished(r)) => println!("  done in {} iterations", r.iterations),
                _ => {}
            }
            true // go on
        })?
        .into_map()?;
    let r = &solution.report;
    println!(
        "{}: {:?}, det J min {:.4}, area {:.6} (exact {:.6})",
        solution.name,
        r.outcome.verdict,
        r.det_j.min,
        r.measures.area,
        0.75 * PI * 3.0
    );
    for f in &r.fit.sides {
        println!("  fit {}: {} elements, max error {:.2e}, converged {}", f.side, f.elements, f.max_error, f.converged);
    }
    Ok((r.outcome.verdict, (r.measures.area - 0.75 * PI * 3.0).abs() / (0.75 * PI * 3.0)))
}

fn main() {
    match run() {
        Ok((v, e)) => println!("verdict: {v:?}, relative area error {e:.1e}"),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}

#[test]
fn annulus_sector_is_bijective() {
    let (verdict, area_error) = run().unwrap();
    assert_eq!(verdict, Verdict::Certified);
    // the map covers the exact sector up to the fit tolerance
    assert!(area_error < 1e-4, "relative area error {area_error:.3e}");
}
