//! Weights in log space: log-sum-exp normalisation, the effective sample size and the rule
//! that decides when to resample ([`ResamplePolicy`]).

use crate::error::{ParticleError, Result};
use trajpred_core::Error as CoreError;

/// Checks a log-weight: NaN and `+inf` are invalid, `-inf` (weight zero) is allowed.
fn check_log_weight(index: usize, value: f64) -> Result<()> {
    if value.is_nan() || value == f64::INFINITY {
        Err(ParticleError::InvalidWeight { index, value })
    } else {
        Ok(())
    }
}

/// `ln sum_i exp(l_i)`, computed stably as `m + ln sum_i exp(l_i - m)` with `m = max l_i`.
///
/// Returns `-inf` when every `l_i` is `-inf` (all weights zero). Errors:
/// [`trajpred_core::Error::Empty`], [`ParticleError::InvalidWeight`] for a NaN or `+inf`.
///
/// ```
/// use trajpred_particle::log_sum_exp;
/// // ln(e^1000 + e^1000) = 1000 + ln 2, without overflow
/// assert!((log_sum_exp(&[1000.0, 1000.0])? - (1000.0 + 2f64.ln())).abs() < 1e-12);
/// # Ok::<(), trajpred_particle::ParticleError>(())
/// ```
pub fn log_sum_exp(log_weights: &[f64]) -> Result<f64> {
    if log_weights.is_empty() {
        return Err(CoreError::Empty {
            what: "log-weights",
        }
        .into());
    }
    let mut max = f64::NEG_INFINITY;
    for (i, &l) in log_weights.iter().enumerate() {
        check_log_weight(i, l)?;
        if l > max {
            max = l;
        }
    }
    if max == f64::NEG_INFINITY {
        return Ok(f64::NEG_INFINITY);
    }
    let s: f64 = log_weights.iter().map(|&l| (l - max).exp()).sum();
    Ok(max + s.ln())
}

/// Normalises log-weights in place so that `sum_i exp(l_i) = 1`, and returns the log of
/// their previous total, `ln sum_i exp(l_i)` (for a particle filter: the log-likelihood
/// increment `ln p(z_k | z_1:k-1)` when the weights were normalised before the update).
///
/// Errors: [`trajpred_core::Error::Empty`], [`ParticleError::InvalidWeight`],
/// [`ParticleError::AllWeightsZero`] when every log-weight is `-inf` (the weights are then
/// left untouched).
pub fn normalize_log_weights(log_weights: &mut [f64]) -> Result<f64> {
    let total = log_sum_exp(log_weights)?;
    if total == f64::NEG_INFINITY {
        return Err(ParticleError::AllWeightsZero {
            count: log_weights.len(),
        });
    }
    for l in log_weights.iter_mut() {
        *l -= total;
    }
    Ok(total)
}

/// Writes the normalised linear weights `exp(l_i - lse(l))` into `out` (no allocation).
///
/// Errors: as [`normalize_log_weights`], and [`trajpred_core::Error::LengthMismatch`].
pub fn weights_from_log_into(log_weights: &[f64], out: &mut [f64]) -> Result<()> {
    if out.len() != log_weights.len() {
        return Err(CoreError::LengthMismatch {
            what: "weights buffer vs log-weights",
            expected: log_weights.len(),
            got: out.len(),
        }
        .into());
    }
    let total = log_sum_exp(log_weights)?;
    if total == f64::NEG_INFINITY {
        return Err(ParticleError::AllWeightsZero {
            count: log_weights.len(),
        });
    }
    for (o, &l) in out.iter_mut().zip(log_weights) {
        *o = (l - total).exp();
    }
    Ok(())
}

/// The effective sample size `(sum w_i)^2 / sum w_i^2` of linear weights (normalised
/// internally; `1 / sum w_i^2` for normalised weights): `N` for equal weights, 1 when one
/// particle holds all the weight.
///
/// Errors: [`trajpred_core::Error::Empty`], [`ParticleError::InvalidWeight`] (negative or
/// non-finite), [`ParticleError::AllWeightsZero`].
pub fn effective_sample_size(weights: &[f64]) -> Result<f64> {
    if weights.is_empty() {
        return Err(CoreError::Empty { what: "weights" }.into());
    }
    let mut max = 0.0f64;
    for (index, &value) in weights.iter().enumerate() {
        if !(value.is_finite() && value >= 0.0) {
            return Err(ParticleError::InvalidWeight { index, value });
        }
        max = max.max(value);
    }
    if max == 0.0 {
        return Err(ParticleError::AllWeightsZero {
            count: weights.len(),
        });
    }
    // scale by the largest weight so that neither sum overflows nor underflows
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for &w in weights {
        let v = w / max;
        s += v;
        s2 += v * v;
    }
    Ok(s * s / s2)
}

/// The effective sample size of log-weights: `exp(2 lse(l) - lse(2 l))`, computed in log
/// space (no underflow for very small weights).
///
/// Errors: as [`log_sum_exp`], and [`ParticleError::AllWeightsZero`].
pub fn effective_sample_size_log(log_weights: &[f64]) -> Result<f64> {
    let total = log_sum_exp(log_weights)?;
    if total == f64::NEG_INFINITY {
        return Err(ParticleError::AllWeightsZero {
            count: log_weights.len(),
        });
    }
    let mut s2 = 0.0f64;
    for &l in log_weights {
        let v = (l - total).exp();
        s2 += v * v;
    }
    Ok(1.0 / s2)
}

/// When a particle filter resamples after weighting.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ResamplePolicy {
    /// After every step (the MKPF paper, `docs/papers.md` C.1). Default.
    #[default]
    Always,
    /// When the effective sample size falls below `fraction * N` (`fraction` in `[0, 1]`;
    /// 0.5 is the common choice).
    EssBelow(f64),
    /// Never (sequential importance sampling without resampling; weights degenerate).
    Never,
}

impl ResamplePolicy {
    /// Checks the fraction of [`ResamplePolicy::EssBelow`]: finite and in `[0, 1]`.
    pub fn validate(&self) -> Result<()> {
        match *self {
            ResamplePolicy::EssBelow(f) if !(f.is_finite() && (0.0..=1.0).contains(&f)) => {
                Err(CoreError::InvalidParameter {
                    name: "ess fraction",
                    reason: format!("must be in [0, 1], got {f}"),
                }
                .into())
            }
            _ => Ok(()),
        }
    }

    /// Whether to resample `n` particles whose effective sample size is `ess`.
    pub fn should_resample(&self, ess: f64, n: usize) -> bool {
        match *self {
            ResamplePolicy::Always => true,
            ResamplePolicy::EssBelow(f) => ess < f * n as f64,
            ResamplePolicy::Never => false,
        }
    }
}
