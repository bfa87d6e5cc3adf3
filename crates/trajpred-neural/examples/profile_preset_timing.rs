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

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let epochs: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(3);
    let gskf = vec![eq20(1000).prefix(800)?];
    let patent = vec![helix(1000).prefix(800)?];

    let mut bp = Mlp::gskf_bp(6, 6)?;
    let full = bp.train_config().epochs;
    bp.set_train_config(bp.train_config().clone().with_epochs(epochs))?;
    let s = Instant::now();
    bp.fit_with(&gskf, &mut |_| {})?;
    report("GSKF BP (3 axes)", epochs, full, s.elapsed().as_secs_f64());

    let mut lstm = LstmNet::gskf_lstm(6, 6)?;
    let full = lstm.train_config().epochs;
    lstm.set_train_config(lstm.train_config().clone().with_epochs(epochs))?;
    let s = Instant::now();
    lstm.fit_with(&gskf, &mut |_| {})?;
    report(
        "GSKF LSTM (3 axes)",
        epochs,
        full,
        s.elapsed().as_secs_f64(),
    );

    let mut rnn = RnnNet::patent_baseline(10, 1)?;
    let full = rnn.train_config().epochs;
    rnn.set_train_config(rnn.train_config().clone().with_epochs(epochs))?;
    let s = Instant::now();
    rnn.fit_with(&patent, &mut |_| {})?;
    report(
        "patent RNN (800 pts)",
        epochs,
        full,
        s.elapsed().as_secs_f64(),
    );

    let mut lstm = LstmNet::patent_baseline(10, 1)?;
    let full = lstm.train_config().epochs;
    lstm.set_train_config(lstm.train_config().clone().with_epochs(epochs))?;
    let s = Instant::now();
    lstm.fit_with(&patent, &mut |_| {})?;
    report(
        "patent LSTM (800 pts)",
        epochs,
        full,
        s.elapsed().as_secs_f64(),
    );

    let mut kfu = KfuLstmNet::patent()?;
    let full = kfu.train_config().epochs;
    let cfg: TrainConfig = kfu.train_config().clone().with_epochs(epochs);
    kfu.set_train_config(cfg)?;
    let s = Instant::now();
    kfu.fit_observed(&patent, &mut |_| {})?;
    report(
        "patent KFU-LSTM (800 pts)",
        epochs,
        full,
        s.elapsed().as_secs_f64(),
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
