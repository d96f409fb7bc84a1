//! Helpers shared by the `winslow` binary's integration tests: the binary, the bundled
//! test data (`winslow::testutil`) and JSON read back from a run or a written file.
// each test file uses its own subset
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

pub use winslow::testutil::data_dir as data;

/// The `winslow` binary built for these tests.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_winslow"))
}

/// A run's standard output parsed as one JSON value (`--json`); the message carries
/// both streams when it is not JSON.
pub fn stdout_json(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not JSON ({e}):\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// A written JSON file (map, report, layout, sweep table).
pub fn read_json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}
