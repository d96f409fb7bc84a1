//! A picture of a map without any GPU or window: the image of a fine parameter grid
//! filled with a `det J` heat map (Gouraud-shaded triangles), the iso-lines of `xi` and
//! `eta`, and the boundary. Non-positive `det J` is painted magenta, a colour that no
//! positive value uses. Output is an RGBA buffer; the CLI encodes it as PNG. A THB map
//! ([`render_thb`]) is drawn with the borders of its active cells instead of iso-lines.

use crate::error::Result;
use crate::spline::basis::BasisDerivs;
use crate::spline::curve::Point;
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::surface::Surface;
use crate::verify::quality::grid_abscissae;

/// An RGBA8 image, row-major from the top-left.
#[derive(Debug, Clone)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `4 * width * height` bytes.
    pub rgba: Vec<u8>,
}

/// What to draw.
#[derive(Debug, Clone)]
pub struct PictureOptions {
    /// Longer side of the image in pixels.
    pub size: usize,
    /// Iso-lines per direction (0: none).
    pub grid_lines: usize,
    /// Heat-map resolution (cells per direction).
    pub resolution: usize,
    /// Extra line segments to draw (e.g. matched pairs), physical coordinates.
    pub segments: Vec<(Point, Point)>,
    /// Kinks of the boundary (paper §9), physical coordinates, and whether the map keeps
    /// each exactly: a diagonal cross where kept (as the paper's Fig. 16 marks them), an
    /// upright one where rounded.
    pub kinks: Vec<(Point, bool)>,
}

impl Default for PictureOptions {
    fn default() -> Self {
        Self { size: 900, grid_lines: 24, resolution: 240, segments: Vec::new(), kinks: Vec::new() }
    }
}

/// Colour of a kink kept exactly ([`PictureOptions::kinks`]).
pub(crate) const KEPT_KINK_COLOUR: [u8; 3] = [200, 0, 0];

/// Colour of a kink rounded by the fit.
pub(crate) const ROUNDED_KINK_COLOUR: [u8; 3] = [240, 140, 0];

/// Colour of non-positive `det J`.
pub const FOLD_COLOUR: [u8; 3] = [255, 0, 255];

/// Viridis-like map of `t in [0, 1]` (never magenta).
pub fn colormap(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] =
        [[68.0, 1.0, 84.0], [59.0, 82.0, 139.0], [33.0, 145.0, 140.0], [94.0, 201.0, 98.0], [253.0, 231.0, 37.0]];
    let t = t.clamp(0.0, 1.0) * 4.0;
    let k = (t.floor() as usize).min(3);
    let f = t - k as f64;
    let mut c = [0u8; 3];
    for i in 0..3 {
        c[i] = (STOPS[k][i] * (1.0 - f) + STOPS[k + 1][i] * f).round() as u8;
    }
    c
}

struct Canvas {
    w: usize,
    h: usize,
    rgba: Vec<u8>,
    x0: f64,
    y0: f64,
    s: f64,
}

impl Canvas {
    fn to_px(&self, p: Point) -> (f64, f64) {
        ((p[0] - self.x0) * self.s, self.h as f64 - (p[1] - self.y0) * self.s)
    }
    fn put(&mut self, x: isize, y: isize, c: [u8; 3], alpha: f64) {
        if x < 0 || y < 0 || x >= self.w as isize || y >= self.h as isize {
            return;
        }
        let k = 4 * (y as usize * self.w + x as usize);
        for i in 0..3 {
            self.rgba[k + i] = (self.rgba[k + i] as f64 * (1.0 - alpha) + c[i] as f64 * alpha).round() as u8;
        }
        self.rgba[k + 3] = 255;
    }
    fn triangle(&mut self, p: [(f64, f64); 3], v: [f64; 3], shade: &dyn Fn(f64) -> [u8; 3]) {
        let minx = p.iter().map(|q| q.0).fold(f64::INFINITY, f64::min).floor().max(0.0) as isize;
        let maxx = p.iter().map(|q| q.0).fold(f64::NEG_INFINITY, f64::max).ceil().min(self.w as f64 - 1.0) as isize;
        let miny = p.iter().map(|q| q.1).fold(f64::INFINITY, f64::min).floor().max(0.0) as isize;
        let maxy = p.iter().map(|q| q.1).fold(f64::NEG_INFINITY, f64::max).ceil().min(self.h as f64 - 1.0) as isize;
        let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
        if area.abs() < 1e-12 {
            return;
        }
        for y in miny..=maxy {
            for x in minx..=maxx {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let w0 = ((p[1].0 - px) * (p[2].1 - py) - (p[2].0 - px) * (p[1].1 - py)) / area;
                let w1 = ((p[2].0 - px) * (p[0].1 - py) - (p[0].0 - px) * (p[2].1 - py)) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 >= -1e-9 && w1 >= -1e-9 && w2 >= -1e-9 {
                    let val = w0 * v[0] + w1 * v[1] + w2 * v[2];
                    self.put(x, y, shade(val), 1.0);
                }
            }
        }
    }
    /// Xiaolin Wu style anti-aliased line of the given width (1 or 2 px).
    fn line(&mut self, a: (f64, f64), b: (f64, f64), c: [u8; 3], alpha: f64) {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let n = dx.abs().max(dy.abs()).ceil().max(1.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let (x, y) = (a.0 + t * dx, a.1 + t * dy);
            let (xi, yi) = (x.floor(), y.floor());
            let (fx, fy) = (x - xi, y - yi);
            self.put(xi as isize, yi as isize, c, alpha * (1.0 - fx) * (1.0 - fy));
            self.put(xi as isize + 1, yi as isize, c, alpha * fx * (1.0 - fy));
            self.put(xi as isize, yi as isize + 1, c, alpha * (1.0 - fx) * fy);
            self.put(xi as isize + 1, yi as isize + 1, c, alpha * fx * fy);
        }
    }
}

/// Render `map`; the colour scale is logarithmic from the smallest positive to the
/// largest sampled `det J` (at most four decades).
pub fn render(map: &Surface, opts: &PictureOptions) -> Image {
    let n = render_resolution(opts);
    let (pts, det) = sample(map, n);
    render_sampled(n, &pts, &det, opts)
}

/// Render a THB map: the `det J` heat map of [`render`] (sampled on its exact tensor
/// form, [`HierarchicalMap::to_surface`]) with the borders of the active cells drawn
/// where [`render`] draws iso-lines (`opts.grid_lines` is not used).
pub fn render_thb(map: &HierarchicalMap, opts: &PictureOptions) -> Result<Image> {
    let tensor = map.to_surface()?;
    let n = render_resolution(opts);
    let (pts, det) = sample(&tensor, n);
    let borders = active_cell_borders(map, &tensor);
    let opts = PictureOptions { grid_lines: 0, ..opts.clone() };
    Ok(render_patches_with(n, &[(&pts, &det)], &opts, &borders))
}

/// The images of the edges of every active cell of `map` (through `tensor`, the same
/// map), as polylines of 9 points each; an edge shared by two cells of one level once
/// (the PNG's and the viewer's picture of the active cells).
pub fn active_cell_borders(map: &HierarchicalMap, tensor: &Surface) -> Vec<Vec<Point>> {
    let mut edges = std::collections::BTreeSet::new();
    for (l, c) in map.basis.active_cells() {
        let [[a, b], [cc, d]] = map.basis.cell_bounds(l, c);
        for e in [[a, cc, b, cc], [a, d, b, d], [a, cc, a, d], [b, cc, b, d]] {
            edges.insert(e.map(f64::to_bits));
        }
    }
    edges
        .into_iter()
        .map(|e| {
            let [u0, v0, u1, v1] = e.map(f64::from_bits);
            (0..=8)
                .map(|k| {
                    let t = k as f64 / 8.0;
                    tensor.eval(u0 + t * (u1 - u0), v0 + t * (v1 - v0))
                })
                .collect()
        })
        .collect()
}

/// Points and `det J` of `map` on the `(n+1)^2` grid of [`render`].
fn sample(map: &Surface, n: usize) -> (Vec<Point>, Vec<f64>) {
    let mut pts = Vec::with_capacity((n + 1) * (n + 1));
    let mut det = Vec::with_capacity((n + 1) * (n + 1));
    let (mut bu, mut bv) = (BasisDerivs::default(), BasisDerivs::default());
    for v in grid_abscissae(n) {
        bv.eval(&map.knots[1], v, 1);
        for u in grid_abscissae(n) {
            bu.eval(&map.knots[0], u, 1);
            let d = map.derivs_with(&bu, &bv, 1);
            pts.push(d.x);
            det.push(d.det_j());
        }
    }
    (pts, det)
}

/// Render the patches `maps` of a multipatch layout into one picture: each patch as
/// [`render`] draws a map, one logarithmic `det J` colour scale over all of them, and
/// every patch's boundary (so the interfaces) drawn in black.
pub fn render_layout(maps: &[Surface], opts: &PictureOptions) -> Image {
    let n = render_resolution(opts);
    let samples: Vec<(Vec<Point>, Vec<f64>)> = maps.iter().map(|m| sample(m, n)).collect();
    let refs: Vec<(&[Point], &[f64])> = samples.iter().map(|(p, d)| (p.as_slice(), d.as_slice())).collect();
    render_patches_sampled(n, &refs, opts)
}

/// Draw a layout without maps: the polylines `curves` (patch borders) in black and the
/// points `marks` (irregular vertices) as red crosses, on white, fitted to the image.
pub fn render_curves(curves: &[Vec<Point>], marks: &[Point], size: usize) -> Image {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in curves.iter().flatten() {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let (wd, ht) = ((hi[0] - lo[0]).max(1e-300), (hi[1] - lo[1]).max(1e-300));
    let margin = 0.04;
    let s = size as f64 * (1.0 - 2.0 * margin) / wd.max(ht);
    let (w, h) = (
        (((wd * s) / (1.0 - 2.0 * margin)).ceil() as usize).max(16),
        (((ht * s) / (1.0 - 2.0 * margin)).ceil() as usize).max(16),
    );
    let (pad, padv) = ((w as f64 - wd * s) / 2.0, (h as f64 - ht * s) / 2.0);
    let mut cv = Canvas { w, h, rgba: vec![255; 4 * w * h], x0: lo[0] - pad / s, y0: lo[1] - padv / s, s };
    for c in curves {
        for q in c.windows(2) {
            let (a, b) = (cv.to_px(q[0]), cv.to_px(q[1]));
            cv.line(a, b, [0, 0, 0], 1.0);
        }
    }
    let r = 0.006 * w.max(h) as f64 + 2.0;
    for &x in marks {
        let (cx, cy) = cv.to_px(x);
        for (dx, dy) in [(r, r), (r, -r)] {
            for o in [0.0, 0.7] {
                cv.line((cx - dx + o, cy - dy), (cx + dx + o, cy + dy), KEPT_KINK_COLOUR, 1.0);
            }
        }
    }
    Image { width: w, height: h, rgba: cv.rgba }
}

/// Grid cells per direction that [`render`] samples for `opts`.
pub fn render_resolution(opts: &PictureOptions) -> usize {
    opts.resolution.max(8)
}

/// Draw from samples on the `(n+1)^2` grid of [`render`] (`n` from
/// [`render_resolution`]): points `pts` and `det J` values `det`, row-major with `eta`
/// outer. Lets another back end (the GPU) do the sampling.
pub fn render_sampled(n: usize, pts: &[Point], det: &[f64], opts: &PictureOptions) -> Image {
    render_patches_sampled(n, &[(pts, det)], opts)
}

/// [`render_sampled`] of several patches in one picture (one colour scale).
pub(crate) fn render_patches_sampled(n: usize, patches: &[(&[Point], &[f64])], opts: &PictureOptions) -> Image {
    render_patches_with(n, patches, opts, &[])
}

/// [`render_patches_sampled`], the polylines `lines` drawn as iso-lines are.
fn render_patches_with(n: usize, patches: &[(&[Point], &[f64])], opts: &PictureOptions, lines: &[Vec<Point>]) -> Image {
    for (pts, det) in patches {
        assert_eq!(pts.len(), (n + 1) * (n + 1), "render_sampled: {} points for n = {n}", pts.len());
        assert_eq!(det.len(), pts.len(), "render_sampled: det and points differ in length");
    }
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for p in patches.iter().flat_map(|(pts, _)| pts.iter()) {
        xmin = xmin.min(p[0]);
        xmax = xmax.max(p[0]);
        ymin = ymin.min(p[1]);
        ymax = ymax.max(p[1]);
    }
    let (wd, ht) = ((xmax - xmin).max(1e-300), (ymax - ymin).max(1e-300));
    let margin = 0.04;
    let inner = opts.size as f64 * (1.0 - 2.0 * margin);
    let s = inner / wd.max(ht);
    let (w, h) = (((wd * s) / (1.0 - 2.0 * margin)).ceil() as usize, ((ht * s) / (1.0 - 2.0 * margin)).ceil() as usize);
    let (w, h) = (w.max(16), h.max(16));
    let pad = (w as f64 - wd * s) / 2.0;
    let padv = (h as f64 - ht * s) / 2.0;
    let mut cv = Canvas { w, h, rgba: vec![255; 4 * w * h], x0: xmin - pad / s, y0: ymin - padv / s, s };
    // logarithmic colour scale over the positive values (at most 4 decades)
    let all = || patches.iter().flat_map(|(_, det)| det.iter().copied());
    let dmax = all().fold(0.0f64, f64::max).max(f64::MIN_POSITIVE);
    let dmin = all().filter(|&v| v > 0.0).fold(dmax, f64::min).max(dmax * 1e-4);
    let span = (dmax / dmin).ln().max(1e-12);
    let shade = move |v: f64| if v <= 0.0 { FOLD_COLOUR } else { colormap((v / dmin).ln() / span) };
    let idx = |i: usize, j: usize| j * (n + 1) + i;
    // positive cells first, then cells with a non-positive corner on top
    for pass in 0..2 {
        for (pts, det) in patches {
            for j in 0..n {
                for i in 0..n {
                    let ks = [idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)];
                    let folded = ks.iter().any(|&k| det[k] <= 0.0);
                    if folded != (pass == 1) {
                        continue;
                    }
                    let p: Vec<(f64, f64)> = ks.iter().map(|&k| cv.to_px(pts[k])).collect();
                    let v: Vec<f64> = ks.iter().map(|&k| det[k]).collect();
                    cv.triangle([p[0], p[1], p[2]], [v[0], v[1], v[2]], &shade);
                    cv.triangle([p[0], p[2], p[3]], [v[0], v[2], v[3]], &shade);
                }
            }
        }
    }
    for (pts, _) in patches {
        // iso-lines
        let gl = opts.grid_lines;
        if gl > 0 {
            for l in 1..gl {
                let t = l as f64 / gl as f64;
                let k = ((t * n as f64).round() as usize).min(n);
                for m in 0..n {
                    let (a, b) = (cv.to_px(pts[idx(k, m)]), cv.to_px(pts[idx(k, m + 1)]));
                    cv.line(a, b, [30, 30, 30], 0.7);
                    let (a, b) = (cv.to_px(pts[idx(m, k)]), cv.to_px(pts[idx(m + 1, k)]));
                    cv.line(a, b, [30, 30, 30], 0.7);
                }
            }
        }
        for m in 0..n {
            for (a, b) in [
                (idx(m, 0), idx(m + 1, 0)),
                (idx(m, n), idx(m + 1, n)),
                (idx(0, m), idx(0, m + 1)),
                (idx(n, m), idx(n, m + 1)),
            ] {
                let (pa, pb) = (cv.to_px(pts[a]), cv.to_px(pts[b]));
                cv.line(pa, pb, [0, 0, 0], 1.0);
            }
        }
    }
    for line in lines {
        for q in line.windows(2) {
            let (a, b) = (cv.to_px(q[0]), cv.to_px(q[1]));
            cv.line(a, b, [30, 30, 30], 0.7);
        }
    }
    for &(a, b) in &opts.segments {
        let (pa, pb) = (cv.to_px(a), cv.to_px(b));
        cv.line(pa, pb, [220, 30, 30], 1.0);
    }
    // kinks: crosses of 1.2 % of the image size, drawn twice as thick (one pixel apart)
    let r = 0.006 * w.max(h) as f64 + 2.0;
    for &(x, kept) in &opts.kinks {
        let (cx, cy) = cv.to_px(x);
        let (colour, arms) =
            if kept { (KEPT_KINK_COLOUR, [(r, r), (r, -r)]) } else { (ROUNDED_KINK_COLOUR, [(r, 0.0), (0.0, r)]) };
        for (dx, dy) in arms {
            for o in [0.0, 0.7] {
                cv.line((cx - dx + o, cy - dy), (cx + dx + o, cy + dy), colour, 1.0);
            }
        }
    }
    Image { width: w, height: h, rgba: cv.rgba }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::knots::KnotVector;

    /// The identity of the unit square on a quadratic 4 x 4 basis, one cell refined: its
    /// THB picture is the tensor picture without iso-lines (one colour: `det J = 1`) plus
    /// the borders of the active cells. A border between two level-1 cells (no knot line
    /// of level 0) and a level-0 knot line are drawn; the centre of a level-1 cell is not.
    #[test]
    fn a_thb_picture_draws_the_active_cell_borders() {
        let kv = KnotVector::open_uniform(2, 4);
        let g = kv.greville();
        let cps = g.iter().flat_map(|&v| g.iter().map(move |&u| [u, v])).collect();
        let s = Surface::new([kv.clone(), kv], cps, None).unwrap();
        let map = HierarchicalMap::from_surface(&s).unwrap().refined(&[(0, [1, 1])], 2).unwrap();
        let opts = PictureOptions { size: 400, resolution: 40, ..Default::default() };
        let thb = render_thb(&map, &opts).unwrap();
        let plain = render(&s, &PictureOptions { grid_lines: 0, ..opts.clone() });
        assert_eq!((thb.width, thb.height), (plain.width, plain.height));
        let (w, h) = (thb.width, thb.height);
        // the canvas of an image of the unit square: scale and padding as `render` sets them
        let sc = opts.size as f64 * 0.92;
        let pad = (w as f64 - sc) / 2.0;
        let px = |x: f64, y: f64| ((x * sc + pad) as usize, (h as f64 - (y * sc + pad)) as usize);
        let block_differs = |(x, y): (usize, usize)| {
            (y - 1..=y + 1).any(|yy| {
                (x - 1..=x + 1).any(|xx| {
                    let k = 4 * (yy * w + xx);
                    thb.rgba[k..k + 3] != plain.rgba[k..k + 3]
                })
            })
        };
        assert!(block_differs(px(0.375, 0.3)), "the border between two level-1 cells");
        assert!(block_differs(px(0.75, 0.6)), "a level-0 knot line");
        assert!(!block_differs(px(0.3125, 0.3125)), "the centre of a level-1 cell");
        assert!(!block_differs(px(0.625, 0.875)), "the centre of a level-0 cell");
    }
}
