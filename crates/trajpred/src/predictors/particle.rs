//! Particle-filter predictors (`docs/papers.md` C): the bootstrap particle filter and the MKPF
//! (UKF + EKF proposal), with a constant-velocity model and position observations.

use super::{invalid, positions_forecast, step_interval};
use nalgebra::{DMatrix, DVector, Dyn};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use trajpred_core::{
    Error, Forecast, Gaussian, Predictor, Result, Trajectory, check_forecast_args,
};
use trajpred_kalman::motion::{StateOrder, constant_velocity};
use trajpred_kalman::{LinearObservation, LinearTransition, MerweSigmaPoints};
use trajpred_particle::{Mkpf, ParticleFilter, ParticleFiltering};

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
    /// White-noise acceleration variance of the constant-velocity model (m^2/s^4).
    pub accel_var: f64,
    /// Observation noise variance per axis (m^2).
    pub obs_var: f64,
    /// Initial covariance `p0 I` around `[z_0, 0]`.
    pub p0: f64,
    /// Seed: every forecast restarts its generator from it, so the same history gives the
    /// same forecast.
    pub seed: u64,
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
            accel_var: 1.0,
            obs_var: 10.0,
            p0: 100.0,
            seed: 0,
        }
    }
}

/// A particle filter run through the history, then its particle cloud pushed `horizon` steps
/// ahead; the forecast is the cloud's mean and covariance of the positions.
///
/// The CV process noise is the discrete white-noise `Q` plus `1e-6 accel_var I`, so that `Q`
/// is positive definite (the MKPF's transition density needs it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParticlePredictor {
    params: ParticleParams,
}

impl ParticlePredictor {
    /// A validated predictor.
    pub fn new(params: ParticleParams) -> Result<Self> {
        if params.particles == 0 {
            return Err(invalid("particles", "need at least one particle"));
        }
        for (name, v) in [
            ("accel_var", params.accel_var),
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
}

fn particle_error(method: &'static str) -> impl Fn(trajpred_particle::ParticleError) -> Error {
    move |e| Error::method(method, e)
}

/// Filters `z` with a freshly built particle filter, then forecasts `horizon` steps.
fn run<F: ParticleFiltering<f64, Dyn, Dyn>>(
    filter: trajpred_particle::Result<F>,
    z: &[Option<DVector<f64>>],
    horizon: usize,
    rng: &mut ChaCha8Rng,
) -> trajpred_particle::Result<Vec<Gaussian<f64, Dyn>>> {
    let mut pf = filter?;
    pf.filter(z, rng)?;
    pf.forecast(horizon, rng)
}

fn kalman_error(method: &'static str) -> impl Fn(trajpred_kalman::KalmanError) -> Error {
    move |e| Error::method(method, e)
}

impl Predictor for ParticlePredictor {
    fn name(&self) -> &str {
        match self.params.kind {
            ParticleKind::Bootstrap => "pf",
            ParticleKind::Mkpf => "mkpf",
        }
    }

    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(())
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let method = match self.params.kind {
            ParticleKind::Bootstrap => "pf",
            ParticleKind::Mkpf => "mkpf",
        };
        let p = &self.params;
        let d = history.dim();
        let n = 2 * d;
        let dt = step_interval(history, history.len());
        let cv = constant_velocity::<f64, Dyn>(d, dt, p.accel_var, StateOrder::PositionsFirst)
            .map_err(kalman_error(method))?;
        let q = cv.q() + DMatrix::identity(n, n) * (1e-6 * p.accel_var);
        let transition = LinearTransition::new(cv.f().clone(), q).map_err(kalman_error(method))?;
        let h = DMatrix::from_fn(d, n, |i, j| if i == j { 1.0 } else { 0.0 });
        let observation = LinearObservation::new(h, DMatrix::identity(d, d) * p.obs_var)
            .map_err(kalman_error(method))?;
        let z: Vec<Option<DVector<f64>>> = history
            .points()
            .map(|pt| Some(DVector::from_column_slice(&pt)))
            .collect();
        let mut x0 = DVector::zeros(n);
        for a in 0..d {
            x0[a] = history.axis(a)[0];
        }
        let initial = Gaussian::new(x0, DMatrix::identity(n, n) * p.p0)?;
        let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
        let states = match p.kind {
            ParticleKind::Bootstrap => run(
                ParticleFilter::from_gaussian(
                    transition,
                    observation,
                    &initial,
                    p.particles,
                    &mut rng,
                ),
                &z[1..],
                horizon,
                &mut rng,
            ),
            ParticleKind::Mkpf => run(
                Mkpf::from_gaussian(
                    transition,
                    observation,
                    &initial,
                    p.particles,
                    MerweSigmaPoints::default(),
                    &mut rng,
                ),
                &z[1..],
                horizon,
                &mut rng,
            ),
        }
        .map_err(particle_error(method))?;
        positions_forecast(&states, d)
    }

    fn min_history(&self) -> usize {
        2
    }
}
