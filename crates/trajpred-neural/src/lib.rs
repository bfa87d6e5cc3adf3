// The crate documentation is the README (its examples are compiled and run as doc tests).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

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

pub use burn;

pub mod arch;
pub mod config;
pub mod error;
mod fused;
pub mod kfu;
mod persist;
pub mod tabular;
mod train;
pub mod window;

pub use arch::{
    Architecture, FusedLstm, LstmArch, LstmCellState, MlpArch, RecurrentLayers, RnnArch,
};
pub use config::{
    Activation, AxisMode, EarlyStopping, EpochReport, Optimizer, Progress, TrainConfig, TrainReport,
};
pub use error::{NeuralError, Result};
pub use kfu::{KfuCell, KfuConfig, KfuLstmNet, Noise, kalman_update};
pub use tabular::{Dense, DistanceMlp, DistanceMlpConfig, PlanarRows};
pub use train::Standardizer;
pub use window::{LstmNet, Mlp, RnnNet, WindowConfig, WindowNet};
