//! What the loaders return ([`Track`]), how they are configured ([`LoadOptions`]), and the
//! cleaning pipeline every format shares.

use crate::error::{Error, Result};
use crate::geodesy::{Geodetic, LocalFrame};
use crate::report::{LoadReport, SkipReason};
use trajpred_core::Trajectory;

/// The coordinates the loaders return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Degrees: axes (latitude, longitude) or (latitude, longitude, altitude in metres).
    Geodetic,
    /// Local east-north-up metres around each trajectory's first point (after cleaning and
    /// splitting). The default.
    EnuAtFirstPoint,
    /// Local east-north-up metres around one reference point shared by every trajectory.
    Enu(Geodetic),
}

/// The frame of a [`Track`]'s axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Frame {
    /// (latitude °, longitude °[, altitude m]).
    Geodetic,
    /// (east m, north m[, up m]) around this origin. Without altitude the points are
    /// projected at height 0 and the origin's altitude is 0.
    Enu(Geodetic),
    /// Metres as the user's file gave them (CSV `t,x,y[,z]`).
    Cartesian,
}

/// A latitude/longitude box, degrees, bounds inclusive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundingBox {
    min_lat: f64,
    max_lat: f64,
    min_lon: f64,
    max_lon: f64,
}

impl BoundingBox {
    /// The box used to clean T-Drive: lon 115.4–117.6, lat 39.4–41.1 (greater Beijing, as in
    /// the data's SOURCE.md).
    pub const BEIJING: BoundingBox = BoundingBox {
        min_lat: 39.4,
        max_lat: 41.1,
        min_lon: 115.4,
        max_lon: 117.6,
    };

    /// A checked box: finite bounds, min ≤ max, latitudes within ±90°, longitudes within ±180°.
    pub fn new(min_lat: f64, max_lat: f64, min_lon: f64, max_lon: f64) -> Result<Self> {
        let ok = [min_lat, max_lat, min_lon, max_lon]
            .iter()
            .all(|v| v.is_finite())
            && min_lat <= max_lat
            && min_lon <= max_lon
            && min_lat >= -90.0
            && max_lat <= 90.0
            && min_lon >= -180.0
            && max_lon <= 180.0;
        if !ok {
            return Err(Error::param(
                "bbox",
                format!(
                    "need -90 <= {min_lat} <= {max_lat} <= 90 and -180 <= {min_lon} <= {max_lon} <= 180"
                ),
            ));
        }
        Ok(BoundingBox {
            min_lat,
            max_lat,
            min_lon,
            max_lon,
        })
    }

    /// Whether the position lies inside (bounds included).
    pub fn contains(&self, lat: f64, lon: f64) -> bool {
        (self.min_lat..=self.max_lat).contains(&lat) && (self.min_lon..=self.max_lon).contains(&lon)
    }
}

/// How the loaders clean, split and project. Start from a preset ([`LoadOptions::geolife`],
/// [`LoadOptions::tdrive`], [`LoadOptions::adsb`]) or `default()` and set fields.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadOptions {
    /// Output coordinates (default: ENU metres around each trajectory's first point).
    pub projection: Projection,
    /// Return 3 axes with the altitude (metres) instead of 2 (default `false`). Points with an
    /// unknown altitude are then skipped as [`SkipReason::MissingValue`].
    pub altitude: bool,
    /// Drop positions outside this box ([`SkipReason::OutsideBounds`]; default none).
    pub bbox: Option<BoundingBox>,
    /// Drop positions at exactly (0°, 0°) ([`SkipReason::ZeroPosition`]; default `true`).
    pub drop_zero: bool,
    /// Split a trajectory where the time between successive kept points exceeds this many
    /// seconds (default none).
    pub max_gap: Option<f64>,
    /// Drop segments with fewer points ([`SkipReason::ShortSegment`]; default 1).
    pub min_points: usize,
    /// Fail on the first malformed line or invalid coordinate with
    /// [`Error::Parse`] instead of skipping it (default `false`).
    pub strict: bool,
    /// The longest line of a text format (GeoLife, T-Drive, CSV), in bytes without the line
    /// end (default [`MAX_LINE_BYTES`], 1 MiB). A longer line is an
    /// [`Error::LimitExceeded`] naming the file and line; the loaders never hold more than
    /// one line of this length.
    pub max_line_bytes: usize,
    /// The most bytes read from one text file, after gzip decompression (default
    /// [`MAX_FILE_BYTES`], 4 GiB). Text formats are streamed, so this bounds time, not
    /// memory; it stops a gzip bomb early.
    pub max_file_bytes: u64,
    /// The most bytes of one JSON file (ADS-B), after decompression (default
    /// [`MAX_JSON_BYTES`], 512 MiB). A JSON document is read whole before it is parsed, so
    /// this bounds the memory a file can take.
    pub max_json_bytes: u64,
    /// The most points one trajectory (before splitting at gaps) may hold while it is read
    /// (default [`MAX_TRACK_POINTS`], 10 million).
    pub max_track_points: usize,
    /// The most points one load call may hold: a `load_*` function over a file or folder,
    /// or a `parse*` function, counting the points already kept in the report it is given
    /// (default [`MAX_TOTAL_POINTS`], 50 million). For ADS-B JSON the records read count,
    /// since they are all held before grouping.
    pub max_total_points: usize,
}

/// Default [`LoadOptions::max_line_bytes`]: 1 MiB (a GeoLife line is about 65 bytes).
pub const MAX_LINE_BYTES: usize = 1 << 20;
/// Default [`LoadOptions::max_file_bytes`]: 4 GiB of decompressed text per file.
pub const MAX_FILE_BYTES: u64 = 4 << 30;
/// Default [`LoadOptions::max_json_bytes`]: 512 MiB of decompressed JSON per file.
pub const MAX_JSON_BYTES: u64 = 512 << 20;
/// Default [`LoadOptions::max_track_points`]: 10 million points in one trajectory.
pub const MAX_TRACK_POINTS: usize = 10_000_000;
/// Default [`LoadOptions::max_total_points`]: 50 million points in one load (GeoLife 1.3
/// has 24.9 million, T-Drive 17.7 million).
pub const MAX_TOTAL_POINTS: usize = 50_000_000;

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            projection: Projection::EnuAtFirstPoint,
            altitude: false,
            bbox: None,
            drop_zero: true,
            max_gap: None,
            min_points: 1,
            strict: false,
            max_line_bytes: MAX_LINE_BYTES,
            max_file_bytes: MAX_FILE_BYTES,
            max_json_bytes: MAX_JSON_BYTES,
            max_track_points: MAX_TRACK_POINTS,
            max_total_points: MAX_TOTAL_POINTS,
        }
    }
}

impl LoadOptions {
    /// GeoLife: one trajectory per `.plt` file, 2-D (the phone altitude is poor).
    pub fn geolife() -> Self {
        Self::default()
    }

    /// T-Drive: Beijing box, split where a taxi is silent for more than 30 minutes.
    pub fn tdrive() -> Self {
        LoadOptions {
            bbox: Some(BoundingBox::BEIJING),
            max_gap: Some(1800.0),
            ..Self::default()
        }
    }

    /// ADS-B: 3-D with the barometric altitude, split at gaps longer than one hour.
    pub fn adsb() -> Self {
        LoadOptions {
            altitude: true,
            max_gap: Some(3600.0),
            ..Self::default()
        }
    }

    /// Checks the parameters (a positive `max_gap`, `min_points` ≥ 1, a valid reference,
    /// limits of at least one line byte and one point).
    pub fn validate(&self) -> Result<()> {
        if let Some(g) = self.max_gap
            && !(g.is_finite() && g > 0.0)
        {
            return Err(Error::param(
                "max_gap",
                format!("must be finite and positive, got {g}"),
            ));
        }
        if self.min_points == 0 {
            return Err(Error::param("min_points", "must be at least 1, got 0"));
        }
        if let Projection::Enu(o) = self.projection {
            LocalFrame::new(o)?;
        }
        if self.max_line_bytes == 0 {
            return Err(Error::param("max_line_bytes", "must be at least 1, got 0"));
        }
        if self.max_track_points == 0 {
            return Err(Error::param(
                "max_track_points",
                "must be at least 1, got 0",
            ));
        }
        if self.max_total_points == 0 {
            return Err(Error::param(
                "max_total_points",
                "must be at least 1, got 0",
            ));
        }
        Ok(())
    }
}

/// One loaded trajectory and where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    /// An identifier: `user/file-stem` (GeoLife), `taxi-id` (T-Drive), `icao24/callsign`
    /// (ADS-B), the file stem (CSV); with `#k` appended for the k-th segment (k ≥ 1) after
    /// splitting at gaps.
    pub id: String,
    /// What the trajectory belongs to, for splitting data by user or vehicle (every segment
    /// of one trajectory, and every trajectory of one user, share it): the user folder's name
    /// (GeoLife), the taxi id (T-Drive), the `icao24` address (ADS-B), the file stem, or
    /// `<file stem>/<id>` for a CSV file with a track/id column.
    pub group: String,
    /// The file it was read from.
    pub source: String,
    /// The line (JSON: record) of its first point.
    pub first_line: usize,
    /// What the axes mean.
    pub frame: Frame,
    /// Timestamps in seconds since the Unix epoch (UTC; T-Drive's local time is read as if
    /// UTC) or as the CSV gave them, and the points.
    pub trajectory: Trajectory,
}

/// Altitudes beyond ±10,000 km are invalid coordinates (they are not altitudes, and would
/// overflow the geodesy).
pub const MAX_ABS_ALTITUDE: f64 = 1.0e7;

/// A parsed point before cleaning; `alt` in metres.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RawPoint {
    pub line: usize,
    pub t: f64,
    pub a: f64,
    pub b: f64,
    pub alt: Option<f64>,
}

/// The shared cleaning pipeline of one file.
pub(crate) struct Cleaner<'a> {
    pub opts: &'a LoadOptions,
    pub file: &'a str,
    pub report: &'a mut LoadReport,
    /// Points (or, for JSON, records) held and not yet passed to [`Cleaner::finish`].
    held: usize,
}

impl<'a> Cleaner<'a> {
    pub fn new(opts: &'a LoadOptions, file: &'a str, report: &'a mut LoadReport) -> Self {
        Cleaner {
            opts,
            file,
            report,
            held: 0,
        }
    }

    /// Counts one more point held at `line`, in a trajectory already holding `track_len`
    /// points: an [`Error::LimitExceeded`] when that crosses
    /// [`LoadOptions::max_track_points`] or [`LoadOptions::max_total_points`].
    pub fn hold(&mut self, line: usize, track_len: usize) -> Result<()> {
        if track_len >= self.opts.max_track_points {
            return Err(self.limit(
                line,
                "max_track_points",
                self.opts.max_track_points,
                "points in one trajectory",
            ));
        }
        self.held += 1;
        if self.report.points_kept.saturating_add(self.held) > self.opts.max_total_points {
            return Err(self.limit(
                line,
                "max_total_points",
                self.opts.max_total_points,
                "points in one load",
            ));
        }
        Ok(())
    }

    /// Forgets `n` held points (records turned into points, or points passed on).
    pub fn release(&mut self, n: usize) {
        self.held = self.held.saturating_sub(n);
    }

    fn limit(&self, line: usize, option: &'static str, limit: usize, what: &'static str) -> Error {
        Error::LimitExceeded {
            file: self.file.to_string(),
            line: Some(line),
            option,
            limit: limit as u64,
            what,
        }
    }

    /// A malformed line: skipped and counted, or an error in strict mode.
    pub fn malformed(&mut self, line: usize, reason: impl Into<String>) -> Result<()> {
        let reason = reason.into();
        if self.opts.strict {
            return Err(Error::parse(self.file, line, reason));
        }
        self.report
            .skip(self.file, line, SkipReason::Malformed, reason);
        Ok(())
    }

    /// Point-level checks of a geodetic point (`a` = lat, `b` = lon). `Ok(true)` keeps it.
    pub fn accept_geodetic(&mut self, p: &RawPoint) -> Result<bool> {
        if !(p.a.is_finite() && p.b.is_finite() && p.a.abs() <= 90.0 && p.b.abs() <= 180.0) {
            if self.opts.strict {
                return Err(Error::parse(
                    self.file,
                    p.line,
                    format!("invalid coordinate lat {} lon {}", p.a, p.b),
                ));
            }
            self.report
                .skip(self.file, p.line, SkipReason::InvalidCoordinate, "");
            return Ok(false);
        }
        if self.opts.drop_zero && p.a == 0.0 && p.b == 0.0 {
            self.report
                .skip(self.file, p.line, SkipReason::ZeroPosition, "");
            return Ok(false);
        }
        if let Some(bb) = self.opts.bbox
            && !bb.contains(p.a, p.b)
        {
            self.report
                .skip(self.file, p.line, SkipReason::OutsideBounds, "");
            return Ok(false);
        }
        self.accept_altitude(p)
    }

    /// Point-level checks of a Cartesian point.
    pub fn accept_cartesian(&mut self, p: &RawPoint) -> Result<bool> {
        if !(p.a.is_finite() && p.b.is_finite()) {
            if self.opts.strict {
                return Err(Error::parse(self.file, p.line, "non-finite coordinate"));
            }
            self.report
                .skip(self.file, p.line, SkipReason::InvalidCoordinate, "");
            return Ok(false);
        }
        self.accept_altitude(p)
    }

    fn accept_altitude(&mut self, p: &RawPoint) -> Result<bool> {
        if self.opts.altitude {
            match p.alt {
                None => {
                    self.report
                        .skip(self.file, p.line, SkipReason::MissingValue, "altitude");
                    return Ok(false);
                }
                Some(h) if !(h.is_finite() && h.abs() <= MAX_ABS_ALTITUDE) => {
                    self.report
                        .skip(self.file, p.line, SkipReason::InvalidCoordinate, "altitude");
                    return Ok(false);
                }
                Some(_) => {}
            }
        }
        Ok(true)
    }

    /// Applies the time rule (see [`time_order`]), splits at gaps, drops short segments and
    /// projects; appends the tracks of trajectory `id`, of group `group`, to `out`.
    pub fn finish(
        &mut self,
        id: &str,
        group: &str,
        points: Vec<RawPoint>,
        frame_kind: FrameKind,
        out: &mut Vec<Track>,
    ) -> Result<()> {
        self.release(points.len());
        if points.is_empty() {
            return Ok(());
        }
        let times: Vec<f64> = points.iter().map(|p| p.t).collect();
        let verdicts = time_order(&times);
        let mut kept: Vec<RawPoint> = Vec::with_capacity(points.len());
        for (p, v) in points.into_iter().zip(verdicts) {
            match v {
                None => kept.push(p),
                Some(reason) => self.report.skip(self.file, p.line, reason, ""),
            }
        }
        let mut segments: Vec<Vec<RawPoint>> = Vec::new();
        let mut current: Vec<RawPoint> = Vec::new();
        for p in kept {
            if let (Some(g), Some(last)) = (self.opts.max_gap, current.last())
                && p.t - last.t > g
            {
                segments.push(std::mem::take(&mut current));
            }
            current.push(p);
        }
        segments.push(current);
        for (k, seg) in segments.into_iter().enumerate() {
            if seg.len() < self.opts.min_points {
                self.report.skip_many(
                    self.file,
                    seg[0].line,
                    SkipReason::ShortSegment,
                    seg.len(),
                    format!("{} points", seg.len()),
                );
                continue;
            }
            let seg_id = if k == 0 {
                id.to_string()
            } else {
                format!("{id}#{k}")
            };
            let track = self.project(seg_id, group, &seg, frame_kind)?;
            self.report.points_kept += seg.len();
            self.report.trajectories += 1;
            out.push(track);
        }
        Ok(())
    }

    fn project(&self, id: String, group: &str, seg: &[RawPoint], kind: FrameKind) -> Result<Track> {
        let n = seg.len();
        let dim = if self.opts.altitude { 3 } else { 2 };
        let mut axes: Vec<Vec<f64>> = (0..dim).map(|_| Vec::with_capacity(n)).collect();
        let times: Vec<f64> = seg.iter().map(|p| p.t).collect();
        let alt = |p: &RawPoint| {
            if self.opts.altitude {
                p.alt.unwrap_or(0.0)
            } else {
                0.0
            }
        };
        let frame = match (kind, self.opts.projection) {
            (FrameKind::Cartesian, _) => {
                for p in seg {
                    axes[0].push(p.a);
                    axes[1].push(p.b);
                    if dim == 3 {
                        axes[2].push(alt(p));
                    }
                }
                Frame::Cartesian
            }
            (FrameKind::Geodetic, Projection::Geodetic) => {
                for p in seg {
                    axes[0].push(p.a);
                    axes[1].push(p.b);
                    if dim == 3 {
                        axes[2].push(alt(p));
                    }
                }
                Frame::Geodetic
            }
            (FrameKind::Geodetic, proj) => {
                let origin = match proj {
                    Projection::Enu(o) if dim == 3 => o,
                    Projection::Enu(o) => Geodetic { alt_m: 0.0, ..o },
                    _ => Geodetic::new(seg[0].a, seg[0].b, alt(&seg[0]))?,
                };
                let frame = LocalFrame::new(origin)?;
                for p in seg {
                    let e = frame.to_enu(&Geodetic {
                        lat_deg: p.a,
                        lon_deg: p.b,
                        alt_m: alt(p),
                    });
                    axes[0].push(e.east);
                    axes[1].push(e.north);
                    if dim == 3 {
                        axes[2].push(e.up);
                    }
                }
                Frame::Enu(origin)
            }
        };
        Ok(Track {
            id,
            group: group.to_string(),
            source: self.file.to_string(),
            first_line: seg[0].line,
            frame,
            trajectory: Trajectory::from_axes(times, axes)?,
        })
    }
}

/// The time rule of one trajectory (`times` in file order, or time order for ADS-B): which
/// points to drop, and why (`None` keeps the point).
///
/// The kept points are a longest subsequence of strictly increasing times, so the fewest
/// points are dropped and none is dropped when the times already increase. Among equally
/// long choices, each kept point is the one with the earliest time that still allows a
/// longest choice, and the earliest in file order among equal times. Consequences: the first
/// point of a run of equal timestamps is kept; a single point stamped far in the future
/// (a clock glitch) is dropped alone, and the track goes on after it; a point out of order
/// is dropped, not the rest of the file. A dropped point is
/// [`SkipReason::RepeatedTimestamp`] if its time equals the previous kept point's,
/// [`SkipReason::TimeBackwards`] if it is earlier, [`SkipReason::TimeOutlier`] otherwise
/// (it is later than the next kept point: a jump forward). Times must not be NaN (the
/// loaders only produce finite times). O(n log n).
pub(crate) fn time_order(times: &[f64]) -> Vec<Option<SkipReason>> {
    let n = times.len();
    // level[i]: the length of the longest strictly increasing run of times starting at i
    let mut level = vec![0usize; n];
    // best[k]: the largest time starting an increasing run of length k + 1 among the points
    // after i (strictly decreasing in k)
    let mut best: Vec<f64> = Vec::new();
    for i in (0..n).rev() {
        let t = times[i];
        let k = best.partition_point(|&b| b > t);
        level[i] = k + 1;
        if k == best.len() {
            best.push(t);
        } else {
            best[k] = t;
        }
    }
    let longest = best.len();
    // the points of each level, in file order: along one level the times never increase
    let mut by_level: Vec<Vec<usize>> = vec![Vec::new(); longest + 1];
    for (i, &l) in level.iter().enumerate() {
        by_level[l].push(i);
    }
    let mut keep = vec![false; n];
    let (mut after, mut last) = (0usize, f64::NEG_INFINITY);
    for need in (1..=longest).rev() {
        // the candidates after the previous kept point with a later time: a prefix of the
        // level's points past `after`; take the earliest time, the first of equal times
        let mut pick: Option<usize> = None;
        for &i in by_level[need].iter().filter(|&&i| i >= after) {
            if times[i] <= last {
                break;
            }
            if pick.is_none_or(|p| times[i] < times[p]) {
                pick = Some(i);
            }
        }
        // a longest run always continues (level `need` exists past `after`); stop defensively
        let Some(i) = pick else { break };
        keep[i] = true;
        after = i + 1;
        last = times[i];
    }
    let mut out = Vec::with_capacity(n);
    let mut previous: Option<f64> = None;
    for (i, &t) in times.iter().enumerate() {
        if keep[i] {
            previous = Some(t);
            out.push(None);
            continue;
        }
        out.push(Some(match previous {
            Some(p) if t == p => SkipReason::RepeatedTimestamp,
            Some(p) if t < p => SkipReason::TimeBackwards,
            _ => SkipReason::TimeOutlier,
        }));
    }
    out
}

/// Whether a file's coordinates are geodetic or Cartesian metres.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FrameKind {
    Geodetic,
    Cartesian,
}

/// Parses a finite `f64` field.
pub(crate) fn num(s: &str) -> Option<f64> {
    s.trim_ascii().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Splits `text` at `sep` into exactly `N` fields, or returns the number of fields found.
/// A plain byte loop: the generic `str::split` is slow in unoptimised (test) builds.
pub(crate) fn fields<const N: usize>(text: &str, sep: u8) -> Result<[&str; N], usize> {
    let b = text.as_bytes();
    let mut out = [""; N];
    let mut count = 0;
    let mut start = 0;
    for i in 0..=b.len() {
        if i == b.len() || b[i] == sep {
            if count < N {
                // `sep` is ASCII, so `start..i` lies on character boundaries
                out[count] = text.get(start..i).unwrap_or("");
            }
            count += 1;
            start = i + 1;
        }
    }
    if count == N { Ok(out) } else { Err(count) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The longest strictly increasing subsequence's length, by the quadratic recurrence.
    fn lis(t: &[f64]) -> usize {
        let mut best = vec![1usize; t.len()];
        for i in 0..t.len() {
            for j in 0..i {
                if t[j] < t[i] {
                    best[i] = best[i].max(best[j] + 1);
                }
            }
        }
        best.into_iter().max().unwrap_or(0)
    }

    #[test]
    fn time_order_examples() {
        use SkipReason::{RepeatedTimestamp as R, TimeBackwards as B, TimeOutlier as O};
        let cases: [(&[f64], &[Option<SkipReason>]); 7] = [
            (&[0.0, 1.0, 2.0], &[None, None, None]),
            (&[0.0, 0.0, 1.0, 1.0], &[None, Some(R), None, Some(R)]),
            // one far-future point, then the track goes on
            (
                &[0.0, 1.0, 2.0, 1e9, 3.0, 4.0],
                &[None, None, None, Some(O), None, None],
            ),
            // two of them in a row
            (
                &[0.0, 1.0, 1e9, 1e9 + 1.0, 2.0, 3.0, 4.0],
                &[None, None, Some(O), Some(O), None, None, None],
            ),
            // the outlier just before the end: the earlier time wins the tie
            (&[0.0, 1.0, 1e9, 2.0], &[None, None, Some(O), None]),
            // a point behind the track
            (
                &[0.0, 1.0, 2.0, 0.5, 3.0],
                &[None, None, None, Some(B), None],
            ),
            // a restart shorter than what came before: dropped as going backwards
            (
                &[5.0, 6.0, 7.0, 8.0, 1.0, 2.0],
                &[None, None, None, None, Some(B), Some(B)],
            ),
        ];
        for (times, want) in cases {
            assert_eq!(time_order(times), want, "{times:?}");
        }
        assert!(time_order(&[]).is_empty());
    }

    #[test]
    fn time_order_keeps_a_longest_increasing_run_of_every_small_sequence() {
        // every sequence of length up to 6 over 4 values
        for len in 0..=6u32 {
            for code in 0..4usize.pow(len) {
                let times: Vec<f64> = (0..len)
                    .map(|k| ((code / 4usize.pow(k)) % 4) as f64)
                    .collect();
                let v = time_order(&times);
                let kept: Vec<f64> = times
                    .iter()
                    .zip(&v)
                    .filter(|(_, v)| v.is_none())
                    .map(|(t, _)| *t)
                    .collect();
                assert!(kept.windows(2).all(|w| w[0] < w[1]), "{times:?} {v:?}");
                assert_eq!(kept.len(), lis(&times), "{times:?} {v:?}");
                // the first of equal times is kept: no dropped point j of the same time could
                // take a kept point i's place (nothing kept between them, all before j earlier)
                let kept_at = |k: usize| v[k].is_none();
                for i in (0..times.len()).filter(|&i| kept_at(i)) {
                    for j in (0..i).filter(|&j| times[j] == times[i]) {
                        let could_swap = (j + 1..i).all(|k| !kept_at(k))
                            && (0..j).filter(|&k| kept_at(k)).all(|k| times[k] < times[i]);
                        assert!(!could_swap, "{times:?} {v:?}");
                    }
                }
            }
        }
    }
}
