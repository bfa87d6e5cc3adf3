//! What the schemes share: the weight check, the fixed-width run store, the rounding helpers,
//! the binary search.

use crate::error::{ParticleError, Result};
use pulp::{Arch, Simd, WithSimd};
use trajpred_core::Error as CoreError;

/// Validated weights: their sum, the index of the last positive weight, and the running sum
/// at the midpoint (`mid`, a multiple of 4: the sum of `weights[..mid]`, accumulated in the
/// same order as the total), where a parallel pass can start its second half exactly.
#[derive(Debug, Clone, Copy)]
pub(super) struct Checked {
    pub(super) total: f64,
    pub(super) last: usize,
    pub(super) mid: usize,
    pub(super) mid_sum: f64,
}

/// The sequential sum of `weights` into `total` (four adds per step, in order) and whether
/// any is negative.
#[inline(always)]
pub(super) fn sum_and_sign(weights: &[f64], total: &mut f64, negative: &mut bool) {
    let chunks = weights.chunks_exact(4);
    let rest = chunks.remainder();
    for q in chunks {
        *total += q[0];
        *total += q[1];
        *total += q[2];
        *total += q[3];
        *negative |= (q[0] < 0.0) | (q[1] < 0.0) | (q[2] < 0.0) | (q[3] < 0.0);
    }
    for &v in rest {
        *total += v;
        *negative |= v < 0.0;
    }
}

/// Checks `weights` for `n` output slots: non-empty, finite, non-negative, with a finite sum
/// that is a normal number and at least `n / f64::MAX`, so that the scale `n / W` the
/// schemes work with is finite. A smaller (subnormal) total means the weights underflowed:
/// it is reported as [`ParticleError::AllWeightsZero`], checked once here at entry instead
/// of in the passes over the weights (where `n / W = inf` made `w n / W` infinite or NaN and
/// the counts read from it garbage).
pub(super) fn check_weights(weights: &[f64], n: usize) -> Result<Checked> {
    if weights.is_empty() {
        return Err(CoreError::Empty { what: "weights" }.into());
    }
    // Fast pass: the sequential sum (the `C_(N-1)` the cumulative sums of the merge passes
    // end with) and a flag for negative weights; a NaN or infinite weight makes the sum
    // non-finite. Only on failure is the first offending weight looked for.
    let mid = (weights.len() / 2) & !3;
    let mut total = 0.0f64;
    let mut negative = false;
    sum_and_sign(&weights[..mid], &mut total, &mut negative);
    let mid_sum = total;
    sum_and_sign(&weights[mid..], &mut total, &mut negative);
    if negative || !total.is_finite() {
        for (index, &value) in weights.iter().enumerate() {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ParticleError::InvalidWeight { index, value });
            }
        }
        if !total.is_finite() {
            return Err(CoreError::NonFinite {
                what: "sum of weights",
                index: 0,
            }
            .into());
        }
    }
    // non-negative weights with a zero sum are all zero
    let last = weights.iter().rposition(|&v| v > 0.0);
    match last {
        Some(last) if scale_ok(total, n) => Ok(Checked {
            total,
            last,
            mid,
            mid_sum,
        }),
        _ => Err(ParticleError::AllWeightsZero {
            count: weights.len(),
        }),
    }
}

/// Whether `n / total` is finite for a normal, positive `total`.
#[inline]
pub(super) fn scale_ok(total: f64, n: usize) -> bool {
    total.is_normal() && total > 0.0 && (n as f64 / total).is_finite()
}

pub(super) fn check_uniform(index: usize, value: f64) -> Result<()> {
    if (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(ParticleError::InvalidUniform { index, value })
    }
}

/// How many slots [`fill_run`] writes unconditionally.
pub(super) const RUN: usize = 4;

/// Writes `i` into `out[start..end]` (`start <= end <= out.len()`). Short runs (the common
/// case: a resampled particle has a few copies) are written as a fixed-width store of
/// [`RUN`] slots, without a data-dependent branch; the slots past `end` are overwritten by
/// the next run or by the final fill of the caller, which must therefore write every slot
/// from its last `end` to `out.len()`.
#[inline(always)]
pub(super) fn fill_run(out: &mut [usize], start: usize, end: usize, i: usize) {
    if end - start <= RUN && start + RUN <= out.len() {
        out[start..start + RUN].copy_from_slice(&[i; RUN]);
    } else {
        out[start..end].fill(i);
    }
}

/// `1.5 * 2^52`: adding it to `|x| < 2^51` rounds `x` to the nearest integer, held in the
/// low bits of the sum.
pub(super) const ROUND: f64 = 6_755_399_441_055_744.0;

/// The integer held in the low bits of `y = x + ROUND` (`x` rounded to the nearest
/// integer, `0 <= x < 2^51`), without a conversion instruction.
#[inline(always)]
pub(super) fn rounded(y: f64) -> usize {
    y.to_bits().wrapping_sub(ROUND.to_bits()) as usize
}

/// For `h ~ e + 1/2` with `e >= -1`: returns the integer nearest to `h` (which is `ceil(e)`
/// unless `e` is within a rounding error of an integer) and `near`, true when `h` lies
/// within `margin` of a half-integer (`e` within `margin` of an integer: the caller then
/// corrects the count exactly). Branch-free and without a conversion instruction: the
/// integer is read from the bits of `h + 1.5 * 2^52`.
#[inline(always)]
pub(super) fn ceil_near(h: f64, margin: f64) -> (usize, bool) {
    let y = h + ROUND;
    let d = (y - ROUND) - h;
    (rounded(y), d.abs() > 0.5 - margin)
}

/// Particles (and output slots) from which [`systematic_counts`] splits its pass in two
/// halves run at once ([`join_here`]); stratified uses the same threshold.
pub(super) const PARALLEL_MIN: usize = 1 << 17;

/// Runs `a` on the calling thread and `b` on rayon's pool at the same time, returning when
/// both are done.
///
/// Not `rayon::join`: called from outside the pool (a user's thread, as resampling usually
/// is), `join` hands both halves to one worker, and the second half runs in parallel only
/// once a second worker has woken and stolen it. On the 2-core machine of docs/particle.md
/// that failed in most calls after a millisecond of single-threaded work (two 1 ms halves
/// took 2.1 ms, in sequence), while a job queued from the calling thread, which then works
/// on its own half, was picked up in time (1.1 ms). Inside the pool both behave alike.
///
/// For two halves only: a pass that splits further (residual's parts) keeps `rayon::join`,
/// since the caller's thread would otherwise work beside every worker (three threads on two
/// cores, measured slower in docs/particle.md).
pub(super) fn join_here(a: impl FnOnce(), b: impl FnOnce() + Send) {
    rayon::in_place_scope(|s| {
        s.spawn(|_| b());
        a();
    });
}

/// Index `i` with `C_(i-1) <= p < C_i` in a cumulative-sum array, by binary search,
/// clamped to `last`.
pub(super) fn search(cumsum: &[f64], p: f64, last: usize) -> usize {
    cumsum.partition_point(|&c| c <= p).min(last)
}

/// Particles per batch of the counting passes ([`CountPass`]): their counts are formed
/// first (vectorised), then their runs written ([`write_runs`]).
pub(super) const BATCH: usize = 64;

/// Writes the runs of the particles `first..first + ks.len()` whose counts `ks` (absolute
/// slots, non-decreasing, at least `base`) end their runs, into `out`, which holds the slots
/// from `base` on and is written from `*start` (relative to `out`). Where the batch's last
/// count leaves room for a run's fixed-width store, no count needs the clamps.
#[inline(always)]
pub(super) fn write_runs(
    ks: &[usize],
    base: usize,
    first: usize,
    start: &mut usize,
    out: &mut [usize],
) {
    let len = out.len();
    let (Some(&lo), Some(&hi)) = (ks.first(), ks.last()) else {
        return;
    };
    if lo >= base && hi - base + RUN <= len {
        for (s, &k) in ks.iter().enumerate() {
            let k = k - base;
            if k - *start <= RUN {
                out[*start..*start + RUN].copy_from_slice(&[first + s; RUN]);
            } else {
                out[*start..k].fill(first + s);
            }
            *start = k;
        }
    } else {
        for (s, &k) in ks.iter().enumerate() {
            let k = k.saturating_sub(base).min(len);
            fill_run(out, *start, k, first + s);
            *start = k;
        }
    }
}

/// A counting pass of systematic or stratified resampling: writes the slots of the
/// particles `first..first + weights.len()`, whose running sum starts at `cum`, into `out`;
/// returns where the written slots end (each scheme documents in which units).
pub(super) trait CountPass: Copy {
    /// The pass itself; implementations are `#[inline(always)]`, so that
    /// [`dispatch_pass`] compiles them for the processor's vectors.
    fn run(&self, weights: &[f64], first: usize, cum: f64, out: &mut [usize]) -> usize;
}

/// A [`CountPass`] with its arguments, for `pulp`'s dispatch.
struct Pass<'a, K> {
    k: K,
    weights: &'a [f64],
    first: usize,
    cum: f64,
    out: &'a mut [usize],
}

impl<K: CountPass> WithSimd for Pass<'_, K> {
    type Output = usize;
    #[inline(always)]
    fn with_simd<S: Simd>(self, _simd: S) -> usize {
        self.k.run(self.weights, self.first, self.cum, self.out)
    }
}

/// Runs the pass compiled for the widest instruction set the processor offers (`pulp`'s
/// run-time dispatch: AVX-512, AVX2 with fused multiply-adds, or the baseline), where a batch
/// of counts is a few vector operations and a run of [`RUN`] slots one vector store.
pub(super) fn dispatch_pass<K: CountPass>(
    k: K,
    weights: &[f64],
    first: usize,
    cum: f64,
    out: &mut [usize],
) -> usize {
    Arch::new().dispatch(Pass {
        k,
        weights,
        first,
        cum,
        out,
    })
}
