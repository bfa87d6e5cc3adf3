//! The evaluation harness: rolling-origin multi-step evaluation of predictors over many
//! trajectories.
//!
//! For every test trajectory and every origin `o` (from `history - 1`, every `stride` points,
//! while `o + horizon` is inside the trajectory) the predictor gets the `history` points
//! ending at `o` and forecasts `horizon` steps; these are scored against the points
//! `o + 1 ..= o + horizon`, asked for at those points' timestamps
//! ([`Predictor::forecast_times`]: their times, never their positions). Trajectories are processed in parallel (rayon) in fixed-size
//! chunks and their partial sums are combined in trajectory order, so results do not depend
//! on the number of threads and memory holds one chunk of trajectories at a time.

use crate::dataset::Segment;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;
use trajpred_core::{Error, Point, Predictor, Result, Trajectory};

/// How to evaluate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EvalConfig {
    /// Points given to the predictor at each origin (the paper: 10..50).
    pub history: usize,
    /// Steps forecast at each origin (the paper: 1..5).
    pub horizon: usize,
    /// Distance between consecutive origins in a trajectory.
    pub stride: usize,
    /// Hit threshold in the data's units (the paper: 25 m).
    pub threshold: f64,
    /// At most this many origins per trajectory (`None`: all).
    pub max_origins_per_trajectory: Option<usize>,
}

impl Default for EvalConfig {
    fn default() -> Self {
        EvalConfig {
            history: 20,
            horizon: 5,
            stride: 1,
            threshold: 25.0,
            max_origins_per_trajectory: None,
        }
    }
}

impl EvalConfig {
    /// Checks the settings (every count at least 1, a finite positive threshold); the
    /// error names the first bad one. [`evaluate`] calls it before any forecast.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, reason: &str| Err(Error::invalid_parameter(name, reason));
        if self.history == 0 {
            return bad("history", "must be at least 1, got 0");
        }
        if self.horizon == 0 {
            return bad("horizon", "must be at least 1, got 0");
        }
        if self.stride == 0 {
            return bad("stride", "must be at least 1, got 0");
        }
        if !(self.threshold.is_finite() && self.threshold > 0.0) {
            return bad(
                "threshold",
                &format!("must be finite and positive, got {}", self.threshold),
            );
        }
        if self.max_origins_per_trajectory == Some(0) {
            return bad(
                "max_origins_per_trajectory",
                "must be at least 1 (None for every origin), got 0",
            );
        }
        Ok(())
    }

    /// The forecast origins of a trajectory of `len` points.
    pub fn origins(&self, len: usize) -> impl Iterator<Item = usize> + use<> {
        let (start, h, stride) = (self.history - 1, self.horizon, self.stride);
        let max = self.max_origins_per_trajectory.unwrap_or(usize::MAX);
        (start..len.saturating_sub(h)).step_by(stride).take(max)
    }
}

/// Partial sums for one trajectory (or many, once merged).
#[derive(Debug, Clone, Default, PartialEq)]
struct Sums {
    forecasts: usize,
    failures: usize,
    first_failure: Option<String>,
    err: Vec<f64>,
    err_sq: Vec<f64>,
    hits: Vec<usize>,
}

impl Sums {
    fn new(h: usize) -> Self {
        Sums {
            err: vec![0.0; h],
            err_sq: vec![0.0; h],
            hits: vec![0; h],
            ..Default::default()
        }
    }

    fn merge(&mut self, o: Sums) {
        self.forecasts += o.forecasts;
        self.failures += o.failures;
        if self.first_failure.is_none() {
            self.first_failure = o.first_failure;
        }
        for k in 0..self.err.len() {
            self.err[k] += o.err[k];
            self.err_sq[k] += o.err_sq[k];
            self.hits[k] += o.hits[k];
        }
    }
}

/// Errors of one method, per forecast step and pooled over every step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodReport {
    /// The predictor's name.
    pub method: String,
    /// Trajectories evaluated (those long enough for at least one origin).
    pub trajectories: usize,
    /// Forecasts made.
    pub forecasts: usize,
    /// Forecasts the predictor refused with an error (counted, never silently dropped).
    pub failures: usize,
    /// The first of those errors, if any.
    pub first_failure: Option<String>,
    /// Mean Euclidean error at step k (k = 1..=horizon).
    pub mean_euclidean: Vec<f64>,
    /// Root mean square Euclidean error at step k.
    pub rms_euclidean: Vec<f64>,
    /// Share of step-k predictions within the threshold.
    pub hit_rate: Vec<f64>,
    /// Mean Euclidean error over every step of every forecast (ADE).
    pub mean_euclidean_all: f64,
    /// Hit rate over every step.
    pub hit_rate_all: f64,
    /// Wall time of fitting, seconds.
    pub fit_seconds: f64,
    /// Wall time of the forecasts, seconds.
    pub forecast_seconds: f64,
}

impl MethodReport {
    /// Forecasts per second of wall time.
    pub fn throughput(&self) -> f64 {
        self.forecasts as f64 / self.forecast_seconds.max(1e-12)
    }
}

/// The history the harness gives a predictor at `origin`: the `history` points ending at
/// `origin` (inclusive). Nothing after the origin is in it.
pub fn history_at(tr: &Trajectory, origin: usize, history: usize) -> Result<Trajectory> {
    let start = (origin + 1).checked_sub(history).ok_or(Error::TooShort {
        what: "trajectory before the origin",
        needed: history,
        got: origin + 1,
    })?;
    tr.slice(start..origin + 1)
}

/// Runs `p` at every origin of `tr` and hands `on` each origin's predicted and true points,
/// or why the forecast was refused (a failed history, an error, a forecast of the wrong
/// shape): the one loop both [`evaluate`] and [`collect_forecasts`] score through.
fn each_origin(
    p: &dyn Predictor,
    tr: &Trajectory,
    cfg: &EvalConfig,
    mut on: impl FnMut(std::result::Result<(Vec<Point>, Vec<Point>), String>),
) {
    for o in cfg.origins(tr.len()) {
        let history = match history_at(tr, o, cfg.history) {
            Ok(h) => h,
            Err(e) => {
                on(Err(e.to_string()));
                continue;
            }
        };
        let times = &tr.times()[o + 1..=o + cfg.horizon];
        on(match p.forecast_times(&history, times) {
            Ok(f) if f.horizon() == cfg.horizon && f.dim() == tr.dim() => {
                let predicted: Vec<Point> = f.points().collect();
                let truth: Vec<Point> = (1..=cfg.horizon).map(|k| tr.point(o + k)).collect();
                Ok((predicted, truth))
            }
            Ok(f) => Err(format!(
                "forecast of {} steps x {} axes, expected {} x {}",
                f.horizon(),
                f.dim(),
                cfg.horizon,
                tr.dim()
            )),
            Err(e) => Err(e.to_string()),
        });
    }
}

fn evaluate_one(p: &dyn Predictor, tr: &Trajectory, cfg: &EvalConfig) -> Sums {
    let mut s = Sums::new(cfg.horizon);
    each_origin(p, tr, cfg, |r| {
        // every error through trajpred-metrics; a non-finite forecast is a failure
        let scored = r.and_then(|(predicted, truth)| {
            trajpred_metrics::euclidean_errors(&predicted, &truth)
                .map_err(|e| format!("{}: {e}", p.name()))
        });
        match scored {
            Ok(errors) => {
                s.forecasts += 1;
                for (k, e) in errors.into_iter().enumerate() {
                    s.err[k] += e;
                    s.err_sq[k] += e * e;
                    s.hits[k] += usize::from(e < cfg.threshold);
                }
            }
            Err(why) => {
                s.failures += 1;
                s.first_failure.get_or_insert(why);
            }
        }
    });
    s
}

/// One origin's forecast and the true points it is scored against, `horizon` each.
pub type ForecastPair = (Vec<Point>, Vec<Point>);

/// What [`collect_forecasts`] gives: every origin's pair, or why one forecast was refused.
pub type Collected = std::result::Result<Vec<ForecastPair>, String>;

/// Every forecast `predictor` makes on `test` under `cfg`, beside the true points, in the
/// order of the trajectories and their origins (the same origins [`evaluate`] scores):
/// `forecasts[i] = (predicted, truth)`, `horizon` points each. What a method that combines
/// other methods' held-out forecasts learns from. The first refused or non-finite forecast
/// is returned as `Err` with its reason, since a combination cannot skip it.
pub fn collect_forecasts(
    predictor: &dyn Predictor,
    test: &[Trajectory],
    cfg: &EvalConfig,
) -> Result<Collected> {
    cfg.validate()?;
    let parts: Vec<_> = test
        .par_iter()
        .map(|tr| {
            let mut out = Vec::new();
            let mut failure = None;
            each_origin(predictor, tr, cfg, |r| match r {
                Ok((p, t)) if p.iter().all(|x| x.as_ref().iter().all(|c| c.is_finite())) => {
                    out.push((p, t))
                }
                Ok(_) => {
                    failure.get_or_insert_with(|| {
                        format!("{}: non-finite forecast", predictor.name())
                    });
                }
                Err(why) => {
                    failure.get_or_insert(why);
                }
            });
            failure.map_or(Ok(out), Err)
        })
        .collect();
    let mut all = Vec::new();
    for part in parts {
        match part {
            Ok(v) => all.extend(v),
            Err(why) => return Ok(Err(why)),
        }
    }
    Ok(Ok(all))
}

/// Number of trajectories evaluated in parallel at a time (and held in memory by
/// [`evaluate_stream`]).
pub const CHUNK: usize = 64;

/// Evaluates a fitted predictor on test trajectories. `progress` is called with the number of
/// trajectories done so far, after each chunk.
pub fn evaluate(
    predictor: &dyn Predictor,
    test: &[Trajectory],
    cfg: &EvalConfig,
    progress: Option<&(dyn Fn(usize) + Sync)>,
) -> Result<MethodReport> {
    evaluate_stream(predictor, test.iter().cloned().map(Ok), cfg, progress)
}

/// Like [`evaluate`], over a stream of trajectories (e.g. a loader reading one file at a
/// time), holding at most [`CHUNK`] of them in memory. The first stream error is returned.
pub fn evaluate_stream(
    predictor: &dyn Predictor,
    test: impl Iterator<Item = Result<Trajectory>>,
    cfg: &EvalConfig,
    progress: Option<&(dyn Fn(usize) + Sync)>,
) -> Result<MethodReport> {
    cfg.validate()?;
    let start = Instant::now();
    let mut total = Sums::new(cfg.horizon);
    let (mut done, mut used) = (0usize, 0usize);
    let mut chunk = Vec::with_capacity(CHUNK);
    let mut test = test.peekable();
    while test.peek().is_some() {
        chunk.clear();
        for tr in test.by_ref().take(CHUNK) {
            chunk.push(tr?);
        }
        let parts: Vec<Sums> = chunk
            .par_iter()
            .map(|tr| evaluate_one(predictor, tr, cfg))
            .collect();
        for part in parts {
            if part.forecasts + part.failures > 0 {
                used += 1;
            }
            total.merge(part);
        }
        done += chunk.len();
        if let Some(cb) = progress {
            cb(done);
        }
    }
    let n = total.forecasts as f64;
    let per = |v: &[f64]| -> Vec<f64> {
        v.iter()
            .map(|x| if n > 0.0 { x / n } else { f64::NAN })
            .collect()
    };
    let mean_euclidean = per(&total.err);
    let rms_euclidean = per(&total.err_sq).into_iter().map(f64::sqrt).collect();
    let hit_rate = total
        .hits
        .iter()
        .map(|&h| if n > 0.0 { h as f64 / n } else { f64::NAN })
        .collect();
    let all_n = n * cfg.horizon as f64;
    Ok(MethodReport {
        method: predictor.name().to_string(),
        trajectories: used,
        forecasts: total.forecasts,
        failures: total.failures,
        first_failure: total.first_failure,
        mean_euclidean,
        rms_euclidean,
        hit_rate,
        mean_euclidean_all: total.err.iter().sum::<f64>() / all_n,
        hit_rate_all: total.hits.iter().sum::<usize>() as f64 / all_n,
        fit_seconds: 0.0,
        forecast_seconds: start.elapsed().as_secs_f64(),
    })
}

/// Fits `predictor` on `train`, then evaluates it on `test`, timing both.
pub fn fit_and_evaluate(
    predictor: &mut dyn Predictor,
    train: &[Trajectory],
    test: &[Trajectory],
    cfg: &EvalConfig,
    progress: Option<&(dyn Fn(usize) + Sync)>,
) -> Result<MethodReport> {
    let t0 = Instant::now();
    predictor.fit(train)?;
    let fit_seconds = t0.elapsed().as_secs_f64();
    let mut report = evaluate(predictor, test, cfg, progress)?;
    report.fit_seconds = fit_seconds;
    Ok(report)
}

/// How to split trajectories into training and test sets.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Split {
    /// The first `train_fraction` of every trajectory trains, the rest tests.
    ByTime {
        /// Share of each trajectory's points used for training.
        train_fraction: f64,
    },
    /// A seeded random `train_fraction` of the trajectories (segments) trains, the others
    /// test. Segments of one trip or one user may land on both sides.
    ByTrajectory {
        /// Share of trajectories used for training.
        train_fraction: f64,
        /// Seed of the shuffle.
        seed: u64,
    },
    /// A seeded random `train_fraction` of the groups (users, vehicles, files: see
    /// [`Segment::group`]) trains, the others test: no user is on both sides, which is how
    /// a method meets new users' data. With at least two groups each side gets one.
    ByGroup {
        /// Share of groups used for training.
        train_fraction: f64,
        /// Seed of the shuffle.
        seed: u64,
    },
    /// No split: every segment is on both sides (exact repeats left out of each), and the
    /// caller takes one of them. Fitting on the whole of one dataset and testing on the
    /// whole of another (`trajpred fit --split none` here, `evaluate --split none --params`
    /// there) is how a model chosen on our users meets yours; evaluating with fitting on
    /// such a split would test on the training data, so [`crate::protocol::run`] refuses it.
    None,
}

impl Split {
    /// The split's name as the CLI spells it (`by-time`, `by-track`, `by-user`, `none`).
    pub fn label(&self) -> &'static str {
        match self {
            Split::ByTime { .. } => "by-time",
            Split::ByTrajectory { .. } => "by-track",
            Split::ByGroup { .. } => "by-user",
            Split::None => "none",
        }
    }

    /// The share that trains (`None` for [`Split::None`]).
    pub fn train_fraction(&self) -> Option<f64> {
        match *self {
            Split::ByTime { train_fraction }
            | Split::ByTrajectory { train_fraction, .. }
            | Split::ByGroup { train_fraction, .. } => Some(train_fraction),
            Split::None => None,
        }
    }

    /// The shuffle's seed (`None` for the splits that do not shuffle).
    pub fn seed(&self) -> Option<u64> {
        match *self {
            Split::ByTrajectory { seed, .. } | Split::ByGroup { seed, .. } => Some(seed),
            Split::ByTime { .. } | Split::None => None,
        }
    }
}

fn check_fraction(f: f64) -> Result<()> {
    if f > 0.0 && f < 1.0 {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "train_fraction",
            reason: format!("must be in (0, 1), got {f}"),
        })
    }
}

/// Splits trajectories into (train, test). Parts too short to form a trajectory are left
/// out, and so are exact repeats ([`drop_repeats`]). With [`Split::ByGroup`] every
/// trajectory is its own group.
pub fn split(
    trajectories: &[Trajectory],
    how: Split,
) -> Result<(Vec<Trajectory>, Vec<Trajectory>)> {
    let segments: Vec<Segment> = trajectories
        .iter()
        .enumerate()
        .map(|(i, t)| Segment {
            group: i.to_string(),
            id: i.to_string(),
            frame: trajpred_data::Frame::Cartesian,
            trajectory: t.clone(),
        })
        .collect();
    let (train, test) = split_segments(&segments, how)?;
    let take = |v: Vec<Segment>| v.into_iter().map(|s| s.trajectory).collect();
    Ok((take(train), take(test)))
}

/// Splits segments into (train, test) as `how` says, keeping their order within each side
/// for [`Split::ByTime`] and the shuffled order otherwise, then leaves out the segments that
/// repeat another exactly ([`drop_repeats`]; [`split_segments_counted`] says how many).
pub fn split_segments(segments: &[Segment], how: Split) -> Result<(Vec<Segment>, Vec<Segment>)> {
    split_segments_counted(segments, how).map(|(train, test, _)| (train, test))
}

/// [`split_segments`] with the count of the repeated segments it left out.
pub fn split_segments_counted(
    segments: &[Segment],
    how: Split,
) -> Result<(Vec<Segment>, Vec<Segment>, Repeats)> {
    if how == Split::None {
        // each side on its own: the test side is not compared with the training side
        let (train, _, r_train) = drop_repeats(segments.to_vec(), Vec::new());
        let (_, test, r_test) = drop_repeats(Vec::new(), segments.to_vec());
        let r = Repeats {
            train: r_train.train,
            test_of_train: 0,
            test: r_test.test,
        };
        return Ok((train, test, r));
    }
    let (train, test) = split_sides(segments, how)?;
    Ok(drop_repeats(train, test))
}

/// Segments left out of a split because they repeat another segment exactly: the same
/// frame, timestamps and points, whatever their group or id ([`drop_repeats`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Repeats {
    /// Training segments equal to an earlier training segment.
    pub train: usize,
    /// Test segments equal to a training segment (left out: they would test the methods on
    /// data they were fitted on).
    pub test_of_train: usize,
    /// Test segments equal to an earlier test segment (left out: they would count twice).
    pub test: usize,
}

impl Repeats {
    /// Segments left out in all.
    pub fn total(&self) -> usize {
        self.train + self.test_of_train + self.test
    }
}

/// A fingerprint of a segment's frame, timestamps and points (not its group or id): equal
/// for exact repeats, stable across runs, machines and builds (64-bit FNV-1a over the bits
/// of every number, little-endian), so that saved parameters can list the segments they
/// were fitted on and a later evaluation can leave them out of its test part
/// ([`crate::params::FittedOn::train_fingerprints`]).
pub fn segment_fingerprint(s: &Segment) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: u64| {
        for b in x.to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(PRIME);
        }
    };
    match s.frame {
        trajpred_data::Frame::Geodetic => eat(1),
        trajpred_data::Frame::Cartesian => eat(2),
        trajpred_data::Frame::Enu(o) => {
            eat(3);
            for v in [o.lat_deg, o.lon_deg, o.alt_m] {
                eat(v.to_bits());
            }
        }
    }
    eat(s.trajectory.len() as u64);
    eat(s.trajectory.dim() as u64);
    for t in s.trajectory.times() {
        eat(t.to_bits());
    }
    for axis in s.trajectory.axes() {
        for v in axis {
            eat(v.to_bits());
        }
    }
    h
}

/// Leaves out every segment that repeats another exactly (the same frame, timestamps and
/// points; groups and ids are not compared): a training segment equal to an earlier
/// training one, and a test segment equal to a training one or to an earlier test one. The
/// first copy stays; the order of the rest is kept.
///
/// Datasets hold such copies: in `../shared/data`'s GeoLife subset, users 058 and 059, 069
/// and 129, 081 and 136, 087 and 111, 108 and 139 share 28 files byte for byte (every file
/// of 059 is one of 058's), so a split by user may put one copy on each side and test the
/// methods on data they were fitted on.
///
/// ```
/// use trajpred::dataset::Segment;
/// use trajpred::harness::drop_repeats;
/// use trajpred_core::Trajectory;
/// use trajpred_data::Frame;
///
/// let seg = |group: &str, x0: f64| Segment {
///     group: group.into(),
///     id: group.into(),
///     frame: Frame::Cartesian,
///     trajectory: Trajectory::new(vec![0.0, 1.0], vec![[x0, 0.0], [x0 + 1.0, 0.0]]).unwrap(),
/// };
/// // user b's track is a copy of user a's; c's is its own
/// let (train, test, r) = drop_repeats(vec![seg("a", 0.0)], vec![seg("b", 0.0), seg("c", 5.0)]);
/// assert_eq!((train.len(), test.len(), r.test_of_train), (1, 1, 1));
/// assert_eq!(test[0].group, "c");
/// ```
pub fn drop_repeats(
    train: Vec<Segment>,
    test: Vec<Segment>,
) -> (Vec<Segment>, Vec<Segment>, Repeats) {
    let same = |a: &Segment, b: &Segment| a.frame == b.frame && a.trajectory == b.trajectory;
    // key -> kept segments with that key: (in training?, index in its side)
    let mut index: std::collections::HashMap<u64, Vec<(bool, usize)>> =
        std::collections::HashMap::new();
    let mut r = Repeats::default();
    let mut kept_train: Vec<Segment> = Vec::with_capacity(train.len());
    for s in train {
        let list = index.entry(segment_fingerprint(&s)).or_default();
        if list.iter().any(|&(_, i)| same(&kept_train[i], &s)) {
            r.train += 1;
        } else {
            list.push((true, kept_train.len()));
            kept_train.push(s);
        }
    }
    let mut kept_test: Vec<Segment> = Vec::with_capacity(test.len());
    for s in test {
        let list = index.entry(segment_fingerprint(&s)).or_default();
        let hit = list.iter().find(|&&(in_train, i)| {
            same(
                if in_train {
                    &kept_train[i]
                } else {
                    &kept_test[i]
                },
                &s,
            )
        });
        match hit {
            Some(&(true, _)) => r.test_of_train += 1,
            Some(_) => r.test += 1,
            None => {
                list.push((false, kept_test.len()));
                kept_test.push(s);
            }
        }
    }
    (kept_train, kept_test, r)
}

fn split_sides(segments: &[Segment], how: Split) -> Result<(Vec<Segment>, Vec<Segment>)> {
    use rand::SeedableRng;
    use rand::seq::SliceRandom;
    match how {
        // (split_segments_counted takes this one apart itself)
        Split::None => Ok((segments.to_vec(), segments.to_vec())),
        Split::ByTime { train_fraction } => {
            check_fraction(train_fraction)?;
            let (mut train, mut test) = (Vec::new(), Vec::new());
            for s in segments {
                let tr = &s.trajectory;
                let cut = (tr.len() as f64 * train_fraction).round() as usize;
                let part = |t: Trajectory| Segment {
                    trajectory: t,
                    ..s.clone()
                };
                if cut >= 1 {
                    train.push(part(tr.slice(0..cut.min(tr.len()))?));
                }
                if cut < tr.len() {
                    test.push(part(tr.slice(cut..tr.len())?));
                }
            }
            Ok((train, test))
        }
        Split::ByTrajectory {
            train_fraction,
            seed,
        } => {
            check_fraction(train_fraction)?;
            let mut idx: Vec<usize> = (0..segments.len()).collect();
            idx.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
            let cut = (segments.len() as f64 * train_fraction).round() as usize;
            let pick = |ix: &[usize]| ix.iter().map(|&i| segments[i].clone()).collect();
            Ok((pick(&idx[..cut]), pick(&idx[cut..])))
        }
        Split::ByGroup {
            train_fraction,
            seed,
        } => {
            check_fraction(train_fraction)?;
            let mut groups: Vec<&str> = segments.iter().map(|s| s.group.as_str()).collect();
            groups.sort_unstable();
            groups.dedup();
            groups.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
            let n = groups.len();
            if n < 2 {
                return Err(Error::InvalidParameter {
                    name: "split",
                    reason: format!(
                        "a split by group (user, vehicle) needs segments of at least 2 groups, \
                         got {n}{}",
                        groups.first().map_or(String::new(), |g| format!(" ({g})"))
                    ),
                });
            }
            let cut = ((n as f64 * train_fraction).round() as usize).clamp(1, n - 1);
            let train_groups: std::collections::HashSet<&str> =
                groups[..cut].iter().copied().collect();
            let (train, test): (Vec<Segment>, Vec<Segment>) = segments
                .iter()
                .cloned()
                .partition(|s| train_groups.contains(s.group.as_str()));
            Ok((train, test))
        }
    }
}

/// The group of each segment as a dense id: the groups' names ([`Segment::group`]) sorted,
/// numbered from 0. What [`Predictor::fit_grouped`] is given by the evaluation path.
pub fn group_ids(segments: &[Segment]) -> Vec<usize> {
    let mut names: Vec<&str> = segments.iter().map(|s| s.group.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    segments
        .iter()
        .map(|s| names.binary_search(&s.group.as_str()).unwrap_or(0))
        .collect()
}

/// Deals `groups` distinct group labels into `folds` folds for cross-validation by group: the
/// labels are sorted, shuffled with `seed` and dealt round-robin, so fold sizes (in groups)
/// differ by at most one. Returns, for each label in sorted order, its fold. Needs
/// `2 <= folds <= groups`.
pub fn group_folds(groups: usize, folds: usize, seed: u64) -> Result<Vec<usize>> {
    use rand::SeedableRng;
    use rand::seq::SliceRandom;
    if folds < 2 || folds > groups {
        return Err(Error::InvalidParameter {
            name: "folds",
            reason: format!("must be between 2 and the number of groups ({groups}), got {folds}"),
        });
    }
    let mut order: Vec<usize> = (0..groups).collect();
    order.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
    let mut fold = vec![0; groups];
    for (i, &g) in order.iter().enumerate() {
        fold[g] = i % folds;
    }
    Ok(fold)
}
