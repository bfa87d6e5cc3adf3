//! Group sparse coding as the MSTPM-GSKF paper uses it: one linear model per forecast step,
//! each fitted by LAR on windows of the last `m` values, forecasting `T` steps at once.
//! Here on a noisy, slowly turning coordinate (sampled every second), fitted on the first
//! 200 values and scored on the next 100, against carrying the last value forward.
//!
//! ```text
//! cargo run -p trajpred-sparse --example gsc_forecast
//! ```
//!
//! `tests/examples_run.rs` runs it and checks that GSC beats the last value at every step.
#![allow(clippy::print_stdout)]

use trajpred_sparse::GroupSparseCoder;

/// Window length `m` and forecast steps `T`.
pub const WINDOW: usize = 6;
/// Forecast steps.
pub const HORIZONS: usize = 5;

/// The test series: `x(t) = 50 sin(t / 40) + 0.3 t` plus a deterministic wobble of 0.5.
pub fn series(n: usize) -> Vec<f64> {
    (0..n)
        .map(|t| {
            let t = t as f64;
            50.0 * (t / 40.0).sin() + 0.3 * t + 0.5 * (1.7 * t).sin()
        })
        .collect()
}

/// Mean absolute error per step `1..=T` of GSC and of the last value, on the held-out part.
pub fn run() -> Result<(Vec<f64>, Vec<f64>), Box<dyn std::error::Error>> {
    let x = series(300);
    let (train, test) = x.split_at(200);
    let gsc = GroupSparseCoder::params(WINDOW, HORIZONS).fit(train)?;
    let (mut e_gsc, mut e_last) = (vec![0.0; HORIZONS], vec![0.0; HORIZONS]);
    let mut count = 0.0;
    for origin in WINDOW..=test.len() - HORIZONS {
        let window = &test[origin - WINDOW..origin];
        let forecast = gsc.predict(window)?;
        for t in 0..HORIZONS {
            e_gsc[t] += (forecast[t] - test[origin + t]).abs();
            e_last[t] += (window[WINDOW - 1] - test[origin + t]).abs();
        }
        count += 1.0;
    }
    Ok((
        e_gsc.iter().map(|e| e / count).collect(),
        e_last.iter().map(|e| e / count).collect(),
    ))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (gsc, last) = run()?;
    println!("step  GSC (m = {WINDOW})  last value");
    for (t, (g, l)) in gsc.iter().zip(&last).enumerate() {
        println!("{:4}  {g:12.3}  {l:10.3}", t + 1);
    }
    Ok(())
}
