//! Criterion benchmarks of the sparse Cholesky factorization of a direct solve, whole
//! (faer's supernodal factorization in the basis's nested-dissection order, as
//! `linsolve` runs it below `SPLIT_MIN` unknowns) against split at the order's top
//! separator with the two halves factorized at once (`SplitCholesky`), on the Winslow
//! Hessian (eq. 16, projected onto the definite matrices) of the EGG maps of puzzle4
//! and jigsaw01: numeric factorization, and one solve. Run with `cargo bench --workspace
//! --bench cholesky`.

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymmetricOrdering};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use winslow::discrete::assembly::Discretization;
use winslow::discrete::dofs::DofMap;
use winslow::linalg::ordering::{interleave, inverse};
use winslow::linalg::sparse::Csr;
use winslow::linalg::split_cholesky::SplitCholesky;
use winslow::methods::winslow::WinslowProblem;
use winslow::methods::DiscreteProblem;
use winslow::solve::options::SolveOptions;
use winslow::{read_boundary, solve, ReadOptions, Topology};

const GEOMETRIES: [&str; 2] = ["gismo/puzzle4", "gismo/jigsaw01"];

/// `∇²J` at the EGG map (fully projected, definite) and its order.
fn hessian(name: &str) -> (Csr, Vec<usize>, Vec<f64>) {
    let path = winslow::testutil::data(&format!("{name}.json"));
    let boundary = read_boundary(&path, &ReadOptions::default()).expect("a shared geometry");
    let map = solve(&boundary, &SolveOptions::default()).expect("the EGG solve").map;
    let [p, q] = map.degrees();
    let dofs = DofMap::for_basis(&map.knots, &Topology::dirichlet()).expect("the DOF map");
    let disc = Arc::new(
        Discretization::with_dofs(map.knots.clone(), p.max(q) + 2, dofs)
            .with_weights(map.weights.clone())
            .expect("the weights"),
    );
    let c0 = disc.dofs.gather(&map.control_points);
    let mut prob = WinslowProblem::new(disc.clone(), map.control_points.clone());
    // 0.3, 0.9, then 1: the projected Hessian
    for _ in 0..3 {
        prob.raise_shift();
    }
    let (mut f, mut jac) = (vec![0.0; c0.len()], Csr::default());
    prob.jacobian(&c0, &mut f, &mut jac);
    for v in jac.values.iter_mut() {
        *v = -*v;
    }
    let order = interleave(&disc.ordering, 2);
    (jac, order, f)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("cholesky");
    g.sample_size(20);
    for name in GEOMETRIES {
        let (a, order, b) = hessian(name);
        let label = format!("{}-{}", name.rsplit('/').next().unwrap_or(name), a.nrows);
        // whole: as `linsolve`'s `Cholesky` (the CSR of a symmetric matrix is its CSC)
        let inv = inverse(&order);
        let pattern = SymbolicSparseColMatRef::new_checked(a.nrows, a.ncols, &a.row_ptr, None, &a.col_idx);
        let ord = SymmetricOrdering::Custom(PermRef::new_checked(&order, &inv, a.nrows));
        let symbolic = factorize_symbolic_cholesky(pattern, Side::Lower, ord, CholeskySymbolicParams::default())
            .expect("the analysis");
        let mut values = vec![0.0; symbolic.len_val()];
        let mut scratch = MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
        let factor = |values: &mut [f64], scratch: &mut MemBuffer| {
            symbolic
                .factorize_numeric_llt(
                    values,
                    SparseColMatRef::new(pattern, &a.values),
                    Side::Lower,
                    Default::default(),
                    Par::Seq,
                    MemStack::new(scratch),
                    Default::default(),
                )
                .map(|_| ())
                .expect("definite")
        };
        g.bench_with_input(BenchmarkId::new("whole-factor", &label), &(), |bch, _| {
            bch.iter(|| factor(&mut values, &mut scratch))
        });
        factor(&mut values, &mut scratch);
        let mut solve_scratch = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        let mut x = b.clone();
        g.bench_with_input(BenchmarkId::new("whole-solve", &label), &(), |bch, _| {
            bch.iter(|| {
                x.copy_from_slice(&b);
                let n = x.len();
                LltRef::new(&symbolic, &values).solve_in_place_with_conj(
                    Conj::No,
                    MatMut::from_column_major_slice_mut(&mut x, n, 1),
                    Par::Seq,
                    MemStack::new(&mut solve_scratch),
                );
            })
        });
        let mut split = SplitCholesky::<f64>::analyze(&a, &order).expect("a top separator");
        g.bench_with_input(BenchmarkId::new("split-factor", &label), &(), |bch, _| {
            bch.iter(|| split.factor(&a).expect("definite"))
        });
        g.bench_with_input(BenchmarkId::new("split-solve", &label), &(), |bch, _| {
            bch.iter(|| {
                x.copy_from_slice(&b);
                split.solve_columns(&mut x);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
