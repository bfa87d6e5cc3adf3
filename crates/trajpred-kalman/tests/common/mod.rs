//! Models, data and comparisons shared by the integration tests.
#![allow(dead_code)]

use nalgebra::{Matrix4, U2, U4, Vector2, Vector4};
use rand::RngExt;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use trajpred_core::Gaussian;
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_velocity, position_observation,
};
use trajpred_kalman::{LinearObservation, LinearTransition};

pub fn assert_close<R: nalgebra::Dim, C: nalgebra::Dim, S1, S2>(
    a: &nalgebra::Matrix<f64, R, C, S1>,
    b: &nalgebra::Matrix<f64, R, C, S2>,
    tol: f64,
    what: &str,
) where
    S1: nalgebra::Storage<f64, R, C>,
    S2: nalgebra::Storage<f64, R, C>,
{
    for (x, y) in a.iter().zip(b.iter()) {
        assert!(
            (x - y).abs() <= tol * y.abs().max(1.0),
            "{what}: {x} vs {y}\n{a}\n{b}"
        );
    }
}

pub type Cv2 = LinearTransition<f64, U4>;

pub fn cv2_models() -> (Cv2, LinearObservation<f64, U4, U2>) {
    let tr = constant_velocity(2, 0.2, 0.7, StateOrder::PositionsFirst).unwrap();
    let layout = KinematicLayout::new(2, 2, StateOrder::PositionsFirst).unwrap();
    let ob = position_observation(layout, 0.4).unwrap();
    (tr, ob)
}

pub fn noisy_observations(n: usize, seed: u64, missing_every: usize) -> Vec<Option<Vector2<f64>>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|k| {
            let t = k as f64 * 0.2;
            let e1: f64 = rng.sample(StandardNormal);
            let e2: f64 = rng.sample(StandardNormal);
            (missing_every == 0 || k % missing_every != missing_every - 1)
                .then(|| Vector2::new(3.0 * t + 0.6 * e1, 5.0 - t * t * 0.1 + 0.6 * e2))
        })
        .collect()
}

pub fn x0_cv2() -> Gaussian<f64, U4> {
    Gaussian {
        mean: Vector4::new(0.0, 5.0, 1.0, 0.0),
        covariance: Matrix4::from_diagonal(&Vector4::new(2.0, 2.0, 3.0, 3.0)),
    }
}

/// A committed fixture `fixtures/kalman/<name>` (JSON written by the script beside it).
pub fn fixture(name: &str) -> serde_json::Value {
    let path = format!(
        "{}/../../fixtures/kalman/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    serde_json::from_str(&std::fs::read_to_string(path).expect("fixture")).expect("JSON")
}

/// A JSON number.
pub fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().expect("number")
}

/// A JSON array of numbers.
pub fn nums(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(num).collect()
}

/// `ours` within `tol` of `theirs`, relative to `max(|theirs|, 1)`.
pub fn close_rel(ours: f64, theirs: f64, tol: f64, what: &str) {
    assert!(
        (ours - theirs).abs() <= tol * theirs.abs().max(1.0),
        "{what}: ours {ours}, filterpy {theirs}"
    );
}
