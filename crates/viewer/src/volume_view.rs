//! A trivariate map (a solved volume, a loft) as drawn: three orthogonal slices
//! `u_d = c_d`, one per parameter direction `d` (`ξ`, `η`, `ζ`), each the exact
//! isoparametric surface of the volume (the control net `Σ_l B_l(c_d) c_(.., l, ..)` of
//! [`Volume::section`], homogeneous for NURBS) sampled on a uniform grid of its two
//! free parameters, with `det J = x_ξ · (x_η × x_ζ)` of the volume at every sample (the
//! heat map, coloured like the planar maps'), and the verdict of the trivariate
//! certificate. A slice is drawn face on: projected onto the two physical coordinates
//! along which its samples spread the most.

use winslow::spline::face::Face;
use winslow::spline::volume::{Point3, Volume};
use winslow::verify::certificate::volume::{certify_volume, VolumeCertificate};
use winslow::verify::certificate::CertifyOptions;

use crate::colour::{ColourScale, ScaleKind};
use crate::view::{bounds_of, Bounds};

/// Cells per direction of a slice's sample grid.
pub const SLICE_CELLS: usize = 48;

/// Names of the parameter directions.
pub const DIRECTIONS: [&str; 3] = ["ξ", "η", "ζ"];

/// The surface `u_dir = at` of a volume, sampled.
#[derive(Debug, Clone)]
pub struct VolumeSlice {
    /// The fixed parameter direction.
    pub dir: usize,
    /// Its value, in `[0, 1]` (the knot domain, as readers normalise it).
    pub at: f64,
    /// The slice as a spline surface in the two other directions (in their order).
    pub surface: Face,
    /// Cells per direction of the sample grid.
    pub n: usize,
    /// The surface at `(i / n, j / n)`, `i` fastest.
    pub points: Vec<Point3>,
    /// `det J` of the volume at the same parameters.
    pub det_j: Vec<f64>,
    /// The physical coordinates the slice is drawn in.
    pub axes: [usize; 2],
}

/// The two free directions of a slice of direction `dir`, in order.
pub fn free_directions(dir: usize) -> [usize; 2] {
    match dir {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    }
}

fn lerp(d: (f64, f64), t: f64) -> f64 {
    d.0 + (d.1 - d.0) * t
}

impl VolumeSlice {
    /// The slice `u_dir = at` (`at` clamped to `[0, 1]`) on an `n x n` grid.
    pub fn new(volume: &Volume, dir: usize, at: f64, n: usize) -> Self {
        let at = if at.is_finite() { at.clamp(0.0, 1.0) } else { 0.5 };
        let n = n.max(1);
        let t = lerp(volume.knots[dir].domain(), at);
        let (control_points, weights) = volume.section(dir, t);
        let free = free_directions(dir);
        let surface = Face { knots: free.map(|d| volume.knots[d].clone()), control_points, weights };
        let domains = free.map(|d| volume.knots[d].domain());
        let mut points = Vec::with_capacity((n + 1) * (n + 1));
        let mut det_j = Vec::with_capacity((n + 1) * (n + 1));
        for j in 0..=n {
            for i in 0..=n {
                let (s, r) = (lerp(domains[0], i as f64 / n as f64), lerp(domains[1], j as f64 / n as f64));
                points.push(surface.eval(s, r));
                let mut u = [t; 3];
                u[free[0]] = s;
                u[free[1]] = r;
                det_j.push(volume.derivs(u).det_j());
            }
        }
        let spread = |c: usize| {
            let (lo, hi) =
                points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p[c]), h.max(p[c])));
            hi - lo
        };
        let thinnest = (0..3).min_by(|&a, &b| spread(a).total_cmp(&spread(b))).unwrap_or(dir);
        let axes = match thinnest {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        };
        Self { dir, at, surface, n, points, det_j, axes }
    }

    /// The samples projected onto [`Self::axes`].
    pub fn projected(&self) -> Vec<[f64; 2]> {
        self.points.iter().map(|p| [p[self.axes[0]], p[self.axes[1]]]).collect()
    }

    /// Bounds of the projected samples.
    pub fn bounds(&self) -> Option<Bounds> {
        bounds_of(self.projected().iter())
    }
}

/// A volume with its three slices and its certificate.
#[derive(Debug, Clone)]
pub struct VolumeView {
    /// Name of the geometry.
    pub name: String,
    /// The volume, knot domains `[0, 1]`.
    pub volume: Volume,
    /// The trivariate certificate (or why it could not be computed).
    pub certificate: Result<VolumeCertificate, String>,
    /// The slices `ξ = c_0`, `η = c_1`, `ζ = c_2`.
    pub slices: [VolumeSlice; 3],
}

impl VolumeView {
    /// The volume with its three middle slices, certified.
    pub fn new(name: String, volume: Volume) -> Self {
        let certificate = certify_volume(&volume, &CertifyOptions::default()).map_err(|e| e.to_string());
        let slices = [0, 1, 2].map(|d| VolumeSlice::new(&volume, d, 0.5, SLICE_CELLS));
        Self { name, volume, certificate, slices }
    }

    /// Move the slice of direction `dir` to `at` (clamped to `[0, 1]`); false when it
    /// is already there.
    pub fn set_slice(&mut self, dir: usize, at: f64) -> bool {
        if dir > 2 || self.slices[dir].at == at {
            return false;
        }
        self.slices[dir] = VolumeSlice::new(&self.volume, dir, at, self.slices[dir].n);
        true
    }

    /// One colour scale over the three slices' `det J`.
    pub fn colour_scale(&self, kind: ScaleKind) -> ColourScale {
        let all: Vec<f64> = self.slices.iter().flat_map(|s| s.det_j.iter().copied()).collect();
        ColourScale::for_values(&all, kind)
    }

    /// The certificate's one-line verdict.
    pub fn verdict(&self) -> String {
        match &self.certificate {
            Ok(c) => c.message(),
            Err(e) => format!("not certified: {e}"),
        }
    }
}
