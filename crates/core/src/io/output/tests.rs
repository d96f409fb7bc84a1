//! Every writer with a reader: `write` then `read` gives the same control points, weights
//! and knots bit for bit; extensions that do not fit are refused; a failed write leaves
//! the old file.

use std::path::{Path, PathBuf};

use serde_json::json;

use super::*;
use crate::boundary::ring::ClosedContour;
use crate::boundary::SideCurve;
use crate::io::{read, Document};
use crate::multipatch::{Interface, Patch, PatchSide};
use crate::spline::curve::Curve;
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;

/// A scratch folder, removed when dropped.
struct Scratch(tempfile::TempDir);

impl Scratch {
    fn new() -> Self {
        Self(tempfile::tempdir().unwrap())
    }

    fn path(&self, file: &str) -> PathBuf {
        self.0.path().join(file)
    }
}

/// A counter-clockwise map of `[x0, x0 + 1] x [0, 1]`, degree (2, 3), perturbed
/// interior, with non-unit weights when `rational`; coordinates with long mantissas.
fn sample_map(x0: f64, rational: bool) -> Surface {
    let ku = KnotVector::new(2, vec![0., 0., 0., 0.3, 1., 1., 1.]).unwrap();
    let kv = KnotVector::open_uniform(3, 2);
    let (gu, gv) = (ku.greville(), kv.greville());
    let (nu, nv) = (ku.num_basis(), kv.num_basis());
    let mut cps = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let inner = i > 0 && i + 1 < nu && j > 0 && j + 1 < nv;
            let d = if inner { 0.01 / 3.0 * (i + j) as f64 } else { 0.0 };
            cps.push([x0 + gu[i] + d, gv[j] - d / 7.0]);
        }
    }
    let weights = rational.then(|| (0..nu * nv).map(|k| 1.0 + 0.1 / (k as f64 + 3.0)).collect());
    Surface::new([ku, kv], cps, weights).unwrap()
}

fn same_map(a: &Surface, b: &Surface) {
    let bits = |s: &Surface| s.control_points.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(a), bits(b));
    assert_eq!(a.knots, b.knots);
    let w = |s: &Surface| s.weights.clone().unwrap_or_else(|| vec![1.0; s.control_points.len()]);
    assert_eq!(w(a), w(b));
}

fn map_output<'a>(map: &'a Surface) -> Output<'a> {
    Output::Map { name: "m", map, label: "certified -- yes", extra: Some(json!({ "report": { "iterations": 3 } })) }
}

#[test]
fn maps_round_trip_through_every_format_with_a_reader() {
    let dir = Scratch::new();
    for rational in [false, true] {
        let map = sample_map(0.0, rational);
        for ext in ["json", "xml", "igs", "iges", ""] {
            let path = dir.path(&format!("m{}.{ext}", u8::from(rational)));
            write(&path, &map_output(&map)).unwrap();
            let doc = read(&path).unwrap_or_else(|e| panic!(".{ext}: {e}"));
            assert_eq!(doc.kind(), "map", ".{ext}");
            let Document::Map { map: back, .. } = doc else { unreachable!() };
            same_map(&back, &map);
        }
    }
    // the JSON keeps the name and the extra fields
    let (doc, report) = crate::io::read_with_report(&dir.path("m0.json")).unwrap();
    assert_eq!(doc.name(), "m");
    assert_eq!(report, Some(json!({ "iterations": 3 })));
    // the writers without a reader write what they say
    let map = sample_map(0.0, true);
    for (ext, start) in [("vtu", "<?xml"), ("vtk", "# vtk DataFile")] {
        let path = dir.path(&format!("m.{ext}"));
        write(&path, &map_output(&map)).unwrap();
        assert!(std::fs::read_to_string(&path).unwrap().starts_with(start), ".{ext}");
    }
}

#[test]
fn a_ring_map_is_read_as_a_ring_map() {
    let dir = Scratch::new();
    let kv = KnotVector::periodic_uniform(2, 4);
    let d = kv.dim();
    let angle = |k: usize| std::f64::consts::TAU * (k % d) as f64 / d as f64;
    let nv = kv.num_basis();
    let ku = KnotVector::open_uniform(1, 1);
    let cps = (0..nv).flat_map(|k| [1.0, 2.0].map(|r| [r * angle(k).cos(), r * angle(k).sin()])).collect();
    let map = Surface::new([ku, kv], cps, None).unwrap();
    let path = dir.path("ring.json");
    write(&path, &map_output(&map)).unwrap();
    let doc = read(&path).unwrap();
    assert_eq!(doc.kind(), "ring map");
    let Document::Map { map: back, .. } = doc else { unreachable!() };
    same_map(&back, &map);
}

#[test]
fn volumes_round_trip() {
    let dir = Scratch::new();
    let k = [KnotVector::open_uniform(2, 2), KnotVector::open_uniform(1, 3), KnotVector::open_uniform(3, 1)];
    let n: usize = k.iter().map(KnotVector::num_basis).product();
    let cps = (0..n).map(|i| [i as f64 / 3.0, (i % 7) as f64 * 0.1 + 1e-17, 1e8 + (i / 12) as f64]).collect();
    let w = Some((0..n).map(|i| 1.0 + 1.0 / (3.0 + i as f64)).collect());
    let volume = Volume::new(k, cps, w).unwrap();
    let out = Output::Volume { name: "v", volume: &volume, label: "a label", extra: None };
    for ext in ["json", "xml"] {
        let path = dir.path(&format!("v.{ext}"));
        write(&path, &out).unwrap();
        let doc = read(&path).unwrap();
        assert_eq!(doc.kind(), "volume", ".{ext}");
        let Document::Volume { volume: back, .. } = doc else { unreachable!() };
        assert_eq!(back, volume, ".{ext}");
        let bits = |v: &Volume| v.control_points.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back), bits(&volume));
    }
    for ext in ["vtu", "vtk"] {
        write(&dir.path(&format!("v.{ext}")), &out).unwrap();
    }
}

/// Two patches side by side sharing the side `x = 1`.
fn two_patches() -> Layout {
    let (a, b) = (sample_map(0.0, false), sample_map(1.0, false));
    Layout {
        name: "two".into(),
        patches: vec![Patch::from_map("a", a), Patch::from_map("b", b)],
        interfaces: vec![Interface {
            first: PatchSide { patch: 0, side: Side::East },
            second: PatchSide { patch: 1, side: Side::West },
            reversed: false,
        }],
    }
}

fn patches_of(layout: &Layout) -> Patches<'_> {
    let n = layout.patches.len();
    Patches {
        layout,
        maps: layout.patches.iter().map(|p| p.map.clone().unwrap()).collect(),
        reports: vec![json!({ "certificate": "none" }); n],
        messages: vec!["not certified".into(); n],
        report: json!({ "message": "written by a test" }),
        message: "written by a test".into(),
    }
}

#[test]
fn multipatch_results_and_layouts_round_trip() {
    let dir = Scratch::new();
    let layout = two_patches();
    let out = Output::Multipatch(patches_of(&layout));
    for (ext, kind) in [("json", "multipatch result"), ("xml", "multipatch layout")] {
        let path = dir.path(&format!("two.{ext}"));
        write(&path, &out).unwrap();
        let doc = read(&path).unwrap();
        assert_eq!(doc.kind(), kind, ".{ext}");
        let (Document::Multipatch(back) | Document::Layout(back)) = doc else { unreachable!() };
        assert_eq!(back.patches.len(), 2);
        for (p, q) in layout.patches.iter().zip(&back.patches) {
            same_map(q.map.as_ref().unwrap(), p.map.as_ref().unwrap());
        }
        assert_eq!(back.interfaces, layout.interfaces, ".{ext}");
    }
    // a VTK multiblock file and one Bézier cell file per patch beside it
    write(&dir.path("two.vtm"), &out).unwrap();
    assert!(dir.path("two/a.vtu").is_file() && dir.path("two/b.vtu").is_file());
    // a layout as input: every patch by its sides
    let path = dir.path("layout.json");
    write(&path, &Output::Layout(&layout)).unwrap();
    let doc = read(&path).unwrap();
    assert_eq!(doc.kind(), "multipatch layout");
    let Document::Layout(back) = doc else { unreachable!() };
    for (p, q) in layout.patches.iter().zip(&back.patches) {
        assert_eq!(p.sides, q.sides);
    }
}

#[test]
fn boundaries_and_rings_round_trip() {
    let dir = Scratch::new();
    let map = sample_map(0.0, true);
    let boundary = Document::Map { name: "b".into(), map }.into_boundary().unwrap();
    let path = dir.path("b.json");
    write(&path, &Output::Boundary(&boundary)).unwrap();
    let Document::Boundary(back) = read(&path).unwrap() else { panic!("not a boundary") };
    for (s, t) in boundary.sides.iter().zip(&back.sides) {
        match (s, t) {
            (SideCurve::Spline(s), SideCurve::Spline(t)) => assert_eq!(s, t),
            other => panic!("{other:?}"),
        }
    }
    let kv = KnotVector::periodic_uniform(2, 4);
    let d = kv.dim();
    let base = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
    let inner = Curve::new(kv.clone(), (0..kv.num_basis()).map(|k| base[k % d]).collect(), None).unwrap();
    let outer = vec![[3.0, 0.0], [0.0, 3.0], [-3.0, 0.0], [0.0, -3.0]];
    let ring =
        Ring { name: "r".into(), inner: ClosedContour::Spline(inner.clone()), outer: ClosedContour::Points(outer) };
    let path = dir.path("r.json");
    write(&path, &Output::Ring(&ring)).unwrap();
    let Document::Ring(back) = read(&path).unwrap() else { panic!("not a ring") };
    assert!(matches!(&back.inner, ClosedContour::Spline(c) if *c == inner));
    assert!(matches!(&back.outer, ClosedContour::Points(p) if p.len() == 4));
}

#[test]
fn pictures_are_png() {
    let dir = Scratch::new();
    let rgba: Vec<u8> = (0..4 * 3 * 2).map(|k| (k * 11) as u8).collect();
    let img = Image { width: 3, height: 2, rgba: rgba.clone() };
    let path = dir.path("p.png");
    write(&path, &Output::Picture(&img)).unwrap();
    let mut reader = png::Decoder::new(std::fs::File::open(&path).unwrap()).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (3, 2));
    assert_eq!(&buf[..rgba.len()], &rgba[..]);
    let short = Image { width: 3, height: 2, rgba: vec![0; 5] };
    assert!(matches!(write(&dir.path("short.png"), &Output::Picture(&short)), Err(Error::Length { .. })));
    assert!(!dir.path("short.png").exists());
}

#[test]
fn extensions_that_do_not_fit_are_refused_and_nothing_is_written() {
    let dir = Scratch::new();
    let map = sample_map(0.0, false);
    let layout = two_patches();
    let img = Image { width: 1, height: 1, rgba: vec![0; 4] };
    let cases: [(Output, &str); 5] = [
        (map_output(&map), "png"),
        (map_output(&map), "vtm"),
        (Output::Multipatch(patches_of(&layout)), "vtu"),
        (Output::Layout(&layout), "xml"),
        (Output::Picture(&img), "json"),
    ];
    for (out, ext) in cases {
        let path = dir.path(&format!("x.{ext}"));
        let e = write(&path, &out).unwrap_err();
        match &e {
            Error::Extension { kind, extension, .. } => {
                assert_eq!((kind.as_str(), extension.as_str()), (out.kind(), ext));
            }
            other => panic!("{other}"),
        }
        let text = e.to_string();
        assert!(text.contains(out.kind()) && text.contains(&format!(".{ext}")), "{text}");
        assert!(!path.exists());
    }
    let e = write(Path::new("picture"), &Output::Picture(&img)).unwrap_err();
    assert!(e.to_string().contains("without an extension"), "{e}");
}

#[test]
fn a_failed_write_leaves_the_old_file() {
    let dir = Scratch::new();
    let map = sample_map(0.0, false);
    let path = dir.path("m.json");
    write(&path, &map_output(&map)).unwrap();
    let before = std::fs::read(&path).unwrap();
    // a folder that cannot be made (a file is in the way): nothing changes
    let blocked = dir.path("m.json/inner.json");
    assert!(matches!(write(&blocked, &map_output(&map)), Err(Error::Io { .. })));
    // a picture whose encoding fails half-way leaves the old file under the name
    let png = dir.path("p.png");
    write(&png, &Output::Picture(&Image { width: 1, height: 1, rgba: vec![1; 4] })).unwrap();
    let old_png = std::fs::read(&png).unwrap();
    let e = crate::io::write_with(&png, |w| {
        w.write_all(&old_png[..8])?;
        Err(std::io::Error::other("encoder failed"))
    });
    assert!(e.is_err());
    assert_eq!(std::fs::read(&png).unwrap(), old_png);
    assert_eq!(std::fs::read(&path).unwrap(), before);
    let mut names: Vec<String> =
        std::fs::read_dir(&dir.0).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(names, ["m.json", "p.png"], "no temporary file is left");
}

/// A THB map (two levels refined around one cell, control points with long mantissas)
/// through `write` and `read` as JSON (with a report beside it) and as G+Smo
/// `THBSpline2`: the same hierarchy and control points bit for bit, the name kept in
/// JSON, and written again from what was read, the same bytes; a THB map is refused
/// where a boundary is needed and as a pipeline input.
#[test]
fn thb_maps_round_trip_through_json_and_xml() {
    use crate::spline::hierarchical::map::HierarchicalMap;
    let dir = Scratch::new();
    let tensor = sample_map(0.25, false);
    let thb = HierarchicalMap::from_surface(&tensor).unwrap().refined(&[(0, [1, 0])], 2).unwrap();
    let (l, c) = thb.basis.cell_at(0.35, 0.2);
    let thb = thb.refined(&[(l, c)], 2).unwrap();
    assert_eq!(thb.basis.num_levels(), 3);
    let extra = Some(json!({ "report": { "verdict": "certified" } }));
    for (file, label) in [("thb.json", ""), ("thb.xml", "verdict certified")] {
        let path = dir.path(file);
        write(&path, &Output::Thb { name: "sample", map: &thb, label, extra: extra.clone() }).unwrap();
        let (doc, report) = crate::io::read_with_report(&path).unwrap();
        assert_eq!(doc.kind(), "THB map");
        // G+Smo XML has no name: the file stem
        assert_eq!(doc.name(), if file.ends_with("json") { "sample" } else { "thb" });
        assert_eq!(report.is_some(), file.ends_with("json"));
        let Document::Thb { name, map } = doc.clone() else { panic!("{file}: a {}", doc.kind()) };
        assert_eq!(map.basis.active_functions(), thb.basis.active_functions(), "{file}");
        assert_eq!(map.control_points, thb.control_points, "{file}");
        let again = dir.path(&format!("again-{file}"));
        let extra = report.map(|r| json!({ "report": r }));
        write(&again, &Output::Thb { name: &name, map: &map, label, extra }).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), std::fs::read(&again).unwrap(), "{file}");
        let e = doc.clone().into_boundary().unwrap_err();
        assert!(matches!(&e, Error::DocumentKind { found, .. } if found == "THB map"), "{e}");
        let e = doc.into_input(&Default::default()).unwrap_err();
        assert!(matches!(&e, Error::DocumentKind { found, .. } if found == "THB map"), "{e}");
    }
    // formats without hierarchical splines get the exact tensor form: read back from
    // IGES, it is the THB map; a picture's extension is still refused
    let igs = dir.path("thb.igs");
    write(&igs, &Output::Thb { name: "x", map: &thb, label: "", extra: None }).unwrap();
    let Document::Map { map, .. } = read(&igs).unwrap() else { panic!("IGES of a THB map is not a map") };
    for (u, v) in [(0.1, 0.2), (0.35, 0.2), (0.9, 0.6)] {
        let (a, b) = (map.eval(u, v), thb.eval(u, v));
        assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12, "at {u}, {v}: {a:?} vs {b:?}");
    }
    for (file, start) in [("thb.vtu", "<?xml"), ("thb.vtk", "# vtk DataFile")] {
        write(&dir.path(file), &Output::Thb { name: "x", map: &thb, label: "", extra: None }).unwrap();
        assert!(std::fs::read_to_string(dir.path(file)).unwrap().starts_with(start), "{file}");
    }
    let e = write(&dir.path("thb.png"), &Output::Thb { name: "x", map: &thb, label: "", extra: None }).unwrap_err();
    assert!(matches!(e, Error::Extension { .. }), "{e}");
    assert!(!dir.path("thb.png").exists());
}
