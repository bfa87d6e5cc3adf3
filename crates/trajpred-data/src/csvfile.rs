//! A plain CSV trajectory for users' own data: a header naming the columns, then one point
//! per row; gzip-compressed files are read transparently. [`load_file`] reads one file,
//! [`load_path`] a file or every `*.csv`/`*.csv.gz` file of a folder.
//!
//! Accepted headers (case-insensitive, any column order, extra columns ignored):
//! - `t,x,y[,z]`: time and metres, returned as they are ([`Frame::Cartesian`](crate::Frame::Cartesian));
//! - `t,lat,lon[,alt]` (also `time`/`timestamp`/`datetime`, `latitude`,
//!   `lon`/`lng`/`longitude`, `altitude`): time, degrees and metres, projected like every
//!   geodetic loader;
//! - optionally a track column, the first of [`ID_COLUMNS`] present (`track`, `track_id`,
//!   `trajectory`, `trajectory_id`, `traj_id`, `id`).
//!
//! **Tracks.** Without a track column a file is one trajectory, id the file's stem. With one,
//! the rows of each distinct value are one trajectory, id `<file stem>/<value>`, in order of
//! the value's first appearance; its rows need not be contiguous (they are gathered, in file
//! order). Either may then be split at gaps (`#k` appended). [`Track::group`] is the id
//! without the `#k`: the file stem, or `<file stem>/<value>`. A row with an empty track value
//! is a [`SkipReason::MissingValue`].
//!
//! **Time units**, detected per file and listed by [`LoadReport::time_units`]: plain numbers
//! are seconds ([`TimeUnit::Seconds`], taken as given); numbers of magnitude at least
//! [`EPOCH_MILLIS_MIN`] (1e11) are milliseconds since the Unix epoch
//! ([`TimeUnit::EpochMillis`], divided by 1000); ISO 8601 date-times
//! (`2008-10-23T02:53:04Z`, a space for the `T`, optional fraction, optional `Z` or UTC
//! offset; see [`crate::time::parse_iso8601`]) become seconds since the epoch
//! ([`TimeUnit::Iso8601`]). Every readable time value of a file must be of the unit of the
//! first: a column mixing units is an [`Error::Parse`] at the first line that disagrees
//! (even out of strict mode: its times cannot be put on one axis).
//!
//! **Rows.** An empty time or coordinate field is [`SkipReason::MissingValue`]; a row with a
//! byte sequence that is not UTF-8 in any field ("not UTF-8"), a time that is neither a
//! number nor a date-time, or a coordinate that is not a number is
//! [`SkipReason::Malformed`] (an [`Error::Parse`] naming the line in strict mode); `nan` or
//! `inf` as a coordinate is a [`SkipReason::InvalidCoordinate`]. Then the shared cleaning
//! (see [`crate::track`] and `docs/data.md`): points out of time order, repeated timestamps
//! and time outliers are dropped and counted.
//!
//! ```
//! use trajpred_data::{csvfile, Frame, LoadOptions, SkipReason, TimeUnit};
//! let f = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/csv/xy.csv");
//! let (tracks, report) = csvfile::load_file(f.as_ref(), &LoadOptions::default())?;
//! assert_eq!(tracks[0].frame, Frame::Cartesian);
//! assert_eq!(tracks[0].trajectory.axis(0), &[0.0, 1.0, 2.5, 4.0]);
//! assert_eq!(report.skipped_total(), 2);
//! assert_eq!(report.time_units()[0].1, TimeUnit::Seconds);
//!
//! // two interleaved vehicles, ISO 8601 times
//! let f = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/csv/vehicles_iso.csv");
//! let (tracks, report) = csvfile::load_path(f.as_ref(), &LoadOptions::default())?;
//! let ids: Vec<&str> = tracks.iter().map(|t| t.id.as_str()).collect();
//! assert_eq!(ids, ["vehicles_iso/bus-12", "vehicles_iso/bus-7"]);
//! assert_eq!(tracks[0].group, "vehicles_iso/bus-12");
//! assert_eq!(report.time_units()[0].1, TimeUnit::Iso8601);
//! assert_eq!(tracks[0].trajectory.times()[0], 1_224_730_384.0); // 2008-10-23T02:53:04Z
//! assert_eq!(report.skipped(SkipReason::TimeOutlier), 0);
//! # Ok::<(), trajpred_data::Error>(())
//! ```

use crate::error::{Error, LimitHit, Result};
use crate::io::{list, open, stem};
use crate::report::{LoadReport, SkipReason};
use crate::time::{TimeUnit, parse_iso8601};
use crate::track::{Cleaner, FrameKind, LoadOptions, RawPoint, Track, num};
use std::collections::{HashMap, VecDeque};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Numbers of at least this magnitude in a time column are epoch milliseconds (1e11 ms is
/// 1973-03-03; 1e11 s would be the year 5138).
pub const EPOCH_MILLIS_MIN: f64 = 1.0e11;

/// The names of the optional track column, by priority (the first present is used).
pub const ID_COLUMNS: [&str; 6] = [
    "track",
    "track_id",
    "trajectory",
    "trajectory_id",
    "traj_id",
    "id",
];

#[derive(Debug, Clone, Copy)]
struct Columns {
    t: usize,
    a: usize,
    b: usize,
    alt: Option<usize>,
    id: Option<usize>,
    kind: FrameKind,
}

fn columns(header: &csv::ByteRecord, file: &str) -> Result<Columns> {
    let names: Vec<String> = header
        .iter()
        .map(|f| String::from_utf8_lossy(f).trim().to_ascii_lowercase())
        .collect();
    let find = |alts: &[&str]| names.iter().position(|n| alts.contains(&n.as_str()));
    let t = find(&["t", "time", "timestamp", "datetime"]);
    let (x, y, z) = (find(&["x"]), find(&["y"]), find(&["z"]));
    let (lat, lon) = (
        find(&["lat", "latitude"]),
        find(&["lon", "lng", "longitude"]),
    );
    let alt = find(&["alt", "altitude"]);
    let id = ID_COLUMNS
        .iter()
        .find_map(|want| names.iter().position(|n| n == want));
    match (t, x, y, lat, lon) {
        (Some(t), Some(a), Some(b), None, None) => Ok(Columns {
            t,
            a,
            b,
            alt: z,
            id,
            kind: FrameKind::Cartesian,
        }),
        (Some(t), None, None, Some(a), Some(b)) => Ok(Columns {
            t,
            a,
            b,
            alt,
            id,
            kind: FrameKind::Geodetic,
        }),
        _ => Err(Error::parse(
            file,
            1,
            format!(
                "header must name t,x,y[,z] or t,lat,lon[,alt] (and optionally track or id); \
                 got {names:?}"
            ),
        )),
    }
}

/// A time field in seconds since the epoch (or as given, for plain seconds), with its unit:
/// a number (epoch milliseconds from a magnitude of [`EPOCH_MILLIS_MIN`]) or an ISO 8601
/// date-time.
fn time_value(s: &str) -> Option<(f64, TimeUnit)> {
    match num(s) {
        Some(v) if v.abs() >= EPOCH_MILLIS_MIN => Some((v / 1000.0, TimeUnit::EpochMillis)),
        Some(v) => Some((v, TimeUnit::Seconds)),
        None => parse_iso8601(s).map(|t| (t, TimeUnit::Iso8601)),
    }
}

/// A coordinate field: any `f64` including `nan` and `inf`, which the cleaning then counts as
/// [`SkipReason::InvalidCoordinate`] (never kept).
fn coordinate(s: &str) -> Option<f64> {
    s.parse::<f64>().ok()
}

/// A reader that remembers where the line ends are, so a record's line number counts the
/// empty lines the CSV parser skips (its own positions do not), and that enforces
/// [`LoadOptions::max_line_bytes`] and [`LoadOptions::max_file_bytes`] on the bytes it passes.
struct LineTracker<R> {
    inner: R,
    /// Bytes read so far.
    offset: u64,
    /// The offsets and bytes (`\r` or `\n`) of the line-end bytes not yet passed.
    ends: VecDeque<(u64, u8)>,
    /// `\n` bytes passed (before the current record).
    newlines_passed: usize,
    /// `\n` bytes read in all, and the last byte read.
    newlines_total: usize,
    last_byte: Option<u8>,
    /// Bytes of the current line so far (line ends excluded), and the limits.
    line_len: usize,
    max_line: usize,
    max_bytes: u64,
}

impl<R: Read> Read for LineTracker<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if self.offset.saturating_add(n as u64) > self.max_bytes {
            return Err(LimitHit {
                line: Some(self.newlines_total + 1),
                option: "max_file_bytes",
                limit: self.max_bytes,
                what: "decompressed size in bytes",
            }
            .into_io());
        }
        for (i, &b) in buf.iter().take(n).enumerate() {
            if b == b'\n' || b == b'\r' {
                self.ends.push_back((self.offset + i as u64, b));
                if b == b'\n' {
                    self.newlines_total += 1;
                    self.line_len = 0;
                }
            } else {
                self.line_len += 1;
                if self.line_len > self.max_line {
                    return Err(LimitHit {
                        line: Some(self.newlines_total + 1),
                        option: "max_line_bytes",
                        limit: self.max_line as u64,
                        what: "line length in bytes",
                    }
                    .into_io());
                }
            }
        }
        if n > 0 {
            self.last_byte = buf.get(n - 1).copied();
        }
        self.offset += n as u64;
        Ok(n)
    }
}

impl<R> LineTracker<R> {
    fn new(inner: R, opts: &LoadOptions) -> Self {
        LineTracker {
            inner,
            offset: 0,
            ends: VecDeque::new(),
            newlines_passed: 0,
            newlines_total: 0,
            last_byte: None,
            line_len: 0,
            max_line: opts.max_line_bytes,
            max_bytes: opts.max_file_bytes,
        }
    }

    /// The 1-based line of a record read after byte `after` (the end of the previous
    /// record): the line-end bytes right after `after` are the empty lines skipped before
    /// the record.
    fn line_of_record_after(&mut self, after: u64) -> usize {
        let mut next = after;
        while let Some(&(at, b)) = self.ends.front() {
            if at < after || at == next {
                if at == next {
                    next += 1;
                }
                self.newlines_passed += usize::from(b == b'\n');
                self.ends.pop_front();
            } else {
                break;
            }
        }
        self.newlines_passed + 1
    }

    /// The number of lines of the whole input (once read to its end).
    fn total_lines(&self) -> usize {
        match self.last_byte {
            None => 0,
            Some(b'\n') => self.newlines_total,
            Some(_) => self.newlines_total + 1,
        }
    }
}

/// Parses one CSV stream named `file` (track ids from `file`'s stem), adding to `report`.
///
/// A missing or unrecognised header is an [`Error::Parse`] at line 1; a time column mixing
/// units is an [`Error::Parse`] at the first line that disagrees with the first time value.
pub fn parse<R: Read>(
    reader: R,
    file: &str,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<Vec<Track>> {
    opts.validate()?;
    report.files_read += 1;
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(LineTracker::new(reader, opts));
    // the last line of the previous record, to count the empty lines between records
    let mut previous_end = 0usize;
    let mut rec = csv::ByteRecord::new();
    let mut cols: Option<Columns> = None;
    // the unit of the first time value read, and its line
    let mut unit: Option<(TimeUnit, usize)> = None;
    // the points of each track value, in order of first appearance
    let mut groups: Vec<(String, Vec<RawPoint>)> = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    let mut c = Cleaner::new(opts, file, report);
    loop {
        let more = match rdr.read_byte_record(&mut rec) {
            Ok(m) => m,
            Err(e) => {
                let after = e.position().map_or(0, csv::Position::byte);
                let line = rdr.get_mut().line_of_record_after(after);
                return Err(match e.into_kind() {
                    csv::ErrorKind::Io(io) => Error::io(file, io),
                    other => Error::parse(file, line, format!("{other:?}")),
                });
            }
        };
        if !more {
            let total = rdr.get_ref().total_lines();
            c.report.blank_lines += total.saturating_sub(previous_end);
            break;
        }
        let after = rec.position().map_or(0, csv::Position::byte);
        let line = rdr.get_mut().line_of_record_after(after);
        c.report.blank_lines += line.saturating_sub(previous_end + 1);
        // quoted fields may hold line ends: the record ends that many lines further
        previous_end = line
            + rec
                .iter()
                .map(|f| f.iter().filter(|&&b| b == b'\n').count())
                .sum::<usize>();
        if rec.iter().all(|f| f.iter().all(u8::is_ascii_whitespace)) {
            c.report.blank_lines += 1;
            continue;
        }
        let Some(cl) = cols else {
            c.report.header_lines += 1;
            cols = Some(columns(&rec, file)?);
            continue;
        };
        c.report.records_read += 1;
        // every field, used or not, must be UTF-8
        if rec.iter().any(|f| std::str::from_utf8(f).is_err()) {
            c.malformed(line, "not UTF-8")?;
            continue;
        }
        let field = |i: usize| {
            std::str::from_utf8(rec.get(i).unwrap_or(b""))
                .unwrap_or("")
                .trim()
        };
        let (t, a, b) = (field(cl.t), field(cl.a), field(cl.b));
        if t.is_empty() || a.is_empty() || b.is_empty() {
            c.report
                .skip(file, line, SkipReason::MissingValue, "empty field");
            continue;
        }
        let slot = match cl.id.map(field) {
            None => 0,
            Some("") => {
                c.report
                    .skip(file, line, SkipReason::MissingValue, "empty track id");
                continue;
            }
            Some(id) => match index.get(id) {
                Some(&k) => k,
                None => {
                    index.insert(id.to_string(), groups.len());
                    groups.push((id.to_string(), Vec::new()));
                    groups.len() - 1
                }
            },
        };
        let Some((t, u)) = time_value(t) else {
            c.malformed(
                line,
                format!("time {t:?} is neither a number nor an ISO 8601 date-time"),
            )?;
            continue;
        };
        match unit {
            None => unit = Some((u, line)),
            Some((first, first_line)) if first != u => {
                return Err(Error::parse(
                    file,
                    line,
                    format!(
                        "the time column mixes units: {u} here, {first} from line {first_line} \
                         (field {:?})",
                        field(cl.t)
                    ),
                ));
            }
            Some(_) => {}
        }
        let (Some(a), Some(b)) = (coordinate(a), coordinate(b)) else {
            c.malformed(line, format!("not numbers: {a:?}, {b:?}"))?;
            continue;
        };
        let alt = match cl.alt.map(field) {
            None | Some("") => None,
            Some(s) => match coordinate(s) {
                Some(v) => Some(v),
                None => {
                    c.malformed(line, format!("altitude {s:?} is not a number"))?;
                    continue;
                }
            },
        };
        let p = RawPoint { line, t, a, b, alt };
        let keep = match cl.kind {
            FrameKind::Geodetic => c.accept_geodetic(&p)?,
            FrameKind::Cartesian => c.accept_cartesian(&p)?,
        };
        if keep {
            if groups.is_empty() {
                groups.push((String::new(), Vec::new()));
            }
            if let Some((_, points)) = groups.get_mut(slot) {
                c.hold(line, points.len())?;
                points.push(p);
            }
        }
    }
    let Some(cl) = cols else {
        return Err(Error::parse(file, 1, "no header"));
    };
    if let Some((u, _)) = unit {
        c.report.record_time_unit(file, u);
    }
    let file_stem = stem(Path::new(file));
    let mut out = Vec::new();
    match cl.id {
        None => {
            c.report.groups += 1;
            let points = groups.pop().map(|(_, p)| p).unwrap_or_default();
            c.finish(&file_stem, &file_stem, points, cl.kind, &mut out)?;
        }
        Some(_) => {
            c.report.groups += groups.len();
            for (value, points) in groups {
                let id = format!("{file_stem}/{value}");
                c.finish(&id, &id, points, cl.kind, &mut out)?;
            }
        }
    }
    Ok(out)
}

/// Loads one CSV file (gzip detected by its magic bytes).
pub fn load_file(path: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    let mut report = LoadReport::new();
    let tracks = parse(open(path)?, &path.display().to_string(), opts, &mut report)?;
    Ok((tracks, report))
}

/// The `*.csv` and `*.csv.gz` files of a folder (names compared case-insensitively; not
/// recursive), sorted by name. Possibly empty.
pub fn files(dir: &Path) -> Result<Vec<PathBuf>> {
    list(dir, |p| {
        let name = p
            .file_name()
            .map(|s| s.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        p.is_file() && (name.ends_with(".csv") || name.ends_with(".csv.gz"))
    })
}

/// Loads a CSV file, or every file of [`files`]`(path)` when `path` is a folder, one after
/// the other (the report adds them up; [`LoadOptions::max_total_points`] bounds the points
/// of them all). A folder without a CSV file is an [`Error::Layout`] naming it.
pub fn load_path(path: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    if !path.is_dir() {
        return load_file(path, opts);
    }
    let found = files(path)?;
    if found.is_empty() {
        return Err(Error::Layout {
            path: path.display().to_string(),
            reason: "no *.csv or *.csv.gz file in this folder".to_string(),
        });
    }
    let mut tracks = Vec::new();
    let mut report = LoadReport::new();
    for f in found {
        tracks.extend(parse(
            open(&f)?,
            &f.display().to_string(),
            opts,
            &mut report,
        )?);
    }
    Ok((tracks, report))
}
