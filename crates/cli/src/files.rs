//! Documents in and out of the commands: [`winslow::io::read`] and
//! [`winslow::io::write`] with each message naming the file once.

use std::path::Path;

use anyhow::Result;
use winslow::io::{self, Document, Output};
use winslow::{Error, Surface};

/// A core error with the file named: errors that name it already (I/O, a document of
/// the wrong kind, an extension that does not fit) pass as they are; the others (a
/// malformed document) get `"{action} {path}"` in front.
fn named(e: Error, action: &str, path: &Path) -> anyhow::Error {
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

/// Write by the path's extension ([`winslow::io::write`]).
pub(crate) fn write(path: &Path, out: &Output) -> Result<()> {
    io::write(path, out).map_err(|e| named(e, "writing", path))
}

/// Write in the format of `extension` whatever the path's ([`winslow::io::output::write_as`]).
pub(crate) fn write_as(path: &Path, extension: &str, out: &Output) -> Result<()> {
    io::output::write_as(path, extension, out).map_err(|e| named(e, "writing", path))
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

/// The error for a boundary or a layout given where a solved map is needed.
pub(crate) const SOLVE_FIRST: &str = "a map is needed (run `winslow solve` first)";
