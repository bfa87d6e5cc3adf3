//! T-Drive (Microsoft Research) taxi logs: `taxi_id,YYYY-MM-DD HH:MM:SS,lon,lat`, one file
//! per taxi, no header.
//!
//! Cleaning, in this order per line: an exact copy of the previous line is dropped
//! ([`SkipReason::DuplicateLine`]); malformed lines and
//! lines of another taxi are dropped; positions at (0, 0) and outside the bounding box
//! ([`LoadOptions::tdrive`] uses [`BoundingBox::BEIJING`](crate::BoundingBox::BEIJING)) are
//! dropped; then the shared time rule (first of equal timestamps kept) and the split at gaps
//! longer than [`LoadOptions::max_gap`]. The times (most likely Beijing local time) are read
//! as if UTC.
//!
//! [`load_dir`] and [`files`] take the dataset's root (`tdrive/`, holding
//! `taxi_log_2008_by_id/`) or the folder of the taxi files itself. A track's id is the taxi
//! id (`#k` appended for the k-th segment after a gap), and [`Track::group`] is the taxi id.
//!
//! ```
//! use trajpred_data::{tdrive, LoadOptions, SkipReason};
//! let f = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/tdrive/7.txt");
//! let (tracks, report) = tdrive::load_file(f.as_ref(), &LoadOptions::tdrive())?;
//! assert_eq!(report.skipped(SkipReason::DuplicateLine), 1);
//! assert_eq!(report.skipped(SkipReason::ZeroPosition), 1);
//! assert_eq!(tracks.len(), 2); // split at the 2-hour gap
//! # Ok::<(), trajpred_data::Error>(())
//! ```

use crate::error::Result;
use crate::io::{for_each_line, list, open, stem};
use crate::report::{LoadReport, SkipReason};
use crate::time::parse_datetime;
use crate::track::{Cleaner, FrameKind, LoadOptions, RawPoint, Track, fields, num};
use std::io::BufRead;
use std::path::{Path, PathBuf};

/// Parses one taxi's log named `file`, adding to `report`. The track id is the taxi id of the
/// first well-formed line (or `file`'s stem when there is none).
pub fn parse<R: BufRead>(
    reader: R,
    file: &str,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<Vec<Track>> {
    opts.validate()?;
    report.files_read += 1;
    report.groups += 1;
    let mut points = Vec::new();
    let mut taxi: Option<String> = None;
    // the previous line, for the duplicate check (`None` after an undecodable line)
    let mut previous = String::new();
    let mut have_previous = false;
    let mut c = Cleaner::new(opts, file, report);
    for_each_line(reader, file, opts, |line, text| {
        let Some(text) = text else {
            c.report.records_read += 1;
            have_previous = false;
            return c.malformed(line, "invalid UTF-8");
        };
        if text.trim_ascii().is_empty() {
            c.report.blank_lines += 1;
            return Ok(());
        }
        c.report.records_read += 1;
        if have_previous && previous == text {
            c.report.skip(file, line, SkipReason::DuplicateLine, "");
            return Ok(());
        }
        previous.clear();
        previous.push_str(text);
        have_previous = true;
        let f: [&str; 4] = match fields(text, b',') {
            Ok(f) => f,
            Err(n) => return c.malformed(line, format!("expected 4 fields, got {n}")),
        };
        let id = f[0].trim_ascii();
        if id.is_empty() {
            return c.malformed(line, "empty taxi id");
        }
        let Some(t) = parse_datetime(f[1]) else {
            return c.malformed(line, format!("bad date/time {:?}", f[1]));
        };
        let (Some(lon), Some(lat)) = (num(f[2]), num(f[3])) else {
            return c.malformed(line, format!("bad lon/lat {:?} {:?}", f[2], f[3]));
        };
        match &taxi {
            Some(first) if first != id => {
                c.report.skip(
                    file,
                    line,
                    SkipReason::ForeignId,
                    format!("taxi {id}, expected {first}"),
                );
                return Ok(());
            }
            None => taxi = Some(id.to_string()),
            _ => {}
        }
        let p = RawPoint {
            line,
            t,
            a: lat,
            b: lon,
            alt: None,
        };
        if c.accept_geodetic(&p)? {
            c.hold(line, points.len())?;
            points.push(p);
        }
        Ok(())
    })?;
    let id = taxi.unwrap_or_else(|| stem(Path::new(file)));
    let mut out = Vec::new();
    c.finish(&id, &id, points, FrameKind::Geodetic, &mut out)?;
    Ok(out)
}

/// Loads one taxi file.
pub fn load_file(path: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    let mut report = LoadReport::new();
    let tracks = parse(open(path)?, &path.display().to_string(), opts, &mut report)?;
    Ok((tracks, report))
}

/// The folder of the taxi files inside the dataset's root folder.
pub const INNER_DIR: &str = "taxi_log_2008_by_id";

/// The `.txt` files of a T-Drive folder, sorted by taxi id (numerically where the stem is a
/// number). `dir` is either the folder of the taxi files or the dataset's root holding it as
/// [`INNER_DIR`] (`tdrive/taxi_log_2008_by_id/*.txt`), which is then listed instead.
pub fn files(dir: &Path) -> Result<Vec<PathBuf>> {
    let inner = dir.join(INNER_DIR);
    let dir = if inner.is_dir() { &inner } else { dir };
    let mut v = list(dir, |p| {
        p.is_file() && p.extension().is_some_and(|e| e.eq_ignore_ascii_case("txt"))
    })?;
    v.sort_by_key(|p| (stem(p).parse::<u64>().unwrap_or(u64::MAX), p.clone()));
    Ok(v)
}

/// Loads every taxi file of a folder, or of the dataset's root folder (see [`files`]);
/// [`LoadOptions::max_total_points`] bounds the points of the whole folder.
pub fn load_dir(dir: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    let mut tracks = Vec::new();
    let mut report = LoadReport::new();
    for f in files(dir)? {
        tracks.extend(parse(
            open(&f)?,
            &f.display().to_string(),
            opts,
            &mut report,
        )?);
    }
    Ok((tracks, report))
}
