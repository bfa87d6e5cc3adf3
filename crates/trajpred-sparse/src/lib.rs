// The crate documentation is the README (its example is compiled and run as a doc test).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

/// The linear algebra this crate takes and returns, re-exported so that a user needs no
/// separate (and exactly matching) nalgebra dependency.
pub use nalgebra;

/// Builder setters, written once: each `name(arg: Type) => self.field = value;` becomes
/// `pub fn name(mut self, arg: Type) -> Self` that stores `value` in `field` and returns
/// `self` for chaining (its doc comment goes with it). The values are checked when the
/// settings are used (`validate`), not here.
macro_rules! setters {
    ($($(#[$doc:meta])* $name:ident($arg:ident: $ty:ty) => self.$field:ident = $value:expr;)*) => {
        $(
            $(#[$doc])*
            pub fn $name(mut self, $arg: $ty) -> Self {
                self.$field = $value;
                self
            }
        )*
    };
}

mod cholesky;
pub mod error;
pub mod gsc;
mod kernels;
pub mod lars;
mod workspace;

pub use error::{Error, Result};
pub use gsc::{GroupSparseCoder, GscParams};
pub use lars::{
    Exclusion, ExclusionReason, Gram, Lars, LarsParams, LarsPath, LarsPathOptions, Method,
    PathEvent, StopReason, lars_path,
};
