//! Loading a dataset by name, then segmenting it: the first two steps of the evaluation path
//! (load -> **segment** -> split -> fit -> forecast -> summarise), shared by the CLI, the
//! protocol presets ([`crate::protocol`]) and the reproduction.
//!
//! - [`load_tracks`] reads a dataset's root folder, an inner folder or one file, unit by unit
//!   (a GeoLife user, a T-Drive taxi, a flight file), and returns every [`Track`] with the
//!   loaders' [`LoadReport`] (every skipped line or point, by cause).
//! - [`Segmentation`] splits each track where two fixes are more than `max_gap` seconds apart,
//!   optionally resamples *inside* each segment (never across a gap), and keeps the segments
//!   with at least `min_points` points. It refuses a resampling that would create more points
//!   than its cap, before allocating them.
//! - A [`Segment`] keeps the *group* its track came from (GeoLife user, T-Drive taxi, ADS-B
//!   aircraft, CSV file), so that a split can keep a user's segments on one side
//!   ([`crate::harness::Split::ByGroup`]).
//!
//! ```
//! use trajpred::dataset::{Dataset, Segmentation, load};
//! let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/geolife");
//! let seg = Segmentation { max_gap: Some(5.0), min_points: 10, ..Default::default() };
//! let loaded = load(Dataset::Geolife, root.as_ref(), &Dataset::Geolife.options(), &seg, None)?;
//! assert!(loaded.segments.iter().all(|s| s.trajectory.len() >= 10));
//! assert!(loaded.segments.iter().all(|s| s.group == "000"));
//! # Ok::<(), trajpred_core::Error>(())
//! ```

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use trajpred_core::{Error, Result, Trajectory};
use trajpred_data::{
    Frame, LoadOptions, LoadReport, Track, adsb, csvfile, geolife, segment, tdrive,
};

/// A dataset format the loaders read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Dataset {
    /// GeoLife 1.3: the dataset's root (holding `Data/`), `Data/`, one user's folder, or one
    /// `.plt` file.
    Geolife,
    /// T-Drive: the dataset's root (holding `taxi_log_2008_by_id/`), that folder, or one file.
    Tdrive,
    /// ADS-B flights as the `traffic` package ships them (`.json`/`.json.gz`): a folder or a file.
    Adsb,
    /// A CSV of `t,x,y[,z]` or `t,lat,lon[,alt]` with a header.
    Csv,
}

impl std::str::FromStr for Dataset {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s {
            "geolife" => Dataset::Geolife,
            "tdrive" | "t-drive" => Dataset::Tdrive,
            "adsb" | "ads-b" => Dataset::Adsb,
            "csv" => Dataset::Csv,
            _ => {
                return Err(Error::InvalidParameter {
                    name: "dataset",
                    reason: format!("unknown dataset `{s}`; known: geolife, tdrive, adsb, csv"),
                });
            }
        })
    }
}

impl std::fmt::Display for Dataset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Dataset::Geolife => "geolife",
            Dataset::Tdrive => "tdrive",
            Dataset::Adsb => "adsb",
            Dataset::Csv => "csv",
        })
    }
}

impl Dataset {
    /// The loader options this dataset starts from. Splitting at gaps is left to
    /// [`Segmentation`] (the loaders' own `max_gap` is off), so one rule applies to every
    /// dataset.
    pub fn options(self) -> LoadOptions {
        let base = match self {
            Dataset::Geolife | Dataset::Csv => LoadOptions::geolife(),
            Dataset::Tdrive => LoadOptions::tdrive(),
            Dataset::Adsb => LoadOptions::adsb(),
        };
        LoadOptions {
            max_gap: None,
            ..base
        }
    }

    /// The units of a folder of this dataset, in the order they are read: GeoLife user
    /// folders, T-Drive taxi files, ADS-B or CSV files. `None` for a single file.
    fn units(self, path: &Path) -> Result<Option<Vec<PathBuf>>> {
        if path.is_file() {
            return Ok(None);
        }
        Ok(match self {
            Dataset::Geolife => {
                if path.join("Trajectory").is_dir() {
                    Some(vec![path.to_path_buf()])
                } else {
                    let data = if path.join("Data").is_dir() {
                        path.join("Data")
                    } else {
                        path.to_path_buf()
                    };
                    Some(geolife::user_dirs(&data).map_err(data_error)?)
                }
            }
            Dataset::Tdrive => {
                let inner = path.join("taxi_log_2008_by_id");
                let dir = if inner.is_dir() {
                    inner
                } else {
                    path.to_path_buf()
                };
                Some(tdrive::files(&dir).map_err(data_error)?)
            }
            Dataset::Adsb => Some(adsb::files(path).map_err(data_error)?),
            Dataset::Csv => Some(csvfile::files(path).map_err(data_error)?),
        })
    }

    fn load_unit(self, path: &Path, opts: &LoadOptions) -> Result<(Vec<Track>, LoadReport)> {
        let is_file = path.is_file();
        match (self, is_file) {
            (Dataset::Geolife, true) => geolife::load_plt(path, opts),
            (Dataset::Geolife, false) => geolife::load_user(path, opts),
            (Dataset::Tdrive, _) => tdrive::load_file(path, opts),
            (Dataset::Adsb, _) => adsb::load_file(path, opts),
            (Dataset::Csv, _) => csvfile::load_path(path, opts),
        }
        .map_err(data_error)
    }
}

fn data_error(e: trajpred_data::Error) -> Error {
    Error::from_crate("data", e)
}

/// What [`load_tracks`] read.
#[derive(Debug, Clone)]
pub struct Tracks {
    /// Every track the loaders returned, in reading order.
    pub tracks: Vec<Track>,
    /// The loaders' report over every file read.
    pub report: LoadReport,
    /// Units read (GeoLife users, T-Drive taxis, ADS-B or CSV files; 1 for a single file).
    pub units_read: usize,
    /// Units there were.
    pub units_total: usize,
}

/// Reads `path` as `dataset`, unit by unit (at most `max_units` of them, in sorted order;
/// `None`: all). `path` may be the dataset's root folder, its inner folder or one file.
pub fn load_tracks(
    dataset: Dataset,
    path: &Path,
    opts: &LoadOptions,
    max_units: Option<usize>,
) -> Result<Tracks> {
    if !path.exists() {
        return Err(Error::InvalidParameter {
            name: "path",
            reason: format!("{} does not exist", path.display()),
        });
    }
    let units = match dataset.units(path)? {
        Some(u) => u,
        None => vec![path.to_path_buf()],
    };
    let units_total = units.len();
    let take = max_units.unwrap_or(usize::MAX).min(units_total);
    let mut report = LoadReport::new();
    let mut tracks = Vec::new();
    let mut total = 0usize;
    for unit in &units[..take] {
        let (t, r) = dataset.load_unit(unit, opts)?;
        total += t.iter().map(|t| t.trajectory.len()).sum::<usize>();
        // the loaders bound one unit; the whole dataset is bounded here
        if total > opts.max_total_points {
            return Err(Error::InvalidParameter {
                name: "max_total_points",
                reason: format!(
                    "{} holds more than {} points (reached at {}); raise the limit \
                     (--max-total-points) or read fewer units (--max-units)",
                    path.display(),
                    opts.max_total_points,
                    unit.display()
                ),
            });
        }
        tracks.extend(t);
        report.merge(r);
    }
    Ok(Tracks {
        tracks,
        report,
        units_read: take,
        units_total,
    })
}

/// A contiguous piece of a track, ready for evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// The user, vehicle or file it came from ([`Track::group`]).
    pub group: String,
    /// The track's id, with `@k` for its k-th segment (k from 0).
    pub id: String,
    /// What the axes mean (for geodetic data, the local frame's origin).
    pub frame: Frame,
    /// Timestamps (s) and points (m).
    pub trajectory: Trajectory,
}

/// Default cap on the points that resampling may create over a whole dataset.
pub const DEFAULT_MAX_RESAMPLED_POINTS: usize = 20_000_000;

/// How tracks become segments, applied before anything else of an evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Segmentation {
    /// Split where two successive fixes are more than this many seconds apart (`None`: never).
    pub max_gap: Option<f64>,
    /// Keep segments with at least this many points (after resampling).
    pub min_points: usize,
    /// Resample every segment to this step in seconds, inside the segment only (linear
    /// interpolation between its own fixes), if set.
    pub resample: Option<f64>,
    /// Refuse a resampling that would create more points than this over the whole dataset.
    pub max_resampled_points: usize,
}

impl Default for Segmentation {
    fn default() -> Self {
        Segmentation {
            max_gap: None,
            min_points: 1,
            resample: None,
            max_resampled_points: DEFAULT_MAX_RESAMPLED_POINTS,
        }
    }
}

/// Counts of a segmentation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SegmentCounts {
    /// Tracks segmented.
    pub tracks: usize,
    /// Segments after the gap split, of any length.
    pub segments_all: usize,
    /// Segments dropped for having fewer than `min_points` points.
    pub too_short: usize,
    /// Points in the kept segments.
    pub points: usize,
}

impl Segmentation {
    /// Checks the settings; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, reason: String| Err(Error::InvalidParameter { name, reason });
        if let Some(g) = self.max_gap
            && !(g.is_finite() && g > 0.0)
        {
            return bad("max_gap", format!("must be finite and positive, got {g}"));
        }
        if self.min_points == 0 {
            return bad("min_points", "must be at least 1, got 0".into());
        }
        if let Some(dt) = self.resample
            && !(dt.is_finite() && dt > 0.0)
        {
            return bad("resample", format!("must be finite and positive, got {dt}"));
        }
        if self.max_resampled_points == 0 {
            return bad("max_resampled_points", "must be at least 1, got 0".into());
        }
        Ok(())
    }

    /// Splits one trajectory at its gaps (no resampling, no length filter).
    pub fn split(&self, tr: &Trajectory) -> Result<Vec<Trajectory>> {
        match self.max_gap {
            Some(g) if tr.len() >= 2 => segment::split_on_gaps(tr, g).map_err(data_error),
            _ => Ok(vec![tr.clone()]),
        }
    }

    /// Segments every track: split at gaps, resample inside each segment, keep the long ones.
    pub fn apply(&self, tracks: &[Track]) -> Result<(Vec<Segment>, SegmentCounts)> {
        self.validate()?;
        let mut pieces: Vec<(usize, usize, Trajectory)> = Vec::new();
        for (ti, t) in tracks.iter().enumerate() {
            for (k, s) in self.split(&t.trajectory)?.into_iter().enumerate() {
                pieces.push((ti, k, s));
            }
        }
        let mut counts = SegmentCounts {
            tracks: tracks.len(),
            segments_all: pieces.len(),
            ..Default::default()
        };
        if let Some(dt) = self.resample {
            // count first, so that a resampling too large is refused before any allocation
            let mut total: usize = 0;
            for (_, _, s) in &pieces {
                let t = s.times();
                let span = t[t.len() - 1] - t[0];
                let n = (span / dt).floor() + 1.0;
                total = total.saturating_add(if n < usize::MAX as f64 {
                    n as usize
                } else {
                    usize::MAX
                });
            }
            if total > self.max_resampled_points {
                return Err(Error::InvalidParameter {
                    name: "resample",
                    reason: format!(
                        "a step of {dt} s would create {total} points, more than the cap of {} \
                         (raise the cap, or resample at a longer step)",
                        self.max_resampled_points
                    ),
                });
            }
        }
        let mut out = Vec::new();
        for (ti, k, s) in pieces {
            let s = match self.resample {
                Some(dt) if s.len() >= 2 => segment::resample(&s, dt).map_err(data_error)?,
                _ => s,
            };
            if s.len() < self.min_points {
                counts.too_short += 1;
                continue;
            }
            counts.points += s.len();
            let id = &tracks[ti].id;
            out.push(Segment {
                group: tracks[ti].group.clone(),
                id: format!("{id}@{k}"),
                frame: tracks[ti].frame,
                trajectory: s,
            });
        }
        Ok((out, counts))
    }
}

/// A dataset loaded and segmented.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The segments kept, in reading order.
    pub segments: Vec<Segment>,
    /// The loaders' report (every skipped line or point, by cause).
    pub report: LoadReport,
    /// Tracks the loaders returned.
    pub tracks: usize,
    /// Units read and units there were (see [`Tracks`]).
    pub units_read: usize,
    /// Units there were.
    pub units_total: usize,
    /// What the segmentation did.
    pub counts: SegmentCounts,
}

impl Loaded {
    /// The segments' trajectories, cloned.
    pub fn trajectories(&self) -> Vec<Trajectory> {
        self.segments.iter().map(|s| s.trajectory.clone()).collect()
    }

    /// One line saying what was read, kept and skipped (by cause).
    pub fn summary(&self) -> String {
        let mut s = format!(
            "read {} of {} units: {} tracks, {} points kept by the loaders; {} segments of {} \
             kept ({} points), {} shorter than the minimum",
            self.units_read,
            self.units_total,
            self.tracks,
            self.report.points_kept,
            self.segments.len(),
            self.counts.segments_all,
            self.counts.points,
            self.counts.too_short,
        );
        let skipped = self.report.skipped_total();
        if skipped > 0 {
            let by: Vec<String> = self
                .report
                .skipped_by_reason()
                .map(|(r, n)| format!("{n} {r}"))
                .collect();
            s.push_str(&format!(
                "; skipped {skipped} lines/points: {}",
                by.join(", ")
            ));
        }
        s
    }
}

/// Loads `path` as `dataset` (at most `max_units` units), then segments it.
pub fn load(
    dataset: Dataset,
    path: &Path,
    opts: &LoadOptions,
    segmentation: &Segmentation,
    max_units: Option<usize>,
) -> Result<Loaded> {
    load_cut_twice(dataset, path, opts, segmentation, None, max_units).map(|(l, _)| l)
}

/// Segments cut from tracks, with the counts of the cut ([`Segmentation::apply`]).
pub type Cut = (Vec<Segment>, SegmentCounts);

/// [`load`], the tracks also cut by `other` when given (a protocol's
/// [training segmentation](crate::protocol::Protocol::train_segmentation)): read once,
/// segmented twice.
pub fn load_cut_twice(
    dataset: Dataset,
    path: &Path,
    opts: &LoadOptions,
    segmentation: &Segmentation,
    other: Option<&Segmentation>,
    max_units: Option<usize>,
) -> Result<(Loaded, Option<Cut>)> {
    segmentation.validate()?;
    if let Some(o) = other {
        o.validate()?;
    }
    let t = load_tracks(dataset, path, opts, max_units)?;
    let (segments, counts) = segmentation.apply(&t.tracks)?;
    let second = other.map(|o| o.apply(&t.tracks)).transpose()?;
    let loaded = Loaded {
        segments,
        report: t.report,
        tracks: t.tracks.len(),
        units_read: t.units_read,
        units_total: t.units_total,
        counts,
    };
    Ok((loaded, second))
}
