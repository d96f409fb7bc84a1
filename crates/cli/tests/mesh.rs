//! `winslow mesh` and `winslow solve --mesh` end to end.

mod common;

use std::collections::HashMap;
use std::path::Path;

use common::{bin, data};

fn run(args: &[&str]) -> (bool, String, String) {
    let out = bin().args(args).output().unwrap();
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

/// A written linear Gmsh MSH 4.1 file read back: its node count, its surface cells, and
/// how many of those turn clockwise (twice the signed area of the corner polygon,
/// `sum p_k x p_(k+1)`, not positive: an inverted cell).
fn msh_cells(path: &str) -> (usize, usize, usize) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let section = |name: &str| -> Vec<&str> {
        let body = text.split(&format!("${name}\n")).nth(1).unwrap_or_else(|| panic!("{path}: no ${name}"));
        body.split(&format!("$End{name}")).next().unwrap().lines().collect()
    };
    let nums = |l: &str| -> Vec<f64> { l.split_whitespace().map(|t| t.parse().unwrap()).collect() };
    // $Nodes: a header, then blocks of (dim, entity, parametric, n), n tags, n coordinates
    let nodes = section("Nodes");
    let mut xy = HashMap::new();
    let mut k = 1;
    while k < nodes.len() {
        let n = nums(nodes[k])[3] as usize;
        for i in 0..n {
            let p = nums(nodes[k + 1 + n + i]);
            xy.insert(nums(nodes[k + 1 + i])[0] as usize, [p[0], p[1]]);
        }
        k += 1 + 2 * n;
    }
    // $Elements: a header, then blocks of (dim, entity, type, n) and n lines `tag nodes...`
    let elements = section("Elements");
    let (mut cells, mut clockwise, mut k) = (0, 0, 1);
    while k < elements.len() {
        let h = nums(elements[k]);
        let n = h[3] as usize;
        if h[0] == 2.0 {
            assert!(h[2] == 2.0 || h[2] == 3.0, "{path}: a linear mesh (triangles, quadrilaterals)");
            for line in &elements[k + 1..k + 1 + n] {
                let p: Vec<[f64; 2]> = nums(line)[1..].iter().map(|&t| xy[&(t as usize)]).collect();
                let area2: f64 =
                    (0..p.len()).map(|i| p[i][0] * p[(i + 1) % p.len()][1] - p[i][1] * p[(i + 1) % p.len()][0]).sum();
                cells += 1;
                clockwise += usize::from(area2 <= 0.0);
            }
        }
        k += 1 + n;
    }
    (nums(nodes[0])[1] as usize, cells, clockwise)
}

#[test]
fn solve_then_mesh_in_every_format() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().join("cli-mesh");
    let d = |f: &str| dir.join(f).to_string_lossy().into_owned();
    let lid = data().join("wavy_lid.json").to_string_lossy().into_owned();
    // solve and mesh in one command: boundary layers at the south side
    let (ok, _, err) = run(&[
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
    // 21 x 31 nodes, 20 x 30 cells, none inverted
    assert_eq!(msh_cells(&d("lid.msh")), (651, 600, 0));
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
        assert!(Path::new(o).exists(), "{o} not written: {out}");
        if extra.contains(&"--unstructured") {
            assert!(out.contains("meshing: boundary"), "{out}");
        }
        if extra.contains(&"xi:curvature:1e-3") {
            // the wavy lid (north) needs more than 5 points along xi for a chord of 1e-3
            let (nodes, _, clockwise) = msh_cells(o);
            assert!(nodes > 25 && nodes.is_multiple_of(5) && clockwise == 0, "{nodes} nodes, {clockwise} inverted");
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
}

/// An SU2 file read back: points, distinct points, marker names, and whether every
/// edge used by one cell only is on a marker (the seam interior).
fn su2_summary(path: &str) -> (usize, usize, Vec<String>, bool) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('%')).collect();
    let ne: usize = lines[1].strip_prefix("NELEM= ").unwrap().parse().unwrap();
    let mut uses: std::collections::HashMap<(usize, usize), usize> = Default::default();
    for l in &lines[2..2 + ne] {
        let v: Vec<usize> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
        let c = &v[1..v.len() - 1];
        for e in 0..c.len() {
            let (a, b) = (c[e], c[(e + 1) % c.len()]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let np: usize = lines[2 + ne].strip_prefix("NPOIN= ").unwrap().parse().unwrap();
    let distinct: std::collections::HashSet<&str> =
        lines[3 + ne..3 + ne + np].iter().map(|l| l.rsplit_once(char::is_whitespace).map_or(*l, |p| p.0)).collect();
    let mut markers = Vec::new();
    let mut marked = std::collections::HashSet::new();
    let mut at = 4 + ne + np;
    while at < lines.len() {
        markers.push(lines[at].strip_prefix("MARKER_TAG= ").unwrap().to_string());
        let k: usize = lines[at + 1].strip_prefix("MARKER_ELEMS= ").unwrap().parse().unwrap();
        for l in &lines[at + 2..at + 2 + k] {
            let v: Vec<usize> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            marked.insert((v[1].min(v[2]), v[1].max(v[2])));
        }
        at += 2 + k;
    }
    let open: std::collections::HashSet<(usize, usize)> =
        uses.iter().filter(|(_, &n)| n == 1).map(|(&e, _)| e).collect();
    (np, distinct.len(), markers, open == marked && uses.values().all(|&n| n <= 2))
}

#[test]
fn a_ring_meshes_without_a_seam_structured_and_unstructured() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let d = |f: &str| dir.join(f).to_string_lossy().into_owned();
    let ring = data().join("rings/annulus_periodic.json").to_string_lossy().into_owned();
    let (ok, _, err) = run(&["solve", &ring, "-o", &d("ring.json"), "-q"]);
    assert!(ok, "{err}");
    // 9 x 40 points: the seam is not repeated, so 40 points around make 40 cells
    let (ok, _, err) = run(&["mesh", &d("ring.json"), "-o", &d("ring.msh"), "--structured", "9x40"]);
    assert!(ok, "{err}");
    let (nodes, cells, clockwise) = msh_cells(&d("ring.msh"));
    assert_eq!((nodes, cells, clockwise), (9 * 40, 8 * 40, 0));
    let layers = ["--cluster", "inner:first-height:1e-3:1.2", "--cluster", "outer:first-height:1e-3:1.2"];
    let map = d("ring.json");
    for out in ["ring.su2", "ring-case/", "ring.xyz", "ring.vtu"] {
        let mut args = vec!["mesh", &map[..], "-o"];
        let o = d(out);
        args.extend([&o[..], "--structured", "61x64"]);
        args.extend(layers);
        let (ok, _, err) = run(&args);
        assert!(ok, "{out}: {err}");
    }
    // markers in side order: east (outer), then west (inner)
    assert_eq!(su2_summary(&d("ring.su2")), (61 * 64, 61 * 64, vec!["outer".into(), "inner".into()], true));
    assert!(dir.join("ring-case/constant/polyMesh/boundary").exists());
    let boundary = std::fs::read_to_string(dir.join("ring-case/constant/polyMesh/boundary")).unwrap();
    assert!(boundary.contains("    inner\n") && boundary.contains("    outer\n") && !boundary.contains("south"));
    // unstructured: the seam shared, the walls inner and outer, in every format
    for out in ["ring-u.su2", "ring-u.msh", "ring-u.vtu", "ring-u-case/"] {
        let (ok, _, err) = run(&["mesh", &map, "-o", &d(out), "--unstructured", "--size", "0.3"]);
        assert!(ok, "{out}: {err}");
    }
    let (np, distinct, markers, closed) = su2_summary(&d("ring-u.su2"));
    assert!(np > 50 && np == distinct && closed, "{np} points, {distinct} distinct");
    assert_eq!(markers, ["outer", "inner"]);
    let (nodes, cells, clockwise) = msh_cells(&d("ring-u.msh"));
    // an annulus: V - E + F = 0 with E = (3 F + boundary edges) / 2
    assert_eq!(clockwise, 0);
    assert!(nodes > 0 && cells > 0);
    let (ok, _, err) = run(&["mesh", &map, "-o", &d("ring-u3.msh"), "--unstructured", "--size", "0.3", "--order", "3"]);
    assert!(ok, "{err}");
    // the eccentric annulus at 0.05: spade splits wall segments off the power-of-two
    // midpoints there (its constraint edges once left their side by an ulp)
    let ecc = data().join("rings/eccentric_annulus.json").to_string_lossy().into_owned();
    let (ok, _, err) = run(&["solve", &ecc, "-o", &d("ecc.json"), "-q"]);
    assert!(ok, "{err}");
    let (ok, _, err) = run(&["mesh", &d("ecc.json"), "-o", &d("ecc.su2"), "--unstructured", "--size", "0.05"]);
    assert!(ok, "{err}");
    let (np, distinct, markers, closed) = su2_summary(&d("ecc.su2"));
    assert!(np > 1000 && np == distinct && closed && markers == ["outer", "inner"], "{np} {distinct} {markers:?}");
    // layers on the seam, inner/outer on a four-sided map: refused
    let (ok, _, _) = run(&[
        "mesh",
        &d("ring.json"),
        "-o",
        &d("seam.su2"),
        "--structured",
        "41x64",
        "--cluster",
        "south:first-height:1e-3",
    ]);
    assert!(!ok);
    let lid = data().join("wavy_lid.json").to_string_lossy().into_owned();
    let (ok, _, _) = run(&["solve", &lid, "-o", &d("lid.json"), "-q"]);
    assert!(ok);
    let (ok, _, _) = run(&[
        "mesh",
        &d("lid.json"),
        "-o",
        &d("seam.msh"),
        "--structured",
        "9x9",
        "--cluster",
        "inner:first-height:1e-3",
    ]);
    assert!(!ok);
    assert!(!dir.join("seam.su2").exists() && !dir.join("seam.msh").exists());
}

#[test]
fn a_cut_ring_is_meshed_with_its_seam_merged() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let d = |f: &str| dir.join(f).to_string_lossy().into_owned();
    // G+Smo's cut ring: west and east coincide to 2.2e-7 of the diameter; xi runs around
    let cut = data().join("gismo/male_casing_ring.json").to_string_lossy().into_owned();
    let (ok, _, err) = run(&["solve", &cut, "-o", &d("cut.json"), "-q"]);
    assert!(ok, "{err}");
    let layers = ["--cluster", "inner:first-height:1e-4:1.2", "--cluster", "outer:first-height:1e-4:1.2"];
    let map = d("cut.json");
    for out in ["cut.su2", "cut.msh", "cut.vtu", "cut-case/", "cut.xyz"] {
        let mut args = vec!["mesh", &map[..], "-o"];
        let o = d(out);
        args.extend([&o[..], "--structured", "201x121"]);
        args.extend(layers);
        let (ok, stdout, err) = run(&args);
        assert!(ok, "{out}: {err}");
        assert!(stdout.contains("merged"), "{stdout}");
    }
    // 201 points around make 201 cells: no node repeated, the seam interior
    assert_eq!(su2_summary(&d("cut.su2")), (201 * 121, 201 * 121, vec!["outer".into(), "inner".into()], true));
    let (nodes, cells, clockwise) = msh_cells(&d("cut.msh"));
    assert_eq!((nodes, cells, clockwise), (201 * 121, 201 * 120, 0));
    let boundary = std::fs::read_to_string(dir.join("cut-case/constant/polyMesh/boundary")).unwrap();
    assert!(boundary.contains("    inner\n") && boundary.contains("    outer\n") && !boundary.contains("west"));
    // a cut annulus (exact circles, west = east): unstructured too
    let ca = data().join("maps/cut_annulus.json").to_string_lossy().into_owned();
    for out in ["ca.su2", "ca.msh", "ca.vtu", "ca-case/"] {
        let (ok, _, err) = run(&["mesh", &ca, "-o", &d(out), "--unstructured", "--size", "0.2"]);
        assert!(ok, "{out}: {err}");
    }
    let (np, distinct, markers, closed) = su2_summary(&d("ca.su2"));
    assert!(np > 100 && np == distinct && closed, "{np} points, {distinct} distinct");
    assert_eq!(markers, ["outer", "inner"]);
    assert_eq!(msh_cells(&d("ca.msh")).2, 0);
    let (ok, _, err) = run(&["mesh", &ca, "-o", &d("ca-s.su2"), "--structured", "64x17"]);
    assert!(ok, "{err}");
    assert_eq!(su2_summary(&d("ca-s.su2")), (64 * 17, 64 * 17, vec!["outer".into(), "inner".into()], true));
    // G+Smo's cut ring triangulated: slivers where the gap is narrow, but one node per
    // seam point, the seam interior, every cell counter-clockwise
    let (ok, _, err) = run(&["mesh", &map, "-o", &d("cut-tri.su2"), "--unstructured", "--size", "2"]);
    assert!(ok, "{err}");
    let (np, distinct, markers, closed) = su2_summary(&d("cut-tri.su2"));
    assert!(np > 1000 && np == distinct && closed && markers == ["outer", "inner"], "{np} {distinct} {markers:?}");
    let (ok, _, err) = run(&["mesh", &map, "-o", &d("cut-tri.msh"), "--unstructured", "--size", "2"]);
    assert!(ok, "{err}");
    assert_eq!(msh_cells(&d("cut-tri.msh")).2, 0);
    // layers on the cut (west) are refused: it is the seam
    let (ok, _, err) =
        run(&["mesh", &ca, "-o", &d("ca-w.su2"), "--structured", "64x17", "--cluster", "west:first-height:1e-3"]);
    assert!(!ok && err.contains("seam"), "{err}");
    assert!(!dir.join("ca-w.su2").exists());
}

/// The physical names of a Gmsh file: `(dimension, name)`.
fn msh_physical_names(path: &Path) -> Vec<(usize, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let body = text.split("$PhysicalNames\n").nth(1).unwrap().split("$EndPhysicalNames").next().unwrap();
    body.lines()
        .skip(1)
        .map(|l| {
            let t: Vec<&str> = l.splitn(3, ' ').collect();
            (t[0].parse().unwrap(), t[2].trim_matches('"').to_string())
        })
        .collect()
}

#[test]
fn a_multipatch_result_is_one_conforming_mesh() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let xml = data().join("gismo/xml/multipatch/plateWithHoleMP.xml");
    let result = dir.join("plate.json");
    let out = bin().arg("solve").arg(&xml).arg("-q").arg("-o").arg(&result).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc = common::read_json(&result);
    let patches: Vec<String> =
        doc["patches"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap().to_string()).collect();
    // the solved result and the G+Smo multipatch itself (its patches are maps)
    for (input, tag) in [(result.clone(), "json"), (xml.clone(), "xml")] {
        let msh = dir.join(format!("{tag}.msh"));
        let (ok, _, err) = run(&["mesh", input.to_str().unwrap(), "-o", msh.to_str().unwrap(), "--structured", "9x7"]);
        assert!(ok, "{tag}: {err}");
        let (nodes, cells, clockwise) = msh_cells(msh.to_str().unwrap());
        assert_eq!(clockwise, 0, "{tag}");
        // two patches of 9x9 points (the interface links xi of one to eta of the other
        // or the same directions: every class gets the larger count) share one side
        assert!(cells >= 2 * 8 * 6 && nodes < 2 * cells, "{tag}: {nodes} nodes, {cells} cells");
        let names = msh_physical_names(&msh);
        let surfaces: Vec<&str> = names.iter().filter(|n| n.0 == 2).map(|n| n.1.as_str()).collect();
        if tag == "json" {
            assert_eq!(surfaces, patches.iter().map(String::as_str).collect::<Vec<_>>());
        }
        assert_eq!(surfaces.len(), 2, "{tag}");
        let curves = names.iter().filter(|n| n.0 == 1).count();
        assert_eq!(curves, 6, "{tag}: two patches with one shared side have 6 outer sides");
        assert!(names.iter().filter(|n| n.0 == 1).all(|n| n.1.contains('.')), "{tag}: PATCH.SIDE");
    }
    // SU2 markers, VTU, an OpenFOAM case with cellZones
    for out in ["plate.su2", "plate.vtu", "case/"] {
        let path = dir.join(out);
        let (ok, _, err) =
            run(&["mesh", result.to_str().unwrap(), "-o", path.to_str().unwrap(), "--structured", "9x7"]);
        assert!(ok, "{out}: {err}");
    }
    let su2 = std::fs::read_to_string(dir.join("plate.su2")).unwrap();
    assert!(su2.contains("NMARK= 6\n"));
    assert!(std::fs::read_to_string(dir.join("plate.vtu")).unwrap().contains("Name=\"patch\""));
    assert!(dir.join("case/constant/polyMesh/cellZones").exists());
    // triangulated: one conforming mesh with the same groups
    let (ok, _, err) = run(&[
        "mesh",
        result.to_str().unwrap(),
        "-o",
        dir.join("u.msh").to_str().unwrap(),
        "--unstructured",
        "--size",
        "0.5",
    ]);
    assert!(ok, "{err}");
    let (nodes, cells, clockwise) = msh_cells(dir.join("u.msh").to_str().unwrap());
    assert_eq!(clockwise, 0);
    // a triangulated disk: 2 nodes - boundary nodes - 2 triangles
    assert!(cells > nodes && cells < 2 * nodes, "{nodes} nodes, {cells} triangles");
    assert_eq!(msh_physical_names(&dir.join("u.msh")), msh_physical_names(&dir.join("json.msh")));
    // refused, nothing written: PLOT3D (one block), curved, clustered
    let refused: [(&str, &[&str]); 4] = [
        ("plate.xyz", &["--structured", "9x7"]),
        ("u2.msh", &["--unstructured", "--size", "0.5", "--order", "2"]),
        ("o2.msh", &["--structured", "9x7", "--order", "2"]),
        ("c.msh", &["--structured", "9x7", "--cluster", "eta:arctan:3"]),
    ];
    for (out, flags) in refused {
        let path = dir.join(out);
        let mut args = vec!["mesh", result.to_str().unwrap(), "-o", path.to_str().unwrap()];
        args.extend_from_slice(flags);
        let (ok, _, err) = run(&args);
        assert!(!ok && !err.is_empty(), "{out}");
        assert!(!path.exists(), "{out}");
    }
}

#[test]
fn mesh_names_a_document_it_cannot_mesh() {
    let scratch = tempfile::tempdir().unwrap();
    let out = scratch.path().join("b.msh");
    for input in [data().join("wavy_lid.json"), data().join("rings/male_rotor_in_casing.json")] {
        let o = bin().arg("mesh").arg(&input).arg("-o").arg(&out).args(["--structured", "9x9"]).output().unwrap();
        assert_eq!(o.status.code(), Some(1), "{}", input.display());
        assert!(!out.exists());
    }
}

#[test]
fn solve_a_layout_with_mesh_writes_one_mesh() {
    let scratch = tempfile::tempdir().unwrap();
    let (json, msh) = (scratch.path().join("c.json"), scratch.path().join("c.msh"));
    let out = bin()
        .arg("solve")
        .arg(data().join("gismo/xml/multipatch/circleMP.xml"))
        .arg("-q")
        .arg("-o")
        .arg(&json)
        .arg("--mesh")
        .arg(&msh)
        .args(["--structured", "5x5"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (_, cells, clockwise) = msh_cells(msh.to_str().unwrap());
    assert_eq!(clockwise, 0);
    let patches = common::read_json(&json)["patches"].as_array().unwrap().len();
    assert_eq!(msh_physical_names(&msh).iter().filter(|n| n.0 == 2).count(), patches);
    assert!(cells >= patches * 16);
}

#[test]
fn a_volume_is_meshed_with_hexahedra() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let qa = data().join("maps/quarter_annulus_nurbs.json");
    let volume = dir.join("v.json");
    let o = bin().arg("loft").args([&qa, &qa]).args(["--dz", "1", "-q", "-o"]).arg(&volume).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = volume.to_str().unwrap();
    for out in ["v.vtu", "v.msh"] {
        let path = dir.join(out);
        let (ok, _, err) = run(&["mesh", v, "-o", path.to_str().unwrap(), "--structured", "5x4x3"]);
        assert!(ok, "{out}: {err}");
        let text = std::fs::read_to_string(&path).unwrap();
        if out.ends_with("vtu") {
            // 4 x 3 x 2 hexahedra (VTK type 12)
            assert!(text.contains("NumberOfPoints=\"60\" NumberOfCells=\"24\""), "{out}");
        } else {
            let names = msh_physical_names(&path);
            let sides: Vec<&str> = names.iter().filter(|n| n.0 == 2).map(|n| n.1.as_str()).collect();
            assert_eq!(sides, ["west", "east", "south", "north", "front", "back"]);
        }
    }
    // refused, nothing written: a planar format, two counts, an unstructured mesh
    let refused: [(&str, &[&str]); 3] = [
        ("v.su2", &["--structured", "5x4x3"]),
        ("w.vtu", &["--structured", "5x4"]),
        ("u.vtu", &["--unstructured", "--size", "0.5"]),
    ];
    for (out, flags) in refused {
        let path = dir.join(out);
        let mut args = vec!["mesh", v, "-o", path.to_str().unwrap()];
        args.extend_from_slice(flags);
        let (ok, _, _) = run(&args);
        assert!(!ok && !path.exists(), "{out}");
    }
}
