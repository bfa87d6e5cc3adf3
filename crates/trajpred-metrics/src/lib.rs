//! # trajpred-metrics
//!
//! Every error measure the trajpred papers use, each named for what it computes
//! (`docs/papers.md` E). All functions take predicted and true points as slices of anything that
//! views as `&[f64]` (a [`Vec<f64>`], an array, a `trajpred_core::Point`), check them, and
//! return a typed [`MetricsError`] for empty, mismatched or non-finite input.
//!
//! | function | computes | used by |
//! |---|---|---|
//! | [`rmse`] | per-axis root mean square error | GSKF paper, Table 3 |
//! | [`rmse_3d`] | `sqrt(sum_i (dx^2 + dy^2 + dz^2) / N)` (eq. 21) | GSKF paper, Tables 1-3 |
//! | [`rms_euclidean_error`] | the same for any number of axes | |
//! | [`mean_euclidean_error`] | `sum_i ||p_i - x_i|| / N` (what the KF-dynamic paper calls "RMSE") | KF-dynamic paper |
//! | [`hit_rate`] | share of points whose Euclidean error is below a threshold | KF-dynamic paper |
//! | [`relative_rmse`] | `sqrt(mean(((p - x) / x)^2))` over every coordinate | MKPF paper |
//! | [`error_statistics`] | mean and variance of the per-point Euclidean errors | GSKF paper, Table 4 |
//! | [`per_horizon`] | mean Euclidean error and RMSE per forecast step; ADE and FDE | evaluation harness |
//! | [`nees`], [`nis`], [`consistency`] | normalised estimation error / innovation squared and chi-square bounds | filter consistency |
//!
//! ```
//! use trajpred_metrics::{mean_euclidean_error, rmse_3d, hit_rate};
//! let truth = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]];
//! let pred = [[3.0, 4.0, 0.0], [1.0, 1.0, 1.0]];
//! // errors: 5 and 0
//! assert_eq!(mean_euclidean_error(&pred, &truth)?, 2.5);
//! assert_eq!(rmse_3d(&pred, &truth)?, (25.0f64 / 2.0).sqrt());
//! assert_eq!(hit_rate(&pred, &truth, 1.0)?, 0.5);
//! # Ok::<(), trajpred_metrics::MetricsError>(())
//! ```
#![forbid(unsafe_code)]

mod consistency;
mod error;
mod point;

pub use consistency::{Consistency, chi_square_bounds, consistency, nees, nis};
pub use error::MetricsError;
pub use point::{
    ErrorStatistics, PerHorizon, error_statistics, euclidean_errors, hit_rate,
    mean_euclidean_error, per_horizon, relative_rmse, rms_euclidean_error, rmse, rmse_3d,
};

/// `Result` with [`MetricsError`].
pub type Result<T, E = MetricsError> = std::result::Result<T, E>;
