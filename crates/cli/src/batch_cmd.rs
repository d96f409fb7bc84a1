//! `winslow batch INPUTS... | --manifest FILE.jsonl -o DIR --jobs N`: many shapes solved
//! in parallel (one shape per worker), each map written (atomically) to `DIR/NAME.json`
//! as it finishes, a typed failure record `DIR/NAME.error.json` per failing shape, and
//! the summary `DIR/batch.jsonl` and `DIR/batch.csv` (name, status, verdict, seconds,
//! unknowns, quality). Re-running skips the shapes whose map is already there, so a
//! killed batch resumes where it stopped; `--overwrite` starts afresh. With
//! `--warm-start` (a shape family in sequence) the shapes are cut into `--jobs`
//! contiguous chains, each solved in order from the previous shape's map
//! ([`winslow::solve::warm::warm_start`]; cold where it does not apply).

use super::*;
use rayon::prelude::*;
use serde_json::{json, Value};
use winslow::{Input, Pipeline};

#[derive(Args, Debug)]
pub(super) struct BatchArgs {
    /// Input files (boundaries, maps, rings): each shape is named after its file stem.
    inputs: Vec<PathBuf>,
    /// A manifest of shapes, one JSON object per line: `{"name": N, "path": FILE}` (a
    /// path relative to the manifest's folder) or `{"name": N, "document": {...}}` (a
    /// document of formats.md inline). Names are file names: letters, digits, `.`, `_`,
    /// `-`.
    #[arg(long)]
    manifest: Option<PathBuf>,
    /// Output folder: NAME.json (the map with its report), NAME.error.json (a failure),
    /// batch.jsonl and batch.csv (the summary).
    #[arg(short, long)]
    output: PathBuf,
    /// Shapes solved at once (default: all cores).
    #[arg(long, short = 'j')]
    jobs: Option<usize>,
    /// Remove the outputs of an earlier batch from the folder first (otherwise the shapes
    /// whose map is there are skipped, and outputs of other shapes are an error).
    #[arg(long)]
    overwrite: bool,
    /// A family in sequence: solve each shape from the previous shape's map, on its basis
    /// (the shapes cut into --jobs contiguous chains, each in order; a shape whose sides
    /// are not on that basis, or whose warm start is not certified, is solved cold). The
    /// report says which ("warm_start").
    #[arg(long)]
    warm_start: bool,
    #[command(flatten)]
    solver: SolverArgs,
}

/// One shape of the batch.
struct Shape {
    name: String,
    source: Source,
}

enum Source {
    File(PathBuf),
    Inline(Box<Value>),
}

/// The files a batch writes: `NAME.json`, `NAME.error.json`, `batch.jsonl`, `batch.csv`.
fn of_a_batch(file: &str) -> bool {
    file.ends_with(".json") || file == "batch.jsonl" || file == "batch.csv"
}

/// The shape a batch output file belongs to (`None` for the summary).
fn shape_of_file(file: &str) -> Option<&str> {
    file.strip_suffix(".error.json").or_else(|| file.strip_suffix(".json"))
}

fn check_name(name: &str, at: &str) -> Result<()> {
    let ok = !name.is_empty()
        && !name.starts_with('.')
        && name != "batch"
        && !name.ends_with(".error")
        && name.bytes().all(|b| b.is_ascii_alphanumeric() || matches!(b, b'.' | b'_' | b'-'));
    if !ok {
        bail!("{at}: the shape name {name:?} is not a plain file name (letters, digits, '.', '_', '-'; not 'batch')");
    }
    Ok(())
}

/// The shapes of the command line and of the manifest, names checked and unique.
fn shapes(a: &BatchArgs) -> Result<Vec<Shape>> {
    let mut out = Vec::new();
    for p in &a.inputs {
        let name = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        check_name(&name, &p.display().to_string())?;
        out.push(Shape { name, source: Source::File(p.clone()) });
    }
    if let Some(m) = &a.manifest {
        let text = std::fs::read_to_string(m).with_context(|| format!("reading the manifest {}", m.display()))?;
        let dir = m.parent().unwrap_or(Path::new("."));
        for (i, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
            let at = format!("{} line {}", m.display(), i + 1);
            let v: Value = serde_json::from_str(line).with_context(|| format!("{at}: malformed JSON"))?;
            let name = v["name"].as_str().with_context(|| format!("{at}: no \"name\""))?.to_string();
            check_name(&name, &at)?;
            let source = match (v.get("path").and_then(Value::as_str), v.get("document")) {
                (Some(p), None) => Source::File(dir.join(p)),
                (None, Some(d)) => Source::Inline(Box::new(d.clone())),
                _ => bail!("{at}: a line needs either \"path\" or \"document\""),
            };
            out.push(Shape { name, source });
        }
    }
    if out.is_empty() {
        bail!("no shapes: give input files or --manifest FILE.jsonl");
    }
    let mut names: Vec<&str> = out.iter().map(|s| s.name.as_str()).collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        bail!("two shapes are named {:?}: the names must be unique (they name the output files)", w[0]);
    }
    Ok(out)
}

/// The pipeline's input of a shape (a boundary checked as `winslow solve` does).
fn input_of(shape: &Shape, reorient: bool) -> winslow::Result<Input> {
    let doc = match &shape.source {
        Source::File(p) => winslow::read(p)?,
        Source::Inline(v) => winslow::io::parse_document(&v.to_string())?,
    };
    doc.into_input(&ReadOptions { reorient })
}

/// The kind of a core error (its variant in snake case, as the Python package's
/// `WinslowError.kind`), for the failure record.
fn error_kind(e: &winslow::Error) -> String {
    let debug = format!("{e:?}");
    let mut kind = String::new();
    for c in debug.chars().take_while(|c| c.is_alphanumeric()) {
        if c.is_uppercase() && !kind.is_empty() {
            kind.push('_');
        }
        kind.push(c.to_ascii_lowercase());
    }
    kind
}

/// The summary row of a solved shape, from its report.
fn row_of(name: &str, report: &Value) -> Value {
    json!({
        "name": name,
        "status": "solved",
        "verdict": report["verdict"],
        "seconds": report["seconds"],
        // a warm-started shape's report has its unknowns at the top
        "unknowns": report["levels"]
            .as_array()
            .and_then(|l| l.last())
            .map_or_else(|| report["unknowns"].clone(), |l| l["unknowns"].clone()),
        "quality": report["quality"]["scaled_jacobian"]["min"],
    })
}

/// A solved shape: its map, report, whether it is bijective, and its label.
struct Solved {
    map: Surface,
    report: Value,
    bijective: bool,
    label: String,
}

/// Solve one shape: from `start` (the previous map of its chain) when given and the warm
/// start applies, else cold by the pipeline.
fn solve_shape(input: Input, start: Option<&Surface>, opts: &SolveOptions) -> winslow::Result<Solved> {
    let mut pipeline = Pipeline::new(input, opts.clone());
    if let Some(prev) = start {
        pipeline = pipeline.warm_start(prev.clone());
    }
    let to_json = |v: Result<Value, serde_json::Error>| v.map_err(|e| winslow::Error::Invalid(e.to_string()));
    match pipeline.solve()? {
        winslow::Solved::Warm(w) => {
            let report = to_json(serde_json::to_value(&*w))?;
            let label = format!("verdict {:?}: {}", w.verdict, w.message);
            Ok(Solved { map: w.map, report, bijective: true, label })
        }
        solved => {
            let sol = solved.into_map()?;
            let report = to_json(serde_json::to_value(&sol.report))?;
            let bijective = matches!(sol.report.outcome.verdict, Verdict::Certified | Verdict::DegenerateCorner);
            let label = format!("verdict {:?}: {}", sol.report.outcome.verdict, sol.report.outcome.message);
            Ok(Solved { map: sol.map, report, bijective, label })
        }
    }
}

/// Solve one shape and write its map or failure record; its summary row, and its map
/// when bijective (the start of the next shape of a chain).
fn run_one(
    shape: &Shape,
    dir: &Path,
    opts: &SolveOptions,
    reorient: bool,
    start: Option<&Surface>,
) -> Result<(Value, Option<Surface>)> {
    let t0 = Instant::now();
    let solved = input_of(shape, reorient).and_then(|input| solve_shape(input, start, opts));
    let failure = dir.join(format!("{}.error.json", shape.name));
    match solved {
        Ok(sol) => {
            let extra = Some(json!({ "report": sol.report }));
            files::write(
                &dir.join(format!("{}.json", shape.name)),
                &Output::Map { name: &shape.name, map: &sol.map, label: &sol.label, extra },
            )?;
            if failure.exists() {
                std::fs::remove_file(&failure).with_context(|| format!("removing {}", failure.display()))?;
            }
            Ok((row_of(&shape.name, &sol.report), sol.bijective.then_some(sol.map)))
        }
        Err(e) => {
            let record = json!({
                "name": shape.name,
                "status": "failed",
                "kind": error_kind(&e),
                "message": e.to_string(),
                "seconds": t0.elapsed().as_secs_f64(),
            });
            files::write_json(&failure, &record)?;
            Ok((record, None))
        }
    }
}

/// The map a finished shape left in the folder, when bijective (a resumed chain goes on
/// from it).
fn done_map(dir: &Path, name: &str) -> Option<Surface> {
    match winslow::io::read_with_report(&dir.join(format!("{name}.json"))) {
        Ok((Document::Map { map, .. }, Some(r)))
            if matches!(r["verdict"].as_str(), Some("certified" | "degenerate-corner")) =>
        {
            Some(map)
        }
        _ => None,
    }
}

const HEADER: &str = "name,status,verdict,seconds,unknowns,quality";

fn csv_row(r: &Value) -> String {
    let s = |v: &Value| match v {
        Value::Null => String::new(),
        Value::String(s) => s.clone(),
        v => v.to_string(),
    };
    format!(
        "{},{},{},{},{},{}",
        s(&r["name"]),
        s(&r["status"]),
        s(&r["verdict"]),
        s(&r["seconds"]),
        s(&r["unknowns"]),
        s(&r["quality"])
    )
}

pub(super) fn run(a: BatchArgs) -> Result<i32> {
    let opts = a.solver.options()?;
    let reorient = a.solver.fit.reorient;
    let shapes = shapes(&a)?;
    let plan = shapes.iter().filter_map(|s| match &s.source {
        Source::File(p) => Some(p),
        Source::Inline(_) => None,
    });
    let plan = plan.chain(&a.manifest).fold(files::OutputPlan::new(), |p, i| p.input(i));
    plan.folder("-o", &a.output).check()?;
    let names: std::collections::HashSet<&str> = shapes.iter().map(|s| s.name.as_str()).collect();
    if a.overwrite {
        files::claim_folder("-o", &a.output, of_a_batch, true)?;
    } else {
        // outputs of shapes that are not in this batch: another batch's folder
        let foreign = |f: &str| of_a_batch(f) && shape_of_file(f).is_some_and(|n| !names.contains(n));
        files::claim_folder("-o", &a.output, foreign, false)?;
    }
    std::fs::create_dir_all(&a.output).with_context(|| format!("creating {}", a.output.display()))?;
    // a shape whose map is there (and reads back with its report) is done
    let mut rows: Vec<Option<Value>> = shapes
        .iter()
        .map(|s| {
            let path = a.output.join(format!("{}.json", s.name));
            match winslow::io::read_with_report(&path) {
                Ok((Document::Map { .. }, Some(report))) => Some(row_of(&s.name, &report)),
                _ => None,
            }
        })
        .collect();
    let todo: Vec<usize> = (0..shapes.len()).filter(|&i| rows[i].is_none()).collect();
    note!(
        "batch: {} shapes, {} done before, {} to solve on {} workers",
        shapes.len(),
        shapes.len() - todo.len(),
        todo.len(),
        a.jobs.unwrap_or_else(rayon::current_num_threads)
    );
    let pool = rayon::ThreadPoolBuilder::new().num_threads(a.jobs.unwrap_or(0)).stack_size(16 << 20).build()?;
    let done = std::sync::atomic::AtomicUsize::new(0);
    // chains of shapes solved in order: with --warm-start one per worker over all shapes
    // (a finished shape's map starts the next), else one per shape to solve
    let chains: Vec<Vec<usize>> = if a.warm_start {
        let per = shapes.len().div_ceil(pool.current_num_threads().max(1)).max(1);
        (0..shapes.len()).collect::<Vec<_>>().chunks(per).map(<[usize]>::to_vec).collect()
    } else {
        todo.iter().map(|&i| vec![i]).collect()
    };
    let finished: Vec<bool> = rows.iter().map(Option::is_some).collect();
    let results: Vec<(usize, Result<Value>)> = pool.install(|| {
        chains
            .par_iter()
            .flat_map_iter(|chain| {
                let mut prev: Option<Surface> = None;
                let mut out = Vec::new();
                for &i in chain {
                    if finished[i] {
                        prev = done_map(&a.output, &shapes[i].name).or(prev);
                        continue;
                    }
                    let start = prev.as_ref().filter(|_| a.warm_start);
                    let r = run_one(&shapes[i], &a.output, &opts, reorient, start);
                    let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    if let Ok((row, _)) = &r {
                        note!(
                            "[{k}/{}] {}: {}",
                            todo.len(),
                            shapes[i].name,
                            row["verdict"].as_str().or(row["kind"].as_str()).unwrap_or("")
                        );
                    }
                    let r = r.map(|(row, map)| {
                        prev = map.or(prev.take());
                        row
                    });
                    out.push((i, r));
                }
                out
            })
            .collect()
    });
    for (i, r) in results {
        rows[i] = Some(r.with_context(|| format!("writing the result of {}", shapes[i].name))?);
    }
    let rows: Vec<Value> = rows.into_iter().flatten().collect();
    let jsonl: String = rows.iter().map(|r| format!("{r}\n")).collect();
    files::write_bytes(&a.output.join("batch.jsonl"), jsonl.as_bytes())?;
    let csv: String = std::iter::once(HEADER.to_string()).chain(rows.iter().map(csv_row)).map(|l| l + "\n").collect();
    files::write_bytes(&a.output.join("batch.csv"), csv.as_bytes())?;
    let failed = rows.iter().filter(|r| r["status"] == "failed").count();
    let worst = rows
        .iter()
        .filter_map(|r| r["verdict"].as_str())
        .map(|v| match v {
            "certified" | "degenerate-corner" => 0,
            "folded" => 3,
            "not-converged" => 4,
            _ => 5,
        })
        .max()
        .unwrap_or(0);
    say!(
        "batch: {} shapes: {} bijective, {} not, {} failed ({})",
        rows.len(),
        rows.iter().filter(|r| matches!(r["verdict"].as_str(), Some("certified" | "degenerate-corner"))).count(),
        rows.iter().filter(|r| r["status"] == "solved").count()
            - rows.iter().filter(|r| matches!(r["verdict"].as_str(), Some("certified" | "degenerate-corner"))).count(),
        failed,
        a.output.join("batch.csv").display()
    );
    Ok(if failed > 0 { 1 } else { worst })
}
