//! The [`Predictor`] trait every method implements, and the [`Forecast`] it returns.

use crate::error::{Error, Result};
use crate::trajectory::{MAX_AXES, Point, Trajectory};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Predicted points for steps `1..=horizon` after the forecast origin, and, where the method
/// has them, the covariance of each prediction.
///
/// ```
/// use trajpred_core::Forecast;
/// let f = Forecast::new(2, vec![vec![1.0, 2.0], vec![3.0, 4.0]])?;
/// assert_eq!(f.horizon(), 2);
/// assert_eq!(f.step(2), &[3.0, 4.0]);
/// assert!(f.covariance(1).is_none());
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Forecast {
    dim: usize,
    /// `horizon * dim` values, step by step.
    means: Vec<f64>,
    covariances: Option<Vec<DMatrix<f64>>>,
}

impl Forecast {
    /// A forecast of `dim`-axis points, one per step. Every point must have `dim` finite values.
    pub fn new<P: AsRef<[f64]>>(dim: usize, steps: Vec<P>) -> Result<Self> {
        if dim == 0 || dim > MAX_AXES {
            return Err(Error::UnsupportedDimension { got: dim });
        }
        if steps.is_empty() {
            return Err(Error::Empty { what: "forecast" });
        }
        let mut means = Vec::with_capacity(steps.len() * dim);
        for (i, p) in steps.iter().enumerate() {
            let p = p.as_ref();
            if p.len() != dim {
                return Err(Error::DimensionMismatch {
                    what: "forecast step",
                    expected: dim,
                    got: p.len(),
                });
            }
            if p.iter().any(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    what: "forecast",
                    index: i,
                });
            }
            means.extend_from_slice(p);
        }
        Ok(Forecast {
            dim,
            means,
            covariances: None,
        })
    }

    /// Attaches one `dim x dim` covariance per step.
    pub fn with_covariances(mut self, covariances: Vec<DMatrix<f64>>) -> Result<Self> {
        if covariances.len() != self.horizon() {
            return Err(Error::LengthMismatch {
                what: "covariances vs forecast steps",
                expected: self.horizon(),
                got: covariances.len(),
            });
        }
        for (i, c) in covariances.iter().enumerate() {
            if c.nrows() != self.dim || c.ncols() != self.dim {
                return Err(Error::DimensionMismatch {
                    what: "forecast covariance",
                    expected: self.dim,
                    got: c.nrows().max(c.ncols()),
                });
            }
            if c.iter().any(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    what: "forecast covariance",
                    index: i,
                });
            }
        }
        self.covariances = Some(covariances);
        Ok(self)
    }

    /// Number of axes of each predicted point.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of predicted steps.
    pub fn horizon(&self) -> usize {
        self.means.len() / self.dim
    }

    /// The prediction `k` steps ahead (`1 <= k <= horizon`). Panics outside that range.
    pub fn step(&self, k: usize) -> &[f64] {
        assert!(
            k >= 1 && k <= self.horizon(),
            "step {k} outside 1..={}",
            self.horizon()
        );
        &self.means[(k - 1) * self.dim..k * self.dim]
    }

    /// The predicted points, step 1 first.
    pub fn points(&self) -> impl ExactSizeIterator<Item = Point> + '_ {
        self.means
            .chunks_exact(self.dim)
            .map(|c| Point::new(c).unwrap_or_else(|_| unreachable!("dim checked at construction")))
    }

    /// The covariance of the prediction `k` steps ahead, if the method provides one.
    pub fn covariance(&self, k: usize) -> Option<&DMatrix<f64>> {
        self.covariances
            .as_ref()
            .and_then(|c| c.get(k.checked_sub(1)?))
    }
}

/// A trajectory predictor: fitted once on training trajectories, then asked for `horizon`
/// steps after the end of any history.
///
/// Contract, for every implementation:
/// - **Causal**: `forecast` sees only `history`; the forecast made at an origin never depends
///   on anything after it. (The evaluation harness passes `history = trajectory[..=origin]`.)
/// - **Deterministic**: the same fitted predictor and history give the same forecast; any
///   randomness is seeded by the predictor's parameters.
/// - Steps are the history's sampling steps; methods that need a time step take it from the
///   history's timestamps.
/// - Errors, never panics, for bad input.
///
/// The trait is object safe, so a method chosen at run time is a `Box<dyn Predictor>`:
///
/// ```
/// use trajpred_core::{check_forecast_args, Forecast, Predictor, Result, Trajectory};
///
/// /// Repeats the last point.
/// struct Persistence;
/// impl Predictor for Persistence {
///     fn name(&self) -> &str { "persistence" }
///     fn fit(&mut self, _train: &[Trajectory]) -> Result<()> { Ok(()) }
///     fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
///         check_forecast_args(history, horizon, self.min_history())?;
///         let last = history.last_point();
///         Forecast::new(history.dim(), vec![last; horizon])
///     }
/// }
///
/// let mut p: Box<dyn Predictor> = Box::new(Persistence);
/// let tr = Trajectory::uniform(0.0, 1.0, vec![vec![1.0, 2.0, 3.0]])?;
/// p.fit(std::slice::from_ref(&tr))?;
/// assert_eq!(p.forecast(&tr, 2)?.step(2), &[3.0]);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
pub trait Predictor: Send + Sync {
    /// A short, stable name (used in tables and on the command line).
    fn name(&self) -> &str;

    /// Learns whatever the method learns from training trajectories (may be a no-op).
    fn fit(&mut self, train: &[Trajectory]) -> Result<()>;

    /// [`Predictor::fit`] told which group (user, vehicle, file) each training trajectory
    /// came from: `groups[i]` labels `train[i]`, and trajectories with the same label belong
    /// together. Methods that choose something by cross-validation use it to hold out whole
    /// groups, so that a choice is scored on users the fold did not train on; the default
    /// ignores the labels and calls [`Predictor::fit`]. The evaluation path calls this one,
    /// with the segments' groups. Errors if the lengths differ.
    fn fit_grouped(&mut self, train: &[Trajectory], groups: &[usize]) -> Result<()> {
        if groups.len() != train.len() {
            return Err(Error::LengthMismatch {
                what: "groups vs training trajectories",
                expected: train.len(),
                got: groups.len(),
            });
        }
        self.fit(train)
    }

    /// Predicts `horizon` steps after the last point of `history`.
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast>;

    /// Predicts the positions at the future `times` (seconds, increasing, after the
    /// history's last time): "where will it be at 12:00:05". The default answers with
    /// [`Predictor::forecast`] of `times.len()` steps on the method's own time grid (the
    /// history's mean interval), for methods that step by index; methods that model time
    /// override it. The evaluation harness asks at the timestamps of the points it scores
    /// against: their times, never their positions.
    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        self.forecast(history, times.len())
    }

    /// The shortest history `forecast` accepts.
    fn min_history(&self) -> usize {
        1
    }

    /// What fitting chose, in words (e.g. the HMM's number of states), for reports; `None`
    /// for a method that learns nothing or has nothing to say.
    fn fitted_summary(&self) -> Option<String> {
        None
    }

    /// What fitting learned, as JSON, to be saved and handed back to
    /// [`Predictor::load_fitted_params`] of a predictor built with the same options:
    /// `null` for a method that learns nothing. The contract: after loading, the predictor
    /// forecasts bit for bit as the fitted one did (so floating-point numbers must survive
    /// the trip exactly; see `docs/evaluation.md`, "Saved parameters").
    ///
    /// The default refuses with [`Error::ParamsUnsupported`]: a method must say what it
    /// learns (or that it learns nothing) before its parameters can be saved, so a learner
    /// that forgets is an error, never a file that silently holds nothing.
    fn fitted_params(&self) -> Result<serde_json::Value> {
        Err(Error::ParamsUnsupported {
            method: self.name().to_string(),
            reason: "the method does not export what fitting learns".into(),
        })
    }

    /// Takes back what [`Predictor::fitted_params`] exported, instead of fitting. Strict:
    /// every value is checked (finite, in range, shapes consistent with the options); a bad
    /// one is [`Error::InvalidFitted`] naming its JSON path. The default refuses, like
    /// [`Predictor::fitted_params`].
    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let _ = params;
        Err(Error::ParamsUnsupported {
            method: self.name().to_string(),
            reason: "the method does not load fitted parameters".into(),
        })
    }
}

/// [`Predictor::load_fitted_params`] of a method that learns nothing: only `null` is
/// accepted.
///
/// ```
/// use trajpred_core::{load_nothing, Error};
/// assert!(load_nothing("poly1", &serde_json::Value::Null).is_ok());
/// assert!(matches!(
///     load_nothing("poly1", &serde_json::json!({"q": 1})),
///     Err(Error::InvalidFitted { .. })
/// ));
/// ```
pub fn load_nothing(method: &str, params: &serde_json::Value) -> Result<()> {
    if params.is_null() {
        Ok(())
    } else {
        Err(Error::InvalidFitted {
            method: method.to_string(),
            path: String::new(),
            reason: "this method learns nothing when fitted: its parameters must be null".into(),
        })
    }
}

impl<P: Predictor + ?Sized> Predictor for Box<P> {
    fn name(&self) -> &str {
        (**self).name()
    }
    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        (**self).fit(train)
    }
    fn fit_grouped(&mut self, train: &[Trajectory], groups: &[usize]) -> Result<()> {
        (**self).fit_grouped(train, groups)
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        (**self).forecast(history, horizon)
    }
    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        (**self).forecast_times(history, times)
    }
    fn min_history(&self) -> usize {
        (**self).min_history()
    }
    fn fitted_summary(&self) -> Option<String> {
        (**self).fitted_summary()
    }
    fn fitted_params(&self) -> Result<serde_json::Value> {
        (**self).fitted_params()
    }
    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        (**self).load_fitted_params(params)
    }
}

/// The longest forecast [`check_forecast_args`] accepts, in steps.
///
/// A forecast holds `horizon` points (and perhaps `horizon` covariances), so an unchecked
/// horizon read from a command line (`--horizon 100000000000`) would make a predictor try to
/// allocate terabytes and abort. 100 000 steps is 27 hours at one point a second, far beyond
/// any horizon a trajectory model is meaningful for; a predictor that needs more calls
/// [`check_forecast_args_with_max`] with its own limit.
pub const MAX_HORIZON: usize = 100_000;

/// Checks the arguments every `forecast` must check: `1 <= horizon <= MAX_HORIZON` and a long
/// enough history. Implementations call it first, before allocating anything that grows with
/// the horizon.
///
/// ```
/// use trajpred_core::{check_forecast_args, Error, Trajectory, MAX_HORIZON};
/// let tr = Trajectory::uniform(0.0, 1.0, vec![vec![1.0, 2.0]])?;
/// assert!(check_forecast_args(&tr, MAX_HORIZON, 1).is_ok());
/// assert!(matches!(
///     check_forecast_args(&tr, MAX_HORIZON + 1, 1),
///     Err(Error::InvalidParameter { name: "horizon", .. })
/// ));
/// # Ok::<(), trajpred_core::Error>(())
/// ```
pub fn check_forecast_args(history: &Trajectory, horizon: usize, min_history: usize) -> Result<()> {
    check_forecast_args_with_max(history, horizon, min_history, MAX_HORIZON)
}

/// [`check_forecast_args`] with a horizon limit of the caller's choosing (`max_horizon`
/// instead of [`MAX_HORIZON`]).
pub fn check_forecast_args_with_max(
    history: &Trajectory,
    horizon: usize,
    min_history: usize,
    max_horizon: usize,
) -> Result<()> {
    if horizon == 0 {
        return Err(Error::InvalidParameter {
            name: "horizon",
            reason: format!("must be at least 1, got {horizon}"),
        });
    }
    if horizon > max_horizon {
        return Err(Error::InvalidParameter {
            name: "horizon",
            reason: format!("{horizon} steps exceeds the maximum horizon of {max_horizon} steps"),
        });
    }
    if history.len() < min_history {
        return Err(Error::TooShort {
            what: "history",
            needed: min_history,
            got: history.len(),
        });
    }
    Ok(())
}
