//! One test body, run over every predictor of the registry: changing any value after the
//! forecast origin leaves the forecast unchanged.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trajpred::harness::history_at;
use trajpred::registry::{MethodOptions, all_methods, build};
use trajpred_core::Trajectory;

/// A curving 2-D track in metres, 1 s sampling, with a little seeded jitter.
fn track(n: usize, seed: u64) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x = (0..n)
        .map(|i| 50.0 * (i as f64 * 0.05).sin() + 3.0 * i as f64 + rng.random::<f64>())
        .collect();
    let y = (0..n)
        .map(|i| 40.0 * (i as f64 * 0.03).cos() + rng.random::<f64>())
        .collect();
    Trajectory::uniform(0.0, 1.0, vec![x, y]).unwrap()
}

/// The same track with every value after `origin` replaced (positions and timestamps).
fn perturb_after(tr: &Trajectory, origin: usize, seed: u64) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut times = tr.times().to_vec();
    let mut axes: Vec<Vec<f64>> = tr.axes().map(<[f64]>::to_vec).collect();
    for i in origin + 1..tr.len() {
        times[i] = times[i - 1] + 0.1 + rng.random::<f64>() * 5.0;
        for a in axes.iter_mut() {
            a[i] = rng.random::<f64>() * 1e4 - 5e3;
        }
    }
    Trajectory::from_axes(times, axes).unwrap()
}

#[test]
fn every_predictor_is_causal() {
    let train = vec![track(200, 1), track(150, 2)];
    let test = track(120, 3);
    // two epochs keep the networks' training short; causality does not depend on it
    let opts = MethodOptions {
        epochs: Some(2),
        ..Default::default()
    };
    let methods = all_methods();
    assert!(methods.len() >= 10);
    for info in &methods {
        let mut p = build(info.name, &opts).unwrap();
        p.fit(&train).unwrap();
        let hist_len = 30.max(p.min_history());
        for origin in [hist_len - 1, 60, 100] {
            let changed = perturb_after(&test, origin, origin as u64);
            // through the harness's own slicing ...
            let a = p
                .forecast(&history_at(&test, origin, hist_len).unwrap(), 5)
                .unwrap();
            let b = p
                .forecast(&history_at(&changed, origin, hist_len).unwrap(), 5)
                .unwrap();
            assert_eq!(a, b, "{} at origin {origin}", info.name);
            // ... and with the whole past as history
            let a = p.forecast(&test.prefix(origin + 1).unwrap(), 5).unwrap();
            let b = p.forecast(&changed.prefix(origin + 1).unwrap(), 5).unwrap();
            assert_eq!(a, b, "{} at origin {origin} (full past)", info.name);
            // the forecast is not trivially constant: it does depend on the past
            let moved = perturb_after(&test, 5, 99);
            let c = p.forecast(&moved.prefix(origin + 1).unwrap(), 5).unwrap();
            assert_ne!(a, c, "{} ignores its history", info.name);
        }
    }
}

#[test]
fn history_at_holds_nothing_after_the_origin() {
    let tr = track(50, 4);
    let h = history_at(&tr, 20, 10).unwrap();
    assert_eq!(h.len(), 10);
    assert_eq!(h.times().last(), Some(&tr.times()[20]));
    assert!(history_at(&tr, 5, 10).is_err());
}
