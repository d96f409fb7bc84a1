//! The `winslow` binary end to end: `inspect` on every shared geometry (JSON and G+Smo
//! XML), `solve` writing a map + report + PNG + VTK that read back, clear errors on bad
//! input, and `bench` printing its table.

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_winslow"))
}

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data")
}

fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    v.sort();
    v
}

#[test]
fn inspect_every_shared_geometry() {
    let mut all = files(&data(), "json");
    all.extend(files(&data().join("gismo"), "json"));
    all.extend(files(&data().join("gismo/xml"), "xml"));
    assert!(all.len() >= 32, "{} files", all.len());
    for f in all {
        let out = bin().arg("inspect").arg(&f).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{}: {text}{}", f.display(), String::from_utf8_lossy(&out.stderr));
        for needle in [
            "south",
            "east",
            "north",
            "west",
            "knots",
            "corner",
            "orientation CounterClockwise",
            "contour fit: tolerance",
            "no problems found",
        ] {
            assert!(text.contains(needle), "{}: missing {needle:?} in\n{text}", f.display());
        }
    }
}

#[test]
fn solve_writes_map_report_png_and_vtk() {
    let dir = std::env::temp_dir().join(format!("winslow-cli-{}", std::process::id()));
    let map = dir.join("lid.json");
    let png = dir.join("lid.png");
    let vtk = dir.join("lid.vtk");
    let out = bin()
        .args(["solve"])
        .arg(data().join("wavy_lid.json"))
        .arg("-o")
        .arg(&map)
        .arg("--png")
        .arg(&png)
        .arg("--vtk")
        .arg(&vtk)
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["verdict"], "positive-on-sample");
    assert!(report["levels"].as_array().unwrap().last().unwrap()["newton_iterations"].as_u64().unwrap() <= 5);
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&map).unwrap()).unwrap();
    assert_eq!(doc["map"]["degree"], serde_json::json!([3, 3]));
    assert_eq!(doc["report"]["verdict"], "positive-on-sample");
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    assert!(std::fs::read_to_string(&vtk).unwrap().starts_with("# vtk DataFile"));
    // the written map is itself accepted as input (its four boundary curves)
    let again = bin().arg("inspect").arg(&map).output().unwrap();
    assert!(again.status.success());
    let render = bin().arg("render").arg(&map).arg("--png").arg(dir.join("again.png")).output().unwrap();
    assert!(render.status.success());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_input_is_a_clear_error_not_a_panic() {
    let dir = std::env::temp_dir().join(format!("winslow-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        ("truncated.json", r#"{"name": "x", "boundary": {"south": {"degree": 1, "knots": [0, 0, 1"#, "malformed JSON"),
        (
            "gap.json",
            r#"{"name":"g","boundary":{"south":{"points":[[0,0],[1,0]]},"east":{"points":[[1,0],[1,1]]},"north":{"points":[[0,1],[1,1]]},"west":{"points":[[0,0.5],[0,1]]}}}"#,
            "corner gap",
        ),
        (
            "cw.json",
            r#"{"name":"c","boundary":{"south":{"points":[[0,0],[0,1]]},"east":{"points":[[0,1],[1,1]]},"north":{"points":[[1,0],[1,1]]},"west":{"points":[[0,0],[1,0]]}}}"#,
            "clockwise",
        ),
    ];
    for (name, text, needle) in cases {
        let f = dir.join(name);
        std::fs::write(&f, text).unwrap();
        let out = bin().arg("solve").arg(&f).arg("-o").arg(dir.join("out.json")).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains(needle), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
    // reorienting fixes the clockwise one
    let out = bin()
        .arg("solve")
        .arg(dir.join("cw.json"))
        .arg("--reorient")
        .arg("-o")
        .arg(dir.join("out.json"))
        .arg("-q")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bench_prints_a_table() {
    let out =
        bin().arg("bench").arg(data().join("quarter_annulus.json")).args(["--refinements", "0,1"]).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("| geometry | refine | DOFs |")
            && text.lines().filter(|l| l.starts_with("| quarter_annulus")).count() == 2,
        "{text}"
    );
}

/// `--reparam`: the default `auto` picks constrained cord length on the narrow tube, the
/// report carries the matched pairs (same parameter, a point on each side, within the
/// matching distance), the summary prints them, and the PNG is written with them drawn;
/// `--reparam none` reports no matches.
#[test]
fn solve_reports_reparameterization_and_matches() {
    let dir = std::env::temp_dir().join(format!("winslow-reparam-{}", std::process::id()));
    let map = dir.join("tube.json");
    let png = dir.join("tube.png");
    let out = bin()
        .arg("solve")
        .arg(data().join("narrow_tube.json"))
        .arg("-o")
        .arg(&map)
        .arg("--png")
        .arg(&png)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        text.contains("reparameterization: constrained (requested auto)") && text.contains("basis functions:"),
        "{text}"
    );
    assert!(text.contains("south/north at "), "{text}");
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&map).unwrap()).unwrap();
    let rp = &doc["report"]["reparam"];
    assert_eq!(rp["used"], "constrained");
    let matches = rp["matches"].as_array().unwrap();
    assert!(!matches.is_empty());
    for m in matches {
        let t = m["parameter"].as_f64().unwrap();
        assert!(t > 0.0 && t < 1.0);
        let p: Vec<Vec<f64>> = serde_json::from_value(m["points"].clone()).unwrap();
        // the tube's gaps are narrow: matched points are close (the threshold is a
        // fraction of the tube's length)
        assert!((p[0][0] - p[1][0]).hypot(p[0][1] - p[1][1]) < 0.05 * doc["report"]["diameter"].as_f64().unwrap());
    }
    assert!(doc["report"]["basis_functions"].as_u64().unwrap() > 0);
    let none = bin()
        .arg("solve")
        .arg(data().join("narrow_tube.json"))
        .args(["--reparam", "none", "--json", "-o"])
        .arg(dir.join("none.json"))
        .output()
        .unwrap();
    let report: serde_json::Value = serde_json::from_slice(&none.stdout).unwrap();
    assert_eq!(report["reparam"]["used"], "none");
    assert!(report["reparam"]["matches"].as_array().unwrap().is_empty());
    std::fs::remove_dir_all(&dir).ok();
}
