//! Judging a map: the bijectivity certificate, the quality functionals and the
//! grid-quality benchmark.
//!
//! | module | holds | paper |
//! |---|---|---|
//! | [`certificate`] | [`certify`](certificate::certify): Bernstein bounds of `det J` with a rigorous rounding bound (`bernstein`: the error arithmetic; `element`: local origin, blossom extraction, coefficients; `search`: proof, fold witnesses, corner neighbourhoods) and subdivision; verdicts certified / degenerate corner / folded / undecided | §8.1, eq. (43) |
//! | [`quality`] | sampled `det J`, the functionals (Winslow eq. 15-16, area orthogonality, Liao, uniformity, harmonic energy), cell statistics, boundary deviation | §2, §4.1 |
//! | [`poisson`] | the Poisson benchmark `Q(x)` solved by IGA on the map | §10, eq. (44)-(45) |
//!
//! Defect correction (§8.2), which acts on the certificate's verdict, is a step of the
//! solve: `solve::repair`.

pub mod certificate;
pub mod poisson;
pub mod quality;
