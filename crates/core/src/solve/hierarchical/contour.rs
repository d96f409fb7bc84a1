//! The THB basis of the contour fit (paper §5 on a truncated hierarchical basis, §4;
//! issue 35): each side's adaptive fit refines only the cells along that side.
//!
//! The tensor hierarchy of §5.4 takes the union of the knots of opposite sides, so a
//! detailed side refines the whole patch across to its coarse opposite. Here the basis
//! starts from the coarse level `S^0` (the tensor solver's coarsest level: balanced, with
//! its minimum number of elements) and refines, side by side, the active cells along the
//! side that hold a knot of that side's fit `Ξ_s` inside their span along the side, and
//! `⌈(p - 1) / 2⌉` cells of their level on either side along it (so every refined stretch
//! of a level holds at least `p` cells of the coarser level, what the univariate
//! hierarchical space needs to contain the splines on its knots), until no active cell
//! along a side straddles a knot of its fit; admissibility class `m` adds the cells
//! inside that keep the hierarchy graded.
//!
//! The THB functions non-zero on a side are the univariate THB functions of the row of
//! cells along it (a level-`l` function `β_a(ξ) β_0(η)` is supported on the first row of
//! level-`l` cells only), so the map's boundary is the fitted curve when the curve lies
//! in that univariate space; [`contour_start`] takes the coefficients by blossoming
//! ([`HierarchicalMap::quasi_interpolant`]) and checks the boundary by knot insertion.

use std::collections::BTreeSet;

use crate::error::{Error, Result};
use crate::spline::hierarchical::map::HierarchicalMap;
use crate::spline::hierarchical::{HierarchicalBasis, Index2, MAX_LEVELS};
use crate::spline::knots::KnotVector;
use crate::spline::surface::{Side, Surface};

/// Whether the cell with parameter bounds `bounds` lies along `side` of the domain `dom`.
fn along(side: Side, bounds: &[[f64; 2]; 2], dom: &[(f64, f64); 2]) -> bool {
    match side {
        Side::South => bounds[1][0] == dom[1].0,
        Side::North => bounds[1][1] == dom[1].1,
        Side::West => bounds[0][0] == dom[0].0,
        Side::East => bounds[0][1] == dom[0].1,
    }
}

/// Why the interior knots of `side` (a side's fit along direction `d`, on the domain of
/// `basis`) cannot be knots of the levels of `basis` (its given levels, then halvings): a
/// knot of multiplicity above level 0's (a kink) or one no level below `MAX_LEVELS`
/// reaches; `None` when they all are.
pub(crate) fn not_nested(basis: &HierarchicalBasis, d: usize, side: &KnotVector) -> Option<String> {
    let level0 = &basis.knots(0)[d];
    if side.degree() != level0.degree() || side.domain() != level0.domain() {
        return Some("the side's fit has another degree or domain than the basis".into());
    }
    let (lo, hi) = level0.domain();
    let elements = level0.elements();
    for (u, m) in side.breaks_with_multiplicity() {
        if u <= lo || u >= hi || level0.multiplicity(u) >= m {
            continue;
        }
        if m > 1 {
            return Some(format!("the knot {u} has multiplicity {m} (a kink kept exactly)"));
        }
        let Some(mut e) = elements.iter().position(|e| e.1 < u && u < e.2) else {
            return Some(format!("the knot {u} lies on no element"));
        };
        let (_, mut a, mut b) = elements[e];
        let mut found = false;
        for l in 0..MAX_LEVELS - 1 {
            // the split of element `e` of level `l`: the given level's, or the midpoint
            let mid = if l + 1 < basis.num_levels() { basis.split_point(l, d, e) } else { Some(0.5 * (a + b)) };
            let Some(mid) = mid else { continue }; // level `l + 1` does not split `d`
            if u == mid {
                found = true;
                break;
            }
            (a, b, e) = if u < mid { (a, mid, 2 * e) } else { (mid, b, 2 * e + 1) };
        }
        if !found {
            let what =
                if basis.given_levels().is_empty() { "a dyadic refinement of" } else { "a knot of the levels of" };
            return Some(format!("the knot {u} is not {what} the coarse level"));
        }
    }
    None
}

/// The THB basis `basis` (one level, or with given finer levels,
/// [`HierarchicalBasis::with_levels`]) refined along each side where that side's fit
/// `sides[s]` (south, east, north, west; knot vectors along the side) has knots (see the
/// module documentation), admissible of class `m`. The fits' interior knots must be knots
/// of the levels ([`not_nested`]); an error names the side otherwise.
pub(crate) fn contour_basis(basis: HierarchicalBasis, sides: &[KnotVector; 4], m: usize) -> Result<HierarchicalBasis> {
    for s in Side::ALL {
        if let Some(why) = not_nested(&basis, s.direction(), &sides[s as usize]) {
            return Err(Error::Invalid(format!("THB contour basis, {s} side: {why}")));
        }
    }
    let mut basis = basis;
    let dom = basis.knots(0).each_ref().map(KnotVector::domain);
    let ring = basis.degrees().map(|p| p.saturating_sub(1).div_ceil(2));
    let interior: Vec<Vec<f64>> = sides
        .iter()
        .zip(Side::ALL)
        .map(|(kv, s)| {
            let (lo, hi) = dom[s.direction()];
            kv.breaks().into_iter().filter(|&u| u > lo && u < hi).collect()
        })
        .collect();
    loop {
        let mut marked: BTreeSet<(usize, Index2)> = BTreeSet::new();
        for (l, c) in basis.active_cells() {
            let bounds = basis.cell_bounds(l, c);
            for s in Side::ALL {
                let d = s.direction();
                let [a, b] = bounds[d];
                if !along(s, &bounds, &dom) || !interior[s as usize].iter().any(|&u| a < u && u < b) {
                    continue;
                }
                marked.insert((l, c));
                // the neighbours along the side: the active cells at the centres of the
                // level-`l` cells next to `c`
                let n = basis.cell_shape(l)[d];
                for k in 1..=ring[d] {
                    for i in [c[d].checked_sub(k), Some(c[d] + k).filter(|&i| i < n)].into_iter().flatten() {
                        let mut nb = c;
                        nb[d] = i;
                        let at = basis.cell_bounds(l, nb).map(|[lo, hi]| 0.5 * (lo + hi));
                        let (ln, cn) = basis.cell_at(at[0], at[1]);
                        if ln <= l {
                            marked.insert((ln, cn));
                        }
                    }
                }
            }
        }
        if marked.is_empty() {
            return Ok(basis);
        }
        basis.refine(&marked.into_iter().collect::<Vec<_>>(), m)?;
    }
}

/// The levels of a THB basis whose finest given level holds the knots `top` (an input
/// basis, each direction with `n_d` elements): `L` levels below it, `L` the most for which
/// the coarsest level keeps at least `min_elements` elements in the direction with the
/// most; the finest level is `top` with the longest elements bisected until each direction
/// has `m_d 2^L` elements, `m_d = ⌈n_d / 2^L⌉` (knot insertion: the space contains
/// `top`'s), and each coarser level removes every other break of the next (so every
/// element splits in two, [`HierarchicalBasis::with_levels`]). Coarse to fine; `Err(why)`
/// when no level fits below `top` or a removed break is a multiple knot.
pub(crate) fn coarsened_levels(
    top: &[KnotVector; 2],
    min_elements: usize,
) -> std::result::Result<Vec<[KnotVector; 2]>, String> {
    let n = top.each_ref().map(KnotVector::num_elements);
    let nmax = n[0].max(n[1]);
    let mut levels = 0;
    while levels + 1 < MAX_LEVELS && nmax.div_ceil(1 << (levels + 1)) >= min_elements.max(1) {
        levels += 1;
    }
    if levels == 0 {
        return Err(format!("{nmax} elements leave no coarser level of at least {min_elements}"));
    }
    let mut chains: Vec<Vec<KnotVector>> = Vec::with_capacity(2);
    for (d, kv) in top.iter().enumerate() {
        let want = n[d].div_ceil(1 << levels) << levels;
        let mut fine = kv.clone();
        while fine.num_elements() < want {
            let longest = fine.elements().into_iter().max_by(|x, y| (x.2 - x.1).total_cmp(&(y.2 - y.1)));
            let Some((_, a, b)) = longest else { return Err("a knot vector without elements".into()) };
            fine = fine.with_inserted(&[0.5 * (a + b)]);
        }
        let mut chain = vec![fine];
        for _ in 0..levels {
            let last = chain.last().expect("the finest level");
            let breaks = last.breaks_with_multiplicity();
            let mut knots = Vec::with_capacity(last.knots().len());
            for (k, &(u, m)) in breaks.iter().enumerate() {
                if k % 2 == 1 {
                    if m > 1 {
                        return Err(format!("the knot {u} of multiplicity {m} would be removed from a coarser level"));
                    }
                    continue;
                }
                knots.extend(std::iter::repeat_n(u, m));
            }
            chain.push(KnotVector::new(last.degree(), knots).map_err(|e| e.to_string())?);
        }
        chain.reverse();
        chains.push(chain);
    }
    Ok((0..=levels).map(|l| [chains[0][l].clone(), chains[1][l].clone()]).collect())
}

/// Largest difference between the boundary curves of `a` and `b` on `side`, control
/// point by control point on the union of their knots (exact knot insertion).
pub(crate) fn boundary_difference(a: &Surface, b: &Surface, side: Side) -> Result<f64> {
    let (ca, cb) = (a.boundary(side), b.boundary(side));
    let kv = ca.knots.union(&cb.knots)?;
    let (ra, rb) = (ca.refined(&kv)?, cb.refined(&kv)?);
    Ok(ra
        .control_points
        .iter()
        .zip(&rb.control_points)
        .map(|(x, y)| (x[0] - y[0]).hypot(x[1] - y[1]))
        .fold(0.0, f64::max))
}

/// Largest distance between the boundary control points of the THB start and of the
/// tensor map, relative to the map's extent, that counts as the same boundary: rounding
/// of the blossoms and knot insertions (male_casing_ring fitted, levels 0 to 12: 3.7e-11
/// apart at an extent of about 36), six orders below the fit's default tolerance `1e-4`;
/// a side outside the THB trace space is off by the fit's own detail, far above.
pub(crate) const BOUNDARY_TOL: f64 = 1e-10;

/// The start of the THB solve from the contour fit: `map` (the tensor solve's map, its
/// boundary the fitted sides) on the THB basis of [`contour_basis`] (`basis`: level 0 and
/// any given finer levels, the fits' knot vectors `sides`, admissibility `m`) by
/// [`HierarchicalMap::quasi_interpolant`]: the boundary functions carry the fitted sides,
/// the others the blossoms of `map`'s pieces (a start for Newton). `Ok(Err(why))` when the
/// fits' knots are not knots of the levels ([`not_nested`]) or the boundary is not
/// reproduced (to rounding, [`BOUNDARY_TOL`] of the map's extent).
pub(crate) fn contour_start(
    map: &Surface,
    basis: HierarchicalBasis,
    sides: &[KnotVector; 4],
    m: usize,
) -> Result<std::result::Result<HierarchicalMap, String>> {
    if map.weights.is_some() || map.knots.iter().any(KnotVector::is_periodic) {
        return Ok(Err("a rational or periodic map keeps its tensor basis".into()));
    }
    if let Some(why) = Side::ALL
        .into_iter()
        .find_map(|s| not_nested(&basis, s.direction(), &sides[s as usize]).map(|w| format!("the {s} side's fit: {w}")))
    {
        return Ok(Err(why));
    }
    let basis = contour_basis(basis, sides, m)?;
    let thb = HierarchicalMap::from_surface(map)?.quasi_interpolant(basis)?;
    let tensor = thb.to_surface()?;
    let extent = map.control_points.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs())).max(f64::MIN_POSITIVE);
    for s in Side::ALL {
        let diff = boundary_difference(&tensor, map, s)?;
        if diff.is_nan() || diff > BOUNDARY_TOL * extent {
            return Ok(Err(format!("the THB basis does not reproduce the {s} side ({diff:.3e} apart)")));
        }
    }
    Ok(Ok(thb))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::curve::Curve;
    use crate::testutil::Lcg;

    /// A map on `[0, 1]²` whose four sides are splines on their own dyadic knots (level 0
    /// 32 uniform elements; south with spans of 1/256 on [0.25, 0.375], north halved,
    /// east with spans of 1/128 on [0.75, 0.875], west level 0), with
    /// perturbed control points, and whose basis is the tensor product of the unions of
    /// opposite sides' knots (as the tensor hierarchy builds it).
    fn detailed_map() -> (Surface, [KnotVector; 4], [KnotVector; 2]) {
        let p = 3;
        let level0 = KnotVector::open_uniform(p, 32);
        // the dyadic knots k / 2^m, k in `ks`, that level 0 lacks
        let detail = |m: i32, ks: std::ops::RangeInclusive<i32>| -> Vec<f64> {
            ks.map(|k| k as f64 / 2f64.powi(m)).filter(|&u| level0.multiplicity(u) == 0).collect()
        };
        let south = level0.with_inserted(&detail(8, 64..=96));
        let north = level0.halved();
        let east = level0.with_inserted(&detail(7, 96..=112));
        let west = level0.clone();
        let knots = [south.union(&north).unwrap(), east.union(&west).unwrap()];
        let mut rng = Lcg::new(11);
        // the side on its own knots from `a` to `b`, bulging, then on the union's knots
        let mut side = |kv: &KnotVector, a: [f64; 2], b: [f64; 2], fine: &KnotVector| {
            let g = kv.greville();
            let n = g.len();
            let cps = (0..n)
                .map(|i| {
                    let t = g[i];
                    let wiggle = if i == 0 || i + 1 == n { 0.0 } else { 0.05 * (rng.uniform() - 0.5) };
                    [a[0] + t * (b[0] - a[0]) + wiggle, a[1] + t * (b[1] - a[1]) - wiggle]
                })
                .collect();
            Curve::polynomial(kv.clone(), cps).refined(fine).unwrap()
        };
        let s_ = side(&south, [0.0, 0.0], [1.0, 0.0], &knots[0]);
        let n_ = side(&north, [0.0, 1.0], [1.0, 1.0], &knots[0]);
        let e_ = side(&east, [1.0, 0.0], [1.0, 1.0], &knots[1]);
        let w_ = side(&west, [0.0, 0.0], [0.0, 1.0], &knots[1]);
        let (nx, ny) = (knots[0].num_basis(), knots[1].num_basis());
        let (gx, gy) = (knots[0].greville(), knots[1].greville());
        let mut cps = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                cps.push(match (i, j) {
                    (_, 0) => s_.control_points[i],
                    (_, j) if j + 1 == ny => n_.control_points[i],
                    (0, _) => w_.control_points[j],
                    (i, _) if i + 1 == nx => e_.control_points[j],
                    _ => [gx[i] + 0.02 * rng.uniform(), gy[j] + 0.02 * rng.uniform()],
                });
            }
        }
        let map = Surface::new(knots, cps, None).unwrap();
        (map, [south, east, north, west], [level0.clone(), level0])
    }

    /// The boundary of the THB start is the tensor map's (the fitted sides) control point
    /// for control point after knot insertion; the basis is a partition of unity; it has
    /// fewer functions than the tensor basis; the cells along the coarse north and west
    /// sides stay on level 0 where the opposite side's detail is not, and no active cell
    /// along a side straddles a knot of that side's fit.
    #[test]
    fn the_thb_start_reproduces_the_fitted_sides_with_fewer_functions() {
        let (map, sides, level0) = detailed_map();
        let thb = contour_start(&map, HierarchicalBasis::new(level0).unwrap(), &sides, 2).unwrap().unwrap();
        let tensor = thb.to_surface().unwrap();
        for s in Side::ALL {
            // to rounding (the map's extent is about 1)
            let diff = boundary_difference(&tensor, &map, s).unwrap();
            assert!(diff < BOUNDARY_TOL, "{s}: {diff:e}");
            // and the THB map's own evaluation on the side is the fitted curve
            let c: &Curve = &map.boundary(s);
            for k in 0..=64 {
                let t = k as f64 / 64.0;
                let (u, v) = match s {
                    Side::South => (t, 0.0),
                    Side::North => (t, 1.0),
                    Side::West => (0.0, t),
                    Side::East => (1.0, t),
                };
                let (x, y) = (thb.eval(u, v), c.eval(t));
                assert!((x[0] - y[0]).hypot(x[1] - y[1]) < BOUNDARY_TOL, "{s} at {t}: {x:?} vs {y:?}");
            }
        }
        let b = &thb.basis;
        assert!(b.len() < map.control_points.len(), "{} THB against {} tensor", b.len(), map.control_points.len());
        let mut rng = Lcg::new(5);
        for _ in 0..200 {
            let s: f64 = b.eval_basis(rng.uniform(), rng.uniform()).iter().map(|x| x.1[0]).sum();
            assert!((s - 1.0).abs() < 1e-13, "partition of unity: {s}");
        }
        let dom = [(0.0, 1.0), (0.0, 1.0)];
        for (l, c) in b.active_cells() {
            let bounds = b.cell_bounds(l, c);
            for s in Side::ALL {
                let d = s.direction();
                let [lo, hi] = bounds[d];
                if along(s, &bounds, &dom) {
                    assert!(sides[s as usize].breaks().iter().all(|&u| !(lo < u && u < hi)), "{s} {l} {c:?}");
                }
            }
        }
        // the north side's cells near xi = 0.3 are coarser than the south side's there
        assert!(b.cell_at(0.3, 0.999).0 < b.cell_at(0.3, 0.001).0);
    }

    /// A fit with a kink's knot (multiplicity p) or a knot off the dyadic levels is not
    /// a THB contour basis: the start says why instead.
    #[test]
    fn knots_off_the_dyadic_levels_are_refused() {
        let (map, mut sides, level0) = detailed_map();
        let basis = HierarchicalBasis::new(level0.clone()).unwrap();
        assert!(not_nested(&basis, 0, &sides[0]).is_none());
        let third = level0[0].with_inserted(&[1.0 / 3.0]);
        assert!(not_nested(&basis, 0, &third).unwrap().contains("dyadic"));
        let kink = level0[0].with_inserted(&[0.375, 0.375, 0.375]);
        assert!(not_nested(&basis, 0, &kink).unwrap().contains("multiplicity"));
        sides[2] = third;
        let why = contour_start(&map, basis, &sides, 2).unwrap().unwrap_err();
        assert!(why.contains("north"), "{why}");
    }

    /// An input basis: a cubic map whose xi knots are 45 non-uniform elements (the south
    /// and north sides' own knots, shared as on a G+Smo patch) and eta 6 uniform ones.
    /// [`coarsened_levels`] makes nested levels from its knots (each splitting every
    /// element of the one below in two, the finest containing the input's knots), the
    /// contour basis on them reproduces the input boundary exactly (knot insertion, to
    /// rounding) with fewer functions than the tensor basis, and is a partition of unity;
    /// the levels are the input's subsets (every other break removed).
    #[test]
    fn an_input_basis_is_reproduced_by_its_coarsened_levels() {
        let p = 3;
        let mut rng = Lcg::new(3);
        // non-uniform breaks: cumulative random spans
        let mut acc = vec![0.0];
        for _ in 0..45 {
            let last = *acc.last().unwrap();
            acc.push(last + 0.2 + rng.uniform());
        }
        let total = *acc.last().unwrap();
        let inner: Vec<f64> = acc[1..45].iter().map(|x| x / total).collect();
        let xi = KnotVector::open_uniform(p, 1).with_inserted(&inner);
        let eta = KnotVector::open_uniform(p, 6);
        let (nx, ny) = (xi.num_basis(), eta.num_basis());
        let (gx, gy) = (xi.greville(), eta.greville());
        let mut cps: Vec<[f64; 2]> = Vec::with_capacity(nx * ny);
        for (j, &y) in gy.iter().enumerate() {
            for &x in &gx {
                let bump = if j == 0 || j + 1 == ny { 0.03 * (rng.uniform() - 0.5) } else { 0.0 };
                cps.push([x + 0.5 * y * x, y + bump]);
            }
        }
        let map = Surface::new([xi.clone(), eta.clone()], cps, None).unwrap();
        let levels = coarsened_levels(&map.knots, 8).unwrap();
        // 45 elements: two levels below (12 elements at level 0), the finest 48 elements
        assert_eq!(levels.len(), 3);
        assert_eq!(levels[0][0].num_elements(), 12);
        assert_eq!(levels[2][0].num_elements(), 48);
        for u in xi.breaks() {
            assert!(levels[2][0].multiplicity(u) == 1 || u == 0.0 || u == 1.0, "{u}");
        }
        for l in 0..2 {
            let (fine, coarse) = (levels[l + 1][0].breaks(), levels[l][0].breaks());
            assert_eq!(coarse, fine.iter().step_by(2).copied().collect::<Vec<_>>());
        }
        let sides = [xi.clone(), eta.clone(), xi.clone(), eta.clone()];
        let basis = HierarchicalBasis::with_levels(levels).unwrap();
        let thb = contour_start(&map, basis, &sides, 2).unwrap().unwrap();
        let tensor = thb.to_surface().unwrap();
        for s in Side::ALL {
            let diff = boundary_difference(&tensor, &map, s).unwrap();
            assert!(diff < 1e-12, "{s}: {diff:e}");
        }
        let b = &thb.basis;
        assert!(b.len() < map.control_points.len(), "{} THB against {} tensor", b.len(), nx * ny);
        for _ in 0..200 {
            let s: f64 = b.eval_basis(rng.uniform(), rng.uniform()).iter().map(|x| x.1[0]).sum();
            assert!((s - 1.0).abs() < 1e-13, "partition of unity: {s}");
        }
        // the cells away from the sides stay coarser than those along them
        assert!(b.cell_at(0.5, 0.5).0 < b.cell_at(0.5, 0.0).0);
        assert_eq!(b.cell_at(0.5, 0.0).0, 2);
    }
}
