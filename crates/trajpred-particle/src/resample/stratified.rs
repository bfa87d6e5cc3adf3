//! Stratified resampling: one uniform per stratum.

use super::Resampler;
use super::common::*;
use crate::error::{ParticleError, Result};
use rand::{Rng, RngExt};

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
