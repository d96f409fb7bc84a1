//! General planar domains through the `winslow` binary: `solve DOMAIN.json` (automatic
//! layout, then the multipatch solve) writing the JSON document whose patches name their
//! face and the layout's report, G+Smo XML and a PNG; `layout DOMAIN.json` writing the
//! layout (which `solve` takes) and its picture; typed errors with exit code 1.

mod common;

use common::{bin, data, read_json, stdout_json};
use winslow::io::multipatch::json::parse_json_multipatch;

#[test]
fn solve_a_curved_pentagon_and_an_l_bracket() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    for (name, patches) in [("pentagon", 5), ("l_bracket", 3), ("hexagon_cloud", 6)] {
        let (json, xml, png) =
            (dir.join(format!("{name}.json")), dir.join(format!("{name}.xml")), dir.join(format!("{name}.png")));
        let out = bin()
            .arg("solve")
            .arg(data().join(format!("domains/{name}.json")))
            .arg("-o")
            .arg(&json)
            .arg("--gismo")
            .arg(&xml)
            .arg("--png")
            .arg(&png)
            .arg("--json")
            .output()
            .unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let report = stdout_json(&out);
        assert_eq!(report["verdicts"], serde_json::json!(vec!["certified"; patches]), "{name}: {}", report["message"]);
        assert_eq!(report["interface_mismatch"], 0.0);
        assert_eq!(report["auto_layout"]["patches"], patches);
        // the written document: every patch a map naming its face, read back as a layout
        let doc = read_json(&json);
        for p in doc["patches"].as_array().unwrap() {
            assert_eq!(p["face"], "domain", "{name}");
        }
        assert!(!doc["report"]["auto_layout"]["faces"].as_array().unwrap().is_empty());
        let back = parse_json_multipatch(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(back.patches.len(), patches);
        assert!(back.patches.iter().all(|p| p.face.as_deref() == Some("domain")));
        assert!(std::fs::read_to_string(&xml).unwrap().contains("<MultiPatch"));
        assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    }
}

#[test]
fn layout_writes_a_layout_that_solve_takes() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let (layout, png, solved) = (dir.join("l.json"), dir.join("l.png"), dir.join("l-map.json"));
    let out = bin()
        .arg("layout")
        .arg(data().join("domains/l_bracket.json"))
        .arg("-o")
        .arg(&layout)
        .arg("--png")
        .arg(&png)
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report = stdout_json(&out);
    assert_eq!(report["patches"], 3);
    assert_eq!(report["cuts"].as_array().unwrap().len(), 2);
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    let doc = read_json(&layout);
    assert_eq!(doc["patches"].as_array().unwrap().len(), 3);
    assert_eq!(doc["patches"][0]["face"], "domain");
    let out = bin().arg("solve").arg(&layout).arg("-o").arg(&solved).arg("-q").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(read_json(&solved)["patches"][2]["face"], "domain");
}

#[test]
fn bad_domains_are_typed_errors() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    for (doc, want) in [
        // not closed
        (
            r#"{"domain": {"outer": {"curves": [{"points": [[0,0],[1,0]]}, {"points": [[1,0],[1,1]]}, {"points": [[1,1],[0,0.5]]}]}}}"#,
            "outer loop, curve 2",
        ),
        // a hole crossing the outer loop
        (
            r#"{"domain": {"outer": {"points": [[0,0],[4,0],[4,4],[0,4]], "corners": [0,1,2,3]},
                           "holes": [{"points": [[3,1],[5,1],[5,2],[3,2]], "corners": [0,1,2,3]}]}}"#,
            "hole 0",
        ),
    ] {
        let input = dir.join("bad.json");
        winslow::io::file::write_bytes(&input, doc.as_bytes()).unwrap();
        for cmd in ["solve", "layout"] {
            let out = bin().arg(cmd).arg(&input).arg("-o").arg(dir.join("never.json")).output().unwrap();
            assert_eq!(out.status.code(), Some(1), "{cmd}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(err.contains(want), "{cmd}: {want}: {err}");
            assert!(!dir.join("never.json").exists());
        }
    }
}

/// The surface groups (`2 TAG "NAME"`) of a Gmsh file's `$PhysicalNames`.
fn surface_groups(msh: &std::path::Path) -> Vec<String> {
    let text = std::fs::read_to_string(msh).unwrap();
    let block = text.split("$PhysicalNames").nth(1).unwrap().split("$EndPhysicalNames").next().unwrap();
    block.lines().filter(|l| l.starts_with("2 ")).map(|l| l.split('"').nth(1).unwrap().to_string()).collect()
}

#[test]
fn a_plane_graph_is_laid_out_solved_and_meshed_by_face() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let graph = data().join("domains/motor12.json");
    let (layout, png, solved, msh) = (dir.join("l.json"), dir.join("l.png"), dir.join("m.json"), dir.join("m.msh"));
    let out =
        bin().arg("layout").arg(&graph).arg("-o").arg(&layout).arg("--png").arg(&png).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report = stdout_json(&out);
    // 12 slots, 12 teeth, rotor, air gap and yoke; the shaft is a void
    assert_eq!(report["graph"]["faces"].as_array().unwrap().len(), 27);
    assert_eq!(report["graph"]["voids"], 1);
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    let out = bin().arg("solve").arg(&graph).arg("-o").arg(&solved).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report = stdout_json(&out);
    assert_eq!(report["interface_mismatch"], 0.0);
    assert!(report["verdicts"].as_array().unwrap().iter().all(|v| v == "certified"), "{}", report["message"]);
    let doc = read_json(&solved);
    let faces: std::collections::BTreeSet<String> =
        doc["patches"].as_array().unwrap().iter().map(|p| p["face"].as_str().unwrap().to_string()).collect();
    assert_eq!(faces.len(), 27);
    for want in ["rotor", "airgap", "yoke", "slot-0", "tooth-11"] {
        assert!(faces.contains(want), "{want}: {faces:?}");
    }
    // one conforming mesh, one physical surface per face
    let out =
        bin().arg("mesh").arg(&solved).arg("-o").arg(&msh).arg("--structured").arg("5x5").arg("-q").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let groups: std::collections::BTreeSet<String> = surface_groups(&msh).into_iter().collect();
    assert_eq!(groups, faces);
    // and one conforming triangulation, the same groups
    let tri = dir.join("t.msh");
    let out =
        bin().args(["mesh", "--unstructured", "--size", "0.1", "-q", "-o"]).arg(&tri).arg(&solved).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let groups: std::collections::BTreeSet<String> = surface_groups(&tri).into_iter().collect();
    assert_eq!(groups, faces);
}

#[test]
fn bad_graphs_are_typed_errors() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let square = r#""vertices": [[0,0],[1,0],[1,1],[0,1]], "edges": [{"from":0,"to":1},{"from":1,"to":2},{"from":2,"to":3},{"from":3,"to":0}"#;
    for (doc, want) in [
        (format!(r#"{{"graph": {{{square}, {{"from":0,"to":2}}, {{"from":1,"to":3}}]}}}}"#), "graph edge 5"),
        (format!(r#"{{"graph": {{{square}, {{"from":0,"to":9}}]}}}}"#), "graph edge 4"),
        (format!(r#"{{"graph": {{{square}], "labels": [{{"name": "x", "point": [7, 7]}}]}}}}"#), "graph label 0 (x)"),
    ] {
        let input = dir.join("bad.json");
        winslow::io::file::write_bytes(&input, doc.as_bytes()).unwrap();
        for cmd in ["solve", "layout"] {
            let out = bin().arg(cmd).arg(&input).arg("-o").arg(dir.join("never.json")).output().unwrap();
            assert_eq!(out.status.code(), Some(1), "{cmd}: {doc}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(err.contains(want), "{cmd}: {want}: {err}");
            assert!(!dir.join("never.json").exists());
        }
    }
}

/// `convert LAYOUT --outline`: the plate with a hole's two hand-made patches give a
/// domain of five corners (the arc's halves merged), which `solve` lays out into five
/// certified patches covering the same area; a map is refused with exit code 1.
#[test]
fn convert_outline_writes_the_domain_of_a_layout() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let (domain, solved) = (dir.join("plate-domain.json"), dir.join("plate.json"));
    let hand = data().join("gismo/xml/multipatch/plateWithHoleMP.xml");
    let out = bin().arg("convert").arg(&hand).arg("--outline").arg("-o").arg(&domain).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc = read_json(&domain);
    assert_eq!(doc["domain"]["outer"]["curves"].as_array().unwrap().len(), 5);
    assert!(doc["domain"].get("holes").is_none_or(|h| h.as_array().unwrap().is_empty()));
    // every side kept: six
    let six = dir.join("plate-six.json");
    let out = bin().args(["convert", "--outline", "--smooth-below", "0", "-o"]).arg(&six).arg(&hand).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(read_json(&six)["domain"]["outer"]["curves"].as_array().unwrap().len(), 6);
    let out = bin().arg("solve").arg(&domain).arg("-o").arg(&solved).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report = stdout_json(&out);
    assert_eq!(report["verdicts"], serde_json::json!(vec!["certified"; 5]), "{}", report["message"]);
    // the quarter plate [-4, 0] x [0, 4] without the unit disc
    let area = 16.0 - std::f64::consts::PI / 4.0;
    let got = report["layout"]["area"].as_f64().unwrap();
    assert!((got - area).abs() < 1e-5 * area, "{got} {area}");
    // a map has no outline
    let out = bin()
        .arg("convert")
        .arg(data().join("maps/skewed_square.json"))
        .arg("--outline")
        .arg("-o")
        .arg(dir.join("no.json"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(!dir.join("no.json").exists());
}

/// A flat corner with no straight cut along its bisector inside its face (the corpus's
/// `wiggly-17`, face 5: a 180° corner on a wiggly edge) is cut straight to a point
/// searched along the sides (`spread` in the cut's report; before, a curved cut split its
/// 180° into 1° and 179°): its new angles stay at least 30° from 0° and 180°, and every
/// patch of the layout is certified.
#[test]
fn a_flat_corner_without_a_straight_bisector_cut_is_cut_far_from_0_and_180_degrees() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let corpus = dir.join("corpus");
    let gen = bin()
        .args(["corpus", "--general", "--families", "wiggly", "--seed", "17", "--per-family", "1", "-q", "-o"])
        .arg(&corpus)
        .output()
        .unwrap();
    assert!(gen.status.success(), "{}", String::from_utf8_lossy(&gen.stderr));
    let out = bin()
        .arg("solve")
        .arg(corpus.join("wiggly-17.json"))
        .arg("-o")
        .arg(dir.join("wiggly-17-map.json"))
        .args(["--json", "-q"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report = stdout_json(&out);
    let verdicts = report["verdicts"].as_array().unwrap();
    assert!(!verdicts.is_empty() && verdicts.iter().all(|v| v == "certified"), "{}", report["message"]);
    let cuts = report["auto_layout"]["cuts"].as_array().unwrap();
    let spread: Vec<_> = cuts.iter().filter(|c| c["spread"] == true).collect();
    assert!(!spread.is_empty(), "no searched cut end in {cuts:?}");
    // one starts from a flat corner and splits its 180° far from 0° and 180°
    let flat = spread.iter().filter(|c| (c["angle"].as_f64().unwrap() - 180.0).abs() < 1.0);
    let mut n = 0;
    for c in flat {
        let new: Vec<f64> = c["new_angles"].as_array().unwrap().iter().map(|a| a.as_f64().unwrap()).collect();
        assert!((new[0] + new[1] - 180.0).abs() < 1e-6 && new.iter().all(|&a| a > 30.0 && a < 150.0), "{c}");
        n += 1;
    }
    assert!(n > 0, "no cut from a flat corner in {cuts:?}");
    assert!(report["auto_layout"]["corner_angles"][0].as_f64().unwrap() > 29.0);
}
