//! A multipatch layout as drawn (paper §11.2): every patch's four sides (the patch
//! borders), the domain's outline (the sides on no interface), and, for a layout made by
//! the automatic layout of a general domain or plane graph (issue 31), the interior
//! vertices whose valence is not 4 and the layout's report. The layout is what a solve
//! in the viewer takes ([`winslow::Input::Layout`]); its report after the solve too.

use winslow::domain::template::IrregularVertex;
use winslow::domain::{AutoLayout, LayoutReport};
use winslow::multipatch::solve::MultipatchReport;
use winslow::multipatch::Layout;
use winslow::spline::surface::Side;
use winslow::Point;

use crate::view::{bounds_of, Bounds};

/// Points per patch side of the drawn borders.
const SIDE_POINTS: usize = 96;

/// A layout as drawn.
#[derive(Debug, Clone)]
pub struct LayoutView {
    /// The layout (patches given by their sides; a map given with a patch is kept).
    pub layout: Layout,
    /// Every patch's south, east, north and west side as polylines.
    pub borders: Vec<[Vec<Point>; 4]>,
    /// The sides that are on no interface: the domain's outline (outer loop and holes).
    pub outline: Vec<Vec<Point>>,
    /// What the automatic layout did (cuts, templates, irregular vertices), for a
    /// `domain` or `graph` document.
    pub report: Option<LayoutReport>,
    /// The report of the layout's solve, once solved in the viewer.
    pub solved: Option<MultipatchReport>,
}

impl LayoutView {
    /// The drawn borders and outline of `layout`.
    pub fn new(layout: Layout, report: Option<LayoutReport>) -> Self {
        let borders: Vec<[Vec<Point>; 4]> =
            layout.patches.iter().map(|p| Side::ALL.map(|s| p.sides[s as usize].sample(SIDE_POINTS))).collect();
        let on_interface = |patch: usize, side: Side| {
            layout.interfaces.iter().any(|i| {
                (i.first.patch == patch && i.first.side == side) || (i.second.patch == patch && i.second.side == side)
            })
        };
        let mut outline = Vec::new();
        for (p, sides) in borders.iter().enumerate() {
            for s in Side::ALL.into_iter().filter(|&s| !on_interface(p, s)) {
                outline.push(sides[s as usize].clone());
            }
        }
        Self { layout, borders, outline, report, solved: None }
    }

    /// The view of an automatic layout.
    pub fn of_auto(auto: AutoLayout) -> Self {
        Self::new(auto.layout, Some(auto.report))
    }

    /// The interior vertices of valence other than 4 (from the automatic layout's report;
    /// none for a layout given as a file).
    pub fn irregular(&self) -> &[IrregularVertex] {
        self.report.as_ref().map_or(&[], |r| r.irregular_vertices.as_slice())
    }

    /// Bounds of the borders.
    pub fn bounds(&self) -> Option<Bounds> {
        bounds_of(self.borders.iter().flatten().flatten())
    }
}
