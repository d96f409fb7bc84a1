//! Helpers of the workspace's tests (behind the `testutil` feature): the bundled test
//! data, deterministic pseudo-random numbers (no external crate), and the readers'
//! exercisers and mutators of the fuzz targets.

use std::path::{Path, PathBuf};

/// The bundled test data folder, `tests/data` at the workspace root (the shared
/// geometries, contours, rings, maps and G+Smo files).
pub fn data_dir() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).expect("crates/core sits two levels down");
    root.join("tests").join("data")
}

/// A bundled test file or folder: `data("gismo/duck.json")` is
/// `tests/data/gismo/duck.json` at the workspace root.
pub fn data(rel: &str) -> PathBuf {
    data_dir().join(rel)
}

/// The bundled files directly in the test data folder `rel` (`""`: `tests/data` itself)
/// whose extension is `ext`, sorted by name.
pub fn data_files(rel: &str, ext: &str) -> Vec<PathBuf> {
    let dir = data(rel);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("a readable folder entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    v.sort();
    v
}

/// A 64-bit linear congruential generator (Knuth's MMIX constants).
#[derive(Debug, Clone)]
pub struct Lcg(u64);

impl Lcg {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407))
    }
    /// Next raw value.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        self.0 ^ (self.0 >> 29)
    }
    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform integer in `0..n` (0 when `n == 0`).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }
}

pub mod exercise;
pub mod mutate;
