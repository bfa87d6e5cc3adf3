// The crate documentation is the README (its examples are compiled and run as doc tests).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod error;
pub mod gaussian;
pub mod io;
pub mod predictor;
pub mod trajectory;
pub mod window;

pub use error::{CrateError, Error, Result};
pub use gaussian::Gaussian;
pub use predictor::{
    Forecast, MAX_HORIZON, Predictor, check_forecast_args, check_forecast_args_with_max,
    load_nothing,
};
pub use trajectory::{MAX_AXES, Point, Trajectory};
