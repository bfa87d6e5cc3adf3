//! A quick check of the KFU-LSTM-Net on a noisy helix: one-step-ahead RMSE against the clean
//! truth, beside the persistence forecast and the LSTM baseline.
//!
//! `cargo run --release -p trajpred-neural --example profile_kfu_check -- [epochs]`

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trajpred_core::{Predictor, Trajectory};
use trajpred_neural::{KfuLstmNet, LstmNet};

fn helix(n: usize) -> Vec<Vec<f64>> {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.05).collect();
    vec![
        t.iter().map(|s| s.cos()).collect(),
        t.iter().map(|s| s.sin()).collect(),
        t.iter().map(|s| 0.1 * s).collect(),
    ]
}

/// Box-Muller normal deviates from a seeded generator.
fn noise(rng: &mut ChaCha8Rng, n: usize, sigma: f64) -> Vec<f64> {
    use rand::RngExt;
    (0..n)
        .map(|_| {
            let (u, v): (f64, f64) = (rng.random(), rng.random());
            sigma * (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        })
        .collect()
}

fn rmse(pred: &[Vec<f64>], truth: &Trajectory, first: usize) -> f64 {
    let mut s = 0.0;
    for (i, p) in pred.iter().enumerate() {
        for (k, v) in p.iter().enumerate() {
            s += (v - truth.axis(k)[first + i]).powi(2);
        }
    }
    (s / pred.len() as f64).sqrt()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let epochs: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(30);
    let n = 1000;
    let clean = Trajectory::uniform(0.0, 1.0, helix(n))?;
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let noisy_axes: Vec<Vec<f64>> = clean
        .axes()
        .map(|a| {
            let e = noise(&mut rng, n, 0.05);
            a.iter().zip(e).map(|(x, e)| x + e).collect()
        })
        .collect();
    let noisy = Trajectory::uniform(0.0, 1.0, noisy_axes)?;
    let (train_obs, train_clean) = (noisy.prefix(800)?, clean.prefix(800)?);
    let test = noisy.slice(800..n)?;
    let test_clean = clean.slice(800..n)?;

    let persistence: Vec<Vec<f64>> = (0..199).map(|i| test.point(i).to_vec()).collect();
    eprintln!(
        "persistence (z(t-1))        RMSE {:.4}",
        rmse(&persistence, &test_clean, 1)
    );

    let mut kfu = KfuLstmNet::patent()?;
    kfu.set_train_config(
        kfu.train_config()
            .clone()
            .with_epochs(epochs)
            .with_learning_rate(1e-3),
    )?;
    let r = kfu.fit_supervised(
        std::slice::from_ref(&train_obs),
        &[train_clean],
        &mut |_| {},
    )?;
    eprintln!(
        "KFU loss {:.5} -> {:.5} in {} epochs ({:.1} s)",
        r.first_loss().unwrap_or(f64::NAN),
        r.last_loss().unwrap_or(f64::NAN),
        r.epochs.len(),
        r.total_time().as_secs_f64()
    );
    let p = kfu.one_step_ahead(&test)?;
    eprintln!(
        "KFU-LSTM one step ahead     RMSE {:.4}",
        rmse(&p, &test_clean, 1)
    );
    eprintln!("learned Q, R (standardised): {:?}", kfu.noise()?);

    let mut lstm = LstmNet::patent_baseline(10, 1)?;
    lstm.set_train_config(lstm.train_config().clone().with_epochs(epochs))?;
    lstm.fit(&[train_obs])?;
    let p: Vec<Vec<f64>> = (9..199)
        .map(|i| {
            lstm.forecast(&test.prefix(i + 1)?, 1)
                .map(|f| f.step(1).to_vec())
        })
        .collect::<Result<_, _>>()?;
    eprintln!(
        "LSTM baseline (m = 10)      RMSE {:.4}",
        rmse(&p, &test_clean, 10)
    );
    Ok(())
}
