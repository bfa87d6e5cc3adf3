//! Line reading and file listing shared by the loaders.

use crate::error::{Error, LimitHit, Result};
use crate::track::LoadOptions;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// Calls `f(line_number, text)` for every line of `reader` (1-based), with the line ending
/// (`\n` or `\r\n`) removed; `text` is `None` for a line that is not valid UTF-8.
///
/// Streams: at most one line (of at most `opts.max_line_bytes` bytes, line end excluded) is
/// held. A longer line, or more than `opts.max_file_bytes` bytes in all (decompressed), is an
/// [`Error::LimitExceeded`] naming the line.
pub(crate) fn for_each_line<R: BufRead>(
    mut reader: R,
    file: &str,
    opts: &LoadOptions,
    mut f: impl FnMut(usize, Option<&str>) -> Result<()>,
) -> Result<()> {
    let max_line = opts.max_line_bytes;
    // the longest read that can still be an acceptable line: the line, `\r` and `\n`
    let read_cap = u64::try_from(max_line)
        .unwrap_or(u64::MAX)
        .saturating_add(2);
    let mut buf = Vec::with_capacity(256);
    let mut line = 0;
    let mut total: u64 = 0;
    loop {
        buf.clear();
        let n = (&mut reader)
            .take(read_cap)
            .read_until(b'\n', &mut buf)
            .map_err(|e| Error::io(file, e))?;
        if n == 0 {
            return Ok(());
        }
        line += 1;
        total = total.saturating_add(n as u64);
        if total > opts.max_file_bytes {
            return Err(LimitHit {
                line: Some(line),
                option: "max_file_bytes",
                limit: opts.max_file_bytes,
                what: "decompressed size in bytes",
            }
            .to_error(file));
        }
        let ended = buf.last() == Some(&b'\n');
        if ended {
            buf.pop();
        }
        if buf.last() == Some(&b'\r') {
            buf.pop();
        }
        if buf.len() > max_line {
            return Err(LimitHit {
                line: Some(line),
                option: "max_line_bytes",
                limit: max_line as u64,
                what: "line length in bytes",
            }
            .to_error(file));
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

/// Reads a whole (possibly gzip-compressed) file into bytes, at most `max_bytes` of them
/// (decompressed): a longer file is an [`Error::LimitExceeded`] for `option`, read no further.
pub(crate) fn read_all(path: &Path, max_bytes: u64, option: &'static str) -> Result<Vec<u8>> {
    let io_err = |e| Error::io(path.display(), e);
    let mut reader = open(path)?;
    let mut out = Vec::new();
    // at most `max_bytes` into memory, then one byte more tells a larger file
    (&mut reader)
        .take(max_bytes)
        .read_to_end(&mut out)
        .map_err(io_err)?;
    if out.len() as u64 == max_bytes && reader.read(&mut [0u8]).map_err(io_err)? > 0 {
        return Err(LimitHit {
            line: None,
            option,
            limit: max_bytes,
            what: "decompressed size in bytes",
        }
        .to_error(path.display()));
    }
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
