//! Tests of the comparison: every method on an affine boundary, names, cancelling.

use super::*;
use crate::boundary::{Analytic, SideCurve};
use crate::methods::egg::CpuAssembler;

/// The image of the unit square under `x = A ξ + b`, four straight sides.
pub(super) fn parallelogram() -> (Boundary, impl Fn(f64, f64) -> [f64; 2]) {
    let f = |u: f64, v: f64| [2.0 * u + 0.5 * v + 1.0, -0.3 * u + 1.5 * v];
    let side = move |g: fn(f64) -> (f64, f64)| {
        SideCurve::Analytic(Analytic::new(move |t| {
            let (u, v) = g(t);
            f(u, v)
        }))
    };
    let sides = [side(|t| (t, 0.0)), side(|t| (1.0, t)), side(|t| (t, 1.0)), side(|t| (0.0, t))];
    (Boundary { name: "parallelogram".into(), sides }, f)
}

/// The comparison's solve options with at least 4 elements per direction on the finest
/// level.
fn coarse() -> SolveOptions {
    let mut o = CompareOptions::default().solve;
    o.levels.min_elements = 4;
    o
}

/// On an affine boundary every method returns the affine map (EGG and VHM to
/// rounding; the quasi-conformal minimizer is degenerate, see
/// [`crate::methods::quasi_conformal`], and resolved to its stopping rule), each
/// certified, on one basis, with `Q / Q(x_G) = 1` for maps equal to EGG's.
#[test]
fn every_method_returns_the_affine_map_of_an_affine_boundary() {
    let (b, f) = parallelogram();
    let opts = CompareOptions { solve: coarse(), ..Default::default() };
    let mut events = Vec::new();
    let cmp = compare(
        &b,
        &[MethodChoice::Qc, MethodChoice::Vhm, MethodChoice::Qc],
        &opts,
        Arc::new(CpuAssembler),
        &mut |e| {
            if let CompareEvent::Started { method, .. } = &e {
                events.push(method.clone());
            }
            true
        },
    )
    .unwrap()
    .unwrap();
    assert_eq!(events, ["egg", "qc", "vhm"], "EGG first, repeats dropped");
    let names: Vec<&str> = cmp.rows.iter().map(|r| r.method.as_str()).collect();
    assert_eq!(names, ["egg", "qc", "vhm"]);
    let shape = cmp.rows[0].measures.as_ref().unwrap().shape;
    for r in &cmp.rows {
        let m = r.measures.as_ref().unwrap();
        assert!(r.converged, "{}: {:?}", r.method, r.failure);
        assert_eq!(m.verdict, Verdict::Certified, "{}", r.method);
        assert_eq!(m.shape, shape, "{}: one basis", r.method);
        let tol = if r.method == "qc" { 1e-4 } else { 1e-9 };
        let map = r.map.as_ref().unwrap();
        for (u, v) in [(0.3, 0.7), (0.5, 0.5), (0.9, 0.2), (0.05, 0.95)] {
            let (x, e) = (map.eval(u, v), f(u, v));
            assert!(
                (x[0] - e[0]).abs() < tol && (x[1] - e[1]).abs() < tol,
                "{} at ({u}, {v}): {x:?} vs {e:?}",
                r.method
            );
        }
        // the same map, the same Poisson error
        let q = r.q_ratio.unwrap();
        assert!((q - 1.0).abs() < if r.method == "qc" { 1e-3 } else { 1e-8 }, "{}: Q / Q(x_G) = {q}", r.method);
    }
    assert_eq!(cmp.rows[0].q_ratio, Some(1.0));
}

#[test]
fn names_parse_and_unknown_names_are_errors() {
    for m in MethodChoice::ALL {
        assert_eq!(MethodChoice::parse(m.name()).unwrap(), m);
    }
    assert_eq!(MethodChoice::parse(" VHM ").unwrap(), MethodChoice::Vhm);
    // the name of earlier versions
    assert_eq!(MethodChoice::parse("winslow-functional").unwrap(), MethodChoice::Winslow);
    let e = MethodChoice::parse("ipopt").unwrap_err().to_string();
    assert!(e.contains("ipopt") && e.contains("egg, vhm, qc"), "{e}");
}

/// The progress callback cancels: `Ok(None)`, no comparison.
#[test]
fn progress_can_cancel() {
    let (b, _) = parallelogram();
    let opts = CompareOptions { solve: coarse(), ..Default::default() };
    let mut seen = 0;
    let out = compare(&b, &[MethodChoice::Vhm], &opts, Arc::new(CpuAssembler), &mut |_| {
        seen += 1;
        seen < 3
    })
    .unwrap();
    assert!(out.is_none());
    assert_eq!(seen, 3);
}

/// Gravesen's methods keep the affine map of an affine boundary: it is the Coons patch
/// (so max-z needs no LP), and it minimises the Liao and area-orthogonality functionals
/// (`Σ σᵢ⁴` and `|x_ξ|⁴ + |x_η|⁴` are convex in `J`, whose mean the boundary fixes:
/// Jensen) and the Winslow functional (its inverse is harmonic), with every constraint
/// inactive; so the SQP stops at its first QP. Every row is certified on EGG's basis.
#[test]
fn gravesens_methods_keep_the_affine_map_of_an_affine_boundary() {
    let (b, f) = parallelogram();
    let opts = CompareOptions { solve: coarse(), ..Default::default() };
    let methods = [MethodChoice::MaxZ, MethodChoice::Liao, MethodChoice::Winslow, MethodChoice::Ao];
    let cmp = compare(&b, &methods, &opts, Arc::new(CpuAssembler), &mut |_| true).unwrap().unwrap();
    let names: Vec<&str> = cmp.rows.iter().map(|r| r.method.as_str()).collect();
    assert_eq!(names, ["egg", "maxz", "liao", "winslow", "ao"]);
    let starts: Vec<&str> = cmp.rows.iter().map(|r| r.start).collect();
    assert_eq!(starts, ["coons", "coons", "egg", "egg", "egg"]);
    let shape = cmp.rows[0].measures.as_ref().unwrap().shape;
    for r in &cmp.rows[1..] {
        let m = r.measures.as_ref().unwrap_or_else(|| panic!("{}: {:?}", r.method, r.failure));
        assert!(r.converged, "{}: {:?}", r.method, r.failure);
        assert_eq!(m.verdict, Verdict::Certified, "{}", r.method);
        assert_eq!(m.shape, shape, "{}: one basis", r.method);
        let expected_iterations = if r.method == "maxz" { 0..=0 } else { 1..=2 };
        assert!(expected_iterations.contains(&r.iterations), "{}: {} iterations", r.method, r.iterations);
        let map = r.map.as_ref().unwrap();
        for (u, v) in [(0.3, 0.7), (0.5, 0.5), (0.9, 0.2), (0.05, 0.95)] {
            let (x, e) = (map.eval(u, v), f(u, v));
            assert!(
                (x[0] - e[0]).abs() < 1e-6 && (x[1] - e[1]).abs() < 1e-6,
                "{} at ({u}, {v}): {x:?} vs {e:?}",
                r.method
            );
        }
        assert!(!r.notes.is_empty(), "{}: the stages are noted", r.method);
    }
}

/// Every method's name is its serialised name (the JSON `method` of a row and the
/// `--methods` spelling agree).
#[test]
fn serialised_names_are_the_names() {
    for m in MethodChoice::ALL {
        assert_eq!(serde_json::to_value(m).unwrap(), m.name());
    }
}

/// Every option of the comparison is checked by the core: the solve's, `λ₁`, `λ₂`, the
/// Poisson scales and Gravesen's `ε`, iteration limits, tolerance and trust radius.
#[test]
fn options_are_validated_by_the_core() {
    assert!(CompareOptions::default().validate().is_ok());
    type Spoil = fn(&mut CompareOptions);
    let bad: [(&str, Spoil); 7] = [
        ("min_elements", |o| o.solve.levels.min_elements = 0),
        ("lambda1", |o| o.lambda1 = -1.0),
        ("lambda2", |o| o.lambda2 = f64::NAN),
        ("Poisson scales", |o| o.poisson_scales = Some([1.0, 0.0])),
        ("eps", |o| o.constrained.eps = 1.0),
        ("iteration limits", |o| o.constrained.max_iterations = 0),
        ("radius", |o| o.constrained.radius = f64::INFINITY),
    ];
    for (needle, spoil) in bad {
        let mut o = CompareOptions::default();
        spoil(&mut o);
        let e = o.validate().unwrap_err().to_string();
        assert!(e.contains(needle), "{needle}: {e}");
    }
}
