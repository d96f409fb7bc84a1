//! `winslow`: the headless command-line front end. Everything the library does, from a
//! shell: inspect a boundary, solve for a map, draw it, and benchmark the solver.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use winslow::boundary::fit::FitOptions;
use winslow::boundary::hierarchy::build_hierarchy;
use winslow::boundary::reparam::{Fill, Reparam, ReparamOptions};
use winslow::boundary::{BasisChoice, KinkMode};
use winslow::discrete::assembly::Operator;
use winslow::io::picture::{render, render_layout, PictureOptions};
use winslow::io::{checked_boundary, Document, Output, ReadOptions};
use winslow::linalg::linsolve::LinearMethod;
use winslow::methods::egg::{EggAssembler, EggMethod};
use winslow::methods::Method;
use winslow::solve::improve::{improve, Improve};
use winslow::solve::newton::NonlinearMethod;
use winslow::solve::options::{KinksLocal, SolveOptions};
use winslow::solve::report::{Solution, Verdict};
use winslow::solve::solver::Event;
use winslow::verify::certificate::{certify, CertifyOptions, Verdict as CertVerdict};
use winslow::verify::quality::{boundary_deviation, quality};
use winslow::{Boundary, Side, Surface};
use winslow_gpu::{Backend, Precision, Selected};

mod check_cmd;
mod compare_cmd;
mod convert_cmd;
mod corpus;
mod files;
mod inspect_ring;
mod loft_cmd;
mod mesh;
mod multipatch_cmd;
mod optimise_cmd;
mod output;
mod reference;
mod solve_cmd;
mod sweep_cmd;

#[derive(Parser, Debug)]
#[command(
    name = "winslow",
    version,
    about = "Bijective spline maps of the unit square from a planar boundary (elliptic grid generation in IGA)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print sides, degrees, knots, corner angles, orientation and fit tolerance per side.
    #[command(after_help = "Example:\n  winslow inspect tests/data/wavy_lid.json")]
    Inspect(InspectArgs),
    /// Solve the EGG equations for a boundary and write the map (with a report).
    #[command(
        after_help = "Example:\n  winslow solve tests/data/wavy_lid.json -o out/wavy_lid.json --png out/wavy_lid.png"
    )]
    Solve(Box<SolveArgs>),
    /// Draw a map, a ring map or a multipatch result as a PNG (grid lines coloured by det J).
    #[command(
        after_help = "Example (a map written by `winslow solve`):\n  winslow render out/wavy_lid.json --png out/wavy_lid-render.png"
    )]
    Render(RenderArgs),
    /// Run the solver on a list of geometries and sizes and print a table.
    #[command(
        after_help = "Example:\n  winslow bench tests/data/wavy_lid.json tests/data/quarter_annulus.json --refinements 0,1"
    )]
    Bench(BenchArgs),
    /// Classical meshes from a map (paper §11.3): structured with clustering and
    /// boundary layers, or unstructured triangulations; linear or curved; written as
    /// Gmsh, VTU, SU2, PLOT3D or OpenFOAM, with a quality table.
    #[command(
        after_help = "Example (a map written by `winslow solve`):\n  winslow mesh out/wavy_lid.json -o out/wavy_lid.msh --structured 65x33 --cluster eta:arctan:6"
    )]
    Mesh(mesh::MeshArgs),
    /// Certify a map's bijectivity (exact Bernstein bounds of det J) and measure its
    /// quality; optionally its boundary deviation and the Poisson benchmark Q(x).
    #[command(
        after_help = "Example (a map written by `winslow solve`):\n  winslow check out/wavy_lid.json --boundary tests/data/wavy_lid.json --poisson"
    )]
    Check(check_cmd::CheckArgs),
    /// Write a map (JSON, G+Smo XML or IGES) in another format, chosen by the output's
    /// extension: .json, .xml (G+Smo), .igs/.iges (IGES 5.3 entity 128), .vtu (exact
    /// Bézier cells), .vtk (sampled structured grid); a multipatch result as .json, .xml
    /// or .vtm; a volume as .json, .xml, .vtu or .vtk. The map is certified again.
    #[command(
        after_help = "Example (a map written by `winslow solve`):\n  winslow convert out/wavy_lid.json -o out/wavy_lid.xml"
    )]
    Convert(ConvertArgs),
    /// The hard corpus: seeded families of difficult domains (narrow clearances, spirals,
    /// sharp corners, puzzle tabs, thin strips, CAD sides, noisy and sparse clouds);
    /// write them, and with --solve solve each and print a table per family.
    #[command(after_help = "Example:\n  winslow corpus -o out/corpus --per-family 1 --families spiral,strip --solve")]
    Corpus(corpus::CorpusArgs),
    /// The sliding O-grid (paper §11.1): a ring whose inner contour turns by a fixed
    /// angle per step, one certified map per frame from extrapolated initial guesses.
    #[command(
        after_help = "Example:\n  winslow sweep tests/data/rings/eccentric_annulus.json --rotate-inner 5 --steps 8 -o out/sweep"
    )]
    Sweep(Box<sweep_cmd::SweepArgs>),
    /// Volumes from planar slices (paper §11.1, Fig. 23): one basis, linear or C2 cubic
    /// in z, certified (trivariate det J), slices inserted where it is not.
    #[command(
        after_help = "Example (the frames of the `winslow sweep` example):\n  winslow loft out/sweep/frame_0000.json out/sweep/frame_0004.json out/sweep/frame_0008.json --dz 0.1 -o out/volume.json"
    )]
    Loft(Box<loft_cmd::LoftArgs>),
    /// Constrained quality optimisation (paper §10.3, Gravesen et al.): minimise the Liao,
    /// Winslow or area-orthogonality functional subject to positive Bernstein coefficients
    /// of det J, from the EGG map or from the max-z point of eq. (49); or eq. (49) alone.
    #[command(
        after_help = "Example:\n  winslow optimise tests/data/quarter_annulus.json --functional liao --from egg --fit-tol 1e-2 -o out/qa-liao.json"
    )]
    Optimise(Box<optimise_cmd::OptimiseArgs>),
    /// The methods of paper §10 on one basis: EGG, the variational harmonic method
    /// (eq. 46), the quasi-conformal functional (eq. 47-48) and, on request, Gravesen's
    /// max-z (eq. 49) and constrained Liao, Winslow and area-orthogonality optimisations
    /// from the EGG map; iterations, the certificate's verdict, Q(x)/Q(x_G), Winslow, Liao, area orthogonality, min scaled
    /// Jacobian and time per method.
    #[command(after_help = "Example:\n  winslow compare tests/data/quarter_annulus.json --methods egg,vhm,qc")]
    Compare(Box<compare_cmd::CompareArgs>),
    /// Split a certified map's domain into two four-sided patches sharing a curve between
    /// points on opposite sides (paper §11.2, Fig. 25); `winslow solve` takes the result.
    #[command(
        after_help = "Example (a map written by `winslow solve`):\n  winslow split out/wavy_lid.json --from south:0.45 --to north:0.55 -o out/parts.json"
    )]
    Split(multipatch_cmd::SplitArgs),
    /// Join two maps sharing a whole side into one map with a C0 knot, smoothed by the
    /// weak form (eq. 14) from that bijective start (paper §11.2, Fig. 27-28).
    #[command(
        after_help = "Example (the two halves of the `winslow split` example, solved):\n  winslow solve out/parts-a.json -o out/a.json -q\n  winslow solve out/parts-b.json -o out/b.json -q\n  winslow join out/a.json out/b.json -o out/joined.json"
    )]
    Join(multipatch_cmd::JoinArgs),
    /// Print the command-line reference (docs/cli.md) generated from these definitions.
    #[command(hide = true)]
    Reference,
}

#[derive(Args, Debug)]
struct ConvertArgs {
    /// Map file (JSON map document, G+Smo XML or IGES), multipatch result or volume.
    map: PathBuf,
    /// Output file; the format follows its extension.
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Args, Debug, Clone)]
struct FitArgs {
    /// Spline degree of the map (p >= 2).
    #[arg(long, default_value_t = 3)]
    degree: usize,
    /// Contour fit tolerance, relative to the bounding-box diameter.
    #[arg(long, default_value_t = 1e-4)]
    fit_tol: f64,
    /// Turn a clockwise boundary counter-clockwise (swaps xi and eta) instead of failing.
    #[arg(long)]
    reorient: bool,
    /// Boundary reparameterization (paper §7): auto = constrained cord length on
    /// opposite sides closer than --reparam-gap times their length, none elsewhere; for a
    /// ring: arc length, with facing points of a narrow gap (closer than --reparam-gap
    /// times the diameter) matched at the same eta (arclength/none: never matched).
    #[arg(long, value_enum, default_value = "auto")]
    reparam: Reparam,
    /// Narrow-gap threshold (auto) and matching distance (constrained), relative to the
    /// mean length of the two opposite sides (for a ring: the outer contour's diameter).
    #[arg(long, default_value_t = ReparamOptions::default().gap)]
    reparam_gap: f64,
    /// Minimum separation of two matched pairs, in cord length of each side.
    #[arg(long, default_value_t = ReparamOptions::default().separation)]
    reparam_separation: f64,
    /// How unmatched parameters are filled: cord length between matches (eq. 41-42) or a
    /// Fritsch-Carlson monotone cubic.
    #[arg(long, value_enum, default_value = "cord-length")]
    reparam_fill: Fill,
    /// Basis of the map: `auto` (the default: the input's own basis, boundary kept
    /// exactly, when its map is certified; else solved again on the fitted basis, with the
    /// reason in the report), `fitted` (dyadic C^{p-1} fits of the sides within --fit-tol,
    /// which with --degree applies to fitted bases only) or `input` (the B-spline or NURBS
    /// sides' own basis whatever the verdict; falls back to `fitted` with a message for
    /// point clouds, analytic sides and C0 knots).
    #[arg(long, value_enum, default_value = "auto")]
    basis: BasisChoice,
    /// Kinks inside the sides kept exactly (paper §9): `auto` (spline sides' C0 knots and
    /// zero-speed knots turning more than 1 degree, point clouds' corners turning 30 degrees
    /// or more), `none` (rounded by the C^{p-1} fit and reported; on the input basis a C0
    /// knot then falls back to fitted) or an angle in degrees (every kink turning at least
    /// that much). A kept kink gets a knot line of multiplicity p; EGG is solved on the
    /// smoothed basis, the map moved to the kinked boundary by damped elasticity and
    /// finished by the Winslow functional (16).
    #[arg(long, default_value_t = FitOptions::default().kinks, value_parser = parse_kinks)]
    kinks: KinkMode,
}

fn parse_kinks_local(s: &str) -> std::result::Result<KinksLocal, String> {
    KinksLocal::parse(s).ok_or_else(|| format!("expected auto, all or a number of knot spans, got '{s}'"))
}

/// `A1,A2`: the two positive length scales of the Poisson benchmark's `u*` (§10).
fn parse_scales(s: &str) -> std::result::Result<[f64; 2], String> {
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

fn parse_kinks(s: &str) -> std::result::Result<KinkMode, String> {
    KinkMode::parse(s).ok_or_else(|| format!("expected auto, none or an angle in (0, 180] degrees, got '{s}'"))
}

#[derive(Args, Debug)]
struct InspectArgs {
    /// Boundary file (JSON boundary, contour or map document; G+Smo XML).
    file: PathBuf,
    #[command(flatten)]
    fit: FitArgs,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
enum MethodArg {
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
enum PrecisionArg {
    Auto,
    F64,
    F32,
}

/// Where the quadrature runs.
#[derive(Args, Debug, Clone)]
struct BackendArgs {
    /// Quadrature back end: the CPU; a GPU through wgpu (any adapter, lavapipe included;
    /// none is an error); or auto (a hardware GPU with f64 shaders, else the CPU).
    #[arg(long, value_enum, default_value = "cpu")]
    backend: Backend,
    /// GPU precision: f64 where the adapter offers it, else f32 matrices with the
    /// residual in f64 on the CPU; or forced.
    #[arg(long, value_enum, default_value = "auto")]
    precision: PrecisionArg,
}

impl BackendArgs {
    /// Open the back end and say which one runs (stderr unless `quiet`).
    fn select(&self, quiet: bool) -> Result<Selected> {
        let precision = match self.precision {
            PrecisionArg::Auto => None,
            PrecisionArg::F64 => Some(Precision::F64),
            PrecisionArg::F32 => Some(Precision::F32),
        };
        let sel = winslow_gpu::assembler(self.backend, precision).context("opening the GPU")?;
        if !quiet {
            eprintln!("backend: {}", sel.describe());
        }
        Ok(sel)
    }
}

/// The picture of `map`, sampled on the GPU when one is selected.
fn picture(sel: &Selected, map: &Surface, opts: &PictureOptions) -> Result<winslow::io::picture::Image> {
    Ok(match sel.gpu() {
        Some(g) => g.render(map, opts).context("sampling det J on the GPU")?,
        None => render(map, opts),
    })
}

#[derive(Args, Debug, Clone)]
struct SolverArgs {
    #[command(flatten)]
    fit: FitArgs,
    /// Nonlinear tolerance on the scaled residual ||F|| sqrt(m) / diam^3.
    #[arg(long, default_value_t = 1e-9)]
    tol: f64,
    /// Solve at most this many levels of the hierarchy (the finest is always solved).
    #[arg(long)]
    levels: Option<usize>,
    /// Minimum number of elements per direction on the finest level.
    #[arg(long, default_value_t = 8)]
    min_elements: usize,
    /// Extra uniform halvings of the finest level.
    #[arg(long, default_value_t = 0)]
    refine: usize,
    /// Basis growth factor between solved levels (1 solves every level of the hierarchy).
    #[arg(long, default_value_t = SolveOptions::default().growth)]
    growth: f64,
    /// Nonlinear iteration (Newton falls back to pseudo time-stepping when it stalls).
    #[arg(long, value_enum, default_value = "newton")]
    iteration: NonlinearMethod,
    /// Method: egg (eq. 8) from the boundary; weak (eq. 14) or winslow (eq. 16) from a
    /// certified map: the EGG map of the boundary (same as `--improve`), or the map of
    /// `--start`. (`--method newton|pseudo-time` is the old spelling of `--iteration`.)
    #[arg(long, value_enum, default_value = "egg")]
    method: MethodArg,
    /// Operator: L of eq. (4), or L / (g11 + g22) as in G+Smo (converges better on the
    /// shared geometries, see BENCHMARKS.md).
    #[arg(long, value_enum, default_value = "scaled")]
    operator: Operator,
    /// Linear solver: sparse LU, GMRES (preconditioned by the metric Laplacian), or auto (LU up to 64 unknowns, GMRES above, LU again when GMRES needs 500 iterations).
    #[arg(long, value_enum, default_value = "auto")]
    linear: LinearMethod,
    /// Rounds of defect correction: while the certificate says folded or undecided,
    /// refine around the offending elements and solve again, at most this often.
    #[arg(long, default_value_t = SolveOptions::default().repair)]
    repair: usize,
    /// Do not repair a folded map (same as --repair 0).
    #[arg(long)]
    no_repair: bool,
    /// In repair rounds, solve only for the control points within this many spans of
    /// the offending elements (the rest stay frozen at the prolonged map).
    #[arg(long)]
    repair_freeze: Option<usize>,
    /// After the solve and its certificate, improve the map on the same basis, from the
    /// certified map: minimize the Winslow functional (eq. 16) or solve the weak form
    /// (eq. 14); certify again and keep the improved map only when it is certified.
    #[arg(long, value_enum)]
    improve: Option<Improve>,
    /// With kinks kept (--kinks): which control points the final Winslow minimisation of
    /// the C0 route moves: `all`, a number of knot spans around each kink (paper §9, last
    /// paragraph; the rest keep the elasticity start), or `auto` (all up to 50 000
    /// unknowns, 3 spans above).
    #[arg(long, default_value = "auto", value_parser = parse_kinks_local)]
    kinks_local: KinksLocal,
}

impl SolverArgs {
    /// The method of `--method` when it needs a bijective start.
    fn improvement_method(&self) -> Option<Improve> {
        match self.method {
            MethodArg::Weak => Some(Improve::WeakForm),
            MethodArg::Winslow => Some(Improve::Winslow),
            _ => None,
        }
    }

    fn options(&self) -> Result<SolveOptions> {
        let mut o = SolveOptions { fit: fit_options(&self.fit), ..Default::default() };
        o.nonlinear.tol = self.tol;
        o.nonlinear.method = match self.method {
            MethodArg::Newton => NonlinearMethod::Newton,
            MethodArg::PseudoTime => NonlinearMethod::PseudoTime,
            MethodArg::Egg | MethodArg::Weak | MethodArg::Winslow => self.iteration,
        };
        o.nonlinear.linear = self.linear;
        o.repair = if self.no_repair { 0 } else { self.repair };
        o.repair_freeze = self.repair_freeze;
        o.operator = self.operator;
        o.max_levels = self.levels;
        o.min_elements = self.min_elements.max(1);
        o.refine = self.refine;
        o.growth = self.growth.max(1.0);
        o.kinks_local = self.kinks_local;
        o.improve = self.improve;
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

fn fit_options(f: &FitArgs) -> FitOptions {
    let reparam = ReparamOptions {
        method: f.reparam,
        gap: f.reparam_gap,
        separation: f.reparam_separation,
        fill: f.reparam_fill,
        ..Default::default()
    };
    FitOptions { degree: f.degree, tol: f.fit_tol, reparam, basis: f.basis, kinks: f.kinks, ..Default::default() }
}

#[derive(Args, Debug)]
struct SolveArgs {
    /// Boundary file (with `--start`: optional, the map's boundary deviation from it is
    /// reported).
    #[arg(required_unless_present = "start")]
    boundary: Option<PathBuf>,
    /// Start from this map document (made by `winslow solve` or another tool) instead of
    /// solving from the boundary: the certificate must prove it bijective, its boundary
    /// control points stay fixed, `--method` (winslow, weak or egg) runs on its basis,
    /// and the result is kept only when certified.
    #[arg(long)]
    start: Option<PathBuf>,
    /// Output map file: JSON with a "report" (default), or by extension G+Smo XML
    /// (.xml), IGES (.igs, .iges), VTK Bézier cells (.vtu) or a sampled VTK grid (.vtk).
    /// A multipatch input (G+Smo `<MultiPatch>` or a JSON document with "patches") is
    /// written as a JSON multipatch document or G+Smo XML (.xml).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    solver: SolverArgs,
    /// Write a picture of the map (grid lines coloured by det J; the matched pairs of
    /// the constrained reparameterization drawn as segments).
    #[arg(long)]
    png: Option<PathBuf>,
    /// Do not draw the matched pairs into the PNG.
    #[arg(long)]
    no_png_matches: bool,
    /// Write a VTK structured grid with det J.
    #[arg(long)]
    vtk: Option<PathBuf>,
    /// Also write the map as G+Smo XML (TensorBSpline2 / TensorNurbs2).
    #[arg(long)]
    gismo: Option<PathBuf>,
    /// Also write the map as IGES 5.3 (rational B-spline surface, entity 128).
    #[arg(long)]
    iges: Option<PathBuf>,
    /// Also write the exact map as VTK Bézier quadrilaterals (.vtu, det J as point data).
    #[arg(long)]
    vtu: Option<PathBuf>,
    /// Print the report as JSON on stdout (progress goes to stderr).
    #[arg(long)]
    json: bool,
    /// Also solve the grid-quality benchmark (paper eq. 44-45) on the map; Q(x) goes
    /// into the report.
    #[arg(long)]
    poisson: bool,
    /// No progress output.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    backend: BackendArgs,
    /// Also write a mesh of the solved map (same options as `winslow mesh`): .msh,
    /// .su2, .xyz, .vtu or a directory (OpenFOAM).
    #[arg(long, value_name = "OUT")]
    mesh: Option<PathBuf>,
    #[command(flatten)]
    mesh_spec: mesh::MeshSpec,
    #[command(flatten)]
    multipatch: multipatch_cmd::MultipatchArgs,
}

#[derive(Args, Debug)]
struct RenderArgs {
    /// Map file (a ring map or a multipatch result too).
    map: PathBuf,
    /// Output PNG.
    #[arg(long)]
    png: PathBuf,
    /// Iso-lines per direction.
    #[arg(long, default_value_t = 24)]
    lines: usize,
    /// Longer image side in pixels.
    #[arg(long, default_value_t = 900)]
    size: usize,
    #[command(flatten)]
    backend: BackendArgs,
    /// Do not draw the matched pairs of the reparameterization stored in the report.
    #[arg(long)]
    no_matches: bool,
}

#[derive(Args, Debug)]
struct BenchArgs {
    /// Boundary files (default: every JSON geometry in tests/data and tests/data/gismo).
    files: Vec<PathBuf>,
    /// Extra uniform halvings of the finest level to run, comma-separated (one table row
    /// per geometry and value).
    #[arg(long, value_delimiter = ',', default_value = "0")]
    refinements: Vec<usize>,
    #[command(flatten)]
    solver: SolverArgs,
    /// Print the rows as JSON lines instead of a table.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    backend: BackendArgs,
    /// Quadrature throughput (residual and Jacobian, CPU versus the selected back end)
    /// at these sizes in scalar DOFs, comma-separated. With a GPU and no FILES this
    /// table alone is printed, by default at 1e3, 1e4, 1e5 and 1e6 DOFs (1e6 left out on
    /// a software adapter such as lavapipe).
    #[arg(long, value_delimiter = ',')]
    sizes: Vec<usize>,
    /// Degree of the quadrature benchmark's basis.
    #[arg(long, default_value_t = 3)]
    bench_degree: usize,
    /// GPU Jacobian kernel of the quadrature benchmark: element matrices (one workgroup
    /// per element, then a gather; the solver's) or one invocation per stencil entry.
    #[arg(long, value_enum, default_value = "element")]
    gpu_kernel: KernelArg,
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
enum KernelArg {
    Element,
    Entry,
}

fn main() {
    let cli = Cli::parse();
    // the command runs on a worker of the thread pool, started with the process: a
    // parallel loop then splits off work for the other workers instead of handing the
    // whole loop to the pool and blocking until a sleeping worker has woken and run it
    // (tens of microseconds per loop, most of the solve of a tiny map); the workers get
    // the main thread's stack size
    let pool = rayon::ThreadPoolBuilder::new().stack_size(16 << 20).build();
    let result = match pool {
        Ok(pool) => pool.install(|| run(cli)),
        Err(_) => run(cli),
    };
    let code = match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            1
        }
    };
    std::process::exit(code);
}

fn run(cli: Cli) -> Result<i32> {
    match cli.command {
        Command::Inspect(a) => inspect(a),
        Command::Solve(a) => solve_cmd::solve(*a),
        Command::Render(a) => convert_cmd::render(a),
        Command::Bench(a) => bench(a),
        Command::Check(a) => check_cmd::check(a),
        Command::Convert(a) => convert_cmd::convert(a),
        Command::Mesh(a) => mesh::run(a),
        Command::Corpus(a) => corpus::run(a),
        Command::Sweep(a) => sweep_cmd::run(*a),
        Command::Loft(a) => loft_cmd::run(*a),
        Command::Optimise(a) => optimise_cmd::run(*a),
        Command::Compare(a) => compare_cmd::run(*a),
        Command::Split(a) => multipatch_cmd::split(a),
        Command::Join(a) => multipatch_cmd::join(a),
        Command::Reference => {
            print!("{}", reference::markdown(<Cli as clap::CommandFactory>::command()));
            Ok(0)
        }
    }
}

fn load_boundary(path: &Path, reorient: bool) -> Result<Boundary> {
    let b = files::boundary_of(files::read(path)?, path)?;
    let (b, _) =
        checked_boundary(b, &ReadOptions { reorient }).with_context(|| format!("validating {}", path.display()))?;
    Ok(b)
}

fn inspect(a: InspectArgs) -> Result<i32> {
    let doc = files::read(&a.file)?;
    let kind = match &doc {
        Document::Ring(ring) => return inspect_ring::run(&a.file, ring, &fit_options(&a.fit), a.json),
        Document::Boundary(_) => "boundary",
        _ => "map (its four boundary curves are inspected)",
    };
    let boundary = files::boundary_of(doc, &a.file)?;
    let mut problems = Vec::new();
    let checked = checked_boundary(boundary.clone(), &ReadOptions { reorient: a.fit.reorient });
    let (boundary, report) = match checked {
        Ok((b, r)) => (b, Some(r)),
        Err(e) => {
            problems.push(e.to_string());
            (boundary, None)
        }
    };
    let fit = if problems.is_empty() { Some(build_hierarchy(&boundary, &fit_options(&a.fit))) } else { None };
    let fit = match fit {
        Some(Ok(h)) => Some(h),
        Some(Err(e)) => {
            problems.push(format!("contour fit failed: {e}"));
            None
        }
        None => None,
    };
    let text = output::inspect_text(&a.file, kind, &boundary, report.as_ref(), fit.as_ref(), &problems);
    if a.json {
        let v = output::inspect_json(&boundary, report.as_ref(), fit.as_ref(), &problems);
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print!("{text}");
    }
    Ok(if problems.is_empty() { 0 } else { 2 })
}

fn bench(a: BenchArgs) -> Result<i32> {
    let opts = a.solver.options()?;
    let sel = a.backend.select(a.json)?;
    let sizes = match sel.gpu() {
        _ if !a.sizes.is_empty() || !a.files.is_empty() => a.sizes.clone(),
        // 10^6 takes many minutes on a software adapter (lavapipe): ask for it explicitly
        Some(g) if g.is_software() => {
            eprintln!("note: software adapter, sizes 1e3..1e5 (pass --sizes 1000000 for 1e6)");
            vec![1_000, 10_000, 100_000]
        }
        Some(_) => vec![1_000, 10_000, 100_000, 1_000_000],
        None => Vec::new(),
    };
    if !sizes.is_empty() {
        quadrature_bench(&sel, &sizes, a.bench_degree, opts.operator, a.gpu_kernel == KernelArg::Entry, a.json)?;
        if a.files.is_empty() {
            return Ok(0);
        }
    }
    let files = if a.files.is_empty() { output::default_bench_files()? } else { a.files.clone() };
    let mut rows = Vec::new();
    for f in &files {
        let boundary = match load_boundary(f, a.solver.fit.reorient) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("skipping {}: {e:#}", f.display());
                continue;
            }
        };
        for &r in &a.refinements {
            let o = SolveOptions { refine: r, ..opts.clone() };
            output::reset_peak_memory();
            let t = Instant::now();
            let sol = solve_cmd::run_pipeline(boundary.clone(), &o, sel.as_assembler(), true)?;
            let total = t.elapsed().as_secs_f64();
            let row = output::BenchRow::new(&sol, r, total);
            if a.json {
                println!("{}", serde_json::to_string(&row)?);
            }
            rows.push(row);
        }
    }
    if !a.json {
        print!("{}", output::bench_table(&rows));
    }
    Ok(0)
}

/// Quadrature throughput at the given sizes, CPU versus the selected GPU.
fn quadrature_bench(
    sel: &Selected,
    sizes: &[usize],
    degree: usize,
    op: Operator,
    per_entry: bool,
    json: bool,
) -> Result<()> {
    if !(2..=8).contains(&degree) {
        bail!("--bench-degree must be in 2..=8, got {degree}");
    }
    let gpu = sel.gpu().map(|g| winslow_gpu::GpuAssembler::new(g.clone()).with_per_entry_jacobian(per_entry));
    let gpu = gpu.as_ref();
    let mut rows = Vec::new();
    for &dofs in sizes {
        let (disc, cps) = winslow_gpu::bench::quadrature_case(dofs, degree);
        let row = winslow_gpu::bench::measure(&disc, &cps, op, gpu, 1.0).context("GPU quadrature")?;
        if json {
            println!("{}", serde_json::to_string(&row)?);
        } else {
            eprintln!("  {} DOFs done", row.dofs);
        }
        rows.push(row);
    }
    if !json {
        print!("{}", output::quadrature_table(&sel.describe(), &rows));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn cli_definition_is_consistent() {
        Cli::command().debug_assert();
    }
}
