//! Every writer's output parsed back by a small reader of the format's rules: counts,
//! counter-clockwise cells, side labels, and the format's own requirements.

mod common;

use std::collections::HashMap;
use std::path::Path;

use common::{annulus, cut_ring, ring, signed_area};
use winslow_mesh::formats::{write, Format};
use winslow_mesh::high_order::elevate;
use winslow_mesh::{structured, unstructured, DVec2, Distribution, Mesh, Side, StructuredOptions, UnstructuredOptions};

/// Meshes and the maps they were made on: a quarter annulus structured and
/// unstructured, a periodic ring structured, then rings whose seam is shared: the ring
/// and a cut ring (west = east) triangulated, the cut ring structured.
fn cases() -> Vec<(Mesh, winslow::Surface)> {
    let map = annulus();
    let opts = StructuredOptions {
        points: [13, 7],
        distribution: [Distribution::Uniform, Distribution::Arctan { strength: 6.0 }],
    };
    let tri = |m: &winslow::Surface| unstructured(m, &UnstructuredOptions { size: 0.4, ..Default::default() }).unwrap();
    let cut = cut_ring(true, 0.0);
    vec![
        (structured(&map, &opts).unwrap(), map.clone()),
        (unstructured(&map, &UnstructuredOptions { size: 0.25, ..Default::default() }).unwrap(), map),
        (
            structured(&ring(), &StructuredOptions { points: [5, 24], distribution: opts.distribution.clone() })
                .unwrap(),
            ring(),
        ),
        (tri(&ring()), ring()),
        (tri(&cut), cut.clone()),
        (structured(&cut, &StructuredOptions::uniform(24, 5)).unwrap(), cut),
    ]
}

fn meshes() -> Vec<Mesh> {
    cases().into_iter().map(|c| c.0).collect()
}

fn side_counts(mesh: &Mesh) -> [usize; 4] {
    Side::ALL.map(|s| mesh.boundary.iter().filter(|e| e.side == s).count())
}

fn section<'a>(text: &'a str, name: &str) -> Vec<&'a str> {
    let start = text.find(&format!("${name}\n")).unwrap_or_else(|| panic!("no ${name}")) + name.len() + 2;
    let end = text.find(&format!("$End{name}")).unwrap();
    text[start..end].lines().collect()
}

fn nums(line: &str) -> Vec<f64> {
    line.split_whitespace().map(|t| t.parse().unwrap()).collect()
}

/// Reads MSH 4.1: physical names, entities, node blocks (classified where the
/// parameters say), element blocks; returns (nodes by tag, cells, lines per curve).
fn read_msh(text: &str, mesh: &Mesh) {
    assert_eq!(section(text, "MeshFormat"), ["4.1 0 8"]);
    let names = section(text, "PhysicalNames");
    let sides = mesh.boundary_sides();
    let mut expect: Vec<String> = sides.iter().map(|&s| format!("1 {} \"{}\"", s as usize + 1, mesh.name(s))).collect();
    expect.push("2 5 \"domain\"".into());
    assert_eq!(names[1..], expect);
    let ent = section(text, "Entities");
    let points = if mesh.periodic.contains(&true) { 0 } else { 4 };
    assert_eq!(ent[0], format!("{points} {} 1 0", sides.len()));
    for (k, &side) in sides.iter().enumerate() {
        let v = nums(ent[1 + points + k]);
        let t = side as usize + 1;
        assert_eq!((v[0], v[7], v[8]), (t as f64, 1.0, t as f64), "curve {t} physical group");
    }
    let mut surface = vec![1.0, 5.0, sides.len() as f64];
    surface.extend(sides.iter().map(|&s| (s as usize + 1) as f64));
    assert_eq!(nums(ent[1 + points + sides.len()])[7..], surface);
    let lines = section(text, "Nodes");
    let head = nums(lines[0]);
    let n = mesh.points.len();
    assert_eq!(head, [head[0], n as f64, 1.0, n as f64]);
    let mut at = 1;
    let mut coords: HashMap<usize, DVec2> = HashMap::new();
    for _ in 0..head[0] as usize {
        let b = nums(lines[at]);
        let (dim, tag, count) = (b[0] as usize, b[1] as usize, b[3] as usize);
        let tags: Vec<usize> = lines[at + 1..at + 1 + count].iter().map(|l| l.trim().parse().unwrap()).collect();
        for (k, &t) in tags.iter().enumerate() {
            let x = nums(lines[at + 1 + count + k]);
            coords.insert(t, DVec2::new(x[0], x[1]));
            assert_eq!(
                winslow_mesh::formats::gmsh::entity(mesh.params[t - 1], mesh.periodic),
                (dim, tag),
                "node {t} classification"
            );
        }
        at += 1 + 2 * count;
    }
    assert_eq!(coords.len(), n);
    let el = section(text, "Elements");
    let head = nums(el[0]);
    let cells = mesh.num_cells();
    let total = cells + mesh.boundary.len();
    assert_eq!(head[1..], [total as f64, 1.0, total as f64]);
    let mut at = 1;
    let mut per_curve = [0usize; 4];
    let mut seen_cells = 0;
    for _ in 0..head[0] as usize {
        let b = nums(el[at]);
        let (dim, tag, ty, count) = (b[0] as usize, b[1] as usize, b[2] as usize, b[3] as usize);
        for l in &el[at + 1..at + 1 + count] {
            let v: Vec<usize> = l.split_whitespace().skip(1).map(|t| t.parse().unwrap()).collect();
            if dim == 1 {
                assert_eq!(ty, [1, 8, 26][mesh.order - 1]);
                assert_eq!(v.len(), mesh.order + 1);
                per_curve[tag - 1] += 1;
                for t in &v {
                    let e = winslow_mesh::formats::gmsh::entity(mesh.params[t - 1], mesh.periodic);
                    assert!(e == (1, tag) || e.0 == 0, "line node {t} off curve {tag}");
                }
            } else {
                assert_eq!(v.len(), mesh.nodes_per_cell());
                let k = mesh.kind.corners();
                let p: Vec<DVec2> = v[..k].iter().map(|t| coords[t]).collect();
                assert!(signed_area(&p) > 0.0, "element not counter-clockwise");
                seen_cells += 1;
            }
        }
        at += 1 + count;
    }
    assert_eq!(per_curve, side_counts(mesh));
    assert_eq!(seen_cells, cells);
}

#[test]
fn gmsh_round_trip() {
    let scratch = tempfile::tempdir().unwrap();
    for (mesh, map) in cases() {
        for p in 1..=3 {
            let m = elevate(&mesh, &map, p).unwrap();
            let path = scratch.path().join(format!("m{p}.msh"));
            write(&m, &path, Format::Gmsh).unwrap();
            read_msh(&std::fs::read_to_string(&path).unwrap(), &m);
        }
    }
}

fn xml_array<'a>(text: &'a str, name: &str) -> Vec<&'a str> {
    let tag = format!("Name=\"{name}\"");
    let start = text.find(&tag).unwrap_or_else(|| panic!("no {name}"));
    let body = &text[start..];
    let open = body.find('>').unwrap() + 1;
    let close = body.find("</DataArray>").unwrap();
    body[open..close].split_whitespace().collect()
}

#[test]
fn vtu_round_trip() {
    let scratch = tempfile::tempdir().unwrap();
    for (mesh, map) in cases() {
        for p in 1..=3 {
            let m = elevate(&mesh, &map, p).unwrap();
            let path = scratch.path().join(format!("m{p}.vtu"));
            write(&m, &path, Format::Vtu).unwrap();
            let text = std::fs::read_to_string(&path).unwrap();
            let n = m.points.len();
            let cells = m.num_cells();
            assert!(text.contains(&format!("NumberOfPoints=\"{n}\" NumberOfCells=\"{cells}\"")));
            let pts_start = text.find("NumberOfComponents=\"3\" format=\"ascii\">").unwrap();
            let pts: Vec<f64> = text[pts_start..]
                .split('>')
                .nth(1)
                .unwrap()
                .split('<')
                .next()
                .unwrap()
                .split_whitespace()
                .map(|t| t.parse().unwrap())
                .collect();
            assert_eq!(pts.len(), 3 * n);
            let conn: Vec<usize> = xml_array(&text, "connectivity").iter().map(|t| t.parse().unwrap()).collect();
            let offsets: Vec<usize> = xml_array(&text, "offsets").iter().map(|t| t.parse().unwrap()).collect();
            let types: Vec<u8> = xml_array(&text, "types").iter().map(|t| t.parse().unwrap()).collect();
            assert_eq!((offsets.len(), types.len(), conn.len()), (cells, cells, cells * m.nodes_per_cell()));
            let ty = match (m.kind, p) {
                (winslow_mesh::ElementKind::Triangle, 1) => 5,
                (winslow_mesh::ElementKind::Triangle, 2) => 22,
                (winslow_mesh::ElementKind::Triangle, _) => 69,
                (_, 1) => 9,
                (_, 2) => 28,
                _ => 70,
            };
            assert!(types.iter().all(|&t| t == ty));
            let mut start = 0;
            for &end in &offsets {
                let k = m.kind.corners();
                let c: Vec<DVec2> =
                    conn[start..start + k].iter().map(|&i| DVec2::new(pts[3 * i], pts[3 * i + 1])).collect();
                assert!(signed_area(&c) > 0.0);
                if ty == 70 {
                    // VTK Lagrange quad: edge 2 runs from corner 3 to corner 2, the
                    // interior is lexicographic: node 12 nearest corner 0, 14 nearest 3
                    let q = |i: usize| m.params[conn[start + i]];
                    assert!((q(8) - q(3)).length() < (q(8) - q(2)).length());
                    assert!((q(14) - q(3)).length() < (q(14) - q(2)).length());
                }
                start = end;
            }
            for f in ["area", "min_angle", "max_angle", "aspect_ratio", "skewness", "growth_ratio", "non_orthogonality"]
            {
                let v: Vec<f64> = xml_array(&text, f).iter().map(|t| t.parse().unwrap()).collect();
                assert_eq!(v.len(), cells, "{f}");
            }
            assert!(xml_array(&text, "area").iter().all(|t| t.parse::<f64>().unwrap() > 0.0));
        }
    }
}

#[test]
fn su2_round_trip() {
    let scratch = tempfile::tempdir().unwrap();
    for mesh in meshes() {
        let path = scratch.path().join("m.su2");
        write(&mesh, &path, Format::Su2).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('%')).collect();
        assert_eq!(lines[0], "NDIME= 2");
        let ne: usize = lines[1].strip_prefix("NELEM= ").unwrap().parse().unwrap();
        assert_eq!(ne, mesh.num_cells());
        let np: usize = lines[2 + ne].strip_prefix("NPOIN= ").unwrap().parse().unwrap();
        let pts: Vec<DVec2> = lines[3 + ne..3 + ne + np]
            .iter()
            .map(|l| {
                let v = nums(l);
                DVec2::new(v[0], v[1])
            })
            .collect();
        for (k, l) in lines[2..2 + ne].iter().enumerate() {
            let v: Vec<usize> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            let k_nodes = mesh.kind.corners();
            assert_eq!(v[0], if k_nodes == 3 { 5 } else { 9 });
            assert_eq!(v.len(), k_nodes + 2);
            assert_eq!(v[k_nodes + 1], k);
            let c: Vec<DVec2> = v[1..=k_nodes].iter().map(|&i| pts[i]).collect();
            assert!(signed_area(&c) > 0.0);
        }
        let mut at = 3 + ne + np;
        let sides = mesh.boundary_sides();
        assert_eq!(lines[at], format!("NMARK= {}", sides.len()));
        at += 1;
        // every edge used by one cell only is on a marker: the seam of a ring is interior
        let mut once: HashMap<(usize, usize), usize> = HashMap::new();
        for l in &lines[2..2 + ne] {
            let v: Vec<usize> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            let c = &v[1..v.len() - 1];
            for e in 0..c.len() {
                let (a, b) = (c[e], c[(e + 1) % c.len()]);
                *once.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        once.retain(|_, n| *n == 1);
        let mut marked = 0;
        for side in &sides {
            let s = *side as usize;
            assert_eq!(lines[at], format!("MARKER_TAG= {}", mesh.name(*side)));
            let k: usize = lines[at + 1].strip_prefix("MARKER_ELEMS= ").unwrap().parse().unwrap();
            assert_eq!(k, side_counts(&mesh)[s]);
            marked += k;
            for l in &lines[at + 2..at + 2 + k] {
                let v: Vec<usize> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
                assert_eq!(v[0], 3);
                assert!(once.contains_key(&(v[1].min(v[2]), v[1].max(v[2]))), "marker edge inside the mesh");
                assert!(v[1..].iter().all(|&i| match side {
                    Side::South => mesh.params[i].y == 0.0,
                    Side::East => mesh.params[i].x == 1.0,
                    Side::North => mesh.params[i].y == 1.0,
                    Side::West => mesh.params[i].x == 0.0,
                }));
            }
            at += 2 + k;
        }
        assert_eq!(at, lines.len());
        assert_eq!(marked, once.len(), "boundary edges without a marker");
        // no two points coincide
        let mut sorted: Vec<(u64, u64)> = pts.iter().map(|p| (p.x.to_bits(), p.y.to_bits())).collect();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), np);
    }
}

#[test]
fn plot3d_round_trip_and_refusals() {
    let scratch = tempfile::tempdir().unwrap();
    let all = meshes();
    let (s, u, r) = (&all[0], &all[1], &all[2]);
    // a ring is an O-grid closed by repeating its seam line (JMAX = 24 + 1)
    let path = scratch.path().join("r.xyz");
    write(r, &path, Format::Plot3d).unwrap();
    let v: Vec<f64> = std::fs::read_to_string(&path).unwrap().split_whitespace().map(|t| t.parse().unwrap()).collect();
    assert_eq!(v[..3], [1.0, 5.0, 25.0]);
    let n = 5 * 25;
    assert_eq!(v.len(), 3 + 2 * n);
    for i in 0..5 {
        assert_eq!((v[3 + i], v[3 + n + i]), (v[3 + 24 * 5 + i], v[3 + n + 24 * 5 + i]));
        assert_eq!((v[3 + i], v[3 + n + i]), (r.points[i].x, r.points[i].y));
    }
    let path = scratch.path().join("m.xyz");
    write(s, &path, Format::Plot3d).unwrap();
    let v: Vec<f64> = std::fs::read_to_string(&path).unwrap().split_whitespace().map(|t| t.parse().unwrap()).collect();
    assert_eq!(v[..3], [1.0, 13.0, 7.0]);
    let n = 13 * 7;
    assert_eq!(v.len(), 3 + 2 * n);
    for (k, p) in s.points.iter().enumerate() {
        assert_eq!((v[3 + k], v[3 + n + k]), (p.x, p.y));
    }
    let bad = scratch.path().join("u.xyz");
    assert!(write(u, &bad, Format::Plot3d).is_err());
    assert!(write(&elevate(s, &annulus(), 2).unwrap(), &scratch.path().join("e.su2"), Format::Su2).is_err());
    assert_eq!(Format::from_path(Path::new("a/b.msh")).unwrap(), Format::Gmsh);
    assert_eq!(Format::from_path(Path::new("case/")).unwrap(), Format::OpenFoam);
    assert!(Format::from_path(Path::new("a.stl")).is_err());
}

/// Strip the FoamFile header and read the list body.
fn foam_list(dir: &Path, name: &str) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join(name)).unwrap();
    let body = &text[text.find("}\n").unwrap() + 2..];
    let mut lines = body.lines().map(str::trim).filter(|l| !l.is_empty());
    let n: usize = lines.next().unwrap().parse().unwrap();
    assert_eq!(lines.next(), Some("("));
    let items: Vec<String> = lines.by_ref().take(n).map(String::from).collect();
    assert_eq!(lines.next(), Some(")"));
    items
}

#[test]
fn openfoam_polymesh_follows_the_rules() {
    let scratch = tempfile::tempdir().unwrap();
    for mesh in meshes() {
        let case = scratch.path().join(format!("case-{}", mesh.kind.name()));
        write(&mesh, &case, Format::OpenFoam).unwrap();
        let dir = case.join("constant/polyMesh");
        let pts: Vec<[f64; 3]> = foam_list(&dir, "points")
            .iter()
            .map(|l| {
                let v = nums(l.trim_matches(|c| c == '(' || c == ')'));
                [v[0], v[1], v[2]]
            })
            .collect();
        let faces: Vec<Vec<usize>> = foam_list(&dir, "faces")
            .iter()
            .map(|l| {
                let (_, r) = l.split_once('(').unwrap();
                r.trim_end_matches(')').split_whitespace().map(|t| t.parse().unwrap()).collect()
            })
            .collect();
        let owner: Vec<usize> = foam_list(&dir, "owner").iter().map(|t| t.parse().unwrap()).collect();
        let neighbour: Vec<usize> = foam_list(&dir, "neighbour").iter().map(|t| t.parse().unwrap()).collect();
        let cells = mesh.num_cells();
        assert_eq!(pts.len(), 2 * mesh.points.len());
        assert_eq!(owner.len(), faces.len());
        let ni = neighbour.len();
        // upper-triangular order: owner < neighbour, sorted by owner then neighbour
        for f in 0..ni {
            assert!(owner[f] < neighbour[f]);
            if f > 0 {
                assert!((owner[f - 1], neighbour[f - 1]) < (owner[f], neighbour[f]));
            }
        }
        // face area vectors (Newell) and centres
        let area = |f: &[usize]| {
            let mut a = [0.0; 3];
            for k in 0..f.len() {
                let (p, q) = (pts[f[k]], pts[f[(k + 1) % f.len()]]);
                a[0] += (p[1] - q[1]) * (p[2] + q[2]);
                a[1] += (p[2] - q[2]) * (p[0] + q[0]);
                a[2] += (p[0] - q[0]) * (p[1] + q[1]);
            }
            a.map(|x| 0.5 * x)
        };
        let centre = |f: &[usize]| {
            let mut c = [0.0; 3];
            for &i in f {
                for d in 0..3 {
                    c[d] += pts[i][d] / f.len() as f64;
                }
            }
            c
        };
        // closed cells: the outward area vectors sum to zero
        let mut sum = vec![[0.0f64; 3]; cells];
        let mut cc = vec![[0.0f64; 3]; cells];
        let mut nf = vec![0.0; cells];
        for (f, face) in faces.iter().enumerate() {
            let a = area(face);
            let c = centre(face);
            for d in 0..3 {
                sum[owner[f]][d] += a[d];
                cc[owner[f]][d] += c[d];
            }
            nf[owner[f]] += 1.0;
            if f < ni {
                for d in 0..3 {
                    sum[neighbour[f]][d] -= a[d];
                    cc[neighbour[f]][d] += c[d];
                }
                nf[neighbour[f]] += 1.0;
            }
        }
        for c in 0..cells {
            assert!(sum[c].iter().all(|x| x.abs() < 1e-12), "cell {c} not closed: {:?}", sum[c]);
        }
        // internal normals point from owner to neighbour
        for f in 0..ni {
            let a = area(&faces[f]);
            let (o, n) = (owner[f], neighbour[f]);
            let d: Vec<f64> = (0..3).map(|k| cc[n][k] / nf[n] - cc[o][k] / nf[o]).collect();
            assert!(a[0] * d[0] + a[1] * d[1] + a[2] * d[2] > 0.0, "face {f}");
        }
        let b = std::fs::read_to_string(dir.join("boundary")).unwrap();
        let mut start = ni;
        let counts = side_counts(&mesh);
        let sides = mesh.boundary_sides();
        let mut names: Vec<&str> = sides.iter().map(|&s| mesh.name(s)).collect();
        names.push("frontAndBack");
        for (k, name) in names.iter().enumerate() {
            let at = b.find(&format!("    {name}\n")).unwrap_or_else(|| panic!("no patch {name}"));
            let block = &b[at..at + b[at..].find('}').unwrap()];
            let get = |key: &str| -> usize {
                let l = block.lines().find(|l| l.trim_start().starts_with(key)).unwrap();
                l.split_whitespace().nth(1).unwrap().trim_end_matches(';').parse().unwrap()
            };
            let wall = k < sides.len();
            let n = if wall { counts[sides[k] as usize] } else { 2 * cells };
            assert_eq!((get("nFaces"), get("startFace")), (n, start), "{name}");
            assert!(block.contains(if wall { "type            patch;" } else { "type            empty;" }));
            start += n;
        }
        assert_eq!(start, faces.len());
    }
}
