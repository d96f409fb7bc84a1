use super::*;
use crate::boundary::volume::tests::trilinear_faces;
use crate::spline::face::Face;
use crate::spline::knots::KnotVector;

/// A rational curved volume on the knot vectors `k` (Greville net, sheared, with an
/// interior wobble and weights in [1, 1.2)): the test map of the EGG and Winslow
/// derivatives against finite differences.
pub(super) fn curved_rational_volume(k: [KnotVector; 3]) -> (crate::spline::volume::Volume, Vec<Point3>) {
    let shape = k.each_ref().map(KnotVector::num_basis);
    let n: usize = shape.iter().product();
    let g: [Vec<f64>; 3] = std::array::from_fn(|d| k[d].greville());
    let cps: Vec<Point3> = (0..n)
        .map(|lin| {
            let (i, j, l) = (lin % shape[0], (lin / shape[0]) % shape[1], lin / (shape[0] * shape[1]));
            let (a, b, c) = (g[0][i], g[1][j], g[2][l]);
            let wob = 0.03 * ((lin * 7919) % 13) as f64 / 13.0;
            [a + 0.2 * b * c + wob, b + 0.1 * a * a - wob, c + 0.15 * a * b + 0.5 * wob]
        })
        .collect();
    let w: Vec<f64> = (0..n).map(|lin| 1.0 + 0.2 * ((lin * 31) % 5) as f64 / 5.0).collect();
    (crate::spline::volume::Volume::new(k, cps.clone(), Some(w)).unwrap(), cps)
}

fn affine(u: [f64; 3]) -> Point3 {
    [2.0 + u[0] + 0.3 * u[1] - 0.2 * u[2], -1.0 + 0.1 * u[0] + 1.5 * u[1], 0.4 * u[0] + 0.2 * u[1] + 0.8 * u[2]]
}

/// An affine volume is its own Winslow minimiser: given by its faces (elevated to
/// quadratic and refined), the solve returns it exactly, certified.
#[test]
fn an_affine_volume_is_reproduced_exactly() {
    let faces = trilinear_faces(affine).map(|f| f.elevated_in(0).unwrap().elevated_in(1).unwrap());
    let b = VolumeBoundary { name: "affine".into(), faces };
    let s =
        solve_volume(&b, &VolumeOptions { method: VolumeMethod::Winslow, refine: 1, ..Default::default() }).unwrap();
    assert_eq!(s.report.verdict, "certified");
    assert_eq!(s.report.start, "coons");
    assert_eq!(s.volume.degrees(), [2, 2, 2]);
    for &u in &[[0.1, 0.2, 0.3], [0.5, 0.5, 0.5], [0.77, 0.13, 0.91]] {
        let (x, y) = (s.volume.eval(u), affine(u));
        for c in 0..3 {
            assert!((x[c] - y[c]).abs() < 1e-12, "{u:?}: {x:?} vs {y:?}");
        }
    }
    assert!(s.report.boundary_kept);
}

/// A cube with its top face bulged up as a quadratic: the solve is certified, keeps
/// the boundary, and reaches a stationary point (gradient down by 1e-8 or more).
#[test]
fn a_bulged_cube_is_certified() {
    let mut faces = trilinear_faces(|u| u).map(|f| f.elevated_in(0).unwrap().elevated_in(1).unwrap());
    // top (zeta = 1): the middle control point raised
    let top = &mut faces[5];
    top.control_points[4][2] += 0.8;
    // the four side faces keep their top edges straight: only the top's middle point moves
    let b = VolumeBoundary { name: "bulge".into(), faces };
    b.validate().unwrap();
    let s =
        solve_volume(&b, &VolumeOptions { method: VolumeMethod::Winslow, refine: 1, ..Default::default() }).unwrap();
    assert_eq!(s.report.verdict, "certified", "{:?}", s.report);
    assert!(s.report.relative_gradient.unwrap() < 1e-8, "{:?}", s.report);
    assert!(s.report.boundary_kept);
    // the enclosed volume equals the certificate's mean det J (unit parameter cube)
    assert!(
        (s.certificate.mean_det_j - b.enclosed_volume()).abs() < 1e-10,
        "{} {}",
        s.certificate.mean_det_j,
        b.enclosed_volume()
    );
}

/// The certificate's verdicts on a planted fold: an interior control point of a
/// solved volume pushed through its neighbours folds the map, and the certificate
/// says so at a point where det J < 0.
#[test]
fn a_planted_fold_is_found() {
    let faces = trilinear_faces(affine).map(|f| f.elevated_in(0).unwrap().elevated_in(1).unwrap());
    let b = VolumeBoundary { name: "affine".into(), faces };
    let s =
        solve_volume(&b, &VolumeOptions { method: VolumeMethod::Winslow, refine: 1, ..Default::default() }).unwrap();
    let mut v = s.volume.clone();
    let shape = v.shape();
    let mid = v.index([shape[0] / 2, shape[1] / 2, shape[2] / 2]);
    let next = v.index([shape[0] / 2 + 1, shape[1] / 2, shape[2] / 2]);
    // past its neighbour in xi: x_xi < 0 there
    let (p, q) = (v.control_points[mid], v.control_points[next]);
    v.control_points[mid] = std::array::from_fn(|c| q[c] + 2.0 * (q[c] - p[c]));
    let cert = certify_volume(&v, &CertifyOptions::default()).unwrap();
    match cert.verdict {
        VolumeFinding::Folded { param, value, error_bound, .. } => {
            assert!(value < -error_bound);
            assert!(v.derivs(param).det_j() < 0.0);
        }
        other => panic!("expected a fold, got {other:?}"),
    }
    let e = WinslowVolume::new(&v, 4);
    assert!(e.evaluate(&v.control_points, false).energy.is_infinite());
}

/// A face that is not a bilinear patch on another basis than its neighbours: a
/// quarter cylinder's curved side (exact NURBS) bounds a certified volume, and the
/// volume's faces are the input faces.
#[test]
fn a_nurbs_quarter_cylinder_shell_is_certified() {
    let b = quarter_shell();
    b.validate().unwrap();
    let s = solve_volume(&b, &VolumeOptions { method: VolumeMethod::Winslow, ..Default::default() }).unwrap();
    assert_eq!(s.report.verdict, "certified", "{:?}", s.report);
    assert!(s.report.boundary_deviation < 1e-12, "{:?}", s.report);
    // the shell between radii 1 and 2, a quarter turn, height 1: volume 3π/4 (the
    // certificate integrates a rational det J by Gauss quadrature: to 1e-5 here)
    assert!((s.certificate.mean_det_j - 0.75 * std::f64::consts::PI).abs() < 1e-4, "{}", s.certificate.mean_det_j);
    assert!((b.enclosed_volume() - 0.75 * std::f64::consts::PI).abs() < 1e-4, "{}", b.enclosed_volume());
}

/// The shell `r ∈ [1, 2]`, `θ ∈ [0, π/2]`, `z ∈ [0, 1]` as six faces: `xi` radial,
/// `eta` the angle (exact quadratic NURBS arcs), `zeta` the height.
fn quarter_shell() -> VolumeBoundary {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let arc = [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let aw = [1.0, h, 1.0];
    let point = |r: f64, j: usize, z: f64| [r * arc[j][0], r * arc[j][1], z];
    let lin = KnotVector::open_uniform(1, 1);
    let quad = KnotVector::new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]).unwrap();
    // (s, t) ranges: function of the cube point u -> control point for side faces
    let face = |side: CubeSide| -> Face {
        let [ps, pt] = side.params();
        let (d, v) = side.fixed();
        let n = |dir: usize| if dir == 1 { 3 } else { 2 };
        let (ns, nt) = (n(ps), n(pt));
        let mut cps = Vec::new();
        let mut w = Vec::new();
        for jt in 0..nt {
            for is in 0..ns {
                let mut ijk = [0usize; 3];
                ijk[d] = if v == 0.0 { 0 } else { n(d) - 1 };
                ijk[ps] = is;
                ijk[pt] = jt;
                cps.push(point(1.0 + ijk[0] as f64, ijk[1], ijk[2] as f64));
                w.push(aw[ijk[1]]);
            }
        }
        let kv = |dir: usize| if dir == 1 { quad.clone() } else { lin.clone() };
        let weights = w.iter().any(|&x| x != 1.0).then_some(w);
        Face::new([kv(ps), kv(pt)], cps, weights).unwrap()
    };
    VolumeBoundary { name: "quarter-shell".into(), faces: CubeSide::ALL.map(face) }
}

/// The control points of the tensor interpolant of `f` at the Greville points of
/// `knots` (`xi` fastest).
fn interpolate(knots: &[KnotVector; 3], f: impl Fn([f64; 3]) -> Point3) -> Vec<Point3> {
    use crate::linalg::linsolve::dense_solve;
    use crate::spline::basis::dense_values;
    let g: [Vec<f64>; 3] = std::array::from_fn(|d| knots[d].greville());
    let n: [usize; 3] = std::array::from_fn(|d| g[d].len());
    let inv: [Vec<Vec<f64>>; 3] = std::array::from_fn(|d| {
        let b: Vec<Vec<f64>> = g[d].iter().map(|&u| dense_values(&knots[d], u)).collect();
        let id: Vec<Vec<f64>> = (0..n[d]).map(|i| (0..n[d]).map(|j| f64::from(u8::from(i == j))).collect()).collect();
        dense_solve(&b, &id)
    });
    let mut v: Vec<Point3> = (0..n[0] * n[1] * n[2])
        .map(|lin| {
            let (i, j, k) = (lin % n[0], (lin / n[0]) % n[1], lin / (n[0] * n[1]));
            f([g[0][i], g[1][j], g[2][k]])
        })
        .collect();
    let stride = [1, n[0], n[0] * n[1]];
    for d in 0..3 {
        let mut out = vec![[0.0; 3]; v.len()];
        for (lin, o) in out.iter_mut().enumerate() {
            let i = (lin / stride[d]) % n[d];
            let base = lin - i * stride[d];
            for (j, c) in inv[d][i].iter().enumerate() {
                let p = v[base + j * stride[d]];
                for z in 0..3 {
                    o[z] += c * p[z];
                }
            }
        }
        v = out;
    }
    v
}

/// EGG (eq. 8 in 3D) from a wobbled interior start on the faces of an affine volume:
/// Newton returns the affine map itself (its second derivatives vanish, so it solves
/// the equation exactly and the discrete solution is unique near it).
#[test]
fn egg_reproduces_an_affine_volume_from_a_wobbled_start() {
    let kv = KnotVector::open_uniform(2, 3);
    let knots = [kv.clone(), kv.clone(), KnotVector::open_uniform(3, 2)];
    let exact = interpolate(&knots, affine);
    let vol = Volume::new(knots, exact.clone(), None).unwrap();
    let op = egg::EggVolume::new(&vol, 4);
    let mut cps: Vec<Point3> = exact
        .iter()
        .enumerate()
        .map(|(lin, p)| {
            let w = if op.discretization().free_index(lin).is_some() {
                0.05 * ((lin * 7919 % 11) as f64 / 11.0 - 0.5)
            } else {
                0.0
            };
            [p[0] + w, p[1] - w, p[2] + 0.5 * w]
        })
        .collect();
    let s = egg::solve_egg(&op, &mut cps, 20, 1e-13, LinearMethod::Auto).unwrap();
    assert!(s.iterations >= 1, "{s:?}");
    for (x, y) in cps.iter().zip(&exact) {
        for c in 0..3 {
            assert!((x[c] - y[c]).abs() < 1e-12, "{x:?} vs {y:?}");
        }
    }
    // and from the faces through `solve_volume`: the Coons start is the affine map already
    let faces = trilinear_faces(affine).map(|f| f.elevated_in(0).unwrap().elevated_in(1).unwrap());
    let b = VolumeBoundary { name: "affine".into(), faces };
    let s = solve_volume(&b, &VolumeOptions { method: VolumeMethod::Egg, refine: 1, ..Default::default() }).unwrap();
    assert_eq!((s.report.method, s.report.verdict), ("egg", "certified"));
    for &u in &[[0.1, 0.2, 0.3], [0.77, 0.13, 0.91]] {
        let (x, y) = (s.volume.eval(u), affine(u));
        assert!((0..3).all(|c| (x[c] - y[c]).abs() < 1e-12), "{u:?}: {x:?} vs {y:?}");
    }
}

/// Convergence of EGG (eq. 8 in 3D) to the closed-form harmonic volume of a
/// cylindrical shell sector `r0 <= r <= r1`, `0 <= θ <= θ1`, `0 <= z <= h`: its inverse
/// `ξ = ln(r/r0)/ln(r1/r0)`, `η = θ/θ1`, `ζ = z/h` is harmonic, so the exact map is
/// `x = (r0 (r1/r0)^ξ cos θ1η, r0 (r1/r0)^ξ sin θ1η, hζ)`. The boundary control points
/// are those of the map's interpolant at the Greville points (an `O(h^(p+1))` boundary),
/// the interior solved by Newton from the interpolant; the largest error at sample
/// points falls at order `p + 1` under halving of the elements.
#[test]
fn egg_converges_at_order_p_plus_1_to_a_harmonic_shell_sector() {
    let (r0, r1, t1, h) = (1.0f64, 2.0f64, std::f64::consts::FRAC_PI_2, 1.0);
    let exact = |u: [f64; 3]| -> Point3 {
        let r = r0 * (r1 / r0).powf(u[0]);
        [r * (t1 * u[1]).cos(), r * (t1 * u[1]).sin(), h * u[2]]
    };
    for p in [2usize, 3] {
        let mut errors = Vec::new();
        for n in [2usize, 4, 8] {
            let knots =
                [KnotVector::open_uniform(p, n), KnotVector::open_uniform(p, n), KnotVector::open_uniform(p, 1)];
            let mut cps = interpolate(&knots, exact);
            let vol = Volume::new(knots.clone(), cps.clone(), None).unwrap();
            let op = egg::EggVolume::new(&vol, p + 2);
            let s = egg::solve_egg(&op, &mut cps, 30, 1e-12, LinearMethod::Auto).unwrap();
            // |F| <= 1e-12 max(|F(start)|, 1), and the start's residual is below 1
            let f = op.evaluate(&cps, false).residual;
            assert!(f.iter().map(|v| v * v).sum::<f64>().sqrt() <= 1e-12 && s.iterations >= 1, "{s:?}");
            let sol = Volume::new(knots, cps, None).unwrap();
            let mut worst = 0.0f64;
            for i in 0..=10 {
                for j in 0..=10 {
                    for k in 0..=4 {
                        let u = [i as f64 / 10.0, j as f64 / 10.0, k as f64 / 4.0];
                        let (x, y) = (sol.eval(u), exact(u));
                        worst = worst.max((0..3).map(|c| (x[c] - y[c]).powi(2)).sum::<f64>().sqrt());
                    }
                }
            }
            errors.push(worst);
        }
        let rates: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        eprintln!("p = {p}: errors {errors:?}, rates {rates:?}");
        let last = *rates.last().unwrap();
        assert!(last > p as f64 + 0.7, "p = {p}: errors {errors:?}, rates {rates:?}");
    }
}

/// Defect correction bisects the spans of the offending elements and one span around
/// them, per direction, and nothing else.
#[test]
fn the_offending_spans_and_their_halo_are_bisected() {
    let knots = [KnotVector::open_uniform(2, 8), KnotVector::open_uniform(2, 4), KnotVector::open_uniform(2, 1)];
    // elements (2, 0, 0) and (3, 3, 0): spans 1..=4 in xi, 0, 1, 2, 3 in eta, 0 in zeta
    let mids = offending_midpoints(&knots, &[[2, 0, 0], [3, 3, 0]], 1);
    assert_eq!(mids[0], vec![0.1875, 0.3125, 0.4375, 0.5625]);
    assert_eq!(mids[1], vec![0.125, 0.375, 0.625, 0.875]);
    assert_eq!(mids[2], vec![0.5]);
    // no halo: the elements' own spans
    let mids = offending_midpoints(&knots, &[[7, 1, 0]], 0);
    assert_eq!(mids, [vec![0.9375], vec![0.375], vec![0.5]]);
    // the refined common faces hold exactly those knots more, the faces refined exactly
    let corner = |u: [f64; 3]| [u[0] + 0.2 * u[1] * u[2], 2.0 * u[1] - 0.1 * u[0], u[2] + 0.3 * u[0] * u[1]];
    let b = VolumeBoundary { name: "t".into(), faces: trilinear_faces(corner) };
    let plain = coons::common_faces(&b, 0, &Default::default()).unwrap();
    let extra = [vec![0.25], vec![0.5, 0.75], vec![]];
    let refined = coons::common_faces(&b, 0, &extra).unwrap();
    for d in 0..3 {
        assert_eq!(refined.knots[d], plain.knots[d].with_inserted(&extra[d]));
    }
    let (v0, v1) = (plain.coons().unwrap(), refined.coons().unwrap());
    for u in [[0.1, 0.2, 0.3], [0.6, 0.8, 0.9]] {
        let (x, y) = (v0.eval(u), v1.eval(u));
        assert!((0..3).all(|c| (x[c] - y[c]).abs() < 1e-13), "{u:?}");
    }
}
