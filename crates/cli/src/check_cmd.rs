//! `winslow check MAP`: the bijectivity certificate of a map (a volume: the trivariate
//! one; a multipatch file: every patch), its quality, and optionally its boundary
//! deviation and the Poisson benchmark Q(x) (paper eq. 44-45).

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use winslow::io::Document;
use winslow::verify::certificate::{certify, CertifyOptions, Finding};
use winslow::verify::poisson::poisson_benchmark;
use winslow::verify::quality::{boundary_deviation, quality};

use crate::{files, load_boundary, loft_cmd, multipatch_cmd, output};

#[derive(Args, Debug)]
pub(crate) struct CheckArgs {
    /// Map file (JSON map document or G+Smo XML; a volume: the trivariate certificate; a
    /// multipatch file: every patch; a THB map: every active cell).
    map: PathBuf,
    /// The input boundary: report the largest deviation of the map's boundary from it.
    #[arg(long)]
    boundary: Option<PathBuf>,
    /// Also solve the grid-quality benchmark -Δu = -Δu* (paper eq. 44-45) and report Q(x).
    #[arg(long)]
    poisson: bool,
    /// Length scales a1,a2 of u* = sin(pi x / a1) sin(pi y / a2) (default: half the
    /// bounding box extents).
    #[arg(long, value_name = "A1,A2", value_parser = super::parse_scales)]
    poisson_scales: Option<[f64; 2]>,
    /// Most bisections per element in the certificate (also the depth of the excused
    /// neighbourhood of a forced corner: 2^-depth of the element).
    #[arg(long, default_value_t = CertifyOptions::default().max_depth)]
    max_depth: usize,
    /// Most Bernstein boxes examined per element.
    #[arg(long, default_value_t = CertifyOptions::default().max_boxes)]
    max_boxes: usize,
    /// Excuse no corner: corners of 180 degrees or more leave the verdict undecided (or
    /// folded) instead of degenerate-corner.
    #[arg(long)]
    strict_corners: bool,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

pub(crate) fn check(a: CheckArgs) -> Result<i32> {
    let opts = CertifyOptions {
        max_depth: a.max_depth.clamp(1, 40),
        max_boxes: a.max_boxes.clamp(1, 1 << 24),
        excuse_corners: !a.strict_corners,
    };
    let (name, map) = match files::read(&a.map)? {
        Document::Thb { name, map } => return crate::thb_cmd::check(&name, &map, &opts, a.json),
        Document::Volume { name, volume } => {
            return loft_cmd::check_volume(&name, &volume, a.max_depth, a.max_boxes, a.json)
        }
        Document::Layout(layout) | Document::Multipatch(layout) => return multipatch_cmd::check(layout, &opts, a.json),
        doc => {
            files::map_of(doc, &a.map, "check needs a map, a multipatch file or a volume (run `winslow solve` first)")?
        }
    };
    let certificate = certify(&map, &opts).context("certifying the map")?;
    let quality = quality(&map);
    let deviation = match &a.boundary {
        Some(p) => {
            let b = load_boundary(p, false)?;
            Some(boundary_deviation(&map, &b, 400))
        }
        None => None,
    };
    let poisson = if a.poisson {
        match poisson_benchmark(&map, a.poisson_scales) {
            Ok(r) => Some(r),
            Err(e) => {
                note!("warning: the Poisson benchmark could not be solved on this map: {e}");
                None
            }
        }
    } else {
        None
    };
    let report = output::CheckReport { name, certificate, quality, boundary_deviation: deviation, poisson };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        say_raw!("{}", output::check_text(&report));
    }
    Ok(match report.certificate.verdict {
        Finding::Certified { .. } | Finding::DegenerateCorner { .. } => 0,
        Finding::Folded { .. } => 3,
        Finding::Undecided { .. } => 5,
    })
}
