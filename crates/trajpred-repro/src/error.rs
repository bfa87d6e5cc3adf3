//! The error type of the reproduction.

use crate::report::Difference;
use std::fmt::Write as _;
use std::path::PathBuf;
use trajpred_core::CrateError;

/// One difference a line.
fn list(differences: &[Difference]) -> String {
    let mut s = String::new();
    for d in differences {
        let _ = write!(s, "\n  - {d}");
    }
    s
}

/// What can go wrong while reproducing a paper or checking a run.
///
/// An error any crate raises with one of the shared variants is [`ReproError::Core`]
/// (converted from the crates' errors by `?`); the crates' own variants keep their crate's
/// variant here.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReproError {
    /// A method or data structure refused its input (the variants every crate shares).
    #[error(transparent)]
    Core(#[from] trajpred_core::Error),
    /// A loader refused a data file.
    #[error(transparent)]
    Data(trajpred_data::Error),
    /// A metric refused its input.
    #[error(transparent)]
    Metrics(trajpred_metrics::MetricsError),
    /// A filter failed.
    #[error(transparent)]
    Kalman(trajpred_kalman::KalmanError),
    /// A particle filter failed.
    #[error(transparent)]
    Particle(trajpred_particle::ParticleError),
    /// A neural model failed to train, save or load.
    #[error(transparent)]
    Neural(trajpred_neural::NeuralError),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A results CSV could not be read or written.
    #[error("{path}: {reason}")]
    Csv {
        /// The file.
        path: PathBuf,
        /// What was wrong.
        reason: String,
    },
    /// An experiment could not be set up as the paper describes (names the table or figure).
    #[error("{experiment}: {reason}")]
    Experiment {
        /// The table or figure, e.g. `gskf/table3`.
        experiment: String,
        /// What was wrong.
        reason: String,
    },
    /// A paper's spec (`papers/<slug>.toml`) cannot be read, is inconsistent, or does not fit
    /// what the run produced.
    #[error("spec of {paper}: {reason}")]
    Spec {
        /// The paper's slug.
        paper: String,
        /// What was wrong.
        reason: String,
    },
    /// `--check`: a fresh run differs from the committed one (every difference is listed).
    #[error(
        "{paper}: {} difference(s) from the run committed in {}:{}",
        .differences.len(),
        .committed.display(),
        list(.differences)
    )]
    CheckFailed {
        /// The paper's slug.
        paper: String,
        /// The committed run's folder.
        committed: PathBuf,
        /// Every difference, in the order [`crate::report::compare_run`] finds them.
        differences: Vec<Difference>,
    },
}

/// `From` for the error of a crate that holds the shared variants in `Core`
/// ([`CrateError`]): a shared variant becomes [`ReproError::Core`], the crate's own variants
/// the crate's variant.
macro_rules! from_crate_error {
    ($($variant:ident($error:ty)),* $(,)?) => {$(
        impl From<$error> for ReproError {
            fn from(e: $error) -> Self {
                e.split_core().map_or_else(ReproError::$variant, ReproError::Core)
            }
        }
    )*};
}

from_crate_error!(
    Data(trajpred_data::Error),
    Metrics(trajpred_metrics::MetricsError),
    Kalman(trajpred_kalman::KalmanError),
    Particle(trajpred_particle::ParticleError),
    Neural(trajpred_neural::NeuralError),
);

/// The reproduction's result type.
pub type Result<T, E = ReproError> = std::result::Result<T, E>;

/// Attaches a path to an I/O error.
pub(crate) fn io_err(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> ReproError {
    let path = path.into();
    move |source| ReproError::Io { path, source }
}
