//! `winslow render` and `winslow convert`: a solved document drawn as a PNG, or written
//! in another format (by the output's extension). Both take every document they can
//! act on — a map (a ring map included), a multipatch result (or a G+Smo multipatch
//! file, whose patches are maps), and for `convert` a volume or the six faces of one
//! (JSON <-> G+Smo `<MultiPatch>`) — and name the kind they
//! got otherwise.

use super::*;
use winslow::io::{Output, Patches};
use winslow::multipatch::Layout;

use crate::files;

/// The patch maps of a layout whose every patch is a map, `None` otherwise.
fn patch_maps(layout: &Layout) -> Option<Vec<Surface>> {
    layout.patches.iter().map(|p| p.map.clone()).collect()
}

const RENDER_NEEDS: &str =
    "render draws a map, a THB map, a ring map or a multipatch result (run `winslow solve` first)";

/// `winslow render MAP --png OUT`.
pub(super) fn render(a: RenderArgs) -> Result<i32> {
    files::OutputPlan::new().input(&a.map).file("--png", &a.png, "picture", files::ext::PNG).check()?;
    let (doc, report) = files::read_with_report(&a.map)?;
    let report = report.unwrap_or_default();
    let segments = if a.no_matches { Vec::new() } else { winslow::boundary::reparam::matches_in_report(&report) };
    let kinks = winslow::boundary::kinks::kinks_in_report(&report);
    let (size, grid_lines) = (a.size.clamp(64, 8192), a.lines);
    let opts = PictureOptions { size, grid_lines, segments, kinks, ..Default::default() };
    let image = match &doc {
        Document::Map { map, .. } => {
            let sel = a.backend.select(false)?;
            picture(&sel, map, &opts)?
        }
        Document::Thb { map, .. } => winslow::io::picture::render_thb(map, &opts).context("drawing the THB map")?,
        Document::Layout(l) | Document::Multipatch(l) => match patch_maps(l) {
            Some(maps) => render_layout(&maps, &opts),
            None => return Err(files::wrong_kind(&doc, &a.map, RENDER_NEEDS)),
        },
        _ => return Err(files::wrong_kind(&doc, &a.map, RENDER_NEEDS)),
    };
    files::write(&a.png, &Output::Picture(&image))?;
    Ok(0)
}

/// The exit code of a planar certificate: 0 certified or degenerate corner, 3 folded,
/// 5 undecided.
fn planar_exit(v: &Finding) -> i32 {
    match v {
        Finding::Certified { .. } | Finding::DegenerateCorner { .. } => 0,
        Finding::Folded { .. } => 3,
        Finding::Undecided { .. } => 5,
    }
}

const CONVERT_NEEDS: &str =
    "convert writes a map, a ring map, a multipatch result, a volume (run `winslow solve` first) or the faces of a volume";

/// `winslow convert IN -o OUT`: certified again (the verdict travels with the file),
/// written by the output's extension.
pub(super) fn convert(a: ConvertArgs) -> Result<i32> {
    let doc = files::read(&a.map)?;
    if let Document::Thb { name, map } = &doc {
        return crate::thb_cmd::convert(name, map, &a.map, &a.output, a.thb);
    }
    if a.thb {
        anyhow::bail!("--thb keeps a THB map hierarchical, and {} holds no THB map", a.map.display());
    }
    if a.outline {
        return outline(doc, &a);
    }
    let (what, extensions) = match doc {
        Document::Volume { .. } => ("volume", files::ext::VOLUME),
        Document::VolumeBoundary(_) => ("volume boundary", files::ext::VOLUME_BOUNDARY),
        Document::Layout(_) | Document::Multipatch(_) => ("multipatch result", files::ext::MULTIPATCH),
        _ => ("map", files::ext::MAP),
    };
    files::OutputPlan::new().input(&a.map).file("-o", &a.output, what, extensions).check()?;
    match doc {
        Document::Map { name, map } => {
            let certificate = certify(&map, &CertifyOptions::default()).context("certifying the map")?;
            let label = format!("certificate: {}", certificate.message());
            let extra = Some(serde_json::json!({ "certificate": &certificate }));
            files::write(&a.output, &Output::Map { name: &name, map: &map, label: &label, extra })?;
            say!("{label}");
            Ok(planar_exit(&certificate.verdict))
        }
        Document::Volume { name, volume } => loft_cmd::convert_volume(&name, &volume, &a.output),
        // validated on read: the six faces share their edges and enclose a positive volume
        Document::VolumeBoundary(b) => {
            files::write(&a.output, &Output::VolumeBoundary(&b))?;
            say!("{}: six faces, validated", b.name);
            Ok(0)
        }
        Document::Layout(ref layout) | Document::Multipatch(ref layout) => {
            let Some(maps) = patch_maps(layout) else { return Err(files::wrong_kind(&doc, &a.map, CONVERT_NEEDS)) };
            convert_patches(layout, maps, &a.output)
        }
        other => Err(files::wrong_kind(&other, &a.map, CONVERT_NEEDS)),
    }
}

/// A multipatch document of maps, every patch certified again, written by extension
/// (.json, .xml, .vtm); the exit code of the worst patch.
fn convert_patches(layout: &Layout, maps: Vec<Surface>, output: &Path) -> Result<i32> {
    let mut reports = Vec::with_capacity(maps.len());
    let mut messages = Vec::with_capacity(maps.len());
    let mut codes = Vec::with_capacity(maps.len());
    for (p, map) in layout.patches.iter().zip(&maps) {
        let c = certify(map, &CertifyOptions::default()).with_context(|| format!("certifying patch {}", p.name))?;
        codes.push(planar_exit(&c.verdict));
        messages.push(c.message());
        reports.push(serde_json::json!({ "certificate": c }));
    }
    let bijective = codes.iter().filter(|&&c| c == 0).count();
    let message = format!("{bijective} of {} patches certified bijective (or best possible at a corner)", maps.len());
    let report = serde_json::json!({ "message": message });
    let patches = Patches { layout, maps, reports, messages, report, message: message.clone() };
    files::write(output, &Output::Multipatch(patches))?;
    say!("{message}");
    Ok(codes.into_iter().max().unwrap_or(0))
}

/// `winslow convert LAYOUT --outline -o DOMAIN.json`: the outer boundary and holes of a
/// multipatch layout as a `domain` document ([`winslow::domain::outline`]).
fn outline(doc: Document, a: &ConvertArgs) -> Result<i32> {
    files::OutputPlan::new().input(&a.map).file("-o", &a.output, "domain", files::ext::JSON).check()?;
    let (Document::Layout(layout) | Document::Multipatch(layout)) = doc else {
        return Err(files::wrong_kind(
            &doc,
            &a.map,
            "--outline takes a multipatch layout (G+Smo <MultiPatch> or JSON)",
        ));
    };
    let domain = winslow::domain::outline(&layout, a.smooth_below)
        .with_context(|| format!("the outline of the layout {}", layout.name))?;
    files::write(&a.output, &Output::Domain(&domain))?;
    say!(
        "{}: outer loop of {} sides, {} holes (sides joining within {} degrees merged)",
        domain.name,
        domain.outer.sides.len(),
        domain.holes.len(),
        a.smooth_below
    );
    Ok(0)
}

#[derive(Args, Debug)]
pub(crate) struct ConvertArgs {
    /// Map file (JSON map document, G+Smo XML or IGES; a THB map too), multipatch result, volume or
    /// volume boundary.
    pub(crate) map: PathBuf,
    /// Output file; the format follows its extension.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// A THB map stays a THB map (`.json` with the map kind "thb", `.xml` as G+Smo
    /// THBSpline2, `.vtu` as one Bézier cell per active cell); without it a THB map
    /// becomes the tensor map on its active cells' knot lines (exact).
    #[arg(long)]
    pub(crate) thb: bool,
    /// Write the outer boundary and holes of a multipatch layout as a general domain
    /// (`"domain"` document, .json): the patch sides in no interface chained into loops,
    /// which `winslow solve` lays out automatically.
    #[arg(long)]
    pub(crate) outline: bool,
    /// With --outline: consecutive sides whose tangents turn by less than this (degrees)
    /// become one curve (0 keeps every patch side a side of the domain).
    #[arg(long, default_value_t = 5.0, requires = "outline")]
    pub(crate) smooth_below: f64,
}

#[derive(Args, Debug)]
pub(crate) struct RenderArgs {
    /// Map file (a ring map or a multipatch result too).
    pub(crate) map: PathBuf,
    /// Output PNG.
    #[arg(long)]
    pub(crate) png: PathBuf,
    /// Iso-lines per direction.
    #[arg(long, default_value_t = 24)]
    pub(crate) lines: usize,
    /// Longer image side in pixels.
    #[arg(long, default_value_t = 900)]
    pub(crate) size: usize,
    #[command(flatten)]
    pub(crate) backend: BackendArgs,
    /// Do not draw the matched pairs of the reparameterization stored in the report.
    #[arg(long)]
    pub(crate) no_matches: bool,
}
