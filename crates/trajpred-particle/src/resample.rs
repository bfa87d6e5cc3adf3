//! Resampling: residual, systematic, stratified and multinomial schemes behind one trait,
//! [`Resampler`], with an injected random number generator and allocation-free variants
//! that write ancestor indices into a caller's buffer.
//!
//! Every scheme takes non-negative weights (not necessarily normalised; they are divided by
//! their sum `W`) and writes `n = out.len()` ancestor indices. With `C_i = w_0 + ... + w_i`
//! the running sum, an index `i` is selected by a position `p in [0, W)` when
//! `C_(i-1) <= p < C_i`, so a particle of zero weight is never selected. Positions that
//! rounding pushes to `W` or beyond select the last particle of positive weight: no scheme
//! indexes past the end (filterpy 2.0.0's systematic resampler does when its offset rounds
//! up to 1).
//!
//! | scheme | positions `p_j / W` (`j = 0..n`) | count of particle `i` |
//! |---|---|---|
//! | [`Systematic`] | `(j + u) / n`, one `u ~ U[0, 1)` | `floor(n w_i)` or `ceil(n w_i)` |
//! | [`Stratified`] | `(j + u_j) / n`, `u_j ~ U[0, 1)` i.i.d. | within 2 of `n w_i` |
//! | [`Multinomial`] | i.i.d. `U[0, 1)` | `Binomial(n, w_i)` |
//! | [`Residual`] | `floor(n w_i)` copies, then `n - sum floor(n w_i)` multinomial draws from the residuals `n w_i - floor(n w_i)` | `>= floor(n w_i)` |
//!
//! All four are unbiased: `E[count_i] = n w_i / W`. The residual scheme follows the
//! textbook (Liu and Chen 1998); filterpy 2.0.0's `residual_resample` draws the remainder
//! from `w_i - floor(n w_i)` instead of `n w_i - floor(n w_i)`, which is biased (filterpy
//! issue #290).
//!
//! The random variants ([`Resampler::resample_into`]) run in `O(n + N)` without allocating
//! (their scratch is a few fixed-size arrays on the stack) and return sorted indices. The
//! multinomial scheme draws *sorted* uniforms as normalised cumulative sums of exponential
//! variates (the order statistics of uniforms), so the selection is one merge pass instead
//! of a binary search per draw. The residual scheme draws its remainder per block of
//! particles: the block's number of draws is binomial given the draws left (the conditional
//! law of a multinomial's block totals), and each draw is a slot of the block accepted with
//! probability its residual (rejection, two tries per 64-bit draw, about one try per
//! particle; blocks whose residual is concentrated on few particles search their cumulative
//! residuals instead); the copies and the drawn places are then written per particle in one
//! streaming pass. From `2^17` weights on, the residual scheme first cuts the particles into
//! up to 16 parts (by their number alone), splits the remainder over the parts the same
//! binomial way, seeds one generator per part from the caller's, and runs the parts in
//! parallel: the indices are the same on any number of threads.
//! The deterministic variants ([`systematic_indices`], [`stratified_indices`],
//! [`multinomial_indices`], [`residual_indices`]) take the uniforms as input and follow the
//! order of the given uniforms (the reference definitions used by the tests).

use crate::error::{ParticleError, Result};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{Rng, RngExt, SeedableRng};
use rand_distr::{Distribution, Exp1};

/// A resampling scheme: from weights, draw ancestor indices.
pub trait Resampler {
    /// Writes `out.len()` ancestor indices drawn according to `weights` (non-negative, not
    /// necessarily normalised) into `out`, without allocating.
    ///
    /// Errors: [`ParticleError::Empty`] (no weights), [`ParticleError::InvalidWeight`]
    /// (negative or non-finite), [`ParticleError::AllWeightsZero`] (also for weights that
    /// underflowed: a total that is subnormal or below `n / f64::MAX`),
    /// [`ParticleError::NonFinite`] (the sum of the weights overflows).
    fn resample_into<R: Rng + ?Sized>(
        &self,
        weights: &[f64],
        rng: &mut R,
        out: &mut [usize],
    ) -> Result<()>;

    /// Draws `n` ancestor indices into a new vector (see [`Resampler::resample_into`]).
    fn resample<R: Rng + ?Sized>(
        &self,
        weights: &[f64],
        n: usize,
        rng: &mut R,
    ) -> Result<Vec<usize>> {
        let mut out = vec![0; n];
        self.resample_into(weights, rng, &mut out)?;
        Ok(out)
    }

    /// The scheme's name.
    fn name(&self) -> &'static str;
}

/// Validated weights: their sum, the index of the last positive weight, and the running sum
/// at the midpoint (`mid`, a multiple of 4: the sum of `weights[..mid]`, accumulated in the
/// same order as the total), where a parallel pass can start its second half exactly.
#[derive(Debug, Clone, Copy)]
struct Checked {
    total: f64,
    last: usize,
    mid: usize,
    mid_sum: f64,
}

/// The sequential sum of `weights` into `total` (four adds per step, in order) and whether
/// any is negative.
#[inline(always)]
fn sum_and_sign(weights: &[f64], total: &mut f64, negative: &mut bool) {
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
fn check_weights(weights: &[f64], n: usize) -> Result<Checked> {
    if weights.is_empty() {
        return Err(ParticleError::Empty { what: "weights" });
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
            return Err(ParticleError::NonFinite {
                what: "sum of weights",
                index: 0,
            });
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
fn scale_ok(total: f64, n: usize) -> bool {
    total.is_normal() && total > 0.0 && (n as f64 / total).is_finite()
}

fn check_uniform(index: usize, value: f64) -> Result<()> {
    if (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(ParticleError::InvalidUniform { index, value })
    }
}

/// The merge pass: for non-decreasing positions `pos(j)` (in units of the weights), writes
/// the index `i` with `C_(i-1) <= pos(j) < C_i` into `out[j]`; positions at or beyond the
/// total select `last` (the last positive weight).
#[inline]
fn merge_sorted(
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

/// How many slots [`fill_run`] writes unconditionally.
const RUN: usize = 4;

/// Writes `i` into `out[start..end]` (`start <= end <= out.len()`). Short runs (the common
/// case: a resampled particle has a few copies) are written as a fixed-width store of
/// [`RUN`] slots, without a data-dependent branch; the slots past `end` are overwritten by
/// the next run or by the final fill of the caller, which must therefore write every slot
/// from its last `end` to `out.len()`.
#[inline(always)]
fn fill_run(out: &mut [usize], start: usize, end: usize, i: usize) {
    if end - start <= RUN && start + RUN <= out.len() {
        out[start..start + RUN].copy_from_slice(&[i; RUN]);
    } else {
        out[start..end].fill(i);
    }
}

/// `1.5 * 2^52`: adding it to `|x| < 2^51` rounds `x` to the nearest integer, held in the
/// low bits of the sum.
const ROUND: f64 = 6_755_399_441_055_744.0;

/// The integer held in the low bits of `y = x + ROUND` (`x` rounded to the nearest
/// integer, `0 <= x < 2^51`), without a conversion instruction.
#[inline(always)]
fn rounded(y: f64) -> usize {
    y.to_bits().wrapping_sub(ROUND.to_bits()) as usize
}

/// For `h ~ e + 1/2` with `e >= -1`: returns the integer nearest to `h` (which is `ceil(e)`
/// unless `e` is within a rounding error of an integer) and `near`, true when `h` lies
/// within `margin` of a half-integer (`e` within `margin` of an integer: the caller then
/// corrects the count exactly). Branch-free and without a conversion instruction: the
/// integer is read from the bits of `h + 1.5 * 2^52`.
#[inline(always)]
fn ceil_near(h: f64, margin: f64) -> (usize, bool) {
    let y = h + ROUND;
    let d = (y - ROUND) - h;
    (rounded(y), d.abs() > 0.5 - margin)
}

/// Particles (and output slots) from which [`systematic_counts`] splits its pass in two
/// halves run by `rayon::join`.
const PARALLEL_MIN: usize = 1 << 17;

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
fn systematic_counts(weights: &[f64], c: Checked, offset: f64, out: &mut [usize]) {
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
        rayon::join(
            || k.run(&weights[..h], 0, 0.0, first),
            || {
                let end = k.run(&weights[h..=c.last], h, c.mid_sum, second);
                second[end - k_mid..].fill(c.last);
            },
        );
    } else {
        let end = k.run(&weights[..=c.last], 0, 0.0, out);
        out[end..].fill(c.last);
    }
}

/// The count rule of [`systematic_counts`] for `n` slots, total `W` and offset `u`.
#[derive(Debug, Clone, Copy)]
struct SystematicCount {
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

    /// Writes the slots of the particles `first..first + weights.len()` (whose running sum
    /// starts at `cum`) into `out`, which holds the slots from `k` of particle `first - 1`
    /// (0 for the first particle) on; returns `k` of the last particle, in absolute slots.
    #[inline(always)]
    fn run(&self, weights: &[f64], first: usize, mut cum: f64, out: &mut [usize]) -> usize {
        let base = if first == 0 { 0 } else { self.count(cum, 0) };
        let len = out.len();
        // the fixed-width stores of the main loop need RUN slots from `start`
        let lim = len.saturating_sub(RUN);
        let mut start = 0usize;
        for (s, &w) in weights.iter().enumerate() {
            cum += w;
            let k = self.count(cum, start + base).saturating_sub(base).min(len);
            if k.wrapping_sub(start) <= RUN && start <= lim && len >= RUN {
                out[start..start + RUN].fill(first + s);
            } else {
                out[start..k].fill(first + s);
            }
            start = k;
        }
        start + base
    }
}

/// Stratified resampling for given uniforms `u_j in [0, 1]` (one per output): positions
/// `(j + u_j) / n`. Errors with [`ParticleError::LengthMismatch`] unless
/// `uniforms.len() == out.len()`, [`ParticleError::InvalidUniform`] outside `[0, 1]`.
pub fn stratified_indices(weights: &[f64], uniforms: &[f64], out: &mut [usize]) -> Result<()> {
    let c = check_weights(weights, out.len())?;
    if uniforms.len() != out.len() {
        return Err(ParticleError::LengthMismatch {
            what: "uniforms vs output",
            expected: out.len(),
            got: uniforms.len(),
        });
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

/// Index `i` with `C_(i-1) <= p < C_i` in a cumulative-sum array, by binary search,
/// clamped to `last`.
fn search(cumsum: &[f64], p: f64, last: usize) -> usize {
    cumsum.partition_point(|&c| c <= p).min(last)
}

/// Multinomial resampling for given uniforms `u_j in [0, 1]`, one draw per uniform, in the
/// order of the uniforms (the inverse of the cumulative distribution at each `u_j`; this
/// function allocates the cumulative sums).
///
/// Equal to filterpy's `multinomial_resample` (`searchsorted` on the cumulative sums) except
/// on exact ties `u_j = C_i`, where filterpy picks `i` and this picks the next particle of
/// positive weight (so a zero weight is never selected, even for `u = 0`).
pub fn multinomial_indices(weights: &[f64], uniforms: &[f64], out: &mut [usize]) -> Result<()> {
    let c = check_weights(weights, out.len())?;
    if uniforms.len() != out.len() {
        return Err(ParticleError::LengthMismatch {
            what: "uniforms vs output",
            expected: out.len(),
            got: uniforms.len(),
        });
    }
    let mut cumsum = Vec::with_capacity(weights.len());
    let mut s = 0.0;
    for &w in weights {
        s += w;
        cumsum.push(s);
    }
    for (j, (&u, o)) in uniforms.iter().zip(out.iter_mut()).enumerate() {
        check_uniform(j, u)?;
        *o = search(&cumsum, u * c.total, c.last);
    }
    Ok(())
}

/// Residual resampling for given uniforms (allocates the residual cumulative sums): the
/// first `k = sum_i floor(n w_i)` outputs are the deterministic copies in index order, the
/// remaining `n - k` outputs are multinomial draws from the residual weights
/// `n w_i - floor(n w_i)`, one per uniform, in the order of `uniforms[..n - k]`. Returns `k`.
///
/// `n = out.len()`; `uniforms` must hold at least `n - k` values (at most `n` are ever
/// needed). This is the textbook definition; filterpy 2.0.0's `residual_resample` uses the
/// residuals `w_i - floor(n w_i)` (biased, filterpy issue #290), so its remainder draws
/// differ whenever some `n w_i >= 1`.
///
/// ```
/// use trajpred_particle::residual_indices;
/// let mut out = [0; 4];
/// // n w = [2.4, 1.2, 0.4]: copies [0, 0, 1], residuals [0.4, 0.2, 0.4] / 1,
/// // one draw at u = 0.7 lands in particle 2 (cumulative residuals 0.4, 0.6, 1.0)
/// let k = residual_indices(&[0.6, 0.3, 0.1], &[0.7], &mut out)?;
/// assert_eq!((k, out), (3, [0, 0, 1, 2]));
/// # Ok::<(), trajpred_particle::ParticleError>(())
/// ```
pub fn residual_indices(weights: &[f64], uniforms: &[f64], out: &mut [usize]) -> Result<usize> {
    let c = check_weights(weights, out.len())?;
    let n = out.len();
    let scale = n as f64 / c.total;
    let (k, _, _) = write_copies(weights, scale, out);
    let m = n - k;
    if uniforms.len() < m {
        return Err(ParticleError::LengthMismatch {
            what: "uniforms vs remainder draws",
            expected: m,
            got: uniforms.len(),
        });
    }
    if m == 0 {
        return Ok(k);
    }
    let mut cumsum = Vec::with_capacity(weights.len());
    let mut s = 0.0;
    let mut last = 0;
    for (i, &w) in weights.iter().enumerate() {
        let x = w * scale;
        let r = x - x.floor();
        if r > 0.0 {
            last = i;
        }
        s += r;
        cumsum.push(s);
    }
    if s <= 0.0 {
        // every residual rounded to zero: the copies fell short by rounding only; give the
        // missing places to the largest weight's particle
        fill_with_largest(weights, &mut out[k..]);
        return Ok(k);
    }
    for (j, (&u, o)) in uniforms.iter().zip(out[k..].iter_mut()).enumerate() {
        check_uniform(j, u)?;
        *o = search(&cumsum, u * s, last);
    }
    Ok(k)
}

/// The deterministic part of residual resampling, in one pass: writes `floor(w_i * scale)`
/// copies of each `i` in index order (at most `out.len()` in total; short runs as
/// fixed-width stores, see [`fill_run`], so the slots from the returned count on hold
/// scratch values the caller overwrites) and sums the residuals
/// `w_i * scale - floor(w_i * scale)`. Returns (copies written, sum of the residuals, index of
/// the last positive residual or 0).
#[inline]
fn write_copies(weights: &[f64], scale: f64, out: &mut [usize]) -> (usize, f64, usize) {
    write_copies_from(weights, 0, scale, out)
}

/// [`write_copies`] for the particles `first..first + weights.len()` (the indices written are
/// offset by `first`; the returned last index is relative to `first`).
#[inline]
fn write_copies_from(
    weights: &[f64],
    first: usize,
    scale: f64,
    out: &mut [usize],
) -> (usize, f64, usize) {
    let n = out.len();
    let mut k = 0usize;
    let mut s = 0.0f64;
    let mut last = 0usize;
    for (i, &w) in weights.iter().enumerate() {
        let x = w * scale;
        // truncation is floor for x >= 0 (one instruction, unlike `floor` without SSE4.1);
        // x <= n (1 + eps) fits
        let copies = x as i64 as usize;
        let r = x - copies as f64;
        s += r;
        last = if r > 0.0 { i } else { last };
        let end = k.saturating_add(copies).min(n);
        fill_run(out, k, end, first + i);
        k = end;
    }
    (k, s, last)
}

fn fill_with_largest(weights: &[f64], out: &mut [usize]) {
    let mut best = 0;
    for (i, &w) in weights.iter().enumerate() {
        if w > weights[best] {
            best = i;
        }
    }
    out.fill(best);
}

/// Fills `buf` with the bit patterns of `m = buf.len()` sorted uniforms scaled to
/// `[0, scale)`: `scale * (E_1 + ... + E_j) / (E_1 + ... + E_(m+1))` with `E ~ Exp(1)` i.i.d.
/// (the joint law of the order statistics of `m` i.i.d. uniforms).
fn sorted_uniform_bits<R: Rng + ?Sized>(rng: &mut R, buf: &mut [u64], scale: f64) {
    let mut s = 0.0f64;
    for b in buf.iter_mut() {
        let e: f64 = Exp1.sample(rng);
        s += e;
        *b = s.to_bits();
    }
    let e: f64 = Exp1.sample(rng);
    let f = scale / (s + e);
    for b in buf.iter_mut() {
        *b = (f64::from_bits(*b) * f).to_bits();
    }
}

/// Merges sorted uniforms (drawn here) with the cumulative sums of `weights` (scaled to
/// total `total`), writing into `out`; allocation-free where `usize` holds 64 bits.
fn sorted_multinomial<R: Rng + ?Sized>(
    rng: &mut R,
    weights: impl Fn(usize) -> f64,
    len: usize,
    total: f64,
    last: usize,
    out: &mut [usize],
) {
    if out.is_empty() {
        return;
    }
    if usize::BITS >= 64 {
        sorted_multinomial_in_place(rng, weights, len, total, last, out);
        return;
    }
    let mut bits = vec![0u64; out.len()];
    sorted_uniform_bits(rng, &mut bits, total);
    let mut i = 0usize;
    let mut c = weights(0);
    for (o, &b) in out.iter_mut().zip(bits.iter()) {
        let p = f64::from_bits(b);
        while p >= c && i < last && i + 1 < len {
            i += 1;
            c += weights(i);
        }
        *o = i;
    }
}

/// [`sorted_multinomial`] holding the positions' bits in the output buffer itself: each
/// slot is read before the merge overwrites it with its index.
fn sorted_multinomial_in_place<R: Rng + ?Sized>(
    rng: &mut R,
    weights: impl Fn(usize) -> f64,
    len: usize,
    total: f64,
    last: usize,
    out: &mut [usize],
) {
    let mut s = 0.0f64;
    for o in out.iter_mut() {
        let e: f64 = Exp1.sample(rng);
        s += e;
        *o = s.to_bits() as usize;
    }
    let e: f64 = Exp1.sample(rng);
    let f = total / (s + e);
    let mut i = 0usize;
    let mut c = weights(0);
    for o in out.iter_mut() {
        let p = f64::from_bits(*o as u64) * f;
        while p >= c && i < last && i + 1 < len {
            i += 1;
            c += weights(i);
        }
        *o = i;
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

/// Stratified resampling: positions `(j + u_j) / n` with an independent uniform per
/// stratum.
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
        let nf = out.len() as f64;
        let total = c.total;
        merge_sorted(weights, c.last, out, |j| {
            let u: f64 = rng.random();
            (j as f64 + u) / nf * total
        });
        Ok(())
    }
    fn name(&self) -> &'static str {
        "stratified"
    }
}

/// Multinomial resampling: `n` i.i.d. draws from the weights (the indices are returned in
/// sorted order, drawn as sorted uniforms; the multiset has the multinomial law).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Multinomial;

impl Resampler for Multinomial {
    fn resample_into<R: Rng + ?Sized>(
        &self,
        weights: &[f64],
        rng: &mut R,
        out: &mut [usize],
    ) -> Result<()> {
        let c = check_weights(weights, out.len())?;
        sorted_multinomial(rng, |i| weights[i], weights.len(), c.total, c.last, out);
        Ok(())
    }
    fn name(&self) -> &'static str {
        "multinomial"
    }
}

/// Residual resampling (the MKPF paper's scheme): `floor(n w_i)` copies of each particle,
/// then the remaining `n - sum floor(n w_i)` places drawn multinomially from the residual
/// weights `n w_i - floor(n w_i)`.
///
/// The remainder is an exact multinomial draw (see the module documentation for how it is
/// drawn); the indices come out sorted, each particle's copies and drawn places together.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Residual;

impl Resampler for Residual {
    fn resample_into<R: Rng + ?Sized>(
        &self,
        weights: &[f64],
        rng: &mut R,
        out: &mut [usize],
    ) -> Result<()> {
        let n = out.len();
        let mut parts = [Part::default(); PARTS_MAX];
        let parts = &mut parts[..part_count(weights.len())];
        let scale = n as f64 / residual_total(weights, parts, n)?;
        let sums = residual_part_sums(weights, scale, parts);
        if sums.copies >= n {
            // no remainder (or, by rounding, copies for more than n places: clamped)
            write_copies(weights, scale, out);
            return Ok(());
        }
        if sums.residual <= 0.0 {
            let (k, _, _) = write_copies(weights, scale, out);
            fill_with_largest(weights, &mut out[k..]);
            return Ok(());
        }
        if u32::try_from(n).is_err() {
            // beyond the block counts' range: copies, then the sorted-uniform remainder
            let (k, s, last) = write_copies(weights, scale, out);
            let residual = |i: usize| split(weights[i], scale).1;
            sorted_multinomial(rng, residual, weights.len(), s, last, &mut out[k..]);
            return Ok(());
        }
        if let [_] = parts {
            residual_blocks(weights, 0, scale, sums, rng, out);
        } else {
            split_draws(parts, (n - sums.copies) as u64, sums.residual, rng);
            run_parts(weights, scale, parts, out);
        }
        Ok(())
    }
    fn name(&self) -> &'static str {
        "residual"
    }
}

/// Particles per block of [`residual_blocks`] (its three per-block arrays, 32 KiB, live on
/// the stack and stay in the first-level cache): `2^11`, the slot bits of a try in
/// [`draw_by_rejection`].
const BLOCK: usize = 2048;

/// Lowest acceptance for which [`residual_blocks`] draws a block's remainder by rejection.
const ACCEPT_MIN: f64 = 0.25;

/// Totals of the residual scheme: the copies `sum_i floor(w_i scale)`, the residual sum
/// (in four interleaved partial sums: its rounding differs from the blocks' sequential sums
/// by a relative `O(N eps)`, which only moves the blocks' binomial probabilities by as
/// much) and the index of the last positive residual.
#[derive(Debug, Clone, Copy, Default)]
struct ResidualSums {
    copies: usize,
    residual: f64,
    last: usize,
}

/// `(floor(x), x - floor(x))` for `x = w scale`, `0 <= x < 2^51`, without a conversion
/// instruction (Rust's saturating `as` costs a compare and a branch per value) and without
/// a data-dependent branch: `x` is rounded to the nearest integer `f` by adding [`ROUND`],
/// and where `f > x` (rounded up, which needs `x >= 1/2`) the floor is `f - 1` and the
/// fraction `x - f + 1`. Both are exact: `x - f` is a multiple of the last place of `x`
/// below 1/2 in magnitude, and `x - f + 1` lies in `[1/2, 1)` where the spacing of doubles
/// (`2^-53`) divides the last place of `x >= 1/2`.
#[inline(always)]
fn split(w: f64, scale: f64) -> (usize, f64) {
    let x = w * scale;
    let y = x + ROUND;
    let f = y - ROUND;
    let up = f > x;
    (
        rounded(y).wrapping_sub(usize::from(up)),
        (x - f) + if up { 1.0 } else { 0.0 },
    )
}

fn residual_sums(weights: &[f64], scale: f64) -> ResidualSums {
    let mut k = [0usize; 4];
    let mut r = [0.0f64; 4];
    let chunks = weights.chunks_exact(4);
    let rest = chunks.remainder();
    for q in chunks {
        for l in 0..4 {
            let (f, x) = split(q[l], scale);
            k[l] += f;
            r[l] += x;
        }
    }
    for &w in rest {
        let (f, x) = split(w, scale);
        k[0] += f;
        r[0] += x;
    }
    let last = weights
        .iter()
        .rposition(|&w| split(w, scale).1 > 0.0)
        .unwrap_or(0);
    ResidualSums {
        copies: k[0] + k[1] + k[2] + k[3],
        residual: (r[0] + r[1]) + (r[2] + r[3]),
        last,
    }
}

/// The draws of one group (a block, or a part) out of the `m_left` draws left, whose
/// residual sum is `s` of the `s_left` left: all of them for the group of the last positive
/// residual (`last`), else `Binomial(m_left, s / s_left)`, the conditional law of a
/// multinomial's group totals.
#[inline]
fn share<R: Rng + ?Sized>(last: bool, m_left: u64, s: f64, s_left: f64, rng: &mut R) -> u64 {
    if last {
        m_left
    } else if m_left == 0 || s <= 0.0 {
        0
    } else {
        match rand_distr::Binomial::new(m_left, (s / s_left).min(1.0)) {
            Ok(d) => d.sample(rng),
            Err(_) => 0,
        }
    }
}

/// Residual resampling with the remainder drawn block by block, the output written in one
/// streaming pass, sorted by particle.
///
/// Requires `sums.copies < out.len() <= u32::MAX` and `sums.residual > 0`. With `m = n - copies`
/// remainder draws from the residuals `r_i in [0, 1)`, the multinomial counts are drawn as
/// 1. per block `b` of [`BLOCK`] particles (residual sum `S_b`), in order: the block's
///    number of draws `M_b ~ Binomial(m_left, S_b / S_left)` (`m_left`, `S_left`: the draws
///    and the residual sum of this block and the blocks after it; the block holding the
///    last positive residual takes all `m_left`), which is the conditional law of a
///    multinomial's block totals;
/// 2. within the block, `M_b` i.i.d. draws from `r_s / S_b`. By rejection when the
///    acceptance `S_b / BLOCK` is at least [`ACCEPT_MIN`] (the slots of a shorter last
///    block past its particles holding residual 0): a try is a slot `t` uniform on the
///    [`BLOCK`] slots and `v ~ U[0, 1)`, accepted when `v < r_t`, so it accepts slot `t` with
///    probability `r_t / BLOCK` and an accepted slot is distributed as `r_t / S_b`; half a
///    64-bit draw per try (see [`draw_by_rejection`]). Tries are repeated until `M_b` are
///    accepted: on average at most `1 / ACCEPT_MIN` per draw, and since `E[M_b] = S_b` up
///    to rounding (the residuals sum to `m`), about `BLOCK` per block however the residuals
///    are spread: no cumulative sums, no table, no search. Below that acceptance (few
///    particles carry the block's residual, and it has few draws), each draw
///    `u ~ U[0, S_b)` is located in the block's cumulative residuals by binary search.
///
/// Together that is exactly a multinomial draw of `m` places from `r_i / sum r`, up to the
/// rounding of `S_b / S_left` (a relative error of order `eps S / S_left`) and the
/// granularity of the uniforms (`2^-74` for `v`, `2^-53` for `u`). Then every
/// particle's `floor(n w_i) + count_i` copies are written in index order. `weights` are the
/// particles `first..first + weights.len()` (the indices written are offset by `first`;
/// `sums` are theirs).
fn residual_blocks<R: Rng + ?Sized>(
    weights: &[f64],
    first: usize,
    scale: f64,
    sums: ResidualSums,
    rng: &mut R,
    out: &mut [usize],
) {
    let n = out.len();
    let mut m_left = (n - sums.copies) as u64;
    let mut s_left = sums.residual;
    let last_block = sums.last / BLOCK;
    let mut resid = [0.0f64; BLOCK];
    let mut coarse = [0u32; BLOCK];
    let mut count = [0u32; BLOCK];
    let mut pos = 0usize;
    for (b, chunk) in weights.chunks(BLOCK).enumerate() {
        let len = chunk.len();
        let sb = block_residuals(
            chunk,
            scale,
            &mut resid[..len],
            &mut coarse[..len],
            &mut count[..len],
        );
        let draws = share(b >= last_block, m_left, sb, s_left, rng);
        m_left -= draws;
        s_left -= sb;
        if draws > 0 {
            if sb >= ACCEPT_MIN * BLOCK as f64 {
                // a last, shorter block: its slots past the particles hold residual 0
                resid[len..].fill(0.0);
                coarse[len..].fill(0);
                draw_by_rejection(&resid, &coarse, draws, rng, &mut count);
            } else {
                draw_by_search(&mut resid[..len], draws, rng, &mut count[..len]);
            }
        }
        let base = first + b * BLOCK;
        for (s, &c) in count[..len].iter().enumerate() {
            let end = pos + c as usize;
            fill_run(out, pos, end, base + s);
            pos = end;
        }
    }
    debug_assert_eq!(pos, n);
}

/// Splits one block's `w_i scale` into copies (`count`) and residuals (`resid`), with each
/// residual's first [`COARSE`] binary digits (`coarse`: an integer `c` with
/// `r 2^COARSE - 1 <= c <= r 2^COARSE`, by the rounding of [`split`]), returning the residual
/// sum (in four interleaved partial sums, like [`residual_sums`]).
#[inline(always)]
fn block_residuals(
    chunk: &[f64],
    scale: f64,
    resid: &mut [f64],
    coarse: &mut [u32],
    count: &mut [u32],
) -> f64 {
    let len = chunk.len();
    let body = len - len % 4;
    let mut acc = [0.0f64; 4];
    let digits = (1u64 << COARSE) as f64;
    let one = |w: f64, r: &mut f64, c: &mut u32, n: &mut u32| {
        let (f, x) = split(w, scale);
        *r = x;
        *c = rounded((x * digits - 0.5) + ROUND) as u32;
        *n = f as u32;
        x
    };
    for (((q, rq), cq), nq) in chunk[..body]
        .chunks_exact(4)
        .zip(resid[..body].chunks_exact_mut(4))
        .zip(coarse[..body].chunks_exact_mut(4))
        .zip(count[..body].chunks_exact_mut(4))
    {
        for l in 0..4 {
            acc[l] += one(q[l], &mut rq[l], &mut cq[l], &mut nq[l]);
        }
    }
    for s in body..len {
        acc[0] += one(chunk[s], &mut resid[s], &mut coarse[s], &mut count[s]);
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

/// Binary digits of `v` compared per try in [`draw_by_rejection`]: with the 11 bits of a
/// slot, a 64-bit draw makes two tries.
const COARSE: u32 = 21;

/// `draws` i.i.d. draws from the residuals `resid` (each in `[0, 1)`, zero past the block's
/// particles; `coarse` their first [`COARSE`] digits), by rejection, each adding one to
/// `count` of its slot; see [`residual_blocks`].
///
/// Each half of a 64-bit draw is a try: its top 11 bits the slot `t` (`BLOCK = 2^11`), its
/// low [`COARSE`] bits the first digits `d` of `v in [0, 1)`. With `R = r_t 2^COARSE` and
/// `c = coarse[t]` (`R - 1 <= c <= R`), `v < r_t` is decided by `d < c` (accept) or `d > c`
/// (reject), and only for `d = c` (probability `2^-COARSE`) by the further digits `u` of `v`,
/// a fresh 53-bit uniform: `u < R - c` (exact in floating point). So each try accepts slot
/// `t` with probability `r_t / BLOCK` (to `2^-74`), as if `v` were drawn whole. Tries go in
/// pairs while two or more draws are left (both may be accepted), then one at a time.
#[inline]
fn draw_by_rejection<R: Rng + ?Sized>(
    resid: &[f64; BLOCK],
    coarse: &[u32; BLOCK],
    draws: u64,
    rng: &mut R,
    count: &mut [u32; BLOCK],
) {
    const _: () = assert!(BLOCK == 1 << (32 - COARSE));
    let mut placed = 0u64;
    let mut one = |h: u32, rng: &mut R| {
        let t = (h >> COARSE) as usize;
        let d = h & ((1 << COARSE) - 1);
        let c = coarse[t];
        let mut hit = d < c;
        if d == c {
            let u = (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
            hit = u < resid[t] * (1u64 << COARSE) as f64 - c as f64;
        }
        count[t] += u32::from(hit);
        u64::from(hit)
    };
    // in batches of `(draws - placed) / 2` pairs, which cannot place more than are left:
    // the same tries as checking before every pair, without the check
    loop {
        let pairs = (draws - placed) / 2;
        if pairs == 0 {
            break;
        }
        for _ in 0..pairs {
            let x = rng.next_u64();
            placed += one(x as u32, rng);
            placed += one((x >> 32) as u32, rng);
        }
    }
    while placed < draws {
        placed += one(rng.next_u64() as u32, rng);
    }
}

/// `draws` i.i.d. draws from the residuals `resid` (positive sum; turned into their
/// cumulative sums in place), each located by binary search and adding one to `count` of
/// its particle; a draw that rounding puts at or past the total selects the last positive
/// residual.
fn draw_by_search<R: Rng + ?Sized>(resid: &mut [f64], draws: u64, rng: &mut R, count: &mut [u32]) {
    let last = resid.iter().rposition(|&r| r > 0.0).unwrap_or(0);
    let mut c = 0.0f64;
    for r in resid.iter_mut() {
        c += *r;
        *r = c;
    }
    let cum = &*resid;
    let unit = c * (1.0 / (1u64 << 53) as f64);
    for _ in 0..draws {
        let u = (rng.next_u64() >> 11) as f64 * unit;
        count[search(cum, u, last)] += 1;
    }
}

/// Most parts of the residual pass; see [`part_count`].
const PARTS_MAX: usize = 16;

/// Fewest particles per part of the residual pass (a multiple of [`BLOCK`]).
const PART_MIN: usize = 1 << 16;

/// One part of the residual pass: the particles `start..end`, their weights' sum, their
/// totals, the number of remainder draws that fall in them and the seed of their generator.
#[derive(Debug, Clone, Copy, Default)]
struct Part {
    start: usize,
    end: usize,
    weight_sum: f64,
    sums: ResidualSums,
    draws: u64,
    seed: [u8; 32],
}

impl Part {
    /// Output slots of the part: its copies and its draws.
    fn slots(&self) -> usize {
        self.sums.copies + self.draws as usize
    }
}

/// How many parts the residual pass splits `len` particles into: 1 below
/// [`PARALLEL_MIN`], then one per [`PART_MIN`] particles, at most [`PARTS_MAX`]. It depends
/// on `len` alone, never on the number of threads, so the draws do not either.
fn part_count(len: usize) -> usize {
    if len < PARALLEL_MIN {
        1
    } else {
        (len / PART_MIN).clamp(2, PARTS_MAX)
    }
}

/// Checks the weights and returns their sum `W`, after cutting `0..len` into
/// `parts.len()` parts of equal size (a multiple of [`BLOCK`], the last one shorter).
///
/// One part: [`check_weights`] (the sequential sum). Several: each part's sum in four
/// interleaved partial sums (in parallel), added in part order; a fixed order that depends
/// on `len` alone, so `W` does not depend on the number of threads either. The residual
/// scheme needs `W` only as the scale `n / W`, not as the end point of the running sums
/// the merge schemes share. A negative, non-finite or all-zero input is reported by
/// [`check_weights`].
fn residual_total(weights: &[f64], parts: &mut [Part], n: usize) -> Result<f64> {
    let len = weights.len();
    if let [part] = parts {
        part.end = len;
        return Ok(check_weights(weights, n)?.total);
    }
    let size = len.div_ceil(parts.len()).div_ceil(BLOCK) * BLOCK;
    for (j, part) in parts.iter_mut().enumerate() {
        part.start = (j * size).min(len);
        part.end = ((j + 1) * size).min(len);
    }
    use rayon::prelude::*;
    parts.par_iter_mut().for_each(|p| {
        let mut s = [0.0f64; 4];
        // the least weight of each lane (a NaN makes the sum NaN instead)
        let mut least = [0.0f64; 4];
        let chunks = weights[p.start..p.end].chunks_exact(4);
        let rest = chunks.remainder();
        for q in chunks {
            for l in 0..4 {
                s[l] += q[l];
                least[l] = if q[l] < least[l] { q[l] } else { least[l] };
            }
        }
        for &v in rest {
            s[0] += v;
            least[0] = if v < least[0] { v } else { least[0] };
        }
        let negative = least.iter().any(|&v| v < 0.0);
        p.weight_sum = if negative {
            f64::NAN
        } else {
            (s[0] + s[1]) + (s[2] + s[3])
        };
    });
    let total: f64 = parts.iter().map(|p| p.weight_sum).sum();
    if total.is_finite() && scale_ok(total, n) {
        Ok(total)
    } else {
        // the error, located (or, should only this order of additions overflow, the
        // sequential sum)
        Ok(check_weights(weights, n)?.total)
    }
}

/// Fills in the parts' totals (in parallel when there are several; the parts cut by
/// [`residual_total`]), returning the totals of all particles: copies and residual sum
/// added in part order, `last` the last positive residual overall.
fn residual_part_sums(weights: &[f64], scale: f64, parts: &mut [Part]) -> ResidualSums {
    if let [part] = parts {
        part.sums = residual_sums(weights, scale);
        return part.sums;
    }
    use rayon::prelude::*;
    parts
        .par_iter_mut()
        .for_each(|p| p.sums = residual_sums(&weights[p.start..p.end], scale));
    let mut total = ResidualSums::default();
    for p in parts.iter() {
        total.copies += p.sums.copies;
        total.residual += p.sums.residual;
        if p.sums.residual > 0.0 {
            total.last = p.start + p.sums.last;
        }
    }
    total
}

/// Splits the `m` remainder draws over the parts as a multinomial's part totals, in part
/// order: `M_j ~ Binomial(m_left, S_j / S_left)` (`S_j` the part's residual sum, `m_left`
/// and `S_left` those of this part and the parts after it; the last part with a positive
/// residual takes all `m_left`), then gives each part a seed drawn from `rng`.
fn split_draws<R: Rng + ?Sized>(parts: &mut [Part], m: u64, residual: f64, rng: &mut R) {
    let last = parts
        .iter()
        .rposition(|p| p.sums.residual > 0.0)
        .unwrap_or(0);
    let mut m_left = m;
    let mut s_left = residual;
    for (j, part) in parts.iter_mut().enumerate() {
        let sj = part.sums.residual;
        part.draws = share(j >= last, m_left, sj, s_left, rng);
        m_left -= part.draws;
        s_left -= sj;
    }
    for part in parts.iter_mut() {
        rng.fill_bytes(&mut part.seed);
    }
}

/// Runs the parts into their consecutive output slots, halving the list under
/// `rayon::join`: each part's draws come from its own generator (xoshiro256++ from its
/// seed), so the indices are the same on any number of threads.
fn run_parts(weights: &[f64], scale: f64, parts: &[Part], out: &mut [usize]) {
    match parts {
        [] => {}
        [p] => {
            let w = &weights[p.start..p.end];
            if p.draws == 0 {
                write_copies_from(w, p.start, scale, out);
            } else {
                let mut rng = Xoshiro256PlusPlus::from_seed(p.seed);
                residual_blocks(w, p.start, scale, p.sums, &mut rng, out);
            }
        }
        _ => {
            let (left, right) = parts.split_at(parts.len() / 2);
            let (a, b) = out.split_at_mut(left.iter().map(Part::slots).sum());
            rayon::join(
                || run_parts(weights, scale, left, a),
                || run_parts(weights, scale, right, b),
            );
        }
    }
}

/// The four schemes as a configuration value.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Resampling {
    /// [`Residual`] (the MKPF paper's choice; default).
    #[default]
    Residual,
    /// [`Systematic`].
    Systematic,
    /// [`Stratified`].
    Stratified,
    /// [`Multinomial`].
    Multinomial,
}

impl Resampling {
    /// Every scheme, for tests and benchmarks that loop over them.
    pub const ALL: [Resampling; 4] = [
        Resampling::Residual,
        Resampling::Systematic,
        Resampling::Stratified,
        Resampling::Multinomial,
    ];
}

impl Resampler for Resampling {
    fn resample_into<R: Rng + ?Sized>(
        &self,
        weights: &[f64],
        rng: &mut R,
        out: &mut [usize],
    ) -> Result<()> {
        match self {
            Resampling::Residual => Residual.resample_into(weights, rng, out),
            Resampling::Systematic => Systematic.resample_into(weights, rng, out),
            Resampling::Stratified => Stratified.resample_into(weights, rng, out),
            Resampling::Multinomial => Multinomial.resample_into(weights, rng, out),
        }
    }
    fn name(&self) -> &'static str {
        match self {
            Resampling::Residual => Residual.name(),
            Resampling::Systematic => Systematic.name(),
            Resampling::Stratified => Stratified.name(),
            Resampling::Multinomial => Multinomial.name(),
        }
    }
}
