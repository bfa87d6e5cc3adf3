//! Tests of the core types: invariants, the first bad index, and the Hankel construction of
//! `docs/papers.md` A.3 checked against windows written out by hand.

use approx::assert_abs_diff_eq;
use nalgebra::{Const, DMatrix, DVector, Dyn, Matrix2, Vector2};
use trajpred_core::window::{design_rows, hankel_design, last_window, windows};
use trajpred_core::*;

#[test]
fn trajectory_accessors() {
    let tr = Trajectory::new(
        vec![0.0, 0.5, 1.5],
        vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]],
    )
    .unwrap();
    assert_eq!((tr.len(), tr.dim()), (3, 3));
    assert!(!tr.is_empty());
    assert_eq!(tr.axis(2), &[3.0, 6.0, 9.0]);
    assert_eq!(&tr.point(1)[..], &[4.0, 5.0, 6.0]);
    assert_eq!(&tr.last_point()[..], &[7.0, 8.0, 9.0]);
    assert_eq!(tr.times(), &[0.0, 0.5, 1.5]);
    assert_eq!(tr.last_interval(), Some(1.0));
    assert_eq!(tr.axes().count(), 3);
    let pts: Vec<Vec<f64>> = tr.points().map(|p| p.to_vec()).collect();
    assert_eq!(pts[2], vec![7.0, 8.0, 9.0]);
    let s = tr.slice(1..3).unwrap();
    assert_eq!(s.times(), &[0.5, 1.5]);
    assert_eq!(s.axis(0), &[4.0, 7.0]);
    assert_eq!(tr.prefix(1).unwrap().len(), 1);
    assert_eq!(tr.prefix(1).unwrap().last_interval(), None);
}

#[test]
fn trajectory_rejects_bad_input_naming_the_first_bad_index() {
    let e = Trajectory::new(vec![0.0, 1.0, 0.5, 0.2], vec![[0.0]; 4]).unwrap_err();
    assert!(
        matches!(e, Error::NonIncreasingTime { index: 2, time, previous } if time == 0.5 && previous == 1.0)
    );
    // duplicate timestamp
    let e = Trajectory::new(vec![0.0, 1.0, 1.0], vec![[0.0]; 3]).unwrap_err();
    assert!(matches!(e, Error::NonIncreasingTime { index: 2, .. }));
    // NaN in a point: the first bad point index, whichever axis
    let e = Trajectory::new(
        vec![0.0, 1.0, 2.0, 3.0],
        vec![[0.0, 0.0], [0.0, 0.0], [0.0, f64::NAN], [f64::NAN, 0.0]],
    )
    .unwrap_err();
    assert!(matches!(
        e,
        Error::NonFinite {
            what: "points",
            index: 2
        }
    ));
    let e = Trajectory::new(vec![0.0, f64::INFINITY], vec![[0.0]; 2]).unwrap_err();
    assert!(matches!(
        e,
        Error::NonFinite {
            what: "timestamps",
            index: 1
        }
    ));
    let e = Trajectory::new(Vec::<f64>::new(), Vec::<[f64; 1]>::new()).unwrap_err();
    assert!(matches!(e, Error::Empty { .. }));
    let e = Trajectory::new(vec![0.0, 1.0], vec![[0.0]; 3]).unwrap_err();
    assert!(matches!(
        e,
        Error::LengthMismatch {
            expected: 2,
            got: 3,
            ..
        }
    ));
    let e = Trajectory::new(vec![0.0, 1.0], vec![vec![0.0, 1.0], vec![0.0]]).unwrap_err();
    assert!(matches!(
        e,
        Error::PointDimension {
            index: 1,
            expected: 2,
            got: 1
        }
    ));
    let e = Trajectory::new(vec![0.0], vec![vec![0.0; 4]]).unwrap_err();
    assert!(matches!(e, Error::UnsupportedDimension { got: 4 }));
    let e = Trajectory::new(vec![0.0], vec![Vec::<f64>::new()]).unwrap_err();
    assert!(matches!(e, Error::UnsupportedDimension { got: 0 }));
    let e = Trajectory::from_axes(vec![0.0, 1.0], vec![vec![0.0, 1.0], vec![0.0]]).unwrap_err();
    assert!(matches!(e, Error::LengthMismatch { .. }));
    let e = Trajectory::uniform(0.0, 0.0, vec![vec![1.0]]).unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { name: "dt", .. }));
    let tr = Trajectory::uniform(0.0, 1.0, vec![vec![1.0, 2.0]]).unwrap();
    assert!(matches!(
        tr.slice(1..5),
        Err(Error::OutOfBounds {
            start: 1,
            end: 5,
            len: 2
        })
    ));
    assert!(matches!(tr.slice(1..1), Err(Error::OutOfBounds { .. })));
}

#[test]
fn error_messages_name_the_problem() {
    let e = Trajectory::new(vec![0.0, 2.0, 1.0], vec![[0.0]; 3]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "timestamps must strictly increase: t[2] = 1 is not after t[1] = 2"
    );
}

#[test]
fn trajectory_serde_round_trip_revalidates() {
    let tr = Trajectory::uniform(10.0, 2.0, vec![vec![1.0, 2.0], vec![3.0, 4.0]]).unwrap();
    let json = serde_json::to_string(&tr).unwrap();
    let back: Trajectory = serde_json::from_str(&json).unwrap();
    assert_eq!(back, tr);
    let bad = r#"{"times":[1.0,0.0],"axes":[[1.0,2.0]]}"#;
    assert!(serde_json::from_str::<Trajectory>(bad).is_err());
}

#[test]
fn point_type() {
    assert!(matches!(
        Point::new(&[]),
        Err(Error::UnsupportedDimension { got: 0 })
    ));
    assert!(matches!(
        Point::new(&[0.0; 4]),
        Err(Error::UnsupportedDimension { got: 4 })
    ));
    let p = Point::new(&[1.0, 2.0, 3.0]).unwrap();
    assert_eq!(p.dim(), 3);
    assert_eq!(p.as_ref(), &[1.0, 2.0, 3.0]);
}

#[test]
fn hankel_design_matches_spec_a3_by_hand() {
    // x_0..x_6 = 10, 11, ..., 16; m = 3, t = 2: p = 7 - 2 - 3 + 1 = 3
    let x: Vec<f64> = (10..17).map(f64::from).collect();
    let d = hankel_design(&x, 3, 2).unwrap();
    let expected = DMatrix::from_row_slice(
        3,
        3,
        &[10.0, 11.0, 12.0, 11.0, 12.0, 13.0, 12.0, 13.0, 14.0],
    );
    assert_eq!(d.design, expected);
    // target x_{j+m-1+t} = x_{j+4}: 14, 15, 16
    assert_eq!(d.target, DVector::from_vec(vec![14.0, 15.0, 16.0]));
    assert_eq!(design_rows(7, 3, 2), Some(3));
    assert_eq!(design_rows(4, 3, 2), None);
    assert_eq!(design_rows(5, 3, 2), Some(1));
    assert_eq!(design_rows(5, 0, 2), None);
}

#[test]
fn hankel_design_errors() {
    let x = [1.0, 2.0, 3.0];
    assert!(matches!(
        hankel_design(&x, 3, 1),
        Err(Error::TooShort {
            needed: 4,
            got: 3,
            ..
        })
    ));
    assert!(matches!(
        hankel_design(&x, 0, 1),
        Err(Error::InvalidParameter { name: "m", .. })
    ));
    assert!(matches!(
        hankel_design(&x, 1, 0),
        Err(Error::InvalidParameter { name: "t", .. })
    ));
    assert!(matches!(
        hankel_design(&[1.0, f64::NAN, 3.0], 1, 1),
        Err(Error::NonFinite { index: 1, .. })
    ));
}

#[test]
fn windows_and_last_window() {
    let x = [1.0, 2.0, 3.0, 4.0];
    assert_eq!(windows(&x, 3).unwrap().count(), 2);
    assert_eq!(last_window(&x, 2).unwrap(), &[3.0, 4.0]);
    assert!(matches!(
        windows(&x, 0),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(last_window(&x, 5), Err(Error::TooShort { .. })));
}

#[test]
fn forecast_construction_and_errors() {
    let f = Forecast::new(2, vec![[1.0, 2.0], [3.0, 4.0]])
        .unwrap()
        .with_covariances(vec![DMatrix::identity(2, 2), DMatrix::identity(2, 2) * 2.0])
        .unwrap();
    assert_eq!((f.dim(), f.horizon()), (2, 2));
    assert_eq!(f.step(1), &[1.0, 2.0]);
    assert_eq!(f.covariance(2).unwrap()[(1, 1)], 2.0);
    assert!(f.covariance(0).is_none() && f.covariance(3).is_none());
    assert_eq!(f.points().count(), 2);
    assert!(matches!(
        Forecast::new(2, Vec::<[f64; 2]>::new()),
        Err(Error::Empty { .. })
    ));
    assert!(matches!(
        Forecast::new(4, vec![[0.0; 4]]),
        Err(Error::UnsupportedDimension { got: 4 })
    ));
    assert!(matches!(
        Forecast::new(2, vec![vec![0.0]]),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        Forecast::new(1, vec![[0.0], [f64::NAN]]),
        Err(Error::NonFinite { index: 1, .. })
    ));
    let f = Forecast::new(1, vec![[0.0]]).unwrap();
    assert!(matches!(
        f.clone().with_covariances(vec![]),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(matches!(
        f.clone().with_covariances(vec![DMatrix::identity(2, 2)]),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        f.with_covariances(vec![DMatrix::from_element(1, 1, f64::NAN)]),
        Err(Error::NonFinite { .. })
    ));
}

/// A trivial predictor to show the trait works as a `Box<dyn Predictor>` and that
/// `check_forecast_args` reports its errors.
struct LastValue;

impl Predictor for LastValue {
    fn name(&self) -> &str {
        "last-value"
    }
    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(())
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        Forecast::new(history.dim(), vec![history.last_point(); horizon])
    }
    fn min_history(&self) -> usize {
        2
    }
}

#[test]
fn predictor_as_trait_object() {
    fn assert_send_sync<T: Send + Sync + ?Sized>() {}
    assert_send_sync::<dyn Predictor>();
    let mut p: Box<dyn Predictor> = Box::new(LastValue);
    let tr = Trajectory::uniform(0.0, 1.0, vec![vec![1.0, 2.0, 3.0]]).unwrap();
    p.fit(std::slice::from_ref(&tr)).unwrap();
    assert_eq!(p.name(), "last-value");
    assert_eq!(p.forecast(&tr, 3).unwrap().step(3), &[3.0]);
    assert!(matches!(
        p.forecast(&tr, 0),
        Err(Error::InvalidParameter {
            name: "horizon",
            ..
        })
    ));
    assert!(matches!(
        p.forecast(&tr.prefix(1).unwrap(), 1),
        Err(Error::TooShort {
            needed: 2,
            got: 1,
            ..
        })
    ));
    let e = Error::method("kf", std::fmt::Error);
    assert!(e.to_string().starts_with("kf: "));
}

#[test]
fn gaussian_static_and_dynamic() {
    // covariance diag(4, 1), x - mean = (2, 1): Mahalanobis^2 = 1 + 1 = 2
    let g =
        Gaussian::<f64, Const<2>>::new(Vector2::new(1.0, 2.0), Matrix2::new(4.0, 0.0, 0.0, 1.0))
            .unwrap();
    assert_eq!(g.dim(), 2);
    assert_abs_diff_eq!(
        g.mahalanobis_squared(&Vector2::new(3.0, 3.0)).unwrap(),
        2.0,
        epsilon = 1e-12
    );
    // log density: -(2 ln 2pi + ln 4 + 2) / 2
    let expected = -(2.0 * (2.0 * std::f64::consts::PI).ln() + 4.0f64.ln() + 2.0) / 2.0;
    assert_abs_diff_eq!(
        g.log_density(&Vector2::new(3.0, 3.0)).unwrap(),
        expected,
        epsilon = 1e-12
    );
    let gd = Gaussian::<f64, Dyn>::new(DVector::zeros(3), DMatrix::identity(3, 3)).unwrap();
    assert!(matches!(
        gd.mahalanobis_squared(&DVector::zeros(2)),
        Err(Error::DimensionMismatch { .. })
    ));
    // f32 works too
    let g32 = Gaussian::<f32, Const<1>>::new(
        nalgebra::Vector1::new(0.0f32),
        nalgebra::Matrix1::new(1.0f32),
    )
    .unwrap();
    assert!(
        (g32.mahalanobis_squared(&nalgebra::Vector1::new(2.0))
            .unwrap()
            - 4.0)
            .abs()
            < 1e-6
    );
}

#[test]
fn gaussian_rejects_bad_covariances() {
    let bad_shape = Gaussian::<f64, Dyn>::new(DVector::zeros(2), DMatrix::identity(3, 3));
    assert!(matches!(bad_shape, Err(Error::DimensionMismatch { .. })));
    let asym = Gaussian::new(Vector2::new(0.0, 0.0), Matrix2::new(1.0, 0.5, 0.0, 1.0));
    assert!(matches!(asym, Err(Error::NotPositiveDefinite { .. })));
    let neg = Gaussian::new(Vector2::new(0.0, 0.0), Matrix2::new(-1.0, 0.0, 0.0, 1.0));
    assert!(matches!(neg, Err(Error::NotPositiveDefinite { .. })));
    let nan = Gaussian::new(Vector2::new(f64::NAN, 0.0), Matrix2::identity());
    assert!(matches!(nan, Err(Error::NonFinite { what: "mean", .. })));
    let nan = Gaussian::new(
        Vector2::new(0.0, 0.0),
        Matrix2::new(1.0, 0.0, 0.0, f64::NAN),
    );
    assert!(matches!(
        nan,
        Err(Error::NonFinite {
            what: "covariance",
            ..
        })
    ));
    // symmetric, non-negative diagonal, but indefinite: accepted by validate (cheap checks),
    // rejected where a factorisation is needed
    let indef = Gaussian::new(Vector2::new(0.0, 0.0), Matrix2::new(1.0, 2.0, 2.0, 1.0)).unwrap();
    assert!(matches!(
        indef.mahalanobis_squared(&Vector2::new(1.0, 0.0)),
        Err(Error::NotPositiveDefinite { .. })
    ));
}

/// A horizon above `MAX_HORIZON` is refused before the predictor allocates anything: asking
/// for 10^11 steps used to abort on a 7.2 TB allocation.
#[test]
fn horizon_above_the_maximum_is_an_error_naming_the_limit() {
    let tr = Trajectory::uniform(0.0, 1.0, vec![vec![1.0, 2.0, 3.0]]).unwrap();
    let p: Box<dyn Predictor> = Box::new(LastValue);
    assert_eq!(p.forecast(&tr, MAX_HORIZON).unwrap().horizon(), MAX_HORIZON);
    for horizon in [MAX_HORIZON + 1, 100_000_000_000, usize::MAX] {
        match p.forecast(&tr, horizon) {
            Err(Error::InvalidParameter {
                name: "horizon",
                reason,
            }) => assert!(
                reason.contains(&MAX_HORIZON.to_string()),
                "reason should name the limit: {reason}"
            ),
            other => panic!("horizon {horizon}: expected InvalidParameter, got {other:?}"),
        }
    }
    // a caller's own limit
    assert!(check_forecast_args_with_max(&tr, 10, 1, 10).is_ok());
    assert!(matches!(
        check_forecast_args_with_max(&tr, 11, 1, 10),
        Err(Error::InvalidParameter {
            name: "horizon",
            ..
        })
    ));
}
