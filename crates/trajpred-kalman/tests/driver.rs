//! The filter driver against filterpy 2.0.0: a constant-velocity KF run over irregular times
//! with missing fixes, its model rebuilt at every step with the continuous white-noise `Q` of
//! that step's interval (`fixtures/kalman/make_timed_cv.py` made `timed_cv.json`).
//!
//! Tolerance: `|ours - filterpy| <= 1e-9 * max(1, |filterpy|)`, as for the other filterpy
//! fixtures (`tests/filterpy_fixtures.rs`): the two implementations agree to rounding, any
//! modelling difference (a wrong `Q` block, a skipped step, the wrong interval) is far larger.

mod common;
use common::{num, nums};
use nalgebra::{DVector, Matrix2, Matrix2x4, Matrix4, U4, Vector2, Vector4};
use serde_json::Value;
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;
use trajpred_kalman::driver::{TimeStepFilter, Timed, drive};
use trajpred_kalman::motion::{KinematicLayout, StateOrder, kinematic, kinematic_continuous};
use trajpred_kalman::{KalmanError, Kf, LinearObservation, Transition};

const TOL: f64 = 1e-9;

fn fixture() -> Value {
    common::fixture("timed_cv.json")
}

fn close(ours: f64, theirs: f64, what: &str) {
    common::close_rel(ours, theirs, TOL, what);
}

fn layout(derivatives: usize) -> KinematicLayout {
    KinematicLayout::new(2, derivatives, StateOrder::AxisBlocks).expect("layout")
}

#[test]
fn continuous_noise_blocks_match_filterpy() {
    let fx = fixture();
    for b in fx["blocks"].as_array().expect("blocks") {
        let dim = b["dim"].as_u64().expect("dim") as usize;
        let (dt, sd) = (num(&b["dt"]), num(&b["spectral_density"]));
        let tr = kinematic_continuous::<f64, nalgebra::Dyn>(layout(dim), dt, sd).expect("model");
        let q = tr.process_noise();
        for (i, row) in b["q"].as_array().expect("rows").iter().enumerate() {
            for (j, v) in row.as_array().expect("row").iter().enumerate() {
                // both axes carry the same block
                close(q[(i, j)], num(v), &format!("dim {dim} dt {dt} q[{i},{j}]"));
                close(q[(dim + i, dim + j)], num(v), "second axis");
                assert_eq!(q[(i, dim + j)], 0.0, "no coupling between axes");
            }
        }
    }
}

type CvKf =
    Kf<trajpred_kalman::LinearTransition<f64, U4>, LinearObservation<f64, U4, nalgebra::U2>>;

fn cv_filter(q: f64, r: f64) -> impl Fn(f64) -> Result<CvKf, KalmanError> {
    move |dt| {
        let tr = kinematic_continuous::<f64, U4>(layout(2), dt, q)?;
        let obs = LinearObservation::new(
            Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0),
            Matrix2::identity() * r,
        )?;
        Kf::new(tr, obs)
    }
}

#[test]
fn the_driver_over_irregular_times_matches_filterpy() {
    let fx = fixture();
    let (q, r) = (num(&fx["q"]), num(&fx["r"]));
    let times = nums(&fx["times"]);
    let z: Vec<Option<Vector2<f64>>> = fx["observations"]
        .as_array()
        .expect("observations")
        .iter()
        .map(|o| o.as_array().map(|p| Vector2::new(num(&p[0]), num(&p[1]))))
        .collect();
    assert!(
        z.iter().filter(|o| o.is_none()).count() >= 4,
        "missing fixes"
    );
    let m0 = nums(&fx["initial_mean"]);
    let p0 = nums(&fx["initial_cov_diag"]);
    let start = Gaussian::new(
        Vector4::from_column_slice(&m0),
        Matrix4::from_diagonal(&Vector4::from_column_slice(&p0)),
    )
    .expect("initial state");
    let mut f = Timed::new(cv_filter(q, r), start.clone());
    let mut calls = 0;
    let est = drive(&mut f, &times, &z, |_, _| {
        calls += 1;
        Ok(())
    })
    .expect("runs");
    assert_eq!(calls, times.len() - 1);
    assert_eq!(est.len(), times.len() - 1);
    for (k, (g, (m, c))) in est
        .iter()
        .zip(
            fx["means"]
                .as_array()
                .expect("means")
                .iter()
                .zip(fx["covs"].as_array().expect("covs")),
        )
        .enumerate()
    {
        for i in 0..4 {
            close(g.mean[i], num(&m[i]), &format!("mean {k}[{i}]"));
            for j in 0..4 {
                close(
                    g.covariance[(i, j)],
                    num(&c[i][j]),
                    &format!("P {k}[{i},{j}]"),
                );
            }
        }
    }
    close(
        f.log_likelihood().expect("summed by default"),
        num(&fx["log_likelihood"]),
        "log-likelihood",
    );
    // without the log-likelihood: none is summed, and every estimate is the same to the bit
    let mut quiet = Timed::new(cv_filter(q, r), start).without_log_likelihood();
    let est_quiet = drive(&mut quiet, &times, &z, |_, _| Ok(())).expect("runs");
    assert_eq!(quiet.log_likelihood(), None);
    assert_eq!(est_quiet, est);
    // forecasts at offsets after the last estimate, each one prediction over the offset
    let cases = fx["forecasts"].as_array().expect("forecasts");
    let offsets: Vec<f64> = cases.iter().map(|c| num(&c["offset"])).collect();
    let ahead = f.forecast_at(&offsets).expect("forecast");
    for (g, c) in ahead.iter().zip(cases) {
        for i in 0..4 {
            close(g.mean[i], num(&c["mean"][i]), "forecast mean");
            for j in 0..4 {
                close(g.covariance[(i, j)], num(&c["cov"][i][j]), "forecast P");
            }
        }
    }
}

#[test]
fn continuous_noise_is_consistent_across_step_sizes_and_discrete_noise_is_not() {
    // two predictions over dt/2 equal one over dt for the continuous model (exactly, in
    // exact arithmetic; to rounding here), not for filterpy's discrete white-noise model
    let x = Gaussian::new(
        DVector::from_vec(vec![1.0, 2.0, -3.0, 0.5]),
        nalgebra::DMatrix::identity(4, 4) * 2.0,
    )
    .expect("state");
    let predict = |tr: &trajpred_kalman::LinearTransition<f64, nalgebra::Dyn>,
                   g: &Gaussian<f64, nalgebra::Dyn>| {
        Gaussian::new(
            tr.f() * &g.mean,
            tr.f() * &g.covariance * tr.f().transpose() + tr.process_noise(),
        )
        .expect("prediction")
    };
    let cont = |dt| kinematic_continuous::<f64, nalgebra::Dyn>(layout(2), dt, 0.8).expect("model");
    let disc = |dt| kinematic::<f64, nalgebra::Dyn>(layout(2), dt, 0.8).expect("model");
    let two = predict(&cont(1.5), &predict(&cont(1.5), &x));
    let one = predict(&cont(3.0), &x);
    assert!((two.covariance - one.covariance).abs().max() < 1e-12);
    let two = predict(&disc(1.5), &predict(&disc(1.5), &x));
    let one = predict(&disc(3.0), &x);
    assert!((two.covariance - one.covariance).abs().max() > 0.1);
}

#[test]
fn bad_time_steps_are_typed_errors() {
    let start = Gaussian::new(Vector4::zeros(), Matrix4::identity()).expect("state");
    let mut f = Timed::new(cv_filter(1.0, 1.0), start);
    let z = vec![None, Some(Vector2::new(1.0, 0.0)), None];
    for times in [[0.0, 1.0, 1.0], [0.0, 1.0, 0.5], [0.0, f64::NAN, 2.0]] {
        match drive(&mut f, &times, &z, |_, _| Ok(())) {
            Err(KalmanError::Core(CoreError::InvalidParameter { name: "times", .. })) => {}
            other => panic!("{times:?}: expected a bad time step, got {other:?}"),
        }
    }
    assert!(matches!(
        drive(&mut f, &[0.0, 1.0], &z, |_, _| Ok(())),
        Err(KalmanError::Core(CoreError::DimensionMismatch { .. }))
    ));
    assert!(matches!(
        f.forecast_at(&[0.0]),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "forecast offset",
            ..
        }))
    ));
    assert!(matches!(
        f.advance(-1.0, None),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "dt",
            ..
        }))
    ));
}

/// The damped-velocity (integrated Ornstein-Uhlenbeck) noise against its defining integrals,
/// computed by Simpson's rule: with `g(s) = (1 - exp(-beta s)) / beta`,
/// `Var x = q int_0^dt g^2`, `Cov(x, v) = q int_0^dt g e^{-beta s}`, `Var v = q int_0^dt e^{-2 beta s}`
/// (tolerance 1e-9 relative: Simpson's rule with 20000 panels is exact to about 1e-15 here).
#[test]
fn damped_velocity_noise_matches_its_integrals() {
    use trajpred_kalman::motion::damped_velocity;
    let l = KinematicLayout::new(1, 2, StateOrder::AxisBlocks).expect("layout");
    for (dt, tau, q) in [
        (1.0, 5.0, 2.0),
        (3.0, 2.0, 0.5),
        (0.5, 100.0, 1.0),
        (4.0, 0.7, 3.0),
    ] {
        let beta: f64 = 1.0 / tau;
        let simpson = |f: &dyn Fn(f64) -> f64| {
            let n = 20_000;
            let h = dt / n as f64;
            (0..=n)
                .map(|i| {
                    let w = if i == 0 || i == n {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    w * f(i as f64 * h)
                })
                .sum::<f64>()
                * h
                / 3.0
        };
        let g = |s: f64| (1.0 - (-beta * s).exp()) / beta;
        let want = [
            q * simpson(&|s| g(s) * g(s)),
            q * simpson(&|s| g(s) * (-beta * s).exp()),
            q * simpson(&|s| (-2.0 * beta * s).exp()),
        ];
        let tr = damped_velocity::<f64, nalgebra::U2>(l, dt, q, tau).expect("model");
        let got = [
            tr.process_noise()[(0, 0)],
            tr.process_noise()[(0, 1)],
            tr.process_noise()[(1, 1)],
        ];
        for (g, w) in got.iter().zip(want) {
            assert!(
                (g - w).abs() <= 1e-9 * w.abs(),
                "dt {dt} tau {tau}: {got:?} vs {want:?}"
            );
        }
        // F: the position moves by v tau (1 - e^{-dt/tau}); the velocity decays
        let x = tr
            .transition(&nalgebra::Vector2::new(0.0, 1.0))
            .expect("transition");
        assert!((x[0] - g(dt)).abs() < 1e-12 && (x[1] - (-beta * dt).exp()).abs() < 1e-15);
    }
}
