//! The network architectures of the windowed models: a multilayer perceptron and stacked
//! Elman RNN / LSTM layers followed by fully connected layers.
//!
//! Every architecture maps a batch of windows `[batch, m, features]` to a batch of direct
//! multi-step outputs `[batch, T * features]`.

use crate::config::{Activation, TrainConfig};
use crate::error::{CoreError, NeuralError, Result};
use crate::fused::recurrent::{self, Cell};
use burn::module::Module;
use burn::nn::{Linear, LinearConfig, Rnn, RnnConfig};
use burn::tensor::activation::{relu, sigmoid, tanh};
use burn::tensor::{Device, Tensor, TensorData};
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
    /// The training loss of a batch: the mean squared error of [`Architecture::forward`]
    /// on `x` against the targets `y` (`[batch, outputs]`), a one-element tensor. An
    /// architecture may compute the same in fewer tensor operations (the LSTM's fused path).
    fn loss(&self, net: &Self::Net, x: Tensor<3>, y: Tensor<2>) -> Tensor<1> {
        crate::train::mse(self.forward(net, x), y)
    }
    /// Applies the choices of the training configuration that live in the network (the
    /// LSTM's [`TrainConfig::fused`]); the default keeps the network as it is.
    fn configure(&self, net: Self::Net, _train: &TrainConfig) -> Self::Net {
        net
    }
}

pub(crate) fn activate(a: Activation, x: Tensor<2>) -> Tensor<2> {
    match a {
        Activation::Relu => relu(x),
        Activation::Tanh => tanh(x),
        Activation::Sigmoid => sigmoid(x),
    }
}

/// The widest layer a network may have (a saved model asking for more is refused before
/// anything is allocated).
pub const MAX_LAYER_WIDTH: usize = 4096;
/// The most layers of one kind (recurrent, fully connected) a network may have.
pub const MAX_LAYERS: usize = 16;

pub(crate) fn check_sizes(name: &'static str, sizes: &[usize], need_one: bool) -> Result<()> {
    if sizes.len() > MAX_LAYERS || sizes.iter().any(|&w| w > MAX_LAYER_WIDTH) {
        return Err(NeuralError::Core(CoreError::InvalidParameter {
            name,
            reason: format!(
                "at most {MAX_LAYERS} layers of at most {MAX_LAYER_WIDTH} units (got {sizes:?})"
            ),
        }));
    }
    if need_one && sizes.is_empty() {
        return Err(NeuralError::Core(CoreError::InvalidParameter {
            name,
            reason: format!("needs at least one layer, got {sizes:?}"),
        }));
    }
    if sizes.contains(&0) {
        return Err(NeuralError::Core(CoreError::InvalidParameter {
            name,
            reason: format!("layer sizes must be at least 1, got {sizes:?}"),
        }));
    }
    Ok(())
}

/// Layers of the widths `sizes`, in order, the first taking `d_in` inputs: `make(d, h)`
/// builds a layer from width `d` to `h`. Returns the layers and the last width (`d_in`
/// when `sizes` is empty).
fn chain<L>(
    d_in: usize,
    sizes: &[usize],
    mut make: impl FnMut(usize, usize) -> L,
) -> (Vec<L>, usize) {
    let mut layers = Vec::with_capacity(sizes.len());
    let mut d = d_in;
    for &h in sizes {
        layers.push(make(d, h));
        d = h;
    }
    (layers, d)
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
        let (hidden, d) = chain(d_in, sizes, |d, h| LinearConfig::new(d, h).init(device));
        Head {
            hidden,
            out: LinearConfig::new(d, outputs).init(device),
            activation,
        }
    }

    /// Every weight and bias flattened, layer by layer (`W` `[in, out]` row-major, then `b`,
    /// zeros without a bias), the output layer last: the packing of the fused KFU op.
    pub(crate) fn fused_params(&self) -> Vec<Tensor<1>> {
        let mut v = Vec::with_capacity(2 * self.hidden.len() + 2);
        for l in self.hidden.iter().chain(std::iter::once(&self.out)) {
            let w = l.weight.val();
            let [i, o] = w.dims();
            let device = w.device();
            v.push(w.reshape([i * o]));
            v.push(match &l.bias {
                Some(b) => b.val(),
                None => Tensor::zeros([o], &device),
            });
        }
        v
    }

    /// The sizes of the fused head op (`src/fused/head.rs`) on inputs of width `input`.
    pub(crate) fn fused_spec(&self, input: usize) -> crate::fused::head::Spec {
        crate::fused::head::Spec {
            input,
            fc: self.hidden.iter().map(|l| l.weight.dims()[1]).collect(),
            output: self.out.weight.dims()[1],
            activation: self.activation,
        }
    }

    /// The mean squared error of the head on `h` against `y` as one fused op; `None` when
    /// the tensors do not allow it.
    pub(crate) fn fused_mse(&self, h: Tensor<2>, y: Tensor<2>) -> Option<Tensor<1>> {
        let spec = self.fused_spec(h.dims()[1]);
        let params = Tensor::cat(self.fused_params(), 0);
        crate::fused::head::mse(h, params, y, &spec).ok()
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

impl RecurrentLayers {
    /// At least one recurrent layer, and no layer of width 0.
    fn validate(&self) -> Result<()> {
        check_sizes("layers", &self.layers, true)?;
        check_sizes("fc", &self.fc, false)
    }

    /// The recurrent layers (`make(d, h)` builds one from width `d` to `h`), the first on
    /// `features` inputs, then the head on the last one's hidden state, in that order.
    fn build<L>(
        &self,
        features: usize,
        outputs: usize,
        device: &Device,
        make: impl FnMut(usize, usize) -> L,
    ) -> (Vec<L>, Head) {
        let (layers, d) = chain(features, &self.layers, make);
        let head = Head::new(d, &self.fc, outputs, self.activation, device);
        (layers, head)
    }
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
    /// Each layer through one fused op (`src/fused/recurrent.rs`) instead of step by step.
    fused: bool,
}

/// Stacked LSTM layers and a head.
#[derive(Module, Debug)]
pub struct LstmStack {
    layers: Vec<FusedLstm>,
    head: Head,
    /// Each layer through one fused op (`src/fused/recurrent.rs`) instead of step by step.
    fused: bool,
}

/// One LSTM layer with the four gates fused into one input and one recurrent matrix
/// (PyTorch's layout): `[i f g o] = x W_ih + b + h W_hh`,
/// `c' = sigmoid(f) c + sigmoid(i) tanh(g)`, `h' = sigmoid(o) tanh(c')`.
///
/// The same equations as burn's `nn::Lstm`, with fewer tensor operations per step (two
/// matrix products instead of eight, one sigmoid for the four gates, `tanh` through
/// sigmoid), which is what a CPU step costs here.
#[derive(Module, Debug)]
pub struct FusedLstm {
    input: Linear,
    recurrent: Linear,
    d_hidden: usize,
}

/// Cell and hidden state of a [`FusedLstm`], each `[batch, hidden]`.
#[derive(Debug, Clone)]
pub struct LstmCellState {
    /// Cell state `c`.
    pub cell: Tensor<2>,
    /// Hidden state `h`.
    pub hidden: Tensor<2>,
}

impl FusedLstm {
    /// A layer from `d_input` features to `d_hidden` units (weights re-initialised later).
    pub fn new(d_input: usize, d_hidden: usize, device: &Device) -> Self {
        FusedLstm {
            input: LinearConfig::new(d_input, 4 * d_hidden).init(device),
            recurrent: LinearConfig::new(d_hidden, 4 * d_hidden)
                .with_bias(false)
                .init(device),
            d_hidden,
        }
    }

    /// The constant `[1, 4 hidden]` row that doubles the cell block of the gates: one
    /// sigmoid of the scaled gates then gives the three gates and `tanh(g) = 2 sigmoid(2 g)
    /// - 1` at once.
    fn gate_scale(&self, device: &Device) -> Tensor<2> {
        let h = self.d_hidden;
        let row: Vec<f32> = (0..4 * h)
            .map(|j| {
                if (2 * h..3 * h).contains(&j) {
                    2.0
                } else {
                    1.0
                }
            })
            .collect();
        Tensor::from_data(TensorData::new(row, [1, 4 * h]), device)
    }

    /// One step from the input projection `xw = x W_ih + b` (`[batch, 4 hidden]`).
    ///
    /// One sigmoid over all four gate blocks, the cell block doubled first (`scale`, from
    /// [`FusedLstm::gate_scale`]) so that its sigmoid gives `tanh(g) = 2 sigmoid(2 g) - 1`;
    /// `tanh(c')` is taken the same way. The same equations: on the CPU backend `tanh` is
    /// the C library's `tanhf`, several times the cost of sigmoid's one `exp` per element,
    /// burn's autodiff evaluates both again in the backward pass, and an operation costs
    /// mostly its fixed overhead (the one extra product here replaces a `tanh` and its
    /// backward).
    fn step(
        &self,
        xw: Tensor<2>,
        state: Option<LstmCellState>,
        scale: &Tensor<2>,
    ) -> LstmCellState {
        let gates = match &state {
            Some(s) => xw + self.recurrent.forward(s.hidden.clone()),
            None => xw,
        };
        let h = self.d_hidden;
        let act = sigmoid(gates * scale.clone());
        let i = act.clone().narrow(1, 0, h);
        let o = act.clone().narrow(1, 3 * h, h);
        let g = act
            .clone()
            .narrow(1, 2 * h, h)
            .mul_scalar(2.0)
            .sub_scalar(1.0);
        let ic = i * g;
        let cell = match state {
            Some(s) => act.narrow(1, h, h) * s.cell + ic,
            None => ic,
        };
        let hidden = o * sigmoid(cell.clone().mul_scalar(2.0))
            .mul_scalar(2.0)
            .sub_scalar(1.0);
        LstmCellState { cell, hidden }
    }

    /// `W_ih` `[d_input, 4 hidden]`, `b` `[4 hidden]` (zeros without a bias) and `W_hh`
    /// `[hidden, 4 hidden]`: the weights as the fused ops take them.
    pub(crate) fn fused_params(&self) -> (Tensor<2>, Tensor<1>, Tensor<2>) {
        let w_ih = self.input.weight.val();
        let b = match &self.input.bias {
            Some(b) => b.val(),
            None => Tensor::zeros([4 * self.d_hidden], &w_ih.device()),
        };
        (w_ih, b, self.recurrent.weight.val())
    }

    /// One step on input `x: [batch, d_input]`.
    pub fn forward_step(&self, x: Tensor<2>, state: Option<LstmCellState>) -> LstmCellState {
        let scale = self.gate_scale(&x.device());
        self.step(self.input.forward(x), state, &scale)
    }

    /// Runs over `x: [batch, steps, d_input]`; returns every hidden state
    /// `[batch, steps, hidden]` and the final state.
    ///
    /// The input product is taken step by step: slicing a whole-sequence product of a
    /// tracked tensor would cost, in the backward pass, one zero-filled full-sequence
    /// gradient per step.
    pub fn forward(
        &self,
        x: Tensor<3>,
        state: Option<LstmCellState>,
    ) -> (Tensor<3>, LstmCellState) {
        let [b, m, d] = x.dims();
        let mut state = state;
        let mut outs = Vec::with_capacity(m);
        let scale = self.gate_scale(&x.device());
        for t in 0..m {
            let xt = x.clone().slice([0..b, t..t + 1, 0..d]).reshape([b, d]);
            let s = self.step(self.input.forward(xt), state, &scale);
            outs.push(s.hidden.clone());
            state = Some(s);
        }
        let last = state.unwrap_or_else(|| {
            let z = Tensor::zeros([b, self.d_hidden], &x.device());
            LstmCellState {
                cell: z.clone(),
                hidden: z,
            }
        });
        (Tensor::stack(outs, 1), last)
    }
}

/// The weights of a layer as the fused ops take them: `W_ih` `[d_input, G]`, `b` `[G]`,
/// `W_hh` `[hidden, G]`.
type FusedParams = (Tensor<2>, Tensor<1>, Tensor<2>);

/// The last hidden state of stacked layers of cell `cell`, each layer one fused op over the
/// window (the top one returning its last step only); `None` when the tensors are not on
/// the flex backend, or there is no layer or no step (then the composed path runs).
fn fused_stack(cell: Cell, layers: Vec<FusedParams>, mut x: Tensor<3>) -> Option<Tensor<2>> {
    let mut layers = layers.into_iter().peekable();
    while let Some((w_ih, b, w_hh)) = layers.next() {
        if layers.peek().is_none() {
            return recurrent::layer_last(cell, x, w_ih, b, w_hh).ok();
        }
        x = recurrent::layer(cell, x, w_ih, b, w_hh).ok()?;
    }
    None
}

fn lstm_params(layers: &[FusedLstm]) -> Vec<FusedParams> {
    layers.iter().map(FusedLstm::fused_params).collect()
}

/// The weights of burn's Elman layers for [`fused_stack`] (`b` the sum of the input and
/// hidden biases, which burn adds at every step, the first too); `None` when a layer
/// clips its state or does not use `tanh`, which the fused op does not do.
fn rnn_params(layers: &[Rnn]) -> Option<Vec<FusedParams>> {
    layers
        .iter()
        .map(|l| {
            if l.clip.is_some()
                || !matches!(
                    l.hidden_activation,
                    burn::nn::activation::Activation::Tanh(_)
                )
            {
                return None;
            }
            let (wi, wh) = (&l.gate.input_transform, &l.gate.hidden_transform);
            let w_ih = wi.weight.val();
            let b = match (&wi.bias, &wh.bias) {
                (Some(a), Some(b)) => a.val() + b.val(),
                (Some(a), None) | (None, Some(a)) => a.val(),
                (None, None) => Tensor::zeros([l.d_hidden], &w_ih.device()),
            };
            Some((w_ih, b, wh.weight.val()))
        })
        .collect()
}

impl Architecture for RnnArch {
    type Net = RnnStack;
    const NAME: &'static str = "rnn";
    fn validate(&self) -> Result<()> {
        self.0.validate()
    }
    fn build(&self, features: usize, _window: usize, outputs: usize, device: &Device) -> RnnStack {
        let (layers, head) = self.0.build(features, outputs, device, |d, h| {
            RnnConfig::new(d, h, true).init(device)
        });
        RnnStack {
            layers,
            head,
            fused: true,
        }
    }
    fn configure(&self, mut net: RnnStack, train: &TrainConfig) -> RnnStack {
        net.fused = train.fused;
        net
    }
    /// With the fused ops, the stacked layers and then the head and the loss, each one op.
    fn loss(&self, net: &RnnStack, x: Tensor<3>, y: Tensor<2>) -> Tensor<1> {
        if net.fused
            && let Some(params) = rnn_params(&net.layers)
            && let Some(h) = fused_stack(Cell::Elman, params, x.clone())
            && let Some(loss) = net.head.fused_mse(h, y.clone())
        {
            return loss;
        }
        crate::train::mse(self.forward(net, x), y)
    }
    fn forward(&self, net: &RnnStack, mut x: Tensor<3>) -> Tensor<2> {
        if net.fused
            && let Some(params) = rnn_params(&net.layers)
            && let Some(h) = fused_stack(Cell::Elman, params, x.clone())
        {
            return net.head.forward(h);
        }
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
        self.0.validate()
    }
    fn build(&self, features: usize, _window: usize, outputs: usize, device: &Device) -> LstmStack {
        let (layers, head) = self.0.build(features, outputs, device, |d, h| {
            FusedLstm::new(d, h, device)
        });
        LstmStack {
            layers,
            head,
            fused: true,
        }
    }
    fn configure(&self, mut net: LstmStack, train: &TrainConfig) -> LstmStack {
        net.fused = train.fused;
        net
    }
    /// With the fused ops, the stacked layers and then the head and the loss, each one op.
    fn loss(&self, net: &LstmStack, x: Tensor<3>, y: Tensor<2>) -> Tensor<1> {
        if net.fused
            && let Some(h) = fused_stack(Cell::Lstm, lstm_params(&net.layers), x.clone())
            && let Some(loss) = net.head.fused_mse(h, y.clone())
        {
            return loss;
        }
        crate::train::mse(self.forward(net, x), y)
    }
    /// Step by step through all layers at once (layer `l` at step `t` reads layer `l - 1`
    /// at step `t`): only the last layer's final hidden state is used, so no layer's
    /// sequence of hidden states is stacked and sliced again.
    fn forward(&self, net: &LstmStack, x: Tensor<3>) -> Tensor<2> {
        if net.fused
            && let Some(h) = fused_stack(Cell::Lstm, lstm_params(&net.layers), x.clone())
        {
            return net.head.forward(h);
        }
        let [b, m, f] = x.dims();
        let mut states: Vec<Option<LstmCellState>> = vec![None; net.layers.len()];
        let scales: Vec<Tensor<2>> = net
            .layers
            .iter()
            .map(|l| l.gate_scale(&x.device()))
            .collect();
        for t in 0..m {
            let mut inp = x.clone().slice([0..b, t..t + 1, 0..f]).reshape([b, f]);
            for ((layer, state), scale) in net.layers.iter().zip(states.iter_mut()).zip(&scales) {
                let next = layer.step(layer.input.forward(inp), state.take(), scale);
                inp = next.hidden.clone();
                *state = Some(next);
            }
        }
        let h = match states.pop().flatten() {
            Some(s) => s.hidden,
            // no layer or an empty window (both rejected by validation)
            None => x
                .slice([0..b, m.saturating_sub(1)..m, 0..f])
                .reshape([b, f]),
        };
        net.head.forward(h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::module::Param;
    use burn::nn::LstmConfig;
    use burn::tensor::TensorData;

    /// The fused layer computes exactly what burn's own `nn::Lstm` computes with the same
    /// weights (an independent implementation of the same equations).
    #[test]
    fn fused_lstm_equals_burn_lstm() {
        let device = Device::flex();
        let lstm = LstmConfig::new(3, 5, true).init(&device);
        let forget = lstm.forget_gate.as_ref().expect("uncoupled LSTM");
        let gates = [&lstm.input_gate, forget, &lstm.cell_gate, &lstm.output_gate];
        let w_ih = Tensor::cat(
            gates
                .iter()
                .map(|g| g.input_transform.weight.val())
                .collect(),
            1,
        );
        let w_hh = Tensor::cat(
            gates
                .iter()
                .map(|g| g.hidden_transform.weight.val())
                .collect(),
            1,
        );
        let bias = |l: &Linear| l.bias.as_ref().expect("bias").val();
        let b = Tensor::cat(
            gates
                .iter()
                .map(|g| bias(&g.input_transform) + bias(&g.hidden_transform))
                .collect(),
            0,
        );
        let mut fused = FusedLstm::new(3, 5, &device);
        fused.input.weight = Param::from_tensor(w_ih);
        fused.input.bias = Some(Param::from_tensor(b));
        fused.recurrent.weight = Param::from_tensor(w_hh);
        let x: Vec<f32> = (0..2 * 4 * 3).map(|i| (i as f32 * 0.37).sin()).collect();
        let x = Tensor::<3>::from_data(TensorData::new(x, [2, 4, 3]), &device);
        let (out_a, st_a) = lstm.forward(x.clone(), None);
        let (out_b, st_b) = fused.forward(x, None);
        let close = |a: Tensor<3>, b: Tensor<3>| {
            let a = a.into_data().try_into_vec::<f32>().expect("f32");
            let b = b.into_data().try_into_vec::<f32>().expect("f32");
            assert_eq!(a.len(), b.len());
            for (x, y) in a.iter().zip(&b) {
                assert!((x - y).abs() < 1e-5, "{x} vs {y}");
            }
        };
        close(out_a, out_b);
        close(st_a.cell.unsqueeze(), st_b.cell.unsqueeze());
    }
}
