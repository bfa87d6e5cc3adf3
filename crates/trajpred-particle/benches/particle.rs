//! Criterion benchmarks of the hot paths:
//!
//! - `resample/<scheme>/<N>`: each resampler at N = 10^4 and 10^6 (throughput in particles
//!   per second; weights i.i.d. uniform, a seeded `SmallRng` (xoshiro256++) as generator),
//!   beside `resample/baseline_sum/<N>`, one pass summing the weights, to calibrate the
//!   figures on a shared machine;
//!   filterpy's figures for the same sizes come from `benches/filterpy_resampling.py`;
//!   the input is *linear, unnormalised* weights (the resamplers divide by the sum);
//! - `resample_from_log/<scheme>/<N>`: what a filter step does before resampling, from
//!   log-weights (i.i.d. `ln U`): `weights_from_log_into` (log-sum-exp, then one `exp` per
//!   particle into a caller's buffer), then the resampler; the difference to `resample/`
//!   is the log-to-linear conversion;
//! - `step/bootstrap_ct5_rb2/1000` and `step/mkpf_ct5_rb2/100`: one filter step on the
//!   coordinated-turn + range-bearing model (throughput: particles per second, so the time
//!   per particle is the inverse).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Matrix5, U2, U5, Vector2, Vector5};
use rand::rngs::SmallRng;
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use trajpred_core::Gaussian;
use trajpred_kalman::{CoordinatedTurn, MerweSigmaPoints, Observation, RangeBearing};
use trajpred_particle::{
    Mkpf, ParticleFilter, ParticleFiltering, Resampler, Resampling, weights_from_log_into,
};

fn resamplers(c: &mut Criterion) {
    let mut group = c.benchmark_group("resample");
    for &n in &[10_000usize, 1_000_000] {
        let mut wrng = SmallRng::seed_from_u64(1);
        let weights: Vec<f64> = (0..n).map(|_| wrng.random::<f64>()).collect();
        let mut out = vec![0usize; n];
        group.throughput(Throughput::Elements(n as u64));
        // calibration on a shared machine: one pass summing the weights (a lower bound for
        // any resampler, which must at least read them)
        group.bench_with_input(BenchmarkId::new("baseline_sum", n), &n, |b, _| {
            b.iter(|| black_box(black_box(&weights).iter().sum::<f64>()))
        });
        for scheme in Resampling::ALL {
            let mut rng = SmallRng::seed_from_u64(2);
            group.bench_with_input(BenchmarkId::new(scheme.name(), n), &n, |b, _| {
                b.iter(|| {
                    scheme
                        .resample_into(black_box(&weights), &mut rng, &mut out)
                        .expect("resample");
                    black_box(&out);
                })
            });
        }
    }
    group.finish();
    let mut group = c.benchmark_group("resample_from_log");
    for &n in &[10_000usize, 1_000_000] {
        let mut wrng = SmallRng::seed_from_u64(1);
        let log_weights: Vec<f64> = (0..n).map(|_| wrng.random::<f64>().ln()).collect();
        let mut w = vec![0.0f64; n];
        let mut out = vec![0usize; n];
        group.throughput(Throughput::Elements(n as u64));
        for scheme in [Resampling::Residual, Resampling::Systematic] {
            let mut rng = SmallRng::seed_from_u64(2);
            group.bench_with_input(BenchmarkId::new(scheme.name(), n), &n, |b, _| {
                b.iter(|| {
                    weights_from_log_into(black_box(&log_weights), &mut w).expect("exp");
                    scheme
                        .resample_into(&w, &mut rng, &mut out)
                        .expect("resample");
                    black_box(&out);
                })
            });
        }
    }
    group.finish();
}

fn model() -> (
    CoordinatedTurn<f64>,
    RangeBearing<f64>,
    Gaussian<f64, U5>,
    Vector2<f64>,
) {
    let q = Matrix5::from_diagonal(&Vector5::new(4.0, 1.0, 4.0, 1.0, 1e-4));
    let ct = CoordinatedTurn::with_process_noise(1.0, q).expect("ct");
    let rb = RangeBearing::new(Vector2::new(0.0, 0.0), 0, 2, 1.0, 1e-6).expect("rb");
    let x = Vector5::new(1000.0, 10.0, 1000.0, 0.0, 0.05);
    let z = rb.observe(&x).expect("z");
    let x0 = Gaussian {
        mean: x,
        covariance: Matrix5::from_diagonal(&Vector5::new(25.0, 4.0, 25.0, 4.0, 1e-3)),
    };
    (ct, rb, x0, z)
}

fn steps(c: &mut Criterion) {
    let (ct, rb, x0, z) = model();
    let mut group = c.benchmark_group("step");
    let n = 1000;
    let mut rng = SmallRng::seed_from_u64(3);
    let mut pf = ParticleFilter::<f64, U5, U2, _, _>::from_gaussian(
        ct.clone(),
        rb.clone(),
        &x0,
        n,
        &mut rng,
    )
    .expect("pf");
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function(BenchmarkId::new("bootstrap_ct5_rb2", n), |b| {
        b.iter(|| {
            // re-seat the filter near the observation so every iteration does the same work
            let s = pf.step(Some(&z), &mut rng);
            black_box(&s);
        })
    });
    let n = 100;
    let mut mkpf = Mkpf::<f64, U5, U2, _, _>::from_gaussian(
        ct,
        rb,
        &x0,
        n,
        MerweSigmaPoints::default(),
        &mut rng,
    )
    .expect("mkpf");
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function(BenchmarkId::new("mkpf_ct5_rb2", n), |b| {
        b.iter(|| {
            let s = mkpf.step(Some(&z), &mut rng);
            black_box(&s);
        })
    });
    group.finish();
}

criterion_group!(benches, resamplers, steps);
criterion_main!(benches);
