//! # winslow-viewer
//!
//! The desktop viewer of winslow: open a boundary or a map, look at its `det J` heat
//! map (paper eq. 43) in the physical domain and in the parameter square, its grid
//! lines and control net, the folded elements and the verdict of the solver, and solve
//! a boundary in a background thread while watching the residuals. A general domain or
//! plane graph opens as its automatic multipatch layout (patch borders, irregular
//! vertices), solved like any layout. A THB map (a file, or a solve with THB refinement)
//! shows its `det J` sampled on its active cells, the cells themselves and the THB
//! certificate's verdict. A volume (trivariate map) opens as three
//! orthogonal slices with their `det J` heat maps, one slider per parameter direction.
//!
//! The numbers all come from the core crate `winslow`; this crate only arranges and
//! draws them. State and logic (loading, the view transform, the colour scale, the
//! folded-element list, the solve job) live in modules without drawing code and are
//! unit-tested; [`app`] draws them with egui.

pub mod app;
pub mod certificate;
pub mod colour;
pub mod export;
pub mod folds;
pub mod layout_view;
pub mod mesh_overlay;
mod paint;
pub mod sampler;
pub mod scene;
mod sections;
pub mod solve_job;
pub mod state;
pub mod thb_view;
pub mod view;
pub mod volume_view;

pub use app::ViewerApp;
pub use sampler::{CpuSampler, DetJSampler};
pub use state::ViewerState;
