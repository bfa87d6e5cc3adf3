//! What a loader read and what it skipped, by reason and line.

use crate::time::TimeUnit;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt;

/// Why a line, record or point was not kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub enum SkipReason {
    /// The line or record could not be parsed: wrong number of fields, a value that is not a
    /// number, an impossible date, invalid UTF-8, a JSON value of the wrong type.
    Malformed,
    /// Latitude outside ±90°, longitude outside ±180°, or a non-finite value.
    InvalidCoordinate,
    /// A required value is null or unknown (ADS-B `null`; GeoLife altitude -777 when
    /// altitude is requested).
    MissingValue,
    /// An exact copy of the previous line (T-Drive).
    DuplicateLine,
    /// A position at exactly (0°, 0°): a GPS fix that never happened.
    ZeroPosition,
    /// A position outside the configured bounding box.
    OutsideBounds,
    /// The same timestamp as the previous kept point of the trajectory: the first point of a
    /// run of equal timestamps is kept, the others are dropped (see `docs/data.md`).
    RepeatedTimestamp,
    /// A timestamp earlier than the previous kept point's (dropped).
    TimeBackwards,
    /// A point whose timestamp jumps ahead of the points that follow it (a clock glitch:
    /// the track goes on from before it); the one point is dropped, not the rest (see
    /// `docs/data.md`, the time rule).
    TimeOutlier,
    /// A T-Drive line whose taxi id differs from the first line's id in that file.
    ForeignId,
    /// A point of a segment with fewer than the required number of points (after splitting
    /// at gaps); `line` is the segment's first line.
    ShortSegment,
}

impl SkipReason {
    /// Every reason, in report order.
    pub const ALL: [SkipReason; 11] = [
        SkipReason::Malformed,
        SkipReason::InvalidCoordinate,
        SkipReason::MissingValue,
        SkipReason::DuplicateLine,
        SkipReason::ZeroPosition,
        SkipReason::OutsideBounds,
        SkipReason::RepeatedTimestamp,
        SkipReason::TimeBackwards,
        SkipReason::TimeOutlier,
        SkipReason::ForeignId,
        SkipReason::ShortSegment,
    ];
}

impl fmt::Display for SkipReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            SkipReason::Malformed => "malformed",
            SkipReason::InvalidCoordinate => "invalid coordinate",
            SkipReason::MissingValue => "missing value",
            SkipReason::DuplicateLine => "duplicate line",
            SkipReason::ZeroPosition => "position (0, 0)",
            SkipReason::OutsideBounds => "outside bounding box",
            SkipReason::RepeatedTimestamp => "repeated timestamp",
            SkipReason::TimeBackwards => "time goes backwards",
            SkipReason::TimeOutlier => "time outlier",
            SkipReason::ForeignId => "foreign id",
            SkipReason::ShortSegment => "segment too short",
        };
        f.write_str(s)
    }
}

/// One skipped line or point.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Skip {
    /// The file (or the name given to in-memory input).
    pub file: String,
    /// 1-based line number; for JSON, the 1-based record index (row index + 1 in the
    /// column-wise layout).
    pub line: usize,
    /// Why.
    pub reason: SkipReason,
    /// Detail for malformed input (the parser's message); empty otherwise.
    pub detail: String,
}

/// How many skips of each reason are kept with their line numbers; the counts are always
/// exact.
pub const MAX_DETAILS_PER_REASON: usize = 1000;

/// What one or more loads read and skipped.
///
/// Invariant: `records_read == points_kept + skipped_total()`, where a record is a data line
/// of a text format or a record (row) of a JSON file.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct LoadReport {
    /// Files read.
    pub files_read: usize,
    /// Data lines or JSON records read (headers and blank lines excluded).
    pub records_read: usize,
    /// Header lines read (GeoLife's six, a CSV header).
    pub header_lines: usize,
    /// Empty lines (ignored; not records).
    pub blank_lines: usize,
    /// Points in the returned trajectories.
    pub points_kept: usize,
    /// Trajectories returned.
    pub trajectories: usize,
    /// Groups before cleaning and splitting at gaps: one per file for GeoLife and T-Drive;
    /// for CSV, one per file, or one per distinct value of its track/id column; for ADS-B,
    /// the distinct (icao24, callsign[, flight_id]) keys of each file's records.
    pub groups: usize,
    skipped: BTreeMap<SkipReason, usize>,
    details: Vec<Skip>,
    time_units: Vec<(String, TimeUnit)>,
}

impl LoadReport {
    /// An empty report.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records one skip.
    pub fn skip(&mut self, file: &str, line: usize, reason: SkipReason, detail: impl Into<String>) {
        self.skip_many(file, line, reason, 1, detail);
    }

    /// Records `count` skipped points of one reason at one line.
    pub fn skip_many(
        &mut self,
        file: &str,
        line: usize,
        reason: SkipReason,
        count: usize,
        detail: impl Into<String>,
    ) {
        let n = self.skipped.entry(reason).or_insert(0);
        if *n < MAX_DETAILS_PER_REASON {
            self.details.push(Skip {
                file: file.to_string(),
                line,
                reason,
                detail: detail.into(),
            });
        }
        *n += count;
    }

    /// How many were skipped for `reason`.
    pub fn skipped(&self, reason: SkipReason) -> usize {
        self.skipped.get(&reason).copied().unwrap_or(0)
    }

    /// How many were skipped in all.
    pub fn skipped_total(&self) -> usize {
        self.skipped.values().sum()
    }

    /// Counts by reason, reasons with no skip left out.
    pub fn skipped_by_reason(&self) -> impl Iterator<Item = (SkipReason, usize)> + '_ {
        self.skipped.iter().map(|(r, n)| (*r, *n))
    }

    /// The skips with their files and lines (the first [`MAX_DETAILS_PER_REASON`] of each
    /// reason, in the order they happened).
    pub fn skips(&self) -> &[Skip] {
        &self.details
    }

    /// Records the time unit detected in `file` (CSV).
    pub fn record_time_unit(&mut self, file: &str, unit: TimeUnit) {
        self.time_units.push((file.to_string(), unit));
    }

    /// The time unit detected in each CSV file read, in reading order. A file without a
    /// single readable time value has no entry; the other formats have fixed units and no
    /// entries.
    pub fn time_units(&self) -> &[(String, TimeUnit)] {
        &self.time_units
    }

    /// Adds `other`'s counts and details to this report.
    pub fn merge(&mut self, other: LoadReport) {
        self.time_units.extend(other.time_units);
        self.files_read += other.files_read;
        self.records_read += other.records_read;
        self.header_lines += other.header_lines;
        self.blank_lines += other.blank_lines;
        self.points_kept += other.points_kept;
        self.trajectories += other.trajectories;
        self.groups += other.groups;
        // details stored per reason = min(count, MAX_DETAILS_PER_REASON)
        let mut stored: BTreeMap<SkipReason, usize> = self
            .skipped
            .iter()
            .map(|(r, n)| (*r, (*n).min(MAX_DETAILS_PER_REASON)))
            .collect();
        for d in other.details {
            let have = stored.entry(d.reason).or_insert(0);
            if *have < MAX_DETAILS_PER_REASON {
                *have += 1;
                self.details.push(d);
            }
        }
        for (r, n) in other.skipped {
            *self.skipped.entry(r).or_insert(0) += n;
        }
    }
}

impl fmt::Display for LoadReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} files, {} records, {} points kept in {} trajectories ({} groups)",
            self.files_read, self.records_read, self.points_kept, self.trajectories, self.groups
        )?;
        for (r, n) in &self.skipped {
            write!(f, "; {r}: {n}")?;
        }
        Ok(())
    }
}
