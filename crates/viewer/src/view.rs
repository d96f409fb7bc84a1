//! The transform between a view's world coordinates (physical `(x, y)` or parameters
//! `(xi, eta)`) and screen points: a uniform scale about a centre, `y` pointing up.
//! Zoom keeps the world point under the cursor fixed; pan moves by screen pixels.

use egui::{Pos2, Rect, Vec2};
use glam::{DAffine2, DVec2};

/// Smallest and largest zoom relative to the fitted view.
pub const ZOOM_RANGE: (f64, f64) = (0.05, 1e5);

/// An axis-aligned box of world coordinates, `[min, max]`.
pub type Bounds = [[f64; 2]; 2];

/// Bounds of a point set (`None` if empty or not finite).
pub fn bounds_of<'a>(points: impl IntoIterator<Item = &'a [f64; 2]>) -> Option<Bounds> {
    let mut b = [[f64::INFINITY; 2], [f64::NEG_INFINITY; 2]];
    for p in points {
        for d in 0..2 {
            b[0][d] = b[0][d].min(p[d]);
            b[1][d] = b[1][d].max(p[d]);
        }
    }
    (b[0][0].is_finite() && b[1][0].is_finite() && b[0][1].is_finite() && b[1][1].is_finite()).then_some(b)
}

/// World-to-screen transform of one view: `screen = rect.center + s (w - c)` with the
/// `y` axis flipped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewTransform {
    /// World point at the centre of the view's rectangle.
    pub centre: [f64; 2],
    /// Pixels per world unit.
    pub scale: f64,
    /// The scale of the fitted view, for the zoom limits.
    pub fitted_scale: f64,
}

impl Default for ViewTransform {
    fn default() -> Self {
        Self { centre: [0.5, 0.5], scale: 100.0, fitted_scale: 100.0 }
    }
}

impl ViewTransform {
    /// The transform showing `bounds` whole in a `size` rectangle with `margin` (a
    /// fraction of the size) around it.
    pub fn fit(bounds: Bounds, size: Vec2, margin: f64) -> Self {
        let w = (bounds[1][0] - bounds[0][0]).max(1e-300);
        let h = (bounds[1][1] - bounds[0][1]).max(1e-300);
        let avail = |s: f32| (s as f64 * (1.0 - 2.0 * margin)).max(1.0);
        let scale = (avail(size.x) / w).min(avail(size.y) / h);
        let centre = [0.5 * (bounds[0][0] + bounds[1][0]), 0.5 * (bounds[0][1] + bounds[1][1])];
        Self { centre, scale, fitted_scale: scale }
    }

    /// The world-to-screen map of this view in `rect` as an affine map,
    /// `screen = rect.center + diag(s, −s) (w − c)`.
    pub fn affine(&self, rect: Rect) -> DAffine2 {
        let c = rect.center();
        DAffine2::from_translation(DVec2::new(c.x as f64, c.y as f64))
            * DAffine2::from_scale(DVec2::new(self.scale, -self.scale))
            * DAffine2::from_translation(-DVec2::from(self.centre))
    }

    /// Screen point of a world point.
    pub fn to_screen(&self, rect: Rect, w: [f64; 2]) -> Pos2 {
        let p = self.affine(rect).transform_point2(DVec2::from(w));
        Pos2::new(p.x as f32, p.y as f32)
    }

    /// World point of a screen point.
    pub fn to_world(&self, rect: Rect, p: Pos2) -> [f64; 2] {
        self.affine(rect).inverse().transform_point2(DVec2::new(p.x as f64, p.y as f64)).into()
    }

    /// Multiply the scale by `factor` (clamped to [`ZOOM_RANGE`] of the fitted scale),
    /// keeping the world point under `anchor` where it is.
    pub fn zoom_about(&mut self, rect: Rect, anchor: Pos2, factor: f64) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let w = self.to_world(rect, anchor);
        let (lo, hi) = (ZOOM_RANGE.0 * self.fitted_scale, ZOOM_RANGE.1 * self.fitted_scale);
        self.scale = (self.scale * factor).clamp(lo, hi);
        let c = rect.center();
        self.centre = [w[0] - (anchor.x - c.x) as f64 / self.scale, w[1] + (anchor.y - c.y) as f64 / self.scale];
    }

    /// Move the picture by `delta` screen pixels.
    pub fn pan(&mut self, delta: Vec2) {
        self.centre[0] -= delta.x as f64 / self.scale;
        self.centre[1] += delta.y as f64 / self.scale;
    }

    /// Zoom relative to the fitted view.
    pub fn zoom(&self) -> f64 {
        self.scale / self.fitted_scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect() -> Rect {
        Rect::from_min_size(Pos2::new(10.0, 20.0), Vec2::new(400.0, 300.0))
    }

    #[test]
    fn fit_shows_the_bounds_whole_and_centred() {
        let b = [[-1.0, 2.0], [3.0, 4.0]];
        let t = ViewTransform::fit(b, rect().size(), 0.05);
        // width 4 in 360 px, height 2 in 270 px: width limits, 90 px per unit
        assert!((t.scale - 90.0).abs() < 1e-9);
        let lo = t.to_screen(rect(), b[0]);
        let hi = t.to_screen(rect(), b[1]);
        assert!((lo.x - 30.0).abs() < 1e-3 && (hi.x - 390.0).abs() < 1e-3);
        // y up: the lower world corner is lower on screen
        assert!(lo.y > hi.y);
        assert!(((lo.y + hi.y) / 2.0 - rect().center().y).abs() < 1e-3);
    }

    #[test]
    fn screen_and_world_round_trip() {
        let t = ViewTransform { centre: [0.3, -2.0], scale: 37.5, fitted_scale: 37.5 };
        for w in [[0.0, 0.0], [1.5, -3.25], [-7.0, 2.0]] {
            let back = t.to_world(rect(), t.to_screen(rect(), w));
            assert!((back[0] - w[0]).abs() < 1e-4 && (back[1] - w[1]).abs() < 1e-4, "{back:?}");
        }
    }

    #[test]
    fn zoom_keeps_the_anchor_fixed() {
        let mut t = ViewTransform::fit([[0.0, 0.0], [1.0, 1.0]], rect().size(), 0.0);
        let anchor = Pos2::new(100.0, 250.0);
        let before = t.to_world(rect(), anchor);
        t.zoom_about(rect(), anchor, 3.0);
        assert!((t.zoom() - 3.0).abs() < 1e-12);
        let after = t.to_world(rect(), anchor);
        assert!((before[0] - after[0]).abs() < 1e-6 && (before[1] - after[1]).abs() < 1e-6);
        // clamped, and still anchored
        t.zoom_about(rect(), anchor, 1e12);
        assert!((t.zoom() - ZOOM_RANGE.1).abs() < 1e-6);
        let after = t.to_world(rect(), anchor);
        assert!((before[0] - after[0]).abs() < 1e-6 && (before[1] - after[1]).abs() < 1e-6);
        let s = t.scale;
        t.zoom_about(rect(), anchor, f64::NAN);
        assert_eq!(t.scale, s);
    }

    #[test]
    fn pan_moves_the_picture_with_the_mouse() {
        let mut t = ViewTransform::fit([[0.0, 0.0], [2.0, 1.0]], rect().size(), 0.1);
        let w = [0.7, 0.2];
        let p = t.to_screen(rect(), w);
        t.pan(Vec2::new(15.0, -8.0));
        let q = t.to_screen(rect(), w);
        assert!((q.x - p.x - 15.0).abs() < 1e-3 && (q.y - p.y + 8.0).abs() < 1e-3);
    }

    #[test]
    fn bounds_of_points() {
        assert_eq!(bounds_of(&[[1.0, 5.0], [-2.0, 3.0]]), Some([[-2.0, 3.0], [1.0, 5.0]]));
        assert_eq!(bounds_of(&[]), None);
        assert_eq!(bounds_of(&[[f64::NAN, 0.0]]), None);
    }
}
