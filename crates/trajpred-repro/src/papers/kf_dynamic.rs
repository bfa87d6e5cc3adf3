//! Paper runner (being written).

use crate::{Context, PaperResult, ReproError, Result};

/// Why this paper's numbers and ours differ (shown in the results index).
pub const EXPLANATION: &str = "";

/// Runs the paper's experiments.
pub fn run(_ctx: &Context) -> Result<PaperResult> {
    Err(ReproError::Experiment {
        experiment: "kf_dynamic".into(),
        reason: "not written yet".into(),
    })
}
