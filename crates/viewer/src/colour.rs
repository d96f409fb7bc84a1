//! The colour scale of the heat map: positive `det J` through the core's viridis-like
//! map ([`winslow::io::picture::colormap`]), logarithmic or linear between the smallest and
//! the largest positive sample; non-positive (and non-finite) values in the core's
//! [`winslow::io::picture::FOLD_COLOUR`] (magenta), which no positive value uses.

use egui::Color32;
use winslow::io::picture::{colormap, FOLD_COLOUR};

/// Largest ratio the logarithmic scale spans (four decades, as the core's pictures).
pub const MAX_DECADES: f64 = 4.0;

/// How positive values map onto `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ScaleKind {
    /// `t = ln(v / lo) / ln(hi / lo)`.
    #[default]
    Log,
    /// `t = (v - lo) / (hi - lo)`.
    Linear,
}

impl ScaleKind {
    /// Name shown in the viewer.
    pub fn label(self) -> &'static str {
        match self {
            ScaleKind::Log => "log",
            ScaleKind::Linear => "linear",
        }
    }
}

/// A colour scale over `[lo, hi]`, `0 < lo <= hi`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColourScale {
    /// Scale kind.
    pub kind: ScaleKind,
    /// Value at the bottom of the scale (smallest positive value; for the log scale at
    /// least `hi / 10^MAX_DECADES`).
    pub lo: f64,
    /// Value at the top of the scale (largest value).
    pub hi: f64,
}

/// Whether `v > 0` (false for NaN): the test that decides the fold colour.
pub fn is_positive(v: f64) -> bool {
    v > 0.0
}

/// The fold colour as an egui colour.
pub fn fold_colour() -> Color32 {
    Color32::from_rgb(FOLD_COLOUR[0], FOLD_COLOUR[1], FOLD_COLOUR[2])
}

impl ColourScale {
    /// The scale of a set of samples: from the smallest positive to the largest value.
    /// With no positive value the scale is `[1, 1]` (everything is painted as folded).
    pub fn for_values(values: &[f64], kind: ScaleKind) -> Self {
        let hi = values.iter().copied().filter(|v| v.is_finite() && *v > 0.0).fold(0.0f64, f64::max);
        if hi <= 0.0 {
            return Self { kind, lo: 1.0, hi: 1.0 };
        }
        let mut lo = values.iter().copied().filter(|v| v.is_finite() && *v > 0.0).fold(hi, f64::min);
        if kind == ScaleKind::Log {
            lo = lo.max(hi * 10f64.powf(-MAX_DECADES));
        }
        Self { kind, lo, hi }
    }

    /// Position of a positive value on the scale, clamped to `[0, 1]`; `None` for a
    /// non-positive or non-finite value.
    pub fn position(&self, v: f64) -> Option<f64> {
        if !(v.is_finite() && is_positive(v)) {
            return None;
        }
        if self.hi <= self.lo {
            return Some(1.0);
        }
        let t = match self.kind {
            ScaleKind::Log => (v / self.lo).ln() / (self.hi / self.lo).ln(),
            ScaleKind::Linear => (v - self.lo) / (self.hi - self.lo),
        };
        Some(t.clamp(0.0, 1.0))
    }

    /// The value at position `t in [0, 1]` (inverse of [`Self::position`]).
    pub fn value_at(&self, t: f64) -> f64 {
        let t = t.clamp(0.0, 1.0);
        match self.kind {
            ScaleKind::Log => self.lo * (self.hi / self.lo).powf(t),
            ScaleKind::Linear => self.lo + t * (self.hi - self.lo),
        }
    }

    /// Colour of a value.
    pub fn colour(&self, v: f64) -> Color32 {
        match self.position(v) {
            Some(t) => colour_at(t),
            None => fold_colour(),
        }
    }

    /// `count >= 2` evenly spaced positions on the bar with their values, bottom first.
    pub fn ticks(&self, count: usize) -> Vec<(f64, f64)> {
        let count = count.max(2);
        (0..count)
            .map(|k| {
                let t = k as f64 / (count - 1) as f64;
                (t, self.value_at(t))
            })
            .collect()
    }
}

/// The colour map at `t in [0, 1]`.
pub fn colour_at(t: f64) -> Color32 {
    let [r, g, b] = colormap(t);
    Color32::from_rgb(r, g, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fold_colour_only_for_nonpositive() {
        let s = ColourScale::for_values(&[-1.0, 0.0, 1e-3, 2.0, 5.0], ScaleKind::Log);
        assert_eq!(s.colour(0.0), fold_colour());
        assert_eq!(s.colour(-3.0), fold_colour());
        assert_eq!(s.colour(f64::NAN), fold_colour());
        // no positive value, however small or large, gets the fold colour
        for kind in [ScaleKind::Log, ScaleKind::Linear] {
            let s = ColourScale { kind, ..s };
            for k in -400..=400 {
                let v = 10f64.powf(k as f64 / 20.0);
                assert_ne!(s.colour(v), fold_colour(), "{v}");
            }
        }
        // nor anything on the colour map
        for k in 0..=1000 {
            assert_ne!(colour_at(k as f64 / 1000.0), fold_colour());
        }
    }

    #[test]
    fn log_scale_spans_at_most_four_decades() {
        let s = ColourScale::for_values(&[1e-9, 1e-2, 3.0, 10.0], ScaleKind::Log);
        assert_eq!(s.hi, 10.0);
        assert!((s.lo - 1e-3).abs() < 1e-15);
        let s = ColourScale::for_values(&[0.5, 3.0, 10.0], ScaleKind::Log);
        assert_eq!((s.lo, s.hi), (0.5, 10.0));
        // geometric mean sits in the middle
        assert!((s.position((0.5f64 * 10.0).sqrt()).unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(s.position(1e-6), Some(0.0));
        assert_eq!(s.position(1e6), Some(1.0));
    }

    #[test]
    fn linear_scale_and_inverse() {
        let s = ColourScale::for_values(&[-2.0, 1.0, 3.0, 5.0], ScaleKind::Linear);
        assert_eq!((s.lo, s.hi), (1.0, 5.0));
        assert_eq!(s.position(3.0), Some(0.5));
        for kind in [ScaleKind::Log, ScaleKind::Linear] {
            let s = ColourScale { kind, ..s };
            for (t, v) in s.ticks(7) {
                assert!((s.position(v).unwrap() - t).abs() < 1e-12);
            }
        }
        assert_eq!(s.ticks(5).first().unwrap().1, 1.0);
        assert_eq!(s.ticks(5).last().unwrap().1, 5.0);
    }

    #[test]
    fn monotone_colours_at_ends() {
        let s = ColourScale::for_values(&[1.0, 100.0], ScaleKind::Log);
        assert_eq!(s.colour(1.0), colour_at(0.0));
        assert_eq!(s.colour(100.0), colour_at(1.0));
        let all_folded = ColourScale::for_values(&[-1.0, 0.0], ScaleKind::Log);
        assert_eq!(all_folded.colour(-1.0), fold_colour());
    }
}
