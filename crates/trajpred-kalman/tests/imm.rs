//! The IMM beyond the filterpy comparison (`filterpy_fixtures.rs`): the coordinated-turn
//! mode checked by properties (on a turning track its probability dominates, on a straight
//! one the constant-velocity mode's does), one mode = the plain filter, the mode
//! probabilities of a hand-worked case, time-step consistency of the switching matrix,
//! and extreme inputs (typed error or finite result, never a panic).

use nalgebra::{DMatrix, Matrix1, Matrix5, U1, U2, U5, Vector1, Vector2, Vector5};
use rand::RngExt;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;
use trajpred_kalman::imm::{
    Imm, ImmState, constant_velocity_in_turn_state, coordinated_turn_continuous,
    turn_state_position_observation, uniform_switching,
};
use trajpred_kalman::{Ekf, Filter, KalmanError, Kf, LinearObservation, LinearTransition};

type Modes = Vec<Box<dyn Filter<f64, U5, U2>>>;

/// CV and CT modes on `[x, vx, y, vy, omega]`, 1 s steps, switching by `m`.
fn cv_ct_with(
    q: f64,
    q_turn: f64,
    r: f64,
    m: DMatrix<f64>,
) -> Imm<f64, Box<dyn Filter<f64, U5, U2>>> {
    let cv = Kf::new(
        constant_velocity_in_turn_state::<f64>(1.0, q).expect("cv"),
        turn_state_position_observation(r).expect("observation"),
    )
    .expect("kf");
    let ct = Ekf::new(
        coordinated_turn_continuous::<f64>(1.0, q, q_turn).expect("ct"),
        turn_state_position_observation(r).expect("observation"),
    )
    .expect("ekf");
    let modes: Modes = vec![Box::new(cv), Box::new(ct)];
    Imm::new(modes, m).expect("imm")
}

/// [`cv_ct_with`] staying in a mode with probability `stay`.
fn cv_ct(q: f64, q_turn: f64, r: f64, stay: f64) -> Imm<f64, Box<dyn Filter<f64, U5, U2>>> {
    let m = DMatrix::from_row_slice(2, 2, &[stay, 1.0 - stay, 1.0 - stay, stay]);
    cv_ct_with(q, q_turn, r, m)
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

type ScalarKf = Kf<LinearTransition<f64, U1>, LinearObservation<f64, U1, U1>>;

/// Two scalar random-walk-free modes `x' = x` observed with noise variance `r_a`, `r_b`.
fn scalar_pair(r_a: f64, r_b: f64, m: [f64; 4]) -> Imm<f64, ScalarKf> {
    let mode = |r: f64| {
        Kf::new(
            LinearTransition::new(Matrix1::new(1.0), Matrix1::new(0.0)).expect("transition"),
            LinearObservation::new(Matrix1::new(1.0), Matrix1::new(r)).expect("observation"),
        )
        .expect("kf")
    };
    Imm::new(
        vec![mode(r_a), mode(r_b)],
        DMatrix::from_row_slice(2, 2, &m),
    )
    .expect("imm")
}

fn unit_start() -> ImmState<f64, U1> {
    ImmState::uniform(
        Gaussian::new(Vector1::new(0.0), Matrix1::new(1.0)).expect("start"),
        2,
    )
    .expect("state")
}

#[test]
fn a_scalar_step_matches_the_formulas_worked_by_hand() {
    // modes N(0, 1) each, mu = (1/2, 1/2), R_a = 1, R_b = 3, z = 2:
    // cbar = (0.5 * 0.9 + 0.5 * 0.2, 0.5 * 0.1 + 0.5 * 0.8) = (0.55, 0.45)
    // S_a = 2, S_b = 4; L_a = exp(-4/4) / sqrt(2 pi 2), L_b = exp(-4/8) / sqrt(2 pi 4)
    // K_a = 1/2: x_a = 1, P_a = 1/2;  K_b = 1/4: x_b = 1/2, P_b = 3/4
    let imm = scalar_pair(1.0, 3.0, [0.9, 0.1, 0.2, 0.8]);
    let step = imm
        .step(&unit_start(), Some(&Vector1::new(2.0)))
        .expect("step");
    let pi = std::f64::consts::PI;
    let (la, lb) = (
        (-1.0f64).exp() / (4.0 * pi).sqrt(),
        (-0.5f64).exp() / (8.0 * pi).sqrt(),
    );
    let (ca, cb) = (0.55, 0.45);
    let mu_a = ca * la / (ca * la + cb * lb);
    let mu = step.state.probabilities();
    assert!((step.predicted_probabilities[0] - ca).abs() < 1e-15);
    assert!((mu[0] - mu_a).abs() < 1e-15, "{mu:?} vs {mu_a}");
    assert!((step.log_likelihood - (ca * la + cb * lb).ln()).abs() < 1e-14);
    assert!((step.mode_log_likelihoods[0] - la.ln()).abs() < 1e-14);
    let x = mu_a * 1.0 + (1.0 - mu_a) * 0.5;
    let p = mu_a * (0.5 + (1.0 - x).powi(2)) + (1.0 - mu_a) * (0.75 + (0.5 - x).powi(2));
    let c = step.state.combined().expect("combined");
    assert!((c.mean[0] - x).abs() < 1e-15, "{} vs {x}", c.mean[0]);
    assert!(
        (c.covariance[(0, 0)] - p).abs() < 1e-15,
        "{} vs {p}",
        c.covariance[(0, 0)]
    );
}

#[test]
fn likelihoods_below_the_f64_range_still_give_the_exact_mode_probabilities() {
    // z = 10^4: ln L_a = -(ln 4 pi + 10^8 / 2) / 2, ln L_b = -(ln 8 pi + 10^8 / 4) / 2, both
    // far below ln(f64::MIN_POSITIVE) = -708; filterpy would floor both and return cbar
    let imm = scalar_pair(1.0, 3.0, [0.9, 0.1, 0.2, 0.8]);
    let step = imm
        .step(&unit_start(), Some(&Vector1::new(1e4)))
        .expect("step");
    let pi = std::f64::consts::PI;
    let a = 0.55f64.ln() - 0.5 * ((4.0 * pi).ln() + 1e8 / 2.0);
    let b = 0.45f64.ln() - 0.5 * ((8.0 * pi).ln() + 1e8 / 4.0);
    assert!(a < -1e7 && b < -1e7);
    let mu_a = 1.0 / (1.0 + (b - a).exp());
    let mu = step.state.probabilities();
    assert_eq!(
        mu[0], mu_a,
        "mode a is 10^7 nats less likely: probability 0"
    );
    assert_eq!(mu[1], 1.0);
    let expected = b + (1.0 + (a - b).exp()).ln();
    assert!((step.log_likelihood - expected).abs() <= 1e-15 * expected.abs());
    assert!(step.log_likelihood.is_finite());
}

#[test]
fn one_mode_is_the_plain_filter() {
    let kf = Kf::new(
        constant_velocity_in_turn_state::<f64>(1.0, 0.3).expect("cv"),
        turn_state_position_observation(2.0).expect("observation"),
    )
    .expect("kf");
    let imm = Imm::new(vec![kf.clone()], DMatrix::from_element(1, 1, 1.0)).expect("imm");
    let zs = track(0.05, 30, 3);
    let g = start().modes()[0].clone();
    let ours = imm
        .filter(&ImmState::uniform(g.clone(), 1).expect("state"), &zs)
        .expect("imm");
    let theirs = kf.filter(&g, &zs).expect("kf");
    for (a, b) in ours.iter().zip(&theirs) {
        let c = a.state.combined().expect("combined");
        assert!((c.mean - b.posterior().mean).amax() < 1e-12);
        assert!((c.covariance - b.posterior().covariance).amax() < 1e-12);
        assert!((a.log_likelihood - b.log_likelihood()).abs() < 1e-12);
        assert_eq!(a.state.probabilities(), &[1.0]);
    }
}

#[test]
fn the_switching_matrix_is_consistent_over_time_steps() {
    for r in 1..=4 {
        let m = uniform_switching::<f64>(r, 0.7, 12.0).expect("matrix");
        let m2 = uniform_switching::<f64>(r, 1.4, 12.0).expect("matrix");
        assert!((&m * &m - m2).amax() < 1e-15, "{r} modes");
        for i in 0..r {
            assert!((m.row(i).sum() - 1.0).abs() < 1e-15);
        }
    }
    // the mean sojourn: leaving rate 1/tau, so over a short dt the stay probability is
    // about 1 - dt / tau
    let m = uniform_switching::<f64>(3, 1e-3, 10.0).expect("matrix");
    assert!((1.0 - m[(0, 0)] - 1e-4).abs() < 1e-7);
    assert!(matches!(
        uniform_switching::<f64>(2, 0.0, 1.0),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "dt",
            ..
        }))
    ));
    assert!(matches!(
        uniform_switching::<f64>(2, 1.0, f64::NAN),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "mean_sojourn",
            ..
        }))
    ));
    assert!(matches!(
        uniform_switching::<f64>(0, 1.0, 1.0),
        Err(KalmanError::Core(CoreError::Empty { .. }))
    ));
}

#[test]
fn bad_construction_gives_typed_errors() {
    let kf = || {
        Kf::new(
            constant_velocity_in_turn_state::<f64>(1.0, 0.3).expect("cv"),
            turn_state_position_observation(2.0).expect("observation"),
        )
        .expect("kf")
    };
    let m = |v: &[f64]| DMatrix::from_row_slice(2, 2, v);
    assert!(matches!(
        Imm::new(vec![kf(), kf()], m(&[0.9, 0.2, 0.5, 0.5])),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "transition matrix row",
            ..
        }))
    ));
    assert!(matches!(
        Imm::new(vec![kf(), kf()], m(&[1.1, -0.1, 0.5, 0.5])),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "transition matrix row",
            ..
        }))
    ));
    assert!(matches!(
        Imm::new(vec![kf(), kf()], m(&[f64::NAN, 0.5, 0.5, 0.5])),
        Err(KalmanError::Core(CoreError::NonFinite {
            what: "transition matrix",
            index: 0
        }))
    ));
    assert!(matches!(
        Imm::new(vec![kf(), kf(), kf()], m(&[1.0, 0.0, 0.0, 1.0])),
        Err(KalmanError::Core(CoreError::DimensionMismatch {
            what: "transition matrix rows",
            expected: 3,
            got: 2
        }))
    ));
    assert!(matches!(
        Imm::<f64, Box<dyn Filter<f64, U5, U2>>>::new(vec![], DMatrix::zeros(0, 0)),
        Err(KalmanError::Core(CoreError::Empty { what: "IMM modes" }))
    ));
    // within the tolerance, rows are normalised
    let imm = Imm::new(vec![kf(), kf()], m(&[0.9 + 1e-12, 0.1, 0.5, 0.5])).expect("imm");
    assert!((imm.transition_matrix().row(0).sum() - 1.0).abs() < 1e-15);
    let g = start().modes()[0].clone();
    assert!(matches!(
        ImmState::new(vec![g.clone(), g.clone()], vec![0.5, 0.6]),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "mode probabilities",
            ..
        }))
    ));
    assert!(matches!(
        ImmState::new(vec![g.clone(), g.clone()], vec![1.0]),
        Err(KalmanError::Core(CoreError::DimensionMismatch {
            what: "mode probabilities",
            ..
        }))
    ));
    // a state of three modes into an IMM of two
    let three = ImmState::uniform(g, 3).expect("state");
    assert!(matches!(
        imm.step(&three, None),
        Err(KalmanError::Core(CoreError::DimensionMismatch {
            what: "IMM state modes",
            expected: 2,
            got: 3
        }))
    ));
}

/// With probability `p`: `10^e` with `e` uniform in `[-300, 300]`, either sign, or a NaN,
/// an infinity or 0; otherwise a moderate value (standard normal times 10).
fn extreme(rng: &mut ChaCha8Rng, p: f64) -> f64 {
    if !rng.random_bool(p) {
        let g: f64 = StandardNormal.sample(rng);
        return 10.0 * g;
    }
    let u: f64 = rng.random();
    let v: f64 = rng.random();
    let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    match (u * 20.0) as u32 {
        0 => f64::NAN,
        1 => f64::INFINITY * sign,
        2 => 0.0,
        _ => sign * 10f64.powf(600.0 * v - 300.0),
    }
}

#[test]
fn extreme_inputs_give_a_typed_error_or_a_finite_result() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    // no switching, always switching, an unreachable mode (a zero column), uniform
    let matrices = [
        [1.0, 0.0, 0.0, 1.0],
        [0.0, 1.0, 1.0, 0.0],
        [1.0, 0.0, 1.0, 0.0],
        [0.5, 0.5, 0.5, 0.5],
    ];
    let (mut ok, mut errors) = (0, 0);
    for case in 0..600 {
        let m = matrices[case % 4];
        let q = 10f64.powf(rng.random_range(-12.0..12.0));
        let r = 10f64.powf(rng.random_range(-12.0..12.0));
        let imm = cv_ct_with(q, q * 1e-3, r, DMatrix::from_row_slice(2, 2, &m));
        let scale = 10f64.powf(rng.random_range(-150.0..150.0));
        let g = Gaussian::new(
            Vector5::new(extreme(&mut rng, 0.3), 1.0, 0.0, 1.0, 0.01),
            Matrix5::from_diagonal(&Vector5::new(scale, scale, scale, scale, 1e-2)),
        );
        let Ok(g) = g else { continue };
        let state = ImmState::uniform(g, 2).expect("state");
        let zs: Vec<Option<Vector2<f64>>> = (0..8)
            .map(|_| {
                rng.random_bool(0.8)
                    .then(|| Vector2::new(extreme(&mut rng, 0.05), extreme(&mut rng, 0.05)))
            })
            .collect();
        match imm.filter(&state, &zs) {
            Ok(steps) => {
                ok += 1;
                for s in &steps {
                    let Ok(c) = s.state.combined() else {
                        assert!(matches!(
                            s.state.combined(),
                            Err(KalmanError::Core(CoreError::NonFinite { .. }))
                        ));
                        continue;
                    };
                    assert!(
                        c.mean
                            .iter()
                            .chain(c.covariance.iter())
                            .all(|v| v.is_finite()),
                        "case {case}"
                    );
                    assert!(s.log_likelihood.is_finite(), "case {case}");
                    let sum: f64 = s.state.probabilities().iter().sum();
                    assert!((sum - 1.0).abs() < 1e-12, "case {case}: {sum}");
                    if m == [1.0, 0.0, 1.0, 0.0] {
                        assert_eq!(s.state.probabilities()[1], 0.0, "unreachable mode");
                    }
                }
                let f = imm.forecast(&steps.last().map_or(state.clone(), |s| s.state.clone()), 3);
                if let Ok(f) = f {
                    assert!(
                        f.iter()
                            .filter_map(|s| s.combined().ok())
                            .all(|c| c.mean.iter().all(|v| v.is_finite()))
                    );
                }
            }
            Err(
                KalmanError::Core(CoreError::NonFinite { .. })
                | KalmanError::Core(CoreError::NotPositiveDefinite { .. })
                | KalmanError::Undefined { .. },
            ) => errors += 1,
            Err(e) => panic!("case {case}: unexpected error {e:?}"),
        }
    }
    eprintln!("extreme inputs: {ok} finite results, {errors} typed errors");
    assert!(
        ok > 50 && errors > 50,
        "both outcomes exercised: {ok} ok, {errors} errors"
    );
}
