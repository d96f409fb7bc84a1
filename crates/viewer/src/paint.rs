//! Painting helpers of the views: the `det J` heat map as a Gouraud-shaded mesh, the
//! control net, element outlines, the side colours and the probe's crosshair.

use egui::epaint::{Mesh, Vertex, WHITE_UV};
use egui::{Color32, Pos2, Shape, Stroke, Vec2};
use winslow::spline::hierarchical::map::HierarchicalMap;
use winslow::Point;

use crate::colour::{fold_colour, is_positive, ColourScale};
use crate::scene::MapView;

/// Colours of the sides south, east, north, west.
pub(crate) fn side_colours() -> [Color32; 4] {
    [
        Color32::from_rgb(200, 40, 40),
        Color32::from_rgb(40, 140, 40),
        Color32::from_rgb(40, 70, 200),
        Color32::from_rgb(200, 140, 0),
    ]
}

pub(crate) fn crosshair(painter: &egui::Painter, c: Pos2) {
    let s = Stroke::new(1.5, Color32::RED);
    painter.line_segment([c - Vec2::new(8.0, 0.0), c + Vec2::new(8.0, 0.0)], s);
    painter.line_segment([c - Vec2::new(0.0, 8.0), c + Vec2::new(0.0, 8.0)], s);
    painter.circle_stroke(c, 4.0, s);
}

/// The heat map over the sample grid: Gouraud-shaded cells with the colours of the
/// samples at their corners, and every cell with a non-positive corner painted flat in
/// the fold colour on top (no blend of fold and scale colours).
pub(crate) fn heat_mesh(mv: &MapView, scale: &ColourScale, pos: impl Fn(usize) -> Pos2) -> Shape {
    heat_mesh_values(mv.sample.n, &mv.sample.values, scale, pos)
}

/// [`heat_mesh`] of the `(n + 1)²` values of any uniform grid, `i` fastest (a volume's
/// slice).
pub(crate) fn heat_mesh_values(n: usize, values: &[f64], scale: &ColourScale, pos: impl Fn(usize) -> Pos2) -> Shape {
    let mut mesh = Mesh::default();
    mesh.vertices.reserve((n + 1) * (n + 1));
    for (k, &v) in values.iter().enumerate() {
        mesh.vertices.push(Vertex { pos: pos(k), uv: WHITE_UV, color: scale.colour(v) });
    }
    let idx = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut folded = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let ks = [idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)];
            if ks.iter().any(|&k| !is_positive(values[k as usize])) {
                folded.push(ks);
                continue;
            }
            mesh.add_triangle(ks[0], ks[1], ks[2]);
            mesh.add_triangle(ks[0], ks[2], ks[3]);
        }
    }
    let fold = fold_colour();
    for ks in folded {
        let base = mesh.vertices.len() as u32;
        for k in ks {
            mesh.vertices.push(Vertex { pos: pos(k as usize), uv: WHITE_UV, color: fold });
        }
        mesh.add_triangle(base, base + 1, base + 2);
        mesh.add_triangle(base, base + 2, base + 3);
    }
    Shape::mesh(mesh)
}

pub(crate) fn control_net(painter: &egui::Painter, map: &winslow::Surface, to: &impl Fn(Point) -> Pos2) {
    let [nx, ny] = map.shape();
    let stroke = Stroke::new(0.8, Color32::from_rgb(90, 90, 90));
    for j in 0..ny {
        painter.add(Shape::line((0..nx).map(|i| to(map.cp(i, j))).collect(), stroke));
    }
    for i in 0..nx {
        painter.add(Shape::line((0..ny).map(|j| to(map.cp(i, j))).collect(), stroke));
    }
    for p in &map.control_points {
        painter.circle_filled(to(*p), 2.0, Color32::from_rgb(60, 60, 60));
    }
}

/// The control net of a THB map ([`HierarchicalMap::control_net`]: on every level the
/// segments between neighbouring active functions' control points), in the colours of the
/// tensor net; the points of the active functions.
pub(crate) fn thb_control_net(painter: &egui::Painter, map: &HierarchicalMap, to: &impl Fn(Point) -> Pos2) {
    let stroke = Stroke::new(0.8, Color32::from_rgb(90, 90, 90));
    for [a, b] in map.control_net() {
        painter.line_segment([to(map.control_points[a]), to(map.control_points[b])], stroke);
    }
    for p in &map.control_points {
        painter.circle_filled(to(*p), 2.0, Color32::from_rgb(60, 60, 60));
    }
}

/// The image of an element's boundary (core evaluation of the map).
pub(crate) fn element_outline(mv: &MapView, xi: [f64; 2], eta: [f64; 2]) -> Vec<Point> {
    let m = 24;
    let mut out = Vec::with_capacity(4 * m);
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    for k in 0..m {
        out.push(mv.map.eval(lerp(xi[0], xi[1], k as f64 / m as f64), eta[0]));
    }
    for k in 0..m {
        out.push(mv.map.eval(xi[1], lerp(eta[0], eta[1], k as f64 / m as f64)));
    }
    for k in 0..m {
        out.push(mv.map.eval(lerp(xi[1], xi[0], k as f64 / m as f64), eta[1]));
    }
    for k in 0..m {
        out.push(mv.map.eval(xi[0], lerp(eta[1], eta[0], k as f64 / m as f64)));
    }
    out
}

/// The marker colour of an irregular vertex of a layout: blue below valence 4, red above.
pub(crate) fn irregular_colour(valence: usize) -> Color32 {
    if valence < 4 {
        Color32::from_rgb(40, 110, 230)
    } else {
        Color32::from_rgb(230, 60, 40)
    }
}
