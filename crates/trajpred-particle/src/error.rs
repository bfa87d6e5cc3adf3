//! The crate's error type, [`ParticleError`].

use thiserror::Error;
use trajpred_core::CrateError;
use trajpred_kalman::KalmanError;

/// Everything that can go wrong in `trajpred-particle`. Bad input and numerical failure are
/// reported here, never through a panic or a NaN in the output.
///
/// The input errors every crate shares (an empty input, mismatched lengths or dimensions, a
/// non-finite value, an invalid parameter, a matrix that is not positive definite) are
/// [`trajpred_core::Error`]'s variants, wrapped in [`ParticleError::Core`]: match them as
/// `ParticleError::Core(trajpred_core::Error::Empty { .. })`. The variants declared here are
/// the particle filters' own.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ParticleError {
    /// An input error shared with the other crates (see [`trajpred_core::Error`]): `Empty`
    /// (no weights, no particles), `LengthMismatch`, `DimensionMismatch`, `NonFinite` (an
    /// observation, a state, a model output), `InvalidParameter`, `NotPositiveDefinite`
    /// (`"Q"`, `"R"`, `"P"`), also when the Kalman crate raises them. Its message is the
    /// core error's.
    #[error(transparent)]
    Core(#[from] trajpred_core::Error),
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
    /// A uniform variate outside `[0, 1]` was given to a deterministic resampler.
    #[error("uniform variate {value} at index {index} is outside [0, 1]")]
    InvalidUniform {
        /// Index of the bad variate.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// An error of the Kalman crate's own (a model undefined at a state, degenerate sigma
    /// points of a UKF step); a shared error the Kalman crate raises converts to
    /// [`ParticleError::Core`].
    #[error("kalman: {0}")]
    Kalman(KalmanError),
}

/// `Result` with [`ParticleError`].
pub type Result<T, E = ParticleError> = std::result::Result<T, E>;

/// A shared variant (`KalmanError::Core`) becomes [`ParticleError::Core`], so it is matched
/// the same way whichever crate raised it; the Kalman crate's own variants
/// [`ParticleError::Kalman`].
impl From<KalmanError> for ParticleError {
    fn from(e: KalmanError) -> Self {
        e.split_core()
            .map_or_else(ParticleError::Kalman, ParticleError::Core)
    }
}

impl CrateError for ParticleError {
    fn split_core(self) -> std::result::Result<trajpred_core::Error, Self> {
        match self {
            ParticleError::Core(e) => Ok(e),
            ParticleError::Kalman(k) => k.split_core().map_err(ParticleError::Kalman),
            own => Err(own),
        }
    }
}

/// A shared variant comes back as the core error itself, the particle filters' own variants
/// (and the Kalman crate's) as [`trajpred_core::Error::Method`] naming `trajpred-particle`.
impl From<ParticleError> for trajpred_core::Error {
    fn from(e: ParticleError) -> Self {
        trajpred_core::Error::from_crate("trajpred-particle", e)
    }
}
