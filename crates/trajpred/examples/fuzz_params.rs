//! Mutation fuzzer of the parameter-file loader (`trajpred::params::ParamsFile::from_slice`):
//! valid files are written by fitting every non-neural learner (and some methods that learn
//! nothing) on a small synthetic dataset, then mutated (bit flips, random bytes, cuts,
//! repeated spans, numbers replaced by 0, -1, 1e308, 1e999, NaN strings and others, arrays
//! grown to thousands of entries, values replaced by deep nesting) and loaded; every method of
//! a file that loads is rebuilt and asked for a forecast. Every execution must end in `Ok` or
//! a typed error: a panic is caught, counted and its input saved under
//! `target/fuzz-findings-params/`.
//!
//! ```text
//! cargo run --release -p trajpred --example fuzz_params -- [EXECUTIONS] [SEED]
//! ```
//!
//! `tests/fuzz_params_short.rs` runs it briefly in every test run.

use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use trajpred::dataset::{Dataset, Segment, Segmentation};
use trajpred::harness::Split;
use trajpred::params::{self, ParamsError, ParamsFile};
use trajpred::protocol::{self, Silent};
use trajpred::registry::MethodOptions;
use trajpred_core::{Predictor, Trajectory};

/// What the fuzzer saw.
#[derive(Debug, Default)]
pub struct Stats {
    /// Executions run.
    pub executions: usize,
    /// Inputs that loaded (their methods then forecast, well or with a typed error).
    pub loaded: usize,
    /// Inputs refused with a typed error.
    pub refused: usize,
    /// Refusals by error variant.
    pub by_error: BTreeMap<&'static str, usize>,
    /// Panics caught (each input saved).
    pub panics: usize,
    /// Where the panicking inputs were saved, with the panic message.
    pub findings: Vec<String>,
}

/// How one input ended.
pub type Outcome = Result<(), &'static str>;

fn curve(i: usize, n: usize) -> Trajectory {
    let f = i as f64;
    let t: Vec<f64> = (0..n)
        .map(|k| k as f64 + 0.25 * ((k + i) % 3) as f64)
        .collect();
    let x = t
        .iter()
        .map(|t| 2.0 * t + 3.0 * (0.2 * t + f).sin())
        .collect();
    let y = t
        .iter()
        .map(|t| 0.5 * t + (0.1 * t * (1.0 + f)).cos())
        .collect();
    Trajectory::from_axes(t, vec![x, y]).unwrap_or_else(|e| panic!("valid curve: {e}"))
}

/// The valid files the mutations start from: each learner alone (small: m = 3, T = 2) and
/// some methods that learn nothing.
pub fn seeds() -> Vec<Vec<u8>> {
    let segments: Vec<Segment> = (0..6)
        .map(|i| Segment {
            group: i.to_string(),
            id: i.to_string(),
            frame: trajpred_data::Frame::Cartesian,
            trajectory: curve(i, 40),
        })
        .collect();
    let options = MethodOptions {
        window: 3,
        horizons: 2,
        ..MethodOptions::default()
    };
    let sets: [&[&str]; 6] = [
        &["kf-cv", "poly1"],
        &["kf-ca"],
        &["gsc"],
        &["gskf"],
        &["hmm"],
        &["kf-dynamic", "cv-time", "naive-kf-4d"],
    ];
    sets.iter()
        .map(|names| {
            let split = Split::ByTrajectory {
                train_fraction: 0.5,
                seed: 1,
            };
            let seg = Segmentation::default();
            let protocol = protocol::custom(Dataset::Csv, names, &options, seg, split, 10, 2);
            params::fit(&protocol, Path::new("fuzz"), &segments, None, &Silent)
                .and_then(|f| f.to_json())
                .unwrap_or_else(|e| panic!("seed file: {e}"))
        })
        .collect()
}

const EXTREME: [&str; 14] = [
    "0",
    "-1",
    "1e308",
    "-1e308",
    "1e999",
    "NaN",
    "\"NaN\"",
    "\"inf\"",
    "-0",
    "null",
    "18446744073709551616",
    "4294967297",
    "1e-320",
    "[]",
];

/// The index of a random byte of `d` for which `pick` holds, if any.
fn random_where(d: &[u8], rng: &mut impl Rng, pick: impl Fn(u8) -> bool) -> Option<usize> {
    let at: Vec<usize> = (0..d.len()).filter(|&i| pick(d[i])).collect();
    (!at.is_empty()).then(|| at[rng.random_range(0..at.len())])
}

/// One mutation of `data`.
pub fn mutate(data: &[u8], rng: &mut impl Rng) -> Vec<u8> {
    let mut d = data.to_vec();
    if d.is_empty() {
        return d;
    }
    let (n, i) = (d.len(), rng.random_range(0..d.len()));
    match rng.random_range(0..8u32) {
        // up to 8 bits flipped, a byte replaced, a cut
        0 => (0..rng.random_range(1..9usize))
            .for_each(|_| d[rng.random_range(0..n)] ^= 1 << rng.random_range(0..8u32)),
        1 => d[i] = rng.random(),
        2 => d.truncate(i),
        3 => {
            // a span of up to 64 bytes repeated 1-3 times somewhere
            let span = d[i..n.min(i + rng.random_range(1..65usize))].to_vec();
            let at = rng.random_range(0..n);
            let copies = span.repeat(rng.random_range(1..4usize));
            d.splice(at..at, copies);
        }
        4 | 5 => {
            // a number (inside an exact string or bare) replaced by an extreme one
            if let Some(i) = random_where(&d, rng, |b| b.is_ascii_digit()) {
                let num = |b: u8| b.is_ascii_digit() || b"+-.eE".contains(&b);
                let mut a = i;
                while a > 0 && num(d[a - 1]) {
                    a -= 1;
                }
                let mut j = i;
                while j < d.len() && num(d[j]) {
                    j += 1;
                }
                let x = EXTREME[rng.random_range(0..EXTREME.len())];
                d.splice(a..j, x.bytes());
            }
        }
        6 => {
            // an array grown: its first item repeated up to 20 000 times
            if let Some(i) = random_where(&d, rng, |b| b == b'[') {
                let end = d[i + 1..]
                    .iter()
                    .position(|&b| b == b',' || b == b']')
                    .map_or(d.len(), |p| i + 1 + p);
                let item = d[i + 1..end].to_vec();
                if !item.is_empty() {
                    let mut grown = Vec::new();
                    for _ in 0..rng.random_range(1..20_000usize) {
                        grown.extend_from_slice(&item);
                        grown.push(b',');
                    }
                    d.splice(i + 1..i + 1, grown);
                }
            }
        }
        _ => {
            // a value replaced by deep nesting
            if let Some(i) = random_where(&d, rng, |b| b == b':') {
                let depth = rng.random_range(1..5_000usize);
                let (open, close) = if rng.random() {
                    (b'[', b']')
                } else {
                    (b'{', b'}')
                };
                let mut nest = vec![open; depth];
                if open == b'{' {
                    // objects need keys: {"a":{"a":...}}
                    nest = b"{\"a\":".repeat(depth);
                }
                nest.extend(std::iter::repeat_n(close, depth));
                d.splice(i + 1..i + 1, nest);
            }
        }
    }
    d
}

fn variant(e: &ParamsError) -> &'static str {
    match e {
        ParamsError::Io { .. } => "Io",
        ParamsError::TooLarge { .. } => "TooLarge",
        ParamsError::Json { .. } => "Json",
        ParamsError::Format { .. } => "Format",
        ParamsError::Version { .. } => "Version",
        ParamsError::Limit { .. } => "Limit",
        ParamsError::UnknownMethod { .. } => "UnknownMethod",
        ParamsError::DuplicateMethod { .. } => "DuplicateMethod",
        ParamsError::Invalid { .. } => "Invalid",
        ParamsError::Missing { .. } => "Missing",
        ParamsError::Unsupported { .. } => "Unsupported",
        ParamsError::Fit { .. } => "Fit",
        _ => "other",
    }
}

/// Loads `data`; a file that loads has each of its methods rebuilt and asked for a forecast
/// (by steps and at times).
pub fn run_one(data: &[u8], history: &Trajectory) -> Outcome {
    let file = ParamsFile::from_slice(data, "fuzz.json").map_err(|e| variant(&e))?;
    for m in &file.methods {
        let p = file.predictor(&m.label).map_err(|e| variant(&e))?;
        let _ = p.forecast(history, 2);
        let last = history.times()[history.len() - 1];
        let _ = p.forecast_times(history, &[last + 0.5, last + 3.0]);
    }
    Ok(())
}

/// Where panicking inputs are saved.
pub fn findings_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/fuzz-findings-params")
}

/// Runs `executions` mutated inputs over `seeds` (round robin), seeded by `seed`.
pub fn fuzz(seeds: &[Vec<u8>], executions: usize, seed: u64) -> Stats {
    let history = curve(9, 12);
    fuzz_with(
        seeds,
        executions,
        seed,
        &|d| run_one(d, &history),
        &findings_dir(),
    )
}

/// [`fuzz`] with the loader `run` and the findings folder `dir` of the caller's choosing.
pub fn fuzz_with(
    seeds: &[Vec<u8>],
    executions: usize,
    seed: u64,
    run: &dyn Fn(&[u8]) -> Outcome,
    dir: &Path,
) -> Stats {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut stats = Stats::default();
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    for e in 0..executions {
        let base = &seeds[e % seeds.len()];
        let mut data = mutate(base, &mut rng);
        if rng.random_range(0..4u32) == 0 {
            data = mutate(&data, &mut rng);
        }
        stats.executions += 1;
        match catch_unwind(AssertUnwindSafe(|| run(&data))) {
            Ok(Ok(())) => stats.loaded += 1,
            Ok(Err(v)) => {
                stats.refused += 1;
                *stats.by_error.entry(v).or_default() += 1;
            }
            Err(payload) => {
                stats.panics += 1;
                let msg = payload
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                let path = dir.join(format!("params-{seed}-{e}.json"));
                if std::fs::create_dir_all(dir).is_ok() && std::fs::write(&path, &data).is_ok() {
                    stats
                        .findings
                        .push(format!("{msg} (saved: {})", path.display()));
                }
            }
        }
    }
    std::panic::set_hook(hook);
    stats
}

#[allow(dead_code)]
fn main() {
    // arguments: executions (default 20 000), seed (default 1)
    let arg = |i: usize, default: u64| {
        std::env::args()
            .nth(i)
            .and_then(|a| a.parse().ok())
            .unwrap_or(default)
    };
    let start = std::time::Instant::now();
    let stats = fuzz(&seeds(), arg(1, 20_000) as usize, arg(2, 1));
    let secs = start.elapsed().as_secs_f64();
    eprintln!("fuzz_params: {secs:.1} s: {stats:?}");
    std::process::exit(i32::from(stats.panics > 0));
}
