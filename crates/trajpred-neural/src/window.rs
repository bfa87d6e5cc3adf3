//! [`WindowNet`]: a network that maps the last `m` points of a series to the next `T` points
//! (direct multi-step output), trained on sliding windows of the training trajectories.
//! [`Mlp`], [`RnnNet`] and [`LstmNet`] are its three instances.

use crate::arch::{Architecture, LstmArch, MlpArch, RecurrentLayers, RnnArch};
use crate::config::{Activation, AxisMode, EpochReport, Optimizer, TrainConfig, TrainReport};
use crate::error::{CoreError, NeuralError, Result};
use crate::persist;
use crate::train::{
    LoopSpec, Standardizer, XavierZeroBias, check_finite, common_dim, device, read, rng, train_loop,
};
use burn::lr_scheduler::module_lr_scheduler::ModuleLrScheduler;
use burn::module::Module;
use burn::tensor::{Device, Tensor, TensorData};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Mutex;
use trajpred_core::{Forecast, Predictor, Trajectory, check_forecast_args};

/// The papers' "BP" network: a multilayer perceptron on the flattened window.
pub type Mlp = WindowNet<MlpArch>;
/// Stacked Elman RNN layers + fully connected layers.
pub type RnnNet = WindowNet<RnnArch>;
/// Stacked LSTM layers + fully connected layers.
pub type LstmNet = WindowNet<LstmArch>;

/// The longest input window and trained horizon of a windowed model.
pub const MAX_WINDOW: usize = 4096;

/// Window length, horizon and axis handling of a windowed model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct WindowConfig {
    /// Input window `m`: the number of most recent points the network sees.
    pub window: usize,
    /// Trained horizon `T`: the network outputs steps `1..=T` at once.
    pub horizon: usize,
    /// One network per axis, or one for all axes.
    pub axes: AxisMode,
}

impl WindowConfig {
    /// Checks `1 <= m <= MAX_WINDOW` and `1 <= T <= MAX_WINDOW`.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("window", self.window), ("horizon", self.horizon)] {
            if !(1..=MAX_WINDOW).contains(&v) {
                return Err(NeuralError::Core(CoreError::InvalidParameter {
                    name,
                    reason: format!("must lie in 1..={MAX_WINDOW}, got {v}"),
                }));
            }
        }
        Ok(())
    }

    /// The shortest training trajectory that yields one sample: `m + T` points.
    pub fn min_series(&self) -> usize {
        self.window + self.horizon
    }
}

/// A fitted model and a snapshot of its networks.
type FittedNets<'a, N> = (&'a Fitted<N>, Vec<N>);

struct Fitted<N> {
    dim: usize,
    scaler: Standardizer,
    /// Behind a mutex because burn modules are `Send` but not `Sync`; forecasts clone the
    /// (reference-counted) weights out and run without holding the lock.
    nets: Mutex<Vec<N>>,
    reports: Vec<TrainReport>,
}

/// A windowed multi-step network of architecture `A`; see [`Mlp`], [`RnnNet`], [`LstmNet`].
///
/// Inputs and outputs are z-scored per axis with the training data's mean and standard
/// deviation; predictions are de-standardised. Asked for more steps than its trained
/// horizon `T`, it feeds its own predictions back (recursive multi-step).
pub struct WindowNet<A: Architecture> {
    arch: A,
    layout: WindowConfig,
    train: TrainConfig,
    fitted: Option<Fitted<A::Net>>,
}

impl<A: Architecture> std::fmt::Debug for WindowNet<A> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WindowNet")
            .field("arch", &self.arch)
            .field("layout", &self.layout)
            .field("train", &self.train)
            .field("fitted", &self.fitted.is_some())
            .finish()
    }
}

#[derive(Serialize, Deserialize)]
struct Header<A> {
    kind: String,
    arch: A,
    layout: WindowConfig,
    train: TrainConfig,
    dim: usize,
    scaler: Standardizer,
    reports: Vec<TrainReport>,
}

/// Training samples: `n` windows `[m, f]` and targets `[out]`, flattened.
struct Samples {
    x: Vec<f32>,
    y: Vec<f32>,
    n: usize,
    m: usize,
    f: usize,
    out: usize,
}

impl Samples {
    fn new(m: usize, f: usize, out: usize) -> Self {
        Samples {
            x: Vec::new(),
            y: Vec::new(),
            n: 0,
            m,
            f,
            out,
        }
    }

    fn push(&mut self, x: impl Iterator<Item = f64>, y: impl Iterator<Item = f64>) {
        self.x.extend(x.map(|v| v as f32));
        self.y.extend(y.map(|v| v as f32));
        self.n += 1;
    }

    fn batch(&self, idx: &[usize], device: &Device) -> (Tensor<3>, Tensor<2>) {
        let (sx, sy) = (self.m * self.f, self.out);
        let mut x = Vec::with_capacity(idx.len() * sx);
        let mut y = Vec::with_capacity(idx.len() * sy);
        for &i in idx {
            x.extend_from_slice(&self.x[i * sx..(i + 1) * sx]);
            y.extend_from_slice(&self.y[i * sy..(i + 1) * sy]);
        }
        (
            Tensor::from_data(TensorData::new(x, [idx.len(), self.m, self.f]), device),
            Tensor::from_data(TensorData::new(y, [idx.len(), self.out]), device),
        )
    }
}

impl<A: Architecture> WindowNet<A> {
    /// A model of architecture `arch`, window layout `layout`, trained with `train`.
    pub fn new(arch: A, layout: WindowConfig, train: TrainConfig) -> Result<Self> {
        arch.validate()?;
        layout.validate()?;
        train.validate()?;
        Ok(WindowNet {
            arch,
            layout,
            train,
            fitted: None,
        })
    }

    /// The architecture.
    pub fn arch(&self) -> &A {
        &self.arch
    }

    /// Window, horizon and axis mode.
    pub fn layout(&self) -> WindowConfig {
        self.layout
    }

    /// The training configuration.
    pub fn train_config(&self) -> &TrainConfig {
        &self.train
    }

    /// Replaces the training configuration (for example fewer epochs in a quick run); takes
    /// effect at the next `fit`.
    pub fn set_train_config(&mut self, train: TrainConfig) -> Result<()> {
        train.validate()?;
        self.train = train;
        Ok(())
    }

    /// The training reports of the fitted networks (one per axis in per-axis mode).
    pub fn reports(&self) -> Option<&[TrainReport]> {
        self.fitted.as_ref().map(|f| f.reports.as_slice())
    }

    /// Whether the model has been trained or loaded.
    pub fn is_fitted(&self) -> bool {
        self.fitted.is_some()
    }

    /// Number of axes the model was fitted on.
    pub fn dim(&self) -> Option<usize> {
        self.fitted.as_ref().map(|f| f.dim)
    }

    fn n_nets(&self, dim: usize) -> usize {
        match self.layout.axes {
            AxisMode::PerAxis => dim,
            AxisMode::Joint => 1,
        }
    }

    /// Features per window step and outputs of each network.
    fn shape(&self, dim: usize) -> (usize, usize) {
        match self.layout.axes {
            AxisMode::PerAxis => (1, self.layout.horizon),
            AxisMode::Joint => (dim, self.layout.horizon * dim),
        }
    }

    fn build_net(&self, dim: usize, device: &Device, seed_stream: u64) -> A::Net {
        let (f, out) = self.shape(dim);
        let net = self.arch.build(f, self.layout.window, out, device);
        let mut r = rng(self.train.seed, seed_stream);
        let net = net.map(&mut XavierZeroBias { rng: &mut r });
        self.arch.configure(net, &self.train)
    }

    /// Trains on `train` (each trajectory's sliding windows), calling `progress` after every
    /// epoch of every network, and returns the training reports.
    pub fn fit_with(
        &mut self,
        train: &[Trajectory],
        progress: &mut dyn FnMut(&EpochReport),
    ) -> Result<&[TrainReport]> {
        self.fit_inner(train, None, progress)
    }

    /// Trains on the windows of `inputs` with targets taken from `targets` at the same
    /// indices (same lengths and axes; e.g. noisy inputs and their clean truth): the sample
    /// of window `i` maps `inputs[i..i + m]` to `targets[i + m..i + m + T]`. Both are
    /// z-scored with the inputs' mean and standard deviation. With `targets == inputs` this
    /// is [`WindowNet::fit_with`].
    pub fn fit_targets(
        &mut self,
        inputs: &[Trajectory],
        targets: &[Trajectory],
        progress: &mut dyn FnMut(&EpochReport),
    ) -> Result<&[TrainReport]> {
        if inputs.len() != targets.len() {
            return Err(NeuralError::Core(CoreError::DimensionMismatch {
                what: "number of target trajectories",
                expected: inputs.len(),
                got: targets.len(),
            }));
        }
        for (i, t) in inputs.iter().zip(targets) {
            if i.len() != t.len() || i.dim() != t.dim() {
                return Err(NeuralError::Core(CoreError::DimensionMismatch {
                    what: "target trajectory length x axes",
                    expected: i.len() * i.dim(),
                    got: t.len() * t.dim(),
                }));
            }
        }
        self.fit_inner(inputs, Some(targets), progress)
    }

    fn fit_inner(
        &mut self,
        train: &[Trajectory],
        targets: Option<&[Trajectory]>,
        progress: &mut dyn FnMut(&EpochReport),
    ) -> Result<&[TrainReport]> {
        let dim = common_dim(train)?;
        let (m, h) = (self.layout.window, self.layout.horizon);
        let longest = train.iter().map(Trajectory::len).max().unwrap_or(0);
        if longest < m + h {
            return Err(NeuralError::Core(CoreError::TooShort {
                what: "longest training trajectory (in points)",
                needed: m + h,
                got: longest,
            }));
        }
        let series: Vec<Vec<&[f64]>> = train
            .iter()
            .map(|t| (0..dim).map(|k| t.axis(k)).collect())
            .collect();
        let scaler = Standardizer::fit(&series, dim);
        let z: Vec<Vec<Vec<f64>>> = series
            .iter()
            .map(|axes| {
                axes.iter()
                    .enumerate()
                    .map(|(k, a)| a.iter().map(|&v| scaler.forward(k, v)).collect())
                    .collect()
            })
            .collect();
        let zt: Option<Vec<Vec<Vec<f64>>>> = targets.map(|ts| {
            ts.iter()
                .map(|t| {
                    (0..dim)
                        .map(|k| t.axis(k).iter().map(|&v| scaler.forward(k, v)).collect())
                        .collect()
                })
                .collect()
        });
        let (f, out) = self.shape(dim);
        let split = self.train.early_stopping.map(|e| e.validation_fraction);
        let mut jobs = Vec::new();
        for net_index in 0..self.n_nets(dim) {
            let mut tr = Samples::new(m, f, out);
            let mut va = Samples::new(m, f, out);
            for (j, axes) in z.iter().enumerate() {
                let tgt = zt.as_ref().and_then(|v| v.get(j)).unwrap_or(axes);
                let n = axes[0].len();
                if n < m + h {
                    continue;
                }
                let count = n - m - h + 1;
                let n_val = split.map_or(0, |s| {
                    if count >= 2 {
                        ((count as f64 * s).round() as usize).clamp(1, count - 1)
                    } else {
                        0
                    }
                });
                for i in 0..count {
                    let dest = if i >= count - n_val { &mut va } else { &mut tr };
                    match self.layout.axes {
                        AxisMode::PerAxis => {
                            let a = &axes[net_index];
                            dest.push(
                                a[i..i + m].iter().copied(),
                                tgt[net_index][i + m..i + m + h].iter().copied(),
                            );
                        }
                        AxisMode::Joint => dest.push(
                            (i..i + m).flat_map(|s| axes.iter().map(move |a| a[s])),
                            (i + m..i + m + h).flat_map(|s| tgt.iter().map(move |a| a[s])),
                        ),
                    }
                }
            }
            jobs.push((net_index, tr, va));
        }
        let this = &*self;
        let results: Vec<Result<(A::Net, TrainReport)>> = if jobs.len() == 1 {
            jobs.into_iter()
                .map(|(i, tr, va)| this.train_one(dim, i, &tr, &va, progress))
                .collect()
        } else {
            // one thread per axis network (flex runs each op on one core); reports are
            // forwarded to the caller's callback on this thread, in arrival order
            std::thread::scope(|scope| {
                let (tx, rx) = std::sync::mpsc::channel::<EpochReport>();
                let handles: Vec<_> = jobs
                    .into_iter()
                    .map(|(i, tr, va)| {
                        let tx = tx.clone();
                        scope.spawn(move || {
                            this.train_one(dim, i, &tr, &va, &mut |r| {
                                // the receiver lives until every thread is joined
                                let _ = tx.send(r.clone());
                            })
                        })
                    })
                    .collect();
                drop(tx);
                for r in rx {
                    progress(&r);
                }
                handles
                    .into_iter()
                    .map(|h| {
                        h.join().unwrap_or_else(|_| {
                            Err(NeuralError::Tensor {
                                reason: "training thread panicked".into(),
                            })
                        })
                    })
                    .collect()
            })
        };
        let mut nets = Vec::new();
        let mut reports = Vec::new();
        for r in results {
            let (net, report) = r?;
            nets.push(net);
            reports.push(report);
        }
        self.fitted = Some(Fitted {
            dim,
            scaler,
            nets: Mutex::new(nets),
            reports,
        });
        Ok(self.reports().unwrap_or(&[]))
    }

    /// Trains network `net_index` on its samples (with validation samples `va`, possibly
    /// empty); returns the network ready for inference.
    fn train_one(
        &self,
        dim: usize,
        net_index: usize,
        tr: &Samples,
        va: &Samples,
        progress: &mut dyn FnMut(&EpochReport),
    ) -> Result<(A::Net, TrainReport)> {
        let device = device();
        let net = self.build_net(dim, &device, 2 * net_index as u64);
        let arch = &self.arch;
        let dev = &device;
        let batch_loss = move |n: &A::Net, idx: &[usize]| {
            let (x, y) = tr.batch(idx, dev);
            arch.loss(n, x, y)
        };
        let validation_loss = move |n: &A::Net| -> Result<f64> {
            let mut total = 0.0;
            let all: Vec<usize> = (0..va.n).collect();
            for idx in all.chunks(256) {
                let (x, y) = va.batch(idx, dev);
                let l = crate::train::read_scalar(arch.loss(n, x, y))?;
                total += l * idx.len() as f64;
            }
            Ok(total / va.n.max(1) as f64)
        };
        let spec = LoopSpec {
            n_train: tr.n,
            batch_loss: &batch_loss,
            validation_loss: (va.n > 0)
                .then_some(&validation_loss as &dyn Fn(&A::Net) -> Result<f64>),
            lr: ModuleLrScheduler::new(self.train.learning_rate),
        };
        let (net, report) = train_loop(net, spec, &self.train, net_index, progress)?;
        Ok((net.valid(), report))
    }

    fn nets(&self) -> Result<FittedNets<'_, A::Net>> {
        let fitted = self.fitted.as_ref().ok_or(NeuralError::NotFitted)?;
        let nets = fitted
            .nets
            .lock()
            .map_err(|_| NeuralError::Tensor {
                reason: "model lock poisoned".into(),
            })?
            .clone();
        Ok((fitted, nets))
    }

    /// Predicts the next `T` points (the trained horizon) after a window of exactly `m`
    /// points, each of `dim` axes, in original units. Rejects NaN, wrong point dimensions
    /// and a wrong window length with typed errors.
    pub fn predict_window(&self, window: &[Vec<f64>]) -> Result<Vec<Vec<f64>>> {
        let (fitted, nets) = self.nets()?;
        let (m, h, dim) = (self.layout.window, self.layout.horizon, fitted.dim);
        if window.len() != m {
            return Err(NeuralError::Core(CoreError::DimensionMismatch {
                what: "window length",
                expected: m,
                got: window.len(),
            }));
        }
        for (i, p) in window.iter().enumerate() {
            if p.len() != dim {
                return Err(NeuralError::Core(CoreError::DimensionMismatch {
                    what: "window point axes",
                    expected: dim,
                    got: p.len(),
                }));
            }
            check_finite("window", p).map_err(|_| CoreError::NonFinite {
                what: "window",
                index: i,
            })?;
        }
        let device = device();
        let z = |s: usize, k: usize| fitted.scaler.forward(k, window[s][k]) as f32;
        let mut outp = vec![vec![0.0; dim]; h];
        match self.layout.axes {
            AxisMode::PerAxis => {
                for (k, net) in nets.iter().enumerate() {
                    let x: Vec<f32> = (0..m).map(|s| z(s, k)).collect();
                    let x = Tensor::from_data(TensorData::new(x, [1, m, 1]), &device);
                    let y = read(self.arch.forward(net, x))?;
                    for (s, v) in y.iter().enumerate().take(h) {
                        outp[s][k] = fitted.scaler.inverse(k, f64::from(*v));
                    }
                }
            }
            AxisMode::Joint => {
                let x: Vec<f32> = (0..m)
                    .flat_map(|s| (0..dim).map(move |k| (s, k)))
                    .map(|(s, k)| z(s, k))
                    .collect();
                let x = Tensor::from_data(TensorData::new(x, [1, m, dim]), &device);
                let net = nets.first().ok_or(NeuralError::NotFitted)?;
                let y = read(self.arch.forward(net, x))?;
                for s in 0..h {
                    for k in 0..dim {
                        outp[s][k] = fitted.scaler.inverse(k, f64::from(y[s * dim + k]));
                    }
                }
            }
        }
        if let Some(i) = outp.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
            return Err(NeuralError::Core(CoreError::NonFinite {
                what: "network output",
                index: i,
            }));
        }
        Ok(outp)
    }

    /// Predicts `horizon` points after the last `m` points of `history` (raw points of `dim`
    /// axes). Beyond the trained horizon `T`, predictions are fed back as inputs.
    pub fn predict_series(&self, history: &[Vec<f64>], horizon: usize) -> Result<Vec<Vec<f64>>> {
        let m = self.layout.window;
        if history.len() < m {
            return Err(NeuralError::Core(CoreError::TooShort {
                what: "history (in points)",
                needed: m,
                got: history.len(),
            }));
        }
        let mut window: Vec<Vec<f64>> = history[history.len() - m..].to_vec();
        let mut out = Vec::with_capacity(horizon);
        while out.len() < horizon {
            let next = self.predict_window(&window)?;
            for p in next {
                if out.len() == horizon {
                    break;
                }
                window.remove(0);
                window.push(p.clone());
                out.push(p);
            }
        }
        Ok(out)
    }

    /// Saves the trained model (configuration, standardisation, reports and weights) to one
    /// file; see [`WindowNet::load`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let (fitted, nets) = self.nets()?;
        let header = Header {
            kind: A::NAME.to_string(),
            arch: self.arch.clone(),
            layout: self.layout,
            train: self.train.clone(),
            dim: fitted.dim,
            scaler: fitted.scaler.clone(),
            reports: fitted.reports.clone(),
        };
        persist::write(path, &persist::to_json(path, &header)?, &nets)
    }

    /// Loads a model saved by [`WindowNet::save`] with the same architecture family.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let (header, records) = persist::read(path)?;
        Self::from_parts(path, &header, records)
    }

    /// [`WindowNet::load`] from the bytes of a model file (held in memory, a database...);
    /// errors name the source `<bytes>`.
    pub fn load_bytes(bytes: &[u8]) -> Result<Self> {
        let path = Path::new("<bytes>");
        let (header, records) = persist::parse(path, bytes)?;
        Self::from_parts(path, &header, records)
    }

    fn from_parts(path: &Path, header: &str, records: Vec<Vec<u8>>) -> Result<Self> {
        let h: Header<A> = persist::from_json(path, header)?;
        persist::check_header(path, h.dim, &h.scaler)?;
        if h.kind != A::NAME {
            return Err(NeuralError::Persistence {
                path: path.display().to_string(),
                reason: format!("file holds a `{}` model, not `{}`", h.kind, A::NAME),
            });
        }
        let mut model = WindowNet::new(h.arch, h.layout, h.train)?;
        if records.len() != model.n_nets(h.dim) {
            return Err(NeuralError::Persistence {
                path: path.display().to_string(),
                reason: format!(
                    "expected {} networks, found {}",
                    model.n_nets(h.dim),
                    records.len()
                ),
            });
        }
        let device = device();
        let mut nets = Vec::new();
        for (i, bytes) in records.into_iter().enumerate() {
            let net = model.build_net(h.dim, &device, 2 * i as u64);
            nets.push(persist::load_into(path, net, bytes)?.valid());
        }
        model.fitted = Some(Fitted {
            dim: h.dim,
            scaler: h.scaler,
            nets: Mutex::new(nets),
            reports: h.reports,
        });
        Ok(model)
    }
}

impl<A: Architecture> Predictor for WindowNet<A> {
    fn name(&self) -> &str {
        A::NAME
    }

    fn fit(&mut self, train: &[Trajectory]) -> trajpred_core::Result<()> {
        self.fit_with(train, &mut |_| {})
            .map(|_| ())
            .map_err(|e| e.into_core(A::NAME))
    }

    fn forecast(&self, history: &Trajectory, horizon: usize) -> trajpred_core::Result<Forecast> {
        check_forecast_args(history, horizon, self.min_history())?;
        let dim = self
            .dim()
            .ok_or_else(|| NeuralError::NotFitted.into_core(A::NAME))?;
        if history.dim() != dim {
            return Err(trajpred_core::Error::DimensionMismatch {
                what: "history axes",
                expected: dim,
                got: history.dim(),
            });
        }
        let m = self.layout.window;
        let start = history.len() - m;
        let pts: Vec<Vec<f64>> = (start..history.len())
            .map(|i| history.point(i).to_vec())
            .collect();
        let steps = self
            .predict_series(&pts, horizon)
            .map_err(|e| e.into_core(A::NAME))?;
        Forecast::new(dim, steps)
    }

    fn min_history(&self) -> usize {
        self.layout.window
    }
}

fn gskf_train(epochs: usize) -> TrainConfig {
    TrainConfig::new(0.1)
        .with_optimizer(Optimizer::SGD)
        .with_epochs(epochs)
        .with_batch_size(32)
}

impl WindowNet<MlpArch> {
    /// The GSKF paper's "BP" baseline of Table 3 (`docs/papers.md` A.5): per axis, `m` inputs ->
    /// `T` outputs, one hidden layer of 10 tanh units (MATLAB's `newff` default), plain gradient
    /// descent at learning rate 0.1, 500 epochs, batch 32, seed 0.
    pub fn gskf_bp(window: usize, horizon: usize) -> Result<Self> {
        WindowNet::new(
            MlpArch {
                hidden: vec![10],
                activation: Activation::Tanh,
            },
            WindowConfig {
                window,
                horizon,
                axes: AxisMode::PerAxis,
            },
            gskf_train(500),
        )
    }
}

impl WindowNet<LstmArch> {
    /// The GSKF paper's LSTM baseline of Table 3 (`docs/papers.md` A.5): per axis, 2 x 64 LSTM +
    /// one fully connected hidden layer of 64, plain gradient descent at learning rate 0.1,
    /// 500 epochs, batch 32, seed 0.
    pub fn gskf_lstm(window: usize, horizon: usize) -> Result<Self> {
        WindowNet::new(
            LstmArch(RecurrentLayers::default()),
            WindowConfig {
                window,
                horizon,
                axes: AxisMode::PerAxis,
            },
            gskf_train(500),
        )
    }

    /// The patent's LSTM baseline (`docs/papers.md` D.1): all axes jointly, 2 x 64 LSTM + fully
    /// connected layers, Adam at learning rate 1e-3, batch 16, 100 epochs, seed 0.
    pub fn patent_baseline(window: usize, horizon: usize) -> Result<Self> {
        WindowNet::new(
            LstmArch(RecurrentLayers::default()),
            WindowConfig {
                window,
                horizon,
                axes: AxisMode::Joint,
            },
            TrainConfig::new(1e-3).with_epochs(100).with_batch_size(16),
        )
    }
}

impl WindowNet<RnnArch> {
    /// The patent's RNN baseline (`docs/papers.md` D.1): all axes jointly, 2 x 64 Elman RNN + fully
    /// connected layers, Adam at learning rate 1e-3, batch 16, 100 epochs, seed 0.
    pub fn patent_baseline(window: usize, horizon: usize) -> Result<Self> {
        WindowNet::new(
            RnnArch(RecurrentLayers::default()),
            WindowConfig {
                window,
                horizon,
                axes: AxisMode::Joint,
            },
            TrainConfig::new(1e-3).with_epochs(100).with_batch_size(16),
        )
    }
}
