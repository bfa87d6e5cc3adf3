//! Kalman filters for trajpred (work in progress).
#![forbid(unsafe_code)]

pub mod error;
pub mod filter;
pub mod kf;
mod linalg;
pub mod model;

pub use error::{KalmanError, Result};
pub use filter::{CovarianceUpdate, Filter, Smoother, Step, Update};
pub use kf::{Ekf, Kf};
pub use model::{
    LinearObservation, LinearObservationModel, LinearTransition, LinearTransitionModel,
    Observation, ObservationJacobian, Transition, TransitionJacobian,
};
pub mod ukf;
pub use ukf::{MerweSigmaPoints, SigmaWeights, Ukf};
pub mod motion;
pub use motion::{CoordinatedTurn, RangeBearing, StateOrder};
pub mod ikf;
pub mod predictor;
pub use ikf::{Ikf, IkfStep, Innovation};
pub use predictor::MultiStep;
pub mod sampling;
