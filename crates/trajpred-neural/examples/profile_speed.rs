//! Training speed of the LSTM and the KFU-LSTM-Net beside PyTorch (`benches/compare.sh`
//! alternates this with `benches/pytorch_lstm_epoch.py` and `benches/pytorch_kfu_iteration.py`).
//!
//! - `lstm`: one epoch of the 2 x 64 LSTM + FC 64 (ReLU) + Linear(64, 3) on the 800-step 3-D
//!   sine, window 10, next step, batch 16 (50 batches), Adam lr 1e-3 — the network of
//!   `pytorch_lstm_epoch.py` and of the criterion bench `lstm_epoch_800x10_b16`;
//! - `kfu`: one KFU-LSTM-Net iteration (forward through 200 steps, backward, Adam) on a
//!   batch of 16 noisy 3-D sine trajectories of 200 steps, the one-step prediction loss —
//!   `pytorch_kfu_iteration.py` and the criterion bench `kfu_iteration_200_b16`.
//!
//! Drops `warmup` epochs, times `repeat` more (each epoch's wall time as the training loop
//! reports it) and prints one JSON line: median, quartiles, min and max in seconds.
//!
//! `cargo run --release -p trajpred-neural --example profile_speed -- lstm|kfu [fused|composed] [warmup] [repeat]`

// the JSON line on standard output is this program's result (read by benches/compare.sh)
#![allow(clippy::print_stdout)]

use trajpred_core::Trajectory;
use trajpred_neural::{
    AxisMode, KfuConfig, KfuLstmNet, LstmArch, LstmNet, RecurrentLayers, TrainConfig, WindowConfig,
};

fn sine(n: usize, phase: f64, noise: f64) -> Trajectory {
    let wobble = |i: usize, a: usize| noise * ((((i * 31 + a * 17) % 13) as f64) / 6.0 - 1.0);
    let axis = |w: f64, p: f64, a: usize| -> Vec<f64> {
        (0..n)
            .map(|i| (w * i as f64 + p + phase).sin() + wobble(i, a))
            .collect()
    };
    Trajectory::uniform(
        0.0,
        1.0,
        vec![axis(0.05, 0.0, 0), axis(0.065, 0.5, 1), axis(0.035, 1.0, 2)],
    )
    .expect("valid trajectory")
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    let pos = q * (sorted.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let what = args.get(1).map_or("lstm", String::as_str).to_string();
    let fused = args.get(2).map_or("fused", String::as_str) != "composed";
    let warmup: usize = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(3);
    let repeat: usize = args.get(4).and_then(|a| a.parse().ok()).unwrap_or(10);
    let epochs = warmup + repeat;
    let mut times = Vec::new();
    let mut losses = Vec::new();
    let mut record = |r: &trajpred_neural::EpochReport| {
        times.push(r.elapsed.as_secs_f64());
        losses.push(r.train_loss);
    };
    let train = TrainConfig::new(1e-3)
        .with_epochs(epochs)
        .with_batch_size(16)
        .with_fused(fused);
    match what.as_str() {
        "lstm" => {
            let mut model = LstmNet::new(
                LstmArch(RecurrentLayers::default()),
                WindowConfig {
                    window: 10,
                    horizon: 1,
                    axes: AxisMode::Joint,
                },
                train,
            )
            .expect("valid config");
            model
                .fit_with(&[sine(800, 0.0, 0.0)], &mut record)
                .expect("trains");
        }
        "kfu" => {
            let data: Vec<Trajectory> = (0..16).map(|i| sine(200, i as f64 * 0.4, 0.1)).collect();
            let mut model = KfuLstmNet::new(
                KfuConfig {
                    seq_len: 200,
                    stride: 200,
                    ..KfuConfig::default()
                },
                train.with_learning_rate(1e-4),
            )
            .expect("valid config");
            model.fit_observed(&data, &mut record).expect("trains");
        }
        other => panic!("unknown workload {other}: lstm or kfu"),
    }
    let mut t: Vec<f64> = times[warmup.min(times.len())..].to_vec();
    t.sort_by(f64::total_cmp);
    println!(
        "{{\"impl\": \"burn-{}\", \"workload\": \"{what}\", \"repeat\": {}, \"median_s\": {:.6}, \"p25_s\": {:.6}, \"p75_s\": {:.6}, \"min_s\": {:.6}, \"max_s\": {:.6}, \"first_loss\": {:.6}, \"last_loss\": {:.6}}}",
        if fused { "fused" } else { "composed" },
        t.len(),
        quantile(&t, 0.5),
        quantile(&t, 0.25),
        quantile(&t, 0.75),
        t[0],
        t[t.len() - 1],
        losses.first().copied().unwrap_or(f64::NAN),
        losses.last().copied().unwrap_or(f64::NAN),
    );
}
