//! Truncated hierarchical B-splines (THB-splines; Giannelli, Jüttler, Speleers 2012;
//! paper §4: "a (truncated) hierarchical spline basis ... allowing for local refinement").
//!
//! **Hierarchy.** Level `0` is an open tensor space `S^0` with knot vectors `(T_ξ^0, T_η^0)`;
//! level `l + 1` splits every element of level `l` in two in each direction: by default at
//! its midpoint (dyadic refinement, [`KnotVector::halved`]); the first levels may instead be
//! given ([`HierarchicalBasis::with_levels`]: an input basis's knot vector as a finer level,
//! its coarser levels every other break removed), each splitting every element of the level
//! below at one new simple knot anywhere inside it, or keeping the knots of one direction
//! (anisotropic levels). Either way `S^0 ⊂ S^1 ⊂ ...` and a level-`l` cell `(i, j)` has
//! the children `(2i + a, 2j + b)`, `a, b ∈ {0, 1}` (`i` itself along a direction the
//! level does not split). The domains `Ω^0 = [0, 1]² ⊇ Ω^1 ⊇ ...` are
//! unions of cells: `Ω^{l+1}` is the union of the level-`l` cells marked *refined*. A
//! level-`l` cell is *active* when it lies in `Ω^l` and is not refined; the active cells
//! tile the domain.
//!
//! **Functions.** The level-`l` B-spline `β` is *active* when `supp β ⊆ Ω^l` and
//! `supp β ⊄ Ω^{l+1}` (the hierarchical basis of Kraft). The truncation of a function
//! `s ∈ S^l` with respect to level `l + 1` drops its components along the finer functions
//! that live inside `Ω^{l+1}`:
//!
//! `trunc^{l+1} s = Σ_{τ ∈ B^{l+1}, supp τ ⊄ Ω^{l+1}} c_τ^{l+1}(s) τ`,
//!
//! where `s = Σ_{τ ∈ B^{l+1}} c_τ^{l+1}(s) τ` is the two-scale (knot insertion) relation,
//! and the THB function of an active `β ∈ B^l` is `Trunc β = trunc^{L}(... trunc^{l+1}(β))`.
//! The THB functions are non-negative, a partition of unity, linearly independent and
//! span the same space as the hierarchical basis (GJS 2012, Thm. 9 and Prop. 6).
//!
//! **Admissibility.** [`HierarchicalBasis::refine`] refines marked cells together with the
//! cells needed to keep the mesh *admissible of class `m`*: on every active cell the
//! non-zero THB functions come from at most `m` successive levels (Bracco, Giannelli,
//! Vázquez 2018, Algorithm "refine_recursive" with the THB neighbourhood
//! `N(Q, m) = {Q' active of level l - m + 1 : Q' ∩ S(Q, l - m + 2) ≠ ∅}`, `S(Q, k)` the
//! union of the supports of the level-`k` B-splines non-zero on `Q`; on anisotropic
//! levels the same, the parents taken per direction).
//!
//! Submodules: `truncation` (the two-scale relation and the restriction of the THB
//! functions to an active cell), [`map`] (THB maps of the plane: control points,
//! evaluation, per-cell Bézier nets, refinement and conversion to a tensor map).

pub mod map;
#[cfg(test)]
mod tests;
pub(crate) mod truncation;

use std::collections::{BTreeSet, HashMap};
use std::ops::Range;

use crate::error::{Error, Result, MAX_CONTROL_POINTS};
use crate::spline::knots::KnotVector;

/// A cell or a function of one level: its index per direction (`xi`, `eta`).
pub(crate) type Index2 = [usize; 2];

/// Levels a hierarchy may hold (level `0` included).
pub(crate) const MAX_LEVELS: usize = 24;

/// One level of the hierarchy: its tensor knot vectors and per direction the elements
/// and, for each knot position `k`, the element that starts at `t_k`.
#[derive(Debug, Clone)]
struct Level {
    knots: [KnotVector; 2],
    /// Per direction, whether this level splits every element of the level below in two
    /// (`false`: the same knots in that direction, a given level only; level 0: `true`).
    split: [bool; 2],
    /// `(span, a, b)` per element.
    elements: [Vec<(usize, f64, f64)>; 2],
    /// `first[k]`: the number of distinct knot values `< t_k` (the index of the element
    /// starting at `t_k`).
    first: [Vec<usize>; 2],
}

impl Level {
    fn new(knots: [KnotVector; 2]) -> Self {
        let elements = knots.each_ref().map(KnotVector::elements);
        let first = knots.each_ref().map(|kv| {
            let t = kv.knots();
            let mut out = Vec::with_capacity(t.len());
            let mut distinct = 0;
            for k in 0..t.len() {
                if k > 0 && t[k] > t[k - 1] {
                    distinct += 1;
                }
                out.push(distinct);
            }
            // the first knot value is the domain start: element 0 starts there
            out
        });
        Self { knots, split: [true; 2], elements, first }
    }

    /// Cells (element indices) of the support of function `f` in direction `d`.
    fn support(&self, d: usize, f: usize) -> Range<usize> {
        let p = self.knots[d].degree();
        let n_el = self.elements[d].len();
        self.first[d][f].min(n_el)..self.first[d][f + p + 1].min(n_el)
    }

    /// Functions non-zero on cell `e` in direction `d`.
    fn functions(&self, d: usize, e: usize) -> Range<usize> {
        let s = self.elements[d][e].0;
        s - self.knots[d].degree()..s + 1
    }
}

/// A truncated hierarchical B-spline basis of the unit square (see the module doc).
#[derive(Debug, Clone)]
pub struct HierarchicalBasis {
    levels: Vec<Level>,
    /// The given finer levels `1, 2, ...` ([`Self::with_levels`]); the levels past them
    /// halve the last one.
    given: Vec<[KnotVector; 2]>,
    /// `refined[l]`: the level-`l` cells that are refined (their children make `Ω^{l+1}`).
    refined: Vec<BTreeSet<Index2>>,
    /// Active functions `(level, index)`, by level, then `eta` index, then `xi` index.
    active: Vec<(usize, Index2)>,
    lookup: HashMap<(usize, Index2), usize>,
}

impl HierarchicalBasis {
    /// The hierarchy with the single level `S^0` on these open knot vectors.
    pub fn new(knots: [KnotVector; 2]) -> Result<Self> {
        for (kv, name) in knots.iter().zip(["xi", "eta"]) {
            if kv.is_periodic() || !kv.is_open() {
                return Err(Error::Knots {
                    context: format!("hierarchical basis, direction {name}"),
                    reason: "level 0 must be an open (clamped), non-periodic knot vector".into(),
                });
            }
        }
        let mut out = Self {
            levels: vec![Level::new(knots)],
            given: Vec::new(),
            refined: vec![BTreeSet::new()],
            active: vec![],
            lookup: HashMap::new(),
        };
        out.update_active();
        Ok(out)
    }

    /// The hierarchy on the open knot vectors `levels[0]` with the finer levels
    /// `levels[1..]` given (the levels past them halve the last one): each level of the
    /// same degrees and domain as the one below, holding, per direction, either its knots
    /// with their multiplicities and exactly one new simple knot strictly inside each of
    /// its elements (a split direction: a cell has two children along it), or the same
    /// knots (an unsplit direction: one child along it, the same span; anisotropic
    /// refinement), at least one direction split. A typed error names the level and
    /// direction otherwise.
    pub fn with_levels(levels: Vec<[KnotVector; 2]>) -> Result<Self> {
        let mut it = levels.into_iter();
        let first = it.next().ok_or_else(|| Error::Invalid("a hierarchy needs a level 0".into()))?;
        let mut out = Self::new(first)?;
        for (l, knots) in it.enumerate().map(|(k, kv)| (k + 1, kv)) {
            if l >= MAX_LEVELS {
                return Err(Error::TooLarge {
                    context: "hierarchical basis".into(),
                    what: "levels".into(),
                    found: l + 1,
                    limit: MAX_LEVELS,
                });
            }
            let mut split = [true; 2];
            for d in 0..2 {
                match splits_in_two(&out.levels[l - 1].knots[d], &knots[d]) {
                    Ok(s) => split[d] = s,
                    Err(why) => {
                        return Err(Error::Knots {
                            context: format!("hierarchical basis, level {l}, direction {}", ["xi", "eta"][d]),
                            reason: why,
                        })
                    }
                }
            }
            if split == [false; 2] {
                return Err(Error::Knots {
                    context: format!("hierarchical basis, level {l}"),
                    reason: "the same knots as the level below in both directions".into(),
                });
            }
            out.given.push(knots.clone());
            out.levels.push(Level { split, ..Level::new(knots) });
            out.refined.push(BTreeSet::new());
        }
        Ok(out)
    }

    /// The given finer levels (`levels[1..]` of [`Self::with_levels`]; empty when every
    /// level halves the one below).
    pub(crate) fn given_levels(&self) -> &[[KnotVector; 2]] {
        &self.given
    }

    /// The knot value splitting element `e` of level `l` in direction `d` (the end of its
    /// first child), creating no level: from level `l + 1` when it exists (`None` when
    /// that level does not split `d`), the midpoint otherwise (a level past the given ones
    /// halves).
    pub(crate) fn split_point(&self, l: usize, d: usize, e: usize) -> Option<f64> {
        match self.levels.get(l + 1) {
            Some(next) => next.split[d].then(|| next.elements[d][2 * e].2),
            None => {
                let (_, a, b) = self.levels[l].elements[d][e];
                Some(0.5 * (a + b))
            }
        }
    }

    /// Whether level `l` splits direction `d` of level `l - 1` (`l >= 1`; a level past the
    /// existing ones halves).
    pub(crate) fn splits(&self, l: usize, d: usize) -> bool {
        self.levels.get(l).is_none_or(|lv| lv.split[d])
    }

    /// The index along direction `d` of the level-`(l - 1)` parent of the level-`l` cell
    /// (or element) `i` (`l >= 1`).
    fn parent_1d(&self, l: usize, d: usize, i: usize) -> usize {
        if self.splits(l, d) {
            i / 2
        } else {
            i
        }
    }

    /// The level-`k` ancestor of cell `c` of level `l >= k`.
    pub(crate) fn ancestor(&self, l: usize, c: Index2, k: usize) -> Index2 {
        let mut c = c;
        for j in (k + 1..=l).rev() {
            c = std::array::from_fn(|d| self.parent_1d(j, d, c[d]));
        }
        c
    }

    /// The children (of level `l + 1`) of cell `c` of level `l`: two along each direction
    /// level `l + 1` splits, one along the others.
    fn children(&self, l: usize, c: Index2) -> impl Iterator<Item = Index2> {
        let range = |d: usize| if self.splits(l + 1, d) { 2 * c[d]..2 * c[d] + 2 } else { c[d]..c[d] + 1 };
        let (ri, rj) = (range(0), range(1));
        rj.flat_map(move |j| ri.clone().map(move |i| [i, j]))
    }

    /// Degrees `(p, q)`.
    pub fn degrees(&self) -> [usize; 2] {
        self.levels[0].knots.each_ref().map(KnotVector::degree)
    }

    /// Number of levels (the finest level is `num_levels() - 1`; it may hold no cell yet).
    pub fn num_levels(&self) -> usize {
        self.levels.len()
    }

    /// Knot vectors of level `l`.
    pub fn knots(&self, l: usize) -> &[KnotVector; 2] {
        &self.levels[l].knots
    }

    /// Number of active (THB) functions.
    pub fn len(&self) -> usize {
        self.active.len()
    }

    /// Whether the basis is empty (never: level 0 always holds a function).
    pub fn is_empty(&self) -> bool {
        self.active.is_empty()
    }

    /// The active functions `(level, index)` in the order of the coefficients.
    pub(crate) fn active_functions(&self) -> &[(usize, Index2)] {
        &self.active
    }

    /// The position of the active function `(l, f)` among [`Self::active_functions`].
    pub(crate) fn index_of(&self, l: usize, f: Index2) -> Option<usize> {
        self.lookup.get(&(l, f)).copied()
    }

    /// The refined cells of level `l` (empty past the finest level).
    pub(crate) fn refined_cells(&self, l: usize) -> impl Iterator<Item = &Index2> {
        self.refined.get(l).into_iter().flatten()
    }

    /// Number of cells per direction at level `l`.
    pub(crate) fn cell_shape(&self, l: usize) -> [usize; 2] {
        self.levels[l].elements.each_ref().map(Vec::len)
    }

    /// Parameter bounds `[[ξ_0, ξ_1], [η_0, η_1]]` of cell `c` of level `l`.
    pub fn cell_bounds(&self, l: usize, c: Index2) -> [[f64; 2]; 2] {
        std::array::from_fn(|d| {
            let (_, a, b) = self.levels[l].elements[d][c[d]];
            [a, b]
        })
    }

    /// Knot spans `(s_ξ, s_η)` of cell `c` of level `l`.
    pub(crate) fn cell_spans(&self, l: usize, c: Index2) -> Index2 {
        std::array::from_fn(|d| self.levels[l].elements[d][c[d]].0)
    }

    /// Whether cell `c` of level `l` lies in `Ω^l`.
    pub(crate) fn in_domain(&self, l: usize, c: Index2) -> bool {
        l == 0 || self.refined.get(l - 1).is_some_and(|r| r.contains(&self.ancestor(l, c, l - 1)))
    }

    /// Whether cell `c` of level `l` is refined (lies in `Ω^{l+1}`).
    pub(crate) fn is_refined(&self, l: usize, c: Index2) -> bool {
        self.refined.get(l).is_some_and(|r| r.contains(&c))
    }

    /// Whether cell `c` of level `l` is active.
    pub(crate) fn is_active_cell(&self, l: usize, c: Index2) -> bool {
        self.in_domain(l, c) && !self.is_refined(l, c)
    }

    /// The active cells, by level, then `eta`, then `xi`.
    pub fn active_cells(&self) -> Vec<(usize, Index2)> {
        let mut out = Vec::new();
        let [nx, ny] = self.cell_shape(0);
        for j in 0..ny {
            for i in 0..nx {
                if !self.is_refined(0, [i, j]) {
                    out.push((0, [i, j]));
                }
            }
        }
        for l in 1..self.levels.len() {
            let mut level: Vec<Index2> = self.domain_cells(l).filter(|&c| !self.is_refined(l, c)).collect();
            level.sort_by_key(|c| (c[1], c[0]));
            out.extend(level.into_iter().map(|c| (l, c)));
        }
        out
    }

    /// The active cell containing the parameter point `(u, v)` (a point on a cell boundary
    /// goes to the cell above it, the last cell keeps the domain's end).
    pub fn cell_at(&self, u: f64, v: f64) -> (usize, Index2) {
        let locate = |level: &Level, d: usize, x: f64| {
            let els = &level.elements[d];
            els.partition_point(|&(_, a, _)| a <= x).saturating_sub(1).min(els.len() - 1)
        };
        let mut c = [locate(&self.levels[0], 0, u), locate(&self.levels[0], 1, v)];
        let mut l = 0;
        while self.is_refined(l, c) {
            l += 1;
            c = [locate(&self.levels[l], 0, u), locate(&self.levels[l], 1, v)];
        }
        (l, c)
    }

    /// Cells of level `l >= 1` in `Ω^l` (the children of the refined cells of level `l - 1`).
    fn domain_cells(&self, l: usize) -> impl Iterator<Item = Index2> + '_ {
        self.refined[l - 1].iter().flat_map(move |&c| self.children(l - 1, c))
    }

    /// Cells of the support of function `f` of level `l`, per direction.
    pub fn support(&self, l: usize, f: Index2) -> [Range<usize>; 2] {
        std::array::from_fn(|d| self.levels[l].support(d, f[d]))
    }

    /// Functions of level `l` non-zero on cell `c`, per direction (`p + 1` and `q + 1`).
    pub(crate) fn functions_on(&self, l: usize, c: Index2) -> [Range<usize>; 2] {
        std::array::from_fn(|d| self.levels[l].functions(d, c[d]))
    }

    /// Whether every cell of the support of `(l, f)` satisfies `pred`.
    fn support_all(&self, l: usize, f: Index2, pred: impl Fn(Index2) -> bool) -> bool {
        let [ri, rj] = self.support(l, f);
        rj.into_iter().all(|j| ri.clone().all(|i| pred([i, j])))
    }

    /// Whether `supp β ⊆ Ω^l` for the level-`l` function `f`.
    pub(crate) fn support_in_domain(&self, l: usize, f: Index2) -> bool {
        l == 0 || self.support_all(l, f, |c| self.in_domain(l, c))
    }

    /// Whether the level-`l` function `f` is active: `supp ⊆ Ω^l`, `supp ⊄ Ω^{l+1}`.
    pub fn is_active(&self, l: usize, f: Index2) -> bool {
        self.support_in_domain(l, f) && !self.support_all(l, f, |c| self.is_refined(l, c))
    }

    fn update_active(&mut self) {
        let mut active = Vec::new();
        let n0 = self.levels[0].knots.each_ref().map(KnotVector::num_basis);
        for j in 0..n0[1] {
            for i in 0..n0[0] {
                if self.is_active(0, [i, j]) {
                    active.push((0, [i, j]));
                }
            }
        }
        for l in 1..self.levels.len() {
            let mut cand = BTreeSet::new();
            for c in self.domain_cells(l) {
                let [fi, fj] = self.functions_on(l, c);
                for j in fj {
                    for i in fi.clone() {
                        cand.insert([j, i]);
                    }
                }
            }
            active.extend(cand.into_iter().map(|[j, i]| [i, j]).filter(|&f| self.is_active(l, f)).map(|f| (l, f)));
        }
        self.lookup = active.iter().enumerate().map(|(k, &lf)| (lf, k)).collect();
        self.active = active;
    }

    /// The cells refined in `self` and not in `before`, per level, when `self` is a
    /// refinement of `before` (the same level-0 knots, every refined cell of `before`
    /// refined here); `None` otherwise.
    pub(crate) fn newly_refined(&self, before: &Self) -> Option<Vec<Vec<Index2>>> {
        let refines = self.levels[0].knots == before.levels[0].knots
            && self.given == before.given
            && before.refined.len() <= self.refined.len()
            && before.refined.iter().zip(&self.refined).all(|(b, s)| b.is_subset(s));
        refines.then(|| {
            self.refined
                .iter()
                .enumerate()
                .map(|(l, s)| s.iter().filter(|c| !before.is_refined(l, **c)).copied().collect())
                .collect()
        })
    }

    /// Whether the restriction of the THB functions to the active cell `c` of level `l`
    /// (its element extraction) may differ from that in the hierarchy `self` was refined
    /// from, given the cells refined since ([`Self::newly_refined`]); `c` active in both.
    ///
    /// On `Q = (l, c)` the extraction is the level coefficients `d^l_τ` of the functions
    /// `τ` non-zero on `Q` (`truncation`). The recursion for `d^l_τ` reads the state
    /// (active, masked by `Ω^{k+1}`, outside `Ω^k`) of level-`k` functions non-zero on
    /// `Q`'s ancestor of level `k` (a parent's support contains its child's), for
    /// `k <= l`; that state depends on `Ω^k` and `Ω^{k+1}` on the function's support,
    /// which lies in the support extension `S(Q, k)`. The level-`l` functions on `Q` are
    /// never masked (`Q` is not refined), and `S(Q, k + 1) ⊆ S(Q, k)`. So the extraction
    /// is unchanged unless a cell of some level `k < l` was refined inside `S(Q, k)`.
    pub(crate) fn extraction_changed(&self, newly: &[Vec<Index2>], l: usize, c: Index2) -> bool {
        (0..l.min(newly.len())).any(|k| {
            !newly[k].is_empty() && {
                let [ri, rj] = self.support_extension(l, c, k);
                newly[k].iter().any(|q| ri.contains(&q[0]) && rj.contains(&q[1]))
            }
        })
    }

    /// Cells of level `k` of the support extension `S(Q, k)` of cell `c` of level `l >= k`:
    /// the union of the supports of the level-`k` functions non-zero on `Q`'s ancestor.
    fn support_extension(&self, l: usize, c: Index2, k: usize) -> [Range<usize>; 2] {
        let anc = self.ancestor(l, c, k);
        let fs = self.functions_on(k, anc);
        std::array::from_fn(|d| {
            let lo = self.levels[k].support(d, fs[d].start).start;
            let hi = self.levels[k].support(d, fs[d].end - 1).end;
            lo..hi
        })
    }

    /// Refine the active cells `marked` (`(level, cell)`) and, recursively, the coarser
    /// active cells that keep the hierarchy admissible of class `m >= 2` (see the module
    /// doc). A marked cell that is not active is a typed error; so is a level past
    /// `MAX_LEVELS` or a knot vector past the size limit.
    pub fn refine(&mut self, marked: &[(usize, Index2)], m: usize) -> Result<()> {
        if m < 2 {
            return Err(Error::Invalid(format!("admissibility class must be at least 2, got {m}")));
        }
        for &(l, c) in marked {
            let shape = self.levels.get(l).map(|_| self.cell_shape(l));
            if !shape.is_some_and(|s| c[0] < s[0] && c[1] < s[1]) || !self.is_active_cell(l, c) {
                return Err(Error::Invalid(format!("cell ({}, {}) of level {l} is not an active cell", c[0], c[1])));
            }
        }
        for &(l, c) in marked {
            self.refine_recursive(l, c, m)?;
        }
        self.update_active();
        Ok(())
    }

    fn refine_recursive(&mut self, l: usize, c: Index2, m: usize) -> Result<()> {
        if !self.is_active_cell(l, c) {
            return Ok(());
        }
        if l + 1 >= m {
            let k = l + 1 - m; // level of the neighbourhood
            let [ri, rj] = self.support_extension(l, c, k + 1);
            let mut nb = BTreeSet::new();
            for j in rj {
                for i in ri.clone() {
                    nb.insert([self.parent_1d(k + 1, 0, i), self.parent_1d(k + 1, 1, j)]);
                }
            }
            for q in nb {
                if self.is_active_cell(k, q) {
                    self.refine_recursive(k, q, m)?;
                }
            }
        }
        self.ensure_level(l + 1)?;
        self.refined[l].insert(c);
        Ok(())
    }

    /// Create the levels up to `l`.
    fn ensure_level(&mut self, l: usize) -> Result<()> {
        while self.levels.len() <= l {
            if self.levels.len() >= MAX_LEVELS {
                return Err(Error::TooLarge {
                    context: "hierarchical basis".into(),
                    what: "levels".into(),
                    found: self.levels.len() + 1,
                    limit: MAX_LEVELS,
                });
            }
            let last = &self.levels[self.levels.len() - 1];
            let knots = match self.given.get(self.levels.len() - 1) {
                Some(given) => given.clone(),
                None => last.knots.each_ref().map(KnotVector::halved),
            };
            if let Some(kv) = knots.iter().find(|kv| kv.num_basis() > MAX_CONTROL_POINTS) {
                return Err(Error::TooLarge {
                    context: "hierarchical basis".into(),
                    what: "functions per direction of a level".into(),
                    found: kv.num_basis(),
                    limit: MAX_CONTROL_POINTS,
                });
            }
            self.levels.push(Level::new(knots));
            self.refined.push(BTreeSet::new());
        }
        Ok(())
    }

    /// The hierarchy on the same levels (level 0 and the given ones) with the refined cells
    /// `refined[l]` instead of this one's (e.g. the start of the THB rounds, the report's
    /// `start.refined`, on the levels of the map they made); each refined cell must lie in
    /// `Ω^l`.
    pub fn with_refined(&self, refined: &[Vec<[usize; 2]>]) -> Result<Self> {
        let mut levels = vec![self.levels[0].knots.clone()];
        levels.extend(self.given.iter().cloned());
        Self::from_refined_levels(levels, refined)
    }

    /// Active functions of each level, coarse to fine.
    pub fn functions_per_level(&self) -> Vec<usize> {
        let mut out = vec![0; self.num_levels()];
        for &(l, _) in &self.active {
            out[l] += 1;
        }
        out
    }

    /// Active cells of each level, coarse to fine.
    pub fn cells_per_level(&self) -> Vec<usize> {
        let mut out = vec![0; self.num_levels()];
        for (l, _) in self.active_cells() {
            out[l] += 1;
        }
        out
    }

    /// The refined cells of every level ([`Self::refined_list`]), the trailing empty
    /// levels left out.
    pub(crate) fn refined_lists(&self) -> Vec<Vec<Index2>> {
        let mut refined: Vec<Vec<Index2>> = (0..self.num_levels()).map(|l| self.refined_list(l)).collect();
        while refined.last().is_some_and(Vec::is_empty) {
            refined.pop();
        }
        refined
    }

    /// Level-`l` refined cells as a sorted list (for writers).
    pub(crate) fn refined_list(&self, l: usize) -> Vec<Index2> {
        let mut v: Vec<Index2> = self.refined_cells(l).copied().collect();
        v.sort_by_key(|c| (c[1], c[0]));
        v
    }

    /// Rebuild a hierarchy from level-0 knots and the refined cells per level (as written
    /// by [`Self::refined_list`]); each refined cell must lie in `Ω^l`.
    pub(crate) fn from_refined(knots: [KnotVector; 2], refined: &[Vec<Index2>]) -> Result<Self> {
        Self::from_refined_levels(vec![knots], refined)
    }

    /// [`Self::from_refined`] on the hierarchy with the given levels
    /// ([`Self::with_levels`]: `levels[0]` is level 0).
    pub(crate) fn from_refined_levels(levels: Vec<[KnotVector; 2]>, refined: &[Vec<Index2>]) -> Result<Self> {
        let mut out = Self::with_levels(levels)?;
        for (l, cells) in refined.iter().enumerate() {
            if cells.is_empty() {
                continue;
            }
            out.ensure_level(l + 1)?;
            let shape = out.cell_shape(l);
            for &c in cells {
                if c[0] >= shape[0] || c[1] >= shape[1] || !out.in_domain(l, c) {
                    return Err(Error::Invalid(format!(
                        "refined cell ({}, {}) of level {l} is outside the level's domain",
                        c[0], c[1]
                    )));
                }
                out.refined[l].insert(c);
            }
        }
        out.update_active();
        Ok(out)
    }
}

/// Whether `fine` is `coarse` with one new simple knot strictly inside each element of
/// `coarse` (`true`; the knots of `coarse` kept with their multiplicities, same degree and
/// domain) or `coarse` itself (`false`: the direction is not split); why not otherwise.
fn splits_in_two(coarse: &KnotVector, fine: &KnotVector) -> std::result::Result<bool, String> {
    if coarse.degree() != fine.degree() || coarse.domain() != fine.domain() {
        return Err("another degree or domain than the level below".into());
    }
    if fine.is_periodic() || !fine.is_open() {
        return Err("not an open (clamped), non-periodic knot vector".into());
    }
    if fine == coarse {
        return Ok(false);
    }
    let (cb, fb) = (coarse.breaks_with_multiplicity(), fine.breaks_with_multiplicity());
    if fb.len() != 2 * cb.len() - 1 {
        return Err(format!("{} elements, not twice the {} below", fb.len() - 1, cb.len() - 1));
    }
    for (k, &(u, m)) in fb.iter().enumerate() {
        let ok = if k % 2 == 0 { cb[k / 2] == (u, m) } else { m == 1 && cb[k / 2].0 < u && u < cb[k / 2 + 1].0 };
        if !ok {
            return Err(format!("the knot {u} (multiplicity {m}) does not split one element of the level below"));
        }
    }
    Ok(true)
}
