//! Stratified resampling with a generator: exactly the stratified definition for the
//! documented counter-based uniforms, independent strata, and the same indices on any
//! number of threads.

mod common;

use common::pool;
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trajpred_particle::{Resampler, Stratified, stratified_indices};

/// The documented uniforms: SplitMix64 at counter `j + 1` under the key (one `next_u64` of
/// the caller's generator), top 53 bits.
fn splitmix_uniforms(key: u64, n: usize) -> Vec<f64> {
    (0..n as u64)
        .map(|j| {
            let mut z = key.wrapping_add((j + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

/// The resampler equals the plain definition (`stratified_indices`, the merge of positions
/// `(j + u_j) / n` with the cumulative sums) for its uniforms, on one pass and on the split
/// pass, `n` equal to, below and above `N`.
#[test]
fn stratified_equals_the_definition_for_its_uniforms() {
    let mut wrng = ChaCha8Rng::seed_from_u64(11);
    for (len, n) in [
        (1000, 1000),
        (1000, 337),
        (700, 2500),
        (300_001, 300_001),
        (300_001, 140_000),
    ] {
        let w: Vec<f64> = (0..len)
            .map(|i| {
                if i % 7 == 3 {
                    0.0
                } else {
                    wrng.random::<f64>()
                }
            })
            .collect();
        for seed in 0..3 {
            let key = ChaCha8Rng::seed_from_u64(seed).next_u64();
            let mut expected = vec![0; n];
            stratified_indices(&w, &splitmix_uniforms(key, n), &mut expected).expect("def");
            for threads in [1, 2] {
                let got = pool(threads).install(|| {
                    Stratified
                        .resample(&w, n, &mut ChaCha8Rng::seed_from_u64(seed))
                        .expect("resample")
                });
                let diff = got.iter().zip(&expected).filter(|(a, b)| a != b).count();
                assert_eq!(diff, 0, "N {len} n {n} seed {seed} threads {threads}");
            }
        }
    }
}

/// Same seed, same indices on 1, 2 and 3 threads (the split pass from 2^17 on), sorted,
/// zero weights never picked.
#[test]
fn stratified_gives_the_same_indices_on_any_thread_count() {
    common::assert_same_indices_on_any_thread_count(&Stratified);
}

/// Independent strata: with two particles per stratum, `w_2j = f_j` and `w_2j+1 = 1 - f_j`
/// (dyadic, so `C_i n / W` is exact), particle `2j`'s count is `[u_j < f_j]`. Over seeded
/// runs: each count's mean within 5 standard errors of `f_j` (pooled per value of `f`), and
/// the variance of their sum within 15 % of `sum f_j (1 - f_j)`, which holds only if the
/// strata's uniforms are uncorrelated (shared or pairwise equal uniforms double it). On one
/// pass (4096 strata) and on the split pass (2^17 + 8 strata, two threads).
#[test]
fn stratified_strata_are_independent() {
    let fs = [0.125, 0.375, 0.5, 0.625, 0.875];
    for (strata, reps) in [(4096usize, 2000usize), ((1 << 17) + 8, 300)] {
        let f: Vec<f64> = (0..strata).map(|j| fs[(j * 7 + j / 5) % 5]).collect();
        let w: Vec<f64> = f.iter().flat_map(|&x| [x, 1.0 - x]).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let mut out = vec![0usize; strata];
        let mut hits = [0u64; 5];
        let mut trials = [0u64; 5];
        let (mut s1, mut s2) = (0.0f64, 0.0f64);
        pool(2).install(|| {
            for _ in 0..reps {
                Stratified
                    .resample_into(&w, &mut rng, &mut out)
                    .expect("resample");
                let mut counts = vec![0u8; 2 * strata];
                for &i in &out {
                    counts[i] += 1;
                }
                let mut sum = 0.0;
                for j in 0..strata {
                    let c = counts[2 * j];
                    assert!(c <= 1 && c + counts[2 * j + 1] == 1, "stratum {j}");
                    let v = fs.iter().position(|&x| x == f[j]).expect("f");
                    hits[v] += u64::from(c);
                    trials[v] += 1;
                    sum += f64::from(c);
                }
                s1 += sum;
                s2 += sum * sum;
            }
        });
        for v in 0..5 {
            let p = fs[v];
            let mean = hits[v] as f64 / trials[v] as f64;
            let se = (p * (1.0 - p) / trials[v] as f64).sqrt();
            assert!((mean - p).abs() < 5.0 * se, "f {p}: mean {mean}, se {se}");
        }
        let r = reps as f64;
        let var = (s2 - s1 * s1 / r) / (r - 1.0);
        let expected: f64 = f.iter().map(|p| p * (1.0 - p)).sum();
        assert!(
            (var / expected - 1.0).abs() < 0.15 * (2000.0 / r).sqrt(),
            "{strata} strata: variance of the sum {var}, expected {expected}"
        );
    }
}
