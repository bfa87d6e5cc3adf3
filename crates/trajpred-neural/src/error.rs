//! The error type of `trajpred-neural`.

use thiserror::Error;
pub(crate) use trajpred_core::Error as CoreError;

/// Everything that can go wrong while building, training, running, saving or loading a
/// neural predictor. The [`Predictor`](trajpred_core::Predictor) implementations convert it
/// into [`trajpred_core::Error`]: a shared variant as itself, the others wrapped in
/// [`trajpred_core::Error::Method`].
///
/// The input errors every crate shares are [`trajpred_core::Error`]'s variants, wrapped in
/// [`NeuralError::Core`]: match them as
/// `NeuralError::Core(trajpred_core::Error::TooShort { .. })`. The variants declared here are
/// the networks' own.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum NeuralError {
    /// An input error shared with the other crates (see [`trajpred_core::Error`]):
    /// `TooShort` (a series, a history or the training set too short for the configured
    /// window), `NonFinite` (a NaN or infinite value, with its index), `DimensionMismatch`
    /// (an input with the wrong number of axes or values) and `InvalidParameter` (a
    /// configuration value outside its domain, with the value). Its message is the core
    /// error's.
    #[error(transparent)]
    Core(#[from] trajpred_core::Error),
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
    /// Converts into the workspace error, naming the method: a shared variant comes back as
    /// the core error itself, [`NeuralError::NotFitted`] as
    /// [`trajpred_core::Error::NotFitted`], the rest as [`trajpred_core::Error::Method`].
    pub(crate) fn into_core(self, method: &str) -> trajpred_core::Error {
        match self {
            NeuralError::NotFitted => trajpred_core::Error::NotFitted {
                method: method.to_string(),
            },
            other => trajpred_core::Error::from_crate(method, other),
        }
    }
}

/// `Result` with [`NeuralError`].
pub type Result<T, E = NeuralError> = std::result::Result<T, E>;

trajpred_core::crate_error!(NeuralError, "trajpred-neural");
