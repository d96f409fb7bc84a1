use super::*;
use crate::error::Error;
use crate::spline::knots::KnotVector;
use crate::testutil::Lcg;
use crate::verify::certificate::bernstein::{eval, Deg};
use crate::verify::certificate::element::Elements;
use crate::verify::certificate::judge::{Exact3, Sign3};

/// The identity of the unit cube on open uniform bases (control points at the Greville
/// abscissae), every control point moved at random by `amp` times the element size.
fn perturbed(rng: &mut Lcg, deg: [usize; 3], ne: [usize; 3], amp: f64, rational: bool) -> Volume {
    let knots = [0, 1, 2].map(|d| KnotVector::open_uniform(deg[d], ne[d]));
    let g = knots.each_ref().map(KnotVector::greville);
    let mut cps = Vec::new();
    for &z in &g[2] {
        for &y in &g[1] {
            for &x in &g[0] {
                let base = [x, y, z];
                cps.push(std::array::from_fn(|c| base[c] + amp * (rng.uniform() - 0.5) / ne[c] as f64));
            }
        }
    }
    let w = rational.then(|| (0..cps.len()).map(|_| 0.6 + 0.8 * rng.uniform()).collect());
    Volume::new(knots, cps, w).unwrap()
}

/// `det J` at `u` evaluated on element `e` (one-sided on its boundary).
fn det_in_element(vol: &Volume, e: [usize; 3], u: [f64; 3]) -> f64 {
    let b = std::array::from_fn(|d| {
        let mut bd = crate::spline::basis::BasisDerivs::default();
        bd.eval_in_span(&vol.knots[d], vol.knots[d].elements()[e[d]].0, u[d], 1);
        bd
    });
    vol.derivs_with(&b).det_j()
}

/// Smallest `det J` on an `(n + 1)³` grid.
fn dense_min(vol: &Volume, n: usize) -> f64 {
    let mut m = f64::INFINITY;
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let u = [i as f64 / n as f64, j as f64 / n as f64, k as f64 / n as f64];
                m = m.min(vol.derivs(u).det_j());
            }
        }
    }
    m
}

#[test]
fn bernstein_det_j_equals_det_j() {
    let mut rng = Lcg::new(17);
    for deg in [[1, 1, 1], [2, 2, 1], [2, 3, 2], [3, 3, 3]] {
        for rational in [false, true] {
            let vol = perturbed(&mut rng, deg, [2, 2, 2], 0.8, rational);
            let dj = Elements::volume(&vol).unwrap();
            let mut tmp = vec![0.0; dj.deg.len()];
            for e in [[0, 0, 0], [1, 0, 1], [1, 1, 1]] {
                let (c, sc, wnet) = dj.volume_coefficients(e);
                let b = dj.bounds(e);
                for _ in 0..10 {
                    let s = [rng.uniform(), rng.uniform(), rng.uniform()];
                    let u = std::array::from_fn(|d| b[d][0] + s[d] * (b[d][1] - b[d][0]));
                    let exact = vol.derivs(u).det_j();
                    let pairs = s.map(|x| [1.0 - x, x]);
                    let mut val = sc.factor * eval(&c, dj.deg, pairs, &mut tmp);
                    if let Some(wn) = &wnet {
                        val /= eval(wn, Deg(deg), pairs, &mut tmp).powi(4);
                    }
                    assert!((val - exact).abs() < 1e-11 * (1.0 + exact.abs()), "{deg:?} {rational}: {val} vs {exact}");
                }
            }
        }
    }
}

/// Random maps from mild to wild: the verdict never contradicts dense sampling, the
/// bound is below every sample, folds are reported where `det J < 0`.
#[test]
fn certificate_agrees_with_dense_sampling() {
    let mut rng = Lcg::new(3);
    let (mut certified, mut folded) = (0, 0);
    for (deg, ne) in [([2, 2, 2], [2, 3, 2]), ([3, 2, 1], [3, 2, 2]), ([1, 1, 1], [3, 3, 3])] {
        for rational in [false, true] {
            for amp in [0.05, 0.3, 0.8, 1.5, 3.0] {
                let vol = perturbed(&mut rng, deg, ne, amp, rational);
                let c = certify_volume(&vol, &CertifyOptions::default()).unwrap();
                let m = dense_min(&vol, 16);
                match &c.verdict {
                    VolumeFinding::Certified { lower_bound, .. } => {
                        certified += 1;
                        assert!(
                            m > 0.0 && *lower_bound > 0.0 && *lower_bound <= m * (1.0 + 1e-12),
                            "{lower_bound} {m}"
                        );
                        let vi = volume_integral(&vol);
                        assert!((c.mean_det_j - vi).abs() < 1e-9 * vi.abs(), "{} vs {vi}", c.mean_det_j);
                    }
                    VolumeFinding::Folded { param, point, value, .. } => {
                        folded += 1;
                        let worst = c.folds.iter().min_by(|a, b| a.value.total_cmp(&b.value)).unwrap();
                        let d = det_in_element(&vol, worst.element, *param);
                        assert!(*value < 0.0 && d < 1e-9 * value.abs(), "reported {value}, evaluated {d}");
                        let x = vol.eval(*param);
                        assert!((0..3).all(|k| (x[k] - point[k]).abs() < 1e-12));
                        assert!(c
                            .folds
                            .iter()
                            .all(|f| det_in_element(&vol, f.element, f.param) < 1e-9 * f.value.abs()));
                    }
                    VolumeFinding::Undecided { .. } => assert!(m <= 0.0 || c.undecided.iter().all(|u| u.depth > 0)),
                    VolumeFinding::DegenerateCorner { .. } => panic!("a volume has no excused corner"),
                }
                if m < 0.0 {
                    assert!(!matches!(c.verdict, VolumeFinding::Certified { .. }), "sampled {m} < 0 yet certified");
                }
            }
        }
    }
    assert!(certified >= 6 && folded >= 6, "{certified} certified, {folded} folded");
}

/// The exact rational judge and the certificate never disagree.
#[test]
fn certificate_agrees_with_the_exact_judge() {
    let mut rng = Lcg::new(41);
    let (mut pos, mut neg) = (0, 0);
    for (deg, ne, rational) in
        [([1, 1, 1], [2, 2, 1], false), ([2, 1, 1], [2, 1, 2], false), ([1, 1, 1], [1, 2, 1], true)]
    {
        for amp in [0.2, 0.9, 1.4, 2.0] {
            let vol = perturbed(&mut rng, deg, ne, amp, rational);
            let c = certify_volume(&vol, &CertifyOptions::default()).unwrap();
            let (exact, _) = Exact3::volume(&vol).sign(1, 5, 200);
            match (&exact, &c.verdict) {
                (Sign3::Positive, VolumeFinding::Folded { .. }) => panic!("judge positive, certificate folded"),
                (Sign3::Negative { .. }, VolumeFinding::Certified { .. }) => panic!("judge negative, certified"),
                _ => {}
            }
            pos += matches!(exact, Sign3::Positive) as usize;
            neg += matches!(exact, Sign3::Negative { .. }) as usize;
        }
    }
    assert!(pos >= 3 && neg >= 3, "{pos} positive, {neg} negative");
}

/// A control point pushed across its neighbour makes a fold inside its support.
#[test]
fn planted_folds_are_found_and_located() {
    let mut rng = Lcg::new(9);
    for deg in [[2, 2, 2], [1, 2, 3]] {
        for rational in [false, true] {
            for _ in 0..4 {
                let mut vol = perturbed(&mut rng, deg, [4, 4, 4], 0.0, rational);
                let [nx, ny, nz] = vol.shape();
                let ijk = [1 + rng.below(nx - 2), 1 + rng.below(ny - 2), 1 + rng.below(nz - 2)];
                let k = vol.index(ijk);
                let (next, prev) = (vol.control_points[k + 1], vol.control_points[k - 1]);
                vol.control_points[k][0] = next[0] + (3.0 + rng.uniform()) * (next[0] - prev[0]);
                let c = certify_volume(&vol, &CertifyOptions::default()).unwrap();
                let VolumeFinding::Folded { param, .. } = c.verdict else {
                    panic!("planted fold missed: {:?}", c.verdict)
                };
                for d in 0..3 {
                    let t = vol.knots[d].knots();
                    assert!(param[d] >= t[ijk[d]] && param[d] <= t[ijk[d] + deg[d] + 1], "{param:?}");
                }
                assert!(!c.offending_elements().is_empty());
            }
        }
    }
}

/// The rounding bound scales with the element, not with the position: a certified map
/// translated far away stays certified with the same bound.
#[test]
fn translation_keeps_the_verdict() {
    let mut rng = Lcg::new(5);
    let vol = perturbed(&mut rng, [2, 2, 2], [2, 2, 2], 0.2, false);
    let a = certify_volume(&vol, &CertifyOptions::default()).unwrap();
    let mut far = vol.clone();
    for p in far.control_points.iter_mut() {
        p[0] += 1e9;
        p[2] -= 3e8;
    }
    let b = certify_volume(&far, &CertifyOptions::default()).unwrap();
    let (VolumeFinding::Certified { lower_bound: la, .. }, VolumeFinding::Certified { lower_bound: lb, .. }) =
        (&a.verdict, &b.verdict)
    else {
        panic!("{:?} {:?}", a.verdict, b.verdict)
    };
    assert!((la - lb).abs() < 1e-5 * la, "{la} vs {lb}");
}

#[test]
fn multiplicity_above_degree_is_a_typed_error() {
    let kv = KnotVector::open_uniform(1, 1);
    let kz = KnotVector::new(1, vec![0., 0., 0.5, 0.5, 1., 1.]).unwrap();
    let n = 2 * 2 * kz.num_basis();
    let cps = (0..n).map(|i| [(i % 2) as f64, ((i / 2) % 2) as f64, (i / 4) as f64]).collect();
    let vol = Volume::new([kv.clone(), kv, kz], cps, None).unwrap();
    match certify_volume(&vol, &CertifyOptions::default()) {
        Err(Error::KnotMultiplicity { direction, multiplicity, .. }) => {
            assert_eq!((direction.as_str(), multiplicity), ("zeta", 2))
        }
        other => panic!("{:?}", other.map(|c| c.verdict)),
    }
}

/// An affine map has constant `det J = det A`: the proven bound is `det A` to rounding,
/// and the mean is exact.
#[test]
fn affine_maps_are_certified_with_a_tight_bound() {
    let mut rng = Lcg::new(12);
    let a = [[2.0, 0.3, -0.1], [0.2, 1.5, 0.4], [-0.3, 0.1, 0.7]];
    let det = crate::spline::volume::triple(
        [a[0][0], a[1][0], a[2][0]],
        [a[0][1], a[1][1], a[2][1]],
        [a[0][2], a[1][2], a[2][2]],
    );
    let mut vol = perturbed(&mut rng, [2, 3, 1], [3, 2, 4], 0.0, false);
    for p in vol.control_points.iter_mut() {
        let x = *p;
        *p = std::array::from_fn(|r| 5.0 + a[r][0] * x[0] + a[r][1] * x[1] + a[r][2] * x[2]);
    }
    let c = certify_volume(&vol, &CertifyOptions::default()).unwrap();
    let VolumeFinding::Certified { lower_bound, relative } = c.verdict else { panic!("{:?}", c.verdict) };
    assert!(det > 0.0 && lower_bound <= det && lower_bound > det * (1.0 - 1e-11), "{lower_bound} vs {det}");
    assert!((c.mean_det_j - det).abs() < 1e-12 * det && (relative - lower_bound / det).abs() < 1e-12);
    assert_eq!(c.boxes, c.elements);
}
