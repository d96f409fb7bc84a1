//! `winslow loft` end to end: slices of different bases (B-spline and NURBS) lofted to a
//! certified volume, written as JSON / G+Smo XML / VTK and read back by `check` and
//! `convert`; a planted fold in a volume found by `check`; typed errors for bad slices.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::{bin, data};

fn maps() -> PathBuf {
    data().join("maps")
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// The skewed square (degree 2) three times and its transposed NURBS cousin are brought
/// to one basis; linear and cubic lofts certify; the outputs read back.
#[test]
fn loft_writes_a_certified_volume_that_reads_back() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let sq = maps().join("skewed_square.json");
    for interp in ["linear", "cubic"] {
        let out_json = dir.join(format!("{interp}.json"));
        let o = bin()
            .arg("loft")
            .args([&sq, &sq, &sq, &sq])
            .args(["--z", "0,0.5,1.5,2", "--interpolation", interp, "--json", "-o"])
            .arg(&out_json)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(r["certificate"]["verdict"]["kind"], "certified");
        assert_eq!(r["report"]["interpolation"], interp);
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out_json).unwrap()).unwrap();
        let deg = doc["map"]["degree"].as_array().unwrap().len();
        assert_eq!(deg, 3);
        assert!(doc["map"]["control_points"][0].as_array().unwrap().len() == 3);
        // check reads the volume (JSON), convert writes XML and VTU, check reads the XML
        let c = bin().arg("check").arg(&out_json).arg("--json").output().unwrap();
        assert_eq!(c.status.code(), Some(0), "{}", text(&c));
        let cr: serde_json::Value = serde_json::from_slice(&c.stdout).unwrap();
        assert_eq!(
            (cr["kind"].as_str(), cr["certificate"]["verdict"]["kind"].as_str()),
            (Some("volume"), Some("certified"))
        );
        // the volume of the cylinder: area of the square slice times the height 2
        assert!(cr["volume"].as_f64().unwrap() > 0.0);
        let xml = dir.join(format!("{interp}.xml"));
        let v = bin().arg("convert").arg(&out_json).arg("-o").arg(&xml).output().unwrap();
        assert_eq!(v.status.code(), Some(0), "{}", text(&v));
        assert!(std::fs::read_to_string(&xml).unwrap().contains("TensorBSpline3"));
        let c2 = bin().arg("check").arg(&xml).output().unwrap();
        assert!(c2.status.success() && text(&c2).contains("certified bijective"), "{}", text(&c2));
        let vtu = dir.join(format!("{interp}.vtu"));
        assert!(bin().arg("convert").arg(&out_json).arg("-o").arg(&vtu).status().unwrap().success());
        let body = std::fs::read_to_string(&vtu).unwrap();
        assert!(body.contains("HigherOrderDegrees") && body.contains("\n79"), "no Bézier hexahedra");
    }
    // slices of different bases: degree (1, 2) NURBS and degree (2, 2) B-spline
    let qa = maps().join("quarter_annulus_nurbs.json");
    let o = bin().arg("loft").args([&qa, &qa]).args(["--dz", "1", "-o"]).arg(dir.join("qa.json")).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

#[test]
fn bad_slices_are_clear_errors() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let sq = maps().join("skewed_square.json");
    let run = |args: &[&str], files: &[&Path]| {
        let o = bin().arg("loft").args(files).args(args).arg("-o").arg(dir.join("v.json")).output().unwrap();
        assert_eq!(o.status.code(), Some(1), "{}", text(&o));
        text(&o)
    };
    assert!(run(&["--z", "0,0"], &[&sq, &sq]).contains("increase strictly"));
    assert!(run(&["--z", "0,1,2"], &[&sq, &sq]).contains("one z per slice"));
    assert!(run(&[], &[&sq, &sq]).contains("--z"));
    // a folded slice
    let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&sq).unwrap()).unwrap();
    let cps = doc["map"]["control_points"].as_array_mut().unwrap();
    let n = cps.len();
    cps[n / 2] = serde_json::json!([50.0, -50.0]);
    let folded = dir.join("folded.json");
    std::fs::write(&folded, doc.to_string()).unwrap();
    let e = run(&["--dz", "1"], &[&sq, &folded]);
    assert!(e.contains("slice 1") && e.contains("not certified"), "{e}");
}

/// A trilinear volume document with its middle control point pushed across its neighbour: `check` says
/// folded (exit 3) with a point inside the moved function's support.
#[test]
fn check_finds_a_fold_in_a_volume() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let g = [0.0, 0.5, 1.0];
    let mut cps = Vec::new();
    for (k, &z) in g.iter().enumerate() {
        for (j, &y) in g.iter().enumerate() {
            for (i, &x) in g.iter().enumerate() {
                cps.push(if (i, j, k) == (1, 1, 1) { [1.5, y, z] } else { [x, y, z] });
            }
        }
    }
    let kv = [0.0, 0.0, 0.5, 1.0, 1.0];
    let doc = serde_json::json!({ "name": "planted", "map": { "degree": [1, 1, 1], "knots": [kv, kv, kv],
        "control_points": cps, "weights": null } });
    let path = dir.join("planted.json");
    std::fs::write(&path, doc.to_string()).unwrap();
    let o = bin().arg("check").arg(&path).arg("--json").output().unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let v = &r["certificate"]["verdict"];
    assert_eq!(v["kind"], "folded");
    assert!(v["value"].as_f64().unwrap() < 0.0, "{v}");
    assert!(v["param"].as_array().unwrap().iter().all(|x| (0.0..=1.0).contains(&x.as_f64().unwrap())), "{v}");
}
