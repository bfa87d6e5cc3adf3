//! The MKPF experiment (`docs/papers.md` C.2) as functions the runner and the tests share: a flight
//! (observed and true frames, geodetic, `flight`), the choice of the process noise from
//! the kept frames (`models`), and one filter run that keeps one frame in every
//! `keep_every`, updates at each kept frame and predicts every frame in between from the kept
//! ones only. The settings are the spec's parameters (`papers/mkpf.toml`).

pub use super::flight::{
    Flight, FlightChoice, load_flight, local_frame, synthetic_flight, to_geodetic, to_local,
};
use super::models::{Prepared, initial, observation, prepare};
pub use super::models::{choose_noise, ct_model, cv_model, kept_frames};
use crate::spec::MethodSpec;
use crate::{ReproError, Result};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, DimName, OMatrix, U2, U4, U5};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;
use std::time::Instant;
use trajpred_kalman::driver::{self, TimeStepFilter, Timed};
use trajpred_kalman::{
    Ekf, LinearObservation, MerweSigmaPoints, NoisyTransition, TransitionJacobian, Ukf,
};
use trajpred_particle::driver::TimedParticles;
use trajpred_particle::{Mkpf, ParticleAllocator, ParticleFilter, ParticlePrior};

/// The motion model of the filters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// Constant velocity, state `[x, vx, y, vy]`.
    Cv,
    /// Coordinated turn with unknown turn rate, state `[x, vx, y, vy, omega]`.
    Ct,
}

impl Motion {
    /// Short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            Motion::Cv => "CV",
            Motion::Ct => "CT",
        }
    }
}

/// A filter compared in the experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The MKPF (per particle a UKF step then an EKF step give the proposal; eq. 9 weights;
    /// residual resampling every step; the UKF from the particle's last proposal mean and
    /// covariance, `ParticlePrior::ProposalMean`), with this many particles.
    Mkpf(usize),
    /// The MKPF with the crate's `ParticlePrior::Conditioned` (each particle's UKF step
    /// starts from its own transition `N(f(x), Q)`, approximating the optimal proposal)
    /// instead of the last proposal's mean and covariance (the paper's Algorithm 1).
    MkpfConditioned(usize),
    /// The bootstrap particle filter (transition prior as proposal; residual resampling every
    /// step), with this many particles.
    Bootstrap(usize),
    /// The unscented Kalman filter (Merwe sigma points, alpha 1e-3, beta 2, kappa 0).
    Ukf,
    /// The extended Kalman filter.
    Ekf,
}

impl Method {
    /// Short name for tables.
    pub fn name(self) -> String {
        match self {
            Method::Mkpf(_) => "MKPF".into(),
            Method::MkpfConditioned(_) => "MKPF (conditioned prior)".into(),
            Method::Bootstrap(_) => "bootstrap PF".into(),
            Method::Ukf => "UKF".into(),
            Method::Ekf => "EKF".into(),
        }
    }

    /// The particle count, if a particle filter.
    pub fn particles(self) -> Option<usize> {
        match self {
            Method::Mkpf(n) | Method::MkpfConditioned(n) | Method::Bootstrap(n) => Some(n),
            Method::Ukf | Method::Ekf => None,
        }
    }
}

/// The process noise of one motion model: white-noise acceleration and turn-rate spectral
/// densities, with the log-likelihood of the kept frames that selected them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// Acceleration spectral density per axis, m^2/s^3.
    pub accel: f64,
    /// Turn-rate spectral density, rad^2/s^3 (unused by CV).
    pub turn: f64,
    /// Initial turn-rate standard deviation, rad/s (unused by CV).
    pub turn_rate_sd: f64,
    /// UKF log-likelihood of the kept frames under this noise.
    pub log_likelihood: f64,
}

/// One filter run: the predicted and true positions of every evaluated in-between frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// The evaluated frames (indices into the flight).
    pub frames: Vec<usize>,
    /// Predicted `[lat, lon]`, degrees, per evaluated frame.
    pub predicted: Vec<[f64; 2]>,
    /// True `[lat, lon]`, degrees, per evaluated frame.
    pub truth: Vec<[f64; 2]>,
    /// Predicted `[east, north]`, metres in the flight's local frame.
    pub predicted_enu: Vec<[f64; 2]>,
    /// True `[east, north]`, metres.
    pub truth_enu: Vec<[f64; 2]>,
    /// Wall time of the run (filtering and prediction), seconds.
    pub seconds: f64,
}

impl Run {
    /// The paper's relative error `sqrt(mean(((x_hat - x) / x)^2))` over latitude and
    /// longitude of every evaluated frame (a fraction; times 100 for percent).
    pub fn relative_error(&self) -> Result<f64> {
        Ok(trajpred_metrics::relative_rmse(
            &self.predicted,
            &self.truth,
        )?)
    }

    /// Horizontal Euclidean errors in metres, per evaluated frame.
    pub fn errors_m(&self) -> Vec<f64> {
        self.predicted_enu
            .iter()
            .zip(&self.truth_enu)
            .map(|(p, t)| ((p[0] - t[0]).powi(2) + (p[1] - t[1]).powi(2)).sqrt())
            .collect()
    }
}

/// The experiment's settings: the `[params]` of `papers/mkpf.toml`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Setup {
    /// Keep one frame in every `keep_every` (the paper: 50).
    pub keep_every: usize,
    /// Observation noise sd per axis, metres (`R = sd^2 I`): a stated ADS-B accuracy.
    pub position_sd: f64,
    /// Standard deviation of each velocity component in the initial state (m/s).
    pub initial_speed_sd: f64,
    /// Candidate standard deviations of the initial turn rate (rad/s).
    pub turn_rate_sd_grid: Vec<f64>,
    /// Candidate white-noise acceleration spectral densities (m^2/s^3).
    pub accel_grid: Vec<f64>,
    /// Candidate turn-rate noise spectral densities (rad^2/s^3), coordinated turn.
    pub turn_grid: Vec<f64>,
    /// Largest ratio of the position variance to the turn-rate variance of a
    /// coordinated-turn `Q` searched (beyond it the MKPF's Cholesky test of `Q` fails).
    pub max_q_condition: f64,
    /// A real flight is split where two successive fresh reports are further apart (s).
    pub max_gap_s: f64,
    /// Where the synthetic flight is placed (latitude, longitude, degrees).
    pub synthetic_origin: [f64; 2],
    /// The ADS-B file, relative to the `adsb-traffic` folder.
    pub adsb_file: String,
    /// Particles of the MKPF and of the bootstrap PF it is compared with.
    pub particles: usize,
    /// Particles of the larger bootstrap PF.
    pub bootstrap_particles: usize,
    /// Where the flight's east-north errors are placed to compare with the paper's relative
    /// error (latitude, longitude, degrees): in the paper's region.
    pub paper_location: [f64; 2],
    /// The MKPF's particle counts compared (Table 4).
    pub particle_counts: Vec<usize>,
    /// The observation noise sds the filters are run with (Table 5), metres per axis.
    pub observation_sds: Vec<f64>,
}

impl Setup {
    /// The paper's settings, from its spec.
    pub fn paper() -> Result<Setup> {
        crate::Paper::Mkpf.spec()?.params()
    }
}

impl Method {
    /// The method a spec entry names (`registry` and `params.particles`).
    pub fn from_spec(m: &MethodSpec) -> Result<Method> {
        let particles = || -> Result<usize> {
            m.params
                .get("particles")
                .and_then(toml::Value::as_integer)
                .and_then(|n| usize::try_from(n).ok())
                .ok_or_else(|| experiment_err(format!("method {}: no particle count", m.key)))
        };
        Ok(match m.registry.as_deref() {
            Some("mkpf") => Method::Mkpf(particles()?),
            Some("mkpf-conditioned") => Method::MkpfConditioned(particles()?),
            Some("bootstrap-pf") => Method::Bootstrap(particles()?),
            Some("ukf") => Method::Ukf,
            Some("ekf") => Method::Ekf,
            other => {
                return Err(experiment_err(format!(
                    "method {}: unknown kind {other:?}",
                    m.key
                )));
            }
        })
    }
}

pub(super) fn experiment_err(reason: impl Into<String>) -> ReproError {
    ReproError::Experiment {
        experiment: "mkpf".into(),
        reason: reason.into(),
    }
}

/// How to build the transition of a motion model for a time step.
type MakeModel<'a, Tr> = &'a (dyn Fn(f64) -> trajpred_kalman::Result<Tr> + Sync);

/// Runs a filter over the flight through the filter driver: update at each kept frame after
/// the first, predict the frames until the next kept frame from there. The frames before the
/// second kept frame are not evaluated (the filters start from one position and no velocity).
fn drive_kept<D, F>(
    prep: &Prepared,
    times: &[f64],
    filter: &mut F,
) -> Result<(Vec<usize>, Vec<[f64; 2]>)>
where
    D: DimName,
    F: TimeStepFilter<f64, D, U2>,
    ReproError: From<F::Error>,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let kept_times: Vec<f64> = prep.kept.iter().map(|&k| times[k]).collect();
    let kept_z: Vec<Option<nalgebra::Vector2<f64>>> = prep
        .kept
        .iter()
        .map(|&k| {
            Some(nalgebra::Vector2::new(
                prep.observed[k][0],
                prep.observed[k][1],
            ))
        })
        .collect();
    let mut frames = Vec::new();
    let mut predicted = Vec::new();
    driver::drive::<f64, D, U2, F, _>(filter, &kept_times, &kept_z, |i, f| {
        let k = prep.kept[i];
        let end = prep.kept.get(i + 1).copied().unwrap_or(k + 1);
        let offsets: Vec<f64> = (k + 1..end).map(|j| times[j] - times[k]).collect();
        for (j, g) in (k + 1..end).zip(f.forecast_at(&offsets)?) {
            predicted.push([g.mean[0], g.mean[2]]);
            frames.push(j);
        }
        Ok(())
    })
    .map_err(ReproError::from)?;
    Ok((frames, predicted))
}

fn run_generic<D, Tr>(
    prep: &Prepared,
    flight: &Flight,
    setup: &Setup,
    noise: &Noise,
    make: MakeModel<'_, Tr>,
    method: Method,
    seed: u64,
) -> Result<(Vec<usize>, Vec<[f64; 2]>)>
where
    D: DimName,
    Tr: TransitionJacobian<f64, D> + NoisyTransition<f64, D> + Sync,
    DefaultAllocator: ParticleAllocator<f64, D, U2>,
    OMatrix<f64, U2, D>: Send + Sync,
{
    let obs = observation::<D>(setup.position_sd)?;
    let initial = initial::<D>(prep.observed[0], setup, noise);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let times = &flight.times;
    // the particle filters are built for the first interval between kept frames
    let first_dt = match prep.kept.as_slice() {
        [a, b, ..] => times[*b] - times[*a],
        _ => return Ok((Vec::new(), Vec::new())),
    };
    match method {
        Method::Ukf => {
            let make_ukf =
                |dt: f64| Ukf::new::<D, U2>(make(dt)?, obs.clone(), MerweSigmaPoints::default());
            drive_kept(prep, times, &mut Timed::new(make_ukf, initial))
        }
        Method::Ekf => {
            let make_ekf = |dt: f64| Ekf::new::<f64, D, U2>(make(dt)?, obs.clone());
            drive_kept(prep, times, &mut Timed::new(make_ekf, initial))
        }
        Method::Mkpf(particles) | Method::MkpfConditioned(particles) => {
            let prior = match method {
                Method::MkpfConditioned(_) => ParticlePrior::Conditioned,
                _ => ParticlePrior::ProposalMean,
            };
            let mkpf = Mkpf::<f64, D, U2, Tr, LinearObservation<f64, D, U2>>::from_gaussian(
                make(first_dt)?,
                obs,
                &initial,
                particles,
                MerweSigmaPoints::default(),
                &mut rng,
            )?
            .with_particle_prior(prior);
            drive_kept(
                prep,
                times,
                &mut TimedParticles::new(make, mkpf, first_dt, rng),
            )
        }
        Method::Bootstrap(particles) => {
            let pf =
                ParticleFilter::<f64, D, U2, Tr, LinearObservation<f64, D, U2>>::from_gaussian(
                    make(first_dt)?,
                    obs,
                    &initial,
                    particles,
                    &mut rng,
                )?;
            drive_kept(
                prep,
                times,
                &mut TimedParticles::new(make, pf, first_dt, rng),
            )
        }
    }
}

/// Runs one method with one motion model and noise on the flight (the seed drives the particle
/// filters' random numbers; the Kalman filters ignore it).
pub fn run_method(
    flight: &Flight,
    setup: &Setup,
    motion: Motion,
    noise: &Noise,
    method: Method,
    seed: u64,
) -> Result<Run> {
    let start = Instant::now();
    let prep = prepare(flight, setup)?;
    let (frames, predicted_enu) = match motion {
        Motion::Cv => {
            let make = |dt: f64| cv_model(noise, dt);
            run_generic::<U4, _>(&prep, flight, setup, noise, &make, method, seed)?
        }
        Motion::Ct => {
            let make = |dt: f64| ct_model(noise, dt);
            run_generic::<U5, _>(&prep, flight, setup, noise, &make, method, seed)?
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    let predicted = predicted_enu
        .iter()
        .map(|p| to_geodetic(&prep.frame, *p))
        .collect();
    Ok(Run {
        truth: frames.iter().map(|&j| flight.truth[j]).collect(),
        truth_enu: frames.iter().map(|&j| prep.truth[j]).collect(),
        frames,
        predicted,
        predicted_enu,
        seconds,
    })
}
