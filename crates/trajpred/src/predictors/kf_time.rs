//! A Kalman filter over actual time, with its noise fitted to the data: constant velocity
//! (or acceleration) driven by continuous white noise, whose `Q` follows each interval of the
//! track, and the spectral density `q` and observation variance `r` chosen by maximum
//! likelihood on the training tracks. Run through the filter driver
//! ([`trajpred_kalman::driver`]); forecasts at any future times.

use super::fitted::{At, exact};
use super::{forecast_times_on_mean_interval, invalid, offsets_after, positions_forecast};
use nalgebra::{Const, DefaultAllocator, Dim, Dyn, OMatrix, OVector, U1, U2, U3, U4, U6, U9};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use trajpred_core::{Error, Forecast, Gaussian, Predictor, Result, Trajectory};
use trajpred_kalman::driver::{StepBuilder, TimeStepFilter, Timed, drive_each};
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, damped_velocity, kinematic_continuous,
    kinematic_continuous_in_place, position_observation,
};
use trajpred_kalman::{FilterAllocator, KalmanError, Kf, LinearObservation, LinearTransition};

/// Settings of [`KfTime`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KfTimeParams {
    /// 2: constant velocity (white-noise acceleration); 3: constant acceleration (white-noise
    /// jerk).
    pub derivatives: usize,
    /// Spectral density `q` of the white noise (m^2/s^3 for velocity, m^2/s^5 for
    /// acceleration); replaced by the fitted value after [`Predictor::fit`] when `fit_noise`.
    pub spectral_density: f64,
    /// Observation variance `r` per axis (m^2); likewise fitted.
    pub r: f64,
    /// Variance of the initial velocity (and acceleration) components: vague, since the
    /// filter starts from one position.
    pub initial_rate_variance: f64,
    /// With 2 derivatives: the velocity relaxes towards zero with this time constant
    /// (seconds; the integrated Ornstein-Uhlenbeck model of
    /// [`trajpred_kalman::motion::damped_velocity`]); `None`: constant velocity.
    pub time_constant: Option<f64>,
    /// Fit `spectral_density` and `r` by maximum likelihood on the training tracks.
    pub fit_noise: bool,
    /// The fit uses at most this many training tracks (evenly spread) ...
    pub fit_tracks: usize,
    /// ... and at most this many points of each.
    pub fit_points: usize,
}

impl Default for KfTimeParams {
    fn default() -> Self {
        KfTimeParams {
            derivatives: 2,
            spectral_density: 1.0,
            r: 10.0,
            initial_rate_variance: 100.0,
            time_constant: None,
            fit_noise: true,
            fit_tracks: 400,
            fit_points: 200,
        }
    }
}

impl KfTimeParams {
    fn validate(&self) -> Result<()> {
        if !(2..=3).contains(&self.derivatives) {
            return Err(invalid(
                "derivatives",
                format!(
                    "must be 2 (velocity) or 3 (acceleration), got {}",
                    self.derivatives
                ),
            ));
        }
        for (name, v) in [
            ("spectral_density", self.spectral_density),
            ("r", self.r),
            ("initial_rate_variance", self.initial_rate_variance),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    name,
                    format!("must be finite and positive, got {v}"),
                ));
            }
        }
        if self.fit_tracks == 0 || self.fit_points < 3 {
            return Err(invalid(
                "fit_tracks",
                format!(
                    "the fit needs at least one track of at least 3 points, got {} tracks of {} points",
                    self.fit_tracks, self.fit_points
                ),
            ));
        }
        Ok(())
    }
}

/// The Kalman filter over actual time ("kf-cv", "kf-ca"): see the module documentation.
///
/// ```
/// use trajpred::predictors::{KfTime, KfTimeParams};
/// use trajpred_core::{Predictor, Trajectory};
/// // 2 m/s along x, sampled at irregular times
/// let t = vec![0.0, 1.0, 3.0, 3.5, 5.0, 8.0, 9.0];
/// let x: Vec<f64> = t.iter().map(|t| 2.0 * t).collect();
/// let tr = Trajectory::from_axes(t, vec![x, vec![0.0; 7]])?;
/// let p = KfTime::new(KfTimeParams { fit_noise: false, ..Default::default() })?;
/// // where at t = 10 s and t = 14 s?
/// let f = p.forecast_times(&tr, &[10.0, 14.0])?;
/// assert!((f.step(2)[0] - 28.0).abs() < 1.0);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KfTime {
    params: KfTimeParams,
}

type SizedKf<N, M> = Kf<LinearTransition<f64, N>, LinearObservation<f64, N, M>>;

/// [`KfTime`]'s filter run by time steps.
type TimedKf<N, M> = Timed<f64, N, SizedKf<N, M>, Steps<N, M>>;

/// The filter of each time step of [`KfTime`]: its transition for the step (constant velocity
/// or acceleration, or the damped velocity) and the one observation. A constant-velocity or
/// -acceleration filter is rebuilt in place for a new step (its `F` and `Q` entries
/// rewritten), so the run moves no filter.
struct Steps<N: Dim, M: Dim>
where
    DefaultAllocator: FilterAllocator<N, M>,
{
    layout: KinematicLayout,
    q: f64,
    tau: Option<f64>,
    obs: LinearObservation<f64, N, M>,
}

impl<N: Dim, M: Dim> StepBuilder<f64, SizedKf<N, M>> for Steps<N, M>
where
    DefaultAllocator: FilterAllocator<N, M>,
{
    fn build(&self, dt: f64) -> trajpred_kalman::Result<SizedKf<N, M>> {
        let tr = match self.tau {
            Some(tau) => damped_velocity::<f64, N>(self.layout, dt, self.q, tau)?,
            None => kinematic_continuous::<f64, N>(self.layout, dt, self.q)?,
        };
        Kf::new(tr, self.obs.clone())
    }

    fn rebuild(&self, dt: f64, filter: &mut SizedKf<N, M>) -> trajpred_kalman::Result<()> {
        match self.tau {
            Some(_) => {
                *filter = self.build(dt)?;
                Ok(())
            }
            None => filter
                .update_transition(|tr| kinematic_continuous_in_place(tr, self.layout, dt, self.q)),
        }
    }
}

/// Calls `$self.$method::<N, M>($args)` at the static state and observation sizes of a
/// 1-3 axis constant-velocity or constant-acceleration state (dynamic sizes otherwise), so
/// the filter's matrices live on the stack.
macro_rules! sized {
    ($self:ident, $axes:expr, $method:ident($($arg:expr),*)) => {
        match ($axes, $self.params.derivatives) {
            (1, 2) => $self.$method::<U2, U1>($($arg),*),
            (2, 2) => $self.$method::<U4, U2>($($arg),*),
            (3, 2) => $self.$method::<U6, U3>($($arg),*),
            (1, 3) => $self.$method::<U3, U1>($($arg),*),
            (2, 3) => $self.$method::<U6, U2>($($arg),*),
            (3, 3) => $self.$method::<U9, U3>($($arg),*),
            _ => $self.$method::<Dyn, Dyn>($($arg),*),
        }
    };
}

fn kalman(e: KalmanError) -> Error {
    Error::from_crate("kf-time", e)
}

impl KfTime {
    /// A validated predictor.
    pub fn new(params: KfTimeParams) -> Result<Self> {
        params.validate()?;
        Ok(KfTime { params })
    }

    /// The settings, with the fitted noise after [`Predictor::fit`].
    pub fn params(&self) -> &KfTimeParams {
        &self.params
    }

    fn layout(&self, axes: usize) -> Result<KinematicLayout> {
        KinematicLayout::new(axes, self.params.derivatives, StateOrder::PositionsFirst)
            .map_err(kalman)
    }

    /// The filter after running through `history` with noise `(q, r)`, at state size `N`
    /// and observation size `M` (static for 1-3 axes, see [`sized`]), summing the
    /// log-likelihood of its updates when `likelihood`.
    fn run<N: Dim, M: Dim>(
        &self,
        history: &Trajectory,
        q: f64,
        r: f64,
        likelihood: bool,
    ) -> Result<TimedKf<N, M>>
    where
        DefaultAllocator: FilterAllocator<N, M>,
    {
        let d = history.dim();
        let layout = self.layout(d)?;
        let (nd, md) = (N::from_usize(layout.state_dim()), M::from_usize(d));
        let tau = self.params.time_constant;
        // the observation is the same at every step: built (and checked) once
        let obs = position_observation::<f64, N, M>(layout, r).map_err(kalman)?;
        let make = Steps {
            layout,
            q,
            tau,
            obs,
        };
        let first = history.point(0);
        let mut mean = OVector::<f64, N>::zeros_generic(nd, Const::<1>);
        let mut var = OVector::<f64, N>::from_element_generic(
            nd,
            Const::<1>,
            self.params.initial_rate_variance,
        );
        for a in 0..d {
            mean[a] = first[a];
            var[a] = r;
        }
        let start = Gaussian::new(mean, OMatrix::<f64, N, N>::from_diagonal(&var))?;
        let mut f = Timed::new(make, start);
        if !likelihood {
            f = f.without_log_likelihood();
        }
        let z: Vec<Option<OVector<f64, M>>> = (0..history.len())
            .map(|k| {
                let p = history.point(k);
                Some(OVector::<f64, M>::from_fn_generic(
                    md,
                    Const::<1>,
                    |a, _| p[a],
                ))
            })
            .collect();
        drive_each(&mut f, history.times(), &z, |_, _| Ok(())).map_err(kalman)?;
        Ok(f)
    }

    /// The log-likelihood of one track under `(q, r)` (`-inf` when the filter fails).
    fn track_log_likelihood<N: Dim, M: Dim>(&self, track: &Trajectory, q: f64, r: f64) -> f64
    where
        DefaultAllocator: FilterAllocator<N, M>,
    {
        match self.run::<N, M>(track, q, r, true) {
            Ok(f) => f.log_likelihood().unwrap_or(f64::NEG_INFINITY),
            Err(_) => f64::NEG_INFINITY,
        }
    }

    /// The forecasts `offsets` seconds after the end of `history`.
    fn forecast_sized<N: Dim, M: Dim>(
        &self,
        history: &Trajectory,
        offsets: &[f64],
    ) -> Result<Forecast>
    where
        DefaultAllocator: FilterAllocator<N, M>,
    {
        let (q, r) = (self.params.spectral_density, self.params.r);
        let f = self.run::<N, M>(history, q, r, false)?;
        let states = f.forecast_at(offsets).map_err(kalman)?;
        positions_forecast(&states, history.dim())
    }

    /// The log-likelihood of the tracks under `(q, r)`, summed.
    fn log_likelihood(&self, tracks: &[Trajectory], q: f64, r: f64) -> f64 {
        tracks
            .par_iter()
            .map(|t| sized!(self, t.dim(), track_log_likelihood(t, q, r)))
            .sum()
    }
}

/// Maximises `f` over a box of `(log10 q, log10 r)`: a coarse grid, then three rounds of
/// a finer grid around the best point.
pub(super) fn maximise(
    f: impl Fn(f64, f64) -> f64,
    q: (f64, f64),
    r: (f64, f64),
) -> (f64, f64, f64) {
    let mut best = (f64::NEG_INFINITY, q.0, r.0);
    let (mut qs, mut rs) = ((q.1 - q.0) / 6.0, (r.1 - r.0) / 6.0);
    let (mut qc, mut rc) = ((q.0 + q.1) / 2.0, (r.0 + r.1) / 2.0);
    for _round in 0..4 {
        for i in -3..=3 {
            for j in -3..=3 {
                let (lq, lr) = (qc + f64::from(i) * qs, rc + f64::from(j) * rs);
                let v = f(10f64.powf(lq), 10f64.powf(lr));
                if v > best.0 {
                    best = (v, lq, lr);
                }
            }
        }
        (qc, rc) = (best.1, best.2);
        qs /= 3.0;
        rs /= 3.0;
    }
    (best.0, 10f64.powf(best.1), 10f64.powf(best.2))
}

impl Predictor for KfTime {
    fn name(&self) -> &str {
        if self.params.derivatives == 3 {
            "kf-ca"
        } else {
            "kf-cv"
        }
    }

    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        if !self.params.fit_noise {
            return Ok(());
        }
        let usable: Vec<&Trajectory> = train.iter().filter(|t| t.len() >= 3).collect();
        if usable.is_empty() {
            return Err(Error::Empty {
                what: "training tracks of at least 3 points (to fit the noise)",
            });
        }
        let step = usable.len().div_ceil(self.params.fit_tracks).max(1);
        let tracks: Vec<Trajectory> = usable
            .iter()
            .step_by(step)
            .map(|t| t.slice(0..t.len().min(self.params.fit_points)))
            .collect::<Result<_>>()?;
        let (ll, q, r) = maximise(
            |q, r| self.log_likelihood(&tracks, q, r),
            (-4.0, 3.0),
            (-2.0, 3.0),
        );
        if !ll.is_finite() {
            return Err(Error::invalid_parameter(
                "noise",
                format!(
                    "no spectral density in [1e-4, 1e3] and observation variance in [1e-2, 1e3] \
                     gives {} a finite likelihood on the training tracks (best: {ll})",
                    self.name()
                ),
            ));
        }
        self.params.spectral_density = q;
        self.params.r = r;
        Ok(())
    }

    fn fitted_summary(&self) -> Option<String> {
        Some(format!(
            "q = {:.4e}, r = {:.4e}",
            self.params.spectral_density, self.params.r
        ))
    }

    /// The noise `{"spectral_density": q, "r": r}` (fitted, or as given when `fit_noise` is
    /// off).
    fn fitted_params(&self) -> Result<serde_json::Value> {
        Ok(serde_json::json!({
            "spectral_density": exact(self.params.spectral_density),
            "r": exact(self.params.r),
        }))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let name = self.name().to_string();
        let [q, r] = At::root(&name, params).fields(["spectral_density", "r"])?;
        let (q, r) = (q.f64_min(0.0, true)?, r.f64_min(0.0, true)?);
        self.params.spectral_density = q;
        self.params.r = r;
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        self.forecast_times(history, &forecast_times_on_mean_interval(history, horizon)?)
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        let offsets = offsets_after(history, times)?;
        sized!(self, history.dim(), forecast_sized(history, &offsets))
    }
}
