//! The time-varying RTS smoother (`smoother::filter_smooth_steps`, `smoother::smooth_steps`)
//! against filterpy 2.0.0: a constant-velocity KF over irregular times with long steps and
//! runs of time points without observations, its model built for every step's interval, smoothed by filterpy's
//! `KalmanFilter.rts_smoother` with per-step `Fs` and `Qs`
//! (`fixtures/kalman/make_rts_varying.py` made `rts_varying.json`).
//!
//! Tolerance: `|ours - filterpy| <= 1e-10 * max(1, |filterpy|)` for every filtered and smoothed
//! mean and covariance entry and every gain. filterpy inverts `P(k+1|k)` explicitly where we
//! factorise it, so the two agree to rounding: within about 1e-12 relative here (a run with
//! 1e-12 fails on a smoothed covariance, 1.2e-12 apart), so 1e-10 leaves room for rounding
//! only, while a modelling error is far larger (using the first step's filter for every step
//! moves the first smoothed position by 26 m).

mod common;
use common::{num, nums};
use nalgebra::{Matrix2, Matrix2x4, Matrix4, U2, U4, Vector2, Vector4};
use serde_json::Value;
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;
use trajpred_kalman::smoother::{filter_smooth_steps, smooth_steps};
use trajpred_kalman::{KalmanError, Kf, LinearObservation, LinearTransition};

const TOL: f64 = 1e-10;

type CvKf = Kf<LinearTransition<f64, U4>, LinearObservation<f64, U4, U2>>;

fn fixture() -> Value {
    common::fixture("rts_varying.json")
}

fn close(ours: f64, theirs: f64, what: &str) {
    common::close_rel(ours, theirs, TOL, what);
}

fn vec4(v: &Value) -> Vector4<f64> {
    Vector4::from_iterator(v.as_array().expect("vector").iter().map(num))
}

fn mat4(v: &Value) -> Matrix4<f64> {
    let rows = v.as_array().expect("matrix");
    Matrix4::from_fn(|i, j| num(&rows[i][j]))
}

/// The constant-velocity KF over `dt` with the continuous white-noise `Q` per axis, state
/// `[x, vx, y, vy]`, observing both positions with variance `r`.
fn cv(dt: f64, q: f64, r: f64) -> Result<CvKf, KalmanError> {
    let mut f = Matrix4::identity();
    let mut qm = Matrix4::zeros();
    for o in [0, 2] {
        f[(o, o + 1)] = dt;
        qm[(o, o)] = q * dt.powi(3) / 3.0;
        qm[(o, o + 1)] = q * dt * dt / 2.0;
        qm[(o + 1, o)] = q * dt * dt / 2.0;
        qm[(o + 1, o + 1)] = q * dt;
    }
    let h = Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    Kf::new(
        LinearTransition::new(f, qm)?,
        LinearObservation::new(h, Matrix2::identity() * r)?,
    )
}

/// The fixture's filters (one per step), initial state and observations after the first.
type Case = (Vec<CvKf>, Gaussian<f64, U4>, Vec<Option<Vector2<f64>>>);

fn setup(fx: &Value) -> Case {
    let (q, r) = (num(&fx["q"]), num(&fx["r"]));
    let times = nums(&fx["times"]);
    let filters = times
        .windows(2)
        .map(|w| cv(w[1] - w[0], q, r).expect("model"))
        .collect();
    let diag = vec4(&fx["initial_cov_diag"]);
    let initial = Gaussian {
        mean: vec4(&fx["initial_mean"]),
        covariance: Matrix4::from_diagonal(&diag),
    };
    let observations = fx["observations"].as_array().expect("observations")[1..]
        .iter()
        .map(|z| match z {
            Value::Null => None,
            z => Some(Vector2::new(num(&z[0]), num(&z[1]))),
        })
        .collect();
    (filters, initial, observations)
}

#[test]
fn time_varying_rts_matches_filterpy() {
    let fx = fixture();
    let (filters, initial, observations) = setup(&fx);
    let fb = filter_smooth_steps(&filters, &initial, &observations).expect("smoother");
    let n = filters.len() + 1;
    assert_eq!(fb.filtered.len(), n);
    assert_eq!(fb.smoothed.states.len(), n);
    assert_eq!(fb.smoothed.gains.len(), n - 1);
    for k in 1..n {
        let (m, p) = (
            vec4(&fx["filtered_mean"][k - 1]),
            mat4(&fx["filtered_cov"][k - 1]),
        );
        for i in 0..4 {
            close(
                fb.filtered[k].mean[i],
                m[i],
                &format!("filtered mean {k}[{i}]"),
            );
            for j in 0..4 {
                close(fb.filtered[k].covariance[(i, j)], p[(i, j)], "filtered cov");
            }
        }
    }
    for k in 0..n {
        let (m, p) = (vec4(&fx["smoothed_mean"][k]), mat4(&fx["smoothed_cov"][k]));
        let s = &fb.smoothed.states[k];
        for i in 0..4 {
            close(s.mean[i], m[i], &format!("smoothed mean {k}[{i}]"));
            for j in 0..4 {
                close(
                    s.covariance[(i, j)],
                    p[(i, j)],
                    &format!("smoothed cov {k}"),
                );
            }
        }
    }
    for (k, g) in fb.smoothed.gains.iter().enumerate() {
        let theirs = mat4(&fx["gains"][k]);
        for i in 0..4 {
            for j in 0..4 {
                close(g[(i, j)], theirs[(i, j)], &format!("gain {k}"));
            }
        }
    }
}

#[test]
fn the_smoother_narrows_the_gaps_and_leaves_the_last_state() {
    let fx = fixture();
    let (filters, initial, observations) = setup(&fx);
    let fb = filter_smooth_steps(&filters, &initial, &observations).expect("smoother");
    let last = fb.filtered.len() - 1;
    assert_eq!(fb.smoothed.states[last], fb.filtered[last]);
    // every smoothed position variance is at most the filtered one, strictly inside a gap
    for (s, f) in fb.smoothed.states.iter().zip(&fb.filtered) {
        assert!(s.covariance[(0, 0)] <= f.covariance[(0, 0)] * (1.0 + 1e-12));
    }
    // time point 18 is in the middle of a run of 12 without observations
    assert!(observations[17].is_none());
    let (s, f) = (&fb.smoothed.states[18], &fb.filtered[18]);
    assert!(s.covariance[(0, 0)] < 0.1 * f.covariance[(0, 0)]);
}

#[test]
fn wrong_lengths_and_empty_input_are_typed_errors() {
    let fx = fixture();
    let (filters, initial, observations) = setup(&fx);
    let err = filter_smooth_steps(&filters, &initial, &observations[1..]).unwrap_err();
    assert!(matches!(
        err,
        KalmanError::Core(CoreError::LengthMismatch { .. })
    ));
    let fb = filter_smooth_steps(&filters, &initial, &observations).expect("smoother");
    let err = smooth_steps(&filters[1..], &fb.filtered).unwrap_err();
    assert!(matches!(
        err,
        KalmanError::Core(CoreError::LengthMismatch { .. })
    ));
    let none: [Gaussian<f64, U4>; 0] = [];
    let err = smooth_steps(&filters[..0], &none).unwrap_err();
    assert!(matches!(err, KalmanError::Core(CoreError::Empty { .. })));
    // a single state and no filter: the state itself
    let one = smooth_steps(&filters[..0], &fb.filtered[..1]).expect("one state");
    assert_eq!(one.states, fb.filtered[..1].to_vec());
    assert!(one.gains.is_empty());
}
