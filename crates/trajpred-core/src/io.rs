//! Files written whole or not at all.
//!
//! [`write_atomic_with`] has the content written into a temporary file in the destination's
//! own folder (so the final rename stays on one file system), flushes it to disk and renames
//! it over the destination. A reader, or a run killed at any moment, sees the old file (or
//! none) or the new one, never a torn one. A killed writer can leave its temporary file
//! behind: its name starts with `.` and the destination's name, and ends in `.tmp` followed
//! by the destination's extension (`.chart.png.a1B2c3.tmp.png`).
//! Every file trajpred writes (models, parameters, forecasts, tables, figures, the
//! reproduction's outputs) goes through here.

use std::io;
use std::path::Path;

/// Writes the file at `path` through `fill`, which receives the path of a fresh temporary
/// file in the same folder and writes the whole content there (by path, so that writers
/// that open their own file, like plotting backends, can use it). When `fill` succeeds the
/// temporary file is synced and renamed over `path`; when anything fails the temporary
/// file is removed and `path` is left as it was.
///
/// ```
/// use trajpred_core::io::write_atomic_with;
/// let dir = std::env::temp_dir().join(format!("trajpred-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let path = dir.join("table.csv");
/// write_atomic_with(&path, |tmp| std::fs::write(tmp, "a,b\n1,2\n"))?;
/// assert_eq!(std::fs::read_to_string(&path)?, "a,b\n1,2\n");
/// // a failed write leaves the old content
/// let failed = write_atomic_with(&path, |_| Err(std::io::Error::other("no")));
/// assert!(failed.is_err());
/// assert_eq!(std::fs::read_to_string(&path)?, "a,b\n1,2\n");
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn write_atomic_with<E, F>(path: &Path, fill: F) -> Result<(), E>
where
    E: From<io::Error>,
    F: FnOnce(&Path) -> Result<(), E>,
{
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{}: the path names no file", path.display()),
        )
    })?;
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(name);
    prefix.push(".");
    // the destination's extension last, for writers that choose the format by it
    let mut suffix = std::ffi::OsString::from(".tmp");
    if let Some(ext) = path.extension() {
        suffix.push(".");
        suffix.push(ext);
    }
    let tmp = tempfile::Builder::new()
        .prefix(&prefix)
        .suffix(&suffix)
        .tempfile_in(dir)
        .map_err(|e| with_path(e, dir))?;
    // on any early return `tmp` is dropped, which removes the temporary file
    fill(tmp.path())?;
    std::fs::File::open(tmp.path())
        .and_then(|f| f.sync_all())
        .map_err(|e| with_path(e, path))?;
    tmp.persist(path).map_err(|e| with_path(e.error, path))?;
    Ok(())
}

/// [`write_atomic_with`] for content already in memory.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |tmp| std::fs::write(tmp, bytes))
}

fn with_path(e: io::Error, path: &Path) -> io::Error {
    io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}
