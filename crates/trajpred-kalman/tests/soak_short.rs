//! A short version of the soak (`examples/kalman_soak.rs`, included here): 1.2 x 10^5 filter steps of the
//! KF, the UKF (range-bearing and position observations), the filter driver over
//! irregular times and the IMM (constant velocity + coordinated turn), every 100 steps checking the covariance finite, symmetric and positive
//! semi-definite (tolerances `SYM_TOL`, `PSD_TOL` of the example) and the log-likelihood
//! finite.

#[allow(dead_code)]
#[path = "../examples/kalman_soak.rs"]
mod soak;

use nalgebra::{DMatrix, Matrix3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use soak::{Part, Soak, check_cov, soak_driver, soak_imm, soak_kf, soak_ukf};

fn assert_clean(name: &str, p: &Part, steps: u64) {
    assert_eq!(p.steps, steps, "{name}: steps ({:?})", p.messages);
    assert_eq!(p.violations, 0, "{name}: {:?}", p.messages);
    assert_eq!(p.errors, 0, "{name}: {:?}", p.messages);
    assert!(p.checks >= steps / 100, "{name}: {} checks", p.checks);
    assert!(
        p.updates > steps / 2 && p.updates < steps,
        "{name}: {} updates",
        p.updates
    );
    assert!(p.max_trace.is_finite() && p.max_trace > 0.0, "{name}");
    assert_eq!(p.nees_n, p.checks, "{name}: a NEES at every check");
    assert!(p.mean_nees().is_finite(), "{name}");
}

#[test]
fn a_short_soak_keeps_every_invariant() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let kf = soak_kf(Soak::new(40_000, 10_000, 100), &mut rng);
    assert_clean("KF", &kf, 40_000);
    assert_eq!(kf.tracks, 4);
    // the linear filters on their own model are consistent: position NEES about 2
    // (chi-squared with 2 degrees of freedom)
    assert!(
        (1.0..4.0).contains(&kf.mean_nees()),
        "KF NEES {}",
        kf.mean_nees()
    );
    let ukf = soak_ukf(Soak::new(30_000, 10_000, 100), &mut rng);
    assert_clean("UKF", &ukf, 30_000);
    assert_eq!(ukf.tracks, 3, "range-bearing, position, range-bearing");
    let drv = soak_driver(Soak::new(30_000, 10_000, 100), &mut rng);
    assert_clean("driver", &drv, 30_000);
    assert!(
        (1.0..4.0).contains(&drv.mean_nees()),
        "driver NEES {}",
        drv.mean_nees()
    );
    // tracks of 10^4 steps stay near the sensor: the UKF is consistent too (over tracks of
    // 10^6 steps, range-bearing at tens of km, it is not: docs/reliability.md)
    assert!(
        (1.0..4.0).contains(&ukf.mean_nees()),
        "UKF NEES {}",
        ukf.mean_nees()
    );
    let imm = soak_imm(Soak::new(20_000, 10_000, 100), &mut rng);
    assert_clean("IMM", &imm, 20_000);
    assert_eq!(imm.tracks, 2);
    // the IMM's combined covariance is the mixture's: NEES near 2 as well
    assert!(
        (1.0..4.0).contains(&imm.mean_nees()),
        "IMM NEES {}",
        imm.mean_nees()
    );
    eprintln!(
        "NEES: KF {:.2}, UKF {:.2}, driver {:.2}, IMM {:.2}",
        kf.mean_nees(),
        ukf.mean_nees(),
        drv.mean_nees(),
        imm.mean_nees()
    );
}

#[test]
fn the_covariance_check_rejects_broken_matrices() {
    let good = Matrix3::new(4.0, 1.0, 0.0, 1.0, 3.0, 0.5, 0.0, 0.5, 2.0);
    assert_eq!(check_cov(&good), Ok(()));
    // positive semi-definite but singular: accepted
    let singular = Matrix3::new(1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0);
    assert_eq!(check_cov(&singular), Ok(()));
    let mut asym = good;
    asym[(0, 1)] += 1e-6;
    assert!(check_cov(&asym).unwrap_err().contains("asymmetric"));
    let indefinite = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    assert!(check_cov(&indefinite).unwrap_err().contains("not PSD"));
    let mut nan = good;
    nan[(2, 2)] = f64::NAN;
    assert!(check_cov(&nan).unwrap_err().contains("non-finite"));
    assert!(check_cov(&DMatrix::<f64>::zeros(2, 3)).is_err());
}

fn break_symmetry(p: &mut DMatrix<f64>) {
    p[(0, 1)] += 1.0;
}

fn make_indefinite(p: &mut DMatrix<f64>) {
    p[(0, 0)] = -p[(0, 0)];
}

#[test]
fn a_broken_covariance_fails_the_soak() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let kf = soak_kf(
        Soak::new(2_000, 1_000, 100).tampered(break_symmetry),
        &mut rng,
    );
    assert_eq!(kf.violations, kf.checks);
    assert!(kf.messages[0].contains("asymmetric"), "{:?}", kf.messages);
    let ukf = soak_ukf(
        Soak::new(2_000, 1_000, 100).tampered(make_indefinite),
        &mut rng,
    );
    assert_eq!(ukf.violations, ukf.checks);
    assert!(ukf.messages[0].contains("not PSD"), "{:?}", ukf.messages);
    let drv = soak_driver(
        Soak::new(2_000, 1_000, 100).tampered(break_symmetry),
        &mut rng,
    );
    assert!(
        drv.violations > 0 && drv.violations == drv.checks,
        "{drv:?}"
    );
    let imm = soak_imm(
        Soak::new(2_000, 1_000, 100).tampered(make_indefinite),
        &mut rng,
    );
    assert_eq!(imm.violations, imm.checks, "{:?}", imm.messages);
    assert!(imm.messages[0].contains("not PSD"), "{:?}", imm.messages);
}
