//! Line reading and file listing shared by the loaders.

use crate::error::{Error, Result};
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// Calls `f(line_number, text)` for every line of `reader` (1-based), with the line ending
/// (`\n` or `\r\n`) removed; `text` is `None` for a line that is not valid UTF-8.
pub(crate) fn for_each_line<R: BufRead>(
    mut reader: R,
    file: &str,
    mut f: impl FnMut(usize, Option<&str>) -> Result<()>,
) -> Result<()> {
    let mut buf = Vec::with_capacity(256);
    let mut line = 0;
    loop {
        buf.clear();
        let n = reader
            .read_until(b'\n', &mut buf)
            .map_err(|e| Error::io(file, e))?;
        if n == 0 {
            return Ok(());
        }
        line += 1;
        if buf.last() == Some(&b'\n') {
            buf.pop();
        }
        if buf.last() == Some(&b'\r') {
            buf.pop();
        }
        f(line, std::str::from_utf8(&buf).ok())?;
    }
}

/// Opens a file for buffered reading, transparently decompressing gzip (detected by its
/// magic bytes `1f 8b`, whatever the file name).
pub(crate) fn open(path: &Path) -> Result<Box<dyn BufRead>> {
    let name = path.display().to_string();
    let mut file =
        BufReader::with_capacity(1 << 16, File::open(path).map_err(|e| Error::io(&name, e))?);
    let head = file.fill_buf().map_err(|e| Error::io(&name, e))?;
    if head.starts_with(&[0x1f, 0x8b]) {
        Ok(Box::new(BufReader::with_capacity(
            1 << 16,
            flate2::read::MultiGzDecoder::new(file),
        )))
    } else {
        Ok(Box::new(file))
    }
}

/// Reads a whole (possibly gzip-compressed) file into bytes.
pub(crate) fn read_all(path: &Path) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    open(path)?
        .read_to_end(&mut out)
        .map_err(|e| Error::io(path.display(), e))?;
    Ok(out)
}

/// The entries of `dir` (sorted by name) for which `keep` holds.
pub(crate) fn list(dir: &Path, keep: impl Fn(&Path) -> bool) -> Result<Vec<PathBuf>> {
    let rd = std::fs::read_dir(dir).map_err(|e| Error::io(dir.display(), e))?;
    let mut out = Vec::new();
    for e in rd {
        let p = e.map_err(|e| Error::io(dir.display(), e))?.path();
        if keep(&p) {
            out.push(p);
        }
    }
    out.sort();
    Ok(out)
}

/// The file name without its extension(s) after the first dot.
pub(crate) fn stem(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    match name.split_once('.') {
        Some((s, _)) => s.to_string(),
        None => name,
    }
}
