//! Bad input: every variant of `KalmanError` is reached, and nothing panics or returns NaN.

use nalgebra::{
    DMatrix, DVector, Matrix1, Matrix1x2, Matrix2, Matrix4, U2, U4, U5, Vector1, Vector2, Vector4,
    Vector5,
};
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_velocity, position_observation,
};
use trajpred_kalman::{
    CoordinatedTurn, Ekf, Filter, Ikf, Innovation, InputChecks, KalmanError, Kf, LinearObservation,
    LinearTransition, MerweSigmaPoints, RangeBearing, Smoother, Ukf,
};

fn cv() -> (LinearTransition<f64, U4>, LinearObservation<f64, U4, U2>) {
    let tr = constant_velocity(2, 0.5, 1.0, StateOrder::AxisBlocks).unwrap();
    let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks).unwrap();
    (tr, position_observation(layout, 0.5).unwrap())
}

fn state() -> Gaussian<f64, U4> {
    Gaussian {
        mean: Vector4::new(1.0, 0.0, 2.0, 0.0),
        covariance: Matrix4::identity(),
    }
}

#[test]
fn dimension_mismatches() {
    // run-time sizes: an observation of the wrong length
    let tr =
        LinearTransition::new(DMatrix::<f64>::identity(3, 3), DMatrix::identity(3, 3)).unwrap();
    let ob =
        LinearObservation::new(DMatrix::<f64>::identity(2, 3), DMatrix::identity(2, 2)).unwrap();
    let kf = Kf::new(&tr, &ob).unwrap();
    let x = Gaussian {
        mean: DVector::zeros(3),
        covariance: DMatrix::identity(3, 3),
    };
    let r = kf.step(&x, Some(&DVector::zeros(3)));
    assert!(matches!(
        r,
        Err(KalmanError::Core(CoreError::DimensionMismatch {
            expected: 2,
            got: 3,
            ..
        }))
    ));
    // a state of the wrong size
    let x4 = Gaussian {
        mean: DVector::zeros(4),
        covariance: DMatrix::identity(4, 4),
    };
    assert!(matches!(
        kf.predict(&x4),
        Err(KalmanError::Core(CoreError::DimensionMismatch { .. }))
    ));
    // F and Q of different sizes; H with the wrong number of columns
    assert!(matches!(
        LinearTransition::new(DMatrix::<f64>::identity(3, 3), DMatrix::identity(2, 2)),
        Err(KalmanError::Core(CoreError::DimensionMismatch { .. }))
    ));
    let bad_h =
        LinearObservation::new(DMatrix::<f64>::identity(2, 4), DMatrix::identity(2, 2)).unwrap();
    assert!(matches!(
        Kf::new(&tr, &bad_h),
        Err(KalmanError::Core(CoreError::DimensionMismatch { .. }))
    ));
    // a static size that does not fit the number of axes
    assert!(matches!(
        constant_velocity::<f64, U5>(2, 1.0, 1.0, StateOrder::AxisBlocks),
        Err(KalmanError::Core(CoreError::DimensionMismatch {
            expected: 4,
            got: 5,
            ..
        }))
    ));
    // an innovation whose S does not match its residual (the core Gaussian's check)
    assert!(matches!(
        Innovation::new(DVector::<f64>::zeros(2), DMatrix::identity(3, 3)),
        Err(CoreError::DimensionMismatch {
            expected: 2,
            got: 3,
            ..
        })
    ));
    // range-bearing indices beyond the state
    let rb = RangeBearing::new(Vector2::new(0.0, 0.0), 0, 7, 1.0, 0.1).unwrap();
    let ekf = Ekf::new(&tr, &rb);
    assert!(
        ekf.is_err() || {
            let e = ekf.unwrap();
            matches!(
                e.update(&x, &Vector2::zeros()),
                Err(KalmanError::Core(CoreError::DimensionMismatch { .. }))
            )
        }
    );
}

#[test]
fn non_finite_inputs() {
    let (tr, ob) = cv();
    let kf = Kf::new(&tr, &ob).unwrap();
    let r = kf.step(&state(), Some(&Vector2::new(f64::NAN, 0.0)));
    assert!(matches!(
        r,
        Err(KalmanError::Core(CoreError::NonFinite {
            what: "observation",
            index: 0
        }))
    ));
    let mut s = state();
    s.mean[2] = f64::INFINITY;
    assert!(matches!(
        kf.predict(&s),
        Err(KalmanError::Core(CoreError::NonFinite { index: 2, .. }))
    ));
    let mut f = Matrix4::identity();
    f[(1, 1)] = f64::NAN;
    assert!(matches!(
        LinearTransition::new(f, Matrix4::identity()),
        Err(KalmanError::Core(CoreError::NonFinite { what: "F", .. }))
    ));
    // overflow inside the filter is reported, never returned as inf/NaN
    let huge = Gaussian {
        mean: Vector4::new(1.7e308, 1.7e308, 0.0, 0.0),
        covariance: Matrix4::identity() * 1.7e308,
    };
    let r = kf.predict(&huge);
    assert!(
        matches!(r, Err(KalmanError::Core(CoreError::NonFinite { .. }))),
        "{r:?}"
    );
    let ukf = Ukf::new(&tr, &ob, MerweSigmaPoints::new(0.5, 2.0, 0.0)).unwrap();
    assert!(matches!(
        ukf.update(&state(), &Vector2::new(0.0, f64::NEG_INFINITY)),
        Err(KalmanError::Core(CoreError::NonFinite { .. }))
    ));
}

#[test]
fn not_positive_definite_p_q_r_s() {
    let (tr, ob) = cv();
    let kf = Kf::new(&tr, &ob).unwrap();
    // P indefinite (an eigenvalue of -1): rejected by every filter
    let mut bad = state();
    bad.covariance = Matrix4::from_diagonal(&Vector4::new(1.0, -1.0, 1.0, 1.0));
    assert!(matches!(
        kf.predict(&bad),
        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
            what: "P"
        }))
    ));
    assert!(matches!(
        kf.update(&bad, &Vector2::new(0.0, 0.0)),
        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
            what: "P"
        }))
    ));
    // P with positive diagonal but indefinite (off-diagonal too large)
    bad.covariance = Matrix4::identity();
    bad.covariance[(0, 1)] = 2.0;
    bad.covariance[(1, 0)] = 2.0;
    let ukf = Ukf::new(&tr, &ob, MerweSigmaPoints::default()).unwrap();
    assert!(matches!(
        ukf.predict(&bad),
        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
            what: "P"
        }))
    ));
    // P not symmetric
    bad.covariance = Matrix4::identity();
    bad.covariance[(0, 1)] = 0.5;
    let ekf = Ekf::new(&tr, &ob).unwrap();
    assert!(matches!(
        ekf.predict(&bad),
        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
            what: "P"
        }))
    ));
    // Q indefinite
    assert!(matches!(
        LinearTransition::new(Matrix2::identity(), Matrix2::new(1.0, 0.0, 0.0, -0.5)),
        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
            what: "Q"
        }))
    ));
    // R singular (positive semi-definite is not enough for R)
    assert!(matches!(
        LinearObservation::new(Matrix1x2::new(1.0, 0.0), Matrix1::new(0.0)),
        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
            what: "R"
        }))
    ));
    // S: an innovation covariance that is not positive definite; a negative variance is
    // refused by the Gaussian, an indefinite symmetric S by the IKF that solves with it
    assert!(matches!(
        Innovation::new(Vector1::new(1.0), Matrix1::new(-1.0)),
        Err(CoreError::NotPositiveDefinite { what: "covariance" })
    ));
    let (tr2, ob2) = (
        LinearTransition::new(Matrix2::identity(), Matrix2::identity()).unwrap(),
        LinearObservation::new(Matrix2::identity(), Matrix2::identity()).unwrap(),
    );
    let indefinite = Innovation::new(Vector2::new(1.0, 0.0), Matrix2::new(1.0, 2.0, 2.0, 1.0));
    let prior2 = Gaussian::new(Vector2::zeros(), Matrix2::identity()).unwrap();
    assert!(matches!(
        Ikf::new(&tr2, &ob2)
            .unwrap()
            .correct(&prior2, &indefinite.unwrap()),
        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
            what: "S"
        }))
    ));
    // the UKF needs a strictly positive definite P for its sigma points
    let mut singular = state();
    singular.covariance[(3, 3)] = 0.0;
    assert!(matches!(
        ukf.predict(&singular),
        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
            what: "P"
        }))
    ));
    // ... while the KF accepts a positive semi-definite P (a known component)
    assert!(kf.predict(&singular).is_ok());
}

#[test]
fn kf_predict_checks_the_symmetry_of_p() {
    // the static-size KF with a structured F, with either input check: an exactly symmetric
    // P takes the fast path, a P symmetric to within sqrt(eps) of its largest diagonal
    // element is accepted, any other P is rejected, including one whose two triangles hold
    // the same non-finite value
    let (tr, ob) = cv();
    for checks in [InputChecks::Full, InputChecks::Cheap] {
        let kf = Kf::new(&tr, &ob).unwrap().with_input_checks(checks);
        let mut x = state();
        x.covariance = Matrix4::from_fn(|i, j| if i == j { 2.0 } else { 0.25 });
        let exact = kf.predict(&x).unwrap();
        let mut near = x.clone();
        near.covariance[(0, 1)] += 1e-10;
        let got = kf.predict(&near).unwrap();
        assert!((got.covariance - exact.covariance).amax() < 1e-9);
        assert_eq!(got.covariance, got.covariance.transpose());
        for (i, j, v) in [
            (0, 1, 0.5),
            (1, 3, -0.25),
            (2, 3, f64::NAN),
            (0, 2, f64::INFINITY),
        ] {
            let mut bad = x.clone();
            bad.covariance[(i, j)] = v;
            let expected = |r: &Result<Gaussian<f64, U4>, KalmanError>| {
                if v.is_finite() {
                    matches!(
                        r,
                        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
                            what: "P"
                        }))
                    )
                } else {
                    matches!(
                        r,
                        Err(KalmanError::Core(CoreError::NonFinite { what: "P", .. }))
                    )
                }
            };
            let r = kf.predict(&bad);
            assert!(expected(&r), "{checks:?}: upper ({i}, {j}) = {v}: {r:?}");
            if !v.is_finite() {
                // symmetric, but not finite
                bad.covariance[(j, i)] = v;
                let r = kf.predict(&bad);
                assert!(expected(&r), "{checks:?}: both ({i}, {j}) = {v}: {r:?}");
            }
        }
        // a negative variance with exactly symmetric triangles
        let mut negative = x.clone();
        negative.covariance[(3, 3)] = -1.0;
        assert!(matches!(
            kf.predict(&negative),
            Err(KalmanError::Core(CoreError::NotPositiveDefinite {
                what: "P"
            }))
        ));
    }
}

#[test]
fn a_step_reports_the_errors_of_its_prediction_first() {
    // the KF's step checks its prediction through the update (a finite posterior proves the
    // prior finite); the errors must still be those of predict, then update
    let (tr, ob) = cv();
    let kf = Kf::new(&tr, &ob).unwrap();
    let z = Vector2::new(1.0, 2.0);
    // the predicted covariance overflows (P_00 + dt^2 P_11 > max)
    let mut huge = state();
    huge.covariance = Matrix4::identity() * 1.7e308;
    // the predicted mean overflows (x + dt v > max)
    let mut fast = state();
    fast.mean = Vector4::new(1.7e308, 1.7e308, 0.0, 0.0);
    for (x, what) in [(huge, "predicted covariance"), (fast, "predicted mean")] {
        let want = |r: &KalmanError| matches!(r, KalmanError::Core(CoreError::NonFinite { what: w, .. }) if *w == what);
        let e = kf.predict(&x).unwrap_err();
        assert!(want(&e), "predict: {e:?}");
        let e = kf.step(&x, Some(&z)).unwrap_err();
        assert!(want(&e), "step: {e:?}");
        let e = kf.filter(&x, &[Some(z)]).unwrap_err();
        assert!(want(&e), "filter: {e:?}");
        // with a bad observation as well, the prediction's error still comes first
        let e = kf.step(&x, Some(&Vector2::new(f64::NAN, 0.0))).unwrap_err();
        assert!(want(&e), "step, NaN observation: {e:?}");
    }
    // a finite prediction and a bad observation: the observation's error
    let e = kf
        .step(&state(), Some(&Vector2::new(f64::NAN, 0.0)))
        .unwrap_err();
    assert!(
        matches!(
            e,
            KalmanError::Core(CoreError::NonFinite {
                what: "observation",
                ..
            })
        ),
        "{e:?}"
    );
}

/// A user's model whose `propagate_covariance` breaks the documented mirror: a NaN in the
/// upper triangle only, at `(1, 3)`, which the update reads nowhere (the Joseph form reads
/// the lower triangle, `H P` the rows 0 and 2).
struct UpperNan(LinearTransition<f64, U4>);

impl trajpred_kalman::Transition<f64, U4> for UpperNan {
    fn transition(&self, x: &Vector4<f64>) -> trajpred_kalman::Result<Vector4<f64>> {
        self.0.transition(x)
    }
    fn process_noise(&self) -> &Matrix4<f64> {
        self.0.process_noise()
    }
}

impl trajpred_kalman::TransitionJacobian<f64, U4> for UpperNan {
    fn transition_jacobian(&self, x: &Vector4<f64>) -> trajpred_kalman::Result<Matrix4<f64>> {
        self.0.transition_jacobian(x)
    }
}

impl trajpred_kalman::LinearTransitionModel<f64, U4> for UpperNan {
    fn transition_matrix(&self) -> &Matrix4<f64> {
        self.0.transition_matrix()
    }
    fn propagate_covariance(&self, p: &Matrix4<f64>) -> Matrix4<f64> {
        let mut out = self.0.propagate_covariance(p);
        out[(1, 3)] = f64::NAN;
        out
    }
    fn has_structured_propagation(&self) -> bool {
        true
    }
    // `mirrors_covariance` keeps its default, `false`
}

#[test]
fn a_prediction_that_is_not_mirrored_is_checked() {
    use trajpred_kalman::LinearTransitionModel;
    let (tr, ob) = cv();
    assert!(tr.mirrors_covariance());
    let model = UpperNan(tr);
    assert!(!model.mirrors_covariance());
    let kf = Kf::new(&model, &ob).unwrap();
    let z = Vector2::new(1.0, 2.0);
    let predicted = |e: &KalmanError| {
        matches!(
            e,
            KalmanError::Core(CoreError::NonFinite {
                what: "predicted covariance",
                index: 13
            })
        )
    };
    let e = kf.step(&state(), Some(&z)).unwrap_err();
    assert!(predicted(&e), "step: {e:?}");
    let e = kf.predict(&state()).unwrap_err();
    assert!(predicted(&e), "predict: {e:?}");
    let e = kf.filter(&state(), &[Some(z)]).unwrap_err();
    assert!(predicted(&e), "filter: {e:?}");
}

#[test]
fn s_not_positive_definite_inside_an_update() {
    // A user observation model whose R is validated but whose Jacobian returns NaN-free
    // values that overflow S: S = H P H^T + R is then not finite -> not positive definite.
    let (tr, _) = cv();
    let h = Matrix1x2::new(1e200, 0.0);
    let tr1 = LinearTransition::new(Matrix2::<f64>::identity(), Matrix2::identity()).unwrap();
    let ob = LinearObservation::new(h, Matrix1::new(1.0)).unwrap();
    let kf = Kf::new(&tr1, &ob).unwrap();
    let x = Gaussian {
        mean: Vector2::new(0.0, 0.0),
        covariance: Matrix2::identity() * 1e200,
    };
    let r = kf.update(&x, &Vector1::new(0.0));
    assert!(
        matches!(
            r,
            Err(KalmanError::Core(CoreError::NotPositiveDefinite {
                what: "S"
            }))
        ),
        "{r:?}"
    );
    let _ = tr;
}

#[test]
fn invalid_parameters() {
    assert!(matches!(
        constant_velocity::<f64, U4>(2, 0.0, 1.0, StateOrder::AxisBlocks),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "dt",
            ..
        }))
    ));
    assert!(matches!(
        constant_velocity::<f64, nalgebra::Dyn>(4, 1.0, 1.0, StateOrder::AxisBlocks),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "axes",
            ..
        }))
    ));
    assert!(matches!(
        CoordinatedTurn::<f64>::new(1.0, -1.0, 0.1),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "accel_var",
            ..
        }))
    ));
    assert!(matches!(
        RangeBearing::<f64>::new(Vector2::zeros(), 0, 1, 0.0, 0.1),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "range_var",
            ..
        }))
    ));
    assert!(matches!(
        MerweSigmaPoints::<f64>::default().weights(0),
        Err(KalmanError::Core(CoreError::InvalidParameter {
            name: "n",
            ..
        }))
    ));
}

#[test]
fn degenerate_sigma_point_weights() {
    let (tr, ob) = cv();
    // kappa = -n: n + lambda = alpha^2 (n + kappa) = 0, weights 1 / (2 (n + lambda)) infinite
    let r = Ukf::new(&tr, &ob, MerweSigmaPoints::new(1.0, 2.0, -4.0));
    assert!(matches!(
        r,
        Err(KalmanError::DegenerateSigmaPoints { n: 4, .. })
    ));
    // kappa < -n: negative weights
    let r = Ukf::new(&tr, &ob, MerweSigmaPoints::new(0.5, 2.0, -5.0));
    assert!(matches!(r, Err(KalmanError::DegenerateSigmaPoints { .. })));
    // alpha = 0 and non-finite parameters
    for p in [
        MerweSigmaPoints::new(0.0, 2.0, 0.0),
        MerweSigmaPoints::new(f64::NAN, 2.0, 0.0),
        MerweSigmaPoints::new(1.0, f64::INFINITY, 0.0),
    ] {
        assert!(matches!(
            Ukf::new(&tr, &ob, p),
            Err(KalmanError::DegenerateSigmaPoints { .. })
        ));
    }
}

#[test]
fn undefined_model_and_empty_input() {
    // an EKF update of a target exactly at the sensor: the bearing Jacobian is undefined
    let ct = CoordinatedTurn::new(1.0, 0.1, 0.01).unwrap();
    let rb = RangeBearing::new(Vector2::new(3.0, 4.0), 0, 2, 1.0, 0.01).unwrap();
    let ekf = Ekf::new(&ct, &rb).unwrap();
    let at_sensor = Gaussian {
        mean: Vector5::new(3.0, 0.0, 4.0, 0.0, 0.0),
        covariance: nalgebra::Matrix5::identity(),
    };
    let r = ekf.update(&at_sensor, &Vector2::new(1.0, 0.0));
    assert!(matches!(r, Err(KalmanError::Undefined { .. })), "{r:?}");
    // smoothing nothing
    let (tr, ob) = cv();
    let kf = Kf::new(&tr, &ob).unwrap();
    assert!(matches!(
        kf.smooth(&[]),
        Err(KalmanError::Core(CoreError::Empty { .. }))
    ));
    // an empty sequence filters to nothing (not an error)
    assert!(kf.filter(&state(), &[]).unwrap().is_empty());
    // the IKF reports the same checks
    let ikf = Ikf::new(&tr, &ob).unwrap();
    assert!(matches!(
        ikf.innovation(&state(), &Vector2::new(f64::NAN, 1.0)),
        Err(KalmanError::Core(CoreError::NonFinite { .. }))
    ));
    let _ = U5;
}

#[test]
fn errors_convert_into_the_core_error() {
    // a shared variant comes back as the core error itself
    let e: CoreError = KalmanError::Core(CoreError::Empty { what: "x" }).into();
    assert!(matches!(e, CoreError::Empty { what: "x" }), "{e:?}");
    // the filters' own variants are wrapped, naming the crate
    let e: CoreError = KalmanError::Undefined { what: "bearing" }.into();
    assert!(
        matches!(&e, CoreError::Method { method, .. } if method == "trajpred-kalman"),
        "{e:?}"
    );
    assert_eq!(e.to_string(), "trajpred-kalman: model undefined: bearing");
}
