//! A reference method for every leaderboard: constant velocity from the last two points,
//! aware of their time difference.

use super::step_interval;
use serde::{Deserialize, Serialize};
use trajpred_core::{Forecast, Predictor, Result, Trajectory, check_forecast_args};

/// Time-aware last-velocity extrapolation (`cv-time` in the registry).
///
/// The velocity is the last displacement over its own time difference,
/// `v = (p_n - p_{n-1}) / (t_n - t_{n-1})`, and step `k` is predicted at
/// `t_n + k Δ`:
///
/// ```text
/// p(k) = p_n + v k Δ,    Δ = (t_n - t_1) / (n - 1)   (the mean interval of the history)
/// ```
///
/// `Δ` is the time grid the KF-dynamic paper's filters step by (the mean interval of the
/// whole history, see `docs/evaluation.md`), so on irregular tracks they forecast the same
/// instants. Dividing by the last leg's own duration keeps a short or long last interval
/// from being read as a change of speed, as a plain "repeat the last displacement" would.
/// It uses nothing but the last two points and `Δ`, fits nothing and carries no
/// covariance. Asked for positions at given times ([`Predictor::forecast_times`], as the
/// evaluation harness asks at the scored points' timestamps), it carries the velocity to
/// those times instead of the grid.
///
/// ```
/// use trajpred::predictors::CvTime;
/// use trajpred_core::{Predictor, Trajectory};
/// // times 0, 1, 4: the history's mean interval is 2 s; the last leg, 3 s for 6 m, is 2 m/s
/// let tr = Trajectory::from_axes(vec![0.0, 1.0, 4.0], vec![vec![0.0, 1.0, 7.0]])?;
/// let f = CvTime::new().forecast(&tr, 2)?;
/// assert_eq!(f.step(1), &[11.0]); // 7 + 2 m/s * 2 s
/// assert_eq!(f.step(2), &[15.0]); // 7 + 2 m/s * 4 s
/// let g = CvTime::new().forecast_times(&tr, &[5.0, 9.5])?;
/// assert_eq!(g.step(2), &[18.0]); // 7 + 2 m/s * 5.5 s
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CvTime;

impl CvTime {
    /// The predictor (it has no parameters).
    pub fn new() -> Self {
        CvTime
    }
}

impl Predictor for CvTime {
    fn name(&self) -> &str {
        "cv-time"
    }

    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(())
    }

    fn fitted_params(&self) -> Result<serde_json::Value> {
        Ok(serde_json::Value::Null)
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        trajpred_core::load_nothing(self.name(), params)
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let n = history.len();
        let delta = step_interval(history, n);
        let last = history.times()[n - 1];
        let times: Vec<f64> = (1..=horizon).map(|k| last + k as f64 * delta).collect();
        self.forecast_times(history, &times)
    }

    /// The last velocity carried to each requested time.
    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        check_forecast_args(history, times.len(), self.min_history())?;
        let n = history.len();
        let t = history.times();
        // timestamps strictly increase (a `Trajectory` invariant), so this is positive
        let leg = t[n - 1] - t[n - 2];
        super::check_times_after(history, times)?;
        let (last, prev) = (history.point(n - 1), history.point(n - 2));
        let steps: Vec<Vec<f64>> = times
            .iter()
            .map(|&at| {
                let ahead = at - t[n - 1];
                (0..history.dim())
                    .map(|a| last[a] + (last[a] - prev[a]) / leg * ahead)
                    .collect()
            })
            .collect();
        // an overflowing velocity is a typed `NonFinite` error from `Forecast::new`
        Forecast::new(history.dim(), steps)
    }

    fn min_history(&self) -> usize {
        2
    }
}

/// Persistence: the target stays at its last position (`last-position` in the registry).
///
/// The plainest reference forecast there is, and the one a velocity extrapolation is
/// shrunk towards: where fixes are minutes apart and a vehicle may have stopped (T-Drive
/// taxis), a blend of the two ([`Blend`](super::Blend)) can beat both. Fits nothing.
///
/// ```
/// use trajpred::predictors::LastPosition;
/// use trajpred_core::{Predictor, Trajectory};
/// let tr = Trajectory::from_axes(vec![0.0, 1.0], vec![vec![0.0, 1.0], vec![5.0, 6.0]])?;
/// let f = LastPosition::new().forecast_times(&tr, &[2.0, 3.0])?;
/// assert_eq!(f.step(2), &[1.0, 6.0]);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LastPosition;

impl LastPosition {
    /// The predictor (it has no parameters).
    pub fn new() -> Self {
        LastPosition
    }
}

impl Predictor for LastPosition {
    fn name(&self) -> &str {
        "last-position"
    }

    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(())
    }

    fn fitted_params(&self) -> Result<serde_json::Value> {
        Ok(serde_json::Value::Null)
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        trajpred_core::load_nothing(self.name(), params)
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let last = history.point(history.len() - 1);
        Forecast::new(history.dim(), vec![last.as_ref().to_vec(); horizon])
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        self.forecast(history, times.len())
    }
}
