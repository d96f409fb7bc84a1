//! The GPU back end from the CLI: `solve` and `bench` with `--backend gpu` give the CPU's
//! results (the quadrature and the multigrid V-cycles on the GPU), `bench` prints the
//! throughput. With `WINSLOW_REQUIRE_GPU=1` (CI, lavapipe) a missing adapter is a failure.

mod common;

use common::{bin, data};

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
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().join("gpu");
    // a four-sided domain and a ring (eta periodic: replicas summed the same on both back ends)
    for geom in ["quarter_annulus.json", "rings/eccentric_annulus.json"] {
        let mut maps = Vec::new();
        for backend in ["cpu", "gpu"] {
            let map = dir.join(format!("{backend}.json"));
            let png = dir.join(format!("{backend}.png"));
            let out = bin()
                .arg("solve")
                .arg(data().join(geom))
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
        let (err, scale) = control_point_gap(&maps[0], &maps[1]);
        assert!(err <= 1e-9 * scale, "{geom}: GPU and CPU maps differ by {err:e}");
    }
}

/// `--backend gpu --linear multigrid`: the multigrid preconditioner's V-cycles and
/// GMRES's products with the Newton Jacobian run on the GPU (the report's back end counts
/// them: at least one product per GMRES iteration) and the solve takes the CPU's Newton
/// and GMRES iterations on every level and writes its map to 1e-9.
#[test]
fn multigrid_cycles_on_the_gpu_give_the_cpu_solve() {
    if !gpu_available_or_required() {
        return;
    }
    let scratch = tempfile::tempdir().unwrap();
    let mut runs = Vec::new();
    for backend in ["cpu", "gpu"] {
        let map = scratch.path().join(format!("{backend}.json"));
        let out = bin()
            .arg("solve")
            .arg(data().join("quarter_annulus.json"))
            .arg("-o")
            .arg(&map)
            .args(["--backend", backend, "--linear", "multigrid", "--min-elements", "40", "-q"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{backend}: {}", String::from_utf8_lossy(&out.stderr));
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&map).unwrap()).unwrap();
        runs.push(doc);
    }
    let backend = runs[1]["report"]["backend"].as_str().unwrap();
    let count = |what: &str| -> usize {
        backend
            .split(what)
            .nth(1)
            .and_then(|s| s.split(|c: char| !c.is_ascii_digit()).next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("no {what} in {backend}"))
    };
    let (cycles, products) = (count("multigrid V-cycles on the GPU: "), count("Jacobian products on the GPU: "));
    assert!(cycles > 0 && !backend.contains("on the CPU after"), "{backend}");
    let levels = |d: &serde_json::Value| -> Vec<(u64, u64)> {
        d["report"]["levels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| (l["newton_iterations"].as_u64().unwrap(), l["krylov_iterations"].as_u64().unwrap()))
            .collect()
    };
    assert_eq!(levels(&runs[0]), levels(&runs[1]));
    assert!(levels(&runs[1]).iter().any(|&(_, k)| k > 0), "no GMRES iterations: {:?}", levels(&runs[1]));
    let krylov: u64 = levels(&runs[1]).iter().map(|&(_, k)| k).sum();
    assert!(products as u64 >= krylov, "{products} GPU products for {krylov} GMRES iterations: {backend}");
    let (err, scale) = control_point_gap(&runs[0]["map"], &runs[1]["map"]);
    assert!(err <= 1e-9 * scale, "GPU and CPU multigrid maps differ by {err:e}");
    // `bench` runs the same path and its JSON rows name the back end with the cycles
    let out = bin()
        .arg("bench")
        .arg(data().join("quarter_annulus.json"))
        .args(["--refinements", "2", "--backend", "gpu", "--linear", "multigrid", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let row: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let backend = row["backend"].as_str().unwrap();
    assert!(backend.starts_with("gpu") && backend.contains("multigrid V-cycles on the GPU: "), "{backend}");
    assert!(!backend.contains("V-cycles on the GPU: 0"), "{backend}");
    assert!(
        backend.contains("Jacobian products on the GPU: ") && !backend.contains("products on the GPU: 0"),
        "{backend}"
    );
}

/// A count and the bytes `[up, down]` per one of them.
type Counted = (u64, [u64; 2]);

/// The bytes over the bus in `report.backend` (`"...; bus: U B up, D B down in all;
/// per Newton step (N): u B up, d B down; per GMRES iteration (P): u B up, d B down"`),
/// as `[up, down]` for "in all", each Newton step and each GMRES iteration, with N and P.
fn bus(backend: &str) -> ([u64; 2], Counted, Counted) {
    let num = |s: &str| -> u64 { s.trim().parse().unwrap_or_else(|_| panic!("no number in {s:?}: {backend}")) };
    let pair = |s: &str| -> [u64; 2] {
        let (up, down) = s.split_once(" B up, ").unwrap_or_else(|| panic!("{s:?}: {backend}"));
        [num(up), num(down.split(" B down").next().unwrap())]
    };
    let part = |key: &str| backend.split(key).nth(1).unwrap_or_else(|| panic!("no {key:?} in {backend}"));
    let counted = |key: &str| {
        let s = part(key);
        let (count, rest) = s.split_once("): ").unwrap();
        (num(count), pair(rest))
    };
    (pair(part("; bus: ")), counted("; per Newton step ("), counted("; per GMRES iteration ("))
}

/// `report.backend` counts the bytes over the bus. With the Newton Jacobian assembled
/// on the device (the default) each Newton step moves less than with `--gpu-jacobian
/// host` (read back in `f64`, uploaded in `f32`): the difference down is twice the
/// difference up (8 and 4 bytes per stencil entry), the GMRES iterations move the same
/// (a vector up for each one down), and the solves are the same.
#[test]
fn the_device_jacobian_does_not_cross_the_bus() {
    if !gpu_available_or_required() {
        return;
    }
    let scratch = tempfile::tempdir().unwrap();
    let mut runs = Vec::new();
    for jac in ["device", "host"] {
        let map = scratch.path().join(format!("{jac}.json"));
        let out = bin()
            .arg("solve")
            .arg(data().join("quarter_annulus.json"))
            .arg("-o")
            .arg(&map)
            .args(["--backend", "gpu", "--linear", "multigrid", "--gpu-jacobian", jac, "--min-elements", "40", "-q"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{jac}: {}", String::from_utf8_lossy(&out.stderr));
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&map).unwrap()).unwrap();
        let backend = doc["report"]["backend"].as_str().unwrap().to_string();
        assert!(!backend.contains("on the CPU after"), "{jac}: {backend}");
        runs.push((bus(&backend), doc));
    }
    let ((all_d, (steps_d, step_d), (its_d, it_d)), doc_d) = &runs[0];
    let ((all_h, (steps_h, step_h), (its_h, it_h)), doc_h) = &runs[1];
    assert_eq!((steps_d, its_d, it_d), (steps_h, its_h, it_h));
    assert!(*steps_d > 0 && *its_d > 0);
    assert_eq!(it_d[0], it_d[1], "per GMRES iteration a vector goes up for each that comes down");
    let (more_up, more_down) = (step_h[0] - step_d[0], step_h[1] - step_d[1]);
    assert!(more_up > 0, "{step_h:?} against {step_d:?}");
    // averages of integer sums over the same steps: each rounded down
    assert!(more_down.abs_diff(2 * more_up) <= 2, "{more_down} down for {more_up} up");
    assert!(all_h[1] > all_d[1] && all_h[0] > all_d[0]);
    assert_eq!(doc_d["map"], doc_h["map"]);
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

/// The largest difference between two JSON maps' control point coordinates, and the
/// largest coordinate of the first (the maps must have as many control points).
fn control_point_gap(a: &serde_json::Value, b: &serde_json::Value) -> (f64, f64) {
    let pts = |m: &serde_json::Value| -> Vec<f64> {
        m["control_points"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|p| p.as_array().unwrap().clone())
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (a, b) = (pts(a), pts(b));
    assert_eq!(a.len(), b.len());
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let err = a.iter().zip(&b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    (err, scale)
}
