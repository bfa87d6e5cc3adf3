//! The crate's error type, [`KalmanError`].

use thiserror::Error;

/// Everything that can go wrong in `trajpred-kalman`. Numerical failure is reported here,
/// never through a panic or a NaN in the output.
///
/// The input errors every crate shares are [`trajpred_core::Error`]'s variants, wrapped in
/// [`KalmanError::Core`]: match them as
/// `KalmanError::Core(trajpred_core::Error::NotPositiveDefinite { what: "S" })`. The variants
/// declared here are the filters' own.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum KalmanError {
    /// An input error shared with the other crates (see [`trajpred_core::Error`]):
    /// `DimensionMismatch` (a vector or matrix with the wrong number of rows or columns),
    /// `NonFinite` (an input, or a result that overflowed; the index is column-major for a
    /// matrix), `NotPositiveDefinite` (the state covariance `"P"`, the noise covariances
    /// `"Q"` and `"R"`, the innovation covariance `"S"`, or a predicted covariance inverted by
    /// the smoother), `InvalidParameter` (a non-positive time step, a negative variance, ...)
    /// and `Empty`. Its message is the core error's.
    #[error(transparent)]
    Core(#[from] trajpred_core::Error),
    /// Sigma-point parameters whose weights are degenerate: `n + lambda <= 0` (the weights
    /// `1 / (2 (n + lambda))` are infinite or negative) or not finite.
    #[error(
        "degenerate sigma-point weights: n + lambda = {n_plus_lambda} (alpha = {alpha}, kappa = {kappa}, n = {n})"
    )]
    DegenerateSigmaPoints {
        /// `n + lambda = alpha^2 (n + kappa)`.
        n_plus_lambda: f64,
        /// The spread parameter alpha.
        alpha: f64,
        /// The secondary scaling parameter kappa.
        kappa: f64,
        /// The state dimension.
        n: usize,
    },
    /// A model is undefined at the given state (e.g. the bearing Jacobian of a target at the
    /// sensor's position).
    #[error("model undefined: {what}")]
    Undefined {
        /// What could not be evaluated.
        what: &'static str,
    },
}

/// `Result` with [`KalmanError`].
pub type Result<T, E = KalmanError> = std::result::Result<T, E>;

trajpred_core::crate_error!(KalmanError, "trajpred-kalman");
