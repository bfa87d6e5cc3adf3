//! The `trajpred` command-line tool: predict, evaluate, plot.

// a command-line tool writes its results to standard output
#![allow(clippy::print_stdout)]

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use trajpred::dataset::{self, Dataset, Loaded, Segment, Segmentation};
use trajpred::harness::{MethodReport, Split};
use trajpred::plot::{Chart, Series, write_chart};
use trajpred::protocol::{self, MethodSpec, Progress, Protocol};
use trajpred::registry::{MethodOptions, all_methods, build};
use trajpred_core::{Forecast, Trajectory};
use trajpred_data::Frame;
use trajpred_data::geodesy::{Enu, LocalFrame};

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

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    Markdown,
    Csv,
    Json,
}

/// Segmentation options, applied right after loading (before anything else).
#[derive(clap::Args, Clone)]
struct SegmentArgs {
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
    fn segmentation(&self, needed: usize) -> Segmentation {
        Segmentation {
            max_gap: self.max_gap,
            min_points: self.min_points.unwrap_or(needed).max(1),
            resample: self.resample,
            max_resampled_points: self.max_resampled_points,
        }
    }
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
}

#[derive(Clone, Copy, ValueEnum)]
enum SplitArg {
    /// Segments are shuffled and split (segments of one trip may fall on both sides).
    ByTrack,
    /// Users (vehicles, files) are shuffled and split: no user on both sides.
    ByUser,
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
        /// Comma-separated methods.
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
    let loaded = dataset::load(ds, &input.input, &ds.options(), &seg, None)
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

/// The forecast's step in seconds: the mean interval of the history, as the methods take it.
fn mean_interval(tr: &Trajectory) -> f64 {
    let t = tr.times();
    if t.len() < 2 {
        return 1.0;
    }
    (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64
}

/// Latitude and longitude of a point of an ENU frame.
fn lat_lon(frame: Option<&LocalFrame>, p: &[f64]) -> Option<(f64, f64)> {
    let g = frame?.to_geodetic(&Enu {
        east: p[0],
        north: p.get(1).copied().unwrap_or(0.0),
        up: p.get(2).copied().unwrap_or(0.0),
    });
    Some((g.lat_deg, g.lon_deg))
}

fn write_forecast(
    f: &Forecast,
    seg: &Segment,
    history: &Trajectory,
    format: Format,
    out: &mut dyn Write,
) -> Result<()> {
    let dt = mean_interval(history);
    let t_last = history.times()[history.len() - 1];
    let times: Vec<f64> = (1..=f.horizon()).map(|k| t_last + dt * k as f64).collect();
    let axes = ["x", "y", "z"];
    let origin = match seg.frame {
        Frame::Enu(o) => Some(o),
        _ => None,
    };
    let local = origin.map(LocalFrame::new).transpose()?;
    let frame = match origin {
        Some(o) => format!(
            "local east/north metres around lat {:.7} lon {:.7}",
            o.lat_deg, o.lon_deg
        ),
        None => "the input's own metres".to_string(),
    };
    match format {
        Format::Json => {
            let steps: Vec<serde_json::Value> = f
                .points()
                .zip(&times)
                .enumerate()
                .map(|(k, (p, t))| {
                    let ll = lat_lon(local.as_ref(), &p);
                    serde_json::json!({
                        "step": k + 1,
                        "t": t,
                        "point": p.to_vec(),
                        "lat_deg": ll.map(|v| v.0),
                        "lon_deg": ll.map(|v| v.1),
                        "covariance": f.covariance(k + 1).map(|c| {
                            c.row_iter().map(|r| r.iter().copied().collect::<Vec<f64>>())
                                .collect::<Vec<_>>()
                        }),
                    })
                })
                .collect();
            let doc = serde_json::json!({
                "segment": seg.id,
                "origin_time": t_last,
                "step_seconds": dt,
                "dim": f.dim(),
                "frame": match origin {
                    Some(o) => serde_json::json!({
                        "kind": "enu",
                        "origin_lat_deg": o.lat_deg,
                        "origin_lon_deg": o.lon_deg,
                        "origin_alt_m": o.alt_m,
                    }),
                    None => serde_json::json!({ "kind": "cartesian" }),
                },
                "steps": steps,
            });
            writeln!(out, "{}", serde_json::to_string_pretty(&doc)?)?;
        }
        Format::Csv | Format::Markdown => {
            let md = matches!(format, Format::Markdown);
            let mut header: Vec<&str> = axes[..f.dim()].to_vec();
            if local.is_some() {
                header.extend(["lat", "lon"]);
            }
            if md {
                writeln!(
                    out,
                    "Forecast of {} from t = {t_last} s, steps of {dt:.3} s (the history's mean \
                     interval), in {frame}.\n",
                    seg.id
                )?;
                writeln!(out, "| step | t | {} |", header.join(" | "))?;
                writeln!(out, "|---|---|{}", "---|".repeat(header.len()))?;
            } else {
                eprintln!(
                    "note: the forecast is in {frame}; steps of {dt} s (the history's mean interval)"
                );
                writeln!(out, "step,t,{}", header.join(","))?;
            }
            for (k, (p, t)) in f.points().zip(&times).enumerate() {
                let mut vals: Vec<String> = p.iter().map(|v| format!("{v:.6}")).collect();
                if let Some((lat, lon)) = lat_lon(local.as_ref(), &p) {
                    vals.extend([format!("{lat:.8}"), format!("{lon:.8}")]);
                }
                if md {
                    writeln!(out, "| {} | {t} | {} |", k + 1, vals.join(" | "))?;
                } else {
                    writeln!(out, "{},{t},{}", k + 1, vals.join(","))?;
                }
            }
        }
    }
    Ok(())
}

/// Progress bars on stderr (none when stderr is not a terminal, or with `--quiet`).
struct Bars {
    multi: MultiProgress,
    current: std::sync::Mutex<Option<ProgressBar>>,
    style: ProgressStyle,
}

impl Bars {
    fn new(quiet: bool) -> Result<Self> {
        let target = if quiet || !std::io::stderr().is_terminal() {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        };
        Ok(Bars {
            multi: MultiProgress::with_draw_target(target),
            current: std::sync::Mutex::new(None),
            style: ProgressStyle::with_template("{prefix:>24} {bar:30} {pos}/{len} {elapsed}")
                .map_err(|e| anyhow!("{e}"))?,
        })
    }

    fn spinner(&self, message: String) -> ProgressBar {
        let s = self
            .multi
            .add(ProgressBar::new_spinner().with_message(message));
        s.enable_steady_tick(std::time::Duration::from_millis(120));
        s
    }
}

impl Progress for Bars {
    fn start(&self, stage: &str, total: u64) {
        let bar = self.multi.add(ProgressBar::new(total));
        bar.set_style(self.style.clone());
        bar.set_prefix(stage.to_string());
        if let Ok(mut c) = self.current.lock() {
            *c = Some(bar);
        }
    }
    fn advance(&self, n: u64) {
        if let Ok(c) = self.current.lock()
            && let Some(b) = c.as_ref()
        {
            b.inc(n);
        }
    }
    fn finish(&self) {
        if let Ok(mut c) = self.current.lock()
            && let Some(b) = c.take()
        {
            b.finish();
        }
    }
}

fn table(reports: &[MethodReport], format: Format) -> Result<String> {
    if let Format::Json = format {
        return Ok(serde_json::to_string_pretty(reports)?);
    }
    let h = reports.first().map_or(0, |r| r.mean_euclidean.len());
    let mut head = vec![
        "method".to_string(),
        "trajectories".into(),
        "forecasts".into(),
        "failures".into(),
    ];
    for k in 1..=h {
        head.push(format!("mean err step {k} (m)"));
    }
    head.extend([
        "mean err all (m)".into(),
        "hit rate all".into(),
        "fit (s)".into(),
        "forecast (s)".into(),
    ]);
    let rows: Vec<Vec<String>> = reports
        .iter()
        .map(|r| {
            let mut row = vec![
                r.method.clone(),
                r.trajectories.to_string(),
                r.forecasts.to_string(),
                r.failures.to_string(),
            ];
            row.extend(r.mean_euclidean.iter().map(|v| format!("{v:.3}")));
            row.extend([
                format!("{:.3}", r.mean_euclidean_all),
                format!("{:.4}", r.hit_rate_all),
                format!("{:.3}", r.fit_seconds),
                format!("{:.3}", r.forecast_seconds),
            ]);
            row
        })
        .collect();
    let mut s = String::new();
    match format {
        Format::Csv => {
            s.push_str(&head.join(","));
            s.push('\n');
            for r in rows {
                s.push_str(&r.join(","));
                s.push('\n');
            }
        }
        _ => {
            s.push_str(&format!("| {} |\n", head.join(" | ")));
            s.push_str(&format!("|{}\n", "---|".repeat(head.len())));
            for r in rows {
                s.push_str(&format!("| {} |\n", r.join(" | ")));
            }
        }
    }
    Ok(s)
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
        } => {
            // a bad method or horizon fails before the loading
            build(&method, &method_options(horizon))?;
            let seg = load_one(&input)?;
            let hist = last_points(&seg.trajectory, history)?;
            let f = forecast_from(&method, &hist, horizon)?;
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
            max_units,
            limit,
            split,
            train_fraction,
            seed,
            kf_q,
            quick,
            format,
            quiet,
        } => {
            let bars = Bars::new(quiet)?;
            let p = match protocol_name {
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
                    let opts = MethodOptions {
                        kf_q,
                        seed,
                        horizons: MethodOptions::default().horizons.max(horizon),
                        ..Default::default()
                    };
                    let names: Vec<&str> = methods
                        .split(',')
                        .map(str::trim)
                        .filter(|s| !s.is_empty())
                        .collect();
                    if names.is_empty() {
                        bail!("--methods names no method");
                    }
                    let split = match split {
                        SplitArg::ByTrack => Split::ByTrajectory {
                            train_fraction,
                            seed,
                        },
                        SplitArg::ByUser => Split::ByGroup {
                            train_fraction,
                            seed,
                        },
                    };
                    Protocol {
                        name: "custom".into(),
                        description: "from the command line".into(),
                        dataset: ds,
                        load_options: ds.options(),
                        max_units,
                        segmentation: segment.segmentation(history + horizon),
                        split,
                        max_train: None,
                        max_test: limit,
                        histories: vec![history],
                        horizon,
                        stride,
                        max_origins,
                        threshold,
                        same_origins: false,
                        methods: names
                            .iter()
                            .map(|n| MethodSpec {
                                label: n.to_string(),
                                name: n.to_string(),
                                options: opts.clone(),
                            })
                            .collect(),
                    }
                }
            };
            // bad settings and misspelt methods fail before the (possibly long) loading
            p.validate()?;
            for m in &p.methods {
                build(&m.name, &m.options)?;
            }
            let spinner = bars.spinner(format!("loading {}", path.display()));
            let loaded = dataset::load(
                p.dataset,
                &path,
                &p.load_options,
                &p.segmentation,
                p.max_units,
            )
            .with_context(|| format!("cannot load {}", path.display()))?;
            spinner.finish_and_clear();
            eprintln!("{}: {}", path.display(), loaded.summary());
            if loaded.segments.len() < 2 {
                bail!(
                    "{}: need at least 2 segments of {} points, found {}",
                    path.display(),
                    p.segmentation.min_points,
                    loaded.segments.len()
                );
            }
            let run = protocol::run(&p, &loaded.segments, &bars)?;
            eprintln!(
                "{}: {} training and {} test segments ({} split)",
                p.name,
                run.train.len(),
                run.test.len(),
                p.split.label()
            );
            if p.histories.len() == 1 {
                let reports: Vec<MethodReport> = run
                    .reports
                    .iter()
                    .zip(&run.fit_seconds)
                    .zip(&run.labels)
                    .map(|((r, &fit), label)| MethodReport {
                        // the row is the method as asked for (`kf-dynamic-literal`, not the
                        // predictor's own `kf-dynamic`)
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
        Command::Plot {
            input,
            method,
            horizon,
            history,
            origin,
            output,
        } => {
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

/// Writes `bytes` to `path` through a temporary file in the same folder, then renames it.
fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let name = path
        .file_name()
        .context("the output path names no file")?
        .to_string_lossy();
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    std::fs::write(&tmp, bytes).with_context(|| format!("cannot write {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

fn main() {
    if let Err(e) = run(Cli::parse()) {
        let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
        eprintln!("error: {}", chain.join(": "));
        std::process::exit(1);
    }
}
