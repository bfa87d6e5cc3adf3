//! GeoLife 1.3 (Microsoft Research): `.plt` trajectories and `labels.txt` transport modes.
//!
//! A `.plt` file has 6 header lines, then `lat,lon,0,alt_ft,days,date,time` per line
//! (CRLF line ends; altitude in feet, -777 = unknown; date and time in UTC). Each file is
//! one trajectory; the timestamp is taken from the date and time fields. Malformed lines are
//! skipped and counted ([`SkipReason::Malformed`](crate::report::SkipReason::Malformed)), or
//! fail in strict mode.
//!
//! Streaming: [`user_dirs`] lists the users; [`load_user`] loads one user's folder,
//! [`load_plt`] one file, so memory stays bounded; [`load_data_dir`] loads everything.
//! [`user_dirs`] and [`load_data_dir`] take the dataset's root (`geolife/`) or its `Data/`
//! folder alike.
//!
//! A track's id is `<user>/<file stem>` (`#k` appended for the k-th segment after a gap) and
//! its [`Track::group`] is the user, so data can be split by user.
//!
//! ```
//! use trajpred_data::{geolife, LoadOptions, SkipReason};
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/geolife/Data/000");
//! let (tracks, report) = geolife::load_user(dir.as_ref(), &LoadOptions::geolife())?;
//! assert_eq!(tracks.len(), 2);
//! assert_eq!(report.skipped(SkipReason::RepeatedTimestamp), 1);
//! assert_eq!(report.skipped(SkipReason::Malformed), 3);
//! # Ok::<(), trajpred_data::Error>(())
//! ```

use crate::error::Result;
use crate::geodesy::FOOT;
use crate::io::{for_each_line, list, open, stem};
use crate::report::LoadReport;
use crate::time::{parse_date_time, parse_datetime};
use crate::track::{Cleaner, FrameKind, LoadOptions, RawPoint, Track, fields, num};
use std::io::BufRead;
use std::path::{Path, PathBuf};

/// Lines of the fixed `.plt` header.
pub const HEADER_LINES: usize = 6;
/// GeoLife's "unknown altitude" value (feet).
pub const UNKNOWN_ALTITUDE_FT: f64 = -777.0;

/// Parses one `.plt` stream named `file` into the tracks of trajectory `id`, adding to
/// `report`. The tracks' [`Track::group`] is `id` up to its first `/` (the user, for the
/// `user/stem` ids of [`load_plt`]), or all of `id`.
pub fn parse_plt<R: BufRead>(
    reader: R,
    file: &str,
    id: &str,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<Vec<Track>> {
    opts.validate()?;
    report.files_read += 1;
    report.groups += 1;
    let mut points = Vec::new();
    let mut c = Cleaner::new(opts, file, report);
    for_each_line(reader, file, opts, |line, text| {
        if line <= HEADER_LINES {
            c.report.header_lines += 1;
            return Ok(());
        }
        let Some(text) = text else {
            c.report.records_read += 1;
            return c.malformed(line, "invalid UTF-8");
        };
        if text.trim_ascii().is_empty() {
            c.report.blank_lines += 1;
            return Ok(());
        }
        c.report.records_read += 1;
        match parse_plt_line(text, line) {
            Ok(p) => {
                if c.accept_geodetic(&p)? {
                    c.hold(line, points.len())?;
                    points.push(p);
                }
                Ok(())
            }
            Err(reason) => c.malformed(line, reason),
        }
    })?;
    let mut out = Vec::new();
    let group = id.split_once('/').map_or(id, |(user, _)| user);
    c.finish(id, group, points, FrameKind::Geodetic, &mut out)?;
    Ok(out)
}

fn parse_plt_line(text: &str, line: usize) -> std::result::Result<RawPoint, String> {
    let f: [&str; 7] = fields(text, b',').map_err(|n| format!("expected 7 fields, got {n}"))?;
    let lat = num(f[0]).ok_or_else(|| format!("latitude {:?} is not a number", f[0]))?;
    let lon = num(f[1]).ok_or_else(|| format!("longitude {:?} is not a number", f[1]))?;
    let alt_ft = num(f[3]).ok_or_else(|| format!("altitude {:?} is not a number", f[3]))?;
    let t = parse_date_time(f[5], f[6])
        .ok_or_else(|| format!("bad date/time {:?} {:?}", f[5], f[6]))?;
    Ok(RawPoint {
        line,
        t,
        a: lat,
        b: lon,
        alt: (alt_ft != UNKNOWN_ALTITUDE_FT).then_some(alt_ft * FOOT),
    })
}

/// Loads one `.plt` file; the id is `user/stem` (the user being the folder above
/// `Trajectory/`).
pub fn load_plt(path: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    let mut report = LoadReport::new();
    let tracks = load_plt_into(path, opts, &mut report)?;
    Ok((tracks, report))
}

/// [`load_plt`] adding to `report` (whose kept points count towards
/// [`LoadOptions::max_total_points`]).
fn load_plt_into(path: &Path, opts: &LoadOptions, report: &mut LoadReport) -> Result<Vec<Track>> {
    let user = path
        .parent()
        .and_then(Path::parent)
        .and_then(Path::file_name)
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let id = format!("{user}/{}", stem(path));
    let name = path.display().to_string();
    parse_plt(open(path)?, &name, &id, opts, report)
}

/// The `.plt` files of one user folder (`<user>/Trajectory/*.plt`), sorted.
pub fn plt_files(user_dir: &Path) -> Result<Vec<PathBuf>> {
    list(&user_dir.join("Trajectory"), |p| {
        p.extension().is_some_and(|e| e.eq_ignore_ascii_case("plt"))
    })
}

/// Loads every trajectory of one user folder; [`LoadOptions::max_total_points`] bounds the
/// points of the whole folder.
pub fn load_user(user_dir: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    let mut report = LoadReport::new();
    let tracks = load_user_into(user_dir, opts, &mut report)?;
    Ok((tracks, report))
}

fn load_user_into(
    user_dir: &Path,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<Vec<Track>> {
    let mut tracks = Vec::new();
    for f in plt_files(user_dir)? {
        tracks.extend(load_plt_into(&f, opts, report)?);
    }
    Ok(tracks)
}

/// The user folders (those holding a `Trajectory/` folder) of a GeoLife `Data/` folder, or
/// of the dataset's root holding it (`geolife/Data/<user>/Trajectory/*.plt`), sorted.
pub fn user_dirs(data_dir: &Path) -> Result<Vec<PathBuf>> {
    let dir = if data_dir.join("Data").is_dir() {
        data_dir.join("Data")
    } else {
        data_dir.to_path_buf()
    };
    list(&dir, |p| p.join("Trajectory").is_dir())
}

/// Loads every user of a GeoLife `Data/` folder or of the dataset's root (see
/// [`user_dirs`]); [`LoadOptions::max_total_points`] bounds the points of the whole load.
pub fn load_data_dir(data_dir: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    let mut tracks = Vec::new();
    let mut report = LoadReport::new();
    for u in user_dirs(data_dir)? {
        tracks.extend(load_user_into(&u, opts, &mut report)?);
    }
    Ok((tracks, report))
}

/// One row of `labels.txt`: a transport mode over a time span (seconds since the epoch,
/// UTC).
#[derive(Debug, Clone, PartialEq)]
pub struct Label {
    /// Start of the span.
    pub start: f64,
    /// End of the span.
    pub end: f64,
    /// The mode as written (`bus`, `walk`, `subway`, ...).
    pub mode: String,
}

/// Parses a `labels.txt` stream (`Start Time<TAB>End Time<TAB>Transportation Mode`, a header
/// line, dates `YYYY/MM/DD HH:MM:SS`). Malformed rows and rows whose end precedes their start
/// are skipped and counted as malformed (or fail in strict mode).
pub fn parse_labels<R: BufRead>(
    reader: R,
    file: &str,
    strict: bool,
) -> Result<(Vec<Label>, LoadReport)> {
    let opts = LoadOptions {
        strict,
        ..LoadOptions::default()
    };
    let mut report = LoadReport::new();
    report.files_read += 1;
    let mut labels = Vec::new();
    let mut c = Cleaner::new(&opts, file, &mut report);
    for_each_line(reader, file, &opts, |line, text| {
        if line == 1 {
            c.report.header_lines += 1;
            return Ok(());
        }
        let Some(text) = text else {
            c.report.records_read += 1;
            return c.malformed(line, "invalid UTF-8");
        };
        if text.trim_ascii().is_empty() {
            c.report.blank_lines += 1;
            return Ok(());
        }
        c.report.records_read += 1;
        let f: Vec<&str> = text.split('\t').collect();
        if f.len() != 3 {
            return c.malformed(
                line,
                format!("expected 3 tab-separated fields, got {}", f.len()),
            );
        }
        match (parse_datetime(f[0]), parse_datetime(f[1])) {
            (Some(start), Some(end)) if end >= start && !f[2].trim().is_empty() => {
                c.hold(line, labels.len())?;
                c.release(1);
                c.report.points_kept += 1;
                labels.push(Label {
                    start,
                    end,
                    mode: f[2].trim().to_string(),
                });
                Ok(())
            }
            _ => c.malformed(line, format!("bad span or mode: {text:?}")),
        }
    })?;
    Ok((labels, report))
}

/// Loads a user's `labels.txt`.
pub fn load_labels(path: &Path, strict: bool) -> Result<(Vec<Label>, LoadReport)> {
    parse_labels(open(path)?, &path.display().to_string(), strict)
}

/// The mode of the first label whose span contains `t` (bounds inclusive), if any.
pub fn mode_at(labels: &[Label], t: f64) -> Option<&str> {
    labels
        .iter()
        .find(|l| l.start <= t && t <= l.end)
        .map(|l| l.mode.as_str())
}
