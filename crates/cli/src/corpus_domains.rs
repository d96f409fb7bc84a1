//! `winslow corpus --general`: the seeded corpus of general domains and plane graphs
//! (`winslow::domain::corpus`): write the domain and graph documents, and optionally lay
//! each out automatically and solve it at the default settings, with a table per family.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Result};
use winslow::domain::corpus::{domain_corpus, DomainFamily, GraphFamily};
use winslow::domain::{Domain, PlaneGraph};
use winslow::solve::report::Verdict;
use winslow::{Pipeline, SolveOptions, Solved};

/// A generated domain or plane graph.
enum Item {
    Domain(Domain),
    Graph(PlaneGraph),
}

impl Item {
    /// The pipeline's input: laid out, then solved.
    fn input(&self) -> winslow::Input {
        match self {
            Item::Domain(d) => winslow::Input::Domain(d.clone()),
            Item::Graph(g) => winslow::Input::Graph(g.clone()),
        }
    }
}

impl Item {
    fn name(&self) -> &str {
        match self {
            Item::Domain(d) => &d.name,
            Item::Graph(g) => &g.name,
        }
    }
}

#[derive(Default)]
struct Tally {
    domains: usize,
    certified: usize,
    patches: usize,
    seconds: f64,
    failures: Vec<String>,
}

pub fn run(
    output: &Option<PathBuf>,
    per_family: usize,
    seed: u64,
    names: &[String],
    solve: bool,
    overwrite: bool,
) -> Result<i32> {
    for n in names {
        if DomainFamily::parse(n).is_none() && GraphFamily::parse(n).is_none() {
            bail!("unknown family '{n}' (ngon, l, t, u, e, plus, plate, wiggly, motor)");
        }
    }
    let families: Vec<DomainFamily> = names.iter().filter_map(|n| DomainFamily::parse(n)).collect();
    let graph_families: Vec<GraphFamily> = names.iter().filter_map(|n| GraphFamily::parse(n)).collect();
    if per_family == 0 || per_family > 10_000 {
        bail!("--per-family must be in 1..=10000, not {per_family}");
    }
    if output.is_none() && !solve {
        bail!("nothing to do: give -o DIR to write the domains, --solve to solve them, or both");
    }
    if let Some(dir) = output {
        crate::files::OutputPlan::new().folder("-o", dir).check()?;
        // FAMILY-N.json of an earlier run
        let ours = |f: &str| {
            f.strip_suffix(".json").and_then(|s| s.rsplit_once('-')).is_some_and(|(family, n)| {
                (DomainFamily::parse(family).is_some() || GraphFamily::parse(family).is_some())
                    && n.bytes().all(|b| b.is_ascii_digit())
            })
        };
        crate::files::claim_folder("-o", dir, ours, overwrite)?;
    }
    let mut domains: Vec<(&str, Item)> = Vec::new();
    if names.is_empty() || !families.is_empty() {
        domains
            .extend(domain_corpus(&families, per_family, seed).into_iter().map(|(f, d)| (f.name(), Item::Domain(d))));
    }
    for f in GraphFamily::ALL.into_iter().filter(|f| names.is_empty() || graph_families.contains(f)) {
        domains.extend((0..per_family as u64).map(|k| (f.name(), Item::Graph(f.generate(seed + k)))));
    }
    if let Some(dir) = output {
        for (_, item) in &domains {
            let (name, out) = match item {
                Item::Domain(d) => (&d.name, winslow::io::Output::Domain(d)),
                Item::Graph(g) => (&g.name, winslow::io::Output::Graph(g)),
            };
            crate::files::write(&dir.join(format!("{name}.json")), &out)?;
        }
    }
    if !solve {
        return Ok(0);
    }
    let mut tally: BTreeMap<&str, Tally> = BTreeMap::new();
    for (family, item) in &domains {
        let t0 = Instant::now();
        let outcome = match Pipeline::new(item.input(), SolveOptions::default()).solve() {
            Ok(Solved::Layout { solution, laid_out: Some(auto) }) => Ok((auto, solution)),
            Ok(other) => Err(winslow::Error::Invalid(format!("a domain solved into a {}", other.kind()))),
            Err(e) => Err(e),
        };
        let secs = t0.elapsed().as_secs_f64();
        let t = tally.entry(family).or_default();
        let name = item.name();
        t.domains += 1;
        t.seconds += secs;
        match outcome {
            Ok((auto, sol)) => {
                let n = sol.patches.len();
                t.patches += n;
                let good = sol.report.verdicts.iter().all(|v| *v == Verdict::Certified);
                say!(
                    "{:<10} {:>3} patches {:>2} cuts, angles {:5.1}..{:5.1}: {:<18} {secs:6.2} s",
                    name,
                    n,
                    auto.cuts.len(),
                    auto.corner_angles[0],
                    auto.corner_angles[1],
                    sol.report.verdict.name()
                );
                if good {
                    t.certified += 1;
                } else {
                    t.failures.push(format!("{name}: {}", sol.report.message));
                }
            }
            Err(e) => {
                say!("{name:<10} error: {e}");
                t.failures.push(format!("{name}: {e}"));
            }
        }
    }
    say!();
    say!("| family | domains | certified | patches | time s |");
    say!("|---|---|---|---|---|");
    let (mut all, mut ok) = (0, 0);
    for (name, t) in &tally {
        say!("| {name} | {} | {} | {} | {:.1} |", t.domains, t.certified, t.patches, t.seconds);
        all += t.domains;
        ok += t.certified;
    }
    say!("\ncertified {ok} of {all} ({:.1} %)", 100.0 * ok as f64 / all.max(1) as f64);
    for t in tally.values() {
        for f in &t.failures {
            say!("  not certified: {f}");
        }
    }
    Ok(if ok == all { 0 } else { 1 })
}
