//! The crate's error type: one enum, every file error naming the file and, for parse errors,
//! the 1-based line (or JSON record) where it happened.

use thiserror::Error;

/// Everything that can go wrong while loading, converting or generating trajectories.
///
/// The errors every crate shares are [`trajpred_core::Error`]'s variants, wrapped in
/// [`Error::Core`]: match them as
/// `Error::Core(trajpred_core::Error::InvalidParameter { name: "dt", .. })`. The variants
/// declared here are the loaders' own.
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
    /// A path that should be a directory of the expected layout is not.
    #[error("{path}: {reason}")]
    Layout {
        /// The path.
        path: String,
        /// What was expected.
        reason: String,
    },
    /// Input crossed one of the limits of [`LoadOptions`](crate::LoadOptions) (a line, a
    /// file's decompressed size, the points of one track or of one load). Raise the named
    /// field to read it anyway.
    #[error("{file}{}: {what} exceeds the limit of {limit} (LoadOptions::{option})", .line.map(|l| format!(":{l}")).unwrap_or_default())]
    LimitExceeded {
        /// The file (or the name given to in-memory input).
        file: String,
        /// The 1-based line (for JSON: record) where the limit was crossed, where known.
        line: Option<usize>,
        /// The [`LoadOptions`](crate::LoadOptions) field that sets the limit
        /// (`max_line_bytes`, `max_file_bytes`, `max_json_bytes`, `max_track_points`,
        /// `max_total_points`).
        option: &'static str,
        /// The limit's value.
        limit: u64,
        /// What crossed it, in words ("line length in bytes", ...).
        what: &'static str,
    },
    /// An error shared with the other crates (see [`trajpred_core::Error`]): a trajectory that
    /// could not be built, or `InvalidParameter` (a bounding box with min > max, a negative
    /// gap, a latitude beyond ±90°, a non-finite SNR, ..., with the offending value). Its
    /// message is the core error's.
    #[error(transparent)]
    Core(#[from] trajpred_core::Error),
}

/// `Result` with [`enum@Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An I/O error of `file`; a [`LimitHit`] carried by a reader (the CSV loader's) becomes
    /// [`Error::LimitExceeded`].
    pub(crate) fn io(file: impl std::fmt::Display, source: std::io::Error) -> Self {
        if let Some(hit) = source.get_ref().and_then(|e| e.downcast_ref::<LimitHit>()) {
            return hit.to_error(file);
        }
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

    /// [`trajpred_core::Error::InvalidParameter`]; `reason` quotes the offending value.
    pub(crate) fn param(name: &'static str, reason: impl Into<String>) -> Self {
        Error::Core(trajpred_core::Error::invalid_parameter(name, reason))
    }
}

/// A limit crossed inside a reader, carried out through `std::io::Error` (see [`Error::io`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LimitHit {
    pub line: Option<usize>,
    pub option: &'static str,
    pub limit: u64,
    pub what: &'static str,
}

impl LimitHit {
    pub(crate) fn to_error(self, file: impl std::fmt::Display) -> Error {
        Error::LimitExceeded {
            file: file.to_string(),
            line: self.line,
            option: self.option,
            limit: self.limit,
            what: self.what,
        }
    }

    pub(crate) fn into_io(self) -> std::io::Error {
        std::io::Error::other(self)
    }
}

impl std::fmt::Display for LimitHit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} exceeds the limit of {} (LoadOptions::{})",
            self.what, self.limit, self.option
        )
    }
}

impl std::error::Error for LimitHit {}

trajpred_core::crate_error!(Error, "trajpred-data");
