//! Helpers shared by the resampling test files.
#![allow(dead_code)]

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
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

/// Draws `n` indices from `w` with `scheme` on 1, 2 and 3 threads (seed 9) and checks they
/// are the same, sorted, and never a zero weight's, over 2^18 + 3 seeded weights (every fifth
/// zero) and three output sizes around the parallel threshold.
pub fn assert_same_indices_on_any_thread_count<S: Resampler + Sync>(scheme: &S) {
    let len = (1 << 18) + 3;
    let mut wrng = ChaCha8Rng::seed_from_u64(5);
    let w: Vec<f64> = (0..len)
        .map(|i| {
            if i % 5 == 0 {
                0.0
            } else {
                wrng.random::<f64>()
            }
        })
        .collect();
    for n in [len, (1 << 17) + 3, 2 * len] {
        let run = |threads: usize| {
            pool(threads).install(|| {
                scheme
                    .resample(&w, n, &mut ChaCha8Rng::seed_from_u64(9))
                    .expect("resample")
            })
        };
        let one = run(1);
        assert!(one.windows(2).all(|p| p[0] <= p[1]), "sorted, n {n}");
        assert!(one.iter().all(|&i| w[i] > 0.0), "zero weight drawn, n {n}");
        assert!(run(2) == one, "2 threads, n {n}");
        assert!(run(3) == one, "3 threads, n {n}");
    }
}
