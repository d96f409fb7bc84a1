//! `winslow corpus`: the hard corpus of seeded domain families
//! (`winslow::boundary::families`): write the boundaries, and optionally solve each at
//! the default settings and print, per family, how many were certified and why the
//! others were not.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use winslow::boundary::families::{corpus, corpus_of, Family};
use winslow::solve;
use winslow::solve::options::SolveOptions;
use winslow::solve::report::Verdict;

#[derive(Args, Debug)]
pub struct CorpusArgs {
    /// Directory the boundary documents are written to (one `FAMILY-SEED.json` each).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Domains per family.
    #[arg(long, default_value_t = 6)]
    per_family: usize,
    /// First seed (domains use `seed, seed + 1, ...`).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Only these families (comma-separated): clearance, spiral, sharp-corner, puzzle,
    /// strip, cad, noisy-cloud, sparse-cloud; and cad-kinks (steps and V-notches at C0
    /// knots of spline sides), jigsaw (jigsaw pieces with barely rounded necks, dense
    /// clouds) and pinched (a channel pinched to 3e-4 of its length), which the default
    /// corpus leaves out; with --general: ngon,
    /// l, t, u, e, plus, plate (domains with holes), wiggly, motor (plane graphs).
    #[arg(long, value_delimiter = ',')]
    families: Vec<String>,
    /// Remove the documents (boundaries, or domains with --general) of an earlier run from the -o folder first (without
    /// it, such files are an error).
    #[arg(long)]
    overwrite: bool,
    /// The corpus of general domains instead (issue 31): N-gons with curved sides
    /// (N = 3 ... 12), L, T, U, E and plus shapes with sharp or filleted reflex corners,
    /// plates with 1 to 5 holes; and plane graphs: squares cut by wiggly curves into 4 to
    /// 60 faces, motor-like sections with 6 to 48 slots; written as domain and graph
    /// documents, and with --solve laid out automatically and solved (a domain counts as
    /// certified when every patch is).
    #[arg(long)]
    general: bool,
    /// Solve every domain (default settings) and print the verdicts and a table per
    /// family; exits 1 when any domain is not certified.
    #[arg(long)]
    solve: bool,
}

#[derive(Default)]
struct Tally {
    domains: usize,
    by_verdict: BTreeMap<String, usize>,
    seconds: f64,
    failures: Vec<String>,
}

pub fn run(a: CorpusArgs) -> Result<i32> {
    if a.general {
        return crate::corpus_domains::run(&a.output, a.per_family, a.seed, &a.families, a.solve, a.overwrite);
    }
    let families: Vec<Family> = a
        .families
        .iter()
        .map(|n| Family::parse(n).with_context(|| format!("unknown family '{n}'")))
        .collect::<Result<_>>()?;
    if a.per_family == 0 || a.per_family > 10_000 {
        bail!("--per-family must be in 1..=10000, not {}", a.per_family);
    }
    if a.output.is_none() && !a.solve {
        bail!("nothing to do: give -o DIR to write the domains, --solve to solve them, or both");
    }
    if let Some(dir) = &a.output {
        crate::files::OutputPlan::new().folder("-o", dir).check()?;
        // FAMILY-SEED.json
        let ours = |f: &str| {
            f.strip_suffix(".json").and_then(|s| s.rsplit_once('-')).is_some_and(|(family, seed)| {
                Family::parse(family).is_some() && seed.bytes().all(|b| b.is_ascii_digit())
            })
        };
        crate::files::claim_folder("-o", dir, ours, a.overwrite)?;
    }
    let domains: Vec<_> = if families.is_empty() {
        corpus(a.per_family, a.seed)
    } else {
        // in the order of the families' list, the extra ones (not in the default corpus) last
        let order: Vec<Family> =
            Family::ALL.into_iter().chain(Family::EXTRA).filter(|f| families.contains(f)).collect();
        corpus_of(&order, a.per_family, a.seed)
    };
    if let Some(dir) = &a.output {
        for (_, b) in &domains {
            crate::files::write(&dir.join(format!("{}.json", b.name)), &winslow::io::Output::Boundary(b))?;
        }
    }
    if !a.solve {
        return Ok(0);
    }
    let mut tally: BTreeMap<&str, Tally> = BTreeMap::new();
    let opts = SolveOptions::default();
    for (family, b) in &domains {
        let t0 = Instant::now();
        let (verdict, detail) = match solve(b, &opts) {
            Ok(sol) => {
                let r = &sol.report;
                let its: Vec<String> = r.solve.levels.iter().map(|l| l.iterations.to_string()).collect();
                (
                    r.outcome.verdict.name().to_string(),
                    format!("{} functions, iterations {}", r.setup.basis_functions, its.join("/")),
                )
            }
            Err(e) => ("error".to_string(), e.to_string()),
        };
        let secs = t0.elapsed().as_secs_f64();
        say!("{:<18} {:<18} {secs:7.2} s  {detail}", b.name, verdict);
        let t = tally.entry(family.name()).or_default();
        t.domains += 1;
        t.seconds += secs;
        if verdict != Verdict::Certified.name() {
            t.failures.push(format!("{}: {verdict} ({detail})", b.name));
        }
        *t.by_verdict.entry(verdict).or_default() += 1;
    }
    say!();
    say!("| family | domains | certified | degenerate corner | folded | undecided | not converged | error | time s |");
    say!("|---|---|---|---|---|---|---|---|---|");
    let (mut all, mut ok) = (0, 0);
    for (name, t) in &tally {
        let n = |v: &str| t.by_verdict.get(v).copied().unwrap_or(0);
        say!(
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {:.1} |",
            t.domains,
            n("certified"),
            n("degenerate-corner"),
            n("folded"),
            n("undecided"),
            n("not-converged"),
            n("error"),
            t.seconds
        );
        all += t.domains;
        ok += n("certified");
    }
    say!("\ncertified {ok} of {all} ({:.1} %)", 100.0 * ok as f64 / all.max(1) as f64);
    for t in tally.values() {
        for f in &t.failures {
            say!("  not certified: {f}");
        }
    }
    Ok(if ok == all { 0 } else { 1 })
}
