//! MKPF (`docs/papers.md` C.2): keep one frame in every 50 of a real flight, predict the frames in
//! between from the kept ones only, and compare with the true frames by the paper's relative
//! error `sqrt(mean(((x_hat - x) / x)^2))` on geodetic coordinates (the paper: 0.03% for the
//! MKPF) and in metres. Compared: the MKPF, the bootstrap PF with the same particle count
//! (and ten times as many), the UKF and the EKF, each with a constant-velocity and a
//! coordinated-turn model. A synthetic coordinated-turn flight runs the same protocol without
//! data. The experiment itself is in [`experiment`]; `docs/mkpf.md` says what the paper left
//! open and what we chose.

pub mod experiment;

use crate::report::{Figure, PaperResult, Table, Value};
use crate::{Context, Result};
use experiment::{
    ACCEL_GRID, ADSB_FILE, Flight, INITIAL_SPEED_SD, MAX_GAP_S, MAX_Q_CONDITION, Method, Motion,
    Noise, Run, Setup, TURN_GRID, TURN_RATE_SD_GRID, choose_noise, load_flight, run_method,
    synthetic_flight,
};
use trajpred::plot::{Chart, Series};

/// Why this paper's numbers and ours differ (shown in the results index).
pub const EXPLANATION: &str = "The paper reports a single relative error for the MKPF on an \
undisclosed BeiDou flight, with no figures for other filters, no noise levels and no particle \
count. We run its protocol (keep one frame in every fifty, predict the frames in between from \
the kept ones, relative error on geodetic coordinates) on a public ADS-B flight with stated \
noise levels, a process noise chosen by likelihood on the kept frames only, and report the \
error in metres beside it, because the relative error on latitude and longitude mostly \
measures how far the aircraft is from the equator and the Greenwich meridian.";

/// The paper's relative error of the MKPF, percent (`docs/papers.md` C.2).
const PAPER_RELATIVE_ERROR_PCT: f64 = 0.03;

/// Particles of the MKPF and of the bootstrap PF it is compared with.
const PARTICLES: usize = 100;
/// The second bootstrap PF has this many times as many particles.
const BOOTSTRAP_FACTOR: usize = 10;

struct Settings {
    seeds: usize,
    synthetic_quick: bool,
    real_frames: Option<usize>,
}

fn settings(ctx: &Context) -> Settings {
    if ctx.quick {
        Settings {
            seeds: 2,
            synthetic_quick: true,
            real_frames: Some(751),
        }
    } else {
        Settings {
            seeds: 5,
            synthetic_quick: false,
            real_frames: None,
        }
    }
}

fn methods() -> [Method; 6] {
    [
        Method::Mkpf(PARTICLES),
        Method::MkpfConditioned(PARTICLES),
        Method::Bootstrap(PARTICLES),
        Method::Bootstrap(PARTICLES * BOOTSTRAP_FACTOR),
        Method::Ukf,
        Method::Ekf,
    ]
}

/// All runs of one method and motion model on one flight.
#[derive(Debug, Clone)]
pub struct MethodRuns {
    /// The motion model.
    pub motion: Motion,
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

/// Summary numbers of one row.
#[derive(Debug, Clone, Copy)]
struct Summary {
    rel_pct: (f64, f64),
    rmse: (f64, f64),
    mean_m: f64,
    max_m: f64,
    seconds: f64,
}

fn summarize(rows: &MethodRuns) -> Result<Summary> {
    let mut rel = Vec::new();
    let mut rmse = Vec::new();
    let mut mean_m = Vec::new();
    let mut max_m = Vec::new();
    let mut secs = Vec::new();
    for r in &rows.runs {
        rel.push(100.0 * r.relative_error()?);
        let e = r.errors_m();
        let n = e.len().max(1) as f64;
        rmse.push((e.iter().map(|x| x * x).sum::<f64>() / n).sqrt());
        mean_m.push(e.iter().sum::<f64>() / n);
        max_m.push(e.iter().copied().fold(0.0, f64::max));
        secs.push(r.seconds);
    }
    Ok(Summary {
        rel_pct: mean_sd(&rel),
        rmse: mean_sd(&rmse),
        mean_m: mean_sd(&mean_m).0,
        max_m: mean_sd(&max_m).0,
        seconds: mean_sd(&secs).0,
    })
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

/// Runs every method and motion model on `flight`.
pub fn run_flight(ctx: &Context, flight: Flight, seeds: usize, tag: &str) -> Result<FlightResult> {
    let setup = Setup::default();
    let mut noise = Vec::new();
    let mut rows = Vec::new();
    let ms = methods();
    let bar = ctx.bar((2 * ms.len()) as u64, format!("mkpf {tag}"));
    for motion in [Motion::Cv, Motion::Ct] {
        let q = choose_noise(&flight, &setup, motion)?;
        noise.push((motion, q));
        for method in ms {
            let n = if method.particles().is_some() {
                seeds
            } else {
                1
            };
            let runs = (0..n)
                .map(|i| {
                    let seed = ctx
                        .seed
                        .wrapping_add((i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
                    run_method(&flight, &setup, motion, &q, method, seed)
                })
                .collect::<Result<Vec<_>>>()?;
            rows.push(MethodRuns {
                motion,
                method,
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

fn results_table(id: &str, title: &str, res: &FlightResult, paper: bool) -> Result<Table> {
    let mut t = Table::new(id, title)
        .label("model")
        .label("method")
        .label("particles")
        .ours("runs", 0, 0.0, 0.0)
        .ours("relative error (%)", 5, 1e-15, 1e-9)
        .paper("relative error (%), paper", 2)
        .ours("relative error sd (%)", 5, 1e-15, 1e-9)
        .ours("RMSE (m)", 1, 1e-9, 1e-9)
        .ours("RMSE sd (m)", 1, 1e-9, 1e-9)
        .ours("mean error (m)", 1, 1e-9, 1e-9)
        .ours("max error (m)", 1, 1e-9, 1e-9)
        .timing("wall time per run (s)", 3);
    for r in &res.rows {
        let s = summarize(r)?;
        let paper_value = match (paper, r.method) {
            (true, Method::Mkpf(_)) => Value::Num(PAPER_RELATIVE_ERROR_PCT),
            _ => Value::Missing,
        };
        t.push(vec![
            r.motion.name().into(),
            r.method.name().into(),
            r.method
                .particles()
                .map_or_else(|| "-".to_string(), |n| n.to_string())
                .into(),
            r.runs.len().into(),
            s.rel_pct.0.into(),
            paper_value,
            s.rel_pct.1.into(),
            s.rmse.0.into(),
            s.rmse.1.into(),
            s.mean_m.into(),
            s.max_m.into(),
            s.seconds.into(),
        ])?;
    }
    t.note(format!(
        "{}: {} frames; one frame in every {} kept ({} kept), the frames in between predicted \
         from the kept frames only and compared with the true frames; the frames before the \
         second kept frame are not evaluated (the filters start from a position without \
         velocity).",
        res.flight.name,
        res.flight.times.len(),
        Setup::default().keep_every,
        experiment::kept_frames(res.flight.times.len(), Setup::default().keep_every).len(),
    ));
    t.note(
        "Relative error: the paper's sqrt(mean(((x_hat - x)/x)^2)) over latitude and longitude \
         (degrees) of every evaluated frame, in percent. Metres: horizontal Euclidean error in \
         the local east-north frame. Particle filters: mean over seeds, sd = sample standard \
         deviation over seeds; the Kalman filters are deterministic (one run).",
    );
    Ok(t)
}

fn noise_table(id: &str, title: &str, res: &FlightResult) -> Result<Table> {
    let mut t = Table::new(id, title)
        .label("model")
        .ours("acceleration noise (m^2/s^3)", 3, 0.0, 1e-12)
        .ours("turn-rate noise (rad^2/s^3)", 9, 0.0, 1e-12)
        .ours("initial turn-rate sd (rad/s)", 3, 0.0, 1e-12)
        .ours("log-likelihood of the kept frames", 2, 1e-9, 1e-9);
    for (m, q) in &res.noise {
        t.push(vec![
            m.name().into(),
            q.accel.into(),
            match m {
                Motion::Cv => Value::Missing,
                Motion::Ct => q.turn.into(),
            },
            match m {
                Motion::Cv => Value::Missing,
                Motion::Ct => q.turn_rate_sd.into(),
            },
            q.log_likelihood.into(),
        ])?;
    }
    t.note(format!(
        "Chosen by the UKF log-likelihood of the kept frames only (never the compared frames), \
         over the grid {ACCEL_GRID:?} (continuous white-noise acceleration, per axis) and, for \
         the coordinated turn, {TURN_GRID:?} (turn-rate random walk) with the initial turn-rate sd \
         in {TURN_RATE_SD_GRID:?}; coordinated-turn noises whose Q has a condition number over \
         {MAX_Q_CONDITION:e} are skipped. Observation noise fixed \
         at sd {} m per axis.",
        experiment::POSITION_SD_M
    ));
    Ok(t)
}

fn find(res: &FlightResult, motion: Motion, method: Method) -> Option<&MethodRuns> {
    res.rows
        .iter()
        .find(|r| r.motion == motion && r.method == method)
}

fn figures(id: &str, what: &str, res: &FlightResult) -> Vec<Figure> {
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
        Method::Mkpf(PARTICLES),
        Method::Ukf,
        Method::Bootstrap(PARTICLES),
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
        Method::Mkpf(PARTICLES),
        Method::Bootstrap(PARTICLES),
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

/// Claims on one flight; `label` names it in the statements.
fn claims(
    result: &mut PaperResult,
    res: &FlightResult,
    label: &str,
    about_paper: bool,
) -> Result<()> {
    let rmse = |motion, method| -> Result<Option<f64>> {
        match find(res, motion, method) {
            Some(r) => Ok(Some(summarize(r)?.rmse.0)),
            None => Ok(None),
        }
    };
    let rel = |motion| -> Result<Option<f64>> {
        match find(res, motion, Method::Mkpf(PARTICLES)) {
            Some(r) => Ok(Some(summarize(r)?.rel_pct.0)),
            None => Ok(None),
        }
    };
    if about_paper {
        let (cv, ct) = (rel(Motion::Cv)?, rel(Motion::Ct)?);
        if let (Some(cv), Some(ct)) = (cv, ct) {
            let best = cv.min(ct);
            result.claim(
                format!(
                    "{label}: the MKPF's relative error is about the paper's \
                     {PAPER_RELATIVE_ERROR_PCT}% (within a factor of two, better model)"
                ),
                (PAPER_RELATIVE_ERROR_PCT / 2.0..=PAPER_RELATIVE_ERROR_PCT * 2.0).contains(&best),
                format!("MKPF relative error: CV {cv:.5}%, CT {ct:.5}% (paper {PAPER_RELATIVE_ERROR_PCT}%)"),
            );
        }
    }
    let mut beats = |other: Method, what: &str| -> Result<()> {
        let mut holds = true;
        let mut ev = Vec::new();
        for motion in [Motion::Cv, Motion::Ct] {
            let (Some(a), Some(b)) = (rmse(motion, Method::Mkpf(PARTICLES))?, rmse(motion, other)?)
            else {
                continue;
            };
            holds &= a < b;
            ev.push(format!(
                "{}: MKPF {a:.1} m vs {} {b:.1} m",
                motion.name(),
                other.name()
            ));
        }
        result.claim(
            format!("{label}: the MKPF beats {what} (RMSE in metres, both models)"),
            holds,
            ev.join("; "),
        );
        Ok(())
    };
    beats(
        Method::Bootstrap(PARTICLES),
        &format!("the bootstrap PF with the same particle count ({PARTICLES})"),
    )?;
    beats(Method::Ukf, "the UKF")?;
    beats(Method::Ekf, "the EKF")?;
    Ok(())
}

/// Runs the paper's experiments.
pub fn run(ctx: &Context) -> Result<PaperResult> {
    let s = settings(ctx);
    let mut result = PaperResult::new();
    let setup = Setup::default();

    // the synthetic flight always runs
    let synthetic = synthetic_flight(ctx.seed, s.synthetic_quick, setup.position_sd)?;
    result.data.push(format!(
        "{} (generated, seed {}): {} frames",
        synthetic.name,
        ctx.seed,
        synthetic.times.len()
    ));
    let syn = run_flight(ctx, synthetic, s.seeds, "synthetic")?;

    // the real flight when the data is present
    let real = match ctx.data("adsb-traffic") {
        Some(dir) => {
            let choice = load_flight(&dir, s.real_frames)?;
            result.data.push(choice.description.clone());
            Some(run_flight(ctx, choice.flight, s.seeds, "ADS-B")?)
        }
        None => {
            result.missing.push(ctx.missing(
                "adsb-traffic",
                &format!(
                    "mkpf/table1 and the flight figures (one frame in every {} of the longest \
                     clean flight of {ADSB_FILE}, MKPF vs bootstrap PF, UKF, EKF)",
                    setup.keep_every
                ),
            ));
            None
        }
    };

    if let Some(real) = &real {
        result.tables.push(results_table(
            "table1",
            "Table 1: one frame in 50 kept, the in-between frames predicted, real ADS-B flight \
             (relative error on latitude/longitude and horizontal error in metres)",
            real,
            true,
        )?);
        result.tables.push(noise_table(
            "table1_noise",
            "Table 1b: process noise of each model, chosen on the kept frames of the real flight",
            real,
        )?);
        result
            .figures
            .extend(figures("fig_flight", "ADS-B flight", real));
        claims(&mut result, real, "real flight", true)?;
    }
    result.tables.push(results_table(
        "table2",
        "Table 2: the same protocol on a synthetic coordinated-turn flight (truth known without \
         noise)",
        &syn,
        false,
    )?);
    result.tables.push(noise_table(
        "table2_noise",
        "Table 2b: process noise of each model, chosen on the kept frames of the synthetic flight",
        &syn,
    )?);
    result
        .figures
        .extend(figures("fig_synthetic", "synthetic flight", &syn));
    claims(&mut result, &syn, "synthetic flight", real.is_none())?;

    result.notes.extend(notes(&s, &setup));
    Ok(result)
}

fn notes(s: &Settings, setup: &Setup) -> Vec<String> {
    vec![
        "The relative error on geodetic coordinates is a weak measure: it divides each error in \
         degrees by the latitude or longitude itself, so the same error in metres gives a \
         smaller relative error far from the equator (latitude) and a much larger one near the \
         Greenwich meridian (longitude); it says where the flight is as much as how good the \
         filter is. The error in metres is the measure to compare filters; the relative error \
         is reported only to stand beside the paper's figure."
            .to_string(),
        "Why our numbers differ from the paper's: its flight (BeiDou reports), its sampling \
         interval, its noise levels, its motion model and its particle count are not given, and \
         it reports no baseline. A slower report rate or a straighter flight gives smaller \
         errors with the same protocol."
            .to_string(),
        format!(
            "Flight: {ADSB_FILE}, the longest run of fresh position reports (repeated positions \
             dropped, split at gaps over {MAX_GAP_S} s). Filtering in local east-north metres \
             (tangent plane at the first report, height 0); predictions converted back to \
             latitude/longitude for the relative error. Altitude is not filtered (the \
             coordinated turn is a horizontal model)."
        ),
        format!(
            "Noise: observation sd {} m per axis (a stated ADS-B accuracy, not fitted); process \
             noise chosen per model by the UKF likelihood of the kept frames only (Tables 1b, \
             2b), shared by all four filters. Initial state: the first kept position, zero \
             velocity with sd {INITIAL_SPEED_SD} m/s per axis, turn rate 0 with the sd chosen \
             with the process noise.",
            setup.position_sd
        ),
        format!(
            "Particle filters: the MKPF and the bootstrap PF with {PARTICLES} particles each, \
             and a bootstrap PF with {} particles; residual resampling at every step (the \
             paper); MKPF with the crate's defaults (carried particle covariances, augmented \
             UKF, relinearised EKF stage, Merwe sigma points alpha 1e-3, beta 2, kappa 0), and \
             once more with the conditioned particle prior (docs/particle.md). The \
             step between kept frames varies with the report times, so the filters are rebuilt \
             for each new step with the same particles; the MKPF's particles then all carry the \
             mean of their covariances (exact for the linear CV model, an approximation for the \
             coordinated turn). In-between positions of the particle filters are the weighted \
             means of the particles pushed through the model without noise. {} seeds per \
             particle filter.",
            PARTICLES * BOOTSTRAP_FACTOR,
            s.seeds
        ),
        "Reproducibility: every random number comes from seeded ChaCha8 generators; the \
         particle filters draw them sequentially, so the tables do not depend on the number of \
         rayon threads; --check compares them with a relative tolerance of 1e-9."
            .to_string(),
    ]
}
