// The crate documentation is the README (its examples are compiled and run as doc tests).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

/// The linear algebra this crate takes and returns, re-exported so that a user needs no
/// separate (and exactly matching) nalgebra dependency.
pub use nalgebra;

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
