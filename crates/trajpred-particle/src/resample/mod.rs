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
//! stratified scheme runs as counts per particle (`floor(x_i) + [u < frac(x_i)]` with
//! `x_i = C_i n / W` and `u` the uniform of stratum `floor(x_i)`, computed from a key by
//! SplitMix64, so any thread can compute it), split in two halves like the systematic one.
//! The multinomial scheme is the residual scheme's remainder sampler with no copies (at a
//! scale below `1 / max w_i` each `w_i` is its own residual). The residual scheme draws its remainder per block of
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

mod blocks;
mod common;
mod multinomial;
mod residual;
mod stratified;
mod systematic;

pub use multinomial::{Multinomial, multinomial_indices};
pub use residual::{Residual, residual_indices};
pub use stratified::{Stratified, stratified_indices};
pub use systematic::{Systematic, systematic_indices};

use crate::error::Result;
use rand::Rng;

/// A resampling scheme: from weights, draw ancestor indices.
pub trait Resampler {
    /// Writes `out.len()` ancestor indices drawn according to `weights` (non-negative, not
    /// necessarily normalised) into `out`, without allocating.
    ///
    /// Errors: [`trajpred_core::Error::Empty`] (no weights), [`ParticleError::InvalidWeight`](crate::ParticleError::InvalidWeight)
    /// (negative or non-finite), [`ParticleError::AllWeightsZero`](crate::ParticleError::AllWeightsZero) (also for weights that
    /// underflowed: a total that is subnormal or below `n / f64::MAX`),
    /// [`trajpred_core::Error::NonFinite`] (the sum of the weights overflows).
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
