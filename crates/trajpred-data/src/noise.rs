//! Additive white Gaussian noise at a given signal-to-noise ratio (`docs/papers.md` E).
//!
//! Per axis, `σ² = mean(signal²) / 10^(SNR/10)` (SNR in dB, the signal's mean power about
//! zero, not about its mean), and independent `N(0, σ²)` noise is added to every value.
//! Randomness is injected, so a seeded generator reproduces a run exactly.
//!
//! ```
//! use rand::SeedableRng;
//! use trajpred_data::{noise::add_noise_snr, synthetic::gskf_eq20};
//! let clean = gskf_eq20();
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
//! let noisy = add_noise_snr(&clean, 20.0, &mut rng)?;
//! assert_eq!(noisy.times(), clean.times());
//! # Ok::<(), trajpred_data::Error>(())
//! ```

use crate::error::{Error, Result};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use trajpred_core::Trajectory;

/// The noise standard deviation for `signal` at `snr_db`:
/// `σ = sqrt(mean(signal²) / 10^(SNR/10))`. Zero for an empty or all-zero signal. Errors for
/// a non-finite SNR or a signal holding a non-finite value.
pub fn noise_sigma(signal: &[f64], snr_db: f64) -> Result<f64> {
    if !snr_db.is_finite() {
        return Err(Error::param(
            "snr_db",
            format!("must be finite, got {snr_db}"),
        ));
    }
    if signal.is_empty() {
        return Ok(0.0);
    }
    if let Some(i) = signal.iter().position(|v| !v.is_finite()) {
        return Err(Error::param(
            "signal",
            format!("non-finite value {} at index {i}", signal[i]),
        ));
    }
    let power = signal.iter().map(|v| v * v).sum::<f64>() / signal.len() as f64;
    let sigma = (power / 10f64.powf(snr_db / 10.0)).sqrt();
    if !sigma.is_finite() {
        return Err(Error::param(
            "snr_db",
            format!("{snr_db} dB gives a non-finite noise level"),
        ));
    }
    Ok(sigma)
}

/// `signal` plus white Gaussian noise at `snr_db` (see [`noise_sigma`]).
pub fn noisy_series<R: Rng + ?Sized>(signal: &[f64], snr_db: f64, rng: &mut R) -> Result<Vec<f64>> {
    let sigma = noise_sigma(signal, snr_db)?;
    Ok(signal
        .iter()
        .map(|&v| {
            let z: f64 = StandardNormal.sample(rng);
            v + sigma * z
        })
        .collect())
}

/// A copy of `trajectory` with white Gaussian noise at `snr_db` added to every axis, each
/// axis with its own `σ` (see [`noise_sigma`]); timestamps unchanged. Axes are drawn in
/// order, axis 0 first, all of its values before axis 1.
pub fn add_noise_snr<R: Rng + ?Sized>(
    trajectory: &Trajectory,
    snr_db: f64,
    rng: &mut R,
) -> Result<Trajectory> {
    let axes = trajectory
        .axes()
        .map(|a| noisy_series(a, snr_db, rng))
        .collect::<Result<Vec<_>>>()?;
    Ok(Trajectory::from_axes(trajectory.times().to_vec(), axes)?)
}
