//! `winslow inspect`: sides, degrees, knots, corner angles, orientation and the fit of a
//! boundary (a ring: `inspect_ring`).

use super::*;

#[derive(Args, Debug)]
pub(crate) struct InspectArgs {
    /// Boundary file (JSON boundary, contour or map document; G+Smo XML), or a ring
    /// document or ring map (its two contours).
    pub(crate) file: PathBuf,
    #[command(flatten)]
    pub(crate) fit: FitArgs,
    /// Print the report as JSON.
    #[arg(long)]
    pub(crate) json: bool,
}

pub(crate) fn load_boundary(path: &Path, reorient: bool) -> Result<Boundary> {
    let b = files::boundary_of(files::read(path)?, path)?;
    let (b, _) =
        checked_boundary(b, &ReadOptions { reorient }).with_context(|| format!("validating {}", path.display()))?;
    Ok(b)
}

pub(crate) fn inspect(a: InspectArgs) -> Result<i32> {
    let doc = files::read(&a.file)?;
    if doc.is_ring_map() {
        let ring = files::ring_of(doc, &a.file)?;
        return inspect_ring::run(&a.file, &ring, &fit_options(&a.fit), a.json);
    }
    let kind = match &doc {
        Document::Ring(ring) => return inspect_ring::run(&a.file, ring, &fit_options(&a.fit), a.json),
        Document::Boundary(_) => "boundary",
        _ => "map (its four boundary curves are inspected)",
    };
    let boundary = files::boundary_of(doc, &a.file)?;
    let mut problems = Vec::new();
    let checked = checked_boundary(boundary.clone(), &ReadOptions { reorient: a.fit.reorient });
    let (boundary, report) = match checked {
        Ok((b, r)) => (b, Some(r)),
        Err(e) => {
            problems.push(e.to_string());
            (boundary, None)
        }
    };
    let fit = if problems.is_empty() { Some(build_hierarchy(&boundary, &fit_options(&a.fit))) } else { None };
    let fit = match fit {
        Some(Ok(h)) => Some(h),
        Some(Err(e)) => {
            problems.push(format!("contour fit failed: {e}"));
            None
        }
        None => None,
    };
    let text = output::inspect_text(&a.file, kind, &boundary, report.as_ref(), fit.as_ref(), &problems);
    if a.json {
        let v = output::inspect_json(&boundary, report.as_ref(), fit.as_ref(), &problems);
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        say_raw!("{text}");
    }
    Ok(if problems.is_empty() { 0 } else { 2 })
}
