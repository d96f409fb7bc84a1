//! One discrete problem over all patches of a conforming layout, in the unknowns of the
//! shared numbering [`GlobalDofs`]: the Winslow functional (eq. 16) summed over the
//! patches, `J(c) = Σ_p ∫ W(∇x_p)`, minimized with its exact gradient and Hessian, or
//! the weak form (eq. 14) summed likewise. Both need only first derivatives, so the map
//! may be `C⁰` across the interfaces, and both need `det J > 0` (a bijective start).
//!
//! Each patch is assembled by the single-patch kernels into its own full residual and
//! stencil storage ([`winslow_gradient`], [`flux_form`] with [`weak_flux`]); a global
//! [`SystemPattern`] whose sources point into the concatenated stencils sums the rows
//! and columns of all copies of a shared control point (the way periodic replicas are
//! summed on one patch, [`crate::discrete::pattern`]). Signs and the diagonal shift of
//! the Winslow Hessian follow [`crate::methods::winslow::WinslowProblem`].

use std::sync::Arc;

use super::dofs::GlobalDofs;
use crate::discrete::assembly::Discretization;
use crate::discrete::dofs::DofMap;
use crate::discrete::pattern::{summed_pattern, StencilBasis, SystemPattern};
use crate::error::Result;
use crate::linalg::sparse::Csr;
use crate::methods::density::{lowered, raised, shift_diagonal};
use crate::methods::flux::{flux_form, min_det_j};
use crate::methods::galerkin::block_mass;
use crate::methods::weak_form::{weak_flux, weak_laplace};
use crate::methods::winslow::{winslow_gradient, winslow_laplace, winslow_objective};
use crate::methods::DiscreteProblem;
use crate::spline::curve::Point;
use crate::spline::surface::Surface;

/// What the global problem over all patches is: the improvement's functional
/// ([`Improve`](crate::solve::improve::Improve)), the Winslow functional (eq. 16) or the
/// weak form (eq. 14), summed over the patches.
pub use crate::solve::improve::Improve as Functional;

/// The global problem (see the module documentation).
pub(crate) struct MultipatchProblem {
    functional: Functional,
    discs: Vec<Arc<Discretization>>,
    dofs: Arc<GlobalDofs>,
    cps: Vec<Vec<Point>>,
    scratch: Vec<Vec<Point>>,
    res: Vec<Vec<f64>>,
    stencil: Vec<f64>,
    offsets: Vec<usize>,
    sstencil: Vec<f64>,
    soffsets: Vec<usize>,
    vector: SystemPattern,
    scalar: SystemPattern,
    mass: Option<Csr>,
    prec: Csr,
    diag: Vec<usize>,
    shift: f64,
    raised: bool,
    assembled: Option<Vec<f64>>,
}

impl std::fmt::Debug for MultipatchProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MultipatchProblem")
            .field("functional", &self.functional)
            .field("patches", &self.discs.len())
            .field("unknowns", &self.size())
            .finish()
    }
}

/// The pattern of the `ncomp`-component global system ([`summed_pattern`]): row `z m +
/// f` sums the stencil rows of every copy `(p, k)` of free point `f`; sources are
/// positions in the concatenation of the patches' stencils (`offsets[p]` where patch
/// `p`'s begins).
fn global_pattern(discs: &[Arc<Discretization>], dofs: &GlobalDofs, ncomp: usize, offsets: &[usize]) -> SystemPattern {
    let basis = |p: usize| {
        let (pd, qd) = discs[p].degrees();
        StencilBasis { shape: discs[p].shape(), degrees: [pd, qd], offset: offsets[p] }
    };
    summed_pattern(ncomp, &dofs.copies, basis, |p, kk| dofs.free_of[p][kk])
}

impl MultipatchProblem {
    /// The problem over the patch maps `maps` (their control points: the fixed ones are
    /// kept, the free ones are the start) with the numbering `dofs`; `(p + 2)` Gauss
    /// points per direction (the quadrature of the reported Winslow value).
    pub fn new(functional: Functional, maps: &[Surface], dofs: Arc<GlobalDofs>) -> Result<Self> {
        let mut discs = Vec::with_capacity(maps.len());
        for map in maps {
            let [p, q] = map.degrees();
            let none = DofMap::from_predicate(map.shape(), |_, _| false);
            let disc =
                Discretization::with_dofs(map.knots.clone(), p.max(q) + 2, none).with_weights(map.weights.clone())?;
            discs.push(Arc::new(disc));
        }
        let lens = |ncomp: usize| -> Vec<usize> {
            discs
                .iter()
                .scan(0, |acc, d| {
                    let o = *acc;
                    *acc += d.stencil_len(ncomp);
                    Some(o)
                })
                .collect()
        };
        let (offsets, soffsets) = (lens(2), lens(1));
        let vector = global_pattern(&discs, &dofs, 2, &offsets);
        let scalar = global_pattern(&discs, &dofs, 1, &soffsets);
        let diag =
            (0..vector.csr.nrows).map(|r| vector.csr.position(r, r).expect("the diagonal is in the pattern")).collect();
        let cps: Vec<Vec<Point>> = maps.iter().map(|m| m.control_points.clone()).collect();
        Ok(Self {
            functional,
            res: discs.iter().map(|d| vec![0.0; 2 * d.dofs.num_total()]).collect(),
            stencil: Vec::new(),
            sstencil: Vec::new(),
            prec: scalar.csr.clone(),
            offsets,
            soffsets,
            vector,
            scalar,
            mass: None,
            diag,
            shift: 0.0,
            raised: false,
            assembled: None,
            scratch: cps.clone(),
            cps,
            discs,
            dofs,
        })
    }

    /// The current unknowns.
    pub fn unknowns(&self) -> Vec<f64> {
        self.dofs.gather(&self.cps)
    }

    /// The control points of every patch with unknowns `c`.
    pub(crate) fn patch_control_points(&self, c: &[f64]) -> Vec<Vec<Point>> {
        let mut cps = self.cps.clone();
        self.dofs.scatter(c, &mut cps);
        cps
    }

    /// `J = Σ_p J_p` at unknowns `c` (`+∞` when a patch folds at a quadrature point).
    pub fn winslow(&mut self, c: &[f64]) -> f64 {
        self.dofs.scatter(c, &mut self.scratch);
        self.discs.iter().zip(&self.scratch).map(|(d, cps)| winslow_objective(d, cps)).sum()
    }

    fn total(&self, ncomp: usize) -> usize {
        self.discs.iter().map(|d| d.stencil_len(ncomp)).sum()
    }

    /// Assemble every patch's full residual and, when `with_matrix`, its stencil.
    fn assemble(&mut self, with_matrix: bool) {
        if with_matrix && self.stencil.is_empty() {
            self.stencil = vec![0.0; self.total(2)];
        }
        for (p, disc) in self.discs.iter().enumerate() {
            let st: &mut [f64] = if with_matrix {
                &mut self.stencil[self.offsets[p]..self.offsets[p] + disc.stencil_len(2)]
            } else {
                &mut []
            };
            match self.functional {
                Functional::Winslow => winslow_gradient(disc, &self.cps[p], &mut self.res[p], st),
                Functional::WeakForm => flux_form(disc, &self.cps[p], &mut self.res[p], st, weak_flux),
            }
        }
    }

    /// Sum the patches' residual rows into the free rows.
    fn restrict(&self, f: &mut [f64]) {
        let m = self.dofs.num_free();
        for (fi, copies) in self.dofs.copies.iter().enumerate() {
            let (mut x, mut y) = (0.0, 0.0);
            for &(p, k) in copies {
                x += self.res[p][2 * k];
                y += self.res[p][2 * k + 1];
            }
            f[fi] = x;
            f[m + fi] = y;
        }
    }
}

impl DiscreteProblem for MultipatchProblem {
    fn size(&self) -> usize {
        2 * self.dofs.num_free()
    }

    fn residual(&mut self, c: &[f64], f: &mut [f64]) {
        self.dofs.scatter(c, &mut self.cps);
        self.assemble(false);
        self.assembled = None;
        self.restrict(f);
    }

    fn jacobian(&mut self, c: &[f64], f: &mut [f64], jac: &mut Csr) {
        let winslow = self.functional == Functional::Winslow;
        if winslow && !std::mem::take(&mut self.raised) {
            self.shift = lowered(self.shift);
        }
        if self.assembled.as_deref() != Some(c) {
            self.dofs.scatter(c, &mut self.cps);
            self.assemble(true);
            self.assembled = Some(c.to_vec());
        }
        self.restrict(f);
        if jac.values.len() != self.vector.src.len() || jac.nrows != self.vector.csr.nrows {
            jac.assign(&self.vector.csr);
        }
        self.vector.gather_into(&self.stencil, &mut jac.values);
        if winslow {
            shift_diagonal(self.shift, &self.diag, &mut jac.values);
        }
    }

    fn mass(&mut self) -> &Csr {
        if self.mass.is_none() {
            let mut st = vec![0.0; self.total(1)];
            for (p, disc) in self.discs.iter().enumerate() {
                disc.mass(&mut st[self.soffsets[p]..self.soffsets[p] + disc.stencil_len(1)]);
            }
            self.mass = Some(block_mass(&self.vector.csr, &self.scalar.matrix(&st)));
        }
        self.mass.as_ref().expect("set above")
    }

    fn objective(&mut self, c: &[f64]) -> Option<f64> {
        match self.functional {
            Functional::Winslow => Some(self.winslow(c)),
            Functional::WeakForm => None,
        }
    }

    fn admissible(&mut self, c: &[f64]) -> bool {
        match self.functional {
            Functional::Winslow => true,
            Functional::WeakForm => {
                self.dofs.scatter(c, &mut self.scratch);
                self.discs.iter().zip(&self.scratch).all(|(d, cps)| min_det_j(d, cps) > 0.0)
            }
        }
    }

    fn raise_shift(&mut self) -> bool {
        if self.functional != Functional::Winslow {
            return false;
        }
        let Some(next) = raised(self.shift) else { return false };
        self.shift = next;
        self.raised = true;
        true
    }

    fn preconditioner(&mut self, shift: f64) -> Option<&Csr> {
        if self.sstencil.is_empty() {
            self.sstencil = vec![0.0; self.total(1)];
        }
        for (p, disc) in self.discs.iter().enumerate() {
            let st = &mut self.sstencil[self.soffsets[p]..self.soffsets[p] + disc.stencil_len(1)];
            match self.functional {
                Functional::Winslow => winslow_laplace(disc, &self.cps[p], shift, st),
                Functional::WeakForm => weak_laplace(disc, &self.cps[p], shift, st),
            }
        }
        self.scalar.gather_into(&self.sstencil, &mut self.prec.values);
        Some(&self.prec)
    }

    fn control_points(&self, c: &[f64]) -> Vec<Point> {
        self.patch_control_points(c).concat()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::multipatch::layout::{Interface, Layout, Patch, PatchSide};
    use crate::spline::knots::KnotVector;
    use crate::spline::surface::Side;
    use crate::testutil::Lcg;

    /// Two patches of `[0,1]x[0,1]` and `[1,2]x[0,1]` (degree 2, 3 elements each way),
    /// interior and interface control points perturbed.
    fn pair(seed: u64, noise: f64) -> (Layout, Vec<Surface>, Arc<GlobalDofs>) {
        let k = KnotVector::open_uniform(2, 3);
        let g = k.greville();
        let maps: Vec<Surface> = (0..2)
            .map(|x| {
                let cps = g.iter().flat_map(|&v| g.iter().map(move |&u| [x as f64 + u, v + 0.1 * u * v])).collect();
                Surface::new([k.clone(), k.clone()], cps, None).unwrap()
            })
            .collect();
        let layout = Layout {
            name: "pair".into(),
            patches: maps.iter().enumerate().map(|(i, m)| Patch::from_map(format!("{i}"), m.clone())).collect(),
            interfaces: vec![Interface {
                first: PatchSide { patch: 0, side: Side::East },
                second: PatchSide { patch: 1, side: Side::West },
                reversed: false,
            }],
        };
        let shapes: Vec<[usize; 2]> = maps.iter().map(|m| m.shape()).collect();
        let dofs = Arc::new(GlobalDofs::new(&layout, &shapes, &layout.topologies()).unwrap());
        let mut cps: Vec<Vec<Point>> = maps.iter().map(|m| m.control_points.clone()).collect();
        let mut c = dofs.gather(&cps);
        let mut rng = Lcg::new(seed);
        for v in &mut c {
            *v += noise * (rng.uniform() - 0.5);
        }
        dofs.scatter(&c, &mut cps);
        let maps = maps.into_iter().zip(cps).map(|(m, cp)| Surface { control_points: cp, ..m }).collect();
        (layout, maps, dofs)
    }

    /// The global gradient against central differences of the summed objective, and the
    /// global Hessian (and the weak form's Jacobian) against central differences of the
    /// residual, with unknowns shared across the interface.
    #[test]
    fn global_derivatives_match_finite_differences() {
        for functional in [Functional::Winslow, Functional::WeakForm] {
            let (_, maps, dofs) = pair(3, 0.05);
            let mut prob = MultipatchProblem::new(functional, &maps, dofs.clone()).unwrap();
            let c = prob.unknowns();
            assert_eq!(c.len(), 2 * dofs.num_free());
            // 3x3 interior points per patch and the 3 interior points of the shared side
            assert_eq!(dofs.num_free(), 2 * 9 + 3);
            if functional == Functional::Winslow {
                let mut f = vec![0.0; c.len()];
                prob.residual(&c, &mut f);
                let h = 1e-6;
                let mut err = 0.0f64;
                let mut scale = 0.0f64;
                for j in 0..c.len() {
                    let (mut cp, mut cm) = (c.clone(), c.clone());
                    cp[j] += h;
                    cm[j] -= h;
                    let fd = -(prob.winslow(&cp) - prob.winslow(&cm)) / (2.0 * h);
                    err = err.max((fd - f[j]).abs());
                    scale = scale.max(fd.abs());
                }
                assert!(err < 1e-7 * scale, "gradient: {err} (scale {scale})");
            }
            let (err, scale) = crate::methods::jacobian_fd_mismatch(&mut prob, &c, 1e-6);
            assert!(err < 1e-7 * scale, "{functional:?}: {err} (scale {scale})");
        }
    }
}
