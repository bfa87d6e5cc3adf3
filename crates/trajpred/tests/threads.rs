//! The harness's results do not depend on the number of threads.

use trajpred::harness::{EvalConfig, MethodReport, evaluate};
use trajpred::registry::{MethodOptions, build};
use trajpred_core::Trajectory;

fn tracks() -> Vec<Trajectory> {
    // deterministic, curved tracks of different lengths (more than one chunk of the
    // harness), no randomness needed
    (0..140)
        .map(|k| {
            let n = 40 + (k % 7) * 5;
            let w = 0.02 + 0.003 * k as f64;
            let xs = (0..n)
                .map(|i| 100.0 * (w * i as f64).sin() + 0.3 * k as f64)
                .collect();
            let ys = (0..n)
                .map(|i| 80.0 * (w * i as f64).cos() - (i * k) as f64 * 0.01)
                .collect();
            Trajectory::uniform(0.0, 1.0, vec![xs, ys]).expect("finite, increasing")
        })
        .collect()
}

fn in_pool(threads: usize, f: impl FnOnce() -> MethodReport + Send) -> MethodReport {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(f)
}

#[test]
fn one_and_two_threads_give_identical_reports() {
    let data = tracks();
    let (train, test) = data.split_at(10);
    let cfg = EvalConfig {
        history: 20,
        horizon: 5,
        stride: 3,
        threshold: 25.0,
        max_origins_per_trajectory: None,
    };
    for name in ["kf-dynamic", "gskf", "hmm", "pf"] {
        let mut p = build(
            name,
            &MethodOptions {
                horizons: 5,
                ..Default::default()
            },
        )
        .expect("registered");
        p.fit(train).expect("fits");
        let run = |threads| {
            in_pool(threads, || {
                evaluate(p.as_ref(), test, &cfg, None).expect("evaluates")
            })
        };
        let (mut a, mut b) = (run(1), run(2));
        assert!(a.forecasts > 1000, "{name}: {} forecasts", a.forecasts);
        a.forecast_seconds = 0.0;
        b.forecast_seconds = 0.0;
        // bit-identical, not merely close
        assert_eq!(a, b, "{name}");
    }
}
