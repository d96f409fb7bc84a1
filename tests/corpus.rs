//! The hard corpus (issue: reliability), a fixed sample in CI: one seeded domain of each
//! family of `boundary::families` (narrow clearances, spirals, sharp corners, puzzle tabs,
//! thin strips, CAD sides, noisy and sparse clouds) is solved at the default settings and
//! must be certified, its sides fitted within the tolerance (a noisy cloud: within the
//! noise). The full corpus (48 domains) is a benchmark:
//! `winslow corpus --solve` (BENCHMARKS.md).

use winslow::boundary::families::Family;
use winslow::solve;
use winslow::solve::options::SolveOptions;
use winslow::solve::report::Verdict;

fn certified(family: Family, seed: u64) {
    let b = family.generate(seed);
    let sol = solve(&b, &SolveOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", b.name));
    let r = &sol.report;
    assert_eq!(r.outcome.verdict, Verdict::Certified, "{}: {}", b.name, r.outcome.message);
    // every side is fitted within the tolerance (at the points of a cloud), except the
    // noise of a noisy cloud (1e-4, up to ~4.5 sigma), which is not fitted
    let slack = if family == Family::NoisyCloud { 5e-4 } else { r.fit.fit_tolerance };
    for f in &r.fit.sides {
        assert!(f.max_error <= slack, "{} {}: fit error {:.3e}, allowed {slack:.3e}", b.name, f.side, f.max_error);
    }
}

#[test]
fn clearance() {
    certified(Family::Clearance, 3);
}
#[test]
fn spiral() {
    certified(Family::Spiral, 2);
}
#[test]
fn sharp_corner() {
    certified(Family::SharpCorner, 1);
}
#[test]
fn puzzle() {
    certified(Family::Puzzle, 2);
}
#[test]
fn strip() {
    certified(Family::Strip, 1);
}
#[test]
fn cad() {
    certified(Family::Cad, 4);
}
#[test]
fn noisy_cloud() {
    certified(Family::NoisyCloud, 2);
}
#[test]
fn sparse_cloud() {
    certified(Family::SparseCloud, 1);
}

/// The noise floor of the contour fit: a noisy cloud stops refining where the noise
/// begins, instead of fitting it with thousands of elements.
#[test]
fn noisy_clouds_are_not_fitted_to_their_noise() {
    use winslow::boundary::fit::FitOptions;
    use winslow::boundary::hierarchy::build_hierarchy;
    for seed in 1..=3 {
        let h = build_hierarchy(&Family::NoisyCloud.generate(seed), &FitOptions::default()).unwrap();
        for f in &h.fits {
            let n = f.finest().knots.num_elements();
            assert!(n <= 64, "noisy-cloud-{seed} {}: {n} elements", f.side);
        }
    }
}
