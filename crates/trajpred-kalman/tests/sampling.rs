//! The Gaussian sampler shared with the particle filters (`trajpred_kalman::sampling`): the
//! square-root factor of a positive semi-definite covariance, draws from it, and the
//! log-density of a zero-mean Gaussian, against the core `Gaussian` and values by hand.

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;
use trajpred_kalman::KalmanError;
use trajpred_kalman::sampling::{ZeroMeanGaussian, covariance_sqrt, draw, push_standard_normals};

/// A positive definite `C` gets its Cholesky factor, a singular one a factor with zero
/// columns: `L L^T = C` to rounding either way, with no jitter added.
#[test]
fn the_factor_reproduces_definite_and_singular_covariances() {
    // positive definite
    let c = Matrix3::new(4.0, 2.0, 0.4, 2.0, 5.0, 1.0, 0.4, 1.0, 3.0);
    let l = covariance_sqrt(&c, "C").unwrap();
    assert!((l * l.transpose() - c).amax() < 1e-14);
    assert_eq!(
        l.upper_triangle() - Matrix3::from_diagonal(&l.diagonal()),
        Matrix3::zeros()
    );
    // rank one (the discrete white-noise Q of a constant-velocity axis, dt = 2): g g^T
    let g = Vector3::new(2.0, 2.0, 0.0);
    let q = g * g.transpose();
    let l = covariance_sqrt(&q, "Q").unwrap();
    assert!((l * l.transpose() - q).amax() < 1e-15, "{l}");
    assert_eq!((l[(1, 1)], l[(2, 2)]), (0.0, 0.0));
}

/// A badly scaled but positive definite covariance keeps its small direction, also in `f32`
/// (where `64 n eps max|C|` is larger than the small variance).
#[test]
fn a_small_variance_is_not_taken_for_a_zero_one() {
    let c = Matrix2::<f32>::new(25.0, 0.0, 0.0, 1e-6);
    let l = covariance_sqrt(&c, "R").unwrap();
    assert!((l[(1, 1)] - 1e-3).abs() < 1e-9, "{l}");
}

/// The shared error a sampler function returned, which must be one (a `KalmanError::Core`).
fn core_error<T: std::fmt::Debug>(r: Result<T, KalmanError>) -> CoreError {
    match r {
        Err(KalmanError::Core(e)) => e,
        other => panic!("expected a shared error, got {other:?}"),
    }
}

#[test]
fn bad_covariances_are_typed_errors() {
    for (bad, what) in [
        (Matrix2::new(1.0, 0.0, 0.0, -1.0), "a negative variance"),
        (Matrix2::new(1.0, 0.5, 0.0, 1.0), "asymmetric"),
    ] {
        let e = core_error(covariance_sqrt(&bad, "Q"));
        assert!(
            matches!(e, CoreError::NotPositiveDefinite { what: "Q" }),
            "{what}: {e:?}"
        );
    }
    let e = core_error(covariance_sqrt(&Matrix2::new(1.0, 0.0, 0.0, f64::NAN), "Q"));
    assert!(
        matches!(
            e,
            CoreError::NonFinite {
                what: "Q",
                index: 3
            }
        ),
        "{e:?}"
    );
    // a density needs a definite S
    let e = core_error(ZeroMeanGaussian::new(
        &Matrix2::new(1.0, 1.0, 1.0, 1.0),
        "S",
    ));
    assert!(
        matches!(e, CoreError::NotPositiveDefinite { what: "S" }),
        "{e:?}"
    );
}

/// The log-density agrees with the core `Gaussian::log_density` (its own Cholesky and
/// Mahalanobis distance), and the density of a draw `L e` from its normals with the density
/// of the drawn point.
#[test]
fn log_densities_agree_with_the_core_gaussian() {
    let s = Matrix3::new(4.0, 2.0, 0.4, 2.0, 5.0, 1.0, 0.4, 1.0, 3.0);
    let g = ZeroMeanGaussian::new(&s, "S").unwrap();
    let core = Gaussian::new(Vector3::zeros(), s).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut e: Vec<f64> = Vec::new();
    for _ in 0..20 {
        e.clear();
        push_standard_normals(&mut rng, 3, &mut e);
        let x = draw(&Vector3::zeros(), g.factor(), e.iter().copied());
        let want = core.log_density(&x).unwrap();
        assert!((g.log_density(&x) - want).abs() < 1e-12 * want.abs().max(1.0));
        assert!((g.log_density_of_normals(&e) - want).abs() < 1e-12 * want.abs().max(1.0));
    }
    // by hand: ln N((2, 0); 0, diag(4, 1)) = -(2 ln 2 pi + ln 4 + 1) / 2
    let g = ZeroMeanGaussian::new(&Matrix2::new(4.0, 0.0, 0.0, 1.0), "S").unwrap();
    let by_hand = -(2.0 * (2.0 * std::f64::consts::PI).ln() + 4f64.ln() + 1.0) / 2.0;
    assert!((g.log_density(&Vector2::new(2.0, 0.0)) - by_hand).abs() < 1e-14);
    assert_eq!(
        g.log_density(&Vector2::new(f64::NAN, 0.0)),
        f64::NEG_INFINITY
    );
}

/// Draws `m + L e` have the mean `m` and covariance `L L^T` to Monte Carlo accuracy, also
/// for a singular covariance (zero spread along its null direction).
#[test]
fn draws_have_the_requested_moments() {
    let m = Vector2::new(1.0, -2.0);
    let c = Matrix2::new(1.0, 2.0, 2.0, 4.0); // rank one: x2 = 2 x1
    let l = covariance_sqrt(&c, "C").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let n = 20_000;
    let mut e: Vec<f64> = Vec::new();
    push_standard_normals(&mut rng, 2 * n, &mut e);
    let xs: Vec<Vector2<f64>> = e
        .chunks(2)
        .map(|e| draw(&m, &l, e.iter().copied()))
        .collect();
    let mean = xs.iter().fold(Vector2::zeros(), |a, x| a + x) / n as f64;
    let cov = xs
        .iter()
        .fold(Matrix2::zeros(), |a, x| a + (x - m) * (x - m).transpose())
        / n as f64;
    assert!((mean - m).amax() < 4.0 * 2.0 / (n as f64).sqrt(), "{mean}");
    assert!((cov - c).amax() < 0.05 * 4.0, "{cov}");
    // exactly on the line x2 + 2 = 2 (x1 - 1)
    assert!(
        xs.iter()
            .all(|x| ((x[1] + 2.0) - 2.0 * (x[0] - 1.0)).abs() < 1e-12)
    );
}
