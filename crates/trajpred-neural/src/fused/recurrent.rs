//! One recurrent layer (LSTM or Elman) over a whole sequence as one autodiff op (zero
//! initial state).
//!
//! Forward: the input projection of every step in one product `X W_ih + b` (`[T B, G]`,
//! time-major, `G = 4H` gates for the LSTM, `G = H` for the Elman cell), then per step
//! `a_t += h_{t-1} W_hh`, the gates activated in place and kept. Backward:
//! backpropagation through time over the kept gates, the pre-activation gradients of every
//! step collected in `dA` (`[T B, G]`); then `dW_ih = Xᵀ dA`, `dW_hh = H_{prev}ᵀ dA`,
//! `db = Σ dA`, `dX = dA W_ihᵀ`, one product each.

use super::bridge;
use super::{Mat, Real, add_column_sums, cell_backward, cell_forward, gemm, tanh};
use crate::error::{CoreError, NeuralError, Result};
use burn::backend::flex::FlexTensor;
use burn::tensor::Tensor;

/// The cell of a layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Cell {
    /// LSTM, four gate blocks `[i f g o]` in PyTorch's order ([`cell_forward`]).
    Lstm,
    /// Elman: `h_t = tanh(a_t)`, one block (burn's `nn::Rnn` with its default `tanh` and no
    /// clipping).
    Elman,
}

impl Cell {
    /// Gate blocks per hidden unit.
    pub(crate) fn blocks(self) -> usize {
        match self {
            Cell::Lstm => 4,
            Cell::Elman => 1,
        }
    }
}

/// Sizes of a layer run: batch, steps, input features, hidden units, and the cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Dims {
    pub batch: usize,
    pub steps: usize,
    pub input: usize,
    pub hidden: usize,
    pub cell: Cell,
}

impl Dims {
    fn rows(&self) -> usize {
        self.batch * self.steps
    }

    /// Gate values per row: `4H` (LSTM) or `H` (Elman).
    fn gates(&self) -> usize {
        self.cell.blocks() * self.hidden
    }

    /// Values per row of the cell-state buffers (none for the Elman cell).
    fn cell_width(&self) -> usize {
        match self.cell {
            Cell::Lstm => self.hidden,
            Cell::Elman => 0,
        }
    }
}

/// What the forward pass keeps for the backward pass (all time-major: row `t B + b`).
#[derive(Debug, Clone)]
pub(crate) struct Cache<T> {
    pub dims: Dims,
    /// The inputs `[T B, D]`.
    xt: Vec<T>,
    /// The activated gates `[T B, G]`.
    gates: Vec<T>,
    /// Cell states `[T B, H]` (empty for the Elman cell).
    cs: Vec<T>,
    /// `tanh` of the cell states `[T B, H]` (empty for the Elman cell).
    tcs: Vec<T>,
    /// Hidden states `[T B, H]`.
    hs: Vec<T>,
}

/// The gradients of one layer run.
#[derive(Debug, Clone)]
pub(crate) struct Grads<T> {
    /// `[B, T, D]`, when asked for.
    pub dx: Option<Vec<T>>,
    /// `[D, G]`.
    pub dw_ih: Vec<T>,
    /// `[G]`.
    pub db: Vec<T>,
    /// `[H, G]`.
    pub dw_hh: Vec<T>,
}

fn check_len<T>(v: &[T], n: usize, what: &'static str) -> Result<()> {
    if v.len() == n {
        Ok(())
    } else {
        Err(NeuralError::Core(CoreError::DimensionMismatch {
            what,
            expected: n,
            got: v.len(),
        }))
    }
}

/// `[B, T, F]` batch-major to `[T, B, F]` time-major (or back, with `batch`/`steps` swapped).
fn swap_01<T: Copy>(v: &[T], n0: usize, n1: usize, f: usize) -> Vec<T> {
    let mut out = Vec::with_capacity(v.len());
    for j in 0..n1 {
        for i in 0..n0 {
            out.extend_from_slice(&v[(i * n1 + j) * f..(i * n1 + j + 1) * f]);
        }
    }
    out
}

impl<T: Copy> Cache<T> {
    /// The hidden states `[B, T, H]`.
    pub(crate) fn output(&self) -> Vec<T> {
        let Dims {
            batch,
            steps,
            hidden,
            ..
        } = self.dims;
        swap_01(&self.hs, steps, batch, hidden)
    }

    /// The hidden states of the last step `[B, H]` (empty without steps).
    pub(crate) fn last(&self) -> &[T] {
        let bh = self.dims.batch * self.dims.hidden;
        &self.hs[self.hs.len().saturating_sub(bh)..]
    }
}

/// The forward pass: `x` `[B, T, D]`, `w_ih` `[D, G]`, `b` `[G]`, `w_hh` `[H, G]`;
/// returns the cache of the backward pass, which holds the hidden states
/// ([`Cache::output`], [`Cache::last`]).
pub(crate) fn forward<T: Real>(
    dims: Dims,
    x: &[T],
    w_ih: &[T],
    b: &[T],
    w_hh: &[T],
) -> Result<Cache<T>> {
    let Dims {
        batch,
        steps,
        input,
        hidden,
        cell,
    } = dims;
    let g = dims.gates();
    check_len(x, dims.rows() * input, "fused recurrent layer input")?;
    check_len(w_ih, input * g, "fused recurrent layer input weights")?;
    check_len(b, g, "fused recurrent layer bias")?;
    check_len(w_hh, hidden * g, "fused recurrent layer recurrent weights")?;
    let xt = swap_01(x, batch, steps, input);
    let rows = dims.rows();
    let mut gates = Vec::with_capacity(rows * g);
    for _ in 0..rows {
        gates.extend_from_slice(b);
    }
    gemm(
        Mat::new(&xt, rows, input),
        Mat::new(w_ih, input, g),
        T::one(),
        &mut gates,
    )?;
    let zero = T::zero();
    let cw = rows * dims.cell_width();
    let (mut cs, mut tcs) = (vec![zero; cw], vec![zero; cw]);
    let mut hs = vec![zero; rows * hidden];
    let (bh, bg) = (batch * hidden, batch * g);
    for t in 0..steps {
        let (h_done, h_rest) = hs.split_at_mut(t * bh);
        let a = &mut gates[t * bg..(t + 1) * bg];
        if t > 0 {
            T::step_mul_add(&h_done[(t - 1) * bh..], w_hh, (batch, hidden, g), a)?;
        }
        match cell {
            Cell::Lstm => {
                let (c_done, c_rest) = cs.split_at_mut(t * bh);
                cell_forward(
                    hidden,
                    a,
                    (t > 0).then(|| &c_done[(t - 1) * bh..]),
                    &mut c_rest[..bh],
                    &mut tcs[t * bh..(t + 1) * bh],
                    &mut h_rest[..bh],
                );
            }
            Cell::Elman => {
                for (v, h) in a.iter_mut().zip(&mut h_rest[..bh]) {
                    *v = tanh(*v);
                    *h = *v;
                }
            }
        }
    }
    Ok(Cache {
        dims,
        xt,
        gates,
        cs,
        tcs,
        hs,
    })
}

/// The gradient of a layer's output: of every hidden state `[B, T, H]`, or of the last
/// step's only `[B, H]` (the other steps' being zero).
#[derive(Debug, Clone, Copy)]
pub(crate) enum OutGrad<'a, T> {
    /// `[B, T, H]`.
    All(&'a [T]),
    /// `[B, H]`, the last step.
    Last(&'a [T]),
}

/// The backward pass from the gradient `dh` of the hidden states.
pub(crate) fn backward<T: Real>(
    cache: &Cache<T>,
    w_ih: &[T],
    w_hh: &[T],
    dh: OutGrad<'_, T>,
    need_dx: bool,
) -> Result<Grads<T>> {
    let dims = cache.dims;
    let Dims {
        batch,
        steps,
        input,
        hidden,
        cell,
    } = dims;
    let g = dims.gates();
    let rows = dims.rows();
    let zero = T::zero();
    let one = T::one();
    let (bh, bg) = (batch * hidden, batch * g);
    let dht = match dh {
        OutGrad::All(dh) => {
            check_len(dh, rows * hidden, "fused recurrent layer output gradient")?;
            swap_01(dh, batch, steps, hidden)
        }
        OutGrad::Last(dh) => {
            check_len(
                dh,
                bh.min(rows * hidden),
                "fused recurrent layer last-step gradient",
            )?;
            let mut v = vec![zero; rows * hidden];
            v[rows * hidden - dh.len()..].copy_from_slice(dh);
            v
        }
    };
    let mut da = vec![zero; rows * g];
    let mut dh_next = vec![zero; bh];
    let mut dc = vec![zero; batch * dims.cell_width()];
    let mut dh_t = vec![zero; bh];
    for t in (0..steps).rev() {
        for ((d, a), n) in dh_t
            .iter_mut()
            .zip(&dht[t * bh..(t + 1) * bh])
            .zip(&dh_next)
        {
            *d = *a + *n;
        }
        let gates_t = &cache.gates[t * bg..(t + 1) * bg];
        let da_t = &mut da[t * bg..(t + 1) * bg];
        match cell {
            Cell::Lstm => cell_backward(
                hidden,
                gates_t,
                (t > 0).then(|| &cache.cs[(t - 1) * bh..t * bh]),
                &cache.tcs[t * bh..(t + 1) * bh],
                &dh_t,
                &mut dc,
                da_t,
            ),
            Cell::Elman => {
                for ((d, &h), &dh) in da_t.iter_mut().zip(gates_t).zip(&dh_t) {
                    *d = dh * (one - h * h);
                }
            }
        }
        if t > 0 {
            T::step_mul_t(da_t, w_hh, (batch, g, hidden), &mut dh_next)?;
        }
    }
    let mut dw_ih = vec![zero; input * g];
    gemm(
        Mat::new(&cache.xt, rows, input).t(),
        Mat::new(&da, rows, g),
        zero,
        &mut dw_ih,
    )?;
    let mut dw_hh = vec![zero; hidden * g];
    if steps > 1 {
        let r = (steps - 1) * batch;
        gemm(
            Mat::new(&cache.hs[..r * hidden], r, hidden).t(),
            Mat::new(&da[batch * g..], r, g),
            zero,
            &mut dw_hh,
        )?;
    }
    let mut db = vec![zero; g];
    add_column_sums(&da, g, &mut db);
    let dx = if need_dx {
        let mut dxt = vec![zero; rows * input];
        gemm(
            Mat::new(&da, rows, g),
            Mat::new(w_ih, input, g).t(),
            zero,
            &mut dxt,
        )?;
        Some(swap_01(&dxt, steps, batch, input))
    } else {
        None
    };
    Ok(Grads {
        dx,
        dw_ih,
        db,
        dw_hh,
    })
}

/// The state the autodiff node keeps: the cache and the weights.
#[derive(Debug, Clone)]
pub(crate) struct State {
    cache: Cache<f32>,
    w_ih: bridge::Kept,
    w_hh: bridge::Kept,
    /// Whether the op's output is the last step's hidden states only.
    last: bool,
}

/// A fused recurrent layer's inputs: `x`, `W_ih`, `b`, `W_hh`.
impl bridge::FusedState<4> for State {
    const WHAT: &'static str = "recurrent layer output gradient";

    fn shapes(&self) -> [Vec<usize>; 4] {
        let dims = self.cache.dims;
        let g = dims.gates();
        [
            vec![dims.batch, dims.steps, dims.input],
            vec![dims.input, g],
            vec![g],
            vec![dims.hidden, g],
        ]
    }

    fn gradients(&self, dh: &[f32], [need_x, ..]: [bool; 4]) -> Result<[Vec<f32>; 4]> {
        let dh = if self.last {
            OutGrad::Last(dh)
        } else {
            OutGrad::All(dh)
        };
        let w_ih = self.w_ih.values("recurrent layer input weights")?;
        let w_hh = self.w_hh.values("recurrent layer recurrent weights")?;
        let g = backward(&self.cache, &w_ih, &w_hh, dh, need_x)?;
        Ok([g.dx.unwrap_or_default(), g.dw_ih, g.db, g.dw_hh])
    }
}

/// Runs one recurrent layer of cell `cell` (`x` `[B, T, D]`, `w_ih` `[D, G]`, `b` `[G]`,
/// `w_hh` `[H, G]` with `G` = [`Cell::blocks`] `x H`, zero initial state) as one op;
/// returns the hidden states `[B, T, H]`.
///
/// Errors when the tensors are not `f32` tensors of the flex backend (then the composed
/// layer is the way).
pub(crate) fn layer(
    cell: Cell,
    x: Tensor<3>,
    w_ih: Tensor<2>,
    b: Tensor<1>,
    w_hh: Tensor<2>,
) -> Result<Tensor<3>> {
    run(cell, x, w_ih, b, w_hh, false)
}

/// [`layer`] returning the last step's hidden states `[B, H]` only (what the windowed
/// models' head reads): no slice of the whole sequence, nor its gradient, in burn's graph.
/// Errors also for a sequence without steps.
pub(crate) fn layer_last(
    cell: Cell,
    x: Tensor<3>,
    w_ih: Tensor<2>,
    b: Tensor<1>,
    w_hh: Tensor<2>,
) -> Result<Tensor<2>> {
    run(cell, x, w_ih, b, w_hh, true)
}

fn run<const D: usize>(
    cell: Cell,
    x: Tensor<3>,
    w_ih: Tensor<2>,
    b: Tensor<1>,
    w_hh: Tensor<2>,
    last: bool,
) -> Result<Tensor<D>> {
    let [batch, steps, input] = x.dims();
    let [_, g] = w_ih.dims();
    let dims = Dims {
        batch,
        steps,
        input,
        hidden: g / cell.blocks(),
        cell,
    };
    if last && steps == 0 {
        return Err(NeuralError::Core(CoreError::DimensionMismatch {
            what: "fused recurrent layer steps",
            expected: 1,
            got: 0,
        }));
    }
    let prims = vec![
        bridge::prim(x, "recurrent layer input")?,
        bridge::prim(w_ih, "recurrent layer input weights")?,
        bridge::prim(b, "recurrent layer bias")?,
        bridge::prim(w_hh, "recurrent layer recurrent weights")?,
    ];
    let shape: Vec<usize> = if last {
        vec![batch, dims.hidden]
    } else {
        vec![batch, steps, dims.hidden]
    };
    let run = |t: &[FlexTensor]| -> Result<(Vec<f32>, State)> {
        let x = bridge::values(&t[0], "recurrent layer input")?;
        let w_ih = bridge::values(&t[1], "recurrent layer input weights")?;
        let b = bridge::values(&t[2], "recurrent layer bias")?;
        let w_hh = bridge::values(&t[3], "recurrent layer recurrent weights")?;
        let cache = forward(dims, &x, &w_ih, &b, &w_hh)?;
        let out = if last {
            cache.last().to_vec()
        } else {
            cache.output()
        };
        Ok((
            out,
            State {
                cache,
                w_ih: bridge::Kept::new(&t[1]),
                w_hh: bridge::Kept::new(&t[3]),
                last,
            },
        ))
    };
    bridge::apply(
        bridge::FusedBackward::<State>::new(),
        prims,
        &shape,
        "fused recurrent layer",
        run,
    )
}
