//! MKPF (`docs/papers.md` C.2): keep one frame in every 50 of a real flight, predict the frames in
//! between from the kept ones only, and compare with the true frames by the paper's relative
//! error `sqrt(mean(((x_hat - x) / x)^2))` on geodetic coordinates (the paper: 0.03% for the
//! MKPF) and in metres. Compared: the MKPF, the bootstrap PF with the same particle count
//! (and ten times as many), the UKF and the EKF, each with a constant-velocity and a
//! coordinated-turn model. A synthetic coordinated-turn flight runs the same protocol without
//! data. On the real flight, Tables 3-5 ([`gap`]) decompose the gap to the paper's figure
//! (the measure at the paper's location, a smoother, the particle count, the observation
//! noise). The paper's tables, figures and claims are in its spec (`papers/mkpf.toml`); this
//! module runs the experiment ([`experiment`]) and hands the numbers to the runner.
//! `docs/mkpf.md` says what the paper left open and what we chose.

pub mod experiment;
mod flight;
pub mod gap;
mod models;

use crate::report::{Figure, PaperResult, Value};
use crate::runner::{Computed, Row, assemble};
use crate::{Context, Paper, Result};
use experiment::{
    Flight, Method, Motion, Noise, Run, Setup, choose_noise, kept_frames, load_flight,
    synthetic_flight,
};
use serde::Deserialize;
use trajpred::plot::{Chart, Series};

/// The run sizes (`[budget]` of the spec).
#[derive(Debug, Clone, Deserialize)]
struct Budget {
    /// Seeds per particle filter.
    seeds: usize,
    /// A synthetic flight of half the length.
    synthetic_quick: bool,
    /// Cut the real flight to this many frames.
    #[serde(default)]
    real_frames: Option<usize>,
}

/// All runs of one method and motion model on one flight.
#[derive(Debug, Clone)]
pub struct MethodRuns {
    /// The motion model.
    pub motion: Motion,
    /// The method's key in the spec.
    pub key: String,
    /// The method.
    pub method: Method,
    /// One run per seed (one run for the Kalman filters).
    pub runs: Vec<Run>,
}

/// Mean and sample standard deviation (0 for a single value).
fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n.max(1.0);
    if v.len() < 2 {
        return (m, 0.0);
    }
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, var.sqrt())
}

/// The row of one method and motion model: the cells of the spec's results table.
fn summary_row(r: &MethodRuns) -> Result<Row> {
    let mut rel = Vec::new();
    let mut rmse = Vec::new();
    let mut mean_m = Vec::new();
    let mut max_m = Vec::new();
    let mut secs = Vec::new();
    for run in &r.runs {
        rel.push(100.0 * run.relative_error()?);
        let e = run.errors_m();
        let n = e.len().max(1) as f64;
        rmse.push((e.iter().map(|x| x * x).sum::<f64>() / n).sqrt());
        mean_m.push(e.iter().sum::<f64>() / n);
        max_m.push(e.iter().copied().fold(0.0, f64::max));
        secs.push(run.seconds);
    }
    let (rel, rel_sd) = mean_sd(&rel);
    let (rmse, rmse_sd) = mean_sd(&rmse);
    Ok(
        Row::new(format!("{}-{}", r.motion.name().to_lowercase(), r.key))
            .set("runs", r.runs.len())
            .set("rel", rel)
            .set("rel_sd", rel_sd)
            .set("rmse", rmse)
            .set("rmse_sd", rmse_sd)
            .set("mean", mean_sd(&mean_m).0)
            .set("max", mean_sd(&max_m).0)
            .set("seconds", mean_sd(&secs).0),
    )
}

/// The seeds of `n` runs from the base seed.
fn seeds_from(base: u64, n: usize) -> Vec<u64> {
    (0..n)
        .map(|i| base.wrapping_add((i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)))
        .collect()
}

/// Everything run on one flight.
#[derive(Debug, Clone)]
pub struct FlightResult {
    /// The flight.
    pub flight: Flight,
    /// The chosen process noise per motion model.
    pub noise: Vec<(Motion, Noise)>,
    /// The runs, by motion model then method.
    pub rows: Vec<MethodRuns>,
}

/// Runs every method of the spec and both motion models on `flight`.
fn run_flight(
    ctx: &Context,
    setup: &Setup,
    methods: &[(String, Method)],
    flight: Flight,
    seeds: usize,
    tag: &str,
) -> Result<FlightResult> {
    let mut noise = Vec::new();
    let mut rows = Vec::new();
    let bar = ctx.bar((2 * methods.len()) as u64, format!("mkpf {tag}"));
    for motion in [Motion::Cv, Motion::Ct] {
        let q = choose_noise(&flight, setup, motion)?;
        noise.push((motion, q));
        for (key, method) in methods {
            let runs = gap::seeded_runs(
                &flight,
                setup,
                motion,
                &q,
                *method,
                &seeds_from(ctx.seed, seeds),
            )?;
            rows.push(MethodRuns {
                motion,
                key: key.clone(),
                method: *method,
                runs,
            });
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(FlightResult {
        flight,
        noise,
        rows,
    })
}

/// The numbers of the results table `id` and the noise table `noise_id` of one flight.
fn tables(
    out: &mut Computed,
    id: &str,
    noise_id: &str,
    res: &FlightResult,
    setup: &Setup,
) -> Result<()> {
    let t = out.table(id);
    for r in &res.rows {
        t.rows.push(summary_row(r)?);
    }
    let n = res.flight.times.len();
    t.var("flight", res.flight.name.as_str());
    t.var("frames", n);
    t.var("kept", kept_frames(n, setup.keep_every).len());
    let t = out.table(noise_id);
    for (m, q) in &res.noise {
        let ct = |x: f64| match m {
            Motion::Cv => Value::Missing,
            Motion::Ct => x.into(),
        };
        t.rows.push(
            Row::new(m.name().to_lowercase())
                .set("accel", q.accel)
                .set("turn", ct(q.turn))
                .set("turn_rate_sd", ct(q.turn_rate_sd))
                .set("ll", q.log_likelihood),
        );
    }
    Ok(())
}

fn find(res: &FlightResult, motion: Motion, method: Method) -> Option<&MethodRuns> {
    res.rows
        .iter()
        .find(|r| r.motion == motion && r.method == method)
}

fn figures(id: &str, what: &str, res: &FlightResult, particles: usize) -> Vec<Figure> {
    let mut out = Vec::new();
    let Some(truth_run) = find(res, Motion::Ct, Method::Ukf).and_then(|r| r.runs.first()) else {
        return out;
    };
    let mut series = vec![Series {
        label: "true (in-between frames)".into(),
        points: truth_run.truth_enu.iter().map(|p| (p[0], p[1])).collect(),
        markers: false,
    }];
    for method in [
        Method::Mkpf(particles),
        Method::Ukf,
        Method::Bootstrap(particles),
    ] {
        if let Some(run) = find(res, Motion::Ct, method).and_then(|r| r.runs.first()) {
            series.push(Series {
                label: format!("{} (CT), predicted", method.name()),
                points: run.predicted_enu.iter().map(|p| (p[0], p[1])).collect(),
                markers: false,
            });
        }
    }
    out.push(Figure {
        id: format!("{id}_path"),
        caption: format!(
            "{what}: true positions of the in-between frames and the positions predicted from \
             the kept frames (coordinated-turn model, first seed), local east-north metres"
        ),
        chart: Chart {
            title: format!("{what}: predicted vs true path"),
            x_label: "east (m)".into(),
            y_label: "north (m)".into(),
            series,
            log_y: false,
        },
    });
    let t0 = res.flight.times.first().copied().unwrap_or(0.0);
    let mut series = Vec::new();
    for method in [
        Method::Mkpf(particles),
        Method::Bootstrap(particles),
        Method::Ukf,
        Method::Ekf,
    ] {
        if let Some(run) = find(res, Motion::Ct, method).and_then(|r| r.runs.first()) {
            series.push(Series {
                label: method.name(),
                points: run
                    .frames
                    .iter()
                    .zip(run.errors_m())
                    .map(|(&j, e)| (res.flight.times[j] - t0, e.max(1e-3)))
                    .collect(),
                markers: false,
            });
        }
    }
    out.push(Figure {
        id: format!("{id}_error"),
        caption: format!(
            "{what}: horizontal error of the predicted in-between frames against time \
             (coordinated-turn model, first seed; log scale)"
        ),
        chart: Chart {
            title: format!("{what}: prediction error"),
            x_label: "time from the first frame (s)".into(),
            y_label: "error (m)".into(),
            series,
            log_y: true,
        },
    });
    out
}

/// Runs the paper's experiments and builds its report from the spec.
pub fn run(ctx: &Context) -> Result<PaperResult> {
    let spec = Paper::Mkpf.spec()?;
    let setup: Setup = spec.params()?;
    let budget: Budget = spec.budget_as(ctx.quick)?;
    let methods = spec
        .methods
        .iter()
        .map(|m| Ok((m.key.clone(), Method::from_spec(m)?)))
        .collect::<Result<Vec<_>>>()?;
    let mut out = Computed::default();

    // the synthetic flight always runs
    let synthetic = synthetic_flight(ctx.seed, budget.synthetic_quick, &setup)?;
    out.data.push(format!(
        "{} (generated, seed {}): {} frames",
        synthetic.name,
        ctx.seed,
        synthetic.times.len()
    ));
    let syn = run_flight(ctx, &setup, &methods, synthetic, budget.seeds, "synthetic")?;

    // the real flight when the data is present
    if let Some(dir) = out.locate(spec, ctx, "adsb")? {
        let choice = load_flight(&dir, &setup, budget.real_frames)?;
        out.data.push(choice.description.clone());
        let real = run_flight(ctx, &setup, &methods, choice.flight, budget.seeds, "ADS-B")?;
        tables(&mut out, "table1", "table1_noise", &real, &setup)?;
        let paper = spec
            .paper_figure("table1", "paper", "cv-mkpf")
            .ok_or_else(|| experiment::experiment_err("no paper figure for table1/cv-mkpf"))?;
        let seeds = seeds_from(ctx.seed, budget.seeds);
        gap::tables(&mut out, &real, &setup, &seeds, paper)?;
        out.figures.extend(figures(
            "fig_flight",
            "ADS-B flight",
            &real,
            setup.particles,
        ));
    }
    tables(&mut out, "table2", "table2_noise", &syn, &setup)?;
    out.figures.extend(figures(
        "fig_synthetic",
        "synthetic flight",
        &syn,
        setup.particles,
    ));
    assemble(spec, ctx, out)
}
