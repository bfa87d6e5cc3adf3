//! The error type shared by the core types, the [`Predictor`](crate::Predictor) trait and,
//! through their `Core` variants, every other crate of the workspace ([`CrateError`]).

use thiserror::Error;

/// Everything that can go wrong in `trajpred-core`, and what a [`Predictor`](crate::Predictor)
/// reports. Every variant names what was wrong and, where there is one, the first bad index
/// or the offending value.
///
/// The input errors every crate shares (`Empty`, `LengthMismatch`, `DimensionMismatch`,
/// `PointDimension`, `NonFinite`, `TooShort`, `InvalidParameter`, `NotPositiveDefinite`, ...)
/// are declared here only: the error enums of the other crates hold them in a variant
/// `Core(trajpred_core::Error)` and declare only their own variants besides (see
/// [`CrateError`]).
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
        /// Why it is invalid, quoting the offending value (`"must be positive, got -1"`).
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

    /// An error of another crate as this one: the shared variant it holds in its `Core`
    /// variant is returned as it is (so `Error::InvalidParameter` is matched the same way
    /// whichever crate raised it), any variant of the crate's own is wrapped in
    /// [`Error::Method`] naming `method`.
    ///
    /// ```
    /// use trajpred_core::{CrateError, Error};
    /// #[derive(Debug, thiserror::Error)]
    /// enum MyError {
    ///     #[error(transparent)]
    ///     Core(#[from] Error),
    ///     #[error("diverged")]
    ///     Diverged,
    /// }
    /// impl CrateError for MyError {
    ///     fn split_core(self) -> Result<Error, Self> {
    ///         match self {
    ///             MyError::Core(e) => Ok(e),
    ///             other => Err(other),
    ///         }
    ///     }
    /// }
    /// let shared = MyError::Core(Error::Empty { what: "history" });
    /// assert!(matches!(Error::from_crate("mine", shared), Error::Empty { what: "history" }));
    /// let own = Error::from_crate("mine", MyError::Diverged);
    /// assert_eq!(own.to_string(), "mine: diverged");
    /// ```
    pub fn from_crate<E: CrateError>(method: impl Into<String>, error: E) -> Self {
        error
            .split_core()
            .unwrap_or_else(|own| Error::method(method, own))
    }

    /// [`Error::InvalidParameter`] naming the parameter; `reason` should quote the offending
    /// value (`format!("must be positive, got {v}")`).
    pub fn invalid_parameter(name: &'static str, reason: impl Into<String>) -> Self {
        Error::InvalidParameter {
            name,
            reason: reason.into(),
        }
    }
}

/// The error convention of the workspace (`docs/architecture.md`, "Errors"): a crate's error
/// enum is `#[non_exhaustive]`, holds the variants every crate shares in one variant
/// `Core(#[from] trajpred_core::Error)` (so `?` converts a core error) and declares only the
/// variants specific to that crate besides. This trait splits such an error into the two
/// kinds; [`Error::from_crate`] uses it to convert into this crate's error.
pub trait CrateError: std::error::Error + Send + Sync + Sized + 'static {
    /// The core error held by the `Core` variant, or `Err(self)` for a variant of the crate's
    /// own.
    fn split_core(self) -> std::result::Result<Error, Self>;
}

/// The convention's conversions for a crate's error enum `$error` whose shared variant is
/// `Core(trajpred_core::Error)`: [`CrateError`], and `From<$error>` for [`enum@Error`] (a shared
/// variant as itself, the crate's own variants wrapped in [`Error::Method`] naming `$name`).
///
/// ```
/// use trajpred_core::Error;
/// #[derive(Debug, thiserror::Error)]
/// enum MyError {
///     #[error(transparent)]
///     Core(#[from] Error),
///     #[error("diverged")]
///     Diverged,
/// }
/// trajpred_core::crate_error!(MyError, "my-crate");
/// let e: Error = MyError::Core(Error::Empty { what: "history" }).into();
/// assert!(matches!(e, Error::Empty { what: "history" }));
/// assert_eq!(Error::from(MyError::Diverged).to_string(), "my-crate: diverged");
/// ```
#[macro_export]
macro_rules! crate_error {
    ($error:ident, $name:literal) => {
        impl $crate::CrateError for $error {
            fn split_core(self) -> ::std::result::Result<$crate::Error, Self> {
                match self {
                    $error::Core(e) => Ok(e),
                    own => Err(own),
                }
            }
        }

        #[doc = concat!("A shared variant as the core error itself, the others naming `", $name, "`.")]
        impl From<$error> for $crate::Error {
            fn from(e: $error) -> Self {
                $crate::Error::from_crate($name, e)
            }
        }
    };
}

/// `Result` with [`enum@Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
