//! Log-space weights and the effective sample size, against values worked by hand.

use approx::assert_relative_eq;
use trajpred_core::Error as CoreError;
use trajpred_particle::{
    ParticleError, ResamplePolicy, effective_sample_size, effective_sample_size_log, log_sum_exp,
    normalize_log_weights, weights_from_log_into,
};

#[test]
fn log_sum_exp_by_hand() {
    // ln(1 + 2 + 3) = ln 6
    let l = [1f64.ln(), 2f64.ln(), 3f64.ln()];
    assert_relative_eq!(log_sum_exp(&l).expect("ok"), 6f64.ln(), epsilon = 1e-15);
    // huge and tiny log-weights: no overflow or underflow
    assert_relative_eq!(
        log_sum_exp(&[-1e4, -1e4]).expect("ok"),
        -1e4 + 2f64.ln(),
        epsilon = 1e-9
    );
    assert_eq!(
        log_sum_exp(&[f64::NEG_INFINITY; 3]).expect("ok"),
        f64::NEG_INFINITY
    );
    assert_relative_eq!(
        log_sum_exp(&[f64::NEG_INFINITY, 0.0]).expect("ok"),
        0.0,
        epsilon = 1e-15
    );
}

#[test]
fn normalisation_and_ess_by_hand() {
    // weights proportional to 1, 1, 2 -> 0.25, 0.25, 0.5; ESS = 1 / (1/16 + 1/16 + 1/4) = 8/3
    let mut l = vec![-800.0, -800.0, -800.0 + 2f64.ln()];
    let lse = normalize_log_weights(&mut l).expect("ok");
    assert_relative_eq!(lse, -800.0 + 4f64.ln(), epsilon = 1e-12);
    let mut w = [0.0; 3];
    weights_from_log_into(&l, &mut w).expect("ok");
    // subtracting log-weights of magnitude 800 loses about 800 eps = 2e-13 in the exponent
    assert_relative_eq!(w[0], 0.25, epsilon = 1e-12);
    assert_relative_eq!(w[2], 0.5, epsilon = 1e-12);
    assert_relative_eq!(
        effective_sample_size_log(&l).expect("ok"),
        8.0 / 3.0,
        epsilon = 1e-12
    );
    assert_relative_eq!(
        effective_sample_size(&[1.0, 1.0, 2.0]).expect("ok"),
        8.0 / 3.0,
        epsilon = 1e-12
    );
    assert_relative_eq!(
        effective_sample_size(&[3.0; 5]).expect("ok"),
        5.0,
        epsilon = 1e-12
    );
    assert_relative_eq!(
        effective_sample_size(&[0.0, 7.0, 0.0]).expect("ok"),
        1.0,
        epsilon = 1e-15
    );
    // tiny weights do not underflow the ESS
    assert_relative_eq!(
        effective_sample_size(&[1e-310, 1e-310]).expect("ok"),
        2.0,
        epsilon = 1e-9
    );
}

#[test]
fn degenerate_weights_are_typed_errors() {
    let mut all_neg_inf = vec![f64::NEG_INFINITY; 4];
    assert!(matches!(
        normalize_log_weights(&mut all_neg_inf),
        Err(ParticleError::AllWeightsZero { count: 4 })
    ));
    assert!(
        all_neg_inf.iter().all(|l| *l == f64::NEG_INFINITY),
        "left untouched"
    );
    assert!(matches!(
        log_sum_exp(&[]),
        Err(ParticleError::Core(CoreError::Empty {
            what: "log-weights"
        }))
    ));
    assert!(matches!(
        log_sum_exp(&[0.0, f64::NAN]),
        Err(ParticleError::InvalidWeight { index: 1, .. })
    ));
    assert!(matches!(
        log_sum_exp(&[f64::INFINITY]),
        Err(ParticleError::InvalidWeight { index: 0, .. })
    ));
    assert!(matches!(
        effective_sample_size(&[0.0, 0.0]),
        Err(ParticleError::AllWeightsZero { count: 2 })
    ));
    assert!(matches!(
        effective_sample_size(&[1.0, -1.0]),
        Err(ParticleError::InvalidWeight { index: 1, .. })
    ));
    assert!(matches!(
        effective_sample_size_log(&[f64::NEG_INFINITY]),
        Err(ParticleError::AllWeightsZero { count: 1 })
    ));
    let mut short = [0.0; 1];
    assert!(matches!(
        weights_from_log_into(&[0.0, 0.0], &mut short),
        Err(ParticleError::Core(CoreError::LengthMismatch { .. }))
    ));
}

#[test]
fn resample_policy() {
    assert!(ResamplePolicy::Always.should_resample(100.0, 100));
    assert!(!ResamplePolicy::Never.should_resample(1.0, 100));
    assert!(ResamplePolicy::EssBelow(0.5).should_resample(49.0, 100));
    assert!(!ResamplePolicy::EssBelow(0.5).should_resample(50.0, 100));
    assert!(ResamplePolicy::EssBelow(0.5).validate().is_ok());
    assert!(matches!(
        ResamplePolicy::EssBelow(1.5).validate(),
        Err(ParticleError::Core(CoreError::InvalidParameter { .. }))
    ));
    assert!(matches!(
        ResamplePolicy::EssBelow(f64::NAN).validate(),
        Err(ParticleError::Core(CoreError::InvalidParameter { .. }))
    ));
}
