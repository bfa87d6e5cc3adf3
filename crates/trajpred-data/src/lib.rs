//! # trajpred-data
//!
//! Trajectory data for trajpred, in metres:
//!
//! - [`geodesy`]: WGS84 latitude/longitude/altitude to a local east-north-up frame (via ECEF,
//!   exact) and back;
//! - [`synthetic`]: eq. (20) of the MSTPM-GSKF paper and the three curves of the KFU-LSTM-Net
//!   patent;
//! - [`noise`]: additive white Gaussian noise at a given SNR in dB, with an injected RNG;
//!
//! Every fallible function returns [`Error`]; nothing panics on bad input.
#![forbid(unsafe_code)]

pub mod error;
pub mod geodesy;
pub mod noise;
pub mod synthetic;

pub use error::{Error, Result};
