//! TEMPORARY: types agreed with the fitting branch; replaced when it merges.
#![allow(missing_docs)]
use crate::curve::Curve;
use crate::knots::KnotVector;
use crate::surface::Side;

#[derive(Debug, Clone)]
pub struct Level {
    pub knots: [KnotVector; 2],
    pub sides: [Curve; 4],
}
impl Level {
    pub fn num_basis(&self) -> usize {
        self.knots[0].num_basis() * self.knots[1].num_basis()
    }
}
#[derive(Debug, Clone)]
pub struct SideFit {
    pub side: Side,
    pub levels: Vec<Curve>,
    pub max_error: Vec<f64>,
    pub rms_error: Vec<f64>,
    pub params: Option<Vec<f64>>,
    pub converged: bool,
}
#[derive(Debug, Clone)]
pub struct Hierarchy {
    pub levels: Vec<Level>,
    pub fits: [SideFit; 4],
    pub tol_abs: f64,
    pub diameter: f64,
}
#[derive(Debug, Clone)]
pub struct FitOptions {
    pub degree: usize,
    pub tol: f64,
    pub initial_elements: usize,
    pub max_levels: usize,
    pub max_elements: usize,
}
impl Default for FitOptions {
    fn default() -> Self {
        Self { degree: 3, tol: 1e-4, initial_elements: 1, max_levels: 14, max_elements: 4096 }
    }
}
pub fn build_hierarchy(_b: &crate::boundary::Boundary, _o: &FitOptions) -> crate::error::Result<Hierarchy> {
    Err(crate::error::Error::Invalid("fit not merged".into()))
}
