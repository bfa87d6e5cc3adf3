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
}

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

    /// Checks the parameters (a positive `max_gap`, `min_points` ≥ 1, a valid reference).
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
            return Err(Error::param("min_points", "must be at least 1"));
        }
        if let Projection::Enu(o) = self.projection {
            LocalFrame::new(o)?;
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
}

impl Cleaner<'_> {
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

    /// Applies the time rule (keep the first point of a run of equal timestamps, drop points
    /// that go back in time), splits at gaps, drops short segments and projects; appends the
    /// tracks to `out`.
    pub fn finish(
        &mut self,
        id: &str,
        points: Vec<RawPoint>,
        frame_kind: FrameKind,
        out: &mut Vec<Track>,
    ) -> Result<()> {
        if points.is_empty() {
            return Ok(());
        }
        let mut kept: Vec<RawPoint> = Vec::with_capacity(points.len());
        for p in points {
            match kept.last() {
                Some(last) if p.t == last.t => {
                    self.report
                        .skip(self.file, p.line, SkipReason::RepeatedTimestamp, "");
                }
                Some(last) if p.t < last.t => {
                    self.report
                        .skip(self.file, p.line, SkipReason::TimeBackwards, "");
                }
                _ => kept.push(p),
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
            let track = self.project(seg_id, &seg, frame_kind)?;
            self.report.points_kept += seg.len();
            self.report.trajectories += 1;
            out.push(track);
        }
        Ok(())
    }

    fn project(&self, id: String, seg: &[RawPoint], kind: FrameKind) -> Result<Track> {
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
            source: self.file.to_string(),
            first_line: seg[0].line,
            frame,
            trajectory: Trajectory::from_axes(times, axes)?,
        })
    }
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
