//! Evaluation throughput (forecasts per second) of every registered method on a fixed
//! synthetic set, and the harness's scaling from 1 to 2 threads.
//!
//! ```text
//! cargo bench -p trajpred --bench throughput
//! ```
//!
//! The set: 32 seeded tracks of 120 points, 1 s apart, a target at 8-15 m/s that turns at a
//! random rate for part of the track, observed with 3 m noise. Each method is fitted once on
//! 8 other tracks from the same generator; the bench times `harness::evaluate` (history 20,
//! horizon 5, 4 origins per track: 128 forecasts per iteration) and reports elements =
//! forecasts, so criterion prints forecasts per second.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::hint::black_box;
use trajpred::harness::{EvalConfig, evaluate};
use trajpred::registry::{MethodOptions, all_methods, build};
use trajpred_core::{Predictor, Trajectory};

fn track(rng: &mut ChaCha8Rng) -> Trajectory {
    let unit = |rng: &mut ChaCha8Rng| rand::RngExt::random::<f64>(rng);
    let speed = 8.0 + 7.0 * unit(rng);
    let mut heading = std::f64::consts::TAU * unit(rng);
    let turn = (unit(rng) - 0.5) * 0.1;
    let turn_from = (unit(rng) * 60.0) as usize;
    let noise = Normal::new(0.0, 3.0).expect("valid sd");
    let (mut x, mut y) = (0.0, 0.0);
    let (mut xs, mut ys) = (Vec::new(), Vec::new());
    for i in 0..120 {
        if (turn_from..turn_from + 40).contains(&i) {
            heading += turn;
        }
        x += speed * heading.cos();
        y += speed * heading.sin();
        xs.push(x + noise.sample(rng));
        ys.push(y + noise.sample(rng));
    }
    Trajectory::uniform(0.0, 1.0, vec![xs, ys]).expect("finite, increasing")
}

fn data() -> (Vec<Trajectory>, Vec<Trajectory>) {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let train = (0..8).map(|_| track(&mut rng)).collect();
    let test = (0..32).map(|_| track(&mut rng)).collect();
    (train, test)
}

fn config() -> EvalConfig {
    EvalConfig {
        history: 20,
        horizon: 5,
        stride: 20,
        threshold: 25.0,
        max_origins_per_trajectory: Some(4),
    }
}

fn fitted(name: &str, train: &[Trajectory]) -> Box<dyn Predictor> {
    let opts = MethodOptions {
        horizons: 5,
        // the networks' forecast cost does not depend on how long they trained
        epochs: Some(2),
        ..Default::default()
    };
    let mut p = build(name, &opts).expect("registered method");
    p.fit(train).expect("fits on the synthetic set");
    p
}

fn forecasts(p: &dyn Predictor, test: &[Trajectory], cfg: &EvalConfig) -> u64 {
    evaluate(p, test, cfg, None).expect("evaluates").forecasts as u64
}

fn throughput(c: &mut Criterion) {
    let (train, test) = data();
    let cfg = config();
    let mut group = c.benchmark_group("evaluate");
    group.sample_size(10);
    for m in all_methods() {
        let p = fitted(m.name, &train);
        group.throughput(Throughput::Elements(forecasts(p.as_ref(), &test, &cfg)));
        group.bench_function(m.name, |b| {
            b.iter(|| evaluate(black_box(p.as_ref()), &test, &cfg, None).expect("evaluates"))
        });
    }
    group.finish();
}

fn scaling(c: &mut Criterion) {
    let (train, test) = data();
    let cfg = config();
    let mut group = c.benchmark_group("threads");
    group.sample_size(10);
    for name in ["kf-dynamic", "gskf", "hmm", "pf", "mkpf"] {
        let p = fitted(name, &train);
        group.throughput(Throughput::Elements(forecasts(p.as_ref(), &test, &cfg)));
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            group.bench_with_input(BenchmarkId::new(name, threads), &threads, |b, _| {
                b.iter(|| {
                    pool.install(|| {
                        evaluate(black_box(p.as_ref()), &test, &cfg, None).expect("evaluates")
                    })
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, throughput, scaling);
criterion_main!(benches);
