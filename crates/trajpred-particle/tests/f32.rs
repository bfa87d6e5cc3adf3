//! The filters compile and run in `f32` (weights stay `f64`).

use nalgebra::{Matrix1, Matrix1x2, Matrix2, Matrix5, U1, U2, U5, Vector1, Vector2, Vector5};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trajpred_core::Gaussian;
use trajpred_kalman::{
    CoordinatedTurn, LinearObservation, LinearTransition, MerweSigmaPoints, Observation,
    RangeBearing,
};
use trajpred_particle::{Mkpf, ParticleFilter, ParticleFiltering};

#[test]
fn bootstrap_and_mkpf_run_in_f32() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let tr = LinearTransition::new(
        Matrix2::new(1.0f32, 1.0, 0.0, 1.0),
        Matrix2::identity() * 0.1,
    )
    .expect("tr");
    let ob = LinearObservation::new(Matrix1x2::new(1.0f32, 0.0), Matrix1::new(0.5)).expect("ob");
    let x0 = Gaussian {
        mean: Vector2::new(0.0f32, 1.0),
        covariance: Matrix2::identity(),
    };
    let mut pf =
        ParticleFilter::<f32, U2, U1, _, _>::from_gaussian(tr, ob, &x0, 200, &mut rng).expect("pf");
    let s = pf
        .step(Some(&Vector1::new(1.0f32)), &mut rng)
        .expect("step");
    // the posterior mean of x lies between the prior mean 1 and the observation 1
    assert!(
        (s.estimate.mean[0] - 1.0).abs() < 0.3,
        "{}",
        s.estimate.mean[0]
    );

    let q = Matrix5::from_diagonal(&Vector5::new(4.0f32, 1.0, 4.0, 1.0, 1e-4));
    let ct = CoordinatedTurn::with_process_noise(1.0, q).expect("ct");
    let rb = RangeBearing::new(Vector2::new(0.0f32, 0.0), 0, 2, 1.0, 1e-6).expect("rb");
    let x = Vector5::new(1000.0f32, 10.0, 1000.0, 0.0, 0.05);
    let x0 = Gaussian {
        mean: x,
        covariance: Matrix5::from_diagonal(&Vector5::new(25.0f32, 4.0, 25.0, 4.0, 1e-3)),
    };
    let mut m = Mkpf::<f32, U5, U2, _, _>::from_gaussian(
        ct,
        rb.clone(),
        &x0,
        10,
        MerweSigmaPoints::default(),
        &mut rng,
    )
    .expect("mkpf");
    let z = rb.observe(&x).expect("z");
    let s = m.step(Some(&z), &mut rng).expect("step");
    assert!(s.estimate.mean.iter().all(|v| v.is_finite()));
}
