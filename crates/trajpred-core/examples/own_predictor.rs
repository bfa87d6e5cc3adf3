//! Writing your own method behind trajpred's `Predictor` interface, so the evaluation
//! harness, the CLI's tables and every metric work with it unchanged. The method here
//! carries the mean velocity of the last few fixes forward, at the history's mean interval.
//!
//! ```text
//! cargo run -p trajpred-core --example own_predictor
//! ```
//!
//! `tests/examples_run.rs` checks it on a straight track (exact) and on a track whose
//! timestamps go backwards (a typed error when the trajectory is built).
#![allow(clippy::print_stdout)]

use trajpred_core::predictor::check_forecast_args;
use trajpred_core::{Forecast, Predictor, Result, Trajectory};

/// Mean velocity of the last `points` fixes, carried forward.
#[derive(Debug, Clone)]
pub struct MeanVelocity {
    /// Fixes the velocity is estimated from (at least 2).
    pub points: usize,
}

impl Predictor for MeanVelocity {
    fn name(&self) -> &str {
        "mean-velocity"
    }

    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(()) // learns nothing
    }

    fn min_history(&self) -> usize {
        self.points.max(2)
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        // validates the horizon (bounded) and the history's length, with typed errors
        check_forecast_args(history, horizon, self.min_history())?;
        let n = history.len();
        let first = n - self.min_history();
        let t = history.times();
        let span = t[n - 1] - t[first];
        let step = (t[n - 1] - t[0]) / (n - 1) as f64;
        let last = history.point(n - 1);
        let velocity: Vec<f64> = (0..history.dim())
            .map(|k| (history.axis(k)[n - 1] - history.axis(k)[first]) / span)
            .collect();
        let steps: Vec<Vec<f64>> = (1..=horizon)
            .map(|h| {
                let dt = h as f64 * step;
                (0..history.dim())
                    .map(|k| last[k] + velocity[k] * dt)
                    .collect()
            })
            .collect();
        Forecast::new(history.dim(), steps)
    }
}

fn main() -> Result<()> {
    // 2 m/s east, 1 m/s north, a fix every 2 s
    let times: Vec<f64> = (0..10).map(|i| 2.0 * f64::from(i)).collect();
    let points: Vec<[f64; 2]> = times.iter().map(|t| [2.0 * t, *t]).collect();
    let track = Trajectory::new(times, points)?;
    let f = MeanVelocity { points: 4 }.forecast(&track, 3)?;
    for k in 1..=f.horizon() {
        println!("step {k}: {:?}", f.step(k));
    }
    Ok(())
}
