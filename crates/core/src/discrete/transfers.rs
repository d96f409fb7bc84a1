//! The nested spaces below a discretization for the geometric multigrid preconditioner
//! ([`crate::linalg::multigrid`]): knot vectors coarsened by removing every second
//! element boundary (the inverse of the knot halving of paper §6.3), and the
//! prolongations of the free scalar unknowns between consecutive spaces by exact knot
//! insertion ([`crate::spline::refine::prolongation`]), one 1D operator per direction,
//! `P = P_eta ⊗ P_xi` restricted to the interior functions, held as its two 1D factors
//! ([`crate::linalg::multigrid::TensorProlongation`]: the restriction of the Kronecker product to the interior
//! functions is the product of the 1D operators restricted to the interior ones).
//!
//! A coarse interior function vanishes on the boundary of the parameter square, so its
//! fine coefficients on the boundary functions are zero: `P` maps free coarse unknowns
//! to free fine ones exactly, `N^c_J = sum_i P_iJ N^f_i`.

use super::assembly::Discretization;
use super::dofs::DofMap;
use crate::error::Result;
#[cfg(test)]
use crate::linalg::multigrid::TensorProlongation;
use crate::linalg::sparse::Csr;
use crate::spline::knots::KnotVector;
use crate::spline::refine::prolongation;

/// Coarsest space the hierarchy goes down to: at most this many free scalar unknowns
/// (its operator is factorized directly, [`crate::linalg::multigrid`]).
pub(crate) const COARSEST_FREE: usize = 400;

/// `kv` with every second interior element boundary removed (the breaks at odd
/// positions kept, with their multiplicities), or `None` when `kv` has fewer than
/// three elements or is periodic. The result's knots are a subset of `kv`'s, so its
/// space is nested in `kv`'s.
pub(crate) fn coarsened(kv: &KnotVector) -> Option<KnotVector> {
    if kv.is_periodic() || !kv.is_open() || kv.num_elements() < 3 {
        return None;
    }
    let p = kv.degree();
    let breaks = kv.breaks_with_multiplicity();
    let (a, b) = (breaks[0].0, breaks[breaks.len() - 1].0);
    let mut knots = vec![a; p + 1];
    for (k, &(u, m)) in breaks[1..breaks.len() - 1].iter().enumerate() {
        if k % 2 == 1 {
            knots.extend(std::iter::repeat_n(u, m));
        }
    }
    knots.extend(std::iter::repeat_n(b, p + 1));
    KnotVector::new(p, knots).ok()
}

/// The coarsening of a tensor basis: each direction with at least three elements
/// coarsened, or `None` when neither has.
fn coarsened_basis(knots: &[KnotVector; 2]) -> Option<[KnotVector; 2]> {
    let c = [coarsened(&knots[0]), coarsened(&knots[1])];
    if c[0].is_none() && c[1].is_none() {
        return None;
    }
    let [x, y] = c;
    Some([x.unwrap_or_else(|| knots[0].clone()), y.unwrap_or_else(|| knots[1].clone())])
}

/// The 1D prolongation from `coarse` to `fine` with the first and last rows and columns
/// (the boundary functions) left out, and its zeros.
fn interior_1d(coarse: &KnotVector, fine: &KnotVector) -> Result<Csr> {
    let p = prolongation(coarse, fine)?;
    let (nf, nc) = (p.nrows, p.ncols);
    let rows = (1..nf.saturating_sub(1))
        .map(|i| p.row(i).filter(|&(j, v)| j > 0 && j + 1 < nc && v != 0.0).map(|(j, v)| (j - 1, v)).collect())
        .collect();
    Ok(Csr::from_rows(nc.saturating_sub(2), rows))
}

/// The prolongation of the interior (free) functions of the coarse tensor basis to
/// those of the fine one, `P_eta ⊗ P_xi` with the rows and columns of boundary functions
/// left out, as the product of the two 1D operators restricted to their interior
/// functions (the free functions of [`DofMap::interior`], `xi` fastest).
#[cfg(test)]
pub(crate) fn interior_tensor_prolongation(
    coarse: &[KnotVector; 2],
    fine: &[KnotVector; 2],
) -> Result<TensorProlongation> {
    Ok(TensorProlongation::new(interior_1d(&coarse[0], &fine[0])?, interior_1d(&coarse[1], &fine[1])?))
}

/// The prolongation of the interior (free) functions of the coarse tensor basis to
/// those of the fine one as a stored matrix: `P_eta ⊗ P_xi` with the rows and columns
/// of boundary functions left out (the reference [`interior_tensor_prolongation`] is
/// tested against).
#[cfg(test)]
pub(crate) fn interior_prolongation(coarse: &[KnotVector; 2], fine: &[KnotVector; 2]) -> Result<Csr> {
    let px = prolongation(&coarse[0], &fine[0])?;
    let py = prolongation(&coarse[1], &fine[1])?;
    let full = py.kron(&px);
    let fine_dofs = DofMap::interior([fine[0].num_basis(), fine[1].num_basis()]);
    let coarse_dofs = DofMap::interior([coarse[0].num_basis(), coarse[1].num_basis()]);
    let rows = fine_dofs
        .free()
        .iter()
        .map(|&k| {
            full.row(k)
                .filter_map(|(j, v)| {
                    let f = coarse_dofs.free_index(j);
                    (f != super::dofs::FIXED && v != 0.0).then_some((f, v))
                })
                .collect()
        })
        .collect();
    Ok(Csr::from_rows(coarse_dofs.num_free(), rows))
}

/// The prolongations of the hierarchy below `disc`, finest first: `P_0` maps the free
/// unknowns of the first coarsening to those of `disc`, `P_1` the second coarsening's
/// to the first's, ..., down to a space of at most [`COARSEST_FREE`] free functions (or
/// one that cannot be coarsened). Empty when `disc` is not a patch with every boundary
/// function fixed (periodic or interface sides), or is small already.
#[cfg(test)]
pub(crate) fn free_prolongations(disc: &Discretization) -> Result<Vec<TensorProlongation>> {
    Ok(free_prolongation_factors(disc)?.into_iter().map(TensorProlongation::from).collect())
}

/// [`free_prolongations`] as the 1D factors `[P_xi, P_eta]` of each `P = P_eta ⊗ P_xi`
/// (restricted to the interior functions).
pub(crate) fn free_prolongation_factors(disc: &Discretization) -> Result<Vec<[Csr; 2]>> {
    let shape = disc.shape();
    if disc.dofs != DofMap::interior(shape) {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    let mut fine = disc.knots.clone();
    let mut free = disc.dofs.num_free();
    while free > COARSEST_FREE {
        let Some(coarse) = coarsened_basis(&fine) else { break };
        let p = [interior_1d(&coarse[0], &fine[0])?, interior_1d(&coarse[1], &fine[1])?];
        free = p[0].ncols * p[1].ncols;
        out.push(p);
        fine = coarse;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::multigrid::{Multigrid, Smoother};
    use crate::spline::basis::BasisDerivs;

    /// Value of the interior function with free index `f` of the tensor basis `knots`
    /// at `(u, v)`.
    fn eval_free(knots: &[KnotVector; 2], coeffs: &[f64], u: f64, v: f64) -> f64 {
        let dofs = DofMap::interior([knots[0].num_basis(), knots[1].num_basis()]);
        let nx = knots[0].num_basis();
        let (bu, bv) = (BasisDerivs::at(&knots[0], u, 0), BasisDerivs::at(&knots[1], v, 0));
        let mut s = 0.0;
        for (jj, &nv) in bv.ders(0).iter().enumerate() {
            for (ii, &nu) in bu.ders(0).iter().enumerate() {
                let k = (bv.first() + jj) * nx + bu.first() + ii;
                let f = dofs.free_index(k);
                if f != crate::discrete::dofs::FIXED {
                    s += coeffs[f] * nu * nv;
                }
            }
        }
        s
    }

    #[test]
    fn coarsening_inverts_halving_and_is_nested() {
        for p in 2..=4 {
            let kv = KnotVector::open_uniform(p, 8);
            let c = coarsened(&kv.halved()).unwrap();
            assert_eq!(c, kv);
            assert!(kv.halved().contains(&c));
            // an odd number of elements and a double knot
            let odd = KnotVector::open_uniform(p, 7).with_inserted(&[3.0 / 7.0]);
            let c = coarsened(&odd).unwrap();
            assert!(odd.contains(&c));
            assert!(c.num_elements() < odd.num_elements());
        }
        assert!(coarsened(&KnotVector::open_uniform(3, 2)).is_none());
    }

    /// A random coarse function `sum c_J N^c_J` equals `sum (P c)_i N^f_i` at points all
    /// over the square (exact reproduction of the coarse space).
    #[test]
    fn prolongation_reproduces_coarse_functions() {
        let fine = [
            KnotVector::open_uniform(3, 12).with_inserted(&[0.3, 0.31]),
            KnotVector::open_uniform(2, 9).with_inserted(&[0.5]),
        ];
        let coarse = coarsened_basis(&fine).unwrap();
        let p = interior_prolongation(&coarse, &fine).unwrap();
        let mut rng = crate::testutil::Lcg::new(7);
        let c: Vec<f64> = (0..p.ncols).map(|_| rng.uniform() - 0.5).collect();
        let f = p.apply(&c);
        let mut worst: f64 = 0.0;
        for a in 0..=23 {
            for b in 0..=19 {
                let (u, v) = (a as f64 / 23.0, b as f64 / 19.0);
                worst = worst.max((eval_free(&coarse, &c, u, v) - eval_free(&fine, &f, u, v)).abs());
            }
        }
        assert!(worst < 1e-13, "coarse function not reproduced: {worst}");
    }

    #[test]
    fn hierarchy_ends_small() {
        let disc = Discretization::new([KnotVector::open_uniform(3, 64), KnotVector::open_uniform(3, 8)]);
        let ps = free_prolongations(&disc).unwrap();
        assert!(!ps.is_empty());
        assert_eq!(ps[0].nrows(), disc.dofs.num_free());
        for w in ps.windows(2) {
            assert_eq!(w[0].ncols(), w[1].nrows());
        }
        assert!(ps.last().unwrap().ncols() <= COARSEST_FREE);
    }

    /// The two 1D passes of the tensor prolongation equal the stored interior matrix
    /// `P` (and `P^T`) times a vector to rounding, on degrees (3, 2) with double knots,
    /// and its generated rows are the stored matrix's, entry for entry.
    #[test]
    fn tensor_passes_equal_the_stored_prolongation() {
        let fine = [
            KnotVector::open_uniform(3, 12).with_inserted(&[0.3, 0.31]),
            KnotVector::open_uniform(2, 9).with_inserted(&[0.5, 0.5]),
        ];
        let coarse = coarsened_basis(&fine).unwrap();
        let stored = interior_prolongation(&coarse, &fine).unwrap();
        let t = interior_tensor_prolongation(&coarse, &fine).unwrap();
        assert_eq!((t.nrows(), t.ncols()), (stored.nrows, stored.ncols));
        let stored_t = stored.transpose();
        for k in 0..stored.nrows {
            assert!(t.row(k).eq(stored.row(k)), "row {k} of P");
        }
        for k in 0..stored.ncols {
            assert!(t.row_of_transpose(k).eq(stored_t.row(k)), "row {k} of P^T");
        }
        let mut rng = crate::testutil::Lcg::new(9);
        let c: Vec<f64> = (0..t.ncols()).map(|_| rng.uniform() - 0.5).collect();
        let r: Vec<f64> = (0..t.nrows()).map(|_| rng.uniform() - 0.5).collect();
        let (mut pc, mut ptr) = (vec![0.0; t.nrows()], vec![0.0; t.ncols()]);
        t.prolong(&c, &mut pc);
        t.restrict(&r, &mut ptr);
        for (got, want) in [(pc, stored.apply(&c)), (ptr, stored_t.apply(&r))] {
            let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let err = got.iter().zip(&want).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(err <= 1e-14 * scale, "{err} against {scale}");
        }
    }

    /// The mean residual reduction per V-cycle of the stationary iteration
    /// `x += B (b - K x)` over `cycles` cycles from `x = 0`, `b` random.
    fn reduction(ne: usize, t: f64, smoother: Smoother, cycles: usize) -> f64 {
        let (disc, k) = crate::testutil::stretched_laplacian(ne, t);
        let mut mg = Multigrid::new(free_prolongations(&disc).unwrap(), smoother, 1);
        mg.factor(&k).unwrap();
        let mut rng = crate::testutil::Lcg::new(3);
        let b: Vec<f64> = (0..k.nrows).map(|_| rng.uniform() - 0.5).collect();
        let mut x = vec![0.0; k.nrows];
        let (mut r, mut z) = (b.clone(), vec![0.0; k.nrows]);
        let norm = |v: &[f64]| v.iter().map(|t| t * t).sum::<f64>().sqrt();
        let r0 = norm(&r);
        for _ in 0..cycles {
            mg.apply(&r, &mut z);
            x.iter_mut().zip(&z).for_each(|(xi, zi)| *xi += zi);
            k.mul_vec(&x, &mut r);
            r.iter_mut().zip(&b).for_each(|(ri, bi)| *ri = bi - *ri);
        }
        (norm(&r) / r0).powf(1.0 / cycles as f64)
    }

    /// The V-cycle with the line smoothers (alternating line Gauss–Seidel, the lines one
    /// after the other and by colours, the solver's) alone reduces the residual of the
    /// metric Laplacian by a factor per cycle that does not grow as `h` halves (three
    /// sizes, three to five levels), on the mildly stretched map and on the narrow gap;
    /// symmetric Gauss–Seidel converges on the mild map, slower (printed, with ILU(0) and
    /// Gauss–Seidel on the narrow gap, for comparison: BENCHMARKS.md "Multigrid").
    #[test]
    fn multigrid_reduction_is_independent_of_h() {
        let sizes = [32, 64, 128];
        let lines = [Smoother::ColouredLines, Smoother::Lines, Smoother::SplitColouredLines];
        assert!(lines.contains(&crate::linalg::linsolve::MG_SMOOTHER));
        for t in [3.0, 0.03] {
            for smoother in lines.into_iter().chain([Smoother::SymmetricGaussSeidel, Smoother::Ilu0]) {
                let rho: Vec<f64> = sizes.iter().map(|&ne| reduction(ne, t, smoother, 8)).collect();
                eprintln!("t = {t}, {smoother:?}: reduction per cycle {rho:?} on {sizes:?} elements");
                let bound = match smoother {
                    Smoother::Lines | Smoother::ColouredLines => 0.6,
                    Smoother::SplitColouredLines => 0.8,
                    Smoother::SymmetricGaussSeidel if t > 1.0 => 0.99,
                    _ => continue,
                };
                assert!(rho.iter().all(|&r| r < bound), "t = {t}, {smoother:?}: {rho:?}");
                if lines.contains(&smoother) {
                    assert!(rho[2] < rho[0] + 0.15, "t = {t}, {smoother:?}: reduction grows with 1/h: {rho:?}");
                }
            }
        }
        for ne in sizes {
            let (disc, _) = crate::testutil::stretched_laplacian(ne, 3.0);
            assert!(!free_prolongations(&disc).unwrap().is_empty(), "{ne}: no coarse level");
        }
    }
}
