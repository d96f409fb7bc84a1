//! The options of a complete solve, grouped by pipeline stage: fit, levels, nonlinear
//! iteration (operator, topology), repair, certificate, improvement, report.

use crate::boundary::fit::FitOptions;
use crate::discrete::assembly::Operator;
use crate::discrete::topology::Topology;
use crate::error::{Error, Result};
use crate::verify::certificate::CertifyOptions;

use super::improve::Improve;
use super::memory::MemoryLimit;
use super::newton::NonlinearOptions;

/// Options of a complete solve, grouped by the stage of the pipeline they control, in
/// the order the stages run: the contour fit ([`fit`](Self::fit), §5, §7), the levels of
/// the hierarchy ([`levels`](Self::levels), §5.4, §6.3), the nonlinear solve of each level
/// ([`nonlinear`](Self::nonlinear), [`operator`](Self::operator),
/// [`topology`](Self::topology), §3, §4, §6), defect correction
/// ([`repair`](Self::repair), §8.2), the certificate ([`certify`](Self::certify), §8.1), the
/// improvement on the same basis ([`improve`](Self::improve),
/// [`kinks_local`](Self::kinks_local), §4.1, §9) and the report ([`report`](Self::report),
/// §8.1, §10); [`max_memory`](Self::max_memory) bounds them all.
///
/// Built from [`Default`] and set field by field (new options are added without breaking
/// callers); [`validate`](Self::validate) checks every option before a solve.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct SolveOptions {
    /// Contour fitting (degree, tolerance, reparameterization, basis, kinks; §5, §7).
    pub fit: FitOptions,
    /// Which levels of the hierarchy are solved (§5.4, §6.3).
    pub levels: LevelOptions,
    /// Nonlinear iteration on every level.
    pub nonlinear: NonlinearOptions,
    /// Operator of eq. (8), plain or scaled.
    pub operator: Operator,
    /// The boundary condition of each side of the patch (four Dirichlet sides by
    /// default; see [`Topology`]).
    pub topology: Topology,
    /// Defect correction of a folded or undecided map (§8.2).
    pub repair: RepairOptions,
    /// Options of the bijectivity certificate.
    pub certify: CertifyOptions,
    /// After the solve and its certificate, improve the map on the same basis (e.g.
    /// minimize the Winslow functional, eq. 16) and certify again; the improved map is
    /// kept only when certified ([`crate::solve::improve`]).
    pub improve: Option<Improve>,
    /// With kinks kept (§9): which control points the final Winslow minimisation of the
    /// `C^0` route moves ([`KinksLocal`]).
    pub kinks_local: KinksLocal,
    /// What the report measures on the final map beyond its certificate (§8.1, §10).
    pub report: ReportOptions,
    /// The most memory the solve may take: its estimated peak
    /// ([`MemoryEstimate`](super::memory::MemoryEstimate)) above it is refused with
    /// [`Error::Memory`] before anything large is allocated (default: the memory
    /// available when the solve starts).
    pub max_memory: MemoryLimit,
}

/// Which levels of the fitted hierarchy are solved, coarse to fine (paper §6.3: each
/// solved level starts the next; §5.4: the finest basis is balanced and refined).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct LevelOptions {
    /// The finest level has at least this many elements per direction.
    pub min_elements: usize,
    /// Extra uniform halvings of the finest level.
    pub refine: usize,
    /// Solve at most this many levels (the finest is always solved).
    pub max_levels: Option<usize>,
    /// Basis growth factor between solved levels (the paper advises 4).
    pub growth: f64,
    /// Largest mean physical aspect ratio of the elements; the coarser direction of a
    /// level is halved until it is met (see `prepare_levels`).
    pub aspect: f64,
}

impl Default for LevelOptions {
    fn default() -> Self {
        Self { min_elements: 8, refine: 0, max_levels: None, growth: 4.0, aspect: 2.0 }
    }
}

/// Defect correction (paper §8.2): while the certificate of the finest map says folded
/// or undecided, refine around the offending elements and solve again.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct RepairOptions {
    /// Rounds of defect correction: at most this many. Default 6: the folds next to the
    /// necks of puzzle tabs in the hard corpus (`boundary::families`) need four rounds,
    /// and the offending-element count is not monotone from round to round (54, 74, 77,
    /// 46, then certified), so no earlier stopping rule is safe; inputs that certify
    /// sooner never see the difference.
    pub rounds: usize,
    /// Spans around each offending element that a repair round also bisects.
    pub halo: usize,
    /// When set, a repair round solves only for the control points whose support meets
    /// the offending elements widened by this many spans; the others keep the values of
    /// the prolonged map (paper §8.2: fewer unknowns).
    pub freeze: Option<usize>,
    /// How defect correction refines: tensor knot spans across the patch (the rounds of
    /// `rounds` in the solve), or THB cells around the defect only
    /// ([`crate::solve::hierarchical`], run by the pipeline on the unrepaired map).
    pub refinement: Refinement,
}

impl Default for RepairOptions {
    fn default() -> Self {
        Self { rounds: 6, halo: 1, freeze: None, refinement: Refinement::Tensor }
    }
}

/// What the report measures on the final map beyond its certificate: `det J` sampled for
/// the quality figures (§8.1) and the grid-quality benchmark of §10.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct ReportOptions {
    /// `det J` is sampled on an `(n+1)^2` grid for the report.
    pub sample: usize,
    /// Run the grid-quality benchmark Q(x) of §10 on the final map.
    pub poisson: bool,
}

impl Default for ReportOptions {
    fn default() -> Self {
        Self { sample: 200, poisson: false }
    }
}

/// How the defect correction (paper §8.2) refines the basis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Refinement {
    /// [`Refinement::Thb`] where a point-cloud side has corners the cloud resolves as
    /// roundings (`boundary::kinks::rounding_of`: no kinks, so the `C^1` fit follows them
    /// and the basis is graded towards those sides, `solve::levels::graded_at_roundings`),
    /// [`Refinement::Tensor`] elsewhere (BENCHMARKS.md "Puzzle necks and hair-thin gaps").
    /// The default of `winslow solve`; a THB map comes out where it applies, so the
    /// library's default stays [`Refinement::Tensor`].
    #[cfg_attr(
        feature = "clap",
        value(help = "thb where a point-cloud side has rounded corners (the jigsaw pieces), tensor elsewhere")
    )]
    Auto,
    /// Bisect the offending knot spans (and a halo) across the whole tensor basis.
    #[default]
    #[cfg_attr(feature = "clap", value(help = "Bisect the offending knot spans across the tensor basis"))]
    Tensor,
    /// Refine the offending cells (and a ring) of a THB basis only.
    #[cfg_attr(feature = "clap", value(help = "Refine only the offending cells and a ring around them (THB-splines)"))]
    Thb,
}

impl Refinement {
    /// The refinement this one stands for on a boundary with (`roundings`) or without
    /// rounded point-cloud corners: [`Refinement::Auto`] resolved, the others as they are.
    pub fn resolved(self, roundings: bool) -> Self {
        match self {
            Refinement::Auto if roundings => Refinement::Thb,
            Refinement::Auto => Refinement::Tensor,
            r => r,
        }
    }
}

/// Which control points the `C^0` route's final Winslow minimisation moves (paper §9,
/// last paragraph: "only recomputing a subset of DOFs in the vicinity of the boundary
/// control points that correspond to the C0-continuities").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KinksLocal {
    /// All interior ones up to `KINKS_LOCAL_ABOVE` unknowns, those within
    /// `KINKS_LOCAL_SPANS` knot spans of a kink above: the global minimisation improves
    /// the whole map a little but costs a Cholesky factorization of the whole vector
    /// Hessian per Newton step (puzzle-5 of the hard corpus, 224 k unknowns: 34 s of a
    /// 51 s solve, against 3 s locally; BENCHMARKS.md).
    #[default]
    Auto,
    /// All interior control points.
    All,
    /// Those whose support meets a square of this many knot spans of `Σ⁰` around each
    /// kink (along the side and into the domain); the others keep the elasticity start.
    Spans(usize),
}

/// Unknowns of the `C^0` basis above which [`KinksLocal::Auto`] minimises locally.
pub(crate) const KINKS_LOCAL_ABOVE: usize = 50_000;

/// Knot spans around each kink that [`KinksLocal::Auto`] moves above [`KINKS_LOCAL_ABOVE`].
pub(crate) const KINKS_LOCAL_SPANS: usize = 3;

impl KinksLocal {
    /// The spans around each kink to move for a `C^0` basis with `unknowns` free
    /// unknowns; `None`: all.
    pub fn spans(self, unknowns: usize) -> Option<usize> {
        match self {
            KinksLocal::Auto => (unknowns > KINKS_LOCAL_ABOVE).then_some(KINKS_LOCAL_SPANS),
            KinksLocal::All => None,
            KinksLocal::Spans(k) => Some(k),
        }
    }

    /// `auto`, `all` or a number of spans.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(KinksLocal::Auto),
            "all" => Some(KinksLocal::All),
            _ => s.parse().ok().map(KinksLocal::Spans),
        }
    }
}

impl SolveOptions {
    /// Check every option before a solve: the fit's ([`FitOptions::validate`]), a positive
    /// finite nonlinear tolerance, a growth factor and an aspect bound of at least 1, at
    /// least one element per direction, a sample count of at least 2, a positive memory
    /// limit, and the topology's boundary conditions. The error names the option.
    pub fn validate(&self) -> Result<()> {
        self.fit.validate()?;
        let tol = self.nonlinear.tol;
        if !(tol.is_finite() && tol > 0.0) {
            return Err(Error::Invalid(format!(
                "the nonlinear tolerance (tol) must be positive and finite, got {tol}"
            )));
        }
        let l = &self.levels;
        if !(l.growth >= 1.0 && l.growth.is_finite()) {
            return Err(Error::Invalid(format!("the growth factor must be finite and at least 1, got {}", l.growth)));
        }
        if l.aspect.is_nan() || l.aspect < 1.0 {
            return Err(Error::Invalid(format!("the aspect bound must be at least 1, got {}", l.aspect)));
        }
        if l.min_elements == 0 {
            return Err(Error::Invalid("min_elements must be at least 1, got 0".into()));
        }
        if self.report.sample < 2 {
            return Err(Error::Invalid(format!("the report's sample must be at least 2, got {}", self.report.sample)));
        }
        if self.max_memory == MemoryLimit::Bytes(0) {
            return Err(Error::Invalid("the memory limit (max_memory) must be positive".into()));
        }
        self.topology.validate(None)
    }
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            fit: FitOptions::default(),
            levels: LevelOptions::default(),
            nonlinear: NonlinearOptions::default(),
            operator: Operator::Scaled,
            topology: Topology::dirichlet(),
            repair: RepairOptions::default(),
            certify: CertifyOptions::default(),
            improve: None,
            kinks_local: KinksLocal::Auto,
            report: ReportOptions::default(),
            max_memory: MemoryLimit::Available,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every group is checked: the defaults pass, and one bad value in the fit, the
    /// levels, the nonlinear iteration, the report or the memory limit is refused with a
    /// message naming the option.
    #[test]
    fn validate_checks_every_group() {
        assert!(SolveOptions::default().validate().is_ok());
        type Edit = fn(&mut SolveOptions);
        let cases: [(&str, Edit); 8] = [
            ("fit tolerance", |o| o.fit.tol = 1.5),
            ("nonlinear tolerance", |o| o.nonlinear.tol = f64::NAN),
            ("growth", |o| o.levels.growth = 0.5),
            ("growth", |o| o.levels.growth = f64::INFINITY),
            ("aspect", |o| o.levels.aspect = 0.9),
            ("min_elements", |o| o.levels.min_elements = 0),
            ("sample", |o| o.report.sample = 1),
            ("max_memory", |o| o.max_memory = MemoryLimit::Bytes(0)),
        ];
        for (what, edit) in cases {
            let mut o = SolveOptions::default();
            edit(&mut o);
            let e = o.validate().expect_err(what);
            assert!(matches!(e, Error::Invalid(_)) && e.to_string().contains(what), "{what}: {e}");
        }
        // the edges of the accepted ranges
        let mut o = SolveOptions::default();
        (o.levels.growth, o.levels.aspect, o.levels.min_elements, o.report.sample) = (1.0, 1.0, 1, 2);
        assert!(o.validate().is_ok());
    }

    /// `auto` moves all control points up to the threshold and a few spans around each
    /// kink above it; the spelled-out choices are taken as given.
    #[test]
    fn kinks_local_choices() {
        assert_eq!(KinksLocal::Auto.spans(KINKS_LOCAL_ABOVE), None);
        assert_eq!(KinksLocal::Auto.spans(KINKS_LOCAL_ABOVE + 1), Some(KINKS_LOCAL_SPANS));
        assert_eq!(KinksLocal::All.spans(10 * KINKS_LOCAL_ABOVE), None);
        assert_eq!(KinksLocal::Spans(2).spans(10), Some(2));
        assert_eq!(KinksLocal::parse("auto"), Some(KinksLocal::Auto));
        assert_eq!(KinksLocal::parse("all"), Some(KinksLocal::All));
        assert_eq!(KinksLocal::parse("4"), Some(KinksLocal::Spans(4)));
        assert_eq!(KinksLocal::parse("-1"), None);
        assert_eq!(KinksLocal::parse("some"), None);
    }
}
