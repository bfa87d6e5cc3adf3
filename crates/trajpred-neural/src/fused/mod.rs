//! Fused recurrent ops with their own backward pass, plugged into burn's autodiff as custom
//! operations (`burn::backend::autodiff::ops::Backward`).
//!
//! burn's per-operation autodiff spends most of an LSTM step on bookkeeping: every gate
//! is a tracked tensor, activations are recomputed in the backward pass, and every
//! operation allocates. Here a whole recurrent computation is **one** node of burn's graph:
//!
//! - [`lstm`]: one LSTM layer over a whole sequence. The input projection of every step is
//!   one matrix product, the recurrent part runs step by step and keeps the activated
//!   gates, backpropagation through time is written out, and the weight gradients are one
//!   matrix product each at the end.
//! - [`kfu`]: the whole unrolled Kalman-filter-unfolded LSTM (stacked LSTM transition,
//!   fully connected head, diagonal Kalman update with learnable `Q`, `R`) over a sequence.
//!
//! The arithmetic is generic over `f32`/`f64` ([`Real`]): burn runs it in `f32`, the
//! finite-difference tests in `f64`. Matrix products go through `ndarray`'s
//! `general_mat_mul` on row-major views. The autodiff-composed models stay as the reference
//! (`TrainConfig::fused = false`); the tests in `fused/tests.rs` hold every gradient of
//! both ops to it.

pub(crate) mod bridge;
pub(crate) mod kfu;
pub(crate) mod lstm;
#[cfg(test)]
mod tests;

use crate::error::{NeuralError, Result};
use ndarray::linalg::general_mat_mul;
use ndarray::{ArrayView2, ArrayViewMut2};

/// The element type of the fused arithmetic: `f32` (training) or `f64` (gradient checks).
pub(crate) trait Real:
    ndarray::LinalgScalar + num_traits::Float + Send + Sync + std::fmt::Debug
{
}
impl Real for f32 {}
impl Real for f64 {}

fn shape_error(what: &str) -> NeuralError {
    NeuralError::Tensor {
        reason: format!("fused op: inconsistent shapes in {what}"),
    }
}

/// A row-major `[rows, cols]` matrix in a slice, optionally used transposed.
#[derive(Clone, Copy)]
pub(crate) struct Mat<'a, T> {
    pub data: &'a [T],
    pub rows: usize,
    pub cols: usize,
    pub transposed: bool,
}

impl<'a, T> Mat<'a, T> {
    pub(crate) fn new(data: &'a [T], rows: usize, cols: usize) -> Self {
        Mat {
            data,
            rows,
            cols,
            transposed: false,
        }
    }

    pub(crate) fn t(self) -> Self {
        Mat {
            transposed: !self.transposed,
            ..self
        }
    }

    fn view(self) -> Result<ArrayView2<'a, T>> {
        let v = ArrayView2::from_shape((self.rows, self.cols), self.data)
            .map_err(|_| shape_error("a matrix operand"))?;
        Ok(if self.transposed {
            v.reversed_axes()
        } else {
            v
        })
    }
}

/// `c = beta c + a b`, `c` row-major `[rows of a, cols of b]`.
pub(crate) fn gemm<T: Real>(a: Mat<'_, T>, b: Mat<'_, T>, beta: T, c: &mut [T]) -> Result<()> {
    let (a, b) = (a.view()?, b.view()?);
    if a.ncols() != b.nrows() {
        return Err(shape_error("a matrix product"));
    }
    let mut cv = ArrayViewMut2::from_shape((a.nrows(), b.ncols()), c)
        .map_err(|_| shape_error("a matrix product's output"))?;
    general_mat_mul(T::one(), &a, &b, beta, &mut cv);
    Ok(())
}

/// Adds the column sums of the row-major `[rows, cols]` matrix `m` to `out` (`[cols]`).
pub(crate) fn add_column_sums<T: Real>(m: &[T], cols: usize, out: &mut [T]) {
    for row in m.chunks_exact(cols) {
        for (o, v) in out.iter_mut().zip(row) {
            *o = *o + *v;
        }
    }
}

pub(crate) fn sigmoid<T: Real>(x: T) -> T {
    T::one() / (T::one() + (-x).exp())
}

/// `tanh(x) = 1 - 2 / (exp(2x) + 1)`: one `exp`, where the C library's `tanhf` (through
/// `expm1f`) took a third of the LSTM epoch; saturates to `±1` without overflow trouble
/// (`exp` going to `inf` or `0`), absolute error a few ulps of 1 (the composed model's
/// `2 sigmoid(2x) - 1` is the same formula).
pub(crate) fn tanh<T: Real>(x: T) -> T {
    let one = T::one();
    one - (one + one) / ((x + x).exp() + one)
}

/// One LSTM step on `rows` rows, gates in PyTorch's order `[i f g o]`.
///
/// `a` (`[rows, 4h]`) holds the pre-activations and is overwritten with the activated gates
/// (`sigmoid` for `i`, `f`, `o`, `tanh` for `g`); writes `c = f c_prev + i g`, `tc = tanh(c)`
/// and `h = o tc` (each `[rows, h]`). `c_prev = None` is the zero state.
pub(crate) fn cell_forward<T: Real>(
    h: usize,
    a: &mut [T],
    c_prev: Option<&[T]>,
    c: &mut [T],
    tc: &mut [T],
    hout: &mut [T],
) {
    let g4 = 4 * h;
    for (r, gates) in a.chunks_exact_mut(g4).enumerate() {
        for j in 0..h {
            let i = sigmoid(gates[j]);
            let f = sigmoid(gates[h + j]);
            let g = tanh(gates[2 * h + j]);
            let o = sigmoid(gates[3 * h + j]);
            gates[j] = i;
            gates[h + j] = f;
            gates[2 * h + j] = g;
            gates[3 * h + j] = o;
            let k = r * h + j;
            let cp = c_prev.map_or(T::zero(), |cp| cp[k]);
            let cn = f * cp + i * g;
            let t = tanh(cn);
            c[k] = cn;
            tc[k] = t;
            hout[k] = o * t;
        }
    }
}

/// The backward pass of [`cell_forward`].
///
/// `dh` is the whole gradient of this step's `h`; `dc` enters as the gradient of this
/// step's `c` from later steps and leaves as the gradient of `c_prev`; `da` (`[rows, 4h]`)
/// receives the gradient of the pre-activations.
pub(crate) fn cell_backward<T: Real>(
    h: usize,
    gates: &[T],
    c_prev: Option<&[T]>,
    tc: &[T],
    dh: &[T],
    dc: &mut [T],
    da: &mut [T],
) {
    let g4 = 4 * h;
    let one = T::one();
    for (r, (gt, dat)) in gates
        .chunks_exact(g4)
        .zip(da.chunks_exact_mut(g4))
        .enumerate()
    {
        for j in 0..h {
            let (i, f, g, o) = (gt[j], gt[h + j], gt[2 * h + j], gt[3 * h + j]);
            let k = r * h + j;
            let t = tc[k];
            let d_o = dh[k] * t;
            let dct = dc[k] + dh[k] * o * (one - t * t);
            let cp = c_prev.map_or(T::zero(), |cp| cp[k]);
            dat[j] = dct * g * i * (one - i);
            dat[h + j] = dct * cp * f * (one - f);
            dat[2 * h + j] = dct * i * (one - g * g);
            dat[3 * h + j] = d_o * o * (one - o);
            dc[k] = dct * f;
        }
    }
}
