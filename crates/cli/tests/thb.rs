//! THB maps from the command line: `winslow check` certifies a THB map per active cell
//! (exit 0 certified, 3 folded), `winslow convert` writes the tensor map on the knot lines
//! of its active cells (the same map, certified again) or, with `--thb`, the THB map as
//! G+Smo `THBSpline2` and back, coefficient for coefficient.

mod common;
use common::*;

use std::ffi::OsStr;
use std::path::Path;

fn run(args: &[&OsStr]) -> std::process::Output {
    bin().args(args).output().unwrap()
}

#[test]
fn check_and_convert_a_thb_map() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let src = data().join("thb/sector_thb.json");
    let os = |p: &Path| p.as_os_str().to_owned();
    // certified, active cell by active cell
    let out = run(&["check".as_ref(), &os(&src), "--json".as_ref()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let report = stdout_json(&out);
    assert_eq!(report["kind"], "thb");
    assert_eq!(report["certificate"]["verdict"]["kind"], "certified");
    let levels = report["certificate"]["levels"].as_u64().unwrap();
    assert!(levels >= 3, "{report}");
    let functions = report["certificate"]["functions"].as_u64().unwrap() as usize;
    // to a tensor map: same mean det J (the same map), certified again
    let tensor = dir.join("tensor.json");
    let out = run(&["convert".as_ref(), &os(&src), "-o".as_ref(), &os(&tensor)]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let out = run(&["check".as_ref(), &os(&tensor), "--json".as_ref()]);
    assert_eq!(out.status.code(), Some(0));
    let t = stdout_json(&out);
    let (a, b) =
        (t["certificate"]["mean_det_j"].as_f64().unwrap(), report["certificate"]["mean_det_j"].as_f64().unwrap());
    assert!((a - b).abs() < 1e-12 * b, "mean det J {a} vs {b}");
    let tensor_cps = read_json(&tensor)["map"]["control_points"].as_array().unwrap().len();
    assert!(tensor_cps > functions, "the tensor map has more unknowns ({tensor_cps}) than the THB map ({functions})");
    // THB as G+Smo XML and back to JSON: the same coefficients, bit for bit
    let xml = dir.join("sector.xml");
    let out = run(&["convert".as_ref(), &os(&src), "-o".as_ref(), &os(&xml), "--thb".as_ref()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::read_to_string(&xml).unwrap().contains("THBSpline2"));
    let back = dir.join("back.json");
    let out = run(&["convert".as_ref(), &os(&xml), "-o".as_ref(), &os(&back), "--thb".as_ref()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let (orig, again) = (read_json(&src), read_json(&back));
    assert_eq!(orig["map"]["control_points"], again["map"]["control_points"]);
    assert_eq!(orig["map"]["refined"], again["map"]["refined"]);
    // --thb writes VTU cells per active cell (one cell per active cell of the
    // certificate), refuses formats without hierarchical splines, and never replaces the input
    let vtu = dir.join("x.vtu");
    let out = run(&["convert".as_ref(), &os(&src), "-o".as_ref(), &os(&vtu), "--thb".as_ref()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let cells = report["certificate"]["cells"].as_u64().unwrap();
    assert!(std::fs::read_to_string(&vtu).unwrap().contains(&format!("NumberOfCells=\"{cells}\"")));
    let out = run(&["convert".as_ref(), &os(&src), "-o".as_ref(), &os(&dir.join("x.igs")), "--thb".as_ref()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(!dir.join("x.igs").exists());
    let out = run(&["convert".as_ref(), &os(&back), "-o".as_ref(), &os(&back), "--thb".as_ref()]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn a_folded_thb_map_exits_3() {
    let scratch = tempfile::tempdir().unwrap();
    let mut doc = read_json(&data().join("thb/sector_thb.json"));
    // pull the last (finest) function's control point to the origin, across the sector
    let cps = doc["map"]["control_points"].as_array_mut().unwrap();
    let last = cps.len() - 1;
    cps[last] = serde_json::json!([0.0, 0.0]);
    let path = scratch.path().join("folded.json");
    winslow::io::write_bytes(&path, doc.to_string().as_bytes()).unwrap();
    let out = run(&["check".as_ref(), path.as_os_str(), "--json".as_ref()]);
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stdout));
    let report = stdout_json(&out);
    assert_eq!(report["certificate"]["verdict"]["kind"], "folded");
    assert!(!report["certificate"]["folds"].as_array().unwrap().is_empty());
    // drawn (the fold in magenta), but not meshed: the inverted cells are refused
    let png = scratch.path().join("x.png");
    let out = run(&["render".as_ref(), path.as_os_str(), "--png".as_ref(), png.as_os_str()]);
    assert_eq!(out.status.code(), Some(0));
    assert!(png.exists());
    let msh = scratch.path().join("x.su2");
    let out = run(&[
        "mesh".as_ref(),
        path.as_os_str(),
        "-o".as_ref(),
        msh.as_os_str(),
        "--structured".as_ref(),
        "33x33".as_ref(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(!msh.exists());
}

/// `winslow solve --refinement thb`: puzzle4 folds without repair; the THB rounds refine
/// only around the folds and the THB map written is certified by `winslow check`, with
/// fewer functions than the tensor repair's map; the other outputs take the THB map.
#[test]
fn solve_with_thb_refinement_writes_a_certified_thb_map() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let src = data().join("gismo/puzzle4.json");
    let (thb, tensor) = (dir.join("thb.json"), dir.join("tensor.json"));
    let out = run(&[
        "solve".as_ref(),
        src.as_os_str(),
        "-o".as_ref(),
        thb.as_os_str(),
        "--refinement".as_ref(),
        "thb".as_ref(),
        "--json".as_ref(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let report = stdout_json(&out);
    assert_eq!(report["refinement"], "thb");
    assert!(!report["thb_rounds"].as_array().unwrap().is_empty());
    assert!(report["levels"].as_u64().unwrap() >= 2);
    let functions = report["functions"].as_u64().unwrap();
    let out = run(&["check".as_ref(), thb.as_os_str(), "--json".as_ref()]);
    assert_eq!(out.status.code(), Some(0));
    let checked = stdout_json(&out);
    assert_eq!(checked["kind"], "thb");
    assert_eq!(checked["certificate"]["functions"].as_u64(), Some(functions));
    let out = run(&["solve".as_ref(), src.as_os_str(), "-o".as_ref(), tensor.as_os_str(), "--json".as_ref()]);
    assert_eq!(out.status.code(), Some(0));
    let tensor_functions = stdout_json(&out)["basis_functions"].as_u64().unwrap();
    assert!(functions < tensor_functions, "THB {functions} vs tensor {tensor_functions}");
    // every output takes the THB map: VTU with one Bézier cell per active cell, IGES and
    // VTK as its exact tensor form (read back and certified: the same mean det J), the
    // Poisson benchmark on that tensor form
    let (vtu, igs, vtk) = (dir.join("x.vtu"), dir.join("x.igs"), dir.join("x.vtk"));
    let out = bin()
        .arg("solve")
        .arg(&src)
        .arg("-o")
        .arg(dir.join("again.json"))
        .arg("--vtu")
        .arg(&vtu)
        .arg("--iges")
        .arg(&igs)
        .arg("--vtk")
        .arg(&vtk)
        .args(["--refinement", "thb", "--poisson", "--json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let again = stdout_json(&out);
    assert!(again["poisson"]["q"].as_f64().unwrap().is_finite(), "{again}");
    let cells = checked["certificate"]["cells"].as_u64().unwrap();
    let text = std::fs::read_to_string(&vtu).unwrap();
    assert!(text.contains(&format!("NumberOfCells=\"{cells}\"")), "{cells} active cells");
    assert!(std::fs::read_to_string(&vtk).unwrap().starts_with("# vtk DataFile"));
    let out = run(&["check".as_ref(), igs.as_os_str(), "--json".as_ref()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let (a, b) = (
        stdout_json(&out)["certificate"]["mean_det_j"].as_f64().unwrap(),
        checked["certificate"]["mean_det_j"].as_f64().unwrap(),
    );
    assert!((a - b).abs() < 1e-10 * b.abs(), "mean det J of the IGES tensor form {a} vs the THB map's {b}");
    // a layout is repaired by tensor refinement: THB refused up front, nothing written
    let layout = data().join("gismo/xml/multipatch/plateWithHoleMP.xml");
    let out = bin().arg("solve").arg(&layout).arg("-o").arg(dir.join("mp.json")).args(["--refinement", "thb"]).output();
    assert_eq!(out.unwrap().status.code(), Some(1));
    assert!(!dir.join("mp.json").exists());
}

/// `winslow solve --refinement thb --improve winslow --png P`: the THB map is improved on
/// its own basis (the report's `improvement`, certified) and drawn with its active cells;
/// `winslow render` takes the THB map file too, `winslow mesh` (and `solve --mesh`) a
/// certified THB map through its tensor form. `--improve weak` with a THB repair is an
/// error, nothing written.
#[test]
fn a_thb_map_is_improved_drawn_and_meshed() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let src = data().join("gismo/puzzle4.json");
    let (thb, png) = (dir.join("thb.json"), dir.join("thb.png"));
    let out = bin()
        .arg("solve")
        .arg(&src)
        .arg("-o")
        .arg(&thb)
        .args(["--refinement", "thb", "--improve", "winslow", "--json", "--png"])
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let report = stdout_json(&out);
    let imp = &report["improvement"];
    assert_eq!(imp["method"], "winslow", "{report}");
    assert!(imp["unknowns"].as_u64().unwrap() > 0);
    if imp["accepted"].as_bool().unwrap() {
        assert_eq!(imp["certificate"], "certified");
        assert!(imp["winslow_after"].as_f64().unwrap() <= imp["winslow_before"].as_f64().unwrap());
    }
    assert_eq!(report["verdict"], "certified");
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    let out = run(&["check".as_ref(), thb.as_os_str(), "--json".as_ref()]);
    assert_eq!(out.status.code(), Some(0));
    let (msh, png2) = (dir.join("sector.su2"), dir.join("again.png"));
    let sector = data().join("thb/sector_thb.json");
    let out = bin().arg("mesh").arg(&sector).arg("-o").arg(&msh).args(["--structured", "9x9"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::metadata(&msh).unwrap().len() > 0);
    let out = bin().arg("render").arg(&thb).arg("--png").arg(&png2).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::read(&png2).unwrap().starts_with(b"\x89PNG"));
    // the weak form has no THB discretization
    let weak = dir.join("weak.json");
    let out = bin()
        .arg("solve")
        .arg(&src)
        .arg("-o")
        .arg(&weak)
        .args(["--refinement", "thb", "--improve", "weak"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(!weak.exists());
}
