//! The fully connected head of the windowed LSTM model and its mean squared error as one
//! autodiff op.
//!
//! Forward, from the last hidden state `u_0 = h` `[B, H]`: per hidden layer
//! `u_{k+1} = act(u_k W_k + b_k)`, the output layer `o = u W + b` `[B, n]`, then
//! `loss = Σ (o - y)² / (B n)`. Backward from the loss's gradient `g`:
//! `dO = 2 g (o - y) / (B n)`, `dy = -dO`; per layer from the top `dW = uᵀ dZ`, `db = Σ dZ`,
//! `dU = dZ Wᵀ`, times the activation's derivative below a hidden layer. The parameters come
//! packed: per layer (the hidden ones, then the output layer) `W` `[in, out]` row-major,
//! then `b` `[out]` (`Head::fused_params`).
//!
//! One node instead of burn's two linear layers, activation, subtraction, square and mean,
//! forward and backward, each a tracked tensor operation.

use super::bridge;
use super::{Mat, Real, activate, activate_backward, add_column_sums, gemm};
use crate::config::Activation;
use crate::error::{CoreError, NeuralError, Result};
use burn::backend::flex::FlexTensor;
use burn::tensor::Tensor;

/// The head's sizes.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Spec {
    /// Width of the input (the last hidden state).
    pub input: usize,
    /// Widths of the hidden fully connected layers.
    pub fc: Vec<usize>,
    /// Outputs.
    pub output: usize,
    /// Activation of the hidden layers.
    pub activation: Activation,
}

/// Where a layer's weights sit in the packed vector, and its widths.
#[derive(Debug, Clone, Copy)]
struct LinearAt {
    w: usize,
    b: usize,
    input: usize,
    output: usize,
}

impl Spec {
    /// The layers, output layer last, and the length of the packed vector.
    fn layers(&self) -> (Vec<LinearAt>, usize) {
        let mut at = 0;
        let mut input = self.input;
        let mut v = Vec::with_capacity(self.fc.len() + 1);
        for &output in self.fc.iter().chain(std::iter::once(&self.output)) {
            v.push(LinearAt {
                w: at,
                b: at + input * output,
                input,
                output,
            });
            at += input * output + output;
            input = output;
        }
        (v, at)
    }

    /// Length of the packed parameter vector.
    #[cfg(test)]
    pub(crate) fn n_params(&self) -> usize {
        self.layers().1
    }
}

/// What the forward pass keeps: the input of every layer (`h`, then the activated hidden
/// outputs) and `o - y`.
#[derive(Debug, Clone)]
pub(crate) struct Cache<T> {
    batch: usize,
    inputs: Vec<Vec<T>>,
    diff: Vec<T>,
}

fn mismatch(what: &'static str, expected: usize, got: usize) -> NeuralError {
    NeuralError::Core(CoreError::DimensionMismatch {
        what,
        expected,
        got,
    })
}

/// The forward pass: `h` `[B, input]`, the packed `params`, the targets `y` `[B, output]`;
/// returns the loss and the cache.
pub(crate) fn forward<T: Real>(
    spec: &Spec,
    batch: usize,
    h: &[T],
    params: &[T],
    y: &[T],
) -> Result<(T, Cache<T>)> {
    let (layers, total) = spec.layers();
    if params.len() != total {
        return Err(mismatch("fused head parameters", total, params.len()));
    }
    if h.len() != batch * spec.input {
        return Err(mismatch("fused head input", batch * spec.input, h.len()));
    }
    if y.len() != batch * spec.output {
        return Err(mismatch("fused head targets", batch * spec.output, y.len()));
    }
    let mut inputs = Vec::with_capacity(layers.len());
    let mut u = h.to_vec();
    let last = layers.len() - 1;
    for (k, at) in layers.iter().enumerate() {
        let mut z = Vec::with_capacity(batch * at.output);
        for _ in 0..batch {
            z.extend_from_slice(&params[at.b..at.b + at.output]);
        }
        gemm(
            Mat::new(&u, batch, at.input),
            Mat::new(&params[at.w..at.b], at.input, at.output),
            T::one(),
            &mut z,
        )?;
        if k < last {
            activate(spec.activation, &mut z);
        }
        inputs.push(std::mem::replace(&mut u, z));
    }
    let diff: Vec<T> = u.iter().zip(y).map(|(&o, &t)| o - t).collect();
    let sum = diff.iter().fold(T::zero(), |s, &d| s + d * d);
    let n = T::from(diff.len()).ok_or_else(|| mismatch("fused head outputs", 1, 0))?;
    Ok((
        sum / n,
        Cache {
            batch,
            inputs,
            diff,
        },
    ))
}

/// The gradients of one run: of `h`, of the packed parameters, of `y`.
#[derive(Debug, Clone)]
pub(crate) struct Grads<T> {
    pub h: Vec<T>,
    pub params: Vec<T>,
    pub y: Vec<T>,
}

/// The backward pass from the loss's gradient `g`.
pub(crate) fn backward<T: Real>(
    spec: &Spec,
    cache: &Cache<T>,
    params: &[T],
    g: T,
) -> Result<Grads<T>> {
    let (layers, total) = spec.layers();
    if params.len() != total {
        return Err(mismatch("fused head parameters", total, params.len()));
    }
    let batch = cache.batch;
    let n = T::from(cache.diff.len()).ok_or_else(|| mismatch("fused head outputs", 1, 0))?;
    let scale = (g + g) / n;
    let mut dz: Vec<T> = cache.diff.iter().map(|&d| d * scale).collect();
    let y = dz.iter().map(|&v| -v).collect();
    let mut gp = vec![T::zero(); total];
    for (k, at) in layers.iter().enumerate().rev() {
        let u = &cache.inputs[k];
        gemm(
            Mat::new(u, batch, at.input).t(),
            Mat::new(&dz, batch, at.output),
            T::zero(),
            &mut gp[at.w..at.b],
        )?;
        add_column_sums(&dz, at.output, &mut gp[at.b..at.b + at.output]);
        let mut du = vec![T::zero(); batch * at.input];
        gemm(
            Mat::new(&dz, batch, at.output),
            Mat::new(&params[at.w..at.b], at.input, at.output).t(),
            T::zero(),
            &mut du,
        )?;
        if k > 0 {
            activate_backward(spec.activation, u, &mut du);
        }
        dz = du;
    }
    Ok(Grads {
        h: dz,
        params: gp,
        y,
    })
}

/// The state the autodiff node keeps.
#[derive(Debug, Clone)]
pub(crate) struct State {
    spec: Spec,
    cache: Cache<f32>,
    params: Vec<f32>,
}

/// The fused head's inputs: `h`, the packed parameters, `y`.
impl bridge::FusedState<3> for State {
    const WHAT: &'static str = "head loss gradient";

    fn shapes(&self) -> [Vec<usize>; 3] {
        let b = self.cache.batch;
        [
            vec![b, self.spec.input],
            vec![self.params.len()],
            vec![b, self.spec.output],
        ]
    }

    fn gradients(&self, g: &[f32], _: [bool; 3]) -> Result<[Vec<f32>; 3]> {
        let g = *g
            .first()
            .ok_or_else(|| mismatch("fused head loss gradient", 1, 0))?;
        let grads = backward(&self.spec, &self.cache, &self.params, g)?;
        Ok([grads.h, grads.params, grads.y])
    }
}

/// The mean squared error of the head on `h` `[B, input]` (packed `params`, see [`Spec`])
/// against `y` `[B, output]`, as one op; a one-element tensor like burn's `mean`.
///
/// Errors when the tensors are not `f32` tensors of the flex backend or the sizes disagree
/// with `spec` (then the composed head and loss are the way).
pub(crate) fn mse(h: Tensor<2>, params: Tensor<1>, y: Tensor<2>, spec: &Spec) -> Result<Tensor<1>> {
    let [batch, input] = h.dims();
    if input != spec.input || y.dims() != [batch, spec.output] {
        return Err(mismatch("fused head input", spec.input, input));
    }
    let prims = vec![
        bridge::prim(h, "head input")?,
        bridge::prim(params, "head parameters")?,
        bridge::prim(y, "head targets")?,
    ];
    let run = |t: &[FlexTensor]| -> Result<(Vec<f32>, State)> {
        let h = bridge::values(&t[0], "head input")?;
        let params = bridge::values(&t[1], "head parameters")?;
        let y = bridge::values(&t[2], "head targets")?;
        let (loss, cache) = forward(spec, batch, &h, &params, &y)?;
        Ok((
            vec![loss],
            State {
                spec: spec.clone(),
                cache,
                params: params.into_owned(),
            },
        ))
    };
    bridge::apply(
        bridge::FusedBackward::<State>::new(),
        prims,
        &[1],
        "fused head",
        run,
    )
}
