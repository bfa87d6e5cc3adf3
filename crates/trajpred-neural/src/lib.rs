//! # trajpred-neural
//!
//! The neural baselines of the trajpred papers on [burn](https://burn.dev) 0.22.1 with its
//! pure-Rust `flex` CPU backend and autodiff. The LSTM layers and the unrolled KFU filter
//! train through fused autodiff ops with their own backward pass (`TrainConfig::fused`,
//! default on), held by tests to burn's autodiff through the composed models, which stay as
//! the reference (`TrainConfig::with_fused(false)`):
//!
//! - [`Mlp`] (the GSKF paper's "BP"), [`RnnNet`] and [`LstmNet`]: instances of
//!   [`WindowNet`], mapping the last `m` points to the next `T` points (direct multi-step
//!   output), per axis or jointly ([`AxisMode`]);
//! - [`KfuLstmNet`]: the patent's Kalman-filter-unfolded LSTM, an LSTM transition corrected
//!   at every step by a differentiable Kalman update ([`kalman_update`]) with learnable
//!   diagonal `Q` and `R`, trained end to end.
//!
//! Every model is a [`trajpred_core::Predictor`] (`fit` trains, `forecast` predicts), is
//! seeded ([`TrainConfig::seed`]: same seed, same weights, same predictions), reports every
//! epoch through a callback (`fit_with`), can stop early on a validation split, and saves to
//! and loads from one file. The papers' settings are presets: [`Mlp::gskf_bp`],
//! [`LstmNet::gskf_lstm`], [`RnnNet::patent_baseline`], [`LstmNet::patent_baseline`],
//! [`KfuLstmNet::patent`]. Decisions where the papers are silent are in `docs/neural.md`.
//!
//! ```
//! use trajpred_core::{Predictor, Trajectory};
//! use trajpred_neural::{AxisMode, LstmArch, LstmNet, RecurrentLayers, TrainConfig, WindowConfig};
//!
//! let t: Vec<f64> = (0..60).map(|i| i as f64 * 0.1).collect();
//! let train = Trajectory::uniform(0.0, 0.1, vec![
//!     t.iter().map(|s| s.sin()).collect(),
//!     t.iter().map(|s| s.cos()).collect(),
//! ])?;
//! let mut lstm = LstmNet::new(
//!     LstmArch(RecurrentLayers { layers: vec![8], fc: vec![], ..Default::default() }),
//!     WindowConfig { window: 4, horizon: 2, axes: AxisMode::Joint },
//!     TrainConfig::new(1e-2).with_epochs(2).with_seed(1),
//! )?;
//! let mut losses = Vec::new();
//! lstm.fit_with(std::slice::from_ref(&train), &mut |e| losses.push(e.train_loss))?;
//! assert_eq!(losses.len(), 2);
//! let forecast = lstm.forecast(&train, 3)?;
//! assert_eq!(forecast.horizon(), 3);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Training is slow in an unoptimised build: the workspace compiles dependencies with
//! `opt-level = 2` even in test builds.
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
pub use train::Standardizer;
pub use window::{LstmNet, Mlp, RnnNet, WindowConfig, WindowNet};
