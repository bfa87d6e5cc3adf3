//! Multinomial resampling: i.i.d. draws, as sorted uniforms merged with the weights.

use super::Resampler;
use super::common::*;
use super::residual::{resample_scaled, with_parts};
use crate::error::Result;
use rand::Rng;
use rand_distr::{Distribution, Exp1};
use trajpred_core::Error as CoreError;

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
        return Err(CoreError::LengthMismatch {
            what: "uniforms vs output",
            expected: out.len(),
            got: uniforms.len(),
        }
        .into());
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

/// Fills `buf` with the bit patterns of `m = buf.len()` sorted uniforms scaled to
/// `[0, scale)`: `scale * (E_1 + ... + E_j) / (E_1 + ... + E_(m+1))` with `E ~ Exp(1)` i.i.d.
/// (the joint law of the order statistics of `m` i.i.d. uniforms).
pub(super) fn sorted_uniform_bits<R: Rng + ?Sized>(rng: &mut R, buf: &mut [u64], scale: f64) {
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
pub(super) fn sorted_multinomial<R: Rng + ?Sized>(
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
pub(super) fn sorted_multinomial_in_place<R: Rng + ?Sized>(
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

/// Multinomial resampling: `n` i.i.d. draws from the weights (the indices are returned in
/// sorted order; the counts have the multinomial law).
///
/// Drawn by the residual scheme's remainder sampler with no copies: at a scale
/// `s < 1 / max w_i` every `w_i s` is its own residual, so the `n` places are drawn
/// multinomially from `w_i s / sum_k w_k s = w_i / W` (binomial part and block totals, then
/// rejection or search within a block; see [`Residual`](super::Residual)), in parallel from
/// `2^17` weights with the same indices on any number of threads. Weights whose largest is
/// subnormal (where `1 / max w_i` overflows) take the sorted uniforms of exponential
/// spacings, merged with the cumulative weights, instead.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Multinomial;

impl Resampler for Multinomial {
    fn resample_into<R: Rng + ?Sized>(
        &self,
        weights: &[f64],
        rng: &mut R,
        out: &mut [usize],
    ) -> Result<()> {
        with_parts(weights, out.len(), |parts, total| {
            let most = match parts {
                [_] => weights
                    .iter()
                    .fold(0.0f64, |a, &w| if w > a { w } else { a }),
                _ => parts.iter().fold(0.0f64, |a, p| p.max.max(a)),
            };
            // below 1 / max w_i (by more than its rounding): every w_i scale is in [0, 1)
            let scale = (1.0 - f64::EPSILON * 64.0) / most;
            if scale.is_finite() {
                resample_scaled(weights, parts, scale, rng, out);
            } else {
                // a subnormal largest weight: the sorted uniforms, at the weights' own scale
                let last = weights.iter().rposition(|&w| w > 0.0).unwrap_or(0);
                sorted_multinomial(rng, |i| weights[i], weights.len(), total, last, out);
            }
        })
    }
    fn name(&self) -> &'static str {
        "multinomial"
    }
}
