//! The machinery every model shares: seeded Xavier initialisation, z-score standardisation,
//! tensor read-back and the mini-batch training loop with early stopping.

use crate::config::{EpochReport, Optimizer, Progress, TrainConfig, TrainReport};
use crate::error::{CoreError, NeuralError, Result};
use crate::fused::adam::FusedAdam;
use burn::grad_clipping::GradientClippingConfig;
use burn::lr_scheduler::module_lr_scheduler::ModuleLrScheduler;
use burn::module::{Module, ModuleMapper, Param};
use burn::optim::{
    AdamConfig, GradientsParams, ModuleOptimizer, SgdConfig, momentum::MomentumConfig,
};
use burn::tensor::{Device, Tensor, TensorData};
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::time::Instant;
use trajpred_core::Trajectory;

/// The CPU device every model trains on: burn's pure-Rust `flex` backend with autodiff.
pub(crate) fn device() -> Device {
    Device::flex().autodiff()
}

/// A random generator for stream `stream` of a model seeded with `seed`.
pub(crate) fn rng(seed: u64, stream: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(stream);
    r
}

/// Re-initialises every parameter of a module from our own seeded generator, so runs are
/// reproducible without touching the framework's global random state (which parallel tests
/// would race on): rank-2 weights `[fan_in, fan_out]` Xavier-uniform
/// (bound `sqrt(6 / (fan_in + fan_out))`), rank-1 parameters (biases) zero.
pub(crate) struct XavierZeroBias<'a> {
    pub rng: &'a mut ChaCha8Rng,
}

impl ModuleMapper for XavierZeroBias<'_> {
    fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        let rng = &mut *self.rng;
        param.map(|t| {
            let dims = t.dims();
            let device = t.device();
            let require_grad = t.is_require_grad();
            let n: usize = dims.iter().product();
            let values: Vec<f32> = if D >= 2 {
                let fan_in = dims[0] as f64;
                let fan_out = dims[1..].iter().product::<usize>() as f64;
                let bound = (6.0 / (fan_in + fan_out)).sqrt();
                (0..n)
                    .map(|_| (rng.random::<f64>() * 2.0 - 1.0) * bound)
                    .map(|v| v as f32)
                    .collect()
            } else {
                vec![0.0; n]
            };
            Tensor::<D>::from_data(TensorData::new(values, dims), &device)
                .set_require_grad(require_grad)
        })
    }
}

/// Per-axis z-score standardisation fitted on training data (eq. 22-23 of the patent).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Standardizer {
    /// Mean per axis.
    pub mean: Vec<f64>,
    /// Standard deviation per axis (1 where the data are constant).
    pub std: Vec<f64>,
}

impl Standardizer {
    /// Fits mean and standard deviation per axis over every point of `series`
    /// (each series a list of axes).
    pub(crate) fn fit(series: &[Vec<&[f64]>], dim: usize) -> Self {
        let mut mean = vec![0.0; dim];
        let mut std = vec![1.0; dim];
        for k in 0..dim {
            let (mut n, mut s) = (0usize, 0.0);
            for axes in series {
                n += axes[k].len();
                s += axes[k].iter().sum::<f64>();
            }
            let mu = if n > 0 { s / n as f64 } else { 0.0 };
            let mut v = 0.0;
            for axes in series {
                v += axes[k].iter().map(|x| (x - mu) * (x - mu)).sum::<f64>();
            }
            let sd = if n > 1 { (v / n as f64).sqrt() } else { 0.0 };
            mean[k] = mu;
            std[k] = if sd > 1e-12 * (1.0 + mu.abs()) {
                sd
            } else {
                1.0
            };
        }
        Standardizer { mean, std }
    }

    /// `(x - mean) / std` for axis `k`.
    pub(crate) fn forward(&self, k: usize, x: f64) -> f64 {
        (x - self.mean[k]) / self.std[k]
    }

    /// `z * std + mean` for axis `k`.
    pub(crate) fn inverse(&self, k: usize, z: f64) -> f64 {
        z * self.std[k] + self.mean[k]
    }
}

/// Reads a tensor back as `f32` values.
pub(crate) fn read<const D: usize>(t: Tensor<D>) -> Result<Vec<f32>> {
    t.try_into_data()
        .map_err(|e| NeuralError::Tensor {
            reason: format!("{e:?}"),
        })?
        .try_into_vec::<f32>()
        .map_err(|e| NeuralError::Tensor {
            reason: format!("{e:?}"),
        })
}

/// Reads a one-element tensor back as `f64`.
pub(crate) fn read_scalar(t: Tensor<1>) -> Result<f64> {
    read(t)?
        .first()
        .map(|v| f64::from(*v))
        .ok_or_else(|| NeuralError::Tensor {
            reason: "empty loss tensor".into(),
        })
}

/// Mean squared error over every element.
pub(crate) fn mse<const D: usize>(pred: Tensor<D>, target: Tensor<D>) -> Tensor<1> {
    let d = pred - target;
    (d.clone() * d).mean()
}

/// The validation loss of a network.
pub(crate) type ValidationLoss<'a, N> = &'a dyn Fn(&N) -> Result<f64>;

/// Everything the generic loop needs from a model family.
pub(crate) struct LoopSpec<'a, N: Module> {
    /// Number of training samples (indexed 0..n).
    pub n_train: usize,
    /// The loss of a training batch, given the sample indices.
    pub batch_loss: &'a dyn Fn(&N, &[usize]) -> Tensor<1>,
    /// The validation loss (early stopping), if there is a validation split.
    pub validation_loss: Option<ValidationLoss<'a, N>>,
    /// The learning rates, per parameter group.
    pub lr: ModuleLrScheduler,
}

/// Mini-batch training: seeded shuffling each epoch, one optimizer step per batch, a report
/// per epoch through `progress`, early stopping with best-weight restore.
pub(crate) fn train_loop<N: Module>(
    mut net: N,
    spec: LoopSpec<'_, N>,
    cfg: &TrainConfig,
    network: usize,
    progress: Progress<'_>,
) -> Result<(N, TrainReport)> {
    let LoopSpec {
        n_train,
        batch_loss,
        validation_loss,
        mut lr,
    } = spec;
    if n_train == 0 {
        return Err(NeuralError::NoTrainingData {
            what: "no training samples",
        });
    }
    let clip = cfg
        .grad_clip_norm
        .map(|c| GradientClippingConfig::Norm(c as f32));
    let mut optim = match cfg.optimizer {
        // with the fused ops, Adam in one loop per parameter (burn's updates bit for bit)
        Optimizer::Adam { epsilon } if cfg.fused => {
            let optim = ModuleOptimizer::from(FusedAdam::new(epsilon as f32));
            match clip {
                Some(c) => optim.with_grad_clipping(c.init()),
                None => optim,
            }
        }
        Optimizer::Adam { epsilon } => AdamConfig::new()
            .with_epsilon(epsilon as f32)
            .with_grad_clipping(clip)
            .init(),
        Optimizer::Sgd { momentum } => {
            let m = (momentum > 0.0).then(|| {
                MomentumConfig::new()
                    .with_momentum(momentum)
                    .with_dampening(0.0)
            });
            SgdConfig::new()
                .with_momentum(m)
                .with_gradient_clipping(clip)
                .init()
        }
    };
    let mut rng = rng(cfg.seed, 2 * network as u64 + 1);
    let mut order: Vec<usize> = (0..n_train).collect();
    let mut report = TrainReport::default();
    let mut best: Option<(f64, N)> = None;
    let mut since_best = 0usize;
    for epoch in 1..=cfg.epochs {
        let start = Instant::now();
        order.shuffle(&mut rng);
        let mut sum = 0.0;
        let mut batches = 0usize;
        for idx in order.chunks(cfg.batch_size) {
            let loss = batch_loss(&net, idx);
            let grads = loss.backward();
            let value = read_scalar(loss)?;
            if !value.is_finite() {
                return Err(NeuralError::Diverged { epoch, loss: value });
            }
            sum += value;
            batches += 1;
            let grads = GradientsParams::from_grads(grads, &net);
            net = optim.step(lr.step(), net, grads);
        }
        let train_loss = sum / batches as f64;
        let mut validation = None;
        let mut stop = false;
        if let Some(vf) = validation_loss {
            let v = vf(&net.valid())?;
            if !v.is_finite() {
                return Err(NeuralError::Diverged { epoch, loss: v });
            }
            validation = Some(v);
            let min_delta = cfg.early_stopping.map_or(0.0, |e| e.min_delta);
            let improved = best.as_ref().is_none_or(|(b, _)| v < b - min_delta);
            if improved {
                best = Some((v, net.clone()));
                report.best_epoch = epoch;
                since_best = 0;
            } else {
                since_best += 1;
                if cfg.early_stopping.is_some_and(|e| since_best >= e.patience) {
                    stop = true;
                }
            }
        } else {
            report.best_epoch = epoch;
        }
        let rep = EpochReport {
            network,
            epoch,
            train_loss,
            validation_loss: validation,
            elapsed: start.elapsed(),
        };
        progress(&rep);
        report.epochs.push(rep);
        if stop {
            report.stopped_early = epoch < cfg.epochs;
            break;
        }
    }
    if let Some((_, b)) = best {
        net = b;
    }
    Ok((net, report))
}

/// The number of axes every training trajectory shares. Errors: [`NeuralError::NoTrainingData`]
/// for none, [`NeuralError::DimensionMismatch`] naming the first that differs from the first.
pub(crate) fn common_dim(train: &[Trajectory]) -> Result<usize> {
    let dim = train
        .first()
        .map(Trajectory::dim)
        .ok_or(NeuralError::NoTrainingData {
            what: "no training trajectories",
        })?;
    if let Some(t) = train.iter().find(|t| t.dim() != dim) {
        return Err(NeuralError::Core(CoreError::DimensionMismatch {
            what: "training trajectory axes",
            expected: dim,
            got: t.dim(),
        }));
    }
    Ok(dim)
}

/// Checks that every value of a raw series is finite.
pub(crate) fn check_finite(what: &'static str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(NeuralError::Core(CoreError::NonFinite { what, index })),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A loss read back from an empty tensor is a typed error, not a panic or a NaN.
    #[test]
    fn reading_an_empty_loss_is_a_tensor_error() {
        let empty = Tensor::<1>::from_data(TensorData::new(Vec::<f32>::new(), [0]), &device());
        assert!(matches!(
            read_scalar(empty),
            Err(NeuralError::Tensor { reason }) if reason == "empty loss tensor"
        ));
        let one = Tensor::<1>::from_data(TensorData::new(vec![2.5f32], [1]), &device());
        assert_eq!(read_scalar(one).expect("one value"), 2.5);
    }
}
