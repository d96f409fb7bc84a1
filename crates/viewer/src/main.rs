//! `winslow-viewer`: the desktop viewer. `winslow-viewer [FILE]` opens a boundary, ring,
//! map, multipatch, domain or graph file (a domain or graph as its automatic layout);
//! `--solve` solves a boundary, ring or layout at start; `--screenshot PNG` writes the window to a
//! PNG once everything is drawn, then exits (for the README picture; under Xvfb on a
//! machine without a display).

use std::path::PathBuf;

use anyhow::{anyhow, Context, Result};
use clap::Parser;
use winslow_viewer::colour::ScaleKind;
use winslow_viewer::sampler::sampler_for;
use winslow_viewer::ViewerApp;

/// Desktop viewer of winslow boundaries and maps: det J heat maps, grid lines,
/// certificate, live solves.
#[derive(Debug, Parser)]
#[command(name = "winslow-viewer", version)]
struct Args {
    /// Boundary, ring, map, multipatch layout, domain or plane-graph file (JSON or G+Smo
    /// XML) to open; a domain or graph opens as its automatic layout.
    file: Option<PathBuf>,
    /// Solve the boundary, ring or layout as soon as it is open.
    #[arg(long)]
    solve: bool,
    /// Smallest number of elements per direction of the finest level (with --solve).
    #[arg(long)]
    min_elements: Option<usize>,
    /// Grid lines (iso-lines of xi and eta) per direction.
    #[arg(long, default_value_t = 16)]
    grid: usize,
    /// Heat-map cells per direction (default: 8 per element, 96 to 256).
    #[arg(long)]
    resolution: Option<usize>,
    /// Colour scale of det J: log or linear.
    #[arg(long, default_value = "log", value_parser = ["log", "linear"])]
    scale: String,
    /// Show the control net.
    #[arg(long)]
    net: bool,
    /// Window size in points, WIDTHxHEIGHT.
    #[arg(long, default_value = "1400x860")]
    size: String,
    /// Where det J heat maps are sampled: cpu (the core), gpu (the WGSL kernel on any
    /// adapter, lavapipe included; none is an error) or auto (a hardware GPU with f64, else
    /// the CPU).
    #[arg(long, default_value = "cpu", value_parser = ["cpu", "gpu", "auto"])]
    backend: String,
    /// Write a PNG of the window once everything is drawn (after --solve finished), then exit.
    #[arg(long, value_name = "PNG")]
    screenshot: Option<PathBuf>,
}

fn parse_size(s: &str) -> Result<[f32; 2]> {
    let (w, h) = s.split_once('x').ok_or_else(|| anyhow!("--size must be WIDTHxHEIGHT, got {s:?}"))?;
    let p = |v: &str| -> Result<f32> {
        let x: f32 = v.trim().parse().with_context(|| format!("--size {s:?}"))?;
        if !(64.0..=16384.0).contains(&x) {
            return Err(anyhow!("--size {s:?}: each side must be between 64 and 16384"));
        }
        Ok(x)
    };
    Ok([p(w)?, p(h)?])
}

fn main() {
    let args = Args::parse();
    if let Err(e) = run(args) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(args: Args) -> Result<()> {
    let size = parse_size(&args.size)?;
    let backend = match args.backend.as_str() {
        "gpu" => winslow_gpu::Backend::Gpu,
        "auto" => winslow_gpu::Backend::Auto,
        _ => winslow_gpu::Backend::Cpu,
    };
    let sampler = sampler_for(backend).context("opening the GPU for --backend")?;
    let mut app = ViewerApp::new(sampler);
    let st = &mut app.state;
    st.settings.density = args.grid.clamp(2, 256);
    st.settings.resolution = args.resolution;
    st.display.scale = if args.scale == "linear" { ScaleKind::Linear } else { ScaleKind::Log };
    st.display.net = args.net;
    if let Some(m) = args.min_elements {
        st.solve.min_elements = m;
    }
    if let Some(f) = &args.file {
        if let Err(e) = st.open(f) {
            if args.screenshot.is_some() {
                return Err(anyhow!(e));
            }
            eprintln!("error: {e}");
        }
    }
    let solve = args.solve;
    if let Some(p) = args.screenshot.clone() {
        app.screenshot_and_exit(p);
    }
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("winslow viewer")
            .with_inner_size(size)
            .with_drag_and_drop(true),
        ..Default::default()
    };
    eframe::run_native(
        "winslow viewer",
        options,
        Box::new(move |cc| {
            if solve {
                let ctx = cc.egui_ctx.clone();
                if !app.state.start_solve(move || ctx.request_repaint()) {
                    eprintln!("--solve: nothing to solve (no valid boundary or layout loaded)");
                }
            }
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| anyhow!("could not open the window: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("800x600").unwrap(), [800.0, 600.0]);
        assert!(parse_size("800").is_err());
        assert!(parse_size("10x600").is_err());
        assert!(parse_size("axb").is_err());
    }

    #[test]
    fn cli_definition_is_consistent() {
        use clap::CommandFactory;
        Args::command().debug_assert();
    }
}
