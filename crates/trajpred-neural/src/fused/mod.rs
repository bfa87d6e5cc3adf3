//! Fused recurrent ops with their own backward pass, plugged into burn's autodiff as custom
//! operations (`burn::backend::autodiff::ops::Backward`).
//!
//! burn's per-operation autodiff spends most of an LSTM step on bookkeeping: every gate
//! is a tracked tensor, activations are recomputed in the backward pass, and every
//! operation allocates. Here a whole recurrent computation is **one** node of burn's graph:
//!
//! - [`recurrent`]: one LSTM or Elman RNN layer over a whole sequence. The input
//!   projection of every step is one matrix product, the recurrent part runs step by step
//!   and keeps the activated gates, backpropagation through time is written out, and the
//!   weight gradients are one matrix product each at the end. The windowed models' top
//!   layer returns its last step only ([`recurrent::layer_last`]).
//! - [`head`]: the windowed recurrent models' fully connected head and its mean squared error
//!   (the training loss of a batch) as one op.
//! - [`kfu`]: the whole unrolled Kalman-filter-unfolded LSTM (stacked LSTM transition,
//!   fully connected head, diagonal Kalman update with learnable `Q`, `R`) over a sequence.
//!
//! [`adam`] is the optimizer that goes with them: burn's Adam, bit for bit, in one loop per
//! parameter. The arithmetic is generic over `f32`/`f64` ([`Real`]): burn runs it in
//! `f32`, the finite-difference tests in `f64`. Matrix products go through `ndarray`'s
//! `general_mat_mul` on row-major views, except a recurrent step's two products in `f32`
//! ([`Real::step_mul_add`], [`Real::step_mul_t`]: `small.rs`, without packing the weight). The autodiff-composed models stay as the reference
//! (`TrainConfig::fused = false`); the tests in `fused/tests.rs` hold every gradient of
//! the ops to it.

pub(crate) mod adam;
pub(crate) mod bridge;
pub(crate) mod head;
pub(crate) mod kfu;
pub(crate) mod recurrent;
mod small;
#[cfg(test)]
mod tests;

use crate::config::Activation;
use crate::error::{NeuralError, Result};
use ndarray::linalg::general_mat_mul;
use ndarray::{ArrayView2, ArrayViewMut2};

/// The element type of the fused arithmetic: `f32` (training) or `f64` (gradient checks).
pub(crate) trait Real:
    ndarray::LinalgScalar + num_traits::Float + Send + Sync + std::fmt::Debug
{
    /// `exp` as the gate nonlinearities take it: [`exp_f32`] for `f32` (a branch-free
    /// polynomial the compiler vectorises), the standard library's `exp` for `f64` (so the
    /// finite-difference checks see exact derivatives of what the backward passes assume).
    fn exp_gate(self) -> Self;

    /// `out += h w` for row-major `h` (`rows x k`), `w` (`k x n`), `out` (`rows x n`): the
    /// recurrent product of a step. [`gemm_by_transpose`] unless the type has a kernel.
    fn step_mul_add(
        h: &[Self],
        w: &[Self],
        (rows, k, n): (usize, usize, usize),
        out: &mut [Self],
    ) -> Result<()> {
        gemm_by_transpose(Mat::new(h, rows, k), Mat::new(w, k, n), Self::one(), out)
    }

    /// `out = g w^T` for row-major `g` (`rows x n`), `w` (`k x n`), `out` (`rows x k`): a
    /// step's gradient back through the recurrent weight. [`gemm`] unless the type has a
    /// kernel.
    fn step_mul_t(
        g: &[Self],
        w: &[Self],
        (rows, n, k): (usize, usize, usize),
        out: &mut [Self],
    ) -> Result<()> {
        gemm(
            Mat::new(g, rows, n),
            Mat::new(w, k, n).t(),
            Self::zero(),
            out,
        )
    }
}
impl Real for f32 {
    #[inline(always)]
    fn exp_gate(self) -> f32 {
        exp_f32(self)
    }

    /// [`small::mul_add`]: no packing of the weight (see there).
    fn step_mul_add(
        h: &[f32],
        w: &[f32],
        (rows, k, n): (usize, usize, usize),
        out: &mut [f32],
    ) -> Result<()> {
        let (h, w, out) = leading(h, w, out, (rows * k, k * n, rows * n))?;
        small::mul_add(h, w, (rows, k, n), out);
        Ok(())
    }

    /// [`small::mul_t`]: no packing of the weight (see there).
    fn step_mul_t(
        g: &[f32],
        w: &[f32],
        (rows, n, k): (usize, usize, usize),
        out: &mut [f32],
    ) -> Result<()> {
        let (g, w, out) = leading(g, w, out, (rows * n, k * n, rows * k))?;
        small::mul_t(g, w, (rows, n, k), out);
        Ok(())
    }
}

/// The leading `lens` elements of two operands and an output, or a shape error when one is
/// shorter (operands may be longer than a product needs, as ndarray's views allow).
type Operands<'a> = (&'a [f32], &'a [f32], &'a mut [f32]);
fn leading<'a>(
    a: &'a [f32],
    b: &'a [f32],
    out: &'a mut [f32],
    (la, lb, lo): (usize, usize, usize),
) -> Result<Operands<'a>> {
    match (a.get(..la), b.get(..lb), out.get_mut(..lo)) {
        (Some(a), Some(b), Some(out)) => Ok((a, b, out)),
        _ => Err(shape_error("a step's matrix product")),
    }
}
impl Real for f64 {
    #[inline(always)]
    fn exp_gate(self) -> f64 {
        self.exp()
    }
}

/// `exp(x)` in `f32` arithmetic without branches or calls, so that loops over slices of
/// gates vectorise (the C library's `expf`, called per element, was a seventh of the fused
/// LSTM epoch): Cephes' `expf`, `exp(x) = 2^n exp(r)` with `n = round(x / ln 2)` (rounded by
/// adding `1.5 * 2^23`), `r = x - n ln 2` (in two parts) and a degree-6 polynomial for
/// `exp(r)` on `[-ln 2 / 2, ln 2 / 2]`; `2^n` is built from its bits. `x` is clamped to
/// `[-87, 88]` first (results between `1.6e-38` and `1.7e38`, normal numbers; `sigmoid` and
/// `tanh` saturate long before); NaN stays NaN. Within 1 ulp of `f32::exp` on the clamped
/// range (`exp_f32_matches_the_standard_library` in the tests).
#[inline(always)]
pub(crate) fn exp_f32(x: f32) -> f32 {
    const ROUND: f32 = 12_582_912.0;
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    let x = x.clamp(-87.0, 88.0);
    let shifted = x * std::f32::consts::LOG2_E + ROUND;
    let n = shifted - ROUND;
    let r = x - n * LN2_HI - n * LN2_LO;
    let p = 1.987_569_1e-4_f32;
    let p = p * r + 1.398_199_9e-3;
    let p = p * r + 8.333_452e-3;
    let p = p * r + 4.166_579_6e-2;
    let p = p * r + 1.666_666_5e-1;
    let p = p * r + 0.5;
    let e = p * r * r + r + 1.0;
    // `shifted`'s bits are ROUND's plus `n` (its unit in the last place is 1 there)
    let scale = f32::from_bits(
        shifted
            .to_bits()
            .wrapping_sub(ROUND.to_bits())
            .wrapping_add(127)
            << 23,
    );
    e * scale
}

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

/// [`gemm`] computed as `cᵀ = beta cᵀ + bᵀ aᵀ` (the same sums, the same `c`): for the step
/// products `[B, H] x [H, 4H]` of a small batch, matrixmultiply's kernel runs faster over this
/// orientation (the weight becomes its column-major left operand).
pub(crate) fn gemm_by_transpose<T: Real>(
    a: Mat<'_, T>,
    b: Mat<'_, T>,
    beta: T,
    c: &mut [T],
) -> Result<()> {
    let (at, bt) = (a.t().view()?, b.t().view()?);
    if bt.ncols() != at.nrows() {
        return Err(shape_error("a matrix product"));
    }
    let mut ct = ArrayViewMut2::from_shape((at.ncols(), bt.nrows()), c)
        .map_err(|_| shape_error("a matrix product's output"))?
        .reversed_axes();
    general_mat_mul(T::one(), &bt, &at, beta, &mut ct);
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

/// The logistic function `1 / (1 + exp(-x))`.
#[inline(always)]
pub(crate) fn sigmoid<T: Real>(x: T) -> T {
    T::one() / (T::one() + (-x).exp_gate())
}

/// `tanh(x) = 1 - 2 / (exp(2x) + 1)`: one `exp`, where the C library's `tanhf` (through
/// `expm1f`) took a third of the LSTM epoch; saturates to `±1` without overflow trouble
/// (`exp` going to `inf` or `0`), absolute error a few ulps of 1 (the composed model's
/// `2 sigmoid(2x) - 1` is the same formula).
#[inline(always)]
pub(crate) fn tanh<T: Real>(x: T) -> T {
    let one = T::one();
    one - (one + one) / ((x + x).exp_gate() + one)
}

/// Applies the activation of fully connected hidden layers to `v` in place.
pub(crate) fn activate<T: Real>(a: Activation, v: &mut [T]) {
    for x in v {
        *x = match a {
            Activation::Relu => x.max(T::zero()),
            Activation::Tanh => tanh(*x),
            Activation::Sigmoid => sigmoid(*x),
        };
    }
}

/// Multiplies `g` by the activation's derivative, given the activated outputs `y`.
pub(crate) fn activate_backward<T: Real>(a: Activation, y: &[T], g: &mut [T]) {
    let one = T::one();
    for (g, &y) in g.iter_mut().zip(y) {
        *g = *g
            * match a {
                Activation::Relu if y > T::zero() => one,
                Activation::Relu => T::zero(),
                Activation::Tanh => one - y * y,
                Activation::Sigmoid => y * (one - y),
            };
    }
}

/// The four gate blocks `[i f g o]` of one row of `4h` values.
fn gate_blocks<T>(row: &[T], h: usize) -> (&[T], &[T], &[T], &[T]) {
    let (i, rest) = row.split_at(h);
    let (f, rest) = rest.split_at(h);
    let (g, o) = rest.split_at(h);
    (i, f, g, o)
}

/// One LSTM step on `rows` rows, gates in PyTorch's order `[i f g o]`.
///
/// `a` (`[rows, 4h]`) holds the pre-activations and is overwritten with the activated gates
/// (`sigmoid` for `i`, `f`, `o`, `tanh` for `g`); writes `c = f c_prev + i g`, `tc = tanh(c)`
/// and `h = o tc` (each `[rows, h]`). `c_prev = None` is the zero state. Every loop runs
/// over contiguous slices without branches, so that it vectorises.
pub(crate) fn cell_forward<T: Real>(
    h: usize,
    a: &mut [T],
    c_prev: Option<&[T]>,
    c: &mut [T],
    tc: &mut [T],
    hout: &mut [T],
) {
    // compiled again for the machine's vector extensions (AVX2 + FMA, AVX-512), chosen at
    // run time: the loops vectorise wider than the baseline target's SSE2
    pulp::Arch::new().dispatch(CellForward {
        h,
        a,
        c_prev,
        c,
        tc,
        hout,
    })
}

/// [`cell_forward`]'s arguments, for `pulp`'s dispatch (a struct whose `with_simd` is
/// inlined into the target-feature function; a closure's call was not).
struct CellForward<'a, T> {
    h: usize,
    a: &'a mut [T],
    c_prev: Option<&'a [T]>,
    c: &'a mut [T],
    tc: &'a mut [T],
    hout: &'a mut [T],
}

impl<T: Real> pulp::WithSimd for CellForward<'_, T> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        cell_forward_loops(self)
    }
}

#[inline(always)]
fn cell_forward_loops<T: Real>(args: CellForward<'_, T>) {
    let CellForward {
        h,
        a,
        c_prev,
        c,
        tc,
        hout,
    } = args;
    let g4 = 4 * h;
    let zeros;
    let c_prev = match c_prev {
        Some(cp) => cp,
        None => {
            zeros = vec![T::zero(); c.len()];
            &zeros
        }
    };
    for ((((gates, cp), c), tc), hout) in a
        .chunks_exact_mut(g4)
        .zip(c_prev.chunks_exact(h))
        .zip(c.chunks_exact_mut(h))
        .zip(tc.chunks_exact_mut(h))
        .zip(hout.chunks_exact_mut(h))
    {
        let (ifg, o) = gates.split_at_mut(3 * h);
        let (i_f, g) = ifg.split_at_mut(2 * h);
        // one loop per block: a chained iterator would not vectorise
        for v in i_f.iter_mut() {
            *v = sigmoid(*v);
        }
        for v in o.iter_mut() {
            *v = sigmoid(*v);
        }
        for v in g.iter_mut() {
            *v = tanh(*v);
        }
        let (i, f, g, o) = gate_blocks(gates, h);
        for ((((c, &cp), &i), &f), &g) in c.iter_mut().zip(cp).zip(i).zip(f).zip(g) {
            *c = f * cp + i * g;
        }
        for (t, &c) in tc.iter_mut().zip(c.iter()) {
            *t = tanh(c);
        }
        for ((hv, &t), &o) in hout.iter_mut().zip(tc.iter()).zip(o) {
            *hv = o * t;
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
    // as cell_forward
    pulp::Arch::new().dispatch(CellBackward {
        h,
        gates,
        c_prev,
        tc,
        dh,
        dc,
        da,
    })
}

/// [`cell_backward`]'s arguments, for `pulp`'s dispatch (see [`CellForward`]).
struct CellBackward<'a, T> {
    h: usize,
    gates: &'a [T],
    c_prev: Option<&'a [T]>,
    tc: &'a [T],
    dh: &'a [T],
    dc: &'a mut [T],
    da: &'a mut [T],
}

impl<T: Real> pulp::WithSimd for CellBackward<'_, T> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        cell_backward_loops(self)
    }
}

#[inline(always)]
fn cell_backward_loops<T: Real>(args: CellBackward<'_, T>) {
    let CellBackward {
        h,
        gates,
        c_prev,
        tc,
        dh,
        dc,
        da,
    } = args;
    let g4 = 4 * h;
    let one = T::one();
    let zeros;
    let c_prev = match c_prev {
        Some(cp) => cp,
        None => {
            zeros = vec![T::zero(); dc.len()];
            &zeros
        }
    };
    for (((((gt, dat), cp), tc), dh), dc) in gates
        .chunks_exact(g4)
        .zip(da.chunks_exact_mut(g4))
        .zip(c_prev.chunks_exact(h))
        .zip(tc.chunks_exact(h))
        .zip(dh.chunks_exact(h))
        .zip(dc.chunks_exact_mut(h))
    {
        let (i, f, g, o) = gate_blocks(gt, h);
        let (d_i, rest) = dat.split_at_mut(h);
        let (d_f, rest) = rest.split_at_mut(h);
        let (d_g, d_o) = rest.split_at_mut(h);
        for j in 0..h {
            let (i, f, g, o) = (i[j], f[j], g[j], o[j]);
            let t = tc[j];
            let dct = dc[j] + dh[j] * o * (one - t * t);
            d_i[j] = dct * g * i * (one - i);
            d_f[j] = dct * cp[j] * f * (one - f);
            d_g[j] = dct * i * (one - g * g);
            d_o[j] = dh[j] * t * o * (one - o);
            dc[j] = dct * f;
        }
    }
}
