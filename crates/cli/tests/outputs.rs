//! The documents and outputs of the `winslow` binary: `convert` and `render` of every
//! document they act on (and the kind named for the others), and `-q` on every command.

mod common;

use std::path::Path;

use common::{bin, data};

/// `convert` and `render` act on a ring map and on a multipatch result (every patch
/// certified again; .json, .xml, .vtm), and name the kind they got otherwise; a missing
/// file's cause is printed once.
#[test]
fn convert_and_render_take_ring_maps_and_multipatch_results() {
    use winslow::io::{Output, Patches};
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let ok = |args: &[&std::ffi::OsStr]| {
        let out = bin().args(args).output().unwrap();
        let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        assert!(out.status.success(), "{args:?}: {text}");
        text
    };
    let refused = |args: &[&std::ffi::OsStr]| {
        let out = bin().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let os = |p: &Path| p.as_os_str().to_owned();
    // a ring map: an annulus between radii 1 and 2, eta periodic
    let kv = winslow::KnotVector::periodic_uniform(2, 8);
    let d = kv.dim();
    let angle = |k: usize| std::f64::consts::TAU * (k % d) as f64 / d as f64;
    let cps = (0..kv.num_basis()).flat_map(|k| [1.0, 2.0].map(|r| [r * angle(k).cos(), r * angle(k).sin()])).collect();
    let annulus = winslow::Surface::new([winslow::KnotVector::open_uniform(1, 1), kv], cps, None).unwrap();
    let ring_map = dir.join("annulus.json");
    winslow::write(&ring_map, &Output::Map { name: "annulus", map: &annulus, label: "", extra: None }).unwrap();
    let xml = dir.join("annulus.xml");
    let text = ok(&["convert".as_ref(), &os(&ring_map), "-o".as_ref(), &os(&xml)]);
    assert!(text.contains("certified"), "{text}");
    // G+Smo has no periodic basis: the same map on a clamped one
    match winslow::read(&xml).unwrap() {
        winslow::Document::Map { map, .. } => {
            for k in 0..=20 {
                let (u, v) = ((k % 3) as f64 / 2.0, k as f64 / 20.0);
                let (a, b) = (map.eval(u, v), annulus.eval(u, v));
                assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12, "({u}, {v}): {a:?} {b:?}");
            }
        }
        other => panic!("{}", other.kind()),
    }
    let again = dir.join("annulus-again.json");
    ok(&["convert".as_ref(), &os(&ring_map), "-o".as_ref(), &os(&again)]);
    match winslow::read(&again).unwrap() {
        winslow::Document::Map { map, .. } => assert_eq!(map, annulus),
        other => panic!("{}", other.kind()),
    }
    ok(&["render".as_ref(), &os(&ring_map), "--png".as_ref(), &os(&dir.join("annulus.png"))]);
    assert!(std::fs::metadata(dir.join("annulus.png")).unwrap().len() > 1000);
    // a multipatch result: the patch maps of a G+Smo layout as a JSON result
    let winslow::Document::Layout(layout) =
        winslow::read(&data().join("gismo/xml/multipatch/plateWithHoleMP.xml")).unwrap()
    else {
        panic!("not a layout")
    };
    let n = layout.patches.len();
    let patches = Patches {
        layout: &layout,
        maps: layout.patches.iter().map(|p| p.map.clone().unwrap()).collect(),
        reports: vec![serde_json::Value::Null; n],
        messages: vec![String::new(); n],
        report: serde_json::json!({}),
        message: String::new(),
    };
    let result = dir.join("plate.json");
    winslow::write(&result, &Output::Multipatch(patches)).unwrap();
    for out in ["plate-again.json", "plate.xml", "plate.vtm"] {
        let text = ok(&["convert".as_ref(), &os(&result), "-o".as_ref(), &os(&dir.join(out))]);
        assert!(text.contains(&format!("{n} of {n} patches certified")), "{text}");
    }
    assert_eq!(winslow::read(&dir.join("plate-again.json")).unwrap().kind(), "multipatch result");
    assert_eq!(winslow::read(&dir.join("plate.xml")).unwrap().kind(), "multipatch layout");
    assert!(dir.join("plate").join(format!("{}.vtu", layout.patches[0].name)).is_file());
    ok(&["render".as_ref(), &os(&result), "--png".as_ref(), &os(&dir.join("plate.png"))]);
    assert!(std::fs::metadata(dir.join("plate.png")).unwrap().len() > 1000);
    // kinds they cannot act on, and extensions that do not fit, are named
    let ring = data().join("rings/eccentric_annulus.json");
    let err = refused(&["convert".as_ref(), &os(&ring), "-o".as_ref(), &os(&dir.join("x.json"))]);
    assert!(err.contains("a ring document, where convert writes a map"), "{err}");
    let err = refused(&["render".as_ref(), &os(&ring), "--png".as_ref(), &os(&dir.join("x.png"))]);
    assert!(err.contains("a ring document, where render draws"), "{err}");
    let input = dir.join("input.json");
    winslow::write(&input, &Output::Layout(&layout)).unwrap();
    let err = refused(&["convert".as_ref(), &os(&input), "-o".as_ref(), &os(&dir.join("x.json"))]);
    assert!(err.contains("a multipatch layout document, where convert writes"), "{err}");
    let err = refused(&["convert".as_ref(), &os(&result), "-o".as_ref(), &os(&dir.join("x.igs"))]);
    assert!(err.contains("a multipatch result is written as") && err.contains("not .igs"), "{err}");
    assert!(!dir.join("x.igs").exists() && !dir.join("x.json").exists() && !dir.join("x.png").exists());
    // an I/O error names the file and its cause once
    let err = refused(&["convert".as_ref(), &os(&dir.join("missing.json")), "-o".as_ref(), &os(&dir.join("x.json"))]);
    assert_eq!(err.matches("os error").count(), 1, "{err}");
    assert_eq!(err.matches("missing.json").count(), 1, "{err}");
}

/// `-q` on every command leaves only errors: nothing on stdout or stderr when a command
/// succeeds (the files are written all the same), the error alone when it fails.
#[test]
fn quiet_leaves_only_errors() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let map = dir.join("map.json");
    let lid = data().join("wavy_lid.json");
    let runs: Vec<Vec<std::ffi::OsString>> = vec![
        vec![
            "solve".into(),
            lid.clone().into(),
            "-o".into(),
            map.clone().into(),
            "--png".into(),
            dir.join("map.png").into(),
        ],
        vec!["inspect".into(), lid.clone().into()],
        vec!["check".into(), map.clone().into()],
        vec!["convert".into(), map.clone().into(), "-o".into(), dir.join("map.xml").into()],
        vec!["render".into(), map.clone().into(), "--png".into(), dir.join("render.png").into()],
        vec![
            "mesh".into(),
            map.clone().into(),
            "--structured".into(),
            "11x11".into(),
            "-o".into(),
            dir.join("m.msh").into(),
        ],
    ];
    for args in runs {
        let out = bin().args(&args).arg("-q").output().unwrap();
        let what = format!("{args:?}");
        assert!(out.status.success(), "{what}: {}", String::from_utf8_lossy(&out.stderr));
        assert!(out.stdout.is_empty(), "{what} printed {}", String::from_utf8_lossy(&out.stdout));
        assert!(out.stderr.is_empty(), "{what} printed {}", String::from_utf8_lossy(&out.stderr));
    }
    for f in ["map.json", "map.png", "map.xml", "render.png", "m.msh"] {
        assert!(dir.join(f).is_file(), "{f} not written");
    }
    // an error is still printed, and the exit code says so
    let out = bin().arg("check").arg(dir.join("missing.json")).arg("-q").output().unwrap();
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    assert!(String::from_utf8_lossy(&out.stderr).starts_with("error: "), "{}", String::from_utf8_lossy(&out.stderr));
}

/// Run `winslow ARGS`; its exit code and standard error.
fn run(args: &[&std::ffi::OsStr]) -> (Option<i32>, String) {
    let out = bin().args(args).arg("-q").output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Every overwrite case of issue 30 is refused before any work, with exit code 1,
/// leaving the inputs as they were and writing nothing: an output naming an input (by
/// the same name, another spelling, or a link), two outputs naming one file, an
/// extension that is not the format's, an output whose folder is a file.
#[test]
fn outputs_that_would_replace_an_input_or_each_other_are_refused_first() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let os = |p: &Path| p.as_os_str().to_owned();
    let lid = dir.join("lid.json");
    std::fs::copy(data().join("wavy_lid.json"), &lid).unwrap();
    let original = std::fs::read(&lid).unwrap();
    let map = dir.join("m.json");
    let (code, err) = run(&["solve".as_ref(), &os(&lid), "-o".as_ref(), &os(&map)]);
    assert_eq!(code, Some(0), "{err}");
    let solved = std::fs::read(&map).unwrap();
    let a_file = dir.join("a-file");
    winslow::io::file::write_bytes(&a_file, b"not a folder").unwrap();
    let before: Vec<String> = listing(dir);
    let dot = dir.join(".").join("lid.json");
    let link = dir.join("link.json");
    #[cfg(unix)]
    std::os::unix::fs::symlink(&lid, &link).unwrap();
    #[cfg(not(unix))]
    std::fs::copy(&lid, &link).unwrap();
    let cases: Vec<Vec<std::ffi::OsString>> = vec![
        // the input replaced by the map
        vec!["solve".into(), os(&lid), "-o".into(), os(&lid)],
        vec!["solve".into(), os(&lid), "-o".into(), os(&dot)],
        #[cfg(unix)]
        vec!["solve".into(), os(&link), "-o".into(), os(&lid)],
        vec!["solve".into(), "--start".into(), os(&map), "-o".into(), os(&map)],
        vec![
            "solve".into(),
            os(&lid),
            "--start".into(),
            os(&map),
            "-o".into(),
            os(&dir.join("x.json")),
            "--png".into(),
            os(&lid),
        ],
        // the map replaced by a picture, a conversion, a mesh
        vec!["render".into(), os(&map), "--png".into(), os(&map)],
        vec!["convert".into(), os(&map), "-o".into(), os(&map)],
        vec!["mesh".into(), os(&map), "-o".into(), os(&map), "--structured".into(), "5x5".into()],
        // two outputs on one file
        vec!["solve".into(), os(&lid), "-o".into(), os(&dir.join("m2.json")), "--png".into(), os(&dir.join("m2.json"))],
        vec!["solve".into(), os(&lid), "-o".into(), os(&dir.join("m2.xml")), "--gismo".into(), os(&dir.join("m2.xml"))],
        // extensions that are not the format's
        vec!["solve".into(), os(&lid), "-o".into(), os(&dir.join("m3.json")), "--png".into(), os(&dir.join("m3.txt"))],
        vec!["solve".into(), os(&lid), "-o".into(), os(&dir.join("m3.png"))],
        vec!["solve".into(), os(&lid), "-o".into(), os(&dir.join("m3.json")), "--iges".into(), os(&dir.join("m3.xml"))],
        vec!["render".into(), os(&map), "--png".into(), os(&dir.join("m3.jpg"))],
        // a folder that is a file
        vec![
            "solve".into(),
            os(&lid),
            "-o".into(),
            os(&dir.join("m4.json")),
            "--png".into(),
            os(&a_file.join("x.png")),
        ],
        vec!["solve".into(), os(&lid), "-o".into(), os(&a_file.join("m4.json"))],
        // a split's parts next to its output, a loft's output on a slice
        vec![
            "split".into(),
            os(&map),
            "--from".into(),
            "south:0.5".into(),
            "--to".into(),
            "north:0.5".into(),
            "-o".into(),
            os(&dir.join("m.json")),
        ],
        vec!["loft".into(), os(&map), os(&solved_copy(dir, &solved)), "--dz".into(), "1".into(), "-o".into(), os(&map)],
    ];
    for args in &cases {
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        let (code, err) = run(&args);
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(err.starts_with("error: "), "{args:?}: {err}");
        assert!(!err.contains("written before the error"), "{args:?}: {err}");
        assert_eq!(std::fs::read(&lid).unwrap(), original, "{args:?} changed the boundary");
        assert_eq!(std::fs::read(&map).unwrap(), solved, "{args:?} changed the map");
        let mut now = listing(dir);
        now.retain(|n| n != "link.json" && n != "copy.json");
        assert_eq!(now, before, "{args:?} wrote something");
    }
}

/// A copy of the solved map (a second slice).
fn solved_copy(dir: &Path, bytes: &[u8]) -> std::path::PathBuf {
    let p = dir.join("copy.json");
    winslow::io::file::write_bytes(&p, bytes).unwrap();
    p
}

/// The names in a folder (recursively, relative), sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() && !p.is_symlink() {
                stack.push(p.clone());
            }
            out.push(p.strip_prefix(dir).unwrap().to_string_lossy().into_owned());
        }
    }
    out.sort();
    out
}

/// Every file written is listed in the `--json` output's `"files"`, and exists; a
/// command that fails after writing some names them on standard error.
#[test]
fn the_files_written_are_reported() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let lid = data().join("wavy_lid.json");
    let out = bin()
        .arg("solve")
        .arg(&lid)
        .arg("-o")
        .arg(dir.join("map.json"))
        .arg("--png")
        .arg(dir.join("map.png"))
        .arg("--gismo")
        .arg(dir.join("map.xml"))
        .arg("--mesh")
        .arg(dir.join("map.msh"))
        .args(["--structured", "9x9", "--json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v = common::stdout_json(&out);
    let files: Vec<&str> = v["files"].as_array().unwrap().iter().map(|f| f.as_str().unwrap()).collect();
    let expected: Vec<String> =
        ["map.json", "map.xml", "map.png", "map.msh"].iter().map(|f| dir.join(f).display().to_string()).collect();
    assert_eq!(files, expected);
    assert!(files.iter().all(|f| Path::new(f).is_file()));
    assert_eq!(v["verdict"], "certified");
    // the mesh fails after the map is written (a mesh of 1 point per direction): the
    // error is followed by the list of what was written
    let out = bin()
        .arg("solve")
        .arg(&lid)
        .arg("-o")
        .arg(dir.join("second.json"))
        .arg("--mesh")
        .arg(dir.join("second.msh"))
        .args(["--structured", "1x1", "-q"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    let last = err.lines().last().unwrap_or_default();
    assert!(last.starts_with("written before the error: ") && last.contains("second.json"), "{err}");
    assert!(dir.join("second.json").is_file() && !dir.join("second.msh").exists());
}

/// `sweep` into a folder that holds an earlier sweep's files is refused (nothing
/// changes there); with `--overwrite` those files are removed first, so that no frame of
/// the earlier sweep is left beside the new ones (and `loft` of `frame_*.json` lofts one
/// sweep); other files in the folder are left alone.
#[test]
fn a_sweep_never_mixes_with_an_earlier_one() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let folder = dir.join("sweep");
    let ring = data().join("rings/eccentric_annulus.json");
    let sweep = |steps: &str, degrees: &str, extra: &[&str]| {
        let out = bin()
            .arg("sweep")
            .arg(&ring)
            .args(["--rotate-inner", degrees, "--steps", steps, "-q", "-o"])
            .arg(&folder)
            .args(extra)
            .output()
            .unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    assert_eq!(sweep("2", "1", &[]).0, Some(0));
    winslow::io::file::write_bytes(&folder.join("notes.txt"), b"mine").unwrap();
    let first = std::fs::read(folder.join("sweep.json")).unwrap();
    let before = listing(&folder);
    assert_eq!(before.iter().filter(|n| n.starts_with("frame_") && n.ends_with(".json")).count(), 3);
    let (code, err) = sweep("1", "0.17", &[]);
    assert_eq!(code, Some(1), "{err}");
    assert_eq!(listing(&folder), before);
    assert_eq!(std::fs::read(folder.join("sweep.json")).unwrap(), first);
    let (code, err) = sweep("1", "0.17", &["--overwrite"]);
    assert_eq!(code, Some(0), "{err}");
    let after = listing(&folder);
    assert!(!after.contains(&"frame_0002.json".to_string()) && !after.contains(&"frame_0002.vtu".to_string()));
    assert!(after.contains(&"frame_0001.json".to_string()) && after.contains(&"notes.txt".to_string()));
    let table = common::read_json(&folder.join("sweep.json"));
    assert_eq!(table["frames"].as_array().unwrap().len(), 2);
    assert_eq!(table["step_degrees"], 0.17);
    // the pictures of `compare --png-dir` likewise
    let pictures = dir.join("pictures");
    let compare = |extra: &[&str]| {
        let out = bin()
            .arg("compare")
            .arg(data().join("quarter_annulus.json"))
            .args(["--methods", "egg", "--png-dir"])
            .arg(&pictures)
            .args(extra)
            .arg("-q")
            .output()
            .unwrap();
        out.status.code()
    };
    assert_eq!(compare(&[]), Some(0));
    let stale = pictures.join("quarter_annulus-vhm.png");
    winslow::io::file::write_bytes(&stale, b"an earlier run's picture").unwrap();
    assert_eq!(compare(&[]), Some(1));
    assert!(stale.is_file());
    assert_eq!(compare(&["--overwrite"]), Some(0));
    assert!(!stale.exists() && pictures.join("quarter_annulus-egg.png").is_file());
}

/// A ring map (what `solve` and `sweep` write for a ring) is taken as its ring by
/// `solve`, `inspect` and `sweep`, and by `split` and `join` named as a ring map where a
/// four-sided map is needed (not a corner gap of its seam).
#[test]
fn a_ring_map_is_taken_as_its_ring() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let os = |p: &Path| p.as_os_str().to_owned();
    let ring_map = dir.join("ring-map.json");
    let ring = data().join("rings/eccentric_annulus.json");
    let (code, err) = run(&["solve".as_ref(), &os(&ring), "-o".as_ref(), &os(&ring_map)]);
    assert_eq!(code, Some(0), "{err}");
    let again = dir.join("again.json");
    let (code, err) = run(&["solve".as_ref(), &os(&ring_map), "-o".as_ref(), &os(&again)]);
    assert_eq!(code, Some(0), "{err}");
    let report = common::read_json(&again)["report"].clone();
    assert_eq!(report["verdict"], "certified");
    // the contours are the first map's sides: the boundary deviation is the fit's
    let first = common::read_json(&ring_map)["report"]["boundary_deviation"].clone();
    let dev = |v: &serde_json::Value, k: usize| v[k].as_f64().unwrap();
    assert!(dev(&report["boundary_deviation"], 1) < 1e-3 && dev(&first, 1) < 1e-3, "{report}");
    assert_eq!(run(&["inspect".as_ref(), &os(&ring_map)]).0, Some(0));
    let frames = dir.join("frames");
    let (code, err) = run(&[
        "sweep".as_ref(),
        &os(&ring_map),
        "--rotate-inner".as_ref(),
        "2".as_ref(),
        "--steps".as_ref(),
        "1".as_ref(),
        "-o".as_ref(),
        &os(&frames),
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(frames.join("frame_0001.json").is_file());
    let parts = dir.join("parts.json");
    let (code, err) = run(&[
        "split".as_ref(),
        &os(&ring_map),
        "--from".as_ref(),
        "south:0.5".as_ref(),
        "--to".as_ref(),
        "north:0.5".as_ref(),
        "-o".as_ref(),
        &os(&parts),
    ]);
    assert_eq!(code, Some(1));
    assert!(err.contains("a ring map document, where split needs a four-sided map"), "{err}");
    assert!(!parts.exists());
}
