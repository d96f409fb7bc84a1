//! Documents in and out of the commands: [`winslow::io::read`] and
//! [`winslow::io::write`] with each message naming the file once; the outputs of a
//! command as one transaction ([`OutputPlan`]: every path checked before the work, every
//! file recorded for the exit summary).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;

use anyhow::{bail, Context, Result};
use winslow::io::{self, Document, Output};
use winslow::{Error, Surface};

/// A core error with the file named: errors that name it already (I/O, a document of
/// the wrong kind, an extension that does not fit) pass as they are; the others (a
/// malformed document) get `"{action} {path}"` in front.
pub(crate) fn named(e: Error, action: &str, path: &Path) -> anyhow::Error {
    match e {
        Error::Io { .. } | Error::DocumentKind { path: Some(_), .. } | Error::Extension { .. } => e.into(),
        e => anyhow::Error::new(e).context(format!("{action} {}", path.display())),
    }
}

/// Read any document ([`winslow::io::read`]).
pub(crate) fn read(path: &Path) -> Result<Document> {
    io::read(path).map_err(|e| named(e, "reading", path))
}

/// Read a document and the `report` stored beside it ([`winslow::io::read_with_report`]).
pub(crate) fn read_with_report(path: &Path) -> Result<(Document, Option<serde_json::Value>)> {
    io::read_with_report(path).map_err(|e| named(e, "reading", path))
}

/// Write by the path's extension ([`winslow::io::write`]) and record the file.
pub(crate) fn write(path: &Path, out: &Output) -> Result<()> {
    io::write(path, out).map_err(|e| named(e, "writing", path))?;
    record(path);
    if extension_of(path) == "vtm" {
        // the blocks go into a folder named after the file
        record(&path.with_extension(""));
    }
    Ok(())
}

/// Write in the format of `extension` whatever the path's ([`winslow::io::output::write_as`])
/// and record the file.
pub(crate) fn write_as(path: &Path, extension: &str, out: &Output) -> Result<()> {
    io::output::write_as(path, extension, out).map_err(|e| named(e, "writing", path))?;
    record(path);
    if extension == "vtm" {
        record(&path.with_extension(""));
    }
    Ok(())
}

/// Write bytes atomically ([`winslow::io::write_bytes`]) and record the file.
pub(crate) fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    io::write_bytes(path, bytes).map_err(|e| named(e, "writing", path))?;
    record(path);
    Ok(())
}

/// Write a JSON value atomically ([`winslow::io::write_json`]) and record the file.
pub(crate) fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    io::write_json(path, value).map_err(|e| named(e, "writing", path))?;
    record(path);
    Ok(())
}

/// The error "`path`: a KIND document, where `needed`".
pub(crate) fn wrong_kind(doc: &Document, path: &Path, needed: &str) -> anyhow::Error {
    doc.wrong_kind(Some(path), needed).into()
}

/// The name and map of a map document (a ring map included); any other kind is the
/// error naming it and `needed`.
pub(crate) fn map_of(doc: Document, path: &Path, needed: &str) -> Result<(String, Surface)> {
    match doc {
        Document::Map { name, map } => Ok((name, map)),
        other => Err(wrong_kind(&other, path, needed)),
    }
}

/// The four-sided boundary of a boundary or map document; any other kind is the error
/// naming it.
pub(crate) fn boundary_of(doc: Document, path: &Path) -> Result<winslow::Boundary> {
    doc.into_boundary().map_err(|e| match e {
        Error::DocumentKind { found, needed, .. } => {
            Error::DocumentKind { path: Some(path.to_path_buf()), found, needed }.into()
        }
        e => e.into(),
    })
}

/// The pipeline input of `doc`, read from `path` ([`Document::into_input`]), a boundary
/// validated and, with `reorient`, turned counter-clockwise; errors name the file.
pub(crate) fn input_of(doc: Document, path: &Path, reorient: bool) -> Result<winslow::Input> {
    let opts = winslow::ReadOptions { reorient };
    doc.into_input(&opts).map_err(|e| match e {
        Error::DocumentKind { found, needed, .. } => {
            Error::DocumentKind { path: Some(path.to_path_buf()), found, needed }.into()
        }
        e => anyhow::Error::new(e).context(format!("validating {}", path.display())),
    })
}

/// The ring of a ring document or a ring map ([`Document::into_ring`]); any other kind is
/// the error naming it.
pub(crate) fn ring_of(doc: Document, path: &Path) -> Result<winslow::boundary::ring::Ring> {
    doc.into_ring().map_err(|e| match e {
        Error::DocumentKind { found, needed, .. } => {
            Error::DocumentKind { path: Some(path.to_path_buf()), found, needed }.into()
        }
        e => e.into(),
    })
}

/// The error for a boundary or a layout given where a solved map is needed.
pub(crate) const SOLVE_FIRST: &str = "a map is needed (run `winslow solve` first)";

// ---------------------------------------------------------------------------------
// Outputs as a transaction: every path checked before the work, every file recorded.

/// Extensions (lower case, without the dot; `""` is a path without one) of each kind of
/// output, as [`winslow::io::write`] takes them.
pub(crate) mod ext {
    /// A map.
    pub const MAP: &[&str] = &["json", "", "xml", "igs", "iges", "vtu", "vtk"];
    /// A volume.
    pub const VOLUME: &[&str] = &["json", "", "xml", "vtu", "vtk"];
    /// The six faces of a volume (JSON or a G+Smo multipatch).
    pub const VOLUME_BOUNDARY: &[&str] = &["json", "", "xml"];
    /// A multipatch result.
    pub const MULTIPATCH: &[&str] = &["json", "", "xml", "vtm"];
    /// A JSON document (layout, boundary).
    pub const JSON: &[&str] = &["json", ""];
    /// A picture.
    pub const PNG: &[&str] = &["png"];
    /// An animated picture.
    pub const APNG: &[&str] = &["png", "apng"];
    /// G+Smo XML.
    pub const XML: &[&str] = &["xml"];
    /// IGES.
    pub const IGES: &[&str] = &["igs", "iges"];
    /// VTK Bézier cells.
    pub const VTU: &[&str] = &["vtu"];
    /// A sampled VTK grid.
    pub const VTK: &[&str] = &["vtk"];
    /// A VTK multiblock file.
    pub const VTM: &[&str] = &["vtm"];
    /// A mesh file (a folder is an OpenFOAM case).
    pub const MESH: &[&str] = &["msh", "vtu", "su2", "xyz", "x"];
}

/// What an output path names.
#[derive(Debug, Clone, Copy)]
enum Shape {
    /// A file of `what`, written as one of the extensions.
    File { what: &'static str, extensions: &'static [&'static str] },
    /// A folder the command writes files into.
    Folder,
}

#[derive(Debug)]
struct Planned {
    flag: String,
    path: PathBuf,
    shape: Shape,
}

/// Every output path of a command, collected from its arguments and checked before any
/// work ([`OutputPlan::check`]): each one's folder exists (or can be made) and is
/// writable (a file is created and removed there), its extension fits the format asked,
/// no two outputs name the same file and no output names an input (paths compared after
/// resolving the folders' links; an existing output also by its file identity).
#[derive(Debug, Default)]
pub(crate) struct OutputPlan {
    inputs: Vec<PathBuf>,
    outputs: Vec<Planned>,
}

impl OutputPlan {
    pub(crate) fn new() -> Self {
        Self::default()
    }

    /// An input file (or folder) that no output may replace.
    pub(crate) fn input(mut self, path: &Path) -> Self {
        self.inputs.push(path.to_path_buf());
        self
    }

    /// An output file of `what` given by `flag`, written as one of `extensions`.
    pub(crate) fn file(
        mut self,
        flag: &str,
        path: &Path,
        what: &'static str,
        extensions: &'static [&'static str],
    ) -> Self {
        self.outputs.push(Planned {
            flag: flag.to_string(),
            path: path.to_path_buf(),
            shape: Shape::File { what, extensions },
        });
        self
    }

    /// [`Self::file`] when the flag was given.
    pub(crate) fn maybe(
        self,
        flag: &str,
        path: Option<&Path>,
        what: &'static str,
        extensions: &'static [&'static str],
    ) -> Self {
        match path {
            Some(p) => self.file(flag, p, what, extensions),
            None => self,
        }
    }

    /// An output folder given by `flag`.
    pub(crate) fn folder(mut self, flag: &str, path: &Path) -> Self {
        self.outputs.push(Planned { flag: flag.to_string(), path: path.to_path_buf(), shape: Shape::Folder });
        self
    }

    /// [`Self::folder`] when the flag was given.
    pub(crate) fn folder_maybe(self, flag: &str, path: Option<&Path>) -> Self {
        match path {
            Some(p) => self.folder(flag, p),
            None => self,
        }
    }

    /// A mesh output when the flag was given: a file by its extension, or a folder (an
    /// OpenFOAM case).
    pub(crate) fn mesh_maybe(self, flag: &str, path: Option<&Path>) -> Result<Self> {
        use winslow_mesh::formats::Format;
        Ok(match path {
            Some(p) if Format::from_path(p)? == Format::OpenFoam => self.folder(flag, p),
            Some(p) => self.file(flag, p, "mesh", ext::MESH),
            None => self,
        })
    }

    /// Check every output (see the type's documentation); the first problem is the
    /// error, naming the flag and the path.
    pub(crate) fn check(self) -> Result<()> {
        for o in &self.outputs {
            check_one(o)?;
        }
        let inputs: Vec<PathBuf> = self.inputs.iter().map(|p| resolved(p)).collect();
        let outputs: Vec<PathBuf> = self.outputs.iter().map(|o| resolved(&o.path)).collect();
        for (i, o) in self.outputs.iter().enumerate() {
            for (j, p) in self.outputs.iter().enumerate().take(i) {
                if outputs[i] == outputs[j] {
                    bail!(
                        "{} {} and {} {} name the same file: each output needs its own path",
                        p.flag,
                        p.path.display(),
                        o.flag,
                        o.path.display()
                    );
                }
            }
            for (input, r) in self.inputs.iter().zip(&inputs) {
                if outputs[i] == *r || same_file(&o.path, input) {
                    bail!(
                        "{} {} is the input {}: an output never replaces an input (choose another path)",
                        o.flag,
                        o.path.display(),
                        input.display()
                    );
                }
            }
        }
        Ok(())
    }
}

/// The extension of `path`, lower case, without the dot (empty when it has none).
fn extension_of(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// `.a`, `.b` or `.c` (`""` shown as "no extension").
fn list(extensions: &[&str]) -> String {
    let names: Vec<String> =
        extensions.iter().map(|e| if e.is_empty() { "no extension".to_string() } else { format!(".{e}") }).collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => names.join(""),
    }
}

fn check_one(o: &Planned) -> Result<()> {
    let (flag, path) = (&o.flag, &o.path);
    match o.shape {
        Shape::File { what, extensions } => {
            let trailing_slash = path.as_os_str().to_string_lossy().ends_with(['/', '\\']);
            if path.file_name().is_none() || trailing_slash {
                bail!("{flag} {}: not a file name", path.display());
            }
            let ext = extension_of(path);
            if !extensions.contains(&ext.as_str()) {
                let got = if ext.is_empty() { "no extension".to_string() } else { format!(".{ext}") };
                bail!("{flag} {}: a {what} is written as {}, not {got}", path.display(), list(extensions));
            }
            if path.is_dir() {
                bail!("{flag} {}: a folder is there, where the {what} should be written", path.display());
            }
            let parent = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
            writable(flag, path, parent)
        }
        Shape::Folder => {
            if path.exists() && !path.is_dir() {
                bail!("{flag} {}: a file is there, where a folder should be", path.display());
            }
            writable(flag, path, path)
        }
    }
}

/// The nearest existing folder at or above `dir` must be a folder and take a new file:
/// one is created there and removed.
fn writable(flag: &str, path: &Path, dir: &Path) -> Result<()> {
    let mut at = dir;
    while !at.exists() {
        match at.parent() {
            Some(p) if !p.as_os_str().is_empty() => at = p,
            _ => {
                at = Path::new(".");
                break;
            }
        }
    }
    if !at.is_dir() {
        bail!("{flag} {}: {} is a file, not a folder", path.display(), at.display());
    }
    static PROBE: AtomicU64 = AtomicU64::new(0);
    let probe = at.join(format!(".winslow-probe.{}.{}", std::process::id(), PROBE.fetch_add(1, Ordering::Relaxed)));
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(cause) => bail!("{flag} {}: cannot write in the folder {} ({cause})", path.display(), at.display()),
    }
}

/// `path` made absolute, its longest existing ancestor canonical (links resolved), the
/// rest appended.
fn resolved(path: &Path) -> PathBuf {
    let abs = std::env::current_dir().map(|d| d.join(path)).unwrap_or_else(|_| path.to_path_buf());
    let mut rest = Vec::new();
    let mut at = abs.as_path();
    loop {
        if let Ok(c) = at.canonicalize() {
            let mut out = c;
            for part in rest.iter().rev() {
                out.push(part);
            }
            return out;
        }
        match (at.parent(), at.file_name()) {
            (Some(p), Some(name)) => {
                rest.push(name.to_os_string());
                at = p;
            }
            _ => return abs,
        }
    }
}

/// Both exist and are one file (a hard link, or the same file by another path).
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (a, b);
        false
    }
}

/// Make sure the output folder `dir` holds no files of another run: the files in it
/// whose names `ours` accepts (the files this command writes there). With `overwrite`
/// they are removed (before the work starts); without, they are the error. Other files
/// are left alone.
pub(crate) fn claim_folder(flag: &str, dir: &Path, ours: impl Fn(&str) -> bool, overwrite: bool) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Ok(()) };
    let mut old: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter(|e| ours(&e.file_name().to_string_lossy()))
        .map(|e| e.path())
        .collect();
    if old.is_empty() {
        return Ok(());
    }
    old.sort();
    if !overwrite {
        let shown: Vec<String> =
            old.iter().take(3).map(|p| p.file_name().unwrap_or_default().to_string_lossy().into_owned()).collect();
        bail!(
            "{flag} {}: the folder holds {} file(s) of an earlier run ({}{}); pass --overwrite to remove them first, or choose another folder",
            dir.display(),
            old.len(),
            shown.join(", "),
            if old.len() > 3 { ", ..." } else { "" }
        );
    }
    for p in &old {
        std::fs::remove_file(p).with_context(|| format!("removing {} (--overwrite)", p.display()))?;
    }
    note!("{flag} {}: removed {} file(s) of an earlier run (--overwrite)", dir.display(), old.len());
    Ok(())
}

static WRITTEN: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static JSON_PRINTED: AtomicBool = AtomicBool::new(false);

/// Record a file (or folder) written by the command, for the exit summary.
pub(crate) fn record(path: &Path) {
    if let Ok(mut w) = WRITTEN.lock() {
        if !w.iter().any(|p| p == path) {
            w.push(path.to_path_buf());
        }
    }
}

/// Every file recorded so far, in the order written.
pub(crate) fn written() -> Vec<PathBuf> {
    WRITTEN.lock().map(|w| w.clone()).unwrap_or_default()
}

/// The files written, for a line: more than four in one folder are shown as the
/// folder and their count.
pub(crate) fn written_list() -> String {
    let all = written();
    let folder = |p: &PathBuf| p.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut shown: Vec<String> = Vec::new();
    let mut done: Vec<PathBuf> = Vec::new();
    for p in &all {
        let dir = folder(p);
        let n = all.iter().filter(|q| folder(q) == dir).count();
        if n > 4 {
            if !done.contains(&dir) {
                shown.push(format!("{} ({n} files)", dir.join("").display()));
                done.push(dir);
            }
        } else {
            shown.push(p.display().to_string());
        }
    }
    shown.join(", ")
}

/// Print a command's JSON report on stdout with the field `"files"`: every file written
/// (the exit summary line is then left out).
pub(crate) fn print_json(mut value: serde_json::Value) -> Result<()> {
    if let serde_json::Value::Object(m) = &mut value {
        let files: Vec<String> = written().iter().map(|p| p.display().to_string()).collect();
        m.insert("files".into(), serde_json::json!(files));
    }
    println!("{}", serde_json::to_string_pretty(&value)?);
    JSON_PRINTED.store(true, Ordering::Relaxed);
    Ok(())
}

/// Whether [`print_json`] printed the report (and with it the files).
pub(crate) fn json_printed() -> bool {
    JSON_PRINTED.load(Ordering::Relaxed)
}
