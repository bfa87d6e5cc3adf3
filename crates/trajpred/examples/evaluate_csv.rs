//! Evaluating methods on a CSV of tracks, as a user with their own data would: load (with
//! the skip report), split where fixes are far apart, split the tracks into training and
//! test sets, fit each method on the training tracks and score its forecasts on the test
//! tracks from every origin.
//!
//! ```text
//! cargo run --release -p trajpred --example evaluate_csv -- [tracks.csv]
//! ```
//!
//! The CSV has a header `t,x,y,track` (seconds, metres, a track id; `t,lat,lon` works too,
//! see `trajpred_data::csvfile`). Without an argument the example writes a generated file
//! of 12 tracks to the system's temporary folder and uses that. `tests/examples.rs` runs it.
#![allow(clippy::print_stdout)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use trajpred::dataset::{self, Dataset, Segmentation};
use trajpred::harness::{EvalConfig, MethodReport, Split, fit_and_evaluate, split_segments};
use trajpred::registry::{MethodOptions, build};

/// The methods the example compares.
pub const METHODS: [&str; 4] = ["cv-time", "naive-kf", "poly1", "gsc"];

/// Writes 12 generated tracks (walkers turning slowly, 1-3 s between fixes, 2 m noise, one
/// 2-minute pause in each) as `t,x,y,track`.
pub fn write_example_csv(path: &Path) -> std::io::Result<()> {
    let mut text = String::from("t,x,y,track\n");
    let mut state: u64 = 12345;
    let mut uniform = || {
        // a small linear congruential generator keeps the example free of extra crates
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for track in 0..12 {
        let (mut t, mut x, mut y) = (0.0, 0.0, 0.0);
        let mut heading = track as f64;
        for k in 0..150 {
            let dt = 1.0 + 2.0 * uniform() + if k == 75 { 120.0 } else { 0.0 };
            heading += 0.02 * (uniform() - 0.5) * dt;
            t += dt;
            x += 1.4 * heading.cos() * dt;
            y += 1.4 * heading.sin() * dt;
            let (nx, ny) = (2.0 * (uniform() - 0.5), 2.0 * (uniform() - 0.5));
            let _ = writeln!(text, "{t:.1},{:.2},{:.2},walker{track}", x + nx, y + ny);
        }
    }
    std::fs::write(path, text)
}

/// Loads `csv`, segments it at 30 s gaps, splits by track (30 % to fit), and evaluates
/// [`METHODS`] with a history of 20 points and 5 steps ahead.
pub fn run(csv: &Path) -> Result<Vec<MethodReport>, Box<dyn std::error::Error>> {
    let seg = Segmentation {
        max_gap: Some(30.0),
        min_points: 40,
        ..Default::default()
    };
    let loaded = dataset::load(Dataset::Csv, csv, &Dataset::Csv.options(), &seg, None)?;
    eprintln!("{}", loaded.summary());
    let split = Split::ByTrajectory {
        train_fraction: 0.3,
        seed: 1,
    };
    let (train, test) = split_segments(&loaded.segments, split)?;
    let take = |v: Vec<trajpred::dataset::Segment>| -> Vec<_> {
        v.into_iter().map(|s| s.trajectory).collect()
    };
    let (train, test) = (take(train), take(test));
    let cfg = EvalConfig {
        history: 20,
        horizon: 5,
        threshold: 5.0,
        ..Default::default()
    };
    let mut reports = Vec::new();
    for name in METHODS {
        let mut method = build(name, &MethodOptions::default())?;
        reports.push(fit_and_evaluate(
            method.as_mut(),
            &train,
            &test,
            &cfg,
            None,
        )?);
    }
    Ok(reports)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let csv = match std::env::args().nth(1) {
        Some(p) => PathBuf::from(p),
        None => {
            let p = std::env::temp_dir().join("trajpred_example_tracks.csv");
            write_example_csv(&p)?;
            p
        }
    };
    println!("| method | forecasts | failures | mean error (m) | step 5 (m) | within 5 m |");
    println!("|---|---|---|---|---|---|");
    for r in run(&csv)? {
        let last = r.mean_euclidean.last().copied().unwrap_or(f64::NAN);
        println!(
            "| {} | {} | {} | {:.2} | {last:.2} | {:.1} % |",
            r.method,
            r.forecasts,
            r.failures,
            r.mean_euclidean_all,
            100.0 * r.hit_rate_all
        );
    }
    Ok(())
}
