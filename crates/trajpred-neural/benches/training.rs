//! Training cost of the recurrent models (criterion).
//!
//! - `lstm_epoch_800x10_b16`: one epoch of the 2 x 64 LSTM (+ one 64 fully connected hidden
//!   layer) on an 800-step 3-D sine trajectory, window 10, next-step target, batch 16
//!   (790 windows -> 50 batches), Adam lr 1e-3.
//! - `lstm_epoch_800x10_b16_plain_head`: the same with the output layer directly on the LSTM
//!   (Linear(64, 3)), the network of `shared/research/torch-anchor.md` row a.
//! - `kfu_iteration_200_b16`: one KFU-LSTM-Net iteration (forward through 200 steps, backward,
//!   Adam step) on a batch of 16 noisy 200-step 3-D sine trajectories.
//!
//! Run: `cargo bench -p trajpred-neural -- --warm-up-time 1 --measurement-time 5`.

use criterion::{Criterion, criterion_group, criterion_main};
use trajpred_core::Trajectory;
use trajpred_neural::{
    AxisMode, KfuConfig, KfuLstmNet, LstmArch, LstmNet, RecurrentLayers, TrainConfig, WindowConfig,
};

fn sine(n: usize, phase: f64, noise: f64) -> Trajectory {
    let k: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let wobble = |i: usize, a: usize| noise * ((((i * 31 + a * 17) % 13) as f64) / 6.0 - 1.0);
    Trajectory::uniform(
        0.0,
        1.0,
        vec![
            k.iter()
                .enumerate()
                .map(|(i, s)| (0.05 * s + phase).sin() + wobble(i, 0))
                .collect(),
            k.iter()
                .enumerate()
                .map(|(i, s)| (0.065 * s + 0.5 + phase).sin() + wobble(i, 1))
                .collect(),
            k.iter()
                .enumerate()
                .map(|(i, s)| (0.035 * s + 1.0 + phase).sin() + wobble(i, 2))
                .collect(),
        ],
    )
    .expect("valid trajectory")
}

fn lstm_epoch(c: &mut Criterion, name: &str, fc: Vec<usize>) {
    let data = vec![sine(800, 0.0, 0.0)];
    let mut model = LstmNet::new(
        LstmArch(RecurrentLayers {
            layers: vec![64, 64],
            fc,
            ..RecurrentLayers::default()
        }),
        WindowConfig {
            window: 10,
            horizon: 1,
            axes: AxisMode::Joint,
        },
        TrainConfig::new(1e-3).with_epochs(1).with_batch_size(16),
    )
    .expect("valid config");
    c.bench_function(name, |b| {
        b.iter(|| model.fit_with(&data, &mut |_| {}).expect("trains").len())
    });
}

fn benches(c: &mut Criterion) {
    lstm_epoch(c, "lstm_epoch_800x10_b16", vec![64]);
    lstm_epoch(c, "lstm_epoch_800x10_b16_plain_head", vec![]);
    let data: Vec<Trajectory> = (0..16).map(|i| sine(200, i as f64 * 0.4, 0.1)).collect();
    let mut kfu = KfuLstmNet::new(
        KfuConfig {
            seq_len: 200,
            stride: 200,
            ..KfuConfig::default()
        },
        TrainConfig::new(1e-4).with_epochs(1).with_batch_size(16),
    )
    .expect("valid config");
    c.bench_function("kfu_iteration_200_b16", |b| {
        b.iter(|| {
            kfu.fit_observed(&data, &mut |_| {})
                .expect("trains")
                .epochs
                .len()
        })
    });
}

criterion_group! {
    name = training;
    config = Criterion::default().sample_size(10);
    targets = benches
}
criterion_main!(training);
