//! `winslow compare` end to end on a small geometry: the paper's columns per method, the
//! JSON form, one picture per method, and clear errors.

mod common;

use std::path::PathBuf;

use common::{bin, data, stdout_json};

fn annulus() -> PathBuf {
    data().join("quarter_annulus.json")
}

#[test]
fn compare_prints_the_table_and_writes_pictures() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().join("compare");
    // the human table: its columns and one row per method
    let out = bin().arg("compare").arg(annulus()).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    for col in ["method", "IT", "conv", "BIJ", "Q/Q(x_G)", "W", "Liao", "AO", "min SJ", "basis", "time [s]"] {
        assert!(text.contains(col), "missing column {col:?} in\n{text}");
    }
    let rows = text.lines().filter(|l| ["egg ", "vhm ", "qc "].iter().any(|m| l.starts_with(m))).count();
    assert_eq!(rows, 3, "{text}");
    // the same run as JSON, with the pictures: every method converged and certified
    let out = bin().arg("compare").arg(annulus()).arg("--png-dir").arg(&dir).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v = stdout_json(&out);
    let rows = v["rows"].as_array().unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(names, ["egg", "vhm", "qc"]);
    for r in rows {
        assert_eq!(r["measures"]["verdict"], "certified", "{r}");
        assert_eq!(r["converged"], true, "{r}");
    }
    // EGG is the reference of Q(x)/Q(x_G)
    assert_eq!(rows[0]["q_ratio"].as_f64(), Some(1.0), "{}", rows[0]);
    for m in ["egg", "vhm", "qc"] {
        let png = dir.join(format!("quarter_annulus-{m}.png"));
        let bytes = std::fs::read(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display()));
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    }
}

#[test]
fn compare_json_has_one_row_per_method() {
    let out =
        bin().arg("compare").arg(annulus()).args(["--methods", "vhm", "--lambda1", "0.01", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(names, ["egg", "vhm"], "EGG always runs first");
    assert_eq!(rows[0]["q_ratio"].as_f64(), Some(1.0));
    for r in rows {
        assert_eq!(r["measures"]["verdict"], "certified", "{r}");
        assert!(r["iterations"].as_u64().unwrap() >= 1);
        assert!(r["measures"]["q"].as_f64().unwrap() > 0.0);
        assert!(r["measures"]["winslow"].as_f64().unwrap() >= 2.0, "W >= 2 for any bijective map");
    }
    assert_eq!(v["basis"], "input");
    assert_eq!(v["poisson_scales"].as_array().unwrap().len(), 2);
}

#[test]
fn unknown_methods_and_bad_weights_are_errors() {
    let out = bin().arg("compare").arg(annulus()).args(["--methods", "egg,ipopt"]).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("ipopt") && err.contains("egg, vhm, qc"), "{err}");
    let out = bin().arg("compare").arg(annulus()).args(["--lambda2=-1"]).output().unwrap();
    assert!(!out.status.success());
    // named by the core's CompareOptions::validate
    assert!(String::from_utf8_lossy(&out.stderr).contains("lambda2"));
}

/// The rows of `winslow compare ARGS --json` by method name.
fn json_rows(args: &[&str]) -> Vec<serde_json::Value> {
    let out = bin().arg("compare").args(args).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["rows"].as_array().unwrap().clone()
}

/// Gravesen's methods on a small fitted basis: verdicts from the certificate, the
/// constrained optimisations from x_G, each no worse than x_G for its own functional
/// (x_G is feasible here, so the SQP's accepted steps only decrease the functional).
#[test]
fn compare_runs_gravesens_methods_from_the_egg_map() {
    let path = annulus();
    let args = [path.to_str().unwrap(), "--methods", "maxz,liao,ao,winslow", "--basis", "fitted", "--fit-tol", "1e-2"];
    let rows = json_rows(&args);
    let names: Vec<&str> = rows.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(names, ["egg", "maxz", "liao", "ao", "winslow"]);
    let shape = &rows[0]["measures"]["shape"];
    for r in &rows {
        assert_eq!(r["measures"]["verdict"], "certified", "{r}");
        assert!(r["measures"]["certificate"].as_str().unwrap().starts_with("certified bijective"), "{r}");
        assert_eq!(r["converged"], true, "{r}");
        assert_eq!(&r["measures"]["shape"], shape, "one basis: {r}");
    }
    assert_eq!(rows[1]["start"], "coons");
    // the Coons patch of the quarter annulus is already feasible (z > 0): no LP needed
    assert!(rows[1]["notes"][0].as_str().unwrap().contains("0 LPs"), "{}", rows[1]);
    let value = |r: &serde_json::Value, key: &str| r["measures"][key].as_f64().unwrap();
    for (row, key) in [(&rows[2], "liao"), (&rows[3], "area_orthogonality"), (&rows[4], "winslow")] {
        assert_eq!(row["start"], "egg", "{row}");
        assert!(row["iterations"].as_u64().unwrap() >= 1, "{row}");
        let (own, egg) = (value(row, key), value(&rows[0], key));
        assert!(own <= egg * (1.0 + 1e-9), "{}: {key} {own} > {egg} of x_G", row["method"]);
    }
    // Liao and AO move well away from x_G (EGG does not minimise them)
    assert!(value(&rows[2], "liao") < 0.95 * value(&rows[0], "liao"), "{}", rows[2]);
    assert!(value(&rows[3], "area_orthogonality") < 0.95 * value(&rows[0], "area_orthogonality"));
}

/// Max-z climbs from a folded Coons patch (the star's) to a certified start.
#[test]
fn compare_maxz_certifies_a_folded_coons_patch() {
    let star = data().join("contours/star8.json");
    let args =
        [star.to_str().unwrap(), "--methods", "maxz", "--basis", "fitted", "--fit-tol", "1e-2", "--min-elements", "4"];
    let rows = json_rows(&args);
    let maxz = &rows[1];
    assert_eq!(maxz["method"], "maxz");
    assert!(maxz["iterations"].as_u64().unwrap() >= 1, "{maxz}");
    assert_eq!(maxz["converged"], true, "{maxz}");
    assert_eq!(maxz["measures"]["verdict"], "certified", "{maxz}");
}

/// A rational basis (the input's NURBS) and a basis over the dense cap are error rows
/// that say why, with no map and no measures.
#[test]
fn gravesens_methods_refuse_a_rational_or_large_basis_clearly() {
    let nurbs = data().join("maps/quarter_annulus_nurbs.json");
    let rows = json_rows(&[nurbs.to_str().unwrap(), "--methods", "maxz,liao"]);
    assert_eq!(rows[0]["measures"]["verdict"], "certified");
    for r in &rows[1..] {
        assert!(r["measures"].is_null(), "{r}");
        let why = r["failure"].as_str().unwrap();
        assert!(why.contains("not run") && why.contains("rational") && why.contains("--basis fitted"), "{why}");
    }
    // the star on at least 32 cubic elements per direction: over the dense SQP's 3000 unknowns
    let star = data().join("contours/star8.json");
    let args =
        [star.to_str().unwrap(), "--methods", "ao", "--basis", "fitted", "--fit-tol", "1e-2", "--min-elements", "32"];
    let rows = json_rows(&args);
    assert!(rows[1]["measures"].is_null(), "{}", rows[1]);
    let why = rows[1]["failure"].as_str().unwrap();
    assert!(why.contains("not run") && why.contains("over the 3000"), "{why}");
    let n: usize = why.split(" unknowns").next().unwrap().rsplit(' ').next().unwrap().parse().unwrap();
    assert!(n > 3000, "{why}");
}

/// Out-of-range flags are refused by the core (exit 1, the option named, nothing
/// written): the solver's by `SolveOptions::validate`, in `solve` and `compare` alike, and
/// those of the comparison and the constrained optimisation by `CompareOptions::validate`
/// and `ConstrainedOptions::validate`: the CLI has no checks of its own that could drift
/// from the library's.
#[test]
fn out_of_range_solver_flags_are_the_cores_typed_error() {
    let scratch = tempfile::tempdir().unwrap();
    let map = scratch.path().join("map.json");
    let input = data().join("quarter_annulus.json");
    for (flag, value, needle) in
        [("--min-elements", "0", "min_elements"), ("--growth", "0.5", "growth"), ("--tol", "0", "tol")]
    {
        let out = bin().args(["solve", "-q", flag, value]).arg(&input).arg("-o").arg(&map).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{flag} {value}: {err}");
        assert!(err.contains("invalid argument") && err.contains(needle), "{flag} {value}: {err}");
        assert!(!map.exists(), "{flag} {value}");
        let out = bin().args(["compare", "--json", flag, value]).arg(&input).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "compare {flag} {value}");
        assert!(String::from_utf8_lossy(&out.stderr).contains(needle), "compare {flag} {value}");
    }
    // the comparison's and the constrained optimisation's own options: the core's
    // CompareOptions::validate and ConstrainedOptions::validate, before any solve
    for (command, flag, value, needle) in [
        ("compare", "--lambda1", "-0.5", "lambda1"),
        ("compare", "--eps", "1.5", "eps"),
        ("compare", "--max-sqp", "0", "iteration limits"),
        ("optimise", "--eps", "0", "eps"),
    ] {
        let mut cmd = bin();
        cmd.args([command, "-q", &format!("{flag}={value}")]).arg(&input);
        if command == "optimise" {
            cmd.arg("-o").arg(&map);
        }
        let out = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{command} {flag} {value}: {err}");
        assert!(err.contains("invalid argument") && err.contains(needle), "{command} {flag} {value}: {err}");
        assert!(!map.exists(), "{command} {flag} {value}");
    }
}
