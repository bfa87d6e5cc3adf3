//! Every resampler with a generator: unbiased counts over seeded repetitions, the counts'
//! structural bounds, same seed same indices, the edges, and every error variant.

mod common;

use common::schemes;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trajpred_particle::{Multinomial, Resampler, Resampling, Residual, Stratified, Systematic};

/// Unbiasedness: over R = 20000 seeded repetitions the mean count of particle i is within
/// 5 standard errors of N w_i. The per-repetition variance of a count is at most the
/// multinomial N w_i (1 - w_i) for multinomial, stratified and residual resampling, and at
/// most 1/4 for systematic (counts are floor or ceil of N w_i); the bound uses
/// max(N w_i (1 - w_i), 1/4) / R. A false alarm at 5 sigma has probability below 1e-6 per
/// check, and the seed is fixed.
#[test]
fn every_resampler_is_unbiased() {
    let w = [0.02, 0.3, 0.0, 0.155, 0.125, 0.4, 0.0005, 0.0];
    let total: f64 = w.iter().sum();
    let n = 9usize; // outputs != inputs on purpose
    let reps = 20_000;
    for (name, scheme) in schemes() {
        let mut rng = ChaCha8Rng::seed_from_u64(42);
        let mut counts = vec![0u64; w.len()];
        let mut out = vec![0usize; n];
        for _ in 0..reps {
            scheme
                .resample_into(&w, &mut rng, &mut out)
                .expect("resample");
            for &i in &out {
                counts[i] += 1;
            }
        }
        for (i, &wi) in w.iter().enumerate() {
            let p = wi / total;
            let expected = n as f64 * p;
            let mean = counts[i] as f64 / reps as f64;
            if wi == 0.0 {
                assert_eq!(counts[i], 0, "{name}: zero weight {i} selected");
                continue;
            }
            let sd = ((n as f64 * p * (1.0 - p)).max(0.25) / reps as f64).sqrt();
            assert!(
                (mean - expected).abs() < 5.0 * sd,
                "{name}: particle {i} mean count {mean}, expected {expected}, sd {sd}"
            );
        }
    }
}

#[test]
fn structural_properties_of_counts() {
    let w = [0.05, 0.31, 0.14, 0.2, 0.3];
    let n = 10;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..500 {
        let mut count = |scheme: &dyn Fn(&mut ChaCha8Rng, &mut [usize])| {
            let mut out = vec![0usize; n];
            scheme(&mut rng, &mut out);
            let mut c = vec![0usize; w.len()];
            for &i in &out {
                c[i] += 1;
            }
            c
        };
        let res = count(&|r, o| Residual.resample_into(&w, r, o).expect("ok"));
        let sys = count(&|r, o| Systematic.resample_into(&w, r, o).expect("ok"));
        let strat = count(&|r, o| Stratified.resample_into(&w, r, o).expect("ok"));
        for (i, &wi) in w.iter().enumerate() {
            let nw = n as f64 * wi;
            // residual keeps floor(N w_i) copies; systematic gives floor or ceil
            assert!(
                res[i] as f64 >= (nw - 1e-9).floor(),
                "residual {i}: {res:?}"
            );
            assert!(
                (sys[i] as f64 - nw).abs() < 1.0 + 1e-9,
                "systematic {i}: {sys:?}"
            );
            assert!((strat[i] as f64 - nw).abs() < 2.0 + 1e-9, "stratified {i}");
        }
        assert_eq!(res.iter().sum::<usize>(), n);
    }
}

#[test]
fn same_seed_same_indices_and_buffer_equals_vector() {
    let w: Vec<f64> = (0..100).map(|i| ((i * 37 % 11) as f64).powi(2)).collect();
    for (name, scheme) in schemes() {
        let a = scheme
            .resample(&w, 100, &mut ChaCha8Rng::seed_from_u64(5))
            .expect("a");
        let mut b = vec![0; 100];
        scheme
            .resample_into(&w, &mut ChaCha8Rng::seed_from_u64(5), &mut b)
            .expect("b");
        assert_eq!(a, b, "{name}");
        assert!(a.iter().all(|&i| w[i] > 0.0), "{name}");
    }
    // the unit structs and the enum agree
    let mut r1 = ChaCha8Rng::seed_from_u64(9);
    let mut r2 = ChaCha8Rng::seed_from_u64(9);
    assert_eq!(
        Multinomial.resample(&w, 50, &mut r1).expect("m"),
        Resampling::Multinomial
            .resample(&w, 50, &mut r2)
            .expect("m")
    );
}

#[test]
fn single_particle_and_empty_output() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for (name, scheme) in schemes() {
        assert_eq!(scheme.resample(&[0.7], 3, &mut rng).expect(name), [0, 0, 0]);
        assert!(
            scheme
                .resample(&[0.2, 0.8], 0, &mut rng)
                .expect(name)
                .is_empty()
        );
    }
}
