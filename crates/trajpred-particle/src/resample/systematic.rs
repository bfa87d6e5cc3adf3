//! Systematic resampling: one offset, counts per particle in one (split) pass.

use super::Resampler;
use super::common::*;
use crate::error::Result;
use rand::{Rng, RngExt};

/// Systematic resampling for a given offset `u in [0, 1]`: positions `(j + u) / n`
/// (`n = out.len()`), written into `out`.
///
/// With normalised weights this is exactly filterpy's `systematic_resample` with
/// `random()` returning `u`, except at the edge: an offset so close to 1 that the last
/// position reaches the rounded sum of the weights selects the last particle of positive
/// weight here, where filterpy indexes past the end of its cumulative sum.
///
/// ```
/// use trajpred_particle::systematic_indices;
/// let mut out = [0; 4];
/// // positions 0.125, 0.375, 0.625, 0.875 against cumulative sums 0.5, 0.75, 1
/// systematic_indices(&[0.5, 0.25, 0.25], 0.5, &mut out)?;
/// assert_eq!(out, [0, 0, 1, 2]);
/// # Ok::<(), trajpred_particle::ParticleError>(())
/// ```
pub fn systematic_indices(weights: &[f64], offset: f64, out: &mut [usize]) -> Result<()> {
    let c = check_weights(weights, out.len())?;
    check_uniform(0, offset)?;
    systematic_counts(weights, c, offset, out);
    Ok(())
}

/// Systematic resampling as counts per input particle, in one pass over the weights.
///
/// The positions are `p_j = fl(fl(fl(j + u) / n) * W)` (the reference's operations, `W`
/// the sequential sum); they are non-decreasing in `j`, so particle `i` receives the slots
/// `k_(i-1) <= j < k_i` with `k_i = #{j : p_j < C_i}`. `k_i` is estimated as
/// `ceil(C_i n / W - u)` (a multiplication, no division, no search); where that estimate is
/// within `16 (n + 2) eps` of an integer (ties and near-ties, where rounding could move it
/// by one; the estimate's error is below `4 (n + 1) eps`) it is corrected against the exact
/// positions. The indices are therefore exactly those of the merge `C_(i-1) <= p_j < C_i`,
/// without its data-dependent branch per particle; the slots from `k_last` on (positions at
/// or past `C_last`) take `last`.
///
/// From [`PARALLEL_MIN`] particles and slots on, the pass runs as two halves on the rayon
/// pool: the second half starts from the running sum at the midpoint that
/// [`check_weights`] kept (the same additions in the same order, so the same `C_i`) and
/// from `k` of the particle before it (computed by the same exact rule), so the indices
/// are identical to the one-pass result on any number of threads.
pub(super) fn systematic_counts(weights: &[f64], c: Checked, offset: f64, out: &mut [usize]) {
    let n = out.len();
    if n == 0 {
        return;
    }
    let k = SystematicCount::new(n, c.total, offset);
    let h = c.mid;
    if h >= PARALLEL_MIN / 2 && h <= c.last && n >= PARALLEL_MIN && rayon::current_num_threads() > 1
    {
        let k_mid = k.count(c.mid_sum, 0);
        let (first, second) = out.split_at_mut(k_mid);
        join_here(
            || {
                dispatch_pass(k, &weights[..h], 0, 0.0, first);
            },
            || {
                let end = dispatch_pass(k, &weights[h..=c.last], h, c.mid_sum, second);
                second[end - k_mid..].fill(c.last);
            },
        );
    } else {
        let end = dispatch_pass(k, &weights[..=c.last], 0, 0.0, out);
        out[end..].fill(c.last);
    }
}

/// The count rule of [`systematic_counts`] for `n` slots, total `W` and offset `u`.
#[derive(Debug, Clone, Copy)]
pub(super) struct SystematicCount {
    n: usize,
    total: f64,
    offset: f64,
    scale: f64,
    half: f64,
    margin: f64,
}

impl SystematicCount {
    fn new(n: usize, total: f64, offset: f64) -> Self {
        let nf = n as f64;
        SystematicCount {
            n,
            total,
            offset,
            scale: nf / total,
            half: 0.5 - offset,
            margin: 16.0 * (nf + 2.0) * f64::EPSILON,
        }
    }

    /// The position of slot `j`, in units of the weights.
    #[inline(always)]
    fn pos(&self, j: usize) -> f64 {
        (j as f64 + self.offset) / self.n as f64 * self.total
    }

    /// `#{j : p_j < cum}`, knowing it is at least `start`.
    #[inline(always)]
    fn count(&self, cum: f64, start: usize) -> usize {
        let n = self.n;
        let (mut k, near) = ceil_near(cum * self.scale + self.half, self.margin);
        if near {
            k = (k as i64).clamp(start as i64, n as i64) as usize;
            while k < n && self.pos(k) < cum {
                k += 1;
            }
            while k > start && self.pos(k - 1) >= cum {
                k -= 1;
            }
        }
        k
    }
}

impl CountPass for SystematicCount {
    /// Writes the slots of the particles `first..first + weights.len()` (whose running sum
    /// starts at `cum`) into `out`, which holds the slots from `k` of particle `first - 1`
    /// (0 for the first particle) on; returns `k` of the last particle, in absolute slots.
    ///
    /// By batches: the running sums (one chain), then the estimates of the counts with their
    /// near-tie flags (independent of each other: they vectorise), corrected one by one in
    /// the rare batch that has a near tie, then the runs, without clamps where the batch's
    /// last count leaves room for a run's fixed-width store.
    #[inline(always)]
    fn run(&self, weights: &[f64], first: usize, mut cum: f64, out: &mut [usize]) -> usize {
        let base = if first == 0 { 0 } else { self.count(cum, 0) };
        let mut start = 0usize;
        let mut prev = base;
        let mut ks = [0usize; BATCH];
        let mut cums = [0.0f64; BATCH];
        for (b, batch) in weights.chunks(BATCH).enumerate() {
            let m = batch.len();
            for (c, &w) in cums.iter_mut().zip(batch) {
                cum += w;
                *c = cum;
            }
            let mut near = false;
            for (k, &c) in ks.iter_mut().zip(&cums[..m]) {
                let (estimate, close) = ceil_near(c * self.scale + self.half, self.margin);
                *k = estimate;
                near |= close;
            }
            if near {
                for (k, &c) in ks.iter_mut().zip(&cums[..m]) {
                    prev = self.count(c, prev);
                    *k = prev;
                }
            }
            prev = ks[m - 1];
            write_runs(&ks[..m], base, first + b * BATCH, &mut start, out);
        }
        start + base
    }
}

/// Systematic resampling: one uniform offset `u`, positions `(j + u) / n`. The lowest
/// variance of the four and `O(n + N)`; each count is `floor(n w_i)` or `ceil(n w_i)`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Systematic;

impl Resampler for Systematic {
    fn resample_into<R: Rng + ?Sized>(
        &self,
        weights: &[f64],
        rng: &mut R,
        out: &mut [usize],
    ) -> Result<()> {
        let u: f64 = rng.random();
        systematic_indices(weights, u, out)
    }
    fn name(&self) -> &'static str {
        "systematic"
    }
}
