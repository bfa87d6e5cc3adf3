//! Particle-filter predictors (`docs/papers.md` C): the bootstrap particle filter and the MKPF
//! (UKF + EKF proposal), with a constant-velocity model and position observations.

use super::fitted::{At, exact};
use super::{KfTime, KfTimeParams, invalid, positions_forecast, step_interval};
use nalgebra::{DMatrix, DVector, Dyn};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use trajpred_core::{
    Error, Forecast, Gaussian, Predictor, Result, Trajectory, check_forecast_args,
};
use trajpred_kalman::driver::{TimeStepFilter, drive_each};
use trajpred_kalman::motion::{KinematicLayout, StateOrder, kinematic_continuous};
use trajpred_kalman::{LinearObservation, MerweSigmaPoints};
use trajpred_particle::driver::TimedParticles;
use trajpred_particle::{Mkpf, ParticleFilter};

/// Which particle filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ParticleKind {
    /// Bootstrap: propose from the transition.
    Bootstrap,
    /// MKPF: per particle a UKF step then an EKF step give the proposal (`docs/papers.md` C.1).
    Mkpf,
}

/// Parameters of [`ParticlePredictor`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ParticleParams {
    /// Which filter.
    pub kind: ParticleKind,
    /// Number of particles.
    pub particles: usize,
    /// Spectral density of the continuous white-noise acceleration of the constant-velocity
    /// model (m^2/s^3): `Q` follows each interval of the track
    /// ([`trajpred_kalman::motion::kinematic_continuous`]).
    pub accel_density: f64,
    /// Observation noise variance per axis (m^2).
    pub obs_var: f64,
    /// Initial covariance `p0 I` around `[z_0, 0]`.
    pub p0: f64,
    /// Seed: every forecast restarts its generator from it, so the same history gives the
    /// same forecast.
    pub seed: u64,
    /// At [`Predictor::fit`], replace `accel_density` and `obs_var` by the maximum-likelihood
    /// fit of the same constant-velocity model on the training tracks (`kf-cv`'s fit,
    /// [`KfTime`](super::KfTime); the filter's model and its noise are the Kalman filter's).
    /// Off by default: on T-Drive's 300 s steps the fitted noise made both filters far worse
    /// than the defaults (`docs/particle.md`).
    pub fit_noise: bool,
}

impl ParticleParams {
    /// Defaults for metre-scale tracks: 500 bootstrap particles or 50 MKPF particles.
    pub fn new(kind: ParticleKind) -> Self {
        ParticleParams {
            kind,
            particles: match kind {
                ParticleKind::Bootstrap => 500,
                ParticleKind::Mkpf => 50,
            },
            accel_density: 1.0,
            obs_var: 10.0,
            p0: 100.0,
            seed: 0,
            fit_noise: false,
        }
    }
}

/// A particle filter run through the history at its actual times (the filter driver,
/// [`trajpred_particle::driver::TimedParticles`]), then asked for the positions at the
/// forecast times: the mean of the particles moved there without noise, and their spread plus
/// that interval's `Q`.
///
/// The process noise is the continuous white-noise acceleration model, so `Q` is positive
/// definite for every interval (the MKPF's transition density needs it) and grows with the
/// interval: a 300 s T-Drive step gets the noise of 300 s, not of one step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParticlePredictor {
    params: ParticleParams,
}

impl ParticlePredictor {
    /// A validated predictor.
    pub fn new(params: ParticleParams) -> Result<Self> {
        if params.particles == 0 {
            return Err(invalid("particles", "need at least one particle, got 0"));
        }
        for (name, v) in [
            ("accel_density", params.accel_density),
            ("obs_var", params.obs_var),
            ("p0", params.p0),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    name,
                    format!("must be finite and positive, got {v}"),
                ));
            }
        }
        Ok(ParticlePredictor { params })
    }

    fn method(&self) -> &'static str {
        match self.params.kind {
            ParticleKind::Bootstrap => "pf",
            ParticleKind::Mkpf => "mkpf",
        }
    }
}

/// Runs a filter through the history by the driver, then forecasts at `offsets`.
fn run<F: TimeStepFilter<f64, Dyn, Dyn>>(
    filter: &mut F,
    times: &[f64],
    z: &[Option<DVector<f64>>],
    offsets: &[f64],
) -> std::result::Result<Vec<Gaussian<f64, Dyn>>, F::Error> {
    drive_each(filter, times, z, |_, _| Ok(()))?;
    filter.forecast_at(offsets)
}

impl Predictor for ParticlePredictor {
    fn name(&self) -> &str {
        self.method()
    }

    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        if !self.params.fit_noise {
            return Ok(());
        }
        let mut kf = KfTime::new(KfTimeParams {
            derivatives: 2,
            ..Default::default()
        })?;
        kf.fit(train)?;
        self.params.accel_density = kf.params().spectral_density;
        self.params.obs_var = kf.params().r;
        Ok(())
    }

    fn fitted_summary(&self) -> Option<String> {
        self.params.fit_noise.then(|| {
            format!(
                "accel_density = {:.4e} m^2/s^3, obs_var = {:.4e} m^2 (kf-cv's maximum-likelihood fit)",
                self.params.accel_density, self.params.obs_var
            )
        })
    }

    /// `{"accel_density", "obs_var"}`: the noise the filter runs with (fitted or given).
    fn fitted_params(&self) -> Result<serde_json::Value> {
        Ok(serde_json::json!({
            "accel_density": exact(self.params.accel_density),
            "obs_var": exact(self.params.obs_var),
        }))
    }

    fn load_fitted_params(&mut self, params: &serde_json::Value) -> Result<()> {
        let root = At::root(self.method(), params);
        let [q, r] = root.fields(["accel_density", "obs_var"])?;
        let (q, r) = (q.f64_min(0.0, true)?, r.f64_min(0.0, true)?);
        self.params.accel_density = q;
        self.params.obs_var = r;
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let dt = step_interval(history, history.len());
        let last = history.times()[history.len() - 1];
        let times: Vec<f64> = (1..=horizon).map(|k| last + dt * k as f64).collect();
        self.forecast_times(history, &times)
    }

    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        check_forecast_args(history, times.len(), self.min_history())?;
        let method = self.method();
        let kalman = |e: trajpred_kalman::KalmanError| Error::from_crate(method, e);
        let particle = |e: trajpred_particle::ParticleError| Error::from_crate(method, e);
        let p = &self.params;
        let d = history.dim();
        let n = 2 * d;
        let layout = KinematicLayout::new(d, 2, StateOrder::PositionsFirst).map_err(kalman)?;
        let density = p.accel_density;
        let make = move |dt: f64| kinematic_continuous::<f64, Dyn>(layout, dt, density);
        let h = DMatrix::from_fn(d, n, |i, j| if i == j { 1.0 } else { 0.0 });
        let observation =
            LinearObservation::new(h, DMatrix::identity(d, d) * p.obs_var).map_err(kalman)?;
        let z: Vec<Option<DVector<f64>>> = history
            .points()
            .map(|pt| Some(DVector::from_column_slice(&pt)))
            .collect();
        let mut x0 = DVector::zeros(n);
        for a in 0..d {
            x0[a] = history.axis(a)[0];
        }
        let initial = Gaussian::new(x0, DMatrix::identity(n, n) * p.p0)?;
        let t = history.times();
        let last = t[t.len() - 1];
        let offsets: Vec<f64> = times.iter().map(|&x| x - last).collect();
        let first_dt = t[1] - t[0];
        let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
        let states = match p.kind {
            ParticleKind::Bootstrap => {
                let pf = ParticleFilter::from_gaussian(
                    make(first_dt).map_err(kalman)?,
                    observation,
                    &initial,
                    p.particles,
                    &mut rng,
                )
                .map_err(particle)?;
                run(
                    &mut TimedParticles::new(make, pf, first_dt, rng),
                    t,
                    &z,
                    &offsets,
                )
            }
            ParticleKind::Mkpf => {
                let mkpf = Mkpf::from_gaussian(
                    make(first_dt).map_err(kalman)?,
                    observation,
                    &initial,
                    p.particles,
                    MerweSigmaPoints::default(),
                    &mut rng,
                )
                .map_err(particle)?;
                run(
                    &mut TimedParticles::new(make, mkpf, first_dt, rng),
                    t,
                    &z,
                    &offsets,
                )
            }
        }
        .map_err(particle)?;
        positions_forecast(&states, d)
    }

    fn min_history(&self) -> usize {
        2
    }
}
