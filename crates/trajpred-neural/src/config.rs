//! Training configuration, per-epoch reports and the small enums shared by every model.

use crate::error::{CoreError, Result};
use serde::{Deserialize, Serialize};
use std::time::Duration;

/// The gradient method that updates the weights.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Optimizer {
    /// Adam (Kingma and Ba) with `beta1 = 0.9`, `beta2 = 0.999` and the given epsilon
    /// (PyTorch's default is `1e-8`; burn's own default would be `1e-5`).
    Adam {
        /// The stabilising constant added to the root of the second moment.
        epsilon: f64,
    },
    /// Plain (mini-batch) gradient descent, optionally with momentum: classic back-propagation.
    Sgd {
        /// Momentum factor (0 for none).
        momentum: f64,
    },
}

impl Optimizer {
    /// Adam with PyTorch's epsilon `1e-8`.
    pub const ADAM: Optimizer = Optimizer::Adam { epsilon: 1e-8 };
    /// Plain gradient descent without momentum.
    pub const SGD: Optimizer = Optimizer::Sgd { momentum: 0.0 };
}

/// Early stopping on a validation split.
///
/// The validation set is the chronologically last `validation_fraction` of the training
/// samples of every training trajectory (never a random subset, so no future leaks into
/// training). Training stops when the validation loss has not improved by more than
/// `min_delta` for `patience` epochs, and the weights of the best epoch are restored.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EarlyStopping {
    /// Share of the samples held out, in `(0, 1)`.
    pub validation_fraction: f64,
    /// Epochs without improvement before stopping (at least 1).
    pub patience: usize,
    /// The smallest decrease of the validation loss that counts as an improvement.
    pub min_delta: f64,
}

impl Default for EarlyStopping {
    fn default() -> Self {
        EarlyStopping {
            validation_fraction: 0.2,
            patience: 20,
            min_delta: 0.0,
        }
    }
}

/// How a model is trained. Every field is public; the `with_*` methods chain.
///
/// ```
/// use trajpred_neural::{Optimizer, TrainConfig};
/// let cfg = TrainConfig::new(1e-3).with_epochs(20).with_batch_size(16).with_seed(7);
/// assert_eq!(cfg.optimizer, Optimizer::ADAM);
/// assert!(cfg.validate().is_ok());
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainConfig {
    /// Passes over the training samples.
    pub epochs: usize,
    /// Samples per gradient step (the last batch of an epoch may be smaller).
    pub batch_size: usize,
    /// Learning rate of the network weights.
    pub learning_rate: f64,
    /// The gradient method.
    pub optimizer: Optimizer,
    /// Seed of the weight initialisation and of the shuffling: the same seed gives the same
    /// weights and the same predictions.
    pub seed: u64,
    /// Optional early stopping on a validation split.
    pub early_stopping: Option<EarlyStopping>,
    /// Optional clipping of the gradient's global L2 norm.
    pub grad_clip_norm: Option<f64>,
    /// Whether the LSTM, the Elman RNN and the KFU-LSTM-Net run through the fused ops with
    /// their own backward pass (one autodiff node per recurrent layer / per unrolled filter,
    /// one for the windowed recurrent models' head and loss) instead of burn's per-operation autodiff, the
    /// reference; with it, Adam runs in one loop per parameter (burn's updates bit for bit).
    /// The same weights give the same predictions either way up to `f32` rounding (see
    /// `docs/neural.md`). Default `true`; for the other models it switches Adam's loop
    /// only.
    #[serde(default = "fused_default")]
    pub fused: bool,
}

fn fused_default() -> bool {
    true
}

impl TrainConfig {
    /// Adam (epsilon `1e-8`) at `learning_rate`, 100 epochs, batch 16, seed 0.
    pub fn new(learning_rate: f64) -> Self {
        TrainConfig {
            epochs: 100,
            batch_size: 16,
            learning_rate,
            optimizer: Optimizer::ADAM,
            seed: 0,
            early_stopping: None,
            grad_clip_norm: None,
            fused: true,
        }
    }

    setters! {
        /// Turns the fused LSTM / RNN / KFU ops on or off (off: burn's per-operation autodiff).
        with_fused(fused: bool) => self.fused = fused;
        /// Sets the number of epochs.
        with_epochs(epochs: usize) => self.epochs = epochs;
        /// Sets the batch size.
        with_batch_size(batch_size: usize) => self.batch_size = batch_size;
        /// Sets the learning rate of the network weights.
        with_learning_rate(learning_rate: f64) => self.learning_rate = learning_rate;
        /// Sets the optimizer.
        with_optimizer(optimizer: Optimizer) => self.optimizer = optimizer;
        /// Sets the seed.
        with_seed(seed: u64) => self.seed = seed;
        /// Turns on early stopping.
        with_early_stopping(early_stopping: EarlyStopping) => self.early_stopping = Some(early_stopping);
        /// Clips the global gradient norm.
        with_grad_clip_norm(norm: f64) => self.grad_clip_norm = Some(norm);
    }

    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &'static str, reason: &str, value: &dyn std::fmt::Display| {
            Err(CoreError::invalid_parameter(name, format!("{reason}, got {value}")).into())
        };
        if self.epochs == 0 {
            return bad("epochs", "must be at least 1", &self.epochs);
        }
        if self.batch_size == 0 {
            return bad("batch_size", "must be at least 1", &self.batch_size);
        }
        if !(self.learning_rate.is_finite() && self.learning_rate > 0.0) {
            return bad(
                "learning_rate",
                "must be finite and positive",
                &self.learning_rate,
            );
        }
        match self.optimizer {
            Optimizer::Adam { epsilon } if !(epsilon.is_finite() && epsilon > 0.0) => {
                return bad("optimizer.epsilon", "must be finite and positive", &epsilon);
            }
            Optimizer::Sgd { momentum }
                if !(momentum.is_finite() && (0.0..1.0).contains(&momentum)) =>
            {
                return bad("optimizer.momentum", "must lie in [0, 1)", &momentum);
            }
            _ => {}
        }
        if let Some(es) = &self.early_stopping {
            if !(es.validation_fraction > 0.0 && es.validation_fraction < 1.0) {
                return bad(
                    "early_stopping.validation_fraction",
                    "must lie in (0, 1)",
                    &es.validation_fraction,
                );
            }
            if es.patience == 0 {
                return bad(
                    "early_stopping.patience",
                    "must be at least 1",
                    &es.patience,
                );
            }
            if !(es.min_delta.is_finite() && es.min_delta >= 0.0) {
                return bad(
                    "early_stopping.min_delta",
                    "must be finite and non-negative",
                    &es.min_delta,
                );
            }
        }
        if let Some(c) = self.grad_clip_norm
            && !(c.is_finite() && c > 0.0)
        {
            return bad("grad_clip_norm", "must be finite and positive", &c);
        }
        Ok(())
    }
}

/// What one epoch of training did, handed to the progress callback.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpochReport {
    /// Which network this is: the axis in [`AxisMode::PerAxis`] mode, otherwise 0.
    pub network: usize,
    /// Epoch number, from 1.
    pub epoch: usize,
    /// Mean training loss over the epoch's batches (in standardised units).
    pub train_loss: f64,
    /// Loss on the validation split, when early stopping is on.
    pub validation_loss: Option<f64>,
    /// Wall-clock time of the epoch.
    pub elapsed: Duration,
}

/// The whole training history of one network.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TrainReport {
    /// One entry per epoch run.
    pub epochs: Vec<EpochReport>,
    /// The epoch whose weights were kept (the last one, or the best one under early stopping).
    pub best_epoch: usize,
    /// Whether early stopping ended training before the configured number of epochs.
    pub stopped_early: bool,
}

impl TrainReport {
    /// The training loss of the first epoch, if any.
    pub fn first_loss(&self) -> Option<f64> {
        self.epochs.first().map(|e| e.train_loss)
    }

    /// The training loss of the last epoch, if any.
    pub fn last_loss(&self) -> Option<f64> {
        self.epochs.last().map(|e| e.train_loss)
    }

    /// Total training time.
    pub fn total_time(&self) -> Duration {
        self.epochs.iter().map(|e| e.elapsed).sum()
    }
}

/// Whether a windowed model treats the axes separately or together.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum AxisMode {
    /// One network per axis, each mapping that axis's last `m` values to its next `T`
    /// values (the GSKF paper's setting: "each axis is predicted separately").
    PerAxis,
    /// One network for all axes: `m` points of `d` axes in, `T` points of `d` axes out.
    Joint,
}

/// Activation of the hidden fully connected layers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Activation {
    /// `max(0, x)`.
    Relu,
    /// Hyperbolic tangent (MATLAB's `tansig`, the classic BP network's choice).
    Tanh,
    /// Logistic sigmoid.
    Sigmoid,
}

/// A progress callback: called once after every epoch.
pub type Progress<'a> = &'a mut dyn FnMut(&EpochReport);
