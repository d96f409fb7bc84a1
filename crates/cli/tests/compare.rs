//! `winslow compare` end to end on a small geometry: the paper's columns per method, the
//! JSON form, one picture per method, and clear errors.

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_winslow"))
}

fn annulus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/quarter_annulus.json")
}

#[test]
fn compare_prints_the_table_and_writes_pictures() {
    let dir = std::env::temp_dir().join(format!("winslow-compare-{}", std::process::id()));
    let out = bin().arg("compare").arg(annulus()).arg("--png-dir").arg(&dir).arg("-q").output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    for col in ["method", "IT", "conv", "BIJ", "Q/Q(x_G)", "W", "Liao", "AO", "min SJ", "basis", "time [s]"] {
        assert!(text.contains(col), "missing column {col:?} in\n{text}");
    }
    let rows: Vec<&str> = text.lines().filter(|l| ["egg ", "vhm ", "qc "].iter().any(|m| l.starts_with(m))).collect();
    assert_eq!(rows.len(), 3, "{text}");
    for r in &rows {
        assert!(r.contains("certified") && r.contains(" yes "), "{r}");
    }
    // EGG is the reference of Q(x)/Q(x_G)
    assert!(rows[0].contains("1.000"), "{}", rows[0]);
    for m in ["egg", "vhm", "qc"] {
        let png = dir.join(format!("quarter_annulus-{m}.png"));
        let bytes = std::fs::read(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display()));
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    }
    std::fs::remove_dir_all(&dir).ok();
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
    assert!(String::from_utf8_lossy(&out.stderr).contains("--lambda2"));
}
