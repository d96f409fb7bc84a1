//! Keyword options of `solve` and `solve_many`, mirroring the command line's solver
//! flags and the core's [`SolveOptions`] (names with underscores), validated by
//! [`SolveOptions::validate`] with the core's messages.

use clap::ValueEnum;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use winslow::boundary::BasisChoice;
use winslow::discrete::assembly::Operator;
use winslow::linalg::linsolve::LinearMethod;
use winslow::solve::improve::Improve;
use winslow::solve::memory::MemoryLimit;
use winslow::solve::newton::NonlinearMethod;
use winslow::SolveOptions;

use crate::errors::{invalid, IntoPy};

/// The keyword options understood, for the message of an unknown one.
pub const KNOWN: &[&str] = &[
    "degree",
    "fit_tol",
    "basis",
    "reparam",
    "tol",
    "iteration",
    "linear",
    "operator",
    "min_elements",
    "refine",
    "levels",
    "growth",
    "aspect",
    "sample",
    "repair",
    "repair_freeze",
    "poisson",
    "improve",
    "max_memory",
    "reorient",
];

/// The solve options and whether to reorient a clockwise boundary.
#[derive(Debug, Clone)]
pub struct Options {
    /// The core's options.
    pub solve: SolveOptions,
    /// Flip a clockwise boundary instead of refusing it (`--reorient`).
    pub reorient: bool,
}

/// A value of a command-line enum by its command-line name (`"scaled"`, `"newton"`).
pub fn choice<T: ValueEnum>(key: &str, s: &str) -> PyResult<T> {
    T::from_str(s, true).map_err(|_| {
        let names: Vec<String> = T::value_variants()
            .iter()
            .filter_map(|x| x.to_possible_value())
            .map(|p| p.get_name().to_string())
            .collect();
        invalid(format!("{key} must be one of {}, got {s:?}", names.join(", ")))
    })
}

/// The options of `kwargs` over the defaults.
pub fn parse(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Options> {
    parse_onto(SolveOptions::default(), kwargs)
}

/// The options of `kwargs` over `base` (a command's own defaults, as `compare`'s).
pub fn parse_onto(base: SolveOptions, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Options> {
    let mut o = base;
    let mut reorient = false;
    if let Some(kw) = kwargs {
        for (k, v) in kw.iter() {
            let key: String = k.extract()?;
            match key.as_str() {
                "degree" => o.fit.degree = v.extract()?,
                "fit_tol" => o.fit.tol = v.extract()?,
                "basis" => o.fit.basis = choice::<BasisChoice>(&key, &v.extract::<String>()?)?,
                "reparam" => o.fit.reparam.method = choice(&key, &v.extract::<String>()?)?,
                "tol" => o.nonlinear.tol = v.extract()?,
                "iteration" => o.nonlinear.method = choice::<NonlinearMethod>(&key, &v.extract::<String>()?)?,
                "linear" => o.nonlinear.linear = choice::<LinearMethod>(&key, &v.extract::<String>()?)?,
                "operator" => o.operator = choice::<Operator>(&key, &v.extract::<String>()?)?,
                "min_elements" => o.levels.min_elements = v.extract()?,
                "refine" => o.levels.refine = v.extract()?,
                "levels" => o.levels.max_levels = v.extract()?,
                "growth" => o.levels.growth = v.extract()?,
                "aspect" => o.levels.aspect = v.extract()?,
                "sample" => o.report.sample = v.extract()?,
                "repair" => o.repair.rounds = v.extract()?,
                "repair_freeze" => o.repair.freeze = v.extract()?,
                "poisson" => o.report.poisson = v.extract()?,
                "improve" => {
                    o.improve =
                        if v.is_none() { None } else { Some(choice::<Improve>(&key, &v.extract::<String>()?)?) };
                }
                "max_memory" => {
                    let s: String = v.extract()?;
                    o.max_memory = MemoryLimit::parse(&s).ok_or_else(|| {
                        invalid(format!("max_memory must be 'available', 'none' or a size such as '8G', got {s:?}"))
                    })?;
                }
                "reorient" => reorient = v.extract()?,
                _ => return Err(invalid(format!("unknown option {key:?}; the options are {}", KNOWN.join(", ")))),
            }
        }
    }
    o.validate().py_err()?;
    Ok(Options { solve: o, reorient })
}
