//! Residual resampling, the MKPF paper's scheme, on a handful of weights: each particle is
//! kept `floor(N w_i)` times, and the places left are drawn from what remains,
//! `N w_i - floor(N w_i)`. The deterministic part is the same on every run; only the
//! remainder is random (seeded here).
//!
//! ```text
//! cargo run -p trajpred-particle --example residual_resampling -- [seed]
//! ```
//!
//! Prints the weights, the copies each particle must get (the floors), and the copies it got.
//! `tests/examples_run.rs` runs it and checks the floors are kept and the counts add up.
#![allow(clippy::print_stdout)]

use trajpred_particle::rand::SeedableRng;
use trajpred_particle::{Resampler, Residual, effective_sample_size};

/// The example's weights (not normalised: the resamplers normalise).
pub const WEIGHTS: [f64; 6] = [0.05, 0.4, 0.02, 0.25, 0.18, 0.10];

/// How many times each particle was drawn when `n` are resampled from [`WEIGHTS`].
pub fn run(seed: u64, n: usize) -> Result<Vec<usize>, Box<dyn std::error::Error>> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let ancestors = Residual.resample(&WEIGHTS, n, &mut rng)?;
    let mut copies = vec![0; WEIGHTS.len()];
    for a in ancestors {
        copies[a] += 1;
    }
    Ok(copies)
}

/// `floor(n w_i)`: the copies residual resampling guarantees.
pub fn floors(n: usize) -> Vec<usize> {
    let total: f64 = WEIGHTS.iter().sum();
    WEIGHTS
        .iter()
        .map(|w| (n as f64 * w / total).floor() as usize)
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let seed = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(1);
    let n = 20;
    let copies = run(seed, n)?;
    println!(
        "effective sample size of the weights: {:.2} of {}",
        effective_sample_size(&WEIGHTS)?,
        WEIGHTS.len()
    );
    println!("particle  weight  floor(N w)  copies (N = {n}, seed {seed})");
    for (i, ((w, f), c)) in WEIGHTS.iter().zip(floors(n)).zip(&copies).enumerate() {
        println!("{i:8}  {w:6.2}  {f:10}  {c:6}");
    }
    Ok(())
}
