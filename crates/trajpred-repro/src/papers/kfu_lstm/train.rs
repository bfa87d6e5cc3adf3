//! Training and scoring on one noisy draw of a series: the noisy observation and persistence
//! references, the RNN and LSTM window baselines, and the KFU-LSTM-Net.

use super::{Budget, Params};
use crate::{ReproError, Result};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::time::Instant;
use trajpred_core::Trajectory;
use trajpred_neural::{EpochReport, KfuLstmNet, LstmNet, RnnNet};

/// Gradient steps per epoch of a window baseline trained on `n_train` points: one sample per
/// window of `p.window` points and its next point.
fn baseline_batches(p: &Params, n_train: usize) -> usize {
    n_train.saturating_sub(p.window).div_ceil(p.batch).max(1)
}

/// Gradient steps per epoch of the KFU-LSTM-Net trained on `n_train` points: sub-sequences
/// of `seq_len` points every `stride`.
fn kfu_batches(p: &Params, n_train: usize, seq_len: usize, stride: usize) -> usize {
    let len = seq_len.min(n_train);
    ((n_train - len) / stride.max(1) + 1)
        .div_ceil(p.batch)
        .max(1)
}

/// The epochs that give a series about the gradient steps `base_epochs` give a curve:
/// `ceil(base_epochs * curve_batches / series_batches)`. On the curves it is `base_epochs`;
/// the 200-point flight, with fewer batches per epoch, gets more epochs.
fn epochs_for(base_epochs: usize, curve_batches: usize, series_batches: usize) -> usize {
    (base_epochs * curve_batches)
        .div_ceil(series_batches.max(1))
        .max(1)
}

/// One series of the experiment: its clean truth and how to label it.
pub(super) struct Case {
    pub(super) name: String,
    pub(super) truth: Trajectory,
    pub(super) sigma: [f64; 3],
    pub(super) axes: [&'static str; 3],
}

/// The seed of repetition `rep` of series `series` (noise draw and network initialisation).
pub fn seed_of(base: u64, series: usize, rep: usize) -> u64 {
    base.wrapping_add(100 * rep as u64 + series as u64)
}

/// The noisy observation of `truth`: `truth + sigma[k] * N(0, 1)`, drawn axis by axis, point
/// by point, from `ChaCha8Rng::seed_from_u64(seed)`.
pub fn observe(truth: &Trajectory, sigma: &[f64], seed: u64) -> Result<Trajectory> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let axes: Vec<Vec<f64>> = truth
        .axes()
        .enumerate()
        .map(|(k, a)| {
            let s = sigma.get(k).copied().unwrap_or(0.0);
            a.iter()
                .map(|x| {
                    let e: f64 = StandardNormal.sample(&mut rng);
                    x + s * e
                })
                .collect()
        })
        .collect();
    Ok(Trajectory::from_axes(truth.times().to_vec(), axes)?)
}

/// The training split: the first 80% of `n` points.
pub fn train_len(n: usize) -> usize {
    n * 4 / 5
}

pub(super) fn points(t: &Trajectory) -> Vec<Vec<f64>> {
    t.points().map(|p| p.to_vec()).collect()
}

/// The scores of one method on one repetition.
#[derive(Debug, Clone)]
pub(super) struct Score {
    pub(super) rmse3: f64,
    pub(super) axes: Vec<f64>,
    pub(super) train_s: Option<f64>,
}

fn score(pred: &[Vec<f64>], truth: &[Vec<f64>]) -> Result<Score> {
    Ok(Score {
        rmse3: trajpred_metrics::rms_euclidean_error(pred, truth)?,
        axes: trajpred_metrics::rmse(pred, truth)?,
        train_s: None,
    })
}

/// What one method produced on one repetition.
pub(super) struct MethodRun {
    pub(super) score: Score,
    pub(super) epochs: Option<usize>,
    pub(super) pred: Vec<Vec<f64>>,
    pub(super) losses: Vec<f64>,
}

fn losses_into(losses: &mut Vec<f64>) -> impl FnMut(&EpochReport) + '_ {
    move |r: &EpochReport| losses.push(r.train_loss)
}

/// Trains and scores every method on one noisy draw of `case`.
pub(super) fn run_once(
    case: &Case,
    noisy: &Trajectory,
    seed: u64,
    p: &Params,
    s: &Budget,
) -> Result<Vec<MethodRun>> {
    let n = case.truth.len();
    let n_train = train_len(n);
    let obs = points(noisy);
    let truth = points(&case.truth);
    let test_truth = &truth[n_train..];
    let mut out = Vec::new();
    let raw = obs[n_train..].to_vec();
    out.push(MethodRun {
        score: score(&raw, test_truth)?,
        pred: raw,
        epochs: None,
        losses: Vec::new(),
    });
    let pers = obs[n_train - 1..n - 1].to_vec();
    out.push(MethodRun {
        score: score(&pers, test_truth)?,
        pred: pers,
        epochs: None,
        losses: Vec::new(),
    });
    let train_obs = noisy.prefix(n_train)?;
    let curve_train = train_len(s.n);
    let epochs_baseline = epochs_for(
        s.epochs_baseline,
        baseline_batches(p, curve_train),
        baseline_batches(p, n_train),
    );

    // the two window baselines
    macro_rules! window_net {
        ($net:ty) => {{
            let mut net = <$net>::patent_baseline(p.window, 1)?;
            net.set_train_config(
                net.train_config()
                    .clone()
                    .with_epochs(epochs_baseline)
                    .with_seed(seed),
            )?;
            let mut losses = Vec::new();
            let start = Instant::now();
            net.fit_with(
                std::slice::from_ref(&train_obs),
                &mut losses_into(&mut losses),
            )?;
            let train_s = start.elapsed().as_secs_f64();
            let mut pred = Vec::with_capacity(n - n_train);
            for t in n_train..n {
                let next = net.predict_window(&obs[t - p.window..t])?;
                pred.push(
                    next.into_iter()
                        .next()
                        .ok_or_else(|| ReproError::Experiment {
                            experiment: format!("kfu-lstm/{}", case.name),
                            reason: "window network returned no prediction".into(),
                        })?,
                );
            }
            let mut sc = score(&pred, test_truth)?;
            sc.train_s = Some(train_s);
            MethodRun {
                score: sc,
                pred,
                epochs: Some(epochs_baseline),
                losses,
            }
        }};
    }
    out.push(window_net!(RnnNet));
    out.push(window_net!(LstmNet));

    // the KFU-LSTM-Net, trained against the clean truth
    let mut kfu = KfuLstmNet::patent()?;
    let (seq_len, stride) = (kfu.config().seq_len, kfu.config().stride);
    let epochs_kfu = epochs_for(
        s.epochs_kfu,
        kfu_batches(p, curve_train, seq_len, stride),
        kfu_batches(p, n_train, seq_len, stride),
    );
    kfu.set_train_config(
        kfu.train_config()
            .clone()
            .with_epochs(epochs_kfu)
            .with_learning_rate(s.kfu_lr)
            .with_seed(seed),
    )?;
    let mut losses = Vec::new();
    let start = Instant::now();
    kfu.fit_supervised(
        std::slice::from_ref(&train_obs),
        &[case.truth.prefix(n_train)?],
        &mut losses_into(&mut losses),
    )?;
    let train_s = start.elapsed().as_secs_f64();
    // entry i of one_step_ahead predicts point i + 1 from points 0..=i of the slice, filtering
    // through at most the last seq_len of them; starting the slice seq_len points before the
    // test part gives every test origin its full context
    let ctx_len = kfu.config().seq_len.min(n_train);
    let first = n_train - ctx_len;
    let ahead = kfu.one_step_ahead(&noisy.slice(first..n)?)?;
    let pred: Vec<Vec<f64>> = ahead.get(ctx_len - 1..).unwrap_or(&[]).to_vec();
    if pred.len() != n - n_train {
        return Err(ReproError::Experiment {
            experiment: format!("kfu-lstm/{}", case.name),
            reason: format!(
                "KFU-LSTM-Net gave {} one-step predictions for {} test points",
                pred.len(),
                n - n_train
            ),
        });
    }
    let mut sc = score(&pred, test_truth)?;
    sc.train_s = Some(train_s);
    out.push(MethodRun {
        score: sc,
        pred,
        epochs: Some(epochs_kfu),
        losses,
    });
    Ok(out)
}
