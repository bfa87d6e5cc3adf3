//! Predicting the test points of the eq. 20 series, fitting the methods, and the errors of
//! eq. 21 (per axis, 3-D, pooled over steps, per point).

use crate::{Context, ReproError, Result};
use std::time::Instant;
use trajpred::predictors::{Gsc, Gskf, GskfParams};
use trajpred_core::{Predictor, Trajectory};
use trajpred_metrics::{error_statistics, euclidean_errors, rmse, rmse_3d};

pub(super) fn experiment(id: &str, reason: impl Into<String>) -> ReproError {
    ReproError::Experiment {
        experiment: format!("gskf/{id}"),
        reason: reason.into(),
    }
}

/// The `k`-step predictions (`k = 1..=T`) of every test point: `steps[k - 1][j]` predicts test
/// point `j` (index `n - test + j` of a series of `n` points) from the origin `n - test + j - k`.
#[derive(Debug, Clone)]
pub struct TestPredictions {
    /// `steps[k - 1][j]`: the k-step prediction of test point `j`.
    pub steps: Vec<Vec<[f64; 3]>>,
    /// Wall time of all forecasts, seconds.
    pub seconds: f64,
}

impl TestPredictions {
    /// The `k`-step predictions (k from 1).
    pub fn step(&self, k: usize) -> Result<&[[f64; 3]]> {
        k.checked_sub(1)
            .and_then(|i| self.steps.get(i))
            .map(Vec::as_slice)
            .ok_or_else(|| experiment("predictions", format!("no {k}-step predictions")))
    }

    /// Every step's predictions, pooled (step 1 first), with the matching truth.
    pub(super) fn pooled(&self, truth: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let pred: Vec<[f64; 3]> = self.steps.iter().flatten().copied().collect();
        let truth = truth
            .iter()
            .copied()
            .cycle()
            .take(pred.len())
            .collect::<Vec<_>>();
        (pred, truth)
    }
}

/// Predicts every test point of `series` (its last `test` points) `1..=horizons` steps ahead
/// with `predictor`: the forecast at origin `o` sees only `series[..=o]`.
pub fn predict_test(
    predictor: &dyn Predictor,
    series: &Trajectory,
    horizons: usize,
    test: usize,
) -> Result<TestPredictions> {
    let n = series.len();
    if series.dim() != 3 || n < test + horizons + predictor.min_history() {
        return Err(experiment(
            "predictions",
            format!(
                "need a 3-D series of at least {} points, got {} points of {} axes",
                test + horizons + predictor.min_history(),
                n,
                series.dim()
            ),
        ));
    }
    let start = n - test;
    let mut steps = vec![vec![[0.0; 3]; test]; horizons];
    let clock = Instant::now();
    for o in (start - horizons)..(n - 1) {
        let h = horizons.min(n - 1 - o);
        let f = predictor.forecast(&series.prefix(o + 1)?, h)?;
        for k in 1..=h {
            let j = o + k;
            if j >= start {
                let p = f.step(k);
                steps[k - 1][j - start] = [p[0], p[1], p[2]];
            }
        }
    }
    Ok(TestPredictions {
        steps,
        seconds: clock.elapsed().as_secs_f64(),
    })
}

/// The last `test` points of a series.
pub(super) fn test_truth(series: &Trajectory, test: usize) -> Vec<[f64; 3]> {
    let n = series.len();
    (n.saturating_sub(test)..n)
        .map(|i| {
            let p = series.point(i);
            [p[0], p[1], p[2]]
        })
        .collect()
}

/// A fitted method with its fit time.
pub(super) struct Fitted {
    pub(super) predictor: Box<dyn Predictor>,
    pub(super) fit_seconds: f64,
}

pub(super) fn fit(mut predictor: Box<dyn Predictor>, train: &Trajectory) -> Result<Fitted> {
    let clock = Instant::now();
    predictor.fit(std::slice::from_ref(train))?;
    Ok(Fitted {
        predictor,
        fit_seconds: clock.elapsed().as_secs_f64(),
    })
}

pub(super) fn gsc(m: usize, t: usize) -> Result<Box<dyn Predictor>> {
    Ok(Box::new(Gsc::new(GskfParams {
        window: m,
        horizons: t,
        ..Default::default()
    })?))
}

/// MSTPM-GSKF as the paper has it: the IKF's gain only (no fitted gain tried).
pub(super) fn gskf(m: usize, t: usize) -> Result<Gskf> {
    Ok(Gskf::new(GskfParams {
        window: m,
        horizons: t,
        gain_lags: Vec::new(),
        ..Default::default()
    })?)
}

/// Our GSKF with its default options: the IKF's gain or one fitted to the training series,
/// chosen on the last quarter of the training origins (`docs/gskf.md`).
pub(super) fn gskf_default(m: usize, t: usize) -> Result<Gskf> {
    Ok(Gskf::new(GskfParams {
        window: m,
        horizons: t,
        ..Default::default()
    })?)
}

/// Trains a neural baseline with a progress bar; returns it and its fit time.
pub(super) fn fit_neural<A: trajpred_neural::arch::Architecture>(
    ctx: &Context,
    mut net: trajpred_neural::WindowNet<A>,
    epochs: usize,
    seed: u64,
    train: &Trajectory,
    label: &str,
) -> Result<Fitted>
where
    trajpred_neural::WindowNet<A>: Predictor + 'static,
{
    let config = net
        .train_config()
        .clone()
        .with_epochs(epochs)
        .with_seed(seed);
    net.set_train_config(config)?;
    let bar = ctx.bar((epochs * 3) as u64, label);
    let clock = Instant::now();
    net.fit_with(std::slice::from_ref(train), &mut |_| bar.inc(1))?;
    bar.finish_and_clear();
    Ok(Fitted {
        predictor: Box::new(net),
        fit_seconds: clock.elapsed().as_secs_f64(),
    })
}

/// Errors of one method at horizon `T`.
#[derive(Debug, Clone)]
pub(super) struct Scores {
    /// Per-axis RMSE of the T-th step predictions (m).
    pub(super) axes: Vec<f64>,
    /// 3-D RMSE of the T-th step predictions (m).
    pub(super) rmse_3d: f64,
    /// 3-D RMSE pooled over steps 1..=T (m).
    pub(super) pooled_3d: f64,
    /// Per-point 3-D errors of the T-th step predictions (m).
    pub(super) per_point: Vec<f64>,
    /// Mean and variance of the per-point errors.
    pub(super) mean: f64,
    pub(super) variance: f64,
}

pub(super) fn score(pred: &TestPredictions, truth: &[[f64; 3]], t: usize) -> Result<Scores> {
    let last = pred.step(t)?;
    let (pooled, pooled_truth) = pred.pooled(truth);
    let stats = error_statistics(last, truth)?;
    Ok(Scores {
        axes: rmse(last, truth)?,
        rmse_3d: rmse_3d(last, truth)?,
        pooled_3d: rmse_3d(&pooled, &pooled_truth)?,
        per_point: euclidean_errors(last, truth)?,
        mean: stats.mean,
        variance: stats.variance,
    })
}
