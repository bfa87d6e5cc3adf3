//! A fixed amount of work for profiling and instruction counting: `epochs` training epochs
//! of the network of the criterion benchmark `lstm_epoch_800x10_b16` (2 x 64 LSTM + FC 64,
//! 800-step 3-D sine, window 10, batch 16, Adam lr 1e-3). Prints every epoch's wall time and
//! loss. On a loaded machine, `perf stat -e instructions:u` over this run is a steadier
//! yardstick than wall time.
//!
//! `cargo run --release -p trajpred-neural --example profile_lstm_epoch -- [epochs]`

use trajpred_core::Trajectory;
use trajpred_neural::{AxisMode, LstmArch, LstmNet, RecurrentLayers, TrainConfig, WindowConfig};

fn main() {
    let epochs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5);
    let k: Vec<f64> = (0..800).map(|i| i as f64).collect();
    let data = vec![
        Trajectory::uniform(
            0.0,
            1.0,
            vec![
                k.iter().map(|s| (0.05 * s).sin()).collect(),
                k.iter().map(|s| (0.065 * s + 0.5).sin()).collect(),
                k.iter().map(|s| (0.035 * s + 1.0).sin()).collect(),
            ],
        )
        .expect("valid trajectory"),
    ];
    let mut model = LstmNet::new(
        LstmArch(RecurrentLayers::default()),
        WindowConfig {
            window: 10,
            horizon: 1,
            axes: AxisMode::Joint,
        },
        TrainConfig::new(1e-3)
            .with_epochs(epochs)
            .with_batch_size(16),
    )
    .expect("valid config");
    model
        .fit_with(&data, &mut |r| {
            eprintln!(
                "epoch {:3}  {:.4} s  loss {:.6}",
                r.epoch,
                r.elapsed.as_secs_f64(),
                r.train_loss
            );
        })
        .expect("trains");
}
