//! The argument groups shared by the commands: the fit, the solver, the back end.

use super::*;

#[derive(Args, Debug, Clone)]
pub(crate) struct FitArgs {
    /// Spline degree of the map (p >= 2).
    #[arg(long, default_value_t = 3)]
    pub(crate) degree: usize,
    /// Contour fit tolerance, relative to the bounding-box diameter.
    #[arg(long, default_value_t = 1e-4)]
    pub(crate) fit_tol: f64,
    /// Turn a clockwise boundary counter-clockwise (swaps xi and eta) instead of failing.
    #[arg(long)]
    pub(crate) reorient: bool,
    /// Boundary reparameterization (paper §7): auto = constrained cord length on
    /// opposite sides closer than --reparam-gap times their length, none elsewhere; for a
    /// ring: arc length, with facing points of a narrow gap (closer than --reparam-gap
    /// times the diameter) matched at the same eta (arclength/none: never matched).
    #[arg(long, value_enum, default_value = "auto")]
    pub(crate) reparam: Reparam,
    /// Narrow-gap threshold (auto) and matching distance (constrained), relative to the
    /// mean length of the two opposite sides (for a ring: the outer contour's diameter).
    #[arg(long, default_value_t = ReparamOptions::default().gap)]
    pub(crate) reparam_gap: f64,
    /// Minimum separation of two matched pairs, in cord length of each side.
    #[arg(long, default_value_t = ReparamOptions::default().separation)]
    pub(crate) reparam_separation: f64,
    /// How unmatched parameters are filled: cord length between matches (eq. 41-42) or a
    /// Fritsch-Carlson monotone cubic.
    #[arg(long, value_enum, default_value = "cord-length")]
    pub(crate) reparam_fill: Fill,
    /// Basis of the map: `auto` (the default: the input's own basis, boundary kept
    /// exactly, when its map is certified; else solved again on the fitted basis, with the
    /// reason in the report), `fitted` (dyadic C^{p-1} fits of the sides within --fit-tol,
    /// which with --degree applies to fitted bases only) or `input` (the B-spline or NURBS
    /// sides' own basis whatever the verdict; falls back to `fitted` with a message for
    /// point clouds, analytic sides and C0 knots).
    #[arg(long, value_enum, default_value = "auto")]
    pub(crate) basis: BasisChoice,
    /// Kinks inside the sides kept exactly (paper §9): `auto` (spline sides' C0 knots and
    /// zero-speed knots turning more than 1 degree, point clouds' corners turning 30 degrees
    /// or more), `none` (rounded by the C^{p-1} fit and reported; on the input basis a C0
    /// knot then falls back to fitted) or an angle in degrees (every kink turning at least
    /// that much). A kept kink gets a knot line of multiplicity p; EGG is solved on the
    /// smoothed basis, the map moved to the kinked boundary by damped elasticity and
    /// finished by the Winslow functional (16).
    #[arg(long, default_value_t = FitOptions::default().kinks, value_parser = parse_kinks)]
    pub(crate) kinks: KinkMode,
}

pub(crate) fn parse_kinks_local(s: &str) -> std::result::Result<KinksLocal, String> {
    KinksLocal::parse(s).ok_or_else(|| format!("expected auto, all or a number of knot spans, got '{s}'"))
}

/// `A1,A2`: the two positive length scales of the Poisson benchmark's `u*` (§10).
pub(crate) fn parse_scales(s: &str) -> std::result::Result<[f64; 2], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| format!("expected A1,A2 (two numbers), got '{s}': {e}"))?;
    match v[..] {
        [a, b] if a.is_finite() && a > 0.0 && b.is_finite() && b > 0.0 => Ok([a, b]),
        _ => Err(format!("expected A1,A2 (two positive numbers), got '{s}'")),
    }
}

pub(crate) fn parse_kinks(s: &str) -> std::result::Result<KinkMode, String> {
    KinkMode::parse(s).ok_or_else(|| format!("expected auto, none or an angle in (0, 180] degrees, got '{s}'"))
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MethodArg {
    /// Elliptic grid generation, eq. (8): from the boundary (or from --start).
    Egg,
    /// The weak form, eq. (14), from a certified map (the EGG map, or --start).
    Weak,
    /// Minimize the Winslow functional, eq. (16), from a certified map (the EGG map, or
    /// --start).
    Winslow,
    /// Old spelling of `--iteration newton`.
    #[value(hide = true)]
    Newton,
    /// Old spelling of `--iteration pseudo-time`.
    #[value(hide = true)]
    PseudoTime,
}

#[derive(ValueEnum, Debug, Clone, Copy)]
pub(crate) enum PrecisionArg {
    Auto,
    F64,
    F32,
}

/// Where the GPU assembles the Newton Jacobian that GMRES multiplies with.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum GpuJacobianArg {
    /// Rounded into the product's buffers on the device: it never crosses the bus.
    Device,
    /// Read back, packed on the host and uploaded again (the earlier path).
    Host,
}

/// Where the quadrature runs.
#[derive(Args, Debug, Clone)]
pub(crate) struct BackendArgs {
    /// Quadrature back end: the CPU; a GPU through wgpu (any adapter, lavapipe included;
    /// none is an error); or auto (a hardware GPU with f64 shaders, else the CPU).
    #[arg(long, value_enum, default_value = "cpu")]
    pub(crate) backend: Backend,
    /// GPU precision: f64 where the adapter offers it, else f32 matrices with the
    /// residual in f64 on the CPU; or forced.
    #[arg(long, value_enum, default_value = "auto")]
    pub(crate) precision: PrecisionArg,
    /// With `--backend gpu --linear multigrid`: the Newton Jacobian assembled on the
    /// device into the product's buffers (the default), or read back, packed on the host
    /// and uploaded again (`host`: to measure what the bus carried before; the map is the
    /// same). `report.backend` counts the bytes either way.
    #[arg(long, value_enum, default_value = "device")]
    pub(crate) gpu_jacobian: GpuJacobianArg,
}

impl BackendArgs {
    /// Open the back end and say which one runs (stderr unless `quiet`).
    pub(crate) fn select(&self, quiet: bool) -> Result<Selected> {
        let precision = match self.precision {
            PrecisionArg::Auto => None,
            PrecisionArg::F64 => Some(Precision::F64),
            PrecisionArg::F32 => Some(Precision::F32),
        };
        let sel = winslow_gpu::assembler(self.backend, precision).context("opening the GPU")?;
        if let Selected::Gpu(g) = &sel {
            g.set_device_jacobian(self.gpu_jacobian == GpuJacobianArg::Device);
        }
        if !quiet {
            note!("backend: {}", sel.describe());
        }
        Ok(sel)
    }
}

/// The picture of `map`, sampled on the GPU when one is selected.
pub(crate) fn picture(sel: &Selected, map: &Surface, opts: &PictureOptions) -> Result<winslow::io::picture::Image> {
    Ok(match sel.gpu() {
        Some(g) => g.render(map, opts).context("sampling det J on the GPU")?,
        None => render(map, opts),
    })
}

#[derive(Args, Debug, Clone)]
pub(crate) struct SolverArgs {
    #[command(flatten)]
    pub(crate) fit: FitArgs,
    /// Nonlinear tolerance on the scaled residual ||F|| sqrt(m) / diam^3.
    #[arg(long, default_value_t = 1e-9)]
    pub(crate) tol: f64,
    /// Solve at most this many levels of the hierarchy (the finest is always solved).
    #[arg(long)]
    pub(crate) levels: Option<usize>,
    /// Minimum number of elements per direction on the finest level.
    #[arg(long, default_value_t = 8)]
    pub(crate) min_elements: usize,
    /// Extra uniform halvings of the finest level.
    #[arg(long, default_value_t = 0)]
    pub(crate) refine: usize,
    /// Basis growth factor between solved levels (1 solves every level of the hierarchy).
    #[arg(long, default_value_t = SolveOptions::default().levels.growth)]
    pub(crate) growth: f64,
    /// Nonlinear iteration (Newton falls back to pseudo time-stepping when it stalls).
    #[arg(long, value_enum, default_value = "newton")]
    pub(crate) iteration: NonlinearMethod,
    /// Method: egg (eq. 8) from the boundary; weak (eq. 14) or winslow (eq. 16) from a
    /// certified map: the EGG map of the boundary (same as `--improve`), or the map of
    /// `--start`. (`--method newton|pseudo-time` is the old spelling of `--iteration`.)
    #[arg(long, value_enum, default_value = "egg")]
    pub(crate) method: MethodArg,
    /// Operator: L of eq. (4), or L / (g11 + g22) as in G+Smo (converges better on the
    /// shared geometries, see BENCHMARKS.md).
    #[arg(long, value_enum, default_value = "scaled")]
    pub(crate) operator: Operator,
    /// Linear solver: sparse LU, GMRES (preconditioned by the metric Laplacian), auto (LU up to 64 unknowns, GMRES above, LU again when GMRES needs 500 iterations; on a patch from 800 000 unknowns on, or where the factorization would exceed --max-memory, multigrid), or multigrid (GMRES preconditioned by a multigrid V-cycle for the metric Laplacian instead of its factorization).
    #[arg(long, value_enum, default_value = "auto")]
    pub(crate) linear: LinearMethod,
    /// Rounds of defect correction: while the certificate says folded or undecided,
    /// refine around the offending elements and solve again, at most this often.
    #[arg(long, default_value_t = SolveOptions::default().repair.rounds)]
    pub(crate) repair: usize,
    /// Do not repair a folded map (same as --repair 0).
    #[arg(long)]
    pub(crate) no_repair: bool,
    /// How a repair round refines: `tensor` bisects the offending knot spans across the
    /// whole basis; `thb` refines only the offending cells and a ring around them on a
    /// THB basis, and a map it repaired is written as a THB map (-o .json or .xml; .vtu
    /// as a Bézier cell per active cell; .igs and .vtk as its exact tensor form);
    /// `auto` is `thb` where a point-cloud side has corners the cloud resolves as
    /// roundings (the report's `roundings`; docs/kinks.md) in `solve`, `tensor` elsewhere.
    #[arg(long, value_enum, default_value = "auto")]
    pub(crate) refinement: Refinement,
    /// In repair rounds, solve only for the control points within this many spans of
    /// the offending elements (the rest stay frozen at the prolonged map).
    #[arg(long)]
    pub(crate) repair_freeze: Option<usize>,
    /// After the solve and its certificate, improve the map on the same basis, from the
    /// certified map: minimize the Winslow functional (eq. 16) or solve the weak form
    /// (eq. 14); certify again and keep the improved map only when it is certified. On a
    /// multipatch layout: free interfaces with this functional (`--interfaces free`).
    #[arg(long, value_enum)]
    pub(crate) improve: Option<Improve>,
    /// With kinks kept (--kinks): which control points the final Winslow minimisation of
    /// the C0 route moves: `all`, a number of knot spans around each kink (paper §9, last
    /// paragraph; the rest keep the elasticity start), or `auto` (all up to 50 000
    /// unknowns, 3 spans above).
    #[arg(long, default_value = "auto", value_parser = parse_kinks_local)]
    pub(crate) kinks_local: KinksLocal,
    #[command(flatten)]
    pub(crate) memory: MemoryArgs,
}

/// The memory bound of a solve (every command that solves).
#[derive(Args, Debug, Clone)]
pub(crate) struct MemoryArgs {
    /// The most memory a solve may take: bytes with an optional K, M, G or T suffix
    /// (powers of 1024, e.g. 4G, 512M), `available` (the memory available when the solve
    /// starts: MemAvailable, the cgroup's limit or `ulimit -v`, whichever is least; no
    /// limit on systems other than Linux) or `none`. A solve whose estimated peak is above
    /// it is refused before it allocates, with what lowers it (docs/solve.md, "Memory").
    #[arg(long, default_value = "available", value_parser = parse_max_memory)]
    pub(crate) max_memory: MemoryLimit,
}

pub(crate) fn parse_max_memory(s: &str) -> std::result::Result<MemoryLimit, String> {
    MemoryLimit::parse(s).ok_or_else(|| format!("expected a size such as 4G or 512M, `available` or `none`, got '{s}'"))
}

impl SolverArgs {
    /// The method of `--method` when it needs a bijective start.
    pub(crate) fn improvement_method(&self) -> Option<Improve> {
        match self.method {
            MethodArg::Weak => Some(Improve::WeakForm),
            MethodArg::Winslow => Some(Improve::Winslow),
            _ => None,
        }
    }

    pub(crate) fn options(&self) -> Result<SolveOptions> {
        let mut o = SolveOptions::default();
        o.fit = fit_options(&self.fit);
        o.nonlinear.tol = self.tol;
        o.nonlinear.method = match self.method {
            MethodArg::Newton => NonlinearMethod::Newton,
            MethodArg::PseudoTime => NonlinearMethod::PseudoTime,
            MethodArg::Egg | MethodArg::Weak | MethodArg::Winslow => self.iteration,
        };
        o.nonlinear.linear = self.linear;
        o.repair.rounds = if self.no_repair { 0 } else { self.repair };
        o.repair.freeze = self.repair_freeze;
        // `auto` is `solve`'s (it may write a THB map); the other commands need tensor maps
        o.repair.refinement = self.refinement.resolved(false);
        o.operator = self.operator;
        o.levels.max_levels = self.levels;
        o.levels.min_elements = self.min_elements;
        o.levels.refine = self.refine;
        o.levels.growth = self.growth;
        o.kinks_local = self.kinks_local;
        o.improve = self.improve;
        o.max_memory = self.memory.max_memory;
        // a method that needs a bijective start runs after the EGG solve
        if let Some(m) = self.improvement_method() {
            if o.improve.is_some_and(|i| i != m) {
                bail!("--method {:?} and --improve {:?} ask for two different improvements", self.method, o.improve);
            }
            o.improve = Some(m);
        }
        o.validate()?;
        Ok(o)
    }
}

pub(crate) fn fit_options(f: &FitArgs) -> FitOptions {
    let mut o = FitOptions::default();
    o.reparam.method = f.reparam;
    o.reparam.gap = f.reparam_gap;
    o.reparam.separation = f.reparam_separation;
    o.reparam.fill = f.reparam_fill;
    (o.degree, o.tol, o.basis, o.kinks) = (f.degree, f.fit_tol, f.basis, f.kinks);
    o
}
