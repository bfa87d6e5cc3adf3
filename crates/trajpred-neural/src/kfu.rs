//! [`KfuLstmNet`]: the Kalman-filter-unfolded LSTM of the patent (`docs/papers.md` D.1).
//!
//! Per step `t` an LSTM (stacked layers, then fully connected layers) maps the previous
//! posterior to the prior `y(t|t-1) = y(t-1|t-1) + f(y(t-1|t-1))`; the diagonal Kalman update
//! [`kalman_update`] with learnable `Q = exp(log_q)`, `R = exp(log_r)` corrects it with the
//! observation `z(t)`. The unrolled filter is trained end to end through burn's autodiff.

use crate::arch::{FusedLstm, Head, LstmCellState};
use crate::config::{Activation, EpochReport, TrainConfig, TrainReport};
use crate::error::{CoreError, NeuralError, Result};
use crate::fused::{self, kfu::Spec};
use crate::persist;
use crate::train::{
    LoopSpec, Standardizer, XavierZeroBias, check_finite, common_dim, device, mse, read, rng,
    train_loop,
};
use burn::lr_scheduler::module_lr_scheduler::ModuleLrScheduler;
use burn::module::{Module, Param, ParamGroup};
use burn::tensor::{Device, Tensor, TensorData};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Mutex;
use trajpred_core::{Forecast, Predictor, Trajectory, check_forecast_args};

/// One diagonal Kalman update with `F = H = I`, written in differentiable tensor ops.
///
/// All tensors are `[batch, d]` (`q` and `r` may be `[1, d]` and broadcast):
/// - `P(t|t-1) = P(t-1|t-1) + Q`
/// - `K = P(t|t-1) / (P(t|t-1) + R)`
/// - `y(t|t) = y(t|t-1) + K (z(t) - y(t|t-1))`
/// - `P(t|t) = (1 - K) P(t|t-1)`
///
/// Returns `(y(t|t), P(t|t))`.
pub fn kalman_update(
    prior: Tensor<2>,
    p: Tensor<2>,
    q: Tensor<2>,
    r: Tensor<2>,
    z: Tensor<2>,
) -> (Tensor<2>, Tensor<2>) {
    let p_prior = p + q;
    let k = p_prior.clone() / (p_prior.clone() + r);
    let posterior = prior.clone() + k.clone() * (z - prior);
    let p_post = (k.neg() + 1.0) * p_prior;
    (posterior, p_post)
}

/// The longest unrolled sequence ([`KfuConfig::seq_len`]).
pub const MAX_SEQ_LEN: usize = 100_000;

/// Architecture and filter settings of [`KfuLstmNet`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KfuConfig {
    /// Hidden sizes of the stacked LSTM layers (patent: 64, 64).
    pub layers: Vec<usize>,
    /// Hidden sizes of the fully connected layers before the linear output layer (patent:
    /// "two fully connected layers", so one hidden layer of 64 and the output layer).
    pub fc: Vec<usize>,
    /// Activation of the fully connected hidden layers.
    pub activation: Activation,
    /// Initial `log Q` per axis (standardised units).
    pub init_log_q: f64,
    /// Initial `log R` per axis (standardised units).
    pub init_log_r: f64,
    /// Initial state covariance `P(0|0)` (diagonal, standardised units).
    pub p0: f64,
    /// Learning rate of `log Q` and `log R` (their own parameter group).
    pub noise_learning_rate: f64,
    /// Length of the training sub-sequences, and the most recent observations a forecast
    /// filters through (the context).
    pub seq_len: usize,
    /// Step between the starts of consecutive training sub-sequences.
    pub stride: usize,
}

impl Default for KfuConfig {
    fn default() -> Self {
        KfuConfig {
            layers: vec![64, 64],
            fc: vec![64],
            activation: Activation::Relu,
            init_log_q: -4.0,
            init_log_r: -2.0,
            p0: 1.0,
            noise_learning_rate: 1e-2,
            seq_len: 50,
            stride: 10,
        }
    }
}

impl KfuConfig {
    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &'static str, reason: &str, value: &dyn std::fmt::Display| {
            Err(CoreError::invalid_parameter(name, format!("{reason}, got {value}")).into())
        };
        crate::arch::check_sizes("layers", &self.layers, true)?;
        crate::arch::check_sizes("fc", &self.fc, false)?;
        if !(self.init_log_q.is_finite() && self.init_log_r.is_finite()) {
            return bad(
                "init_log_q/init_log_r",
                "must be finite",
                &format!("{} / {}", self.init_log_q, self.init_log_r),
            );
        }
        if !(self.p0.is_finite() && self.p0 > 0.0) {
            return bad("p0", "must be finite and positive", &self.p0);
        }
        if !(self.noise_learning_rate.is_finite() && self.noise_learning_rate >= 0.0) {
            return bad(
                "noise_learning_rate",
                "must be finite and non-negative",
                &self.noise_learning_rate,
            );
        }
        if !(3..=MAX_SEQ_LEN).contains(&self.seq_len) {
            return bad("seq_len", "must lie in 3..=100000", &self.seq_len);
        }
        if self.stride == 0 {
            return bad("stride", "must be at least 1", &self.stride);
        }
        Ok(())
    }
}

/// The learnable noise of the filter.
#[derive(Module, Debug)]
pub struct Noise {
    /// `log Q`, one per axis.
    pub log_q: Param<Tensor<1>>,
    /// `log R`, one per axis.
    pub log_r: Param<Tensor<1>>,
}

/// The weights of [`KfuLstmNet`]: the transition network and the noise parameters.
#[derive(Module, Debug)]
pub struct KfuCell {
    lstm: Vec<FusedLstm>,
    head: Head,
    /// `log Q` and `log R`.
    pub noise: Noise,
}

/// What one run of the filter over a batch of sequences produced (standardised units).
pub(crate) struct FilterRun {
    /// `y(t|t-1)` for `t = 1..c-1`: `[batch, c-1, d]`.
    pub(crate) priors: Tensor<3>,
    /// `y(t|t)` for `t = 1..c-1`: `[batch, c-1, d]`.
    pub(crate) posteriors: Tensor<3>,
    /// The one-step-ahead prior after the last observation, then further steps without
    /// update: `extra` tensors `[batch, d]`.
    pub(crate) ahead: Vec<Tensor<2>>,
}

impl KfuCell {
    pub(crate) fn new(cfg: &KfuConfig, d: usize, device: &Device) -> Self {
        let mut lstm = Vec::new();
        let mut h = d;
        for &size in &cfg.layers {
            lstm.push(FusedLstm::new(h, size, device));
            h = size;
        }
        KfuCell {
            lstm,
            head: Head::new(h, &cfg.fc, d, cfg.activation, device),
            noise: Noise {
                log_q: Param::from_tensor(Tensor::zeros([d], device)),
                log_r: Param::from_tensor(Tensor::zeros([d], device)),
            },
        }
    }

    /// `x + f(x)`, advancing the LSTM states.
    fn transition(&self, x: Tensor<2>, states: &mut [Option<LstmCellState>]) -> Tensor<2> {
        let mut inp = x.clone();
        for (l, s) in self.lstm.iter().zip(states.iter_mut()) {
            let ns = l.forward_step(inp, s.take());
            inp = ns.hidden.clone();
            *s = Some(ns);
        }
        x + self.head.forward(inp)
    }

    /// [`KfuCell::run`] through the fused op (`src/fused/kfu.rs`): the whole filter one
    /// autodiff node, the parameters packed into one vector.
    pub(crate) fn run_fused(
        &self,
        z: Tensor<3>,
        spec: &Spec,
        p0: f64,
        extra: usize,
    ) -> Result<FilterRun> {
        let [b, c, d] = z.dims();
        let mut parts = Vec::new();
        for l in &self.lstm {
            let (w_ih, bias, w_hh) = l.fused_params();
            let ([i, g], [h, _]) = (w_ih.dims(), w_hh.dims());
            parts.extend([w_ih.reshape([i * g]), bias, w_hh.reshape([h * g])]);
        }
        parts.extend(self.head.fused_params());
        parts.extend([self.noise.log_q.val(), self.noise.log_r.val()]);
        let out = fused::kfu::sequence(z, Tensor::cat(parts, 0), spec, p0, extra)?;
        let n = c.saturating_sub(1);
        let part = |from: usize, to: usize, k: usize| {
            if to > from {
                out.clone().slice([0..b, from..to, k * d..(k + 1) * d])
            } else {
                Tensor::<3>::zeros([b, 0, d], &out.device())
            }
        };
        Ok(FilterRun {
            priors: part(0, n, 0),
            posteriors: part(0, n, 1),
            ahead: (n..n + extra)
                .map(|t| part(t, t + 1, 0).reshape([b, d]))
                .collect(),
        })
    }

    /// Filters `z: [batch, c, d]` from `y(0|0) = z(0)`, `P(0|0) = p0`, and predicts `extra`
    /// steps past the last observation: through the fused op when `spec` is given and the
    /// tensors allow it, otherwise composed of burn's tensor operations (the reference).
    pub(crate) fn run(
        &self,
        z: Tensor<3>,
        p0: f64,
        extra: usize,
        spec: Option<&Spec>,
    ) -> FilterRun {
        if let Some(spec) = spec
            && let Ok(run) = self.run_fused(z.clone(), spec, p0, extra)
        {
            return run;
        }
        let [b, c, d] = z.dims();
        let device = z.device();
        let q = self.noise.log_q.val().exp().unsqueeze::<2>();
        let r = self.noise.log_r.val().exp().unsqueeze::<2>();
        let mut x = z.clone().slice([0..b, 0..1, 0..d]).reshape([b, d]);
        let mut p = Tensor::<2>::full([b, d], p0, &device);
        let mut states: Vec<Option<LstmCellState>> = vec![None; self.lstm.len()];
        let mut priors = Vec::with_capacity(c);
        let mut posts = Vec::with_capacity(c);
        for t in 1..c {
            let prior = self.transition(x, &mut states);
            let zt = z.clone().slice([0..b, t..t + 1, 0..d]).reshape([b, d]);
            let (post, pp) = kalman_update(prior.clone(), p, q.clone(), r.clone(), zt);
            priors.push(prior);
            posts.push(post.clone());
            x = post;
            p = pp;
        }
        let mut ahead = Vec::with_capacity(extra);
        for _ in 0..extra {
            x = self.transition(x, &mut states);
            ahead.push(x.clone());
        }
        let stack = |v: Vec<Tensor<2>>| {
            if v.is_empty() {
                Tensor::<3>::zeros([b, 0, d], &device)
            } else {
                Tensor::stack(v, 1)
            }
        };
        FilterRun {
            priors: stack(priors),
            posteriors: stack(posts),
            ahead,
        }
    }
}

struct KfuFitted {
    dim: usize,
    scaler: Standardizer,
    cell: Mutex<KfuCell>,
    report: TrainReport,
}

#[derive(Serialize, Deserialize)]
struct KfuHeader {
    kind: String,
    config: KfuConfig,
    train: TrainConfig,
    dim: usize,
    scaler: Standardizer,
    report: TrainReport,
}

/// The Kalman-filter-unfolded LSTM network (`docs/papers.md` D.1) as a one-step-ahead predictor.
///
/// - Inputs are z-scored per axis with the training data's statistics; outputs are
///   de-standardised.
/// - [`KfuLstmNet::fit_supervised`] trains with the loss decided in `docs/papers.md` D.1,
///   `MSE(y(t|t), truth) + 0.5 MSE(y(t|t-1), truth)`, when the clean truth of the training
///   trajectories is known; [`Predictor::fit`] has only observations and trains the one-step
///   prediction error `MSE(y(t|t-1), z(t))` instead (see `docs/neural.md`).
/// - A forecast filters through the last `seq_len` observations of the history (the
///   training sub-sequence length), then predicts by iterating the transition without update.
pub struct KfuLstmNet {
    config: KfuConfig,
    train: TrainConfig,
    fitted: Option<KfuFitted>,
}

impl std::fmt::Debug for KfuLstmNet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KfuLstmNet")
            .field("config", &self.config)
            .field("train", &self.train)
            .field("fitted", &self.fitted.is_some())
            .finish()
    }
}

/// Name used in tables and on the command line.
const NAME: &str = "kfu-lstm";

fn series_of(t: &Trajectory) -> Vec<&[f64]> {
    (0..t.dim()).map(|k| t.axis(k)).collect()
}

impl KfuLstmNet {
    /// A model with the given architecture/filter settings and training configuration.
    pub fn new(config: KfuConfig, train: TrainConfig) -> Result<Self> {
        config.validate()?;
        train.validate()?;
        Ok(KfuLstmNet {
            config,
            train,
            fitted: None,
        })
    }

    /// The patent's settings (`docs/papers.md` D.1): 2 x 64 LSTM + two fully connected layers,
    /// Xavier weights, zero biases, Adam at learning rate 1e-4 (noise parameters 1e-2), batch 16,
    /// 300 epochs, sub-sequences of 50 steps every 10 steps, seed 0.
    pub fn patent() -> Result<Self> {
        KfuLstmNet::new(
            KfuConfig::default(),
            TrainConfig::new(1e-4).with_epochs(300).with_batch_size(16),
        )
    }

    /// The sizes of the fused filter op when training config asks for it.
    fn spec(&self, d: usize) -> Option<Spec> {
        self.train.fused.then(|| Spec {
            d,
            layers: self.config.layers.clone(),
            fc: self.config.fc.clone(),
            activation: self.config.activation,
        })
    }

    /// The architecture and filter settings.
    pub fn config(&self) -> &KfuConfig {
        &self.config
    }

    /// The training configuration.
    pub fn train_config(&self) -> &TrainConfig {
        &self.train
    }

    /// Replaces the training configuration; takes effect at the next fit.
    pub fn set_train_config(&mut self, train: TrainConfig) -> Result<()> {
        train.validate()?;
        self.train = train;
        Ok(())
    }

    /// The training report, once fitted.
    pub fn report(&self) -> Option<&TrainReport> {
        self.fitted.as_ref().map(|f| &f.report)
    }

    /// Number of axes, once fitted.
    pub fn dim(&self) -> Option<usize> {
        self.fitted.as_ref().map(|f| f.dim)
    }

    /// The learned `Q` and `R` diagonals (standardised units), once fitted.
    pub fn noise(&self) -> Result<(Vec<f64>, Vec<f64>)> {
        let cell = self.cell()?.1;
        let q = read(cell.noise.log_q.val().exp())?;
        let r = read(cell.noise.log_r.val().exp())?;
        Ok((
            q.into_iter().map(f64::from).collect(),
            r.into_iter().map(f64::from).collect(),
        ))
    }

    fn cell(&self) -> Result<(&KfuFitted, KfuCell)> {
        let f = self.fitted.as_ref().ok_or(NeuralError::NotFitted)?;
        let cell = f
            .cell
            .lock()
            .map_err(|_| NeuralError::Tensor {
                reason: "model lock poisoned".into(),
            })?
            .clone();
        Ok((f, cell))
    }

    fn init_cell(&self, dim: usize, device: &Device) -> KfuCell {
        let cell = KfuCell::new(&self.config, dim, device);
        let mut r = rng(self.train.seed, 0);
        let mut cell = cell.map(&mut XavierZeroBias { rng: &mut r });
        cell.noise = Noise {
            log_q: Param::from_tensor(Tensor::full([dim], self.config.init_log_q, device)),
            log_r: Param::from_tensor(Tensor::full([dim], self.config.init_log_r, device)),
        };
        cell
    }

    /// Trains with the loss of `docs/papers.md` D.1,
    /// `MSE(y(t|t), truth) + 0.5 MSE(y(t|t-1), truth)`, on noisy `observed` trajectories whose
    /// clean `truth` is known (same lengths).
    pub fn fit_supervised(
        &mut self,
        observed: &[Trajectory],
        truth: &[Trajectory],
        progress: &mut dyn FnMut(&EpochReport),
    ) -> Result<&TrainReport> {
        if observed.len() != truth.len() {
            return Err(NeuralError::Core(CoreError::DimensionMismatch {
                what: "number of truth trajectories",
                expected: observed.len(),
                got: truth.len(),
            }));
        }
        for (o, t) in observed.iter().zip(truth) {
            if o.len() != t.len() {
                return Err(NeuralError::Core(CoreError::DimensionMismatch {
                    what: "truth trajectory length",
                    expected: o.len(),
                    got: t.len(),
                }));
            }
            if o.dim() != t.dim() {
                return Err(NeuralError::Core(CoreError::DimensionMismatch {
                    what: "truth trajectory axes",
                    expected: o.dim(),
                    got: t.dim(),
                }));
            }
        }
        self.fit_inner(observed, Some(truth), progress)
    }

    /// Trains on observations only (the [`Predictor::fit`] path): the loss is the one-step
    /// prediction error `MSE(y(t|t-1), z(t))`.
    pub fn fit_observed(
        &mut self,
        observed: &[Trajectory],
        progress: &mut dyn FnMut(&EpochReport),
    ) -> Result<&TrainReport> {
        self.fit_inner(observed, None, progress)
    }

    fn fit_inner(
        &mut self,
        observed: &[Trajectory],
        truth: Option<&[Trajectory]>,
        progress: &mut dyn FnMut(&EpochReport),
    ) -> Result<&TrainReport> {
        let dim = common_dim(observed)?;
        let shortest = observed.iter().map(Trajectory::len).min().unwrap_or(0);
        if shortest < 3 {
            return Err(NeuralError::Core(CoreError::TooShort {
                what: "shortest training trajectory (in points)",
                needed: 3,
                got: shortest,
            }));
        }
        let series: Vec<Vec<&[f64]>> = observed.iter().map(series_of).collect();
        let scaler = Standardizer::fit(&series, dim);
        let len = self.config.seq_len.min(shortest);
        let stride = self.config.stride;
        // (observation, target) sub-sequences, flattened [len, d] step-major
        let mut obs: Vec<f32> = Vec::new();
        let mut tgt: Vec<f32> = Vec::new();
        let mut val_obs: Vec<f32> = Vec::new();
        let mut val_tgt: Vec<f32> = Vec::new();
        let split = self.train.early_stopping.map(|e| e.validation_fraction);
        for (j, o) in observed.iter().enumerate() {
            let target = truth.map_or(o, |t| &t[j]);
            let n = o.len();
            let starts: Vec<usize> = (0..=n - len).step_by(stride).collect();
            let n_val = split.map_or(0, |s| {
                if starts.len() >= 2 {
                    ((starts.len() as f64 * s).round() as usize).clamp(1, starts.len() - 1)
                } else {
                    0
                }
            });
            for (i, &s0) in starts.iter().enumerate() {
                let (ob, tg) = if i >= starts.len() - n_val {
                    (&mut val_obs, &mut val_tgt)
                } else {
                    (&mut obs, &mut tgt)
                };
                for s in s0..s0 + len {
                    for k in 0..dim {
                        ob.push(scaler.forward(k, o.axis(k)[s]) as f32);
                        tg.push(scaler.forward(k, target.axis(k)[s]) as f32);
                    }
                }
            }
        }
        let stride_len = len * dim;
        let n_train = obs.len() / stride_len;
        let n_val = val_obs.len() / stride_len;
        let device = device();
        let cell = self.init_cell(dim, &device);
        let p0 = self.config.p0;
        let supervised = truth.is_some();
        let spec = self.spec(dim);
        let spec = spec.as_ref();
        let dev = &device;
        let loss_of = move |cell: &KfuCell, zo: &[f32], zt: &[f32], b: usize| {
            let z = Tensor::<3>::from_data(TensorData::new(zo.to_vec(), [b, len, dim]), dev);
            let y = Tensor::<3>::from_data(TensorData::new(zt.to_vec(), [b, len, dim]), dev);
            let run = cell.run(z, p0, 0, spec);
            let y1 = y.slice([0..b, 1..len, 0..dim]);
            if supervised {
                mse(run.posteriors, y1.clone()) + mse(run.priors, y1) * 0.5
            } else {
                mse(run.priors, y1)
            }
        };
        let gather = |src: &[f32], idx: &[usize]| -> Vec<f32> {
            let mut v = Vec::with_capacity(idx.len() * stride_len);
            for &i in idx {
                v.extend_from_slice(&src[i * stride_len..(i + 1) * stride_len]);
            }
            v
        };
        let (obs_r, tgt_r) = (&obs, &tgt);
        let batch_loss = |cell: &KfuCell, idx: &[usize]| {
            loss_of(cell, &gather(obs_r, idx), &gather(tgt_r, idx), idx.len())
        };
        let (vo, vt) = (&val_obs, &val_tgt);
        let validation_loss = |cell: &KfuCell| -> Result<f64> {
            let mut total = 0.0;
            let all: Vec<usize> = (0..n_val).collect();
            for idx in all.chunks(64) {
                let l = loss_of(cell, &gather(vo, idx), &gather(vt, idx), idx.len());
                total += crate::train::read_scalar(l)? * idx.len() as f64;
            }
            Ok(total / n_val.max(1) as f64)
        };
        let lr = ModuleLrScheduler::new(self.train.learning_rate).with_group(
            ParamGroup::ids_from_module(cell.noise.clone()),
            self.config.noise_learning_rate,
        );
        let spec = LoopSpec {
            n_train,
            batch_loss: &batch_loss,
            validation_loss: (n_val > 0)
                .then_some(&validation_loss as &dyn Fn(&KfuCell) -> Result<f64>),
            lr,
        };
        let (cell, report) = train_loop(cell, spec, &self.train, 0, progress)?;
        self.fitted = Some(KfuFitted {
            dim,
            scaler,
            cell: Mutex::new(cell.valid()),
            report,
        });
        self.report().ok_or(NeuralError::NotFitted)
    }

    /// Filters through the last `seq_len` observations of `history` (points of `dim` axes,
    /// original units) and predicts `horizon` points after it.
    pub fn predict_series(&self, history: &[Vec<f64>], horizon: usize) -> Result<Vec<Vec<f64>>> {
        let (f, cell) = self.cell()?;
        let dim = f.dim;
        if history.is_empty() {
            return Err(NeuralError::Core(CoreError::TooShort {
                what: "history (in points)",
                needed: 1,
                got: 0,
            }));
        }
        let c = history.len().min(self.config.seq_len);
        let recent = &history[history.len() - c..];
        let mut z = Vec::with_capacity(c * dim);
        for (i, p) in recent.iter().enumerate() {
            if p.len() != dim {
                return Err(NeuralError::Core(CoreError::DimensionMismatch {
                    what: "history point axes",
                    expected: dim,
                    got: p.len(),
                }));
            }
            check_finite("history", p).map_err(|_| CoreError::NonFinite {
                what: "history",
                index: history.len() - c + i,
            })?;
            z.extend(
                p.iter()
                    .enumerate()
                    .map(|(k, &v)| f.scaler.forward(k, v) as f32),
            );
        }
        let device = device();
        let z = Tensor::<3>::from_data(TensorData::new(z, [1, c, dim]), &device);
        let run = cell.run(z, self.config.p0, horizon, self.spec(dim).as_ref());
        let mut out = Vec::with_capacity(horizon);
        for (s, t) in run.ahead.into_iter().enumerate() {
            let v = read(t)?;
            let p: Vec<f64> = (0..dim)
                .map(|k| f.scaler.inverse(k, f64::from(v[k])))
                .collect();
            if p.iter().any(|x| !x.is_finite()) {
                return Err(NeuralError::Core(CoreError::NonFinite {
                    what: "network output",
                    index: s,
                }));
            }
            out.push(p);
        }
        Ok(out)
    }

    /// The one-step-ahead predictions along a whole observed trajectory, in one batched pass:
    /// entry `i` predicts point `i + 1` from points `0..=i` only (exactly what
    /// [`Predictor::forecast`] with that history and horizon 1 returns, up to rounding).
    /// Returns `len - 1` points.
    pub fn one_step_ahead(&self, observed: &Trajectory) -> Result<Vec<Vec<f64>>> {
        let (f, cell) = self.cell()?;
        let dim = f.dim;
        if observed.dim() != dim {
            return Err(NeuralError::Core(CoreError::DimensionMismatch {
                what: "trajectory axes",
                expected: dim,
                got: observed.dim(),
            }));
        }
        let n = observed.len();
        if n < 2 {
            return Err(NeuralError::Core(CoreError::TooShort {
                what: "trajectory (in points)",
                needed: 2,
                got: n,
            }));
        }
        let l = self.config.seq_len;
        let spec = self.spec(dim);
        let zs: Vec<f32> = (0..n)
            .flat_map(|i| (0..dim).map(move |k| (i, k)))
            .map(|(i, k)| f.scaler.forward(k, observed.axis(k)[i]) as f32)
            .collect();
        let device = device();
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(n - 1);
        let de = |v: &[f32]| -> Vec<f64> {
            (0..dim)
                .map(|k| f.scaler.inverse(k, f64::from(v[k])))
                .collect()
        };
        // origins with a history shorter than the context: one filter from point 0
        let c = n.min(l);
        let z = Tensor::<3>::from_data(
            TensorData::new(zs[..c * dim].to_vec(), [1, c, dim]),
            &device,
        );
        let run = cell.run(z, self.config.p0, 1, spec.as_ref());
        let priors = read(run.priors)?;
        for t in 0..c - 1 {
            out.push(de(&priors[t * dim..(t + 1) * dim]));
        }
        if let Some(last) = run.ahead.into_iter().next()
            && c < n
        {
            out.push(de(&read(last)?));
        }
        // origins i >= l: history window i+1-l..=i, batched
        let origins: Vec<usize> = (l..n - 1).collect();
        for chunk in origins.chunks(256) {
            let mut v = Vec::with_capacity(chunk.len() * l * dim);
            for &i in chunk {
                v.extend_from_slice(&zs[(i + 1 - l) * dim..(i + 1) * dim]);
            }
            let z = Tensor::<3>::from_data(TensorData::new(v, [chunk.len(), l, dim]), &device);
            let run = cell.run(z, self.config.p0, 1, spec.as_ref());
            if let Some(a) = run.ahead.into_iter().next() {
                let vals = read(a)?;
                for b in 0..chunk.len() {
                    out.push(de(&vals[b * dim..(b + 1) * dim]));
                }
            }
        }
        if let Some(i) = out.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(NeuralError::Core(CoreError::NonFinite {
                what: "network output",
                index: i,
            }));
        }
        Ok(out)
    }

    /// Saves the trained model to one file; see [`KfuLstmNet::load`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let (f, cell) = self.cell()?;
        let header = KfuHeader {
            kind: NAME.to_string(),
            config: self.config.clone(),
            train: self.train.clone(),
            dim: f.dim,
            scaler: f.scaler.clone(),
            report: f.report.clone(),
        };
        persist::write(path, &persist::to_json(path, &header)?, &[cell])
    }

    /// Loads a model saved by [`KfuLstmNet::save`].
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let (header, records) = persist::read(path)?;
        Self::from_parts(path, &header, records)
    }

    /// [`KfuLstmNet::load`] from the bytes of a model file; errors name the source `<bytes>`.
    pub fn load_bytes(bytes: &[u8]) -> Result<Self> {
        let path = Path::new("<bytes>");
        let (header, records) = persist::parse(path, bytes)?;
        Self::from_parts(path, &header, records)
    }

    fn from_parts(path: &Path, header: &str, mut records: Vec<Vec<u8>>) -> Result<Self> {
        let h: KfuHeader = persist::from_json(path, header)?;
        persist::check_header(path, h.dim, &h.scaler)?;
        if h.kind != NAME || records.len() != 1 {
            return Err(NeuralError::Persistence {
                path: path.display().to_string(),
                reason: format!("not a `{NAME}` model file"),
            });
        }
        let mut model = KfuLstmNet::new(h.config, h.train)?;
        let device = device();
        let cell = model.init_cell(h.dim, &device);
        let cell = persist::load_into(path, cell, records.remove(0))?.valid();
        model.fitted = Some(KfuFitted {
            dim: h.dim,
            scaler: h.scaler,
            cell: Mutex::new(cell),
            report: h.report,
        });
        Ok(model)
    }
}

impl Predictor for KfuLstmNet {
    fn name(&self) -> &str {
        NAME
    }

    fn fit(&mut self, train: &[Trajectory]) -> trajpred_core::Result<()> {
        self.fit_observed(train, &mut |_| {})
            .map(|_| ())
            .map_err(|e| e.into_core(NAME))
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> trajpred_core::Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let dim = self
            .dim()
            .ok_or_else(|| NeuralError::NotFitted.into_core(NAME))?;
        if history.dim() != dim {
            return Err(trajpred_core::Error::DimensionMismatch {
                what: "history axes",
                expected: dim,
                got: history.dim(),
            });
        }
        let c = history.len().min(self.config.seq_len);
        let pts: Vec<Vec<f64>> = (history.len() - c..history.len())
            .map(|i| history.point(i).to_vec())
            .collect();
        let steps = self
            .predict_series(&pts, horizon)
            .map_err(|e| e.into_core(NAME))?;
        Forecast::new(dim, steps)
    }

    fn min_history(&self) -> usize {
        1
    }
}
