//! General planar domains and plane graphs (`formats.md`, "General planar domain",
//! "Plane graph") from the command line: `winslow layout DOMAIN.json` lays the domain out
//! only ([`winslow::domain::auto_layout`], [`winslow::domain::graph_layout`]) and writes
//! the layout and its picture; `winslow solve DOMAIN.json` runs the pipeline, which lays
//! it out and solves the layout, and prints the layout with [`summary`].

use super::*;
use crate::files;
use winslow::domain::{auto_layout, graph_layout, AutoLayout, Domain, LayoutOptions, PlaneGraph};
use winslow::io::picture::render_curves;

/// A document the automatic layout takes.
pub(crate) enum Planar {
    /// A general planar domain.
    Domain(Domain),
    /// A plane graph.
    Graph(PlaneGraph),
}

/// Lay `input` out with the fit options `fit`, or fail naming it.
fn lay_out(input: &Planar, fit: FitOptions) -> Result<AutoLayout> {
    let opts = LayoutOptions { fit, ..Default::default() };
    match input {
        Planar::Domain(d) => auto_layout(d, &opts).with_context(|| format!("laying out the domain {}", d.name)),
        Planar::Graph(g) => graph_layout(g, &opts).with_context(|| format!("laying out the plane graph {}", g.name)),
    }
}

/// One line per cut, face and irregular vertex.
pub(super) fn summary(auto: &AutoLayout) -> String {
    let r = &auto.report;
    let what = match (&r.domain, &r.graph) {
        (Some(d), _) => format!("{} corners, {} holes", d.outer_corners, d.hole_corners.len()),
        (_, Some(g)) => format!("{} vertices, {} edges, {} faces", g.vertices, g.edges, g.faces.len()),
        _ => String::new(),
    };
    let mut s = format!(
        "{}: {what}, area {:.6}; {} patches, {} cuts from holes, {} cuts from reflex corners, {} irregular interior vertices; corner angles {:.1} to {:.1} degrees ({:.3} s)\n",
        auto.layout.name,
        r.area,
        r.patches,
        r.hole_cuts.len(),
        r.cuts.len(),
        r.irregular_vertices.len(),
        r.corner_angles[0],
        r.corner_angles[1],
        r.seconds
    );
    for why in r.domain.iter().flat_map(|d| &d.reoriented) {
        s.push_str(&format!("  note: {why}\n"));
    }
    for c in &r.hole_cuts {
        s.push_str(&format!(
            "  cut from {} at ({:.6}, {:.6}) to the {} ({:.6}, {:.6})\n",
            c.hole, c.from[0], c.from[1], c.ends_on, c.to[0], c.to[1]
        ));
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

/// `winslow layout`: lay a general domain or a plane graph out into four-sided patches.
#[derive(Args, Debug)]
pub(super) struct LayoutArgs {
    /// The domain or plane graph document (`formats.md`, "General planar domain",
    /// "Plane graph").
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
    let input = match doc {
        Document::Domain(d) => Planar::Domain(d),
        Document::Graph(g) => Planar::Graph(g),
        doc => {
            return Err(files::wrong_kind(
                &doc,
                &a.domain,
                "a general planar domain (\"domain\") or a plane graph (\"graph\") is needed",
            ))
        }
    };
    let auto = lay_out(&input, fit_options(&a.fit))?;
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
