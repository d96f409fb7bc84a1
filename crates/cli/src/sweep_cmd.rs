//! `winslow sweep RING (--rotate-inner DEG --steps N [--center X,Y] | --inner-frames
//! PATH...) -o DIR`: the sliding O-grid of paper §11.1 ([`winslow::pipeline::sweep`]): one
//! map per frame (JSON with the frame's row, and VTK Bézier cells), a ParaView `.pvd`
//! series, the per-frame table (`sweep.csv`, `sweep.json`, and on stdout), and with
//! `--apng` an animated PNG of the frames.

use super::*;
use winslow::boundary::ring::{ClosedContour, Ring};
use winslow::boundary::ring_fit::EtaRefinement;
use winslow::io::picture::Image;
use winslow::pipeline::sweep::{frame0_options, Frame, FrameReport, Seam, Sweep, SweepOptions};

#[derive(Args, Debug)]
pub(super) struct SweepArgs {
    /// Ring document (two closed contours, see formats.md) or a ring map (its two
    /// contours): frame 0.
    ring: PathBuf,
    /// Rotation of the inner contour per step, degrees (counter-clockwise).
    #[arg(long, allow_negative_numbers = true, required_unless_present = "inner_frames")]
    rotate_inner: Option<f64>,
    /// Number of steps after frame 0 (a turning contour; with --inner-frames, at most
    /// this many of the files).
    #[arg(long)]
    steps: Option<usize>,
    /// Centre of rotation `x,y` (default: the inner contour's centroid).
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    center: Option<[f64; 2]>,
    /// Non-rigid motion: the inner contours of frames 1, 2, ..., as ring documents
    /// (their outer contour must be frame 0's) or directories of them (their *.json files
    /// in name order).
    #[arg(long, num_args = 1.., conflicts_with_all = ["rotate_inner", "center"])]
    inner_frames: Vec<PathBuf>,
    /// Times of the --inner-frames, increasing and positive (frame 0 is at time 0;
    /// default 1, 2, 3, ...). Uneven steps are fine: the extrapolation uses the times.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, requires = "inner_frames")]
    times: Vec<f64>,
    /// Where eta = 0 sits on the turning inner contour: `slide` (the grid slides along
    /// the contour at the mean angular rate), `ray` (on the ray from the inner centroid
    /// through the frame-0 seam, the paper's choice) or `material` (turns with the
    /// contour: the grid twists).
    #[arg(long, value_enum, default_value_t = Seam::Slide)]
    seam: Seam,
    /// Highest order of the predictor: the time extrapolation of the control points (0 to
    /// 5). (`--order` elsewhere is a mesh's element order.)
    #[arg(long, default_value_t = 5)]
    predictor_order: usize,
    /// Output directory: frame_NNNN.json, frame_NNNN.vtu, sweep.pvd, sweep.csv, sweep.json.
    #[arg(short, long)]
    output: PathBuf,
    /// Write the maps (and the .pvd and --apng frames) of every N-th frame only; the
    /// table has every frame.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    every: u64,
    /// Remove the files of an earlier sweep (frame_NNNN.json/.vtu, sweep.pvd/.csv/.json)
    /// from the output directory first; without it, such files are an error (frames of
    /// two sweeps never mix).
    #[arg(long)]
    overwrite: bool,
    /// Also write an animated PNG (APNG) of the written frames: det J heat map and grid.
    #[arg(long)]
    apng: Option<PathBuf>,
    /// Longer side of the --apng frames in pixels.
    #[arg(long, default_value_t = 480)]
    apng_size: usize,
    /// Frames per second of the --apng.
    #[arg(long, default_value_t = 25)]
    apng_fps: u16,
    /// Every N-th frame of a turning contour, also solve that frame cold (the ring with
    /// the input inner contour turned, fitted and solved from scratch) and record its time
    /// (`cold_checks` in sweep.json): the per-frame cost against a cold solve of the same
    /// frame.
    #[arg(long, default_value_t = 0)]
    cold_every: usize,
    #[command(flatten)]
    solver: SolverArgs,
}

fn parse_point(s: &str) -> std::result::Result<[f64; 2], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().map_err(|e| format!("{t:?}: {e}")))
        .collect::<std::result::Result<_, _>>()?;
    match v[..] {
        [x, y] if x.is_finite() && y.is_finite() => Ok([x, y]),
        _ => Err(format!("expected two finite numbers x,y, got {s:?}")),
    }
}

/// Whether a file name is one a sweep writes: `frame_NNNN.json`, `frame_NNNN.vtu`,
/// `sweep.pvd`, `sweep.csv`, `sweep.json`.
fn of_a_sweep(name: &str) -> bool {
    let frame = name
        .strip_prefix("frame_")
        .and_then(|r| r.strip_suffix(".json").or_else(|| r.strip_suffix(".vtu")))
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
    frame || matches!(name, "sweep.pvd" | "sweep.csv" | "sweep.json")
}

const HEADER: &str = "frame,time,angle_deg,predictor,newton,linear_solves,residual_before,residual_after,converged,inner_fit_error,inner_shift,seam_offset_deg,seconds,verdict,det_j_lower_bound";

fn row(r: &FrameReport) -> String {
    format!(
        "{},{:.9},{},{},{},{},{:.3e},{:.3e},{},{:.3e},{:.6e},{:.4},{:.4},{},{}",
        r.frame,
        r.time,
        r.angle_degrees.map_or(String::new(), |a| format!("{a:.6}")),
        r.predictor_order.map_or("cold".into(), |o| o.to_string()),
        r.newton_iterations,
        r.linear_solves,
        r.residual_before,
        r.residual_after,
        r.converged,
        r.inner_fit_error,
        r.inner_shift,
        r.seam_offset_degrees,
        r.seconds,
        r.verdict,
        r.det_j_lower_bound.map_or(String::new(), |b| format!("{b:.6e}"))
    )
}

/// The ring documents of `paths` (directories give their `*.json` files in name order)
/// with their inner contours; each outer contour must be `base`'s.
fn inner_frames(paths: &[PathBuf], base: &Ring) -> Result<Vec<(PathBuf, ClosedContour)>> {
    let mut files = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut v: Vec<PathBuf> = std::fs::read_dir(p)
                .with_context(|| format!("reading directory {}", p.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.extension().is_some_and(|x| x.eq_ignore_ascii_case("json")))
                .collect();
            v.sort();
            if v.is_empty() {
                bail!("--inner-frames: {} holds no .json files", p.display());
            }
            files.extend(v);
        } else {
            files.push(p.clone());
        }
    }
    files
        .into_iter()
        .map(|f| {
            let ring = ring_in(&f, "--inner-frames takes ring documents")?;
            let dev = ring.outer.deviation_from(&base.outer);
            if dev.is_none_or(|d| d > 1e-9) {
                bail!(
                    "{}: its outer contour is not frame 0's ({}); a sweep moves the inner contour only",
                    f.display(),
                    dev.map_or("sampled differently".into(), |d| format!("{d:.3e} apart"))
                );
            }
            Ok((f, ring.inner))
        })
        .collect()
}

/// The ring of a ring document or a ring map (e.g. a frame of another sweep); any other
/// kind is the error naming it.
fn ring_in(path: &Path, needed: &str) -> Result<Ring> {
    match crate::files::read(path)? {
        Document::Ring(ring) => Ok(ring),
        doc if doc.is_ring_map() => crate::files::ring_of(doc, path),
        doc => Err(crate::files::wrong_kind(&doc, path, needed)),
    }
}

/// An animated PNG encoded frame by frame in memory (written at the end through the
/// atomic writer); every frame is cropped or padded (white) to the first frame's size.
struct Apng {
    writer: png::Writer<Bytes>,
    bytes: Bytes,
    size: (usize, usize),
}

/// The encoded bytes, shared between the encoder and [`Apng`].
#[derive(Clone, Default)]
struct Bytes(std::rc::Rc<std::cell::RefCell<Vec<u8>>>);

impl std::io::Write for Bytes {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Apng {
    fn create(first: &Image, frames: u32, fps: u16) -> Result<Self> {
        let bytes = Bytes::default();
        let mut enc = png::Encoder::new(bytes.clone(), first.width as u32, first.height as u32);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_animated(frames, 0)?;
        enc.set_frame_delay(1, fps.max(1))?;
        Ok(Self { writer: enc.write_header()?, bytes, size: (first.width, first.height) })
    }

    fn push(&mut self, img: &Image) -> Result<()> {
        let (w, h) = self.size;
        let mut rgba = vec![255u8; 4 * w * h];
        for y in 0..h.min(img.height) {
            let n = 4 * w.min(img.width);
            rgba[4 * y * w..4 * y * w + n].copy_from_slice(&img.rgba[4 * y * img.width..4 * y * img.width + n]);
        }
        self.writer.write_image_data(&rgba)?;
        Ok(())
    }
}

pub(super) fn run(a: SweepArgs) -> Result<i32> {
    if a.predictor_order > 5 {
        bail!("--predictor-order must be between 0 and 5, got {}", a.predictor_order);
    }
    let step = match a.rotate_inner {
        Some(d) if !d.is_finite() => bail!("--rotate-inner must be a finite number of degrees, got {d}"),
        Some(d) => d.to_radians(),
        None => 0.0,
    };
    let opts = a.solver.options()?;
    let ring =
        ring_in(&a.ring, "sweep needs a ring document (a \"ring\" with inner and outer contours) or a ring map")?;
    let mut contours = inner_frames(&a.inner_frames, &ring)?;
    if let Some(n) = a.steps.filter(|_| !contours.is_empty()) {
        contours.truncate(n);
    }
    let steps = match (a.rotate_inner, a.steps) {
        (Some(_), Some(n)) => n,
        (Some(_), None) => bail!("--rotate-inner needs --steps"),
        (None, _) => contours.len(),
    };
    let times: Vec<f64> = if a.times.is_empty() { (1..=steps).map(|k| k as f64).collect() } else { a.times.clone() };
    if !contours.is_empty() && times.len() != contours.len() {
        bail!("--times gives {} times for {} inner frames", times.len(), contours.len());
    }
    let plan = std::iter::once(&a.ring).chain(&a.inner_frames).fold(crate::files::OutputPlan::new(), |p, i| p.input(i));
    plan.folder("-o", &a.output).maybe("--apng", a.apng.as_deref(), "animated PNG", crate::files::ext::APNG).check()?;
    crate::files::claim_folder("-o", &a.output, of_a_sweep, a.overwrite)?;
    std::fs::create_dir_all(&a.output).with_context(|| format!("creating {}", a.output.display()))?;
    let seam = a.seam;
    let so = SweepOptions { step, steps, center: a.center, max_order: a.predictor_order, seam };
    let (mut sweep, sol, f0) = Sweep::new(&ring, &opts, so).context("solving frame 0")?;
    if !output::quiet() {
        let what = match a.rotate_inner {
            Some(d) => format!("{steps} frames at {d} degrees per step"),
            None => format!("{steps} inner contours"),
        };
        note!(
            "{}: frame 0 solved cold ({}x{} basis, {:.3} s, {}, reparameterization {} with {} matched pairs, kept by every frame); {what}",
            ring.name,
            sol.map.shape()[0],
            sol.map.shape()[1],
            f0.report.seconds,
            f0.report.verdict,
            sol.report.fit.reparam.used.name(),
            sol.report.fit.reparam.matches.len(),
        );
        // the sliding seam moves the parameter by |Δθ| / 2π of a period per step; the
        // prediction is good while that is a small part of the smallest element
        let h = sol.map.knots[1].elements().iter().map(|e| e.2 - e.1).fold(f64::INFINITY, f64::min);
        let slide = step.abs() / std::f64::consts::TAU * sol.map.knots[1].length() / h;
        if seam != Seam::Material && a.rotate_inner.is_some() {
            note!("the inner parameter slides by {slide:.3} of the smallest eta element per step");
            if slide > 0.25 {
                note!(
                    "warning: more than a quarter of an element per step; the extrapolated predictions will be poor (a coarser --fit-tol or a smaller step keeps them within one Newton step)"
                );
            }
        }
        note!("{HEADER}");
    }
    let every = a.every as usize;
    let picture = PictureOptions {
        size: a.apng_size.max(16),
        grid_lines: 16,
        resolution: 160,
        segments: Vec::new(),
        kinks: Vec::new(),
    };
    let mut apng: Option<Apng> = None;
    let mut rows = Vec::new();
    let mut pvd =
        String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n");
    let mut failures = 0;
    let mut cold_checks = Vec::new();
    let mut frame: Frame = f0;
    loop {
        let r = &frame.report;
        if r.frame.is_multiple_of(every) {
            let stem = format!("frame_{:04}", r.frame);
            let label = format!("frame {} at time {:.9}: {}", r.frame, r.time, r.verdict);
            let report = serde_json::to_value(r)?;
            let name = format!("{}-{stem}", ring.name);
            let extra = Some(serde_json::json!({ "frame": report }));
            let map = Output::Map { name: &name, map: &frame.map, label: &label, extra };
            crate::files::write(&a.output.join(format!("{stem}.json")), &map)?;
            crate::files::write(&a.output.join(format!("{stem}.vtu")), &map)?;
            pvd.push_str(&format!("    <DataSet timestep=\"{}\" part=\"0\" file=\"{stem}.vtu\"/>\n", r.time));
            if a.apng.is_some() {
                let img = render(&frame.map, &picture);
                let w = match apng.as_mut() {
                    Some(w) => w,
                    None => apng.insert(Apng::create(&img, (steps / every + 1) as u32, a.apng_fps)?),
                };
                w.push(&img)?;
            }
        }
        if r.verdict != "certified" || !r.converged {
            failures += 1;
        }
        if !output::quiet() {
            note!("{}", row(r));
        }
        rows.push(frame.report.clone());
        let k = rows.len();
        if k > steps {
            break;
        }
        if a.cold_every > 0 && contours.is_empty() && k % a.cold_every == 0 {
            let angle = k as f64 * step;
            let centre = a.center.unwrap_or_else(|| ring.inner.centroid());
            let turned = Ring { inner: ring.inner.rotated(centre, angle), ..ring.clone() };
            let refinement = if seam == Seam::Material { EtaRefinement::Adaptive } else { EtaRefinement::Uniform };
            let t0 = std::time::Instant::now();
            let cold = winslow::Pipeline::new(turned, frame0_options(&opts))
                .eta_refinement(refinement)
                .solve()
                .and_then(|s| s.into_map())
                .with_context(|| format!("cold solve of frame {k}"))?;
            let seconds = t0.elapsed().as_secs_f64();
            cold_checks.push(serde_json::json!({
                "frame": k,
                "seconds": seconds,
                "verdict": cold.report.outcome.verdict.name(),
                "shape": cold.map.shape(),
            }));
        }
        frame = match contours.get(k - 1) {
            Some((path, inner)) => sweep
                .next_frame_contour(inner, times[k - 1])
                .with_context(|| format!("solving frame {k} ({})", path.display()))?,
            None => sweep.next_frame().with_context(|| format!("solving frame {k}"))?,
        };
    }
    if let (Some(w), Some(path)) = (apng, &a.apng) {
        w.writer.finish()?;
        crate::files::write_bytes(path, &w.bytes.0.borrow())?;
    }
    pvd.push_str("  </Collection>\n</VTKFile>\n");
    crate::files::write_bytes(&a.output.join("sweep.pvd"), pvd.as_bytes())?;
    let csv: String = std::iter::once(HEADER.to_string()).chain(rows.iter().map(row)).collect::<Vec<_>>().join("\n");
    crate::files::write_bytes(&a.output.join("sweep.csv"), (csv + "\n").as_bytes())?;
    let cold = rows[0].seconds;
    let later: Vec<&FrameReport> = rows.iter().skip(6).collect();
    let max_newton = later.iter().map(|r| r.newton_iterations).max();
    let max_solves = later.iter().map(|r| r.linear_solves).max();
    let mean = (!later.is_empty()).then(|| later.iter().map(|r| r.seconds).sum::<f64>() / later.len() as f64);
    let min_det = rows.iter().filter_map(|r| r.det_j_lower_bound).fold(f64::INFINITY, f64::min);
    let summary = serde_json::json!({
        "name": ring.name,
        "step_degrees": a.rotate_inner,
        "seam": serde_json::to_value(seam)?,
        // frame 0's parameterization, which every frame keeps (arc length unless
        // `--reparam constrained`: see `winslow::pipeline::sweep`)
        "reparam": serde_json::to_value(&sol.report.fit.reparam)?,
        "frames": rows,
        "cold_seconds": cold,
        "failures": failures,
        "cold_checks": cold_checks,
        "from_frame_6": {
            "max_newton": max_newton,
            "max_linear_solves": max_solves,
            "mean_seconds": mean,
        },
    });
    crate::files::write_json(&a.output.join("sweep.json"), &summary)?; // atomic, as every file
    say!(
        "{}: {} frames, {} not certified or not converged; cold solve {:.3} s; from frame 6: at most {} Newton iterations and {} linear solves per frame, mean {:.4} s; smallest certified det J {:.4e}",
        ring.name,
        rows.len(),
        failures,
        cold,
        max_newton.unwrap_or(0),
        max_solves.unwrap_or(0),
        mean.unwrap_or(f64::NAN),
        min_det,
    );
    if !cold_checks.is_empty() {
        let cold: Vec<f64> = cold_checks.iter().filter_map(|c| c["seconds"].as_f64()).collect();
        let mean_cold = cold.iter().sum::<f64>() / cold.len() as f64;
        say!(
            "cold solves of {} frames: mean {mean_cold:.4} s; a predicted frame takes {:.3} of that",
            cold.len(),
            mean.unwrap_or(f64::NAN) / mean_cold
        );
    }
    Ok(if failures == 0 { 0 } else { 3 })
}
