//! The `trajpred` command-line tool: predict, evaluate, plot.

// a command-line tool writes its results to standard output
#![allow(clippy::print_stdout)]

mod args;
mod custom;
mod folds;
mod output;
mod progress;

use anyhow::{Context, Result, bail};
use args::{LimitArgs, SegmentArgs, SplitArg, TrainCutArgs};
use clap::{Parser, Subcommand};
use custom::{custom_options, custom_protocol, load_segments};
use output::{Format, table, write_atomic, write_forecast};
use progress::Bars;
use std::path::PathBuf;
use trajpred::dataset::{self, Dataset, Loaded, Segment};
use trajpred::harness::{EvalConfig, MethodReport, Split};
use trajpred::params::{self, ParamsFile};
use trajpred::plot::{Chart, Series, write_chart};
use trajpred::protocol::{self, Protocol};
use trajpred::registry::{MethodOptions, all_methods, build, leaderboard_methods};
use trajpred_core::MAX_HORIZON;
use trajpred_core::{Forecast, Trajectory};

/// The neural methods allocate and free a tensor per operation (burn's ops return new
/// tensors): mimalloc serves that churn with less work than glibc's malloc (the
/// reproduction's kfu-lstm paper, docs/performance.md: about 0.75x the time).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[derive(Parser)]
#[command(
    name = "trajpred",
    version,
    about = "Trajectory prediction: predict, evaluate, plot"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// A horizon within the stated limit, checked before any model is sized by it.
fn check_horizon(horizon: usize) -> Result<()> {
    if horizon == 0 || horizon > MAX_HORIZON {
        bail!("--horizon must be between 1 and {MAX_HORIZON}, got {horizon}");
    }
    Ok(())
}

#[derive(clap::Args)]
struct Input {
    /// Input file or folder.
    #[arg(long)]
    input: PathBuf,
    /// Its format: geolife, tdrive, adsb or csv.
    #[arg(long, default_value = "csv")]
    dataset: String,
    /// Which segment of the input (0 = the first; see `--max-gap`).
    #[arg(long, default_value_t = 0)]
    track: usize,
    #[command(flatten)]
    segment: SegmentArgs,
    #[command(flatten)]
    limits: LimitArgs,
}

#[derive(Subcommand)]
enum Command {
    /// Forecast the next steps after the end of a track (or of `--history` points of it).
    Predict {
        #[command(flatten)]
        input: Input,
        /// The method (see `trajpred methods`).
        #[arg(long)]
        method: String,
        /// Steps to forecast.
        #[arg(long, default_value_t = 5)]
        horizon: usize,
        /// Use only the last this many points of the segment (default: all of it).
        #[arg(long)]
        history: Option<usize>,
        /// Output format (markdown prints a table).
        #[arg(long, value_enum, default_value = "csv")]
        format: Format,
        /// Write to this file instead of standard output.
        #[arg(long)]
        output: Option<PathBuf>,
        /// Use the method's parameters saved by `trajpred fit` instead of fitting it on the
        /// track.
        #[arg(long)]
        params: Option<PathBuf>,
    },
    /// Evaluate methods on a dataset with a rolling origin, or run a paper's protocol.
    Evaluate {
        /// Run this protocol preset (see `trajpred protocols`): its segmentation, split,
        /// histories, horizon, threshold and methods, exactly as the reproduction runs it.
        #[arg(long)]
        protocol: Option<String>,
        /// geolife, tdrive, adsb or csv (implied by `--protocol`).
        #[arg(long)]
        dataset: Option<String>,
        /// File or folder to load (a dataset's root folder works).
        #[arg(long)]
        path: PathBuf,
        /// Comma-separated methods; `all` is every method that runs in minutes without extra
        /// files (all but the particle filters and the neural networks, see `docs/accuracy.md`).
        #[arg(long, default_value = "kf-dynamic,naive-kf,poly1,poly2,hmm")]
        methods: String,
        /// History length given to the predictors.
        #[arg(long, default_value_t = 20)]
        history: usize,
        /// Steps forecast at each origin.
        #[arg(long, default_value_t = 5)]
        horizon: usize,
        /// Hit threshold in metres.
        #[arg(long, default_value_t = 25.0)]
        threshold: f64,
        /// Distance between origins.
        #[arg(long, default_value_t = 1)]
        stride: usize,
        /// At most this many forecast origins per segment (the first ones; default: all).
        /// Bounds the run time of slow methods (pf, mkpf) on large datasets.
        #[arg(long)]
        max_origins: Option<usize>,
        #[command(flatten)]
        segment: SegmentArgs,
        #[command(flatten)]
        train_cut: TrainCutArgs,
        #[command(flatten)]
        limits: LimitArgs,
        /// Read at most this many units (GeoLife users, T-Drive taxis, files).
        #[arg(long)]
        max_units: Option<usize>,
        /// Evaluate at most this many test segments.
        #[arg(long)]
        limit: Option<usize>,
        /// How to split segments into training and test parts.
        #[arg(long, value_enum, default_value = "by-track")]
        split: SplitArg,
        /// Share of segments (or users) used to fit trained methods.
        #[arg(long, default_value_t = 0.3)]
        train_fraction: f64,
        /// Seed of the split and of randomised methods (with `--protocol`: the base seed,
        /// default the reproduction's).
        #[arg(long)]
        seed: Option<u64>,
        /// `Q = q I` of the Kalman predictors.
        #[arg(long, default_value_t = 10.0)]
        kf_q: f64,
        /// With `--protocol`: its reduced version (what the quick reproduction runs).
        #[arg(long)]
        quick: bool,
        /// Table format.
        #[arg(long, value_enum, default_value = "markdown")]
        format: Format,
        /// No progress bars (they are off anyway when stderr is not a terminal).
        #[arg(long)]
        quiet: bool,
        /// Load the methods' parameters saved by `trajpred fit` instead of fitting them
        /// (every method asked for must be in the file).
        #[arg(long)]
        params: Option<PathBuf>,
        /// Cross-validate by user instead of one split: users are dealt into this many folds
        /// (seeded by `--seed`), each fold is the test part once with the others training;
        /// the table gives the mean and standard deviation over folds.
        #[arg(long)]
        folds: Option<usize>,
        /// Also draw the per-step mean error of the best methods (SVG or PNG by extension).
        #[arg(long)]
        figure: Option<PathBuf>,
    },
    /// Fit methods on the training part of a dataset's split (the part `evaluate` with the
    /// same options fits on) and save what they learned to a JSON file.
    Fit {
        /// geolife, tdrive, adsb or csv.
        #[arg(long)]
        dataset: String,
        /// File or folder to load (a dataset's root folder works).
        #[arg(long)]
        path: PathBuf,
        /// Comma-separated methods.
        #[arg(long)]
        methods: String,
        /// History length (with the horizon, the shortest segment kept, as in `evaluate`).
        #[arg(long, default_value_t = 20)]
        history: usize,
        /// Steps forecast (the multi-step models are fitted for it).
        #[arg(long, default_value_t = 5)]
        horizon: usize,
        #[command(flatten)]
        segment: SegmentArgs,
        #[command(flatten)]
        train_cut: TrainCutArgs,
        #[command(flatten)]
        limits: LimitArgs,
        /// Read at most this many units (GeoLife users, T-Drive taxis, files).
        #[arg(long)]
        max_units: Option<usize>,
        /// How to split segments into training and test parts.
        #[arg(long, value_enum, default_value = "by-track")]
        split: SplitArg,
        /// Share of segments (or users) fitted on.
        #[arg(long, default_value_t = 0.3)]
        train_fraction: f64,
        /// Seed of the split and of randomised methods.
        #[arg(long)]
        seed: Option<u64>,
        /// `Q = q I` of the Kalman predictors.
        #[arg(long, default_value_t = 10.0)]
        kf_q: f64,
        /// The parameter file to write (JSON).
        #[arg(long)]
        output: PathBuf,
        /// No progress bars.
        #[arg(long)]
        quiet: bool,
    },
    /// Draw a track and a method's forecast from an origin (SVG or PNG by extension).
    Plot {
        #[command(flatten)]
        input: Input,
        /// The method.
        #[arg(long, default_value = "kf-dynamic")]
        method: String,
        /// Steps to forecast.
        #[arg(long, default_value_t = 10)]
        horizon: usize,
        /// Points of history before the origin given to the method (default: all).
        #[arg(long)]
        history: Option<usize>,
        /// Forecast origin (point index); default: `horizon` points before the end.
        #[arg(long)]
        origin: Option<usize>,
        /// Output file, `.svg` or `.png`.
        #[arg(long)]
        output: PathBuf,
    },
    /// List the methods.
    Methods,
    /// List the protocol presets with their parameters.
    Protocols,
}

/// One segment of the input, and its frame.
fn load_one(input: &Input) -> Result<Segment> {
    let ds: Dataset = input.dataset.parse()?;
    let seg = input.segment.segmentation(1);
    let opts = input.limits.apply(ds.options());
    let loaded = dataset::load(ds, &input.input, &opts, &seg, None)
        .with_context(|| format!("cannot load {}", input.input.display()))?;
    say_skips(&loaded);
    let n = loaded.segments.len();
    if input.track >= n {
        bail!(
            "{}: has {n} segments, no segment {} ({})",
            input.input.display(),
            input.track,
            loaded.summary()
        );
    }
    loaded
        .segments
        .into_iter()
        .nth(input.track)
        .context("segment")
}

/// Tells on stderr what the loaders skipped, by cause.
fn say_skips(loaded: &Loaded) {
    if loaded.report.skipped_total() > 0 || loaded.counts.too_short > 0 {
        eprintln!("note: {}", loaded.summary());
    }
}

/// What the split left out as exact repeats ([`trajpred::harness::drop_repeats`]), for the
/// line that counts the segments; empty when nothing was.
fn repeats_note(r: &trajpred::harness::Repeats) -> String {
    if r.total() == 0 {
        return String::new();
    }
    format!(
        "; left out as exact repeats of other segments: {} training, {} test (copies of \
         training segments), {} test (copies of test segments)",
        r.train, r.test_of_train, r.test
    )
}

/// Tells on stderr what each fitted method chose (`auto`'s pick and fold scores, ...).
fn say_fitted(run: &protocol::ProtocolRun) {
    for (label, p) in run.labels.iter().zip(&run.predictors) {
        if let Some(s) = p.fitted_summary() {
            eprintln!("{label}: {s}");
        }
    }
}

fn method_options(horizon: usize) -> MethodOptions {
    let d = MethodOptions::default();
    // the multi-step models are fitted for the longest forecast they will be asked
    MethodOptions {
        horizons: d.horizons.max(horizon),
        ..d
    }
}

fn forecast_from(method: &str, tr: &Trajectory, horizon: usize) -> Result<Forecast> {
    let mut p = build(method, &method_options(horizon))?;
    // only the track itself, up to its end (the origin), is used to fit
    p.fit(std::slice::from_ref(tr))?;
    Ok(p.forecast(tr, horizon)?)
}

/// The last `history` points of `tr` (all of it for `None`).
fn last_points(tr: &Trajectory, history: Option<usize>) -> Result<Trajectory> {
    match history {
        Some(0) => bail!("--history must be at least 1"),
        Some(h) if h < tr.len() => Ok(tr.slice(tr.len() - h..tr.len())?),
        _ => Ok(tr.clone()),
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Methods => {
            for m in all_methods() {
                println!("{:<16} {}", m.name, m.description);
            }
        }
        Command::Protocols => {
            for p in protocol::presets(protocol::DEFAULT_SEED, false)? {
                print!("{}", p.describe());
            }
        }
        Command::Predict {
            input,
            method,
            horizon,
            history,
            format,
            output,
            params,
        } => {
            // a bad method or horizon fails before the loading
            check_horizon(horizon)?;
            build(&method, &method_options(horizon))?;
            let saved = match &params {
                Some(file) => Some(ParamsFile::load(file)?.predictor(&method)?),
                None => None,
            };
            let seg = load_one(&input)?;
            let hist = last_points(&seg.trajectory, history)?;
            let f = match saved {
                Some(p) => p.forecast(&hist, horizon)?,
                None => forecast_from(&method, &hist, horizon)?,
            };
            match output {
                Some(path) => {
                    let mut buf = Vec::new();
                    write_forecast(&f, &seg, &hist, format, &mut buf)?;
                    write_atomic(&path, &buf)?;
                }
                None => write_forecast(&f, &seg, &hist, format, &mut std::io::stdout().lock())?,
            }
        }
        Command::Evaluate {
            protocol: protocol_name,
            dataset: ds,
            path,
            methods,
            history,
            horizon,
            threshold,
            stride,
            max_origins,
            segment,
            train_cut,
            limits,
            max_units,
            limit,
            split,
            train_fraction,
            seed,
            kf_q,
            quick,
            format,
            quiet,
            params,
            folds,
            figure,
        } => {
            let bars = Bars::new(quiet)?;
            check_horizon(horizon)?;
            let mut p = match protocol_name {
                Some(name) => {
                    let p = protocol::preset(&name, seed.unwrap_or(protocol::DEFAULT_SEED), quick)?;
                    if let Some(d) = &ds
                        && d.parse::<Dataset>()? != p.dataset
                    {
                        bail!("protocol {name} reads {}, not {d}", p.dataset);
                    }
                    p
                }
                None => {
                    let ds: Dataset = ds
                        .as_deref()
                        .context("--dataset is needed (or --protocol)")?
                        .parse()?;
                    let seed = seed.unwrap_or(0);
                    let opts = custom_options(
                        kf_q,
                        seed,
                        EvalConfig {
                            history,
                            horizon,
                            stride,
                            threshold,
                            max_origins_per_trajectory: max_origins,
                        },
                    );
                    // `all,imm` names imm twice: each method runs once, in first-named order
                    let mut names: Vec<&str> = Vec::new();
                    for n in methods
                        .split(',')
                        .map(str::trim)
                        .filter(|s| !s.is_empty())
                        .flat_map(|s| match s {
                            "all" => leaderboard_methods(),
                            _ => vec![s],
                        })
                    {
                        if !names.contains(&n) {
                            names.push(n);
                        }
                    }
                    if names.is_empty() {
                        bail!("--methods names no method");
                    }
                    Protocol {
                        max_test: limit,
                        stride,
                        max_origins,
                        threshold,
                        ..custom_protocol(
                            ds,
                            &names,
                            &opts,
                            &segment,
                            history,
                            horizon,
                            max_units,
                            split.of(train_fraction, seed),
                        )
                    }
                }
            };
            p.load_options = limits.apply(p.load_options);
            p.train_segmentation = train_cut.of(&p.segmentation);
            // bad settings and misspelt methods fail before the (possibly long) loading
            p.validate()?;
            for m in &p.methods {
                build(&m.name, &m.options)?;
            }
            // so do a bad parameter file and a method it lacks
            let saved = params.as_deref().map(ParamsFile::load).transpose()?;
            if let Some(file) = &saved {
                for m in &p.methods {
                    file.predictor(&m.label)?;
                }
                for d in file.differences(&p) {
                    eprintln!(
                        "note: {}: {d} (the test part may overlap the training part)",
                        file.source()
                    );
                }
            }
            let (loaded, pool) = load_segments(&p, &path, &bars)?;
            if let Some(k) = folds {
                if saved.is_some() {
                    bail!("--folds fits every fold anew: it cannot use --params");
                }
                if pool.is_some() {
                    bail!("--folds cuts every fold from --max-gap: it cannot use --train-max-gap");
                }
                if !matches!(p.split, Split::ByGroup { .. }) {
                    bail!("--folds cross-validates by user: use it with --split by-user");
                }
                let seed = seed.unwrap_or(0);
                let runs = protocol::cross_validate(&p, &loaded.segments, k, seed, &bars)?;
                for (f, r) in runs.iter().enumerate() {
                    eprintln!(
                        "fold {f}: {} training and {} test segments{}",
                        r.train.len(),
                        r.test.len(),
                        repeats_note(&r.repeats)
                    );
                    say_fitted(r);
                }
                let s = folds::summarise(&runs);
                print!("{}", folds::markdown(&s, k));
                if let Some(path) = &figure {
                    let title = format!("{}: mean error per step, {k} folds by user", p.dataset);
                    folds::figure(&s, &title, path)?;
                    eprintln!("wrote {}", path.display());
                }
                return Ok(());
            }
            let run = match &saved {
                Some(file) => {
                    let (run, seen) = file.evaluate(&p, &loaded.segments, &bars)?;
                    if seen > 0 {
                        eprintln!(
                            "note: left out {seen} test segments that {} was fitted on",
                            file.source()
                        );
                    }
                    run
                }
                None if pool.is_some() => {
                    let split = protocol::split_with_pool(&p, &loaded.segments, pool.as_deref())?;
                    let n = loaded.segments.len();
                    protocol::run_split(&p, n, split, &bars, &protocol::build_and_fit)?
                }
                None => protocol::run(&p, &loaded.segments, &bars)?,
            };
            say_fitted(&run);
            if let Some(path) = &figure {
                let s = folds::summarise(std::slice::from_ref(&run));
                let title = format!("{}: mean error per step ({})", p.dataset, p.split.label());
                folds::figure(&s, &title, path)?;
                eprintln!("wrote {}", path.display());
            }
            match (&saved, p.split) {
                // nothing of these data trained: say what did
                (Some(file), Split::None) => eprintln!(
                    "{}: {} test segments (none split: every segment tests; fitted on {} \
                     training segments of {}){}",
                    p.name,
                    run.test.len(),
                    file.fitted_on.train_segments,
                    file.fitted_on.path,
                    repeats_note(&run.repeats)
                ),
                _ => eprintln!(
                    "{}: {} training and {} test segments ({} split){}",
                    p.name,
                    run.train.len(),
                    run.test.len(),
                    p.split.label(),
                    repeats_note(&run.repeats)
                ),
            }
            if p.histories.len() == 1 {
                let reports: Vec<MethodReport> = run
                    .reports
                    .iter()
                    .zip(&run.fit_seconds)
                    .zip(&run.labels)
                    .map(|((r, &fit), label)| MethodReport {
                        // the name asked for (kf-dynamic-4d), not the predictor's family name
                        method: label.clone(),
                        fit_seconds: fit,
                        ..r[0].clone()
                    })
                    .collect();
                print!("{}", table(&reports, format)?);
            } else {
                let t = run.history_table();
                match format {
                    Format::Markdown => {
                        println!(
                            "{}: mean Euclidean error (m) against history length, mean over \
                             steps 1..{}\n",
                            p.name, p.horizon
                        );
                        print!("{}", t.markdown(2));
                    }
                    Format::Csv => print!("{}", t.csv()),
                    Format::Json => {
                        let rows: Vec<serde_json::Value> = t
                            .rows
                            .iter()
                            .map(|(l, v)| serde_json::json!({"method": l, "values": v}))
                            .collect();
                        println!(
                            "{}",
                            serde_json::to_string_pretty(
                                &serde_json::json!({"columns": t.columns, "rows": rows})
                            )?
                        );
                    }
                }
            }
            // a method that never forecast is a failed run, whatever the others did
            let mut dead = Vec::new();
            for (m, label) in run.labels.iter().enumerate() {
                let made: usize = run.reports[m].iter().map(|r| r.forecasts).sum();
                if made == 0 {
                    let why = run.reports[m]
                        .iter()
                        .find_map(|r| r.first_failure.clone())
                        .unwrap_or_else(|| "no origin in the test segments".into());
                    dead.push(format!("{label}: {why}"));
                }
            }
            if !dead.is_empty() {
                bail!("no forecast was made by {}", dead.join("; "));
            }
        }
        Command::Fit {
            dataset: ds,
            path,
            methods,
            history,
            horizon,
            segment,
            train_cut,
            limits,
            max_units,
            split,
            train_fraction,
            seed,
            kf_q,
            output,
            quiet,
        } => {
            let bars = Bars::new(quiet)?;
            check_horizon(horizon)?;
            let ds: Dataset = ds.parse()?;
            let seed = seed.unwrap_or(0);
            let names: Vec<&str> = methods.split(',').map(str::trim).collect();
            if names.iter().any(|n| n.is_empty()) {
                bail!("--methods has an empty name: `{methods}`");
            }
            let opts = custom_options(
                kf_q,
                seed,
                EvalConfig {
                    history,
                    horizon,
                    ..Default::default()
                },
            );
            let split = split.of(train_fraction, seed);
            let mut p = custom_protocol(
                ds, &names, &opts, &segment, history, horizon, max_units, split,
            );
            p.load_options = limits.apply(p.load_options);
            p.train_segmentation = train_cut.of(&p.segmentation);
            // bad settings, misspelt methods and methods that cannot be saved fail before
            // the loading
            p.validate()?;
            params::check_exportable(&p.methods)?;
            let (loaded, pool) = load_segments(&p, &path, &bars)?;
            let file = params::fit(&p, &path, &loaded.segments, pool.as_deref(), &bars)?;
            file.save(&output)?;
            let on = &file.fitted_on;
            for m in &file.methods {
                let what = match (&m.summary, m.params.is_null()) {
                    (Some(s), _) => s.as_str(),
                    (None, true) => "learns nothing",
                    (None, false) => "fitted",
                };
                println!(
                    "{}: {what} ({} training segments, {} points, {:.2} s)",
                    m.label, on.train_segments, on.train_points, m.fit_seconds
                );
            }
            if on.repeated_train_segments > 0 {
                eprintln!(
                    "left out {} training segments that repeat another exactly",
                    on.repeated_train_segments
                );
            }
            eprintln!("wrote {}", output.display());
        }
        Command::Plot {
            input,
            method,
            horizon,
            history,
            origin,
            output,
        } => {
            check_horizon(horizon)?;
            build(&method, &method_options(horizon))?;
            let seg = load_one(&input)?;
            let tr = &seg.trajectory;
            let origin = origin.unwrap_or(tr.len().saturating_sub(horizon + 1));
            if origin + 1 >= tr.len() || origin == 0 {
                bail!(
                    "origin {origin} must be inside the track (1..{})",
                    tr.len() - 1
                );
            }
            let hist = last_points(&tr.prefix(origin + 1)?, history)?;
            let f = forecast_from(&method, &hist, horizon)?;
            let xy = |p: &[f64]| (p[0], if p.len() > 1 { p[1] } else { 0.0 });
            let mut pred = vec![xy(&hist.last_point())];
            pred.extend(f.points().map(|p| xy(&p)));
            let chart = Chart {
                title: format!("{} forecast, {horizon} steps from point {origin}", method),
                x_label: "x (m)".into(),
                y_label: "y (m)".into(),
                series: vec![
                    Series {
                        label: "track".into(),
                        points: tr.points().map(|p| xy(&p)).collect(),
                        markers: false,
                    },
                    Series {
                        label: method.clone(),
                        points: pred,
                        markers: true,
                    },
                ],
                log_y: false,
            };
            write_chart(&chart, &output)?;
            eprintln!("wrote {}", output.display());
        }
    }
    Ok(())
}

fn main() {
    if let Err(e) = run(Cli::parse()) {
        let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
        eprintln!("error: {}", chain.join(": "));
        std::process::exit(1);
    }
}
