//! The certified loft (paper §11.1): planar maps at heights `z_i` become one trivariate
//! map ([`crate::spline::loft`]), certified by the volume certificate
//! ([`certify_volume`]); where it is not certified, slices are inserted and the volume
//! is built again.
//!
//! **Inserting a slice.** Every folded or undecided element of the volume lies in one or
//! more intervals `[z_i, z_{i+1}]` between slices; a slice is inserted at the middle `z*`
//! of each such interval. Its initial guess is the interpolated volume's section there
//! (the paper's "excellent initial guesses ... via interpolation in `z`"), on the common
//! basis; its boundary control points come from [`SliceBoundary`]: a parametric family
//! that knows the boundary at every `z` (a sweep, a twisted or scaled domain), or, when
//! only the maps are given, the section's own boundary (the interpolated boundary, exact
//! for linear interpolation of the boundary control points). EGG is then solved for the
//! interior by Newton on that basis with the topology of the slices (four Dirichlet
//! sides, or a ring: `η` periodic), and the slice must certify. Rounds repeat until the
//! volume is certified or [`LoftOptions::max_inserted`] slices were inserted.

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use super::fixed_basis::{scaled_options, FixedBasisSolve};
use super::newton::NonlinearOptions;
use crate::boundary::normalise::Similarity;
use crate::discrete::assembly::{Discretization, Operator};
use crate::discrete::topology::Topology;
use crate::error::{Error, Result};
use crate::methods::egg::EggMethod;
use crate::spline::loft::{check_heights, common_basis, interpolate, planar_section, zeta_of, Interpolation};
use crate::spline::surface::Surface;
use crate::spline::volume::Volume;
use crate::verify::certificate::volume::{certify_volume, VolumeCertificate, VolumeFinding};
use crate::verify::certificate::{certify, CertifyOptions, Finding};

/// Options of [`loft`].
#[derive(Debug, Clone)]
pub struct LoftOptions {
    /// Interpolation in `z` (linear by default, see [`Interpolation`]).
    pub interpolation: Interpolation,
    /// Most slices inserted in all.
    pub max_inserted: usize,
    /// Options of the volume certificate and of the slices' certificates.
    pub certify: CertifyOptions,
    /// Newton iteration of an inserted slice.
    pub nonlinear: NonlinearOptions,
    /// Operator of eq. (8) for inserted slices.
    pub operator: Operator,
}

impl Default for LoftOptions {
    fn default() -> Self {
        Self {
            interpolation: Interpolation::default(),
            max_inserted: 64,
            certify: CertifyOptions::default(),
            nonlinear: NonlinearOptions::default(),
            operator: Operator::default(),
        }
    }
}

/// A family's boundary: given `z` and the interpolated section (on the common basis),
/// the map whose boundary control points are the true boundary at `z` (its interior
/// control points are ignored).
pub(crate) type BoundaryFamily<'a> = dyn Fn(f64, &Surface) -> Result<Surface> + 'a;

/// Where the boundary of an inserted slice comes from.
#[derive(Clone, Copy)]
pub enum SliceBoundary<'a> {
    /// The boundary control points of the interpolated section (only maps given).
    Interpolated,
    /// A parametric family that knows the boundary at every `z`.
    Family(&'a BoundaryFamily<'a>),
}

impl std::fmt::Debug for SliceBoundary<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl SliceBoundary<'_> {
    /// `interpolated` or `family`.
    pub fn name(&self) -> &'static str {
        match self {
            SliceBoundary::Interpolated => "interpolated",
            SliceBoundary::Family(_) => "family",
        }
    }
}

/// One slice of the final volume.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct SliceReport {
    /// Height.
    pub z: f64,
    /// Index among the given slices, `null` for an inserted one.
    pub given: Option<usize>,
    /// For inserted slices: where the boundary came from (`interpolated`, `family`).
    pub boundary: Option<&'static str>,
    /// For inserted slices: Newton iterations and residuals before and after.
    pub newton_iterations: Option<usize>,
    /// `||F||` of the interpolated initial guess.
    pub residual_before: Option<f64>,
    /// `||F||` of the solution.
    pub residual_after: Option<f64>,
    /// Proven lower bound of the slice's planar `det J`.
    pub det_j_lower_bound: f64,
}

/// One round: the volume built from the slices of that round and its verdict.
#[derive(Debug, Clone, Serialize)]
pub struct LoftRound {
    /// Slices in this round.
    pub slices: usize,
    /// The volume certificate's verdict.
    pub verdict: &'static str,
    /// Folded or undecided elements.
    pub offending_elements: usize,
    /// Heights of the slices inserted after this round.
    pub inserted_z: Vec<f64>,
    /// Seconds of the volume certificate.
    pub certificate_seconds: f64,
}

/// The report of a loft.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct LoftReport {
    /// Interpolation in `z`.
    pub interpolation: Interpolation,
    /// Where inserted slices got their boundary.
    pub boundary: &'static str,
    /// Degrees of the volume.
    pub degrees: [usize; 3],
    /// Basis functions per direction.
    pub shape: [usize; 3],
    /// The slices, by height.
    pub slices: Vec<SliceReport>,
    /// The rounds of certification and insertion.
    pub rounds: Vec<LoftRound>,
    /// Final verdict (`certified`, `folded`, `undecided`).
    pub verdict: &'static str,
    /// Wall-clock seconds (common basis, slices' certificates, rounds).
    pub seconds: f64,
}

/// A lofted volume with its certificate.
#[derive(Debug, Clone)]
pub struct Loft {
    /// The volume.
    pub volume: Volume,
    /// Its certificate (of the last round).
    pub certificate: VolumeCertificate,
    /// The slices on the common basis, by height (inserted ones included).
    pub slices: Vec<Surface>,
    /// Their heights.
    pub z: Vec<f64>,
    /// The report.
    pub report: LoftReport,
}

/// The topology of a slice: a ring (periodic `η`) or four Dirichlet sides.
fn topology_of(s: &Surface) -> Topology {
    if s.knots[1].is_periodic() {
        Topology::ring()
    } else {
        Topology::dirichlet()
    }
}

fn require_certified(s: &Surface, slice: usize, z: f64, opts: &CertifyOptions) -> Result<f64> {
    let c = certify(s, opts)?;
    match &c.verdict {
        Finding::Certified { lower_bound, .. } => Ok(*lower_bound),
        v => Err(Error::SliceNotCertified { slice, z, verdict: v.name().into(), message: c.message() }),
    }
}

/// Solve EGG for the interior of `guess` (boundary control points fixed) by Newton on
/// its basis; returns the map, the Newton iterations and the residuals before and after
/// (of the normalised problem). Solved in the normalised coordinates of the guess' box
/// ([`Similarity`]) like every planar solve, so that a loft far from the origin or of
/// extreme size inserts the slices it inserts at unit size.
fn solve_slice(guess: &Surface, opts: &LoftOptions) -> Result<(Surface, usize, f64, f64)> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &guess.control_points {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let sim = Similarity::for_box(lo, hi, "an inserted slice")?;
    if sim.is_identity() {
        return solve_unit_slice(guess, opts);
    }
    let unit =
        Surface { control_points: guess.control_points.iter().map(|&p| sim.to_unit(p)).collect(), ..guess.clone() };
    let (map, iterations, before, after) = solve_unit_slice(&unit, opts)?;
    Ok((sim.physical_surface(&map)?, iterations, before, after))
}

/// [`solve_slice`] in the coordinates given.
fn solve_unit_slice(guess: &Surface, opts: &LoftOptions) -> Result<(Surface, usize, f64, f64)> {
    let topology = topology_of(guess);
    let disc = Discretization::for_topology(guess.knots.clone(), &topology)?.with_weights(guess.weights.clone())?;
    let disc = Arc::new(disc);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &guess.control_points {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let diameter = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    let method = EggMethod::cpu(opts.operator);
    let nl = scaled_options(opts.nonlinear, &method, diameter, disc.dofs.num_free());
    let mut cps = guess.control_points.clone();
    disc.dofs.wrap(&mut cps);
    let solved = FixedBasisSolve::new(&method, disc, cps, nl).finish()?;
    if let Some(why) = solved.failure() {
        return Err(Error::NoConvergence(format!("inserted slice: {why}")));
    }
    let h = &solved.history;
    let (iterations, (before, after)) = (h.iterations, h.residuals_before_after());
    let map =
        Surface { knots: guess.knots.clone(), control_points: solved.control_points, weights: guess.weights.clone() };
    Ok((map, iterations, before, after))
}

/// The guess of a slice inserted at `z` of `vol` (heights `z0..z1` of the volume).
fn inserted_guess(vol: &Volume, z: f64, zs: &[f64], boundary: SliceBoundary<'_>) -> Result<Surface> {
    let zeta = (z - zs[0]) / (zs[zs.len() - 1] - zs[0]);
    let mut guess = planar_section(vol, zeta);
    if let SliceBoundary::Family(f) = boundary {
        let b = f(z, &guess)?;
        if b.knots != guess.knots || b.control_points.len() != guess.control_points.len() {
            return Err(Error::Invalid(format!(
                "the boundary family returned a map on another basis at z = {z} (it must keep the common basis)"
            )));
        }
        let dofs = crate::discrete::dofs::DofMap::for_basis(&guess.knots, &topology_of(&guess))?;
        let free: std::collections::HashSet<usize> = dofs.free().iter().copied().collect();
        for (k, p) in guess.control_points.iter_mut().enumerate() {
            if !free.contains(&k) {
                *p = b.control_points[k];
            }
        }
    }
    Ok(guess)
}

/// The heights at which to insert slices: the middle of every interval between slices
/// that meets a folded or undecided element's `ζ` range.
fn insertion_heights(vol: &Volume, cert: &VolumeCertificate, zs: &[f64]) -> Vec<f64> {
    let zeta = zeta_of(zs);
    let elements = vol.knots[2].elements();
    let mut intervals: Vec<usize> = Vec::new();
    for e in cert.offending_elements() {
        let (_, a, b) = elements[e[2]];
        for i in 0..zeta.len() - 1 {
            if zeta[i] < b && zeta[i + 1] > a {
                intervals.push(i);
            }
        }
    }
    intervals.sort_unstable();
    intervals.dedup();
    let total = zs[zs.len() - 1] - zs[0];
    intervals.into_iter().filter(|&i| zs[i + 1] - zs[i] > 4e-9 * total).map(|i| 0.5 * (zs[i] + zs[i + 1])).collect()
}

/// Loft `slices` at heights `z` (see the module doc): the slices must each be certified
/// ([`Error::SliceNotCertified`] otherwise) and fit one basis ([`Error::Slices`]).
/// Returns the last volume with its certificate, whatever the verdict: the caller must
/// not treat a volume whose verdict is not `certified` as valid.
pub fn loft(slices: &[Surface], z: &[f64], opts: &LoftOptions, boundary: SliceBoundary<'_>) -> Result<Loft> {
    let t0 = Instant::now();
    check_heights(z, slices.len())?;
    let mut reports = Vec::with_capacity(slices.len());
    for (i, (s, &zi)) in slices.iter().zip(z).enumerate() {
        let lb = require_certified(s, i, zi, &opts.certify)?;
        reports.push(SliceReport {
            z: zi,
            given: Some(i),
            boundary: None,
            newton_iterations: None,
            residual_before: None,
            residual_after: None,
            det_j_lower_bound: lb,
        });
    }
    let mut maps = common_basis(slices)?;
    let mut zs = z.to_vec();
    let mut rounds = Vec::new();
    let mut inserted = 0;
    loop {
        let vol = interpolate(&maps, &zs, opts.interpolation)?;
        let cert = certify_volume(&vol, &opts.certify)?;
        let mut round = LoftRound {
            slices: maps.len(),
            verdict: cert.verdict.name(),
            offending_elements: cert.offending_elements().len(),
            inserted_z: Vec::new(),
            certificate_seconds: cert.seconds,
        };
        let heights = if matches!(cert.verdict, VolumeFinding::Certified { .. }) {
            Vec::new()
        } else {
            insertion_heights(&vol, &cert, &zs)
        };
        if heights.is_empty() || inserted + heights.len() > opts.max_inserted {
            rounds.push(round);
            let report = LoftReport {
                interpolation: opts.interpolation,
                boundary: boundary.name(),
                degrees: vol.degrees(),
                shape: vol.shape(),
                slices: reports,
                rounds,
                verdict: cert.verdict.name(),
                seconds: t0.elapsed().as_secs_f64(),
            };
            return Ok(Loft { volume: vol, certificate: cert, slices: maps, z: zs, report });
        }
        for &zn in &heights {
            let guess = inserted_guess(&vol, zn, &zs, boundary)?;
            let (map, iterations, before, after) = solve_slice(&guess, opts)?;
            let at = zs.partition_point(|&x| x < zn);
            let lb = require_certified(&map, at, zn, &opts.certify)?;
            zs.insert(at, zn);
            maps.insert(at, map);
            reports.insert(
                at,
                SliceReport {
                    z: zn,
                    given: None,
                    boundary: Some(boundary.name()),
                    newton_iterations: Some(iterations),
                    residual_before: Some(before),
                    residual_after: Some(after),
                    det_j_lower_bound: lb,
                },
            );
        }
        inserted += heights.len();
        round.inserted_z = heights;
        rounds.push(round);
    }
}

#[cfg(test)]
mod tests;
