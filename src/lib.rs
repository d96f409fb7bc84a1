//! Facade of the winslow workspace: re-exports the core crate so that the
//! top-level `examples/` and `tests/` are ordinary cargo targets.
pub use winslow::*;
