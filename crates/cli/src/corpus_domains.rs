//! `winslow corpus --general`: the seeded corpus of general domains
//! (`winslow::domain::corpus`): write the domain documents, and optionally lay each out
//! automatically and solve it at the default settings, with a table per family.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use winslow::domain::corpus::{domain_corpus, DomainFamily};
use winslow::domain::{auto_layout, LayoutOptions};
use winslow::solve::report::Verdict;
use winslow::{Pipeline, SolveOptions, Solved};

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
    let families: Vec<DomainFamily> = names
        .iter()
        .map(|n| DomainFamily::parse(n).with_context(|| format!("unknown family '{n}' (ngon, l, t, u, e, plus)")))
        .collect::<Result<_>>()?;
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
                DomainFamily::parse(family).is_some() && n.bytes().all(|b| b.is_ascii_digit())
            })
        };
        crate::files::claim_folder("-o", dir, ours, overwrite)?;
    }
    let domains = domain_corpus(&families, per_family, seed);
    if let Some(dir) = output {
        for (_, d) in &domains {
            crate::files::write(&dir.join(format!("{}.json", d.name)), &winslow::io::Output::Domain(d))?;
        }
    }
    if !solve {
        return Ok(0);
    }
    let mut tally: BTreeMap<&str, Tally> = BTreeMap::new();
    for (family, d) in &domains {
        let t0 = Instant::now();
        let outcome = auto_layout(d, &LayoutOptions::default()).and_then(|auto| {
            match Pipeline::new(auto.layout.clone(), SolveOptions::default()).solve()? {
                Solved::Layout(sol) => Ok((auto, *sol)),
                other => Err(winslow::Error::Invalid(format!("a layout solved into {:?}", other.verdict()))),
            }
        });
        let secs = t0.elapsed().as_secs_f64();
        let t = tally.entry(family.name()).or_default();
        t.domains += 1;
        t.seconds += secs;
        match outcome {
            Ok((auto, sol)) => {
                let n = sol.patches.len();
                t.patches += n;
                let good = sol.report.verdicts.iter().all(|v| *v == Verdict::Certified);
                say!(
                    "{:<10} {:>3} patches {:>2} cuts, angles {:5.1}..{:5.1}: {:<18} {secs:6.2} s",
                    d.name,
                    n,
                    auto.report.cuts.len(),
                    auto.report.corner_angles[0],
                    auto.report.corner_angles[1],
                    sol.report.verdict.name()
                );
                if good {
                    t.certified += 1;
                } else {
                    t.failures.push(format!("{}: {}", d.name, sol.report.message));
                }
            }
            Err(e) => {
                say!("{:<10} error: {e}", d.name);
                t.failures.push(format!("{}: {e}", d.name));
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
