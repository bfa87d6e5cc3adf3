//! Multinomial resampling with a generator: the counts have the multinomial law (means,
//! variances, the covariance between groups), on one pass and over parts run in parallel,
//! and the same indices on any number of threads.

mod common;

use common::pool;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use trajpred_particle::{Multinomial, Resampler};

/// Counts per particle of `reps` seeded multinomial resamplings of `w` into `n` places:
/// their sums and sums of squares, and those of the group count `A` (particles below
/// `len / 2`).
fn counts(w: &[f64], n: usize, reps: usize, seed: u64) -> (Vec<f64>, Vec<f64>, f64, f64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = vec![0usize; n];
    let mut c = vec![0u32; w.len()];
    let mut s1 = vec![0.0f64; w.len()];
    let mut s2 = vec![0.0f64; w.len()];
    let (mut a1, mut a2) = (0.0, 0.0);
    for _ in 0..reps {
        Multinomial
            .resample_into(w, &mut rng, &mut out)
            .expect("multinomial");
        assert!(out.windows(2).all(|p| p[0] <= p[1]), "sorted");
        c.fill(0);
        for &i in &out {
            c[i] += 1;
        }
        let mut a = 0.0;
        for (i, &k) in c.iter().enumerate() {
            let k = f64::from(k);
            s1[i] += k;
            s2[i] += k * k;
            if i < w.len() / 2 {
                a += k;
            }
        }
        a1 += a;
        a2 += a * a;
    }
    (s1, s2, a1, a2)
}

/// Multinomial counts `K_i` of `n` draws with `p_i = w_i / W`: `E[K_i] = n p_i`,
/// `Var[K_i] = n p_i (1 - p_i)`, and for the groups `A` (first half of the particles,
/// probability `P`): `Var[A] = n P (1 - P)` (so `Cov[A, n - A] = -n P (1 - P)`).
/// Checked over `reps` runs: the chi-square of the means
/// `sum_i (mean_i - n p_i)^2 / (n p_i (1 - p_i) / reps)` within `6 sqrt(2 d)` of its `d`
/// degrees of freedom; the sum of the variances within 4 % of `n (1 - sum p_i^2)` (a
/// systematic or stratified draw, at most 1/4 per particle, fails it); `Var[A]` within
/// `15 % sqrt(2000 / reps)` (4.7 standard deviations) of `n P (1 - P)` (a draw whose blocks or parts got fixed instead of binomial totals fails
/// it); zero weights never drawn.
fn assert_multinomial(w: &[f64], reps: usize, seed: u64) {
    let n = w.len();
    let (s1, s2, a1, a2) = counts(w, n, reps, seed);
    let total: f64 = w.iter().sum();
    let r = reps as f64;
    let nf = n as f64;
    let (mut stat, mut d, mut sum_var, mut sum_p2) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..n {
        let p = w[i] / total;
        if p == 0.0 {
            assert_eq!(s1[i], 0.0, "zero weight {i} drawn");
            continue;
        }
        let mean = s1[i] / r;
        let var = (s2[i] / r - mean * mean) * r / (r - 1.0);
        let e = nf * p;
        stat += (mean - e).powi(2) / (e * (1.0 - p) / r);
        d += 1.0;
        sum_var += var;
        sum_p2 += p * p;
    }
    assert!(
        (stat - d).abs() < 6.0 * (2.0 * d).sqrt(),
        "chi-square {stat} on {d} degrees of freedom"
    );
    let expected = nf * (1.0 - sum_p2);
    assert!(
        (sum_var / expected - 1.0).abs() < 0.04,
        "sum of variances {sum_var}, multinomial {expected}"
    );
    let p_a: f64 = w[..n / 2].iter().sum::<f64>() / total;
    let mean_a = a1 / r;
    let var_a = (a2 / r - mean_a * mean_a) * r / (r - 1.0);
    let v = nf * p_a * (1.0 - p_a);
    assert!(
        (mean_a - nf * p_a).abs() < 5.0 * (v / r).sqrt(),
        "group mean {mean_a}"
    );
    assert!(
        (var_a / v - 1.0).abs() < 0.15 * (2000.0 / r).sqrt(),
        "group variance {var_a}, multinomial {v}"
    );
}

/// One pass (fewer than 2^17 weights), three shapes: i.i.d. uniform weights with zeros
/// (blocks drawn by rejection), log-normal weights of log-sd 3 (most blocks far below the
/// largest weight: drawn by search) and one dominant weight among small ones.
#[test]
fn multinomial_counts_are_multinomial() {
    let mut wrng = ChaCha8Rng::seed_from_u64(7);
    let uniform: Vec<f64> = (0..5000)
        .map(|i| {
            if i % 9 == 4 {
                0.0
            } else {
                wrng.random::<f64>()
            }
        })
        .collect();
    assert_multinomial(&uniform, 2000, 1);
    let lognormal: Vec<f64> = (0..5000)
        .map(|_| {
            let z: f64 = StandardNormal.sample(&mut wrng);
            (3.0 * z).exp()
        })
        .collect();
    assert_multinomial(&lognormal, 2000, 2);
    let mut dominant = vec![1.0; 3000];
    dominant[1777] = 3000.0;
    assert_multinomial(&dominant, 2000, 3);
}

/// Over parts (2^18 weights, parts run on two threads): the same checks, fewer runs.
#[test]
fn multinomial_over_parts_is_multinomial() {
    let mut wrng = ChaCha8Rng::seed_from_u64(8);
    let w: Vec<f64> = (0..1 << 18)
        .map(|i| {
            // the first quarter carries a third of the mass per particle
            let u: f64 = wrng.random();
            if i < 1 << 16 { u / 3.0 } else { u }
        })
        .collect();
    pool(2).install(|| assert_multinomial(&w, 200, 4));
}

/// Same seed, same indices on 1, 2 and 3 threads, zero weights never drawn.
#[test]
fn multinomial_gives_the_same_indices_on_any_thread_count() {
    common::assert_same_indices_on_any_thread_count(&Multinomial);
}
