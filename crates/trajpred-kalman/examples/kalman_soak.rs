//! A soak run of the Kalman filters over long generated tracks (seeded):
//!
//! - KF, 2-D constant velocity, position observations (10 % missing);
//! - UKF, coordinated turn, range-bearing observations from a sensor at the origin on even
//!   tracks and position observations on odd ones;
//! - the filter driver `driver::{Timed, drive}` with a constant-velocity KF whose model is
//!   rebuilt for irregular time steps (continuous white-noise `Q`), fed in chunks;
//! - the IMM, constant-velocity and coordinated-turn modes, on a target that flies straight
//!   and turns in turn.
//!
//! Every `check_every` steps the filter's covariance must be finite, symmetric
//! (`|P - P^T|_max <= SYM_TOL * max(1, |P|_max)`) and positive semi-definite (the smallest
//! eigenvalue of `(P + P^T) / 2` at least `-PSD_TOL * trace P`); every step's log-likelihood
//! must be finite. VmRSS (from `/proc/self/status`) is read at the start, after the first
//! track and at the end.
//!
//! ```text
//! cargo run --release -p trajpred-kalman --example kalman_soak -- <total steps> <seed>
//! ```
//!
//! The steps are split 30 % KF, 25 % UKF, 25 % driver, 20 % IMM, in tracks of up to 10^6
//! steps.

use nalgebra::{DMatrix, Dim, Matrix2, Matrix2x4, Matrix2x5, OMatrix, U2, U4, U5, Vector2};
use nalgebra::{DefaultAllocator, allocator::Allocator};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use std::time::Instant;
use trajpred_core::Gaussian;
use trajpred_kalman::driver::{Timed, drive};
use trajpred_kalman::imm::{
    Imm, ImmState, constant_velocity_in_turn_state, coordinated_turn_continuous,
    turn_state_position_observation, uniform_switching,
};
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_velocity, kinematic_continuous, position_observation,
};
use trajpred_kalman::{
    CoordinatedTurn, Ekf, Filter, KalmanError, Kf, LinearObservation, LinearTransition,
    MerweSigmaPoints, RangeBearing, Transition, Ukf,
};

/// Symmetry tolerance, relative to `max(1, |P|_max)`.
pub const SYM_TOL: f64 = 1e-9;
/// Positive semi-definiteness tolerance: the smallest eigenvalue may be `-PSD_TOL * trace`.
pub const PSD_TOL: f64 = 1e-9;

/// Checks a covariance: finite, symmetric, positive semi-definite (see the module docs).
pub fn check_cov<D: Dim>(p: &OMatrix<f64, D, D>) -> Result<(), String>
where
    DefaultAllocator: Allocator<D, D>,
{
    let n = p.nrows();
    if p.ncols() != n {
        return Err(format!("not square: {n}x{}", p.ncols()));
    }
    if let Some(i) = p.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "non-finite entry {i}: {}",
            p.iter().nth(i).copied().unwrap_or(0.0)
        ));
    }
    let scale = p.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let mut asym = 0.0f64;
    for i in 0..n {
        for j in 0..i {
            asym = asym.max((p[(i, j)] - p[(j, i)]).abs());
        }
    }
    if asym > SYM_TOL * scale {
        return Err(format!(
            "asymmetric: |P - P^T|_max = {asym:e}, |P|_max = {scale:e}"
        ));
    }
    let d = DMatrix::from_fn(n, n, |i, j| 0.5 * (p[(i, j)] + p[(j, i)]));
    let trace = d.trace();
    let min = d.symmetric_eigenvalues().min();
    if min < -PSD_TOL * trace.abs().max(f64::MIN_POSITIVE) {
        return Err(format!(
            "not PSD: smallest eigenvalue {min:e}, trace {trace:e}"
        ));
    }
    Ok(())
}

/// The resident set size in KiB, from `/proc/self/status` (`None` where there is none).
pub fn vm_rss_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmRSS:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Totals of one filter's soak.
#[derive(Debug, Default, Clone)]
pub struct Part {
    /// Filter steps taken.
    pub steps: u64,
    /// Observations used (steps minus missing ones).
    pub updates: u64,
    /// Tracks run.
    pub tracks: u64,
    /// Covariance checks done.
    pub checks: u64,
    /// Failed checks (covariance or log-likelihood).
    pub violations: u64,
    /// Typed errors returned by a filter (the track then ends).
    pub errors: u64,
    /// The first few violation and error messages.
    pub messages: Vec<String>,
    /// Wall time in seconds.
    pub seconds: f64,
    /// Largest `trace P` seen at a check.
    pub max_trace: f64,
    /// Sum of the position NEES `e^T P_pos^-1 e` at the checks (`e`: estimated minus true
    /// position, `P_pos` the position block; 2 on average for a consistent filter).
    pub nees_sum: f64,
    /// Number of NEES values summed.
    pub nees_n: u64,
}

impl Part {
    /// The mean position NEES at the checks.
    pub fn mean_nees(&self) -> f64 {
        self.nees_sum / self.nees_n.max(1) as f64
    }

    /// Adds the position NEES of `state` (positions at indices 0 and 2) against `truth`.
    fn nees<D: Dim>(&mut self, state: &Gaussian<f64, D>, truth: Vector2<f64>)
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let p = &state.covariance;
        let e = Vector2::new(state.mean[0] - truth[0], state.mean[2] - truth[1]);
        let block = Matrix2::new(p[(0, 0)], p[(0, 2)], p[(2, 0)], p[(2, 2)]);
        match block.try_inverse() {
            Some(inv) if (e.transpose() * inv * e)[0].is_finite() => {
                self.nees_sum += (e.transpose() * inv * e)[0];
                self.nees_n += 1;
            }
            _ => self.fail(format!("position block not invertible: {block:?}")),
        }
    }

    /// Counts step `k` (an update when `observed`); its log-likelihood must be finite.
    fn count_step(&mut self, k: u64, observed: bool, log_likelihood: f64) {
        self.steps += 1;
        if observed {
            self.updates += 1;
        }
        if !log_likelihood.is_finite() {
            self.fail(format!("step {k}: log-likelihood {log_likelihood}"));
        }
    }

    fn fail(&mut self, what: String) {
        self.violations += 1;
        if self.messages.len() < 5 {
            self.messages.push(what);
        }
    }

    fn error(&mut self, e: &KalmanError) {
        self.errors += 1;
        if self.messages.len() < 5 {
            self.messages.push(format!("error: {e}"));
        }
    }

    fn check<D: Dim>(&mut self, p: &OMatrix<f64, D, D>, at: u64)
    where
        DefaultAllocator: Allocator<D, D>,
    {
        self.checks += 1;
        self.max_trace = self.max_trace.max(p.trace());
        if let Err(e) = check_cov(p) {
            self.fail(format!("step {at}: {e}"));
        }
    }
}

/// How much to soak: `steps` steps in tracks of at most `track_len`, the invariants checked
/// every `check_every` steps, the covariance handed to `tamper` first, if set.
#[derive(Debug, Clone, Copy)]
pub struct Soak {
    /// Steps in all.
    pub steps: u64,
    /// The longest track.
    pub track_len: u64,
    /// Steps between two checks.
    pub check_every: u64,
    /// A hook that breaks the covariance before it is checked (tests only).
    pub tamper: Option<Tamper>,
}

impl Soak {
    /// `steps` in tracks of at most `track_len`, checked every `check_every`, untampered.
    pub fn new(steps: u64, track_len: u64, check_every: u64) -> Self {
        Soak {
            steps,
            track_len,
            check_every,
            tamper: None,
        }
    }

    /// `(steps, track_len, check_every, tamper)`.
    pub fn parts(self) -> (u64, u64, u64, Option<Tamper>) {
        (self.steps, self.track_len, self.check_every, self.tamper)
    }

    /// The same run with `tamper` applied before every check.
    pub fn tampered(self, tamper: Tamper) -> Self {
        Soak {
            tamper: Some(tamper),
            ..self
        }
    }
}

/// Runs one part, timing it.
fn timed(run: impl FnOnce(&mut Part)) -> Part {
    let start = Instant::now();
    let mut part = Part::default();
    run(&mut part);
    part.seconds = start.elapsed().as_secs_f64();
    part
}

/// A hook that may tamper with a covariance before it is checked (the identity in a real
/// run; the tests use it to show that a broken covariance is caught).
pub type Tamper = fn(&mut DMatrix<f64>);

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

/// Runs `filter` from `state` for `steps` steps, `observe` giving each step's true position
/// and observation (`None`: missing); checks every `check_every` steps.
fn run_track<D, F>(
    filter: &F,
    mut state: Gaussian<f64, D>,
    steps: u64,
    check_every: u64,
    mut observe: impl FnMut() -> (Vector2<f64>, Option<Vector2<f64>>),
    part: &mut Part,
    tamper: Option<Tamper>,
) where
    D: Dim,
    F: Filter<f64, D, U2>,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<D, U2> + Allocator<U2, D>,
{
    part.tracks += 1;
    for k in 1..=steps {
        let (truth, z) = observe();
        let step = match filter.step(&state, z.as_ref()) {
            Ok(s) => s,
            Err(e) => {
                part.error(&e);
                return;
            }
        };
        part.count_step(k, z.is_some(), step.log_likelihood());
        state = step.posterior().clone();
        if k.is_multiple_of(check_every) || k == steps {
            part.nees(&state, truth);
            match tamper {
                None => part.check(&state.covariance, k),
                Some(t) => {
                    let n = state.covariance.nrows();
                    let mut d = DMatrix::from_fn(n, n, |i, j| state.covariance[(i, j)]);
                    t(&mut d);
                    part.check::<nalgebra::Dyn>(&d, k);
                }
            }
        }
    }
}

/// KF, constant velocity: `steps` steps in tracks of at most `track_len`.
pub fn soak_kf(soak: Soak, rng: &mut ChaCha8Rng) -> Part {
    timed(|part| {
        let (steps, track_len, check_every, tamper) = soak.parts();
        let dt = 0.1;
        let tr: LinearTransition<f64, U4> =
            constant_velocity(2, dt, 0.5, StateOrder::AxisBlocks).expect("model");
        let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks).expect("layout");
        let ob = position_observation(layout, 0.3).expect("model");
        let kf = Kf::new(tr, ob).expect("filter");
        let mut left = steps;
        while left > 0 {
            let n = left.min(track_len);
            left -= n;
            // truth [x, vx, y, vy], white acceleration
            let mut x = [
                gauss(rng) * 100.0,
                gauss(rng) * 5.0,
                gauss(rng) * 100.0,
                gauss(rng) * 5.0,
            ];
            let state = Gaussian {
                mean: nalgebra::Vector4::new(x[0], 0.0, x[2], 0.0),
                covariance: nalgebra::Matrix4::from_diagonal(&nalgebra::Vector4::new(
                    100.0, 25.0, 100.0, 25.0,
                )),
            };
            let sa = 0.5f64.sqrt();
            let observe = || {
                for o in [0, 2] {
                    let a = gauss(rng) * sa;
                    x[o] += x[o + 1] * dt + 0.5 * a * dt * dt;
                    x[o + 1] += a * dt;
                }
                let z = if rng.random_bool(0.1) {
                    None
                } else {
                    Some(Vector2::new(
                        x[0] + gauss(rng) * 0.3f64.sqrt(),
                        x[2] + gauss(rng) * 0.3f64.sqrt(),
                    ))
                };
                (Vector2::new(x[0], x[2]), z)
            };
            run_track(&kf, state, n, check_every, observe, part, tamper);
        }
    })
}

/// UKF, coordinated turn; range-bearing observations on even tracks, positions on odd ones.
pub fn soak_ukf(soak: Soak, rng: &mut ChaCha8Rng) -> Part {
    timed(|part| {
        let (steps, track_len, check_every, tamper) = soak.parts();
        let dt = 0.5;
        let ct = CoordinatedTurn::<f64>::new(dt, 0.2, 1e-3).expect("model");
        let truth = CoordinatedTurn::<f64>::new(dt, 0.0, 0.0).expect("model");
        let (range_var, bearing_var, pos_var) = (0.5, 1e-4, 4.0);
        let rb =
            RangeBearing::new(Vector2::new(0.0, 0.0), 0, 2, range_var, bearing_var).expect("model");
        let mut h = Matrix2x5::zeros();
        h[(0, 0)] = 1.0;
        h[(1, 2)] = 1.0;
        let pos =
            LinearObservation::<f64, U5, U2>::new(h, Matrix2::identity() * pos_var).expect("model");
        let ukf_rb = Ukf::new(ct.clone(), rb, MerweSigmaPoints::new(0.5, 2.0, -2.0)).expect("ukf");
        let ukf_pos = Ukf::new(ct, pos, MerweSigmaPoints::new(0.5, 2.0, -2.0)).expect("ukf");
        let mut left = steps;
        let mut track = 0u64;
        while left > 0 {
            let n = left.min(track_len);
            left -= n;
            // truth: a turning target; the turn rate is mean-reverting around +-0.05 rad/s
            let mut x = nalgebra::Vector5::new(
                100.0 + gauss(rng) * 20.0,
                7.0,
                -50.0 + gauss(rng) * 20.0,
                2.5,
                0.05,
            );
            let mut target = 0.05;
            let state = Gaussian {
                mean: nalgebra::Vector5::new(x[0], 5.0, x[2], 0.0, 0.0),
                covariance: nalgebra::Matrix5::from_diagonal(&nalgebra::Vector5::new(
                    25.0, 25.0, 25.0, 25.0, 0.01,
                )),
            };
            let range_bearing = track.is_multiple_of(2);
            let observe = || {
                if rng.random_bool(0.002) {
                    target = -target;
                }
                x = truth.transition(&x).expect("truth");
                x[4] += 0.05 * (target - x[4]) + gauss(rng) * 1e-3;
                x[1] += gauss(rng) * 0.1;
                x[3] += gauss(rng) * 0.1;
                let pos = Vector2::new(x[0], x[2]);
                if rng.random_bool(0.1) {
                    return (pos, None);
                }
                let z = if range_bearing {
                    let (dx, dy) = (x[0], x[2]);
                    Vector2::new(
                        dx.hypot(dy) + gauss(rng) * range_var.sqrt(),
                        trajpred_kalman::motion::wrap_angle(
                            dy.atan2(dx) + gauss(rng) * bearing_var.sqrt(),
                        ),
                    )
                } else {
                    Vector2::new(
                        x[0] + gauss(rng) * pos_var.sqrt(),
                        x[2] + gauss(rng) * pos_var.sqrt(),
                    )
                };
                (pos, Some(z))
            };
            if range_bearing {
                run_track(&ukf_rb, state, n, check_every, observe, part, tamper);
            } else {
                run_track(&ukf_pos, state, n, check_every, observe, part, tamper);
            }
            track += 1;
        }
    })
}

type CvKf = Kf<LinearTransition<f64, U4>, LinearObservation<f64, U4, U2>>;

fn cv_filter(q: f64, r: f64) -> impl Fn(f64) -> Result<CvKf, KalmanError> {
    move |dt| {
        let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks)?;
        let tr = kinematic_continuous::<f64, U4>(layout, dt, q)?;
        let obs = LinearObservation::new(
            Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0),
            Matrix2::identity() * r,
        )?;
        Kf::new(tr, obs)
    }
}

/// The driver over irregular times (70 % of steps repeat the previous interval, the others
/// draw a new one in `[0.01, 3)` s; 10 % of observations missing), in chunks of `chunk`
/// times so memory stays bounded.
pub fn soak_driver(soak: Soak, rng: &mut ChaCha8Rng) -> Part {
    timed(|part| {
        let (steps, track_len, check_every, tamper) = soak.parts();
        let (q, r) = (0.5, 0.3);
        let chunk = 10_000usize;
        let mut left = steps;
        while left > 0 {
            let n = left.min(track_len);
            left -= n;
            part.tracks += 1;
            let mut x = [
                gauss(rng) * 100.0,
                gauss(rng) * 5.0,
                gauss(rng) * 100.0,
                gauss(rng) * 5.0,
            ];
            let init = Gaussian {
                mean: nalgebra::Vector4::new(x[0], 0.0, x[2], 0.0),
                covariance: nalgebra::Matrix4::from_diagonal(&nalgebra::Vector4::new(
                    100.0, 25.0, 100.0, 25.0,
                )),
            };
            let mut f = Timed::new(cv_filter(q, r), init);
            let (mut t, mut dt) = (0.0f64, 0.1f64);
            let mut done = 0u64;
            let mut times = Vec::with_capacity(chunk + 1);
            let mut obs: Vec<Option<Vector2<f64>>> = Vec::with_capacity(chunk + 1);
            let mut truth: Vec<Vector2<f64>> = Vec::with_capacity(chunk + 1);
            while done < n {
                let m = (n - done).min(chunk as u64) as usize;
                times.clear();
                obs.clear();
                truth.clear();
                times.push(t);
                obs.push(None);
                truth.push(Vector2::new(x[0], x[2]));
                for _ in 0..m {
                    if !rng.random_bool(0.7) {
                        dt = rng.random_range(0.01..3.0);
                    }
                    t += dt;
                    for o in [0, 2] {
                        // exact continuous white-noise acceleration would need the joint draw;
                        // an Euler step is close enough for a truth to track
                        let a = gauss(rng) * (q / dt).sqrt();
                        x[o] += x[o + 1] * dt + 0.5 * a * dt * dt;
                        x[o + 1] += a * dt;
                    }
                    times.push(t);
                    truth.push(Vector2::new(x[0], x[2]));
                    obs.push(if rng.random_bool(0.1) {
                        None
                    } else {
                        Some(Vector2::new(
                            x[0] + gauss(rng) * r.sqrt(),
                            x[2] + gauss(rng) * r.sqrt(),
                        ))
                    });
                }
                let base = done;
                let mut checks = Part::default();
                let res = drive(&mut f, &times, &obs, |k, f| {
                    let at = base + k as u64;
                    if at.is_multiple_of(check_every) || k == m {
                        checks.nees(f.state(), truth[k]);
                        match tamper {
                            None => checks.check(&f.state().covariance, at),
                            Some(tm) => {
                                let p = &f.state().covariance;
                                let mut d = DMatrix::from_fn(4, 4, |i, j| p[(i, j)]);
                                tm(&mut d);
                                checks.check(&d, at);
                            }
                        }
                        match f.log_likelihood() {
                            Some(ll) if ll.is_finite() => {}
                            ll => checks.fail(format!("step {at}: total log-likelihood {ll:?}")),
                        }
                    }
                    Ok(())
                });
                part.checks += checks.checks;
                part.violations += checks.violations;
                part.max_trace = part.max_trace.max(checks.max_trace);
                part.nees_sum += checks.nees_sum;
                part.nees_n += checks.nees_n;
                part.messages.extend(checks.messages.into_iter().take(5));
                match res {
                    Ok(estimates) => {
                        part.steps += estimates.len() as u64;
                        part.updates += obs[1..].iter().filter(|z| z.is_some()).count() as u64;
                    }
                    Err(e) => {
                        part.error(&e);
                        break;
                    }
                }
                done += m as u64;
            }
        }
    })
}

/// The IMM: constant-velocity (KF) and coordinated-turn (EKF) modes on `[x, vx, y, vy,
/// omega]`, 1 s steps, switching by [`uniform_switching`] (mean sojourn 30 s); the truth
/// flies straight and turns in turn (a turn rate of +-0.05 rad/s for 2 % of its steps on
/// average, switching on and off at random), positions observed with variance 4 (10 %
/// missing). Checks the combined covariance and every mode's; the log-likelihood of every
/// observed step must be finite and the mode probabilities must sum to 1.
pub fn soak_imm(soak: Soak, rng: &mut ChaCha8Rng) -> Part {
    timed(|part| {
        let (steps, track_len, check_every, tamper) = soak.parts();
        let (dt, q, pos_var) = (1.0, 0.05, 4.0);
        let obs = turn_state_position_observation::<f64>(pos_var).expect("model");
        let cv = Kf::new(
            constant_velocity_in_turn_state::<f64>(dt, q).expect("model"),
            obs.clone(),
        )
        .expect("kf");
        let ct = Ekf::new(
            coordinated_turn_continuous::<f64>(dt, q, 1e-4).expect("model"),
            obs,
        )
        .expect("ekf");
        let modes: Vec<Box<dyn Filter<f64, U5, U2>>> = vec![Box::new(cv), Box::new(ct)];
        let imm = Imm::new(modes, uniform_switching(2, dt, 30.0).expect("matrix")).expect("imm");
        let truth = CoordinatedTurn::<f64>::new(dt, 0.0, 0.0).expect("model");
        let mut left = steps;
        while left > 0 {
            let n = left.min(track_len);
            left -= n;
            part.tracks += 1;
            let mut x =
                nalgebra::Vector5::new(gauss(rng) * 100.0, 8.0, gauss(rng) * 100.0, 0.0, 0.0);
            let start = Gaussian {
                mean: nalgebra::Vector5::new(x[0], 0.0, x[2], 0.0, 0.0),
                covariance: nalgebra::Matrix5::from_diagonal(&nalgebra::Vector5::new(
                    25.0, 25.0, 25.0, 25.0, 0.01,
                )),
            };
            let mut state = ImmState::uniform(start, 2).expect("state");
            for k in 1..=n {
                // turns of about 20 s, straight legs of about 1000 s, speed kept near 8 m/s
                if x[4] != 0.0 && rng.random_bool(0.05) {
                    x[4] = 0.0;
                } else if x[4] == 0.0 && rng.random_bool(0.001) {
                    x[4] = if rng.random_bool(0.5) { 0.05 } else { -0.05 };
                }
                x = truth.transition(&x).expect("truth");
                let speed = x[1].hypot(x[3]).max(1e-9);
                x[1] += gauss(rng) * 0.05 + 0.01 * (8.0 / speed - 1.0) * x[1];
                x[3] += gauss(rng) * 0.05 + 0.01 * (8.0 / speed - 1.0) * x[3];
                let pos = Vector2::new(x[0], x[2]);
                let z = (!rng.random_bool(0.1)).then(|| {
                    Vector2::new(
                        x[0] + gauss(rng) * pos_var.sqrt(),
                        x[2] + gauss(rng) * pos_var.sqrt(),
                    )
                });
                let step = match imm.step(&state, z.as_ref()) {
                    Ok(s) => s,
                    Err(e) => {
                        part.error(&e);
                        break;
                    }
                };
                part.count_step(k, z.is_some(), step.log_likelihood);
                let sum: f64 = step.state.probabilities().iter().sum();
                if (sum - 1.0).abs() > 1e-12 {
                    part.fail(format!("step {k}: mode probabilities sum to {sum}"));
                }
                state = step.state;
                if k.is_multiple_of(check_every) || k == n {
                    let combined = match state.combined() {
                        Ok(c) => c,
                        Err(e) => {
                            part.error(&e);
                            break;
                        }
                    };
                    part.nees(&combined, pos);
                    for g in state.modes() {
                        if let Err(e) = check_cov(&g.covariance) {
                            part.fail(format!("step {k}: mode covariance {e}"));
                        }
                    }
                    match tamper {
                        None => part.check(&combined.covariance, k),
                        Some(t) => {
                            let p = &combined.covariance;
                            let mut d = DMatrix::from_fn(5, 5, |i, j| p[(i, j)]);
                            t(&mut d);
                            part.check(&d, k);
                        }
                    }
                }
            }
        }
    })
}

/// Prints one part's figures.
#[allow(clippy::print_stdout)] // a report on the terminal is the point of the example
pub fn print(name: &str, p: &Part) {
    println!(
        "{name:<7} steps {:>9}  updates {:>9}  tracks {:>3}  checks {:>6}  violations {}  errors {}  max trace P {:.3e}  mean position NEES {:.2}  {:.1} s ({:.0} steps/s)",
        p.steps,
        p.updates,
        p.tracks,
        p.checks,
        p.violations,
        p.errors,
        p.max_trace,
        p.mean_nees(),
        p.seconds,
        p.steps as f64 / p.seconds.max(1e-9)
    );
    for m in &p.messages {
        println!("        {m}");
    }
}

#[allow(clippy::print_stdout)]
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let total: u64 = args
        .first()
        .map_or(10_000_000, |s| s.parse().expect("steps"));
    let seed: u64 = args.get(1).map_or(0, |s| s.parse().expect("seed"));
    let track_len = 1_000_000;
    let check_every = 1_000;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let rss0 = vm_rss_kib();
    println!(
        "soak: {total} steps, seed {seed}, tracks of up to {track_len}, checks every {check_every}"
    );
    println!("VmRSS at start: {rss0:?} KiB");
    let soak = |steps| Soak::new(steps, track_len, check_every);
    let kf = soak_kf(soak(total * 3 / 10), &mut rng);
    let rss1 = vm_rss_kib();
    print("KF", &kf);
    println!("VmRSS after KF: {rss1:?} KiB");
    let ukf = soak_ukf(soak(total / 4), &mut rng);
    print("UKF", &ukf);
    println!("VmRSS after UKF: {:?} KiB", vm_rss_kib());
    let drv = soak_driver(soak(total / 4), &mut rng);
    print("driver", &drv);
    println!("VmRSS after driver: {:?} KiB", vm_rss_kib());
    let imm = soak_imm(
        soak(total - total * 3 / 10 - total / 4 - total / 4),
        &mut rng,
    );
    print("IMM", &imm);
    let rss2 = vm_rss_kib();
    println!("VmRSS at end: {rss2:?} KiB");
    let all = [&kf, &ukf, &drv, &imm];
    let steps: u64 = all.iter().map(|p| p.steps).sum();
    let bad: u64 = all.iter().map(|p| p.violations + p.errors).sum();
    println!(
        "total steps {steps}, violations + errors {bad}, {:.1} s",
        all.iter().map(|p| p.seconds).sum::<f64>()
    );
    if bad > 0 || steps != total {
        std::process::exit(1);
    }
}
