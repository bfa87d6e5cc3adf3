//! # trajpred-core
//!
//! The types every trajpred crate shares:
//!
//! - [`Trajectory`]: timestamps and points of 1, 2 or 3 axes, validated once at construction
//!   (lengths agree, values finite, timestamps strictly increasing);
//! - [`window`]: sliding windows and the Hankel design matrices of multi-step linear prediction;
//! - [`Predictor`] and [`Forecast`]: the one interface behind which every method of trajpred
//!   stands (fit on training trajectories, forecast `horizon` steps from a history);
//! - [`Gaussian`]: mean and covariance, generic over nalgebra's static and dynamic sizes;
//! - [`Error`]: structured errors; nothing in this crate panics on bad input.
//!
//! ```
//! use trajpred_core::{window::hankel_design, Trajectory};
//! let tr = Trajectory::uniform(0.0, 0.5, vec![(0..10).map(f64::from).collect()])?;
//! let d = hankel_design(tr.axis(0), 3, 1)?;
//! assert_eq!(d.design.nrows(), 10 - 1 - 3 + 1);
//! # Ok::<(), trajpred_core::Error>(())
//! ```
#![forbid(unsafe_code)]

pub mod error;
pub mod gaussian;
pub mod io;
pub mod predictor;
pub mod trajectory;
pub mod window;

pub use error::{Error, Result};
pub use gaussian::Gaussian;
pub use predictor::{
    Forecast, MAX_HORIZON, Predictor, check_forecast_args, check_forecast_args_with_max,
    load_nothing,
};
pub use trajectory::{MAX_AXES, Point, Trajectory};
