//! The KFU-LSTM-Net patent (`docs/papers.md` D.2): one-step-ahead prediction from noisy
//! observations on three simulated 3-D curves and one real flight, RNN and LSTM against the
//! Kalman-filter-unfolded LSTM, scored against the clean truth.
//!
//! The experiment (written up with the equations in `docs/kfu-lstm.md`):
//!
//! - **Series.** The three [`PatentCurve`]s, `n` points at `dt` (full run: 1000 at 0.1 s),
//!   metres; and, when `ctx.data("adsb-traffic")` is present, the 200-point window of flight
//!   `3e4b2e`/`DITRA` in `samples/collections/quickstart.json.gz` starting at the first point
//!   at or after 2021-10-07 13:34:57 UTC (`flight_start` of the spec; SOURCE.md's ready-made window:
//!   climb, level-off, climb, about 245° of turning), converted to local east-north-up metres
//!   around the window's first point. The recorded positions are the flight's truth.
//! - **Noise.** Independent Gaussian noise per axis: σ = `curve_sigma` m on every axis of
//!   the curves; `flight_sigma` (east, north, up) on the flight. Repetition `r` of series
//!   `s` draws from `ChaCha8Rng::seed_from_u64(ctx.seed + 100 r + s)` (wrapping), axis by
//!   axis, point by point, `noisy = truth + σ_axis * StandardNormal`.
//! - **Split.** Train on the first 80% (`n * 4 / 5` points), predict every point of the last
//!   20% one step ahead from the noisy observations before it (the history may reach back into
//!   the training part), score the 3-D RMSE `sqrt(mean ||p - y||²)` and the per-axis RMSE
//!   against the truth.
//! - **Methods.** `RnnNet::patent_baseline(10, 1)` and `LstmNet::patent_baseline(10, 1)`
//!   trained on the noisy training part (their targets are the next noisy point: the window
//!   API has no separate truth); `KfuLstmNet::patent()` trained with `fit_supervised` on the
//!   noisy training part and its truth. Network seed of repetition `r`, series `s`:
//!   `ctx.seed + 100 r + s`. Two reference rows: the noisy observation `z(t)` itself (not a
//!   forecast: what "beating the noise" means) and persistence `z(t-1)`.
//!
//! The table's layout and the claims are in `papers/kfu-lstm.toml`; this module computes the
//! numbers ([`train`]: training and scoring; `flight`: the real flight and the figures).

use crate::pool::map_in_parallel;
use crate::runner::{Computed, Row, assemble};
use crate::{Context, Paper, PaperResult, ReproError, Result, Value};
use flight::{figures, load_flight};
use serde::Deserialize;
use train::{Case, MethodRun, run_once};
use trajpred_data::synthetic::PatentCurve;

mod fair;
mod flight;
pub mod train;

pub use train::{observe, seed_of, train_len};

/// The experiment's fixed settings (`[params]` of the spec).
#[derive(Debug, Clone, Deserialize)]
pub(crate) struct Params {
    /// Noise sd (m) on every axis of the simulated curves.
    curve_sigma: f64,
    /// Noise sd (m) on the flight's east, north and up.
    flight_sigma: [f64; 3],
    /// First timestamp (s since the Unix epoch) of the flight window.
    flight_start: f64,
    /// Points in the flight window.
    flight_points: usize,
    /// The flight's file under the adsb-traffic folder, and its track id.
    flight_file: String,
    flight_id: String,
    /// Window length of the RNN and LSTM baselines, and the batch of every network.
    window: usize,
    batch: usize,
    /// How the all-series claim names its scope, with and without the real flight.
    scope_with_flight: String,
    scope_without_flight: String,
}

/// Run sizes (`[budget]` of the spec): full or quick.
#[derive(Debug, Clone, Deserialize)]
pub(crate) struct Budget {
    /// Points per simulated curve, and their sampling interval (s).
    n: usize,
    dt: f64,
    /// Epochs of the RNN and LSTM baselines, and of the KFU-LSTM-Net, on a curve of `n`
    /// points (other series: the same number of gradient steps).
    epochs_baseline: usize,
    epochs_kfu: usize,
    /// Learning rate of the KFU-LSTM-Net's weights.
    kfu_lr: f64,
    /// Repetitions (noise draw and network seed).
    reps: usize,
    /// The fair test (`fair`): epochs of every model on a curve (other series: scaled by
    /// the fit part's length), seeds, and the validation grid of hidden sizes and learning
    /// rates.
    fair_epochs: usize,
    fair_seeds: usize,
    fair_hidden: Vec<usize>,
    fair_lr: Vec<f64>,
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn sample_sd(v: &[f64]) -> Option<f64> {
    if v.len() < 2 {
        return None;
    }
    let m = mean(v);
    Some((v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt())
}

/// The rows of one series (means over the repetitions `runs[rep][method]`); returns the mean
/// 3-D RMSE per method.
fn series_rows(
    spec_keys: &[String],
    case: &Case,
    runs: &[Vec<MethodRun>],
    out: &mut Computed,
) -> Vec<f64> {
    let mut means = Vec::new();
    for (mi, key) in spec_keys.iter().enumerate() {
        let r3: Vec<f64> = runs.iter().map(|r| r[mi].score.rmse3).collect();
        let ax = |k: usize| -> f64 {
            mean(
                &runs
                    .iter()
                    .map(|r| r[mi].score.axes.get(k).copied().unwrap_or(f64::NAN))
                    .collect::<Vec<_>>(),
            )
        };
        let times: Vec<f64> = runs.iter().filter_map(|r| r[mi].score.train_s).collect();
        means.push(mean(&r3));
        out.table("table3").rows.push(
            Row::new(format!("{}:{key}", case.name))
                .set("rmse", mean(&r3))
                .set("sd", sample_sd(&r3))
                .set("axis1", ax(0))
                .set("axis2", ax(1))
                .set("axis3", ax(2))
                .set(
                    "epochs",
                    runs.first()
                        .and_then(|r| r[mi].epochs)
                        .map_or(Value::Missing, Value::from),
                )
                .set(
                    "train_s",
                    if times.is_empty() {
                        Value::Missing
                    } else {
                        mean(&times).into()
                    },
                ),
        );
    }
    out.table("table3").notes.push(format!(
        "{}: axes 1-3 are {}, {}, {}",
        case.name, case.axes[0], case.axes[1], case.axes[2]
    ));
    means
}

/// Runs the paper's experiments and builds its report from the spec.
pub fn run(ctx: &Context) -> Result<PaperResult> {
    let spec = Paper::KfuLstm.spec()?;
    let p: Params = spec.params()?;
    let s: Budget = spec.budget_as(ctx.quick)?;
    let mut out = Computed::default();

    let mut cases = Vec::new();
    for c in PatentCurve::ALL {
        cases.push(Case {
            name: c.name().to_string(),
            truth: c.generate(s.n, s.dt)?,
            sigma: [p.curve_sigma; 3],
            axes: ["x", "y", "z"],
        });
        out.data.push(format!(
            "{}: PatentCurve::{:?}.generate({}, {}) (equations in docs/kfu-lstm.md), metres, \
             Gaussian noise σ = {} m per axis",
            c.name(),
            c,
            s.n,
            s.dt,
            p.curve_sigma
        ));
    }
    if let Some(dir) = out.locate(spec, ctx, "adsb")? {
        let (truth, desc) = load_flight(&dir, &p)?;
        cases.push(Case {
            name: "flight".into(),
            truth,
            sigma: p.flight_sigma,
            axes: ["east", "north", "up"],
        });
        out.data.push(desc);
    }

    let keys: Vec<String> = spec.methods.iter().map(|m| m.key.clone()).collect();
    let labels: Vec<&str> = spec.methods.iter().map(|m| m.label.as_str()).collect();
    let bar = ctx.bar((cases.len() * s.reps) as u64, "kfu-lstm: series x seeds");
    let mut beats = Vec::new();
    let mut persistence = Vec::new();
    // every (series, seed) run is seeded on its own: two workers pull them in order, as the
    // fair comparison's jobs, and the results do not depend on which worker ran which
    let jobs: Vec<(usize, usize)> = (0..cases.len())
        .flat_map(|si| (0..s.reps).map(move |rep| (si, rep)))
        .collect();
    let mut done = map_in_parallel(&jobs, 2, |&(si, rep)| -> Result<(_, Vec<MethodRun>)> {
        let case = &cases[si];
        let seed = seed_of(ctx.seed, si, rep);
        let noisy = observe(&case.truth, &case.sigma, seed)?;
        let runs = run_once(case, &noisy, seed, &p, &s)?;
        bar.inc(1);
        Ok((noisy, runs))
    })
    .into_iter();
    for case in &cases {
        // runs[rep][method]
        let mut runs: Vec<Vec<MethodRun>> = Vec::new();
        for rep in 0..s.reps {
            let (noisy, run) = done.next().ok_or_else(|| ReproError::Experiment {
                experiment: format!("kfu-lstm/{}", case.name),
                reason: "a seed's run is missing".into(),
            })??;
            if rep == 0 {
                figures(&labels, &mut out.figures, case, &noisy, &run)?;
            }
            runs.push(run);
        }
        let m = series_rows(&keys, case, &runs, &mut out);
        beats.push(format!(
            "{}: KFU {:.4}, RNN {:.4}, LSTM {:.4} m",
            case.name, m[4], m[2], m[3]
        ));
        persistence.push(format!(
            "{}: KFU {:.4}, persistence {:.4} m",
            case.name, m[4], m[1]
        ));
    }
    bar.finish_and_clear();
    fair::run(&cases, ctx.seed, &p, &s, &mut out)?;
    out.var("fair_epochs", s.fair_epochs);
    out.var("fair_seeds", s.fair_seeds);
    out.var(
        "fair_grid",
        format!("hidden {:?} x lr {:?}", s.fair_hidden, s.fair_lr),
    );
    let flight = cases.iter().any(|c| c.name == "flight");
    out.var(
        "scope",
        if flight {
            p.scope_with_flight.as_str()
        } else {
            p.scope_without_flight.as_str()
        },
    );
    out.var("beats_evidence", beats.join("; "));
    out.var("persistence_evidence", persistence.join("; "));
    out.var("n_train", train_len(s.n));
    out.var("n_test", s.n - train_len(s.n));
    assemble(spec, ctx, out)
}
