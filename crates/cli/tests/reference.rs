//! `docs/cli.md` is the command-line reference generated from the clap definitions
//! (`winslow reference`, hidden from the help); this test fails when the committed file
//! is not what the current definitions give. Regenerate it with
//! `cargo run --bin winslow -- reference > docs/cli.md`, or run this test with
//! `WINSLOW_BLESS=1` (`WINSLOW_BLESS=1 cargo test -p winslow-cli --test reference`).

use std::path::Path;
use std::process::Command;

#[test]
fn committed_reference_is_current() {
    let out = Command::new(env!("CARGO_BIN_EXE_winslow")).arg("reference").output().expect("run winslow reference");
    assert!(out.status.success(), "winslow reference failed: {}", String::from_utf8_lossy(&out.stderr));
    let generated = String::from_utf8(out.stdout).expect("UTF-8 reference");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/cli.md");
    if std::env::var_os("WINSLOW_BLESS").is_some() {
        winslow::io::write_bytes(&path, generated.as_bytes()).expect("write docs/cli.md");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != generated {
        let line = committed.lines().zip(generated.lines()).position(|(a, b)| a != b);
        panic!(
            "docs/cli.md is not current (first difference at line {}); regenerate it: \
             cargo run --bin winslow -- reference > docs/cli.md \
             (or WINSLOW_BLESS=1 cargo test -p winslow-cli --test reference)",
            line.map_or(committed.lines().count().min(generated.lines().count()) + 1, |l| l + 1)
        );
    }
}

#[test]
fn reference_covers_every_command_and_hides_itself() {
    let out = Command::new(env!("CARGO_BIN_EXE_winslow")).arg("reference").output().expect("run winslow reference");
    let text = String::from_utf8_lossy(&out.stdout);
    let help = Command::new(env!("CARGO_BIN_EXE_winslow")).arg("--help").output().expect("run winslow --help");
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(!help.contains("reference"), "`reference` must stay hidden from --help:\n{help}");
    let commands: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 14, "commands in --help: {commands:?}");
    for c in commands {
        assert!(text.contains(&format!("\n## winslow {c}\n")), "no section for `winslow {c}`");
        let sub = Command::new(env!("CARGO_BIN_EXE_winslow")).args([c, "--help"]).output().expect("run --help");
        let sub = String::from_utf8_lossy(&sub.stdout);
        assert!(sub.contains("Example"), "`winslow {c} --help` has no example:\n{sub}");
    }
}
