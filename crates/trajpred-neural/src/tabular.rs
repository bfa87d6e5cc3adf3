//! A multilayer perceptron on rows of features, fitted to a mean Euclidean distance:
//! [`DistanceMlp`] (trajpred's `aligned-mlp`).
//!
//! Each row of features maps to `pairs` planar outputs `c_k = (c_k,a, c_k,b)`; a sample's
//! loss is the mean over its pairs of `sqrt(|s_k c_k - y_k|^2 + floor^2)`, with `y_k` a planar
//! target and `s_k > 0` a per-sample scale of the pair (so the network can learn a
//! correction per unit of something, a time ahead, while the loss is measured in the
//! target's units). The mean distance is what a forecast of positions is judged by; a
//! squared loss would be led by the few wildest targets.

use crate::arch::Head;
use crate::config::{Activation, TrainConfig};
use crate::error::{CoreError, NeuralError, Result};
use crate::train::{LoopSpec, XavierZeroBias, device, read, rng, train_loop};
use burn::lr_scheduler::cosine::CosineAnnealingLrSchedulerConfig;
use burn::module::Module;
use burn::tensor::{Tensor, TensorData};
use serde::{Deserialize, Serialize};

/// How a [`DistanceMlp`] is built and trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DistanceMlpConfig {
    /// Hidden layer sizes (ReLU).
    pub hidden: Vec<usize>,
    /// Passes over the training rows.
    pub epochs: usize,
    /// Rows per Adam step.
    pub batch_size: usize,
    /// Adam's learning rate at the first step, annealed along a cosine to 0 at the last.
    pub learning_rate: f64,
    /// Added in quadrature to every distance (target units), so the loss is smooth where a
    /// pair is fitted exactly.
    pub floor: f64,
    /// Seed of the initial weights and of the shuffling.
    pub seed: u64,
}

impl Default for DistanceMlpConfig {
    /// Two hidden layers of 256, 20 epochs of batches of 1024, learning rate 3e-3, floor
    /// 0.1, seed 0.
    fn default() -> Self {
        DistanceMlpConfig {
            hidden: vec![256, 256],
            epochs: 20,
            batch_size: 1024,
            learning_rate: 3e-3,
            floor: 0.1,
            seed: 0,
        }
    }
}

impl DistanceMlpConfig {
    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &'static str, why: String| -> Result<()> {
            Err(CoreError::invalid_parameter(name, why).into())
        };
        crate::arch::check_sizes("hidden", &self.hidden, false)?;
        if self.epochs == 0 {
            return bad("epochs", "must be at least 1, got 0".into());
        }
        if self.batch_size == 0 {
            return bad("batch_size", "must be at least 1, got 0".into());
        }
        if !(self.learning_rate > 0.0 && self.learning_rate <= 1.0) {
            return bad(
                "learning_rate",
                format!("must be in (0, 1], got {}", self.learning_rate),
            );
        }
        if !(self.floor.is_finite() && self.floor > 0.0) {
            return bad(
                "floor",
                format!("must be finite and positive, got {}", self.floor),
            );
        }
        Ok(())
    }
}

/// Training rows for [`DistanceMlp::fit`], row-major.
#[derive(Debug, Clone, Copy)]
pub struct PlanarRows<'a> {
    /// Features per row.
    pub features: usize,
    /// `n * features` values.
    pub rows: &'a [f64],
    /// Planar outputs per row.
    pub pairs: usize,
    /// `n * pairs * 2` target values (pair by pair, `a` then `b`).
    pub targets: &'a [f64],
    /// `n * pairs` positive scales (the output of pair `k` is multiplied by its scale
    /// before it is compared with the target).
    pub scales: &'a [f64],
}

impl PlanarRows<'_> {
    /// The number of rows, once every length agrees and every value is finite (scales
    /// positive).
    fn check(&self) -> Result<usize> {
        if self.features == 0 || self.pairs == 0 {
            return Err(CoreError::invalid_parameter(
                if self.features == 0 {
                    "features"
                } else {
                    "pairs"
                },
                "must be at least 1, got 0",
            )
            .into());
        }
        let n = self.rows.len() / self.features;
        if n == 0 {
            return Err(NeuralError::NoTrainingData {
                what: "no training rows",
            });
        }
        let lengths = [
            ("rows", self.rows.len(), n * self.features),
            ("targets", self.targets.len(), n * self.pairs * 2),
            ("scales", self.scales.len(), n * self.pairs),
        ];
        for (what, got, expected) in lengths {
            if got != expected {
                return Err(CoreError::DimensionMismatch {
                    what,
                    expected,
                    got,
                }
                .into());
            }
        }
        for (what, v) in [("rows", self.rows), ("targets", self.targets)] {
            if let Some(index) = v.iter().position(|x| !x.is_finite()) {
                return Err(CoreError::NonFinite { what, index }.into());
            }
        }
        if let Some(index) = self
            .scales
            .iter()
            .position(|s| !(s.is_finite() && *s > 0.0))
        {
            return Err(CoreError::invalid_parameter(
                "scales",
                format!(
                    "must be finite and positive, got {} at {index}",
                    self.scales[index]
                ),
            )
            .into());
        }
        Ok(n)
    }
}

/// One fully connected layer of a [`DistanceMlp`]: output `o` is
/// `b[o] + sum_i h[i] w[i * outputs + o]` (then ReLU, but after the last layer).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Dense {
    /// Inputs of the layer.
    pub inputs: usize,
    /// Outputs of the layer.
    pub outputs: usize,
    /// `inputs * outputs` weights, input by input.
    pub w: Vec<f64>,
    /// `outputs` biases.
    pub b: Vec<f64>,
}

/// A trained MLP from a row of features to planar outputs (see the [module](self) docs).
///
/// Inputs are centred on each feature's training median and divided by its interquartile
/// range (1 where that is 0), then clipped to `[-10, 10]`, so one wild feature value does
/// not saturate the network. Trained with Adam in `f32` by burn's autodiff; prediction runs
/// in `f64` on the weights read back, so a forecast needs no tensor framework.
///
/// ```
/// use trajpred_neural::{DistanceMlp, DistanceMlpConfig, PlanarRows};
/// // the target is (2 x, -x) times the row's scale
/// let n = 2000;
/// let x: Vec<f64> = (0..n).map(|i| (i as f64 / n as f64) * 4.0 - 2.0).collect();
/// let scales: Vec<f64> = (0..n).map(|i| 1.0 + (i % 3) as f64).collect();
/// let targets: Vec<f64> =
///     (0..n).flat_map(|i| [2.0 * x[i] * scales[i], -x[i] * scales[i]]).collect();
/// let cfg = DistanceMlpConfig { hidden: vec![16], epochs: 60, batch_size: 64, ..Default::default() };
/// let rows = PlanarRows { features: 1, rows: &x, pairs: 1, targets: &targets, scales: &scales };
/// let m = DistanceMlp::fit(&cfg, rows)?;
/// let c = m.predict(&[1.5])?;
/// assert!((c[0] - 3.0).abs() < 0.1 && (c[1] + 1.5).abs() < 0.1, "{c:?}");
/// # Ok::<(), trajpred_neural::NeuralError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct DistanceMlp {
    pairs: usize,
    center: Vec<f64>,
    spread: Vec<f64>,
    layers: Vec<Dense>,
}

/// Inputs further than this many interquartile ranges from the median are clipped.
const CLIP: f64 = 10.0;

/// The median and the interquartile range (1 where it is 0) of every column.
fn robust_scale(rows: &[f64], features: usize) -> (Vec<f64>, Vec<f64>) {
    let n = rows.len() / features;
    let mut col = vec![0.0; n];
    let mut center = Vec::with_capacity(features);
    let mut spread = Vec::with_capacity(features);
    let at = |c: &[f64], q: f64| c[((n - 1) as f64 * q).round() as usize];
    for j in 0..features {
        for (i, v) in col.iter_mut().enumerate() {
            *v = rows[i * features + j];
        }
        col.sort_by(f64::total_cmp);
        let iqr = at(&col, 0.75) - at(&col, 0.25);
        center.push(at(&col, 0.5));
        spread.push(if iqr > 0.0 { iqr } else { 1.0 });
    }
    (center, spread)
}

impl DistanceMlp {
    /// Trains a network on `data` (see [`DistanceMlpConfig`]). Errors: the configuration's
    /// first bad field, mismatched lengths, a non-finite value, a scale that is not
    /// positive, no rows, or a loss that became non-finite.
    pub fn fit(cfg: &DistanceMlpConfig, data: PlanarRows<'_>) -> Result<Self> {
        cfg.validate()?;
        let n = data.check()?;
        let (f, p) = (data.features, data.pairs);
        let (center, spread) = robust_scale(data.rows, f);
        let z: Vec<f32> = data
            .rows
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let j = i % f;
                ((v - center[j]) / spread[j]).clamp(-CLIP, CLIP) as f32
            })
            .collect();
        let targets: Vec<f32> = data.targets.iter().map(|&v| v as f32).collect();
        let scales: Vec<f32> = data.scales.iter().map(|&v| v as f32).collect();
        let dev = device();
        let mut r = rng(cfg.seed, 0);
        let net = Head::new(f, &cfg.hidden, 2 * p, Activation::Relu, &dev)
            .map(&mut XavierZeroBias { rng: &mut r });
        let floor2 = (cfg.floor * cfg.floor) as f32;
        let batch_loss = |net: &Head, idx: &[usize]| {
            let b = idx.len();
            let mut x = Vec::with_capacity(b * f);
            let mut y = Vec::with_capacity(b * 2 * p);
            let mut s = Vec::with_capacity(b * p);
            for &i in idx {
                x.extend_from_slice(&z[i * f..(i + 1) * f]);
                y.extend_from_slice(&targets[i * 2 * p..(i + 1) * 2 * p]);
                s.extend_from_slice(&scales[i * p..(i + 1) * p]);
            }
            let x = Tensor::<2>::from_data(TensorData::new(x, [b, f]), &dev);
            let y = Tensor::<3>::from_data(TensorData::new(y, [b, p, 2]), &dev);
            let s = Tensor::<3>::from_data(TensorData::new(s, [b, p, 1]), &dev);
            let d = net.forward(x).reshape([b, p, 2]) * s - y;
            ((d.clone() * d).sum_dim(2) + floor2).sqrt().mean()
        };
        let steps = cfg.epochs * n.div_ceil(cfg.batch_size);
        let lr = CosineAnnealingLrSchedulerConfig::new(cfg.learning_rate, steps)
            .init()
            .map_err(|reason| NeuralError::Tensor { reason })?;
        let train = TrainConfig::new(cfg.learning_rate)
            .with_epochs(cfg.epochs)
            .with_batch_size(cfg.batch_size)
            .with_seed(cfg.seed)
            .with_fused(false);
        let spec = LoopSpec {
            n_train: n,
            batch_loss: &batch_loss,
            validation_loss: None,
            lr,
        };
        let (net, _) = train_loop(net, spec, &train, 0, &mut |_| {})?;
        let net = net.valid();
        let spec = net.fused_spec(f);
        let params = net.fused_params();
        let mut sizes = vec![f];
        sizes.extend(&spec.fc);
        sizes.push(spec.output);
        let mut layers = Vec::with_capacity(sizes.len() - 1);
        for (k, wb) in params.chunks(2).enumerate() {
            let [w, b] = wb else {
                return Err(NeuralError::Tensor {
                    reason: "a layer without its bias".into(),
                });
            };
            let w: Vec<f64> = read(w.clone())?.into_iter().map(f64::from).collect();
            let b: Vec<f64> = read(b.clone())?.into_iter().map(f64::from).collect();
            layers.push(Dense {
                inputs: sizes[k],
                outputs: sizes[k + 1],
                w,
                b,
            });
        }
        let m = DistanceMlp {
            pairs: p,
            center,
            spread,
            layers,
        };
        if let Some(index) = m
            .layers
            .iter()
            .flat_map(|l| l.w.iter().chain(&l.b))
            .position(|v| !v.is_finite())
        {
            return Err(CoreError::NonFinite {
                what: "trained weights",
                index,
            }
            .into());
        }
        Ok(m)
    }

    /// A network from its parts (as [`DistanceMlp::center`], [`DistanceMlp::spread`] and
    /// [`DistanceMlp::layers`] give them), checked: every layer's input is the previous
    /// one's output, every weight and bias is there and finite, the first layer takes the
    /// features and the last gives `2 * pairs` outputs. Errors name what is wrong
    /// ([`CoreError::InvalidParameter`] `"network"`).
    pub fn from_parts(
        pairs: usize,
        center: Vec<f64>,
        spread: Vec<f64>,
        layers: Vec<Dense>,
    ) -> Result<Self> {
        let m = DistanceMlp {
            pairs,
            center,
            spread,
            layers,
        };
        m.check()
            .map_err(|reason| CoreError::invalid_parameter("network", reason))?;
        Ok(m)
    }

    /// Each feature's training median, subtracted before the first layer.
    pub fn center(&self) -> &[f64] {
        &self.center
    }

    /// Each feature's training interquartile range (1 where it was 0), divided by.
    pub fn spread(&self) -> &[f64] {
        &self.spread
    }

    /// The layers, first to last.
    pub fn layers(&self) -> &[Dense] {
        &self.layers
    }

    fn check(&self) -> std::result::Result<(), String> {
        let f = self.center.len();
        if f == 0 || self.spread.len() != f {
            return Err(format!(
                "{} centres and {} spreads for the features",
                f,
                self.spread.len()
            ));
        }
        if self.layers.is_empty() {
            return Err("no layers".into());
        }
        let mut inputs = f;
        for (k, l) in self.layers.iter().enumerate() {
            if l.inputs != inputs
                || l.w.len() != l.inputs * l.outputs
                || l.b.len() != l.outputs
                || l.outputs == 0
                || l.outputs > crate::arch::MAX_LAYER_WIDTH
            {
                return Err(format!(
                    "layer {k}: {} inputs (expected {inputs}), {} outputs, {} weights, {} biases",
                    l.inputs,
                    l.outputs,
                    l.w.len(),
                    l.b.len()
                ));
            }
            inputs = l.outputs;
        }
        if inputs != 2 * self.pairs {
            return Err(format!("{inputs} outputs for {} planar pairs", self.pairs));
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let positive = self.spread.iter().all(|s| s.is_finite() && *s > 0.0);
        if !(finite(&self.center)
            && positive
            && self.layers.iter().all(|l| finite(&l.w) && finite(&l.b)))
        {
            return Err("a value that is not finite (or a spread that is not positive)".into());
        }
        Ok(())
    }

    /// Features a row must have.
    pub fn features(&self) -> usize {
        self.center.len()
    }

    /// Planar outputs per row.
    pub fn pairs(&self) -> usize {
        self.pairs
    }

    /// The `2 * pairs` outputs (unscaled) for one row of features. Errors: a row of the wrong
    /// length or with a non-finite value.
    pub fn predict(&self, row: &[f64]) -> Result<Vec<f64>> {
        if row.len() != self.features() {
            return Err(CoreError::DimensionMismatch {
                what: "features of a row",
                expected: self.features(),
                got: row.len(),
            }
            .into());
        }
        if let Some(index) = row.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::NonFinite { what: "row", index }.into());
        }
        let mut h: Vec<f64> = row
            .iter()
            .zip(self.center.iter().zip(&self.spread))
            .map(|(v, (c, s))| ((v - c) / s).clamp(-CLIP, CLIP))
            .collect();
        let last = self.layers.len().saturating_sub(1);
        for (k, l) in self.layers.iter().enumerate() {
            let mut out = l.b.clone();
            for (i, &hi) in h.iter().enumerate() {
                let w = &l.w[i * l.outputs..(i + 1) * l.outputs];
                for (o, wo) in out.iter_mut().zip(w) {
                    *o += hi * wo;
                }
            }
            if k < last {
                out.iter_mut().for_each(|v| *v = v.max(0.0));
            }
            h = out;
        }
        Ok(h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toy(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let x: Vec<f64> = (0..n)
            .flat_map(|i| {
                let a = (i as f64 * 0.37).sin();
                [a, (i as f64 * 0.11).cos()]
            })
            .collect();
        let s: Vec<f64> = (0..n).map(|i| 0.5 + (i % 4) as f64).collect();
        let y: Vec<f64> = (0..n)
            .flat_map(|i| {
                let (a, b) = (x[2 * i], x[2 * i + 1]);
                [s[i] * (a + b), s[i] * a * b]
            })
            .collect();
        (x, y, s)
    }

    /// Rows of two features with one planar target each.
    fn two<'a>(x: &'a [f64], y: &'a [f64], s: &'a [f64]) -> PlanarRows<'a> {
        PlanarRows {
            features: 2,
            rows: x,
            pairs: 1,
            targets: y,
            scales: s,
        }
    }

    fn cfg() -> DistanceMlpConfig {
        DistanceMlpConfig {
            hidden: vec![32, 32],
            epochs: 30,
            batch_size: 64,
            ..Default::default()
        }
    }

    #[test]
    fn it_learns_a_scaled_planar_function_and_the_same_seed_gives_the_same_weights() {
        let (x, y, s) = toy(3000);
        let rows = two(&x, &y, &s);
        let a = DistanceMlp::fit(&cfg(), rows).unwrap();
        let b = DistanceMlp::fit(&cfg(), rows).unwrap();
        assert_eq!(a, b);
        // mean distance over the rows, against the zero prediction's
        let (mut fitted, mut zero) = (0.0, 0.0);
        for i in 0..3000 {
            let c = a.predict(&x[2 * i..2 * i + 2]).unwrap();
            let (ta, tb) = (y[2 * i], y[2 * i + 1]);
            fitted += (s[i] * c[0] - ta).hypot(s[i] * c[1] - tb);
            zero += ta.hypot(tb);
        }
        assert!(fitted < 0.1 * zero, "{fitted} against {zero}");
        let other = DistanceMlp::fit(&DistanceMlpConfig { seed: 1, ..cfg() }, rows).unwrap();
        assert_ne!(a, other);
    }

    #[test]
    fn a_network_rebuilt_from_its_parts_is_the_same_and_damaged_parts_are_refused() {
        let (x, y, s) = toy(200);
        let rows = two(&x, &y, &s);
        let m = DistanceMlp::fit(&DistanceMlpConfig { epochs: 2, ..cfg() }, rows).unwrap();
        let parts = || {
            (
                m.center().to_vec(),
                m.spread().to_vec(),
                m.layers().to_vec(),
            )
        };
        let (c, sp, l) = parts();
        assert_eq!(DistanceMlp::from_parts(1, c, sp, l).unwrap(), m);
        let (c, sp, mut l) = parts();
        l[1].w.pop();
        let e = DistanceMlp::from_parts(1, c, sp, l).unwrap_err();
        assert!(e.to_string().contains("layer 1"), "{e}");
        let (c, sp, l) = parts();
        let e = DistanceMlp::from_parts(2, c, sp, l).unwrap_err();
        assert!(e.to_string().contains("for 2 planar pairs"), "{e}");
        let (c, mut sp, l) = parts();
        sp[0] = 0.0;
        assert!(DistanceMlp::from_parts(1, c, sp, l).is_err());
    }

    #[test]
    fn bad_rows_are_typed_errors() {
        let (x, y, s) = toy(10);
        let ok = two(&x, &y, &s);
        let short = PlanarRows {
            targets: &y[..19],
            ..ok
        };
        assert!(matches!(
            DistanceMlp::fit(&cfg(), short),
            Err(NeuralError::Core(CoreError::DimensionMismatch {
                what: "targets",
                ..
            }))
        ));
        let mut nan = x.clone();
        nan[5] = f64::NAN;
        let bad = PlanarRows { rows: &nan, ..ok };
        assert!(matches!(
            DistanceMlp::fit(&cfg(), bad),
            Err(NeuralError::Core(CoreError::NonFinite {
                what: "rows",
                index: 5
            }))
        ));
        let mut s0 = s.clone();
        s0[3] = 0.0;
        let zero = PlanarRows { scales: &s0, ..ok };
        assert!(matches!(
            DistanceMlp::fit(&cfg(), zero),
            Err(NeuralError::Core(CoreError::InvalidParameter { .. }))
        ));
        let none = PlanarRows {
            rows: &[],
            targets: &[],
            scales: &[],
            ..ok
        };
        assert!(matches!(
            DistanceMlp::fit(&cfg(), none),
            Err(NeuralError::NoTrainingData { .. })
        ));
        let zero_epochs = DistanceMlpConfig { epochs: 0, ..cfg() };
        assert!(matches!(
            DistanceMlp::fit(&zero_epochs, ok),
            Err(NeuralError::Core(CoreError::InvalidParameter { .. }))
        ));
    }

    #[test]
    fn a_prediction_checks_its_row() {
        let (x, y, s) = toy(200);
        let rows = two(&x, &y, &s);
        let m = DistanceMlp::fit(&DistanceMlpConfig { epochs: 1, ..cfg() }, rows).unwrap();
        assert!(matches!(
            m.predict(&[1.0]),
            Err(NeuralError::Core(CoreError::DimensionMismatch { .. }))
        ));
        assert!(matches!(
            m.predict(&[1.0, f64::INFINITY]),
            Err(NeuralError::Core(CoreError::NonFinite { index: 1, .. }))
        ));
        assert_eq!(m.predict(&[0.1, 0.2]).unwrap().len(), 2);
    }
}
