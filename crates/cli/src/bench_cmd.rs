//! `winslow bench`: the solver on a list of geometries and sizes, and the quadrature
//! throughput of the back ends.

use super::*;

#[derive(Args, Debug)]
pub(crate) struct BenchArgs {
    /// Boundary files (default: every JSON geometry in tests/data and tests/data/gismo).
    pub(crate) files: Vec<PathBuf>,
    /// Extra uniform halvings of the finest level to run, comma-separated (one table row
    /// per geometry and value).
    #[arg(long, value_delimiter = ',', default_value = "0")]
    pub(crate) refinements: Vec<usize>,
    #[command(flatten)]
    pub(crate) solver: SolverArgs,
    /// Print the rows as JSON lines instead of a table.
    #[arg(long)]
    pub(crate) json: bool,
    #[command(flatten)]
    pub(crate) backend: BackendArgs,
    /// Quadrature throughput (residual and Jacobian, CPU versus the selected back end)
    /// at these sizes in scalar DOFs, comma-separated. With a GPU and no FILES this
    /// table alone is printed, by default at 1e3, 1e4, 1e5 and 1e6 DOFs (1e6 left out on
    /// a software adapter such as lavapipe).
    #[arg(long, value_delimiter = ',')]
    pub(crate) sizes: Vec<usize>,
    /// Degree of the quadrature benchmark's basis.
    #[arg(long, default_value_t = 3)]
    pub(crate) bench_degree: usize,
    /// GPU Jacobian kernel of the quadrature benchmark: element matrices (one workgroup
    /// per element, then a gather; the solver's) or one invocation per stencil entry.
    #[arg(long, value_enum, default_value = "element")]
    pub(crate) gpu_kernel: KernelArg,
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum KernelArg {
    Element,
    Entry,
}

pub(crate) fn bench(a: BenchArgs) -> Result<i32> {
    let opts = a.solver.options()?;
    let sel = a.backend.select(a.json)?;
    let sizes = match sel.gpu() {
        _ if !a.sizes.is_empty() || !a.files.is_empty() => a.sizes.clone(),
        // 10^6 takes many minutes on a software adapter (lavapipe): ask for it explicitly
        Some(g) if g.is_software() => {
            note!("note: software adapter, sizes 1e3..1e5 (pass --sizes 1000000 for 1e6)");
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
                note!("skipping {}: {e:#}", f.display());
                continue;
            }
        };
        for &r in &a.refinements {
            let mut o = opts.clone();
            o.levels.refine = r;
            let estimate = winslow::Pipeline::new(boundary.clone(), o.clone()).estimate()?;
            output::reset_peak_memory();
            let t = Instant::now();
            let sol = solve_cmd::run_pipeline(boundary.clone(), &o, sel.as_assembler(), true)?.into_map()?;
            let total = t.elapsed().as_secs_f64();
            let row = output::BenchRow::new(&sol, r, total, estimate.bytes);
            if a.json {
                println!("{}", serde_json::to_string(&row)?);
            }
            rows.push(row);
        }
    }
    if !a.json {
        say_raw!("{}", output::bench_table(&rows));
    }
    Ok(0)
}

/// Quadrature throughput at the given sizes, CPU versus the selected GPU.
pub(crate) fn quadrature_bench(
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
            note!("  {} DOFs done", row.dofs);
        }
        rows.push(row);
    }
    if !json {
        say_raw!("{}", output::quadrature_table(&sel.describe(), &rows));
    }
    Ok(())
}
