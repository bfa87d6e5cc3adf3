//! The KF-dynamic paper's predictors: "KF dynamic" (the predictor form of eq. 13-15 through
//! the history; see [`Continuation`] for its steps after the first) and the "naive KF"
//! (filter, then extrapolate `X(k+1) = A X(k)` without correction).

use super::{invalid, positions_forecast, step_interval};
use nalgebra::{Const, DefaultAllocator, Dim, Dyn, OMatrix, OVector, U1, U2, U3, U4, U6};
use serde::{Deserialize, Serialize};
use trajpred_core::{
    Error, Forecast, Gaussian, Predictor, Result, Trajectory, check_forecast_args,
};
use trajpred_kalman::motion::{StateOrder, constant_velocity};
use trajpred_kalman::{
    Filter, FilterAllocator, Kf, LinearObservation, LinearTransition, MultiStep,
};

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

fn kalman_error(method: &str) -> impl Fn(trajpred_kalman::KalmanError) -> Error + '_ {
    move |e| Error::from_crate(method, e)
}

/// Which of the two predictors runs.
#[derive(Clone, Copy)]
enum Form {
    /// Eq. 13-15 through the history, then [`KfDynamicParams::multi_step`].
    Predictor(Continuation),
    /// Filter through the history, then extrapolate.
    Naive,
}

/// Runs `form` on `history` with the constant-velocity filter at state size `N` (`2 d`) and
/// observation size `M` (`d`, or `2 d` with the velocity observed). Static sizes keep the
/// filter on the stack; [`forecast`] picks them from the history's dimension.
fn forecast_sized<N: Dim, M: Dim>(
    params: &KfDynamicParams,
    history: &Trajectory,
    horizon: usize,
    form: Form,
    method: &str,
) -> Result<Forecast>
where
    DefaultAllocator: FilterAllocator<N, M>,
{
    let err = kalman_error(method);
    let d = history.dim();
    let (n, m) = (2 * d, if params.observe_velocity { 2 * d } else { d });
    let (nd, md) = (N::from_usize(n), M::from_usize(m));
    let dt = step_interval(history, history.len());
    let cv = constant_velocity::<f64, N>(d, dt, 1.0, StateOrder::PositionsFirst).map_err(&err)?;
    let q = OMatrix::<f64, N, N>::identity_generic(nd, nd) * params.q;
    let transition = LinearTransition::new(cv.f().clone(), q).map_err(&err)?;
    let h = OMatrix::<f64, M, N>::identity_generic(md, nd);
    let r = OMatrix::<f64, M, M>::identity_generic(md, md) * params.r;
    let kf = Kf::new(transition, LinearObservation::new(h, r).map_err(&err)?).map_err(&err)?;
    let times = history.times();
    let z: Vec<Option<OVector<f64, M>>> = (0..history.len())
        .map(|k| {
            let p = history.point(k);
            // the velocity: a finite difference; the first point borrows the second's
            let (i, j) = if k == 0 { (0, 1) } else { (k - 1, k) };
            let (pi, pj) = (history.point(i), history.point(j));
            Some(OVector::<f64, M>::from_fn_generic(
                md,
                Const::<1>,
                |a, _| {
                    if a < d {
                        p[a]
                    } else {
                        (pj[a - d] - pi[a - d]) / (times[j] - times[i])
                    }
                },
            ))
        })
        .collect();
    let mut x0 = OVector::<f64, N>::zeros_generic(nd, Const::<1>);
    for (a, x) in history.point(0).iter().enumerate() {
        x0[a] = *x;
    }
    let initial = Gaussian::new(
        x0,
        OMatrix::<f64, N, N>::identity_generic(nd, nd) * params.p0,
    )?;
    let (last, head) = match z.split_last() {
        Some((Some(last), head)) => (last, head),
        _ => return Err(Error::Empty { what: "history" }),
    };
    let states = match form {
        Form::Predictor(mode) => {
            let predictions = kf.predictor_filter(&initial, head).map_err(&err)?;
            let prediction = predictions.last().unwrap_or(&initial);
            kf.predictor_forecast(prediction, last, horizon, mode.into())
        }
        Form::Naive => {
            // the first observation updates the initial state directly (no prediction before it)
            let first = match z.first() {
                Some(Some(z0)) => kf.update(&initial, z0).map_err(&err)?.posterior,
                _ => initial,
            };
            let steps = kf.filter(&first, &z[1..]).map_err(&err)?;
            kf.forecast(steps.last().map_or(&first, |s| s.posterior()), horizon)
        }
    }
    .map_err(&err)?;
    positions_forecast(&states, d)
}

/// [`forecast_sized`] at the static sizes of a 1-, 2- or 3-D history.
fn forecast(
    params: &KfDynamicParams,
    history: &Trajectory,
    horizon: usize,
    form: Form,
    method: &str,
) -> Result<Forecast> {
    let run = match (history.dim(), params.observe_velocity) {
        (1, false) => forecast_sized::<U2, U1>,
        (1, true) => forecast_sized::<U2, U2>,
        (2, false) => forecast_sized::<U4, U2>,
        (2, true) => forecast_sized::<U4, U4>,
        (3, false) => forecast_sized::<U6, U3>,
        (3, true) => forecast_sized::<U6, U6>,
        _ => forecast_sized::<Dyn, Dyn>,
    };
    run(params, history, horizon, form, method)
}

/// The constructor and the [`Predictor`] of [`KfDynamic`] and [`NaiveKf`], which differ
/// only in their name and in the [`Form`] they run.
macro_rules! kf_predictor {
    ($ty:ident, $name:literal, $form:expr) => {
        impl $ty {
            /// A validated predictor (q, r, p0 finite and positive).
            pub fn new(params: KfDynamicParams) -> Result<Self> {
                params.validate()?;
                Ok($ty { params })
            }
        }

        impl Predictor for $ty {
            fn name(&self) -> &str {
                $name
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
                let form = $form(&self.params);
                forecast(&self.params, history, horizon, form, self.name())
            }
            fn min_history(&self) -> usize {
                2
            }
        }
    };
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

kf_predictor!(KfDynamic, "kf-dynamic", |p: &KfDynamicParams| {
    Form::Predictor(p.multi_step)
});

/// The paper's "naive KF": the standard Kalman filter through the history, then
/// `X(k+1) = A X(k)` from the last filtered state, with no correction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NaiveKf {
    params: KfDynamicParams,
}

kf_predictor!(NaiveKf, "naive-kf", |_: &KfDynamicParams| Form::Naive);
