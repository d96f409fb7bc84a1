//! `winslow solve VOLUME_BOUNDARY.json -o volume.json` end to end: every bundled volume
//! boundary (tests/data/volumes, made by scripts/volume-geometries.py) gives a certified
//! volume that keeps its faces, that `check` certifies again and `mesh` meshes with
//! hexahedra; a bad boundary is a typed error that names the face, nothing written.

mod common;

use common::{bin, data, read_json, stdout_json};

const GEOMETRIES: [&str; 5] = ["twisted-duct", "curved-pipe", "bulged-hex", "bracket", "blade-passage"];

#[test]
fn every_bundled_volume_boundary_is_certified_checked_and_meshed() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    for name in GEOMETRIES {
        let input = data().join(format!("volumes/{name}.json"));
        let out = dir.join(format!("{name}.json"));
        let o = bin().arg("solve").arg(&input).arg("-o").arg(&out).arg("--json").output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{name}: {}", String::from_utf8_lossy(&o.stderr));
        let r = stdout_json(&o);
        assert_eq!(r["certificate"]["verdict"]["kind"], "certified", "{name}");
        assert_eq!(r["report"]["boundary_kept"], true, "{name}");
        assert!(r["report"]["boundary_deviation"].as_f64().unwrap() < 1e-9, "{name}");
        let doc = read_json(&out);
        assert_eq!(doc["map"]["degree"].as_array().unwrap().len(), 3, "{name}");
        assert_eq!(doc["report"]["verdict"], "certified", "{name}");
        let c = bin().arg("check").arg(&out).arg("--json").output().unwrap();
        assert_eq!(c.status.code(), Some(0), "{name}");
        let cr = stdout_json(&c);
        assert_eq!(
            (cr["kind"].as_str(), cr["certificate"]["verdict"]["kind"].as_str()),
            (Some("volume"), Some("certified"))
        );
        let mesh = dir.join(format!("{name}.vtu"));
        let m =
            bin().arg("mesh").arg(&out).arg("-o").arg(&mesh).args(["--structured", "5x4x3", "-q"]).output().unwrap();
        assert!(m.status.success(), "{name}: {}", String::from_utf8_lossy(&m.stderr));
        assert!(std::fs::read_to_string(&mesh).unwrap().contains("NumberOfCells=\"24\""), "{name}");
    }
}

#[test]
fn a_bad_volume_boundary_is_refused_naming_the_face() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let mut doc = read_json(&data().join("volumes/bulged-hex.json"));
    // the top face moved up: its edges leave the side faces
    for p in doc["volume_boundary"]["top"]["control_points"].as_array_mut().unwrap() {
        p[2] = serde_json::json!(p[2].as_f64().unwrap() + 0.1);
    }
    let input = dir.join("bad.json");
    winslow::io::write_bytes(&input, doc.to_string().as_bytes()).unwrap();
    let out = dir.join("out.json");
    let o = bin().arg("solve").arg(&input).arg("-o").arg(&out).output().unwrap();
    assert!(!o.status.success());
    assert!(!out.exists());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("volume boundary") && err.contains("top"), "{err}");
    // a planar-only output is refused before the work
    let good = data().join("volumes/bulged-hex.json");
    let png = dir.join("v.png");
    let o = bin().arg("solve").arg(&good).arg("-o").arg(&out).arg("--png").arg(&png).output().unwrap();
    assert!(!o.status.success() && !out.exists() && !png.exists());
}
