//! Every metric against values worked by hand (the arithmetic is in the comments).

use approx::assert_abs_diff_eq;
use nalgebra::{DMatrix, DVector, dmatrix, dvector};
use trajpred_core::Error as CoreError;
use trajpred_metrics::*;

/// The shared error a metric returned, which must be one (a `MetricsError::Core`).
fn core_error<T: std::fmt::Debug>(r: Result<T>) -> CoreError {
    match r {
        Err(MetricsError::Core(e)) => e,
        other => panic!("expected a shared error, got {other:?}"),
    }
}

// Three 3-D points; errors (pred - truth): (1,2,2) |3|, (0,0,0) |0|, (2,3,6) |7|.
const TRUTH: [[f64; 3]; 3] = [[1.0, 1.0, 1.0], [2.0, -1.0, 4.0], [-1.0, 2.0, 0.5]];
const PRED: [[f64; 3]; 3] = [[2.0, 3.0, 3.0], [2.0, -1.0, 4.0], [1.0, 5.0, 6.5]];

#[test]
fn euclidean_errors_by_hand() {
    assert_eq!(
        euclidean_errors(&PRED, &TRUTH).unwrap(),
        vec![3.0, 0.0, 7.0]
    );
}

#[test]
fn per_axis_rmse_by_hand() {
    // x: (1, 0, 2) -> sqrt(5/3); y: (2, 0, 3) -> sqrt(13/3); z: (2, 0, 6) -> sqrt(40/3)
    let r = rmse(&PRED, &TRUTH).unwrap();
    assert_abs_diff_eq!(r[0], (5.0f64 / 3.0).sqrt(), epsilon = 1e-15);
    assert_abs_diff_eq!(r[1], (13.0f64 / 3.0).sqrt(), epsilon = 1e-15);
    assert_abs_diff_eq!(r[2], (40.0f64 / 3.0).sqrt(), epsilon = 1e-15);
}

#[test]
fn rmse_3d_is_eq_21() {
    // (9 + 0 + 49) / 3 = 58/3
    assert_abs_diff_eq!(
        rmse_3d(&PRED, &TRUTH).unwrap(),
        (58.0f64 / 3.0).sqrt(),
        epsilon = 1e-15
    );
    // and the per-axis RMSEs combine to it: 5/3 + 13/3 + 40/3 = 58/3
    let r = rmse(&PRED, &TRUTH).unwrap();
    assert_abs_diff_eq!(
        r.iter().map(|v| v * v).sum::<f64>().sqrt(),
        rmse_3d(&PRED, &TRUTH).unwrap(),
        epsilon = 1e-14
    );
}

#[test]
fn rmse_3d_wants_three_axes() {
    let e = core_error(rmse_3d(&[[1.0, 2.0]], &[[0.0, 0.0]]));
    assert!(
        matches!(
            e,
            CoreError::DimensionMismatch {
                expected: 3,
                got: 2,
                ..
            }
        ),
        "{e:?}"
    );
    // the general form takes any dimension: sqrt(1 + 4)
    assert_abs_diff_eq!(
        rms_euclidean_error(&[[1.0, 2.0]], &[[0.0, 0.0]]).unwrap(),
        5.0f64.sqrt(),
        epsilon = 1e-15
    );
}

#[test]
fn mean_euclidean_error_is_a_mean_distance() {
    // (3 + 0 + 7) / 3
    assert_abs_diff_eq!(
        mean_euclidean_error(&PRED, &TRUTH).unwrap(),
        10.0 / 3.0,
        epsilon = 1e-15
    );
}

#[test]
fn hit_rate_counts_strictly_below() {
    assert_abs_diff_eq!(hit_rate(&PRED, &TRUTH, 3.0).unwrap(), 1.0 / 3.0); // only 0 < 3
    assert_abs_diff_eq!(hit_rate(&PRED, &TRUTH, 3.5).unwrap(), 2.0 / 3.0);
    assert_abs_diff_eq!(hit_rate(&PRED, &TRUTH, 25.0).unwrap(), 1.0);
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            core_error(hit_rate(&PRED, &TRUTH, bad)),
            CoreError::InvalidParameter {
                name: "threshold",
                ..
            }
        ));
    }
}

#[test]
fn relative_rmse_by_hand() {
    // relative errors: (2-1)/1 = 1, (1.5-2)/2 = -0.25 -> sqrt((1 + 0.0625) / 2)
    let r = relative_rmse(&[[2.0], [1.5]], &[[1.0], [2.0]]).unwrap();
    assert_abs_diff_eq!(r, (1.0625f64 / 2.0).sqrt(), epsilon = 1e-15);
    assert!(matches!(
        relative_rmse(&[[1.0, 1.0]], &[[1.0, 0.0]]),
        Err(MetricsError::ZeroReference { index: 0, axis: 1 })
    ));
}

#[test]
fn error_statistics_by_hand() {
    // errors 3, 0, 7: mean 10/3; deviations -1/3, -10/3, 11/3 -> (1 + 100 + 121) / 9 / 3 = 222/27
    let s = error_statistics(&PRED, &TRUTH).unwrap();
    assert_eq!(s.count, 3);
    assert_abs_diff_eq!(s.mean, 10.0 / 3.0, epsilon = 1e-15);
    assert_abs_diff_eq!(s.variance, 222.0 / 27.0, epsilon = 1e-14);
}

#[test]
fn per_horizon_by_hand() {
    // two forecasts of 2 steps in 2-D
    let f = vec![vec![[3.0, 4.0], [0.0, 1.0]], vec![[0.0, 0.0], [6.0, 8.0]]];
    let a = vec![vec![[0.0, 0.0], [0.0, 0.0]], vec![[0.0, 0.0], [0.0, 0.0]]];
    let h = per_horizon(&f, &a).unwrap();
    // step 1 errors 5, 0; step 2 errors 1, 10
    assert_eq!(h.count, 2);
    assert_eq!(h.mean_euclidean, vec![2.5, 5.5]);
    assert_abs_diff_eq!(h.rms_euclidean[0], (25.0f64 / 2.0).sqrt(), epsilon = 1e-15);
    assert_abs_diff_eq!(h.rms_euclidean[1], (101.0f64 / 2.0).sqrt(), epsilon = 1e-15);
    assert_abs_diff_eq!(h.ade(), 4.0, epsilon = 1e-15);
    assert_abs_diff_eq!(h.fde(), 5.5, epsilon = 1e-15);
}

#[test]
fn per_horizon_rejects_ragged_forecasts() {
    let f = vec![vec![[0.0], [0.0]], vec![[0.0]]];
    let a = vec![vec![[0.0], [0.0]], vec![[0.0], [0.0]]];
    assert!(matches!(
        per_horizon(&f, &a),
        Err(MetricsError::ItemDimensionMismatch {
            what: "forecast",
            index: 1,
            expected: 2,
            got: 1
        })
    ));
    let f = vec![vec![[0.0], [f64::NAN]]];
    let a = vec![vec![[0.0], [0.0]]];
    assert!(matches!(
        core_error(per_horizon(&f, &a)),
        CoreError::NonFinite {
            what: "predicted",
            index: 0
        }
    ));
    let empty: Vec<Vec<[f64; 1]>> = vec![];
    assert!(matches!(
        core_error(per_horizon(&empty, &empty)),
        CoreError::Empty { what: "forecasts" }
    ));
    assert!(matches!(
        core_error(per_horizon(
            &[Vec::<[f64; 1]>::new()],
            &[Vec::<[f64; 1]>::new()]
        )),
        CoreError::Empty { what: "forecast 0" }
    ));
    assert!(matches!(
        core_error(per_horizon(&f, &[a[0].clone(), a[0].clone()])),
        CoreError::LengthMismatch {
            expected: 1,
            got: 2,
            ..
        }
    ));
}

#[test]
fn nees_and_nis_by_hand() {
    // P = [[2, 1], [1, 2]], P^-1 = [[2, -1], [-1, 2]] / 3; e = (1, 1): e^T P^-1 e = (2 - 1 - 1 + 2)/3 = 2/3
    let p = dmatrix![2.0, 1.0; 1.0, 2.0];
    let e = dvector![1.0, 1.0];
    let v = nees(std::slice::from_ref(&e), std::slice::from_ref(&p)).unwrap();
    assert_abs_diff_eq!(v[0], 2.0 / 3.0, epsilon = 1e-14);
    // e = (1, -1): (2 + 1 + 1 + 2)/3 = 2
    let v = nis(&[dvector![1.0, -1.0]], std::slice::from_ref(&p)).unwrap();
    assert_abs_diff_eq!(v[0], 2.0, epsilon = 1e-14);
}

#[test]
fn nees_errors() {
    let p = dmatrix![1.0, 2.0; 2.0, 1.0]; // eigenvalues 3 and -1
    assert!(matches!(
        nees(&[dvector![1.0, 0.0]], &[p]),
        Err(MetricsError::CovarianceNotPositiveDefinite { index: 0 })
    ));
    assert!(matches!(
        nees(&[dvector![1.0, 0.0]], &[DMatrix::identity(3, 3)]),
        Err(MetricsError::ItemDimensionMismatch {
            what: "covariance",
            index: 0,
            expected: 2,
            got: 3
        })
    ));
    assert!(matches!(
        core_error(nees(&[dvector![f64::NAN, 0.0]], &[DMatrix::identity(2, 2)])),
        CoreError::NonFinite {
            what: "error vector",
            index: 0
        }
    ));
    assert!(matches!(
        core_error(nees(&[], &[])),
        CoreError::Empty { what: "errors" }
    ));
    assert!(matches!(
        core_error(nees(&[DVector::zeros(2)], &[])),
        CoreError::LengthMismatch {
            expected: 1,
            got: 0,
            ..
        }
    ));
}

#[test]
fn chi_square_bounds_by_hand() {
    // chi2 with 2 dof is exponential with mean 2: quantile q = -2 ln(1 - q)
    let (lo, hi) = chi_square_bounds(2, 1, 0.95).unwrap();
    assert_abs_diff_eq!(lo, -2.0 * 0.975f64.ln(), epsilon = 1e-9);
    assert_abs_diff_eq!(hi, -2.0 * 0.025f64.ln(), epsilon = 1e-9);
    // average of 2 chi2(1) values: 2 * avg ~ chi2(2), bounds halve
    let (lo2, hi2) = chi_square_bounds(1, 2, 0.95).unwrap();
    assert_abs_diff_eq!(lo2, lo / 2.0, epsilon = 1e-9);
    assert_abs_diff_eq!(hi2, hi / 2.0, epsilon = 1e-9);
    // chi2(1) is the square of a standard normal: its 97.5% quantile (the upper two-sided 95%
    // bound) is z_0.9875^2 = 2.241402727604947^2, and its 2.5% quantile is z_0.5125^2
    let (lo1, hi1) = chi_square_bounds(1, 1, 0.95).unwrap();
    assert_abs_diff_eq!(hi1, 2.241_402_727_604_947f64.powi(2), epsilon = 1e-9);
    assert_abs_diff_eq!(lo1, 0.031_337_982_021_426_6f64.powi(2), epsilon = 1e-9);
}

#[test]
fn consistency_test() {
    let c = consistency(&[1.0, 3.0], 2, 0.95).unwrap();
    assert_eq!(c.mean, 2.0);
    assert!(c.consistent && c.lower < 2.0 && c.upper > 2.0);
    let c = consistency(&[50.0, 60.0], 2, 0.95).unwrap();
    assert!(!c.consistent);
    assert!(matches!(
        core_error(consistency(&[1.0], 2, 1.5)),
        CoreError::InvalidParameter {
            name: "confidence",
            ..
        }
    ));
    assert!(matches!(
        core_error(consistency(&[1.0], 0, 0.9)),
        CoreError::InvalidParameter {
            name: "degrees of freedom",
            ..
        }
    ));
    assert!(matches!(
        core_error(consistency(&[], 2, 0.9)),
        CoreError::Empty { what: "samples" }
    ));
    assert!(matches!(
        core_error(consistency(&[-1.0], 2, 0.9)),
        CoreError::NonFinite { index: 0, .. }
    ));
}

/// Every point metric rejects empty, mismatched and non-finite input with the named variant.
#[test]
fn every_point_metric_rejects_bad_input() {
    type Metric = fn(&[Vec<f64>], &[Vec<f64>]) -> Result<f64>;
    let metrics: [(&str, Metric); 7] = [
        ("rmse", |p, a| rmse(p, a).map(|v| v[0])),
        ("rms_euclidean_error", |p, a| rms_euclidean_error(p, a)),
        ("mean_euclidean_error", |p, a| mean_euclidean_error(p, a)),
        ("hit_rate", |p, a| hit_rate(p, a, 1.0)),
        ("relative_rmse", |p, a| relative_rmse(p, a)),
        ("error_statistics", |p, a| {
            error_statistics(p, a).map(|s| s.mean)
        }),
        ("euclidean_errors", |p, a| {
            euclidean_errors(p, a).map(|v| v[0])
        }),
    ];
    let one = vec![vec![1.0, 1.0]];
    let two = vec![vec![1.0, 1.0], vec![2.0, 2.0]];
    for (name, m) in metrics {
        let e = core_error(m(&[], &[]));
        assert!(
            matches!(e, CoreError::Empty { what: "points" }),
            "{name}: {e:?}"
        );
        let e = core_error(m(&one, &two));
        assert!(
            matches!(
                e,
                CoreError::LengthMismatch {
                    expected: 1,
                    got: 2,
                    ..
                }
            ),
            "{name}: {e:?}"
        );
        let e = core_error(m(&two, &[vec![1.0, 1.0], vec![2.0]]));
        assert!(
            matches!(
                e,
                CoreError::PointDimension {
                    index: 1,
                    expected: 2,
                    got: 1
                }
            ),
            "{name}: {e:?}"
        );
        let e = core_error(m(&[vec![1.0, f64::NAN]], &one));
        assert!(
            matches!(
                e,
                CoreError::NonFinite {
                    what: "predicted",
                    index: 0
                }
            ),
            "{name}: {e:?}"
        );
        let e = core_error(m(&two, &[vec![1.0, 1.0], vec![f64::INFINITY, 1.0]]));
        assert!(
            matches!(
                e,
                CoreError::NonFinite {
                    what: "actual",
                    index: 1
                }
            ),
            "{name}: {e:?}"
        );
        let e = core_error(m(&[vec![]], &[vec![]]));
        assert!(
            matches!(e, CoreError::Empty { what: "point 0" }),
            "{name}: {e:?}"
        );
    }
}
