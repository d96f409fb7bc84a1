//! The options of a complete solve: fit, nonlinear iteration, operator, levels,
//! repair, certificate, topology.

use crate::boundary::fit::FitOptions;
use crate::discrete::assembly::Operator;
use crate::discrete::topology::Topology;
use crate::verify::certificate::CertifyOptions;

use super::improve::Improve;
use super::newton::NonlinearOptions;

/// Options of a complete solve.
#[derive(Debug, Clone)]
pub struct SolveOptions {
    /// Contour fitting (degree, tolerance).
    pub fit: FitOptions,
    /// Nonlinear iteration on every level.
    pub nonlinear: NonlinearOptions,
    /// Operator of eq. (8), plain or scaled.
    pub operator: Operator,
    /// The finest level has at least this many elements per direction.
    pub min_elements: usize,
    /// Extra uniform halvings of the finest level.
    pub refine: usize,
    /// Solve at most this many levels (the finest is always solved).
    pub max_levels: Option<usize>,
    /// Basis growth factor between solved levels (the paper advises 4).
    pub growth: f64,
    /// Largest mean physical aspect ratio of the elements; the coarser direction of a
    /// level is halved until it is met (see [`prepare_levels`](super::levels::prepare_levels)).
    pub aspect: f64,
    /// `det J` is sampled on an `(n+1)^2` grid for the report.
    pub sample: usize,
    /// Rounds of defect correction (paper §8.2): while the certificate of the finest
    /// map says folded or undecided, refine around the offending elements and solve
    /// again, at most this many times. Default 6: the folds next to the necks of puzzle
    /// tabs in the hard corpus (`boundary::families`) need four rounds, and the
    /// offending-element count is not monotone from round to round (54, 74, 77, 46, then
    /// certified), so no earlier stopping rule is safe; inputs that certify sooner never
    /// see the difference.
    pub repair: usize,
    /// Spans around each offending element that a repair round also bisects.
    pub repair_halo: usize,
    /// When set, a repair round solves only for the control points whose support meets
    /// the offending elements widened by this many spans; the others keep the values of
    /// the prolonged map (paper §8.2: fewer unknowns).
    pub repair_freeze: Option<usize>,
    /// Options of the bijectivity certificate.
    pub certify: CertifyOptions,
    /// Run the grid-quality benchmark Q(x) of §10 on the final map.
    pub poisson: bool,
    /// The boundary condition of each side of the patch (four Dirichlet sides by
    /// default; see [`Topology`]).
    pub topology: Topology,
    /// After the solve and its certificate, improve the map on the same basis (e.g.
    /// minimize the Winslow functional, eq. 16) and certify again; the improved map is
    /// kept only when certified ([`crate::solve::improve`]).
    pub improve: Option<Improve>,
    /// With kinks kept (§9): the final Winslow minimisation of the `C^0` route moves only
    /// the control points whose support meets a square of this many knot spans of `Σ⁰`
    /// around each kink (paper §9, last paragraph); the others keep the elasticity start.
    /// `None`: all interior control points.
    pub kinks_local: Option<usize>,
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            fit: FitOptions::default(),
            nonlinear: NonlinearOptions::default(),
            operator: Operator::Scaled,
            min_elements: 8,
            refine: 0,
            max_levels: None,
            growth: 4.0,
            aspect: 2.0,
            sample: 200,
            repair: 6,
            repair_halo: 1,
            repair_freeze: None,
            certify: CertifyOptions::default(),
            poisson: false,
            topology: Topology::dirichlet(),
            improve: None,
            kinks_local: None,
        }
    }
}
