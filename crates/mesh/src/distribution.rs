//! Point distributions on `[0, 1]` for one parameter direction of a structured mesh.
//!
//! A distribution maps the uniform parameter `t_k = k / n` to `s(t_k)`, monotone with
//! `s(0) = 0` and `s(1) = 1`; the structured mesh samples the map at `xi_i x eta_j`
//! (paper §11.3). The geometric layers of [`Distribution::Layers`] are set from a
//! first-cell height in *physical* units and need the map, see
//! [`crate::structured::StructuredOptions`]; this module builds them once the heights
//! are known in parameter units.

use crate::equidistribution::Equidistribution;
use crate::error::{MeshError, Result};

/// One end of a parameter direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// `t = 0` (south for `eta`, west for `xi`).
    Start,
    /// `t = 1` (north for `eta`, east for `xi`).
    End,
}

/// How the points of one direction are spaced.
#[derive(Debug, Clone, PartialEq)]
pub enum Distribution {
    /// `s(t) = t`.
    Uniform,
    /// Paper eq. (50): `s(t) = (arctan(a (t - 1/2)) / arctan(a / 2) + 1) / 2`, clustered at
    /// both ends; the paper's Fig. 31 uses `a = 6`.
    Arctan {
        /// Strength `a > 0`.
        strength: f64,
    },
    /// Two-sided tanh stretching, `s(t) = (1 + tanh(d (t - 1/2)) / tanh(d / 2)) / 2`.
    TanhTwoSided {
        /// Strength `d > 0`.
        strength: f64,
    },
    /// One-sided tanh stretching clustered at `end`: `s(t) = 1 + tanh(d (t - 1)) / tanh(d)`
    /// at the start, `s(t) = tanh(d t) / tanh(d)` at the end.
    TanhOneSided {
        /// Strength `d > 0`.
        strength: f64,
        /// Where the points cluster.
        at: End,
    },
    /// Geometric boundary layers: the first cell at each given end has the given height
    /// in **physical units**, the cells grow by `growth` away from the wall while
    /// smaller than the uniform spacing left for the core, which is filled uniformly.
    Layers {
        /// First-cell height at the start, physical units.
        start: Option<f64>,
        /// First-cell height at the end, physical units.
        end: Option<f64>,
        /// Growth-ratio limit `> 1` between neighbouring cells.
        growth: f64,
    },
    /// Points equidistributing arc length or curvature along the two sides of the
    /// direction ([`crate::equidistribution`]); a curvature tolerance may add points.
    Equidistributed(Equidistribution),
}

impl Distribution {
    /// Check the parameters.
    pub fn validate(&self, what: &str) -> Result<()> {
        let pos = |v: f64, name: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(MeshError::param(format!("{what} {name}"), format!("must be positive and finite, got {v}")))
            }
        };
        match self {
            Distribution::Uniform => Ok(()),
            Distribution::Arctan { strength }
            | Distribution::TanhTwoSided { strength }
            | Distribution::TanhOneSided { strength, .. } => pos(*strength, "strength"),
            Distribution::Layers { start, end, growth } => {
                if start.is_none() && end.is_none() {
                    return Err(MeshError::param(what, "layers need a first-cell height at one end at least"));
                }
                for h in start.iter().chain(end.iter()) {
                    pos(*h, "first-cell height")?;
                }
                if !(growth.is_finite() && *growth > 1.0) {
                    return Err(MeshError::param(format!("{what} growth"), format!("must be > 1, got {growth}")));
                }
                Ok(())
            }
            Distribution::Equidistributed(Equidistribution::ArcLength) => Ok(()),
            Distribution::Equidistributed(Equidistribution::Curvature { tol }) => pos(*tol, "chord tolerance"),
        }
    }

    /// `s(t)` of the closed-form distributions (`None` for those that need the map,
    /// [`Distribution::Layers`] and [`Distribution::Equidistributed`]).
    pub fn eval(&self, t: f64) -> Option<f64> {
        Some(match *self {
            Distribution::Uniform => t,
            Distribution::Arctan { strength: a } => 0.5 * ((a * (t - 0.5)).atan() / (0.5 * a).atan() + 1.0),
            Distribution::TanhTwoSided { strength: d } => 0.5 * (1.0 + (d * (t - 0.5)).tanh() / (0.5 * d).tanh()),
            Distribution::TanhOneSided { strength: d, at: End::Start } => 1.0 + (d * (t - 1.0)).tanh() / d.tanh(),
            Distribution::TanhOneSided { strength: d, at: End::End } => (d * t).tanh() / d.tanh(),
            Distribution::Layers { .. } | Distribution::Equidistributed(_) => return None,
        })
    }

    /// `n + 1` points of a closed-form distribution, ends exactly 0 and 1.
    pub fn points(&self, cells: usize) -> Option<Vec<f64>> {
        let mut s: Vec<f64> = (0..=cells).map(|k| self.eval(k as f64 / cells as f64)).collect::<Option<_>>()?;
        s[0] = 0.0;
        s[cells] = 1.0;
        Some(s)
    }
}

/// Cell sizes of geometric layers in parameter units: `h0 g^k` from the start and
/// `h1 g^k` from the end while each new layer cell is no larger than the uniform spacing
/// left for the remaining cells (which never decreases), the rest uniform. Every
/// neighbour ratio is then at most `g`; refused when the core cells would exceed `g`
/// times the last layer cell (too few cells) or a first cell exceeds the uniform spacing
/// (too large a height). `label` names the direction in errors.
pub fn layer_sizes(cells: usize, h0: Option<f64>, h1: Option<f64>, g: f64, label: [&str; 2]) -> Result<Vec<f64>> {
    let mut front: Vec<f64> = Vec::new();
    let mut back: Vec<f64> = Vec::new();
    let mut sum = 0.0;
    let next = |h: Option<f64>, v: &Vec<f64>| h.map(|h| v.last().map_or(h, |&l| l * g));
    loop {
        let rem = cells - front.len() - back.len();
        if rem <= 1 {
            break;
        }
        let (a, b) = (next(h0, &front), next(h1, &back));
        let pick_front = match (a, b) {
            (Some(a), Some(b)) => a <= b,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (None, None) => break,
        };
        let c = if pick_front { a.unwrap_or(0.0) } else { b.unwrap_or(0.0) };
        // add while c <= the uniform spacing left after adding it (equivalently <= before)
        if c * rem as f64 > 1.0 - sum {
            break;
        }
        sum += c;
        if pick_front {
            front.push(c);
        } else {
            back.push(c);
        }
    }
    let rem = cells - front.len() - back.len();
    let core = (1.0 - sum) / rem as f64;
    for (h, v, side) in [(h0, &front, label[0]), (h1, &back, label[1])] {
        let Some(h) = h else { continue };
        let Some(&last) = v.last() else {
            return Err(MeshError::Layer {
                side: side.into(),
                height: h,
                growth: g,
                why: format!(
                    "the first cell is larger than the uniform spacing {:.3e} of {cells} cells (in parameter units): use fewer cells or a smaller height",
                    1.0 / cells as f64
                ),
            });
        };
        if core > g * last * (1.0 + 1e-12) {
            // cells needed: the layer grows until its cell reaches the core spacing
            return Err(MeshError::Layer {
                side: side.into(),
                height: h,
                growth: g,
                why: format!(
                    "{cells} cells are too few: the uniform core cells ({core:.3e}) would be more than {g} times the last layer cell ({last:.3e}); use more cells or a larger growth ratio"
                ),
            });
        }
    }
    let mut sizes = front;
    sizes.extend(std::iter::repeat_n(core, rem));
    sizes.extend(back.iter().rev());
    Ok(sizes)
}

/// Points from cell sizes, ends exactly 0 and 1: the first half summed from 0, the
/// second half from 1 backwards, so the cells at both ends keep their sizes to round-off.
pub fn points_from_sizes(sizes: &[f64]) -> Vec<f64> {
    let n = sizes.len();
    let mut s = vec![0.0; n + 1];
    let half = n / 2;
    for k in 0..half {
        s[k + 1] = s[k] + sizes[k];
    }
    s[n] = 1.0;
    for k in (half + 1..n).rev() {
        s[k] = s[k + 1] - sizes[k];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms_are_monotone_and_hit_the_ends() {
        for d in [
            Distribution::Uniform,
            Distribution::Arctan { strength: 6.0 },
            Distribution::TanhTwoSided { strength: 3.0 },
            Distribution::TanhOneSided { strength: 2.5, at: End::Start },
            Distribution::TanhOneSided { strength: 2.5, at: End::End },
        ] {
            assert!(d.eval(0.0).unwrap().abs() < 1e-15, "{d:?}");
            assert!((d.eval(1.0).unwrap() - 1.0).abs() < 1e-15, "{d:?}");
            let p = d.points(50).unwrap();
            assert!(p.windows(2).all(|w| w[1] > w[0]), "{d:?}");
        }
        // eq. (50) with a = 6: the paper's arctan(3) normaliser, symmetric about 1/2
        let d = Distribution::Arctan { strength: 6.0 };
        let t = 0.2;
        let expect = 0.5 * ((6.0f64 * (t - 0.5)).atan() / 3f64.atan() + 1.0);
        assert_eq!(d.eval(t).unwrap(), expect);
        assert!((d.eval(t).unwrap() + d.eval(1.0 - t).unwrap() - 1.0).abs() < 1e-15);
        // one-sided tanh clusters where asked
        let s = Distribution::TanhOneSided { strength: 3.0, at: End::Start }.points(10).unwrap();
        assert!(s[1] - s[0] < s[10] - s[9]);
    }

    #[test]
    fn layers_meet_height_and_growth() {
        let sizes = layer_sizes(40, Some(1e-3), Some(2e-3), 1.3, ["start", "end"]).unwrap();
        assert_eq!(sizes.len(), 40);
        assert!((sizes.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert_eq!(sizes[0], 1e-3);
        assert_eq!(sizes[39], 2e-3);
        assert!((sizes[1] / sizes[0] - 1.3).abs() < 1e-12);
        for w in sizes.windows(2) {
            let r = (w[1] / w[0]).max(w[0] / w[1]);
            assert!(r <= 1.3 * (1.0 + 1e-12), "{r}");
        }
    }

    #[test]
    fn layers_refuse_what_cannot_be_met() {
        assert!(matches!(layer_sizes(4, Some(1e-4), None, 1.1, ["s", "n"]), Err(MeshError::Layer { .. })));
        assert!(matches!(layer_sizes(10, Some(0.5), None, 1.1, ["s", "n"]), Err(MeshError::Layer { .. })));
        assert!(Distribution::Layers { start: None, end: None, growth: 1.2 }.validate("eta").is_err());
        assert!(Distribution::Layers { start: Some(1e-3), end: None, growth: 1.0 }.validate("eta").is_err());
    }
}
