//! `winslow batch`: maps, failure records and the summary of many shapes; a killed batch
//! resumes without solving a shape twice and gives the same maps.

mod common;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use common::{bin, data, read_json};

/// The map part of a written map document (its report has the times, which differ).
fn map_part(path: &Path) -> serde_json::Value {
    let mut v = read_json(path);
    v.as_object_mut().unwrap().remove("report");
    v
}

/// Inputs, a manifest with a path and an inline document, and a failing shape: one map
/// per solved shape (the same map as `winslow solve`), a typed failure record, the
/// summary in JSONL and CSV, exit code 1 (a shape failed).
#[test]
fn batch_writes_maps_failures_and_summary() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().join("out");
    let manifest = scratch.path().join("shapes.jsonl");
    let lid = std::fs::read_to_string(data().join("wavy_lid.json")).unwrap();
    let lid: serde_json::Value = serde_json::from_str(&lid).unwrap();
    let lines = [
        serde_json::json!({"name": "tube", "path": data().join("narrow_tube.json")}),
        serde_json::json!({"name": "lid-inline", "document": lid}),
    ];
    let text: String = lines.iter().map(|l| format!("{l}\n")).collect();
    winslow::io::file::write_bytes(&manifest, text.as_bytes()).unwrap();
    let out = bin()
        .arg("batch")
        .arg(data().join("gismo/duck.json"))
        .arg(data().join("rings/eccentric_annulus.json"))
        .arg(data().join("domains/l_bracket.json"))
        .arg("--manifest")
        .arg(&manifest)
        .args(["--jobs", "2", "-o"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    for name in ["duck", "eccentric_annulus", "tube", "lid-inline"] {
        let m = read_json(&dir.join(format!("{name}.json")));
        assert_eq!(m["report"]["verdict"], "certified", "{name}");
        assert_eq!(m["name"], name);
    }
    let failure = read_json(&dir.join("l_bracket.error.json"));
    assert_eq!(failure["kind"], "document_kind");
    assert_eq!(failure["status"], "failed");
    let rows: Vec<serde_json::Value> = std::fs::read_to_string(dir.join("batch.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(rows.len(), 5);
    let duck = rows.iter().find(|r| r["name"] == "duck").unwrap();
    let report = read_json(&dir.join("duck.json"))["report"].clone();
    assert_eq!(duck["unknowns"], report["levels"].as_array().unwrap().last().unwrap()["unknowns"]);
    assert_eq!(duck["quality"], report["quality"]["scaled_jacobian"]["min"]);
    let csv = std::fs::read_to_string(dir.join("batch.csv")).unwrap();
    assert_eq!(csv.lines().count(), 6);
    assert!(csv.lines().any(|l| l.starts_with("l_bracket,failed,,")));
    // the same map as `winslow solve`
    let single = scratch.path().join("duck.json");
    let st = bin().arg("solve").arg(data().join("gismo/duck.json")).arg("-o").arg(&single).arg("-q").status().unwrap();
    assert!(st.success());
    assert_eq!(map_part(&single), map_part(&dir.join("duck.json")));
}

/// Shape names must be unique file names; outputs of other shapes in the folder are
/// refused (without --overwrite), before anything is written.
#[test]
fn batch_refuses_clashing_names_and_foreign_folders() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().join("out");
    let twice = bin()
        .arg("batch")
        .arg(data().join("gismo/duck.json"))
        .arg(data().join("gismo/duck.json"))
        .arg("-o")
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(twice.status.code(), Some(1));
    assert!(!dir.exists());
    let first = bin().arg("batch").arg(data().join("gismo/duck.json")).arg("-q").arg("-o").arg(&dir).status().unwrap();
    assert_eq!(first.code(), Some(0));
    let other = bin().arg("batch").arg(data().join("quarter_annulus.json")).arg("-o").arg(&dir).output().unwrap();
    assert_eq!(other.status.code(), Some(1));
    assert!(!dir.join("quarter_annulus.json").exists());
    let fresh = bin()
        .arg("batch")
        .arg(data().join("quarter_annulus.json"))
        .args(["--overwrite", "-q", "-o"])
        .arg(&dir)
        .status();
    assert_eq!(fresh.unwrap().code(), Some(0));
    assert!(dir.join("quarter_annulus.json").exists() && !dir.join("duck.json").exists());
}

/// The maps in a batch folder and their modification times.
fn maps_in(dir: &Path) -> Vec<(PathBuf, std::time::SystemTime)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|e| e == "json"))
                .map(|p| {
                    let t = std::fs::metadata(&p).unwrap().modified().unwrap();
                    (p, t)
                })
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// A batch killed after its first map: every file in the folder reads back whole, the
/// re-run solves only the others (the maps there are not rewritten), and the maps are
/// those of an uninterrupted batch.
#[test]
fn batch_resumes_after_a_kill() {
    let scratch = tempfile::tempdir().unwrap();
    let (dir, whole) = (scratch.path().join("killed"), scratch.path().join("whole"));
    let shapes: Vec<PathBuf> = ["duck", "jigsaw01", "puzzle3", "cooks_membrane", "puzzle4", "flapping_beam"]
        .iter()
        .map(|n| data().join(format!("gismo/{n}.json")))
        .collect();
    let batch = |out: &Path| {
        let mut c = bin();
        c.arg("batch").args(&shapes).args(["--jobs", "1", "-o"]).arg(out);
        c
    };
    let mut child =
        batch(&dir).stderr(std::process::Stdio::null()).stdout(std::process::Stdio::null()).spawn().unwrap();
    let t0 = Instant::now();
    while maps_in(&dir).is_empty() && t0.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let before = maps_in(&dir);
    assert!(!before.is_empty() && before.len() < shapes.len(), "killed after {} maps", before.len());
    for (p, _) in &before {
        let (doc, report) = winslow::io::read_with_report(p).unwrap();
        assert!(matches!(doc, winslow::Document::Map { .. }) && report.is_some(), "{}", p.display());
    }
    let again = batch(&dir).output().unwrap();
    assert_eq!(again.status.code(), Some(0), "{}", String::from_utf8_lossy(&again.stderr));
    let stderr = String::from_utf8_lossy(&again.stderr);
    let expected = format!("{} done before, {} to solve", before.len(), shapes.len() - before.len());
    assert!(stderr.contains(&expected), "{stderr}");
    let after = maps_in(&dir);
    for b in &before {
        assert!(after.contains(b), "{} was written again", b.0.display());
    }
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    assert!(batch(&whole).arg("-q").status().unwrap().success());
    for s in &shapes {
        let name = format!("{}.json", s.file_stem().unwrap().to_string_lossy());
        assert_eq!(map_part(&dir.join(&name)), map_part(&whole.join(&name)), "{name}");
    }
    assert_eq!(
        std::fs::read_to_string(dir.join("batch.jsonl")).unwrap().lines().count(),
        std::fs::read_to_string(whole.join("batch.jsonl")).unwrap().lines().count()
    );
}

/// A family of perturbed ducks (every side's control points moved by the smooth field
/// `eps (sin(pi s), sin(pi t)) C_k` of the normalised position `(s, t)`), as manifest
/// lines of inline boundary documents.
fn duck_family(n: usize) -> Vec<serde_json::Value> {
    let text = std::fs::read_to_string(data().join("gismo/duck.json")).unwrap();
    let duck: serde_json::Value = serde_json::from_str(&text).unwrap();
    let points = |v: &serde_json::Value| -> Vec<[f64; 2]> {
        v.as_array().unwrap().iter().map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()]).collect()
    };
    const SIDES: [&str; 4] = ["south", "east", "north", "west"];
    let all: Vec<[f64; 2]> = SIDES.iter().flat_map(|s| points(&duck["boundary"][s]["control_points"])).collect();
    let lo = [0, 1].map(|d| all.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min));
    let hi = [0, 1].map(|d| all.iter().map(|p| p[d]).fold(f64::NEG_INFINITY, f64::max));
    let l = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    (0..n)
        .map(|k| {
            let c = [[0.3, -0.2], [0.1 * k as f64 - 0.15, 0.25 - 0.05 * k as f64]];
            let mut doc = duck.clone();
            for name in SIDES {
                let side = &mut doc["boundary"][name];
                let moved: Vec<serde_json::Value> = points(&side["control_points"])
                    .iter()
                    .map(|p| {
                        let (s, t) = ((p[0] - lo[0]) / l, (p[1] - lo[1]) / l);
                        let f = [(std::f64::consts::PI * s).sin(), (std::f64::consts::PI * t).sin()];
                        let d = [0, 1].map(|j| 0.02 * l * (f[0] * c[0][j] + f[1] * c[1][j]));
                        serde_json::json!([p[0] + d[0], p[1] + d[1]])
                    })
                    .collect();
                side["control_points"] = serde_json::Value::Array(moved);
            }
            serde_json::json!({ "name": format!("duck{k}"), "document": doc })
        })
        .collect()
}

/// `--warm-start`: two chains of three ducks, the first of each solved cold, the others
/// from the previous map: the same verdicts, and maps on the same basis within the
/// solver's tolerance of the cold batch's; a re-run of a partial folder goes on from the
/// maps there.
#[test]
fn batch_warm_start_chains() {
    let scratch = tempfile::tempdir().unwrap();
    let manifest = scratch.path().join("ducks.jsonl");
    let text: String = duck_family(6).iter().map(|l| format!("{l}\n")).collect();
    winslow::io::file::write_bytes(&manifest, text.as_bytes()).unwrap();
    let (cold, warm) = (scratch.path().join("cold"), scratch.path().join("warm"));
    let run = |out: &Path, warm: bool| {
        let mut c = bin();
        c.arg("batch").arg("--manifest").arg(&manifest).args(["--jobs", "2", "-q", "-o"]).arg(out);
        if warm {
            c.arg("--warm-start");
        }
        c.status().unwrap()
    };
    assert_eq!(run(&cold, false).code(), Some(0));
    assert_eq!(run(&warm, true).code(), Some(0));
    for k in 0..6 {
        let name = format!("duck{k}.json");
        let (c, w) = (read_json(&cold.join(&name)), read_json(&warm.join(&name)));
        assert_eq!(c["report"]["verdict"], "certified");
        assert_eq!(w["report"]["verdict"], "certified", "{name}");
        let used = w["report"]["warm_start"]["used"].as_bool().unwrap_or(false);
        assert_eq!(used, k % 3 != 0, "{name}: {}", w["report"]["warm_start"]);
        let cp = |v: &serde_json::Value| -> Vec<f64> {
            v["map"]["control_points"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()])
                .collect()
        };
        assert_eq!(c["map"]["knots"], w["map"]["knots"], "{name}");
        let (a, b) = (cp(&c), cp(&w));
        assert_eq!(a.len(), b.len());
        let d = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(d < 1e-6, "{name}: {d}");
    }
    let rows = std::fs::read_to_string(warm.join("batch.jsonl")).unwrap();
    assert!(rows.lines().all(|l| serde_json::from_str::<serde_json::Value>(l).unwrap()["unknowns"].is_u64()));
    // a partial folder: the chains go on from the maps that are there
    std::fs::remove_file(warm.join("duck2.json")).unwrap();
    assert_eq!(run(&warm, true).code(), Some(0));
    let again = read_json(&warm.join("duck2.json"));
    assert_eq!(again["report"]["warm_start"]["used"], true);
}
