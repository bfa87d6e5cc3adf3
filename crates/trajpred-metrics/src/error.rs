use thiserror::Error;

/// What can be wrong with the input of a metric.
///
/// The input errors every crate shares are [`trajpred_core::Error`]'s variants, wrapped in
/// [`MetricsError::Core`]: match them as
/// `MetricsError::Core(trajpred_core::Error::Empty { what: "points" })`. The variants declared
/// here are the metrics' own.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MetricsError {
    /// An input error shared with the other crates (see [`trajpred_core::Error`]): `Empty`
    /// (no points, no forecasts, a point or forecast with no values), `LengthMismatch`
    /// (predictions and truth have different numbers of points or forecasts),
    /// `PointDimension` (a point differs in size from the first predicted point),
    /// `DimensionMismatch` (points of other than three axes for [`rmse_3d`](crate::rmse_3d)),
    /// `NonFinite` (a NaN or infinite value: the index of the first point, forecast or value
    /// holding one) and `InvalidParameter` (a threshold, confidence or number of degrees of
    /// freedom outside its domain, with the value). Its message is the core error's.
    #[error(transparent)]
    Core(#[from] trajpred_core::Error),
    /// Item `index` of a sequence of forecasts, error vectors or covariances differs in size
    /// from the others (the core `DimensionMismatch` names no item).
    #[error("{what} {index} has size {got}, expected {expected}")]
    ItemDimensionMismatch {
        /// What was measured (`"forecast"`, `"forecast point"`, `"error vector"`,
        /// `"covariance"`).
        what: &'static str,
        /// Index of the first offending item.
        index: usize,
        /// The expected size.
        expected: usize,
        /// The size found.
        got: usize,
    },
    /// A relative error was asked for where the true value is zero.
    #[error("relative error undefined: true value is zero at point {index}, axis {axis}")]
    ZeroReference {
        /// Point index.
        index: usize,
        /// Axis index.
        axis: usize,
    },
    /// Covariance `index` of a sequence (NEES, NIS) is not positive definite (the core
    /// `NotPositiveDefinite` names no item).
    #[error("covariance {index} is not positive definite")]
    CovarianceNotPositiveDefinite {
        /// Index of the covariance.
        index: usize,
    },
}

trajpred_core::crate_error!(MetricsError, "trajpred-metrics");

/// The start of every metric over a pair of sequences: `others` as long as `items`
/// (`LengthMismatch` naming the pair `what`) and at least one item (`Empty` naming `empty`);
/// returns the first item.
pub(crate) fn first_of_pair<'a, A, B>(
    items: &'a [A],
    others: &[B],
    what: &'static str,
    empty: &'static str,
) -> Result<&'a A, MetricsError> {
    if items.len() != others.len() {
        return Err(trajpred_core::Error::LengthMismatch {
            what,
            expected: items.len(),
            got: others.len(),
        }
        .into());
    }
    items
        .first()
        .ok_or(trajpred_core::Error::Empty { what: empty }.into())
}

/// `NonFinite { what, index }` unless every value is finite (`index` is the item's, not the
/// value's).
pub(crate) fn check_finite<'a>(
    values: impl IntoIterator<Item = &'a f64>,
    what: &'static str,
    index: usize,
) -> Result<(), MetricsError> {
    if values.into_iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(trajpred_core::Error::NonFinite { what, index }.into())
    }
}
