//! Bounded memory: the peak a solve will reach, estimated from the basis sizes of the
//! levels it will walk before anything large is allocated, and the limit it is checked
//! against ([`MemoryLimit`], `--max-memory`).
//!
//! **Model.** The finest level dominates (the levels below it are at least
//! [`growth`](super::options::LevelOptions::growth) times smaller and freed before it
//! starts). On a tensor basis of `n_ξ × n_η` functions of degrees `(p, q)` two functions
//! interact when their supports share an element, so the scalar pattern has
//! `z_1 = z(Ξ) z(H)` nonzeros, `z(Ξ) = Σ_i #{j : supp B_i ∩ supp B_j ≠ ∅}`
//! (`(2p + 1) n_ξ − p (p + 1)` on an open vector with simple interior knots, `(2p + 1)
//! n_ξ` on a periodic one), and the vector Jacobian of eq. (23) has `z = 4 z_1`. What a
//! Newton step holds is a small number of arrays of that size (the stencil storage, the
//! Jacobian in CSR, the elasticity and preconditioner matrices, their single-precision
//! nested-dissection Cholesky factors, whose fill on these meshes is of the same order,
//! the Krylov basis), plus vectors of the unknowns' length, so the peak is modelled as
//!
//! ```text
//! peak ≈ BASE + BYTES_PER_UNKNOWN · 2 n_ξ n_η + BYTES_PER_NONZERO · z
//! ```
//!
//! with [`BASE`] the process without a problem and the two weights calibrated on the
//! peak resident memory (`VmHWM`, which `winslow bench --json` prints as `peak_mib` next to
//! this estimate as `estimated_mib`) of `wavy_lid` on its input basis (degrees 3 x 2) and
//! on fitted bases of degree 2, 3 and 4, each at three sizes from 4 400 to 1 000 000
//! unknowns: the measured peak is 0.87 to 1.08 times the estimate (docs/solve.md,
//! "Memory", has the table and the commands).
//!
//! **Allocation failure is never an abort.** The estimate is checked against the limit
//! before the fit's hierarchy is solved ([`Error::Memory`], naming what lowers it); each
//! level then reserves its estimated peak with `try_reserve` and releases it before it
//! allocates ([`reserve`]), so an address-space limit (`ulimit -v`) that the limit did not
//! see is a typed error too, not the allocator's abort.

pub use crate::error::human;
use crate::error::{Error, Result};
use crate::linalg::linsolve::LinearMethod;
use crate::spline::knots::KnotVector;

/// Resident memory of the process before a problem is allocated (binary, thread pool,
/// input and fit), bytes.
pub const BASE: u64 = 16 << 20;

/// Peak bytes per nonzero of the finest level's vector Jacobian (see the module
/// documentation for the calibration).
pub const BYTES_PER_NONZERO: u64 = 68;

/// Peak bytes per unknown of the finest level (see the module documentation).
pub const BYTES_PER_UNKNOWN: u64 = 200;

/// Peak bytes per nonzero of the finest level's vector Jacobian with `--linear
/// multigrid` ([`LinearMethod::Multigrid`]): the Newton systems are solved over the
/// stencil storage in single precision (`discrete::stencil::Stencil32`, assembled by
/// row bands on the CPU: `Discretization::egg_single`), and neither the vector nor the
/// scalar pattern is built (`K` goes to the V-cycle as a grid stencil, the elasticity
/// blocks come from their stencil storage, the transfers are 1D factors). The V-cycle
/// is set up before the Jacobian is assembled; the peak is now the assembly of a later
/// Newton step beside the frozen V-cycle, or its flexible GMRES basis, and these
/// constants over-estimate it by 1.1-1.5x at about 10^6 unknowns (BENCHMARKS.md, "10^6
/// unknowns on 2 cores"; not refitted). With
/// [`MULTIGRID_BYTES_PER_UNKNOWN`] fitted to the peaks (`VmHWM`, dev profile, one
/// geometry per process; `WINSLOW_MEMORY_TRACE` shows the stage) of quarter_annulus at
/// 918 k and male_rotor at 2.13 M unknowns (degrees 3 x 2 and 3: 70 and 98 nonzeros per
/// unknown): measured over estimated 0.98 and 1.05 there, 0.99-1.26 on quarter_annulus,
/// wavy_lid, puzzle4 (degree 2: 50 nonzeros per unknown) and male_rotor at `--refine 4`
/// and `5` (BENCHMARKS.md, "Under 1 KiB per unknown").
pub(crate) const MULTIGRID_BYTES_PER_NONZERO: u64 = 11;

/// Peak bytes per unknown of the finest level with `--linear multigrid` (see
/// [`MULTIGRID_BYTES_PER_NONZERO`]): the vectors of a Newton step and of the flexible
/// GMRES basis (two per iteration), and the freed vectors the allocator keeps.
pub(crate) const MULTIGRID_BYTES_PER_UNKNOWN: u64 = 150;

/// Unknowns of a level from which `--linear auto` ([`LinearMethod::Auto`]) solves its
/// Newton systems as `--linear multigrid` does ([`auto_linear`]); below it, GMRES
/// preconditioned by the single-precision Cholesky factor of `K` (LU up to 64 unknowns).
/// Chosen on the CPU seconds and peaks of both at refine 4, 5 and 6 of four geometries
/// (BENCHMARKS.md, "Under 1 KiB per unknown, and `--linear auto` choosing multigrid": no
/// size wins on time on all four; from about 10^6 unknowns multigrid is within 0.94-1.26x
/// of the CPU time at 4-5x less memory).
pub(crate) const AUTO_MULTIGRID_UNKNOWNS: usize = 800_000;

/// The linear solver of a level with knot vectors `knots` when `requested` is asked
/// for: `requested` itself unless it is [`LinearMethod::Auto`]; for `Auto`,
/// [`LinearMethod::Multigrid`] on a non-periodic tensor basis of at least
/// [`AUTO_MULTIGRID_UNKNOWNS`] unknowns, or of fewer whose estimated peak with the direct
/// preconditioner ([`MemoryEstimate::for_knots_with`]) exceeds `limit` (bytes; `None`:
/// no limit) while the multigrid one does not; `Auto` otherwise.
pub(crate) fn auto_linear(knots: &[KnotVector; 2], requested: LinearMethod, limit: Option<u64>) -> LinearMethod {
    if requested != LinearMethod::Auto || knots.iter().any(KnotVector::is_periodic) {
        return requested;
    }
    let direct = MemoryEstimate::with_weights(knots, BYTES_PER_UNKNOWN, BYTES_PER_NONZERO);
    if direct.unknowns >= AUTO_MULTIGRID_UNKNOWNS {
        return LinearMethod::Multigrid;
    }
    let multigrid = MemoryEstimate::with_weights(knots, MULTIGRID_BYTES_PER_UNKNOWN, MULTIGRID_BYTES_PER_NONZERO);
    match limit {
        Some(limit) if direct.bytes > limit && multigrid.bytes <= limit => LinearMethod::Multigrid,
        _ => LinearMethod::Auto,
    }
}

/// With the environment variable `WINSLOW_MEMORY_TRACE` set, one line on standard error
/// per call: `stage`, the resident memory now (`VmRSS`) and the peak so far (`VmHWM`), in
/// MiB (Linux; nothing elsewhere). The stages of a solve (each level's set-up, elasticity
/// prolongation, Newton assembly, preconditioner set-up, Krylov solve, certificate,
/// report) then show where its peak is reached (BENCHMARKS.md, "Under 1 KiB per unknown").
pub fn trace(stage: impl FnOnce() -> String) {
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    if !*ON.get_or_init(|| std::env::var_os("WINSLOW_MEMORY_TRACE").is_some()) {
        return;
    }
    let Ok(status) = std::fs::read_to_string("/proc/self/status") else { return };
    let mib = |key: &str| field_kib(&status, key).map_or(0.0, |kb| kb as f64 / 1024.0);
    eprintln!("memory: {:<48} rss {:>9.1} MiB  peak {:>9.1} MiB", stage(), mib("VmRSS:"), mib("VmHWM:"));
}

/// How much more than the fixed stage's sum a layout's free-interface stage takes. Measured
/// (VmHWM, dev profile, TUDflame's 5 patches, `--refine 2, 3, 4`): fixed 41, 121, 389 MiB
/// and free 102, 358, 1435 MiB against a sum of 67, 214, 800 MiB.
pub(crate) const FREE_INTERFACE_FACTOR: u64 = 2;

/// The estimated peak of a solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct MemoryEstimate {
    /// Basis functions of the finest level.
    pub functions: usize,
    /// Unknowns of the finest level (two per function).
    pub unknowns: usize,
    /// Nonzeros of the finest level's vector Jacobian, `4 z(Ξ) z(H)`.
    pub nonzeros: usize,
    /// Estimated peak resident memory, bytes.
    pub bytes: u64,
}

/// Pairs of functions of `kv` whose supports share an element: `z(Ξ)` of the module
/// documentation (counted exactly from the knots; a periodic vector's `dim` functions
/// each meet `2p + 1`, or all of them when there are fewer).
pub(crate) fn interacting_pairs(kv: &KnotVector) -> usize {
    let p = kv.degree();
    if kv.is_periodic() {
        let d = kv.dim();
        return d * (2 * p + 1).min(d);
    }
    let t = kv.knots();
    let n = kv.num_basis();
    // B_i lives on [t_i, t_{i+p+1}]; for i < j they share an element iff t_j < t_{i+p+1}
    let mut pairs = n;
    for i in 0..n {
        let end = t[i + p + 1];
        pairs += 2 * (i + 1..n).take_while(|&j| t[j] < end).count();
    }
    pairs
}

impl MemoryEstimate {
    /// The estimate for a solve whose finest level has the knot vectors `knots`.
    pub(crate) fn for_knots(knots: &[KnotVector; 2]) -> Self {
        Self::for_knots_with(knots, LinearMethod::Auto)
    }

    /// The estimate for a solve whose finest level has the knot vectors `knots` and
    /// whose Newton systems are solved by `linear`: [`MULTIGRID_BYTES_PER_NONZERO`] and
    /// [`MULTIGRID_BYTES_PER_UNKNOWN`] for [`LinearMethod::Multigrid`],
    /// [`BYTES_PER_NONZERO`] and [`BYTES_PER_UNKNOWN`] otherwise.
    pub(crate) fn for_knots_with(knots: &[KnotVector; 2], linear: LinearMethod) -> Self {
        match linear {
            LinearMethod::Multigrid => {
                Self::with_weights(knots, MULTIGRID_BYTES_PER_UNKNOWN, MULTIGRID_BYTES_PER_NONZERO)
            }
            _ => Self::with_weights(knots, BYTES_PER_UNKNOWN, BYTES_PER_NONZERO),
        }
    }

    /// `BASE + per_unknown · unknowns + per_nonzero · nonzeros` on the basis `knots`.
    fn with_weights(knots: &[KnotVector; 2], per_unknown: u64, per_nonzero: u64) -> Self {
        let functions = knots[0].dim() * knots[1].dim();
        let nonzeros = 4 * interacting_pairs(&knots[0]) * interacting_pairs(&knots[1]);
        let unknowns = 2 * functions;
        let bytes = BASE
            .saturating_add(per_unknown.saturating_mul(unknowns as u64))
            .saturating_add(per_nonzero.saturating_mul(nonzeros as u64));
        Self { functions, unknowns, nonzeros, bytes }
    }

    /// The estimate for a multipatch layout whose patches have the knot vectors
    /// `patches`: the fixed stage solves patches side by side, so the per-unknown and
    /// per-nonzero terms are summed over the patches (one [`BASE`]); the free-interface
    /// stage (`free`) factors the vector Hessian of all patches at once, which takes
    /// [`FREE_INTERFACE_FACTOR`] times that sum.
    pub(crate) fn for_patches<'a>(patches: impl IntoIterator<Item = &'a [KnotVector; 2]>, free: bool) -> Self {
        let mut sum = Self { functions: 0, unknowns: 0, nonzeros: 0, bytes: 0 };
        for k in patches {
            let e = Self::for_knots(k);
            sum.functions += e.functions;
            sum.unknowns += e.unknowns;
            sum.nonzeros += e.nonzeros;
            sum.bytes = sum.bytes.saturating_add(e.bytes - BASE);
        }
        let factor = if free { FREE_INTERFACE_FACTOR } else { 1 };
        sum.bytes = BASE.saturating_add(sum.bytes.saturating_mul(factor));
        sum
    }
}

/// The most memory a solve may take (`--max-memory`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MemoryLimit {
    /// What the machine has available when the solve starts (`available_memory`); no
    /// limit where that cannot be read (systems other than Linux).
    #[default]
    Available,
    /// This many bytes.
    Bytes(u64),
    /// No limit.
    Unlimited,
}

impl MemoryLimit {
    /// `available`, `none`, or a size: a number of bytes with an optional suffix `K`, `M`,
    /// `G` or `T` (powers of 1024; `KiB`, `MB`, ... accepted alike), e.g. `4G`, `512M`,
    /// `1.5G`.
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim() {
            "available" => return Some(MemoryLimit::Available),
            "none" | "unlimited" => return Some(MemoryLimit::Unlimited),
            _ => {}
        }
        let t = s.trim().trim_end_matches(['b', 'B']).trim_end_matches(['i', 'I']);
        let (num, shift) = match t.chars().last()? {
            'k' | 'K' => (&t[..t.len() - 1], 10),
            'm' | 'M' => (&t[..t.len() - 1], 20),
            'g' | 'G' => (&t[..t.len() - 1], 30),
            't' | 'T' => (&t[..t.len() - 1], 40),
            _ => (t, 0),
        };
        let v: f64 = num.trim().parse().ok()?;
        let bytes = v * (1u64 << shift) as f64;
        (bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64).then_some(MemoryLimit::Bytes(bytes as u64))
    }

    /// The limit in bytes and where it comes from; `None`: no limit.
    pub(crate) fn resolve(&self) -> Option<(u64, String)> {
        match *self {
            MemoryLimit::Available => available_memory(),
            MemoryLimit::Bytes(b) => Some((b, "--max-memory".into())),
            MemoryLimit::Unlimited => None,
        }
    }

    /// [`Error::Memory`] when `estimate` exceeds the limit; `refine` is the solve's
    /// extra uniform refinements, named in the advice.
    pub fn check(&self, estimate: &MemoryEstimate, refine: usize, what: &str) -> Result<()> {
        let Some((limit, source)) = self.resolve() else { return Ok(()) };
        if estimate.bytes <= limit {
            return Ok(());
        }
        Err(Error::Memory {
            what: format!(
                "{what}: {} unknowns, {} Jacobian nonzeros on the finest level",
                estimate.unknowns, estimate.nonzeros
            ),
            needed: estimate.bytes,
            available: limit,
            limit: source,
            advice: advice(estimate, refine),
        })
    }
}

/// What lowers the peak: each uniform halving multiplies it by about 4.
fn advice(estimate: &MemoryEstimate, refine: usize) -> String {
    let quarter = BASE + (estimate.bytes - BASE.min(estimate.bytes)) / 4;
    if refine > 0 {
        format!("--refine {} needs about {} (each halving takes about 4x the memory)", refine - 1, human(quarter))
    } else {
        "a coarser basis needs less: a larger --fit-tol, a smaller --min-elements, or --basis input".into()
    }
}

/// The memory this process may still take, and where that figure comes from: the least
/// of the kernel's `MemAvailable` (`/proc/meminfo`), the cgroup's limit less its usage
/// (v2 `memory.max`, v1 `memory.limit_in_bytes`) and the address-space limit (`ulimit
/// -v`, `/proc/self/limits`) less the address space in use. `None` where none of them
/// can be read (systems other than Linux): no default limit there.
pub(crate) fn available_memory() -> Option<(u64, String)> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let num = |s: Option<String>| s.and_then(|s| s.trim().parse::<u64>().ok());
    let mut best: Option<(u64, String)> = None;
    let mut offer = |bytes: u64, what: &str| {
        if best.as_ref().is_none_or(|(b, _)| bytes < *b) {
            best = Some((bytes, what.to_string()));
        }
    };
    if let Some(kb) = read("/proc/meminfo").and_then(|s| field_kib(&s, "MemAvailable:")) {
        offer(kb << 10, "available memory (MemAvailable)");
    }
    for (max, current) in [
        ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
        ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes"),
    ] {
        if let (Some(max), Some(used)) = (num(read(max)), num(read(current))) {
            // v1 writes "no limit" as a huge number
            if max < 1 << 60 {
                offer(max.saturating_sub(used), "the cgroup's memory limit");
            }
        }
    }
    if let Some(limit) = read("/proc/self/limits").and_then(|s| address_space_limit(&s)) {
        let used = read("/proc/self/status").and_then(|s| field_kib(&s, "VmSize:")).unwrap_or(0) << 10;
        offer(limit.saturating_sub(used), "the address-space limit (ulimit -v)");
    }
    best
}

/// `KEY   1234 kB` in a `/proc` file.
fn field_kib(s: &str, key: &str) -> Option<u64> {
    s.lines().find(|l| l.starts_with(key))?.split_whitespace().nth(1)?.parse().ok()
}

/// The soft limit of "Max address space" in `/proc/self/limits`; `None` when unlimited.
fn address_space_limit(s: &str) -> Option<u64> {
    let line = s.lines().find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..].split_whitespace().next()?.parse().ok()
}

/// The address space that faer's dense products take on x86-64 (its `private-gemm-x86`
/// kernels) in each thread that runs one: a thread-local buffer of twice the L3 cache,
/// allocated (not touched) on the thread's first product and kept. On a machine that
/// reports a 480 MiB L3 this is 960 MiB per thread, which an address-space limit
/// (`ulimit -v`) may not hold: the allocation then aborts inside faer. Counted for the
/// main thread and every thread of the pool; 0 where the L3 size is not known (Linux's
/// `/sys/devices/system/cpu/cpu0/cache`) or on other architectures.
pub fn dense_product_workspace() -> u64 {
    static L3: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    let l3 = *L3.get_or_init(|| if cfg!(target_arch = "x86_64") { l3_cache_bytes().unwrap_or(0) } else { 0 });
    2 * l3 * (rayon::current_num_threads() as u64 + 1)
}

/// The size of the L3 cache from Linux's sysfs (`index*/level` 3, `size` like `491520K`).
fn l3_cache_bytes() -> Option<u64> {
    let dir = std::path::Path::new("/sys/devices/system/cpu/cpu0/cache");
    std::fs::read_dir(dir).ok()?.flatten().find_map(|e| {
        let level = std::fs::read_to_string(e.path().join("level")).ok()?;
        (level.trim() == "3").then_some(())?;
        cache_size(&std::fs::read_to_string(e.path().join("size")).ok()?)
    })
}

/// `491520K`, `32M` or `1024` as bytes.
fn cache_size(s: &str) -> Option<u64> {
    let s = s.trim();
    let (digits, unit) = match s.char_indices().find(|(_, c)| !c.is_ascii_digit()) {
        Some((i, _)) => (&s[..i], &s[i..]),
        None => (s, ""),
    };
    let n: u64 = digits.parse().ok()?;
    let k = match unit {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        _ => return None,
    };
    n.checked_mul(k)
}

/// Reserve `bytes`, and the address space of the dense products
/// ([`dense_product_workspace`]), and release them at once: [`Error::Memory`] when the
/// allocator refuses (an address-space limit, a heuristic overcommit refusal), instead of
/// the abort that a failing allocation inside the solve would be. Pages are not touched.
pub fn reserve(bytes: u64, what: &str) -> Result<()> {
    let bytes = bytes.saturating_add(dense_product_workspace());
    let mut probe: Vec<u8> = Vec::new();
    let n = usize::try_from(bytes).unwrap_or(usize::MAX);
    probe.try_reserve_exact(n).map_err(|_| Error::Memory {
        what: what.into(),
        needed: bytes,
        available: available_memory().map_or(0, |a| a.0),
        limit: "the allocator refused".into(),
        advice: "ask for less (--refine, --fit-tol), or raise the limit".into(),
    })
}

#[cfg(test)]
/// A vector of `n` copies of `value`, [`Error::Memory`] instead of an abort when it
/// cannot be allocated.
pub(crate) fn try_filled<T: Clone>(n: usize, value: T, what: &str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    let bytes = (n as u64).saturating_mul(std::mem::size_of::<T>() as u64);
    v.try_reserve_exact(n).map_err(|_| Error::Memory {
        what: what.into(),
        needed: bytes,
        available: available_memory().map_or(0, |a| a.0),
        limit: "the allocator refused".into(),
        advice: "ask for less (--refine, --fit-tol), or raise the limit".into(),
    })?;
    v.resize(n, value);
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(MemoryLimit::parse("4G"), Some(MemoryLimit::Bytes(4 << 30)));
        assert_eq!(MemoryLimit::parse("512M"), Some(MemoryLimit::Bytes(512 << 20)));
        assert_eq!(MemoryLimit::parse("512MiB"), Some(MemoryLimit::Bytes(512 << 20)));
        assert_eq!(MemoryLimit::parse("1.5g"), Some(MemoryLimit::Bytes(3 << 29)));
        assert_eq!(MemoryLimit::parse("64k"), Some(MemoryLimit::Bytes(64 << 10)));
        assert_eq!(MemoryLimit::parse("1000"), Some(MemoryLimit::Bytes(1000)));
        assert_eq!(MemoryLimit::parse("none"), Some(MemoryLimit::Unlimited));
        assert_eq!(MemoryLimit::parse("available"), Some(MemoryLimit::Available));
        for bad in ["", "G", "-1G", "0", "x", "nanG", "1e30T"] {
            assert_eq!(MemoryLimit::parse(bad), None, "{bad}");
        }
    }

    /// `z(Ξ)` counted from the knots equals the closed forms: `(2p + 1) n − p (p + 1)`
    /// on open vectors with simple knots, fewer pairs across a `C^0` knot (the supports
    /// of the two sides meet only in the knot's own function), `(2p + 1) d` periodic.
    #[test]
    fn interacting_pairs_match_the_closed_forms() {
        for p in 1..=4 {
            for e in [1, 2, 5, 16] {
                let kv = KnotVector::open_uniform(p, e);
                let n = kv.num_basis();
                let brute = (0..n)
                    .flat_map(|i| (0..n).map(move |j| (i, j)))
                    .filter(|&(i, j)| {
                        let t = kv.knots();
                        t[i].max(t[j]) < t[i + p + 1].min(t[j + p + 1])
                    })
                    .count();
                assert_eq!(interacting_pairs(&kv), brute, "p {p}, {e} elements");
                if n > p {
                    assert_eq!(brute, (2 * p + 1) * n - p * (p + 1), "p {p}, {e} elements");
                }
            }
        }
        let kv = KnotVector::periodic_uniform(3, 16);
        assert_eq!(interacting_pairs(&kv), 7 * kv.dim());
        let c0 = KnotVector::open_from_breaks(2, &[0.0, 0.5, 1.0], 2);
        assert!(interacting_pairs(&c0) < 5 * c0.num_basis() - 6);
    }

    /// The estimate grows with the basis (about 4x per uniform halving) and the check
    /// refuses with the typed error, naming the refinement that fits.
    #[test]
    fn estimates_grow_and_the_check_refuses() {
        let k = |e| [KnotVector::open_uniform(3, e), KnotVector::open_uniform(3, e)];
        let (a, b) = (MemoryEstimate::for_knots(&k(64)), MemoryEstimate::for_knots(&k(128)));
        let ratio = (b.bytes - BASE) as f64 / (a.bytes - BASE) as f64;
        assert!((3.5..4.5).contains(&ratio), "{ratio}");
        assert_eq!(b.unknowns, 2 * 131 * 131);
        assert!(MemoryLimit::Bytes(b.bytes).check(&b, 1, "x").is_ok());
        assert!(MemoryLimit::Unlimited.check(&b, 1, "x").is_ok());
        let e = MemoryLimit::Bytes(b.bytes - 1).check(&b, 2, "wavy").unwrap_err();
        let Error::Memory { needed, available, ref advice, .. } = e else { panic!("{e}") };
        assert_eq!((needed, available), (b.bytes, b.bytes - 1));
        assert!(advice.contains("--refine 1"), "{advice}");
    }

    /// `--linear auto` on a level: unchanged below [`AUTO_MULTIGRID_UNKNOWNS`] unless the
    /// factorization's estimate exceeds the limit while multigrid's fits; multigrid from
    /// that size on; an explicit solver and a periodic basis are never changed.
    #[test]
    fn auto_switches_to_multigrid_by_size_and_by_memory() {
        let k = |e| [KnotVector::open_uniform(3, e), KnotVector::open_uniform(3, e)];
        let (small, large) = (k(200), k(640));
        let (a, m) = (LinearMethod::Auto, LinearMethod::Multigrid);
        let unknowns = |k: &[KnotVector; 2]| MemoryEstimate::for_knots(k).unknowns;
        assert!(unknowns(&small) < AUTO_MULTIGRID_UNKNOWNS && unknowns(&large) >= AUTO_MULTIGRID_UNKNOWNS);
        assert_eq!(auto_linear(&small, a, None), a);
        assert_eq!(auto_linear(&large, a, None), m);
        assert_eq!(auto_linear(&large, LinearMethod::Gmres, None), LinearMethod::Gmres);
        let direct = MemoryEstimate::for_knots_with(&small, a).bytes;
        let multigrid = MemoryEstimate::for_knots_with(&small, m).bytes;
        assert!(multigrid < direct / 3, "{multigrid} against {direct}");
        assert_eq!(auto_linear(&small, a, Some(direct)), a);
        assert_eq!(auto_linear(&small, a, Some(direct - 1)), m);
        assert_eq!(auto_linear(&small, a, Some(multigrid - 1)), a);
        let ring = [KnotVector::open_uniform(3, 640), KnotVector::periodic_uniform(3, 640)];
        assert_eq!(auto_linear(&ring, a, Some(1)), a);
    }

    #[test]
    fn proc_files_parse() {
        let limits = "Limit                     Soft Limit           Hard Limit           Units     \n\
                      Max address space         4294967296           unlimited            bytes     \n";
        assert_eq!(address_space_limit(limits), Some(4294967296));
        assert_eq!(
            address_space_limit("Max address space         unlimited            unlimited            bytes"),
            None
        );
        assert_eq!(field_kib("MemTotal: 10 kB\nMemAvailable:   2048 kB\n", "MemAvailable:"), Some(2048));
    }

    #[test]
    fn impossible_reservations_are_a_typed_error() {
        assert_eq!(cache_size("491520K"), Some(480 << 20));
        assert_eq!(cache_size("32M\n"), Some(32 << 20));
        assert_eq!(cache_size("4096"), Some(4096));
        assert_eq!(cache_size("12X"), None);
        let e = reserve(u64::MAX / 2, "a test").unwrap_err();
        assert!(matches!(e, Error::Memory { .. }), "{e}");
        assert!(reserve(1 << 20, "a test").is_ok());
        assert!(matches!(try_filled(usize::MAX / 16, 0.0f64, "a test"), Err(Error::Memory { .. })));
        assert_eq!(try_filled(3, 1u8, "a test").unwrap(), vec![1, 1, 1]);
    }
}
