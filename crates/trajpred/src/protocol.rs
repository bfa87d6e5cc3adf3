//! The papers' evaluation protocols as presets: one value says how to segment, split, fit and
//! forecast, and one function runs it. `trajpred evaluate --protocol NAME` and the
//! reproduction (`cargo xtask reproduce`) both call [`run`] on a [`preset`], so the table the
//! command line prints is the table the reproduction writes.
//!
//! A protocol is data ([`Protocol`]); [`presets`] lists the ones we ship and `trajpred
//! protocols` prints them with their parameters. A protocol with several history lengths
//! forecasts from the same origins at every history when [`Protocol::same_origins`] is set
//! (each test segment is trimmed so that its first origin is the longest history's), so the
//! columns of a table differ only by the history.
//!
//! ```
//! use trajpred::protocol::{self, Protocol};
//! let p = protocol::preset("kf-dynamic-geolife", protocol::DEFAULT_SEED, false)?;
//! assert_eq!(p.segmentation.max_gap, Some(5.0));
//! assert_eq!(p.histories, vec![10, 20, 30, 40, 50]);
//! assert_eq!(p.segmentation.min_points, 55);
//! # Ok::<(), trajpred_core::Error>(())
//! ```

use crate::dataset::{Dataset, Segment, Segmentation};
use crate::harness::{self, EvalConfig, MethodReport, Split};
use crate::registry::{MethodOptions, build};
use std::fmt::Write as _;
use std::time::Instant;
use trajpred_core::{Error, Predictor, Result, Trajectory};
use trajpred_data::LoadOptions;

/// Base seed of the presets (the reproduction's default): every random choice derives from it.
pub const DEFAULT_SEED: u64 = 20260611;

/// A method of a protocol: the registry name it is built from, with its options, and the label
/// its rows carry.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodSpec {
    /// Row label in tables.
    pub label: String,
    /// Name in the registry ([`crate::registry::build`]).
    pub name: String,
    /// Options it is built with.
    pub options: MethodOptions,
}

/// An evaluation protocol: what a paper (or a user) runs on one dataset.
#[derive(Debug, Clone, PartialEq)]
pub struct Protocol {
    /// Its name (`trajpred evaluate --protocol NAME`).
    pub name: String,
    /// One line: where it comes from and what it measures.
    pub description: String,
    /// The dataset format it reads.
    pub dataset: Dataset,
    /// How the loaders clean and project.
    pub load_options: LoadOptions,
    /// Read at most this many units (users, taxis, files), in sorted order.
    pub max_units: Option<usize>,
    /// How tracks become segments.
    pub segmentation: Segmentation,
    /// How the training users' tracks become the segments the methods are fitted on, when
    /// not as [`segmentation`](Self::segmentation) (`None`): e.g. a longer gap gives more
    /// training origins from the same users ([`split_with_pool`]). The test part is always
    /// cut by `segmentation`. Only with a split by group or none.
    pub train_segmentation: Option<Segmentation>,
    /// How segments are split into training and test parts.
    pub split: Split,
    /// Keep at most this many training segments (after the split's shuffle).
    pub max_train: Option<usize>,
    /// Keep at most this many test segments (after the split's shuffle).
    pub max_test: Option<usize>,
    /// History lengths, one column each.
    pub histories: Vec<usize>,
    /// Steps forecast at each origin.
    pub horizon: usize,
    /// Points between origins.
    pub stride: usize,
    /// At most this many origins per test segment.
    pub max_origins: Option<usize>,
    /// Hit threshold, metres.
    pub threshold: f64,
    /// Forecast from the same origins at every history (see the module docs).
    pub same_origins: bool,
    /// The methods, one row each.
    pub methods: Vec<MethodSpec>,
}

/// A protocol of one history with every method built under the same options, and the rest as
/// `trajpred evaluate` has it by default (stride 1, every origin, 25 m, no caps): what the
/// command line builds when no preset is named (`evaluate` and `fit` alike, so the same
/// options give the same split).
pub fn custom(
    dataset: Dataset,
    names: &[&str],
    options: &MethodOptions,
    segmentation: Segmentation,
    split: Split,
    history: usize,
    horizon: usize,
) -> Protocol {
    Protocol {
        name: "custom".into(),
        description: "from the command line".into(),
        dataset,
        load_options: dataset.options(),
        max_units: None,
        segmentation,
        train_segmentation: None,
        split,
        max_train: None,
        max_test: None,
        histories: vec![history],
        horizon,
        stride: 1,
        max_origins: None,
        threshold: 25.0,
        same_origins: false,
        methods: names
            .iter()
            .map(|n| MethodSpec {
                label: n.to_string(),
                name: n.to_string(),
                options: options.clone(),
            })
            .collect(),
    }
}

/// The names of the presets, in the order [`presets`] returns them.
pub const PRESETS: [&str; 2] = ["kf-dynamic-geolife", "kf-dynamic-tdrive"];

/// KF-dynamic paper: the history lengths of its Table 1.
const KF_DYNAMIC_HISTORIES: [usize; 5] = [10, 20, 30, 40, 50];

/// The KF-dynamic paper's methods: KF dynamic and the naive KF with both parameter sets of its
/// Table 1, the HMM, and the 5-point linear and quadratic fits. KF dynamic is the paper's
/// multi-step rule read literally (`kf-dynamic-literal`, `kf-dynamic-4d-literal`: every step
/// re-uses the last observation), as the reproduction reports it.
fn kf_dynamic_methods(seed: u64) -> Vec<MethodSpec> {
    let with = |kf_q: f64| MethodOptions {
        kf_q,
        poly_points: 5,
        seed,
        ..MethodOptions::default()
    };
    let spec = |label: &str, name: &str, options: MethodOptions| MethodSpec {
        label: label.to_string(),
        name: name.to_string(),
        options,
    };
    vec![
        spec(
            "KF dynamic (2-D obs., R = 10 I, Q = 10 I)",
            "kf-dynamic-literal",
            with(10.0),
        ),
        spec(
            "KF dynamic (4-D obs., R = 1 I, Q = 100 I)",
            "kf-dynamic-4d-literal",
            with(100.0),
        ),
        spec(
            "naive KF (2-D obs., R = 10 I, Q = 10 I)",
            "naive-kf",
            with(10.0),
        ),
        spec(
            "naive KF (4-D obs., R = 1 I, Q = 100 I)",
            "naive-kf-4d",
            with(100.0),
        ),
        spec("HMM", "hmm", with(10.0)),
        spec("5-point linear", "poly1", with(10.0)),
        spec("5-point quadratic", "poly2", with(10.0)),
    ]
}

/// The preset called `name`, seeded from `seed`; `quick` is the reduced version the quick
/// reproduction and CI run (fewer units, segments and origins).
pub fn preset(name: &str, seed: u64, quick: bool) -> Result<Protocol> {
    let max_h = KF_DYNAMIC_HISTORIES[KF_DYNAMIC_HISTORIES.len() - 1];
    let horizon = 5;
    let base = |dataset: Dataset, max_gap: f64, ds_seed: u64, max_units: usize| Protocol {
        name: name.to_string(),
        description: String::new(),
        dataset,
        load_options: dataset.options(),
        max_units: quick.then_some(max_units),
        segmentation: Segmentation {
            max_gap: Some(max_gap),
            min_points: max_h + horizon,
            ..Segmentation::default()
        },
        train_segmentation: None,
        split: Split::ByTrajectory {
            train_fraction: 0.3,
            seed: ds_seed,
        },
        max_train: Some(if quick { 24 } else { 400 }),
        max_test: Some(if quick { 24 } else { 800 }),
        histories: KF_DYNAMIC_HISTORIES.to_vec(),
        horizon,
        stride: 10,
        max_origins: Some(if quick { 4 } else { 8 }),
        threshold: 25.0,
        same_origins: true,
        methods: kf_dynamic_methods(ds_seed),
    };
    match name {
        "kf-dynamic-geolife" => Ok(Protocol {
            description: "KF-dynamic paper on GeoLife: split where fixes are more than 5 s apart, \
                          segments of at least 55 points, histories 10..50, 5 steps, 25 m"
                .into(),
            ..base(Dataset::Geolife, 5.0, seed ^ 0x6765_6f6c, 6)
        }),
        "kf-dynamic-tdrive" => Ok(Protocol {
            description: "KF-dynamic paper on T-Drive: split where fixes are more than 300 s \
                          apart (the paper's 5 s leaves nothing), segments of at least 55 points, \
                          histories 10..50, 5 steps, 25 m"
                .into(),
            ..base(Dataset::Tdrive, 300.0, seed ^ 0x7464_7276, 40)
        }),
        _ => Err(Error::InvalidParameter {
            name: "protocol",
            reason: format!("unknown protocol `{name}`; known: {}", PRESETS.join(", ")),
        }),
    }
}

/// Every preset, seeded from `seed`.
pub fn presets(seed: u64, quick: bool) -> Result<Vec<Protocol>> {
    PRESETS.iter().map(|n| preset(n, seed, quick)).collect()
}

impl Protocol {
    /// Checks the settings; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        self.segmentation.validate()?;
        if let Some(t) = &self.train_segmentation {
            t.validate()?;
            if !matches!(self.split, Split::ByGroup { .. } | Split::None) {
                return Err(Error::InvalidParameter {
                    name: "train_segmentation",
                    reason: "a training segmentation needs a split by group (user, vehicle) or                              none: split by track, another cut of a test track could train"
                        .into(),
                });
            }
        }
        let max_h = self.histories.iter().copied().max().ok_or(Error::Empty {
            what: "protocol histories",
        })?;
        if self.methods.is_empty() {
            return Err(Error::Empty {
                what: "protocol methods",
            });
        }
        for &h in &self.histories {
            self.config(h).validate()?;
        }
        if self.same_origins && self.segmentation.min_points < max_h + self.horizon {
            return Err(Error::InvalidParameter {
                name: "min_points",
                reason: format!(
                    "the same origins at every history need segments of at least {} points \
                     (the longest history + the horizon), got {}",
                    max_h + self.horizon,
                    self.segmentation.min_points
                ),
            });
        }
        Ok(())
    }

    /// The evaluation settings at history `h`.
    pub fn config(&self, h: usize) -> EvalConfig {
        EvalConfig {
            history: h,
            horizon: self.horizon,
            stride: self.stride,
            threshold: self.threshold,
            max_origins_per_trajectory: self.max_origins,
        }
    }

    /// The test trajectories as history `h` sees them: with [`Self::same_origins`], trimmed
    /// so that the first origin is the longest history's.
    pub fn test_at(&self, test: &[Segment], h: usize) -> Result<Vec<Trajectory>> {
        let max_h = self.histories.iter().copied().max().unwrap_or(h);
        let skip = if self.same_origins {
            max_h.saturating_sub(h)
        } else {
            0
        };
        test.iter()
            .map(|s| s.trajectory.slice(skip..s.trajectory.len()))
            .collect()
    }

    /// The parameters, one `name: value` line each (what `trajpred protocols` prints).
    pub fn describe(&self) -> String {
        let mut s = String::new();
        let opt = |v: Option<usize>| v.map_or("all".to_string(), |n| n.to_string());
        let _ = writeln!(s, "{}: {}", self.name, self.description);
        let _ = writeln!(s, "  dataset: {}", self.dataset);
        let _ = writeln!(
            s,
            "  segmentation: max gap {} s, at least {} points{}",
            self.segmentation
                .max_gap
                .map_or("none".to_string(), |g| g.to_string()),
            self.segmentation.min_points,
            self.segmentation
                .resample
                .map_or(String::new(), |dt| format!(", resampled every {dt} s")),
        );
        if let Some(t) = &self.train_segmentation {
            let gap = t.max_gap.map_or("none".to_string(), |g| g.to_string());
            let _ = writeln!(s, "  training tracks cut at: max gap {gap} s");
        }
        let (fraction, seed) = (self.split.train_fraction(), self.split.seed());
        let _ = writeln!(
            s,
            "  split: {}{}{}, at most {} training and {} test segments",
            self.split.label(),
            fraction.map_or(String::new(), |f| format!(", training share {f}")),
            seed.map_or(String::new(), |x| format!(", seed {x}")),
            opt(self.max_train),
            opt(self.max_test),
        );
        let _ = writeln!(
            s,
            "  histories {:?}, horizon {}, origins {} apart, at most {} per segment{}, \
             threshold {} m",
            self.histories,
            self.horizon,
            self.stride,
            opt(self.max_origins),
            if self.same_origins {
                " (the same origins at every history)"
            } else {
                ""
            },
            self.threshold,
        );
        let _ = writeln!(s, "  units read: {}", opt(self.max_units));
        let names: Vec<&str> = self.methods.iter().map(|m| m.name.as_str()).collect();
        let _ = writeln!(s, "  methods: {}", names.join(", "));
        s
    }
}

/// Progress of a protocol run. Every method has a default that does nothing.
pub trait Progress: Sync {
    /// A stage begins (`fit <method>`, `forecast <method>`) with `total` units of work.
    fn start(&self, _stage: &str, _total: u64) {}
    /// `n` more units of the current stage are done.
    fn advance(&self, _n: u64) {}
    /// The current stage is over.
    fn finish(&self) {}
}

/// No progress reporting.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {}

/// A protocol's results: per method and history, the harness's report.
pub struct ProtocolRun {
    /// The protocol's name.
    pub protocol: String,
    /// Row labels, in the protocol's order.
    pub labels: Vec<String>,
    /// History lengths, in the protocol's order.
    pub histories: Vec<usize>,
    /// `reports[m][h]`: method `m` at history `histories[h]`.
    pub reports: Vec<Vec<MethodReport>>,
    /// The fitted methods, in the protocol's order.
    pub predictors: Vec<Box<dyn Predictor>>,
    /// Wall time of each method's fit, seconds.
    pub fit_seconds: Vec<f64>,
    /// The training segments used.
    pub train: Vec<Segment>,
    /// The test segments used.
    pub test: Vec<Segment>,
    /// Segments the split left out for repeating another ([`harness::drop_repeats`]).
    pub repeats: harness::Repeats,
}

fn mean(v: impl IntoIterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for x in v {
        s += x;
        n += 1;
    }
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// The (training, test) segments of `protocol`: its split (repeated segments left out,
/// [`harness::drop_repeats`]), then its caps. What [`run`] fits and tests on, and what
/// `trajpred fit` fits on.
pub fn split(protocol: &Protocol, segments: &[Segment]) -> Result<(Vec<Segment>, Vec<Segment>)> {
    split_counted(protocol, segments).map(|(train, test, _)| (train, test))
}

/// [`split`] with the count of the repeated segments left out. Errors for a protocol with a
/// [training segmentation](Protocol::train_segmentation): see [`split_with_pool`].
pub fn split_counted(
    protocol: &Protocol,
    segments: &[Segment],
) -> Result<(Vec<Segment>, Vec<Segment>, harness::Repeats)> {
    split_with_pool(protocol, segments, None)
}

/// [`split_counted`] for a protocol with a [training
/// segmentation](Protocol::train_segmentation): `pool` is the tracks cut by it (`None`
/// without one). The split (and its test part) is made on `segments`, cut by the
/// protocol's segmentation; the training part is then the segments of `pool` that belong
/// to the training part's groups (every one of `pool` for [`Split::None`]), exact repeats
/// left out, [`Protocol::max_train`] applied. Errors when `pool` is given without a
/// training segmentation or missing with one.
pub fn split_with_pool(
    protocol: &Protocol,
    segments: &[Segment],
    pool: Option<&[Segment]>,
) -> Result<(Vec<Segment>, Vec<Segment>, harness::Repeats)> {
    let (mut train, mut test, repeats) = harness::split_segments_counted(segments, protocol.split)?;
    match (&protocol.train_segmentation, pool) {
        (None, None) => {}
        (Some(_), Some(pool)) => {
            let groups: std::collections::HashSet<&str> =
                train.iter().map(|s| s.group.as_str()).collect();
            let mine: Vec<Segment> = pool
                .iter()
                .filter(|s| protocol.split == Split::None || groups.contains(s.group.as_str()))
                .cloned()
                .collect();
            train = harness::drop_repeats(mine, Vec::new()).0;
        }
        (t, _) => {
            return Err(Error::InvalidParameter {
                name: "train_segmentation",
                reason: if t.is_some() {
                    "the protocol cuts its training tracks differently: split with the \
                     segments that cut makes (`split_with_pool`)"
                } else {
                    "segments to train on were given for a protocol without a training \
                     segmentation"
                }
                .into(),
            });
        }
    }
    if let Some(n) = protocol.max_train {
        train.truncate(n);
    }
    if let Some(n) = protocol.max_test {
        test.truncate(n);
    }
    Ok((train, test, repeats))
}

/// Makes the predictor of a method for [`run_with`], given the training trajectories and
/// their groups (users, vehicles; one label per trajectory).
pub type Fitter<'a> =
    dyn Fn(&MethodSpec, &[Trajectory], &[usize]) -> Result<Box<dyn Predictor>> + 'a;

/// Builds the method and fits it, telling it the training segments' groups
/// ([`Predictor::fit_grouped`]): what [`run`] and [`cross_validate`] do.
pub fn build_and_fit(
    m: &MethodSpec,
    train: &[Trajectory],
    groups: &[usize],
) -> Result<Box<dyn Predictor>> {
    let mut p = build(&m.name, &m.options)?;
    p.fit_grouped(train, groups)?;
    Ok(p)
}

/// Splits, fits and evaluates `segments` as `protocol` says.
pub fn run(
    protocol: &Protocol,
    segments: &[Segment],
    progress: &dyn Progress,
) -> Result<ProtocolRun> {
    if protocol.split == Split::None {
        return Err(Error::InvalidParameter {
            name: "split",
            reason: "`none` puts every segment on both sides: fitting and testing on it would \
                     test the methods on their training data (fit on other data and evaluate \
                     with the saved parameters instead)"
                .into(),
        });
    }
    run_with(protocol, segments, progress, &build_and_fit)
}

/// [`run`] with the predictors made by `fitter` (e.g. loaded from saved parameters instead
/// of fitted); its time is reported as the fit time.
pub fn run_with(
    protocol: &Protocol,
    segments: &[Segment],
    progress: &dyn Progress,
    fitter: &Fitter<'_>,
) -> Result<ProtocolRun> {
    protocol.validate()?;
    let (train, test, repeats) = split_counted(protocol, segments)?;
    run_split(
        protocol,
        segments.len(),
        (train, test, repeats),
        progress,
        fitter,
    )
}

/// [`run_with`] on a split already made (by [`split_counted`], then perhaps trimmed, as
/// `evaluate --params` trims the segments its parameters were fitted on): makes each
/// method's predictor with `fitter` from `train` and its groups and evaluates on `test`.
/// `segments` (how many there were before the split) only words the error for an empty
/// test part.
pub fn run_split(
    protocol: &Protocol,
    segments: usize,
    (train, test, repeats): (Vec<Segment>, Vec<Segment>, harness::Repeats),
    progress: &dyn Progress,
    fitter: &Fitter<'_>,
) -> Result<ProtocolRun> {
    if test.is_empty() {
        return Err(Error::InvalidParameter {
            name: "segments",
            reason: format!(
                "{} segments of at least {} points: too few for a test part{}",
                segments,
                protocol.segmentation.min_points,
                match repeats.test_of_train + repeats.test {
                    0 => String::new(),
                    n =>
                        format!(" ({n} test segments left out as exact repeats of other segments)"),
                }
            ),
        });
    }
    let train_tr: Vec<Trajectory> = train.iter().map(|s| s.trajectory.clone()).collect();
    let groups = harness::group_ids(&train);
    let mut predictors = Vec::with_capacity(protocol.methods.len());
    let mut fit_seconds = Vec::with_capacity(protocol.methods.len());
    for m in &protocol.methods {
        progress.start(&format!("fit {}", m.name), 1);
        let t0 = Instant::now();
        let p = fitter(m, &train_tr, &groups)?;
        fit_seconds.push(t0.elapsed().as_secs_f64());
        progress.finish();
        predictors.push(p);
    }
    let tests: Vec<Vec<Trajectory>> = protocol
        .histories
        .iter()
        .map(|&h| protocol.test_at(&test, h))
        .collect::<Result<_>>()?;
    let mut reports = Vec::with_capacity(predictors.len());
    for (p, m) in predictors.iter().zip(&protocol.methods) {
        let total = (tests.len() * test.len()) as u64;
        progress.start(&format!("forecast {}", m.name), total);
        let mut row = Vec::with_capacity(protocol.histories.len());
        for (&h, t) in protocol.histories.iter().zip(&tests) {
            let before = std::sync::atomic::AtomicU64::new(0);
            let cb = |done: usize| {
                let prev = before.swap(done as u64, std::sync::atomic::Ordering::Relaxed);
                progress.advance((done as u64).saturating_sub(prev));
            };
            row.push(harness::evaluate(
                p.as_ref(),
                t,
                &protocol.config(h),
                Some(&cb),
            )?);
        }
        progress.finish();
        reports.push(row);
    }
    Ok(ProtocolRun {
        protocol: protocol.name.clone(),
        labels: protocol.methods.iter().map(|m| m.label.clone()).collect(),
        histories: protocol.histories.clone(),
        reports,
        predictors,
        fit_seconds,
        train,
        test,
        repeats,
    })
}

/// Cross-validation by group: the groups (users, vehicles) of `segments` are dealt into
/// `folds` folds ([`harness::group_folds`], seeded by `seed`); each fold's segments are the
/// test part once, with the other folds' segments training. The protocol's own split and
/// `max_train` are not used (every other fold trains); repeated segments are left out of
/// each fold ([`harness::drop_repeats`]) and `max_test` still bounds each test part. One
/// [`ProtocolRun`] per fold, in fold order.
pub fn cross_validate(
    protocol: &Protocol,
    segments: &[Segment],
    folds: usize,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<ProtocolRun>> {
    protocol.validate()?;
    let ids = harness::group_ids(segments);
    let groups = ids.iter().copied().max().map_or(0, |m| m + 1);
    let fold_of = harness::group_folds(groups, folds, seed)?;
    (0..folds)
        .map(|f| {
            let (mut test, mut train) = (Vec::new(), Vec::new());
            for (s, &g) in segments.iter().zip(&ids) {
                if fold_of[g] == f {
                    test.push(s.clone());
                } else {
                    train.push(s.clone());
                }
            }
            let (train, mut test, repeats) = harness::drop_repeats(train, test);
            if let Some(n) = protocol.max_test {
                test.truncate(n);
            }
            run_split(
                protocol,
                segments.len(),
                (train, test, repeats),
                progress,
                &build_and_fit,
            )
        })
        .collect()
}

impl ProtocolRun {
    /// Mean Euclidean error of method `m` over every step and history (metres).
    pub fn error(&self, m: usize) -> f64 {
        mean(self.reports[m].iter().map(|r| r.mean_euclidean_all))
    }

    /// Share of forecasts within the threshold (percent), over every step and history.
    pub fn accuracy(&self, m: usize) -> f64 {
        100.0 * mean(self.reports[m].iter().map(|r| r.hit_rate_all))
    }

    /// Root mean square Euclidean error over every step and history.
    pub fn rmse(&self, m: usize) -> f64 {
        mean(
            self.reports[m]
                .iter()
                .flat_map(|r| r.rms_euclidean.iter().map(|x| x * x)),
        )
        .sqrt()
    }

    /// Mean Euclidean error at step `k` (from 0), over histories.
    pub fn step_error(&self, m: usize, k: usize) -> f64 {
        mean(self.reports[m].iter().map(|r| r.mean_euclidean[k]))
    }

    /// Accuracy (percent) at step `k` (from 0), over histories.
    pub fn step_accuracy(&self, m: usize, k: usize) -> f64 {
        100.0 * mean(self.reports[m].iter().map(|r| r.hit_rate[k]))
    }

    /// Forecasts that failed, per method, over every history.
    pub fn failures(&self, m: usize) -> usize {
        self.reports[m].iter().map(|r| r.failures).sum()
    }

    /// The error table against history length, as the reproduction writes it: per method the
    /// mean error at each history, their mean, the RMSE over everything, and the accuracy.
    pub fn history_table(&self) -> HistoryTable {
        let mut columns: Vec<String> = self.histories.iter().map(|h| format!("h = {h}")).collect();
        columns.extend(["mean".into(), "RMSE (all)".into(), "accuracy (%)".into()]);
        let rows = (0..self.labels.len())
            .map(|m| {
                let mut v: Vec<f64> = self.reports[m]
                    .iter()
                    .map(|r| r.mean_euclidean_all)
                    .collect();
                v.extend([self.error(m), self.rmse(m), self.accuracy(m)]);
                (self.labels[m].clone(), v)
            })
            .collect();
        HistoryTable { columns, rows }
    }
}

/// A table of numbers with labelled rows.
#[derive(Debug, Clone, PartialEq)]
pub struct HistoryTable {
    /// Column headers (after the label column).
    pub columns: Vec<String>,
    /// (label, one value per column).
    pub rows: Vec<(String, Vec<f64>)>,
}

impl HistoryTable {
    /// As Markdown, with `digits` decimals.
    pub fn markdown(&self, digits: usize) -> String {
        let mut s = format!("| method | {} |\n", self.columns.join(" | "));
        let _ = writeln!(s, "|---|{}", "---:|".repeat(self.columns.len()));
        for (label, v) in &self.rows {
            let cells: Vec<String> = v.iter().map(|x| format!("{x:.digits$}")).collect();
            let _ = writeln!(s, "| {label} | {} |", cells.join(" | "));
        }
        s
    }

    /// As CSV, with full precision.
    pub fn csv(&self) -> String {
        let mut s = format!("method,{}\n", self.columns.join(","));
        for (label, v) in &self.rows {
            let cells: Vec<String> = v.iter().map(|x| x.to_string()).collect();
            let _ = writeln!(s, "\"{label}\",{}", cells.join(","));
        }
        s
    }
}
