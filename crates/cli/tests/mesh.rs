//! `winslow mesh` and `winslow solve --mesh` end to end.

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_winslow"))
}

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data")
}

fn run(args: &[&str]) -> (bool, String, String) {
    let out = bin().args(args).output().unwrap();
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

#[test]
fn solve_then_mesh_in_every_format() {
    let dir = std::env::temp_dir().join(format!("winslow-cli-mesh-{}", std::process::id()));
    let d = |f: &str| dir.join(f).to_string_lossy().into_owned();
    let lid = data().join("wavy_lid.json").to_string_lossy().into_owned();
    // solve and mesh in one command: boundary layers at the south side
    let (ok, out, err) = run(&[
        "solve",
        &lid,
        "--basis",
        "fitted",
        "-o",
        &d("lid.json"),
        "-q",
        "--mesh",
        &d("lid.msh"),
        "--structured",
        "21x31",
        "--cluster",
        "south:first-height:1e-3:1.3",
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("nodes / cells                651 / 600"), "{out}");
    assert!(out.contains("inverted cells               0"), "{out}");
    assert!(std::fs::read_to_string(d("lid.msh")).unwrap().starts_with("$MeshFormat\n4.1 0 8\n"));
    for (o, extra) in [
        ("lid.su2", vec!["--structured", "11x9", "--cluster", "eta:arctan:6"]),
        ("lid.xyz", vec!["--structured", "11x9", "--cluster", "xi:tanh:2"]),
        ("lid.vtu", vec!["--unstructured", "--size", "0.1", "--order", "2"]),
        ("lid-case/", vec!["--unstructured", "--size", "0.1", "--min-angle", "25"]),
        ("lid-eq.msh", vec!["--structured", "5x5", "--equidistribute", "xi:curvature:1e-3"]),
        ("lid-arc.msh", vec!["--structured", "11x5", "--equidistribute", "arclength"]),
    ] {
        let mut args = vec!["mesh", &*Box::leak(d("lid.json").into_boxed_str()), "-o"];
        let o = Box::leak(d(o).into_boxed_str());
        args.push(o);
        args.extend(extra.iter().copied());
        let (ok, out, err) = run(&args);
        assert!(ok, "{args:?}: {err}");
        assert!(out.contains("wrote"), "{out}");
        if extra.contains(&"--unstructured") {
            assert!(out.contains("meshing: boundary"), "{out}");
        }
        if extra.contains(&"xi:curvature:1e-3") {
            // the wavy lid (north) needs more than 5 points along xi for a chord of 1e-3
            let nodes: usize =
                out.split("nodes / cells").nth(1).unwrap().split('/').next().unwrap().trim().parse().unwrap();
            assert!(nodes > 25 && nodes.is_multiple_of(5), "{out}");
        }
    }
    assert!(dir.join("lid-case/constant/polyMesh/owner").exists());
    // refusals: a boundary is not a map; PLOT3D holds no triangles; bad specs
    let (ok, _, err) = run(&["mesh", &lid, "-o", &d("x.msh"), "--structured", "5x5"]);
    assert!(!ok && err.contains("a boundary document, where mesh needs a map"), "{err}");
    let (ok, _, err) = run(&["mesh", &d("lid.json"), "-o", &d("x.xyz"), "--unstructured", "--size", "0.2"]);
    assert!(!ok && err.contains("PLOT3D"), "{err}");
    let (ok, _, err) =
        run(&["mesh", &d("lid.json"), "-o", &d("x.msh"), "--structured", "5x5", "--cluster", "up:arctan:2"]);
    assert!(!ok && err.contains("--cluster"), "{err}");
    let (ok, _, err) = run(&[
        "mesh",
        &d("lid.json"),
        "-o",
        &d("x.msh"),
        "--unstructured",
        "--size",
        "0.2",
        "--equidistribute",
        "arclength",
    ]);
    assert!(!ok && err.contains("--equidistribute"), "{err}");
    let (ok, _, err) = run(&["mesh", &d("lid.json"), "-o", &d("x.stl"), "--structured", "5x5"]);
    assert!(!ok && err.contains("unknown mesh format"), "{err}");
    assert!(!dir.join("x.msh").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
