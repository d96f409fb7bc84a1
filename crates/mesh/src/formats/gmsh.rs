//! Gmsh MSH 4.1 ASCII.
//!
//! Entities: points 1-4 at the parameter corners `(0,0), (1,0), (1,1), (0,1)`, curves 1-4
//! = south, east, north, west (counter-clockwise, physical groups 1-4 named by
//! [`Mesh::names`]), surface 1 bounded by them (physical group 5 "domain"). A ring
//! (periodic `eta`) has no corners and two closed curves, 4 (`inner`, `xi = 0`) and 2
//! (`outer`, `xi = 1`); its seam nodes are surface nodes. Every node is classified on
//! the entity its parameters lie on (corner, side or interior), one node block per
//! entity; elements: lines on the curves (types 1, 8, 26 for order 1, 2, 3), the cells
//! on the surface (triangles 2, 9, 21; quadrilaterals 3, 10, 36). Node tag = index + 1.
//!
//! A mesh with [`crate::Groups`] (several patches) is classified by group instead
//! ([`grouped`]): a curve per boundary group (physical group `1..=B`, named
//! `PATCH.SIDE`), a surface per cell group (physical group `B+1..=B+C`, named by the
//! patch), no point entities; a node lies on the curve of the first boundary edge that
//! holds it, else on the surface of the first cell that holds it.

use std::fmt::Write;

use winslow::Side;

use crate::error::Result;
use crate::{ElementKind, Mesh};

/// Entity `(dim, tag)` of a node from its parameters (a periodic direction has no
/// sides: its seam is interior).
pub fn entity(q: glam::DVec2, periodic: [bool; 2]) -> (usize, usize) {
    let (u0, u1) = (!periodic[0] && q.x == 0.0, !periodic[0] && q.x == 1.0);
    let (v0, v1) = (!periodic[1] && q.y == 0.0, !periodic[1] && q.y == 1.0);
    match (u0, u1, v0, v1) {
        (true, _, true, _) => (0, 1),
        (_, true, true, _) => (0, 2),
        (_, true, _, true) => (0, 3),
        (true, _, _, true) => (0, 4),
        (_, _, true, _) => (1, 1),
        (_, true, _, _) => (1, 2),
        (_, _, _, true) => (1, 3),
        (true, _, _, _) => (1, 4),
        _ => (2, 1),
    }
}

/// Gmsh element type of a cell kind and order.
pub fn cell_type(kind: ElementKind, order: usize) -> usize {
    match (kind, order) {
        (ElementKind::Triangle, 1) => 2,
        (ElementKind::Triangle, 2) => 9,
        (ElementKind::Triangle, _) => 21,
        (ElementKind::Quad, 1) => 3,
        (ElementKind::Quad, 2) => 10,
        (ElementKind::Quad, _) => 36,
    }
}

/// Gmsh line type of an order.
pub fn line_type(order: usize) -> usize {
    match order {
        1 => 1,
        2 => 8,
        _ => 26,
    }
}

/// The file's text.
pub fn to_string(mesh: &Mesh) -> Result<String> {
    if mesh.groups.is_some() {
        return grouped(mesh);
    }
    let mut s = String::with_capacity(64 * mesh.points.len() + 16 * mesh.cells.len());
    let w = |s: &mut String, a: std::fmt::Arguments| {
        let _ = s.write_fmt(a);
    };
    let sides = mesh.boundary_sides();
    let corners = !mesh.periodic.contains(&true);
    w(&mut s, format_args!("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n{}\n", sides.len() + 1));
    for &side in &sides {
        w(&mut s, format_args!("1 {} \"{}\"\n", side as usize + 1, mesh.name(side)));
    }
    w(&mut s, format_args!("2 5 \"domain\"\n$EndPhysicalNames\n"));
    // corner positions and bounding boxes from the nodes classified on each entity
    let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); 9]; // points 1-4, curves 1-4, surface
    let slot = |(d, t): (usize, usize)| match d {
        0 => t - 1,
        1 => 3 + t,
        _ => 8,
    };
    for (n, q) in mesh.params.iter().enumerate() {
        buckets[slot(entity(*q, mesh.periodic))].push(n);
    }
    let bbox = |nodes: &[usize]| {
        let mut lo = glam::DVec2::splat(f64::INFINITY);
        let mut hi = glam::DVec2::splat(f64::NEG_INFINITY);
        for &n in nodes {
            lo = lo.min(mesh.points[n]);
            hi = hi.max(mesh.points[n]);
        }
        (lo, hi)
    };
    let points = if corners { 4 } else { 0 };
    w(&mut s, format_args!("$Entities\n{points} {} 1 0\n", sides.len()));
    for t in 0..points {
        let p = buckets[t].first().map_or(glam::DVec2::ZERO, |&n| mesh.points[n]);
        w(&mut s, format_args!("{} {} {} 0 0\n", t + 1, p.x, p.y));
    }
    let curve_points = [[1, 2], [2, 3], [3, 4], [4, 1]];
    for t in sides.iter().map(|&side| side as usize) {
        let mut nodes = buckets[4 + t].clone();
        nodes.extend(curve_points[t].iter().flat_map(|&c| buckets[c - 1].iter().copied()));
        let (lo, hi) = bbox(&nodes);
        let [a, b] = curve_points[t];
        let ends = if corners { format!("2 {a} -{b}") } else { "0".into() };
        w(&mut s, format_args!("{} {} {} 0 {} {} 0 1 {} {ends}\n", t + 1, lo.x, lo.y, hi.x, hi.y, t + 1));
    }
    let all: Vec<usize> = (0..mesh.points.len()).collect();
    let (lo, hi) = bbox(&all);
    w(&mut s, format_args!("1 {} {} 0 {} {} 0 1 5 {}", lo.x, lo.y, hi.x, hi.y, sides.len()));
    for &side in &sides {
        w(&mut s, format_args!(" {}", side as usize + 1));
    }
    w(&mut s, format_args!("\n$EndEntities\n"));
    let entities = |k: usize| match k {
        0..=3 => (0, k + 1),
        4..=7 => (1, k - 3),
        _ => (2, 1),
    };
    let blocks = buckets.iter().filter(|b| !b.is_empty()).count();
    let n = mesh.points.len();
    w(&mut s, format_args!("$Nodes\n{blocks} {n} 1 {n}\n"));
    for (k, b) in buckets.iter().enumerate().filter(|(_, b)| !b.is_empty()) {
        let (d, t) = entities(k);
        w(&mut s, format_args!("{d} {t} 0 {}\n", b.len()));
        s.push_str(&super::par_text(b.len(), |s, k| {
            let _ = writeln!(s, "{}", b[k] + 1);
        }));
        s.push_str(&super::par_text(b.len(), |s, k| {
            let p = mesh.points[b[k]];
            let _ = writeln!(s, "{} {} 0", p.x, p.y);
        }));
    }
    w(&mut s, format_args!("$EndNodes\n"));
    let per_side: Vec<Vec<&crate::BoundaryEdge>> =
        Side::ALL.iter().map(|&sd| mesh.boundary.iter().filter(|e| e.side == sd).collect()).collect();
    let lines: usize = per_side.iter().map(Vec::len).sum();
    let cells = mesh.num_cells();
    let total = lines + cells;
    let blocks = per_side.iter().filter(|v| !v.is_empty()).count() + usize::from(cells > 0);
    w(&mut s, format_args!("$Elements\n{blocks} {total} 1 {total}\n"));
    let mut tag = 0;
    for (k, edges) in per_side.iter().enumerate().filter(|(_, v)| !v.is_empty()) {
        w(&mut s, format_args!("1 {} {} {}\n", k + 1, line_type(mesh.order), edges.len()));
        for e in edges {
            tag += 1;
            s.push_str(&tag.to_string());
            for &v in &e.nodes {
                w(&mut s, format_args!(" {}", v + 1));
            }
            s.push('\n');
        }
    }
    if cells > 0 {
        w(&mut s, format_args!("2 1 {} {cells}\n", cell_type(mesh.kind, mesh.order)));
        s.push_str(&super::par_text(cells, |s, c| {
            let _ = write!(s, "{}", tag + c + 1);
            for &v in mesh.cell(c) {
                let _ = write!(s, " {}", v + 1);
            }
            s.push('\n');
        }));
    }
    s.push_str("$EndElements\n");
    Ok(s)
}

/// The text of a mesh with [`crate::Groups`]: entities and physical groups by group.
pub fn grouped(mesh: &Mesh) -> Result<String> {
    let bgroups = mesh.boundary_groups();
    let cgroups = mesh.cell_groups();
    let (nb, nc) = (bgroups.len(), cgroups.len());
    let mut s = String::with_capacity(64 * mesh.points.len() + 16 * mesh.cells.len());
    let w = |s: &mut String, a: std::fmt::Arguments| {
        let _ = s.write_fmt(a);
    };
    w(&mut s, format_args!("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n{}\n", nb + nc));
    for (k, (name, _)) in bgroups.iter().enumerate() {
        w(&mut s, format_args!("1 {} \"{name}\"\n", k + 1));
    }
    for (k, (name, _)) in cgroups.iter().enumerate() {
        w(&mut s, format_args!("2 {} \"{name}\"\n", nb + k + 1));
    }
    s.push_str("$EndPhysicalNames\n");
    // the entity of each node: slot k < nb is curve k + 1, slot nb + k surface k + 1
    let mut slot = vec![usize::MAX; mesh.points.len()];
    for (k, (_, edges)) in bgroups.iter().enumerate() {
        for &e in edges {
            for &v in &mesh.boundary[e].nodes {
                if slot[v] == usize::MAX {
                    slot[v] = k;
                }
            }
        }
    }
    for (k, (_, cells)) in cgroups.iter().enumerate() {
        for &c in cells {
            for &v in mesh.cell(c) {
                if slot[v] == usize::MAX {
                    slot[v] = nb + k;
                }
            }
        }
    }
    let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); nb + nc];
    for (v, &k) in slot.iter().enumerate() {
        if let Some(b) = buckets.get_mut(k) {
            b.push(v);
        }
    }
    let bbox = |nodes: &mut dyn Iterator<Item = usize>| {
        let mut lo = glam::DVec2::splat(f64::INFINITY);
        let mut hi = glam::DVec2::splat(f64::NEG_INFINITY);
        for n in nodes {
            lo = lo.min(mesh.points[n]);
            hi = hi.max(mesh.points[n]);
        }
        (lo, hi)
    };
    // the curves that bound each surface: those with an edge of a cell of its group
    let faces = crate::topology::faces(mesh)?;
    let group_of = |c: usize| mesh.groups.as_ref().map_or(0, |g| g.cell_group[c]);
    let mut bounding: Vec<Vec<usize>> = vec![Vec::new(); nc];
    for (k, (_, edges)) in bgroups.iter().enumerate() {
        if let Some(&e) = edges.first() {
            // cell_groups lists every group, in order
            let g = group_of(faces.boundary[e].owner);
            if !bounding[g].contains(&(k + 1)) {
                bounding[g].push(k + 1);
            }
        }
    }
    w(&mut s, format_args!("$Entities\n0 {nb} {nc} 0\n"));
    for (k, (_, edges)) in bgroups.iter().enumerate() {
        let (lo, hi) = bbox(&mut edges.iter().flat_map(|&e| mesh.boundary[e].nodes.iter().copied()));
        w(&mut s, format_args!("{} {} {} 0 {} {} 0 1 {} 0\n", k + 1, lo.x, lo.y, hi.x, hi.y, k + 1));
    }
    for (k, (_, cells)) in cgroups.iter().enumerate() {
        let (lo, hi) = bbox(&mut cells.iter().flat_map(|&c| mesh.cell(c).iter().copied()));
        w(
            &mut s,
            format_args!("{} {} {} 0 {} {} 0 1 {} {}", k + 1, lo.x, lo.y, hi.x, hi.y, nb + k + 1, bounding[k].len()),
        );
        for t in &bounding[k] {
            w(&mut s, format_args!(" {t}"));
        }
        s.push('\n');
    }
    s.push_str("$EndEntities\n");
    let blocks = buckets.iter().filter(|b| !b.is_empty()).count();
    let n = mesh.points.len();
    w(&mut s, format_args!("$Nodes\n{blocks} {n} 1 {n}\n"));
    for (k, b) in buckets.iter().enumerate().filter(|(_, b)| !b.is_empty()) {
        let (d, t) = if k < nb { (1, k + 1) } else { (2, k - nb + 1) };
        w(&mut s, format_args!("{d} {t} 0 {}\n", b.len()));
        s.push_str(&super::par_text(b.len(), |s, k| {
            let _ = writeln!(s, "{}", b[k] + 1);
        }));
        s.push_str(&super::par_text(b.len(), |s, k| {
            let p = mesh.points[b[k]];
            let _ = writeln!(s, "{} {} 0", p.x, p.y);
        }));
    }
    s.push_str("$EndNodes\n");
    let lines: usize = bgroups.iter().map(|g| g.1.len()).sum();
    let total = lines + mesh.num_cells();
    let blocks = nb + cgroups.iter().filter(|g| !g.1.is_empty()).count();
    w(&mut s, format_args!("$Elements\n{blocks} {total} 1 {total}\n"));
    let mut tag = 0;
    for (k, (_, edges)) in bgroups.iter().enumerate() {
        w(&mut s, format_args!("1 {} {} {}\n", k + 1, line_type(mesh.order), edges.len()));
        for &e in edges {
            tag += 1;
            s.push_str(&tag.to_string());
            for &v in &mesh.boundary[e].nodes {
                w(&mut s, format_args!(" {}", v + 1));
            }
            s.push('\n');
        }
    }
    for (k, (_, cells)) in cgroups.iter().enumerate().filter(|g| !g.1 .1.is_empty()) {
        w(&mut s, format_args!("2 {} {} {}\n", k + 1, cell_type(mesh.kind, mesh.order), cells.len()));
        s.push_str(&super::par_text(cells.len(), |s, i| {
            let _ = write!(s, "{}", tag + i + 1);
            for &v in mesh.cell(cells[i]) {
                let _ = write!(s, " {}", v + 1);
            }
            s.push('\n');
        }));
        tag += cells.len();
    }
    s.push_str("$EndElements\n");
    Ok(s)
}
