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

/// Whether a GPU test may run: an adapter is there, or `WINSLOW_REQUIRE_GPU=1` demands
/// one (then its absence fails the test through the command's error).
fn gpu_available_or_required() -> bool {
    if std::env::var("WINSLOW_REQUIRE_GPU").is_ok_and(|v| v == "1") {
        return true;
    }
    let out = bin().args(["bench", "--backend", "gpu", "--sizes", "200"]).output().unwrap();
    if !out.status.success() {
        eprintln!("note: skipping, no GPU: {}", String::from_utf8_lossy(&out.stderr));
    }
    out.status.success()
}

#[test]
fn solve_on_the_gpu_writes_the_cpu_map() {
    if !gpu_available_or_required() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("winslow-gpu-{}", std::process::id()));
    let mut maps = Vec::new();
    for backend in ["cpu", "gpu"] {
        let map = dir.join(format!("{backend}.json"));
        let png = dir.join(format!("{backend}.png"));
        let out = bin()
            .arg("solve")
            .arg(data().join("quarter_annulus.json"))
            .arg("-o")
            .arg(&map)
            .arg("--png")
            .arg(&png)
            .args(["--backend", backend, "--min-elements", "6"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{backend}: {err}");
        assert!(err.contains(&format!("backend: {backend}")), "{backend}: {err}");
        assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&map).unwrap()).unwrap();
        let backend_field = doc["report"]["backend"].as_str().unwrap().to_string();
        assert!(backend_field.starts_with(backend), "{backend_field}");
        assert!(!backend_field.contains("fell back"), "{backend_field}");
        maps.push(doc["map"].clone());
    }
    assert_eq!(maps[0]["knots"], maps[1]["knots"]);
    let pts = |m: &serde_json::Value| -> Vec<f64> {
        m["control_points"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|p| p.as_array().unwrap().clone())
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (a, b) = (pts(&maps[0]), pts(&maps[1]));
    assert_eq!(a.len(), b.len());
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let err = a.iter().zip(&b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(err <= 1e-9 * scale, "GPU and CPU maps differ by {err:e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bench_on_the_gpu_prints_throughput_and_the_time_split() {
    if !gpu_available_or_required() {
        return;
    }
    let out = bin().args(["bench", "--backend", "gpu", "--sizes", "1000,4000"]).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("quadrature throughput; back end gpu: "), "{text}");
    for col in ["CPU Mqp/s", "GPU Mqp/s", "GPU GB/s", "upload s", "dispatch s", "readback s", "scatter s"] {
        assert!(text.contains(col), "missing {col}: {text}");
    }
    // two sizes, residual and Jacobian rows each
    assert_eq!(text.lines().filter(|l| l.contains(" | F | ") || l.contains(" | J | ")).count(), 4, "{text}");
}
