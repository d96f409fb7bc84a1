//! The storage every Galerkin problem on one basis keeps, requested once up front: the
//! control points (fixed ones hold the boundary data, free ones are overwritten from the
//! unknowns `c` on every call), the full residual vector, the stencil storage of the
//! vector system (eq. 23's Jacobian, or a Hessian), the block mass matrix `diag(M, M)` of
//! eq. (30) and the scalar preconditioner `K`. [`super::egg`], [`super::weak_form`] and
//! [`super::winslow`] differ only in their kernels.

use std::sync::Arc;

use crate::discrete::assembly::Discretization;
use crate::discrete::stencil::{DeviceOperator, Stencil32};
use crate::linalg::multigrid::GridStencil;
use crate::linalg::sparse::Csr;
use crate::spline::curve::Point;

/// See the module documentation.
#[derive(Debug)]
pub(crate) struct GalerkinState {
    /// Tables, DOF map and patterns of the basis.
    pub disc: Arc<Discretization>,
    /// All control points; the free ones are overwritten from `c` on every call.
    pub cps: Vec<Point>,
    /// The residual of every basis function (interleaved, length `2 n`).
    pub res_full: Vec<f64>,
    /// Stencil storage of the vector system; empty until the first Jacobian (and after
    /// it was packed into [`GalerkinState::packed`]).
    pub stencil: Vec<f64>,
    /// The vector system's stencil storage rounded to single precision, for products
    /// only (`discrete::stencil::Stencil32`; the Jacobian operator of EGG).
    pub packed: Option<Stencil32>,
    /// [`GalerkinState::packed`] uploaded to the assembler's operator back end
    /// (`discrete::stencil::OperatorBackend`), where there is one.
    pub device: Option<Box<dyn DeviceOperator>>,
    /// The unknowns at which [`GalerkinState::device`] was assembled on the back end
    /// itself (`EggAssembler::egg_operator`; empty otherwise): what the CPU needs to
    /// assemble the Jacobian again should a product there fail.
    pub point: Vec<f64>,
    /// That CPU Jacobian, assembled on the first failed product only.
    pub fallback: std::sync::OnceLock<Stencil32>,
    mass: Option<Csr>,
    pstencil: Vec<f64>,
    prec: Csr,
}

impl GalerkinState {
    /// Storage for the basis `disc` with all control points `cps`.
    pub fn new(disc: Arc<Discretization>, cps: Vec<Point>) -> Self {
        let n = disc.dofs.num_total();
        Self {
            cps,
            res_full: vec![0.0; 2 * n],
            stencil: Vec::new(),
            packed: None,
            device: None,
            point: Vec::new(),
            fallback: std::sync::OnceLock::new(),
            mass: None,
            pstencil: Vec::new(),
            prec: Csr::default(),
            disc,
        }
    }

    /// Number of unknowns `2 m`.
    pub fn size(&self) -> usize {
        2 * self.disc.dofs.num_free()
    }

    /// The current unknown vector.
    pub fn unknowns(&self) -> Vec<f64> {
        self.disc.dofs.gather(&self.cps)
    }

    /// Scatter the unknowns `c` into the control points.
    pub fn load(&mut self, c: &[f64]) {
        self.disc.dofs.scatter(c, &mut self.cps);
    }

    /// All control points with unknowns `c` (the stored ones untouched).
    pub fn control_points(&self, c: &[f64]) -> Vec<Point> {
        let mut cps = self.cps.clone();
        self.disc.dofs.scatter(c, &mut cps);
        cps
    }

    /// Load `c` and make sure the stencil storage of the vector system exists.
    pub(crate) fn load_for_jacobian(&mut self, c: &[f64]) {
        self.load(c);
        if self.stencil.is_empty() {
            self.stencil = vec![0.0; self.disc.stencil_len(2)];
        }
    }

    /// The free rows of the full residual into `f`.
    pub(crate) fn restrict_residual(&self, f: &mut [f64]) {
        f.copy_from_slice(&self.disc.restrict(&self.res_full, 2));
    }

    /// The stencil storage gathered into `jac` (the vector pattern is written into it
    /// on the first call only).
    pub(crate) fn gather_jacobian(&self, jac: &mut Csr) {
        let pattern = &self.disc.vector;
        if jac.values.len() != pattern.src.len() || jac.nrows != pattern.csr.nrows {
            jac.assign(&pattern.csr);
        }
        pattern.gather_into(&self.stencil, &mut jac.values);
    }

    /// `diag(M, M)` (eq. 30) in the vector pattern, the scalar mass matrix written into
    /// stencil storage by `fill` on the first call.
    pub fn mass(&mut self, fill: impl FnOnce(&Discretization, &mut [f64])) -> &Csr {
        if self.mass.is_none() {
            let mut st = vec![0.0; self.disc.stencil_len(1)];
            fill(&self.disc, &mut st);
            self.mass = Some(block_mass(&self.disc.vector.csr, &self.disc.scalar.matrix(&st)));
        }
        self.mass.as_ref().expect("set above")
    }

    /// The scalar preconditioner `K`, its stencil storage filled by `fill(disc, cps, st)`
    /// on the current control points.
    pub fn preconditioner(&mut self, fill: impl FnOnce(&Discretization, &[Point], &mut [f64])) -> &Csr {
        if self.pstencil.is_empty() {
            self.pstencil = vec![0.0; self.disc.stencil_len(1)];
        }
        fill(&self.disc, &self.cps, &mut self.pstencil);
        if self.prec.values.len() != self.disc.scalar.src.len() {
            self.prec = self.disc.scalar.csr.clone();
        }
        self.disc.scalar.gather_into(&self.pstencil, &mut self.prec.values);
        &self.prec
    }

    /// [`GalerkinState::preconditioner`] handed over as a grid stencil of the free
    /// functions, made in place in its stencil storage
    /// ([`Discretization::free_grid_stencil`]: no matrix); `None` (the storage kept) where
    /// the free functions are not a rectangle of the basis grid.
    pub fn take_preconditioner_grid(
        &mut self,
        fill: impl FnOnce(&Discretization, &[Point], &mut [f64]),
    ) -> Option<GridStencil> {
        let mut st = std::mem::take(&mut self.pstencil);
        if st.len() != self.disc.stencil_len(1) {
            st = vec![0.0; self.disc.stencil_len(1)];
        }
        fill(&self.disc, &self.cps, &mut st);
        match self.disc.free_grid_stencil(st) {
            Ok(k) => Some(k),
            Err(st) => {
                self.pstencil = st;
                None
            }
        }
    }

    /// [`GalerkinState::preconditioner`] handed over: `K` in a new matrix, its stencil
    /// storage freed after the gather, neither kept. On a basis without periodic replicas
    /// the matrix is built from the stencil storage alone
    /// ([`Discretization::stencil_diagonal_block`]: the same entries, without the scalar
    /// pattern and its gather map).
    pub fn take_preconditioner(&mut self, fill: impl FnOnce(&Discretization, &[Point], &mut [f64])) -> Csr {
        let mut st = std::mem::take(&mut self.pstencil);
        if st.is_empty() {
            st = vec![0.0; self.disc.stencil_len(1)];
        }
        fill(&self.disc, &self.cps, &mut st);
        match self.disc.stencil_diagonal_block(1, &st[..], 0) {
            Some(k) => k,
            None => {
                self.pstencil = st;
                self.preconditioner(|_, _, _| {});
                self.pstencil = Vec::new();
                std::mem::take(&mut self.prec)
            }
        }
    }
}

/// The block mass matrix `diag(M, M)` of eq. (30) in the two-component pattern `vector`,
/// from the scalar mass matrix `m` (in the scalar pattern of the same unknowns).
pub(crate) fn block_mass(vector: &Csr, m: &Csr) -> Csr {
    let ms = m.nrows;
    let mut out = vector.clone();
    for r in 0..out.nrows {
        let (z, f) = (r / ms, r % ms);
        for k in out.row_ptr[r]..out.row_ptr[r + 1] {
            let cidx = out.col_idx[k];
            let (d, g) = (cidx / ms, cidx % ms);
            out.values[k] = if z == d { m.get(f, g) } else { 0.0 };
        }
    }
    out
}
