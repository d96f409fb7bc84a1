//! Helpers of the workspace's tests (behind the `testutil` feature): the bundled test
//! data, deterministic pseudo-random numbers (no external crate), and the readers'
//! exercisers and mutators of the fuzz targets.

use std::path::{Path, PathBuf};

/// The bundled test data folder, `tests/data` at the workspace root (the shared
/// geometries, contours, rings, maps and G+Smo files).
pub fn data_dir() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).expect("crates/core sits two levels down");
    root.join("tests").join("data")
}

/// A bundled test file or folder: `data("gismo/duck.json")` is
/// `tests/data/gismo/duck.json` at the workspace root.
pub fn data(rel: &str) -> PathBuf {
    data_dir().join(rel)
}

/// The bundled files directly in the test data folder `rel` (`""`: `tests/data` itself)
/// whose extension is `ext`, sorted by name.
pub fn data_files(rel: &str, ext: &str) -> Vec<PathBuf> {
    let dir = data(rel);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("a readable folder entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    v.sort();
    v
}

/// A 64-bit linear congruential generator (Knuth's MMIX constants).
#[derive(Debug, Clone)]
pub struct Lcg(u64);

impl Lcg {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407))
    }
    /// Next raw value.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        self.0 ^ (self.0 >> 29)
    }
    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform integer in `0..n` (0 when `n == 0`).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }
}

/// A square of side 4 centred at the origin, its corners rounded at radius `r` (sharp for
/// `r = 0`), as a counter-clockwise closed point cloud with spacing about `h`, starting in
/// the middle of its bottom side (`ceil(pi r / 2h)` points on each quarter circle): the
/// contour of the ring tests of rounded corners (`boundary::ring_fit`, the CLI's rings).
pub fn rounded_square(r: f64, h: f64) -> Vec<[f64; 2]> {
    let q = std::f64::consts::FRAC_PI_2;
    let a = 2.0 - r;
    let mut pts = Vec::new();
    // a straight part from `from` up to `to` (excluded)
    let segment = |pts: &mut Vec<[f64; 2]>, from: [f64; 2], to: [f64; 2]| {
        let n = ((to[0] - from[0]).hypot(to[1] - from[1]) / h).ceil().max(1.0) as usize;
        pts.extend((0..n).map(|i| {
            let t = i as f64 / n as f64;
            [from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])]
        }));
    };
    let mut at = [0.0, -2.0];
    for (k, c) in [[a, -a], [a, a], [-a, a], [-a, -a]].into_iter().enumerate() {
        let start = -q + k as f64 * q;
        let on = |phi: f64| [c[0] + r * phi.cos(), c[1] + r * phi.sin()];
        segment(&mut pts, at, on(start));
        // (no arc on a sharp corner: the next straight part starts there)
        let m = if r > 0.0 { (q * r / h).ceil() as usize } else { 0 };
        pts.extend((0..m).map(|i| on(start + q * i as f64 / m as f64)));
        at = on(start + q);
    }
    segment(&mut pts, at, [0.0, -2.0]);
    pts
}

pub mod exercise;
pub mod mutate;

/// The metric Laplacian `K` (`Discretization::metric_laplace`, scaled operator) of a
/// stretched, sheared map on `p = 3` with `ne x ne` elements: a quarter annulus with
/// radii 1 and `1 + t`, stretched radially towards the inner side (`r = 1 + t v^2`,
/// degenerate at `v = 0` like a map into a reflex corner) and sheared (`g12 != 0`).
/// `t = 3`: cells of aspect ratio up to ~10 away from the inner side; `t = 0.03`: a
/// narrow gap, cells of aspect ratio 50 and more (`g11 / g22` above 2500).
pub(crate) fn stretched_laplacian(
    ne: usize,
    t: f64,
) -> (crate::discrete::assembly::Discretization, crate::linalg::sparse::Csr) {
    use crate::discrete::assembly::Operator;
    let (disc, cps) = stretched_map(ne, t);
    let mut st = vec![0.0; disc.stencil_len(1)];
    disc.metric_laplace(&cps, Operator::Scaled, 0.0, &mut st);
    let k = disc.scalar.matrix(&st);
    (disc, k)
}

/// A symmetric positive definite banded matrix of size `n` and bandwidth 3 (the
/// bandwidth of a cubic spline line), diagonally dominant, its entries drawn from `rng`.
#[cfg(test)]
pub(crate) fn banded_spd(n: usize, rng: &mut Lcg) -> crate::linalg::sparse::Csr {
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i, i, 8.0 + rng.uniform()));
        for d in 1..=3 {
            if i + d < n {
                let v = rng.uniform() - 0.5;
                t.push((i, i + d, v));
                t.push((i + d, i, v));
            }
        }
    }
    crate::linalg::sparse::Csr::from_triplets(n, n, &t)
}

/// The multigrid V-cycle of `--linear multigrid` for the metric Laplacian `K` of a
/// stretched, sheared quarter annulus (radii 1 and `1 + t`, `r = 1 + t v^2`; degree 3,
/// `ne x ne` elements, the knot-halving hierarchy of its interior functions), for the
/// back ends' tests. With `far`, `K + ε (e_0 e_last^T + e_last e_0^T)` (`ε` a thousandth
/// of the diagonal's mean): a coupling outside every stencil, so the levels are held
/// as CSR matrices, not stencils.
///
/// Errors: the set-up's ([`crate::Error::LinearSolver`]).
pub fn multigrid_cycle(ne: usize, t: f64, far: bool) -> crate::Result<crate::linalg::multigrid_kernels::Cycle> {
    let (disc, mut k) = stretched_laplacian(ne, t);
    if far {
        let n = k.nrows;
        let eps = 1e-3 * (0..n).map(|i| k.get(i, i)).sum::<f64>() / n as f64;
        let mut triplets: Vec<(usize, usize, f64)> =
            (0..n).flat_map(|i| k.row(i).map(move |(j, v)| (i, j, v))).collect();
        triplets.extend([(0, n - 1, eps), (n - 1, 0, eps)]);
        k = crate::linalg::sparse::Csr::from_triplets(n, n, &triplets);
    }
    let p = crate::discrete::transfers::free_prolongation_factors(&disc)?;
    crate::linalg::multigrid_kernels::Cycle::new(p, k)
}

/// The basis and control points of [`multigrid_cycle`]'s map (the stretched, sheared
/// quarter annulus of degree 3 on `ne x ne` elements, radii 1 and `1 + t`): the map whose
/// EGG Jacobian the GPU product's benchmark multiplies with.
pub fn stretched_map(ne: usize, t: f64) -> (crate::discrete::assembly::Discretization, Vec<[f64; 2]>) {
    use crate::discrete::assembly::Discretization;
    use crate::spline::knots::KnotVector;
    let kv = KnotVector::open_uniform(3, ne);
    let disc = Discretization::new([kv.clone(), kv.clone()]);
    let g = kv.greville();
    let mut cps = Vec::new();
    for &v in &g {
        for &u in &g {
            let r = 1.0 + t * v * v;
            let a = std::f64::consts::FRAC_PI_2 * (u + 0.2 * u * (1.0 - u) * v);
            cps.push([r * a.cos(), r * a.sin()]);
        }
    }
    (disc, cps)
}

/// The unsymmetric tridiagonal matrix `tridiag(-1, 2.5, -1.2)` of size `n` (a 1D
/// convection-diffusion operator): the system of the linear solvers' and GMRES's tests.
#[cfg(test)]
pub(crate) fn poisson_1d(n: usize) -> crate::linalg::sparse::Csr {
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i, i, 2.5));
        if i > 0 {
            t.push((i, i - 1, -1.0));
        }
        if i + 1 < n {
            t.push((i, i + 1, -1.2));
        }
    }
    crate::linalg::sparse::Csr::from_triplets(n, n, &t)
}
