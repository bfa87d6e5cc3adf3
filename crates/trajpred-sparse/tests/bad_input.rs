//! Bad and degenerate input: every error variant of the LARS builder is reached, and the
//! degenerate-but-valid cases (constant target, some constant columns, ties) give a
//! documented path instead of NaN or a panic.

#![allow(clippy::needless_range_loop)] // index loops mirror the knot/feature indices of the formulas

use nalgebra::DMatrix;
use trajpred_core::Error as CoreError;
use trajpred_sparse::{
    Error, ExclusionReason, Gram, Lars, LarsParams, Method, PathEvent, StopReason,
};

fn small() -> (DMatrix<f64>, Vec<f64>) {
    let x = DMatrix::from_row_slice(
        5,
        3,
        &[
            1.0, 2.0, 0.5, 2.0, 1.0, 1.5, 3.0, 5.0, 2.5, 4.0, 2.0, 0.0, 5.0, 4.0, 1.0,
        ],
    );
    (x, vec![1.0, 2.0, 4.0, 3.0, 6.0])
}

/// The default settings, and the design used as given with and without the Gram matrix
/// (whose diagonal then serves as the check of the design's entries).
fn settings() -> [LarsParams; 3] {
    let raw = Lars::params().fit_intercept(false).normalize(false);
    [
        Lars::params(),
        raw.clone().gram(Gram::Precompute),
        raw.gram(Gram::Never),
    ]
}

#[test]
fn nan_and_infinity_are_located() {
    for params in settings() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (mut x, y) = small();
            x[(3, 1)] = bad;
            assert!(
                matches!(
                    params.fit(&x, &y),
                    Err(Error::NonFiniteEntry {
                        what: "design",
                        row: 3,
                        col: 1
                    })
                ),
                "{params:?} {bad}"
            );
        }
        let (x, mut y) = small();
        y[2] = f64::INFINITY;
        assert!(matches!(
            params.fit(&x, &y),
            Err(Error::Core(CoreError::NonFinite {
                what: "target",
                index: 2
            }))
        ));
    }
}

#[test]
fn mismatched_and_empty_inputs() {
    let (x, y) = small();
    assert!(matches!(
        Lars::params().fit(&x, &y[..4]),
        Err(Error::Core(CoreError::DimensionMismatch {
            expected: 5,
            got: 4,
            ..
        }))
    ));
    assert!(matches!(
        Lars::params().fit(&DMatrix::zeros(0, 3), &[]),
        Err(Error::Core(CoreError::Empty { .. }))
    ));
    assert!(matches!(
        Lars::params().fit(&DMatrix::zeros(5, 0), &y),
        Err(Error::Core(CoreError::Empty { .. }))
    ));
    let fit = Lars::params().fit(&x, &y).expect("fit");
    assert!(matches!(
        fit.predict_row(&[1.0, 2.0]),
        Err(Error::Core(CoreError::DimensionMismatch {
            expected: 3,
            got: 2,
            ..
        }))
    ));
    assert!(matches!(
        fit.predict(&DMatrix::zeros(2, 4)),
        Err(Error::Core(CoreError::DimensionMismatch {
            expected: 3,
            got: 4,
            ..
        }))
    ));
    assert!(matches!(
        fit.predict_row(&[1.0, f64::NAN, 0.0]),
        Err(Error::Core(CoreError::NonFinite {
            what: "sample",
            index: 1
        }))
    ));
    assert!(matches!(
        fit.predict_row_at(99, &[1.0, 2.0, 0.0]),
        Err(Error::Core(CoreError::InvalidParameter {
            name: "knot",
            ..
        }))
    ));
}

#[test]
fn all_constant_columns_are_an_error() {
    let x = DMatrix::from_fn(6, 3, |_, j| j as f64 + 1.0);
    let y = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    assert!(matches!(
        Lars::params().fit(&x, &y),
        Err(Error::AllColumnsConstant { columns: 3 })
    ));
    // without an intercept a constant column is a legitimate regressor; a zero column is not
    assert!(Lars::params().fit_intercept(false).fit(&x, &y).is_ok());
    assert!(matches!(
        Lars::params()
            .fit_intercept(false)
            .fit(&DMatrix::zeros(6, 2), &y),
        Err(Error::AllColumnsConstant { columns: 2 })
    ));
    // one row with an intercept: every centred column is zero
    assert!(matches!(
        Lars::params().fit(&DMatrix::from_row_slice(1, 2, &[1.0, 2.0]), &[3.0]),
        Err(Error::AllColumnsConstant { .. })
    ));
}

#[test]
fn invalid_parameters() {
    let (x, y) = small();
    for params in [
        Lars::params().alpha_min(f64::NAN),
        Lars::params().alpha_min(-0.1),
        Lars::params().tie_tolerance(0.5),
        Lars::params().collinearity_tolerance(-1.0),
        Lars::params().vanish_tolerance(f64::INFINITY),
    ] {
        assert!(matches!(
            params.fit(&x, &y),
            Err(Error::Core(CoreError::InvalidParameter { .. }))
        ));
    }
}

#[test]
fn constant_column_is_excluded_and_reported() {
    let (x, y) = small();
    let mut x4 = x.clone().insert_column(1, 7.0);
    x4[(0, 1)] = 7.0;
    let fit = Lars::params().fit(&x4, &y).expect("fit");
    assert_eq!(fit.excluded().len(), 1);
    assert_eq!(fit.excluded()[0].feature, 1);
    assert_eq!(fit.excluded()[0].reason, ExclusionReason::ZeroVariance);
    assert!(fit.coef_path().column(1).iter().all(|&v| v == 0.0));
    // the other columns give the same path as without the constant column
    let reference = Lars::params().fit(&x, &y).expect("fit");
    let a = fit.coef_path().clone().remove_column(1);
    assert!((a - reference.coef_path()).amax() < 1e-12 * reference.coef_path().amax());
}

#[test]
fn constant_target_gives_the_single_zero_knot() {
    let (x, _) = small();
    let fit = Lars::params().fit(&x, &[2.5; 5]).expect("fit");
    assert_eq!(fit.n_knots(), 1);
    assert_eq!(fit.alphas(), &[0.0]);
    assert_eq!(fit.stop_reason(), StopReason::CorrelationVanished);
    assert_eq!(fit.predict_row(&[9.0, 9.0, 9.0]).expect("predict"), 2.5);
}

#[test]
fn exact_ties_enter_together() {
    // columns 0 and 1 are different but have exactly the same correlation with y
    let x = DMatrix::from_row_slice(
        4,
        3,
        &[
            1.0, 1.0, 0.0, 1.0, -1.0, 1.0, -1.0, 1.0, 0.0, -1.0, -1.0, -1.0,
        ],
    );
    let y = [2.0, 0.0, 0.0, -2.0];
    let fit = Lars::params()
        .fit_intercept(false)
        .normalize(false)
        .method(Method::Lar)
        .fit(&x, &y)
        .expect("fit");
    let first: Vec<usize> = fit
        .events()
        .iter()
        .filter_map(|e| match e {
            PathEvent::Added { feature, step: 1 } => Some(*feature),
            _ => None,
        })
        .collect();
    assert_eq!(first, vec![0, 1]);
    assert!(fit.coef_path().iter().all(|v| v.is_finite()));
}

#[test]
fn max_steps_zero_and_alpha_min_above_the_start() {
    let (x, y) = small();
    let fit = Lars::params().max_steps(0).fit(&x, &y).expect("fit");
    assert_eq!(fit.n_knots(), 1);
    assert_eq!(fit.stop_reason(), StopReason::MaxSteps);
    let fit = Lars::params().alpha_min(1e6).fit(&x, &y).expect("fit");
    assert_eq!(fit.alphas(), &[1e6]);
    assert_eq!(fit.stop_reason(), StopReason::AlphaMin);
    assert!(fit.coef().iter().all(|&v| v == 0.0));
}

#[test]
fn overflowing_column_is_reported() {
    for params in settings() {
        let (mut x, y) = small();
        x[(2, 2)] = 1e200;
        assert!(matches!(
            params.fit(&x, &y),
            Err(Error::Overflow { col: 2 })
        ));
    }
}

/// A target whose sum overflows used to give an infinite intercept and no error; now the
/// overflow is a `NonFinite` naming the target and the row where the running sum overflows.
#[test]
fn overflowing_target_is_an_error_not_inf() {
    let (x, _) = small();
    let y = vec![1e308; 5];
    match Lars::params().fit(&x, &y) {
        Err(Error::Core(CoreError::NonFinite { what, index: 1 })) => {
            assert!(what.contains("target sum"), "{what}")
        }
        other => panic!("{other:?}"),
    }
    // without an intercept the sum is not needed, but the squared norm overflows
    match Lars::params().fit_intercept(false).fit(&x, &y) {
        Err(Error::Core(CoreError::NonFinite { what, index: 0 })) => {
            assert!(what.contains("squared norm"), "{what}")
        }
        other => panic!("{other:?}"),
    }
    // a finite mean, but the centred values' squares overflow
    let y = vec![1e200, -1e200, 1e200, -1e200, 0.0];
    match Lars::params().fit(&x, &y) {
        Err(Error::Core(CoreError::NonFinite { what, index: 0 })) => {
            assert!(what.contains("squared norm"), "{what}")
        }
        other => panic!("{other:?}"),
    }
    // large but representable: a finite path
    let y: Vec<f64> = [1.0, 2.0, 4.0, 3.0, 6.0]
        .iter()
        .map(|v| v * 1e150)
        .collect();
    let fit = Lars::params().fit(&x, &y).unwrap();
    assert!(fit.coef_path().iter().all(|v| v.is_finite()));
    assert!(fit.intercepts().iter().all(|v| v.is_finite()));
    assert!(fit.alphas().iter().all(|v| v.is_finite()));
}

/// Tiny columns (norm ~1e-160) with a huge target: the standardised path is finite but its
/// coefficients on the original scale overflow; that is an error naming the path.
#[test]
fn overflowing_path_is_an_error_not_inf() {
    let (x, y) = small();
    let x = x.map(|v| v * 1e-160);
    let y: Vec<f64> = y.iter().map(|v| v * 1e150).collect();
    match Lars::params().fit(&x, &y) {
        Err(
            Error::Core(CoreError::NonFinite { what, .. }) | Error::NonFiniteEntry { what, .. },
        ) => {
            assert!(what.contains("path"), "{what}")
        }
        other => panic!("{other:?}"),
    }
}
