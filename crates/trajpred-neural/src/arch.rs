//! The network architectures of the windowed models: a multilayer perceptron and stacked
//! Elman RNN / LSTM layers followed by fully connected layers.
//!
//! Every architecture maps a batch of windows `[batch, m, features]` to a batch of direct
//! multi-step outputs `[batch, T * features]`.

use crate::config::Activation;
use crate::error::{NeuralError, Result};
use burn::module::Module;
use burn::nn::{Linear, LinearConfig, Lstm, LstmConfig, Rnn, RnnConfig};
use burn::tensor::activation::{relu, sigmoid, tanh};
use burn::tensor::{Device, Tensor};
use serde::{Deserialize, Serialize, de::DeserializeOwned};
use std::fmt::Debug;

/// A network family usable by [`WindowNet`](crate::WindowNet).
///
/// Implemented by [`MlpArch`], [`RnnArch`] and [`LstmArch`]; the associated `Net` is the
/// burn module that holds the weights.
pub trait Architecture:
    Clone + Debug + PartialEq + Send + Sync + Serialize + DeserializeOwned + 'static
{
    /// The burn module of this family.
    type Net: Module + 'static;
    /// Short name used in tables and on the command line (`"bp"`, `"rnn"`, `"lstm"`).
    const NAME: &'static str;
    /// Checks the layer sizes.
    fn validate(&self) -> Result<()>;
    /// Builds a network for windows of `window` steps of `features` values, with `outputs`
    /// outputs. Weights are re-initialised by the caller.
    fn build(&self, features: usize, window: usize, outputs: usize, device: &Device) -> Self::Net;
    /// `[batch, window, features]` -> `[batch, outputs]`.
    fn forward(&self, net: &Self::Net, x: Tensor<3>) -> Tensor<2>;
}

pub(crate) fn activate(a: Activation, x: Tensor<2>) -> Tensor<2> {
    match a {
        Activation::Relu => relu(x),
        Activation::Tanh => tanh(x),
        Activation::Sigmoid => sigmoid(x),
    }
}

fn check_sizes(name: &'static str, sizes: &[usize], need_one: bool) -> Result<()> {
    if need_one && sizes.is_empty() {
        return Err(NeuralError::InvalidConfig {
            name,
            reason: "needs at least one layer".into(),
        });
    }
    if sizes.contains(&0) {
        return Err(NeuralError::InvalidConfig {
            name,
            reason: "layer sizes must be at least 1".into(),
        });
    }
    Ok(())
}

/// Fully connected layers with an activation, then a linear output layer.
#[derive(Module, Debug)]
pub struct Head {
    hidden: Vec<Linear>,
    out: Linear,
    #[module(skip)]
    activation: Activation,
}

impl Head {
    pub(crate) fn new(
        d_in: usize,
        sizes: &[usize],
        outputs: usize,
        activation: Activation,
        device: &Device,
    ) -> Self {
        let mut hidden = Vec::with_capacity(sizes.len());
        let mut d = d_in;
        for &h in sizes {
            hidden.push(LinearConfig::new(d, h).init(device));
            d = h;
        }
        Head {
            hidden,
            out: LinearConfig::new(d, outputs).init(device),
            activation,
        }
    }

    pub(crate) fn forward(&self, mut x: Tensor<2>) -> Tensor<2> {
        for l in &self.hidden {
            x = activate(self.activation, l.forward(x));
        }
        self.out.forward(x)
    }
}

/// The papers' "BP" network: the flattened window through fully connected hidden layers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MlpArch {
    /// Hidden layer sizes (may be empty: a linear model).
    pub hidden: Vec<usize>,
    /// Hidden activation.
    pub activation: Activation,
}

impl Default for MlpArch {
    /// Two hidden layers of 64 with ReLU.
    fn default() -> Self {
        MlpArch {
            hidden: vec![64, 64],
            activation: Activation::Relu,
        }
    }
}

impl Architecture for MlpArch {
    type Net = Head;
    const NAME: &'static str = "bp";
    fn validate(&self) -> Result<()> {
        check_sizes("hidden", &self.hidden, false)
    }
    fn build(&self, features: usize, window: usize, outputs: usize, device: &Device) -> Head {
        Head::new(
            features * window,
            &self.hidden,
            outputs,
            self.activation,
            device,
        )
    }
    fn forward(&self, net: &Head, x: Tensor<3>) -> Tensor<2> {
        let [b, m, f] = x.dims();
        net.forward(x.reshape([b, m * f]))
    }
}

/// Stacked recurrent layers of the given sizes, then fully connected layers on the last
/// hidden state. Shared by [`RnnArch`] and [`LstmArch`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecurrentLayers {
    /// Hidden sizes of the stacked recurrent layers (at least one).
    pub layers: Vec<usize>,
    /// Hidden sizes of the fully connected layers after them (the output layer is extra).
    pub fc: Vec<usize>,
    /// Activation of the fully connected hidden layers.
    pub activation: Activation,
}

impl Default for RecurrentLayers {
    /// Two recurrent layers of 64, one fully connected hidden layer of 64 (ReLU), then the
    /// linear output layer: "two hidden layers of 64, then fully connected layers".
    fn default() -> Self {
        RecurrentLayers {
            layers: vec![64, 64],
            fc: vec![64],
            activation: Activation::Relu,
        }
    }
}

/// Elman RNN (tanh) layers + fully connected layers.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RnnArch(pub RecurrentLayers);

/// LSTM layers + fully connected layers.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LstmArch(pub RecurrentLayers);

/// Stacked Elman RNN layers and a head.
#[derive(Module, Debug)]
pub struct RnnStack {
    layers: Vec<Rnn>,
    head: Head,
}

/// Stacked LSTM layers and a head.
#[derive(Module, Debug)]
pub struct LstmStack {
    layers: Vec<Lstm>,
    head: Head,
}

impl Architecture for RnnArch {
    type Net = RnnStack;
    const NAME: &'static str = "rnn";
    fn validate(&self) -> Result<()> {
        check_sizes("layers", &self.0.layers, true)?;
        check_sizes("fc", &self.0.fc, false)
    }
    fn build(&self, features: usize, _window: usize, outputs: usize, device: &Device) -> RnnStack {
        let mut d = features;
        let mut layers = Vec::new();
        for &h in &self.0.layers {
            layers.push(RnnConfig::new(d, h, true).init(device));
            d = h;
        }
        RnnStack {
            layers,
            head: Head::new(d, &self.0.fc, outputs, self.0.activation, device),
        }
    }
    fn forward(&self, net: &RnnStack, mut x: Tensor<3>) -> Tensor<2> {
        let [b, _, _] = x.dims();
        let mut last = None;
        for l in &net.layers {
            let (out, state) = l.forward(x, None);
            x = out;
            last = Some(state.hidden);
        }
        let h = last.unwrap_or_else(|| {
            let [_, m, f] = x.dims();
            x.slice([0..b, m - 1..m, 0..f]).reshape([b, f])
        });
        net.head.forward(h)
    }
}

impl Architecture for LstmArch {
    type Net = LstmStack;
    const NAME: &'static str = "lstm";
    fn validate(&self) -> Result<()> {
        check_sizes("layers", &self.0.layers, true)?;
        check_sizes("fc", &self.0.fc, false)
    }
    fn build(&self, features: usize, _window: usize, outputs: usize, device: &Device) -> LstmStack {
        let mut d = features;
        let mut layers = Vec::new();
        for &h in &self.0.layers {
            layers.push(LstmConfig::new(d, h, true).init(device));
            d = h;
        }
        LstmStack {
            layers,
            head: Head::new(d, &self.0.fc, outputs, self.0.activation, device),
        }
    }
    fn forward(&self, net: &LstmStack, mut x: Tensor<3>) -> Tensor<2> {
        let [b, _, _] = x.dims();
        let mut last = None;
        for l in &net.layers {
            let (out, state) = l.forward(x, None);
            x = out;
            last = Some(state.hidden);
        }
        let h = last.unwrap_or_else(|| {
            let [_, m, f] = x.dims();
            x.slice([0..b, m - 1..m, 0..f]).reshape([b, f])
        });
        net.head.forward(h)
    }
}
