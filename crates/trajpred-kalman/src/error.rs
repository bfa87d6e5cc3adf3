//! The crate's error type, [`KalmanError`].

use thiserror::Error;

/// Everything that can go wrong in `trajpred-kalman`. Numerical failure is reported here,
/// never through a panic or a NaN in the output.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum KalmanError {
    /// A vector or matrix has the wrong number of rows or columns.
    #[error("dimension mismatch in {what}: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Which input or model output disagrees.
        what: &'static str,
        /// The dimension that was required.
        expected: usize,
        /// The dimension that was given.
        got: usize,
    },
    /// A value was NaN or infinite (an input, or a result that overflowed).
    #[error("non-finite value in {what} at index {index}")]
    NonFinite {
        /// Which vector or matrix held the value.
        what: &'static str,
        /// Column-major index of the first non-finite value.
        index: usize,
    },
    /// A matrix that must be symmetric positive (semi-)definite is not: the state covariance
    /// `P`, the noise covariances `Q` and `R`, the innovation covariance `S`, or a predicted
    /// covariance inverted by the smoother.
    #[error("{what} is not symmetric positive definite")]
    NotPositiveDefinite {
        /// Which matrix (`"P"`, `"Q"`, `"R"`, `"S"`, ...).
        what: &'static str,
    },
    /// A parameter outside its valid domain (a non-positive time step, a negative variance, ...).
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// Why it is invalid.
        reason: String,
    },
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
    /// A sequence that must hold at least one element was empty.
    #[error("{what} is empty")]
    Empty {
        /// What was empty.
        what: &'static str,
    },
}

/// `Result` with [`KalmanError`].
pub type Result<T, E = KalmanError> = std::result::Result<T, E>;

impl From<KalmanError> for trajpred_core::Error {
    fn from(e: KalmanError) -> Self {
        trajpred_core::Error::method("trajpred-kalman", e)
    }
}
