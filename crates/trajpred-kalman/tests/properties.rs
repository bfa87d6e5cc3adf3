//! Properties and hand-worked values: UKF = KF on a linear model, EKF Jacobians = finite
//! differences, batch = step by step, the IKF and the KF-dynamic predictor form on scalar
//! examples worked by hand, forecasts, and a 10^6-step covariance soak.
//! (Numerical edge cases and the speed paths: `numerics.rs`.)

use nalgebra::{
    Const, DMatrix, DVector, Matrix1, Matrix1x2, Matrix2, Matrix4, Matrix5, U1, U2, U4, Vector1,
    Vector2, Vector4, Vector5,
};
use rand::RngExt;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use trajpred_core::Gaussian;
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_acceleration, constant_velocity, position_observation,
    wrap_angle,
};
use trajpred_kalman::sampling::{covariance_sqrt, observation_log_likelihood, sample_transition};
use trajpred_kalman::{
    AugmentedUkf, CoordinatedTurn, CovarianceUpdate, Ekf, Filter, Ikf, Innovation, InputChecks, Kf,
    LinearObservation, LinearTransition, MerweSigmaPoints, MultiStep, NoisyTransition, Observation,
    ObservationJacobian, RangeBearing, Smoother, Transition, TransitionJacobian, Ukf,
};

mod common;
use common::{assert_close, cv2_models, noisy_observations, x0_cv2};

#[test]
fn ukf_equals_kf_on_a_linear_model() {
    // The unscented transform is exact for linear f and h, so every prior and posterior must
    // agree with the KF's to rounding: tolerance 1e-9 relative for alpha >= 0.5 (60 steps of
    // rounding in two operation orders). With alpha = 1e-3 the sigma points sit only
    // 2e-3 sqrt(P) from a mean of size ~10, so their offsets carry about 1/alpha^2 less
    // relative precision (measured: 1.7e-9 in the log-likelihood); tolerance 1e-7 there.
    let (tr, ob) = cv2_models();
    let kf = Kf::new(&tr, &ob).unwrap();
    let zs = noisy_observations(60, 1, 7);
    let reference = kf.filter(&x0_cv2(), &zs).unwrap();
    for (alpha, beta, kappa, tol) in [
        (1.0, 2.0, 0.0, 1e-9),
        (0.5, 2.0, -1.0, 1e-9),
        (1e-3, 2.0, 0.0, 1e-7),
    ] {
        let ukf = Ukf::new(&tr, &ob, MerweSigmaPoints::new(alpha, beta, kappa)).unwrap();
        let steps = ukf.filter(&x0_cv2(), &zs).unwrap();
        for (u, k) in steps.iter().zip(&reference) {
            assert_close(&u.prior.mean, &k.prior.mean, tol, "prior mean");
            assert_close(&u.prior.covariance, &k.prior.covariance, tol, "prior cov");
            assert_close(&u.posterior().mean, &k.posterior().mean, tol, "mean");
            assert_close(
                &u.posterior().covariance,
                &k.posterior().covariance,
                1e-9,
                "cov",
            );
            let d = (u.log_likelihood() - k.log_likelihood()).abs();
            assert!(d < tol, "alpha {alpha}: log-likelihood differs by {d}");
        }
        // and the unscented RTS smoother equals the KF's RTS smoother
        let sk = kf.filter_smooth(&x0_cv2(), &zs).unwrap();
        let su = ukf.filter_smooth(&x0_cv2(), &zs).unwrap();
        for (a, b) in su.iter().zip(&sk) {
            assert_close(&a.mean, &b.mean, tol * 10.0, "smoothed mean");
            assert_close(&a.covariance, &b.covariance, tol * 10.0, "smoothed cov");
        }
    }
}

/// Central differences with step `h`: truncation error O(h^2), rounding O(eps / h).
fn fd_jacobian<const N: usize, const M: usize>(
    g: impl Fn(&nalgebra::SVector<f64, N>) -> nalgebra::SVector<f64, M>,
    x: &nalgebra::SVector<f64, N>,
) -> nalgebra::SMatrix<f64, M, N> {
    let h = 1e-6;
    let mut j = nalgebra::SMatrix::<f64, M, N>::zeros();
    for c in 0..N {
        let mut xp = *x;
        let mut xm = *x;
        xp[c] += h;
        xm[c] -= h;
        j.set_column(c, &((g(&xp) - g(&xm)) / (2.0 * h)));
    }
    j
}

#[test]
fn ekf_jacobians_equal_finite_differences() {
    // tolerance 1e-6: central differences with h = 1e-6 are accurate to about 1e-8 here
    let ct = CoordinatedTurn::new(0.7, 0.1, 0.01).unwrap();
    for w in [0.8, -0.3, 1e-3, 1e-5, 0.0] {
        let x = Vector5::new(3.0, -2.0, 1.0, 4.0, w);
        let analytic = ct.transition_jacobian(&x).unwrap();
        let numeric = fd_jacobian(|v| ct.transition(v).unwrap(), &x);
        assert_close(&analytic, &numeric, 1e-6, "CT Jacobian");
    }
    // the small-|wT| series joins the closed form smoothly at the switch |wT| = 1e-2: the
    // difference quotient across the switch equals the mean of the Jacobian's d/dw columns
    // on both sides (trapezoid rule: error O(dw^2) ~ 1e-10 for dw = 3e-5; a jump between the
    // branches of size d would show as d / dw, so 1e-8 bounds it by ~3e-13)
    for (lo, hi) in [
        (0.999e-2 / 0.7, 1.001e-2 / 0.7),
        (-1.001e-2 / 0.7, -0.999e-2 / 0.7),
    ] {
        let xl = Vector5::new(0.0, 3.0, 0.0, 1.0, lo);
        let xh = Vector5::new(0.0, 3.0, 0.0, 1.0, hi);
        let quotient = (ct.transition(&xh).unwrap() - ct.transition(&xl).unwrap()) / (hi - lo);
        let mean_column = (ct.transition_jacobian(&xl).unwrap().column(4)
            + ct.transition_jacobian(&xh).unwrap().column(4))
            / 2.0;
        assert_close(&mean_column, &quotient, 1e-8, "CT d/dw across the switch");
    }
    let rb = RangeBearing::new(Vector2::new(1.0, -2.0), 0, 2, 1.0, 0.01).unwrap();
    for x in [
        Vector5::new(3.0, 0.0, 4.0, 0.0, 0.0),
        Vector5::new(-7.0, 1.0, -3.0, 2.0, 0.1),
    ] {
        let analytic: nalgebra::Matrix2x5<f64> = rb.observation_jacobian(&x).unwrap();
        let numeric = fd_jacobian(|v| rb.observe(v).unwrap(), &x);
        assert_close(&analytic, &numeric, 1e-6, "range-bearing Jacobian");
    }
}

#[test]
fn batch_equals_step_by_step_for_every_filter() {
    fn check<F: Filter<f64, U4, U2>>(f: &F, zs: &[Option<Vector2<f64>>]) {
        let batch = f.filter(&x0_cv2(), zs).unwrap();
        let mut state = x0_cv2();
        for (b, z) in batch.iter().zip(zs) {
            let prior = f.predict(&state).unwrap();
            let post = match z {
                Some(z) => f.update(&prior, z).unwrap().posterior,
                None => prior.clone(),
            };
            assert_eq!(b.prior, prior);
            assert_eq!(b.posterior(), &post);
            state = post;
        }
    }
    let (tr, ob) = cv2_models();
    let zs = noisy_observations(40, 2, 5);
    check(&Kf::new(&tr, &ob).unwrap(), &zs);
    check(&Ekf::new(&tr, &ob).unwrap(), &zs);
    check(
        &Ukf::new(&tr, &ob, MerweSigmaPoints::default()).unwrap(),
        &zs,
    );
    // the lighter input checks change nothing for valid input
    check(
        &Kf::new(&tr, &ob)
            .unwrap()
            .with_input_checks(InputChecks::Cheap),
        &zs,
    );
    for form in [CovarianceUpdate::Plain, CovarianceUpdate::Symmetrised] {
        check(
            &Kf::new(&tr, &ob).unwrap().with_covariance_update(form),
            &zs,
        );
    }
}

#[test]
fn covariance_forms_agree_with_the_optimal_gain() {
    // with the optimal gain, Joseph, plain and symmetrised forms are algebraically equal
    let (tr, ob) = cv2_models();
    let zs = noisy_observations(30, 3, 0);
    let joseph = Kf::new(&tr, &ob).unwrap().filter(&x0_cv2(), &zs).unwrap();
    let plain = Kf::new(&tr, &ob)
        .unwrap()
        .with_covariance_update(CovarianceUpdate::Plain)
        .filter(&x0_cv2(), &zs)
        .unwrap();
    for (a, b) in joseph.iter().zip(&plain) {
        assert_close(
            &a.posterior().covariance,
            &b.posterior().covariance,
            1e-10,
            "forms",
        );
    }
}

#[test]
fn covariance_stays_symmetric_positive_definite_over_a_million_steps() {
    // 10^6 steps of a well-posed model: the 2-state (1-D constant velocity, position
    // observed) static-size KF with the Joseph form. The 4-state model is too slow for 10^6
    // steps in a debug build of this crate, so the soak uses the 2-state model.
    let tr: LinearTransition<f64, U2> =
        constant_velocity(1, 0.1, 0.5, StateOrder::AxisBlocks).unwrap();
    let layout = KinematicLayout::new(1, 2, StateOrder::AxisBlocks).unwrap();
    let ob: LinearObservation<f64, U2, U1> = position_observation(layout, 0.2).unwrap();
    let kf = Kf::new(tr, ob).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut state = Gaussian {
        mean: Vector2::new(0.0, 1.0),
        covariance: Matrix2::identity() * 10.0,
    };
    let mut truth = 0.0f64;
    for k in 0..1_000_000u32 {
        truth += 0.1;
        let e: f64 = rng.sample(StandardNormal);
        let z = Vector1::<f64>::new(truth + 0.45 * e);
        state = kf.step(&state, Some(&z)).unwrap().update.unwrap().posterior;
        let p = &state.covariance;
        assert_eq!(p[(0, 1)], p[(1, 0)], "symmetric at step {k}");
        assert!(
            p[(0, 0)] > 0.0 && p[(0, 0)] * p[(1, 1)] - p[(0, 1)] * p[(1, 0)] > 0.0,
            "PD at step {k}"
        );
    }
    // steady state: the position variance is below the observation variance
    assert!(state.covariance[(0, 0)] < 0.2);
}

#[test]
fn kf_dynamic_predictor_form_hand_worked_and_equal_to_update_then_predict() {
    // scalar, worked by hand: A = H = 1, Q = 0.1, R = 1, X(k|k-1) = 0, P(k|k-1) = 1, Z = 2:
    // K = 1 * 1 / (1 + 1) = 0.5; X(k+1|k) = 0 + 0.5 * 2 = 1; P(k+1|k) = 1 - 1/2 + 0.1 = 0.6
    let tr = LinearTransition::new(Matrix1::<f64>::new(1.0), Matrix1::<f64>::new(0.1)).unwrap();
    let ob = LinearObservation::new(Matrix1::<f64>::new(1.0), Matrix1::<f64>::new(1.0)).unwrap();
    let kf = Kf::new(tr, ob).unwrap();
    let pred = Gaussian {
        mean: Vector1::<f64>::new(0.0),
        covariance: Matrix1::<f64>::new(1.0),
    };
    let next = kf
        .predictor_step(&pred, Some(&Vector1::<f64>::new(2.0)))
        .unwrap();
    assert!((next.mean[0] - 1.0).abs() < 1e-15);
    assert!((next.covariance[(0, 0)] - 0.6).abs() < 1e-15);
    // reusing Z for a second step: K = 0.6 / 1.6 = 0.375, X = 1 + 0.375 (2 - 1) = 1.375,
    // P = 0.6 - 0.36 / 1.6 + 0.1 = 0.475
    let f = kf
        .predictor_forecast(
            &pred,
            &Vector1::<f64>::new(2.0),
            2,
            MultiStep::ReuseLastObservation,
        )
        .unwrap();
    assert!((f[1].mean[0] - 1.375).abs() < 1e-15);
    assert!((f[1].covariance[(0, 0)] - 0.475).abs() < 1e-15);
    // extrapolating instead: X = 1, P = 0.6 + 0.1
    let f = kf
        .predictor_forecast(&pred, &Vector1::<f64>::new(2.0), 2, MultiStep::Extrapolate)
        .unwrap();
    assert!((f[1].mean[0] - 1.0).abs() < 1e-15);
    assert!((f[1].covariance[(0, 0)] - 0.7).abs() < 1e-15);

    // on a CV track, eq. 13-15 equal update (plain form) followed by predict
    let (tr, ob) = cv2_models();
    let kf = Kf::new(&tr, &ob)
        .unwrap()
        .with_covariance_update(CovarianceUpdate::Plain);
    let zs = noisy_observations(30, 5, 6);
    let first = kf.predict(&x0_cv2()).unwrap();
    let predictions = kf.predictor_filter(&first, &zs).unwrap();
    let steps = kf.filter(&x0_cv2(), &zs).unwrap();
    for (k, p) in predictions.iter().enumerate().take(zs.len() - 1) {
        let expected = &steps[k + 1].prior;
        assert_close(&p.mean, &expected.mean, 1e-10, "predictor mean");
        assert_close(&p.covariance, &expected.covariance, 1e-10, "predictor cov");
    }
}

#[test]
fn ikf_hand_worked_scalar_and_causal() {
    // F = H = 1, Q = 0.5, R = 1, start N(0, 1).
    // step 1: prior N(0, 1.5); no previous innovation, so corrected = prior;
    //         Z(1) = 2 gives V(1) = 2, S(1) = 1.5 + 1 = 2.5.
    // step 2: prior N(0, 2.0); K = 2.0 / 2.5 = 0.8; X = 0 + 0.8 * 2 = 1.6;
    //         Joseph P = 0.2^2 * 2 + 0.8^2 * 1 = 0.72; plain P = 0.2 * 2 = 0.4.
    let tr = LinearTransition::new(Matrix1::<f64>::new(1.0), Matrix1::<f64>::new(0.5)).unwrap();
    let ob = LinearObservation::new(Matrix1::<f64>::new(1.0), Matrix1::<f64>::new(1.0)).unwrap();
    let x0 = Gaussian {
        mean: Vector1::<f64>::new(0.0),
        covariance: Matrix1::<f64>::new(1.0),
    };
    let zs = vec![
        Some(Vector1::<f64>::new(2.0)),
        Some(Vector1::<f64>::new(-7.0)),
    ];
    let ikf = Ikf::new(&tr, &ob).unwrap();
    let steps = ikf.filter(&x0, &zs).unwrap();
    assert_eq!(steps[0].corrected, steps[0].prior);
    let v = steps[0].innovation.as_ref().unwrap();
    assert!((v.mean[0] - 2.0).abs() < 1e-15 && (v.covariance[(0, 0)] - 2.5).abs() < 1e-15);
    assert!((steps[1].prior.covariance[(0, 0)] - 2.0).abs() < 1e-15);
    assert!((steps[1].corrected.mean[0] - 1.6).abs() < 1e-15);
    assert!((steps[1].corrected.covariance[(0, 0)] - 0.72).abs() < 1e-15);
    let plain = Ikf::new(&tr, &ob)
        .unwrap()
        .with_covariance_update(CovarianceUpdate::Plain)
        .filter(&x0, &zs)
        .unwrap();
    assert!((plain[1].corrected.covariance[(0, 0)] - 0.4).abs() < 1e-15);
    // causal: the prediction for time k does not depend on Z(k) or later
    let zs2 = vec![
        Some(Vector1::<f64>::new(2.0)),
        Some(Vector1::<f64>::new(100.0)),
    ];
    let steps2 = ikf.filter(&x0, &zs2).unwrap();
    assert_eq!(steps2[1].corrected, steps[1].corrected);
}

#[test]
fn ikf_with_run_time_sizes_for_the_gskf() {
    // T = 3 horizons chosen at run time, H = I: the correction moves each horizon by
    // P (P + R)^-1 V with the previous S = P + R, here diagonal: K = 2 / (2 + 1) per row
    let t = 3;
    let tr = LinearTransition::new(DMatrix::identity(t, t), DMatrix::identity(t, t) * 0.5).unwrap();
    let ob = LinearObservation::new(DMatrix::identity(t, t), DMatrix::identity(t, t)).unwrap();
    let ikf = Ikf::new(tr, ob).unwrap();
    let p = ikf
        .propagate_covariance(&(DMatrix::identity(t, t) * 1.5))
        .unwrap();
    assert_close(
        &p,
        &(DMatrix::<f64>::identity(t, t) * 2.0),
        1e-15,
        "P(k|k-1)",
    );
    let prior = Gaussian {
        mean: DVector::from_vec(vec![1.0, 2.0, 3.0]),
        covariance: p,
    };
    let previous = Innovation::new(
        DVector::from_vec(vec![0.3, -0.3, 0.6]),
        DMatrix::identity(t, t) * 3.0,
    )
    .unwrap();
    let c = ikf.correct(&prior, &previous).unwrap();
    let k = 2.0 / 3.0;
    assert_close(
        &c.mean,
        &DVector::from_vec(vec![1.0 + k * 0.3, 2.0 - k * 0.3, 3.0 + k * 0.6]),
        1e-15,
        "corrected",
    );
}

#[test]
fn forecast_with_covariance_matches_closed_form() {
    // CV in 1-D with dt = 1: x_j = [p + j v, v], P_j = F^j P0 F^jT + sum_i F^i Q F^iT.
    // With P0 = 0 and Q from var = 1: Q = [[1/4, 1/2], [1/2, 1]]; by hand P_2 = F Q F^T + Q
    // = [[9/4 + 1/4, 3/2 + 1/2], [3/2 + 1/2, 2]] = [[2.5, 2], [2, 2]].
    let tr: LinearTransition<f64, U2> =
        constant_velocity(1, 1.0, 1.0, StateOrder::AxisBlocks).unwrap();
    let ob = LinearObservation::new(Matrix1x2::new(1.0, 0.0), Matrix1::<f64>::new(1.0)).unwrap();
    let kf = Kf::new(tr, ob).unwrap();
    let x = Gaussian {
        mean: Vector2::new(2.0, 0.5),
        covariance: Matrix2::zeros(),
    };
    let f = kf.forecast(&x, 5).unwrap();
    assert_eq!(f.len(), 5);
    for (j, g) in f.iter().enumerate() {
        assert!((g.mean[0] - (2.0 + 0.5 * (j + 1) as f64)).abs() < 1e-14);
    }
    assert_close(
        &f[1].covariance,
        &Matrix2::new(2.5, 2.0, 2.0, 2.0),
        1e-14,
        "P_2",
    );
    // the same forecast from the UKF and the EKF
    let (tr, ob) = cv2_models();
    let ukf = Ukf::new(&tr, &ob, MerweSigmaPoints::new(1.0, 2.0, 0.0)).unwrap();
    let kf = Kf::new(&tr, &ob).unwrap();
    let a = ukf.forecast(&x0_cv2(), 5).unwrap();
    let b = kf.forecast(&x0_cv2(), 5).unwrap();
    for (u, k) in a.iter().zip(&b) {
        assert_close(&u.covariance, &k.covariance, 1e-10, "forecast cov");
    }
}

#[test]
fn control_effect_is_added_to_the_predicted_mean() {
    let (tr, ob) = cv2_models();
    let kf = Kf::new(&tr, &ob).unwrap();
    let bu = Vector4::new(0.1, -0.2, 0.0, 0.3);
    let plain = kf.predict(&x0_cv2()).unwrap();
    let controlled = kf.predict_with_control(&x0_cv2(), &bu).unwrap();
    assert_eq!(controlled.mean, plain.mean + bu);
    assert_eq!(controlled.covariance, plain.covariance);
}

#[test]
fn bearing_residual_wraps_across_pi() {
    let rb = RangeBearing::new(Vector2::new(0.0, 0.0), 0, 1, 1.0, 0.01).unwrap();
    let y = Observation::<f64, U2, U2>::observation_residual(
        &rb,
        &Vector2::new(5.0, -std::f64::consts::PI + 0.01),
        &Vector2::new(5.0, std::f64::consts::PI - 0.01),
    );
    assert!((y[1] - 0.02).abs() < 1e-12);
    assert!((wrap_angle(3.0 * std::f64::consts::PI) + std::f64::consts::PI).abs() < 1e-12);
    // a UKF update of a target just across the -x axis: the posterior bearing stays near pi
    let ct = CoordinatedTurn::new(1.0, 0.1, 1e-4).unwrap();
    let rb = RangeBearing::new(Vector2::new(0.0, 0.0), 0, 2, 0.1, 1e-4).unwrap();
    let ukf = Ukf::new(&ct, &rb, MerweSigmaPoints::new(0.5, 2.0, -2.0)).unwrap();
    let prior = Gaussian {
        mean: Vector5::new(-10.0, 0.0, 0.0, 0.0, 0.0),
        covariance: Matrix5::from_diagonal(&Vector5::new(0.5, 0.1, 0.5, 0.1, 1e-4)),
    };
    let z = Vector2::new(10.0, -std::f64::consts::PI + 0.01);
    let u = ukf.update(&prior, &z).unwrap();
    assert!(u.innovation[1].abs() < 0.05, "innovation {}", u.innovation);
    assert!(u.posterior.mean[2] < 0.0 && u.posterior.mean[2] > -0.2);
}

#[test]
fn constant_acceleration_model_by_hand() {
    // 1-D CA, dt = 2: F = [[1, 2, 2], [0, 1, 2], [0, 0, 1]]
    let ca: LinearTransition<f64, Const<3>> =
        constant_acceleration(1, 2.0, 1.0, StateOrder::AxisBlocks).unwrap();
    let x = ca
        .transition(&nalgebra::Vector3::new(1.0, 1.0, 1.0))
        .unwrap();
    assert_eq!(x, nalgebra::Vector3::new(5.0, 3.0, 1.0));
    // Q row 0: [dt^4/4, dt^3/2, dt^2/2] = [4, 4, 2]
    assert_eq!(
        ca.q().row(0).transpose(),
        nalgebra::Vector3::new(4.0, 4.0, 2.0)
    );
    // dynamic size, 3 axes
    let ca3: LinearTransition<f64, nalgebra::Dyn> =
        constant_acceleration(3, 0.5, 1.0, StateOrder::PositionsFirst).unwrap();
    assert_eq!(ca3.f().nrows(), 9);
    assert_eq!(ca3.f()[(0, 3)], 0.5); // x from vx
    assert_eq!(ca3.f()[(0, 6)], 0.125); // x from ax: dt^2 / 2
}

#[test]
fn sampling_and_likelihood_for_a_bootstrap_particle_filter() {
    // the sample mean and covariance of f(x) + w over 20000 seeded draws match N(f(x), Q)
    // to Monte Carlo accuracy (about 3 / sqrt(20000) relative)
    let (tr, ob) = cv2_models();
    let l = covariance_sqrt(tr.q(), "Q").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let x = Vector4::new(1.0, 2.0, 3.0, 4.0);
    let n = 20_000;
    let draws: Vec<Vector4<f64>> = (0..n)
        .map(|_| sample_transition(&tr, &l, &x, &mut rng).unwrap())
        .collect();
    let mean = draws.iter().fold(Vector4::zeros(), |a, d| a + d) / n as f64;
    let fx = tr.transition(&x).unwrap();
    let cov = draws
        .iter()
        .fold(Matrix4::zeros(), |a, d| a + (d - fx) * (d - fx).transpose())
        / n as f64;
    for i in 0..4 {
        let sd = tr.q()[(i, i)].sqrt();
        assert!((mean[i] - fx[i]).abs() < 4.0 * sd / (n as f64).sqrt());
        assert!((cov[(i, i)] - tr.q()[(i, i)]).abs() < 0.05 * tr.q()[(i, i)]);
    }
    // log N(z; Hx, R) by hand: R = 0.4 I, H x = (x0, x1) = (1, 2), z - Hx = (0.2, -0.4):
    // -(2 ln 2pi + 2 ln 0.4 + (0.04 + 0.16) / 0.4) / 2
    let ll = observation_log_likelihood(&ob, &x, &Vector2::new(1.2, 1.6)).unwrap();
    let expected = -(2.0 * (2.0 * std::f64::consts::PI).ln() + 2.0 * 0.4f64.ln() + 0.5) / 2.0;
    assert!((ll - expected).abs() < 1e-14);
}

#[test]
fn f32_filters_run() {
    let tr: LinearTransition<f32, U4> =
        constant_velocity(2, 0.1, 0.5, StateOrder::AxisBlocks).unwrap();
    let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks).unwrap();
    let ob: LinearObservation<f32, U4, U2> = position_observation(layout, 0.3).unwrap();
    let x0 = Gaussian {
        mean: nalgebra::Vector4::<f32>::zeros(),
        covariance: nalgebra::Matrix4::<f32>::identity(),
    };
    let z = nalgebra::Vector2::<f32>::new(0.1, 0.2);
    let kf = Kf::new(&tr, &ob).unwrap();
    let s = kf.step(&x0, Some(&z)).unwrap();
    assert!(s.posterior().covariance.iter().all(|v| v.is_finite()));
    let ukf = Ukf::new(&tr, &ob, MerweSigmaPoints::new(0.5f32, 2.0, 0.0)).unwrap();
    let u = ukf.step(&x0, Some(&z)).unwrap();
    assert!((u.posterior().mean - s.posterior().mean).amax() < 1e-4);
    let _ = U1;
}

#[test]
fn augmented_ukf_equals_kf_on_a_linear_model() {
    // the joint unscented transform of linear f and h in [x; w; v] is exact: every prior,
    // posterior, S, K and log-likelihood equals the KF's (1e-9 relative, rounding)
    let (tr, ob) = cv2_models();
    let kf = Kf::new(&tr, &ob).unwrap();
    let aug = AugmentedUkf::new(&tr, &ob, MerweSigmaPoints::new(0.5, 2.0, 0.0)).unwrap();
    let zs = noisy_observations(40, 8, 9);
    let a = aug.filter(&x0_cv2(), &zs).unwrap();
    let k = kf.filter(&x0_cv2(), &zs).unwrap();
    for (sa, sk) in a.iter().zip(&k) {
        assert_close(&sa.prior.mean, &sk.prior.mean, 1e-9, "prior mean");
        assert_close(
            &sa.prior.covariance,
            &sk.prior.covariance,
            1e-9,
            "prior cov",
        );
        assert_close(&sa.posterior().mean, &sk.posterior().mean, 1e-9, "mean");
        assert_close(
            &sa.posterior().covariance,
            &sk.posterior().covariance,
            1e-9,
            "cov",
        );
        if let (Some(ua), Some(uk)) = (&sa.update, &sk.update) {
            assert_close(
                &ua.innovation_covariance,
                &uk.innovation_covariance,
                1e-9,
                "S",
            );
            assert_close(&ua.gain, &uk.gain, 1e-9, "K");
            assert!((ua.log_likelihood() - uk.log_likelihood()).abs() < 1e-9);
        }
    }
    assert_eq!(aug.predict(&x0_cv2()).unwrap(), a[0].prior);
}

/// `x' = x (1 + w)`: multiplicative process noise, which only the augmented form represents.
struct Multiplicative {
    q: Matrix1<f64>,
}

impl Transition<f64, U1> for Multiplicative {
    fn transition(&self, x: &Vector1<f64>) -> trajpred_kalman::Result<Vector1<f64>> {
        Ok(*x)
    }
    fn process_noise(&self) -> &Matrix1<f64> {
        &self.q
    }
}

impl NoisyTransition<f64, U1> for Multiplicative {
    fn transition_with_noise(
        &self,
        x: &Vector1<f64>,
        w: &Vector1<f64>,
    ) -> trajpred_kalman::Result<Vector1<f64>> {
        Ok(Vector1::new(x[0] * (1.0 + w[0])))
    }
}

#[test]
fn augmented_ukf_with_multiplicative_noise_by_hand() {
    // x ~ N(mu, P), w ~ N(0, Q): the augmented sigma points lie on the axes, so the
    // transform gives mean mu and variance P + mu^2 Q exactly (worked by hand: the x-points
    // give y = x_i, the w-points y = mu (1 + w_i), the v-points y = mu; the PQ cross term
    // of the true variance needs points off the axes). mu = 2, P = 0.5, Q = 0.1: 0.9.
    let model = Multiplicative {
        q: Matrix1::<f64>::new(0.1),
    };
    let ob = LinearObservation::new(Matrix1::<f64>::new(1.0), Matrix1::<f64>::new(1.0)).unwrap();
    let aug = AugmentedUkf::new(&model, &ob, MerweSigmaPoints::new(0.7, 2.0, 0.0)).unwrap();
    let x = Gaussian {
        mean: Vector1::<f64>::new(2.0),
        covariance: Matrix1::<f64>::new(0.5),
    };
    let prior = aug.predict(&x).unwrap();
    assert!((prior.mean[0] - 2.0).abs() < 1e-12);
    assert!((prior.covariance[(0, 0)] - 0.9).abs() < 1e-12);
    // update with z = 3: S = 0.9 + 1, K = 0.9 / 1.9, x = 2 + K
    let s = aug.step(&x, Some(&Vector1::<f64>::new(3.0))).unwrap();
    let u = s.update.unwrap();
    assert!((u.posterior.mean[0] - (2.0 + 0.9 / 1.9)).abs() < 1e-12);
    assert!((u.posterior.covariance[(0, 0)] - (0.9 - 0.81 / 1.9)).abs() < 1e-12);
}
