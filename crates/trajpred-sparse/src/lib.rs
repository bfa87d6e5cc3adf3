//! # trajpred-sparse
//!
//! Least angle regression and group sparse coding.
#![forbid(unsafe_code)]

mod cholesky;
pub mod error;
pub mod gsc;
pub mod lars;

pub use error::{Error, Result};
pub use gsc::{GroupSparseCoder, GscParams};
pub use lars::{Exclusion, ExclusionReason, Gram, Lars, LarsParams, Method, PathEvent, StopReason};
