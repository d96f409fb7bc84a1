//! Files: reading a whole text file with a size limit ([`read_text`]), and the one
//! atomic writer every output of the crate goes through ([`write_with`]): the content is
//! written to a temporary file in the destination's folder and renamed into place, so
//! that a failed write (an error of the encoder, a full disk) never leaves a
//! half-written file under the final name, and an older file there stays intact.

use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Largest file [`read_text`] accepts: 256 MiB.
pub const MAX_FILE_BYTES: u64 = 256 << 20;

fn io_error(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |cause| Error::Io { path: path.to_path_buf(), cause }
}

/// Read a whole file as UTF-8 text, refusing files above [`MAX_FILE_BYTES`].
pub fn read_text(path: &Path) -> Result<String> {
    let io = io_error(path);
    let file = std::fs::File::open(path).map_err(&io)?;
    let too_large = |found: u64| Error::TooLarge {
        context: path.display().to_string(),
        what: "file size in bytes".into(),
        found: usize::try_from(found).unwrap_or(usize::MAX),
        limit: MAX_FILE_BYTES as usize,
    };
    if let Ok(meta) = file.metadata() {
        if meta.len() > MAX_FILE_BYTES {
            return Err(too_large(meta.len()));
        }
    }
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes).map_err(&io)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|e| Error::Invalid(format!("{} is not UTF-8 text: {e}", path.display())))
}

/// A temporary name next to `path`: `.NAME.PID.N.tmp` in the same folder (a rename
/// within one file system is atomic).
fn temporary_name(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

/// Write a file atomically: make its folder, let `fill` write the content into a
/// temporary file in that folder, then rename it to `path`. When `fill` or the write
/// fails, the temporary file is removed and `path` is left as it was. Errors name `path`.
pub fn write_with(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let io = io_error(path);
    if path.file_name().is_none() {
        return Err(io(std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name")));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|cause| Error::Io { path: dir.to_path_buf(), cause })?;
    }
    let tmp = temporary_name(path);
    let written = (|| {
        let mut w = BufWriter::new(std::fs::File::create(&tmp)?);
        fill(&mut w)?;
        w.into_inner().map_err(|e| e.into_error())?.sync_data()?;
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        // the temporary file may not exist (creating it failed): nothing to report
        let _ = std::fs::remove_file(&tmp);
    } else {
        remove_stale_temporaries(path);
    }
    written.map_err(io)
}

/// The temporaries of `path` left by writers that were killed mid-file
/// (`.NAME.PID.N.tmp` whose process no longer runs, [`temporary_name`]) are removed
/// after a successful write of `path`: a kill leaves a hidden file only until the next
/// write of the same file. Where `/proc` is missing (not Linux) nothing is removed.
fn remove_stale_temporaries(path: &Path) {
    let (Some(dir), Some(name)) = (path.parent(), path.file_name()) else { return };
    let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
    if !Path::new("/proc/self").exists() {
        return;
    }
    let prefix = format!(".{}.", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let file = file.to_string_lossy();
        let Some((pid, n)) =
            file.strip_prefix(&prefix).and_then(|r| r.strip_suffix(".tmp")).and_then(|r| r.split_once('.'))
        else {
            continue;
        };
        let (Ok(pid), Ok(_)) = (pid.parse::<u32>(), n.parse::<u64>()) else { continue };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            // another writer may have removed it first: nothing to report
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Write bytes to a file atomically ([`write_with`]).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |w| w.write_all(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path();
        let path = dir.join("out.json");
        write_bytes(&path, b"old").unwrap();
        let e = write_with(&path, |w| {
            w.write_all(b"half of the new content")?;
            Err(std::io::Error::other("the encoder failed"))
        })
        .unwrap_err();
        assert!(matches!(&e, Error::Io { path: p, .. } if p == &path), "{e}");
        assert!(e.to_string().contains("the encoder failed"), "{e}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(entries(dir), ["out.json"]);
        write_bytes(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(entries(dir), ["out.json"]);
    }

    /// A temporary of a writer that was killed (its process gone) is removed by the next
    /// write of the same file; those of running writers (this process) and of other files
    /// stay.
    #[test]
    fn a_killed_writers_temporary_goes_with_the_next_write() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path();
        let path = dir.join("out.v1.json");
        // no process has a PID above the kernel's pid_max (at most 2^22)
        let dead = ".out.v1.json.999999999.0.tmp";
        let running = format!(".out.v1.json.{}.77.tmp", std::process::id());
        for f in [dead, running.as_str(), ".other.json.999999999.0.tmp", ".out.v1.json.x.tmp"] {
            write_bytes(&dir.join(f), b"half").unwrap();
        }
        write_bytes(&path, b"new").unwrap();
        let mut expect = vec![".other.json.999999999.0.tmp", ".out.v1.json.x.tmp", running.as_str(), "out.v1.json"];
        expect.sort();
        assert_eq!(entries(dir), expect);
    }

    #[test]
    fn folders_are_made_and_a_folder_in_the_way_is_an_error() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path();
        let path = dir.join("a/b/c.txt");
        write_bytes(&path, b"x").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"x");
        // a folder where the file should go: the rename fails, the folder stays
        let e = write_bytes(&dir.join("a"), b"y").unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");
        assert!(dir.join("a/b/c.txt").is_file());
        assert_eq!(entries(dir), ["a"]);
        // a file where a folder should go
        let e = write_bytes(&dir.join("a/b/c.txt/d.txt"), b"z").unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");
    }

    #[test]
    fn the_cause_is_printed_once() {
        let e = read_text(Path::new("/nonexistent/winslow/nothing.json")).unwrap_err();
        assert!(std::error::Error::source(&e).is_none());
        let text = e.to_string();
        assert_eq!(text.matches("os error").count(), 1, "{text}");
    }
}
