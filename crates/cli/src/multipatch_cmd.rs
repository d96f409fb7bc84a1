//! Multipatch layouts (paper §11.2) from the command line: `winslow solve` on a G+Smo
//! `<MultiPatch>` file or a JSON multipatch document (`--interfaces fixed|free`), and
//! the `split` and `join` commands.

use super::*;
use winslow::io::multipatch::write_patch_maps;
use winslow::io::Patches;
use winslow::multipatch::split::SplitPath;

use crate::files;
use winslow::multipatch::{interfaces_of, Functional, Interfaces, Layout, MultipatchSolution};

/// The options of `winslow solve` that only a multipatch layout reads.
#[derive(Args, Debug, Clone)]
pub(super) struct MultipatchArgs {
    /// Multipatch input: keep the interfaces where they are (each patch solved with its
    /// four sides as Dirichlet data, conforming bases), or, after that, free the interior
    /// control points of the interfaces and solve one problem over all patches.
    #[arg(long, value_enum, default_value = "fixed")]
    interfaces: Interfaces,
    /// The problem over all patches with `--interfaces free`: the Winslow functional
    /// (eq. 16) or the weak form (eq. 14).
    #[arg(long, value_enum, default_value = "winslow")]
    functional: Functional,
    /// Multipatch input: also write one JSON map document per patch into this directory.
    #[arg(long, value_name = "DIR")]
    pub(super) patch_maps: Option<PathBuf>,
    /// With `--patch-maps`: remove the JSON documents an earlier run left in the folder
    /// first (without it such a folder is refused, so that no stale patch is mixed in).
    #[arg(long)]
    pub(super) overwrite: bool,
    /// Multipatch input: also write a VTK multiblock file (.vtm) with one exact Bézier
    /// .vtu per patch (in a directory named after the file).
    #[arg(long, value_name = "FILE.vtm")]
    pub(super) vtm: Option<PathBuf>,
}

/// The options of a layout solve from the arguments of `winslow solve`: `--interfaces
/// free` is the layout's improvement by `--functional` (or by `--improve`'s method when
/// given), the pipeline's free-interface stage.
pub(super) fn options(a: &SolveArgs) -> Result<SolveOptions> {
    let mut solve = a.solver.options()?;
    if a.multipatch.interfaces == Interfaces::Free && solve.improve.is_none() {
        solve.improve = Some(a.multipatch.functional);
    }
    Ok(solve)
}

/// The first line of a layout solve's progress.
pub(super) fn announce(layout: &Layout, opts: &SolveOptions) {
    note!(
        "{}: multipatch layout, {} patches, {} interfaces; interfaces {}",
        layout.name,
        layout.patches.len(),
        layout.interfaces.len(),
        interfaces_of(opts).name()
    );
}

/// `winslow solve LAYOUT` after the pipeline: write, summarize; the exit code of the
/// worst verdict. `made` is the report of the automatic layout when the layout was made
/// from a general domain (`winslow solve DOMAIN`): it goes into the top-level report as
/// `auto_layout`.
pub(super) fn finish(sol: MultipatchSolution, a: &SolveArgs, made: Option<serde_json::Value>) -> Result<i32> {
    let mut report = serde_json::to_value(&sol.report)?;
    if let Some(m) = made {
        report["auto_layout"] = m;
    }
    write(&sol, report.clone(), a)?;
    if let Some(out) = &a.mesh {
        // one conforming mesh of the solved patches (a folded patch gives inverted
        // cells, which the writers refuse)
        let mut layout = sol.layout.clone();
        for (patch, map) in layout.patches.iter_mut().zip(sol.maps()) {
            patch.map = Some(map);
        }
        super::mesh::make_and_write_multipatch(&layout, &a.mesh_spec, out, a.json || output::quiet())?;
    }
    if a.json {
        files::print_json(report)?;
    } else {
        say_raw!("{}", summary(&sol));
    }
    Ok(output::exit_code(sol.report.verdict))
}

/// Write the solution where `a` asks: `-o` by its extension (.json, .xml for G+Smo,
/// .vtm), `--gismo`, `--png` (the whole layout), `--vtm`, `--patch-maps`.
fn write(sol: &MultipatchSolution, report: serde_json::Value, a: &SolveArgs) -> Result<()> {
    let mut patches = Patches::of_solution(sol)?;
    patches.report = report;
    let patches = Output::Multipatch(patches);
    files::write(&a.output, &patches)?;
    if let Some(p) = &a.gismo {
        files::write_as(p, "xml", &patches)?;
    }
    if let Some(p) = &a.png {
        files::write(p, &Output::Picture(&render_layout(&sol.maps(), &PictureOptions::default())))?;
    }
    if let Some(p) = &a.multipatch.vtm {
        files::write_as(p, "vtm", &patches)?;
    }
    if let Some(d) = &a.multipatch.patch_maps {
        for p in write_patch_maps(sol, d)? {
            files::record(&p);
        }
    }
    for (flag, given) in [("--iges", a.iges.is_some()), ("--vtu", a.vtu.is_some()), ("--vtk", a.vtk.is_some())] {
        if given {
            note!("note: {flag} writes one map; for a multipatch layout use --vtm, --patch-maps, --gismo or --mesh");
        }
    }
    Ok(())
}

/// The text summary of a layout solve.
pub(super) fn summary(sol: &MultipatchSolution) -> String {
    let r = &sol.report;
    let mut s = format!("{}: {}\n  {}\n", r.name, output::verdict_word(r.verdict), r.message);
    for (p, v) in sol.patches.iter().zip(&r.verdicts) {
        let [nx, ny] = p.map.shape();
        let last = p.solve.solve.levels.last();
        s.push_str(&format!(
            "  patch {:<10} {:>3}x{:<3} functions, {} Newton iterations: {} ({})\n",
            p.name,
            nx,
            ny,
            last.map_or(0, |l| l.newton_iterations),
            v.name(),
            p.certificate.message()
        ));
    }
    for c in &r.classes {
        s.push_str(&format!("  knot class p={} {} elements: {}\n", c.degree, c.elements, c.members.join(" ")));
    }
    let w = r.winslow.map_or("undefined".into(), |w| format!("{w:.6}"));
    s.push_str(&format!("  total Winslow value {w}; {:.3} s (fixed interfaces {:.3} s)\n", r.seconds, r.fixed_seconds));
    s
}

/// `winslow split`: cut a certified map's domain in two (paper §11.2, Fig. 25).
#[derive(Args, Debug)]
pub(super) struct SplitArgs {
    /// The map (JSON map document or G+Smo XML patch); it must be certified bijective.
    map: PathBuf,
    /// First end of the splitting curve: `SIDE:T` (south, east, north or west, and the
    /// parameter along it in (0, 1)) or a point `X,Y` (the nearest boundary point).
    #[arg(long, allow_hyphen_values = true)]
    from: String,
    /// Second end, on the opposite side, in the same form.
    #[arg(long, allow_hyphen_values = true)]
    to: String,
    /// The curve in the parameter square: the straight segment, or the shortest path in
    /// the metric of the map (through narrow gaps).
    #[arg(long, value_enum, default_value = "straight")]
    path: SplitPath,
    /// Spline degree of the splitting curve.
    #[arg(long, default_value_t = 3)]
    degree: usize,
    /// Fit tolerance of the splitting curve, relative to the diameter (as `--fit-tol` of
    /// `solve` for the sides).
    #[arg(long, default_value_t = 1e-5)]
    fit_tol: f64,
    /// Output: the multipatch document of the two parts (`winslow solve` takes it); the
    /// two boundary documents go next to it as STEM-a.json and STEM-b.json.
    #[arg(short, long)]
    output: PathBuf,
    /// Also draw the map with the splitting curve.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// `winslow join`: two maps sharing a whole side as one map (paper §11.2, Fig. 27-28).
#[derive(Args, Debug)]
pub(super) struct JoinArgs {
    /// The first map.
    a: PathBuf,
    /// The second map.
    b: PathBuf,
    /// Smoothing of the joined map from its bijective start: the weak form (eq. 14, as in
    /// the paper) or the Winslow functional (eq. 16).
    #[arg(long, value_enum, default_value = "weak")]
    functional: Functional,
    /// Output map (.json with a report, or .xml, .igs, .vtu, .vtk by extension).
    #[arg(short, long)]
    output: PathBuf,
    /// Also draw the joined map.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// A four-sided map (a ring map has no four sides to split or join along).
fn read_map(path: &Path, command: &str) -> Result<(String, Surface)> {
    let doc = files::read(path)?;
    if doc.is_ring_map() {
        return Err(files::wrong_kind(&doc, path, &format!("{command} needs a four-sided map")));
    }
    files::map_of(doc, path, files::SOLVE_FIRST)
}

/// `SIDE:T` or `X,Y` as a side point of `map`.
fn side_point(map: &Surface, s: &str) -> Result<winslow::multipatch::split::SidePoint> {
    use winslow::multipatch::split::{nearest_boundary_point, SidePoint};
    if let Some((side, t)) = s.split_once(':') {
        let side = Side::ALL
            .into_iter()
            .find(|x| x.name() == side.trim())
            .with_context(|| format!("{side:?} is not south, east, north or west"))?;
        let t: f64 = t.trim().parse().with_context(|| format!("{t:?} is not a number"))?;
        return Ok(SidePoint { side, t });
    }
    let xy: Vec<f64> = s
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .with_context(|| format!("{s:?} is neither SIDE:T nor X,Y"))?;
    let [x, y] = xy[..] else { bail!("{s:?} is neither SIDE:T nor X,Y") };
    let (p, d) = nearest_boundary_point(map, [x, y]);
    note!("({x}, {y}) -> {} side at t = {:.6} ({d:.3e} away)", p.side, p.t);
    Ok(p)
}

pub(super) fn split(a: SplitArgs) -> Result<i32> {
    use winslow::multipatch::split::{split_map, SplitOptions};
    let (name, map) = read_map(&a.map, "split")?;
    let stem = a.output.file_stem().map(|x| x.to_string_lossy().into_owned()).unwrap_or_else(|| "split".into());
    let parts = ["a", "b"].map(|k| a.output.with_file_name(format!("{stem}-{k}.json")));
    files::OutputPlan::new()
        .input(&a.map)
        .file("-o", &a.output, "multipatch layout", files::ext::JSON)
        .file("-o (part a)", &parts[0], "boundary", files::ext::JSON)
        .file("-o (part b)", &parts[1], "boundary", files::ext::JSON)
        .maybe("--png", a.png.as_deref(), "picture", files::ext::PNG)
        .check()?;
    let cert = certify(&map, &CertifyOptions::default()).context("certifying the map")?;
    let (from, to) = (side_point(&map, &a.from)?, side_point(&map, &a.to)?);
    let path = a.path;
    let opts = SplitOptions { path, degree: a.degree, tol: a.fit_tol, ..Default::default() };
    let s = split_map(&name, &map, &cert, from, to, &opts).context("splitting the map")?;
    files::write(&a.output, &Output::Layout(&s.layout))?;
    for (p, path) in s.layout.patches.iter().zip(&parts) {
        let b = Boundary { name: p.name.clone(), sides: p.sides.clone().map(winslow::SideCurve::Spline) };
        files::write(path, &Output::Boundary(&b))?;
    }
    if let Some(p) = &a.png {
        let pts = s.curve.sample(256);
        let segments = pts.windows(2).map(|w| (w[0], w[1])).collect();
        let image = render(&map, &PictureOptions { segments, ..Default::default() });
        files::write(p, &Output::Picture(&image))?;
    }
    if a.json {
        files::print_json(serde_json::to_value(&s.report)?)?;
    } else {
        let r = &s.report;
        say!(
            "{name}: split from the {} side at {:.6} to the {} side at {:.6} ({:?} parameter path)",
            r.from.side,
            r.from.t,
            r.to.side,
            r.to.t,
            r.path
        );
        say!(
            "  splitting curve: p={}, {} elements, length {:.6}, fit error {:.3e}; areas {:.6} and {:.6}",
            s.curve.degree(),
            r.elements,
            r.length,
            r.fit_error,
            r.areas[0],
            r.areas[1]
        );
    }
    Ok(0)
}

pub(super) fn join(a: JoinArgs) -> Result<i32> {
    use winslow::multipatch::join::join_and_smooth;
    let (na, ma) = read_map(&a.a, "join")?;
    let (nb, mb) = read_map(&a.b, "join")?;
    files::OutputPlan::new()
        .input(&a.a)
        .input(&a.b)
        .file("-o", &a.output, "map", files::ext::MAP)
        .maybe("--png", a.png.as_deref(), "picture", files::ext::PNG)
        .check()?;
    let functional = a.functional;
    let opts = CertifyOptions::default();
    let j = join_and_smooth(&ma, &mb, functional, Default::default(), &opts).context("joining the maps")?;
    let name = format!("{na}+{nb}");
    let verdict = Verdict::of_certificate(&j.certificate);
    let report = serde_json::json!({
        "version": env!("CARGO_PKG_VERSION"),
        "verdict": verdict,
        "message": j.certificate.message(),
        "certificate": j.certificate,
        "join": j.join,
        "smoothing": j.smoothing,
    });
    let label = format!("verdict {verdict:?}: {}", j.certificate.message());
    let extra = Some(serde_json::json!({ "report": report }));
    files::write(&a.output, &Output::Map { name: &name, map: &j.map, label: &label, extra })?;
    if let Some(p) = &a.png {
        files::write(p, &Output::Picture(&render(&j.map, &PictureOptions::default())))?;
    }
    if a.json {
        files::print_json(report)?;
    } else {
        say!("{name}: {}", output::verdict_word(verdict));
        say!(
            "  joined along the {} side of {} and the {} side of {}: {}x{} functions, C0 knot at {:.4}, boundary turns by {:.1} and {:.1} degrees where they meet",
            j.join.sides[0], a.a.display(), j.join.sides[1], a.b.display(), j.join.shape[0], j.join.shape[1], j.join.c0_knot,
            j.join.turn_degrees[0], j.join.turn_degrees[1]
        );
        say!("  {}", j.smoothing.message);
    }
    Ok(output::exit_code(verdict))
}

/// `winslow check LAYOUT`: certify every patch map of a multipatch file (a G+Smo
/// `<MultiPatch>` or a solved JSON layout) and measure how far the two sides of every
/// interface are apart; the exit code of the worst patch.
pub(super) fn check(layout: Layout, opts: &CertifyOptions, json: bool) -> Result<i32> {
    use winslow::multipatch::solve::interface_mismatch;
    let mut maps = Vec::with_capacity(layout.patches.len());
    for p in &layout.patches {
        let Some(m) = &p.map else {
            bail!(
                "patch {} of {} is a boundary, not a map: there is nothing to certify (solve the layout first)",
                p.name,
                layout.name
            )
        };
        maps.push(m.clone());
    }
    let validation = winslow::multipatch::validate_layout(&layout);
    let mut rows = Vec::with_capacity(maps.len());
    let mut worst = Verdict::Certified;
    for (p, m) in layout.patches.iter().zip(&maps) {
        let c = certify(m, opts).with_context(|| format!("certifying patch {}", p.name))?;
        let v = Verdict::of_certificate(&c);
        if output::exit_code(v) > output::exit_code(worst) {
            worst = v;
        }
        let w = quality(m).functionals.winslow;
        rows.push(serde_json::json!({
            "name": p.name, "verdict": v, "message": c.message(), "certificate": c,
            "winslow": w.is_finite().then_some(w), "shape": m.shape(),
        }));
    }
    let mismatch = interface_mismatch(&layout, &maps);
    let report = serde_json::json!({
        "name": layout.name,
        "verdict": worst,
        "patches": rows,
        "interfaces": layout.interfaces.len(),
        "interface_mismatch": mismatch,
        "layout": match &validation { Ok(r) => serde_json::to_value(r)?, Err(e) => serde_json::json!({ "error": e.to_string() }) },
    });
    if json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        say!(
            "{}: {} ({} patches, {} interfaces)",
            layout.name,
            output::verdict_word(worst),
            maps.len(),
            layout.interfaces.len()
        );
        for r in &rows {
            say!("  patch {:<10} {}", r["name"].as_str().unwrap_or(""), r["message"].as_str().unwrap_or(""));
        }
        say!("  interface control points differ by up to {mismatch:.3e}");
        if let Err(e) = &validation {
            say!("  layout: {e}");
        }
    }
    Ok(output::exit_code(worst))
}
