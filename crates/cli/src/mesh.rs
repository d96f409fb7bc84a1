//! `winslow mesh`: classical meshes from a map (paper §11.3), and the mesh step of
//! `winslow solve --mesh`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use winslow::io::Document;
use winslow::multipatch::Layout;
use winslow::spline::hierarchical::map::HierarchicalMap;
use winslow::spline::volume::Volume;
use winslow::Surface;
use winslow_mesh::formats::{write, Format};
use winslow_mesh::high_order::elevate;
use winslow_mesh::quality::quality;
use winslow_mesh::{
    structured, unstructured_with_stats, Distribution, End, Equidistribution, MeshingStats, StructuredOptions,
    UnstructuredOptions,
};

/// What mesh to make (shared by `mesh` and `solve --mesh`).
#[derive(Args, Debug, Clone)]
pub struct MeshSpec {
    /// A structured mesh of NXxNY points (e.g. 401x35), sampled at xi_i x eta_j
    /// (NXxNYxNZ for a volume).
    #[arg(long, value_name = "NXxNY", conflicts_with = "unstructured")]
    pub structured: Option<String>,
    /// Point distribution of a structured mesh, repeatable: DIR:uniform, DIR:arctan:A
    /// (eq. 50, A = 6 in the paper), DIR:tanh:D (two-sided), SIDE:tanh:D (one-sided,
    /// clustered at SIDE), `SIDE:first-height:H[:GROWTH]` (geometric layers whose first
    /// cell is H long in physical units on every grid line, growth ratio limit GROWTH,
    /// default 1.2). DIR is xi or eta; SIDE is south, east, north or west, or on a ring
    /// (a periodic map, or a ring cut into a four-sided map whose opposite sides
    /// coincide) inner or outer, its walls named by the area they enclose; the seam's
    /// two sides are not walls.
    #[arg(long, value_name = "SPEC")]
    pub cluster: Vec<String>,
    /// Equidistribute a structured mesh's points along the boundary, repeatable:
    /// `[DIR:]arclength` (equal arc length of the two sides along DIR) or
    /// `[DIR:]curvature:TOL` (sqrt(curvature) times arc length, with the fewest points, at
    /// least NX or NY, that keep every boundary chord within TOL of its side). DIR is xi
    /// or eta; without it, both directions.
    #[arg(long, value_name = "SPEC")]
    pub equidistribute: Vec<String>,
    /// An unstructured triangulation (spade, refined in physical space).
    #[arg(long, requires = "size")]
    pub unstructured: bool,
    /// Target physical edge length of the unstructured mesh.
    #[arg(long, value_name = "H")]
    pub size: Option<f64>,
    /// Smallest angle of the triangulation in the parameter square, degrees.
    #[arg(long, default_value_t = 28.0)]
    pub min_angle: f64,
    /// Largest distance of a boundary segment's midpoint from the mapped side (physical
    /// units; default size/20).
    #[arg(long)]
    pub chord_tol: Option<f64>,
    /// Split triangles over which det J varies by more than this factor (0: off).
    #[arg(long, default_value_t = 4.0)]
    pub det_j_ratio: f64,
    /// Element order: 1 linear, 2 quadratic, 3 cubic (Gmsh types 10/36 quads, 9/21
    /// triangles; nodes on the map; .msh and .vtu only).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=3))]
    pub order: u8,
}

/// `winslow mesh` arguments.
#[derive(Args, Debug)]
pub struct MeshArgs {
    /// Map file (JSON map document or G+Smo XML), or a multipatch result (JSON with
    /// "patches", or a G+Smo multipatch whose patches are maps): one conforming mesh,
    /// structured or triangulated, a cell group per face (or patch); or a trivariate map (`winslow loft`):
    /// hexahedra, --structured NXxNYxNZ, .vtu or .msh.
    pub map: PathBuf,
    /// Output: .msh (Gmsh 4.1), .su2, .xyz (PLOT3D), .vtu, or a directory (OpenFOAM
    /// case; polyMesh goes to DIR/constant/polyMesh).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub spec: MeshSpec,
}

fn parse_num(s: &str, what: &str, spec: &str) -> Result<f64> {
    s.parse::<f64>().with_context(|| format!("--cluster {spec}: {what} '{s}' is not a number"))
}

/// The distributions of `xi` and `eta` from the `--cluster` and `--equidistribute` specs.
pub fn distributions(specs: &[String], equi: &[String]) -> Result<[Distribution; 2]> {
    let mut out = [Distribution::Uniform, Distribution::Uniform];
    let mut set = [false, false];
    for spec in specs {
        let parts: Vec<&str> = spec.split(':').collect();
        let (dir, end) = match parts[0] {
            "xi" => (0, None),
            "eta" => (1, None),
            "west" | "inner" => (0, Some(End::Start)),
            "east" | "outer" => (0, Some(End::End)),
            "south" => (1, Some(End::Start)),
            "north" => (1, Some(End::End)),
            o => bail!("--cluster {spec}: '{o}' is not xi, eta, south, east, north, west, inner or outer"),
        };
        let arg = |k: usize, what: &str| -> Result<f64> {
            let s = parts.get(k).with_context(|| format!("--cluster {spec}: missing {what}"))?;
            parse_num(s, what, spec)
        };
        let d = match (parts.get(1).copied(), end) {
            (Some("uniform"), None) => Distribution::Uniform,
            (Some("arctan"), None) => Distribution::Arctan { strength: arg(2, "strength")? },
            (Some("tanh"), None) => Distribution::TanhTwoSided { strength: arg(2, "strength")? },
            (Some("tanh"), Some(at)) => Distribution::TanhOneSided { strength: arg(2, "strength")?, at },
            (Some("first-height"), Some(at)) => {
                let h = arg(2, "height")?;
                let g = if parts.len() > 3 { arg(3, "growth")? } else { 1.2 };
                // a layer at the other end of the same direction joins this one
                let (mut start, mut end) = (None, None);
                if let (true, Distribution::Layers { start: s0, end: e0, growth }) = (set[dir], &out[dir]) {
                    if *growth != g {
                        bail!("--cluster {spec}: growth {g} differs from {growth} given for the other end");
                    }
                    (start, end) = (*s0, *e0);
                } else if set[dir] {
                    bail!("--cluster {spec}: the {} direction already has a distribution", ["xi", "eta"][dir]);
                }
                match at {
                    End::Start => start = Some(h),
                    End::End => end = Some(h),
                }
                out[dir] = Distribution::Layers { start, end, growth: g };
                set[dir] = true;
                continue;
            }
            _ => bail!(
                "--cluster {spec}: expected DIR:uniform, DIR:arctan:A, DIR:tanh:D, SIDE:tanh:D or SIDE:first-height:H[:GROWTH]"
            ),
        };
        if set[dir] {
            bail!("--cluster {spec}: the {} direction already has a distribution", ["xi", "eta"][dir]);
        }
        d.validate(["xi", "eta"][dir])?;
        out[dir] = d;
        set[dir] = true;
    }
    for spec in equi {
        let (dirs, rest) = match spec.split_once(':') {
            Some(("xi", r)) => (vec![0], r),
            Some(("eta", r)) => (vec![1], r),
            _ => (vec![0, 1], spec.as_str()),
        };
        let e = match rest.split_once(':') {
            None if rest == "arclength" => Equidistribution::ArcLength,
            Some(("curvature", tol)) => Equidistribution::Curvature {
                tol: tol
                    .parse()
                    .with_context(|| format!("--equidistribute {spec}: tolerance '{tol}' is not a number"))?,
            },
            _ => bail!("--equidistribute {spec}: expected [xi:|eta:]arclength or [xi:|eta:]curvature:TOL"),
        };
        for dir in dirs {
            if set[dir] {
                bail!("--equidistribute {spec}: the {} direction already has a distribution", ["xi", "eta"][dir]);
            }
            let d = Distribution::Equidistributed(e);
            d.validate(["xi", "eta"][dir])?;
            out[dir] = d;
            set[dir] = true;
        }
    }
    Ok(out)
}

/// The `--cluster` specs with a ring's `inner` and `outer` replaced by the sides they
/// are (the walls at the ends of the direction across the seam `seam_dir`, named by the
/// area they enclose); refused on a map without a seam.
fn wall_sides(specs: &[String], map: &Surface, seam_dir: Option<usize>) -> Result<Vec<String>> {
    specs
        .iter()
        .map(|c| {
            let Some((wall, rest)) = c.split_once(':').filter(|(w, _)| *w == "inner" || *w == "outer") else {
                return Ok(c.clone());
            };
            let Some(d) = seam_dir else {
                bail!("--cluster {c}: inner and outer name the walls of a ring (a periodic map, or a cut ring whose opposite sides coincide); this map has south, east, north and west");
            };
            let names = winslow_mesh::seam::wall_names(map, d);
            let sides = winslow_mesh::seam::ends(1 - d);
            let k = usize::from(names[1] == wall);
            Ok(format!("{}:{rest}", sides[k].name()))
        })
        .collect()
}

fn parse_points(s: &str) -> Result<[usize; 2]> {
    let (a, b) = s.split_once(['x', 'X']).with_context(|| format!("--structured {s}: expected NXxNY, e.g. 401x35"))?;
    let n = |t: &str| t.trim().parse::<usize>().with_context(|| format!("--structured {s}: '{t}' is not a count"));
    Ok([n(a)?, n(b)?])
}

/// The options of `--unstructured`.
fn unstructured_options(spec: &MeshSpec) -> Result<UnstructuredOptions> {
    Ok(UnstructuredOptions {
        size: spec.size.context("--unstructured needs --size H")?,
        min_angle: spec.min_angle,
        chord_tol: spec.chord_tol,
        det_j_ratio: (spec.det_j_ratio > 0.0).then_some(spec.det_j_ratio),
        order: spec.order as usize,
        ..Default::default()
    })
}

/// Build the mesh `spec` asks for, write it, print the quality table; returns 0.
pub fn make_and_write(map: &Surface, spec: &MeshSpec, output: &Path, quiet: bool) -> Result<()> {
    let format = Format::from_path(output)?;
    let t = Instant::now();
    let mut stats: Option<MeshingStats> = None;
    let seam = winslow_mesh::seam::seams(map)?;
    let cluster = wall_sides(&spec.cluster, map, seam.dir())?;
    let linear = if let Some(s) = &spec.structured {
        let opts = StructuredOptions {
            points: parse_points(s)?,
            distribution: distributions(&cluster, &spec.equidistribute)?,
        };
        structured(map, &opts)?
    } else if spec.unstructured {
        if !spec.cluster.is_empty() || !spec.equidistribute.is_empty() {
            bail!("--cluster and --equidistribute apply to --structured meshes only");
        }
        let (mesh, st) = unstructured_with_stats(map, &unstructured_options(spec)?)?;
        stats = Some(st);
        mesh
    } else {
        bail!("say which mesh: --structured NXxNY or --unstructured --size H");
    };
    let mesh = elevate(&linear, map, spec.order as usize)?;
    let built = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let q = quality(&mesh)?;
    let measured = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let files = write(&mesh, output, format).with_context(|| format!("writing {}", output.display()))?;
    let written = t.elapsed().as_secs_f64();
    if !quiet {
        say!(
            "{} mesh, {} {}s of order {} ({}):",
            if mesh.structured.is_some() { "structured" } else { "unstructured" },
            mesh.num_cells(),
            mesh.kind.name(),
            mesh.order,
            format.name()
        );
        say_raw!("{}", q.table());
        if let Some(line) = seam.describe() {
            say!("  {line}");
        }
        say!("  built in {built:.3} s, quality in {measured:.3} s, checked and written in {written:.3} s");
        if let Some(st) = stats {
            say!(
                "  meshing: boundary {:.3} s, spade refinement {:.3} s ({} of {} rounds), mapping {:.3} s, criteria {:.3} s, insertion {:.3} s, mesh {:.3} s",
                st.boundary, st.refine, st.spade_refinements, st.rounds, st.map, st.criteria, st.insert, st.build
            );
        }
    }
    for f in files {
        crate::files::record(&f);
    }
    Ok(())
}

/// Mesh a multipatch result (every patch a map): one conforming mesh, structured
/// (`--structured NXxNY`, points made equal across interfaces) or triangulated
/// (`--unstructured --size H`, interface points shared by both patches), a cell group
/// per face (or patch) and a boundary group per outer side; prints the resolution and
/// the quality table.
pub fn make_and_write_multipatch(layout: &Layout, spec: &MeshSpec, output: &Path, quiet: bool) -> Result<()> {
    let format = Format::from_path(output)?;
    if !spec.cluster.is_empty() || !spec.equidistribute.is_empty() {
        bail!(
            "--cluster and --equidistribute apply to a single map; a multipatch result is meshed with uniform points or --unstructured"
        );
    }
    if spec.order != 1 {
        bail!("--order {}: a multipatch result is meshed with linear cells only", spec.order);
    }
    let t = Instant::now();
    let mut lines = Vec::new();
    let (mesh, gap) = if let Some(s) = &spec.structured {
        let mp = winslow_mesh::multipatch(layout, parse_points(s)?)?;
        let classes: Vec<String> = mp.class_points.iter().enumerate().map(|(c, n)| format!("{c}: {n}")).collect();
        lines.push(format!("points per direction class (equal across interfaces): {}", classes.join(", ")));
        for (p, n) in mp.patch_points.iter().enumerate() {
            lines.push(format!("{}: {}x{} points", layout.label(p), n[0], n[1]));
        }
        (mp.mesh, mp.interface_gap)
    } else if spec.unstructured {
        let mt = winslow_mesh::multipatch_unstructured(layout, &unstructured_options(spec)?)?;
        lines.push(format!(
            "interface points agreed after {} round{} of triangulating the patches",
            mt.rounds,
            if mt.rounds == 1 { "" } else { "s" }
        ));
        let (lo, hi) = (mt.patch_cells.iter().min().copied(), mt.patch_cells.iter().max().copied());
        lines.push(format!("triangles per patch {} to {}", lo.unwrap_or(0), hi.unwrap_or(0)));
        let st = mt.stats;
        lines.push(format!(
            "meshing (summed over patches): boundary {:.3} s, spade refinement {:.3} s, mapping {:.3} s, criteria {:.3} s, insertion {:.3} s, mesh {:.3} s",
            st.boundary, st.refine, st.map, st.criteria, st.insert, st.build
        ));
        (mt.mesh, mt.interface_gap)
    } else {
        bail!("say which mesh: --structured NXxNY or --unstructured --size H");
    };
    let built = t.elapsed().as_secs_f64();
    let q = quality(&mesh)?;
    let t = Instant::now();
    let files = write(&mesh, output, format).with_context(|| format!("writing {}", output.display()))?;
    let written = t.elapsed().as_secs_f64();
    if !quiet {
        say!(
            "multipatch mesh, {} patches, {} {}s, {} nodes ({}):",
            layout.patches.len(),
            mesh.num_cells(),
            mesh.kind.name(),
            mesh.points.len(),
            format.name()
        );
        for l in lines {
            say!("  {l}");
        }
        let groups: Vec<&str> = mesh.boundary_groups().into_iter().map(|g| g.0).collect();
        say!("  boundary groups: {}", groups.join(", "));
        let cells: Vec<&str> = mesh.cell_groups().into_iter().map(|g| g.0).collect();
        say!("  cell groups: {}", cells.join(", "));
        say!("  largest interface gap {gap:.3e}");
        say_raw!("{}", q.table());
        say!("  built in {built:.3} s, checked and written in {written:.3} s");
    }
    for f in files {
        crate::files::record(&f);
    }
    Ok(())
}

/// Mesh a trivariate map (a loft): a structured hexahedral mesh, `--structured
/// NXxNYxNZ`, written as .vtu or .msh after its corner Jacobians are checked.
pub fn make_and_write_volume(volume: &Volume, spec: &MeshSpec, output: &Path, quiet: bool) -> Result<()> {
    let format = Format::from_path(output)?;
    let Some(s) = &spec.structured else {
        bail!("a volume is meshed with --structured NXxNYxNZ (hexahedra); --unstructured is for planar maps");
    };
    if !spec.cluster.is_empty() || !spec.equidistribute.is_empty() || spec.order != 1 {
        bail!("--cluster, --equidistribute and --order apply to planar maps; a volume is meshed with uniform linear hexahedra");
    }
    let parts: Vec<&str> = s.split(['x', 'X']).collect();
    let n = |t: &str| t.trim().parse::<usize>().with_context(|| format!("--structured {s}: '{t}' is not a count"));
    let points = match parts.as_slice() {
        [a, b, c] => [n(a)?, n(b)?, n(c)?],
        _ => bail!("--structured {s}: a volume needs NXxNYxNZ, e.g. 17x17x9"),
    };
    let mesh = winslow_mesh::volume::hexahedra(volume, points)?;
    let files = winslow_mesh::volume::write_hex(&mesh, output, format)
        .with_context(|| format!("writing {}", output.display()))?;
    if !quiet {
        let vols: Vec<f64> =
            (0..mesh.cells.len()).map(|c| winslow_mesh::volume::hex_volume(&mesh.corners(c))).collect();
        let (lo, hi) = vols.iter().fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
        say!(
            "structured hexahedral mesh, {} hexahedra, {} nodes ({}): volume {:.6e}, cell volumes {lo:.3e} .. {hi:.3e}",
            mesh.cells.len(),
            mesh.points.len(),
            format.name(),
            vols.iter().sum::<f64>()
        );
    }
    for f in files {
        crate::files::record(&f);
    }
    Ok(())
}

/// The mesh of a THB map: made from its exact tensor map on the knot lines of its active
/// cells ([`HierarchicalMap::to_surface`], knot insertion), which the report line says.
pub fn make_and_write_thb(map: &HierarchicalMap, spec: &MeshSpec, output: &Path, quiet: bool) -> Result<()> {
    let tensor = map.to_surface().context("converting the THB map to its tensor map")?;
    if !quiet {
        say!(
            "THB map of {} functions on {} levels: meshed through its exact tensor map of {} x {} control points (knot insertion)",
            map.basis.len(),
            map.basis.num_levels(),
            tensor.shape()[0],
            tensor.shape()[1]
        );
    }
    make_and_write(&tensor, spec, output, quiet)
}

/// `winslow mesh`: a map, or a multipatch result (a JSON result or a G+Smo multipatch
/// whose patches are maps).
pub fn run(a: MeshArgs) -> Result<i32> {
    let needed =
        "mesh needs a map, a THB map, a multipatch result or a volume (run `winslow solve` or `winslow loft` first, or `solve --mesh`)";
    crate::files::OutputPlan::new().input(&a.map).mesh_maybe("-o", Some(&a.output))?.check()?;
    match crate::files::read(&a.map)? {
        Document::Map { map, .. } => make_and_write(&map, &a.spec, &a.output, false)?,
        Document::Multipatch(layout) => make_and_write_multipatch(&layout, &a.spec, &a.output, false)?,
        Document::Layout(layout) if layout.patches.iter().all(|p| p.map.is_some()) => {
            make_and_write_multipatch(&layout, &a.spec, &a.output, false)?
        }
        Document::Volume { volume, .. } => make_and_write_volume(&volume, &a.spec, &a.output, false)?,
        Document::Thb { map, .. } => make_and_write_thb(&map, &a.spec, &a.output, false)?,
        other => return Err(crate::files::wrong_kind(&other, &a.map, needed)),
    }
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn distributions_of(specs: &[String]) -> Result<[Distribution; 2]> {
        distributions(specs, &[])
    }

    #[test]
    fn equidistribute_specs_parse() {
        let d = distributions(&[], &["arclength".into()]).unwrap();
        assert_eq!(d, [0, 1].map(|_| Distribution::Equidistributed(Equidistribution::ArcLength)));
        let d = distributions(&["xi:arctan:3".into()], &["eta:curvature:1e-3".into()]).unwrap();
        assert_eq!(d[1], Distribution::Equidistributed(Equidistribution::Curvature { tol: 1e-3 }));
        assert!(distributions(&["eta:arctan:3".into()], &["eta:arclength".into()]).is_err());
        assert!(distributions(&[], &["curvature:0".into()]).is_err());
        assert!(distributions(&[], &["curvature:x".into()]).is_err());
        assert!(distributions(&[], &["eta:spline".into()]).is_err());
    }

    #[test]
    fn cluster_specs_parse() {
        let d = distributions_of(&["eta:arctan:6".into()]).unwrap();
        assert_eq!(d[1], Distribution::Arctan { strength: 6.0 });
        let d =
            distributions_of(&["south:first-height:1e-4:1.1".into(), "north:first-height:2e-4:1.1".into()]).unwrap();
        assert_eq!(d[1], Distribution::Layers { start: Some(1e-4), end: Some(2e-4), growth: 1.1 });
        let d = distributions_of(&["inner:first-height:1e-4".into(), "outer:first-height:2e-4".into()]).unwrap();
        assert_eq!(d[0], Distribution::Layers { start: Some(1e-4), end: Some(2e-4), growth: 1.2 });
        let d = distributions_of(&["west:tanh:2".into()]).unwrap();
        assert_eq!(d[0], Distribution::TanhOneSided { strength: 2.0, at: End::Start });
        assert!(distributions_of(&["eta:arctan:x".into()]).is_err());
        assert!(distributions_of(&["eta:arctan:6".into(), "south:first-height:1e-3".into()]).is_err());
        assert!(
            distributions_of(&["south:first-height:1e-3:1.1".into(), "north:first-height:1e-3:1.2".into()]).is_err()
        );
        assert!(distributions_of(&["up:uniform".into()]).is_err());
        assert_eq!(parse_points("401x35").unwrap(), [401, 35]);
        assert!(parse_points("401").is_err());
    }
}
