//! The conforming multipatch solve (paper §11.2): every patch is solved on the bases of
//! the layout ([`LayoutBases`]: one knot vector per interface, propagated through the
//! whole layout) with its four sides as Dirichlet data, so the interfaces are fixed and
//! the patches conforming, their shared control points identical bit for bit; each
//! patch is an ordinary single-patch EGG solve (the coarse-to-fine solver of
//! [`crate::solve::solver`] on the input basis of its conforming sides), run in
//! parallel, and certified on its own. A patch that is not certified refines the
//! direction classes it belongs to (the direction of its longer elements, or both; its
//! neighbours are refined with it, so the layout stays conforming) and the layout is
//! solved again, at most
//! [`LAYOUT_REPAIR`] times. With [`Interfaces::Free`] the certified layout
//! is then improved with its interfaces free (`free`).
//!
//! The layout is solved in the normalised coordinates of one `Similarity` for all
//! patches (the identity for a well-placed domain), so that the maps brought back are
//! still conforming bit for bit.

use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use super::check::{validate_layout, LayoutReport};
use super::classes::LayoutBases;
use super::free::{free_interfaces, total_winslow, FreeReport};
use super::layout::Layout;
use super::problem::Functional;
use crate::boundary::hierarchy::{BasisReport, Hierarchy, Level};
use crate::boundary::input_basis::input_levels;
use crate::boundary::normalise::Similarity;
use crate::boundary::reparam::ReparamReport;
use crate::boundary::{diameter, BasisChoice, Boundary, SideCurve};
use crate::error::{Error, Result};
use crate::methods::egg::EggAssembler;
use crate::solve::memory::MemoryEstimate;
use crate::solve::options::SolveOptions;
use crate::solve::report::{Report, Verdict};
use crate::solve::solver::EggSolver;
use crate::spline::curve::Curve;
use crate::spline::surface::{Side, Surface};
use crate::verify::certificate::{certify, Certificate, Finding};

/// How the interfaces between patches are treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Interfaces {
    /// The interfaces are Dirichlet data of both patches (their curves as given).
    #[default]
    Fixed,
    /// After the fixed solve, the interface control points (except corners where three
    /// or more patches meet, and the outer boundary) are unknowns of one problem over
    /// all patches.
    Free,
}

impl Interfaces {
    /// `"fixed"` or `"free"`.
    pub fn name(self) -> &'static str {
        match self {
            Interfaces::Fixed => "fixed",
            Interfaces::Free => "free",
        }
    }
}

/// Layout refinement rounds at most while a patch is not certified
/// ([`RepairOptions::rounds`](crate::solve::options::RepairOptions::rounds) when lower): a
/// layout refinement refines whole chains of patches.
pub const LAYOUT_REPAIR: usize = 3;

/// How the options of one solve apply to a layout: every patch is solved with `opts`
/// (method, nonlinear iteration, certificate), but `levels.refine` refines the layout's
/// bases, `repair.rounds` counts layout refinement rounds (at most [`LAYOUT_REPAIR`]), and `improve`
/// is the free-interface stage (paper §11.2: improving a layout, one patch being a
/// one-patch layout): [`Interfaces::Free`] with that functional.
pub fn interfaces_of(opts: &SolveOptions) -> Interfaces {
    if opts.improve.is_some() {
        Interfaces::Free
    } else {
        Interfaces::Fixed
    }
}

/// What a layout solve reports while it runs (the module documentation).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum LayoutEvent {
    /// The layout was validated and its conforming bases built.
    Bases {
        /// Patches.
        patches: usize,
        /// Direction classes (one knot vector each).
        classes: usize,
        /// Basis functions summed over the patches.
        basis_functions: usize,
    },
    /// A round of fixed-interface solves ended.
    Round {
        /// The round (0: the first solve; then one per layout refinement).
        round: usize,
        /// Patches solved in this round (those whose bases changed).
        solved: usize,
        /// The patches not certified after it (the next round, if any, refines them).
        failing: Vec<String>,
    },
    /// The free-interface stage starts.
    Free {
        /// Its functional: `"winslow"` or `"weak-form"`.
        functional: &'static str,
    },
}

/// One solved patch.
#[derive(Debug, Clone)]
pub struct PatchSolution {
    /// Its name.
    pub name: String,
    /// Its map.
    pub map: Surface,
    /// Its certificate.
    pub certificate: Certificate,
    /// Its verdict.
    pub verdict: Verdict,
    /// The report of its fixed-interface solve (levels, iterations, fit, corners).
    pub solve: Report,
}

/// One direction class of the layout's bases.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ClassReport {
    /// Degree.
    pub degree: usize,
    /// Elements.
    pub elements: usize,
    /// Its patch directions, `"name.xi"` or `"name.eta"` (`"-"` prefixed when flipped).
    pub members: Vec<String>,
}

/// The report of a multipatch solve.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct MultipatchReport {
    /// Crate version.
    pub version: &'static str,
    /// Name of the layout.
    pub name: String,
    /// `"fixed"` or `"free"`.
    pub interfaces: &'static str,
    /// What the validation measured.
    pub layout: LayoutReport,
    /// The direction classes and their bases.
    pub classes: Vec<ClassReport>,
    /// Basis functions summed over the patches.
    pub basis_functions: usize,
    /// Layout refinement rounds run because a patch was not certified.
    pub layout_refinements: usize,
    /// Largest difference between the control points of the two sides of an interface
    /// (0: identical bit for bit).
    pub interface_mismatch: f64,
    /// Total Winslow value of the final maps.
    pub winslow: Option<f64>,
    /// The worst verdict over the patches.
    pub verdict: Verdict,
    /// Verdict per patch.
    pub verdicts: Vec<Verdict>,
    /// Seconds of the validation of the layout.
    pub validation_seconds: f64,
    /// Seconds of the fixed-interface solves (all rounds, validation and bases included).
    pub fixed_seconds: f64,
    /// The free-interface stage, when run.
    pub free: Option<FreeReport>,
    /// The similarity the layout was solved in, when not the identity.
    pub normalisation: Option<Similarity>,
    /// Total seconds.
    pub seconds: f64,
    /// Plain-language summary.
    pub message: String,
}

/// A solved layout.
#[derive(Debug, Clone)]
pub struct MultipatchSolution {
    /// The layout that was solved (as given).
    pub layout: Layout,
    /// One solved patch per patch of the layout.
    pub patches: Vec<PatchSolution>,
    /// The report.
    pub report: MultipatchReport,
}

impl MultipatchSolution {
    /// The patch maps.
    pub fn maps(&self) -> Vec<Surface> {
        self.patches.iter().map(|p| p.map.clone()).collect()
    }
}

/// How bad a verdict is (for the worst over the patches).
fn rank(v: Verdict) -> u8 {
    match v {
        Verdict::Certified => 0,
        Verdict::DegenerateCorner => 1,
        Verdict::Undecided => 2,
        Verdict::Folded => 3,
        Verdict::NotConverged => 4,
    }
}

/// Largest distance between the control points of the two sides of every interface of
/// `layout` in `maps` (0 when they are identical).
pub fn interface_mismatch(layout: &Layout, maps: &[Surface]) -> f64 {
    let mut worst = 0.0f64;
    for i in &layout.interfaces {
        let a = maps[i.first.patch].boundary(i.first.side).control_points;
        let mut b = maps[i.second.patch].boundary(i.second.side).control_points;
        if i.reversed {
            b.reverse();
        }
        if a.len() != b.len() {
            return f64::INFINITY;
        }
        for (p, q) in a.iter().zip(&b) {
            worst = worst.max((p[0] - q[0]).abs().max((p[1] - q[1]).abs()));
        }
    }
    worst
}

/// Solve one patch with its conforming `sides` as Dirichlet data on their own basis;
/// its certificate is the solve's when the solved boundary is the conforming sides' bit
/// for bit, else that of the map with them.
fn solve_patch(
    layout: &Layout,
    p: usize,
    sides: &[Curve; 4],
    opts: &SolveOptions,
    assembler: Arc<dyn EggAssembler>,
) -> Result<(Surface, Report, Certificate)> {
    let boundary = Boundary { name: layout.patches[p].name.clone(), sides: sides.clone().map(SideCurve::Spline) };
    let input = input_levels(&boundary)?
        .map_err(|why| layout.error(p, None, format!("its conforming sides cannot be kept in their basis: {why}")))?;
    let diameter = diameter(&boundary);
    let h = Hierarchy {
        levels: input.levels.into_iter().map(|(knots, sides)| Level { knots, sides }).collect(),
        fits: input.fits,
        tol_abs: opts.fit.tol * diameter,
        diameter,
        reparam: ReparamReport::native(),
        basis: BasisReport { requested: BasisChoice::Input, used: BasisChoice::Input, fallback: None, kinks: None },
        kinked: None,
        similarity: Similarity::IDENTITY,
        detected: crate::boundary::kinks::detect(&boundary, crate::boundary::KinkMode::Auto, true),
        roundings: Vec::new(),
    };
    let mut o = opts.clone();
    o.levels.refine = 0;
    o.repair.rounds = 0;
    o.improve = None;
    o.fit.basis = BasisChoice::Input;
    // the report's det J sample (information only: the verdict is the certificate's) at
    // 8 points per element of the finer direction, not more than asked for
    let finest = h.levels.last().map_or(1, |l| l.knots[0].num_elements().max(l.knots[1].num_elements()));
    o.report.sample = o.report.sample.min(8 * finest.max(4));
    let sol = EggSolver::new(&boundary, Arc::new(h), o, assembler)?.finish()?;
    let mut map = sol.map;
    // the boundary control points are the conforming sides' exactly
    let shape = map.shape();
    let mut changed = false;
    for s in Side::ALL {
        let idx = Surface::side_indices(shape, s);
        for (k, q) in idx.into_iter().zip(&sides[s as usize].control_points) {
            changed |= map.control_points[k] != *q;
            map.control_points[k] = *q;
        }
    }
    let cert = if changed { certify(&map, &opts.certify)? } else { sol.report.outcome.certificate.clone() };
    Ok((map, sol.report, cert))
}

/// The directions of a patch to refine when it is not certified: the one whose elements
/// are longer (mean length of its two sides per element), or both when they are within a
/// factor 2 of each other (a thin C-grid refines across, not along).
fn coarse_directions(sides: &[Curve; 4], knots: &[crate::spline::knots::KnotVector; 2]) -> Vec<usize> {
    let length = |c: &Curve| c.sample(64).windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum::<f64>();
    let per = |d: usize, a: Side, b: Side| {
        0.5 * (length(&sides[a as usize]) + length(&sides[b as usize])) / knots[d].num_elements().max(1) as f64
    };
    let (hx, hy) = (per(0, Side::South, Side::North), per(1, Side::West, Side::East));
    if hx > 2.0 * hy {
        vec![0]
    } else if hy > 2.0 * hx {
        vec![1]
    } else {
        vec![0, 1]
    }
}

/// A patch's map, report and certificate, and the knot vectors it was solved on.
/// The estimated peak memory of solving `layout` with `opts` ([`MemoryEstimate::for_patches`]
/// of the conforming bases of the first round, after `opts.levels.refine` halvings).
pub(crate) fn layout_estimate(layout: &Layout, opts: &SolveOptions) -> Result<MemoryEstimate> {
    validate_layout(layout)?;
    let (lo, hi) = layout.bounding_box();
    let sim = Similarity::for_box(lo, hi, &format!("layout '{}'", layout.name))?;
    let mut bases = LayoutBases::new(&layout.similar(&sim))?;
    for _ in 0..opts.levels.refine {
        bases = bases.refined(None);
    }
    let knots: Vec<_> = (0..layout.patches.len()).map(|p| bases.patch_knots(p)).collect();
    Ok(MemoryEstimate::for_patches(&knots, interfaces_of(opts) == Interfaces::Free))
}

type PatchSolved = (Surface, Report, Certificate, [crate::spline::knots::KnotVector; 2]);

/// Solve `layout` (see the module documentation) with `opts` as [`interfaces_of`] says,
/// every patch assembled on `assembler`; `observer` sees the [`LayoutEvent`]s and stops
/// the solve ([`Error::Cancelled`]) when it returns `false`. The entry is
/// [`Pipeline`](crate::pipeline::Pipeline) with a layout input.
pub(crate) fn solve_multipatch(
    layout: &Layout,
    opts: &SolveOptions,
    assembler: Arc<dyn EggAssembler>,
    observer: &mut dyn FnMut(&LayoutEvent) -> bool,
) -> Result<MultipatchSolution> {
    let t0 = Instant::now();
    let interfaces = interfaces_of(opts);
    let functional = opts.improve.unwrap_or_default();
    let repair = opts.repair.rounds.min(LAYOUT_REPAIR);
    let mut tell = |e: LayoutEvent| if observer(&e) { Ok(()) } else { Err(Error::Cancelled) };
    let checked = validate_layout(layout)?;
    let validation_seconds = t0.elapsed().as_secs_f64();
    let (lo, hi) = layout.bounding_box();
    let sim = Similarity::for_box(lo, hi, &format!("layout '{}'", layout.name))?;
    let unit = layout.similar(&sim);
    let mut bases = LayoutBases::new(&unit)?;
    for _ in 0..opts.levels.refine {
        bases = bases.refined(None);
    }
    let n = unit.patches.len();
    let fits = |bases: &LayoutBases| {
        let knots: Vec<_> = (0..n).map(|p| bases.patch_knots(p)).collect();
        let estimate = MemoryEstimate::for_patches(&knots, interfaces == Interfaces::Free);
        opts.max_memory.check(&estimate, opts.levels.refine, &format!("solving layout '{}' ({n} patches)", layout.name))
    };
    fits(&bases)?;
    tell(LayoutEvent::Bases { patches: n, classes: bases.classes.len(), basis_functions: bases.num_basis() })?;
    let mut solved: Vec<Option<PatchSolved>> = vec![None; n];
    let mut rounds = 0;
    loop {
        let sides = bases.conforming_sides(&unit)?;
        let todo: Vec<usize> =
            (0..n).filter(|&p| solved[p].as_ref().is_none_or(|s| s.3 != bases.patch_knots(p))).collect();
        let results: Vec<Result<(usize, Surface, Report, Certificate)>> = todo
            .par_iter()
            .map(|&p| {
                let (map, report, cert) = solve_patch(&unit, p, &sides[p], opts, assembler.clone())?;
                Ok((p, map, report, cert))
            })
            .collect();
        for r in results {
            let (p, map, report, cert) = r?;
            solved[p] = Some((map, report, cert, bases.patch_knots(p)));
        }
        let failing: Vec<usize> = (0..n)
            .filter(|&p| {
                let s = solved[p].as_ref().expect("every patch solved");
                let converged = s.1.solve.levels.last().is_some_and(|l| l.converged);
                !converged || !matches!(s.2.verdict, Finding::Certified { .. } | Finding::DegenerateCorner { .. })
            })
            .collect();
        let failing_names = failing.iter().map(|&p| layout.label(p)).collect();
        tell(LayoutEvent::Round { round: rounds, solved: todo.len(), failing: failing_names })?;
        if failing.is_empty() || rounds >= repair {
            break;
        }
        let mut classes = Vec::new();
        for &p in &failing {
            for d in coarse_directions(&sides[p], &bases.patch_knots(p)) {
                classes.push(bases.classes.member[p][d].0);
            }
        }
        classes.sort_unstable();
        classes.dedup();
        bases = bases.refined(Some(&classes));
        // a repair round's finer bases are refused like the first ones, before any solve
        fits(&bases)?;
        rounds += 1;
    }
    let fixed_seconds = t0.elapsed().as_secs_f64();
    let mut maps = Vec::with_capacity(n);
    let mut certs = Vec::with_capacity(n);
    let mut reports = Vec::with_capacity(n);
    let mut converged = Vec::with_capacity(n);
    for s in solved {
        let (map, report, cert, _) = s.expect("every patch solved");
        converged.push(report.solve.levels.last().is_some_and(|l| l.converged));
        maps.push(map);
        certs.push(cert);
        reports.push(report);
    }
    // the free interfaces move in the normalised coordinates the patches were solved in
    // (their stopping rule and line search see lengths), then everything goes back
    let mut free = None;
    if interfaces == Interfaces::Free {
        if converged.iter().all(|&c| c) {
            tell(LayoutEvent::Free { functional: functional.name() })?;
            let out = free_interfaces(
                &unit,
                &maps,
                &certs,
                functional,
                opts.nonlinear,
                &opts.certify,
                checked.diameter / sim.scale,
            );
            match out {
                Ok(f) => {
                    maps = f.maps;
                    certs = f.certificates;
                    free = Some(f.report);
                }
                Err(crate::error::Error::InfeasibleStart { reason, .. }) => {
                    free = Some(skipped(functional, &maps, format!("not run: {reason}")));
                }
                Err(e) => return Err(e),
            }
        } else {
            free = Some(skipped(functional, &maps, "not run: a patch's solve did not converge".into()));
        }
    }
    if !sim.is_identity() {
        maps = maps.iter().map(|m| sim.physical_surface(m)).collect::<Result<_>>()?;
        certs = maps.iter().map(|m| certify(m, &opts.certify)).collect::<Result<_>>()?;
        if let Some(f) = free.as_mut().filter(|f| f.accepted) {
            f.certificates = certs.iter().map(Certificate::message).collect();
        }
    }
    let verdicts: Vec<Verdict> = certs
        .iter()
        .zip(&converged)
        .map(|(c, &ok)| if ok { Verdict::of_certificate(c) } else { Verdict::NotConverged })
        .collect();
    let verdict = verdicts.iter().copied().max_by_key(|&v| rank(v)).unwrap_or(Verdict::Certified);
    let classes = (0..bases.classes.len())
        .map(|c| ClassReport {
            degree: bases.knots[c].degree(),
            elements: bases.knots[c].num_elements(),
            members: bases
                .classes
                .members(c)
                .into_iter()
                .map(|(p, d, f)| format!("{}{}.{}", if f { "-" } else { "" }, layout.patches[p].name, ["xi", "eta"][d]))
                .collect(),
        })
        .collect();
    let mismatch = interface_mismatch(layout, &maps);
    let winslow = total_winslow(&maps);
    let good = verdicts.iter().filter(|v| matches!(v, Verdict::Certified | Verdict::DegenerateCorner)).count();
    let message = format!(
        "{good} of {n} patches certified ({}), interfaces {} ({} rounds of layout refinement); interface control points {}{}",
        verdict.name(),
        interfaces.name(),
        rounds,
        if mismatch == 0.0 { "identical bit for bit".to_string() } else { format!("differ by up to {mismatch:.3e}") },
        free.as_ref().map(|f| format!("; {}", f.message)).unwrap_or_default()
    );
    let patches = layout
        .patches
        .iter()
        .zip(maps)
        .zip(certs)
        .zip(reports)
        .zip(&verdicts)
        .map(|((((p, map), certificate), solve), &verdict)| PatchSolution {
            name: p.name.clone(),
            map,
            certificate,
            verdict,
            solve,
        })
        .collect::<Vec<_>>();
    let report = MultipatchReport {
        version: env!("CARGO_PKG_VERSION"),
        name: layout.name.clone(),
        interfaces: interfaces.name(),
        layout: checked,
        classes,
        basis_functions: patches.iter().map(|p| p.map.control_points.len()).sum(),
        layout_refinements: rounds,
        validation_seconds,
        interface_mismatch: mismatch,
        winslow,
        verdict,
        verdicts,
        fixed_seconds,
        free,
        normalisation: (!sim.is_identity()).then_some(sim),
        seconds: t0.elapsed().as_secs_f64(),
        message,
    };
    Ok(MultipatchSolution { layout: layout.clone(), patches, report })
}

/// The report of a free-interface stage that did not run.
fn skipped(functional: Functional, maps: &[Surface], why: String) -> FreeReport {
    let w = total_winslow(maps);
    FreeReport {
        functional: functional.name(),
        accepted: false,
        converged: false,
        failure: Some(why.clone()),
        iterations: 0,
        unknowns: 0,
        interface_unknowns: 0,
        fixed_vertices: 0,
        residuals: Vec::new(),
        objective: Vec::new(),
        winslow_before: w,
        winslow_after: w,
        max_interface_displacement: 0.0,
        certificates: Vec::new(),
        seconds: 0.0,
        message: format!("free interfaces ({}): {why}; the fixed-interface maps are kept", functional.name()),
    }
}
