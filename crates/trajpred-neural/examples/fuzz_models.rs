//! Mutation fuzzer of the model files: a small trained LSTM (`WindowNet`) and a small
//! KFU-LSTM-Net are saved, then their bytes are mutated (bit flips, random bytes, cuts,
//! repeated spans, numbers in the JSON header replaced by extreme ones, length fields
//! rewritten) and loaded with `load_bytes`; a model that loads is asked for a forecast. Every
//! execution must end in `Ok` or a typed error: a panic is caught, counted and its input saved
//! under `target/fuzz-findings-models/`.
//!
//! ```text
//! cargo run --release -p trajpred-neural --example fuzz_models -- [EXECUTIONS] [SEED]
//! ```
//!
//! `tests/fuzz_models_short.rs` runs it briefly in every test run.

use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use trajpred_core::{Predictor, Trajectory};
use trajpred_neural::{
    AxisMode, KfuConfig, KfuLstmNet, LstmArch, LstmNet, RecurrentLayers, TrainConfig, WindowConfig,
    WindowNet,
};

/// Which loader a seed feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `WindowNet<LstmArch>::load_bytes`.
    Lstm,
    /// `KfuLstmNet::load_bytes`.
    Kfu,
}

/// What the fuzzer saw.
#[derive(Debug, Default)]
pub struct Stats {
    /// Executions run.
    pub executions: usize,
    /// Inputs that loaded (and then forecast, well or with a typed error).
    pub loaded: usize,
    /// Inputs refused with a typed error.
    pub refused: usize,
    /// Panics caught (each input saved).
    pub panics: usize,
    /// Where the panicking inputs were saved.
    pub findings: Vec<PathBuf>,
}

fn curve(n: usize, phase: f64) -> Trajectory {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.1 + phase).collect();
    let axes = vec![
        t.iter().map(|s| (0.7 * s).sin()).collect(),
        t.iter().map(|s| (0.5 * s).cos()).collect(),
    ];
    Trajectory::uniform(0.0, 0.1, axes).unwrap_or_else(|e| panic!("valid curve: {e}"))
}

/// The saved bytes of the two small models (trained for one epoch).
pub fn seeds() -> Vec<(Kind, Vec<u8>)> {
    let dir = std::env::temp_dir().join(format!("trajpred-fuzz-models-{}", std::process::id()));
    let read = |path: &std::path::Path| std::fs::read(path).unwrap_or_else(|e| panic!("{e}"));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
    let layers = RecurrentLayers {
        layers: vec![8],
        fc: vec![8],
        ..RecurrentLayers::default()
    };
    let layout = WindowConfig {
        window: 5,
        horizon: 2,
        axes: AxisMode::Joint,
    };
    let mut lstm = LstmNet::new(
        LstmArch(layers),
        layout,
        TrainConfig::new(1e-2).with_epochs(1),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    lstm.fit(&[curve(40, 0.0)])
        .unwrap_or_else(|e| panic!("{e}"));
    let lstm_path = dir.join("lstm.tpnn");
    lstm.save(&lstm_path).unwrap_or_else(|e| panic!("{e}"));
    let config = KfuConfig {
        layers: vec![8],
        fc: vec![8],
        seq_len: 10,
        stride: 5,
        ..KfuConfig::default()
    };
    let mut kfu = KfuLstmNet::new(config, TrainConfig::new(3e-3).with_epochs(1))
        .unwrap_or_else(|e| panic!("{e}"));
    kfu.fit(&[curve(30, 0.0)]).unwrap_or_else(|e| panic!("{e}"));
    let kfu_path = dir.join("kfu.tpnn");
    kfu.save(&kfu_path).unwrap_or_else(|e| panic!("{e}"));
    let out = vec![(Kind::Lstm, read(&lstm_path)), (Kind::Kfu, read(&kfu_path))];
    let _ = std::fs::remove_dir_all(&dir);
    out
}

const EXTREME: [&str; 8] = [
    "0",
    "-1",
    "1e308",
    "-1e308",
    "18446744073709551615",
    "4294967297",
    "1e-320",
    "null",
];

/// One mutation of `data`.
pub fn mutate(data: &[u8], rng: &mut impl Rng) -> Vec<u8> {
    let mut d = data.to_vec();
    if d.is_empty() {
        return d;
    }
    match rng.random_range(0..6u32) {
        0 => {
            for _ in 0..rng.random_range(1..8usize) {
                let i = rng.random_range(0..d.len());
                d[i] ^= 1 << rng.random_range(0..8u32);
            }
        }
        1 => {
            let i = rng.random_range(0..d.len());
            d[i] = rng.random();
        }
        2 => d.truncate(rng.random_range(0..d.len())),
        3 => {
            let a = rng.random_range(0..d.len());
            let b = (a + rng.random_range(1..64usize)).min(d.len());
            let span = d[a..b].to_vec();
            let at = rng.random_range(0..d.len());
            d.splice(at..at, span);
        }
        4 => {
            // a number of the JSON header (after the magic line and the length field)
            let start = 18 + 8;
            let end = d.len().min(start + 4096);
            let digits: Vec<usize> = (start..end).filter(|&i| d[i].is_ascii_digit()).collect();
            if let Some(&i) = digits.get(rng.random_range(0..digits.len().max(1))) {
                let mut j = i;
                while j < end && (d[j].is_ascii_digit() || d[j] == b'.' || d[j] == b'e') {
                    j += 1;
                }
                let x = EXTREME[rng.random_range(0..EXTREME.len())];
                let old_len = j - i;
                d.splice(i..j, x.bytes());
                // keep the header's length field right, so the JSON is what is tested
                let delta = x.len() as i64 - old_len as i64;
                if let Some(field) = d.get(18..26) {
                    let mut b = [0u8; 8];
                    b.copy_from_slice(field);
                    let len = (u64::from_le_bytes(b) as i64 + delta).max(0) as u64;
                    d[18..26].copy_from_slice(&len.to_le_bytes());
                }
            }
        }
        _ => {
            // a length field rewritten
            let v: u64 = match rng.random_range(0..3u32) {
                0 => 0,
                1 => u64::MAX,
                _ => rng.random_range(0..(d.len() as u64 * 2)),
            };
            if d.len() >= 26 {
                d[18..26].copy_from_slice(&v.to_le_bytes());
            }
        }
    }
    d
}

fn run_one(kind: Kind, data: &[u8], history: &Trajectory) -> bool {
    match kind {
        Kind::Lstm => match WindowNet::<LstmArch>::load_bytes(data) {
            Ok(m) => {
                let _ = m.forecast(history, 3);
                true
            }
            Err(_) => false,
        },
        Kind::Kfu => match KfuLstmNet::load_bytes(data) {
            Ok(m) => {
                let _ = m.forecast(history, 3);
                true
            }
            Err(_) => false,
        },
    }
}

/// Runs `executions` mutated inputs over `seeds` (round robin), seeded by `seed`.
pub fn fuzz(seeds: &[(Kind, Vec<u8>)], executions: usize, seed: u64) -> Stats {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let history = curve(20, 0.3);
    let mut stats = Stats::default();
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    for e in 0..executions {
        let (kind, base) = &seeds[e % seeds.len()];
        let mut data = mutate(base, &mut rng);
        if rng.random_range(0..4u32) == 0 {
            data = mutate(&data, &mut rng);
        }
        stats.executions += 1;
        match catch_unwind(AssertUnwindSafe(|| run_one(*kind, &data, &history))) {
            Ok(true) => stats.loaded += 1,
            Ok(false) => stats.refused += 1,
            Err(_) => {
                stats.panics += 1;
                let dir = PathBuf::from("target/fuzz-findings-models");
                let path = dir.join(format!("{kind:?}-{seed}-{e}.tpnn"));
                if std::fs::create_dir_all(&dir).is_ok() && std::fs::write(&path, &data).is_ok() {
                    stats.findings.push(path);
                }
            }
        }
    }
    std::panic::set_hook(hook);
    stats
}

#[allow(dead_code)]
fn main() {
    let mut args = std::env::args().skip(1);
    let executions = args.next().and_then(|a| a.parse().ok()).unwrap_or(20_000);
    let seed = args.next().and_then(|a| a.parse().ok()).unwrap_or(1);
    let start = std::time::Instant::now();
    let stats = fuzz(&seeds(), executions, seed);
    eprintln!(
        "fuzz_models: {} executions in {:.1} s: {} loaded, {} refused with a typed error, {} panics {:?}",
        stats.executions,
        start.elapsed().as_secs_f64(),
        stats.loaded,
        stats.refused,
        stats.panics,
        stats.findings
    );
    if stats.panics > 0 {
        std::process::exit(1);
    }
}
