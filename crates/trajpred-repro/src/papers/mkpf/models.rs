//! The filters' models and the choice of the process noise from the kept frames: the
//! constant-velocity and coordinated-turn transitions, the observation, the initial state,
//! and the UKF likelihood of the kept frames that selects the noise.

use super::experiment::{Motion, Noise, Setup, experiment_err};
use super::flight::{Flight, local_frame, to_local};
use crate::Result;
use nalgebra::allocator::Allocator;
use nalgebra::{
    DefaultAllocator, DimName, Matrix2, Matrix4, Matrix5, OMatrix, OVector, U2, U4, U5,
};
use trajpred_core::Gaussian;
use trajpred_data::geodesy::LocalFrame;
use trajpred_kalman::{
    CoordinatedTurn, Filter, LinearObservation, LinearTransition, MerweSigmaPoints, Transition, Ukf,
};

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

pub(super) fn observation<D: DimName>(sd: f64) -> Result<LinearObservation<f64, D, U2>>
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

pub(super) fn initial<D: DimName>(z: [f64; 2], setup: &Setup, noise: &Noise) -> Gaussian<f64, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let mut mean = OVector::<f64, D>::zeros();
    mean[0] = z[0];
    mean[2] = z[1];
    let mut cov = OMatrix::<f64, D, D>::zeros();
    let sd = setup.position_sd;
    let v = setup.initial_speed_sd * setup.initial_speed_sd;
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
pub(super) struct Prepared {
    pub(super) frame: LocalFrame,
    pub(super) observed: Vec<[f64; 2]>,
    pub(super) truth: Vec<[f64; 2]>,
    pub(super) kept: Vec<usize>,
}

pub(super) fn prepare(flight: &Flight, setup: &Setup) -> Result<Prepared> {
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
/// `setup.accel_grid` (and `setup.turn_grid` for the coordinated turn). Only the kept frames enter:
/// the compared in-between frames are never used to choose it. Ties keep the first.
pub fn choose_noise(flight: &Flight, setup: &Setup, motion: Motion) -> Result<Noise> {
    let prep = prepare(flight, setup)?;
    let (turns, priors): (&[f64], &[f64]) = match motion {
        Motion::Cv => (&[0.0], &[0.0]),
        Motion::Ct => (&setup.turn_grid, &setup.turn_rate_sd_grid),
    };
    let max_dt = prep
        .kept
        .windows(2)
        .map(|w| flight.times[w[1]] - flight.times[w[0]])
        .fold(0.0, f64::max);
    let mut best: Option<Noise> = None;
    for &accel in &setup.accel_grid {
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
            // variance (condition number over max_q_condition at the longest step) is skipped:
            // the MKPF's transition density needs a numerically positive definite Q
            if motion == Motion::Ct && accel * max_dt * max_dt / 3.0 > setup.max_q_condition * turn
            {
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
