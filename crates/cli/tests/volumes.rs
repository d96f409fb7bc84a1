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

/// The faces of `curved-pipe` (exact NURBS) as a G+Smo multipatch
/// (`tests/data/volumes/curved-pipe-faces.xml`, written by `winslow convert`): the
/// committed file is what the writer writes, it reads back as the same faces, and
/// `solve` on it gives the volume of the JSON input bit for bit, written as G+Smo
/// `TensorNurbs3` too, which `check` certifies.
#[test]
fn the_faces_as_a_gismo_multipatch_end_to_end() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let json_in = data().join("volumes/curved-pipe.json");
    let xml_in = data().join("volumes/curved-pipe-faces.xml");
    let xml = dir.join("faces.xml");
    let o = bin().arg("convert").arg(&json_in).arg("-o").arg(&xml).arg("-q").output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read_to_string(&xml).unwrap(), std::fs::read_to_string(&xml_in).unwrap());
    let back = dir.join("back.json");
    let o = bin().arg("convert").arg(&xml_in).arg("-o").arg(&back).arg("-q").output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(read_json(&back)["volume_boundary"], read_json(&json_in)["volume_boundary"]);
    let (from_json, from_xml, vol_xml) = (dir.join("a.json"), dir.join("b.json"), dir.join("b.xml"));
    let o = bin().arg("solve").arg(&json_in).arg("-o").arg(&from_json).arg("-q").output().unwrap();
    assert_eq!(o.status.code(), Some(0));
    let o = bin().arg("solve").arg(&xml_in).arg("-o").arg(&from_xml).arg("--gismo").arg(&vol_xml).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(read_json(&from_json)["map"], read_json(&from_xml)["map"]);
    assert!(std::fs::read_to_string(&vol_xml).unwrap().contains("TensorNurbs3"));
    let c = bin().arg("check").arg(&vol_xml).arg("--json").output().unwrap();
    assert_eq!(c.status.code(), Some(0));
    assert_eq!(stdout_json(&c)["certificate"]["verdict"]["kind"], "certified");
}

/// Five faces, and a face whose edge leaves its neighbour: typed errors naming the
/// face (and the edge), nothing written.
#[test]
fn a_bad_gismo_face_set_is_refused_naming_the_face() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let text = std::fs::read_to_string(data().join("volumes/curved-pipe-faces.xml")).unwrap();
    let five = text.replace("<patches type=\"id_range\">0 5</patches>", "<patches type=\"id_range\">0 4</patches>");
    // the first control point of the top face (geometry 5), a corner, moved
    let top = text.find("<Geometry type=\"TensorNurbs2\" id=\"5\">").unwrap();
    let at = top + text[top..].find("<coefs geoDim=\"3\">").unwrap() + "<coefs geoDim=\"3\">".len();
    let start = at + 1;
    let end = start + text[start..].find('\n').unwrap();
    let moved = format!("{}      0.123 0.456 0.789{}", &text[..start], &text[end..]);
    for (name, body, want) in [("five", five, "5 faces"), ("moved", moved, "Geometry id 5")] {
        let input = dir.join(format!("{name}.xml"));
        winslow::io::write_bytes(&input, body.as_bytes()).unwrap();
        let out = dir.join(format!("{name}.json"));
        let o = bin().arg("solve").arg(&input).arg("-o").arg(&out).output().unwrap();
        assert!(!o.status.success() && !out.exists(), "{name}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("volume boundary") && err.contains(want), "{name}: {err}");
    }
}

/// The method of a volume solve in the planar vocabulary: EGG (eq. 8 in 3D) by
/// default (its Newton step by GMRES, by LU with `--linear lu`), `--improve winslow` (or `--method winslow`) minimises the 3D Winslow
/// functional from the EGG map, which lowers its energy; `--improve weak` and
/// `--operator plain` (the 3D operator is the scaled one) are refused before anything is
/// written; a basis that is not `C¹` (the curved pipe is linear
/// across its wall) is solved by the Winslow functional, and the report says so.
#[test]
fn the_volume_method_follows_method_and_improve() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let input = data().join("volumes/twisted-duct.json");
    let run = |extra: &[&str], out: &str| {
        let o = bin().arg("solve").arg(&input).arg("-o").arg(dir.join(out)).arg("--json").args(extra).output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        stdout_json(&o)["report"].clone()
    };
    let egg = run(&[], "egg.json");
    assert_eq!((egg["method"].as_str(), egg["start"].as_str()), (Some("egg"), Some("coons")));
    assert!(egg["egg_iterations"].as_u64().unwrap() >= 1);
    assert!(egg["egg_relative_residual"].as_f64().unwrap() < 1e-9);
    assert!(egg["relative_gradient"].is_null());
    // the Newton step by GMRES (84 unknowns: above `auto`'s LU limit), or by LU
    assert_eq!(egg["egg_linear"].as_str(), Some("gmres"));
    assert!(egg["egg_krylov_iterations"].as_u64().unwrap() >= 1);
    let lu = run(&["--linear", "lu"], "lu.json");
    assert_eq!((lu["egg_linear"].as_str(), lu["egg_krylov_iterations"].as_u64()), (Some("lu"), Some(0)));
    assert_eq!(lu["egg_iterations"], egg["egg_iterations"]);
    assert!(lu["egg_relative_residual"].as_f64().unwrap() < 1e-9);
    for flag in [["--improve", "winslow"], ["--method", "winslow"]] {
        let w = run(&flag, "winslow.json");
        assert_eq!((w["method"].as_str(), w["start"].as_str()), (Some("egg+winslow"), Some("egg")), "{flag:?}");
        assert!(w["relative_gradient"].as_f64().unwrap() < 1e-8, "{flag:?}");
        assert!(w["energy"].as_f64().unwrap() < egg["energy"].as_f64().unwrap(), "{flag:?}");
    }
    for (flags, what) in [(["--improve", "weak"], "winslow"), (["--operator", "plain"], "--operator plain")] {
        let out = dir.join("refused.json");
        let o = bin().arg("solve").arg(&input).arg("-o").arg(&out).args(flags).output().unwrap();
        assert!(!o.status.success() && !out.exists(), "{flags:?}");
        assert!(String::from_utf8_lossy(&o.stderr).contains(what), "{flags:?}: {}", String::from_utf8_lossy(&o.stderr));
    }
    let pipe = bin()
        .arg("solve")
        .arg(data().join("volumes/curved-pipe.json"))
        .arg("-o")
        .arg(dir.join("pipe.json"))
        .arg("--json")
        .output()
        .unwrap();
    assert_eq!(pipe.status.code(), Some(0));
    assert_eq!(stdout_json(&pipe)["report"]["method"], "winslow");
}
