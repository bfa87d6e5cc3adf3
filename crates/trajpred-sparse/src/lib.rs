// The crate documentation is the README (its example is compiled and run as a doc test).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

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
