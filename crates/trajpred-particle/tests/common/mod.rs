//! Helpers shared by the resampling test files.
#![allow(dead_code)]

use trajpred_particle::Resampler;

/// A rayon pool of `threads` threads, to run a resampler on a given thread count.
pub fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
}

/// Every scheme with its name.
pub fn schemes() -> Vec<(&'static str, trajpred_particle::Resampling)> {
    trajpred_particle::Resampling::ALL
        .iter()
        .map(|r| (r.name(), *r))
        .collect()
}
