//! General planar domains (`formats.md`, "General planar domain") from the command
//! line: `winslow solve DOMAIN.json` lays the domain out automatically
//! ([`winslow::domain::auto_layout`]) and solves the layout like any multipatch layout;
//! `winslow layout DOMAIN.json` lays it out only, and writes the layout and its picture.

use super::*;
use crate::files;
use winslow::domain::{auto_layout, AutoLayout, Domain, LayoutOptions};
use winslow::io::picture::render_curves;

/// Lay `domain` out with the fit options `fit`, or fail naming the domain.
fn lay_out(domain: &Domain, fit: FitOptions) -> Result<AutoLayout> {
    auto_layout(domain, &LayoutOptions { fit, ..Default::default() })
        .with_context(|| format!("laying out the domain {}", domain.name))
}

/// One line per cut, face and irregular vertex.
fn summary(auto: &AutoLayout) -> String {
    let r = &auto.report;
    let mut s = format!(
        "{}: {} corners, area {:.6}; {} patches, {} cuts from reflex corners, {} irregular interior vertices; corner angles {:.1} to {:.1} degrees ({:.3} s)\n",
        auto.layout.name,
        r.domain.outer_corners,
        r.domain.area,
        r.patches,
        r.cuts.len(),
        r.irregular_vertices.len(),
        r.corner_angles[0],
        r.corner_angles[1],
        r.seconds
    );
    for why in &r.domain.reoriented {
        s.push_str(&format!("  note: {why}\n"));
    }
    for c in &r.cuts {
        s.push_str(&format!(
            "  cut from the {:.1}-degree corner ({:.6}, {:.6}) to the {} ({:.6}, {:.6})\n",
            c.angle, c.from[0], c.from[1], c.ends_on, c.to[0], c.to[1]
        ));
    }
    for f in &r.faces {
        s.push_str(&format!("  face {} with {} corners: {} ({} patches)\n", f.label, f.corners, f.template, f.patches));
    }
    for v in &r.irregular_vertices {
        s.push_str(&format!("  irregular vertex of valence {} at ({:.6}, {:.6})\n", v.valence, v.point[0], v.point[1]));
    }
    s
}

/// `winslow solve DOMAIN`: the automatic layout, then the multipatch solve.
pub(super) fn solve(domain: Domain, a: &SolveArgs, sel: &Selected) -> Result<i32> {
    let auto = lay_out(&domain, a.solver.options()?.fit)?;
    if !(output::quiet() || a.json) {
        eprint!("{}", summary(&auto));
    }
    let made = serde_json::to_value(&auto.report)?;
    super::solve_cmd::solve_layout(auto.layout, a, Some(made), sel)
}

/// `winslow layout`: lay a general domain out into four-sided patches.
#[derive(Args, Debug)]
pub(super) struct LayoutArgs {
    /// The domain document (`formats.md`, "General planar domain").
    domain: PathBuf,
    /// Write the layout as a multipatch document (every patch a boundary, naming its
    /// face), which `winslow solve` takes.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Draw the layout: the patch borders, and the irregular interior vertices as red
    /// crosses.
    #[arg(long)]
    png: Option<PathBuf>,
    #[command(flatten)]
    fit: FitArgs,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

pub(super) fn layout(a: LayoutArgs) -> Result<i32> {
    files::OutputPlan::new()
        .input(&a.domain)
        .maybe("-o", a.output.as_deref(), "layout", files::ext::JSON)
        .maybe("--png", a.png.as_deref(), "picture", files::ext::PNG)
        .check()?;
    let doc = files::read(&a.domain)?;
    let Document::Domain(domain) = doc else {
        return Err(files::wrong_kind(&doc, &a.domain, "a general planar domain (\"domain\") is needed"));
    };
    let auto = lay_out(&domain, fit_options(&a.fit))?;
    if let Some(p) = &a.output {
        files::write(p, &Output::Layout(&auto.layout))?;
    }
    if let Some(p) = &a.png {
        let curves: Vec<Vec<winslow::Point>> =
            auto.layout.patches.iter().flat_map(|p| p.sides.iter().map(|c| c.sample(64))).collect();
        let marks: Vec<winslow::Point> = auto.report.irregular_vertices.iter().map(|v| v.point).collect();
        files::write(p, &Output::Picture(&render_curves(&curves, &marks, 900)))?;
    }
    if a.json {
        files::print_json(serde_json::to_value(&auto.report)?)?;
    } else {
        say_raw!("{}", summary(&auto));
    }
    Ok(0)
}
