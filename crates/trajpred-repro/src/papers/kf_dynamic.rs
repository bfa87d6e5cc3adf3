//! Dynamic trajectory prediction with a Kalman filter (Qiao et al., Acta Electronica Sinica
//! 46(2), 2018; `docs/papers.md` B.4).
//!
//! On GeoLife and on T-Drive (each read from [`Context::data`]; when one is absent its
//! experiments are listed in [`PaperResult::missing`] and the rest still runs):
//!
//! - methods: KF dynamic and naive KF with both parameter sets of the paper's Table 1, the HMM
//!   (fitted on a seeded training part disjoint from the test trajectories), and the N-point
//!   linear and quadratic fits (N = 5);
//! - the mean Euclidean error (the paper's "RMSE", def. 3) and the accuracy (share of
//!   predictions closer than 25 m) against the history length 10..50 and the step 1..5;
//! - the run time against the number of test trajectories (seeded random test sets of
//!   increasing size, up to what the subset holds);
//! - the paper's four reported figures beside ours, and its claims decided from the run.
//!
//! Every history length forecasts from the same origins (the test trajectories are trimmed so
//! that the first origin is the 50th point for every history), so the rows of a table differ
//! only by the method or the history. See `docs/kf-dynamic.md`.

use crate::report::{Figure, PaperResult, Table, Value};
use crate::{Context, ReproError, Result};
use rand::SeedableRng;
use rand::seq::SliceRandom;
use std::path::{Path, PathBuf};
use trajpred::dataset::{self, Segment, Segmentation};
use trajpred::harness::{self, EvalConfig, MethodReport, Split};
use trajpred::plot::{Chart, Series};
use trajpred::predictors::{KfDynamic, KfDynamicParams, NaiveKf};
use trajpred::protocol::{self, Protocol, ProtocolRun};
use trajpred::{Predictor, Trajectory};
use trajpred_data::LoadReport;

mod claims;
mod tables;

use claims::claims;
use tables::{headline, tables_and_figures};

/// History lengths of the paper's Table 1.
const HISTORIES: [usize; 5] = [10, 20, 30, 40, 50];
/// Forecast steps 1..=HORIZON.
const HORIZON: usize = 5;
/// Points fitted by the N-point baselines.
const POLY_POINTS: usize = 5;
/// The paper's limit on the sampling interval, seconds.
const PAPER_MAX_INTERVAL_S: f64 = 5.0;
/// History length of the run-time experiment.
const TIMING_HISTORY: usize = 20;
/// Increasing test-set sizes of the run-time experiment (k/TIMING_SIZES of the test pool).
const TIMING_SIZES: usize = 5;
/// Paper: GeoLife average error of KF dynamic, metres.
const PAPER_GEOLIFE_ERROR_M: f64 = 12.5;
/// Paper: GeoLife accuracy of KF dynamic, percent ("about 88%").
const PAPER_GEOLIFE_ACCURACY_PCT: f64 = 88.0;
/// Paper: T-Drive, fitting methods' error minus KF dynamic's, metres.
const PAPER_TDRIVE_ERROR_GAIN_M: f64 = 555.4;
/// Paper: T-Drive, KF dynamic's accuracy minus the fitting methods', points.
const PAPER_TDRIVE_ACCURACY_GAIN_PTS: f64 = 7.1;
/// Tolerance of `--check` on our errors and accuracies (seeded, deterministic run).
const REL_TOL: f64 = 1e-9;
/// "About" in the claims on the paper's GeoLife figures: relative band on the error.
const ABOUT_ERROR_REL: f64 = 0.2;
/// "About" on the accuracy: band in percentage points.
const ABOUT_ACCURACY_PTS: f64 = 5.0;

/// Name of the accuracy metric in titles.
const ACCURACY_KIND: &str = "accuracy (error < 25 m)";
/// The longest history; every segment must hold it plus the horizon.
const MAX_HISTORY: usize = 50;
/// Points a segment needs: the longest history and the horizon.
const MIN_POINTS: usize = MAX_HISTORY + HORIZON;
/// Points the shortest history needs (for the count at the paper's 5 s limit).
const MIN_POINTS_SHORTEST: usize = 10 + HORIZON;

/// What this runner adds to the protocol presets: the run-time experiment's origins.
#[derive(Debug, Clone, Copy)]
struct Budget {
    /// Origins per test trajectory in the run-time experiment.
    timing_origins: usize,
}

impl Budget {
    fn new(quick: bool) -> Self {
        Budget {
            timing_origins: if quick { 2 } else { 4 },
        }
    }
}

/// One of the two datasets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ds {
    Geolife,
    Tdrive,
}

impl Ds {
    fn folder(self) -> &'static str {
        match self {
            Ds::Geolife => "geolife",
            Ds::Tdrive => "tdrive",
        }
    }
    fn label(self) -> &'static str {
        match self {
            Ds::Geolife => "GeoLife",
            Ds::Tdrive => "T-Drive",
        }
    }
    /// The protocol preset this dataset runs (segmentation, split, histories, methods).
    fn protocol(self, ctx: &Context) -> Result<Protocol> {
        let name = match self {
            Ds::Geolife => "kf-dynamic-geolife",
            Ds::Tdrive => "kf-dynamic-tdrive",
        };
        protocol::preset(name, ctx.seed, ctx.quick).map_err(experiment_err("protocol"))
    }
}

/// A method of the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Method {
    /// KF dynamic, parameter set 1: 2-D observation, R = diag(10, 10), Q = 10 I.
    KfDyn1,
    /// KF dynamic, parameter set 2: 4-D observation, R = I_4, Q = 100 I.
    KfDyn2,
    /// Naive KF, set 1.
    Naive1,
    /// Naive KF, set 2.
    Naive2,
    /// HMM.
    Hmm,
    /// N-point linear fit.
    Poly1,
    /// N-point quadratic fit.
    Poly2,
}

const METHODS: [Method; 7] = [
    Method::KfDyn1,
    Method::KfDyn2,
    Method::Naive1,
    Method::Naive2,
    Method::Hmm,
    Method::Poly1,
    Method::Poly2,
];

/// Parameter set 1 of the paper's Table 1 (first column): position observation.
fn set1() -> KfDynamicParams {
    KfDynamicParams::paper_position_literal(10.0)
}

/// Parameter set 2 (second column): position + velocity observation.
fn set2() -> KfDynamicParams {
    KfDynamicParams::paper_position_velocity_literal(100.0)
}

fn describe(p: &KfDynamicParams) -> String {
    let obs = if p.observe_velocity { 4 } else { 2 };
    format!("{obs}-D obs., R = {} I, Q = {} I", p.r, p.q)
}

impl Method {
    fn label(self) -> String {
        match self {
            Method::KfDyn1 => format!("KF dynamic ({})", describe(&set1())),
            Method::KfDyn2 => format!("KF dynamic ({})", describe(&set2())),
            Method::Naive1 => format!("naive KF ({})", describe(&set1())),
            Method::Naive2 => format!("naive KF ({})", describe(&set2())),
            Method::Hmm => "HMM".to_string(),
            Method::Poly1 => format!("{POLY_POINTS}-point linear"),
            Method::Poly2 => format!("{POLY_POINTS}-point quadratic"),
        }
    }
    fn short(self) -> &'static str {
        match self {
            Method::KfDyn1 => "KF dynamic (set 1)",
            Method::KfDyn2 => "KF dynamic (set 2)",
            Method::Naive1 => "naive KF (set 1)",
            Method::Naive2 => "naive KF (set 2)",
            Method::Hmm => "HMM",
            Method::Poly1 => "linear",
            Method::Poly2 => "quadratic",
        }
    }
    fn is_kf_dynamic(self) -> bool {
        matches!(self, Method::KfDyn1 | Method::KfDyn2)
    }
}

fn experiment_err(experiment: &str) -> impl Fn(trajpred::Error) -> ReproError + '_ {
    move |e| ReproError::Experiment {
        experiment: format!("kf-dynamic/{experiment}"),
        reason: e.to_string(),
    }
}

/// The trajectories of one dataset, as the experiments use them.
struct Loaded {
    /// Segments with at least [`MIN_POINTS`] points after the gap split.
    segments: Vec<Segment>,
    /// Loader's report over every file read.
    report: LoadReport,
    /// Folder read.
    folder: PathBuf,
    /// User folders (GeoLife) or taxi files (T-Drive) read, and how many there were.
    units_read: usize,
    units_total: usize,
    /// Trajectories the loader returned.
    loaded: usize,
    /// Segments after the split at the protocol's limit (any length).
    segments_all: usize,
    /// Segments with at least [`MIN_POINTS_SHORTEST`] points at the paper's 5 s limit.
    paper_limit_usable: usize,
    /// Points in [`Self::segments`].
    points: usize,
    /// The protocol's gap limit, seconds.
    max_gap: f64,
}

fn load(p: &Protocol, dir: &Path) -> Result<Loaded> {
    let e = experiment_err("load");
    let t = dataset::load_tracks(p.dataset, dir, &p.load_options, p.max_units).map_err(&e)?;
    let paper_limit = Segmentation {
        max_gap: Some(PAPER_MAX_INTERVAL_S),
        min_points: MIN_POINTS_SHORTEST,
        ..Segmentation::default()
    };
    let (usable, _) = paper_limit.apply(&t.tracks).map_err(&e)?;
    let (segments, counts) = p.segmentation.apply(&t.tracks).map_err(&e)?;
    Ok(Loaded {
        segments,
        report: t.report,
        folder: dir.to_path_buf(),
        units_read: t.units_read,
        units_total: t.units_total,
        loaded: t.tracks.len(),
        segments_all: counts.segments_all,
        paper_limit_usable: usable.len(),
        points: counts.points,
        max_gap: p.segmentation.max_gap.unwrap_or(f64::INFINITY),
    })
}

/// The grid of one dataset: per method, per history, the protocol's report.
struct Grid {
    /// The protocol's run: `run.reports[m][h]` for METHODS[m] and HISTORIES[h].
    run: ProtocolRun,
    /// Run-time experiment: per size, (test trajectories, per method report).
    timing: Vec<(usize, Vec<MethodReport>)>,
    /// Extra KF parameter combinations at [`TIMING_HISTORY`]: (label, kf-dynamic, naive).
    combos: Vec<(String, MethodReport, MethodReport)>,
    /// HMM fit time, seconds, and what its fit chose.
    hmm_fit_seconds: f64,
    hmm_states: Option<String>,
}

/// A progress bar that moves once per stage of the protocol run.
struct StageBar<'a>(&'a indicatif::ProgressBar);

impl protocol::Progress for StageBar<'_> {
    fn finish(&self) {
        self.0.inc(1);
    }
}

fn run_grid(ds: Ds, p: &Protocol, data: &Loaded, ctx: &Context, budget: &Budget) -> Result<Grid> {
    if data.segments.len() < 2 {
        return Err(ReproError::Experiment {
            experiment: format!("kf-dynamic/{}", ds.folder()),
            reason: format!(
                "{} segments of at least {MIN_POINTS} points: too few for a training and a \
                 test part",
                data.segments.len()
            ),
        });
    }
    let n_sizes = TIMING_SIZES.min(data.segments.len());
    let bar = ctx.bar(
        (METHODS.len() * (2 + n_sizes) + 4) as u64,
        format!("kf-dynamic {}", ds.label()),
    );
    let run = protocol::run(p, &data.segments, &StageBar(&bar)).map_err(experiment_err("grid"))?;
    if run.train.is_empty() {
        return Err(ReproError::Experiment {
            experiment: format!("kf-dynamic/{}", ds.folder()),
            reason: "no training segment".into(),
        });
    }
    let hmm_i = METHODS.iter().position(|&m| m == Method::Hmm).unwrap_or(0);
    let hmm_fit_seconds = run.fit_seconds[hmm_i];
    let hmm_states = run.predictors[hmm_i].fitted_summary();
    // run time against the number of test trajectories: seeded random samples of the pool
    let seed = match p.split {
        Split::ByTrajectory { seed, .. } | Split::ByGroup { seed, .. } => seed,
        Split::ByTime { .. } => ctx.seed,
    };
    let timing_test = p
        .test_at(&run.test, TIMING_HISTORY)
        .map_err(experiment_err("trim"))?;
    let n_sizes = TIMING_SIZES.min(timing_test.len());
    let cfg = EvalConfig {
        max_origins_per_trajectory: Some(budget.timing_origins),
        ..p.config(TIMING_HISTORY)
    };
    let mut timing = Vec::with_capacity(n_sizes);
    for k in 1..=n_sizes {
        let n = (k * timing_test.len()).div_ceil(n_sizes);
        let mut idx: Vec<usize> = (0..timing_test.len()).collect();
        idx.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(
            seed.wrapping_add(k as u64),
        ));
        let sample: Vec<Trajectory> = idx[..n].iter().map(|&i| timing_test[i].clone()).collect();
        let mut per = Vec::with_capacity(METHODS.len());
        for pr in &run.predictors {
            per.push(
                harness::evaluate(pr.as_ref(), &sample, &cfg, None)
                    .map_err(experiment_err("timing"))?,
            );
            bar.inc(1);
        }
        timing.push((n, per));
    }
    // the other two pairings of Table 1's R and Q; KF dynamic re-uses the last observation at
    // every step (the paper read literally), as in the protocol's rows
    let cfg = p.config(TIMING_HISTORY);
    let mut combos = Vec::new();
    for params in [
        KfDynamicParams::paper_position_literal(100.0),
        KfDynamicParams::paper_position_velocity_literal(10.0),
    ] {
        let e = experiment_err("parameter sets");
        let kd = KfDynamic::new(params).map_err(&e)?;
        let nv = NaiveKf::new(params).map_err(&e)?;
        let a = harness::evaluate(&kd, &timing_test, &cfg, None).map_err(&e)?;
        bar.inc(1);
        let b = harness::evaluate(&nv, &timing_test, &cfg, None).map_err(&e)?;
        bar.inc(1);
        combos.push((describe(&params), a, b));
    }
    bar.finish_and_clear();
    Ok(Grid {
        run,
        timing,
        combos,
        hmm_fit_seconds,
        hmm_states,
    })
}

impl Grid {
    fn index(m: Method) -> usize {
        METHODS.iter().position(|&x| x == m).unwrap_or(0)
    }
    fn report(&self, m: Method) -> &[MethodReport] {
        &self.run.reports[Self::index(m)]
    }
    /// Mean Euclidean error over every step and history.
    fn error(&self, m: Method) -> f64 {
        self.run.error(Self::index(m))
    }
    /// Accuracy (percent) over every step and history.
    fn accuracy(&self, m: Method) -> f64 {
        self.run.accuracy(Self::index(m))
    }
    /// Root mean square error over every step and history.
    fn rmse(&self, m: Method) -> f64 {
        self.run.rmse(Self::index(m))
    }
    fn step_error(&self, m: Method, k: usize) -> f64 {
        self.run.step_error(Self::index(m), k)
    }
    fn step_accuracy(&self, m: Method, k: usize) -> f64 {
        self.run.step_accuracy(Self::index(m), k)
    }
    fn fitting_error(&self) -> f64 {
        (self.error(Method::Poly1) + self.error(Method::Poly2)) / 2.0
    }
    fn fitting_accuracy(&self) -> f64 {
        (self.accuracy(Method::Poly1) + self.accuracy(Method::Poly2)) / 2.0
    }
}

fn data_lines(ds: Ds, d: &Loaded) -> Vec<String> {
    let r = &d.report;
    let skipped: Vec<String> = r
        .skipped_by_reason()
        .filter(|(_, n)| *n > 0)
        .map(|(reason, n)| format!("{reason}: {n}"))
        .collect();
    vec![
        format!(
            "{}: read {} of {} {} in {}; {} files, {} records, {} points kept, {} skipped ({}); \
             {} trajectories loaded.",
            ds.label(),
            d.units_read,
            d.units_total,
            if ds == Ds::Geolife {
                "user folders"
            } else {
                "taxi files"
            },
            d.folder.display(),
            r.files_read,
            r.records_read,
            r.points_kept,
            r.skipped_total(),
            if skipped.is_empty() {
                "none".to_string()
            } else {
                skipped.join(", ")
            },
            d.loaded
        ),
        format!(
            "{}: split where the sampling interval exceeds {} s: {} segments, {} with at least \
             {MIN_POINTS} points ({} points) used; at the paper's {} s limit, {} segments \
             would have at least {MIN_POINTS_SHORTEST} points.",
            ds.label(),
            d.max_gap,
            d.segments_all,
            d.segments.len(),
            d.points,
            PAPER_MAX_INTERVAL_S,
            d.paper_limit_usable
        ),
    ]
}

/// Runs the paper's experiments (see the module documentation).
pub fn run(ctx: &Context) -> Result<PaperResult> {
    let budget = Budget::new(ctx.quick);
    let mut out = PaperResult::new();
    let mut grids: Vec<(Ds, Grid)> = Vec::new();
    for ds in [Ds::Geolife, Ds::Tdrive] {
        let Some(dir) = ctx.data(ds.folder()) else {
            out.missing.push(ctx.missing(
                ds.folder(),
                &format!(
                    "{}: error, accuracy and run time of KF dynamic, naive KF, HMM and the \
                     N-point fits (the paper's Figs. {})",
                    ds.label(),
                    if ds == Ds::Geolife { "1-3" } else { "4-6" }
                ),
            ));
            continue;
        };
        let t0 = std::time::Instant::now();
        let p = ds.protocol(ctx)?;
        let data = load(&p, &dir)?;
        let load_s = t0.elapsed().as_secs_f64();
        out.data.extend(data_lines(ds, &data));
        out.data.push(format!(
            "{}: reading and splitting took {load_s:.1} s of wall time.",
            ds.label()
        ));
        let grid = run_grid(ds, &p, &data, ctx, &budget)?;
        tables_and_figures(ds, &p, &grid, &budget, &mut out)?;
        claims(ds, &grid, &mut out);
        if let Some(k) = &grid.hmm_states {
            out.notes.push(format!(
                "{}: the HMM chose {k} on its training part.",
                ds.label()
            ));
        }
        grids.push((ds, grid));
    }
    out.tables.insert(0, headline(&grids)?);
    notes(ctx, &mut out)?;
    Ok(out)
}

fn notes(ctx: &Context, out: &mut PaperResult) -> Result<()> {
    let geo = Ds::Geolife.protocol(ctx)?;
    let td = Ds::Tdrive.protocol(ctx)?;
    let fraction = match geo.split {
        Split::ByTime { train_fraction }
        | Split::ByTrajectory { train_fraction, .. }
        | Split::ByGroup { train_fraction, .. } => train_fraction,
    };
    out.notes.push(format!(
        "Data: subsets of GeoLife and T-Drive (see data above), not the full datasets, so the \
         test sets are smaller than the paper's; {}at most {} test and {} training \
         trajectories per dataset (seeded split {}, training share {fraction}), at most {} \
         origins per test trajectory {} points apart. The protocols are the presets \
         `{}` and `{}` (`trajpred protocols`), which `trajpred evaluate --protocol` runs alike.",
        if ctx.quick {
            format!(
                "quick run: at most {} GeoLife user folders and {} T-Drive taxi files read, ",
                geo.max_units.unwrap_or(0),
                td.max_units.unwrap_or(0)
            )
        } else {
            String::new()
        },
        geo.max_test.unwrap_or(0),
        geo.max_train.unwrap_or(0),
        geo.split.label(),
        geo.max_origins.unwrap_or(0),
        geo.stride,
        geo.name,
        td.name,
    ));
    let gap = |p: &Protocol| p.segmentation.max_gap.unwrap_or(f64::INFINITY);
    let (geolife_gap, tdrive_gap) = (gap(&geo), gap(&td));
    out.notes.push(format!(
        "Sampling: GeoLife trajectories are split where successive points are more than \
         {geolife_gap} s apart (the paper's limit, stated for T-Drive). T-Drive taxis \
         mostly report every few minutes, so the {PAPER_MAX_INTERVAL_S} s limit leaves almost \
         nothing (counted in the data lines above); we split T-Drive at \
         {tdrive_gap} s instead, so its steps are minutes long and its errors far \
         larger than GeoLife's. Segments need {MIN_POINTS} points (history {MAX_HISTORY} + \
         {HORIZON} steps)."
    ));
    out.notes.push(
        "No resampling: a step is the next recorded point. The filters and fits take the \
         sampling interval from the history (the mean interval of the points they use) and \
         forecast at multiples of it, so irregular sampling inside a segment is part of the \
         error."
            .into(),
    );
    out.notes.push(
        "Projection: WGS84 to local east-north metres at each trajectory's first point \
         (trajpred-data); repeated timestamps are dropped by the loader, T-Drive points outside \
         the Beijing box or at (0, 0) are skipped."
            .into(),
    );
    out.notes.push(
        "KF dynamic iterates eq. 13-15 with the latest observation at every step (the paper's \
         wording, read literally); naive KF extrapolates the last filtered state. Not in the \
         paper: the initial state is the first point with zero velocity and P = 100 I."
            .into(),
    );
    out.notes.push(
        "The HMM (the authors' earlier work; not specified in this paper) clusters training \
         displacements with k-means, counts state transitions and chooses the number of states \
         on its training part only; nothing is tuned on the test trajectories."
            .into(),
    );
    out.notes.push(format!(
        "Averages: the paper does not say how its figures average over histories, steps and \
         test sets; ours are the means over histories {:?} and steps 1..{HORIZON} of the \
         per-forecast errors.",
        HISTORIES
    ));
    Ok(())
}
