//! The interacting multiple model filter over actual time ("imm"): constant-velocity,
//! coordinated-turn (EKF) and constant-acceleration modes on the state
//! `[x, vx, y, vy, omega, ax, ay]` ([`trajpred_kalman::turn_accel`]), switching at random
//! ([`trajpred_kalman::imm::uniform_switching`]); the noise of every mode follows each
//! interval of the track (continuous white noise, as in [`KfTime`]). Run through the filter
//! driver ([`trajpred_kalman::driver`]); forecasts at any future times with the mixture's
//! mean and covariance. 2-D tracks only (the turn acts in the plane).
//!
//! Fitting, on the training tracks: the acceleration density `q` and observation variance
//! `r` are [`KfTime`]'s maximum-likelihood fit of the constant-velocity model, the jerk
//! density its fit of the constant-acceleration model; then the turn-rate density and the mean sojourn time in a mode maximise the IMM's own likelihood
//! (the same grid search). See `docs/kalman.md`, section "IMM".

use super::fitted::{At, exact};
use super::{
    forecast_times_on_mean_interval, invalid, kf_time::maximise, offsets_after, positions_forecast,
};
use crate::predictors::{KfTime, KfTimeParams};
use nalgebra::{SMatrix, SVector, U2, U7, Vector2};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use trajpred_core::{Error, Forecast, Gaussian, Predictor, Result, Trajectory};
use trajpred_kalman::driver::{TimeStepFilter, drive_each};
use trajpred_kalman::imm::{
    Imm, ImmState, TimedImm, coordinated_turn_continuous, uniform_switching,
};
use trajpred_kalman::turn_accel::{
    TurnWithAcceleration, constant_acceleration, constant_velocity, position_observation,
};
use trajpred_kalman::{Ekf, Filter, KalmanError, Kf};

/// Settings of [`ImmPredictor`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ImmParams {
    /// Spectral density of the white-noise acceleration of both modes (m^2/s^3); fitted.
    pub spectral_density: f64,
    /// Observation variance per axis (m^2); fitted.
    pub r: f64,
    /// Spectral density of the turn rate's random walk in the turn mode (rad^2/s^3); fitted.
    pub turn_rate_density: f64,
    /// Spectral density of the white jerk of the constant-acceleration mode (m^2/s^5);
    /// fitted.
    pub jerk_density: f64,
    /// Mean time spent in a mode before switching (s); fitted.
    pub mean_sojourn: f64,
    /// Variance of the initial velocity components (m^2/s^2).
    pub initial_rate_variance: f64,
    /// Variance of the initial turn rate (rad^2/s^2).
    pub initial_turn_rate_variance: f64,
    /// Fit the four noise settings on the training tracks.
    pub fit_noise: bool,
    /// The fit of `q`, `r` uses at most this many training tracks (evenly spread), the fit of
    /// the turn and switching settings a quarter of them ...
    pub fit_tracks: usize,
    /// ... and at most this many points of each.
    pub fit_points: usize,
}

impl Default for ImmParams {
    fn default() -> Self {
        ImmParams {
            spectral_density: 1.0,
            r: 10.0,
            turn_rate_density: 1e-3,
            jerk_density: 0.1,
            mean_sojourn: 20.0,
            initial_rate_variance: 100.0,
            initial_turn_rate_variance: 0.01,
            fit_noise: true,
            fit_tracks: 400,
            fit_points: 200,
        }
    }
}

impl ImmParams {
    fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("spectral_density", self.spectral_density),
            ("r", self.r),
            ("turn_rate_density", self.turn_rate_density),
            ("jerk_density", self.jerk_density),
            ("mean_sojourn", self.mean_sojourn),
            ("initial_rate_variance", self.initial_rate_variance),
            (
                "initial_turn_rate_variance",
                self.initial_turn_rate_variance,
            ),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    name,
                    format!("must be finite and positive, got {v}"),
                ));
            }
        }
        if self.fit_tracks < 4 || self.fit_points < 3 {
            return Err(invalid(
                "fit_tracks",
                format!(
                    "the fit needs at least 4 tracks of at least 3 points, got {} tracks of {} points",
                    self.fit_tracks, self.fit_points
                ),
            ));
        }
        Ok(())
    }
}

/// The IMM predictor ("imm"): see the module documentation.
///
/// ```
/// use trajpred::predictors::{ImmParams, ImmPredictor};
/// use trajpred_core::{Predictor, Trajectory};
/// // 2 m/s along x, sampled at irregular times
/// let t = vec![0.0, 1.0, 3.0, 3.5, 5.0, 8.0, 9.0];
/// let x: Vec<f64> = t.iter().map(|t| 2.0 * t).collect();
/// let tr = Trajectory::from_axes(t, vec![x, vec![0.0; 7]])?;
/// let p = ImmPredictor::new(ImmParams { fit_noise: false, ..Default::default() })?;
/// let f = p.forecast_times(&tr, &[10.0, 14.0])?;
/// assert!((f.step(2)[0] - 28.0).abs() < 1.0);
/// assert!(f.covariance(2).is_some());
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImmPredictor {
    params: ImmParams,
}

type Mode = Box<dyn Filter<f64, U7, U2>>;

fn kalman(e: KalmanError) -> Error {
    Error::from_crate("imm", e)
}

/// The IMM for a step of `dt` seconds under `p`.
fn build(p: ImmParams, dt: f64) -> trajpred_kalman::Result<Imm<f64, Mode>> {
    let obs = position_observation::<f64>(p.r)?;
    let cv = Kf::new(
        constant_velocity::<f64>(dt, p.spectral_density)?,
        obs.clone(),
    )?;
    let turn = coordinated_turn_continuous::<f64>(dt, p.spectral_density, p.turn_rate_density)?;
    let ct = Ekf::new(TurnWithAcceleration::new(turn), obs.clone())?;
    let ca = Kf::new(constant_acceleration::<f64>(dt, p.jerk_density)?, obs)?;
    let modes: Vec<Mode> = vec![Box::new(cv), Box::new(ct), Box::new(ca)];
    Imm::new(modes, uniform_switching(MODES, dt, p.mean_sojourn)?)
}

/// The modes: constant velocity, coordinated turn, constant acceleration.
const MODES: usize = 3;

type Run = TimedImm<f64, U7, Mode, Box<dyn Fn(f64) -> trajpred_kalman::Result<Imm<f64, Mode>>>>;

impl ImmPredictor {
    /// A validated predictor.
    pub fn new(params: ImmParams) -> Result<Self> {
        params.validate()?;
        Ok(ImmPredictor { params })
    }

    /// The settings, with the fitted noise after [`Predictor::fit`].
    pub fn params(&self) -> &ImmParams {
        &self.params
    }

    /// The IMM after running through `history` under `p`.
    fn run(history: &Trajectory, p: ImmParams) -> Result<Run> {
        if history.dim() != 2 {
            return Err(invalid(
                "dim",
                format!(
                    "the IMM predictor needs 2-D tracks, got {}-D",
                    history.dim()
                ),
            ));
        }
        let first = history.point(0);
        let v = p.initial_rate_variance;
        let start = Gaussian::new(
            SVector::<f64, 7>::from_column_slice(&[first[0], 0.0, first[1], 0.0, 0.0, 0.0, 0.0]),
            SMatrix::<f64, 7, 7>::from_diagonal(&SVector::<f64, 7>::from_column_slice(&[
                p.r,
                v,
                p.r,
                v,
                p.initial_turn_rate_variance,
                v,
                v,
            ])),
        )?;
        let make: Box<dyn Fn(f64) -> trajpred_kalman::Result<Imm<f64, Mode>>> =
            Box::new(move |dt| build(p, dt));
        let mut f = TimedImm::new(make, ImmState::uniform(start, MODES).map_err(kalman)?);
        let z: Vec<Option<Vector2<f64>>> = (0..history.len())
            .map(|k| {
                let q = history.point(k);
                Some(Vector2::new(q[0], q[1]))
            })
            .collect();
        drive_each(&mut f, history.times(), &z, |_, _| Ok(())).map_err(kalman)?;
        Ok(f)
    }

    /// The log-likelihood of the tracks under `p` (a failing track counts `-inf`).
    fn log_likelihood(tracks: &[Trajectory], p: ImmParams) -> f64 {
        tracks
            .par_iter()
            .map(|t| Self::run(t, p).map_or(f64::NEG_INFINITY, |f| f.log_likelihood()))
            .sum()
    }
}

impl Predictor for ImmPredictor {
    fn name(&self) -> &str {
        "imm"
    }

    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        if !self.params.fit_noise {
            return Ok(());
        }
        let mut kf = KfTime::new(KfTimeParams {
            derivatives: 2,
            fit_tracks: self.params.fit_tracks,
            fit_points: self.params.fit_points,
            ..Default::default()
        })?;
        kf.fit(train)?;
        let mut p = self.params;
        (p.spectral_density, p.r) = (kf.params().spectral_density, kf.params().r);
        let mut ca = KfTime::new(KfTimeParams {
            derivatives: 3,
            fit_tracks: self.params.fit_tracks,
            fit_points: self.params.fit_points,
            ..Default::default()
        })?;
        ca.fit(train)?;
        p.jerk_density = ca.params().spectral_density;
        let usable: Vec<&Trajectory> = train.iter().filter(|t| t.len() >= 3).collect();
        let step = usable.len().div_ceil(self.params.fit_tracks / 4).max(1);
        let tracks: Vec<Trajectory> = usable
            .iter()
            .step_by(step)
            .map(|t| t.slice(0..t.len().min(self.params.fit_points)))
            .collect::<Result<_>>()?;
        let (ll, turn, sojourn) = maximise(
            |turn, sojourn| {
                let q = ImmParams {
                    turn_rate_density: turn,
                    mean_sojourn: sojourn,
                    ..p
                };
                Self::log_likelihood(&tracks, q)
            },
            (-7.0, -1.0),
            (0.0, 3.0),
        );
        if ll.is_finite() {
            (p.turn_rate_density, p.mean_sojourn) = (turn, sojourn);
        }
        self.params = p;
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        self.forecast_times(history, &forecast_times_on_mean_interval(history, horizon)?)
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        let offsets = offsets_after(history, times)?;
        let f = Self::run(history, self.params)?;
        let states = f.forecast_at(&offsets).map_err(kalman)?;
        // positions_forecast reads the first d components: gather (x, y) from [x, vx, y, ...]
        let states: Vec<Gaussian<f64, U2>> = states
            .iter()
            .map(|g| Gaussian {
                mean: Vector2::new(g.mean[0], g.mean[2]),
                covariance: nalgebra::Matrix2::new(
                    g.covariance[(0, 0)],
                    g.covariance[(0, 2)],
                    g.covariance[(2, 0)],
                    g.covariance[(2, 2)],
                ),
            })
            .collect();
        positions_forecast(&states, 2)
    }

    /// The five fitted settings `{"spectral_density", "r", "turn_rate_density",
    /// "jerk_density", "mean_sojourn"}` (fitted, or as given when `fit_noise` is off).
    fn fitted_params(&self) -> Result<serde_json::Value> {
        let p = &self.params;
        Ok(serde_json::json!({
            "spectral_density": exact(p.spectral_density),
            "r": exact(p.r),
            "turn_rate_density": exact(p.turn_rate_density),
            "jerk_density": exact(p.jerk_density),
            "mean_sojourn": exact(p.mean_sojourn),
        }))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let name = self.name().to_string();
        let [q, r, turn, jerk, sojourn] = At::root(&name, params).fields([
            "spectral_density",
            "r",
            "turn_rate_density",
            "jerk_density",
            "mean_sojourn",
        ])?;
        self.params = ImmParams {
            spectral_density: q.f64_min(0.0, true)?,
            r: r.f64_min(0.0, true)?,
            turn_rate_density: turn.f64_min(0.0, true)?,
            jerk_density: jerk.f64_min(0.0, true)?,
            mean_sojourn: sojourn.f64_min(0.0, true)?,
            ..self.params
        };
        Ok(())
    }

    fn fitted_summary(&self) -> Option<String> {
        let p = &self.params;
        Some(format!(
            "q = {:.3e} m^2/s^3, r = {:.3e} m^2, turn-rate density {:.3e} rad^2/s^3, jerk density {:.3e} m^2/s^5, mean sojourn {:.3e} s",
            p.spectral_density, p.r, p.turn_rate_density, p.jerk_density, p.mean_sojourn
        ))
    }
}
