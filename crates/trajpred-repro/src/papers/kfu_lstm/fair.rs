//! A fair test of the patent's claim (issue 23): RNN, LSTM and KFU-LSTM-Net trained on the
//! same targets, the same noisy inputs and the same epochs, each with its hidden size and
//! learning rate chosen on the same validation split, over several seeds; once with every
//! model trained against the clean truth, once against the next noisy observation.
//!
//! Per series, seed and target choice: the training part (first 80%) is split again, the
//! first 80% of it to fit (`n_fit` points) and the rest to validate. Every configuration of
//! the grid (`fair_hidden` x `fair_lr`) is fitted on the fit part; the one with the lowest
//! one-step RMSE on the validation points against the chosen target (truth or noisy
//! observation) is kept, without refitting, and scored one step ahead on the test part
//! against the truth. The test part is never seen before the scoring.

use super::train::{Case, observe, points, seed_of, train_len};
use super::{Budget, Params};
use crate::pool::map_in_parallel;
use crate::runner::{Computed, Row};
use crate::{ReproError, Result, Value};
use std::time::Instant;
use trajpred_core::Trajectory;
use trajpred_neural::{
    AxisMode, KfuConfig, KfuLstmNet, LstmArch, RecurrentLayers, RnnArch, TrainConfig, WindowConfig,
    WindowNet,
};

/// The models compared, by row key.
const MODELS: [&str; 3] = ["rnn", "lstm", "kfu"];
/// The target choices, by table suffix: the clean truth, the next noisy observation.
const TARGETS: [&str; 2] = ["truth", "noisy"];

/// One model trained on one noisy draw with one target choice.
struct Job<'a> {
    case: &'a Case,
    noisy: &'a Trajectory,
    seed: u64,
    target: usize,
    model: usize,
}

/// What one job produced: test RMSE of the chosen configuration, the choice, and the
/// training time of the whole grid.
struct Outcome {
    rmse: f64,
    hidden: usize,
    lr: f64,
    train_s: f64,
}

fn exp_err(case: &Case, reason: String) -> ReproError {
    ReproError::Experiment {
        experiment: format!("kfu-lstm/fair/{}", case.name),
        reason,
    }
}

/// Epochs on a series whose fit part has `n_fit` points: `fair_epochs` on a curve of the
/// budget's size, scaled up for shorter series so that every model takes as many passes'
/// worth of samples as on a curve (the same factor for every model).
pub(super) fn fair_epochs(s: &Budget, n_fit: usize) -> usize {
    let curve_fit = train_len(train_len(s.n));
    (s.fair_epochs * curve_fit).div_ceil(n_fit.max(1)).max(1)
}

/// One-step predictions of points `a..b` from the noisy observations before each.
fn predict(model: &Fitted, obs: &Trajectory, a: usize, b: usize) -> Result<Vec<Vec<f64>>> {
    match model {
        Fitted::Window(net, m) => {
            let pts = points(obs);
            let mut out = Vec::with_capacity(b - a);
            for t in a..b {
                let w = pts.get(t.saturating_sub(*m)..t).unwrap_or(&[]);
                out.extend(net(w)?.into_iter().next());
            }
            Ok(out)
        }
        Fitted::Kfu(k) => {
            let c = k.config().seq_len.min(a);
            let ahead = k.one_step_ahead(&obs.slice(a - c..b)?)?;
            Ok(ahead.get(c.saturating_sub(1)..).unwrap_or(&[]).to_vec())
        }
    }
}

type WindowPredict = Box<dyn Fn(&[Vec<f64>]) -> Result<Vec<Vec<f64>>>>;

enum Fitted {
    Window(WindowPredict, usize),
    Kfu(Box<KfuLstmNet>),
}

fn window_net<A>(
    arch: A,
    p: &Params,
    tc: TrainConfig,
    fit_in: &Trajectory,
    fit_tgt: Option<&Trajectory>,
) -> Result<Fitted>
where
    A: trajpred_neural::Architecture + 'static,
{
    let layout = WindowConfig {
        window: p.window,
        horizon: 1,
        axes: AxisMode::Joint,
    };
    let mut net = WindowNet::new(arch, layout, tc)?;
    match fit_tgt {
        Some(t) => net.fit_targets(
            std::slice::from_ref(fit_in),
            std::slice::from_ref(t),
            &mut |_| {},
        )?,
        None => net.fit_with(std::slice::from_ref(fit_in), &mut |_| {})?,
    };
    let m = p.window;
    Ok(Fitted::Window(
        Box::new(move |w| Ok(net.predict_window(w)?)),
        m,
    ))
}

fn fit_one(job: &Job, p: &Params, s: &Budget, hidden: usize, lr: f64) -> Result<Fitted> {
    let n_fit = train_len(train_len(job.case.truth.len()));
    let fit_in = job.noisy.prefix(n_fit)?;
    let truth_fit = job.case.truth.prefix(n_fit)?;
    let fit_tgt = (job.target == 0).then_some(&truth_fit);
    let tc = TrainConfig::new(lr)
        .with_epochs(fair_epochs(s, n_fit))
        .with_batch_size(p.batch)
        .with_seed(job.seed);
    let rec = RecurrentLayers {
        layers: vec![hidden, hidden],
        fc: vec![hidden],
        ..RecurrentLayers::default()
    };
    match job.model {
        0 => window_net(RnnArch(rec), p, tc, &fit_in, fit_tgt),
        1 => window_net(LstmArch(rec), p, tc, &fit_in, fit_tgt),
        _ => {
            let cfg = KfuConfig {
                layers: vec![hidden, hidden],
                fc: vec![hidden],
                ..KfuConfig::default()
            };
            let mut k = KfuLstmNet::new(cfg, tc)?;
            match fit_tgt {
                Some(t) => k.fit_supervised(
                    std::slice::from_ref(&fit_in),
                    std::slice::from_ref(t),
                    &mut |_| {},
                )?,
                None => k.fit_observed(std::slice::from_ref(&fit_in), &mut |_| {})?,
            };
            Ok(Fitted::Kfu(Box::new(k)))
        }
    }
}

fn rmse(pred: &[Vec<f64>], want: &[Vec<f64>], case: &Case) -> Result<f64> {
    if pred.len() != want.len() {
        return Err(exp_err(
            case,
            format!("{} predictions for {} points", pred.len(), want.len()),
        ));
    }
    Ok(trajpred_metrics::rms_euclidean_error(pred, want)?)
}

/// Runs the grid of one job, keeps the configuration best on validation, scores it on test.
fn run_job(job: &Job, p: &Params, s: &Budget) -> Result<Outcome> {
    let n = job.case.truth.len();
    let n_train = train_len(n);
    let n_fit = train_len(n_train);
    let truth = points(&job.case.truth);
    let obs = points(job.noisy);
    let val_want = if job.target == 0 { &truth } else { &obs };
    let start = Instant::now();
    let mut best: Option<(f64, usize, f64, Fitted)> = None;
    for &hidden in &s.fair_hidden {
        for &lr in &s.fair_lr {
            let f = fit_one(job, p, s, hidden, lr)?;
            let v = predict(&f, job.noisy, n_fit, n_train)?;
            let score = rmse(&v, &val_want[n_fit..n_train], job.case)?;
            // a diverged configuration (NaN) never wins
            if best.as_ref().is_none_or(|b| score < b.0) {
                best = Some((score, hidden, lr, f));
            }
        }
    }
    let train_s = start.elapsed().as_secs_f64();
    let (_, hidden, lr, f) =
        best.ok_or_else(|| exp_err(job.case, "no configuration gave a finite score".into()))?;
    let pred = predict(&f, job.noisy, n_train, n)?;
    Ok(Outcome {
        rmse: rmse(&pred, &truth[n_train..], job.case)?,
        hidden,
        lr,
        train_s,
    })
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn sd(v: &[f64]) -> Option<f64> {
    (v.len() >= 2).then(|| {
        let m = mean(v);
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
    })
}

/// Runs the fair test on `cases` and adds the tables `fair_truth` and `fair_noisy` and the
/// variables their notes and claims use.
pub(super) fn run(
    cases: &[Case],
    base_seed: u64,
    p: &Params,
    s: &Budget,
    out: &mut Computed,
) -> Result<()> {
    let mut draws = Vec::new();
    for (si, case) in cases.iter().enumerate() {
        for rep in 0..s.fair_seeds {
            let seed = seed_of(base_seed, si, rep);
            draws.push((case, observe(&case.truth, &case.sigma, seed)?, seed));
        }
    }
    let mut jobs = Vec::new();
    for (case, noisy, seed) in &draws {
        for target in 0..TARGETS.len() {
            for model in 0..MODELS.len() {
                jobs.push(Job {
                    case,
                    noisy,
                    seed: *seed,
                    target,
                    model,
                });
            }
        }
    }
    // two workers pull jobs in order; each job is seeded, so the results do not depend on
    // which worker ran it
    let done = map_in_parallel(&jobs, 2, |job| run_job(job, p, s))
        .into_iter()
        .collect::<Result<Vec<Outcome>>>()?;
    summarise(cases, &jobs, &done, s, out);
    Ok(())
}

fn summarise(cases: &[Case], jobs: &[Job], done: &[Outcome], s: &Budget, out: &mut Computed) {
    for (ti, tname) in TARGETS.iter().enumerate() {
        let table = format!("fair_{tname}");
        let mut evidence = Vec::new();
        let mut choices = Vec::new();
        for case in cases {
            let of = |mi: usize| -> Vec<&Outcome> {
                jobs.iter()
                    .zip(done)
                    .filter(|(j, _)| j.case.name == case.name && j.target == ti && j.model == mi)
                    .map(|(_, o)| o)
                    .collect()
            };
            let kfu: Vec<f64> = of(2).iter().map(|o| o.rmse).collect();
            let (km, ks) = (mean(&kfu), sd(&kfu).unwrap_or(f64::NAN));
            let mut ev = format!("{}: KFU {km:.4} ± {ks:.4}", case.name);
            for (mi, key) in MODELS.iter().enumerate() {
                let runs = of(mi);
                let r: Vec<f64> = runs.iter().map(|o| o.rmse).collect();
                let (m, d) = (mean(&r), sd(&r));
                let n_fit = train_len(train_len(case.truth.len()));
                let mut row = Row::new(format!("{}:{key}", case.name))
                    .set("rmse", m)
                    .set("sd", d)
                    .set("min", r.iter().copied().fold(f64::INFINITY, f64::min))
                    .set("max", r.iter().copied().fold(f64::NEG_INFINITY, f64::max))
                    .set("epochs", fair_epochs(s, n_fit) as f64)
                    .set(
                        "train_s",
                        mean(&runs.iter().map(|o| o.train_s).collect::<Vec<_>>()),
                    );
                if mi < 2 {
                    let pooled = d.map(|d| ((d * d + ks * ks) / 2.0).sqrt());
                    row = row.set("pooled", pooled);
                    ev.push_str(&format!(
                        ", {} {m:.4} ± {:.4} (margin {:.4} - pooled sd {:.4})",
                        key.to_uppercase(),
                        d.unwrap_or(f64::NAN),
                        m - km,
                        pooled.unwrap_or(f64::NAN)
                    ));
                } else {
                    row = row.set("pooled", Value::Missing);
                }
                out.table(&table).rows.push(row);
                let picks: Vec<String> = runs
                    .iter()
                    .map(|o| format!("{}/{:e}", o.hidden, o.lr))
                    .collect();
                choices.push(format!("{} {key}: {}", case.name, picks.join(", ")));
            }
            evidence.push(ev);
        }
        out.var(&format!("fair_{tname}_evidence"), evidence.join("; "));
        out.var(&format!("fair_{tname}_choices"), choices.join("; "));
    }
}
