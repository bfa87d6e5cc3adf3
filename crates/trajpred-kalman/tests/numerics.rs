//! Numerical edge cases and the speed paths held to the general ones: structured covariance
//! propagation and the selection update against the dense products, batch sigma-point images,
//! covariances at every scale, and log-likelihoods whose determinant under- or overflows.

use nalgebra::{
    Const, DMatrix, DVector, Matrix1, Matrix1x2, Matrix1x4, Matrix2, Matrix2x4, Matrix4, Matrix5,
    SMatrix, SVector, U2, U3, U4, U6, Vector2, Vector4, Vector5,
};
use rand::RngExt;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_acceleration, constant_velocity, position_observation,
};
use trajpred_kalman::sampling::covariance_sqrt;
use trajpred_kalman::{
    CoordinatedTurn, Ekf, Filter, InputChecks, KalmanError, Kf, LinearObservation,
    LinearTransition, Observation, RangeBearing, Transition,
};

mod common;
use common::{assert_close, cv2_models};

#[test]
fn structured_propagation_equals_the_dense_products() {
    use nalgebra::Dyn;
    use trajpred_kalman::LinearTransitionModel;
    for derivatives in [2usize, 3] {
        for axes in 1..=3 {
            for order in [StateOrder::AxisBlocks, StateOrder::PositionsFirst] {
                let n = axes * derivatives;
                let tr: LinearTransition<f64, Dyn> = if derivatives == 2 {
                    constant_velocity(axes, 0.3, 0.7, order).unwrap()
                } else {
                    constant_acceleration(axes, 0.3, 0.7, order).unwrap()
                };
                assert!(tr.has_structured_propagation());
                let a = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 5) as f64 * 0.3 - 0.5);
                let p = &a * a.transpose() + DMatrix::identity(n, n);
                let x = DVector::from_fn(n, |i, _| i as f64 - 1.5);
                let (f, q) = (tr.f(), tr.q());
                let dense = f * &p * f.transpose() + (q + q.transpose()) * 0.5;
                let got = tr.propagate_covariance(&p);
                assert_close(&got, &dense, 1e-13, "F P F^T + Q");
                assert_eq!(got, got.transpose(), "exactly symmetric");
                assert_close(&tr.propagate_mean(&x), &(f * &x), 1e-14, "F x");
            }
        }
    }
    // a unit-diagonal F whose row updates cannot run in place (the update of row 0 reads row
    // 1, which an earlier entry updates): the structured path with a copy
    let coupled = LinearTransition::new(
        Matrix2::new(1.0, 0.3, 0.2, 1.0),
        Matrix2::new(0.5, 0.1, 0.1, 0.4),
    )
    .unwrap();
    assert!(coupled.has_structured_propagation());
    let p = Matrix2::new(2.0, -0.7, -0.7, 1.5);
    let (f, q) = (coupled.f(), coupled.q());
    let got = coupled.propagate_covariance(&p);
    assert_close(
        &got,
        &(f * p * f.transpose() + q),
        1e-14,
        "coupled F P F^T + Q",
    );
    assert_eq!(got, got.transpose(), "exactly symmetric");
    // a general F keeps the dense products
    let dense =
        LinearTransition::new(Matrix2::new(0.9, 0.1, -0.2, 1.0), Matrix2::identity()).unwrap();
    assert!(!dense.has_structured_propagation());
    // every path of `LinearTransition` mirrors (its `mirrors_covariance` is `true`): the
    // two triangles equal bit for bit, for the dense products of static and run-time sizes
    // and for the KF's prediction through the factorisation of `P`
    let bits_symmetric = |m: &DMatrix<f64>| {
        (0..m.nrows()).all(|i| (0..i).all(|j| m[(i, j)].to_bits() == m[(j, i)].to_bits()))
    };
    let f = Matrix4::from_fn(|i, j| ((i * 3 + j * 5) as f64).sin() * 0.7 + (i == j) as u8 as f64);
    let a = Matrix4::from_fn(|i, j| ((i * 7 + j * 2 + 1) as f64).cos());
    let (p, q) = (
        a * a.transpose() + Matrix4::identity(),
        a.transpose() * a * 0.1,
    );
    let q = (q + q.transpose()) * 0.5;
    let tr = LinearTransition::new(f, q).unwrap();
    let dyn_tr = LinearTransition::new(
        DMatrix::from_column_slice(4, 4, f.as_slice()),
        DMatrix::from_column_slice(4, 4, q.as_slice()),
    )
    .unwrap();
    assert!(tr.mirrors_covariance() && dyn_tr.mirrors_covariance());
    assert!(!tr.has_structured_propagation());
    let to_dyn = |m: &Matrix4<f64>| DMatrix::from_column_slice(4, 4, m.as_slice());
    assert!(bits_symmetric(&to_dyn(&tr.propagate_covariance(&p))));
    assert!(bits_symmetric(&dyn_tr.propagate_covariance(&to_dyn(&p))));
    let ob = LinearObservation::new(Matrix2x4::identity(), Matrix2::identity()).unwrap();
    let x = Gaussian {
        mean: Vector4::new(1.0, -2.0, 0.5, 3.0),
        covariance: p,
    };
    for checks in [InputChecks::Full, InputChecks::Cheap] {
        let kf = Kf::new(&tr, &ob).unwrap().with_input_checks(checks);
        assert!(bits_symmetric(&to_dyn(&kf.predict(&x).unwrap().covariance)));
    }
}

/// The KF's update (and step) on the selection picks against the EKF's general products on
/// the same linear models.
fn check_selection_update<D: nalgebra::DimName, M: nalgebra::DimName>(
    tr: &LinearTransition<f64, D>,
    ob: &LinearObservation<f64, D, M>,
) where
    nalgebra::DefaultAllocator: nalgebra::allocator::Allocator<D>
        + nalgebra::allocator::Allocator<D, D>
        + nalgebra::allocator::Allocator<M>
        + nalgebra::allocator::Allocator<M, M>
        + nalgebra::allocator::Allocator<D, M>
        + nalgebra::allocator::Allocator<M, D>,
{
    use nalgebra::OMatrix;
    use trajpred_kalman::LinearObservationModel;
    assert!(ob.selected_components().is_some());
    let kf = Kf::new(tr, ob).unwrap();
    let ekf = Ekf::new(tr, ob).unwrap();
    let a = OMatrix::<f64, D, D>::from_fn(|i, j| ((i * 5 + j * 3) % 7) as f64 * 0.2 - 0.6);
    let state = Gaussian {
        mean: OMatrix::<f64, D, nalgebra::U1>::from_fn(|i, _| (i as f64 * 1.3).sin() * 2.0),
        covariance: &a * a.transpose() + OMatrix::<f64, D, D>::identity() * 0.1,
    };
    let z = OMatrix::<f64, M, nalgebra::U1>::from_fn(|i, _| 1.07 - 3.02 * i as f64);
    let (u, v) = (
        kf.update(&state, &z).unwrap(),
        ekf.update(&state, &z).unwrap(),
    );
    let (s, t) = (
        kf.step(&state, Some(&z)).unwrap(),
        ekf.step(&state, Some(&z)).unwrap(),
    );
    for (u, v) in [
        (&u, &v),
        (s.update.as_ref().unwrap(), t.update.as_ref().unwrap()),
    ] {
        assert_close(&u.posterior.mean, &v.posterior.mean, 1e-13, "mean");
        assert_close(&u.posterior.covariance, &v.posterior.covariance, 1e-13, "P");
        assert_close(&u.innovation, &v.innovation, 1e-14, "y");
        assert_close(
            &u.innovation_covariance,
            &v.innovation_covariance,
            1e-14,
            "S",
        );
        assert_close(&u.gain, &v.gain, 1e-13, "K");
        assert!((u.log_likelihood() - v.log_likelihood()).abs() < 1e-12);
    }
    assert_close(&s.prior.covariance, &t.prior.covariance, 1e-13, "prior P");
}

#[test]
fn selection_update_equals_the_general_update() {
    // the KF picks H x, H P, H P H^T for an observation that selects state components (with
    // the indices as constants for the strides 1 to 3 of the kinematic positions, from a
    // table otherwise); the EKF with the same linear models takes the general products
    for order in [StateOrder::AxisBlocks, StateOrder::PositionsFirst] {
        // strides 2 and 1
        let tr: LinearTransition<f64, U4> = constant_velocity(2, 0.1, 0.5, order).unwrap();
        let layout = KinematicLayout::new(2, 2, order).unwrap();
        let ob: LinearObservation<f64, U4, U2> = position_observation(layout, 0.3).unwrap();
        check_selection_update(&tr, &ob);
        // strides 3 and 1
        let tr: LinearTransition<f64, U6> = constant_acceleration(2, 0.1, 0.5, order).unwrap();
        let layout = KinematicLayout::new(2, 3, order).unwrap();
        let ob: LinearObservation<f64, U6, U2> = position_observation(layout, 0.3).unwrap();
        check_selection_update(&tr, &ob);
        // three axes, strides 2 and 1
        let tr: LinearTransition<f64, U6> = constant_velocity(3, 0.1, 0.5, order).unwrap();
        let layout = KinematicLayout::new(3, 2, order).unwrap();
        let ob: LinearObservation<f64, U6, U3> = position_observation(layout, 0.3).unwrap();
        check_selection_update(&tr, &ob);
    }
    // other selections: the velocities, the positions swapped, one position (index 2)
    let tr: LinearTransition<f64, U4> =
        constant_velocity(2, 0.1, 0.5, StateOrder::AxisBlocks).unwrap();
    let r = Matrix2::new(0.3, 0.05, 0.05, 0.2);
    for (i, j) in [(1, 3), (2, 0)] {
        let mut h = Matrix2x4::zeros();
        h[(0, i)] = 1.0;
        h[(1, j)] = 1.0;
        check_selection_update(&tr, &LinearObservation::new(h, r).unwrap());
    }
    let h = Matrix1x4::new(0.0, 0.0, 1.0, 0.0);
    check_selection_update(&tr, &LinearObservation::new(h, Matrix1::new(0.3)).unwrap());
    // run-time sizes: a stride (positions of axis blocks) and a general selection
    use nalgebra::Dyn;
    let tr: LinearTransition<f64, Dyn> =
        constant_velocity(2, 0.1, 0.5, StateOrder::AxisBlocks).unwrap();
    let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks).unwrap();
    let strided: LinearObservation<f64, Dyn, Dyn> = position_observation(layout, 0.3).unwrap();
    let general = LinearObservation::new(
        DMatrix::from_row_slice(2, 4, &[0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
        DMatrix::from_row_slice(2, 2, &[0.3, 0.05, 0.05, 0.2]),
    )
    .unwrap();
    let a = DMatrix::from_fn(4, 4, |i, j| ((i * 5 + j * 3) % 7) as f64 * 0.2 - 0.6);
    let state = Gaussian {
        mean: DVector::from_fn(4, |i, _| (i as f64 * 1.3).sin() * 2.0),
        covariance: &a * a.transpose() + DMatrix::identity(4, 4) * 0.1,
    };
    let z = DVector::from_row_slice(&[1.07, -1.95]);
    for ob in [&strided, &general] {
        use trajpred_kalman::LinearObservationModel;
        assert!(ob.selected_components().is_some());
        let u = Kf::new(&tr, ob).unwrap().step(&state, Some(&z)).unwrap();
        let v = Ekf::new(&tr, ob).unwrap().step(&state, Some(&z)).unwrap();
        let (u, v) = (u.update.unwrap(), v.update.unwrap());
        assert_close(&u.posterior.mean, &v.posterior.mean, 1e-13, "mean");
        assert_close(&u.posterior.covariance, &v.posterior.covariance, 1e-13, "P");
        assert_close(&u.gain, &v.gain, 1e-13, "K");
    }
    // a general H is not a selection
    let ob = LinearObservation::new(Matrix1x2::new(1.0, 0.5), Matrix1::new(0.25)).unwrap();
    use trajpred_kalman::LinearObservationModel;
    assert!(ob.selected_components().is_none());
}

#[test]
fn batch_sigma_point_images_equal_the_per_point_ones() {
    let ct = CoordinatedTurn::new(0.5, 0.2, 1e-3).unwrap();
    let rb = RangeBearing::new(Vector2::new(-20.0, 15.0), 0, 2, 0.5, 1e-3).unwrap();
    let x = Vector5::new(0.5, 7.0, -0.5, 2.5, 0.1);
    // a lower-triangular spread with the turn rate correlated to everything, and one with
    // the turn rate uncorrelated (shared sin/cos) and a zero turn rate (series branch)
    let full = Matrix5::from_fn(|i, j| {
        if i >= j {
            0.3 + 0.1 * (i + 2 * j) as f64
        } else {
            0.0
        }
    });
    let mut diag = Matrix5::from_diagonal(&Vector5::new(1.4, 1.0, 1.4, 1.0, 0.1));
    diag[(4, 4)] = 0.1;
    for (l, x) in [
        (full, x),
        (diag, x),
        (full, Vector5::new(0.5, 7.0, -0.5, 2.5, 0.0)),
    ] {
        let t = ct.transition_sigma_points(&x, &l).unwrap();
        let o = rb.observe_sigma_points(&x, &l).unwrap();
        assert_close(&t.center, &ct.transition(&x).unwrap(), 1e-14, "f(x)");
        assert_close(
            &o.center,
            &Observation::<f64, Const<5>, U2>::observe(&rb, &x).unwrap(),
            1e-14,
            "h(x)",
        );
        for j in 0..5 {
            for (sign, img, oimg) in [(1.0, &t.plus, &o.plus), (-1.0, &t.minus, &o.minus)] {
                let xj = x + l.column(j) * sign;
                let want = ct.transition(&xj).unwrap();
                assert_close(&img.column(j).into_owned(), &want, 1e-12, "f(x +- L_j)");
                let want = Observation::<f64, Const<5>, U2>::observe(&rb, &xj).unwrap();
                assert_close(&oimg.column(j).into_owned(), &want, 1e-14, "h(x +- L_j)");
            }
        }
    }
}

#[test]
fn predict_accepts_and_rejects_p_at_every_scale() {
    // P = V diag(e) V^T with a seeded random orthogonal V: the fast definiteness check of the
    // predict (leading minors for a structured F, L D L^T fused with F P F^T for a dense F)
    // must agree with the exact check whatever the scale, including scales at which the
    // minors of a 4 x 4 matrix (the 4th power of the entries) under- or overflow and the
    // check falls back to the exact one
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let g = Matrix4::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal));
    let v = g.qr().q();
    let (structured, ob) = cv2_models();
    let dense_f = Matrix4::new(
        1.0, 0.1, 0.02, 0.0, 0.0, 0.9, 0.1, 0.0, 0.05, 0.0, 1.0, 0.2, 0.0, 0.0, 0.1, 0.8,
    );
    let dense = LinearTransition::new(dense_f, *structured.q()).unwrap();
    let kfs = [
        Kf::new(structured.clone(), ob.clone()).unwrap(),
        Kf::new(dense, ob).unwrap(),
    ];
    let cases: [([f64; 4], bool); 5] = [
        ([1.0, 0.5, 0.2, 0.1], true),
        ([1.0, 1e-12, 0.3, 0.2], true), // positive definite, ill-conditioned
        ([1.0, 0.0, 0.3, 0.2], true),   // semi-definite: accepted by the KF
        ([1.0, -1e-6, 0.3, 0.2], false),
        ([1.0, -0.5, 0.3, 0.2], false),
    ];
    for scale in [1e-150, 1e-20, 1.0, 1e20, 1e150] {
        for (eig, accept) in cases {
            let p = v * Matrix4::from_diagonal(&Vector4::from(eig)) * v.transpose() * scale;
            let p = (p + p.transpose()) * 0.5;
            let state = Gaussian {
                mean: Vector4::new(1.0, 2.0, 3.0, 4.0),
                covariance: p,
            };
            for kf in &kfs {
                let r = kf.predict(&state);
                if accept {
                    let pred = r.unwrap_or_else(|e| panic!("{eig:?} x {scale:e}: {e}"));
                    // the prediction of the path without the fast check (the same
                    // products for the structured F; for the dense F the fused
                    // `F L D L^T F^T` against `F P F^T`, equal to rounding)
                    let cheap = kf
                        .clone()
                        .with_input_checks(InputChecks::Cheap)
                        .predict(&state)
                        .unwrap();
                    assert_eq!(pred.mean, cheap.mean);
                    let size = cheap.covariance.amax();
                    let diff = (pred.covariance - cheap.covariance).amax();
                    assert!(diff <= 1e-12 * size, "{eig:?} x {scale:e}: {diff:e}");
                } else {
                    assert!(
                        matches!(
                            r,
                            Err(KalmanError::Core(CoreError::NotPositiveDefinite {
                                what: "P"
                            }))
                        ),
                        "{eig:?} x {scale:e}: {r:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn dense6_predict_accepts_and_rejects_p_at_every_scale() {
    // the 6-state dense F (on machines with AVX2 or AVX-512, the SIMD `F P F^T` after the
    // leading-minors check): the same verdicts as the exact check at every scale, and the
    // prediction equal to rounding to the one of the cheap path (the SIMD product without
    // the check) and to nalgebra's `F P F^T + Q`; the cheap path, which does not verify
    // definiteness, gives that product for the indefinite P too
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    let v = SMatrix::<f64, 6, 6>::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal))
        .qr()
        .q();
    let f = SMatrix::<f64, 6, 6>::from_fn(|_, _| 0.3 * rng.sample::<f64, _>(StandardNormal));
    let q = SMatrix::<f64, 6, 6>::from_fn(|i, j| if i == j { 0.01 } else { 0.0 });
    let h = SMatrix::<f64, 3, 6>::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal));
    let kf = Kf::new(
        LinearTransition::new(f, q).unwrap(),
        LinearObservation::new(h, SMatrix::<f64, 3, 3>::identity()).unwrap(),
    )
    .unwrap();
    let cases: [([f64; 6], bool); 5] = [
        ([1.0, 0.5, 0.2, 0.1, 2.0, 0.7], true),
        ([1.0, 1e-12, 0.3, 0.2, 0.5, 0.4], true),
        ([1.0, 0.0, 0.3, 0.2, 0.5, 0.4], true),
        ([1.0, -1e-6, 0.3, 0.2, 0.5, 0.4], false),
        ([1.0, 0.5, 0.3, 0.2, -0.5, 0.4], false),
    ];
    for scale in [1e-150, 1e-40, 1.0, 1e40, 1e150] {
        for (eig, accept) in cases {
            let p = v * SMatrix::<f64, 6, 6>::from_diagonal(&eig.into()) * v.transpose() * scale;
            let p = (p + p.transpose()) * 0.5;
            let state = Gaussian {
                mean: SVector::<f64, 6>::from_fn(|i, _| i as f64),
                covariance: p,
            };
            let r = kf.predict(&state);
            let cheap = kf
                .clone()
                .with_input_checks(InputChecks::Cheap)
                .predict(&state)
                .unwrap();
            let reference = f * p * f.transpose() + q;
            let (size, diff) = (reference.amax(), (cheap.covariance - reference).amax());
            assert!(diff <= 1e-12 * size, "cheap {eig:?} x {scale:e}: {diff:e}");
            assert_eq!(cheap.covariance, cheap.covariance.transpose());
            if accept {
                let pred = r.unwrap_or_else(|e| panic!("{eig:?} x {scale:e}: {e}"));
                assert_eq!(pred.mean, cheap.mean);
                assert_eq!(pred.covariance, pred.covariance.transpose());
                let size = cheap.covariance.amax();
                let diff = (pred.covariance - cheap.covariance).amax();
                assert!(diff <= 1e-12 * size, "{eig:?} x {scale:e}: {diff:e}");
            } else {
                assert!(
                    matches!(
                        r,
                        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
                            what: "P"
                        }))
                    ),
                    "{eig:?} x {scale:e}: {r:?}"
                );
            }
        }
    }
}

#[test]
fn covariance_sqrt_of_zero_is_zero() {
    let z = covariance_sqrt(&Matrix2::<f64>::zeros(), "Q").unwrap();
    assert_eq!(z, Matrix2::zeros());
}

#[test]
fn log_likelihood_when_det_s_under_or_overflows() {
    // H = I, P = 0, R = s I (3 x 3): S = s I, y = (sqrt(s), 0, 0), so NIS = 1 and
    // ln N(y; 0, S) = -(3 ln 2 pi + 3 ln s + 1) / 2; det S = s^3 underflows (s = 1e-110) or
    // overflows (s = 1e110) and the log-determinant is then summed over the pivots
    use nalgebra::{Matrix3, Vector3};
    for s in [1e-110, 1.0, 1e110] {
        let tr = LinearTransition::new(Matrix3::<f64>::identity(), Matrix3::zeros()).unwrap();
        let ob =
            LinearObservation::new(Matrix3::<f64>::identity(), Matrix3::identity() * s).unwrap();
        let kf = Kf::new(tr, ob).unwrap();
        let x = Gaussian {
            mean: Vector3::zeros(),
            covariance: Matrix3::zeros(),
        };
        let u = kf.update(&x, &Vector3::new(s.sqrt(), 0.0, 0.0)).unwrap();
        assert!((u.nis - 1.0).abs() < 1e-15, "{s:e}: {}", u.nis);
        let two_pi = 2.0 * std::f64::consts::PI;
        let want = -(3.0 * two_pi.ln() + 3.0 * s.ln() + 1.0) / 2.0;
        let got = u.log_likelihood();
        assert!(
            (got - want).abs() <= 1e-12 * want.abs(),
            "{s:e}: {got} vs {want}"
        );
    }
}

#[test]
fn two_by_two_innovation_covariance_at_every_scale() {
    // H = I, P = s I, R = s [[2, 1], [1, 2]]: S = s [[3, 1], [1, 3]], worked by hand:
    // K = P S^-1 = [[3, -1], [-1, 3]] / 8 at every scale, posterior covariance
    // (I - K) P = s [[5, 1], [1, 5]] / 8, and for y = sqrt(s) (1, 2) the NIS is
    // (3 - 4 + 12) / 8 = 11 / 8 and ln N(y; 0, S) = -(2 ln 2 pi + ln 8 + 2 ln s + 11 / 8) / 2.
    // det S = 8 s^2 is a normal number for s = 1e-100 .. 1e100 (the closed-form 2 x 2
    // factors) and sub-normal (s = 1e-160) or infinite (s = 1e160) otherwise (the general
    // elimination); every scale gives the same relative figures.
    use nalgebra::Matrix2;
    for s in [1e-160, 1e-100, 1e-3, 1.0, 1e3, 1e100, 1e160] {
        let tr = LinearTransition::new(Matrix2::<f64>::identity(), Matrix2::zeros()).unwrap();
        let ob = LinearObservation::new(
            Matrix2::<f64>::identity(),
            Matrix2::new(2.0, 1.0, 1.0, 2.0) * s,
        )
        .unwrap();
        let kf = Kf::new(tr, ob).unwrap();
        let x = Gaussian {
            mean: Vector2::zeros(),
            covariance: Matrix2::identity() * s,
        };
        let z = Vector2::new(1.0, 2.0) * s.sqrt();
        let u = kf.update(&x, &z).unwrap();
        let k = Matrix2::new(3.0, -1.0, -1.0, 3.0) / 8.0;
        assert!((u.gain - k).amax() < 1e-15, "{s:e}: K {}", u.gain);
        let post = Matrix2::new(5.0, 1.0, 1.0, 5.0) / 8.0;
        assert!(
            (u.posterior.covariance / s - post).amax() < 1e-15,
            "{s:e}: P {}",
            u.posterior.covariance
        );
        assert!((u.nis - 11.0 / 8.0).abs() < 1e-15, "{s:e}: NIS {}", u.nis);
        let two_pi = 2.0 * std::f64::consts::PI;
        let want = -(2.0 * two_pi.ln() + 8f64.ln() + 2.0 * s.ln() + 11.0 / 8.0) / 2.0;
        let got = u.log_likelihood();
        assert!(
            (got - want).abs() <= 1e-13 * want.abs().max(1.0),
            "{s:e}: {got} vs {want}"
        );
    }
    // a prior whose S = H P H^T + R is indefinite (update_predicted skips the check of P):
    // P = [[1, 3], [3, 1]] (eigenvalues 4 and -2), R = I / 10
    let tr = LinearTransition::new(Matrix2::<f64>::identity(), Matrix2::zeros()).unwrap();
    let ob = LinearObservation::new(Matrix2::<f64>::identity(), Matrix2::identity() * 0.1).unwrap();
    let kf = Kf::new(tr, ob).unwrap();
    let bad = Gaussian {
        mean: Vector2::zeros(),
        covariance: Matrix2::new(1.0, 3.0, 3.0, 1.0),
    };
    assert!(matches!(
        kf.update_predicted(&bad, &Vector2::zeros()),
        Err(KalmanError::Core(CoreError::NotPositiveDefinite {
            what: "S"
        }))
    ));
}
