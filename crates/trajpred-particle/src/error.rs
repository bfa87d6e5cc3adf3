//! The crate's error type, [`ParticleError`].

use thiserror::Error;
use trajpred_kalman::KalmanError;

/// Everything that can go wrong in `trajpred-particle`. Bad input and numerical failure are
/// reported here, never through a panic or a NaN in the output.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ParticleError {
    /// An input that must hold at least one element was empty (no weights, no particles).
    #[error("{what} is empty")]
    Empty {
        /// What was empty.
        what: &'static str,
    },
    /// Two inputs that must have the same length do not.
    #[error("{what}: expected length {expected}, got {got}")]
    LengthMismatch {
        /// Which pair of inputs disagrees.
        what: &'static str,
        /// The required length.
        expected: usize,
        /// The given length.
        got: usize,
    },
    /// A vector or matrix has the wrong number of rows or columns.
    #[error("dimension mismatch in {what}: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Which input disagrees.
        what: &'static str,
        /// The required dimension.
        expected: usize,
        /// The given dimension.
        got: usize,
    },
    /// A weight that is negative, NaN or infinite (or a log-weight that is NaN or `+inf`).
    #[error("invalid weight {value} at index {index}")]
    InvalidWeight {
        /// Index of the first bad weight.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// Every weight is zero (every log-weight `-inf`): the observation is impossible under
    /// every particle, or all weights underflowed. Filters leave their state unchanged when
    /// they return this, so the caller may skip the observation and continue.
    #[error("all {count} weights are zero (observation impossible under every particle)")]
    AllWeightsZero {
        /// Number of weights.
        count: usize,
    },
    /// A value was NaN or infinite (an observation, a state, a model output).
    #[error("non-finite value in {what} at index {index}")]
    NonFinite {
        /// Which input held the value.
        what: &'static str,
        /// Index of the first non-finite value.
        index: usize,
    },
    /// A uniform variate outside `[0, 1]` was given to a deterministic resampler.
    #[error("uniform variate {value} at index {index} is outside [0, 1]")]
    InvalidUniform {
        /// Index of the bad variate.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A parameter outside its valid domain.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// Why it is invalid.
        reason: String,
    },
    /// A matrix that must be symmetric positive (semi-)definite is not.
    #[error("{what} is not symmetric positive definite")]
    NotPositiveDefinite {
        /// Which matrix (`"Q"`, `"R"`, `"P"`).
        what: &'static str,
    },
    /// An error of the Kalman crate (a model evaluation, a UKF or EKF step).
    #[error("kalman: {0}")]
    Kalman(#[from] KalmanError),
}

/// `Result` with [`ParticleError`].
pub type Result<T, E = ParticleError> = std::result::Result<T, E>;

impl From<ParticleError> for trajpred_core::Error {
    fn from(e: ParticleError) -> Self {
        trajpred_core::Error::method("trajpred-particle", e)
    }
}
