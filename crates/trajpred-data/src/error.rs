//! The crate's error type: one enum, every file error naming the file and, for parse errors,
//! the 1-based line (or JSON record) where it happened.

use thiserror::Error;

/// Everything that can go wrong while loading, converting or generating trajectories.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// A file or directory could not be read.
    #[error("{file}: {source}")]
    Io {
        /// The file or directory.
        file: String,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A line (or record) that cannot be parsed, in strict mode or where the format leaves no
    /// way to skip it (a missing header, a JSON document that is not JSON).
    #[error("{file}:{line}: {reason}")]
    Parse {
        /// The file (or `<memory>` for in-memory input).
        file: String,
        /// 1-based line number (for JSON: the line reported by the JSON parser, or the
        /// 1-based record index where noted in `reason`).
        line: usize,
        /// What was wrong.
        reason: String,
    },
    /// A parameter outside its valid domain (a bounding box with min > max, a negative gap,
    /// a latitude beyond ±90°, a non-finite SNR, ...).
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// Why it is invalid.
        reason: String,
    },
    /// A path that should be a directory of the expected layout is not.
    #[error("{path}: {reason}")]
    Layout {
        /// The path.
        path: String,
        /// What was expected.
        reason: String,
    },
    /// A trajectory could not be built (see [`trajpred_core::Error`]).
    #[error(transparent)]
    Trajectory(#[from] trajpred_core::Error),
}

/// `Result` with [`enum@Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub(crate) fn io(file: impl std::fmt::Display, source: std::io::Error) -> Self {
        Error::Io {
            file: file.to_string(),
            source,
        }
    }

    pub(crate) fn parse(file: &str, line: usize, reason: impl Into<String>) -> Self {
        Error::Parse {
            file: file.to_string(),
            line,
            reason: reason.into(),
        }
    }

    pub(crate) fn param(name: &'static str, reason: impl Into<String>) -> Self {
        Error::InvalidParameter {
            name,
            reason: reason.into(),
        }
    }
}
