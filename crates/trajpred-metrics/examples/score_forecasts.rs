//! Scoring multi-step forecasts as the trajpred papers do: the mean Euclidean error per step
//! (ADE and FDE), the share within a radius, the RMSE, and, for forecasts that come with a
//! covariance, whether those covariances are honest (NEES against its chi-square bounds).
//!
//! ```text
//! cargo run -p trajpred-metrics --example score_forecasts
//! ```
//!
//! Two forecasts of two steps against a target that stays at the origin, chosen so that
//! every figure can be checked by hand: the errors are 5 and 10 m (forecast A), 0 and 5 m
//! (forecast B). `tests/examples_run.rs` checks the printed figures against those sums.
#![allow(clippy::print_stdout)]

use trajpred_metrics::nalgebra::{DMatrix, DVector};
use trajpred_metrics::{MetricsError, consistency, hit_rate, nees, per_horizon, rmse};

/// What the example computes.
#[derive(Debug, Clone, PartialEq)]
pub struct Scores {
    /// Mean Euclidean error at step 1 and step 2.
    pub per_step: Vec<f64>,
    /// Average displacement error.
    pub ade: f64,
    /// Final displacement error.
    pub fde: f64,
    /// Share of the four points within 6 m.
    pub within_6m: f64,
    /// RMSE per axis over the four points.
    pub rmse: Vec<f64>,
    /// Mean NEES of the four points with the stated covariance `25 I`.
    pub mean_nees: f64,
    /// Whether that mean lies inside the 95 % chi-square bounds for 2 degrees of freedom.
    pub consistent: bool,
}

/// Computes [`Scores`].
pub fn run() -> Result<Scores, MetricsError> {
    let forecasts = vec![vec![[3.0, 4.0], [6.0, 8.0]], vec![[0.0, 0.0], [0.0, 5.0]]];
    let truth = vec![vec![[0.0, 0.0]; 2]; 2];
    let steps = per_horizon(&forecasts, &truth)?;

    let points: Vec<[f64; 2]> = forecasts.concat();
    let actual: Vec<[f64; 2]> = truth.concat();
    let errors: Vec<DVector<f64>> = points
        .iter()
        .map(|p| DVector::from_column_slice(p))
        .collect();
    let covariances = vec![DMatrix::identity(2, 2) * 25.0; errors.len()];
    let values = nees(&errors, &covariances)?;
    let c = consistency(&values, 2, 0.95)?;
    Ok(Scores {
        per_step: steps.mean_euclidean.clone(),
        ade: steps.ade(),
        fde: steps.fde(),
        within_6m: hit_rate(&points, &actual, 6.0)?,
        rmse: rmse(&points, &actual)?,
        mean_nees: c.mean,
        consistent: c.consistent,
    })
}

fn main() -> Result<(), MetricsError> {
    let s = run()?;
    println!(
        "mean error per step: {:?} m (ADE {} m, FDE {} m)",
        s.per_step, s.ade, s.fde
    );
    println!("within 6 m: {} of the points", s.within_6m);
    println!("RMSE per axis: {:?} m", s.rmse);
    println!(
        "mean NEES {} (2 degrees of freedom; consistent at 95 %: {})",
        s.mean_nees, s.consistent
    );
    Ok(())
}
