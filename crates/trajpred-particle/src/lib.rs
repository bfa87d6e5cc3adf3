//! Particle filters for trajpred (work in progress).
#![forbid(unsafe_code)]

pub mod cloud;
pub mod error;
mod gauss;
pub mod mkpf;
pub mod pf;
pub mod resample;
pub mod weights;

pub use cloud::ParticleCloud;
pub use error::{ParticleError, Result};
pub use mkpf::{EkfStage, Mkpf, ParticlePrior};
pub use pf::{ParticleFilter, ParticleFiltering, PfConfig, StepSummary};
pub use resample::{
    Multinomial, Resampler, Resampling, Residual, Stratified, Systematic, multinomial_indices,
    residual_indices, stratified_indices, systematic_indices,
};
pub use weights::{
    ResamplePolicy, effective_sample_size, effective_sample_size_log, log_sum_exp,
    normalize_log_weights, weights_from_log_into,
};
