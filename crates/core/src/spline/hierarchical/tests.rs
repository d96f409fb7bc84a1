//! THB basis and maps against their mathematics: two-scale relation against knot
//! insertion, partition of unity, linear independence, admissibility, exact
//! reproduction and nestedness under refinement, Bézier patches and tensor conversion.

use super::map::HierarchicalMap;
use super::truncation::{insert_knot, LevelCoefficients, Sparse};
use super::*;
use crate::spline::refine::prolongation;
use crate::spline::surface::Surface;
use crate::testutil::Lcg;

fn kv(p: usize, breaks: &[f64]) -> KnotVector {
    KnotVector::open_from_breaks(p, breaks, 1)
}

/// A hierarchy refined towards the south-west corner and around an interior cell.
fn sample_basis(p: usize, q: usize, m: usize) -> HierarchicalBasis {
    let mut b =
        HierarchicalBasis::new([kv(p, &[0.0, 0.2, 0.45, 0.6, 0.8, 1.0]), kv(q, &[0.0, 0.3, 0.5, 0.75, 1.0])]).unwrap();
    b.refine(&[(0, [0, 0]), (0, [2, 1])], m).unwrap();
    b.refine(&[(1, [0, 0]), (1, [5, 3])], m).unwrap();
    b.refine(&[(2, [1, 0])], m).unwrap();
    b
}

#[test]
fn knot_insertion_of_one_function_matches_the_prolongation() {
    for p in 1..=4 {
        let coarse = kv(p, &[0.0, 0.1, 0.35, 0.5, 0.9, 1.0]);
        let fine = coarse.halved();
        let pm = prolongation(&coarse, &fine).unwrap();
        let b = HierarchicalBasis::new([coarse.clone(), coarse.clone()]).unwrap();
        for s in 0..coarse.num_basis() {
            let ch = b.children_1d(0, 0, s);
            for i in 0..fine.num_basis() {
                let want: f64 = pm.row(i).filter(|e| e.0 == s).map(|e| e.1).sum();
                let got: f64 = ch.iter().filter(|e| e.0 == i).map(|e| e.1).sum();
                assert!((want - got).abs() < 1e-14, "p={p} s={s} i={i}: {got} vs {want}");
            }
        }
    }
    // a knot inserted into a local sequence keeps the function
    let mut t = vec![0.0, 0.2, 0.3, 0.7, 0.9];
    let mut c = vec![1.0];
    insert_knot(3, &mut t, &mut c, 0.5);
    assert_eq!(t, vec![0.0, 0.2, 0.3, 0.5, 0.7, 0.9]);
    assert_eq!(c.len(), 2);
}

#[test]
fn partition_of_unity_and_non_negativity() {
    for (p, q, m) in [(2, 2, 2), (3, 2, 2), (3, 3, 3), (1, 2, 2)] {
        let b = sample_basis(p, q, m);
        assert!(b.num_levels() >= 4, "refined to level 3");
        let mut rng = Lcg::new(3);
        for _ in 0..300 {
            let (u, v) = (rng.uniform(), rng.uniform());
            let vals = b.eval_basis(u, v);
            let s: f64 = vals.iter().map(|x| x.1[0]).sum();
            let su: f64 = vals.iter().map(|x| x.1[1]).sum();
            let sv: f64 = vals.iter().map(|x| x.1[2]).sum();
            assert!((s - 1.0).abs() < 1e-13, "p={p} q={q}: sum {s} at ({u}, {v})");
            assert!(su.abs() < 1e-10 && sv.abs() < 1e-10, "derivatives of unity {su} {sv}");
            assert!(vals.iter().all(|x| x.1[0] >= -1e-14), "negative THB function at ({u}, {v})");
        }
    }
}

/// Rank of a dense matrix (rows of equal length) by Gaussian elimination with full pivoting.
fn rank(mut a: Vec<Vec<f64>>, tol: f64) -> usize {
    let (rows, cols) = (a.len(), a[0].len());
    let mut r = 0;
    for c in 0..cols {
        let Some(piv) = (r..rows).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs())) else { break };
        if a[piv][c].abs() <= tol {
            continue;
        }
        a.swap(r, piv);
        for i in r + 1..rows {
            let f = a[i][c] / a[r][c];
            for k in c..cols {
                a[i][k] -= f * a[r][k];
            }
        }
        r += 1;
    }
    r
}

/// The values of the THB functions (one row each) at `per_cell` random points inside
/// every active cell.
fn cell_collocation(b: &HierarchicalBasis, rng: &mut Lcg, per_cell: usize) -> Vec<Vec<f64>> {
    let mut rows = Vec::new();
    for (l, c) in b.active_cells() {
        let [[a, bb], [cc, dd]] = b.cell_bounds(l, c);
        for _ in 0..per_cell {
            let mut row = vec![0.0; b.len()];
            let (u, v) = (a + (bb - a) * rng.uniform(), cc + (dd - cc) * rng.uniform());
            for (k, val) in b.eval_basis(u, v) {
                row[k] = val[0];
            }
            rows.push(row);
        }
    }
    rows
}

#[test]
fn linear_independence_by_collocation() {
    for (p, q, m) in [(2, 2, 2), (3, 3, 3), (1, 1, 2)] {
        let b = sample_basis(p, q, m);
        let n = b.len();
        let mut rng = Lcg::new(11);
        let rows: Vec<Vec<f64>> = (0..4 * n)
            .map(|_| {
                let mut row = vec![0.0; n];
                for (k, v) in b.eval_basis(rng.uniform(), rng.uniform()) {
                    row[k] = v[0];
                }
                row
            })
            .collect();
        // plus points inside the small cells, so that every function is sampled
        let mut rows = rows;
        rows.extend(cell_collocation(&b, &mut rng, (p + 1) * (q + 1)));
        assert_eq!(rank(rows, 1e-12), n, "p={p} q={q}: {n} THB functions");
    }
}

#[test]
fn one_level_is_the_tensor_basis() {
    let b = HierarchicalBasis::new([kv(2, &[0.0, 0.5, 1.0]), kv(3, &[0.0, 1.0])]).unwrap();
    assert_eq!(b.len(), 4 * 4);
    assert_eq!(b.num_levels(), 1);
    assert_eq!(b.active_cells().len(), 2);
}

#[test]
fn admissibility_bounds_the_levels_on_every_cell() {
    for m in [2, 3] {
        let mut b =
            HierarchicalBasis::new([kv(2, &[0.0, 0.25, 0.5, 0.75, 1.0]), kv(2, &[0.0, 0.25, 0.5, 0.75, 1.0])]).unwrap();
        // refine towards an interior point, five times
        for _ in 0..5 {
            let (l, c) = b.cell_at(0.51, 0.49);
            b.refine(&[(l, c)], m).unwrap();
        }
        assert_eq!(b.cell_at(0.51, 0.49).0, 5);
        for (l, c) in b.active_cells() {
            let [[a, bb], [cc, dd]] = b.cell_bounds(l, c);
            let vals = b.eval_basis(0.5 * (a + bb), 0.5 * (cc + dd));
            let levels: BTreeSet<usize> = vals.iter().map(|v| b.active_functions()[v.0].0).collect();
            let span = levels.last().unwrap() - levels.first().unwrap() + 1;
            assert!(span <= m, "m={m}: cell ({l}, {c:?}) sees levels {levels:?}");
        }
    }
    // a marked cell that is not active is a typed error
    let mut b = sample_basis(2, 2, 2);
    assert!(b.refine(&[(0, [0, 0])], 2).is_err());
    assert!(b.refine(&[(0, [99, 0])], 2).is_err());
    assert!(b.refine(&[(1, [0, 0])], 1).is_err());
}

fn random_surface(p: usize, q: usize, seed: u64) -> Surface {
    let knots = [kv(p, &[0.0, 0.3, 0.5, 1.0]), kv(q, &[0.0, 0.4, 0.7, 1.0])];
    let n = knots[0].num_basis() * knots[1].num_basis();
    let mut rng = Lcg::new(seed);
    let cps = (0..n).map(|_| [rng.uniform(), rng.uniform()]).collect();
    Surface::new(knots, cps, None).unwrap()
}

#[test]
fn tensor_map_is_reproduced_and_refinement_keeps_the_map() {
    for (p, q) in [(2, 2), (3, 2), (2, 3), (1, 1)] {
        let s = random_surface(p, q, 5 + p as u64);
        let mut map = HierarchicalMap::from_surface(&s).unwrap();
        let mut rng = Lcg::new(9);
        for step in 0..4 {
            // refine the active cell around a random point
            let (l, c) = map.basis.cell_at(rng.uniform(), rng.uniform());
            let (l2, c2) = map.basis.cell_at(0.01, 0.99);
            map = map.refined(&[(l, c), (l2, c2)], 2).unwrap();
            for _ in 0..200 {
                let (u, v) = (rng.uniform(), rng.uniform());
                let (a, b) = (map.derivs(u, v), s.derivs(u, v, 2));
                for z in 0..2 {
                    assert!((a.x[z] - b.x[z]).abs() < 1e-13, "p={p} q={q} step {step}: x");
                    assert!((a.xu[z] - b.xu[z]).abs() < 1e-11 && (a.xv[z] - b.xv[z]).abs() < 1e-11, "gradient");
                    assert!((a.xuv[z] - b.xuv[z]).abs() < 1e-8, "mixed derivative");
                }
            }
        }
        assert!(map.basis.num_levels() >= 4);
    }
}

#[test]
fn refinement_keeps_a_genuine_thb_map() {
    // a map with coefficients only the THB space has (random on every active function)
    let b = sample_basis(2, 3, 2);
    let mut rng = Lcg::new(21);
    let cps: Vec<[f64; 2]> = (0..b.len()).map(|_| [rng.uniform(), rng.uniform()]).collect();
    let map = HierarchicalMap::new(b, cps).unwrap();
    let cells: Vec<(usize, Index2)> = map.basis.active_cells().into_iter().step_by(5).take(4).collect();
    let fine = map.refined(&cells, 3).unwrap();
    assert!(fine.basis.len() > map.basis.len());
    for _ in 0..300 {
        let (u, v) = (rng.uniform(), rng.uniform());
        let (a, b) = (map.eval(u, v), fine.eval(u, v));
        assert!((a[0] - b[0]).abs() < 1e-13 && (a[1] - b[1]).abs() < 1e-13, "({u}, {v}): {a:?} vs {b:?}");
    }
    // and the tensor conversion is the same map
    let t = fine.to_surface().unwrap();
    for _ in 0..300 {
        let (u, v) = (rng.uniform(), rng.uniform());
        let (a, b) = (fine.derivs(u, v), t.derivs(u, v, 1));
        for z in 0..2 {
            assert!((a.x[z] - b.x[z]).abs() < 1e-12, "tensor conversion at ({u}, {v})");
            assert!((a.xu[z] - b.xu[z]).abs() < 1e-9 && (a.xv[z] - b.xv[z]).abs() < 1e-9);
        }
    }
    // the tensor space is the coarsest with the active cells' edges: fewer knots than the finest level
    let finest = fine.basis.knots(fine.basis.num_levels() - 1);
    assert!(t.knots[0].knots().len() < finest[0].knots().len());
}

#[test]
fn map_derivatives_match_finite_differences() {
    let b = sample_basis(3, 3, 2);
    let mut rng = Lcg::new(2);
    let cps: Vec<[f64; 2]> = (0..b.len()).map(|_| [rng.uniform(), rng.uniform()]).collect();
    let map = HierarchicalMap::new(b, cps).unwrap();
    let h = 1e-6;
    for _ in 0..200 {
        let (u, v) = (0.01 + 0.98 * rng.uniform(), 0.01 + 0.98 * rng.uniform());
        let d = map.derivs(u, v);
        let (xp, xm) = (map.eval(u + h, v), map.eval(u - h, v));
        let (yp, ym) = (map.eval(u, v + h), map.eval(u, v - h));
        for z in 0..2 {
            // the map is C^2 for cubics: central differences across cell edges are fine
            assert!(((xp[z] - xm[z]) / (2.0 * h) - d.xu[z]).abs() < 1e-6 * (1.0 + d.xu[z].abs()));
            assert!(((yp[z] - ym[z]) / (2.0 * h) - d.xv[z]).abs() < 1e-6 * (1.0 + d.xv[z].abs()));
        }
    }
}

#[test]
fn bezier_patches_equal_the_map_on_their_cells() {
    let b = sample_basis(2, 3, 2);
    let mut rng = Lcg::new(4);
    let cps: Vec<[f64; 2]> = (0..b.len()).map(|_| [rng.uniform(), rng.uniform()]).collect();
    let map = HierarchicalMap::new(b, cps).unwrap();
    let patches = map.bezier_patches().unwrap();
    assert_eq!(patches.len(), map.basis.active_cells().len());
    for (l, c, patch) in &patches {
        let [[a, bb], [cc, dd]] = map.basis.cell_bounds(*l, *c);
        for _ in 0..10 {
            let (u, v) = (a + (bb - a) * rng.uniform(), cc + (dd - cc) * rng.uniform());
            let (x, y) = (map.eval(u, v), patch.eval(u, v));
            assert!((x[0] - y[0]).abs() < 1e-13 && (x[1] - y[1]).abs() < 1e-13, "cell ({l}, {c:?})");
        }
    }
}

#[test]
fn restriction_of_each_function_sums_to_the_map() {
    // the level coefficients of the map are the combination of those of the functions
    let b = sample_basis(2, 2, 2);
    let mut rng = Lcg::new(8);
    let cps: Vec<[f64; 2]> = (0..b.len()).map(|_| [rng.uniform(), rng.uniform()]).collect();
    let map = HierarchicalMap::new(b.clone(), cps.clone()).unwrap();
    let mut pts = map.level_coefficients();
    let mut sparse = LevelCoefficients::<Sparse>::new(&b, |k| vec![(k, 1.0)]);
    for (l, c) in b.active_cells() {
        let (np, ns) = (pts.cell_net(l, c), sparse.cell_net(l, c));
        for (x, s) in np.iter().zip(&ns) {
            let y = s.iter().fold([0.0, 0.0], |a, &(k, w)| [a[0] + w * cps[k][0], a[1] + w * cps[k][1]]);
            assert!((x[0] - y[0]).abs() < 1e-14 && (x[1] - y[1]).abs() < 1e-14);
        }
    }
}

#[test]
fn from_refined_rebuilds_the_hierarchy() {
    let b = sample_basis(2, 2, 2);
    let refined: Vec<Vec<Index2>> = (0..b.num_levels()).map(|l| b.refined_list(l)).collect();
    let c = HierarchicalBasis::from_refined(b.knots(0).clone(), &refined).unwrap();
    assert_eq!(c.active_functions(), b.active_functions());
    // a refined cell outside its level's domain is a typed error
    let bad = vec![vec![], vec![[7, 7]]];
    assert!(HierarchicalBasis::from_refined(b.knots(0).clone(), &bad).is_err());
}

/// The control net of a THB map: on one level the tensor net (`nx (ny - 1) + ny (nx - 1)`
/// segments). After refinement, the identity `x(ξ, η) = (ξ, η)` keeps its control points
/// at the Greville abscissae of each active function's own level (the THB basis preserves
/// the coefficients of every function of the coarsest space it lies in: the identity lies
/// in `S^0`), so every segment joins two functions of one level that are neighbours in its
/// index grid and is the axis-parallel step between their Greville abscissae; every pair of
/// such neighbours is a segment.
#[test]
fn the_control_net_joins_neighbouring_active_functions_of_one_level() {
    let knots = [kv(3, &[0.0, 0.25, 0.5, 0.75, 1.0]), kv(2, &[0.0, 0.3, 0.6, 1.0])];
    let (gx, gy) = (knots[0].greville(), knots[1].greville());
    let cps = gy.iter().flat_map(|&y| gx.iter().map(move |&x| [x, y])).collect();
    let s = Surface::new(knots, cps, None).unwrap();
    let map = HierarchicalMap::from_surface(&s).unwrap();
    let [nx, ny] = [gx.len(), gy.len()];
    assert_eq!(map.control_net().len(), nx * (ny - 1) + ny * (nx - 1));
    // three of the four columns of coarse cells, then a 4 x 4 block of level-1 cells
    let coarse: Vec<(usize, Index2)> = (1..4).flat_map(|i| (0..3).map(move |j| (0, [i, j]))).collect();
    let map = map.refined(&coarse, 2).unwrap();
    let fine: Vec<(usize, Index2)> = (3..7).flat_map(|i| (1..5).map(move |j| (1, [i, j]))).collect();
    let map = map.refined(&fine, 2).unwrap();
    assert_eq!(map.basis.num_levels(), 3);
    let b = &map.basis;
    let greville = |l: usize, f: Index2| [b.knots(l)[0].greville()[f[0]], b.knots(l)[1].greville()[f[1]]];
    for (k, &(l, f)) in b.active_functions().iter().enumerate() {
        let (x, g) = (map.control_points[k], greville(l, f));
        assert!((x[0] - g[0]).abs() < 1e-13 && (x[1] - g[1]).abs() < 1e-13, "({l}, {f:?}): {x:?} vs {g:?}");
    }
    let net = map.control_net();
    let mut expected = 0;
    for &(l, [i, j]) in b.active_functions() {
        expected += usize::from(b.index_of(l, [i + 1, j]).is_some()) + usize::from(b.index_of(l, [i, j + 1]).is_some());
    }
    assert_eq!(net.len(), expected);
    let mut levels = BTreeSet::new();
    for &[a, c] in &net {
        let ((la, fa), (lc, fc)) = (b.active_functions()[a], b.active_functions()[c]);
        assert_eq!(la, lc, "one level");
        assert!(fc == [fa[0] + 1, fa[1]] || fc == [fa[0], fa[1] + 1], "{fa:?} {fc:?}");
        let (pa, pc) = (map.control_points[a], map.control_points[c]);
        let (ga, gc) = (greville(la, fa), greville(lc, fc));
        for d in 0..2 {
            assert!(((pc[d] - pa[d]) - (gc[d] - ga[d])).abs() < 1e-13);
        }
        assert!((gc[0] > ga[0] && gc[1] == ga[1]) || (gc[0] == ga[0] && gc[1] > ga[1]), "{ga:?} {gc:?}");
        levels.insert(la);
    }
    assert!(levels.len() >= 2, "segments on the coarse and a finer level: {levels:?}");
}

/// `map` (equal to the tensor map `s`) refined `steps` times at a random active cell and at
/// the cell at `at`, class 2: after each step still `s` at 200 random points (the spaces
/// are nested, the prolongation exact) and a partition of unity there; refined past the
/// given levels at the end.
fn refined_keeping(
    mut map: HierarchicalMap,
    s: &Surface,
    rng: &mut Lcg,
    steps: usize,
    at: [f64; 2],
) -> HierarchicalMap {
    for step in 0..steps {
        let (l, c) = map.basis.cell_at(rng.uniform(), rng.uniform());
        let (l2c, c2) = map.basis.cell_at(at[0], at[1]);
        map = map.refined(&[(l, c), (l2c, c2)], 2).unwrap();
        for _ in 0..200 {
            let (u, v) = (rng.uniform(), rng.uniform());
            let (a, t) = (map.eval(u, v), s.eval(u, v));
            assert!((a[0] - t[0]).abs() < 1e-13 && (a[1] - t[1]).abs() < 1e-13, "step {step} at ({u}, {v})");
            let sum: f64 = map.basis.eval_basis(u, v).iter().map(|x| x.1[0]).sum();
            assert!((sum - 1.0).abs() < 1e-13, "partition of unity: {sum}");
        }
    }
    assert!(map.basis.num_levels() >= 4, "refined past the given levels");
    map
}

/// Given levels that split each element off its midpoint (an input basis's knots, every
/// other break removed below): the two-scale relation is knot insertion of the finer
/// level's knots, a tensor map on level 0 refined through the given levels and past them
/// (halving) stays the same map (exact prolongation), the basis is a partition of unity,
/// and a level that does not split every element in two is refused with its level named.
#[test]
fn given_levels_are_nested_and_refinement_through_them_keeps_the_map() {
    let coarse = [kv(3, &[0.0, 0.3, 0.5, 1.0]), kv(2, &[0.0, 0.4, 0.7, 1.0])];
    let l1 = [coarse[0].with_inserted(&[0.1, 0.42, 0.9]), coarse[1].with_inserted(&[0.05, 0.6, 0.71])];
    let l2 = [l1[0].with_inserted(&[0.02, 0.2, 0.31, 0.47, 0.6, 0.95]), l1[1].halved()];
    let b = HierarchicalBasis::with_levels(vec![coarse.clone(), l1.clone(), l2.clone()]).unwrap();
    assert_eq!(b.given_levels().len(), 2);
    // the two-scale relation of level 0 to level 1 is the knot insertion matrix
    for d in 0..2 {
        let pm = prolongation(&coarse[d], &l1[d]).unwrap();
        for s in 0..coarse[d].num_basis() {
            let ch = b.children_1d(0, d, s);
            for i in 0..l1[d].num_basis() {
                let want: f64 = pm.row(i).filter(|e| e.0 == s).map(|e| e.1).sum();
                let got: f64 = ch.iter().filter(|e| e.0 == i).map(|e| e.1).sum();
                assert!((want - got).abs() < 1e-14, "d={d} s={s} i={i}: {got} vs {want}");
            }
        }
    }
    let mut rng = Lcg::new(17);
    let n = coarse[0].num_basis() * coarse[1].num_basis();
    let s = Surface::new(coarse.clone(), (0..n).map(|_| [rng.uniform(), rng.uniform()]).collect(), None).unwrap();
    let map =
        refined_keeping(HierarchicalMap::new(b, s.control_points.clone()).unwrap(), &s, &mut rng, 4, [0.01, 0.99]);
    // the level-1 cells' bounds are the given knots, not midpoints
    assert_eq!(map.basis.knots(1)[0], l1[0]);
    assert_eq!(map.basis.knots(3)[0], l2[0].halved());
    // a level with an element left whole, or two knots in one element, is refused
    let whole = [coarse[0].with_inserted(&[0.1, 0.42]), l1[1].clone()];
    let err = HierarchicalBasis::with_levels(vec![coarse.clone(), whole]).unwrap_err().to_string();
    assert!(err.contains("level 1") && err.contains("xi"), "{err}");
    let two = [l1[0].clone(), coarse[1].with_inserted(&[0.05, 0.1, 0.6, 0.71])];
    let err = HierarchicalBasis::with_levels(vec![coarse, two]).unwrap_err().to_string();
    assert!(err.contains("level 1") && err.contains("eta"), "{err}");
}

/// Anisotropic given levels (`eta` not split: the same knots on every level, as on a thin
/// ring whose few `eta` elements all stay): a refined cell has two children, side by side
/// along `xi`; refining the south row through the levels keeps the hierarchy admissible
/// of class 2 (the support extension of a row-0 cell along `eta` reaches row 2 of the
/// quadratic `eta` functions, so rows 0 to 2 of level 0 are refined, and on every active
/// cell the THB functions come from at most two successive levels); the functions per
/// level are those of the supports counted by hand; the basis is a partition of unity and
/// linearly independent, and a tensor map on level 0 refined through the levels and past
/// them (halving both directions) stays the same map (nested spaces, exact prolongation).
/// A level that splits neither direction is refused.
#[test]
fn anisotropic_levels_refine_along_one_direction_and_keep_the_map() {
    let coarse = [kv(3, &[0.0, 0.3, 0.5, 1.0]), kv(2, &[0.0, 0.25, 0.5, 0.75, 1.0])];
    let l1 = [coarse[0].with_inserted(&[0.1, 0.42, 0.9]), coarse[1].clone()];
    let l2 = [l1[0].with_inserted(&[0.02, 0.2, 0.31, 0.47, 0.6, 0.95]), coarse[1].clone()];
    let mut b = HierarchicalBasis::with_levels(vec![coarse.clone(), l1.clone(), l2.clone()]).unwrap();
    assert!(b.splits(1, 0) && !b.splits(1, 1) && !b.splits(2, 1) && b.splits(3, 1));
    for s in 0..coarse[1].num_basis() {
        assert_eq!(b.children_1d(0, 1, s), vec![(s, 1.0)]);
        assert_eq!(b.parents_1d(2, 1, s), vec![(s, 1.0)]);
    }
    // the south row through both given levels
    b.refine(&[(0, [0, 0]), (0, [1, 0]), (0, [2, 0])], 2).unwrap();
    assert_eq!(b.cells_per_level(), vec![9, 6, 0]);
    let row: Vec<(usize, Index2)> = (0..6).map(|i| (1, [i, 0])).collect();
    b.refine(&row, 2).unwrap();
    // level 0 keeps row 3 (3 cells); level 1 rows 1 and 2 (6 cells each); level 2 row 0
    assert_eq!(b.cells_per_level(), vec![3, 12, 12]);
    for (l, c) in b.active_cells() {
        assert!(l != 2 || c[1] == 0, "cell ({l}, {c:?}) of level 2 off the south row");
        let [[a, bb], [cc, dd]] = b.cell_bounds(l, c);
        let vals = b.eval_basis(0.5 * (a + bb), 0.5 * (cc + dd));
        let levels: BTreeSet<usize> = vals.iter().map(|v| b.active_functions()[v.0].0).collect();
        assert!(levels.last().unwrap() - levels.first().unwrap() < 2, "cell ({l}, {c:?}) sees levels {levels:?}");
    }
    // level 2: the row `β_0(η)` (support row 0) of the 15 cubic `xi` functions of 12
    // elements; level 1: `β_1(η)`, `β_2(η)` (supports in rows 0 to 2, not in row 0) times
    // 9; level 0: `β_3(η)` to `β_5(η)` times 6
    assert_eq!(b.functions_per_level(), vec![18, 18, 15]);
    let mut rng = Lcg::new(23);
    let n = coarse[0].num_basis() * coarse[1].num_basis();
    let s = Surface::new(coarse.clone(), (0..n).map(|_| [rng.uniform(), rng.uniform()]).collect(), None).unwrap();
    let mut map = HierarchicalMap::new(
        HierarchicalBasis::with_levels(vec![coarse.clone(), l1, l2]).unwrap(),
        s.control_points.clone(),
    )
    .unwrap();
    map = map
        .refined(
            &row.iter().map(|&(_, [i, j])| (0, [i / 2, j])).collect::<BTreeSet<_>>().into_iter().collect::<Vec<_>>(),
            2,
        )
        .unwrap();
    let map = refined_keeping(map, &s, &mut rng, 5, [0.35, 0.01]);
    // linear independence: collocation inside every active cell
    let n = map.basis.len();
    let rows = cell_collocation(&map.basis, &mut rng, 16);
    assert_eq!(rank(rows, 1e-12), n, "{n} THB functions");
    // a level with the same knots in both directions is refused
    let err = HierarchicalBasis::with_levels(vec![coarse.clone(), coarse]).unwrap_err().to_string();
    assert!(err.contains("level 1") && err.contains("both directions"), "{err}");
}
