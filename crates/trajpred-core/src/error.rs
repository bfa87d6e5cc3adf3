//! The error type shared by the core types and the [`Predictor`](crate::Predictor) trait.

use thiserror::Error;

/// Everything that can go wrong in `trajpred-core`, and what a [`Predictor`](crate::Predictor)
/// reports. Every variant names what was wrong and, where there is one, the first bad index.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading or writing a file failed (the message names the file).
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// An input that must hold at least one element was empty.
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
        /// The length that was required.
        expected: usize,
        /// The length that was given.
        got: usize,
    },
    /// A point, matrix or vector has the wrong number of axes / rows / columns.
    #[error("dimension mismatch in {what}: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Where the mismatch was found.
        what: &'static str,
        /// The dimension that was required.
        expected: usize,
        /// The dimension that was given.
        got: usize,
    },
    /// Point `index` has a different number of axes from the first point.
    #[error("point {index} has {got} axes, expected {expected} like the first point")]
    PointDimension {
        /// Index of the first point whose dimension differs.
        index: usize,
        /// The dimension of the first point.
        expected: usize,
        /// The dimension of point `index`.
        got: usize,
    },
    /// Points must have 1, 2 or 3 axes.
    #[error("points must have 1, 2 or 3 axes, got {got}")]
    UnsupportedDimension {
        /// The number of axes that was given.
        got: usize,
    },
    /// A value was NaN or infinite.
    #[error("non-finite value in {what} at index {index}")]
    NonFinite {
        /// Which input held the value.
        what: &'static str,
        /// Index of the first non-finite value (point index for points).
        index: usize,
    },
    /// Timestamps must strictly increase; `index` is the first timestamp that does not.
    #[error("timestamps must strictly increase: t[{index}] = {time} is not after t[{}] = {previous}", index - 1)]
    NonIncreasingTime {
        /// Index of the first timestamp that is not larger than its predecessor.
        index: usize,
        /// The offending timestamp.
        time: f64,
        /// The timestamp before it.
        previous: f64,
    },
    /// A series or history is too short for the requested operation.
    #[error("{what} too short: needs at least {needed}, got {got}")]
    TooShort {
        /// What is too short.
        what: &'static str,
        /// The minimum length.
        needed: usize,
        /// The length that was given.
        got: usize,
    },
    /// A range that does not fit inside the trajectory or series.
    #[error("range {start}..{end} out of bounds for length {len}")]
    OutOfBounds {
        /// Range start.
        start: usize,
        /// Range end (exclusive).
        end: usize,
        /// Length of the indexed object.
        len: usize,
    },
    /// A parameter outside its valid domain.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// Why it is invalid.
        reason: String,
    },
    /// A matrix that must be symmetric positive definite is not.
    #[error("{what} is not symmetric positive definite")]
    NotPositiveDefinite {
        /// Which matrix.
        what: &'static str,
    },
    /// `forecast` was called on a predictor that needs `fit` first.
    #[error("predictor `{method}` must be fitted before forecasting")]
    NotFitted {
        /// The predictor's name.
        method: String,
    },
    /// A method cannot save what fitting learned (or load it back): the neural methods keep
    /// their weights in model files of their own.
    #[error("`{method}` cannot save or load fitted parameters: {reason}")]
    ParamsUnsupported {
        /// The predictor's name.
        method: String,
        /// Why, and what to use instead.
        reason: String,
    },
    /// Fitted parameters handed to [`Predictor::load_fitted_params`](crate::Predictor::load_fitted_params)
    /// that the method refuses: `path` is the JSON path of the bad field inside them
    /// (`axes[0].a[2][1]`; empty for the whole value).
    #[error("fitted parameters of `{method}` at `{path}`: {reason}")]
    InvalidFitted {
        /// The predictor's name.
        method: String,
        /// JSON path of the bad field, relative to the parameters.
        path: String,
        /// What is wrong with it.
        reason: String,
    },
    /// An error raised inside a method's own crate (a filter diverged, a solver failed, ...).
    #[error("{method}: {source}")]
    Method {
        /// The predictor's name.
        method: String,
        /// The underlying error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
}

impl Error {
    /// Wraps an error of a method's own crate, naming the method.
    pub fn method(
        method: impl Into<String>,
        source: impl std::error::Error + Send + Sync + 'static,
    ) -> Self {
        Error::Method {
            method: method.into(),
            source: Box::new(source),
        }
    }
}

/// `Result` with [`enum@Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
