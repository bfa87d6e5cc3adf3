//! The options shared by the subcommands: segmentation, the loaders' limits, the split.

use clap::ValueEnum;
use trajpred::dataset::{self, Segmentation};
use trajpred::harness::Split;
use trajpred_data::LoadOptions;

/// Segmentation options, applied right after loading (before anything else).
#[derive(clap::Args, Clone)]
pub(crate) struct SegmentArgs {
    /// Split a track where two fixes are more than this many seconds apart.
    #[arg(long)]
    max_gap: Option<f64>,
    /// Keep segments with at least this many points (default: what the command needs).
    #[arg(long)]
    min_points: Option<usize>,
    /// Resample every segment to this step (seconds), inside the segment only.
    #[arg(long)]
    resample: Option<f64>,
    /// Refuse a resampling that would create more points than this.
    #[arg(long, default_value_t = dataset::DEFAULT_MAX_RESAMPLED_POINTS)]
    max_resampled_points: usize,
}

impl SegmentArgs {
    pub(crate) fn segmentation(&self, needed: usize) -> Segmentation {
        Segmentation {
            max_gap: self.max_gap,
            min_points: self.min_points.unwrap_or(needed).max(1),
            resample: self.resample,
            max_resampled_points: self.max_resampled_points,
        }
    }
}

/// How the training users' tracks are cut (`evaluate` and `fit`).
#[derive(clap::Args, Clone, Copy)]
pub(crate) struct TrainCutArgs {
    /// Cut the training users' tracks where fixes are more than this many seconds apart
    /// (default: as `--max-gap`): longer training segments, more origins to learn from. The
    /// test part is cut by `--max-gap` all the same. Needs `--split by-user` or `none`.
    #[arg(long)]
    train_max_gap: Option<f64>,
}

impl TrainCutArgs {
    /// The training segmentation: `seg` with the training gap, if one was given.
    pub(crate) fn of(&self, seg: &Segmentation) -> Option<Segmentation> {
        self.train_max_gap.map(|g| Segmentation {
            max_gap: Some(g),
            ..*seg
        })
    }
}

/// Limits on what the loaders read (each has a default; a crossed limit is an error naming
/// the file, the line and the option to raise).
#[derive(clap::Args, Clone)]
pub(crate) struct LimitArgs {
    /// Longest line read, bytes.
    #[arg(long, default_value_t = trajpred_data::MAX_LINE_BYTES)]
    max_line_bytes: usize,
    /// Most decompressed bytes read from one text file.
    #[arg(long, default_value_t = trajpred_data::MAX_FILE_BYTES)]
    max_file_bytes: u64,
    /// Most decompressed bytes read from one JSON file (read whole).
    #[arg(long, default_value_t = trajpred_data::MAX_JSON_BYTES)]
    max_json_bytes: u64,
    /// Most points in one track.
    #[arg(long, default_value_t = trajpred_data::MAX_TRACK_POINTS)]
    max_track_points: usize,
    /// Most points loaded in all.
    #[arg(long, default_value_t = trajpred_data::MAX_TOTAL_POINTS)]
    max_total_points: usize,
}

impl LimitArgs {
    pub(crate) fn apply(&self, opts: LoadOptions) -> LoadOptions {
        LoadOptions {
            max_line_bytes: self.max_line_bytes,
            max_file_bytes: self.max_file_bytes,
            max_json_bytes: self.max_json_bytes,
            max_track_points: self.max_track_points,
            max_total_points: self.max_total_points,
            ..opts
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum SplitArg {
    /// Segments are shuffled and split (segments of one trip may fall on both sides).
    ByTrack,
    /// Users (vehicles, files) are shuffled and split: no user on both sides.
    ByUser,
    /// No split: `fit` trains on every segment; `evaluate` tests every segment with
    /// `--params` fitted on other data (segments the parameters were fitted on are left
    /// out), and refuses to run without them.
    None,
}

impl SplitArg {
    pub(crate) fn of(self, train_fraction: f64, seed: u64) -> Split {
        match self {
            SplitArg::ByTrack => Split::ByTrajectory {
                train_fraction,
                seed,
            },
            SplitArg::ByUser => Split::ByGroup {
                train_fraction,
                seed,
            },
            SplitArg::None => Split::None,
        }
    }
}
