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
    assert!(err.contains("a multipatch result cannot be written as .igs"), "{err}");
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
