//! The folded elements of a map: the knot-span elements `[xi_a, xi_b] x [eta_a, eta_b]`
//! that contain a sample of `det J <= 0` (paper eq. 43; a bijective map has `det J > 0`
//! away from corners its boundary forces). Read off the sampler's grid, never
//! recomputed here.

use winslow::verify::quality::DetJSample;
use winslow::Surface;

/// One element with at least one non-positive `det J` sample.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldedElement {
    /// Element index `(i, j)`: `i`-th span in `xi`, `j`-th in `eta`.
    pub element: [usize; 2],
    /// `[xi_a, xi_b]`.
    pub xi: [f64; 2],
    /// `[eta_a, eta_b]`.
    pub eta: [f64; 2],
    /// Smallest sample in the element.
    pub min_det_j: f64,
    /// Parameter point of that sample.
    pub argmin: [f64; 2],
    /// Number of non-positive samples in the element.
    pub samples: usize,
    /// Whether the element touches a corner whose angle forces `det J <= 0` there and all
    /// of its non-positive samples lie in the corner's neighbourhood (not a fold of the
    /// map: the boundary allows nothing better).
    pub forced_corner: bool,
}

/// Indices of the spans of the (strictly increasing) `breaks` whose closed interval
/// contains `t`: one, or two on an interior break.
fn spans_containing(breaks: &[f64], t: f64) -> impl Iterator<Item = usize> + '_ {
    let n = breaks.len().saturating_sub(1);
    let k = breaks.partition_point(|&b| b <= t).saturating_sub(1).min(n.saturating_sub(1));
    let on_break = k > 0 && breaks[k] == t;
    let first = if on_break { k - 1 } else { k };
    (first..=k).filter(move |&s| s < n)
}

/// The elements of `map` with non-positive samples in `sample`, worst first.
/// `forced` lists the corners (south-west, south-east, north-east, north-west) where the
/// boundary forces `det J <= 0` ([`winslow::boundary::corners::CornerReport`]); a non-positive
/// sample counts as forced when it lies in the element at such a corner.
pub fn folded_elements(map: &Surface, sample: &DetJSample, forced: [bool; 4]) -> Vec<FoldedElement> {
    let bu = map.knots[0].breaks();
    let bv = map.knots[1].breaks();
    let (du, dv) = (map.knots[0].domain(), map.knots[1].domain());
    let (nu, nv) = (bu.len() - 1, bv.len() - 1);
    let corner_of = |e: [usize; 2]| -> Option<usize> {
        match (e[0] == 0, e[0] + 1 == nu, e[1] == 0, e[1] + 1 == nv) {
            (true, _, true, _) => Some(0),
            (_, true, true, _) => Some(1),
            (_, true, _, true) => Some(2),
            (true, _, _, true) => Some(3),
            _ => None,
        }
    };
    let n = sample.n;
    // per element: (min, argmin, count, all samples forced)
    let mut found: std::collections::BTreeMap<[usize; 2], (f64, [f64; 2], usize, bool)> = Default::default();
    for j in 0..=n {
        let v = dv.0 + (dv.1 - dv.0) * j as f64 / n as f64;
        for i in 0..=n {
            let d = sample.values[j * (n + 1) + i];
            if d > 0.0 {
                continue;
            }
            let u = du.0 + (du.1 - du.0) * i as f64 / n as f64;
            for ej in spans_containing(&bv, v) {
                for ei in spans_containing(&bu, u) {
                    let e = [ei, ej];
                    let is_forced = corner_of(e).is_some_and(|c| forced[c]);
                    let entry = found.entry(e).or_insert((f64::INFINITY, [u, v], 0, true));
                    // NaN samples count as folded (not `> 0`) and sort first
                    if d < entry.0 || d.is_nan() {
                        entry.0 = d;
                        entry.1 = [u, v];
                    }
                    entry.2 += 1;
                    entry.3 &= is_forced;
                }
            }
        }
    }
    let mut out: Vec<FoldedElement> = found
        .into_iter()
        .map(|(e, (min, argmin, samples, forced_corner))| FoldedElement {
            element: e,
            xi: [bu[e[0]], bu[e[0] + 1]],
            eta: [bv[e[1]], bv[e[1] + 1]],
            min_det_j: min,
            argmin,
            samples,
            forced_corner,
        })
        .collect();
    // folds before forced corners, then worst first
    out.sort_by(|a, b| a.forced_corner.cmp(&b.forced_corner).then(a.min_det_j.total_cmp(&b.min_det_j)));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use winslow::verify::quality::sample_det_j;
    use winslow::KnotVector;

    /// Degree-2 map of the square `[0, 3]^2` on 3x3 elements, control points at the
    /// Greville points (the identity up to scaling: `det J = 9`).
    fn square() -> Surface {
        let kv = KnotVector::open_uniform(2, 3);
        let g = kv.greville();
        let mut cps = Vec::new();
        for &v in &g {
            for &u in &g {
                cps.push([3.0 * u, 3.0 * v]);
            }
        }
        Surface::new([kv.clone(), kv], cps, None).unwrap()
    }

    #[test]
    fn spans_of_points() {
        let b = [0.0, 0.25, 0.5, 1.0];
        assert_eq!(spans_containing(&b, 0.0).collect::<Vec<_>>(), vec![0]);
        assert_eq!(spans_containing(&b, 0.1).collect::<Vec<_>>(), vec![0]);
        assert_eq!(spans_containing(&b, 0.25).collect::<Vec<_>>(), vec![0, 1]);
        assert_eq!(spans_containing(&b, 0.7).collect::<Vec<_>>(), vec![2]);
        assert_eq!(spans_containing(&b, 1.0).collect::<Vec<_>>(), vec![2]);
    }

    #[test]
    fn positive_map_has_no_folded_elements() {
        let s = square();
        let sample = sample_det_j(&s, 30);
        assert!((sample.min - 9.0).abs() < 1e-9 && (sample.max - 9.0).abs() < 1e-9);
        assert!(folded_elements(&s, &sample, [false; 4]).is_empty());
    }

    #[test]
    fn a_pushed_control_point_folds_its_elements() {
        let mut s = square();
        // drag control point (1, 1) far past its neighbours: det J < 0 near (xi, eta) = (1/6, 1/6)
        let nx = s.shape()[0];
        s.control_points[nx + 1] = [4.0, 4.0];
        let sample = sample_det_j(&s, 60);
        assert!(sample.min < 0.0);
        let folded = folded_elements(&s, &sample, [false; 4]);
        assert!(!folded.is_empty());
        // the worst element contains the global minimum
        let w = &folded[0];
        assert_eq!(w.min_det_j, sample.min);
        let [u, v] = sample.argmin;
        assert!(w.xi[0] <= u && u <= w.xi[1] && w.eta[0] <= v && v <= w.eta[1], "{w:?} {:?}", sample.argmin);
        // control point (1, 1) supports the elements [0, 2) x [0, 2) only
        assert!(folded.iter().all(|e| e.element[0] < 2 && e.element[1] < 2), "{folded:?}");
        // every listed element does contain a non-positive sample, counted
        assert!(folded.iter().all(|e| e.min_det_j <= 0.0 && e.samples > 0));
        // sorted worst first
        assert!(folded.windows(2).all(|p| p[0].min_det_j <= p[1].min_det_j));
    }

    #[test]
    fn forced_corner_elements_are_marked() {
        let mut s = square();
        // collapse the south-west corner angle: x_eta parallel to x_xi at (0, 0)
        let nx = s.shape()[0];
        s.control_points[nx] = [1.0, 0.0];
        let sample = sample_det_j(&s, 30);
        assert!(sample.values[0] <= 1e-12);
        let marked = folded_elements(&s, &sample, [true, false, false, false]);
        assert!(!marked.is_empty() && marked.iter().all(|e| e.element == [0, 0] && e.forced_corner), "{marked:?}");
        let unmarked = folded_elements(&s, &sample, [false; 4]);
        assert!(unmarked.iter().all(|e| !e.forced_corner));
    }
}
