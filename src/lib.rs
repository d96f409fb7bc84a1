#![doc = include_str!("../README.md")]
//!
//! ---
//!
//! This package is the workspace's facade: it re-exports the core crate so that the
//! top-level `examples/` and `tests/` are ordinary cargo targets, and its documentation is
//! the README above, whose library snippet runs as a doctest.
pub use winslow::*;
