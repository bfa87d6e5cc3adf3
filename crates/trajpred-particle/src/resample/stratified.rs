//! Stratified resampling: one uniform per stratum.

use super::Resampler;
use super::common::*;
use crate::error::Result;
use rand::Rng;
use trajpred_core::Error as CoreError;

/// The merge pass: for non-decreasing positions `pos(j)` (in units of the weights), writes
/// the index `i` with `C_(i-1) <= pos(j) < C_i` into `out[j]`; positions at or beyond the
/// total select `last` (the last positive weight).
#[inline]
pub(super) fn merge_sorted(
    weights: &[f64],
    last: usize,
    out: &mut [usize],
    mut pos: impl FnMut(usize) -> f64,
) {
    let mut i = 0usize;
    let mut c = weights[0];
    for (j, o) in out.iter_mut().enumerate() {
        let p = pos(j);
        while p >= c && i < last {
            i += 1;
            c += weights[i];
        }
        *o = i;
    }
}

/// Stratified resampling for given uniforms `u_j in [0, 1]` (one per output): positions
/// `(j + u_j) / n`. Errors with [`trajpred_core::Error::LengthMismatch`] unless
/// `uniforms.len() == out.len()`, [`ParticleError::InvalidUniform`](crate::ParticleError::InvalidUniform) outside `[0, 1]`.
pub fn stratified_indices(weights: &[f64], uniforms: &[f64], out: &mut [usize]) -> Result<()> {
    let c = check_weights(weights, out.len())?;
    if uniforms.len() != out.len() {
        return Err(CoreError::LengthMismatch {
            what: "uniforms vs output",
            expected: out.len(),
            got: uniforms.len(),
        }
        .into());
    }
    for (i, &u) in uniforms.iter().enumerate() {
        check_uniform(i, u)?;
    }
    let nf = out.len() as f64;
    let total = c.total;
    merge_sorted(weights, c.last, out, |j| {
        (j as f64 + uniforms[j]) / nf * total
    });
    Ok(())
}

/// Stratified resampling: positions `(j + u_j) / n` with an independent uniform per
/// stratum.
///
/// The uniforms are counter-based: `u_j` is the SplitMix64 output for the counter `j + 1` under
/// a key, one 64-bit draw from the caller's generator (its top 53 bits as `u_j in [0, 1)`).
/// So each `u_j` can be computed where it is needed, by any thread, and a seed gives the
/// same indices on any number of threads. The pass is counts per particle, like
/// [`Systematic`](super::Systematic): particle `i` gets `floor(x_i) + [u < frac(x_i)]` slots in
/// all, `x_i = C_i n / W`, `u` the uniform of the stratum `floor(x_i)`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stratified;

impl Resampler for Stratified {
    fn resample_into<R: Rng + ?Sized>(
        &self,
        weights: &[f64],
        rng: &mut R,
        out: &mut [usize],
    ) -> Result<()> {
        let c = check_weights(weights, out.len())?;
        let key = rng.next_u64();
        stratified_counts(weights, c, key, out);
        Ok(())
    }
    fn name(&self) -> &'static str {
        "stratified"
    }
}

/// SplitMix64's increment (the golden ratio in 64 bits).
const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// The uniform of stratum `j` under `key`: SplitMix64 (Steele, Lea and Flood 2014, the
/// generator of Java's `SplittableRandom`) at counter `j + 1`, its top 53 bits scaled to
/// `[0, 1)`. Consecutive counters under one key are the consecutive outputs of a SplitMix64
/// stream seeded with `key`.
#[inline(always)]
pub(super) fn stratum_uniform(key: u64, j: usize) -> f64 {
    let mut z = key.wrapping_add((j as u64).wrapping_add(1).wrapping_mul(GOLDEN));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    exact_f64(z >> 11) * (1.0 / (1u64 << 53) as f64)
}

/// `m` as `f64`, exactly for `m < 2^53`, from the bits of its two 32-bit halves placed in the
/// significands of `2^84` and `2^52` (the conversion instruction for 64-bit integers exists
/// only in AVX-512, and a vectorised batch of counts would leave the vectors for it).
#[inline(always)]
fn exact_f64(m: u64) -> f64 {
    let hi =
        f64::from_bits(0x4530_0000_0000_0000 | (m >> 32)) - 19_342_813_118_337_666_422_669_312.0;
    let lo = f64::from_bits(0x4330_0000_0000_0000 | (m & 0xFFFF_FFFF));
    hi + lo
}

/// Stratified resampling as counts per input particle, in one pass over the weights.
///
/// With `x_i = fl(C_i n / W)` (`C_i` the sequential running sum, `W` the total), particle `i`
/// receives the slots `k_(i-1) <= j < k_i`, `k_i = #{j < n : j + u_j < x_i}`. As
/// `u_j in [0, 1)`, every stratum below `j0 = floor(x_i)` counts, none above it, and `j0`
/// counts when `u_j0 < x_i - j0`: `k_i = min(n, j0 + [u_j0 < x_i - j0])`, with the floor and
/// the fraction exact. One uniform per particle, no search, no data-dependent
/// branch; the slots from `k_last` on take `last`. The counts are non-decreasing in `i` (a
/// particle of zero weight gets none), and `E[k_i - k_(i-1)] = x_i - x_(i-1) = n w_i / W`.
///
/// From [`PARALLEL_MIN`] particles and slots on, the pass runs as two halves on the rayon
/// pool; the second starts from the running sum at the midpoint kept by [`check_weights`]
/// (the same `C_i`) and `k` of the particle before it (the same rule), and the uniforms do
/// not depend on who computes them: the indices are those of the one-pass result on any
/// number of threads.
pub(super) fn stratified_counts(weights: &[f64], c: Checked, key: u64, out: &mut [usize]) {
    let n = out.len();
    if n == 0 {
        return;
    }
    let k = StratifiedCount {
        n,
        scale: n as f64 / c.total,
        key,
    };
    let h = c.mid;
    if h >= PARALLEL_MIN / 2 && h <= c.last && n >= PARALLEL_MIN && rayon::current_num_threads() > 1
    {
        let k_mid = k.count(c.mid_sum);
        let (first, second) = out.split_at_mut(k_mid);
        join_here(
            || {
                dispatch_pass(k, &weights[..h], 0, 0.0, first);
            },
            || {
                let end = dispatch_pass(k, &weights[h..=c.last], h, c.mid_sum, second);
                second[end..].fill(c.last);
            },
        );
    } else {
        let end = dispatch_pass(k, &weights[..=c.last], 0, 0.0, out);
        out[end..].fill(c.last);
    }
}

/// The count rule of [`stratified_counts`]: `n` slots, scale `n / W`, the uniforms' key.
#[derive(Debug, Clone, Copy)]
pub(super) struct StratifiedCount {
    n: usize,
    scale: f64,
    key: u64,
}

impl StratifiedCount {
    /// `#{j < n : j + u_j < cum n / W}`.
    #[inline(always)]
    fn count(&self, cum: f64) -> usize {
        // `j0 = floor(x)` and `x - j0`, exact for `0 <= x < 2^51` (as in [`split`]), without
        // a data-dependent branch or a conversion instruction (so that a batch of counts
        // vectorises): `y - ROUND` is `x` rounded to the nearest integer, one too many where
        // it rounded up
        let x = cum * self.scale;
        let y = x + ROUND;
        let r = y - ROUND;
        let up = r > x;
        let floor = if up { r - 1.0 } else { r };
        let j0 = rounded(y).wrapping_sub(usize::from(up));
        let frac = x - floor;
        (j0 + usize::from(stratum_uniform(self.key, j0) < frac)).min(self.n)
    }
}

impl CountPass for StratifiedCount {
    /// Writes the slots of the particles `first..first + weights.len()` (whose running sum
    /// starts at `cum`) into `out`, which starts at the slot `count(cum)`; returns the end of
    /// the written slots, relative to `out`.
    #[inline(always)]
    fn run(&self, weights: &[f64], first: usize, mut cum: f64, out: &mut [usize]) -> usize {
        let base = if first == 0 { 0 } else { self.count(cum) };
        let mut start = 0usize;
        // the counts of a batch first (independent of each other but for the running sum),
        // then its runs
        let mut ks = [0usize; BATCH];
        let mut cums = [0.0f64; BATCH];
        for (b, batch) in weights.chunks(BATCH).enumerate() {
            // the running sums (one chain), then the counts, independent of each other
            for (c, &w) in cums.iter_mut().zip(batch) {
                cum += w;
                *c = cum;
            }
            for (k, &c) in ks.iter_mut().zip(&cums) {
                *k = self.count(c);
            }
            write_runs(&ks[..batch.len()], base, first + b * BATCH, &mut start, out);
        }
        start
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_f64_is_the_conversion_below_2_pow_53() {
        let mut m = 0x2545_F491_4F6C_DD1Du64;
        let mut cases = vec![0, 1, (1 << 32) - 1, 1 << 32, (1 << 32) + 1, (1 << 52) + 1];
        cases.push((1 << 53) - 1);
        for _ in 0..10_000 {
            m ^= m << 13;
            m ^= m >> 7;
            m ^= m << 17;
            cases.push(m >> 11);
        }
        for m in cases {
            assert_eq!(exact_f64(m).to_bits(), (m as f64).to_bits(), "m = {m}");
        }
    }
}
