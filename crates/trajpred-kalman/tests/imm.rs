//! The IMM beyond the filterpy comparison (`filterpy_fixtures.rs`): the coordinated-turn
//! mode checked by properties (on a turning track its probability dominates, on a straight
//! one the constant-velocity mode's does), one mode = the plain filter, the mode
//! probabilities of a hand-worked case, time-step consistency of the switching matrix,
//! and extreme inputs (typed error or finite result, never a panic).

use nalgebra::{DMatrix, Matrix2, Matrix2x5, Matrix5, U2, U5, Vector2, Vector5};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use trajpred_core::Gaussian;
use trajpred_kalman::imm::{
    Imm, ImmState, constant_velocity_in_turn_state, coordinated_turn_continuous,
    uniform_switching,
};
use trajpred_kalman::{Ekf, Filter, KalmanError, Kf, LinearObservation};

type Modes = Vec<Box<dyn Filter<f64, U5, U2>>>;

fn position_obs(r: f64) -> LinearObservation<f64, U5, U2> {
    let mut h = Matrix2x5::zeros();
    h[(0, 0)] = 1.0;
    h[(1, 2)] = 1.0;
    LinearObservation::new(h, Matrix2::identity() * r).expect("observation")
}

/// CV and CT modes on `[x, vx, y, vy, omega]`, 1 s steps.
fn cv_ct(q: f64, q_turn: f64, r: f64, stay: f64) -> Imm<f64, Box<dyn Filter<f64, U5, U2>>> {
    let cv = Kf::new(
        constant_velocity_in_turn_state::<f64>(1.0, q).expect("cv"),
        position_obs(r),
    )
    .expect("kf");
    let ct = Ekf::new(
        coordinated_turn_continuous::<f64>(1.0, q, q_turn).expect("ct"),
        position_obs(r),
    )
    .expect("ekf");
    let modes: Modes = vec![Box::new(cv), Box::new(ct)];
    Imm::new(
        modes,
        DMatrix::from_row_slice(2, 2, &[stay, 1.0 - stay, 1.0 - stay, stay]),
    )
    .expect("imm")
}

fn start() -> ImmState<f64, U5> {
    let g = Gaussian::new(
        Vector5::new(0.0, 10.0, 0.0, 0.0, 0.0),
        Matrix5::from_diagonal(&Vector5::new(4.0, 4.0, 4.0, 4.0, 0.01)),
    )
    .expect("start");
    ImmState::uniform(g, 2).expect("state")
}

/// A target at 10 m/s along x, turning at `omega` rad/s, observed with noise of variance 4.
fn track(omega: f64, n: usize, seed: u64) -> Vec<Option<Vector2<f64>>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut g = || -> f64 { StandardNormal.sample(&mut rng) };
    (1..=n)
        .map(|k| {
            let t = k as f64;
            let (x, y) = if omega == 0.0 {
                (10.0 * t, 0.0)
            } else {
                let a = omega * t;
                (10.0 / omega * a.sin(), 10.0 / omega * (1.0 - a.cos()))
            };
            Some(Vector2::new(x + 2.0 * g(), y + 2.0 * g()))
        })
        .collect()
}

#[test]
fn the_turn_mode_dominates_a_turning_track_and_cv_a_straight_one() {
    let imm = cv_ct(0.05, 1e-4, 4.0, 0.95);
    let mean_mu = |zs: &[Option<Vector2<f64>>]| {
        let steps = imm.filter(&start(), zs).expect("filter");
        let late = &steps[20..];
        late.iter().map(|s| s.state.probabilities()[1]).sum::<f64>() / late.len() as f64
    };
    let turning = mean_mu(&track(0.1, 60, 1));
    let straight = mean_mu(&track(0.0, 60, 2));
    eprintln!("mean CT probability: turning {turning:.3}, straight {straight:.3}");
    assert!(turning > 0.8, "turning track: CT probability {turning}");
    assert!(straight < 0.5, "straight track: CT probability {straight}");
}

