//! Volumes from their six boundary faces (a hexahedral topology, paper §11.1 in 3D):
//! the faces on common knot vectors, the trivariate Coons patch as the start
//! (`coons`), the interior control points moved by Newton's method on EGG in Galerkin
//! form (eq. 8 in 3D, `egg`; the default) and/or on the 3D Winslow functional
//! (`winslow`), both on one trivariate discretization (`assembly`), and the verdict of
//! the volume certificate ([`certify_volume`]). [`VolumeMethod`] chooses.
//!
//! **Continuation** (Winslow only; EGG needs no barrier). Winslow's functional needs a start with `det J > 0` at every
//! quadrature point. When the Coons patch of the faces is not one (a strongly bulged or
//! concave face), the boundary is moved there from the trilinear volume of the eight
//! corners (itself a Coons patch, positive for any convex hexahedron of corners): the
//! boundary net `B(t) = (1 - t) B₀ + t B₁`, `t` from 0 to 1, the interior moved with it by
//! the Coons patch of the boundary's displacement and then relaxed by Newton at every
//! accepted `t`; a step whose moved start leaves the barrier is halved. The first step
//! tried is `t = 1`, i.e. the Coons patch of the faces itself.
//!
//! **Defect correction** (§8.2 in 3D). A volume whose certificate is not `certified` is
//! solved again with the knot spans of its offending (folded or undecided) elements and
//! one span around them bisected, in each direction ([`VolumeOptions::max_refinements`]
//! rounds at most; every element halved instead when the certificate names no element);
//! the faces are refined exactly, so the boundary is the same. The result is the last
//! volume with its certificate, whatever its verdict.

pub(crate) mod assembly;
pub(crate) mod coons;
pub(crate) mod egg;
pub(crate) mod tensor_points;
pub(crate) mod winslow;

use std::time::Instant;

use serde::Serialize;

use crate::boundary::volume::{CubeSide, VolumeBoundary};
use crate::error::{Error, Result};
use crate::linalg::linsolve::{LinearMethod, LinearSolver};
use crate::linalg::sparse::Csr;
use crate::spline::knots::KnotVector;
use crate::spline::volume::{Point3, Volume};
use crate::verify::certificate::volume::{certify_volume, VolumeCertificate, VolumeFinding};
use crate::verify::certificate::CertifyOptions;
use assembly::VolumeDiscretization;
use coons::{common_faces, coons_fill, volume_of, CommonFaces};
use egg::{solve_egg, EggSolved, EggVolume};
use std::sync::Arc;
use winslow::WinslowVolume;

/// What moves the interior control points of a volume.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum VolumeMethod {
    /// EGG in Galerkin form (eq. 8 in 3D, module `egg`) by Newton from the Coons patch
    /// (the default, as for planar maps).
    #[default]
    Egg,
    /// EGG, then the 3D Winslow functional minimised from the EGG map (from the
    /// continuation when the EGG map leaves the barrier).
    EggWinslow,
    /// The 3D Winslow functional minimised from the Coons patch, or from the
    /// continuation when the Coons patch leaves the barrier (module doc).
    Winslow,
}

impl VolumeMethod {
    /// `egg`, `egg+winslow` or `winslow`.
    pub fn name(self) -> &'static str {
        match self {
            VolumeMethod::Egg => "egg",
            VolumeMethod::EggWinslow => "egg+winslow",
            VolumeMethod::Winslow => "winslow",
        }
    }
}

/// Options of `solve_volume`.
#[derive(Debug, Clone)]
pub struct VolumeOptions {
    /// The method. EGG needs a `C¹` basis (degree 2 or more, no interior knot of
    /// multiplicity `p`); on any other the Winslow functional is minimised instead (the
    /// report's `method` says which ran).
    pub method: VolumeMethod,
    /// Times every element of the common bases is halved before the solve.
    pub refine: usize,
    /// Rounds of defect correction (the offending elements' spans bisected) tried when
    /// the certificate is not `certified`.
    pub max_refinements: usize,
    /// Newton iterations of the final minimisation.
    pub max_iterations: usize,
    /// Newton stops when `|∇E| <= tolerance |∇E(start)|` or `E` stops decreasing.
    pub tolerance: f64,
    /// Continuation steps at most (accepted and halved ones together).
    pub max_continuation: usize,
    /// Options of the volume certificate.
    pub certify: CertifyOptions,
    /// The linear solver of EGG's Newton steps (module `egg::newton`): sparse LU
    /// ([`LinearMethod::Lu`]), or GMRES preconditioned by the cofactor metric's stiffness
    /// (the others; [`LinearMethod::Auto`], the default, factorizes up to 64 unknowns
    /// and falls back to LU when GMRES fails).
    pub linear: LinearMethod,
}

impl Default for VolumeOptions {
    fn default() -> Self {
        Self {
            method: VolumeMethod::default(),
            refine: 0,
            max_refinements: 2,
            max_iterations: 60,
            tolerance: 1e-10,
            max_continuation: 64,
            certify: CertifyOptions::default(),
            linear: LinearMethod::Auto,
        }
    }
}

/// What a volume solve did.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct VolumeSolveReport {
    /// The method that ran ([`VolumeMethod::name`]).
    pub method: &'static str,
    /// Degrees of the volume.
    pub degrees: [usize; 3],
    /// Basis functions per direction.
    pub shape: [usize; 3],
    /// Free scalar unknowns (3 per interior control point).
    pub unknowns: usize,
    /// Halvings of the common bases (`--refine`, and a round of defect correction whose
    /// certificate named no element).
    pub refine: usize,
    /// The rounds of defect correction, in order (empty when the first volume was
    /// certified).
    pub repair: Vec<VolumeRepairRound>,
    /// `coons` when the Coons patch of the faces was the start, `continuation` when the
    /// boundary was moved there from the corners' trilinear volume, `egg` when the
    /// Winslow functional was minimised from the EGG map.
    pub start: &'static str,
    /// Continuation steps accepted (1 when the Coons patch was the start).
    pub continuation_steps: usize,
    /// Newton iterations in all (EGG's and continuation included).
    pub newton_iterations: usize,
    /// Newton iterations of EGG (`null` when it did not run).
    pub egg_iterations: Option<usize>,
    /// `|F|` of the EGG map relative to that of the Coons patch (`null` when EGG did
    /// not run).
    pub egg_relative_residual: Option<f64>,
    /// The linear solver of EGG's last Newton step, `lu` or `gmres` (`null` when EGG
    /// did not run).
    pub egg_linear: Option<&'static str>,
    /// GMRES iterations of all EGG Newton steps (`null` when EGG did not run).
    pub egg_krylov_iterations: Option<usize>,
    /// `E` of the Coons patch (`null` when it leaves the barrier).
    pub energy_start: Option<f64>,
    /// `E` of the result (`null` when it leaves the barrier: possible for EGG).
    pub energy: f64,
    /// `|∇E|` of the result, relative to that of its start (`null` when the Winslow
    /// functional was not minimised).
    pub relative_gradient: Option<f64>,
    /// Largest distance between a face of the result and the input face, at sample
    /// points.
    pub boundary_deviation: f64,
    /// Whether that distance is within `10⁻⁹` of the diameter.
    pub boundary_kept: bool,
    /// The certificate's verdict (`certified`, `folded`, `undecided`).
    pub verdict: &'static str,
    /// Seconds of the certificate.
    pub certificate_seconds: f64,
    /// Wall-clock seconds in all.
    pub seconds: f64,
}

/// One round of defect correction of a volume.
#[derive(Debug, Clone, Serialize)]
pub struct VolumeRepairRound {
    /// The verdict of the volume repaired.
    pub verdict: &'static str,
    /// Its folded or undecided elements.
    pub offending_elements: usize,
    /// Knot spans bisected per direction (offending ones and one around them); all of
    /// them when no element was named.
    pub spans_refined: [usize; 3],
    /// Basis functions per direction after the round.
    pub shape: [usize; 3],
}

/// A volume solved from its faces, with its certificate.
#[derive(Debug, Clone)]
pub struct VolumeSolve {
    /// The volume.
    pub volume: Volume,
    /// Its certificate.
    pub certificate: VolumeCertificate,
    /// The report.
    pub report: VolumeSolveReport,
}

/// Statistics of one minimisation.
#[derive(Debug, Clone, Copy)]
struct Minimised {
    iterations: usize,
    relative_gradient: f64,
    /// `E` of the result.
    energy: f64,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// `a + s diag(|a|)` (`a` itself, not a copy, when `s = 0`).
fn shifted(a: &Csr, s: f64) -> std::borrow::Cow<'_, Csr> {
    if s <= 0.0 {
        return std::borrow::Cow::Borrowed(a);
    }
    let mut b = a.clone();
    for i in 0..b.nrows {
        if let Some(p) = b.position(i, i) {
            b.values[p] += s * b.values[p].abs().max(1e-300);
        }
    }
    std::borrow::Cow::Owned(b)
}

/// Newton's method with a backtracking (Armijo) line search on `E` over the free
/// control points of `cps`, from a start inside the barrier; the Hessian is shifted on
/// its diagonal where its Cholesky factorization fails or its step is not a descent.
fn minimise(e: &WinslowVolume, cps: &mut [Point3], max_iterations: usize, tolerance: f64) -> Result<Minimised> {
    let mut ev = e.evaluate(cps, true);
    if !ev.energy.is_finite() {
        return Err(Error::InfeasibleStart {
            method: "the 3D Winslow functional".into(),
            reason: "det J <= 0 at a quadrature point of the start".into(),
        });
    }
    let g0 = norm(&ev.gradient).max(f64::MIN_POSITIVE);
    let mut x = e.gather(cps);
    let mut solver = LinearSolver::new(LinearMethod::Cholesky);
    let mut shift = 0.0;
    let mut iterations = 0;
    while iterations < max_iterations && e.unknowns() > 0 {
        let gn = norm(&ev.gradient);
        if gn <= tolerance * g0 {
            break;
        }
        let h = ev.hessian.as_ref().expect("evaluated with the Hessian");
        let mut step = None;
        for _ in 0..12 {
            let hs = shifted(h, shift);
            if solver.factor(&hs).is_ok() {
                let rhs: Vec<f64> = ev.gradient.iter().map(|g| -g).collect();
                let d = solver.solve(&rhs)?;
                let slope: f64 = d.iter().zip(&ev.gradient).map(|(a, b)| a * b).sum();
                if slope < 0.0 && d.iter().all(|v| v.is_finite()) {
                    step = Some((d, slope));
                    break;
                }
            }
            shift = if shift == 0.0 { 1e-6 } else { shift * 10.0 };
        }
        let Some((d, slope)) = step else {
            return Err(Error::NoConvergence("3D Winslow: no descent direction from the shifted Hessian".into()));
        };
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..40 {
            let trial: Vec<f64> = x.iter().zip(&d).map(|(a, b)| a + alpha * b).collect();
            let mut c = cps.to_vec();
            e.scatter(&mut c, &trial);
            let t = e.evaluate(&c, false);
            if t.energy.is_finite() && t.energy <= ev.energy + 1e-4 * alpha * slope {
                accepted = Some((trial, c, t.energy));
                break;
            }
            alpha *= 0.5;
        }
        iterations += 1;
        let Some((trial, c, energy)) = accepted else { break };
        let decrease = ev.energy - energy;
        x = trial;
        cps.copy_from_slice(&c);
        if let Some(h) = ev.hessian.take() {
            e.recycle(h);
        }
        ev = e.evaluate(cps, true);
        shift = if shift < 1e-5 { 0.0 } else { shift * 0.1 };
        if decrease <= 1e-15 * energy.abs() {
            break;
        }
    }
    Ok(Minimised { iterations, relative_gradient: norm(&ev.gradient) / g0, energy: ev.energy })
}

/// The similarity to unit size: `(centre, scale)` of the bounding box of `pts`.
fn unit_frame(pts: &[Point3]) -> (Point3, f64) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in pts {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let centre = std::array::from_fn(|c| 0.5 * (lo[c] + hi[c]));
    let scale = (0..3).map(|c| hi[c] - lo[c]).fold(0.0, f64::max);
    (centre, scale)
}

/// The Cartesian boundary net of `cf` and its weights.
fn boundary_points(cf: &CommonFaces) -> Result<(Vec<Point3>, Vec<f64>)> {
    let h = cf.boundary_net()?;
    let w: Vec<f64> = h.iter().map(|p| if p[3] == 0.0 { 1.0 } else { p[3] }).collect();
    let pts = h.iter().zip(&w).map(|(p, w)| [p[0] / w, p[1] / w, p[2] / w]).collect();
    Ok((pts, w))
}

/// What [`solve_on`] did.
struct OnBasis {
    volume: Volume,
    method: VolumeMethod,
    start: &'static str,
    continuation_steps: usize,
    iterations: usize,
    egg: Option<EggSolved>,
    relative_gradient: Option<f64>,
    energy: f64,
    energy_start: Option<f64>,
}

/// Whether EGG's second derivatives are defined on `knots`: degree 2 or more and no
/// interior knot of multiplicity `p` or more in every direction.
fn is_c1(knots: &[KnotVector; 3]) -> bool {
    knots.iter().all(|kv| {
        let b = kv.breaks_with_multiplicity();
        kv.degree() >= 2 && b.len() >= 2 && b[1..b.len() - 1].iter().all(|&(_, m)| m < kv.degree())
    })
}

/// Solve on the common bases `cf` (module doc) with `opts.method`: the volume (unit
/// frame undone) and what was done.
fn solve_on(cf: &CommonFaces, opts: &VolumeOptions) -> Result<OnBasis> {
    let shape = cf.shape();
    let (target, weights) = boundary_points(cf)?;
    let (centre, scale) = unit_frame(&target);
    let to_unit = |p: &Point3| -> Point3 { std::array::from_fn(|c| (p[c] - centre[c]) / scale) };
    let target: Vec<Point3> = target.iter().map(to_unit).collect();
    let is_boundary = |lin: usize| {
        let ijk = [lin % shape[0], (lin / shape[0]) % shape[1], lin / (shape[0] * shape[1])];
        (0..3).any(|d| ijk[d] == 0 || ijk[d] == shape[d] - 1)
    };
    let rational = cf.rational();
    let template = volume_of(cf.knots.clone(), &vec![[0.0, 0.0, 0.0, 1.0]; target.len()], false);
    let template = Volume { weights: rational.then(|| weights.clone()), ..template };
    let degree = template.degrees().into_iter().max().unwrap_or(1);
    let disc = Arc::new(VolumeDiscretization::new(&template, degree + 2));
    let energy = WinslowVolume::on(disc.clone());
    let method =
        if opts.method != VolumeMethod::Winslow && is_c1(&cf.knots) { opts.method } else { VolumeMethod::Winslow };
    let mut egg = None;
    // the Winslow energies of the start and the result (report fields) come with the
    // last evaluations of the methods, none is evaluated for them alone
    let (current, start, continuation_steps, iterations, relative_gradient, energy_start, energy) = match method {
        VolumeMethod::Egg | VolumeMethod::EggWinslow => {
            // the Coons patch of the faces
            let disp: Vec<[f64; 3]> =
                target.iter().enumerate().map(|(lin, p)| if is_boundary(lin) { *p } else { [0.0; 3] }).collect();
            let mut cps = coons_fill(&cf.knots, disp);
            let op = EggVolume::on(disc.clone());
            let solved = solve_egg(&op, &mut cps, opts.max_iterations, opts.tolerance, opts.linear)?;
            let energy_start = solved.energy_start.is_finite().then_some(solved.energy_start * scale);
            egg = Some(solved);
            if method == VolumeMethod::Egg {
                (cps, "coons", 1, solved.iterations, None, energy_start, solved.energy)
            } else if solved.energy.is_finite() {
                let stats = minimise(&energy, &mut cps, opts.max_iterations, opts.tolerance)?;
                let it = solved.iterations + stats.iterations;
                (cps, "egg", 0, it, Some(stats.relative_gradient), energy_start, stats.energy)
            } else {
                let (cps, start, steps, stats, _) = winslow_from_corners(&energy, cf, &target, &is_boundary, opts)?;
                let it = solved.iterations + stats.iterations;
                (cps, start, steps, it, Some(stats.relative_gradient), energy_start, stats.energy)
            }
        }
        VolumeMethod::Winslow => {
            let (cps, start, steps, stats, energy_start) =
                winslow_from_corners(&energy, cf, &target, &is_boundary, opts)?;
            let it = stats.iterations;
            (cps, start, steps, it, Some(stats.relative_gradient), energy_start.map(|e| e * scale), stats.energy)
        }
    };
    let energy = energy * scale;
    // exact boundary: the input's control points, not their unit image
    let (orig, _) = boundary_points(cf)?;
    let cps: Vec<Point3> = current
        .iter()
        .enumerate()
        .map(|(lin, p)| if is_boundary(lin) { orig[lin] } else { std::array::from_fn(|c| centre[c] + scale * p[c]) })
        .collect();
    let volume = Volume::new(cf.knots.clone(), cps, template.weights.clone())?;
    Ok(OnBasis { volume, method, start, continuation_steps, iterations, egg, relative_gradient, energy, energy_start })
}

/// What [`winslow_from_corners`] returns.
type FromCorners = (Vec<Point3>, &'static str, usize, Minimised, Option<f64>);

/// The 3D Winslow functional minimised on the unit-frame boundary `target` from the
/// Coons patch, or by the continuation from the corners' trilinear volume (module doc):
/// the control points, the start's kind, continuation steps, Newton statistics (the
/// continuation's iterations included) and `E` of the Coons patch (unit frame).
fn winslow_from_corners(
    energy: &WinslowVolume,
    cf: &CommonFaces,
    target: &[Point3],
    is_boundary: &dyn Fn(usize) -> bool,
    opts: &VolumeOptions,
) -> Result<FromCorners> {
    let shape = cf.shape();
    // the corners' trilinear volume, at the Greville points
    let corner = |i: usize, j: usize, k: usize| {
        let lin = ((k * (shape[2] - 1)) * shape[1] + j * (shape[1] - 1)) * shape[0] + i * (shape[0] - 1);
        target[lin]
    };
    let g: [Vec<f64>; 3] = std::array::from_fn(|d| cf.knots[d].greville());
    let start: Vec<Point3> = (0..target.len())
        .map(|lin| {
            let (i, j, k) = (lin % shape[0], (lin / shape[0]) % shape[1], lin / (shape[0] * shape[1]));
            let (a, b, c) = (g[0][i], g[1][j], g[2][k]);
            let mut p = [0.0; 3];
            for (ci, wa) in [(0, 1.0 - a), (1, a)] {
                for (cj, wb) in [(0, 1.0 - b), (1, b)] {
                    for (ck, wc) in [(0, 1.0 - c), (1, c)] {
                        let q = corner(ci, cj, ck);
                        for z in 0..3 {
                            p[z] += wa * wb * wc * q[z];
                        }
                    }
                }
            }
            p
        })
        .collect();
    let mut current = start.clone();
    let (mut t, mut dt) = (0.0f64, 1.0f64);
    let (mut steps, mut accepted, mut iterations) = (0, 0, 0);
    let mut coons_energy = None;
    while t < 1.0 {
        steps += 1;
        if steps > opts.max_continuation || dt < 1e-6 {
            return Err(Error::NoConvergence(format!(
                "3D Winslow continuation: the boundary could not be moved past t = {t:.6} from the corners' trilinear volume \
                 in {} steps",
                steps - 1
            )));
        }
        let tn = (t + dt).min(1.0);
        // displacement of the boundary, extended into the interior by the Coons patch
        let disp: Vec<[f64; 3]> = (0..target.len())
            .map(|lin| {
                if is_boundary(lin) {
                    std::array::from_fn(|c| start[lin][c] + tn * (target[lin][c] - start[lin][c]) - current[lin][c])
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        let disp = coons_fill(&cf.knots, disp);
        let trial: Vec<Point3> = current.iter().zip(&disp).map(|(p, d)| std::array::from_fn(|c| p[c] + d[c])).collect();
        let ev = energy.evaluate(&trial, false);
        if steps == 1 {
            coons_energy = ev.energy.is_finite().then_some(ev.energy);
        }
        if !ev.energy.is_finite() {
            dt *= 0.5;
            continue;
        }
        current = trial;
        t = tn;
        accepted += 1;
        if t < 1.0 {
            iterations += minimise(energy, &mut current, 20, 1e-6)?.iterations;
            dt *= 2.0;
        }
    }
    let mut stats = minimise(energy, &mut current, opts.max_iterations, opts.tolerance)?;
    stats.iterations += iterations;
    let kind = if accepted == 1 { "coons" } else { "continuation" };
    Ok((current, kind, accepted, stats, coons_energy))
}

/// Largest distance between the faces of `v` and those of `b` on a 17 x 17 grid per
/// face.
pub fn boundary_deviation(v: &Volume, b: &VolumeBoundary) -> f64 {
    let mut worst = 0.0f64;
    for side in CubeSide::ALL {
        let (d, val) = side.fixed();
        let [ps, pt] = side.params();
        for i in 0..17 {
            for j in 0..17 {
                let (s, t) = (i as f64 / 16.0, j as f64 / 16.0);
                let mut u = [0.0; 3];
                u[d] = val;
                u[ps] = s;
                u[pt] = t;
                let (x, y) = (v.eval(u), b.face(side).eval(s, t));
                let dist = (0..3).map(|c| (x[c] - y[c]).powi(2)).sum::<f64>().sqrt();
                worst = worst.max(if dist.is_nan() { f64::INFINITY } else { dist });
            }
        }
    }
    worst
}

/// The volume bounded by the faces of `b` (validated first; module doc): certified,
/// or the last attempt with its certificate (the caller must not treat a volume whose
/// verdict is not `certified` as valid).
pub(crate) fn solve_volume(b: &VolumeBoundary, opts: &VolumeOptions) -> Result<VolumeSolve> {
    let t0 = Instant::now();
    b.validate()?;
    let diameter = b.diameter();
    let mut refine = opts.refine;
    let mut extra: [Vec<f64>; 3] = Default::default();
    let mut repair = Vec::new();
    loop {
        let cf = common_faces(b, refine, &extra)?;
        let on = solve_on(&cf, opts)?;
        let volume = on.volume;
        let certificate = certify_volume(&volume, &opts.certify)?;
        let certified = matches!(certificate.verdict, VolumeFinding::Certified { .. });
        if certified || repair.len() >= opts.max_refinements {
            let deviation = boundary_deviation(&volume, b);
            let report = VolumeSolveReport {
                method: on.method.name(),
                degrees: volume.degrees(),
                shape: volume.shape(),
                unknowns: 3 * volume.shape().iter().map(|n| n - 2).product::<usize>(),
                refine,
                repair,
                start: on.start,
                continuation_steps: on.continuation_steps,
                newton_iterations: on.iterations,
                egg_iterations: on.egg.map(|e| e.iterations),
                egg_relative_residual: on.egg.map(|e| e.relative_residual),
                egg_linear: on.egg.map(|e| if e.linear == LinearMethod::Lu { "lu" } else { "gmres" }),
                egg_krylov_iterations: on.egg.map(|e| e.krylov_iterations),
                energy_start: on.energy_start,
                energy: on.energy,
                relative_gradient: on.relative_gradient,
                boundary_deviation: deviation,
                boundary_kept: deviation <= 1e-9 * diameter,
                verdict: certificate.verdict.name(),
                certificate_seconds: certificate.seconds,
                seconds: t0.elapsed().as_secs_f64(),
            };
            return Ok(VolumeSolve { volume, certificate, report });
        }
        let offending = certificate.offending_elements();
        let (spans_refined, shape) = if offending.is_empty() {
            refine += 1;
            (cf.knots.each_ref().map(KnotVector::num_elements), cf.knots.each_ref().map(|k| k.halved().num_basis()))
        } else {
            let mids = offending_midpoints(&cf.knots, &offending, REPAIR_HALO);
            let shape = std::array::from_fn(|d| cf.knots[d].with_inserted(&mids[d]).num_basis());
            let counts = mids.each_ref().map(Vec::len);
            for (e, m) in extra.iter_mut().zip(mids) {
                e.extend(m);
            }
            (counts, shape)
        };
        repair.push(VolumeRepairRound {
            verdict: certificate.verdict.name(),
            offending_elements: offending.len(),
            spans_refined,
            shape,
        });
    }
}

/// Spans around an offending element bisected with it, per direction.
const REPAIR_HALO: usize = 1;

/// The midpoints of the knot spans (elements) of `knots` in each direction that hold
/// an element of `offending` or lie within `halo` spans of one.
fn offending_midpoints(knots: &[KnotVector; 3], offending: &[[usize; 3]], halo: usize) -> [Vec<f64>; 3] {
    std::array::from_fn(|d| {
        let elems = knots[d].elements();
        let n = elems.len();
        let mut mark = vec![false; n];
        for e in offending {
            let i = e[d].min(n - 1);
            for m in &mut mark[i.saturating_sub(halo)..=(i + halo).min(n - 1)] {
                *m = true;
            }
        }
        elems.iter().zip(&mark).filter(|(_, &m)| m).map(|(&(_, a, b), _)| 0.5 * (a + b)).collect()
    })
}

#[cfg(test)]
mod tests;
