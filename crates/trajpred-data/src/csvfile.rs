//! A plain CSV trajectory for users' own data: a header naming the columns, then one point
//! per row; gzip-compressed files are read transparently.
//!
//! Accepted headers (case-insensitive, any column order, extra columns ignored):
//! - `t,x,y[,z]`: seconds and metres, returned as they are ([`Frame::Cartesian`](crate::Frame::Cartesian));
//! - `t,lat,lon[,alt]` (also `time`/`timestamp`, `latitude`, `lon`/`lng`/`longitude`,
//!   `altitude`): seconds, degrees and metres, projected like every geodetic loader.
//!
//! A file is one trajectory (split at gaps if asked). An empty field is a missing value; a
//! field that is not a number is malformed.
//!
//! ```
//! use trajpred_data::{csvfile, Frame, LoadOptions};
//! let f = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/csv/xy.csv");
//! let (tracks, report) = csvfile::load_file(f.as_ref(), &LoadOptions::default())?;
//! assert_eq!(tracks[0].frame, Frame::Cartesian);
//! assert_eq!(tracks[0].trajectory.axis(0), &[0.0, 1.0, 2.5, 4.0]);
//! assert_eq!(report.skipped_total(), 2);
//! # Ok::<(), trajpred_data::Error>(())
//! ```

use crate::error::{Error, Result};
use crate::io::{open, stem};
use crate::report::{LoadReport, SkipReason};
use crate::track::{Cleaner, FrameKind, LoadOptions, RawPoint, Track, num};
use std::io::Read;
use std::path::Path;

#[derive(Debug, Clone, Copy)]
struct Columns {
    t: usize,
    a: usize,
    b: usize,
    alt: Option<usize>,
    kind: FrameKind,
}

fn columns(header: &csv::ByteRecord, file: &str) -> Result<Columns> {
    let names: Vec<String> = header
        .iter()
        .map(|f| String::from_utf8_lossy(f).trim().to_ascii_lowercase())
        .collect();
    let find = |alts: &[&str]| names.iter().position(|n| alts.contains(&n.as_str()));
    let t = find(&["t", "time", "timestamp"]);
    let (x, y, z) = (find(&["x"]), find(&["y"]), find(&["z"]));
    let (lat, lon) = (
        find(&["lat", "latitude"]),
        find(&["lon", "lng", "longitude"]),
    );
    let alt = find(&["alt", "altitude"]);
    match (t, x, y, lat, lon) {
        (Some(t), Some(a), Some(b), None, None) => Ok(Columns {
            t,
            a,
            b,
            alt: z,
            kind: FrameKind::Cartesian,
        }),
        (Some(t), None, None, Some(a), Some(b)) => Ok(Columns {
            t,
            a,
            b,
            alt,
            kind: FrameKind::Geodetic,
        }),
        _ => Err(Error::parse(
            file,
            1,
            format!("header must name t,x,y[,z] or t,lat,lon[,alt]; got {names:?}"),
        )),
    }
}

/// Parses one CSV stream named `file` (trajectory id: `file`'s stem), adding to `report`.
/// A missing or unrecognised header is an [`Error::Parse`] at line 1.
pub fn parse<R: Read>(
    reader: R,
    file: &str,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<Vec<Track>> {
    opts.validate()?;
    report.files_read += 1;
    report.groups += 1;
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(reader);
    let mut rec = csv::ByteRecord::new();
    let mut cols: Option<Columns> = None;
    let mut points = Vec::new();
    let mut c = Cleaner { opts, file, report };
    loop {
        let more = match rdr.read_byte_record(&mut rec) {
            Ok(m) => m,
            Err(e) => {
                let line = e.position().map_or(0, |p| p.line() as usize);
                return Err(match e.into_kind() {
                    csv::ErrorKind::Io(io) => Error::io(file, io),
                    other => Error::parse(file, line, format!("{other:?}")),
                });
            }
        };
        if !more {
            break;
        }
        let line = rec.position().map_or(0, |p| p.line() as usize);
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
        let field = |i: usize| std::str::from_utf8(rec.get(i).unwrap_or(b"")).map(str::trim);
        let (Ok(t), Ok(a), Ok(b)) = (field(cl.t), field(cl.a), field(cl.b)) else {
            c.malformed(line, "invalid UTF-8")?;
            continue;
        };
        if t.is_empty() || a.is_empty() || b.is_empty() {
            c.report
                .skip(file, line, SkipReason::MissingValue, "empty field");
            continue;
        }
        let (Some(t), Some(a), Some(b)) = (num(t), num(a), num(b)) else {
            c.malformed(line, format!("not numbers: {t:?}, {a:?}, {b:?}"))?;
            continue;
        };
        let alt = match cl.alt.map(field) {
            None => None,
            Some(Ok("")) => None,
            Some(Ok(s)) => match num(s) {
                Some(v) => Some(v),
                None => {
                    c.malformed(line, format!("altitude {s:?} is not a number"))?;
                    continue;
                }
            },
            Some(Err(_)) => {
                c.malformed(line, "invalid UTF-8")?;
                continue;
            }
        };
        let p = RawPoint { line, t, a, b, alt };
        let keep = match cl.kind {
            FrameKind::Geodetic => c.accept_geodetic(&p)?,
            FrameKind::Cartesian => c.accept_cartesian(&p)?,
        };
        if keep {
            points.push(p);
        }
    }
    let Some(cl) = cols else {
        return Err(Error::parse(file, 1, "no header"));
    };
    let mut out = Vec::new();
    let id = stem(Path::new(file));
    c.finish(&id, &id, points, cl.kind, &mut out)?;
    Ok(out)
}

/// Loads one CSV file (gzip detected by its magic bytes).
pub fn load_file(path: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
    let mut report = LoadReport::new();
    let tracks = parse(open(path)?, &path.display().to_string(), opts, &mut report)?;
    Ok((tracks, report))
}
