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
use winslow::solve::improve::Improve;
use winslow::solve::memory::MemoryLimit;
use winslow::solve::newton::NonlinearMethod;
use winslow::solve::options::{KinksLocal, Refinement, SolveOptions};
use winslow::solve::report::Verdict;
use winslow::solve::solver::Event;
use winslow::verify::certificate::{certify, CertifyOptions, Finding};
use winslow::verify::quality::quality;
use winslow::{Boundary, Side, Surface};
use winslow_gpu::{Backend, Precision, Selected};

/// `println!` unless `-q`: a command's human-readable output.
macro_rules! say {
    ($($t:tt)*) => {
        if !$crate::output::quiet() {
            println!($($t)*)
        }
    };
}

/// `print!` unless `-q`.
macro_rules! say_raw {
    ($($t:tt)*) => {
        if !$crate::output::quiet() {
            print!($($t)*)
        }
    };
}

/// `eprintln!` unless `-q`: progress, notes and warnings (errors are always printed).
macro_rules! note {
    ($($t:tt)*) => {
        if !$crate::output::quiet() {
            eprintln!($($t)*)
        }
    };
}

mod args;
mod batch_cmd;
mod bench_cmd;
mod check_cmd;
mod compare_cmd;
mod convert_cmd;
mod corpus;
mod corpus_domains;
mod domain_cmd;
mod files;
mod inspect_cmd;
mod inspect_ring;
mod loft_cmd;
mod mesh;
mod multipatch_cmd;
mod optimise_cmd;
mod output;
mod reference;
mod solve_cmd;
mod sweep_cmd;
mod thb_cmd;
mod volume_cmd;

use args::*;
use bench_cmd::*;
use convert_cmd::{ConvertArgs, RenderArgs};
use inspect_cmd::*;
use solve_cmd::SolveArgs;

#[derive(Parser, Debug)]
#[command(
    name = "winslow",
    version,
    about = "Bijective spline maps of the unit square from a planar boundary (elliptic grid generation in IGA)"
)]
struct Cli {
    /// Print nothing but errors: the exit code and the files written say the rest
    /// (`--json` output is still printed).
    #[arg(short, long, global = true)]
    quiet: bool,
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
        after_help = "Example:\n  winslow solve tests/data/wavy_lid.json -o out/wavy_lid.json --png out/wavy_lid.png\nExample (a plane graph, laid out automatically):\n  winslow solve tests/data/domains/motor12.json -o out/motor12.json -q\nExample (a volume from its six boundary faces):\n  winslow solve tests/data/volumes/twisted-duct.json -o out/twisted-duct-volume.json -q"
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
        after_help = "Example (a map written by `winslow solve`):\n  winslow mesh out/wavy_lid.json -o out/wavy_lid.msh --structured 65x33 --cluster eta:arctan:6\nExample (a multipatch result: one conforming mesh, a group per patch):\n  winslow mesh tests/data/gismo/xml/multipatch/plateWithHoleMP.xml -o out/plate.su2 --structured 17x17"
    )]
    Mesh(mesh::MeshArgs),
    /// Certify a map's bijectivity (exact Bernstein bounds of det J) and measure its
    /// quality; optionally its boundary deviation and the Poisson benchmark Q(x).
    #[command(
        after_help = "Example (a map written by `winslow solve`):\n  winslow check out/wavy_lid.json --boundary tests/data/wavy_lid.json --poisson\nExample (a THB map, certified cell by active cell):\n  winslow check tests/data/thb/sector_thb.json"
    )]
    Check(check_cmd::CheckArgs),
    /// Write a map (JSON, G+Smo XML or IGES) in another format, chosen by the output's
    /// extension: .json, .xml (G+Smo), .igs/.iges (IGES 5.3 entity 128), .vtu (exact
    /// Bézier cells), .vtk (sampled structured grid); a multipatch result as .json, .xml
    /// or .vtm; a volume as .json, .xml, .vtu or .vtk; the six faces of a volume as .json
    /// or .xml (a G+Smo multipatch). The map is certified again.
    #[command(
        after_help = "Example (a map written by `winslow solve`):\n  winslow convert out/wavy_lid.json -o out/wavy_lid.xml\nExample (a THB map to its exact tensor map):\n  winslow convert tests/data/thb/sector_thb.json -o out/sector_tensor.json\nExample (the six faces of a volume as a G+Smo multipatch):\n  winslow convert tests/data/volumes/twisted-duct.json -o out/twisted-duct-faces.xml\nExample (the outer boundary of a multipatch layout as a domain, to lay out automatically):\n  winslow convert tests/data/gismo/xml/multipatch/TUDflame.xml --outline -o out/tudflame-domain.json"
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
    /// Solve many shapes in parallel into a folder: one map per shape as it finishes, a
    /// failure record per failing shape, a summary (batch.jsonl, batch.csv); a re-run
    /// skips the shapes already solved. Exit code: 1 when a shape failed, else the worst
    /// verdict's (0 when every map is bijective).
    #[command(
        after_help = "Example:\n  winslow batch tests/data/gismo/duck.json tests/data/quarter_annulus.json -o out/batch --jobs 2"
    )]
    Batch(Box<batch_cmd::BatchArgs>),
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
    /// Lay a general planar domain (any number of corners, holes) or a plane graph out
    /// into four-sided patches automatically: cuts from holes and reflex corners, a
    /// template per face placed by a harmonic map; write the layout (which `winslow
    /// solve` takes) and draw it. `winslow solve` on the domain or graph lays it out and
    /// solves it in one go.
    #[command(after_help = "Example:
  winslow layout tests/data/domains/pentagon.json -o out/pentagon-layout.json --png out/pentagon-layout.png
  winslow layout tests/data/domains/motor12.json --png out/motor-layout.png")]
    Layout(domain_cmd::LayoutArgs),
    /// Print the command-line reference (docs/cli.md) generated from these definitions.
    #[command(hide = true)]
    Reference,
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
    // the files written: one line after the command's own output (in `--json` output
    // the field "files"), and after an error what was written before it
    let written = files::written_list();
    let code = match result {
        Ok(code) => {
            if !written.is_empty() && !files::json_printed() {
                say!("wrote: {written}");
            }
            code
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            if !written.is_empty() {
                eprintln!("written before the error: {written}");
            }
            1
        }
    };
    std::process::exit(code);
}

fn run(cli: Cli) -> Result<i32> {
    output::set_quiet(cli.quiet);
    match cli.command {
        Command::Inspect(a) => inspect_cmd::inspect(a),
        Command::Solve(a) => solve_cmd::solve(*a),
        Command::Render(a) => convert_cmd::render(a),
        Command::Bench(a) => bench_cmd::bench(a),
        Command::Check(a) => check_cmd::check(a),
        Command::Convert(a) => convert_cmd::convert(a),
        Command::Mesh(a) => mesh::run(a),
        Command::Corpus(a) => corpus::run(a),
        Command::Sweep(a) => sweep_cmd::run(*a),
        Command::Batch(a) => batch_cmd::run(*a),
        Command::Loft(a) => loft_cmd::run(*a),
        Command::Optimise(a) => optimise_cmd::run(*a),
        Command::Compare(a) => compare_cmd::run(*a),
        Command::Split(a) => multipatch_cmd::split(a),
        Command::Join(a) => multipatch_cmd::join(a),
        Command::Layout(a) => domain_cmd::layout(a),
        Command::Reference => {
            print!("{}", reference::markdown(<Cli as clap::CommandFactory>::command()));
            Ok(0)
        }
    }
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
