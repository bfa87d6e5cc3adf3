//! The error type of the reproduction.

use crate::report::Difference;
use std::fmt::Write as _;
use std::path::PathBuf;

/// One difference a line.
fn list(differences: &[Difference]) -> String {
    let mut s = String::new();
    for d in differences {
        let _ = write!(s, "\n  - {d}");
    }
    s
}

/// What can go wrong while reproducing a paper or checking a run.
#[derive(Debug, thiserror::Error)]
pub enum ReproError {
    /// A method or data structure of the core crates refused its input.
    #[error(transparent)]
    Core(#[from] trajpred_core::Error),
    /// A loader refused a data file.
    #[error(transparent)]
    Data(#[from] trajpred_data::Error),
    /// A metric refused its input.
    #[error(transparent)]
    Metrics(#[from] trajpred_metrics::MetricsError),
    /// A filter refused its input.
    #[error(transparent)]
    Kalman(#[from] trajpred_kalman::KalmanError),
    /// A particle filter refused its input.
    #[error(transparent)]
    Particle(#[from] trajpred_particle::ParticleError),
    /// A neural model refused its input or failed to train.
    #[error(transparent)]
    Neural(#[from] trajpred_neural::NeuralError),
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

/// The reproduction's result type.
pub type Result<T, E = ReproError> = std::result::Result<T, E>;

/// Attaches a path to an I/O error.
pub(crate) fn io_err(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> ReproError {
    let path = path.into();
    move |source| ReproError::Io { path, source }
}
