//! The `trajpred` command-line tool: predict, evaluate, plot.

// a command-line tool writes its results to standard output
#![allow(clippy::print_stdout)]

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use std::io::Write;
use std::path::PathBuf;
use trajpred::dataset::{self, Dataset, Prepare};
use trajpred::harness::{EvalConfig, MethodReport, Split, fit_and_evaluate, split};
use trajpred::plot::{Chart, Series, write_chart};
use trajpred::registry::{MethodOptions, all_methods, build};
use trajpred_core::{Forecast, Trajectory};

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

#[derive(clap::Args)]
struct Input {
    /// Input file or folder.
    #[arg(long)]
    input: PathBuf,
    /// Its format.
    #[arg(long, default_value = "csv")]
    dataset: String,
    /// Which trajectory of the file (0 = the first).
    #[arg(long, default_value_t = 0)]
    track: usize,
}

#[derive(Subcommand)]
enum Command {
    /// Forecast the next steps after the end of a track.
    Predict {
        #[command(flatten)]
        input: Input,
        /// The method (see `trajpred methods`).
        #[arg(long)]
        method: String,
        /// Steps to forecast.
        #[arg(long, default_value_t = 5)]
        horizon: usize,
        /// Output format (markdown prints a table).
        #[arg(long, value_enum, default_value = "csv")]
        format: Format,
        /// Write to this file instead of standard output.
        #[arg(long)]
        output: Option<PathBuf>,
    },
    /// Evaluate methods on a dataset with a rolling origin.
    Evaluate {
        /// geolife, tdrive, adsb or csv.
        #[arg(long)]
        dataset: String,
        /// File or folder to load.
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
        /// At most this many forecast origins per trajectory (the first ones; default: all).
        /// Bounds the run time of slow methods (pf, mkpf) on large datasets.
        #[arg(long)]
        max_origins: Option<usize>,
        /// Resample every trajectory to this step (seconds) first.
        #[arg(long)]
        resample: Option<f64>,
        /// Evaluate at most this many test trajectories.
        #[arg(long)]
        limit: Option<usize>,
        /// Share of trajectories used to fit trained methods (seeded split).
        #[arg(long, default_value_t = 0.3)]
        train_fraction: f64,
        /// Seed of the split and of randomised methods.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// `Q = q I` of the Kalman predictors.
        #[arg(long, default_value_t = 10.0)]
        kf_q: f64,
        /// Table format.
        #[arg(long, value_enum, default_value = "markdown")]
        format: Format,
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
        /// Forecast origin (point index); default: `horizon` points before the end.
        #[arg(long)]
        origin: Option<usize>,
        /// Output file, `.svg` or `.png`.
        #[arg(long)]
        output: PathBuf,
    },
    /// List the methods.
    Methods,
}

fn load_one(input: &Input) -> Result<Trajectory> {
    let ds: Dataset = input.dataset.parse()?;
    let prep = Prepare {
        resample_dt: None,
        min_points: 1,
    };
    let (mut trs, _) = dataset::load(ds, &input.input, &ds.options(), &prep)
        .with_context(|| format!("cannot load {}", input.input.display()))?;
    let n = trs.len();
    if input.track >= n {
        bail!(
            "{}: has {n} trajectories, no trajectory {}",
            input.input.display(),
            input.track
        );
    }
    Ok(trs.swap_remove(input.track))
}

fn forecast_from(method: &str, tr: &Trajectory, horizon: usize) -> Result<Forecast> {
    let mut p = build(method, &MethodOptions::default())?;
    // only the track itself, up to its end (the origin), is used to fit
    p.fit(std::slice::from_ref(tr))?;
    Ok(p.forecast(tr, horizon)?)
}

fn write_forecast(
    f: &Forecast,
    tr: &Trajectory,
    format: Format,
    out: &mut dyn Write,
) -> Result<()> {
    let dt = tr.last_interval().unwrap_or(1.0);
    let t_last = tr.times()[tr.len() - 1];
    let axes = ["x", "y", "z"];
    match format {
        Format::Json => writeln!(out, "{}", serde_json::to_string_pretty(f)?)?,
        Format::Csv | Format::Markdown => {
            let header: Vec<&str> = axes[..f.dim()].to_vec();
            if matches!(format, Format::Markdown) {
                writeln!(out, "| step | t | {} |", header.join(" | "))?;
                writeln!(out, "|---|---|{}", "---|".repeat(f.dim()))?;
            } else {
                writeln!(out, "step,t,{}", header.join(","))?;
            }
            for (k, p) in f.points().enumerate() {
                let vals: Vec<String> = p.iter().map(|v| format!("{v:.6}")).collect();
                let t = t_last + dt * (k + 1) as f64;
                if matches!(format, Format::Markdown) {
                    writeln!(out, "| {} | {t} | {} |", k + 1, vals.join(" | "))?;
                } else {
                    writeln!(out, "{},{t},{}", k + 1, vals.join(","))?;
                }
            }
        }
    }
    Ok(())
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
        Command::Predict {
            input,
            method,
            horizon,
            format,
            output,
        } => {
            let tr = load_one(&input)?;
            let f = forecast_from(&method, &tr, horizon)?;
            match output {
                Some(path) => {
                    let mut file = std::fs::File::create(&path)
                        .with_context(|| format!("cannot create {}", path.display()))?;
                    write_forecast(&f, &tr, format, &mut file)?;
                }
                None => write_forecast(&f, &tr, format, &mut std::io::stdout().lock())?,
            }
        }
        Command::Evaluate {
            dataset: ds,
            path,
            methods,
            history,
            horizon,
            threshold,
            stride,
            max_origins,
            resample,
            limit,
            train_fraction,
            seed,
            kf_q,
            format,
        } => {
            let ds: Dataset = ds.parse()?;
            let names: Vec<&str> = methods
                .split(',')
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .collect();
            if names.is_empty() {
                bail!("--methods names no method");
            }
            let opts = MethodOptions {
                kf_q,
                seed,
                ..Default::default()
            };
            // build every method first, so a misspelt one fails before the loading
            let mut predictors = names
                .iter()
                .map(|n| build(n, &opts))
                .collect::<Result<Vec<_>, _>>()?;
            let cfg = EvalConfig {
                history,
                horizon,
                stride,
                threshold,
                max_origins_per_trajectory: max_origins,
            };
            // bad settings fail before the (possibly long) loading
            cfg.validate()?;
            let spinner =
                ProgressBar::new_spinner().with_message(format!("loading {}", path.display()));
            spinner.enable_steady_tick(std::time::Duration::from_millis(120));
            let prep = Prepare {
                resample_dt: resample,
                min_points: history + horizon,
            };
            let (trs, report) = dataset::load(ds, &path, &ds.options(), &prep)
                .with_context(|| format!("cannot load {}", path.display()))?;
            spinner.finish_and_clear();
            eprintln!(
                "loaded {} trajectories ({} points kept, {} lines/points skipped) from {}",
                trs.len(),
                report.points_kept,
                report.skipped_total(),
                path.display()
            );
            if trs.len() < 2 {
                bail!(
                    "{}: need at least 2 trajectories of {} points (history + horizon), found {}",
                    path.display(),
                    history + horizon,
                    trs.len()
                );
            }
            let (train, mut test) = split(
                &trs,
                Split::ByTrajectory {
                    train_fraction,
                    seed,
                },
            )?;
            if let Some(n) = limit {
                test.truncate(n);
            }
            let multi = MultiProgress::new();
            let style = ProgressStyle::with_template(
                "{prefix:>14} {bar:30} {pos}/{len} trajectories {elapsed}",
            )
            .map_err(|e| anyhow!("{e}"))?;
            let mut reports = Vec::new();
            for p in predictors.iter_mut() {
                let bar = multi.add(ProgressBar::new(test.len() as u64));
                bar.set_style(style.clone());
                bar.set_prefix(p.name().to_string());
                let cb = |done: usize| bar.set_position(done as u64);
                reports.push(fit_and_evaluate(
                    p.as_mut(),
                    &train,
                    &test,
                    &cfg,
                    Some(&cb),
                )?);
                bar.finish();
            }
            print!("{}", table(&reports, format)?);
        }
        Command::Plot {
            input,
            method,
            horizon,
            origin,
            output,
        } => {
            let tr = load_one(&input)?;
            let origin = origin.unwrap_or(tr.len().saturating_sub(horizon + 1));
            if origin + 1 >= tr.len() || origin == 0 {
                bail!(
                    "origin {origin} must be inside the track (1..{})",
                    tr.len() - 1
                );
            }
            let history = tr.prefix(origin + 1)?;
            let f = forecast_from(&method, &history, horizon)?;
            let xy = |p: &[f64]| (p[0], if p.len() > 1 { p[1] } else { 0.0 });
            let mut pred = vec![xy(&history.last_point())];
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
