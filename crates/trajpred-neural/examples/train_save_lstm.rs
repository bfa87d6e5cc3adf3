//! Training an LSTM forecaster on trajectories, saving it, and loading it back elsewhere:
//! the model maps the last 8 points to the next 3; here trained on noisy circles (a target
//! circling at constant speed), scored on a circle it never saw, against the last position.
//!
//! ```text
//! cargo run --release -p trajpred-neural --example train_save_lstm -- [model-file]
//! ```
//!
//! Prints the training loss per epoch, the held-out error of the LSTM and of the last
//! position, and whether the reloaded model forecasts exactly as the trained one.
//! `tests/examples_run.rs` runs it.
#![allow(clippy::print_stdout)]

use std::path::{Path, PathBuf};
use trajpred_core::{Predictor, Trajectory};
use trajpred_neural::{AxisMode, LstmArch, LstmNet, RecurrentLayers, TrainConfig, WindowConfig};

/// What the run measured.
#[derive(Debug, Clone)]
pub struct Summary {
    /// Mean training loss of each epoch.
    pub losses: Vec<f64>,
    /// Mean Euclidean error of the LSTM's 3-step forecasts on the held-out circle.
    pub lstm_error: f64,
    /// The same for repeating the last position.
    pub last_position_error: f64,
    /// Whether the model loaded from the file gave the very same forecasts.
    pub reload_identical: bool,
}

/// A circle of radius `r` m, travelled at `speed` m/s, sampled every second, starting at
/// angle `phase`, with a deterministic wobble of `wobble` m.
pub fn circle(
    r: f64,
    speed: f64,
    phase: f64,
    wobble: f64,
    n: usize,
) -> trajpred_core::Result<Trajectory> {
    let w = speed / r;
    let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let x = t
        .iter()
        .map(|s| r * (phase + w * s).cos() + wobble * (2.3 * s).sin())
        .collect();
    let y = t
        .iter()
        .map(|s| r * (phase + w * s).sin() + wobble * (1.7 * s).cos())
        .collect();
    Trajectory::uniform(0.0, 1.0, vec![x, y])
}

/// Trains for `epochs` with `seed`, saves to `file`, reloads, scores.
pub fn run(file: &Path, epochs: usize, seed: u64) -> Result<Summary, Box<dyn std::error::Error>> {
    let train = (0..6)
        .map(|k| circle(60.0 + 10.0 * k as f64, 5.0, k as f64, 0.3, 120))
        .collect::<Result<Vec<_>, _>>()?;
    let test = circle(75.0, 5.0, 2.5, 0.3, 120)?;

    let mut lstm = LstmNet::new(
        LstmArch(RecurrentLayers {
            layers: vec![16],
            fc: vec![],
            ..Default::default()
        }),
        WindowConfig {
            window: 8,
            horizon: 3,
            axes: AxisMode::Joint,
        },
        TrainConfig::new(1e-2).with_epochs(epochs).with_seed(seed),
    )?;
    let mut losses = Vec::new();
    lstm.fit_with(&train, &mut |e| losses.push(e.train_loss))?;
    lstm.save(file)?;
    let loaded = LstmNet::load(file)?;

    let (mut e_lstm, mut e_last, mut count, mut identical) = (0.0, 0.0, 0.0, true);
    for origin in (8..test.len() - 3).step_by(4) {
        let history = test.slice(0..origin)?;
        let f = lstm.forecast(&history, 3)?;
        identical &= loaded.forecast(&history, 3)? == f;
        let last = history.point(origin - 1);
        for k in 1..=3 {
            let (p, truth) = (f.step(k), test.point(origin + k - 1));
            e_lstm += ((p[0] - truth[0]).powi(2) + (p[1] - truth[1]).powi(2)).sqrt();
            e_last += ((last[0] - truth[0]).powi(2) + (last[1] - truth[1]).powi(2)).sqrt();
            count += 1.0;
        }
    }
    Ok(Summary {
        losses,
        lstm_error: e_lstm / count,
        last_position_error: e_last / count,
        reload_identical: identical,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let file = std::env::args().nth(1).map_or_else(
        || std::env::temp_dir().join("trajpred_example_lstm.model"),
        PathBuf::from,
    );
    let s = run(&file, 30, 1)?;
    for (e, l) in s.losses.iter().enumerate() {
        println!("epoch {:2}: training loss {l:.5}", e + 1);
    }
    println!(
        "held-out mean error over 3 steps: LSTM {:.2} m, last position {:.2} m",
        s.lstm_error, s.last_position_error
    );
    println!(
        "saved to {}; reloaded model identical: {}",
        file.display(),
        s.reload_identical
    );
    Ok(())
}
