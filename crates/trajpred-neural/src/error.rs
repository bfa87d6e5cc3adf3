//! The error type of `trajpred-neural`.

use thiserror::Error;

/// Everything that can go wrong while building, training, running, saving or loading a
/// neural predictor. Converted into [`trajpred_core::Error::Method`] by the
/// [`Predictor`](trajpred_core::Predictor) implementations.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum NeuralError {
    /// A series, a history or the training set is too short for the configured window.
    #[error("{what} too short: needs at least {needed} points, got {got}")]
    TooShort {
        /// What is too short.
        what: &'static str,
        /// The minimum number of points.
        needed: usize,
        /// The number of points given.
        got: usize,
    },
    /// A value is NaN or infinite.
    #[error("non-finite value in {what} at index {index}")]
    NonFinite {
        /// Which input held the value.
        what: &'static str,
        /// Index of the first non-finite value.
        index: usize,
    },
    /// An input has the wrong number of axes or values.
    #[error("dimension mismatch in {what}: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Where the mismatch was found.
        what: &'static str,
        /// The required dimension.
        expected: usize,
        /// The given dimension.
        got: usize,
    },
    /// A configuration value outside its valid domain.
    #[error("invalid configuration `{name}`: {reason}")]
    InvalidConfig {
        /// The parameter's name.
        name: &'static str,
        /// Why it is invalid.
        reason: String,
    },
    /// No training data was given.
    #[error("no training data: {what}")]
    NoTrainingData {
        /// What was empty.
        what: &'static str,
    },
    /// The model was used before it was trained or loaded.
    #[error("model must be fitted (or loaded) before use")]
    NotFitted,
    /// Training produced a non-finite loss (learning rate too high, data badly scaled).
    #[error("training diverged: loss {loss} at epoch {epoch}")]
    Diverged {
        /// The epoch (1-based) in which the loss became non-finite.
        epoch: usize,
        /// The loss value.
        loss: f64,
    },
    /// A tensor could not be read back from the framework.
    #[error("tensor read-back failed: {reason}")]
    Tensor {
        /// The framework's message.
        reason: String,
    },
    /// Saving or loading a model file failed.
    #[error("model file {path}: {reason}")]
    Persistence {
        /// The file.
        path: String,
        /// What went wrong.
        reason: String,
    },
}

impl NeuralError {
    /// Converts into the workspace error, naming the method.
    pub(crate) fn into_core(self, method: &str) -> trajpred_core::Error {
        match self {
            NeuralError::TooShort { what, needed, got } => {
                trajpred_core::Error::TooShort { what, needed, got }
            }
            NeuralError::DimensionMismatch {
                what,
                expected,
                got,
            } => trajpred_core::Error::DimensionMismatch {
                what,
                expected,
                got,
            },
            NeuralError::NotFitted => trajpred_core::Error::NotFitted {
                method: method.to_string(),
            },
            other => trajpred_core::Error::method(method, other),
        }
    }
}

/// `Result` with [`NeuralError`].
pub type Result<T, E = NeuralError> = std::result::Result<T, E>;
