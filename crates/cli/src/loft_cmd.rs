//! `winslow loft SLICES... --z z0,z1,... -o volume.json`: volumes from planar slices
//! (paper §11.1, Fig. 23; [`winslow::solve::loft`]), certified by the trivariate
//! certificate, with slices inserted where it fails; and the volume side of `check` and
//! `convert` (JSON, G+Smo XML `TensorBSpline3`, VTK).

use super::*;
use crate::files;
use winslow::solve::loft::{loft, LoftOptions, SliceBoundary};
use winslow::spline::loft::Interpolation;
use winslow::spline::volume::Volume;
use winslow::verify::certificate::volume::{certify_volume, VolumeCertificate, VolumeFinding};

#[derive(Args, Debug)]
pub(super) struct LoftArgs {
    /// Planar maps (JSON map documents or G+Smo XML), in the order of their heights.
    #[arg(required = true, num_args = 2..)]
    slices: Vec<PathBuf>,
    /// Heights z0,z1,... of the slices, strictly increasing, one per slice.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, conflicts_with = "dz")]
    z: Vec<f64>,
    /// Uniform spacing instead of --z: slice k at z0 + k dz.
    #[arg(long)]
    dz: Option<f64>,
    /// First height with --dz.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    z0: f64,
    /// Interpolation in z. Linear is the default: each piece mixes only two neighbouring
    /// slices (the paper's choice), so an inserted slice changes nothing beyond its two
    /// intervals; cubic is smooth (C2) but couples all slices.
    #[arg(long, value_enum, default_value = "linear")]
    interpolation: Interpolation,
    /// Most slices inserted where the volume is not certified.
    #[arg(long, default_value_t = LoftOptions::default().max_inserted)]
    max_inserted: usize,
    /// Operator of inserted slices' EGG solves (as in `solve`).
    #[arg(long, value_enum, default_value = "scaled")]
    operator: Operator,
    /// Most bisections per element in the certificates.
    #[arg(long, default_value_t = CertifyOptions::default().max_depth)]
    max_depth: usize,
    /// Most Bernstein boxes examined per element.
    #[arg(long, default_value_t = CertifyOptions::default().max_boxes)]
    max_boxes: usize,
    /// Output: .json (volume document with report and certificate), .xml (G+Smo
    /// TensorBSpline3), .vtu (Bézier hexahedra with det J), .vtk (sampled grid).
    #[arg(short, long)]
    output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

fn exit_code(v: &VolumeFinding) -> i32 {
    output::exit_code(Verdict::of_finding(v))
}

fn certify_options(max_depth: usize, max_boxes: usize) -> CertifyOptions {
    CertifyOptions { max_depth: max_depth.clamp(1, 40), max_boxes: max_boxes.clamp(1, 1 << 24), excuse_corners: true }
}

pub(super) fn run(a: LoftArgs) -> Result<i32> {
    let t0 = Instant::now();
    output::reset_peak_memory();
    let z = match a.dz {
        Some(dz) if dz.is_finite() && dz > 0.0 => (0..a.slices.len()).map(|k| a.z0 + k as f64 * dz).collect(),
        Some(dz) => bail!("--dz must be a positive number, got {dz}"),
        None if a.z.is_empty() => bail!("give the heights with --z z0,z1,... or --dz"),
        None => a.z.clone(),
    };
    a.slices
        .iter()
        .fold(files::OutputPlan::new(), |p, s| p.input(s))
        .file("-o", &a.output, "volume", files::ext::VOLUME)
        .check()?;
    let mut slices = Vec::with_capacity(a.slices.len());
    let mut name = String::new();
    for (i, p) in a.slices.iter().enumerate() {
        let doc = files::read(p).with_context(|| format!("slice {i}"))?;
        let (n, map) = files::map_of(doc, p, &format!("slice {i} must be a map (solve it first)"))?;
        if i == 0 {
            name = format!("{n}-loft");
        }
        slices.push(map);
    }
    let (interpolation, operator) = (a.interpolation, a.operator);
    let opts = LoftOptions {
        interpolation,
        max_inserted: a.max_inserted,
        certify: certify_options(a.max_depth, a.max_boxes),
        operator,
        ..Default::default()
    };
    // only maps are given: inserted slices take the interpolated boundary
    let out = loft(&slices, &z, &opts, SliceBoundary::Interpolated).context("lofting the slices")?;
    let cert = &out.certificate;
    let label = format!("volume certificate: {}", cert.message());
    let extra = Some(serde_json::json!({ "report": &out.report, "certificate": cert }));
    files::write(&a.output, &Output::Volume { name: &name, volume: &out.volume, label: &label, extra })?;
    let inserted = out.report.slices.iter().filter(|s| s.given.is_none()).count();
    if a.json {
        let v = serde_json::json!({ "report": &out.report, "certificate": cert, "seconds": t0.elapsed().as_secs_f64(),
            "peak_memory_mib": output::peak_memory_mib() });
        files::print_json(v)?;
    } else {
        say!(
            "{name}: {} slices ({} given, {inserted} inserted, boundary of inserted slices interpolated), {} interpolation, \
             {}, {} elements",
            out.slices.len(),
            slices.len(),
            interpolation.name(),
            crate::volume_cmd::degrees_and_shape(out.volume.degrees(), out.volume.shape()),
            cert.elements
        );
        say!("{}", cert.message());
        say!(
            "{} round(s); volume certificate {:.3} s; total {:.3} s; peak memory {:.1} MiB",
            out.report.rounds.len(),
            cert.seconds,
            t0.elapsed().as_secs_f64(),
            output::peak_memory_mib(),
        );
    }
    Ok(exit_code(&cert.verdict))
}

/// The JSON report of `check` on a volume.
#[derive(serde::Serialize)]
struct VolumeCheck<'a> {
    name: &'a str,
    kind: &'static str,
    degrees: [usize; 3],
    shape: [usize; 3],
    volume: f64,
    certificate: &'a VolumeCertificate,
}

/// `winslow check` on a volume document (JSON or G+Smo XML): the trivariate certificate.
pub(super) fn check_volume(name: &str, vol: &Volume, max_depth: usize, max_boxes: usize, json: bool) -> Result<i32> {
    let cert = certify_volume(vol, &certify_options(max_depth, max_boxes)).context("certifying the volume")?;
    let report = VolumeCheck {
        name,
        kind: "volume",
        degrees: vol.degrees(),
        shape: vol.shape(),
        // mean det J times the parameter volume (knot domains are [0, 1]): exact from the
        // Bernstein coefficients for polynomial maps, Gauss quadrature for rational ones
        volume: cert.mean_det_j * vol.knots.iter().map(|k| k.domain().1 - k.domain().0).product::<f64>(),
        certificate: &cert,
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        let (d, s) = (report.degrees, report.shape);
        say!(
            "{}: volume of degrees ({}, {}, {}), {} x {} x {} control points, {} elements, det J of degree ({}, {}, {})",
            name, d[0], d[1], d[2], s[0], s[1], s[2], cert.elements, cert.det_degree[0], cert.det_degree[1], cert.det_degree[2]
        );
        say!("{}", cert.message());
        say!("volume (integral of det J) {:.6e}; certificate {:.3} s", report.volume, cert.seconds);
    }
    Ok(exit_code(&cert.verdict))
}

/// `winslow convert` of a volume: certified again, written by the output's extension.
pub(super) fn convert_volume(name: &str, volume: &Volume, output: &Path) -> Result<i32> {
    let cert = certify_volume(volume, &CertifyOptions::default()).context("certifying the volume")?;
    let label = format!("volume certificate: {}", cert.message());
    let extra = Some(serde_json::json!({ "certificate": &cert }));
    files::write(output, &Output::Volume { name, volume, label: &label, extra })?;
    say!("{label}");
    Ok(exit_code(&cert.verdict))
}
