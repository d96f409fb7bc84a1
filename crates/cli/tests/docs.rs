//! Every command line of the README and the user guide (`docs/*.md`, the generated
//! `docs/cli.md` with each command's example included) runs: the `winslow ...` and
//! `cargo run ... --bin winslow -- ...` lines of every fenced `sh` block are run, page by
//! page and in order, by `sh` with this build's binary first on `PATH`, in a scratch
//! folder where `tests/` links to the repository's test data (so `out/...` and every
//! other relative output lands in the scratch folder). Each must exit with 0, or with the
//! code a trailing `# exit N` comment states.
//!
//! Conventions of the pages: a comment line `# not run: REASON` before a command skips it
//! (keep these rare: a display, a peer tool); a command with `--backend gpu` runs only
//! where GPU tests are required (`WINSLOW_REQUIRE_GPU=1`, set by `scripts/test.sh`);
//! command lines in other shell blocks (`bash`, `console`, unmarked) are refused. Also
//! checked: every guide page is linked from the README (which stays under 200 lines),
//! relative links of the pages point to files that exist, and `docs/formats.md` is
//! `../shared/formats.md` (only where that folder exists).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().expect("repository root")
}

/// README.md and every page of `docs/`, in name order.
fn pages() -> Vec<PathBuf> {
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .expect("docs/")
        .map(|e| e.expect("docs/ entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    let mut all = vec![root().join("README.md")];
    all.extend(docs);
    all
}

/// Block languages that hold shell lines but are not the `sh` blocks this test runs.
const SHELL_LIKE: [&str; 5] = ["", "bash", "shell", "console", "zsh"];

/// One documented command line.
#[derive(Debug)]
struct DocCommand {
    /// `page:line` of its first line.
    place: String,
    /// The line, continuations joined, `cargo run ... --bin winslow --` made `winslow`.
    line: String,
    /// The exit code it must end with.
    expect: i32,
    /// Why it is not run, if it is not.
    skip: Option<String>,
}

/// Whether `line` runs the `winslow` binary (after leading `VAR=value` assignments).
fn runs_winslow(line: &str) -> bool {
    let mut words = line.split_whitespace().skip_while(|w| is_assignment(w));
    match words.next() {
        Some("winslow") => true,
        Some("cargo") => cargo_prefix_end(line).is_some(),
        _ => false,
    }
}

fn is_assignment(word: &str) -> bool {
    word.split_once('=').is_some_and(|(k, _)| {
        !k.is_empty() && k.chars().all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
    })
}

/// The byte range of `cargo run [flags] --bin winslow --` in `line`, if it has one.
fn cargo_prefix_end(line: &str) -> Option<(usize, usize)> {
    let start = line.find("cargo run")?;
    let marker = " --bin winslow -- ";
    let at = line[start..].find(marker)? + start;
    Some((start, at + marker.len()))
}

/// `line` with the cargo prefix replaced by `winslow`.
fn as_binary_call(line: &str) -> String {
    match cargo_prefix_end(line) {
        Some((a, b)) => format!("{}winslow {}", &line[..a], &line[b..]),
        None => line.to_string(),
    }
}

/// The exit code stated by a trailing `# exit N`, else 0.
fn stated_exit(line: &str) -> Result<i32, String> {
    let Some((_, comment)) = line.rsplit_once(" # ") else { return Ok(0) };
    match comment.trim().strip_prefix("exit ") {
        Some(n) => n.trim().parse().map_err(|_| format!("`# exit {n}`: not an exit code")),
        None => Ok(0),
    }
}

/// The documented commands of one page, and the problems of its markup.
fn commands(page: &Path) -> (Vec<DocCommand>, Vec<String>) {
    let text = std::fs::read_to_string(page).unwrap_or_else(|e| panic!("{}: {e}", page.display()));
    let name = page.strip_prefix(root()).unwrap_or(page).display().to_string();
    let (mut found, mut problems) = (Vec::new(), Vec::new());
    let mut block: Option<String> = None;
    let mut pending_skip: Option<String> = None;
    let mut pending: Option<(usize, String)> = None;
    for (i, raw) in text.lines().enumerate() {
        let trimmed = raw.trim();
        if let Some(lang) = trimmed.strip_prefix("```") {
            block = match block {
                Some(_) => None,
                None => Some(lang.trim().to_string()),
            };
            pending_skip = None;
            continue;
        }
        let Some(lang) = &block else { continue };
        if lang != "sh" {
            // usage lines and printed output may stand in text blocks; a shell block
            // under another name would escape the test
            if SHELL_LIKE.contains(&lang.as_str()) && runs_winslow(trimmed) {
                problems.push(format!("{name}:{}: a command line in a ```{lang} block (make it ```sh)", i + 1));
            }
            continue;
        }
        let (start, mut line) = match pending.take() {
            Some((start, mut acc)) => {
                acc.push(' ');
                acc.push_str(trimmed);
                (start, acc)
            }
            None => (i + 1, trimmed.to_string()),
        };
        if let Some(head) = line.strip_suffix('\\') {
            pending = Some((start, head.trim_end().to_string()));
            continue;
        }
        if let Some(reason) = line.strip_prefix("# not run:") {
            if reason.trim().is_empty() {
                problems.push(format!("{name}:{start}: `# not run:` without a reason"));
            }
            pending_skip = Some(reason.trim().to_string());
            continue;
        }
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if !runs_winslow(&line) {
            pending_skip = None;
            continue;
        }
        line = as_binary_call(&line);
        let expect = stated_exit(&line).unwrap_or_else(|e| {
            problems.push(format!("{name}:{start}: {e}"));
            0
        });
        let mut skip = pending_skip.take();
        if skip.is_none() && line.contains("--backend gpu") && std::env::var_os("WINSLOW_REQUIRE_GPU").is_none() {
            skip = Some("needs a GPU adapter (WINSLOW_REQUIRE_GPU unset)".into());
        }
        found.push(DocCommand { place: format!("{name}:{start}"), line, expect, skip });
    }
    (found, problems)
}

/// A scratch folder for one page, with `tests` linked to the repository's.
fn scratch(page: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("winslow-docs-{}-{}", std::process::id(), page.replace('/', "_")));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    #[cfg(unix)]
    std::os::unix::fs::symlink(root().join("tests"), dir.join("tests")).expect("link to tests/");
    dir
}

#[test]
fn documented_commands_run() {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_winslow"));
    let bin_dir = bin.parent().expect("binary folder").to_path_buf();
    let path = std::env::join_paths(
        std::iter::once(bin_dir).chain(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default())),
    )
    .expect("PATH");
    let (mut failures, mut ran, mut skipped) = (Vec::new(), 0, Vec::new());
    for page in pages() {
        let (cmds, problems) = commands(&page);
        failures.extend(problems);
        if cmds.is_empty() {
            continue;
        }
        let name = page.strip_prefix(root()).unwrap_or(&page).display().to_string();
        let dir = scratch(&name);
        let mut page_ok = true;
        for c in cmds {
            if let Some(why) = &c.skip {
                skipped.push(format!("{}: {} ({why})", c.place, c.line));
                continue;
            }
            let t = Instant::now();
            let out = Command::new("sh").arg("-c").arg(&c.line).current_dir(&dir).env("PATH", &path).output();
            let out = match out {
                Ok(o) => o,
                Err(e) => {
                    failures.push(format!("{}: {}: cannot run sh: {e}", c.place, c.line));
                    page_ok = false;
                    continue;
                }
            };
            ran += 1;
            let code = out.status.code().unwrap_or(-1);
            eprintln!("{:7.2} s  exit {code}  {}: {}", t.elapsed().as_secs_f64(), c.place, c.line);
            if code != c.expect {
                let err = String::from_utf8_lossy(&out.stderr);
                let tail: Vec<&str> = err.lines().rev().take(6).collect();
                let tail: Vec<&str> = tail.into_iter().rev().collect();
                failures.push(format!(
                    "{}: `{}` exited with {code}, expected {}:\n    {}",
                    c.place,
                    c.line,
                    c.expect,
                    tail.join("\n    ")
                ));
                page_ok = false;
            }
        }
        if page_ok {
            let _ = std::fs::remove_dir_all(&dir);
        } else {
            eprintln!("outputs of {name} kept in {}", dir.display());
        }
    }
    for s in &skipped {
        eprintln!("not run: {s}");
    }
    assert!(failures.is_empty(), "{} documented command(s) failed:\n{}", failures.len(), failures.join("\n"));
    assert!(ran >= 40, "only {ran} documented commands found: is the extraction broken?");
}

#[test]
fn every_guide_page_is_linked_from_the_readme() {
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    let missing: Vec<String> = pages()
        .iter()
        .skip(1)
        .filter_map(|p| p.strip_prefix(root()).ok().map(|r| r.display().to_string()))
        .filter(|r| !readme.contains(&format!("({r})")))
        .collect();
    assert!(missing.is_empty(), "README.md does not link {missing:?}");
    assert!(readme.lines().count() < 200, "README.md has {} lines (keep it under 200)", readme.lines().count());
}

#[test]
fn relative_links_point_to_files() {
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).expect("page");
        let dir = page.parent().expect("page folder");
        for (i, _) in text.match_indices("](") {
            let rest = &text[i + 2..];
            let Some(end) = rest.find(')') else { continue };
            let target = rest[..end].split('#').next().unwrap_or_default();
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") || target.contains(' ') {
                continue;
            }
            if !dir.join(target).exists() {
                broken.push(format!("{}: {target}", page.display()));
            }
        }
    }
    assert!(broken.is_empty(), "links to missing files: {broken:#?}");
}

#[test]
fn formats_page_is_the_shared_specification() {
    let shared = root().join("../shared/formats.md");
    if !shared.exists() {
        eprintln!("{} not present: nothing to compare", shared.display());
        return;
    }
    let ours = std::fs::read_to_string(root().join("docs/formats.md")).expect("docs/formats.md");
    let theirs = std::fs::read_to_string(&shared).expect("shared formats.md");
    assert!(ours == theirs, "docs/formats.md differs from {}: copy it again", shared.display());
}

#[test]
fn extraction_follows_the_conventions() {
    assert!(runs_winslow("winslow solve a.json -o b.json"));
    assert!(runs_winslow("WGPU_BACKEND=vulkan winslow bench --backend gpu"));
    assert!(runs_winslow("cargo run --release --bin winslow -- solve a.json -o b.json"));
    assert!(!runs_winslow("cargo run --bin winslow-viewer -- a.json"));
    assert!(!runs_winslow("bash scripts/test.sh"));
    assert_eq!(as_binary_call("cargo run --release --bin winslow -- check m.json"), "winslow check m.json");
    assert_eq!(stated_exit("winslow corpus --solve   # exit 1"), Ok(1));
    assert_eq!(stated_exit("winslow check m.json # the certificate"), Ok(0));
    assert!(stated_exit("winslow check m.json # exit three").is_err());
}
