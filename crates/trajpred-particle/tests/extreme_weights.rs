//! Extreme weights (subnormal, zero, huge) in every resampler, serial and parallel: a typed
//! error or valid indices (`n` of them, each in range and of a positive weight), never a
//! panic.
//!
//! The cause of the old failure: the residual and systematic schemes scale the weights by
//! `n / W`; with a subnormal total `W` (or any `W < n / f64::MAX`) that scale is infinite,
//! `w * scale` is infinite or NaN, and the counts read from its bits were garbage (wrong
//! indices in release, an arithmetic overflow panic in debug). Such weights now give
//! `ParticleError::AllWeightsZero` (they have underflowed) at entry.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trajpred_core::Error as CoreError;
use trajpred_particle::{
    ParticleError, Resampler, Resampling, multinomial_indices, residual_indices,
    stratified_indices, systematic_indices,
};

/// Every way of resampling `weights` into `n` slots: the four schemes through the trait and
/// the four functions that take uniforms. Each entry: name and result.
fn every_scheme(
    weights: &[f64],
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<(String, Result<Vec<usize>, ParticleError>)> {
    let mut out = Vec::new();
    for r in Resampling::ALL {
        out.push((r.name().to_string(), r.resample(weights, n, rng)));
    }
    let u: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
    let mut o = vec![0; n];
    out.push((
        "systematic_indices".into(),
        systematic_indices(weights, u.first().copied().unwrap_or(0.5), &mut o).map(|_| o.clone()),
    ));
    out.push((
        "stratified_indices".into(),
        stratified_indices(weights, &u, &mut o).map(|_| o.clone()),
    ));
    out.push((
        "multinomial_indices".into(),
        multinomial_indices(weights, &u, &mut o).map(|_| o.clone()),
    ));
    out.push((
        "residual_indices".into(),
        residual_indices(weights, &u, &mut o).map(|_| o.clone()),
    ));
    out
}

/// The property: a typed error, or `n` indices each of a positive weight.
#[track_caller]
fn assert_valid(weights: &[f64], n: usize, name: &str, res: &Result<Vec<usize>, ParticleError>) {
    match res {
        Ok(idx) => {
            assert_eq!(idx.len(), n, "{name}");
            for &i in idx {
                assert!(i < weights.len(), "{name}: index {i} of {}", weights.len());
                assert!(
                    weights[i] > 0.0,
                    "{name}: index {i} has weight {}",
                    weights[i]
                );
            }
        }
        Err(
            ParticleError::AllWeightsZero { .. }
            | ParticleError::Core(CoreError::NonFinite { .. })
            | ParticleError::InvalidWeight { .. }
            | ParticleError::Core(CoreError::Empty { .. }),
        ) => {}
        Err(e) => panic!("{name}: unexpected error {e:?}"),
    }
}

/// Runs `f` on a rayon pool of `threads` threads.
fn on_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Subnormal weights (all of them, or one among zeros): `AllWeightsZero`, from every scheme.
#[test]
fn subnormal_total_weight_is_all_weights_zero() {
    let tiny = f64::from_bits(1); // 4.9e-324
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let cases: Vec<Vec<f64>> = vec![
        vec![tiny; 10],
        vec![0.0, 0.0, tiny, 0.0],
        vec![f64::MIN_POSITIVE / 4.0; 3],
        vec![tiny],
    ];
    for w in &cases {
        for n in [1, 7, 100] {
            for (name, res) in every_scheme(w, n, &mut rng) {
                assert!(
                    matches!(res, Err(ParticleError::AllWeightsZero { count }) if count == w.len()),
                    "{name}, n = {n}, weights {w:?}: {res:?}"
                );
            }
        }
    }
}

/// A normal total too small for `n` slots (`n / W` overflows): the same error; one slot
/// fewer zeros in `n` and the weights are usable.
#[test]
fn total_below_n_over_max_is_all_weights_zero() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let w = [1e-305, 0.0, 1e-305];
    for (name, res) in every_scheme(&w, 100_000, &mut rng) {
        assert!(
            matches!(res, Err(ParticleError::AllWeightsZero { count: 3 })),
            "{name}: {res:?}"
        );
    }
    for (name, res) in every_scheme(&w, 100, &mut rng) {
        assert_valid(&w, 100, &name, &res);
        assert!(res.is_ok(), "{name}: {res:?}");
    }
}

/// The parallel paths (from 2^17 particles and slots): subnormal weights are refused on one
/// thread and on four alike; small normal weights give valid indices on both.
#[test]
fn parallel_paths_with_extreme_weights() {
    let len = 1 << 18;
    let tiny = f64::from_bits(3);
    let subnormal = vec![tiny; len];
    let mut small: Vec<f64> = (0..len)
        .map(|i| if i % 3 == 0 { 0.0 } else { 1e-290 })
        .collect();
    small[7] = 1e-250;
    for threads in [1, 4] {
        let (a, b) = on_pool(threads, || {
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            (
                every_scheme(&subnormal, len, &mut rng),
                every_scheme(&small, len, &mut rng),
            )
        });
        for (name, res) in a {
            assert!(
                matches!(res, Err(ParticleError::AllWeightsZero { .. })),
                "{threads} threads, {name}: {res:?}"
            );
        }
        for (name, res) in &b {
            assert_valid(&small, len, name, res);
            assert!(res.is_ok(), "{threads} threads, {name}");
        }
    }
}

/// Huge weights: a sum that overflows is `NonFinite`; huge weights whose sum is finite give
/// valid indices.
#[test]
fn huge_weights() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let w = [f64::MAX, f64::MAX, 1.0];
    for (name, res) in every_scheme(&w, 10, &mut rng) {
        assert!(
            matches!(res, Err(ParticleError::Core(CoreError::NonFinite { .. }))),
            "{name}: {res:?}"
        );
    }
    let w = [
        f64::MAX / 4.0,
        0.0,
        f64::MAX / 2.0,
        f64::MIN_POSITIVE,
        tiny_subnormal(),
    ];
    for (name, res) in every_scheme(&w, 50, &mut rng) {
        assert_valid(&w, 50, &name, &res);
        assert!(res.is_ok(), "{name}: {res:?}");
    }
}

fn tiny_subnormal() -> f64 {
    f64::from_bits(1)
}

/// A weight drawn from the extremes: zero, subnormal, tiny normal, ordinary, huge.
fn extreme_weight(rng: &mut ChaCha8Rng, len: usize) -> f64 {
    match rng.random_range(0..8u32) {
        0 | 1 => 0.0,
        2 => f64::from_bits(rng.random_range(1..(1u64 << 52))),
        3 => f64::MIN_POSITIVE * rng.random_range(1.0..1e6),
        4 => 10f64.powi(rng.random_range(-300..-200)),
        5 => rng.random::<f64>(),
        6 => 10f64.powi(rng.random_range(200..300)),
        _ => f64::MAX / (len as f64) * rng.random::<f64>(),
    }
}

/// The property over random weight vectors mixing zeros, subnormals, tiny, ordinary and huge
/// values (and all-of-one-kind vectors): every scheme gives a typed error or valid indices,
/// never a panic. 3000 seeded cases.
#[test]
fn property_typed_error_or_valid_indices() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for case in 0..3000 {
        let len = rng.random_range(1..40usize);
        let n = rng.random_range(0..200usize);
        let uniform_kind = case % 5 == 0;
        let first = extreme_weight(&mut rng, len);
        let w: Vec<f64> = (0..len)
            .map(|_| {
                if uniform_kind {
                    first
                } else {
                    extreme_weight(&mut rng, len)
                }
            })
            .collect();
        for (name, res) in every_scheme(&w, n, &mut rng) {
            assert_valid(&w, n, &format!("case {case} {name} n {n} w {w:?}"), &res);
        }
    }
}
