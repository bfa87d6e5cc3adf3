//! Times a few epochs of every preset at the papers' data sizes and extrapolates to the full
//! epoch counts, so the reproduction can budget its run time.
//!
//! `cargo run --release -p trajpred-neural --example profile_preset_timing -- [epochs]`

use std::time::Instant;
use trajpred_core::Trajectory;
use trajpred_neural::{KfuLstmNet, LstmNet, Mlp, RnnNet, TrainConfig};

/// `docs/papers.md` A.5 eq. 20: 1000 points, t_i = 0.01 pi i; the first 800 are the training part.
fn eq20(n: usize) -> Trajectory {
    let t: Vec<f64> = (0..n)
        .map(|i| i as f64 * 0.01 * std::f64::consts::PI)
        .collect();
    Trajectory::from_axes(
        t.clone(),
        vec![
            t.iter().map(|s| 2.0 * (0.1 * s).sin()).collect(),
            t.iter().map(|s| s.sin() * (0.1 * s).cos()).collect(),
            t.iter().map(|s| 2.0 * s.sin() * (2.0 * s).cos()).collect(),
        ],
    )
    .expect("valid")
}

/// A noisy helix of `n` points (a stand-in for the patent's curves).
fn helix(n: usize) -> Trajectory {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.05).collect();
    let w = |i: usize, a: usize| 0.05 * ((((i * 31 + a * 17) % 13) as f64) / 6.0 - 1.0);
    Trajectory::uniform(
        0.0,
        1.0,
        vec![
            t.iter()
                .enumerate()
                .map(|(i, s)| s.cos() + w(i, 0))
                .collect(),
            t.iter()
                .enumerate()
                .map(|(i, s)| s.sin() + w(i, 1))
                .collect(),
            t.iter()
                .enumerate()
                .map(|(i, s)| 0.1 * s + w(i, 2))
                .collect(),
        ],
    )
    .expect("valid")
}

fn report(name: &str, epochs: usize, full: usize, secs: f64) {
    let per = secs / epochs as f64;
    eprintln!(
        "{name:<28} {per:>8.4} s/epoch   full {full} epochs: ~{:.0} s",
        per * full as f64
    );
}

/// Trains the preset `$model` for `$epochs` epochs with `$fit` (`fit_with`, or
/// `fit_observed` for the KFU net) on `$data`, reports the time per epoch and the
/// extrapolation to the preset's own epoch count as `$name`, and gives back the model.
/// (A macro: the presets are different types with the same inherent methods.)
macro_rules! time_preset {
    ($name:expr, $model:expr, $fit:ident, $data:expr, $epochs:expr) => {{
        let mut model = $model;
        let full = model.train_config().epochs;
        let cfg: TrainConfig = model.train_config().clone().with_epochs($epochs);
        model.set_train_config(cfg)?;
        let s = Instant::now();
        model.$fit($data, &mut |_| {})?;
        report($name, $epochs, full, s.elapsed().as_secs_f64());
        model
    }};
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let epochs: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(3);
    let gskf = vec![eq20(1000).prefix(800)?];
    let patent = vec![helix(1000).prefix(800)?];

    let bp = Mlp::gskf_bp(6, 6)?;
    time_preset!("GSKF BP (3 axes)", bp, fit_with, &gskf, epochs);
    let lstm = LstmNet::gskf_lstm(6, 6)?;
    time_preset!("GSKF LSTM (3 axes)", lstm, fit_with, &gskf, epochs);
    let rnn = RnnNet::patent_baseline(10, 1)?;
    time_preset!("patent RNN (800 pts)", rnn, fit_with, &patent, epochs);
    let lstm = LstmNet::patent_baseline(10, 1)?;
    time_preset!("patent LSTM (800 pts)", lstm, fit_with, &patent, epochs);
    let kfu = KfuLstmNet::patent()?;
    let kfu = time_preset!(
        "patent KFU-LSTM (800 pts)",
        kfu,
        fit_observed,
        &patent,
        epochs
    );
    let s = Instant::now();
    let p = kfu.one_step_ahead(&helix(200))?;
    eprintln!(
        "KFU one_step_ahead, 200 points: {:.3} s ({} predictions)",
        s.elapsed().as_secs_f64(),
        p.len()
    );
    Ok(())
}
