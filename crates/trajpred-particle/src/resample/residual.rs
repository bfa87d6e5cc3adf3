//! Residual resampling: `floor(n w_i)` copies, the remainder multinomial from the residuals;
//! the split into parts run in parallel.

use super::Resampler;
use super::blocks::residual_blocks;
use super::common::*;
use super::multinomial::sorted_multinomial;
use crate::error::Result;
use rand::rngs::Xoshiro256PlusPlus;
use rand::{Rng, SeedableRng};
use rand_distr::Distribution;
use trajpred_core::Error as CoreError;

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
        return Err(CoreError::LengthMismatch {
            what: "uniforms vs remainder draws",
            expected: m,
            got: uniforms.len(),
        }
        .into());
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
pub(super) fn write_copies(weights: &[f64], scale: f64, out: &mut [usize]) -> (usize, f64, usize) {
    write_copies_from(weights, 0, scale, out)
}

/// [`write_copies`] for the particles `first..first + weights.len()` (the indices written are
/// offset by `first`; the returned last index is relative to `first`).
#[inline]
pub(super) fn write_copies_from(
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

pub(super) fn fill_with_largest(weights: &[f64], out: &mut [usize]) {
    let mut best = 0;
    for (i, &w) in weights.iter().enumerate() {
        if w > weights[best] {
            best = i;
        }
    }
    out.fill(best);
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
        with_parts(weights, n, |parts, total| {
            resample_scaled(weights, parts, n as f64 / total, rng, out);
        })
    }
    fn name(&self) -> &'static str {
        "residual"
    }
}

/// The residual scheme at a given `scale` (the parts cut and the weights checked by
/// [`residual_total`]): `floor(w_i scale)` copies of each particle, the other
/// `n - sum floor(w_i scale)` places drawn multinomially from the residuals
/// `w_i scale - floor(w_i scale)`, sorted. Residual resampling takes `scale = n / W`;
/// multinomial resampling takes a scale below `1 / max w_i`, so that there are no copies and
/// the residuals are proportional to the weights.
pub(super) fn resample_scaled<R: Rng + ?Sized>(
    weights: &[f64],
    parts: &mut [Part],
    scale: f64,
    rng: &mut R,
    out: &mut [usize],
) {
    let n = out.len();
    let sums = residual_part_sums(weights, scale, parts);
    if sums.copies >= n {
        // no remainder (or, by rounding, copies for more than n places: clamped)
        write_copies(weights, scale, out);
        return;
    }
    if sums.residual <= 0.0 {
        let (k, _, _) = write_copies(weights, scale, out);
        fill_with_largest(weights, &mut out[k..]);
        return;
    }
    if u32::try_from(n).is_err() {
        // beyond the block counts' range: copies, then the sorted-uniform remainder
        let (k, s, last) = write_copies(weights, scale, out);
        let residual = |i: usize| split(weights[i], scale).1;
        sorted_multinomial(rng, residual, weights.len(), s, last, &mut out[k..]);
        return;
    }
    if let [_] = parts {
        residual_blocks(weights, 0, scale, sums, rng, out);
    } else {
        split_draws(parts, (n - sums.copies) as u64, sums.residual, rng);
        run_parts(weights, scale, parts, out);
    }
}

/// Particles per block of [`residual_blocks`] (its three per-block arrays, 32 KiB, live on
/// the stack and stay in the first-level cache): `2^11`, the slot bits of a try in
/// [`draw_by_rejection`].
pub(super) const BLOCK: usize = 2048;

/// Lowest acceptance for which [`residual_blocks`] draws a block's remainder by rejection.
pub(super) const ACCEPT_MIN: f64 = 0.25;

/// Totals of the residual scheme: the copies `sum_i floor(w_i scale)`, the residual sum
/// (in four interleaved partial sums: its rounding differs from the blocks' sequential sums
/// by a relative `O(N eps)`, which only moves the blocks' binomial probabilities by as
/// much) and the index of the last positive residual.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct ResidualSums {
    pub(super) copies: usize,
    pub(super) residual: f64,
    pub(super) last: usize,
}

/// `(floor(x), x - floor(x))` for `x = w scale`, `0 <= x < 2^51`, without a conversion
/// instruction (Rust's saturating `as` costs a compare and a branch per value) and without
/// a data-dependent branch: `x` is rounded to the nearest integer `f` by adding [`ROUND`],
/// and where `f > x` (rounded up, which needs `x >= 1/2`) the floor is `f - 1` and the
/// fraction `x - f + 1`. Both are exact: `x - f` is a multiple of the last place of `x`
/// below 1/2 in magnitude, and `x - f + 1` lies in `[1/2, 1)` where the spacing of doubles
/// (`2^-53`) divides the last place of `x >= 1/2`.
#[inline(always)]
pub(super) fn split(w: f64, scale: f64) -> (usize, f64) {
    let x = w * scale;
    let y = x + ROUND;
    let f = y - ROUND;
    let up = f > x;
    (
        rounded(y).wrapping_sub(usize::from(up)),
        (x - f) + if up { 1.0 } else { 0.0 },
    )
}

pub(super) fn residual_sums(weights: &[f64], scale: f64) -> ResidualSums {
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
pub(super) fn share<R: Rng + ?Sized>(
    last: bool,
    m_left: u64,
    s: f64,
    s_left: f64,
    rng: &mut R,
) -> u64 {
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

/// Most parts of the residual pass; see [`part_count`].
pub(super) const PARTS_MAX: usize = 16;

/// Fewest particles per part of the residual pass (a multiple of [`BLOCK`]).
pub(super) const PART_MIN: usize = 1 << 16;

/// One part of the residual pass: the particles `start..end`, their weights' sum, their
/// totals, the number of remainder draws that fall in them and the seed of their generator.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Part {
    start: usize,
    end: usize,
    weight_sum: f64,
    /// The largest weight of the part (filled in with `weight_sum`).
    pub(super) max: f64,
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
pub(super) fn part_count(len: usize) -> usize {
    if len < PARALLEL_MIN {
        1
    } else {
        (len / PART_MIN).clamp(2, PARTS_MAX)
    }
}

/// The start both the residual and the multinomial scheme share: checks `weights`, cuts them
/// into [`part_count`] parts and sums them ([`residual_total`]), then hands the parts and
/// the total `W` to `then`.
pub(super) fn with_parts<T>(
    weights: &[f64],
    n: usize,
    then: impl FnOnce(&mut [Part], f64) -> T,
) -> Result<T> {
    let mut parts = [Part::default(); PARTS_MAX];
    let parts = &mut parts[..part_count(weights.len())];
    let total = residual_total(weights, parts, n)?;
    Ok(then(parts, total))
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
pub(super) fn residual_total(weights: &[f64], parts: &mut [Part], n: usize) -> Result<f64> {
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
        let mut most = [0.0f64; 4];
        let chunks = weights[p.start..p.end].chunks_exact(4);
        let rest = chunks.remainder();
        for q in chunks {
            for l in 0..4 {
                s[l] += q[l];
                least[l] = if q[l] < least[l] { q[l] } else { least[l] };
                most[l] = if q[l] > most[l] { q[l] } else { most[l] };
            }
        }
        for &v in rest {
            s[0] += v;
            least[0] = if v < least[0] { v } else { least[0] };
            most[0] = if v > most[0] { v } else { most[0] };
        }
        let negative = least.iter().any(|&v| v < 0.0);
        p.max = most.iter().fold(0.0, |a, &b| if b > a { b } else { a });
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
pub(super) fn residual_part_sums(weights: &[f64], scale: f64, parts: &mut [Part]) -> ResidualSums {
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
pub(super) fn split_draws<R: Rng + ?Sized>(parts: &mut [Part], m: u64, residual: f64, rng: &mut R) {
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
pub(super) fn run_parts(weights: &[f64], scale: f64, parts: &[Part], out: &mut [usize]) {
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
            // `rayon::join`, not `join_here`: the parts recurse, and from outside the pool
            // `join_here` would run the caller's thread beside both workers (three threads
            // on two cores; measured slower, docs/particle.md)
            rayon::join(
                || run_parts(weights, scale, left, a),
                || run_parts(weights, scale, right, b),
            );
        }
    }
}
