//! Every method of the four papers as a [`Predictor`](trajpred_core::Predictor).

mod aligned_features;
mod aligned_gbm;
#[cfg(feature = "neural")]
mod aligned_mlp;
mod aligned_ridge;
mod auto;
mod blend;
mod cv_cache;
mod cv_time;
mod fitted;
mod gskf;
mod hmm;
mod imm;
mod kf_dynamic;
mod kf_time;
mod particle;
mod poly;
mod trees;

pub use aligned_gbm::{AlignedGbm, AlignedGbmParams};
#[cfg(feature = "neural")]
pub use aligned_mlp::{AlignedMlp, AlignedMlpParams};
pub use aligned_ridge::{AlignedRidge, AlignedRidgeParams};
pub use auto::{Auto, AutoParams, CandidateScore, DEFAULT_CANDIDATES, cross_validate};
pub use blend::{Blend, BlendParams};
pub use cv_cache::HeldOutCache;
pub use cv_time::{CvTime, LastPosition};
pub use gskf::{Diverged, Gsc, Gskf, GskfParams};
pub use hmm::{Hmm, HmmParams, MAX_HMM_STATES};
pub use imm::{ImmParams, ImmPredictor};
pub use kf_dynamic::{Continuation, KfDynamic, KfDynamicParams, NaiveKf};
pub use kf_time::{KfTime, KfTimeParams};
pub use particle::{ParticleKind, ParticleParams, ParticlePredictor};
pub use poly::{PolyFit, PolyFitParams};

use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim};
use trajpred_core::{Error, Forecast, Gaussian, Result, Trajectory};

/// The forecast of the first `d` state components (the positions, for `[positions,
/// velocities]` states) of each predicted Gaussian, with their covariances.
pub(crate) fn positions_forecast<D: Dim>(states: &[Gaussian<f64, D>], d: usize) -> Result<Forecast>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let means: Vec<Vec<f64>> = states
        .iter()
        .map(|g| g.mean.rows(0, d).iter().copied().collect())
        .collect();
    let covs = states
        .iter()
        .map(|g| g.covariance.view((0, 0), (d, d)).into_owned())
        .collect();
    Forecast::new(d, means)?.with_covariances(covs)
}

pub(crate) fn invalid(name: &'static str, reason: impl Into<String>) -> Error {
    Error::InvalidParameter {
        name,
        reason: reason.into(),
    }
}

/// The sampling interval a predictor steps by: the mean interval of the last `window` points
/// of the history (at least two points; a single point gives 1 s).
pub(crate) fn step_interval(history: &Trajectory, window: usize) -> f64 {
    let n = history.len();
    let w = window.clamp(2, n.max(2));
    if n < 2 {
        return 1.0;
    }
    let t = history.times();
    (t[n - 1] - t[n - w.min(n)]) / (w.min(n) - 1) as f64
}

/// The `horizon` forecast times after the end of `history`, spaced by the history's mean
/// interval (1 s for a single point), the forecast arguments checked.
pub(crate) fn forecast_times_on_mean_interval(
    history: &Trajectory,
    horizon: usize,
) -> Result<Vec<f64>> {
    trajpred_core::check_forecast_args(history, horizon, 1)?;
    let t = history.times();
    let n = t.len();
    let dt = if n >= 2 {
        (t[n - 1] - t[0]) / (n - 1) as f64
    } else {
        1.0
    };
    Ok((1..=horizon).map(|k| t[n - 1] + dt * k as f64).collect())
}

/// The offsets of `times` after the end of `history`, the forecast arguments checked.
pub(crate) fn offsets_after(history: &Trajectory, times: &[f64]) -> Result<Vec<f64>> {
    trajpred_core::check_forecast_args(history, times.len(), 1)?;
    let last = history.times()[history.len() - 1];
    Ok(times.iter().map(|&t| t - last).collect())
}

/// The checks of a fitted multi-step model's `forecast_times`: at most `fitted` steps, every
/// time finite and after the history's end; the errors name `horizon` or `times`.
pub(crate) fn check_fitted_times(
    method: &str,
    fitted: usize,
    history: &Trajectory,
    times: &[f64],
) -> Result<()> {
    if times.len() > fitted {
        return Err(invalid(
            "horizon",
            format!(
                "{method} was fitted for {fitted} steps, asked for {}",
                times.len()
            ),
        ));
    }
    check_times_after(history, times)
}

/// Every forecast time finite and after the history's end (an error naming `times`).
pub(crate) fn check_times_after(history: &Trajectory, times: &[f64]) -> Result<()> {
    let Some(&end) = history.times().last() else {
        return Err(Error::Empty { what: "history" });
    };
    match times.iter().find(|&&x| !(x.is_finite() && x > end)) {
        Some(&bad) => Err(invalid(
            "times",
            format!("forecast times must be after the history's end {end}, got {bad}"),
        )),
        None => Ok(()),
    }
}

/// The point `tau` seconds after the end of `history` that a horizontal displacement
/// `(dx, dy)` reaches (`dy` dropped for 1-D tracks); a third axis (altitude) follows its last
/// velocity. Needs at least two history points for 3-D tracks.
pub(crate) fn displaced_point(history: &Trajectory, (dx, dy): (f64, f64), tau: f64) -> Vec<f64> {
    let n = history.len();
    let last = history.last_point();
    let mut p = vec![last[0] + dx];
    if history.dim() >= 2 {
        p.push(last[1] + dy);
    }
    if history.dim() >= 3 && n >= 2 {
        let t = history.times();
        let vz = (last[2] - history.point(n - 2)[2]) / (t[n - 1] - t[n - 2]);
        p.push(last[2] + vz * tau);
    }
    p
}

/// The horizontal frame of the aligned methods (`aligned-ridge`, `aligned-gbm`): the unit
/// heading `(cos, sin)` of the first velocity faster than 1e-9 m/s (+x if none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Heading(f64, f64);

impl Heading {
    /// From velocities, newest first.
    pub(crate) fn of<'a>(velocities: impl IntoIterator<Item = &'a (f64, f64)>) -> Self {
        let (c, s) = velocities
            .into_iter()
            .map(|&(a, b)| (a, b, a.hypot(b)))
            .find(|&(_, _, s)| s > 1e-9)
            .map_or((1.0, 0.0), |(a, b, s)| (a / s, b / s));
        Heading(c, s)
    }

    /// A vector in the frame where the heading points along +x.
    pub(crate) fn rotate(self, (a, b): (f64, f64)) -> (f64, f64) {
        (self.0 * a + self.1 * b, self.0 * b - self.1 * a)
    }

    /// An aligned vector back in the data's axes.
    pub(crate) fn unrotate(self, (a, b): (f64, f64)) -> (f64, f64) {
        (self.0 * a - self.1 * b, self.1 * a + self.0 * b)
    }
}

/// The first two axes of a track (`y` zeros for a 1-D track).
pub(crate) fn horizontal_axes(tr: &Trajectory) -> (&[f64], Vec<f64>) {
    let y = if tr.dim() >= 2 {
        tr.axis(1).to_vec()
    } else {
        vec![0.0; tr.len()]
    };
    (tr.axis(0), y)
}

/// Each trajectory its own group: what `fit` without groups means for the methods that
/// cross-validate by group.
pub(crate) fn own_groups(train: &[Trajectory]) -> Vec<usize> {
    (0..train.len()).collect()
}

/// Labels `0..n`: `n` trajectories, each its own group.
pub(crate) fn own_groups_of(n: usize) -> Vec<usize> {
    (0..n).collect()
}

/// One group label per training trajectory.
pub(crate) fn check_groups(train: &[Trajectory], groups: &[usize]) -> Result<()> {
    if groups.len() == train.len() {
        return Ok(());
    }
    Err(Error::LengthMismatch {
        what: "groups vs training trajectories",
        expected: train.len(),
        got: groups.len(),
    })
}
