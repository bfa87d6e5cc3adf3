// The crate documentation is the README (its example is compiled and run as a doc test).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

/// The linear algebra this crate takes and returns, re-exported so that a user needs no
/// separate (and exactly matching) nalgebra dependency.
pub use nalgebra;

mod cholesky;
pub mod error;
pub mod gsc;
mod kernels;
pub mod lars;

pub use error::{Error, Result};
pub use gsc::{GroupSparseCoder, GscParams};
pub use lars::{
    Exclusion, ExclusionReason, Gram, Lars, LarsParams, LarsPath, LarsPathOptions, Method,
    PathEvent, StopReason, lars_path,
};
