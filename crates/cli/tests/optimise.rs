//! `winslow optimise` end to end (paper §10.3): both starts on a coarse basis, the JSON
//! report, the written map certified again by `winslow check`, and eq. (49) alone.

mod common;

use common::{bin, data};

#[test]
fn optimise_from_both_starts_writes_a_certified_map() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().join("optimise");
    let map = dir.join("annulus.json");
    let out = bin()
        .arg("optimise")
        .arg(data().join("quarter_annulus.json"))
        .args(["--functional", "winslow", "--from", "both", "--fit-tol", "1e-2", "--json", "-o"])
        .arg(&map)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let runs = v["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    let mut optimum = Vec::new();
    for (r, name) in runs.iter().zip(["winslow-from-egg", "winslow-from-maxz"]) {
        assert_eq!(r["name"], name);
        assert_eq!(r["certified"], true, "{r}");
        assert_eq!(r["converged"], true, "{r}");
        assert!(r["iterations"].as_u64().unwrap() >= 1);
        let (w0, w) = (r["start_values"]["winslow"].as_f64().unwrap(), r["values"]["winslow"].as_f64().unwrap());
        assert!(w <= w0 && w >= 2.0, "{w0} -> {w}");
        optimum.push(w);
    }
    // the same minimiser from both starts
    assert!((optimum[0] - optimum[1]).abs() < 1e-6 * optimum[0], "{optimum:?}");
    assert!(runs[1]["max_z"].is_object() && runs[0]["max_z"].is_null());
    // the written map (the run from G) is certified by `winslow check`
    let check = bin().arg("check").arg(&map).output().unwrap();
    assert!(check.status.success(), "{}", String::from_utf8_lossy(&check.stdout));
}

#[test]
fn maxz_only_certifies_the_start_it_finds() {
    let out = bin()
        .arg("optimise")
        .arg(data().join("gismo/puzzle3.json"))
        .args(["--maxz-only", "--fit-tol", "1e-2", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = &v["runs"][0];
    assert_eq!(r["name"], "maxz");
    assert_eq!(r["certified"], true, "{r}");
    let z = r["max_z"]["z_history"].as_array().unwrap();
    // the Coons patch of the puzzle piece folds; eq. (49) stops at the first z > 0
    assert!(z[0].as_f64().unwrap() < 0.0 && z.last().unwrap().as_f64().unwrap() > 0.0, "{z:?}");
    assert_eq!(r["start_values"]["winslow"], serde_json::Value::Null, "the Coons patch folds");
}
