//! # trajpred-kalman
//!
//! The Kalman family of trajpred, usable on its own: the linear [`Kf`], the extended
//! [`Ekf`] (nonlinear transition **and** observation), the unscented [`Ukf`] (Merwe's scaled
//! sigma points), the improved one-step-ahead [`Ikf`] of the MSTPM-GSKF paper, the KF-dynamic
//! predictor form ([`Kf::predictor_step`], [`Kf::predictor_forecast`]), the RTS
//! [`Smoother`] for the KF, EKF and UKF, k-step forecasts with covariance for every filter,
//! and the usual motion models ([`motion`]).
//!
//! ## Design
//!
//! - **Models** ([`model`]) keep the transition (`f`, `F`, `Q`) apart from the observation
//!   (`h`, `H`, `R`); linear models expose `F`, `H` by reference, nonlinear ones give
//!   Jacobians for the EKF or plain functions for the UKF. The same traits serve
//!   particle filters ([`sampling`]).
//! - **One filtering loop** ([`Filter`]): every filter provides `predict` and `update` as
//!   pure functions of an explicit [`Gaussian`](trajpred_core::Gaussian) state, and inherits
//!   `step` (with `Option` observations for missing data), `filter` (a batch over a
//!   sequence), `log_likelihood` and `forecast` from the trait.
//! - **Generic sizes**: the same code runs on static nalgebra sizes (`Matrix4`, no heap in a
//!   step) and on run-time sizes (`DMatrix`), in `f64` (tested) and `f32`.
//! - **Errors**: bad input and numerical failure give a typed [`KalmanError`], never a panic
//!   or a NaN in the output.
//!
//! ## Equations
//!
//! ```text
//! predict   x(k|k-1) = f(x(k-1|k-1))          P(k|k-1) = F P(k-1|k-1) F^T + Q
//! update    y = z - h(x(k|k-1))               S = H P(k|k-1) H^T + R
//!           K = P(k|k-1) H^T S^-1  (Cholesky solve, no inverse)
//!           x(k|k) = x(k|k-1) + K y
//!           P(k|k) = (I - K H) P (I - K H)^T + K R K^T   (Joseph form, the default)
//!           ln L = -(m ln 2 pi + ln det S + y^T S^-1 y) / 2
//! ```
//!
//! For the KF `f(x) = F x`, `h(x) = H x`; for the EKF `F`, `H` are the Jacobians at the
//! current estimate; the UKF replaces the linearisation by sigma points (see [`Ukf`]).
//! The derivations, what each paper leaves open and what we chose are in `docs/kalman.md`.
//!
//! ## Track a 2-D target, smooth it, forecast 5 steps
//!
//! ```
//! use nalgebra::{Matrix4, Vector2, Vector4, U2, U4};
//! use trajpred_core::Gaussian;
//! use trajpred_kalman::motion::{constant_velocity, position_observation, KinematicLayout, StateOrder};
//! use trajpred_kalman::{Filter, Kf, LinearObservation, LinearTransition, Smoother};
//!
//! // state [x, y, vx, vy], 0.5 s steps, white-noise acceleration of variance 0.1,
//! // position observed with variance 0.25 per axis
//! let layout = KinematicLayout::new(2, 2, StateOrder::PositionsFirst)?;
//! let tr: LinearTransition<f64, U4> = constant_velocity(2, 0.5, 0.1, StateOrder::PositionsFirst)?;
//! let ob: LinearObservation<f64, U4, U2> = position_observation(layout, 0.25)?;
//! let kf = Kf::new(tr, ob)?;
//!
//! // a target moving at (2, 1) m/s; the fourth report is missing
//! let zs: Vec<Option<Vector2<f64>>> = (1..=8)
//!     .map(|k| (k != 4).then(|| Vector2::new(1.0 * k as f64, 0.5 * k as f64)))
//!     .collect();
//! let x0 = Gaussian { mean: Vector4::zeros(), covariance: Matrix4::identity() * 10.0 };
//!
//! let steps = kf.filter(&x0, &zs)?;
//! let last = steps.last().unwrap().posterior();
//! assert!((last.mean[2] - 2.0).abs() < 0.3); // vx
//! assert!(steps[3].update.is_none()); // the missing report: prediction only
//! let total_log_likelihood: f64 = steps.iter().map(|s| s.log_likelihood()).sum();
//! assert!(total_log_likelihood.is_finite());
//!
//! // RTS smoothing of the whole track
//! let filtered: Vec<_> = steps.iter().map(|s| s.posterior().clone()).collect();
//! let smoothed = kf.smooth(&filtered)?;
//! assert!(smoothed[0].covariance[(0, 0)] <= filtered[0].covariance[(0, 0)]);
//!
//! // 5-step forecast with covariance: the uncertainty grows with the horizon
//! let forecast = kf.forecast(last, 5)?;
//! assert_eq!(forecast.len(), 5);
//! assert!(forecast[4].covariance[(0, 0)] > forecast[0].covariance[(0, 0)]);
//! # Ok::<(), trajpred_kalman::KalmanError>(())
//! ```
//!
//! ## One UKF step then one EKF step on the same models (the MKPF proposal)
//!
//! ```
//! use nalgebra::{Matrix5, Vector2, Vector5};
//! use trajpred_core::Gaussian;
//! use trajpred_kalman::{CoordinatedTurn, Ekf, Filter, MerweSigmaPoints, RangeBearing, Ukf};
//!
//! let ct = CoordinatedTurn::<f64>::new(1.0, 0.1, 1e-3)?; // [x, vx, y, vy, turn rate]
//! let rb = RangeBearing::new(Vector2::new(0.0, 0.0), 0, 2, 1.0, 1e-4)?;
//! let ukf = Ukf::new(&ct, &rb, MerweSigmaPoints::new(1e-3, 2.0, 0.0))?;
//! let ekf = Ekf::new(&ct, &rb)?;
//! let particle = Gaussian {
//!     mean: Vector5::new(100.0, 5.0, 50.0, 0.0, 0.05),
//!     covariance: Matrix5::from_diagonal(&Vector5::new(4.0, 1.0, 4.0, 1.0, 1e-4)),
//! };
//! let z = Vector2::new(113.0, 0.47);
//! let u = ukf.step(&particle, Some(&z))?; // UKF estimate ...
//! let prior = ekf.predict(u.posterior())?; // ... as the prior of an EKF step
//! let proposal = ekf.update(&prior, &z)?;
//! assert!(proposal.log_likelihood().is_finite());
//! # Ok::<(), trajpred_kalman::KalmanError>(())
//! ```
#![forbid(unsafe_code)]

mod alloc;
pub mod driver;
pub mod error;
pub mod filter;
pub mod kf;
mod linalg;
pub mod model;

pub use alloc::FilterAllocator;
pub use error::{KalmanError, Result};
pub use filter::{
    CovarianceUpdate, Filter, InputChecks, PredictionAndUpdate, PredictionWithCross, Smoother,
    Step, Update,
};
pub use kf::{Ekf, Kf};
pub use model::{
    LinearObservation, LinearObservationModel, LinearTransition, LinearTransitionModel,
    Observation, ObservationJacobian, SigmaImages, Transition, TransitionJacobian,
};
pub mod ukf;
pub use ukf::{MerweSigmaPoints, SigmaWeights, Ukf};
pub mod motion;
pub use motion::{CoordinatedTurn, RangeBearing, StateOrder};
pub mod ikf;
pub mod imm;
pub mod predictor;
pub use ikf::{Ikf, IkfStep, Innovation};
pub use imm::{Imm, ImmState, ImmStep, TimedImm};
pub use predictor::MultiStep;
pub mod augmented;
pub mod sampling;
pub use augmented::{AugmentedUkf, NoisyObservation, NoisyTransition};
