// The crate documentation is the README (its examples are compiled and run as doc tests).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod alloc;
pub mod driver;
pub mod error;
pub mod filter;
pub mod kf;
mod linalg;
pub mod model;

/// The linear algebra the filters take and return, re-exported so that a user needs no
/// separate (and exactly matching) nalgebra dependency.
pub use nalgebra;
/// The random number traits [`sampling`] takes (an injected, seeded generator), re-exported so
/// that a user's generator matches them.
pub use rand;
/// The Gaussian state every filter steps.
pub use trajpred_core::Gaussian;

pub use alloc::FilterAllocator;
pub use error::{KalmanError, Result};
pub use filter::{
    CovarianceUpdate, Filter, InputChecks, PredictionAndUpdate, PredictionWithCross, RtsSmoothed,
    Smoother, Step, Update,
};
pub use kf::{Ekf, Kf};
pub use model::{
    LinearObservation, LinearObservationModel, LinearTransition, LinearTransitionModel,
    Observation, ObservationJacobian, SigmaImages, Transition, TransitionJacobian,
};
pub mod ukf;
pub use ukf::{
    AdditiveNoise, AugmentedNoise, MerweSigmaPoints, SigmaPointFilter, SigmaSpace, SigmaWeights,
    Ukf,
};
pub mod motion;
pub use motion::{CoordinatedTurn, RangeBearing, StateOrder};
pub mod ikf;
pub mod imm;
pub mod predictor;
pub mod turn_accel;
pub use ikf::{Ikf, IkfStep, Innovation};
pub use imm::{Imm, ImmState, ImmStep, TimedImm};
pub use predictor::MultiStep;
pub mod augmented;
pub mod sampling;
pub mod smoother;
pub use augmented::{AugmentedUkf, NoisyObservation, NoisyTransition};
