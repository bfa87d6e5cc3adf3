// The crate documentation is the README (its examples are compiled and run as doc tests).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod alloc;
pub mod cloud;
pub mod driver;
pub mod error;
pub mod mkpf;
pub mod pf;
pub mod resample;
pub mod weights;

// What a user of this crate alone needs, so that it is the only dependency: the linear
// algebra (the exact nalgebra version the filters take), the random-number traits the
// filters are generic over, the Gaussian state, and the Kalman crate's model traits and the
// models and sigma points the MKPF uses.
pub use nalgebra;
pub use rand;
pub use trajpred_core::Gaussian;
pub use trajpred_kalman::{
    CoordinatedTurn, LinearObservation, LinearTransition, MerweSigmaPoints, Observation,
    ObservationJacobian, RangeBearing, Transition, TransitionJacobian,
};

pub use alloc::ParticleAllocator;
pub use cloud::ParticleCloud;
pub use error::{ParticleError, Result};
pub use mkpf::{EkfStage, Mkpf, ParticlePrior, UkfVariant};
pub use pf::{ParticleFilter, ParticleFiltering, PfConfig, StepSummary};
pub use resample::{
    Multinomial, Resampler, Resampling, Residual, Stratified, Systematic, multinomial_indices,
    residual_indices, stratified_indices, systematic_indices,
};
pub use weights::{
    ResamplePolicy, effective_sample_size, effective_sample_size_log, log_sum_exp,
    normalize_log_weights, weights_from_log_into,
};
