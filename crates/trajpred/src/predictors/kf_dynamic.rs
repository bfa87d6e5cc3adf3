//! The KF-dynamic paper's predictors: "KF dynamic" (the predictor form of eq. 13-15 through
//! the history; see [`Continuation`] for its steps after the first) and the "naive KF"
//! (filter, then extrapolate `X(k+1) = A X(k)` without correction).

use super::{invalid, positions_forecast, step_interval};
use nalgebra::{DMatrix, DVector, Dyn};
use serde::{Deserialize, Serialize};
use trajpred_core::{
    Error, Forecast, Gaussian, Predictor, Result, Trajectory, check_forecast_args,
};
use trajpred_kalman::motion::{StateOrder, constant_velocity};
use trajpred_kalman::{Filter, Kf, LinearObservation, LinearTransition, MultiStep};

/// Parameters shared by [`KfDynamic`] and [`NaiveKf`]: a constant-velocity state
/// `[positions, velocities]` with the sampling interval of the history as `dt`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KfDynamicParams {
    /// `Q = q I` over the whole state (the paper: 10 or 100).
    pub q: f64,
    /// `R = r I` over the observation (the paper: 10 for the 2-D observation, 1 for the 4-D).
    pub r: f64,
    /// Observe the finite-difference velocity too (the paper's 4-D observation).
    pub observe_velocity: bool,
    /// Initial covariance `P(1|0) = p0 I`.
    pub p0: f64,
    /// How "KF dynamic" continues after the first step (ignored by [`NaiveKf`]); the
    /// presets [`Self::paper_position`] and [`Self::paper_position_velocity`] extrapolate,
    /// the `_literal` ones re-use the last observation.
    pub multi_step: Continuation,
}

/// How "KF dynamic" continues after its first forecast step (mirrors
/// [`trajpred_kalman::MultiStep`], with serde support).
///
/// The paper iterates eq. 13-15 k times "with the previous moment's observation". Read
/// literally ([`Continuation::ReuseLastObservation`]), every later step is corrected towards
/// the same last observation `Z(k)` again, which pulls steps 2.. back to where the target
/// was; on real tracks that makes steps 2.. several times worse than the naive KF (see
/// `docs/kf-dynamic.md`, "Multi-step forecast"). The default,
/// [`Continuation::Extrapolate`], uses `Z(k)` for the first step only and then predicts
/// alone: its forecast equals the naive KF's, `A^j X(k|k)`.
///
/// ```
/// use trajpred::predictors::{Continuation, KfDynamicParams};
/// assert_eq!(KfDynamicParams::default().multi_step, Continuation::Extrapolate);
/// assert_eq!(
///     KfDynamicParams::paper_position_literal(10.0).multi_step,
///     Continuation::ReuseLastObservation
/// );
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Continuation {
    /// Re-apply eq. 13-15 with the latest observation at every step: the paper's wording read
    /// literally, kept for its reproduction (`kf-dynamic-literal` in the registry).
    ReuseLastObservation,
    /// Use the latest observation for the first step, then extrapolate without correction
    /// (`X = A X`, `P = A P A^T + Q`). The default.
    #[default]
    Extrapolate,
}

impl From<Continuation> for MultiStep {
    fn from(c: Continuation) -> Self {
        match c {
            Continuation::ReuseLastObservation => MultiStep::ReuseLastObservation,
            Continuation::Extrapolate => MultiStep::Extrapolate,
        }
    }
}

impl Default for KfDynamicParams {
    fn default() -> Self {
        Self::paper_position(10.0)
    }
}

impl KfDynamicParams {
    /// The paper's Table 1 with a position observation: `R = diag(10, 10)`, `Q = q I`
    /// (q = 10 or 100); extrapolates after the first step ([`Continuation::Extrapolate`]).
    pub fn paper_position(q: f64) -> Self {
        KfDynamicParams {
            q,
            r: 10.0,
            observe_velocity: false,
            p0: 100.0,
            multi_step: Continuation::Extrapolate,
        }
    }

    /// The paper's Table 1 with a position + velocity observation: `R = I_4`, `Q = q I`;
    /// extrapolates after the first step ([`Continuation::Extrapolate`]).
    pub fn paper_position_velocity(q: f64) -> Self {
        KfDynamicParams {
            r: 1.0,
            observe_velocity: true,
            ..Self::paper_position(q)
        }
    }

    /// [`Self::paper_position`] with the paper's multi-step rule read literally
    /// ([`Continuation::ReuseLastObservation`]), as the reproduction runs it.
    ///
    /// ```
    /// use trajpred::predictors::{Continuation, KfDynamicParams};
    /// let p = KfDynamicParams::paper_position_literal(100.0);
    /// assert_eq!(p.multi_step, Continuation::ReuseLastObservation);
    /// assert_eq!((p.q, p.r, p.observe_velocity), (100.0, 10.0, false));
    /// ```
    pub fn paper_position_literal(q: f64) -> Self {
        KfDynamicParams {
            multi_step: Continuation::ReuseLastObservation,
            ..Self::paper_position(q)
        }
    }

    /// [`Self::paper_position_velocity`] with the paper's multi-step rule read literally
    /// ([`Continuation::ReuseLastObservation`]), as the reproduction runs it.
    ///
    /// ```
    /// use trajpred::predictors::{Continuation, KfDynamicParams};
    /// let p = KfDynamicParams::paper_position_velocity_literal(10.0);
    /// assert_eq!(p.multi_step, Continuation::ReuseLastObservation);
    /// assert_eq!((p.q, p.r, p.observe_velocity), (10.0, 1.0, true));
    /// ```
    pub fn paper_position_velocity_literal(q: f64) -> Self {
        KfDynamicParams {
            multi_step: Continuation::ReuseLastObservation,
            ..Self::paper_position_velocity(q)
        }
    }

    fn validate(&self) -> Result<()> {
        for (name, v) in [("q", self.q), ("r", self.r), ("p0", self.p0)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    name,
                    format!("must be finite and positive, got {v}"),
                ));
            }
        }
        Ok(())
    }
}

type DynKf = Kf<LinearTransition<f64, Dyn>, LinearObservation<f64, Dyn, Dyn>>;

fn kalman_error(method: &str) -> impl Fn(trajpred_kalman::KalmanError) -> Error + '_ {
    move |e| Error::method(method, e)
}

/// The CV filter for a history, its observations and the initial one-step prediction.
struct Setup {
    kf: DynKf,
    z: Vec<DVector<f64>>,
    initial: Gaussian<f64, Dyn>,
}

/// Builds the CV filter for `history` and its observation sequence.
fn build(params: &KfDynamicParams, history: &Trajectory, method: &str) -> Result<Setup> {
    let d = history.dim();
    let n = 2 * d;
    let dt = step_interval(history, history.len());
    let cv = constant_velocity::<f64, Dyn>(d, dt, 1.0, StateOrder::PositionsFirst)
        .map_err(kalman_error(method))?;
    let q = DMatrix::identity(n, n) * params.q;
    let transition = LinearTransition::new(cv.f().clone(), q).map_err(kalman_error(method))?;
    let m = if params.observe_velocity { n } else { d };
    let h = DMatrix::from_fn(m, n, |i, j| if i == j { 1.0 } else { 0.0 });
    let observation = LinearObservation::new(h, DMatrix::identity(m, m) * params.r)
        .map_err(kalman_error(method))?;
    let kf = Kf::new(transition, observation).map_err(kalman_error(method))?;
    let times = history.times();
    let z: Vec<DVector<f64>> = (0..history.len())
        .map(|k| {
            let p = history.point(k);
            let mut z = DVector::zeros(m);
            for a in 0..d {
                z[a] = p[a];
            }
            if params.observe_velocity {
                // finite-difference velocity; the first point borrows the second's
                let (i, j) = if k == 0 { (0, 1) } else { (k - 1, k) };
                let (pi, pj) = (history.point(i), history.point(j));
                for a in 0..d {
                    z[d + a] = (pj[a] - pi[a]) / (times[j] - times[i]);
                }
            }
            z
        })
        .collect();
    let mut x0 = DVector::zeros(n);
    for a in 0..d {
        x0[a] = z[0][a];
    }
    let initial = Gaussian::new(x0, DMatrix::identity(n, n) * params.p0)?;
    Ok(Setup { kf, z, initial })
}

/// "KF dynamic" (eq. 13-15): the one-step-ahead predictor form of the Kalman filter, run
/// through the history; the first forecast step uses the latest observation, and the later
/// ones follow [`KfDynamicParams::multi_step`] (by default prediction alone, which gives
/// the naive KF's forecast; the paper's literal reading re-uses the latest observation at
/// every step). The forecast carries the position covariance of every step.
///
/// ```
/// use trajpred::predictors::{KfDynamic, KfDynamicParams};
/// use trajpred_core::{Predictor, Trajectory};
/// // uniform motion at 2 m/s along x
/// let tr = Trajectory::uniform(0.0, 1.0, vec![(0..30).map(|i| 2.0 * i as f64).collect(), vec![5.0; 30]])?;
/// let f = KfDynamic::new(KfDynamicParams::paper_position(10.0))?.forecast(&tr, 3)?;
/// assert!((f.step(1)[0] - 60.0).abs() < 1.0);
/// assert!((f.step(3)[0] - 64.0).abs() < 1.0);
/// assert!(f.covariance(1).is_some());
/// // the literal reading falls behind from step 2 on: it is pulled back to x = 58
/// let lit = KfDynamic::new(KfDynamicParams::paper_position_literal(10.0))?.forecast(&tr, 3)?;
/// assert!(lit.step(3)[0] < 62.0);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KfDynamic {
    params: KfDynamicParams,
}

impl KfDynamic {
    /// A validated predictor (q, r, p0 finite and positive).
    pub fn new(params: KfDynamicParams) -> Result<Self> {
        params.validate()?;
        Ok(KfDynamic { params })
    }
}

impl Predictor for KfDynamic {
    fn name(&self) -> &str {
        "kf-dynamic"
    }
    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(())
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let Setup { kf, z, initial } = build(&self.params, history, self.name())?;
        let last = z.len() - 1;
        let mut prediction = initial;
        for zk in &z[..last] {
            prediction = kf
                .predictor_step(&prediction, Some(zk))
                .map_err(kalman_error(self.name()))?;
        }
        let states = kf
            .predictor_forecast(
                &prediction,
                &z[last],
                horizon,
                self.params.multi_step.into(),
            )
            .map_err(kalman_error(self.name()))?;
        positions_forecast(&states, history.dim())
    }
    fn min_history(&self) -> usize {
        2
    }
}

/// The paper's "naive KF": the standard Kalman filter through the history, then
/// `X(k+1) = A X(k)` from the last filtered state, with no correction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NaiveKf {
    params: KfDynamicParams,
}

impl NaiveKf {
    /// A validated predictor (q, r, p0 finite and positive).
    pub fn new(params: KfDynamicParams) -> Result<Self> {
        params.validate()?;
        Ok(NaiveKf { params })
    }
}

impl Predictor for NaiveKf {
    fn name(&self) -> &str {
        "naive-kf"
    }
    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(())
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let Setup { kf, z, initial } = build(&self.params, history, self.name())?;
        // the first observation updates the initial state directly (no prediction before it)
        let first = kf
            .update(&initial, &z[0])
            .map_err(kalman_error(self.name()))?;
        let obs: Vec<Option<DVector<f64>>> = z[1..].iter().cloned().map(Some).collect();
        let steps = kf
            .filter(&first.posterior, &obs)
            .map_err(kalman_error(self.name()))?;
        let last = steps.last().map_or(&first.posterior, |s| s.posterior());
        let states = kf
            .forecast(last, horizon)
            .map_err(kalman_error(self.name()))?;
        positions_forecast(&states, history.dim())
    }
    fn min_history(&self) -> usize {
        2
    }
}
