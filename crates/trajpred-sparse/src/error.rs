//! The error type of `trajpred-sparse`.

use thiserror::Error;

/// Everything that can go wrong when fitting or using a LARS path or a group sparse coder.
///
/// Numerical trouble *inside* a path (collinear columns, a vanishing residual correlation)
/// is not an error: the path stops or skips the column and says so in
/// [`Lars::stop_reason`](crate::Lars::stop_reason) and [`Lars::excluded`](crate::Lars::excluded).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// An input that must hold at least one element was empty.
    #[error("{what} is empty")]
    Empty {
        /// What was empty.
        what: &'static str,
    },
    /// Two inputs whose sizes must agree do not.
    #[error("dimension mismatch in {what}: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Which inputs disagree.
        what: &'static str,
        /// The size that was required.
        expected: usize,
        /// The size that was given.
        got: usize,
    },
    /// A value was NaN or infinite.
    #[error("non-finite value in {what} at row {row}, column {col}")]
    NonFinite {
        /// Which input held the value.
        what: &'static str,
        /// Row of the first non-finite value (the index for a vector).
        row: usize,
        /// Column of the first non-finite value (0 for a vector).
        col: usize,
    },
    /// Every column of the design is constant (zero after centring, or exactly zero without an
    /// intercept), so no variable can enter the path.
    #[error("all {columns} columns of the design are constant")]
    AllColumnsConstant {
        /// Number of columns.
        columns: usize,
    },
    /// The squared norm of a design column overflows `f64` (values around 1e154 or larger):
    /// rescale the data.
    #[error("column {col} of the design is too large: its squared norm overflows")]
    Overflow {
        /// Column index.
        col: usize,
    },
    /// A parameter outside its valid domain.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// Why it is invalid.
        reason: String,
    },
    /// A series is too short for the requested windows and horizons.
    #[error("{what} too short: needs at least {needed}, got {got}")]
    TooShort {
        /// What is too short.
        what: &'static str,
        /// The minimum length.
        needed: usize,
        /// The length that was given.
        got: usize,
    },
}

/// `Result` with [`enum@Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
