//! Group sparse coding on the trajectory of the GSKF paper (eq. 20) and against least squares.

#![allow(clippy::needless_range_loop)] // index loops mirror the horizon/window indices

use nalgebra::{DMatrix, DVector};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use trajpred_core::Error as CoreError;
use trajpred_sparse::{Error, GroupSparseCoder, Lars};

/// Eq. (20): x = 2 sin(0.1 t), y = sin(t) cos(0.1 t), z = 2 sin(t) cos(2 t), t_i = 0.01 pi i.
fn eq20() -> [Vec<f64>; 3] {
    let t: Vec<f64> = (0..1000)
        .map(|i| 0.01 * std::f64::consts::PI * i as f64)
        .collect();
    [
        t.iter().map(|t| 2.0 * (0.1 * t).sin()).collect(),
        t.iter().map(|t| t.sin() * (0.1 * t).cos()).collect(),
        t.iter().map(|t| 2.0 * t.sin() * (2.0 * t).cos()).collect(),
    ]
}

#[test]
fn noise_free_eq20_is_predicted_exactly_for_every_horizon() {
    // `docs/papers.md` A.5: each axis is a sum of sinusoids, an exact linear recurrence of order 2
    // (x) or 4 (y, z), so with m = 6 a full path predicts the test part to rounding error. The
    // bound 1e-9 m is the issue's; the values are O(1) m.
    let (m, horizons) = (6, 6);
    for (axis, series) in eq20().iter().enumerate() {
        let gsc = GroupSparseCoder::params(m, horizons)
            .fit(&series[..800])
            .expect("fit");
        let mut worst: f64 = 0.0;
        for origin in 799..(1000 - horizons) {
            let pred = gsc
                .predict(&series[origin + 1 - m..=origin])
                .expect("predict");
            for t in 1..=horizons {
                worst = worst.max((pred[t - 1] - series[origin + t]).abs());
            }
        }
        assert!(worst < 1e-9, "axis {axis}: worst error {worst:e} m");
        for v in gsc.residual_variances() {
            assert!(*v < 1e-18);
        }
    }
}

#[test]
fn with_noise_the_full_path_is_least_squares_per_horizon() {
    // The end of a full LAR path is the least-squares fit with intercept. Reference: nalgebra's
    // SVD solve on [1 | D_t] (independent of the LARS code). Tolerance 1e-8 relative: the
    // windows of a slowly varying series are strongly correlated (condition number ~1e3 here),
    // so both solutions carry ~cond * eps relative rounding.
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let noise = Normal::new(0.0, 0.05).expect("normal");
    let [x, _, z] = eq20();
    for series in [x, z] {
        let noisy: Vec<f64> = series.iter().map(|v| v + noise.sample(&mut rng)).collect();
        let (m, horizons) = (6, 8); // T > m is allowed
        let gsc = GroupSparseCoder::params(m, horizons)
            .fit(&noisy[..800])
            .expect("fit");
        for t in 1..=horizons {
            let d = trajpred_core::window::hankel_design(&noisy[..800], m, t).expect("design");
            let p = d.design.nrows();
            let aug = DMatrix::from_fn(
                p,
                m + 1,
                |i, j| if j == 0 { 1.0 } else { d.design[(i, j - 1)] },
            );
            let ls = aug.svd(true, true).solve(&d.target, 1e-14).expect("ls");
            let ours = gsc.coefficients().row(t - 1);
            for k in 0..m {
                let err = (ours[k] - ls[k + 1]).abs();
                assert!(err < 1e-8 * ls.rows(1, m).amax(), "t={t} k={k}: {err:e}");
            }
            assert!((gsc.intercepts()[t - 1] - ls[0]).abs() < 1e-8 * ls.amax());
            // residual variance = mean squared LS residual
            let resid = &d.target - &aug_times(&d.design, &ls);
            let var = resid.norm_squared() / p as f64;
            assert!((gsc.residual_variances()[t - 1] - var).abs() < 1e-8 * var);
            assert!(gsc.path(t).is_some());
        }
    }
}

fn aug_times(design: &DMatrix<f64>, ls: &DVector<f64>) -> DVector<f64> {
    let m = design.ncols();
    let mut out = design * ls.rows(1, m);
    out.add_scalar_mut(ls[0]);
    out
}

#[test]
fn parallel_and_serial_fits_are_identical() {
    let [_, y, _] = eq20();
    let a = GroupSparseCoder::params(8, 10).fit(&y).expect("parallel");
    let b = GroupSparseCoder::params(8, 10)
        .parallel(false)
        .fit(&y)
        .expect("serial");
    assert_eq!(a.coefficients(), b.coefficients());
    assert_eq!(a.intercepts(), b.intercepts());
}

#[test]
fn sparse_paths_are_used_when_asked() {
    let [x, _, _] = eq20();
    let gsc = GroupSparseCoder::params(6, 3)
        .lars(Lars::params().max_steps(1))
        .fit(&x[..800])
        .expect("fit");
    for t in 0..3 {
        let nonzero = gsc
            .coefficients()
            .row(t)
            .iter()
            .filter(|v| **v != 0.0)
            .count();
        assert_eq!(nonzero, 1);
    }
}

#[test]
fn constant_series_predicts_the_constant() {
    let gsc = GroupSparseCoder::params(3, 2).fit(&[4.0; 20]).expect("fit");
    assert_eq!(
        gsc.predict(&[4.0, 4.0, 4.0]).expect("predict"),
        vec![4.0, 4.0]
    );
    assert!(gsc.coefficients().iter().all(|&v| v == 0.0));
    assert_eq!(gsc.residual_variances(), &[0.0, 0.0]);
}

#[test]
fn bad_input_is_typed() {
    let s: Vec<f64> = (0..10).map(f64::from).collect();
    assert!(matches!(
        GroupSparseCoder::params(0, 2).fit(&s),
        Err(Error::Core(CoreError::InvalidParameter {
            name: "window",
            ..
        }))
    ));
    assert!(matches!(
        GroupSparseCoder::params(3, 0).fit(&s),
        Err(Error::Core(CoreError::InvalidParameter {
            name: "horizons",
            ..
        }))
    ));
    assert!(matches!(
        GroupSparseCoder::params(5, 5).fit(&s),
        Err(Error::Core(CoreError::TooShort {
            what: "series for group sparse coding",
            needed: 11,
            got: 10
        }))
    ));
    let mut bad = s.clone();
    bad[4] = f64::NAN;
    assert!(matches!(
        GroupSparseCoder::params(2, 2).fit(&bad),
        Err(Error::NonFiniteEntry {
            what: "series",
            row: 4,
            col: 0
        })
    ));
    let gsc = GroupSparseCoder::params(2, 2).fit(&s).expect("fit");
    assert!(matches!(
        gsc.predict(&[1.0]),
        Err(Error::Core(CoreError::DimensionMismatch {
            expected: 2,
            got: 1,
            ..
        }))
    ));
    assert!(matches!(
        gsc.predict_next(&[1.0]),
        Err(Error::Core(CoreError::TooShort { .. }))
    ));
    assert!(matches!(
        gsc.predict(&[1.0, f64::INFINITY]),
        Err(Error::Core(CoreError::NonFinite {
            what: "window",
            index: 1
        }))
    ));
}
