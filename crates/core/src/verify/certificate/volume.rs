//! Certified bijectivity of a trivariate map (a volume, paper §11.1): `det J` of a
//! tensor-product map of degree `(p, q, r)` is, on every element, a polynomial of degree
//! `(3p - 1, 3q - 1, 3r - 1)` (`det J = x_ξ · (x_η × x_ζ)`, each factor one degree lower
//! in its own direction); for a NURBS map `det J = N / W⁴` with a numerator `N` of degree
//! `(4p - 1, 4q - 1, 4r - 1)`. The machinery is the plane's ([`super`]), in three
//! variables: the coefficients come in Bernstein form from the Bézier extraction
//! (module `element`), carry a rigorous bound of their rounding error (module
//! `bernstein`: `γ_n` bounds, the net taken relative to the element's first control
//! point and scaled by a power of two), the smallest coefficient minus its bound is a
//! proven lower bound, and boxes that are neither proven positive nor shown to fold are
//! bisected (de Casteljau, all three directions; module `search`).
//!
//! **Verdicts.** [`Finding::Certified`] when every element is proven
//! (`min ĉ - e > 0` on every box), with the proven lower bound of `det J`;
//! [`Finding::Folded`] when a point with `det J < -(its rounding bound)` is found,
//! re-evaluated at the reported parameter point (with the parameter and the physical
//! point); [`Finding::Undecided`] when the budget is spent, with the reason per
//! element. Unlike maps of the plane there is no excused corner: every point counts.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use super::element::Elements;
use super::{
    certified_message, folded_message, offending, search, undecided_message, CertifyOptions, Finding, Fold, Undecided,
};
use crate::error::Result;
use crate::spline::basis::BasisDerivs;
use crate::spline::quadrature::GaussLegendre;
use crate::spline::volume::Volume;

/// The outcome of [`certify_volume`] (never [`Finding::DegenerateCorner`]: every point
/// of a volume counts).
pub type VolumeFinding = Finding<3>;

/// A fold of a volume.
pub(crate) type VolumeFold = Fold<3>;

/// An undecided element of a volume.
pub(crate) type VolumeUndecided = Undecided<3>;

/// The bijectivity certificate of a volume.
#[derive(Debug, Clone, Serialize)]
pub struct VolumeCertificate {
    /// The verdict.
    pub verdict: VolumeFinding,
    /// Proven lower bound of `det J` over the proven elements.
    pub lower_bound: f64,
    /// Mean of `det J` over the parameter domain (volume / parameter volume; exact for
    /// polynomial maps, Gauss quadrature for rational ones).
    pub mean_det_j: f64,
    /// Smallest exact value of `det J` met at box corners (polynomial maps).
    pub min_value_found: f64,
    /// Degrees of the `det J` polynomial (of its numerator for rational maps).
    pub det_degree: [usize; 3],
    /// Elements examined.
    pub elements: usize,
    /// Elements per direction.
    pub element_shape: [usize; 3],
    /// Sub-boxes examined in total (elements included).
    pub boxes: usize,
    /// Deepest bisection level used.
    pub max_depth: usize,
    /// Elements where a negative value was proven.
    pub folds: Vec<VolumeFold>,
    /// Elements left undecided, with the reason.
    pub undecided: Vec<VolumeUndecided>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

impl VolumeCertificate {
    /// Elements that are folded or undecided.
    pub fn offending_elements(&self) -> Vec<[usize; 3]> {
        offending(&self.folds, self.undecided.iter().map(|u| u.element))
    }

    /// A sentence describing the verdict.
    pub fn message(&self) -> String {
        match &self.verdict {
            VolumeFinding::Certified { lower_bound, relative } => {
                certified_message(*lower_bound, *relative, self.elements, self.boxes)
            }
            VolumeFinding::Folded { param, point, value, error_bound, one_sided } => {
                folded_message(param, point, *value, *error_bound, one_sided, self.folds.len())
            }
            VolumeFinding::Undecided { elements } => {
                undecided_message(elements.len(), &self.undecided, self.max_depth, self.min_value_found)
            }
            VolumeFinding::DegenerateCorner { lower_bound, relative, .. } => {
                certified_message(*lower_bound, *relative, self.elements, self.boxes)
            }
        }
    }
}

/// `∫ det J` over the parameter domain by Gauss quadrature (`max degree + 2` points per
/// direction and element): the volume of the image of a bijective map.
pub(crate) fn volume_integral(vol: &Volume) -> f64 {
    let n = vol.degrees().into_iter().max().unwrap_or(1) + 2;
    let g = GaussLegendre::new(n);
    let pts: [Vec<(BasisDerivs, f64)>; 3] = std::array::from_fn(|d| {
        let kv = &vol.knots[d];
        kv.elements()
            .into_iter()
            .flat_map(|(s, a, b)| {
                g.on(a, b)
                    .map(|(u, w)| {
                        let mut bd = BasisDerivs::default();
                        bd.eval_in_span(kv, s, u, 1);
                        (bd, w)
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    });
    pts[2]
        .par_iter()
        .map(|(bw, ww)| {
            let mut s = 0.0;
            for (bv, wv) in &pts[1] {
                for (bu, wu) in &pts[0] {
                    s += wu * wv * ww * vol.derivs_with(&[*bu, *bv, *bw]).det_j();
                }
            }
            s
        })
        .sum()
}

/// Certify `det J > 0` on the whole volume, element by element in parallel
/// ([`CertifyOptions::max_depth`] and [`CertifyOptions::max_boxes`] per element;
/// `excuse_corners` does not apply). A knot of multiplicity above the degree inside the
/// domain is a typed error ([`crate::error::Error::KnotMultiplicity`]).
pub fn certify_volume(vol: &Volume, opts: &CertifyOptions) -> Result<VolumeCertificate> {
    let t0 = Instant::now();
    let dj = Elements::volume(vol)?;
    let shape = dj.shape();
    let all = search::all_elements(shape);
    let results: Vec<(search::ElementResult<3>, f64)> =
        all.par_iter().map(|&e| search::examine_volume(&dj, e, opts)).collect();
    let mut totals = search::Totals::new();
    for (r, integral) in results {
        totals.add(r, integral);
    }
    let par_volume: f64 = vol.knots.iter().map(|k| k.domain().1 - k.domain().0).product();
    let integral = if vol.weights.is_some() { volume_integral(vol) } else { totals.integral };
    let mean_det_j = integral / par_volume;
    let relative = totals.lower_bound / mean_det_j;
    let verdict = totals.finding(|u| vol.eval(u), relative);
    Ok(VolumeCertificate {
        verdict,
        lower_bound: totals.lower_bound,
        mean_det_j,
        min_value_found: totals.min_value_found,
        det_degree: dj.deg.0,
        elements: all.len(),
        element_shape: shape,
        boxes: totals.boxes,
        max_depth: totals.max_depth,
        folds: totals.folds,
        undecided: totals.undecided,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests;
