// The crate documentation is the README (its examples are compiled and run as doc tests).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod dataset;
pub mod harness;
pub mod params;
pub mod plot;
pub mod predictors;
pub mod protocol;
pub mod registry;

pub use trajpred_core::{Error, Forecast, Predictor, Result, Trajectory};
