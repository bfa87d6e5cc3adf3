//! The error type of `trajpred-sparse`.

use thiserror::Error;

/// Everything that can go wrong when fitting or using a LARS path or a group sparse coder.
///
/// Numerical trouble *inside* a path (collinear columns, a vanishing residual correlation)
/// is not an error: the path stops or skips the column and says so in
/// [`Lars::stop_reason`](crate::Lars::stop_reason) and [`Lars::excluded`](crate::Lars::excluded).
///
/// The input errors every crate shares are [`trajpred_core::Error`]'s variants, wrapped in
/// [`Error::Core`]: match them as `Error::Core(trajpred_core::Error::Empty { .. })`. The
/// variants declared here are the sparse coders' own.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// An input error shared with the other crates (see [`trajpred_core::Error`]): `Empty`
    /// (no rows, no columns), `DimensionMismatch` (inputs whose sizes disagree), `NonFinite`
    /// (a NaN or infinite value of a vector, or a sum or path value that overflowed: the
    /// index is the row, knot or series), `InvalidParameter` (with the offending value) and
    /// `TooShort` (a series too short for the windows and horizons). Its message is the core
    /// error's.
    #[error(transparent)]
    Core(#[from] trajpred_core::Error),
    /// A NaN or infinite entry of a matrix (the design, a series set, the coefficients, the
    /// path's coefficients): the core `NonFinite` has a single index, this names the row and
    /// the column.
    #[error("non-finite value in {what} at row {row}, column {col}")]
    NonFiniteEntry {
        /// Which matrix held the value (for a set of series: row = point, column = series).
        what: &'static str,
        /// Row of the first non-finite value.
        row: usize,
        /// Its column.
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
}

/// `Result` with [`enum@Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

trajpred_core::crate_error!(Error, "trajpred-sparse");
