//! The MKPF experiment (`docs/papers.md` C.2) as functions the runner and the tests share: a flight
//! (observed and true frames, geodetic), the choice of the process noise from the kept frames,
//! and one filter run that keeps one frame in every `keep_every`, updates at each kept frame
//! and predicts every frame in between from the kept ones only.

use crate::{ReproError, Result};
use nalgebra::allocator::Allocator;
use nalgebra::{
    DefaultAllocator, DimName, Matrix2, Matrix4, Matrix5, OMatrix, OVector, U2, U4, U5,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::path::Path;
use std::time::Instant;
use trajpred_core::Gaussian;
use trajpred_data::geodesy::{Enu, Geodetic, LocalFrame};
use trajpred_data::{LoadOptions, Projection, adsb};
use trajpred_kalman::driver::{self, TimeStepFilter, Timed};
use trajpred_kalman::{
    CoordinatedTurn, Ekf, Filter, LinearObservation, LinearTransition, MerweSigmaPoints,
    NoisyTransition, Transition, TransitionJacobian, Ukf,
};
use trajpred_particle::driver::TimedParticles;
use trajpred_particle::{Mkpf, ParticleFilter, ParticlePrior};

/// ADS-B horizontal position noise, standard deviation per axis in metres (`R = sd^2 I`): a
/// stated physical value (NACp 8 bounds the 95% horizontal error by 30 m), not fitted.
pub const POSITION_SD_M: f64 = 15.0;
/// Standard deviation of each velocity component in the initial state (m/s): vague, of the
/// order of an airliner's speed (the filters start from one position and no velocity).
pub const INITIAL_SPEED_SD: f64 = 150.0;
/// Candidate standard deviations of the turn rate in the initial state (rad/s), chosen with
/// the process noise by the likelihood of the kept frames: from a quarter of a degree per
/// second to about a standard-rate turn (3 degrees per second). Wide priors put weight on
/// turn rates that alias over the time between kept frames.
pub const TURN_RATE_SD_GRID: [f64; 4] = [0.005, 0.01, 0.02, 0.05];
/// Candidate white-noise acceleration spectral densities (m^2/s^3) searched by likelihood.
pub const ACCEL_GRID: [f64; 11] = [
    1e-3, 3e-3, 1e-2, 3e-2, 1e-1, 3e-1, 1.0, 3.0, 10.0, 30.0, 100.0,
];
/// Candidate turn-rate noise spectral densities (rad^2/s^3) for the coordinated turn.
pub const TURN_GRID: [f64; 5] = [1e-9, 1e-8, 1e-7, 1e-6, 1e-5];
/// Largest ratio of the position variance to the turn-rate variance of a coordinated-turn
/// `Q` searched (beyond it the MKPF's Cholesky test of `Q` fails).
pub const MAX_Q_CONDITION: f64 = 1e10;
/// A real flight is split where two successive fresh position reports are further apart.
pub const MAX_GAP_S: f64 = 10.0;
/// Where the synthetic flight is placed on the Earth (latitude, longitude in degrees): near
/// Paris, like the real flights of `collections/quickstart`, so both relative errors divide by
/// similar coordinates.
pub const SYNTHETIC_ORIGIN: (f64, f64) = (48.85, 2.35);

/// A flight: per frame the time, the observed position and the true position, both as
/// geodetic `[latitude, longitude]` in degrees. For real data the two are the same reports;
/// the synthetic flight observes the truth with noise.
#[derive(Debug, Clone, PartialEq)]
pub struct Flight {
    /// What it is (file and flight, or the synthetic scenario).
    pub name: String,
    /// Seconds (from the first frame for synthetic data, Unix time for real data).
    pub times: Vec<f64>,
    /// Observed `[lat, lon]`, degrees.
    pub observed: Vec<[f64; 2]>,
    /// True `[lat, lon]`, degrees (what the predictions are compared with).
    pub truth: Vec<[f64; 2]>,
}

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
    /// residual resampling every step), with this many particles.
    Mkpf(usize),
    /// The MKPF with the crate's `ParticlePrior::Conditioned` (each particle's UKF step
    /// starts from its own transition `N(f(x), Q)`, approximating the optimal proposal)
    /// instead of the carried covariance of the paper's Algorithm 1.
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

/// The experiment's fixed settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    /// Keep one frame in every `keep_every` (the paper: 50).
    pub keep_every: usize,
    /// Observation noise sd per axis, metres.
    pub position_sd: f64,
}

impl Default for Setup {
    fn default() -> Self {
        Setup {
            keep_every: 50,
            position_sd: POSITION_SD_M,
        }
    }
}

fn experiment_err(reason: impl Into<String>) -> ReproError {
    ReproError::Experiment {
        experiment: "mkpf".into(),
        reason: reason.into(),
    }
}

/// The flight's local frame: east-north-up at the first observed point, height 0.
pub fn local_frame(flight: &Flight) -> Result<LocalFrame> {
    let first = flight
        .observed
        .first()
        .ok_or_else(|| experiment_err("empty flight"))?;
    Ok(LocalFrame::new(Geodetic::new(first[0], first[1], 0.0)?)?)
}

/// `[lat, lon]` at height 0 to local `[east, north]` metres.
pub fn to_local(frame: &LocalFrame, p: [f64; 2]) -> Result<[f64; 2]> {
    let e = frame.to_enu(&Geodetic::new(p[0], p[1], 0.0)?);
    Ok([e.east, e.north])
}

/// Local `[east, north]` metres back to `[lat, lon]` at height 0: the `up` coordinate of the
/// point at height 0 is found by fixed-point iteration (the tangent plane drops below the
/// ellipsoid with distance), so a round trip through [`to_local`] returns the input.
pub fn to_geodetic(frame: &LocalFrame, p: [f64; 2]) -> [f64; 2] {
    let mut up = 0.0;
    let mut g = frame.to_geodetic(&Enu {
        east: p[0],
        north: p[1],
        up,
    });
    for _ in 0..4 {
        let on_ellipsoid = Geodetic { alt_m: 0.0, ..g };
        up = frame.to_enu(&on_ellipsoid).up;
        g = frame.to_geodetic(&Enu {
            east: p[0],
            north: p[1],
            up,
        });
    }
    [g.lat_deg, g.lon_deg]
}

/// Indices of the kept frames: 0, k, 2k, ... (the flight is cut after the last kept frame).
pub fn kept_frames(len: usize, keep_every: usize) -> Vec<usize> {
    (0..len).step_by(keep_every.max(1)).collect()
}

/// Continuous white-noise acceleration block `q [[T^3/3, T^2/2], [T^2/2, T]]` (positive
/// definite, as the MKPF's transition density needs).
fn cwna(q: f64, dt: f64) -> [[f64; 2]; 2] {
    [
        [q * dt.powi(3) / 3.0, q * dt * dt / 2.0],
        [q * dt * dt / 2.0, q * dt],
    ]
}

/// The constant-velocity transition `[x, vx, y, vy]` over `dt` seconds.
pub fn cv_model(noise: &Noise, dt: f64) -> trajpred_kalman::Result<LinearTransition<f64, U4>> {
    let b = cwna(noise.accel, dt);
    let mut f = Matrix4::identity();
    let mut q = Matrix4::zeros();
    for o in [0usize, 2] {
        f[(o, o + 1)] = dt;
        for i in 0..2 {
            for j in 0..2 {
                q[(o + i, o + j)] = b[i][j];
            }
        }
    }
    LinearTransition::new(f, q)
}

/// The coordinated-turn transition `[x, vx, y, vy, omega]` over `dt` seconds.
pub fn ct_model(noise: &Noise, dt: f64) -> trajpred_kalman::Result<CoordinatedTurn<f64>> {
    let b = cwna(noise.accel, dt);
    let mut q = Matrix5::zeros();
    for o in [0usize, 2] {
        for i in 0..2 {
            for j in 0..2 {
                q[(o + i, o + j)] = b[i][j];
            }
        }
    }
    q[(4, 4)] = noise.turn * dt;
    CoordinatedTurn::with_process_noise(dt, q)
}

fn observation<D: DimName>(sd: f64) -> Result<LinearObservation<f64, D, U2>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<U2, D>,
{
    let mut h = OMatrix::<f64, U2, D>::zeros();
    h[(0, 0)] = 1.0;
    h[(1, 2)] = 1.0;
    Ok(LinearObservation::<f64, D, U2>::new(
        h,
        Matrix2::identity() * (sd * sd),
    )?)
}

fn initial<D: DimName>(z: [f64; 2], setup: &Setup, noise: &Noise) -> Gaussian<f64, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let mut mean = OVector::<f64, D>::zeros();
    mean[0] = z[0];
    mean[2] = z[1];
    let mut cov = OMatrix::<f64, D, D>::zeros();
    let sd = setup.position_sd;
    let v = INITIAL_SPEED_SD * INITIAL_SPEED_SD;
    for (i, var) in [sd * sd, v, sd * sd, v].into_iter().enumerate() {
        cov[(i, i)] = var;
    }
    if D::dim() > 4 {
        cov[(4, 4)] = noise.turn_rate_sd * noise.turn_rate_sd;
    }
    Gaussian {
        mean,
        covariance: cov,
    }
}

/// The flight in local metres with its kept frames.
struct Prepared {
    frame: LocalFrame,
    observed: Vec<[f64; 2]>,
    truth: Vec<[f64; 2]>,
    kept: Vec<usize>,
}

fn prepare(flight: &Flight, setup: &Setup) -> Result<Prepared> {
    let n = flight.times.len();
    if n != flight.observed.len() || n != flight.truth.len() {
        return Err(experiment_err(
            "flight: times, observed and truth differ in length",
        ));
    }
    let kept = kept_frames(n, setup.keep_every);
    if kept.len() < 3 {
        return Err(experiment_err(format!(
            "flight {} has {n} frames: fewer than 3 kept frames at one in {}",
            flight.name, setup.keep_every
        )));
    }
    let frame = local_frame(flight)?;
    let observed = flight
        .observed
        .iter()
        .map(|p| to_local(&frame, *p))
        .collect::<Result<Vec<_>>>()?;
    let truth = flight
        .truth
        .iter()
        .map(|p| to_local(&frame, *p))
        .collect::<Result<Vec<_>>>()?;
    Ok(Prepared {
        frame,
        observed,
        truth,
        kept,
    })
}

/// The best piece so far: length, flight id, times, positions, repeated reports dropped.
type Piece = (usize, String, Vec<f64>, Vec<[f64; 2]>, usize);

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
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<U2, D> + Allocator<D, U2>,
    OVector<f64, D>: Send + Sync,
    OMatrix<f64, D, D>: Send + Sync,
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
                _ => ParticlePrior::Carried,
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

/// The UKF log-likelihood of the kept frames (after the first) under `noise`.
fn kept_log_likelihood(
    prep: &Prepared,
    flight: &Flight,
    setup: &Setup,
    motion: Motion,
    noise: &Noise,
) -> Result<f64> {
    fn ll<D, Tr>(
        prep: &Prepared,
        times: &[f64],
        setup: &Setup,
        noise: &Noise,
        make: &dyn Fn(f64) -> trajpred_kalman::Result<Tr>,
    ) -> Result<f64>
    where
        D: DimName,
        Tr: Transition<f64, D>,
        DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<U2, D> + Allocator<D, U2>,
    {
        let obs = observation::<D>(setup.position_sd)?;
        let mut state = initial::<D>(prep.observed[0], setup, noise);
        let mut total = 0.0;
        for w in prep.kept.windows(2) {
            let tr = make(times[w[1]] - times[w[0]])?;
            let z = prep.observed[w[1]];
            let f = Ukf::new::<D, U2>(&tr, &obs, MerweSigmaPoints::default())?;
            let step =
                Filter::<f64, D, U2>::step(&f, &state, Some(&nalgebra::Vector2::new(z[0], z[1])))?;
            total += step.log_likelihood();
            state = step.posterior().clone();
        }
        Ok(total)
    }
    match motion {
        Motion::Cv => ll::<U4, _>(prep, &flight.times, setup, noise, &|dt| cv_model(noise, dt)),
        Motion::Ct => ll::<U5, _>(prep, &flight.times, setup, noise, &|dt| ct_model(noise, dt)),
    }
}

/// The process noise of `motion` with the highest UKF log-likelihood of the kept frames over
/// [`ACCEL_GRID`] (and [`TURN_GRID`] for the coordinated turn). Only the kept frames enter:
/// the compared in-between frames are never used to choose it. Ties keep the first.
pub fn choose_noise(flight: &Flight, setup: &Setup, motion: Motion) -> Result<Noise> {
    let prep = prepare(flight, setup)?;
    let (turns, priors): (&[f64], &[f64]) = match motion {
        Motion::Cv => (&[0.0], &[0.0]),
        Motion::Ct => (&TURN_GRID, &TURN_RATE_SD_GRID),
    };
    let max_dt = prep
        .kept
        .windows(2)
        .map(|w| flight.times[w[1]] - flight.times[w[0]])
        .fold(0.0, f64::max);
    let mut best: Option<Noise> = None;
    for &accel in &ACCEL_GRID {
        for (&turn, &turn_rate_sd) in turns
            .iter()
            .flat_map(|t| priors.iter().map(move |p| (t, p)))
        {
            let mut noise = Noise {
                accel,
                turn,
                turn_rate_sd,
                log_likelihood: f64::NEG_INFINITY,
            };
            // a coordinated-turn Q whose turn-rate variance is negligible beside the position
            // variance (condition number over MAX_Q_CONDITION at the longest step) is skipped:
            // the MKPF's transition density needs a numerically positive definite Q
            if motion == Motion::Ct && accel * max_dt * max_dt / 3.0 > MAX_Q_CONDITION * turn {
                continue;
            }
            // a grid point where the filter fails numerically is skipped
            if let Ok(ll) = kept_log_likelihood(&prep, flight, setup, motion, &noise)
                && ll.is_finite()
            {
                noise.log_likelihood = ll;
                if best.is_none_or(|b| ll > b.log_likelihood) {
                    best = Some(noise);
                }
            }
        }
    }
    best.ok_or_else(|| {
        experiment_err(format!(
            "no {} noise gives a finite likelihood",
            motion.name()
        ))
    })
}

/// The synthetic flight: a coordinated-turn target at `speed` m/s, 1 s frames, straight legs
/// and turns of both signs, observed with Gaussian noise of `sd` metres per axis, placed at
/// [`SYNTHETIC_ORIGIN`]. `quick` halves its length.
pub fn synthetic_flight(seed: u64, quick: bool, sd: f64) -> Result<Flight> {
    // (duration s, turn rate deg/s)
    let legs: &[(usize, f64)] = &[
        (200, 0.0),
        (60, 3.0),
        (150, 0.0),
        (120, -1.5),
        (100, 0.0),
        (90, 2.0),
        (180, 0.0),
        (45, -3.0),
        (106, 0.0),
    ];
    let speed = 120.0;
    let total: usize = legs.iter().map(|l| l.0).sum();
    let len = if quick { total / 2 + 1 } else { total + 1 };
    let origin = Geodetic::new(SYNTHETIC_ORIGIN.0, SYNTHETIC_ORIGIN.1, 0.0)?;
    let frame = LocalFrame::new(origin)?;
    let noise = Normal::new(0.0, sd).map_err(|e| experiment_err(e.to_string()))?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed_f11e);
    let (mut x, mut y, mut heading) = (-20_000.0f64, -5_000.0f64, 0.3f64);
    let mut rates = legs
        .iter()
        .flat_map(|&(n, r)| std::iter::repeat_n(r.to_radians(), n));
    let mut flight = Flight {
        name: format!(
            "synthetic coordinated-turn flight, {speed} m/s, 1 s frames, noise sd {sd} m"
        ),
        times: Vec::with_capacity(len),
        observed: Vec::with_capacity(len),
        truth: Vec::with_capacity(len),
    };
    for k in 0..len {
        let obs = [x + noise.sample(&mut rng), y + noise.sample(&mut rng)];
        flight.times.push(k as f64);
        flight.truth.push(to_geodetic(&frame, [x, y]));
        flight.observed.push(to_geodetic(&frame, obs));
        let w = rates.next().unwrap_or(0.0);
        // exact coordinated turn over 1 s
        let (vx, vy) = (speed * heading.cos(), speed * heading.sin());
        if w.abs() < 1e-12 {
            x += vx;
            y += vy;
        } else {
            let (s, c) = w.sin_cos();
            x += s / w * vx - (1.0 - c) / w * vy;
            y += (1.0 - c) / w * vx + s / w * vy;
        }
        heading += w;
    }
    Ok(flight)
}

/// How the real flight was chosen, for the results.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightChoice {
    /// The flight.
    pub flight: Flight,
    /// File, flight id, counts and times, in words.
    pub description: String,
}

/// The ADS-B file the real experiment reads, relative to the `adsb-traffic` folder.
pub const ADSB_FILE: &str = "samples/collections/quickstart.json.gz";

/// Loads [`ADSB_FILE`] and picks the flight by a fixed rule: in every `(icao24, callsign)`
/// flight, drop reports that repeat the previous position (OpenSky re-sends the last
/// position when no new one came), split where fresh reports are more than [`MAX_GAP_S`]
/// apart, and take the longest piece (ties: the smallest id). `max_frames` cuts it (quick
/// runs).
pub fn load_flight(dir: &Path, max_frames: Option<usize>) -> Result<FlightChoice> {
    let path = dir.join(ADSB_FILE);
    let opts = LoadOptions {
        projection: Projection::Geodetic,
        altitude: false,
        ..LoadOptions::default()
    };
    let (tracks, _report) = adsb::load_file(&path, &opts)?;
    let mut best: Option<Piece> = None;
    for track in &tracks {
        let t = track.trajectory.times();
        let (lat, lon) = (track.trajectory.axis(0), track.trajectory.axis(1));
        let mut pieces: Vec<(Vec<f64>, Vec<[f64; 2]>)> = vec![(Vec::new(), Vec::new())];
        let mut repeated = 0usize;
        for i in 0..t.len() {
            let p = [lat[i], lon[i]];
            let Some(cur) = pieces.last_mut() else {
                continue;
            };
            if let (Some(lt), Some(lp)) = (cur.0.last(), cur.1.last()) {
                if *lp == p {
                    repeated += 1;
                    continue;
                }
                if t[i] - lt > MAX_GAP_S {
                    pieces.push((Vec::new(), Vec::new()));
                }
            }
            if let Some(cur) = pieces.last_mut() {
                cur.0.push(t[i]);
                cur.1.push(p);
            }
        }
        for (times, pts) in pieces {
            let better = match &best {
                None => true,
                Some((n, id, ..)) => pts.len() > *n || (pts.len() == *n && track.id < *id),
            };
            if better && !pts.is_empty() {
                best = Some((pts.len(), track.id.clone(), times, pts, repeated));
            }
        }
    }
    let (_, id, mut times, mut pts, repeated) =
        best.ok_or_else(|| experiment_err(format!("{}: no flight", path.display())))?;
    let full = pts.len();
    if let Some(m) = max_frames {
        times.truncate(m);
        pts.truncate(m);
    }
    let description = format!(
        "{} (adsb-traffic, OpenSky Network via the traffic package; not redistributed): flight \
         {id}, the longest run of fresh position reports in the file ({full} reports, gaps at \
         most {MAX_GAP_S} s; {repeated} repeated positions of that flight dropped); {} frames \
         used, Unix time {:.0} to {:.0}",
        path.display(),
        pts.len(),
        times.first().copied().unwrap_or(f64::NAN),
        times.last().copied().unwrap_or(f64::NAN),
    );
    Ok(FlightChoice {
        flight: Flight {
            name: format!("ADS-B flight {id}"),
            times,
            truth: pts.clone(),
            observed: pts,
        },
        description,
    })
}
