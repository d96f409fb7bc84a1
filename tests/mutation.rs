//! Structure-aware mutation test: random edits of the valid files under `tests/data`
//! (boundary, contour and map JSON, G+Smo XML, IGES; `winslow::testutil::mutate`) go
//! through every reader, the validator, the certificate and the writers' round trips
//! (`winslow::testutil::exercise`). No mutant may panic, every error must say what is
//! wrong, and every map that is read must round-trip. Seeded, so a failure reproduces;
//! the coverage-guided fuzz targets under `fuzz/` do the long runs.

use std::cell::Cell;
use std::path::{Path, PathBuf};

use winslow::error::Error;
use winslow::testutil::exercise::{exercise_ring_text, exercise_text, Reader, Trace};
use winslow::testutil::mutate::{run_mutants, Failure};

/// Mutants per file (about 30 files); `WINSLOW_MUTANTS=N` runs more (a long run by hand).
const PER_FILE: usize = 150;
const SEED: u64 = 0x5eed_2026;
/// Files larger than this are left out (mutants of large files cost more and teach little).
const MAX_BYTES: u64 = 16 << 10;

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            // regression inputs of the fuzzer are invalid on purpose; multipatch layouts,
            // general domains, volume boundaries and THB maps are not single-patch documents
            // (their readers have their own tests)
            let skip = ["fuzz", "multipatch", "domains", "volumes", "thb"];
            if p.file_name().is_some_and(|n| !skip.iter().any(|s| n == *s)) {
                collect(&p, out);
            }
        } else if p.extension().is_some_and(|e| e == "json" || e == "xml" || e == "igs")
            && p.metadata().unwrap().len() <= MAX_BYTES
            // a ring cut into a four-sided map: its west and east sides coincide (the seam
            // the mesher merges), so its boundary is not a valid four-sided one by design
            && p.file_name().is_some_and(|n| n != "cut_annulus.json")
        {
            out.push(p);
        }
    }
}

/// The valid files: `(path relative to tests/data, text)`.
fn valid_files() -> Vec<(String, String)> {
    let root = winslow::testutil::data_dir();
    let mut paths = Vec::new();
    collect(&root, &mut paths);
    paths
        .iter()
        .map(|p| (p.strip_prefix(&root).unwrap().display().to_string(), std::fs::read_to_string(p).unwrap()))
        .collect()
}

/// The reader a file is meant for (besides detection by content).
fn reader_for(name: &str) -> Reader {
    if name.ends_with(".xml") {
        Reader::Gismo
    } else if name.ends_with(".igs") {
        Reader::Iges
    } else {
        Reader::Json
    }
}

/// Both readers of a file's kind; the violations found.
fn traces(name: &str, text: &str) -> [Trace; 2] {
    if name.starts_with("rings/") {
        // ring (O-type) documents have their own reader (`io::ring`)
        return [exercise_ring_text(text), exercise_ring_text(text)];
    }
    [exercise_text(Reader::Document, text), exercise_text(reader_for(name), text)]
}

fn per_file() -> usize {
    std::env::var("WINSLOW_MUTANTS").ok().and_then(|n| n.parse().ok()).unwrap_or(PER_FILE)
}

fn report(failures: &[Failure]) -> String {
    failures
        .iter()
        .take(5)
        .map(|f| {
            format!(
                "{} mutant {} ({}): {}\n--- input (first 2000 bytes) ---\n{}\n",
                f.file,
                f.mutant,
                f.edits.join(", "),
                f.problem,
                &f.input[..f.input.floor_char_boundary(2000)]
            )
        })
        .collect()
}

#[test]
fn the_valid_files_are_valid() {
    let files = valid_files();
    let kinds = ["json", "xml", "igs"].map(|e| files.iter().filter(|(n, _)| n.ends_with(e)).count());
    assert!(files.len() >= 20 && kinds.iter().all(|&k| k >= 2), "{kinds:?} of {} files", files.len());
    for (name, text) in &files {
        for t in traces(name, text) {
            assert!(t.errors.is_empty() && t.violations.is_empty(), "{name}: {t:?}");
            assert_eq!(t.valid_boundaries, 1, "{name}");
        }
    }
}

#[test]
fn mutants_fail_cleanly() {
    let files = valid_files();
    let (accepted, rejected, maps) = (Cell::new(0), Cell::new(0), Cell::new(0));
    let per_file = per_file();
    let failures = run_mutants(&files, per_file, SEED, |name, text| {
        let mut violations = Vec::new();
        for t in traces(name, text) {
            maps.set(maps.get() + t.maps);
            if t.valid_boundaries > 0 {
                accepted.set(accepted.get() + 1);
            } else {
                rejected.set(rejected.get() + 1);
            }
            violations.extend(t.violations);
        }
        violations
    });
    assert!(failures.is_empty(), "{} failures; the first:\n{}", failures.len(), report(&failures));
    // the edits must reach past the parsers: some mutants are still valid, maps are read
    let runs = 2 * per_file * files.len();
    let (a, r, m) = (accepted.get(), rejected.get(), maps.get());
    assert_eq!(a + r, runs);
    assert!(a > runs / 20 && r > runs / 5 && m > runs / 50, "accepted {a}, rejected {r}, maps {m} of {runs}");
}

/// The harness is not blind: a pipeline that panics on some inputs (here: whenever the
/// reader reports a non-finite number, as an unchecked `f64` would have panicked
/// further down) and one that produces uninformative errors are caught.
#[test]
fn harness_catches_injected_panics_and_bad_errors() {
    let files = valid_files();
    let failures = run_mutants(&files, 10, SEED, |name, text| {
        for t in traces(name, text) {
            if t.errors.iter().any(|(_, e)| matches!(e, Error::NonFinite { .. })) {
                panic!("injected: non-finite input reached the pipeline");
            }
        }
        Vec::new()
    });
    assert!(!failures.is_empty(), "no mutant triggered the injected panic");
    assert!(failures.iter().all(|f| f.problem == "panic: injected: non-finite input reached the pipeline"));
    assert!(failures.iter().all(|f| f.input != files.iter().find(|(n, _)| *n == f.file).unwrap().1));

    let failures = run_mutants(&files, 4, SEED, |name, text| {
        traces(name, text).iter().flat_map(|t| &t.errors).map(|_| String::from("error without a message")).collect()
    });
    assert!(!failures.is_empty());
}
