//! Multipatch layouts through the `winslow` binary: `solve` on a G+Smo `<MultiPatch>` file
//! with free interfaces writing G+Smo XML (read back), the JSON document, per-patch maps,
//! a VTK multiblock file and a PNG; `split` -> `solve` -> `join` on one geometry; and the
//! typed error of an inconsistent layout.

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::{bin, data};
use winslow::io::multipatch::gismo::parse_gismo_multipatch;
use winslow::io::multipatch::json::parse_json_multipatch;

fn run(cmd: &mut Command) -> (String, String) {
    let out = cmd.output().unwrap();
    let (o, e) = (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned());
    assert!(out.status.success(), "{o}{e}");
    (o, e)
}

#[test]
fn solve_a_gismo_multipatch_with_free_interfaces() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let (xml, json, vtm, png, maps) =
        (dir.join("flame.xml"), dir.join("flame.json"), dir.join("flame.vtm"), dir.join("flame.png"), dir.join("maps"));
    let (out, _) = run(bin()
        .arg("solve")
        .arg(data().join("gismo/xml/multipatch/TUDflame.xml"))
        .args(["--interfaces", "free", "-o"])
        .arg(&xml)
        .arg("--vtm")
        .arg(&vtm)
        .arg("--png")
        .arg(&png)
        .arg("--patch-maps")
        .arg(&maps)
        .arg("--json"));
    // every patch certified, the interface control points shared bit for bit
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(report["verdicts"], serde_json::json!(vec!["certified"; 5]), "{}", report["message"]);
    assert_eq!(report["interface_mismatch"], 0.0);
    // the G+Smo file reads back as a valid layout whose interfaces are shared exactly
    let layout = parse_gismo_multipatch(&std::fs::read_to_string(&xml).unwrap()).unwrap();
    winslow::multipatch::validate_layout(&layout).unwrap();
    let maps_back: Vec<_> = layout.patches.iter().map(|p| p.map.clone().unwrap()).collect();
    assert_eq!(winslow::multipatch::solve::interface_mismatch(&layout, &maps_back), 0.0);
    for m in &maps_back {
        let c = winslow::certify(m, &Default::default()).unwrap();
        assert!(matches!(c.verdict, winslow::verify::certificate::Finding::Certified { .. }), "{}", c.message());
    }
    assert!(std::fs::read_to_string(&vtm).unwrap().contains("vtkMultiBlockDataSet"));
    assert_eq!(std::fs::read_dir(dir.join("flame")).unwrap().count(), 5);
    assert_eq!(std::fs::read_dir(&maps).unwrap().count(), 5);
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    // the JSON document with the report, read back as a layout of maps
    let (out, _) = run(bin()
        .arg("solve")
        .arg(data().join("gismo/xml/multipatch/plateWithHoleMP.xml"))
        .args(["--json", "-o"])
        .arg(&json));
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(report["verdict"], "certified");
    assert_eq!(report["interface_mismatch"], 0.0);
    let l = parse_json_multipatch(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!((l.patches.len(), l.interfaces.len()), (2, 1));
}

#[test]
fn split_solve_join() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let (map, split, layout, joined) =
        (dir.join("annulus.json"), dir.join("split.json"), dir.join("layout.json"), dir.join("joined.json"));
    run(bin().arg("solve").arg(data().join("quarter_annulus.json")).arg("-q").arg("-o").arg(&map));
    let (out, _) =
        run(bin().arg("split").arg(&map).args(["--from", "south:0.5", "--to", "north:0.5", "-o"]).arg(&split));
    assert!(out.contains("split from the south side"), "{out}");
    assert!(dir.join("split-a.json").exists() && dir.join("split-b.json").exists());
    let (out, _) = run(bin()
        .arg("solve")
        .arg(&split)
        .args(["--interfaces", "free", "-o"])
        .arg(&layout)
        .arg("--patch-maps")
        .arg(dir.join("patches"))
        .arg("--json"));
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(report["verdicts"], serde_json::json!(vec!["certified"; 2]), "{}", report["message"]);
    let mut patches: Vec<PathBuf> =
        std::fs::read_dir(dir.join("patches")).unwrap().map(|e| e.unwrap().path()).collect();
    patches.sort();
    assert_eq!(patches.len(), 2);
    // a second run into the same folder would mix its patches with these: refused before
    // the solve (the old files intact), accepted with --overwrite (the old files removed)
    let before = std::fs::read(&patches[0]).unwrap();
    winslow::io::file::write_bytes(&dir.join("patches/stale.json"), b"{}").unwrap();
    let again = |overwrite: bool| {
        let mut c = bin();
        c.arg("solve").arg(&split).args(["-q", "-o"]).arg(dir.join("again.json")).arg("--patch-maps");
        c.arg(dir.join("patches"));
        if overwrite {
            c.arg("--overwrite");
        }
        c.output().unwrap()
    };
    let refused = again(false);
    let e = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(1), "{e}");
    assert!(
        e.contains("--patch-maps") && e.contains("3 file(s) of an earlier run") && e.contains("--overwrite"),
        "{e}"
    );
    assert!(!dir.join("again.json").exists());
    assert_eq!(std::fs::read(&patches[0]).unwrap(), before);
    assert!(again(true).status.success());
    assert!(!dir.join("patches/stale.json").exists());
    assert_eq!(std::fs::read_dir(dir.join("patches")).unwrap().count(), 2);
    let (out, _) = run(bin().arg("join").arg(&patches[0]).arg(&patches[1]).arg("-o").arg(&joined));
    assert!(out.contains("certified bijective") && out.contains("C0 knot"), "{out}");
    let m = match winslow::read(&joined).unwrap() {
        winslow::Document::Map { map, .. } => map,
        _ => panic!("a map"),
    };
    // a C0 knot inside xi: multiplicity p
    let bm = m.knots[0].breaks_with_multiplicity();
    assert_eq!(bm[1..bm.len() - 1].iter().map(|b| b.1).max(), Some(m.degrees()[0]));
}

#[test]
fn an_inconsistent_layout_is_a_typed_error() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let text = std::fs::read_to_string(data().join("gismo/xml/multipatch/plateWithHoleMP.xml")).unwrap();
    // flip the orientation flag of the one interface
    let bad = text.replace("1 1 0 2 0 1 1 1", "1 1 0 2 0 1 1 0");
    let f = dir.join("bad.xml");
    winslow::io::file::write_bytes(&f, bad.as_bytes()).unwrap();
    let out = bin().arg("solve").arg(&f).arg("-o").arg(dir.join("o.json")).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("multipatch layout, patch 1 (p1), west side") && e.contains("orientations inconsistent"), "{e}");
}
