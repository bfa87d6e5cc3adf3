use thiserror::Error;

/// What can be wrong with the input of a metric.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MetricsError {
    /// No points (or no forecasts) were given.
    #[error("{what} is empty")]
    Empty {
        /// What was empty.
        what: &'static str,
    },
    /// Predictions and truth have different numbers of points.
    #[error("{predicted} predicted points but {actual} true points")]
    LengthMismatch {
        /// Number of predicted points.
        predicted: usize,
        /// Number of true points.
        actual: usize,
    },
    /// A point (or a forecast) differs in size from the first one, or from its partner.
    #[error("{what} {index} has size {got}, expected {expected}")]
    DimensionMismatch {
        /// What was measured (`"point"`, `"forecast"`, `"covariance"`, ...).
        what: &'static str,
        /// Index of the first offending item.
        index: usize,
        /// The expected size.
        expected: usize,
        /// The size found.
        got: usize,
    },
    /// A value was NaN or infinite.
    #[error("non-finite value in {what} at index {index}")]
    NonFinite {
        /// Which input held it (`"predicted"` or `"actual"`, ...).
        what: &'static str,
        /// Index of the first point holding one.
        index: usize,
    },
    /// A relative error was asked for where the true value is zero.
    #[error("relative error undefined: true value is zero at point {index}, axis {axis}")]
    ZeroReference {
        /// Point index.
        index: usize,
        /// Axis index.
        axis: usize,
    },
    /// A parameter (threshold, confidence, degrees of freedom) outside its domain.
    #[error("invalid {name}: {value}")]
    InvalidParameter {
        /// The parameter.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A covariance that must be positive definite is not.
    #[error("covariance {index} is not positive definite")]
    NotPositiveDefinite {
        /// Index of the covariance.
        index: usize,
    },
}
